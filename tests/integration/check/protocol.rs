//! The strict adapter protocol, the harness's own caps and the time budget, against the small
//! misbehaving adapter of tests/fixtures/adapters/misbehaving.py (it answers "miss" to
//! everything, so on a run of definite misses every case it does not spoil passes).

use std::path::Path;
use std::time::{Duration, Instant};

use rtoracle::candidate::check_command;
use rtoracle::candidate::fuzzing::generate::random_cases;
use rtoracle::candidate::judging::check::FailureKind;
use rtoracle::candidate::judging::report::CheckReport;
use rtoracle::candidate::process::command::CandidateCommand;
use rtoracle::candidate::process::options::RunOptions;
use rtoracle::oracle::vectors::{Case, Class, ShapeKind};

use crate::common::*;

/// `/usr/bin/python3` when it exists (it is what CI installs), else `python3`.
fn python() -> &'static str {
    if Path::new("/usr/bin/python3").is_file() {
        "/usr/bin/python3"
    } else {
        "python3"
    }
}

fn python_ok() -> bool {
    let ok = std::process::Command::new(python())
        .args(["-c", "pass"])
        .status()
        .map(|s| s.success())
        .unwrap_or(false);
    if !ok {
        eprintln!("skipped: python3 is not available");
    }
    ok
}

fn adapter_line(args: &str) -> String {
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/adapters/misbehaving.py");
    format!("{} -I {} {args}", python(), script.display())
}

fn adapter(args: &str) -> CandidateCommand {
    CandidateCommand::adapter(&adapter_line(args)).unwrap()
}

/// 60 definite misses (spheres and quads).
fn misses() -> Vec<Case> {
    random_cases(11, 0, 600, &[ShapeKind::Sphere, ShapeKind::Quad])
        .into_iter()
        .filter(|c| c.expect.class == Class::Miss)
        .take(60)
        .collect()
}

/// A case timeout far above what any answer here takes, even on a loaded machine: a test
/// that finishes well under it was decided when the line came, not by a timeout.
fn options() -> RunOptions {
    RunOptions {
        timeout: Duration::from_secs(10),
        hello_timeout: Duration::from_secs(5),
        ..RunOptions::default()
    }
}

/// Runs `mode` spoiling the answer to case 20 of [`misses`]; returns the report and the cases.
fn spoil(mode: &str) -> (CheckReport, Vec<Case>, Duration) {
    let cases = misses();
    let start = Instant::now();
    let report = check_command(
        adapter(&format!("{mode} {}", cases[20].id)),
        &cases,
        options(),
    )
    .unwrap();
    (report, cases, start.elapsed())
}

/// The common evidence: exactly the cases `blamed` fail, each as a protocol error, at once (no
/// timeout, no restart), and every other case passes.
fn assert_protocol_errors(mode: &str, blamed: &[usize], needle: &str) {
    let (r, cases, took) = spoil(mode);
    let failed: Vec<(&str, FailureKind)> =
        r.failures.iter().map(|f| (f.id.as_str(), f.kind)).collect();
    let want: Vec<(&str, FailureKind)> = blamed
        .iter()
        .map(|&i| (cases[i].id.as_str(), FailureKind::Protocol))
        .collect();
    assert_eq!(failed, want, "{mode}:\n{}", r.to_text(5));
    assert_eq!(r.counts.timeouts, 0, "{mode}");
    assert_eq!(r.restarts, 0, "{mode}");
    assert_eq!(r.counts.passed, cases.len() - blamed.len(), "{mode}");
    assert!(
        r.failures[0].message.contains(needle),
        "{mode}: {}",
        r.failures[0].message
    );
    // Decided when the line came, not after the 10 s case timeout.
    assert!(took < Duration::from_secs(8), "{mode} took {took:?}");
}

#[test]
fn an_answer_with_another_id_is_a_protocol_error_of_its_case_only() {
    if python_ok() {
        assert_protocol_errors("other-id", &[20], "\"no-such-request\"");
    }
}

#[test]
fn a_missing_answer_is_blamed_on_its_case_when_the_next_answer_comes() {
    if python_ok() {
        assert_protocol_errors("skip", &[20], "answers come in request order");
    }
}

