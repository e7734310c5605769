//! Two renders of the same scene compared with no golden (`rtoracle compare A B`), and a set of
//! renders against an exact value (the physics checks' furnace scenes): Welch's two-sample test
//! at the same four scales as the comparison against a golden, with the same family-wise
//! false-alarm rate and the same report.
//!
//! Each side ([`Side`]) gives, per pixel and channel, a mean, the variance of that mean and its
//! degrees of freedom: from one EXR with a `variance` layer (the per-sample variance over the
//! `rtoracle.spp` samples: the mean's variance is it over `spp`, with `spp - 1` degrees of
//! freedom), or from several renders with different seeds (their average, the sample variance
//! of their means over their number, with one degree of freedom fewer than renders), or an exact
//! value (variance 0). At each scale (pixel, 8x8 and 32x32 tiles, the whole image) the
//! difference of the sums over a unit is divided by the square root of the sum of the variances
//! and judged by Student's t with Welch-Satterthwaite's degrees of freedom ("Detecting bias in
//! Monte Carlo renderers using Welch's t-test", Jung, Hanika, Dachsbacher, JCGT 2020); each
//! scale gets a quarter of the per-image rate and Šidák's adjustment over its tests, as
//! [`super::verdict`] does.
//!
//! At the pixel scale each pixel's variance is at least its 3x3 neighbourhood's average (a few
//! renders' estimate can be 0 beside an edge); the tiles and the image sum the variances as
//! estimated (a sum of unbiased estimates, whose few degrees of freedom Welch-Satterthwaite's
//! formula counts), so the floor does not make them conservative. A variance of 0 on both sides
//! (a pixel that sees only a flat background) is given a floor of float rounding,
//! `(2^-20 max(|a|, |b|) + 1e-9)^2`, so that exactly equal values pass and any real difference
//! fails; over a tile or the image the pixels' floors add before they are squared (rounding in
//! an f32 renderer leans the same way in every pixel, so it does not average away: Mitsuba 3's
//! film is 6.7e-7 of the value off the exact light in every pixel that sees it).

use std::path::{Path, PathBuf};

use statrs::distribution::{ContinuousCDF, StudentsT};

use super::stats::sidak;
use super::{CompareError, Comparison, Region, ScaleResult, Verdict};
use crate::image_io::ExrImage;

/// One side of a two-sample comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct Side {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Mean linear RGB per pixel.
    pub mean: Vec<[f64; 3]>,
    /// The variance of each mean.
    pub variance: Vec<[f64; 3]>,
    /// Degrees of freedom of the variances (infinite for an exact value).
    pub dof: f64,
    /// Samples per pixel behind each mean (renders times their spp), when known.
    pub spp: u32,
    /// Renders behind it (1 for an EXR with a variance layer, 0 for an exact value).
    pub renders: usize,
    /// What it is, for the report.
    pub label: String,
}

