//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `rtoracle` binary built for these tests.
pub fn rtoracle() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rtoracle"))
}

/// Runs `rtoracle` with `args` in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    rtoracle()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("rtoracle runs")
}

/// The course's fixture folder from `RTORACLE_COURSE_FIXTURES`, or `None` after saying the test
/// is skipped.
pub fn course_fixtures(test: &str) -> Option<PathBuf> {
    match std::env::var_os("RTORACLE_COURSE_FIXTURES") {
        Some(dir) if !dir.is_empty() => {
            let dir = PathBuf::from(dir);
            let dir = if dir.is_absolute() {
                dir
            } else {
                // Relative paths are taken from the crate root, where `.ci/run` sets it.
                Path::new(env!("CARGO_MANIFEST_DIR")).join(dir)
            };
            Some(dir)
        }
        _ => {
            eprintln!("skipped {test}: RTORACLE_COURSE_FIXTURES is not set");
            None
        }
    }
}

/// The course's real code (`RTORACLE_COURSE_CODE`: a folder of `weekNN/skeleton` and
/// `weekNN/solution`, weeks 4 to 10), or `None` after saying the test is skipped. Tests that
/// need it are also marked `#[cfg_attr(not(rtoracle_course_code), ignore = "...")]`, so that
/// `cargo test` lists them as ignored when the variable is unset.
pub fn course_code(test: &str) -> Option<PathBuf> {
    match std::env::var_os("RTORACLE_COURSE_CODE") {
        Some(dir) if !dir.is_empty() => {
            let dir = PathBuf::from(dir);
            Some(if dir.is_absolute() {
                dir
            } else {
                // Relative paths are taken from the crate root, where `.ci/run` sets it.
                Path::new(env!("CARGO_MANIFEST_DIR")).join(dir)
            })
        }
        _ => {
            eprintln!("skipped {test}: RTORACLE_COURSE_CODE is not set");
            None
        }
    }
}

/// Which of a week's two folders of the course's code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CourseTree {
    /// What a student of the week is handed.
    Skeleton,
    /// The instructor's solution of the week.
    Solution,
}

/// A writable copy of week `week`'s skeleton or solution (the course's folders are read-only in
/// CI, and `main.py` writes its pictures into the working folder), in a temporary folder that
/// is removed when the returned guard drops; `None` (after saying so) when
/// `RTORACLE_COURSE_CODE` is unset. The copy is at `guard.path().join("weekNN-kind")`.
pub fn course_week_copy(
    test: &str,
    week: u8,
    tree: CourseTree,
) -> Option<(tempfile::TempDir, PathBuf)> {
    let root = course_code(test)?;
    let kind = match tree {
        CourseTree::Skeleton => "skeleton",
        CourseTree::Solution => "solution",
    };
    let from = root.join(format!("week{week:02}")).join(kind);
    assert!(
        from.is_dir(),
        "{} is not a folder: RTORACLE_COURSE_CODE must name the course's code (weekNN/skeleton, weekNN/solution)",
        from.display()
    );
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let to = tmp.path().join(format!("week{week:02}-{kind}"));
    copy_tree(&from, &to);
    Some((tmp, to))
}

/// Copies the regular files and folders under `from` to `to` (made), leaving out Python's
/// caches; files are made writable.
pub fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create the copy's folder");
    for entry in std::fs::read_dir(from).expect("read the folder") {
        let entry = entry.expect("a folder entry");
        let path = entry.path();
        let name = entry.file_name();
        if name == "__pycache__" {
            continue;
        }
        let kind = entry.file_type().expect("a file type");
        if kind.is_dir() {
            copy_tree(&path, &to.join(&name));
        } else if kind.is_file() {
            let dest = to.join(&name);
            std::fs::copy(&path, &dest).expect("copy a file");
            let mut perms = std::fs::metadata(&dest).expect("metadata").permissions();
            #[allow(clippy::permissions_set_readonly_false)]
            perms.set_readonly(false);
            std::fs::set_permissions(&dest, perms).expect("make the copy writable");
        }
    }
}

