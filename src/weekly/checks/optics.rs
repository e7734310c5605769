//! Week 6's optics (`reflect`, `refract`, `schlick`, `Mirror`, `Dielectric`) and week 8's
//! `halfvector`.
//!
//! The expected answers are the reference's ([`crate::render::reflect`], [`refracted`],
//! [`schlick`], [`halfvector`]). `refract`'s two decisions, total internal reflection
//! (`ratio sin > 1`) and Schlick's choice (`schlick(cos, ratio) > u`), are taken from the
//! course's expressions evaluated in outward-rounded interval arithmetic, widened 8 times: a
//! case whose threshold lies within that band is ambiguous (rounding decides), not scored.

use glam::DVec3;
use serde_json::json;

use super::{
    Body, CASE_TIMEOUT, Case, FunctionCheck, SAMPLES_TIMEOUT, Variant, jnum, jvec, py, steer,
    stream, week,
};
use crate::oracle::band::Iv;
use crate::render::{halfvector, reflect, refracted, schlick};
use crate::weekly::expect::{Class, Expected, Want};
use crate::weekly::samplers::mistakes;
use crate::weekly::samplers::{
    DIELECTRIC_SAMPLES, Sample, SamplerCheck, Standing, surfaces::DielectricSetting,
};

mod dielectric;

/// Tolerance of a vector computed by a few operations on inputs of size about `scale`.
fn vtol(scale: f64) -> f64 {
    1e-9 * scale.max(1.0)
}

fn iv(x: f64) -> Iv {
    Iv::point(x)
}

fn iv_dot(a: DVec3, b: DVec3) -> Iv {
    iv(a.x) * iv(b.x) + iv(a.y) * iv(b.y) + iv(a.z) * iv(b.z)
}

/// `min(x, 1)` of an interval.
fn iv_min1(x: Iv) -> Iv {
    Iv {
        lo: x.lo.min(1.0),
        hi: x.hi.min(1.0),
    }
}

/// Where `refract` goes for a unit `v` and unit `n`, as the course decides it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Branch {
    /// Total internal reflection (no random number is drawn).
    TotalReflection,
    /// Schlick's choice reflects.
    Reflect,
    /// It refracts.
    Refract,
    /// Rounding decides: the reason.
    Rounding(&'static str),
}

impl Branch {
    /// Whether the direction is the reflected one.
    pub(crate) fn reflects(self) -> bool {
        matches!(self, Branch::TotalReflection | Branch::Reflect)
    }
}

/// The course's `cos = min(-v . n, 1)` and `schlick` fed `cosine_of`'s choice (the course's
/// cosine, or the sine for the mistake).
fn decide(v: DVec3, n: DVec3, ratio: f64, u: f64, schlick_of_sine: bool) -> Branch {
    let c = iv_min1(-iv_dot(v, n));
    let s = (iv(1.0) - c * c).sqrt();
    let tir = (iv(ratio) * s - iv(1.0)).widen(8.0);
    if tir.lo > 0.0 {
        return Branch::TotalReflection;
    }
    if tir.hi >= 0.0 {
        return Branch::Rounding("ratio * sin is within rounding of 1 (total internal reflection)");
    }
    let x = if schlick_of_sine { s } else { c };
    let r0 = (iv(1.0) - iv(ratio)) / (iv(1.0) + iv(ratio));
    let r0 = r0 * r0;
    let k = iv(1.0) - x;
    let k5 = k * k * k * k * k;
    let sch = (r0 + (iv(1.0) - r0) * k5).widen(8.0);
    if sch.lo > u {
        Branch::Reflect
    } else if sch.hi <= u {
        Branch::Refract
    } else {
        Branch::Rounding("schlick(cos, ratio) is within rounding of the random number")
    }
}

/// The course's `cos = min(-v . n, 1)` in `f64`.
fn course_cos(v: DVec3, n: DVec3) -> f64 {
    (-v.dot(n)).min(1.0)
}

/// What `refract(v, n, ratio)` returns on `branch` (the refracted direction by the course's
/// formula otherwise), and its tolerance.
fn refract_answer(v: DVec3, n: DVec3, ratio: f64, reflects: bool) -> (DVec3, f64) {
    if reflects {
        (reflect(v, n), vtol(1.0))
    } else {
        let cos = course_cos(v, n);
        let r = refracted(v, n, ratio, cos);
        // Near grazing refraction sqrt(|1 - |r_perp|^2|) loses digits: a looser tolerance.
        let perp = ratio * (v + cos * n);
        let rest = (1.0 - perp.length_squared()).abs();
        let tol = if rest > 1e-6 { vtol(1.0) } else { 1e-6 };
        (r, tol)
    }
}

