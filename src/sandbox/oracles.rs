//! rtoracle binaries a sandbox's code could run as an oracle (`rtoracle explain` answers every
//! vector of a suite), found by inode or content, never by name or path: a copy in a virtual
//! environment next to the interpreter (the student wheel's), a build tree's hard link
//! (`target/release/deps/rtoracle-<hash>`), another install.
//!
//! Promises:
//! - [`is_rtoracle_binary`]: a regular file of at least [`MIN_BYTES`] that starts with the ELF
//!   magic and either is the running binary (same device and inode: a hard link), or has the
//!   section [`MARKER_SECTION`] that every build holds (found from its section headers: three
//!   small reads), or, looked at in depth, holds [`BINARY_MARKER`] or the crate's description
//!   anywhere (which every build's `--help` shows, so builds older than the marker are found
//!   too). Other files are read no further than their first four bytes.
//! - [`found_in`] walks a tree without following links, on its own file system, at most
//!   [`MAX_DEPTH`] folders deep and [`MAX_ENTRIES`] entries, each file (by inode) looked at
//!   once, in depth or by its sections only (the system's program folders: 1 GB of ELF files
//!   here, too much to read on every run); what it finds in a tree is cached for the process.
//! - [`refusal`]: every rtoracle binary refuses to run as a sandbox's identity (a uid of
//!   [`identity`](super::identity)'s range), so one that the view could not hide (the fallback
//!   without a mount namespace shows the host) answers nothing.

use std::collections::{HashMap, HashSet};
use std::io::Read;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// The ELF section every rtoracle binary holds [`BINARY_MARKER`] in.
pub const MARKER_SECTION: &str = ".rtoracle";

/// Bytes every rtoracle binary holds, in its section [`MARKER_SECTION`]: this static is what
/// [`is_rtoracle_binary`] looks for, so every binary that can look holds it.
#[unsafe(link_section = ".rtoracle")]
#[used]
pub static BINARY_MARKER: [u8; 32] = *b"rtoracle-binary:2f6b1c9e8d3a7054";

/// The crate's description, which clap's `--help` shows: in every build of every version.
const DESCRIPTION: &str = env!("CARGO_PKG_DESCRIPTION");

/// Files smaller than this are not looked into (a build of rtoracle is megabytes).
pub const MIN_BYTES: u64 = 256 << 10;

/// How deep [`found_in`] walks.
pub const MAX_DEPTH: usize = 16;

/// Most entries [`found_in`] looks at in one tree.
pub const MAX_ENTRIES: usize = 200_000;

/// The running binary's device and inode.
fn own_inode() -> Option<(u64, u64)> {
    static OWN: OnceLock<Option<(u64, u64)>> = OnceLock::new();
    *OWN.get_or_init(|| {
        let m = std::fs::metadata("/proc/self/exe").ok()?;
        Some((m.dev(), m.ino()))
    })
}

/// Whether the file at `path` (not followed if it is a link) is an rtoracle binary, looked at
/// in depth.
pub fn is_rtoracle_binary(path: &Path) -> bool {
    match std::fs::symlink_metadata(path) {
        Ok(meta) => is_binary_with(path, &meta, true),
        Err(_) => false,
    }
}

fn is_binary_with(path: &Path, meta: &std::fs::Metadata, deep: bool) -> bool {
    if !meta.is_file() || meta.len() < MIN_BYTES {
        return false;
    }
    if own_inode() == Some((meta.dev(), meta.ino())) {
        return true;
    }
    use std::os::unix::fs::OpenOptionsExt;
    let Ok(mut file) = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
    else {
        return false;
    };
    let mut header = [0u8; 64];
    if file.read_exact(&mut header).is_err() || &header[..4] != b"\x7fELF" {
        return false;
    }
    if has_marker_section(&file, &header) {
        return true;
    }
    deep && {
        use std::io::Seek;
        file.seek(std::io::SeekFrom::Start(0)).is_ok() && holds_a_needle(&mut file)
    }
}

