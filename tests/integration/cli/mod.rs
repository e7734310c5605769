//! The principles over every subcommand: no input and no interruption makes rtoracle panic,
//! abort, hang, leave a file or folder behind, or say something untrue.
//!
//! One test per principle, table-driven over the subcommands:
//! - every subcommand is in the tables (checked against `rtoracle --help`, so a new one cannot
//!   be forgotten);
//! - a closed stdout: exit 0 or the verdict's code, no panic, no "Broken pipe";
//! - every numeric option (checked against each subcommand's `--help`) at 0, -1, 1e308, NaN and
//!   past the machine: exit 2, one line naming the option;
//! - every output path as the wrong kind (a folder for a file, a file for a folder), under a
//!   file, under a missing folder and where nobody can create files (`/proc`, which refuses even
//!   root): exit 2 at once, one line naming the option, nothing created;
//! - SIGINT and SIGTERM mid-run: exit 130 / 143, no partial output, no temporary or sandbox
//!   folder (the child gets a private `TMPDIR`).

mod readme;

use std::collections::BTreeSet;
use std::path::Path;
use std::process::{Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{assert_bad_input, rtoracle, run_in};

/// Every subcommand, with the areas of `bench`.
const SUBCOMMANDS: [&str; 12] = [
    "render",
    "scenes",
    "golden",
    "vectors",
    "explain",
    "check",
    "fuzz",
    "physics",
    "compare",
    "grade",
    "autograder",
    "bench",
];
const BENCH_AREAS: [&str; 5] = ["render", "oracle", "candidate", "compare", "grade"];

/// Names listed in the `Commands:` part of a help text.
fn listed_commands(help: &str) -> BTreeSet<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|n| *n != "help")
        .map(String::from)
        .collect()
}

fn help_of(args: &[&str]) -> String {
    let out = rtoracle().args(args).arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{args:?} --help");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn the_tables_name_every_subcommand_and_bench_area() {
    let top: BTreeSet<String> = SUBCOMMANDS.iter().map(|s| s.to_string()).collect();
    assert_eq!(listed_commands(&help_of(&[])), top);
    let areas: BTreeSet<String> = BENCH_AREAS.iter().map(|s| s.to_string()).collect();
    assert_eq!(listed_commands(&help_of(&["bench"])), areas);
    // The one-line summary names them all too.
    let top_help = help_of(&[]);
    let bench_line = top_help.lines().find(|l| l.contains("  bench ")).unwrap();
    for area in BENCH_AREAS {
        assert!(bench_line.contains(area), "{bench_line}");
    }
}

// ---------------------------------------------------------------------------------------------
// Numeric options

