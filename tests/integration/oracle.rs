//! The oracle: `vectors` and `explain` on the command line, the fuzz corpora replayed, the
//! filter against exact arithmetic on a million cases, and the reference against the oracle.

use std::path::Path;

use crate::common::*;
use rtoracle::geometry::Shape;
use rtoracle::oracle::band::Iv;
use rtoracle::oracle::exact::{Dyadic, decide_with};
use rtoracle::oracle::generate::{Stream, random_plane, random_sphere};
use rtoracle::oracle::vectors::{Class, read_vectors};
use rtoracle::oracle::{analyse, fuzzing};

#[test]
fn vectors_writes_the_same_bytes_for_a_seed_and_a_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["a.jsonl", "b.jsonl"] {
        let out = run_in(
            dir.path(),
            &["vectors", "--seed", "7", "--count", "400", "-o", name],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let a = std::fs::read(dir.path().join("a.jsonl")).unwrap();
    assert_eq!(a, std::fs::read(dir.path().join("b.jsonl")).unwrap());
    let cases = read_vectors(&dir.path().join("a.jsonl")).unwrap();
    assert_eq!(cases.len(), 400);
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("a.jsonl.meta.json")).unwrap())
            .unwrap();
    assert_eq!(meta["seed"], 7);
    assert_eq!(meta["schema_version"], 1);
    // Every line's expect is what the oracle says of its inputs.
    for c in cases.iter().step_by(7) {
        let again = rtoracle::oracle::classify(&c.shape, &c.ray, c.interval);
        assert_eq!(again.class, c.expect.class, "{}", c.id);
        assert_eq!(
            again.t.map(f64::to_bits),
            c.expect.t.map(f64::to_bits),
            "{}",
            c.id
        );
    }
    let out = run_in(
        dir.path(),
        &[
            "vectors", "--count", "50", "--shapes", "quad", "-o", "q.jsonl",
        ],
    );
    assert!(out.status.success());
    let q = read_vectors(&dir.path().join("q.jsonl")).unwrap();
    assert!(q.iter().all(|c| c.id.starts_with("quad-")));
}

#[test]
fn vectors_and_explain_refuse_bad_input_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert_bad_input(
        &run_in(d, &["vectors", "--shapes", "sphere,cone", "-o", "x.jsonl"]),
        "cone",
    );
    assert_bad_input(
        &run_in(d, &["vectors", "--count", "0", "-o", "x.jsonl"]),
        "--count",
    );
    assert_bad_input(
        &run_in(d, &["vectors", "--count", "5", "-o", "no/such/dir/x.jsonl"]),
        "x.jsonl",
    );
    assert!(!d.join("x.jsonl").exists());
    assert_bad_input(
        &run_in(d, &["explain", "sphere-nothing-9999"]),
        "sphere-nothing-9999",
    );
    assert_bad_input(&run_in(d, &["explain", "{\"shape\": 3"]), "JSON");
    assert_bad_input(
        &run_in(d, &["explain", "x", "--vectors", "missing.jsonl"]),
        "missing.jsonl",
    );
}

#[test]
fn explain_tells_an_exact_tangent_apart_from_a_clear_hit() {
    let dir = tempfile::tempdir().unwrap();
    // d = (2,3,6) and n = (6,2,-3) are orthogonal with length 7: O = C + n - 10 d is tangent.
    let tangent = r#"{"shape":{"type":"sphere","center":[0,0,0],"radius":7},"ray":{"origin":[-14,-28,-63],"direction":[2,3,6]}}"#;
    let out = run_in(dir.path(), &["explain", tangent]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(text.contains("exactly zero"), "{text}");
    assert!(text.contains("Class: ambiguous"), "{text}");
    assert!(text.contains("hit at t = 10.0"), "{text}");
    let clear = r#"{"shape":{"type":"sphere","center":[0,0,-5],"radius":1},"ray":{"origin":[0,0,0],"direction":[0,0,-1]},"interval":[0.000001,"inf"]}"#;
    let out = run_in(dir.path(), &["explain", clear]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("Class: hit"), "{text}");
    assert!(text.contains("t = 4.0"), "{text}");
    let out = run_in(dir.path(), &["explain", "quad-parallel-0000"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("n.d = 0.0 (exactly)"));
}

#[test]
fn fuzz_corpora_replay_without_violations() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let mut replayed = 0;
    for name in fuzzing::TARGETS {
        let f = fuzzing::target(name).unwrap();
        let dir = root.join(name);
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            if let Err(v) = f(&bytes) {
                panic!("{}: {v}", path.display());
            }
            replayed += 1;
        }
    }
    assert!(replayed >= 50, "only {replayed} corpus files");
}

/// The filter and exact arithmetic agree wherever the filter answers, and the reference equals
/// the exact decision on every definite case, over a million random cases across scales.
#[test]
fn filter_and_exact_agree_and_reference_is_exact_on_a_million_cases() {
    let mut r = Stream::new(2024, "million");
    let (mut filtered, mut definite) = (0usize, 0usize);
    for i in 0..1_000_000usize {
        let c = match i % 4 {
            0 | 1 => random_sphere(&mut r, 1e8, None),
            2 => random_plane(&mut r, false),
            _ => random_plane(&mut r, true),
        };
        let fast = decide_with::<Iv>(&c.shape, &c.ray, c.interval);
        // Exact arithmetic on every case.
        {
            let exact = decide_with::<Dyadic>(&c.shape, &c.ray, c.interval).unwrap();
            if let Some(f) = fast {
                assert_eq!(f, exact, "case {i}: {c:?}");
            }
        }
        filtered += usize::from(fast.is_some());
        if i % 8 == 0 {
            let a = analyse(&c.shape, &c.ray, c.interval);
            if a.class.is_definite() {
                definite += 1;
                let hit = c.shape.object().hit_t(
                    &c.ray.ray(),
                    rtoracle::geometry::Interval::new(c.interval[0], c.interval[1]),
                );
                assert_eq!(hit.is_some(), a.class == Class::Hit, "case {i}: {c:?}");
                if let (Some(t), Some(h)) = (hit, a.hit) {
                    assert!(
                        ((t - h.t) / h.t).abs() <= 1e-12,
                        "case {i}: t {t} vs {}",
                        h.t
                    );
                }
            }
        }
    }
    assert!(filtered > 900_000, "the filter decided only {filtered}");
    assert!(definite > 50_000);
}
