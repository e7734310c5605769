//! `rtoracle check` / `fuzz` and the candidate harness, against the Python fixtures in
//! tests/fixtures/python (course layout, written for these tests).
//!
//! The fixture tests use the fuzz generator's definite cases (seeded), not the built-in suite,
//! so they hold whatever the real suite becomes; the CLI tests that run the built-in suite only
//! rely on it having definite sphere and quad vectors (marked "suite:").

use std::path::Path;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use rtoracle::candidate::bench::assemble_fixture;
use rtoracle::candidate::generate::random_cases;
use rtoracle::candidate::{CandidateCommand, CheckReport, FailureKind, RunOptions, check_command};
use rtoracle::oracle::vectors::{Case, ShapeKind};

use crate::common::*;

fn cases() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| random_cases(5, 0, 1200, &[ShapeKind::Sphere, ShapeKind::Quad]))
}

fn python_ok() -> bool {
    let ok = std::process::Command::new("python3")
        .arg("-c")
        .arg("pass")
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("skipped: python3 is not available");
    }
    ok
}

fn fast() -> RunOptions {
    RunOptions {
        timeout: Duration::from_millis(400),
        hello_timeout: Duration::from_millis(1500),
        ..RunOptions::default()
    }
}

fn check(variant: &str, options: RunOptions) -> CheckReport {
    let dir = assemble_fixture(variant).unwrap();
    check_command(
        CandidateCommand::python_course(dir.path()).unwrap(),
        cases(),
        options,
    )
    .unwrap()
}

fn group(r: &CheckReport, kind: ShapeKind) -> rtoracle::candidate::Counts {
    r.by_shape[&kind]
}

const HONEST: [&str; 6] = [
    "honest_reference",
    "honest_contains_surrounds",
    "honest_strict_edges",
    "honest_full_quadratic",
    "honest_denom_exact_zero",
    "honest_normalised_direction",
];

#[test]
fn honest_variants_pass_every_definite_vector() {
    if !python_ok() {
        return;
    }
    for variant in HONEST {
        let r = check(variant, RunOptions::default());
        assert!(r.passed(), "{variant}:\n{}", r.to_text(3));
        for kind in [ShapeKind::Sphere, ShapeKind::Quad] {
            let g = group(&r, kind);
            assert!(g.total > 400, "{variant}: {kind} has {} vectors", g.total);
            assert_eq!(g.passed, g.total, "{variant} {kind}");
        }
        assert!(r.failures.is_empty(), "{variant}");
        assert_eq!(r.restarts, 0);
    }
}

#[test]
fn each_bug_is_caught_in_its_own_shape_group_only() {
    if !python_ok() {
        return;
    }
    use FailureKind::*;
    use ShapeKind::*;
    let bugs = [
        ("bug_far_root_first", Sphere, Mismatch),
        ("bug_sphere_no_interval_check", Sphere, Mismatch),
        ("bug_unnormalised_normal", Sphere, Mismatch),
        ("bug_abs_radius_normal", Sphere, Mismatch),
        ("bug_radius_not_squared", Sphere, Mismatch),
        ("bug_sqrt_precedence", Sphere, Mismatch),
        ("bug_normal_not_flipped", Sphere, Mismatch),
        ("bug_alpha_sign", Quad, Mismatch),
        ("bug_w_is_unit_normal", Quad, Mismatch),
        ("bug_no_parallel_test", Quad, Error),
        ("bug_wrong_plane_d", Quad, Mismatch),
        ("bug_front_face_reversed", Quad, Mismatch),
        ("bug_beta_uses_v", Quad, Mismatch),
        ("bug_quad_no_interval_check", Quad, Mismatch),
        ("bug_interior_upper_bounds_only", Quad, Mismatch),
    ];
    for (variant, kind, failure) in bugs {
        let r = check(variant, RunOptions::default());
        assert!(!r.passed(), "{variant} passed");
        let bad = group(&r, kind);
        assert!(bad.passed < bad.total, "{variant}: {kind} group all passed");
        let other = if kind == Sphere { Quad } else { Sphere };
        let good = group(&r, other);
        assert_eq!(
            good.passed, good.total,
            "{variant}: {other} group should pass"
        );
        assert!(
            r.failures
                .iter()
                .all(|f| f.shape == kind && f.kind == failure),
            "{variant}: {:?}",
            r.failures
                .iter()
                .map(|f| (f.shape, f.kind))
                .collect::<Vec<_>>()
        );
    }
    // Specific evidence for two bugs: the parallel test and the negative radius.
    let r = check("bug_no_parallel_test", RunOptions::default());
    assert!(
        r.failures
            .iter()
            .all(|f| f.tags.iter().any(|t| t == "parallel")
                && f.message.contains("ZeroDivisionError"))
    );
    let r = check("bug_abs_radius_normal", RunOptions::default());
    assert!(
        r.failures
            .iter()
            .all(|f| f.tags.iter().any(|t| t == "negative-radius"))
    );
}

