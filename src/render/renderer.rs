use std::io::IsTerminal;

use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

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

/// Renders every pixel of `camera` over `scene`.
///
/// Pixel `(i, j)` draws from [`PixelSampler::new(seed, j * width + i)`](PixelSampler::new): per
/// sample, the x then the y jitter (then, with defocus, a disk point), so the film is the same bit
/// for bit on any number of threads. Rows are rendered in parallel on rayon's current pool.
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
    let (columns, rows_of_strata) = strata(spp);
    let rows: Vec<(Vec<DVec3>, Vec<DVec3>)> = (0..height)
        .into_par_iter()
        .map(|j| {
            let mut means = Vec::with_capacity(width);
            let mut variances = Vec::with_capacity(if options.variance { width } else { 0 });
            for i in 0..width {
                let mut sampler = PixelSampler::new(options.seed, (j * width + i) as u64);
                let mut sum = DVec3::ZERO;
                let mut running_mean = DVec3::ZERO;
                let mut m2 = DVec3::ZERO;
                for s in 0..spp {
                    let (ox, oy) = match options.jitter {
                        PixelJitter::Uniform => {
                            (sampler.next_f64() - 0.5, sampler.next_f64() - 0.5)
                        }
                        PixelJitter::Stratified => {
                            let (cx, cy) = ((s % columns) as f64, (s / columns) as f64);
                            (
                                (cx + sampler.next_f64()) / columns as f64 - 0.5,
                                (cy + sampler.next_f64()) / rows_of_strata as f64 - 0.5,
                            )
                        }
                    };
                    let disk = if camera.defocus {
                        sampler.in_unit_disk()
                    } else {
                        (0.0, 0.0)
                    };
                    let ray = camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
                    let colour = radiance(scene, &ray);
                    sum += colour;
                    if options.variance {
                        let delta = colour - running_mean;
                        running_mean += delta / (s + 1) as f64;
                        m2 += delta * (colour - running_mean);
                    }
                }
                means.push(sum / spp as f64);
                if options.variance {
                    variances.push(if spp > 1 {
                        m2 / (spp - 1) as f64
                    } else {
                        DVec3::ZERO
                    });
                }
            }
            progress.inc(1);
            (means, variances)
        })
        .collect();
    progress.finish_and_clear();
    let mut mean = Vec::with_capacity(width * height);
    let mut variance = Vec::with_capacity(if options.variance { width * height } else { 0 });
    for (m, v) in rows {
        mean.extend(m);
        variance.extend(v);
    }
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
