//! `rtoracle grade` and `rtoracle autograder` end to end on this repository's fixture
//! submissions (tests/fixtures/submissions, images rendered at test time).

mod feedback;
mod reports;
mod schemas;
mod shards;
mod verdicts;
mod weeks;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::common::*;
use rtoracle::bench::grade::{fixture_names, materialize};

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
        let vectors = rtoracle::bench::grade::fixtures_dir().join("vectors.jsonl");
        // The uploaded images are judged (`source = "upload"`): what each fixture's images
        // cost is the point of `loses`; the grader's renders have tests of their own
        // (renders.rs).
        std::fs::write(
            root.join("upload.toml"),
            rtoracle::grade::rubric::week04_uploads_toml(),
        )
        .unwrap();
        let output = grade_batch(
            &root,
            "upload.toml",
            "out",
            &[
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
    let python = rtoracle::bench::harness::course_python().expect("the batch graded with it");
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
        // The batch graded with the uploads' variant of the built-in rubric.
        sha256_hex(rtoracle::grade::rubric::week04_uploads_toml().as_bytes())
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
    // The seed is named by its digest, never spelt out (docs/sandbox.md).
    let digest = rtoracle::secret::digest(0);
    assert!(
        checker.contains(&format!("built-in suite of the rubric's seed ({digest})")),
        "{checker}"
    );
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
    rtoracle::grade::rubric::Rubric::from_toml(&text, "packaged")
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
    // The far root first fails the sphere vectors, and the grader's render of the sphere scene
    // from the same code shows it; the quads and their scene pass.
    let statuses: Vec<&str> = tests
        .iter()
        .map(|t| t["status"].as_str().unwrap())
        .collect();
    assert_eq!(
        statuses,
        ["failed", "passed", "failed", "passed"],
        "{tests:#?}"
    );
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

// ---- A grade that measures the student's own work (constant answers, copies) ----

/// `RT_object.py` whose `Sphere` and `Quad` answer every ray with `body` (Python, indented for
/// a method, may use `rRay`), after the course's constructors.
fn strategy_object(body: &str) -> String {
    format!(
        r#"import random
import RT_utility as rtu

_coin = random.Random(12345)


def _answer(rRay):
{body}


class Sphere:
    def __init__(self, vCenter, fRadius, mMat=None):
        self.center = vCenter
        self.radius = fRadius
        self.material = mMat

    def intersect(self, rRay, cInterval):
        return _answer(rRay)


class Quad:
    def __init__(self, vQ, vU, vV, mMat=None):
        self.Qpoint = vQ
        self.Uvec = vU
        self.Vvec = vV
        self.material = mMat
        self.uxv = rtu.Vec3.cross_product(self.Uvec, self.Vvec)
        self.normal = rtu.Vec3.unit_vector(self.uxv)
        self.D = rtu.Vec3.dot_product(self.normal, self.Qpoint)
        self.Wvec = self.uxv / rtu.Vec3.dot_product(self.uxv, self.uxv)

    def intersect(self, rRay, cInterval):
        return _answer(rRay)

    def is_interior(self, fa, fb):
        return None


class Triangle:
    def __init__(self):
        pass
"#
    )
}

/// The answers that ignore the ray: the bodies of [`strategy_object`].
const STRATEGIES: [(&str, &str); 5] = [
    // The course's skeleton: `intersect` is a stub.
    ("always-none", "    pass"),
    (
        "constant-hit",
        "    h = rtu.Hitinfo(rtu.Vec3(0.0, 0.0, 0.0), rtu.Vec3(0.0, 0.0, 1.0), 1.0)\n    h.front_face = True\n    return h",
    ),
    (
        "ray-origin",
        "    d = rtu.Vec3.unit_vector(rRay.getDirection())\n    h = rtu.Hitinfo(rRay.getOrigin(), -d, 0.0)\n    h.front_face = True\n    return h",
    ),
    (
        "coin-toss",
        "    if _coin.random() < 0.5:\n        return None\n    t = _coin.uniform(0.0, 20.0)\n    h = rtu.Hitinfo(rRay.at(t), rtu.Vec3(0.0, 1.0, 0.0), t)\n    h.front_face = _coin.random() < 0.5\n    return h",
    ),
    (
        "mostly-miss",
        "    if _coin.random() < 0.9:\n        return None\n    h = rtu.Hitinfo(rRay.at(2.0), rtu.Vec3(0.0, 0.0, -1.0), 2.0)\n    h.front_face = True\n    return h",
    ),
];

/// The two week-4 images of an honest student: the reference's render at `seed`.
fn honest_images(dest: &Path, seed: u64) {
    for (scene, file) in [
        ("week04-sphere", "week04_sphere.png"),
        ("week04-quad", "week04_quad.png"),
    ] {
        let d = rtoracle::scene::builtin(scene).unwrap();
        let img = rtoracle::grade::checkers::copies::render_png_pixels(&d, None, seed).unwrap();
        rtoracle::image_io::write_png(&dest.join(file), &img).unwrap();
    }
}

/// A submission of the course's modules, `object` as its `RT_object.py` and the images of
/// `seed` (or none).
fn course_submission(dest: &Path, object: &str, seed: Option<u64>) {
    std::fs::create_dir_all(dest).unwrap();
    let common = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/common");
    for e in std::fs::read_dir(common).unwrap().flatten() {
        std::fs::copy(e.path(), dest.join(e.file_name())).unwrap();
    }
    std::fs::write(dest.join("RT_object.py"), object).unwrap();
    if let Some(seed) = seed {
        honest_images(dest, seed);
    }
}

/// The `check` fixture variant `name`'s own files on top of the course's modules.
fn variant_submission(dest: &Path, name: &str, seed: u64) {
    let variant = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/python/variants")
        .join(name);
    let object = std::fs::read_to_string(variant.join("RT_object.py")).unwrap();
    course_submission(dest, &object, Some(seed));
    for e in std::fs::read_dir(&variant).unwrap().flatten() {
        std::fs::copy(e.path(), dest.join(e.file_name())).unwrap();
    }
}

/// `src` written again as an RGBA PNG (the same pixels, another file).
fn re_encode(src: &Path, dest: &Path) {
    let img = rtoracle::image_io::read_png(src).unwrap();
    let rgba: Vec<u8> = img
        .data
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    image::save_buffer(
        dest,
        &rgba,
        img.width as u32,
        img.height as u32,
        image::ExtendedColorType::Rgba8,
    )
    .unwrap();
}

struct GamingBatch {
    /// The honest work and the skeleton graded with the built-in rubric (the grader renders
    /// each submission's code).
    out: PathBuf,
    /// Graded with its uploads' variant (`source = "upload"`).
    uploads: PathBuf,
    output: Output,
    /// Whether the course's published images were there (the skeleton's submission).
    skeleton: bool,
}

/// One batch of what must earn nothing (the answers that ignore the ray, the course's skeleton
/// with its published images, a copy of a classmate's image, the reference's own render) and of
/// honest work that must earn everything: all of it graded with the built-in suite and the
/// uploads judged, the honest work and the skeleton also with the built-in rubric's renders.
fn gaming_batch() -> &'static GamingBatch {
    static BATCH: OnceLock<GamingBatch> = OnceLock::new();
    BATCH.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("grade-gaming");
        let _ = std::fs::remove_dir_all(&root);
        let subs = root.join("subs");
        for (i, (name, body)) in STRATEGIES.iter().enumerate() {
            course_submission(
                &subs.join(name),
                &strategy_object(body),
                Some(40 + i as u64),
            );
        }
        // The instructor's solution is the course's formulas as the course teaches them.
        variant_submission(&subs.join("instructor-solution"), "honest_reference", 31);
        variant_submission(&subs.join("honest-numpy"), "honest_numpy_vectors", 32);
        // A classmate's sphere image, re-encoded; the quad image is the copier's own.
        variant_submission(&subs.join("copier"), "honest_reference", 33);
        re_encode(
            &subs.join("honest-numpy/week04_sphere.png"),
            &subs.join("copier/week04_sphere.png"),
        );
        // The sphere image `rtoracle render week04-sphere` writes.
        variant_submission(&subs.join("pip-render"), "honest_reference", 34);
        let made = run_in(
            &subs.join("pip-render"),
            &["render", "week04-sphere", "-o", "week04_sphere.png"],
        );
        assert!(made.status.success(), "{made:?}");
        let skeleton = match course_fixtures("the skeleton's grade") {
            Some(dir) => {
                let dest = subs.join("skeleton");
                course_submission(&dest, &strategy_object("    pass"), None);
                for f in ["week04_sphere.png", "week04_quad.png"] {
                    std::fs::copy(dir.join(f), dest.join(f)).unwrap();
                }
                true
            }
            None => false,
        };
        // The built-in rubric, with ten minutes instead of one for each render: these renders
        // are the submissions' own Python, and the suite runs them beside every other test on
        // the machine's cores, where an honest render of week04-quad has taken over a minute.
        // What this batch tests is the points of each kind of work, not the time limit (tested
        // on its own: `a_render_that_raises_hangs_returns_nan_or_the_wrong_size_scores_0_with_the_reason`).
        let printed = run_in(&root, &["grade", "--print-rubric", "week04"]);
        assert!(printed.status.success(), "{printed:?}");
        let built_in = String::from_utf8(printed.stdout).unwrap();
        assert_eq!(built_in.matches("render_seconds = 60\n").count(), 2);
        std::fs::write(
            root.join("rubric.toml"),
            built_in.replace("render_seconds = 60\n", "render_seconds = 600\n"),
        )
        .unwrap();
        // Rendered: the work whose images earn points (the honest two) and the skeleton; the
        // answers that ignore the ray are judged on their code, which the uploads' batch below
        // grades with the same suite (their renders would only cost minutes).
        let rendered = root.join("rendered");
        for name in ["instructor-solution", "honest-numpy", "skeleton"] {
            let Ok(files) = std::fs::read_dir(subs.join(name)) else {
                continue;
            };
            std::fs::create_dir_all(rendered.join(name)).unwrap();
            for f in files.flatten() {
                std::fs::copy(f.path(), rendered.join(name).join(f.file_name())).unwrap();
            }
        }
        let output = run_in(
            &root,
            &[
                "grade",
                "--batch",
                "rendered",
                "--rubric",
                "rubric.toml",
                "--out",
                "out",
            ],
        );
        // The same batch with the uploads judged, as a rubric with `source = "upload"` does:
        // where the copy checks of uploads decide the points.
        std::fs::write(
            root.join("uploads.toml"),
            rtoracle::grade::rubric::week04_uploads_toml(),
        )
        .unwrap();
        let uploads_output = grade_batch(&root, "uploads.toml", "uploads", &[]);
        assert!(
            uploads_output.status.code().is_some_and(|c| c <= 1),
            "{uploads_output:?}"
        );
        GamingBatch {
            out: root.join("out"),
            uploads: root.join("uploads"),
            output,
            skeleton,
        }
    })
}

