//! Differential fuzzing: random definite cases (see [`crate::candidate::fuzzing::generate`]) run through a
//! candidate in rounds until a number of cases or a time is reached (whichever first); each
//! distinct failure, by shape group and [`FuzzKind`] (a hit/miss flip either way, t, normal,
//! front_face, a raised error, a dead process, a timeout, a protocol error), is shrunk to a
//! small case that still fails the same way.
//!
//! Time: with a limit `T` ([`FuzzOptions::time`]) the search stops at the first round boundary
//! past `T` ([`FuzzOptions::round`] cases a round), and shrinking what it found gets a tenth of
//! `T` more (at least 0.2 s, at most [`SHRINK_TIME`]), so `--time 6` ends by about 6.6 s.
//! Without a limit, shrinking gets at most [`SHRINK_TIME`] in all.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::candidate::fuzzing::generate::random_cases_with;
use crate::candidate::judging::check::{
    FailureKind, Verdict, Winding, decide_winding, judge_wound,
};
use crate::candidate::judging::diagnose::{Diagnosis, SAMPLE, diagnose};
use crate::candidate::judging::repro::{expected_in_words, python_repro};
use crate::candidate::process::error::HarnessError;
use crate::candidate::process::outcome::Outcome;
use crate::oracle::profile::Judging;
use crate::oracle::vectors::{Case, Class, ShapeKind};

/// A candidate as the fuzzer sees it: a batch of cases in, one outcome per case out.
pub type RunBatch<'a> = dyn FnMut(&[Case]) -> Result<Vec<Outcome>, HarnessError> + 'a;

/// Longest time spent shrinking, over all the failures of one run.
pub const SHRINK_TIME: Duration = Duration::from_secs(5);

/// What a fuzz run does.
#[derive(Clone, Debug)]
pub struct FuzzOptions {
    /// Stop after this many cases (`None`: only the time bounds the run).
    pub cases: Option<usize>,
    /// The seed of the generator.
    pub seed: u64,
    /// Stop after this much time (checked between rounds; `None`: only `cases` bounds the run).
    pub time: Option<Duration>,
    /// Cases per round (one batch through the candidate).
    pub round: usize,
    /// The shape groups to fuzz.
    pub kinds: Vec<ShapeKind>,
    /// Largest number of cases tried while shrinking one failure.
    pub shrink_budget: usize,
    /// The profile and precision the cases are classified by.
    pub judging: Judging,
    /// Whether reproductions are written in the course's Python (the course adapter).
    pub course_api: bool,
}

impl Default for FuzzOptions {
    fn default() -> Self {
        FuzzOptions {
            cases: Some(10_000),
            seed: 0,
            time: None,
            round: 1000,
            kinds: ShapeKind::ALL.to_vec(),
            shrink_budget: 2000,
            judging: Judging::COURSE,
            course_api: true,
        }
    }
}

/// How a case failed, finer than [`FailureKind`]: each kind of wrong answer is its own, so a
/// hit/miss flip is not hidden behind a t mismatch of the same shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FuzzKind {
    /// A definite hit answered with a miss.
    MissedHit,
    /// A definite miss answered with a hit.
    FalseHit,
    /// A hit with t beyond the tolerance.
    T,
    /// A hit with a wrong normal.
    Normal,
    /// A hit with the wrong `front_face`.
    FrontFace,
    /// Another mismatch.
    OtherMismatch,
    /// The candidate raised an error.
    Error,
    /// The candidate's process died.
    Crash,
    /// No answer within the timeout.
    Timeout,
    /// A line that is not a valid answer.
    Protocol,
}

