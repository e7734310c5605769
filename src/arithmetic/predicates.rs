//! The decisions of a ray against the three primitives, as signs of polynomials in the `f64`
//! inputs, written once over [`Num`]: with [`Iv`] they are the fast filter (`None` when an
//! interval straddles zero), with [`Dyadic`] they are exact and always answer.
//!
//! Quotients are compared by cross-multiplying signs, square roots by squaring.

use std::cmp::Ordering;

#[cfg(doc)]
use super::{Dyadic, Iv};
use super::{Num, V3};

/// A ray as plain numbers: `origin + t direction`, the direction not normalised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// The origin.
    pub origin: [f64; 3],
    /// The direction.
    pub direction: [f64; 3],
}

/// Which flat primitive [`plane_decide`] decides, and the rule that goes with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlaneKind {
    /// A quad `(Q, u, v)` with the edges `u`, `v` from its corner `Q`: a hit also needs
    /// `|unit(n) . d| >= parallel_epsilon` (the course's absolute threshold).
    Quad {
        /// The threshold below which a ray counts as parallel.
        parallel_epsilon: f64,
    },
    /// A triangle given by its three vertices `(a, b, c)`.
    Triangle,
}

/// Which root of a sphere was taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Root {
    /// `(h - sqrt(disc)) / a`.
    Near,
    /// `(h + sqrt(disc)) / a`.
    Far,
}

/// The exact decision for one case, before `t` and the record are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    /// Degenerate input (zero radius, zero direction, `u x v = 0`, a ray in a quad's plane).
    Degenerate,
    /// A miss.
    Miss,
    /// A sphere hit at the given root.
    SphereHit(Root),
    /// A quad or triangle hit.
    PlaneHit,
}

/// Why a quad or triangle decision came out as it did: the signs of its deciding quantities.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlaneSigns {
    /// `n . d == 0`.
    pub parallel: bool,
    /// The course's `|unit(n) . d| < 1e-8` (quads only).
    pub below_threshold: bool,
    /// `t >= t_min`.
    pub after_min: bool,
    /// `t <= t_max`.
    pub before_max: bool,
    /// `alpha >= 0` (triangle: the weight of `b`).
    pub alpha_ge_0: bool,
    /// `alpha <= 1` (triangle: `alpha + beta <= 1`).
    pub alpha_le_1: bool,
    /// `beta >= 0` (triangle: the weight of `c`).
    pub beta_ge_0: bool,
    /// `beta <= 1` (triangle: always true).
    pub beta_le_1: bool,
}

/// `min < x` for the finite end `min` (true for `-inf`), given `x - min` as a closure.
fn bound<N: Num>(end: f64, f: impl FnOnce(N) -> N) -> Option<Ordering> {
    if end.is_infinite() {
        Some(Ordering::Greater)
    } else {
        f(N::of(end)).sign()
    }
}

/// The sphere decision in arithmetic `N`; `None` when `N` cannot decide.
pub fn sphere_decide<N: Num>(
    center: [f64; 3],
    radius: f64,
    ray: &Line,
    interval: [f64; 2],
) -> Option<Decision> {
    if radius == 0.0 || ray.direction == [0.0; 3] {
        return Some(Decision::Degenerate);
    }
    let d = V3::<N>::of(ray.direction);
    let oc = V3::<N>::of(center).minus(&V3::of(ray.origin));
    let a = d.dot(&d);
    let h = d.dot(&oc);
    let r = N::of(radius);
    let c = oc.dot(&oc).minus(&r.times(&r));
    let disc = h.times(&h).minus(&a.times(&c));
    let ds = disc.sign()?;
    if ds == Ordering::Less {
        return Some(Decision::Miss);
    }
    // X = h - a t_min, Y = h - a t_max (t = (h -+ sqrt(disc)) / a, a > 0).
    let x = (!interval[0].is_infinite()).then(|| h.minus(&a.times(&N::of(interval[0]))));
    let y = (!interval[1].is_infinite()).then(|| h.minus(&a.times(&N::of(interval[1]))));
    // sqrt(disc) compared with a quantity q: sign of sqrt(disc) - q.
    let sqrt_vs = |q: &N| -> Option<Ordering> {
        match q.sign()? {
            Ordering::Less => Some(Ordering::Greater),
            Ordering::Equal => Some(ds),
            Ordering::Greater => Some(disc.minus(&q.times(q)).sign()?),
        }
    };
    let neg = |q: &N| N::of(0.0).minus(q);
    // near > t_min  <=>  X > sqrt(disc)
    let near_after = match &x {
        None => true,
        Some(x) => sqrt_vs(x)? == Ordering::Less,
    };
    // near < t_max  <=>  sqrt(disc) > Y
    let near_before = match &y {
        None => true,
        Some(y) => sqrt_vs(y)? == Ordering::Greater,
    };
    if near_after && near_before {
        return Some(Decision::SphereHit(Root::Near));
    }
    // far > t_min  <=>  sqrt(disc) > -X
    let far_after = match &x {
        None => true,
        Some(x) => sqrt_vs(&neg(x))? == Ordering::Greater,
    };
    // far < t_max  <=>  sqrt(disc) < -Y
    let far_before = match &y {
        None => true,
        Some(y) => sqrt_vs(&neg(y))? == Ordering::Less,
    };
    Some(if far_after && far_before {
        Decision::SphereHit(Root::Far)
    } else {
        Decision::Miss
    })
}

