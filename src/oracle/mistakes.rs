//! Rust transcriptions of the course's intersection code: the naive formulas, each honest
//! variant the course's code admits (`docs/oracle.md`, "The course's semantics"), and a catalogue
//! of buggy ones.
//!
//! They follow Python's float semantics: a float division by zero raises (here
//! [`Answer::Err`]), comparisons with NaN are false, and nothing is fused. The fairness tests
//! require every honest variant to pass every definite vector, and the power tests require every
//! buggy variant to fail at least one; [`judge`] is the rule both use, and the checking code can
//! reuse it.

use super::generate::{add, cross, dot, scale, sub};
use super::vectors::{Class, Expect, RaySpec, ShapeKind, ShapeSpec};
use crate::geometry::Shape;

/// A hit as a variant reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VHit {
    /// The ray parameter.
    pub t: f64,
    /// The normal facing the ray.
    pub normal: [f64; 3],
    /// Whether the ray arrives from the outside.
    pub front_face: bool,
}

/// A variant's answer: a hit, a miss (`None`), or a raised error (Python's `ZeroDivisionError`).
pub type Answer = Result<Option<VHit>, &'static str>;

/// One transcription.
#[derive(Clone, Copy)]
pub struct Variant {
    /// A short name (`"sphere-course"`, `"quad-no-parallel-test"`, ...).
    pub name: &'static str,
    /// The shape it intersects.
    pub shape: ShapeKind,
    /// Whether a fair grader must accept it.
    pub honest: bool,
    /// The intersection routine.
    pub run: Routine,
}

/// An intersection routine: the answer for a shape, a ray and an interval `[t_min, t_max]`.
pub type Routine = fn(&ShapeSpec, &RaySpec, [f64; 2]) -> Answer;

impl Variant {
    /// A variant a fair grader must accept.
    pub const fn honest(name: &'static str, shape: ShapeKind, run: Routine) -> Variant {
        Variant {
            name,
            shape,
            honest: true,
            run,
        }
    }

    /// A variant with a mistake a grader must catch.
    pub const fn buggy(name: &'static str, shape: ShapeKind, run: Routine) -> Variant {
        Variant {
            name,
            shape,
            honest: false,
            run,
        }
    }
}

impl std::fmt::Debug for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// Whether `answer` is right for a definite `expect` (`Ok`), or why not. Non-definite classes
/// accept anything.
pub fn judge(expect: &Expect, answer: &Answer) -> Result<(), String> {
    match (expect.class, answer) {
        (Class::Ambiguous | Class::Any, _) => Ok(()),
        (_, Err(e)) => Err(format!("raised {e}")),
        (Class::Miss, Ok(None)) => Ok(()),
        (Class::Miss, Ok(Some(h))) => Err(format!("hit at t = {} where the ray misses", h.t)),
        (Class::Hit, Ok(None)) => Err("missed where the ray hits".into()),
        (Class::Hit, Ok(Some(h))) => {
            let (t, tol) = (expect.t.unwrap_or(f64::NAN), expect.t_tol.unwrap_or(0.0));
            if (h.t - t).abs().is_nan() || (h.t - t).abs() > tol {
                return Err(format!("t = {} but expected {t} +- {tol:e}", h.t));
            }
            if let Some(n) = expect.normal {
                let off = (0..3)
                    .map(|i| (h.normal[i] - n[i]).abs())
                    .fold(0.0, f64::max);
                if h.normal.iter().any(|x| !x.is_finite())
                    || off > expect.normal_tol.unwrap_or(1e-6)
                {
                    return Err(format!("normal {:?} but expected {n:?}", h.normal));
                }
            }
            if expect.front_face.is_some_and(|f| f != h.front_face) {
                return Err(format!("front_face = {} is wrong", h.front_face));
            }
            Ok(())
        }
    }
}

fn div(a: f64, b: f64) -> Result<f64, &'static str> {
    if b == 0.0 {
        Err("ZeroDivisionError")
    } else {
        Ok(a / b)
    }
}

fn vdiv(v: [f64; 3], s: f64) -> Result<[f64; 3], &'static str> {
    Ok([div(v[0], s)?, div(v[1], s)?, div(v[2], s)?])
}