/// `rtoracle grade --batch subs --rubric RUBRIC --out OUT` in `root`, with `extra` arguments.
fn grade_batch(root: &Path, rubric: &str, out: &str, extra: &[&str]) -> Output {
    let mut args = vec!["grade", "--batch", "subs", "--rubric", rubric, "--out", out];
    args.extend_from_slice(extra);
    run_in(root, &args)
}

fn check<'a>(report: &'a Value, id: &str) -> &'a Value {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == id)
        .unwrap_or_else(|| panic!("no check {id}"))
}

#[test]
fn answers_that_ignore_the_ray_earn_at_most_2_percent_of_each_code_group() {
    let b = gaming_batch();
    assert!(
        b.output.status.success(),
        "{}",
        String::from_utf8_lossy(&b.output.stderr)
    );
    for (name, _) in STRATEGIES {
        let report = read_json(&b.uploads.join(name).join("report.json"));
        for id in ["sphere.intersect", "quad.intersect"] {
            let c = check(&report, id);
            let (score, max) = (
                c["score"].as_f64().unwrap(),
                c["max_score"].as_f64().unwrap(),
            );
            assert!(
                score <= 0.02 * max,
                "{name} {id}: {score} of {max}: {}",
                c["message"]
            );
            // The rule and its components are in report.json.
            let credit = &c["credit"];
            assert_eq!(credit["rule"], "hit_credit_times_miss_credit", "{c}");
            let f =
                credit["hit_credit"].as_f64().unwrap() * credit["miss_credit"].as_f64().unwrap();
            assert!(
                (f - credit["fraction"].as_f64().unwrap()).abs() < 1e-12,
                "{credit}"
            );
            assert!(
                credit["hits"].as_u64().unwrap() > 100 && credit["misses"].as_u64().unwrap() > 100
            );
        }
    }
}