/// Asserts a command failed with exit code 2, one line on stderr mentioning `needle`, no panic.
pub fn assert_bad_input(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "exit code; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panicked: {stderr}");
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "one line on stderr: {stderr}"
    );
    assert!(
        stderr.contains(needle),
        "stderr should mention {needle:?}: {stderr}"
    );
}

/// Folders shared by the tests of a module for the whole run (made once, kept in a `static`),
/// removed when the test process exits: a `static` is never dropped, so without this they would
/// stay in the temporary folder after every run.
static REMOVED_AT_EXIT: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

extern "C" fn remove_shared_folders() {
    if let Ok(dirs) = REMOVED_AT_EXIT.lock() {
        for dir in dirs.iter() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// Makes a temporary folder named `prefix...` that lives until the test process exits (the
/// test harness exits through `exit`, which runs the removal registered here).
pub fn shared_temporary_folder(prefix: &str) -> &'static Path {
    static REGISTERED: std::sync::Once = std::sync::Once::new();
    REGISTERED.call_once(|| {
        // SAFETY: registers a plain function with no arguments; it only locks a static and
        // removes folders.
        unsafe {
            libc::atexit(remove_shared_folders);
        }
    });
    let dir = tempfile::Builder::new()
        .prefix(prefix)
        .tempdir()
        .unwrap()
        .keep();
    REMOVED_AT_EXIT.lock().unwrap().push(dir.clone());
    Box::leak(dir.into_boxed_path())
}

/// Inserts `line` as the first line of the body of the first `def NAME(` found in `files`, in
/// their order (after the line starting with `after`, when given), indented as the body is;
/// returns the file and the inserted line's number (1-based), or `None` when no file has it.
pub fn insert_first_in_def(
    files: &[PathBuf],
    name: &str,
    after: Option<&str>,
    line: &str,
) -> Option<(PathBuf, usize)> {
    for path in files {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        let start = match after {
            Some(a) => match lines.iter().position(|l| l.starts_with(a)) {
                Some(i) => i,
                None => continue,
            },
            None => 0,
        };
        let Some(def) = (start..lines.len())
            .find(|&i| lines[i].trim_start().starts_with(&format!("def {name}(")))
        else {
            continue;
        };
        // The body: the first line of code after the `def` (which may span lines up to its
        // `:`), past blank lines and comments.
        let colon = (def..lines.len())
            .find(|&i| lines[i].trim_end().ends_with(':'))
            .unwrap();
        let body = (colon + 1..lines.len())
            .find(|&i| {
                let t = lines[i].trim();
                !t.is_empty() && !t.starts_with('#')
            })
            .unwrap();
        let indent: String = lines[body]
            .chars()
            .take_while(|c| c.is_whitespace())
            .collect();
        lines.insert(body, format!("{indent}{line}"));
        std::fs::write(path, lines.join("\n") + "\n").unwrap();
        return Some((path.clone(), body + 1));
    }
    None
}

/// `examples/adapter-c/adapter.c` built with `cc` (or `$CC`, and `extra` flags) in `dir`, or
/// `None` after saying the test is skipped.
pub fn build_c_adapter(dir: &Path, name: &str, extra: &[&str]) -> Option<PathBuf> {
    build_c_example(dir, "adapter.c", name, extra)
}

/// `examples/adapter-c/SOURCE` built with `cc` (or `$CC`; `-O2 -Wall -Werror` and `extra`)
/// into `dir/name`, or `None` after saying the test is skipped.
pub fn build_c_example(dir: &Path, source: &str, name: &str, extra: &[&str]) -> Option<PathBuf> {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let exe = dir.join(name);
    let source = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/adapter-c")
        .join(source);
    let built = Command::new(&cc)
        .args(["-O2", "-Wall", "-Werror"])
        .args(extra)
        .arg("-o")
        .arg(&exe)
        .arg(&source)
        .arg("-lm")
        .status();
    if !built.map(|s| s.success()).unwrap_or(false) {
        eprintln!("skipped: no working C compiler ({cc})");
        return None;
    }
    Some(exe)
}
