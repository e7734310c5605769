//! Running a week's function checks through a [`FunctionRunner`] and judging them: one
//! [`FunctionResult`] per function, with its counts, its smallest failing case and a Python
//! reproduction, the catalogued mistakes that fit its answers, and (for a sampler) its
//! statistics.
//!
//! Nothing an answer says about itself is believed (docs/sandbox.md, "What a submission
//! controls"): each op's `result` has a fixed set of keys, and any other (`"unsteered"`, a
//! misspelling) makes the case a protocol error, which fails it and is counted
//! ([`CaseCounts::protocol`]) for a person to look at. Whether a case was steered is the
//! request's doing ([`Body::Steered`]). A function earns its points only for scored cases it
//! answered right: one with none right fails, and its notes say why. A sampler must answer
//! exactly the samples each request asked for, each of the right arity and finite.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::checks::steer::Behaviour;
use super::checks::{Body, Case, FunctionCheck, Variant, week_checks};
use super::expect::Class;
use super::runner::{FunctionRunner, Reply, answer_keys};
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
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
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
    /// Cases answered with a protocol error (a malformed answer, a key its op's answer does not
    /// have, a wrong number of samples): counted among the failed, and flagged for a person to
    /// look at (a well-behaved adapter never makes one).
    pub protocol: usize,
}

/// The first failing case of a function (its smallest: cases go from simple to random).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NamedMistake {
    /// The catalogue's name.
    pub name: String,
    /// What it does wrong.
    pub says: String,
    /// Mistake, physical alternative or the course's other version.
    pub standing: Standing,
}

/// A statistical check's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Statistics {
    /// Samples judged.
    pub samples: usize,
    /// How they fit the course's hypothesis (invariant failures, the test).
    pub fit: Fit,
}

/// The result of one function.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Things worth knowing (cases not scored and why, cases judged by what the code does).
    pub notes: Vec<String>,
    /// Cases of a steered check whose answer was not the course's for the steered numbers but
    /// kept the function's invariant: right only when the statistical check of the same
    /// function passed ([`settle_steered`]).
    pub by_behaviour: usize,
    /// The statistical checks those cases wait for (their ids; empty but for a steered check).
    #[serde(skip)]
    pub partners: &'static [&'static str],
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

