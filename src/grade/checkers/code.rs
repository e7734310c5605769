//! The real [`CodeChecker`]: the `check` harness ([`crate::candidate`]) running the bundled
//! course adapter on the submission, in the [sandbox](crate::sandbox), against the built-in
//! suite filtered to the rubric's groups.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde_json::Value;

use crate::candidate::judging::check::{
    FailureKind as CheckKind, Verdict, decide_winding, judge_exact_wound, judge_wound,
};
use crate::candidate::judging::report::python_repro;
use crate::candidate::process::command::CandidateCommand;
use crate::candidate::process::error::HarnessError;
use crate::candidate::process::options::RunOptions;
use crate::candidate::process::outcome::Outcome;
use crate::candidate::process::python;
use crate::candidate::process::render_request::{RenderJob, RenderOutcome, render_scene};
use crate::candidate::process::session::Session;
use crate::grade::checkers::{CodeChecker, CodeOutcome, FailureKind, FailureSummary, GroupCounts};
use crate::grade::rubric::credit;
use crate::grade::rubric::sha256_hex;
use crate::oracle::suite::default_suite;
use crate::oracle::vectors::{Case, Class, ShapeKind};
use crate::sandbox::policy::SandboxPolicy;

/// Checks a submission's `RT_object.py` with the course adapter of `rtoracle check
/// --python-course`: one sandboxed interpreter per submission, restarted after a crash; a
/// vector that hangs costs [`case_timeout`](Self::case_timeout), and after
/// [`max_timeouts_per_group`](Self::max_timeouts_per_group) of them the rest of the group is
/// not run. What the submission prints goes to its stderr (shown in the report), never among
/// the answers.
#[derive(Clone, Debug)]
pub struct CourseCodeChecker {
    /// The rubric's secret seed: the built-in suite is that of the seed derived from it for the
    /// purpose `"vectors"` ([`crate::secret`]), so a seed printed by a hostile submission (a
    /// render's, a sampler's) does not give the suite (`rtoracle vectors --seed`).
    pub seed: u64,
    /// Vectors to run instead of the built-in suite (a vector file the course pinned), with a
    /// label for the report (e.g. its path).
    pub vectors: Option<(String, Vec<Case>)>,
    /// Wall-clock limit per vector.
    pub case_timeout: Duration,
    /// Wall-clock limit for starting Python and importing the submission.
    pub import_timeout: Duration,
    /// After this many timeouts in a group, the rest of the group is not run.
    pub max_timeouts_per_group: u32,
    /// Wall time for all of a submission's code checks (the rubric's
    /// `code_time_budget_seconds`); past it the rest is not run. `None`: no limit.
    pub time_budget: Option<Duration>,
    /// The sandbox's limits.
    pub policy: SandboxPolicy,
    /// The interpreter (`--python`; default: [`python::choose`]'s, which probes
    /// `$RTORACLE_PYTHON` or the usual places, in the sandbox, for [`Self::python_requires`]).
    pub python: Option<PathBuf>,
    /// The modules the interpreter must have (the rubric's `python_requires`).
    pub python_requires: Vec<String>,
    /// The course week of the submissions (the rubric's `week`): from week 7 on, a sphere
    /// vector on which the course's own `get_uv` raises at a pole is not scored
    /// ([`crate::weekly::submission::excuse_pole_crashes`]).
    pub week: Option<crate::weekly::week::Week>,
}

impl Default for CourseCodeChecker {
    fn default() -> Self {
        CourseCodeChecker {
            seed: 0,
            vectors: None,
            case_timeout: Duration::from_secs(2),
            import_timeout: Duration::from_secs(5),
            max_timeouts_per_group: 3,
            time_budget: Some(Duration::from_secs(60)),
            policy: SandboxPolicy::grading(),
            python: None,
            python_requires: python::default_requires(),
            week: None,
        }
    }
}

/// Removes the sandbox folder, and the submission folder the harness names in its place, from
/// file names: the student's feedback says `RT_object.py`, not where the grader kept it.
fn strip_dirs(text: &str, dirs: &[&Path]) -> String {
    let mut text = text.to_string();
    for &dir in dirs {
        let canonical = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
        for d in [canonical.as_path(), dir] {
            for prefix in [format!("{}/./", d.display()), format!("{}/", d.display())] {
                text = text.replace(&prefix, "");
            }
        }
    }
    text
}

