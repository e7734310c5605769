//! Reading and writing images: PNG (8-bit) and OpenEXR (linear `f32`), written atomically
//! (through [`crate::output`]: the whole file or nothing, also on Ctrl-C).

mod exr_file;
mod png_file;

pub use exr_file::{ExrImage, decode_exr, encode_exr, exr_part_sizes, read_exr, write_exr};
pub use png_file::{PNG_DECODE_ALLOWANCE, Rgb8Image, encode_png, read_png, write_png};

use std::path::{Path, PathBuf};

/// What can go wrong reading or writing an image (one line, naming the file).
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be opened, read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The file is not a usable image of the expected kind.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
}

impl ImageError {
    /// `path` could not be read: "no such file" and "is a folder" in those words, else the
    /// system's reason.
    pub(crate) fn unreadable(path: &Path, e: &std::io::Error) -> Self {
        let message = match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".to_string(),
            std::io::ErrorKind::IsADirectory => "is a folder, not an image".to_string(),
            _ => format!("cannot read: {e}"),
        };
        ImageError::io(path, message)
    }

    pub(crate) fn io(path: &Path, message: impl std::fmt::Display) -> Self {
        ImageError::Io {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
    pub(crate) fn format(path: &Path, message: impl std::fmt::Display) -> Self {
        ImageError::Format {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}

/// Checks that `path` can be written (see [`crate::output::check_output_file`]). Call before
/// long work, so a bad output path fails at once.
pub fn check_writable(path: &Path) -> Result<(), ImageError> {
    crate::output::check_output_file(path, "").map_err(|e| ImageError::io(path, e.message))
}

/// Writes `bytes` to `path` through a temporary file in the same folder renamed into place, so a
/// failure or an interruption never leaves a half-written file behind (see
/// [`crate::output::OutputFile`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    crate::output::write_file(path, "", bytes).map_err(|e| ImageError::io(path, e.message))
}
