//! Grading a folder of submissions: one report folder each, `gradebook.csv` and `summary.md`.
//! Submissions are graded in parallel on rayon's current pool; one that breaks grading is a row
//! marked `error` and never stops the batch.
//!
//! A batch can be spread over machines: `--shard K/N` grades the share [`Shard::holds`] gives
//! shard K (decided by each folder's name alone, so the same on every machine and whatever other
//! folders there are), and every batch also writes `batch.json` ([`BatchFile`]: the rows the
//! gradebook and summary are made from), from which [`merge`] joins the shards into the
//! gradebook and summary an unsharded run writes, byte for byte.

pub mod entry;
pub mod merge;
pub mod shared_noise;

use std::collections::BTreeMap;
use std::fmt::Write;
use std::io::IsTerminal;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use self::entry::{ENTRY_FILE, EntryFile};
use self::shared_noise::flag_shared_noise;
use super::checkers::copies::CopyFinding;
use super::checkers::{CodeChecker, ImageChecker};
use super::report::Format;
use super::result::{CheckStatus, GradeError, GradeReport, round2};
use super::rubric::Rubric;
use super::write::{REPORT_FOLDER, grade_into};
use crate::escape::{Untrusted, csv_cell, markdown_inline};
use crate::oracle::vectors::ShapeKind;
use crate::output::OutputDir;

/// One submission of a batch.
#[derive(Debug)]
pub struct BatchEntry {
    /// The sub-folder's name (the submission's).
    pub name: Untrusted,
    /// Its report, or why grading it failed.
    pub result: Result<GradeReport, String>,
}

/// The sub-folders of `dir` that are submissions: not hidden, sorted by name, without `skip`
/// (the output folder, when it lies inside `dir`).
pub fn submissions(dir: &Path, skip: Option<&Path>) -> Result<Vec<PathBuf>, GradeError> {
    let entries =
        std::fs::read_dir(dir).map_err(|_| GradeError::NoSubmission(dir.to_path_buf()))?;
    let skip = skip.and_then(|p| p.canonicalize().ok());
    let mut out: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| e.file_type().map(|t| t.is_dir()).unwrap_or(false))
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .map(|e| e.path())
        .filter(|p| skip.is_none() || p.canonicalize().ok() != skip)
        .collect();
    out.sort();
    Ok(out)
}

/// A folder's name as the batch's rows and report folders show it: its bytes that are not
/// UTF-8 written as `\xNN`, so two names that differ only there stay apart.
pub fn folder_name(name: &std::ffi::OsStr) -> String {
    let mut out = String::new();
    for chunk in name.as_encoded_bytes().utf8_chunks() {
        out.push_str(chunk.valid());
        for b in chunk.invalid() {
            let _ = write!(out, "\\x{b:02x}");
        }
    }
    out
}

/// The batch's own files in its output folder: a submission folder of one of these names is
/// an error row of the batch, not graded (its reports would take their place).
pub const BATCH_FILES: [&str; 3] = ["gradebook.csv", "summary.md", "batch.json"];

/// Why a text is not a shard (`K/N`); each names the text.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ShardError {
    /// No `/` between two numbers.
    #[error("{0:?} is not K/N (shard K of N, as 2/3)")]
    NotKOfN(String),
    /// K or N is not a whole number.
    #[error("{0:?} is not K/N with whole numbers (as 2/3)")]
    NotWhole(String),
    /// N is 0, or K is 0 or past N.
    #[error("{0:?}: K must be from 1 to N, and N at least 1")]
    OutOfRange(String),
}

/// One share of a batch: shard `k` of `n` (1 <= k <= n), as `--shard K/N` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which share, from 1.
    pub k: u64,
    /// How many shares.
    pub n: u64,
}

