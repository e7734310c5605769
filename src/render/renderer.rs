use std::io::IsTerminal;

use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use super::fixed_origin::FixedOrigin;
use super::{Film, PixelSampler, radiance, sky};
use crate::geometry::{Interval, Ray};
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

/// The colour seen along a primary ray: the course's integrator, through the general scene or
/// through the fixed-origin fast path (the same value, bit for bit).
trait Trace: Sync {
    fn trace(&self, ray: &Ray) -> DVec3;
}

impl Trace for Scene {
    #[inline]
    fn trace(&self, ray: &Ray) -> DVec3 {
        radiance(self, ray)
    }
}

/// The fast path with the scene's materials.
struct Pinhole<'a> {
    prepared: FixedOrigin,
    scene: &'a Scene,
}

impl Trace for Pinhole<'_> {
    #[inline(always)]
    fn trace(&self, ray: &Ray) -> DVec3 {
        debug_assert_eq!(ray.origin, self.prepared.origin());
        match self.prepared.closest(ray.direction, Interval::CAMERA) {
            Some((_, index)) => self.scene.material_of(index).albedo(),
            None => sky(ray.direction),
        }
    }
}

/// Everything a row needs, shared by all rows.
struct Job<'a, T> {
    tracer: &'a T,
    camera: &'a Camera,
    spp: u32,
    seed: u64,
    jitter: PixelJitter,
    strata: (u32, u32),
}

impl<T: Trace> Job<'_, T> {
    /// Renders row `j` into `means` (and `variances` when `VARIANCE`).
    #[inline]
    fn row<const VARIANCE: bool>(&self, j: usize, means: &mut [DVec3], variances: &mut [DVec3]) {
        match self.jitter {
            PixelJitter::Uniform => self.row_with::<VARIANCE, 0>(j, means, variances),
            PixelJitter::Stratified => self.row_with::<VARIANCE, 1>(j, means, variances),
            PixelJitter::Centre => self.row_with::<VARIANCE, 2>(j, means, variances),
        }
    }

    /// The row with the jitter fixed at compile time (`JITTER` 0 uniform, 1 stratified,
    /// 2 centre), so the per-sample loop has no branch on it.
    #[inline(always)]
    fn row_with<const VARIANCE: bool, const JITTER: u8>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    ) {
        let width = self.camera.width;
        let (columns, rows_of_strata) = self.strata;
        for (i, mean) in means.iter_mut().enumerate() {
            let mut sampler = PixelSampler::new(self.seed, (j * width + i) as u64);
            let mut sum = DVec3::ZERO;
            let mut lowest = DVec3::INFINITY;
            let mut highest = DVec3::NEG_INFINITY;
            let mut running_mean = DVec3::ZERO;
            let mut m2 = DVec3::ZERO;
            for s in 0..self.spp {
                let (ox, oy) = match JITTER {
                    0 => (sampler.next_f64() - 0.5, sampler.next_f64() - 0.5),
                    1 => {
                        let (cx, cy) = ((s % columns) as f64, (s / columns) as f64);
                        (
                            (cx + sampler.next_f64()) / columns as f64 - 0.5,
                            (cy + sampler.next_f64()) / rows_of_strata as f64 - 0.5,
                        )
                    }
                    _ => (0.0, 0.0),
                };
                let disk = if self.camera.defocus {
                    sampler.in_unit_disk()
                } else {
                    (0.0, 0.0)
                };
                let ray = self.camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
                let colour = self.tracer.trace(&ray);
                sum += colour;
                lowest = lowest.min(colour);
                highest = highest.max(colour);
                if VARIANCE {
                    let delta = colour - running_mean;
                    running_mean += delta / (s + 1) as f64;
                    m2 += delta * (colour - running_mean);
                }
            }
            // The sum over the count, except when every sample saw the same colour: then that
            // colour exactly (a sum of equal values over their count can be off by an ulp:
            // (0.2 + 0.2 + 0.2) / 3 = 0.20000000000000004).
            *mean = if lowest == highest {
                lowest
            } else {
                sum / self.spp as f64
            };
            if VARIANCE {
                variances[i] = if self.spp > 1 {
                    m2 / (self.spp - 1) as f64
                } else {
                    DVec3::ZERO
                };
            }
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
    let strata = strata(spp);
    if camera.defocus {
        let job = Job {
            tracer: scene,
            camera,
            spp,
            seed: options.seed,
            jitter: options.jitter,
            strata,
        };
        job.run(&mut mean, &mut variance, &progress);
    } else {
        let pinhole = Pinhole {
            prepared: FixedOrigin::new(scene, camera.center),
            scene,
        };
        let job = Job {
            tracer: &pinhole,
            camera,
            spp,
            seed: options.seed,
            jitter: options.jitter,
            strata,
        };
        job.run(&mut mean, &mut variance, &progress);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_are_as_square_as_the_count_allows() {
        assert_eq!(strata(16), (4, 4));
        assert_eq!(strata(20), (5, 4));
        assert_eq!(strata(7), (7, 1));
        assert_eq!(strata(1), (1, 1));
    }
}