/// Whether the ELF file whose first 64 bytes are `header` has a section named
/// [`MARKER_SECTION`]: from its section headers and their names' table (32 or 64 bits, either
/// byte order).
fn has_marker_section(file: &std::fs::File, header: &[u8; 64]) -> bool {
    use std::os::unix::fs::FileExt;
    let wide = header[4] == 2;
    let little = header[5] == 1;
    let int = |bytes: &[u8], at: usize, len: usize| -> u64 {
        let b = &bytes[at..at + len];
        let mut v = 0u64;
        for i in 0..len {
            let byte = if little { b[len - 1 - i] } else { b[i] };
            v = (v << 8) | byte as u64;
        }
        v
    };
    let (shoff, shentsize, shnum, shstrndx) = if wide {
        (
            int(header, 0x28, 8),
            int(header, 0x3a, 2),
            int(header, 0x3c, 2),
            int(header, 0x3e, 2),
        )
    } else {
        (
            int(header, 0x20, 4),
            int(header, 0x2e, 2),
            int(header, 0x30, 2),
            int(header, 0x32, 2),
        )
    };
    let min_entry = if wide { 0x28 } else { 0x18 };
    if shnum == 0 || shnum > 4096 || shstrndx >= shnum || shentsize < min_entry {
        return false;
    }
    let mut table = vec![0u8; (shnum * shentsize) as usize];
    if file.read_exact_at(&mut table, shoff).is_err() {
        return false;
    }
    let names = &table[(shstrndx * shentsize) as usize..];
    let (offset, size) = if wide {
        (int(names, 0x18, 8), int(names, 0x20, 8))
    } else {
        (int(names, 0x10, 4), int(names, 0x14, 4))
    };
    if size == 0 || size > 1 << 20 {
        return false;
    }
    let mut strings = vec![0u8; size as usize];
    if file.read_exact_at(&mut strings, offset).is_err() {
        return false;
    }
    strings
        .split(|&b| b == 0)
        .any(|name| name == MARKER_SECTION.as_bytes())
}

/// Whether what `reader` gives holds [`BINARY_MARKER`] or [`DESCRIPTION`], read in chunks (a
/// needle across two chunks is found: each chunk starts with the end of the one before).
fn holds_a_needle(reader: &mut impl Read) -> bool {
    let needles = [
        memchr::memmem::Finder::new(&BINARY_MARKER[..]),
        memchr::memmem::Finder::new(DESCRIPTION.as_bytes()),
    ];
    let keep = BINARY_MARKER.len().max(DESCRIPTION.len());
    let mut buf = vec![0u8; 1 << 20];
    let mut filled = 0;
    loop {
        let n = match reader.read(&mut buf[filled..]) {
            Ok(0) => return false,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => return false,
        };
        filled += n;
        if needles.iter().any(|f| f.find(&buf[..filled]).is_some()) {
            return true;
        }
        if filled == buf.len() {
            buf.copy_within(filled - keep..filled, 0);
            filled = keep;
        }
    }
}

/// The binaries found in each tree walked so far, by the tree and the walk's depth.
type Found = HashMap<(PathBuf, bool), Vec<PathBuf>>;

/// The rtoracle binaries in the tree at `root` (or `root` itself when it is one), sorted, each
/// file looked at in depth when `deep`, by its sections otherwise; cached for the process.
pub fn found_in(root: &Path, deep: bool) -> Vec<PathBuf> {
    static CACHE: OnceLock<Mutex<Found>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    let key = (root.to_path_buf(), deep);
    // Held while a tree is walked: sandboxes made at once wait for one walk, not make many.
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(found) = cache.get(&key) {
        return found.clone();
    }
    let mut found = Vec::new();
    if let Ok(meta) = std::fs::symlink_metadata(root) {
        if meta.is_dir() {
            let mut walk = Walk {
                deep,
                dev: meta.dev(),
                seen: HashSet::new(),
                entries: 0,
                found: &mut found,
            };
            walk.folder(root, 0);
        } else if is_binary_with(root, &meta, deep) {
            found.push(root.to_path_buf());
        }
    }
    found.sort();
    cache.insert(key, found.clone());
    found
}

/// A walk of one tree for [`found_in`].
struct Walk<'a> {
    deep: bool,
    dev: u64,
    /// The inodes looked at (a hard-linked file is read once, and every link to it named).
    seen: HashSet<u64>,
    entries: usize,
    found: &'a mut Vec<PathBuf>,
}

