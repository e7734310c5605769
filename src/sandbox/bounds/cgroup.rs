//! Cgroups v2, where the host delegates them to the harness: each sandbox's processes in a
//! cgroup of their own, with the kernel's bound behind the watchdog's (`memory.max`: its memory
//! and its files together, no swap; `pids.max`) and a CPU weight of its own (`cpu.weight`: a
//! submission of many processes gets the share of one, below the harness's), said in the facts;
//! where they are not delegated, the facts say why, and the other limits hold alone.
//!
//! Promises:
//! - [`delegation`] (once per process): the harness's cgroup (from `/proc/self/cgroup` and the
//!   `cgroup2` mount) must offer the `memory` and `cpu` controllers and be writable. To give
//!   them to sandboxes, the harness moves itself into a leaf of its cgroup (`rtoracle-harness`;
//!   a cgroup with processes cannot hand controllers down) and enables them; where other
//!   processes share its cgroup this fails, the harness is moved back, and cgroups are not used.
//! - [`Group::make`] makes a sandbox's cgroup; the child joins it before it drops root or
//!   executes anything ([`Group::procs_file`]), so every process of the code is in it;
//!   [`Group::kill`] ends them all (`cgroup.kill`); [`Group::oom_kills`] says whether the kernel
//!   ended one at `memory.max`. Dropping a group removes it once it is empty.

use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Duration;

/// The controllers a sandbox's cgroup needs.
const NEEDED: [&str; 2] = ["memory", "cpu"];

/// A sandbox's CPU weight (the default, and so the harness's, is 100).
pub const CPU_WEIGHT: u32 = 50;

/// What `memory.max` allows above the policy's memory and files: the page cache of what the
/// code reads (numpy's libraries), which the kernel reclaims before it stops anything.
const PAGE_CACHE_SLACK: u64 = 128 << 20;

/// The folder the sandboxes' cgroups are made in, or why none can be.
pub fn delegation() -> Result<&'static Path, &'static str> {
    static DELEGATION: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    DELEGATION
        .get_or_init(set_up)
        .as_ref()
        .map(PathBuf::as_path)
        .map_err(String::as_str)
}

/// The cgroup v2 folder of this process: `/proc/self/cgroup`'s `0::PATH` under the `cgroup2`
/// mount of `/proc/self/mountinfo`.
fn own_cgroup() -> Result<PathBuf, String> {
    let cgroup = std::fs::read_to_string("/proc/self/cgroup").map_err(|e| e.to_string())?;
    let mountinfo = std::fs::read_to_string("/proc/self/mountinfo").map_err(|e| e.to_string())?;
    locate(&cgroup, &mountinfo)
}

/// [`own_cgroup`] from the two files' texts.
fn locate(cgroup: &str, mountinfo: &str) -> Result<PathBuf, String> {
    let path = cgroup
        .lines()
        .find_map(|l| l.strip_prefix("0::"))
        .ok_or("this process is in no cgroup v2 hierarchy")?;
    let mount = mountinfo
        .lines()
        .find(|l| {
            l.split_once(" - ")
                .is_some_and(|(_, r)| r.starts_with("cgroup2 "))
        })
        .ok_or("no cgroup v2 file system is mounted")?;
    let fields: Vec<&str> = mount.split(' ').collect();
    let (root, point) = (fields.get(3).copied(), fields.get(4).copied());
    let (Some(root), Some(point)) = (root, point) else {
        return Err("the cgroup v2 mount cannot be read".into());
    };
    let inside = Path::new(path)
        .strip_prefix(root)
        .map_err(|_| format!("this process's cgroup {path} is outside the mounted {root}"))?;
    Ok(Path::new(point).join(inside))
}

