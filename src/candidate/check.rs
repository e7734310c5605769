//! Judging one outcome against a case's expectation.
//!
//! On a definite case (`hit` or `miss`): the hit/miss decision must match; for a hit,
//! `|t - t_exact| <= t_tol` (when the vector has no `t_tol`, `1e-9 max(|t|, 1)`), every component
//! of the normal within [`NORMAL_TOL`] of the expected unit normal facing the ray, and
//! `front_face` exact. An error answer, a dead process or a timeout is an `error` / `timeout`;
//! stray output is a `protocol` error. `ambiguous` and `any` cases are reported, never scored.

use serde::{Deserialize, Serialize};

use super::process::Outcome;
use crate::oracle::vectors::{Case, Class};

/// How far each component of a candidate's normal may be from the expected one.
pub const NORMAL_TOL: f64 = 1e-6;

/// Why a definite case did not pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// A wrong answer.
    Mismatch,
    /// The candidate raised an error or its process died.
    Error,
    /// No answer within the per-case timeout.
    Timeout,
    /// Not run (its group used up its timeouts, or the shape is unsupported).
    NotRun,
    /// Output that is not an answer, or a malformed answer.
    Protocol,
}

impl FailureKind {
    /// The name used in reports (`"mismatch"`, `"not_run"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            FailureKind::Mismatch => "mismatch",
            FailureKind::Error => "error",
            FailureKind::Timeout => "timeout",
            FailureKind::NotRun => "not_run",
            FailureKind::Protocol => "protocol",
        }
    }
}

/// The judgement of one case.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// A definite case answered right.
    Pass,
    /// A case that is not scored (`ambiguous` or `any`).
    NotScored,
    /// A definite case that did not pass.
    Fail {
        /// What kind of failure.
        kind: FailureKind,
        /// One line saying what went wrong.
        message: String,
    },
}

fn fail(kind: FailureKind, message: impl Into<String>) -> Verdict {
    Verdict::Fail {
        kind,
        message: message.into(),
    }
}

fn with_junk(mut message: String, junk: &[String]) -> String {
    if !junk.is_empty() {
        message.push_str(&format!("; it printed {}", junk.join(", ")));
    }
    message
}

/// Judges `outcome` for `case`.
pub fn judge(case: &Case, outcome: &Outcome) -> Verdict {
    if !case.expect.class.is_definite() {
        return Verdict::NotScored;
    }
    match outcome {
        Outcome::NotRun { reason } => fail(FailureKind::NotRun, reason.clone()),
        Outcome::Timeout { junk } => fail(
            FailureKind::Timeout,
            with_junk("no answer within the timeout".into(), junk),
        ),
        Outcome::Died { message, junk } => {
            fail(FailureKind::Error, with_junk(message.clone(), junk))
        }
        Outcome::Protocol { message, junk } => {
            fail(FailureKind::Protocol, with_junk(message.clone(), junk))
        }
        Outcome::Answered { answer, junk } => {
            if !junk.is_empty() {
                return fail(
                    FailureKind::Protocol,
                    format!(
                        "the candidate printed something that is not an answer: {}",
                        junk.join(", ")
                    ),
                );
            }
            judge_answer(case, answer)
        }
    }
}

/// Judges an `ambiguous` case against its exact answer, as if it were definite (a hit when the
/// vector records an exact `t`, else a miss): [`Verdict::Pass`] when the candidate gave the
/// exact answer. Other cases are [`Verdict::NotScored`]. Reported, never scored by `check`;
/// grading scores it when the rubric says so.
pub fn judge_exact(case: &Case, outcome: &Outcome) -> Verdict {
    if case.expect.class != Class::Ambiguous {
        return Verdict::NotScored;
    }
    let mut exact = case.clone();
    exact.expect.class = if exact.expect.t.is_some() {
        Class::Hit
    } else {
        Class::Miss
    };
    judge(&exact, outcome)
}

