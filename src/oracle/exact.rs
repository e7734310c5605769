//! Exact decisions: every `f64` is a dyadic rational `m 2^e`, and every deciding quantity of the
//! three primitives is a polynomial in the inputs, so it is evaluated exactly with big integers
//! sharing a binary exponent (sums and products of dyadics stay dyadic: no gcd, no division).
//! Quotients are compared by cross-multiplying signs, square roots by squaring.
//!
//! The decisions are written once, generic over [`Num`]: with [`Iv`] (outward-rounded intervals)
//! they are the fast filter, which answers `None` when an interval straddles zero; with
//! [`Dyadic`] they are exact. [`decide`] runs the filter and falls back to the exact arithmetic.

use std::cmp::Ordering;

use num_bigint::{BigInt, Sign};
use num_traits::{Signed, ToPrimitive, Zero};

use super::band::Iv;
use super::vectors::{RaySpec, ShapeSpec};
use crate::geometry::PARALLEL_EPSILON;

/// An exact dyadic rational `m * 2^e`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dyadic {
    /// The integer mantissa.
    pub m: BigInt,
    /// The binary exponent.
    pub e: i64,
}

impl Dyadic {
    /// Zero.
    pub fn zero() -> Self {
        Self {
            m: BigInt::zero(),
            e: 0,
        }
    }

    /// The exact value of a finite `x`, or `None` for NaN and infinities.
    pub fn from_f64(x: f64) -> Option<Self> {
        if !x.is_finite() {
            return None;
        }
        if x == 0.0 {
            return Some(Self::zero());
        }
        let bits = x.to_bits();
        let negative = bits >> 63 == 1;
        let exp = ((bits >> 52) & 0x7ff) as i64;
        let frac = bits & ((1u64 << 52) - 1);
        let (mut mant, mut e) = if exp == 0 {
            (frac, -1074)
        } else {
            (frac | (1u64 << 52), exp - 1075)
        };
        let tz = mant.trailing_zeros();
        mant >>= tz;
        e += tz as i64;
        let m = BigInt::from(mant);
        Some(Self {
            m: if negative { -m } else { m },
            e,
        })
    }

    /// The sign.
    pub fn signum(&self) -> Ordering {
        match self.m.sign() {
            Sign::Minus => Ordering::Less,
            Sign::NoSign => Ordering::Equal,
            Sign::Plus => Ordering::Greater,
        }
    }

    /// Whether the value is zero.
    pub fn is_zero(&self) -> bool {
        self.m.is_zero()
    }

    /// `self + o`.
    pub fn add(&self, o: &Self) -> Self {
        if self.m.is_zero() {
            return o.clone();
        }
        if o.m.is_zero() {
            return self.clone();
        }
        let e = self.e.min(o.e);
        let m = (&self.m << (self.e - e) as usize) + (&o.m << (o.e - e) as usize);
        Self { m, e }
    }

    /// `-self`.
    pub fn neg(&self) -> Self {
        Self {
            m: -&self.m,
            e: self.e,
        }
    }

    /// `self - o`.
    pub fn sub(&self, o: &Self) -> Self {
        self.add(&o.neg())
    }

    /// `self * o`.
    pub fn mul(&self, o: &Self) -> Self {
        if self.m.is_zero() || o.m.is_zero() {
            return Self::zero();
        }
        Self {
            m: &self.m * &o.m,
            e: self.e + o.e,
        }
    }

    /// Compares two values exactly.
    pub fn cmp_value(&self, o: &Self) -> Ordering {
        self.sub(o).signum()
    }

    /// The value rounded to the nearest `f64` (ties to even; overflow gives an infinity;
    /// subnormal results may be off by one unit).
    pub fn to_f64(&self) -> f64 {
        round_parts(&self.m, self.e, false)
    }

    /// `self / o` rounded to the nearest `f64` (`o` must be non-zero).
    pub fn div_to_f64(&self, o: &Self) -> f64 {
        if self.m.is_zero() {
            return 0.0;
        }
        let (q, e, inexact) = big_quotient(&self.m, self.e, &o.m, o.e, 70);
        round_parts(&q, e, inexact)
    }