impl CourseCodeChecker {
    fn suite(&self) -> Vec<Case> {
        match &self.vectors {
            Some((_, cases)) => cases.clone(),
            None => default_suite(crate::secret::derive(self.seed, "vectors")),
        }
    }

    fn options(&self) -> RunOptions {
        RunOptions {
            timeout: self.case_timeout,
            hello_timeout: self.import_timeout,
            max_timeouts_per_group: self.max_timeouts_per_group,
            limits: self.policy.clone(),
            budget: self.time_budget,
            ..RunOptions::default()
        }
    }
}

/// The grade's failure kind and message for a definite case that did not pass.
fn grade_failure(
    kind: CheckKind,
    message: String,
    outcome: &Outcome,
    timeout: Duration,
) -> (FailureKind, String) {
    match (kind, outcome) {
        // A dead interpreter is an error (counted as a crash), not a time-out.
        (CheckKind::Error, Outcome::Died { .. }) => (
            FailureKind::Error,
            message.replace(
                "the candidate died on this case",
                "Python died on this vector",
            ),
        ),
        (CheckKind::Error, _) => (FailureKind::Error, message),
        (CheckKind::Timeout, _) => (
            FailureKind::Timeout,
            format!(
                "no answer within {} s (an infinite loop?)",
                timeout.as_secs_f64()
            ),
        ),
        (CheckKind::NotRun, _) => (FailureKind::NotRun, message),
        (CheckKind::Mismatch, _) => (FailureKind::Mismatch, message),
        (CheckKind::Protocol, _) => (FailureKind::Protocol, message),
    }
}

impl CodeChecker for CourseCodeChecker {
    fn describe(&self) -> String {
        let suite = match &self.vectors {
            Some((label, cases)) => format!("{} vectors from {label}", cases.len()),
            None => format!(
                "built-in suite of the rubric's seed ({})",
                crate::secret::digest(self.seed)
            ),
        };
        format!(
            "course adapter (as `rtoracle check --python-course`), {suite}, {} ms per vector",
            self.case_timeout.as_millis()
        )
    }

    fn render(
        &self,
        submission: &Path,
        jobs: &[crate::grade::checkers::RenderJob],
    ) -> Vec<crate::grade::checkers::RenderOutcome> {
        course_render(self, submission, jobs)
    }

    fn check_functions(
        &self,
        submission: &Path,
        week: crate::weekly::week::Week,
        options: crate::weekly::run::FunctionOptions,
    ) -> crate::grade::checkers::FunctionsOutcome {
        course_functions(self, submission, week, options)
    }

    fn vectors_sha256(&self) -> String {
        let text: String = self
            .suite()
            .iter()
            .map(|c| c.to_json_line() + "\n")
            .collect();
        sha256_hex(text.as_bytes())
    }

    fn check(&self, submission: &Path, groups: &[ShapeKind]) -> CodeOutcome {
        let suite = self.suite();
        let sizes = watertight_sizes(&suite);
        let cases: Vec<Case> = suite
            .into_iter()
            .filter(|c| groups.contains(&c.shape.kind()))
            .collect();
        let mut out = CodeOutcome {
            per_group: groups
                .iter()
                .map(|&g| (g, GroupCounts::default()))
                .collect(),
            ..Default::default()
        };
        for c in &cases {
            let counts = out.per_group.get_mut(&c.shape.kind()).expect("asked for");
            if c.expect.class.is_definite() {
                counts.definite_total += 1;
            }
        }
        let mut session = match self.start(submission) {
            Ok(s) => s,
            Err(msg) => {
                fatal(&mut out, msg);
                return out;
            }
        };
        let paths = PathStripper::new(&session, submission);
        out.sandbox = serde_json::to_value(session.sandbox_facts()).unwrap_or_default();
        let failure = if let Some(e) = &session.hello().error {
            Some(import_failure(e, &paths))
        } else {
            session.start_failure().map(|why| {
                format!(
                    "Python could not import the submission: {}",
                    paths.strip(why)
                )
            })
        };
        match failure {
            Some(msg) => fatal(&mut out, msg),
            None => match session.run(&cases) {
                Ok(outcomes) => {
                    // From week 7 on, the course's own get_uv raises at a sphere's pole.
                    let cases = match self.week {
                        Some(week) => {
                            let (excused, _) = crate::weekly::submission::excuse_pole_crashes(
                                week, &cases, &outcomes,
                            );
                            for (before, after) in cases.iter().zip(&excused) {
                                if before.expect.class != after.expect.class {
                                    let counts = out
                                        .per_group
                                        .get_mut(&before.shape.kind())
                                        .expect("asked for");
                                    counts.definite_total -= 1;
                                }
                            }
                            excused
                        }
                        None => cases,
                    };
                    self.tally(&cases, &outcomes, &mut out, &paths);
                    tally_unanswered_and_cracks(&cases, &outcomes, &sizes, &mut out);
                }
                Err(e) => fatal(&mut out, e.to_string()),
            },
        }
        out.stderr_tail = paths.strip(&session.stderr_tail());
        out.sandbox = serde_json::to_value(session.sandbox_facts()).unwrap_or_default();
        out
    }
}

