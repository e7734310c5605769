//! The comparison as grading's [`ImageChecker`]: the noise-aware verdict of [`crate::compare`],
//! the signed z heatmap and the diagnosis for the student's feedback, against the golden of a
//! built-in scene or of an instructor's scene file.
//!
//! This adapter lives in `grade`, not in `compare`, so the comparison knows nothing of rubrics.
//! It promises: each golden is obtained once per checker (a batch shares one checker) and kept
//! in memory; a scene file's golden is the rubric's `golden` when it names one, else the one in
//! the cache ([`crate::golden::cached_golden`]), rendered there the first time (one line on
//! stderr says so, and indicatif's bar shows the progress when stderr is a terminal). An image
//! of a scene file is judged as a render of the scene's own `samples_per_pixel` (the count its
//! students are told to use), with a golden of [`golden_spp`] of it; built-in scenes use the
//! options' count (20, the course's).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use sha2::{Digest, Sha256};

use super::inputs::{ImageChecker, ImageOutcome, ImageVerdict, SceneFile, SceneSource};
use crate::compare::{
    CandidateImage, CompareError, CompareOptions, Golden, check_size, compare_image,
    golden_for_scene, golden_spp, write_heatmap,
};
use crate::image_io::decode_exr;

/// Grades images with [`compare_image`] against the golden of each scene: for built-in scenes
/// the embedded one (or one rendered once and cached), for scene files the rubric's golden or
/// the cached one; each golden is kept in memory for the whole batch.
#[derive(Debug, Default)]
pub struct CompareImageChecker {
    /// How to compare (samples per pixel, encoding, false-failure rate). Its samples per pixel
    /// are the built-in scenes' candidates'; a scene file's candidates are judged at the scene's
    /// own `samples_per_pixel` instead.
    pub options: CompareOptions,
    /// The golden cache folder for scene files; `None`: [`crate::golden::cache_dir`].
    pub cache_dir: Option<PathBuf>,
    goldens: Mutex<HashMap<String, (Arc<Golden>, String)>>,
}

impl CompareImageChecker {
    /// A checker with the given options.
    pub fn new(options: CompareOptions) -> Self {
        CompareImageChecker {
            options,
            cache_dir: None,
            goldens: Mutex::new(HashMap::new()),
        }
    }

    /// The golden of `scene` and the SHA-256 of its bytes (the EXR file's for scene files).
    fn golden(&self, scene: &SceneSource) -> Result<(Arc<Golden>, String), CompareError> {
        let key = match scene {
            SceneSource::Builtin(name) => format!("builtin:{name}"),
            SceneSource::File(f) => format!(
                "file:{}:{}",
                f.sha256,
                f.golden.as_ref().map_or("cache", |g| g.sha256.as_str())
            ),
        };
        // Held while the golden is made: the members of a batch wait for one render.
        let mut cache = self.goldens.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((g, h)) = cache.get(&key) {
            return Ok((Arc::clone(g), h.clone()));
        }
        let (golden, sha) = match scene {
            SceneSource::Builtin(name) => {
                let g = golden_for_scene(name, self.options.samples_per_pixel)?;
                let sha = hex(&Sha256::digest(g.to_cache_bytes()));
                (g, sha)
            }
            SceneSource::File(f) => self.file_golden(f)?,
        };
        let golden = Arc::new(golden);
        cache.insert(key, (Arc::clone(&golden), sha.clone()));
        Ok((golden, sha))
    }

    /// The candidate's samples per pixel for `scene`: a scene file's own, else the options'.
    fn candidate_spp(&self, scene: &SceneSource) -> u32 {
        match scene {
            SceneSource::Builtin(_) => self.options.samples_per_pixel,
            SceneSource::File(f) => f.description.image.samples_per_pixel,
        }
    }

    fn file_golden(&self, f: &SceneFile) -> Result<(Golden, String), CompareError> {
        let (bytes, path) = match &f.golden {
            Some(g) => (g.bytes.clone(), g.path.clone()),
            None => {
                let spp = golden_spp(f.description.image.samples_per_pixel);
                let camera = f.description.camera(None);
                let dir = self.cache_dir.clone().or_else(crate::golden::cache_dir);
                let cache_file = dir
                    .as_ref()
                    .map(|d| crate::golden::cache_file(d, &f.description, spp));
                if !cache_file.as_ref().is_some_and(|p| p.is_file()) {
                    crate::output::stderr_line(&format!(
                        "rendering the golden of {} ({}x{}, {spp} spp), once per cache{}",
                        crate::escape::terminal_line(&f.label),
                        camera.width,
                        camera.height,
                        cache_file.as_ref().map_or(String::new(), |p| format!(
                            ": {}",
                            crate::escape::terminal_line(&p.display().to_string())
                        ))
                    ));
                }
                let made = crate::golden::cached_golden_in(
                    dir.as_deref(),
                    &f.description,
                    &f.label,
                    spp,
                    true,
                )
                .map_err(|e| CompareError::Golden(e.to_string()))?;
                if let Some(why) = &made.warning {
                    crate::output::stderr_line(&format!(
                        "warning: the golden of {} is not cached ({}); it is rendered again next time",
                        crate::escape::terminal_line(&f.label),
                        crate::escape::terminal_line(why)
                    ));
                }
                let path = made
                    .path
                    .clone()
                    .unwrap_or_else(|| f.path.with_extension("exr"));
                (made.bytes, path)
            }
        };
        let image = decode_exr(&bytes, &path)?;
        let golden = Golden::from_exr_image(image, &path)?;
        Ok((golden, hex(&Sha256::digest(&bytes))))
    }
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.display().to_string())
}

