//! The comparison as grading's [`ImageChecker`]: the noise-aware verdict of [`crate::compare`],
//! the signed z heatmap and the diagnosis for the student's feedback, against the golden of a
//! built-in scene or of an instructor's scene file.
//!
//! This adapter lives in `grade`, not in `compare`, so the comparison knows nothing of rubrics.
//! It promises: each golden is obtained once per checker (a batch shares one checker) and kept
//! in memory; a scene file's golden is the rubric's `golden` when it names one, else the one
//! [`crate::golden::golden_of`] gives, as for a built-in scene (embedded, cached, or rendered
//! into the cache the first time: one line on stderr says so, and indicatif's bar shows the
//! progress when stderr is a terminal). An image of a scene file is judged as a render of the
//! scene's own `samples_per_pixel` (the count its students are told to use), with a golden of
//! [`golden_spp`] of it; built-in scenes use the options' count (20, the course's). A golden's
//! SHA-256 is that of its EXR bytes.
//!
//! The grader's own renders (a render group's scene and its variant) are judged as renders of
//! exactly their spp: besides `compare`'s verdict, one too clean for its spp fails
//! ([`crate::grade::checkers::noise_floor`], reported as `metrics.noise_floor`). A variant's reference is
//! rendered on the spot at `max(`[`VARIANT_REFERENCE_SPP`]`, 100 N)` samples per pixel, with its
//! variance, once per variant and checker (a batch asks every submission the same variant).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::compare::{
    CompareError, CompareOptions, candidate::CandidateImage, check_size, compare_image,
    heatmap::write_heatmap, noise_model::Golden,
};
use crate::golden::{FoundGolden, GoldenScene, golden_of, golden_spp, sha256_hex};
use crate::grade::checkers::noise_floor::too_clean;
use crate::grade::checkers::{
    ImageChecker, ImageOutcome, ImageVerdict, RenderedImage, SceneFile, SceneSource,
};
use crate::image_io::decode_exr;
use crate::scene::SceneDescription;

/// The least samples per pixel of the reference's render of a variant (made on the spot, once
/// per variant and batch): `max(1024, 100 N)` for renders of `N`. A variant is a quarter of its
/// scene's pixels, so this costs about a sixteenth of a 4096-spp golden.
pub const VARIANT_REFERENCE_SPP: u32 = 1024;

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
                let scene =
                    GoldenScene::builtin(name).map_err(|e| CompareError::Golden(e.to_string()))?;
                self.found(&scene, self.options.samples_per_pixel)?
            }
            SceneSource::File(f) => self.file_golden(f)?,
        };
        let golden = Arc::new(golden);
        cache.insert(key, (Arc::clone(&golden), sha.clone()));
        Ok((golden, sha))
    }

    /// The golden a render of `scene` at `spp` samples per pixel is judged against: the scene's
    /// own, except for a scene whose image depends on its samples per pixel (the course's
    /// jittered sampling, [`crate::golden::at_spp`]), whose golden is that of the scene at
    /// `spp` (embedded for the built-in rubrics' counts, else rendered once into the cache).
    fn render_golden(
        &self,
        scene: &SceneSource,
        spp: u32,
    ) -> Result<(Arc<Golden>, String), CompareError> {
        let derived = match scene {
            SceneSource::Builtin(name) => crate::scene::builtin(name)
                .ok()
                .and_then(|d| crate::golden::at_spp(&d, spp))
                .map(|_| (format!("builtin:{name}@{spp}"), None)),
            SceneSource::File(f) if f.golden.is_none() => {
                crate::golden::at_spp(&f.description, spp)
                    .map(|d| (format!("file:{}@{spp}", f.sha256), Some((f, d))))
            }
            SceneSource::File(_) => None,
        };
        let Some((key, file)) = derived else {
            return self.golden(scene);
        };
        let mut cache = self.goldens.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((g, h)) = cache.get(&key) {
            return Ok((Arc::clone(g), h.clone()));
        }
        let golden_scene = match (scene, file) {
            (SceneSource::Builtin(name), _) => GoldenScene::builtin_at_spp(name, spp),
            (_, Some((f, d))) => GoldenScene::from_description(&f.label, d, f.path.parent()),
            _ => unreachable!("a derived golden is of a built-in scene or a scene file"),
        }
        .map_err(|e| CompareError::Golden(e.to_string()))?;
        let (golden, sha) = self.found(&golden_scene, spp)?;
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

    /// The golden of `scene` for candidates of `candidate_spp` from [`golden_of`] (with this
    /// checker's cache folder), and its SHA-256.
    fn found(
        &self,
        scene: &GoldenScene,
        candidate_spp: u32,
    ) -> Result<(Golden, String), CompareError> {
        let dir = self.cache_dir.clone().or_else(crate::golden::cache_dir);
        let FoundGolden {
            bytes,
            image,
            source,
            ..
        } = golden_of(scene, golden_spp(candidate_spp), dir.as_deref(), true)
            .map_err(|e| CompareError::Golden(e.to_string()))?;
        let mut golden = Golden::from_exr_image(image, &source)?;
        golden.scene = Some(scene.name.clone());
        Ok((golden, sha256_hex(&bytes)))
    }

    fn file_golden(&self, f: &SceneFile) -> Result<(Golden, String), CompareError> {
        match &f.golden {
            Some(g) => {
                let image = decode_exr(&g.bytes, &g.path)?;
                let golden = Golden::from_exr_image(image, &g.path)?;
                Ok((golden, sha256_hex(&g.bytes)))
            }
            None => {
                let scene = golden_scene_of(f).map_err(|e| CompareError::Golden(e.to_string()))?;
                self.found(&scene, f.description.image.samples_per_pixel)
            }
        }
    }
}

