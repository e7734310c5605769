//! Joining the shards of a batch (`rtoracle grade --merge OUT... --out DIR`): each shard's
//! report folder (as `grade --batch DIR --shard K/N --out OUT` writes it) holds its
//! submissions' report folders, each with its [`ENTRY_FILE`] (the report as graded and its
//! images' fingerprints), and a `batch.json` ([`BatchFile`]). The merge is as strict as grading
//! the batch whole: it compares every two submissions' images across the shards (the copy
//! check of [`flag_shared_noise`](crate::grade::batch::shared_noise::flag_shared_noise)) and writes every
//! submission's reports, the gradebook, the summary and `batch.json` from the entries, so the
//! merged folder is the whole batch's, byte for byte, copy findings included.
//!
//! What is refused, before anything is written, in one line naming the folder: a folder without
//! a readable `batch.json` (or of an older layout); shards of different batches (other
//! submission folders, another N); shards graded otherwise: by another rtoracle version, under
//! a rubric of other groups or points (weights) or another text, with other vectors (the
//! rubric's seed, or `--vectors`: their digests differ), other code or image checks, or other
//! report formats; a shard given twice or missing; an unsharded batch among shards; a
//! submission's entry that cannot be read.

use std::path::{Path, PathBuf};

use crate::grade::batch::entry::{ENTRY_FILE, EntryFile};
use crate::grade::batch::{
    BATCH_SCHEMA, BATCH_VERSION, BatchEntry, BatchFile, BatchRow, flag_copies,
};
use crate::grade::report::Format;
use crate::grade::result::GradeError;
use crate::grade::write::REPORT_FOLDER;
use crate::output::OutputDir;

