use std::io::IsTerminal;

use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use super::pinhole::Pinhole;
use super::{Film, PixelSampler, radiance};
use crate::scene::{Camera, Scene};

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

/// What a render needs besides the scene and camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Samples per pixel (at least 1).
    pub samples_per_pixel: u32,
    /// The seed of every pixel's random stream.
    pub seed: u64,
    /// Keep the per-sample variance (for goldens).
    pub variance: bool,
    /// How sample positions are drawn.
    pub jitter: PixelJitter,
    /// Show a progress bar on stderr when it is a terminal.
    pub progress: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            samples_per_pixel: 20,
            seed: 0,
            variance: false,
            jitter: PixelJitter::Uniform,
            progress: false,
        }
    }
}

/// What stops a render.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Zero samples per pixel.
    #[error("samples per pixel must be at least 1")]
    NoSamples,
    /// The camera's image has no pixels.
    #[error("the image is {width}x{height}: it needs at least one pixel")]
    EmptyImage {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
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

/// How a renderer draws the rows of a [`Job`]: the general path, one ray at a time through the
/// scene, or the pinhole fast path ([`Pinhole`]), which gives the same film bit for bit.
pub(super) trait Trace: Sync + Sized {
    /// Renders row `j` of `job` into `means` (and `variances` when `VARIANCE`) with the jitter
    /// `JITTER` (0 uniform, 1 stratified, 2 centre).
    fn row<const VARIANCE: bool, const JITTER: u8>(
        job: &Job<'_, Self>,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    );
}

impl Trace for Scene {
    /// Each sample's ray (with its disk point under defocus) through [`radiance`].
    #[inline(always)]
    fn row<const VARIANCE: bool, const JITTER: u8>(
        job: &Job<'_, Self>,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    ) {
        let width = job.camera.width;
        for (i, mean) in means.iter_mut().enumerate() {
            let mut sampler = PixelSampler::new(job.seed, (j * width + i) as u64);
            let mut moments = None;
            for s in 0..job.spp {
                let (ox, oy) = job.offsets::<JITTER>(&mut sampler, s);
                let disk = if job.camera.defocus {
                    sampler.in_unit_disk()
                } else {
                    (0.0, 0.0)
                };
                let ray = job.camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
                let colour = radiance(job.tracer, &ray);
                let colour = [colour.x, colour.y, colour.z, 0.0];
                moments
                    .get_or_insert_with(|| Moments::new(colour))
                    .add::<VARIANCE>(colour, s);
            }
            if let Some(moments) = moments {
                moments.store::<VARIANCE>(job.spp, mean, variances.get_mut(i));
            }
        }
    }
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
        }
    }

    /// Adds sample number `s` (from 0), in order: the sum, whether it equals the first, and
    /// (when `VARIANCE`) Welford's update.
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
            }
        }
    }

    /// The pixel's mean of `spp` samples into `mean`: the sum over the count, except when every
    /// sample equals the first (in every channel): then that colour exactly, since a sum of
    /// equal values over their count can be off by an ulp: (0.2 + 0.2 + 0.2) / 3 =
    /// 0.20000000000000004. When `VARIANCE`, the unbiased variance into `variance`.
    #[inline(always)]
    pub(super) fn store<const VARIANCE: bool>(
        &self,
        spp: u32,
        mean: &mut DVec3,
        variance: Option<&mut DVec3>,
    ) {
        let [fx, fy, fz, _] = self.first;
        let [sx, sy, sz, _] = self.sum;
        *mean = if self.same[..3].iter().all(|&same| same != 0) {
            DVec3::new(fx, fy, fz)
        } else {
            DVec3::new(sx, sy, sz) / spp as f64
        };
        if let (true, Some(variance)) = (VARIANCE, variance) {
            let [mx, my, mz, _] = self.m2;
            *variance = if spp > 1 {
                DVec3::new(mx, my, mz) / (spp - 1) as f64
            } else {
                DVec3::ZERO
            };
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
        }
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
            _ => (0.0, 0.0),
        }
    }

    /// Renders row `j` into `means` (and `variances` when `VARIANCE`), with AVX2 where the
    /// processor has it (four lanes per vector instead of two: the same operations, so the same
    /// bits).
    #[inline]
    fn row<const VARIANCE: bool>(&self, j: usize, means: &mut [DVec3], variances: &mut [DVec3]) {
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
    unsafe fn row_avx2<const VARIANCE: bool>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    ) {
        self.row_any::<VARIANCE>(j, means, variances);
    }

    /// Renders row `j` with the jitter chosen, fixed at compile time so the per-sample loop has
    /// no branch on it.
    #[inline(always)]
    fn row_any<const VARIANCE: bool>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    ) {
        match self.jitter {
            PixelJitter::Uniform => T::row::<VARIANCE, 0>(self, j, means, variances),
            PixelJitter::Stratified => T::row::<VARIANCE, 1>(self, j, means, variances),
            PixelJitter::Centre => T::row::<VARIANCE, 2>(self, j, means, variances),
        }
    }

    /// Renders every row into `mean` (and `variance` when it is not empty), rows in parallel.
    fn run(&self, mean: &mut [DVec3], variance: &mut [DVec3], progress: &ProgressBar) {
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

/// The vector instructions the renderer's fast path runs with on this processor: `"AVX2"` (four
/// `f64` lanes per instruction) where it has them, else the target's baseline (`"SSE2"` on
/// x86-64, two lanes). The film is the same either way.
pub fn vector_instructions() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return "AVX2";
    }
    if cfg!(target_arch = "x86_64") {
        "SSE2"
    } else if cfg!(target_arch = "aarch64") {
        "NEON"
    } else {
        "the target's baseline"
    }
}

