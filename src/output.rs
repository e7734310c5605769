//! Output files and folders that are checked before the work, never half-written, and removed
//! on Ctrl-C. Every file and folder rtoracle writes goes through here.
//!
//! What it promises:
//! - [`check_output_file`] and [`check_output_dir`] say, before any work starts, whether a path
//!   can be written: its parent exists and is a folder in which a file can really be created (a
//!   probe file is created and removed at once, because running as root, permissions alone do not
//!   tell), and the target is not of the wrong kind (a folder where a file is wanted, or the other
//!   way round). The error is one line naming the option and the path, never a temporary name.
//! - [`OutputFile`] is written in a temporary sibling (`.NAME.rtoracle-XXXXXX`) that is renamed
//!   onto the target by [`OutputFile::commit`]. Until then the target is untouched; dropping the
//!   value, an error, or an interruption (through [`crate::interrupt::remove_on_interrupt`])
//!   removes the temporary file.
//! - [`OutputDir`] is the one way an output folder is replaced (compare's `--report`, grade's
//!   `--out`, a batch's folder):
//!   - [`check_replaceable`] (which [`OutputDir::create`] calls first) says before any work
//!     whether the folder may be replaced: what [`check_output_dir`] checks, and an existing
//!     folder must hold only the output's own files, as its [`Replaceable`] says (a compare
//!     report's; grading's reports and a batch's folders of them), so no file of the user's is
//!     ever removed;
//!   - a symbolic link to a folder stays a link: the folder it leads to is the one replaced;
//!   - the new folder is filled in a fresh staging folder beside the target
//!     (`.NAME.rtoracle-XXXXXX`, so on the same file system), removed on drop, on an error, and on
//!     Ctrl-C or SIGTERM (registered with [`crate::interrupt`] as it is created);
//!   - [`OutputDir::commit`] checks the target again (a file the user put there during the run
//!     is kept: the commit fails instead) and swaps the staging folder in whole. A missing target
//!     is a rename; an existing one is exchanged with it atomically (`renameat2`'s
//!     `RENAME_EXCHANGE`), the old folder then removed. Where the exchange is not available the
//!     old folder is renamed aside and the new one in, both under
//!     [`crate::interrupt::hold_off`], so an interruption cannot fall between them. Where the
//!     target cannot be renamed at all (a mount point), the new files are copied into a hidden
//!     folder inside it, and then, under the hold-off, the old entries are moved out and the new
//!     ones in. Either way the target holds the previous output or the new one, whole (an
//!     interrupted run leaves the previous one as it was), nothing of an earlier run survives, and
//!     no temporary folder is left.
//!
//! The temporary names come from `tempfile` (already a dependency: unique names created with
//! `O_EXCL`, removed on drop).

use std::ffi::OsString;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::escape::terminal_line;
use crate::interrupt::{self, CleanupGuard};

/// Why an output path cannot be written (one line: the option, the path, the problem).
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {message}", option_prefix(.option), .path.display())]
pub struct OutputError {
    /// The command-line option that named the path (empty when none did).
    pub option: String,
    /// The path as given.
    pub path: PathBuf,
    /// What is wrong, in words.
    pub message: String,
}

fn option_prefix(option: &str) -> String {
    if option.is_empty() {
        String::new()
    } else {
        format!("{option} ")
    }
}

