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
//! - a **generator** ([`super::simulate`]): the same sampler in Rust, so that
//!   [`rejection_rate`] measures the false-alarm rate of the course's hypothesis on honest
//!   samples and the power against each mistake with many seeds.
//!
//! A check passes when the samples satisfy the course's invariant and its test does not reject;
//! when it fails, every mistake whose own hypothesis the samples satisfy is named.
//!
//! Samples are `[f64; 9]` ([`Sample`]); each check says what its nine numbers are.

use std::sync::OnceLock;

use glam::DVec3;
use serde::Serialize;

use super::simulate;
use super::stats::{TestResult, binomial, chi_square};
use crate::render::PixelSampler;

/// One sample of a random function, in the domain its check reads (unused entries are 0).
pub type Sample = [f64; 9];

type Invariant = Box<dyn Fn(&Sample) -> Result<(), String> + Send + Sync>;
type CellOf = Box<dyn Fn(&Sample) -> usize + Send + Sync>;
type Draw = Box<dyn Fn(&mut PixelSampler) -> Sample + Send + Sync>;

/// What a hypothesis stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    /// Samples that break the invariant.
    pub invariant_failures: usize,
    /// The first of them: its index and what is wrong.
    pub first_failure: Option<(usize, String)>,
    /// The test of the cell counts (of the samples that keep the invariant).
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

/// `d` in the frame of the unit axis `n` (the frame of [`simulate::about`]).
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

fn sphere_hypothesis(
    name: &'static str,
    standing: Standing,
    says: &str,
    probs: Probs,
    draw: fn(&mut PixelSampler) -> DVec3,
) -> Hypothesis {
    Hypothesis::new(
        name,
        standing,
        says,
        Box::new(|s| {
            finite(s)?;
            unit_length(v3(s, 0), "the vector")
        }),
        (SPHERE_CELLS, Box::new(|s| sphere_cell(v3(s, 0)))),
        probs,
        Box::new(move |r| sample_of(draw(r), DVec3::ZERO, DVec3::ZERO)),
    )
}

impl SamplerCheck {
    /// `random_vec3_unit()`: unit vectors, uniform on the sphere.
    pub fn unit_sphere() -> Self {
        let ball = Hypothesis::new(
            "unit_vector_not_normalised",
            Standing::Mistake,
            "a uniform point inside the unit ball, not on the sphere (not normalised)",
            Box::new(|s| {
                finite(s)?;
                let l = v3(s, 0).length();
                if l <= 1.0 + 1e-9 {
                    Ok(())
                } else {
                    Err(format!("length {l:?} > 1"))
                }
            }),
            (
                10,
                Box::new(|s| ((v3(s, 0).length().powi(3) * 10.0) as usize).min(9)),
            ),
            Probs::Equal,
            Box::new(|r| sample_of(simulate::in_ball(r), DVec3::ZERO, DVec3::ZERO)),
        );
        SamplerCheck {
            kind: SamplerKind::UnitSphere,
            samples: UNIT_SPHERE_SAMPLES,
            course: sphere_hypothesis(
                "course",
                Standing::Course,
                "a unit vector, uniform on the sphere",
                Probs::Equal,
                simulate::unit_vector,
            ),
            mistakes: vec![
                ball,
                sphere_hypothesis(
                    "unit_vector_from_cube",
                    Standing::Mistake,
                    "a point of the cube normalised without rejecting those outside the ball (the cube's corners are over-represented)",
                    Probs::Simulated(OnceLock::new()),
                    simulate::unit_vector_from_cube,
                ),
                sphere_hypothesis(
                    "unit_vector_uniform_angles",
                    Standing::Mistake,
                    "the polar angle drawn uniformly (the poles are over-represented)",
                    Probs::Simulated(OnceLock::new()),
                    simulate::unit_vector_uniform_angles,
                ),
            ],
        }
    }

