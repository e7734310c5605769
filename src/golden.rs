//! Golden images: the reference's high-sample renders of the built-in scenes, kept as EXR files.
//!
//! A golden is `golden/<scene>.exr`: the built-in scene rendered by [`crate::render::render`]
//! with [`GOLDEN_SPP`] samples per pixel and seed [`GOLDEN_SEED`], storing the per-pixel mean
//! (`R`, `G`, `B`) and the per-sample variance of each channel (the `variance` layer), and
//! string attributes saying what it is ([`golden_attributes`]). The bytes depend only on the
//! scene, the sample count, the seed and the tool version: not on the machine or its number of
//! threads ([`crate::image_io::encode_exr`]).
//!
//! The goldens of the built-in scenes are also compiled into the library
//! ([`embedded_golden`]), so an installed `rtoracle` has them without the source tree.
//! [`compare_goldens`] compares two goldens pixel by pixel within a [`Tolerance`]; `rtoracle
//! golden --check` and the test suite's insta snapshots use it.
//!
//! Goldens of instructors' own scene files ([`golden_bytes_of`]) are the same kind of file,
//! rendered the first time they are needed and kept in a cache ([`cached_golden`]) keyed by the
//! scene's content hash, the sample count and the tool version: a batch renders each one once,
//! and a golden is never used for a scene it was not made from ([`golden_fits`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use sha2::{Digest, Sha256};

use crate::image_io::{ExrImage, ImageError, decode_exr, encode_exr, read_exr, write_atomically};
use crate::render::{Film, PixelJitter, RenderError, RenderOptions, render};
use crate::scene::{SceneDescription, SceneError, builtin};

/// Samples per pixel of the goldens.
pub const GOLDEN_SPP: u32 = 4096;

/// Seed of the goldens' per-pixel random streams.
pub const GOLDEN_SEED: u64 = 0;

/// The attribute naming the scene.
pub const ATTR_SCENE: &str = "rtoracle.scene";
/// The attribute holding the SHA-256 (lower-case hex) of the scene's canonical TOML
/// ([`SceneDescription::to_toml`]).
pub const ATTR_SCENE_SHA256: &str = "rtoracle.sceneSha256";
/// The attribute holding the samples per pixel.
pub const ATTR_SPP: &str = "rtoracle.spp";
/// The attribute holding the seed.
pub const ATTR_SEED: &str = "rtoracle.seed";
/// The attribute holding the version of rtoracle that wrote the file.
pub const ATTR_VERSION: &str = "rtoracle.version";
/// The attribute describing the camera convention.
pub const ATTR_CAMERA: &str = "rtoracle.camera";
/// The attribute describing how samples were placed in a pixel.
pub const ATTR_SAMPLING: &str = "rtoracle.sampling";
/// The attribute describing the `variance` layer.
pub const ATTR_VARIANCE: &str = "rtoracle.variance";

/// The camera convention written into every golden.
pub const CAMERA_CONVENTION: &str = "course (Ray Tracing in One Weekend, 4th edition): pinhole at \
look_from, vertical field of view vfov in degrees, row 0 at the top; the centre of pixel (i, j) is \
pixel00 + i * pixel_delta_u + j * pixel_delta_v";

/// The sampling written into every golden.
pub const SAMPLING: &str = "uniform jitter in [-0.5, 0.5) of a pixel around its centre, \
independently per sample (x then y), from a PCG64 stream per pixel seeded by (seed, pixel index)";

/// What the `variance` layer holds, written into every golden.
pub const VARIANCE_MEANING: &str = "per-sample variance of each channel (Welford's update in f64, \
divided by n - 1), rounded to f32; the variance of the mean is this divided by rtoracle.spp";

/// Name of the golden file of `scene`: `<scene>.exr`.
pub fn golden_file_name(scene: &str) -> String {
    format!("{scene}.exr")
}

/// What goes wrong making, reading or checking a golden (one line).
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// The scene is not a built-in one.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The render was refused.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The EXR could not be written or read.
    #[error(transparent)]
    Image(#[from] ImageError),
}

/// Lower-case hex SHA-256 of the scene's canonical TOML ([`SceneDescription::to_toml`]).
pub fn scene_sha256(description: &SceneDescription) -> String {
    sha256_hex(description.to_toml().as_bytes())
}

