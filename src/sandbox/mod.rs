//! How untrusted code is started: the one place that spawns a candidate or a student's
//! submission (`check --python-course`, `check --adapter`, `fuzz` and `grade` all come here,
//! through [`candidate::Session`](crate::candidate::Session)). What it does, for a reader who
//! runs it: `docs/sandbox.md`.
//!
//! # What it promises
//! - **Never as root.** Untrusted code never runs as uid 0. A root harness gives every
//!   [`Sandbox`] an unprivileged uid and gid of its own ([`identity`]: `2^30 + ...`, no `passwd`
//!   entry needed), so no submission can signal, trace or read another's files; a harness that is
//!   not root runs the code as its own (unprivileged) user. When no unprivileged identity can be
//!   used, [`Sandbox::new`] fails ([`SandboxError::Unavailable`]): `grade` exits 2, and so do
//!   `check` and `fuzz` unless `--unsandboxed` asks to run one's own code without a sandbox
//!   ([`Isolation::Unsandboxed`], which the facts and the output then say).
//! - **A real sandbox where one can be made: bubblewrap** ([`Isolation::Bubblewrap`]). bubblewrap
//!   is probed once per process (it fails in containers that refuse user namespaces). The code
//!   runs in new user, PID, mount, IPC, network, UTS (and cgroup, where allowed) namespaces, with
//!   `--die-with-parent`, `--new-session`, `--disable-userns`, `--cap-drop ALL`, a cleared
//!   environment and a minimal read-only view ([`bwrap`]): the system's `/usr` and `/lib*`, the
//!   loader's `/etc` files, a read-only `/dev`, the sandbox folder at `/sandbox` (its `.tmp` is
//!   the code's `/tmp`: [`scratch`]), and
//!   for an `--adapter` its program's and its files' folders. Nothing of the grader is visible:
//!   not its binary, the rubric, the vectors, the reports, the batch folder, another submission,
//!   `/root` or `/home`. bubblewrap itself runs as the submission's uid (the switch happens before
//!   it is executed), so even outside its user namespace the code is that uid.
//! - **A fallback where no namespace can be made** ([`Isolation::FallbackUid`], root only): the
//!   limits, its own session, the per-submission uid and gid, with the sandbox folder owned by
//!   that uid, mode `0700`, and, each where the kernel allows it (attempted, verified from
//!   `/proc/<pid>/ns`, never assumed): a network namespace, an IPC namespace (System V objects
//!   die with it; they are swept by owner where it cannot be made), and a private mount
//!   namespace whose `/proc` is mounted `hidepid=2` (the code sees only its own processes: not
//!   the grader's command line, which names its binary, rubric and folders), whose grader
//!   binary is covered with `/dev/null` (the code found it in `/proc/*/cmdline` and ran
//!   `rtoracle explain` as an oracle), and where every mount is read-only but the sandbox
//!   folder and the shared folders the watchdog measures and the sweep cleans (`/tmp`,
//!   `/var/tmp`, `/dev/shm`, ...): it could write a classmate's world-writable submission. [`Isolation::CurrentUser`] is the same without the uid
//!   switch and the namespaces, for a harness that is not root. Without namespaces the code can
//!   see the host's world-readable files and processes; bubblewrap is what hides them.
//! - **Limits** in every mode, set with `setrlimit` between `fork` and `exec` (inherited through
//!   bubblewrap): CPU time, address space, open files, file size, no core files, and a process
//!   count (threads included) for a per-submission uid. Under bubblewrap the count holds for any
//!   harness: bubblewrap's first process waits (`--block-fd`) until the harness has set
//!   `RLIMIT_NPROC` on it, which inside its own user namespace counts the sandbox's processes
//!   alone (a harness that is not root gave a fork bomb no limit: 1527 forks in 2 s); where it
//!   cannot be set, that process is killed. File descriptors other than the standard three are
//!   closed. The memory of all the code's processes together is bounded by the watchdog (next).
//! - **Bounded writing and memory, nothing left** ([`scratch`]): a watchdog ends the code once
//!   its files (its folder, its `/tmp`, what a per-submission uid owns in the host's
//!   world-writable folders, and the unlinked files and memfds its processes hold open) pass the
//!   policy's `disk_bytes`, or the resident memory of all its processes together passes
//!   `memory_bytes`; those files (and a uid's System V objects) are swept when the sandbox goes.
//! - **Nothing outlives it.** [`Sandbox::reaper`] ends every process the code started: the PID
//!   namespace dies with bubblewrap (killed with its process group), and a per-submission uid is
//!   swept with [`identity::kill_all`] (double-forked `setsid` sleepers included). Dropping the
//!   sandbox does both and removes its folder; while it exists, the same cleanup is registered
//!   with [`crate::interrupt::on_interrupt`], so Ctrl-C and SIGTERM leave nothing behind.
//! - **Truthful facts** ([`SandboxFacts`]): which isolation was used, the namespaces that were
//!   seen made (bubblewrap's `--info-fd` compared with the harness's own namespaces), the uid,
//!   and `network_isolated` only when verified. [`announce_on_stderr`] makes the first session of
//!   a run say it once on stderr, e.g. `rtoracle: sandbox: bubblewrap (user, pid, net, ipc,
//!   mount, uts namespaces), uid 1073741824 (one per submission)`.
//!
//! `RTORACLE_SANDBOX` forces a mode ([`Mode`]): `bubblewrap` (an error where it does not work),
//! `uid` (the fallback even where bubblewrap works), `none` (as on a host where neither works:
//! a root harness then refuses to run untrusted code), `auto` (the default).
//!
//! # Why bubblewrap
//! It is the established tool for this (Flatpak's sandbox; Debian package `bubblewrap`), small
//! and audited, needs no daemon, no configuration file and no setuid bit (it uses unprivileged
//! user namespaces), and it works as root and as an ordinary user on these machines. The
//! alternatives: nsjail (stronger seccomp policies, but not packaged in Debian 12 and configured
//! through protobuf files), firejail (setuid-root with a large attack surface and a history of
//! privilege escalations), the `landlock` crate (filesystem rules only: no PID or network
//! isolation, and kernel >= 5.13), `hakoniwa` (a young crate re-implementing what bubblewrap
//! does, with far fewer users).

