//! The function checks of weeks 5 to 10 on the course-shaped fixtures
//! (`tests/fixtures/python/weeks/`): the protocol's function requests through a real session
//! and the bundled adapter's driver, and `check` on a week's folder. Whether each week is
//! judged fairly (the solution passing every function, the skeleton failing its tasks, each
//! catalogued mistake caught and named) is tested on the course's real code instead
//! (`course_code`), where the fixtures cannot drift from the course.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use rtoracle::bench::harness::course_python_or_skip;
use rtoracle::candidate::process::command::CandidateCommand;
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::candidate::process::session::Session;
use rtoracle::weekly::{runner::FunctionRunner, runner::Reply, runner::SessionRunner};
use serde_json::json;

fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| course_python_or_skip("the function-check tests"))
        .as_deref()
}

fn weeks() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks")
}

fn session(folder: &str) -> Option<Session> {
    let python = python()?;
    let command = CandidateCommand::python_course_with(&weeks().join(folder), Some(python), false)
        .expect("a submission folder");
    let options = RunOptions {
        hello_timeout: Duration::from_secs(30),
        ..RunOptions::default()
    };
    Some(Session::start(command, options).expect("the adapter starts"))
}

const T: Duration = Duration::from_secs(20);

/// The driver answers the course's functions with their results, returns samples, names a
/// missing function and a stub's `None`.
#[test]
fn function_requests_reach_the_submissions_own_functions() {
    let Some(mut s) = session("week10/solution") else {
        return;
    };
    let mut r = SessionRunner::new(&mut s);
    assert!(r.supports("reflect") && r.supports("sample_camera_ray") && !r.supports("render_all"));
    let reflect = r.call(
        &json!({"op": "reflect", "v": [1.0, -1.0, 0.0], "n": [0.0, 1.0, 0.0]}),
        T,
    );
    assert_eq!(reflect, Reply::Result(json!({"vector": [1.0, 1.0, 0.0]})));
    // 60 degrees from the normal out of glass: total internal reflection, no number drawn.
    let tir = r.call(
        &json!({"op": "refract", "v": [0.8660254037844386, -0.5, 0.0], "n": [0.0, 1.0, 0.0], "ratio": 1.5, "random": [1.0]}),
        T,
    );
    match tir {
        Reply::Result(v) => {
            // The answer holds the vector only: what was drawn is not the answer's to say.
            assert_eq!(v.as_object().unwrap().len(), 1, "{v}");
            let d = v["vector"].as_array().unwrap();
            assert!((d[1].as_f64().unwrap() - 0.5).abs() < 1e-12, "{v}");
        }
        other => panic!("{other:?}"),
    }
    match r.call(&json!({"op": "sample_unit_vector", "n": 7, "seed": 3}), T) {
        Reply::Result(v) => assert_eq!(v["samples"].as_array().unwrap().len(), 7),
        other => panic!("{other:?}"),
    }
    match r.call(&json!({"op": "no_such_op"}), T) {
        Reply::Error(e) => assert!(e.message.contains("unknown request op"), "{e:?}"),
        other => panic!("{other:?}"),
    }
    let Some(mut s) = session("week06/skeleton") else {
        return;
    };
    let mut r = SessionRunner::new(&mut s);
    match r.call(
        &json!({"op": "reflect", "v": [1.0, -1.0, 0.0], "n": [0.0, 1.0, 0.0]}),
        T,
    ) {
        Reply::Error(e) => {
            assert_eq!(e.kind, "BadReturn");
            assert!(e.message.contains("reflect returned None"), "{e:?}");
        }
        other => panic!("{other:?}"),
    }
    match r.call(
        &json!({"op": "halfvector", "v": [1.0, 0.0, 0.0], "l": [0.0, 1.0, 0.0]}),
        T,
    ) {
        Reply::Error(e) => {
            assert_eq!(e.kind, "NotFound");
            assert!(
                e.message.contains("no function halfvector") && e.message.contains("RT_utility.py"),
                "{e:?}"
            );
        }
        other => panic!("{other:?}"),
    }
}

/// A submission folder: week `week`'s solution (or skeleton) with `overlay`'s modules over it,
/// copied into a temporary folder.
fn assemble(base: &str, overlay: Option<&str>) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let copy = |from: &Path| {
        for entry in std::fs::read_dir(from).unwrap().flatten() {
            let name = entry.file_name();
            if entry.path().is_file() && name.to_string_lossy().ends_with(".py") {
                std::fs::copy(entry.path(), dir.path().join(name)).unwrap();
            }
        }
    };
    copy(&weeks().join(base));
    if let Some(o) = overlay {
        copy(&weeks().join(o));
    }
    dir
}