/// Judges a well-delivered answer for a definite `case`.
pub fn judge_answer(case: &Case, answer: &super::protocol::Answer) -> Verdict {
    let expect = &case.expect;
    if !expect.class.is_definite() {
        return Verdict::NotScored;
    }
    if let Some(e) = &answer.error {
        return fail(FailureKind::Error, format!("raised {e}"));
    }
    if let Err(problem) = answer.validate() {
        return fail(FailureKind::Protocol, problem);
    }
    let hit = answer.hit == Some(true);
    match (expect.class, hit) {
        (Class::Miss, false) => Verdict::Pass,
        (Class::Miss, true) => fail(
            FailureKind::Mismatch,
            format!(
                "expected a miss, got a hit at t = {:?}",
                answer.t.unwrap_or(f64::NAN)
            ),
        ),
        (Class::Hit, false) => fail(
            FailureKind::Mismatch,
            match expect.t {
                Some(t) => format!("expected a hit at t = {t:?}, got a miss"),
                None => "expected a hit, got a miss".to_string(),
            },
        ),
        (Class::Hit, true) => {
            let t = answer.t.expect("validated");
            if let Some(te) = expect.t {
                let tol = expect.t_tol.unwrap_or(1e-9 * te.abs().max(1.0));
                // Written so that a NaN t fails.
                let close = (t - te).abs() <= tol;
                if !close {
                    return fail(
                        FailureKind::Mismatch,
                        format!("t = {t:?}, expected {te:?} (tolerance {tol:.3e})"),
                    );
                }
            }
            if let (Some(ne), Some(n)) = (expect.normal, answer.normal) {
                let off = (0..3)
                    .map(|k| (n[k] - ne[k]).abs())
                    .fold(0.0f64, |a, b| if b.is_nan() { f64::NAN } else { a.max(b) });
                let close = off <= NORMAL_TOL;
                if !close {
                    return fail(
                        FailureKind::Mismatch,
                        format!("normal = {n:?}, expected {ne:?} (the unit normal facing the ray)"),
                    );
                }
            }
            if let (Some(fe), Some(f)) = (expect.front_face, answer.front_face) {
                if fe != f {
                    return fail(
                        FailureKind::Mismatch,
                        format!("front_face = {f}, expected {fe}"),
                    );
                }
            }
            Verdict::Pass
        }
        _ => Verdict::NotScored,
    }
}

#[cfg(test)]
mod tests {
    use super::super::protocol::Answer;
    use super::*;

    fn sphere_hit() -> Case {
        crate::candidate::test_cases::basic_cases().remove(0)
    }

    #[test]
    fn a_right_hit_passes_and_each_wrong_field_fails() {
        let case = sphere_hit();
        let good = Answer::hit(4.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], true);
        assert_eq!(judge_answer(&case, &good), Verdict::Pass);
        // t within 1e-9 * 4 passes, beyond fails.
        let mut a = good.clone();
        a.t = Some(4.0 + 3e-9);
        assert_eq!(judge_answer(&case, &a), Verdict::Pass);
        a.t = Some(4.0 + 5e-9);
        assert!(matches!(
            judge_answer(&case, &a),
            Verdict::Fail {
                kind: FailureKind::Mismatch,
                ..
            }
        ));
        a.t = Some(f64::NAN);
        assert!(matches!(judge_answer(&case, &a), Verdict::Fail { .. }));
        let mut a = good.clone();
        a.normal = Some([0.0, 0.0, 2.0]);
        assert!(matches!(judge_answer(&case, &a), Verdict::Fail { .. }));
        a.normal = Some([0.0, 0.0, f64::NAN]);
        assert!(matches!(judge_answer(&case, &a), Verdict::Fail { .. }));
        let mut a = good.clone();
        a.front_face = Some(false);
        assert!(matches!(judge_answer(&case, &a), Verdict::Fail { .. }));
        assert!(matches!(
            judge_answer(&case, &Answer::miss()),
            Verdict::Fail {
                kind: FailureKind::Mismatch,
                ..
            }
        ));
        assert!(matches!(
            judge_answer(&case, &Answer::error("ZeroDivisionError", "x")),
            Verdict::Fail {
                kind: FailureKind::Error,
                ..
            }
        ));
        let mut a = good.clone();
        a.normal = None;
        assert!(matches!(
            judge_answer(&case, &a),
            Verdict::Fail {
                kind: FailureKind::Protocol,
                ..
            }
        ));
    }

    #[test]
    fn junk_times_and_deaths_have_their_kinds_and_unscored_cases_are_not_scored() {
        let case = sphere_hit();
        let good = Answer::hit(4.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], true);
        let junk = Outcome::Answered {
            answer: good.clone(),
            junk: vec!["debug".into()],
        };
        assert!(matches!(
            judge(&case, &junk),
            Verdict::Fail {
                kind: FailureKind::Protocol,
                ..
            }
        ));
        assert!(matches!(
            judge(&case, &Outcome::Timeout { junk: vec![] }),
            Verdict::Fail {
                kind: FailureKind::Timeout,
                ..
            }
        ));
        let mut amb = case.clone();
        amb.expect.class = Class::Ambiguous;
        assert_eq!(
            judge(&amb, &Outcome::Timeout { junk: vec![] }),
            Verdict::NotScored
        );
        let mut miss = case.clone();
        miss.expect.class = Class::Miss;
        assert_eq!(judge_answer(&miss, &Answer::miss()), Verdict::Pass);
        // An ambiguous case with an exact t is judged as that hit by judge_exact only.
        let right = Outcome::Answered {
            answer: good.clone(),
            junk: vec![],
        };
        assert_eq!(judge(&amb, &right), Verdict::NotScored);
        assert_eq!(judge_exact(&amb, &right), Verdict::Pass);
        let missed = Outcome::Answered {
            answer: Answer::miss(),
            junk: vec![],
        };
        assert!(matches!(judge_exact(&amb, &missed), Verdict::Fail { .. }));
        amb.expect.t = None;
        assert_eq!(judge_exact(&amb, &missed), Verdict::Pass);
        assert_eq!(judge_exact(&case, &right), Verdict::NotScored);
    }
}
