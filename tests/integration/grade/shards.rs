//! A batch spread over shards: `grade --batch DIR --shard K/N` grades the share its documented
//! rule gives (checked here with the rule written again), and `grade --merge` joins the shards'
//! folders into the gradebook and summary of the batch graded whole, byte for byte.

use std::collections::BTreeSet;
use std::path::Path;

use sha2::{Digest, Sha256};

use crate::common::*;
use rtoracle::bench::grade::{fixture_names, fixtures_dir, materialize, materialize_code};

/// The week-4 rubric's code groups (no image to render: the shards are what is tested).
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

/// The shard of a folder, as docs/grading.md states the rule: 1 + the first 8 bytes of the
/// SHA-256 of its name, big-endian, modulo N.
fn shard_of(name: &str, n: u64) -> u64 {
    let d = Sha256::digest(name.as_bytes());
    u64::from_be_bytes(d[..8].try_into().unwrap()) % n + 1
}

/// The sub-folders of a report folder.
fn folders(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect()
}

fn grade(root: &Path, args: &[&str]) -> String {
    let out = run_in(root, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn three_shards_merged_equal_the_batch_graded_whole() {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("shards");
    let _ = std::fs::remove_dir_all(&root);
    let subs = root.join("subs");
    let mut names = Vec::new();
    for name in fixture_names().into_iter().filter(|n| n != "hang") {
        materialize_code(&name, &subs.join(&name)).unwrap();
        names.push(name);
    }
    // A folder the batch cannot grade is a row too.
    std::fs::create_dir_all(subs.join("summary.md")).unwrap();
    names.push("summary.md".into());
    names.sort();
    std::fs::write(root.join("code.toml"), CODE_ONLY).unwrap();
    let vectors = fixtures_dir().join("vectors.jsonl");
    let common = [
        "--rubric",
        "code.toml",
        "--vectors",
        vectors.to_str().unwrap(),
        "--case-timeout-ms",
        "1000",
    ];
    let batch = |extra: &[&str]| {
        let mut args = vec!["grade", "--batch", "subs"];
        args.extend(common);
        args.extend(extra);
        grade(&root, &args)
    };
    let whole = batch(&["--out", "whole"]);
    let mut held = BTreeSet::new();
    for k in 1..=3u64 {
        let out = format!("shard-{k}");
        batch(&["--shard", &format!("{k}/3"), "--out", &out]);
        // Each shard holds what the rule gives it, and no other.
        let csv = std::fs::read_to_string(root.join(&out).join("gradebook.csv")).unwrap();
        let rows: BTreeSet<String> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().to_string())
            .collect();
        let expected: BTreeSet<String> = names
            .iter()
            .filter(|n| shard_of(n, 3) == k)
            .cloned()
            .collect();
        assert_eq!(rows, expected, "shard {k}/3");
        assert!(held.is_disjoint(&rows));
        held.extend(rows);
    }
    assert_eq!(held, names.iter().cloned().collect::<BTreeSet<_>>());
    // Merged in any order: the whole batch's gradebook and summary, byte for byte.
    let merged = grade(
        &root,
        &[
            "grade", "--merge", "shard-3", "shard-1", "shard-2", "--out", "merged",
        ],
    );
    assert_eq!(merged, whole, "the scores on stdout");
    for file in ["gradebook.csv", "summary.md", "batch.json"] {
        let a = std::fs::read(root.join("whole").join(file)).unwrap();
        let b = std::fs::read(root.join("merged").join(file)).unwrap();
        assert!(
            a == b,
            "{file} differs:\n{}\n---\n{}",
            String::from_utf8_lossy(&a),
            String::from_utf8_lossy(&b)
        );
    }
    // Every submission's reports are there, as in the whole batch's folder.
    assert_eq!(folders(&root.join("merged")), folders(&root.join("whole")));
    for sub in folders(&root.join("whole")) {
        let files = |d: &Path| -> BTreeSet<String> {
            std::fs::read_dir(d.join(&sub))
                .unwrap()
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(files(&root.join("merged")), files(&root.join("whole")));
    }

    // What cannot be merged is refused, one line, exit 2, nothing written.
    let refused = |args: &[&str], needle: &str| {
        let out = run_in(&root, args);
        assert_bad_input(&out, needle);
        assert!(!root.join("refused").exists());
    };
    refused(
        &["grade", "--merge", "shard-1", "shard-2", "--out", "refused"],
        "shard 3/3 missing",
    );
    refused(
        &[
            "grade", "--merge", "shard-1", "shard-1", "shard-2", "shard-3", "--out", "refused",
        ],
        "shard 1/3 is given twice",
    );
    refused(
        &["grade", "--merge", "whole", "shard-1", "--out", "refused"],
        "unsharded",
    );
    refused(
        &["grade", "--merge", "subs", "--out", "refused"],
        "batch.json",
    );
    refused(
        &[
            "grade", "--batch", "subs", "--shard", "4/3", "--out", "refused",
        ],
        "4/3",
    );
}

/// Every file under `dir` (relative path -> bytes), with what two runs of one batch may differ
/// in set to 0: the wall-clock times (`execution_time` in the JSON reports and entries, `time`
/// in junit.xml) and the uid the sandbox drew for each submission (`code.sandbox.uid`).
fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut std::collections::BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let path = e.path();
            if path.is_dir() {
                walk(root, &path, out);
                continue;
            }
            let rel = path
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .into_owned();
            let bytes = std::fs::read(&path).unwrap();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = match name.as_str() {
                "report.json" | "results.json" | "batch-entry.json" => {
                    let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                    zero_times(&mut v);
                    serde_json::to_vec_pretty(&v).unwrap()
                }
                "junit.xml" => {
                    let text = String::from_utf8(bytes).unwrap();
                    let mut out = String::new();
                    let mut rest = text.as_str();
                    while let Some(i) = rest.find(" time=\"") {
                        out.push_str(&rest[..i + 7]);
                        rest = &rest[i + 7..];
                        let end = rest.find('"').unwrap();
                        out.push('0');
                        rest = &rest[end..];
                    }
                    out.push_str(rest);
                    out.into_bytes()
                }
                _ => bytes,
            };
            out.insert(rel, bytes);
        }
    }
    fn zero_times(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(o) => {
                for (k, x) in o.iter_mut() {
                    // The wall-clock time, and the uid the sandbox drew for the run.
                    if k == "execution_time" || k == "uid" {
                        *x = 0.into();
                    } else {
                        zero_times(x);
                    }
                }
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(zero_times),
            _ => {}
        }
    }
    let mut out = std::collections::BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// Merging is as strict as grading whole: two submissions whose images are one copy, graded in