fn unit(v: [f64; 3]) -> Result<[f64; 3], &'static str> {
    vdiv(v, dot(v, v).sqrt())
}

fn face(d: [f64; 3], outward: [f64; 3], t: f64, reversed: bool) -> VHit {
    let mut front_face = dot(d, outward) < 0.0;
    let normal = if front_face {
        outward
    } else {
        outward.map(|x| -x)
    };
    if reversed {
        front_face = !front_face;
    }
    VHit {
        t,
        normal,
        front_face,
    }
}

/// Knobs of the sphere transcription.
#[derive(Clone, Copy, Default)]
struct SphereOpts {
    closed: bool,
    disc_le: bool,
    full_b: bool,
    normalise: bool,
    far_first: bool,
    no_interval: bool,
    raw_normal: bool,
    abs_radius: bool,
    r_not_squared: bool,
    b_sign: bool,
    no_a_in_disc: bool,
    front_reversed: bool,
}

fn sphere_with(o: SphereOpts, shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Sphere { center, radius } = *shape else {
        return Ok(None);
    };
    let (orig, mut d) = (ray.origin, ray.direction);
    let len = dot(d, d).sqrt();
    if o.normalise {
        d = unit(d)?;
    }
    let oc = sub(orig, center);
    let a = dot(d, d);
    let r2 = if o.r_not_squared {
        radius
    } else {
        radius * radius
    };
    let c = dot(oc, oc) - r2;
    let (half_b, disc) = if o.full_b {
        let b = 2.0 * dot(oc, d);
        (b, b * b - 4.0 * a * c)
    } else {
        let hb = dot(oc, d);
        let disc = if o.no_a_in_disc {
            hb * hb - c
        } else {
            hb * hb - a * c
        };
        (hb, disc)
    };
    if disc < 0.0 || (o.disc_le && disc <= 0.0) {
        return Ok(None);
    }
    let sq = disc.sqrt();
    let den = if o.full_b { 2.0 * a } else { a };
    let hb = if o.b_sign { -half_b } else { half_b };
    let mut roots = [div(-hb - sq, den)?, div(-hb + sq, den)?];
    if o.far_first {
        roots.swap(0, 1);
    }
    let to_t = |t: f64| if o.normalise { t / len } else { t };
    let inside = |t: f64| {
        o.no_interval
            || if o.closed {
                iv[0] <= t && t <= iv[1]
            } else {
                iv[0] < t && t < iv[1]
            }
    };
    let Some(root) = roots.into_iter().map(to_t).find(|&t| inside(t)) else {
        return Ok(None);
    };
    let p = add(orig, scale(ray.direction, root));
    let outward = if o.raw_normal {
        sub(p, center)
    } else if o.abs_radius {
        vdiv(sub(p, center), radius.abs())?
    } else {
        vdiv(sub(p, center), radius)?
    };
    Ok(Some(face(ray.direction, outward, root, o.front_reversed)))
}

/// Knobs of the quad / course-style triangle transcription.
#[derive(Clone, Copy, Default)]
struct QuadOpts {
    triangle: bool,
    open_interval: bool,
    strict_edges: bool,
    exact_zero: bool,
    normalise: bool,
    alpha_sign: bool,
    w_is_normal: bool,
    no_parallel: bool,
    wrong_d: bool,
    front_reversed: bool,
    no_interval: bool,
    no_third_edge: bool,
    swap_uv_in_beta: bool,
}

