//! Which isolation this host allows: whether bubblewrap works and a root harness can switch
//! to an unused uid (each probed once per process), what `RTORACLE_SANDBOX` asks for, and
//! [`Sandbox::new`], which makes a sandbox with the strongest isolation that works.

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use super::identity::{self, running_as_root};
use super::lifecycle::Sandbox;
use super::policy::{Isolation, Mode, SandboxError, SandboxPolicy};
use super::start::bwrap;

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
        Mode::UidBare => fallback("RTORACLE_SANDBOX=uid-bare".into()),
        Mode::None if root => Err(SandboxError::Unavailable(
            "RTORACLE_SANDBOX=none: no sandbox may be made, and untrusted code never runs as root"
                .into(),
        )),
        Mode::None => Ok(Isolation::CurrentUser),
    }
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
        let mut sandbox = Sandbox::with_isolation(policy, isolation, files, note)?;
        if Mode::from_env() == Ok(Mode::UidBare) {
            // No namespace at all: no view to mount a root on.
            sandbox.view_root = None;
        }
        Ok(sandbox)
    }
}
