//! The error bands of the course's naive formulas, in outward-rounded interval arithmetic.
//!
//! Each operation of [`Iv`] (from [`crate::arithmetic`]) encloses both the exact real result and
//! what `f64` code computes, so evaluating the course's formula in it encloses the exact value
//! *and* what the course's `f64` code computes; [`Iv::widen`] by `K` allows for honest variants
//! that round differently. [`Iv32`] does the same for code computing in `f32`, and the band
//! functions are generic over the arithmetic ([`Band`]); the robust profile's sphere formulas are
//! [`robust_sphere_bands_in`].

use std::ops::{Add, Div, Mul, Neg, Sub};

pub use crate::arithmetic::{Iv, next_down, next_up};

/// The widening factor of the error bands.
pub const K: f64 = 8.0;

/// A 3-vector of intervals.
#[derive(Clone, Copy, Debug)]
pub struct IV3(pub [Iv; 3]);

#[allow(clippy::should_implement_trait)]
impl IV3 {
    /// From points.
    pub fn of(v: [f64; 3]) -> Self {
        IV3(v.map(Iv::point))
    }
    /// `self + o`.
    pub fn add(self, o: IV3) -> IV3 {
        IV3([0, 1, 2].map(|i| self.0[i] + o.0[i]))
    }
    /// `self - o`.
    pub fn sub(self, o: IV3) -> IV3 {
        IV3([0, 1, 2].map(|i| self.0[i] - o.0[i]))
    }
    /// `self * s`.
    pub fn scale(self, s: Iv) -> IV3 {
        IV3(self.0.map(|x| x * s))
    }
    /// `self / s`.
    pub fn div(self, s: Iv) -> IV3 {
        IV3(self.0.map(|x| x / s))
    }
    /// Dot product.
    pub fn dot(self, o: IV3) -> Iv {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    /// Cross product.
    pub fn cross(self, o: IV3) -> IV3 {
        let (a, b) = (self.0, o.0);
        IV3([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }
}

/// Interval arithmetic in a given precision: each operation's result encloses the exact real
/// result for any operands in the intervals *and* what code computing in that precision gets.
pub trait Band:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// An input number as code in this precision sees it (for `f32`, the hull of `x` and its
    /// rounding to `f32`).
    fn input(x: f64) -> Self;
    /// An interval computed elsewhere, in this precision.
    fn from_iv(iv: Iv) -> Self;
    /// The interval.
    fn iv(self) -> Iv;
    /// The square root of the non-negative part.
    fn sqrt(self) -> Self;
    /// `|self|`.
    fn abs(self) -> Self;
}

impl Band for Iv {
    fn input(x: f64) -> Self {
        Iv::point(x)
    }
    fn from_iv(iv: Iv) -> Self {
        iv
    }
    fn iv(self) -> Iv {
        self
    }
    fn sqrt(self) -> Self {
        Iv::sqrt(&self)
    }
    fn abs(self) -> Self {
        Iv::abs(&self)
    }
}

/// The largest `f32` at or below `x` (as an `f64`; `-inf` below `-f32::MAX`).
fn f32_floor(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NEG_INFINITY;
    }
    let f = x as f32;
    if (f as f64) <= x {
        return f as f64;
    }
    // One f32 step down.
    let b = f.to_bits();
    let down = if f == 0.0 {
        -f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(b - 1)
    } else {
        f32::from_bits(b + 1)
    };
    down as f64
}

/// The smallest `f32` at or above `x`.
fn f32_ceil(x: f64) -> f64 {
    -f32_floor(-x)
}

/// Interval arithmetic whose every result is also widened to the `f32` grid (so it holds the
/// result of the same operation computed in `f32`), with inputs rounded to `f32` first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iv32(pub Iv);

impl Iv32 {
    fn round(iv: Iv) -> Self {
        Iv32(Iv {
            lo: f32_floor(iv.lo),
            hi: f32_ceil(iv.hi),
        })
    }
}

impl Band for Iv32 {
    fn input(x: f64) -> Self {
        if x.is_nan() {
            return Iv32(Iv::ENTIRE);
        }
        let r = x as f32 as f64;
        Iv32(Iv {
            lo: x.min(r),
            hi: x.max(r),
        })
    }
    fn from_iv(iv: Iv) -> Self {
        Iv32::round(iv)
    }
    fn iv(self) -> Iv {
        self.0
    }
    fn sqrt(self) -> Self {
        Iv32::round(self.0.sqrt())
    }
    fn abs(self) -> Self {
        Iv32(self.0.abs())
    }
}

impl Add for Iv32 {
    type Output = Iv32;
    fn add(self, o: Iv32) -> Iv32 {
        Iv32::round(self.0 + o.0)
    }
}
impl Sub for Iv32 {
    type Output = Iv32;
    fn sub(self, o: Iv32) -> Iv32 {
        Iv32::round(self.0 - o.0)
    }
}
impl Mul for Iv32 {
    type Output = Iv32;
    fn mul(self, o: Iv32) -> Iv32 {
        Iv32::round(self.0 * o.0)
    }
}
impl Div for Iv32 {
    type Output = Iv32;
    fn div(self, o: Iv32) -> Iv32 {
        Iv32::round(self.0 / o.0)
    }
}
impl Neg for Iv32 {
    type Output = Iv32;
    fn neg(self) -> Iv32 {
        Iv32(-self.0)
    }
}

/// A 3-vector in a [`Band`] arithmetic.
pub type B3<B> = [B; 3];

/// The input vector `v`.
pub fn b3<B: Band>(v: [f64; 3]) -> B3<B> {
    v.map(B::input)
}
fn badd<B: Band>(a: B3<B>, b: B3<B>) -> B3<B> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `a - b`.
pub fn bsub<B: Band>(a: B3<B>, b: B3<B>) -> B3<B> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn bscale<B: Band>(a: B3<B>, s: B) -> B3<B> {
    a.map(|x| x * s)
}
fn bdivs<B: Band>(a: B3<B>, s: B) -> B3<B> {
    a.map(|x| x / s)
}
fn bdot<B: Band>(a: B3<B>, b: B3<B>) -> B {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn bcross<B: Band>(a: B3<B>, b: B3<B>) -> B3<B> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The sphere quantities of a profile's formula in interval arithmetic (not yet widened).
#[derive(Clone, Copy, Debug)]
pub struct SphereBands {
    /// The discriminant: the course's `half_b^2 - a c` with `oc = O - C`, `half_b = oc . d`,
    /// `c = oc . oc - r^2`; the robust `a (r^2 - |f - (f.d/a) d|^2)`. Both have the sign of the
    /// exact `h^2 - a c`.
    pub disc: Iv,
    /// The near root: `(-half_b - sqrt(disc)) / a`; robust: the smaller of `c / q` and `q / a`.
    pub t_near: Iv,
    /// The far root: `(-half_b + sqrt(disc)) / a`; robust: the larger.
    pub t_far: Iv,
}

/// Evaluates the course's sphere formulas in interval arithmetic.
pub fn sphere_bands(center: [f64; 3], radius: f64, origin: [f64; 3], dir: [f64; 3]) -> SphereBands {
    sphere_bands_in::<Iv>(center, radius, origin, dir)
}

/// Evaluates the course's sphere formulas in the arithmetic `B`.
pub fn sphere_bands_in<B: Band>(
    center: [f64; 3],
    radius: f64,
    origin: [f64; 3],
    dir: [f64; 3],
) -> SphereBands {
    let d = b3::<B>(dir);
    let oc = bsub(b3::<B>(origin), b3(center));
    let a = bdot(d, d);
    let half_b = bdot(oc, d);
    let r = B::input(radius);
    let c = bdot(oc, oc) - r * r;
    let disc = half_b * half_b - a * c;
    let sq = disc.sqrt();
    SphereBands {
        disc: disc.iv(),
        t_near: ((-half_b - sq) / a).iv(),
        t_far: ((-half_b + sq) / a).iv(),
    }
}

/// The hull of two intervals.
fn hull(a: Iv, b: Iv) -> Iv {
    Iv {
        lo: a.lo.min(b.lo),
        hi: a.hi.max(b.hi),
    }
}

/// Evaluates the reference's robust sphere formulas (`crate::geometry::sphere`: the
/// discriminant `a (r^2 - |f - (f.d/a) d|^2)`, Ray Tracing Gems roots) in the arithmetic `B`.
pub fn robust_sphere_bands_in<B: Band>(
    center: [f64; 3],
    radius: f64,
    origin: [f64; 3],
    dir: [f64; 3],
) -> SphereBands {
    let d = b3::<B>(dir);
    let f = bsub(b3::<B>(origin), b3(center));
    let a = bdot(d, d);
    let half_b = bdot(f, d);
    let r = B::input(radius);
    let r2 = r * r;
    let c = bdot(f, f) - r2;
    let perp = bsub(f, bscale(d, half_b / a));
    let disc = a * (r2 - bdot(perp, perp));
    let sq = disc.sqrt();
    // q = -(half_b + copysign(sqrt(disc), half_b)); both choices when the sign is unknown.
    let hb = half_b.iv();
    let q_pos = -(half_b + sq);
    let q_neg = -(half_b - sq);
    let roots = |q: B| {
        let (t0, t1) = ((c / q).iv(), (q / a).iv());
        (
            Iv {
                lo: t0.lo.min(t1.lo),
                hi: t0.hi.min(t1.hi),
            },
            Iv {
                lo: t0.lo.max(t1.lo),
                hi: t0.hi.max(t1.hi),
            },
        )
    };
    let (t_near, t_far) = if hb.lo >= 0.0 {
        roots(q_pos)
    } else if hb.hi <= 0.0 {
        roots(q_neg)
    } else {
        let (n1, f1) = roots(q_pos);
        let (n2, f2) = roots(q_neg);
        (hull(n1, n2), hull(f1, f2))
    };
    SphereBands {
        disc: disc.iv(),
        t_near,
        t_far,
    }
}

/// The course's naive quad (or course-style triangle) quantities in interval arithmetic.
#[derive(Clone, Copy, Debug)]
pub struct PlaneBands {
    /// `unit(n) . d`.
    pub denom: Iv,
    /// `t = (D - unit(n) . O) / denom`.
    pub t: Iv,
    /// `alpha = Wvec . (p x v)`.
    pub alpha: Iv,
    /// `beta = Wvec . (u x p)`.
    pub beta: Iv,
}

/// Evaluates the course's quad formulas in interval arithmetic (`u`, `v` the edges from `q`; for
/// a triangle the edges `b - a`, `c - a` as intervals holding their exact and rounded values).
pub fn plane_bands(q: IV3, u: IV3, v: IV3, origin: [f64; 3], dir: [f64; 3]) -> PlaneBands {
    plane_bands_in::<Iv>(q.0, u.0, v.0, origin, dir)
}

/// Evaluates the course's quad formulas in the arithmetic `B`.
pub fn plane_bands_in<B: Band>(
    q: B3<B>,
    u: B3<B>,
    v: B3<B>,
    origin: [f64; 3],
    dir: [f64; 3],
) -> PlaneBands {
    let n = bcross(u, v);
    let nn = bdot(n, n);
    let normal = bdivs(n, nn.sqrt());
    let big_d = bdot(normal, q);
    let w = bdivs(n, nn);
    let d = b3::<B>(dir);
    let o = b3::<B>(origin);
    let denom = bdot(normal, d);
    let t = (big_d - bdot(normal, o)) / denom;
    let p = bsub(badd(o, bscale(d, t)), q);
    PlaneBands {
        denom: denom.iv(),
        t: t.iv(),
        alpha: bdot(w, bcross(p, v)).iv(),
        beta: bdot(w, bcross(u, p)).iv(),
    }
}

/// The worst band radius (widened by `K`) of the sphere normal `(O + t d - C) / r` over its
/// components, for `t` in the band `t`.
pub fn sphere_normal_radius<B: Band>(
    center: [f64; 3],
    radius: f64,
    origin: [f64; 3],
    dir: [f64; 3],
    t: Iv,
) -> f64 {
    let p = badd(b3::<B>(origin), bscale(b3::<B>(dir), B::from_iv(t)));
    let n = bdivs(bsub(p, b3(center)), B::input(radius));
    n.iter().map(|c| c.iv().widen(K).rad()).fold(0.0, f64::max)
}