pub mod bwrap;
pub mod identity;
pub mod scratch;

use std::ffi::{CString, OsStr, OsString};
use std::io::Read;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// The `PATH` inside the sandbox (the harness's own `PATH` may lead to a root-only Python).
pub const SANDBOX_PATH: &str = "/usr/local/bin:/usr/bin:/bin";

/// Environment variables passed through when set (older OpenBLAS builds need them on some
/// processors, and numpy loads OpenBLAS).
const PASSED_THROUGH: [&str; 2] = ["OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"];

/// Why a sandbox cannot be made.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SandboxError {
    /// `RTORACLE_SANDBOX` holds an unknown mode.
    #[error("RTORACLE_SANDBOX={0:?} is not one of auto, bubblewrap, uid, none")]
    BadMode(String),
    /// No isolation that keeps untrusted code from running as root can be used here.
    #[error("cannot sandbox untrusted code: {0}")]
    Unavailable(String),
    /// The sandbox folder could not be prepared.
    #[error("preparing the sandbox folder: {0}")]
    Io(String),
}

/// A mode forced with `RTORACLE_SANDBOX` (default [`Mode::Auto`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// bubblewrap where it works, else the fallback.
    Auto,
    /// bubblewrap or nothing.
    Bubblewrap,
    /// The fallback (limits, session, per-submission uid) even where bubblewrap works.
    Uid,
    /// As if neither could be made (a root harness then refuses untrusted code).
    None,
}

impl Mode {
    /// The environment variable.
    pub const ENV: &'static str = "RTORACLE_SANDBOX";

    /// The mode `RTORACLE_SANDBOX` asks for.
    pub fn from_env() -> Result<Mode, SandboxError> {
        match std::env::var(Self::ENV).as_deref() {
            Err(_) | Ok("") | Ok("auto") => Ok(Mode::Auto),
            Ok("bubblewrap") | Ok("bwrap") => Ok(Mode::Bubblewrap),
            Ok("uid") => Ok(Mode::Uid),
            Ok("none") => Ok(Mode::None),
            Ok(other) => Err(SandboxError::BadMode(other.to_string())),
        }
    }
}

/// Which isolation a candidate ran under.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Isolation {
    /// bubblewrap: new namespaces, a minimal read-only view.
    Bubblewrap,
    /// Limits, own session, attempted network, IPC and mount namespaces, a per-submission uid
    /// (root harness).
    FallbackUid,
    /// Limits and own session as the harness's own unprivileged user (no bubblewrap).
    CurrentUser,
    /// Asked for with `--unsandboxed`: limits and own session as the current user, root
    /// included.
    Unsandboxed,
}

impl Isolation {
    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Isolation::Bubblewrap => "bubblewrap",
            Isolation::FallbackUid => "fallback-uid",
            Isolation::CurrentUser => "current-user",
            Isolation::Unsandboxed => "unsandboxed",
        }
    }
}

/// Limits and switches of the sandbox.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SandboxPolicy {
    /// CPU seconds per process (`RLIMIT_CPU`; a restart starts afresh).
    pub cpu_seconds: u64,
    /// Address space of each process in bytes (`RLIMIT_AS`), and the resident memory of all the
    /// code's processes together ([`scratch::Watchdog`]).
    pub memory_bytes: u64,
    /// Open files (`RLIMIT_NOFILE`).
    pub open_files: u64,
    /// Largest file it may write, in bytes (`RLIMIT_FSIZE`).
    pub file_size_bytes: u64,
    /// Processes and threads (`RLIMIT_NPROC`): for a per-submission uid, and inside
    /// bubblewrap's user namespace for any harness (elsewhere it would count every process of
    /// the harness's user).
    pub processes: u64,
    /// Bytes the code may keep in files, its `/tmp` included ([`scratch::Watchdog`]).
    #[serde(default = "default_disk_bytes")]
    pub disk_bytes: u64,
    /// Try a new network namespace in the fallback (bubblewrap always makes one).
    pub isolate_network: bool,
    /// Run without a sandbox, as the current user (root included): `--unsandboxed`, for one's
    /// own code. Limits, the folder and the session still apply.
    #[serde(default)]
    pub unsandboxed: bool,
}

/// [`SandboxPolicy::disk_bytes`] of `check` and `fuzz` (and of reports written before it existed).
fn default_disk_bytes() -> u64 {
    256 << 20
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
            disk_bytes: default_disk_bytes(),
            isolate_network: true,
            unsandboxed: false,
        }
    }
}

impl SandboxPolicy {
    /// The tighter limits of `grade`: 30 CPU seconds, 1 GiB, 16 MiB files, 64 MiB of files in
    /// all.
    pub fn grading() -> Self {
        SandboxPolicy {
            cpu_seconds: 30,
            memory_bytes: 1 << 30,
            file_size_bytes: 16 << 20,
            disk_bytes: 64 << 20,
            ..SandboxPolicy::default()
        }
    }
}

/// What the sandbox did, for the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SandboxFacts {
    /// The policy.
    pub policy: SandboxPolicy,
    /// Which isolation was used.
    pub isolation: Isolation,
    /// The namespaces the candidate was seen in that differ from the harness's (`user`, `pid`,
    /// `net`, `ipc`, `mount`, `uts`), as verified after it started; empty when not looked at. In
    /// the fallback, `mount` is listed only when its `/proc` was also seen mounted `hidepid`.
    #[serde(default)]
    pub namespaces: Vec<String>,
    /// The user id the code ran as, seen from outside any user namespace.
    pub uid: u32,
    /// A remark for the reader (why this isolation and not a stronger one).
    pub note: Option<String>,
    /// Whether the candidate was seen in a network namespace of its own (`None`: not verified).
    pub network_isolated: Option<bool>,
    /// Files of the submission not copied into the sandbox, each named (control characters
    /// escaped) with why: links, FIFOs, devices, files over the size caps.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped_files: Vec<String>,
}

