//! The benchmarks: every figure `rtoracle bench` and `cargo bench` print, each a ratio against a
//! baseline measured in the same run, out of the product's modules.
//!
//! - [`oracle`]: the oracle's figures (exact decisions per second, how many cases the fast
//!   filter settles).
//! - [`harness`]: the throughput of checking a candidate (the course adapter and the C example)
//!   against baselines measured in the same run.
//! - [`compare`]: the comparison's speed against a plain difference pass.
//! - [`grade`]: grading speed, one submission and a batch.
//! - [`fixtures`]: the fixture submissions and adapters those need, embedded in the binary (and
//!   used by tests to assemble a fixture folder).
//!
//! `rtoracle bench render` (the reference against a C loop of the same integrator) lives with
//! the command line, which builds and runs the C loop (`benches/baseline.c`).

pub mod compare;
pub mod fixtures;
pub mod grade;
pub mod harness;
pub mod oracle;
