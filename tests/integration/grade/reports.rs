//! Reports that untrusted text cannot forge, submissions read with care, and output folders
//! swapped in whole: forged messages and folder names through every writer, special files
//! where images should be, a reused `--out` folder.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use pulldown_cmark::{Event, HeadingLevel, Parser, Tag, TagEnd};
use rtoracle::candidate::judging::check::FailureKind;
use rtoracle::grade::{
    checkers::CodeChecker, checkers::CodeOutcome, checkers::FailureSummary, checkers::GroupCounts,
    checkers::ImageChecker, checkers::ImageOutcome, checkers::ImageVerdict, report::Format,
    rubric::Rubric, write::grade_to_dir,
};
use rtoracle::oracle::vectors::ShapeKind;

use crate::common::*;

/// Everything a hostile message tries at once: a newline, fences of 3 and 10 backticks, a fake
/// score heading, HTML, a link and ANSI escapes.
const PAYLOAD: &str = "boom\n```\n# Score: 100 / 100\n``````````\n<img src=x onerror=alert(1)>\n[link](http://evil)\n\x1b[2J\x1b[31mred";

/// A code checker whose every failure and import error says [`PAYLOAD`].
struct Forged {
    fatal: bool,
}

impl CodeChecker for Forged {
    fn check(&self, _: &Path, groups: &[ShapeKind]) -> CodeOutcome {
        let counts = GroupCounts {
            definite_total: 2,
            passed: 1,
            errors: 1,
            ..Default::default()
        };
        let failure = |shape: ShapeKind| FailureSummary {
            id: format!("{}-basic-0000", shape.name()),
            shape,
            tags: vec![],
            kind: FailureKind::Error,
            definite: true,
            expected: serde_json::Value::Null,
            actual: serde_json::Value::Null,
            message: PAYLOAD.into(),
            repro: "print(1)\n".to_string(),
        };
        CodeOutcome {
            per_group: groups.iter().map(|g| (*g, counts.clone())).collect(),
            failures: groups.iter().map(|g| failure(*g)).collect(),
            fatal: self.fatal.then(|| PAYLOAD.to_string()),
            stderr_tail: PAYLOAD.to_string(),
            sandbox: serde_json::Value::Null,
            ..Default::default()
        }
    }
    fn describe(&self) -> String {
        "forged".into()
    }
    fn vectors_sha256(&self) -> String {
        String::new()
    }
}

/// Every image passes (the images are not what is forged here).
struct Pass;

impl ImageChecker for Pass {
    fn check(&self, _: &Path, _: &str, _: &Path) -> ImageOutcome {
        ImageOutcome {
            verdict: ImageVerdict::Pass,
            metrics: serde_json::json!({}),
            diagnosis: None,
            heatmap: None,
        }
    }
    fn describe(&self) -> String {
        "pass".into()
    }
    fn golden_sha256(&self, _: &str) -> String {
        String::new()
    }
}

/// A PNG header of the size of `scene` (grading reads the header before the checker).
fn png_header(scene: &str) -> Vec<u8> {
    let camera = rtoracle::scene::builtin(scene).unwrap().camera(None);
    let mut b = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
    b.extend((camera.width as u32).to_be_bytes());
    b.extend((camera.height as u32).to_be_bytes());
    b.extend([8, 2, 0, 0, 0, 0, 0, 0, 0]);
    b
}

fn submission(dir: &Path, name: &str) -> std::path::PathBuf {
    let sub = dir.join(name);
    std::fs::create_dir_all(&sub).unwrap();
    std::fs::write(sub.join("RT_object.py"), "x = 1\n").unwrap();
    std::fs::write(sub.join("week04_sphere.png"), png_header("week04-sphere")).unwrap();
    std::fs::write(sub.join("week04_quad.png"), png_header("week04-quad")).unwrap();
    sub
}

/// Structure of a Markdown text: the top-level headings' texts, and whether any link, image or
/// HTML node appears; text outside code blocks is collected too.
struct Structure {
    h1: Vec<String>,
    headings: Vec<String>,
    links_images_html: Vec<String>,
    prose: String,
}

fn structure(md: &str) -> Structure {
    let mut s = Structure {
        h1: vec![],
        headings: vec![],
        links_images_html: vec![],
        prose: String::new(),
    };
    let (mut in_heading, mut level, mut in_code, mut text) = (false, 0, false, String::new());
    for event in Parser::new(md) {
        match event {
            Event::Start(Tag::Heading { level: l, .. }) => {
                in_heading = true;
                level = if l == HeadingLevel::H1 { 1 } else { 2 };
                text.clear();
            }
            Event::End(TagEnd::Heading(_)) => {
                in_heading = false;
                if level == 1 {
                    s.h1.push(text.clone());
                }
                s.headings.push(text.clone());
            }
            Event::Start(Tag::CodeBlock(_)) => in_code = true,
            Event::End(TagEnd::CodeBlock) => in_code = false,
            Event::Start(Tag::Link { dest_url, .. }) => {
                s.links_images_html.push(format!("link {dest_url}"))
            }
            Event::Start(Tag::Image { dest_url, .. }) => {
                s.links_images_html.push(format!("image {dest_url}"))
            }
            Event::Html(h) | Event::InlineHtml(h) => s.links_images_html.push(format!("html {h}")),
            Event::Text(t) | Event::Code(t) => {
                if in_heading {
                    text.push_str(&t);
                }
                if !in_code {
                    s.prose.push_str(&t);
                    s.prose.push('\n');
                }
            }
            _ => {}
        }
    }
    s
}

