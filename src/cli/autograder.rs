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
    /// The seed of the suite to package (default: the rubric's when non-zero, else a secret one
    /// drawn from the OS, so students cannot know the vectors in advance).
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (rubric_text, rubric_seed) = match &args.rubric {
        Some(path) => {
            // Validate it now, so a bad rubric fails here and not on Gradescope.
            let rubric = Rubric::from_file(path)?;
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("{}: cannot read the rubric", path.display()))?;
            (text, rubric.seed)
        }
        None => (
            rtoracle::grade::rubric::WEEK04_RUBRIC.to_string(),
            Rubric::week04().seed,
        ),
    };
    if args.seed.is_some_and(|s| s > i64::MAX as u64) {
        anyhow::bail!(
            "--seed {}: at most {} (a TOML integer)",
            args.seed.unwrap_or(0),
            i64::MAX
        );
    }
    let (seed, how) = match (args.seed, rubric_seed) {
        (Some(s), _) => (s, "from --seed"),
        (None, s) if s != 0 => (s, "the rubric's"),
        (None, _) => (
            autograder::secret_seed().context("cannot draw a secret seed from /dev/urandom")?,
            "secret, drawn now",
        ),
    };
    let rubric_text = autograder::with_seed(&rubric_text, seed);
    let binary = match args.binary {
        Some(b) => b,
        None => std::env::current_exe().context("cannot find the running rtoracle binary")?,
    };
    autograder::build_package(&binary, &rubric_text, &args.out)?;
    eprintln!(
        "wrote {} (setup.sh, run_autograder, rubric.toml with seed {seed} ({how}), rtoracle from {}); upload it as the assignment's autograder",
        args.out.display(),
        binary.display()
    );
    Ok(ExitCode::SUCCESS)
}
