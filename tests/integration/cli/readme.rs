//! The docs (README.md and every page of `docs/`): every `console` example in them is real,
//! every relative link resolves, and none names a design note that is not in the repository.
//!
//! A `console` block is a list of commands (`$ ` lines), each followed by its output (stdout and
//! stderr together) up to the next command or the closing fence. The test runs every block of a
//! page in order (the pages at the same time), in one fresh folder per page (so a file written
//! by one block is there for the next; mode 755, so a sandbox user can run a script written
//! there), with `rtoracle` on `PATH` being the binary under test and `RTORACLE_CACHE_DIR` the
//! page folder's `.cache` (so no golden is cached in the user's home), and compares the outputs
//! after masking what changes from run to run (see [`mask`]):
//! - numbers of seconds (`1.2 s`, `0.48 s`) become `N s`;
//! - the version after `rtoracle ` and in a cached golden's name (`...-4096spp-0.1.0.exr`)
//!   becomes `VERSION`;
//! - the folder the example ran in becomes `.`, and the binary's path becomes `RTORACLE`;
//! - a sandbox's uid of its own (the number after `uid ` in text, `'uid': ` in a Python dict,
//!   `"uid": ` in JSON) becomes `N`;
//! - a seed drawn from the OS (`seed 1467482570707934685 (secret, drawn now)`) becomes `N`; a
//!   seed given with `--seed` is compared.
//!
//! Setup lines and commands see `RTORACLE_SOURCE`, the checkout, to copy fixtures from.
//!
//! Comment lines right before a block prepare or explain it:
//! - `<!-- fixtures: WHAT... -->` makes fixture submissions in the page's folder first: `NAME`
//!   (or `NAME=FOLDER`, `FOLDER` ending in the name) is `tests/fixtures/submissions/NAME` made a
//!   submission by `rtoracle::bench::grade::materialize` (its images rendered), and
//!   `python:VARIANT=FOLDER` is the `check` fixture `tests/fixtures/python/variants/VARIANT` (the
//!   common modules, then the variant's) by `rtoracle::bench::harness::assemble_fixture`, and
//!   `mistake:SCENE:MISTAKE=FILE.png` is the built-in `SCENE` rendered with a mistake of
//!   `rtoracle::compare::diagnose::mistakes` (`MISTAKE` by the names `examples/mistake.rs` takes) by
//!   `render_with_mistake`, at the scene's samples per pixel and seed 1: the PNG that
//!   `cargo run --release --example mistake -- SCENE MISTAKE FILE.png` writes;
//! - `<!-- setup: SHELL -->`: the shell line runs, silently, in the page's folder (after the
//!   fixtures are made);
//! - `<!-- no-run: REASON -->` says why a block marked `console,no-run` cannot run in the tests
//!   (every such block must say it; the test prints how many were skipped).
//!
//! A shell transcript (a line starting `$ `, indented or not) in a fenced block of any other
//! kind (bare, `text`, fenced with `~~~`, indented in a list...) fails the test: every transcript
//! is a `console` block, or `console,no-run` with a reason.
//!
//! `RTORACLE_UPDATE_README=1 cargo test --release --test integration -- cli::readme::` writes the real outputs
//! of the examples that differ into their pages instead of comparing (the others keep their
//! masked figures).
//!
//! Links ([`every_relative_link_resolves`]): every link and image of a page whose target is not a
//! URL must name a file or folder of the repository (relative to the page, never leaving the
//! repository), and a `#anchor` must be a heading of the Markdown page it points into, spelt as
//! GitHub spells heading anchors ([`slug`]).

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The pages of the docs, relative to the checkout: README.md, then every Markdown file under
/// `docs/` in name order.
fn pages() -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let mut docs = Vec::new();
    walk(&root().join("docs"), &mut docs);
    docs.sort();
    let mut pages = vec!["README.md".to_string()];
    pages.extend(docs.iter().map(|p| {
        p.strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .into_owned()
    }));
    pages
}

/// One command of a block and the output the docs show.
#[derive(Debug)]
struct Step {
    command: String,
    output: Vec<String>,
}

/// A console block: its steps, whether it runs, the directives before it (see the module docs),
/// its line range in the file (the lines between the fences) and the line of its opening fence.
#[derive(Debug)]
struct Block {
    steps: Vec<Step>,
    run: bool,
    setup: Option<String>,
    fixtures: Vec<Fixture>,
    no_run_reason: Option<String>,
    body: std::ops::Range<usize>,
    fence: usize,
}