impl Walk<'_> {
    fn folder(&mut self, dir: &Path, depth: usize) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for entry in entries.flatten() {
            self.entries += 1;
            if self.entries > MAX_ENTRIES {
                return;
            }
            let Ok(meta) = entry.metadata() else {
                continue;
            };
            let path = entry.path();
            if meta.is_dir() {
                if meta.dev() == self.dev && depth < MAX_DEPTH {
                    self.folder(&path, depth + 1);
                }
            } else if meta.is_file() && meta.len() >= MIN_BYTES {
                let fresh = self.seen.insert(meta.ino());
                let known = !fresh && self.found.iter().any(|f| same_file(f, &meta));
                if known || (fresh && is_binary_with(&path, &meta, self.deep)) {
                    self.found.push(path);
                }
            }
        }
    }
}

/// Whether `path` is the file `meta` describes.
fn same_file(path: &Path, meta: &std::fs::Metadata) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.dev() == meta.dev() && m.ino() == meta.ino())
}

/// Why this process must not run, if it runs as a sandbox's identity: a submission that found
/// a copy of rtoracle the view could not hide would use it as an oracle.
pub fn refusal() -> Option<String> {
    // SAFETY: getuid has no preconditions.
    let uid = unsafe { libc::getuid() };
    super::identity::is_sandbox_uid(uid).then(|| {
        format!(
            "rtoracle does not run inside its own sandbox (uid {uid} is a sandbox's): the code \
             it grades cannot use it"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file of `len` bytes that starts with the ELF magic and holds `needle` at `at`.
    fn fake_elf(dir: &Path, name: &str, len: usize, needle: &[u8], at: usize) -> PathBuf {
        let mut bytes = vec![0u8; len];
        bytes[..4].copy_from_slice(b"\x7fELF");
        bytes[at..at + needle.len()].copy_from_slice(needle);
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn binaries_are_known_by_content_inode_and_magic_not_by_name() {
        let dir = tempfile::tempdir().unwrap();
        // The marker across the first 1 MiB chunk's end, and the description deep inside.
        let marked = fake_elf(dir.path(), "tracer", 3 << 20, &BINARY_MARKER, (1 << 20) - 7);
        let old = fake_elf(dir.path(), "x", 2 << 20, DESCRIPTION.as_bytes(), 3 << 19);
        let plain = fake_elf(dir.path(), "rtoracle", 2 << 20, b"nothing", 100);
        // The description alone is found in depth only; the marker's section by its headers.
        let shallow = |p: &Path| is_binary_with(p, &std::fs::metadata(p).unwrap(), false);
        assert!(!shallow(&old));
        // The marker, but not an ELF file (a text file quoting it).
        let text = dir.path().join("notes.txt");
        let mut bytes = vec![b' '; 1 << 20];
        bytes[10..42].copy_from_slice(&BINARY_MARKER);
        std::fs::write(&text, bytes).unwrap();
        let small = fake_elf(dir.path(), "small", 1000, &BINARY_MARKER, 100);
        assert!(is_rtoracle_binary(&marked));
        assert!(is_rtoracle_binary(&old));
        assert!(!is_rtoracle_binary(&plain), "named rtoracle, but is not");
        assert!(!is_rtoracle_binary(&text));
        assert!(!is_rtoracle_binary(&small));
        // The running test binary holds the marker (it links the library that looks for it).
        let exe = std::env::current_exe().unwrap();
        assert!(is_rtoracle_binary(&exe));
        let copy = dir.path().join("copy-of-the-test");
        std::fs::copy(&exe, &copy).unwrap();
        assert!(shallow(&copy), "the section, from the headers alone");
        std::fs::remove_file(&copy).unwrap();
        // A hard link to the running binary, found by its inode, and both links named.
        let sub = dir.path().join("deep/er");
        std::fs::create_dir_all(&sub).unwrap();
        let link = sub.join("copy");
        std::fs::hard_link(&marked, &link).unwrap();
        std::os::unix::fs::symlink(&marked, dir.path().join("symlink")).unwrap();
        assert_eq!(
            found_in(dir.path(), true),
            [link, marked.clone(), old],
            "symbolic links are not followed"
        );
        assert_eq!(found_in(&marked, true), std::slice::from_ref(&marked));
    }
}