/// Renders every pixel of `camera` over `scene`.
///
/// Pixel `(i, j)` draws from [`PixelSampler::new(seed, j * width + i)`](PixelSampler::new): per
/// sample, the x then the y jitter (then, with defocus, a disk point), so the film is the same bit
/// for bit on any number of threads. Rows are rendered in parallel on rayon's current pool,
/// straight into the film (no other per-pixel memory). Without defocus every ray leaves the
/// camera's centre, and the render takes a fast path that gives the same bits.
pub fn render(
    scene: &Scene,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Film, RenderError> {
    let spp = options.samples_per_pixel;
    if spp == 0 {
        return Err(RenderError::NoSamples);
    }
    let (width, height) = (camera.width, camera.height);
    if width == 0 || height == 0 {
        return Err(RenderError::EmptyImage { width, height });
    }
    let progress = if options.progress && std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(Some(height as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("rendering {bar:40} {pos}/{len} rows, {eta} left")
                .expect("a valid progress template"),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut mean = vec![DVec3::ZERO; width * height];
    let mut variance = if options.variance {
        vec![DVec3::ZERO; width * height]
    } else {
        Vec::new()
    };
    let (seed, jitter) = (options.seed, options.jitter);
    if camera.defocus {
        Job::new(scene, camera, spp, seed, jitter).run(&mut mean, &mut variance, &progress);
    } else {
        let pinhole = Pinhole::new(scene, camera.center);
        Job::new(&pinhole, camera, spp, seed, jitter).run(&mut mean, &mut variance, &progress);
    }
    progress.finish_and_clear();
    Ok(Film {
        width,
        height,
        samples_per_pixel: spp,
        mean,
        variance: options.variance.then_some(variance),
    })
}

/// The film of `job`, row by row on this thread (the dispatch's path), as the bits of its means
/// then its variances.
#[cfg(test)]
pub(super) fn film_bits<T: Trace>(job: &Job<'_, T>) -> Vec<u64> {
    film_bits_with(job, |job, j, means, variances| {
        job.row::<true>(j, means, variances)
    })
}

/// [`film_bits`] with each row rendered by `row` (one of the dispatch's paths).
#[cfg(test)]
fn film_bits_with<T: Trace>(
    job: &Job<'_, T>,
    row: impl Fn(&Job<'_, T>, usize, &mut [DVec3], &mut [DVec3]),
) -> Vec<u64> {
    let (width, height) = (job.camera.width, job.camera.height);
    let mut mean = vec![DVec3::ZERO; width * height];
    let mut variance = vec![DVec3::ZERO; width * height];
    for (j, (means, variances)) in mean
        .chunks_mut(width)
        .zip(variance.chunks_mut(width))
        .enumerate()
    {
        row(job, j, means, variances);
    }
    mean.iter()
        .chain(&variance)
        .flat_map(|c| c.to_array().map(f64::to_bits))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::packet::WIDTH;

    /// The pinhole fast path (ray packets, with and without AVX2) renders the film the general
    /// path renders one ray at a time through `Scene::closest`, bit for bit: every built-in scene,
    /// every jitter, sample counts that fill the packets and counts that leave a partial one.
    #[test]
    fn packets_render_the_general_paths_film() {
        for builtin in crate::scene::BUILTIN_SCENES {
            let description = builtin.description();
            let scene = description.scene();
            let camera = description.camera(Some(24));
            assert!(
                !camera.defocus,
                "{}: the fast path needs a pinhole",
                builtin.name
            );
            let pinhole = Pinhole::new(&scene, camera.center);
            for jitter in [
                PixelJitter::Uniform,
                PixelJitter::Stratified,
                PixelJitter::Centre,
            ] {
                for spp in [1, 3, WIDTH as u32, 7, 20] {
                    let general = Job::new(&scene, &camera, spp, 5, jitter);
                    let fast = Job::new(&pinhole, &camera, spp, 5, jitter);
                    let expected =
                        film_bits_with(&general, |job, j, m, v| job.row_any::<true>(j, m, v));
                    let what = format!("{} {jitter:?} {spp} spp", builtin.name);
                    assert_eq!(
                        film_bits_with(&fast, |job, j, m, v| job.row_any::<true>(j, m, v)),
                        expected,
                        "{what}"
                    );
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        assert_eq!(
                            film_bits_with(&fast, |job, j, m, v| unsafe {
                                job.row_avx2::<true>(j, m, v)
                            }),
                            expected,
                            "{what}, AVX2"
                        );
                    }
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
