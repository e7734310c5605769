//! Grading one submission: the code groups through a [`CodeChecker`], the image groups through an
//! [`ImageChecker`], scored into a [`GradeReport`].

use crate::candidate::judging::check::FailureKind;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use super::checkers::copies::{CopyFinding, Fingerprint, recognise};
use super::checkers::{CodeChecker, CodeOutcome, ImageChecker, ImageOutcome, ImageVerdict};
use super::result::{CodeRun, GradeError, GradeReport, Reproducibility, round2};
use super::rubric::{Group, GroupKind, Rubric, SceneSource};
use super::score::{code_check, heatmap_name, image_check};
use crate::candidate::process::render_request::RenderOutcome;

/// The size the image of `scene` must have, when `scene` is a built-in scene.
pub(crate) fn expected_size(scene: &SceneSource) -> Option<(usize, usize)> {
    let camera = match scene {
        SceneSource::Builtin(name) => crate::scene::builtin(name).ok()?.camera(None),
        SceneSource::File(f) => f.description.camera(None),
    };
    Some((camera.width, camera.height))
}

/// Reads the image of group `g` with care (see [`intake`](super::intake)) into a private copy
/// and hands the copy to `images`; whatever the checker says names the file relative to the
/// submission, never by the grader's paths.
///
/// The image is first checked for a copy ([`copies`](super::checkers::copies)): the course's published
/// image or the reference tracer's own render is not compared (it scores 0, the finding says
/// why); the fingerprint comes back for a batch's comparison of submissions.
fn check_image(
    submission: &Path,
    g: &Group,
    images: &dyn ImageChecker,
    out_dir: &Path,
) -> StagedImage {
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
            return StagedImage::unusable(format!(
                "{rel} could not be staged for comparison ({})",
                e.kind()
            ));
        }
    };
    let staged =
        match super::intake::stage_image(submission, rel, expected_size(&scene), stage.path()) {
            Ok(p) => p,
            Err(why) => return StagedImage::unusable(why),
        };
    // An image that cannot be decoded is the comparison's to explain.
    let fingerprint = crate::image_io::read_png(&staged)
        .ok()
        .map(|img| Arc::new(Fingerprint::of(&img)));
    let copy = fingerprint.as_deref().and_then(|fp| recognise(fp, &scene));
    if copy.is_some() {
        return StagedImage {
            outcome: ImageOutcome {
                verdict: ImageVerdict::Fail,
                ..ImageOutcome::unusable("")
            },
            fingerprint,
            copy,
        };
    }
    let mut outcome = images.check_scene(&staged, &scene, &out_dir.join(heatmap_name(g)));
    if let ImageVerdict::Unusable(why) = &mut outcome.verdict {
        let shown = format!("{}: ", staged.display());
        *why = why.replace(&shown, &format!("{rel}: "));
        *why = why.replace(&staged.display().to_string(), rel);
    }
    StagedImage {
        outcome,
        fingerprint,
        copy: None,
    }
}

/// What checking one image group's upload found.
struct StagedImage {
    outcome: ImageOutcome,
    fingerprint: Option<Arc<Fingerprint>>,
    copy: Option<CopyFinding>,
}

impl StagedImage {
    fn unusable(why: String) -> Self {
        StagedImage {
            outcome: ImageOutcome::unusable(why),
            fingerprint: None,
            copy: None,
        }
    }
}

/// The check of a render group: the grader's render of the submission's code judged against
/// the golden, the upload's judgement (`upload`) reported beside it.
///
/// What the submission's code returned may itself be a copy: pixels read from the course's
/// published image or from the reference's render (scored 0, said so). Renders are not
/// compared with each other: one seed and the same formulas give honest submissions the same
/// noise.
fn render_check(
    g: &Group,
    upload: ImageOutcome,
    render: super::checkers::rendered::GroupRender,
    images: &dyn ImageChecker,
    out_dir: &Path,
) -> super::result::CheckResult {
    let copy = match &render.scene {
        RenderOutcome::Rendered(image) => {
            let scene = g.scene_source().expect("validated");
            let fp = Fingerprint::of(&super::checkers::encoded(image));
            recognise(&fp, &scene).filter(CopyFinding::zeroes)
        }
        _ => None,
    };
    let heatmap = out_dir.join(heatmap_name(g));
    let judged = super::checkers::rendered::judge(g, render, upload, images, &heatmap);
    let mut check = image_check(g, judged, copy.clone(), out_dir);
    match &copy {
        Some(c) => check.message = c.render_sentence().into(),
        None => super::score::explain(&mut check, g),
    }
    check
}

