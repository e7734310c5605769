//! Scoring: from what the checkers found and the rubric's groups to the checks, their points and
//! their messages (a render group's says what was judged and what became of the upload).

pub mod weekly;

use crate::candidate::judging::check::FailureKind;
use std::path::Path;

use serde_json::Value;

use crate::escape::Untrusted;
use crate::grade::checkers::copies::CopyFinding;
use crate::grade::checkers::rendered::scene_description;
use crate::grade::checkers::{
    CodeOutcome, FailureSummary, GroupCounts, ImageOutcome, ImageVerdict,
};
use crate::grade::result::{
    CheckResult, CheckStatus, FAILURES_SHOWN, ImageResult, round2, simplicity,
    smallest_case_sentence, smallest_failure,
};
use crate::grade::rubric::Group;
use crate::grade::rubric::credit::{ClassTally, Credit, credit};
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
            crate::escape::Untrusted::from(format!("No {shape} vector could be run. "))
                .join("", &fatal.as_str().into()),
        )
    } else if total == 0 {
        (
            group.points,
            CheckStatus::Passed,
            crate::escape::Untrusted::from(format!("There are no {shape} vectors to run.")),
        )
    } else {
        let c = credit(tally, group.all_or_nothing);
        // Full marks need every vector right, whatever the tally says, and nothing `check`
        // fails: a watertight group cracked, a vector not scored left unanswered.
        let unanswered = counts.unscored_timeouts + counts.unscored_crashes;
        let all_right = passed == total && counts.watertight_cracked == 0 && unanswered == 0;
        let fraction = if all_right { 1.0 } else { c.fraction.min(1.0) };
        earned = Some(c);
        let message = code_message(group, outcome, &counts, (passed, total), &failures, &c);
        let status = if all_right {
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
) -> crate::escape::Untrusted {
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
    message.push_str(&check_fails_sentence(counts));
    let all_right = passed == total
        && counts.watertight_cracked + counts.unscored_timeouts + counts.unscored_crashes == 0;
    if !all_right {
        message.push_str(&credit_sentence(credit, counts.watertight));
    }
    if group.all_or_nothing && !all_right {
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
    let mut message = crate::escape::Untrusted::from(message);
    if let Some(f) = smallest_failure(failures) {
        message.push(&smallest_case_sentence(f));
    }
    message
}

/// What `rtoracle check` fails besides a definite vector, in its words: the watertight groups
/// judged and cracked, the vectors not scored that the code left unanswered (empty when there
/// is nothing to say).
fn check_fails_sentence(counts: &GroupCounts) -> String {
    let mut s = String::new();
    if counts.watertight_cracked > 0 {
        s.push_str(&format!(
            " Watertight groups: {}; each counts as a vector where the ray hits.",
            crate::candidate::judging::watertight::groups_summary(
                counts.watertight,
                counts.watertight_cracked
            )
        ));
    }
    let (hung, died) = (counts.unscored_timeouts, counts.unscored_crashes);
    if hung + died > 0 {
        let mut what = Vec::new();
        if hung > 0 {
            what.push(format!("hung on {hung}"));
        }
        if died > 0 {
            what.push(format!("crashed Python on {died}"));
        }
        s.push_str(&format!(
            " Your code {} of the vectors that are not scored, but code must answer every vector: each counts as a vector answered wrong.",
            what.join(" and ")
        ));
    }
    s
}

/// How the points of a code check that lost some were counted: the vectors that hit and those
/// that miss are scored apart, and the group earns the product of the two credits (`watertight`
/// of the vectors that hit are watertight groups).
fn credit_sentence(c: &Credit, watertight: usize) -> String {
    let t = &c.tally;
    let partly = t.hits_wrong_normal + t.hits_wrong_front_face + t.hits_t_only;
    let partly = if partly > 0 {
        format!(
            " and {partly} more at the right t with a wrong normal or front_face (partial credit)"
        )
    } else {
        String::new()
    };
    let groups = if watertight > 0 {
        format!(" ({watertight} of them watertight groups)")
    } else {
        String::new()
    };
    format!(
        " Points: of the {} vectors where the ray hits{groups}, {} right{partly} (hit credit {:.2}); of the {} where it misses, {} right (miss credit {:.2}); {:.2} x {:.2} = {:.1}% of the group's points.",
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
        )
        .into(),
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

/// How the intake and the image checker say that an image is not in the submission.
pub(crate) const MISSING: &str = "is missing from the submission";

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
            if why.starts_with(file.as_str()) && why.ends_with(MISSING) {
                format!(
                    "{why}: it costs this group's {} points, since this rubric judges the uploaded image (upload it).",
                    round2(group.points)
                )
            } else if why.starts_with(file.as_str()) {
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
        message: message.into(),
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

/// The course's jittered renders take floor(sqrt(spp))^2 samples and its film divides by spp;
/// a film made by the submission that is brighter by exactly spp / floor(sqrt(spp))^2 divides by
/// the samples taken. Says so, when the comparison's best explanation is that uniform scale.
fn film_hint(g: &Group, render: &Value, metrics: &Value) -> Option<String> {
    if render["made_by"].as_str() != Some("main_function") {
        return None;
    }
    let spp = u32::try_from(render["spp"].as_u64()?).ok()?;
    let scene = scene_description(&g.scene_source()?).ok()?;
    if scene.render.sampling != crate::scene::PixelSampling::CourseJittered {
        return None;
    }
    let taken = {
        let m = (f64::from(spp).sqrt().floor()) as u32;
        m * m
    };
    // "scale:1.25", or per channel "scale:1.25,1.25,1.33" (the clamp and the sky's blue).
    let scales: Vec<f64> = metrics["diagnosis"]["best"]
        .as_str()?
        .strip_prefix("scale:")?
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    let expected = f64::from(spp) / f64::from(taken);
    let mut sorted = scales.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let near = (median - expected).abs() <= 0.03 * expected
        && scales
            .iter()
            .all(|k| (k - expected).abs() <= 0.08 * expected);
    (taken != spp && near).then(|| {
        format!(
            " A film brighter by {spp}/{taken} is what dividing by the {taken} samples render_jittered takes gives, instead of by samples_per_pixel ({spp}) as the course's write_to_film does."
        )
    })
}

/// What the message says was judged: the render, by which function or from what, at what spp.
fn judged(render: &Value) -> String {
    let timing = match (render["spp"].as_u64(), render["seconds"].as_f64()) {
        (Some(spp), Some(s)) => format!(" ({spp} spp, {s:.1} s)"),
        _ => String::new(),
    };
    match (render["made_by"].as_str(), render["main_function"].as_str()) {
        (Some("main_function"), Some(f)) => {
            format!("The image your main.py's {f}() made{timing}")
        }
        _ => format!("The render of your code{timing}"),
    }
}

/// Rewrites the message of a render group's check to say what was judged (the render of the
/// submission's code, its spp and time) and what became of the upload.
pub(crate) fn explain(check: &mut CheckResult, g: &Group) {
    let file = g.file.clone().unwrap_or_default();
    let Some(image) = &check.image else {
        return;
    };
    let render = &image.metrics["render"];
    let what = judged(render);
    let mut message = check.message.clone();
    for (from, to) in [
        (
            format!("{file} could not be compared and scores 0: "),
            format!("{what} could not be judged and scores 0: "),
        ),
        (format!("{file} matches"), format!("{what} matches")),
        (format!("{file} differs"), format!("{what} differs")),
    ] {
        if let Some(rest) = message.strip_prefix(&from) {
            message = Untrusted::from(to).join("", &rest);
            break;
        }
    }
    // A render that matches but whose variant does not: say that it matched.
    if render["variant"]["scene_matches"] == true && check.status != CheckStatus::Passed {
        if let Some(d) = image.diagnosis.as_deref() {
            if message.starts_with(&format!("{what} differs")) {
                message = format!("{what} matches the reference, but it scores 0: {d}.").into();
            }
        }
    }
    let upload = &image.metrics["upload"];
    let said = match upload["verdict"]["verdict"].as_str() {
        Some("pass") => format!(
            " Your uploaded {file} matches the reference (uploads earn no points: the grader renders your code)."
        ),
        Some("fail") => format!(
            " Your uploaded {file} differs from the reference (uploads earn no points: the grader renders your code)."
        ),
        _ => match upload["verdict"]["reason"].as_str() {
            Some(why) if why.contains("missing") => {
                format!(
                    " {file} is missing from the submission; it costs nothing: the grader renders your code."
                )
            }
            Some(why) => format!(
                " Your uploaded {file} could not be compared ({}); uploads earn no points.",
                why.trim_end_matches('.')
            ),
            None => String::new(),
        },
    };
    message.push_str(&said);
    if let Some(hint) = film_hint(g, render, &image.metrics) {
        message.push_str(&hint);
    }
    if let (Some(f), Some(why)) = (
        render["main_function"].as_str(),
        render["main_function_not_used"].as_str(),
    ) {
        message.push_str(&format!(
            " Your main.py's {f}() was not used ({}), so the grader rendered its own description of the scene with your classes.",
            why.trim_end_matches('.')
        ));
    }
    check.message = message;
}