impl OutputError {
    fn new(option: &str, path: &Path, message: impl std::fmt::Display) -> Self {
        OutputError {
            option: option.to_string(),
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}

/// An I/O error in words, without the path `tempfile` attaches to it (that path is a temporary
/// name, which must not reach the user).
fn words(e: &std::io::Error) -> String {
    let inner = e
        .get_ref()
        .and_then(|inner| inner.source())
        .and_then(|source| source.downcast_ref::<std::io::Error>());
    let code = e
        .raw_os_error()
        .or_else(|| inner.and_then(|i| i.raw_os_error()));
    match code {
        Some(code) => std::io::Error::from_raw_os_error(code).to_string(),
        None => std::io::Error::from(e.kind()).to_string(),
    }
}

/// An error creating or renaming a file, in words (see [`words`]).
fn plain(e: &std::io::Error) -> String {
    match e.kind() {
        // Creating a file in an existing folder said "not found": /proc, /sys and the like.
        std::io::ErrorKind::NotFound => "the folder does not take new files".to_string(),
        std::io::ErrorKind::Interrupted => "interrupted".to_string(),
        _ => words(e),
    }
}

/// The error of a step not taken because a signal came (the process is about to exit).
fn interrupted() -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted")
}

/// The folder a path lives in (`.` for a bare name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The temporary-name prefix of a sibling of `path`: `.NAME.rtoracle-`.
fn temp_prefix(path: &Path) -> OsString {
    let mut prefix = OsString::from(".");
    prefix.push(path.file_name().unwrap_or_else(|| "output".as_ref()));
    prefix.push(".rtoracle-");
    prefix
}

/// Checks the folder that will hold `path`: it exists, is a folder, and a file can be created in
/// it.
fn check_parent(path: &Path, option: &str) -> Result<(), OutputError> {
    if path.as_os_str().is_empty() {
        return Err(OutputError::new(option, path, "an empty path"));
    }
    if path.file_name().is_none() {
        return Err(OutputError::new(
            option,
            path,
            "names no file or folder (it ends in '..' or '/')",
        ));
    }
    let dir = parent_dir(path);
    match std::fs::metadata(dir) {
        Err(_) if !dir.exists() => {
            return Err(OutputError::new(
                option,
                path,
                format!("the folder '{}' does not exist", dir.display()),
            ));
        }
        Err(e) => {
            return Err(OutputError::new(
                option,
                path,
                format!("cannot use the folder '{}': {}", dir.display(), plain(&e)),
            ));
        }
        Ok(m) if !m.is_dir() => {
            return Err(OutputError::new(
                option,
                path,
                format!("'{}' is a file, not a folder", dir.display()),
            ));
        }
        Ok(_) => {}
    }
    // Permissions do not tell (root writes anywhere, a read-only mount refuses everyone): try.
    tempfile::Builder::new()
        .prefix(&temp_prefix(path))
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| {
            OutputError::new(
                option,
                path,
                format!("cannot create files in '{}': {}", dir.display(), plain(&e)),
            )
        })
}

/// Checks, before any work, that a file can be written at `path` (see the module docs).
/// `option` names the option that gave the path, for the message (`"-o"`, `"--heatmap"`).
pub fn check_output_file(path: &Path, option: &str) -> Result<(), OutputError> {
    check_parent(path, option)?;
    if path.is_dir() {
        return Err(OutputError::new(
            option,
            path,
            "is a folder; a file is wanted here",
        ));
    }
    Ok(())
}

/// Checks, before any work, that a folder can be written at `path`: its parent is a writable
/// folder and `path` is a folder or does not exist.
pub fn check_output_dir(path: &Path, option: &str) -> Result<(), OutputError> {
    check_parent(path, option)?;
    if path.exists() && !path.is_dir() {
        return Err(OutputError::new(
            option,
            path,
            "is a file; a folder is wanted here",
        ));
    }
    if path.is_dir() {
        // Some commands add files to an existing folder: it must take them too.
        tempfile::Builder::new()
            .prefix(".rtoracle-probe-")
            .tempfile_in(path)
            .map(drop)
            .map_err(|e| {
                OutputError::new(
                    option,
                    path,
                    format!("cannot create files in it: {}", plain(&e)),
                )
            })?;
    }
    Ok(())
}

/// A file being written: a temporary sibling of the target until [`OutputFile::commit`].
#[derive(Debug)]
pub struct OutputFile {
    target: PathBuf,
    option: String,
    tmp: tempfile::NamedTempFile,
    _guard: CleanupGuard,
}

