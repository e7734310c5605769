//! What a sandbox may do and how strongly it is made: its limits ([`SandboxPolicy`]), the mode
//! `RTORACLE_SANDBOX` asks for ([`Mode`]), the isolation a run got ([`Isolation`]) and why a
//! sandbox cannot be made ([`SandboxError`]).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// Why a sandbox cannot be made.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SandboxError {
    /// `RTORACLE_SANDBOX` holds an unknown mode.
    #[error("RTORACLE_SANDBOX={0:?} is not one of auto, bubblewrap, uid, uid-bare, none")]
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
    /// The fallback without any namespace, as in a container that refuses them (what the code
    /// can reach there is what the host's modes allow).
    UidBare,
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
            Ok("uid-bare") => Ok(Mode::UidBare),
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
    /// code's processes together ([`Watchdog`](super::bounds::watchdog::Watchdog)).
    pub memory_bytes: u64,
    /// Open files (`RLIMIT_NOFILE`).
    pub open_files: u64,
    /// Largest file it may write, in bytes (`RLIMIT_FSIZE`).
    pub file_size_bytes: u64,
    /// Processes and threads (`RLIMIT_NPROC`): for a per-submission uid, and inside
    /// bubblewrap's user namespace for any harness (elsewhere it would count every process of
    /// the harness's user).
    pub processes: u64,
    /// Bytes the code may keep in files, its `/tmp` included ([`Watchdog`](super::bounds::watchdog::Watchdog)).
    #[serde(default = "default_disk_bytes")]
    pub disk_bytes: u64,
    /// Try a new network namespace in the fallback (bubblewrap always makes one).
    pub isolate_network: bool,
    /// Run without a sandbox, as the current user (root included): `--unsandboxed`, for one's
    /// own code. Limits, the folder and the session still apply.
    #[serde(default)]
    pub unsandboxed: bool,
    /// Folders shown read-only in the sandbox's view besides those of the files the command
    /// line names (`check --expose FOLDER`: an adapter that starts a program from elsewhere).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shown: Vec<PathBuf>,
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
            shown: Vec::new(),
        }
    }
}

impl SandboxPolicy {
    /// The size of the tmpfs that is the code's `/tmp` where it has a view of its own:
    /// `disk_bytes` and one MiB more, so that filling it passes the limit, which the watchdog
    /// then says, rather than ending in "No space left on device".
    pub fn tmp_bytes(&self) -> u64 {
        self.disk_bytes.saturating_add(1 << 20)
    }

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