#[test]
fn a_duplicate_answer_is_a_protocol_error_of_the_case_it_arrives_during() {
    // The second answer for case 20 arrives while case 21 waits: 21 is charged, and still gets
    // its own answer, so nothing after it shifts.
    if python_ok() {
        assert_protocol_errors("duplicate", &[21], "a second answer for");
    }
}

#[test]
fn a_string_where_a_bool_belongs_is_a_protocol_error() {
    if python_ok() {
        assert_protocol_errors("hit-string", &[20], "invalid type: string \"true\"");
    }
}

#[test]
fn a_bare_nan_is_a_protocol_error() {
    if python_ok() {
        assert_protocol_errors("bare-nan", &[20], "not valid JSON");
    }
}

#[test]
fn a_hit_without_its_fields_is_a_protocol_error() {
    if python_ok() {
        assert_protocol_errors("missing", &[20], "lacks normal, front_face");
    }
}

#[test]
fn a_non_finite_number_written_as_a_number_is_a_protocol_error() {
    if python_ok() {
        assert_protocol_errors("overflow", &[20], "number out of range");
    }
}

#[test]
fn an_oversize_line_is_a_protocol_error() {
    if python_ok() {
        assert_protocol_errors("oversize", &[20], "longer than 1 MiB");
    }
}

#[test]
fn a_bare_nan_adapter_gets_protocol_errors_on_the_default_suite_in_seconds() {
    if !python_ok() {
        return;
    }
    let start = Instant::now();
    let out = rtoracle()
        .args([
            "check",
            "--adapter",
            &adapter_line("bare-nan '*'"),
            "--json",
        ])
        .output()
        .unwrap();
    let took = start.elapsed();
    assert!(took < Duration::from_secs(15), "took {took:?}");
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The intersections' report (check --json, version 2).
    let json = &json["intersections"];
    assert_eq!(json["timeouts"], 0);
    assert_eq!(json["restarts"], 0);
    // Every definite sphere and quad vector is a protocol error (triangles are not run).
    for shape in ["sphere", "quad"] {
        let g = &json["by_shape"][shape];
        assert!(g["total"].as_u64().unwrap() > 500);
        assert_eq!(g["errors"], g["total"], "{shape}");
    }
    let failures = json["failures"].as_array().unwrap();
    assert!(failures.iter().all(|f| f["kind"] == "protocol"));
}

#[test]
fn hellos_with_another_version_no_version_or_an_unknown_shape_exit_2() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    for (mode, needle) in [
        ("hello-v2", "\"protocol\": 2"),
        ("hello-none", "no \"protocol\""),
        (
            "hello-quads",
            "unknown shape \"quads\"; the known shapes are sphere, quad, triangle",
        ),
    ] {
        let out = run_in(tmp.path(), &["check", "--adapter", &adapter_line(mode)]);
        assert_bad_input(&out, needle);
        let out = run_in(
            tmp.path(),
            &["fuzz", "--adapter", &adapter_line(mode), "--cases", "10"],
        );
        assert_bad_input(&out, needle);
    }
}

/// Peak resident memory of this process, in KiB (VmHWM), where /proc has it.
fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

#[test]
fn huge_messages_are_capped_by_the_harness() {
    if !python_ok() {
        return;
    }
    // 300 KB of message and 300 KB of traceback on each of 600 definite cases: 360 MB sent.
    let cases: Vec<Case> = random_cases(12, 0, 700, &[ShapeKind::Sphere, ShapeKind::Quad])
        .into_iter()
        .filter(|c| c.expect.class.is_definite())
        .take(600)
        .collect();
    assert_eq!(cases.len(), 600);
    let r = check_command(adapter("huge-error '*'"), &cases, options()).unwrap();
    assert_eq!(r.counts.errors, 600, "{}", r.to_text(1));
    let json = r.to_json();
    // Uncapped, the report would hold the 600 messages at least once: 180 MB.
    assert!(json.len() < 4_000_000, "report of {} bytes", json.len());
    for f in &r.failures {
        let e = f.actual.as_ref().unwrap().error.as_ref().unwrap();
        assert!(e.message.len() <= 4096 + 40 && e.traceback.len() <= 4096 + 40);
    }
    if let Some(kib) = peak_rss_kib() {
        eprintln!("peak RSS of the test process: {kib} KiB");
    }
}

