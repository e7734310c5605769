//! The statistical checks of the course's random functions: what each sample must satisfy, how
//! samples are binned, which distribution the bins must follow, and the catalogued mistakes,
//! each a [`Hypothesis`] of its own.
//!
//! A check ([`SamplerCheck`]) holds the course's hypothesis and its mistakes'. Each hypothesis
//! has
//! - an **invariant** every sample must satisfy exactly (up to rounding): a unit length, the
//!   course's `|d|^2 = 2 d . n` of `n + u`, a lens point inside the disk, a jitter offset inside
//!   its stratum, a time in `[0, 1)`. One sample that breaks it fails the check: no statistics
//!   are needed for that, and there is no false alarm;
//! - **cells** and their probabilities (equal by construction for the course's hypotheses;
//!   estimated once from a seeded Rust simulation of the mistake where it has no closed form),
//!   tested by Pearson's chi-square, or by the exact binomial test when there are two cells, at
//!   the false-alarm rate asked ([`super::stats::DEFAULT_ALPHA`] by default);
//! - a **generator** ([`super::samplers::mistakes`]): the same sampler in Rust, so that
//!   [`rejection_rate`] measures the false-alarm rate of the course's hypothesis on honest
//!   samples and the power against each mistake with many seeds.
//!
//! A check passes when the samples satisfy the course's invariant and its test does not reject;
//! when it fails, every mistake whose own hypothesis the samples satisfy is named.
//!
//! Samples are `[f64; 9]` ([`Sample`]); each check says what its nine numbers are.

use std::sync::OnceLock;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::stats::{TestResult, binomial, chi_square};
use crate::render::PixelSampler;

pub mod camera;
mod directions;
pub mod mistakes;
pub mod surfaces;

/// One sample of a random function, in the domain its check reads (unused entries are 0).
pub type Sample = [f64; 9];

type Invariant = Box<dyn Fn(&Sample) -> Result<(), String> + Send + Sync>;
type CellOf = Box<dyn Fn(&Sample) -> usize + Send + Sync>;
type Draw = Box<dyn Fn(&mut PixelSampler) -> Sample + Send + Sync>;

/// What a hypothesis stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Standing {
    /// What the course's code does.
    Course,
    /// A catalogued mistake.
    Mistake,
    /// What physics (or the book) does where the course departs from it: named, not a slip.
    Physical,
    /// Another version of the course's own code (or of its README): accepted or named, not a
    /// slip.
    Alternative,
    /// The course's behaviour, reached another way (the work split differently between
    /// functions, another convention for the same input): named, and not charged
    /// ([`crate::weekly::departures`]).
    Departure,
}

/// How a hypothesis's cell probabilities are known.
enum Probs {
    /// All cells equally likely.
    Equal,
    /// Given.
    Given(Vec<f64>),
    /// Estimated from [`SIMULATED_SAMPLES`] draws of the generator (seeded), once.
    Simulated(OnceLock<Vec<f64>>),
}

/// Draws used to estimate a mistake's cell probabilities.
pub const SIMULATED_SAMPLES: usize = 400_000;

/// One hypothesis about a sampler's output.
pub struct Hypothesis {
    /// The mistake's name (the catalogue's), or `"course"`.
    pub name: &'static str,
    /// What the sampler does under it, in words.
    pub says: String,
    /// Course, mistake or physical.
    pub standing: Standing,
    invariant: Invariant,
    cell: CellOf,
    cells: usize,
    probs: Probs,
    draw: Draw,
}

/// How a set of samples fits a hypothesis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// Samples that break the invariant.
    pub invariant_failures: usize,
    /// The first of them: its index and what is wrong.
    pub first_failure: Option<(usize, String)>,
    /// The test of the cell counts (of the samples that keep the invariant).
    #[serde(deserialize_with = "super::stats::read_test")]
    pub test: Option<TestResult>,
}

impl Fit {
    /// Whether the samples are consistent with the hypothesis.
    pub fn holds(&self) -> bool {
        self.invariant_failures == 0 && !self.test.as_ref().is_some_and(TestResult::rejected)
    }
}

