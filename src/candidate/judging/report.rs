//! The check report's model ([`CheckReport`]): counts overall and per shape group, every
//! failure with what was asked and what was expected, the candidate's import error and the end
//! of its stderr, as JSON (serde); [`build_report`] judges every outcome into it. Its text is
//! [`crate::candidate::judging::report_text`]'s.
//!
//! Counting: `total` is the number of *definite* vectors (overall, or of one shape) and
//! `total = passed + failed + errors + timeouts + not_run`, where `failed` counts mismatches,
//! `errors` counts raised errors, dead processes and protocol errors. `ambiguous` counts the
//! `ambiguous` vectors and `any` the `any` vectors (degenerate or non-finite inputs); their
//! answers are never scored. `ambiguous_passed` counts the `ambiguous` vectors answered with the
//! exact answer (so `ambiguous_passed <= ambiguous`).
//!
//! What fails a check besides a definite vector answered wrong: a time-out or a dead process on
//! *any* vector, unscored ones included (`unscored_timeouts`, `unscored_crashes`: a candidate
//! must answer every vector, whatever it answers), and a definite vector left unrun for any
//! reason but a shape the candidate said it does not implement (`not_run - unsupported`: after
//! a group's time-outs or crashes, past the time budget). Such unscored vectors are listed in
//! `failures` too, with their class in `expected`. And a watertight group whose ray hit none of
//! its shapes (`watertight_cracked`, of `watertight` groups judged; [`crate::candidate::judging::watertight`]):
//! listed in `failures` under its first member's id.
//!
//! Every message, traceback, name and stderr line from the candidate was capped by the harness
//! when it was read ([`crate::candidate::process::protocol`], [`crate::candidate::process::session`]).
//!
//! A failure keeps the request line as sent and the expected answer in words, which any
//! adapter author can use, and a Python reproduction against the course's API only for the
//! bundled course adapter ([`crate::candidate::judging::repro`]). Vectors not run are summarised per shape and
//! reason (`not_run_summary`), not listed one by one.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::candidate::judging::check::{
    FailureKind, Verdict, Winding, decide_winding, judge_exact_wound, judge_wound,
};
use crate::candidate::judging::diagnose::Diagnosis;
pub use crate::candidate::judging::repro::{expected_in_words, python_repro};
use crate::candidate::judging::watertight::{GroupResult, crack_message, judge_groups};
use crate::candidate::process::outcome::Outcome;
use crate::candidate::process::protocol::{Answer, CandidateError};
use crate::oracle::vectors::{Case, Class, Expect, ShapeKind};
use crate::sandbox::facts::SandboxFacts;

/// Counts of one group (or of the whole run).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Definite vectors.
    pub total: usize,
    /// Definite vectors answered right.
    pub passed: usize,
    /// Wrong answers.
    pub failed: usize,
    /// Errors raised, processes dead, protocol errors.
    pub errors: usize,
    /// Timeouts.
    pub timeouts: usize,
    /// Definite vectors not run.
    pub not_run: usize,
    /// `ambiguous` vectors (not scored).
    pub ambiguous: usize,
    /// `ambiguous` vectors answered with the exact answer ([`judge_exact`](crate::candidate::judging::check::judge_exact)).
    pub ambiguous_passed: usize,
    /// `any` vectors: degenerate or non-finite inputs, where any answer (or an error) is
    /// accepted (not scored).
    #[serde(default)]
    pub any: usize,
    /// Definite vectors not run because the candidate does not implement their shape (counted
    /// in `not_run` too); the other vectors not run fail the check.
    #[serde(default)]
    pub unsupported: usize,
    /// `ambiguous` and `any` vectors with no answer within the time-out: not scored, but a hang
    /// fails the check.
    #[serde(default)]
    pub unscored_timeouts: usize,
    /// `ambiguous` and `any` vectors on which the candidate's process died: not scored, but a
    /// crash fails the check.
    #[serde(default)]
    pub unscored_crashes: usize,
    /// Watertight groups of class `hit` judged ([`crate::candidate::judging::watertight`]), counted under the
    /// shape of their first member.
    #[serde(default)]
    pub watertight: usize,
    /// Of those, the groups whose ray hit none of their shapes (a crack): each fails the check.
    #[serde(default)]
    pub watertight_cracked: usize,
}

