//! A render's work, shared by the general path and the pinhole fast path: how sample positions
//! are drawn in a pixel ([`PixelJitter`]), a pixel's running sums ([`Moments`]), and the job
//! ([`Job`]) that renders rows through any [`Trace`].

use glam::DVec3;
use indicatif::ProgressBar;
use rayon::prelude::*;

use super::PixelSampler;
use crate::geometry::Ray;
use crate::scene::Camera;

/// How the sample positions inside a pixel are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelJitter {
    /// The course's: uniform in `[-0.5, 0.5)` around the pixel centre, independently per sample.
    #[default]
    Uniform,
    /// Stratified: the pixel is cut into an `m x n` grid of cells (as square as the sample count
    /// allows) and each sample is uniform in its own cell; a different honest sampler with the
    /// same expectation.
    Stratified,
    /// No jitter: every sample goes through the pixel's centre (draws no random numbers). For
    /// analytic checks, where a pixel's value must be a function of one known ray.
    Centre,
}

/// The grid `(columns, rows)` of a stratified pixel with `n` samples: the largest divisor of `n`
/// not above `sqrt(n)` gives the rows.
fn strata(n: u32) -> (u32, u32) {
    let mut rows = (n as f64).sqrt() as u32;
    while rows > 1 && n % rows != 0 {
        rows -= 1;
    }
    let rows = rows.max(1);
    (n / rows, rows)
}

/// How a renderer draws the rows of a [`Job`]: the general path (one ray at a time through the
/// scene, or four paths at a time in a small scene of spheres and quads, `render::fast::lanes`), or the
/// pinhole fast path (`render::fast::pinhole`), each giving the same film bit for bit.
pub(super) trait Trace: Sync + Sized {
    /// Renders row `j` of `job` into `means` (and `variances` when `VARIANCE`) with the jitter
    /// `JITTER` (0 uniform, 1 stratified, 2 centre, 3 the course's jittered sampling).
    fn row<const VARIANCE: bool, const JITTER: u8>(
        job: &Job<'_, Self>,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [Spread],
    );
}

/// The running sums of one pixel's samples, one colour per `[f64; 4]` (red, green, blue, and a
/// lane that stays zero), so each update is one vector operation per step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Moments {
    sum: [f64; 4],
    /// The pixel's first sample.
    first: [f64; 4],
    /// Per channel, all ones while every sample so far equals the first (`==`), else zero.
    same: [u64; 4],
    running_mean: [f64; 4],
    m2: [f64; 4],
    /// Per channel, the smallest and the largest sample so far (kept when `VARIANCE`).
    lo: [f64; 4],
    hi: [f64; 4],
}

/// What a pixel's samples say of their spread, kept for goldens: the per-sample variance of each
/// channel, and the largest distance of a sample from the mean (`max(hi - mean, mean - lo)`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Spread {
    /// Per-sample variance (Welford's update, divided by `n - 1`).
    pub(super) variance: DVec3,
    /// The largest `|sample - mean|` of the pixel's samples.
    pub(super) deviation: DVec3,
}

impl Spread {
    /// No spread: every sample equal.
    pub(super) const ZERO: Spread = Spread {
        variance: DVec3::ZERO,
        deviation: DVec3::ZERO,
    };
}

impl Moments {
    /// The sums of a pixel whose first sample is `first` (not yet added).
    #[inline(always)]
    pub(super) fn new(first: [f64; 4]) -> Self {
        Self {
            sum: [0.0; 4],
            first,
            same: [u64::MAX; 4],
            running_mean: [0.0; 4],
            m2: [0.0; 4],
            lo: [f64::INFINITY; 4],
            hi: [f64::NEG_INFINITY; 4],
        }
    }