impl FuzzKind {
    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            FuzzKind::MissedHit => "missed hit",
            FuzzKind::FalseHit => "false hit",
            FuzzKind::T => "t",
            FuzzKind::Normal => "normal",
            FuzzKind::FrontFace => "front_face",
            FuzzKind::OtherMismatch => "mismatch",
            FuzzKind::Error => "error",
            FuzzKind::Crash => "crash",
            FuzzKind::Timeout => "timeout",
            FuzzKind::Protocol => "protocol",
        }
    }

    /// How `outcome` fails `case` (`None` when it passes, is not scored or was not run).
    pub fn of(case: &Case, outcome: &Outcome) -> Option<FuzzKind> {
        Self::of_wound(case, outcome, None)
    }

    /// [`FuzzKind::of`], judging triangles' `front_face` by the candidate's own `winding`.
    pub fn of_wound(case: &Case, outcome: &Outcome, winding: Option<Winding>) -> Option<FuzzKind> {
        let Verdict::Fail { kind, message } = judge_wound(case, outcome, winding) else {
            return None;
        };
        Some(match kind {
            FailureKind::NotRun => return None,
            FailureKind::Timeout => FuzzKind::Timeout,
            FailureKind::Protocol => FuzzKind::Protocol,
            FailureKind::Error => match outcome {
                Outcome::Answered { .. } => FuzzKind::Error,
                _ => FuzzKind::Crash,
            },
            FailureKind::Mismatch => {
                let hit =
                    matches!(outcome, Outcome::Answered { answer, .. } if answer.hit == Some(true));
                match (case.expect.class, hit) {
                    (Class::Hit, false) => FuzzKind::MissedHit,
                    (Class::Miss, true) => FuzzKind::FalseHit,
                    // The judge checks t, then the normal, then front_face; its message names
                    // the first that is wrong.
                    _ if message.starts_with("t = ") => FuzzKind::T,
                    _ if message.starts_with("normal = ") => FuzzKind::Normal,
                    _ if message.starts_with("front_face = ") => FuzzKind::FrontFace,
                    _ => FuzzKind::OtherMismatch,
                }
            }
        })
    }
}

/// One failure, as found and as shrunk.
#[derive(Clone, Debug, Serialize)]
pub struct FuzzFailure {
    /// What kind of failure, as the check report counts it.
    pub kind: FailureKind,
    /// What kind of failure, finely.
    pub detail: FuzzKind,
    /// The message for the minimal case.
    pub message: String,
    /// The random case that failed first.
    pub original: Case,
    /// The smallest case found that still fails the same way: the original when it was not
    /// shrunk ([`FuzzFailure::shrinking`] says whether and why not).
    pub minimal: Case,
    /// What shrinking did.
    pub shrinking: Shrinking,
    /// The minimal case's expected answer in words.
    pub expected_text: String,
    /// A Python snippet reproducing the minimal case with the course's API (course adapter
    /// only; empty otherwise: the minimal case's vector line is the reproduction).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub repro: String,
}

/// What shrinking did to a failure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shrinking {
    /// A smaller case fails the same way.
    Shrunk,
    /// The shrinker tried and found no smaller case failing the same way.
    NothingSmaller,
    /// Not tried: a time-out or a crash costs a restart per try, so it is kept as found.
    KeptAsFound,
    /// Not tried (or not finished): the time for shrinking was used up.
    OutOfTime,
}

impl Shrinking {
    /// How the report introduces the case.
    pub fn label(self) -> &'static str {
        match self {
            Shrinking::Shrunk => "minimal case",
            Shrinking::NothingSmaller => {
                "case as found (the shrinker found no smaller one failing the same way)"
            }
            Shrinking::KeptAsFound => {
                "case as found (not shrunk: a time-out or crash costs a restart per try)"
            }
            Shrinking::OutOfTime => "case as found (not shrunk: the time for shrinking ran out)",
        }
    }
}

