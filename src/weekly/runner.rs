//! Sending function requests: the [`FunctionRunner`] a week's checks run through (a candidate's
//! session, or a Rust stand-in in tests), and what one request got ([`Reply`]).

use std::time::Duration;

use crate::candidate::process::protocol::CandidateError;

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
    /// No answer: the candidate died, could not start, or its time budget is used up.
    Failed(String),
    /// An answer that breaks the protocol: a malformed line, a key its op's answer does not
    /// have ([`answer_keys`]), a wrong number of samples. A failure, never a skip, and counted
    /// for a person to look at: the bundled adapter never makes one, so it is a broken or a
    /// hijacked adapter.
    Protocol(String),
}

/// The keys of the `result` of each function request (`docs/PROTOCOL.md`, "Function
/// requests"); a check also allows every key its expectations name. Nothing else: a key such as
/// `"unsteered"` is a protocol error. `"departures"` (where the camera is built) only adds words
/// to the report ([`super::departures::listed`]); it never earns a point.
pub fn answer_keys(op: &str) -> &'static [&'static str] {
    match op {
        "reflect" | "refract" | "halfvector" => &["vector"],
        "schlick" => &["value"],
        "sphere_uv" => &["uv"],
        "quad_uv" | "intersect_at_time" => &["hit", "t", "point", "normal", "front_face", "uv"],
        "move_sphere" => &["center"],
        "texture" | "shade" => &["color"],
        "brdf" => &["value", "color"],
        "scatter" => &["scattered", "origin", "direction", "time", "attenuation"],
        "onb" => &["u", "v", "w", "local"],
        "camera" => &[
            "center",
            "u",
            "v",
            "w",
            "pixel00",
            "pixel_du",
            "pixel_dv",
            "defocus_radius",
            "height",
            "departures",
        ],
        "occlusion" => &["occluded"],
        "sample_camera_ray" => &["samples", "departures"],
        op if op.starts_with("sample_") => &["samples"],
        _ => &[],
    }
}

/// Something that answers function requests.
pub trait FunctionRunner {
    /// Whether the candidate answers requests of kind `op` (its hello's `ops`).
    fn supports(&self, op: &str) -> bool;

    /// Sends `request` (a JSON object with its `op` and arguments; the runner adds the `id`)
    /// and waits up to `timeout` for the answer.
    fn call(&mut self, request: &serde_json::Value, timeout: Duration) -> Reply;
}

/// A candidate's [`Session`](crate::candidate::process::session::Session) as a [`FunctionRunner`]: ids `f1`,
/// `f2`, ... in the order of the calls.
pub struct SessionRunner<'a> {
    session: &'a mut crate::candidate::process::session::Session,
    next: u64,
}

impl<'a> SessionRunner<'a> {
    /// Function requests through `session`.
    pub fn new(session: &'a mut crate::candidate::process::session::Session) -> Self {
        SessionRunner { session, next: 0 }
    }
}

impl FunctionRunner for SessionRunner<'_> {
    fn supports(&self, op: &str) -> bool {
        self.session.hello().answers(op)
    }

    fn call(&mut self, request: &serde_json::Value, timeout: Duration) -> Reply {
        use crate::candidate::process::session::CallOutcome;
        self.next += 1;
        let id = format!("f{}", self.next);
        match self.session.call(&id, request, timeout) {
            CallOutcome::Result(v) => Reply::Result(v),
            CallOutcome::Error(e) => Reply::Error(e),
            CallOutcome::TimedOut => Reply::TimedOut,
            CallOutcome::Failed(why) => Reply::Failed(why),
            CallOutcome::Protocol(why) => Reply::Protocol(why),
        }
    }
}