    /// Adds sample number `s` (from 0), in order: the sum, whether it equals the first, and
    /// (when `VARIANCE`) Welford's update and the smallest and largest sample.
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::needless_range_loop)]
    pub(super) fn add<const VARIANCE: bool>(&mut self, colour: [f64; 4], s: u32) {
        let n = (s + 1) as f64;
        for c in 0..4 {
            self.sum[c] += colour[c];
            self.same[c] &= if colour[c] == self.first[c] {
                u64::MAX
            } else {
                0
            };
            if VARIANCE {
                let delta = colour[c] - self.running_mean[c];
                self.running_mean[c] += delta / n;
                self.m2[c] += delta * (colour[c] - self.running_mean[c]);
                self.lo[c] = self.lo[c].min(colour[c]);
                self.hi[c] = self.hi[c].max(colour[c]);
            }
        }
    }

    /// The pixel's mean of `spp` samples into `mean`: the sum over the count, except when every
    /// sample equals the first (in every channel): then that colour exactly, since a sum of
    /// equal values over their count can be off by an ulp: (0.2 + 0.2 + 0.2) / 3 =
    /// 0.20000000000000004. When `VARIANCE`, the unbiased variance and the largest deviation
    /// from that mean into `spread`.
    #[inline(always)]
    pub(super) fn store<const VARIANCE: bool>(
        &self,
        spp: u32,
        mean: &mut DVec3,
        spread: Option<&mut Spread>,
    ) {
        let [fx, fy, fz, _] = self.first;
        let [sx, sy, sz, _] = self.sum;
        *mean = if self.same[..3].iter().all(|&same| same != 0) {
            DVec3::new(fx, fy, fz)
        } else {
            DVec3::new(sx, sy, sz) / spp as f64
        };
        if let (true, Some(spread)) = (VARIANCE, spread) {
            let [mx, my, mz, _] = self.m2;
            spread.variance = if spp > 1 {
                DVec3::new(mx, my, mz) / (spp - 1) as f64
            } else {
                DVec3::ZERO
            };
            let m = *mean;
            let [lx, ly, lz, _] = self.lo;
            let [hx, hy, hz, _] = self.hi;
            let (lo, hi) = (DVec3::new(lx, ly, lz), DVec3::new(hx, hy, hz));
            // Zero when every sample is the mean (and for a pixel of no sample, whose bounds
            // are still infinite).
            let d = (hi - m).max(m - lo);
            spread.deviation = DVec3::select(d.is_finite_mask(), d.max(DVec3::ZERO), DVec3::ZERO);
        }
    }
}

/// Everything a row needs, shared by all rows.
pub(super) struct Job<'a, T> {
    pub(super) tracer: &'a T,
    pub(super) camera: &'a Camera,
    pub(super) spp: u32,
    pub(super) seed: u64,
    jitter: PixelJitter,
    strata: (u32, u32),
    /// The course's jittered sampling (weeks 9 and 10), when it is used: strata a side and the
    /// frozen step.
    course: Option<(u32, f64)>,
    /// What every sample is multiplied by (the course's jittered sampling's `m^2 / spp`).
    pub(super) scale: f64,
}

impl<'a, T: Trace> Job<'a, T> {
    /// A job of `spp` samples per pixel through `tracer`.
    pub(super) fn new(
        tracer: &'a T,
        camera: &'a Camera,
        spp: u32,
        seed: u64,
        jitter: PixelJitter,
    ) -> Self {
        Self {
            tracer,
            camera,
            spp,
            seed,
            jitter,
            strata: strata(spp),
            course: None,
            scale: 1.0,
        }
    }

    /// A job of `spp` samples per pixel (a multiple of `grid^2`) under the course's jittered
    /// sampling: `grid` strata a side, the frozen `step`, every sample times `scale`.
    pub(super) fn course_jittered(
        tracer: &'a T,
        camera: &'a Camera,
        spp: u32,
        seed: u64,
        (grid, step): (u32, f64),
        scale: f64,
    ) -> Self {
        Self {
            course: Some((grid, step)),
            scale,
            ..Self::new(tracer, camera, spp, seed, PixelJitter::Uniform)
        }
    }

