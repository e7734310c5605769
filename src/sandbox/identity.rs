//! Who the code runs as: whether the harness is root, a user and group id of its own for every
//! [`Sandbox`](super::lifecycle::Sandbox) made by a root harness, and the kill of every process of such an id.
//!
//! Promises:
//! - [`allocate`] returns an id in `[2^30, 2^31)` that has no `passwd` entry and no live process,
//!   built from this process's id and a per-process counter, so two graders running at once (and
//!   two members of one batch) never share one.
//! - [`kill_all`] ends every process whose real or saved uid is that id (a forked helper switches
//!   to the id and calls `kill(-1, SIGKILL)`, which reaches exactly the processes that id may
//!   signal), and repeats until a scan of `/proc` finds none running. Double-forked `setsid`
//!   sleepers are processes of the id like any other, so they end too.

use std::ffi::CString;
use std::sync::atomic::{AtomicU32, Ordering};

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

/// The first id handed out (2^30): far above any real account, below `2^31` (some tools treat
/// larger ids as negative).
const BASE: u32 = 1 << 30;

static COUNTER: AtomicU32 = AtomicU32::new(0);

/// Whether `uid` is in the range [`allocate`] hands out: a sandbox's identity.
pub fn is_sandbox_uid(uid: u32) -> bool {
    (BASE..1u32 << 31).contains(&uid)
}

/// Whether `uid` has a `passwd` entry.
fn has_account(uid: u32) -> bool {
    // SAFETY: getpwuid returns a pointer to static storage or null; only its nullness is read.
    unsafe { !libc::getpwuid(uid).is_null() }
}

/// A fresh id for one submission: `2^30 + (pid mod 2^22) * 256 + k`, with `k` from a
/// per-process counter; ids with an account or a live process are skipped.
pub fn allocate() -> u32 {
    let pid = std::process::id() & 0x3f_ffff;
    let mut uid = BASE;
    for _ in 0..256 {
        let k = COUNTER.fetch_add(1, Ordering::Relaxed) & 0xff;
        uid = BASE + (pid << 8) + k;
        if !has_account(uid) && processes_of(uid).is_empty() {
            return uid;
        }
    }
    // Every id of this process is busy (256 sandboxes alive at once): reuse the last after
    // ending what runs under it, which can only be a leftover.
    kill_all(uid);
    uid
}

/// Every process `/proc` lists now: its id and its `/proc/<pid>` folder (none when `/proc`
/// cannot be read).
pub(crate) fn proc_entries() -> impl Iterator<Item = (u32, std::path::PathBuf)> {
    std::fs::read_dir("/proc")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|entry| {
            let pid = entry.file_name().to_str()?.parse::<u32>().ok()?;
            Some((pid, entry.path()))
        })
}

/// The ids of the running (not zombie) processes whose real uid is `uid`.
pub fn processes_of(uid: u32) -> Vec<u32> {
    let mut found = Vec::new();
    for (pid, proc_dir) in proc_entries() {
        let Ok(status) = std::fs::read_to_string(proc_dir.join("status")) else {
            continue;
        };
        let mut real = None;
        let mut zombie = false;
        for line in status.lines() {
            if let Some(rest) = line.strip_prefix("State:") {
                zombie = matches!(rest.trim_start().chars().next(), Some('Z' | 'X'));
            } else if let Some(rest) = line.strip_prefix("Uid:") {
                real = rest
                    .split_whitespace()
                    .next()
                    .and_then(|s| s.parse::<u32>().ok());
            }
        }
        if real == Some(uid) && !zombie {
            found.push(pid);
        }
    }
    found
}

/// Sends `SIGKILL` to every process `uid` may signal, from a forked helper running as `uid`;
/// repeats (up to 50 times, 2 ms apart) until no process of `uid` runs. Needs root; does
/// nothing for uid 0 or the harness's own uid. Returns whether none is left.
pub fn kill_all(uid: u32) -> bool {
    // SAFETY: getuid has no preconditions.
    let me = unsafe { libc::getuid() };
    if uid == 0 || uid == me || me != 0 {
        return false;
    }
    for _ in 0..50 {
        if processes_of(uid).is_empty() {
            return true;
        }
        // SAFETY: the child makes only async-signal-safe calls (setgroups, setgid, setuid,
        // kill, _exit) and allocates nothing, as required after fork in a threaded process.
        unsafe {
            let pid = libc::fork();
            if pid == 0 {
                if libc::setgroups(0, std::ptr::null()) == 0
                    && libc::setgid(uid) == 0
                    && libc::setuid(uid) == 0
                {
                    libc::kill(-1, libc::SIGKILL);
                }
                libc::_exit(0);
            }
            if pid > 0 {
                let mut status = 0;
                libc::waitpid(pid, &mut status, 0);
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    processes_of(uid).is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_distinct_unused_and_in_range() {
        let a = allocate();
        let b = allocate();
        assert_ne!(a, b);
        for id in [a, b] {
            assert!((BASE..1u32 << 31).contains(&id), "{id}");
            assert!(!has_account(id));
        }
        // The pid is part of the id, so another grader's ids differ.
        assert_eq!((a - BASE) >> 8, std::process::id() & 0x3f_ffff);
    }

    #[test]
    fn kill_all_ends_every_process_of_the_id_and_only_those() {
        if !super::running_as_root() {
            eprintln!("skipped: needs root");
            return;
        }
        let uid = allocate();
        // Two sleepers of the id, one of them in its own session, and one of ours.
        use std::os::unix::process::CommandExt;
        let mut theirs = std::process::Command::new("/bin/sh")
            .args(["-c", "setsid sleep 30 & sleep 30"])
            .uid(uid)
            .gid(uid)
            .spawn()
            .unwrap();
        let mut ours = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let mut waited = 0;
        while processes_of(uid).len() < 3 && waited < 200 {
            std::thread::sleep(std::time::Duration::from_millis(10));
            waited += 1;
        }
        assert_eq!(processes_of(uid).len(), 3, "sh, sleep and the setsid sleep");
        assert!(kill_all(uid));
        let _ = theirs.wait();
        assert!(processes_of(uid).is_empty());
        // Ours was not touched.
        assert!(ours.try_wait().unwrap().is_none());
        let _ = ours.kill();
        let _ = ours.wait();
    }
}
