//! Ctrl-C and SIGTERM: whatever rtoracle has started or half-written is cleaned up before it
//! exits with `128 + signal` (130 for SIGINT, 143 for SIGTERM).
//!
//! Work that leaves something behind if the process dies (a sandbox folder holding a student's
//! code, a temporary output folder, processes of a sandbox identity) registers a cleanup with
//! [`on_interrupt`] (or [`remove_on_interrupt`] for a path; [`create_temporary`] makes a
//! temporary file or folder and registers it in one step no signal can split) and keeps the
//! returned [`CleanupGuard`] while the thing exists; dropping the guard unregisters it, so the normal path
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
use std::sync::{Mutex, MutexGuard};

type Cleanup = Box<dyn Fn() + Send + Sync + 'static>;

/// Registered cleanups by registration number (so newest first is the reverse order).
struct Registry {
    map: Mutex<BTreeMap<u64, Cleanup>>,
}

impl Registry {
    const fn new() -> Self {
        Registry {
            map: Mutex::new(BTreeMap::new()),
        }
    }

    fn register(&'static self, cleanup: Cleanup) -> CleanupGuard {
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        if let Ok(mut map) = self.map.lock() {
            map.insert(id, cleanup);
        }
        CleanupGuard { id, registry: self }
    }

    /// Runs every cleanup, newest first, and empties the registry.
    fn run_all(&self) {
        let cleanups: Vec<Cleanup> = match self.map.lock() {
            Ok(mut map) => std::mem::take(&mut *map).into_values().rev().collect(),
            Err(_) => return,
        };
        for cleanup in cleanups {
            cleanup();
        }
    }
}

/// The process's cleanups, run on a signal. (Tests of this module use registries of their own,
/// so they never run another test's cleanups.)
static REGISTRY: Registry = Registry::new();

static NEXT_ID: AtomicU64 = AtomicU64::new(0);

/// Held while a process is started (and recorded for its cleanup), while a few steps run that an
/// interruption must not cut in half ([`hold_off`]), and by the signal thread from the signal to
/// the exit: so no process can be started after the cleanups have looked for them, and no
/// cleanup runs in the middle of those steps.
static SPAWN_GATE: Mutex<()> = Mutex::new(());
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static INSTALLED: AtomicBool = AtomicBool::new(false);

/// Keeps a cleanup registered; dropping it unregisters the cleanup without running it.
#[must_use = "the cleanup is unregistered as soon as the guard is dropped"]
pub struct CleanupGuard {
    id: u64,
    registry: &'static Registry,
}

impl std::fmt::Debug for CleanupGuard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CleanupGuard")
            .field("id", &self.id)
            .finish()
    }
}

impl Drop for CleanupGuard {
    fn drop(&mut self) {
        if let Ok(mut map) = self.registry.map.lock() {
            map.remove(&self.id);
        }
    }
}

#[cfg(test)]
impl CleanupGuard {
    /// Runs this cleanup alone, as an interruption would, and unregisters it (for tests of what
    /// an interruption leaves, without running every other test's cleanups).
    pub(crate) fn run_now(self) {
        let cleanup = self
            .registry
            .map
            .lock()
            .ok()
            .and_then(|mut m| m.remove(&self.id));
        if let Some(cleanup) = cleanup {
            cleanup();
        }
    }
}

/// Registers `cleanup` to run if the process is interrupted while the guard lives.
pub fn on_interrupt(cleanup: impl Fn() + Send + Sync + 'static) -> CleanupGuard {
    REGISTRY.register(Box::new(cleanup))
}

/// Registers the removal of `path` (a folder, recursively, or a file) on interruption. A folder
/// that another thread is still writing into when the cleanup runs may not go at the first try
/// (a file made between the listing and the removal): it is tried a few more times.
pub fn remove_on_interrupt(path: impl Into<PathBuf>) -> CleanupGuard {
    let path = path.into();
    on_interrupt(move || {
        for _ in 0..REMOVAL_TRIES {
            match std::fs::symlink_metadata(&path) {
                Ok(m) if m.is_dir() => {
                    let _ = std::fs::remove_dir_all(&path);
                }
                Ok(_) => {
                    let _ = std::fs::remove_file(&path);
                }
                Err(_) => return,
            }
        }
    })
}

/// How many times a cleanup tries to remove a path (see [`remove_on_interrupt`]).
const REMOVAL_TRIES: usize = 8;

