//! Scoring: from what the checkers found and the rubric's groups to the checks and their points.

use std::path::Path;

use super::copies::CopyFinding;
use super::credit::{ClassTally, Credit, credit};
use super::inputs::{
    CodeOutcome, FailureKind, FailureSummary, GroupCounts, ImageOutcome, ImageVerdict,
};
use super::result::{
    CheckResult, CheckStatus, FAILURES_SHOWN, ImageResult, round2, simplicity,
    smallest_case_sentence, smallest_failure,
};
use super::rubric::Group;
use crate::oracle::vectors::ShapeKind;

pub(crate) fn code_check(group: &Group, outcome: &CodeOutcome) -> Vec<CheckResult> {
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
    let tally = if group.score_ambiguous {
        counts.tally.plus(counts.ambiguous_tally)
    } else {
        counts.tally
    };
    // A checker that does not say which vectors hit is scored as if every one did.
    let tally = if tally.is_empty() {
        ClassTally {
            hits: total,
            hits_right: passed,
            ..Default::default()
        }
    } else {
        tally
    };
    let mut earned = None;
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
        let c = credit(tally, group.all_or_nothing);
        // Full marks need every vector right, whatever the tally says.
        let fraction = if passed == total {
            1.0
        } else {
            c.fraction.min(1.0)
        };
        earned = Some(c);
        let message = code_message(group, outcome, &counts, (passed, total), &failures, &c);
        let status = if passed == total {
            CheckStatus::Passed
        } else {
            CheckStatus::Failed
        };
        (round2(group.points * fraction), status, message)
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
        tags,
        counts: Some(counts.clone()),
        credit: earned,
        failures,
        image: None,
        function: None,
    }];
    if counts.ambiguous > 0 && !group.score_ambiguous && outcome.fatal.is_none() {
        checks.push(ambiguous_check(group, outcome, &counts));
    }
    checks
}

/// What a code check says when its vectors ran: how many passed of how many, how the others
/// went wrong, the diagnosis, the triangles' winding, and last the smallest failing case.
fn code_message(
    group: &Group,
    outcome: &CodeOutcome,
    counts: &GroupCounts,
    (passed, total): (usize, usize),
    failures: &[FailureSummary],
    credit: &Credit,
) -> String {
    let shape = group.shape.expect("validated: code groups have a shape");
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
    if passed < total {
        message.push_str(&credit_sentence(credit));
    }
    if group.all_or_nothing && passed < total {
        message.push_str(" This group is all-or-nothing.");
    }
    if let Some(d) = outcome.diagnosis.iter().find(|d| d.shape == shape) {
        message.push_str(&format!(" Diagnosis: {}.", d.sentence()));
    }
    if let (ShapeKind::Triangle, Some(w)) = (shape, outcome.triangle_winding) {
        message.push_str(&format!(
            " Your triangles face {} (front_face is judged by that winding).",
            w.formula()
        ));
    }
    // Last, so the reports can show the vector's own message apart (it is the candidate's).
    if let Some(f) = smallest_failure(failures) {
        message.push_str(&smallest_case_sentence(f));
    }
    message
}

/// How the points of a code check that lost some were counted: the vectors that hit and those
/// that miss are scored apart, and the group earns the product of the two credits.
fn credit_sentence(c: &Credit) -> String {
    let t = &c.tally;
    let partly = t.hits_wrong_normal + t.hits_wrong_front_face + t.hits_t_only;
    let partly = if partly > 0 {
        format!(
            " and {partly} more at the right t with a wrong normal or front_face (partial credit)"
        )
    } else {
        String::new()
    };
    format!(
        " Points: of the {} vectors where the ray hits, {} right{partly} (hit credit {:.2}); of the {} where it misses, {} right (miss credit {:.2}); {:.2} x {:.2} = {:.1}% of the group's points.",
        t.hits,
        t.hits_right,
        c.hit_credit,
        t.misses,
        t.misses_right,
        c.miss_credit,
        c.hit_credit,
        c.miss_credit,
        100.0 * c.fraction
    )
}

/// The unscored check that reports a group's ambiguous vectors (where rounding decides).
fn ambiguous_check(group: &Group, outcome: &CodeOutcome, counts: &GroupCounts) -> CheckResult {
    let shape = group.shape.expect("validated: code groups have a shape");
    CheckResult {
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
        tags: vec!["code".to_string(), shape.name().to_string()],
        counts: None,
        credit: None,
        failures: outcome
            .failures
            .iter()
            .filter(|f| f.shape == shape && !f.definite && f.kind != FailureKind::NotRun)
            .take(FAILURES_SHOWN)
            .cloned()
            .collect(),
        image: None,
        function: None,
    }
}

pub(crate) fn heatmap_name(group: &Group) -> String {
    format!(
        "heatmap-{}.png",
        group
            .id
            .trim_start_matches("image.")
            .replace(['/', '\\'], "_")
    )
}

pub(crate) fn image_check(
    group: &Group,
    outcome: ImageOutcome,
    copy: Option<CopyFinding>,
    out_dir: &Path,
) -> CheckResult {
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
    let (score, status, message) = match (&copy, &outcome.verdict) {
        (Some(c), _) => (0.0, CheckStatus::Failed, c.sentence(&file)),
        (None, ImageVerdict::Pass) => (
            group.points,
            CheckStatus::Passed,
            format!("{file} matches the reference of {shown} up to sampling noise."),
        ),
        (None, ImageVerdict::Fail) => (
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
        (None, ImageVerdict::Unusable(why)) => (
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
        credit: None,
        failures: vec![],
        function: None,
        image: Some(ImageResult {
            file,
            scene,
            verdict: outcome.verdict,
            metrics: outcome.metrics,
            diagnosis: outcome.diagnosis,
            heatmap,
            copies: copy.into_iter().collect(),
        }),
    }
}
