use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::grade::{CourseCodeChecker, Format, Rubric, batch, grade_to_dir};
use rtoracle::oracle::vectors::read_vectors;

/// `rtoracle grade SUBMISSION_DIR [--rubric FILE.toml] [--vectors FILE.jsonl] [--out DIR] [--format all|json,gradescope,junit,markdown]`
/// or `rtoracle grade --batch DIR --out OUT`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A submission folder in the course's layout (RT_object.py, week04_sphere.png, week04_quad.png).
    #[arg(required_unless_present_any = ["batch", "print_rubric"], conflicts_with = "batch")]
    submission: Option<PathBuf>,
    /// Grade every sub-folder of DIR as a submission, in parallel, and write a gradebook.
    #[arg(long, value_name = "DIR")]
    batch: Option<PathBuf>,
    /// The rubric (TOML); default: the built-in week-4 rubric (see --print-rubric).
    #[arg(long, value_name = "FILE.toml")]
    rubric: Option<PathBuf>,
    /// The report folder (created).
    #[arg(long, value_name = "DIR", default_value = "grade-report")]
    out: PathBuf,
    /// Which reports: all, or a comma list of json, gradescope, junit, markdown.
    #[arg(long, value_name = "LIST", default_value = "all")]
    format: String,
    /// A vector file (as `rtoracle vectors` writes) to run instead of the built-in suite.
    #[arg(long, value_name = "FILE.jsonl")]
    vectors: Option<PathBuf>,
    /// Wall-clock limit per test vector, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 2000)]
    case_timeout_ms: u64,
    /// Worker threads for --batch (default: all cores).
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
    /// The Python 3 that runs the submissions (it must have the rubric's python_requires,
    /// default numpy and PIL); default: $RTORACLE_PYTHON, else the first of /usr/bin/python3,
    /// /usr/local/bin/python3, python3 on PATH, ... that has them.
    #[arg(long, value_name = "PATH")]
    python: Option<PathBuf>,
    /// Print the rubric in use (the built-in one unless --rubric) and exit.
    #[arg(long)]
    print_rubric: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let rubric = match &args.rubric {
        Some(path) => Rubric::from_file(path)?,
        None => Rubric::week04(),
    };
    if args.print_rubric {
        match &args.rubric {
            Some(path) => print!("{}", std::fs::read_to_string(path)?),
            None => print!("{}", rtoracle::grade::rubric::WEEK04_RUBRIC),
        }
        return Ok(ExitCode::SUCCESS);
    }
    let formats = Format::parse_list(&args.format)?;
    if args.threads == Some(0) {
        anyhow::bail!("--threads 0: at least one thread is needed");
    }
    if args.case_timeout_ms == 0 {
        anyhow::bail!("--case-timeout-ms 0: the limit must be at least 1 ms");
    }
    let vectors = match &args.vectors {
        Some(path) => Some((path.display().to_string(), read_vectors(path)?)),
        None => None,
    };
    // Before grading anything: a sandbox that keeps the code from running as root (fail
    // closed), and a Python with the rubric's modules that the sandbox user can run.
    let policy = rtoracle::sandbox::SandboxPolicy::grading();
    let python = rtoracle::candidate::python::choose(
        args.python.as_deref(),
        &rubric.python_requires,
        &policy,
    )?;
    rtoracle::sandbox::announce_on_stderr();
    let code = CourseCodeChecker {
        seed: rubric.seed,
        vectors,
        case_timeout: Duration::from_millis(args.case_timeout_ms),
        policy,
        python: Some(python),
        python_requires: rubric.python_requires.clone(),
        ..Default::default()
    };
    let images = rtoracle::compare::CompareImageChecker::default();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;

    if let Some(dir) = &args.batch {
        let entries =
            pool.install(|| batch::grade_batch(dir, &rubric, &code, &images, &args.out, &formats))?;
        let graded = entries.iter().filter(|e| e.result.is_ok()).count();
        for e in &entries {
            match &e.result {
                Ok(r) => println!("{}: {} / {}", e.name, r.score, r.max_score),
                Err(msg) => println!("{}: not graded: {msg}", e.name),
            }
        }
        eprintln!(
            "graded {graded} of {} submissions; gradebook in {}",
            entries.len(),
            args.out.join("gradebook.csv").display()
        );
        return Ok(ExitCode::SUCCESS);
    }

    let submission = args.submission.as_ref().expect("clap requires it");
    let report =
        pool.install(|| grade_to_dir(submission, &rubric, &code, &images, &args.out, &formats))?;
    for c in &report.checks {
        println!(
            "{:<24} {:>6} / {:<6} {}",
            c.id,
            c.score,
            c.max_score,
            c.status.name()
        );
    }
    println!(
        "{:<24} {:>6} / {:<6}",
        "total", report.score, report.max_score
    );
    eprintln!(
        "graded {} in {:.2} s; reports in {}",
        report.submission,
        report.execution_time,
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
