use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use rtoracle::escape::terminal_line;
use rtoracle::grade::{
    batch, checkers::ImageChecker, checkers::code::CourseCodeChecker, report::Format,
    rubric::Rubric, write::grade_to_dir,
};
use rtoracle::oracle::vectors::read_vectors;

/// `rtoracle grade SUBMISSION_DIR [--rubric FILE.toml] [--vectors FILE.jsonl] [--out DIR] [--format all|json,gradescope,junit,markdown]`
/// or `rtoracle grade --batch DIR [--shard K/N] --out OUT`, or `rtoracle grade --merge OUT... --out DIR`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A submission folder in the course's layout (RT_object.py, week04_sphere.png, week04_quad.png).
    #[arg(conflicts_with = "batch")]
    submission: Option<PathBuf>,
    /// Grade every sub-folder of DIR as a submission, in parallel, and write a gradebook.
    #[arg(long, value_name = "DIR")]
    batch: Option<PathBuf>,
    /// With --batch: grade only share K of N of its sub-folders (each folder's share follows
    /// from its name alone, so N runs with 1/N ... N/N, on any machines, grade each folder
    /// once); join their --out folders with --merge.
    #[arg(long, value_name = "K/N", requires = "batch", value_parser = batch::Shard::parse)]
    shard: Option<batch::Shard>,
    /// Join the --out folders of a batch's shards (--batch DIR --shard K/N) into --out: every
    /// submission's reports, and the gradebook and summary of the whole batch, as one run
    /// without --shard writes them.
    #[arg(long, value_name = "OUT", num_args = 1.., conflicts_with_all = ["submission", "batch"])]
    merge: Vec<PathBuf>,
    /// The rubric: a built-in one by name (week04 ... week10) or a TOML file; default: the
    /// built-in week04 (see --print-rubric).
    #[arg(long, value_name = "NAME|FILE.toml")]
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
    #[arg(long, value_name = "MS", default_value_t = 2000, value_parser = crate::cli::args::millis)]
    case_timeout_ms: u64,
    /// Worker threads for --batch (default: all cores).
    #[arg(long, value_name = "T", value_parser = crate::cli::args::threads)]
    threads: Option<usize>,
    /// The Python 3 that runs the submissions (it must have the rubric's python_requires,
    /// default numpy and PIL); default: $RTORACLE_PYTHON, else the first of /usr/bin/python3,
    /// /usr/local/bin/python3, python3 on PATH, ... that has them.
    #[arg(long, value_name = "PATH")]
    python: Option<PathBuf>,
    /// Print a rubric and exit: the built-in one named (week04 ... week10), else the one in use
    /// (--rubric's, or the built-in week04).
    #[arg(long, value_name = "NAME", num_args = 0..=1, default_missing_value = "")]
    print_rubric: Option<String>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if !args.merge.is_empty() {
        return run_merge(&args);
    }
    if let Some(name) = args.print_rubric.as_deref().filter(|n| !n.is_empty()) {
        let Some(text) = rtoracle::grade::rubric::weeks::builtin_rubric_toml(name) else {
            // `grade --print-rubric SUBMISSION` reads the folder as the rubric's name.
            let folder = if Path::new(name).is_dir() {
                "; it is a folder: to print the rubric in use, write --print-rubric= or put \
                 --print-rubric last"
            } else {
                ""
            };
            anyhow::bail!(
                "--print-rubric {}: not a built-in rubric (known: {}){folder}",
                terminal_line(name),
                rtoracle::grade::rubric::weeks::BUILTIN_RUBRICS.join(", ")
            );
        };
        out!("{text}")?;
        return Ok(ExitCode::SUCCESS);
    }
    let (rubric, text) = match &args.rubric {
        Some(path) => Rubric::named(path)?,
        None => (
            Rubric::week04(),
            rtoracle::grade::rubric::WEEK04_RUBRIC.to_string(),
        ),
    };
    if args.print_rubric.is_some() {
        out!("{text}")?;
        return Ok(ExitCode::SUCCESS);
    }
    let formats = Format::parse_list(&args.format)?;
    // Every input and the output folder are checked before any grading.
    check_inputs(&args)?;
    let code = code_checker(&args, &rubric)?;
    // Where the code runs on the host as uids of their own (the fallback), what it must not
    // read is made unreadable by others until grading ends.
    let _kept = match code.python {
        Some(_) => Some(rtoracle::sandbox::originals::keep_from_sandboxes(
            &private_inputs(&args, &rubric),
        )?),
        None => None,
    };
    // Said once the grading is done, so bad input stays one line on stderr.
    let public_seed = (code.python.is_some() && code.vectors.is_none() && rubric.seed == 0).then_some(
        "warning: the rubric uses the public seed 0, so its vectors can be known in advance; set `seed = N` in it (`rtoracle autograder` writes a secret one)",
    );
    let images = rtoracle::grade::checkers::images::CompareImageChecker::default();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;

    // The goldens first (a scene file's is rendered once, on every thread), so one that
    // cannot be made stops the grading before it starts.
    pool.install(|| images.prepare(&rubric.image_scenes()))
        .map_err(|e| anyhow::anyhow!("{}: {e}", rubric.source))?;

    if let Some(dir) = &args.batch {
        let entries = pool.install(|| {
            batch::grade_batch_shard(
                dir, &rubric, &code, &images, &args.out, &formats, args.shard,
            )
        })?;
        print_batch(&entries, &args)?;
    } else {
        let submission = args.submission.as_ref().expect("clap requires it");
        let report = pool
            .install(|| grade_to_dir(submission, &rubric, &code, &images, &args.out, &formats))?;
        print_report(&report, &args)?;
    }
    if let Some(w) = public_seed {
        errln!("{w}");
    }
    Ok(ExitCode::SUCCESS)
}

