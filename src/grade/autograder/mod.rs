//! The Gradescope autograder package: a zip with `setup.sh`, `run_autograder`, the `rtoracle`
//! binary itself and the rubric, so a course grades on Gradescope's machines without any network
//! access beyond the distribution's archive (or PyPI where there is no apt).
//!
//! What it promises:
//! - `setup.sh` leaves a Python 3 that imports numpy and Pillow, which every real submission
//!   needs (the course's `RT_utility.py` imports both at module level): the distribution's
//!   `python3 python3-numpy python3-pil` where `apt-get` exists, `python3 -m pip install numpy
//!   pillow` otherwise, unless one already can. It checks the import and fails loudly when it
//!   does not work, so no student is ever graded 0 because the grader lacks a package. It
//!   records the interpreter, which `run_autograder` passes to `grade --python`. It installs the
//!   binary mode `0700` (only root, the grader, may run it: where Gradescope's container refuses
//!   namespaces, the sandbox cannot hide it from a submission that would use it as an oracle),
//!   and makes the unpacked package itself (`/autograder/source`: the binary again, and the
//!   rubric with the secret seed) readable by root only.
//! - A secret suite: [`secret_seed`] draws the seed from the OS (`/dev/urandom`, no dependency)
//!   when the rubric's seed is 0 (the public one) and no `--seed` is given; [`with_seed`] writes
//!   it into the packaged rubric, which `setup.sh` installs readable only by root (mode 600).
//!   Every seed draws the same families of cases, so fairness does not depend on it. The seed
//!   never leaves the grader ([`crate::secret`]): each `report.json` names it by its digest
//!   (`reproducibility.code_checker`), so a grade re-run with the rubric can be matched to it.
//!
//! Gradescope's images are Ubuntu on x86_64 with glibc, so the binary packed must be built for
//! `x86_64-unknown-linux-gnu` (or `-musl`) against a glibc no newer than the image's; the package
//! refuses any other kind of executable.

pub mod pack;

use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime, ZipWriter};

