//! The golden as the noise model reads it: per pixel and channel the mean of `M` samples, their
//! per-sample variance, the largest distance of one of them from the mean (when the golden
//! recorded it), and a bound on how far one sample may lie from the mean.
//!
//! The bound is what Bernstein's inequality needs: how far a single sample of the candidate may
//! land from the golden's mean. Three standard deviations of the pixel and its neighbours cover
//! one-bounce colours; they do not cover a rare bright path (a specular lobe met by a scattered
//! ray, a bounce into a small light), whose probability is too small to show in the variance
//! but whose samples lie far away. The golden's measured deviations do: the pixel scale's bound
//! (`Golden::tail_bound`) takes the largest of them over a 5x5 neighbourhood, so a path the
//! golden saw once in the ~25 M samples around a pixel counts as possible there. The sums over
//! tiles and the image keep the edge-tolerant bound (`Golden::bound`): one rare sample moves a
//! sum of hundreds of pixels by a small share of its standard deviation, while the largest
//! bound of its terms, which Bernstein's inequality charges to the whole sum, would cost a
//! tile most of its power (a missing shadow in a 32x32 image of a point light passed with it).
//!
//! The goldens themselves (their files, the cache, how each scene gets one) are
//! [`crate::golden`]'s; [`Golden::of_scene`] reads the one [`crate::golden::golden_of`] gives.

use std::path::Path;

use super::CompareError;
use crate::golden::{ATTR_SPP, GoldenRecord, GoldenScene, golden_of, sha256_hex};
use crate::image_io::ExrImage;
use crate::render::Film;
use crate::scene::SceneDescription;

/// The scene a golden's attributes record: the TOML it holds (a scene file's golden), else the
/// built-in scene it names, when the recorded hash is that scene's.
pub fn recorded_scene(record: &GoldenRecord) -> Option<SceneDescription> {
    let want = record.scene_sha256.as_deref()?;
    if let Some(toml) = &record.scene_toml {
        let name = record.scene.as_deref().unwrap_or("the golden's scene");
        return (sha256_hex(toml.as_bytes()) == want)
            .then(|| SceneDescription::from_toml(toml, name).ok())
            .flatten();
    }
    let scene = GoldenScene::builtin(record.scene.as_deref()?).ok()?;
    (scene.scene_sha256() == want).then_some(scene.description)
}

