//! The command line: one module per subcommand, each with its clap arguments and a `run`.

mod render;
mod scenes;

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
    }
}
