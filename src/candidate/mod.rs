//! Checking other implementations: the JSON-lines adapter protocol, candidate processes with
//! limits and timeouts, the bundled adapter for the course's Python API, judging answers,
//! reports with Python reproductions, fuzzing with shrinking, and an in-process Rust trait.
//!
//! Three rooms, bottom up, and the path through them on top (this file):
//!
//! - [`process`]: a candidate as a process. What it runs ([`CandidateCommand`]: an `--adapter`
//!   command line or the bundled course adapter on a submission folder), the protocol's lines
//!   ([`process::protocol`], `docs/PROTOCOL.md`), the [`Session`] that runs it in the
//!   [sandbox](crate::sandbox) with pipelined requests, per-case time-outs and restarts, the
//!   `render` request ([`process::render_request`]) and the choice of the course adapter's Python.
//! - [`judging`]: what an answer is worth. The verdict of one case ([`judging::check`]), the
//!   watertight rule, the [`CheckReport`] and its text, Python reproductions, and the known
//!   mistake that explains the failures ([`judging::diagnose`]).
//! - [`fuzzing`]: random cases classified by the oracle, the fuzz driver and shrinking.
//! - [`rust`]: the [`Candidate`](rust::Candidate) trait and
//!   [`check_candidate`](rust::check_candidate) for Rust implementations.
//! - Here: [`check_command`] and [`check_session`], one candidate checked against a list of
//!   cases, start to report.

pub mod process;
pub mod judging;
pub mod fuzzing;
pub mod rust;
#[cfg(test)]
pub(crate) mod test_cases;

use self::judging::report::{CheckReport, RunInfo, build_report};
use self::process::command::CandidateCommand;
use self::process::error::HarnessError;
use self::process::options::RunOptions;
use self::process::session::Session;
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
        notes: session.notes().to_vec(),
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
