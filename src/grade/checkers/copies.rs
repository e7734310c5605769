//! Images that are not a render of the submission's code: the course's published reference
//! images, the reference tracer's own render of a scene at its default seed, and two
//! submissions of a batch whose images share their Monte Carlo noise.
//!
//! - **The course's images** are known by the SHA-256 of their decoded pixels
//!   ([`pixels_sha256`]: width, height and the 8-bit RGB values, so neither the PNG's encoding,
//!   compression, alpha channel nor metadata matter). The grader carries those hashes, never
//!   the images.
//! - **Shared noise.** A render with random pixel jitter is noisy only where a pixel straddles an
//!   edge; two independent renders of one scene give those pixels different values, a copy
//!   gives the same ones. An image's [`Fingerprint`] keeps its *busy* pixels (those that differ
//!   by more than [`CODES`] codes from a neighbour); two fingerprints [`share noise`](shared_noise)
//!   when, over the pixels busy in both, at most [`SHARED_AT_MOST`] of them differ by more than
//!   [`CODES`] codes. A copy, re-encoded or not, differs in none, or in the few pixels someone
//!   changed; independent renders differ in a third or more (the figures are measured in
//!   `docs/grading.md`).
//! - **The reference tracer's render** (`rtoracle render SCENE` at seed 0 and the scene's
//!   samples per pixel) is rendered once per process and compared the same way.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::grade::rubric::SceneSource;
use crate::image_io::Rgb8Image;

/// How many codes (of 255) two pixel values may differ by and still count as the same value.
pub const CODES: u8 = 2;

/// The largest share of the pixels busy in two images whose values differ, for the two to share
/// their noise.
pub const SHARED_AT_MOST: f64 = 0.05;

/// The fewest pixels busy in both images for a verdict: with fewer, there is too little noise to
/// tell a copy from an independent render, and nothing is flagged.
pub const MIN_COMMON_BUSY: usize = 40;

/// The SHA-256 (hex) of an image's decoded pixels: `"{width}x{height}\n"` then the RGB bytes.
pub fn pixels_sha256(image: &Rgb8Image) -> String {
    let mut h = Sha256::new();
    h.update(format!("{}x{}\n", image.width, image.height).as_bytes());
    h.update(&image.data);
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The course's published week-4 images: the scene, the file name and the hash of their pixels.
pub const COURSE_IMAGES: [(&str, &str, &str); 2] = [
    (
        "week04-sphere",
        "week04_sphere.png",
        "b959e04f25242867bcac0d661c6c0062965fc86d463d2b2ee5425ac6cf7f34d5",
    ),
    (
        "week04-quad",
        "week04_quad.png",
        "c1be288169c43f4b49463c39a8bf2902f90516c6644eec656d6dd1375446c1f9",
    ),
];

/// The course's published image whose pixels hash to `sha256`, by its file name.
pub fn course_image(sha256: &str) -> Option<&'static str> {
    COURSE_IMAGES
        .iter()
        .find(|(_, _, h)| *h == sha256)
        .map(|(_, f, _)| *f)
}

/// What an image keeps for the copy checks: its size, the hash of its pixels and its busy
/// pixels (sorted by position), a few percent of the image.
#[derive(Clone, Debug, PartialEq)]
pub struct Fingerprint {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// [`pixels_sha256`] of the image.
    pub sha256: String,
    /// The busy pixels: position (`y * width + x`) and RGB value.
    pub busy: Vec<(u32, [u8; 3])>,
}

fn differs(a: [u8; 3], b: [u8; 3]) -> bool {
    (0..3).any(|k| a[k].abs_diff(b[k]) > CODES)
}

impl Fingerprint {
    /// The fingerprint of `image`.
    pub fn of(image: &Rgb8Image) -> Fingerprint {
        let (w, h) = (image.width, image.height);
        let px = |x: usize, y: usize| {
            let i = 3 * (y * w + x);
            [image.data[i], image.data[i + 1], image.data[i + 2]]
        };
        let mut busy = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let p = px(x, y);
                let neighbour_differs = (y.saturating_sub(1)..=(y + 1).min(h - 1)).any(|ny| {
                    (x.saturating_sub(1)..=(x + 1).min(w - 1)).any(|nx| differs(p, px(nx, ny)))
                });
                if neighbour_differs {
                    busy.push(((y * w + x) as u32, p));
                }
            }
        }
        Fingerprint {
            width: w,
            height: h,
            sha256: pixels_sha256(image),
            busy,
        }
    }
}

/// How two images' noise compares.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct NoiseMatch {
    /// Pixels busy in both images.
    pub common_busy: usize,
    /// Of those, how many differ by more than [`CODES`] codes.
    pub differing: usize,
    /// Whether the two share their noise: one is a copy of the other (or both of a third).
    pub shared: bool,
}

/// Compares the noise of two images of the same size (of different sizes: nothing shared).
pub fn shared_noise(a: &Fingerprint, b: &Fingerprint) -> NoiseMatch {
    if (a.width, a.height) != (b.width, b.height) {
        return NoiseMatch {
            common_busy: 0,
            differing: 0,
            shared: false,
        };
    }
    let (mut i, mut j) = (0, 0);
    let (mut common, mut differing) = (0usize, 0usize);
    while i < a.busy.len() && j < b.busy.len() {
        let ((pa, va), (pb, vb)) = (a.busy[i], b.busy[j]);
        match pa.cmp(&pb) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                common += 1;
                differing += differs(va, vb) as usize;
                i += 1;
                j += 1;
            }
        }
    }
    NoiseMatch {
        common_busy: common,
        differing,
        shared: common >= MIN_COMMON_BUSY && differing as f64 <= SHARED_AT_MOST * common as f64,
    }
}

