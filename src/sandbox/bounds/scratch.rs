//! What a sandbox's code may write where, how it is measured, and that none of it is left
//! behind: trees walked and removed by descriptor at any depth, and what a per-submission uid
//! owns in the host's world-writable folders.

use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// The host's world-writable folders a uid without a mount namespace can write into.
pub const SHARED_ROOTS: [&str; 6] = [
    "/tmp",
    "/var/tmp",
    "/dev/shm",
    "/run/lock",
    "/var/lock",
    "/dev/mqueue",
];

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
    fn a_tree_deeper_than_a_path_can_name_is_measured_and_removed() {
        let dir = tempfile::tempdir().unwrap();
        let long = "n".repeat(200);
        // 90 levels of 200-byte names: 18 KB of path to a 1 MiB file.
        nest(dir.path(), &long, 90, 90, 1 << 20);
        let usage = usage_of_tree(dir.path());
        assert_eq!(usage.entries, 91, "{usage:?}");
        assert!(usage.bytes >= 1 << 20, "{usage:?}");
        assert_eq!(usage.deepest, 90);
        let deep = tempfile::tempdir().unwrap();
        nest(deep.path(), "a", 2100, 2100, 4096);
        let usage = usage_of_tree(deep.path());
        // Past `MAX_NESTING`, which the watchdog judges a violation in itself.
        assert_eq!(usage.deepest, MAX_NESTING + 1, "{usage:?}");
        for d in [dir, deep] {
            let path = d.path().to_path_buf();
            assert!(remove_deep(&path), "{}", path.display());
            assert!(!path.exists());
        }
    }
}