fn quad_with(o: QuadOpts, shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let (q, u, v) = match *shape {
        ShapeSpec::Quad { q, u, v } => (q, u, v),
        ShapeSpec::Triangle { a, b, c } => (a, sub(b, a), sub(c, a)),
        _ => return Ok(None),
    };
    // The constructor.
    let uxv = cross(u, v);
    let normal = unit(uxv)?;
    let big_d = if o.wrong_d {
        dot(uxv, q)
    } else {
        dot(normal, q)
    };
    let w = if o.w_is_normal {
        normal
    } else {
        vdiv(uxv, dot(uxv, uxv))?
    };
    // intersect
    let (orig, mut d) = (ray.origin, ray.direction);
    let len = dot(d, d).sqrt();
    if o.normalise {
        d = unit(d)?;
    }
    let denom = dot(normal, d);
    if !o.no_parallel
        && (if o.exact_zero {
            denom == 0.0
        } else {
            denom.abs() < 1e-8
        })
    {
        return Ok(None);
    }
    let mut t = div(big_d - dot(normal, orig), denom)?;
    if o.normalise {
        t /= len;
    }
    let in_iv = if o.open_interval {
        iv[0] < t && t < iv[1]
    } else {
        iv[0] <= t && t <= iv[1]
    };
    if !o.no_interval && !in_iv {
        return Ok(None);
    }
    let p = sub(add(orig, scale(ray.direction, t)), q);
    let alpha = if o.alpha_sign {
        dot(w, cross(v, p))
    } else {
        dot(w, cross(p, v))
    };
    let beta = if o.swap_uv_in_beta {
        dot(w, cross(p, u))
    } else {
        dot(w, cross(u, p))
    };
    let within = |x: f64| {
        if o.strict_edges {
            0.0 < x && x < 1.0
        } else {
            (0.0..=1.0).contains(&x)
        }
    };
    let interior = if o.triangle && !o.no_third_edge {
        let ge = |x: f64| if o.strict_edges { x > 0.0 } else { x >= 0.0 };
        let s = alpha + beta;
        ge(alpha) && ge(beta) && (if o.strict_edges { s < 1.0 } else { s <= 1.0 })
    } else {
        within(alpha) && within(beta)
    };
    if !interior {
        return Ok(None);
    }
    Ok(Some(face(ray.direction, normal, t, o.front_reversed)))
}

/// Möller–Trumbore without an epsilon (`det == 0` is a miss), closed edges and interval.
fn moller_trumbore(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Triangle { a, b, c } = *shape else {
        return Ok(None);
    };
    let (e1, e2) = (sub(b, a), sub(c, a));
    let d = ray.direction;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == 0.0 {
        return Ok(None);
    }
    let inv = div(1.0, det)?;
    let s = sub(ray.origin, a);
    let bu = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&bu) {
        return Ok(None);
    }
    let qv = cross(s, e1);
    let bv = dot(d, qv) * inv;
    if !(bv >= 0.0 && bu + bv <= 1.0) {
        return Ok(None);
    }
    let t = dot(e2, qv) * inv;
    if !(iv[0] <= t && t <= iv[1]) {
        return Ok(None);
    }
    Ok(Some(face(d, unit(cross(e1, e2))?, t, false)))
}

/// The reference tracer (`rtoracle::geometry`).
fn reference(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let interval = crate::geometry::Interval::new(iv[0], iv[1]);
    Ok(shape
        .object()
        .intersect(&ray.ray(), interval)
        .map(|h| VHit {
            t: h.t,
            normal: h.normal.to_array(),
            front_face: h.front_face,
        }))
}

