//! `rtoracle check`: runs a candidate against the intersection vectors.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::candidate::{CandidateCommand, RunOptions, SandboxPolicy, check_command, python};
use rtoracle::oracle::{default_suite, vectors::read_vectors};
use rtoracle::sandbox::SandboxError;

/// Which candidate to run (shared by `check` and `fuzz`).
#[derive(Debug, clap::Args)]
#[group(required = true, multiple = false)]
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
}

impl SandboxArgs {
    /// The sandbox policy of `check` and `fuzz`.
    pub fn policy(&self) -> SandboxPolicy {
        SandboxPolicy {
            unsandboxed: self.unsandboxed,
            ..SandboxPolicy::default()
        }
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
        let policy = sandbox.policy();
        rtoracle::sandbox::isolation_for(&policy).map_err(with_hint)?;
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
                CandidateCommand::python_course_with(dir, Some(&python), false)?
            }
            (_, Some(cmd)) => {
                if sandbox.python.is_some() {
                    anyhow::bail!(
                        "--python is for --python-course; put the interpreter in the --adapter command"
                    );
                }
                CandidateCommand::adapter(cmd)?
            }
            _ => unreachable!("clap requires one"),
        })
    }
}

/// `rtoracle check`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    target: Target,
    #[command(flatten)]
    sandbox: SandboxArgs,
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
        limits: args.sandbox.policy(),
        ..RunOptions::default()
    };
    rtoracle::sandbox::announce_on_stderr();
    let command = args.target.command(&args.sandbox)?;
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
