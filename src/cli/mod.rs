//! The command line: one module per subcommand, each with its clap arguments and a `run`.

#[macro_use]
mod out;

mod autograder;
mod bench;
mod check;
mod compare;
mod explain;
mod fuzz;
mod golden;
mod grade;
mod render;
mod scenes;
mod vectors;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    Render(render::Args),
    /// List the built-in scenes, or print one as TOML.
    Scenes(scenes::Args),
    /// Write or verify the golden EXRs of the built-in scenes.
    Golden(golden::Args),
    /// Export intersection test vectors as JSON lines.
    Vectors(vectors::Args),
    /// Explain, step by step, the oracle's answer for one vector.
    Explain(explain::Args),
    /// Check an implementation against the intersection vectors.
    Check(check::Args),
    /// Differential fuzzing of an implementation against the oracle, with shrinking.
    Fuzz(fuzz::Args),
    /// Compare a rendered image with a golden, telling Monte Carlo noise from bugs.
    Compare(compare::Args),
    /// Grade a submission (or a folder of them) and write the reports.
    Grade(grade::Args),
    /// Build a Gradescope autograder package.
    Autograder(autograder::Args),
    /// Measure speed (renderer, oracle, comparison) against baselines in the same run.
    Bench(bench::Args),
}

/// Exit code of a verdict that failed.
#[allow(dead_code)]
pub const FAILED: u8 = 1;

/// Parses the arguments and runs the subcommand. Usage errors exit 2 through clap.
pub fn run() -> anyhow::Result<ExitCode> {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return Ok(ExitCode::from(code));
        }
    };
    match cli.command {
        Command::Render(args) => render::run(args),
        Command::Scenes(args) => scenes::run(args),
        Command::Golden(args) => golden::run(args),
        Command::Vectors(args) => vectors::run(args),
        Command::Explain(args) => explain::run(args),
        Command::Check(args) => check::run(args),
        Command::Fuzz(args) => fuzz::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Grade(args) => grade::run(args),
        Command::Autograder(args) => autograder::run(args),
        Command::Bench(args) => bench::run(args),
    }
}