impl Shard {
    /// Reads `K/N`.
    pub fn parse(text: &str) -> Result<Shard, ShardError> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| ShardError::NotKOfN(text.to_string()))?;
        let (k, n) = match (k.trim().parse::<u64>(), n.trim().parse::<u64>()) {
            (Ok(k), Ok(n)) => (k, n),
            _ => return Err(ShardError::NotWhole(text.to_string())),
        };
        if n == 0 || k == 0 || k > n {
            return Err(ShardError::OutOfRange(text.to_string()));
        }
        Ok(Shard { k, n })
    }

    /// Whether the submission folder `name` is in this share: its shard is 1 + the first 8
    /// bytes of the SHA-256 of its name (UTF-8), read as a big-endian number, modulo N. A
    /// folder's shard depends on its name and N only, so every machine agrees on it and adding
    /// or removing other folders never moves it; the shares are even up to chance (each holds
    /// a folder with probability 1/N).
    pub fn holds(&self, name: &str) -> bool {
        let digest = Sha256::digest(name.as_bytes());
        let mut first = [0u8; 8];
        first.copy_from_slice(&digest[..8]);
        u64::from_be_bytes(first) % self.n + 1 == self.k
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// Grades every submission in `dir` into `out/<name>/` and writes `out/gradebook.csv`,
/// `out/summary.md` and `out/batch.json`.
pub fn grade_batch(
    dir: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    out: &Path,
    formats: &[Format],
) -> Result<Vec<BatchEntry>, GradeError> {
    grade_batch_shard(dir, rubric, code, images, out, formats, None)
}

/// [`grade_batch`] on the share `shard` of the submissions (all of them for `None`); the
/// gradebook and summary are the share's, and `batch.json` says which share of which folders
/// it holds.
pub fn grade_batch_shard(
    dir: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    out: &Path,
    formats: &[Format],
    shard: Option<Shard>,
) -> Result<Vec<BatchEntry>, GradeError> {
    if !dir.is_dir() {
        return Err(GradeError::NoSubmission(dir.to_path_buf()));
    }
    // Everything is written into a fresh folder beside `out` and swapped in whole at the end.
    let output = OutputDir::create(out, "", &REPORT_FOLDER)?;
    let all = submissions(dir, Some(output.target()))?;
    let batch: Vec<String> = all
        .iter()
        .map(|s| folder_name(s.file_name().unwrap_or_default()))
        .collect();
    let subs: Vec<PathBuf> = all
        .into_iter()
        .filter(|s| {
            shard.is_none_or(|sh| sh.holds(&folder_name(s.file_name().unwrap_or_default())))
        })
        .collect();
    let bar = if std::io::stderr().is_terminal() {
        let bar =
            ProgressBar::with_draw_target(Some(subs.len() as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("grading {bar:40} {pos}/{len} submissions, {eta} left")
                .expect("a valid progress template"),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let names: Vec<String> = subs
        .iter()
        .map(|s| folder_name(s.file_name().unwrap_or_default()))
        .collect();
    let entries: Vec<BatchEntry> = subs
        .par_iter()
        .zip(names.par_iter())
        .map(|(sub, name)| {
            let name = name.clone();
            let result = catch_unwind(AssertUnwindSafe(|| {
                let same = names.iter().filter(|n| **n == name).count();
                if same > 1 {
                    return Err(GradeError::Output {
                        path: output.shown(&name),
                        message: format!(
                            "{same} submission folders have this name once their bytes that \
                             are not UTF-8 are written as \\xNN; rename them to grade them"
                        ),
                    });
                }
                if BATCH_FILES.contains(&name.as_str()) {
                    // Named by the folder alone: a row says the same in every shard's run.
                    return Err(GradeError::Output {
                        path: PathBuf::from(&name),
                        message: "a submission folder cannot have the name of the batch's own \
                                  report; rename it to grade it"
                            .to_string(),
                    });
                }
                std::fs::create_dir(output.path().join(&name)).map_err(|e| GradeError::Output {
                    path: output.shown(&name),
                    message: e.to_string(),
                })?;
                let report = grade_into(
                    sub,
                    rubric,
                    code,
                    images,
                    &output,
                    Path::new(&name),
                    formats,
                )?;
                // What a merge of shards needs of it: the report as graded, its fingerprints.
                output.write(
                    Path::new(&name).join(ENTRY_FILE),
                    &EntryFile::of(&report).to_bytes(),
                )?;
                Ok(report)
            }));
            bar.inc(1);
            let result = match result {
                Ok(Ok(report)) => Ok(report),
                Ok(Err(e)) => Err(e.to_string()),
                Err(_) => Err("the grader panicked on this submission".to_string()),
            };
            BatchEntry {
                name: name.into(),
                result,
            }
        })
        .collect();
    bar.finish_and_clear();
    let mut entries = entries;
    // In name order, as a merge of shards has them.
    entries.sort_by(|a, b| a.name.cmp(&b.name));
    flag_copies(&mut entries, &output, formats)?;
    let file = BatchFile {
        schema: BATCH_SCHEMA.to_string(),
        version: BATCH_VERSION,
        rubric: BatchRubric::of(rubric),
        graded_with: GradedWith::of(rubric, code, images, formats),
        shard,
        batch,
        rows: entries.iter().map(BatchRow::of).collect(),
    };
    file.write_into(&output)?;
    output.commit()?;
    Ok(entries)
}

/// Flags the submissions whose images share their noise with another's
/// ([`flag_shared_noise`]) and writes their reports again.
pub(crate) fn flag_copies(
    entries: &mut [BatchEntry],
    output: &OutputDir,
    formats: &[Format],
) -> Result<(), GradeError> {
    let mut named: Vec<(&str, &mut GradeReport)> = entries
        .iter_mut()
        .filter_map(|BatchEntry { name, result }| {
            Some((name.as_file_name(), result.as_mut().ok()?))
        })
        .collect();
    let pairs = flag_shared_noise(&mut named);
    let flagged: std::collections::BTreeSet<&str> = pairs
        .iter()
        .flat_map(|p| p.submissions.iter().map(Untrusted::as_file_name))
        .collect();
    for (name, report) in named.iter().filter(|(n, _)| flagged.contains(n)) {
        for &f in formats {
            output.write(
                Path::new(name).join(f.file_name()),
                f.render(report).as_bytes(),
            )?;
        }
    }
    Ok(())
}

/// What `batch.json` says it is.
pub const BATCH_SCHEMA: &str = "rtoracle-batch";

/// The version of `batch.json`'s layout: 2 since it says what the batch was graded with and
/// each submission's folder keeps its [`ENTRY_FILE`] (version 1 had `"format":
/// "rtoracle-batch-1"` instead of `schema` and `version`; its shards cannot be merged with
/// this rtoracle: grade them again).
pub const BATCH_VERSION: u32 = 2;

/// What the gradebook and summary need of the rubric, and what tells one rubric from another.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BatchRubric {
    /// Its name.
    pub name: String,
    /// Its groups' ids, in order (the gradebook's columns).
    pub groups: Vec<String>,
    /// Each group's points, in the same order (the weights).
    pub points: Vec<f64>,
    /// Points available.
    pub max_score: f64,
    /// The SHA-256 of the rubric's TOML.
    pub sha256: String,
}

impl BatchRubric {
    /// The facts of `rubric`.
    pub fn of(rubric: &Rubric) -> BatchRubric {
        BatchRubric {
            name: rubric.name.clone(),
            groups: rubric.groups.iter().map(|g| g.id.clone()).collect(),
            points: rubric.groups.iter().map(|g| g.points).collect(),
            max_score: rubric.max_score(),
            sha256: rubric.sha256.clone(),
        }
    }
}

/// What a batch was graded with besides its rubric: shards graded otherwise cannot be merged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GradedWith {
    /// rtoracle's version.
    pub tool_version: String,
    /// The SHA-256 of the vectors run (the rubric's seed's suite, or `--vectors`): a digest of
    /// the seed, never the seed (empty without code groups).
    pub vectors_sha256: String,
    /// The code checker and its options (the time-out per vector).
    pub code_checker: String,
    /// The image checker.
    pub image_checker: String,
    /// The report formats written (`--format`).
    pub formats: Vec<String>,
}

impl GradedWith {
    /// What a batch of `rubric` graded with `code`, `images` and `formats` records.
    pub fn of(
        rubric: &Rubric,
        code: &dyn CodeChecker,
        images: &dyn ImageChecker,
        formats: &[Format],
    ) -> GradedWith {
        let has_code = rubric.groups.iter().any(|g| g.shape.is_some());
        GradedWith {
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
            vectors_sha256: if has_code {
                code.vectors_sha256()
            } else {
                String::new()
            },
            code_checker: code.describe(),
            image_checker: images.describe(),
            formats: formats.iter().map(|f| f.name().to_string()).collect(),
        }
    }
}

/// One check as the summary counts it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowCheck {
    /// The check's id.
    pub id: String,
    /// Its name.
    pub name: String,
    /// Points earned and available.
    pub score: f64,
    /// Points available.
    pub max_score: f64,
    /// Whether it failed or could not run (a check of a 0-point group loses nothing but can
    /// still fail).
    pub failed: bool,
    /// The failing vectors it showed the student: id and message.
    pub failures: Vec<(String, Untrusted)>,
    /// Its group's id.
    #[serde(default)]
    pub group: String,
    /// For an image check: the image's file and what the copy checks found of it.
    #[serde(default)]
    pub image: Option<RowImage>,
}

/// What the summary says of an image check: its file and the copies found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowImage {
    /// The image's file in the submission.
    pub file: String,
    /// What the copy checks found of it.
    pub copies: Vec<CopyFinding>,
}

