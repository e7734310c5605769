//! The stand-in image checker (see the [module docs](super)).

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

use serde_json::json;

use crate::grade::inputs::{ImageChecker, ImageOutcome, ImageVerdict};
use crate::grade::rubric::sha256_hex;
use crate::image_io::{ImageError, Rgb8Image, read_png, write_png};
use crate::render::{RenderOptions, render};

/// Compares a PNG with a reference render of the same built-in scene, pixel by pixel.
#[derive(Debug)]
pub struct StandinImageChecker {
    /// Samples per pixel of the reference render.
    pub spp: u32,
    /// Seed of the reference render.
    pub seed: u64,
    /// A pixel is off when a channel differs by more than this many codes.
    pub code_tolerance: u8,
    /// The image fails when more than this fraction of its pixels is off.
    pub max_off_fraction: f64,
    references: Mutex<HashMap<String, Arc<Rgb8Image>>>,
}

impl Default for StandinImageChecker {
    fn default() -> Self {
        StandinImageChecker {
            spp: 20,
            seed: 0,
            code_tolerance: 2,
            max_off_fraction: 0.02,
            references: Mutex::new(HashMap::new()),
        }
    }
}

impl StandinImageChecker {
    /// The reference image of `scene`, rendered once and kept.
    pub fn reference(&self, scene: &str) -> Option<Arc<Rgb8Image>> {
        let mut cache = self.references.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(img) = cache.get(scene) {
            return Some(Arc::clone(img));
        }
        let description = crate::scene::builtin(scene).ok()?;
        let options = RenderOptions {
            samples_per_pixel: self.spp,
            seed: self.seed,
            ..Default::default()
        };
        let film = render(&description.scene(), &description.camera(None), &options).ok()?;
        let img = Arc::new(Rgb8Image {
            width: film.width,
            height: film.height,
            data: film.to_course_rgb8(),
        });
        cache.insert(scene.to_string(), Arc::clone(&img));
        Some(img)
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.display().to_string())
}

impl ImageChecker for StandinImageChecker {
    fn describe(&self) -> String {
        format!(
            "stand-in: reference render ({} spp, seed {}); fails when more than {}% of pixels differ by more than {} codes",
            self.spp,
            self.seed,
            self.max_off_fraction * 100.0,
            self.code_tolerance
        )
    }

    fn golden_sha256(&self, scene: &str) -> String {
        self.reference(scene)
            .map(|img| sha256_hex(&img.data))
            .unwrap_or_default()
    }