    /// `random_cosine_hemisphere_on_z()`: unit vectors about `z` with density `cos / pi`.
    pub fn cosine_hemisphere() -> Self {
        let hemisphere =
            |name, standing, says: &str, probs, draw: fn(&mut PixelSampler) -> DVec3| {
                Hypothesis::new(
                    name,
                    standing,
                    says,
                    Box::new(|s| {
                        finite(s)?;
                        let d = v3(s, 0);
                        unit_length(d, "the direction")?;
                        if d.z >= -1e-12 {
                            Ok(())
                        } else {
                            Err(format!(
                                "the direction {} points below the xy plane",
                                fmt(d)
                            ))
                        }
                    }),
                    (LOBE_CELLS, Box::new(|s| lobe_cell(v3(s, 0)))),
                    probs,
                    Box::new(move |r| sample_of(draw(r), DVec3::ZERO, DVec3::ZERO)),
                )
            };
        SamplerCheck {
            kind: SamplerKind::CosineHemisphere,
            samples: HEMISPHERE_SAMPLES,
            course: hemisphere(
                "course",
                Standing::Course,
                "a unit vector of the upper hemisphere with density cos(theta) / pi",
                Probs::Equal,
                simulate::cosine_hemisphere,
            ),
            mistakes: vec![hemisphere(
                "hemisphere_instead_of_cosine_lobe",
                Standing::Mistake,
                "the hemisphere sampled uniformly (z = r2) instead of the cosine lobe (z = sqrt(1 - r2))",
                Probs::Simulated(OnceLock::new()),
                simulate::uniform_hemisphere,
            )],
        }
    }

    /// `random_in_unit_disk()`: points of the open unit disk of the xy plane, uniform.
    pub fn unit_disk() -> Self {
        let disk_invariant = |s: &Sample| {
            finite(s)?;
            let p = v3(s, 0);
            if p.z.abs() > 1e-12 {
                return Err(format!("the point {} is not in the xy plane", fmt(p)));
            }
            if p.x * p.x + p.y * p.y <= 1.0 + 1e-12 {
                Ok(())
            } else {
                Err(format!("the point {} lies outside the unit disk", fmt(p)))
            }
        };
        SamplerCheck {
            kind: SamplerKind::UnitDisk,
            samples: DISK_SAMPLES,
            course: Hypothesis::new(
                "course",
                Standing::Course,
                "a point of the unit disk, uniform",
                Box::new(disk_invariant),
                (DISK_CELLS, Box::new(|s| disk_cell(s[0], s[1]))),
                Probs::Equal,
                Box::new(|r| sample_of(simulate::in_disk(r), DVec3::ZERO, DVec3::ZERO)),
            ),
            mistakes: vec![
                square_hypothesis(|r| sample_of(simulate::in_square(r), DVec3::ZERO, DVec3::ZERO)),
                Hypothesis::new(
                    "disk_radius_uniform",
                    Standing::Mistake,
                    "polar coordinates with a uniform radius (the centre is over-represented; the radius wants a square root)",
                    Box::new(disk_invariant),
                    (DISK_CELLS, Box::new(|s| disk_cell(s[0], s[1]))),
                    Probs::Simulated(OnceLock::new()),
                    Box::new(|r| {
                        sample_of(simulate::disk_radius_uniform(r), DVec3::ZERO, DVec3::ZERO)
                    }),
                ),
            ],
        }
    }
}

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

/// A Lambertian's scattering at `point` with unit normal `normal` and `albedo`.
struct Surface {
    point: DVec3,
    normal: DVec3,
    albedo: DVec3,
}

impl Surface {
    /// A unit direction of the hemisphere about the normal, in its lobe cells.
    fn lobe(
        &self,
        name: &'static str,
        standing: Standing,
        says: &str,
        probs: Probs,
        draw: impl Fn(&mut PixelSampler) -> DVec3 + Send + Sync + 'static,
        course_checks: bool,
    ) -> Hypothesis {
        let (p, n, a) = (self.point, self.normal, self.albedo);
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                if course_checks {
                    origin_and_attenuation(s, p, a)?;
                }
                let d = v3(s, 1);
                unit_length(d, "the scattered direction")?;
                if d.dot(n) >= -1e-12 {
                    Ok(())
                } else {
                    Err(format!(
                        "the scattered direction {} points into the surface (normal {})",
                        fmt(d),
                        fmt(n)
                    ))
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1)))),
            ),
            probs,
            Box::new(move |r| sample_of(p, draw(r), a)),
        )
    }
}

