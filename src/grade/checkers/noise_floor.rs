//! Is a render too clean for the samples per pixel it claims? The other half of "a render's
//! measured noise must fit the spp it claims" ([`crate::compare`]'s noise check is the half
//! that fails a render noisier than its claim).
//!
//! The grader asks for its renders at a few samples per pixel, so an honest render is noisy.
//! A picture made with many more samples (a reference render carried in, a golden, an average
//! of many renders) has the right mean but too little noise: its pixels sit closer to the
//! golden's means than `N` samples of any honest sampler can put them.
//!
//! The test, over the pixel-channels whose noise shows well above the code's width and that the
//! film's clamp cannot reach ([`too_clean`]'s conditions): with `d` the distance from the middle
//! of the candidate's code interval (of width `w`) to the golden's mean, an honest sampler whose
//! per-sample variance is at least [`FLOOR_LAMBDA`] times the golden's `s2` has
//! `E d^2 >= e = (sqrt(FLOOR_LAMBDA s2 / N) - w / 2)^2` (Minkowski: the code moves the mean by at
//! most `w / 2`). The squared distances are independent and non-negative, so Maurer's
//! inequality bounds the chance that their sum falls as far below `sum e` as it does:
//! `exp(-t^2 / (2 sum E d^4))`, with `E d^4` bounded by the fourth moment of a mean of `N`
//! samples within `b` of their mean (the golden's edge-tolerant bound), whose variance is at most
//! `lambda` times the golden's, plus the golden's own error and the code's half width. A render
//! fails when that chance is below [`FLOOR_ALPHA`].
//!
//! Measured (`tests/integration/attacks/renders.rs`, `course_grades.rs`): the course's own
//! renders pass it, and a reference render at 64 spp or more claimed as 2 to 5 spp fails it.

use serde::Serialize;

use crate::compare::{candidate::CandidateImage, encoding::Encoding, noise_model::Golden};

/// The least per-sample variance an honest sampler is assumed to have, as a share of the
/// golden's: a quarter (the course's samplers are the reference's; stratified jitter lowers the
/// variance of edge pixels only).
pub const FLOOR_LAMBDA: f64 = 0.25;

/// The false-failure bound of the test.
pub const FLOOR_ALPHA: f64 = 1e-6;

/// Fewer pixel-channels than this that show their noise, and the test says nothing.
pub const FLOOR_MIN_TERMS: usize = 200;

/// What the test found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoiseFloor {
    /// The samples per pixel the render claims.
    pub claimed_spp: u32,
    /// The pixel-channels judged.
    pub terms: usize,
    /// The sum of their squared distances to the golden.
    pub sum: f64,
    /// Its least expectation under the claim.
    pub floor: f64,
    /// The chance of a sum this low under the claim (Maurer's bound).
    pub p: f64,
    /// The samples per pixel the render's noise suggests (`None`: less noise than the golden's
    /// own error and the codes' rounding explain, as of a render of very many samples).
    pub effective_spp: Option<f64>,
    /// Whether the render is too clean for its claim (`p` below [`FLOOR_ALPHA`]).
    pub too_clean: bool,
}

impl NoiseFloor {
    /// The finding in words, for a diagnosis.
    pub fn sentence(&self) -> String {
        let about = match self.effective_spp {
            Some(e) => format!("that of about {e:.0} samples per pixel"),
            None => "less than any render of a few samples has".to_string(),
        };
        format!(
            "it is cleaner than a render of {} samples per pixel can be (its noise is {about}; p {:.1e} < {:.0e}): a picture rendered with more samples, not by your code at {} samples per pixel",
            self.claimed_spp, self.p, FLOOR_ALPHA, self.claimed_spp
        )
    }
}

