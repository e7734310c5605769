//! Running a week's function checks through a [`FunctionRunner`] and judging them: one
//! [`FunctionResult`] per function, with its counts, its smallest failing case and a Python
//! reproduction, the catalogued mistakes that fit its answers, and (for a sampler) its
//! statistics.

use std::collections::HashMap;

use serde::Serialize;

use super::checks::{Body, Case, FunctionCheck, Variant, week_checks};
use super::expect::Class;
use super::runner::{FunctionRunner, Reply};
use super::samplers::{Fit, Sample, SamplerCheck, Standing};
use super::stats::DEFAULT_ALPHA;
use super::week::Week;

/// How a week's function checks are run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FunctionOptions {
    /// Seeds the random cases and the samplers' requests (same seed, same requests).
    pub seed: u64,
    /// The false-alarm rate of each statistical test.
    pub alpha: f64,
}

impl Default for FunctionOptions {
    fn default() -> Self {
        FunctionOptions {
            seed: 0,
            alpha: DEFAULT_ALPHA,
        }
    }
}

/// A function's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every scored case (or the statistical check) passed.
    Passed,
    /// A scored case or the statistical check failed.
    Failed,
    /// Nothing was run (the candidate does not answer the request, or the budget ran out).
    NotRun,
}

/// Case counts of one function (a statistical check counts as one case).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CaseCounts {
    /// Scored cases answered right.
    pub passed: usize,
    /// Scored cases answered wrong, with an error, or not at all.
    pub failed: usize,
    /// Cases not scored (rounding decides, the course's code fails there, or the code cannot
    /// be steered).
    pub not_scored: usize,
    /// Cases not run.
    pub not_run: usize,
}

/// The first failing case of a function (its smallest: cases go from simple to random).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseFailure {
    /// The case's id.
    pub case: String,
    /// The input, in words.
    pub input: String,
    /// What was wrong, in words.
    pub problem: String,
    /// A Python reproduction.
    pub repro: String,
}

/// A catalogued mistake whose answers the function's fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NamedMistake {
    /// The catalogue's name.
    pub name: String,
    /// What it does wrong.
    pub says: String,
    /// Mistake, physical alternative or the course's other version.
    pub standing: Standing,
}

/// A statistical check's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Statistics {
    /// Samples judged.
    pub samples: usize,
    /// How they fit the course's hypothesis (invariant failures, the test).
    pub fit: Fit,
}

/// The result of one function.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FunctionResult {
    /// The check's id (`refract`).
    pub id: String,
    /// The function as the course names it.
    pub function: String,
    /// The week that introduces it (this version of it).
    pub week: Week,
    /// Whether that week's skeleton already holds it.
    pub given: bool,
    /// How answers are compared.
    pub tolerance: String,
    /// The verdict.
    pub status: Status,
    /// Case counts.
    pub counts: CaseCounts,
    /// The smallest failing case.
    pub failure: Option<CaseFailure>,
    /// The mistakes that fit (when it failed).
    pub mistakes: Vec<NamedMistake>,
    /// A statistical check's figures.
    pub statistics: Option<Statistics>,
    /// Things worth knowing (cases not scored and why, what could not be steered).
    pub notes: Vec<String>,
}

/// The function checks of a submission of one week.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeekReport {
    /// The submission's week.
    pub week: Week,
    /// The options it was run with.
    pub options: FunctionOptions,
    /// One result per function, by week then id.
    pub functions: Vec<FunctionResult>,
}

impl WeekReport {
    /// Whether every function that was run passed (`not_run` ones are not failures here; see
    /// [`WeekReport::not_run`]).
    pub fn passed(&self) -> bool {
        self.functions.iter().all(|f| f.status != Status::Failed)
    }

    /// The functions of the submission's own week.
    pub fn of_the_week(&self) -> impl Iterator<Item = &FunctionResult> {
        self.functions.iter().filter(move |f| f.week == self.week)
    }

