//! Grading one submission: the result model and the scoring (the reports are written by
//! [`report`](super::report), into a folder by [`write`](super::write)).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use super::inputs::{
    CodeChecker, CodeOutcome, FailureKind, FailureSummary, GroupCounts, ImageChecker, ImageOutcome,
    ImageVerdict,
};
use super::rubric::{Group, GroupKind, Rubric, SceneSource, Visibility};
use crate::output::OutputError;

/// How many failing vectors of a group the reports show.
pub const FAILURES_SHOWN: usize = 5;

/// How a check came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckStatus {
    /// Full marks.
    Passed,
    /// Some points lost.
    Failed,
    /// The check could not run on this submission (import error, missing or unusable image).
    Error,
    /// Reported but not scored (ambiguous vectors).
    Skipped,
}

impl CheckStatus {
    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            CheckStatus::Passed => "passed",
            CheckStatus::Failed => "failed",
            CheckStatus::Error => "error",
            CheckStatus::Skipped => "skipped",
        }
    }
}

/// One image's comparison, as the reports show it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageResult {
    /// The file in the submission.
    pub file: String,
    /// The scene it must show: a built-in's name or the rubric's scene file.
    pub scene: String,
    /// What the comparison said: `"verdict": "pass" | "fail" | "unusable"`, with `"reason"` for
    /// unusable input.
    #[serde(flatten)]
    pub verdict: ImageVerdict,
    /// The comparison's figures.
    pub metrics: serde_json::Value,
    /// What the difference looks like.
    pub diagnosis: Option<String>,
    /// The heatmap, relative to the report folder.
    pub heatmap: Option<String>,
}

/// One check: a line of the gradebook's detail and a test on Gradescope.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CheckResult {
    /// Starts with the group's id: `sphere.intersect`, `image.week04-quad`.
    pub id: String,
    /// The group's id.
    pub group: String,
    /// A name for people.
    pub name: String,
    /// Points earned.
    pub score: f64,
    /// Points available.
    pub max_score: f64,
    /// How it came out.
    pub status: CheckStatus,
    /// What happened, in plain words.
    pub message: String,
    /// Who sees it on Gradescope.
    pub visibility: Visibility,
    /// Tags (`code`, `sphere`, `image`, ...).
    pub tags: Vec<String>,
    /// The vector counts, for code checks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counts: Option<GroupCounts>,
    /// The first failing vectors, with reproductions.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<FailureSummary>,
    /// The comparison, for image checks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<ImageResult>,
}

/// What was checked and with what, so a grade can be reproduced.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Reproducibility {
    /// rtoracle's version.
    pub tool_version: String,
    /// SHA-256 of the rubric's TOML.
    pub rubric_sha256: String,
    /// SHA-256 of the vectors run.
    pub vectors_sha256: String,
    /// SHA-256 of each scene's golden (for a scene file: of the golden EXR file's bytes).
    pub goldens_sha256: BTreeMap<String, String>,
    /// SHA-256 of each scene file's bytes, by the rubric's `scene` value (built-in scenes are
    /// not listed: the tool version names them).
    pub scenes_sha256: BTreeMap<String, String>,
    /// SHA-256 of each file of the submission folder (top level).
    pub submission_sha256: BTreeMap<String, String>,
    /// The code checker.
    pub code_checker: String,
    /// The image checker.
    pub image_checker: String,
}

/// Everything known about the code run, beyond the checks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CodeRun {
    /// Why nothing could run, if so.
    pub fatal: Option<String>,
    /// The end of what the code wrote to stderr.
    pub stderr_tail: String,
    /// The sandbox's facts.
    pub sandbox: serde_json::Value,
    /// The known mistakes that explain the code's failures, per shape.
    pub diagnosis: Vec<crate::candidate::diagnose::Diagnosis>,
    /// The winding of the submission's triangles, when it has any that hit.
    pub triangle_winding: Option<crate::candidate::check::Winding>,
    /// Every definite vector it failed (not only the few each check shows), for a batch's
    /// summary; not written into report.json.
    #[serde(skip)]
    pub failed_vectors: Vec<(String, crate::oracle::vectors::ShapeKind)>,
}

