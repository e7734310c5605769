//! Output files and folders that are checked before the work, never half-written, and removed
//! on Ctrl-C.
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
//! - [`OutputDir`] is a fresh temporary sibling folder; [`OutputDir::commit`] swaps it in whole
//!   (the previous folder, if any, is renamed aside, the new one renamed in, the old one
//!   removed), so a reused output folder never keeps a previous run's files, and an interrupted
//!   run leaves the previous folder as it was and no temporary folder.
//!
//! The temporary names come from `tempfile` (already a dependency: unique names created with
//! `O_EXCL`, removed on drop).

use std::ffi::OsString;
use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

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
fn plain(e: &std::io::Error) -> String {
    let inner = e
        .get_ref()
        .and_then(|inner| inner.source())
        .and_then(|source| source.downcast_ref::<std::io::Error>());
    let code = e
        .raw_os_error()
        .or_else(|| inner.and_then(|i| i.raw_os_error()));
    match e.kind() {
        // Creating a file in an existing folder said "not found": /proc, /sys and the like.
        std::io::ErrorKind::NotFound => "the folder does not take new files".to_string(),
        _ => match code {
            Some(code) => std::io::Error::from_raw_os_error(code).to_string(),
            None => std::io::Error::from(e.kind()).to_string(),
        },
    }
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
        let tmp = tempfile::Builder::new()
            .prefix(&temp_prefix(path))
            .tempfile_in(parent_dir(path))
            .map_err(|e| OutputError::new(option, path, plain(&e)))?;
        let guard = interrupt::remove_on_interrupt(tmp.path());
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

/// A folder being filled: a fresh temporary sibling of the target until [`OutputDir::commit`]
/// swaps it in whole.
#[derive(Debug)]
pub struct OutputDir {
    target: PathBuf,
    option: String,
    tmp: tempfile::TempDir,
    _guard: CleanupGuard,
}

impl OutputDir {
    /// Checks `path` (as [`check_output_dir`]) and creates the fresh temporary folder.
    pub fn create(path: &Path, option: &str) -> Result<Self, OutputError> {
        check_output_dir(path, option)?;
        let tmp = tempfile::Builder::new()
            .prefix(&temp_prefix(path))
            .tempdir_in(parent_dir(path))
            .map_err(|e| OutputError::new(option, path, plain(&e)))?;
        let guard = interrupt::remove_on_interrupt(tmp.path());
        Ok(OutputDir {
            target: path.to_path_buf(),
            option: option.to_string(),
            tmp,
            _guard: guard,
        })
    }

    /// The temporary folder, to write into.
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// The target path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Swaps the temporary folder in as the target (mode 0755): the previous target, if any, is
    /// renamed aside, the new folder renamed in, and the previous one removed.
    pub fn commit(self) -> Result<(), OutputError> {
        let OutputDir {
            target,
            option,
            tmp,
            _guard,
        } = self;
        let fail = |e: &std::io::Error| OutputError::new(&option, &target, plain(e));
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o755))
                .map_err(|e| fail(&e))?;
        }
        let new = tmp.keep();
        // From here `new` is ours to remove: on an error, and on an interruption.
        let new_guard = interrupt::remove_on_interrupt(&new);
        drop(_guard);
        let result = swap_in(&new, &target);
        if result.is_err() {
            let _ = std::fs::remove_dir_all(&new);
        }
        drop(new_guard);
        result.map_err(|message| OutputError::new(&option, &target, message))
    }
}

/// Renames `new` onto `target`, moving a previous `target` folder aside first and removing it
/// after.
fn swap_in(new: &Path, target: &Path) -> Result<(), String> {
    match std::fs::symlink_metadata(target) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return std::fs::rename(new, target).map_err(|e| plain(&e).to_string());
        }
        Err(e) => return Err(plain(&e).to_string()),
        Ok(m) if !m.is_dir() => return Err("is a file; a folder is wanted here".to_string()),
        Ok(_) => {}
    }
    // A free name beside the target for the previous folder.
    let aside_holder = tempfile::Builder::new()
        .prefix(&temp_prefix(target))
        .suffix(".old")
        .tempdir_in(parent_dir(target))
        .map_err(|e| plain(&e).to_string())?;
    let aside = aside_holder.path().to_path_buf();
    // Renaming a folder onto an empty folder replaces it; the holder's drop would then remove
    // the previous folder, which is what we want after the swap.
    std::fs::rename(target, &aside).map_err(|e| plain(&e).to_string())?;
    // If interrupted between the two renames, put the previous folder back.
    let restore = {
        let (aside, target) = (aside.clone(), target.to_path_buf());
        interrupt::on_interrupt(move || {
            if !target.exists() {
                let _ = std::fs::rename(&aside, &target);
            }
        })
    };
    if let Err(e) = std::fs::rename(new, target) {
        let _ = std::fs::rename(&aside, target);
        drop(restore);
        // The holder's path is the previous folder again; do not remove it.
        let _ = aside_holder.keep();
        return Err(plain(&e).to_string());
    }
    drop(restore);
    drop(aside_holder);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
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

    #[test]
    fn a_folder_is_swapped_in_whole() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("stale.png"), b"old").unwrap();
        let out = OutputDir::create(&target, "--report").unwrap();
        std::fs::write(out.path().join("fresh.json"), b"{}").unwrap();
        assert!(target.join("stale.png").exists(), "untouched until commit");
        out.commit().unwrap();
        assert_eq!(names(&target), vec!["fresh.json"]);
        assert_eq!(names(dir.path()), vec!["report"]);
    }

    #[test]
    fn a_dropped_folder_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("report");
        let out = OutputDir::create(&target, "--report").unwrap();
        std::fs::write(out.path().join("half.png"), b"x").unwrap();
        drop(out);
        assert!(names(dir.path()).is_empty());
    }

    #[test]
    fn a_new_folder_is_created_by_commit() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fresh");
        let out = OutputDir::create(&target, "--dir").unwrap();
        std::fs::write(out.path().join("a"), b"1").unwrap();
        out.commit().unwrap();
        assert_eq!(names(&target), vec!["a"]);
        assert_eq!(names(dir.path()), vec!["fresh"]);
    }
}
