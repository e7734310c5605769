//! What a sandbox shows of the host, in both modes that can hide it (bubblewrap, and the
//! fallback's own mount namespace): the system folders, the loader's `/etc` files, the paths a
//! caller exposes read-only, and the rtoracle binaries among them covered with an empty file.
//!
//! Promises:
//! - [`system`]: `/usr` and the `/bin`, `/sbin`, `/lib*` of the host (as the links they are where
//!   the host has merged `/usr`) and the few `/etc` files the dynamic loader and Debian's
//!   alternatives need. Nothing else of the host: no `/home`, `/root`, `/work`, `/opt`, `/var`,
//!   `/run`, no `/tmp` of the host.
//! - Under bubblewrap the sandbox folder is seen at [`INSIDE`]; [`replace_path`] tells the
//!   sandbox's own paths in what its code says in the user's terms.
//! - [`exposure`] shows no more than a program needs: for a program in a `bin/` folder (an
//!   interpreter in a virtual environment or under `/opt`), the program and its prefix's
//!   library tree (`lib`, `lib64`, `pyvenv.cfg`), never the rest of that `bin/` (where a venv
//!   holding the student wheel keeps an `rtoracle`); for another program or a file, its folder;
//!   the file alone in a shared folder (`/tmp`, `/home`, a home, ...).
//! - [`View::new`] covers every rtoracle binary the view would show ([`crate::sandbox::oracles`]: by
//!   inode or content, not by name): in the exposed paths (looked at in depth), in the system's
//!   program folders and `/usr/local` (by the marker's ELF section), and the running binary
//!   wherever it lies in the view.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::sandbox::oracles;

/// Where the sandbox folder is seen from inside a bubblewrap sandbox.
pub const INSIDE: &str = "/sandbox";

/// `text` with the path `from` replaced by `to` where it starts a path (not inside a longer
/// one: `/sandbox/x.py` is replaced, `/work/sandbox/x.py` and `/sandboxes` are not).
pub fn replace_path(text: &str, from: &Path, to: &str) -> String {
    let from = from.display().to_string();
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(&from) {
        let before = rest[..i].chars().next_back();
        let after = rest[i + from.len()..].chars().next();
        let path_char = |c: char| c.is_alphanumeric() || "._-/~".contains(c);
        let starts = before.is_none_or(|c| !path_char(c));
        let ends = after.is_none_or(|c| c == '/' || !path_char(c));
        out.push_str(&rest[..i]);
        out.push_str(if starts && ends { to } else { &from });
        rest = &rest[i + from.len()..];
    }
    out.push_str(rest);
    out
}

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

/// Where the system view holds programs an install could have put there (the whole of `/usr`
/// is too large to read on every run: 3 GB of ELF files here).
const SCANNED: [&str; 5] = ["/usr/local", "/usr/bin", "/usr/sbin", "/bin", "/sbin"];

/// Folders never exposed whole (only the one file asked for is): exposing them would show
/// the grader's files or other sandboxes.
const NEVER_WHOLE: [&str; 8] = [
    "/", "/tmp", "/var/tmp", "/dev/shm", "/home", "/root", "/run", "/var",
];

/// What a library tree of a prefix holds, relative to the prefix.
const PREFIX_LIBRARIES: [&str; 3] = ["lib", "lib64", "pyvenv.cfg"];

/// One entry of the system view.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SystemEntry {
    /// A folder (or file) shown read-only at its own path.
    Shown(PathBuf),
    /// A folder that is a symbolic link on the host (`/bin -> usr/bin`): the same link.
    Link(PathBuf, OsString),
}

/// The system view of this host: `SYSTEM` as folders or links, then `ETC` where present.
pub fn system() -> Vec<SystemEntry> {
    let mut out = Vec::new();
    for s in SYSTEM {
        let p = Path::new(s);
        match std::fs::symlink_metadata(p) {
            Ok(m) if m.file_type().is_symlink() => {
                if let Ok(target) = std::fs::read_link(p) {
                    out.push(SystemEntry::Link(p.to_path_buf(), target.into_os_string()));
                }
            }
            Ok(m) if m.is_dir() => out.push(SystemEntry::Shown(p.to_path_buf())),
            _ => {}
        }
    }
    out.extend(
        ETC.iter()
            .map(Path::new)
            .filter(|p| p.exists())
            .map(|p| SystemEntry::Shown(p.to_path_buf())),
    );
    out
}

/// Whether `path` is inside the system view.
pub fn in_system_view(path: &Path) -> bool {
    SYSTEM.iter().any(|s| path.starts_with(s))
}

