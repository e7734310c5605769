//! The check report: counts overall and per shape group, every failure with what was asked and
//! what was expected, the candidate's import error and the end of its stderr; JSON (serde) and
//! text renderings.
//!
//! Counting: `total` is the number of *definite* vectors (overall, or of one shape) and
//! `total = passed + failed + errors + timeouts + not_run`, where `failed` counts mismatches,
//! `errors` counts raised errors, dead processes and protocol errors. `ambiguous` counts the
//! `ambiguous` vectors and `any` the `any` vectors (degenerate or non-finite inputs); both are
//! run and reported but never scored. `ambiguous_passed` counts the `ambiguous` vectors answered
//! with the exact answer (so `ambiguous_passed <= ambiguous`).
//!
//! What the report promises about text from the candidate: every message, traceback, name and
//! stderr line was capped by the harness when it was read ([`super::protocol`],
//! [`super::process`]), and [`CheckReport::to_text`] writes each through
//! [`crate::escape::terminal_line`] or [`crate::escape::terminal_text`], so nothing a candidate
//! prints can move the cursor, colour the terminal or fake a line of the report.
//!
//! A failure shows the request line as sent and the expected answer in words, which any
//! adapter author can use; a Python reproduction against the course's API only for the bundled
//! course adapter. Vectors not run are summarised per shape and reason (`not_run_summary`), not
//! listed one by one. When every failure is the same error (a submission that cannot be
//! imported), the text says it once.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::check::{FailureKind, Verdict, Winding, decide_winding, judge_exact_wound, judge_wound};
use super::diagnose::Diagnosis;
use super::process::Outcome;
use super::protocol::{Answer, CandidateError};
use crate::escape::{terminal_line, terminal_text};
use crate::oracle::vectors::{Case, Class, Expect, ShapeKind, ShapeSpec};
use crate::sandbox::SandboxFacts;

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
    /// `ambiguous` vectors answered with the exact answer ([`judge_exact`](crate::candidate::check::judge_exact)).
    pub ambiguous_passed: usize,
    /// `any` vectors: degenerate or non-finite inputs, where any answer (or an error) is
    /// accepted (not scored).
    #[serde(default)]
    pub any: usize,
}

impl Counts {
    fn add(&mut self, class: Class, verdict: &Verdict) {
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

    /// Whether no definite vector failed, raised an error or timed out, and at least one
    /// passed if there were any (vectors not run, e.g. of a shape the candidate does not
    /// implement, do not count against it, but a candidate that runs nothing does not pass).
    pub fn all_passed(&self) -> bool {
        self.failed == 0
            && self.errors == 0
            && self.timeouts == 0
            && (self.total == 0 || self.passed > 0)
    }
}

/// One definite vector that was run and did not pass.
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
    /// [`crate::oracle::Judging`]), or where they came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub judged_by: Option<String>,
    /// Counts over all shapes.
    #[serde(flatten)]
    pub counts: Counts,
    /// Counts per shape group (all three groups are always present).
    pub by_shape: BTreeMap<ShapeKind, Counts>,
    /// Every definite vector that was run and did not pass, in suite order.
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
    /// The known mistakes that explain the failures, per shape group ([`super::diagnose`]).
    #[serde(default)]
    pub diagnosis: Vec<Diagnosis>,
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
        counts.add(class, &verdict);
        group.add(class, &verdict);
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
                let actual = match outcome {
                    Outcome::Answered { answer, .. } => Some(answer.clone()),
                    _ => None,
                };
                failures.push(Failure {
                    id: case.id.clone(),
                    shape: case.shape.kind(),
                    tags: case.expect.tags.clone(),
                    kind,
                    expected: case.expect.clone(),
                    expected_text: expected_in_words(&case.expect),
                    actual,
                    message,
                    repro: if info.course_api {
                        python_repro(case)
                    } else {
                        String::new()
                    },
                    request: super::protocol::Request::for_case(case).to_line(),
                });
            }
            _ => {}
        }
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
        diagnosis: super::diagnose::diagnose(cases, outcomes, winding),
        required: Vec::new(),
    }
}

/// A float as Rust prints it (shortest round trip), `inf`, `-inf` or `nan`.
fn num(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:?}")
    }
}

/// How an expected answer is written: its numbers, its booleans, and what follows a miss and a
/// normal (the words of any language, or Python's).
struct Dialect {
    number: fn(f64) -> String,
    boolean: fn(bool) -> &'static str,
    miss: &'static str,
    normal_note: &'static str,
}

/// The expected answer of a vector in words, for any language.
pub fn expected_in_words(e: &Expect) -> String {
    expected_as(
        e,
        &Dialect {
            number: num,
            boolean: |b| if b { "true" } else { "false" },
            miss: "a miss",
            normal_note: " (unit, facing the ray)",
        },
    )
}