/// Makes a temporary file or folder with `make` and registers its removal on interruption (of
/// the path `path_of` gives), both under the gate the signal thread holds while it cleans up: so
/// the thing is either made before the cleanups look, and removed by them, or never made (an
/// `Interrupted` error once a signal has come). Temporary things made while other threads work
/// (a batch grades submissions in parallel) must be made this way: one made during the cleanups
/// would be missed by them.
pub fn create_temporary<T>(
    make: impl FnOnce() -> std::io::Result<T>,
    path_of: impl FnOnce(&T) -> &std::path::Path,
) -> std::io::Result<(T, CleanupGuard)> {
    let _gate = hold_off()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted"))?;
    let made = make()?;
    let guard = remove_on_interrupt(path_of(&made));
    Ok((made, guard))
}

/// Whether a signal has been received (long loops may stop early; the process exits soon).
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::Relaxed)
}

/// Once a signal has come, waits for the signal thread to finish its cleanups and exit the
/// process with the signal's code (so it never returns then); otherwise returns at once. Called
/// before anything is reported (every line the binary prints, and its exit): a child that the
/// cleanups killed must not be reported as the command's own failure, nor a verdict drawn from
/// it printed, and the exit code must be the signal's.
pub fn exit_if_interrupted() {
    if !interrupted() {
        return;
    }
    // The signal thread holds the gate from the signal to its `exit`: this blocks until then.
    let _gate = SPAWN_GATE.lock();
    loop {
        std::thread::park();
    }
}

/// Lets one process be started: hold the returned guard across the spawn and the registration
/// of its cleanup. `None` once a signal has come (the process is about to exit; start nothing).
/// While the signal thread cleans up it holds the gate, so a spawn either finished before the
/// cleanups looked (and they find the new process) or never happens.
pub fn spawn_gate() -> Option<MutexGuard<'static, ()>> {
    let guard = SPAWN_GATE.lock().unwrap_or_else(|e| e.into_inner());
    (!interrupted()).then_some(guard)
}

/// Holds off an interruption while a few quick steps run that must not be cut in half (the
/// renames that swap an output folder in): a signal that comes meanwhile is acted on, cleanups
/// and exit, once the returned guard is dropped. `None` once a signal has come (the process is
/// about to exit; start nothing). Never held across slow work, nor while taking it again.
pub fn hold_off() -> Option<MutexGuard<'static, ()>> {
    spawn_gate()
}

/// Runs every registered cleanup, newest first, and empties the registry.
pub fn run_cleanups() {
    REGISTRY.run_all();
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

    #[test]
    fn a_dropped_guard_never_runs_and_a_live_one_runs_once() {
        static LOCAL: Registry = Registry::new();
        let count = Arc::new(AtomicUsize::new(0));
        let c1 = Arc::clone(&count);
        let dropped = LOCAL.register(Box::new(move || {
            c1.fetch_add(100, Ordering::SeqCst);
        }));
        drop(dropped);
        let c2 = Arc::clone(&count);
        let _live = LOCAL.register(Box::new(move || {
            c2.fetch_add(1, Ordering::SeqCst);
        }));
        LOCAL.run_all();
        LOCAL.run_all();
        assert_eq!(count.load(Ordering::SeqCst), 1);
    }

    #[test]
    fn cleanups_run_newest_first() {
        static LOCAL: Registry = Registry::new();
        let order = Arc::new(Mutex::new(Vec::new()));
        let guards: Vec<CleanupGuard> = (0..3)
            .map(|i| {
                let order = Arc::clone(&order);
                LOCAL.register(Box::new(move || order.lock().unwrap().push(i)))
            })
            .collect();
        LOCAL.run_all();
        assert_eq!(*order.lock().unwrap(), [2, 1, 0]);
        drop(guards);
    }

    #[test]
    fn a_hold_off_keeps_the_signal_thread_out_until_it_is_dropped() {
        let hold = hold_off().expect("no signal has come");
        // The signal thread takes this lock before it runs any cleanup.
        let blocked = std::thread::spawn(|| SPAWN_GATE.try_lock().is_err())
            .join()
            .unwrap();
        assert!(blocked, "the gate is held");
        drop(hold);
        // Free again (a process may be starting elsewhere: wait for it rather than try).
        std::thread::spawn(|| drop(SPAWN_GATE.lock()))
            .join()
            .unwrap();
    }

    #[test]
    fn remove_on_interrupt_removes_a_folder() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("partial");
        std::fs::create_dir_all(sub.join("inner")).unwrap();
        std::fs::write(sub.join("inner/file"), b"x").unwrap();
        remove_on_interrupt(&sub).run_now();
        assert!(!sub.exists());
        // A file too.
        let file = dir.path().join("half.png");
        std::fs::write(&file, b"x").unwrap();
        remove_on_interrupt(&file).run_now();
        assert!(!file.exists());
    }
}
