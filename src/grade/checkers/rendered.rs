//! Image groups rendered from the submission's own code (`source = "render"`, the default).
//!
//! For each such group the grader asks the submission, through the protocol's `render` request
//! ([`crate::candidate::process::render_request`]), to render the group's scene at the group's `spp` within its
//! `render_seconds`, in the sandbox, with one interpreter per submission for all its groups
//! (`course_render`). The render is judged by the image checker against the golden at the spp
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
//! A film, a render or a picture could be one the submission carries (the reference's own
//! render made at home, a classmate's), answered by a `main.py` that saves it or by a module
//! that replaces the adapter's renderer. So every render group is also rendered as a *variant*
//! (`variant_of`): the same scene from a camera the grader moves (`look_from` and `look_at`
//! moved by 3 to 6% and 1 to 3% of their distance, the field of view scaled by 3 to 6% either
//! way, in directions and amounts drawn from `variant_key`, which follows the rubric's secret
//! seed and the group), at half the width. The submission renders it the same way as the scene
//! (its `main.py` function moves its camera in `init_camera`), the reference renders the same
//! variant on the spot ([`ImageChecker::check_variant`]), and the group earns its points only
//! when both the scene and its variant match. A picture made before the grade cannot show a
//! camera drawn during it.
//!
//! What this module promises the reports: the outcome's `metrics` hold the comparison of the
//! render (as an uploaded image's would) plus `source` (`"render"`), `render` (`spp`,
//! `seconds`, `width`, `height`, `made_by` (`"main_function"` or `"description"`), the group's
//! `main_function` and, when it was not used, `main_function_not_used` with the reason; or
//! `not_run` with the reason; `variant` with the camera's `move`, the variant's `width` and
//! `height`, its `seconds`, its `verdict`, its `diagnosis` and whether the scene alone matched,
//! `scene_matches`) and `upload` (the uploaded image's verdict, or why there is none); the
//! check's message starts with what was judged ("The render of your code (4 spp, 7.1 s) ...")
//! and ends with a sentence on the upload.

use std::path::Path;
use std::time::Duration;

use serde_json::{Value, json};

use crate::candidate::process::render_request::{
    CameraMove, MadeBy, RenderJob, RenderOutcome, RenderedImage,
};
use crate::grade::checkers::{ImageChecker, ImageOutcome, ImageVerdict};
use crate::grade::rubric::{Group, SceneSource};
use crate::scene::SceneDescription;

/// The scene description an image group renders: the built-in's or the rubric's scene file.
pub(crate) fn scene_description(scene: &SceneSource) -> Result<SceneDescription, String> {
    match scene {
        SceneSource::Builtin(name) => crate::scene::builtin(name).map_err(|e| e.to_string()),
        SceneSource::File(f) => Ok(f.description.clone()),
    }
}

/// The key a group's variant is drawn from: derived from the rubric's secret seed for the
/// purpose `variant/<group id>` by the keyed one-way function of [`crate::secret`], so neither
/// a request nor a report tells it.
pub(crate) fn variant_key(secret: u64, group: &str) -> u64 {
    crate::secret::derive(secret, &format!("variant/{group}"))
}

fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The variant of `scene` for `key` ([module docs](self)): the camera moved, the image half as
/// wide (at least 16 pixels), and the move.
pub(crate) fn variant_of(scene: &SceneDescription, key: u64) -> (SceneDescription, CameraMove) {
    let mut state = key;
    let mut uniform = || {
        state = splitmix(state);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let direction = |uniform: &mut dyn FnMut() -> f64| {
        let z = 2.0 * uniform() - 1.0;
        let phi = std::f64::consts::TAU * uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        [r * phi.cos(), r * phi.sin(), z]
    };
    let c = &scene.camera;
    let distance = (0..3)
        .map(|k| (c.look_at[k] - c.look_from[k]).powi(2))
        .sum::<f64>()
        .sqrt()
        .max(1e-3);
    let from = direction(&mut uniform);
    let from_len = distance * (0.03 + 0.03 * uniform());
    let at = direction(&mut uniform);
    let at_len = distance * (0.01 + 0.02 * uniform());
    let sign = if uniform() < 0.5 { -1.0 } else { 1.0 };
    let vfov_scale = 1.0 + sign * (0.03 + 0.03 * uniform());
    let camera_move = CameraMove {
        look_from: from.map(|x| x * from_len),
        look_at: at.map(|x| x * at_len),
        vfov_scale,
    };
    let mut moved = camera_move.apply(scene);
    moved.image.width = (scene.image.width / 2).max(16);
    (moved, camera_move)
}

/// What one render group asks of the submission: the scene at the group's spp, and its variant.
pub(crate) struct Planned<'g> {
    scene: SceneDescription,
    variant: SceneDescription,
    camera_move: CameraMove,
    spp: u32,
    limit: Duration,
    program: Option<&'g str>,
}

/// The render jobs of the rubric's render groups, in `groups`' order: `Err` for a group whose
/// scene cannot be had (it is not rendered).
pub(crate) fn jobs_of<'g>(groups: &[&'g Group], seed: u64) -> Vec<Result<Planned<'g>, String>> {
    groups
        .iter()
        .map(|g| {
            let scene = g.scene_source().ok_or("the group has no scene")?;
            let d = scene_description(&scene)?;
            let spp = g.render_spp();
            // A scene of the course's jittered sampling is sent as it is at the render's spp.
            let at = |d: SceneDescription| crate::golden::at_spp(&d, spp).unwrap_or(d);
            let (variant, camera_move) = variant_of(&d, variant_key(seed, &g.id));
            Ok(Planned {
                scene: at(d),
                variant: at(variant),
                camera_move,
                spp,
                limit: Duration::from_secs_f64(g.render_seconds()),
                program: g.main_function.as_deref(),
            })
        })
        .collect()
}

