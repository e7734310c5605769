//! The Gradescope autograder package: a zip with `setup.sh`, `run_autograder`, the `rtoracle`
//! binary itself and the rubric, so a course grades on Gradescope's machines without any network
//! access beyond Debian's archive (for `python3`, when the base image lacks it).
//!
//! Gradescope's images are Ubuntu on x86_64 with glibc, so the binary packed must be built for
//! `x86_64-unknown-linux-gnu` (or `-musl`) against a glibc no newer than the image's; the package
//! refuses any other kind of executable.

use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

/// `setup.sh`: run once by Gradescope when it builds the autograder image.
pub const SETUP_SH: &str = r#"#!/usr/bin/env bash
# rtoracle autograder: installs the grader. Gradescope runs this once, as root, when it builds
# the image; the package already holds the rtoracle binary, so the only download is python3
# from the distribution's archive when the image lacks it.
# PREFIX (default /usr/local) only exists so the package can be tried outside Gradescope.
set -euo pipefail
cd "$(dirname "$0")"
prefix="${PREFIX:-/usr/local}"
mkdir -p "$prefix/bin" "$prefix/share"
install -m 0755 rtoracle "$prefix/bin/rtoracle"
install -m 0644 rubric.toml "$prefix/share/rtoracle-rubric.toml"
# The rubric's own scene files and their goldens (rubric.toml names them relative to itself).
if [ -d rtoracle-scenes ]; then
    mkdir -p "$prefix/share/rtoracle-scenes"
    install -m 0644 rtoracle-scenes/* "$prefix/share/rtoracle-scenes/"
fi
if ! command -v python3 >/dev/null 2>&1; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3
fi
"$prefix/bin/rtoracle" --version
"#;

/// `run_autograder`: run by Gradescope for every submission.
pub const RUN_AUTOGRADER: &str = r#"#!/usr/bin/env bash
# rtoracle autograder: grades /autograder/submission into /autograder/results/results.json.
# PREFIX and AUTOGRADER (defaults /usr/local, /autograder) only exist so the package can be
# tried outside Gradescope.
set -uo pipefail
prefix="${PREFIX:-/usr/local}"
root="${AUTOGRADER:-/autograder}"
sub="$root/submission"
# Students sometimes upload a folder: grade the one that holds RT_object.py.
if [ ! -e "$sub/RT_object.py" ]; then
    found=$(find "$sub" -maxdepth 3 -name RT_object.py -print -quit 2>/dev/null)
    if [ -n "$found" ]; then sub=$(dirname "$found"); fi
fi
mkdir -p "$root/results"
"$prefix/bin/rtoracle" grade "$sub" --rubric "$prefix/share/rtoracle-rubric.toml" \
    --format gradescope --out "$root/results"
status=$?
if [ "$status" -ne 0 ] || [ ! -s "$root/results/results.json" ]; then
    printf '{"score": 0, "execution_time": 0, "output": "The autograder could not grade this submission (rtoracle exit %s). Please tell your instructor.", "tests": []}\n' "$status" \
        > "$root/results/results.json"
fi
exit 0
"#;

/// What stops the package from being built.
#[derive(Debug, thiserror::Error)]
pub enum AutograderError {
    /// The binary to pack cannot be read.
    #[error("{path}: cannot read the binary to pack: {message}")]
    Binary {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// The binary is not an x86_64 Linux executable.
    #[error(
        "{path}: not an x86_64 Linux (ELF) executable, which Gradescope needs; build with --target x86_64-unknown-linux-gnu and pass it with --binary"
    )]
    NotLinuxX86_64 {
        /// The file.
        path: String,
    },
    /// The zip cannot be written.
    #[error("{path}: cannot write the package: {message}")]
    Write {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

/// Whether `bytes` start like a 64-bit little-endian ELF file for x86_64.
pub fn is_linux_x86_64_elf(bytes: &[u8]) -> bool {
    bytes.len() >= 20
        && bytes[..4] == *b"\x7fELF"
        && bytes[4] == 2 // 64-bit
        && bytes[5] == 1 // little-endian
        && u16::from_le_bytes([bytes[18], bytes[19]]) == 0x3e // EM_X86_64
}

/// Checks that `binary` can be read and is an x86_64 Linux executable, as the package needs.
pub fn check_binary(binary: &Path) -> Result<(), AutograderError> {
    let bin = std::fs::read(binary).map_err(|e| AutograderError::Binary {
        path: binary.display().to_string(),
        message: e.to_string(),
    })?;
    if is_linux_x86_64_elf(&bin) {
        Ok(())
    } else {
        Err(AutograderError::NotLinuxX86_64 {
            path: binary.display().to_string(),
        })
    }
}

/// Writes the package to `out_zip` (atomically): `setup.sh`, `run_autograder`, `rtoracle` (the
/// file `binary`) and `rubric.toml` (`rubric_toml`). Entries have fixed times, so the same inputs
/// give the same bytes.
pub fn build_package(
    binary: &Path,
    rubric_toml: &str,
    out_zip: &Path,
) -> Result<(), AutograderError> {
    build_package_with(binary, rubric_toml, &[], out_zip)
}

/// [`build_package`] with `extra` files (path in the package, bytes) after the others: the
/// rubric's scene files and goldens ([`super::pack::pack_rubric`]).
pub fn build_package_with(
    binary: &Path,
    rubric_toml: &str,
    extra: &[(String, Vec<u8>)],
    out_zip: &Path,
) -> Result<(), AutograderError> {
    let bin = std::fs::read(binary).map_err(|e| AutograderError::Binary {
        path: binary.display().to_string(),
        message: e.to_string(),
    })?;
    if !is_linux_x86_64_elf(&bin) {
        return Err(AutograderError::NotLinuxX86_64 {
            path: binary.display().to_string(),
        });
    }
    let write_err = |e: &dyn std::fmt::Display| AutograderError::Write {
        path: out_zip.display().to_string(),
        message: e.to_string(),
    };
    let mut zip = ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = |mode: u32| {
        SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .compression_level(Some(1))
            .last_modified_time(DateTime::default())
            .unix_permissions(mode)
    };
    let files: [(&str, &[u8], u32); 4] = [
        ("setup.sh", SETUP_SH.as_bytes(), 0o755),
        ("run_autograder", RUN_AUTOGRADER.as_bytes(), 0o755),
        ("rubric.toml", rubric_toml.as_bytes(), 0o644),
        ("rtoracle", &bin, 0o755),
    ];
    for (name, bytes, mode) in files {
        zip.start_file(name, options(mode))
            .map_err(|e| write_err(&e))?;
        zip.write_all(bytes).map_err(|e| write_err(&e))?;
    }
    for (name, bytes) in extra {
        zip.start_file(name.as_str(), options(0o644))
            .map_err(|e| write_err(&e))?;
        zip.write_all(bytes).map_err(|e| write_err(&e))?;
    }
    let cursor = zip.finish().map_err(|e| write_err(&e))?;
    super::run::write_public(out_zip, &cursor.into_inner()).map_err(|e| write_err(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_package_holds_the_scripts_the_binary_and_the_rubric() {
        let dir = tempfile::tempdir().unwrap();
        let mut fake = vec![0u8; 64];
        fake[..4].copy_from_slice(b"\x7fELF");
        fake[4] = 2;
        fake[5] = 1;
        fake[18] = 0x3e;
        let bin = dir.path().join("bin");
        std::fs::write(&bin, &fake).unwrap();
        let out = dir.path().join("autograder.zip");
        build_package(&bin, "name = \"x\"\n", &out).unwrap();
        let first = std::fs::read(&out).unwrap();
        let mut archive = zip::ZipArchive::new(std::io::Cursor::new(first.clone())).unwrap();
        let mut names: Vec<String> = archive.file_names().map(String::from).collect();
        names.sort();
        assert_eq!(
            names,
            ["rtoracle", "rubric.toml", "run_autograder", "setup.sh"]
        );
        let mut f = archive.by_name("rtoracle").unwrap();
        assert_eq!(f.unix_mode().map(|m| m & 0o777), Some(0o755));
        let mut back = Vec::new();
        std::io::Read::read_to_end(&mut f, &mut back).unwrap();
        assert_eq!(back, fake);
        drop(f);
        // Deterministic bytes.
        build_package(&bin, "name = \"x\"\n", &out).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), first);
        // Something that is not an x86_64 ELF is refused.
        fake[18] = 0xb7; // aarch64
        std::fs::write(&bin, &fake).unwrap();
        let e = build_package(&bin, "", &out).unwrap_err().to_string();
        assert!(e.contains("not an x86_64 Linux"), "{e}");
        assert!(
            RUN_AUTOGRADER.contains("rtoracle\" grade \"$sub\"")
                && RUN_AUTOGRADER.contains("/autograder}")
        );
    }
}