#[test]
fn past_the_time_budget_the_rest_is_not_run_and_the_report_says_why() {
    if !python_ok() {
        return;
    }
    let cases = misses();
    // Each answer takes 0.3 s, under the case timeout; the budget allows about 10, where all
    // 60 would take 18 s.
    let options = RunOptions {
        budget: Some(Duration::from_secs(3)),
        ..options()
    };
    let start = Instant::now();
    let r = check_command(adapter("slow '*' 0.3"), &cases, options).unwrap();
    let took = start.elapsed();
    assert!(took < Duration::from_secs(8), "took {took:?}");
    let c = r.counts;
    assert!(c.passed >= 1 && c.passed <= 10, "{}", r.to_text(3));
    assert_eq!(c.not_run, cases.len() - c.passed);
    assert_eq!((c.timeouts, c.errors, c.failed), (0, 0, 0));
    let text = r.to_text(3);
    assert!(
        text.contains("the submission's 3 s budget for code checks was used up"),
        "{text}"
    );
}

#[test]
fn fuzz_refuses_bounds_that_run_nothing_or_never_end() {
    let tmp = tempfile::tempdir().unwrap();
    let target = ["fuzz", "--adapter", "cat"];
    for (extra, needle) in [
        (&["--cases", "0"][..], "'0' for '--cases"),
        (&["--time=1e308"], "'1e308' for '--time"),
        (&["--time=1e-300"], "'1e-300' for '--time"),
        (&["--time", "nan"], "'nan' for '--time"),
        (&["--time", "0"], "'0' for '--time"),
    ] {
        let args: Vec<&str> = target.iter().chain(extra).copied().collect();
        let out = run_in(tmp.path(), &args);
        assert_bad_input(&out, needle);
    }
}

#[test]
fn fuzz_by_time_runs_for_the_time_and_shows_every_kind() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // Answers "miss" to everything: every definite hit is a missed hit.
    let start = Instant::now();
    let out = run_in(
        tmp.path(),
        &[
            "fuzz",
            "--adapter",
            &adapter_line("none"),
            "--time",
            "2",
            "--save",
            "found.jsonl",
        ],
    );
    let took = start.elapsed();
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(took >= Duration::from_secs(2), "{took:?}");
    // The search runs the 2 s, shrinking a tenth more (0.2 s); the rest is start-up.
    assert!(took < Duration::from_secs(2 + 6), "{took:?}");
    // More than one round of 1000: the time bounded the run.
    let run: usize = text
        .lines()
        .find(|l| l.contains("random definite cases run"))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("no count of cases run: {text}"));
    assert!(run > 1000, "{text}");
    assert!(text.contains("[missed hit]") && text.contains("(sphere)") && text.contains("(quad)"));
    // An adapter's report speaks of requests, not of the course's Python.
    assert!(!text.contains("RT_object"), "{text}");
    let saved = std::fs::read_to_string(tmp.path().join("found.jsonl")).unwrap();
    assert_eq!(saved.lines().count(), 2, "{saved}");
}

#[test]
fn fuzz_save_with_nothing_failing_writes_nothing() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // The misbehaving adapter only fails hits; `--cases 1` draws one case, a hit or a miss:
    // the first seed that draws a miss makes a run where nothing fails.
    for seed in 0..40 {
        let seed = seed.to_string();
        let out = run_in(
            tmp.path(),
            &[
                "fuzz",
                "--adapter",
                &adapter_line("none"),
                "--cases",
                "1",
                "--seed",
                &seed,
                "--save",
                "found.jsonl",
            ],
        );
        if out.status.code() == Some(0) {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(stderr.contains("nothing failed, so found.jsonl was not written"));
            assert!(!tmp.path().join("found.jsonl").exists());
            return;
        }
    }
    panic!("no seed drew a miss");
}