/// Every option that takes a value, per (sub)command: `(command, option, numeric, zero is a
/// valid value)`. A test checks this against `--help`, so it cannot go stale.
const VALUE_OPTIONS: &[(&str, &str, bool, bool)] = &[
    ("render", "--output", false, false),
    ("render", "--spp", true, false),
    ("render", "--seed", true, true),
    ("render", "--width", true, false),
    ("render", "--threads", true, false),
    ("render", "--profile", false, false),
    ("render", "--textures", false, false),
    ("scenes", "--dump", false, false),
    ("scenes", "--profile", false, false),
    ("scenes", "--textures", false, false),
    ("scenes", "--export", false, false),
    ("golden", "--dir", false, false),
    ("golden", "--spp", true, false),
    ("golden", "--scenes", false, false),
    ("golden", "--out", false, false),
    ("vectors", "--seed", true, true),
    ("vectors", "--count", true, false),
    ("vectors", "--shapes", false, false),
    ("vectors", "--output", false, false),
    ("vectors", "--profile", false, false),
    ("vectors", "--precision", false, false),
    ("explain", "--seed", true, true),
    ("explain", "--vectors", false, false),
    ("explain", "--profile", false, false),
    ("explain", "--precision", false, false),
    ("check", "--python-course", false, false),
    ("check", "--adapter", false, false),
    ("check", "--vectors", false, false),
    ("check", "--seed", true, true),
    ("check", "--timeout-ms", true, false),
    ("check", "--hello-timeout-ms", true, false),
    ("check", "--show", true, true),
    ("check", "--profile", false, false),
    ("check", "--precision", false, false),
    ("check", "--require", false, false),
    ("check", "--python", false, false),
    ("check", "--week", true, false),
    ("check", "--alpha", true, false),
    ("check", "--expose", false, false),
    ("fuzz", "--python-course", false, false),
    ("fuzz", "--adapter", false, false),
    ("fuzz", "--cases", true, false),
    ("fuzz", "--seed", true, true),
    ("fuzz", "--time", true, false),
    ("fuzz", "--timeout-ms", true, false),
    ("fuzz", "--hello-timeout-ms", true, false),
    ("fuzz", "--save", false, false),
    ("fuzz", "--profile", false, false),
    ("fuzz", "--precision", false, false),
    ("fuzz", "--python", false, false),
    ("fuzz", "--expose", false, false),
    ("physics", "--python-course", false, false),
    ("physics", "--adapter", false, false),
    ("physics", "--python", false, false),
    ("physics", "--expose", false, false),
    ("physics", "--material", false, false),
    ("physics", "--samples", true, false),
    ("physics", "--seed", true, true),
    ("physics", "--alpha", true, false),
    ("physics", "--timeout-ms", true, false),
    ("physics", "--hello-timeout-ms", true, false),
    ("physics", "--furnace-spp", true, false),
    ("physics", "--renders", true, false),
    ("compare", "--scene", false, false),
    ("compare", "--golden", false, false),
    ("compare", "--spp", true, false),
    ("compare", "--encoding", false, false),
    ("compare", "--heatmap", false, false),
    ("compare", "--report", false, false),
    ("grade", "--batch", false, false),
    ("grade", "--shard", false, false),
    ("grade", "--merge", false, false),
    ("grade", "--rubric", false, false),
    ("grade", "--out", false, false),
    ("grade", "--format", false, false),
    ("grade", "--vectors", false, false),
    ("grade", "--case-timeout-ms", true, false),
    ("grade", "--threads", true, false),
    ("grade", "--python", false, false),
    ("autograder", "--out", false, false),
    ("autograder", "--rubric", false, false),
    ("autograder", "--binary", false, false),
    ("autograder", "--seed", true, true),
    ("bench render", "--runs", true, false),
    ("bench render", "--memory-width", true, false),
    ("bench render", "--cc", false, false),
    ("bench render", "--mitsuba-spp", true, false),
    ("bench render", "--python", false, false),
    ("bench oracle", "--cases", true, false),
];

/// The long options of a help text that take a value (`--name <VALUE>`).
fn value_options(help: &str) -> BTreeSet<String> {
    help.lines()
        .map(str::trim_start)
        .map(|l| {
            // "-o, --output <OUT>" or "--spp <N>"
            match l.split_once(", ") {
                Some((short, rest)) if short.len() == 2 && short.starts_with('-') => rest,
                _ => l,
            }
        })
        .filter(|l| l.starts_with("--"))
        .filter_map(|l| {
            let mut words = l.split_whitespace();
            let name = words.next()?;
            let value = words.next()?;
            value.starts_with('<').then(|| name.to_string())
        })
        .collect()
}

#[test]
fn the_option_table_matches_every_help_text() {
    let mut commands: Vec<String> = SUBCOMMANDS
        .iter()
        .filter(|s| **s != "bench")
        .map(|s| s.to_string())
        .collect();
    commands.extend(BENCH_AREAS.iter().map(|a| format!("bench {a}")));
    for command in &commands {
        let args: Vec<&str> = command.split(' ').collect();
        let from_help = value_options(&help_of(&args));
        let from_table: BTreeSet<String> = VALUE_OPTIONS
            .iter()
            .filter(|(c, ..)| c == command)
            .map(|(_, o, ..)| o.to_string())
            .collect();
        assert_eq!(from_help, from_table, "options of `rtoracle {command}`");
    }
}

/// Arguments that make each command otherwise valid (the bad option is appended), in a folder
/// holding an empty `sub/` and a course folder `course/` with an `RT_object.py`.
fn valid_prefix(command: &str) -> Vec<&'static str> {
    match command {
        "render" => vec!["render", "week04-quad", "-o", "out.png"],
        "golden" => vec!["golden", "--dir", "g"],
        "vectors" => vec!["vectors", "-o", "v.jsonl"],
        "explain" => vec!["explain", "sphere-random-0000"],
        "check" => vec!["check", "--adapter", "cat"],
        "fuzz" => vec!["fuzz", "--adapter", "cat"],
        "physics" => vec!["physics", "--adapter", "cat"],
        "compare" => vec!["compare", "missing.png", "--scene", "week04-quad"],
        "grade" => vec!["grade", "sub"],
        "autograder" => vec!["autograder", "--out", "a.zip"],
        "bench render" => vec!["bench", "render"],
        "bench oracle" => vec!["bench", "oracle"],
        other => panic!("no valid prefix for {other}"),
    }
}