impl OutputFile {
    /// Checks `path` (as [`check_output_file`]) and opens its temporary sibling.
    pub fn create(path: &Path, option: &str) -> Result<Self, OutputError> {
        check_output_file(path, option)?;
        Self::open(path, option)
    }

    /// Opens the temporary sibling of `path`, a path known to be writable.
    fn open(path: &Path, option: &str) -> Result<Self, OutputError> {
        let (tmp, guard) = interrupt::create_temporary(
            || {
                tempfile::Builder::new()
                    .prefix(&temp_prefix(path))
                    .tempfile_in(parent_dir(path))
            },
            |t| t.path(),
        )
        .map_err(|e| OutputError::new(option, path, plain(&e)))?;
        Ok(OutputFile {
            target: path.to_path_buf(),
            option: option.to_string(),
            tmp,
            _guard: guard,
        })
    }

    /// The temporary file, to write into.
    pub fn file(&mut self) -> &mut File {
        self.tmp.as_file_mut()
    }

    /// Writes all of `bytes` to the temporary file.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), OutputError> {
        self.tmp
            .as_file_mut()
            .write_all(bytes)
            .map_err(|e| OutputError::new(&self.option, &self.target, plain(&e)))
    }

    /// The target path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Makes the file an ordinary one (mode 0644, flushed) and renames it onto the target.
    pub fn commit(self) -> Result<(), OutputError> {
        let OutputFile {
            target,
            option,
            tmp,
            _guard,
        } = self;
        let fail = |e: &std::io::Error| OutputError::new(&option, &target, plain(e));
        tmp.as_file().flush().map_err(|e| fail(&e))?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(|e| fail(&e))?;
        }
        if target.is_dir() {
            return Err(OutputError::new(
                &option,
                &target,
                "is a folder; a file is wanted here",
            ));
        }
        tmp.persist(&target).map_err(|e| fail(&e.error))?;
        Ok(())
    }
}

/// Writes `bytes` to `path` through an [`OutputFile`]: all of it or nothing.
pub fn write_file(path: &Path, option: &str, bytes: &[u8]) -> Result<(), OutputError> {
    let mut file = OutputFile::create(path, option)?;
    file.write_all(bytes)?;
    file.commit()
}

/// `path`, or the folder it leads to when it is a symbolic link (so swapping a folder in replaces
/// the folder, not the link). A link that leads nowhere is returned as it is.
pub fn resolve_link(path: &Path) -> PathBuf {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => path.canonicalize().unwrap_or_else(|_| path.into()),
        _ => path.to_path_buf(),
    }
}

/// What an existing folder may hold for an [`OutputDir`] to replace it whole: only the files of
/// the output it is, and where `folders` says so, folders of them one level down. Anything else
/// (a file of the user's, a link, a deeper folder) makes [`check_replaceable`] refuse the folder.
#[derive(Clone, Copy, Debug)]
pub struct Replaceable {
    /// What the output is, for messages: `"a compare report"`.
    pub what: &'static str,
    /// Whether a file of this name is one of the output's.
    pub is_output_file: fn(&str) -> bool,
    /// Whether folders holding only such files may stand in it (a batch's submission folders).
    pub folders: bool,
}

impl Replaceable {
    /// The first entry of the folder `dir` that is not part of the output (`sub/name` one level
    /// down), if any.
    fn foreign_entry(&self, dir: &Path, depth: usize) -> std::io::Result<Option<String>> {
        for entry in std::fs::read_dir(dir)? {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let kind = entry.file_type()?;
            if kind.is_file() && (self.is_output_file)(&name) {
                continue;
            }
            if kind.is_dir() && self.folders && depth == 0 {
                match self.foreign_entry(&entry.path(), 1)? {
                    Some(inner) => return Ok(Some(format!("{name}/{inner}"))),
                    None => continue,
                }
            }
            return Ok(Some(name));
        }
        Ok(None)
    }