impl ImageChecker for CompareImageChecker {
    fn describe(&self) -> String {
        format!(
            "noise-aware comparison (rtoracle compare): a built-in scene's image as {} spp against a golden of {} spp; a scene file's as its samples_per_pixel N against a golden of max(4096, 100 N) spp, or the rubric's golden as given (each image's metrics give its candidate_spp and golden_spp); {} encoding, per-image false-failure rate {}",
            self.options.samples_per_pixel,
            golden_spp(self.options.samples_per_pixel),
            self.options.encoding,
            self.options.alpha
        )
    }

    fn golden_sha256(&self, scene: &str) -> String {
        self.scene_golden_sha256(&SceneSource::Builtin(scene.to_string()))
    }

    fn prepare(&self, scenes: &[SceneSource]) -> Result<(), String> {
        for scene in scenes {
            self.golden(scene)
                .map_err(|e| format!("no golden for {}: {e}", scene.label()))?;
        }
        Ok(())
    }

    fn scene_golden_sha256(&self, scene: &SceneSource) -> String {
        self.golden(scene).map(|(_, h)| h).unwrap_or_default()
    }

    fn check(&self, candidate_png: &Path, scene: &str, heatmap_out: &Path) -> ImageOutcome {
        self.check_scene(
            candidate_png,
            &SceneSource::Builtin(scene.to_string()),
            heatmap_out,
        )
    }

    fn check_scene(
        &self,
        candidate_png: &Path,
        scene: &SceneSource,
        heatmap_out: &Path,
    ) -> ImageOutcome {
        let name = file_name(candidate_png);
        if !candidate_png.exists() {
            return ImageOutcome::unusable(format!("{name} is missing from the submission"));
        }
        let candidate = match CandidateImage::load(candidate_png) {
            Ok(c) => c,
            Err(e) => return ImageOutcome::unusable(e.to_string()),
        };
        let golden = match self.golden(scene) {
            Ok((g, _)) => g,
            Err(e) => {
                return ImageOutcome::unusable(format!("no golden for {}: {e}", scene.label()));
            }
        };
        if let Err(e) = check_size(candidate_png, &candidate, golden.width, golden.height) {
            // Name the file as the student knows it, not by the grader's path.
            let why = e
                .to_string()
                .replace(&format!("{}: ", candidate_png.display()), "");
            return ImageOutcome::unusable(format!("{name} {why}"));
        }
        let options = CompareOptions {
            samples_per_pixel: self.candidate_spp(scene),
            ..self.options
        };
        let comparison = match compare_image(&candidate, &golden, &options) {
            Ok(c) => c,
            Err(e) => return ImageOutcome::unusable(format!("{name}: {e}")),
        };
        let heatmap = write_heatmap(heatmap_out, &comparison)
            .ok()
            .map(|_| heatmap_out.to_path_buf());
        let mut diagnosis = comparison.diagnosis.as_ref().map(|d| {
            let mut s = d.summary.clone();
            if let Some(r) = comparison.regions.first() {
                s.push_str(&format!(
                    "; the strongest difference is at x {}..{}, y {}..{} (outlined in the heatmap)",
                    r.x,
                    r.x + r.width,
                    r.y,
                    r.y + r.height
                ));
            }
            s
        });
        // Too few samples is told first when no mistake of the catalogue explains the image (a
        // wrong encoding also makes an image look noisy: then the mistake is the cause).
        let explained = comparison
            .diagnosis
            .as_ref()
            .is_some_and(|d| d.best.is_some() && d.hypotheses.first().is_some_and(|h| h.passes));
        if let Some(n) = comparison
            .noise
            .as_ref()
            .filter(|n| !n.passed && !explained)
        {
            let about = n
                .effective_spp
                .map(|e| format!(" (its noise is that of about {e:.1} samples per pixel)"))
                .unwrap_or_default();
            let noisy = format!(
                "it is noisier than a render of {} samples per pixel{about}: render it with {} samples per pixel",
                n.claimed_spp, n.claimed_spp
            );
            diagnosis = Some(match diagnosis {
                Some(d) => format!("{noisy}; {d}"),
                None => noisy,
            });
        }
        ImageOutcome {
            verdict: if comparison.passed() {
                ImageVerdict::Pass
            } else {
                ImageVerdict::Fail
            },
            metrics: serde_json::to_value(&comparison).unwrap_or_default(),
            diagnosis,
            heatmap,
        }
    }
}