/// A graded submission as the gradebook and summary use it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowScores {
    /// Points earned.
    pub score: f64,
    /// Points available.
    pub max_score: f64,
    /// Points per group id, in rubric order.
    pub groups: Vec<(String, f64)>,
    /// Its checks.
    pub checks: Vec<RowCheck>,
    /// Whether its code could not be run at all.
    pub fatal: bool,
    /// Every definite vector it failed.
    pub failed_vectors: Vec<(String, ShapeKind)>,
    /// Answers that broke the protocol ([`super::result::CodeRun::protocol_errors`]): the
    /// gradebook's status then asks for a review.
    #[serde(default)]
    pub protocol_errors: usize,
}

/// One submission of a batch as its gradebook and summary use it (what `batch.json` keeps).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BatchRow {
    /// The sub-folder's name (the submission's).
    pub name: Untrusted,
    /// Its scores, or why grading it failed.
    pub result: Result<RowScores, String>,
}

impl BatchRow {
    /// The row of `entry`.
    pub fn of(entry: &BatchEntry) -> BatchRow {
        let result = entry
            .result
            .as_ref()
            .map_err(Clone::clone)
            .map(|r| RowScores {
                score: r.score,
                max_score: r.max_score,
                groups: r
                    .group_scores()
                    .into_iter()
                    .map(|(g, s, _)| (g, s))
                    .collect(),
                checks: r
                    .checks
                    .iter()
                    .map(|c| RowCheck {
                        id: c.id.clone(),
                        name: c.name.clone(),
                        score: c.score,
                        max_score: c.max_score,
                        failed: matches!(c.status, CheckStatus::Failed | CheckStatus::Error),
                        failures: c
                            .failures
                            .iter()
                            .map(|f| (f.id.clone(), f.message.clone()))
                            .collect(),
                        group: c.group.clone(),
                        image: c.image.as_ref().map(|i| RowImage {
                            file: i.file.clone(),
                            copies: i.copies.clone(),
                        }),
                    })
                    .collect(),
                fatal: r.code.fatal.is_some(),
                failed_vectors: r.code.failed_vectors.clone(),
                protocol_errors: r.code.protocol_errors,
            });
        BatchRow {
            name: entry.name.clone(),
            result,
        }
    }
}

