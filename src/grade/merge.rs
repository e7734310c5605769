//! Joining the shards of a batch (`rtoracle grade --merge OUT... --out DIR`): each shard's
//! report folder (as `grade --batch DIR --shard K/N --out OUT` writes it) holds its
//! submissions' report folders and a `batch.json` ([`BatchFile`]); the merged folder holds every
//! submission's report folder and the gradebook, summary and `batch.json` an unsharded run of
//! the same batch writes, byte for byte.
//!
//! What is refused, before anything is written, each naming the folder: a folder without a
//! readable `batch.json`; shards of different batches (other folders, another rubric, another N);
//! a shard given twice or missing; an unsharded batch among shards.

use std::path::{Path, PathBuf};

use super::batch::{BATCH_FORMAT, BatchFile, BatchRow};
use super::result::GradeError;
use super::write::REPORT_FOLDER;
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
    let file: BatchFile = serde_json::from_str(&text)
        .map_err(|e| refuse(&path, format!("not a batch file of rtoracle's: {e}")))?;
    if file.format != BATCH_FORMAT {
        return Err(refuse(
            &path,
            format!(
                "written in the layout {:?}, this rtoracle reads {BATCH_FORMAT:?}",
                file.format
            ),
        ));
    }
    Ok(file)
}

/// Checks that `shards` (read from `dirs`) are the shards 1..N of one batch, each once, and
/// returns the merged file: every row, in name order, and no shard.
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
        if shard.n != n || file.batch != first.batch || file.rubric != first.rubric {
            return Err(refuse(
                dir,
                format!(
                    "shard {shard} is not of the same batch as {} (shard {}/{n}): the submission folders, the rubric or N differ",
                    dirs[0].display(),
                    first.shard.map_or(0, |s| s.k)
                ),
            ));
        }
        let slot = &mut seen[(shard.k - 1) as usize];
        if *slot {
            return Err(refuse(dir, format!("shard {shard} is given twice")));
        }
        *slot = true;
        if let Some(row) = file.rows.iter().find(|r| !shard.holds(&r.name)) {
            return Err(refuse(
                dir,
                format!("holds {:?}, which is not in shard {shard}", row.name),
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
        format: BATCH_FORMAT.to_string(),
        rubric: first.rubric.clone(),
        shard: None,
        batch: first.batch.clone(),
        rows,
    })
}

/// Copies the files of the report folder `from` into the staging folder's `rel`.
fn copy_reports(from: &Path, output: &OutputDir, rel: &str) -> Result<(), MergeError> {
    let io = |e: std::io::Error| GradeError::Output {
        path: output.shown(rel),
        message: e.to_string(),
    };
    std::fs::create_dir(output.path().join(rel)).map_err(io)?;
    let mut names: Vec<_> = std::fs::read_dir(from)
        .map_err(io)?
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name())
        .collect();
    names.sort();
    for name in names {
        let bytes = std::fs::read(from.join(&name)).map_err(io)?;
        output.write(Path::new(rel).join(&name), &bytes)?;
    }
    Ok(())
}

/// Merges the shard folders `dirs` into `out` (replaced whole, as `grade --out` is): every
/// submission's report folder, then the gradebook, summary and `batch.json` of the whole batch.
/// Returns the merged file.
pub fn merge_shards(dirs: &[PathBuf], out: &Path) -> Result<BatchFile, MergeError> {
    let shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<Vec<_>, _>>()?;
    let merged = join(dirs, shards.clone())?;
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
    let output = OutputDir::create(out, "--out", &REPORT_FOLDER)?;
    for (dir, file) in dirs.iter().zip(&shards) {
        for row in &file.rows {
            let from = dir.join(&row.name);
            if from.is_dir() {
                copy_reports(&from, &output, &row.name)?;
            }
        }
    }
    merged.write_into(&output)?;
    output.commit()?;
    Ok(merged)
}
