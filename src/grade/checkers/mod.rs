//! The two narrow interfaces grading is built on: one checks a submission's code against the
//! intersection vectors, the other compares one of its images with the reference.
//!
//! [`grade`](super::run::grade) only ever talks to a [`CodeChecker`] and an [`ImageChecker`]: the
//! `check` harness ([`CourseCodeChecker`](super::checkers::code::CourseCodeChecker)), the noise-aware comparison
//! ([`CompareImageChecker`](super::checkers::images::CompareImageChecker)) and the fakes of the tests implement
//! them.

pub mod code;
pub mod copies;
pub mod noise_floor;
pub mod images;
pub mod rendered;
#[cfg(test)]
pub(crate) mod fakes;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::rubric::credit::ClassTally;
use crate::oracle::vectors::ShapeKind;
use crate::scene::SceneDescription;

use super::rubric::{SceneFile, SceneSource};

/// Checks the intersection code of a submission.
pub trait CodeChecker: Sync {
    /// Runs the vectors of every kind in `groups` against the submission in folder `submission`
    /// and counts the outcomes per kind. Never panics and never returns an error: whatever goes
    /// wrong with the student's code (import error, crash, hang, junk output) is described in
    /// the outcome ([`CodeOutcome::fatal`], failure kinds), so the rest of the grading goes on.
    fn check(&self, submission: &Path, groups: &[ShapeKind]) -> CodeOutcome;

    /// What the checker runs, for the report (e.g. `"stand-in python driver, default suite seed 0"`).
    fn describe(&self) -> String;

    /// The SHA-256 (hex) of the vectors it runs, for the report's reproducibility block.
    fn vectors_sha256(&self) -> String;

    /// Renders each job's scene with the submission's own code (the image groups rendered by
    /// the grader, [`render`](super::checkers::rendered)), one outcome per job, in order. Never panics:
    /// whatever the code does is an outcome. The default declines every job (a checker that
    /// cannot run the submission's renderer).
    fn render(&self, submission: &Path, jobs: &[RenderJob]) -> Vec<RenderOutcome> {
        let _ = submission;
        jobs.iter()
            .map(|_| RenderOutcome::Declined(format!("{} does not render", self.describe())))
            .collect()
    }

    /// Runs week `week`'s function checks ([`crate::weekly`]) on the submission. Never
    /// panics: whatever the code does is in the outcome. The default runs none (a checker that
    /// cannot send function requests), and says so in `fatal`.
    fn check_functions(
        &self,
        submission: &Path,
        week: crate::weekly::week::Week,
        options: crate::weekly::run::FunctionOptions,
    ) -> FunctionsOutcome {
        let _ = (submission, week, options);
        FunctionsOutcome {
            fatal: Some(format!("{} does not run function checks", self.describe())),
            ..FunctionsOutcome::default()
        }
    }
}

use crate::candidate::process::render_request::{RenderJob, RenderOutcome, RenderedImage};

/// What running a week's function checks on a submission found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FunctionsOutcome {
    /// The function checks, judged (`None` when nothing could be run: see `fatal`).
    pub report: Option<crate::weekly::run::WeekReport>,
    /// Set when nothing could be run: the import failed (the message shows the exception), the
    /// interpreter is missing, the checker does not run function checks.
    pub fatal: Option<String>,
    /// The last lines the code wrote to stderr (truncated), file names as the student knows them.
    pub stderr_tail: String,
    /// Functions not run because the code time budget ran out.
    pub out_of_time: usize,
}

/// Compares one image of a submission with the reference of a scene.
pub trait ImageChecker: Sync {
    /// Compares `candidate_png` with the reference of the built-in scene `scene` (for example
    /// `"week04-sphere"`), writing a heatmap to `heatmap_out` when it can. Never panics and never
    /// returns an error: an unreadable or wrong-size file is [`ImageVerdict::Unusable`].
    fn check(&self, candidate_png: &Path, scene: &str, heatmap_out: &Path) -> ImageOutcome;

    /// What the checker does, for the report.
    fn describe(&self) -> String;

    /// The SHA-256 (hex) of the golden/reference it compares `scene` with.
    fn golden_sha256(&self, scene: &str) -> String;

    /// Compares `candidate_png` with the reference of any scene: a built-in one or an
    /// instructor's scene file. Grading calls this one. The default hands the scene's
    /// [label](SceneSource::label) to [`check`](Self::check), which is enough for checkers that
    /// only know built-in scenes (and for fakes).
    fn check_scene(
        &self,
        candidate_png: &Path,
        scene: &SceneSource,
        heatmap_out: &Path,
    ) -> ImageOutcome {
        self.check(candidate_png, scene.label(), heatmap_out)
    }