#[test]
fn the_instructors_solution_and_honest_work_score_100_and_the_skeleton_at_most_5() {
    let b = gaming_batch();
    for name in ["instructor-solution", "honest-numpy"] {
        let report = read_json(&b.out.join(name).join("report.json"));
        assert_eq!(report["score"].as_f64(), Some(100.0), "{name}: {report}");
    }
    if b.skeleton {
        let report = read_json(&b.out.join("skeleton/report.json"));
        assert!(report["score"].as_f64().unwrap() <= 5.0, "{report}");
        // With its uploads judged, the published images are recognised as the course's.
        let report = read_json(&b.uploads.join("skeleton/report.json"));
        assert!(report["score"].as_f64().unwrap() <= 5.0, "{report}");
        for (id, file) in [
            ("image.week04-sphere", "week04_sphere.png"),
            ("image.week04-quad", "week04_quad.png"),
        ] {
            let c = check(&report, id);
            assert_eq!(c["score"].as_f64(), Some(0.0));
            assert!(
                c["message"]
                    .as_str()
                    .unwrap()
                    .contains("is the course's published image"),
                "{c}"
            );
            assert_eq!(c["image"]["copies"][0]["kind"], "course_image");
            assert_eq!(c["image"]["copies"][0]["file"], file);
        }
    }
}

