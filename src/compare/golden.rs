//! Goldens: the reference's per-pixel mean and per-sample variance at many samples per pixel.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::CompareError;
use crate::image_io::ExrImage;
use crate::render::{Film, RenderOptions, render};
use crate::scene::SceneDescription;

/// The seed goldens are rendered with (distinct from any seed a test renders a candidate with).
pub const GOLDEN_SEED: u64 = 0x676f_6c64_656e;

/// Samples per pixel of a golden for candidates with `candidate_spp`: `max(4096, 100 N)`.
pub fn golden_spp(candidate_spp: u32) -> u32 {
    4096u32.max(candidate_spp.saturating_mul(100))
}

/// A golden image: per pixel and channel the mean of `samples_per_pixel` samples and their
/// per-sample variance, plus what the comparison derives from them.
#[derive(Clone, Debug, PartialEq)]
pub struct Golden {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Samples per pixel `M` of the golden.
    pub samples_per_pixel: u32,
    /// Mean linear RGB, row-major, top row first.
    pub mean: Vec<[f64; 3]>,
    /// Per-sample variance of each channel.
    pub variance: Vec<[f64; 3]>,
    /// The scene's name, when known.
    pub scene: Option<String>,
    /// Per pixel and channel, a bound on how far one sample may lie from the mean: the largest
    /// `|mu_nb - mu| + 3 sd_nb` over the 3x3 neighbourhood, at most 1. Edge-tolerant: a pixel
    /// beside an edge may receive samples of the other side that the golden never drew.
    pub(crate) bound: Vec<[f64; 3]>,
}

impl Golden {
    /// A golden from its parts; the mean and variance must have `width * height` finite entries.
    pub fn new(
        width: usize,
        height: usize,
        samples_per_pixel: u32,
        mean: Vec<[f64; 3]>,
        variance: Vec<[f64; 3]>,
        scene: Option<String>,
    ) -> Result<Self, CompareError> {
        let n = width * height;
        if n == 0 || mean.len() != n || variance.len() != n {
            return Err(CompareError::Golden(format!(
                "a {width}x{height} golden needs {n} pixels; it has {} means and {} variances",
                mean.len(),
                variance.len()
            )));
        }
        if samples_per_pixel < 2 {
            return Err(CompareError::Golden(
                "a golden needs at least 2 samples per pixel".into(),
            ));
        }
        let finite = |v: &[[f64; 3]]| v.iter().all(|p| p.iter().all(|x| x.is_finite()));
        if !finite(&mean) || !finite(&variance) {
            return Err(CompareError::Golden(
                "the golden has a NaN or infinite value".into(),
            ));
        }
        let mut golden = Golden {
            width,
            height,
            samples_per_pixel,
            mean,
            variance: variance
                .into_iter()
                .map(|v| v.map(|x| x.max(0.0)))
                .collect(),
            scene,
            bound: Vec::new(),
        };
        golden.bound = golden.neighbourhood_bound();
        Ok(golden)
    }