/// The result model every report format is written from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GradeReport {
    /// The submission folder's name.
    pub submission: String,
    /// The rubric's name.
    pub rubric: String,
    /// Where the rubric came from (`built-in` or its file).
    pub rubric_source: String,
    /// Points earned (the sum of the checks', rounded to 1/100).
    pub score: f64,
    /// Points available.
    pub max_score: f64,
    /// Seconds spent grading.
    pub execution_time: f64,
    /// Every check, in rubric order.
    pub checks: Vec<CheckResult>,
    /// The code run.
    pub code: CodeRun,
    /// Versions and hashes.
    pub reproducibility: Reproducibility,
}

impl GradeReport {
    /// Points earned per group id, in rubric order.
    pub fn group_scores(&self) -> Vec<(String, f64, f64)> {
        let mut out: Vec<(String, f64, f64)> = Vec::new();
        for c in &self.checks {
            match out.iter_mut().find(|(g, _, _)| *g == c.group) {
                Some(entry) => {
                    entry.1 += c.score;
                    entry.2 += c.max_score;
                }
                None => out.push((c.group.clone(), c.score, c.max_score)),
            }
        }
        for e in &mut out {
            e.1 = round2(e.1);
        }
        out
    }
}

/// What stops grading itself (not the student's mistakes, which are in the report).
#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    /// The submission folder is missing.
    #[error("{0}: no such submission folder")]
    NoSubmission(PathBuf),
    /// A report could not be written.
    #[error("{path}: cannot write the report: {message}")]
    Output {
        /// The file or folder.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A report format name is unknown.
    #[error(
        "--format {0:?}: unknown format; use all or a comma list of json, gradescope, junit, markdown"
    )]
    Format(String),
}

impl From<OutputError> for GradeError {
    fn from(e: OutputError) -> Self {
        GradeError::Output {
            path: e.path,
            message: e.message,
        }
    }
}

/// The failure a student should look at first: a definite vector that was run and failed (never
/// one that was not run), an answer before a time-out, with the fewest edge-case tags, then the
/// shortest reproduction.
pub fn smallest_failure(failures: &[FailureSummary]) -> Option<&FailureSummary> {
    failures
        .iter()
        .filter(|f| f.definite && f.kind != FailureKind::NotRun)
        .min_by_key(|f| simplicity(f))
}

/// The sentence a code check's message ends with when a vector failed (the report writers that
/// show the case in their own way take it off again).
pub(crate) fn smallest_case_sentence(f: &FailureSummary) -> String {
    format!(" Smallest failing case, {}: {}.", f.id, f.message)
}

/// What makes a failure easy to show a student, smallest first: an answer (not a timeout),
/// definite, few edge-case tags, a short reproduction (small numbers), then the id.
fn simplicity(f: &FailureSummary) -> (bool, bool, usize, usize, String) {
    (
        matches!(f.kind, FailureKind::NotRun | FailureKind::Timeout),
        !f.definite,
        f.tags.len(),
        f.repro.len(),
        f.id.clone(),
    )
}

/// Rounds to 1/100 of a point.
pub fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

