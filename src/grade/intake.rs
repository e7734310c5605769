//! Reading what a submission holds, with care: only regular files inside the submission folder
//! are read, size caps are checked before anything is read or hashed, and a PNG's header is
//! checked (size, colour type, bit depth) before it is decoded.
//!
//! Promises:
//! - a FIFO, a socket, a device, a folder or a symbolic link (even to a regular file) where a
//!   file is expected is reported by name and never opened, so it cannot block or redirect the
//!   grader. The check is made with `symlink_metadata`, the file is opened with
//!   `O_NOFOLLOW | O_NONBLOCK` and checked again with `fstat` (same device and inode, still a
//!   regular file), so swapping it between the check and the open does not help;
//! - no file is read past its cap ([`MAX_IMAGE_BYTES`] for an image; [`HASH_FILE_CAP`] per file
//!   and [`HASH_TOTAL_CAP`] in all for the hashes of `report.json`), whatever its size claims,
//!   and at most [`HASH_MAX_FILES`] files are listed there, so a submission of many files cannot
//!   make a report of many megabytes;
//! - a PNG whose header says it is not the expected size, has more than [`MAX_IMAGE_PIXELS`]
//!   pixels, is grey or has 16-bit channels is reported in plain words, naming
//!   the file as the student knows it (relative to the submission), without being decoded;
//! - so is an OpenEXR file (which the comparison also reads, whatever the file's name says)
//!   whose header describes a part of another size or of more than [`MAX_IMAGE_PIXELS`], or
//!   parts that would decode to more than [`MAX_EXR_DECODED_BYTES`]: only its header is read, so
//!   a decompression bomb (a few MB of deflated zeros claiming 16000 x 16000 pixels) costs
//!   nothing.

use std::collections::BTreeMap;
use std::fs::{File, FileType, Metadata};
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt};
use std::path::{Component, Path, PathBuf};

use super::rubric::sha256_hex;

/// The largest image file read (64 MiB).
pub const MAX_IMAGE_BYTES: u64 = 64 << 20;
/// The most pixels an image may have (about 8192 x 8192).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;
/// The most bytes of samples an OpenEXR image of a submission may decode to (256 MiB; a
/// 400 x 225 image of four 32-bit channels holds 1.4 MB).
pub const MAX_EXR_DECODED_BYTES: u64 = 256 << 20;
/// The largest file hashed for `report.json` (16 MiB); larger ones are listed as not hashed.
pub const HASH_FILE_CAP: u64 = 16 << 20;
/// The most bytes hashed for `report.json` over the whole submission (64 MiB).
pub const HASH_TOTAL_CAP: u64 = 64 << 20;
/// The most files listed in `report.json`'s hashes (the first by name); the rest are counted
/// under [`MORE_FILES_KEY`].
pub const HASH_MAX_FILES: usize = 1000;
/// The key that counts the files past [`HASH_MAX_FILES`] (no file's name holds a `/`).
pub const MORE_FILES_KEY: &str = "/more";

/// What a file that is not a regular file is, in words.
fn kind_of(t: &FileType) -> &'static str {
    if t.is_symlink() {
        "a symbolic link"
    } else if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else {
        "not a regular file"
    }
}

/// What went wrong reading a file of a submission: each says which file (as the submission
/// names it) and what is wrong with it, in a sentence the student reads.
#[derive(Debug, thiserror::Error)]
pub enum IntakeError {
    /// The path leaves the submission (absolute, or through `..`).
    #[error("{shown} is outside the submission")]
    Outside {
        /// The file, as the rubric names it.
        shown: String,
    },
    /// A folder on the way is something else (a file, a symbolic link, ...).
    #[error("{shown} is {kind}, not a folder")]
    NotAFolder {
        /// The folder, relative to the submission.
        shown: String,
        /// What it is instead ("a symbolic link", "a regular file", ...).
        kind: &'static str,
    },
    /// There is no such file.
    #[error("{shown} is missing from the submission")]
    Missing {
        /// The file.
        shown: String,
    },
    /// It is not a regular file (a FIFO, a socket, a device, a folder or a symbolic link).
    #[error("{shown} is {kind}, not a regular file")]
    NotRegular {
        /// The file.
        shown: String,
        /// What it is instead.
        kind: &'static str,
    },
    /// It is larger than the cap (known before reading, or found while reading).
    #[error("{shown} is {}, over the limit of {cap} bytes", size_words(*.len, *.cap))]
    TooLarge {
        /// The file.
        shown: String,
        /// Its size in bytes; `None` when it grew past the cap while being read.
        len: Option<u64>,
        /// The cap, in bytes.
        cap: u64,
    },
    /// It was replaced between the look and the open.
    #[error("{shown} changed while it was being read")]
    Changed {
        /// The file.
        shown: String,
    },
    /// The system refused to read it.
    #[error("{shown} cannot be read ({kind})")]
    Unreadable {
        /// The file.
        shown: String,
        /// Why, as the system says.
        kind: std::io::ErrorKind,
    },
}