impl Counts {
    fn add(&mut self, class: Class, outcome: &Outcome, verdict: &Verdict) {
        if let Verdict::NotScored = verdict {
            match outcome {
                Outcome::Timeout { .. } => self.unscored_timeouts += 1,
                Outcome::Died { .. } => self.unscored_crashes += 1,
                _ => {}
            }
        }
        if let Outcome::Unsupported { .. } = outcome {
            self.unsupported += usize::from(class.is_definite());
        }
        match verdict {
            Verdict::NotScored if class == Class::Any => self.any += 1,
            Verdict::NotScored => self.ambiguous += 1,
            Verdict::Pass => {
                self.total += 1;
                self.passed += 1;
            }
            Verdict::Fail { kind, .. } => {
                self.total += 1;
                match kind {
                    FailureKind::Mismatch => self.failed += 1,
                    FailureKind::Error | FailureKind::Protocol => self.errors += 1,
                    FailureKind::Timeout => self.timeouts += 1,
                    FailureKind::NotRun => self.not_run += 1,
                }
            }
        }
    }

    /// Whether no definite vector failed, raised an error or timed out, no vector at all hung
    /// or killed the candidate, every definite vector ran but those of a shape the candidate
    /// does not implement, and at least one passed if there were any (a candidate that runs
    /// nothing does not pass).
    pub fn all_passed(&self) -> bool {
        self.failed == 0
            && self.errors == 0
            && self.timeouts == 0
            && self.unscored_timeouts == 0
            && self.unscored_crashes == 0
            && self.not_run == self.unsupported
            && self.watertight_cracked == 0
            && (self.total == 0 || self.passed > 0)
    }

    /// Definite vectors the harness stopped running (after a group's time-outs or crashes, or
    /// past the time budget): each fails the check.
    pub fn left_unrun(&self) -> usize {
        self.not_run - self.unsupported
    }
}

/// One vector that was run and did not pass: a definite vector answered wrong (or not at all),
/// or any vector on which the candidate hung or died.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The vector's id.
    pub id: String,
    /// Its shape group.
    pub shape: ShapeKind,
    /// Its tags.
    pub tags: Vec<String>,
    /// What kind of failure.
    pub kind: FailureKind,
    /// The oracle's answer.
    pub expected: Expect,
    /// The oracle's answer in words (`a hit at t = 4.0 (+- 4.0e-9), normal (0.0, 0.0, 1.0),
    /// front_face true`).
    #[serde(default)]
    pub expected_text: String,
    /// The candidate's answer, when it gave one.
    pub actual: Option<Answer>,
    /// One line saying what went wrong.
    pub message: String,
    /// A Python snippet that reproduces the case against the course's API (the course adapter
    /// only; empty for other candidates).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub repro: String,
    /// The request line, as sent, for reproducing it with any adapter.
    pub request: String,
}

/// Definite vectors of one shape not run, for one reason.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct NotRunSummary {
    /// The shape group.
    pub shape: ShapeKind,
    /// How many definite vectors.
    pub count: usize,
    /// Why they were not run.
    pub reason: String,
}

/// The result of checking a candidate against a suite.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckReport {
    /// The candidate's name (from its hello).
    pub candidate: String,
    /// What the expectations were judged by (`"robust/f64"`, ...; see
    /// [`crate::oracle::profile::Judging`]), or where they came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub judged_by: Option<String>,
    /// Counts over all shapes.
    #[serde(flatten)]
    pub counts: Counts,
    /// Counts per shape group (all three groups are always present).
    pub by_shape: BTreeMap<ShapeKind, Counts>,
    /// Every definite vector that was run and did not pass, and every vector on which the
    /// candidate hung or died (`ambiguous` and `any` ones included), in suite order.
    pub failures: Vec<Failure>,
    /// The definite vectors not run, per shape and reason, in the order first met.
    #[serde(default)]
    pub not_run_summary: Vec<NotRunSummary>,
    /// The error that kept the candidate from answering anything (a submission that cannot be
    /// imported), also reported on every case.
    pub import_error: Option<CandidateError>,
    /// Why the candidate could not be started at all, if so.
    pub start_failure: Option<String>,
    /// The last 4 KB the candidate wrote to stderr.
    pub stderr_tail: String,
    /// How many times the candidate's process was restarted.
    pub restarts: u32,
    /// What the [sandbox](crate::sandbox) did: the isolation used (bubblewrap, a uid of its own,
    /// or unsandboxed by request), the namespaces seen made, limits, the uid the candidate ran
    /// as, network isolation, files not copied. `None` for in-process candidates.
    #[serde(default)]
    pub sandbox: Option<SandboxFacts>,
    /// The winding of the candidate's triangles, decided from its answers
    /// ([`decide_winding`]); `None` when no triangle was hit.
    #[serde(default)]
    pub triangle_winding: Option<Winding>,
    /// The known mistakes that explain the failures, per shape group ([`crate::candidate::judging::diagnose`]).
    #[serde(default)]
    pub diagnosis: Vec<Diagnosis>,
    /// What the harness noticed about the candidate's use of the protocol that is no vector's
    /// failure: keys of its hello the protocol does not name, answers that never came after the
    /// hello (stdout not flushed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The shapes the check requires (`check --require`): one of them with a definite vector
    /// not run (a candidate without triangles, say) fails the check ([`Self::required_not_run`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub required: Vec<ShapeKind>,
}

