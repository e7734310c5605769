//! The signed z maps: one per channel (red, green, blue, side by side, [`GAP`] pixels apart),
//! orange where the candidate is higher than the golden, purple where it is lower, white where
//! it agrees, the colour full from `|z| =` [`SATURATE`] on; every failing region outlined in
//! green in each map. Three maps, not one, so that a colour change (red up, blue down) does not
//! read as a brighter image.

use std::path::Path;

use super::{CompareError, Comparison};
use crate::image_io::{Rgb8Image, write_png};

/// `|z|` from which the colour is full.
pub const SATURATE: f32 = 8.0;
/// The colour of a channel higher than the golden's (`z >= SATURATE`).
pub const HIGHER: [u8; 3] = [230, 97, 1];
/// The colour of a channel lower than the golden's (`z <= -SATURATE`).
pub const LOWER: [u8; 3] = [94, 60, 153];
/// The outline of failing regions.
pub const OUTLINE: [u8; 3] = [0, 170, 0];
/// White columns between the three maps.
pub const GAP: usize = 4;

/// The colour of a signed `z`: white at 0, blended linearly towards [`HIGHER`] or [`LOWER`].
pub fn colour(z: f32) -> [u8; 3] {
    let t = (z.abs() / SATURATE).min(1.0);
    let end = if z > 0.0 { HIGHER } else { LOWER };
    end.map(|e| (255.0 + t * (f32::from(e) - 255.0)).round() as u8)
}

/// The three maps as one image, `3 w + 2 GAP` wide.
pub fn heatmap_image(comparison: &Comparison) -> Rgb8Image {
    let (w, h) = (comparison.width, comparison.height);
    let out_w = 3 * w + 2 * GAP;
    let mut data = vec![255u8; 3 * out_w * h];
    for (i, z) in comparison.z_map.iter().enumerate() {
        let (x, y) = (i % w, i / w);
        for (c, &zc) in z.iter().enumerate() {
            let at = 3 * (y * out_w + c * (w + GAP) + x);
            data[at..at + 3].copy_from_slice(&colour(zc));
        }
    }
    let mut put = |x: usize, y: usize| {
        if x < w && y < h {
            for c in 0..3 {
                let at = 3 * (y * out_w + c * (w + GAP) + x);
                data[at..at + 3].copy_from_slice(&OUTLINE);
            }
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
        width: out_w,
        height: h,
        data,
    }
}

/// The heatmap as PNG bytes.
pub fn heatmap_png(comparison: &Comparison) -> Result<Vec<u8>, CompareError> {
    crate::image_io::encode_png(&heatmap_image(comparison))
        .map_err(|message| CompareError::Golden(format!("cannot encode the heatmap: {message}")))
}

/// Writes the heatmap PNG atomically.
pub fn write_heatmap(path: &Path, comparison: &Comparison) -> Result<(), CompareError> {
    Ok(write_png(path, &heatmap_image(comparison))?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_run_from_purple_through_white_to_orange() {
        assert_eq!(colour(0.0), [255; 3]);
        assert_eq!(colour(SATURATE), HIGHER);
        assert_eq!(colour(1000.0), HIGHER);
        assert_eq!(colour(-SATURATE), LOWER);
        // Half way: half way between white and the end, per channel.
        assert_eq!(colour(-SATURATE / 2.0), [175, 158, 204]);
    }
}