impl SamplerCheck {
    /// Week 5's `Lambertian.scattering` at `point` (unit normal `normal`, `albedo`): the
    /// course's `n + u`, not normalised, so `|d|^2 = 2 d . n` and `d / |d|` follows the cosine
    /// lobe about `n`.
    pub fn lambertian_n_plus_u(point: DVec3, normal: DVec3, albedo: DVec3) -> Self {
        let surface = Surface {
            point,
            normal,
            albedo,
        };
        let (p, n, a) = (point, normal, albedo);
        let course = Hypothesis::new(
            "course",
            Standing::Course,
            "n + u for a uniform unit vector u, not normalised",
            Box::new(move |s| {
                finite(s)?;
                origin_and_attenuation(s, p, a)?;
                let d = v3(s, 1);
                let (l2, dn) = (d.length_squared(), 2.0 * d.dot(n));
                if (l2 - dn).abs() <= tol(l2) {
                    Ok(())
                } else {
                    Err(format!(
                        "the scattered direction {} is not n + u for a unit u: |d|^2 = {l2:?}, 2 d . n = {dn:?} (normal {})",
                        fmt(d),
                        fmt(n)
                    ))
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1).normalize_or_zero()))),
            ),
            Probs::Equal,
            Box::new(move |r| sample_of(p, n + simulate::unit_vector(r), a)),
        );
        let normalised = surface.lobe(
            "n_plus_u_normalised",
            Standing::Mistake,
            "n + u normalised (the course leaves it as it is: its length 2 cos(theta) weighs week 8's cosine)",
            Probs::Equal,
            move |r| (n + simulate::unit_vector(r)).normalize(),
            false,
        );
        let hemisphere = surface.lobe(
            "hemisphere_instead_of_cosine_lobe",
            Standing::Mistake,
            "a uniform unit vector flipped to the normal's side: the hemisphere uniformly instead of the cosine lobe",
            Probs::Simulated(OnceLock::new()),
            move |r| simulate::about(n, simulate::uniform_hemisphere(r)),
            false,
        );
        SamplerCheck {
            kind: SamplerKind::LambertianNPlusU,
            samples: LAMBERTIAN_SAMPLES,
            course,
            mistakes: vec![normalised, hemisphere],
        }
    }

    /// Week 9's `Lambertian.scattering`: a unit direction with density `cos / pi` about `n`.
    pub fn lambertian_cosine(point: DVec3, normal: DVec3, albedo: DVec3) -> Self {
        let surface = Surface {
            point,
            normal,
            albedo,
        };
        let (p, n, a) = (point, normal, albedo);
        let course = surface.lobe(
            "course",
            Standing::Course,
            "a unit direction with density cos(theta) / pi about the normal",
            Probs::Equal,
            move |r| simulate::about(n, simulate::cosine_hemisphere(r)),
            true,
        );
        let hemisphere = surface.lobe(
            "hemisphere_instead_of_cosine_lobe",
            Standing::Mistake,
            "the hemisphere about the normal sampled uniformly instead of the cosine lobe",
            Probs::Simulated(OnceLock::new()),
            move |r| simulate::about(n, simulate::uniform_hemisphere(r)),
            false,
        );
        let wrong_axis = Hypothesis::new(
            "lobe_around_wrong_axis",
            Standing::Mistake,
            "the cosine lobe lies about a tangent instead of the normal (ONB.local mixes up its axes): half the directions point into the surface",
            Box::new(|s| {
                finite(s)?;
                unit_length(v3(s, 1), "the scattered direction")
            }),
            (
                10,
                Box::new(move |s| (((v3(s, 1).dot(n) + 1.0) * 5.0) as usize).min(9)),
            ),
            Probs::Simulated(OnceLock::new()),
            Box::new(move |r| {
                let c = simulate::cosine_hemisphere(r);
                sample_of(p, simulate::about(n, DVec3::new(c.z, c.y, c.x)), a)
            }),
        );
        let kept_week5 = Hypothesis::new(
            "n_plus_u_kept",
            Standing::Mistake,
            "week 5's n + u, not normalised, instead of the cosine lobe through the ONB",
            Box::new(move |s| {
                finite(s)?;
                let d = v3(s, 1);
                let (l2, dn) = (d.length_squared(), 2.0 * d.dot(n));
                if (l2 - dn).abs() <= tol(l2) && (d.length() - 1.0).abs() > 1e-6 {
                    Ok(())
                } else {
                    Err("not n + u".into())
                }
            }),
            (
                LOBE_CELLS,
                Box::new(move |s| lobe_cell(local_to(n, v3(s, 1).normalize_or_zero()))),
            ),
            Probs::Equal,
            Box::new(move |r| sample_of(p, n + simulate::unit_vector(r), a)),
        );
        SamplerCheck {
            kind: SamplerKind::LambertianCosine,
            samples: LAMBERTIAN_SAMPLES,
            course,
            mistakes: vec![hemisphere, wrong_axis, kept_week5],
        }
    }
}