/// Lower-case hex SHA-256 of `bytes`.
fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The string attributes of a golden of `scene` rendered with `spp` samples and `seed`.
pub fn golden_attributes(
    scene: &str,
    description: &SceneDescription,
    spp: u32,
    seed: u64,
) -> Vec<(String, String)> {
    [
        (ATTR_SCENE, scene.to_string()),
        (ATTR_SCENE_SHA256, scene_sha256(description)),
        (ATTR_SPP, spp.to_string()),
        (ATTR_SEED, seed.to_string()),
        (ATTR_VERSION, env!("CARGO_PKG_VERSION").to_string()),
        (ATTR_CAMERA, CAMERA_CONVENTION.to_string()),
        (ATTR_SAMPLING, SAMPLING.to_string()),
        (ATTR_VARIANCE, VARIANCE_MEANING.to_string()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// Renders the built-in `scene` as a golden: its own size, `spp` samples per pixel, `seed`,
/// uniform jitter, with the per-sample variance. Renders on rayon's current pool; the film does
/// not depend on its size. `progress` shows a bar on a terminal.
pub fn render_golden(
    scene: &str,
    spp: u32,
    seed: u64,
    progress: bool,
) -> Result<Film, GoldenError> {
    render_golden_of(&builtin(scene)?, spp, seed, progress)
}

/// [`render_golden`] of any scene (a built-in or a scene file). Counted by [`golden_renders`].
pub fn render_golden_of(
    description: &SceneDescription,
    spp: u32,
    seed: u64,
    progress: bool,
) -> Result<Film, GoldenError> {
    let options = RenderOptions {
        samples_per_pixel: spp,
        seed,
        variance: true,
        jitter: PixelJitter::Uniform,
        progress,
    };
    RENDERS.fetch_add(1, Ordering::Relaxed);
    Ok(render(
        &description.scene(),
        &description.camera(None),
        &options,
    )?)
}

/// The bytes of the golden file of the built-in `scene` with `spp` samples and `seed`
/// ([`GOLDEN_SPP`] and [`GOLDEN_SEED`] for the committed goldens).
pub fn golden_bytes(
    scene: &str,
    spp: u32,
    seed: u64,
    progress: bool,
) -> Result<Vec<u8>, GoldenError> {
    let description = builtin(scene)?;
    golden_bytes_of(&description, scene, spp, seed, progress)
}

/// The bytes of the golden file of any scene (a built-in or a scene file), named `name` in its
/// `rtoracle.scene` attribute: rendered at the scene's own size with `spp` samples per pixel,
/// `seed`, uniform jitter and the per-sample variance ([`render_golden_of`]).
pub fn golden_bytes_of(
    description: &SceneDescription,
    name: &str,
    spp: u32,
    seed: u64,
    progress: bool,
) -> Result<Vec<u8>, GoldenError> {
    let film = render_golden_of(description, spp, seed, progress)?;
    let attributes = golden_attributes(name, description, spp, seed);
    Ok(encode_exr(
        &film,
        &attributes,
        Path::new(&golden_file_name(name)),
    )?)
}

static RENDERS: AtomicUsize = AtomicUsize::new(0);

/// How many goldens [`render_golden_of`] (and so [`render_golden`], [`golden_bytes`] and
/// [`cached_golden`]) has rendered in this process: a cache hit renders none.
pub fn golden_renders() -> usize {
    RENDERS.load(Ordering::Relaxed)
}

/// The folder rtoracle caches in: `$RTORACLE_CACHE_DIR`, else `$XDG_CACHE_HOME/rtoracle`, else
/// `$HOME/.cache/rtoracle` (empty variables count as unset); `None` when none is set.
pub fn cache_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("RTORACLE_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("rtoracle")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("rtoracle")))
}

/// Where [`cached_golden`] keeps the golden of a scene in cache folder `dir`:
/// `goldens/<scene sha256>-<spp>spp-<version>.exr`, keyed by the scene's content
/// ([`scene_sha256`]), the sample count and the tool version (the seed is always
/// [`GOLDEN_SEED`]), so editing the scene or upgrading rtoracle renders a new one.
pub fn cache_file(dir: &Path, description: &SceneDescription, spp: u32) -> PathBuf {
    dir.join("goldens").join(format!(
        "{}-{spp}spp-{}.exr",
        scene_sha256(description),
        env!("CARGO_PKG_VERSION")
    ))
}

/// A golden [`cached_golden`] found or made.
#[derive(Clone, Debug, PartialEq)]
pub struct CachedGolden {
    /// The EXR's bytes.
    pub bytes: Vec<u8>,
    /// The cache file holding them, or `None` when there is no cache folder or it could not be
    /// written (the golden was rendered for this process only; [`CachedGolden::warning`] says
    /// why).
    pub path: Option<PathBuf>,
    /// Whether this call rendered it (false: read from the cache).
    pub rendered: bool,
    /// Why the golden could not be cached, when it could not.
    pub warning: Option<String>,
}

/// One lock per cache key, so the members of a batch render each golden once.
fn key_lock(key: &Path) -> Arc<Mutex<()>> {
    static LOCKS: OnceLock<Mutex<HashMap<PathBuf, Arc<Mutex<()>>>>> = OnceLock::new();
    let mut locks = LOCKS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    Arc::clone(locks.entry(key.to_path_buf()).or_default())
}

/// The golden of `description` (named `name` in the file) with `spp` samples per pixel and
/// [`GOLDEN_SEED`], from the cache ([`cache_dir`], [`cache_file`]) or, the first time, rendered
/// (`progress`: a bar on stderr when it is a terminal) and written there atomically (a
/// temporary file renamed into place, so another process never reads half a golden).
///
/// Within a process, callers asking for the same key wait for the first one's render instead
/// of rendering again; across processes, two may render the same golden at the same time, and
/// both write the same bytes. A cache file that is not a golden of this scene (corrupt, or
/// made by another tool) is rendered again and replaced.
pub fn cached_golden(
    description: &SceneDescription,
    name: &str,
    spp: u32,
    progress: bool,
) -> Result<CachedGolden, GoldenError> {
    cached_golden_in(cache_dir().as_deref(), description, name, spp, progress)
}

/// [`cached_golden`] with the cache in folder `dir` (`None`: no cache, always render).
pub fn cached_golden_in(
    dir: Option<&Path>,
    description: &SceneDescription,
    name: &str,
    spp: u32,
    progress: bool,
) -> Result<CachedGolden, GoldenError> {
    let Some(dir) = dir else {
        let bytes = golden_bytes_of(description, name, spp, GOLDEN_SEED, progress)?;
        return Ok(CachedGolden {
            bytes,
            path: None,
            rendered: true,
            warning: Some(
                "no cache folder (set RTORACLE_CACHE_DIR, XDG_CACHE_HOME or HOME)".to_string(),
            ),
        });
    };
    let path = cache_file(dir, description, spp);
    let lock = key_lock(&path);
    let _held = lock.lock().unwrap_or_else(|e| e.into_inner());
    if let Ok(bytes) = std::fs::read(&path) {
        if golden_fits(&bytes, &path, description).is_ok() {
            return Ok(CachedGolden {
                bytes,
                path: Some(path),
                rendered: false,
                warning: None,
            });
        }
    }
    let bytes = golden_bytes_of(description, name, spp, GOLDEN_SEED, progress)?;
    let written = std::fs::create_dir_all(path.parent().expect("a file in goldens/"))
        .map_err(|e| format!("{}: cannot create the cache folder: {e}", dir.display()))
        .and_then(|()| write_atomically(&path, &bytes).map_err(|e| e.to_string()));
    Ok(match written {
        Ok(()) => CachedGolden {
            bytes,
            path: Some(path),
            rendered: true,
            warning: None,
        },
        Err(why) => CachedGolden {
            bytes,
            path: None,
            rendered: true,
            warning: Some(why),
        },
    })
}

/// Checks that EXR `bytes` (read from `source`) are a golden of `description`: an EXR with a
/// `variance` layer, the scene's size and its content hash in `rtoracle.sceneSha256`. The error
/// is one line without the file name.
pub fn golden_fits(
    bytes: &[u8],
    source: &Path,
    description: &SceneDescription,
) -> Result<ExrImage, String> {
    let image = decode_exr(bytes, source).map_err(|e| {
        let text = e.to_string();
        let prefix = format!("{}: ", source.display());
        text.strip_prefix(&prefix).map(String::from).unwrap_or(text)
    })?;
    let camera = description.camera(None);
    if (image.width, image.height) != (camera.width, camera.height) {
        return Err(format!(
            "is {}x{} but the scene is {}x{}",
            image.width, image.height, camera.width, camera.height
        ));
    }
    let want = scene_sha256(description);
    match image.attribute(ATTR_SCENE_SHA256) {
        Some(h) if h == want => {}
        Some(h) => {
            return Err(format!(
                "was made from another scene ({ATTR_SCENE_SHA256} {h}, but the scene's is {want})"
            ));
        }
        None => return Err(format!("has no {ATTR_SCENE_SHA256} attribute")),
    }
    if image.variance.is_none() {
        return Err("has no 'variance' layer".to_string());
    }
    Ok(image)
}

/// Reads a golden (or any EXR [`read_exr`] reads).
pub fn load_golden(path: &Path) -> Result<ExrImage, ImageError> {
    read_exr(path)
}

/// The goldens compiled into the library, by scene name.
const EMBEDDED: &[(&str, &[u8])] = &[
    (
        "week04-sphere",
        include_bytes!("../golden/week04-sphere.exr"),
    ),
    ("week04-quad", include_bytes!("../golden/week04-quad.exr")),
    ("triangles", include_bytes!("../golden/triangles.exr")),
    ("edge-cases", include_bytes!("../golden/edge-cases.exr")),
];

/// The bytes of the committed golden of the built-in `scene`, compiled into the library
/// (`golden/<scene>.exr` when it was built), or `None` for a scene without one.
pub fn embedded_golden(scene: &str) -> Option<&'static [u8]> {
    EMBEDDED
        .iter()
        .find(|(name, _)| *name == scene)
        .map(|(_, bytes)| *bytes)
}

/// The committed golden of the built-in `scene`, decoded.
pub fn embedded_golden_image(scene: &str) -> Option<ExrImage> {
    let bytes = embedded_golden(scene)?;
    let label = format!("(embedded) golden/{}", golden_file_name(scene));
    Some(decode_exr(bytes, Path::new(&label)).expect("the embedded goldens are valid EXR files"))
}

/// How close two goldens' pixels must be to count as equal: `|a - b| <= absolute + relative *
/// max(|a|, |b|)` for every pixel and channel of the mean and of the variance.
///
/// The reference is bit-reproducible (f64 arithmetic, libm's `tan`, a seeded stream per pixel),
/// so a regenerated golden normally equals the committed one exactly; the tolerance only absorbs
/// last-bit differences (a few f32 ulps) and still catches a single sample out of 4096 changing
/// colour by more than about 0.05.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Absolute allowance.
    pub absolute: f32,
    /// Allowance relative to the larger magnitude.
    pub relative: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            absolute: 1e-6,
            relative: 1e-5,
        }
    }
}