/// What the copy checks found about one uploaded image.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CopyFinding {
    /// Pixel for pixel the course's published image `file`.
    CourseImage {
        /// The published image's file name.
        file: String,
    },
    /// The reference tracer's own render of the scene (at seed 0), or a copy of it.
    ReferenceRender {
        /// How its noise compares with the reference's render.
        #[serde(flatten)]
        noise: NoiseMatch,
    },
    /// In a batch: shares its noise with another submission's image (flagged for review).
    SharedWith {
        /// The other submission (its folder's name).
        submission: crate::escape::Untrusted,
        /// How their noise compares.
        #[serde(flatten)]
        noise: NoiseMatch,
    },
}

impl CopyFinding {
    /// Whether the group scores 0 for it (the course's image or the reference's render);
    /// shared noise within a batch is flagged for review and scores as judged.
    pub fn zeroes(&self) -> bool {
        !matches!(self, CopyFinding::SharedWith { .. })
    }

    /// The sentence the student reads when the grader's render of the submission's code
    /// returned such an image (its pixels were read, not computed).
    pub fn render_sentence(&self) -> String {
        match self {
            CopyFinding::CourseImage { file: course } => format!(
                "The render of your code returned the course's published image {course}, pixel for pixel: your code did not compute it; it scores 0."
            ),
            CopyFinding::ReferenceRender { .. } => "The render of your code returned the reference tracer's own render of the scene (rtoracle render at its default seed): your code did not compute it; it scores 0.".to_string(),
            CopyFinding::SharedWith { .. } => self.sentence("The render of your code"),
        }
    }

    /// The sentence the student reads (never naming a classmate).
    pub fn sentence(&self, file: &str) -> String {
        match self {
            CopyFinding::CourseImage { file: course } => format!(
                "{file} is the course's published image {course}, pixel for pixel, not a render of your code; it scores 0."
            ),
            CopyFinding::ReferenceRender { .. } => format!(
                "{file} is the reference tracer's own render of the scene (rtoracle render at its default seed), not a render of your code; it scores 0."
            ),
            CopyFinding::SharedWith { .. } => format!(
                "{file} shares its Monte Carlo noise with another submission's image (one is a copy of the other); both are flagged for review."
            ),
        }
    }
}

/// The course's image or the reference's render that `fp` (an upload for `scene`) is, if any.
pub fn recognise(fp: &Fingerprint, scene: &SceneSource) -> Option<CopyFinding> {
    if let Some(file) = course_image(&fp.sha256) {
        return Some(CopyFinding::CourseImage { file: file.into() });
    }
    let reference = reference_render(scene)?;
    let noise = shared_noise(fp, &reference);
    noise
        .shared
        .then_some(CopyFinding::ReferenceRender { noise })
}

/// The fingerprint of the PNG `rtoracle render` writes for `scene` with its defaults (seed 0,
/// the scene's samples per pixel and size), rendered once per process; `None` when the scene
/// cannot be rendered.
pub fn reference_render(scene: &SceneSource) -> Option<Arc<Fingerprint>> {
    type Cache = Mutex<BTreeMap<String, Option<Arc<Fingerprint>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    let key = match scene {
        SceneSource::Builtin(name) => format!("builtin:{name}"),
        SceneSource::File(f) => format!("file:{}", f.sha256),
    };
    if let Some(hit) = cache.lock().ok()?.get(&key) {
        return hit.clone();
    }
    // Rendered outside the lock (two threads may both render it once; the result is the same).
    let made = render_default(scene).map(|img| Arc::new(Fingerprint::of(&img)));
    cache.lock().ok()?.insert(key, made.clone());
    made
}

/// The most samples (pixels times samples per pixel) the reference's render of a scene may take
/// for the check: an instructor's scene beyond it (a large, converged image) is not rendered,
/// and uploads are not compared with it.
pub const MAX_REFERENCE_SAMPLES: usize = 16_000_000;

/// The 8-bit image `rtoracle render` writes for `scene` with its defaults (`None` beyond
/// [`MAX_REFERENCE_SAMPLES`]).
pub fn render_default(scene: &SceneSource) -> Option<Rgb8Image> {
    let description = match scene {
        SceneSource::Builtin(name) => crate::scene::builtin(name).ok()?,
        SceneSource::File(f) => f.description.clone(),
    };
    let camera = description.camera(None);
    let samples =
        (camera.width * camera.height).saturating_mul(description.image.samples_per_pixel as usize);
    if samples > MAX_REFERENCE_SAMPLES {
        return None;
    }
    render_png_pixels(&description, None, 0)
}

/// The 8-bit image `rtoracle render` writes for `description` at `width` (the scene's when
/// `None`) and `seed`, at the scene's samples per pixel.
pub fn render_png_pixels(
    description: &crate::scene::SceneDescription,
    width: Option<usize>,
    seed: u64,
) -> Option<Rgb8Image> {
    let camera = description.camera(width);
    let options = crate::render::RenderOptions {
        samples_per_pixel: description.image.samples_per_pixel,
        seed,
        ..Default::default()
    };
    let film = crate::render::render(&description.scene(), &camera, &options).ok()?;
    Some(Rgb8Image {
        width: film.width,
        height: film.height,
        data: film.to_course_rgb8(),
    })
}

#[cfg(test)]
#[path = "copies_tests.rs"]
mod tests;