/// The submission (or batch) folder, `--python` and `--out`, checked before any grading.
fn check_inputs(args: &Args) -> anyhow::Result<()> {
    match (&args.submission, &args.batch) {
        (None, None) => anyhow::bail!(
            "give a SUBMISSION folder to grade, or --batch DIR to grade every sub-folder of DIR \
             (see 'rtoracle grade --help')"
        ),
        (Some(sub), _) if !sub.is_dir() => {
            let what = if sub.exists() {
                "is a file; a submission folder is wanted"
            } else {
                "no such submission folder"
            };
            anyhow::bail!("{}: {what}", sub.display());
        }
        (_, Some(dir)) => {
            if !dir.is_dir() {
                let what = if dir.exists() {
                    "is a file; a folder of submission folders is wanted"
                } else {
                    "no such folder"
                };
                anyhow::bail!("--batch {}: {what}", dir.display());
            }
            if batch::submissions(dir, Some(&args.out))?.is_empty() {
                anyhow::bail!(
                    "--batch {}: no submissions found (each submission is a sub-folder)",
                    dir.display()
                );
            }
        }
        _ => {}
    }
    if let Some(p) = args.python.as_ref().filter(|p| !p.is_file()) {
        anyhow::bail!("--python {}: no such file", p.display());
    }
    // Replaced whole at the end: it may hold only rtoracle's reports.
    rtoracle::output::check_replaceable(
        &args.out,
        "--out",
        &rtoracle::grade::write::REPORT_FOLDER,
    )?;
    if let Some(sub) = &args.submission {
        // The reports must not land among the student's files (nor replace them).
        let out = std::path::absolute(&args.out)?;
        let sub_abs = sub.canonicalize()?;
        let out_real = match out.parent().and_then(|p| p.canonicalize().ok()) {
            Some(parent) => parent.join(out.file_name().unwrap_or_default()),
            None => out,
        };
        if out_real.starts_with(&sub_abs) {
            anyhow::bail!(
                "--out {}: is inside the submission folder {}; put the reports elsewhere",
                args.out.display(),
                sub.display()
            );
        }
    }
    Ok(())
}

/// The code checker of `rubric`. Before grading anything: a sandbox that keeps the code from
/// running as root (fail closed), and a Python with the rubric's modules that the sandbox user
/// can run. A rubric of images only runs no code, so it needs neither (its checker's `python`
/// stays `None`).
fn code_checker(args: &Args, rubric: &Rubric) -> anyhow::Result<CourseCodeChecker> {
    let vectors = match &args.vectors {
        Some(path) => Some((path.display().to_string(), read_vectors(path)?)),
        None => None,
    };
    let runs_code = rubric.week.is_some()
        || rubric
            .groups
            .iter()
            .any(|g| g.kind == rtoracle::grade::rubric::GroupKind::Code || g.renders());
    let policy = rubric.sandbox_policy();
    let python = if runs_code {
        let python = rtoracle::candidate::process::python::choose(
            args.python.as_deref(),
            &rubric.python_requires,
            &policy,
        )?;
        rtoracle::sandbox::facts::announce_on_stderr();
        Some(python)
    } else {
        None
    };
    Ok(CourseCodeChecker {
        seed: rubric.seed,
        vectors,
        case_timeout: Duration::from_millis(args.case_timeout_ms),
        time_budget: Some(Duration::from_secs_f64(rubric.code_time_budget_seconds)),
        policy,
        python,
        python_requires: rubric.python_requires.clone(),
        week: rubric.week.and_then(rtoracle::weekly::week::Week::new),
        ..Default::default()
    })
}

