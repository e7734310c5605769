//! One verdict for one submission: `rtoracle check` (what a student runs before handing in) and
//! `rtoracle grade` (what the instructor runs) say the same of its code. For every shape the
//! rubric grades, `check` passes that shape exactly when `grade` gives its group full marks,
//! they count the same watertight groups judged and cracked, and grade's reports explain a
//! crack in check's words. On every fixture submission and on the course's real week-4 code:
//! its solution, its skeleton, and its solution with open quad edges (`fa <= 0 or 1.0 <= fa`),
//! which both must fail (a ray through the edge two quads share hits neither).

use std::path::Path;

use serde_json::Value;

use crate::common::*;
use rtoracle::bench::grade::{fixture_names, materialize_code};

/// The week-4 rubric's code groups (its images are not what `check` checks).
const CODE_RUBRIC: &str = r#"name = "week04-code"

[[group]]
id = "sphere"
name = "Sphere intersection"
kind = "code"
shape = "sphere"
points = 30

[[group]]
id = "quad"
name = "Quad constructor and intersection"
kind = "code"
shape = "quad"
points = 30
"#;

/// `check --json` and `grade`'s report.json of the submission `dir` (graded into `work`),
/// and check's exit code.
fn check_and_grade(dir: &Path, work: &Path) -> (Value, i32, Value) {
    let check = rtoracle()
        .args(["check", "--json", "--timeout-ms", "1000"])
        .arg(dir)
        .output()
        .unwrap();
    let code = check.status.code().unwrap();
    assert!(
        code == 0 || code == 1,
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    let check: Value = serde_json::from_slice(&check.stdout).unwrap();
    let rubric = work.join("code.toml");
    std::fs::write(&rubric, CODE_RUBRIC).unwrap();
    let out = work.join("report");
    let grade = rtoracle()
        .args(["grade", "--format", "json", "--case-timeout-ms", "1000"])
        .arg(dir)
        .arg("--rubric")
        .arg(&rubric)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        grade.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&grade.stderr)
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    (check, code, report)
}

/// Whether `check` passes `shape` (its verdict's rule, `Counts::all_passed`, on the shape's
/// counts, and no import error).
fn check_passes(check: &Value, shape: &str) -> bool {
    let r = &check["intersections"];
    let c = &r["by_shape"][shape];
    let n = |k: &str| c[k].as_u64().unwrap_or_else(|| panic!("{shape}.{k}: {c}"));
    r["import_error"].is_null()
        && n("failed") == 0
        && n("errors") == 0
        && n("timeouts") == 0
        && n("unscored_timeouts") == 0
        && n("unscored_crashes") == 0
        && n("not_run") == n("unsupported")
        && n("watertight_cracked") == 0
        && (n("total") == 0 || n("passed") > 0)
}

