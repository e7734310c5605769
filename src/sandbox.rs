//! How untrusted code is started: the one place that spawns a candidate or a student's
//! submission (`check --python-course`, `check --adapter`, `fuzz` and `grade` all come here,
//! through [`candidate::Session`](crate::candidate::Session)). GRADING.md, "Running untrusted
//! code".
//!
//! What is done, and where:
//! - **A fresh temporary folder** per [`Sandbox`] (one per checked candidate; a restart after a
//!   crash reuses it): the files the code needs (for the course adapter: the submission's
//!   top-level `.py` files and the adapter script) are copied into it, readable by all, and the
//!   code runs there, so it never touches the submission or the grader's files; it is deleted
//!   afterwards. (Everywhere.)
//! - **A cleared environment**: only `PATH` (inherited), `HOME` and `TMPDIR` (the folder),
//!   `LANG` and `LC_ALL` (`C.UTF-8`), and the `PYTHON*` switches of [`Sandbox::command`].
//!   (Everywhere.)
//! - **Limits** set with `setrlimit` between `fork` and `exec`: CPU time, address space, open
//!   files, file size, no core files; and a process count for the drop user. (Unix.)
//! - **Its own session and process group** (`setsid`), killed as a whole ([`kill_group`]); and
//!   `SIGKILL` when the thread that spawned it dies (`PR_SET_PDEATHSIG`, Linux).
//! - **No network** where the platform allows: a new, empty network namespace
//!   (`unshare(CLONE_NEWNET)`), which needs root or `CAP_SYS_ADMIN` (so it works on Gradescope,
//!   which runs the grader as root, and in most CI containers). Whether it took effect is read
//!   back from `/proc/<pid>/ns/net` ([`SandboxFacts::network_isolated`]). (Linux.)
//! - **Never as root when a drop user exists**: when the harness runs as root the child switches
//!   to the user `nobody` (or `$RTORACLE_SANDBOX_USER`) with no supplementary groups, after the
//!   namespace is made. If that user cannot run the program (say Python lives under `/root`),
//!   which [`Sandbox::probe`] or [`Sandbox::probe_access`] finds out before any untrusted code
//!   runs, the run falls back to the current user and [`SandboxFacts::note`] says so. (Unix.)

use std::ffi::{CString, OsStr, OsString};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use serde::{Deserialize, Serialize};

/// Limits and switches of the sandbox.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SandboxPolicy {
    /// CPU seconds per process (`RLIMIT_CPU`; a restart starts afresh).
    pub cpu_seconds: u64,
    /// Address space in bytes (`RLIMIT_AS`).
    pub memory_bytes: u64,
    /// Open files (`RLIMIT_NOFILE`).
    pub open_files: u64,
    /// Largest file it may write, in bytes (`RLIMIT_FSIZE`).
    pub file_size_bytes: u64,
    /// Processes and threads of the drop user (`RLIMIT_NPROC`; set only when the child drops
    /// to that user, since it counts every process of the user).
    pub processes: u64,
    /// The user to run as when the harness is root.
    pub drop_user: String,
    /// Try a new network namespace.
    pub isolate_network: bool,
}

impl Default for SandboxPolicy {
    /// The limits of `check` and `fuzz`: generous CPU time for long suites.
    fn default() -> Self {
        SandboxPolicy {
            cpu_seconds: 600,
            memory_bytes: 2 << 30,
            open_files: 64,
            file_size_bytes: 64 << 20,
            processes: 64,
            drop_user: std::env::var("RTORACLE_SANDBOX_USER").unwrap_or_else(|_| "nobody".into()),
            isolate_network: true,
        }
    }
}

impl SandboxPolicy {
    /// The tighter limits of `grade`: 30 CPU seconds, 1 GiB, 16 MiB files.
    pub fn grading() -> Self {
        SandboxPolicy {
            cpu_seconds: 30,
            memory_bytes: 1 << 30,
            file_size_bytes: 16 << 20,
            ..SandboxPolicy::default()
        }
    }
}

/// A prepared sandbox: a temporary folder holding copies of the files, and the policy.
#[derive(Debug)]
pub struct Sandbox {
    policy: SandboxPolicy,
    dir: tempfile::TempDir,
    /// `(uid, gid)` to switch to, when the harness is root and the drop user exists.
    drop_to: Option<(u32, u32)>,
    /// Why the drop user is not used (for the report).
    drop_note: Option<String>,
}

