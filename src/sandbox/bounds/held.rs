//! What a sandbox's processes hold: which processes are its code's ([`Members`]), their
//! resident memory (a page shared by forked processes once), the unlinked files and memfds they
//! hold open, the System V shared memory of a uid or of their own IPC namespaces ([`crate::sandbox::bounds::ipc`]),
//! and the tmpfs of their own view.

use std::collections::{HashMap, HashSet};
use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// Which processes are the code's, for the `Watchdog`.
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
    /// The System V shared memory counted in `memory`: a uid's in the harness's IPC namespace,
    /// and all of the code's own IPC namespaces' (counted from inside them, root only).
    pub ipc_bytes: u64,
    /// What the tmpfs at `/tmp` of the code's own views holds (bubblewrap's, the fallback's):
    /// files, counted with the files.
    pub tmpfs_bytes: u64,
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

/// The inode of `/proc/<pid>/ns/<ns>` under `proc_dir`.
fn ns_inode(proc_dir: &Path, ns: &str) -> Option<u64> {
    let link = std::fs::read_link(proc_dir.join("ns").join(ns)).ok()?;
    let link = link.to_string_lossy();
    link.split_once('[')?.1.strip_suffix(']')?.parse().ok()
}

/// Whether the process at `proc_dir` is one of `members` (sessions and PID namespaces as
/// listed in `sessions` and `namespaces`; a uid's processes are checked by their status).
fn is_member(members: &Members, proc_dir: &Path, sessions: &[i32], namespaces: &[u64]) -> bool {
    match members {
        Members::Uid(_) => true,
        Members::PidNamespaces(_) => {
            ns_inode(proc_dir, "pid").is_some_and(|ns| namespaces.contains(&ns))
        }
        Members::Sessions(_) => std::fs::read_to_string(proc_dir.join("stat"))
            .ok()
            .and_then(|stat| {
                // The fields after the command's closing parenthesis: state, ppid, pgrp,
                // session.
                let rest = stat.rsplit_once(')')?.1.to_string();
                rest.split_whitespace().nth(3)?.parse::<i32>().ok()
            })
            .is_some_and(|sid| sessions.contains(&sid)),
    }
}

/// Adds the blocks of the unlinked regular files the process at `proc_dir` holds open to
/// `bytes`, each file (in `seen`) once.
fn add_unlinked(proc_dir: &Path, seen: &mut HashSet<(u64, u64)>, bytes: &mut u64) {
    let Ok(fds) = std::fs::read_dir(proc_dir.join("fd")) else {
        return;
    };
    for fd in fds.flatten() {
        // Followed: the open file itself (a memfd or a deleted file has no other name).
        let Ok(meta) = std::fs::metadata(fd.path()) else {
            continue;
        };
        if meta.is_file() && meta.nlink() == 0 && seen.insert((meta.dev(), meta.ino())) {
            *bytes = bytes.saturating_add(meta.blocks().saturating_mul(512));
        }
    }
}

