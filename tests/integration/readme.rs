//! The README: assembled from `docs/sections/` by `docs/assemble-readme.sh` (an edit to one that
//! is not carried to the other fails here), and every `console` example in it is real.
//!
//! A `console` block is a list of commands (`$ ` lines), each followed by its output (stdout and
//! stderr together) up to the next command or the closing fence. The test runs every block of a
//! section in order, in one fresh folder per section (so a file written by one block is there for
//! the next), with `rtoracle` on `PATH` being the binary under test, and compares the outputs
//! after masking what changes from run to run (see [`mask`]):
//! - numbers of seconds (`1.2 s`, `0.48 s`) become `N s`;
//! - the version after `rtoracle ` becomes `VERSION`;
//! - the folder the example ran in becomes `.`, and the binary's path becomes `RTORACLE`;
//! - the number after `uid ` (a sandbox's identity of its own) becomes `N`.
//!
//! Setup lines and commands see `RTORACLE_SOURCE`, the checkout, to copy fixtures from.
//!
//! A block that cannot run here (slow, needs fixtures that only a checkout has, or prints sizes of
//! the binary) is marked `console,no-run`; the test prints how many were skipped. A block may be
//! preceded by `<!-- setup: SHELL -->`: the shell line runs, silently, in the section's folder
//! first.
//!
//! `RTORACLE_UPDATE_README=1 cargo test --test integration -- readme::` writes the real outputs
//! into `docs/sections/` instead of comparing, and reassembles README.md.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The sections in the order the script concatenates them.
const SECTIONS: [&str; 9] = [
    "intro",
    "subcommands",
    "render",
    "golden",
    "oracle",
    "check",
    "compare",
    "grade",
    "development",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn readme_is_the_sections_assembled() {
    let script = std::fs::read_to_string(root().join("docs/assemble-readme.sh")).unwrap();
    assert!(
        script.contains(&format!("for s in {}; do", SECTIONS.join(" "))),
        "docs/assemble-readme.sh lists other sections than this test"
    );
    let sections: Vec<String> = SECTIONS
        .iter()
        .map(|s| std::fs::read_to_string(root().join(format!("docs/sections/{s}.md"))).unwrap())
        .collect();
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(
        readme == sections.join("\n"),
        "README.md differs from docs/sections/: run docs/assemble-readme.sh"
    );
}

/// One command of a block and the output the docs show.
#[derive(Debug)]
struct Step {
    command: String,
    output: Vec<String>,
}

/// A console block: its steps, whether it runs, its setup, and its line range in the file (the
/// lines between the fences).
#[derive(Debug)]
struct Block {
    steps: Vec<Step>,
    run: bool,
    setup: Option<String>,
    body: std::ops::Range<usize>,
}

fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let info = lines[i].strip_prefix("```").map(str::trim);
        let run = match info {
            Some("console") => true,
            Some("console,no-run") => false,
            _ => {
                i += 1;
                continue;
            }
        };
        let setup = i
            .checked_sub(1)
            .and_then(|j| lines[j].trim().strip_prefix("<!-- setup:"))
            .and_then(|s| s.strip_suffix("-->"))
            .map(|s| s.trim().to_string());
        let start = i + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].starts_with("```") {
            end += 1;
        }
        let mut steps: Vec<Step> = Vec::new();
        for line in &lines[start..end] {
            match line.strip_prefix("$ ") {
                Some(cmd) => steps.push(Step {
                    command: cmd.to_string(),
                    output: Vec::new(),
                }),
                None => {
                    if let Some(step) = steps.last_mut() {
                        step.output.push(line.to_string());
                    }
                }
            }
        }
        out.push(Block {
            steps,
            run,
            setup,
            body: start..end,
        });
        i = end + 1;
    }
    out
}

/// Replaces what changes from run to run (see the module docs).
fn mask(text: &str, dir: &Path, bin: &Path) -> String {
    let text = text
        .replace(&bin.display().to_string(), "RTORACLE")
        .replace(&format!("{}/", dir.display()), "")
        .replace(&dir.display().to_string(), ".");
    let text = mask_after(
        &text,
        "rtoracle ",
        |w| w.split('.').count() == 3 && w.split('.').all(|p| p.parse::<u32>().is_ok()),
        "VERSION",
    );
    // The sandbox's uid of its own differs on every run.
    let text = mask_after(&text, "uid ", |w| w.parse::<u64>().is_ok(), "N");
    mask_seconds(&text)
}

/// Replaces each word after `prefix` for which `is` holds by `by`.
fn mask_after(text: &str, prefix: &str, is: impl Fn(&str) -> bool, by: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find(prefix) {
        out.push_str(&rest[..at + prefix.len()]);
        rest = &rest[at + prefix.len()..];
        let end = rest
            .find(|c: char| c.is_whitespace() || c == ')' || c == ',')
            .unwrap_or(rest.len());
        if is(&rest[..end]) {
            out.push_str(by);
            rest = &rest[end..];
        }
    }
    out.push_str(rest);
    out
}