fn input_error(path: &Path, message: impl Into<String>) -> CompareError {
    CompareError::Input {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

impl Side {
    /// An exact image: every pixel `value`, no variance.
    pub fn exact(width: usize, height: usize, value: [f64; 3], label: &str) -> Side {
        Side {
            width,
            height,
            mean: vec![value; width * height],
            variance: vec![[0.0; 3]; width * height],
            dof: f64::INFINITY,
            spp: 0,
            renders: 0,
            label: label.to_string(),
        }
    }

    /// Several renders of the same size with independent seeds (at least two), each at `spp`.
    pub fn from_renders(
        width: usize,
        height: usize,
        renders: &[Vec<[f32; 3]>],
        spp: u32,
        label: &str,
    ) -> Side {
        let k = renders.len().max(1) as f64;
        let mut mean = vec![[0.0; 3]; width * height];
        let mut variance = vec![[0.0; 3]; width * height];
        for (i, (m, v)) in mean.iter_mut().zip(variance.iter_mut()).enumerate() {
            for c in 0..3 {
                let avg = renders.iter().map(|r| f64::from(r[i][c])).sum::<f64>() / k;
                let ss: f64 = renders
                    .iter()
                    .map(|r| (f64::from(r[i][c]) - avg).powi(2))
                    .sum();
                m[c] = avg;
                v[c] = ss / (k - 1.0).max(1.0) / k;
            }
        }
        Side {
            width,
            height,
            mean,
            variance,
            dof: k - 1.0,
            spp: spp.saturating_mul(renders.len() as u32),
            renders: renders.len(),
            label: label.to_string(),
        }
    }

    /// A side from EXR files: one with a `variance` layer and an `rtoracle.spp` attribute, or
    /// several (each a render with its own seed).
    pub fn from_exrs(images: &[(PathBuf, ExrImage)], label: &str) -> Result<Side, CompareError> {
        let Some((first_path, first)) = images.first() else {
            return Err(input_error(Path::new(label), "no EXR render given"));
        };
        let (width, height) = (first.width, first.height);
        for (path, image) in images {
            if (image.width, image.height) != (width, height) {
                return Err(input_error(
                    path,
                    format!(
                        "is {}x{} but {} is {width}x{height}",
                        image.width,
                        image.height,
                        first_path.display()
                    ),
                ));
            }
        }
        if images.len() == 1 {
            let Some(var) = &first.variance else {
                return Err(input_error(
                    first_path,
                    "one render without a variance layer cannot show its noise: give a folder of \
                     several renders with different seeds, or render with --variance",
                ));
            };
            let spp: u32 = first
                .attribute("rtoracle.spp")
                .and_then(|s| s.parse().ok())
                .filter(|&n| n >= 2)
                .ok_or_else(|| {
                    input_error(
                        first_path,
                        "has a variance layer but no rtoracle.spp attribute of at least 2 (the \
                         samples behind each mean)",
                    )
                })?;
            return Ok(Side {
                width,
                height,
                mean: first.mean.iter().map(|p| p.map(f64::from)).collect(),
                variance: var
                    .iter()
                    .map(|p| p.map(|v| f64::from(v).max(0.0) / f64::from(spp)))
                    .collect(),
                dof: f64::from(spp) - 1.0,
                spp,
                renders: 1,
                label: label.to_string(),
            });
        }
        for (j, (path, image)) in images.iter().enumerate() {
            if let Some((same, _)) = images[..j].iter().find(|(_, o)| o.mean == image.mean) {
                return Err(input_error(
                    path,
                    format!(
                        "is the same render as {} (the same seed?): the renders of a side need \
                         different seeds",
                        same.display()
                    ),
                ));
            }
        }
        let spp = first
            .attribute("rtoracle.spp")
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        let renders: Vec<Vec<[f32; 3]>> = images.iter().map(|(_, i)| i.mean.clone()).collect();
        Ok(Side::from_renders(width, height, &renders, spp, label))
    }
}

/// Two-sided p-value of Student's t with `dof` degrees of freedom (the normal's past 1e7).
pub fn t_two_sided(t: f64, dof: f64) -> f64 {
    if t.is_nan() {
        return 0.0;
    }
    let t = t.abs();
    if !dof.is_finite() || dof > 1e7 {
        return libm::erfc(t / std::f64::consts::SQRT_2).min(1.0);
    }
    match StudentsT::new(0.0, 1.0, dof.max(1e-3)) {
        Ok(d) => (2.0 * d.sf(t)).min(1.0),
        Err(_) => 0.0,
    }
}

/// The sums of a unit (a pixel, a tile, the image) for one channel.
#[derive(Clone, Copy, Default)]
struct Sums {
    diff: f64,
    var: f64,
    /// Welch-Satterthwaite's denominator: `sum vA^2 / nuA + vB^2 / nuB`.
    welch: f64,
    floor: f64,
}

impl Sums {
    fn add(&mut self, a: f64, va: f64, b: f64, vb: f64, (na, nb): (f64, f64)) {
        self.diff += a - b;
        self.var += va + vb;
        let w = |v: f64, n: f64| {
            if n.is_finite() && n > 0.0 {
                v * v / n
            } else {
                0.0
            }
        };
        self.welch += w(va, na) + w(vb, nb);
        // Systematic, not independent: an f32 renderer's rounding (its film's weights, its
        // constants) leans the same way in every pixel of a flat region, so it is added, not
        // added in quadrature, and does not average away over a tile.
        self.floor += a.abs().max(b.abs()) * (1.0 / (1u64 << 20) as f64) + 1e-9;
    }

    /// The signed t and its two-sided p.
    fn test(&self) -> (f64, f64) {
        let var = self.var + self.floor * self.floor;
        let t = self.diff / var.sqrt();
        let dof = if self.welch > 0.0 {
            self.var * self.var / self.welch
        } else {
            f64::INFINITY
        };
        (t, t_two_sided(t, dof))
    }
}

/// Each pixel's variance, at least the average of its 3x3 neighbourhood's: an estimate from a
/// few renders (or a pixel whose samples all agreed) can be 0 beside an edge where the
/// neighbours show the noise an honest render has there; one that is 0 over the whole
/// neighbourhood (a flat region) stays 0 and is decided up to rounding.
fn neighbourhood(side: &Side) -> Vec<[f64; 3]> {
    let (w, h) = (side.width, side.height);
    let mut out = side.variance.clone();
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0; 3];
            let mut n = 0.0;
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    for (s, v) in sum.iter_mut().zip(side.variance[yy * w + xx]) {
                        *s += v;
                    }
                    n += 1.0;
                }
            }
            for c in 0..3 {
                out[y * w + x][c] = out[y * w + x][c].max(sum[c] / n);
            }
        }
    }
    out
}

