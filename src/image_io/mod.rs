//! Reading and writing images: PNG (8-bit) and OpenEXR (linear `f32`), written atomically.

mod exr_file;
mod png_file;

pub use exr_file::{ExrImage, decode_exr, encode_exr, read_exr, write_exr};
pub use png_file::{Rgb8Image, read_png, write_png};

use std::io::Write;
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

/// Checks that `path` can be written: its folder exists. Call before long work, so a bad output
/// path fails at once.
pub fn check_writable(path: &Path) -> Result<(), ImageError> {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Err(ImageError::io(
            path,
            format!("the output folder '{}' does not exist", dir.display()),
        ));
    }
    Ok(())
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder renamed into place, so a
/// failure never leaves a half-written file behind.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageError> {
    check_writable(path)?;
    let mut tmp =
        tempfile::NamedTempFile::new_in(parent_dir(path)).map_err(|e| ImageError::io(path, e))?;
    tmp.write_all(bytes).map_err(|e| ImageError::io(path, e))?;
    // Temporary files are created private (0600); an output is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(|e| ImageError::io(path, e))?;
    }
    tmp.persist(path)
        .map_err(|e| ImageError::io(path, e.error))?;
    Ok(())
}
