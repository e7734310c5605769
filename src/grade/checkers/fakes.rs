//! Test doubles of the two interfaces grading is built on.

use std::collections::BTreeMap;
use std::path::Path;

use crate::grade::checkers::{
    CodeChecker, CodeOutcome, FailureSummary, GroupCounts, ImageChecker, ImageOutcome, ImageVerdict,
};
use crate::grade::rubric::SceneSource;
use crate::grade::run::expected_size;
use crate::oracle::vectors::ShapeKind;

/// Answers with fixed counts per shape (and an optional fatal error).
pub struct FakeCode {
    pub counts: BTreeMap<ShapeKind, GroupCounts>,
    pub fatal: Option<String>,
    pub panic_on: Option<String>,
    /// The failures every submission gets.
    pub failures: Vec<FailureSummary>,
}

impl FakeCode {
    pub fn new(sphere: GroupCounts, quad: GroupCounts) -> Self {
        FakeCode {
            counts: [(ShapeKind::Sphere, sphere), (ShapeKind::Quad, quad)].into(),
            fatal: None,
            panic_on: None,
            failures: Vec::new(),
        }
    }
}

/// `total` definite vectors of which `passed` passed and the rest failed as `kind`.
pub fn counts(total: usize, passed: usize) -> GroupCounts {
    GroupCounts {
        definite_total: total,
        passed,
        failed: total - passed,
        ..Default::default()
    }
}

impl CodeChecker for FakeCode {
    fn check(&self, submission: &Path, groups: &[ShapeKind]) -> CodeOutcome {
        if let Some(name) = &self.panic_on {
            if submission.ends_with(name) {
                panic!("fake checker told to panic on {name}");
            }
        }
        CodeOutcome {
            per_group: groups
                .iter()
                .map(|g| (*g, self.counts.get(g).cloned().unwrap_or_default()))
                .collect(),
            failures: self.failures.clone(),
            fatal: self.fatal.clone(),
            stderr_tail: String::new(),
            sandbox: serde_json::Value::Null,
            ..Default::default()
        }
    }
    fn describe(&self) -> String {
        "fake".into()
    }
    fn vectors_sha256(&self) -> String {
        "v".into()
    }
    /// A grey image of each job's size at once (the fake image checker reads no pixel).
    fn render(
        &self,
        _: &Path,
        jobs: &[crate::grade::checkers::RenderJob],
    ) -> Vec<crate::grade::checkers::RenderOutcome> {
        jobs.iter()
            .map(|job| {
                let camera = job.scene.camera(None);
                crate::grade::checkers::RenderOutcome::Rendered(
                    crate::grade::checkers::RenderedImage {
                        width: camera.width,
                        height: camera.height,
                        spp: job.spp,
                        seconds: 0.0,
                        data: vec![[0.5; 3]; camera.width * camera.height],
                        film: None,
                        made_by: Default::default(),
                    },
                )
            })
            .collect()
    }
}

/// Gives a fixed verdict per scene.
pub struct FakeImage(pub BTreeMap<String, ImageVerdict>);

impl ImageChecker for FakeImage {
    fn check(&self, _: &Path, scene: &str, _: &Path) -> ImageOutcome {
        ImageOutcome {
            verdict: self.0.get(scene).cloned().unwrap_or(ImageVerdict::Pass),
            metrics: serde_json::json!({}),
            diagnosis: None,
            heatmap: None,
        }
    }
    fn describe(&self) -> String {
        "fake".into()
    }
    fn golden_sha256(&self, scene: &str) -> String {
        format!("golden-{scene}")
    }
    /// A variant passes (the fake reads no pixel).
    fn check_variant(
        &self,
        _: &crate::grade::checkers::RenderedImage,
        _: &crate::scene::SceneDescription,
    ) -> ImageOutcome {
        ImageOutcome {
            verdict: ImageVerdict::Pass,
            metrics: serde_json::json!({}),
            diagnosis: None,
            heatmap: None,
        }
    }
}

pub fn all_pass() -> FakeImage {
    FakeImage(BTreeMap::new())
}

/// Writes the images of the week-4 rubric into `dir` as PNG headers of the right size (the
/// fake checker reads no pixel; grading reads the header before handing the file over).
pub fn fake_images(dir: &Path) {
    for (file, scene) in [
        ("week04_sphere.png", "week04-sphere"),
        ("week04_quad.png", "week04-quad"),
    ] {
        let (w, h) = expected_size(&SceneSource::Builtin(scene.into())).unwrap();
        let mut b = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
        b.extend((w as u32).to_be_bytes());
        b.extend((h as u32).to_be_bytes());
        b.extend([8, 2, 0, 0, 0, 0, 0, 0, 0]);
        std::fs::write(dir.join(file), b).unwrap();
    }
}
