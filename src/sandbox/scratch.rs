//! What a sandbox's code may write, how much, and that none of it is left behind.
//!
//! Promises:
//! - **Any depth.** Trees are walked and removed by descriptor, never by path, so a tree deeper
//!   than a path can name is measured and removed like any other; one nested more than
//!   [`MAX_NESTING`] folders deep is a violation in itself (below that, the walk does not go).
//! - **One place to write.** Under bubblewrap the code's writable paths are the sandbox folder
//!   (`/sandbox`) and its `/tmp`, which is [`TMP_DIR`] inside that folder (not a `tmpfs`, whose
//!   size bubblewrap 0.8 cannot bound and which lives in the host's memory); `/dev` is read-only,
//!   so `/dev/shm` is not writable either. In the other modes `TMPDIR` and the working directory
//!   are the sandbox folder; the host's world-writable folders ([`SHARED_ROOTS`]: `/tmp`,
//!   `/var/tmp`, `/dev/shm`, ...) stay writable, since nothing can hide them without namespaces.
//! - **Bounded.** [`Watchdog`] measures, every [`TICK`], the blocks the sandbox folder holds and,
//!   for a per-submission uid, the blocks of everything that uid owns under [`SHARED_ROOTS`], and
//!   the code's processes ([`Members`]: those of its uid, of its bubblewrap PID namespaces, or of
//!   its sessions): the files they hold open that are unlinked (a deleted temporary file, a
//!   memfd) count as files, and their resident memory (anonymous and shared pages, and a uid's
//!   System V shared memory) is added up, a page shared by forked processes once (proportional
//!   sets, read when the cheap sum of resident sets is over the limit). Past the policy's `disk_bytes` (or [`MAX_ENTRIES`] files
//!   and folders) or `memory_bytes` for all its processes together (`RLIMIT_AS` bounds each
//!   alone) it ends the code's processes and records why ([`Watchdog::violation`]); the session
//!   then says so instead of "killed by signal 9", and starts nothing more in that sandbox. What
//!   is written or allocated between two ticks can pass the limits for up to a tick.
//! - **Nothing left behind.** [`sweep`] removes everything a per-submission uid owns under
//!   [`SHARED_ROOTS`] once none of its processes is left (so nothing can race it): entries are
//!   unlinked, never followed (a link the code planted pointing at a grader file removes the link
//!   only), and only world-writable folders not owned by the uid are entered, on the same file
//!   system, at most [`MAX_DEPTH`] deep. [`sweep_ipc`] removes the System V shared memory,
//!   message queues and semaphores the uid made or owns (they outlive every process; the fallback
//!   also gives the code an IPC namespace where it can). The sandbox folder itself is removed with
//!   the sandbox.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::reaper::Reaper;

/// Which processes are the code's, for the [`Watchdog`].
#[derive(Clone, Debug)]
pub enum Members {
    /// Every process of a per-submission uid (a root harness).
    Uid(u32),
    /// Every process in one of these PID namespaces (bubblewrap run by a harness that is not
    /// root), by the inode of `/proc/<pid>/ns/pid`.
    PidNamespaces(Arc<Mutex<Vec<u64>>>),
    /// Every process in one of these sessions (the code's own sessions, without bubblewrap nor
    /// a uid: a process that leaves its session is not seen).
    Sessions(Arc<Mutex<Vec<i32>>>),
}

/// The limits the [`Watchdog`] enforces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Bytes of files (the policy's `disk_bytes`).
    pub disk_bytes: u64,
    /// Bytes of resident memory of all the code's processes together (the policy's
    /// `memory_bytes`).
    pub memory_bytes: u64,
}

/// What the code's processes hold.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ProcessUsage {
    /// Processes seen.
    pub processes: u64,
    /// Resident anonymous and shared memory (`RssAnon + RssShmem`), plus a uid's System V shared
    /// memory: cheap to read, and an upper bound (pages shared by forked processes count once
    /// per process); see [`ProcessUsage::proportional`].
    pub memory: u64,
    /// Blocks of the unlinked regular files they hold open (each file once).
    pub unlinked_bytes: u64,
    /// The processes seen, with what each counted in `memory`.
    pub pids: Vec<(u32, u64)>,
    /// The uid's System V shared memory counted in `memory`.
    pub ipc_bytes: u64,
}

