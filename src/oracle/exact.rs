//! Exact decisions and exact hit records of the vector file's cases.
//!
//! Every `f64` is a dyadic rational and every deciding quantity of the three primitives is a
//! polynomial in the inputs, so the decisions of [`crate::arithmetic`] settle them exactly: the
//! interval filter first, exact dyadic arithmetic when it cannot decide ([`decide`]). This module
//! applies them to [`ShapeSpec`] and [`RaySpec`], and computes what a hit records (`t`, the
//! point, the normal, the surface coordinates) from the exact quantities, rounded once.

use std::cmp::Ordering;

pub use crate::arithmetic::{Decision, Dyadic, Num, PlaneSigns, Root, V3};
use crate::arithmetic::{Iv, PlaneKind};
use crate::geometry::PARALLEL_EPSILON;

use super::vectors::{RaySpec, ShapeSpec};

/// Whether a case's inputs are all finite (NaN or an infinity anywhere but the interval ends).
pub fn inputs_finite(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> bool {
    shape.numbers().iter().all(|x| x.is_finite())
        && ray
            .origin
            .iter()
            .chain(&ray.direction)
            .all(|x| x.is_finite())
        && !interval[0].is_nan()
        && !interval[1].is_nan()
        && interval[0] != f64::INFINITY
        && interval[1] != f64::NEG_INFINITY
}

/// The sphere decision in arithmetic `N`; `None` when `N` cannot decide.
pub fn sphere_decide<N: Num>(
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<Decision> {
    crate::arithmetic::sphere_decide::<N>(center, radius, &ray.line(), interval)
}

/// The quad (`triangle == false`, with the course's parallel threshold) or triangle decision in
/// arithmetic `N`, with the signs of its deciding quantities; `None` when `N` cannot decide.
pub fn plane_decide<N: Num>(
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    triangle: bool,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<(Decision, PlaneSigns)> {
    let kind = if triangle {
        PlaneKind::Triangle
    } else {
        PlaneKind::Quad {
            parallel_epsilon: PARALLEL_EPSILON,
        }
    };
    crate::arithmetic::plane_decide::<N>(q, u, v, kind, &ray.line(), interval)
}

/// The exact decision of a case with finite inputs, by the interval filter when it can and by
/// exact dyadic arithmetic otherwise. Also says whether the filter decided.
pub fn decide(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> (Decision, bool) {
    if let Some(d) = decide_with::<Iv>(shape, ray, interval) {
        return (d, true);
    }
    (
        decide_with::<Dyadic>(shape, ray, interval).expect("exact arithmetic always decides"),
        false,
    )
}

/// The decision in arithmetic `N` only (`None` when `N` cannot decide).
pub fn decide_with<N: Num>(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<Decision> {
    match *shape {
        ShapeSpec::Sphere { center, radius } => sphere_decide::<N>(center, radius, ray, interval),
        ShapeSpec::Quad { q, u, v } => {
            plane_decide::<N>(q, u, v, false, ray, interval).map(|x| x.0)
        }
        ShapeSpec::Triangle { a, b, c } => {
            plane_decide::<N>(a, b, c, true, ray, interval).map(|x| x.0)
        }
    }
}

/// The signs of a quad's or triangle's deciding quantities, exactly (filter first).
pub fn plane_signs(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Option<PlaneSigns> {
    let (q, u, v, tri) = match *shape {
        ShapeSpec::Sphere { .. } => return None,
        ShapeSpec::Quad { q, u, v } => (q, u, v, false),
        ShapeSpec::Triangle { a, b, c } => (a, b, c, true),
    };
    plane_decide::<Iv>(q, u, v, tri, ray, interval)
        .or_else(|| plane_decide::<Dyadic>(q, u, v, tri, ray, interval))
        .map(|x| x.1)
}

/// The exact quantities of a sphere case, for the record and for `explain`.
#[derive(Clone, Debug)]
pub struct SphereExact {
    /// `a = d . d`.
    pub a: Dyadic,
    /// `h = d . (C - O)`.
    pub h: Dyadic,
    /// `c = |C - O|^2 - r^2`.
    pub c: Dyadic,
    /// `disc = h^2 - a c`.
    pub disc: Dyadic,
    /// The near and far roots to about 120 bits (when `disc >= 0`).
    pub roots: Option<(Dyadic, Dyadic)>,
}

/// The exact quantities of a quad or triangle case.
#[derive(Clone, Debug)]
pub struct PlaneExact {
    /// `n = u x v` (triangle: `(b - a) x (c - a)`).
    pub n: [Dyadic; 3],
    /// `n . d`.
    pub nd: Dyadic,
    /// `-(n . (O - Q))`: `t = tn / nd`.
    pub tn: Dyadic,
    /// `alpha * nd`.
    pub an: Dyadic,
    /// `beta * nd`.
    pub bn: Dyadic,
}

fn dv(v: [f64; 3]) -> V3<Dyadic> {
    V3::of(v)
}

/// The exact sphere quantities (finite inputs).
pub fn sphere_exact(center: [f64; 3], radius: f64, ray: &RaySpec) -> SphereExact {
    sphere_exact_roots(center, radius, ray, true)
}

/// The exact sphere quantities, the roots only when `roots` (they need a 130-bit square root).
pub fn sphere_exact_roots(
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    roots: bool,
) -> SphereExact {
    let d = dv(ray.direction);
    let oc = dv(center).minus(&dv(ray.origin));
    let a = d.dot(&d);
    let h = d.dot(&oc);
    let r = Dyadic::of(radius);
    let c = oc.dot(&oc).sub(&r.mul(&r));
    let disc = h.mul(&h).sub(&a.mul(&c));
    let roots = (roots && disc.signum() != Ordering::Less && !a.is_zero()).then(|| {
        let s = disc.sqrt_approx(130);
        const B: u64 = 130;
        // No cancellation: (h - s)/a = c/(h + s) when h > 0, and (h + s)/a = c/(h - s) when h < 0.
        let hs_plus = h.add(&s);
        let hs_minus = h.sub(&s);
        let near = if h.signum() == Ordering::Greater {
            c.div_approx(&hs_plus, B)
        } else {
            hs_minus.div_approx(&a, B)
        };
        let far = if h.signum() == Ordering::Less {
            c.div_approx(&hs_minus, B)
        } else {
            hs_plus.div_approx(&a, B)
        };
        (near, far)
    });
    SphereExact {
        a,
        h,
        c,
        disc,
        roots,
    }
}

/// The exact plane quantities (finite inputs).
pub fn plane_exact(
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    triangle: bool,
    ray: &RaySpec,
) -> PlaneExact {
    let qn = dv(q);
    let (un, vn) = if triangle {
        (dv(u).minus(&qn), dv(v).minus(&qn))
    } else {
        (dv(u), dv(v))
    };
    let n = un.cross(&vn);
    let d = dv(ray.direction);
    let w = dv(ray.origin).minus(&qn);
    let nd = n.dot(&d);
    let tn = n.dot(&w).neg();
    let an = w.dot(&vn.cross(&d));
    let bn = un.dot(&w.cross(&d));
    PlaneExact {
        n: n.0,
        nd,
        tn,
        an,
        bn,
    }
}

/// An exact hit record rounded to `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactHit {
    /// `t`, rounded to nearest (faithfully for spheres).
    pub t: f64,
    /// `O + t d`, rounded.
    pub point: [f64; 3],
    /// The unit normal facing the ray.
    pub normal: [f64; 3],
    /// `d . outward < 0`.
    pub front_face: bool,
    /// `(alpha, beta)` of a quad, the weights of `b` and `c` of a triangle; `None` for spheres.
    pub uv: Option<(f64, f64)>,
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        v.map(|x| x / l)
    } else {
        // Scale first when the squared length under- or overflows.
        let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if m == 0.0 || !m.is_finite() {
            return v;
        }
        let s = v.map(|x| x / m);
        let l = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        s.map(|x| x / l)
    }
}

/// The exact hit record of a case the decision says hits.
pub fn exact_hit(shape: &ShapeSpec, ray: &RaySpec, decision: Decision) -> Option<ExactHit> {
    let d = dv(ray.direction);
    let o = dv(ray.origin);
    match (*shape, decision) {
        (ShapeSpec::Sphere { center, radius }, Decision::SphereHit(root)) => {
            let ex = sphere_exact(center, radius, ray);
            let (near, far) = ex.roots?;
            let t = if root == Root::Near { near } else { far };
            let p: Vec<Dyadic> = (0..3).map(|i| o.0[i].add(&t.mul(&d.0[i]))).collect();
            let cn = dv(center);
            let out: Vec<f64> = (0..3)
                .map(|i| p[i].sub(&cn.0[i]).to_f64() / radius)
                .collect();
            let outward = unit([out[0], out[1], out[2]]);
            // d . (P - C) is -sqrt(disc) at the near root and +sqrt(disc) at the far one.
            let front_face = match (root, ex.disc.is_zero()) {
                (_, true) => false,
                (Root::Near, false) => radius > 0.0,
                (Root::Far, false) => radius < 0.0,
            };
            let normal = if front_face {
                outward
            } else {
                outward.map(|x| -x)
            };
            Some(ExactHit {
                t: t.to_f64(),
                point: [p[0].to_f64(), p[1].to_f64(), p[2].to_f64()],
                normal,
                front_face,
                uv: None,
            })
        }
        (ShapeSpec::Quad { q, u, v }, Decision::PlaneHit) => Some(plane_hit(q, u, v, false, ray)),
        (ShapeSpec::Triangle { a, b, c }, Decision::PlaneHit) => {
            Some(plane_hit(a, b, c, true, ray))
        }
        _ => None,
    }
}

fn plane_hit(q: [f64; 3], u: [f64; 3], v: [f64; 3], triangle: bool, ray: &RaySpec) -> ExactHit {
    let ex = plane_exact(q, u, v, triangle, ray);
    let d = dv(ray.direction);
    let o = dv(ray.origin);
    let t = ex.tn.div_to_f64(&ex.nd);
    // P_i = (O_i nd + tn d_i) / nd, rounded once.
    let point = [0, 1, 2].map(|i| {
        o.0[i]
            .mul(&ex.nd)
            .add(&ex.tn.mul(&d.0[i]))
            .div_to_f64(&ex.nd)
    });
    let nf = ex.n.clone().map(|x| x.to_f64());
    let outward = unit(nf);
    let front_face = ex.nd.signum() == Ordering::Less;
    let normal = if front_face {
        outward
    } else {
        outward.map(|x| -x)
    };
    ExactHit {
        t,
        point,
        normal,
        front_face,
        uv: Some((ex.an.div_to_f64(&ex.nd), ex.bn.div_to_f64(&ex.nd))),
    }
}