fn code_check(group: &Group, outcome: &CodeOutcome) -> Vec<CheckResult> {
    let shape = group.shape.expect("validated: code groups have a shape");
    let counts = outcome.per_group.get(&shape).cloned().unwrap_or_default();
    // The simplest failures of the group are the ones shown (and reproduced in the feedback).
    let mut failures: Vec<FailureSummary> = outcome
        .failures
        .iter()
        .filter(|f| f.shape == shape && (f.definite || group.score_ambiguous))
        // A vector that was not run did not fail: the counts say how many were not run.
        .filter(|f| f.kind != FailureKind::NotRun)
        .cloned()
        .collect();
    failures.sort_by_cached_key(simplicity);
    failures.truncate(FAILURES_SHOWN);
    let (passed, total) = if group.score_ambiguous {
        (
            counts.passed + counts.ambiguous_passed,
            counts.definite_total + counts.ambiguous,
        )
    } else {
        (counts.passed, counts.definite_total)
    };
    let (score, status, message) = if let Some(fatal) = &outcome.fatal {
        (
            0.0,
            CheckStatus::Error,
            format!("No {shape} vector could be run. {fatal}"),
        )
    } else if total == 0 {
        (
            group.points,
            CheckStatus::Passed,
            format!("There are no {shape} vectors to run."),
        )
    } else {
        let score = if passed == total {
            group.points
        } else if group.all_or_nothing {
            0.0
        } else {
            group.points * passed as f64 / total as f64
        };
        let mut parts = Vec::new();
        for (n, what) in [
            (counts.failed, "wrong"),
            (counts.errors, "raised an exception"),
            (counts.crashes, "crashed Python"),
            (counts.timeouts, "timed out"),
            (counts.not_run, "not run"),
        ] {
            if n > 0 {
                parts.push(format!("{n} {what}"));
            }
        }
        let mut message = format!("{passed} of {total} {shape} test vectors answered correctly");
        if !parts.is_empty() {
            message.push_str(&format!(" ({})", parts.join(", ")));
        }
        message.push('.');
        if group.all_or_nothing && passed < total {
            message.push_str(" This group is all-or-nothing.");
        }
        if let Some(d) = outcome.diagnosis.iter().find(|d| d.shape == shape) {
            message.push_str(&format!(" Diagnosis: {}.", d.sentence()));
        }
        if let (crate::oracle::vectors::ShapeKind::Triangle, Some(w)) =
            (shape, outcome.triangle_winding)
        {
            message.push_str(&format!(
                " Your triangles face {} (front_face is judged by that winding).",
                w.formula()
            ));
        }
        // Last, so the reports can show the vector's own message apart (it is the candidate's).
        if let Some(f) = smallest_failure(&failures) {
            message.push_str(&smallest_case_sentence(f));
        }
        let status = if passed == total {
            CheckStatus::Passed
        } else {
            CheckStatus::Failed
        };
        (round2(score), status, message)
    };
    let tags = vec!["code".to_string(), shape.name().to_string()];
    let mut checks = vec![CheckResult {
        id: format!("{}.intersect", group.id),
        group: group.id.clone(),
        name: group.name.clone(),
        score,
        max_score: group.points,
        status,
        message,
        visibility: group.visibility,
        tags: tags.clone(),
        counts: Some(counts.clone()),
        failures,
        image: None,
    }];
    if counts.ambiguous > 0 && !group.score_ambiguous && outcome.fatal.is_none() {
        checks.push(CheckResult {
            id: format!("{}.ambiguous", group.id),
            group: group.id.clone(),
            name: format!("{} (ambiguous vectors, not scored)", group.name),
            score: 0.0,
            max_score: 0.0,
            status: CheckStatus::Skipped,
            message: format!(
                "{} of {} ambiguous {shape} vectors (where rounding decides) gave the exact answer; they are reported, not scored.",
                counts.ambiguous_passed, counts.ambiguous
            ),
            visibility: group.visibility,
            tags,
            counts: None,
            failures: outcome
                .failures
                .iter()
                .filter(|f| f.shape == shape && !f.definite && f.kind != FailureKind::NotRun)
                .take(FAILURES_SHOWN)
                .cloned()
                .collect(),
            image: None,
        });
    }
    checks
}

fn heatmap_name(group: &Group) -> String {
    format!(
        "heatmap-{}.png",
        group
            .id
            .trim_start_matches("image.")
            .replace(['/', '\\'], "_")
    )
}

fn image_check(group: &Group, outcome: ImageOutcome, out_dir: &Path) -> CheckResult {
    let file = group.file.clone().expect("validated");
    let scene = group.scene.clone().expect("validated");
    // A scene file is named by its file name in messages: the folder is the rubric's business
    // (an autograder package keeps its scenes in `rtoracle-scenes/`, which students never see).
    let shown = if scene.ends_with(".toml") {
        Path::new(&scene)
            .file_name()
            .map_or_else(|| scene.clone(), |n| n.to_string_lossy().to_string())
    } else {
        scene.clone()
    };
    let (score, status, message) = match &outcome.verdict {
        ImageVerdict::Pass => (
            group.points,
            CheckStatus::Passed,
            format!("{file} matches the reference of {shown} up to sampling noise."),
        ),
        ImageVerdict::Fail => (
            0.0,
            CheckStatus::Failed,
            match outcome.diagnosis.as_deref().map(str::trim) {
                Some(d) if !d.is_empty() => {
                    let mut chars = d.chars();
                    let first = chars.next().map(|c| c.to_uppercase().collect::<String>());
                    let d = format!("{}{}", first.unwrap_or_default(), chars.as_str());
                    let end = if d.ends_with('.') { "" } else { "." };
                    format!("{file} differs from the reference of {shown}. {d}{end}")
                }
                _ => format!("{file} differs from the reference of {shown}."),
            },
        ),
        ImageVerdict::Unusable(why) => (
            0.0,
            CheckStatus::Error,
            if why.starts_with(file.as_str()) {
                format!("{why}. It scores 0.")
            } else {
                format!("{file} could not be compared and scores 0: {why}.")
            },
        ),
    };
    if let Some(p) = &outcome.heatmap {
        use std::os::unix::fs::PermissionsExt;
        let _ = std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o644));
    }
    let heatmap = outcome.heatmap.as_ref().map(|p| {
        p.strip_prefix(out_dir)
            .unwrap_or(p)
            .to_string_lossy()
            .to_string()
    });
    CheckResult {
        id: group.id.clone(),
        group: group.id.clone(),
        name: group.name.clone(),
        score,
        max_score: group.points,
        status,
        message,
        visibility: group.visibility,
        tags: vec!["image".to_string(), shown.clone()],
        counts: None,
        failures: vec![],
        image: Some(ImageResult {
            file,
            scene,
            verdict: outcome.verdict,
            metrics: outcome.metrics,
            diagnosis: outcome.diagnosis,
            heatmap,
        }),
    }
}