/// different shards (for N = 2 and N = 3), are flagged in the merged reports and summary as in
/// the whole batch's, and every file of the merged folder is the whole batch's, byte for byte
/// (wall-clock times and sandbox uids aside). Shards graded under other weights, other vectors (another seed) or
/// by another rtoracle are refused with one line and exit 2, before anything is written.
#[test]
fn merged_shards_keep_copy_findings_and_refuse_shards_graded_otherwise() {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("shards-copies");
    let _ = std::fs::remove_dir_all(&root);
    let subs = root.join("subs");
    // Two names that no sharding into 2 or 3 puts together.
    let (a, b) = (0..)
        .map(|i| (format!("copy-{i}-a"), format!("copy-{i}-b")))
        .find(|(a, b)| (2..=3).all(|n| shard_of(a, n) != shard_of(b, n)))
        .unwrap();
    materialize("honest", &subs.join(&a)).unwrap();
    copy_tree(&subs.join(&a), &subs.join(&b));
    for name in ["sphere-bug", "missing-image", "no-gamma", "unimportable"] {
        materialize(name, &subs.join(name)).unwrap();
    }
    std::fs::write(
        root.join("uploads.toml"),
        rtoracle::grade::rubric::week04_uploads_toml(),
    )
    .unwrap();
    let vectors = fixtures_dir().join("vectors.jsonl");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "grade",
            "--batch",
            "subs",
            "--rubric",
            "uploads.toml",
            "--vectors",
            vectors.to_str().unwrap(),
            "--case-timeout-ms",
            "1000",
        ];
        args.extend(extra);
        grade(&root, &args)
    };
    let whole = run(&["--out", "whole"]);
    // The whole batch flags the pair (the copy check's own rule: the same pixels share their
    // noise), in both reports and in the summary.
    let summary = std::fs::read_to_string(root.join("whole/summary.md")).unwrap();
    assert!(summary.contains(&format!("{a} and {b}")), "{summary}");
    let report = std::fs::read_to_string(root.join("whole").join(&a).join("report.json")).unwrap();
    assert!(
        report.contains("\"shared_with\"") && report.contains(&b),
        "{report}"
    );
    let expected = tree(&root.join("whole"));
    for n in [2u64, 3] {
        let mut dirs = Vec::new();
        for k in 1..=n {
            let out = format!("shard-{k}-of-{n}");
            run(&["--shard", &format!("{k}/{n}"), "--out", &out]);
            dirs.push(out);
        }
        let mut args = vec!["grade", "--merge"];
        args.extend(dirs.iter().rev().map(String::as_str));
        let merged_dir = format!("merged-{n}");
        args.extend(["--out", &merged_dir]);
        let merged = grade(&root, &args);
        assert_eq!(merged, whole, "the scores on stdout, {n} shards");
        let got = tree(&root.join(&merged_dir));
        assert_eq!(
            got.keys().collect::<Vec<_>>(),
            expected.keys().collect::<Vec<_>>(),
            "{n} shards"
        );
        for (file, bytes) in &expected {
            assert!(
                got[file] == *bytes,
                "{file} differs after merging {n} shards:\n{}\n---\n{}",
                String::from_utf8_lossy(bytes),
                String::from_utf8_lossy(&got[file])
            );
        }
    }
    // Shards graded otherwise: refused, one line, exit 2, nothing written.
    let refused = |other: &str, needle: &str| {
        let out = run_in(
            &root,
            &[
                "grade",
                "--merge",
                "shard-1-of-2",
                other,
                "--out",
                "refused",
            ],
        );
        assert_bad_input(&out, needle);
        assert!(!root.join("refused").exists());
    };
    // Other weights, the same total.
    let weights = rtoracle::grade::rubric::week04_uploads_toml()
        .replacen("points = 30", "points = 40", 1)
        .replacen("points = 30", "points = 20", 1);
    assert_ne!(weights, rtoracle::grade::rubric::week04_uploads_toml());
    std::fs::write(root.join("weights.toml"), weights).unwrap();
    grade(
        &root,
        &[
            "grade",
            "--batch",
            "subs",
            "--rubric",
            "weights.toml",
            "--vectors",
            vectors.to_str().unwrap(),
            "--case-timeout-ms",
            "1000",
            "--shard",
            "2/2",
            "--out",
            "weights",
        ],
    );
    refused("weights", "other groups or points");
    // Other vectors (what another seed gives): a vector fewer.
    let text = std::fs::read_to_string(&vectors).unwrap();
    let fewer: String = text.lines().skip(1).map(|l| format!("{l}\n")).collect();
    std::fs::write(root.join("fewer.jsonl"), fewer).unwrap();
    grade(
        &root,
        &[
            "grade",
            "--batch",
            "subs",
            "--rubric",
            "uploads.toml",
            "--vectors",
            "fewer.jsonl",
            "--case-timeout-ms",
            "1000",
            "--shard",
            "2/2",
            "--out",
            "seed",
        ],
    );
    refused("seed", "other vectors");
    // Another rtoracle.
    copy_tree(&root.join("shard-2-of-2"), &root.join("version"));
    let path = root.join("version/batch.json");
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    file["graded_with"]["tool_version"] = "0.0.1-other".into();
    std::fs::write(&path, serde_json::to_string_pretty(&file).unwrap()).unwrap();
    refused("version", "rtoracle 0.0.1-other");
}