/// The test of `candidate`, a render claimed to have `spp` samples per pixel, against `golden`
/// (`lambda`: how much more per-sample variance than the golden's an honest sampler may have;
/// `encoding`: how 8-bit codes are read). `None` when the sizes differ or too few pixels show
/// their noise to tell.
pub fn too_clean(
    candidate: &CandidateImage,
    golden: &Golden,
    spp: u32,
    lambda: f64,
    encoding: Encoding,
) -> Option<NoiseFloor> {
    let (width, height) = candidate.size();
    if (width, height) != (golden.width, golden.height) {
        return None;
    }
    let n = f64::from(spp.max(1));
    let m = f64::from(golden.samples_per_pixel.max(1));
    let table = encoding.table();
    let (top, _) = encoding.decode(254);
    let interval = |k: usize, c: usize| -> (f64, f64) {
        match candidate {
            CandidateImage::Rgb8 { data, .. } => table[usize::from(data[3 * k + c])],
            CandidateImage::Linear { data, .. } => {
                let x = f64::from(data[k][c]);
                (x, x)
            }
        }
    };
    let (mut terms, mut sum, mut floor, mut fourth) = (0usize, 0.0, 0.0, 0.0);
    let (mut s2_sum, mut excess) = (0.0, 0.0);
    for k in 0..width * height {
        for c in 0..3 {
            let (lo, hi) = interval(k, c);
            let (mu, s2) = (golden.mean[k][c], golden.variance[k][c]);
            let b = golden.bound[k][c];
            let w = hi - lo;
            let sd_lo = (FLOOR_LAMBDA * s2 / n).sqrt();
            let sd_hi = (lambda * s2 / n).sqrt();
            // Noise well above the code's width, and a mean the clamp cannot reach.
            if !(s2 > 0.0 && sd_lo >= 2.0 * w && mu + 3.0 * sd_hi < top && hi <= top) {
                continue;
            }
            let d = 0.5 * (lo + hi) - mu;
            terms += 1;
            sum += d * d;
            floor += (sd_lo - w / 2.0).powi(2);
            let sigma2 = lambda * s2;
            let m4 = b * b * sigma2 / (n * n * n) + 3.0 * sigma2 * sigma2 / (n * n);
            let g4 = 3.0 * (s2 / m).powi(2);
            fourth += (m4.powf(0.25) + g4.powf(0.25) + w / 2.0).powi(4);
            s2_sum += s2;
            excess += d * d - w * w / 12.0 - s2 / m;
        }
    }
    if terms < FLOOR_MIN_TERMS {
        return None;
    }
    let p = if sum < floor {
        (-(floor - sum).powi(2) / (2.0 * fourth)).exp()
    } else {
        1.0
    };
    Some(NoiseFloor {
        claimed_spp: spp,
        terms,
        sum,
        floor,
        p,
        effective_spp: (excess > 0.0).then(|| s2_sum / excess),
        too_clean: p < FLOOR_ALPHA,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A golden of `w x h` pixels, every channel of mean 0.25 and per-sample variance `s2`.
    fn flat_golden(w: usize, h: usize, s2: f64) -> Golden {
        Golden::new(
            w,
            h,
            4096,
            vec![[0.25; 3]; w * h],
            vec![[s2; 3]; w * h],
            None,
        )
        .unwrap()
    }

    /// A linear candidate whose pixel means are those of `spp` samples of a two-point
    /// distribution of the golden's mean and variance (exact: a fixed seed's draws).
    fn rendered(w: usize, h: usize, s2: f64, spp: u32, seed: u64) -> CandidateImage {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let sd = s2.sqrt();
        let data = (0..w * h)
            .map(|_| {
                let mut px = [0f32; 3];
                for v in &mut px {
                    let mean: f64 = (0..spp)
                        .map(|_| if next() < 0.5 { 0.25 - sd } else { 0.25 + sd })
                        .sum::<f64>()
                        / f64::from(spp);
                    *v = mean as f32;
                }
                px
            })
            .collect();
        CandidateImage::Linear {
            width: w,
            height: h,
            data,
        }
    }

    #[test]
    fn honest_renders_pass_and_clean_ones_fail() {
        // 128 x 96 pixels: about as many noisy pixel-channels as a variant of the course's scenes.
        let (w, h, s2) = (128, 96, 0.01);
        let golden = flat_golden(w, h, s2);
        for seed in 0..10 {
            for spp in [2, 4, 5] {
                let honest = rendered(w, h, s2, spp, seed);
                let f = too_clean(&honest, &golden, spp, 2.25, Encoding::Course).unwrap();
                assert!(!f.too_clean, "seed {seed} spp {spp}: {f:?}");
                let e = f.effective_spp.unwrap();
                assert!((e / f64::from(spp) - 1.0).abs() < 0.2, "{e} for {spp}");
                // The same distribution at 64 samples, claimed as `spp`: too clean.
                let clean = rendered(w, h, s2, 64, seed + 1000);
                let f = too_clean(&clean, &golden, spp, 2.25, Encoding::Course).unwrap();
                assert!(f.too_clean, "seed {seed} spp {spp}: {f:?}");
            }
        }
        // The golden's own means: no noise at all.
        let exact = CandidateImage::Linear {
            width: w,
            height: h,
            data: vec![[0.25; 3]; w * h],
        };
        let f = too_clean(&exact, &golden, 4, 2.25, Encoding::Course).unwrap();
        assert!(f.too_clean && f.effective_spp.is_none(), "{f:?}");
        assert!(
            f.sentence()
                .contains("cleaner than a render of 4 samples per pixel")
        );
    }

    #[test]
    fn too_few_noisy_pixels_or_another_size_say_nothing() {
        let golden = flat_golden(8, 8, 0.01);
        let c = rendered(8, 8, 0.01, 4, 1);
        assert!(too_clean(&c, &golden, 4, 2.25, Encoding::Course).is_none());
        let quiet = flat_golden(64, 48, 0.0);
        let c = rendered(64, 48, 0.0, 4, 1);
        assert!(too_clean(&c, &quiet, 4, 2.25, Encoding::Course).is_none());
        let c = rendered(32, 48, 0.01, 4, 1);
        assert!(too_clean(&c, &flat_golden(64, 48, 0.01), 4, 2.25, Encoding::Course).is_none());
    }
}
