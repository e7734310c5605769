//! System V and POSIX IPC of a sandbox's code: the limits written inside its IPC namespace,
//! the shared memory it holds there (counted from outside), and the objects a uid left in the
//! harness's own namespace (found by owner and removed).
//!
//! Promises:
//! - [`Limits::for_memory`] bounds a namespace's System V shared memory to the policy's
//!   `memory_bytes` (`shmmax`, `shmall`), and its segments, message queues, semaphores and
//!   POSIX message queues to a few (a new IPC namespace allows 32,000 queues and segments of any
//!   size). They are written from inside the namespace: by the fallback's child before it drops
//!   root ([`Limits::write_in_child`]), by the harness for bubblewrap's ([`Limits::write_for`],
//!   which enters the namespace on a thread of its own and needs root). POSIX message queues are
//!   also bounded by `RLIMIT_MSGQUEUE`, in every mode.
//! - [`shm_bytes_of`] counts the System V shared memory of other IPC namespaces (the code's),
//!   entering each from the calling thread and coming back (root only: `None` otherwise).
//! - [`ipc_objects`] and [`sweep_ipc`]: the objects a uid owns or made in the harness's own
//!   namespace (where the fallback could not make one), which outlive every process.

use std::ffi::CString;
use std::os::fd::AsRawFd;

/// Values written to a new IPC namespace's `/proc/sys` files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Limits {
    /// `(file, value)`, each value as written (no newline needed).
    entries: Vec<(CString, Vec<u8>)>,
}

impl Limits {
    /// The limits of a sandbox whose processes may hold `memory_bytes` together.
    pub fn for_memory(memory_bytes: u64) -> Limits {
        // SAFETY: sysconf has no preconditions.
        let page = unsafe { libc::sysconf(libc::_SC_PAGESIZE) }.max(4096) as u64;
        let values: [(&std::ffi::CStr, String); 10] = [
            (c"/proc/sys/kernel/shmmax", memory_bytes.to_string()),
            (
                c"/proc/sys/kernel/shmall",
                memory_bytes.div_ceil(page).to_string(),
            ),
            (c"/proc/sys/kernel/shmmni", "64".into()),
            (c"/proc/sys/kernel/msgmni", "16".into()),
            (c"/proc/sys/kernel/msgmnb", "65536".into()),
            (c"/proc/sys/kernel/msgmax", "8192".into()),
            (c"/proc/sys/kernel/sem", "250 4096 32 32".into()),
            (c"/proc/sys/fs/mqueue/queues_max", "16".into()),
            (c"/proc/sys/fs/mqueue/msg_max", "10".into()),
            (c"/proc/sys/fs/mqueue/msgsize_max", "8192".into()),
        ];
        Limits {
            entries: values
                .into_iter()
                .map(|(f, v)| (f.to_owned(), v.into_bytes()))
                .collect(),
        }
    }

    /// Writes the limits into the calling process's IPC namespace; whether every one was.
    ///
    /// # Safety
    /// Safe after fork: only open, write and close, nothing allocated.
    pub unsafe fn write_in_child(&self) -> bool {
        let mut all = true;
        for (file, value) in &self.entries {
            // SAFETY: plain system calls on a path and a buffer made before the fork.
            unsafe {
                let fd = libc::open(file.as_ptr(), libc::O_WRONLY | libc::O_CLOEXEC);
                let written = fd >= 0
                    && libc::write(fd, value.as_ptr().cast(), value.len()) == value.len() as isize;
                if fd >= 0 {
                    libc::close(fd);
                }
                all &= written;
            }
        }
        all
    }

    /// Writes the limits into the IPC namespace of process `pid`, from the calling thread,
    /// which stays in that namespace (call it from a thread that ends afterwards). Needs root.
    pub fn write_for(&self, pid: i32) -> bool {
        let Ok(ns) = std::fs::File::open(format!("/proc/{pid}/ns/ipc")) else {
            return false;
        };
        // SAFETY: setns with a namespace descriptor; it changes this thread alone.
        if unsafe { libc::setns(ns.as_raw_fd(), libc::CLONE_NEWIPC) } != 0 {
            return false;
        }
        self.entries
            .iter()
            .all(|(file, value)| std::fs::write(file.to_str().unwrap_or_default(), value).is_ok())
    }
}

/// The bytes of System V shared memory segments in the IPC namespaces of `pids` (one process
/// per namespace), counted from inside each: the calling thread enters it and comes back.
/// `None` when a namespace cannot be entered (not root).
pub fn shm_bytes_of(pids: &[u32]) -> Option<u64> {
    if pids.is_empty() {
        return Some(0);
    }
    let home = std::fs::File::open("/proc/thread-self/ns/ipc").ok()?;
    let mut total = 0u64;
    let mut entered = true;
    for pid in pids {
        let Ok(ns) = std::fs::File::open(format!("/proc/{pid}/ns/ipc")) else {
            continue;
        };
        // SAFETY: setns with namespace descriptors; it changes this thread alone.
        if unsafe { libc::setns(ns.as_raw_fd(), libc::CLONE_NEWIPC) } != 0 {
            entered = false;
            continue;
        }
        let text = std::fs::read_to_string("/proc/sysvipc/shm").unwrap_or_default();
        // SAFETY: as above, back to the thread's own namespace.
        if unsafe { libc::setns(home.as_raw_fd(), libc::CLONE_NEWIPC) } != 0 {
            return None;
        }
        total = total.saturating_add(segment_bytes(&text, None));
    }
    entered.then_some(total)
}

/// The bytes of the segments listed in a `/proc/sysvipc/shm` text, of all owners or of `uid`.
fn segment_bytes(text: &str, uid: Option<u32>) -> u64 {
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let words: Vec<&str> = line.split_whitespace().collect();
            let number = |i: usize| words.get(i).and_then(|w| w.parse::<u64>().ok());
            let ours = uid.is_none_or(|u| [7, 9].iter().any(|&i| number(i) == Some(u as u64)));
            ours.then(|| number(3).unwrap_or(0))
        })
        .sum()
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn segments_are_summed_by_owner_or_all() {
        let text = "       key      shmid perms                  size  cpid  lpid nattch   uid   gid  cuid  cgid\n\
                    0 1 1666 1048576 10 0 0 1073741824 1073741824 1073741824 1073741824\n\
                    0 2 1666 4096 10 0 0 5 5 5 5\n";
        assert_eq!(segment_bytes(text, None), (1 << 20) + 4096);
        assert_eq!(segment_bytes(text, Some(1 << 30)), 1 << 20);
        assert_eq!(segment_bytes(text, Some(7)), 0);
    }

    /// Without an IPC namespace a uid's System V objects outlive its processes: they are found
    /// by owner and removed, and another uid's are not touched.
    #[test]
    fn a_uid_s_system_v_objects_are_measured_and_swept() {
        if !crate::sandbox::identity::running_as_root() || !Path::new("/usr/bin/ipcmk").exists() {
            eprintln!("skipped: needs root and ipcmk");
            return;
        }
        use std::os::unix::process::CommandExt;
        let uid = crate::sandbox::identity::allocate();
        let other = crate::sandbox::identity::allocate();
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
        let table = std::fs::read_to_string("/proc/sysvipc/shm").unwrap();
        assert_eq!(segment_bytes(&table, Some(uid)), 1 << 20);
        assert_eq!(sweep_ipc(uid), 3);
        assert!(ipc_objects(uid).is_empty());
        assert_eq!(ipc_objects(other).len(), 1);
        assert_eq!(sweep_ipc(other), 1);
    }
}