/// How many standard deviations from the mean a golden's farthest sample must lie for its pixel
/// to count as heavy-tailed. The farthest of `M = 4096` samples of a light-tailed colour lies
/// about 3.5 to 4.5 of them away (a normal's largest of 4096 is about 3.5); a rare event seen
/// `k` times lies about `sqrt(M / k)` away (64 for one sample in 4096, 6 for 110). Below the
/// threshold the sample bound stays the edge-tolerant one, whose power a pattern mistake (a
/// texture's u and v swapped) needs at the pixel scale.
const HEAVY_TAIL: f64 = 6.0;

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
    /// The vertical field of view of the scene's camera in degrees, when known (the diagnosis
    /// names a zoom as a field of view).
    pub vfov: Option<f64>,
    /// Per pixel and channel, the largest distance of one of the golden's samples from its mean,
    /// when the golden recorded it (rtoracle's goldens do; an EXR of another renderer may not).
    pub deviation: Option<Vec<[f64; 3]>>,
    /// Per pixel and channel, a bound on how far one sample may lie from the mean: the largest
    /// `|mu_nb - mu| + 3 sd_nb` over the 3x3 neighbourhood, at most 1. Edge-tolerant: a pixel
    /// beside an edge may receive samples of the other side that the golden never drew. The
    /// sums over tiles and the image use it.
    pub(crate) bound: Vec<[f64; 3]>,
    /// [`Self::bound`] or the largest measured deviation over the 5x5 neighbourhood of the
    /// pixels with a heavy tail ([`HEAVY_TAIL`]), whichever is larger, at most 1: tail-tolerant too, a pixel may receive a rare bright sample its
    /// neighbours' samples show. The pixel scale uses it.
    pub(crate) tail_bound: Vec<[f64; 3]>,
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
            vfov: None,
            deviation: None,
            bound: Vec::new(),
            tail_bound: Vec::new(),
        };
        golden.bound = golden.neighbourhood_bound();
        golden.tail_bound = golden.bound.clone();
        Ok(golden)
    }

    /// The same golden with its samples' largest deviations from the mean known (`None`:
    /// unknown); they must be `width * height` finite values, not negative.
    pub fn with_deviation(
        mut self,
        deviation: Option<Vec<[f64; 3]>>,
    ) -> Result<Self, CompareError> {
        if let Some(d) = &deviation {
            if d.len() != self.mean.len() {
                return Err(CompareError::Golden(format!(
                    "a {}x{} golden needs {} deviations; it has {}",
                    self.width,
                    self.height,
                    self.mean.len(),
                    d.len()
                )));
            }
            if !d
                .iter()
                .all(|p| p.iter().all(|x| x.is_finite() && *x >= 0.0))
            {
                return Err(CompareError::Golden(
                    "the golden has a deviation that is not a finite distance".into(),
                ));
            }
        }
        self.tail_bound = match &deviation {
            Some(d) => self.with_tails(d),
            None => self.bound.clone(),
        };
        self.deviation = deviation;
        Ok(self)
    }

    /// The same golden with the camera's vertical field of view `vfov` (degrees) known.
    pub fn with_vfov(mut self, vfov: Option<f64>) -> Self {
        self.vfov = vfov;
        self
    }

    /// The golden of some of its rows only, stacked top to bottom in the order given: the
    /// golden a render of just those rows is judged against. Each pixel keeps its mean, variance
    /// and sample bound from the whole image (its neighbours in the scene, not in the stack);
    /// the field of view is dropped, since a stack of rows is not a camera's image. `Err` when a
    /// row is outside the image or none is given.
    pub fn rows(&self, rows: &[usize]) -> Result<Golden, CompareError> {
        if rows.is_empty() {
            return Err(CompareError::Golden(
                "no rows of the golden asked for".into(),
            ));
        }
        if let Some(&y) = rows.iter().find(|&&y| y >= self.height) {
            return Err(CompareError::Golden(format!(
                "row {y} is outside the {}x{} golden",
                self.width, self.height
            )));
        }
        let pick = |v: &[[f64; 3]]| -> Vec<[f64; 3]> {
            rows.iter()
                .flat_map(|&y| v[y * self.width..(y + 1) * self.width].iter().copied())
                .collect()
        };
        Ok(Golden {
            width: self.width,
            height: rows.len(),
            samples_per_pixel: self.samples_per_pixel,
            mean: pick(&self.mean),
            variance: pick(&self.variance),
            scene: self.scene.clone(),
            vfov: None,
            deviation: self.deviation.as_deref().map(pick),
            bound: pick(&self.bound),
            tail_bound: pick(&self.tail_bound),
        })
    }

    fn neighbourhood_bound(&self) -> Vec<[f64; 3]> {
        let sd: Vec<[f64; 3]> = self.variance.iter().map(|v| v.map(f64::sqrt)).collect();
        self.over_neighbours(1, |i, j, c| {
            (self.mean[j][c] - self.mean[i][c]).abs() + 3.0 * sd[j][c]
        })
    }

    /// [`Self::tail_bound`] from the measured deviations `d`: a neighbour's deviation counts
    /// when it shows a heavy tail, more than [`HEAVY_TAIL`] of its standard deviations.
    fn with_tails(&self, d: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let tails = self.over_neighbours(2, |_, j, c| {
            let heavy = d[j][c] > HEAVY_TAIL * self.variance[j][c].sqrt();
            if heavy { d[j][c] } else { 0.0 }
        });
        self.bound
            .iter()
            .zip(tails)
            .map(|(b, t)| [0, 1, 2].map(|c| b[c].max(t[c])))
            .collect()
    }

    /// Per pixel `i` and channel `c`, the largest `value(i, j, c)` over the pixels `j` within
    /// `radius` (a square, cut at the image's border), at most 1.
    fn over_neighbours(
        &self,
        radius: isize,
        value: impl Fn(usize, usize, usize) -> f64,
    ) -> Vec<[f64; 3]> {
        let (w, h) = (self.width as isize, self.height as isize);
        let mut out = vec![[0.0; 3]; self.mean.len()];
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let mut b = [0.0f64; 3];
                for ny in (y - radius).max(0)..=(y + radius).min(h - 1) {
                    for nx in (x - radius).max(0)..=(x + radius).min(w - 1) {
                        let j = (ny * w + nx) as usize;
                        for (c, b) in b.iter_mut().enumerate() {
                            *b = b.max(value(i, j, c));
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
        )?
        .with_deviation(
            film.deviation
                .as_ref()
                .map(|d| d.iter().map(|v| v.to_array()).collect()),
        )
    }

    /// A golden from an EXR file with a `variance` layer; `M` comes from its `rtoracle.spp`
    /// attribute. Errors name the file.
    pub fn from_exr(path: &Path) -> Result<Self, CompareError> {
        let image = crate::image_io::read_exr(path)?;
        Golden::from_exr_image(image, path)
    }

    /// A golden from an EXR already read (for instance one embedded in the binary); `source`
    /// names it in errors. The scene it records (the TOML it holds, or the built-in scene it
    /// names, when the hashes agree) gives its camera's field of view.
    pub fn from_exr_image(image: ExrImage, source: &Path) -> Result<Self, CompareError> {
        let bad = |message: String| CompareError::Input {
            path: source.to_path_buf(),
            message,
        };
        let record = GoldenRecord::of(&image);
        let spp = image.attribute(ATTR_SPP).ok_or_else(|| {
            bad(format!(
                "has no '{ATTR_SPP}' attribute (the golden's samples per pixel)"
            ))
        })?;
        let spp: u32 = spp
            .trim()
            .parse()
            .map_err(|_| bad(format!("its '{ATTR_SPP}' attribute '{spp}' is not a count")))?;
        let vfov = recorded_scene(&record).map(|d| d.camera.vfov);
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
            record.scene,
        )
        .and_then(|g| g.with_vfov(vfov).with_deviation(image.deviation.map(widen)))
        .map_err(|e| bad(e.to_string()))
    }

    /// The golden of `scene` for candidates of `candidate_spp` samples per pixel: the one
    /// [`golden_of`] gives with [`crate::golden::golden_spp`] samples, from the cache in
    /// `cache` (`progress`: a line and a bar on stderr when it is rendered), named after the
    /// scene as asked (a cached golden may carry the name of another file of the same content).
    pub fn of_scene(
        scene: &GoldenScene,
        candidate_spp: u32,
        cache: Option<&Path>,
        progress: bool,
    ) -> Result<Self, CompareError> {
        let spp = crate::golden::golden_spp(candidate_spp);
        let found = golden_of(scene, spp, cache, progress)
            .map_err(|e| CompareError::Golden(e.to_string()))?;
        let mut golden = Golden::from_exr_image(found.image, &found.source)?;
        golden.scene = Some(scene.name.clone());
        golden.vfov = Some(scene.description.camera.vfov);
        Ok(golden)
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
        .with_vfov(self.vfov)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample the golden saw once, 0.5 from the mean of pixel (3, 3) of a flat 7x7 golden
    /// (standard deviation 0.001 everywhere, so 500 of them: a heavy tail): the pixel scale's
    /// bound is 0.5 within two pixels of it (the 5x5 neighbourhood) and three standard
    /// deviations beyond; without the deviations, three standard deviations everywhere.
    #[test]
    fn a_measured_deviation_bounds_its_5x5_neighbourhood() {
        let n = 49;
        let flat = Golden::new(7, 7, 4096, vec![[0.1; 3]; n], vec![[1e-6; 3]; n], None).unwrap();
        let mut deviation = vec![[0.0; 3]; n];
        deviation[3 * 7 + 3] = [0.5, 0.0, 0.0];
        let seen = flat.clone().with_deviation(Some(deviation)).unwrap();
        for y in 0..7usize {
            for x in 0..7usize {
                let i = y * 7 + x;
                let near = x.abs_diff(3) <= 2 && y.abs_diff(3) <= 2;
                let red = if near { 0.5 } else { 0.003 };
                let what = format!("({x}, {y}) {:?}", seen.tail_bound[i]);
                assert!((seen.tail_bound[i][0] - red).abs() < 1e-12, "{what}");
                assert!((seen.tail_bound[i][1] - 0.003).abs() < 1e-12, "{what}");
                assert!((flat.tail_bound[i][0] - 0.003).abs() < 1e-12, "{what}");
                // The sums' bound stays the edge-tolerant one.
                assert!((seen.bound[i][0] - 0.003).abs() < 1e-12, "{what}");
            }
        }
        // A farthest sample 5 standard deviations away is a light tail: no change.
        let light = flat
            .clone()
            .with_deviation(Some(vec![[0.005; 3]; n]))
            .unwrap();
        assert_eq!(light.tail_bound, flat.bound);
        assert!(
            flat.clone()
                .with_deviation(Some(vec![[0.0; 3]; 48]))
                .is_err()
        );
        assert!(
            flat.clone()
                .with_deviation(Some(vec![[-0.1; 3]; 49]))
                .is_err()
        );
        assert!(flat.with_deviation(Some(vec![[f64::NAN; 3]; 49])).is_err());
    }

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
    fn the_bound_covers_the_neighbours_and_the_spread() {
        let g = tiny();
        // Pixel 0, red: |0 - 0.25| + 3 * sqrt(0.04) = 0.85 from its neighbour.
        assert!((g.bound[0][0] - 0.85).abs() < 1e-12);
        // Green: own spread 3 * 0.1 = 0.3 beats |0.1 - 0.5| = 0.4? No: 0.4 wins.
        assert!((g.bound[0][1] - 0.4).abs() < 1e-12);
    }

    #[test]
    fn a_golden_of_rows_keeps_each_pixel_as_the_whole_image_has_it() {
        // Three rows of one pixel: 0.1, 0.5, 0.9, with variances 0.01, 0.04, 0.09.
        let g = Golden::new(
            1,
            3,
            16,
            vec![[0.1; 3], [0.5; 3], [0.9; 3]],
            vec![[0.01; 3], [0.04; 3], [0.09; 3]],
            None,
        )
        .unwrap();
        let r = g.rows(&[2, 0]).unwrap();
        assert_eq!((r.width, r.height), (1, 2));
        assert_eq!(r.mean, vec![[0.9; 3], [0.1; 3]]);
        assert_eq!(r.variance, vec![[0.09; 3], [0.01; 3]]);
        // Row 0's bound is its neighbour's (row 1): |0.5 - 0.1| + 3 * 0.2 = 1.0 (at most 1),
        // not what rows 2 and 0 stacked side by side would give.
        assert_eq!(r.bound[1], g.bound[0]);
        assert_eq!(r.bound[0], g.bound[2]);
        assert!(g.rows(&[3]).is_err());
        assert!(g.rows(&[]).is_err());
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
            deviation: None,
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
    fn the_course_goldens_serve_20_spp_candidates() {
        for scene in ["week04-sphere", "week04-quad"] {
            let g = Golden::of_scene(&GoldenScene::builtin(scene).unwrap(), 20, None, false)
                .expect("embedded");
            assert_eq!(g.samples_per_pixel, 4096);
            assert_eq!(g.scene.as_deref(), Some(scene));
            let camera = crate::scene::builtin(scene).unwrap().camera(None);
            assert_eq!((g.width, g.height), (camera.width, camera.height));
        }
    }
}