#[test]
fn a_submission_hanging_on_misses_costs_three_timeouts_per_group() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let r = check("hostile_hang_on_miss", fast());
    let elapsed = start.elapsed();
    // 2 groups x 3 timeouts x 0.4 s, plus restarts.
    assert!(elapsed < Duration::from_secs(8), "took {elapsed:?}");
    for kind in [ShapeKind::Sphere, ShapeKind::Quad] {
        let g = group(&r, kind);
        assert_eq!(g.timeouts, 3, "{kind}");
        assert!(g.not_run > 0 && g.passed > 0, "{kind}: {g:?}");
        assert_eq!(g.failed + g.errors, 0, "{kind}: {g:?}");
    }
    assert!(r.failures.iter().any(|f| f.kind == FailureKind::NotRun
        && f.message.contains("after 3 timeouts in the sphere group")));
    // Every timed-out case is a miss.
    assert!(
        r.failures
            .iter()
            .filter(|f| f.kind == FailureKind::Timeout)
            .all(|f| f.expected.class == rtoracle::oracle::vectors::Class::Miss)
    );
}

#[test]
fn a_submission_that_kills_itself_is_restarted_and_the_run_goes_on() {
    if !python_ok() {
        return;
    }
    let r = check("hostile_kill_self", RunOptions::default());
    // It kills itself on its 100th sphere; every restart counts afresh. The first death
    // loses the batched answers and switches the session to one flush per answer, so each
    // later death is blamed on the case that caused it: one error per 100 spheres.
    let spheres = cases()
        .iter()
        .filter(|c| c.shape.kind() == ShapeKind::Sphere)
        .count();
    assert_eq!(r.counts.errors, spheres / 100, "{}", r.to_text(2));
    assert_eq!(r.restarts as usize, r.counts.errors + 1);
    assert!(
        r.failures.iter().all(|f| f.kind == FailureKind::Error
            && f.shape == ShapeKind::Sphere
            && f.message.contains("signal 9")),
        "{:?}",
        r.failures.iter().map(|f| &f.message).collect::<Vec<_>>()
    );
    assert_eq!(
        group(&r, ShapeKind::Quad).passed,
        group(&r, ShapeKind::Quad).total
    );
    let s = group(&r, ShapeKind::Sphere);
    assert_eq!(s.passed + s.errors, s.total);
}

#[test]
fn stray_prints_are_protocol_errors_of_their_cases_only() {
    if !python_ok() {
        return;
    }
    let r = check("hostile_junk_stdout", RunOptions::default());
    let s = group(&r, ShapeKind::Sphere);
    // It prints on every sphere hit, not on misses.
    let sphere_hits = cases()
        .iter()
        .filter(|c| {
            c.shape.kind() == ShapeKind::Sphere
                && c.expect.class == rtoracle::oracle::vectors::Class::Hit
        })
        .count();
    assert_eq!(s.errors, sphere_hits);
    assert_eq!(s.passed, s.total - sphere_hits);
    assert!(r.failures.iter().all(|f| f.kind == FailureKind::Protocol
        && f.message.contains("debug: root =")
        && f.actual.as_ref().is_some_and(|a| a.hit == Some(true))));
    assert_eq!(
        group(&r, ShapeKind::Quad).passed,
        group(&r, ShapeKind::Quad).total
    );
}