/// What the reports say when the submission cannot be imported: the exception and where the
/// submission raised it (`SyntaxError: expected ':' (RT_object.py, line 19)`), then Python's
/// traceback, with the submission's file names.
fn import_failure(
    e: &crate::candidate::process::protocol::CandidateError,
    paths: &PathStripper,
) -> String {
    let mut text = format!(
        "importing the submission failed: {}",
        paths.strip(&e.to_string())
    );
    if !e.traceback.trim().is_empty() {
        text.push('\n');
        text.push_str(&paths.strip(e.traceback.trim_end()));
    }
    text
}

/// How many members each watertight group of `suite` has, by the group's id.
fn watertight_sizes(suite: &[Case]) -> std::collections::HashMap<String, usize> {
    let mut sizes = std::collections::HashMap::new();
    for c in suite {
        if let Some(w) = &c.expect.watertight {
            *sizes.entry(w.group.clone()).or_insert(0) += 1;
        }
    }
    sizes
}

/// What fails `rtoracle check` besides a definite vector, scored the same way here (so `check`
/// and `grade` give one verdict and one explanation; docs/grading.md, "One verdict"): a vector
/// that is not scored but on which the code hung or killed Python (a candidate must answer
/// every vector) counts as a vector of its exact answer's kind answered wrong; a watertight
/// group of class `hit` counts as one vector where the ray hits, right when the ray hit one of
/// its shapes, wrong when every member ran and the ray went through the crack between them (a
/// group with a member of a shape the rubric does not grade cannot crack). Both are counted
/// under the shape of their first member, and their failures are shown as scored ones.
fn tally_unanswered_and_cracks(
    cases: &[Case],
    outcomes: &[Outcome],
    sizes: &std::collections::HashMap<String, usize>,
    out: &mut CodeOutcome,
) {
    use crate::candidate::judging::watertight::{GroupResult, crack_message, judge_groups};
    let summary = |case: &Case, outcome: &Outcome, kind, message: String| FailureSummary {
        id: case.id.clone(),
        shape: case.shape.kind(),
        tags: case.expect.tags.clone(),
        kind,
        definite: true,
        expected: serde_json::to_value(&case.expect).unwrap_or_default(),
        actual: match outcome {
            Outcome::Answered { answer, .. } => serde_json::to_value(answer).unwrap_or(Value::Null),
            _ => Value::Null,
        },
        message: message.into(),
        repro: python_repro(case),
    };
    let mut extra = Vec::new();
    for (case, outcome) in cases.iter().zip(outcomes) {
        if case.expect.class.is_definite() {
            continue;
        }
        let Some((kind, message)) = crate::candidate::judging::report::unscored_failure(outcome)
        else {
            continue;
        };
        let counts = out
            .per_group
            .get_mut(&case.shape.kind())
            .expect("asked for");
        match outcome {
            Outcome::Timeout { .. } => counts.unscored_timeouts += 1,
            _ => counts.unscored_crashes += 1,
        }
        counts
            .tally
            .record(credit::expects_hit(case), credit::Mark::Wrong);
        extra.push(summary(case, outcome, kind, message));
    }
    for g in judge_groups(cases, outcomes) {
        // A group with a member of a shape not graded holds when the others hit, as in
        // `check` when a shape is not supported; it cannot be said to crack.
        let whole = sizes.get(&g.id) == Some(&g.members.len());
        if g.result == GroupResult::Unjudged || (g.result == GroupResult::Cracked && !whole) {
            continue;
        }
        let first = &cases[g.members[0]];
        let counts = out
            .per_group
            .get_mut(&first.shape.kind())
            .expect("asked for");
        counts.watertight += 1;
        if g.result == GroupResult::Held {
            counts.tally.record(true, credit::Mark::Right);
            continue;
        }
        counts.watertight_cracked += 1;
        counts.tally.record(true, credit::Mark::Wrong);
        let message = crack_message(&g, cases);
        extra.push(summary(
            first,
            &outcomes[g.members[0]],
            FailureKind::Mismatch,
            message,
        ));
    }
    // The definite failures first (by shape), as the tally leaves them, then these.
    let definite = out.failures.iter().take_while(|f| f.definite).count();
    let rest = out.failures.split_off(definite);
    out.failures.extend(extra);
    out.failures.sort_by_key(|f| f.shape);
    out.failures.extend(rest);
}