/// "N bytes", or "more than CAP bytes" for a file that grew past the cap while being read.
fn size_words(len: Option<u64>, cap: u64) -> String {
    match len {
        Some(len) => format!("{len} bytes"),
        None => format!("more than {cap} bytes"),
    }
}

/// `rel` under `root`, refusing absolute paths, `..`, and folders on the way that are symbolic
/// links or not folders. `rel` names the file in messages.
fn inside(root: &Path, rel: &str) -> Result<PathBuf, IntakeError> {
    let rel_path = Path::new(rel);
    let mut path = root.to_path_buf();
    let parts: Vec<Component> = rel_path.components().collect();
    for (i, part) in parts.iter().enumerate() {
        match part {
            Component::Normal(name) => path.push(name),
            Component::CurDir => continue,
            _ => return Err(IntakeError::Outside { shown: rel.into() }),
        }
        if i + 1 < parts.len() {
            match std::fs::symlink_metadata(&path) {
                Ok(m) if m.is_dir() => {}
                Ok(m) => {
                    let shown = path.strip_prefix(root).unwrap_or(&path).display();
                    return Err(IntakeError::NotAFolder {
                        shown: shown.to_string(),
                        kind: kind_of(&m.file_type()),
                    });
                }
                Err(_) => return Err(IntakeError::Missing { shown: rel.into() }),
            }
        }
    }
    Ok(path)
}

/// Opens `path` only if it is a regular file of at most `cap` bytes (see the module's
/// promises); `shown` names it in the error.
pub fn open_regular(path: &Path, shown: &str, cap: u64) -> Result<(File, Metadata), IntakeError> {
    let unreadable = |e: std::io::Error| IntakeError::Unreadable {
        shown: shown.into(),
        kind: e.kind(),
    };
    let before = std::fs::symlink_metadata(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            IntakeError::Missing {
                shown: shown.into(),
            }
        } else {
            unreadable(e)
        }
    })?;
    if !before.file_type().is_file() {
        return Err(IntakeError::NotRegular {
            shown: shown.into(),
            kind: kind_of(&before.file_type()),
        });
    }
    let over = |len: u64| IntakeError::TooLarge {
        shown: shown.into(),
        len: Some(len),
        cap,
    };
    if before.len() > cap {
        return Err(over(before.len()));
    }
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| {
            if e.raw_os_error() == Some(libc::ELOOP) {
                IntakeError::NotRegular {
                    shown: shown.into(),
                    kind: "a symbolic link",
                }
            } else {
                unreadable(e)
            }
        })?;
    let after = file.metadata().map_err(unreadable)?;
    if !after.file_type().is_file() || (after.dev(), after.ino()) != (before.dev(), before.ino()) {
        return Err(IntakeError::Changed {
            shown: shown.into(),
        });
    }
    if after.len() > cap {
        return Err(over(after.len()));
    }
    Ok((file, after))
}

/// The bytes of the regular file `path`, at most `cap` of them (an error past it).
pub fn read_regular(path: &Path, shown: &str, cap: u64) -> Result<Vec<u8>, IntakeError> {
    let (file, meta) = open_regular(path, shown, cap)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| IntakeError::Unreadable {
            shown: shown.into(),
            kind: e.kind(),
        })?;
    if bytes.len() as u64 > cap {
        return Err(IntakeError::TooLarge {
            shown: shown.into(),
            len: None,
            cap,
        });
    }
    Ok(bytes)
}

/// What a PNG's IHDR chunk says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PngHeader {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bits per channel.
    pub bit_depth: u8,
    /// 0 grey, 2 RGB, 3 palette, 4 grey and alpha, 6 RGBA.
    pub colour_type: u8,
}

