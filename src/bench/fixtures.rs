//! The crate's fixture files, embedded at build time (`FIXTURE_FILES`, written by `build.rs`):
//! the fixture submissions, the course modules and the `check` fixtures' variants, so that
//! `rtoracle bench candidate` and `rtoracle bench grade` run from an installed binary, with no
//! checkout and no path of the build machine.

include!(concat!(env!("OUT_DIR"), "/fixtures.rs"));

/// The `.py` files directly in the embedded folder `folder` (a path under `tests/fixtures/`,
/// such as `python/common`), by file name, sorted.
pub(crate) fn python_files_in(folder: &str) -> Vec<(&'static str, &'static [u8])> {
    let mut files: Vec<(&str, &[u8])> = FIXTURE_FILES
        .iter()
        .filter_map(|(path, bytes)| {
            let name = path.strip_prefix(folder)?.strip_prefix('/')?;
            (name.ends_with(".py") && !name.contains('/')).then_some((name, *bytes))
        })
        .collect();
    files.sort();
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The generated list names no folder of the machine that built it: every file is
    /// included relative to the crate being compiled (a clone sharing the target folder of
    /// another one read the other's files, or failed when it had moved).
    #[test]
    fn the_embedded_list_holds_no_absolute_path() {
        let code = include_str!(concat!(env!("OUT_DIR"), "/fixtures.rs"));
        let here = env!("CARGO_MANIFEST_DIR");
        assert!(!code.contains(here), "{code}");
        let includes = code.matches("include_bytes!(").count();
        assert_eq!(includes, FIXTURE_FILES.len());
        assert_eq!(
            code.matches("include_bytes!(concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/tests/fixtures/")
                .count(),
            includes
        );
        // The variants the candidate benchmark needs are there.
        for variant in ["honest_reference", "hostile_hang_on_miss"] {
            let files = python_files_in(&format!("python/variants/{variant}"));
            assert!(files.iter().any(|(n, _)| *n == "RT_object.py"), "{variant}");
        }
        assert!(python_files_in("python/common").len() >= 3);
    }
}
