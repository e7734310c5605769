//! `rtoracle fuzz`: differential fuzzing of a candidate with shrinking.

use std::io::IsTerminal;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rtoracle::candidate::fuzzing::fuzz::{FuzzOptions, fuzz};
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::candidate::process::session::Session;
use rtoracle::oracle::vectors::ShapeKind;

/// Cases run when neither `--cases` nor `--time` is given.
const DEFAULT_CASES: usize = 10_000;

/// Longest `--time`: a week.
const MAX_TIME_SECS: f64 = 7.0 * 24.0 * 3600.0;

/// Shortest `--time`: a millisecond (one round is always run).
const MIN_TIME_SECS: f64 = 1e-3;

/// `rtoracle fuzz`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    target: crate::cli::checking::check::Target,
    #[command(flatten)]
    judging: crate::cli::args::JudgingArgs,
    #[command(flatten)]
    sandbox: crate::cli::checking::check::SandboxArgs,
    /// How many random cases to run (default 10000 when --time is not given; with both,
    /// whichever comes first).
    #[arg(long, value_name = "N", value_parser = crate::cli::args::count)]
    cases: Option<usize>,
    /// Seed of the generator.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// Run for this many seconds (checked between rounds of 1000 cases; shrinking what was
    /// found takes a tenth of it more, at least 0.2 s and at most 5 s).
    #[arg(long, value_name = "SECS", value_parser = crate::cli::args::seconds)]
    time: Option<f64>,
    /// Time allowed per case, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 2000, value_parser = crate::cli::args::millis)]
    timeout_ms: u64,
    /// Time allowed for the candidate to start and answer the hello, in milliseconds.
    #[arg(long, value_name = "N", default_value_t = 10_000, value_parser = crate::cli::args::millis)]
    hello_timeout_ms: u64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Also write the minimal failing cases to this vector file (JSON lines), for
    /// `rtoracle check --vectors`; nothing is written when nothing fails.
    #[arg(long, value_name = "FILE")]
    save: Option<std::path::PathBuf>,
}

/// `--time` as a duration, or why it cannot be one.
fn time_limit(secs: Option<f64>) -> anyhow::Result<Option<Duration>> {
    match secs {
        None => Ok(None),
        Some(s) if s.is_finite() && (MIN_TIME_SECS..=MAX_TIME_SECS).contains(&s) => {
            Ok(Some(Duration::from_secs_f64(s)))
        }
        Some(s) => anyhow::bail!(
            "--time {s:?}: give a number of seconds from {MIN_TIME_SECS} to {MAX_TIME_SECS} (a week)"
        ),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.cases == Some(0) {
        anyhow::bail!("--cases 0: at least one case is needed");
    }
    let time = time_limit(args.time)?;
    let cases = match (args.cases, time) {
        (None, None) => Some(DEFAULT_CASES),
        (cases, _) => cases,
    };
    args.target.check()?;
    if let Some(path) = &args.save {
        rtoracle::output::check_output_file(path, "--save")?;
    }
    let options = RunOptions {
        timeout: Duration::from_millis(args.timeout_ms),
        hello_timeout: Duration::from_millis(args.hello_timeout_ms),
        limits: args.sandbox.policy(),
        ..RunOptions::default()
    };
    rtoracle::sandbox::facts::announce_on_stderr();
    let command = args.target.command(&args.sandbox)?;
    let mut session = Session::start(command, options).context("fuzz")?;
    if let Some(e) = &session.hello().error {
        errln!(
            "rtoracle: the submission cannot be imported: {}",
            rtoracle::escape::terminal_line(&e.to_string())
        );
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
        cases,
        seed: args.seed,
        time,
        judging: args.judging.judging(args.target.default_profile()),
        course_api: session.command().is_course_adapter(),
        ..FuzzOptions::default()
    };
    // Progress on stderr when it is a terminal: cases run (shrinking included).
    let progress = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(
            fuzz_options.cases.map(|n| n as u64),
            ProgressDrawTarget::stderr(),
        );
        let template = if fuzz_options.cases.is_some() {
            "fuzzing {bar:40} {pos}/{len} cases, {elapsed}"
        } else {
            "fuzzing {pos} cases, {elapsed}"
        };
        bar.set_style(ProgressStyle::with_template(template).expect("a valid progress template"));
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut report = fuzz(
        &mut |cases| {
            let outcomes = session.run(cases);
            progress.inc(cases.len() as u64);
            outcomes
        },
        &fuzz_options,
    )
    .context("fuzz")?;
    progress.finish_and_clear();
    report.notes = session.notes().to_vec();
    if let Some(path) = &args.save {
        if report.failures.is_empty() {
            errln!(
                "rtoracle: nothing failed, so {} was not written",
                path.display()
            );
        } else {
            let text: String = report
                .failures
                .iter()
                .map(|f| f.minimal.to_json_line() + "\n")
                .collect();
            rtoracle::image_io::write_atomically(path, text.as_bytes())?;
        }
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&report)?)?;
    } else {
        out!("{}", report.to_text())?;
    }
    Ok(ExitCode::from(if report.failed == 0 {
        0
    } else {
        crate::cli::FAILED
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_limits_outside_a_millisecond_to_a_week_are_refused() {
        for bad in [1e308, 1e-300, f64::NAN, f64::INFINITY, 0.0, -1.0, 1e6] {
            let err = time_limit(Some(bad)).unwrap_err().to_string();
            assert!(err.starts_with("--time "), "{err}");
        }
        assert_eq!(time_limit(Some(6.0)).unwrap(), Some(Duration::from_secs(6)));
        assert_eq!(time_limit(None).unwrap(), None);
    }
}