    /// The functions that were not run.
    pub fn not_run(&self) -> impl Iterator<Item = &FunctionResult> {
        self.functions.iter().filter(|f| f.status == Status::NotRun)
    }
}

/// After this many timeouts in one function, its other requests are not sent.
pub const MAX_TIMEOUTS_PER_FUNCTION: usize = 2;

/// Runs the function checks of a week-`week` submission through `runner`.
pub fn run_week(
    runner: &mut dyn FunctionRunner,
    week: Week,
    options: FunctionOptions,
) -> WeekReport {
    let checks = week_checks(week, options.seed);
    let mut memo = HashMap::new();
    let functions = checks
        .iter()
        .map(|c| run_check(runner, c, options, &mut memo))
        .collect();
    let mut report = WeekReport {
        week,
        options,
        functions,
    };
    apply_departures(&mut report);
    report
}

/// The departures that rest on several functions' results ([`super::departures`]): a failing
/// function whose failure is one of them passes, with the departure named and noted.
fn apply_departures(report: &mut WeekReport) {
    let passed = |id: &str| {
        report
            .functions
            .iter()
            .any(|f| f.id == id && f.status == Status::Passed)
    };
    let (dielectric, choice) = (passed("dielectric"), passed("dielectric-choice"));
    for f in &mut report.functions {
        let fits: Vec<&str> = f.mistakes.iter().map(|m| m.name.as_str()).collect();
        let departure = match f.id.as_str() {
            "refract" if f.status == Status::Failed => {
                super::departures::schlick_in_material(&fits, dielectric, choice)
            }
            _ => None,
        };
        if let Some(d) = departure {
            let moved = f.counts.failed;
            f.counts.passed += moved;
            f.counts.failed = 0;
            f.status = Status::Passed;
            f.failure = None;
            f.mistakes = vec![NamedMistake {
                name: d.name.to_string(),
                says: d.says.to_string(),
                standing: Standing::Departure,
            }];
            f.notes.push(format!(
                "departure that keeps the course's behaviour: {} ({moved} case(s) answered as such)",
                d.says
            ));
        }
    }
}

/// Runs one check (answers to identical requests are reused from `memo`).
pub fn run_check(
    runner: &mut dyn FunctionRunner,
    check: &FunctionCheck,
    options: FunctionOptions,
    memo: &mut HashMap<String, Reply>,
) -> FunctionResult {
    let mut result = FunctionResult {
        id: check.id.to_string(),
        function: check.function.to_string(),
        week: check.week,
        given: check.given,
        tolerance: check.tolerance.to_string(),
        status: Status::NotRun,
        counts: CaseCounts::default(),
        failure: None,
        mistakes: Vec::new(),
        statistics: None,
        notes: Vec::new(),
    };
    let total = match &check.body {
        Body::Cases { cases, .. } => cases.len(),
        Body::Samples { .. } => 1,
    };
    if !runner.supports(check.op) {
        result.counts.not_run = total;
        result.notes.push(format!(
            "not run: the candidate's hello does not list \"{}\" among its ops",
            check.op
        ));
        return result;
    }
    let mut timeouts = 0;
    let mut ask = |request: &serde_json::Value, runner: &mut dyn FunctionRunner| -> Reply {
        if timeouts >= MAX_TIMEOUTS_PER_FUNCTION {
            return Reply::NotRun(format!(
                "not run after {MAX_TIMEOUTS_PER_FUNCTION} timeouts"
            ));
        }
        let key = request.to_string();
        if let Some(r) = memo.get(&key) {
            return r.clone();
        }
        let reply = runner.call(request, check.timeout);
        if reply == Reply::TimedOut {
            timeouts += 1;
        }
        memo.insert(key, reply.clone());
        reply
    };
    match &check.body {
        Body::Cases {
            cases,
            variants,
            normalise,
        } => {
            let replies: Vec<Reply> = cases
                .iter()
                .map(|c| {
                    let r = ask(&c.request, runner);
                    if let Reply::Result(v) = &r {
                        note_departures(&mut result, v);
                    }
                    match (r, normalise) {
                        (Reply::Result(v), Some(f)) => Reply::Result(f(v)),
                        (r, _) => r,
                    }
                })
                .collect();
            judge_cases(&mut result, cases, variants, &replies);
        }
        Body::Samples {
            requests,
            extract,
            check: sampler,
            repro,
        } => {
            let replies: Vec<Reply> = requests.iter().map(|r| ask(r, runner)).collect();
            for r in &replies {
                if let Reply::Result(v) = r {
                    note_departures(&mut result, v);
                }
            }
            judge_samples(
                &mut result,
                &replies,
                extract,
                sampler,
                repro,
                options.alpha,
            );
        }
    }
    result
}