/// The header of a PNG: `None` when `bytes` is not a PNG at all, an error when its header is
/// cut short or is not an IHDR chunk.
pub fn png_header(bytes: &[u8]) -> Option<Result<PngHeader, &'static str>> {
    if !bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        return None;
    }
    if bytes.len() < 29 || &bytes[12..16] != b"IHDR" {
        return Some(Err("is not a readable PNG (its header is cut short)"));
    }
    let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    Some(Ok(PngHeader {
        width: be(16),
        height: be(20),
        bit_depth: bytes[24],
        colour_type: bytes[25],
    }))
}

/// Checks a PNG's header against what grading needs, in plain words naming `shown`.
pub fn check_png(
    shown: &str,
    bytes: &[u8],
    expected: Option<(usize, usize)>,
) -> Result<(), String> {
    let header = match png_header(bytes) {
        None => return Ok(()),
        Some(Err(why)) => return Err(format!("{shown} {why}")),
        Some(Ok(h)) => h,
    };
    let (w, h) = (header.width as u64, header.height as u64);
    if w * h > MAX_IMAGE_PIXELS {
        return Err(format!(
            "{shown} is {w}x{h} pixels, more than the {MAX_IMAGE_PIXELS} allowed"
        ));
    }
    if let Some((ew, eh)) = expected {
        if (w, h) != (ew as u64, eh as u64) {
            return Err(format!("{shown} is {w}x{h} pixels; expected {ew}x{eh}"));
        }
    }
    match header.colour_type {
        0 | 4 => Err(format!("{shown} is greyscale; expected an RGB PNG")),
        // A palette image decodes to the RGB it stands for, losslessly (as `compare` reads it).
        3 => Ok(()),
        2 | 6 if header.bit_depth != 8 => Err(format!(
            "{shown} has {} bits per channel; expected 8",
            header.bit_depth
        )),
        2 | 6 => Ok(()),
        _ => Err(format!(
            "{shown} is not a readable PNG (unknown colour type)"
        )),
    }
}

/// Checks an OpenEXR file's header against what grading needs (see the module's promises),
/// reading nothing past it; `Ok` for bytes that are not an OpenEXR file.
pub fn check_exr(
    shown: &str,
    bytes: &[u8],
    expected: Option<(usize, usize)>,
) -> Result<(), String> {
    if !bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return Ok(());
    }
    let parts = crate::image_io::exr_part_sizes(bytes).map_err(|_| {
        format!("{shown} is not a readable OpenEXR file (its header is cut short or damaged)")
    })?;
    let mut decoded = 0u64;
    for (w, h, bytes_per_pixel) in parts {
        let (w, h) = (w as u64, h as u64);
        if w.saturating_mul(h) > MAX_IMAGE_PIXELS {
            return Err(format!(
                "{shown} is {w}x{h} pixels, more than the {MAX_IMAGE_PIXELS} allowed"
            ));
        }
        if let Some((ew, eh)) = expected
            && (w, h) != (ew as u64, eh as u64)
        {
            return Err(format!("{shown} is {w}x{h} pixels; expected {ew}x{eh}"));
        }
        decoded = decoded.saturating_add((w * h).saturating_mul(bytes_per_pixel as u64));
    }
    if decoded > MAX_EXR_DECODED_BYTES {
        return Err(format!(
            "{shown} would decode to {decoded} bytes of samples, more than the \
             {MAX_EXR_DECODED_BYTES} allowed"
        ));
    }
    Ok(())
}

/// Checks the header of an image grading will decode, a PNG ([`check_png`]) or an OpenEXR file
/// ([`check_exr`]), before anything is decoded.
pub fn check_image_header(
    shown: &str,
    bytes: &[u8],
    expected: Option<(usize, usize)>,
) -> Result<(), String> {
    check_png(shown, bytes, expected)?;
    check_exr(shown, bytes, expected)
}

/// Reads the image `rel` of `submission` with care, checks its header, and writes its bytes to
/// `stage_dir` under its own file name (the path returned), so whatever reads it next reads a
/// copy the grader owns. The error is a sentence naming `rel`.
pub fn stage_image(
    submission: &Path,
    rel: &str,
    expected: Option<(usize, usize)>,
    stage_dir: &Path,
) -> Result<PathBuf, String> {
    let path = inside(submission, rel).map_err(|e| e.to_string())?;
    let bytes = read_regular(&path, rel, MAX_IMAGE_BYTES).map_err(|e| e.to_string())?;
    check_image_header(rel, &bytes, expected)?;
    let name = path.file_name().unwrap_or_else(|| "image".as_ref());
    let staged = stage_dir.join(name);
    std::fs::write(&staged, &bytes)
        .map_err(|e| format!("{rel} could not be staged for comparison ({})", e.kind()))?;
    Ok(staged)
}