    /// `self / o` as a dyadic truncated to about `bits` significant bits (`o` non-zero).
    pub fn div_approx(&self, o: &Self, bits: u64) -> Self {
        if self.m.is_zero() {
            return Self::zero();
        }
        let (q, e, _) = big_quotient(&self.m, self.e, &o.m, o.e, bits);
        Self { m: q, e }
    }

    /// `sqrt(self)` truncated to about `bits` significant bits (`self >= 0`).
    pub fn sqrt_approx(&self, bits: u64) -> Self {
        if self.m.sign() != Sign::Plus {
            return Self::zero();
        }
        let mut m = self.m.clone();
        let mut e = self.e;
        let want = 2 * bits + 2;
        let have = m.bits();
        let mut shift = want.saturating_sub(have) as i64;
        if (e - shift) % 2 != 0 {
            shift += 1;
        }
        m <<= shift as usize;
        e -= shift;
        Self {
            m: m.sqrt(),
            e: e / 2,
        }
    }
}

/// `(n 2^ne) / (d 2^de)` as an integer quotient `q 2^e` with at least `bits` significant bits,
/// and whether the division left a remainder.
fn big_quotient(n: &BigInt, ne: i64, d: &BigInt, de: i64, bits: u64) -> (BigInt, i64, bool) {
    let shift = (bits + d.bits()).saturating_sub(n.bits()) as i64 + 2;
    let num = n << shift as usize;
    let q = &num / d;
    let inexact = !(&q * d - &num).is_zero();
    (q, ne - de - shift, inexact)
}

/// Rounds `m 2^e` (plus a sticky bit for a discarded remainder) to the nearest `f64`.
fn round_parts(m: &BigInt, e: i64, sticky: bool) -> f64 {
    if m.is_zero() {
        return 0.0;
    }
    let negative = m.is_negative();
    let mag = m.abs();
    let bits = mag.bits();
    let (top, e) = if bits > 62 {
        let s = bits - 62;
        let top = &mag >> s as usize;
        let lost = sticky || (&top << s as usize) != mag;
        let top = top.to_u64().expect("62 bits fit") | u64::from(lost);
        (top, e + s as i64)
    } else {
        let top = mag.to_u64().expect("62 bits fit");
        // A remainder below the last bit: shift in one guard bit set.
        if sticky {
            ((top << 2) | 1, e - 2)
        } else {
            (top, e)
        }
    };
    // `top < 2^63` converts with one correct rounding; the sticky bit breaks ties.
    let x = top as f64;
    let e = e.clamp(-4000, 4000) as i32;
    let y = libm::scalbn(x, e);
    if negative { -y } else { y }
}

/// Arithmetic both the interval filter and the exact evaluation provide.
pub trait Num: Clone {
    /// The (exact) value of a finite `f64`.
    fn of(x: f64) -> Self;
    /// `self + o`.
    fn plus(&self, o: &Self) -> Self;
    /// `self - o`.
    fn minus(&self, o: &Self) -> Self;
    /// `self * o`.
    fn times(&self, o: &Self) -> Self;
    /// The sign, or `None` when it cannot be told (an interval straddling zero).
    fn sign(&self) -> Option<Ordering>;
}

impl Num for Dyadic {
    fn of(x: f64) -> Self {
        Dyadic::from_f64(x).expect("exact decisions take finite inputs")
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(o)
    }
    fn sign(&self) -> Option<Ordering> {
        Some(self.signum())
    }
}

impl Num for Iv {
    fn of(x: f64) -> Self {
        Iv::point(x)
    }
    fn plus(&self, o: &Self) -> Self {
        *self + *o
    }
    fn minus(&self, o: &Self) -> Self {
        *self - *o
    }
    fn times(&self, o: &Self) -> Self {
        *self * *o
    }
    fn sign(&self) -> Option<Ordering> {
        self.sign()
    }
}

/// A 3-vector of [`Num`]s.
#[derive(Clone, Debug)]
pub struct V3<N>(pub [N; 3]);