    fn neighbourhood_bound(&self) -> Vec<[f64; 3]> {
        let (w, h) = (self.width as isize, self.height as isize);
        let sd: Vec<[f64; 3]> = self.variance.iter().map(|v| v.map(f64::sqrt)).collect();
        let mut out = vec![[0.0; 3]; self.mean.len()];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let mu = self.mean[i];
                let mut b = [0.0f64; 3];
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= w || ny >= h {
                            continue;
                        }
                        let j = (ny * w + nx) as usize;
                        for c in 0..3 {
                            let v = (self.mean[j][c] - mu[c]).abs() + 3.0 * sd[j][c];
                            b[c] = b[c].max(v);
                        }
                    }
                }
                out[i] = b.map(|v| v.min(1.0));
            }
        }
        out
    }

    /// A golden from a film rendered with `variance: true`.
    pub fn from_film(film: &Film, scene: Option<String>) -> Result<Self, CompareError> {
        let variance = film.variance.as_ref().ok_or_else(|| {
            CompareError::Golden("the film was rendered without its variance".into())
        })?;
        Golden::new(
            film.width,
            film.height,
            film.samples_per_pixel,
            film.mean.iter().map(|m| m.to_array()).collect(),
            variance.iter().map(|v| v.to_array()).collect(),
            scene,
        )
    }

    /// A golden from an EXR file with a `variance` layer; `M` comes from its `rtoracle.spp`
    /// attribute. Errors name the file.
    pub fn from_exr(path: &Path) -> Result<Self, CompareError> {
        let image = crate::image_io::read_exr(path)?;
        Golden::from_exr_image(image, path)
    }

    /// A golden from an EXR already read (for instance one embedded in the binary); `source`
    /// names it in errors.
    pub fn from_exr_image(image: ExrImage, source: &Path) -> Result<Self, CompareError> {
        let bad = |message: String| CompareError::Input {
            path: source.to_path_buf(),
            message,
        };
        let attribute = |name: &str| {
            image
                .attributes
                .iter()
                .find(|(k, _)| k == name)
                .map(|(_, v)| v.clone())
        };
        let spp = attribute("rtoracle.spp").ok_or_else(|| {
            bad("has no 'rtoracle.spp' attribute (the golden's samples per pixel)".into())
        })?;
        let spp: u32 = spp.trim().parse().map_err(|_| {
            bad(format!(
                "its 'rtoracle.spp' attribute '{spp}' is not a count"
            ))
        })?;
        let scene = attribute("rtoracle.scene");
        let variance = image
            .variance
            .ok_or_else(|| bad("has no 'variance' layer, so it cannot serve as a golden".into()))?;
        let widen = |v: Vec<[f32; 3]>| -> Vec<[f64; 3]> {
            v.into_iter().map(|p| p.map(f64::from)).collect()
        };
        Golden::new(
            image.width,
            image.height,
            spp,
            widen(image.mean),
            widen(variance),
            scene,
        )
        .map_err(|e| bad(e.to_string()))
    }

    /// Renders the golden of a scene with `spp` samples per pixel and [`GOLDEN_SEED`].
    pub fn render(
        description: &SceneDescription,
        name: &str,
        spp: u32,
        progress: bool,
    ) -> Result<Self, CompareError> {
        let options = RenderOptions {
            samples_per_pixel: spp,
            seed: GOLDEN_SEED,
            variance: true,
            progress,
            ..Default::default()
        };
        let film = render(&description.scene(), &description.camera(None), &options)
            .map_err(|e| CompareError::Golden(e.to_string()))?;
        Golden::from_film(&film, Some(name.to_string()))
    }

    /// The golden seen through a camera shifted by half a pixel along both axes (`sign` +1:
    /// right and down, -1: left and up): each pixel becomes the mixture of the four pixels it
    /// straddles. An approximation used only by the diagnosis.
    pub fn half_pixel_shifted(&self, sign: i32) -> Golden {
        let (w, h) = (self.width as isize, self.height as isize);
        let s = if sign >= 0 { 1 } else { -1 };
        let mut mean = Vec::with_capacity(self.mean.len());
        let mut variance = Vec::with_capacity(self.mean.len());
        for y in 0..h {
            for x in 0..w {
                let idx = |dx: isize, dy: isize| {
                    let nx = (x + dx * s).clamp(0, w - 1);
                    let ny = (y + dy * s).clamp(0, h - 1);
                    (ny * w + nx) as usize
                };
                let quads = [idx(0, 0), idx(1, 0), idx(0, 1), idx(1, 1)];
                let mut m = [0.0; 3];
                let mut v = [0.0; 3];
                for c in 0..3 {
                    let mus = quads.map(|q| self.mean[q][c]);
                    let avg = mus.iter().sum::<f64>() / 4.0;
                    let spread = mus.iter().map(|u| (u - avg).powi(2)).sum::<f64>() / 4.0;
                    m[c] = avg;
                    v[c] = quads.iter().map(|&q| self.variance[q][c]).sum::<f64>() / 4.0 + spread;
                }
                mean.push(m);
                variance.push(v);
            }
        }
        Golden::new(
            self.width,
            self.height,
            self.samples_per_pixel,
            mean,
            variance,
            self.scene.clone(),
        )
        .expect("a shifted golden has the same size and finite values")
    }

    /// The golden in rtoracle's cache format: a header line, then width, height and `M` as
    /// little-endian `u32`, then the means and variances as little-endian `f32` (as in an EXR).
    pub fn to_cache_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(32 + self.mean.len() * 24);
        out.extend_from_slice(CACHE_MAGIC);
        for v in [
            self.width as u32,
            self.height as u32,
            self.samples_per_pixel,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for layer in [&self.mean, &self.variance] {
            for p in layer.iter() {
                for x in p {
                    out.extend_from_slice(&(*x as f32).to_le_bytes());
                }
            }
        }
        out
    }

    /// Reads [`Golden::to_cache_bytes`]'s format.
    pub fn from_cache_bytes(bytes: &[u8], scene: Option<String>) -> Result<Self, CompareError> {
        let bad = || CompareError::Golden("the cached golden is corrupt".into());
        let rest = bytes.strip_prefix(CACHE_MAGIC).ok_or_else(bad)?;
        if rest.len() < 12 {
            return Err(bad());
        }
        let word = |i: usize| u32::from_le_bytes(rest[4 * i..4 * i + 4].try_into().unwrap());
        let (w, h, m) = (word(0) as usize, word(1) as usize, word(2));
        let n = w.checked_mul(h).ok_or_else(bad)?;
        let body = &rest[12..];
        if body.len() != n * 24 {
            return Err(bad());
        }
        let floats: Vec<f64> = body
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect();
        let layer = |k: usize| -> Vec<[f64; 3]> {
            floats[k * 3 * n..(k + 1) * 3 * n]
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect()
        };
        Golden::new(w, h, m, layer(0), layer(1), scene)
    }
}

