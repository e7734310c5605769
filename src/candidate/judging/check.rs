//! Judging one outcome against a case's expectation.
//!
//! On a definite case (`hit` or `miss`): the hit/miss decision must match; for a hit,
//! `|t - t_exact| <= t_tol` (when the vector has no `t_tol`, `1e-9 max(|t|, 1)`), every component
//! of the normal within [`NORMAL_TOL`] of the expected unit normal facing the ray, and
//! `front_face` exact. An error answer, a dead process or a timeout is an `error` / `timeout`;
//! stray output is a `protocol` error. `ambiguous` and `any` cases are reported, never scored.
//!
//! Triangles: the course defines none, so no winding is wrong. [`decide_winding`] reads the
//! submission's own winding off its answers (the majority of its definite triangle hits whose
//! `front_face` agrees with `(b - a) x (c - a)`, the reference's, against those that agree with
//! `(c - a) x (b - a)`; a tie keeps the reference's), and [`judge_wound`] judges `front_face`
//! against it. The normal facing the ray and `t` do not depend on the winding.

use serde::{Deserialize, Serialize};

use crate::candidate::process::outcome::Outcome;
use crate::oracle::vectors::{Case, Class, ShapeKind};

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

/// Which way a submission's triangles face: the side `front_face` calls the front.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Winding {
    /// The outward normal is `unit((b - a) x (c - a))`, as the reference's.
    BaCa,
    /// The outward normal is `unit((c - a) x (b - a))`.
    CaBa,
}

impl Winding {
    /// The cross product, as the report says it: `"(b - a) x (c - a)"`.
    pub fn formula(self) -> &'static str {
        match self {
            Winding::BaCa => "(b - a) x (c - a)",
            Winding::CaBa => "(c - a) x (b - a)",
        }
    }

    /// `case` with its expectation as the winding makes it: `front_face` negated for a
    /// triangle when the winding is not the reference's; any other case unchanged.
    pub fn expectation(self, case: &Case) -> std::borrow::Cow<'_, Case> {
        match (self, case.shape.kind()) {
            (Winding::CaBa, ShapeKind::Triangle) => {
                let mut c = case.clone();
                c.expect.front_face = c.expect.front_face.map(|f| !f);
                std::borrow::Cow::Owned(c)
            }
            _ => std::borrow::Cow::Borrowed(case),
        }
    }
}

/// The winding of the submission's triangles, decided from its answers on definite triangle
/// hits that it answers with a hit and a `front_face`: [`Winding::CaBa`] when more of them
/// disagree with the reference's `front_face` than agree, else [`Winding::BaCa`]. `None` when
/// there is no such answer (no triangles run, or none hit).
pub fn decide_winding(cases: &[Case], outcomes: &[Outcome]) -> Option<Winding> {
    let (mut agree, mut disagree) = (0usize, 0usize);
    for (case, outcome) in cases.iter().zip(outcomes) {
        if case.shape.kind() != ShapeKind::Triangle || case.expect.class != Class::Hit {
            continue;
        }
        let Outcome::Answered { answer, .. } = outcome else {
            continue;
        };
        if answer.error.is_some() || answer.hit != Some(true) {
            continue;
        }
        match (case.expect.front_face, answer.front_face) {
            (Some(e), Some(f)) if e == f => agree += 1,
            (Some(_), Some(_)) => disagree += 1,
            _ => {}
        }
    }
    match (agree, disagree) {
        (0, 0) => None,
        (a, d) if d > a => Some(Winding::CaBa),
        _ => Some(Winding::BaCa),
    }
}

/// [`judge`] with triangles' `front_face` judged against `winding` (`None`: the reference's).
pub fn judge_wound(case: &Case, outcome: &Outcome, winding: Option<Winding>) -> Verdict {
    match winding {
        Some(w) => judge(&w.expectation(case), outcome),
        None => judge(case, outcome),
    }
}

/// [`judge_exact`] with triangles' `front_face` judged against `winding`.
pub fn judge_exact_wound(case: &Case, outcome: &Outcome, winding: Option<Winding>) -> Verdict {
    match winding {
        Some(w) => judge_exact(&w.expectation(case), outcome),
        None => judge_exact(case, outcome),
    }
}