/// `batch.json`: the rubric, what it was graded with, the share graded (none: all), every
/// submission folder of the batch (graded here or not) and the rows of those graded here, in
/// name order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BatchFile {
    /// [`BATCH_SCHEMA`].
    pub schema: String,
    /// [`BATCH_VERSION`].
    pub version: u32,
    /// The rubric's facts.
    pub rubric: BatchRubric,
    /// What it was graded with.
    pub graded_with: GradedWith,
    /// The share graded.
    pub shard: Option<Shard>,
    /// Every submission folder of the batch, in name order.
    pub batch: Vec<String>,
    /// The rows of the submissions graded, in name order.
    pub rows: Vec<BatchRow>,
}

impl BatchFile {
    /// Writes `gradebook.csv`, `summary.md` and `batch.json` into `output`.
    pub fn write_into(&self, output: &OutputDir) -> Result<(), GradeError> {
        output.write(
            "gradebook.csv",
            rows_gradebook_csv(&self.rubric, &self.rows).as_bytes(),
        )?;
        output.write(
            "summary.md",
            rows_summary_md(&self.rubric, &self.rows).as_bytes(),
        )?;
        let json = serde_json::to_string_pretty(self).expect("a batch file always serialises");
        output.write("batch.json", (json + "\n").as_bytes())?;
        Ok(())
    }
}

/// `gradebook.csv`: `submission,score,max_score`, one column per rubric group, then `status`.
pub fn gradebook_csv(rubric: &Rubric, entries: &[BatchEntry]) -> String {
    let rows: Vec<BatchRow> = entries.iter().map(BatchRow::of).collect();
    rows_gradebook_csv(&BatchRubric::of(rubric), &rows)
}

