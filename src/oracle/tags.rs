//! What each tag of a vector means, as a predicate decided with exact arithmetic on the `f64`
//! inputs ([`holds`]). Classification keeps a tag only when its definition holds: a comparison
//! that the profile's band cannot settle, far from the boundary the tag names, is tagged with
//! [`Judging::ill_conditioned_tag`] instead (for example `naive-ill-conditioned`: a far sphere
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

use super::exact::{self, Dyadic, Num, V3};
use super::profile::Judging;
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

fn dy(x: f64) -> Dyadic {
    Dyadic::of(x)
}

fn pow2(k: i32) -> Dyadic {
    dy(libm::ldexp(1.0, k))
}

fn abs(x: &Dyadic) -> Dyadic {
    if x.signum() == Ordering::Less {
        x.neg()
    } else {
        x.clone()
    }
}

/// `|x| <= k |y|`.
fn within(x: &Dyadic, k: &Dyadic, y: &Dyadic) -> bool {
    abs(x).cmp_value(&k.mul(&abs(y))) != Ordering::Greater
}

/// `|t - end| <= 2^-20 max(|t|, |end|)` for finite `end`.
fn near_end(t: &Dyadic, end: f64) -> bool {
    if !end.is_finite() {
        return false;
    }
    let e = dy(end);
    let (at, ae) = (abs(t), abs(&e));
    let m = if at.cmp_value(&ae) == Ordering::Greater {
        at
    } else {
        ae
    };
    within(&t.sub(&e), &pow2(-20), &m)
}

/// Whether `tag`'s definition holds for the case; `None` for a tag without one (`random`,
/// `overflow`, the ill-conditioned tags, anything unknown).
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
    let d = V3::<Dyadic>::of(ray.direction);
    let dd = d.dot(&d);
    match tag {
        "scale" => {
            let big = libm::ldexp(1.0, 20);
            let small = libm::ldexp(1.0, -20);
            return Some(
                shape
                    .numbers()
                    .iter()
                    .chain(&ray.origin)
                    .chain(&ray.direction)
                    .any(|x| *x != 0.0 && (x.abs() >= big || x.abs() <= small)),
            );
        }
        "unnormalised" => {
            return Some(
                dd.cmp_value(&dy(0.25)) != Ordering::Greater
                    || dd.cmp_value(&dy(4.0)) != Ordering::Less,
            );
        }
        _ => {}
    }
    let o = V3::<Dyadic>::of(ray.origin);
    match *shape {
        ShapeSpec::Sphere { center, radius } => {
            let r = dy(radius);
            let r2 = r.mul(&r);
            let f = o.minus(&V3::of(center));
            let ff = f.dot(&f);
            let h = f.dot(&d); // = -d.(C - O)
            let disc = h.mul(&h).sub(&dd.mul(&ff.sub(&r2)));
            let ar2 = dd.mul(&r2);
            Some(match tag {
                "degenerate" => radius == 0.0 || ray.direction == [0.0; 3],
                "negative-radius" => radius < 0.0,
                "tangent" => within(&disc, &pow2(-20), &ar2),
                "near-tangent" => within(&disc, &pow2(-8), &ar2),
                "far" => ff.cmp_value(&dy(1e6).mul(&r2)) != Ordering::Less,
                "inside" => ff.cmp_value(&r2) == Ordering::Less,
                "tiny" => r2.mul(&pow2(20)).cmp_value(&ff) != Ordering::Greater,
                "behind" => h.signum() != Ordering::Less && ff.cmp_value(&r2) == Ordering::Greater,
                "interval-boundary" => {
                    let ex = exact::sphere_exact(center, radius, ray);
                    match ex.roots {
                        Some((near, far)) => [near, far]
                            .iter()
                            .any(|t| near_end(t, interval[0]) || near_end(t, interval[1])),
                        None => false,
                    }
                }
                _ => false,
            })
        }
        ShapeSpec::Quad { q, u, v } => Some(plane_holds(tag, q, u, v, false, ray, interval)),
        ShapeSpec::Triangle { a, b, c } => Some(plane_holds(tag, a, b, c, true, ray, interval)),
    }
}