/// Why shards cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// A shard folder (or the set of them) that cannot be merged, and why.
    #[error("{}: {message}", path.display())]
    Shard {
        /// The shard's folder (`--merge` for the set).
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The merged folder could not be written.
    #[error(transparent)]
    Write(#[from] GradeError),
}

impl From<crate::output::OutputError> for MergeError {
    fn from(e: crate::output::OutputError) -> Self {
        MergeError::Write(e.into())
    }
}

fn refuse(path: &Path, message: impl Into<String>) -> MergeError {
    MergeError::Shard {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

/// Reads the `batch.json` of the shard folder `dir`.
pub fn read_shard(dir: &Path) -> Result<BatchFile, MergeError> {
    let path = dir.join("batch.json");
    let text = std::fs::read_to_string(&path).map_err(|e| {
        refuse(
            dir,
            format!(
                "cannot read batch.json ({}): give the --out folder of `rtoracle grade --batch DIR --shard K/N`",
                e.kind()
            ),
        )
    })?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| refuse(&path, format!("not a batch file of rtoracle's: {e}")))?;
    let layout = (
        value.get("schema").and_then(|v| v.as_str()),
        value.get("version").and_then(|v| v.as_u64()),
    );
    if layout != (Some(BATCH_SCHEMA), Some(u64::from(BATCH_VERSION))) {
        let was = match (layout, value.get("format").and_then(|v| v.as_str())) {
            (_, Some(old)) => old.to_string(),
            ((Some(s), Some(v)), None) => format!("{s} {v}"),
            _ => "unknown".to_string(),
        };
        return Err(refuse(
            &path,
            format!(
                "written in the layout {was:?}, this rtoracle merges {BATCH_SCHEMA} {BATCH_VERSION}: grade the shard again with this rtoracle"
            ),
        ));
    }
    serde_json::from_value(value)
        .map_err(|e| refuse(&path, format!("not a batch file of rtoracle's: {e}")))
}

/// Why shard `file` was graded otherwise than `first` (named `first_dir`), if it was: the
/// first difference, in words.
fn graded_otherwise(file: &BatchFile, first: &BatchFile, first_dir: &Path) -> Option<String> {
    let (a, b) = (&file.graded_with, &first.graded_with);
    let at = first_dir.display();
    let why = if a.tool_version != b.tool_version {
        format!(
            "graded by rtoracle {}, {at} by rtoracle {}: grade every shard with the same rtoracle",
            a.tool_version, b.tool_version
        )
    } else if file.rubric.groups != first.rubric.groups || file.rubric.points != first.rubric.points
    {
        format!(
            "graded under a rubric of other groups or points (weights {:?}, {at}: {:?}): grade every shard with the same rubric",
            file.rubric.points, first.rubric.points
        )
    } else if a.vectors_sha256 != b.vectors_sha256 {
        format!(
            "graded with other vectors than {at} (another seed in the rubric, or another --vectors: their SHA-256 differ): grade every shard with the same"
        )
    } else if file.rubric.sha256 != first.rubric.sha256 || file.rubric.name != first.rubric.name {
        format!(
            "graded under another rubric than {at} (rubric SHA-256 {} and {}): grade every shard with the same rubric",
            short(&file.rubric.sha256),
            short(&first.rubric.sha256)
        )
    } else if a.code_checker != b.code_checker || a.image_checker != b.image_checker {
        format!(
            "graded with other checks than {at} ({:?}, {at}: {:?}): grade every shard with the same options",
            a.code_checker, b.code_checker
        )
    } else if a.formats != b.formats {
        format!(
            "written in other formats than {at} ({}, {at}: {}): give every shard the same --format",
            a.formats.join(","),
            b.formats.join(",")
        )
    } else {
        return None;
    };
    Some(why)
}

/// The first 12 hex digits of a digest.
fn short(sha: &str) -> &str {
    &sha[..sha.len().min(12)]
}

/// Checks that `shards` (read from `dirs`) are the shards 1..N of one batch, graded alike, each
/// once, and returns the merged file: every row, in name order, and no shard.
pub fn join(dirs: &[PathBuf], shards: Vec<BatchFile>) -> Result<BatchFile, MergeError> {
    let first = shards
        .first()
        .ok_or_else(|| refuse(Path::new("--merge"), "no shard folder given"))?;
    let n = match first.shard {
        Some(s) => s.n,
        None => {
            return Err(refuse(
                &dirs[0],
                "an unsharded batch (graded without --shard): there is nothing to merge",
            ));
        }
    };
    let mut seen = vec![false; n as usize];
    for (dir, file) in dirs.iter().zip(&shards) {
        let Some(shard) = file.shard else {
            return Err(refuse(dir, "an unsharded batch among shards"));
        };
        if shard.n != n || file.batch != first.batch {
            return Err(refuse(
                dir,
                format!(
                    "shard {shard} is not of the same batch as {} (shard {}/{n}): the submission folders or N differ",
                    dirs[0].display(),
                    first.shard.map_or(0, |s| s.k)
                ),
            ));
        }
        if let Some(why) = graded_otherwise(file, first, &dirs[0]) {
            return Err(refuse(dir, why));
        }
        let slot = &mut seen[(shard.k - 1) as usize];
        if *slot {
            return Err(refuse(dir, format!("shard {shard} is given twice")));
        }
        *slot = true;
        if let Some(row) = file
            .rows
            .iter()
            .find(|r| !shard.holds(r.name.as_file_name()))
        {
            return Err(refuse(
                dir,
                format!(
                    "holds {}, which is not in shard {shard}",
                    row.name.terminal_line()
                ),
            ));
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !seen[(*k - 1) as usize])
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(refuse(
            Path::new("--merge"),
            format!("shard {} missing", missing.join(", ")),
        ));
    }
    let mut rows: Vec<BatchRow> = shards.iter().flat_map(|f| f.rows.clone()).collect();
    rows.sort_by(|a, b| a.name.cmp(&b.name));
    Ok(BatchFile {
        schema: BATCH_SCHEMA.to_string(),
        version: BATCH_VERSION,
        rubric: first.rubric.clone(),
        graded_with: first.graded_with.clone(),
        shard: None,
        batch: first.batch.clone(),
        rows,
    })
}

/// Copies the files of the report folder `from` into the staging folder's `rel`, but the
/// reports and the entry, which the merge writes itself.
fn copy_pictures(from: &Path, output: &OutputDir, rel: &str) -> Result<(), MergeError> {
    let io = |e: std::io::Error| GradeError::Output {
        path: output.shown(rel),
        message: e.to_string(),
    };
    std::fs::create_dir(output.path().join(rel)).map_err(io)?;
    let written: Vec<&str> = Format::ALL
        .iter()
        .map(|f| f.file_name())
        .chain([ENTRY_FILE])
        .collect();
    let mut names: Vec<_> = std::fs::read_dir(from)
        .map_err(io)?
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name())
        .filter(|n| !written.iter().any(|w| n.as_encoded_bytes() == w.as_bytes()))
        .collect();
    names.sort();
    for name in names {
        let bytes = std::fs::read(from.join(&name)).map_err(io)?;
        output.write(Path::new(rel).join(&name), &bytes)?;
    }
    Ok(())
}

/// Merges the shard folders `dirs` into `out` (replaced whole, as `grade --out` is): every
/// submission's report folder, compared across the shards as one batch, then the gradebook,
/// summary and `batch.json` of the whole batch. Returns the merged entries, in name order.
pub fn merge_shards(dirs: &[PathBuf], out: &Path) -> Result<Vec<BatchEntry>, MergeError> {
    let shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<Vec<_>, _>>()?;
    let merged = join(dirs, shards.clone())?;
    let formats: Vec<Format> = merged
        .graded_with
        .formats
        .iter()
        .map(|f| Format::parse_list(f))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| refuse(&dirs[0], format!("batch.json: {e}")))?
        .concat();
    // The merged folder replaces `out` whole: it must not be one of the shards read.
    let out_real = out.canonicalize().ok();
    if let Some(dir) = dirs
        .iter()
        .find(|d| out_real.is_some() && d.canonicalize().ok() == out_real)
    {
        return Err(refuse(
            out,
            format!(
                "is the shard folder {}: merge into another folder",
                dir.display()
            ),
        ));
    }
    // Every entry is read before anything is written.
    let mut entries: Vec<(BatchEntry, Option<PathBuf>)> = Vec::new();
    for (dir, file) in dirs.iter().zip(&shards) {
        for row in &file.rows {
            let entry = match &row.result {
                Err(why) => (
                    BatchEntry {
                        name: row.name.clone(),
                        result: Err(why.clone()),
                    },
                    None,
                ),
                Ok(_) => {
                    let folder = dir.join(row.name.as_file_name());
                    let report = EntryFile::read(&folder.join(ENTRY_FILE))
                        .map_err(|why| refuse(&folder.join(ENTRY_FILE), why.to_string()))?;
                    (
                        BatchEntry {
                            name: row.name.clone(),
                            result: Ok(report),
                        },
                        Some(folder),
                    )
                }
            };
            entries.push(entry);
        }
    }
    entries.sort_by(|a, b| a.0.name.cmp(&b.0.name));
    let output = OutputDir::create(out, "--out", &REPORT_FOLDER)?;
    for (entry, folder) in &entries {
        let (Some(folder), Ok(report)) = (folder, &entry.result) else {
            continue;
        };
        let name = entry.name.as_file_name();
        copy_pictures(folder, &output, name)?;
        output.write(
            Path::new(name).join(ENTRY_FILE),
            &EntryFile::of(report).to_bytes(),
        )?;
        for f in &formats {
            output.write(
                Path::new(name).join(f.file_name()),
                f.render(report).as_bytes(),
            )?;
        }
    }
    let mut entries: Vec<BatchEntry> = entries.into_iter().map(|(e, _)| e).collect();
    // As one batch: every two submissions' images compared, across the shards.
    flag_copies(&mut entries, &output, &formats)?;
    let file = BatchFile {
        rows: entries.iter().map(BatchRow::of).collect(),
        ..merged
    };
    file.write_into(&output)?;
    output.commit()?;
    Ok(entries)
}
