//! `rtoracle check` / `fuzz` and the candidate harness, against the Python fixtures in
//! tests/fixtures/python (course layout, written for these tests).
//!
//! The fixture tests use the fuzz generator's definite cases (seeded), not the built-in suite,
//! so they hold whatever the real suite becomes; the CLI tests that run the built-in suite only
//! rely on it having definite sphere and quad vectors (marked "suite:").

mod physics;
mod protocol;
mod weekly;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use rtoracle::bench::harness::{assemble_fixture, course_python_or_skip};
use rtoracle::candidate::check_command;
use rtoracle::candidate::fuzzing::generate::random_cases;
use rtoracle::candidate::judging::check::FailureKind;
use rtoracle::candidate::judging::report::CheckReport;
use rtoracle::candidate::process::command::CandidateCommand;
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::oracle::vectors::{Case, ShapeKind};

use crate::common::*;

fn cases() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| random_cases(5, 0, 1200, &[ShapeKind::Sphere, ShapeKind::Quad]))
}

/// The Python the fixtures need (numpy and PIL, as the course's `RT_utility.py`), or `None`
/// after saying the test is skipped ([`course_python_or_skip`]).
fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| course_python_or_skip("the Python fixture tests"))
        .as_deref()
}

fn python_ok() -> bool {
    python().is_some()
}

/// `rtoracle` with `args` in `dir`, told which Python to run the course adapter with.
fn run_py(dir: &Path, args: &[&str]) -> std::process::Output {
    rtoracle()
        .current_dir(dir)
        .env("RTORACLE_PYTHON", python().expect("checked"))
        .args(args)
        .output()
        .expect("rtoracle runs")
}

/// A short case timeout, and a hello timeout long enough for a sandboxed Python importing numpy
/// on a loaded machine (restarts must say hello too).
fn fast() -> RunOptions {
    RunOptions {
        timeout: Duration::from_millis(400),
        hello_timeout: Duration::from_secs(5),
        ..RunOptions::default()
    }
}

fn course(dir: &Path) -> CandidateCommand {
    CandidateCommand::python_course_with(dir, python(), false).unwrap()
}

fn check(variant: &str, options: RunOptions) -> CheckReport {
    check_on(variant, cases(), options)
}

fn check_on(variant: &str, cases: &[Case], options: RunOptions) -> CheckReport {
    let dir = assemble_fixture(variant).unwrap();
    check_command(course(dir.path()), cases, options).unwrap()
}

fn group(r: &CheckReport, kind: ShapeKind) -> rtoracle::candidate::judging::report::Counts {
    r.by_shape[&kind]
}

const HONEST: [&str; 8] = [
    "honest_reference",
    "honest_contains_surrounds",
    "honest_strict_edges",
    "honest_full_quadratic",
    "honest_denom_exact_zero",
    "honest_normalised_direction",
    // Later weeks' API: Ray(..., fTime=0.0), Hitinfo(..., tcTex=None), a motion-blur Sphere
    // defining intersect twice, a Quad filling texture coordinates, RT_object importing
    // numpy, RT_texture and RT_material; and components in numpy arrays (np.float64, np.bool_).
    "honest_week10_shapes",
    "honest_numpy_vectors",
];

/// The random sphere and quad cases, then the built-in suite's triangles (which hold the small
/// triangles an absolute epsilon on the determinant misses).
fn mixed() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| {
        let mut all = cases().to_vec();
        all.extend(
            rtoracle::oracle::suite::default_suite(0)
                .into_iter()
                .filter(|c| c.shape.kind() == ShapeKind::Triangle),
        );
        all
    })
}

