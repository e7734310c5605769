use std::io::IsTerminal;

use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use super::fixed_origin::FixedOrigin;
use super::integrator::{sky_at, sky_height};
use super::packet::{Directions, WIDTH};
use super::{Film, PixelSampler, radiance};
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

/// The colours seen along a packet of primary rays: the course's integrator, through the general
/// scene or through the fixed-origin fast path (the same values, bit for bit).
trait Trace: Sync {
    fn trace(&self, rays: &[Ray; WIDTH]) -> [DVec3; WIDTH];
}

impl Trace for Scene {
    #[inline]
    fn trace(&self, rays: &[Ray; WIDTH]) -> [DVec3; WIDTH] {
        rays.map(|ray| radiance(self, &ray))
    }
}

/// The fast path with the scene's materials.
struct Pinhole {
    prepared: FixedOrigin,
    /// Each object's albedo.
    albedos: Vec<DVec3>,
}

impl Pinhole {
    /// `scene` prepared for rays leaving `origin`.
    fn new(scene: &Scene, origin: DVec3) -> Self {
        Self {
            prepared: FixedOrigin::new(scene, origin),
            albedos: (0..scene.objects.len())
                .map(|index| scene.material_of(index).albedo())
                .collect(),
        }
    }
}

impl Trace for Pinhole {
    #[inline(always)]
    fn trace(&self, rays: &[Ray; WIDTH]) -> [DVec3; WIDTH] {
        let mut d = Directions::default();
        for (k, ray) in rays.iter().enumerate() {
            debug_assert_eq!(ray.origin, self.prepared.origin());
            d.set(k, ray.direction);
        }
        let index = self.prepared.closest_packet(&d, Interval::CAMERA);
        // The sky of every lane, then the albedo where a lane hit: no branch per ray.
        let height: [f64; WIDTH] = std::array::from_fn(|k| sky_height(d.lane(k)));
        std::array::from_fn(|k| match self.albedos.get(index[k] as usize) {
            Some(&albedo) => albedo,
            None => sky_at(height[k]),
        })
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

impl<'a, T: Trace> Job<'a, T> {
    /// A job of `spp` samples per pixel through `tracer`.
    fn new(tracer: &'a T, camera: &'a Camera, spp: u32, seed: u64, jitter: PixelJitter) -> Self {
        Self {
            tracer,
            camera,
            spp,
            seed,
            jitter,
            strata: strata(spp),
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

    /// Renders row `j` with the jitter chosen.
    #[inline(always)]
    fn row_any<const VARIANCE: bool>(
        &self,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [DVec3],
    ) {
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
        let no_ray = Ray::new(self.camera.center, DVec3::ZERO);
        for (i, mean) in means.iter_mut().enumerate() {
            let mut sampler = PixelSampler::new(self.seed, (j * width + i) as u64);
            let mut sum = DVec3::ZERO;
            let mut lowest = DVec3::INFINITY;
            let mut highest = DVec3::NEG_INFINITY;
            let mut running_mean = DVec3::ZERO;
            let mut m2 = DVec3::ZERO;
            // The samples in packets of `WIDTH`, drawn and accumulated in order; the lanes of a
            // last, partial packet past the count repeat its first ray and are not used.
            let mut first = 0;
            while first < self.spp {
                let count = (self.spp - first).min(WIDTH as u32) as usize;
                let mut rays = [no_ray; WIDTH];
                for (k, ray) in rays.iter_mut().enumerate().take(count) {
                    let s = first + k as u32;
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
                    *ray = self.camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
                }
                for k in count..WIDTH {
                    rays[k] = rays[0];
                }
                let colours = self.tracer.trace(&rays);
                for (k, &colour) in colours.iter().enumerate().take(count) {
                    sum += colour;
                    lowest = lowest.min(colour);
                    highest = highest.max(colour);
                    if VARIANCE {
                        let delta = colour - running_mean;
                        running_mean += delta / (first + k as u32 + 1) as f64;
                        m2 += delta * (colour - running_mean);
                    }
                }
                first += count as u32;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Renders every row of `job` with `row` (one of the dispatch's paths).
    fn film_of<T: Trace>(
        job: &Job<'_, T>,
        row: impl Fn(&Job<'_, T>, usize, &mut [DVec3], &mut [DVec3]),
    ) -> (Vec<u64>, Vec<u64>) {
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
        let bits = |v: &[DVec3]| {
            v.iter()
                .flat_map(|c| c.to_array().map(f64::to_bits))
                .collect()
        };
        (bits(&mean), bits(&variance))
    }

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
                    let expected = film_of(&general, |job, j, m, v| job.row_any::<true>(j, m, v));
                    let what = format!("{} {jitter:?} {spp} spp", builtin.name);
                    assert_eq!(
                        film_of(&fast, |job, j, m, v| job.row_any::<true>(j, m, v)),
                        expected,
                        "{what}"
                    );
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx2") {
                        assert_eq!(
                            film_of(&fast, |job, j, m, v| unsafe {
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
