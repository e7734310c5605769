//! The built-in rubrics on the course's real code (`RTORACLE_COURSE_CODE`): every week's
//! instructor solution scores 100, functions and images alike, its images' variants (the scene
//! from a camera the grader moves) included; every week's unmodified skeleton scores at most 5.
//!
//! Each test grades one folder, a copy of the course's own, with `rtoracle grade --rubric
//! weekNN` as an instructor would (week 4: the default rubric), in the sandbox, and reads its
//! `report.json`. The expected scores are the promises, not values read from a run: a
//! solution earns every point, and a skeleton earns none of a week's points, since every
//! function and image the built-in rubric scores is one the skeleton leaves blank
//! (`rtoracle::grade::rubric::weeks`). Run with `--test-threads=2`: each test starts Python.

use std::path::Path;

use serde_json::Value;

use crate::common::{CourseTree, course_week_copy, run_in};

/// Grades the copy of week `week`'s `tree` with the week's built-in rubric; its report.
fn graded(test: &str, week: u8, tree: CourseTree) -> Option<Value> {
    let (tmp, folder) = course_week_copy(test, week, tree)?;
    let out = tmp.path().join("report");
    let rubric = format!("week{week:02}");
    let mut args = vec!["grade", folder.to_str().unwrap(), "--out"];
    args.push(out.to_str().unwrap());
    if week > 4 {
        args.extend(["--rubric", rubric.as_str()]);
    }
    let done = run_in(tmp.path(), &args);
    assert!(
        done.status.success(),
        "{test}: {}",
        String::from_utf8_lossy(&done.stderr)
    );
    let text = std::fs::read_to_string(out.join("report.json")).unwrap();
    Some(serde_json::from_str(&text).unwrap())
}

/// `id score/max status: message` of every check, for failure messages.
fn table(report: &Value) -> String {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            format!(
                "{} {}/{} {}: {}",
                c["id"].as_str().unwrap_or(""),
                c["score"],
                c["max_score"],
                c["status"].as_str().unwrap_or(""),
                c["message"].as_str().unwrap_or("")
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The instructor's solution of `week` earns every point: every scored check passes, and every
/// image's variant matched its reference.
fn solution_scores_100(week: u8) {
    let test = format!("course_grades::week{week:02}_solution");
    let Some(report) = graded(&test, week, CourseTree::Solution) else {
        return;
    };
    let score = report["score"].as_f64().unwrap();
    assert!(
        (score - 100.0).abs() < 0.011,
        "week {week} solution: {score}\n{}",
        table(&report)
    );
    for c in report["checks"].as_array().unwrap() {
        let render = &c["image"]["metrics"]["render"];
        if c["id"].as_str().unwrap().starts_with("image.") && week > 4 {
            assert_eq!(render["made_by"], "main_function", "{c:#}");
            assert_eq!(render["variant"]["verdict"]["verdict"], "pass", "{c:#}");
            assert_eq!(c["status"], "passed", "{c:#}");
        }
    }
}

/// The unmodified skeleton of `week` earns at most 5 points.
fn skeleton_scores_at_most_5(week: u8) {
    let test = format!("course_grades::week{week:02}_skeleton");
    let Some(report) = graded(&test, week, CourseTree::Skeleton) else {
        return;
    };
    let score = report["score"].as_f64().unwrap();
    assert!(
        score <= 5.0,
        "week {week} skeleton: {score}\n{}",
        table(&report)
    );
}

macro_rules! week_tests {
    ($($solution:ident, $skeleton:ident, $week:expr;)*) => {$(
        #[test]
        #[cfg_attr(
            not(rtoracle_course_code),
            ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
        )]
        fn $solution() {
            solution_scores_100($week);
        }

        #[test]
        #[cfg_attr(
            not(rtoracle_course_code),
            ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
        )]
        fn $skeleton() {
            skeleton_scores_at_most_5($week);
        }
    )*};
}

week_tests! {
    week04_solution, week04_skeleton, 4;
    week05_solution, week05_skeleton, 5;
    week06_solution, week06_skeleton, 6;
    week07_solution, week07_skeleton, 7;
    week08_solution, week08_skeleton, 8;
    week09_solution, week09_skeleton, 9;
    week10_solution, week10_skeleton, 10;
}

/// Every scored function of a built-in rubric is one its week's skeleton leaves blank and its
/// solution fills in: the file that holds it differs between the two folders of the course.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn scored_functions_live_in_the_files_the_week_changes() {
    let Some(root) = crate::common::course_code("course_grades::scored_functions") else {
        return;
    };
    // Where the course keeps each scored function.
    let file_of = |f: &str| match f {
        "direct-term" => "RT_integrator.py",
        "reflect" | "mirror" | "dielectric" | "dielectric-choice" | "metal" | "metal-fuzz"
        | "phong" | "blinn" | "cook-torrance" | "lambertian" | "lambertian-lobe" => {
            "RT_material.py"
        }
        "quad-uv" => "RT_object.py",
        "cosine-hemisphere" => "RT_utility.py",
        "lens" | "ray-time" => "RT_camera.py",
        other => panic!("no file known for {other}"),
    };
    let differs = |week: u8, file: &str| {
        let dir = root.join(format!("week{week:02}"));
        let read = |tree: &str| std::fs::read(dir.join(tree).join(file)).unwrap_or_default();
        read("skeleton") != read("solution")
    };
    for week in 5..=10u8 {
        let rubric = rtoracle::grade::rubric::Rubric::builtin(&format!("week{week:02}")).unwrap();
        for g in &rubric.groups {
            for f in g.functions.iter().flatten() {
                assert!(
                    differs(week, file_of(f)),
                    "week {week}: {f} is scored, but {} is the same in the skeleton and the solution",
                    file_of(f)
                );
            }
        }
    }
    assert!(Path::new(&root).is_dir());
}