#[test]
fn a_closed_stdout_ends_check_quietly() {
    if !python_ok() {
        return;
    }
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    for extra in [&["--show", "3000"][..], &["--json"]] {
        let mut child = rtoracle()
            .args(["check", "--adapter", &adapter_line("bare-nan '*'")])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        // The reader is gone (as with `| head -1`).
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!first.is_empty());
        assert_eq!(out.status.code(), Some(1), "{extra:?}: {stderr}");
        // Nothing but the one line saying how the candidate was sandboxed: no panic, no
        // "Broken pipe".
        let others: Vec<&str> = stderr
            .lines()
            .filter(|l| !l.starts_with("rtoracle: sandbox: "))
            .collect();
        assert!(others.is_empty(), "{extra:?}: {stderr}");
    }
}

#[test]
fn grading_stops_a_slow_submission_at_its_budget_and_keeps_the_rest() {
    if !python_ok() {
        return;
    }
    use rtoracle::grade::{checkers::CodeChecker, checkers::code::CourseCodeChecker};
    // Hangs on every miss: with a 2 s case timeout and 3 timeouts per group it would cost 12 s
    // and more; a 3 s budget stops it there.
    let dir = rtoracle::bench::harness::assemble_fixture("hostile_hang_on_miss").unwrap();
    // The seed-0 suite itself (grading derives its suite from the rubric's seed), whose first
    // sphere vectors are hits the fixture answers before its first miss hangs.
    let checker = CourseCodeChecker {
        time_budget: Some(Duration::from_secs(3)),
        vectors: Some((
            "the seed-0 suite".into(),
            rtoracle::oracle::suite::default_suite(0),
        )),
        ..CourseCodeChecker::default()
    };
    let start = Instant::now();
    let out = checker.check(dir.path(), &[ShapeKind::Sphere, ShapeKind::Quad]);
    let took = start.elapsed();
    assert!(took < Duration::from_secs(6), "took {took:?}");
    let spheres = &out.per_group[&ShapeKind::Sphere];
    let quads = &out.per_group[&ShapeKind::Quad];
    // What ran before the budget was used up keeps its marks.
    assert!(spheres.passed > 0, "{spheres:?}");
    assert!(quads.not_run > 0, "{quads:?}");
    assert!(
        out.failures
            .iter()
            .any(|f| f.message.contains("3 s budget for code checks was used up")),
        "{:?}",
        out.failures.iter().map(|f| &f.message).collect::<Vec<_>>()
    );
}

/// `n` vectors of class `any` (degenerate quads) from the default suite, then [`misses`].
fn any_quads_then_misses(n: usize) -> Vec<Case> {
    let any: Vec<Case> = rtoracle::oracle::suite::default_suite(0)
        .into_iter()
        .filter(|c| c.shape.kind() == ShapeKind::Quad && c.expect.class == Class::Any)
        .take(n)
        .collect();
    assert_eq!(any.len(), n);
    any.into_iter().chain(misses()).collect()
}

/// The ids of `cases`, comma-separated (the misbehaving adapter's target list).
fn ids(cases: &[Case]) -> String {
    cases
        .iter()
        .map(|c| c.id.as_str())
        .collect::<Vec<_>>()
        .join(",")
}

/// An adapter hanging on the degenerate quads (class `any`) got PASS: its time-outs were not
/// counted, and the definite quads left unrun after 3 of them did not fail it. Both fail now.
#[test]
fn a_hang_on_vectors_that_are_not_scored_fails_and_so_do_the_vectors_left_unrun() {
    if !python_ok() {
        return;
    }
    let cases = any_quads_then_misses(3);
    let options = RunOptions {
        timeout: Duration::from_millis(500),
        ..options()
    };
    let r = check_command(
        adapter(&format!("hang {}", ids(&cases[..3]))),
        &cases,
        options,
    )
    .unwrap();
    let text = r.to_text(3);
    assert!(!r.passed(), "{text}");
    assert_eq!(
        (r.counts.unscored_timeouts, r.counts.timeouts),
        (3, 0),
        "{text}"
    );
    let quads = &r.by_shape[&ShapeKind::Quad];
    assert!(quads.total > 0 && quads.not_run == quads.total, "{text}");
    assert_eq!(quads.unsupported, 0);
    let spheres = &r.by_shape[&ShapeKind::Sphere];
    assert_eq!(spheres.passed, spheres.total, "{text}");
    assert!(
        text.contains("hangs and crashes: 3 time-outs and 0 crashes"),
        "{text}"
    );
    assert!(text.contains(&format!("left unrun: {} definite vectors", quads.total)));
    assert!(text.contains("verdict: FAIL"), "{text}");
}

