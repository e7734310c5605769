//! Build script.
//!
//! - The fixture submissions (`tests/fixtures/submissions/*/`, with the shared course modules of
//!   `tests/fixtures/python/common`) are embedded in the library for `rtoracle bench grade`, so an
//!   installed binary runs it without a checkout: `$OUT_DIR/fixtures.rs` lists them as
//!   `include_bytes!`.
//! - One cfg, so that the tests needing the course's published images show as ignored, with the
//!   reason, in `cargo test`'s own output when `RTORACLE_COURSE_FIXTURES` is not set (a test that
//!   returns early would show as passed, its "skipped" line swallowed by libtest).

fn main() {
    embed_fixtures();
    println!("cargo::rerun-if-env-changed=RTORACLE_COURSE_FIXTURES");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(rtoracle_course_fixtures)");
    if std::env::var_os("RTORACLE_COURSE_FIXTURES").is_some_and(|v| !v.is_empty()) {
        println!("cargo::rustc-cfg=rtoracle_course_fixtures");
    }
}

fn embed_fixtures() {
    use std::fmt::Write;
    let root = std::path::PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let base = root.join("tests/fixtures");
    let mut files = Vec::new();
    for top in ["submissions", "python/common", "python/triangle_assignment"] {
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
        writeln!(
            code,
            "    ({rel:?}, include_bytes!({:?})),",
            path.display().to_string()
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
