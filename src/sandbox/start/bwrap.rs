//! The bubblewrap command line: which namespaces, which view, what is mounted where, and
//! reading back what bubblewrap made (`--info-fd`).
//!
//! Promises: the sandbox sees the system view and the exposed paths ([`crate::sandbox::view`]: read-only,
//! its rtoracle binaries covered with an empty file), a fresh `/proc` of the new PID namespace, a
//! minimal read-only `/dev` whose `/dev/shm` is a tmpfs of [`SHM_BYTES`] (the semaphores and
//! locks of Python's `multiprocessing`), a `/tmp` that is a tmpfs of bounded size
//! ([`Args::tmp_bytes`]: its pages are the host's memory), and the sandbox folder at [`INSIDE`]:
//! those three are the only writable places. The root (bubblewrap's own tmpfs, which would hold
//! whatever the code wrote there in the host's memory, unbounded) is remounted read-only last.
//! The harness's own binary is covered wherever the view shows it.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::sandbox::view::{INSIDE, SystemEntry, View, system};

/// The size of the tmpfs at `/dev/shm`: room for the POSIX semaphores and locks of Python's
/// `multiprocessing` (a `Pool` makes a handful, a page each), small enough that what it holds
/// in the host's memory stays a bounded extra beside the memory limit.
pub const SHM_BYTES: u64 = 4 << 20;

/// Where bubblewrap is looked for (never on the harness's `PATH`: a root harness must not run
/// whatever `bwrap` comes first there).
const PROGRAMS: [&str; 3] = ["/usr/bin/bwrap", "/usr/local/bin/bwrap", "/bin/bwrap"];

/// The namespaces asked for, by the names bubblewrap's `--info-fd` uses (`user` is read from
/// `/proc`).
pub const NAMESPACES: [(&str, &str); 6] = [
    ("user", "user"),
    ("pid", "pid-namespace"),
    ("net", "net-namespace"),
    ("ipc", "ipc-namespace"),
    ("mount", "mnt-namespace"),
    ("uts", "uts-namespace"),
];

/// The bubblewrap program, if installed in a system folder.
pub fn program() -> Option<PathBuf> {
    PROGRAMS.iter().map(PathBuf::from).find(|p| p.is_file())
}

/// What one bubblewrap command is made of, up to (not including) the program.
#[derive(Debug)]
pub struct Args<'a> {
    /// The sandbox folder on the host, shown at [`INSIDE`].
    pub dir: &'a Path,
    /// The user and group ids inside (those of the code: bubblewrap runs as them).
    pub uid: u32,
    /// See `uid`.
    pub gid: u32,
    /// What is shown of the host beyond the system view, and what is covered.
    pub view: &'a View,
    /// The size of `/tmp`'s tmpfs in bytes.
    pub tmp_bytes: u64,
    /// The code's environment.
    pub env: &'a [(&'a str, OsString)],
    /// `--info-fd`: where bubblewrap reports the first process and its namespaces.
    pub info_fd: Option<i32>,
    /// `--block-fd`: what the first process waits on until the harness has set its limits.
    pub block_fd: Option<i32>,
}

/// The arguments of bubblewrap up to (not including) the program (see the module's promises).
pub fn args(a: &Args) -> Vec<OsString> {
    let mut out: Vec<OsString> = Vec::with_capacity(128);
    let mut push = |words: &[&dyn AsRef<std::ffi::OsStr>]| {
        for w in words {
            out.push(w.as_ref().to_os_string());
        }
    };
    push(&[
        &"--unshare-user",
        &"--unshare-pid",
        &"--unshare-ipc",
        &"--unshare-net",
        &"--unshare-uts",
        &"--unshare-cgroup-try",
        &"--disable-userns",
        &"--die-with-parent",
        &"--new-session",
        &"--hostname",
        &"sandbox",
        &"--cap-drop",
        &"ALL",
    ]);
    push(&[&"--uid", &a.uid.to_string(), &"--gid", &a.gid.to_string()]);
    for entry in system() {
        match entry {
            SystemEntry::Link(p, target) => push(&[&"--symlink", &target, &p]),
            SystemEntry::Shown(p) => push(&[&"--ro-bind", &p, &p]),
        }
    }
    // `/dev` read-only (its device nodes still work), but for `/dev/shm`, a small tmpfs of its
    // own (mounted before the remount, which leaves it writable); `/tmp` a tmpfs whose size
    // bounds what it holds in the host's memory.
    push(&[
        &"--proc",
        &"/proc",
        &"--dev",
        &"/dev",
        &"--size",
        &SHM_BYTES.to_string(),
        &"--tmpfs",
        &"/dev/shm",
        &"--remount-ro",
        &"/dev",
    ]);
    push(&[&"--size", &a.tmp_bytes.to_string(), &"--tmpfs", &"/tmp"]);
    // After /tmp, so an exposed path under /tmp is not hidden by it.
    for p in &a.view.exposed {
        push(&[&"--ro-bind-try", p, p]);
    }
    push(&[&"--bind", &a.dir, &INSIDE, &"--chdir", &INSIDE]);
    for p in &a.view.hidden {
        push(&[&"--ro-bind-try", &"/dev/null", p]);
    }
    push(&[&"--remount-ro", &"/"]);
    push(&[&"--clearenv"]);
    for (k, v) in a.env {
        push(&[&"--setenv", k, v]);
    }
    if let Some(fd) = a.info_fd {
        push(&[&"--info-fd", &fd.to_string()]);
    }
    if let Some(fd) = a.block_fd {
        push(&[&"--block-fd", &fd.to_string()]);
    }
    out
}

/// The namespaces bubblewrap reports as new (their inode differs from the harness's own), in
/// the order of [`NAMESPACES`], and the pid of the sandbox's first process.
pub fn made_namespaces(info: &str) -> (Vec<String>, Option<u32>) {
    let Ok(v) = serde_json::from_str::<serde_json::Value>(info) else {
        return (Vec::new(), None);
    };
    let child = v["child-pid"].as_u64().map(|p| p as u32);
    let own = |ns: &str| {
        let ns = if ns == "mount" { "mnt" } else { ns };
        std::fs::read_link(format!("/proc/self/ns/{ns}"))
            .ok()
            .and_then(|l| inode(&l.to_string_lossy()))
    };
    let mut made = Vec::new();
    for (name, key) in NAMESPACES {
        let theirs = if name == "user" {
            child.and_then(|pid| {
                std::fs::read_link(format!("/proc/{pid}/ns/user"))
                    .ok()
                    .and_then(|l| inode(&l.to_string_lossy()))
            })
        } else {
            v[key].as_u64()
        };
        if let (Some(t), Some(o)) = (theirs, own(name))
            && t != o
        {
            made.push(name.to_string());
        }
    }
    (made, child)
}

/// The inode of a namespace link such as `net:[4026531833]`.
fn inode(link: &str) -> Option<u64> {
    link.split_once('[')?.1.strip_suffix(']')?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn namespace_links_give_their_inode() {
        assert_eq!(inode("net:[4026531833]"), Some(4026531833));
        assert_eq!(inode("garbage"), None);
    }
}
