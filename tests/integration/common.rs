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