impl<N: Num> V3<N> {
    /// From `f64` components.
    pub fn of(v: [f64; 3]) -> Self {
        V3(v.map(N::of))
    }
    /// `self - o`.
    pub fn minus(&self, o: &Self) -> Self {
        V3([0, 1, 2].map(|i| self.0[i].minus(&o.0[i])))
    }
    /// The dot product.
    pub fn dot(&self, o: &Self) -> N {
        self.0[0]
            .times(&o.0[0])
            .plus(&self.0[1].times(&o.0[1]))
            .plus(&self.0[2].times(&o.0[2]))
    }
    /// The cross product.
    pub fn cross(&self, o: &Self) -> Self {
        let (a, b) = (&self.0, &o.0);
        V3([
            a[1].times(&b[2]).minus(&a[2].times(&b[1])),
            a[2].times(&b[0]).minus(&a[0].times(&b[2])),
            a[0].times(&b[1]).minus(&a[1].times(&b[0])),
        ])
    }
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

fn gt0(s: Ordering) -> bool {
    s == Ordering::Greater
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
    ray: &RaySpec,
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

/// The quad (`triangle == false`) or triangle decision in arithmetic `N`, with the signs of its
/// deciding quantities; `None` when `N` cannot decide.
///
/// With `w = O - Q`, `n = u x v`, `nd = n . d`: `t = -(n . w) / nd`, `alpha = w . (v x d) / nd`,
/// `beta = u . (w x d) / nd` (Cramer's rule; equal to the course's `n.((P-Q) x v) / n.n` for the
/// exact `P`). For a triangle `(a, b, c)`: `Q = a`, `u = b - a`, `v = c - a`, and the third edge
/// is `alpha + beta <= 1`.
pub fn plane_decide<N: Num>(
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    triangle: bool,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<(Decision, PlaneSigns)> {
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
    if !triangle {
        // (n.d)^2 < eps^2 (n.n)
        let eps = N::of(PARALLEL_EPSILON);
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
    let _ = gt0;
    Some((
        if inside && !s.below_threshold {
            Decision::PlaneHit
        } else {
            Decision::Miss
        },
        s,
    ))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn dy(x: f64) -> Dyadic {
        Dyadic::from_f64(x).unwrap()
    }

    #[test]
    fn dyadic_round_trips_every_kind_of_f64() {
        for x in [
            0.0,
            1.0,
            -1.5,
            0.1,
            1e300,
            -5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            3.0e-310,
        ] {
            assert_eq!(dy(x).to_f64().to_bits(), x.to_bits(), "{x}");
        }
    }

    #[test]
    fn dyadic_arithmetic_is_exact_where_f64_is_not() {
        // 0.1 + 0.2 != 0.3 in f64, and the exact sum is neither.
        let s = dy(0.1).add(&dy(0.2));
        assert_ne!(s.cmp_value(&dy(0.3)), Ordering::Equal);
        assert_eq!(s.sub(&dy(0.1)).cmp_value(&dy(0.2)), Ordering::Equal);
        // (1 + 2^-60)^2 - 1 - 2^-59 = 2^-120 exactly.
        let x = dy(1.0).add(&dy(2f64.powi(-60)));
        let r = x.mul(&x).sub(&dy(1.0)).sub(&dy(2f64.powi(-59)));
        assert_eq!(r.to_f64(), 2f64.powi(-120));
    }

    #[test]
    fn quotients_and_roots_round_correctly() {
        assert_eq!(dy(1.0).div_to_f64(&dy(3.0)), 1.0 / 3.0);
        assert_eq!(dy(-2.0).div_to_f64(&dy(7.0)), -2.0 / 7.0);
        assert_eq!(dy(2.0).sqrt_approx(120).to_f64(), 2f64.sqrt());
        assert_eq!(dy(1e-300).sqrt_approx(120).to_f64(), 1e-300f64.sqrt());
        // Ties go to even: 1 + 2^-53 rounds to 1.
        assert_eq!(dy(1.0).add(&dy(2f64.powi(-53))).to_f64(), 1.0);
        assert_eq!(
            dy(1.0)
                .add(&dy(2f64.powi(-53)))
                .add(&dy(2f64.powi(-100)))
                .to_f64(),
            1.0 + f64::EPSILON
        );
    }
}