/// Each buggy fixture and the catalogue's mistake that is its bug (by how the fixture is
/// written: make_variants.py).
const DIAGNOSED: [(&str, &str); 20] = [
    ("bug_quad_unnormalised_normal", "quad-unnormalised-normal"),
    ("bug_far_root_first", "sphere-far-root-first"),
    ("bug_sphere_no_interval_check", "sphere-no-interval-check"),
    ("bug_unnormalised_normal", "sphere-unnormalised-normal"),
    ("bug_abs_radius_normal", "sphere-abs-radius-in-normal"),
    ("bug_radius_not_squared", "sphere-r-instead-of-r-squared"),
    ("bug_sqrt_precedence", "sphere-sqrt-precedence"),
    ("bug_normal_not_flipped", "sphere-normal-not-flipped"),
    ("bug_alpha_sign", "quad-sign-error-in-alpha"),
    ("bug_w_is_unit_normal", "quad-w-is-unit-normal"),
    ("bug_no_parallel_test", "quad-no-parallel-test"),
    ("bug_wrong_plane_d", "quad-d-from-u"),
    ("bug_front_face_reversed", "quad-front-face-reversed"),
    ("bug_beta_uses_v", "quad-beta-uses-v"),
    ("bug_quad_no_interval_check", "quad-no-interval-check"),
    (
        "bug_interior_upper_bounds_only",
        "quad-interior-upper-bounds-only",
    ),
    ("bug_triangle_absolute_epsilon", "triangle-absolute-epsilon"),
    (
        "bug_triangle_absolute_epsilon_mat_required_cxb",
        "triangle-absolute-epsilon",
    ),
    // The same mistakes seen twice must still be one diagnosis each (their own group).
    ("bug_far_root_first", "sphere-far-root-first"),
    ("bug_alpha_sign", "quad-sign-error-in-alpha"),
];

#[test]
fn every_buggy_fixture_is_diagnosed_as_its_own_mistake_and_no_honest_one_is() {
    if !python_ok() {
        return;
    }
    let mut named = std::collections::BTreeSet::new();
    for (variant, mistake) in DIAGNOSED {
        if !named.insert(variant) {
            continue;
        }
        let r = check_on(variant, mixed(), RunOptions::default());
        assert!(!r.passed(), "{variant} passed");
        assert_eq!(r.diagnosis.len(), 1, "{variant}: {:?}", r.diagnosis);
        let d = &r.diagnosis[0];
        assert_eq!(d.mistake_id, mistake, "{variant}: {d:?}");
        // It explains the failures of its group, which are all the failures there are.
        let failing = r
            .failures
            .iter()
            .filter(|f| matches!(f.kind, FailureKind::Mismatch | FailureKind::Error))
            .count();
        assert_eq!((d.explained, d.of), (failing, failing), "{variant}");
        assert!(
            r.to_text(1)
                .contains(&format!("diagnosis: {}", d.sentence()))
        );
        let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
        assert_eq!(json["diagnosis"][0]["mistake_id"], mistake);
    }
    for variant in HONEST.iter().chain(&TRIANGLES_HONEST) {
        let r = check_on(variant, mixed(), RunOptions::default());
        assert!(r.passed(), "{variant}:\n{}", r.to_text(3));
        assert!(r.diagnosis.is_empty(), "{variant}: {:?}", r.diagnosis);
    }
}

const TRIANGLES_HONEST: [&str; 4] = [
    "honest_triangle_course_style",
    "honest_triangle_mt_bxc",
    "honest_triangle_mt_mat_required_cxb",
    "honest_triangle_stub_without_intersect",
];

fn triangle_cases() -> Vec<Case> {
    mixed()
        .iter()
        .filter(|c| c.shape.kind() == ShapeKind::Triangle)
        .cloned()
        .collect()
}