/// Marks every vector not run, for `msg`: nothing of the code could be checked.
fn fatal(out: &mut CodeOutcome, msg: String) {
    for counts in out.per_group.values_mut() {
        counts.not_run = counts.definite_total;
    }
    out.fatal = Some(msg);
}

/// Names files as the student knows them: without the sandbox's folder (inside and outside)
/// or the grader's copy of the submission.
struct PathStripper {
    sandbox_dir: PathBuf,
    inside_dir: PathBuf,
    submission_dir: PathBuf,
}

impl PathStripper {
    fn new(session: &Session, submission: &Path) -> Self {
        PathStripper {
            sandbox_dir: session.sandbox_dir().to_path_buf(),
            inside_dir: session.sandbox_inside_dir(),
            submission_dir: std::path::absolute(submission)
                .unwrap_or_else(|_| submission.to_path_buf()),
        }
    }

    fn strip(&self, text: &str) -> String {
        let text = if self.inside_dir != self.sandbox_dir {
            let to = self.submission_dir.display().to_string();
            crate::sandbox::view::replace_path(text, &self.inside_dir, &to)
        } else {
            text.to_string()
        };
        strip_dirs(&text, &[&self.sandbox_dir, &self.submission_dir])
    }
}

impl CourseCodeChecker {
    /// Starts the course adapter on `submission` in the sandbox, or says why it cannot run.
    fn start(&self, submission: &Path) -> Result<Session, String> {
        let has_object = std::fs::symlink_metadata(submission.join("RT_object.py"))
            .map(|m| m.is_file())
            .unwrap_or(false);
        if !has_object {
            return Err("RT_object.py is not in the submission".into());
        }
        // Probed once per process (cached): a batch pays for it once.
        let python = python::choose(self.python.as_deref(), &self.python_requires, &self.policy)
            .map_err(|e| e.to_string())?;
        CandidateCommand::python_course_with(submission, Some(&python), true)
            .and_then(|command| Session::start(command, self.options()))
            .map_err(|e| match e {
                HarnessError::Python(e) => format!("cannot run the Python interpreter: {e}"),
                e => e.to_string(),
            })
    }