/// The size the image of `scene` must have, when `scene` is a built-in scene.
fn expected_size(scene: &SceneSource) -> Option<(usize, usize)> {
    let camera = match scene {
        SceneSource::Builtin(name) => crate::scene::builtin(name).ok()?.camera(None),
        SceneSource::File(f) => f.description.camera(None),
    };
    Some((camera.width, camera.height))
}

/// Reads the image of group `g` with care (see [`intake`](super::intake)) into a private copy
/// and hands the copy to `images`; whatever the checker says names the file relative to the
/// submission, never by the grader's paths.
fn check_image(
    submission: &Path,
    g: &Group,
    images: &dyn ImageChecker,
    out_dir: &Path,
) -> ImageOutcome {
    let rel = g.file.as_deref().expect("validated");
    let scene = g.scene_source().expect("validated");
    // Made and registered in one step: a batch makes these on many threads at once.
    let made = crate::interrupt::create_temporary(
        || {
            tempfile::Builder::new()
                .prefix(".rtoracle-image-")
                .tempdir()
        },
        |t| t.path(),
    );
    let (stage, _cleanup) = match made {
        Ok(made) => made,
        Err(e) => {
            return ImageOutcome::unusable(format!(
                "{rel} could not be staged for comparison ({})",
                e.kind()
            ));
        }
    };
    let staged =
        match super::intake::stage_image(submission, rel, expected_size(&scene), stage.path()) {
            Ok(p) => p,
            Err(why) => return ImageOutcome::unusable(why),
        };
    let mut outcome = images.check_scene(&staged, &scene, &out_dir.join(heatmap_name(g)));
    if let ImageVerdict::Unusable(why) = &mut outcome.verdict {
        let shown = format!("{}: ", staged.display());
        *why = why.replace(&shown, &format!("{rel}: "));
        *why = why.replace(&staged.display().to_string(), rel);
    }
    outcome
}

