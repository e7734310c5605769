//! The watchdog of a sandbox: every [`TICK`] it measures the files its code keeps and the
//! memory its processes hold against the policy's limits, and ends the code (and records why)
//! once it passes them.
//!
//! Promises: it measures the blocks the sandbox folder holds, the tmpfs of the code's own view
//! (`/tmp`), for a per-submission uid the blocks of everything that uid owns under
//! [`SHARED_ROOTS`](crate::sandbox::bounds::scratch::SHARED_ROOTS), and the code's processes ([`Members`]: those
//! of its uid, of its bubblewrap PID namespaces, or of its sessions): the unlinked files and
//! memfds they hold open count as files, and their resident memory (a page shared by forked
//! processes once) and their System V shared memory as memory ([`crate::sandbox::bounds::held`]). Past the
//! policy's `disk_bytes` (or [`MAX_ENTRIES`] files and folders, or [`MAX_NESTING`] levels) or
//! `memory_bytes` (or when the kernel ended a process at its cgroup's `memory.max`) it ends the
//! code's processes and records why ([`Watchdog::violation`]); the session then says so instead
//! of "killed by signal 9", and starts nothing more in that sandbox. What is written or
//! allocated between two ticks can pass the limits for up to a tick, within the tmpfs's size,
//! the IPC namespace's `shmall` and the cgroup's `memory.max`.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::sandbox::bounds::held::{Members, process_usage};
use crate::sandbox::bounds::reaper::Reaper;
use crate::sandbox::bounds::scratch::{
    MAX_ENTRIES, MAX_NESTING, Usage, owned_usage, usage_of_tree,
};

/// The limits the [`Watchdog`] enforces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Bytes of files (the policy's `disk_bytes`).
    pub disk_bytes: u64,
    /// Bytes of resident memory of all the code's processes together (the policy's
    /// `memory_bytes`).
    pub memory_bytes: u64,
}

/// Whether the kernel ended a process of the cgroup at `memory.max` (where it has one).
fn cgroup_ran_out(cgroup: Option<&std::path::Path>) -> bool {
    cgroup.is_some_and(|c| crate::sandbox::bounds::cgroup::oom_kills_in(c) > 0)
}

/// How often the watchdog measures.
pub const TICK: Duration = Duration::from_millis(100);

/// Measures a sandbox's writing while it lives (see the module's promises).
pub struct Watchdog {
    stop: Arc<AtomicBool>,
    violation: Arc<Mutex<Option<String>>>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// One measurement (what each tick runs), for [`Watchdog::measure_now`].
    measure: Arc<dyn Fn() + Send + Sync>,
}

impl std::fmt::Debug for Watchdog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Watchdog")
            .field("violation", &self.violation())
            .finish_non_exhaustive()
    }
}

impl Watchdog {
    /// Starts measuring `dir`, the processes of `members` (and, for a uid, what it owns under
    /// `SHARED_ROOTS`) against `limits`; `reaper` ends the code on a violation.
    pub fn start(dir: PathBuf, members: Members, limits: Limits, reaper: Reaper) -> Watchdog {
        let cgroup = reaper.cgroup.clone();
        let uid = match members {
            Members::Uid(uid) => Some(uid),
            _ => None,
        };
        let stop = Arc::new(AtomicBool::new(false));
        let violation = Arc::new(Mutex::new(None));
        let measure: Arc<dyn Fn() + Send + Sync> = {
            let violation = violation.clone();
            Arc::new(move || {
                let mut usage = usage_of_tree(&dir);
                if let Some(uid) = uid {
                    let shared = owned_usage(uid);
                    usage.bytes = usage.bytes.saturating_add(shared.bytes);
                    usage.entries = usage.entries.saturating_add(shared.entries);
                    usage.deepest = usage.deepest.max(shared.deepest);
                }
                let procs = process_usage(&members);
                usage.bytes = usage
                    .bytes
                    .saturating_add(procs.unlinked_bytes)
                    .saturating_add(procs.tmpfs_bytes);
                let memory = if procs.memory > limits.memory_bytes {
                    procs.proportional()
                } else {
                    procs.memory
                };
                let memory = if cgroup_ran_out(cgroup.as_deref()) {
                    // The kernel's bound was reached between two ticks.
                    memory.max(limits.memory_bytes.saturating_add(1))
                } else {
                    memory
                };
                let why = judge(usage, limits.disk_bytes)
                    .or_else(|| judge_memory(memory, limits.memory_bytes));
                if let Some(why) = why {
                    // Recorded before the kill, so the session that sees the code die
                    // finds why.
                    violation
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .get_or_insert(why);
                    reaper.reap();
                }
            })
        };
        let thread = {
            let (stop, measure) = (stop.clone(), measure.clone());
            std::thread::Builder::new()
                .name("sandbox-watchdog".into())
                .spawn(move || {
                    while !stop.load(Ordering::Relaxed) {
                        std::thread::park_timeout(TICK);
                        if stop.load(Ordering::Relaxed) {
                            break;
                        }
                        measure();
                    }
                })
                .ok()
        };
        Watchdog {
            stop,
            violation,
            thread,
            measure,
        }
    }

