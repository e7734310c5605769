//! # rtoracle
//!
//! A test oracle and verification harness for ray tracers, built for the course "Ray Tracing in
//! Entertainment Industry" (after *Ray Tracing in One Weekend*) and for any renderer that wants
//! to be checked.
//!
//! A short tour, bottom floor first (a module uses only the ones above it in this list):
//! - [`arithmetic`]: outward-rounded intervals, exact dyadic rationals and the exact decisions
//!   of a ray against the three primitives, shared by the reference and the oracle.
//! - [`escape`]: untrusted text kept as text in every format (terminal, Markdown, HTML, CSV, XML).
//! - [`interrupt`]: Ctrl-C and SIGTERM clean up what was started or half-written.
//! - [`secret`]: the seeds a candidate sees, derived from the rubric's secret by HMAC-SHA256.
//! - [`output`]: output files and folders checked before the work, written whole or not at all.
//! - [`geometry`]: rays, intervals, hit records and the reference primitives (sphere, quad,
//!   watertight triangle) in `f64`, following the course's semantics.
//! - [`scene`]: materials, the course's camera, TOML scene files and the built-in scenes (and,
//!   in `scene/accel/`, what makes a world quick to query).
//! - [`render`]: the course's integrator and a renderer that gives the same bytes for a seed on
//!   any number of threads (the fast paths in `render/fast/`).
//! - [`oracle`]: the vector format and the exact intersection oracle.
//! - [`sandbox`]: how untrusted code (candidates, students' submissions) is started: a fresh
//!   folder, a cleared environment, limits, its own process group, no network, never as root.
//! - [`image_io`]: PNG and OpenEXR, written atomically.
//! - [`candidate`]: checking other implementations (a candidate as a process, judging its
//!   answers, fuzzing; the course's Python API; a trait for Rust tracers).
//! - [`weekly`]: the weekly checks of the course's weeks 5 to 10, the protocol's function
//!   requests judged against the reference's own answers.
//! - [`golden`]: the golden EXRs of the built-in scenes (mean and per-sample variance at 4096 spp),
//!   embedded in the library, the golden of any scene file, and their comparison.
//! - [`compare`]: the noise-aware image comparison against goldens or between two renders, with
//!   its diagnosis of common mistakes, FLIP, heatmaps and reports.
//! - [`grade`]: rubrics, grading a submission or a batch, the report formats (JSON, Gradescope,
//!   JUnit, Markdown), and the Gradescope autograder package.
//! - [`physics`]: physics checks that need no golden: a renderer's materials (sampling, pdf,
//!   weights, energy, reciprocity) through the protocol's material requests, and furnace scenes.
//! - [`bench`](mod@bench): the figures of `rtoracle bench` and `cargo bench`, each against a baseline
//!   measured in the same run.
#![warn(missing_docs)]
#![deny(clippy::undocumented_unsafe_blocks)]

pub mod arithmetic;
pub mod bench;
pub mod candidate;
pub mod compare;
pub mod escape;
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
pub mod weekly;