/// What the sandbox did, for the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SandboxFacts {
    /// The policy.
    pub policy: SandboxPolicy,
    /// The user id the code ran as.
    pub uid: u32,
    /// Why the drop user was not used, when the harness is root and it was not.
    pub note: Option<String>,
    /// Whether the child was seen in a network namespace of its own (`None`: not looked at).
    pub network_isolated: Option<bool>,
}

/// The user id and group id of user `name`, if it exists.
pub fn lookup_user(name: &str) -> Option<(u32, u32)> {
    let cname = CString::new(name).ok()?;
    // SAFETY: getpwnam returns a pointer to static storage or null; we read it at once.
    let pw = unsafe { libc::getpwnam(cname.as_ptr()) };
    if pw.is_null() {
        return None;
    }
    // SAFETY: non-null pointer to a passwd record.
    let (uid, gid) = unsafe { ((*pw).pw_uid, (*pw).pw_gid) };
    Some((uid, gid))
}

/// Whether this process runs as root.
pub fn running_as_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

/// `program` as found on `PATH` when it is a bare name.
fn resolve_on_path(program: &Path) -> Option<PathBuf> {
    if program.components().count() > 1 || program.is_absolute() {
        return Some(program.to_path_buf());
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(program))
        .find(|p| p.is_file())
}