/// A SIGABRT on a degenerate quad gave 0 errors and PASS.
#[test]
fn a_crash_on_a_vector_that_is_not_scored_fails() {
    if !python_ok() {
        return;
    }
    let cases = any_quads_then_misses(1);
    let r = check_command(
        adapter(&format!("abort {}", cases[0].id)),
        &cases,
        options(),
    )
    .unwrap();
    let text = r.to_text(3);
    assert!(!r.passed(), "{text}");
    assert_eq!(r.counts.unscored_crashes, 1, "{text}");
    assert_eq!(r.counts.passed, r.counts.total, "{text}");
    assert_eq!(r.failures.len(), 1);
    assert_eq!(r.failures[0].id, cases[0].id);
    assert!(r.failures[0].message.contains("SIGABRT"), "{text}");
}

/// An adapter that dies having flushed half of its answer: the case it was answering is the one
/// that died (the blame went to the next case, which answers right alone, and the half line
/// was a protocol error of its own case).
#[test]
fn an_adapter_killed_mid_line_is_blamed_on_the_case_it_was_answering() {
    if !python_ok() {
        return;
    }
    let cases = misses();
    let r = check_command(
        adapter(&format!("die-mid-line {}", cases[20].id)),
        &cases,
        options(),
    )
    .unwrap();
    let text = r.to_text(3);
    let failed: Vec<(&str, FailureKind)> =
        r.failures.iter().map(|f| (f.id.as_str(), f.kind)).collect();
    assert_eq!(
        failed,
        [(cases[20].id.as_str(), FailureKind::Error)],
        "{text}"
    );
    let m = &r.failures[0].message;
    assert!(
        m.starts_with(
            "the candidate died on this case in the middle of a line (it had written \"{"
        ),
        "{m}"
    );
    assert!(m.contains("SIGKILL"), "{m}");
    assert_eq!(r.counts.passed, cases.len() - 1, "{text}");
}

/// The common C mistake of flushing the hello's answer only: every answer stays in the
/// adapter's buffer. The check fails, and the report says the usual cause.
#[test]
fn an_adapter_that_flushes_only_its_hello_fails_and_is_told_why() {
    if !python_ok() {
        return;
    }
    let cases = misses();
    let options = RunOptions {
        timeout: Duration::from_millis(500),
        ..options()
    };
    let r = check_command(adapter("no-flush none"), &cases, options).unwrap();
    let text = r.to_text(3);
    assert!(!r.passed(), "{text}");
    assert!(r.counts.timeouts > 0, "{text}");
    assert!(
        text.contains(
            "note: no line came from the candidate after its hello while it was sent requests to \
             answer one at a time; the usual cause: stdout not flushed after each line"
        ),
        "{text}"
    );
}

/// A hello that never arrives (not flushed) is refused with the usual cause, by `check` and by
/// `fuzz` (which has `--hello-timeout-ms` too).
#[test]
fn a_hello_that_never_arrives_says_the_usual_cause() {
    if !python_ok() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    for sub in ["check", "fuzz"] {
        let out = run_in(
            tmp.path(),
            &[
                sub,
                "--adapter",
                &adapter_line("no-flush-hello"),
                "--hello-timeout-ms",
                "1500",
            ],
        );
        assert_bad_input(
            &out,
            "no hello answer within 1.5 s (the usual cause: stdout not flushed after each line",
        );
    }
}

/// A misspelt hello key (`shape` for `shapes`) was ignored in silence: the report warns.
#[test]
fn an_unknown_hello_key_is_warned_about() {
    if !python_ok() {
        return;
    }
    let cases = misses();
    let r = check_command(adapter("hello-shape"), &cases, options()).unwrap();
    let text = r.to_text(3);
    assert!(r.passed(), "{text}");
    assert!(
        text.contains("note: its hello has the key \"shape\", which the protocol does not name")
            && text.contains("(did you mean \"shapes\"?)"),
        "{text}"
    );
    let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
    assert!(json["notes"][0].as_str().unwrap().contains("\"shape\""));
}