impl SandboxFacts {
    /// One line for stderr: `bubblewrap (user, pid, net, ... namespaces), uid N`.
    pub fn summary(&self) -> String {
        let ns = if self.namespaces.is_empty() {
            "no namespaces verified".to_string()
        } else {
            format!("{} namespaces", self.namespaces.join(", "))
        };
        let mut line = match self.isolation {
            Isolation::Bubblewrap => format!("bubblewrap ({ns}), uid {}", self.uid),
            Isolation::FallbackUid => {
                let mut parts = vec!["limits".to_string(), "own session".to_string()];
                if self.network_isolated != Some(true) {
                    parts.push("network NOT isolated".into());
                }
                if !self.namespaces.is_empty() {
                    parts.push(format!("{} namespaces", self.namespaces.join(", ")));
                }
                if self.namespaces.iter().any(|n| n == "mount") {
                    parts.push("/proc shows only its processes".into());
                    parts.push("read-only but its folder and /tmp".into());
                }
                format!("fallback-uid ({}), uid {}", parts.join(", "), self.uid)
            }
            Isolation::CurrentUser => format!(
                "current-user (limits, own session, no namespaces), uid {}",
                self.uid
            ),
            Isolation::Unsandboxed => format!(
                "UNSANDBOXED by request (--unsandboxed): limits only, uid {}",
                self.uid
            ),
        };
        if let Some(note) = self
            .note
            .as_ref()
            .filter(|_| self.isolation != Isolation::Unsandboxed)
        {
            line.push_str("; ");
            line.push_str(note);
        }
        line
    }
}

static ANNOUNCE: AtomicBool = AtomicBool::new(false);
static ANNOUNCED: AtomicBool = AtomicBool::new(false);

/// Makes the first sandbox of this process that starts a candidate say which isolation it
/// used, once, on stderr (the binary calls this; a library user stays quiet).
pub fn announce_on_stderr() {
    ANNOUNCE.store(true, Ordering::SeqCst);
}

/// Prints `facts` once per process when [`announce_on_stderr`] was called.
pub fn announce(facts: &SandboxFacts) {
    if ANNOUNCE.load(Ordering::SeqCst) && !ANNOUNCED.swap(true, Ordering::SeqCst) {
        let per = if facts.isolation != Isolation::Unsandboxed && running_as_root() {
            " (a uid of its own per candidate)"
        } else {
            ""
        };
        crate::output::stderr_line(&format!(
            "rtoracle: sandbox: {}{per}",
            crate::escape::terminal_line(&facts.summary())
        ));
    }
}

/// Whether this process runs as root.
pub fn running_as_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
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

/// Whether bubblewrap works here, probed once per process (as the identity it would run as):
/// `Err` says why not.
pub fn bubblewrap_works() -> Result<(), String> {
    static PROBE: OnceLock<Result<(), String>> = OnceLock::new();
    PROBE
        .get_or_init(|| {
            let Some(_) = bwrap::program() else {
                return Err("bwrap is not installed (apt-get install bubblewrap)".into());
            };
            let sandbox =
                Sandbox::with_isolation(SandboxPolicy::default(), Isolation::Bubblewrap, &[], None)
                    .map_err(|e| e.to_string())?;
            let out = sandbox
                .command(Path::new("true"))
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .output()
                .map_err(|e| format!("bwrap: {e}"))?;
            if out.status.success() {
                Ok(())
            } else {
                let why = String::from_utf8_lossy(&out.stderr);
                Err(format!(
                    "bwrap fails here ({})",
                    why.lines().next().unwrap_or("no message").trim()
                ))
            }
        })
        .clone()
}

/// Whether a root harness can switch to an unused uid (a container may forbid `setuid`).
fn can_switch_uid() -> Result<(), String> {
    static PROBE: OnceLock<Result<(), String>> = OnceLock::new();
    PROBE
        .get_or_init(|| {
            let uid = identity::allocate();
            let status = Command::new("/bin/true")
                .uid(uid)
                .gid(uid)
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status();
            match status {
                Ok(s) if s.success() => Ok(()),
                Ok(s) => Err(format!("a process switched to uid {uid} failed ({s})")),
                Err(e) => Err(format!("cannot switch to uid {uid}: {e}")),
            }
        })
        .clone()
}

/// The isolation a sandbox made under `policy` gets here, or why none may be used.
pub fn isolation_for(policy: &SandboxPolicy) -> Result<Isolation, SandboxError> {
    if policy.unsandboxed {
        return Ok(Isolation::Unsandboxed);
    }
    let mode = Mode::from_env()?;
    let root = running_as_root();
    let fallback = |why: String| -> Result<Isolation, SandboxError> {
        if !root {
            return Ok(Isolation::CurrentUser);
        }
        can_switch_uid().map_err(|e| {
            SandboxError::Unavailable(format!(
                "{why}, and no unprivileged identity can be used ({e}); untrusted code never runs as root"
            ))
        })?;
        Ok(Isolation::FallbackUid)
    };
    match mode {
        Mode::Auto => match bubblewrap_works() {
            Ok(()) => Ok(Isolation::Bubblewrap),
            Err(why) => fallback(why),
        },
        Mode::Bubblewrap => bubblewrap_works()
            .map(|()| Isolation::Bubblewrap)
            .map_err(|why| {
                SandboxError::Unavailable(format!("RTORACLE_SANDBOX=bubblewrap: {why}"))
            }),
        Mode::Uid => fallback("RTORACLE_SANDBOX=uid".into()),
        Mode::None if root => Err(SandboxError::Unavailable(
            "RTORACLE_SANDBOX=none: no sandbox may be made, and untrusted code never runs as root"
                .into(),
        )),
        Mode::None => Ok(Isolation::CurrentUser),
    }
}

/// Ends what a sandbox's code started: its process groups and, for a per-submission uid, every
/// process of that uid. Cheap to clone; usable after the sandbox is gone.
#[derive(Clone, Debug)]
pub struct Reaper {
    uid: Option<u32>,
    groups: Arc<Mutex<Vec<i32>>>,
}

impl Reaper {
    /// Kills every process group spawned so far and every process of the uid.
    pub fn reap(&self) {
        let groups = self.groups.lock().map(|g| g.clone()).unwrap_or_default();
        for pgid in groups {
            // SAFETY: plain system call; a group that is gone gives ESRCH.
            unsafe {
                libc::killpg(pgid, libc::SIGKILL);
            }
        }
        if let Some(uid) = self.uid {
            identity::kill_all(uid);
        }
    }

