//! One door for untrusted text: a hostile payload (a code fence, a `# Score: 100 / 100`
//! heading, HTML with `onerror`, an ANSI escape, NUL, bidi controls, a spreadsheet formula) sent
//! through every path a candidate's text takes (an import that raises, the intersection vectors,
//! a function check, a sampler, the grader's render, an adapter's hello name and answers, a
//! batch's folder name) reaches every format (Markdown, HTML, JUnit, CSV, JSON, the terminal)
//! only escaped for it: no heading or HTML tag is made, no control character is sent, no
//! formula is written into a cell, and JSON carries the text as data.

use std::path::Path;

use pulldown_cmark::{Event, HeadingLevel, Parser, Tag};
use serde_json::Value;

use crate::common::*;
use rtoracle::bench::grade::{fixtures_dir, materialize};

/// What every hostile message says: a fence, a heading, HTML, ANSI, NUL, bidi, a formula.
const PAYLOAD: &str = "=HYPERLINK(\"http://e\")\n```\n# Score: 100 / 100\n<img src=x onerror=alert(1)>\n\u{1b}[2J\u{1b}[31mred\u{0}\u{202e}txt.exe";

/// The payload as a Python string literal.
fn python_literal() -> String {
    serde_json::to_string(PAYLOAD).unwrap()
}

/// Characters that must never be written raw to a text format: C0 controls but newline and
/// tab, DEL, C1, and the bidi and zero-width controls.
fn raw_control(text: &str) -> Option<char> {
    text.chars().find(|&c| {
        (c.is_control() && c != '\n' && c != '\t' && c != '\r')
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
    })
}

/// Asserts `md` is Markdown the payload did not forge: no heading saying a score, no HTML, no
/// raw control character.
fn assert_markdown(md: &str, what: &str) {
    assert_eq!(
        raw_control(md),
        None,
        "{what}: a raw control character:\n{md}"
    );
    let mut in_heading = false;
    for event in Parser::new(md) {
        match event {
            Event::Start(Tag::Heading { level, .. }) => in_heading = level <= HeadingLevel::H6,
            Event::End(_) => in_heading = false,
            Event::Text(t) if in_heading => {
                assert!(
                    !t.contains("Score: 100 / 100"),
                    "{what}: a forged heading:\n{md}"
                )
            }
            Event::Html(h) | Event::InlineHtml(h) => {
                panic!("{what}: raw HTML {h:?}:\n{md}")
            }
            _ => {}
        }
    }
}

/// Asserts a text for the terminal holds no raw control character.
fn assert_terminal(text: &str, what: &str) {
    assert_eq!(raw_control(text), None, "{what}: {text:?}");
}

/// Asserts `xml` is well-formed JUnit without raw control characters.
fn assert_junit(xml: &str, what: &str) {
    assert_eq!(raw_control(xml), None, "{what}");
    roxmltree::Document::parse(xml).unwrap_or_else(|e| panic!("{what}: not XML: {e}"));
}

/// Inserts `line` as the first line of the body of the first `def NAME(` of the `.py` files of
/// `dir` (after the line starting with `after`, when given).
fn insert_into(dir: &Path, name: &str, after: Option<&str>, line: &str) {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "py"))
        .collect();
    files.sort();
    if insert_first_in_def(&files, name, after, line).is_none() {
        panic!("no def {name} in {}", dir.display());
    }
}

/// Every report of `out` and the terminal's text, checked for their formats; returns
/// report.json.
fn assert_reports(out: &Path, terminal: &str, what: &str) -> Value {
    let md = std::fs::read_to_string(out.join("feedback.md")).unwrap();
    assert_markdown(&md, &format!("{what}: feedback.md"));
    let results: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_markdown(
        results["output"].as_str().unwrap(),
        &format!("{what}: results.json"),
    );
    for t in results["tests"].as_array().unwrap() {
        assert_markdown(
            t["output"].as_str().unwrap(),
            &format!("{what}: results.json test"),
        );
    }
    assert_junit(
        &std::fs::read_to_string(out.join("junit.xml")).unwrap(),
        &format!("{what}: junit.xml"),
    );
    let report_text = std::fs::read_to_string(out.join("report.json")).unwrap();
    // JSON carries the text as data: escaped by the JSON writer, never a raw C0 control.
    assert!(
        !report_text.chars().any(|c| c.is_control() && c != '\n'),
        "{what}: report.json"
    );
    assert_terminal(terminal, &format!("{what}: the terminal"));
    serde_json::from_str(&report_text).unwrap()
}