const CACHE_MAGIC: &[u8] = b"rtoracle golden cache v1\n";

/// The folder goldens are cached in: `$RTORACLE_CACHE_DIR`, else `$XDG_CACHE_HOME/rtoracle`,
/// else `~/.cache/rtoracle`.
pub fn cache_dir() -> Option<PathBuf> {
    crate::golden::cache_dir()
}

/// The cache file of a scene's golden: keyed by the scene's content, `M`, the seed and the tool
/// version, so a change to any of them renders a new golden.
pub fn cache_path(dir: &Path, name: &str, description: &SceneDescription, spp: u32) -> PathBuf {
    let mut hasher = Sha256::new();
    hasher.update(description.to_toml().as_bytes());
    hasher.update(format!(
        "\nspp={spp}\nseed={GOLDEN_SEED}\nversion={}\n",
        env!("CARGO_PKG_VERSION")
    ));
    let digest = hasher.finalize();
    let hex: String = digest[..8].iter().map(|b| format!("{b:02x}")).collect();
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    dir.join(format!("golden-{safe}-{spp}spp-{hex}.bin"))
}

/// The golden compiled into the binary for the built-in scene `name`, when there is one, it was
/// made from the scene as it is now (its `rtoracle.sceneSha256` attribute), and it has at least
/// `spp` samples per pixel.
pub fn embedded_golden(name: &str, spp: u32) -> Option<Golden> {
    let description = crate::scene::builtin(name).ok()?;
    let image = crate::golden::embedded_golden_image(name)?;
    let made_from = image.attribute(crate::golden::ATTR_SCENE_SHA256)?;
    if made_from != crate::golden::scene_sha256(&description) {
        return None;
    }
    let label = format!(
        "(embedded) golden/{}",
        crate::golden::golden_file_name(name)
    );
    let golden = Golden::from_exr_image(image, Path::new(&label)).ok()?;
    (golden.samples_per_pixel >= spp).then_some(golden)
}