    /// Records a spawned child (the leader of its own process group).
    pub fn track(&self, pid: u32) {
        if let Ok(mut g) = self.groups.lock() {
            g.push(pid as i32);
        }
    }

    /// Forgets a child once it is reaped (its pid may be reused: never signal it again).
    pub fn untrack(&self, pid: u32) {
        if let Ok(mut g) = self.groups.lock() {
            g.retain(|&p| p != pid as i32);
        }
    }
}

/// A prepared sandbox: a temporary folder holding copies of the files, the policy, the
/// isolation and the identity the code runs as.
#[derive(Debug)]
pub struct Sandbox {
    policy: SandboxPolicy,
    isolation: Isolation,
    dir: Option<tempfile::TempDir>,
    /// `(uid, gid)` to switch to (a per-submission id of a root harness).
    switch_to: Option<(u32, u32)>,
    /// Paths shown read-only inside bubblewrap besides the system view.
    exposed: Vec<PathBuf>,
    /// What bubblewrap reports (`--info-fd`) for the last command, filled by its admission.
    info: Mutex<Option<Arc<InfoSlot>>>,
    /// The PID namespaces of the bubblewrap sandboxes started so far (their processes are the
    /// code's, for the watchdog).
    pid_namespaces: Arc<Mutex<Vec<u64>>>,
    reaper: Reaper,
    note: Option<String>,
    skipped: Vec<String>,
    /// Measures what the code writes (dropped, and so stopped, before the folder is removed).
    watchdog: Option<scratch::Watchdog>,
    _cleanup: crate::interrupt::CleanupGuard,
}

/// What bubblewrap's `--info-fd` said for one command, once its admission has read it.
#[derive(Debug, Default)]
struct InfoSlot {
    text: Mutex<Option<String>>,
    ready: std::sync::Condvar,
}

impl InfoSlot {
    fn set(&self, text: String) {
        *self.text.lock().unwrap_or_else(|e| e.into_inner()) = Some(text);
        self.ready.notify_all();
    }

    /// The text, waiting up to `timeout` for it (empty when it does not come).
    fn wait(&self, timeout: Duration) -> String {
        let guard = self.text.lock().unwrap_or_else(|e| e.into_inner());
        let (guard, _) = self
            .ready
            .wait_timeout_while(guard, timeout, |t| t.is_none())
            .unwrap_or_else(|e| e.into_inner());
        guard.clone().unwrap_or_default()
    }
}

/// Lets a bubblewrap sandbox's first process go on, once it has its limits: reads what
/// bubblewrap reports (`--info-fd`: the first process's pid and its namespaces), records its PID
/// namespace, sets `RLIMIT_NPROC` to `processes` on that process when asked (`Some`: a harness
/// that is not root, whose user the limit cannot be set for before bubblewrap, since it would
/// count all of that user's processes; inside the sandbox's own user namespace it counts the
/// sandbox's alone), and only then writes to its `--block-fd`. Where the limit cannot be set the
/// process is killed (fail closed). A per-submission uid got the limit before bubblewrap (its
/// processes are the sandbox's alone), and a root harness may lack `CAP_SYS_RESOURCE` (Docker
/// drops it) to set another uid's.
fn admit(
    info: OwnedFd,
    block: OwnedFd,
    slot: Arc<InfoSlot>,
    processes: Option<u64>,
    namespaces: Arc<Mutex<Vec<u64>>>,
) {
    let text = read_with_timeout(info, Duration::from_secs(10));
    let value: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    let child = value["child-pid"]
        .as_u64()
        .and_then(|p| libc::pid_t::try_from(p).ok());
    if let Some(ns) = value["pid-namespace"].as_u64()
        && let Ok(mut list) = namespaces.lock()
    {
        list.push(ns);
    }
    if let Some(pid) = child {
        // SAFETY: plain system calls on a process bubblewrap just made and holds waiting.
        unsafe {
            let limited = processes.is_none_or(|n| {
                let rl = libc::rlimit {
                    rlim_cur: n as libc::rlim_t,
                    rlim_max: n as libc::rlim_t,
                };
                libc::prlimit(pid, libc::RLIMIT_NPROC, &rl, std::ptr::null_mut()) == 0
            });
            if limited {
                libc::write(block.as_raw_fd(), b"x".as_ptr().cast(), 1);
            } else {
                libc::kill(pid, libc::SIGKILL);
            }
        }
    }
    slot.set(text);
}

/// A pipe whose both ends close on exec (the child's end is made inheritable in `pre_exec`).
fn cloexec_pipe() -> std::io::Result<(OwnedFd, OwnedFd)> {
    let mut fds = [0; 2];
    // SAFETY: pipe2 writes two fds into the array on success.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: both fds are fresh and owned by nobody else.
    Ok(unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) })
}

/// Most bytes copied of one file into a sandbox folder.
pub const MAX_COPIED_FILE_BYTES: u64 = 1 << 20;

/// Copies a regular file without following a link and without blocking on a FIFO (opened
/// `O_NOFOLLOW | O_NONBLOCK`, checked regular after opening, so a swap after the caller's check
/// cannot make it block), at most [`MAX_COPIED_FILE_BYTES`].
fn copy_regular(source: &Path, target: &Path) -> std::io::Result<()> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(source)?;
    if !file.metadata()?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let mut out = std::fs::File::create(target)?;
    std::io::copy(&mut file.take(MAX_COPIED_FILE_BYTES), &mut out)?;
    Ok(())
}

/// Removes a folder the code may have made hard to remove (read-only subfolders, thousands of
/// levels deep: [`scratch::remove_deep`]).
fn remove_tree(path: &Path) {
    if std::fs::remove_dir_all(path).is_ok() || !path.exists() || scratch::remove_deep(path) {
        return;
    }
    fn open_up(p: &Path) {
        let _ = std::fs::set_permissions(p, std::fs::Permissions::from_mode(0o700));
        if let Ok(entries) = std::fs::read_dir(p) {
            for e in entries.flatten() {
                if e.file_type().map(|t| t.is_dir()).unwrap_or(false) {
                    open_up(&e.path());
                }
            }
        }
    }
    open_up(path);
    let _ = std::fs::remove_dir_all(path);
}