/// A fixture to make in the page's folder before a block.
#[derive(Debug, PartialEq)]
enum Fixture {
    /// `tests/fixtures/submissions/<name>`, materialized into the folder.
    Submission { name: String, folder: String },
    /// `tests/fixtures/python/variants/<variant>` with the common modules, into the folder.
    Python { variant: String, folder: String },
    /// A built-in scene rendered with a mistake of the catalogue, as `examples/mistake.rs`
    /// renders it (the scene's samples per pixel, seed 1), into the PNG `file`.
    Mistake {
        scene: String,
        mistake: String,
        file: String,
    },
}

/// The value of the directive `<!-- key: VALUE -->` on `line`, if it is one.
fn directive<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.trim()
        .strip_prefix("<!--")?
        .trim_start()
        .strip_prefix(key)?
        .strip_prefix(':')?
        .strip_suffix("-->")
        .map(str::trim)
}

/// The fixtures of a `fixtures:` directive (see the module docs).
fn parse_fixtures(spec: &str) -> Result<Vec<Fixture>, String> {
    spec.split_whitespace()
        .map(|word| {
            let (what, folder) = match word.split_once('=') {
                Some((what, folder)) => (what, folder),
                None => (word.rsplit('/').next().unwrap_or(word), word),
            };
            if what.is_empty()
                || folder.is_empty()
                || folder.starts_with('/')
                || folder.contains("..")
            {
                return Err(format!(
                    "fixture {word:?}: want NAME, FOLDER/NAME, NAME=FOLDER or python:VARIANT=FOLDER"
                ));
            }
            if let Some(spec) = what.strip_prefix("mistake:") {
                return match spec.split_once(':') {
                    Some((scene, mistake))
                        if word.contains('=')
                            && rtoracle::scene::builtin(scene).is_ok()
                            && rtoracle::compare::diagnose::mistakes::Mistake::from_argument(mistake).is_some() =>
                    {
                        Ok(Fixture::Mistake {
                            scene: scene.to_string(),
                            mistake: mistake.to_string(),
                            file: folder.to_string(),
                        })
                    }
                    _ => Err(format!(
                        "fixture {word:?}: want mistake:SCENE:MISTAKE=FILE.png, a built-in scene and a mistake examples/mistake.rs knows"
                    )),
                };
            }
            Ok(match what.strip_prefix("python:") {
                Some(variant) => Fixture::Python {
                    variant: variant.to_string(),
                    folder: folder.to_string(),
                },
                None => Fixture::Submission {
                    name: what.to_string(),
                    folder: folder.to_string(),
                },
            })
        })
        .collect()
}

/// Makes `fixture` in `dir`.
fn make_fixture(fixture: &Fixture, dir: &Path) -> Result<(), String> {
    match fixture {
        Fixture::Submission { name, folder } => {
            rtoracle::bench::grade::materialize(name, &dir.join(folder)).map(|_| ())
        }
        Fixture::Python { variant, folder } => {
            let made = rtoracle::bench::harness::assemble_fixture(variant)
                .map_err(|e| format!("python fixture {variant}: {e}"))?;
            let dest = dir.join(folder);
            std::fs::create_dir_all(&dest).map_err(|e| format!("{}: {e}", dest.display()))?;
            for entry in std::fs::read_dir(made.path()).map_err(|e| e.to_string())? {
                let entry = entry.map_err(|e| e.to_string())?;
                std::fs::copy(entry.path(), dest.join(entry.file_name()))
                    .map_err(|e| format!("{}: {e}", entry.path().display()))?;
            }
            Ok(())
        }
        Fixture::Mistake {
            scene,
            mistake,
            file,
        } => {
            let description = rtoracle::scene::builtin(scene).map_err(|e| e.to_string())?;
            let mistake = rtoracle::compare::diagnose::mistakes::Mistake::from_argument(mistake)
                .ok_or("an unknown mistake")?;
            let spp = description.image.samples_per_pixel;
            let image = rtoracle::compare::diagnose::mistakes::render_with_mistake(
                &description,
                mistake,
                spp,
                1,
            );
            rtoracle::image_io::write_png(&dir.join(file), &image).map_err(|e| e.to_string())
        }
    }
}