impl ProcessUsage {
    /// The memory counted with each shared page divided among the processes sharing it
    /// (`Pss_Anon + Pss_Shmem` of `/proc/<pid>/smaps_rollup`, which walks the page tables: read
    /// only when [`ProcessUsage::memory`] is over a limit), plus the System V shared memory. A
    /// process whose rollup cannot be read counts its resident set.
    pub fn proportional(&self) -> u64 {
        let mut total = self.ipc_bytes;
        for &(pid, resident) in &self.pids {
            let rollup = std::fs::read_to_string(format!("/proc/{pid}/smaps_rollup"))
                .ok()
                .and_then(|t| {
                    Some(status_number(&t, "Pss_Anon:")? + status_number(&t, "Pss_Shmem:")?)
                });
            total = total.saturating_add(rollup.map_or(resident, |kb| kb.saturating_mul(1024)));
        }
        total
    }
}

/// The first number of the `/proc/<pid>/status` line starting with `key`.
fn status_number(status: &str, key: &str) -> Option<u64> {
    status
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

/// Measures the processes of `members` (see [`ProcessUsage`]).
pub fn process_usage(members: &Members) -> ProcessUsage {
    let mut usage = ProcessUsage::default();
    let set = |list: &Arc<Mutex<Vec<i32>>>| list.lock().map(|l| l.clone()).unwrap_or_default();
    let sessions = match members {
        Members::Sessions(list) => set(list),
        _ => Vec::new(),
    };
    let namespaces = match members {
        Members::PidNamespaces(list) => list.lock().map(|l| l.clone()).unwrap_or_default(),
        _ => Vec::new(),
    };
    let mut files = std::collections::HashSet::new();
    for (pid, proc_dir) in super::identity::proc_entries() {
        let member = match members {
            Members::Uid(_) => true,
            Members::PidNamespaces(_) => std::fs::read_link(proc_dir.join("ns/pid"))
                .ok()
                .and_then(|l| {
                    let l = l.to_string_lossy().into_owned();
                    l.split_once('[')?.1.strip_suffix(']')?.parse::<u64>().ok()
                })
                .is_some_and(|ns| namespaces.contains(&ns)),
            Members::Sessions(_) => std::fs::read_to_string(proc_dir.join("stat"))
                .ok()
                .and_then(|stat| {
                    // The fields after the command's closing parenthesis: state, ppid, pgrp,
                    // session.
                    let rest = stat.rsplit_once(')')?.1.to_string();
                    rest.split_whitespace().nth(3)?.parse::<i32>().ok()
                })
                .is_some_and(|sid| sessions.contains(&sid)),
        };
        if !member {
            continue;
        }
        let Ok(status) = std::fs::read_to_string(proc_dir.join("status")) else {
            continue;
        };
        if let Members::Uid(uid) = members
            && status_number(&status, "Uid:") != Some(*uid as u64)
        {
            continue;
        }
        if pid == std::process::id() {
            continue;
        }
        usage.processes += 1;
        let kb = status_number(&status, "RssAnon:").unwrap_or(0)
            + status_number(&status, "RssShmem:").unwrap_or(0);
        let resident = kb.saturating_mul(1024);
        usage.memory = usage.memory.saturating_add(resident);
        usage.pids.push((pid, resident));
        let Ok(fds) = std::fs::read_dir(proc_dir.join("fd")) else {
            continue;
        };
        for fd in fds.flatten() {
            // Followed: the open file itself (a memfd or a deleted file has no other name).
            let Ok(meta) = std::fs::metadata(fd.path()) else {
                continue;
            };
            if meta.is_file() && meta.nlink() == 0 && files.insert((meta.dev(), meta.ino())) {
                usage.unlinked_bytes = usage
                    .unlinked_bytes
                    .saturating_add(meta.blocks().saturating_mul(512));
            }
        }
    }
    if let Members::Uid(uid) = members {
        usage.ipc_bytes = ipc_objects(*uid)
            .iter()
            .filter(|o| o.table == "shm")
            .map(|o| o.bytes)
            .sum();
        usage.memory = usage.memory.saturating_add(usage.ipc_bytes);
    }
    usage
}

/// A System V IPC object of the harness's IPC namespace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IpcObject {
    /// `shm`, `msg` or `sem`.
    pub table: &'static str,
    /// Its id.
    pub id: i32,
    /// Bytes (a shared memory segment's size, a queue's bytes; 0 for semaphores).
    pub bytes: u64,
}