impl Sandbox {
    /// Makes the temporary folder and copies `files` (`(source, name in the folder)`) into it.
    pub fn new(policy: SandboxPolicy, files: &[(PathBuf, String)]) -> std::io::Result<Sandbox> {
        let dir = tempfile::Builder::new()
            .prefix("rtoracle-sandbox-")
            .tempdir()?;
        let (drop_to, drop_note) = if !running_as_root() {
            (None, None)
        } else {
            match lookup_user(&policy.drop_user) {
                Some((uid, gid)) if uid != 0 => (Some((uid, gid)), None),
                _ => (
                    None,
                    Some(format!(
                        "running as root: no user {:?} to drop to",
                        policy.drop_user
                    )),
                ),
            }
        };
        for (source, name) in files {
            let target = dir.path().join(name);
            std::fs::copy(source, &target)?;
            std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o644))?;
        }
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755))?;
        if let Some((uid, gid)) = drop_to {
            std::os::unix::fs::chown(dir.path(), Some(uid), Some(gid))?;
        }
        Ok(Sandbox {
            policy,
            dir,
            drop_to,
            drop_note,
        })
    }

    /// The temporary folder the code runs in.
    pub fn dir(&self) -> &Path {
        self.dir.path()
    }

    /// The policy.
    pub fn policy(&self) -> &SandboxPolicy {
        &self.policy
    }

    /// Writes an extra file (such as an adapter script) into the folder, readable by all.
    pub fn add_file(&self, name: &str, contents: &[u8]) -> std::io::Result<PathBuf> {
        let path = self.dir.path().join(name);
        std::fs::write(&path, contents)?;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644))?;
        Ok(path)
    }

    /// Gives up the drop user (after a probe showed it cannot run the program).
    pub fn keep_current_user(&mut self, why: String) {
        if self.drop_to.take().is_some() {
            self.drop_note = Some(why);
        }
    }

    /// Whether the child switches user.
    pub fn drops_user(&self) -> bool {
        self.drop_to.is_some()
    }

    /// A command for `program` that runs inside the sandbox: working directory, cleared
    /// environment, own session and process group, limits, network namespace, user.
    pub fn command(&self, program: &Path) -> Command {
        let mut cmd = Command::new(program);
        let dir = self.dir.path();
        cmd.current_dir(dir)
            .env_clear()
            .env(
                "PATH",
                std::env::var_os("PATH").unwrap_or_else(|| "/usr/local/bin:/usr/bin:/bin".into()),
            )
            .env("HOME", dir)
            .env("TMPDIR", dir)
            .env("LANG", "C.UTF-8")
            .env("LC_ALL", "C.UTF-8")
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("PYTHONHASHSEED", "0")
            .env("PYTHONIOENCODING", "utf-8")
            .env("PYTHONNOUSERSITE", "1")
            .env("PYTHONUNBUFFERED", "1");
        let policy = self.policy.clone();
        let drop_to = self.drop_to;
        let parent = std::process::id() as libc::pid_t;
        // SAFETY: the closure only makes async-signal-safe system calls (setsid, unshare,
        // setrlimit, setgroups, setgid, setuid, prctl, getppid) and allocates nothing.
        unsafe {
            cmd.pre_exec(move || {
                if libc::setsid() < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                #[cfg(target_os = "linux")]
                if policy.isolate_network {
                    // Best effort: fails without CAP_SYS_ADMIN, which the facts show.
                    let _ = libc::unshare(libc::CLONE_NEWNET);
                }
                let limit = |resource, value: u64| {
                    let rl = libc::rlimit {
                        rlim_cur: value as libc::rlim_t,
                        rlim_max: value as libc::rlim_t,
                    };
                    libc::setrlimit(resource, &rl);
                };
                limit(libc::RLIMIT_CPU, policy.cpu_seconds);
                limit(libc::RLIMIT_AS, policy.memory_bytes);
                limit(libc::RLIMIT_NOFILE, policy.open_files);
                limit(libc::RLIMIT_FSIZE, policy.file_size_bytes);
                limit(libc::RLIMIT_CORE, 0);
                if let Some((uid, gid)) = drop_to {
                    limit(libc::RLIMIT_NPROC, policy.processes);
                    if libc::setgroups(0, std::ptr::null()) != 0
                        || libc::setgid(gid) != 0
                        || libc::setuid(uid) != 0
                    {
                        return Err(std::io::Error::last_os_error());
                    }
                }
                // After the user change, which clears it.
                #[cfg(target_os = "linux")]
                {
                    libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong);
                    if libc::getppid() != parent {
                        // The harness died before the signal was armed.
                        libc::_exit(137);
                    }
                }
                Ok(())
            });
        }
        cmd
    }

    /// Runs `program args` (such as `python3 -I -S -c pass`) in the sandbox and says whether it
    /// exited 0; when it cannot run as the drop user, falls back to the current user and notes
    /// why. Never run untrusted code here: whatever fails makes the sandbox give up the drop
    /// user.
    pub fn probe(&mut self, program: &Path, args: &[&OsStr]) -> bool {
        let ok = |sandbox: &Sandbox| {
            sandbox
                .command(program)
                .args(args)
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .map(|s| s.success())
                .unwrap_or(false)
        };
        if ok(self) {
            return true;
        }
        if self.drops_user() {
            self.keep_current_user(format!(
                "user {:?} cannot run {}: ran as the current user",
                self.policy.drop_user,
                program.display()
            ));
            return ok(self);
        }
        false
    }

    /// For a program that cannot be probed by running it (an adapter command): checks, as the
    /// drop user, that `program` is executable and every argument naming an existing absolute
    /// path is readable; if not, falls back to the current user and notes why. Does nothing
    /// when the sandbox does not drop the user.
    pub fn probe_access(&mut self, program: &Path, args: &[OsString]) {
        if !self.drops_user() {
            return;
        }
        let Some(resolved) = resolve_on_path(program) else {
            return; // The spawn will say the program does not exist.
        };
        let files = args
            .iter()
            .filter(|a| Path::new(a).is_absolute() && Path::new(a).exists());
        let ok = self
            .command(Path::new("/bin/sh"))
            .arg("-c")
            .arg(r#"[ -x "$1" ] || exit 1; shift; for p; do [ -r "$p" ] || exit 1; done"#)
            .arg("sh")
            .arg(&resolved)
            .args(files)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        if !ok {
            self.keep_current_user(format!(
                "user {:?} cannot run {} or read its files: ran as the current user",
                self.policy.drop_user,
                program.display()
            ));
        }
    }

    /// The facts of a run, given the id of a child spawned from [`Sandbox::command`] (for the
    /// network check).
    pub fn facts(&self, child: Option<u32>) -> SandboxFacts {
        let network_isolated = child.and_then(|pid| {
            let mine = std::fs::read_link("/proc/self/ns/net").ok()?;
            let theirs = std::fs::read_link(format!("/proc/{pid}/ns/net")).ok()?;
            Some(mine != theirs)
        });
        SandboxFacts {
            policy: self.policy.clone(),
            // SAFETY: getuid has no preconditions.
            uid: self
                .drop_to
                .map_or_else(|| unsafe { libc::getuid() }, |d| d.0),
            note: self.drop_note.clone(),
            network_isolated,
        }
    }
}