/// The result of a fuzz run.
#[derive(Clone, Debug, Serialize)]
pub struct FuzzReport {
    /// What the cases were classified by (`"course/f64"`, ...; see [`Judging`]).
    pub judged_by: String,
    /// Cases run (not counting shrinking).
    pub cases_run: usize,
    /// Cases that failed.
    pub failed: usize,
    /// Seconds spent on the search (shrinking not included).
    pub search_seconds: f64,
    /// How many failed, per shape and kind (every kind met, shown or not).
    pub by_kind: Vec<KindCount>,
    /// One shrunk failure per shape group and kind, in the order found.
    pub failures: Vec<FuzzFailure>,
    /// The known mistakes that explain the failures, per shape group ([`crate::candidate::judging::diagnose`], on
    /// the failing cases and a sample of the passing ones).
    pub diagnosis: Vec<Diagnosis>,
    /// What the harness noticed about the candidate's use of the protocol (filled in by the
    /// caller from [`Session::notes`](crate::candidate::process::session::Session::notes)).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

/// How many cases of one shape failed one way.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct KindCount {
    /// The shape group.
    pub shape: ShapeKind,
    /// The kind of failure.
    pub kind: FuzzKind,
    /// How many cases.
    pub count: usize,
}

impl FuzzReport {
    /// A text rendering with every reproduction (candidate text escaped for the terminal).
    pub fn to_text(&self) -> String {
        use crate::escape::terminal_line;
        let mut s = format!("judged by: {}\n", self.judged_by);
        for note in &self.notes {
            s.push_str(&format!("note: {}\n", terminal_line(note)));
        }
        s.push_str(&format!(
            "{} random definite cases run in {:.1} s, {} failed\n",
            self.cases_run, self.search_seconds, self.failed
        ));
        for k in &self.by_kind {
            s.push_str(&format!(
                "  {} {}: {} failed\n",
                k.shape,
                k.kind.name(),
                k.count
            ));
        }
        for d in &self.diagnosis {
            s.push_str(&format!("diagnosis: {}\n", d.sentence()));
        }
        for f in &self.failures {
            s.push_str(&format!(
                "\n[{}] {} ({}): {}\n  {} (vector line):\n    {}\n  expected: {}\n",
                f.detail.name(),
                terminal_line(&f.minimal.id),
                f.minimal.shape.kind(),
                terminal_line(&f.message),
                f.shrinking.label(),
                f.minimal.to_json_line(),
                f.expected_text
            ));
            if !f.repro.is_empty() {
                s.push_str("  reproduce (run in the submission folder):\n");
                for line in f.repro.lines() {
                    s.push_str(&format!("    {line}\n"));
                }
            }
        }
        s
    }
}

/// A failure found by the search, before shrinking: the case, how it failed (finely and as
/// the check report counts it).
type Found = (Case, FuzzKind, FailureKind);

/// Most failing cases of a shape kept for the diagnosis.
const DIAGNOSIS_FAILURES: usize = 500;

/// What the diagnosis is made from: the first [`DIAGNOSIS_FAILURES`] failing cases of each
/// shape and the first [`SAMPLE`] passing ones, with their outcomes.
#[derive(Default)]
struct Evidence {
    cases: Vec<Case>,
    outcomes: Vec<Outcome>,
    /// Failing and passing cases kept, per shape.
    kept: std::collections::BTreeMap<ShapeKind, (usize, usize)>,
}

impl Evidence {
    fn keep(&mut self, case: &Case, outcome: &Outcome, failed: bool) {
        let (failing, passing) = self.kept.entry(case.shape.kind()).or_default();
        let room = if failed {
            failing
        } else if matches!(outcome, Outcome::Answered { .. }) {
            passing
        } else {
            return;
        };
        let cap = if failed { DIAGNOSIS_FAILURES } else { SAMPLE };
        if *room < cap {
            *room += 1;
            self.cases.push(case.clone());
            self.outcomes.push(outcome.clone());
        }
    }
}