impl CompareImageChecker {
    /// Compares `candidate` (named `name` in messages), a render of `spp` samples per pixel, with
    /// the golden of `scene`: the verdict, the metrics, the diagnosis and the heatmap; with
    /// `floor`, a candidate too clean for `spp` fails ([`crate::grade::checkers::noise_floor`]).
    fn judge(
        &self,
        candidate: &CandidateImage,
        scene: &SceneSource,
        spp: u32,
        name: &str,
        heatmap_out: &Path,
        floor: bool,
    ) -> ImageOutcome {
        let golden = match self.render_golden(scene, spp) {
            Ok((g, _)) => g,
            Err(e) => {
                return ImageOutcome::unusable(format!("no golden for {}: {e}", scene.label()));
            }
        };
        self.judge_against(candidate, &golden, spp, name, Some(heatmap_out), floor)
    }

    /// The reference of a variant (`variant` rendered now at `spp` samples per pixel, with its
    /// variance, as a golden is), kept for the batch: every submission of a rubric and seed is
    /// asked the same variant.
    fn variant_golden(&self, variant: &SceneDescription, spp: u32) -> Result<Arc<Golden>, String> {
        let key = format!("variant:{}@{spp}", crate::golden::scene_sha256(variant));
        let mut cache = self.goldens.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((g, _)) = cache.get(&key) {
            return Ok(Arc::clone(g));
        }
        let scene = GoldenScene::from_description("the variant", variant.clone(), None)
            .map_err(|e| e.to_string())?;
        let film = crate::golden::render_golden(&scene, spp, false).map_err(|e| e.to_string())?;
        let golden = Golden::from_film(&film, Some("the variant".into()))
            .map_err(|e| e.to_string())?
            .with_vfov(Some(variant.camera.vfov));
        let golden = Arc::new(golden);
        cache.insert(key, (Arc::clone(&golden), String::new()));
        Ok(golden)
    }