/// Kills a child spawned from [`Sandbox::command`] and everything in its process group, and
/// reaps it.
pub fn kill_group(child: &mut Child) {
    // SAFETY: the child leads its own process group (setsid) and is not reaped yet, so its pid
    // is still that group's id.
    unsafe {
        libc::killpg(child.id() as libc::pid_t, libc::SIGKILL);
    }
    let _ = child.kill();
    let _ = child.wait();
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    fn sh_output(sandbox: &Sandbox, script: &str) -> String {
        let mut child = sandbox
            .command(Path::new("/bin/sh"))
            .args(["-c", script])
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut out = String::new();
        child
            .stdout
            .take()
            .unwrap()
            .read_to_string(&mut out)
            .unwrap();
        child.wait().unwrap();
        out
    }

    #[test]
    fn the_child_gets_a_cleared_environment_its_folder_and_the_limits() {
        // SAFETY: setting a variable in a test before spawning; the child must not see it.
        unsafe { std::env::set_var("RTORACLE_SECRET_FOR_TEST", "leak") };
        let src = tempfile::tempdir().unwrap();
        let file = src.path().join("a.py");
        std::fs::write(&file, "x = 1\n").unwrap();
        let sandbox = Sandbox::new(SandboxPolicy::grading(), &[(file, "a.py".into())]).unwrap();
        let out = sh_output(&sandbox, "env; pwd; ls; ulimit -n; ulimit -t; id -u");
        assert!(!out.contains("RTORACLE_SECRET_FOR_TEST"), "{out}");
        assert!(out.contains("PYTHONDONTWRITEBYTECODE=1"), "{out}");
        let dir = sandbox.dir().canonicalize().unwrap();
        assert!(out.contains(&format!("{}\n", dir.display())), "{out}");
        assert!(out.contains("a.py\n64\n30\n"), "{out}");
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } == 0 && lookup_user("nobody").is_some() {
            assert!(sandbox.drops_user());
            assert!(
                out.trim_end().ends_with("65534"),
                "not dropped to nobody: {out}"
            );
        }
    }

    #[test]
    fn an_adapter_the_drop_user_cannot_reach_makes_the_sandbox_keep_the_current_user() {
        if !running_as_root() || lookup_user("nobody").is_none() {
            eprintln!("skipped: needs root and the user nobody");
            return;
        }
        // A program in a folder only root may enter.
        let private = tempfile::tempdir().unwrap();
        std::fs::set_permissions(private.path(), std::fs::Permissions::from_mode(0o700)).unwrap();
        let program = private.path().join("adapter.sh");
        std::fs::write(&program, "#!/bin/sh\n").unwrap();
        std::fs::set_permissions(&program, std::fs::Permissions::from_mode(0o755)).unwrap();
        let mut sandbox = Sandbox::new(SandboxPolicy::default(), &[]).unwrap();
        sandbox.probe_access(&program, &[]);
        assert!(!sandbox.drops_user());
        let note = sandbox.facts(None).note.unwrap_or_default();
        assert!(note.contains("cannot run"), "{note}");
        // A system program it can run, with a file it cannot read on its command line.
        let mut sandbox = Sandbox::new(SandboxPolicy::default(), &[]).unwrap();
        sandbox.probe_access(Path::new("sh"), &[]);
        assert!(sandbox.drops_user());
        sandbox.probe_access(Path::new("sh"), &[program.into_os_string()]);
        assert!(!sandbox.drops_user());
    }

    #[test]
    fn a_killed_group_takes_its_grandchildren_with_it() {
        let sandbox = Sandbox::new(SandboxPolicy::default(), &[]).unwrap();
        let mut child = sandbox
            .command(Path::new("/bin/sh"))
            .args(["-c", "sleep 30 & echo $! > grandchild; wait"])
            .spawn()
            .unwrap();
        let pid_file = sandbox.dir().join("grandchild");
        let mut waited = 0;
        while !pid_file.exists() && waited < 100 {
            std::thread::sleep(std::time::Duration::from_millis(20));
            waited += 1;
        }
        let grandchild: u32 = std::fs::read_to_string(&pid_file)
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let facts = sandbox.facts(Some(child.id()));
        kill_group(&mut child);
        std::thread::sleep(std::time::Duration::from_millis(100));
        // Gone, or a zombie waiting for init to reap it: either way, not running.
        let state = std::fs::read_to_string(format!("/proc/{grandchild}/stat"))
            .ok()
            .and_then(|s| {
                s.rsplit(')')
                    .next()
                    .map(|r| r.trim().chars().next().unwrap_or('?'))
            });
        assert!(
            matches!(state, None | Some('Z') | Some('X')),
            "grandchild state {state:?}"
        );
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } == 0 {
            assert_eq!(facts.network_isolated, Some(true));
        }
    }
}
