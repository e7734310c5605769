//! What a batch keeps of each submission it graded, so that `grade --merge` can do what grading
//! the batch whole does: `<name>/batch-entry.json` ([`EntryFile`]), the submission's report as
//! graded (before the batch compared it with the others), the fingerprints of its uploaded
//! images (what the copy check across submissions needs) and every vector it failed (what the
//! summary counts). The merge reads every shard's entries, compares every two submissions'
//! images across the shards, and writes every report from them: the same bytes as the whole
//! batch's.

use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::grade::checkers::copies::Fingerprint;
use crate::grade::result::GradeReport;
use crate::oracle::vectors::ShapeKind;

/// The entry's file in a submission's report folder.
pub const ENTRY_FILE: &str = "batch-entry.json";

/// What the entry says it is.
pub const ENTRY_SCHEMA: &str = "rtoracle-batch-entry";

/// The version of its layout.
pub const ENTRY_VERSION: u32 = 1;

/// An image's fingerprint as the entry keeps it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredFingerprint {
    /// The image group's id.
    pub group: String,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The SHA-256 of its pixels.
    pub sha256: String,
    /// The busy pixels, 7 bytes each in hex: the position (`y * width + x`, 4 bytes,
    /// big-endian) and the red, green and blue codes.
    pub busy: String,
}

/// `<name>/batch-entry.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EntryFile {
    /// [`ENTRY_SCHEMA`].
    pub schema: String,
    /// [`ENTRY_VERSION`].
    pub version: u32,
    /// The report as graded, before the batch's comparison of submissions.
    pub report: GradeReport,
    /// Every definite vector it failed.
    pub failed_vectors: Vec<(String, ShapeKind)>,
    /// Its uploaded images' fingerprints, by image group.
    pub fingerprints: Vec<StoredFingerprint>,
}

fn hex_of(busy: &[(u32, [u8; 3])]) -> String {
    let mut s = String::with_capacity(14 * busy.len());
    for (p, rgb) in busy {
        let _ = write!(s, "{p:08x}{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2]);
    }
    s
}

/// Why an entry file cannot be merged; each says so in words that follow the file's name.
#[derive(Debug, thiserror::Error)]
pub enum EntryError {
    /// The file could not be read.
    #[error("cannot read it ({0})")]
    Unreadable(std::io::Error),
    /// Its content is not an entry's JSON.
    #[error("not a batch entry of rtoracle's: {0}")]
    NotAnEntry(serde_json::Error),
    /// An entry of another layout (another version of rtoracle wrote it).
    #[error(
        "a batch entry of layout {schema} {version}, this rtoracle reads {ENTRY_SCHEMA} {ENTRY_VERSION}"
    )]
    OtherLayout {
        /// The layout's name the file states.
        schema: String,
        /// Its version.
        version: u32,
    },
    /// A fingerprint's record is malformed (what is wrong with it).
    #[error("{0}")]
    BadFingerprint(String),
}

fn busy_of(hex: &str) -> Result<Vec<(u32, [u8; 3])>, String> {
    if hex.len() % 14 != 0 || !hex.is_ascii() {
        return Err("a fingerprint's busy pixels are not 7-byte hex records".into());
    }
    let byte = |s: &str| u8::from_str_radix(s, 16).map_err(|e| e.to_string());
    (0..hex.len() / 14)
        .map(|i| {
            let r = &hex[14 * i..14 * i + 14];
            let p = u32::from_str_radix(&r[..8], 16).map_err(|e| e.to_string())?;
            Ok((p, [byte(&r[8..10])?, byte(&r[10..12])?, byte(&r[12..14])?]))
        })
        .collect()
}

impl EntryFile {
    /// The entry of `report` (as graded, before the batch's comparison).
    pub fn of(report: &GradeReport) -> EntryFile {
        EntryFile {
            schema: ENTRY_SCHEMA.to_string(),
            version: ENTRY_VERSION,
            report: report.clone(),
            failed_vectors: report.code.failed_vectors.clone(),
            fingerprints: report
                .fingerprints
                .iter()
                .map(|(group, f)| StoredFingerprint {
                    group: group.clone(),
                    width: f.width,
                    height: f.height,
                    sha256: f.sha256.clone(),
                    busy: hex_of(&f.busy),
                })
                .collect(),
        }
    }

    /// The entry as the bytes of its file.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut json = serde_json::to_string(self).expect("an entry always serialises");
        json.push('\n');
        json.into_bytes()
    }

    /// Reads the entry file at `path`: the report with its fingerprints and failed vectors.
    pub fn read(path: &Path) -> Result<GradeReport, EntryError> {
        let text = std::fs::read_to_string(path).map_err(EntryError::Unreadable)?;
        let entry: EntryFile = serde_json::from_str(&text).map_err(EntryError::NotAnEntry)?;
        if entry.schema != ENTRY_SCHEMA || entry.version != ENTRY_VERSION {
            return Err(EntryError::OtherLayout {
                schema: entry.schema,
                version: entry.version,
            });
        }
        let mut report = entry.report;
        report.code.failed_vectors = entry.failed_vectors;
        report.fingerprints = entry
            .fingerprints
            .into_iter()
            .map(|f| {
                let busy = busy_of(&f.busy)?;
                let fingerprint = Fingerprint {
                    width: f.width,
                    height: f.height,
                    sha256: f.sha256,
                    busy,
                };
                Ok((f.group, Arc::new(fingerprint)))
            })
            .collect::<Result<_, String>>()
            .map_err(EntryError::BadFingerprint)?;
        Ok(report)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn busy_pixels_come_back_as_they_were() {
        let busy = vec![
            (0, [0, 1, 2]),
            (u32::MAX, [255, 128, 7]),
            (90_000, [9, 9, 9]),
        ];
        let hex = hex_of(&busy);
        assert_eq!(hex.len(), 14 * 3);
        assert_eq!(&hex[..14], "00000000000102");
        assert_eq!(busy_of(&hex).unwrap(), busy);
        assert!(busy_of("0000").is_err());
        assert!(busy_of("zz000000000102").is_err());
    }
}