/// `1.2 s` and `0.048 s` become `N s`.
fn mask_seconds(text: &str) -> String {
    let mut out = String::new();
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts_number =
            chars[i].is_ascii_digit() && (i == 0 || !chars[i - 1].is_alphanumeric());
        if starts_number {
            let mut j = i;
            while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
                j += 1;
            }
            let unit = chars.get(j) == Some(&' ')
                && chars.get(j + 1) == Some(&'s')
                && chars.get(j + 2).is_none_or(|c| !c.is_alphanumeric());
            if unit {
                out.push('N');
                i = j;
                continue;
            }
            out.extend(&chars[i..j]);
            i = j;
            continue;
        }
        out.push(chars[i]);
        i += 1;
    }
    out
}

/// A folder with `rtoracle` (a link to the binary under test), to put first on `PATH`.
fn bin_dir() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_rtoracle"));
    std::os::unix::fs::symlink(&bin, dir.path().join("rtoracle")).unwrap();
    (dir, bin)
}

/// Runs one shell command in `dir` with `$?` set to `last`; returns its output (stdout and
/// stderr together, in order) and exit code.
fn run_step(command: &str, dir: &Path, path: &str, last: i32) -> (String, i32) {
    let script = format!("(exit {last}); {command}");
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!("exec 2>&1; {script}"))
        .current_dir(dir)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .env("RTORACLE_SOURCE", root())
        .output()
        .expect("bash runs");
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        out.status.code().unwrap_or(-1),
    )
}

#[test]
fn every_console_example_of_the_readme_is_real_output() {
    let update = std::env::var_os("RTORACLE_UPDATE_README").is_some_and(|v| v == "1");
    let (bins, bin) = bin_dir();
    let path = format!(
        "{}:/usr/bin:/bin:{}",
        bins.path().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (mut ran, mut skipped) = (0, 0);
    let mut failures = Vec::new();
    for section in SECTIONS {
        let file = root().join(format!("docs/sections/{section}.md"));
        let text = std::fs::read_to_string(&file).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        let work = tempfile::tempdir().unwrap();
        // Blocks in reverse order when rewriting, so earlier line numbers stay valid.
        let mut rewritten: Vec<(std::ops::Range<usize>, Vec<String>)> = Vec::new();
        for block in blocks(&text) {
            if !block.run {
                skipped += 1;
                continue;
            }
            ran += 1;
            if let Some(setup) = &block.setup {
                let (out, code) = run_step(setup, work.path(), &path, 0);
                assert_eq!(code, 0, "{section}: setup {setup:?} failed: {out}");
            }
            let mut last = 0;
            let mut body = Vec::new();
            for step in &block.steps {
                let (out, code) = run_step(&step.command, work.path(), &path, last);
                last = code;
                let got = mask(out.trim_end_matches('\n'), work.path(), &bin);
                let want = mask(&step.output.join("\n"), work.path(), &bin);
                if got != want {
                    failures.push(format!(
                        "docs/sections/{section}.md: `$ {}`\n--- the docs show:\n{want}\n--- it prints:\n{got}",
                        step.command
                    ));
                }
                body.push(format!("$ {}", step.command));
                if !out.trim_end_matches('\n').is_empty() {
                    let shown = out
                        .trim_end_matches('\n')
                        .replace(&format!("{}/", work.path().display()), "");
                    body.extend(shown.lines().map(String::from));
                }
            }
            rewritten.push((block.body.clone(), body));
        }
        if update && !rewritten.is_empty() {
            for (range, body) in rewritten.into_iter().rev() {
                lines.splice(range, body);
            }
            let mut new = lines.join("\n");
            if text.ends_with('\n') {
                new.push('\n');
            }
            std::fs::write(&file, new).unwrap();
        }
    }
    eprintln!("README examples: {ran} blocks run, {skipped} marked no-run");
    if update {
        let status = Command::new("bash")
            .arg(root().join("docs/assemble-readme.sh"))
            .status()
            .unwrap();
        assert!(status.success());
        return;
    }
    assert!(ran > 0, "no console block ran");
    assert!(
        failures.is_empty(),
        "{} README examples differ (RTORACLE_UPDATE_README=1 cargo test --test integration -- readme:: rewrites them):\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn the_masks_hide_only_what_changes() {
    let dir = Path::new("/tmp/x");
    let bin = Path::new("/b/rtoracle");
    assert_eq!(
        mask(
            "wrote /tmp/x/g/a.exr (64 spp, 690106 bytes) in 1.2 s; rtoracle 0.1.0 from /b/rtoracle; 3 spheres",
            dir,
            bin
        ),
        "wrote g/a.exr (64 spp, 690106 bytes) in N s; rtoracle VERSION from RTORACLE; 3 spheres"
    );
    assert_eq!(mask_seconds("x 0.48 s, 12 ss, v2 s"), "x N s, 12 ss, v2 s");
}