/// The bytes the tmpfs at `/tmp` of process `pid`'s own view holds (0 when its `/tmp` is not a
/// tmpfs).
fn tmpfs_bytes_of(pid: u32) -> u64 {
    const TMPFS_MAGIC: i64 = 0x0102_1994;
    let Ok(path) = std::ffi::CString::new(format!("/proc/{pid}/root/tmp")) else {
        return 0;
    };
    // SAFETY: statfs fills the struct it is given.
    unsafe {
        let mut st: libc::statfs = std::mem::zeroed();
        if libc::statfs(path.as_ptr(), &mut st) != 0 || st.f_type as i64 != TMPFS_MAGIC {
            return 0;
        }
        (st.f_blocks.saturating_sub(st.f_bfree) as u64).saturating_mul(st.f_bsize as u64)
    }
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
    let own = Path::new("/proc/self");
    let (own_mnt, own_ipc) = (ns_inode(own, "mnt"), ns_inode(own, "ipc"));
    // One process of each mount and IPC namespace of the code's that is not the harness's.
    let mut views: HashMap<u64, u32> = HashMap::new();
    let mut ipcs: HashMap<u64, u32> = HashMap::new();
    let mut files = HashSet::new();
    for (pid, proc_dir) in crate::sandbox::identity::proc_entries() {
        if pid == std::process::id() || !is_member(members, &proc_dir, &sessions, &namespaces) {
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
        usage.processes += 1;
        let kb = status_number(&status, "RssAnon:").unwrap_or(0)
            + status_number(&status, "RssShmem:").unwrap_or(0);
        let resident = kb.saturating_mul(1024);
        usage.memory = usage.memory.saturating_add(resident);
        usage.pids.push((pid, resident));
        if let Some(mnt) = ns_inode(&proc_dir, "mnt").filter(|m| Some(*m) != own_mnt) {
            views.entry(mnt).or_insert(pid);
        }
        if let Some(ipc) = ns_inode(&proc_dir, "ipc").filter(|i| Some(*i) != own_ipc) {
            ipcs.entry(ipc).or_insert(pid);
        }
        add_unlinked(&proc_dir, &mut files, &mut usage.unlinked_bytes);
    }
    usage.tmpfs_bytes = views.values().map(|&pid| tmpfs_bytes_of(pid)).sum();
    let theirs: Vec<u32> = ipcs.values().copied().collect();
    usage.ipc_bytes = crate::sandbox::bounds::ipc::shm_bytes_of(&theirs).unwrap_or(0);
    if let Members::Uid(uid) = members {
        let own_ns: u64 = crate::sandbox::bounds::ipc::ipc_objects(*uid)
            .iter()
            .filter(|o| o.table == "shm")
            .map(|o| o.bytes)
            .sum();
        usage.ipc_bytes = usage.ipc_bytes.saturating_add(own_ns);
    }
    usage.memory = usage.memory.saturating_add(usage.ipc_bytes);
    usage
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// Children forked from a process share its pages until they write them: 20 children of a
    /// process holding 100 MiB hold about 100 MiB, not 2 GiB (their resident sets, added up,
    /// made a forking submission "hold more than 1 GiB" that it did not hold).
    #[test]
    fn memory_shared_by_forked_children_is_counted_once() {
        if !crate::sandbox::identity::running_as_root() || !Path::new("/usr/bin/python3").exists() {
            eprintln!("skipped: needs root and /usr/bin/python3");
            return;
        }
        use std::os::unix::process::CommandExt;
        let uid = crate::sandbox::identity::allocate();
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
        crate::sandbox::identity::kill_all(uid);
        let _ = parent.wait();
        assert_eq!(seen.processes, 21, "{seen:?}");
        // Resident sets count the 100 MiB 21 times; proportional sets about once.
        assert!(cheap.memory > 1 << 30, "{cheap:?}");
        assert!(
            exact > 90 << 20 && exact < 250 << 20,
            "{exact} of {cheap:?}"
        );
    }

    /// A uid's System V segment with no process left counts as the uid's memory.
    #[test]
    fn a_uid_s_segment_counts_as_its_memory() {
        if !crate::sandbox::identity::running_as_root() || !Path::new("/usr/bin/ipcmk").exists() {
            eprintln!("skipped: needs root and ipcmk");
            return;
        }
        use std::os::unix::process::CommandExt;
        let uid = crate::sandbox::identity::allocate();
        let out = std::process::Command::new("/usr/bin/ipcmk")
            .args(["-M", "1048576"])
            .uid(uid)
            .gid(uid)
            .output()
            .unwrap();
        assert!(out.status.success(), "{out:?}");
        let usage = process_usage(&Members::Uid(uid));
        assert_eq!(crate::sandbox::bounds::ipc::sweep_ipc(uid), 1);
        assert_eq!(usage.memory, 1 << 20, "no process, the segment alone");
    }
}
