//! `rtoracle check`: runs a candidate against the intersection vectors, and from week 5 on
//! against the week's function checks (`--week N`, or the week found from a course folder's
//! files).

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::candidate::process::command::CandidateCommand;
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::candidate::{check_command, process::python};
use rtoracle::oracle::vectors::{Case, read_vectors};
use rtoracle::oracle::{
    classify::classify_tagged_with, profile::Judging, profile::Profile, suite::default_suite_with,
};
use rtoracle::sandbox::policy::SandboxError;
use rtoracle::sandbox::policy::SandboxPolicy;
use rtoracle::weekly::{run::FunctionOptions, submission::check_week, week::Week, week::detect};

/// Which candidate to run (shared by `check` and `fuzz`; `check` without either checks the
/// course submission in the current folder).
#[derive(Debug, clap::Args)]
#[group(required = false, multiple = false)]
pub struct Target {
    /// A submission folder in the course's Python layout (RT_utility.py, RT_ray.py,
    /// RT_object.py), run through the bundled adapter.
    #[arg(long, value_name = "DIR")]
    pub python_course: Option<PathBuf>,
    /// A command speaking the JSON-lines adapter protocol (docs/PROTOCOL.md), e.g.
    /// 'python3 my_adapter.py'.
    #[arg(long, value_name = "CMD ARGS")]
    pub adapter: Option<String>,
}

/// Reclassifies `cases` under `judging`, keeping the file's provenance tags (its
/// ill-conditioned tags belong to the judging that wrote it and are dropped).
pub fn reclassify(cases: Vec<Case>, judging: Judging) -> Vec<Case> {
    cases
        .into_iter()
        .map(|mut c| {
            let tags: Vec<&str> = c
                .expect
                .tags
                .iter()
                .map(String::as_str)
                .filter(|t| !t.ends_with("ill-conditioned"))
                .collect();
            c.expect = classify_tagged_with(&c.shape, &c.ray, c.interval, &tags, judging);
            c
        })
        .collect()
}

impl Target {
    /// The profile a candidate is judged by when `--profile` is not given: `course` (today's
    /// policy) for every candidate, so `--precision f32` alone judges an f32 port of naive code
    /// fairly; `--profile robust` is one flag away, and the report of an `--adapter` candidate
    /// judged by the default says so.
    pub fn default_profile(&self) -> Profile {
        Profile::Course
    }

    /// What the report adds to `judged by:` when the default profile judged another renderer.
    pub fn profile_hint(&self, judging: &crate::cli::args::JudgingArgs) -> &'static str {
        if self.adapter.is_some() && judging.profile.is_none() {
            " (the default; --profile robust also judges the far, scaled and near-tangent cases a carefully written f64 intersector must get right)"
        } else {
            ""
        }
    }
}

/// How the candidate is sandboxed and which Python runs the course adapter (shared by `check`
/// and `fuzz`).
#[derive(Debug, clap::Args)]
pub struct SandboxArgs {
    /// The Python 3 that runs the course adapter (it must have numpy and PIL); default:
    /// $RTORACLE_PYTHON, else the first of /usr/bin/python3, /usr/local/bin/python3, python3
    /// on PATH, ... that has them.
    #[arg(long, value_name = "PATH")]
    pub python: Option<PathBuf>,
    /// Run the candidate without a sandbox, as the current user (root included), for one's own
    /// code where no sandbox can be made; the output says so.
    #[arg(long)]
    pub unsandboxed: bool,
    /// Show FOLDER read-only inside the sandbox too (repeatable): for an adapter that starts a
    /// program its command line does not name (a wrapper script running ../build/tracer).
    #[arg(long, value_name = "FOLDER")]
    pub expose: Vec<PathBuf>,
}

