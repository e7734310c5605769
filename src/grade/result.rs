//! The result model every report format is written from: a [`GradeReport`] of
//! [`CheckResult`]s, what was run and with what ([`CodeRun`], [`Reproducibility`]), and what stops
//! grading itself ([`GradeError`]).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::checkers::copies::{CopyFinding, Fingerprint};
use super::checkers::{FailureSummary, GroupCounts, ImageVerdict};
use super::rubric::Visibility;
use crate::candidate::judging::check::FailureKind;
use crate::escape::Untrusted;
use crate::output::OutputError;

/// How many failing vectors of a group the reports show.
pub const FAILURES_SHOWN: usize = 5;

/// How a check came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// What the copy checks found: the course's image, the reference's render, or (in a batch)
    /// another submission's image sharing its noise.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub copies: Vec<CopyFinding>,
}

/// One check: a line of the gradebook's detail and a test on Gradescope.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// What happened, in plain words: the harness's, with what the submission said or named
    /// in it (a render's exception, its code's error), so all of it is untrusted and written
    /// out only escaped.
    pub message: Untrusted,
    /// Who sees it on Gradescope.
    pub visibility: Visibility,
    /// Tags (`code`, `sphere`, `image`, ...).
    pub tags: Vec<String>,
    /// The vector counts, for code checks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counts: Option<GroupCounts>,
    /// How a code check's points were counted: the rule, its components and the share earned.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "super::rubric::credit::read_credit"
    )]
    pub credit: Option<super::rubric::credit::Credit>,
    /// The first failing vectors, with reproductions.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failures: Vec<FailureSummary>,
    /// The comparison, for image checks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub image: Option<ImageResult>,
    /// For function checks that did not pass (and the unscored check's first failure): the
    /// function's result, with its smallest failing case and its reproduction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub function: Option<crate::weekly::run::FunctionResult>,
}

/// What was checked and with what, so a grade can be reproduced.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CodeRun {
    /// Why nothing could run, if so (Python's words).
    pub fatal: Option<Untrusted>,
    /// The end of what the code wrote to stderr.
    pub stderr_tail: Untrusted,
    /// The sandbox's facts.
    pub sandbox: serde_json::Value,
    /// The known mistakes that explain the code's failures, per shape.
    pub diagnosis: Vec<crate::candidate::judging::diagnose::Diagnosis>,
    /// The winding of the submission's triangles, when it has any that hit.
    pub triangle_winding: Option<crate::candidate::judging::check::Winding>,
    /// Why the week's function checks could not run at all, when they could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub functions_fatal: Option<Untrusted>,
    /// The last lines the code wrote to stderr during the function checks (truncated).
    #[serde(default, skip_serializing_if = "Untrusted::is_empty")]
    pub functions_stderr_tail: Untrusted,
    /// Answers that broke the protocol (to function, render and intersection requests: a
    /// malformed answer, a key its answer does not have, a wrong number of samples). The
    /// bundled adapter never makes one, so a count above 0 means a broken or hijacked adapter:
    /// the gradebook's status says to look at the submission.
    pub protocol_errors: usize,
    /// Every definite vector it failed (not only the few each check shows), for a batch's
    /// summary; not written into report.json.
    #[serde(skip)]
    pub failed_vectors: Vec<(String, crate::oracle::vectors::ShapeKind)>,
}

/// The result model every report format is written from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GradeReport {
    /// The submission folder's name (the submission's).
    pub submission: Untrusted,
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
    /// The uploaded images' fingerprints by image group id, for a batch's comparison of
    /// submissions (not written into report.json; recognised copies are left out).
    #[serde(skip)]
    pub fingerprints: Vec<(String, Arc<Fingerprint>)>,
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
pub(crate) fn smallest_case_sentence(f: &FailureSummary) -> Untrusted {
    let mut s = Untrusted::from(format!(" Smallest failing case, {}: ", f.id));
    s.push(&f.message);
    s.push_str(".");
    s
}

/// What makes a failure easy to show a student, smallest first: an answer (not a timeout),
/// definite, few edge-case tags, a short reproduction (small numbers), then the id.
pub(crate) fn simplicity(f: &FailureSummary) -> (bool, bool, usize, usize, String) {
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
