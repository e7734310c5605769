//! A batch spread over shards: `grade --batch DIR --shard K/N` grades the share its documented
//! rule gives (checked here with the rule written again), and `grade --merge` joins the shards'
//! folders into the gradebook and summary of the batch graded whole, byte for byte.

use std::collections::BTreeSet;
use std::path::Path;

use sha2::{Digest, Sha256};

use crate::common::*;
use rtoracle::grade::bench::{fixture_names, fixtures_dir, materialize_code};

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