impl SandboxArgs {
    /// The sandbox policy of `check` and `fuzz`.
    pub fn policy(&self) -> SandboxPolicy {
        SandboxPolicy {
            unsandboxed: self.unsandboxed,
            shown: self
                .expose
                .iter()
                .map(|p| p.canonicalize().unwrap_or_else(|_| p.clone()))
                .collect(),
            ..SandboxPolicy::default()
        }
    }

    /// `--expose` names existing folders, and not the whole file system.
    fn check_shown(&self) -> anyhow::Result<()> {
        for p in &self.expose {
            if !p.is_dir() {
                anyhow::bail!("--expose {}: no such folder", p.display());
            }
            if p.canonicalize()? == Path::new("/") {
                anyhow::bail!(
                    "--expose {}: the whole file system cannot be shown; name the folder the \
                     adapter needs",
                    p.display()
                );
            }
        }
        Ok(())
    }
}

/// A sandbox error with the way out that `check` and `fuzz` offer.
fn with_hint(e: SandboxError) -> anyhow::Error {
    match e {
        SandboxError::Unavailable(_) => {
            anyhow::anyhow!("{e} (pass --unsandboxed to run your own code without a sandbox)")
        }
        other => other.into(),
    }
}

impl Target {
    /// The command to run, after checking that a sandbox can be made (fail closed) and, for the
    /// course adapter, choosing the interpreter: both before any work.
    pub fn command(&self, sandbox: &SandboxArgs) -> anyhow::Result<CandidateCommand> {
        self.check()?;
        sandbox.check_shown()?;
        let policy = sandbox.policy();
        rtoracle::sandbox::detect::isolation_for(&policy).map_err(with_hint)?;
        Ok(match (&self.python_course, &self.adapter) {
            (Some(dir), _) => {
                let python = python::choose(
                    sandbox.python.as_deref(),
                    &python::default_requires(),
                    &policy,
                )
                .map_err(|e| match e {
                    python::PythonError::Sandbox(e) => with_hint(e),
                    other => other.into(),
                })?;
                // What the submission prints goes to stderr, as when grading: a debug print
                // is not an answer, and `check` and `grade` give one verdict.
                CandidateCommand::python_course_with(dir, Some(&python), true)?
            }
            (_, Some(cmd)) => {
                if sandbox.python.is_some() {
                    anyhow::bail!(
                        "--python is for --python-course; put the interpreter in the --adapter command"
                    );
                }
                CandidateCommand::adapter(cmd)?
            }
            _ => anyhow::bail!("give the candidate: --python-course DIR or --adapter 'CMD ARGS'"),
        })
    }
}

impl Target {
    /// Checks the submission folder before any work: it is a folder holding `RT_object.py`.
    pub fn check(&self) -> anyhow::Result<()> {
        match &self.python_course {
            Some(dir) => check_submission_folder(dir, "--python-course "),
            None => Ok(()),
        }
    }
}

/// Checks that `dir` is a folder holding `RT_object.py`; errors name it after `label` (the
/// option it came with, or nothing for a positional argument).
fn check_submission_folder(dir: &std::path::Path, label: &str) -> anyhow::Result<()> {
    if !dir.is_dir() {
        let what = if dir.exists() {
            "is a file; the submission folder is wanted"
        } else {
            "no such folder"
        };
        anyhow::bail!("{label}{}: {what}", dir.display());
    }
    if !dir.join("RT_object.py").is_file() {
        anyhow::bail!(
            "{label}{}: the folder has no RT_object.py (the course's layout: \
             RT_utility.py, RT_ray.py, RT_object.py)",
            dir.display()
        );
    }
    Ok(())
}

