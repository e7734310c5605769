//! The sandbox against hostile submissions (docs/sandbox.md): one test per
//! class of attack, each a course-layout submission (the honest fixture plus a hostile import)
//! run through the real binary. They need root, as a grader on Gradescope has it; they say so
//! and pass when not root.

use std::path::{Path, PathBuf};
use std::process::Output;

use rtoracle::bench::harness::assemble_fixture;

use crate::common::*;

fn root(test: &str) -> bool {
    // SAFETY: geteuid has no preconditions.
    let root = unsafe { libc::geteuid() } == 0;
    if !root {
        eprintln!("skipped {test}: needs root (the grader's situation on Gradescope)");
    }
    root
}

/// The honest fixture with `hostile` appended to its `RT_object.py` (run at import), in a folder
/// a sandbox user may read.
fn hostile(hostile: &str) -> tempfile::TempDir {
    let dir = assemble_fixture("honest_reference").unwrap();
    let object = dir.path().join("RT_object.py");
    let mut text = std::fs::read_to_string(&object).unwrap();
    text.push_str("\n# --- hostile part ---\n");
    text.push_str(hostile);
    std::fs::write(&object, text).unwrap();
    open_up(dir.path());
    dir
}

fn open_up(dir: &Path) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o755)).unwrap();
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn check_json(dir: &Path, extra: &[&str]) -> (Output, serde_json::Value) {
    let mut args = vec!["check", "--python-course", dir.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let out = run_in(dir, &args);
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
    // The intersections' report, where the sandbox and the stderr tail are (check --json v2).
    (out, json["intersections"].clone())
}

#[test]
fn a_submission_cannot_read_root_only_files_nor_the_grader_s() {
    if !root("a_submission_cannot_read_root_only_files_nor_the_grader_s") {
        return;
    }
    // A grader's file it guesses: world-readable, outside the submission.
    let grader = tempfile::tempdir().unwrap();
    open_up(grader.path());
    let secret = grader.path().join("vectors.jsonl");
    std::fs::write(&secret, "GRADER-SECRET-VECTORS\n").unwrap();
    let sub = hostile(&format!(
        r#"
import sys as _s
for _p in ["/etc/shadow", {secret:?}]:
    try:
        with open(_p) as _f:
            _s.stderr.write("READ %s %r\n" % (_p, _f.read(60)))
    except Exception as _e:
        _s.stderr.write("DENIED %s %s\n" % (_p, type(_e).__name__))
"#,
        secret = secret.display().to_string()
    ));
    let (out, json) = check_json(sub.path(), &[]);
    let tail = json["stderr_tail"].as_str().unwrap_or_default().to_string();
    assert!(
        tail.contains("DENIED /etc/shadow"),
        "{tail}\n{}",
        stderr(&out)
    );
    assert!(!tail.contains("READ /etc/shadow"), "{tail}");
    // The grader's file is hidden under bubblewrap (the fallback sees world-readable files).
    if json["sandbox"]["isolation"] == "bubblewrap" {
        assert!(!tail.contains("GRADER-SECRET"), "{tail}");
        assert!(
            tail.contains(&format!("DENIED {} FileNotFoundError", secret.display())),
            "{tail}"
        );
    }
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

#[test]
fn a_double_forked_setsid_sleeper_does_not_outlive_the_check() {
    if !root("a_double_forked_setsid_sleeper_does_not_outlive_the_check") {
        return;
    }
    let marker = format!("rtoracle-test-sleeper-{}", std::process::id());
    let sub = hostile(&format!(
        r#"
import os as _o, sys as _s
if _o.fork() == 0:
    _o.setsid()
    if _o.fork() == 0:
        _o.execv(_s.executable, [_s.executable, "-c", "import time; time.sleep(600)", {marker:?}])
    _o._exit(0)
_s.stderr.write("daemon started\n")
"#
    ));
    for mode in ["auto", "uid"] {
        let out = rtoracle()
            .current_dir(sub.path())
            .env("RTORACLE_SANDBOX", mode)
            .args(["check", "--python-course", sub.path().to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{mode}: {}", stderr(&out));
        let survivors = processes_with(&marker);
        assert!(survivors.is_empty(), "{mode}: still running: {survivors:?}");
    }
}

/// Files a submission made anywhere it could write, and their bloat: in both modes it is stopped
/// once it holds more than the policy's `disk_bytes`, said so in words, and none of its files is
/// left (in the fallback, the host's `/tmp`, `/var/tmp` and `/dev/shm` are swept of the uid's
/// files, a link it planted to a grader file included, the file itself untouched).
#[test]
fn a_submission_that_fills_the_disk_is_stopped_and_leaves_no_file() {
    // Its 257 MiB tmpfs is the host's shared memory while it lives, which the tests that measure
    // the host's shared memory would count as theirs.
    let _measuring = SHMEM_MEASURED.lock().unwrap_or_else(|e| e.into_inner());
    if !root("a_submission_that_fills_the_disk_is_stopped_and_leaves_no_file") {
        return;
    }
    let marker = format!("rtoracle-test-bloat-{}", std::process::id());
    let grader = tempfile::tempdir().unwrap();
    open_up(grader.path());
    let precious = grader.path().join("precious.txt");
    std::fs::write(&precious, "keep me").unwrap();
    let sub = hostile(&format!(
        r#"
import os as _o
_chunk = b"x" * (1 << 20)
for _d in ("/tmp", "/var/tmp", "/dev/shm", "."):
    try:
        with open(_o.path.join(_d, {marker:?}), "wb") as _f:
            _f.write(_chunk)
        _o.symlink({precious:?}, _o.path.join(_d, {marker:?} + "-link"))
        _o.makedirs(_o.path.join(_d, {marker:?} + "-dir", "deep"))
    except OSError:
        pass
for _n in range(400):
    with open("/tmp/{marker}-%d" % _n, "wb") as _f:
        for _ in range(8):
            _f.write(_chunk)
"#,
        precious = precious.display().to_string()
    ));
    for mode in ["auto", "uid"] {
        let out = rtoracle()
            .current_dir(sub.path())
            .env("RTORACLE_SANDBOX", mode)
            .args([
                "check",
                "--python-course",
                sub.path().to_str().unwrap(),
                "--json",
                // The write limit, not the hello's timer, must stop it, however slowly a loaded
                // machine writes its 256 MiB.
                "--hello-timeout-ms",
                "300000",
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            text.contains("the sandbox stopped it: it wrote more than 256 MiB"),
            "{mode}: {}\n...\n{}\n{}",
            text.get(..600).unwrap_or(&text),
            // The first case's words, where the reason it failed is.
            text.find("\"message\"")
                .and_then(|at| text.get(at..).map(|t| t.get(..1200).unwrap_or(t)))
                .unwrap_or(""),
            stderr(&out)
        );
        assert_eq!(out.status.code(), Some(1), "{mode}: {}", stderr(&out));
        for root in ["/tmp", "/var/tmp", "/dev/shm"] {
            let left: Vec<_> = std::fs::read_dir(root)
                .map(|d| {
                    d.flatten()
                        .filter(|e| e.file_name().to_string_lossy().contains(&marker))
                        .map(|e| e.path())
                        .collect()
                })
                .unwrap_or_default();
            assert!(left.is_empty(), "{mode}: left {left:?}");
        }
        assert_eq!(std::fs::read_to_string(&precious).unwrap(), "keep me");
    }
}

/// The pids whose command line contains `needle`.
fn processes_with(needle: &str) -> Vec<u32> {
    let mut found = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        if pid == std::process::id() {
            continue;
        }
        let cmdline = std::fs::read(e.path().join("cmdline")).unwrap_or_default();
        let state = std::fs::read_to_string(e.path().join("stat")).unwrap_or_default();
        let zombie = state
            .rsplit(')')
            .next()
            .is_some_and(|r| r.trim_start().starts_with('Z'));
        if !zombie && String::from_utf8_lossy(&cmdline).contains(needle) {
            found.push(pid);
        }
    }
    found
}

/// `name: score / max` lines of `grade --batch`.
fn scores(out: &Output) -> Vec<(String, String)> {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| {
            let (name, score) = l.split_once(": ")?;
            Some((name.to_string(), score.to_string()))
        })
        .collect()
}

/// The built-in week-4 rubric with its images judged from uploads (these submissions upload
/// none, so the images score 0 alone and in a batch alike): a batch here spends its time on the
/// code the sandbox runs, not on Python renders of scenes.
fn code_rubric() -> &'static str {
    static RUBRIC: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    RUBRIC.get_or_init(|| {
        let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("sandbox-uploads-rubric.toml");
        std::fs::write(&path, rtoracle::grade::rubric::week04_uploads_toml()).unwrap();
        path.to_str().unwrap().to_string()
    })
}

#[test]
fn a_killer_in_a_batch_costs_its_honest_classmates_nothing() {
    if !root("a_killer_in_a_batch_costs_its_honest_classmates_nothing") {
        return;
    }
    let batch = tempfile::tempdir().unwrap();
    open_up(batch.path());
    let honest = assemble_fixture("honest_reference").unwrap();
    let killer = hostile(
        r#"
import os as _o, time as _t
if _o.fork() == 0:
    _o.setsid()
    _end = _t.time() + 8
    while _t.time() < _end:
        try:
            _o.kill(-1, 9)
        except Exception:
            pass
        _t.sleep(0.005)
    _o._exit(0)
"#,
    );
    let copy = |from: &Path, to: PathBuf| {
        std::fs::create_dir_all(&to).unwrap();
        for e in std::fs::read_dir(from).unwrap().flatten() {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    };
    copy(killer.path(), batch.path().join("a-killer"));
    for i in 0..3 {
        copy(honest.path(), batch.path().join(format!("honest-{i}")));
    }
    // Alone, an honest submission scores this.
    let alone_out = tempfile::tempdir().unwrap();
    let alone = run_in(
        batch.path(),
        &[
            "grade",
            batch.path().join("honest-0").to_str().unwrap(),
            "--rubric",
            code_rubric(),
            "--out",
            alone_out.path().to_str().unwrap(),
        ],
    );
    assert_eq!(alone.status.code(), Some(0), "{}", stderr(&alone));
    let total = String::from_utf8_lossy(&alone.stdout)
        .lines()
        .find(|l| l.starts_with("total"))
        .map(|l| l.split_whitespace().skip(1).collect::<Vec<_>>().join(" "))
        .unwrap();
    let out_dir = tempfile::tempdir().unwrap();
    let out = run_in(
        batch.path(),
        &[
            "grade",
            "--batch",
            batch.path().to_str().unwrap(),
            "--rubric",
            code_rubric(),
            "--out",
            out_dir.path().join("out").to_str().unwrap(),
            "--threads",
            "2",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let scores = scores(&out);
    for i in 0..3 {
        let name = format!("honest-{i}");
        let score = scores.iter().find(|(n, _)| *n == name).map(|(_, s)| s);
        // What it scores alone (`N / 100`) it scores beside the killer.
        assert_eq!(
            score.map(|s| s.split_whitespace().collect::<Vec<_>>().join(" ")),
            Some(total.clone()),
            "{name}: {scores:?}"
        );
    }
}

#[test]
fn the_grader_s_binary_is_not_found_in_proc_under_bubblewrap() {
    if !root("the_grader_s_binary_is_not_found_in_proc_under_bubblewrap") {
        return;
    }
    let sub = hostile(
        r#"
import os as _o, sys as _s
for _p in _o.listdir("/proc"):
    if _p.isdigit():
        try:
            with open("/proc/%s/cmdline" % _p, "rb") as _f:
                _c = _f.read().replace(b"\0", b" ").decode("utf-8", "replace")
        except Exception:
            continue
        if "rtoracle" in _c or "grade" in _c:
            _s.stderr.write("FOUND %s\n" % _c)
_s.stderr.write("scanned /proc\n")
"#,
    );
    let (out, json) = check_json(sub.path(), &[]);
    if json["sandbox"]["isolation"] != "bubblewrap" {
        eprintln!(
            "skipped: bubblewrap does not work here ({})",
            json["sandbox"]
        );
        return;
    }
    let tail = json["stderr_tail"].as_str().unwrap_or_default();
    assert!(tail.contains("scanned /proc"), "{tail}\n{}", stderr(&out));
    assert!(!tail.contains("FOUND"), "{tail}");
}

#[test]
fn with_no_sandbox_grade_refuses_and_check_runs_only_when_asked_unsandboxed() {
    if !root("with_no_sandbox_grade_refuses_and_check_runs_only_when_asked_unsandboxed") {
        return;
    }
    let sub = assemble_fixture("honest_reference").unwrap();
    open_up(sub.path());
    let out_dir = tempfile::tempdir().unwrap();
    let report = out_dir.path().join("report");
    let run = |args: &[&str]| {
        rtoracle()
            .current_dir(sub.path())
            .env("RTORACLE_SANDBOX", "none")
            .args(args)
            .output()
            .unwrap()
    };
    let grade = run(&[
        "grade",
        sub.path().to_str().unwrap(),
        "--out",
        report.to_str().unwrap(),
    ]);
    assert_bad_input(&grade, "untrusted code never runs as root");
    assert!(!report.exists(), "nothing graded, nothing written");
    let check = run(&["check", "--python-course", sub.path().to_str().unwrap()]);
    assert_bad_input(&check, "--unsandboxed");
    let check = run(&[
        "check",
        "--python-course",
        sub.path().to_str().unwrap(),
        "--unsandboxed",
    ]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    assert!(
        stderr(&check).contains("rtoracle: sandbox: UNSANDBOXED"),
        "{}",
        stderr(&check)
    );
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        stdout.contains("sandbox: unsandboxed by request"),
        "{stdout}"
    );
    // A mode that does not exist is bad input too.
    let bad = rtoracle()
        .env("RTORACLE_SANDBOX", "chroot")
        .args(["check", "--python-course", sub.path().to_str().unwrap()])
        .output()
        .unwrap();
    assert_bad_input(&bad, "RTORACLE_SANDBOX=\"chroot\"");
}

#[test]
fn an_interpreter_without_numpy_is_named_with_numpy_by_check_and_grade() {
    if !Path::new("/usr/bin/python3").is_file() {
        eprintln!("skipped: no /usr/bin/python3");
        return;
    }
    // A Python that really lacks numpy: the system one without its site-packages (-S).
    let bin = tempfile::tempdir().unwrap();
    open_up(bin.path());
    let fake = bin.path().join("python3-without-numpy");
    std::fs::write(&fake, "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n").unwrap();
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let lacks = std::process::Command::new(&fake)
        .args(["-c", "import numpy"])
        .output()
        .unwrap();
    assert!(!lacks.status.success(), "the fake Python has numpy");
    let sub = assemble_fixture("honest_reference").unwrap();
    open_up(sub.path());
    let fake = fake.to_str().unwrap();
    let check = run_in(
        sub.path(),
        &[
            "check",
            "--python-course",
            sub.path().to_str().unwrap(),
            "--python",
            fake,
        ],
    );
    assert_bad_input(&check, &format!("--python {fake}: lacks numpy"));
    assert!(
        stderr(&check).contains("apt-get install python3-numpy"),
        "{}",
        stderr(&check)
    );
    let out_dir = tempfile::tempdir().unwrap();
    let grade = run_in(
        sub.path(),
        &[
            "grade",
            sub.path().to_str().unwrap(),
            "--python",
            fake,
            "--out",
            out_dir.path().join("r").to_str().unwrap(),
        ],
    );
    assert_bad_input(&grade, &format!("--python {fake}: lacks numpy"));
    assert!(!out_dir.path().join("r").exists());
}

#[test]
fn only_python_modules_of_regular_files_are_copied_and_the_rest_is_named() {
    let sub = assemble_fixture("honest_reference").unwrap();
    open_up(sub.path());
    // A FIFO, a link to a root-only file and an oversized module: none is opened or copied.
    let fifo = std::ffi::CString::new(sub.path().join("fifo.py").to_str().unwrap()).unwrap();
    // SAFETY: mkfifo with a valid path.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o644) }, 0);
    std::os::unix::fs::symlink("/etc/shadow", sub.path().join("shadow.py")).unwrap();
    std::fs::write(sub.path().join("big.py"), vec![b'#'; 2 << 20]).unwrap();
    std::fs::write(sub.path().join("bad\u{1b}[31mname.py"), "x = 1\n").unwrap();
    let (out, json) = check_json(sub.path(), &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let skipped: Vec<String> = json["sandbox"]["skipped_files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let has = |needle: &str| skipped.iter().any(|s| s.contains(needle));
    assert!(has("fifo.py (not a regular file)"), "{skipped:?}");
    assert!(has("shadow.py (a symbolic link)"), "{skipped:?}");
    assert!(has("big.py (2097152 bytes"), "{skipped:?}");
    // The escape reaches nobody's terminal as an escape.
    assert!(skipped.iter().all(|s| !s.contains('\u{1b}')), "{skipped:?}");
    assert_eq!(skipped.len(), 4, "{skipped:?}");
}

#[test]
fn sigterm_mid_check_leaves_no_process_and_no_folder() {
    if !root("sigterm_mid_check_leaves_no_process_and_no_folder") {
        return;
    }
    let marker = format!("rtoracle-test-sigterm-{}", std::process::id());
    // Its import starts a setsid daemon and then hangs.
    let sub = hostile(&format!(
        r#"
import os as _o, sys as _s, time as _t
if _o.fork() == 0:
    _o.setsid()
    _o.execv(_s.executable, [_s.executable, "-c", "import time; time.sleep(600)", {marker:?}])
_t.sleep(600)
"#
    ));
    let tmp = tempfile::tempdir().unwrap();
    open_up(tmp.path());
    let mut child = rtoracle()
        .current_dir(sub.path())
        .env("TMPDIR", tmp.path())
        .args(["check", "--python-course", sub.path().to_str().unwrap()])
        .args(["--hello-timeout-ms", "60000"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    while processes_with(&marker).is_empty() && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert!(
        !processes_with(&marker).is_empty(),
        "the daemon did not start"
    );
    let folders = || std::fs::read_dir(tmp.path()).unwrap().count();
    assert!(folders() > 0, "no sandbox folder in TMPDIR");
    // SAFETY: signalling our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143));
    let mut left = processes_with(&marker);
    for _ in 0..100 {
        if left.is_empty() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
        left = processes_with(&marker);
    }
    assert!(left.is_empty(), "still running: {left:?}");
    assert_eq!(folders(), 0, "a folder was left in TMPDIR");
}

/// `check --python-course DIR --json` with `RTORACLE_SANDBOX=mode`.
fn check_json_in(mode: &str, dir: &Path, extra: &[&str]) -> (Output, serde_json::Value) {
    let out = rtoracle()
        .current_dir(dir)
        .env("RTORACLE_SANDBOX", mode)
        .args(["check", "--python-course", dir.to_str().unwrap(), "--json"])
        .args(extra)
        .output()
        .unwrap();
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
    // The intersections' report, where the sandbox and the stderr tail are (check --json v2).
    (out, json["intersections"].clone())
}

/// `grade DIR --out OUT` with `RTORACLE_SANDBOX=mode`; the report.json as text.
fn grade_in(mode: &str, dir: &Path) -> (Output, String) {
    grade_as(mode, dir, false)
}

/// Asserts that grading in `mode` ended with exit 0 and a report that says `why` (the
/// sandbox's message to the student), showing the start of the report otherwise.
fn assert_stopped(mode: &str, out: &Output, report: &str, why: &str) {
    assert_eq!(out.status.code(), Some(0), "{mode}: {}", stderr(out));
    assert!(
        report.contains(why),
        "{mode}: no {why:?} in {}",
        report.chars().take(3000).collect::<String>()
    );
}

/// [`grade_in`], by user `nobody` when `as_nobody` (a grader that is not root).
fn grade_as(mode: &str, dir: &Path, as_nobody: bool) -> (Output, String) {
    let out_dir = tempfile::tempdir().unwrap();
    let report = out_dir.path().join("r");
    let mut cmd = rtoracle();
    if as_nobody {
        use std::os::unix::fs::PermissionsExt;
        use std::os::unix::process::CommandExt;
        std::fs::set_permissions(out_dir.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
        cmd.uid(65534).gid(65534).env("HOME", "/nonexistent");
    }
    let out = cmd
        .current_dir(dir)
        .env("RTORACLE_SANDBOX", mode)
        .args([
            "grade",
            dir.to_str().unwrap(),
            "--out",
            report.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = std::fs::read_to_string(report.join("report.json")).unwrap_or_default();
    (out, text)
}

/// The lines of the candidate's stderr tail that start with `prefix`.
fn tail_lines(json: &serde_json::Value, prefix: &str) -> Vec<String> {
    json["stderr_tail"]
        .as_str()
        .unwrap_or_default()
        .lines()
        .filter(|l| l.starts_with(prefix))
        .map(str::to_string)
        .collect()
}

/// A fork bomb is held to the policy's 64 processes under bubblewrap even when the grader is
/// not root: RLIMIT_NPROC counts every process of a user, so it was set only for a uid of the
/// grader's own; bubblewrap's first process now gets it inside its user namespace, where it
/// counts the sandbox's processes alone (1527 forks in 2 s got through before).
#[test]
fn a_fork_bomb_is_held_to_the_process_limit_under_bubblewrap_as_any_user() {
    if !root("a_fork_bomb_is_held_to_the_process_limit_under_bubblewrap_as_any_user") {
        return;
    }
    let sub = hostile(
        r#"
import os as _o, sys as _s, time as _t
_n, _err = 0, None
while _n < 400:
    try:
        if _o.fork() == 0:
            _t.sleep(3)
            _o._exit(0)
        _n += 1
    except OSError as _e:
        _err = _e
        break
_s.stderr.write("FORKED %d %r\n" % (_n, _err))
"#,
    );
    // As root (a uid of its own) and as an unprivileged user (nobody) running the grader.
    for as_nobody in [false, true] {
        let mut cmd = rtoracle();
        if as_nobody {
            use std::os::unix::process::CommandExt;
            cmd.uid(65534).gid(65534).env("HOME", "/nonexistent");
        }
        let out = cmd
            .current_dir(sub.path())
            .env("RTORACLE_SANDBOX", "bubblewrap")
            .args([
                "check",
                "--python-course",
                sub.path().to_str().unwrap(),
                "--json",
            ])
            .output()
            .unwrap();
        let json: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
        if json["sandbox"]["isolation"] != "bubblewrap" {
            eprintln!("skipped: bubblewrap does not work here: {}", stderr(&out));
            return;
        }
        let forked = tail_lines(&json, "FORKED");
        let n: usize = forked
            .first()
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("nobody={as_nobody}: {json}"));
        assert!(n < 64, "nobody={as_nobody}: {forked:?}");
        assert!(
            forked[0].contains("Resource temporarily unavailable"),
            "{forked:?}"
        );
    }
}

/// Bytes the code keeps in files it unlinked but holds open, or in memfds, are files like any
/// other: the watchdog counts them (600 MiB of them went unseen by a 256 MiB limit).
#[test]
fn unlinked_files_and_memfds_count_toward_the_disk_limit() {
    if !root("unlinked_files_and_memfds_count_toward_the_disk_limit") {
        return;
    }
    let sub = hostile(
        r#"
import os as _o, sys as _s, time as _t
_keep = []
_chunk = b"x" * (1 << 20)
for _i in range(3):
    _p = "/tmp/unlinked-%d" % _i
    _f = open(_p, "wb")
    for _ in range(15):
        _f.write(_chunk)
    _f.flush()
    _o.unlink(_p)
    _keep.append(_f)
    _fd = _o.memfd_create("m%d" % _i)
    for _ in range(15):
        _o.write(_fd, _chunk)
    _keep.append(_fd)
_s.stderr.write("HELD 90 MiB\n")
_t.sleep(3)
"#,
    );
    for mode in ["auto", "uid"] {
        let (out, report) = grade_in(mode, sub.path());
        assert_stopped(
            mode,
            &out,
            &report,
            "the sandbox stopped it: it wrote more than 64 MiB",
        );
    }
}

/// The memory of all the code's processes together is bounded by the policy's `memory_bytes`
/// (RLIMIT_AS bounds each process alone: 64 processes could hold 64 GiB), in every mode: a uid
/// of its own, bubblewrap run by a user that is not root (its PID namespace), and no sandbox
/// at all for such a user (its sessions).
#[test]
fn the_memory_of_all_its_processes_together_is_bounded() {
    if !root("the_memory_of_all_its_processes_together_is_bounded") {
        return;
    }
    let sub = hostile(
        r#"
import os as _o, select as _sel, sys as _s, time as _t
# Each child says when its 400 MiB are written; until all have, every vector waits (up to 1.5 s
# of its 2 s): a loaded machine's slow page faults must not end the session first.
_r, _w = _o.pipe()
for _i in range(4):
    if _o.fork() == 0:
        _b = b"\x01" * (400 << 20)
        _o.write(_w, b"x")
        _t.sleep(60)
        _o._exit(0)
_o.close(_w)
_s.stderr.write("FORKED\n")
_filled = [0]
_intersect = Sphere.intersect
def _waiting(self, r, i):
    if _filled[0] < 4 and _sel.select([_r], [], [], 1.5)[0]:
        _filled[0] += len(_o.read(_r, 4))
    return _intersect(self, r, i)
Sphere.intersect = _waiting
"#,
    );
    for (mode, as_nobody) in [
        ("auto", false),
        ("uid", false),
        ("bubblewrap", true),
        ("none", true),
    ] {
        let (out, report) = grade_as(mode, sub.path(), as_nobody);
        let mode = format!("{mode} nobody={as_nobody}");
        assert_stopped(
            &mode,
            &out,
            &report,
            "the sandbox stopped it: its processes held more than 1 GiB",
        );
    }
}

/// System V shared memory, message queues and semaphores outlive the processes that made them:
/// in the fallback (no IPC namespace of bubblewrap) 192 MiB of segments stayed after the grader
/// exited. Now the fallback makes an IPC namespace where it can, and sweeps the uid's objects.
#[test]
fn system_v_ipc_objects_do_not_outlive_the_sandbox() {
    if !root("system_v_ipc_objects_do_not_outlive_the_sandbox") {
        return;
    }
    let sub = hostile(
        r#"
import ctypes as _c, sys as _s
_libc = _c.CDLL(None, use_errno=True)
_ids = [_libc.shmget(0, 8 << 20, 0o1666) for _ in range(3)]
_q = _libc.msgget(0, 0o1666)
_sem = _libc.semget(0, 1, 0o1666)
_s.stderr.write("IPC %r %r %r\n" % (_ids, _q, _sem))
"#,
    );
    for mode in ["auto", "uid"] {
        let (out, json) = check_json_in(mode, sub.path(), &[]);
        assert_eq!(out.status.code(), Some(0), "{mode}: {}", stderr(&out));
        let made = tail_lines(&json, "IPC");
        assert!(
            !made.is_empty() && !made[0].contains("-1"),
            "{mode}: {made:?}"
        );
        let uid = json["sandbox"]["uid"].as_u64().unwrap();
        for table in ["shm", "msg", "sem"] {
            let text = std::fs::read_to_string(format!("/proc/sysvipc/{table}")).unwrap();
            let left: Vec<&str> = text
                .lines()
                .skip(1)
                .filter(|l| l.split_whitespace().any(|w| w == uid.to_string()))
                .collect();
            assert!(left.is_empty(), "{mode}: {table} left {left:?}");
        }
    }
}

/// In the fallback the code found the grader's binary in `/proc/*/cmdline` and ran it as an
/// oracle (`rtoracle explain ...`). Where a mount namespace can be made, its `/proc` shows only
/// its own processes and the grader's binary is an empty file there.
#[test]
fn in_the_fallback_the_grader_s_processes_and_binary_are_hidden() {
    if !root("in_the_fallback_the_grader_s_processes_and_binary_are_hidden") {
        return;
    }
    let exe = env!("CARGO_BIN_EXE_rtoracle");
    let sub = hostile(&format!(
        r#"
import os as _o, sys as _s, subprocess as _sp
for _p in _o.listdir("/proc"):
    if _p.isdigit():
        try:
            _c = open("/proc/%s/cmdline" % _p, "rb").read()
        except Exception:
            continue
        if b"rtoracle" in _c:
            _s.stderr.write("FOUND %r\n" % _c)
try:
    _r = _sp.run([{exe:?}, "--version"], capture_output=True, timeout=5)
    _s.stderr.write("RAN rc=%s %r\n" % (_r.returncode, _r.stdout[:80]))
except Exception as _e:
    _s.stderr.write("NOT RUN %s\n" % type(_e).__name__)
_s.stderr.write("SCANNED\n")
"#
    ));
    let (out, json) = check_json_in("uid", sub.path(), &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let namespaces = json["sandbox"]["namespaces"].to_string();
    if !namespaces.contains("mount") {
        eprintln!("skipped: no mount namespace here ({namespaces})");
        return;
    }
    let tail = json["stderr_tail"].as_str().unwrap_or_default();
    assert!(tail.contains("SCANNED"), "{tail}");
    assert!(!tail.contains("FOUND"), "{tail}");
    assert!(!tail.contains("RAN rc=0"), "{tail}");
}

/// Files deeper than a path can name were not seen by the watchdog (360 MiB at depth 2100 of a
/// 256 MiB limit): a tree nested that deep is stopped, and removed, in both modes.
#[test]
fn a_tree_nested_past_what_a_path_can_name_is_stopped_and_removed() {
    if !root("a_tree_nested_past_what_a_path_can_name_is_stopped_and_removed") {
        return;
    }
    let marker = format!("rtoracle-test-deep-{}", std::process::id());
    let sub = hostile(&format!(
        r#"
import os as _o, sys as _s, time as _t
for _root in ("/tmp", "."):
    _d = _o.open(_root, _o.O_RDONLY)
    _o.mkdir({marker:?}, dir_fd=_d)
    _nd = _o.open({marker:?}, _o.O_RDONLY, dir_fd=_d)
    _o.close(_d)
    _d = _nd
    for _i in range(2100):
        _o.mkdir("a", dir_fd=_d)
        _nd = _o.open("a", _o.O_RDONLY, dir_fd=_d)
        _o.close(_d)
        _d = _nd
    _f = _o.open("data", _o.O_WRONLY | _o.O_CREAT, 0o644, dir_fd=_d)
    _o.write(_f, b"x" * (1 << 20))
    _o.close(_f)
_s.stderr.write("NESTED\n")
_t.sleep(3)
"#
    ));
    for mode in ["auto", "uid"] {
        let (out, json) = check_json_in(mode, sub.path(), &[]);
        assert_eq!(out.status.code(), Some(1), "{mode}: {}", stderr(&out));
        let text = json.to_string();
        assert!(
            text.contains("the sandbox stopped it: it nested folders more than 100 deep"),
            "{mode}: {}",
            &text[..text.len().min(2000)]
        );
        let left: Vec<_> = std::fs::read_dir("/tmp")
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().contains(&marker))
            .collect();
        assert!(left.is_empty(), "{mode}: left {left:?}");
    }
}

/// In the fallback the code could write wherever the host lets any user write: a classmate's
/// submission in a world-writable batch folder (found by walking the file system). Where a mount
/// namespace can be made, the code has a view of its own: the classmate's folder is not in it,
/// and the only writable places are its own folder and its `/tmp` (a tmpfs of its own; the host's
/// `/var/tmp` is not shown).
#[test]
fn in_the_fallback_the_host_is_read_only_but_the_code_s_own_folder() {
    if !root("in_the_fallback_the_host_is_read_only_but_the_code_s_own_folder") {
        return;
    }
    use std::os::unix::fs::PermissionsExt;
    let marker = format!("rtoracle-test-ro-{}", std::process::id());
    // Outside the shared folders, as a batch folder would be (a checkout under /tmp puts the
    // target folder inside one).
    let shared = |p: &Path| {
        rtoracle::sandbox::bounds::scratch::SHARED_ROOTS
            .iter()
            .any(|root| p.starts_with(root))
    };
    let place = [env!("CARGO_TARGET_TMPDIR"), "/var/lib", "/opt", "/srv"]
        .into_iter()
        .map(Path::new)
        .find(|p| p.is_dir() && !shared(&p.canonicalize().unwrap_or(p.to_path_buf())))
        .expect("a folder outside the shared ones");
    let classmate = tempfile::tempdir_in(place).unwrap();
    std::fs::set_permissions(classmate.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
    let theirs = classmate.path().join("RT_object.py");
    std::fs::write(&theirs, "# a classmate's work\n").unwrap();
    std::fs::set_permissions(&theirs, std::fs::Permissions::from_mode(0o666)).unwrap();
    let sub = hostile(&format!(
        r#"
import sys as _s
for _p in [{theirs:?}, {planted:?}, "/tmp/{marker}", "/var/tmp/{marker}", "scratch-{marker}"]:
    try:
        with open(_p, "w") as _f:
            _f.write("raise SystemExit('sabotaged')\n")
        _s.stderr.write("WROTE %s\n" % _p)
    except OSError as _e:
        _s.stderr.write("REFUSED %s %s\n" % (_p, type(_e).__name__))
"#,
        theirs = theirs.display().to_string(),
        planted = classmate.path().join("planted.py").display().to_string(),
    ));
    let (out, json) = check_json_in("uid", sub.path(), &[]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let namespaces = json["sandbox"]["namespaces"].to_string();
    if !namespaces.contains("mount") {
        eprintln!("skipped: no mount namespace here ({namespaces})");
        return;
    }
    let tail = json["stderr_tail"].as_str().unwrap_or_default();
    assert!(
        tail.contains(&format!("REFUSED {}", theirs.display())),
        "{tail}"
    );
    // Its folder and its /tmp are writable, the host's /var/tmp is not there, and nothing it
    // wrote reaches the host.
    for place in ["/tmp/", "scratch-"] {
        assert!(tail.contains(&format!("WROTE {place}")), "{tail}");
    }
    assert!(tail.contains("REFUSED /var/tmp/"), "{tail}");
    assert!(!Path::new(&format!("/tmp/{marker}")).exists());
    assert!(!Path::new(&format!("/var/tmp/{marker}")).exists());
    assert_eq!(
        std::fs::read_to_string(&theirs).unwrap(),
        "# a classmate's work\n"
    );
    assert!(!classmate.path().join("planted.py").exists());
}

/// Held by each test that measures the host's shared memory or makes much of it, so that no two
/// of them run at once: one's 1 GiB segment (or 257 MiB tmpfs) would be the other's growth.
static SHMEM_MEASURED: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The host's shared memory (tmpfs files, System V segments, memfds) in KiB: `Shmem` of
/// `/proc/meminfo`.
fn host_shmem_kib() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .unwrap()
        .lines()
        .find_map(|l| l.strip_prefix("Shmem:"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap()
}

/// Samples [`host_shmem_kib`] every 20 ms while `run` runs; returns `run`'s result and the
/// highest sample.
fn with_peak_shmem<T>(run: impl FnOnce() -> T) -> (T, u64) {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let sampler = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let mut peak = host_shmem_kib();
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                peak = peak.max(host_shmem_kib());
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            peak
        })
    };
    let out = run();
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    (out, sampler.join().unwrap())
}

/// The modes a root grader can be in here: bubblewrap (`auto`, where it works), the fallback
/// with its own namespaces (`uid`) and without any (`uid-bare`, as in a container).
const ROOT_MODES: [&str; 3] = ["auto", "uid", "uid-bare"];

/// Other engineers' tests share this machine's memory: what they add or free meanwhile stays
/// under this (KiB).
const SHMEM_NOISE_KIB: u64 = 48 << 10;

/// bubblewrap's root was its own tmpfs, writable by the code: files written there lived in the
/// host's memory and were counted nowhere (3 GiB in 11 s, stopped only by the time budget). The
/// root is read-only now, `/tmp` a tmpfs of the policy's size, `/dev` read-only; in the fallback
/// its view is the same, and without namespaces the host's `/dev/shm` is measured by owner. In
/// every mode a 1 GiB fill is stopped at the 64 MiB limit with the reason in the report, the
/// host's shared memory never grows by anything near the fill, and nothing is left.
#[test]
fn a_1_gib_tmpfs_fill_is_stopped_at_the_limit_in_every_mode_and_leaves_nothing() {
    let _measuring = SHMEM_MEASURED.lock().unwrap_or_else(|e| e.into_inner());
    if !root("a_1_gib_tmpfs_fill_is_stopped_at_the_limit_in_every_mode_and_leaves_nothing") {
        return;
    }
    let marker = format!("rtoracle-test-fill-{}", std::process::id());
    let sub = hostile(&format!(
        r#"
import os as _o, sys as _s
_chunk = b"\x01" * (8 << 20)
_done = 0
for _d in ("/", "/dev/shm", "/tmp", "."):
    _n = 0
    while _done < (1 << 30):
        try:
            with open(_o.path.join(_d, "{marker}-%d" % _n), "wb") as _f:
                _f.write(_chunk)
        except OSError as _e:
            _s.stderr.write("REFUSED %s %s\n" % (_d, _e.strerror))
            break
        _n += 1
        _done += len(_chunk)
_s.stderr.write("FILLED %d MiB\n" % (_done >> 20))
"#
    ));
    for mode in ROOT_MODES {
        let before = host_shmem_kib();
        let ((out, report), peak) = with_peak_shmem(|| grade_in(mode, sub.path()));
        assert_stopped(
            mode,
            &out,
            &report,
            "the sandbox stopped it: it wrote more than 64 MiB",
        );
        assert!(
            !report.contains("FILLED 1024 MiB"),
            "{mode}: the whole GiB was written"
        );
        // Bounded while it ran (the limit, one tick of writing, the noise), gone after.
        assert!(
            peak < before + (384 << 10),
            "{mode}: the host's shared memory grew from {before} to {peak} KiB"
        );
        let after = host_shmem_kib();
        assert!(
            after < before + SHMEM_NOISE_KIB,
            "{mode}: {before} KiB of shared memory before, {after} KiB after"
        );
        for dir in ["/tmp", "/dev/shm", "/"] {
            let left: Vec<_> = std::fs::read_dir(dir)
                .unwrap()
                .flatten()
                .filter(|e| e.file_name().to_string_lossy().contains(&marker))
                .collect();
            assert!(left.is_empty(), "{mode}: left in {dir}: {left:?}");
        }
    }
}

/// System V shared memory in bubblewrap's IPC namespace (and the fallback's) was unlimited and
/// uncounted: twelve 256 MiB segments held 3 GiB for the whole time budget. The namespace's
/// `shmmax` and `shmall` are the policy's memory now, and the watchdog counts its segments
/// with the processes' memory: 1 GiB of segments, filled by children that then detach and
/// exit, is stopped at the 1 GiB limit in every mode, and nothing is left.
#[test]
fn a_gib_of_system_v_shared_memory_is_stopped_at_the_limit_in_every_mode() {
    let _measuring = SHMEM_MEASURED.lock().unwrap_or_else(|e| e.into_inner());
    if !root("a_gib_of_system_v_shared_memory_is_stopped_at_the_limit_in_every_mode") {
        return;
    }
    let sub = hostile(
        r#"
import ctypes as _c, os as _o, sys as _s, time as _t
_libc = _c.CDLL(None, use_errno=True)
_libc.shmat.restype = _c.c_void_p
_libc.shmat.argtypes = [_c.c_int, _c.c_void_p, _c.c_int]
_libc.shmdt.argtypes = [_c.c_void_p]
_held = 0
for _i in range(4):
    _id = _libc.shmget(0, 256 << 20, 0o1600)
    if _id < 0:
        _s.stderr.write("SHMGET refused %d\n" % _c.get_errno())
        break
    _pid = _o.fork()
    if _pid == 0:
        _p = _libc.shmat(_id, None, 0)
        if _p is not None and _p != _c.c_void_p(-1).value:
            _c.memset(_p, 1, 256 << 20)
            _libc.shmdt(_p)
        _o._exit(0)
    _o.waitpid(_pid, 0)
    _held += 256
    _s.stderr.write("HELD %d MiB\n" % _held)
_t.sleep(6)
_s.stderr.write("KEPT %d MiB\n" % _held)
"#,
    );
    for mode in ROOT_MODES {
        let before = host_shmem_kib();
        let (out, report) = grade_in(mode, sub.path());
        assert_stopped(
            mode,
            &out,
            &report,
            "the sandbox stopped it: its processes held more than 1 GiB of memory together",
        );
        // A segment left behind would hold the 1 GiB it was stopped at: a quarter of that is
        // room for the other tests' tmpfs files and memfds (a full run of the suite on 2 cores
        // added 78 MiB here while this test ran).
        // The kernel frees a dead IPC namespace's segments from a work queue, not at once.
        let freed_by = std::time::Instant::now() + std::time::Duration::from_secs(20);
        let mut after = host_shmem_kib();
        while after >= before + (256 << 10) && std::time::Instant::now() < freed_by {
            std::thread::sleep(std::time::Duration::from_millis(100));
            after = host_shmem_kib();
        }
        assert!(
            after < before + (256 << 10),
            "{mode}: {before} KiB of shared memory before, {after} KiB after"
        );
        let json: serde_json::Value = serde_json::from_str(&report).unwrap();
        let uid = json["code"]["sandbox"]["uid"].as_u64().unwrap().to_string();
        let table = std::fs::read_to_string("/proc/sysvipc/shm").unwrap();
        let left: Vec<&str> = table
            .lines()
            .skip(1)
            .filter(|l| l.split_whitespace().nth(7) == Some(uid.as_str()))
            .collect();
        assert!(left.is_empty(), "{mode}: segments left {left:?}");
    }
}

/// A submission with no geometry that answers every vector by asking an rtoracle binary it can
/// find (`explain` prints the exact answer): near its interpreter, in a build tree beside the
/// interpreter's environment, or at the `hints` it was told about. It writes `SEEN path` for
/// each non-empty candidate it can see and `RAN path rc` for each it tried to run; without a
/// working one, every vector raises.
fn explain_asking(hints: &[&Path]) -> tempfile::TempDir {
    let dir = assemble_fixture("honest_reference").unwrap();
    let hints: Vec<String> = hints.iter().map(|h| h.display().to_string()).collect();
    let code = format!(
        r#"
import json, os, re, subprocess, sys
import RT_utility as rtu

def _candidates():
    roots = {hints:?} + [os.path.dirname(sys.executable), sys.prefix,
             os.path.dirname(sys.prefix)]
    seen = []
    for root in roots:
        for dirpath, dirs, files in os.walk(root):
            if dirpath.count(os.sep) - root.count(os.sep) > 4:
                dirs[:] = []
            for f in files:
                p = os.path.join(dirpath, f)
                if f.startswith("rtoracle") and p not in seen:
                    seen.append(p)
    return seen

def _find():
    for p in _candidates():
        try:
            if os.path.getsize(p) == 0:
                continue
        except OSError:
            continue
        sys.stderr.write("SEEN %s\n" % p)
        try:
            r = subprocess.run([p, "--version"], capture_output=True, timeout=10)
        except Exception as e:
            sys.stderr.write("RAN %s %s\n" % (p, type(e).__name__))
            continue
        sys.stderr.write("RAN %s rc=%d %r\n" % (p, r.returncode, r.stderr[:120]))
        if r.returncode == 0 and b"rtoracle" in r.stdout:
            return p
    return None

_ORACLE = _find()
sys.stderr.write("ORACLE %s\n" % _ORACLE)
_ANSWER = re.compile(r"Exact answer: hit at t = (\S+), point \((.*?)\), normal \((.*?)\), front_face (\w+)")

def _v(e):
    return [e.x(), e.y(), e.z()]

def _ask(shape, ray, interval):
    if _ORACLE is None:
        raise NotImplementedError("no geometry here")
    case = {{"shape": shape, "ray": {{"origin": _v(ray.getOrigin()), "direction": _v(ray.getDirection())}},
            "interval": [interval.min_val, interval.max_val]}}
    out = subprocess.run([_ORACLE, "explain", json.dumps(case)], capture_output=True, text=True).stdout
    m = _ANSWER.search(out)
    if m is None:
        return None
    t = float(m.group(1))
    p = rtu.Vec3(*[float(x) for x in m.group(2).split(",")])
    n = rtu.Vec3(*[float(x) for x in m.group(3).split(",")])
    h = rtu.Hitinfo(p, n, t)
    h.front_face = m.group(4) == "true"
    return h

class Sphere:
    def __init__(self, vCenter, fRadius, mMat=None):
        self.center, self.radius = vCenter, fRadius
    def intersect(self, rRay, cInterval):
        return _ask({{"type": "sphere", "center": _v(self.center), "radius": self.radius}}, rRay, cInterval)

class Quad:
    def __init__(self, vQ, vU, vV, mMat=None):
        self.q, self.u, self.v = vQ, vU, vV
    def intersect(self, rRay, cInterval):
        return _ask({{"type": "quad", "q": _v(self.q), "u": _v(self.u), "v": _v(self.v)}}, rRay, cInterval)
"#
    );
    std::fs::write(dir.path().join("RT_object.py"), code).unwrap();
    open_up(dir.path());
    dir
}

/// `src` at `to`, a hard link where the file system allows it (one copy for many names).
fn link_or_copy(src: &Path, to: &Path) {
    std::fs::create_dir_all(to.parent().unwrap()).unwrap();
    if std::fs::hard_link(src, to).is_err() {
        std::fs::copy(src, to).unwrap();
    }
}

/// The points a report gives its code groups (`sphere`, `quad`), and their most.
fn code_points(report: &str) -> (f64, f64) {
    let json: serde_json::Value = serde_json::from_str(report).unwrap();
    let mut points = (0.0, 0.0);
    for c in json["checks"].as_array().unwrap() {
        if ["sphere", "quad"].contains(&c["group"].as_str().unwrap_or_default()) {
            points.0 += c["score"].as_f64().unwrap();
            points.1 += c["max_score"].as_f64().unwrap();
        }
    }
    points
}

/// A copy of rtoracle was reachable from inside: under bubblewrap a `--python` in a virtual
/// environment exposed the whole environment, whose `bin/` holds the student wheel's `rtoracle`
/// next to `python3`, and in the fallback a build tree's `deps/rtoracle-<hash>` is
/// world-executable; asking it `explain` for every vector scored 100/100. Now only the
/// interpreter's library tree is shown, every rtoracle binary in the view is covered (by inode
/// or content: here a copy inside the environment's `site-packages` and a hard link of the
/// grader itself), and an rtoracle binary refuses to run as a sandbox's uid (the fallback
/// without namespaces shows the host): the submission scores at most 5% of the code points.
#[test]
fn an_explain_asking_submission_finds_no_working_rtoracle_near_its_interpreter() {
    if !root("an_explain_asking_submission_finds_no_working_rtoracle_near_its_interpreter") {
        return;
    }
    // A course's environment: a venv whose python3 is the system's (with its numpy and PIL),
    // the student wheel's rtoracle beside it, a copy inside its site-packages, and a build tree
    // beside the venv (its release binary and the hard link cargo keeps in deps/).
    let course = tempfile::tempdir().unwrap();
    open_up(course.path());
    let venv = course.path().join("venv");
    let site = venv.join("lib/python3/site-packages/tool");
    std::fs::create_dir_all(venv.join("bin")).unwrap();
    std::fs::create_dir_all(&site).unwrap();
    std::os::unix::fs::symlink("/usr/bin/python3", venv.join("bin/python3")).unwrap();
    std::fs::write(
        venv.join("pyvenv.cfg"),
        "home = /usr/bin\ninclude-system-site-packages = true\n",
    )
    .unwrap();
    let wheel = venv.join("bin/rtoracle");
    std::fs::copy(env!("CARGO_BIN_EXE_rtoracle"), &wheel).unwrap();
    link_or_copy(&wheel, &site.join("rtoracle-helper"));
    let build = course.path().join("target/release");
    link_or_copy(&wheel, &build.join("rtoracle"));
    link_or_copy(
        Path::new(env!("CARGO_BIN_EXE_rtoracle")),
        &build.join("deps/rtoracle-0123456789abcdef"),
    );
    for d in walk_dirs(course.path()) {
        open_up(&d);
    }
    let vectors = course.path().join("v.jsonl");
    let made = run_in(
        course.path(),
        &[
            "vectors",
            "--count",
            "120",
            "--shapes",
            "sphere,quad",
            "--seed",
            "7",
            "-o",
            vectors.to_str().unwrap(),
        ],
    );
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let sub = explain_asking(&[course.path()]);
    let python = venv.join("bin/python3");
    for mode in ROOT_MODES {
        let out_dir = tempfile::tempdir().unwrap();
        let out = rtoracle()
            .current_dir(sub.path())
            .env("RTORACLE_SANDBOX", mode)
            .args(["grade", sub.path().to_str().unwrap(), "--out"])
            .arg(out_dir.path().join("r"))
            .arg("--python")
            .arg(&python)
            .arg("--vectors")
            .arg(&vectors)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{mode}: {}", stderr(&out));
        let report = std::fs::read_to_string(out_dir.path().join("r/report.json")).unwrap();
        let json: serde_json::Value = serde_json::from_str(&report).unwrap();
        let tail = json["code"]["stderr_tail"].as_str().unwrap_or_default();
        assert!(tail.contains("ORACLE None"), "{mode}: {tail}");
        let (points, most) = code_points(&report);
        assert!(
            most > 0.0 && points <= 0.05 * most,
            "{mode}: {points} of {most}"
        );
        let isolation = json["code"]["sandbox"]["isolation"]
            .as_str()
            .unwrap_or_default();
        let namespaces = json["code"]["sandbox"]["namespaces"].to_string();
        if isolation == "bubblewrap" || namespaces.contains("mount") {
            // Hidden: nothing of the build tree or the venv's bin/ is there, and the copy in
            // the library tree is an empty file.
            assert!(!tail.contains("SEEN"), "{mode}: {tail}");
        } else {
            // Shown (nothing can hide them without namespaces), and each refuses to run.
            assert!(
                tail.contains(&format!("SEEN {}", wheel.display())),
                "{mode}: {tail}"
            );
            assert!(
                tail.contains("does not run inside its own sandbox"),
                "{mode}: {tail}"
            );
        }
    }
}

/// Every folder under `root`, itself included.
fn walk_dirs(root: &Path) -> Vec<PathBuf> {
    let mut out = vec![root.to_path_buf()];
    let mut i = 0;
    while i < out.len() {
        if let Ok(entries) = std::fs::read_dir(&out[i]) {
            for e in entries.flatten() {
                if e.file_type().map(|t| t.is_dir()).unwrap_or(false) {
                    out.push(e.path());
                }
            }
        }
        i += 1;
    }
    out
}

/// In the fallback the code runs on the host as a uid of its own, and a batch folder unpacked
/// under the default umask is readable by all: a broken submission walked `/tmp`, ran a
/// classmate's `RT_object.py` and scored 100/100 (40 under bubblewrap). The fallback's view
/// does not show the batch, and the batch folder is made unreadable by others while it is
/// graded (and put back): in both fallbacks the reader scores in the batch what it scores
/// alone.
#[test]
fn a_classmate_reading_submission_in_the_fallback_scores_what_it_scores_alone() {
    if !root("a_classmate_reading_submission_in_the_fallback_scores_what_it_scores_alone") {
        return;
    }
    let marker = format!("classmate-marker-{}", std::process::id());
    // Broken on its own (no geometry); with a classmate's classes it would pass.
    let reader = hostile(&format!(
        r#"
import os as _o, sys as _s
class Sphere:
    def __init__(self, *a):
        pass
    def intersect(self, r, i):
        raise NotImplementedError
class Quad(Sphere):
    pass
_mine = _o.path.dirname(_o.path.abspath(__file__))
for _root, _dirs, _files in _o.walk("/tmp"):
    if _root.count("/") > 4:
        _dirs[:] = []
    if "RT_object.py" in _files and _root != _mine:
        _p = _o.path.join(_root, "RT_object.py")
        try:
            _text = open(_p).read()
        except OSError:
            continue
        if {m1:?} + {m2:?} in _text:
            _s.stderr.write("READ %s\n" % _p)
            exec(compile(_text, _p, "exec"), globals())
            break
"#,
        m1 = &marker[..9],
        m2 = &marker[9..],
    ));
    let honest = assemble_fixture("honest_reference").unwrap();
    let mut text = std::fs::read_to_string(honest.path().join("RT_object.py")).unwrap();
    text.push_str(&format!("\n# {marker}\n"));
    let score_of = |out: &Output, name: &str| {
        scores(out)
            .into_iter()
            .find(|(n, _)| n == name)
            .map(|(_, s)| s.split_whitespace().collect::<Vec<_>>().join(" "))
    };
    for mode in ["uid", "uid-bare"] {
        // Alone: no classmate's file exists yet.
        let alone_batch = tempfile::tempdir().unwrap();
        open_up(alone_batch.path());
        copy_folder(reader.path(), &alone_batch.path().join("a-reader"));
        let out_dir = tempfile::tempdir().unwrap();
        let alone = rtoracle()
            .env("RTORACLE_SANDBOX", mode)
            .args(["grade", "--batch"])
            .arg(alone_batch.path())
            .args(["--rubric", code_rubric()])
            .arg("--out")
            .arg(out_dir.path().join("alone"))
            .output()
            .unwrap();
        assert_eq!(alone.status.code(), Some(0), "{mode}: {}", stderr(&alone));
        let alone_score = score_of(&alone, "a-reader").unwrap();
        // Beside a classmate, in a folder everyone can read.
        let batch = tempfile::tempdir().unwrap();
        open_up(batch.path());
        copy_folder(reader.path(), &batch.path().join("a-reader"));
        copy_folder(honest.path(), &batch.path().join("b-honest"));
        std::fs::write(batch.path().join("b-honest/RT_object.py"), &text).unwrap();
        for d in walk_dirs(batch.path()) {
            open_up(&d);
        }
        let out = rtoracle()
            .env("RTORACLE_SANDBOX", mode)
            .args(["grade", "--batch"])
            .arg(batch.path())
            .args(["--rubric", code_rubric()])
            .arg("--out")
            .arg(out_dir.path().join("batch"))
            .args(["--threads", "1"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0), "{mode}: {}", stderr(&out));
        assert_eq!(
            score_of(&out, "a-reader"),
            Some(alone_score.clone()),
            "{mode}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert_ne!(score_of(&out, "b-honest"), Some(alone_score), "{mode}");
        let report =
            std::fs::read_to_string(out_dir.path().join("batch/a-reader/report.json")).unwrap();
        assert!(!report.contains("READ /tmp"), "{mode}: {report}");
        // The folder's mode is put back.
        use std::os::unix::fs::PermissionsExt;
        let mode_after = std::fs::metadata(batch.path())
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode_after & 0o777, 0o755, "{mode}");
    }
}

/// The regular files of `from` copied into a new folder `to`.
fn copy_folder(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        if e.file_type().unwrap().is_file() {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// An adapter that starts a program its command line does not name (a wrapper script running
/// `../build/tracer`) failed inside the sandbox with that program's "No such file or
/// directory", though the file exists. The message says that the sandbox shows only the
/// folders of the files on the command line, and `--expose FOLDER` shows another read-only.
#[test]
fn an_adapter_that_starts_a_program_from_elsewhere_is_told_about_expose() {
    if !root("an_adapter_that_starts_a_program_from_elsewhere_is_told_about_expose") {
        return;
    }
    let top = tempfile::tempdir().unwrap();
    let (bin, build) = (top.path().join("bin"), top.path().join("build"));
    std::fs::create_dir_all(&bin).unwrap();
    std::fs::create_dir_all(&build).unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/adapters/misbehaving.py"),
        build.join("tracer.py"),
    )
    .unwrap();
    let wrapper = bin.join("run.sh");
    std::fs::write(
        &wrapper,
        "#!/bin/sh\nexec /usr/bin/python3 -I \"$(dirname \"$0\")/../build/tracer.py\"\n",
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    for d in walk_dirs(top.path()) {
        open_up(&d);
    }
    let vectors_dir = tempfile::tempdir().unwrap();
    let vectors = vectors_dir.path().join("v.jsonl");
    let made = run_in(
        vectors_dir.path(),
        &[
            "vectors",
            "--count",
            "20",
            "--shapes",
            "sphere",
            "-o",
            vectors.to_str().unwrap(),
        ],
    );
    assert_eq!(made.status.code(), Some(0), "{}", stderr(&made));
    let check = |mode: &str, show: &[&Path]| {
        let mut cmd = rtoracle();
        cmd.current_dir(vectors_dir.path())
            .env("RTORACLE_SANDBOX", mode)
            .args(["check", "--adapter"])
            .arg(&wrapper)
            .arg("--vectors")
            .arg(&vectors);
        for s in show {
            cmd.arg("--expose").arg(s);
        }
        let out = cmd.output().unwrap();
        let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
        (out, text)
    };
    for mode in ["auto", "uid"] {
        let (_, text) = check(mode, &[]);
        assert!(text.contains("did not answer the hello"), "{mode}: {text}");
        assert!(
            text.contains("the sandbox shows only the system's folders and the folders of the files on the command line")
                && text.contains(&bin.display().to_string())
                && text.contains("pass --expose FOLDER to show a folder read-only"),
            "{mode}: {text}"
        );
        let (out, text) = check(mode, &[&build]);
        assert!(!text.contains("did not answer the hello"), "{mode}: {text}");
        assert!(matches!(out.status.code(), Some(0 | 1)), "{mode}: {text}");
    }
    let (out, _) = check("auto", &[Path::new("/no/such/folder")]);
    assert_bad_input(&out, "--expose /no/such/folder: no such folder");
}
