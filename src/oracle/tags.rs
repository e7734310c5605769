//! What each tag of a vector means, as a predicate decided with exact arithmetic on the `f64`
//! inputs ([`holds`]). Classification keeps a tag only when its definition holds: a comparison
//! that the profile's band cannot settle, far from the boundary the tag names, is tagged with
//! [`ill_conditioned`] instead (for example `naive-ill-conditioned`: a far sphere
//! where only the naive `half_b^2 - a c` cancels).
//!
//! The definitions (`a = d.d`, `f = O - C`, `disc = (f.d)^2 - a (f.f - r^2)`, which is
//! `a (r^2 - dist^2)` for the distance `dist` of the ray's line from the centre; for planes
//! `n = u x v`, and `alpha`, `beta` the exact surface coordinates of the line's hit):
//!
//! | tag | holds when |
//! |---|---|
//! | `tangent` | `\|disc\| <= 2^-20 a r^2` (`dist` within about `2^-21 r` of `r`) |
//! | `near-tangent` | `\|disc\| <= 2^-8 a r^2` (`dist` within about `2^-9 r` of `r`) |
//! | `far` | `\|C - O\| >= 1000 \|r\|` |
//! | `tiny` | sphere: `\|r\| <= 2^-10 \|C - O\|`; plane: the longer edge `<= 2^-10 \|Q - O\|` |
//! | `inside` | `\|C - O\| < \|r\|` |
//! | `behind` | sphere: `d.(C - O) <= 0` and `\|C - O\| > \|r\|` (both roots negative); plane: `t < 0` |
//! | `negative-radius` | `r < 0` |
//! | `grazing` | `\|unit(n).d\| / \|d\| <= 2^-10` (about `9.8e-4`; `0` when parallel) |
//! | `parallel` | `n.d = 0` |
//! | `parallel-threshold` | `\|unit(n).d\| <= 2e-8` (the course's absolute `1e-8` threshold decides, or nearly) |
//! | `edge` | some edge coordinate (`alpha`, `1 - alpha`, `beta`, `1 - beta`; triangles: the three barycentrics) within `2^-20` of 0 |
//! | `corner` | two of those at once (for a quad, one of `alpha`'s and one of `beta`'s) |
//! | `interval-boundary` | a hit parameter of the line (a sphere's either root, a plane's `t`) within `2^-20 max(\|t\|, \|end\|)` of a finite interval end |
//! | `scale` | some non-zero input of the shape or the ray has magnitude `>= 2^20` or `<= 2^-20` |
//! | `unnormalised` | `\|d\| <= 1/2` or `\|d\| >= 2` |
//! | `skewed` | `(u.v)^2 >= 3/4 (u.u)(v.v)` (the edges within 30 degrees of parallel) |
//! | `skinny` | one edge at least 16 times as long as the other |
//! | `degenerate` | `r = 0`, `d = 0`, `n = 0`, or the ray lies in the plane |
//! | `nonfinite` | some input is NaN, an infinity, or `-0` |
//!
//! Tags with no geometric claim, for which [`holds`] is `None`: `random` (drawn by the random
//! generator), `overflow` (a band of the profile's formula is unbounded), and the
//! ill-conditioned tags.

use std::cmp::Ordering;

use super::band::{Iv, robust_sphere_bands_in};
use super::exact::{self, Dyadic, Num, V3};
use super::profile::{Judging, Precision, Profile};
use super::vectors::{RaySpec, ShapeSpec};
use crate::geometry::PARALLEL_EPSILON;

/// The tags [`holds`] has a definition for.
pub const DEFINED: [&str; 20] = [
    "tiny",
    "tangent",
    "near-tangent",
    "far",
    "inside",
    "behind",
    "negative-radius",
    "grazing",
    "parallel",
    "parallel-threshold",
    "edge",
    "corner",
    "interval-boundary",
    "scale",
    "unnormalised",
    "skewed",
    "skinny",
    "degenerate",
    "nonfinite",
    "overflow",
];

