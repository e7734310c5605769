//! A sandbox's life: its private folder and the files copied into it, the identity its code
//! runs as, the watchdog that measures it, and what its end (a drop, Ctrl-C or SIGTERM) kills
//! and removes.

use std::io::Read;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use super::bounds::reaper::Reaper;
use super::bounds::{cgroup, held, ipc, scratch, watchdog};
use super::identity::{self, running_as_root};
use super::policy::{Isolation, SandboxError, SandboxPolicy};
use super::view;

/// A prepared sandbox: a temporary folder holding copies of the files, the policy, the
/// isolation and the identity the code runs as.
#[derive(Debug)]
pub struct Sandbox {
    pub(super) policy: SandboxPolicy,
    pub(super) isolation: Isolation,
    pub(super) dir: Option<tempfile::TempDir>,
    /// `(uid, gid)` to switch to (a per-submission id of a root harness).
    pub(super) switch_to: Option<(u32, u32)>,
    /// Paths shown read-only in the sandbox's view besides the system view.
    pub(super) exposed: Vec<PathBuf>,
    /// The empty folder the fallback's child mounts its new root on; `None` where the fallback
    /// makes no namespace (`RTORACLE_SANDBOX=uid-bare`) or another isolation is used.
    pub(super) view_root: Option<tempfile::TempDir>,
    /// The code's cgroup, where cgroups v2 are delegated (dropped after the code is ended).
    pub(super) cgroup: Option<cgroup::Group>,
    /// What bubblewrap reports (`--info-fd`) for the last command, filled by its admission.
    pub(super) info: Mutex<Option<Arc<InfoSlot>>>,
    /// The PID namespaces of the bubblewrap sandboxes started so far (their processes are the
    /// code's, for the watchdog).
    pub(super) pid_namespaces: Arc<Mutex<Vec<u64>>>,
    pub(super) reaper: Reaper,
    pub(super) note: Option<String>,
    pub(super) skipped: Vec<String>,
    /// Measures what the code writes (dropped, and so stopped, before the folder is removed).
    pub(super) watchdog: Option<watchdog::Watchdog>,
    pub(super) _cleanup: crate::interrupt::CleanupGuard,
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
    /// for `isolation` (which the caller has found to work here), with `note` for the facts.
    pub(super) fn with_isolation(
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
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o700)).map_err(io)?;
        if let Some((uid, gid)) = switch_to {
            std::os::unix::fs::chown(dir.path(), Some(uid), Some(gid)).map_err(io)?;
        }
        // The fallback's child mounts its new root on an empty folder of the harness's.
        let view_root = match isolation {
            Isolation::FallbackUid => Some(
                tempfile::Builder::new()
                    .prefix("rtoracle-view-")
                    .tempdir()
                    .map_err(io)?,
            ),
            _ => None,
        };
        // Where cgroups are not delegated (or the group cannot be made) the other limits hold
        // alone, and the facts name no cgroup.
        let cgroup = cgroup::delegation().ok().and_then(|base| {
            cgroup::Group::make(
                base,
                policy.memory_bytes,
                policy.tmp_bytes(),
                policy.processes,
            )
            .ok()
        });
        let reaper = Reaper {
            uid: switch_to.map(|s| s.0),
            groups: Arc::new(Mutex::new(Vec::new())),
            cgroup: cgroup.as_ref().map(|g| g.path().to_path_buf()),
        };
        let cleanup = {
            let reaper = reaper.clone();
            let path = dir.path().to_path_buf();
            let root = view_root.as_ref().map(|r| r.path().to_path_buf());
            crate::interrupt::on_interrupt(move || {
                reaper.reap();
                if let Some(group) = &reaper.cgroup {
                    cgroup::remove(group);
                }
                if let Some(uid) = reaper.uid {
                    scratch::sweep(uid);
                    ipc::sweep_ipc(uid);
                }
                remove_tree(&path);
                if let Some(root) = &root {
                    let _ = std::fs::remove_dir(root);
                }
            })
        };
        let pid_namespaces = Arc::new(Mutex::new(Vec::new()));
        let members = match (reaper.uid, isolation) {
            (Some(uid), _) => held::Members::Uid(uid),
            (None, Isolation::Bubblewrap) => held::Members::PidNamespaces(pid_namespaces.clone()),
            (None, _) => held::Members::Sessions(reaper.groups.clone()),
        };
        let watchdog = watchdog::Watchdog::start(
            dir.path().to_path_buf(),
            members,
            watchdog::Limits {
                disk_bytes: policy.disk_bytes,
                memory_bytes: policy.memory_bytes,
            },
            reaper.clone(),
        );
        let exposed = policy.shown.clone();
        Ok(Sandbox {
            policy,
            isolation,
            dir: Some(dir),
            switch_to,
            exposed,
            view_root,
            cgroup,
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
            Isolation::Bubblewrap => PathBuf::from(view::INSIDE),
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

    /// Why the code was stopped for what it wrote ([`watchdog::Watchdog`]), if it was: then
    /// nothing more should be started in this sandbox.
    pub fn violation(&self) -> Option<String> {
        self.watchdog
            .as_ref()
            .and_then(watchdog::Watchdog::violation)
    }

    /// Measures what the code wrote and holds once, now ([`watchdog::Watchdog::measure_now`]):
    /// for the end of a run, which may come between two of the watchdog's ticks.
    pub fn measure_now(&self) {
        if let Some(w) = &self.watchdog {
            w.measure_now();
        }
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

    /// Whether the code has a view of its own (bubblewrap's, or the fallback's where it makes a
    /// mount namespace) that shows only some folders of the host.
    pub fn has_view(&self) -> bool {
        match self.isolation {
            Isolation::Bubblewrap => true,
            Isolation::FallbackUid => self.view_root.is_some(),
            _ => false,
        }
    }

    /// When a program of the sandbox failed to find a file (`stderr` says "No such file or
    /// directory" or "not found") and the sandbox has a view: that the view shows only some
    /// folders, which, and how to show another.
    pub fn view_hint(&self, stderr: &str) -> Option<String> {
        let missing = ["No such file or directory", "not found"]
            .iter()
            .any(|m| stderr.contains(m));
        if !missing || !self.has_view() {
            return None;
        }
        let shown: Vec<String> = self
            .exposed
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        Some(format!(
            "the sandbox shows only the system's folders and the folders of the files on the \
             command line ({}): a program started from elsewhere is not there; pass \
             --expose FOLDER to show a folder read-only",
            if shown.is_empty() {
                "none".to_string()
            } else {
                shown.join(", ")
            }
        ))
    }

    /// Records the files of the submission that were not copied in, each named (escaped) with
    /// why, for the facts.
    pub fn set_skipped(&mut self, skipped: Vec<String>) {
        self.skipped = skipped;
    }

    /// Shows `path` read-only inside the sandbox's view (see [`view::exposure`]: its folder,
    /// an interpreter's library tree, or the file alone in a shared folder). Without a view
    /// (the fallback without a mount namespace) the code sees the host anyway.
    pub fn expose(&mut self, path: &Path) {
        for p in view::exposure(path) {
            if !self.exposed.contains(&p) {
                self.exposed.push(p);
            }
        }
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        self.watchdog = None;
        self.reaper.reap();
        if let Some(uid) = self.reaper.uid {
            scratch::sweep(uid);
            ipc::sweep_ipc(uid);
        }
        if let Some(dir) = self.dir.take() {
            let path = dir.path().to_path_buf();
            if dir.close().is_err() {
                remove_tree(&path);
            }
        }
        // Killed and removed once empty.
        self.cgroup = None;
    }
}

/// What bubblewrap's `--info-fd` said for one command, once its admission has read it.
#[derive(Debug, Default)]
pub(in crate::sandbox) struct InfoSlot {
    text: Mutex<Option<String>>,
    ready: std::sync::Condvar,
}

impl InfoSlot {
    pub(in crate::sandbox) fn set(&self, text: String) {
        *self.text.lock().unwrap_or_else(|e| e.into_inner()) = Some(text);
        self.ready.notify_all();
    }

    /// The text, waiting up to `timeout` for it (empty when it does not come).
    pub(in crate::sandbox) fn wait(&self, timeout: std::time::Duration) -> String {
        let guard = self.text.lock().unwrap_or_else(|e| e.into_inner());
        let (guard, _) = self
            .ready
            .wait_timeout_while(guard, timeout, |t| t.is_none())
            .unwrap_or_else(|e| e.into_inner());
        guard.clone().unwrap_or_default()
    }
}