/// The System V objects `uid` owns or made, from `/proc/sysvipc/{shm,msg,sem}`.
pub fn ipc_objects(uid: u32) -> Vec<IpcObject> {
    // The columns of the id, the size, the owner and the creator in each table.
    const TABLES: [(&str, usize, Option<usize>, usize, usize); 3] = [
        ("shm", 1, Some(3), 7, 9),
        ("msg", 1, Some(3), 7, 9),
        ("sem", 1, None, 4, 6),
    ];
    let mut found = Vec::new();
    for (table, id_at, bytes_at, uid_at, cuid_at) in TABLES {
        let Ok(text) = std::fs::read_to_string(format!("/proc/sysvipc/{table}")) else {
            continue;
        };
        for line in text.lines().skip(1) {
            let words: Vec<&str> = line.split_whitespace().collect();
            let number = |i: usize| words.get(i).and_then(|w| w.parse::<u64>().ok());
            let ours = [uid_at, cuid_at]
                .iter()
                .any(|&i| number(i) == Some(uid as u64));
            if let (true, Some(id)) = (ours, number(id_at)) {
                found.push(IpcObject {
                    table,
                    id: id as i32,
                    bytes: bytes_at.and_then(number).unwrap_or(0),
                });
            }
        }
    }
    found
}

/// Removes the System V objects `uid` owns or made ([`ipc_objects`]); returns how many. Needs
/// root (or the uid).
pub fn sweep_ipc(uid: u32) -> usize {
    let mut removed = 0;
    for object in ipc_objects(uid) {
        // SAFETY: IPC_RMID takes no buffer (a null one is allowed).
        let done = unsafe {
            match object.table {
                "shm" => libc::shmctl(object.id, libc::IPC_RMID, std::ptr::null_mut()),
                "msg" => libc::msgctl(object.id, libc::IPC_RMID, std::ptr::null_mut()),
                _ => libc::semctl(object.id, 0, libc::IPC_RMID),
            }
        };
        if done == 0 {
            removed += 1;
        }
    }
    removed
}

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

/// How deeply the code may nest folders: a deeper tree is a violation in itself (the walks go no
/// deeper, so what lies below would not be measured).
pub const MAX_NESTING: usize = 100;

/// Space and entries measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    /// Bytes of the blocks allocated (`st_blocks * 512`: a sparse file counts what it holds).
    pub bytes: u64,
    /// Files, folders and links.
    pub entries: u64,
    /// The deepest folder seen (1: a folder of the root; [`MAX_NESTING`] + 1 at most, where the
    /// walk stops going down).
    pub deepest: usize,
}

impl Usage {
    fn add(&mut self, meta: &std::fs::Metadata) {
        self.bytes = self.bytes.saturating_add(meta.blocks().saturating_mul(512));
        self.entries += 1;
    }
}

/// The usage of the tree at `root` (itself excluded), without following links or leaving its
/// file system; stops counting past `MAX_ENTRIES + 1` entries, and going down past
/// [`MAX_NESTING`] folders. The walk goes by descriptors (`openat`, `fstatat`), never by paths,
/// so a tree deeper than a path can name (4096 bytes) is measured as any other.
pub fn usage_of_tree(root: &Path) -> Usage {
    let mut usage = Usage::default();
    let Ok(meta) = std::fs::symlink_metadata(root) else {
        return usage;
    };
    let Ok(c) = std::ffi::CString::new(root.as_os_str().as_encoded_bytes()) else {
        return usage;
    };
    if let Some(dir) = Dir::open_at(libc::AT_FDCWD, &c) {
        walk_all(&dir, meta.dev(), 1, &mut usage);
    }
    usage
}

fn walk_all(dir: &Dir, dev: u64, depth: usize, usage: &mut Usage) {
    for name in dir.names() {
        if usage.entries > MAX_ENTRIES {
            return;
        }
        let Some(st) = dir.stat(&name) else {
            continue;
        };
        usage.bytes = usage
            .bytes
            .saturating_add((st.st_blocks as u64).saturating_mul(512));
        usage.entries += 1;
        if st.st_mode & libc::S_IFMT == libc::S_IFDIR && st.st_dev == dev {
            usage.deepest = usage.deepest.max(depth);
            if depth > MAX_NESTING {
                continue;
            }
            if let Some(child) = Dir::open_at(dir.fd(), &name) {
                walk_all(&child, dev, depth + 1, usage);
            }
        }
    }
}