    /// Makes ready what comparing with `scenes` needs (a golden to render, say) before any
    /// submission is graded, so a batch does it once with every core of the pool it runs on;
    /// the error says which scene could not be made ready. The default does nothing.
    fn prepare(&self, scenes: &[SceneSource]) -> Result<(), String> {
        let _ = scenes;
        Ok(())
    }

    /// The SHA-256 (hex) of the golden it compares `scene` with; the default asks
    /// [`golden_sha256`](Self::golden_sha256) with the scene's label.
    fn scene_golden_sha256(&self, scene: &SceneSource) -> String {
        self.golden_sha256(scene.label())
    }

    /// The SHA-256 (hex) of the golden a render of `scene` at `spp` samples per pixel is judged
    /// against (for a scene of the course's jittered sampling, that of the scene at `spp`); the
    /// default is [`scene_golden_sha256`](Self::scene_golden_sha256)'s.
    fn render_golden_sha256(&self, scene: &SceneSource, spp: u32) -> String {
        let _ = spp;
        self.scene_golden_sha256(scene)
    }

    /// Judges the grader's render of `scene` from the submission's code (linear RGB at
    /// `render.spp` samples per pixel). The default judges it as an uploaded PNG of the course's
    /// encoding ([`judge_as_png`]), which is enough for checkers
    /// that read only files (and for fakes).
    fn check_render(
        &self,
        render: &RenderedImage,
        scene: &SceneSource,
        heatmap_out: &Path,
    ) -> ImageOutcome {
        judge_as_png(render, |png| self.check_scene(png, scene, heatmap_out))
    }

    /// Judges the grader's render of a *variant* of a scene (the scene seen from a camera the
    /// grader moved, `variant` its description at the render's spp) against a reference of the
    /// same variant, which the checker renders on the spot: a variant has no golden made in
    /// advance. The default cannot render one and says so ([`ImageVerdict::Unusable`]).
    fn check_variant(&self, render: &RenderedImage, variant: &SceneDescription) -> ImageOutcome {
        let _ = (render, variant);
        ImageOutcome::unusable(format!(
            "{} cannot render the reference of a variant",
            self.describe()
        ))
    }
}

/// Counts of one shape kind's vectors.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct GroupCounts {
    /// Definite (`hit` / `miss`) vectors of this kind: the ones that are scored.
    pub definite_total: usize,
    /// Definite vectors answered correctly.
    pub passed: usize,
    /// Definite vectors answered wrongly (wrong hit/miss, t, normal or front_face, or junk).
    pub failed: usize,
    /// Definite vectors on which the code raised an exception.
    pub errors: usize,
    /// Definite vectors on which the code did not answer in time.
    pub timeouts: usize,
    /// Definite vectors on which the interpreter died (a crash, `os._exit`, a signal).
    #[serde(default)]
    pub crashes: usize,
    /// Definite vectors never run (after too many timeouts, or when the import failed).
    pub not_run: usize,
    /// Ambiguous vectors run (reported, scored only when the rubric says so).
    pub ambiguous: usize,
    /// Ambiguous vectors whose answer equals the exact one.
    pub ambiguous_passed: usize,
    /// Vectors not scored (ambiguous or `any`) on which the code did not answer in time: each
    /// counts as a scored vector answered wrong (a candidate must answer every vector, as
    /// `rtoracle check` requires).
    #[serde(default)]
    pub unscored_timeouts: usize,
    /// Vectors not scored on which the interpreter died: each counts as a scored vector
    /// answered wrong.
    #[serde(default)]
    pub unscored_crashes: usize,
    /// Watertight groups judged (of class `hit`, every member run; counted under the shape of
    /// their first member): each counts as one scored vector where the ray hits.
    #[serde(default)]
    pub watertight: usize,
    /// Of those, the groups whose ray hit none of their shapes (an open edge): each is a hit
    /// vector answered wrong, and the check fails, as `rtoracle check` does.
    #[serde(default)]
    pub watertight_cracked: usize,
    /// The definite vectors by what they expect and how they were answered: what the scoring
    /// rule ([`credit`](super::rubric::credit)) reads. `report.json` shows it in the check's `credit`.
    /// A checker that leaves it empty is scored as if every vector hit (in proportion to the
    /// vectors passed).
    #[serde(default, skip_serializing)]
    pub tally: ClassTally,
    /// The same for the ambiguous vectors, judged by their exact answer (scored only when the
    /// rubric says so).
    #[serde(default, skip_serializing)]
    pub ambiguous_tally: ClassTally,
}

/// How one vector went wrong: the `check` harness's own kinds.
use crate::candidate::judging::check::FailureKind;

