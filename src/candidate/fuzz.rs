//! Differential fuzzing: random definite cases (see [`super::generate`]) run through a
//! candidate in rounds; each distinct failure (shape group and kind) is shrunk to a small case.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use serde::Serialize;

use super::check::{FailureKind, Verdict, decide_winding, judge_wound};
use super::generate::random_cases_with;
use super::process::{HarnessError, Outcome};
use super::report::python_repro;
use crate::oracle::Judging;
use crate::oracle::vectors::{Case, ShapeKind};

/// A candidate as the fuzzer sees it: a batch of cases in, one outcome per case out.
pub type RunBatch<'a> = dyn FnMut(&[Case]) -> Result<Vec<Outcome>, HarnessError> + 'a;

/// What a fuzz run does.
#[derive(Clone, Debug)]
pub struct FuzzOptions {
    /// Stop after this many cases.
    pub cases: usize,
    /// The seed of the generator.
    pub seed: u64,
    /// Stop after this much time (checked between rounds).
    pub time: Option<Duration>,
    /// Cases per round (one batch through the candidate).
    pub round: usize,
    /// The shape groups to fuzz.
    pub kinds: Vec<ShapeKind>,
    /// Largest number of cases tried while shrinking one failure.
    pub shrink_budget: usize,
    /// The profile and precision the cases are classified by.
    pub judging: Judging,
}

impl Default for FuzzOptions {
    fn default() -> Self {
        FuzzOptions {
            cases: 10_000,
            seed: 0,
            time: None,
            round: 1000,
            kinds: ShapeKind::ALL.to_vec(),
            shrink_budget: 2000,
            judging: Judging::COURSE,
        }
    }
}

/// One failure, as found and as shrunk.
#[derive(Clone, Debug, Serialize)]
pub struct FuzzFailure {
    /// What kind of failure.
    pub kind: FailureKind,
    /// The message for the minimal case.
    pub message: String,
    /// The random case that failed first.
    pub original: Case,
    /// The minimal case that still fails the same way.
    pub minimal: Case,
    /// A Python snippet reproducing the minimal case with the course's API.
    pub repro: String,
}

/// The result of a fuzz run.
#[derive(Clone, Debug, Serialize)]
pub struct FuzzReport {
    /// Cases run (not counting shrinking).
    pub cases_run: usize,
    /// Cases that failed.
    pub failed: usize,
    /// One shrunk failure per shape group and kind, in the order found.
    pub failures: Vec<FuzzFailure>,
}

impl FuzzReport {
    /// A text rendering with every reproduction.
    pub fn to_text(&self) -> String {
        let mut s = format!(
            "{} random definite cases run, {} failed\n",
            self.cases_run, self.failed
        );
        for f in &self.failures {
            s.push_str(&format!(
                "\n[{}] {} ({}): {}\n  minimal case (vector line):\n    {}\n  reproduce (run in the submission folder):\n",
                f.kind.name(),
                f.minimal.id,
                f.minimal.shape.kind(),
                f.message,
                f.minimal.to_json_line()
            ));
            for line in f.repro.lines() {
                s.push_str(&format!("    {line}\n"));
            }
        }
        s
    }
}

/// Runs the fuzzer with `run` as the candidate (a batch of cases in, one outcome per case out).
pub fn fuzz(run: &mut RunBatch<'_>, options: &FuzzOptions) -> Result<FuzzReport, HarnessError> {
    let start = Instant::now();
    let mut report = FuzzReport {
        cases_run: 0,
        failed: 0,
        failures: Vec::new(),
    };
    let mut found: Vec<(Case, FailureKind)> = Vec::new();
    let mut seen: BTreeSet<(ShapeKind, FailureKind)> = BTreeSet::new();
    let mut stream = 0u64;
    // Students' triangles are judged by their own winding, decided on the first round that hits.
    let mut winding = None;
    while report.cases_run < options.cases {
        if options.time.is_some_and(|t| start.elapsed() >= t) {
            break;
        }
        let n = options.round.min(options.cases - report.cases_run);
        let cases = random_cases_with(options.seed, stream, n, &options.kinds, options.judging);
        stream += 1;
        if cases.is_empty() {
            break;
        }
        let outcomes = run(&cases)?;
        report.cases_run += cases.len();
        winding = winding.or_else(|| decide_winding(&cases, &outcomes));
        for (case, outcome) in cases.iter().zip(&outcomes) {
            if let Verdict::Fail { kind, .. } = judge_wound(case, outcome, winding) {
                if kind == FailureKind::NotRun {
                    continue;
                }
                report.failed += 1;
                if seen.insert((case.shape.kind(), kind)) {
                    found.push((case.clone(), kind));
                }
            }
        }
    }
    for (case, kind) in found {
        // Timeouts and deaths cost a restart per try: keep them as found.
        let keep =
            kind == FailureKind::Timeout || (kind == FailureKind::Error && !is_raised(&case, run));
        let minimal = if keep {
            case.clone()
        } else {
            let mut fails = |batch: &[Case]| -> Vec<Option<FailureKind>> {
                match run(batch) {
                    Ok(outcomes) => batch
                        .iter()
                        .zip(&outcomes)
                        .map(|(c, o)| match judge_wound(c, o, winding) {
                            Verdict::Fail { kind, .. } => Some(kind),
                            _ => None,
                        })
                        .collect(),
                    Err(_) => vec![None; batch.len()],
                }
            };
            super::shrink::shrink_with(
                &case,
                kind,
                &mut fails,
                options.shrink_budget,
                options.judging,
            )
        };
        let message = match run(std::slice::from_ref(&minimal))?
            .first()
            .map(|o| judge_wound(&minimal, o, winding))
        {
            Some(Verdict::Fail { message, .. }) => message,
            _ => "failed when first run".into(),
        };
        report.failures.push(FuzzFailure {
            kind,
            message,
            repro: python_repro(&minimal),
            original: case,
            minimal,
        });
    }
    Ok(report)
}

/// Whether an `error` failure is a raised error (cheap to shrink) rather than a dead process.
fn is_raised(case: &Case, run: &mut RunBatch<'_>) -> bool {
    matches!(
        run(std::slice::from_ref(case)).ok().as_deref(),
        Some([Outcome::Answered { answer, .. }]) if answer.error.is_some()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::protocol::Answer;
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
            cases: 3000,
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
    }
}
