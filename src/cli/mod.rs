//! The command line: one module per subcommand, each with its clap arguments and a `run`, in
//! rooms by what the subcommands are for, in the order `rtoracle --help` lists them:
//! [`reference`] (render, scenes, golden, vectors, explain), [`checking`] (check, fuzz, physics,
//! compare), [`grading`] (grade, autograder) and [`bench`]; `out` (stdout and stderr that a
//! closed pipe cannot make panic) and `args` (the options several share) serve them all.

#[macro_use]
mod out;
mod args;

mod reference;
mod checking;
mod grading;
mod bench;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// A test oracle and verification harness for ray tracers.
#[derive(Debug, Parser)]
#[command(name = "rtoracle", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Render a built-in scene or a TOML scene file to PNG or EXR.
    Render(reference::render::Args),
    /// List the built-in scenes, or print one as TOML.
    Scenes(reference::scenes::Args),
    /// Write or verify the golden EXRs of the built-in scenes.
    Golden(reference::golden::Args),
    /// Export intersection test vectors as JSON lines.
    Vectors(reference::vectors::Args),
    /// Explain, step by step, the oracle's answer for one vector.
    Explain(reference::explain::Args),
    /// Check an implementation against the intersection vectors.
    ///
    /// Exit codes: 0 every vector run passed (shapes the candidate does not support are not run,
    /// and said so; `--require triangle` makes that a failure), 1 a vector failed, 2 bad input or
    /// a harness error.
    Check(checking::check::Args),
    /// Differential fuzzing of an implementation against the oracle, with shrinking.
    Fuzz(checking::fuzz::Args),
    /// Physics checks that need no golden: a renderer's materials (sampling, pdf, weights,
    /// energy, reciprocity) through the protocol's material requests.
    ///
    /// Exit codes: 0 every law held (findings about a model aside), 1 a law failed or nothing
    /// could be checked, 2 bad input or a harness error.
    Physics(checking::physics::Args),
    /// Compare a rendered image with a golden, telling Monte Carlo noise from bugs; or two
    /// renders of the same scene with no golden (`compare A B`).
    ///
    /// `compare A B` judges A against B by Welch's two-sample t-test at the same four scales and
    /// the same per-image false-failure rate (1e-4) as against a golden. Each side is an EXR with
    /// a variance layer and an rtoracle.spp attribute (`rtoracle render --variance`), or a
    /// folder of EXR renders of the scene with different seeds.
    ///
    /// Exit codes: 0 PASS (the differences are noise), 1 FAIL, 2 bad input.
    Compare(checking::compare::Args),
    /// Grade a submission (or a folder of them with --batch) and write the reports.
    ///
    /// Exit codes: 0 graded (whatever the score; the score is in the reports), 2 bad input or
    /// a harness error.
    Grade(grading::grade::Args),
    /// Build a Gradescope autograder package.
    Autograder(grading::autograder::Args),
    /// Measure speed (render, oracle, candidate, compare, grade) against baselines in the same run.
    Bench(bench::Args),
}

/// Exit code of a verdict that failed.
#[allow(dead_code)]
pub const FAILED: u8 = 1;

/// Parses the arguments and runs the subcommand. Usage errors are one line on stderr and exit 2.
pub fn run() -> anyhow::Result<ExitCode> {
    let command = args::allow_negative_numbers(Cli::command());
    let parsed = command
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version: the whole text, on stdout.
            out::print(&e.render().to_string())?;
            return Ok(ExitCode::SUCCESS);
        }
        Err(e) => {
            errln!(
                "rtoracle: {}",
                one_line_usage_error(&e.render().to_string())
            );
            return Ok(ExitCode::from(2));
        }
    };
    match cli.command {
        Command::Render(args) => reference::render::run(args),
        Command::Scenes(args) => reference::scenes::run(args),
        Command::Golden(args) => reference::golden::run(args),
        Command::Vectors(args) => reference::vectors::run(args),
        Command::Explain(args) => reference::explain::run(args),
        Command::Check(args) => checking::check::run(args),
        Command::Fuzz(args) => checking::fuzz::run(args),
        Command::Physics(args) => checking::physics::run(args),
        Command::Compare(args) => checking::compare::run(args),
        Command::Grade(args) => grading::grade::run(args),
        Command::Autograder(args) => grading::autograder::run(args),
        Command::Bench(args) => bench::run(args),
    }
}

/// The subcommand the user typed (for the pointer to its `--help`), if any.
fn subcommand_typed() -> Option<String> {
    let names: Vec<String> = Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let first = args.iter().find(|a| !a.starts_with('-'))?;
    if !names.contains(first) {
        return None;
    }
    // `bench AREA`: point to the area's help.
    let rest = args.iter().skip_while(|a| *a != first).skip(1);
    let sub = Cli::command().find_subcommand(first)?.clone();
    let second = rest.into_iter().find(|a| !a.starts_with('-'));
    match second {
        Some(area) if sub.find_subcommand(area).is_some() => Some(format!("{first} {area}")),
        _ => Some(first.clone()),
    }
}

/// Clap's error as one line: its first line without the `error: ` prefix (with the list that
/// follows a line ending in `:` joined onto it), then where to look.
fn one_line_usage_error(rendered: &str) -> String {
    let mut lines = rendered.lines();
    let mut line = lines
        .next()
        .unwrap_or("bad arguments")
        .trim_start_matches("error: ")
        .to_string();
    if line.ends_with(':') {
        let items: Vec<&str> = lines
            .take_while(|l| l.starts_with("  "))
            .map(str::trim)
            .collect();
        line = format!("{} {}", line, items.join(", "));
    }
    let help = match subcommand_typed() {
        Some(sub) => format!("rtoracle {sub} --help"),
        None => "rtoracle --help".to_string(),
    };
    format!("{line} (see '{help}')")
}