#[test]
fn students_triangles_are_run_in_each_constructor_form_and_judged_by_their_own_winding() {
    if !python_ok() {
        return;
    }
    use rtoracle::candidate::judging::check::Winding;
    let tris = triangle_cases();
    let definite = tris.iter().filter(|c| c.expect.class.is_definite()).count();
    assert!(definite > 100, "{definite}");
    // (fixture, its winding as written, constructor)
    for (variant, winding) in [
        ("honest_triangle_course_style", Winding::BaCa), // Triangle(a, b, c, mMat=None)
        ("honest_triangle_mt_bxc", Winding::BaCa),       // Triangle(v0, v1, v2, mMat=None)
        ("honest_triangle_mt_mat_required_cxb", Winding::CaBa), // Triangle(v0, v1, v2, mat)
    ] {
        let r = check_on(variant, &tris, RunOptions::default());
        let g = group(&r, ShapeKind::Triangle);
        assert_eq!((g.passed, g.not_run), (definite, 0), "{variant}: {g:?}");
        assert_eq!(r.triangle_winding, Some(winding), "{variant}");
        assert!(
            r.to_text(1)
                .contains(&format!("your triangles face {}", winding.formula())),
            "{variant}"
        );
    }
    // The reversed fixture's front_face is the opposite of the reference's on every hit it
    // answers: judged against the reference's winding it would fail them all.
    let r = check_on(
        "honest_triangle_mt_mat_required_cxb",
        &tris,
        RunOptions::default(),
    );
    assert!(r.passed() && r.failures.is_empty());
    // fuzz judges by the same winding: random triangles (and spheres and quads) all pass.
    let dir = assemble_fixture("honest_triangle_mt_mat_required_cxb").unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = run_py(
        tmp.path(),
        &[
            "fuzz",
            "--python-course",
            dir.path().to_str().unwrap(),
            "--cases",
            "3000",
        ],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("0 failed"), "{text}");
    // A stub with three vertices and no intersect is unsupported: nothing run, nothing failed.
    let r = check_on(
        "honest_triangle_stub_without_intersect",
        &tris,
        RunOptions::default(),
    );
    let g = group(&r, ShapeKind::Triangle);
    assert_eq!((g.not_run, g.failed + g.errors), (definite, 0), "{g:?}");
    assert_eq!(r.triangle_winding, None);
}

#[test]
fn an_absolute_epsilon_on_the_determinant_misses_exactly_the_small_triangles() {
    if !python_ok() {
        return;
    }
    let tris = triangle_cases();
    let det = |c: &Case| {
        let rtoracle::oracle::vectors::ShapeSpec::Triangle { a, b, c: cc } = c.shape else {
            unreachable!()
        };
        let sub = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
        let cross = |x: [f64; 3], y: [f64; 3]| {
            [
                x[1] * y[2] - x[2] * y[1],
                x[2] * y[0] - x[0] * y[2],
                x[0] * y[1] - x[1] * y[0],
            ]
        };
        let (e1, e2) = (sub(b, a), sub(cc, a));
        let p = cross(c.ray.direction, e2);
        e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2]
    };
    // Independently of the fixture: the hits whose determinant is below 1e-8.
    let expected: Vec<&str> = tris
        .iter()
        .filter(|c| c.expect.class == rtoracle::oracle::vectors::Class::Hit && det(c).abs() < 1e-8)
        .map(|c| c.id.as_str())
        .collect();
    assert!(!expected.is_empty());
    for variant in [
        "bug_triangle_absolute_epsilon",
        "bug_triangle_absolute_epsilon_mat_required_cxb",
    ] {
        let r = check_on(variant, &tris, RunOptions::default());
        let failed: Vec<&str> = r.failures.iter().map(|f| f.id.as_str()).collect();
        assert_eq!(failed, expected, "{variant}");
        assert!(r.failures.iter().all(|f| f.message.contains("got a miss")));
        assert_eq!(r.diagnosis[0].mistake_id, "triangle-absolute-epsilon");
        assert!(
            r.to_text(1)
                .contains("your triangle failures are exactly those of an absolute epsilon"),
            "{}",
            r.to_text(1)
        );
    }
}

