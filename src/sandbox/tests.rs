//! Tests of the sandbox: what the code sees, who it runs as, and that nothing outlives it.

use super::bounds::reaper::kill_group;
use super::detect::bubblewrap_works;
use super::identity::running_as_root;
use super::lifecycle::Sandbox;
use super::policy::{Isolation, SandboxPolicy};
use super::start::command::SANDBOX_PATH;
use super::view::replace_path;
use super::*;
use std::io::Read;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::Duration;

fn sh_output(sandbox: &Sandbox, script: &str) -> String {
    let mut child = sandbox
        .command(Path::new("/bin/sh"))
        .args(["-c", script])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    child.wait().unwrap();
    out + &err
}

/// The modes this machine can test: bubblewrap where it works, and the fallback (root only).
fn modes() -> Vec<Isolation> {
    let mut modes = Vec::new();
    match bubblewrap_works() {
        Ok(()) => modes.push(Isolation::Bubblewrap),
        Err(why) => eprintln!("bubblewrap not tested: {why}"),
    }
    if running_as_root() {
        modes.push(Isolation::FallbackUid);
    } else {
        modes.push(Isolation::CurrentUser);
    }
    modes
}

fn sandbox(isolation: Isolation, files: &[(PathBuf, String)]) -> Sandbox {
    Sandbox::with_isolation(SandboxPolicy::grading(), isolation, files, None).unwrap()
}

#[test]
fn the_child_gets_a_cleared_environment_its_folder_the_limits_and_never_root() {
    // SAFETY: setting a variable in a test before spawning; the child must not see it.
    unsafe { std::env::set_var("RTORACLE_SECRET_FOR_TEST", "leak") };
    let src = tempfile::tempdir().unwrap();
    let file = src.path().join("a.py");
    std::fs::write(&file, "x = 1\n").unwrap();
    for isolation in modes() {
        let sandbox = sandbox(isolation, &[(file.clone(), "a.py".into())]);
        let out = sh_output(&sandbox, "env; pwd; ls; ulimit -n; ulimit -t; id -u");
        assert!(
            !out.contains("RTORACLE_SECRET_FOR_TEST"),
            "{isolation:?}: {out}"
        );
        assert!(out.contains("PYTHONDONTWRITEBYTECODE=1"), "{out}");
        assert!(out.contains(&format!("PATH={SANDBOX_PATH}\n")), "{out}");
        let inside = sandbox.inside_dir();
        let inside = inside.canonicalize().unwrap_or(inside);
        assert!(
            out.contains(&format!("{}\na.py\n64\n30\n", inside.display())),
            "{out}"
        );
        let uid: u32 = out.lines().last().unwrap().trim().parse().unwrap();
        assert_eq!(uid, sandbox.uid(), "{isolation:?}");
        if running_as_root() {
            assert_ne!(uid, 0, "{isolation:?}: ran as root");
            assert!(
                uid >= 1 << 30,
                "{isolation:?}: not a per-submission id: {uid}"
            );
        }
    }
}

#[test]
fn every_sandbox_of_a_root_harness_has_its_own_uid_and_a_private_folder() {
    if !running_as_root() {
        eprintln!("skipped: needs root");
        return;
    }
    let a = sandbox(Isolation::FallbackUid, &[]);
    let b = sandbox(Isolation::FallbackUid, &[]);
    assert_ne!(a.uid(), b.uid());
    let secret = a.add_file("secret.py", b"answer = 42\n").unwrap();
    let mode = std::fs::metadata(a.dir()).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o700);
    // b's code cannot read a's folder, nor signal a's processes.
    let out = sh_output(
        &b,
        &format!(
            "cat {} 2>/dev/null && echo READ; ls {} 2>/dev/null && echo LISTED; echo done",
            secret.display(),
            a.dir().display()
        ),
    );
    assert!(!out.contains("READ") && !out.contains("LISTED"), "{out}");
    assert!(out.contains("done"), "{out}");
}

#[test]
fn under_bubblewrap_nothing_of_the_grader_is_visible() {
    if let Err(why) = bubblewrap_works() {
        eprintln!("skipped: {why}");
        return;
    }
    let sandbox = sandbox(Isolation::Bubblewrap, &[]);
    let here = std::env::current_dir().unwrap();
    let exe = std::env::current_exe().unwrap();
    // The paths to look for come in a file, so no command line inside names them.
    let paths = format!(
        "/root\n/home\n/work\n{}\n{}\n{}\n/etc/shadow\n/etc/passwd\n",
        here.display(),
        exe.display(),
        sandbox.dir().display()
    );
    sandbox.add_file("paths", paths.as_bytes()).unwrap();
    let out = sh_output(
        &sandbox,
        "ls / | tr '\\n' ' '; echo; while read p; do [ -e \"$p\" ] && printf 'VIS%s %s\\n' IBLE \"$p\"; done < paths; \
         for f in /proc/[0-9]*/cmdline; do tr '\\0' ' ' < $f; echo; done; hostname; echo end",
    );
    assert!(!out.contains("VISIBLE"), "{out}");
    // Only the sandbox's own processes: bubblewrap's init, the shell and its children.
    assert!(!out.contains("rtoracle"), "{out}");
    assert!(!out.contains("cargo"), "{out}");
    assert!(out.contains("sandbox\nend"), "{out}");
}