/// Extra facts about a run for [`build_report`].
#[derive(Clone, Debug, Default)]
pub struct RunInfo {
    /// The candidate's name.
    pub candidate: String,
    /// Its import error, if any.
    pub import_error: Option<CandidateError>,
    /// Why it could not start, if so.
    pub start_failure: Option<String>,
    /// The end of its stderr.
    pub stderr_tail: String,
    /// Restarts.
    pub restarts: u32,
    /// The sandbox's facts, for a candidate run as a process.
    pub sandbox: Option<SandboxFacts>,
    /// Whether the candidate is the course's Python API (through the bundled adapter): its
    /// failures then carry a Python reproduction.
    pub course_api: bool,
    /// What the harness noticed about the candidate's use of the protocol
    /// ([`Session::notes`](crate::candidate::process::session::Session::notes)).
    pub notes: Vec<String>,
}

/// The failure of `case`.
fn failure(
    case: &Case,
    outcome: &Outcome,
    kind: FailureKind,
    message: String,
    course_api: bool,
) -> Failure {
    let actual = match outcome {
        Outcome::Answered { answer, .. } => Some(answer.clone()),
        _ => None,
    };
    Failure {
        id: case.id.clone(),
        shape: case.shape.kind(),
        tags: case.expect.tags.clone(),
        kind,
        expected: case.expect.clone(),
        expected_text: expected_in_words(&case.expect),
        actual,
        message,
        repro: if course_api {
            python_repro(case)
        } else {
            String::new()
        },
        request: crate::candidate::process::protocol::Request::for_case(case).to_line(),
    }
}

/// What fails the check on a vector that is not scored: a time-out or a dead process, which no
/// answer excuses.
pub fn unscored_failure(outcome: &Outcome) -> Option<(FailureKind, String)> {
    let note = "on a vector that is not scored, but a candidate must answer every vector";
    match outcome {
        Outcome::Timeout { .. } => Some((
            FailureKind::Timeout,
            format!("no answer within the timeout ({note})"),
        )),
        Outcome::Died { message, .. } => Some((FailureKind::Error, format!("{message} ({note})"))),
        _ => None,
    }
}

