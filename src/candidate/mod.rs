//! Checking other implementations: the JSON-lines adapter protocol, candidate processes with
//! limits and timeouts, the bundled adapter for the course's Python API, judging answers,
//! reports with Python reproductions, fuzzing with shrinking, and an in-process Rust trait.
//!
//! - [`protocol`]: request and answer lines, the hello (`docs/PROTOCOL.md`).
//! - [`process`]: [`Session`] runs a [`CandidateCommand`] (an `--adapter` command line or the
//!   course adapter on a submission folder) in the [sandbox](crate::sandbox) with pipelined
//!   requests, per-case timeouts, restarts after crashes and the process group killed on drop.
//! - [`python`]: choosing the interpreter of the course adapter (the assignment's modules,
//!   runnable in the sandbox).
//! - [`check`]: the verdict for one case; [`report`]: [`CheckReport`] (serde) and its text.
//! - [`diagnose`]: the known mistake (a buggy variant of the oracle) that explains the failures.
//! - [`rust`]: the [`Candidate`] trait and [`check_candidate`] for Rust implementations.
//! - [`generate`], [`shrink`], [`fuzz`](mod@fuzz): random cases, classification through
//!   [`generate::oracle_expect`], shrinking, the fuzz driver.
//! - [`bench`](mod@bench): throughput of the harness against baselines measured in the same run.

pub mod bench;
pub mod check;
pub mod diagnose;
pub mod fuzz;
pub mod generate;
pub mod process;
pub mod protocol;
pub mod python;
pub mod report;
pub mod rust;
pub mod shrink;
#[cfg(test)]
pub(crate) mod test_cases;

pub use crate::sandbox::SandboxPolicy;
pub use check::{FailureKind, Verdict, judge};
pub use process::{CandidateCommand, HarnessError, Outcome, RunOptions, Session};
pub use protocol::{Answer, CandidateError, Hello};
pub use report::{CheckReport, Counts, Failure, RunInfo, build_report};
pub use rust::{Candidate, Reference, check_candidate};

use crate::oracle::vectors::Case;

/// Runs `cases` through a started session and builds the report.
pub fn check_session(session: &mut Session, cases: &[Case]) -> Result<CheckReport, HarnessError> {
    let outcomes = session.run(cases)?;
    Ok(build_report(
        cases,
        &outcomes,
        RunInfo {
            candidate: session.hello().name.clone(),
            import_error: session.hello().error.clone(),
            start_failure: session.start_failure().map(str::to_string),
            stderr_tail: session.stderr_tail(),
            restarts: session.restarts(),
            sandbox: Some(session.sandbox_facts()),
            course_api: session.command().is_course_adapter(),
        },
    ))
}

/// Starts `command`, checks it against `cases` and returns the report (the process group is
/// killed before returning).
pub fn check_command(
    command: CandidateCommand,
    cases: &[Case],
    options: RunOptions,
) -> Result<CheckReport, HarnessError> {
    let mut session = Session::start(command, options)?;
    check_session(&mut session, cases)
}