/// Ray Tracing in One Weekend's own C++ (`sphere.h`, `quad.h`, `hittable.h`), transcribed in the
/// float type `$t`: every input rounded to `$t` first, all arithmetic in `$t`, C++ semantics
/// (a division by zero gives an infinity or NaN, never an error).
macro_rules! rtiow {
    ($sphere:ident, $quad:ident, $t:ty, $far_first:expr) => {
        fn $sphere(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
            let ShapeSpec::Sphere { center, radius } = *shape else {
                return Ok(None);
            };
            let v = |x: [f64; 3]| x.map(|c| c as $t);
            let dot = |a: [$t; 3], b: [$t; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let (c, r) = (v(center), radius as $t);
            let (o, d) = (v(ray.origin), v(ray.direction));
            let (tmin, tmax) = (iv[0] as $t, iv[1] as $t);
            let surrounds = |x: $t| tmin < x && x < tmax;
            let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
            let a = dot(d, d);
            let half_b = dot(oc, d);
            let cc = dot(oc, oc) - r * r;
            let discriminant = half_b * half_b - a * cc;
            if discriminant < 0.0 {
                return Ok(None);
            }
            let sqrtd = discriminant.sqrt();
            let (first, second) = ((-half_b - sqrtd) / a, (-half_b + sqrtd) / a);
            let (first, second) = if $far_first {
                (second, first)
            } else {
                (first, second)
            };
            let mut root = first;
            if !surrounds(root) {
                root = second;
                if !surrounds(root) {
                    return Ok(None);
                }
            }
            let p = [0, 1, 2].map(|i| o[i] + root * d[i]);
            let outward = [0, 1, 2].map(|i| (p[i] - c[i]) / r);
            let front_face = dot(d, outward) < 0.0;
            let normal = outward.map(|x| if front_face { x as f64 } else { -x as f64 });
            Ok(Some(VHit {
                t: root as f64,
                normal,
                front_face,
            }))
        }

        fn $quad(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
            let ShapeSpec::Quad { q, u, v: e } = *shape else {
                return Ok(None);
            };
            let v = |x: [f64; 3]| x.map(|c| c as $t);
            let dot = |a: [$t; 3], b: [$t; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let cross = |a: [$t; 3], b: [$t; 3]| {
                [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ]
            };
            let (q, u, vv) = (v(q), v(u), v(e));
            let (o, d) = (v(ray.origin), v(ray.direction));
            let (tmin, tmax) = (iv[0] as $t, iv[1] as $t);
            let n = cross(u, vv);
            let len = dot(n, n).sqrt();
            let normal = n.map(|x| x / len);
            let big_d = dot(normal, q);
            let nn = dot(n, n);
            let w = n.map(|x| x / nn);
            let denom = dot(normal, d);
            if denom.abs() < 1e-8 {
                return Ok(None);
            }
            let t = (big_d - dot(normal, o)) / denom;
            if !(tmin <= t && t <= tmax) {
                return Ok(None);
            }
            let p = [0, 1, 2].map(|i| o[i] + t * d[i] - q[i]);
            let alpha = dot(w, cross(p, vv));
            let beta = dot(w, cross(u, p));
            if !((0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)) {
                return Ok(None);
            }
            let front_face = dot(d, normal) < 0.0;
            Ok(Some(VHit {
                t: t as f64,
                normal: normal.map(|x| if front_face { x as f64 } else { -x as f64 }),
                front_face,
            }))
        }
    };
}

rtiow!(rtiow_sphere, rtiow_quad, f64, false);
rtiow!(rtiow_sphere_f32, rtiow_quad_f32, f32, false);
rtiow!(rtiow_sphere_f32_far_first, rtiow_quad_f32_unused, f32, true);

/// Ray Tracing in One Weekend's C++ sphere and quad in `f64` (`half_b^2 - a c`, the near root
/// then the far root with `ray_t.surrounds`, the quad's `fabs(denom) < 1e-8` on the unnormalised
/// direction, `set_face_normal`). Honest under the course profile; the robust profile finds its
/// cancellation on far and scaled spheres.
pub fn rtiow() -> Vec<Variant> {
    vec![
        Variant::honest("sphere-rtiow", ShapeKind::Sphere, rtiow_sphere),
        Variant::honest("quad-rtiow", ShapeKind::Quad, rtiow_quad),
    ]
}

/// The same code in `f32` (inputs rounded to `f32`): honest under `--precision f32`.
pub fn rtiow_f32() -> Vec<Variant> {
    vec![
        Variant::honest("sphere-rtiow-f32", ShapeKind::Sphere, rtiow_sphere_f32),
        Variant::honest("quad-rtiow-f32", ShapeKind::Quad, rtiow_quad_f32),
    ]
}

/// The reference's robust sphere formulas (`a (r^2 - |f - (f.d/a) d|^2)`, Ray Tracing Gems
/// roots) transcribed in `f32`, inputs rounded to `f32`: honest under `robust/f32`.
fn robust_sphere_f32(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Sphere { center, radius } = *shape else {
        return Ok(None);
    };
    let v = |x: [f64; 3]| x.map(|c| c as f32);
    let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (c, r, o, d) = (v(center), radius as f32, v(ray.origin), v(ray.direction));
    let (tmin, tmax) = (iv[0] as f32, iv[1] as f32);
    let f = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let (a, half_b, r2) = (dot(d, d), dot(f, d), r * r);
    let cc = dot(f, f) - r2;
    let k = half_b / a;
    let perp = [f[0] - d[0] * k, f[1] - d[1] * k, f[2] - d[2] * k];
    let disc = a * (r2 - dot(perp, perp));
    if disc.is_nan() || disc < 0.0 {
        return Ok(None);
    }
    let q = -(half_b + disc.sqrt().copysign(half_b));
    let (t0, t1) = if q == 0.0 {
        (-half_b / a, -half_b / a)
    } else {
        (cc / q, q / a)
    };
    let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
    let root = [near, far].into_iter().find(|&t| tmin < t && t < tmax);
    let Some(root) = root else {
        return Ok(None);
    };
    let outward = [0, 1, 2].map(|i| (o[i] + root * d[i] - c[i]) / r);
    let front_face = dot(d, outward) < 0.0;
    Ok(Some(VHit {
        t: root as f64,
        normal: outward.map(|x| if front_face { x as f64 } else { -x as f64 }),
        front_face,
    }))
}

/// The reference's robust sphere in `f32` (with RTIOW's `f32` quad, which is the reference's
/// quad formula): honest under `robust/f32`.
pub fn robust_f32() -> Vec<Variant> {
    vec![
        Variant::honest("sphere-robust-f32", ShapeKind::Sphere, robust_sphere_f32),
        Variant::honest("quad-rtiow-f32", ShapeKind::Quad, rtiow_quad_f32),
    ]
}

/// The `f32` sphere with a bug (the far root tried first): `--precision f32` must still fail it.
pub fn rtiow_f32_buggy() -> Vec<Variant> {
    let _ = rtiow_quad_f32_unused;
    vec![Variant {
        name: "sphere-rtiow-f32-far-root-first",
        shape: ShapeKind::Sphere,
        honest: false,
        run: rtiow_sphere_f32_far_first,
    }]
}

macro_rules! sphere_variant {
    ($name:literal, $honest:expr, { $($k:ident),* }) => {
        Variant {
            name: $name,
            shape: ShapeKind::Sphere,
            honest: $honest,
            run: |s, r, i| sphere_with(SphereOpts { $($k: true,)* ..Default::default() }, s, r, i),
        }
    };
}

macro_rules! plane_variant {
    ($name:literal, $kind:expr, $honest:expr, { $($k:ident),* }) => {
        Variant {
            name: $name,
            shape: $kind,
            honest: $honest,
            run: |s, r, i| quad_with(QuadOpts { $($k: true,)* ..Default::default() }, s, r, i),
        }
    };
}

/// The honest variants: the course's formulas and every variation a fair grader must accept.
pub fn honest() -> Vec<Variant> {
    use ShapeKind::{Quad, Triangle};
    vec![
        sphere_variant!("sphere-course", true, {}),
        sphere_variant!("sphere-closed-interval", true, { closed }),
        sphere_variant!("sphere-disc-le-zero", true, { disc_le }),
        sphere_variant!("sphere-full-quadratic", true, { full_b }),
        sphere_variant!("sphere-normalised-direction", true, { normalise }),
        sphere_variant!("sphere-full-quadratic-closed", true, { full_b, closed }),
        Variant::honest("sphere-reference", ShapeKind::Sphere, reference),
        plane_variant!("quad-course", Quad, true, {}),
        plane_variant!("quad-open-interval", Quad, true, { open_interval }),
        plane_variant!("quad-strict-edges", Quad, true, { strict_edges }),
        plane_variant!("quad-denom-eq-zero", Quad, true, { exact_zero }),
        plane_variant!("quad-normalised-direction", Quad, true, { normalise }),
        Variant {
            name: "quad-reference",
            shape: Quad,
            honest: true,
            run: reference,
        },
        plane_variant!("triangle-course-style", Triangle, true, { triangle, exact_zero }),
        plane_variant!("triangle-course-style-strict", Triangle, true, { triangle, exact_zero, strict_edges, open_interval }),
        Variant {
            name: "triangle-moller-trumbore",
            shape: Triangle,
            honest: true,
            run: moller_trumbore,
        },
        Variant {
            name: "triangle-reference",
            shape: Triangle,
            honest: true,
            run: reference,
        },
    ]
}

/// The buggy variants: each must fail at least one definite vector of the default suite.
pub fn buggy() -> Vec<Variant> {
    use ShapeKind::{Quad, Triangle};
    vec![
        sphere_variant!("sphere-far-root-first", false, { far_first }),
        sphere_variant!("sphere-no-interval-check", false, { no_interval }),
        sphere_variant!("sphere-unnormalised-normal", false, { raw_normal }),
        sphere_variant!("sphere-abs-radius-in-normal", false, { abs_radius }),
        sphere_variant!("sphere-r-instead-of-r-squared", false, { r_not_squared }),
        sphere_variant!("sphere-sign-error-in-b", false, { b_sign }),
        sphere_variant!("sphere-disc-without-a", false, { no_a_in_disc }),
        sphere_variant!("sphere-front-face-reversed", false, { front_reversed }),
        plane_variant!("quad-sign-error-in-alpha", Quad, false, { alpha_sign }),
        plane_variant!("quad-w-is-unit-normal", Quad, false, { w_is_normal }),
        plane_variant!("quad-no-parallel-test", Quad, false, { no_parallel }),
        plane_variant!("quad-wrong-d", Quad, false, { wrong_d }),
        plane_variant!("quad-front-face-reversed", Quad, false, { front_reversed }),
        plane_variant!("quad-no-interval-check", Quad, false, { no_interval }),
        plane_variant!("quad-u-v-swapped-in-beta", Quad, false, { swap_uv_in_beta }),
        plane_variant!("triangle-missing-third-edge", Triangle, false, { triangle, exact_zero, no_third_edge }),
        plane_variant!("triangle-no-parallel-test", Triangle, false, { triangle, no_parallel }),
    ]
}

// ---- More known mistakes, for the candidate diagnosis (`candidate::judging::diagnose`). ----

/// The course's sphere (as `sphere-course`) with the roots written `-half_b -+ sqrt_disc / a`
/// (the division binds tighter).
fn sphere_sqrt_precedence(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Sphere { center, radius } = *shape else {
        return Ok(None);
    };
    let (orig, d) = (ray.origin, ray.direction);
    let oc = sub(orig, center);
    let a = dot(d, d);
    let hb = dot(oc, d);
    let c = dot(oc, oc) - radius * radius;
    let disc = hb * hb - a * c;
    if disc < 0.0 {
        return Ok(None);
    }
    let sq = disc.sqrt();
    let surrounds = |t: f64| iv[0] < t && t < iv[1];
    let mut root = -hb - div(sq, a)?;
    if !surrounds(root) {
        root = -hb + div(sq, a)?;
        if !surrounds(root) {
            return Ok(None);
        }
    }
    let p = add(orig, scale(d, root));
    let outward = vdiv(sub(p, center), radius)?;
    Ok(Some(face(d, outward, root, false)))
}

/// The course's sphere without `set_face_normal`: the outward normal, and `front_face` left
/// at the `Hitinfo`'s `True`.
fn sphere_normal_not_flipped(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let hit = sphere_with(SphereOpts::default(), shape, ray, iv)?;
    Ok(hit.map(|h| VHit {
        normal: if h.front_face {
            h.normal
        } else {
            h.normal.map(|x| -x)
        },
        front_face: true,
        ..h
    }))
}

/// Knobs of the extra quad transcription.
#[derive(Clone, Copy, Default)]
struct QuadExtra {
    beta_uses_v: bool,
    d_from_u: bool,
    upper_bounds_only: bool,
    unnormalised_normal: bool,
}

/// The course's quad (as `quad-course`) with one of the extra mistakes.
fn quad_extra(o: QuadExtra, shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Quad { q, u, v } = *shape else {
        return Ok(None);
    };
    let uxv = cross(u, v);
    let normal = if o.unnormalised_normal {
        uxv
    } else {
        unit(uxv)?
    };
    let big_d = if o.d_from_u {
        dot(normal, u)
    } else {
        dot(normal, q)
    };
    let w = vdiv(uxv, dot(uxv, uxv))?;
    let (orig, d) = (ray.origin, ray.direction);
    let denom = dot(normal, d);
    if denom.abs() < 1e-8 {
        return Ok(None);
    }
    let t = div(big_d - dot(normal, orig), denom)?;
    if !(iv[0] <= t && t <= iv[1]) {
        return Ok(None);
    }
    let p = sub(add(orig, scale(d, t)), q);
    let alpha = dot(w, cross(p, v));
    let beta = if o.beta_uses_v {
        dot(w, cross(v, p))
    } else {
        dot(w, cross(u, p))
    };
    let interior = if o.upper_bounds_only {
        !(alpha > 1.0 || beta > 1.0)
    } else {
        (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta)
    };
    if !interior {
        return Ok(None);
    }
    Ok(Some(face(d, normal, t, false)))
}

/// Möller–Trumbore with the course's `near_zero(det)`: `|det| < 1e-8` on the unnormalised
/// determinant, which misses small triangles (and long rays' grazing ones).
fn moller_trumbore_absolute_epsilon(shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) -> Answer {
    let ShapeSpec::Triangle { a, b, c } = *shape else {
        return Ok(None);
    };
    let (e1, e2) = (sub(b, a), sub(c, a));
    let d = ray.direction;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-8 {
        return Ok(None);
    }
    moller_trumbore(shape, ray, iv)
}

/// A quad variant making the one mistake of [`QuadExtra`] named by `field`.
macro_rules! quad_mistake {
    ($name:literal, $field:ident) => {
        Variant {
            name: $name,
            shape: ShapeKind::Quad,
            honest: false,
            run: |s, r, i| {
                let mistake = QuadExtra {
                    $field: true,
                    ..Default::default()
                };
                quad_extra(mistake, s, r, i)
            },
        }
    };
}

/// More buggy variants (the diagnosis's catalogue is [`buggy`] and these): each must fail at
/// least one definite vector of the default suite.
pub fn buggy_extra() -> Vec<Variant> {
    vec![
        Variant::buggy(
            "sphere-sqrt-precedence",
            ShapeKind::Sphere,
            sphere_sqrt_precedence,
        ),
        Variant::buggy(
            "sphere-normal-not-flipped",
            ShapeKind::Sphere,
            sphere_normal_not_flipped,
        ),
        quad_mistake!("quad-beta-uses-v", beta_uses_v),
        quad_mistake!("quad-d-from-u", d_from_u),
        quad_mistake!("quad-interior-upper-bounds-only", upper_bounds_only),
        quad_mistake!("quad-unnormalised-normal", unnormalised_normal),
        Variant::buggy(
            "triangle-absolute-epsilon",
            ShapeKind::Triangle,
            moller_trumbore_absolute_epsilon,
        ),
    ]
}

#[cfg(test)]
mod extra_tests {
    use super::*;
    use crate::oracle::suite::default_suite;

    #[test]
    fn every_extra_buggy_variant_fails_a_definite_vector_and_differs_from_the_others() {
        let suite = default_suite(0);
        // The failing vectors and the wrong answers given on them.
        let fails = |v: &Variant| -> Vec<String> {
            suite
                .iter()
                .filter(|c| c.shape.kind() == v.shape && c.expect.class.is_definite())
                .filter_map(|c| {
                    let answer = (v.run)(&c.shape, &c.ray, c.interval);
                    judge(&c.expect, &answer)
                        .is_err()
                        .then(|| format!("{} {answer:?}", c.id))
                })
                .collect()
        };
        let old: Vec<Vec<String>> = buggy().iter().map(fails).collect();
        for v in buggy_extra() {
            let f = fails(&v);
            assert!(!f.is_empty(), "{} passes every definite vector", v.name);
            assert!(
                !old.contains(&f),
                "{} answers as an existing variant",
                v.name
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::profile::{Judging, Precision, Profile};
    use crate::oracle::suite::default_suite;

    fn failures(v: &Variant, suite: &[crate::oracle::vectors::Case]) -> Vec<String> {
        suite
            .iter()
            .filter(|c| c.shape.kind() == v.shape && c.expect.class.is_definite())
            .filter_map(|c| {
                judge(&c.expect, &(v.run)(&c.shape, &c.ray, c.interval))
                    .err()
                    .map(|e| format!("{}: {e}", c.id))
            })
            .collect()
    }

    #[test]
    fn every_honest_variant_passes_every_definite_vector() {
        let suite: Vec<_> = (0..3).flat_map(default_suite).collect();
        let mut bad = vec![];
        for v in honest() {
            let f = failures(&v, &suite);
            if !f.is_empty() {
                bad.push(format!(
                    "{} fails {} vectors, e.g. {:?}",
                    v.name,
                    f.len(),
                    &f[..f.len().min(3)]
                ));
            }
        }
        assert!(bad.is_empty(), "{bad:#?}");
    }

    fn judged(j: Judging) -> Vec<crate::oracle::vectors::Case> {
        crate::oracle::suite::default_suite_with(0, j)
    }

    #[test]
    fn the_reference_passes_the_robust_profile_on_the_default_suite() {
        let suite = judged(Judging::ROBUST);
        for v in honest().iter().filter(|v| v.name.ends_with("-reference")) {
            let f = failures(v, &suite);
            assert!(f.is_empty(), "{} fails {:?}", v.name, &f[..f.len().min(5)]);
        }
        // The robust profile is not "accept everything": it still scores most of the suite.
        let definite = suite
            .iter()
            .filter(|c| c.expect.class.is_definite())
            .count();
        assert!(definite * 10 >= suite.len() * 6, "{definite} definite");
    }

    #[test]
    fn rtiow_passes_the_course_profile_and_fails_the_robust_one_on_far_or_scaled_spheres() {
        let course = judged(Judging::COURSE);
        let robust = judged(Judging::ROBUST);
        let mut robust_sphere_failures = vec![];
        for v in rtiow() {
            let f = failures(&v, &course);
            assert!(
                f.is_empty(),
                "{} fails course: {:?}",
                v.name,
                &f[..f.len().min(5)]
            );
            if v.shape == ShapeKind::Sphere {
                robust_sphere_failures = failures(&v, &robust);
            }
        }
        eprintln!(
            "RTIOW's sphere fails {} robust vectors of the default suite, e.g. {:?}",
            robust_sphere_failures.len(),
            &robust_sphere_failures[..robust_sphere_failures.len().min(2)]
        );
        assert!(
            robust_sphere_failures
                .iter()
                .any(|f| f.starts_with("sphere-far-") || f.starts_with("sphere-scale-")),
            "{robust_sphere_failures:?}"
        );
    }

    #[test]
    fn f32_code_passes_the_f32_profiles_but_not_f64_and_a_buggy_f32_fails() {
        for profile in [Profile::Course, Profile::Robust] {
            let suite = judged(Judging::new(profile, Precision::F32));
            // Naive f32 code under course/f32; the robust formulas in f32 under robust/f32
            // (which, like robust/f64, finds the naive formula's cancellation).
            let honest = if profile == Profile::Course {
                rtiow_f32()
            } else {
                robust_f32()
            };
            for v in honest {
                let f = failures(&v, &suite);
                assert!(
                    f.is_empty(),
                    "{} fails {profile}/f32: {:?}",
                    v.name,
                    &f[..f.len().min(5)]
                );
            }
            let bug = &rtiow_f32_buggy()[0];
            assert!(
                !failures(bug, &suite).is_empty(),
                "{profile}/f32 accepts {}",
                bug.name
            );
            // Still a real test: most sphere and quad vectors stay definite in f32.
            let definite = suite
                .iter()
                .filter(|c| c.expect.class.is_definite() && c.shape.kind() == ShapeKind::Sphere)
                .count();
            assert!(
                definite >= 500,
                "{definite} definite sphere vectors in {profile}/f32"
            );
        }
        let f64_suite = judged(Judging::COURSE);
        for v in rtiow_f32() {
            assert!(
                !failures(&v, &f64_suite).is_empty(),
                "{} passes course/f64",
                v.name
            );
        }
    }

    #[test]
    fn every_buggy_variant_fails_a_definite_vector() {
        let suite = default_suite(0);
        let list = buggy();
        assert!(list.len() >= 12);
        for v in list {
            let f = failures(&v, &suite);
            assert!(!f.is_empty(), "{} passes every definite vector", v.name);
        }
    }
}
