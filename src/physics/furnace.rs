//! Scenes with a closed-form answer ("furnaces"), judged with no golden.
//!
//! Promises: each [`Furnace`] is a scene of the `physical` profile whose every pixel has one
//! exact expected value, whatever the renderer's sampling, by the rendering equation alone:
//!
//! - `furnace-white`: two white Lambertian spheres (albedo 1) in a uniform environment of
//!   radiance 0.5. Every path ends in the environment with its throughput unchanged (a white
//!   Lambertian reflects all it receives), so every pixel is 0.5, spheres and background alike,
//!   through any number of bounces between the two.
//! - `furnace-grey`: one Lambertian sphere of albedo (0.8, 0.5, 0.2) in a uniform environment of
//!   0.75, filling the whole view. A convex surface never sees itself: one bounce reaches the
//!   environment, so every pixel is the albedo times 0.75, (0.6, 0.375, 0.15).
//!
//! [`check_furnaces`] renders each scene several times with independent seeds (through any
//! [`FurnaceRenderer`]: a candidate's render requests or rtoracle's own renderer) and compares
//! the renders with the exact image by the two-sample test of `compare A B` (one side exact), at
//! the run's false-alarm rate shared by the scenes. A renderer whose estimator has no variance
//! here (the book's: cosine-weighted sampling with weight = albedo) is decided up to rounding;
//! one with variance (uniform hemisphere sampling, Russian roulette, light sampling) by its
//! noise. A missing cosine, a weight not divided by its pdf, a doubled light or a lost bounce
//! moves the mean and fails.
//!
//! The depth limit is the one way an honest renderer loses energy here: the scenes allow 50
//! bounces, and a path between the two white spheres bounces that often with a probability far
//! below the test's resolution.

use serde::Serialize;

use crate::compare::Comparison;
use crate::compare::twosample::{Side, compare_two};
use crate::render::{PixelJitter, RenderOptions, render};
use crate::scene::{
    Background, CameraSettings, ImageSettings, MaterialEntry, MaterialKind, ObjectEntry, Profile,
    RenderSettings, SceneDescription,
};

/// One furnace scene and its exact pixel value.
#[derive(Clone, Debug)]
pub struct Furnace {
    /// Its name in reports (`furnace-white`).
    pub name: &'static str,
    /// What it is and why its answer is exact, in one line.
    pub summary: &'static str,
    /// Every pixel's exact linear RGB.
    pub expected: [f64; 3],
    /// The scene, as the render request sends it.
    pub scene: SceneDescription,
}

fn lambertian(name: &str, albedo: [f64; 3]) -> MaterialEntry {
    MaterialEntry::new(name, MaterialKind::Lambertian, albedo)
}

fn sphere(center: [f64; 3], radius: f64, material: &str) -> ObjectEntry {
    ObjectEntry::Sphere {
        center,
        radius,
        material: material.to_string(),
        moving_center: None,
    }
}

/// A furnace's scene: 48x36 pixels, the camera at the origin looking down -z with `vfov`, a flat
/// background of `environment`, depth 50, the `physical` profile.
fn scene(
    vfov: f64,
    environment: f64,
    materials: Vec<MaterialEntry>,
    objects: Vec<ObjectEntry>,
) -> SceneDescription {
    let mut d = SceneDescription::new(
        ImageSettings {
            width: 48,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: DEFAULT_SPP,
        },
        CameraSettings {
            look_from: [0.0, 0.0, 0.0],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            vfov,
            focus_distance: 1.0,
            defocus_angle: 0.0,
        },
        materials,
        objects,
    );
    d.profile = Profile::Physical;
    d.render = RenderSettings {
        max_depth: 50,
        background: Background::Flat,
        background_color: [environment; 3],
        ..RenderSettings::default()
    };
    d
}

/// The furnace scenes, in the order they are run.
pub fn furnaces() -> Vec<Furnace> {
    let albedo = [0.8, 0.5, 0.2];
    let environment = 0.75;
    vec![
        Furnace {
            name: "furnace-white",
            summary: "two white Lambertian spheres in a uniform environment of 0.5: every pixel \
                      0.5 (a white surface reflects all it receives, through every bounce)",
            expected: [0.5; 3],
            scene: scene(
                60.0,
                0.5,
                vec![lambertian("white", [1.0; 3])],
                vec![
                    sphere([-1.05, 0.0, -4.0], 1.0, "white"),
                    sphere([1.05, 0.3, -4.5], 1.0, "white"),
                ],
            ),
        },
        Furnace {
            name: "furnace-grey",
            summary: "a Lambertian sphere of albedo (0.8, 0.5, 0.2) filling the view, in a \
                      uniform environment of 0.75: every pixel (0.6, 0.375, 0.15) (a convex \
                      surface never sees itself)",
            expected: albedo.map(|a| a * environment),
            // Seen from 3 away, a sphere of radius 2 fills a cone of half-angle asin(2/3) =
            // 41.8 degrees; the view's corners are at 31.2 (vfov 40, aspect 4:3).
            scene: scene(
                40.0,
                environment,
                vec![lambertian("grey", albedo)],
                vec![sphere([0.0, 0.0, -3.0], 2.0, "grey")],
            ),
        },
    ]
}