/// Judges every outcome and builds the report.
pub fn build_report(cases: &[Case], outcomes: &[Outcome], info: RunInfo) -> CheckReport {
    assert_eq!(cases.len(), outcomes.len(), "one outcome per case");
    let mut counts = Counts::default();
    let mut by_shape: BTreeMap<ShapeKind, Counts> = ShapeKind::ALL
        .iter()
        .map(|&k| (k, Counts::default()))
        .collect();
    let mut failures = Vec::new();
    let mut not_run: Vec<NotRunSummary> = Vec::new();
    let winding = decide_winding(cases, outcomes);
    for (case, outcome) in cases.iter().zip(outcomes) {
        let verdict = judge_wound(case, outcome, winding);
        let class = case.expect.class;
        let group = by_shape.get_mut(&case.shape.kind()).expect("every kind");
        counts.add(class, outcome, &verdict);
        group.add(class, outcome, &verdict);
        if judge_exact_wound(case, outcome, winding) == Verdict::Pass {
            counts.ambiguous_passed += 1;
            group.ambiguous_passed += 1;
        }
        match verdict {
            Verdict::Fail {
                kind: FailureKind::NotRun,
                message,
            } => {
                let shape = case.shape.kind();
                match not_run
                    .iter_mut()
                    .find(|s| s.shape == shape && s.reason == message)
                {
                    Some(s) => s.count += 1,
                    None => not_run.push(NotRunSummary {
                        shape,
                        count: 1,
                        reason: message,
                    }),
                }
            }
            Verdict::Fail { kind, message } => {
                failures.push(failure(case, outcome, kind, message, info.course_api));
            }
            Verdict::NotScored => {
                if let Some((kind, message)) = unscored_failure(outcome) {
                    failures.push(failure(case, outcome, kind, message, info.course_api));
                }
            }
            Verdict::Pass => {}
        }
    }
    for g in judge_groups(cases, outcomes) {
        let first = &cases[g.members[0]];
        let group = by_shape.get_mut(&first.shape.kind()).expect("every kind");
        match g.result {
            GroupResult::Unjudged => continue,
            GroupResult::Held => {}
            GroupResult::Cracked => {
                counts.watertight_cracked += 1;
                group.watertight_cracked += 1;
                let message = crack_message(&g, cases);
                let outcome = &outcomes[g.members[0]];
                let kind = FailureKind::Mismatch;
                failures.push(failure(first, outcome, kind, message, info.course_api));
            }
        }
        counts.watertight += 1;
        group.watertight += 1;
    }
    CheckReport {
        candidate: info.candidate,
        judged_by: None,
        counts,
        by_shape,
        failures,
        not_run_summary: not_run,
        import_error: info.import_error,
        start_failure: info.start_failure,
        stderr_tail: info.stderr_tail,
        restarts: info.restarts,
        sandbox: info.sandbox,
        triangle_winding: winding,
        diagnosis: crate::candidate::judging::diagnose::diagnose(cases, outcomes, winding),
        notes: info.notes,
        required: Vec::new(),
    }
}

impl CheckReport {
    /// Whether no definite vector failed, raised an error or timed out (exit code 0); see
    /// [`Counts::all_passed`].
    pub fn passed(&self) -> bool {
        self.counts.all_passed() && self.required_not_run().is_empty()
    }

    /// The [required](Self::required) shapes some of whose definite vectors were not run.
    pub fn required_not_run(&self) -> Vec<ShapeKind> {
        self.required
            .iter()
            .copied()
            .filter(|k| self.by_shape.get(k).is_some_and(|c| c.not_run > 0))
            .collect()
    }

