//! Image groups rendered from the submission's own code (`source = "render"`, the default).
//!
//! For each such group the grader asks the submission, through the protocol's `render` request
//! ([`crate::candidate::render`]), to render the group's scene at the group's `spp` within its
//! `render_seconds`, in the sandbox, with one interpreter per submission for all its groups
//! ([`course_render`]). The render is judged by the image checker against the golden at the spp
//! it was rendered with ([`ImageChecker::check_render`]); the points come from that judgement.
//! An uploaded image of the group is still read and judged, and reported beside it, but earns
//! nothing. A render that raises, hangs, declines, returns NaN or the wrong size scores 0 for
//! its group with the reason, and the rest of the grade stands.
//!
//! What this module promises the reports: the outcome's `metrics` hold the comparison of the
//! render (as an uploaded image's would) plus `source` (`"render"`), `render` (`spp`,
//! `seconds`, `width`, `height`, or `not_run` with the reason) and `upload` (the uploaded
//! image's verdict, or why there is none); the check's message starts with what was judged
//! ("The render of your code (4 spp, 7.1 s) ...") and ends with a sentence on the upload.

use std::path::Path;
use std::time::Duration;

use serde_json::{Value, json};

use super::inputs::{ImageChecker, ImageOutcome};
use super::result::CheckResult;
use super::rubric::{Group, SceneSource};
use crate::candidate::render::{RenderJob, RenderOutcome, RenderedImage};
use crate::scene::SceneDescription;

/// The scene description an image group renders: the built-in's or the rubric's scene file.
pub(crate) fn scene_description(scene: &SceneSource) -> Result<SceneDescription, String> {
    match scene {
        SceneSource::Builtin(name) => crate::scene::builtin(name).map_err(|e| e.to_string()),
        SceneSource::File(f) => Ok(f.description.clone()),
    }
}

/// The render jobs of the rubric's render groups, in `groups`' order: `Err` for a group whose
/// scene cannot be had (it is not rendered).
pub(crate) fn jobs_of(groups: &[&Group]) -> Vec<Result<(SceneDescription, u32, Duration), String>> {
    groups
        .iter()
        .map(|g| {
            let scene = g.scene_source().ok_or("the group has no scene")?;
            let d = scene_description(&scene)?;
            // A scene of the course's jittered sampling is sent as it is at the render's spp.
            let d = crate::golden::at_spp(&d, g.render_spp()).unwrap_or(d);
            Ok((
                d,
                g.render_spp(),
                Duration::from_secs_f64(g.render_seconds()),
            ))
        })
        .collect()
}

/// Renders the render groups of one submission through `render` (the code checker's), one
/// outcome per group, timed.
pub(crate) fn render_groups(
    groups: &[&Group],
    seed: u64,
    render: impl FnOnce(&[RenderJob]) -> Vec<RenderOutcome>,
) -> Vec<RenderOutcome> {
    let wanted = jobs_of(groups);
    let ok: Vec<RenderJob> = wanted
        .iter()
        .filter_map(|w| w.as_ref().ok())
        .map(|(scene, spp, limit)| RenderJob {
            scene,
            spp: *spp,
            seed,
            time_limit: *limit,
        })
        .collect();
    let mut done = if ok.is_empty() {
        Vec::new()
    } else {
        render(&ok)
    }
    .into_iter();
    wanted
        .iter()
        .map(|w| match w {
            Ok(_) => done
                .next()
                .unwrap_or_else(|| RenderOutcome::Invalid("the checker rendered nothing".into())),
            Err(why) => RenderOutcome::Declined(why.clone()),
        })
        .collect()
}

/// The outcome of a render group: the render's judgement (or why there is none), with the
/// upload's judgement kept in its metrics.
pub(crate) fn judge(
    g: &Group,
    render: RenderOutcome,
    upload: ImageOutcome,
    images: &dyn ImageChecker,
    heatmap_out: &Path,
) -> ImageOutcome {
    let file = g.file.as_deref().unwrap_or("the image");
    let upload_json = json!({
        "file": file,
        "verdict": &upload.verdict,
        "diagnosis": &upload.diagnosis,
    });
    let (mut outcome, render_json) = match &render {
        RenderOutcome::Rendered(image) => {
            let scene = g.scene_source().expect("validated");
            let outcome = images.check_render(image, &scene, heatmap_out);
            (outcome, rendered_json(image))
        }
        failed => {
            let why = failed.reason().unwrap_or_default();
            (
                ImageOutcome::unusable(why.clone()),
                json!({"spp": g.render_spp(), "not_run": why}),
            )
        }
    };
    let mut metrics = match std::mem::take(&mut outcome.metrics) {
        Value::Object(map) => map,
        _ => serde_json::Map::new(),
    };
    metrics.insert("source".into(), json!("render"));
    metrics.insert("render".into(), render_json);
    metrics.insert("upload".into(), upload_json);
    outcome.metrics = Value::Object(metrics);
    outcome
}

fn rendered_json(image: &RenderedImage) -> Value {
    json!({
        "spp": image.spp,
        "seconds": (image.seconds * 1000.0).round() / 1000.0,
        "width": image.width,
        "height": image.height,
    })
}

/// Rewrites the message of a render group's check to say what was judged (the render of the
/// submission's code, its spp and time) and what became of the upload.
pub(crate) fn explain(check: &mut CheckResult, g: &Group) {
    let file = g.file.clone().unwrap_or_default();
    let Some(image) = &check.image else {
        return;
    };
    let render = &image.metrics["render"];
    let what = match (render["spp"].as_u64(), render["seconds"].as_f64()) {
        (Some(spp), Some(s)) => format!("The render of your code ({spp} spp, {s:.1} s)"),
        _ => "The render of your code".to_string(),
    };
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
            message = format!("{to}{rest}");
            break;
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
                format!(" No {file} was uploaded (none is needed: the grader renders your code).")
            }
            Some(why) => format!(
                " Your uploaded {file} could not be compared ({}); uploads earn no points.",
                why.trim_end_matches('.')
            ),
            None => String::new(),
        },
    };
    message.push_str(&said);
    check.message = message;
}
