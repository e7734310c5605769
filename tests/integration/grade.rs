//! `rtoracle grade` and `rtoracle autograder` end to end on this repository's fixture
//! submissions (tests/fixtures/submissions, images rendered at test time).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::common::*;
use rtoracle::grade::bench::{fixture_names, materialize};

struct Batch {
    subs: PathBuf,
    out: PathBuf,
    output: Output,
    /// (fixture, groups it must lose points in)
    fixtures: Vec<(String, Vec<String>)>,
}

/// Every fixture made a submission and graded once, as one batch.
fn batch() -> &'static Batch {
    static BATCH: OnceLock<Batch> = OnceLock::new();
    BATCH.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("grade-batch");
        let _ = std::fs::remove_dir_all(&root);
        let subs = root.join("subs");
        let fixtures: Vec<(String, Vec<String>)> = fixture_names()
            .into_iter()
            .map(|name| {
                let loses = materialize(&name, &subs.join(&name)).unwrap();
                (name, loses)
            })
            .collect();
        assert!(fixtures.len() >= 8, "{fixtures:?}");
        let out = root.join("out");
        // A vector file of these tests' own, so the snapshots of the feedback do not change
        // with the built-in suite (which the unit tests of the checker and
        // `one_submission_writes_the_chosen_formats_and_exits_0` run).
        let vectors = rtoracle::grade::bench::fixtures_dir().join("vectors.jsonl");
        // The uploaded images are judged (`source = "upload"`): what each fixture's images
        // cost is the point of `loses`; the grader's renders have tests of their own
        // (renders.rs).
        std::fs::write(
            root.join("upload.toml"),
            rtoracle::grade::rubric::week04_uploads_toml(),
        )
        .unwrap();
        let output = run_in(
            &root,
            &[
                "grade",
                "--batch",
                "subs",
                "--rubric",
                "upload.toml",
                "--out",
                "out",
                "--case-timeout-ms",
                "1000",
                "--vectors",
                vectors.to_str().unwrap(),
            ],
        );
        Batch {
            subs,
            out,
            output,
            fixtures,
        }
    })
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn honest_submissions_get_full_marks_and_each_bug_costs_exactly_its_groups() {
    let b = batch();
    assert!(
        b.output.status.success(),
        "{}",
        String::from_utf8_lossy(&b.output.stderr)
    );
    for (name, loses) in &b.fixtures {
        let report = read_json(&b.out.join(name).join("report.json"));
        let mut lost = BTreeSet::new();
        for c in report["checks"].as_array().unwrap() {
            let (score, max) = (
                c["score"].as_f64().unwrap(),
                c["max_score"].as_f64().unwrap(),
            );
            assert!(score >= 0.0 && score <= max, "{name}: {c}");
            if score < max {
                lost.insert(c["group"].as_str().unwrap().to_string());
            }
        }
        let expected: BTreeSet<String> = loses.iter().cloned().collect();
        assert_eq!(lost, expected, "{name} lost points in the wrong groups");
        if loses.is_empty() {
            assert_eq!(report["score"], report["max_score"], "{name}");
            assert_eq!(report["max_score"].as_f64(), Some(100.0));
        }
    }
}

