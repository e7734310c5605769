use std::io::IsTerminal;

use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::fast;
use super::fast::pinhole::Pinhole;
use super::job::{Job, Moments, PixelJitter, Spread, Trace};
use super::{Film, PixelSampler, trace};
use crate::scene::{Background, Camera, Integrator, Material, PixelSampling, Profile, World};

/// What a render needs besides the scene and camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Samples per pixel (at least 1).
    pub samples_per_pixel: u32,
    /// The seed of every pixel's random stream.
    pub seed: u64,
    /// Keep the per-sample variance and the largest sample deviation (for goldens).
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

impl Trace for World {
    /// Each sample's ray ([`Job::sample_ray`]) through the world's integrator ([`trace`]), times
    /// the job's scale; in a small scene of spheres, moving spheres and quads, four paths at a
    /// time ([`lanes::row`](super::fast::lanes::row)), to the same film.
    #[inline(always)]
    fn row<const VARIANCE: bool, const JITTER: u8>(
        job: &Job<'_, Self>,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [Spread],
    ) {
        let width = job.camera.width;
        let world = job.tracer;
        if fast::lanes_row::<VARIANCE, JITTER>(job, j, means, variances) {
            return;
        }
        for (i, mean) in means.iter_mut().enumerate() {
            let mut sampler = PixelSampler::new(job.seed, (j * width + i) as u64);
            let mut moments = None;
            for s in 0..job.spp {
                let ray = job.sample_ray::<JITTER>(&mut sampler, (i, j), s, world.moving);
                let mut colour = trace(world, &ray, &mut sampler);
                if JITTER == 3 {
                    colour *= job.scale;
                }
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

/// How many samples a pixel takes when `spp` are asked for, and the course's jittered
/// sampling's strata, step and scale when `world` uses it.
///
/// The course's `render_jittered` (weeks 9 and 10) takes `m^2` samples, `m = floor(sqrt(spp))`
/// of the scene's `samples_per_pixel`, and divides their sum by that `spp` (course departure:
/// 25 samples over 30 in week 9, 196 over 200 in week 10). Asked for `n` samples, the reference
/// takes whole passes over the strata, so every stratum gets the same number: one pass (the
/// course's pixel) for `n` up to the scene's `spp` (more passes only where `m = 1`), and above it
/// the smallest multiple of `m^2` at least `n`, so that a golden asked for 4096 samples holds at
/// least 4096. Each sample is multiplied by `m^2 / spp`, so the mean at any `n` estimates the
/// course's pixel's expectation.
pub fn samples_taken(world: &World, spp: u32) -> (u32, Option<CourseJitter>) {
    let settings = &world.settings;
    match (world.profile, settings.sampling, settings.jitter_step) {
        (Profile::Course, PixelSampling::CourseJittered, Some(step)) => {
            let scene_spp = world.samples_per_pixel.max(1);
            let grid = ((scene_spp as f64).sqrt() as u32).max(1);
            let cells = grid * grid;
            let passes = if spp <= scene_spp {
                (spp / cells).max(1)
            } else {
                spp.div_ceil(cells)
            };
            let taken = passes.saturating_mul(cells);
            let scale = cells as f64 / scene_spp as f64;
            (taken, Some(CourseJitter { grid, step, scale }))
        }
        _ => (spp, None),
    }
}

/// The course's jittered sampling of a render ([`samples_taken`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CourseJitter {
    /// Strata a side, `floor(sqrt(spp))` of the scene's `samples_per_pixel`.
    pub grid: u32,
    /// The frozen stratum width (`one_over_sqrt_spp`).
    pub step: f64,
    /// What each sample is multiplied by: `grid^2 / spp`.
    pub scale: f64,
}

/// Whether `world` seen by `camera` can take the pinhole fast path, which renders the week-4
/// integrator only: the course's albedo integrator over untextured materials, the sky, a
/// pinhole, nothing moving, uniform sampling.
fn takes_the_fast_path(world: &World, camera: &Camera) -> bool {
    let s = &world.settings;
    world.profile == Profile::Course
        && s.integrator == Integrator::Albedo
        && s.background == Background::Sky
        && s.sampling == PixelSampling::Uniform
        && !camera.defocus
        && !world.moving
        && !world
            .materials
            .iter()
            .any(|m| matches!(m, Material::Textured { .. }))
}

/// Renders every pixel of `camera` over `world`.
///
/// Pixel `(i, j)` draws from [`PixelSampler::new(seed, j * width + i)`](PixelSampler::new): per
/// sample, the x then the y jitter (then, with defocus, a disk point; then, when something
/// moves, the ray's time; then whatever the integrator draws, in path order), so the film is
/// the same bit for bit on any number of threads. Rows are rendered in parallel on rayon's
/// current pool, straight into the film (no other per-pixel memory). A week-4 scene seen
/// through a pinhole takes a fast path that gives the same bits.
///
/// The film's `samples_per_pixel` is the number of samples each pixel took: the number asked
/// for, except under the course's jittered sampling ([`samples_taken`]). `options.jitter` is
/// ignored there too (the course's strata are part of the expected image).
pub fn render(
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<Film, RenderError> {
    if options.samples_per_pixel == 0 {
        return Err(RenderError::NoSamples);
    }
    let (width, height) = (camera.width, camera.height);
    if width == 0 || height == 0 {
        return Err(RenderError::EmptyImage { width, height });
    }
    let (spp, course) = samples_taken(world, options.samples_per_pixel);
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
        vec![Spread::ZERO; width * height]
    } else {
        Vec::new()
    };
    let (seed, jitter) = (options.seed, options.jitter);
    if let Some(c) = course {
        Job::course_jittered(world, camera, spp, seed, (c.grid, c.step), c.scale).run(
            &mut mean,
            &mut variance,
            &progress,
        );
    } else if takes_the_fast_path(world, camera) {
        let pinhole = Pinhole::new(world, camera.center);
        Job::new(&pinhole, camera, spp, seed, jitter).run(&mut mean, &mut variance, &progress);
    } else {
        Job::new(world, camera, spp, seed, jitter).run(&mut mean, &mut variance, &progress);
    }
    progress.finish_and_clear();
    Ok(Film {
        width,
        height,
        samples_per_pixel: spp,
        mean,
        deviation: options
            .variance
            .then(|| variance.iter().map(|s| s.deviation).collect()),
        variance: options
            .variance
            .then(|| variance.iter().map(|s| s.variance).collect()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::fast::packet::WIDTH;
    use crate::render::job::film_bits_with;

    /// The book's final scene (about 490 spheres) renders through the hierarchy to the very film
    /// the linear scan gives, variance included.
    #[test]
    fn the_final_scene_renders_the_same_through_the_hierarchy() {
        let d = crate::scene::rtiow_final_scene(1);
        assert!(d.objects.len() > 400, "{}", d.objects.len());
        let world = d.scene();
        assert!(world.has_hierarchy());
        let linear = world.clone().without_hierarchy();
        let camera = d.camera(Some(48));
        let options = RenderOptions {
            samples_per_pixel: 2,
            seed: 3,
            variance: true,
            ..Default::default()
        };
        let bits = |film: Film| -> Vec<u64> {
            film.mean
                .iter()
                .chain(film.variance.as_deref().unwrap_or(&[]))
                .chain(film.deviation.as_deref().unwrap_or(&[]))
                .flat_map(|c| c.to_array().map(f64::to_bits))
                .collect()
        };
        let fast = bits(render(&world, &camera, &options).unwrap());
        assert_eq!(fast, bits(render(&linear, &camera, &options).unwrap()));
    }

    /// The course's jittered sampling takes whole passes over its strata: week 9's 30 spp is 25
    /// samples (the course's), 4096 asked is 164 passes of 25 (at least what was asked), fewer
    /// than 25 is one pass; each sample weighs `25 / 30`. Week 10's 200 spp is 196 samples of weight `196 / 200`.
    #[test]
    fn course_jitter_takes_whole_passes() {
        let mut d = crate::scene::builtin("week10-moving").unwrap();
        let world = d.scene();
        assert_eq!(world.samples_per_pixel, 200);
        let (taken, course) = samples_taken(&world, 200);
        assert_eq!(taken, 196);
        let c = course.unwrap();
        assert_eq!((c.grid, c.scale), (14, 196.0 / 200.0));
        assert_eq!(c.step, 1.0 / 10f64.sqrt());
        d.image.samples_per_pixel = 30;
        let world = d.scene();
        assert_eq!(samples_taken(&world, 30).0, 25);
        assert_eq!(samples_taken(&world, 4096).0, 4100);
        assert_eq!(samples_taken(&world, 31).0, 50);
        assert_eq!(samples_taken(&world, 3).0, 25);
        let uniform = crate::scene::builtin("week08-blinn").unwrap().scene();
        assert_eq!(samples_taken(&uniform, 30), (30, None));
    }

    /// The pinhole fast path (ray packets, with and without AVX2) renders the film the general
    /// path renders one ray at a time through `Scene::closest`, bit for bit: every built-in scene
    /// that takes it, every jitter, sample counts that fill the packets and counts that leave a
    /// partial one.
    #[test]
    fn packets_render_the_general_paths_film() {
        let mut tested = 0;
        for builtin in crate::scene::BUILTIN_SCENES {
            let description = builtin.description();
            let scene = description.scene();
            let camera = description.camera(Some(24));
            if !takes_the_fast_path(&scene, &camera) {
                continue;
            }
            tested += 1;
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
                            // SAFETY: AVX2 was detected just above.
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
        assert!(tested >= 4, "{tested} scenes take the fast path");
    }
}