#[test]
fn bubblewrap_reports_the_namespaces_it_made() {
    if let Err(why) = bubblewrap_works() {
        eprintln!("skipped: {why}");
        return;
    }
    let sandbox = sandbox(Isolation::Bubblewrap, &[]);
    let mut child = sandbox
        .command(Path::new("sleep"))
        .arg("5")
        .spawn()
        .unwrap();
    let facts = sandbox.facts(Some(child.id()));
    kill_group(&mut child);
    for ns in ["user", "pid", "net", "ipc", "mount", "uts"] {
        assert!(facts.namespaces.iter().any(|n| n == ns), "{ns}: {facts:?}");
    }
    assert_eq!(facts.network_isolated, Some(true));
    assert_eq!(facts.isolation, Isolation::Bubblewrap);
    assert!(
        facts.summary().starts_with("bubblewrap (user, pid, net"),
        "{}",
        facts.summary()
    );
}

#[test]
fn a_double_forked_setsid_sleeper_does_not_outlive_the_sandbox() {
    for isolation in modes() {
        if isolation == Isolation::CurrentUser {
            // An unprivileged harness without bubblewrap cannot reach a process that left its
            // session: the documented limit of that mode.
            continue;
        }
        let sandbox = sandbox(isolation, &[]);
        let mut child = sandbox
            .command(Path::new("/bin/sh"))
            .args([
                "-c",
                "(setsid sh -c 'exec sleep 1000' & ) ; sleep 0.2; \
                 for f in /proc/[0-9]*/cmdline; do tr '\\0' ' ' < $f; echo; done > procs; sleep 1000",
            ])
            .stdout(Stdio::null())
            .spawn()
            .unwrap();
        sandbox.reaper().track(child.id());
        let procs = sandbox.dir().join("procs");
        let mut waited = 0;
        while std::fs::metadata(&procs)
            .map(|m| m.len() == 0)
            .unwrap_or(true)
            && waited < 250
        {
            std::thread::sleep(Duration::from_millis(20));
            waited += 1;
        }
        let uid = sandbox.uid();
        assert!(
            identity::processes_of(uid).len() >= 2,
            "{isolation:?}: the sleepers did not start"
        );
        sandbox.reaper().reap();
        kill_group(&mut child);
        sandbox.reaper().untrack(child.id());
        drop(sandbox);
        // Everything of that uid is gone, the setsid sleeper included, and the folder too.
        let mut left = identity::processes_of(uid);
        for _ in 0..100 {
            if left.is_empty() {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
            left = identity::processes_of(uid);
        }
        assert!(left.is_empty(), "{isolation:?}: left {left:?}");
        assert!(!procs.exists());
    }
}

#[test]
fn an_unsandboxed_run_says_so() {
    let policy = SandboxPolicy {
        unsandboxed: true,
        ..SandboxPolicy::default()
    };
    let sandbox = Sandbox::new(policy, &[]).unwrap();
    let facts = sandbox.facts(None);
    assert_eq!(facts.isolation, Isolation::Unsandboxed);
    // SAFETY: getuid has no preconditions.
    assert_eq!(facts.uid, unsafe { libc::getuid() });
    assert!(
        facts.summary().contains("UNSANDBOXED"),
        "{}",
        facts.summary()
    );
    assert!(facts.note.unwrap().contains("--unsandboxed"));
}

#[test]
fn an_adapter_the_sandbox_user_cannot_reach_is_refused_not_run_as_root() {
    if !running_as_root() {
        eprintln!("skipped: needs root");
        return;
    }
    // A program in a folder only root may enter.
    let private = tempfile::tempdir().unwrap();
    std::fs::set_permissions(private.path(), std::fs::Permissions::from_mode(0o700)).unwrap();
    let program = private.path().join("adapter.sh");
    std::fs::write(&program, "#!/bin/sh\n").unwrap();
    std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o755)).unwrap();
    for isolation in modes() {
        let mut sandbox = sandbox(isolation, &[]);
        sandbox.expose(&program);
        let err = sandbox
            .probe_access(&program, &[])
            .expect_err(&format!("{isolation:?}"));
        assert!(err.contains("cannot run or read"), "{isolation:?}: {err}");
        // The folder that blocks is named, with the fix (the file itself is readable by all).
        let folder = private.path().display();
        assert!(
            err.contains(&format!(
                "the folder {folder} is closed to other users (mode 700)"
            )) && err.contains(&format!("`chmod o+x {folder}`"))
                && err.contains("--unsandboxed"),
            "{isolation:?}: {err}"
        );
        // A system program it can run; a file it cannot read on its command line.
        sandbox.probe_access(Path::new("sh"), &[]).unwrap();
        let err = sandbox
            .probe_access(Path::new("sh"), &[program.clone().into_os_string()])
            .unwrap_err();
        assert!(err.contains("adapter.sh"), "{err}");
    }
    // Once the folder is open, the file's own mode is what is named.
    std::fs::set_permissions(private.path(), std::fs::Permissions::from_mode(0o711)).unwrap();
    std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o700)).unwrap();
    let mut sandbox = sandbox(Isolation::FallbackUid, &[]);
    sandbox.expose(&program);
    let err = sandbox.probe_access(&program, &[]).unwrap_err();
    assert!(
        err.contains(&format!("`chmod o+rx {}`", program.display())),
        "{err}"
    );
}

#[test]
fn the_inside_folder_is_replaced_only_where_it_starts_a_path() {
    let from = Path::new("/sandbox");
    assert_eq!(
        replace_path(
            "File \"/sandbox/RT_object.py\", /work/wt/sandbox/x /sandboxes /sandbox",
            from,
            "/sub"
        ),
        "File \"/sub/RT_object.py\", /work/wt/sandbox/x /sandboxes /sub"
    );
}
