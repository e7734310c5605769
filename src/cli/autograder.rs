use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::grade::{Rubric, autograder};

/// `rtoracle autograder --out autograder.zip [--rubric FILE.toml] [--binary PATH]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The package to write.
    #[arg(long, value_name = "ZIP", default_value = "autograder.zip")]
    out: PathBuf,
    /// The rubric to grade with (default: the built-in week-4 rubric).
    #[arg(long, value_name = "FILE.toml")]
    rubric: Option<PathBuf>,
    /// The rtoracle binary to pack (default: this one). It must be an x86_64 Linux executable,
    /// as Gradescope's machines are.
    #[arg(long, value_name = "PATH")]
    binary: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let rubric_text = match &args.rubric {
        Some(path) => {
            // Validate it now, so a bad rubric fails here and not on Gradescope.
            Rubric::from_file(path)?;
            std::fs::read_to_string(path)
                .with_context(|| format!("{}: cannot read the rubric", path.display()))?
        }
        None => rtoracle::grade::rubric::WEEK04_RUBRIC.to_string(),
    };
    let binary = match args.binary {
        Some(b) => b,
        None => std::env::current_exe().context("cannot find the running rtoracle binary")?,
    };
    autograder::build_package(&binary, &rubric_text, &args.out)?;
    eprintln!(
        "wrote {} (setup.sh, run_autograder, rubric.toml, rtoracle from {}); upload it as the assignment's autograder",
        args.out.display(),
        binary.display()
    );
    Ok(ExitCode::SUCCESS)
}