#[test]
fn results_json_follows_gradescope_s_specification() {
    let b = batch();
    let top_allowed: BTreeSet<&str> = [
        "score",
        "execution_time",
        "output",
        "output_format",
        "test_output_format",
        "test_name_format",
        "visibility",
        "stdout_visibility",
        "extra_data",
        "tests",
        "leaderboard",
    ]
    .into();
    let test_allowed: BTreeSet<&str> = [
        "score",
        "max_score",
        "status",
        "name",
        "name_format",
        "number",
        "output",
        "output_format",
        "tags",
        "visibility",
        "extra_data",
    ]
    .into();
    let visibilities = ["visible", "hidden", "after_due_date", "after_published"];
    let formats = ["text", "html", "simple_format", "md", "ansi"];
    for (name, _) in &b.fixtures {
        let r = read_json(&b.out.join(name).join("results.json"));
        let top = r.as_object().unwrap();
        for k in top.keys() {
            assert!(top_allowed.contains(k.as_str()), "{name}: unknown key {k}");
        }
        assert!(r["execution_time"].is_number(), "{name}");
        assert!(r["output"].is_string());
        assert!(formats.contains(&r["output_format"].as_str().unwrap()));
        assert!(visibilities.contains(&r["visibility"].as_str().unwrap()));
        let tests = r["tests"].as_array().unwrap();
        assert!(!tests.is_empty());
        let mut sum = 0.0;
        let mut numbers = BTreeSet::new();
        for t in tests {
            for k in t.as_object().unwrap().keys() {
                assert!(
                    test_allowed.contains(k.as_str()),
                    "{name}: unknown test key {k}"
                );
            }
            assert!(t["name"].as_str().is_some_and(|s| !s.is_empty()));
            assert!(
                numbers.insert(t["number"].as_str().unwrap().to_string()),
                "numbers unique"
            );
            let (score, max) = (
                t["score"].as_f64().unwrap(),
                t["max_score"].as_f64().unwrap(),
            );
            assert!((0.0..=max).contains(&score), "{t}");
            let status = t["status"].as_str().unwrap();
            assert!(status == "passed" || status == "failed", "{status}");
            assert_eq!(
                status == "passed",
                score == max,
                "{name}: status vs score: {t}"
            );
            assert!(t["output"].is_string());
            assert!(formats.contains(&t["output_format"].as_str().unwrap()));
            assert!(visibilities.contains(&t["visibility"].as_str().unwrap()));
            assert!(t["tags"].as_array().unwrap().iter().all(Value::is_string));
            sum += score;
        }
        let score = r["score"].as_f64().unwrap();
        assert!(
            (score - sum).abs() < 1e-9,
            "{name}: score {score} != sum {sum}"
        );
        // The same score as the native report.
        let native = read_json(&b.out.join(name).join("report.json"));
        assert_eq!(native["score"].as_f64(), Some(score));
    }
}

#[test]
fn junit_xml_has_a_suite_per_group_and_a_case_per_check() {
    let b = batch();
    for (name, _) in &b.fixtures {
        let xml = std::fs::read_to_string(b.out.join(name).join("junit.xml")).unwrap();
        let doc = roxmltree::Document::parse(&xml).unwrap_or_else(|e| panic!("{name}: {e}"));
        let report = read_json(&b.out.join(name).join("report.json"));
        let checks = report["checks"].as_array().unwrap();
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "testsuites");
        let suites: Vec<_> = root
            .children()
            .filter(|n| n.has_tag_name("testsuite"))
            .collect();
        let groups: Vec<&str> = {
            let mut g: Vec<&str> = checks
                .iter()
                .map(|c| c["group"].as_str().unwrap())
                .collect();
            g.dedup();
            g
        };
        assert_eq!(
            suites
                .iter()
                .map(|s| s.attribute("name").unwrap())
                .collect::<Vec<_>>(),
            groups,
            "{name}"
        );
        let mut cases = 0;
        let mut bad = 0;
        for s in &suites {
            let tc: Vec<_> = s
                .children()
                .filter(|n| n.has_tag_name("testcase"))
                .collect();
            assert_eq!(
                s.attribute("tests").unwrap().parse::<usize>().unwrap(),
                tc.len()
            );
            let count = |tag: &str| {
                tc.iter()
                    .filter(|c| c.children().any(|n| n.has_tag_name(tag)))
                    .count()
            };
            assert_eq!(
                s.attribute("failures").unwrap().parse::<usize>().unwrap(),
                count("failure")
            );
            assert_eq!(
                s.attribute("errors").unwrap().parse::<usize>().unwrap(),
                count("error")
            );
            for c in &tc {
                let id = c.attribute("name").unwrap();
                let check = checks.iter().find(|k| k["id"] == id).unwrap();
                assert!(id.starts_with(s.attribute("name").unwrap()));
                let status = check["status"].as_str().unwrap();
                let child = c
                    .children()
                    .find(|n| n.is_element())
                    .map(|n| n.tag_name().name());
                let expected = match status {
                    "passed" => None,
                    "failed" => Some("failure"),
                    "error" => Some("error"),
                    _ => Some("skipped"),
                };
                assert_eq!(child, expected, "{name} {id}");
                // The text round-trips through the escaping.
                if let Some(node) = c.children().find(|n| n.is_element()) {
                    assert!(
                        node.text()
                            .unwrap()
                            .starts_with(check["message"].as_str().unwrap())
                    );
                    bad += 1;
                }
            }
            cases += tc.len();
        }
        assert_eq!(cases, checks.len());
        assert_eq!(
            root.attribute("failures")
                .unwrap()
                .parse::<usize>()
                .unwrap()
                + root.attribute("errors").unwrap().parse::<usize>().unwrap()
                + root.attribute("skipped").unwrap().parse::<usize>().unwrap(),
            bad
        );
    }
}