/// The code checks of `submission`: the intersection vectors of the rubric's shapes and, with a
/// week, that week's function checks, at the same time.
fn run_code(
    submission: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
) -> (CodeOutcome, Option<super::checkers::FunctionsOutcome>) {
    let shapes = rubric.code_shapes();
    let week = rubric.week.and_then(crate::weekly::week::Week::new);
    let function_options = crate::weekly::run::FunctionOptions {
        seed: rubric.seed,
        alpha: rubric.alpha.unwrap_or(crate::weekly::stats::DEFAULT_ALPHA),
    };
    rayon::join(
        || {
            if shapes.is_empty() {
                CodeOutcome::default()
            } else {
                code.check(submission, &shapes)
            }
        },
        || week.map(|w| code.check_functions(submission, w, function_options)),
    )
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
    let image_groups: Vec<&Group> = rubric
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Image)
        .collect();
    let render_groups: Vec<&Group> = image_groups
        .iter()
        .copied()
        .filter(|g| g.renders())
        .collect();
    let ((outcome, functions), (image_outcomes, renders)) = rayon::join(
        || run_code(submission, rubric, code),
        || {
            rayon::join(
                || {
                    image_groups
                        .iter()
                        .map(|g| check_image(submission, g, images, out_dir))
                        .collect::<Vec<_>>()
                },
                || {
                    super::checkers::rendered::render_groups(&render_groups, rubric.seed, |jobs| {
                        code.render(submission, jobs)
                    })
                },
            )
        },
    );
    let protocol_errors = protocol_errors(&outcome, functions.as_ref(), &renders);
    let mut image_outcomes = image_outcomes.into_iter();
    let mut renders = renders.into_iter();
    let mut checks = Vec::new();
    let mut fingerprints = Vec::new();
    let mut function_checks = functions
        .as_ref()
        .map(|f| super::score::weekly::function_checks(rubric, f))
        .unwrap_or_default();
    for g in &rubric.groups {
        match g.kind {
            GroupKind::Code => checks.extend(code_check(g, &outcome)),
            GroupKind::Functions => {
                let (mine, rest) = function_checks.into_iter().partition(|c| c.group == g.id);
                checks.extend::<Vec<_>>(mine);
                function_checks = rest;
            }
            GroupKind::Image if g.renders() => checks.push(render_check(
                g,
                image_outcomes.next().expect("one per image group").outcome,
                renders.next().expect("one per render group"),
                images,
                out_dir,
            )),
            GroupKind::Image => {
                let staged = image_outcomes.next().expect("one per image group");
                // A recognised copy is not compared with classmates' images (it scores 0).
                if let (Some(fp), None) = (staged.fingerprint, &staged.copy) {
                    fingerprints.push((g.id.clone(), fp));
                }
                checks.push(image_check(g, staged.outcome, staged.copy, out_dir));
            }
        }
    }
    // The unscored check of the functions that carry no points comes last.
    checks.extend(function_checks);
    let score = round2(checks.iter().map(|c| c.score).sum());
    let submission_name = submission
        .canonicalize()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().to_string()))
        .unwrap_or_else(|| submission.display().to_string());
    Ok(GradeReport {
        submission: submission_name.into(),
        rubric: rubric.name.clone(),
        rubric_source: rubric.source.clone(),
        score,
        max_score: rubric.max_score(),
        execution_time: 0.0,
        checks,
        fingerprints,
        code: CodeRun {
            fatal: outcome.fatal.clone().map(Into::into),
            stderr_tail: outcome.stderr_tail.clone().into(),
            sandbox: outcome.sandbox.clone(),
            diagnosis: outcome.diagnosis.clone(),
            triangle_winding: outcome.triangle_winding,
            functions_fatal: functions
                .as_ref()
                .and_then(|f| f.fatal.clone())
                .map(Into::into),
            functions_stderr_tail: functions
                .as_ref()
                .map(|f| f.stderr_tail.clone())
                .unwrap_or_default()
                .into(),
            protocol_errors,
            failed_vectors: outcome
                .failures
                .iter()
                .filter(|f| f.definite && f.kind != FailureKind::NotRun)
                .map(|f| (f.id.clone(), f.shape))
                .collect(),
        },
        reproducibility: reproducibility(submission, rubric, code, images, &image_groups),
    })
    .map(|mut r| {
        r.execution_time = (start.elapsed().as_secs_f64() * 1000.0).round() / 1000.0;
        r
    })
}

/// How many answers broke the protocol: intersection vectors, function cases and renders.
fn protocol_errors(
    outcome: &CodeOutcome,
    functions: Option<&super::checkers::FunctionsOutcome>,
    renders: &[super::checkers::rendered::GroupRender],
) -> usize {
    let vectors = outcome
        .failures
        .iter()
        .filter(|f| f.kind == FailureKind::Protocol)
        .count();
    let cases: usize = functions
        .and_then(|f| f.report.as_ref())
        .map_or(0, |r| r.functions.iter().map(|f| f.counts.protocol).sum());
    vectors
        + cases
        + renders
            .iter()
            .flat_map(|r| std::iter::once(&r.scene).chain(r.variant.as_ref().map(|v| &v.0)))
            .filter(|r| r.is_protocol_error())
            .count()
}

/// What the report says the grade was made from: tool, rubric, vectors, goldens, scene files
/// and the submission's files, each by its SHA-256, and the checkers.
fn reproducibility(
    submission: &Path,
    rubric: &Rubric,
    code: &dyn CodeChecker,
    images: &dyn ImageChecker,
    image_groups: &[&Group],
) -> Reproducibility {
    let shapes = rubric.code_shapes();
    let goldens_sha256 = image_groups
        .iter()
        .filter_map(|g| g.scene_source().map(|s| (g, s)))
        .map(|(g, s)| {
            let sha = if g.renders() {
                images.render_golden_sha256(&s, g.render_spp())
            } else {
                images.scene_golden_sha256(&s)
            };
            (s.label().to_string(), sha)
        })
        .collect();
    let scenes_sha256 = image_groups
        .iter()
        .filter_map(|g| g.scene_file.as_ref())
        .map(|f| (f.label.clone(), f.sha256.clone()))
        .collect();
    Reproducibility {
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grade::checkers::fakes::*;
    use crate::grade::checkers::{FailureSummary, GroupCounts};
    use crate::grade::result::{CheckStatus, smallest_failure};
    use crate::grade::rubric::Visibility;
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
        assert!(c.message.contains("1 of 4 sphere test vectors answered correctly (1 raised an exception, 1 timed out, 1 not run)."), "{:?}", c.message);
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
            message: format!("{kind:?}").into(),
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
            "{:?}",
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
            "{:?}",
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