/// Asserts that check and grade agree on `name`; returns whether its code passed.
fn assert_agree(name: &str, check: &Value, code: i32, report: &Value) -> bool {
    let mut all = true;
    for shape in ["sphere", "quad"] {
        let id = format!("{shape}.intersect");
        let graded = report["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["id"] == id.as_str())
            .unwrap_or_else(|| panic!("{name}: no check {id}"));
        let passes = check_passes(check, shape);
        all &= passes;
        let full = graded["status"] == "passed";
        assert_eq!(
            passes,
            full,
            "{name}: check {} {shape}, grade {} / {} ({}): {}",
            if passes { "passes" } else { "fails" },
            graded["score"],
            graded["max_score"],
            graded["status"],
            graded["message"]
        );
        assert_eq!(full, graded["score"] == graded["max_score"], "{name} {id}");
        if report["code"]["fatal"].is_null() {
            let c = &check["intersections"]["by_shape"][shape];
            for k in ["watertight", "watertight_cracked"] {
                assert_eq!(c[k], graded["counts"][k], "{name} {shape} {k}");
            }
        }
        // Every crack grade shows is one check reports, in the same words. The grade's
        // vectors are drawn from the rubric's secret (not check's seed), so the groups'
        // numbers differ: the words are compared with their digits left out.
        let words = |m: &str| m.replace(|c: char| c.is_ascii_digit(), "#");
        let check_messages: Vec<String> = check["intersections"]["failures"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|f| f["message"].as_str())
            .map(words)
            .collect();
        for f in graded["failures"].as_array().into_iter().flatten() {
            let m = f["message"].as_str().unwrap();
            if m.starts_with("watertight group") {
                assert!(check_messages.contains(&words(m)), "{name}: {m}");
            }
        }
    }
    // Week 4 has no triangles: check's exit code is the two shapes' verdict.
    assert_eq!(code == 0, all, "{name}: check exit code {code}");
    assert_eq!(check["verdict"] == "pass", all, "{name}");
    all
}

#[test]
fn check_and_grade_agree_on_every_fixture_submission() {
    let tmp = tempfile::tempdir().unwrap();
    let names = fixture_names();
    assert!(names.len() >= 10, "{names:?}");
    for name in names {
        let dir = tmp.path().join(&name);
        let loses = materialize_code(&name, &dir).unwrap();
        let work = tmp.path().join(format!("{name}-work"));
        std::fs::create_dir(&work).unwrap();
        let (check, code, report) = check_and_grade(&dir, &work);
        let passed = assert_agree(&name, &check, code, &report);
        // The fixture's own account of its code (independent of both commands).
        let code_lost = loses.iter().any(|g| g == "sphere" || g == "quad");
        assert_eq!(passed, !code_lost, "{name}: loses {loses:?}");
    }
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn check_and_grade_agree_on_the_course_s_week_4_code() {
    let Some((_solution_guard, solution)) = course_week_copy(
        "check_and_grade_agree_on_the_course_s_week_4_code",
        4,
        CourseTree::Solution,
    ) else {
        return;
    };
    let (_skeleton_guard, skeleton) = course_week_copy("", 4, CourseTree::Skeleton).unwrap();
    // The solution with open quad edges: the course's `is_interior` test made strict.
    let open = solution.with_file_name("week04-open-edges");
    copy_tree(&solution, &open);
    let object = std::fs::read_to_string(open.join("RT_object.py")).unwrap();
    let closed = "if (fa<delta) or (1.0<fa) or (fb<delta) or (1.0<fb):";
    assert!(object.contains(closed), "the course's is_interior changed");
    let strict = "if (fa<=delta) or (1.0<=fa) or (fb<=delta) or (1.0<=fb):";
    std::fs::write(open.join("RT_object.py"), object.replace(closed, strict)).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let mut verdicts = Vec::new();
    for (name, dir) in [
        ("solution", &solution),
        ("skeleton", &skeleton),
        ("open-edges", &open),
    ] {
        let work = tmp.path().join(name);
        std::fs::create_dir(&work).unwrap();
        let (check, code, report) = check_and_grade(dir, &work);
        verdicts.push(assert_agree(name, &check, code, &report));
        if name == "open-edges" {
            let quad = &check["intersections"]["by_shape"]["quad"];
            let cracked = quad["watertight_cracked"].as_u64().unwrap();
            assert!(cracked > 0, "{quad}");
            let graded = report["checks"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c["id"] == "quad.intersect")
                .unwrap();
            // Each cracked group is one vector where the ray hits, answered wrong: the hit
            // credit is (hits right) / (hits), the groups among them.
            let credit = &graded["credit"];
            let hits = credit["hits"].as_u64().unwrap();
            let right = credit["hits_right"].as_u64().unwrap();
            assert_eq!(hits - right, cracked, "{credit}");
            let expected = 30.0 * right as f64 / hits as f64;
            let score = graded["score"].as_f64().unwrap();
            assert!((score - expected).abs() <= 0.005, "{score} vs {expected}");
            let message = graded["message"].as_str().unwrap();
            assert!(
                message.contains(&format!("judged, {cracked} cracked")),
                "{message}"
            );
        }
    }
    assert_eq!(verdicts, [true, false, false]);
}