#[test]
fn a_copied_image_flags_both_submissions_and_the_reference_render_scores_0() {
    let b = gaming_batch();
    let shared = |name: &str| -> Vec<String> {
        let report = read_json(&b.uploads.join(name).join("report.json"));
        let mut with = Vec::new();
        for c in report["checks"].as_array().unwrap() {
            for f in c["image"]["copies"].as_array().into_iter().flatten() {
                if f["kind"] == "shared_with" {
                    with.push(format!(
                        "{} {}",
                        c["id"].as_str().unwrap(),
                        f["submission"].as_str().unwrap()
                    ));
                }
            }
        }
        with
    };
    assert_eq!(shared("copier"), ["image.week04-sphere honest-numpy"]);
    assert_eq!(shared("honest-numpy"), ["image.week04-sphere copier"]);
    // Independent renders of the same scenes are never flagged.
    for (name, _) in STRATEGIES {
        assert!(shared(name).is_empty(), "{name}: {:?}", shared(name));
    }
    assert!(shared("instructor-solution").is_empty());
    let feedback = std::fs::read_to_string(b.uploads.join("copier/feedback.md")).unwrap();
    assert!(
        feedback.contains("shares its Monte Carlo noise with another submission"),
        "{feedback}"
    );
    assert!(
        !feedback.contains("honest-numpy"),
        "a student's feedback names no classmate"
    );
    let summary = std::fs::read_to_string(b.uploads.join("summary.md")).unwrap();
    assert!(
        summary.contains("| `image.week04-sphere` | copier and honest-numpy |"),
        "{summary}"
    );
    // The reference tracer's own render scores 0 and says so; the rest of the grade stands.
    let report = read_json(&b.uploads.join("pip-render/report.json"));
    let c = check(&report, "image.week04-sphere");
    assert_eq!(c["score"].as_f64(), Some(0.0));
    assert!(
        c["message"]
            .as_str()
            .unwrap()
            .contains("the reference tracer's own render"),
        "{c}"
    );
    assert_eq!(report["score"].as_f64(), Some(80.0));
    assert!(
        summary.contains("pip-render: week04_sphere.png is the reference tracer's own render"),
        "{summary}"
    );
}