/// Adds to `result`'s notes the departures `answer` lists (each once).
fn note_departures(result: &mut FunctionResult, answer: &serde_json::Value) {
    for note in super::departures::listed(answer) {
        if !result.notes.contains(&note) {
            result.notes.push(note);
        }
    }
}

/// Why a reply is not an answer, in words (`None` for an answer).
fn not_an_answer(reply: &Reply, timeout: &str) -> Option<String> {
    match reply {
        Reply::Result(_) => None,
        Reply::Error(e) => Some(match e.kind.as_str() {
            "BadReturn" if e.message.ends_with("returned None") => {
                format!("{} (is it still the skeleton's stub?)", e.message)
            }
            "NotFound" | "BadReturn" | "RandomExhausted" => e.message.clone(),
            _ => format!("raised {e}"),
        }),
        Reply::TimedOut => Some(format!("no answer within {timeout}")),
        Reply::Failed(why) | Reply::NotRun(why) => Some(why.clone()),
    }
}

/// The reason an answer could not be steered (its code drew nothing from the replaced random
/// function), when it could not.
fn unsteered(reply: &Reply) -> bool {
    matches!(reply, Reply::Result(v) if v.get("unsteered").is_some())
}

fn judge_cases(
    result: &mut FunctionResult,
    cases: &[Case],
    variants: &[Variant],
    replies: &[Reply],
) {
    let mut unsteered_count = 0;
    let mut ambiguous = 0;
    let mut course_fails = 0;
    let mut scored: Vec<usize> = Vec::new();
    for (k, (case, reply)) in cases.iter().zip(replies).enumerate() {
        if matches!(reply, Reply::NotRun(_)) {
            result.counts.not_run += 1;
            continue;
        }
        match &case.class {
            Class::Ambiguous(_) => {
                ambiguous += 1;
                result.counts.not_scored += 1;
                continue;
            }
            Class::CourseFails(_) => {
                course_fails += 1;
                result.counts.not_scored += 1;
                continue;
            }
            Class::Definite => {}
        }
        if unsteered(reply) {
            unsteered_count += 1;
            result.counts.not_scored += 1;
            continue;
        }
        scored.push(k);
        let problem = match reply {
            Reply::Result(v) => case.expect.judge(v).err(),
            other => not_an_answer(other, "the time allowed"),
        };
        match problem {
            None => result.counts.passed += 1,
            Some(problem) => {
                result.counts.failed += 1;
                if result.failure.is_none() {
                    result.failure = Some(CaseFailure {
                        case: case.id.clone(),
                        input: case.input.clone(),
                        problem,
                        repro: case.repro.clone(),
                    });
                }
            }
        }
    }
    if ambiguous > 0 {
        result.notes.push(format!(
            "{ambiguous} case(s) not scored: rounding decides a threshold there"
        ));
    }
    if course_fails > 0 {
        result.notes.push(format!(
            "{course_fails} case(s) not scored: the course's own code raises on them"
        ));
    }
    if unsteered_count > 0 {
        result.notes.push(format!(
            "{unsteered_count} case(s) not scored: the code does not call the course's random function the request replaces, so its answer cannot be fixed in advance (the statistical check of the same function judges it)"
        ));
    }
    result.status = if result.counts.failed > 0 {
        Status::Failed
    } else if result.counts.passed > 0 || result.counts.not_scored > 0 {
        Status::Passed
    } else {
        Status::NotRun
    };
    if result.status == Status::Failed {
        result.mistakes = fitting_variants(cases, variants, replies, &scored);
    }
}