    /// Why the existing `target` may not be replaced, if it may not (`Ok` when it is missing).
    fn refusal(&self, target: &Path) -> Result<(), String> {
        let m = match std::fs::symlink_metadata(target) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(e) => return Err(format!("cannot be read: {}", words(&e))),
            Ok(m) => m,
        };
        if m.file_type().is_symlink() {
            return Err("is a symbolic link that leads nowhere; a folder is wanted here".into());
        }
        if !m.is_dir() {
            return Err("is a file; a folder is wanted here".into());
        }
        match self.foreign_entry(target, 0) {
            Ok(None) => Ok(()),
            Ok(Some(name)) => Err(format!(
                "holds {}, which is not part of {}; the folder is replaced whole, so choose an empty or new one",
                terminal_line(&name),
                self.what
            )),
            Err(e) => Err(format!("cannot be read: {}", words(&e))),
        }
    }
}

/// The folder `path` stands for, once it is known that a fresh folder may replace it (see
/// [`check_replaceable`]).
fn replaceable_target(
    path: &Path,
    option: &str,
    replace: &Replaceable,
) -> Result<PathBuf, OutputError> {
    check_output_dir(path, option)?;
    let target = resolve_link(path);
    if target != path {
        // The staging folder goes beside the folder the link leads to.
        check_output_dir(&target, option).map_err(|e| {
            let to = e.path.display();
            OutputError::new(option, path, format!("leads to {to}: {}", e.message))
        })?;
    }
    replace
        .refusal(&target)
        .map_err(|message| OutputError::new(option, path, message))?;
    Ok(target)
}

/// Checks, before any work, that a fresh folder can replace `path` whole: what
/// [`check_output_dir`] checks, and an existing folder (or the folder a link leads to) holds
/// nothing but what `replace` allows.
pub fn check_replaceable(
    path: &Path,
    option: &str,
    replace: &Replaceable,
) -> Result<(), OutputError> {
    replaceable_target(path, option, replace).map(drop)
}

/// A folder being filled: a fresh staging folder beside the target until [`OutputDir::commit`]
/// swaps it in whole (see the module docs).
#[derive(Debug)]
pub struct OutputDir {
    /// The path as given, for messages.
    given: PathBuf,
    /// The folder replaced (the one a link leads to).
    target: PathBuf,
    option: String,
    replace: Replaceable,
    tmp: tempfile::TempDir,
    _guard: CleanupGuard,
}

impl OutputDir {
    /// Checks `path` (as [`check_replaceable`]) and creates the fresh staging folder beside it,
    /// removed on an interruption from the moment it exists.
    pub fn create(path: &Path, option: &str, replace: &Replaceable) -> Result<Self, OutputError> {
        let target = replaceable_target(path, option, replace)?;
        let (tmp, guard) = interrupt::create_temporary(
            || {
                tempfile::Builder::new()
                    .prefix(&temp_prefix(&target))
                    .tempdir_in(parent_dir(&target))
            },
            |t| t.path(),
        )
        .map_err(|e| {
            OutputError::new(
                option,
                path,
                format!("cannot make a folder beside it: {}", plain(&e)),
            )
        })?;
        Ok(OutputDir {
            given: path.to_path_buf(),
            target,
            option: option.to_string(),
            replace: *replace,
            tmp,
            _guard: guard,
        })
    }

    /// The staging folder, to write into.
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// Where `rel`, a path inside the staging folder, ends up once committed, as the user named
    /// it: for messages, which never name the staging folder.
    pub fn shown(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.given.join(rel)
    }

    /// Writes `bytes` to the file `rel` of the staging folder (mode 0644), whole or not at all;
    /// an error names the file where it would end up ([`OutputDir::shown`]).
    pub fn write(&self, rel: impl AsRef<Path>, bytes: &[u8]) -> Result<(), OutputError> {
        let rel = rel.as_ref();
        let fail = |e: OutputError| OutputError::new(&self.option, &self.shown(rel), e.message);
        let mut file = OutputFile::open(&self.path().join(rel), &self.option).map_err(fail)?;
        file.write_all(bytes).map_err(fail)?;
        file.commit().map_err(fail)
    }