impl Hypothesis {
    fn new(
        name: &'static str,
        standing: Standing,
        says: impl Into<String>,
        invariant: Invariant,
        (cells, cell): (usize, CellOf),
        probs: Probs,
        draw: Draw,
    ) -> Self {
        Hypothesis {
            name,
            says: says.into(),
            standing,
            invariant,
            cell,
            cells,
            probs,
            draw,
        }
    }

    /// Whether one sample keeps this hypothesis's invariant (what is wrong when it does not).
    pub fn invariant_holds(&self, sample: &Sample) -> Result<(), String> {
        (self.invariant)(sample)
    }

    /// A sample drawn under this hypothesis.
    pub fn draw(&self, sampler: &mut PixelSampler) -> Sample {
        (self.draw)(sampler)
    }

    /// The cells' probabilities.
    pub fn probabilities(&self) -> Vec<f64> {
        match &self.probs {
            Probs::Equal => vec![1.0 / self.cells as f64; self.cells],
            Probs::Given(p) => p.clone(),
            Probs::Simulated(cache) => cache
                .get_or_init(|| {
                    let mut counts = vec![0u64; self.cells];
                    let mut sampler = PixelSampler::new(0x5eed, self.cells as u64);
                    let mut kept = 0u64;
                    for _ in 0..SIMULATED_SAMPLES {
                        let s = (self.draw)(&mut sampler);
                        if (self.invariant)(&s).is_ok() {
                            counts[(self.cell)(&s).min(self.cells - 1)] += 1;
                            kept += 1;
                        }
                    }
                    // Half a count in every cell: a cell the simulation missed is unlikely,
                    // not impossible.
                    let total = kept as f64 + 0.5 * self.cells as f64;
                    counts.iter().map(|&c| (c as f64 + 0.5) / total).collect()
                })
                .clone(),
        }
    }

    /// How `samples` fit this hypothesis, testing at false-alarm rate `alpha`.
    pub fn fit(&self, samples: &[Sample], alpha: f64) -> Fit {
        let mut counts = vec![0u64; self.cells];
        let mut failures = 0;
        let mut first = None;
        for (i, s) in samples.iter().enumerate() {
            match (self.invariant)(s) {
                Ok(()) => counts[(self.cell)(s).min(self.cells - 1)] += 1,
                Err(why) => {
                    failures += 1;
                    if first.is_none() {
                        first = Some((i, why));
                    }
                }
            }
        }
        let test = (counts.iter().sum::<u64>() > 0).then(|| {
            let probs = self.probabilities();
            if self.cells == 2 {
                binomial(counts[0], counts[0] + counts[1], probs[0], alpha)
            } else {
                chi_square(&counts, &probs, alpha)
            }
        });
        Fit {
            invariant_failures: failures,
            first_failure: first,
            test,
        }
    }
}

/// Which random function a check samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplerKind {
    /// `random_vec3_unit()`: `[x, y, z]`.
    UnitSphere,
    /// `random_cosine_hemisphere_on_z()`: `[x, y, z]`.
    CosineHemisphere,
    /// `random_in_unit_disk()`: `[x, y, z]`.
    UnitDisk,
    /// Week 5's `Lambertian.scattering` (`n + u`): `[origin, direction, attenuation]`.
    LambertianNPlusU,
    /// Week 9's `Lambertian.scattering` (the cosine lobe through the ONB): as above.
    LambertianCosine,
    /// `Metal.scattering`: as above.
    MetalFuzz,
    /// `Dielectric.scattering`'s choice between reflection and refraction: as above.
    DielectricChoice,
    /// The camera's jittered sample within its stratum: `[px, py]`, the offset from the pixel's
    /// centre in pixels.
    JitterStratum,
    /// The camera's lens: `[x, y, w]`, the ray origin's offset from the camera centre along the
    /// frame's `u` and `v` in units of the defocus radius, and along `w` in world units.
    LensDisk,
    /// The camera ray's time: `[t]`.
    RayTime,
}