/// A metal's scattering: the hit, the mirror direction of the unit incoming direction, the
/// roughness as the course clamps it (at most 1) and as the scene gave it, and the mirror
/// direction of the raw incoming direction.
#[derive(Clone, Copy, Debug)]
pub struct MetalSetting {
    /// The hit point.
    pub point: DVec3,
    /// The unit normal facing the incoming ray.
    pub normal: DVec3,
    /// The albedo.
    pub albedo: DVec3,
    /// `reflect(unit(d), n)`.
    pub mirror: DVec3,
    /// `reflect(d, n)` of the raw direction.
    pub raw_mirror: DVec3,
    /// The roughness the course uses, `min(roughness, 1)`.
    pub roughness: f64,
    /// The roughness as given to the constructor.
    pub given_roughness: f64,
}

impl MetalSetting {
    fn fuzz(
        &self,
        name: &'static str,
        says: &str,
        mirror: DVec3,
        radius: f64,
        course: bool,
    ) -> Hypothesis {
        let m = *self;
        Hypothesis::new(
            name,
            if course {
                Standing::Course
            } else {
                Standing::Mistake
            },
            says,
            Box::new(move |s| {
                finite(s)?;
                if course {
                    let o = v3(s, 0);
                    if (o - m.point).abs().max_element() > tol(m.point.abs().max_element()) {
                        return Err(format!(
                            "the scattered ray starts at {}, not at the hit point {}",
                            fmt(o),
                            fmt(m.point)
                        ));
                    }
                }
                let d = v3(s, 1);
                let off = (d - mirror).length();
                if (off - radius).abs() > tol(radius) {
                    return Err(format!(
                        "the scattered direction {} lies {off:?} from the mirror direction {}, not the roughness {radius:?}",
                        fmt(d),
                        fmt(mirror)
                    ));
                }
                if course {
                    // The attenuation: the albedo, or zero at or below 1e-8 (a sample within
                    // rounding of the threshold is not judged on it).
                    let dn = d.dot(m.normal);
                    let a = v3(s, 2);
                    if (dn - 1e-8).abs() > 1e-12 {
                        let want = if dn <= 1e-8 { DVec3::ZERO } else { m.albedo };
                        if (a - want).abs().max_element() > 1e-12 {
                            return Err(format!(
                                "the attenuation is {} where d . n = {dn:?}: the course's is {}",
                                fmt(a),
                                fmt(want)
                            ));
                        }
                    }
                }
                Ok(())
            }),
            (
                SPHERE_CELLS,
                Box::new(move |s| {
                    sphere_cell(
                        ((v3(s, 1) - mirror) / radius.max(f64::MIN_POSITIVE)).normalize_or_zero(),
                    )
                }),
            ),
            Probs::Equal,
            Box::new(move |r| {
                let d = mirror + radius * simulate::unit_vector(r);
                let a = if d.dot(m.normal) <= 1e-8 {
                    DVec3::ZERO
                } else {
                    m.albedo
                };
                sample_of(m.point, d, a)
            }),
        )
    }
}