    /// The folder that will be replaced: the path given, or the folder its link leads to.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Makes the staging folder an ordinary one (mode 0755), checks the target again and swaps
    /// the staging folder in whole (see the module docs). On an error the target is as it was and
    /// the staging folder is removed.
    pub fn commit(self) -> Result<(), OutputError> {
        let OutputDir {
            given,
            target,
            option,
            replace,
            tmp,
            _guard,
        } = self;
        let fail = |message: String| OutputError::new(&option, &given, message);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o755))
                .map_err(|e| fail(plain(&e)))?;
        }
        // Something the user put there since the check is not removed.
        replace.refusal(&target).map_err(fail)?;
        // Until the swap is done the staging path holds the new folder, and after an exchange
        // the old one: the guard removes whichever it is on an interruption.
        swap_in(tmp, &target).map_err(|e| fail(plain(&e)))?;
        drop(_guard);
        Ok(())
    }
}

/// Puts the folder `new` where `target` is (see the module docs); `new` is removed on an error.
fn swap_in(new: tempfile::TempDir, target: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(target) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::rename(new.path(), target)?;
            let _ = new.keep();
            return Ok(());
        }
        Err(e) => return Err(e),
        Ok(_) => {}
    }
    if exchange(new.path(), target).is_ok() {
        // `new`'s path now holds the old folder: dropping it removes it.
        return Ok(());
    }
    if swap_aside(new.path(), target)? {
        return Ok(());
    }
    swap_by_moves(new.path(), target)
}

/// Exchanges the folders `a` and `b` atomically (`renameat2` with `RENAME_EXCHANGE`).
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c =
        |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: two valid NUL-terminated paths; renameat2 only reads them.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if rc == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Renames `target` aside and `new` in its place, both under the hold-off, then removes the old
/// folder. `Ok(false)` when `target` cannot be renamed (nothing has changed).
fn swap_aside(new: &Path, target: &Path) -> std::io::Result<bool> {
    // A free name beside the target; renaming a folder onto an empty folder replaces it.
    let (aside, _remove) = interrupt::create_temporary(
        || {
            tempfile::Builder::new()
                .prefix(&temp_prefix(target))
                .suffix(".old")
                .tempdir_in(parent_dir(target))
        },
        |t| t.path(),
    )?;
    {
        let _hold = interrupt::hold_off().ok_or_else(interrupted)?;
        if std::fs::rename(target, aside.path()).is_err() {
            return Ok(false);
        }
        if let Err(e) = std::fs::rename(new, target) {
            if std::fs::rename(aside.path(), target).is_err() {
                // The previous folder is still aside: never remove it.
                let _ = aside.keep();
            }
            return Err(e);
        }
    }
    // The previous folder, now aside, goes with the holder (and on an interruption, the guard).
    drop(aside);
    Ok(true)
}

/// Replaces the contents of `target`, a folder that cannot be renamed (a mount point), by those
/// of `new`: copied into a hidden folder inside `target` first, then, under the hold-off, the
/// old entries moved into another hidden folder and the new ones moved up; the old ones are
/// removed after. On an error every move is undone.
fn swap_by_moves(new: &Path, target: &Path) -> std::io::Result<()> {
    let hidden = |tag: &str| {
        interrupt::create_temporary(
            || {
                tempfile::Builder::new()
                    .prefix(&format!(".rtoracle-{tag}-"))
                    .tempdir_in(target)
            },
            |t| t.path(),
        )
    };
    let (incoming, _remove_incoming) = hidden("new")?;
    copy_tree(new, incoming.path())?;
    let (outgoing, _remove_outgoing) = hidden("old")?;
    let ours = [incoming.path().file_name(), outgoing.path().file_name()];
    let _hold = interrupt::hold_off().ok_or_else(interrupted)?;
    let mut moved: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut step = || -> std::io::Result<()> {
        for entry in std::fs::read_dir(target)? {
            let name = entry?.file_name();
            if !ours.contains(&Some(name.as_os_str())) {
                let (from, to) = (target.join(&name), outgoing.path().join(&name));
                std::fs::rename(&from, &to)?;
                moved.push((from, to));
            }
        }
        for entry in std::fs::read_dir(incoming.path())? {
            let name = entry?.file_name();
            let (from, to) = (incoming.path().join(&name), target.join(&name));
            std::fs::rename(&from, &to)?;
            moved.push((from, to));
        }
        Ok(())
    };
    if let Err(e) = step() {
        for (from, to) in moved.iter().rev() {
            let _ = std::fs::rename(to, from);
        }
        return Err(e);
    }
    drop(_hold);
    // The old entries go now (and on an interruption, through the guards, which outlive them).
    drop(outgoing);
    drop(incoming);
    Ok(())
}