/// [`gradebook_csv`] from rows.
pub fn rows_gradebook_csv(rubric: &BatchRubric, rows: &[BatchRow]) -> String {
    let mut csv = String::from("submission,score,max_score");
    for g in &rubric.groups {
        csv.push(',');
        csv.push_str(&csv_cell(g));
    }
    csv.push_str(",status\n");
    for e in rows {
        csv.push_str(&e.name.csv_cell());
        match &e.result {
            Ok(r) => {
                let groups: BTreeMap<&str, f64> =
                    r.groups.iter().map(|(g, s)| (g.as_str(), *s)).collect();
                let _ = write!(
                    csv,
                    ",{},{}",
                    csv_cell(&r.score.to_string()),
                    csv_cell(&r.max_score.to_string())
                );
                for g in &rubric.groups {
                    let points = groups.get(g.as_str()).copied().unwrap_or(0.0);
                    let _ = write!(csv, ",{}", csv_cell(&points.to_string()));
                }
                if r.protocol_errors > 0 {
                    let _ = writeln!(
                        csv,
                        ",review: {} protocol errors (a broken or hijacked adapter)",
                        r.protocol_errors
                    );
                } else {
                    csv.push_str(",ok\n");
                }
            }
            Err(msg) => {
                let _ = write!(csv, ",,{}", csv_cell(&rubric.max_score.to_string()));
                for _ in &rubric.groups {
                    csv.push(',');
                }
                let _ = writeln!(csv, ",{}", csv_cell(&format!("error: {msg}")));
            }
        }
    }
    csv
}

/// How many vectors "Most common failures" lists.
const VECTORS_SHOWN: usize = 10;

/// The `n` vectors failed most often, fairly across shapes: each shape's vectors are ranked by
/// how many submissions failed them (then by id), and the list takes them by count, then by rank
/// within their shape, then shape by shape, so a tie never hides a shape behind another's
/// alphabetically earlier ids.
fn most_failed(
    vectors: BTreeMap<String, (ShapeKind, usize, Untrusted)>,
    n: usize,
) -> Vec<(String, usize, Untrusted)> {
    let mut by_shape: BTreeMap<ShapeKind, Vec<(String, usize, Untrusted)>> = BTreeMap::new();
    for (id, (shape, count, msg)) in vectors {
        by_shape.entry(shape).or_default().push((id, count, msg));
    }
    let mut ranked = Vec::new();
    for (shape, mut rows) in by_shape {
        rows.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        for (rank, row) in rows.into_iter().enumerate() {
            ranked.push((row.1, rank, shape, row));
        }
    }
    ranked.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    ranked.into_iter().take(n).map(|r| r.3).collect()
}

/// `summary.md`: the score distribution and the most common failures.
pub fn summary_md(rubric: &Rubric, entries: &[BatchEntry]) -> String {
    let rows: Vec<BatchRow> = entries.iter().map(BatchRow::of).collect();
    rows_summary_md(&BatchRubric::of(rubric), &rows)
}

/// [`summary_md`] from rows.
pub fn rows_summary_md(rubric: &BatchRubric, entries: &[BatchRow]) -> String {
    let graded: Vec<&RowScores> = entries
        .iter()
        .filter_map(|e| e.result.as_ref().ok())
        .collect();
    let mut md = format!(
        "# Batch summary ({} rubric)\n\n{} submissions, {} graded, {} could not be graded.\n",
        rubric.name,
        entries.len(),
        graded.len(),
        entries.len() - graded.len()
    );
    if !graded.is_empty() {
        score_distribution(&mut md, &graded, rubric.max_score);
        common_failures(&mut md, &graded);
        copies_section(&mut md, entries);
    }
    let errors: Vec<&BatchRow> = entries.iter().filter(|e| e.result.is_err()).collect();
    if !errors.is_empty() {
        md.push_str("\n## Not graded\n\n");
        for e in errors {
            let _ = writeln!(
                md,
                "- {}: {}",
                e.name.markdown_inline(),
                markdown_inline(e.result.as_ref().err().map_or("", |s| s))
            );
        }
    }
    md
}