/// An open folder, read by descriptor.
struct Dir(std::ptr::NonNull<libc::DIR>);

impl Dir {
    /// Opens the folder `name` of the folder `parent` (a descriptor, or `AT_FDCWD`), never
    /// through a link.
    fn open_at(parent: libc::c_int, name: &std::ffi::CStr) -> Option<Dir> {
        // SAFETY: plain system calls; the descriptor is owned by the DIR once fdopendir succeeds,
        // and closed here otherwise.
        unsafe {
            let fd = libc::openat(
                parent,
                name.as_ptr(),
                libc::O_RDONLY | libc::O_DIRECTORY | libc::O_NOFOLLOW | libc::O_CLOEXEC,
            );
            if fd < 0 {
                return None;
            }
            match std::ptr::NonNull::new(libc::fdopendir(fd)) {
                Some(d) => Some(Dir(d)),
                None => {
                    libc::close(fd);
                    None
                }
            }
        }
    }

    fn fd(&self) -> libc::c_int {
        // SAFETY: the DIR is open.
        unsafe { libc::dirfd(self.0.as_ptr()) }
    }

    /// The names in the folder, `.` and `..` aside, read from its start.
    fn names(&self) -> Vec<std::ffi::CString> {
        let mut names = Vec::new();
        // SAFETY: the DIR is open and used by this thread only; each entry's name is a
        // NUL-terminated string valid until the next readdir, copied at once.
        unsafe {
            libc::rewinddir(self.0.as_ptr());
            loop {
                let entry = libc::readdir(self.0.as_ptr());
                if entry.is_null() {
                    break;
                }
                let name = std::ffi::CStr::from_ptr((*entry).d_name.as_ptr());
                if name.to_bytes() != b"." && name.to_bytes() != b".." {
                    names.push(name.to_owned());
                }
            }
        }
        names
    }

    /// `fstatat` of `name` without following a link.
    fn stat(&self, name: &std::ffi::CStr) -> Option<libc::stat> {
        // SAFETY: fstatat fills the struct it is given.
        unsafe {
            let mut st: libc::stat = std::mem::zeroed();
            (libc::fstatat(self.fd(), name.as_ptr(), &mut st, libc::AT_SYMLINK_NOFOLLOW) == 0)
                .then_some(st)
        }
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        // SAFETY: the DIR is open and closed once.
        unsafe {
            libc::closedir(self.0.as_ptr());
        }
    }
}