    /// Compares `candidate` (named `name`), a render of `spp` samples per pixel, with `golden`,
    /// writing the heatmap to `heatmap_out` when one is given; with `floor`, a candidate that
    /// passes but is too clean for `spp` fails ([`too_clean`]).
    fn judge_against(
        &self,
        candidate: &CandidateImage,
        golden: &Golden,
        spp: u32,
        name: &str,
        heatmap_out: Option<&Path>,
        floor: bool,
    ) -> ImageOutcome {
        let (w, h) = candidate.size();
        if (w, h) != (golden.width, golden.height) {
            return ImageOutcome::unusable(format!(
                "{name} is {w}x{h} but the golden is {}x{}",
                golden.width, golden.height
            ));
        }
        let options = CompareOptions {
            samples_per_pixel: spp,
            ..self.options
        };
        let comparison = match compare_image(candidate, golden, &options) {
            Ok(c) => c,
            Err(e) => return ImageOutcome::unusable(format!("{name}: {e}")),
        };
        let heatmap = heatmap_out.and_then(|out| {
            write_heatmap(out, &comparison)
                .ok()
                .map(|_| out.to_path_buf())
        });
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
        let mut metrics = serde_json::to_value(&comparison).unwrap_or_default();
        let mut passed = comparison.passed();
        if floor {
            let found = too_clean(candidate, golden, spp, options.lambda, options.encoding);
            if let Some(f) = found.as_ref().filter(|f| f.too_clean && passed) {
                passed = false;
                diagnosis = Some(f.sentence());
            }
            if let (Some(f), Some(map)) = (found, metrics.as_object_mut()) {
                map.insert(
                    "noise_floor".into(),
                    serde_json::to_value(f).unwrap_or_default(),
                );
            }
        }
        ImageOutcome {
            verdict: if passed {
                ImageVerdict::Pass
            } else {
                ImageVerdict::Fail
            },
            metrics,
            diagnosis,
            heatmap,
        }
    }
}

/// The candidate a render is judged as: a program's film as the PNG it would have written, a
/// description's render as the linear means it is.
fn candidate_of(render: &RenderedImage) -> CandidateImage {
    match &render.film {
        Some(film) => CandidateImage::Rgb8 {
            width: render.width,
            height: render.height,
            data: film.clone(),
        },
        None => CandidateImage::Linear {
            width: render.width,
            height: render.height,
            data: render.data.clone(),
        },
    }
}

/// What the golden of a rubric's scene file is made from: the scene, named by its label, reading
/// its other files from its folder.
pub(crate) fn golden_scene_of(f: &SceneFile) -> Result<GoldenScene, crate::golden::GoldenError> {
    GoldenScene::from_description(&f.label, f.description.clone(), f.path.parent())
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

    fn render_golden_sha256(&self, scene: &SceneSource, spp: u32) -> String {
        self.render_golden(scene, spp)
            .map(|(_, h)| h)
            .unwrap_or_default()
    }

    fn check(&self, candidate_png: &Path, scene: &str, heatmap_out: &Path) -> ImageOutcome {
        self.check_scene(
            candidate_png,
            &SceneSource::Builtin(scene.to_string()),
            heatmap_out,
        )
    }

    fn check_render(
        &self,
        render: &RenderedImage,
        scene: &SceneSource,
        heatmap_out: &Path,
    ) -> ImageOutcome {
        let candidate = candidate_of(render);
        self.judge(
            &candidate,
            scene,
            render.spp,
            "the render",
            heatmap_out,
            true,
        )
    }

    fn check_variant(&self, render: &RenderedImage, variant: &SceneDescription) -> ImageOutcome {
        let m = VARIANT_REFERENCE_SPP.max(render.spp.saturating_mul(100));
        let golden = match self.variant_golden(variant, m) {
            Ok(g) => g,
            Err(e) => {
                return ImageOutcome::unusable(format!("no reference for the variant: {e}"));
            }
        };
        let candidate = candidate_of(render);
        self.judge_against(
            &candidate,
            &golden,
            render.spp,
            "the variant's render",
            None,
            true,
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
        self.judge(
            &candidate,
            scene,
            self.candidate_spp(scene),
            &name,
            heatmap_out,
            false,
        )
    }
}