/// `rtoracle check`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Without FOLDER, --python-course or --adapter, checks the course submission in the current folder (as --python-course .)."
)]
pub struct Args {
    /// A course submission folder to check (the same as --python-course FOLDER).
    #[arg(value_name = "FOLDER", conflicts_with_all = ["python_course", "adapter"])]
    folder: Option<PathBuf>,
    #[command(flatten)]
    target: Target,
    #[command(flatten)]
    judging: crate::cli::args::JudgingArgs,
    #[command(flatten)]
    sandbox: SandboxArgs,
    /// A vector file (JSON lines); the built-in suite when absent. Its expectations are used as
    /// written unless --profile or --precision is given, which reclassifies every case.
    #[arg(long, value_name = "FILE")]
    vectors: Option<PathBuf>,
    /// Seed of the built-in suite.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// Time allowed per case, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 2000, value_parser = crate::cli::args::millis)]
    timeout_ms: u64,
    /// Time allowed for the candidate to start and answer the hello, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 10_000, value_parser = crate::cli::args::millis)]
    hello_timeout_ms: u64,
    /// Print the whole report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Failures shown in the text report.
    #[arg(long, value_name = "N", default_value_t = 10, value_parser = crate::cli::args::show)]
    show: usize,
    /// Shapes the check must cover (sphere, quad, triangle; comma-separated or repeated): if any
    /// of their vectors is not run (a candidate without a usable Triangle, say), the check fails.
    /// Without it, shapes the candidate does not support are reported as not run and the check
    /// can still pass (the course's week 4 has no triangles).
    #[arg(long, value_name = "SHAPE", value_delimiter = ',', value_parser = shape_kind)]
    require: Vec<rtoracle::oracle::vectors::ShapeKind>,
    /// The course week to check (4 to 10): from week 5 on, the week's functions (and the
    /// earlier weeks') are checked too. Without it, a course folder's week is found from the
    /// functions and classes its files define; an adapter is checked as week 4.
    #[arg(long, value_name = "N", value_parser = crate::cli::args::week)]
    week: Option<u8>,
    /// False-alarm rate of each statistical test of the week's samplers.
    #[arg(long, value_name = "P", default_value_t = rtoracle::weekly::stats::DEFAULT_ALPHA, value_parser = crate::cli::args::alpha)]
    alpha: f64,
    /// Score the ambiguous vectors too, each by its exact answer (as a grading rubric's
    /// `score_ambiguous` does): edges, corners and tangents answered otherwise then fail.
    #[arg(long)]
    score_ambiguous: bool,
}

/// A shape kind named on the command line.
fn shape_kind(s: &str) -> Result<rtoracle::oracle::vectors::ShapeKind, String> {
    rtoracle::oracle::vectors::ShapeKind::from_name(s)
        .ok_or_else(|| format!("{s:?} is not a shape (sphere, quad or triangle)"))
}

/// `rtoracle check` with no candidate: the course submission in the current folder, as
/// `--python-course .`, announced on stderr (stdout stays the report, JSON with `--json`).
fn current_submission() -> anyhow::Result<PathBuf> {
    let here = std::env::current_dir().context("cannot read the current folder")?;
    let shown = rtoracle::escape::terminal_line(&here.display().to_string());
    if !here.join("RT_object.py").is_file() {
        // Run one folder too high: name the submission folders below (a few, sorted).
        let mut below: Vec<String> = std::fs::read_dir(&here)
            .map(|entries| {
                entries
                    .flatten()
                    .filter(|e| e.path().join("RT_object.py").is_file())
                    .map(|e| e.file_name().to_string_lossy().to_string())
                    .collect()
            })
            .unwrap_or_default();
        below.sort();
        let hint = match below.first() {
            Some(first) => format!(
                "; {} has one: `rtoracle check {}`",
                rtoracle::escape::terminal_line(first),
                rtoracle::escape::terminal_line(first)
            ),
            None => String::new(),
        };
        anyhow::bail!(
            "no RT_object.py in {shown}: run `rtoracle check` in a course submission folder (RT_utility.py, RT_ray.py, RT_object.py), or give --python-course DIR or --adapter 'CMD ARGS'{hint}"
        );
    }
    errln!("checking the course submission in {shown} (as --python-course .)");
    Ok(here)
}

