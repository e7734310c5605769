//! What a student reads: `feedback.md` and Gradescope's `results.json` of `rtoracle grade` on
//! real submissions (the repository's fixtures, and variants of the honest one made here), and
//! `rtoracle check`'s report in a student's folder.
//!
//! - the instructor's own solution at full marks reads no word "fail": the vectors where rounding
//!   decides come last, short, as differing "from the exact answer where rounding decides (not
//!   scored)", their repro giving the exact answer;
//! - a missing PNG is "missing" in the table and below;
//! - an exception names the file and line of the student's code, once;
//! - every Markdown output renders as its `output_format` says, and escapes only what Markdown
//!   would otherwise change (a backslash that makes no difference to the rendering is one too
//!   many).

use std::path::{Path, PathBuf};

use pulldown_cmark::{Event, Options, Parser, Tag};
use serde_json::Value;

use crate::common::*;
use rtoracle::bench::grade::{fixtures_dir, materialize, materialize_code};

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("feedback")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The week-4 rubric's two code groups alone (no image to render).
const CODE_ONLY: &str = r#"name = "code-only"
seed = 0

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

/// Grades `sub` (in `dir`) into `dir/out` with `extra` arguments; returns feedback.md and
/// results.json.
/// Grades `sub` in `dir` (with the uploads' variant of the built-in rubric unless `extra` names
/// a rubric: these tests are of the feedback's words, not of the grader's renders).
fn grade(dir: &Path, sub: &str, extra: &[&str]) -> (String, Value) {
    let mut args = vec!["grade", sub, "--out", "out"];
    if !extra.contains(&"--rubric") {
        std::fs::write(
            dir.join("uploads.toml"),
            rtoracle::grade::rubric::week04_uploads_toml(),
        )
        .unwrap();
        args.extend(["--rubric", "uploads.toml"]);
    }
    args.extend(extra);
    let out = run_in(dir, &args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let md = std::fs::read_to_string(dir.join("out/feedback.md")).unwrap();
    let gs = std::fs::read_to_string(dir.join("out/results.json")).unwrap();
    (md, serde_json::from_str(&gs).unwrap())
}

/// The small vector file of the grading tests (a few vectors a shape, fast).
fn basic_vectors() -> String {
    fixtures_dir()
        .join("vectors.jsonl")
        .to_string_lossy()
        .into_owned()
}

/// The `## ` headings of a Markdown text, in order.
fn sections(md: &str) -> Vec<&str> {
    md.lines().filter(|l| l.starts_with("## ")).collect()
}

/// Markdown as what a CommonMark renderer with GitHub's tables, strikethrough and math makes
/// of it: its events, with adjacent runs of text joined (an escape splits a run, and says
/// nothing by that).
fn render(md: &str) -> Vec<String> {
    let options = Options::ENABLE_TABLES | Options::ENABLE_STRIKETHROUGH | Options::ENABLE_MATH;
    let mut out: Vec<String> = Vec::new();
    let mut text: Option<String> = None;
    for event in Parser::new_ext(md, options) {
        match event {
            Event::Text(t) => text.get_or_insert_with(String::new).push_str(&t),
            other => {
                if let Some(t) = text.take() {
                    out.push(format!("text {t:?}"));
                }
                out.push(format!("{other:?}"));
            }
        }
    }
    if let Some(t) = text {
        out.push(format!("text {t:?}"));
    }
    out
}

/// Characters whose meaning depends on a partner elsewhere on the line or on where the line
/// sits (emphasis, code, strikethrough, links, tables, math, headings): escaping one of them
/// where it happens to change nothing is the safe, simple choice. Escaping anything else where
/// it changes nothing is over-escaping.
const CONTEXTUAL: &[char] = &['*', '_', '~', '`', '[', ']', '|', '$', '#', '\\'];

/// The backslash escapes of `md` (outside code blocks and code spans) that change nothing in its
/// rendering and escape a character that never needs it there: each removed in turn, the
/// renderings are compared.
fn needless_escapes(md: &str) -> Vec<String> {
    let rendered = render(md);
    // Byte ranges of code (fenced blocks and spans), where a backslash is text.
    let mut code = Vec::new();
    for (event, range) in Parser::new_ext(md, Options::ENABLE_TABLES).into_offset_iter() {
        // A start's range is the whole block.
        if matches!(event, Event::Start(Tag::CodeBlock(_)) | Event::Code(_)) {
            code.push(range);
        }
    }
    let bytes = md.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i + 1 < bytes.len() {
        if bytes[i] == b'\\' && bytes[i + 1].is_ascii_punctuation() {
            let escaped = bytes[i + 1] as char;
            let in_code = code.iter().any(|r| r.contains(&i));
            if !in_code && !CONTEXTUAL.contains(&escaped) {
                let without = format!("{}{}", &md[..i], &md[i + 1..]);
                if render(&without) == rendered {
                    let line_start = md[..i].rfind('\n').map_or(0, |p| p + 1);
                    let line_end = md[i..].find('\n').map_or(md.len(), |p| i + p);
                    found.push(format!("\\{escaped} in: {}", &md[line_start..line_end]));
                }
            }
            i += 2;
        } else {
            i += 1;
        }
    }
    found
}

/// Every Markdown output of `results.json` says it is Markdown and escapes nothing needlessly.
fn assert_gradescope_markdown(gs: &Value) {
    assert_eq!(gs["output_format"], "md", "{gs:#}");
    let mut outputs = vec![gs["output"].as_str().unwrap().to_string()];
    for t in gs["tests"].as_array().unwrap() {
        assert_eq!(t["output_format"], "md", "{t:#}");
        outputs.push(t["output"].as_str().unwrap().to_string());
    }
    for o in outputs {
        let needless = needless_escapes(&o);
        assert!(needless.is_empty(), "{needless:#?}\n\nin:\n{o}");
    }
}

#[test]
fn the_instructor_s_solution_at_full_marks_reads_no_failure() {
    let dir = scratch("honest");
    materialize("honest", &dir.join("honest")).unwrap();
    // The built-in suite, with its ambiguous vectors, on which the course's own formulas differ
    // from the exact answer now and then.
    let (md, gs) = grade(&dir, "honest", &[]);
    assert!(md.starts_with("# Feedback for honest: 100 / 100\n"), "{md}");
    assert!(!md.to_lowercase().contains("fail"), "{md}");
    for t in gs["tests"].as_array().unwrap() {
        let output = t["output"].as_str().unwrap().to_lowercase();
        assert!(!output.contains("fail"), "{t:#}");
        assert_eq!(t["status"], "passed", "{t:#}");
    }
    // The vectors where rounding decides are there, last and short, with the exact answer.
    let heads = sections(&md);
    assert_eq!(
        heads.last(),
        Some(&"## Where rounding decides (not scored)"),
        "{md}"
    );
    let note = md
        .split("## Where rounding decides (not scored)")
        .nth(1)
        .unwrap();
    assert!(
        note.contains("differ from the exact answer where rounding decides (not scored)"),
        "{note}"
    );
    assert!(note.contains("# expected: exactly a "), "{note}");
    assert!(!note.contains("expected: ambiguous"), "{note}");
    assert!(
        note.matches("```python").count() <= 2,
        "one repro a group: {note}"
    );
    // On Gradescope too: after every scored test.
    let tests = gs["tests"].as_array().unwrap();
    let first_note = tests
        .iter()
        .position(|t| t["max_score"] == 0.0)
        .expect("a note on ambiguous vectors");
    assert!(tests[first_note..].iter().all(|t| t["max_score"] == 0.0));
    assert_gradescope_markdown(&gs);
}

#[test]
fn a_missing_png_is_missing_in_the_table_and_below() {
    let dir = scratch("missing");
    materialize("missing-image", &dir.join("missing-image")).unwrap();
    let (md, gs) = grade(&dir, "missing-image", &["--vectors", &basic_vectors()]);
    assert!(
        md.contains("| Sphere scene image (week04_sphere.png) | 0 / 20 | missing |"),
        "{md}"
    );
    assert!(
        md.contains("week04_sphere.png is missing from the submission"),
        "{md}"
    );
    assert!(!md.contains("could not be checked"), "{md}");
    let test = gs["tests"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == "Sphere scene image (week04_sphere.png)")
        .unwrap();
    assert!(
        test["output"].as_str().unwrap().contains("missing"),
        "{test:#}"
    );
}

/// The honest submission's code with every intersection calling a helper that raises a
/// NameError; returns the line of the helper's `return` (what Python reports).
fn name_error_submission(sub: &Path) -> usize {
    materialize_code("honest", sub).unwrap();
    let path = sub.join("RT_object.py");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text.replace(
        "    def intersect(self, rRay, cInterval):\n",
        "    def intersect(self, rRay, cInterval):\n        _helper()\n",
    );
    let text = format!("{text}\n\ndef _helper():\n    return undefined_name\n");
    std::fs::write(&path, &text).unwrap();
    text.lines()
        .position(|l| l == "    return undefined_name")
        .unwrap()
        + 1
}

#[test]
fn an_exception_names_its_file_and_line_once() {
    let dir = scratch("name-error");
    let line = name_error_submission(&dir.join("OwlVi+RayTracing"));
    std::fs::write(dir.join("code.toml"), CODE_ONLY).unwrap();
    let (md, gs) = grade(
        &dir,
        "OwlVi+RayTracing",
        &["--rubric", "code.toml", "--vectors", &basic_vectors()],
    );
    let place = format!("RT_object.py, line {line}, in \\_helper");
    assert!(md.contains(&format!("Python raised it in {place}")), "{md}");
    assert!(md.contains("return undefined_name"), "{md}");
    // Said once: the second section points to the first.
    assert_eq!(
        md.matches("name 'undefined_name' is not defined").count(),
        1,
        "{md}"
    );
    assert!(
        md.contains("raised the same error as in Sphere intersection above"),
        "{md}"
    );
    // The folder's name as it is (a `+` changes nothing in Markdown).
    assert!(
        md.starts_with("# Feedback for OwlVi+RayTracing: 0 / 60\n"),
        "{md}"
    );
    let needless = needless_escapes(&md);
    assert!(needless.is_empty(), "{needless:#?}\n\n{md}");
    // Gradescope names the place too.
    let sphere = &gs["tests"][0];
    assert!(
        sphere["output"].as_str().unwrap().contains(&place),
        "{sphere:#}"
    );
    assert_gradescope_markdown(&gs);
}

#[test]
fn results_json_renders_as_its_output_format_says() {
    // A wrong normal: the message holds brackets, an equals sign, dots and parentheses.
    let dir = scratch("normal");
    let sub = dir.join("normal-bug");
    materialize_code("honest", &sub).unwrap();
    let path = sub.join("RT_object.py");
    let text = std::fs::read_to_string(&path).unwrap();
    let bug = text.replace(
        "outward = (point - self.center) / self.radius",
        "outward = (point - self.center)",
    );
    assert_ne!(bug, text, "the honest sphere's normal line moved");
    std::fs::write(&path, bug).unwrap();
    std::fs::write(dir.join("code.toml"), CODE_ONLY).unwrap();
    let (md, gs) = grade(&dir, "normal-bug", &["--rubric", "code.toml"]);
    let sphere = gs["tests"][0]["output"].as_str().unwrap();
    assert!(sphere.contains("normal"), "{sphere}");
    assert_gradescope_markdown(&gs);
    let needless = needless_escapes(&md);
    assert!(needless.is_empty(), "{needless:#?}\n\n{md}");
}

/// The detector of needless escapes finds what the issue saw, and lets needed ones be.
#[test]
fn needless_escapes_are_found_and_needed_ones_kept() {
    let md = "normal \\= \\[0\\.28\\] \\(the unit normal\\) OwlVi\\+RayTracing\n";
    let found = needless_escapes(md);
    let chars: Vec<&str> = found.iter().map(|f| &f[..2]).collect();
    assert_eq!(chars, ["\\=", "\\.", "\\(", "\\)", "\\+"], "{found:#?}");
    // A list marker at the start, a link's brackets: needed (or contextual).
    assert!(needless_escapes("\\- item\n\n\\[x\\](y)\n").is_empty());
    // In code, a backslash is text.
    assert!(needless_escapes("```text\na \\= b\n```\n").is_empty());
}

/// A student's `rtoracle check` in the folder of a submission whose every triangle failure is
/// one known mistake: the diagnosis, its fix and one reproduction (not ten), pasteable as it is;
/// the winding line says either winding is accepted; the table says what `total` counts.
#[test]
fn check_after_a_diagnosis_shows_the_fix_and_one_repro() {
    let dir = rtoracle::bench::harness::assemble_fixture("bug_triangle_absolute_epsilon").unwrap();
    let out = run_in(dir.path(), &["check"]);
    let text = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{text}\n{stderr}");
    assert!(
        text.contains("your triangle failures are exactly those of an absolute epsilon"),
        "{text}"
    );
    assert!(
        text.contains("fix for the triangle failures: scale the epsilon by the triangle's size"),
        "{text}"
    );
    assert_eq!(text.matches("reproduce:").count(), 1, "{text}");
    assert!(
        text.lines()
            .any(|l| l.starts_with("triangles: your triangles face ")
                && l.contains("either winding is accepted")),
        "{text}"
    );
    assert!(
        text.contains("(total: the definite vectors, which are judged; the ambiguous and any ones are run and not counted in it)"),
        "{text}"
    );
    // The reproduction as a file holds it: its lines start at the margin.
    assert!(
        text.lines()
            .any(|l| l == "from RT_utility import Vec3, Interval"),
        "{text}"
    );
    // An instructor's warning has no place in a student's check.
    assert!(!text.contains("public seed") && !stderr.contains("public seed"));
}

/// Every mistake of the catalogue comes with its fix.
#[test]
fn every_catalogued_mistake_has_a_fix() {
    let missing: Vec<&str> = rtoracle::oracle::mistakes::buggy()
        .into_iter()
        .chain(rtoracle::oracle::mistakes::buggy_extra())
        .filter(|v| !v.honest)
        .map(|v| v.name)
        .filter(|name| rtoracle::candidate::judging::diagnose::fix(name).is_none())
        .collect();
    assert!(missing.is_empty(), "no fix for {missing:?}");
}

/// A rubric that renders the sphere scene from the code at 1 sample per pixel (quick), and
/// judges nothing else.
const RENDER_SPHERE: &str = r#"name = "render-sphere"

[[group]]
id = "image.week04-sphere"
name = "Sphere scene image (week04_sphere.png)"
kind = "image"
file = "week04_sphere.png"
scene = "week04-sphere"
source = "render"
spp = 1
render_seconds = 600
points = 20
"#;

/// The reports' words for one check (feedback.md, the Gradescope test's output, junit.xml's
/// message and report.json's), all of them.
fn words_of(out: &Path, name: &str) -> String {
    let md = std::fs::read_to_string(out.join("feedback.md")).unwrap();
    let gs: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let test = gs["tests"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == name)
        .unwrap_or_else(|| panic!("no test {name}: {gs:#}"));
    let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
    format!("{md}\n{}\n{junit}", test["output"].as_str().unwrap())
}

/// A missing upload is called missing, with what it costs under the rubric in force: its
/// group's points under a rubric that judges uploads; nothing under one that renders the code
/// (whatever the render gives). Never "could not be checked".
fn assert_missing_costs(sub: &Path, dir: &Path) {
    let name = "Sphere scene image (week04_sphere.png)";
    std::fs::write(
        dir.join("uploads.toml"),
        rtoracle::grade::rubric::week04_uploads_toml(),
    )
    .unwrap();
    std::fs::write(dir.join("render.toml"), RENDER_SPHERE).unwrap();
    for (rubric, cost) in [
        (
            "uploads.toml",
            "it costs this group's 20 points, since this rubric judges the uploaded image",
        ),
        (
            "render.toml",
            "is missing from the submission; it costs nothing: the grader renders your code",
        ),
    ] {
        let out = dir.join(format!("out-{rubric}"));
        let run = rtoracle()
            .current_dir(dir)
            .arg("grade")
            .arg(sub)
            .args(["--rubric", rubric, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(
            run.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let words = words_of(&out, name);
        assert!(
            words.contains("week04_sphere.png is missing from the submission"),
            "{rubric}: {words}"
        );
        assert!(words.contains(cost), "{rubric}: {words}");
        assert!(!words.contains("could not be checked"), "{rubric}: {words}");
        let md = std::fs::read_to_string(out.join("feedback.md")).unwrap();
        if rubric == "uploads.toml" {
            assert!(
                md.contains(&format!("| {name} | 0 / 20 | missing |")),
                "{md}"
            );
        }
    }
}

#[test]
fn a_missing_upload_says_what_it_costs_under_the_rubric_in_force() {
    let dir = scratch("missing-costs");
    materialize("missing-image", &dir.join("missing-image")).unwrap();
    assert_missing_costs(&dir.join("missing-image"), &dir);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn a_missing_upload_of_the_course_s_code_says_what_it_costs() {
    let Some((_guard, sub)) = course_week_copy(
        "a_missing_upload_of_the_course_s_code_says_what_it_costs",
        4,
        CourseTree::Solution,
    ) else {
        return;
    };
    std::fs::remove_file(sub.join("week04_sphere.png")).unwrap();
    let dir = scratch("missing-costs-course");
    assert_missing_costs(&sub, &dir);
}