/// Runs the fuzzer with `run` as the candidate (a batch of cases in, one outcome per case out).
pub fn fuzz(run: &mut RunBatch<'_>, options: &FuzzOptions) -> Result<FuzzReport, HarnessError> {
    let start = Instant::now();
    let mut report = FuzzReport {
        judged_by: options.judging.to_string(),
        cases_run: 0,
        failed: 0,
        search_seconds: 0.0,
        by_kind: Vec::new(),
        failures: Vec::new(),
        diagnosis: Vec::new(),
        notes: Vec::new(),
    };
    let mut evidence = Evidence::default();
    let (found, winding) = search(run, options, &mut report, &mut evidence, start)?;
    report.search_seconds = start.elapsed().as_secs_f64();
    report.diagnosis = diagnose(&evidence.cases, &evidence.outcomes, winding);
    // With a time limit T, shrinking gets a tenth of it more (at least 0.2 s, at most
    // SHRINK_TIME), so `--time 6` ends by about 6.6 s; without one, SHRINK_TIME.
    let shrink_time = match options.time {
        Some(t) => (t / 10).clamp(Duration::from_millis(200), SHRINK_TIME),
        None => SHRINK_TIME,
    };
    let shrink_until = Instant::now() + shrink_time;
    for (case, detail, kind) in found {
        let failure = shrunk(run, options, case, detail, kind, winding, shrink_until)?;
        report.failures.push(failure);
    }
    Ok(report)
}

/// The search: rounds of random cases until the case count or the time is reached, counting
/// failures into `report`; returns the first failure of each shape and kind, and the winding
/// of the candidate's triangles.
fn search(
    run: &mut RunBatch<'_>,
    options: &FuzzOptions,
    report: &mut FuzzReport,
    evidence: &mut Evidence,
    start: Instant,
) -> Result<(Vec<Found>, Option<Winding>), HarnessError> {
    let mut found: Vec<Found> = Vec::new();
    let mut seen: BTreeSet<(ShapeKind, FuzzKind)> = BTreeSet::new();
    let mut stream = 0u64;
    // Students' triangles are judged by their own winding, decided on the first round that hits.
    let mut winding = None;
    loop {
        let left = match options.cases {
            Some(n) => n.saturating_sub(report.cases_run),
            None => usize::MAX,
        };
        // At least one round, however short the time.
        let out_of_time =
            report.cases_run > 0 && options.time.is_some_and(|t| start.elapsed() >= t);
        if left == 0 || out_of_time {
            break;
        }
        let n = options.round.max(1).min(left);
        let cases = random_cases_with(options.seed, stream, n, &options.kinds, options.judging);
        stream += 1;
        if cases.is_empty() {
            break;
        }
        let outcomes = run(&cases)?;
        // Nothing can run any more (every group used up its timeouts or crashes): stop.
        if outcomes
            .iter()
            .all(|o| matches!(o, Outcome::NotRun { .. } | Outcome::Unsupported { .. }))
        {
            break;
        }
        report.cases_run += cases.len();
        winding = winding.or_else(|| decide_winding(&cases, &outcomes));
        for (case, outcome) in cases.iter().zip(&outcomes) {
            let detail = FuzzKind::of_wound(case, outcome, winding);
            evidence.keep(case, outcome, detail.is_some());
            let Some(detail) = detail else {
                continue;
            };
            report.failed += 1;
            let shape = case.shape.kind();
            match report
                .by_kind
                .iter_mut()
                .find(|k| k.shape == shape && k.kind == detail)
            {
                Some(k) => k.count += 1,
                None => report.by_kind.push(KindCount {
                    shape,
                    kind: detail,
                    count: 1,
                }),
            }
            if seen.insert((shape, detail)) {
                let kind = match judge_wound(case, outcome, winding) {
                    Verdict::Fail { kind, .. } => kind,
                    _ => FailureKind::Mismatch,
                };
                found.push((case.clone(), detail, kind));
            }
        }
    }
    Ok((found, winding))
}