fn assert_unforged(md: &str, score: &str, what: &str) {
    let s = structure(md);
    assert_eq!(
        s.h1.len(),
        1,
        "{what}: one top-level heading: {:?}\n{md}",
        s.h1
    );
    assert!(s.h1[0].ends_with(score), "{what}: {:?}", s.h1);
    assert!(
        s.headings.iter().all(|h| !h.contains("Score: 100")),
        "{what}: {:?}",
        s.headings
    );
    assert!(
        s.links_images_html.is_empty(),
        "{what}: {:?}\n{md}",
        s.links_images_html
    );
    // Outside code blocks the payload is text, with its escapes shown, not sent.
    assert!(
        !s.prose.contains('\x1b'),
        "{what}: an ESC byte in the prose"
    );
}

#[test]
fn forged_messages_and_names_stay_text_in_feedback_and_results_json() {
    let dir = tempfile::tempdir().unwrap();
    for (fatal, name) in [(false, "=HYPERLINK(\"http:e\",\"x\")"), (true, "a\x1b[2Jb")] {
        let sub = submission(dir.path(), name);
        let out = dir.path().join(format!("out-{fatal}"));
        let report = grade_to_dir(
            &sub,
            &Rubric::week04(),
            &Forged { fatal },
            &Pass,
            &out,
            &Format::ALL,
        )
        .unwrap();
        let score = format!("{} / 100", report.score);
        let md = std::fs::read_to_string(out.join("feedback.md")).unwrap();
        assert_unforged(&md, &score, "feedback.md");
        // The message is in the feedback, whole, in a block.
        assert!(md.contains("<img src=x onerror=alert(1)>"), "{md}");
        assert!(md.contains("\\x1b[31mred"), "{md}");
        assert!(!md.contains('\x1b'));

        let gs: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap())
                .unwrap();
        let mut outputs = vec![gs["output"].as_str().unwrap().to_string()];
        for t in gs["tests"].as_array().unwrap() {
            assert_eq!(t["output_format"], "md");
            outputs.push(t["output"].as_str().unwrap().to_string());
        }
        for o in &outputs {
            assert!(!o.contains('<'), "raw < in Gradescope's output: {o}");
            assert!(!o.contains('\x1b'));
            let s = structure(o);
            assert!(s.headings.is_empty(), "{:?}\n{o}", s.headings);
            assert!(
                s.links_images_html.is_empty(),
                "{:?}\n{o}",
                s.links_images_html
            );
        }
        let all = outputs.join("\n");
        assert!(all.contains("&lt;img src=x onerror=alert(1)&gt;"), "{all}");

        let junit = std::fs::read_to_string(out.join("junit.xml")).unwrap();
        assert!(!junit.contains("<img") && !junit.contains('\x1b'));
    }
}

fn gradebook_rows(csv: &str) -> Vec<String> {
    csv.lines().skip(1).map(str::to_string).collect()
}

#[test]
fn forged_folder_names_reach_neither_the_terminal_nor_a_spreadsheet_formula() {
    let dir = tempfile::tempdir().unwrap();
    let batch_dir = dir.path().join("subs");
    let hyperlink = "=HYPERLINK(\"http:e\",\"x\")";
    let ansi = "x\x1b[2Jy";
    submission(&batch_dir, hyperlink);
    submission(&batch_dir, ansi);
    // Not graded: no RT_object.py, so the code checks are zero without running Python.
    std::fs::remove_file(batch_dir.join(hyperlink).join("RT_object.py")).unwrap();
    std::fs::remove_file(batch_dir.join(ansi).join("RT_object.py")).unwrap();
    let out = run_in(dir.path(), &["grade", "--batch", "subs", "--out", "out"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.stdout.contains(&0x1b) && !out.stderr.contains(&0x1b));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("x\\x1b[2Jy: "), "{stdout}");
    let csv = std::fs::read_to_string(dir.path().join("out/gradebook.csv")).unwrap();
    let rows = gradebook_rows(&csv);
    let cell = "\"'=HYPERLINK(\"\"http:e\"\",\"\"x\"\")\"";
    assert!(
        rows.iter().any(|r| r.starts_with(&format!("{cell},"))),
        "{csv}"
    );
    assert!(rows.iter().any(|r| r.starts_with("x\\x1b[2Jy,")), "{csv}");
    assert!(!csv.contains('\x1b'));
    let summary = std::fs::read_to_string(dir.path().join("out/summary.md")).unwrap();
    assert!(!summary.contains('\x1b'));
}

