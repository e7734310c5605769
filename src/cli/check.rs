//! `rtoracle check`: runs a candidate against the intersection vectors.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::candidate::{CandidateCommand, RunOptions, check_command};
use rtoracle::oracle::{default_suite, vectors::read_vectors};

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

impl Target {
    /// The command to run.
    pub fn command(&self) -> anyhow::Result<CandidateCommand> {
        Ok(match (&self.python_course, &self.adapter) {
            (Some(dir), _) => CandidateCommand::python_course(dir)?,
            (_, Some(cmd)) => CandidateCommand::adapter(cmd)?,
            _ => unreachable!("clap requires one"),
        })
    }
}

/// `rtoracle check`.
#[derive(Debug, clap::Args)]
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
    let command = args.target.command()?;
    let report = check_command(command, &cases, options).context("check")?;
    let text = if args.json {
        report.to_json()
    } else {
        report.to_text(args.show)
    };
    print_stdout(&format!("{}\n", text.trim_end()))?;
    Ok(ExitCode::from(if report.passed() {
        0
    } else {
        super::FAILED
    }))
}

/// Writes `text` to stdout; a reader that went away (`| head -1`) is not an error: the rest is
/// dropped quietly, as ripgrep does.
pub(super) fn print_stdout(text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::new(e).context("cannot write to stdout"))
        }
        _ => Ok(()),
    }
}