/// The images that are not a render of the submission's code: the course's, the reference
/// tracer's, and the pairs that share their noise (for review). Nothing when there is none.
fn copies_section(md: &mut String, entries: &[BatchRow]) {
    let mut zeroed = Vec::new();
    let mut pairs = std::collections::BTreeSet::new();
    for e in entries {
        let Ok(r) = &e.result else { continue };
        for c in &r.checks {
            let Some(image) = &c.image else { continue };
            for f in &image.copies {
                match f {
                    CopyFinding::SharedWith { submission, noise } => {
                        let (a, b) = if e.name <= *submission {
                            (&e.name, submission)
                        } else {
                            (submission, &e.name)
                        };
                        pairs.insert((
                            c.group.clone(),
                            a.clone(),
                            b.clone(),
                            noise.differing,
                            noise.common_busy,
                        ));
                    }
                    CopyFinding::CourseImage { .. } => zeroed.push((
                        e.name.clone(),
                        image.file.clone(),
                        "the course's published image",
                    )),
                    CopyFinding::ReferenceRender { .. } => zeroed.push((
                        e.name.clone(),
                        image.file.clone(),
                        "the reference tracer's own render",
                    )),
                }
            }
        }
    }
    if zeroed.is_empty() && pairs.is_empty() {
        return;
    }
    md.push_str("\n## Images that are not the submission's render\n\n");
    for (name, file, what) in &zeroed {
        let _ = writeln!(
            md,
            "- {}: {} is {what} (scored 0).",
            name.markdown_inline(),
            markdown_inline(file)
        );
    }
    if !pairs.is_empty() {
        md.push_str("\nThese pairs' images share their Monte Carlo noise (one copied from the other, or both from a third); review them:\n\n");
        md.push_str("| Group | Submissions | Busy pixels that differ |\n|---|---|---:|\n");
        for (group, a, b, differing, common) in pairs {
            let _ = writeln!(
                md,
                "| `{group}` | {} and {} | {differing} of {common} |",
                a.markdown_inline(),
                b.markdown_inline()
            );
        }
    }
}

/// The scores' mean, median and range, and a histogram by tenths of `max`.
fn score_distribution(md: &mut String, graded: &[&RowScores], max: f64) {
    let mut scores: Vec<f64> = graded.iter().map(|r| r.score).collect();
    scores.sort_by(f64::total_cmp);
    let n = scores.len();
    let mean = scores.iter().sum::<f64>() / n as f64;
    let median = if n % 2 == 1 {
        scores[n / 2]
    } else {
        (scores[n / 2 - 1] + scores[n / 2]) / 2.0
    };
    let _ = writeln!(
        md,
        "\nScore out of {max}: mean {}, median {}, min {}, max {}.\n",
        round2(mean),
        round2(median),
        scores[0],
        scores[n - 1]
    );
    md.push_str("| Score | Submissions |\n|---|---:|\n");
    let mut buckets = [0usize; 11];
    for s in &scores {
        let frac = if max > 0.0 { s / max } else { 1.0 };
        let b = if frac >= 1.0 {
            10
        } else {
            (frac * 10.0).floor().clamp(0.0, 9.0) as usize
        };
        buckets[b] += 1;
    }
    for (i, count) in buckets.iter().enumerate() {
        let label = if i == 10 {
            "100%".to_string()
        } else {
            format!("{}-{}%", i * 10, i * 10 + 10)
        };
        let bar = if *count > 0 {
            format!(" {}", "#".repeat(*count))
        } else {
            String::new()
        };
        let _ = writeln!(md, "| {label} | {count}{bar} |");
    }
}

