//! Image groups rendered by the grader from the submission's own code (`source = "render"`):
//! `rtoracle grade` end to end on submissions shaped like the course's code, whose renders
//! pass, raise, hang, return NaN or the wrong size.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::*;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// Copies the `.py` files directly in each of `folders` into `dest` (later ones win).
fn copy_py(folders: &[PathBuf], dest: &Path) {
    std::fs::create_dir_all(dest).unwrap();
    for folder in folders {
        for entry in std::fs::read_dir(folder).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "py") {
                std::fs::copy(&path, dest.join(path.file_name().unwrap())).unwrap();
            }
        }
    }
}

/// A week-4 submission: the course modules of `python/common`, the honest `RT_object.py`, and
/// the render overlay `overlay` (a folder of `python/render`) when given.
fn week4_submission(dest: &Path, overlay: Option<&str>) {
    let f = fixtures();
    let mut folders = vec![f.join("python/common"), f.join("submissions/honest")];
    if let Some(o) = overlay {
        folders.push(f.join("python/render").join(o));
    }
    copy_py(&folders, dest);
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn check<'a>(report: &'a Value, id: &str) -> &'a Value {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == id)
        .unwrap_or_else(|| panic!("no check {id}: {report}"))
}

/// The instructor's week-4 solution (the course's own modules: week 5's skeleton is week 4's
/// solution, with `RT_renderer` importing the progress bar the grader's Python lacks) gets full
/// marks from the built-in rubric, which renders both scenes from its code at the rubric's spp
/// (this test takes about 20 s of CPU: it is the only full-size render of both scenes, which is
/// what the built-in rubric does to every submission); the report says per image group the spp,
/// the time and the comparison, in report.json, the feedback and results.json.
#[test]
fn the_instructor_s_week_4_solution_is_rendered_from_its_code_and_gets_full_marks() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("solution");
    copy_py(&[fixtures().join("python/weeks/week05/skeleton")], &sub);
    // No image uploaded: the points come from the grader's renders.
    let out = run_in(
        dir.path(),
        &["grade", "solution", "--out", "out", "--format", "all"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let report = read_json(&dir.path().join("out/report.json"));
    assert_eq!(report["score"], report["max_score"], "{report:#}");
    for (id, (w, h)) in [
        ("image.week04-sphere", (400, 225)),
        ("image.week04-quad", (400, 400)),
    ] {
        let c = check(&report, id);
        let m = &c["image"]["metrics"];
        assert_eq!(m["source"], "render", "{c}");
        assert_eq!(m["render"]["spp"], 4, "{c}");
        assert_eq!(
            (
                m["render"]["width"].as_u64(),
                m["render"]["height"].as_u64()
            ),
            (Some(w), Some(h))
        );
        let seconds = m["render"]["seconds"].as_f64().unwrap();
        assert!(seconds > 0.0 && seconds < 60.0, "{c}");
        // The comparison is the noise-aware one's, at the spp rendered.
        assert_eq!(m["verdict"], "pass", "{c}");
        assert_eq!(m["candidate_spp"], 4, "{c}");
        let message = c["message"].as_str().unwrap();
        assert!(
            message.starts_with("The render of your code (4 spp, ")
                && message.contains("matches the reference"),
            "{message}"
        );
        assert!(
            message.contains("is missing from the submission; it costs nothing"),
            "{message}"
        );
    }
    let feedback = std::fs::read_to_string(dir.path().join("out/feedback.md")).unwrap();
    assert!(
        feedback.contains("The render of your code (4 spp, "),
        "{feedback}"
    );
    let results = read_json(&dir.path().join("out/results.json"));
    let tests = results["tests"].as_array().unwrap();
    assert!(
        tests.iter().any(|t| t["output"]
            .as_str()
            .is_some_and(|o| o.contains("The render of your code (4 spp, "))),
        "{results:#}"
    );
}

/// A rubric of the sphere vectors and the sphere scene rendered at 1 spp in at most `seconds`.
fn sphere_rubric(seconds: f64) -> String {
    format!(
        "name = \"r\"\n\
         [[group]]\nid = \"sphere\"\nname = \"S\"\nkind = \"code\"\nshape = \"sphere\"\npoints = 30\n\
         [[group]]\nid = \"image.week04-sphere\"\nname = \"I\"\nkind = \"image\"\n\
         file = \"week04_sphere.png\"\nscene = \"week04-sphere\"\nspp = 1\nrender_seconds = {seconds}\npoints = 20\n"
    )
}

/// Each way a render can go wrong costs its image group (0, with the reason in the message and
/// in the metrics' `render.not_run`) and nothing else: the sphere vectors keep their 30 points.
#[test]
fn a_render_that_raises_hangs_returns_nan_or_the_wrong_size_scores_0_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("raises", "ZeroDivisionError"),
        ("hangs", "did not finish within 3 s"),
        ("nan", "is NaN"),
        ("wrong_size", "[400,226] but the scene is 400x225"),
    ];
    for (overlay, _) in cases {
        week4_submission(&dir.path().join("subs").join(overlay), Some(overlay));
    }
    std::fs::write(dir.path().join("r.toml"), sphere_rubric(3.0)).unwrap();
    let out = run_in(
        dir.path(),
        &[
            "grade", "--batch", "subs", "--rubric", "r.toml", "--out", "out",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (overlay, reason) in cases {
        let report = read_json(&dir.path().join("out").join(overlay).join("report.json"));
        assert_eq!(
            check(&report, "sphere.intersect")["score"],
            30.0,
            "{overlay}"
        );
        let c = check(&report, "image.week04-sphere");
        assert_eq!(c["score"], 0.0, "{overlay}: {c}");
        let message = c["message"].as_str().unwrap();
        assert!(
            message.starts_with("The render of your code could not be judged and scores 0: "),
            "{overlay}: {message}"
        );
        assert!(message.contains(reason), "{overlay}: {message}");
        let not_run = c["image"]["metrics"]["render"]["not_run"].as_str().unwrap();
        assert!(not_run.contains(reason), "{overlay}: {not_run}");
        assert_eq!(report["score"], 30.0, "{overlay}");
    }
}

/// A camera whose `init_camera` takes no lens arguments (an earlier week's, or a student's own)
/// is built all the same: the render passes and earns its points.
#[test]
fn a_camera_whose_init_takes_no_lens_is_rendered_all_the_same() {
    let dir = tempfile::tempdir().unwrap();
    week4_submission(&dir.path().join("sub"), Some("no_lens"));
    std::fs::write(dir.path().join("r.toml"), sphere_rubric(60.0)).unwrap();
    let out = run_in(
        dir.path(),
        &["grade", "sub", "--rubric", "r.toml", "--out", "out"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = read_json(&dir.path().join("out/report.json"));
    let c = check(&report, "image.week04-sphere");
    assert_eq!(c["score"], 20.0, "{c}");
}

/// `source = "upload"` keeps the old behaviour: the uploaded image is judged and earns the
/// points, nothing is rendered; under `render` the same upload earns nothing of its own (a
/// submission whose render fails gets 0 whatever it uploads).
#[test]
fn source_upload_judges_the_uploaded_image_and_render_ignores_it_for_points() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("subs/raises");
    week4_submission(&sub, Some("raises"));
    // A correct image of the scene, from the reference tracer (as a student could make one).
    let out = run_in(
        dir.path(),
        &[
            "render",
            "week04-sphere",
            "--seed",
            "11",
            "-o",
            "subs/raises/week04_sphere.png",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let upload =
        sphere_rubric(30.0).replace("spp = 1\nrender_seconds = 30\n", "source = \"upload\"\n");
    std::fs::write(dir.path().join("upload.toml"), &upload).unwrap();
    std::fs::write(dir.path().join("render.toml"), sphere_rubric(30.0)).unwrap();
    for (rubric, points) in [("upload.toml", 20.0), ("render.toml", 0.0)] {
        let out_dir = format!("out-{rubric}");
        let out = run_in(
            dir.path(),
            &[
                "grade",
                "subs/raises",
                "--rubric",
                rubric,
                "--out",
                &out_dir,
            ],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report = read_json(&dir.path().join(&out_dir).join("report.json"));
        let c = check(&report, "image.week04-sphere");
        assert_eq!(c["score"], points, "{rubric}: {c}");
        let m = &c["image"]["metrics"];
        if points > 0.0 {
            assert!(m.get("render").is_none(), "{c}");
        } else {
            assert_eq!(m["upload"]["verdict"]["verdict"], "pass", "{c}");
            let message = c["message"].as_str().unwrap();
            assert!(
                message.contains("Your uploaded week04_sphere.png matches the reference"),
                "{message}"
            );
        }
    }
}
