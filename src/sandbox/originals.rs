//! What the code must not read kept from the sandbox users while it is graded: in the fallback
//! the code runs as a uid of its own on the host, where a batch folder unpacked under the
//! default umask is readable by all (a submission walked `/tmp`, found a classmate's
//! `RT_object.py` and ran it), and so are a rubric (its secret seed), its scenes and goldens.
//!
//! Promises: [`keep_from_sandboxes`] takes away the others' bits (`o-rwx`) of each path given
//! (a folder: no sandbox uid can enter it; a file: none can read it) when the code would run in
//! the fallback and they are set, and says so once on stderr (when the binary asked for the
//! sandbox's announcements); the returned guard puts every mode back when grading ends, and on
//! Ctrl-C or SIGTERM. A path whose mode cannot be changed is an error: grading does not start.
//! Under bubblewrap nothing is changed: its view does not show them.

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

use super::detect::isolation_for;
use super::facts::say;
use super::policy::{Isolation, SandboxError, SandboxPolicy};

/// Puts the modes back when dropped.
#[derive(Debug)]
pub struct Restore {
    /// The paths changed, with their modes before.
    changed: Vec<(PathBuf, u32)>,
    _cleanup: Option<crate::interrupt::CleanupGuard>,
}

impl Restore {
    /// The paths whose modes were changed.
    pub fn changed(&self) -> impl Iterator<Item = &Path> {
        self.changed.iter().map(|(p, _)| p.as_path())
    }
}

impl Drop for Restore {
    fn drop(&mut self) {
        put_back(&self.changed);
    }
}

fn put_back(changed: &[(PathBuf, u32)]) {
    for (path, mode) in changed {
        let _ = std::fs::set_permissions(path, std::fs::Permissions::from_mode(*mode));
    }
}

/// Keeps `paths` (a batch folder, a rubric, its scenes and goldens) from the sandbox users while
/// the returned guard lives (see the module's promises); nothing to do where the code runs
/// under bubblewrap or not as a uid of its own.
pub fn keep_from_sandboxes(paths: &[PathBuf]) -> Result<Restore, SandboxError> {
    let mut restore = Restore {
        changed: Vec::new(),
        _cleanup: None,
    };
    if isolation_for(&SandboxPolicy::grading())? != Isolation::FallbackUid {
        return Ok(restore);
    }
    let mut shown = Vec::new();
    for given in paths {
        let io = |e: std::io::Error| SandboxError::Io(format!("{}: {e}", given.display()));
        let path = given.canonicalize().map_err(io)?;
        let mode = std::fs::metadata(&path).map_err(io)?.permissions().mode() & 0o7777;
        if mode & 0o007 == 0 || restore.changed.iter().any(|(p, _)| *p == path) {
            continue;
        }
        let tight = mode & !0o007;
        if let Err(e) = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(tight)) {
            put_back(&restore.changed);
            return Err(SandboxError::Io(format!(
                "{}: readable by all, and its mode cannot be changed ({e}): make it unreadable \
                 by others (chmod o-rwx) before grading, so the code graded cannot read it",
                given.display()
            )));
        }
        restore.changed.push((path, mode));
        shown.push(format!(
            "{} ({mode:o} -> {tight:o})",
            crate::escape::terminal_line(&given.display().to_string())
        ));
    }
    if !restore.changed.is_empty() {
        say(&format!(
            "rtoracle: sandbox: made unreadable by others while grading, put back afterwards \
             (the code runs as uids of its own on this host): {}",
            shown.join(", ")
        ));
        let changed = restore.changed.clone();
        restore._cleanup = Some(crate::interrupt::on_interrupt(move || put_back(&changed)));
    }
    Ok(restore)
}