/// One failing vector, ready to be shown to a student.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FailureSummary {
    /// The vector's id (`sphere-basic-0000`).
    pub id: String,
    /// The shape kind.
    pub shape: ShapeKind,
    /// The vector's tags (`tangent`, `corner`, ...).
    pub tags: Vec<String>,
    /// How it failed.
    pub kind: FailureKind,
    /// Whether the vector is definite (scored) or ambiguous (reported only).
    pub definite: bool,
    /// The expected answer, as JSON.
    pub expected: serde_json::Value,
    /// The answer received, as JSON (`null` when there was none).
    pub actual: serde_json::Value,
    /// One line saying what differs (quoting what the code answered or raised: untrusted).
    pub message: crate::escape::Untrusted,
    /// A ready-to-run Python snippet reproducing the case with the course's API.
    pub repro: String,
}

/// Everything a [`CodeChecker`] found.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CodeOutcome {
    /// Counts per shape kind (every kind asked for is present).
    pub per_group: BTreeMap<ShapeKind, GroupCounts>,
    /// Failing vectors, definite ones first, in the suite's order within each kind.
    pub failures: Vec<FailureSummary>,
    /// Set when nothing could be run at all: the import failed (the message shows the
    /// exception), the interpreter is missing, ...
    pub fatal: Option<String>,
    /// The last lines the code wrote to stderr (truncated).
    pub stderr_tail: String,
    /// Facts about the sandbox the code ran in (limits, user, network), for the report.
    pub sandbox: serde_json::Value,
    /// The known mistakes that explain the failures, per shape ([`crate::candidate::judging::diagnose`]).
    #[serde(default)]
    pub diagnosis: Vec<crate::candidate::judging::diagnose::Diagnosis>,
    /// The winding of the submission's triangles, decided from its answers.
    #[serde(default)]
    pub triangle_winding: Option<crate::candidate::judging::check::Winding>,
}

/// The verdict on one image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", content = "reason", rename_all = "snake_case")]
pub enum ImageVerdict {
    /// Indistinguishable from the reference up to Monte Carlo noise.
    Pass,
    /// Differs from the reference.
    Fail,
    /// Cannot be compared: missing, unreadable, wrong size, ... (the reason says which).
    Unusable(String),
}

/// Everything an [`ImageChecker`] found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageOutcome {
    /// Pass, fail, or unusable.
    pub verdict: ImageVerdict,
    /// The comparison's figures (free-form JSON object).
    pub metrics: serde_json::Value,
    /// A sentence saying what the difference looks like, when there is one.
    pub diagnosis: Option<String>,
    /// The heatmap written, if any.
    pub heatmap: Option<PathBuf>,
}

impl ImageOutcome {
    /// An unusable image with `reason`.
    pub fn unusable(reason: impl Into<String>) -> Self {
        ImageOutcome {
            verdict: ImageVerdict::Unusable(reason.into()),
            metrics: serde_json::Value::Object(Default::default()),
            diagnosis: None,
            heatmap: None,
        }
    }
}

/// The render as the 8-bit image of the course's encoding (what the course's code would have
/// written as a PNG).
pub(crate) fn encoded(image: &RenderedImage) -> crate::image_io::Rgb8Image {
    let data = match &image.film {
        Some(film) => film.clone(),
        None => image
            .data
            .iter()
            .flat_map(|p| {
                p.map(|x| crate::compare::encoding::Encoding::Course.encode(f64::from(x)))
            })
            .collect(),
    };
    crate::image_io::Rgb8Image {
        width: image.width,
        height: image.height,
        data,
    }
}

/// How a render group's result reads when the checker has no render to judge: the render
/// converted to the course's 8-bit encoding, written as a PNG into a private folder, and judged
/// as an uploaded image of that encoding would be. [`ImageChecker::check_render`]'s default.
pub fn judge_as_png(
    image: &RenderedImage,
    check_png: impl FnOnce(&Path) -> ImageOutcome,
) -> ImageOutcome {
    // Made and registered in one step (removed on Ctrl-C), as an upload's staging folder is.
    let made = crate::interrupt::create_temporary(
        || {
            tempfile::Builder::new()
                .prefix(".rtoracle-render-")
                .tempdir()
        },
        |t| t.path(),
    );
    let (dir, _cleanup) = match made {
        Ok(made) => made,
        Err(e) => {
            return ImageOutcome::unusable(format!(
                "the render could not be staged ({})",
                e.kind()
            ));
        }
    };
    let path = dir.path().join("render.png");
    let png = encoded(image);
    if let Err(e) = crate::image_io::write_png(&path, &png) {
        return ImageOutcome::unusable(format!("the render could not be staged ({e})"));
    }
    let mut outcome = check_png(&path);
    if let ImageVerdict::Unusable(why) = &mut outcome.verdict {
        *why = why.replace(&path.display().to_string(), "the render");
    }
    outcome
}