/// A statistical check: the course's hypothesis and the mistakes it can name.
pub struct SamplerCheck {
    /// What it samples.
    pub kind: SamplerKind,
    /// Samples to ask for (chosen for the power stated in the docs).
    pub samples: usize,
    /// What the course's code does.
    pub course: Hypothesis,
    /// The mistakes (and physical alternatives) it can tell apart.
    pub mistakes: Vec<Hypothesis>,
}

/// The verdict of a statistical check on some samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SamplerVerdict {
    /// Samples judged.
    pub samples: usize,
    /// How they fit the course's hypothesis.
    pub fit: Fit,
    /// Whether the check passed.
    pub passed: bool,
    /// The mistakes whose hypotheses the samples fit (when it failed), with their standing.
    pub named: Vec<(&'static str, Standing)>,
}

impl SamplerCheck {
    /// Judges `samples` at false-alarm rate `alpha`.
    pub fn judge(&self, samples: &[Sample], alpha: f64) -> SamplerVerdict {
        let fit = self.course.fit(samples, alpha);
        let passed = fit.holds();
        let named = if passed {
            Vec::new()
        } else {
            self.mistakes
                .iter()
                .filter(|m| m.fit(samples, alpha).holds())
                .map(|m| (m.name, m.standing))
                .collect()
        };
        SamplerVerdict {
            samples: samples.len(),
            fit,
            passed,
            named,
        }
    }

    /// The mistake called `name`.
    pub fn mistake(&self, name: &str) -> Option<&Hypothesis> {
        self.mistakes.iter().find(|m| m.name == name)
    }
}

/// In `runs` runs of `check` on `samples` draws from `under` (seeded by `seed` and the run),
/// how many failed, and how many named `named` (`None`: any mistake).
pub fn rejection_rate(
    check: &SamplerCheck,
    under: &Hypothesis,
    samples: usize,
    runs: u64,
    seed: u64,
    alpha: f64,
) -> (u64, u64) {
    let mut failed = 0;
    let mut named = 0;
    let mut buf = Vec::with_capacity(samples);
    for run in 0..runs {
        let mut sampler = PixelSampler::new(seed, run);
        buf.clear();
        buf.extend((0..samples).map(|_| under.draw(&mut sampler)));
        let v = check.judge(&buf, alpha);
        if !v.passed {
            failed += 1;
            if v.named.iter().any(|(n, _)| *n == under.name) {
                named += 1;
            }
        }
    }
    (failed, named)
}

// ---------------------------------------------------------------------------------------------
// Reading samples.

fn v3(s: &Sample, k: usize) -> DVec3 {
    DVec3::new(s[3 * k], s[3 * k + 1], s[3 * k + 2])
}

fn sample_of(a: DVec3, b: DVec3, c: DVec3) -> Sample {
    [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]
}

fn finite(s: &Sample) -> Result<(), String> {
    if s.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err("not a finite sample (or the function returned None)".into())
    }
}

fn fmt(v: DVec3) -> String {
    format!("({:?}, {:?}, {:?})", v.x, v.y, v.z)
}

