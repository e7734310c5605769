//! The function checks of weeks 5 to 10 on the course-shaped fixtures
//! (`tests/fixtures/python/weeks/`): the protocol's function requests through a real session
//! and the bundled adapter's driver.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use rtoracle::candidate::bench::course_python_or_skip;
use rtoracle::candidate::{CandidateCommand, RunOptions, Session};
use rtoracle::functions::{
    FunctionOptions, FunctionRunner, Reply, SessionRunner, Status, Week, WeekReport, run_week,
};
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

/// The driver answers the course's functions with their results, says how many random numbers
/// were drawn, returns samples, names a missing function and a stub's `None`.
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
            assert_eq!(v["draws"]["random_double"], 0, "{v}");
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

/// The week's function checks on `folder` (a copy), through the bundled adapter.
fn week_report(base: &str, overlay: Option<&str>, week: u8) -> Option<WeekReport> {
    let python = python()?;
    let dir = assemble(base, overlay);
    let command = CandidateCommand::python_course_with(dir.path(), Some(python), false)
        .expect("a submission folder");
    let options = RunOptions {
        hello_timeout: Duration::from_secs(30),
        ..RunOptions::default()
    };
    let mut session = Session::start(command, options).expect("the adapter starts");
    let week = Week::new(week).unwrap();
    Some(run_week(
        &mut SessionRunner::new(&mut session),
        week,
        FunctionOptions::default(),
    ))
}

/// The catalogue's mistakes of `week` (`(name, kind)`).
fn catalogue(week: u8) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(weeks().join("mistakes.json")).unwrap();
    let all: Vec<serde_json::Value> = serde_json::from_str(&text).unwrap();
    all.iter()
        .filter(|m| m["week"] == format!("week{week:02}"))
        .map(|m| {
            (
                m["name"].as_str().unwrap().to_string(),
                m["kind"].as_str().unwrap_or("mistake").to_string(),
            )
        })
        .collect()
}

/// Image-only mistakes: no function request can show them (they are in `main.py`'s scenes or
/// the film), so the image groups judge them.
const IMAGE_ONLY: &[&str] = &["motion_on_wrong_sphere", "film_divides_by_samples_taken"];

/// Departures the catalogue marks as giving the solution's answers everywhere (Schlick's `r0`
/// is the same for a ratio and its inverse).
const UNTELLABLE: &[&str] = &["schlick_ior_inverted"];

/// The solution of `week` passes every function; its skeleton fails each function of the week
/// the course does not give; each catalogued mistake fails a function and is named there.
fn week_is_judged_fairly(week: u8) {
    let base = format!("week{week:02}");
    let Some(solution) = week_report(&format!("{base}/solution"), None, week) else {
        return;
    };
    let text = rtoracle::functions::report::to_text(&solution, 20);
    assert!(
        solution
            .functions
            .iter()
            .all(|f| f.status == Status::Passed),
        "the solution of {base}:\n{text}"
    );
    let skeleton = week_report(&format!("{base}/skeleton"), None, week).unwrap();
    let text = rtoracle::functions::report::to_text(&skeleton, 0);
    for f in skeleton.of_the_week().filter(|f| !f.given) {
        assert_eq!(
            f.status,
            Status::Failed,
            "{} on the skeleton of {base}:\n{text}",
            f.id
        );
    }
    let mut missed = Vec::new();
    for (name, kind) in catalogue(week) {
        if IMAGE_ONLY.contains(&name.as_str()) {
            continue;
        }
        let overlay = format!("{base}/mistakes/{name}");
        let report = week_report(&format!("{base}/solution"), Some(&overlay), week).unwrap();
        if UNTELLABLE.contains(&name.as_str()) {
            // The catalogue says no probe can tell it from the solution: it must pass as the
            // solution does.
            assert!(
                report.passed(),
                "{name}:\n{}",
                rtoracle::functions::report::to_text(&report, 3)
            );
            continue;
        }
        let named = report
            .functions
            .iter()
            .filter(|f| f.status == Status::Failed)
            .any(|f| f.mistakes.iter().any(|m| m.name == name));
        if !named {
            missed.push(format!(
                "{name} ({kind}):\n{}",
                rtoracle::functions::report::to_text(&report, 3)
            ));
        }
    }
    assert!(
        missed.is_empty(),
        "{base}: mistakes not named:\n{}",
        missed.join("\n")
    );
}

#[test]
fn week05_is_judged_fairly() {
    week_is_judged_fairly(5);
}

#[test]
fn week06_is_judged_fairly() {
    week_is_judged_fairly(6);
}

#[test]
fn week07_is_judged_fairly() {
    week_is_judged_fairly(7);
}

#[test]
fn week08_is_judged_fairly() {
    week_is_judged_fairly(8);
}

#[test]
fn week09_is_judged_fairly() {
    week_is_judged_fairly(9);
}

#[test]
fn week10_is_judged_fairly() {
    week_is_judged_fairly(10);
}