/// Runs the function checks of a week-`week` submission through `runner`. The checks' inputs
/// and every seed their requests carry are derived from `options.seed` for the purpose
/// `"functions"` ([`crate::secret::derive`]): the seed itself is never sent.
pub fn run_week(
    runner: &mut dyn FunctionRunner,
    week: Week,
    options: FunctionOptions,
) -> WeekReport {
    let checks = week_checks(week, crate::secret::derive(options.seed, "functions"));
    let mut memo = HashMap::new();
    let mut functions: Vec<FunctionResult> = checks
        .iter()
        .map(|c| run_check(runner, c, options, &mut memo))
        .collect();
    settle_steered(&mut functions);
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

/// Settles the cases of steered checks judged by what the code does ([`Body::Steered`]): they
/// were counted failed by [`run_check`]; they count as right where the statistical check they
/// wait for passed.
pub fn settle_steered(results: &mut [FunctionResult]) {
    let passed: Vec<(String, Status)> = results.iter().map(|r| (r.id.clone(), r.status)).collect();
    for r in results.iter_mut() {
        let n = r.by_behaviour;
        if n == 0 {
            continue;
        }
        let partner = r.partners.join(", ");
        let status_of = |id: &str| passed.iter().find(|(p, _)| p == id).map(|p| p.1);
        let all_passed = r
            .partners
            .iter()
            .all(|p| status_of(p) == Some(Status::Passed));
        let status = if all_passed {
            Some(Status::Passed)
        } else if r.partners.iter().all(|p| status_of(p).is_some()) {
            Some(Status::Failed)
        } else {
            None
        };
        if status == Some(Status::Passed) {
            r.counts.failed -= n;
            r.counts.passed += n;
            r.notes.push(format!(
                "{n} case(s) judged by what the code does: its answers are not the course's for the steered random numbers (it draws them otherwise than the course does), but keep the function's invariant, and {partner} passed, so they count as right"
            ));
            if r.counts.failed == 0 {
                r.failure = None;
                r.mistakes.clear();
            }
        } else {
            r.notes.push(format!(
                "{n} case(s) judged by what the code does: its answers are not the course's for the steered random numbers, and keep the function's invariant, but they count as right only when {partner} passes, which {}",
                if status.is_some() { "did not" } else { "was not run" }
            ));
        }
        r.status = decided(r);
    }
}

/// Runs one check (answers to identical requests are reused from `memo`). The cases of a
/// steered check judged by what the code does are counted failed here: [`settle_steered`]
/// (which [`run_week`] calls) turns them right when their statistical check passed.
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
        by_behaviour: 0,
        partners: &[],
    };
    let total = match &check.body {
        Body::Cases { cases, .. } | Body::Steered { cases, .. } => cases.len(),
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
    let allowed = allowed_keys(check);
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
        let reply = strict(runner.call(request, check.timeout), check.op, &allowed);
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
            judge_cases(&mut result, cases, variants, &replies, None);
        }
        Body::Steered {
            cases,
            variants,
            partners,
            behaviour,
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
            result.partners = partners;
            judge_cases(&mut result, cases, variants, &replies, Some(behaviour));
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
                (requests, &replies),
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

/// The keys a check's answers may hold: its op's ([`answer_keys`]) and every key its cases and
/// variants expect.
fn allowed_keys(check: &FunctionCheck) -> Vec<String> {
    let mut keys: Vec<String> = answer_keys(check.op)
        .iter()
        .map(|k| k.to_string())
        .collect();
    let mut add = |e: &super::expect::Expected| {
        for (k, _) in &e.fields {
            if !keys.contains(k) {
                keys.push(k.clone());
            }
        }
    };
    if let Body::Cases {
        cases, variants, ..
    }
    | Body::Steered {
        cases, variants, ..
    } = &check.body
    {
        cases.iter().for_each(|c| add(&c.expect));
        variants
            .iter()
            .flat_map(|v| v.expect.iter().flatten())
            .for_each(&mut add);
    }
    keys
}

/// `reply`, or a protocol error when its `result` is not an object, is empty, or holds a key
/// `allowed` does not name (the first such key, quoted).
fn strict(reply: Reply, op: &str, allowed: &[String]) -> Reply {
    let Reply::Result(v) = &reply else {
        return reply;
    };
    let Some(map) = v.as_object() else {
        return Reply::Protocol(format!(
            "the answer's \"result\" is not an object: {}",
            super::expect::show(v)
        ));
    };
    if map.is_empty() {
        return Reply::Protocol(format!(
            "the answer to a \"{op}\" request is an empty object (its keys: {})",
            allowed.join(", ")
        ));
    }
    match map.keys().find(|k| !allowed.iter().any(|a| a == *k)) {
        Some(k) => Reply::Protocol(format!(
            "the answer to a \"{op}\" request has the key \"{}\", which that answer does not have (its keys: {})",
            crate::escape::truncate(k, 60),
            allowed.join(", ")
        )),
        None => reply,
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
            "NotFound" | "BadReturn" => e.message.clone(),
            _ => format!("raised {e}"),
        }),
        Reply::TimedOut => Some(format!("no answer within {timeout}")),
        Reply::Protocol(why) => Some(format!("a protocol error: {why}")),
        Reply::Failed(why) | Reply::NotRun(why) => Some(why.clone()),
    }
}

/// The verdict of a function from its counts: failed when a scored case failed or none was
/// scored right (a function earns nothing without a case answered right), not run when nothing
/// was, passed otherwise.
fn decided(result: &FunctionResult) -> Status {
    let c = &result.counts;
    if c.failed > 0 {
        Status::Failed
    } else if c.passed > 0 {
        Status::Passed
    } else if c.not_scored > 0 {
        Status::Failed
    } else {
        Status::NotRun
    }
}

/// How one scored case came out.
enum Judged {
    Right,
    Wrong(String),
    /// Not the course's answer, but it keeps the case's behaviour: waits for the partners.
    ByBehaviour(String),
}