#[test]
fn a_submission_that_cannot_be_imported_reports_it_on_every_case() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let dir = assemble_fixture("hostile_cannot_import").unwrap();
    let r = check_command(
        CandidateCommand::python_course(dir.path()).unwrap(),
        cases(),
        RunOptions::default(),
    )
    .unwrap();
    assert!(start.elapsed() < Duration::from_secs(5));
    let e = r.import_error.as_ref().expect("an import error");
    assert_eq!(e.kind, "SyntaxError");
    // The traceback names the student's file, not the sandbox's copy of it.
    let file = dir.path().join("RT_object.py");
    assert!(
        e.traceback.contains(&format!("\"{}\"", file.display())),
        "{}",
        e.traceback
    );
    assert_eq!(r.counts.errors, r.counts.total);
    assert!(r.failures.iter().all(|f| f.message.contains("SyntaxError")));
    assert!(r.to_text(1).contains("could not be imported: SyntaxError"));
}

#[test]
fn an_import_that_hangs_costs_the_hello_timeout_once() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let r = check("hostile_import_hangs", fast());
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(r.counts.errors, r.counts.total);
    assert!(
        r.start_failure
            .as_deref()
            .unwrap()
            .contains("no hello answer within 1.5 s")
    );
}

#[test]
fn a_forked_child_is_killed_with_its_group() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let r = check("hostile_fork_sleeper", RunOptions::default());
    assert!(start.elapsed() < Duration::from_secs(10));
    assert!(r.passed(), "{}", r.to_text(3));
    let pid: u32 = r
        .stderr_tail
        .split("forked child ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no pid in {:?}", r.stderr_tail));
    let facts = r.sandbox.as_ref().expect("sandbox facts");
    if facts.isolation == rtoracle::sandbox::Isolation::Bubblewrap {
        // The pid is the PID namespace's: no process of the sandbox's uid may be left.
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } == 0 {
            let left = rtoracle::sandbox::identity::processes_of(facts.uid);
            assert!(left.is_empty(), "left: {left:?}");
        }
        return;
    }
    // Gone, or a zombie waiting for init: not sleeping.
    std::thread::sleep(Duration::from_millis(100));
    let state = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    let state = state.rsplit(')').next().unwrap_or("").trim_start();
    assert!(
        state.is_empty() || state.starts_with('Z'),
        "child {pid}: {state}"
    );
}

#[test]
fn a_memory_hog_gets_a_memory_error_not_the_machine() {
    if !python_ok() {
        return;
    }
    let r = check("hostile_memory_hog", RunOptions::default());
    // It tries to allocate 16 GiB once; the address-space limit turns that into MemoryError.
    assert_eq!(r.counts.errors, 1, "{}", r.to_text(3));
    assert!(r.failures[0].message.contains("MemoryError"));
    assert_eq!(r.counts.passed, r.counts.total - 1);
}

