use glam::DVec3;

use crate::scene::Profile;

/// A rendered image: the per-pixel mean of the samples and, when asked for, the per-sample
/// (unbiased) variance of each channel. Row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Samples per pixel the film was rendered with.
    pub samples_per_pixel: u32,
    /// Mean linear RGB per pixel: the sum of the samples divided by their number, or, when all
    /// the samples are equal, that value exactly.
    pub mean: Vec<DVec3>,
    /// Per-sample variance per pixel and channel (Welford's update, divided by `n - 1`).
    pub variance: Option<Vec<DVec3>>,
    /// Per pixel and channel, the largest distance of one of its samples from its mean; kept
    /// with the variance. A golden's measured bound on a sample (see
    /// `compare::noise_model::Golden`): a rare bright path the variance hardly shows still shows here.
    pub deviation: Option<Vec<DVec3>>,
}

impl Film {
    /// The mean at column `x`, row `y`.
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> DVec3 {
        self.mean[y * self.width + x]
    }

    /// The image as 8-bit RGB under the course's encoding ([`encode_course_png`]).
    pub fn to_course_rgb8(&self) -> Vec<u8> {
        self.mean
            .iter()
            .flat_map(|c| c.to_array().map(encode_course_png))
            .collect()
    }
}

impl Film {
    /// The image as 8-bit RGB under `profile`'s encoding: the course's
    /// ([`encode_course_png`]) or the book's ([`encode_book_png`]).
    pub fn to_rgb8(&self, profile: Profile) -> Vec<u8> {
        let encode = match profile {
            Profile::Course => encode_course_png,
            Profile::Physical => encode_book_png,
        };
        self.mean
            .iter()
            .flat_map(|c| c.to_array().map(encode))
            .collect()
    }
}

/// The book's encoding of one linear value (`write_color`): `linear_to_gamma` (`sqrt`, 0 for
/// values that are not positive), clamped to `[0, 0.999]`, times 256, truncated. So 255 is the
/// largest code, reached from `(255/256)^2` up.
#[inline]
pub fn encode_book_png(linear: f64) -> u8 {
    let gamma = if linear > 0.0 { linear.sqrt() } else { 0.0 };
    (256.0 * gamma.clamp(0.0, 0.999)) as u8
}

/// The course's encoding of one linear value: `sqrt` (gamma 2, 0 for negative values), clamped to
/// `[0, 0.999]`, times 255, truncated. So 254 is the largest code.
#[inline]
pub fn encode_course_png(linear: f64) -> u8 {
    let gamma = if linear > 0.0 { linear.sqrt() } else { 0.0 };
    (255.0 * gamma.clamp(0.0, 0.999)) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn course_encoding_matches_its_formula() {
        assert_eq!(encode_course_png(0.0), 0);
        assert_eq!(encode_course_png(-1.0), 0);
        assert_eq!(encode_course_png(1.0), 254);
        assert_eq!(encode_course_png(4.0), 254);
        // sqrt(0.25) = 0.5, 127.5 truncates to 127.
        assert_eq!(encode_course_png(0.25), 127);
        assert_eq!(encode_course_png(f64::NAN), 0);
    }

    #[test]
    fn book_encoding_matches_its_formula() {
        assert_eq!(encode_book_png(0.0), 0);
        assert_eq!(encode_book_png(-1.0), 0);
        assert_eq!(encode_book_png(1.0), 255);
        // sqrt(0.25) = 0.5, 128 exactly.
        assert_eq!(encode_book_png(0.25), 128);
        // 0.999 * 256 = 255.744.
        assert_eq!(encode_book_png(0.998), 255);
        assert_eq!(encode_book_png(f64::NAN), 0);
    }
}
