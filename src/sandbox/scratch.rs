//! What a sandbox's code may write, how much, and that none of it is left behind.
//!
//! Promises:
//! - **One place to write.** Under bubblewrap the code's writable paths are the sandbox folder
//!   (`/sandbox`) and its `/tmp`, which is [`TMP_DIR`] inside that folder (not a `tmpfs`, whose
//!   size bubblewrap 0.8 cannot bound and which lives in the host's memory); `/dev` is read-only,
//!   so `/dev/shm` is not writable either. In the other modes `TMPDIR` and the working directory
//!   are the sandbox folder; the host's world-writable folders ([`SHARED_ROOTS`]: `/tmp`,
//!   `/var/tmp`, `/dev/shm`, ...) stay writable, since nothing can hide them without namespaces.
//! - **Bounded.** [`Watchdog`] measures, every [`TICK`], the blocks the sandbox folder holds and,
//!   for a per-submission uid, the blocks of everything that uid owns under [`SHARED_ROOTS`]. Past
//!   the policy's `disk_bytes` (or [`MAX_ENTRIES`] files and folders) it ends the code's processes
//!   and records why ([`Watchdog::violation`]); the session then says so instead of "killed by
//!   signal 9", and starts nothing more in that sandbox.
//! - **Nothing left behind.** [`sweep`] removes everything a per-submission uid owns under
//!   [`SHARED_ROOTS`] once none of its processes is left (so nothing can race it): entries are
//!   unlinked, never followed (a link the code planted pointing at a grader file removes the link
//!   only), and only world-writable folders not owned by the uid are entered, on the same file
//!   system, at most [`MAX_DEPTH`] deep. The sandbox folder itself is removed with the sandbox.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::Reaper;

/// The folder inside the sandbox folder that bubblewrap shows as `/tmp`.
pub const TMP_DIR: &str = ".tmp";

/// The host's world-writable folders a uid without a mount namespace can write into.
pub const SHARED_ROOTS: [&str; 6] = [
    "/tmp",
    "/var/tmp",
    "/dev/shm",
    "/run/lock",
    "/var/lock",
    "/dev/mqueue",
];

/// How often the watchdog measures.
pub const TICK: Duration = Duration::from_millis(100);

/// Most files and folders the code may make (each costs an inode and a step of every walk).
pub const MAX_ENTRIES: u64 = 10_000;

/// How deep the walks of [`SHARED_ROOTS`] go into world-writable folders not owned by the uid.
pub const MAX_DEPTH: usize = 8;

/// Space and entries measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    /// Bytes of the blocks allocated (`st_blocks * 512`: a sparse file counts what it holds).
    pub bytes: u64,
    /// Files, folders and links.
    pub entries: u64,
}

impl Usage {
    fn add(&mut self, meta: &std::fs::Metadata) {
        self.bytes = self.bytes.saturating_add(meta.blocks().saturating_mul(512));
        self.entries += 1;
    }
}

/// The usage of the tree at `root` (itself excluded), without following links or leaving its
/// file system; stops counting past `MAX_ENTRIES + 1` entries.
pub fn usage_of_tree(root: &Path) -> Usage {
    let mut usage = Usage::default();
    let Ok(meta) = std::fs::symlink_metadata(root) else {
        return usage;
    };
    walk_all(root, meta.dev(), &mut usage);
    usage
}

fn walk_all(dir: &Path, dev: u64, usage: &mut Usage) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        if usage.entries > MAX_ENTRIES {
            return;
        }
        let Ok(meta) = entry.metadata() else {
            continue;
        };
        usage.add(&meta);
        if meta.is_dir() && meta.dev() == dev {
            walk_all(&entry.path(), dev, usage);
        }
    }
}

/// What `uid` owns under [`SHARED_ROOTS`] (see [`owned_entries`]), with the trees of the folders
/// it owns.
pub fn owned_usage(uid: u32) -> Usage {
    let mut usage = Usage::default();
    for path in owned_entries(uid) {
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        usage.add(&meta);
        if meta.is_dir() {
            let inner = usage_of_tree(&path);
            usage.bytes = usage.bytes.saturating_add(inner.bytes);
            usage.entries = usage.entries.saturating_add(inner.entries);
        }
        if usage.entries > MAX_ENTRIES {
            break;
        }
    }
    usage
}

