//! Why the harness itself cannot run a candidate ([`HarnessError`]).

use crate::sandbox::policy::SandboxError;

/// Why the harness itself cannot run a candidate.
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    /// The program could not be started.
    // Reasons are in the messages, not `#[source]`s, so a report of the whole chain prints each
    // once.
    #[error("cannot start the candidate {program}: {reason}")]
    Spawn {
        /// The program.
        program: String,
        /// Why.
        reason: std::io::Error,
    },
    /// The candidate did not complete the hello.
    #[error("the candidate {program} did not answer the hello: {message}")]
    Hello {
        /// The program.
        program: String,
        /// What happened, with the end of its stderr.
        message: String,
    },
    /// The candidate's hello cannot be accepted (another protocol version, an unknown shape).
    #[error("the candidate {program} cannot be checked: {problem}")]
    BadHello {
        /// The program.
        program: String,
        /// What is wrong with its hello.
        problem: String,
    },
    /// The adapter command line is unusable.
    #[error("the adapter command {command:?} {problem}")]
    Command {
        /// The command line.
        command: String,
        /// What is wrong.
        problem: String,
    },
    /// The submission folder is unusable.
    #[error("{path}: {problem}")]
    Submission {
        /// The folder.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// No usable Python interpreter (the message says which were tried and how to fix it).
    #[error("{0}")]
    Python(String),
    /// No sandbox may be made here: untrusted code is not run (fail closed).
    #[error("{0}")]
    Sandbox(#[from] SandboxError),
    /// An I/O error of the harness (temporary files, pipes).
    #[error("{context}: {reason}")]
    Io {
        /// What the harness was doing.
        context: String,
        /// Why it failed.
        reason: std::io::Error,
    },
}