/// Judges one scored case's reply: the course's answer, else (a steered case) its behaviour.
fn judge_one(case: &Case, reply: &Reply, behaviour: Option<&Behaviour>) -> Judged {
    let Reply::Result(v) = reply else {
        return Judged::Wrong(not_an_answer(reply, "the time allowed").unwrap_or_default());
    };
    let Err(problem) = case.expect.judge(v) else {
        return Judged::Right;
    };
    match behaviour.map(|b| b(v)) {
        Some(Ok(())) => Judged::ByBehaviour(problem),
        Some(Err(why)) => Judged::Wrong(format!("{problem}; {why}")),
        None => Judged::Wrong(problem),
    }
}

fn judge_cases(
    result: &mut FunctionResult,
    cases: &[Case],
    variants: &[Variant],
    replies: &[Reply],
    behaviour: Option<&Vec<Behaviour>>,
) {
    let mut ambiguous = 0;
    let mut course_fails = 0;
    let mut scored: Vec<usize> = Vec::new();
    for (k, (case, reply)) in cases.iter().zip(replies).enumerate() {
        if matches!(reply, Reply::NotRun(_)) {
            result.counts.not_run += 1;
            continue;
        }
        if matches!(reply, Reply::Protocol(_)) {
            // A protocol error is never excused, not even on a case that is not scored.
            result.counts.protocol += 1;
        } else {
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
        }
        scored.push(k);
        let problem = match judge_one(case, reply, behaviour.and_then(|b| b.get(k))) {
            Judged::Right => {
                result.counts.passed += 1;
                continue;
            }
            Judged::ByBehaviour(problem) => {
                result.by_behaviour += 1;
                format!(
                    "{problem}: not the course's answer for the steered random numbers; it keeps the function's invariant, so it counts as right only when {} passes",
                    result.partners.join(" and ")
                )
            }
            Judged::Wrong(problem) => problem,
        };
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
    if result.counts.protocol > 0 {
        result.notes.push(format!(
            "{} case(s) answered with a protocol error (a malformed answer or a key the protocol does not name): failed, and flagged for review",
            result.counts.protocol
        ));
    }
    result.status = decided(result);
    if result.counts.passed == 0 && result.counts.failed == 0 && result.counts.not_scored > 0 {
        result.notes.push(format!(
            "none of its {} case(s) could be scored, so it earns nothing",
            cases.len()
        ));
    }
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

/// The samples of one answer to `request`: exactly the `n` it asked for, each of the right arity
/// (`extract`'s) and finite; what is wrong otherwise, and whether that is a protocol error.
fn samples_of(
    request: &serde_json::Value,
    reply: &Reply,
    extract: &super::checks::Extract,
) -> Result<Vec<Sample>, (String, bool)> {
    let v = match reply {
        Reply::Result(v) => v,
        other => {
            let protocol = matches!(other, Reply::Protocol(_));
            return Err((
                not_an_answer(other, "the time allowed").unwrap_or_default(),
                protocol,
            ));
        }
    };
    let samples = extract(v).map_err(|why| (why, true))?;
    let asked = request
        .get("n")
        .and_then(serde_json::Value::as_u64)
        .unwrap_or(0) as usize;
    if samples.len() != asked {
        return Err((
            format!(
                "a protocol error: {} samples answered where {asked} were asked for",
                samples.len()
            ),
            true,
        ));
    }
    Ok(samples)
}

fn judge_samples(
    result: &mut FunctionResult,
    (requests, replies): (&[serde_json::Value], &[Reply]),
    extract: &super::checks::Extract,
    check: &SamplerCheck,
    repro: &str,
    alpha: f64,
) {
    let mut samples: Vec<Sample> = Vec::new();
    for (request, reply) in requests.iter().zip(replies) {
        if let Reply::NotRun(why) = reply {
            result.counts.not_run = 1;
            result.notes.push(why.clone());
            return;
        }
        let problem = match samples_of(request, reply, extract) {
            Ok(s) => {
                samples.extend(s);
                None
            }
            Err((why, protocol)) => {
                result.counts.protocol += usize::from(protocol);
                Some(why)
            }
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

#[cfg(test)]
#[path = "run_tests.rs"]
mod tests;
