//! Every exception a student's code raises, on every path (the intersection vectors, a function
//! check, a sampler, the grader's render, the import), is shown with the student's own file and
//! line and the exception's message, in feedback.md, results.json, junit.xml and on the
//! terminal (`grade`'s and `check`'s). The test puts a `raise` of its own at a line it knows
//! into a week-9 submission (the repository's course-shaped solution, and the course's real
//! one), so where the exception comes from is known without asking rtoracle.

use std::path::Path;

use serde_json::Value;

use crate::common::*;
use rtoracle::bench::grade::materialize_code;

/// Inserts `raise ZeroDivisionError("MARK")` as the first line of the body of the first
/// `def NAME(` in a `.py` file of `dir` (after the line `after`, when given); returns the
/// file's name and the inserted line's number (1-based).
fn raise_in(dir: &Path, name: &str, after: Option<&str>, mark: &str) -> (String, usize) {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "py"))
        .collect();
    files.sort();
    // The course's own placement first (RT_utility, RT_material, RT_object), as a grader
    // would call it.
    files.sort_by_key(|p| {
        let n = p.file_name().unwrap().to_string_lossy().to_string();
        ["RT_utility.py", "RT_material.py", "RT_object.py"]
            .iter()
            .position(|f| *f == n)
            .unwrap_or(9)
    });
    let line = format!("raise ZeroDivisionError(\"{mark}\")");
    let (path, number) = insert_first_in_def(&files, name, after, &line)
        .unwrap_or_else(|| panic!("no def {name} in {}", dir.display()));
    (
        path.file_name().unwrap().to_string_lossy().to_string(),
        number,
    )
}

/// The places put into the week-9 submission `dir`: (what, "ZeroDivisionError: MARK (FILE,
/// line N)").
fn plant(dir: &Path) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for (what, name, after) in [
        // The sphere's intersect: the vectors and the grader's render both call it.
        ("intersections", "intersect", Some("class Sphere")),
        // A sampler (a statistical check).
        ("sampler", "random_cosine_hemisphere_on_z", None),
        // A function check the week-9 rubric scores (the Lambertian's scattering through the
        // ONB).
        ("function", "scattering", Some("class Lambertian")),
    ] {
        let mark = format!("people-{what}");
        let (file, line) = raise_in(dir, name, after, &mark);
        out.push((
            what,
            format!("ZeroDivisionError: {mark} ({file}, line {line})"),
        ));
    }
    out
}

/// The text of `junit.xml` as a reader sees it: every text node and `message` attribute,
/// unescaped.
fn junit_text(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    doc.descendants()
        .filter_map(|n| n.text())
        .chain(doc.descendants().filter_map(|n| n.attribute("message")))
        .collect::<Vec<_>>()
        .join("\n")
}

fn assert_places(dir: &Path, work: &Path) {
    let places = plant(dir);
    let out = work.join("report");
    let grade = rtoracle()
        .args(["grade", "--rubric", "week09", "--case-timeout-ms", "2000"])
        .arg(dir)
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
    let terminal = String::from_utf8_lossy(&grade.stdout).to_string();
    let feedback = std::fs::read_to_string(out.join("feedback.md")).unwrap();
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let results: String = results["tests"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["output"].as_str().unwrap().to_string() + "\n")
        .collect();
    let junit = junit_text(&out.join("junit.xml"));
    let check = rtoracle().arg("check").arg(dir).output().unwrap();
    let check = String::from_utf8_lossy(&check.stdout).to_string();
    for (what, place) in &places {
        // In results.json the message is a Markdown quote: `(` and `)` stay, nothing else in
        // the place needs escaping.
        for (format, text) in [
            ("feedback.md", &feedback),
            ("results.json", &results),
            ("junit.xml", &junit),
            ("grade's terminal", &terminal),
            ("check's terminal", &check),
        ] {
            assert!(
                text.contains(place.as_str()),
                "{what}: {place:?} not in {format}:\n{text}"
            );
        }
    }
    // The grader's render calls the code that raises (the sphere's intersect, the Lambertian's
    // scattering): the render's exception names the student's place too.
    let render = |text: &str| {
        places
            .iter()
            .any(|(_, place)| text.contains(&format!("the render raised {place}")))
    };
    assert!(render(&feedback), "{feedback}");
    assert!(render(&results), "{results}");
}

#[test]
fn every_exception_names_the_student_s_file_and_line_on_every_path() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("week09");
    copy_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks/week09/solution"),
        &dir,
    );
    assert_places(&dir, tmp.path());
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn every_exception_names_the_student_s_file_and_line_in_the_course_s_code() {
    let Some((_guard, dir)) = course_week_copy(
        "every_exception_names_the_student_s_file_and_line_in_the_course_s_code",
        9,
        CourseTree::Solution,
    ) else {
        return;
    };
    let work = tempfile::tempdir().unwrap();
    assert_places(&dir, work.path());
}

#[test]
fn an_import_error_names_the_file_and_line_in_every_format() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("unimportable");
    materialize_code("unimportable", &dir).unwrap();
    // The fixture's syntax error: the line of `def intersect(...)` without its colon.
    let text = std::fs::read_to_string(dir.join("RT_object.py")).unwrap();
    let line = 1 + text
        .lines()
        .position(|l| l.trim_start().starts_with("def ") && !l.trim_end().ends_with(':'))
        .unwrap();
    let place = format!("SyntaxError: expected ':' (RT_object.py, line {line})");
    let out = tmp.path().join("out");
    let grade = rtoracle()
        .arg("grade")
        .arg(&dir)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(grade.status.code(), Some(0));
    let terminal = String::from_utf8_lossy(&grade.stdout);
    assert!(terminal.contains(&place), "{terminal}");
    for file in ["feedback.md", "results.json"] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(text.contains(&place), "{file}: {text}");
    }
    let junit = junit_text(&out.join("junit.xml"));
    assert!(junit.contains(&place), "{junit}");
    let check = rtoracle().arg("check").arg(&dir).output().unwrap();
    assert!(String::from_utf8_lossy(&check.stdout).contains(&place));
}