/// The checks that lost points (or failed), and the vectors failed most often.
fn common_failures(md: &mut String, graded: &[&RowScores]) {
    let mut checks: BTreeMap<String, (String, usize)> = BTreeMap::new();
    // Per vector: its shape, how many submissions failed it (having run it), one message.
    let mut vectors: BTreeMap<String, (ShapeKind, usize, Untrusted)> = BTreeMap::new();
    let mut examples: BTreeMap<String, Untrusted> = BTreeMap::new();
    let mut fatal = 0usize;
    for r in graded {
        if r.fatal {
            fatal += 1;
        }
        for c in &r.checks {
            // A check of a 0-point group loses nothing but can still fail.
            if c.score < c.max_score || c.failed {
                let e = checks.entry(c.id.clone()).or_insert((c.name.clone(), 0));
                e.1 += 1;
            }
            // The example is a message a student was shown.
            for (id, message) in &c.failures {
                examples.entry(id.clone()).or_insert(message.clone());
            }
        }
        // Every vector the submission failed, once (a check shows only its first few).
        let failed: BTreeMap<&String, ShapeKind> =
            r.failed_vectors.iter().map(|(id, s)| (id, *s)).collect();
        for (id, shape) in failed {
            vectors
                .entry(id.clone())
                .or_insert((shape, 0, Untrusted::default()))
                .1 += 1;
        }
    }
    for (id, (_, _, example)) in vectors.iter_mut() {
        *example = examples
            .get(id)
            .cloned()
            .unwrap_or_else(|| "(not among the failures shown to any student)".into());
    }
    md.push_str("\n## Most common failures\n\n");
    if checks.is_empty() {
        md.push_str("Every submission passed every check.\n");
    } else {
        let mut rows: Vec<_> = checks.into_iter().collect();
        rows.sort_by(|a, b| b.1.1.cmp(&a.1.1).then(a.0.cmp(&b.0)));
        md.push_str("| Check | Submissions losing points |\n|---|---:|\n");
        for (id, (name, count)) in rows {
            let _ = writeln!(md, "| `{id}` {name} | {count} |");
        }
    }
    if fatal > 0 {
        let _ = writeln!(md, "\n{fatal} submission(s) could not be imported.");
    }
    if !vectors.is_empty() {
        md.push_str("\n| Vector | Submissions failing it | Example |\n|---|---:|---|\n");
        for (id, count, msg) in most_failed(vectors, VECTORS_SHOWN) {
            let _ = writeln!(
                md,
                "| `{}` | {count} | {} |",
                id.replace('`', "'"),
                msg.markdown_inline()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::judging::check::FailureKind;
    use crate::grade::checkers::FailureSummary;
    use crate::grade::checkers::fakes::*;

    /// Makes a submission folder with fake images for each of `names` in a new temporary
    /// folder and grades them as a batch with `code` (JSON reports into its `out`). Returns the
    /// folder (kept alive), the output folder and the entries.
    fn batch_of(names: &[&str], code: &FakeCode) -> (tempfile::TempDir, PathBuf, Vec<BatchEntry>) {
        let dir = tempfile::tempdir().unwrap();
        for name in names {
            std::fs::create_dir(dir.path().join(name)).unwrap();
            fake_images(&dir.path().join(name));
        }
        let out = dir.path().join("out");
        let entries = grade_batch(
            dir.path(),
            &Rubric::week04(),
            code,
            &all_pass(),
            &out,
            &[Format::Json],
        )
        .unwrap();
        (dir, out, entries)
    }

    /// Ties are shared between shapes: with ten sphere vectors and two quad vectors all failed
    /// by 3 submissions, the ten listed include both quad ones (alphabetically "quad-" came
    /// after every "a-sphere-" id and was never listed).
    #[test]
    fn most_failed_vectors_take_turns_between_shapes_on_ties() {
        let mut v = BTreeMap::new();
        for i in 0..10 {
            v.insert(
                format!("a-sphere-{i:02}"),
                (ShapeKind::Sphere, 3, Untrusted::default()),
            );
        }
        for i in 0..2 {
            v.insert(
                format!("quad-{i:02}"),
                (ShapeKind::Quad, 3, Untrusted::default()),
            );
        }
        v.insert(
            "a-sphere-top".into(),
            (ShapeKind::Sphere, 5, Untrusted::default()),
        );
        let listed: Vec<String> = most_failed(v, 10).into_iter().map(|r| r.0).collect();
        assert_eq!(listed[0], "a-sphere-top");
        assert!(listed.contains(&"quad-00".to_string()), "{listed:?}");
        assert!(listed.contains(&"quad-01".to_string()), "{listed:?}");
        assert_eq!(listed.len(), 10);
    }

    /// A vector failed by both submissions counts 2 even where no check shows it (each check
    /// shows its 5 simplest failures; both fail 8 vectors).
    #[test]
    fn the_summary_counts_every_failed_vector_not_only_those_shown() {
        let mut code = FakeCode::new(counts(10, 2), counts(2, 2));
        code.failures = (0..8)
            .map(|i| FailureSummary {
                id: format!("sphere-x-{i:04}"),
                shape: ShapeKind::Sphere,
                tags: vec![],
                kind: FailureKind::Mismatch,
                definite: true,
                expected: serde_json::Value::Null,
                actual: serde_json::Value::Null,
                message: format!("missed {i}").into(),
                repro: String::new(),
            })
            .collect();
        let (_dir, out, _) = batch_of(&["a", "b"], &code);
        let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
        let report = std::fs::read_to_string(out.join("a/report.json")).unwrap();
        let shown = report.matches("\"sphere-x-").count();
        assert!(
            shown < 8,
            "the test needs failures a check does not show: {shown}"
        );
        for i in 0..8 {
            assert!(
                summary.contains(&format!("| `sphere-x-{i:04}` | 2 |")),
                "sphere-x-{i:04}:\n{summary}"
            );
        }
        assert!(!report.contains("failed_vectors"), "{report}");
    }

    /// A group worth 0 points loses nothing when it fails, but its failures are still the most
    /// common ones: the summary lists the check, not "every submission passed".
    #[test]
    fn a_failing_check_of_a_0_point_group_is_listed_in_the_summary() {
        let text = crate::grade::rubric::WEEK04_RUBRIC.replacen("points = 30", "points = 0", 1);
        let rubric = Rubric::from_toml(&text, "zero.toml").unwrap();
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("a")).unwrap();
        fake_images(&dir.path().join("a"));
        let out = dir.path().join("out");
        let code = FakeCode::new(counts(2, 1), counts(2, 2));
        grade_batch(
            dir.path(),
            &rubric,
            &code,
            &all_pass(),
            &out,
            &[Format::Json],
        )
        .unwrap();
        let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
        assert!(summary.contains("| `sphere"), "{summary}");
        assert!(
            !summary.contains("Every submission passed every check"),
            "{summary}"
        );
    }

    /// A submission folder named like the batch's own report is an error row; the others are
    /// graded and the batch's files written.
    #[test]
    fn a_submission_named_like_the_batch_s_report_is_an_error_row() {
        let code = FakeCode::new(counts(2, 2), counts(2, 2));
        let (_dir, out, entries) = batch_of(&["a", "summary.md", "gradebook.csv"], &code);
        assert_eq!(entries.len(), 3);
        for e in &entries {
            assert_eq!(
                e.result.is_ok(),
                e.name.is("a"),
                "{:?}: {:?}",
                e.name,
                e.result
            );
        }
        assert!(out.join("a/report.json").is_file());
        let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
        assert!(
            summary.contains("3 submissions, 1 graded, 2 could not be graded"),
            "{summary}"
        );
        let csv = std::fs::read_to_string(out.join("gradebook.csv")).unwrap();
        assert!(csv.contains("summary.md,,100"), "{csv}");
    }

    #[test]
    fn a_panicking_submission_does_not_stop_the_batch() {
        let mut code = FakeCode::new(counts(2, 1), counts(2, 2));
        code.panic_on = Some("b".into());
        let (_dir, out, entries) = batch_of(&["a", "b", "c"], &code);
        // The output folder inside the batch folder is not taken for a submission.
        assert_eq!(
            entries
                .iter()
                .map(|e| e.name.as_file_name())
                .collect::<Vec<_>>(),
            ["a", "b", "c"]
        );
        assert!(entries[1].result.is_err());
        let csv = std::fs::read_to_string(out.join("gradebook.csv")).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(
            lines,
            [
                "submission,score,max_score,sphere,quad,image.week04-sphere,image.week04-quad,status",
                "a,85,100,15,30,20,20,ok",
                "b,,100,,,,,error: the grader panicked on this submission",
                "c,85,100,15,30,20,20,ok",
            ]
        );
        assert!(out.join("a/report.json").is_file() && out.join("c/report.json").is_file());
        let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
        assert!(
            summary.contains("3 submissions, 2 graded, 1 could not be graded"),
            "{summary}"
        );
        assert!(
            summary.contains("| `sphere.intersect` Sphere intersection | 2 |"),
            "{summary}"
        );
    }

    /// Two folder names that differ only in bytes that are not UTF-8 were both `\u{fffd}a`: one
    /// "not graded: File exists" and two rows no one could tell apart. They are rows of their
    /// own, named with `\xNN`; a name that clashes once written so is an error row that says so.
    #[test]
    fn folder_names_that_are_not_utf8_stay_apart_and_a_clash_is_an_error_row() {
        use std::os::unix::ffi::OsStrExt;
        let dir = tempfile::tempdir().unwrap();
        let raw: [&[u8]; 4] = [b"\xffa", b"\xfea", b"\xfdb", b"\\xfdb"];
        for name in raw {
            let path = dir.path().join(std::ffi::OsStr::from_bytes(name));
            std::fs::create_dir(&path).unwrap();
            fake_images(&path);
        }
        let code = FakeCode::new(counts(2, 2), counts(2, 2));
        let out = dir.path().join("out");
        let entries = grade_batch(
            dir.path(),
            &Rubric::week04(),
            &code,
            &all_pass(),
            &out,
            &[Format::Json],
        )
        .unwrap();
        let rows: Vec<(&str, bool)> = entries
            .iter()
            .map(|e| (e.name.as_file_name(), e.result.is_ok()))
            .collect();
        assert_eq!(
            rows,
            [
                ("\\xfdb", false),
                ("\\xfdb", false),
                ("\\xfea", true),
                ("\\xffa", true),
            ],
            "sorted by their bytes"
        );
        for name in ["\\xffa", "\\xfea"] {
            assert!(out.join(name).join("report.json").is_file(), "{name}");
        }
        let err = entries[0].result.as_ref().unwrap_err();
        assert!(
            err.contains("2 submission folders have this name once their bytes"),
            "{err}"
        );
    }
}