/// `--merge`: the shards joined into `--out`, each submission's score on stdout, one line each,
/// and where the gradebook is on stderr.
fn run_merge(args: &Args) -> anyhow::Result<ExitCode> {
    let merged = rtoracle::grade::batch::merge::merge_shards(&args.merge, &args.out)?;
    for e in &merged {
        match &e.result {
            Ok(r) => outln!("{}: {} / {}", e.name.terminal_line(), r.score, r.max_score)?,
            Err(msg) => outln!(
                "{}: not graded: {}",
                e.name.terminal_line(),
                terminal_line(msg)
            )?,
        }
    }
    let graded = merged.iter().filter(|e| e.result.is_ok()).count();
    errln!(
        "merged {} shards: graded {graded} of {} submissions; gradebook in {}",
        args.merge.len(),
        merged.len(),
        args.out.join("gradebook.csv").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// A batch's scores on stdout, one line each, and where the gradebook is on stderr.
fn print_batch(entries: &[batch::BatchEntry], args: &Args) -> anyhow::Result<()> {
    let graded = entries.iter().filter(|e| e.result.is_ok()).count();
    for e in entries {
        match &e.result {
            Ok(r) => outln!("{}: {} / {}", e.name.terminal_line(), r.score, r.max_score)?,
            Err(msg) => outln!(
                "{}: not graded: {}",
                e.name.terminal_line(),
                terminal_line(msg)
            )?,
        }
    }
    errln!(
        "graded {graded} of {} submissions; gradebook in {}",
        entries.len(),
        args.out.join("gradebook.csv").display()
    );
    Ok(())
}

/// A submission's checks and total on stdout, and where the reports are on stderr.
fn print_report(report: &rtoracle::grade::result::GradeReport, args: &Args) -> anyhow::Result<()> {
    use rtoracle::grade::result::round2;
    // Unscored checks are listed only when some ambiguous vector differs (no `0 / 0` rows).
    let shown: Vec<&rtoracle::grade::result::CheckResult> = report
        .checks
        .iter()
        .filter(|c| {
            c.status != rtoracle::grade::result::CheckStatus::Skipped || !c.failures.is_empty()
        })
        .collect();
    let width = shown
        .iter()
        .map(|c| terminal_line(&c.id).chars().count())
        .max()
        .unwrap_or(0)
        .max(24);
    for c in shown {
        if c.status == rtoracle::grade::result::CheckStatus::Skipped {
            outln!("{:<width$} {:>15} not scored", terminal_line(&c.id), "")?;
            continue;
        }
        outln!(
            "{:<width$} {:>6} / {:<6} {}",
            terminal_line(&c.id),
            round2(c.score),
            round2(c.max_score),
            c.status.name()
        )?;
        if let Some(raised) = rtoracle::grade::report::exception_of(c) {
            outln!("  {}", raised.truncated(300).terminal_line())?;
        }
    }
    outln!(
        "{:<width$} {:>6} / {:<6}",
        "total",
        report.score,
        report.max_score
    )?;
    if let Some(fatal) = &report.code.fatal {
        outln!(
            "code: {}",
            fatal.first_line().truncated(300).terminal_line()
        )?;
    }
    errln!(
        "graded {} in {:.2} s; reports in {}",
        report.submission.terminal_line(),
        report.execution_time,
        args.out.display()
    );
    Ok(())
}

/// What the code graded must not read: the batch folder (the classmates' submissions), the
/// rubric file (its seed), its scene files and goldens, the vector file.
fn private_inputs(args: &Args, rubric: &Rubric) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = [
        args.batch.clone(),
        // A built-in rubric's name is no file.
        args.rubric.clone().filter(|p| p.is_file()),
        args.vectors.clone(),
    ]
    .into_iter()
    .flatten()
    .collect();
    for scene in rubric.groups.iter().filter_map(|g| g.scene_file.as_ref()) {
        paths.push(scene.path.clone());
        paths.extend(scene.golden.as_ref().map(|g| g.path.clone()));
    }
    paths.retain(|p| p.exists());
    paths
}
