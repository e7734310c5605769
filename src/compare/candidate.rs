//! The image being judged: read from a PNG (8-bit RGB or RGBA, or a palette), a PPM (`P3` text
//! or `P6` binary, 8-bit: what *Ray Tracing in One Weekend*'s own program writes to stdout) or an
//! EXR (linear values), told apart by their first bytes.
//!
//! PPM files are decoded by the `image` crate's `pnm` codec (it reads both the text and the
//! binary form, with comments); the header is read here first, so that what this module does
//! not take (grey PGM or PBM, PAM, 16-bit samples, another maxval) is refused in words, and a
//! header claiming more pixels than the file can hold is refused before anything is allocated.

use std::path::Path;

use super::{CompareError, encoding::Encoding};

/// A candidate image: 8-bit codes (from a PNG or PPM) or linear values (from an EXR).
#[derive(Clone, Debug, PartialEq)]
pub enum CandidateImage {
    /// 8-bit RGB, row-major, top row first.
    Rgb8 {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
        /// `3 * width * height` codes.
        data: Vec<u8>,
    },
    /// Linear RGB (an EXR, read as `f32`), row-major, top row first.
    Linear {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
        /// One linear RGB triple per pixel.
        data: Vec<[f32; 3]>,
    },
}

impl CandidateImage {
    /// Reads a PNG (8-bit RGB or RGBA), a PPM (`P3` or `P6`, maxval 255) or an EXR, telling them
    /// apart by their first bytes. Errors name the file and say what it is.
    pub fn load(path: &Path) -> Result<Self, CompareError> {
        let bad = |message: String| CompareError::Input {
            path: path.to_path_buf(),
            message,
        };
        let mut head = [0u8; 8];
        let n = {
            use std::io::Read;
            let mut f = std::fs::File::open(path).map_err(|e| {
                bad(if e.kind() == std::io::ErrorKind::NotFound {
                    "no such file".to_string()
                } else {
                    format!("cannot open: {e}")
                })
            })?;
            if f.metadata().map(|m| m.is_dir()).unwrap_or(false) {
                return Err(bad("is a folder, not an image".into()));
            }
            f.read(&mut head)
                .map_err(|e| bad(format!("cannot read: {e}")))?
        };
        if n >= 8 && head == *b"\x89PNG\r\n\x1a\n" {
            let img = crate::image_io::read_png(path)?;
            Ok(CandidateImage::Rgb8 {
                width: img.width,
                height: img.height,
                data: img.data,
            })
        } else if n >= 4 && head[..4] == [0x76, 0x2f, 0x31, 0x01] {
            let img = crate::image_io::read_exr(path)?;
            if img.mean.iter().any(|p| p.iter().any(|x| !x.is_finite())) {
                return Err(bad("has a NaN or infinite pixel value".into()));
            }
            Ok(CandidateImage::Linear {
                width: img.width,
                height: img.height,
                data: img.mean,
            })
        } else if n >= 3 && head[0] == b'P' && head[2].is_ascii_whitespace() {
            let bytes = std::fs::read(path).map_err(|e| bad(format!("cannot read: {e}")))?;
            read_ppm(&bytes).map_err(bad)
        } else if n == 0 {
            Err(bad("is empty, not an image".into()))
        } else {
            Err(bad("is not a PNG, PPM or EXR image".into()))
        }
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        match self {
            CandidateImage::Rgb8 { width, height, .. }
            | CandidateImage::Linear { width, height, .. } => (*width, *height),
        }
    }

    /// The linear values the image stands for: an 8-bit code's the mid-point of its interval
    /// under `encoding` (within `[0, 1]`), a linear image's its own.
    pub fn linear_mid_points(&self, encoding: Encoding) -> Vec<[f64; 3]> {
        match self {
            CandidateImage::Rgb8 { data, .. } => {
                let table = encoding.table();
                data.chunks_exact(3)
                    .map(|p| {
                        [0, 1, 2].map(|c| {
                            let (lo, hi) = table[p[c] as usize];
                            (0.5 * (lo + hi)).clamp(0.0, 1.0)
                        })
                    })
                    .collect()
            }
            CandidateImage::Linear { data, .. } => {
                data.iter().map(|p| p.map(|x| x as f64)).collect()
            }
        }
    }