pub fn run(mut args: Args) -> anyhow::Result<ExitCode> {
    use rtoracle::weekly::report::CheckDocument;
    if let Some(folder) = args.folder.take() {
        check_submission_folder(&folder, "")?;
        args.target.python_course = Some(folder);
    }
    args.target.check()?;
    let judging = args.judging.judging(args.target.default_profile());
    let (cases, judged_by) = match &args.vectors {
        Some(path) if args.judging.given() => (
            reclassify(read_vectors(path)?, judging),
            format!("{judging} (the file's cases reclassified)"),
        ),
        Some(path) => (
            read_vectors(path)?,
            format!("the expectations in {}", path.display()),
        ),
        None => (
            default_suite_with(args.seed, judging),
            format!("{judging}{}", args.target.profile_hint(&args.judging)),
        ),
    };
    let (cases, judged_by) = if args.score_ambiguous {
        let scored = rtoracle::candidate::judging::check::score_ambiguous(cases);
        (
            scored,
            format!("{judged_by}; ambiguous vectors scored by their exact answers"),
        )
    } else {
        (cases, judged_by)
    };
    let options = RunOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        hello_timeout: Duration::from_millis(args.hello_timeout_ms),
        limits: args.sandbox.policy(),
        ..RunOptions::default()
    };
    rtoracle::sandbox::facts::announce_on_stderr();
    let (command, folder) = if args.target.python_course.is_none() && args.target.adapter.is_none()
    {
        let here = Target {
            python_course: Some(current_submission()?),
            adapter: None,
        };
        (here.command(&args.sandbox)?, here.python_course)
    } else {
        (
            args.target.command(&args.sandbox)?,
            args.target.python_course.clone(),
        )
    };
    if let Some((week, week_from)) = week_of(args.week, folder.as_deref()) {
        errln!("checking as {week} ({week_from})");
        let functions = FunctionOptions {
            seed: args.seed,
            alpha: args.alpha,
        };
        let mut report =
            check_week(command, &cases, options, week, week_from, functions).context("check")?;
        report.intersections.judged_by = Some(judged_by);
        report.intersections.required = args.require.clone();
        let text = if args.json {
            report.document().to_json()
        } else {
            report.to_text(args.show)
        };
        outln!("{}", text.trim_end())?;
        return Ok(ExitCode::from(if report.passed() {
            0
        } else {
            crate::cli::FAILED
        }));
    }
    let mut report = check_command(command, &cases, options).context("check")?;
    report.judged_by = Some(judged_by);
    report.required = args.require.clone();
    let text = if args.json {
        let why = match (&folder, args.week) {
            (None, _) => "an adapter: the intersection vectors only",
            (Some(_), Some(_)) => "--week 4: the intersection vectors only",
            (Some(_), None) => {
                "no file of a later week in the folder: the intersection vectors only"
            }
        };
        CheckDocument::intersections(&report, why).to_json()
    } else {
        report.to_text(args.show)
    };
    outln!("{}", text.trim_end())?;
    Ok(ExitCode::from(if report.passed() {
        0
    } else {
        crate::cli::FAILED
    }))
}

/// The week to check as, and how it was found: `--week N` (4 is intersections only), else the
/// week a course folder's files show (`None`: week 4).
fn week_of(given: Option<u8>, folder: Option<&std::path::Path>) -> Option<(Week, String)> {
    match given {
        Some(n) => Week::new(n).map(|w| (w, format!("--week {n}"))),
        None => {
            let found = detect(folder?);
            let week = found.week?;
            let shown: Vec<String> = found
                .because
                .iter()
                .take(3)
                .map(|b| rtoracle::escape::terminal_line(b))
                .collect();
            let mut why = format!("found from the files: {}", shown.join(", "));
            for aside in &found.set_aside {
                why.push_str("; ");
                why.push_str(&rtoracle::escape::terminal_line(aside));
            }
            Some((week, why))
        }
    }
}