/// Samples per pixel of each render when not told otherwise.
pub const DEFAULT_SPP: u32 = 16;

/// Renders of each scene when not told otherwise (each with its own seed).
pub const DEFAULT_RENDERS: usize = 4;

/// How to run the furnaces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FurnaceOptions {
    /// Samples per pixel of each render.
    pub spp: u32,
    /// Renders of each scene (at least 2: their spread is the noise).
    pub renders: usize,
    /// The first render's seed (the others follow it).
    pub seed: u64,
    /// The false-alarm rate of the whole run, shared by the scenes.
    pub alpha: f64,
}

impl Default for FurnaceOptions {
    fn default() -> Self {
        FurnaceOptions {
            spp: DEFAULT_SPP,
            renders: DEFAULT_RENDERS,
            seed: 0,
            alpha: crate::weekly::stats::DEFAULT_ALPHA,
        }
    }
}

/// What draws a furnace: a candidate through its render requests, or rtoracle's own renderer.
pub trait FurnaceRenderer {
    /// Who it is, for the report.
    fn label(&self) -> String;
    /// The mean linear RGB of each pixel of `scene` at `spp` with `seed` (row-major, top row
    /// first), or why there is none.
    fn render(
        &mut self,
        scene: &SceneDescription,
        spp: u32,
        seed: u64,
    ) -> Result<Vec<[f32; 3]>, String>;
}

/// rtoracle's own renderer (the reference), at uniform jitter.
pub struct ReferenceRenderer;

impl FurnaceRenderer for ReferenceRenderer {
    fn label(&self) -> String {
        "rtoracle's reference renderer".to_string()
    }

    fn render(
        &mut self,
        scene: &SceneDescription,
        spp: u32,
        seed: u64,
    ) -> Result<Vec<[f32; 3]>, String> {
        let options = RenderOptions {
            samples_per_pixel: spp,
            seed,
            variance: false,
            jitter: PixelJitter::Uniform,
            progress: false,
        };
        let film =
            render(&scene.scene(), &scene.camera(None), &options).map_err(|e| e.to_string())?;
        Ok(film
            .mean
            .iter()
            .map(|p| p.to_array().map(|x| x as f32))
            .collect())
    }
}

/// A candidate's renders through the protocol's render requests (a started session), each
/// within `time_limit`.
pub struct CandidateRenderer<'a> {
    session: &'a mut crate::candidate::process::session::Session,
    time_limit: std::time::Duration,
}

impl<'a> CandidateRenderer<'a> {
    /// Renders through `session`, each image within `time_limit`.
    pub fn new(
        session: &'a mut crate::candidate::process::session::Session,
        time_limit: std::time::Duration,
    ) -> Self {
        CandidateRenderer {
            session,
            time_limit,
        }
    }
}

impl FurnaceRenderer for CandidateRenderer<'_> {
    fn label(&self) -> String {
        self.session.hello().name.clone()
    }

    fn render(
        &mut self,
        scene: &SceneDescription,
        spp: u32,
        seed: u64,
    ) -> Result<Vec<[f32; 3]>, String> {
        use crate::candidate::process::render_request::{RenderJob, RenderOutcome, render_scene};
        let job = RenderJob {
            scene,
            spp,
            seed,
            time_limit: self.time_limit,
            program: None,
            variant: None,
        };
        match render_scene(self.session, &job) {
            RenderOutcome::Rendered(image) => Ok(image.data),
            other => Err(other
                .reason()
                .unwrap_or_else(|| "the render did not finish".to_string())),
        }
    }
}

/// One furnace's result.
#[derive(Clone, Debug, Serialize)]
pub struct FurnaceResult {
    /// The scene's name.
    pub name: &'static str,
    /// What it is.
    pub summary: &'static str,
    /// Every pixel's exact value.
    pub expected: [f64; 3],
    /// `passed`, `failed` or `not run`.
    pub status: &'static str,
    /// The mean of the renders over the image, per channel (absent when not run).
    pub image_mean: Option<[f64; 3]>,
    /// The image mean over the expected value, per channel (a doubled light is 2).
    pub ratio: Option<[f64; 3]>,
    /// Why it failed or did not run, in words.
    pub why: Option<String>,
    /// The two-sample comparison of the renders with the exact image (absent when not run).
    pub comparison: Option<Comparison>,
}