/// The scales, as the comparison against a golden has them: `(name, tile side)`; 0 is the whole
/// image.
const SCALES: [(&str, usize); 4] = [("pixel", 1), ("tile8", 8), ("tile32", 32), ("global", 0)];

/// Compares `a` with `b` at the per-image false-alarm rate `alpha`: the report of
/// [`super::compare_image`]'s kind, `a` in the candidate's place and `b` in the golden's.
pub fn compare_two(a: &Side, b: &Side, alpha: f64) -> Result<Comparison, CompareError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(input_error(
            Path::new(&b.label),
            format!(
                "is {}x{} but {} is {}x{}: two renders of the same scene have the same size",
                b.width, b.height, a.label, a.width, a.height
            ),
        ));
    }
    let (w, h) = (a.width, a.height);
    let dofs = (a.dof, b.dof);
    let (va, vb) = (neighbourhood(a), neighbourhood(b));
    let threshold = alpha / 4.0;
    let mut scales = Vec::new();
    let mut regions = Vec::new();
    let mut z_map = vec![[0.0f32; 3]; w * h];
    for (name, side) in SCALES {
        let (tw, th) = if side == 0 { (w, h) } else { (side, side) };
        let units_x = w.div_ceil(tw);
        let units_y = h.div_ceil(th);
        let tests = (units_x * units_y * 3) as f64;
        let mut result = ScaleResult {
            scale: name.to_string(),
            tests: tests as usize,
            smallest_adjusted_p: 1.0,
            threshold,
            largest_abs_z: 0.0,
            failing: 0,
        };
        for uy in 0..units_y {
            for ux in 0..units_x {
                let (x0, y0) = (ux * tw, uy * th);
                let (x1, y1) = ((x0 + tw).min(w), (y0 + th).min(h));
                let mut worst: Option<(f64, f64, usize)> = None;
                for c in 0..3 {
                    let mut s = Sums::default();
                    for y in y0..y1 {
                        for x in x0..x1 {
                            let i = y * w + x;
                            let (vai, vbi) = if side == 1 {
                                (va[i][c], vb[i][c])
                            } else {
                                (a.variance[i][c], b.variance[i][c])
                            };
                            s.add(a.mean[i][c], vai, b.mean[i][c], vbi, dofs);
                        }
                    }
                    let (t, p) = s.test();
                    if side == 1 {
                        z_map[y0 * w + x0][c] = t.clamp(-1000.0, 1000.0) as f32;
                    }
                    let adjusted = sidak(p, tests);
                    result.smallest_adjusted_p = result.smallest_adjusted_p.min(adjusted);
                    result.largest_abs_z = result.largest_abs_z.max(t.abs());
                    if adjusted < threshold {
                        result.failing += 1;
                        if worst.is_none_or(|(p0, _, _)| adjusted < p0) {
                            worst = Some((adjusted, t, c));
                        }
                    }
                }
                if let Some((p, t, c)) = worst {
                    regions.push(Region {
                        x: x0,
                        y: y0,
                        width: x1 - x0,
                        height: y1 - y0,
                        scale: name.to_string(),
                        channel: ["R", "G", "B"][c].to_string(),
                        adjusted_p: p,
                        z: t,
                        change: None,
                    });
                }
            }
        }
        scales.push(result);
    }
    let passed = scales.iter().all(|s| s.failing == 0);
    let regions_total = regions.len();
    let ranked = super::regions::rank(regions, &z_map, (w, h), 50);
    let n = (w * h) as f64;
    let mut bias = [0.0; 3];
    let mut rel_mse = 0.0;
    for (pa, pb) in a.mean.iter().zip(&b.mean) {
        for c in 0..3 {
            bias[c] += (pa[c] - pb[c]) / n;
            rel_mse += super::stats::rel_mse_term(pa[c], pb[c]) / (3.0 * n);
        }
    }
    let flip = super::flip::flip_of(&b.mean, &a.mean, w, h);
    let mut comparison = Comparison {
        verdict: if passed { Verdict::Pass } else { Verdict::Fail },
        candidate: Some(a.label.clone()),
        width: w,
        height: h,
        candidate_spp: a.spp,
        golden_spp: b.spp,
        scene: None,
        encoding: "exr".to_string(),
        alpha,
        scales,
        regions: ranked.iter().take(50).cloned().collect(),
        regions_total,
        outline: ranked,
        noise: None,
        bias,
        rel_mse: Some(rel_mse),
        flip: None,
        flip_map: Vec::new(),
        effective_spp: None,
        diagnosis: None,
        z_map,
    };
    comparison.set_flip(flip);
    Ok(comparison)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table values of Student's t: `P(|T_10| > 2.228) = 0.05`, `P(|T_3| > 5.841) = 0.01`; the
    /// normal's `P(|Z| > 1.96) = 0.05`.
    #[test]
    fn t_tails_match_the_tables() {
        assert!((t_two_sided(2.228, 10.0) - 0.05).abs() < 1e-4);
        assert!((t_two_sided(5.841, 3.0) - 0.01).abs() < 1e-4);
        assert!((t_two_sided(1.959964, f64::INFINITY) - 0.05).abs() < 1e-6);
    }

    /// Two renders 0 and 1 of a pixel: mean 1/2, sample variance 1/2, the mean's variance 1/4,
    /// one degree of freedom.
    #[test]
    fn renders_give_the_mean_and_its_variance() {
        let side = Side::from_renders(
            1,
            1,
            &[vec![[0.0, 2.0, 3.0]], vec![[1.0, 2.0, 5.0]]],
            8,
            "s",
        );
        assert_eq!(side.mean[0], [0.5, 2.0, 4.0]);
        assert_eq!(side.variance[0], [0.25, 0.0, 1.0]);
        assert_eq!((side.dof, side.spp, side.renders), (1.0, 16, 2));
    }

    /// Welch-Satterthwaite: two variances of 1 with 9 degrees of freedom each give 18; the t of
    /// a difference of 2 is 2 / sqrt(2).
    #[test]
    fn welch_degrees_of_freedom() {
        let mut s = Sums::default();
        s.add(3.0, 1.0, 1.0, 1.0, (9.0, 9.0));
        let (t, p) = s.test();
        assert!((t - std::f64::consts::SQRT_2).abs() < 1e-9);
        assert!((p - t_two_sided(std::f64::consts::SQRT_2, 18.0)).abs() < 1e-12);
        assert!(p > t_two_sided(std::f64::consts::SQRT_2, f64::INFINITY));
    }

    /// relMSE beside the verdict: A a uniform 0.9 of B = 1 gives 0.01 / 1.01 exactly (by hand:
    /// `(0.9 - 1)^2 / (1 + 0.01)` at every pixel and channel), and fails; A = B gives 0.
    #[test]
    fn rel_mse_of_a_uniform_scale() {
        let b = Side::exact(8, 4, [1.0; 3], "b");
        let a = Side::exact(8, 4, [0.9; 3], "a");
        let c = compare_two(&a, &b, 1e-4).unwrap();
        assert!((c.rel_mse.unwrap() - 0.01 / 1.01).abs() < 1e-12);
        assert!(!c.passed());
        assert_eq!(compare_two(&b, &b, 1e-4).unwrap().rel_mse, Some(0.0));
    }

    /// An exact image against itself passes; one channel of one pixel 1e-3 off fails at the
    /// pixel scale.
    #[test]
    fn exact_sides_are_decided_exactly() {
        let a = Side::exact(16, 16, [0.5, 0.25, 1.0], "a");
        let mut b = a.clone();
        assert!(compare_two(&a, &b, 1e-4).unwrap().passed());
        b.mean[37][1] += 1e-3;
        let c = compare_two(&a, &b, 1e-4).unwrap();
        assert!(!c.passed());
        assert!(c.scales[0].failing == 1, "{:?}", c.scales);
    }
}
