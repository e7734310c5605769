//! `rtoracle check`: runs a candidate against the intersection vectors.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::candidate::{CandidateCommand, RunOptions, check_command};
use rtoracle::oracle::{default_suite, vectors::read_vectors};

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

impl Target {
    /// The command to run.
    pub fn command(&self) -> anyhow::Result<CandidateCommand> {
        Ok(match (&self.python_course, &self.adapter) {
            (Some(dir), _) => CandidateCommand::python_course(dir)?,
            (_, Some(cmd)) => CandidateCommand::adapter(cmd)?,
            _ => anyhow::bail!("give the candidate: --python-course DIR or --adapter 'CMD ARGS'"),
        })
    }
}

/// `rtoracle check`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Without --python-course or --adapter, checks the course submission in the current folder (as --python-course .)."
)]
pub struct Args {
    #[command(flatten)]
    target: Target,
    /// A vector file (JSON lines); the built-in suite when absent.
    #[arg(long, value_name = "FILE")]
    vectors: Option<PathBuf>,
    /// Seed of the built-in suite.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Time allowed per case, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 2000)]
    timeout_ms: u64,
    /// Time allowed for the candidate to start and answer the hello, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 10_000)]
    hello_timeout_ms: u64,
    /// Print the whole report as one JSON object on stdout.
    #[arg(long)]
    json: bool,
    /// Failures shown in the text report.
    #[arg(long, value_name = "N", default_value_t = 10)]
    show: usize,
}

/// `rtoracle check` with no candidate: the course submission in the current folder, as
/// `--python-course .`, announced on stderr (stdout stays the report, JSON with `--json`).
fn current_submission() -> anyhow::Result<CandidateCommand> {
    let here = std::env::current_dir().context("cannot read the current folder")?;
    let shown = rtoracle::escape::terminal_line(&here.display().to_string());
    if !here.join("RT_object.py").is_file() {
        anyhow::bail!(
            "no RT_object.py in {shown}: run `rtoracle check` in a course submission folder (RT_utility.py, RT_ray.py, RT_object.py), or give --python-course DIR or --adapter 'CMD ARGS'"
        );
    }
    eprintln!("checking the course submission in {shown} (as --python-course .)");
    Ok(CandidateCommand::python_course(&here)?)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let cases = match &args.vectors {
        Some(path) => read_vectors(path)?,
        None => default_suite(args.seed),
    };
    if args.timeout_ms == 0 || args.hello_timeout_ms == 0 {
        anyhow::bail!("--timeout-ms and --hello-timeout-ms must be positive");
    }
    let options = RunOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        hello_timeout: Duration::from_millis(args.hello_timeout_ms),
        ..RunOptions::default()
    };
    let command = if args.target.python_course.is_none() && args.target.adapter.is_none() {
        current_submission()?
    } else {
        args.target.command()?
    };
    let report = check_command(command, &cases, options).context("check")?;
    let text = if args.json {
        report.to_json()
    } else {
        report.to_text(args.show)
    };
    println!("{}", text.trim_end());
    Ok(ExitCode::from(if report.passed() {
        0
    } else {
        super::FAILED
    }))
}