/// One failure found, shrunk until `shrink_until` (timeouts and crashes are kept as found:
/// each try would cost a restart), with the message of its minimal case run once more.
fn shrunk(
    run: &mut RunBatch<'_>,
    options: &FuzzOptions,
    case: Case,
    detail: FuzzKind,
    kind: FailureKind,
    winding: Option<Winding>,
    shrink_until: Instant,
) -> Result<FuzzFailure, HarnessError> {
    let keep = matches!(detail, FuzzKind::Timeout | FuzzKind::Crash);
    let mut shrinking = if keep {
        Shrinking::KeptAsFound
    } else if Instant::now() >= shrink_until {
        Shrinking::OutOfTime
    } else {
        Shrinking::Shrunk
    };
    let minimal = if shrinking != Shrinking::Shrunk {
        case.clone()
    } else {
        let mut fails = |batch: &[Case]| -> Vec<Option<FuzzKind>> {
            if Instant::now() >= shrink_until {
                return vec![None; batch.len()];
            }
            match run(batch) {
                Ok(outcomes) => batch
                    .iter()
                    .zip(&outcomes)
                    .map(|(c, o)| FuzzKind::of_wound(c, o, winding))
                    .collect(),
                Err(_) => vec![None; batch.len()],
            }
        };
        let minimal = crate::candidate::fuzzing::shrink::shrink_with(
            &case,
            detail,
            &mut fails,
            options.shrink_budget,
            options.judging,
        );
        if minimal == case {
            shrinking = if Instant::now() >= shrink_until {
                Shrinking::OutOfTime
            } else {
                Shrinking::NothingSmaller
            };
        }
        minimal
    };
    let message = match run(std::slice::from_ref(&minimal))?
        .first()
        .map(|o| judge_wound(&minimal, o, winding))
    {
        Some(Verdict::Fail { message, .. }) => message,
        _ => "failed when first run".into(),
    };
    Ok(FuzzFailure {
        kind,
        detail,
        message,
        expected_text: expected_in_words(&minimal.expect),
        repro: if options.course_api {
            python_repro(&minimal)
        } else {
            String::new()
        },
        original: case,
        minimal,
        shrinking,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::process::protocol::Answer;
    use crate::candidate::rust::{Candidate, Reference, run_candidate};
    use crate::oracle::vectors::{RaySpec, ShapeSpec};

    /// Forgets to flip the normal of a sphere hit from inside.
    struct NoFlip;
    impl Candidate for NoFlip {
        fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer {
            let mut a = Reference.intersect(shape, ray, interval);
            if let (ShapeSpec::Sphere { .. }, Some(false)) = (shape, a.front_face) {
                a.normal = a.normal.map(|n| n.map(|x| -x));
            }
            a
        }
    }

    #[test]
    fn the_reference_survives_and_a_bug_is_found_and_shrunk() {
        let options = FuzzOptions {
            cases: Some(3000),
            seed: 1,
            ..FuzzOptions::default()
        };
        let mut reference = |c: &[Case]| Ok(run_candidate(&mut Reference, c));
        let clean = fuzz(&mut reference, &options).unwrap();
        assert_eq!((clean.cases_run, clean.failed), (3000, 0));

        let mut buggy = |c: &[Case]| Ok(run_candidate(&mut NoFlip, c));
        let report = fuzz(&mut buggy, &options).unwrap();
        assert!(report.failed > 0);
        assert_eq!(report.failures.len(), 1, "{}", report.to_text());
        let f = &report.failures[0];
        assert_eq!(f.kind, FailureKind::Mismatch);
        assert_eq!(f.minimal.expect.front_face, Some(false));
        assert!(f.message.contains("normal"), "{}", f.message);
        // The minimal case is no more complex than the original.
        let bits = |c: &Case| {
            let mut v = c.shape.numbers();
            v.extend(c.ray.origin);
            v.extend(c.ray.direction);
            v.iter().filter(|x| x.fract() != 0.0).count()
        };
        assert!(bits(&f.minimal) <= bits(&f.original));
        assert!(f.repro.contains("from RT_object import Sphere"));
        assert_eq!(f.detail, FuzzKind::Normal);
    }

    /// Misses every sphere hit from inside, and is off in t on quads seen from the front.
    struct TwoBugs;
    impl Candidate for TwoBugs {
        fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer {
            let mut a = Reference.intersect(shape, ray, interval);
            match (shape, a.front_face) {
                (ShapeSpec::Sphere { .. }, Some(false)) => Answer::miss(),
                (ShapeSpec::Quad { .. }, Some(true)) => {
                    a.t = a.t.map(|t| t * (1.0 + 1e-3) + 1e-3);
                    a
                }
                _ => a,
            }
        }
    }

    #[test]
    fn every_failing_kind_of_a_shape_is_shown_and_shrunk_apart() {
        let options = FuzzOptions {
            cases: Some(3000),
            seed: 2,
            course_api: false,
            ..FuzzOptions::default()
        };
        let mut buggy = |c: &[Case]| Ok(run_candidate(&mut TwoBugs, c));
        let report = fuzz(&mut buggy, &options).unwrap();
        let shown: BTreeSet<(ShapeKind, FuzzKind)> = report
            .failures
            .iter()
            .map(|f| (f.minimal.shape.kind(), f.detail))
            .collect();
        assert!(
            shown.contains(&(ShapeKind::Sphere, FuzzKind::MissedHit))
                && shown.contains(&(ShapeKind::Quad, FuzzKind::T)),
            "{}",
            report.to_text()
        );
        // Each shown failure still fails its own way, and the counts add up.
        for f in &report.failures {
            let o = run_candidate(&mut TwoBugs, std::slice::from_ref(&f.minimal));
            assert_eq!(FuzzKind::of(&f.minimal, &o[0]), Some(f.detail));
            assert!(f.repro.is_empty(), "no Python for a non-course candidate");
        }
        let counted: usize = report.by_kind.iter().map(|k| k.count).sum();
        assert_eq!(counted, report.failed);
    }

    #[test]
    fn a_time_limit_alone_runs_until_the_time_is_up() {
        let options = FuzzOptions {
            cases: None,
            time: Some(Duration::from_millis(300)),
            round: 200,
            ..FuzzOptions::default()
        };
        let start = Instant::now();
        let mut reference = |c: &[Case]| Ok(run_candidate(&mut Reference, c));
        let report = fuzz(&mut reference, &options).unwrap();
        assert!(start.elapsed() >= Duration::from_millis(300));
        // Far more than one round: the case count bounded nothing.
        assert!(report.cases_run > 400, "{}", report.cases_run);
        assert_eq!(report.cases_run % 200, 0);
        // Both bounds: whichever first.
        let options = FuzzOptions {
            cases: Some(300),
            ..options
        };
        assert_eq!(fuzz(&mut reference, &options).unwrap().cases_run, 300);
        // A candidate that can run nothing more ends the run at once, not at the time limit.
        let options = FuzzOptions {
            cases: None,
            time: Some(Duration::from_secs(30)),
            ..options
        };
        let mut exhausted = |c: &[Case]| {
            Ok(c.iter()
                .map(|_| Outcome::NotRun {
                    reason: "not run after 3 timeouts".into(),
                })
                .collect())
        };
        let start = Instant::now();
        let report = fuzz(&mut exhausted, &options).unwrap();
        assert!(start.elapsed() < Duration::from_secs(5));
        assert_eq!((report.cases_run, report.failed), (0, 0));
    }

    /// The report called every case "minimal", time-outs never shrunk included, and did not
    /// say what it judged by nor which mistake explains the failures.
    #[test]
    fn only_shrunk_cases_are_called_minimal_and_the_report_says_its_judging_and_diagnosis() {
        let options = FuzzOptions {
            cases: Some(2000),
            seed: 1,
            course_api: false,
            ..FuzzOptions::default()
        };
        // Times out on every sphere hit seen from outside, answers the rest as NoFlip does.
        let mut hangs = |c: &[Case]| {
            let mut outcomes = run_candidate(&mut NoFlip, c);
            for (case, o) in c.iter().zip(outcomes.iter_mut()) {
                let front = case.expect.front_face == Some(true);
                if matches!(case.shape, ShapeSpec::Sphere { .. }) && front {
                    *o = Outcome::Timeout { junk: vec![] };
                }
            }
            Ok(outcomes)
        };
        let report = fuzz(&mut hangs, &options).unwrap();
        let text = report.to_text();
        assert!(text.starts_with("judged by: course/f64\n"), "{text}");
        let timeout = report
            .failures
            .iter()
            .find(|f| f.detail == FuzzKind::Timeout)
            .expect("a time-out");
        assert_eq!(timeout.shrinking, Shrinking::KeptAsFound);
        assert_eq!(timeout.minimal, timeout.original);
        let normal = report
            .failures
            .iter()
            .find(|f| f.detail == FuzzKind::Normal)
            .expect("a wrong normal");
        assert_eq!(normal.shrinking, Shrinking::Shrunk);
        assert_ne!(normal.minimal, normal.original);
        assert_eq!(
            text.matches("minimal case (vector line)").count(),
            1,
            "{text}"
        );
        assert!(text.contains(
            "case as found (not shrunk: a time-out or crash costs a restart per try) (vector line)"
        ));
        // NoFlip's wrong normals are the catalogue's unflipped normal.
        assert_eq!(report.diagnosis.len(), 1, "{text}");
        assert_eq!(report.diagnosis[0].shape, ShapeKind::Sphere);
        assert!(text.contains("diagnosis: "), "{text}");
        let json = serde_json::to_value(&report).unwrap();
        assert_eq!(json["judged_by"], "course/f64");
        assert!(json["failures"][0]["shrinking"].is_string());
    }

    #[test]
    fn failure_kinds_are_told_apart() {
        let case = crate::candidate::test_cases::basic_cases().remove(0);
        let good = Answer::hit(4.0, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], true);
        let answered = |a: Answer| Outcome::Answered {
            answer: a,
            junk: vec![],
        };
        let with = |f: &dyn Fn(&mut Answer)| {
            let mut a = good.clone();
            f(&mut a);
            FuzzKind::of(&case, &answered(a))
        };
        assert_eq!(FuzzKind::of(&case, &answered(good.clone())), None);
        assert_eq!(with(&|a| a.t = Some(4.5)), Some(FuzzKind::T));
        assert_eq!(
            with(&|a| a.normal = Some([1.0, 0.0, 0.0])),
            Some(FuzzKind::Normal)
        );
        assert_eq!(
            with(&|a| a.front_face = Some(false)),
            Some(FuzzKind::FrontFace)
        );
        assert_eq!(
            FuzzKind::of(&case, &answered(Answer::miss())),
            Some(FuzzKind::MissedHit)
        );
        assert_eq!(
            FuzzKind::of(&case, &answered(Answer::error("E", "m"))),
            Some(FuzzKind::Error)
        );
        let died = Outcome::Died {
            message: "x".into(),
            junk: vec![],
        };
        assert_eq!(FuzzKind::of(&case, &died), Some(FuzzKind::Crash));
        let timeout = Outcome::Timeout { junk: vec![] };
        assert_eq!(FuzzKind::of(&case, &timeout), Some(FuzzKind::Timeout));
        let protocol = Outcome::Protocol {
            message: "x".into(),
            junk: vec![],
        };
        assert_eq!(FuzzKind::of(&case, &protocol), Some(FuzzKind::Protocol));
        let mut miss = case.clone();
        miss.expect.class = Class::Miss;
        assert_eq!(
            FuzzKind::of(&miss, &answered(good)),
            Some(FuzzKind::FalseHit)
        );
    }
}
