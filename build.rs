//! Build script: one cfg, so that the tests needing the course's published images show as
//! ignored, with the reason, in `cargo test`'s own output when `RTORACLE_COURSE_FIXTURES` is not
//! set (a test that returns early would show as passed, its "skipped" line swallowed by libtest).

fn main() {
    println!("cargo::rerun-if-env-changed=RTORACLE_COURSE_FIXTURES");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(rtoracle_course_fixtures)");
    if std::env::var_os("RTORACLE_COURSE_FIXTURES").is_some_and(|v| !v.is_empty()) {
        println!("cargo::rustc-cfg=rtoracle_course_fixtures");
    }
}