    /// The image as 8-bit RGB for pictures (linear images are encoded with `encoding`).
    pub fn to_rgb8(&self, encoding: Encoding) -> Vec<u8> {
        match self {
            CandidateImage::Rgb8 { data, .. } => data.clone(),
            CandidateImage::Linear { data, .. } => data
                .iter()
                .flat_map(|p| p.map(|x| encoding.encode(x as f64)))
                .collect(),
        }
    }
}

/// The largest width or height of a PPM read (as of a scene).
const MAX_PPM_SIDE: u64 = 100_000;

/// The header of a PPM: magic, width, height, maxval, and where the samples start.
struct PpmHeader {
    binary: bool,
    width: usize,
    height: usize,
    maxval: u64,
    body: usize,
}

/// Reads the PPM header (whitespace and `#` comments between its fields, one whitespace byte
/// after the maxval); the error is in words.
fn ppm_header(bytes: &[u8]) -> Result<PpmHeader, String> {
    let binary = match &bytes[..2] {
        b"P3" => false,
        b"P6" => true,
        b"P1" | b"P4" => return Err("is a PBM (black and white) image, not an RGB PPM".into()),
        b"P2" | b"P5" => return Err("is a PGM (grey) image, not an RGB PPM (P3 or P6)".into()),
        b"P7" => return Err("is a PAM image; only PPM (P3 or P6) is read".into()),
        _ => return Err("is not a PNG, PPM or EXR image".into()),
    };
    let mut at = 2;
    let mut fields = [0u64; 3];
    for (k, field) in fields.iter_mut().enumerate() {
        loop {
            match bytes.get(at) {
                Some(b) if b.is_ascii_whitespace() => at += 1,
                Some(b'#') => {
                    while bytes.get(at).is_some_and(|&b| b != b'\n') {
                        at += 1;
                    }
                }
                _ => break,
            }
        }
        let start = at;
        while bytes.get(at).is_some_and(u8::is_ascii_digit) {
            at += 1;
        }
        let what = ["width", "height", "maxval"][k];
        let digits = std::str::from_utf8(&bytes[start..at]).unwrap_or("");
        *field = digits
            .parse()
            .map_err(|_| format!("is a PPM whose header has no readable {what}"))?;
    }
    if !bytes.get(at).is_some_and(u8::is_ascii_whitespace) {
        return Err("is a PPM whose header does not end after its maxval".into());
    }
    let [width, height, maxval] = fields;
    if width == 0 || height == 0 {
        return Err(format!(
            "is a PPM of {width}x{height} pixels, an empty image"
        ));
    }
    let side = MAX_PPM_SIDE;
    if width > side || height > side {
        return Err(format!(
            "is a PPM of {width}x{height} pixels; a side may be at most {side}"
        ));
    }
    Ok(PpmHeader {
        binary,
        width: width as usize,
        height: height as usize,
        maxval,
        body: at + 1,
    })
}

