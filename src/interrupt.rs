//! Ctrl-C and SIGTERM: whatever rtoracle has started or half-written is cleaned up before it
//! exits with `128 + signal` (130 for SIGINT, 143 for SIGTERM).
//!
//! Work that leaves something behind if the process dies (a sandbox folder holding a student's
//! code, a temporary output folder, processes of a sandbox identity) registers a cleanup with
//! [`on_interrupt`] (or [`remove_on_interrupt`] for a path) and keeps the returned
//! [`CleanupGuard`] while the thing exists; dropping the guard unregisters it, so the normal path
//! cleans up as usual (say by `tempfile`'s drop) and the cleanup runs only on an interruption.
//!
//! [`install`] (called once by the binary, before any work) starts a thread that waits for
//! SIGINT, SIGTERM and SIGHUP with `signal-hook` (the ecosystem's well-kept crate for it: the
//! handler itself only writes to a pipe, and everything else runs on an ordinary thread, so the
//! cleanups may allocate, lock and make system calls). On a signal it runs every registered
//! cleanup, newest first, and exits. A second signal during cleanup is ignored (the cleanups are
//! bounded). A library user that never calls [`install`] keeps the default behaviour.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};

type Cleanup = Box<dyn Fn() + Send + Sync + 'static>;

/// The registered cleanups by registration number (so newest first is the reverse order).
fn registry() -> &'static Mutex<BTreeMap<u64, Cleanup>> {
    static REGISTRY: OnceLock<Mutex<BTreeMap<u64, Cleanup>>> = OnceLock::new();
    REGISTRY.get_or_init(|| Mutex::new(BTreeMap::new()))
}

static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// Held while a process is started (and recorded for its cleanup), and by the signal thread from
/// the signal to the exit: so no process can be started after the cleanups have looked for them.
static SPAWN_GATE: Mutex<()> = Mutex::new(());
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static INSTALLED: AtomicBool = AtomicBool::new(false);

/// Keeps a cleanup registered; dropping it unregisters the cleanup without running it.
#[derive(Debug)]
#[must_use = "the cleanup is unregistered as soon as the guard is dropped"]
pub struct CleanupGuard {
    id: u64,
}

impl Drop for CleanupGuard {
    fn drop(&mut self) {
        if let Ok(mut map) = registry().lock() {
            map.remove(&self.id);
        }
    }
}

/// Registers `cleanup` to run if the process is interrupted while the guard lives.
pub fn on_interrupt(cleanup: impl Fn() + Send + Sync + 'static) -> CleanupGuard {
    let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
    if let Ok(mut map) = registry().lock() {
        map.insert(id, Box::new(cleanup));
    }
    CleanupGuard { id }
}

/// Registers the removal of `path` (a folder, recursively, or a file) on interruption.
pub fn remove_on_interrupt(path: impl Into<PathBuf>) -> CleanupGuard {
    let path = path.into();
    on_interrupt(move || {
        if path.is_dir() {
            let _ = std::fs::remove_dir_all(&path);
        } else {
            let _ = std::fs::remove_file(&path);
        }
    })
}

/// Whether a signal has been received (long loops may stop early; the process exits soon).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::Relaxed)
}

/// Lets one process be started: hold the returned guard across the spawn and the registration
/// of its cleanup. `None` once a signal has come (the process is about to exit; start nothing).
/// While the signal thread cleans up it holds the gate, so a spawn either finished before the
/// cleanups looked (and they find the new process) or never happens.
pub fn spawn_gate() -> Option<std::sync::MutexGuard<'static, ()>> {
    let guard = SPAWN_GATE.lock().unwrap_or_else(|e| e.into_inner());
    (!interrupted()).then_some(guard)
}

/// Runs every registered cleanup, newest first, and empties the registry.
pub fn run_cleanups() {
    let cleanups: Vec<Cleanup> = match registry().lock() {
        Ok(mut map) => std::mem::take(&mut *map).into_values().rev().collect(),
        Err(_) => return,
    };
    for cleanup in cleanups {
        cleanup();
    }
}

/// Starts the signal thread (once; later calls do nothing). Returns an error only when the
/// handlers cannot be registered.
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    if INSTALLED.swap(true, Ordering::SeqCst) {
        return Ok(());
    }
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("rtoracle-signals".into())
        .spawn(move || {
            if let Some(sig) = signals.forever().next() {
                // No process starts from here to the exit (see spawn_gate).
                let _gate = SPAWN_GATE.lock().unwrap_or_else(|e| e.into_inner());
                INTERRUPTED.store(true, Ordering::SeqCst);
                run_cleanups();
                std::process::exit(128 + sig);
            }
        })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::AtomicUsize;

    /// The registry is global: these tests take turns.
    static TURN: Mutex<()> = Mutex::new(());

    #[test]
    fn a_dropped_guard_never_runs_and_a_live_one_runs_once() {
        let _turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        let count = Arc::new(AtomicUsize::new(0));
        let c1 = Arc::clone(&count);
        let dropped = on_interrupt(move || {
            c1.fetch_add(100, Ordering::SeqCst);
        });
        drop(dropped);
        let c2 = Arc::clone(&count);
        let _live = on_interrupt(move || {
            c2.fetch_add(1, Ordering::SeqCst);
        });
        run_cleanups();
        run_cleanups();
        assert_eq!(count.load(Ordering::SeqCst), 1);
    }

    #[test]
    fn remove_on_interrupt_removes_a_folder() {
        let _turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("partial");
        std::fs::create_dir_all(sub.join("inner")).unwrap();
        std::fs::write(sub.join("inner/file"), b"x").unwrap();
        let _guard = remove_on_interrupt(&sub);
        run_cleanups();
        assert!(!sub.exists());
    }
}