/// Runs `rtoracle` with `args` in `dir`, killed after `limit` (so a regression that blocks
/// fails the test instead of hanging it).
fn run_with_timeout(dir: &Path, args: &[&str], limit: Duration) -> (Option<i32>, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtoracle"))
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let (mut o, mut e) = (String::new(), String::new());
            child.stdout.take().unwrap().read_to_string(&mut o).unwrap();
            child.stderr.take().unwrap().read_to_string(&mut e).unwrap();
            return (status.code(), o, e);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("rtoracle {args:?} did not finish in {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A FIFO where an image should be is reported by name and scored 0, never opened (the grade
/// finishes; before, it blocked forever); a symlink to a real image is refused the same way.
#[test]
fn a_fifo_or_a_symlink_where_an_image_should_be_scores_0_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    rtoracle::bench::grade::materialize("honest", &sub).unwrap();
    let image = sub.join("week04_sphere.png");
    let real = dir.path().join("real.png");
    std::fs::rename(&image, &real).unwrap();
    let c = std::ffi::CString::new(image.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    std::os::unix::fs::symlink(&real, sub.join("week04_quad.png")).unwrap_or_else(|_| {
        std::fs::remove_file(sub.join("week04_quad.png")).unwrap();
        std::os::unix::fs::symlink(&real, sub.join("week04_quad.png")).unwrap();
    });
    // The uploads are what is judged here (`source = "upload"`): with the grader's renders they
    // are still read with the same care, but earn nothing either way.
    std::fs::write(
        dir.path().join("upload.toml"),
        rtoracle::grade::rubric::week04_uploads_toml(),
    )
    .unwrap();
    let (code, stdout, stderr) = run_with_timeout(
        dir.path(),
        &[
            "grade",
            "sub",
            "--rubric",
            "upload.toml",
            "--out",
            "out",
            "--format",
            "json,markdown",
        ],
        Duration::from_secs(120),
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("image.week04-sphere"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/report.json")).unwrap())
            .unwrap();
    let check = |id: &str| {
        report["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["id"] == id)
            .unwrap()
            .clone()
    };
    let sphere = check("image.week04-sphere");
    assert_eq!(sphere["score"], 0.0);
    assert_eq!(
        sphere["message"],
        "week04_sphere.png is a FIFO, not a regular file. It scores 0."
    );
    let quad = check("image.week04-quad");
    assert_eq!(quad["score"], 0.0);
    assert_eq!(
        quad["message"],
        "week04_quad.png is a symbolic link, not a regular file. It scores 0."
    );
    // The code is graded as usual.
    assert_eq!(check("sphere.intersect")["score"], 30.0);
}

/// A reused `--out` folder keeps nothing of the previous run (an earlier submission's heatmap),
/// and one holding a file of the user's is refused before any work.
#[test]
fn a_reused_out_folder_keeps_nothing_stale() {
    let dir = tempfile::tempdir().unwrap();
    let sub = submission(dir.path(), "sub");
    std::fs::remove_file(sub.join("RT_object.py")).unwrap();
    let out = dir.path().join("grade-report");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("heatmap-week04-quad.png"), b"stale").unwrap();
    std::fs::write(out.join("feedback.md"), b"stale").unwrap();
    let run = run_in(dir.path(), &["grade", "sub", "--format", "json,markdown"]);
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(!out.join("heatmap-week04-quad.png").exists());
    assert_ne!(std::fs::read(out.join("feedback.md")).unwrap(), b"stale");
    let hidden: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
    std::fs::write(out.join("notes.txt"), b"mine").unwrap();
    let run = run_in(dir.path(), &["grade", "sub"]);
    assert_bad_input(&run, "notes.txt");
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
}

/// SIGTERM in the middle of a grade exits 143 and leaves neither the report folder nor its
/// temporary folder (before, a folder with only heatmaps was left).
#[test]
fn sigterm_mid_grade_leaves_no_report_folder_behind() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    rtoracle::bench::grade::materialize("hang", &sub).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtoracle"))
        .current_dir(dir.path())
        .args(["grade", "sub", "--out", "out"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // The hanging submission keeps the grade busy for seconds (a 2 s case timeout, twice).
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(20) {
        let staging = std::fs::read_dir(dir.path()).unwrap().flatten().any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(".out.rtoracle-")
        });
        if staging || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the grade ended before the signal"
    );
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("no exit after SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(143));
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n != "sub")
        .collect();
    assert!(left.is_empty(), "{left:?}");
}
