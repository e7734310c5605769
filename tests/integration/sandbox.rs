//! The sandbox against hostile submissions (docs/sandbox.md): one test per
//! class of attack, each a course-layout submission (the honest fixture plus a hostile import)
//! run through the real binary. They need root, as a grader on Gradescope has it; they say so
//! and pass when not root.

use std::path::{Path, PathBuf};
use std::process::Output;

use rtoracle::candidate::bench::assemble_fixture;

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
    let json = serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
    (out, json)
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
            ])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            text.contains("the sandbox stopped it: it wrote more than 256 MiB"),
            "{mode}: {}\n{}",
            &text[..text.len().min(2000)],
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
        // `12.5 / 100` alone is `12.5 / 100` beside the killer.
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
    let json = serde_json::from_slice(&out.stdout).unwrap_or(serde_json::Value::Null);
    (out, json)
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
import os as _o, sys as _s, time as _t
for _i in range(4):
    if _o.fork() == 0:
        _b = b"\x01" * (400 << 20)
        _t.sleep(4)
        _o._exit(0)
_s.stderr.write("FORKED\n")
_t.sleep(4)
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
/// namespace can be made, everything is read-only but its own folder and the shared folders
/// (`/tmp`, `/var/tmp`, ...), where what it writes is measured and swept.
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
        rtoracle::sandbox::scratch::SHARED_ROOTS
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
    // Its folder and the shared folders are writable, and what it left there is swept.
    for place in ["/tmp/", "/var/tmp/", "scratch-"] {
        assert!(tail.contains(&format!("WROTE {place}")), "{tail}");
    }
    assert!(!Path::new(&format!("/tmp/{marker}")).exists());
    assert!(!Path::new(&format!("/var/tmp/{marker}")).exists());
    assert_eq!(
        std::fs::read_to_string(&theirs).unwrap(),
        "# a classmate's work\n"
    );
    assert!(!classmate.path().join("planted.py").exists());
}