#[test]
fn a_module_the_grader_lacks_is_the_student_s_error_said_plainly() {
    if !python_ok() {
        return;
    }
    let r = check(
        "bug_imports_a_module_the_grader_lacks",
        RunOptions::default(),
    );
    let e = r.import_error.as_ref().expect("an import error");
    assert_eq!(e.kind, "ModuleNotFoundError");
    assert_eq!(
        e.message,
        "your code imports rtoracle_no_such_module (RT_object.py, line 5), which the grader does not provide"
    );
    // The traceback (what grade's feedback shows) ends with the same words, after the line of
    // the student's file that imports it.
    assert!(
        e.traceback
            .trim_end()
            .ends_with(&format!("ModuleNotFoundError: {}", e.message))
            && e.traceback.contains("import rtoracle_no_such_module"),
        "{}",
        e.traceback
    );
    let r = check(
        "bug_imports_a_course_module_not_uploaded",
        RunOptions::default(),
    );
    let e = r.import_error.as_ref().expect("an import error");
    assert!(
        e.message.contains(
            "imports RT_camera_not_uploaded (RT_object.py, line 5), which is not in your submission"
        ),
        "{}",
        e.message
    );
    // A required module that is missing is the grader's problem: the adapter, told that the
    // module it cannot import is required, says so.
    let dir = assemble_fixture("bug_imports_a_module_the_grader_lacks").unwrap();
    std::fs::write(
        dir.path().join("adapter.py"),
        rtoracle::candidate::process::command::PYTHON_COURSE_ADAPTER,
    )
    .unwrap();
    let mut child = std::process::Command::new(python().unwrap())
        .args([
            "-I",
            "-B",
            "adapter.py",
            ".",
            "--requires",
            "numpy,PIL,rtoracle_no_such_module",
        ])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"{\"hello\":1}\n")
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let hello: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&out.stdout).lines().next().unwrap()).unwrap();
    let message = hello["error"]["message"].as_str().unwrap();
    assert!(
        message.starts_with("the grader's Python lacks rtoracle_no_such_module")
            && message.contains("not the submission's"),
        "{message}"
    );
}

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
    // 2 groups x 3 timeouts x 0.4 s, plus six restarts; a timeout on every miss would be
    // hundreds of them (the counts below are the exact check, this bound a loose one).
    assert!(elapsed < Duration::from_secs(20), "took {elapsed:?}");
    for kind in [ShapeKind::Sphere, ShapeKind::Quad] {
        let g = group(&r, kind);
        assert_eq!(g.timeouts, 3, "{kind}");
        assert!(g.not_run > 0 && g.passed > 0, "{kind}: {g:?}");
        assert_eq!(g.failed + g.errors, 0, "{kind}: {g:?}");
    }
    // What was not run is summarised per shape, not listed.
    assert!(r.failures.iter().all(|f| f.kind != FailureKind::NotRun));
    assert!(
        r.not_run_summary
            .iter()
            .any(|n| n.shape == ShapeKind::Sphere
                && n.count == group(&r, ShapeKind::Sphere).not_run
                && n.reason.contains("after 3 timeouts in the sphere group"))
    );
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
    let r = check_command(course(dir.path()), cases(), RunOptions::default()).unwrap();
    // One start, not one per case (the loose bound leaves room for a loaded machine).
    assert!(
        start.elapsed() < Duration::from_secs(15),
        "{:?}",
        start.elapsed()
    );
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
    let text = r.to_text(10);
    assert!(text.contains("could not be imported: SyntaxError"));
    // Said once at the top and once for all the failures, not once per failure with a repro.
    assert!(text.matches("SyntaxError").count() <= 3, "{text}");
    assert!(!text.contains("reproduce"), "{text}");
}