/// Copies the folder `from` into the existing folder `to`: files, and folders recursively.
fn copy_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let dest = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            std::fs::create_dir(&dest)?;
            copy_tree(&entry.path(), &dest)?;
        } else {
            std::fs::copy(entry.path(), &dest)?;
        }
    }
    Ok(())
}

/// Writes `line` and a newline to stderr, losing it quietly when stderr is closed (`2>&1 | head
/// -1`), where `eprintln!` would panic. For the library's own notes on stderr (the sandbox's
/// announcement, a golden being rendered); the CLI has `errln!`.
pub fn stderr_line(line: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "{line}");
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The names in `dir`, sorted (a test helper of other modules too).
    pub(crate) fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_file_is_written_whole_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.png");
        let mut f = OutputFile::create(&target, "-o").unwrap();
        f.write_all(b"abc").unwrap();
        assert!(!target.exists(), "nothing at the target before commit");
        f.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"abc");
        assert_eq!(names(dir.path()), vec!["out.png"]);
    }

    #[test]
    fn a_dropped_file_leaves_nothing_and_keeps_the_old_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.png");
        std::fs::write(&target, b"old").unwrap();
        let mut f = OutputFile::create(&target, "-o").unwrap();
        f.write_all(b"new").unwrap();
        drop(f);
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(names(dir.path()), vec!["out.png"]);
    }

    #[test]
    fn wrong_kinds_and_missing_parents_are_refused_naming_option_and_path() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a-file");
        std::fs::write(&file, b"x").unwrap();
        let folder = dir.path().join("a-folder");
        std::fs::create_dir(&folder).unwrap();

        let e = check_output_file(&folder, "-o").unwrap_err().to_string();
        assert!(e.starts_with("-o ") && e.contains("a-folder") && e.contains("is a folder"));
        let e = check_output_dir(&file, "--out").unwrap_err().to_string();
        assert!(e.starts_with("--out ") && e.contains("is a file"), "{e}");
        let e = check_output_file(&file.join("x.png"), "-o")
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a file, not a folder"), "{e}");
        let e = check_output_file(&dir.path().join("nope/x.png"), "-o")
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not exist"), "{e}");
        // A folder where nobody can create files, even root.
        let e = check_output_file(Path::new("/proc/rtoracle-x.png"), "-o")
            .unwrap_err()
            .to_string();
        assert!(e.contains("cannot create files in '/proc'"), "{e}");
        assert!(!e.contains(".rtoracle-"), "no temporary name: {e}");
        assert_eq!(names(dir.path()), vec!["a-file", "a-folder"]);
    }

    /// A report of `.png` and `.json` files, with folders of them (a batch).
    const REPORT: Replaceable = Replaceable {
        what: "a test report",
        is_output_file: |n| n.ends_with(".png") || n.ends_with(".json"),
        folders: true,
    };

    /// Makes `dir` hold `files` (`sub/name` for a file in a sub-folder), each holding its name.
    fn fill(dir: &Path, files: &[&str]) {
        for f in files {
            let path = dir.join(f);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, f.as_bytes()).unwrap();
        }
    }

    #[test]
    fn a_folder_is_swapped_in_whole() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        fill(&target, &["stale.png", "sub/old.json"]);
        let out = OutputDir::create(&target, "--report", &REPORT).unwrap();
        assert_eq!(
            out.path().parent(),
            Some(dir.path()),
            "staged beside the target"
        );
        out.write("fresh.json", b"{}").unwrap();
        assert!(target.join("stale.png").exists(), "untouched until commit");
        out.commit().unwrap();
        assert_eq!(names(&target), vec!["fresh.json"]);
        assert_eq!(names(dir.path()), vec!["report"]);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode(&target), 0o755);
            assert_eq!(mode(&target.join("fresh.json")), 0o644);
        }
    }

    #[test]
    fn a_dropped_folder_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        let out = OutputDir::create(&target, "--report", &REPORT).unwrap();
        std::fs::write(out.path().join("half.png"), b"x").unwrap();
        drop(out);
        assert!(names(dir.path()).is_empty());
    }

    #[test]
    fn a_new_folder_is_created_by_commit() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fresh");
        let out = OutputDir::create(&target, "--dir", &REPORT).unwrap();
        std::fs::create_dir(out.path().join("a")).unwrap();
        out.write("a/b.json", b"1").unwrap();
        out.commit().unwrap();
        assert_eq!(names(&target), vec!["a"]);
        assert_eq!(std::fs::read(target.join("a/b.json")).unwrap(), b"1");
        assert_eq!(names(dir.path()), vec!["fresh"]);
    }

    #[test]
    fn a_folder_holding_anything_else_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        let refused = |files: &[&str]| {
            let _ = std::fs::remove_dir_all(&target);
            fill(&target, files);
            let e = OutputDir::create(&target, "--out", &REPORT)
                .unwrap_err()
                .to_string();
            assert_eq!(
                names(dir.path()),
                vec!["report"],
                "nothing staged for {files:?}"
            );
            e
        };
        let e = refused(&["a.png", "notes.txt"]);
        assert!(e.starts_with("--out ") && e.contains("report: holds notes.txt, which is not part of a test report; the folder is replaced whole"), "{e}");
        // One level down: named with its folder.
        let e = refused(&["a.png", "sub/b.json", "sub/notes.txt"]);
        assert!(e.contains("holds sub/notes.txt,"), "{e}");
        // Two levels down is not a report's.
        let e = refused(&["sub/deeper/b.json"]);
        assert!(e.contains("holds sub/deeper,"), "{e}");
        // A name that could move the terminal is shown escaped.
        let e = refused(&["a\x1b[2Jb"]);
        assert!(!e.contains('\x1b'), "{e:?}");
        // Without `folders`, no folder at all.
        let flat = Replaceable {
            folders: false,
            ..REPORT
        };
        let _ = std::fs::remove_dir_all(&target);
        fill(&target, &["sub/b.json"]);
        let e = check_replaceable(&target, "--report", &flat)
            .unwrap_err()
            .to_string();
        assert!(e.contains("holds sub,"), "{e}");
        // What is allowed is allowed, and a missing folder too.
        assert!(check_replaceable(&target, "--report", &REPORT).is_ok());
        assert!(check_replaceable(&dir.path().join("new"), "--report", &flat).is_ok());
    }

    #[test]
    fn a_file_put_in_the_target_during_the_run_is_kept_and_the_commit_fails() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        fill(&target, &["old.json"]);
        let out = OutputDir::create(&target, "--out", &REPORT).unwrap();
        out.write("new.json", b"{}").unwrap();
        std::fs::write(target.join("notes.txt"), b"mine").unwrap();
        let e = out.commit().unwrap_err().to_string();
        assert!(e.contains("holds notes.txt"), "{e}");
        assert_eq!(names(&target), vec!["notes.txt", "old.json"]);
        assert_eq!(names(dir.path()), vec!["report"], "no staging folder left");
    }

    #[test]
    fn through_a_link_the_folder_it_leads_to_is_replaced_and_the_link_stays() {
        let dir = tempfile::tempdir().unwrap();
        let real_parent = dir.path().join("elsewhere");
        let real = real_parent.join("rep");
        fill(&real, &["stale.png"]);
        let link = dir.path().join("link");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        let out = OutputDir::create(&link, "--out", &REPORT).unwrap();
        assert_eq!(out.target(), real.canonicalize().unwrap());
        assert_eq!(
            out.path().parent().map(Path::to_path_buf),
            Some(real_parent.canonicalize().unwrap()),
            "staged beside the folder, not the link"
        );
        out.write("index.json", b"{}").unwrap();
        out.commit().unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(names(&link), vec!["index.json"]);
        assert_eq!(names(&real_parent), vec!["rep"]);
        assert_eq!(names(dir.path()), vec!["elsewhere", "link"]);
        // A link that leads nowhere is refused up front.
        let dangling = dir.path().join("dangling");
        std::os::unix::fs::symlink(dir.path().join("gone"), &dangling).unwrap();
        let e = check_replaceable(&dangling, "--out", &REPORT)
            .unwrap_err()
            .to_string();
        assert!(e.contains("symbolic link that leads nowhere"), "{e}");
    }

    #[test]
    fn an_interruption_while_staging_leaves_the_previous_folder_and_no_staging() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        fill(&target, &["old.json"]);
        let out = OutputDir::create(&target, "--out", &REPORT).unwrap();
        out.write("half.json", b"{").unwrap();
        // What the signal thread runs for this folder.
        let OutputDir { _guard, tmp, .. } = out;
        _guard.run_now();
        assert!(!tmp.path().exists(), "the staging folder is removed");
        assert_eq!(names(dir.path()), vec!["report"]);
        assert_eq!(names(&target), vec!["old.json"]);
        assert_eq!(std::fs::read(target.join("old.json")).unwrap(), b"old.json");
    }

    #[test]
    fn errors_writing_into_the_staging_folder_name_the_final_place() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        let out = OutputDir::create(&target, "--out", &REPORT).unwrap();
        let e = out.write("missing/a.json", b"{}").unwrap_err().to_string();
        assert!(
            e.starts_with(&format!(
                "--out {}",
                target.join("missing/a.json").display()
            )),
            "{e}"
        );
        assert!(!e.contains(".rtoracle-"), "{e}");
    }

    #[test]
    fn the_exchange_swaps_two_folders() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        fill(&a, &["from-a.json"]);
        fill(&b, &["from-b.json"]);
        exchange(&a, &b).unwrap();
        assert_eq!(names(&a), vec!["from-b.json"]);
        assert_eq!(names(&b), vec!["from-a.json"]);
        assert!(exchange(&a, &dir.path().join("missing")).is_err());
    }

    #[test]
    fn without_the_exchange_the_old_folder_is_renamed_aside_and_removed() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        fill(&target, &["stale.png", "sub/old.json"]);
        let new = dir.path().join("new");
        fill(&new, &["fresh.json"]);
        assert!(swap_aside(&new, &target).unwrap());
        assert_eq!(names(&target), vec!["fresh.json"]);
        assert_eq!(names(dir.path()), vec!["report"]);
    }

    #[test]
    fn a_folder_that_cannot_be_renamed_gets_the_new_entries_only() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("mount");
        fill(&target, &["stale.png", "sub/old.json", "report.json"]);
        let new = dir.path().join("new");
        fill(&new, &["report.json", "a/feedback.json", "a/heatmap.png"]);
        swap_by_moves(&new, &target).unwrap();
        assert_eq!(names(&target), vec!["a", "report.json"]);
        assert_eq!(
            names(&target.join("a")),
            vec!["feedback.json", "heatmap.png"]
        );
        assert_eq!(
            std::fs::read(target.join("report.json")).unwrap(),
            b"report.json"
        );
        assert_eq!(names(dir.path()), vec!["mount", "new"]);
    }
}