impl SamplerCheck {
    /// `Metal.scattering`: `reflect(unit(d), n) + roughness u` for a uniform unit `u`.
    pub fn metal(setting: MetalSetting) -> Self {
        let m = setting;
        let mut mistakes = vec![
            Hypothesis::new(
                "metal_roughness_ignored",
                Standing::Mistake,
                "the mirror direction alone: the roughness times a random unit vector is not added",
                Box::new(move |s| {
                    finite(s)?;
                    if (v3(s, 1) - m.mirror).length() <= tol(1.0) {
                        Ok(())
                    } else {
                        Err("not the mirror direction".into())
                    }
                }),
                (1, Box::new(|_| 0)),
                Probs::Equal,
                Box::new(move |_| sample_of(m.point, m.mirror, m.albedo)),
            ),
            Hypothesis::new(
                "metal_fuzz_in_ball",
                Standing::Mistake,
                "the roughness times a point inside the unit ball (the book's first fuzz) instead of a unit vector",
                Box::new(move |s| {
                    finite(s)?;
                    if (v3(s, 1) - m.mirror).length() < m.roughness + tol(m.roughness) {
                        Ok(())
                    } else {
                        Err("outside the ball".into())
                    }
                }),
                (
                    10,
                    Box::new(move |s| {
                        (((v3(s, 1) - m.mirror).length() / m.roughness).powi(3) * 10.0) as usize
                    }),
                ),
                Probs::Equal,
                Box::new(move |r| {
                    sample_of(
                        m.point,
                        m.mirror + m.roughness * simulate::in_ball(r),
                        m.albedo,
                    )
                }),
            ),
        ];
        if (m.raw_mirror - m.mirror).length() > 1e-6 {
            mistakes.push(m.fuzz(
                "metal_reflects_raw_direction",
                "the raw incoming direction reflected (the course reflects the unit direction)",
                m.raw_mirror,
                m.roughness,
                false,
            ));
        }
        if m.given_roughness > m.roughness {
            mistakes.push(m.fuzz(
                "metal_roughness_not_clamped",
                "the roughness used as given, above 1 (the course clamps it to 1)",
                m.mirror,
                m.given_roughness,
                false,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::MetalFuzz,
            samples: METAL_SAMPLES,
            course: m.fuzz(
                "course",
                "reflect(unit(d), n) + roughness u, u uniform on the unit sphere",
                m.mirror,
                m.roughness,
                true,
            ),
            mistakes,
        }
    }
}

/// A dielectric's choice at one hit: the two directions and the course's probability of
/// reflecting, with the probabilities the mistakes give.
#[derive(Clone, Copy, Debug)]
pub struct DielectricSetting {
    /// The hit point.
    pub point: DVec3,
    /// The albedo.
    pub albedo: DVec3,
    /// The reflected direction.
    pub reflected: DVec3,
    /// The refracted direction (`None` under total internal reflection).
    pub refracted: Option<DVec3>,
    /// The course's probability of reflecting: 1 under total internal reflection, else
    /// `schlick(cos, ratio)`.
    pub p_reflect: f64,
    /// The probability when Schlick is fed the sine instead of the cosine.
    pub p_wrong_cosine: f64,
}

impl DielectricSetting {
    fn hypothesis(&self, name: &'static str, standing: Standing, says: &str, p: f64) -> Hypothesis {
        let m = *self;
        let course = standing == Standing::Course;
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                if course {
                    origin_and_attenuation(s, m.point, m.albedo)?;
                }
                let d = v3(s, 1);
                let near = |e: DVec3| (d - e).abs().max_element() <= 1e-9;
                if near(m.reflected) || m.refracted.is_some_and(near) {
                    Ok(())
                } else {
                    Err(match m.refracted {
                        Some(t) => format!(
                            "the scattered direction {} is neither the reflected {} nor the refracted {}",
                            fmt(d),
                            fmt(m.reflected),
                            fmt(t)
                        ),
                        None => format!(
                            "the scattered direction {} is not the reflected {} (total internal reflection)",
                            fmt(d),
                            fmt(m.reflected)
                        ),
                    })
                }
            }),
            (
                2,
                Box::new(move |s| usize::from((v3(s, 1) - m.reflected).abs().max_element() > 1e-9)),
            ),
            Probs::Given(vec![p, 1.0 - p]),
            Box::new(move |r| {
                let d = match m.refracted {
                    Some(t) if r.next_f64() >= p => t,
                    _ => m.reflected,
                };
                sample_of(m.point, d, m.albedo)
            }),
        )
    }
}