/// What to expose read-only for `path` (a program, or a file an adapter's arguments name): see
/// the module's promises. Nothing for paths already in the system view.
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
        let whole_ok = |d: &Path| {
            !NEVER_WHOLE.iter().any(|n| d == Path::new(n))
                && d.components().count() > 2
                && !is_home(d)
        };
        let prefix = parent
            .as_deref()
            .filter(|dir| dir.file_name().is_some_and(|n| n == "bin"))
            .and_then(Path::parent);
        match (prefix, &parent) {
            (Some(prefix), _) if whole_ok(prefix) => {
                out.push(p.clone());
                out.extend(PREFIX_LIBRARIES.iter().map(|l| prefix.join(l)));
            }
            (None, Some(d)) if whole_ok(d) => out.push(d.clone()),
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

/// The host paths a sandbox shows beyond the system view, and the binaries it covers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct View {
    /// Shown read-only (folders whole, or files), sorted.
    pub exposed: Vec<PathBuf>,
    /// rtoracle binaries the view would show, each covered with an empty file, sorted.
    pub hidden: Vec<PathBuf>,
}

impl View {
    /// The view of the system and `exposed`, with every rtoracle binary in it hidden.
    pub fn new(mut exposed: Vec<PathBuf>) -> View {
        exposed.sort();
        exposed.dedup();
        // The system's folders by their sections (a read of every byte of /usr/bin on every
        // run would cost more than the grading); what is exposed in depth.
        let system = SCANNED
            .iter()
            .filter_map(|r| Path::new(r).canonicalize().ok())
            .map(|r| (r, false));
        let roots: Vec<(PathBuf, bool)> = system
            .chain(exposed.iter().map(|e| (e.clone(), true)))
            .collect();
        let mut hidden: Vec<PathBuf> = roots
            .iter()
            .flat_map(|(r, deep)| oracles::found_in(r, *deep))
            .collect();
        if let Ok(exe) = std::env::current_exe()
            && (in_system_view(&exe) || exposed.iter().any(|e| exe.starts_with(e)))
        {
            hidden.push(exe);
        }
        // A binary in a canonical root is also seen at the path the view shows it (a link
        // such as `/bin`): covering the canonical one covers the file.
        hidden.sort();
        hidden.dedup();
        View { exposed, hidden }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_folders_are_never_exposed_whole_and_a_bin_folder_never() {
        assert_eq!(
            exposure(Path::new("/tmp/adapter")),
            [PathBuf::from("/tmp/adapter")]
        );
        assert_eq!(
            exposure(Path::new("/usr/bin/python3")),
            Vec::<PathBuf>::new()
        );
        // An interpreter under /opt: itself and its library tree, not its bin/.
        assert_eq!(
            exposure(Path::new("/opt/py311/bin/python3")),
            [
                PathBuf::from("/opt/py311/bin/python3"),
                PathBuf::from("/opt/py311/lib"),
                PathBuf::from("/opt/py311/lib64"),
                PathBuf::from("/opt/py311/pyvenv.cfg"),
            ]
        );
        assert_eq!(
            exposure(Path::new("/home/ann/adapter")),
            [PathBuf::from("/home/ann/adapter")]
        );
        assert_eq!(
            exposure(Path::new("/home/ann/tracer/adapter")),
            [PathBuf::from("/home/ann/tracer")]
        );
        // A bin/ in a home: the program alone.
        assert_eq!(
            exposure(Path::new("/home/ann/bin/python3")),
            [PathBuf::from("/home/ann/bin/python3")]
        );
    }

    /// A venv holding an rtoracle next to its python3 (the student wheel's): the view shows the
    /// interpreter and its libraries, and covers an rtoracle found in them by content.
    #[test]
    fn a_venv_s_bin_is_not_shown_and_a_copy_in_its_libraries_is_covered() {
        let dir = tempfile::tempdir().unwrap();
        let venv = dir.path().join("venv");
        let site = venv.join("lib/python3/site-packages/tool");
        std::fs::create_dir_all(venv.join("bin")).unwrap();
        std::fs::create_dir_all(&site).unwrap();
        std::os::unix::fs::symlink("/usr/bin/python3", venv.join("bin/python3")).unwrap();
        let exe = std::env::current_exe().unwrap();
        std::fs::copy(&exe, venv.join("bin/rtoracle")).unwrap();
        std::fs::copy(&exe, site.join("helper")).unwrap();
        let exposed = exposure(&venv.join("bin/python3"));
        assert!(
            !exposed.iter().any(|p| p.ends_with("bin") || p == &venv),
            "{exposed:?}"
        );
        let view = View::new(exposed);
        assert!(view.hidden.contains(&site.join("helper")), "{view:?}");
        assert!(
            !view.hidden.contains(&venv.join("bin/rtoracle")),
            "not shown at all"
        );
    }
}