    /// Sample `s`'s camera ray through pixel `(i, j)`, drawn from the pixel's `sampler` in the
    /// renderer's order: the x then the y offset ([`Job::offsets`]), then a disk point under
    /// defocus, then, when something in the scene `moves`, the ray's time.
    #[inline(always)]
    pub(super) fn sample_ray<const JITTER: u8>(
        &self,
        sampler: &mut PixelSampler,
        (i, j): (usize, usize),
        s: u32,
        moves: bool,
    ) -> Ray {
        let (ox, oy) = self.offsets::<JITTER>(sampler, s);
        let disk = if self.camera.defocus {
            sampler.in_unit_disk()
        } else {
            (0.0, 0.0)
        };
        let mut ray = self.camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
        if moves {
            ray.time = sampler.next_f64();
        }
        ray
    }

    /// Sample `s`'s offset from its pixel's centre, drawn from `sampler` (x, then y) under the
    /// jitter `JITTER`.
    #[inline(always)]
    pub(super) fn offsets<const JITTER: u8>(
        &self,
        sampler: &mut PixelSampler,
        s: u32,
    ) -> (f64, f64) {
        let (columns, rows_of_strata) = self.strata;
        match JITTER {
            0 => (sampler.next_f64() - 0.5, sampler.next_f64() - 0.5),
            1 => {
                let (cx, cy) = ((s % columns) as f64, (s / columns) as f64);
                (
                    (cx + sampler.next_f64()) / columns as f64 - 0.5,
                    (cy + sampler.next_f64()) / rows_of_strata as f64 - 0.5,
                )
            }
            3 => {
                // Weeks 9 and 10's `pixel_sample_square`: stratum `(s_i, s_j)` of a `grid`-wide
                // grid, offset `0.5 (-0.5 + step (s + U))` on each axis. Course departure: the
                // step is the frozen `one_over_sqrt_spp`, so the offsets need not cover the
                // pixel (week 9: [-0.25, 0.58), week 10: [-0.25, 1.33)).
                let (grid, step) = self.course.unwrap_or((1, 1.0));
                let cell = s % (grid * grid);
                let (si, sj) = ((cell % grid) as f64, (cell / grid) as f64);
                (
                    0.5 * (-0.5 + step * (si + sampler.next_f64())),
                    0.5 * (-0.5 + step * (sj + sampler.next_f64())),
                )
            }
            _ => (0.0, 0.0),
        }
    }

    /// Renders row `j` into `means` (and `variances` when `VARIANCE`), with AVX2 where the
    /// processor has it (four lanes per vector instead of two: the same operations, so the same
    /// bits).
    #[inline]
    fn row<const VARIANCE: bool>(&self, j: usize, means: &mut [DVec3], variances: &mut [Spread]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2, just checked.
            unsafe { self.row_avx2::<VARIANCE>(j, means, variances) };
            return;
        }
        self.row_any::<VARIANCE>(j, means, variances);
    }

    /// [`Self::row_any`] compiled for AVX2.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2. (An `unsafe fn` rather than a safe one with the target
    /// feature, which needs Rust 1.86, above the crate's minimum.)
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) unsafe fn row_avx2<const VARIANCE: bool>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [Spread],
    ) {
        self.row_any::<VARIANCE>(j, means, variances);
    }

    /// Renders row `j` with the jitter chosen, fixed at compile time so the per-sample loop has
    /// no branch on it.
    #[inline(always)]
    pub(super) fn row_any<const VARIANCE: bool>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [Spread],
    ) {
        if self.course.is_some() {
            return T::row::<VARIANCE, 3>(self, j, means, variances);
        }
        match self.jitter {
            PixelJitter::Uniform => T::row::<VARIANCE, 0>(self, j, means, variances),
            PixelJitter::Stratified => T::row::<VARIANCE, 1>(self, j, means, variances),
            PixelJitter::Centre => T::row::<VARIANCE, 2>(self, j, means, variances),
        }
    }

    /// Renders every row into `mean` (and `variance` when it is not empty), rows in parallel.
    pub(super) fn run(&self, mean: &mut [DVec3], variance: &mut [Spread], progress: &ProgressBar) {
        let width = self.camera.width;
        if variance.is_empty() {
            mean.par_chunks_mut(width)
                .enumerate()
                .for_each(|(j, means)| {
                    self.row::<false>(j, means, &mut []);
                    progress.inc(1);
                });
        } else {
            mean.par_chunks_mut(width)
                .zip(variance.par_chunks_mut(width))
                .enumerate()
                .for_each(|(j, (means, variances))| {
                    self.row::<true>(j, means, variances);
                    progress.inc(1);
                });
        }
    }
}

