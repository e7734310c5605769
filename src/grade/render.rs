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
//! A group with a `main_function` (the built-in week rubrics set one per `main.py` scene) is
//! rendered by that function of the submission's own `main.py`: its scene, camera, renderer and
//! film, at the group's size, spp and depth, and what is judged is the 8-bit film it saves. So a
//! mistake in the student's scene or film costs the group, as it would cost the student's own
//! image. When the function cannot render (it is missing, raises, saves no picture or one of
//! another size), the group falls back to the description, within the same time limit, and
//! says why.
//!
//! A film the program saves could be any picture the submission carries (the reference's own
//! render, a classmate's). So after a program's film, the submission's own classes render again,
//! from the grader's description of the scene, a band of about one row in
//! [`crate::candidate::render::CHECKED_BAND_PERIOD`] (which band follows the seed), and the film
//! earns its points only if those rows match the reference's same rows too: a correct picture
//! over classes that compute something else scores 0, and says so. Classes that cannot render
//! the rows make the group unusable, with the reason.
//!
//! What this module promises the reports: the outcome's `metrics` hold the comparison of the
//! render (as an uploaded image's would) plus `source` (`"render"`), `render` (`spp`,
//! `seconds`, `width`, `height`, `made_by` (`"main_function"` or `"description"`), the group's
//! `main_function` and, when it was not used, `main_function_not_used` with the reason; or
//! `not_run` with the reason; after a program's film, `class_rows` with the `rows` rendered
//! again by the classes, their `verdict`, its `diagnosis`, and whether the film alone matched,
//! `film_matches`) and `upload` (the uploaded
//! image's verdict, or why there is none); the check's message starts with what was judged
//! ("The render of your code (4 spp, 7.1 s) ...") and ends with a sentence on the upload.

use std::path::Path;
use std::time::Duration;

use serde_json::{Value, json};

use super::inputs::{ImageChecker, ImageOutcome, ImageVerdict};
use super::result::{CheckResult, CheckStatus};
use super::rubric::{Group, SceneSource};
use crate::candidate::render::{ClassRows, MadeBy, RenderJob, RenderOutcome, RenderedImage};
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
#[allow(clippy::type_complexity)]
pub(crate) fn jobs_of<'g>(
    groups: &[&'g Group],
) -> Vec<Result<(SceneDescription, u32, Duration, Option<&'g str>), String>> {
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
                g.main_function.as_deref(),
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
        .map(|(scene, spp, limit, program)| RenderJob {
            scene,
            spp: *spp,
            seed,
            time_limit: *limit,
            program: *program,
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
            let mut made = rendered_json(image);
            let outcome = match &image.class_rows {
                Some(rows) => tie_to_classes(outcome, image, rows, &scene, images, &mut made),
                None => outcome,
            };
            (outcome, made)
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

/// A program's film earns its points only when the submission's classes, rendering some of its
/// rows again from the scene's description ([`ClassRows`]), match the reference there too: a
/// `main.py` that saves a picture it carries, not one its code computes, fails here. Records
/// the rows' verdict in `made["class_rows"]`; a film that already fails is left as it is.
fn tie_to_classes(
    film: ImageOutcome,
    image: &RenderedImage,
    rows: &ClassRows,
    scene: &SceneSource,
    images: &dyn ImageChecker,
    made: &mut Value,
) -> ImageOutcome {
    let judged = match &rows.rendered {
        Ok(data) => images.check_rows(scene, image.spp, image.width, &rows.rows, data),
        Err(why) => ImageOutcome::unusable(why.clone()),
    };
    let what = format!(
        "{} of its {} rows rendered again from the grader's description of the scene with your classes",
        rows.rows.len(),
        image.height
    );
    made["class_rows"] = json!({
        "rows": rows.rows.len(),
        "verdict": &judged.verdict,
        "diagnosis": &judged.diagnosis,
        "film_matches": film.verdict == ImageVerdict::Pass,
    });
    if film.verdict != ImageVerdict::Pass {
        return film;
    }
    let tail = "an image earns its points only when it is what your code computes";
    match judged.verdict {
        ImageVerdict::Pass => film,
        ImageVerdict::Fail => ImageOutcome {
            verdict: ImageVerdict::Fail,
            diagnosis: Some(format!(
                "{what} differ from the reference{}: {tail}",
                judged
                    .diagnosis
                    .as_deref()
                    .map_or(String::new(), |d| format!(" ({})", d.trim_end_matches('.')))
            )),
            ..film
        },
        ImageVerdict::Unusable(why) => ImageOutcome {
            verdict: ImageVerdict::Unusable(format!(
                "your classes could not render the scene to tie the image to your code ({what}: {}); {tail}",
                why.trim_end_matches('.')
            )),
            ..film
        },
    }
}

fn rendered_json(image: &RenderedImage) -> Value {
    let mut made = json!({
        "spp": image.spp,
        "seconds": (image.seconds * 1000.0).round() / 1000.0,
        "width": image.width,
        "height": image.height,
    });
    match &image.made_by {
        MadeBy::Description => made["made_by"] = json!("description"),
        MadeBy::Program(program) => {
            made["made_by"] = json!("main_function");
            made["main_function"] = json!(program);
        }
        MadeBy::DescriptionInstead { program, why } => {
            made["made_by"] = json!("description");
            made["main_function"] = json!(program);
            made["main_function_not_used"] = json!(why);
        }
    }
    made
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
            message = format!("{to}{rest}");
            break;
        }
    }
    // A film that matches but is not what the classes compute: say that it matched.
    if render["class_rows"]["film_matches"] == true && check.status != CheckStatus::Passed {
        if let Some(d) = image.diagnosis.as_deref() {
            if message.starts_with(&format!("{what} differs")) {
                message = format!("{what} matches the reference, but it scores 0: {d}.");
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