impl Tolerance {
    /// Whether `a` and `b` are equal within the tolerance (two NaNs are equal; NaN and a number
    /// are not).
    pub fn accepts(&self, a: f32, b: f32) -> bool {
        if a.is_nan() || b.is_nan() {
            return a.is_nan() && b.is_nan();
        }
        (a - b).abs() <= self.absolute + self.relative * a.abs().max(b.abs())
    }
}

/// One pixel value that differs beyond the tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelDifference {
    /// Column.
    pub x: usize,
    /// Row (0 at the top).
    pub y: usize,
    /// The channel: `R`, `G`, `B`, `variance.R`, `variance.G` or `variance.B`.
    pub channel: &'static str,
    /// The expected (committed) value.
    pub expected: f32,
    /// The actual (regenerated) value.
    pub actual: f32,
}

/// How two goldens differ, if they do.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GoldenDiff {
    /// Differences that make the pixels incomparable (size, missing variance, different scene,
    /// hash, spp or seed attributes), one line each.
    pub structural: Vec<String>,
    /// Number of pixel values (pixel and channel) beyond the tolerance.
    pub values_differing: usize,
    /// Number of pixels with at least one channel beyond the tolerance.
    pub pixels_differing: usize,
    /// The value with the largest absolute difference.
    pub worst: Option<PixelDifference>,
}