/// Finds and prepares the delegation (see the module's promises).
fn set_up() -> Result<PathBuf, String> {
    let own = own_cgroup()?;
    let controllers = std::fs::read_to_string(own.join("cgroup.controllers")).unwrap_or_default();
    let offered: Vec<&str> = controllers.split_whitespace().collect();
    if let Some(missing) = NEEDED.iter().find(|c| !offered.contains(c)) {
        return Err(format!(
            "the cgroup v2 controller {missing} is not delegated to {} (it offers: {})",
            own.display(),
            if offered.is_empty() {
                "none".to_string()
            } else {
                offered.join(" ")
            }
        ));
    }
    let enabled = std::fs::read_to_string(own.join("cgroup.subtree_control")).unwrap_or_default();
    if NEEDED
        .iter()
        .all(|c| enabled.split_whitespace().any(|e| e == *c))
    {
        return Ok(own);
    }
    // A cgroup with processes cannot hand controllers down: move into a leaf first.
    let leaf = own.join("rtoracle-harness");
    let why = |e: std::io::Error| format!("{} is not delegated ({e})", own.display());
    match std::fs::create_dir(&leaf) {
        Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => return Err(why(e)),
        _ => {}
    }
    let pid = std::process::id().to_string();
    std::fs::write(leaf.join("cgroup.procs"), &pid).map_err(why)?;
    let wanted: Vec<String> = NEEDED.iter().map(|c| format!("+{c}")).collect();
    if let Err(e) = std::fs::write(own.join("cgroup.subtree_control"), wanted.join(" ")) {
        let _ = std::fs::write(own.join("cgroup.procs"), &pid);
        let _ = std::fs::remove_dir(&leaf);
        return Err(format!(
            "{} cannot hand its controllers to sandboxes (other processes share it: {e})",
            own.display()
        ));
    }
    // pids too, where offered (best effort).
    if offered.contains(&"pids") {
        let _ = std::fs::write(own.join("cgroup.subtree_control"), "+pids");
    }
    Ok(own)
}

/// One sandbox's cgroup.
#[derive(Debug)]
pub struct Group {
    path: PathBuf,
    procs: CString,
}

