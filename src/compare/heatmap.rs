//! The signed z-map: red where the candidate is brighter than the golden, blue where darker,
//! white where it agrees, failing regions outlined in green.

use std::path::Path;

use super::{CompareError, Comparison};
use crate::image_io::{Rgb8Image, write_png};

/// |z| at which the colour saturates.
const SATURATE: f32 = 8.0;
const OUTLINE: [u8; 3] = [0, 170, 0];

/// The heatmap as an image.
pub fn heatmap_image(comparison: &Comparison) -> Rgb8Image {
    let (w, h) = (comparison.width, comparison.height);
    let mut data = Vec::with_capacity(w * h * 3);
    for &z in &comparison.z_map {
        let t = (z.abs() / SATURATE).min(1.0);
        let fade = (255.0 * (1.0 - t)).round() as u8;
        data.extend_from_slice(&if z > 0.0 {
            [255, fade, fade]
        } else {
            [fade, fade, 255]
        });
    }
    let mut put = |x: usize, y: usize| {
        if x < w && y < h {
            data[3 * (y * w + x)..3 * (y * w + x) + 3].copy_from_slice(&OUTLINE);
        }
    };
    // Every failing region, not only the ones the report lists.
    let regions = if comparison.outline.len() >= comparison.regions.len() {
        &comparison.outline
    } else {
        &comparison.regions
    };
    for r in regions {
        let (x1, y1) = (r.x + r.width - 1, r.y + r.height - 1);
        for x in r.x..=x1 {
            put(x, r.y);
            put(x, y1);
        }
        for y in r.y..=y1 {
            put(r.x, y);
            put(x1, y);
        }
    }
    Rgb8Image {
        width: w,
        height: h,
        data,
    }
}

/// Writes the heatmap PNG atomically.
pub fn write_heatmap(path: &Path, comparison: &Comparison) -> Result<(), CompareError> {
    Ok(write_png(path, &heatmap_image(comparison))?)
}
