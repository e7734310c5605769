//! The comparison as grading's [`ImageChecker`]: the noise-aware verdict, the signed z heatmap
//! and the diagnosis for the student's feedback.

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

use sha2::{Digest, Sha256};

use super::{
    CandidateImage, CompareError, CompareOptions, Golden, check_size, compare_image,
    golden_for_scene, golden_spp, write_heatmap,
};
use crate::grade::inputs::{ImageChecker, ImageOutcome, ImageVerdict};

/// Grades images with [`compare_image`] against the golden of each built-in scene (embedded,
/// or rendered once and cached), keeping each golden in memory for the whole batch.
#[derive(Debug, Default)]
pub struct CompareImageChecker {
    /// How to compare (samples per pixel, encoding, false-failure rate).
    pub options: CompareOptions,
    goldens: Mutex<HashMap<String, Arc<Golden>>>,
}

impl CompareImageChecker {
    /// A checker with the given options.
    pub fn new(options: CompareOptions) -> Self {
        CompareImageChecker {
            options,
            goldens: Mutex::new(HashMap::new()),
        }
    }

    fn golden(&self, scene: &str) -> Result<Arc<Golden>, CompareError> {
        let mut cache = self.goldens.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(g) = cache.get(scene) {
            return Ok(Arc::clone(g));
        }
        let g = Arc::new(golden_for_scene(scene, self.options.samples_per_pixel)?);
        cache.insert(scene.to_string(), Arc::clone(&g));
        Ok(g)
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.display().to_string())
}

impl ImageChecker for CompareImageChecker {
    fn describe(&self) -> String {
        format!(
            "noise-aware comparison (rtoracle compare): golden of {} spp, candidate {} spp, {} encoding, per-image false-failure rate {}",
            golden_spp(self.options.samples_per_pixel),
            self.options.samples_per_pixel,
            self.options.encoding,
            self.options.alpha
        )
    }

    fn golden_sha256(&self, scene: &str) -> String {
        match self.golden(scene) {
            Ok(g) => Sha256::digest(g.to_cache_bytes())
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect(),
            Err(_) => String::new(),
        }
    }

    fn check(&self, candidate_png: &Path, scene: &str, heatmap_out: &Path) -> ImageOutcome {
        let name = file_name(candidate_png);
        if !candidate_png.exists() {
            return ImageOutcome::unusable(format!("{name} is missing from the submission"));
        }
        let candidate = match CandidateImage::load(candidate_png) {
            Ok(c) => c,
            Err(e) => return ImageOutcome::unusable(e.to_string()),
        };
        let golden = match self.golden(scene) {
            Ok(g) => g,
            Err(e) => return ImageOutcome::unusable(format!("no golden for {scene}: {e}")),
        };
        if let Err(e) = check_size(candidate_png, &candidate, golden.width, golden.height) {
            // Name the file as the student knows it, not by the grader's path.
            let why = e
                .to_string()
                .replace(&format!("{}: ", candidate_png.display()), "");
            return ImageOutcome::unusable(format!("{name} {why}"));
        }
        let comparison = match compare_image(&candidate, &golden, &self.options) {
            Ok(c) => c,
            Err(e) => return ImageOutcome::unusable(format!("{name}: {e}")),
        };
        let heatmap = write_heatmap(heatmap_out, &comparison)
            .ok()
            .map(|_| heatmap_out.to_path_buf());
        let diagnosis = comparison.diagnosis.as_ref().map(|d| {
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