/// Judges `outcome` for `case`.
pub fn judge(case: &Case, outcome: &Outcome) -> Verdict {
    if !case.expect.class.is_definite() {
        return Verdict::NotScored;
    }
    match outcome {
        Outcome::NotRun { reason } | Outcome::Unsupported { reason } => {
            fail(FailureKind::NotRun, reason.clone())
        }
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

/// `cases` with every `ambiguous` case made definite by its exact answer (a hit when it
/// records an exact `t`, else a miss), as `check --score-ambiguous` scores them: a candidate
/// that gets an edge or a tangent wrong then fails, as [`judge_exact`] would say. The
/// watertight groups' rules are unchanged (a group in the plane stays unscored).
pub fn score_ambiguous(cases: Vec<Case>) -> Vec<Case> {
    cases
        .into_iter()
        .map(|mut c| {
            if c.expect.class == Class::Ambiguous {
                c.expect.class = if c.expect.t.is_some() {
                    Class::Hit
                } else {
                    Class::Miss
                };
            }
            c
        })
        .collect()
}

/// Judges a well-delivered answer for a definite `case`.
pub fn judge_answer(case: &Case, answer: &crate::candidate::process::protocol::Answer) -> Verdict {
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
                let close = off <= expect.normal_tol.unwrap_or(NORMAL_TOL);
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
    use super::*;
    use crate::candidate::process::protocol::Answer;

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

    /// A definite triangle hit facing +z (the reference's `(b - a) x (c - a)`) seen from above.
    fn triangle_hit(id: &str) -> Case {
        use crate::oracle::vectors::{Expect, RaySpec, ShapeSpec};
        Case {
            id: id.into(),
            shape: ShapeSpec::Triangle {
                a: [0.0, 0.0, 0.0],
                b: [1.0, 0.0, 0.0],
                c: [0.0, 1.0, 0.0],
            },
            ray: RaySpec {
                origin: [0.25, 0.25, 1.0],
                direction: [0.0, 0.0, -1.0],
            },
            interval: [1e-6, f64::MAX],
            expect: Expect {
                class: Class::Hit,
                tags: vec![],
                t: Some(1.0),
                t_tol: None,
                point: Some([0.25, 0.25, 0.0]),
                normal: Some([0.0, 0.0, 1.0]),
                normal_tol: None,
                front_face: Some(true),
                watertight: None,
            },
        }
    }

    fn said(front_face: bool) -> Outcome {
        Outcome::Answered {
            answer: Answer::hit(1.0, [0.25, 0.25, 0.0], [0.0, 0.0, 1.0], front_face),
            junk: vec![],
        }
    }

    #[test]
    fn the_winding_is_the_majority_of_the_answers_and_front_face_is_judged_by_it() {
        let cases: Vec<Case> = (0..3).map(|i| triangle_hit(&format!("t{i}"))).collect();
        // Two of three answers face (c - a) x (b - a): that is the winding, and the third,
        // inconsistent with it, is the only failure.
        let outcomes = [said(false), said(false), said(true)];
        let w = decide_winding(&cases, &outcomes);
        assert_eq!(w, Some(Winding::CaBa));
        assert_eq!(judge_wound(&cases[0], &outcomes[0], w), Verdict::Pass);
        assert!(matches!(
            judge_wound(&cases[2], &outcomes[2], w),
            Verdict::Fail {
                kind: FailureKind::Mismatch,
                ..
            }
        ));
        // A tie keeps the reference's winding; no triangle hit decides nothing.
        assert_eq!(
            decide_winding(&cases[..2], &[said(true), said(false)]),
            Some(Winding::BaCa)
        );
        assert_eq!(
            decide_winding(&cases, &vec![Outcome::Timeout { junk: vec![] }; 3]),
            None
        );
        // The winding never changes a sphere's judgement, nor a triangle's normal or t.
        let sphere = sphere_hit();
        let right = Outcome::Answered {
            answer: Answer::hit(4.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], true),
            junk: vec![],
        };
        assert_eq!(
            judge_wound(&sphere, &right, Some(Winding::CaBa)),
            Verdict::Pass
        );
        let flipped = Outcome::Answered {
            answer: Answer::hit(1.0, [0.25, 0.25, 0.0], [0.0, 0.0, -1.0], false),
            junk: vec![],
        };
        assert!(matches!(
            judge_wound(&cases[0], &flipped, Some(Winding::CaBa)),
            Verdict::Fail { .. }
        ));
        assert_eq!(Winding::CaBa.formula(), "(c - a) x (b - a)");
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
        // Scored as asked (`check --score-ambiguous`): the same verdicts, as definite ones.
        let scored = score_ambiguous(vec![amb.clone()]).remove(0);
        assert_eq!(judge(&scored, &right), Verdict::Pass);
        assert!(matches!(judge(&scored, &missed), Verdict::Fail { .. }));
        amb.expect.t = None;
        assert_eq!(judge_exact(&amb, &missed), Verdict::Pass);
        assert_eq!(judge_exact(&case, &right), Verdict::NotScored);
    }
}
