//! OpenEXR files: linear `f32` R, G, B, an optional `variance` layer, and string attributes.
//!
//! Placeholder: the golden work fills this in with a deterministic writer.

use std::path::Path;

use super::ImageError;
use crate::render::Film;

/// An EXR image as rtoracle reads it: mean R, G, B, the optional per-sample variance, and the
/// header's string attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Mean linear RGB, row-major, top row first.
    pub mean: Vec<[f32; 3]>,
    /// Per-sample variance of each channel, when the file has a `variance` layer.
    pub variance: Option<Vec<[f32; 3]>>,
    /// String attributes of the header, sorted by name.
    pub attributes: Vec<(String, String)>,
}

/// Writes a film as EXR (f32 R, G, B, and a `variance` layer when the film has one) with the
/// given string attributes, atomically and deterministically.
pub fn write_exr(
    path: &Path,
    _film: &Film,
    _attributes: &[(String, String)],
) -> Result<(), ImageError> {
    Err(ImageError::io(path, "EXR output is not implemented yet"))
}

/// Reads an EXR written by rtoracle or any RGB(A) EXR.
pub fn read_exr(path: &Path) -> Result<ExrImage, ImageError> {
    Err(ImageError::io(path, "EXR input is not implemented yet"))
}