#[test]
fn an_import_that_hangs_costs_the_hello_timeout_once() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let options = RunOptions {
        hello_timeout: Duration::from_millis(1500),
        ..fast()
    };
    let r = check("hostile_import_hangs", options);
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
    if facts.isolation == rtoracle::sandbox::policy::Isolation::Bubblewrap {
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

    let out = run_py(
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
    // The intersections' report (check --json, version 2).
    let json = &json["intersections"];
    assert_eq!(json["total"], 300);
    assert_eq!(json["passed"], 300);
    assert_eq!(json["failures"].as_array().unwrap().len(), 0);

    let out = run_py(
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
    // The intersections' report (check --json, version 2).
    let json = &json["intersections"];
    assert!(json["by_shape"]["sphere"]["failed"].as_u64().unwrap() > 0);
    assert_eq!(json["by_shape"]["quad"]["failed"], 0);
    let f = &json["failures"][0];
    for key in [
        "id", "shape", "tags", "kind", "expected", "actual", "message", "repro",
    ] {
        assert!(!f[key].is_null(), "{key}");
    }
    assert_eq!(f["kind"], "mismatch");

    let out = run_py(
        tmp.path(),
        &["check", "--python-course", b, "--vectors", &vectors],
    );
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("verdict: FAIL") && text.contains("from RT_object import Sphere"));

    // suite: the built-in suite has definite sphere and quad vectors; triangles (a stub in the
    // course) are not run and do not fail the verdict.
    let out = run_py(tmp.path(), &["check", "--python-course", h]);
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
    let out = std::process::Command::new(python().unwrap())
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
    let out = run_py(
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
        text.contains("[missed hit]") && text.contains("(quad)"),
        "{text}"
    );
    assert!(text.contains("from RT_object import Quad"), "{text}");
    // What it judged by, and the mistake (the fuzz report named neither).
    assert!(text.starts_with("judged by: course/f64\n"), "{text}");
    assert!(
        text.contains("diagnosis: ") && text.contains("taking w as the unit normal"),
        "{text}"
    );
    assert!(!text.contains("(sphere)"), "{text}");

    let honest = assemble_fixture("honest_full_quadratic").unwrap();
    let out = run_py(
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
        "{} -I {} {die} {hang} {junk}",
        python().unwrap().display(),
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
    let tmp = tempfile::tempdir().unwrap();
    let Some(_) = build_c_example(tmp.path(), "sphere_adapter.c", "sphere_adapter", &[]) else {
        return;
    };
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
    // The intersections' report (check --json, version 2).
    let json = &json["intersections"];
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
    let err = match rtoracle::candidate::process::session::Session::start(command, fast()) {
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
    let adapter = r#"sh -c 'read l; echo "{\"name\":\"flood\",\"protocol\":1}"; yes junk'"#;
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
    // The intersections' report (check --json, version 2).
    let json = &json["intersections"];
    for group in ["sphere", "quad"] {
        assert_eq!(json["by_shape"][group]["timeouts"], 3, "{group}");
    }
    let first = &json["failures"][0];
    assert_eq!(first["kind"], "timeout");
    assert!(
        first["message"]
            .as_str()
            .unwrap()
            .contains(r#""junk", "junk""#),
        "{first}"
    );
}

/// `bwrap` with the crate's source folder hidden (an empty folder mounted over it), where this
/// machine can run it; `None` otherwise.
fn without_the_checkout() -> Option<std::process::Command> {
    let here = env!("CARGO_MANIFEST_DIR");
    let args = ["--dev-bind", "/", "/", "--tmpfs", here, "--"];
    let works = std::process::Command::new("bwrap")
        .args(args)
        .args(["sh", "-c", &format!("test ! -e {here}/Cargo.toml")])
        .status()
        .is_ok_and(|s| s.success());
    works.then(|| {
        let mut cmd = std::process::Command::new("bwrap");
        cmd.args(args);
        cmd
    })
}

/// `rtoracle bench candidate` read its fixtures from the source folder named at compile time
/// ("assembling the fixture: No such file or directory" from an installed binary): a copy of
/// the binary, run in an empty folder with the checkout hidden where bwrap can hide it, runs
/// the quick benchmark through the course adapter.
#[test]
fn bench_candidate_runs_from_a_copy_of_the_binary_in_an_empty_folder() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let bin = tmp.path().join("bin");
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&bin).unwrap();
    std::fs::create_dir_all(&empty).unwrap();
    let copy = bin.join("rtoracle");
    std::fs::copy(env!("CARGO_BIN_EXE_rtoracle"), &copy).unwrap();
    let mut cmd = match without_the_checkout() {
        Some(mut bwrap) => {
            bwrap.arg(&copy);
            bwrap
        }
        None => {
            eprintln!("bwrap cannot hide the checkout here: the copy runs beside it");
            std::process::Command::new(&copy)
        }
    };
    let out = cmd
        .args(["bench", "candidate", "--quick"])
        .current_dir(&empty)
        .env("RTORACLE_PYTHON", python().expect("checked"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("course adapter passed: true"), "{stdout}");
    // The quick run is no measurement: no suites.
    assert!(!stdout.contains("default suite"), "{stdout}");
    assert_eq!(
        std::fs::read_dir(&empty).unwrap().count(),
        0,
        "nothing left"
    );
}

/// `rtoracle check --adapter ./NAME ARGS --json` in `dir`: the exit code and the report.
fn check_c(dir: &Path, name: &str, args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let adapter = format!("./{name}");
    let mut all = vec!["check", "--adapter", adapter.as_str(), "--json"];
    all.extend_from_slice(args);
    let out = run_in(dir, &all);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stderr)));
    // The intersections' report (check --json, version 2).
    (out.status.code(), json["intersections"].clone())
}