/// The payload raised on every path of a week-9 submission: the sphere's intersect (the
/// vectors and the grader's render), a function check (`ONB.local`), a sampler; and in another submission
/// at import. Every report is checked, and the payload is there as data in report.json.
#[test]
fn a_hostile_exception_on_every_path_reaches_every_format_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("week09");
    copy_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks/week09/solution"),
        &dir,
    );
    let raise = format!("raise RuntimeError({})", python_literal());
    insert_into(&dir, "intersect", Some("class Sphere"), &raise);
    insert_into(&dir, "local", Some("class ONB"), &raise);
    insert_into(&dir, "random_cosine_hemisphere_on_z", None, &raise);
    let out = tmp.path().join("out");
    let run = rtoracle()
        .args(["grade", "--rubric", "week09"])
        .arg(&dir)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let terminal =
        String::from_utf8_lossy(&run.stdout).to_string() + &String::from_utf8_lossy(&run.stderr);
    let report = assert_reports(&out, &terminal, "week 9");
    // The payload is in report.json as data (the JSON writer's escaping), on each path.
    let text = report.to_string();
    let payload_json = serde_json::to_string(PAYLOAD).unwrap();
    let inner = &payload_json[1..payload_json.len() - 1];
    assert!(text.contains(inner), "the payload as data");
    let check = rtoracle().arg("check").arg(&dir).output().unwrap();
    assert_terminal(&String::from_utf8_lossy(&check.stdout), "check");
    assert_terminal(&String::from_utf8_lossy(&check.stderr), "check's stderr");

    // At import.
    let sub = tmp.path().join("import");
    materialize("honest", &sub).unwrap();
    let object = std::fs::read_to_string(sub.join("RT_object.py")).unwrap();
    std::fs::write(sub.join("RT_object.py"), format!("{raise}\n{object}")).unwrap();
    let out = tmp.path().join("out-import");
    let run = rtoracle()
        .arg("grade")
        .arg(&sub)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(0));
    let terminal = String::from_utf8_lossy(&run.stdout).to_string();
    assert_reports(&out, &terminal, "import");
    let check = rtoracle().arg("check").arg(&sub).output().unwrap();
    assert_terminal(&String::from_utf8_lossy(&check.stdout), "check at import");
}

/// An adapter whose hello names it with the payload and whose every answer is an error saying
/// the payload: `check`'s text is clean, its JSON carries the text as data.
#[test]
fn a_hostile_adapter_name_and_answers_reach_check_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let script = tmp.path().join("hostile_adapter.py");
    std::fs::write(
        &script,
        format!(
            r#"import json, sys
P = {p}
for line in sys.stdin:
    req = json.loads(line)
    if req.get("op") == "hello":
        out = {{"name": P, "protocol": 1, "shapes": ["sphere", "quad", "triangle"]}}
    else:
        out = {{"id": req.get("id"), "error": {{"type": P, "message": P, "traceback": P, "file": P, "line": 7, "function": P, "code": P}}}}
    sys.stdout.write(json.dumps(out) + "\n")
    sys.stdout.flush()
"#,
            p = python_literal()
        ),
    )
    .unwrap();
    let adapter = format!("python3 {}", script.display());
    let text = rtoracle()
        .args(["check", "--adapter", &adapter, "--vectors"])
        .arg(fixtures_dir().join("vectors.jsonl"))
        .output()
        .unwrap();
    assert_eq!(
        text.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&text.stderr)
    );
    assert_terminal(&String::from_utf8_lossy(&text.stdout), "check --adapter");
    assert_terminal(
        &String::from_utf8_lossy(&text.stderr),
        "check --adapter's stderr",
    );
    let json = rtoracle()
        .args(["check", "--json", "--adapter", &adapter, "--vectors"])
        .arg(fixtures_dir().join("vectors.jsonl"))
        .output()
        .unwrap();
    let doc: Value = serde_json::from_slice(&json.stdout).unwrap();
    let failure = &doc["intersections"]["failures"][0];
    assert_eq!(failure["actual"]["error"]["message"], PAYLOAD);
    assert_eq!(failure["actual"]["error"]["line"], 7);
}

