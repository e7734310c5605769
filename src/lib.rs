//! # rtoracle
//!
//! A test oracle and verification harness for ray tracers, built for the course "Ray Tracing in
//! Entertainment Industry" (after *Ray Tracing in One Weekend*) and for any renderer that wants
//! to be checked.
//!
//! A short tour:
//! - [`arithmetic`]: outward-rounded intervals, exact dyadic rationals and the exact decisions
//!   of a ray against the three primitives, shared by the reference and the oracle.
//! - [`geometry`]: rays, intervals, hit records and the reference primitives (sphere, quad,
//!   watertight triangle) in `f64`, following the course's semantics.
//! - [`scene`]: materials, the course's camera, TOML scene files and the built-in scenes.
//! - [`render`]: the course's integrator and a renderer that gives the same bytes for a seed on
//!   any number of threads.
//! - [`image_io`]: PNG and OpenEXR, written atomically.
//! - [`golden`]: the golden EXRs of the built-in scenes (mean and per-sample variance at 4096 spp),
//!   embedded in the library, and their pixel comparison.
//! - [`oracle`]: the vector format and the exact intersection oracle.
//! - [`compare`]: the noise-aware image comparison against goldens, with its diagnosis of
//!   common mistakes, heatmaps and reports.
//! - [`grade`]: rubrics, grading a submission or a batch, the report formats (JSON, Gradescope,
//!   JUnit, Markdown), and the Gradescope autograder package.
//! - [`physics`]: physics checks that need no golden: a renderer's materials (sampling, pdf,
//!   weights, energy, reciprocity) through the protocol's material requests.
//! - [`candidate`]: checking other implementations (adapter protocol, the course's Python API,
//!   sandboxed processes, reports, fuzzing, a trait for Rust tracers).
//! - [`escape`]: untrusted text kept as text in every format (terminal, Markdown, HTML, CSV).
//! - [`interrupt`]: Ctrl-C and SIGTERM clean up what was started or half-written.
//! - [`output`]: output files and folders checked before the work, written whole or not at all.
//! - [`secret`]: the seeds a candidate sees, derived from the rubric's secret by HMAC-SHA256.
//! - [`sandbox`]: how untrusted code (candidates, students' submissions) is started: a fresh
//!   folder, a cleared environment, limits, its own process group, no network, never as root.
#![warn(missing_docs)]

pub mod arithmetic;
pub mod bench;
pub mod candidate;
pub mod compare;
pub mod escape;
pub mod functions;
pub mod geometry;
pub mod golden;
pub mod grade;
pub mod image_io;
pub mod interrupt;
pub mod oracle;
pub mod output;
pub mod physics;
pub mod render;
pub mod sandbox;
pub mod scene;
pub mod secret;