impl GoldenDiff {
    /// Whether the goldens are equal within the tolerance.
    pub fn is_match(&self) -> bool {
        self.structural.is_empty() && self.values_differing == 0
    }

    /// A one-line account of the difference (or `"equal within tolerance"`).
    pub fn summary(&self, pixels: usize) -> String {
        if self.is_match() {
            return "equal within tolerance".to_string();
        }
        let mut parts = self.structural.clone();
        if self.values_differing > 0 {
            let mut s = format!(
                "{} of {pixels} pixels differ beyond tolerance ({} values)",
                self.pixels_differing, self.values_differing
            );
            if let Some(w) = &self.worst {
                s.push_str(&format!(
                    "; worst at x={} y={} {}: expected {}, got {} (difference {:e})",
                    w.x,
                    w.y,
                    w.channel,
                    w.expected,
                    w.actual,
                    (w.actual - w.expected).abs()
                ));
            }
            parts.push(s);
        }
        parts.join("; ")
    }
}

/// Attributes that must agree for two goldens to be the same golden (the tool version may
/// differ).
const IDENTITY_ATTRIBUTES: &[&str] = &[ATTR_SCENE, ATTR_SCENE_SHA256, ATTR_SPP, ATTR_SEED];

/// Compares `actual` with `expected` pixel by pixel (mean and variance) within `tolerance`,
/// and their identifying attributes (scene, scene hash, spp, seed) exactly.
pub fn compare_goldens(
    expected: &ExrImage,
    actual: &ExrImage,
    tolerance: &Tolerance,
) -> GoldenDiff {
    let mut diff = GoldenDiff::default();
    for name in IDENTITY_ATTRIBUTES {
        let (e, a) = (expected.attribute(name), actual.attribute(name));
        if e != a {
            diff.structural.push(format!(
                "{name} is {} but {} was expected",
                a.map_or("missing".to_string(), |v| format!("'{v}'")),
                e.map_or("none".to_string(), |v| format!("'{v}'")),
            ));
        }
    }
    if (expected.width, expected.height) != (actual.width, actual.height) {
        diff.structural.push(format!(
            "the size is {}x{} but {}x{} was expected",
            actual.width, actual.height, expected.width, expected.height
        ));
        return diff;
    }
    const MEAN: [&str; 3] = ["R", "G", "B"];
    const VARIANCE: [&str; 3] = ["variance.R", "variance.G", "variance.B"];
    // (expected values, actual values, channel names) per layer.
    type LayerPair<'a> = (&'a [[f32; 3]], &'a [[f32; 3]], [&'static str; 3]);
    let mut layers: Vec<LayerPair> = vec![(&expected.mean, &actual.mean, MEAN)];
    match (&expected.variance, &actual.variance) {
        (Some(e), Some(a)) => layers.push((e, a, VARIANCE)),
        (None, None) => {}
        (Some(_), None) => diff
            .structural
            .push("the variance layer is missing".to_string()),
        (None, Some(_)) => diff
            .structural
            .push("there is a variance layer where none was expected".to_string()),
    }
    let mut differing = vec![false; expected.width * expected.height];
    let mut worst_gap = -1.0f32;
    for (e, a, names) in layers {
        for (i, (pe, pa)) in e.iter().zip(a).enumerate() {
            for c in 0..3 {
                if !tolerance.accepts(pe[c], pa[c]) {
                    diff.values_differing += 1;
                    differing[i] = true;
                    let gap = (pe[c] - pa[c]).abs();
                    let gap = if gap.is_nan() { f32::INFINITY } else { gap };
                    if gap > worst_gap {
                        worst_gap = gap;
                        diff.worst = Some(PixelDifference {
                            x: i % expected.width,
                            y: i / expected.width,
                            channel: names[c],
                            expected: pe[c],
                            actual: pa[c],
                        });
                    }
                }
            }
        }
    }
    diff.pixels_differing = differing.iter().filter(|d| **d).count();
    diff
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> ExrImage {
        ExrImage {
            width: values.len(),
            height: 1,
            mean: values.iter().map(|&v| [v, v, v]).collect(),
            variance: Some(values.iter().map(|&v| [v * v, 0.0, 0.0]).collect()),
            attributes: vec![(ATTR_SCENE.to_string(), "s".to_string())],
        }
    }

    #[test]
    fn tolerance_accepts_last_bits_and_rejects_one_sample_in_4096() {
        let t = Tolerance::default();
        let x = 0.7f32;
        assert!(t.accepts(x, f32::from_bits(x.to_bits() + 3)));
        // One of 4096 samples changing colour by 0.05 moves the mean by 1.2e-5.
        assert!(!t.accepts(x, x + 0.05 / 4096.0));
        assert!(t.accepts(f32::NAN, f32::NAN));
        assert!(!t.accepts(f32::NAN, 0.0));
        assert!(t.accepts(0.0, 0.0));
    }

    #[test]
    fn compare_reports_the_worst_pixel() {
        let e = image(&[0.1, 0.2, 0.3, 0.4]);
        let mut a = e.clone();
        a.mean[2][1] = 0.35;
        a.mean[3][0] = 0.401;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert!(!d.is_match());
        assert_eq!((d.pixels_differing, d.values_differing), (2, 2));
        let w = d.worst.unwrap();
        assert_eq!((w.x, w.y, w.channel), (2, 0, "G"));
        assert_eq!((w.expected, w.actual), (0.3, 0.35));
        assert!(compare_goldens(&e, &e, &Tolerance::default()).is_match());
    }

    #[test]
    fn compare_checks_variance_size_and_identity() {
        let e = image(&[0.1, 0.2]);
        let mut a = e.clone();
        a.variance.as_mut().unwrap()[1][0] = 1.0;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(d.worst.unwrap().channel, "variance.R");

        let mut a = e.clone();
        a.variance = None;
        assert!(!compare_goldens(&e, &a, &Tolerance::default()).is_match());

        let mut a = e.clone();
        a.attributes[0].1 = "other".into();
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(
            d.structural,
            ["rtoracle.scene is 'other' but 's' was expected"]
        );

        let a = image(&[0.1, 0.2, 0.3]);
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert!(
            d.summary(2)
                .contains("the size is 3x1 but 2x1 was expected")
        );
    }

    fn tiny_scene(radius: f64) -> SceneDescription {
        let mut d = builtin("week04-sphere").unwrap();
        d.image.width = 8;
        if let crate::scene::ObjectEntry::Sphere { radius: r, .. } = &mut d.objects[1] {
            *r = radius;
        }
        d
    }

    #[test]
    fn the_cache_renders_each_golden_once_even_when_asked_concurrently() {
        let dir = tempfile::tempdir().unwrap();
        let d = tiny_scene(0.5);
        let results: Vec<CachedGolden> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| s.spawn(|| cached_golden_in(Some(dir.path()), &d, "tiny", 4, false)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap().unwrap())
                .collect()
        });
        assert_eq!(results.iter().filter(|r| r.rendered).count(), 1);
        let path = cache_file(dir.path(), &d, 4);
        assert!(
            results
                .iter()
                .all(|r| r.path.as_deref() == Some(path.as_path()))
        );
        let on_disk = std::fs::read(&path).unwrap();
        assert!(results.iter().all(|r| r.bytes == on_disk));
        // The file is the golden of this scene and of no other.
        assert!(golden_fits(&on_disk, &path, &d).is_ok());
        let other = tiny_scene(0.3);
        let e = golden_fits(&on_disk, &path, &other).unwrap_err();
        assert!(e.contains("another scene"), "{e}");
        let mut wider = d.clone();
        wider.image.width = 9;
        assert!(
            golden_fits(&on_disk, &path, &wider)
                .unwrap_err()
                .contains("is 8x")
        );
        // Another scene has another key; a corrupt cache file is rendered again.
        assert_ne!(cache_file(dir.path(), &other, 4), path);
        std::fs::write(&path, b"junk").unwrap();
        let again = cached_golden_in(Some(dir.path()), &d, "tiny", 4, false).unwrap();
        assert!(again.rendered);
        assert_eq!(again.bytes, on_disk);
        assert_eq!(std::fs::read(&path).unwrap(), on_disk);
    }

    #[test]
    fn scene_hash_is_sha256_of_the_toml() {
        // Published test vectors (FIPS 180-2): "" and "abc".
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let d = builtin("week04-quad").unwrap();
        let h = scene_sha256(&d);
        assert_eq!(h.len(), 64);
        assert_eq!(h, sha256_hex(d.to_toml().as_bytes()));
        assert_ne!(h, scene_sha256(&builtin("week04-sphere").unwrap()));
    }
}