fn class_of(branch: Branch) -> Class {
    match branch {
        Branch::Rounding(why) => Class::Ambiguous(why.to_string()),
        _ => Class::Definite,
    }
}

/// A unit direction arriving at the unit normal `n` at angle `theta` (radians) from it.
fn arriving(n: DVec3, tangent: DVec3, theta: f64) -> DVec3 {
    (theta.sin() * tangent - theta.cos() * n).normalize()
}

/// A random unit normal, a unit direction arriving at it, and its tangent.
fn random_arrival(r: &mut crate::render::PixelSampler) -> (DVec3, DVec3) {
    let n = mistakes::unit_vector(r);
    let t = n.any_orthonormal_pair().0;
    let theta = r.next_f64() * 1.55;
    let phi = r.next_f64() * std::f64::consts::TAU;
    let (t, b) = (t, n.cross(t));
    let tangent = phi.cos() * t + phi.sin() * b;
    (n, arriving(n, tangent, theta))
}

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![
        reflect_check(seed),
        refract_check(seed),
        schlick_check(seed),
        halfvector_check(seed),
        mirror_check(seed),
        dielectric::dielectric_check(seed),
        dielectric_choice_check(seed),
    ]
}

fn reflect_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        (DVec3::new(1.0, -1.0, 0.0), DVec3::Y),
        (DVec3::new(2.0, 3.0, -1.0), DVec3::Z),
        (DVec3::new(0.0, -6.0, 8.0), DVec3::Y),
    ];
    let mut r = stream(seed, "reflect");
    for _ in 0..8 {
        let n = mistakes::unit_vector(&mut r);
        let v = mistakes::unit_vector(&mut r) * (0.5 + 9.5 * r.next_f64());
        inputs.push((v, n));
    }
    let mut cases = Vec::new();
    let (mut sign, mut unit) = (Vec::new(), Vec::new());
    for (k, &(v, n)) in inputs.iter().enumerate() {
        let want = reflect(v, n);
        let tol = vtol(v.length());
        cases.push(Case {
            id: format!("reflect-{k:04}"),
            request: json!({"op": "reflect", "v": jvec(v), "n": jvec(n)}),
            expect: Expected::one("vector", Want::vector(want, tol)),
            class: Class::Definite,
            input: format!("v = {}, n = {}", py::list(v), py::list(n)),
            repro: py::script(
                &format!("print(rtm.reflect({}, {}).e)", py::vec(v), py::vec(n)),
                &py::list(want),
            ),
        });
        sign.push(Some(Expected::one(
            "vector",
            Want::vector(2.0 * v - want, tol),
        )));
        unit.push(Some(Expected::one(
            "vector",
            Want::vector(want.normalize(), tol),
        )));
    }
    FunctionCheck {
        id: "reflect",
        function: "RT_material.reflect(v, n)",
        week: week(6),
        given: false,
        op: "reflect",
        tolerance: "each component within 1e-9 max(1, |v|)",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "reflect_sign",
                    says: "reflect adds 2 (v . n) n instead of subtracting it (the ray goes on into the surface)",
                    standing: Standing::Mistake,
                    expect: sign,
                },
                Variant {
                    name: "reflect_normalised",
                    says: "reflect returns a unit vector (the course keeps v's length)",
                    standing: Standing::Mistake,
                    expect: unit,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// One refract case: unit `v`, unit `n`, `ratio`, the random number `u`.
struct RefractInput {
    v: DVec3,
    n: DVec3,
    ratio: f64,
    u: f64,
}

fn refract_inputs(seed: u64) -> Vec<RefractInput> {
    let s3 = 3f64.sqrt() / 2.0;
    let v30 = DVec3::new(0.5, -s3, 0.0);
    let v60 = DVec3::new(s3, -0.5, 0.0);
    let mut inputs = vec![
        RefractInput {
            v: v30,
            n: DVec3::Y,
            ratio: 1.0 / 1.5,
            u: 1.0,
        },
        RefractInput {
            v: v30,
            n: DVec3::Y,
            ratio: 1.0 / 1.5,
            u: 0.0,
        },
        RefractInput {
            v: v30,
            n: DVec3::Y,
            ratio: 1.0 / 1.5,
            u: 0.05,
        },
        RefractInput {
            v: v60,
            n: DVec3::Y,
            ratio: 1.5,
            u: 1.0,
        },
        RefractInput {
            v: -DVec3::Y,
            n: DVec3::Y,
            ratio: 1.0 / 1.5,
            u: 1.0,
        },
        RefractInput {
            v: v30,
            n: DVec3::Y,
            ratio: 1.5,
            u: 1.0,
        },
        RefractInput {
            v: v60,
            n: DVec3::Y,
            ratio: 0.5,
            u: 1.0,
        },
    ];
    let mut r = stream(seed, "refract");
    let ratios = [1.0 / 1.5, 1.5, 1.0 / 1.33, 2.0, 0.5, 1.0 / 2.4];
    for k in 0..18 {
        let (n, v) = random_arrival(&mut r);
        let u = match k % 3 {
            0 => 1.0,
            1 => 0.0,
            _ => r.next_f64(),
        };
        inputs.push(RefractInput {
            v,
            n,
            ratio: ratios[k % ratios.len()],
            u,
        });
    }
    inputs
}

fn refract_check(seed: u64) -> FunctionCheck {
    let inputs = refract_inputs(seed);
    let mut cases = Vec::new();
    let mut variants: Vec<(&'static str, &'static str, Vec<Option<Expected>>)> = vec![
        (
            "no_total_internal_reflection",
            "refract drops the ratio * sin > 1 test",
            Vec::new(),
        ),
        (
            "schlick_wrong_cosine",
            "refract feeds Schlick the sine of the angle instead of its cosine",
            Vec::new(),
        ),
        (
            "schlick_fraction_inverted",
            "Schlick's r0 is ((1 + x) / (1 - x))^2, above 1: refract always reflects",
            Vec::new(),
        ),
        (
            "refract_without_schlick",
            "refract reflects only under total internal reflection: Schlick's random choice is left out",
            Vec::new(),
        ),
    ];
    for (k, c) in inputs.iter().enumerate() {
        let branch = decide(c.v, c.n, c.ratio, c.u, false);
        let (want, tol) = refract_answer(c.v, c.n, c.ratio, branch.reflects());
        let expect = Expected::one("vector", Want::vector(want, tol));
        let tir = matches!(branch, Branch::TotalReflection);
        let answer = |reflects: bool| {
            let (w, t) = refract_answer(c.v, c.n, c.ratio, reflects);
            Some(Expected::one("vector", Want::vector(w, t)))
        };
        let definite = |b: Branch| !matches!(b, Branch::Rounding(_));
        // Without the test, the course's Schlick choice decides under total reflection too,
        // and the "refracted" direction is the formula's, with its absolute value.
        let sch = schlick(course_cos(c.v, c.n), c.ratio);
        variants[0]
            .2
            .push(if tir { answer(sch > c.u) } else { None });
        let wrong = decide(c.v, c.n, c.ratio, c.u, true);
        variants[1].2.push(if definite(wrong) && definite(branch) {
            answer(wrong.reflects())
        } else {
            None
        });
        let inverted = {
            let r0 = ((1.0 + c.ratio) / (1.0 - c.ratio)).powi(2);
            r0 + (1.0 - r0) * (1.0 - course_cos(c.v, c.n)).powi(5) > c.u
        };
        variants[2]
            .2
            .push(if definite(branch) && !tir && c.ratio != 1.0 {
                answer(inverted)
            } else {
                None
            });
        variants[3]
            .2
            .push(if definite(branch) { answer(tir) } else { None });
        let why = match branch {
            Branch::TotalReflection => "total internal reflection",
            Branch::Reflect => "Schlick's value is above the random number: it reflects",
            Branch::Refract => "it refracts",
            Branch::Rounding(_) => "rounding decides",
        };
        cases.push(Case {
            id: format!("refract-{k:04}"),
            request: json!({"op": "refract", "v": jvec(c.v), "n": jvec(c.n), "ratio": jnum(c.ratio), "random": [jnum(c.u)]}),
            expect,
            class: class_of(branch),
            input: format!(
                "v = {}, n = {}, ratio = {}, random_double() = {} ({why})",
                py::list(c.v),
                py::list(c.n),
                py::f(c.ratio),
                py::f(c.u)
            ),
            repro: py::script(
                &format!(
                    "{}\nprint(rtm.refract({}, {}, {}).e)",
                    py::random_doubles(&[c.u]),
                    py::vec(c.v),
                    py::vec(c.n),
                    py::f(c.ratio)
                ),
                &py::list(want),
            ),
        });
    }
    FunctionCheck {
        id: "refract",
        function: "RT_material.refract(v, n, ratio)",
        week: week(6),
        given: false,
        op: "refract",
        tolerance: "each component within 1e-9 (more near grazing refraction, where the course's square root loses digits); cases within rounding of total internal reflection or of Schlick's choice are not scored",
        body: Body::Cases {
            cases,
            variants: variants
                .into_iter()
                .map(|(name, says, expect)| Variant {
                    name,
                    says,
                    standing: Standing::Mistake,
                    expect,
                })
                .collect(),
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn schlick_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        (1.0, 1.5),
        (0.5, 1.5),
        (0.0, 1.0 / 1.5),
        (0.5, 1.0),
        (0.2, 1.0 / 1.5),
    ];
    let mut r = stream(seed, "schlick");
    for _ in 0..8 {
        inputs.push((r.next_f64(), 0.3 + 2.7 * r.next_f64()));
    }
    let mut cases = Vec::new();
    let mut inverted = Vec::new();
    for (k, &(cos, x)) in inputs.iter().enumerate() {
        let want = schlick(cos, x);
        cases.push(Case {
            id: format!("schlick-{k:04}"),
            request: json!({"op": "schlick", "cosine": jnum(cos), "ratio": jnum(x)}),
            expect: Expected::one(
                "value",
                Want::Number {
                    value: want,
                    tol: 1e-12,
                },
            ),
            class: Class::Definite,
            input: format!("cosine = {}, ratio = {}", py::f(cos), py::f(x)),
            repro: py::script(
                &format!("print(rtm.schlick({}, {}))", py::f(cos), py::f(x)),
                &py::f(want),
            ),
        });
        inverted.push((x != 1.0).then(|| {
            let r0 = ((1.0 + x) / (1.0 - x)).powi(2);
            let v = r0 + (1.0 - r0) * (1.0 - cos).powi(5);
            Expected::one(
                "value",
                Want::Number {
                    value: v,
                    tol: 1e-9 * v.abs().max(1.0),
                },
            )
        }));
    }
    FunctionCheck {
        id: "schlick",
        function: "RT_material.schlick(cosine, ratio)",
        week: week(6),
        given: false,
        op: "schlick",
        tolerance: "within 1e-12",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "schlick_fraction_inverted",
                says: "Schlick's r0 is ((1 + x) / (1 - x))^2, the fraction upside down",
                standing: Standing::Mistake,
                expect: inverted,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn halfvector_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        (DVec3::new(1.0, 2.0, 3.0), DVec3::new(3.0, 2.0, 1.0)),
        (DVec3::new(0.0, 2.0, 0.0), DVec3::new(1.0, 1.0, 0.0)),
    ];
    let mut r = stream(seed, "halfvector");
    for _ in 0..6 {
        let v = mistakes::unit_vector(&mut r) * (0.5 + 12.0 * r.next_f64());
        let l = mistakes::unit_vector(&mut r) * (0.5 + 3.0 * r.next_f64());
        inputs.push((v, l));
    }
    let (mut unit, mut of_units) = (Vec::new(), Vec::new());
    let mut cases = Vec::new();
    for (k, &(v, l)) in inputs.iter().enumerate() {
        let want = halfvector(v, l);
        let tol = vtol(v.length() + l.length());
        cases.push(Case {
            id: format!("halfvector-{k:04}"),
            request: json!({"op": "halfvector", "v": jvec(v), "l": jvec(l)}),
            expect: Expected::one("vector", Want::vector(want, tol)),
            class: Class::Definite,
            input: format!("V = {}, L = {}", py::list(v), py::list(l)),
            repro: py::script(
                &format!("print(rtm.halfvector({}, {}).e)", py::vec(v), py::vec(l)),
                &py::list(want),
            ),
        });
        unit.push(Some(Expected::one(
            "vector",
            Want::vector(want.normalize(), tol),
        )));
        of_units.push(Some(Expected::one(
            "vector",
            Want::vector(halfvector(v.normalize(), l.normalize()), tol),
        )));
    }
    FunctionCheck {
        id: "halfvector",
        function: "RT_material.halfvector(V, L)",
        week: week(8),
        given: false,
        op: "halfvector",
        tolerance: "each component within 1e-9 max(1, |V| + |L|)",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "halfvector_normalised",
                    says: "halfvector returns unit(V + L) (the course's is (V + L) / 2, not normalised)",
                    standing: Standing::Mistake,
                    expect: unit,
                },
                Variant {
                    name: "halfvector_of_unit_vectors",
                    says: "halfvector halves the unit V and L (the course halves them as they are)",
                    standing: Standing::Mistake,
                    expect: of_units,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// A hit for a scattering request: the ray `(origin, direction)` meets a surface at `point`
/// with outward normal `outward`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HitInput {
    pub(crate) origin: DVec3,
    pub(crate) direction: DVec3,
    pub(crate) point: DVec3,
    pub(crate) outward: DVec3,
}

impl HitInput {
    /// The normal facing the ray and whether the ray hits the front face, as
    /// `set_face_normal` decides (`d . outward < 0`).
    pub(crate) fn facing(&self) -> (DVec3, bool) {
        let front = self.direction.dot(self.outward) < 0.0;
        (if front { self.outward } else { -self.outward }, front)
    }

    pub(crate) fn json(&self) -> (serde_json::Value, serde_json::Value) {
        (
            json!({"origin": jvec(self.origin), "direction": jvec(self.direction)}),
            json!({"point": jvec(self.point), "normal": jvec(self.outward)}),
        )
    }

    pub(crate) fn words(&self) -> String {
        format!(
            "a ray from {} along {} hits {} (outward normal {})",
            py::list(self.origin),
            py::list(self.direction),
            py::list(self.point),
            py::list(self.outward)
        )
    }

    /// Python lines that make `ray` and `hit` for material expression `material`.
    pub(crate) fn py(&self, material: &str) -> String {
        format!(
            "m = {material}\nray = {}\n{}",
            py::ray(self.origin, self.direction, 0.0),
            py::hit(self.point, self.outward, "ray", "m")
        )
    }
}

/// The scattered ray's answer: origin, direction, attenuation.
pub(crate) fn scattered(point: DVec3, direction: DVec3, dtol: f64, attenuation: DVec3) -> Expected {
    Expected::one("scattered", Want::Bool(true))
        .and(
            "origin",
            Want::vector(point, vtol(point.abs().max_element())),
        )
        .and("direction", Want::vector(direction, dtol))
        .and("attenuation", Want::vector(attenuation, 1e-12))
}

fn mirror_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![HitInput {
        origin: DVec3::new(0.0, 2.0, 0.0),
        direction: DVec3::new(1.0, -2.0, 0.0),
        point: DVec3::new(1.0, 0.0, 0.0),
        outward: DVec3::Y,
    }];
    let mut r = stream(seed, "mirror");
    for k in 0..6 {
        let (n, v) = random_arrival(&mut r);
        let d = v * (0.5 + 14.0 * r.next_f64());
        let point = mistakes::unit_vector(&mut r) * 3.0;
        // Every other one from inside (the outward normal faces away from the ray).
        let outward = if k % 2 == 0 { n } else { -n };
        inputs.push(HitInput {
            origin: point - 2.0 * d,
            direction: d,
            point,
            outward,
        });
    }
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let mut cases = Vec::new();
    let mut unit = Vec::new();
    for (k, h) in inputs.iter().enumerate() {
        let (n, _) = h.facing();
        let want = reflect(h.direction, n);
        let tol = vtol(h.direction.length());
        let (ray, hit) = h.json();
        cases.push(Case {
            id: format!("mirror-{k:04}"),
            request: json!({"op": "scatter", "material": {"type": "mirror", "albedo": jvec(albedo)}, "ray": ray, "hit": hit}),
            expect: scattered(h.point, want, tol, albedo),
            class: Class::Definite,
            input: h.words(),
            repro: py::script(
                &format!(
                    "{}\ns = m.scattering(ray, hit)\n{}",
                    h.py(&format!("rtm.Mirror({})", py::color(albedo))),
                    py::PRINT_SCATTERED
                ),
                &format!("the direction {}", py::list(want)),
            ),
        });
        unit.push(Some(scattered(
            h.point,
            reflect(h.direction.normalize(), n),
            tol,
            albedo,
        )));
    }
    FunctionCheck {
        id: "mirror",
        function: "RT_material.Mirror.scattering(ray, hit)",
        week: week(6),
        given: false,
        op: "scatter",
        tolerance: "the direction's components within 1e-9 max(1, |d|), the attenuation within 1e-12",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "mirror_reflects_unit_direction",
                says: "Mirror reflects the unit direction (the course reflects the raw one, whose length week 8's cosine weighs)",
                standing: Standing::Mistake,
                expect: unit,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// The nine numbers of a scattering sample: origin, direction, attenuation.
pub(crate) fn scatter_samples(answer: &serde_json::Value) -> Result<Vec<Sample>, String> {
    let samples = answer
        .get("samples")
        .and_then(serde_json::Value::as_array)
        .ok_or("the answer has no \"samples\" list")?;
    samples
        .iter()
        .map(|s| {
            if s.is_null() {
                return Ok([f64::NAN; 9]);
            }
            let v = crate::weekly::expect::numbers(Some(s), 9).ok_or_else(|| {
                format!(
                    "a sample is not 9 numbers: {}",
                    crate::weekly::expect::show(s)
                )
            })?;
            let mut out = [0.0; 9];
            out.copy_from_slice(&v);
            Ok(out)
        })
        .collect()
}

/// Requests of `total` samples of `numbers` numbers each, in chunks whose answers stay well
/// under [`crate::candidate::process::protocol::MAX_RESULT_BYTES`] (about 22 bytes a number), each
/// with its own seed, derived from the checks' seed for its purpose ([`crate::secret`]).
pub(crate) fn sample_requests(
    base: serde_json::Value,
    total: usize,
    numbers: usize,
    seed: u64,
    id: &str,
) -> Vec<serde_json::Value> {
    let chunk = (crate::candidate::process::protocol::MAX_RESULT_BYTES * 2 / 3 / (24 * numbers))
        .clamp(1, 2000);
    let mut out = Vec::new();
    let mut left = total;
    while left > 0 {
        let n = left.min(chunk);
        left -= n;
        let mut req = base.clone();
        req["n"] = json!(n);
        req["seed"] = json!(crate::secret::derive32(
            seed,
            &format!("samples/{id}/{}", out.len())
        ));
        out.push(req);
    }
    out
}

fn dielectric_choice_check(seed: u64) -> FunctionCheck {
    // Into glass (IOR 1.5) at cos 0.2 from the normal y: Schlick's value 0.3546, fed the sine
    // 0.04: far apart.
    let n = DVec3::Y;
    let cos: f64 = 0.2;
    let v = DVec3::new((1.0 - cos * cos).sqrt(), -cos, 0.0);
    let hit = HitInput {
        origin: DVec3::new(0.0, 1.0, 0.0) - v,
        direction: v,
        point: DVec3::new(0.0, 1.0, 0.0),
        outward: n,
    };
    let ratio = 1.0 / 1.5;
    let vu = v.normalize();
    let c = course_cos(vu, n);
    let setting = DielectricSetting {
        point: hit.point,
        albedo: DVec3::ONE,
        reflected: reflect(vu, n),
        refracted: Some(refracted(vu, n, ratio, c)),
        p_reflect: schlick(c, ratio),
        p_wrong_cosine: schlick((1.0 - c * c).sqrt(), ratio),
    };
    let (ray, hj) = hit.json();
    let base = json!({"op": "sample_scatter", "material": {"type": "dielectric", "albedo": [1.0, 1.0, 1.0], "ior": 1.5}, "ray": ray, "hit": hj});
    FunctionCheck {
        id: "dielectric-choice",
        function: "RT_material.Dielectric.scattering(ray, hit) (its random choice)",
        week: week(6),
        given: false,
        op: "sample_scatter",
        tolerance: "every direction the reflected or the refracted one within 1e-9; the count of reflections by the exact binomial test",
        body: Body::Samples {
            requests: sample_requests(base, DIELECTRIC_SAMPLES, 9, seed, "dielectric-choice"),
            extract: Box::new(scatter_samples),
            check: SamplerCheck::dielectric(setting),
            repro: py::script(
                &format!(
                    "{}\nreflected = sum(m.scattering(ray, hit).scattered_ray.getDirection().y() > 0 for _ in range(2000))",
                    hit.py("rtm.Dielectric(rtu.Color(1.0, 1.0, 1.0), 1.5)")
                ),
                &format!(
                    "reflected / 2000 close to schlick(0.2, 1 / 1.5) = {}",
                    py::f(setting.p_reflect)
                ),
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}