    fn check(&self, candidate_png: &Path, scene: &str, heatmap_out: &Path) -> ImageOutcome {
        let name = file_name(candidate_png);
        if !candidate_png.exists() {
            return ImageOutcome::unusable(format!("{name} is missing from the submission"));
        }
        let candidate = match read_png(candidate_png) {
            Ok(img) => img,
            Err(ImageError::Io { message, .. } | ImageError::Format { message, .. }) => {
                return ImageOutcome::unusable(format!("{name}: {message}"));
            }
        };
        let Some(reference) = self.reference(scene) else {
            return ImageOutcome::unusable(format!("no reference for scene {scene:?}"));
        };
        if (candidate.width, candidate.height) != (reference.width, reference.height) {
            return ImageOutcome::unusable(format!(
                "{name} is {}x{} pixels; the scene {scene} is {}x{}",
                candidate.width, candidate.height, reference.width, reference.height
            ));
        }
        let (w, h) = (reference.width, reference.height);
        let mut off = 0usize;
        let mut max_diff = 0i32;
        let mut signed = [0i64; 3];
        let mut bbox: Option<[usize; 4]> = None;
        let mut heat = Vec::with_capacity(3 * w * h);
        for p in 0..w * h {
            let mut worst = 0i32;
            let mut luma = 0i32;
            for (k, sum) in signed.iter_mut().enumerate() {
                let d = candidate.data[3 * p + k] as i32 - reference.data[3 * p + k] as i32;
                *sum += d as i64;
                worst = worst.max(d.abs());
                luma += reference.data[3 * p + k] as i32;
            }
            max_diff = max_diff.max(worst);
            let grey = (luma / 9) as u8;
            if worst > self.code_tolerance as i32 {
                off += 1;
                let (x, y) = (p % w, p / w);
                let b = bbox.get_or_insert([x, y, x, y]);
                *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
                let strength = (96 + worst * 4).min(255) as u8;
                heat.extend([strength, grey / 2, grey / 2]);
            } else {
                heat.extend([grey, grey, grey]);
            }
        }
        let n = (w * h) as f64;
        let fraction = off as f64 / n;
        let bias = signed.map(|s| s as f64 / n);
        let heatmap = write_png(
            heatmap_out,
            &Rgb8Image {
                width: w,
                height: h,
                data: heat,
            },
        )
        .ok()
        .map(|_| heatmap_out.to_path_buf());
        let pass = fraction <= self.max_off_fraction;
        let diagnosis = if pass {
            None
        } else if bias.iter().all(|b| *b < 0.0) && bias.iter().sum::<f64>() < -24.0 {
            Some("The whole image is darker than the reference: is the gamma correction (sqrt) missing, or the albedo too low?".into())
        } else if bias.iter().all(|b| *b > 0.0) && bias.iter().sum::<f64>() > 24.0 {
            Some("The whole image is brighter than the reference: is the colour scaled twice, or gamma applied twice?".into())
        } else {
            let b = bbox.unwrap_or([0, 0, 0, 0]);
            Some(format!(
                "{:.1}% of the pixels differ by more than {} codes, within x {}..{}, y {}..{} (red in the heatmap): is an object missing, moved or the wrong colour?",
                fraction * 100.0,
                self.code_tolerance,
                b[0],
                b[2],
                b[1],
                b[3]
            ))
        };
        ImageOutcome {
            verdict: if pass {
                ImageVerdict::Pass
            } else {
                ImageVerdict::Fail
            },
            metrics: json!({
                "width": w,
                "height": h,
                "off_pixels": off,
                "off_fraction": fraction,
                "max_code_difference": max_diff,
                "mean_signed_difference_rgb": bias,
                "off_region": bbox,
                "tolerance": {"codes": self.code_tolerance, "max_off_fraction": self.max_off_fraction},
            }),
            diagnosis,
            heatmap,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render_png(dir: &Path, scene: &str, seed: u64, f: impl Fn(f64) -> u8) -> std::path::PathBuf {
        let d = crate::scene::builtin(scene).unwrap();
        let options = RenderOptions {
            samples_per_pixel: 20,
            seed,
            ..Default::default()
        };
        let film = render(&d.scene(), &d.camera(None), &options).unwrap();
        let data = film
            .mean
            .iter()
            .flat_map(|c| c.to_array().map(&f))
            .collect();
        let path = dir.join(format!("{scene}-{seed}.png"));
        write_png(
            &path,
            &Rgb8Image {
                width: film.width,
                height: film.height,
                data,
            },
        )
        .unwrap();
        path
    }

    #[test]
    fn another_seed_passes_a_missing_gamma_fails_and_a_wrong_size_is_unusable() {
        let dir = tempfile::tempdir().unwrap();
        let checker = StandinImageChecker::default();
        let heat = dir.path().join("heat.png");
        let honest = render_png(
            dir.path(),
            "week04-quad",
            11,
            crate::render::encode_course_png,
        );
        let o = checker.check(&honest, "week04-quad", &heat);
        assert_eq!(o.verdict, ImageVerdict::Pass, "{}", o.metrics);
        assert!(heat.exists());
        // Linear values written without the square root: darker everywhere.
        let linear = render_png(dir.path(), "week04-quad", 12, |x| {
            (255.0 * x.clamp(0.0, 0.999)) as u8
        });
        let o = checker.check(&linear, "week04-quad", &heat);
        assert_eq!(o.verdict, ImageVerdict::Fail);
        assert!(
            o.diagnosis.clone().unwrap().contains("darker"),
            "{:?} {}",
            o.diagnosis,
            o.metrics
        );
        let o = checker.check(&honest, "week04-sphere", &heat);
        match o.verdict {
            ImageVerdict::Unusable(m) => assert!(
                m.contains("is 400x400 pixels; the scene week04-sphere is 400x225"),
                "{m}"
            ),
            v => panic!("{v:?}"),
        }
        let junk = dir.path().join("junk.png");
        std::fs::write(&junk, b"not a png").unwrap();
        match checker.check(&junk, "week04-quad", &heat).verdict {
            ImageVerdict::Unusable(m) => {
                assert!(m.starts_with("junk.png: not a readable PNG"), "{m}")
            }
            v => panic!("{v:?}"),
        }
        let o = checker.check(&dir.path().join("nope.png"), "week04-quad", &heat);
        assert_eq!(
            o.verdict,
            ImageVerdict::Unusable("nope.png is missing from the submission".into())
        );
    }
}