#[test]
fn every_numeric_option_refuses_zero_negatives_huge_nan_and_past_the_machine() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir(tmp.path().join("sub")).unwrap();
    let mut checked = 0;
    for &(command, option, numeric, zero_ok) in VALUE_OPTIONS {
        if !numeric {
            continue;
        }
        let mut values = vec!["-1", "1e308", "NaN", "99999999999999999999999"];
        if !zero_ok {
            values.push("0");
        }
        for value in values {
            for joined in [false, true] {
                let mut args = valid_prefix(command);
                let together = format!("{option}={value}");
                if joined {
                    args.push(&together);
                } else {
                    args.push(option);
                    args.push(value);
                }
                let start = Instant::now();
                let out = run_in(tmp.path(), &args);
                let stderr = String::from_utf8_lossy(&out.stderr);
                assert_bad_input(&out, option);
                assert!(
                    !stderr.contains("tip:") && !stderr.contains("-- "),
                    "no clap tip: {args:?}: {stderr}"
                );
                assert!(
                    start.elapsed() < Duration::from_secs(20),
                    "refused before any work: {args:?}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 100, "{checked}");
    let left: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        left,
        vec![std::ffi::OsString::from("sub")],
        "nothing written"
    );
}

#[test]
fn usage_errors_are_one_line_pointing_to_help() {
    let tmp = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (&["render"][..], "<SCENE>"),
        (&["render", "week04-quad", "--nope"], "--nope"),
        (&["grade"], "--batch"),
        (&["nope"], "nope"),
        (
            &["bench", "render", "--memory-width", "99999999"],
            "100 million",
        ),
    ] {
        let out = run_in(tmp.path(), args);
        assert_bad_input(&out, needle);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("--help"), "{args:?}: {stderr}");
    }
}

// ---------------------------------------------------------------------------------------------
// Output paths

/// Every option that names an output: `(args before, option, args after, wants a folder)`.
/// The command is otherwise valid and would work for long (minutes), so a quick exit 2 shows the
/// path was checked first.
const OUTPUTS: &[(&[&str], &str, &[&str], bool)] = &[
    (
        &["render", "week04-quad", "--spp", "100000"],
        "-o",
        &[],
        false,
    ),
    (&["golden", "--scenes", "week04-quad"], "--dir", &[], true),
    (&["vectors", "--count", "10000000"], "-o", &[], false),
    (&["fuzz", "--adapter", "sleep 600"], "--save", &[], false),
    (
        &["compare", "c.png", "--scene", "week04-quad"],
        "--heatmap",
        &[],
        false,
    ),
    (
        &["compare", "c.png", "--scene", "week04-quad"],
        "--report",
        &[],
        true,
    ),
    (&["grade", "sub"], "--out", &[], true),
    (&["autograder"], "--out", &[], false),
];

#[test]
fn every_output_path_is_checked_before_the_work() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    std::fs::create_dir(root.join("sub")).unwrap();
    std::fs::create_dir(root.join("a-folder")).unwrap();
    std::fs::write(root.join("a-file"), b"x").unwrap();
    std::fs::write(root.join("c.png"), b"not a png").unwrap();
    let before = names(root);
    for &(pre, option, post, wants_folder) in OUTPUTS {
        let wrong_kind = if wants_folder { "a-file" } else { "a-folder" };
        let leaf = if wants_folder { "out" } else { "out.png" };
        let under_file = format!("a-file/{leaf}");
        let missing = format!("no-such-folder/{leaf}");
        let proc = format!("/proc/{leaf}");
        for (path, says) in [
            (
                wrong_kind,
                if wants_folder {
                    "is a file"
                } else {
                    "is a folder"
                },
            ),
            (under_file.as_str(), "is a file, not a folder"),
            (missing.as_str(), "does not exist"),
            (proc.as_str(), "cannot create files in '/proc'"),
        ] {
            let mut args: Vec<&str> = pre.to_vec();
            args.push(option);
            args.push(path);
            args.extend_from_slice(post);
            let start = Instant::now();
            let out = run_in(root, &args);
            assert_bad_input(&out, option);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(stderr.contains(path), "{args:?}: {stderr}");
            assert!(
                stderr.contains(says),
                "{args:?} should say {says:?}: {stderr}"
            );
            assert!(
                !stderr.contains(".tmp") && !stderr.contains(".rtoracle-"),
                "{stderr}"
            );
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "{args:?} took {:?}",
                start.elapsed()
            );
            assert_eq!(names(root), before, "{args:?} left something behind");
        }
    }
}

