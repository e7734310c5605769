//! The JSON documents the commands write hold to their JSON Schemas in `docs/schemas/`: one
//! shape for `rtoracle check --json` whatever the week (week 4, with no functions; a later
//! week's, with them), and for grade's `report.json` whatever the week. Validated by the
//! `jsonschema` crate (draft 2020-12) against real output, on the fixtures and on the course's
//! real code.

use std::path::Path;

use serde_json::Value;

use crate::common::*;
use rtoracle::bench::grade::materialize_code;

fn schema(name: &str) -> jsonschema::Validator {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/schemas")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let value: Value = serde_json::from_str(&text).unwrap();
    jsonschema::draft202012::new(&value)
        .unwrap_or_else(|e| panic!("{}: not a valid schema: {e}", path.display()))
}

/// Asserts `doc` holds to `validator`, listing every place it does not.
fn assert_valid(validator: &jsonschema::Validator, doc: &Value, what: &str) {
    let errors: Vec<String> = validator
        .iter_errors(doc)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .take(10)
        .collect();
    assert!(errors.is_empty(), "{what}:\n{}", errors.join("\n"));
}

fn check_json(dir: &Path, extra: &[&str]) -> Value {
    let out = rtoracle()
        .args(["check", "--json"])
        .args(extra)
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        matches!(out.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn report_json(dir: &Path, out: &Path, rubric: &str) -> Value {
    let run = rtoracle()
        .args(["grade", "--format", "json", "--rubric", rubric])
        .arg(dir)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap()
}

/// A rubric of `week`'s built-in one with its images judged on uploads (nothing rendered: the
/// shape of the document is what is tested here).
fn uploads_rubric(week: &str, dir: &Path) -> String {
    let out = rtoracle()
        .args(["grade", "--print-rubric", week])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let text: String = text
        .lines()
        .filter(|l| {
            !["source =", "main_function =", "spp =", "render_seconds ="]
                .iter()
                .any(|k| l.starts_with(k))
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let path = dir.join(format!("{week}-uploads.toml"));
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn check_json_has_one_shape_for_week_4_and_later_weeks() {
    let validator = schema("check.schema.json");
    let tmp = tempfile::tempdir().unwrap();
    let week4 = tmp.path().join("sphere-bug");
    materialize_code("sphere-bug", &week4).unwrap();
    let doc = check_json(&week4, &[]);
    assert_valid(&validator, &doc, "check --json, week 4");
    assert_eq!(
        (&doc["schema"], &doc["version"], &doc["week"]),
        (
            &Value::from("rtoracle-check"),
            &Value::from(2),
            &Value::from(4)
        )
    );
    assert!(doc["functions"].is_null() && doc["score"].is_null());
    assert_eq!(doc["verdict"], "fail");
    // A later week's course-shaped solution: the same document, with its functions.
    let week6 = tmp.path().join("week06");
    copy_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks/week06/solution"),
        &week6,
    );
    let doc = check_json(&week6, &[]);
    assert_valid(&validator, &doc, "check --json, week 6");
    assert_eq!(doc["week"], 6);
    assert!(doc["functions"]["functions"].as_array().unwrap().len() > 3);
    // The schema refuses the old layouts: week 4's report at the top, a later week without
    // a version.
    let mut old = doc.clone();
    old.as_object_mut().unwrap().remove("version");
    assert!(!validator.is_valid(&old));
    assert!(!validator.is_valid(&doc["intersections"]));
}

#[test]
fn report_json_holds_to_its_schema_for_week_4() {
    let validator = schema("report.schema.json");
    let tmp = tempfile::tempdir().unwrap();
    let rubric = uploads_rubric("week04", tmp.path());
    for name in ["sphere-bug", "unimportable", "honest"] {
        let dir = tmp.path().join(name);
        materialize_code(name, &dir).unwrap();
        let doc = report_json(&dir, &tmp.path().join(format!("{name}-out")), &rubric);
        assert_valid(&validator, &doc, name);
        assert_eq!(doc["schema"], "rtoracle-grade-report");
        assert_eq!(doc["version"], 2);
    }
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn the_course_s_real_code_gives_documents_of_the_schemas() {
    let check = schema("check.schema.json");
    let report = schema("report.schema.json");
    let tmp = tempfile::tempdir().unwrap();
    for (week, tree) in [(4, CourseTree::Solution), (9, CourseTree::Solution)] {
        let Some((_guard, dir)) = course_week_copy(
            "the_course_s_real_code_gives_documents_of_the_schemas",
            week,
            tree,
        ) else {
            return;
        };
        let doc = check_json(&dir, &[]);
        assert_valid(
            &check,
            &doc,
            &format!("check --json, the course's week {week}"),
        );
        assert_eq!(doc["week"], week);
        let rubric = uploads_rubric(&format!("week{week:02}"), tmp.path());
        let out = tmp.path().join(format!("week{week}-out"));
        let doc = report_json(&dir, &out, &rubric);
        assert_valid(
            &report,
            &doc,
            &format!("report.json, the course's week {week}"),
        );
    }
}