/// A batch whose folder is named with the payload (all a file name can hold: no NUL or `/`):
/// the gradebook's cell is no formula, the summary and every report are clean, the terminal too.
#[test]
fn a_hostile_folder_name_reaches_the_gradebook_and_summary_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let subs = tmp.path().join("subs");
    let name: String = PAYLOAD
        .chars()
        .filter(|c| *c != '\0' && *c != '/')
        .collect();
    let name = name.replace("http://e", "http:e");
    materialize("sphere-bug", &subs.join(&name)).unwrap();
    std::fs::write(
        tmp.path().join("uploads.toml"),
        rtoracle::grade::rubric::week04_uploads_toml(),
    )
    .unwrap();
    let run = rtoracle()
        .current_dir(tmp.path())
        .args([
            "grade",
            "--batch",
            "subs",
            "--rubric",
            "uploads.toml",
            "--vectors",
        ])
        .arg(fixtures_dir().join("vectors.jsonl"))
        .args(["--out", "out"])
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_terminal(&String::from_utf8_lossy(&run.stdout), "batch stdout");
    assert_terminal(&String::from_utf8_lossy(&run.stderr), "batch stderr");
    let out = tmp.path().join("out");
    let csv = std::fs::read_to_string(out.join("gradebook.csv")).unwrap();
    assert_eq!(raw_control(&csv), None, "{csv}");
    let row = csv.lines().nth(1).unwrap();
    // Quoted, defused with a leading `'` (OWASP), so no spreadsheet reads a formula.
    assert!(row.starts_with("\"'=HYPERLINK("), "{row}");
    assert_markdown(
        &std::fs::read_to_string(out.join("summary.md")).unwrap(),
        "summary.md",
    );
    assert_reports(&out.join(&name), "", "the folder's reports");
}

/// A candidate image whose file name is the payload (all a name can hold): `compare`'s summary
/// and its HTML report show it escaped.
#[test]
fn a_hostile_image_name_reaches_compare_s_html_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let name: String = PAYLOAD
        .chars()
        .filter(|c| *c != '\0' && *c != '/')
        .collect();
    let name = name.replace("http://e", "http:e") + ".png";
    let out = rtoracle()
        .current_dir(tmp.path())
        .args(["render", "week04-sphere", "--spp", "2", "-o", "x.png"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::rename(tmp.path().join("x.png"), tmp.path().join(&name)).unwrap();
    let run = rtoracle()
        .current_dir(tmp.path())
        .env("RTORACLE_CACHE_DIR", tmp.path().join("cache"))
        .args([
            "compare",
            &name,
            "--scene",
            "week04-sphere",
            "--spp",
            "2",
            "--report",
            "r",
        ])
        .output()
        .unwrap();
    assert!(matches!(run.status.code(), Some(0..=2)));
    assert_terminal(&String::from_utf8_lossy(&run.stdout), "compare stdout");
    assert_terminal(&String::from_utf8_lossy(&run.stderr), "compare stderr");
    if let Ok(html) = std::fs::read_to_string(tmp.path().join("r/index.html")) {
        assert_eq!(raw_control(&html), None);
        assert!(!html.contains("<img src=x"), "{html}");
        assert!(!html.contains("onerror=alert(1)>"), "{html}");
    }
}