#[test]
fn wrong_names_and_wrong_inputs_are_refused_up_front() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    std::fs::create_dir(root.join("empty")).unwrap();
    std::fs::write(root.join("a-file"), b"x").unwrap();
    std::fs::write(root.join("c.png"), b"x").unwrap();
    let before = names(root);
    let cases: &[(&[&str], &str)] = &[
        (&["render", "week04-quad", "-o", ".png"], "no extension"),
        (&["render", "week04-quad", "-o", "x.jpg"], ".png or .exr"),
        (
            &[
                "compare",
                "c.png",
                "--scene",
                "week04-quad",
                "--heatmap",
                "h.jpg",
            ],
            ".png",
        ),
        (
            &["check", "--python-course", "empty"],
            "has no RT_object.py",
        ),
        (&["fuzz", "--python-course", "empty"], "has no RT_object.py"),
        (&["check", "--python-course", "a-file"], "is a file"),
        (&["grade", "--batch", "empty"], "no submissions found"),
        (&["grade", "--batch", "a-file"], "is a file"),
        (&["grade", "a-file"], "is a file"),
        (&["golden", "--scenes", "nope"], "no such built-in scene"),
        (&["golden", "--check", "--dir", "a-file"], "is a file"),
        (&["autograder", "--binary", "/bin/ls"], "is not an rtoracle"),
        (&["autograder", "--binary", "empty"], "is a folder"),
        (
            &["grade", "empty", "--out", "empty"],
            "is inside the submission folder",
        ),
        (
            &["grade", "empty", "--out", "empty/report"],
            "is inside the submission folder",
        ),
    ];
    for (args, needle) in cases {
        let out = run_in(root, args);
        assert_bad_input(&out, needle);
        assert_eq!(names(root), before, "{args:?} left something behind");
    }
    let out = run_in(root, &["golden", "--scenes", "nope"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains(".toml"));
}

#[test]
fn a_vector_file_with_a_duplicate_id_is_refused_naming_the_id_and_lines() {
    let tmp = tempfile::tempdir().unwrap();
    let out = run_in(tmp.path(), &["vectors", "--count", "3", "-o", "v.jsonl"]);
    assert_eq!(out.status.code(), Some(0));
    let text = std::fs::read_to_string(tmp.path().join("v.jsonl")).unwrap();
    let first = text.lines().next().unwrap().to_string();
    let id = serde_json::from_str::<serde_json::Value>(&first).unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string();
    std::fs::write(tmp.path().join("v.jsonl"), format!("{text}{first}\n")).unwrap();
    let out = run_in(tmp.path(), &["explain", &id, "--vectors", "v.jsonl"]);
    assert_bad_input(
        &out,
        &format!("v.jsonl:4: not a valid vector: the id {id:?} is already used on line 1"),
    );
}

// ---------------------------------------------------------------------------------------------
// A closed stdout

/// Runs `args` in `dir` with stdout a pipe whose reading end is closed at once.
fn with_closed_stdout(dir: &Path, args: &[&str]) -> Output {
    let mut child = rtoracle()
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    child.wait_with_output().unwrap()
}