fn write_vectors(dir: &Path, cases: &[Case]) -> String {
    let path = dir.join("v.jsonl");
    let text: String = cases.iter().map(|c| c.to_json_line() + "\n").collect();
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

#[test]
fn check_cli_exit_codes_json_and_text() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let vectors = write_vectors(tmp.path(), &cases()[..300]);
    let honest = assemble_fixture("honest_reference").unwrap();
    let buggy = assemble_fixture("bug_far_root_first").unwrap();
    let h = honest.path().to_str().unwrap();
    let b = buggy.path().to_str().unwrap();

    let out = run_in(
        tmp.path(),
        &[
            "check",
            "--python-course",
            h,
            "--vectors",
            &vectors,
            "--json",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["total"], 300);
    assert_eq!(json["passed"], 300);
    assert_eq!(json["failures"].as_array().unwrap().len(), 0);

    let out = run_in(
        tmp.path(),
        &[
            "check",
            "--python-course",
            b,
            "--vectors",
            &vectors,
            "--json",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(json["by_shape"]["sphere"]["failed"].as_u64().unwrap() > 0);
    assert_eq!(json["by_shape"]["quad"]["failed"], 0);
    let f = &json["failures"][0];
    for key in [
        "id", "shape", "tags", "kind", "expected", "actual", "message", "repro",
    ] {
        assert!(!f[key].is_null(), "{key}");
    }
    assert_eq!(f["kind"], "mismatch");

    let out = run_in(
        tmp.path(),
        &["check", "--python-course", b, "--vectors", &vectors],
    );
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("verdict: FAIL") && text.contains("from RT_object import Sphere"));

    // suite: the built-in suite has definite sphere and quad vectors; triangles (a stub in the
    // course) are not run and do not fail the verdict.
    let out = run_in(tmp.path(), &["check", "--python-course", h]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn a_repro_snippet_reproduces_the_failure_in_python() {
    if !python_ok() {
        return;
    }
    let r = check("bug_far_root_first", RunOptions::default());
    let f = &r.failures[0];
    let dir = assemble_fixture("bug_far_root_first").unwrap();
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(&f.repro)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The snippet prints the candidate's (wrong) t, which the report also recorded.
    let printed = String::from_utf8_lossy(&out.stdout);
    let t = f.actual.as_ref().unwrap().t.unwrap();
    assert!(
        printed.starts_with(&format!("({t:?}, ")),
        "{printed} vs {t}"
    );
}

#[test]
fn bad_inputs_and_broken_adapters_exit_2_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let out = run_in(tmp.path(), &["check", "--python-course", "no/such/dir"]);
    assert_bad_input(&out, "no/such/dir");
    std::fs::write(tmp.path().join("bad.jsonl"), "{\"id\": 3}\n").unwrap();
    let out = run_in(
        tmp.path(),
        &["check", "--adapter", "cat", "--vectors", "bad.jsonl"],
    );
    assert_bad_input(&out, "bad.jsonl:1");
    let out = run_in(tmp.path(), &["check", "--adapter", "/no/such/program"]);
    assert_bad_input(&out, "/no/such/program");
    // The reason is said once, not once per layer of the error.
    let out = run_in(
        tmp.path(),
        &["check", "--adapter", "cat", "--vectors", "missing.jsonl"],
    );
    assert_bad_input(&out, "missing.jsonl: cannot read");
    for out in [
        &out,
        &run_in(tmp.path(), &["check", "--adapter", "/no/such/program"]),
    ] {
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.matches("os error 2").count(), 1, "{stderr}");
    }
    // Speaks no protocol: prints junk and exits.
    let out = run_in(
        tmp.path(),
        &["check", "--adapter", "sh -c 'echo hello there'"],
    );
    assert_bad_input(&out, "did not answer the hello");
    // Floods stdout with junk and never answers: bounded memory, one line, exit 2.
    let start = Instant::now();
    let out = run_in(
        tmp.path(),
        &[
            "check",
            "--adapter",
            "yes junk",
            "--hello-timeout-ms",
            "500",
        ],
    );
    assert_bad_input(&out, "no hello answer within 0.5 s");
    assert!(start.elapsed() < Duration::from_secs(10));
    let out = run_in(tmp.path(), &["check"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn fuzz_finds_shrinks_and_prints_a_reproduction() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let buggy = assemble_fixture("bug_w_is_unit_normal").unwrap();
    let out = run_in(
        tmp.path(),
        &[
            "fuzz",
            "--python-course",
            buggy.path().to_str().unwrap(),
            "--cases",
            "2000",
            "--seed",
            "3",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("[mismatch]") && text.contains("(quad)"),
        "{text}"
    );
    assert!(text.contains("from RT_object import Quad"), "{text}");
    assert!(!text.contains("(sphere)"), "{text}");

    let honest = assemble_fixture("honest_full_quadratic").unwrap();
    let out = run_in(
        tmp.path(),
        &[
            "fuzz",
            "--python-course",
            honest.path().to_str().unwrap(),
            "--cases",
            "2000",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("0 failed"));
}

#[test]
fn blame_lands_on_the_right_case_even_when_the_adapter_batches_its_answers() {
    if !python_ok() {
        return;
    }
    // Misses only, so every answer of the adapter is right except on the three marked cases.
    let misses: Vec<Case> = cases()
        .iter()
        .filter(|c| c.expect.class == rtoracle::oracle::vectors::Class::Miss)
        .take(400)
        .cloned()
        .collect();
    let (die, hang, junk) = (&misses[150].id, &misses[250].id, &misses[300].id);
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/adapters/batching_misser.py");
    let command = CandidateCommand::adapter(&format!(
        "python3 -I {} {die} {hang} {junk}",
        script.display()
    ))
    .unwrap();
    let r = check_command(command, &misses, fast()).unwrap();
    let blamed: Vec<(&str, FailureKind)> =
        r.failures.iter().map(|f| (f.id.as_str(), f.kind)).collect();
    assert_eq!(
        blamed,
        [
            (die.as_str(), FailureKind::Error),
            (hang.as_str(), FailureKind::Timeout),
            (junk.as_str(), FailureKind::Protocol),
        ],
        "{}",
        r.to_text(5)
    );
    assert_eq!(r.counts.passed, 397);
    assert!(r.failures[2].message.contains("junk line"));
    assert!(r.failures[0].message.contains("exited with code 3"));
}

#[test]
fn the_c_example_adapter_passes_the_sphere_vectors() {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let tmp = tempfile::tempdir().unwrap();
    let exe = tmp.path().join("sphere_adapter");
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/adapter-c/sphere_adapter.c");
    let built = std::process::Command::new(&cc)
        .args(["-O2", "-o"])
        .arg(&exe)
        .arg(&source)
        .arg("-lm")
        .status();
    if !built.map(|s| s.success()).unwrap_or(false) {
        eprintln!("skipped: no working C compiler ({cc})");
        return;
    }
    let vectors = write_vectors(tmp.path(), &cases()[..600]);
    let out = run_in(
        tmp.path(),
        &[
            "check",
            "--adapter",
            "./sphere_adapter",
            "--vectors",
            &vectors,
            "--json",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let sphere = &json["by_shape"]["sphere"];
    assert!(sphere["total"].as_u64().unwrap() > 200);
    assert_eq!(sphere["passed"], sphere["total"]);
    // It declares spheres only: the quads are not run, which does not fail the verdict.
    assert_eq!(
        json["by_shape"]["quad"]["not_run"],
        json["by_shape"]["quad"]["total"]
    );
    assert_eq!(json["candidate"], "c-sphere-adapter");
}

#[test]
fn the_candidate_gets_no_network_when_the_platform_allows_it() {
    let allowed = std::process::Command::new("unshare")
        .args(["-n", "true"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !allowed {
        eprintln!("skipped: this user cannot create network namespaces");
        return;
    }
    let mine = std::fs::read_link("/proc/self/ns/net").unwrap();
    // An "adapter" that reports its network namespace on stderr, then speaks no protocol.
    let command = CandidateCommand::adapter("sh -c 'readlink /proc/self/ns/net >&2'").unwrap();
    let err = match rtoracle::candidate::Session::start(command, fast()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("it does not answer the hello"),
    };
    assert!(err.contains("net:["), "{err}");
    assert!(
        !err.contains(&mine.display().to_string()),
        "{err} vs {mine:?}"
    );
}

#[test]
fn a_candidate_flooding_stdout_times_out_with_bounded_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let vectors = write_vectors(tmp.path(), &cases()[..50]);
    // Answers the hello, then prints junk without end.
    let adapter = r#"sh -c 'read l; echo "{\"name\":\"flood\"}"; yes junk'"#;
    let start = Instant::now();
    let out = run_in(
        tmp.path(),
        &[
            "check",
            "--adapter",
            adapter,
            "--vectors",
            &vectors,
            "--timeout-ms",
            "300",
            "--json",
        ],
    );
    assert!(
        start.elapsed() < Duration::from_secs(15),
        "{:?}",
        start.elapsed()
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for group in ["sphere", "quad"] {
        assert_eq!(json["by_shape"][group]["timeouts"], 3, "{group}");
    }
    let first = &json["failures"][0];
    assert_eq!(first["kind"], "timeout");
    assert!(
        first["message"].as_str().unwrap().contains("junk\\njunk"),
        "{first}"
    );
}