/// The film of `job`, row by row on this thread (the dispatch's path), as the bits of its means
/// then its variances and deviations.
#[cfg(test)]
pub(super) fn film_bits<T: Trace>(job: &Job<'_, T>) -> Vec<u64> {
    film_bits_with(job, |job, j, means, variances| {
        job.row::<true>(j, means, variances)
    })
}

/// [`film_bits`] with each row rendered by `row` (one of the dispatch's paths).
#[cfg(test)]
pub(super) fn film_bits_with<T: Trace>(
    job: &Job<'_, T>,
    row: impl Fn(&Job<'_, T>, usize, &mut [DVec3], &mut [Spread]),
) -> Vec<u64> {
    let (width, height) = (job.camera.width, job.camera.height);
    let mut mean = vec![DVec3::ZERO; width * height];
    let mut variance = vec![Spread::ZERO; width * height];
    for (j, (means, variances)) in mean
        .chunks_mut(width)
        .zip(variance.chunks_mut(width))
        .enumerate()
    {
        row(job, j, means, variances);
    }
    mean.iter()
        .chain(variance.iter().map(|s| &s.variance))
        .chain(variance.iter().map(|s| &s.deviation))
        .flat_map(|c| c.to_array().map(f64::to_bits))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Week 9's jitter (a grid of 5, the frozen step 1/3): stratum `(s_i, s_j)` is offset by
    /// `0.5 (-0.5 + (s + U) / 3)`, so the first column lies in `[-0.25, -0.0833)` and the last
    /// in `[0.4167, 0.5833)`: the offsets reach past the pixel's right half and never cover its
    /// left quarter (the course's departure).
    #[test]
    fn course_jitter_puts_each_stratum_where_the_course_does() {
        let world = crate::scene::World::from(crate::scene::Scene::default());
        let camera = crate::scene::builtin("week04-quad")
            .unwrap()
            .camera(Some(4));
        let job = Job::course_jittered(&world, &camera, 25, 0, (5, 1.0 / 3.0), 25.0 / 30.0);
        let mut sampler = PixelSampler::new(3, 3);
        for round in 0..200 {
            for s in 0..25u32 {
                let (ox, oy) = job.offsets::<3>(&mut sampler, s + 25 * round);
                let (si, sj) = ((s % 5) as f64, (s / 5) as f64);
                for (o, k) in [(ox, si), (oy, sj)] {
                    let lo = 0.5 * (-0.5 + k / 3.0);
                    let hi = 0.5 * (-0.5 + (k + 1.0) / 3.0);
                    assert!(
                        o >= lo - 1e-15 && o < hi + 1e-15,
                        "stratum {s}: {o} outside [{lo}, {hi})"
                    );
                }
            }
        }
    }

    #[test]
    fn strata_are_as_square_as_the_count_allows() {
        assert_eq!(strata(16), (4, 4));
        assert_eq!(strata(20), (5, 4));
        assert_eq!(strata(7), (7, 1));
        assert_eq!(strata(1), (1, 1));
    }
}
