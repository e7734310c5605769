//! How far, beside whether: NVIDIA's FLIP between a reference and a test image.
//!
//! Promises: [`flip_of`] compares two images of linear RGB as an sRGB display shows them (each
//! value clamped to `[0, 1]`, encoded with the sRGB curve, rounded to 8 bits) with LDR-FLIP at
//! [`PIXELS_PER_DEGREE`] (FLIP's default: a 0.7 m wide 4K monitor seen from 0.7 m), and returns
//! the per-pixel error map (each in `[0, 1]`) with its mean, median, 99th percentile and
//! largest value. It is a figure for people (how visible the difference is), never a verdict:
//! the noise-aware test decides, FLIP says how far.
//!
//! FLIP is NVIDIA's own implementation, through the `nv-flip` crate (the bindings wgpu's image
//! tests use), rather than a port here: the metric is defined by that code, and a re-implementation
//! would be one more thing to test against it. Same inputs, same bytes: it runs on one thread and
//! has no randomness.

use serde::{Deserialize, Serialize};

/// FLIP's viewing condition: pixels per degree of visual angle (its default, 67.0).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// FLIP's summary of an error map.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlipSummary {
    /// The mean error over the pixels (0 equal, 1 as different as FLIP can say).
    pub mean: f64,
    /// The median pixel's error.
    pub median: f64,
    /// The 99th percentile of the pixels' errors (the worst 1% start here).
    pub p99: f64,
    /// The largest pixel error.
    pub max: f64,
}

/// An error map and its summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Flip {
    /// The summary.
    pub summary: FlipSummary,
    /// One error in `[0, 1]` per pixel, row-major, top row first.
    pub map: Vec<f32>,
}

/// The 8-bit sRGB code of a linear value, clamped to `[0, 1]` (NaN as 0).
fn srgb_code(x: f64) -> u8 {
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    let g = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (255.0 * g).round() as u8
}

fn codes(image: &[[f64; 3]]) -> Vec<u8> {
    image
        .iter()
        .flat_map(|p| p.map(srgb_code))
        .collect::<Vec<u8>>()
}

/// FLIP of `test` against `reference`, both `width * height` pixels of linear RGB (row-major, top
/// row first). `None` when the sizes do not match or the image is empty.
pub fn flip_of(
    reference: &[[f64; 3]],
    test: &[[f64; 3]],
    width: usize,
    height: usize,
) -> Option<Flip> {
    let pixels = width.checked_mul(height)?;
    if pixels == 0 || reference.len() != pixels || test.len() != pixels {
        return None;
    }
    let (w, h) = (u32::try_from(width).ok()?, u32::try_from(height).ok()?);
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, &codes(reference));
    let test = nv_flip::FlipImageRgb8::with_data(w, h, &codes(test));
    let map = nv_flip::flip(reference, test, PIXELS_PER_DEGREE).to_vec();
    Some(Flip {
        summary: summarise(&map),
        map,
    })
}

/// The mean, median, 99th percentile and largest value of an error map (NaN read as 1).
fn summarise(map: &[f32]) -> FlipSummary {
    let mut sorted: Vec<f64> = map
        .iter()
        .map(|&e| if e.is_nan() { 1.0 } else { e as f64 })
        .collect();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    // The nearest-rank percentile: the smallest value at or above a fraction q of the pixels.
    let rank = |q: f64| sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1];
    FlipSummary {
        mean: sorted.iter().sum::<f64>() / n as f64,
        median: rank(0.5),
        p99: rank(0.99),
        max: sorted[n - 1],
    }
}

/// The error map as an 8-bit RGB picture under FLIP's magma colour map (black no error,
/// yellow-white the largest), row-major, top row first.
pub fn magma_picture(map: &[f32], width: usize, height: usize) -> Option<Vec<u8>> {
    let (w, h) = (u32::try_from(width).ok()?, u32::try_from(height).ok()?);
    if map.len() != width.checked_mul(height)? || map.is_empty() {
        return None;
    }
    let errors = nv_flip::FlipImageFloat::with_data(w, h, map);
    Some(errors.apply_color_lut(&nv_flip::magma_lut()).to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(value: f64, n: usize) -> Vec<[f64; 3]> {
        vec![[value; 3]; n]
    }

    /// Equal images have no error anywhere (FLIP's definition: the error is a distance).
    #[test]
    fn equal_images_have_no_error() {
        let a: Vec<[f64; 3]> = (0..64 * 48)
            .map(|i| [(i % 64) as f64 / 64.0, (i / 64) as f64 / 48.0, 0.3])
            .collect();
        let f = flip_of(&a, &a, 64, 48).unwrap();
        assert_eq!(f.summary.max, 0.0);
        assert_eq!(f.map.len(), 64 * 48);
    }

    /// Black against white is as different as two colours get: FLIP's colour term is
    /// normalised by the largest distance in its colour space, so the error is near 1.
    #[test]
    fn black_against_white_is_near_the_largest_error() {
        let f = flip_of(&flat(0.0, 32 * 32), &flat(1.0, 32 * 32), 32, 32).unwrap();
        assert!(f.summary.median > 0.9, "{:?}", f.summary);
    }

    /// A larger difference is a larger error (monotone in the difference), and the summary is
    /// ordered: median <= p99 <= max, mean <= max.
    #[test]
    fn a_larger_difference_is_a_larger_error() {
        let base = flat(0.2, 32 * 32);
        let near = flip_of(&base, &flat(0.22, 32 * 32), 32, 32)
            .unwrap()
            .summary;
        let far = flip_of(&base, &flat(0.5, 32 * 32), 32, 32).unwrap().summary;
        assert!(near.mean < far.mean, "{near:?} {far:?}");
        for s in [near, far] {
            assert!(
                s.median <= s.p99 && s.p99 <= s.max && s.mean <= s.max,
                "{s:?}"
            );
        }
    }

    /// The sRGB codes: 0 and 1 at the ends, 0.5 at 188 (the sRGB curve of 0.5 is 0.7354), values
    /// past the ends clamped, NaN black.
    #[test]
    fn srgb_codes_by_hand() {
        assert_eq!(srgb_code(0.0), 0);
        assert_eq!(srgb_code(1.0), 255);
        assert_eq!(srgb_code(0.5), 188);
        assert_eq!(srgb_code(7.0), 255);
        assert_eq!(srgb_code(-1.0), 0);
        assert_eq!(srgb_code(f64::NAN), 0);
    }

    #[test]
    fn mismatched_or_empty_images_have_no_flip() {
        assert!(flip_of(&flat(0.0, 4), &flat(0.0, 6), 2, 2).is_none());
        assert!(flip_of(&[], &[], 0, 0).is_none());
    }

    /// The nearest-rank percentiles of 1..=100 (hundredths): median 0.50, p99 0.99.
    #[test]
    fn percentiles_by_hand() {
        let map: Vec<f32> = (1..=100).map(|i| i as f32 / 100.0).collect();
        let s = summarise(&map);
        assert!(
            (s.median - 0.5).abs() < 1e-6 && (s.p99 - 0.99).abs() < 1e-6,
            "{s:?}"
        );
        assert!(
            (s.max - 1.0).abs() < 1e-6 && (s.mean - 0.505).abs() < 1e-6,
            "{s:?}"
        );
    }
}
