//! The sandbox student code runs in (GRADING.md, "Running untrusted code").
//!
//! What is done, and where:
//! - **A fresh temporary folder** per run: the submission's `.py` files are copied into it and the
//!   code runs there, so it never touches the submission or the grader's files; it is deleted
//!   afterwards. (Everywhere.)
//! - **A cleared environment**: only `PATH`, `HOME` and `TMPDIR` (the temporary folder), `LANG`,
//!   and the `PYTHON*` switches below. (Everywhere.)
//! - **Limits** set with `setrlimit` between `fork` and `exec`: CPU time, address space, open
//!   files, file size, no core files, and a process count. (Linux and other Unixes; the process
//!   count only binds a non-root user.)
//! - **Its own process group**, killed as a whole on a timeout. (Unix.)
//! - **No network** where the platform allows: a new, empty network namespace
//!   (`unshare(CLONE_NEWNET)`), which needs root or `CAP_SYS_ADMIN` (so it works on Gradescope,
//!   which runs the grader as root, and in most CI containers). Whether it took effect is read
//!   back from `/proc/<pid>/ns/net` and written to the report.
//! - **Never as root when a drop user exists**: when the grader runs as root it switches the child
//!   to the user `nobody` (or `RTORACLE_SANDBOX_USER`) with no supplementary groups, after the
//!   namespace is made. If that user cannot run the interpreter (say Python lives under `/root`),
//!   the run falls back to the current user and the report says so.

use std::ffi::CString;
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command};

use serde::Serialize;

/// Limits and switches of the sandbox.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SandboxPolicy {
    /// CPU seconds per process (`RLIMIT_CPU`).
    pub cpu_seconds: u64,
    /// Address space in bytes (`RLIMIT_AS`).
    pub memory_bytes: u64,
    /// Open files (`RLIMIT_NOFILE`).
    pub open_files: u64,
    /// Largest file it may write, in bytes (`RLIMIT_FSIZE`).
    pub file_size_bytes: u64,
    /// Processes of the user (`RLIMIT_NPROC`, not enforced for root).
    pub processes: u64,
    /// The user to run as when the grader is root.
    pub drop_user: String,
    /// Try a new network namespace.
    pub isolate_network: bool,
}

impl Default for SandboxPolicy {
    fn default() -> Self {
        SandboxPolicy {
            cpu_seconds: 30,
            memory_bytes: 1 << 30,
            open_files: 64,
            file_size_bytes: 16 << 20,
            processes: 64,
            drop_user: std::env::var("RTORACLE_SANDBOX_USER").unwrap_or_else(|_| "nobody".into()),
            isolate_network: true,
        }
    }
}

/// A prepared sandbox: a temporary folder holding copies of the files, and the policy.
#[derive(Debug)]
pub struct Sandbox {
    policy: SandboxPolicy,
    dir: tempfile::TempDir,
    /// `(uid, gid)` to switch to, when the grader is root and the drop user exists.
    drop_to: Option<(u32, u32)>,
    /// Why the drop user is not used (for the report).
    drop_note: Option<String>,
}

/// What the sandbox did, for the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SandboxFacts {
    /// The policy.
    pub policy: SandboxPolicy,
    /// The user id the code ran as.
    pub uid: u32,
    /// Why the drop user was not used, when it was not.
    pub note: Option<String>,
    /// Whether the child was seen in a network namespace of its own.
    pub network_isolated: Option<bool>,
}

fn lookup_user(name: &str) -> Option<(u32, u32)> {
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

impl Sandbox {
    /// Makes the temporary folder and copies `files` (`(source, name in the folder)`) into it.
    pub fn new(policy: SandboxPolicy, files: &[(PathBuf, String)]) -> std::io::Result<Sandbox> {
        let dir = tempfile::Builder::new()
            .prefix("rtoracle-sandbox-")
            .tempdir()?;
        // SAFETY: geteuid has no preconditions.
        let root = unsafe { libc::geteuid() } == 0;
        let (drop_to, drop_note) = if !root {
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

    /// Writes an extra file (such as a driver script) into the folder, readable by all.
    pub fn add_file(&self, name: &str, contents: &[u8]) -> std::io::Result<PathBuf> {
        let path = self.dir.path().join(name);
        std::fs::write(&path, contents)?;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644))?;
        Ok(path)
    }

    /// Gives up the drop user (after [`Sandbox::probe`] showed it cannot run the program).
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
    /// environment, own process group, limits, network namespace, user.
    pub fn command(&self, program: &Path) -> Command {
        let mut cmd = Command::new(program);
        let dir = self.dir.path();
        cmd.current_dir(dir)
            .env_clear()
            .env("PATH", "/usr/local/bin:/usr/bin:/bin")
            .env("HOME", dir)
            .env("TMPDIR", dir)
            .env("LANG", "C.UTF-8")
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("PYTHONHASHSEED", "0")
            .env("PYTHONIOENCODING", "utf-8")
            .env("PYTHONNOUSERSITE", "1")
            .env("PYTHONUNBUFFERED", "1")
            .process_group(0);
        let policy = self.policy.clone();
        let drop_to = self.drop_to;
        // SAFETY: the closure only makes async-signal-safe system calls (unshare, setrlimit,
        // setgroups, setgid, setuid) and allocates nothing.
        unsafe {
            cmd.pre_exec(move || {
                if policy.isolate_network {
                    // Best effort: fails without CAP_SYS_ADMIN, which the report shows.
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
                limit(libc::RLIMIT_NPROC, policy.processes);
                if let Some((uid, gid)) = drop_to {
                    if libc::setgroups(0, std::ptr::null()) != 0
                        || libc::setgid(gid) != 0
                        || libc::setuid(uid) != 0
                    {
                        return Err(std::io::Error::last_os_error());
                    }
                }
                Ok(())
            });
        }
        cmd
    }

    /// Runs `program -c pass`-style `args` in the sandbox and says whether it exited 0; when it
    /// cannot run as the drop user, falls back to the current user and notes why.
    pub fn probe(&mut self, program: &Path, args: &[&str]) -> bool {
        let ok = |sandbox: &Sandbox| {
            sandbox
                .command(program)
                .args(args)
                .stdin(std::process::Stdio::null())
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null())
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

    /// The facts of a run, given a child spawned from [`Sandbox::command`] (for the network check).
    pub fn facts(&self, child: Option<&Child>) -> SandboxFacts {
        let network_isolated = child.and_then(|c| {
            let mine = std::fs::read_link("/proc/self/ns/net").ok()?;
            let theirs = std::fs::read_link(format!("/proc/{}/ns/net", c.id())).ok()?;
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
    // SAFETY: kill with a negative pid signals the process group the child leads.
    unsafe {
        libc::kill(-(child.id() as libc::pid_t), libc::SIGKILL);
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
        let sandbox = Sandbox::new(SandboxPolicy::default(), &[(file, "a.py".into())]).unwrap();
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
        let facts = sandbox.facts(Some(&child));
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