/// The complete C adapter that PROTOCOL.md gives (spheres, quads, triangles, RTIOW style with
/// closed edges and the robust sphere) passes the built-in suite in both profiles, its
/// watertight groups included. Built with `-DOPEN_EDGES` (`alpha > 0`, `disc > 0`) it passed
/// too before the suite had watertight groups (every exact edge is ambiguous for one shape
/// alone); now the groups' rays through shared edges and vertices crack in both profiles.
#[test]
fn the_c_adapter_of_the_protocol_passes_and_its_open_edge_variant_cracks_in_both_profiles() {
    let tmp = tempfile::tempdir().unwrap();
    if build_c_adapter(tmp.path(), "adapter", &[]).is_none() {
        return;
    }
    build_c_adapter(tmp.path(), "open", &["-DOPEN_EDGES"]).unwrap();
    let groups = rtoracle::oracle::watertight::GROUPS
        .iter()
        .map(|g| g.1 - rtoracle::oracle::watertight::TANGENT_GROUPS)
        .sum::<usize>() as u64;
    for profile in ["course", "robust"] {
        let (code, json) = check_c(tmp.path(), "adapter", &["--profile", profile]);
        let counts = &json;
        assert_eq!(code, Some(0), "{profile}: {json}");
        assert_eq!(counts["passed"], counts["total"], "{profile}");
        assert_eq!(json["candidate"], "c-adapter");
        assert_eq!(counts["watertight"], groups, "{profile}");
        assert_eq!(counts["watertight_cracked"], 0, "{profile}");

        let (code, json) = check_c(tmp.path(), "open", &["--profile", profile]);
        let counts = &json;
        assert_eq!(code, Some(1), "{profile}: {counts}");
        // Every definite vector still passes: only the groups find the open edges.
        assert_eq!(counts["passed"], counts["total"], "{profile}");
        assert_eq!(counts["watertight_cracked"], groups, "{profile}");
        let failures = json["failures"].as_array().unwrap();
        assert!(failures.iter().all(|f| {
            f["id"].as_str().unwrap().starts_with("watertight-")
                && f["message"].as_str().unwrap().contains("hit none of them")
        }));
    }
    // The text report says it.
    let out = run_in(tmp.path(), &["check", "--adapter", "./open"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!(
            "watertight groups: {groups} judged, {groups} cracked"
        )),
        "{text}"
    );
    assert!(text.contains("verdict: FAIL"), "{text}");
}

/// `check --score-ambiguous` scores the ambiguous vectors by their exact answers: the open-edge
/// adapter then fails the single edges too, and the closed one is judged on them (it passed
/// only the definite ones before; `check` had no such option).
#[test]
fn check_scores_ambiguous_vectors_when_asked() {
    let tmp = tempfile::tempdir().unwrap();
    if build_c_adapter(tmp.path(), "open", &["-DOPEN_EDGES"]).is_none() {
        return;
    }
    let (_, plain) = check_c(tmp.path(), "open", &[]);
    let (code, scored) = check_c(tmp.path(), "open", &["--score-ambiguous"]);
    assert_eq!(code, Some(1));
    let (p, s) = (&plain, &scored);
    assert_eq!(s["ambiguous"], 0);
    assert_eq!(
        s["total"].as_u64().unwrap(),
        p["total"].as_u64().unwrap() + p["ambiguous"].as_u64().unwrap()
    );
    // The ambiguous vectors it answered exactly now pass, the others fail.
    assert_eq!(
        s["passed"].as_u64().unwrap(),
        p["passed"].as_u64().unwrap() + p["ambiguous_passed"].as_u64().unwrap()
    );
    let edge_failed = scored["failures"].as_array().unwrap().iter().any(|f| {
        !f["id"].as_str().unwrap().starts_with("watertight-")
            && f["tags"].as_array().unwrap().iter().any(|t| t == "edge")
    });
    assert!(edge_failed);
    assert!(
        scored["judged_by"]
            .as_str()
            .unwrap()
            .ends_with("; ambiguous vectors scored by their exact answers")
    );
}