impl SamplerCheck {
    /// `Dielectric.scattering`'s choice: reflect with the course's probability, else refract.
    pub fn dielectric(setting: DielectricSetting) -> Self {
        let m = setting;
        let mut mistakes = vec![m.hypothesis(
            "schlick_fraction_inverted",
            Standing::Mistake,
            "always reflects: Schlick's r0 = ((1 + x) / (1 - x))^2 is above 1",
            1.0,
        )];
        if (m.p_wrong_cosine - m.p_reflect).abs() > 1e-6 {
            mistakes.push(m.hypothesis(
                "schlick_wrong_cosine",
                Standing::Mistake,
                "reflects with Schlick's value of the sine instead of the cosine",
                m.p_wrong_cosine,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::DielectricChoice,
            samples: DIELECTRIC_SAMPLES,
            course: m.hypothesis(
                "course",
                Standing::Course,
                "reflects with probability schlick(cos, ratio) (always under total internal reflection), else refracts",
                m.p_reflect,
            ),
            mistakes,
        }
    }
}

/// One stratum of the camera's jittered sampling.
#[derive(Clone, Copy, Debug)]
pub struct JitterSetting {
    /// The stratum `(s_i, s_j)`.
    pub stratum: (u32, u32),
    /// The course's step, `one_over_sqrt_spp` frozen from the default spp (1/3 in week 9,
    /// `1/sqrt(10)` in week 10).
    pub step: f64,
    /// The step recomputed from the scene's spp, `1 / floor(sqrt(spp))`.
    pub unfrozen_step: f64,
}

impl JitterSetting {
    /// The offsets `0.5 (-0.5 + step (s + U))` (`half`) or `-0.5 + step (s + U)`, as a
    /// hypothesis on `[px, py]`.
    fn hypothesis(
        &self,
        name: &'static str,
        standing: Standing,
        says: &str,
        step: f64,
        half: bool,
    ) -> Hypothesis {
        let (si, sj) = (self.stratum.0 as f64, self.stratum.1 as f64);
        let scale = if half { 0.5 } else { 1.0 };
        let unit = move |p: f64, s: f64| (p / scale + 0.5) / step - s;
        let course = standing == Standing::Course;
        Hypothesis::new(
            name,
            standing,
            says,
            Box::new(move |s| {
                finite(s)?;
                let (ux, uy) = (unit(s[0], si), unit(s[1], sj));
                let inside = |u: f64| (-1e-9..=1.0 + 1e-9).contains(&u);
                if inside(ux) && inside(uy) {
                    Ok(())
                } else if course {
                    let lo = |s: f64| scale * (-0.5 + step * s);
                    Err(format!(
                        "the sample lies at ({:?}, {:?}) pixels from the pixel's centre, outside its stratum [{:.4}, {:.4}] x [{:.4}, {:.4}]",
                        s[0],
                        s[1],
                        lo(si),
                        lo(si + 1.0),
                        lo(sj),
                        lo(sj + 1.0)
                    ))
                } else {
                    Err("outside".into())
                }
            }),
            (
                SQUARE_CELLS,
                Box::new(move |s| square_cell(unit(s[0], si), unit(s[1], sj))),
            ),
            Probs::Equal,
            Box::new(move |r| {
                let px = scale * (-0.5 + step * (si + r.next_f64()));
                let py = scale * (-0.5 + step * (sj + r.next_f64()));
                [px, py, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            }),
        )
    }
}

impl SamplerCheck {
    /// The jittered sample of stratum `setting.stratum`: `0.5 (-0.5 + step (s + U))` pixels from
    /// the pixel's centre, `U` uniform in `[0, 1)` on each axis.
    pub fn jitter(setting: JitterSetting) -> Self {
        let j = setting;
        let mut mistakes = vec![
            j.hypothesis(
                "jitter_outside_pixel",
                Standing::Mistake,
                "the stratum step one_over_sqrt_spp left out: -0.5 + (s + U) reaches far outside the pixel",
                1.0,
                true,
            ),
            j.hypothesis(
                "jitter_without_half",
                Standing::Mistake,
                "the offsets not halved: -0.5 + step (s + U) instead of 0.5 (-0.5 + step (s + U))",
                j.step,
                false,
            ),
            Hypothesis::new(
                "jitter_ignores_stratum",
                Standing::Mistake,
                "a uniform point of the whole pixel (get_ray's), not of the stratum",
                Box::new(|s| {
                    finite(s)?;
                    if s[0].abs() <= 0.5 + 1e-9 && s[1].abs() <= 0.5 + 1e-9 {
                        Ok(())
                    } else {
                        Err("outside the pixel".into())
                    }
                }),
                (SQUARE_CELLS, Box::new(|s| square_cell(s[0] + 0.5, s[1] + 0.5))),
                Probs::Equal,
                Box::new(|r| {
                    [r.next_f64() - 0.5, r.next_f64() - 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            ),
        ];
        if (j.unfrozen_step - j.step).abs() > 1e-12 {
            mistakes.push(j.hypothesis(
                "jitter_step_not_frozen",
                Standing::Physical,
                "the stratum step recomputed from the scene's spp, 1 / floor(sqrt(spp)) (the strata then tile the pixel's centre region as intended; the course freezes the step at the default spp 10)",
                j.unfrozen_step,
                true,
            ));
        }
        SamplerCheck {
            kind: SamplerKind::JitterStratum,
            samples: CAMERA_SAMPLES,
            course: j.hypothesis(
                "course",
                Standing::Course,
                "0.5 (-0.5 + step (s + U)) pixels from the pixel's centre on each axis, U uniform in [0, 1), step the course's frozen one_over_sqrt_spp",
                j.step,
                true,
            ),
            mistakes,
        }
    }

    /// The lens: ray origins uniform on the defocus disk of radius 1 (in units of the course's
    /// radius) in the camera's `(u, v)` plane. `doubled` is the radius ratio of the
    /// doubled-angle mistake, `tan(angle) / tan(angle / 2)`.
    pub fn lens(doubled: f64) -> Self {
        let disk = |name, standing, says: &str, radius: f64| {
            Hypothesis::new(
                name,
                standing,
                says,
                Box::new(move |s: &Sample| {
                    finite(s)?;
                    if s[2].abs() > 1e-9 {
                        return Err(format!(
                            "the ray starts {:?} off the lens plane (along the camera's w)",
                            s[2]
                        ));
                    }
                    let r2 = (s[0] * s[0] + s[1] * s[1]) / (radius * radius);
                    if r2 <= 1.0 + 1e-9 {
                        Ok(())
                    } else {
                        Err(format!(
                            "the ray starts {:?} lens radii from the camera's centre, outside the lens",
                            r2.sqrt() * radius
                        ))
                    }
                }),
                (
                    DISK_CELLS,
                    Box::new(move |s: &Sample| disk_cell(s[0] / radius, s[1] / radius)),
                ),
                Probs::Equal,
                Box::new(move |r: &mut PixelSampler| {
                    let (x, y) = r.in_unit_disk();
                    [radius * x, radius * y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            )
        };
        SamplerCheck {
            kind: SamplerKind::LensDisk,
            samples: CAMERA_SAMPLES,
            course: disk(
                "course",
                Standing::Course,
                "origins uniform on the defocus disk (radius focus tan(angle / 2)) in the camera's u, v plane",
                1.0,
            ),
            mistakes: vec![
                Hypothesis::new(
                    "jittered_ray_without_lens",
                    Standing::Mistake,
                    "every ray starts at the camera's centre: the jittered path has no lens (the week-10 skeleton's)",
                    Box::new(|s| {
                        finite(s)?;
                        if s[0].abs() <= 1e-9 && s[1].abs() <= 1e-9 {
                            Ok(())
                        } else {
                            Err("off the centre".into())
                        }
                    }),
                    (1, Box::new(|_| 0)),
                    Probs::Equal,
                    Box::new(|_| [0.0; 9]),
                ),
                disk(
                    "defocus_radius_doubled",
                    Standing::Mistake,
                    "a lens of radius focus tan(angle) instead of focus tan(angle / 2)",
                    doubled,
                ),
                square_hypothesis(|r| {
                    let p = simulate::in_square(r);
                    [p.x, p.y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
                }),
            ],
        }
    }

    /// The camera ray's time: uniform in `[0, 1)`.
    pub fn ray_time() -> Self {
        SamplerCheck {
            kind: SamplerKind::RayTime,
            samples: CAMERA_SAMPLES,
            course: Hypothesis::new(
                "course",
                Standing::Course,
                "a time uniform in [0, 1)",
                Box::new(|s| {
                    finite(s)?;
                    if (0.0..=1.0).contains(&s[0]) {
                        Ok(())
                    } else {
                        Err(format!("the ray's time {:?} is outside [0, 1)", s[0]))
                    }
                }),
                (20, Box::new(|s| ((s[0] * 20.0) as usize).min(19))),
                Probs::Equal,
                Box::new(|r| [r.next_f64(), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            ),
            mistakes: vec![Hypothesis::new(
                "jittered_ray_without_time",
                Standing::Mistake,
                "every ray has time 0: no motion blur",
                Box::new(|s| {
                    finite(s)?;
                    if s[0] == 0.0 {
                        Ok(())
                    } else {
                        Err("not 0".into())
                    }
                }),
                (1, Box::new(|_| 0)),
                Probs::Equal,
                Box::new(|_| [0.0; 9]),
            )],
        }
    }
}

#[cfg(test)]
mod tests;