/// Whether a case's input numbers (shape, ray, interval) hold a NaN, an infinity or a `-0`.
fn poisoned(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> bool {
    shape
        .numbers()
        .iter()
        .chain(&ray.origin)
        .chain(&ray.direction)
        .chain(&interval)
        .any(|x| !x.is_finite() || (*x == 0.0 && x.is_sign_negative()))
}

fn pow2(k: i32) -> f64 {
    libm::ldexp(1.0, k)
}

/// `a <= b`, or `None` when `N` cannot tell.
fn le<N: Num>(a: &N, b: &N) -> Option<bool> {
    Some(b.minus(a).sign()? != Ordering::Less)
}

/// `a < b`.
fn lt<N: Num>(a: &N, b: &N) -> Option<bool> {
    Some(b.minus(a).sign()? == Ordering::Greater)
}

/// `|x|`, or `None` when the sign of `x` is unknown.
fn abs<N: Num>(x: &N) -> Option<N> {
    Some(if x.sign()? == Ordering::Less {
        N::of(0.0).minus(x)
    } else {
        x.clone()
    })
}

/// `|x| <= k |y|`.
fn within<N: Num>(x: &N, k: f64, y: &N) -> Option<bool> {
    le(&abs(x)?, &N::of(k).times(&abs(y)?))
}

/// The larger of two non-negative values.
fn max<N: Num>(a: N, b: N) -> Option<N> {
    Some(if le(&a, &b)? { b } else { a })
}

/// `|t - end| <= 2^-20 max(|t|, |end|)` for finite `end`, for `t = tn / nd` (`nd != 0`):
/// `|tn - end nd| <= 2^-20 max(|tn|, |end nd|)`.
fn near_end_ratio<N: Num>(tn: &N, nd: &N, end: f64) -> Option<bool> {
    if !end.is_finite() {
        return Some(false);
    }
    let e = N::of(end).times(nd);
    let m = max(abs(tn)?, abs(&e)?)?;
    within(&tn.minus(&e), pow2(-20), &m)
}

/// `|t - end| <= 2^-20 max(|t|, |end|)` for finite `end`.
fn near_end(t: &Dyadic, end: f64) -> bool {
    near_end_ratio(t, &Dyadic::of(1.0), end).expect("exact")
}

/// `|t - end| <= 2^-20 max(|t|, |end|)` decided in interval arithmetic for `t` in the band
/// `t`, or `None` when the band cannot tell.
fn near_end_iv(t: Iv, end: f64) -> Option<bool> {
    near_end_ratio(&t, &Iv::point(1.0), end)
}

/// The sphere's `interval-boundary` by the robust root bands when they decide it.
fn sphere_boundary_fast(
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    iv: [f64; 2],
) -> Option<bool> {
    let b = robust_sphere_bands_in::<Iv>(center, radius, ray.origin, ray.direction);
    if b.disc.hi < 0.0 {
        return Some(false);
    }
    if b.disc.lo < 0.0 {
        return None;
    }
    let mut any = false;
    for t in [b.t_near, b.t_far] {
        for e in iv {
            any |= near_end_iv(t, e)?;
        }
    }
    Some(any)
}

/// Whether `tag`'s definition holds for the case; `None` for a tag without one (`random`,
/// `overflow`, the ill-conditioned tags, anything unknown). Decided in interval arithmetic
/// when that can, else with exact dyadic arithmetic.
pub fn holds(tag: &str, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Option<bool> {
    if tag == "nonfinite" {
        return Some(poisoned(shape, ray, interval));
    }
    if !DEFINED.contains(&tag) || tag == "overflow" {
        return None;
    }
    if !exact::inputs_finite(shape, ray, interval) {
        return Some(false);
    }
    match tag {
        "scale" => {
            let (big, small) = (pow2(20), pow2(-20));
            return Some(
                shape
                    .numbers()
                    .iter()
                    .chain(&ray.origin)
                    .chain(&ray.direction)
                    .any(|x| *x != 0.0 && (x.abs() >= big || x.abs() <= small)),
            );
        }
        "negative-radius" => {
            return Some(matches!(shape, ShapeSpec::Sphere { radius, .. } if *radius < 0.0));
        }
        "interval-boundary" => {
            if let ShapeSpec::Sphere { center, radius } = *shape {
                if let Some(b) = sphere_boundary_fast(center, radius, ray, interval) {
                    return Some(b);
                }
                let ex = exact::sphere_exact(center, radius, ray);
                return Some(match ex.roots {
                    Some((near, far)) => [near, far]
                        .iter()
                        .any(|t| near_end(t, interval[0]) || near_end(t, interval[1])),
                    None => false,
                });
            }
        }
        _ => {}
    }
    Some(
        holds_in::<Iv>(tag, shape, ray, interval)
            .or_else(|| holds_in::<Dyadic>(tag, shape, ray, interval))
            .expect("exact arithmetic decides"),
    )
}

/// [`holds`] for a defined tag with finite inputs in arithmetic `N` (`None`: cannot tell).
fn holds_in<N: Num>(
    tag: &str,
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<bool> {
    let d = V3::<N>::of(ray.direction);
    let dd = d.dot(&d);
    if tag == "unnormalised" {
        return Some(le(&dd, &N::of(0.25))? || le(&N::of(4.0), &dd)?);
    }
    let o = V3::<N>::of(ray.origin);
    match *shape {
        ShapeSpec::Sphere { center, radius } => {
            let r = N::of(radius);
            let r2 = r.times(&r);
            let f = o.minus(&V3::of(center));
            let ff = f.dot(&f);
            match tag {
                "degenerate" => Some(radius == 0.0 || ray.direction == [0.0; 3]),
                "far" => le(&N::of(1e6).times(&r2), &ff),
                "inside" => lt(&ff, &r2),
                "tiny" => le(&r2.times(&N::of(pow2(20))), &ff),
                "behind" => {
                    // d.(C - O) <= 0 <=> f.d >= 0, and the origin outside.
                    let h = f.dot(&d);
                    Some(h.sign()? != Ordering::Less && lt(&r2, &ff)?)
                }
                "tangent" | "near-tangent" => {
                    let h = f.dot(&d);
                    let disc = h.times(&h).minus(&dd.times(&ff.minus(&r2)));
                    let k = if tag == "tangent" {
                        pow2(-20)
                    } else {
                        pow2(-8)
                    };
                    within(&disc, k, &dd.times(&r2))
                }
                _ => Some(false),
            }
        }
        ShapeSpec::Quad { q, u, v } => plane_holds::<N>(tag, q, u, v, false, ray, interval),
        ShapeSpec::Triangle { a, b, c } => plane_holds::<N>(tag, a, b, c, true, ray, interval),
    }
}

fn plane_holds<N: Num>(
    tag: &str,
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    triangle: bool,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Option<bool> {
    let qn = V3::<N>::of(q);
    let (un, vn) = if triangle {
        (V3::of(u).minus(&qn), V3::of(v).minus(&qn))
    } else {
        (V3::of(u), V3::of(v))
    };
    let n = un.cross(&vn);
    let mut n_zero = true;
    for c in &n.0 {
        n_zero &= c.sign()? == Ordering::Equal;
    }
    let d = V3::<N>::of(ray.direction);
    let w = V3::<N>::of(ray.origin).minus(&qn);
    let nd = n.dot(&d);
    let nd_zero = nd.sign()? == Ordering::Equal;
    let uu = un.dot(&un);
    let vv = vn.dot(&vn);
    match tag {
        "degenerate" => {
            return Some(
                n_zero
                    || ray.direction == [0.0; 3]
                    || (nd_zero && n.dot(&w).sign()? == Ordering::Equal),
            );
        }
        "parallel" => return Some(!n_zero && nd_zero),
        "skewed" => {
            let uv = un.dot(&vn);
            return le(&N::of(0.75).times(&uu).times(&vv), &uv.times(&uv));
        }
        "skinny" => {
            return Some(le(&N::of(256.0).times(&uu), &vv)? || le(&N::of(256.0).times(&vv), &uu)?);
        }
        "tiny" => {
            let big = max(uu, vv)?;
            return le(&big.times(&N::of(pow2(20))), &w.dot(&w));
        }
        _ => {}
    }
    if n_zero {
        return Some(false);
    }
    let nn = n.dot(&n);
    let nd2 = nd.times(&nd);
    match tag {
        "grazing" => return le(&nd2, &N::of(pow2(-20)).times(&nn).times(&d.dot(&d))),
        "parallel-threshold" => {
            // (n.d)^2 <= (2e-8)^2 n.n
            let eps = N::of(2.0 * PARALLEL_EPSILON);
            return le(&nd2, &eps.times(&eps).times(&nn));
        }
        _ => {}
    }
    if nd_zero {
        return Some(false);
    }
    let tn = N::of(0.0).minus(&n.dot(&w));
    match tag {
        "interval-boundary" => {
            return Some(
                near_end_ratio(&tn, &nd, interval[0])? || near_end_ratio(&tn, &nd, interval[1])?,
            );
        }
        "behind" => return Some(tn.times(&nd).sign()? == Ordering::Less),
        _ => {}
    }
    // alpha nd = w.(v x d), beta nd = u.(w x d).
    let an = w.dot(&vn.cross(&d));
    let bn = un.dot(&w.cross(&d));
    let k = pow2(-20);
    let mut e = vec![within(&an, k, &nd)?, within(&bn, k, &nd)?];
    if triangle {
        e.push(within(&nd.minus(&an).minus(&bn), k, &nd)?);
    } else {
        e.push(within(&nd.minus(&an), k, &nd)?);
        e.push(within(&nd.minus(&bn), k, &nd)?);
    }
    match tag {
        "edge" => Some(e.iter().any(|&x| x)),
        "corner" => Some(if triangle {
            e.iter().filter(|&&x| x).count() >= 2
        } else {
            // e = [alpha ~ 0, beta ~ 0, alpha ~ 1, beta ~ 1]
            (e[0] || e[2]) && (e[1] || e[3])
        }),
        _ => Some(false),
    }
}

/// The tags to try, in order, in place of a tag whose definition does not hold for an
/// ambiguous case (the last resort is the judging's ill-conditioned tag).
fn fallbacks(tag: &str) -> &'static [&'static str] {
    match tag {
        "tangent" => &["near-tangent"],
        "grazing" => &["parallel-threshold"],
        "corner" => &["edge"],
        _ => &[],
    }
}

/// The tag of a case that is near no geometric boundary (by the definitions above) and still
/// ambiguous: only the judging's formulas cannot settle it.
pub fn ill_conditioned(judging: Judging) -> &'static str {
    match (judging.profile, judging.precision) {
        (Profile::Course, Precision::F64) => "naive-ill-conditioned",
        (Profile::Robust, Precision::F64) => "ill-conditioned",
        (Profile::Course, Precision::F32) => "naive-f32-ill-conditioned",
        (Profile::Robust, Precision::F32) => "f32-ill-conditioned",
    }
}

/// Keeps the tags whose definitions hold. For an `ambiguous` case, a tag that does not hold is
/// replaced by its nearest true neighbour (`tangent` by `near-tangent`, `grazing` by
/// `parallel-threshold`, `corner` by `edge`) or by the judging's ill-conditioned tag; for other
/// classes it is dropped. Sorted, unique.
pub fn truthful(
    tags: Vec<String>,
    ambiguous: bool,
    judging: Judging,
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
) -> Vec<String> {
    let mut out = Vec::with_capacity(tags.len());
    for t in tags {
        if holds(&t, shape, ray, interval) != Some(false) {
            out.push(t);
            continue;
        }
        if !ambiguous {
            continue;
        }
        let alt = fallbacks(&t)
            .iter()
            .find(|a| holds(a, shape, ray, interval) == Some(true))
            .copied()
            .unwrap_or(ill_conditioned(judging));
        out.push(alt.to_string());
    }
    out.sort();
    out.dedup();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f64; 3], d: [f64; 3]) -> RaySpec {
        RaySpec {
            origin: o,
            direction: d,
        }
    }

    #[test]
    fn definitions_hold_on_hand_made_cases_and_fail_just_beyond() {
        let s = ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 1.0,
        };
        let iv = [1e-6, f64::MAX];
        // The line x = 1 touches the unit sphere: disc = 0.
        let t = ray([1.0, 0.0, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("tangent", &s, &t, iv), Some(true));
        // dist = 1 - 2^-10: 1 - dist^2 ~ 2^-9 > 2^-20, < 2^-8.
        let nt = ray([1.0 - 2f64.powi(-10), 0.0, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("tangent", &s, &nt, iv), Some(false));
        assert_eq!(holds("near-tangent", &s, &nt, iv), Some(true));
        let far = ray([0.0, 0.0, 1000.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("far", &s, &far, iv), Some(true));
        let close = ray([0.0, 0.0, 999.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("far", &s, &close, iv), Some(false));
        assert_eq!(holds("random", &s, &far, iv), None);
        // A quad hit head-on with a tiny direction is neither grazing nor an edge case, but the
        // course's 1e-8 threshold on |unit(n).d| = 1e-9 decides it.
        let q = ShapeSpec::Quad {
            q: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
        };
        let tiny = ray([0.5, 0.5, 1.0], [0.0, 0.0, -1e-9]);
        assert_eq!(holds("grazing", &q, &tiny, iv), Some(false));
        assert_eq!(holds("parallel-threshold", &q, &tiny, iv), Some(true));
        assert_eq!(holds("edge", &q, &tiny, iv), Some(false));
        assert_eq!(holds("unnormalised", &q, &tiny, iv), Some(true));
        let corner = ray([1.0, 1.0, 1.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("corner", &q, &corner, iv), Some(true));
        let edge = ray([1.0, 0.5, 1.0], [0.0, 0.0, -1.0]);
        assert_eq!(holds("corner", &q, &edge, iv), Some(false));
        assert_eq!(holds("edge", &q, &edge, iv), Some(true));
        let graze = ray([0.5, 0.5, 1.0], [1.0, 0.0, -2f64.powi(-11)]);
        assert_eq!(holds("grazing", &q, &graze, iv), Some(true));
        assert_eq!(
            holds("interval-boundary", &q, &edge, [1.0, 2.0]),
            Some(true)
        );
        assert_eq!(
            holds("interval-boundary", &q, &edge, [1.01, 2.0]),
            Some(false)
        );
    }

    #[test]
    fn an_untrue_tag_of_an_ambiguous_case_becomes_its_neighbour_or_ill_conditioned() {
        let s = ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 1.0,
        };
        let nt = ray([1.0 - 2f64.powi(-10), 0.0, 5.0], [0.0, 0.0, -1.0]);
        let iv = [1e-6, f64::MAX];
        let tags = vec!["tangent".to_string(), "far".to_string()];
        assert_eq!(
            truthful(tags.clone(), true, Judging::COURSE, &s, &nt, iv),
            vec![
                "naive-ill-conditioned".to_string(),
                "near-tangent".to_string()
            ]
        );
        assert_eq!(
            truthful(tags, false, Judging::ROBUST, &s, &nt, iv),
            Vec::<String>::new()
        );
    }
}