/// What a page holds: its console blocks, and the opening fence (0-based line) of every other
/// fenced block with a line starting `$ `, a shell transcript nothing would check.
#[derive(Debug)]
struct Parsed {
    blocks: Vec<Block>,
    stray_transcripts: Vec<usize>,
}

/// The console blocks of `text` (see [`parse`]).
fn blocks(text: &str) -> Vec<Block> {
    parse(text).blocks
}

/// The closing fence of the block whose body starts at `start`, opened by `len` of `mark`
/// (`` ` `` or `~`): the index of the first line of as many or more of them only (indented or
/// not), or the end.
fn closing_fence(lines: &[&str], start: usize, mark: char, len: usize) -> usize {
    let closes = |line: &str| {
        let line = line.trim();
        line.len() >= len && line.chars().all(|c| c == mark)
    };
    (start..lines.len())
        .find(|&i| closes(lines[i]))
        .unwrap_or(lines.len())
}

/// Reads the fenced blocks of a page: the console ones, and the others only for transcripts.
fn parse(text: &str) -> Parsed {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut stray_transcripts = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        // A fence of 3 or more backticks (4 when the output holds fences of 3) or tildes,
        // closed by a line of as many or more of them only. A console block's fence is of
        // backticks and starts its line.
        let fence = lines[i].trim_start();
        let mark = match fence.chars().next() {
            Some(c @ ('`' | '~')) => c,
            _ => {
                i += 1;
                continue;
            }
        };
        let ticks = fence.len() - fence.trim_start_matches(mark).len();
        if ticks < 3 {
            i += 1;
            continue;
        }
        let info = fence[ticks..].trim();
        let run = match info {
            "console" if mark == '`' && fence.len() == lines[i].len() => true,
            "console,no-run" if mark == '`' && fence.len() == lines[i].len() => false,
            _ => {
                // Another block (`text`, `toml`, bare, `~~~`, indented in a list...): skipped
                // whole, but a shell transcript in it would be an example no test keeps.
                let end = closing_fence(&lines, i + 1, mark, ticks);
                if lines[i + 1..end]
                    .iter()
                    .any(|l| l.trim_start().starts_with("$ "))
                {
                    stray_transcripts.push(i);
                }
                i = end + 1;
                continue;
            }
        };
        // The directive lines right above the fence.
        let (mut setup, mut fixtures, mut no_run_reason) = (None, Vec::new(), None);
        let mut j = i;
        while j > 0 && lines[j - 1].trim().starts_with("<!--") {
            j -= 1;
            let line = lines[j];
            if let Some(s) = directive(line, "setup") {
                setup = Some(s.to_string());
            } else if let Some(s) = directive(line, "fixtures") {
                fixtures = parse_fixtures(s).unwrap_or_else(|e| panic!("line {}: {e}", j + 1));
            } else if let Some(s) = directive(line, "no-run") {
                no_run_reason = Some(s.to_string()).filter(|s| !s.is_empty());
            }
        }
        let start = i + 1;
        let end = closing_fence(&lines, start, '`', ticks);
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
            fixtures,
            no_run_reason,
            body: start..end,
            fence: i,
        });
        i = end + 1;
    }
    Parsed {
        blocks: out,
        stray_transcripts,
    }
}

/// Replaces what changes from run to run (see the module docs).
fn mask(text: &str, dir: &Path, bin: &Path) -> String {
    let text = text
        .replace(&bin.display().to_string(), "RTORACLE")
        .replace(&format!("{}/", dir.display()), "")
        .replace(&dir.display().to_string(), ".");
    let text = mask_after(&text, "rtoracle ", "", is_version, "VERSION");
    // A cached golden's name ends in the tool's version: `<sha256>-<spp>spp-<version>.exr`.
    let text = mask_after(
        &text,
        "spp-",
        "",
        |w| w.strip_suffix(".exr").is_some_and(is_version),
        "VERSION.exr",
    );
    // The sandbox's uid of its own differs on every run: in text, a Python dict and JSON.
    let is_number = |w: &str| !w.is_empty() && w.bytes().all(|b| b.is_ascii_digit());
    let text = mask_after(&text, "uid ", "", is_number, "N");
    let text = mask_after(&text, "'uid': ", "", is_number, "N");
    let text = mask_after(&text, "\"uid\": ", "", is_number, "N");
    // A secret seed is drawn from the OS on every run (one given with `--seed` is not masked).
    let text = mask_after(&text, "seed ", " (secret, drawn now)", is_number, "N");
    mask_seconds(&text)
}

