use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::grade::{Rubric, autograder, pack};

/// `rtoracle autograder --out autograder.zip [--rubric FILE.toml] [--binary PATH]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The package to write.
    #[arg(long, value_name = "ZIP", default_value = "autograder.zip")]
    out: PathBuf,
    /// The rubric to grade with (default: the built-in week-4 rubric). Its scene files and
    /// their goldens are packed too (missing goldens are rendered now), so Gradescope never
    /// renders.
    #[arg(long, value_name = "FILE.toml")]
    rubric: Option<PathBuf>,
    /// The rtoracle binary to pack (default: this one). It must be an x86_64 Linux executable,
    /// as Gradescope's machines are.
    #[arg(long, value_name = "PATH")]
    binary: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let binary = match args.binary {
        Some(b) => b,
        None => std::env::current_exe().context("cannot find the running rtoracle binary")?,
    };
    // Refuse a wrong binary before rendering any golden.
    autograder::check_binary(&binary)?;
    let packed = match &args.rubric {
        Some(path) => {
            // Validate it now, so a bad rubric fails here and not on Gradescope.
            let rubric = Rubric::from_file(path)?;
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("{}: cannot read the rubric", path.display()))?;
            pack::pack_rubric(&rubric, &text)?
        }
        None => pack::PackedRubric {
            rubric_toml: rtoracle::grade::rubric::WEEK04_RUBRIC.to_string(),
            files: vec![],
            rendered: 0,
        },
    };
    autograder::build_package_with(&binary, &packed.rubric_toml, &packed.files, &args.out)?;
    let scenes = if packed.files.is_empty() {
        String::new()
    } else {
        let n = packed.files.len() / 2;
        let s = if n == 1 { "" } else { "s" };
        format!(
            ", {n} scene file{s} and golden{s} in {}/",
            pack::PACKED_SCENES
        )
    };
    eprintln!(
        "wrote {} (setup.sh, run_autograder, rubric.toml, rtoracle from {}{scenes}); upload it as the assignment's autograder",
        args.out.display(),
        binary.display()
    );
    Ok(ExitCode::SUCCESS)
}