    /// Measures once, now, in the caller's thread: a run that ends between two ticks (code
    /// that fills its `/tmp` and then fails fast) is still judged on what it left.
    pub fn measure_now(&self) {
        (self.measure)();
    }

    /// Why the code was stopped, if it was.
    pub fn violation(&self) -> Option<String> {
        self.violation
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
}

/// The violation of `limit` by `usage`, in words, if any.
pub fn judge(usage: Usage, limit: u64) -> Option<String> {
    if usage.deepest > MAX_NESTING {
        Some(format!(
            "the sandbox stopped it: it nested folders more than {MAX_NESTING} deep"
        ))
    } else if usage.bytes > limit {
        Some(format!(
            "the sandbox stopped it: it wrote more than {} of files (its folder, /tmp and the \
             unlinked files it holds open hold at most that)",
            human_bytes(limit)
        ))
    } else if usage.entries > MAX_ENTRIES {
        Some(format!(
            "the sandbox stopped it: it made more than {MAX_ENTRIES} files and folders"
        ))
    } else {
        None
    }
}

/// The violation of `limit` by `memory` bytes of all the code's processes, in words, if any.
pub fn judge_memory(memory: u64, limit: u64) -> Option<String> {
    (memory > limit).then(|| {
        format!(
            "the sandbox stopped it: its processes held more than {} of memory together \
             (System V shared memory included)",
            human_bytes(limit)
        )
    })
}

/// `64 MiB`, `1.5 GiB`, `512 KiB`, `100 bytes`.
fn human_bytes(n: u64) -> String {
    const UNITS: [(u64, &str); 3] = [(1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (size, unit) in UNITS {
        if n >= size {
            let value = n as f64 / size as f64;
            return if n % size == 0 {
                format!("{} {unit}", n / size)
            } else {
                format!("{value:.1} {unit}")
            };
        }
    }
    format!("{n} bytes")
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.thread().unpark();
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn judging_names_the_limit() {
        let at = Usage {
            bytes: 64 << 20,
            entries: 10,
            deepest: MAX_NESTING,
        };
        assert_eq!(judge(at, 64 << 20), None);
        let over = Usage {
            bytes: (64 << 20) + 1,
            ..at
        };
        assert!(judge(over, 64 << 20).unwrap().contains("more than 64 MiB"));
        let many = Usage {
            entries: MAX_ENTRIES + 1,
            ..Usage::default()
        };
        assert!(judge(many, 64 << 20).unwrap().contains("10000 files"));
        let deep = Usage {
            deepest: MAX_NESTING + 1,
            ..Usage::default()
        };
        assert_eq!(
            judge(deep, 64 << 20).unwrap(),
            format!("the sandbox stopped it: it nested folders more than {MAX_NESTING} deep")
        );
        assert_eq!(
            judge_memory((1 << 30) + 1, 1 << 30).unwrap(),
            "the sandbox stopped it: its processes held more than 1 GiB of memory together \
             (System V shared memory included)"
        );
        assert_eq!(judge_memory(1 << 30, 1 << 30), None);
        assert_eq!(human_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(human_bytes(100), "100 bytes");
    }
}