    /// Counts the outcomes per shape and keeps the failures: students' triangles judged by
    /// their own winding, the failures diagnosed.
    fn tally(
        &self,
        cases: &[Case],
        outcomes: &[Outcome],
        out: &mut CodeOutcome,
        paths: &PathStripper,
    ) {
        let winding = decide_winding(cases, outcomes);
        out.triangle_winding = winding;
        out.diagnosis = crate::candidate::judging::diagnose::diagnose(cases, outcomes, winding);
        let mut definite_failures = Vec::new();
        let mut ambiguous_failures = Vec::new();
        for (case, outcome) in cases.iter().zip(outcomes) {
            let kind = case.shape.kind();
            let definite = case.expect.class.is_definite();
            let counts = out.per_group.get_mut(&kind).expect("asked for");
            let verdict = if definite {
                judge_wound(case, outcome, winding)
            } else if case.expect.class == Class::Ambiguous {
                counts.ambiguous += 1;
                judge_exact_wound(case, outcome, winding)
            } else {
                continue;
            };
            let mark = credit::mark(case, outcome, &verdict, winding);
            let hit = credit::expects_hit(case);
            if definite {
                counts.tally.record(hit, mark);
            } else {
                counts.ambiguous_tally.record(hit, mark);
            }
            let (failure_kind, message) = match verdict {
                Verdict::Pass => {
                    if definite {
                        counts.passed += 1;
                    } else {
                        counts.ambiguous_passed += 1;
                    }
                    continue;
                }
                Verdict::NotScored => continue,
                Verdict::Fail { kind: k, message } => {
                    grade_failure(k, message, outcome, self.case_timeout)
                }
            };
            if definite {
                match failure_kind {
                    FailureKind::Error if matches!(outcome, Outcome::Died { .. }) => {
                        counts.crashes += 1
                    }
                    FailureKind::Error => counts.errors += 1,
                    FailureKind::Timeout => counts.timeouts += 1,
                    FailureKind::NotRun => counts.not_run += 1,
                    FailureKind::Mismatch | FailureKind::Protocol => counts.failed += 1,
                }
            }
            let actual = match outcome {
                Outcome::Answered { answer, .. } => {
                    serde_json::to_value(answer).unwrap_or(Value::Null)
                }
                _ => Value::Null,
            };
            let summary = FailureSummary {
                id: case.id.clone(),
                shape: kind,
                tags: case.expect.tags.clone(),
                kind: failure_kind,
                definite,
                expected: serde_json::to_value(&case.expect).unwrap_or_default(),
                actual,
                message: paths.strip(&message).into(),
                repro: python_repro(case),
            };
            if definite {
                definite_failures.push(summary);
            } else {
                ambiguous_failures.push(summary);
            }
        }
        definite_failures.sort_by_key(|f| f.shape);
        ambiguous_failures.sort_by_key(|f| f.shape);
        out.failures = definite_failures;
        out.failures.extend(ambiguous_failures);
    }
}

/// A [`FunctionRunner`](crate::weekly::runner::FunctionRunner) that stops sending requests once a
/// wall-clock deadline has passed (the rubric's code time budget): the rest are not run.
struct BudgetRunner<'a> {
    inner: crate::weekly::runner::SessionRunner<'a>,
    deadline: Option<std::time::Instant>,
    refused: usize,
}

impl crate::weekly::runner::FunctionRunner for BudgetRunner<'_> {
    fn supports(&self, op: &str) -> bool {
        self.inner.supports(op)
    }

    fn call(&mut self, request: &Value, timeout: Duration) -> crate::weekly::runner::Reply {
        let now = std::time::Instant::now();
        match self.deadline {
            Some(d) if now >= d => {
                self.refused += 1;
                crate::weekly::runner::Reply::NotRun("the code time budget ran out".into())
            }
            Some(d) => self.inner.call(request, timeout.min(d - now)),
            None => self.inner.call(request, timeout),
        }
    }
}

/// Runs week `week`'s function checks with the course adapter in one sandboxed session on
/// `submission`, within the checker's time budget (its CPU limit is raised to the budget: the
/// samplers' requests take seconds of Python each); what the submission's errors say names its
/// files as the student knows them.
fn course_functions(
    checker: &CourseCodeChecker,
    submission: &Path,
    week: crate::weekly::week::Week,
    options: crate::weekly::run::FunctionOptions,
) -> crate::grade::checkers::FunctionsOutcome {
    use crate::grade::checkers::FunctionsOutcome;
    let fatal = |msg: String| FunctionsOutcome {
        fatal: Some(msg),
        ..FunctionsOutcome::default()
    };
    let budget = checker.time_budget;
    let mut checker = checker.clone();
    if let Some(b) = budget {
        checker.policy.cpu_seconds = checker.policy.cpu_seconds.max(b.as_secs() + 5);
    }
    // The budget is this session's: the vectors' deadline is not shared with it.
    checker.time_budget = None;
    let mut session = match checker.start(submission) {
        Ok(s) => s,
        Err(msg) => return fatal(msg),
    };
    let paths = PathStripper::new(&session, submission);
    let failure = if let Some(e) = &session.hello().error {
        Some(import_failure(e, &paths))
    } else {
        session.start_failure().map(|why| {
            format!(
                "Python could not import the submission: {}",
                paths.strip(why)
            )
        })
    };
    if let Some(msg) = failure {
        let mut out = fatal(msg);
        out.stderr_tail = paths.strip(&session.stderr_tail());
        return out;
    }
    let deadline = budget.map(|b| std::time::Instant::now() + b);
    let mut runner = BudgetRunner {
        inner: crate::weekly::runner::SessionRunner::new(&mut session),
        deadline,
        refused: 0,
    };
    let mut report = crate::weekly::run::run_week(&mut runner, week, options);
    let out_of_time = runner.refused;
    for f in &mut report.functions {
        if let Some(failure) = &mut f.failure {
            failure.problem = paths.strip(&failure.problem);
        }
        for note in &mut f.notes {
            *note = paths.strip(note);
        }
    }
    FunctionsOutcome {
        report: Some(report),
        fatal: None,
        stderr_tail: paths.strip(&session.stderr_tail()),
        out_of_time,
    }
}