/// The expected answer of a vector written in `dialect`.
fn expected_as(e: &Expect, dialect: &Dialect) -> String {
    let number = dialect.number;
    match e.class {
        Class::Miss => dialect.miss.to_string(),
        Class::Hit => {
            let mut s = String::from("a hit");
            if let Some(t) = e.t {
                s.push_str(&format!(" at t = {}", number(t)));
                if let Some(tol) = e.t_tol {
                    s.push_str(&format!(" (+- {tol:.1e})"));
                }
            }
            if let Some(n) = e.normal {
                s.push_str(&format!(
                    ", normal ({}, {}, {}){}",
                    number(n[0]),
                    number(n[1]),
                    number(n[2]),
                    dialect.normal_note
                ));
            }
            if let Some(f) = e.front_face {
                s.push_str(&format!(", front_face {}", (dialect.boolean)(f)));
            }
            s
        }
        Class::Ambiguous => "ambiguous (not scored)".to_string(),
        Class::Any => "anything (not scored)".to_string(),
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

    /// A summary table and the first `max_failures` failures, each with its request and
    /// expected answer (or its Python reproduction for the course adapter). Every text from
    /// the candidate is escaped for the terminal.
    pub fn to_text(&self, max_failures: usize) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "candidate: {}", terminal_line(&self.candidate));
        if let Some(j) = &self.judged_by {
            let _ = writeln!(s, "judged by: {j}");
        }
        if let Some(e) = &self.import_error {
            let _ = writeln!(
                s,
                "the submission could not be imported: {}",
                terminal_line(&e.to_string())
            );
            if !e.traceback.is_empty() {
                for line in terminal_text(e.traceback.trim_end()).lines() {
                    let _ = writeln!(s, "    {line}");
                }
            }
        }
        if let Some(f) = &self.start_failure {
            let _ = writeln!(
                s,
                "the candidate could not be started: {}",
                terminal_line(f)
            );
        }
        let _ = writeln!(
            s,
            "\n{:<10} {:>7} {:>7} {:>7} {:>7} {:>8} {:>7} {:>10} {:>5}",
            "shape",
            "total",
            "passed",
            "failed",
            "errors",
            "timeouts",
            "not_run",
            "ambiguous",
            "any"
        );
        let row = |s: &mut String, name: &str, c: &Counts| {
            let _ = writeln!(
                s,
                "{:<10} {:>7} {:>7} {:>7} {:>7} {:>8} {:>7} {:>10} {:>5}",
                name,
                c.total,
                c.passed,
                c.failed,
                c.errors,
                c.timeouts,
                c.not_run,
                c.ambiguous,
                c.any
            );
        };
        for (kind, c) in &self.by_shape {
            row(&mut s, kind.name(), c);
        }
        row(&mut s, "all", &self.counts);
        let _ = writeln!(
            s,
            "\nverdict: {} ({} of {} definite vectors passed{})",
            if self.passed() { "PASS" } else { "FAIL" },
            self.counts.passed,
            self.counts.total,
            if self.counts.not_run > 0 {
                format!(", {} not run", self.counts.not_run)
            } else {
                String::new()
            }
        );
        for k in self.required_not_run() {
            let _ = writeln!(
                s,
                "required: {k}s (--require {k}), but {} {k} vectors were not run (why: below)",
                self.by_shape[&k].not_run
            );
        }
        if let Some(w) = self.triangle_winding {
            let _ = writeln!(s, "triangles: your triangles face {}", w.formula());
        }
        for d in &self.diagnosis {
            let _ = writeln!(s, "diagnosis: {}", d.sentence());
        }
        if self.restarts > 0 {
            let _ = writeln!(s, "the candidate was restarted {} times", self.restarts);
        }
        if let Some(note) = self.sandbox.as_ref().and_then(|f| f.note.as_ref()) {
            let _ = writeln!(s, "sandbox: {}", terminal_line(note));
        }
        // Vectors not run: one line per shape and reason.
        for n in &self.not_run_summary {
            let _ = writeln!(
                s,
                "not run: {} {} vectors: {}",
                n.count,
                n.shape,
                terminal_line(&n.reason)
            );
        }
        let shown = &self.failures;
        if shown.is_empty() {
        } else if shown.len() > 1
            && shown
                .iter()
                .all(|f| f.kind == shown[0].kind && f.message == shown[0].message)
        {
            // One cause for all (an import error): said once, with one example.
            let f = &shown[0];
            let _ = writeln!(
                s,
                "\nall {} failures are the same: [{}] {}",
                shown.len(),
                f.kind.name(),
                terminal_line(&f.message)
            );
            if max_failures > 0 && self.import_error.is_none() {
                let _ = writeln!(s, "for example {} ({}):", terminal_line(&f.id), f.shape);
                self.write_case(&mut s, f);
            }
        } else {
            let _ = writeln!(
                s,
                "\nfirst {} of {} failures:",
                shown.len().min(max_failures),
                shown.len()
            );
            for f in shown.iter().take(max_failures) {
                self.write_failure(&mut s, f);
            }
        }
        let tail = self.stderr_tail.trim_end();
        if !tail.is_empty() {
            let _ = writeln!(s, "\nend of the candidate's stderr:");
            for line in tail
                .lines()
                .rev()
                .take(20)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
            {
                let _ = writeln!(s, "    {}", terminal_line(line));
            }
        }
        s
    }

    fn write_failure(&self, s: &mut String, f: &Failure) {
        let _ = writeln!(
            s,
            "\n[{}] {} ({}): {}",
            f.kind.name(),
            terminal_line(&f.id),
            f.shape,
            terminal_line(&f.message)
        );
        self.write_case(s, f);
    }

    /// A failure's tags and how to reproduce it.
    fn write_case(&self, s: &mut String, f: &Failure) {
        if !f.tags.is_empty() {
            let _ = writeln!(s, "  tags: {}", terminal_line(&f.tags.join(", ")));
        }
        if f.repro.is_empty() {
            let _ = writeln!(s, "  request: {}", terminal_line(&f.request));
            let _ = writeln!(s, "  expected: {}", f.expected_text);
        } else {
            let _ = writeln!(s, "  reproduce (run in the submission folder):");
            for line in f.repro.lines() {
                let _ = writeln!(s, "    {}", terminal_line(line));
            }
        }
    }
}