/// Decodes an 8-bit RGB PPM (`P3` or `P6`, maxval 255) with the `image` crate.
fn read_ppm(bytes: &[u8]) -> Result<CandidateImage, String> {
    let header = ppm_header(bytes)?;
    let kind = if header.binary { "P6" } else { "P3" };
    if header.maxval != 255 {
        let depth = if header.maxval > 255 {
            "16-bit"
        } else {
            "not 8-bit"
        };
        return Err(format!(
            "is a {kind} PPM with maxval {} ({depth}); only 8-bit PPMs (maxval 255) are read",
            header.maxval
        ));
    }
    let samples = 3 * header.width * header.height;
    // Each sample takes a byte (P6), or a digit and a separator (P3): a header claiming more
    // pixels than the file can hold is refused before the decoder allocates them.
    let least = if header.binary {
        samples
    } else {
        2 * samples - 1
    };
    let available = bytes.len().saturating_sub(header.body);
    if available < least {
        return Err(format!(
            "is a truncated {kind} PPM: its header says {}x{} pixels, which need at least {least} bytes of samples, but {available} follow",
            header.width, header.height
        ));
    }
    let malformed = |e: image::ImageError| format!("is a malformed {kind} PPM: {e}");
    let decoder =
        image::codecs::pnm::PnmDecoder::new(std::io::Cursor::new(bytes)).map_err(malformed)?;
    let decoded = image::DynamicImage::from_decoder(decoder).map_err(malformed)?;
    let (width, height) = (decoded.width() as usize, decoded.height() as usize);
    match decoded {
        image::DynamicImage::ImageRgb8(img) => Ok(CandidateImage::Rgb8 {
            width,
            height,
            data: img.into_raw(),
        }),
        other => Err(format!(
            "is a {kind} PPM the decoder read as {:?}, not 8-bit RGB",
            other.color()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(bytes: &[u8]) -> Result<CandidateImage, String> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.ppm");
        std::fs::write(&path, bytes).unwrap();
        CandidateImage::load(&path).map_err(|e| {
            let text = e.to_string();
            assert!(text.starts_with(&format!("{}: ", path.display())), "{text}");
            text
        })
    }

    /// A 2x1 image, written as RTIOW's program writes it (P3, one pixel a line), with a comment
    /// and as P6: the same codes.
    #[test]
    fn text_and_binary_ppm_give_the_same_codes() {
        let want = CandidateImage::Rgb8 {
            width: 2,
            height: 1,
            data: vec![255, 0, 7, 1, 128, 254],
        };
        assert_eq!(load(b"P3\n2 1\n255\n255 0 7\n1 128 254\n").unwrap(), want);
        assert_eq!(
            load(b"P3\n# made by hand\n2 1 255\n255 0 7 1 128 254").unwrap(),
            want
        );
        let mut p6 = b"P6\n2 1\n255\n".to_vec();
        p6.extend_from_slice(&[255, 0, 7, 1, 128, 254]);
        assert_eq!(load(&p6).unwrap(), want);
    }

    #[test]
    fn what_is_not_an_8_bit_rgb_ppm_is_refused_in_words() {
        let mut p6_16 = b"P6\n1 1\n65535\n".to_vec();
        p6_16.extend_from_slice(&[0; 6]);
        let mut big = b"P6\n100000 100000\n255\n".to_vec();
        big.extend_from_slice(&[0; 12]);
        for (bytes, needle) in [
            (&b"P2\n1 1\n255\n0\n"[..], "PGM (grey)"),
            (b"P5\n1 1\n255\n\0", "PGM (grey)"),
            (b"P1\n1 1\n0\n", "PBM"),
            (b"P7\nWIDTH 1\n", "PAM"),
            (
                &p6_16,
                "maxval 65535 (16-bit); only 8-bit PPMs (maxval 255)",
            ),
            (b"P3\n1 1\n15\n1 2 3\n", "maxval 15 (not 8-bit)"),
            (b"P3\n2 2\n255\n1 2 3\n", "truncated P3 PPM"),
            (&big, "truncated P6 PPM: its header says 100000x100000"),
            (b"P3\n1 1\n255\n1 2 x\n", "malformed P3 PPM"),
            (b"P3\nwide 1\n255\n", "no readable width"),
            (b"P3\n0 1\n255\n", "an empty image"),
            (b"P9 hello", "not a PNG, PPM or EXR"),
        ] {
            let e = load(bytes).unwrap_err();
            assert!(e.contains(needle), "{needle}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
