//! `rtoracle fuzz`: differential fuzzing of a candidate with shrinking.

use std::io::IsTerminal;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rtoracle::candidate::fuzz::{FuzzOptions, fuzz};
use rtoracle::candidate::{RunOptions, Session};
use rtoracle::oracle::vectors::ShapeKind;

/// `rtoracle fuzz`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    target: super::check::Target,
    #[command(flatten)]
    sandbox: super::check::SandboxArgs,
    /// How many random cases to run.
    #[arg(long, value_name = "N", default_value_t = 10_000)]
    cases: usize,
    /// Seed of the generator.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Stop after this many seconds (checked between rounds of 1000 cases).
    #[arg(long, value_name = "SECS")]
    time: Option<f64>,
    /// Time allowed per case, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 2000)]
    timeout_ms: u64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Also write the minimal failing cases to this vector file (JSON lines), for
    /// `rtoracle check --vectors`.
    #[arg(long, value_name = "FILE")]
    save: Option<std::path::PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.timeout_ms == 0 {
        anyhow::bail!("--timeout-ms must be positive");
    }
    let time = match args.time {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 => Some(Duration::from_secs_f64(s)),
        Some(s) => anyhow::bail!("--time must be a positive number of seconds, not {s}"),
    };
    let options = RunOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        limits: args.sandbox.policy(),
        ..RunOptions::default()
    };
    rtoracle::sandbox::announce_on_stderr();
    let command = args.target.command(&args.sandbox)?;
    let mut session = Session::start(command, options).context("fuzz")?;
    if let Some(e) = &session.hello().error {
        eprintln!("rtoracle: the submission cannot be imported: {e}");
    }
    let kinds: Vec<ShapeKind> = ShapeKind::ALL
        .into_iter()
        .filter(|&k| session.hello().supports(k))
        .collect();
    if kinds.is_empty() {
        anyhow::bail!("the candidate supports none of sphere, quad, triangle");
    }
    let fuzz_options = FuzzOptions {
        kinds,
        cases: args.cases,
        seed: args.seed,
        time,
        ..FuzzOptions::default()
    };
    // Progress on stderr when it is a terminal: cases run (shrinking included).
    let progress = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(
            Some(fuzz_options.cases as u64),
            ProgressDrawTarget::stderr(),
        );
        bar.set_style(
            ProgressStyle::with_template("fuzzing {bar:40} {pos}/{len} cases, {elapsed}")
                .expect("a valid progress template"),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let report = fuzz(
        &mut |cases| {
            let outcomes = session.run(cases);
            progress.inc(cases.len() as u64);
            outcomes
        },
        &fuzz_options,
    )
    .context("fuzz")?;
    progress.finish_and_clear();
    if let Some(path) = &args.save {
        let text: String = report
            .failures
            .iter()
            .map(|f| f.minimal.to_json_line() + "\n")
            .collect();
        rtoracle::image_io::write_atomically(path, text.as_bytes())?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    Ok(ExitCode::from(if report.failed == 0 {
        0
    } else {
        super::FAILED
    }))
}