/// The quad or triangle decision in arithmetic `N`, with the signs of its deciding quantities;
/// `None` when `N` cannot decide.
///
/// With `w = O - Q`, `n = u x v`, `nd = n . d`: `t = -(n . w) / nd`, `alpha = w . (v x d) / nd`,
/// `beta = u . (w x d) / nd` (Cramer's rule; equal to the course's `n.((P-Q) x v) / n.n` for the
/// exact `P`). For a triangle `(a, b, c)`: `Q = a`, `u = b - a`, `v = c - a`, and the third edge
/// is `alpha + beta <= 1`.
pub fn plane_decide<N: Num>(
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    kind: PlaneKind,
    ray: &Line,
    interval: [f64; 2],
) -> Option<(Decision, PlaneSigns)> {
    let triangle = kind == PlaneKind::Triangle;
    let mut s = PlaneSigns::default();
    let (qn, mut un, mut vn) = (V3::<N>::of(q), V3::<N>::of(u), V3::<N>::of(v));
    if triangle {
        un = un.minus(&qn);
        vn = vn.minus(&qn);
    }
    let n = un.cross(&vn);
    let mut zero = true;
    for c in &n.0 {
        if c.sign()? != Ordering::Equal {
            zero = false;
        }
    }
    if zero || ray.direction == [0.0; 3] {
        return Some((Decision::Degenerate, s));
    }
    let d = V3::<N>::of(ray.direction);
    let w = V3::<N>::of(ray.origin).minus(&qn);
    let nd = n.dot(&d);
    let nw = n.dot(&w);
    let sd = nd.sign()?;
    if sd == Ordering::Equal {
        s.parallel = true;
        return Some(if nw.sign()? == Ordering::Equal {
            (Decision::Degenerate, s)
        } else {
            (Decision::Miss, s)
        });
    }
    let flip = |x: N| {
        if sd == Ordering::Less {
            N::of(0.0).minus(&x)
        } else {
            x
        }
    };
    if let PlaneKind::Quad { parallel_epsilon } = kind {
        // (n.d)^2 < eps^2 (n.n)
        let eps = N::of(parallel_epsilon);
        let lhs = nd.times(&nd);
        let rhs = eps.times(&eps).times(&n.dot(&n));
        s.below_threshold = rhs.minus(&lhs).sign()? == Ordering::Greater;
    }
    let tn = N::of(0.0).minus(&nw);
    // t >= t_min <=> sd (tn - t_min nd) >= 0
    s.after_min = bound::<N>(interval[0], |m| flip(tn.minus(&m.times(&nd))))? != Ordering::Less;
    s.before_max = bound::<N>(interval[1], |m| flip(m.times(&nd).minus(&tn)))? != Ordering::Less;
    let an = w.dot(&vn.cross(&d));
    let bn = un.dot(&w.cross(&d));
    s.alpha_ge_0 = flip(an.clone()).sign()? != Ordering::Less;
    s.beta_ge_0 = flip(bn.clone()).sign()? != Ordering::Less;
    if triangle {
        s.alpha_le_1 = flip(nd.minus(&an).minus(&bn)).sign()? != Ordering::Less;
        s.beta_le_1 = true;
    } else {
        s.alpha_le_1 = flip(nd.minus(&an)).sign()? != Ordering::Less;
        s.beta_le_1 = flip(nd.minus(&bn)).sign()? != Ordering::Less;
    }
    let inside =
        s.after_min && s.before_max && s.alpha_ge_0 && s.alpha_le_1 && s.beta_ge_0 && s.beta_le_1;
    Some((
        if inside && !s.below_threshold {
            Decision::PlaneHit
        } else {
            Decision::Miss
        },
        s,
    ))
}