/// The golden of the built-in scene `name` for candidates with `candidate_spp` samples per
/// pixel (`M >= max(4096, 100 N)`): the one embedded in the binary when it is good enough,
/// else read from the cache, else rendered once (with a progress bar) and cached atomically.
pub fn golden_for_scene(name: &str, candidate_spp: u32) -> Result<Golden, CompareError> {
    let description =
        crate::scene::builtin(name).map_err(|e| CompareError::Golden(e.to_string()))?;
    let spp = golden_spp(candidate_spp);
    if let Some(golden) = embedded_golden(name, spp) {
        return Ok(golden);
    }
    let cached = cache_dir().map(|d| cache_path(&d, name, &description, spp));
    if let Some(path) = &cached {
        if let Ok(bytes) = std::fs::read(path) {
            if let Ok(g) = Golden::from_cache_bytes(&bytes, Some(name.to_string())) {
                return Ok(g);
            }
        }
    }
    crate::output::stderr_line(&format!(
        "rendering the golden of {name} at {spp} spp (once; it is cached)"
    ));
    let golden = Golden::render(&description, name, spp, true)?;
    if let Some(path) = &cached {
        // A cache that cannot be written costs time, not correctness.
        if let Some(dir) = path.parent() {
            let _ = std::fs::create_dir_all(dir);
        }
        let _ = crate::image_io::write_atomically(path, &golden.to_cache_bytes());
    }
    Ok(golden)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> Golden {
        Golden::new(
            2,
            1,
            16,
            vec![[0.25, 0.5, 1.0], [0.0, 0.1, 0.2]],
            vec![[0.0, 0.01, 0.0], [0.04, 0.0, 0.0]],
            None,
        )
        .unwrap()
    }

    #[test]
    fn cache_bytes_round_trip_through_f32() {
        let g = tiny();
        let back = Golden::from_cache_bytes(&g.to_cache_bytes(), None).unwrap();
        // Every value above is exact in f32 except 0.1, 0.2 and 0.01.
        for (a, b) in g.mean.iter().zip(&back.mean) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= a[c] * 1e-7);
            }
        }
        assert_eq!(
            (back.width, back.height, back.samples_per_pixel),
            (2, 1, 16)
        );
        let mut bytes = g.to_cache_bytes();
        bytes.pop();
        assert!(Golden::from_cache_bytes(&bytes, None).is_err());
    }

    #[test]
    fn the_bound_covers_the_neighbours_and_the_spread() {
        let g = tiny();
        // Pixel 0, red: |0 - 0.25| + 3 * sqrt(0.04) = 0.85 from its neighbour.
        assert!((g.bound[0][0] - 0.85).abs() < 1e-12);
        // Green: own spread 3 * 0.1 = 0.3 beats |0.1 - 0.5| = 0.4? No: 0.4 wins.
        assert!((g.bound[0][1] - 0.4).abs() < 1e-12);
    }

    #[test]
    fn wrong_sizes_and_nan_are_rejected() {
        assert!(Golden::new(2, 2, 16, vec![[0.0; 3]; 3], vec![[0.0; 3]; 4], None).is_err());
        assert!(Golden::new(1, 1, 16, vec![[f64::NAN; 3]], vec![[0.0; 3]], None).is_err());
    }

    #[test]
    fn exr_goldens_need_variance_and_their_sample_count() {
        let image = |variance: bool, spp: Option<&str>| ExrImage {
            width: 1,
            height: 1,
            mean: vec![[0.5; 3]],
            variance: variance.then(|| vec![[0.01; 3]]),
            attributes: spp
                .map(|s| vec![("rtoracle.spp".to_string(), s.to_string())])
                .unwrap_or_default(),
        };
        let src = Path::new("g.exr");
        let g = Golden::from_exr_image(image(true, Some("4096")), src).unwrap();
        assert_eq!(g.samples_per_pixel, 4096);
        for (img, needle) in [
            (image(false, Some("4096")), "variance"),
            (image(true, None), "rtoracle.spp"),
            (image(true, Some("many")), "not a count"),
        ] {
            let e = Golden::from_exr_image(img, src).unwrap_err().to_string();
            assert!(e.starts_with("g.exr: ") && e.contains(needle), "{e}");
        }
    }

    #[test]
    fn the_cache_key_follows_the_scene_and_the_sample_count() {
        let dir = Path::new("/cache");
        let d = crate::scene::builtin("week04-sphere").unwrap();
        let a = cache_path(dir, "week04-sphere", &d, 4096);
        assert_eq!(a, cache_path(dir, "week04-sphere", &d, 4096));
        assert_ne!(a, cache_path(dir, "week04-sphere", &d, 8192));
        let mut moved = d.clone();
        moved.objects.pop();
        assert_ne!(a, cache_path(dir, "week04-sphere", &moved, 4096));
        assert!(a.starts_with(dir));
    }

    #[test]
    fn the_course_goldens_are_embedded_at_4096_spp() {
        for scene in ["week04-sphere", "week04-quad"] {
            let g = embedded_golden(scene, golden_spp(20)).expect("embedded");
            assert_eq!(g.samples_per_pixel, 4096);
            assert_eq!(g.scene.as_deref(), Some(scene));
            let camera = crate::scene::builtin(scene).unwrap().camera(None);
            assert_eq!((g.width, g.height), (camera.width, camera.height));
            // Candidates with more than 40 spp need a golden with more samples than embedded.
            assert!(embedded_golden(scene, golden_spp(41)).is_none());
        }
    }

    #[test]
    fn golden_spp_follows_the_rule() {
        assert_eq!(golden_spp(20), 4096);
        assert_eq!(golden_spp(100), 10_000);
    }
}