impl Sandbox {
    /// Makes the temporary folder and copies `files` (`(source, name in the folder)`) into it,
    /// with the isolation [`isolation_for`] gives; fails closed.
    pub fn new(
        policy: SandboxPolicy,
        files: &[(PathBuf, String)],
    ) -> Result<Sandbox, SandboxError> {
        let isolation = isolation_for(&policy)?;
        let note = match isolation {
            Isolation::FallbackUid | Isolation::CurrentUser => bubblewrap_works().err(),
            _ => None,
        };
        Sandbox::with_isolation(policy, isolation, files, note)
    }

    fn with_isolation(
        policy: SandboxPolicy,
        isolation: Isolation,
        files: &[(PathBuf, String)],
        note: Option<String>,
    ) -> Result<Sandbox, SandboxError> {
        let io = |e: std::io::Error| SandboxError::Io(e.to_string());
        let dir = tempfile::Builder::new()
            .prefix("rtoracle-sandbox-")
            .tempdir()
            .map_err(io)?;
        let switch_to = match isolation {
            Isolation::Bubblewrap | Isolation::FallbackUid if running_as_root() => {
                let id = identity::allocate();
                Some((id, id))
            }
            _ => None,
        };
        for (source, name) in files {
            let target = dir.path().join(name);
            copy_regular(source, &target)
                .map_err(|e| SandboxError::Io(format!("{}: {e}", source.display())))?;
            std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o644))
                .map_err(io)?;
        }
        let tmp = dir.path().join(scratch::TMP_DIR);
        std::fs::create_dir(&tmp).map_err(io)?;
        for folder in [&tmp, &dir.path().to_path_buf()] {
            std::fs::set_permissions(folder, std::fs::Permissions::from_mode(0o700)).map_err(io)?;
            if let Some((uid, gid)) = switch_to {
                std::os::unix::fs::chown(folder, Some(uid), Some(gid)).map_err(io)?;
            }
        }
        let reaper = Reaper {
            uid: switch_to.map(|s| s.0),
            groups: Arc::new(Mutex::new(Vec::new())),
        };
        let cleanup = {
            let reaper = reaper.clone();
            let path = dir.path().to_path_buf();
            crate::interrupt::on_interrupt(move || {
                reaper.reap();
                if let Some(uid) = reaper.uid {
                    scratch::sweep(uid);
                    scratch::sweep_ipc(uid);
                }
                remove_tree(&path);
            })
        };
        let pid_namespaces = Arc::new(Mutex::new(Vec::new()));
        let members = match (reaper.uid, isolation) {
            (Some(uid), _) => scratch::Members::Uid(uid),
            (None, Isolation::Bubblewrap) => {
                scratch::Members::PidNamespaces(pid_namespaces.clone())
            }
            (None, _) => scratch::Members::Sessions(reaper.groups.clone()),
        };
        let watchdog = scratch::Watchdog::start(
            dir.path().to_path_buf(),
            members,
            scratch::Limits {
                disk_bytes: policy.disk_bytes,
                memory_bytes: policy.memory_bytes,
            },
            reaper.clone(),
        );
        Ok(Sandbox {
            policy,
            isolation,
            dir: Some(dir),
            switch_to,
            exposed: Vec::new(),
            info: Mutex::new(None),
            pid_namespaces,
            reaper,
            note,
            skipped: Vec::new(),
            watchdog: Some(watchdog),
            _cleanup: cleanup,
        })
    }

    /// The temporary folder the code runs in, as the harness sees it.
    pub fn dir(&self) -> &Path {
        self.dir
            .as_ref()
            .expect("the folder lives as long as the sandbox")
            .path()
    }

    /// The folder as the code sees it (`/sandbox` under bubblewrap).
    pub fn inside_dir(&self) -> PathBuf {
        match self.isolation {
            Isolation::Bubblewrap => PathBuf::from(bwrap::INSIDE),
            _ => self.dir().to_path_buf(),
        }
    }

    /// The policy.
    pub fn policy(&self) -> &SandboxPolicy {
        &self.policy
    }

    /// The isolation in use.
    pub fn isolation(&self) -> Isolation {
        self.isolation
    }

    /// The uid the code runs as (seen from outside).
    pub fn uid(&self) -> u32 {
        // SAFETY: getuid has no preconditions.
        self.switch_to
            .map_or_else(|| unsafe { libc::getuid() }, |s| s.0)
    }

    /// Whether the code runs as a uid of its own (a root harness).
    pub fn drops_user(&self) -> bool {
        self.switch_to.is_some()
    }

    /// Why the code was stopped for what it wrote ([`scratch::Watchdog`]), if it was: then
    /// nothing more should be started in this sandbox.
    pub fn violation(&self) -> Option<String> {
        self.watchdog
            .as_ref()
            .and_then(scratch::Watchdog::violation)
    }

    /// What ends the code's processes (for a restart or the end of a session).
    pub fn reaper(&self) -> Reaper {
        self.reaper.clone()
    }

    /// Writes an extra file (such as an adapter script) into the folder, readable by all.
    pub fn add_file(&self, name: &str, contents: &[u8]) -> std::io::Result<PathBuf> {
        let path = self.dir().join(name);
        std::fs::write(&path, contents)?;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644))?;
        Ok(path)
    }

    /// Records the files of the submission that were not copied in, each named (escaped) with
    /// why, for the facts.
    pub fn set_skipped(&mut self, skipped: Vec<String>) {
        self.skipped = skipped;
    }

    /// Shows `path` read-only inside bubblewrap (see [`bwrap::exposure`]: its folder, or the
    /// file alone in a shared folder). Other modes see the host anyway.
    pub fn expose(&mut self, path: &Path) {
        for p in bwrap::exposure(path) {
            if !self.exposed.contains(&p) {
                self.exposed.push(p);
            }
        }
    }

    /// The environment of the code.
    fn env(&self) -> Vec<(&'static str, OsString)> {
        let inside = self.inside_dir().into_os_string();
        let tmp: OsString = match self.isolation {
            Isolation::Bubblewrap => "/tmp".into(),
            _ => inside.clone(),
        };
        let path: OsString = match self.isolation {
            Isolation::Unsandboxed => {
                std::env::var_os("PATH").unwrap_or_else(|| SANDBOX_PATH.into())
            }
            _ => SANDBOX_PATH.into(),
        };
        let mut env = vec![
            ("PATH", path),
            ("HOME", inside),
            ("TMPDIR", tmp),
            ("LANG", "C.UTF-8".into()),
            ("LC_ALL", "C.UTF-8".into()),
            ("PYTHONDONTWRITEBYTECODE", "1".into()),
            ("PYTHONHASHSEED", "0".into()),
            ("PYTHONIOENCODING", "utf-8".into()),
            ("PYTHONNOUSERSITE", "1".into()),
            ("PYTHONUNBUFFERED", "1".into()),
        ];
        for k in PASSED_THROUGH {
            if let Some(v) = std::env::var_os(k) {
                env.push((k, v));
            }
        }
        env
    }

    /// A command for `program` that runs inside the sandbox: under bubblewrap (`bwrap ...
    /// program`) or directly, with the folder as working directory, a cleared environment, its
    /// own session and process group, the limits and the identity. A bare program name is looked
    /// up on [`SANDBOX_PATH`] (the harness's `PATH` when unsandboxed).
    pub fn command(&self, program: &Path) -> Command {
        let env = self.env();
        let mut info_child: Option<i32> = None;
        let mut args_child: Option<i32> = None;
        let mut block_child: Option<i32> = None;
        let mut cmd = match self.isolation {
            Isolation::Bubblewrap => {
                let bwrap = bwrap::program().unwrap_or_else(|| PathBuf::from("/usr/bin/bwrap"));
                let mut cmd = Command::new(bwrap);
                let mut exposed = self.exposed.clone();
                for p in bwrap::exposure(program) {
                    if !exposed.contains(&p) {
                        exposed.push(p);
                    }
                }
                let (uid, gid) = self.switch_to.unwrap_or_else(|| {
                    // SAFETY: getuid and getgid have no preconditions.
                    unsafe { (libc::getuid(), libc::getgid()) }
                });
                // bubblewrap reports on one pipe and waits on another until the admission
                // thread has set the limits of its first process (see `admit`).
                let mut info_write = None;
                let mut block_read = None;
                if let (Ok((info_read, write)), Ok((read, block_write))) =
                    (cloexec_pipe(), cloexec_pipe())
                {
                    info_child = Some(write.as_raw_fd());
                    block_child = Some(read.as_raw_fd());
                    let slot = Arc::new(InfoSlot::default());
                    *self.info.lock().unwrap_or_else(|e| e.into_inner()) = Some(slot.clone());
                    let processes = self.switch_to.is_none().then_some(self.policy.processes);
                    let namespaces = self.pid_namespaces.clone();
                    let admission = std::thread::Builder::new()
                        .name("sandbox-admit".into())
                        .spawn(move || admit(info_read, block_write, slot, processes, namespaces));
                    if admission.is_ok() {
                        info_write = Some(write);
                        block_read = Some(read);
                    } else {
                        (info_child, block_child) = (None, None);
                    }
                }
                let words = bwrap::args(
                    self.dir(),
                    uid,
                    gid,
                    &exposed,
                    &env,
                    info_child,
                    block_child,
                );
                // The options go through a pipe (`--args FD`), so the sandbox's `/proc/1/cmdline`
                // shows none of the host's paths.
                let mut args_read = None;
                if let Ok((read, write)) = cloexec_pipe() {
                    let mut bytes = Vec::new();
                    for w in &words {
                        bytes.extend_from_slice(w.as_encoded_bytes());
                        bytes.push(0);
                    }
                    // Far below a pipe's 64 KiB buffer, so this never blocks.
                    if bytes.len() < 60_000 {
                        let mut file = std::fs::File::from(write);
                        if std::io::Write::write_all(&mut file, &bytes).is_ok() {
                            args_child = Some(read.as_raw_fd());
                            args_read = Some(read);
                        }
                    }
                }
                match args_child {
                    Some(fd) => {
                        cmd.arg("--args").arg(fd.to_string());
                    }
                    None => {
                        cmd.args(&words);
                    }
                }
                // The closure owns the parent's copies of the pipes' child ends, so they close
                // when the command is dropped after the spawn. Without the admission's pipes
                // the processes could not be limited: the command then fails (fail closed).
                // SAFETY: the closure makes no system call.
                unsafe {
                    cmd.pre_exec(move || {
                        let _ = (&info_write, &args_read);
                        match block_read {
                            Some(_) => Ok(()),
                            None => Err(std::io::Error::other(
                                "no pipe to admit the sandbox's first process",
                            )),
                        }
                    });
                }
                cmd.arg(program);
                cmd.current_dir("/").env_clear().env("PATH", SANDBOX_PATH);
                cmd
            }
            _ => {
                let mut cmd = Command::new(program);
                cmd.current_dir(self.dir()).env_clear();
                for (k, v) in &env {
                    cmd.env(k, v);
                }
                cmd
            }
        };
        let policy = self.policy.clone();
        let switch_to = self.switch_to;
        let fallback = self.isolation == Isolation::FallbackUid;
        let unshare_net = fallback && policy.isolate_network;
        // The fallback's own view where a mount namespace can be made: a `/proc` that shows
        // only the code's processes (`hidepid=2`), and the grader's binary as an empty file.
        let hide_exe = std::env::current_exe()
            .ok()
            .and_then(|p| CString::new(p.into_os_string().into_encoded_bytes()).ok());
        // ... and the host read-only but the sandbox folder and the shared folders (`/tmp`, ...:
        // where the watchdog measures and the sweep cleans what the uid writes).
        let mut writable: Vec<CString> = scratch::SHARED_ROOTS
            .iter()
            .filter(|r| Path::new(r).is_dir())
            .filter_map(|r| CString::new(*r).ok())
            .collect();
        let own_dir = CString::new(self.dir().as_os_str().as_encoded_bytes()).ok();
        if let Some(dir) = &own_dir
            && !scratch::SHARED_ROOTS
                .iter()
                .any(|r| self.dir().starts_with(r))
        {
            writable.push(dir.clone());
        }
        let parent = std::process::id() as libc::pid_t;
        // SAFETY: the closure only makes async-signal-safe system calls (setsid, unshare, mount,
        // setrlimit, setgroups, setgid, setuid, prctl, getppid, fcntl, close_range) and
        // allocates nothing (the paths it mounts are made before the fork).
        unsafe {
            cmd.pre_exec(move || {
                if libc::setsid() < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                // Every inherited descriptor but 0, 1, 2 (and bubblewrap's info pipe) closes on
                // exec: a descriptor the harness inherited must not reach the code.
                libc::syscall(
                    libc::SYS_close_range,
                    3u32,
                    u32::MAX,
                    libc::CLOSE_RANGE_CLOEXEC,
                );
                for fd in [info_child, args_child, block_child].into_iter().flatten() {
                    libc::fcntl(fd, libc::F_SETFD, 0);
                }
                #[cfg(target_os = "linux")]
                if unshare_net {
                    // Best effort: fails without CAP_SYS_ADMIN, which the facts show.
                    let _ = libc::unshare(libc::CLONE_NEWNET);
                }
                #[cfg(target_os = "linux")]
                if fallback {
                    // Best effort too, verified by the facts: an IPC namespace (System V objects
                    // die with it), and a mount namespace whose mounts never reach the host's
                    // (made private first, or nothing is mounted).
                    let _ = libc::unshare(libc::CLONE_NEWIPC);
                    let null = std::ptr::null::<libc::c_char>();
                    if libc::unshare(libc::CLONE_NEWNS) == 0
                        && libc::mount(
                            null,
                            c"/".as_ptr(),
                            null,
                            libc::MS_REC | libc::MS_PRIVATE,
                            std::ptr::null(),
                        ) == 0
                    {
                        libc::mount(
                            c"proc".as_ptr(),
                            c"/proc".as_ptr(),
                            c"proc".as_ptr(),
                            libc::MS_NOSUID | libc::MS_NODEV | libc::MS_NOEXEC,
                            c"hidepid=2".as_ptr().cast(),
                        );
                        if let Some(exe) = &hide_exe {
                            libc::mount(
                                c"/dev/null".as_ptr(),
                                exe.as_ptr(),
                                null,
                                libc::MS_BIND,
                                std::ptr::null(),
                            );
                        }
                        // Every mount read-only (`mount_setattr`, Linux 5.12), then the folder and
                        // the shared folders writable again at their own paths, and the working
                        // directory moved onto those mounts.
                        const MOUNT_ATTR_RDONLY: u64 = 1;
                        let attr: [u64; 4] = [MOUNT_ATTR_RDONLY, 0, 0, 0];
                        if let Some(dir) = &own_dir
                            && libc::syscall(
                                libc::SYS_mount_setattr,
                                libc::AT_FDCWD,
                                c"/".as_ptr(),
                                libc::AT_RECURSIVE as libc::c_uint,
                                attr.as_ptr(),
                                std::mem::size_of_val(&attr),
                            ) == 0
                        {
                            for path in &writable {
                                let p = path.as_ptr();
                                let bound = libc::mount(
                                    p,
                                    p,
                                    null,
                                    libc::MS_BIND | libc::MS_REC,
                                    std::ptr::null(),
                                );
                                if bound == 0 {
                                    libc::mount(
                                        null,
                                        p,
                                        null,
                                        libc::MS_REMOUNT
                                            | libc::MS_BIND
                                            | libc::MS_NOSUID
                                            | libc::MS_NODEV,
                                        std::ptr::null(),
                                    );
                                }
                            }
                            libc::chdir(dir.as_ptr());
                        }
                    }
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
                if let Some((uid, gid)) = switch_to {
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

    /// Runs `program args` in the sandbox with `timeout`, never untrusted code: for probes such
    /// as an interpreter's. Returns the exit status's success and stdout, or why it did not run.
    pub fn probe_output(
        &self,
        program: &Path,
        args: &[&OsStr],
        timeout: Duration,
    ) -> Result<(bool, String, String), String> {
        // Started and recorded under the gate, so an interruption's cleanup finds it.
        let gate = crate::interrupt::spawn_gate().ok_or_else(|| "interrupted".to_string())?;
        let mut child = self
            .command(program)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("{}: {e}", program.display()))?;
        self.reaper.track(child.id());
        drop(gate);
        let out = child.stdout.take();
        let err = child.stderr.take();
        let read = |s: Option<std::process::ChildStdout>| {
            std::thread::spawn(move || {
                let mut text = String::new();
                if let Some(s) = s {
                    let _ = s.take(1 << 16).read_to_string(&mut text);
                }
                text
            })
        };
        let out = read(out);
        let err = std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(s) = err {
                let _ = s.take(1 << 16).read_to_string(&mut text);
            }
            text
        });
        let deadline = Instant::now() + timeout;
        let status = loop {
            match child.try_wait() {
                Ok(Some(s)) => break Some(s),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2))
                }
                _ => break None,
            }
        };
        let Some(status) = status else {
            self.reaper.reap();
            kill_group(&mut child);
            self.reaper.untrack(child.id());
            return Err(format!(
                "{} did not finish within {:.0} s",
                program.display(),
                timeout.as_secs_f64()
            ));
        };
        self.reaper.untrack(child.id());
        self.reaper.reap();
        let out = out.join().unwrap_or_default();
        let err = err.join().unwrap_or_default();
        Ok((status.success(), out, err))
    }

    /// For a program that cannot be probed by running it (an adapter command): checks, inside
    /// the sandbox and as its user, that `program` is executable and every argument naming an
    /// existing absolute path is readable; `Err` names what is not.
    pub fn probe_access(&self, program: &Path, args: &[OsString]) -> Result<(), String> {
        let files: Vec<&OsString> = args
            .iter()
            .filter(|a| Path::new(a).is_absolute() && Path::new(a).exists())
            .collect();
        let script = r#"p=$1; shift
case $p in */*) [ -x "$p" ] || { echo "$p"; exit 1; } ;; *) command -v "$p" >/dev/null || { echo "$p"; exit 1; } ;; esac
for f; do [ -r "$f" ] || { echo "$f"; exit 1; }; done"#;
        let mut words: Vec<&OsStr> = vec![OsStr::new("-c"), OsStr::new(script), OsStr::new("sh")];
        words.push(program.as_os_str());
        words.extend(files.iter().map(|f| f.as_os_str()));
        match self.probe_output(Path::new("/bin/sh"), &words, Duration::from_secs(10)) {
            Ok((true, _, _)) => Ok(()),
            Ok((false, out, err)) => {
                let what = out.trim();
                let what = if what.is_empty() { err.trim() } else { what };
                Err(format!(
                    "the sandbox user (uid {}) cannot run or read {what}: make it readable by all, \
                     or pass --unsandboxed to run your own code without a sandbox",
                    self.uid()
                ))
            }
            Err(e) => Err(e),
        }
    }

    /// The facts of a run, given the id of a child spawned from [`Sandbox::command`]: under
    /// bubblewrap, the namespaces it reports (waiting up to 2 s for its `--info-fd`); in the
    /// fallback, whether the child is in a network namespace of its own.
    pub fn facts(&self, child: Option<u32>) -> SandboxFacts {
        let own_net = std::fs::read_link("/proc/self/ns/net").ok();
        let mut namespaces = Vec::new();
        let mut network_isolated = None;
        match (self.isolation, child) {
            (Isolation::Bubblewrap, Some(_)) => {
                let slot = self.info.lock().unwrap_or_else(|e| e.into_inner()).take();
                if let Some(slot) = slot {
                    let text = slot.wait(Duration::from_secs(2));
                    namespaces = bwrap::made_namespaces(&text).0;
                    network_isolated = Some(namespaces.iter().any(|n| n == "net"));
                }
            }
            (_, Some(pid)) => {
                let theirs = std::fs::read_link(format!("/proc/{pid}/ns/net")).ok();
                if let (Some(mine), Some(theirs)) = (own_net, theirs) {
                    network_isolated = Some(mine != theirs);
                    if mine != theirs {
                        namespaces.push("net".into());
                    }
                }
                if self.isolation == Isolation::FallbackUid {
                    namespaces.extend(fallback_namespaces(pid));
                }
            }
            _ => {}
        }
        let note = match self.isolation {
            Isolation::Unsandboxed => Some(format!(
                "unsandboxed by request (--unsandboxed): the candidate ran as uid {} with limits only",
                self.uid()
            )),
            _ => self.note.clone(),
        };
        SandboxFacts {
            policy: self.policy.clone(),
            isolation: self.isolation,
            namespaces,
            uid: self.uid(),
            note,
            network_isolated,
            skipped_files: self.skipped.clone(),
        }
    }
}

/// The IPC and mount namespaces a fallback's process `pid` was seen in, when they differ from
/// the harness's: `mount` only when its `/proc` is also seen mounted with `hidepid` and its `/`
/// read-only (what the mount namespace is for).
fn fallback_namespaces(pid: u32) -> Vec<String> {
    let differs = |ns: &str| {
        let mine = std::fs::read_link(format!("/proc/self/ns/{ns}")).ok();
        let theirs = std::fs::read_link(format!("/proc/{pid}/ns/{ns}")).ok();
        mine.is_some() && theirs.is_some() && mine != theirs
    };
    let mut made = Vec::new();
    if differs("ipc") {
        made.push("ipc".to_string());
    }
    let mountinfo = std::fs::read_to_string(format!("/proc/{pid}/mountinfo")).unwrap_or_default();
    // The last mount at a point is the one seen there; field 5 is the point, 6 its options.
    let at = |point: &str| {
        mountinfo
            .lines()
            .rfind(|l| l.split(' ').nth(4) == Some(point))
            .unwrap_or_default()
            .to_string()
    };
    let proc_line = at("/proc");
    let hidden = proc_line.contains(" - proc ") && proc_line.contains("hidepid=");
    let read_only = at("/")
        .split(' ')
        .nth(5)
        .is_some_and(|o| o.split(',').any(|w| w == "ro"));
    if differs("mnt") && hidden && read_only {
        made.push("mount".to_string());
    }
    made
}

/// Reads a pipe to its end or until `timeout`, at most 64 KiB.
fn read_with_timeout(fd: OwnedFd, timeout: Duration) -> String {
    let deadline = Instant::now() + timeout;
    let mut bytes = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() || bytes.len() > 1 << 16 {
            break;
        }
        let mut pfd = libc::pollfd {
            fd: fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd.
        let ready = unsafe { libc::poll(&mut pfd, 1, left.as_millis().min(2000) as i32) };
        if ready <= 0 {
            break;
        }
        // SAFETY: reading into a local buffer of its length.
        let n = unsafe { libc::read(fd.as_raw_fd(), buf.as_mut_ptr().cast(), buf.len()) };
        if n <= 0 {
            break;
        }
        bytes.extend_from_slice(&buf[..n as usize]);
        // bubblewrap writes one JSON object: done as soon as it is whole.
        if serde_json::from_slice::<serde_json::Value>(&bytes).is_ok() {
            break;
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        self.watchdog = None;
        self.reaper.reap();
        if let Some(uid) = self.reaper.uid {
            scratch::sweep(uid);
            scratch::sweep_ipc(uid);
        }
        if let Some(dir) = self.dir.take() {
            let path = dir.path().to_path_buf();
            if dir.close().is_err() {
                remove_tree(&path);
            }
        }
    }
}

/// `text` with the path `from` replaced by `to` where it starts a path (not inside a longer
/// one: `/sandbox/x.py` is replaced, `/work/sandbox/x.py` and `/sandboxes` are not).
pub fn replace_path(text: &str, from: &Path, to: &str) -> String {
    let from = from.display().to_string();
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(&from) {
        let before = rest[..i].chars().next_back();
        let after = rest[i + from.len()..].chars().next();
        let path_char = |c: char| c.is_alphanumeric() || "._-/~".contains(c);
        let starts = before.is_none_or(|c| !path_char(c));
        let ends = after.is_none_or(|c| c == '/' || !path_char(c));
        out.push_str(&rest[..i]);
        out.push_str(if starts && ends { to } else { &from });
        rest = &rest[i + from.len()..];
    }
    out.push_str(rest);
    out
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
mod tests;