#[test]
fn report_json_holds_checks_repros_metrics_pictures_and_hashes() {
    let b = batch();
    let dir = b.out.join("sphere-bug");
    let r = read_json(&dir.join("report.json"));
    for c in r["checks"].as_array().unwrap() {
        for k in [
            "id",
            "name",
            "score",
            "max_score",
            "status",
            "message",
            "visibility",
            "tags",
        ] {
            assert!(!c[k].is_null(), "{k} in {c}");
        }
    }
    let sphere = &r["checks"][0];
    assert_eq!(sphere["id"], "sphere.intersect");
    // The fixture tries the far root first (its source says so): the diagnosis names it, as
    // data and beside the smallest failing case.
    assert_eq!(
        r["code"]["diagnosis"][0]["mistake_id"],
        "sphere-far-root-first"
    );
    assert_eq!(r["code"]["diagnosis"][0]["shape"], "sphere");
    assert!(sphere["message"].as_str().unwrap().contains(
        "Diagnosis: your sphere failures are exactly those of taking the far root first"
    ));
    let f = &sphere["failures"][0];
    assert_eq!(f["kind"], "mismatch");
    let repro = f["repro"].as_str().unwrap();
    // The reproduction runs in the submission folder and shows the wrong answer.
    let sub = b.subs.join("sphere-bug");
    std::fs::write(sub.join("repro.py"), repro).unwrap();
    // With the Python the grader used (the submission's RT_utility imports numpy and PIL).
    let python = rtoracle::candidate::bench::course_python().expect("the batch graded with it");
    let out = std::process::Command::new(python)
        .arg("repro.py")
        .current_dir(&sub)
        .output()
        .unwrap();
    std::fs::remove_file(sub.join("repro.py")).unwrap();
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(printed.starts_with("(6.0,"), "the far root: {printed}");
    // Images: metrics, and the heatmap on disk.
    let image = &r["checks"][2]["image"];
    assert_eq!(image["metrics"]["verdict"], "pass", "{}", image["metrics"]);
    assert!(dir.join(image["heatmap"].as_str().unwrap()).is_file());
    // Reproducibility.
    let rep = &r["reproducibility"];
    assert_eq!(rep["tool_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(
        rep["rubric_sha256"],
        sha256_hex(rtoracle::grade::rubric::WEEK04_RUBRIC.as_bytes())
    );
    assert_eq!(rep["vectors_sha256"].as_str().unwrap().len(), 64);
    assert_eq!(
        rep["goldens_sha256"]["week04-quad"].as_str().unwrap().len(),
        64
    );
    for file in ["RT_object.py", "RT_utility.py", "week04_sphere.png"] {
        assert_eq!(
            rep["submission_sha256"][file],
            sha256_hex(&std::fs::read(sub.join(file)).unwrap()),
            "{file}"
        );
    }
    // The sandbox: never root when a drop user exists.
    let sandbox = &r["code"]["sandbox"];
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } == 0 && sandbox["note"].is_null() {
        assert_ne!(sandbox["uid"], 0);
    }
}

