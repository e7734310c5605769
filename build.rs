//! Build script.
//!
//! - The fixtures (`tests/fixtures/submissions/*/`, the course modules of
//!   `tests/fixtures/python/common`, the triangle assignment's and the `check` fixtures'
//!   variants of `tests/fixtures/python/variants`, the week-8 solution of
//!   `tests/fixtures/python/weeks/week08/solution`) are embedded in the library for
//!   `rtoracle bench grade` and `rtoracle bench candidate`, so an installed binary runs them
//!   without a checkout: `$OUT_DIR/fixtures.rs` lists them as `include_bytes!` of paths relative
//!   to the crate's own folder (`concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/...")`),
//!   resolved when the crate compiles. No absolute path is written: two clones sharing one
//!   `CARGO_TARGET_DIR` share this script's output (its `OUT_DIR`), and each must read its own
//!   files.
//! - Two cfgs, so that the tests needing the course's published images
//!   (`RTORACLE_COURSE_FIXTURES`, cfg `rtoracle_course_fixtures`) or the course's real code of
//!   weeks 4 to 10 (`RTORACLE_COURSE_CODE`, cfg `rtoracle_course_code`) show as ignored, with
//!   the reason, in `cargo test`'s own output when the variable is not set (a test that returns
//!   early would show as passed, its "skipped" line swallowed by libtest).

/// The folders under `tests/fixtures/` whose `.py` and `.toml` files are embedded.
const EMBEDDED: [&str; 5] = [
    "submissions",
    "python/common",
    "python/triangle_assignment",
    "python/variants",
    // The week-8 solution, which `rtoracle bench grade` grades with the week08 rubric.
    "python/weeks/week08/solution",
];

fn main() {
    embed_fixtures();
    println!("cargo::rerun-if-changed=build.rs");
    for (variable, cfg) in [
        ("RTORACLE_COURSE_FIXTURES", "rtoracle_course_fixtures"),
        ("RTORACLE_COURSE_CODE", "rtoracle_course_code"),
    ] {
        println!("cargo::rerun-if-env-changed={variable}");
        println!("cargo::rustc-check-cfg=cfg({cfg})");
        if std::env::var_os(variable).is_some_and(|v| !v.is_empty()) {
            println!("cargo::rustc-cfg={cfg}");
        }
    }
}

fn embed_fixtures() {
    use std::fmt::Write;
    let root = std::path::PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let base = root.join("tests/fixtures");
    let mut files = Vec::new();
    for top in EMBEDDED {
        println!("cargo::rerun-if-changed=tests/fixtures/{top}");
        collect(&base.join(top), &mut files);
    }
    files.sort();
    let mut code = String::from(
        "/// The fixture files, by path under `tests/fixtures/`.\n\
         pub(crate) static FIXTURE_FILES: &[(&str, &[u8])] = &[\n",
    );
    for path in &files {
        let rel = path
            .strip_prefix(&base)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        // Resolved against the crate being compiled, not the folder this script ran in.
        let include = format!("/tests/fixtures/{rel}");
        writeln!(
            code,
            "    ({rel:?}, include_bytes!(concat!(env!(\"CARGO_MANIFEST_DIR\"), {include:?}))),"
        )
        .unwrap();
    }
    code.push_str("];\n");
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").unwrap()).join("fixtures.rs");
    std::fs::write(out, code).unwrap();
}

fn collect(dir: &std::path::Path, files: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let path = e.path();
        if path.is_dir() {
            collect(&path, files);
        } else if path.extension().is_some_and(|x| x == "py" || x == "toml") {
            files.push(path);
        }
    }
}
