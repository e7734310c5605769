//! Checking other implementations: the JSON-lines adapter protocol, candidate processes with
//! limits and timeouts, the bundled adapter for the course's Python API, judging answers,
//! reports with Python reproductions, fuzzing with shrinking, and an in-process Rust trait.
//!
//! - [`protocol`]: request and answer lines, the hello (`docs/PROTOCOL.md`).
//! - [`command`]: [`CandidateCommand`], what a candidate runs (an `--adapter` command line or
//!   the course adapter on a submission folder) and the sandbox made for it; [`options`]:
//!   [`RunOptions`]; [`error`]: [`HarnessError`]; [`outcome`]: [`Outcome`], what one case got.
//! - [`session`]: [`Session`] runs a [`CandidateCommand`] in the [sandbox](crate::sandbox) with
//!   pipelined requests, per-case timeouts, restarts after crashes and the process group killed
//!   on drop, over the pipes of [`pipe`], judging each line by the strict protocol of [`lines`].
//! - [`python`]: choosing the interpreter of the course adapter (the assignment's modules,
//!   runnable in the sandbox).
//! - [`check`]: the verdict for one case; [`report`]: [`CheckReport`] (serde) and
//!   [`build_report`]; [`report_text`]: its text; [`repro`]: expected answers in words and
//!   Python reproductions.
//! - [`diagnose`]: the known mistake (a buggy variant of the oracle) that explains the failures.
//! - [`rust`]: the [`Candidate`] trait and [`check_candidate`] for Rust implementations.
//! - [`generate`], [`shrink`], [`fuzz`](mod@fuzz): random cases, classification through
//!   [`generate::oracle_expect`], shrinking, the fuzz driver.
//! - [`bench`](mod@bench): throughput of the harness against baselines measured in the same run;
//!   [`fixtures`]: the fixture files it (and grading's benchmark) needs, embedded in the binary.

pub mod bench;
pub mod check;
pub mod command;
pub mod diagnose;
pub mod error;
pub mod fixtures;
pub mod fuzz;
pub mod generate;
pub mod lines;
pub mod options;
pub mod outcome;
pub mod pipe;
pub mod protocol;
pub mod python;
pub mod report;
pub mod report_text;
pub mod repro;
pub mod rust;
pub mod session;
pub mod shrink;
#[cfg(test)]
pub(crate) mod test_cases;

pub use crate::sandbox::SandboxPolicy;
pub use check::{FailureKind, Verdict, judge};
pub use command::CandidateCommand;
pub use error::HarnessError;
pub use options::RunOptions;
pub use outcome::Outcome;
pub use protocol::{Answer, CandidateError, Hello};
pub use report::{CheckReport, Counts, Failure, RunInfo, build_report};
pub use rust::{Candidate, Reference, check_candidate};
pub use session::{CallOutcome, Session};

use crate::oracle::vectors::Case;

/// Runs `cases` through a started session and builds the report.
pub fn check_session(session: &mut Session, cases: &[Case]) -> Result<CheckReport, HarnessError> {
    let outcomes = session.run(cases)?;
    Ok(build_report(cases, &outcomes, run_info(session)))
}

/// What a report says of the session that ran it (its candidate, import error, restarts,
/// stderr, sandbox).
pub fn run_info(session: &Session) -> RunInfo {
    RunInfo {
        candidate: session.hello().name.clone(),
        import_error: session.hello().error.clone(),
        start_failure: session.start_failure().map(str::to_string),
        stderr_tail: session.stderr_tail(),
        restarts: session.restarts(),
        sandbox: Some(session.sandbox_facts()),
        course_api: session.command().is_course_adapter(),
    }
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
