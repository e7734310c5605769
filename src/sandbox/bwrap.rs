//! The bubblewrap command line: which namespaces, which read-only view, what is mounted where,
//! and reading back what bubblewrap made (`--info-fd`).
//!
//! Promises: the view holds `/usr` and the `/bin`, `/sbin`, `/lib*` of the host (as links where
//! the host has merged `/usr`), the few `/etc` files the dynamic loader and Debian's
//! alternatives need, a fresh `/proc` of the new PID namespace, a minimal read-only `/dev`, a
//! `/tmp` that is a folder of the sandbox folder ([`super::scratch::TMP_DIR`]: the only writable
//! places are there), the sandbox folder at [`INSIDE`], and the extra paths a caller
//! exposes read-only. Nothing else of the host is there: no `/home`, `/root`, `/work`, no other
//! `/tmp` folder; the harness's own binary is covered with an empty file when it lies inside the
//! view (say `/usr/local/bin/rtoracle`).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Where the sandbox folder is seen from inside.
pub const INSIDE: &str = "/sandbox";

/// Where bubblewrap is looked for (never on the harness's `PATH`: a root harness must not run
/// whatever `bwrap` comes first there).
const PROGRAMS: [&str; 3] = ["/usr/bin/bwrap", "/usr/local/bin/bwrap", "/bin/bwrap"];

/// Top-level folders of the host shown read-only (or as the links they are).
const SYSTEM: [&str; 7] = [
    "/usr", "/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32",
];

/// `/etc` entries the loader (`ld.so.cache`) and Debian's alternatives (`libblas.so.3` of
/// numpy is such a link) need.
const ETC: [&str; 4] = [
    "/etc/ld.so.cache",
    "/etc/ld.so.conf",
    "/etc/ld.so.conf.d",
    "/etc/alternatives",
];

/// Folders never exposed whole (only the one file asked for is): exposing them would show
/// the grader's files or other sandboxes.
const NEVER_WHOLE: [&str; 8] = [
    "/", "/tmp", "/var/tmp", "/dev/shm", "/home", "/root", "/run", "/var",
];

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

/// Whether `path` is inside the system view.
pub fn in_system_view(path: &Path) -> bool {
    SYSTEM.iter().any(|s| path.starts_with(s))
}

/// What to expose read-only for `path` (a program or a file an adapter's arguments name): its
/// folder (the folder above `bin/` for a program in one, so a virtual environment or a Python
/// under `/opt` finds its libraries), or the file alone when that folder is one of the shared
/// ones (`/tmp`, `/home`, ...). Nothing for paths already in the system view.
pub fn exposure(path: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut paths = vec![path.to_path_buf()];
    if let Ok(real) = path.canonicalize()
        && real != path
    {
        paths.push(real);
    }
    for p in paths {
        if in_system_view(&p) || !p.is_absolute() {
            continue;
        }
        let parent = p.parent().map(Path::to_path_buf);
        let tree = match &parent {
            Some(dir) if dir.file_name().is_some_and(|n| n == "bin") => {
                dir.parent().map(Path::to_path_buf)
            }
            other => other.clone(),
        };
        let whole_ok = |d: &Path| {
            !NEVER_WHOLE.iter().any(|n| d == Path::new(n))
                && d.components().count() > 2
                && !is_home(d)
        };
        match tree {
            Some(d) if whole_ok(&d) => out.push(d),
            _ => out.push(p.clone()),
        }
    }
    out.sort();
    out.dedup();
    out
}

/// A user's home folder (`/home/x`) or the harness's `$HOME`.
fn is_home(dir: &Path) -> bool {
    dir.parent() == Some(Path::new("/home"))
        || std::env::var_os("HOME").is_some_and(|h| Path::new(&h) == dir)
}

/// The arguments of bubblewrap up to (not including) the program: namespaces, the view, the
/// folder at [`INSIDE`], the identity inside, the environment, `--info-fd` and `--block-fd` (the
/// sandbox's first process waits on it until the harness has set its limits).
pub fn args(
    dir: &Path,
    uid: u32,
    gid: u32,
    exposed: &[PathBuf],
    env: &[(&str, OsString)],
    info_fd: Option<i32>,
    block_fd: Option<i32>,
) -> Vec<OsString> {
    let mut a: Vec<OsString> = Vec::with_capacity(96);
    let mut push = |words: &[&dyn AsRef<std::ffi::OsStr>]| {
        for w in words {
            a.push(w.as_ref().to_os_string());
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
    push(&[&"--uid", &uid.to_string(), &"--gid", &gid.to_string()]);
    for s in SYSTEM {
        let p = Path::new(s);
        match std::fs::symlink_metadata(p) {
            Ok(m) if m.file_type().is_symlink() => {
                if let Ok(target) = std::fs::read_link(p) {
                    push(&[&"--symlink", &target, &p]);
                }
            }
            Ok(m) if m.is_dir() => push(&[&"--ro-bind", &p, &p]),
            _ => {}
        }
    }
    for e in ETC {
        push(&[&"--ro-bind-try", &e, &e]);
    }
    // `/dev` read-only (its device nodes still work), so `/dev/shm` is not writable; `/tmp` is
    // a folder of the sandbox folder, where the watchdog measures it (a tmpfs would live in the
    // host's memory, unbounded: bubblewrap 0.8 has no `--size`).
    let tmp = dir.join(super::scratch::TMP_DIR);
    push(&[
        &"--proc",
        &"/proc",
        &"--dev",
        &"/dev",
        &"--remount-ro",
        &"/dev",
    ]);
    push(&[&"--bind", &tmp, &"/tmp"]);
    // After the private /tmp, so an exposed path under /tmp is not hidden by it.
    for p in exposed {
        push(&[&"--ro-bind-try", p, p]);
    }
    push(&[&"--bind", &dir, &INSIDE, &"--chdir", &INSIDE]);
    // The harness's binary, when the view shows it.
    if let Ok(exe) = std::env::current_exe()
        && (in_system_view(&exe) || exposed.iter().any(|e| exe.starts_with(e)))
    {
        push(&[&"--ro-bind", &"/dev/null", &exe]);
    }
    push(&[&"--clearenv"]);
    for (k, v) in env {
        push(&[&"--setenv", k, v]);
    }
    if let Some(fd) = info_fd {
        push(&[&"--info-fd", &fd.to_string()]);
    }
    if let Some(fd) = block_fd {
        push(&[&"--block-fd", &fd.to_string()]);
    }
    a
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
    fn shared_folders_are_never_exposed_whole() {
        assert_eq!(
            exposure(Path::new("/tmp/adapter")),
            [PathBuf::from("/tmp/adapter")]
        );
        assert_eq!(
            exposure(Path::new("/usr/bin/python3")),
            Vec::<PathBuf>::new()
        );
        assert_eq!(
            exposure(Path::new("/opt/py311/bin/python3")),
            [PathBuf::from("/opt/py311")]
        );
        assert_eq!(
            exposure(Path::new("/home/ann/adapter")),
            [PathBuf::from("/home/ann/adapter")]
        );
        assert_eq!(
            exposure(Path::new("/home/ann/tracer/adapter")),
            [PathBuf::from("/home/ann/tracer")]
        );
    }

    #[test]
    fn namespace_links_give_their_inode() {
        assert_eq!(inode("net:[4026531833]"), Some(4026531833));
        assert_eq!(inode("garbage"), None);
    }
}