/// Removes the tree at `path` (itself included) without following links, whatever its depth:
/// one folder is open at a time and the way down is remembered by name (the standard library's
/// removal keeps a descriptor per level, so a tree thousands of folders deep fails where open
/// files are limited). Folders it cannot enter are opened up (`0700`) first. Call it once no
/// process can write there. Returns whether the tree is gone.
pub fn remove_deep(path: &Path) -> bool {
    let Ok(c) = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()) else {
        return false;
    };
    let Some(mut dir) = Dir::open_at(libc::AT_FDCWD, &c) else {
        return std::fs::remove_file(path).is_ok() || !path.exists();
    };
    let mut way: Vec<std::ffi::CString> = Vec::new();
    let dotdot = c"..";
    loop {
        let mut down = None;
        for name in dir.names() {
            let Some(st) = dir.stat(&name) else {
                continue;
            };
            if st.st_mode & libc::S_IFMT != libc::S_IFDIR {
                // SAFETY: unlinkat of an entry of the open folder.
                unsafe {
                    libc::unlinkat(dir.fd(), name.as_ptr(), 0);
                }
                continue;
            }
            let child = Dir::open_at(dir.fd(), &name).or_else(|| {
                // SAFETY: fchmodat of a folder of the open folder (no process writes there).
                unsafe {
                    libc::fchmodat(dir.fd(), name.as_ptr(), 0o700, 0);
                }
                Dir::open_at(dir.fd(), &name)
            });
            match child {
                Some(child) => {
                    down = Some((name, child));
                    break;
                }
                None => return false,
            }
        }
        if let Some((name, child)) = down {
            way.push(name);
            dir = child;
            continue;
        }
        // This folder is empty now: go up and remove it.
        let Some(name) = way.pop() else {
            break;
        };
        let Some(parent) = Dir::open_at(dir.fd(), dotdot) else {
            return false;
        };
        dir = parent;
        // SAFETY: unlinkat of a folder of the open folder.
        if unsafe { libc::unlinkat(dir.fd(), name.as_ptr(), libc::AT_REMOVEDIR) } != 0 {
            // Something in it could not be removed: stop rather than go down again.
            return false;
        }
    }
    drop(dir);
    std::fs::remove_dir(path).is_ok()
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
            usage.deepest = usage.deepest.max(inner.deepest + 1);
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
/// [`std::fs::remove_dir_all`], which does not follow links, or [`remove_deep`] when it fails.
pub fn sweep(uid: u32) -> usize {
    let mut removed = 0;
    for path in owned_entries(uid) {
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        let gone = if meta.is_dir() {
            std::fs::remove_dir_all(&path).is_ok() || remove_deep(&path)
        } else {
            std::fs::remove_file(&path).is_ok()
        };
        if gone {
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
    /// Starts measuring `dir`, the processes of `members` (and, for a uid, what it owns under
    /// [`SHARED_ROOTS`]) against `limits`; `reaper` ends the code on a violation.
    pub fn start(dir: PathBuf, members: Members, limits: Limits, reaper: Reaper) -> Watchdog {
        let uid = match members {
            Members::Uid(uid) => Some(uid),
            _ => None,
        };
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
                            usage.deepest = usage.deepest.max(shared.deepest);
                        }
                        let procs = process_usage(&members);
                        usage.bytes = usage.bytes.saturating_add(procs.unlinked_bytes);
                        let memory = if procs.memory > limits.memory_bytes {
                            procs.proportional()
                        } else {
                            procs.memory
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
            "the sandbox stopped it: its processes held more than {} of memory together",
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

    /// Makes `depth` nested folders named `name` under `root` (through descriptors, as the code
    /// can, past what a path can name) and writes `bytes` into a file at level `file_at`.
    fn nest(root: &Path, name: &str, depth: usize, file_at: usize, bytes: usize) {
        use std::ffi::CString;
        let name = CString::new(name).unwrap();
        let file = CString::new("data").unwrap();
        let root = CString::new(root.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: plain system calls on descriptors this loop owns.
        unsafe {
            let mut fd = libc::open(root.as_ptr(), libc::O_RDONLY | libc::O_DIRECTORY);
            assert!(fd >= 0);
            for level in 1..=depth {
                assert_eq!(libc::mkdirat(fd, name.as_ptr(), 0o755), 0, "level {level}");
                let next = libc::openat(fd, name.as_ptr(), libc::O_RDONLY | libc::O_DIRECTORY);
                assert!(next >= 0, "level {level}");
                libc::close(fd);
                fd = next;
                if level == file_at {
                    let f = libc::openat(fd, file.as_ptr(), libc::O_WRONLY | libc::O_CREAT, 0o644);
                    assert!(f >= 0);
                    let data = vec![1u8; bytes];
                    assert_eq!(libc::write(f, data.as_ptr().cast(), bytes), bytes as isize);
                    libc::close(f);
                }
            }
            libc::close(fd);
        }
    }

    /// Files deeper than a path can name (4096 bytes) were not seen by the watchdog: 360 MiB at
    /// depth 2100 passed a 256 MiB limit. The walk goes by descriptors, a tree nested more than
    /// [`MAX_NESTING`] deep is a violation in itself, and any depth is removed.
    #[test]
    fn a_tree_deeper_than_a_path_can_name_is_measured_judged_and_removed() {
        let dir = tempfile::tempdir().unwrap();
        let long = "n".repeat(200);
        // 90 levels of 200-byte names: 18 KB of path to a 1 MiB file.
        nest(dir.path(), &long, 90, 90, 1 << 20);
        let usage = usage_of_tree(dir.path());
        assert_eq!(usage.entries, 91, "{usage:?}");
        assert!(usage.bytes >= 1 << 20, "{usage:?}");
        assert_eq!(usage.deepest, 90);
        assert_eq!(judge(usage, 64 << 20), None);
        let deep = tempfile::tempdir().unwrap();
        nest(deep.path(), "a", 2100, 2100, 4096);
        let usage = usage_of_tree(deep.path());
        assert!(usage.deepest > MAX_NESTING, "{usage:?}");
        assert_eq!(
            judge(usage, 64 << 20).unwrap(),
            format!("the sandbox stopped it: it nested folders more than {MAX_NESTING} deep")
        );
        for d in [dir, deep] {
            let path = d.path().to_path_buf();
            assert!(remove_deep(&path), "{}", path.display());
            assert!(!path.exists());
        }
    }

    /// Children forked from a process share its pages until they write them: 20 children of a
    /// process holding 100 MiB hold about 100 MiB, not 2 GiB (their resident sets, added up,
    /// made a forking submission "hold more than 1 GiB" that it did not hold).
    #[test]
    fn memory_shared_by_forked_children_is_counted_once() {
        if !super::super::running_as_root() || !Path::new("/usr/bin/python3").exists() {
            eprintln!("skipped: needs root and /usr/bin/python3");
            return;
        }
        use std::os::unix::process::CommandExt;
        let uid = super::super::identity::allocate();
        let mut parent = std::process::Command::new("/usr/bin/python3")
            .args([
                "-c",
                "import os, time\nb = bytearray(b'x' * (100 << 20))\n\
                 for i in range(20):\n    if os.fork() == 0:\n        time.sleep(30)\n\
                         os._exit(0)\ntime.sleep(30)\n",
            ])
            .uid(uid)
            .gid(uid)
            .spawn()
            .unwrap();
        let mut seen = ProcessUsage::default();
        for _ in 0..1000 {
            seen = process_usage(&Members::Uid(uid));
            if seen.processes == 21 {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        std::thread::sleep(Duration::from_millis(200));
        let cheap = process_usage(&Members::Uid(uid));
        let exact = cheap.proportional();
        super::super::identity::kill_all(uid);
        let _ = parent.wait();
        assert_eq!(seen.processes, 21, "{seen:?}");
        // Resident sets count the 100 MiB 21 times; proportional sets about once.
        assert!(cheap.memory > 1 << 30, "{cheap:?}");
        assert!(
            exact > 90 << 20 && exact < 250 << 20,
            "{exact} of {cheap:?}"
        );
    }

    /// Without an IPC namespace a uid's System V objects outlive its processes: they are found
    /// by owner and removed, and another uid's are not touched.
    #[test]
    fn a_uid_s_system_v_objects_are_measured_and_swept() {
        if !super::super::running_as_root() || !Path::new("/usr/bin/ipcmk").exists() {
            eprintln!("skipped: needs root and ipcmk");
            return;
        }
        use std::os::unix::process::CommandExt;
        let uid = super::super::identity::allocate();
        let other = super::super::identity::allocate();
        let make = |uid: u32, args: &[&str]| {
            let out = std::process::Command::new("/usr/bin/ipcmk")
                .args(args)
                .uid(uid)
                .gid(uid)
                .output()
                .unwrap();
            assert!(out.status.success(), "{out:?}");
        };
        make(uid, &["-M", "1048576"]);
        make(uid, &["-Q"]);
        make(uid, &["-S", "1"]);
        make(other, &["-M", "4096"]);
        let mine = ipc_objects(uid);
        let tables: Vec<&str> = mine.iter().map(|o| o.table).collect();
        assert_eq!(tables, ["shm", "msg", "sem"], "{mine:?}");
        assert_eq!(mine[0].bytes, 1 << 20);
        assert_eq!(
            process_usage(&Members::Uid(uid)).memory,
            1 << 20,
            "no process, the segment alone"
        );
        assert_eq!(sweep_ipc(uid), 3);
        assert!(ipc_objects(uid).is_empty());
        assert_eq!(ipc_objects(other).len(), 1);
        assert_eq!(sweep_ipc(other), 1);
    }

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
        assert_eq!(
            judge_memory((1 << 30) + 1, 1 << 30).unwrap(),
            "the sandbox stopped it: its processes held more than 1 GiB of memory together"
        );
        assert_eq!(judge_memory(1 << 30, 1 << 30), None);
        assert_eq!(human_bytes(1536 << 20), "1.5 GiB");
        assert_eq!(human_bytes(100), "100 bytes");
    }
}