/// SHA-256 of each regular file at the top of `dir`, by name: only regular files (never through a
/// symbolic link), each up to [`HASH_FILE_CAP`] and [`HASH_TOTAL_CAP`] in all (in name order); a
/// file past a cap or unreadable gets a note instead of a hash. At most [`HASH_MAX_FILES`] files
/// are listed; [`MORE_FILES_KEY`] counts the others.
pub fn submission_hashes(dir: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return out;
    };
    let mut files: Vec<(String, PathBuf)> = entries
        .flatten()
        .filter(|e| e.file_type().map(|t| t.is_file()).unwrap_or(false))
        .map(|e| (e.file_name().to_string_lossy().to_string(), e.path()))
        .collect();
    files.sort();
    if files.len() > HASH_MAX_FILES {
        out.insert(
            MORE_FILES_KEY.to_string(),
            format!(
                "{} more files, not listed (at most {HASH_MAX_FILES} are)",
                files.len() - HASH_MAX_FILES
            ),
        );
        files.truncate(HASH_MAX_FILES);
    }
    let mut total = 0u64;
    for (name, path) in files {
        let cap = HASH_FILE_CAP.min(HASH_TOTAL_CAP - total);
        let value = match read_regular(&path, &name, cap) {
            Ok(bytes) => {
                total += bytes.len() as u64;
                sha256_hex(&bytes)
            }
            Err(IntakeError::TooLarge { len, .. }) => format!(
                "not hashed: {}, over the cap ({HASH_FILE_CAP} per file, {HASH_TOTAL_CAP} in all)",
                size_words(len, cap)
            ),
            Err(why) => format!("not hashed: {why}"),
        };
        out.insert(name, value);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn png(width: u32, height: u32, bit_depth: u8, colour_type: u8) -> Vec<u8> {
        let mut b = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
        b.extend(width.to_be_bytes());
        b.extend(height.to_be_bytes());
        b.extend([bit_depth, colour_type, 0, 0, 0, 0, 0, 0, 0]);
        b
    }

    #[test]
    fn special_files_are_named_and_never_opened() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let fifo = std::ffi::CString::new(d.join("week04_sphere.png").to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path that lives across the call.
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o644) }, 0);
        std::fs::write(d.join("real.png"), b"x").unwrap();
        std::os::unix::fs::symlink(d.join("real.png"), d.join("link.png")).unwrap();
        let _sock = std::os::unix::net::UnixListener::bind(d.join("sock.png")).unwrap();
        std::fs::create_dir(d.join("dir.png")).unwrap();
        let start = Instant::now();
        let err = |name: &str| {
            read_regular(&d.join(name), name, 100)
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            err("week04_sphere.png"),
            "week04_sphere.png is a FIFO, not a regular file"
        );
        assert_eq!(
            err("link.png"),
            "link.png is a symbolic link, not a regular file"
        );
        assert_eq!(err("sock.png"), "sock.png is a socket, not a regular file");
        assert_eq!(err("dir.png"), "dir.png is a folder, not a regular file");
        assert_eq!(err("none.png"), "none.png is missing from the submission");
        // A device, where root can make one (a copy of /dev/null's numbers).
        let dev = std::ffi::CString::new(d.join("dev.png").to_str().unwrap()).unwrap();
        // SAFETY: a NUL-terminated path that lives across the call.
        if unsafe { libc::mknod(dev.as_ptr(), libc::S_IFCHR | 0o644, libc::makedev(1, 3)) } == 0 {
            assert_eq!(
                err("dev.png"),
                "dev.png is a character device, not a regular file"
            );
        }
        assert!(start.elapsed() < Duration::from_secs(5));
        assert_eq!(
            read_regular(&d.join("real.png"), "real.png", 100).unwrap(),
            b"x"
        );
    }

    #[test]
    fn caps_are_checked_before_reading_and_a_sparse_giant_is_not_hashed() {
        let dir = tempfile::tempdir().unwrap();
        let big = std::fs::File::create(dir.path().join("big.bin")).unwrap();
        big.set_len(4 << 30).unwrap();
        std::fs::write(dir.path().join("RT_object.py"), b"x = 1\n").unwrap();
        std::os::unix::fs::symlink("/etc/hostname", dir.path().join("link.py")).unwrap();
        let start = Instant::now();
        let hashes = submission_hashes(dir.path());
        // Reading 4 GiB of zeros would take far longer than this on any machine here.
        assert!(
            start.elapsed() < Duration::from_secs(2),
            "{:?}",
            start.elapsed()
        );
        assert!(
            hashes["big.bin"].starts_with("not hashed: 4294967296 bytes, over the cap"),
            "{hashes:?}"
        );
        assert_eq!(hashes["RT_object.py"], sha256_hex(b"x = 1\n"));
        assert!(!hashes.contains_key("link.py"), "{hashes:?}");
        let e = read_regular(&dir.path().join("big.bin"), "big.bin", MAX_IMAGE_BYTES).unwrap_err();
        assert!(matches!(
            e,
            IntakeError::TooLarge {
                len: Some(4294967296),
                ..
            }
        ));
        assert_eq!(
            e.to_string(),
            format!("big.bin is 4294967296 bytes, over the limit of {MAX_IMAGE_BYTES} bytes")
        );
    }

    /// 30,000 empty files (a zip of 3 MB) made report.json 13 MB: only the first files by name
    /// are listed, and one entry that cannot be a file's name says how many more there are.
    #[test]
    fn a_submission_of_many_files_lists_a_bounded_number() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..HASH_MAX_FILES + 500 {
            std::fs::write(dir.path().join(format!("f{i:05}.py")), b"").unwrap();
        }
        let hashes = submission_hashes(dir.path());
        assert_eq!(hashes.len(), HASH_MAX_FILES + 1);
        assert_eq!(hashes["f00000.py"], sha256_hex(b""));
        assert!(!hashes.contains_key(&format!("f{:05}.py", HASH_MAX_FILES)));
        assert_eq!(
            hashes[MORE_FILES_KEY],
            format!("500 more files, not listed (at most {HASH_MAX_FILES} are)")
        );
        assert!(MORE_FILES_KEY.contains('/'), "no file name holds a slash");
    }

    #[test]
    fn png_headers_are_judged_before_decoding() {
        let ok = Some((400, 225));
        assert_eq!(check_png("a.png", &png(400, 225, 8, 2), ok), Ok(()));
        assert_eq!(check_png("a.png", &png(400, 225, 8, 6), ok), Ok(()));
        assert_eq!(
            check_png("week04_quad.png", &png(400, 225, 8, 0), ok).unwrap_err(),
            "week04_quad.png is greyscale; expected an RGB PNG"
        );
        // A palette (of any bit depth) stands for RGB colours: decoded, not refused.
        assert_eq!(check_png("a.png", &png(400, 225, 8, 3), ok), Ok(()));
        assert_eq!(check_png("a.png", &png(400, 225, 4, 3), ok), Ok(()));
        assert_eq!(
            check_png("a.png", &png(400, 225, 16, 2), ok).unwrap_err(),
            "a.png has 16 bits per channel; expected 8"
        );
        assert_eq!(
            check_png("a.png", &png(200, 100, 8, 2), ok).unwrap_err(),
            "a.png is 200x100 pixels; expected 400x225"
        );
        assert!(
            check_png("a.png", &png(100_000, 100_000, 8, 2), None)
                .unwrap_err()
                .contains("more than the 67108864 allowed")
        );
        assert_eq!(
            check_png("a.png", &png(4, 4, 8, 2)[..20], None).unwrap_err(),
            "a.png is not a readable PNG (its header is cut short)"
        );
        assert_eq!(check_png("a.png", b"not a png", None), Ok(()));
    }

    /// The header of a single-part scan-line EXR (R, G, B halves, ZIP of 16 lines) of `width` x
    /// `height` pixels with an offset table of zeros and no pixel data: what an EXR
    /// decompression bomb's header looks like (its blocks would inflate to gigabytes).
    fn exr_header(width: i32, height: i32) -> Vec<u8> {
        let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        let mut attr = |name: &str, kind: &str, value: &[u8]| {
            b.extend(name.as_bytes());
            b.push(0);
            b.extend(kind.as_bytes());
            b.push(0);
            b.extend((value.len() as i32).to_le_bytes());
            b.extend(value);
        };
        let mut channels = Vec::new();
        for c in ["B", "G", "R"] {
            channels.extend(c.as_bytes());
            channels.push(0);
            channels.extend(1i32.to_le_bytes());
            channels.extend([0, 0, 0, 0]);
            channels.extend(1i32.to_le_bytes());
            channels.extend(1i32.to_le_bytes());
        }
        channels.push(0);
        attr("channels", "chlist", &channels);
        attr("compression", "compression", &[3]);
        let window: Vec<u8> = [0, 0, width - 1, height - 1]
            .iter()
            .flat_map(|v: &i32| v.to_le_bytes())
            .collect();
        attr("dataWindow", "box2i", &window);
        attr("displayWindow", "box2i", &window);
        attr("lineOrder", "lineOrder", &[0]);
        attr("pixelAspectRatio", "float", &1f32.to_le_bytes());
        attr("screenWindowCenter", "v2f", &[0; 8]);
        attr("screenWindowWidth", "float", &1f32.to_le_bytes());
        b.push(0);
        b.extend(vec![0u8; 8 * (height as usize).div_ceil(16)]);
        b
    }

    #[test]
    fn exr_headers_are_judged_before_decoding() {
        // 8000 x 8000 pixels in 4 KB of header: decoding its blocks (once filled with deflated
        // zeros) would take gigabytes. A 4.6 MB file of 16000 x 16000 cost 7.5 GB and 110 s.
        let bomb = exr_header(8000, 8000);
        assert!(bomb.len() < 8 << 10);
        let start = Instant::now();
        assert_eq!(
            check_image_header("week04_sphere.png", &bomb, Some((400, 225))).unwrap_err(),
            "week04_sphere.png is 8000x8000 pixels; expected 400x225"
        );
        assert_eq!(
            check_image_header("a.exr", &bomb, None).unwrap_err(),
            "a.exr would decode to 384000000 bytes of samples, more than the 268435456 allowed"
        );
        assert!(
            check_image_header("a.exr", &exr_header(16000, 16000), None)
                .unwrap_err()
                .contains("is 16000x16000 pixels, more than the 67108864 allowed"),
        );
        assert!(start.elapsed() < Duration::from_secs(1));
        // The right size passes the header check (decoding then judges the data).
        assert_eq!(
            check_image_header("a.exr", &exr_header(400, 225), Some((400, 225))),
            Ok(())
        );
        // A header that cannot be read is named, not decoded.
        assert_eq!(
            check_image_header("a.exr", &exr_header(400, 225)[..30], None).unwrap_err(),
            "a.exr is not a readable OpenEXR file (its header is cut short or damaged)"
        );
        // Through the staging, a bomb is refused with the file named as the student knows it.
        let dir = tempfile::tempdir().unwrap();
        let stage = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("week04_sphere.png"), &bomb).unwrap();
        assert_eq!(
            stage_image(
                dir.path(),
                "week04_sphere.png",
                Some((400, 225)),
                stage.path()
            )
            .unwrap_err(),
            "week04_sphere.png is 8000x8000 pixels; expected 400x225"
        );
        // PNG headers are judged as before.
        assert_eq!(
            check_image_header("a.png", &png(200, 100, 8, 2), Some((400, 225))).unwrap_err(),
            "a.png is 200x100 pixels; expected 400x225"
        );
    }

    #[test]
    fn images_are_only_read_inside_the_submission() {
        let dir = tempfile::tempdir().unwrap();
        let stage = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        std::fs::write(outside.path().join("a.png"), png(4, 4, 8, 2)).unwrap();
        std::os::unix::fs::symlink(outside.path(), dir.path().join("imgs")).unwrap();
        assert_eq!(
            stage_image(dir.path(), "imgs/a.png", None, stage.path()).unwrap_err(),
            "imgs is a symbolic link, not a folder"
        );
        assert_eq!(
            stage_image(dir.path(), "../a.png", None, stage.path()).unwrap_err(),
            "../a.png is outside the submission"
        );
        std::fs::write(dir.path().join("b.png"), png(4, 4, 8, 2)).unwrap();
        let staged = stage_image(dir.path(), "b.png", Some((4, 4)), stage.path()).unwrap();
        assert_eq!(staged, stage.path().join("b.png"));
        assert_eq!(std::fs::read(staged).unwrap(), png(4, 4, 8, 2));
    }
}