/// The cell of a direction on the sphere: 8 bands of equal area in `z`, 16 sectors in azimuth.
fn sphere_cell(d: DVec3) -> usize {
    let band = (((d.z + 1.0) * 4.0) as usize).min(7);
    let phi = (d.y.atan2(d.x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
    band * 16 + ((phi * 16.0) as usize).min(15)
}

const SPHERE_CELLS: usize = 128;

/// The cell of a direction about an axis under the cosine lobe: 10 bands of equal probability in
/// `cos^2`, 8 sectors in azimuth (`local` in the axis's frame).
fn lobe_cell(local: DVec3) -> usize {
    let band = ((local.z * local.z * 10.0) as usize).min(9);
    let phi = (local.y.atan2(local.x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
    band * 8 + ((phi * 8.0) as usize).min(7)
}

const LOBE_CELLS: usize = 80;

/// The cell of a point of the unit disk: 8 rings of equal area, 16 sectors.
fn disk_cell(x: f64, y: f64) -> usize {
    let ring = (((x * x + y * y) * 8.0) as usize).min(7);
    let phi = (y.atan2(x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
    ring * 16 + ((phi * 16.0) as usize).min(15)
}

const DISK_CELLS: usize = 128;

/// The cell of a point of `[0, 1)^2`: 8 x 8.
fn square_cell(u: f64, v: f64) -> usize {
    let i = ((u * 8.0).max(0.0) as usize).min(7);
    let j = ((v * 8.0).max(0.0) as usize).min(7);
    i * 8 + j
}

const SQUARE_CELLS: usize = 64;

/// `d` in the frame of the unit axis `n` (the frame of [`mistakes::about`]).
fn local_to(n: DVec3, d: DVec3) -> DVec3 {
    let (t, b) = n.any_orthonormal_pair();
    DVec3::new(d.dot(t), d.dot(b), d.dot(n))
}

/// Tolerance of an exact relation between numbers of size about `scale`.
fn tol(scale: f64) -> f64 {
    1e-9 * scale.max(1.0)
}

fn unit_length(d: DVec3, what: &str) -> Result<(), String> {
    if (d.length() - 1.0).abs() <= 1e-9 {
        Ok(())
    } else {
        Err(format!(
            "{what} {} has length {:?}, not 1",
            fmt(d),
            d.length()
        ))
    }
}

// ---------------------------------------------------------------------------------------------
// The checks.

/// Samples of `random_vec3_unit()` asked for (power in the docs).
pub const UNIT_SPHERE_SAMPLES: usize = 8000;
/// Samples of `random_cosine_hemisphere_on_z()` asked for.
pub const HEMISPHERE_SAMPLES: usize = 4000;
/// Samples of `random_in_unit_disk()` asked for.
pub const DISK_SAMPLES: usize = 4000;
/// Samples of a Lambertian's scattering asked for.
pub const LAMBERTIAN_SAMPLES: usize = 4000;
/// Samples of a metal's scattering asked for.
pub const METAL_SAMPLES: usize = 2000;
/// Samples of a dielectric's scattering asked for.
pub const DIELECTRIC_SAMPLES: usize = 2000;
/// Samples of the camera's rays through one pixel and stratum asked for.
pub const CAMERA_SAMPLES: usize = 4000;

/// The lens square mistake: points of `[-1, 1]^2` (`s[0]`, `s[1]`), uniform.
fn square_hypothesis(draw: fn(&mut PixelSampler) -> Sample) -> Hypothesis {
    Hypothesis::new(
        "lens_square_not_disk",
        Standing::Mistake,
        "points of the square [-1, 1]^2 kept without rejecting those outside the disk: a square lens",
        Box::new(|s| {
            finite(s)?;
            if s[0].abs() <= 1.0 + 1e-9 && s[1].abs() <= 1.0 + 1e-9 {
                Ok(())
            } else {
                Err("outside the square".into())
            }
        }),
        (
            SQUARE_CELLS,
            Box::new(|s| square_cell(0.5 * (s[0] + 1.0), 0.5 * (s[1] + 1.0))),
        ),
        Probs::Equal,
        Box::new(draw),
    )
}

/// The scattered rays' origin and attenuation must be the hit point and the albedo.
fn origin_and_attenuation(s: &Sample, point: DVec3, albedo: DVec3) -> Result<(), String> {
    let o = v3(s, 0);
    if (o - point).abs().max_element() > tol(point.abs().max_element()) {
        return Err(format!(
            "the scattered ray starts at {}, not at the hit point {}",
            fmt(o),
            fmt(point)
        ));
    }
    let a = v3(s, 2);
    if (a - albedo).abs().max_element() > 1e-12 {
        return Err(format!(
            "the attenuation is {}, not the albedo {}",
            fmt(a),
            fmt(albedo)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests;