#[test]
fn a_closed_stdout_is_a_quiet_exit_for_every_subcommand() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    std::fs::create_dir(root.join("sub")).unwrap();
    // A failing candidate with many failures to print: an adapter answering every case "miss".
    let adapter = root.join("miss.py");
    std::fs::write(&adapter, rtoracle::bench::harness::ECHO_ADAPTER).unwrap();
    let adapter_cmd = format!("/usr/bin/python3 {}", adapter.display());
    // (args, allowed exit codes)
    let runs: Vec<(Vec<&str>, &[i32])> = vec![
        (vec!["--help"], &[0]),
        (vec!["--version"], &[0]),
        (vec!["render", "--help"], &[0]),
        (
            vec![
                "render",
                "week04-quad",
                "--width",
                "8",
                "--spp",
                "1",
                "-o",
                "r.png",
            ],
            &[0],
        ),
        (vec!["scenes"], &[0]),
        (vec!["scenes", "--dump", "week04-quad"], &[0]),
        (
            vec![
                "golden",
                "--scenes",
                "week04-quad",
                "--spp",
                "1",
                "--dir",
                "g",
            ],
            &[0],
        ),
        (vec!["vectors", "--count", "10", "-o", "v.jsonl"], &[0]),
        (vec!["explain", "sphere-random-0000"], &[0]),
        (
            vec!["check", "--adapter", &adapter_cmd, "--show", "3000"],
            &[1],
        ),
        (vec!["check", "--adapter", &adapter_cmd, "--json"], &[1]),
        (
            vec!["fuzz", "--adapter", &adapter_cmd, "--cases", "50"],
            &[1],
        ),
        (
            vec!["physics", "--adapter", &adapter_cmd, "--samples", "100"],
            &[1],
        ),
        (
            vec!["compare", "r.png", "--golden", "g/week04-quad.exr"],
            &[0, 1, 2],
        ),
        (
            vec![
                "render",
                "week04-quad",
                "--width",
                "8",
                "--spp",
                "4",
                "--variance",
                "-o",
                "a.exr",
            ],
            &[0],
        ),
        (
            vec![
                "render",
                "week04-quad",
                "--width",
                "8",
                "--spp",
                "4",
                "--seed",
                "1",
                "--variance",
                "-o",
                "b.exr",
            ],
            &[0],
        ),
        (vec!["compare", "a.exr", "b.exr"], &[0, 1]),
        (vec!["compare", "a.exr", "b.exr", "--json"], &[0, 1]),
        (vec!["grade", "--print-rubric"], &[0]),
        (vec!["grade", "sub", "--out", "report"], &[0]),
        (vec!["autograder", "--out", "a.zip"], &[0]),
        (vec!["bench", "--help"], &[0]),
    ];
    for (args, codes) in runs {
        let out = with_closed_stdout(root, &args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.code().is_some_and(|c| codes.contains(&c)),
            "{args:?}: exit {:?}: {stderr}",
            out.status
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!stderr.contains("Broken pipe"), "{args:?}: {stderr}");
    }
}

