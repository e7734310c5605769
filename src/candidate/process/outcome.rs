//! What the harness got for one case of a candidate run as a process ([`Outcome`]): an answer,
//! a protocol error, a time-out, a death, a case of a shape the candidate does not implement,
//! or a case the harness stopped running.

use crate::candidate::process::protocol::Answer;

/// What the harness got for one case.
// An answer (with its error's file, line and code) is a few hundred bytes, made once per case
// and read once: boxing it would cost an allocation per case for nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// An answer line with the case's id; `junk` holds the non-answer lines printed while the
    /// case ran (a protocol error when not empty).
    Answered {
        /// The answer.
        answer: Answer,
        /// Stray output before the answer.
        junk: Vec<String>,
    },
    /// A line that is not a valid answer to this case's request (a malformed answer, an answer
    /// with another id, an oversize line): a protocol error, decided when the line arrived.
    Protocol {
        /// What was wrong, with the line quoted.
        message: String,
        /// Stray output before it.
        junk: Vec<String>,
    },
    /// No answer within the timeout: the candidate was killed and restarted.
    Timeout {
        /// Stray output while waiting.
        junk: Vec<String>,
    },
    /// The candidate's process died (or could not be restarted) on this case.
    Died {
        /// How it died.
        message: String,
        /// Stray output before it died.
        junk: Vec<String>,
    },
    /// The case was not sent because the harness stopped running it: its group used up its
    /// timeouts or crashes, or the session its time budget. A definite case left so fails the
    /// check.
    NotRun {
        /// Why.
        reason: String,
    },
    /// The case was not sent: the candidate said it does not implement the case's shape (its
    /// hello's `shapes`, or [`Candidate::supports`](crate::candidate::rust::Candidate::supports)). This
    /// alone fails no check (unless the shape is required).
    Unsupported {
        /// Why, in words.
        reason: String,
    },
}