/// Grades the submission in folder `submission`: runs the code groups through `code` and the
/// image groups through `images` (heatmaps go into `out_dir`, which must exist), and scores them
/// with `rubric`. Whatever the student's code does, a report comes back; the only errors are a
/// missing submission folder.
pub fn grade(
    submission: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    out_dir: &Path,
) -> Result<GradeReport, GradeError> {
    let start = Instant::now();
    if !submission.is_dir() {
        return Err(GradeError::NoSubmission(submission.to_path_buf()));
    }
    let shapes = rubric.code_shapes();
    let image_groups: Vec<&Group> = rubric
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Image)
        .collect();
    let (outcome, image_outcomes) = rayon::join(
        || {
            if shapes.is_empty() {
                CodeOutcome::default()
            } else {
                code.check(submission, &shapes)
            }
        },
        || {
            image_groups
                .iter()
                .map(|g| check_image(submission, g, images, out_dir))
                .collect::<Vec<_>>()
        },
    );
    let mut image_outcomes = image_outcomes.into_iter();
    let mut checks = Vec::new();
    for g in &rubric.groups {
        match g.kind {
            GroupKind::Code => checks.extend(code_check(g, &outcome)),
            GroupKind::Image => checks.push(image_check(
                g,
                image_outcomes.next().expect("one per image group"),
                out_dir,
            )),
        }
    }
    let goldens_sha256 = image_groups
        .iter()
        .filter_map(|g| g.scene_source())
        .map(|s| (s.label().to_string(), images.scene_golden_sha256(&s)))
        .collect();
    let scenes_sha256 = image_groups
        .iter()
        .filter_map(|g| g.scene_file.as_ref())
        .map(|f| (f.label.clone(), f.sha256.clone()))
        .collect();
    let score = round2(checks.iter().map(|c| c.score).sum());
    let submission_name = submission
        .canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
        .unwrap_or_else(|| submission.display().to_string());
    Ok(GradeReport {
        submission: submission_name,
        rubric: rubric.name.clone(),
        rubric_source: rubric.source.clone(),
        score,
        max_score: rubric.max_score(),
        execution_time: 0.0,
        checks,
        code: CodeRun {
            fatal: outcome.fatal.clone(),
            stderr_tail: outcome.stderr_tail.clone(),
            sandbox: outcome.sandbox.clone(),
            diagnosis: outcome.diagnosis.clone(),
            triangle_winding: outcome.triangle_winding,
            failed_vectors: outcome
                .failures
                .iter()
                .filter(|f| f.definite && f.kind != FailureKind::NotRun)
                .map(|f| (f.id.clone(), f.shape))
                .collect(),
        },
        reproducibility: Reproducibility {
            tool_version: env!("CARGO_PKG_VERSION").to_string(),
            rubric_sha256: rubric.sha256.clone(),
            vectors_sha256: if shapes.is_empty() {
                String::new()
            } else {
                code.vectors_sha256()
            },
            goldens_sha256,
            scenes_sha256,
            submission_sha256: super::intake::submission_hashes(submission),
            code_checker: code.describe(),
            image_checker: images.describe(),
        },
    })
    .map(|mut r| {
        r.execution_time = (start.elapsed().as_secs_f64() * 1000.0).round() / 1000.0;
        r
    })
}

#[cfg(test)]
pub(crate) mod fakes {
    //! Test doubles of the two interfaces.
    use super::*;
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
}

#[cfg(test)]
mod tests {
    use super::fakes::*;
    use super::*;
    use crate::grade::rubric::sha256_hex;

    fn run(rubric: &Rubric, code: &FakeCode, images: &FakeImage) -> GradeReport {
        let sub = tempfile::tempdir().unwrap();
        std::fs::write(sub.path().join("RT_object.py"), "x = 1\n").unwrap();
        fake_images(sub.path());
        let out = tempfile::tempdir().unwrap();
        grade(sub.path(), rubric, code, images, out.path()).unwrap()
    }

    fn score(r: &GradeReport, id: &str) -> f64 {
        r.checks.iter().find(|c| c.id == id).unwrap().score
    }

    #[test]
    fn points_are_proportional_to_definite_vectors_passed_and_ids_start_with_the_group() {
        let r = run(
            &Rubric::week04(),
            &FakeCode::new(counts(4, 3), counts(3, 1)),
            &all_pass(),
        );
        assert_eq!(score(&r, "sphere.intersect"), 22.5); // 30 * 3/4
        assert_eq!(score(&r, "quad.intersect"), 10.0); // 30 * 1/3
        assert_eq!(r.score, 22.5 + 10.0 + 40.0);
        assert_eq!(r.max_score, 100.0);
        for c in &r.checks {
            assert!(c.id.starts_with(&c.group), "{}", c.id);
        }
        assert_eq!(
            r.reproducibility.goldens_sha256["week04-quad"],
            "golden-week04-quad"
        );
        assert_eq!(
            r.reproducibility.submission_sha256["RT_object.py"],
            sha256_hex(b"x = 1\n")
        );
    }

    #[test]
    fn errors_timeouts_and_not_run_never_earn_points() {
        let sphere = GroupCounts {
            definite_total: 4,
            passed: 1,
            errors: 1,
            timeouts: 1,
            not_run: 1,
            ..Default::default()
        };
        let r = run(
            &Rubric::week04(),
            &FakeCode::new(sphere, counts(2, 2)),
            &all_pass(),
        );
        assert_eq!(score(&r, "sphere.intersect"), 7.5);
        let c = &r.checks[0];
        assert_eq!(c.status, CheckStatus::Failed);
        assert!(c.message.contains("1 of 4 sphere test vectors answered correctly (1 raised an exception, 1 timed out, 1 not run)."), "{}", c.message);
    }