/// Renders each job with the course adapter in one sandboxed session on `submission` (started
/// once, restarted after a time-out or a death); a session that cannot start gives every job
/// the reason.
fn course_render(
    checker: &CourseCodeChecker,
    submission: &Path,
    jobs: &[RenderJob],
) -> Vec<RenderOutcome> {
    let mut session = match start(checker, submission, jobs) {
        Ok(s) => s,
        Err(why) => {
            return jobs
                .iter()
                .map(|_| RenderOutcome::Declined(why.clone()))
                .collect();
        }
    };
    let submission_dir = std::path::absolute(submission).unwrap_or_else(|_| submission.into());
    let sandbox_dir = session.sandbox_dir().to_path_buf();
    let dirs = [sandbox_dir.as_path(), submission_dir.as_path()];
    jobs.iter()
        .map(|job| match render_scene(&mut session, job) {
            RenderOutcome::Raised(mut e) => {
                for text in [&mut e.message, &mut e.traceback] {
                    *text = strip_dirs(text, &dirs);
                }
                RenderOutcome::Raised(e)
            }
            other => other,
        })
        .collect()
}

/// Starts the render session. One interpreter renders every job, so its CPU limit is the
/// code checks' plus every job's wall time: a render that keeps within its `render_seconds` is
/// never stopped by the CPU limit meant for the code checks.
fn start(
    checker: &CourseCodeChecker,
    submission: &Path,
    jobs: &[RenderJob],
) -> Result<Session, String> {
    let python = python::choose(
        checker.python.as_deref(),
        &checker.python_requires,
        &checker.policy,
    )
    .map_err(|e| e.to_string())?;
    let options = RunOptions {
        timeout: checker.case_timeout,
        hello_timeout: checker.import_timeout,
        limits: {
            let mut limits = checker.policy.clone();
            let render_seconds: u64 = jobs.iter().map(|j| j.time_limit.as_secs() + 1).sum();
            limits.cpu_seconds = limits.cpu_seconds.saturating_add(render_seconds);
            limits
        },
        budget: None,
        ..RunOptions::default()
    };
    CandidateCommand::python_course_with(submission, Some(&python), true)
        .and_then(|command| Session::start(command, options))
        .map_err(|e| match e {
            HarnessError::Python(e) => format!("cannot run the Python interpreter: {e}"),
            e => e.to_string(),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        crate::bench::grade::materialize_code(name, dir.path()).unwrap();
        dir
    }

    fn definite(kind: ShapeKind) -> usize {
        default_suite(crate::secret::derive(0, "vectors"))
            .iter()
            .filter(|c| c.shape.kind() == kind && c.expect.class.is_definite())
            .count()
    }

    #[test]
    fn the_honest_fixture_passes_every_vector_in_the_sandbox() {
        let sub = fixture("honest");
        let out =
            CourseCodeChecker::default().check(sub.path(), &[ShapeKind::Sphere, ShapeKind::Quad]);
        assert_eq!(out.fatal, None, "{}", out.stderr_tail);
        for kind in [ShapeKind::Sphere, ShapeKind::Quad] {
            let n = definite(kind);
            let c = &out.per_group[&kind];
            assert_eq!((c.definite_total, c.passed), (n, n), "{kind}");
        }
        // Ambiguous vectors are reported (not scored); no definite one may fail.
        let definite: Vec<_> = out
            .failures
            .iter()
            .filter(|f| f.definite)
            .map(|f| &f.id)
            .collect();
        assert!(definite.is_empty(), "{definite:?}");
        // Never root: a root harness gives the submission a uid of its own.
        if crate::sandbox::identity::running_as_root() {
            let uid = out.sandbox["uid"].as_u64().unwrap();
            assert!(uid >= 1 << 30, "{}", out.sandbox);
        }
    }

    #[test]
    fn a_sphere_bug_costs_sphere_vectors_only_and_comes_with_a_repro() {
        let sub = fixture("sphere-bug");
        let out =
            CourseCodeChecker::default().check(sub.path(), &[ShapeKind::Sphere, ShapeKind::Quad]);
        assert_eq!(out.fatal, None);
        let s = &out.per_group[&ShapeKind::Sphere];
        assert!(
            s.failed > 0 && s.passed + s.failed == s.definite_total,
            "{s:?}"
        );
        let q = &out.per_group[&ShapeKind::Quad];
        assert_eq!(q.passed, q.definite_total);
        let f = &out.failures[0];
        assert!(f.definite && f.shape == ShapeKind::Sphere && f.kind == FailureKind::Mismatch);
        assert!(
            f.repro.contains("from RT_object import Sphere"),
            "{}",
            f.repro
        );
    }

    #[test]
    fn an_unimportable_submission_is_fatal_with_python_s_message_and_no_sandbox_path() {
        let sub = fixture("unimportable");
        let out = CourseCodeChecker::default().check(sub.path(), &[ShapeKind::Sphere]);
        let fatal = out.fatal.expect("fatal");
        assert!(fatal.contains("SyntaxError"), "{fatal}");
        assert!(fatal.contains("File \"RT_object.py\""), "{fatal}");
        assert!(!fatal.contains("rtoracle-sandbox"), "{fatal}");
        let s = &out.per_group[&ShapeKind::Sphere];
        assert_eq!(s.not_run, s.definite_total);
    }

    #[test]
    fn prints_do_not_change_the_answers_and_land_in_stderr() {
        // It prints an answer-looking line on every quad it checks and a debug line on spheres.
        let sub = fixture("chatty");
        let out =
            CourseCodeChecker::default().check(sub.path(), &[ShapeKind::Sphere, ShapeKind::Quad]);
        assert_eq!(out.fatal, None);
        // Ambiguous vectors are reported (not scored); no definite one may fail.
        let definite: Vec<_> = out
            .failures
            .iter()
            .filter(|f| f.definite)
            .map(|f| &f.id)
            .collect();
        assert!(definite.is_empty(), "{definite:?}");
        // The answer-shaped print went to stderr (the tail keeps the last 4 KB, which the quad
        // prints, coming last, fill).
        assert!(
            out.stderr_tail
                .contains(r#"{"id": "quad-basic-0000", "hit": false}"#),
            "{}",
            out.stderr_tail
        );
    }

    #[test]
    fn an_interpreter_the_sandbox_user_cannot_run_is_refused_never_run_as_root() {
        // Python under /root (mode 0700) cannot be run by a sandbox user.
        let private = Path::new("/root/.pyenv/versions/3.11.7/bin/python3");
        if !crate::sandbox::identity::running_as_root() || !private.exists() {
            eprintln!("skipped: needs root and a Python under /root");
            return;
        }
        let checker = CourseCodeChecker {
            python: Some(private.to_path_buf()),
            ..Default::default()
        };
        let sub = fixture("honest");
        let out = checker.check(sub.path(), &[ShapeKind::Sphere]);
        let fatal = out.fatal.expect("refused");
        assert!(
            fatal.starts_with(&format!(
                "--python {}: cannot be run by the sandbox user",
                private.display()
            )),
            "{fatal}"
        );
        let s = &out.per_group[&ShapeKind::Sphere];
        assert_eq!(s.not_run, s.definite_total);
        assert!(out.sandbox.is_null(), "nothing ran: {}", out.sandbox);
    }
}