impl Group {
    /// Makes a cgroup under `base` for a sandbox whose code may hold `memory_bytes` and keep
    /// `file_bytes` of files (in memory, in a tmpfs) with at most `processes` processes.
    pub fn make(
        base: &Path,
        memory_bytes: u64,
        file_bytes: u64,
        processes: u64,
    ) -> Result<Group, String> {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = base.join(format!("rtoracle-sandbox-{}-{n}", std::process::id()));
        std::fs::create_dir(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let max = memory_bytes
            .saturating_add(file_bytes)
            .saturating_add(PAGE_CACHE_SLACK);
        let settings: [(&str, String, bool); 5] = [
            ("memory.max", max.to_string(), true),
            ("memory.swap.max", "0".into(), false),
            ("memory.oom.group", "1".into(), false),
            ("cpu.weight", CPU_WEIGHT.to_string(), true),
            ("pids.max", processes.to_string(), false),
        ];
        for (file, value, required) in settings {
            let target = path.join(file);
            if let Err(e) = std::fs::write(&target, &value)
                && required
            {
                let _ = std::fs::remove_dir(&path);
                return Err(format!("{}: {e}", target.display()));
            }
        }
        let procs = CString::new(
            path.join("cgroup.procs")
                .into_os_string()
                .into_encoded_bytes(),
        )
        .map_err(|e| e.to_string())?;
        Ok(Group { path, procs })
    }

    /// The group's folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The `cgroup.procs` file a child writes `0` to, to join the group (made before the fork).
    pub fn procs_file(&self) -> &CString {
        &self.procs
    }

    /// Ends every process of the group (`cgroup.kill`, Linux 5.14).
    pub fn kill(&self) {
        let _ = std::fs::write(self.path.join("cgroup.kill"), "1");
    }

    /// How many processes the kernel ended at `memory.max`.
    pub fn oom_kills(&self) -> u64 {
        oom_kills_in(&self.path)
    }

    /// Whether process `pid` is in the group.
    pub fn holds(&self, pid: u32) -> bool {
        let Ok(text) = std::fs::read_to_string(format!("/proc/{pid}/cgroup")) else {
            return false;
        };
        let name = self.path.file_name().unwrap_or_default().to_string_lossy();
        text.lines()
            .find_map(|l| l.strip_prefix("0::"))
            .is_some_and(|p| p.ends_with(&format!("/{name}")))
    }
}

/// `oom_kill` of `memory.events` in the cgroup folder `path`.
pub fn oom_kills_in(path: &Path) -> u64 {
    std::fs::read_to_string(path.join("memory.events"))
        .unwrap_or_default()
        .lines()
        .find_map(|l| l.strip_prefix("oom_kill "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0)
}

/// Removes the cgroup folder `path` once its processes are gone (waiting up to 200 ms).
pub fn remove(path: &Path) {
    for _ in 0..100 {
        if std::fs::remove_dir(path).is_ok() || !path.exists() {
            return;
        }
        let _ = std::fs::write(path.join("cgroup.kill"), "1");
        std::thread::sleep(Duration::from_millis(2));
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        self.kill();
        remove(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cgroup_is_found_under_the_cgroup2_mount() {
        let mountinfo = "24 30 0:21 / /proc rw - proc proc rw\n\
                         35 25 0:30 / /sys/fs/cgroup rw,nosuid - cgroup2 cgroup2 rw,nsdelegate\n";
        assert_eq!(
            locate("0::/user.slice/grader.service\n", mountinfo).unwrap(),
            Path::new("/sys/fs/cgroup/user.slice/grader.service")
        );
        // A hybrid host: v1 controllers and v2 at /sys/fs/cgroup/unified.
        let hybrid = "40 30 0:40 / /sys/fs/cgroup/memory rw - cgroup cgroup rw,memory\n\
                      41 30 0:41 / /sys/fs/cgroup/unified rw - cgroup2 cgroup2 rw\n";
        assert_eq!(
            locate("4:memory:/x\n0::/\n", hybrid).unwrap(),
            Path::new("/sys/fs/cgroup/unified")
        );
        // A container's cgroup namespace mounts its own root.
        let ns = "50 40 0:50 /docker/abc /sys/fs/cgroup ro - cgroup2 cgroup2 rw\n";
        assert_eq!(
            locate("0::/docker/abc/inner\n", ns).unwrap(),
            Path::new("/sys/fs/cgroup/inner")
        );
        assert!(locate("4:memory:/x\n", hybrid).is_err());
        assert!(locate("0::/\n", "24 30 0:21 / /proc rw - proc proc rw\n").is_err());
    }

    #[test]
    fn out_of_memory_kills_are_read_from_memory_events() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("memory.events"),
            "low 0\nhigh 0\nmax 12\noom 1\noom_kill 2\noom_group_kill 1\n",
        )
        .unwrap();
        assert_eq!(oom_kills_in(dir.path()), 2);
        assert_eq!(oom_kills_in(&dir.path().join("none")), 0);
    }

    /// Where cgroups are delegated (not on every host), a group takes its limits and a child
    /// that writes `0` to its `cgroup.procs` is in it; elsewhere the reason is one line.
    #[test]
    fn a_delegated_group_holds_a_child_that_joins_it() {
        let base = match delegation() {
            Ok(base) => base,
            Err(why) => {
                assert!(!why.is_empty() && !why.contains('\n'), "{why}");
                eprintln!("skipped: {why}");
                return;
            }
        };
        let group = Group::make(base, 64 << 20, 16 << 20, 8).unwrap();
        let max = std::fs::read_to_string(group.path().join("memory.max")).unwrap();
        assert_eq!(
            max.trim(),
            ((64u64 << 20) + (16 << 20) + PAGE_CACHE_SLACK).to_string()
        );
        let procs = group.procs_file().clone();
        use std::os::unix::process::CommandExt;
        let mut child = std::process::Command::new("sleep");
        child.arg("5");
        // SAFETY: open, write and close after fork.
        unsafe {
            child.pre_exec(move || {
                let fd = libc::open(procs.as_ptr(), libc::O_WRONLY | libc::O_CLOEXEC);
                if fd >= 0 {
                    libc::write(fd, b"0".as_ptr().cast(), 1);
                    libc::close(fd);
                }
                Ok(())
            });
        }
        let mut child = child.spawn().unwrap();
        assert!(group.holds(child.id()));
        group.kill();
        let _ = child.wait();
    }
}
