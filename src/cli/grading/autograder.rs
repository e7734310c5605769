use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::grade::autograder::{self, pack};
use rtoracle::grade::rubric::Rubric;

/// `rtoracle autograder --out autograder.zip [--rubric NAME|FILE.toml] [--binary PATH]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The package to write.
    #[arg(long, value_name = "ZIP", default_value = "autograder.zip")]
    out: PathBuf,
    /// The rubric to grade with: a built-in one by name (week04 ... week10) or a TOML file
    /// (default: the built-in week04). A file's scene files and
    /// their goldens are packed too (missing goldens are rendered now), so Gradescope never
    /// renders.
    #[arg(long, value_name = "NAME|FILE.toml")]
    rubric: Option<PathBuf>,
    /// The rtoracle binary to pack (default: this one). It must be an x86_64 Linux executable,
    /// as Gradescope's machines are.
    #[arg(long, value_name = "PATH")]
    binary: Option<PathBuf>,
    /// The seed of the suite to package (default: the rubric's when non-zero, else a secret one
    /// drawn from the OS, so students cannot know the vectors in advance).
    #[arg(long, value_name = "N", value_parser = crate::cli::args::seed)]
    seed: Option<u64>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    rtoracle::output::check_output_file(&args.out, "--out")?;
    if let Some(binary) = &args.binary {
        check_is_rtoracle(binary)?;
    }
    if args.seed.is_some_and(|s| s > i64::MAX as u64) {
        anyhow::bail!(
            "--seed {}: at most {} (a TOML integer)",
            args.seed.unwrap_or(0),
            i64::MAX
        );
    }
    let binary = match args.binary {
        Some(b) => b,
        None => std::env::current_exe().context("cannot find the running rtoracle binary")?,
    };
    // Refuse a wrong binary before rendering any golden.
    autograder::check_binary(&binary)?;
    let (packed, rubric_seed, runs_code) = match &args.rubric {
        Some(path) => {
            // Validate it now, so a bad rubric fails here and not on Gradescope.
            let (rubric, text) = Rubric::named(path)?;
            let runs_code = rubric.week.is_some()
                || rubric
                    .groups
                    .iter()
                    .any(|g| g.kind == rtoracle::grade::rubric::GroupKind::Code);
            (pack::pack_rubric(&rubric, &text)?, rubric.seed, runs_code)
        }
        None => (
            pack::PackedRubric {
                rubric_toml: rtoracle::grade::rubric::WEEK04_RUBRIC.to_string(),
                files: vec![],
                rendered: 0,
            },
            Rubric::week04().seed,
            true,
        ),
    };
    let (seed, how) = match (args.seed, rubric_seed) {
        (Some(s), _) => (s, "from --seed"),
        (None, s) if s != 0 => (s, "the rubric's"),
        (None, _) => (
            autograder::secret_seed().context("cannot draw a secret seed from /dev/urandom")?,
            "secret, drawn now",
        ),
    };
    // A rubric of images only draws no vectors: its seed is there but unused.
    let how = if runs_code {
        how
    } else {
        "unused: the rubric has no code group"
    };
    let rubric_text = autograder::with_seed(&packed.rubric_toml, seed);
    autograder::build_package_with(&binary, &rubric_text, &packed.files, &args.out)?;
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
    errln!(
        "wrote {} (setup.sh, run_autograder, rubric.toml with seed {seed} ({how}), rtoracle from {}{scenes}); upload it as the assignment's autograder",
        args.out.display(),
        binary.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Checks that `binary` is an rtoracle: run with `--version` it prints `rtoracle VERSION`, as
/// this binary does. (The package runs it on Gradescope; anything else would fail there, on
/// every student's submission.) It runs in a fresh empty folder, with a time limit.
fn check_is_rtoracle(binary: &std::path::Path) -> anyhow::Result<()> {
    use std::process::{Command, Stdio};
    let refuse = |why: String| anyhow::anyhow!("--binary {}: {why}", binary.display());
    if binary.is_dir() {
        return Err(refuse("is a folder; the rtoracle binary is wanted".into()));
    }
    if !binary.is_file() {
        return Err(refuse("no such file".into()));
    }
    // Not an ELF at all: the package builder says what it must be, without running it.
    let mut magic = [0u8; 4];
    let is_elf = std::fs::File::open(binary)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic))
        .is_ok()
        && magic == *b"\x7fELF";
    if !is_elf {
        return Ok(());
    }
    let (dir, _cleanup) =
        rtoracle::interrupt::create_temporary(tempfile::tempdir, |t: &tempfile::TempDir| t.path())
            .map_err(|e| refuse(format!("cannot run it: {e}")))?;
    let mut child = Command::new(std::path::absolute(binary)?)
        .arg("--version")
        .current_dir(dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| refuse(format!("cannot run it: {e}")))?;
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    loop {
        match child.try_wait() {
            Ok(Some(_)) => break,
            Ok(None) if std::time::Instant::now() < deadline => {
                std::thread::sleep(std::time::Duration::from_millis(20))
            }
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(refuse(
                    "is not an rtoracle (it did not answer --version)".into(),
                ));
            }
        }
    }
    let output = child.wait_with_output()?;
    let text = String::from_utf8_lossy(&output.stdout);
    let first = text.lines().next().unwrap_or("");
    if !first.starts_with("rtoracle ") {
        return Err(refuse(format!(
            "is not an rtoracle (`--version` printed {:?}, not \"rtoracle VERSION\")",
            rtoracle::escape::truncate(first, 60)
        )));
    }
    let ours = format!("rtoracle {}", env!("CARGO_PKG_VERSION"));
    if first.trim() != ours {
        errln!(
            "rtoracle: note: --binary {} is {}, this is {ours}",
            binary.display(),
            rtoracle::escape::terminal_line(first.trim())
        );
    }
    Ok(())
}