/// The furnaces' report.
#[derive(Clone, Debug, Serialize)]
pub struct FurnaceReport {
    /// The renderer.
    pub candidate: String,
    /// How they were run.
    pub options: FurnaceOptions,
    /// The false-alarm rate of each scene's comparison (Šidák's share of `alpha`).
    pub alpha_per_scene: f64,
    /// One result per scene.
    pub scenes: Vec<FurnaceResult>,
}

impl FurnaceReport {
    /// Whether every scene ran and passed.
    pub fn passed(&self) -> bool {
        !self.scenes.is_empty() && self.scenes.iter().all(|s| s.status == "passed")
    }

    /// The report in words, one paragraph per scene.
    pub fn to_text(&self) -> String {
        use crate::escape::terminal_line;
        let mut s = format!(
            "furnaces of {}: {} renders of {} spp per scene, seeds from {}, false-alarm rate {:.0e} ({:.1e} per scene)\n",
            terminal_line(&self.candidate),
            self.options.renders,
            self.options.spp,
            self.options.seed,
            self.options.alpha,
            self.alpha_per_scene
        );
        for r in &self.scenes {
            let rgb = |v: [f64; 3]| format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2]);
            s.push_str(&format!(
                "{:<14} {:<7} expected {} everywhere",
                r.name,
                r.status.to_uppercase(),
                rgb(r.expected)
            ));
            if let (Some(mean), Some(ratio)) = (r.image_mean, r.ratio) {
                s.push_str(&format!(
                    "; image mean {} (x{:.3} x{:.3} x{:.3})",
                    rgb(mean),
                    ratio[0],
                    ratio[1],
                    ratio[2]
                ));
            }
            s.push('\n');
            s.push_str(&format!("  {}\n", r.summary));
            if let Some(why) = &r.why {
                s.push_str(&format!("  {}\n", terminal_line(why)));
            }
        }
        s.push_str(if self.passed() {
            "verdict: pass\n"
        } else {
            "verdict: fail\n"
        });
        s
    }
}

/// Renders every furnace `options.renders` times with `renderer` and judges each against its
/// exact image.
pub fn check_furnaces(
    renderer: &mut dyn FurnaceRenderer,
    options: FurnaceOptions,
) -> FurnaceReport {
    let scenes = furnaces();
    let alpha_per_scene = 1.0 - (1.0 - options.alpha).powf(1.0 / scenes.len() as f64);
    let renders = options.renders.max(2);
    let results = scenes
        .into_iter()
        .enumerate()
        .map(|(k, furnace)| {
            let mut images = Vec::with_capacity(renders);
            for r in 0..renders {
                let seed = options.seed.wrapping_add((k * renders + r) as u64);
                match renderer.render(&furnace.scene, options.spp, seed) {
                    Ok(image) => images.push(image),
                    Err(why) => {
                        return FurnaceResult {
                            name: furnace.name,
                            summary: furnace.summary,
                            expected: furnace.expected,
                            status: "not run",
                            image_mean: None,
                            ratio: None,
                            why: Some(format!("render {} of {renders}: {why}", r + 1)),
                            comparison: None,
                        };
                    }
                }
            }
            judge(&furnace, &images, options.spp, alpha_per_scene)
        })
        .collect();
    FurnaceReport {
        candidate: renderer.label(),
        options: FurnaceOptions { renders, ..options },
        alpha_per_scene,
        scenes: results,
    }
}