#[test]
fn a_closed_stderr_is_no_panic_either() {
    let tmp = tempfile::tempdir().unwrap();
    let runs: &[(&[&str], i32)] = &[
        (
            &[
                "render",
                "week04-quad",
                "--width",
                "8",
                "--spp",
                "1",
                "-o",
                "r.png",
            ],
            0,
        ),
        (&["vectors", "--count", "10", "-o", "v.jsonl"], 0),
        (&["render", "no-such-scene"], 2),
        (&["render", "--spp", "-1", "week04-quad"], 2),
        // A submission folder: the sandbox announces itself on stderr.
        (&["check", "--python-course", "sub"], 0),
    ];
    let sub = tmp.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python");
    for f in [
        "common/RT_utility.py",
        "common/RT_ray.py",
        "common/RT_material.py",
        "common/RT_texture.py",
    ] {
        let from = fixtures.join(f);
        std::fs::copy(&from, sub.join(from.file_name().unwrap())).unwrap();
    }
    std::fs::copy(
        fixtures.join("reference_RT_object.py"),
        sub.join("RT_object.py"),
    )
    .unwrap();
    {
        use std::os::unix::fs::PermissionsExt;
        for d in [tmp.path(), sub.as_path()] {
            std::fs::set_permissions(d, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
    }
    for (args, code) in runs {
        let mut child = rtoracle()
            .current_dir(tmp.path())
            .args(*args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stderr.take());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(*code), "{args:?}");
    }
    assert!(tmp.path().join("r.png").is_file() && tmp.path().join("v.jsonl").is_file());
}

// ---------------------------------------------------------------------------------------------
// Interruptions

/// Starts `args` in `dir` with a private `TMPDIR`, waits `after`, sends `signal`, and returns
/// the exit code and what was left in `TMPDIR`.
fn interrupted(
    dir: &Path,
    args: &[&str],
    after: Duration,
    signal: i32,
) -> (Option<i32>, Vec<String>) {
    interrupted_when(dir, args, &[], signal, |_| std::thread::sleep(after))
}

/// Starts `args` in `dir` with a private `TMPDIR` and `envs`, calls `wait` with the child,
/// sends `signal`, and returns the exit code and what was left in `TMPDIR`.
fn interrupted_when(
    dir: &Path,
    args: &[&str],
    envs: &[(&str, &Path)],
    signal: i32,
    wait: impl FnOnce(&mut std::process::Child),
) -> (Option<i32>, Vec<String>) {
    let private = tempfile::tempdir().unwrap();
    let mut child = rtoracle()
        .current_dir(dir)
        .args(args)
        .env("TMPDIR", private.path())
        .envs(envs.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait(&mut child);
    // SAFETY: kill(2) on our own child's pid, which has not been waited for.
    unsafe {
        libc::kill(child.id() as i32, signal);
    }
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("{args:?} did not exit within 30 s of signal {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (status.code(), names(private.path()))
}

const SIGINT: i32 = libc::SIGINT;
const SIGTERM: i32 = libc::SIGTERM;

#[test]
fn sigint_and_sigterm_mid_run_leave_nothing_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let runs: &[&[&str]] = &[
        &["render", "week04-quad", "--spp", "100000", "-o", "out.png"],
        &["render", "week04-quad", "--spp", "100000", "-o", "out.exr"],
        &[
            "golden",
            "--scenes",
            "week04-quad,week04-sphere",
            "--dir",
            "goldens",
        ],
        &["vectors", "--count", "10000000", "-o", "v.jsonl"],
    ];
    for args in runs {
        for (signal, code) in [(SIGINT, 130), (SIGTERM, 143)] {
            let (got, left_in_tmp) = interrupted(root, args, Duration::from_millis(700), signal);
            assert_eq!(got, Some(code), "{args:?} on signal {signal}");
            assert!(
                left_in_tmp.is_empty(),
                "{args:?}: TMPDIR keeps {left_in_tmp:?}"
            );
            assert!(names(root).is_empty(), "{args:?} left {:?}", names(root));
        }
    }
}

/// `bench render` builds its C loop and measures memory in temporary folders, with a compiler
/// and `rtoracle render` as children: interrupted while it times the reference, while it builds
/// or runs the C loop, or while it measures memory, it exits with the signal's code and leaves
/// nothing in its TMPDIR.
#[test]
fn an_interrupted_bench_render_leaves_nothing_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let args = ["bench", "render", "--runs", "1", "--memory-width", "600"];
    for (after, signal, code) in [
        (400, SIGINT, 130),
        (1300, SIGTERM, 143),
        (1800, SIGINT, 130),
        (2600, SIGINT, 130),
        (3600, SIGTERM, 143),
    ] {
        let (got, left_in_tmp) = interrupted(root, &args, Duration::from_millis(after), signal);
        // A run that finished before the signal exits 0; it must leave nothing either.
        assert!(
            got == Some(code) || got == Some(0),
            "after {after} ms: {got:?}"
        );
        assert!(
            left_in_tmp.is_empty(),
            "after {after} ms: TMPDIR keeps {left_in_tmp:?}"
        );
        assert!(
            names(root).is_empty(),
            "after {after} ms: left {:?}",
            names(root)
        );
    }
}

#[test]
fn sigint_during_check_and_grade_leaves_no_sandbox_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let hang = rtoracle::bench::harness::assemble_fixture("hostile_hang_on_miss").unwrap();
    let course = hang.path().to_str().unwrap().to_string();
    std::fs::create_dir(root.join("sub")).unwrap();
    for f in std::fs::read_dir(hang.path()).unwrap() {
        let f = f.unwrap();
        std::fs::copy(f.path(), root.join("sub").join(f.file_name())).unwrap();
    }
    let runs: Vec<Vec<&str>> = vec![
        vec!["check", "--python-course", &course],
        vec!["fuzz", "--python-course", &course],
        vec!["physics", "--adapter", "sleep 600"],
        vec!["grade", "sub", "--out", "report"],
    ];
    for args in &runs {
        for (signal, code) in [(SIGINT, 130), (SIGTERM, 143)] {
            let (got, left_in_tmp) = interrupted(root, args, Duration::from_millis(1500), signal);
            assert_eq!(got, Some(code), "{args:?} on signal {signal}");
            assert!(
                left_in_tmp.is_empty(),
                "{args:?}: TMPDIR keeps {left_in_tmp:?}"
            );
            assert_eq!(names(root), vec!["sub"], "{args:?} left a report behind");
        }
    }
}

