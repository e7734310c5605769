//! The function checks of weeks 5 to 10 on the course-shaped fixtures
//! (`tests/fixtures/python/weeks/`): the protocol's function requests through a real session
//! and the bundled adapter's driver.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Duration;

use rtoracle::candidate::bench::course_python_or_skip;
use rtoracle::candidate::{CandidateCommand, RunOptions, Session};
use rtoracle::functions::score::score;
use rtoracle::functions::{
    FunctionOptions, FunctionRunner, Reply, SessionRunner, Status, Week, WeekReport, run_week,
};
use rtoracle::grade::{CheckResult, FunctionsOutcome, Rubric, UNSCORED_ID, function_checks};
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
/// the film), so the image groups judge them, rendered by the submission's own `main.py`
/// (`grade_weeks::image_only_mistakes_cost_their_image_and_are_named`).
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
    assert_eq!(score(&solution).score, 100.0, "{base}");
    // The same reports scored by the week's built-in rubric, as `grade` scores them.
    let rubric = Rubric::builtin(&base).unwrap();
    let graded = |report: &WeekReport| {
        function_checks(
            &rubric,
            &FunctionsOutcome {
                report: Some(report.clone()),
                ..FunctionsOutcome::default()
            },
        )
    };
    let points = |checks: &[CheckResult]| -> (f64, f64) {
        (
            checks.iter().map(|c| c.score).sum(),
            checks.iter().map(|c| c.max_score).sum(),
        )
    };
    let (got, max) = points(&graded(&solution));
    assert!(
        (got - max).abs() < 1e-9 && (max - 70.0).abs() < 1e-9,
        "{base}: the solution's functions score {got} of {max} in the rubric"
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
    let skeleton_score = score(&skeleton).score;
    assert!(
        skeleton_score <= 5.0,
        "{base}'s skeleton scores {skeleton_score}"
    );
    let (got, _) = points(&graded(&skeleton));
    assert!(
        got <= 3.5,
        "{base}'s skeleton's functions score {got} in the rubric"
    );
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
        let scored = score(&report);
        let lost_in_its_group = scored
            .groups
            .iter()
            .any(|g| g.score < g.max && g.mistakes.contains(&name));
        // A mistake in an earlier week's function, or one the skeleton gives, is a regression:
        // named, no points of this week's groups (its images show it).
        let regression = report.functions.iter().any(|f| {
            (f.week.number() < week || f.given) && f.mistakes.iter().any(|m| m.name == name)
        });
        if kind == "mistake" && named && !lost_in_its_group && !regression {
            missed.push(format!("{name} loses no points: {scored:?}"));
        }
        // In the rubric: a check of a functions group that loses points says the mistake's
        // name; a regression is named by the unscored check.
        let checks = graded(&report);
        let in_rubric = checks.iter().any(|c| {
            let says = c.message.contains(&format!(" {name} ("));
            if regression {
                c.id == UNSCORED_ID && c.message.contains(&name)
            } else {
                c.score < c.max_score && says
            }
        });
        if kind == "mistake" && named && !in_rubric {
            missed.push(format!(
                "{name} is not named by a check that loses points in the {base} rubric: {:#?}",
                checks
                    .iter()
                    .map(|c| (&c.id, c.score, c.max_score, &c.message))
                    .collect::<Vec<_>>()
            ));
        }
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
        stdout.contains("reflect (RT_utility.reflect(v, n)) fails:"),
        "{stdout}"
    );
    assert!(
        stdout.contains("is it still the skeleton's stub?"),
        "{stdout}"
    );
    assert!(stdout.contains("print(rtu.reflect("), "{stdout}");
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
        Reply::Failed(why) => assert!(why.contains("over 131072 bytes"), "{why}"),
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
