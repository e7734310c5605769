//! Sending function requests: the [`FunctionRunner`] a week's checks run through (a candidate's
//! session, or a Rust stand-in in tests), and what one request got ([`Reply`]).

use std::time::Duration;

use crate::candidate::CandidateError;

/// What a function request got.
#[derive(Clone, Debug, PartialEq)]
pub enum Reply {
    /// The answer's `result` object.
    Result(serde_json::Value),
    /// The candidate raised an error instead (with the submission's file names).
    Error(CandidateError),
    /// The request was not sent: why (the candidate does not list the op, the budget is spent).
    NotRun(String),
    /// No answer within the time allowed (the candidate was restarted).
    TimedOut,
    /// No answer: the candidate died, could not start, or broke the protocol.
    Failed(String),
}

/// Something that answers function requests.
pub trait FunctionRunner {
    /// Whether the candidate answers requests of kind `op` (its hello's `ops`).
    fn supports(&self, op: &str) -> bool;

    /// Sends `request` (a JSON object with its `op` and arguments; the runner adds the `id`)
    /// and waits up to `timeout` for the answer.
    fn call(&mut self, request: &serde_json::Value, timeout: Duration) -> Reply;
}

/// A candidate's [`Session`](crate::candidate::Session) as a [`FunctionRunner`]: ids `f1`,
/// `f2`, ... in the order of the calls.
pub struct SessionRunner<'a> {
    session: &'a mut crate::candidate::Session,
    next: u64,
}

impl<'a> SessionRunner<'a> {
    /// Function requests through `session`.
    pub fn new(session: &'a mut crate::candidate::Session) -> Self {
        SessionRunner { session, next: 0 }
    }
}

impl FunctionRunner for SessionRunner<'_> {
    fn supports(&self, op: &str) -> bool {
        self.session.hello().answers(op)
    }

    fn call(&mut self, request: &serde_json::Value, timeout: Duration) -> Reply {
        use crate::candidate::CallOutcome;
        self.next += 1;
        let id = format!("f{}", self.next);
        match self.session.call(&id, request, timeout) {
            CallOutcome::Result(v) => Reply::Result(v),
            CallOutcome::Error(e) => Reply::Error(e),
            CallOutcome::TimedOut => Reply::TimedOut,
            CallOutcome::Failed(why) => Reply::Failed(why),
        }
    }
}