/// `0.1.0`: three numbers separated by dots.
fn is_version(w: &str) -> bool {
    w.split('.').count() == 3 && w.split('.').all(|p| p.parse::<u32>().is_ok())
}

/// Replaces each word after `prefix` for which `is` holds, and which `suffix` follows, by `by`.
/// A word ends at white space, `)`, `,` or `}`.
fn mask_after(
    text: &str,
    prefix: &str,
    suffix: &str,
    is: impl Fn(&str) -> bool,
    by: &str,
) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find(prefix) {
        out.push_str(&rest[..at + prefix.len()]);
        rest = &rest[at + prefix.len()..];
        let end = rest
            .find(|c: char| c.is_whitespace() || matches!(c, ')' | ',' | '}'))
            .unwrap_or(rest.len());
        if is(&rest[..end]) && rest[end..].starts_with(suffix) {
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

/// Runs one shell command in `dir` (the page's folder) with `$?` set to `last`, and with the
/// golden cache in `dir/.cache`; returns its output (stdout and stderr together, in order) and
/// exit code.
fn run_step(command: &str, dir: &Path, path: &str, last: i32) -> (String, i32) {
    let script = format!("(exit {last}); {command}");
    let out = Command::new("bash")
        .arg("-c")
        .arg(format!("exec 2>&1; {script}"))
        .current_dir(dir)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .env("RTORACLE_SOURCE", root())
        .env("RTORACLE_CACHE_DIR", dir.join(".cache"))
        .output()
        .expect("bash runs");
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        out.status.code().unwrap_or(-1),
    )
}

/// What running one page's examples gave.
struct PageRun {
    ran: usize,
    skipped: usize,
    failures: Vec<String>,
}

/// Runs the console blocks of the page `page` (a path relative to the checkout) in a fresh
/// folder of its own (see the module docs); with `update`, writes the real outputs of those
/// that differ into its file.
fn run_page(page: &str, update: bool, path: &str, bin: &Path) -> PageRun {
    let file = root().join(page);
    let text = std::fs::read_to_string(&file).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    // World-readable, as a user's folder usually is: the sandbox user runs scripts from it
    // (`--python ./python3-no-numpy`).
    let work = tempfile::Builder::new()
        .permissions(std::fs::Permissions::from_mode(0o755))
        .tempdir()
        .unwrap();
    let mut run = PageRun {
        ran: 0,
        skipped: 0,
        failures: Vec::new(),
    };
    // Blocks in reverse order when rewriting, so earlier line numbers stay valid.
    let mut rewritten: Vec<(std::ops::Range<usize>, Vec<String>)> = Vec::new();
    let parsed = parse(&text);
    for fence in parsed.stray_transcripts {
        run.failures.push(format!(
            "{page}:{}: a shell transcript must be a `console` block (or `console,no-run` with a reason)",
            fence + 1
        ));
    }
    for block in parsed.blocks {
        if !block.run {
            run.skipped += 1;
            if block.no_run_reason.is_none() {
                run.failures.push(format!(
                    "{page}:{}: a `console,no-run` block without a `<!-- no-run: REASON -->` line before it",
                    block.fence + 1
                ));
            }
            continue;
        }
        run.ran += 1;
        for fixture in &block.fixtures {
            if let Err(e) = make_fixture(fixture, work.path()) {
                panic!("{page}: fixture {fixture:?}: {e}");
            }
        }
        if let Some(setup) = &block.setup {
            let (out, code) = run_step(setup, work.path(), path, 0);
            assert_eq!(code, 0, "{page}: setup {setup:?} failed: {out}");
        }
        let mut last = 0;
        let mut body = Vec::new();
        for step in &block.steps {
            let (out, code) = run_step(&step.command, work.path(), path, last);
            last = code;
            let got = mask(out.trim_end_matches('\n'), work.path(), bin);
            let want = mask(&step.output.join("\n"), work.path(), bin);
            if got != want {
                run.failures.push(format!(
                    "{page}: `$ {}`\n--- the docs show:\n{want}\n--- it prints:\n{got}",
                    step.command
                ));
            }
            body.push(format!("$ {}", step.command));
            if got == want {
                // Unchanged but for what the masks hide: the docs keep their figures.
                body.extend(step.output.iter().cloned());
            } else if !out.trim_end_matches('\n').is_empty() {
                // The page's folder as the masks see it (a reader's own folder).
                let shown = out
                    .trim_end_matches('\n')
                    .replace(&format!("{}/", work.path().display()), "")
                    .replace(&work.path().display().to_string(), ".");
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
    run
}

#[test]
fn every_console_example_of_the_docs_is_real_output() {
    let update = std::env::var_os("RTORACLE_UPDATE_README").is_some_and(|v| v == "1");
    let (bins, bin) = bin_dir();
    let path = format!(
        "{}:/usr/bin:/bin:{}",
        bins.path().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    // The pages are independent (a folder each), so they run at the same time: the test takes
    // about as long as grading.md, its longest.
    let pages = pages();
    let runs: Vec<PageRun> = std::thread::scope(|s| {
        let handles: Vec<_> = pages
            .iter()
            .map(|page| s.spawn(|| run_page(page, update, &path, &bin)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a page's examples ran"))
            .collect()
    });
    let ran: usize = runs.iter().map(|r| r.ran).sum();
    let skipped: usize = runs.iter().map(|r| r.skipped).sum();
    let failures: Vec<String> = runs.into_iter().flat_map(|r| r.failures).collect();
    eprintln!(
        "docs examples: {ran} blocks run, {skipped} marked no-run, in {} pages",
        pages.len()
    );
    if update {
        return;
    }
    assert!(ran > 0, "no console block ran");
    assert!(
        failures.is_empty(),
        "{} examples of the docs differ (RTORACLE_UPDATE_README=1 cargo test --release --test integration -- cli::readme:: rewrites them):\n\n{}",
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
    // A sandbox's uid, in text, a Python dict and JSON; nothing else named uid.
    assert_eq!(
        mask(
            "uid 1077390338 (a uid of its own); {'uid': 1077390338}, {\"uid\": 12, 'uid': None, 'uids': 3}",
            dir,
            bin
        ),
        "uid N (a uid of its own); {'uid': N}, {\"uid\": N, 'uid': None, 'uids': 3}"
    );
    // A seed drawn now, not one given.
    assert_eq!(
        mask(
            "rubric.toml with seed 1467482570707934685 (secret, drawn now); seed 42 (from --seed); seed 7",
            dir,
            bin
        ),
        "rubric.toml with seed N (secret, drawn now); seed 42 (from --seed); seed 7"
    );
    // The version in a cached golden's name, not the sample count or the hash.
    assert_eq!(
        mask(
            "/tmp/x/.cache/goldens/549a18-4096spp-0.1.0.exr golden-64spp-v1.exr, 4096spp-0.1.exr",
            dir,
            bin
        ),
        ".cache/goldens/549a18-4096spp-VERSION.exr golden-64spp-v1.exr, 4096spp-0.1.exr"
    );
}

#[test]
fn directives_before_a_block_are_read() {
    let text = "x\n<!-- no-run: slow -->\n```console,no-run\n$ a\n```\n\
                <!-- fixtures: sphere-bug honest=week04-honest subs/hang python:bug_far_root_first=far -->\n\
                <!-- setup: touch f -->\n```console\n$ b\nout\n```\n```console\n$ c\n```\n";
    let b = blocks(text);
    assert_eq!(b.len(), 3);
    assert!(!b[0].run);
    assert_eq!(b[0].no_run_reason.as_deref(), Some("slow"));
    assert!(b[1].run && b[1].no_run_reason.is_none());
    assert_eq!(b[1].setup.as_deref(), Some("touch f"));
    let sub = |name: &str, folder: &str| Fixture::Submission {
        name: name.into(),
        folder: folder.into(),
    };
    assert_eq!(
        b[1].fixtures,
        [
            sub("sphere-bug", "sphere-bug"),
            sub("honest", "week04-honest"),
            sub("hang", "subs/hang"),
            Fixture::Python {
                variant: "bug_far_root_first".into(),
                folder: "far".into()
            }
        ]
    );
    assert_eq!(b[1].steps[0].output, ["out"]);
    // Directives belong to the block right below them only.
    assert!(b[2].setup.is_none() && b[2].fixtures.is_empty());
    // A block of four backticks holds fences of three.
    let b = blocks("````console\n$ cat f.md\n```python\nx = 1\n```\n````\n```toml\n```\n");
    assert_eq!(b.len(), 1);
    assert_eq!(b[0].steps[0].output, ["```python", "x = 1", "```"]);
    assert!(parse_fixtures("honest=/tmp/x").is_err());
    assert!(parse_fixtures("honest=../x").is_err());
    assert_eq!(
        parse_fixtures("mistake:week04-sphere:flip-y=flipped.png"),
        Ok(vec![Fixture::Mistake {
            scene: "week04-sphere".into(),
            mistake: "flip-y".into(),
            file: "flipped.png".into()
        }])
    );
    // No file, an unknown scene or mistake, a file outside the folder.
    for bad in [
        "mistake:week04-sphere:flip-y",
        "mistake:no-such-scene:flip-y=a.png",
        "mistake:week04-sphere:flip-z=a.png",
        "mistake:week04-sphere=a.png",
        "mistake:week04-sphere:bgr=../a.png",
    ] {
        assert!(parse_fixtures(bad).is_err(), "{bad}");
    }
}

#[test]
fn a_transcript_outside_a_console_block_is_found() {
    let text = "```\n$ rtoracle scenes\nweek04-sphere\n```\n\
                ```text\nno command\n```\n\
                ```toml\nx = \"$ not at the start\"\n```\n\
                ````\n```console\n```\n$ inside four\n````\n\
                ```console\n$ rtoracle scenes\n```\n\
                - a list item:\n  ```\n  $ rtoracle scenes\n  ```\n\
                ~~~\n$ rtoracle scenes\n~~~\n\
                ```text\n$ cargo bench\n";
    let parsed = parse(text);
    // The bare block, the four-backtick one (its inner fences do not close it), the indented
    // one, the one fenced with tildes and the unclosed one at the end; not the blocks without
    // a `$ ` line at a line's start.
    assert_eq!(parsed.stray_transcripts, [0, 10, 19, 22, 25]);
    // The console block after them is still read, and the one inside four backticks is not.
    assert_eq!(parsed.blocks.len(), 1);
    assert_eq!(parsed.blocks[0].fence, 15);
    assert_eq!(parsed.blocks[0].steps[0].command, "rtoracle scenes");
}

/// The anchor GitHub gives a heading whose text is `text`: lower case, every character that is
/// not a letter, a digit, a space, `-` or `_` dropped, and each space made a `-`.
fn slug(text: &str) -> String {
    text.trim()
        .chars()
        .flat_map(char::to_lowercase)
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of the headings of a Markdown text, with GitHub's `-1`, `-2`... for repeats.
fn anchors(text: &str) -> Vec<String> {
    use pulldown_cmark::{Event, Options, Parser, Tag, TagEnd};
    let mut out: Vec<String> = Vec::new();
    let mut heading: Option<String> = None;
    for event in Parser::new_ext(text, Options::ENABLE_TABLES) {
        match event {
            Event::Start(Tag::Heading { .. }) => heading = Some(String::new()),
            Event::Text(t) | Event::Code(t) => {
                if let Some(h) = heading.as_mut() {
                    h.push_str(&t);
                }
            }
            Event::End(TagEnd::Heading(_)) => {
                let base = slug(&heading.take().unwrap_or_default());
                let mut anchor = base.clone();
                let mut n = 0;
                while out.contains(&anchor) {
                    n += 1;
                    anchor = format!("{base}-{n}");
                }
                out.push(anchor);
            }
            _ => {}
        }
    }
    out
}

/// The targets of the links and images of a Markdown text, with the line each is on.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    use pulldown_cmark::{Event, Options, Parser, Tag};
    Parser::new_ext(text, Options::ENABLE_TABLES)
        .into_offset_iter()
        .filter_map(|(event, range)| match event {
            Event::Start(Tag::Link { dest_url, .. } | Tag::Image { dest_url, .. }) => {
                let line = text[..range.start].matches('\n').count() + 1;
                Some((line, dest_url.into_string()))
            }
            _ => None,
        })
        .collect()
}

/// Why the link `target` of the page `page` (relative to `root`) does not resolve, if it does
/// not; `None` for a URL or a link that resolves.
fn broken_link(root: &Path, page: &Path, target: &str) -> Option<String> {
    let is_url = target.starts_with("//")
        || target.split_once(':').is_some_and(|(scheme, _)| {
            !scheme.is_empty()
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        });
    if is_url {
        return None;
    }
    let (path, anchor) = match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target, None),
    };
    let file = if path.is_empty() {
        root.join(page)
    } else {
        if path.starts_with('/') {
            return Some("an absolute path (links are relative to the page)".into());
        }
        let mut resolved = root.join(page).parent().unwrap().to_path_buf();
        for part in Path::new(path).components() {
            match part {
                std::path::Component::ParentDir => {
                    resolved.pop();
                }
                std::path::Component::Normal(p) => resolved.push(p),
                _ => {}
            }
            if !resolved.starts_with(root) {
                return Some("leaves the repository".into());
            }
        }
        if !resolved.exists() {
            return Some(format!(
                "no such file {}",
                resolved.strip_prefix(root).unwrap().display()
            ));
        }
        resolved
    };
    let anchor = anchor.filter(|a| !a.is_empty())?;
    if file.extension().is_none_or(|e| e != "md") {
        return Some(format!(
            "#{anchor} points into {}, which is not a Markdown page",
            file.display()
        ));
    }
    let text = std::fs::read_to_string(&file).unwrap();
    if anchors(&text).iter().any(|a| a == anchor) {
        None
    } else {
        Some(format!(
            "no heading of {} has the anchor #{anchor}",
            file.strip_prefix(root).unwrap().display()
        ))
    }
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(root().join(&page)).unwrap();
        for (line, target) in link_targets(&text) {
            checked += 1;
            if let Some(why) = broken_link(root(), Path::new(&page), &target) {
                broken.push(format!("{page}:{line}: ({target}): {why}"));
            }
        }
    }
    assert!(checked > 0, "no link found");
    assert!(
        broken.is_empty(),
        "links that do not resolve:\n{}",
        broken.join("\n")
    );
}

#[test]
fn links_are_resolved_as_github_resolves_them() {
    assert_eq!(slug("`rtoracle render`"), "rtoracle-render");
    assert_eq!(
        slug("Students' code: every week's API, their triangles, and a diagnosis"),
        "students-code-every-weeks-api-their-triangles-and-a-diagnosis"
    );
    assert_eq!(
        slug("Reports: JSON, heatmap, HTML"),
        "reports-json-heatmap-html"
    );
    assert_eq!(slug("snake_case and a-b"), "snake_case-and-a-b");
    assert_eq!(
        anchors("# A\n\n## `x` y\n\n```\n# not a heading\n```\n\n## A\n\n## A\n"),
        ["a", "x-y", "a-1", "a-2"]
    );
    assert_eq!(
        link_targets("[a](b.md#c) and ![i](img.png)\n\n`[not](a link)`\n[u](https://x.y/z)\n"),
        [
            (1, "b.md#c".to_string()),
            (1, "img.png".to_string()),
            (4, "https://x.y/z".to_string())
        ]
    );
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir(root.join("docs")).unwrap();
    std::fs::write(root.join("docs/p.md"), "# Page\n\n## The part\n").unwrap();
    std::fs::write(root.join("README.md"), "# R\n").unwrap();
    let page = Path::new("docs/p.md");
    for ok in [
        "p.md",
        "p.md#the-part",
        "#page",
        "../README.md",
        "../docs",
        "https://x/y#z",
        "mailto:a@b",
    ] {
        assert_eq!(broken_link(root, page, ok), None, "{ok}");
    }
    for bad in [
        "q.md",
        "p.md#the-parts",
        "#nothing",
        "../../x.md",
        "/etc/passwd",
        "../README.md#z",
    ] {
        assert!(broken_link(root, page, bad).is_some(), "{bad}");
    }
}

/// The design notes the project was written from live outside the repository: what the code
/// and the docs need from them is in `docs/`, and nothing names them.
#[test]
fn nothing_names_a_design_note_outside_the_repository() {
    const NOTES: [&str; 5] = [
        "GRADING.md",
        "COURSE_API.md",
        "ORACLE.md",
        "IMAGES.md",
        "COURSE_LATER_WEEKS.md",
    ];
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else {
                out.push(path);
            }
        }
    }
    let mut files = vec![root().join("README.md")];
    walk(&root().join("src"), &mut files);
    walk(&root().join("docs"), &mut files);
    let mut found = Vec::new();
    for file in files {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        for (n, line) in text.lines().enumerate() {
            if let Some(note) = NOTES.iter().find(|note| line.contains(*note)) {
                found.push(format!(
                    "{}:{}: names {note}",
                    file.strip_prefix(root()).unwrap().display(),
                    n + 1
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "point to docs/ instead (write what is needed there):\n{}",
        found.join("\n")
    );
}

/// Each package of `cargo tree` with the features it is built with, for the dependency `edges`
/// given (`no-dev`: what `cargo run --release` builds; `all`: what `cargo test` builds).
fn resolved_features(edges: &str) -> std::collections::BTreeMap<String, String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--offline", "--locked", "--prefix", "none"])
        .args(["-e", edges, "-f", "{p}|{f}"])
        .current_dir(root())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|line| {
            let (package, features) = line.trim_end_matches(" (*)").split_once('|')?;
            Some((package.trim().to_string(), features.trim().to_string()))
        })
        .collect()
}

/// The README's two set-up commands share one build: `cargo test --release` resolves, for every
/// dependency, the features `cargo run --release` resolved. Cargo turns on the features that
/// dev-dependencies ask of a shared dependency only when it builds tests, so a dev-dependency
/// that asks for one makes the second command rebuild that dependency, everything above it and
/// the library. The fix is to turn the same features on in `[dependencies]` (as `Cargo.toml`
/// does for getrandom and once_cell).
#[test]
fn the_tests_resolve_the_features_of_the_release_build() {
    let release = resolved_features("no-dev");
    let tests = resolved_features("all");
    assert!(release.len() > 20, "cargo tree listed {release:?}");
    let differ: Vec<String> = release
        .iter()
        .filter_map(|(package, features)| {
            let with_dev = tests.get(package)?;
            (with_dev != features).then(|| {
                format!(
                    "{package}: [{features}] without the dev-dependencies, [{with_dev}] with them"
                )
            })
        })
        .collect();
    assert!(
        differ.is_empty(),
        "`cargo test --release` would rebuild these and the library; turn their features on in [dependencies]:\n{}",
        differ.join("\n")
    );
}

/// The README's test command: the second line of the sh block under "## Set up", without its
/// comment.
fn readme_test_command() -> String {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let setup = readme
        .split("\n## Set up")
        .nth(1)
        .expect("README has a \"## Set up\" section");
    let block = setup
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("the set-up section has an sh block");
    let line = block
        .lines()
        .nth(1)
        .expect("the set-up block has two commands");
    line.split('#').next().unwrap().trim().to_string()
}

/// Every `cargo test` the README and `docs/` name, except in a paragraph about "A plain
/// `cargo test`" (the test profile's own build, named as such): `(page, line, text)` of those
/// that do not run in the README's profile (`cargo test --release`).
fn cargo_tests_outside_the_readme_profile(page: &str, text: &str) -> Vec<(String, usize, String)> {
    let mut found = Vec::new();
    let mut plain_paragraph = false;
    for (number, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            plain_paragraph = false;
            continue;
        }
        if line.contains("A plain `cargo test`") {
            plain_paragraph = true;
        }
        let mut rest = line;
        while let Some(at) = rest.find("cargo test") {
            let after = &rest[at + "cargo test".len()..];
            if !plain_paragraph && !after.starts_with(" --release") {
                found.push((page.to_string(), number + 1, line.trim().to_string()));
            }
            rest = after;
        }
    }
    found
}

/// The README's test command is the one `.ci/run` runs, and every page that names the test
/// suite names it in the same profile, so that a reader runs what CI runs and reuses the first
/// set-up command's build.
#[test]
fn the_readme_test_command_is_the_one_ci_runs_everywhere() {
    let command = readme_test_command();
    assert_eq!(command, "cargo test --release", "the README's test command");
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert!(
        ci.lines().any(|line| line.trim() == command),
        ".ci/run does not run the README's test command `{command}` as a line of its own"
    );
    let mut found = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(root().join(&page)).unwrap();
        found.extend(cargo_tests_outside_the_readme_profile(&page, &text));
    }
    let found: Vec<String> = found
        .iter()
        .map(|(page, line, text)| format!("{page}:{line}: {text}"))
        .collect();
    assert!(
        found.is_empty(),
        "name the README's test command `{command}` (filters after it), not another profile:\n{}",
        found.join("\n")
    );
}

/// The check above finds a `cargo test` in another profile and lets a paragraph about the plain
/// one be.
#[test]
fn a_test_command_in_another_profile_is_found() {
    let text = "Run `cargo test --release`.\n\nOr `cargo test --lib x::`.\n\n\
                A plain `cargo test` works,\nas `cargo test --lib y::` does.\n\nThen `cargo test`.\n";
    let found = cargo_tests_outside_the_readme_profile("p.md", text);
    let lines: Vec<usize> = found.iter().map(|f| f.1).collect();
    assert_eq!(lines, vec![3, 8]);
}