/// The variants whose answers every scored case's answer fits (where the variant knows its
/// answer), differing from the course's on at least one.
fn fitting_variants(
    cases: &[Case],
    variants: &[Variant],
    replies: &[Reply],
    scored: &[usize],
) -> Vec<NamedMistake> {
    variants
        .iter()
        .filter(|v| {
            let mut differs = false;
            let fits = scored.iter().all(|&k| {
                // `None`: rounding decides what the mistake answers there (or its code raises
                // there): no constraint.
                let Some(e) = v.expect.get(k).and_then(Option::as_ref) else {
                    return true;
                };
                let Reply::Result(answer) = &replies[k] else {
                    return false;
                };
                if cases[k].expect.judge(answer).is_err() {
                    differs = true;
                }
                e.judge(answer).is_ok()
            });
            fits && differs
        })
        .map(|v| NamedMistake {
            name: v.name.to_string(),
            says: v.says.to_string(),
            standing: v.standing,
        })
        .collect()
}

fn judge_samples(
    result: &mut FunctionResult,
    replies: &[Reply],
    extract: &super::checks::Extract,
    check: &SamplerCheck,
    repro: &str,
    alpha: f64,
) {
    let mut samples: Vec<Sample> = Vec::new();
    for reply in replies {
        if let Reply::NotRun(why) = reply {
            result.counts.not_run = 1;
            result.notes.push(why.clone());
            return;
        }
        let problem = match reply {
            Reply::Result(v) => match extract(v) {
                Ok(s) => {
                    samples.extend(s);
                    None
                }
                Err(why) => Some(why),
            },
            other => not_an_answer(other, "the time allowed"),
        };
        if let Some(problem) = problem {
            result.status = Status::Failed;
            result.counts.failed = 1;
            result.failure = Some(CaseFailure {
                case: format!("{}-samples", result.id),
                input: "a request for samples".into(),
                problem,
                repro: repro.to_string(),
            });
            return;
        }
    }
    let verdict = check.judge(&samples, alpha);
    result.statistics = Some(Statistics {
        samples: verdict.samples,
        fit: verdict.fit.clone(),
    });
    if verdict.passed {
        result.status = Status::Passed;
        result.counts.passed = 1;
        return;
    }
    result.status = Status::Failed;
    result.counts.failed = 1;
    let problem = match (&verdict.fit.first_failure, &verdict.fit.test) {
        (Some((i, why)), _) => format!(
            "sample {i} of {}: {why} ({} of the samples break it)",
            verdict.samples, verdict.fit.invariant_failures
        ),
        (None, Some(t)) if t.test == "binomial" => format!(
            "the samples do not follow the course's: {}; {} of {} in the first outcome, p = {:.2e} < {:.0e} (exact binomial test)",
            check.course.says, t.statistic, t.dof, t.p_value, t.alpha
        ),
        (None, Some(t)) => format!(
            "the samples do not follow the course's: {}; chi-square {:.1} with {} degrees of freedom, p = {:.2e} < {:.0e}",
            check.course.says, t.statistic, t.dof, t.p_value, t.alpha
        ),
        (None, None) => "no samples".into(),
    };
    result.failure = Some(CaseFailure {
        case: format!("{}-samples", result.id),
        input: format!("{} samples", verdict.samples),
        problem,
        repro: repro.to_string(),
    });
    result.mistakes = verdict
        .named
        .iter()
        .filter_map(|(name, _)| check.mistake(name))
        .map(|m| NamedMistake {
            name: m.name.to_string(),
            says: m.says.clone(),
            standing: m.standing,
        })
        .collect();
}