fn plane_holds(
    tag: &str,
    q: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    triangle: bool,
    ray: &RaySpec,
    interval: [f64; 2],
) -> bool {
    let qn = V3::<Dyadic>::of(q);
    let (un, vn) = if triangle {
        (V3::of(u).minus(&qn), V3::of(v).minus(&qn))
    } else {
        (V3::of(u), V3::of(v))
    };
    let ex = exact::plane_exact(q, u, v, triangle, ray);
    let n = V3(ex.n.clone());
    let nn = n.dot(&n);
    let d = V3::<Dyadic>::of(ray.direction);
    let dd = d.dot(&d);
    let nd2 = ex.nd.mul(&ex.nd);
    let (uu, vv, uv) = (un.dot(&un), vn.dot(&vn), un.dot(&vn));
    let n_zero = ex.n.iter().all(|x| x.is_zero());
    let edges = || -> Vec<bool> {
        if ex.nd.is_zero() {
            return vec![false; 4];
        }
        let k = pow2(-20);
        let a_near_0 = within(&ex.an, &k, &ex.nd);
        let b_near_0 = within(&ex.bn, &k, &ex.nd);
        if triangle {
            let rest = ex.nd.sub(&ex.an).sub(&ex.bn);
            vec![a_near_0, b_near_0, within(&rest, &k, &ex.nd)]
        } else {
            vec![
                a_near_0,
                within(&ex.nd.sub(&ex.an), &k, &ex.nd),
                b_near_0,
                within(&ex.nd.sub(&ex.bn), &k, &ex.nd),
            ]
        }
    };
    match tag {
        "degenerate" => n_zero || ray.direction == [0.0; 3] || (ex.nd.is_zero() && ex.tn.is_zero()),
        "parallel" => !n_zero && ex.nd.is_zero(),
        "grazing" => !n_zero && nd2.cmp_value(&pow2(-20).mul(&nn).mul(&dd)) != Ordering::Greater,
        "parallel-threshold" => {
            // (n.d)^2 <= (2e-8)^2 n.n
            let eps = dy(2.0 * PARALLEL_EPSILON);
            !n_zero && nd2.cmp_value(&eps.mul(&eps).mul(&nn)) != Ordering::Greater
        }
        "edge" => edges().iter().any(|&e| e),
        "corner" => {
            let e = edges();
            if triangle {
                e.iter().filter(|&&x| x).count() >= 2
            } else {
                (e[0] || e[1]) && (e[2] || e[3])
            }
        }
        "interval-boundary" => {
            !ex.nd.is_zero() && {
                let t = ex.tn.div_approx(&ex.nd, 130);
                near_end(&t, interval[0]) || near_end(&t, interval[1])
            }
        }
        "behind" => !ex.nd.is_zero() && ex.tn.mul(&ex.nd).signum() == Ordering::Less,
        "tiny" => {
            let w = V3::<Dyadic>::of(ray.origin).minus(&qn);
            let big = if uu.cmp_value(&vv) == Ordering::Less {
                vv.clone()
            } else {
                uu.clone()
            };
            big.mul(&pow2(20)).cmp_value(&w.dot(&w)) != Ordering::Greater
        }
        "skewed" => uv.mul(&uv).cmp_value(&dy(0.75).mul(&uu).mul(&vv)) != Ordering::Less,
        "skinny" => {
            let (lo, hi) = if uu.cmp_value(&vv) == Ordering::Less {
                (uu, vv)
            } else {
                (vv, uu)
            };
            hi.cmp_value(&dy(256.0).mul(&lo)) != Ordering::Less
        }
        _ => false,
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
            .unwrap_or(judging.ill_conditioned_tag());
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