#[test]
fn the_gradebook_has_a_row_per_submission_and_a_column_per_group() {
    let b = batch();
    let csv = std::fs::read_to_string(b.out.join("gradebook.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "submission,score,max_score,sphere,quad,image.week04-sphere,image.week04-quad,status"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), b.fixtures.len());
    for row in &rows {
        let report = read_json(&b.out.join(row[0]).join("report.json"));
        assert_eq!(
            row[1].parse::<f64>().unwrap(),
            report["score"].as_f64().unwrap()
        );
        let groups: f64 = row[3..7].iter().map(|x| x.parse::<f64>().unwrap()).sum();
        assert!(
            (groups - row[1].parse::<f64>().unwrap()).abs() < 1e-9,
            "{row:?}"
        );
        assert_eq!(row[7], "ok");
    }
    let honest = rows.iter().find(|r| r[0] == "honest").unwrap();
    assert_eq!(&honest[1..7], ["100", "100", "30", "30", "20", "20"]);
    let summary = std::fs::read_to_string(b.out.join("summary.md")).unwrap();
    assert!(summary.contains(&format!(
        "{} submissions, {} graded",
        rows.len(),
        rows.len()
    )));
    assert!(summary.contains("`sphere.intersect`") && summary.contains("could not be imported"));
    // stdout: one line per submission.
    let stdout = String::from_utf8_lossy(&b.output.stdout);
    assert!(stdout.contains("honest: 100 / 100"), "{stdout}");
}

#[test]
fn feedback_tells_the_student_what_failed() {
    let b = batch();
    for (name, _) in &b.fixtures {
        let md = std::fs::read_to_string(b.out.join(name).join("feedback.md")).unwrap();
        insta::assert_snapshot!(format!("feedback-{name}"), md);
    }
}

#[test]
fn one_submission_writes_the_chosen_formats_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    materialize("quad-bug", &dir.path().join("sub")).unwrap();
    let out = run_in(dir.path(), &["grade", "sub", "--format", "json,markdown"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report_dir = dir.path().join("grade-report");
    let mut files: Vec<String> = std::fs::read_dir(&report_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    files.sort();
    assert_eq!(
        files,
        [
            "feedback.md",
            "heatmap-week04-quad.png",
            "heatmap-week04-sphere.png",
            "report.json"
        ]
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("quad.intersect")
            && stdout.contains("sphere.intersect             30 / 30"),
        "{stdout}"
    );
    // The built-in rubric's seed is the public 0: one warning line says so, and the seed
    // stays in report.json, so the grade can be re-run.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        stderr
            .matches("warning: the rubric uses the public seed 0")
            .count(),
        1,
        "{stderr}"
    );
    let r = read_json(&report_dir.join("report.json"));
    let checker = r["reproducibility"]["code_checker"].as_str().unwrap();
    assert!(checker.contains("built-in suite seed 0"), "{checker}");
}

#[test]
fn grading_that_cannot_run_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["grade", "nope"]);
    assert_bad_input(&out, "nope: no such submission folder");
    assert!(!dir.path().join("grade-report").exists());
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let out = run_in(dir.path(), &["grade", "sub", "--rubric", "missing.toml"]);
    assert_bad_input(&out, "missing.toml: cannot read the rubric");
    std::fs::write(dir.path().join("bad.toml"), "name = 3\n").unwrap();
    let out = run_in(dir.path(), &["grade", "sub", "--rubric", "bad.toml"]);
    assert_bad_input(&out, "bad.toml: not a valid rubric");
    let out = run_in(dir.path(), &["grade", "sub", "--format", "pdf"]);
    assert_bad_input(&out, "--format \"pdf\"");
    let out = run_in(dir.path(), &["grade", "--batch", "nowhere"]);
    assert_bad_input(&out, "--batch nowhere: no such folder");
    let out = run_in(dir.path(), &["grade", "sub", "--vectors", "none.jsonl"]);
    assert_bad_input(&out, "none.jsonl: cannot read");
    std::fs::write(dir.path().join("bad.jsonl"), "{\"id\": 1}\n").unwrap();
    let out = run_in(dir.path(), &["grade", "sub", "--vectors", "bad.jsonl"]);
    assert_bad_input(&out, "bad.jsonl:1: not a valid vector");
    assert!(!dir.path().join("grade-report").exists());
    // An output folder holding a file of the user's would be replaced whole: refused before any
    // work, naming the option and the file, which stays; for a batch too.
    std::fs::create_dir(dir.path().join("mine")).unwrap();
    std::fs::write(dir.path().join("mine/notes.txt"), b"mine").unwrap();
    for args in [
        &["grade", "sub", "--out", "mine"][..],
        &["grade", "--batch", ".", "--out", "mine"],
    ] {
        let out = run_in(dir.path(), args);
        assert_bad_input(
            &out,
            "rtoracle: --out mine: holds notes.txt, which is not part of an rtoracle grade report",
        );
        assert_eq!(
            std::fs::read_dir(dir.path().join("mine")).unwrap().count(),
            1,
            "{args:?}"
        );
        assert_eq!(
            std::fs::read(dir.path().join("mine/notes.txt")).unwrap(),
            b"mine"
        );
    }
    std::fs::remove_dir_all(dir.path().join("mine")).unwrap();
    // An empty folder is a submission with nothing in it: graded 0, exit 0.
    let out = run_in(dir.path(), &["grade", "sub"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r = read_json(&dir.path().join("grade-report/report.json"));
    assert_eq!(r["score"].as_f64(), Some(0.0));
    assert_eq!(r["code"]["fatal"], "RT_object.py is not in the submission");
}

/// The seed of the rubric packed in `zip`.
fn packaged_seed(zip: &Path) -> u64 {
    let file = std::fs::File::open(zip).unwrap();
    let mut archive = zip::ZipArchive::new(file).unwrap();
    let mut text = String::new();
    std::io::Read::read_to_string(&mut archive.by_name("rubric.toml").unwrap(), &mut text).unwrap();
    rtoracle::grade::Rubric::from_toml(&text, "packaged")
        .unwrap()
        .seed
}

#[test]
fn the_autograder_package_has_a_secret_seed_unless_one_is_chosen() {
    let dir = tempfile::tempdir().unwrap();
    let mut seeds = Vec::new();
    for name in ["a.zip", "b.zip"] {
        let out = run_in(dir.path(), &["autograder", "--out", name]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("(secret, drawn now)"));
        seeds.push(packaged_seed(&dir.path().join(name)));
    }
    // Drawn from the OS: non-zero, and not the same twice (a 2^-63 chance of a false alarm).
    assert!(
        seeds[0] != 0 && seeds[1] != 0 && seeds[0] != seeds[1],
        "{seeds:?}"
    );
    let out = run_in(dir.path(), &["autograder", "--out", "c.zip", "--seed", "7"]);
    assert!(out.status.success());
    assert_eq!(packaged_seed(&dir.path().join("c.zip")), 7);
    // A rubric's own non-zero seed is kept.
    let rubric = rtoracle::grade::rubric::WEEK04_RUBRIC.replace("seed = 0", "seed = 42");
    std::fs::write(dir.path().join("r.toml"), rubric).unwrap();
    let out = run_in(
        dir.path(),
        &["autograder", "--out", "d.zip", "--rubric", "r.toml"],
    );
    assert!(out.status.success());
    assert_eq!(packaged_seed(&dir.path().join("d.zip")), 42);
}

#[test]
fn the_autograder_package_grades_a_submission_like_gradescope_would() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["autograder", "--out", "autograder.zip"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let seed = packaged_seed(&dir.path().join("autograder.zip"));
    // Unpack as Gradescope does into /autograder/source.
    let root = dir.path().join("autograder");
    let source = root.join("source");
    let file = std::fs::File::open(dir.path().join("autograder.zip")).unwrap();
    zip::ZipArchive::new(file)
        .unwrap()
        .extract(&source)
        .unwrap();
    let prefix = dir.path().join("prefix");
    let setup = std::process::Command::new("bash")
        .arg(source.join("setup.sh"))
        .env("PREFIX", &prefix)
        .output()
        .unwrap();
    assert!(
        setup.status.success(),
        "{}",
        String::from_utf8_lossy(&setup.stderr)
    );
    let said = String::from_utf8_lossy(&setup.stdout);
    assert!(said.contains(env!("CARGO_PKG_VERSION")));
    // It found (or installed) a Python with numpy and Pillow, checked, and recorded it.
    assert!(
        said.contains("students' code will run with") && said.contains("numpy"),
        "{said}"
    );
    let python = std::fs::read_to_string(prefix.join("share/rtoracle-python")).unwrap();
    let imports = std::process::Command::new(python.trim())
        .args(["-c", "import numpy, PIL"])
        .status()
        .unwrap();
    assert!(imports.success(), "{python}");
    // The installed rubric (with the secret seed) is readable by root only.
    use std::os::unix::fs::PermissionsExt;
    let installed = prefix.join("share/rtoracle-rubric.toml");
    let mode = std::fs::metadata(&installed).unwrap().permissions().mode();
    assert_eq!(mode & 0o777, 0o600);
    // So is the binary (a submission the sandbox cannot hide it from must not run it).
    let mode = std::fs::metadata(prefix.join("bin/rtoracle"))
        .unwrap()
        .permissions()
        .mode();
    assert_eq!(mode & 0o777, 0o700);
    // And the package as unpacked (its binary, its rubric with the secret seed): where the
    // sandbox cannot hide the host's files, the students' code could read and run them.
    for name in ["rtoracle", "rubric.toml", "setup.sh", "run_autograder"] {
        let mode = std::fs::metadata(source.join(name))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o077, 0, "{name}: {mode:o}");
    }
    // A student who uploaded their folder instead of its files.
    materialize("sphere-bug", &root.join("submission/my-week4")).unwrap();
    let run = std::process::Command::new("bash")
        .arg(source.join("run_autograder"))
        .env("PREFIX", &prefix)
        .env("AUTOGRADER", &root)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let results = read_json(&root.join("results/results.json"));
    // The four scored checks (the report of ambiguous vectors, worth no points, aside).
    let tests: Vec<_> = results["tests"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|t| t["max_score"].as_f64().unwrap() > 0.0)
        .collect();
    assert_eq!(tests.len(), 4);
    assert_eq!(tests[0]["status"], "failed");
    assert!(tests[1..].iter().all(|t| t["status"] == "passed"));
    // Graded with the secret seed, which needs no warning, by the recorded interpreter.
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!stderr.contains("public seed"), "{stderr}");
    assert!(rtoracle::grade::autograder::RUN_AUTOGRADER.contains("--python \"$python\""));
    // What students see (results.json) does not give the secret seed away.
    let text = std::fs::read_to_string(root.join("results/results.json")).unwrap();
    assert!(
        !text.contains(&seed.to_string()),
        "the seed {seed} is in results.json"
    );
    // Something that is not a Linux x86_64 binary is refused.
    std::fs::write(dir.path().join("notelf"), b"#!/bin/sh\n").unwrap();
    let out = run_in(
        dir.path(),
        &["autograder", "--binary", "notelf", "--out", "x.zip"],
    );
    assert_bad_input(&out, "notelf: not an x86_64 Linux");
    assert!(!dir.path().join("x.zip").exists());
}