/// Judges the renders of one furnace against its exact image.
fn judge(furnace: &Furnace, images: &[Vec<[f32; 3]>], spp: u32, alpha: f64) -> FurnaceResult {
    let camera = furnace.scene.camera(None);
    let (w, h) = (camera.width, camera.height);
    let renders = Side::from_renders(w, h, images, spp, "the renders");
    let exact = Side::exact(w, h, furnace.expected, "the exact image");
    let pixels = (w * h).max(1) as f64;
    let mut mean = [0.0; 3];
    for p in &renders.mean {
        for c in 0..3 {
            mean[c] += p[c] / pixels;
        }
    }
    let ratio = [0, 1, 2].map(|c| mean[c] / furnace.expected[c]);
    let comparison = compare_two(&renders, &exact, alpha).ok();
    let passed = comparison.as_ref().is_some_and(Comparison::passed);
    let why = match &comparison {
        None => Some("the renders could not be compared".to_string()),
        Some(c) if !c.passed() => Some(match c.regions.first() {
            Some(r) => format!(
                "differs from the exact value by more than the renders' noise: {} failing \
                 regions, the worst at x {} y {} ({} scale, channel {}, t {:+.1})",
                c.regions_total, r.x, r.y, r.scale, r.channel, r.z
            ),
            None => "differs from the exact value by more than the renders' noise".to_string(),
        }),
        Some(_) => None,
    };
    FurnaceResult {
        name: furnace.name,
        summary: furnace.summary,
        expected: furnace.expected,
        status: if passed { "passed" } else { "failed" },
        image_mean: Some(mean),
        ratio: Some(ratio),
        why,
        comparison,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grey furnace's sphere fills the view: every corner ray of the camera meets it (so no
    /// pixel sees the environment directly, and one value is exact everywhere).
    #[test]
    fn the_grey_sphere_fills_the_view() {
        let grey = furnaces()
            .into_iter()
            .find(|f| f.name == "furnace-grey")
            .unwrap();
        let camera = grey.scene.camera(None);
        let half_v = (40.0f64.to_radians() / 2.0).tan();
        let half_h = half_v * camera.width as f64 / camera.height as f64;
        let corner = glam::DVec3::new(half_h, half_v, -1.0).normalize();
        // The angle between the corner ray and the direction to the centre, against the
        // silhouette's half-angle asin(r / d).
        let to_centre = glam::DVec3::new(0.0, 0.0, -1.0);
        assert!(corner.dot(to_centre).acos() < (2.0f64 / 3.0).asin());
    }

    /// The reference renderer passes both furnaces; its book-style estimator has no variance
    /// there, so its image means are the exact values up to rounding.
    #[test]
    fn the_reference_passes_every_furnace() {
        let report = check_furnaces(&mut ReferenceRenderer, FurnaceOptions::default());
        assert!(report.passed(), "{}", report.to_text());
        for s in &report.scenes {
            for c in 0..3 {
                let ratio = s.ratio.unwrap()[c];
                assert!((ratio - 1.0).abs() < 1e-6, "{}: {ratio}", s.name);
            }
        }
    }

    /// A renderer that doubles the light, or halves it, fails both furnaces; one whose noise
    /// is honest but whose mean is right passes.
    #[test]
    fn a_wrong_mean_fails_and_honest_noise_passes() {
        struct Scaled(f32, bool);
        impl FurnaceRenderer for Scaled {
            fn label(&self) -> String {
                "scaled".into()
            }
            fn render(
                &mut self,
                scene: &SceneDescription,
                spp: u32,
                seed: u64,
            ) -> Result<Vec<[f32; 3]>, String> {
                let exact = ReferenceRenderer.render(scene, spp, seed)?;
                // A deterministic "noise" of mean zero across the renders: +-0.05 by seed parity
                // in a checkerboard, so that 4 renders average back to the exact value.
                Ok(exact
                    .iter()
                    .enumerate()
                    .map(|(i, p)| {
                        let sign = if (i + seed as usize).is_multiple_of(2) {
                            1.0
                        } else {
                            -1.0
                        };
                        let noise = if self.1 { 0.05 * sign } else { 0.0 };
                        p.map(|x| x * self.0 + noise)
                    })
                    .collect())
            }
        }
        for scale in [2.0, 0.5] {
            let report = check_furnaces(&mut Scaled(scale, false), FurnaceOptions::default());
            assert!(
                report.scenes.iter().all(|s| s.status == "failed"),
                "{}",
                report.to_text()
            );
        }
        let noisy = check_furnaces(&mut Scaled(1.0, true), FurnaceOptions::default());
        assert!(noisy.passed(), "{}", noisy.to_text());
    }

    /// A renderer that cannot render says why, and nothing passes.
    #[test]
    fn a_render_that_fails_is_not_run() {
        struct Refuses;
        impl FurnaceRenderer for Refuses {
            fn label(&self) -> String {
                "refuses".into()
            }
            fn render(
                &mut self,
                _: &SceneDescription,
                _: u32,
                _: u64,
            ) -> Result<Vec<[f32; 3]>, String> {
                Err("no spheres here".into())
            }
        }
        let report = check_furnaces(&mut Refuses, FurnaceOptions::default());
        assert!(!report.passed());
        assert!(report.scenes.iter().all(|s| s.status == "not run"));
        assert!(report.to_text().contains("render 1 of 4: no spheres here"));
    }
}