/// Every file below `dir` with its bytes (`sub/name` for files in folders).
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for name in names(dir) {
        let path = dir.join(&name);
        if path.is_dir() {
            out.extend(
                tree(&path)
                    .into_iter()
                    .map(|(n, b)| (format!("{name}/{n}"), b)),
            );
        } else {
            out.push((name, std::fs::read(&path).unwrap()));
        }
    }
    out
}

/// Waits until a name starting with `staging` stands in `dir` (the child's staging folder), then
/// `then` more.
fn until_staged<'a>(
    dir: &'a Path,
    staging: &'a str,
    then: Duration,
) -> impl FnOnce(&mut std::process::Child) + 'a {
    move |child| {
        let deadline = Instant::now() + Duration::from_secs(60);
        while !names(dir).iter().any(|n| n.starts_with(staging)) {
            if let Some(s) = child.try_wait().unwrap() {
                panic!("it ended ({s}) before its staging folder {staging}* appeared");
            }
            assert!(Instant::now() < deadline, "no {staging}* in 60 s");
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(then);
    }
}

/// An interruption while a report folder is being made (`compare --report` rendering its
/// golden, `grade` and `grade --batch` running a submission that hangs) removes the staging
/// folder, which was there when the signal came, and leaves the previous report folder as it
/// was, byte for byte.
#[test]
fn an_interrupted_report_leaves_the_previous_one_as_it_was_and_no_staging_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let hang = rtoracle::bench::harness::assemble_fixture("hostile_hang_on_miss").unwrap();
    for sub in ["sub", "subs/a", "subs/b"] {
        std::fs::create_dir_all(root.join(sub)).unwrap();
        for f in std::fs::read_dir(hang.path()).unwrap() {
            let f = f.unwrap();
            std::fs::copy(f.path(), root.join(sub).join(f.file_name())).unwrap();
        }
    }
    let camera = rtoracle::scene::builtin("week04-sphere")
        .unwrap()
        .camera(None);
    let (w, h) = (camera.width, camera.height);
    rtoracle::image_io::write_png(
        &root.join("cand.png"),
        &rtoracle::image_io::Rgb8Image {
            width: w,
            height: h,
            data: vec![128; 3 * w * h],
        },
    )
    .unwrap();
    // The previous reports.
    let previous: [(&str, &[&str]); 3] = [
        ("rep", &["report.json", "heatmap.png", "region-7.png"]),
        ("graded", &["report.json", "feedback.md"]),
        (
            "batch",
            &["gradebook.csv", "a/report.json", "old/feedback.md"],
        ),
    ];
    for (dir, files) in previous {
        for f in files {
            let path = root.join(dir).join(f);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, format!("previous {f}")).unwrap();
        }
    }
    let before: Vec<_> = previous.iter().map(|(d, _)| tree(&root.join(d))).collect();
    let inputs = names(root);
    // A golden at an spp that is not embedded is rendered, for seconds, into a cache of its own.
    let cache = tempfile::tempdir().unwrap();
    let runs: [(&[&str], &str); 3] = [
        (
            &[
                "compare",
                "cand.png",
                "--scene",
                "week04-sphere",
                "--spp",
                "50",
                "--report",
                "rep",
            ],
            ".rep.rtoracle-",
        ),
        (&["grade", "sub", "--out", "graded"], ".graded.rtoracle-"),
        (
            &["grade", "--batch", "subs", "--out", "batch"],
            ".batch.rtoracle-",
        ),
    ];
    for (args, staging) in runs {
        for (signal, code) in [(SIGINT, 130), (SIGTERM, 143)] {
            let envs = [("RTORACLE_CACHE_DIR", cache.path())];
            let wait = until_staged(root, staging, Duration::from_millis(300));
            let (got, left_in_tmp) = interrupted_when(root, args, &envs, signal, wait);
            assert_eq!(got, Some(code), "{args:?} on signal {signal}");
            assert!(
                left_in_tmp.is_empty(),
                "{args:?}: TMPDIR keeps {left_in_tmp:?}"
            );
            assert_eq!(names(root), inputs, "{args:?} on signal {signal}");
            let after: Vec<_> = previous.iter().map(|(d, _)| tree(&root.join(d))).collect();
            assert!(after == before, "{args:?} changed a previous report");
        }
    }
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}