/// A float as a Python literal that reads back to the same bits.
fn py(x: f64) -> String {
    if x.is_nan() {
        "float('nan')".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "float('inf')".into()
        } else {
            "float('-inf')".into()
        }
    } else {
        format!("{x:?}")
    }
}

fn py3(v: [f64; 3]) -> String {
    format!("Vec3({}, {}, {})", py(v[0]), py(v[1]), py(v[2]))
}

/// A Python snippet that reproduces `case` against the course's API: builds the object with
/// the course's constructor, calls `intersect` and prints what it got and what it should get.
pub fn python_repro(case: &Case) -> String {
    let (class_name, ctor) = match case.shape {
        ShapeSpec::Sphere { center, radius } => (
            "Sphere",
            format!("Sphere({}, {}, None)", py3(center), py(radius)),
        ),
        ShapeSpec::Quad { q, u, v } => (
            "Quad",
            format!("Quad({}, {}, {}, None)", py3(q), py3(u), py3(v)),
        ),
        ShapeSpec::Triangle { a, b, c } => (
            "Triangle",
            format!("Triangle({}, {}, {})", py3(a), py3(b), py3(c)),
        ),
    };
    let expected = expected_as(
        &case.expect,
        &Dialect {
            number: py,
            boolean: |b| if b { "True" } else { "False" },
            miss: "a miss (None)",
            normal_note: "",
        },
    );
    format!(
        "from RT_utility import Vec3, Interval\n\
         from RT_ray import Ray\n\
         from RT_object import {class_name}\n\
         obj = {ctor}\n\
         ray = Ray({}, {})\n\
         hit = obj.intersect(ray, Interval({}, {}))\n\
         print(None if hit is None else (hit.getT(), hit.getNormal().e, hit.front_face))\n\
         # expected: {expected}\n",
        py3(case.ray.origin),
        py3(case.ray.direction),
        py(case.interval[0]),
        py(case.interval[1]),
    )
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

    #[test]
    fn one_error_on_every_case_is_said_once_and_candidate_text_is_escaped() {
        let cases = crate::candidate::test_cases::basic_cases();
        let error = Answer::error("SyntaxError", "bad\x1b[31m input");
        let outcomes: Vec<Outcome> = cases
            .iter()
            .map(|_| Outcome::Answered {
                answer: error.clone(),
                junk: vec![],
            })
            .collect();
        let info = RunInfo {
            candidate: "evil\nverdict: PASS".into(),
            course_api: true,
            ..RunInfo::default()
        };
        let text = build_report(&cases, &outcomes, info).to_text(10);
        assert_eq!(text.matches("raised SyntaxError").count(), 1, "{text}");
        assert_eq!(text.matches("reproduce").count(), 1, "{text}");
        assert!(text.contains(&format!("all {} failures are the same", cases.len())));
        assert!(
            !text.contains('\x1b') && text.contains("\\x1b[31m"),
            "{text}"
        );
        assert!(!text.contains("\nverdict: PASS"), "{text}");
    }

    #[test]
    fn python_literals_read_back_exactly() {
        assert_eq!(py(0.1), "0.1");
        assert_eq!(py(4.0), "4.0");
        assert_eq!(py(f64::MAX), "1.7976931348623157e308");
        assert_eq!(py(1e-6), "1e-6");
        assert_eq!(py(f64::NEG_INFINITY), "float('-inf')");
    }
}