/// The entries `uid` owns under [`SHARED_ROOTS`]: found by entering only folders that are
/// world-writable and not the uid's (where it could have made something), never through a link,
/// on each root's file system, at most [`MAX_DEPTH`] deep. A folder the uid owns is listed, not
/// entered.
pub fn owned_entries(uid: u32) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for root in SHARED_ROOTS {
        let root = Path::new(root);
        let Ok(meta) = std::fs::symlink_metadata(root) else {
            continue;
        };
        if meta.is_dir() {
            find_owned(root, meta.dev(), uid, 0, &mut found);
        }
    }
    found
}

fn find_owned(dir: &Path, dev: u64, uid: u32, depth: usize, found: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let Ok(meta) = entry.metadata() else {
            continue;
        };
        if meta.uid() == uid {
            found.push(entry.path());
        } else if meta.is_dir()
            && meta.mode() & 0o002 != 0
            && meta.dev() == dev
            && depth < MAX_DEPTH
        {
            find_owned(&entry.path(), dev, uid, depth + 1, found);
        }
        if found.len() as u64 > MAX_ENTRIES {
            return;
        }
    }
}

/// Removes everything `uid` owns under [`SHARED_ROOTS`] (call it once no process of the uid is
/// left). Returns how many entries were removed. Folders go with
/// [`std::fs::remove_dir_all`], which does not follow links.
pub fn sweep(uid: u32) -> usize {
    let mut removed = 0;
    for path in owned_entries(uid) {
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        let gone = if meta.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        };
        if gone.is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Measures a sandbox's writing while it lives (see the module's promises).
#[derive(Debug)]
pub struct Watchdog {
    stop: Arc<AtomicBool>,
    violation: Arc<Mutex<Option<String>>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Watchdog {
    /// Starts measuring `dir` (and what `uid` owns under [`SHARED_ROOTS`], when given) against
    /// `limit` bytes; `reaper` ends the code on a violation.
    pub fn start(dir: PathBuf, uid: Option<u32>, limit: u64, reaper: Reaper) -> Watchdog {
        let stop = Arc::new(AtomicBool::new(false));
        let violation = Arc::new(Mutex::new(None));
        let thread = {
            let (stop, violation) = (stop.clone(), violation.clone());
            std::thread::Builder::new()
                .name("sandbox-watchdog".into())
                .spawn(move || {
                    while !stop.load(Ordering::Relaxed) {
                        std::thread::park_timeout(TICK);
                        if stop.load(Ordering::Relaxed) {
                            break;
                        }
                        let mut usage = usage_of_tree(&dir);
                        if let Some(uid) = uid {
                            let shared = owned_usage(uid);
                            usage.bytes = usage.bytes.saturating_add(shared.bytes);
                            usage.entries = usage.entries.saturating_add(shared.entries);
                        }
                        if let Some(why) = judge(usage, limit) {
                            // Recorded before the kill, so the session that sees the code die
                            // finds why.
                            violation
                                .lock()
                                .unwrap_or_else(|e| e.into_inner())
                                .get_or_insert(why);
                            reaper.reap();
                        }
                    }
                })
                .ok()
        };
        Watchdog {
            stop,
            violation,
            thread,
        }
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
    if usage.bytes > limit {
        Some(format!(
            "the sandbox stopped it: it wrote more than {} of files (its folder and /tmp hold at \
             most that)",
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
    fn usage_counts_blocks_not_apparent_size() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("sub/a"), vec![1u8; 1 << 20]).unwrap();
        // A sparse file of 1 GiB holds (almost) nothing.
        let sparse = std::fs::File::create(dir.path().join("sparse")).unwrap();
        sparse.set_len(1 << 30).unwrap();
        let usage = usage_of_tree(dir.path());
        assert_eq!(usage.entries, 3);
        assert!(usage.bytes >= 1 << 20, "{usage:?}");
        assert!(usage.bytes < 2 << 20, "{usage:?}");
    }

    #[test]
    fn judging_names_the_limit() {
        let at = Usage {
            bytes: 64 << 20,
            entries: 10,
        };
        assert_eq!(judge(at, 64 << 20), None);
        let over = Usage {
            bytes: (64 << 20) + 1,
            ..at
        };
        assert!(judge(over, 64 << 20).unwrap().contains("more than 64 MiB"));
        let many = Usage {
            bytes: 0,
            entries: MAX_ENTRIES + 1,
        };
        assert!(judge(many, 64 << 20).unwrap().contains("10000 files"));
        assert_eq!(human_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(human_bytes(100), "100 bytes");
    }
}