/// A render group's renders: the scene's, and its variant's with what the variant is.
pub(crate) struct GroupRender {
    /// The render of the group's scene.
    pub(crate) scene: RenderOutcome,
    /// The variant's render, its description (moved, at the render's spp) and the move; `None`
    /// when the group's scene could not be had.
    pub(crate) variant: Option<(RenderOutcome, SceneDescription, CameraMove)>,
}

/// Renders the render groups of one submission through `render` (the code checker's), the scene
/// and its variant of each group, timed. `secret` is the rubric's seed, never sent: each job's
/// seed is derived from it for the purpose `render/<group id>` ([`crate::secret`]), and the
/// variants are drawn from it ([`variant_key`]).
pub(crate) fn render_groups(
    groups: &[&Group],
    secret: u64,
    render: impl FnOnce(&[RenderJob]) -> Vec<RenderOutcome>,
) -> Vec<GroupRender> {
    let wanted = jobs_of(groups, secret);
    let mut jobs: Vec<RenderJob> = Vec::new();
    for (p, g) in wanted
        .iter()
        .zip(groups)
        .filter_map(|(w, g)| w.as_ref().ok().map(|p| (p, g)))
    {
        let job = |scene, variant| RenderJob {
            scene,
            spp: p.spp,
            seed: crate::secret::derive32(secret, &format!("render/{}", g.id)).into(),
            time_limit: p.limit,
            program: p.program,
            variant,
        };
        jobs.push(job(&p.scene, None));
        jobs.push(job(&p.variant, Some(p.camera_move)));
    }
    let mut done = if jobs.is_empty() {
        Vec::new()
    } else {
        render(&jobs)
    }
    .into_iter();
    let mut next = || {
        done.next()
            .unwrap_or_else(|| RenderOutcome::Invalid("the checker rendered nothing".into()))
    };
    wanted
        .into_iter()
        .map(|w| match w {
            Ok(p) => GroupRender {
                scene: next(),
                variant: Some((next(), p.variant, p.camera_move)),
            },
            Err(why) => GroupRender {
                scene: RenderOutcome::Declined(why),
                variant: None,
            },
        })
        .collect()
}

/// The outcome of a render group: the render's judgement (or why there is none), with the
/// upload's judgement kept in its metrics; the points need the variant's render to match its
/// reference too.
pub(crate) fn judge(
    g: &Group,
    render: GroupRender,
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
    let (mut outcome, mut render_json) = match &render.scene {
        RenderOutcome::Rendered(image) => {
            let scene = g.scene_source().expect("validated");
            (
                images.check_render(image, &scene, heatmap_out),
                rendered_json(image),
            )
        }
        failed => {
            let why = failed.reason().unwrap_or_default();
            (
                ImageOutcome::unusable(why.clone()),
                json!({"spp": g.render_spp(), "not_run": why}),
            )
        }
    };
    if let (RenderOutcome::Rendered(_), Some((variant, description, camera_move))) =
        (&render.scene, &render.variant)
    {
        outcome = tie_to_variant(
            outcome,
            variant,
            description,
            camera_move,
            images,
            &mut render_json,
        );
    }
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

/// The scene's render earns its points only when the variant's render (the same scene from the
/// moved camera, [`variant_of`]) matches the reference's render of the same variant too: a
/// picture carried in cannot. Records the variant's judgement in `made["variant"]`; a render
/// that already fails is left as it is.
fn tie_to_variant(
    scene: ImageOutcome,
    variant: &RenderOutcome,
    description: &SceneDescription,
    camera_move: &CameraMove,
    images: &dyn ImageChecker,
    made: &mut Value,
) -> ImageOutcome {
    let camera = description.camera(None);
    // A scene that already fails is not redeemed by its variant: its reference is not rendered.
    let judged = match variant {
        _ if scene.verdict != ImageVerdict::Pass => {
            ImageOutcome::unusable("not judged: the render of the scene itself does not match")
        }
        RenderOutcome::Rendered(image) => images.check_variant(image, description),
        failed => ImageOutcome::unusable(failed.reason().unwrap_or_default()),
    };
    made["variant"] = json!({
        "move": camera_move,
        "width": camera.width,
        "height": camera.height,
        "seconds": match variant {
            RenderOutcome::Rendered(image) => json!((image.seconds * 1000.0).round() / 1000.0),
            _ => Value::Null,
        },
        "verdict": &judged.verdict,
        "diagnosis": &judged.diagnosis,
        "scene_matches": scene.verdict == ImageVerdict::Pass,
    });
    if scene.verdict != ImageVerdict::Pass {
        return scene;
    }
    let what = format!(
        "its render of the same scene from a camera the grader moved ({}x{} pixels; a picture made before the grade cannot show it)",
        camera.width, camera.height
    );
    let tail = "an image earns its points only when it is what your code computes";
    match judged.verdict {
        ImageVerdict::Pass => scene,
        ImageVerdict::Fail => ImageOutcome {
            verdict: ImageVerdict::Fail,
            diagnosis: Some(format!(
                "{what} differs from the reference's render of it{}: {tail}",
                judged
                    .diagnosis
                    .as_deref()
                    .map_or(String::new(), |d| format!(" ({})", d.trim_end_matches('.')))
            )),
            ..scene
        },
        ImageVerdict::Unusable(why) => ImageOutcome {
            verdict: ImageVerdict::Unusable(format!(
                "{what} could not be judged ({}); {tail}",
                why.trim_end_matches('.')
            )),
            ..scene
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