    fn failure(id: &str, kind: FailureKind) -> FailureSummary {
        FailureSummary {
            id: id.into(),
            shape: crate::oracle::vectors::ShapeKind::Sphere,
            tags: vec![],
            kind,
            definite: true,
            expected: serde_json::Value::Null,
            actual: serde_json::Value::Null,
            message: format!("{kind:?}"),
            repro: String::new(),
        }
    }

    #[test]
    fn the_smallest_failing_case_was_run_and_crashes_are_not_time_outs() {
        let not_run = failure("a", FailureKind::NotRun);
        let timeout = failure("b", FailureKind::Timeout);
        let pair = [not_run.clone(), timeout];
        assert_eq!(smallest_failure(&pair).unwrap().id, "b");
        assert!(smallest_failure(&[not_run]).is_none());
        let sphere = GroupCounts {
            definite_total: 3,
            passed: 1,
            crashes: 1,
            not_run: 1,
            ..Default::default()
        };
        let r = run(
            &Rubric::week04(),
            &FakeCode::new(sphere, counts(1, 1)),
            &all_pass(),
        );
        assert!(
            r.checks[0].message.contains(
                "1 of 3 sphere test vectors answered correctly (1 crashed Python, 1 not run)."
            ),
            "{}",
            r.checks[0].message
        );
    }

    #[test]
    fn all_or_nothing_ambiguous_scoring_and_visibility_follow_the_rubric() {
        let text = crate::grade::rubric::WEEK04_RUBRIC
            .replacen(
                "points = 30\nvisibility = \"visible\"",
                "points = 30\nall_or_nothing = true\nvisibility = \"after_due_date\"",
                1,
            )
            .replacen(
                "shape = \"quad\"\npoints = 30",
                "shape = \"quad\"\npoints = 30\nscore_ambiguous = true",
                1,
            );
        let rubric = Rubric::from_toml(&text, "t.toml").unwrap();
        let mut quad = counts(2, 2);
        quad.ambiguous = 2;
        quad.ambiguous_passed = 1;
        let mut sphere = counts(4, 3);
        sphere.ambiguous = 5;
        let r = run(&rubric, &FakeCode::new(sphere, quad), &all_pass());
        assert_eq!(score(&r, "sphere.intersect"), 0.0); // 3 of 4, all-or-nothing
        assert_eq!(r.checks[0].visibility, Visibility::AfterDueDate);
        // Ambiguous sphere vectors: reported as a separate, unscored check.
        let amb = r
            .checks
            .iter()
            .find(|c| c.id == "sphere.ambiguous")
            .unwrap();
        assert_eq!(
            (amb.score, amb.max_score, amb.status),
            (0.0, 0.0, CheckStatus::Skipped)
        );
        // Quad scores ambiguous vectors: (2 + 1) of (2 + 2).
        assert_eq!(score(&r, "quad.intersect"), 22.5);
        assert!(r.checks.iter().all(|c| c.id != "quad.ambiguous"));
    }

    #[test]
    fn an_import_error_zeroes_the_code_groups_only_and_unusable_images_score_zero() {
        let mut code = FakeCode::new(counts(2, 2), counts(2, 2));
        code.fatal = Some("SyntaxError: expected ':'".into());
        let images = FakeImage(
            [(
                "week04-quad".to_string(),
                ImageVerdict::Unusable("week04_quad.png is missing".into()),
            )]
            .into(),
        );
        let r = run(&Rubric::week04(), &code, &images);
        assert_eq!(score(&r, "sphere.intersect"), 0.0);
        assert_eq!(score(&r, "quad.intersect"), 0.0);
        assert_eq!(score(&r, "image.week04-sphere"), 20.0);
        assert_eq!(score(&r, "image.week04-quad"), 0.0);
        assert_eq!(r.score, 20.0);
        assert!(r.checks[0].message.contains("SyntaxError"));
        let quad_image = &r.checks[3];
        assert_eq!(quad_image.status, CheckStatus::Error);
        assert!(
            quad_image.message.contains("week04_quad.png is missing"),
            "{}",
            quad_image.message
        );
    }

    #[test]
    fn a_missing_folder_is_the_only_error() {
        let out = tempfile::tempdir().unwrap();
        let e = grade(
            Path::new("/no/such/dir"),
            &Rubric::week04(),
            &FakeCode::new(counts(1, 1), counts(1, 1)),
            &all_pass(),
            out.path(),
        )
        .unwrap_err();
        assert_eq!(e.to_string(), "/no/such/dir: no such submission folder");
    }
}