    /// The report as one JSON object.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report always serialises")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_add_up_per_group_and_overall() {
        let cases = crate::candidate::test_cases::basic_cases();
        let mut outcomes: Vec<Outcome> = cases
            .iter()
            .map(|c| Outcome::Answered {
                answer: Answer::from_record(crate::geometry::Shape::intersect(
                    &c.shape.object(),
                    &c.ray.ray(),
                    c.interval(),
                )),
                junk: vec![],
            })
            .collect();
        let report = build_report(&cases, &outcomes, RunInfo::default());
        assert!(report.passed(), "{}", report.to_text(5));
        let none_run: Vec<Outcome> = cases
            .iter()
            .map(|_| Outcome::NotRun {
                reason: "unsupported".into(),
            })
            .collect();
        let report = build_report(&cases, &none_run, RunInfo::default());
        assert!(
            !report.passed(),
            "a candidate that runs nothing does not pass"
        );
        outcomes[1] = Outcome::Timeout { junk: vec![] };
        outcomes[2] = Outcome::NotRun { reason: "r".into() };
        let report = build_report(&cases, &outcomes, RunInfo::default());
        assert!(!report.passed());
        let c = report.counts;
        assert!(!c.all_passed());
        assert_eq!((c.total, c.passed, c.timeouts, c.not_run), (5, 3, 1, 1));
        assert_eq!(report.by_shape[&ShapeKind::Sphere].timeouts, 1);
        assert_eq!(report.by_shape[&ShapeKind::Quad].not_run, 1);
        // Failures list what ran; what did not is summarised per shape and reason.
        assert_eq!(report.failures.len(), 1);
        assert_eq!(
            report.not_run_summary,
            [NotRunSummary {
                shape: ShapeKind::Quad,
                count: 1,
                reason: "r".into()
            }]
        );
        let json: serde_json::Value = serde_json::from_str(&report.to_json()).unwrap();
        for key in [
            "total",
            "passed",
            "failed",
            "errors",
            "timeouts",
            "not_run",
            "ambiguous",
        ] {
            assert!(json[key].is_u64(), "{key}");
            assert!(json["by_shape"]["triangle"][key].is_u64(), "{key}");
        }
        assert_eq!(json["failures"][0]["kind"], "timeout");
        assert_eq!(json["not_run_summary"][0]["count"], 1);
        // Not the course adapter: no Python, but the request and the expected answer.
        assert!(json["failures"][0].get("repro").is_none());
        assert!(
            json["failures"][0]["request"]
                .as_str()
                .unwrap()
                .starts_with("{\"id\":")
        );
        let text = report.to_text(5);
        assert!(text.contains("  request: {\"id\":") && text.contains("  expected: a "));
        assert!(!text.contains("RT_object"), "{text}");
    }

    /// The reference's answers to `cases`.
    fn right(cases: &[Case]) -> Vec<Outcome> {
        cases
            .iter()
            .map(|c| Outcome::Answered {
                answer: Answer::from_record(crate::geometry::Shape::intersect(
                    &c.shape.object(),
                    &c.ray.ray(),
                    c.interval(),
                )),
                junk: vec![],
            })
            .collect()
    }

    /// A hang or a death on a vector that is not scored counted for nothing (an adapter hanging
    /// on every degenerate quad got PASS), and so did the definite vectors left unrun after a
    /// group's time-outs; a shape the candidate does not implement still fails nothing.
    #[test]
    fn hangs_and_crashes_anywhere_and_vectors_left_unrun_fail_the_check() {
        let mut cases = crate::candidate::test_cases::basic_cases();
        cases[0].expect.class = Class::Any;
        cases[1].expect.class = Class::Ambiguous;
        let mut outcomes = right(&cases);
        assert!(build_report(&cases, &outcomes, RunInfo::default()).passed());
        outcomes[0] = Outcome::Timeout { junk: vec![] };
        let r = build_report(&cases, &outcomes, RunInfo::default());
        assert!(!r.passed());
        assert_eq!((r.counts.unscored_timeouts, r.counts.timeouts), (1, 0));
        assert_eq!(r.by_shape[&ShapeKind::Sphere].unscored_timeouts, 1);
        assert_eq!(r.failures.len(), 1);
        assert_eq!(
            (r.failures[0].id.as_str(), r.failures[0].kind),
            ("sphere-basic-0000", FailureKind::Timeout)
        );
        assert!(
            r.to_text(5)
                .contains("hangs and crashes: 1 time-outs and 0 crashes")
        );
        outcomes[0] = right(&cases).remove(0);
        outcomes[1] = Outcome::Died {
            message:
                "the candidate died on this case: its process was killed by signal 6 (SIGABRT)"
                    .into(),
            junk: vec![],
        };
        let r = build_report(&cases, &outcomes, RunInfo::default());
        assert!(!r.passed());
        assert_eq!(r.counts.unscored_crashes, 1);
        assert!(r.failures[0].message.contains("SIGABRT"));
        outcomes[1] = right(&cases).remove(1);
        outcomes[3] = Outcome::NotRun {
            reason: "not run after 3 timeouts in the quad group".into(),
        };
        let r = build_report(&cases, &outcomes, RunInfo::default());
        assert!(!r.passed());
        assert_eq!((r.counts.not_run, r.counts.left_unrun()), (1, 1));
        assert!(r.to_text(5).contains("left unrun: 1 definite vectors"));
        outcomes[3] = Outcome::Unsupported {
            reason: "the candidate does not support quads".into(),
        };
        let r = build_report(&cases, &outcomes, RunInfo::default());
        assert!(r.passed(), "{}", r.to_text(5));
        assert_eq!((r.counts.not_run, r.counts.unsupported), (1, 1));
    }

    #[test]
    fn any_is_counted_apart_from_ambiguous() {
        let mut cases = crate::candidate::test_cases::basic_cases();
        cases[0].expect.class = Class::Any;
        cases[1].expect.class = Class::Ambiguous;
        cases[1].expect.t = None;
        // Every case answered with a miss: the ambiguous one (a miss exactly) passes exactly;
        // the `any` one is not counted as ambiguous, passed or not.
        let outcomes: Vec<Outcome> = cases
            .iter()
            .map(|_| Outcome::Answered {
                answer: Answer::miss(),
                junk: vec![],
            })
            .collect();
        let r = build_report(&cases, &outcomes, RunInfo::default());
        assert_eq!(
            (r.counts.any, r.counts.ambiguous, r.counts.ambiguous_passed),
            (1, 1, 1)
        );
        assert_eq!(r.counts.total, cases.len() - 2);
    }
}