/// `setup.sh`: run once by Gradescope when it builds the autograder image.
pub const SETUP_SH: &str = r#"#!/usr/bin/env bash
# rtoracle autograder: installs the grader. Gradescope runs this once, as root, when it builds
# the image. The package already holds the rtoracle binary; students' code needs a Python 3 with
# numpy and Pillow (the course's RT_utility.py imports both), installed here from the
# distribution (python3 python3-numpy python3-pil) where apt-get exists, else with pip.
# PREFIX (default /usr/local) only exists so the package can be tried outside Gradescope.
set -euo pipefail
cd "$(dirname "$0")"
# The package as unpacked (the binary, the rubric with the secret seed) is for root alone: where
# the sandbox cannot hide the host's files, students' code runs as another uid and could read it.
chmod -R go-rwx .
prefix="${PREFIX:-/usr/local}"
mkdir -p "$prefix/bin" "$prefix/share"
# The grader runs as root; nobody else may run it (a submission that found it could use it as
# an oracle where the sandbox cannot hide it).
install -m 0700 rtoracle "$prefix/bin/rtoracle"
# The rubric holds the secret seed of the suite: readable by root (the grader) only.
install -m 0600 rubric.toml "$prefix/share/rtoracle-rubric.toml"
# The rubric's own scene files and their goldens (rubric.toml names them relative to itself).
if [ -d rtoracle-scenes ]; then
    mkdir -p "$prefix/share/rtoracle-scenes"
    install -m 0644 rtoracle-scenes/* "$prefix/share/rtoracle-scenes/"
fi
has_modules() { [ -n "$1" ] && [ -x "$1" ] && "$1" -I -c "import numpy, PIL" >/dev/null 2>&1; }
python=""
for p in /usr/bin/python3 /usr/local/bin/python3 "$(command -v python3 || true)"; do
    if has_modules "$p"; then python="$p"; break; fi
done
if [ -z "$python" ]; then
    if command -v apt-get >/dev/null 2>&1; then
        apt-get update
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
            python3 python3-numpy python3-pil
        python=/usr/bin/python3
    else
        python="$(command -v python3 || true)"
        if [ -z "$python" ]; then
            echo "setup.sh: no python3 and no apt-get to install it: the grader cannot run students' code" >&2
            exit 1
        fi
        "$python" -m pip install numpy pillow \
            || "$python" -m pip install --break-system-packages numpy pillow
    fi
fi
if ! "$python" -I -c "import numpy, PIL"; then
    echo "setup.sh: $python cannot import numpy and PIL, which students' code needs: the grader would score every submission 0" >&2
    exit 1
fi
printf '%s\n' "$python" > "$prefix/share/rtoracle-python"
echo "students' code will run with $python ($("$python" -I -c 'import numpy, PIL; print("numpy", numpy.__version__, "Pillow", PIL.__version__)'))"
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
# The interpreter setup.sh installed and checked (numpy and Pillow).
python="$(cat "$prefix/share/rtoracle-python" 2>/dev/null || echo /usr/bin/python3)"
# Students sometimes upload a folder: grade the one that holds RT_object.py.
if [ ! -e "$sub/RT_object.py" ]; then
    found=$(find "$sub" -maxdepth 3 -name RT_object.py -print -quit 2>/dev/null)
    if [ -n "$found" ]; then sub=$(dirname "$found"); fi
fi
mkdir -p "$root/results"
"$prefix/bin/rtoracle" grade "$sub" --rubric "$prefix/share/rtoracle-rubric.toml" \
    --python "$python" --format gradescope --out "$root/results"
status=$?
if [ "$status" -ne 0 ] || [ ! -s "$root/results/results.json" ]; then
    printf '{"score": 0, "execution_time": 0, "output": "The autograder could not grade this submission (rtoracle exit %s). Please tell your instructor.", "tests": []}\n' "$status" \
        > "$root/results/results.json"
fi
exit 0
"#;

/// A seed for a secret suite: 8 bytes from the OS (`/dev/urandom`), non-zero, at most
/// `i64::MAX` (TOML integers are signed 64-bit).
pub fn secret_seed() -> std::io::Result<u64> {
    use std::io::Read;
    let mut file = std::fs::File::open("/dev/urandom")?;
    loop {
        let mut bytes = [0u8; 8];
        file.read_exact(&mut bytes)?;
        let seed = u64::from_le_bytes(bytes) & (i64::MAX as u64);
        if seed != 0 {
            return Ok(seed);
        }
    }
}

/// `rubric_toml` with its top-level `seed` set to `seed`: the `seed = ...` line before the first
/// table is replaced, or one is added at the top when there is none. Comments and everything
/// else are kept.
pub fn with_seed(rubric_toml: &str, seed: u64) -> String {
    let line = format!("seed = {seed}  # the suite's seed, written by `rtoracle autograder`");
    let mut out = Vec::new();
    let mut replaced = false;
    let mut in_table = false;
    for l in rubric_toml.lines() {
        let t = l.trim_start();
        if t.starts_with('[') {
            in_table = true;
        }
        let key = t.split('=').next().unwrap_or("").trim();
        if !in_table && !replaced && key == "seed" && t.contains('=') {
            out.push(line.clone());
            replaced = true;
        } else {
            out.push(l.to_string());
        }
    }
    if !replaced {
        out.insert(0, line);
    }
    let mut text = out.join("\n");
    text.push('\n');
    text
}

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
/// rubric's scene files and goldens ([`super::autograder::pack::pack_rubric`]).
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
        ("rubric.toml", rubric_toml.as_bytes(), 0o600),
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
    crate::output::write_file(out_zip, "", &cursor.into_inner()).map_err(|e| write_err(&e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grade::rubric::Rubric;
    use crate::grade::rubric::WEEK04_RUBRIC;
    use std::collections::BTreeMap;

    #[test]
    fn the_seed_is_written_into_the_rubric_and_a_secret_one_is_non_zero_and_fresh() {
        let parse = |t: &str| Rubric::from_toml(t, "test").unwrap();
        assert_eq!(parse(WEEK04_RUBRIC).seed, 0);
        let text = with_seed(WEEK04_RUBRIC, 12345);
        let r = parse(&text);
        assert_eq!(r.seed, 12345);
        // Nothing but the seed changed: same groups, and one seed line.
        assert_eq!(r.groups, parse(WEEK04_RUBRIC).groups);
        assert_eq!(text.lines().filter(|l| l.starts_with("seed")).count(), 1);
        // A rubric without a seed line gets one at the top; a group's own keys are untouched.
        let bare: String = WEEK04_RUBRIC
            .lines()
            .filter(|l| !l.starts_with("seed"))
            .map(|l| format!("{l}\n"))
            .collect();
        assert_eq!(
            parse(&with_seed(&bare, i64::MAX as u64)).seed,
            i64::MAX as u64
        );
        let (a, b) = (secret_seed().unwrap(), secret_seed().unwrap());
        assert!(a != 0 && b != 0 && a != b, "{a} {b}");
        assert!(a <= i64::MAX as u64 && b <= i64::MAX as u64);
        assert!(SETUP_SH.contains("install -m 0600 rubric.toml"));
        // The binary runs as root only: where the sandbox falls back to a uid without a mount
        // namespace (Gradescope's containers may refuse one), a submission that finds it must
        // not be able to run it as an oracle.
        assert!(SETUP_SH.contains("install -m 0700 rtoracle \"$prefix/bin/rtoracle\""));
    }

    /// The family of a case: its id without the trailing number (`sphere-basic-0003` ->
    /// `sphere-basic`). A watertight group counts once, whatever its members
    /// (`watertight-quads-0003-a`, `-b`, and `-c` where a third shape contains the point).
    fn families(seed: u64) -> BTreeMap<String, usize> {
        let mut by = BTreeMap::new();
        let mut groups = std::collections::BTreeSet::new();
        for c in crate::oracle::suite::default_suite(seed) {
            let id = match &c.expect.watertight {
                Some(w) if !groups.insert(w.group.clone()) => continue,
                Some(w) => w.group.clone(),
                None => c.id.clone(),
            };
            let family = id.trim_end_matches(|ch: char| ch.is_ascii_digit());
            *by.entry(family.trim_end_matches('-').to_string())
                .or_default() += 1;
        }
        by
    }

    #[test]
    fn every_seed_draws_the_same_families_of_cases() {
        let public = families(0);
        assert!(public.len() > 5, "{public:?}");
        for seed in [1, 2, 99, 1 << 40, i64::MAX as u64, secret_seed().unwrap()] {
            assert_eq!(families(seed), public, "seed {seed}");
        }
        // And the seed matters: another seed gives other vectors.
        let (a, b) = (
            crate::oracle::suite::default_suite(0),
            crate::oracle::suite::default_suite(1),
        );
        assert_ne!(a[0].ray, b[0].ray);
    }

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