/// `rtoracle check` in a week-6 folder finds the week from its files and runs its function
/// checks too: the solution passes (exit 0), the skeleton fails (exit 1) and names `reflect`'s
/// stub with a Python reproduction; `--week 4` checks the intersections only.
#[test]
fn check_finds_the_week_and_runs_its_functions() {
    let Some(python) = python() else {
        return;
    };
    let run = |dir: &Path, args: &[&str]| {
        crate::common::rtoracle()
            .current_dir(dir)
            .args(args)
            .env("RTORACLE_PYTHON", python)
            .output()
            .expect("rtoracle runs")
    };
    let solution = assemble("week06/solution", None);
    let out = run(solution.path(), &["check"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("checking as week 6 (found from the files: ")
            && stderr.contains("def refract in RT_utility.py"),
        "{stderr}"
    );
    assert!(stdout.contains("verdict: PASS"), "{stdout}");
    assert!(stdout.contains("week 6 refract"), "{stdout}");
    assert!(
        stdout.contains("score of week 6's functions: 100.0 / 100"),
        "{stdout}"
    );
    let skeleton = assemble("week06/skeleton", None);
    let out = run(skeleton.path(), &["check", "--show", "20"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("reflect (RT_material.reflect(v, n)) fails:"),
        "{stdout}"
    );
    assert!(
        stdout.contains("is it still the skeleton's stub?"),
        "{stdout}"
    );
    assert!(stdout.contains("print(rtm.reflect("), "{stdout}");
    assert!(
        stdout.contains("score of week 6's functions: 0.0 / 100"),
        "{stdout}"
    );
    let out = run(skeleton.path(), &["check", "--week", "4"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("functions of week"), "{stdout}");
}

/// `check --json` on a week's folder is one JSON object with the week, the intersections, the
/// functions and the score; a week or a rate out of range is one line on stderr, exit 2.
#[test]
fn check_week_json_and_bad_input() {
    let Some(python) = python() else {
        return;
    };
    let solution = assemble("week09/solution", None);
    let out = crate::common::rtoracle()
        .current_dir(solution.path())
        .args(["check", "--json"])
        .env("RTORACLE_PYTHON", python)
        .output()
        .expect("rtoracle runs");
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["week"], 9);
    assert_eq!(v["score"]["score"], 100.0);
    assert_eq!(v["functions"]["options"]["alpha"], 1e-4);
    let jitter = v["functions"]["functions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["id"] == "jitter")
        .expect("the jitter check");
    assert_eq!(jitter["statistics"]["fit"]["invariant_failures"], 0);
    for (args, needle) in [
        (&["check", "--week", "11"][..], "--week"),
        (&["check", "--week", "x"][..], "--week"),
        (&["check", "--alpha", "2"][..], "--alpha"),
        (&["check", "--alpha", "nan"][..], "--alpha"),
    ] {
        let out = crate::common::run_in(solution.path(), args);
        crate::common::assert_bad_input(&out, needle);
    }
}

/// A function answer over 128 KiB, an adapter that hangs or dies, stray lines: each is a failure
/// of its own request, named; the next request restarts the adapter and gets its answer.
#[test]
fn a_hostile_function_answer_fails_its_request_only() {
    let Some(python) = python() else {
        return;
    };
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/adapters/function_answers.py");
    let command =
        CandidateCommand::adapter(&format!("{} -I {}", python.display(), script.display()))
            .unwrap();
    let options = RunOptions {
        hello_timeout: Duration::from_secs(30),
        ..RunOptions::default()
    };
    let mut s = Session::start(command, options).expect("the adapter starts");
    let mut r = SessionRunner::new(&mut s);
    assert!(r.supports("reflect") && r.supports("intersect") && !r.supports("refract"));
    let ask = |r: &mut SessionRunner, mode: &str, timeout: Duration| {
        r.call(
            &json!({"op": "reflect", "v": [1.0, 2.0, 3.0], "n": [0.0, 1.0, 0.0], "mode": mode}),
            timeout,
        )
    };
    let ok = Reply::Result(json!({"vector": [1.0, 2.0, 3.0]}));
    assert_eq!(ask(&mut r, "ok", T), ok);
    assert_eq!(ask(&mut r, "stray", T), ok);
    match ask(&mut r, "big", T) {
        Reply::Protocol(why) => assert!(why.contains("over 131072 bytes"), "{why}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(ask(&mut r, "hang", Duration::from_secs(1)), Reply::TimedOut);
    assert_eq!(ask(&mut r, "ok", T), ok);
    match ask(&mut r, "die", T) {
        Reply::Failed(why) => assert!(why.contains("died"), "{why}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(ask(&mut r, "ok", T), ok);
    assert_eq!(s.restarts(), 2);
}
