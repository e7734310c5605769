//! Classification of a case into `hit` / `miss` (definite), `ambiguous` or `any`, by the
//! error-band policy of `docs/oracle.md` ("Classes", "Profiles and precision").
//!
//! The exact answer comes from [`super::exact`]. Each comparison the course's code makes on the
//! way to that answer is then checked against the band of its naive formula (see
//! [`super::band`]), widened by [`K`]: the case is definite only when every comparison that
//! decides it lies outside its band, so every honest `f64` variant reaches the same answer.
//!
//! Which formulas give the bands, and in which precision, is the [`Judging`]: [`analyse`] and
//! [`classify`] use [`Judging::COURSE`] (today's policy); the `_with` functions take any.
//! Tags are kept only when their definitions ([`super::tags`]) hold.

use super::band::{
    B3, Band, Iv, Iv32, K, PlaneBands, SphereBands, b3, bsub, plane_bands_in,
    robust_sphere_bands_in, sphere_bands_in, sphere_normal_radius,
};
use super::exact::{self, Decision, ExactHit, PlaneSigns, Root};
use super::profile::{Judging, Precision, Profile};
use super::tags;
use super::vectors::{Class, Expect, RaySpec, ShapeSpec};
use crate::geometry::PARALLEL_EPSILON;

/// One deciding comparison and its band.
#[derive(Clone, Debug)]
pub struct Check {
    /// What is compared, in words (`"disc = half_b^2 - a c"`, `"alpha"`, `"t - t_min"`, ...).
    pub quantity: &'static str,
    /// The tag a case gets when this comparison is ambiguous.
    pub tag: &'static str,
    /// The naive formula's interval enclosure, before widening.
    pub band: Iv,
    /// The exact sign: `true` when the comparison passes (`> 0` / `>= 0`).
    pub passes: bool,
    /// Whether the band widened by `K` excludes zero.
    pub definite: bool,
}

impl Check {
    fn new(quantity: &'static str, tag: &'static str, band: Iv, passes: bool) -> Self {
        let w = band.widen(K);
        let definite = if passes { w.lo > 0.0 } else { w.hi < 0.0 };
        Check {
            quantity,
            tag,
            band,
            passes,
            definite,
        }
    }
}

/// Everything the oracle knows about one case.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// The exact decision (`None` for non-finite inputs).
    pub decision: Option<Decision>,
    /// Whether the interval filter decided without exact arithmetic.
    pub by_filter: bool,
    /// The exact hit, rounded.
    pub hit: Option<ExactHit>,
    /// The comparisons on the course's path and their bands.
    pub checks: Vec<Check>,
    /// The class.
    pub class: Class,
    /// Tags the classification found (`tangent`, `edge`, `grazing`, ...).
    pub tags: Vec<String>,
    /// `t_tol` of a hit.
    pub t_tol: Option<f64>,
    /// Words on why the case is not definite, if it is not.
    pub why: Option<String>,
    /// What the case was judged by.
    pub judging: Judging,
}

/// Classifies a case: its class, tags, and for a hit the exact `t`, `t_tol`, point, normal and
/// `front_face`.
pub fn classify(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Expect {
    analyse(shape, ray, interval).expect(&[])
}

/// [`classify`] under `judging`.
pub fn classify_with(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    judging: Judging,
) -> Expect {
    analyse_with(shape, ray, interval, judging).expect(&[])
}

/// Classifies a case and merges the generator's `tags` into the answer.
pub fn classify_tagged(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    tags: &[&str],
) -> Expect {
    classify_tagged_with(shape, ray, interval, tags, Judging::COURSE)
}

/// [`classify_tagged`] under `judging`; a generator's tag is kept only when its definition
/// ([`super::tags`]) holds.
pub fn classify_tagged_with(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    extra: &[&str],
    judging: Judging,
) -> Expect {
    let mut a = analyse_with(shape, ray, interval, judging);
    let mut all = a.tags.clone();
    all.extend(extra.iter().map(|t| t.to_string()));
    a.tags = tags::truthful(
        all,
        a.class == Class::Ambiguous,
        judging,
        shape,
        ray,
        interval,
    );
    a.expect(&[])
}

impl Analysis {
    /// The vector file's `expect` object, with `extra` tags merged in (sorted, unique).
    pub fn expect(&self, extra: &[&str]) -> Expect {
        let mut tags: Vec<String> = self
            .tags
            .iter()
            .cloned()
            .chain(extra.iter().map(|s| s.to_string()))
            .collect();
        tags.sort();
        tags.dedup();
        let hit = self.hit.filter(|_| self.class != Class::Any);
        Expect {
            class: self.class,
            tags,
            t: hit.map(|h| h.t),
            t_tol: hit.and(self.t_tol),
            point: hit.map(|h| h.point),
            normal: hit.map(|h| h.normal),
            front_face: hit.map(|h| h.front_face),
            normal_tol: (hit.is_some() && self.judging.precision != Precision::F64)
                .then(|| self.judging.normal_tol()),
            watertight: None,
        }
    }
}

fn any(tag: &str, decision: Option<Decision>, by_filter: bool, why: &str) -> Analysis {
    Analysis {
        decision,
        by_filter,
        hit: None,
        checks: vec![],
        class: Class::Any,
        tags: vec![tag.to_string()],
        t_tol: None,
        why: Some(why.to_string()),
        judging: Judging::COURSE,
    }
}

fn t_tol(band: Iv, t: f64, judging: Judging) -> Option<f64> {
    let tol = (band.rad() * K).max(judging.t_floor() * t.abs());
    tol.is_finite().then_some(tol)
}

/// The full analysis of a case under [`Judging::COURSE`].
pub fn analyse(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Analysis {
    analyse_with(shape, ray, interval, Judging::COURSE)
}

/// The full analysis of a case under `judging`, its tags kept only where they hold.
pub fn analyse_with(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    judging: Judging,
) -> Analysis {
    let mut a = match judging.precision {
        Precision::F64 => analyse_in::<Iv>(shape, ray, interval, judging),
        Precision::F32 => analyse_in::<Iv32>(shape, ray, interval, judging),
    };
    a.judging = judging;
    a.tags = tags::truthful(
        std::mem::take(&mut a.tags),
        a.class == Class::Ambiguous,
        judging,
        shape,
        ray,
        interval,
    );
    a
}

/// An interval end as code in precision `B` compares with it.
fn end<B: Band>(x: f64) -> Iv {
    B::input(x).iv()
}

fn analyse_in<B: Band>(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    judging: Judging,
) -> Analysis {
    if !exact::inputs_finite(shape, ray, interval) {
        return any(
            "nonfinite",
            None,
            false,
            "an input is NaN or infinite: any answer (or an error) is accepted",
        );
    }
    let (decision, by_filter) = exact::decide(shape, ray, interval);
    if decision == Decision::Degenerate {
        let why = match shape {
            ShapeSpec::Sphere { .. } if ray.direction == [0.0; 3] => "the direction is zero",
            ShapeSpec::Sphere { .. } => "the radius is zero",
            _ if ray.direction == [0.0; 3] => "the direction is zero",
            _ => "the primitive is degenerate (u x v = 0) or the ray lies in its plane",
        };
        let mut a = any("degenerate", Some(decision), by_filter, why);
        if !matches!(shape, ShapeSpec::Sphere { .. }) && ray.direction != [0.0; 3] {
            if let Some(s) = exact::plane_signs(shape, ray, interval) {
                if s.parallel {
                    a.tags.push("parallel".into());
                }
            }
        }
        return a;
    }
    let hit = exact::exact_hit(shape, ray, decision);
    let ctx = Ctx {
        decision,
        by_filter,
        hit,
        judging,
    };
    match *shape {
        ShapeSpec::Sphere { center, radius } => sphere::<B>(center, radius, ray, interval, ctx),
        ShapeSpec::Quad { q, u, v } => {
            let s = exact::plane_signs(shape, ray, interval).expect("a plane shape");
            let bands = plane_bands_in::<B>(b3(q), b3(u), b3(v), ray.origin, ray.direction);
            plane::<B>(false, bands, s, ray, interval, ctx)
        }
        ShapeSpec::Triangle { a, b, c } => {
            let s = exact::plane_signs(shape, ray, interval).expect("a plane shape");
            let qa: B3<B> = b3(a);
            let bands = plane_bands_in::<B>(
                qa,
                bsub(b3(b), qa),
                bsub(b3(c), qa),
                ray.origin,
                ray.direction,
            );
            plane::<B>(true, bands, s, ray, interval, ctx)
        }
    }
}

/// What every classification step carries along.
#[derive(Clone, Copy)]
struct Ctx {
    decision: Decision,
    by_filter: bool,
    hit: Option<ExactHit>,
    judging: Judging,
}

/// The words for a profile's formulas in its precision.
fn formulas(j: Judging) -> String {
    let who = match j.profile {
        Profile::Course => "the course's naive formula",
        Profile::Robust => "the robust formula",
    };
    format!("{who} in {}", j.precision)
}

fn finish(
    ctx: Ctx,
    checks: Vec<Check>,
    definite: bool,
    mut tags: Vec<String>,
    t_band: Option<Iv>,
    why: Option<String>,
) -> Analysis {
    let Ctx {
        decision,
        by_filter,
        hit,
        judging,
    } = ctx;
    let is_hit = hit.is_some();
    let overflow = checks
        .iter()
        .any(|c| !(c.definite || c.band.lo.is_finite() || c.band.hi.is_finite()));
    if !definite {
        for c in &checks {
            if !c.definite {
                tags.push(c.tag.to_string());
            }
        }
        if overflow {
            tags.push("overflow".into());
        }
    }
    tags.sort();
    tags.dedup();
    let class = match (definite, is_hit) {
        (false, _) => Class::Ambiguous,
        (true, true) => Class::Hit,
        (true, false) => Class::Miss,
    };
    let why = if definite {
        why
    } else {
        why.or_else(|| {
            let names: Vec<String> = checks
                .iter()
                .filter(|c| !c.definite)
                .map(|c| {
                    let w = c.band.widen(K);
                    format!(
                        "{} (exactly {}, but the band of {} widened by K = {K} is [{:e}, {:e}], which holds 0)",
                        c.quantity,
                        if c.passes { "passes" } else { "fails" },
                        formulas(judging),
                        w.lo,
                        w.hi
                    )
                })
                .collect();
            Some(names.join("; "))
        })
    };
    let t_tol = match (hit, t_band) {
        (Some(h), Some(b)) => t_tol(b, h.t, judging),
        _ => None,
    };
    Analysis {
        decision: Some(decision),
        by_filter,
        hit,
        checks,
        class,
        tags,
        t_tol,
        why,
        judging,
    }
}

fn sphere<B: Band>(
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    interval: [f64; 2],
    ctx: Ctx,
) -> Analysis {
    let decision = ctx.decision;
    let b: SphereBands = match ctx.judging.profile {
        Profile::Course => sphere_bands_in::<B>(center, radius, ray.origin, ray.direction),
        Profile::Robust => robust_sphere_bands_in::<B>(center, radius, ray.origin, ray.direction),
    };
    let (tmin, tmax) = (end::<B>(interval[0]), end::<B>(interval[1]));
    // Exact comparisons (from the decision and the exact roots).
    let ex = exact::sphere_exact_roots(center, radius, ray, false);
    let disc_pos = ex.disc.signum() == std::cmp::Ordering::Greater;
    let disc_neg = ex.disc.signum() == std::cmp::Ordering::Less;
    let mut checks = vec![Check::new(
        match ctx.judging.profile {
            Profile::Course => "disc = half_b^2 - a c > 0",
            Profile::Robust => "disc = a (r^2 - |f - (f.d/a) d|^2) > 0",
        },
        "tangent",
        b.disc,
        disc_pos,
    )];
    let mut tags = vec![];
    if radius < 0.0 {
        tags.push("negative-radius".to_string());
    }
    if disc_neg {
        let definite = checks[0].definite;
        return finish(ctx, checks, definite, tags, None, None);
    }
    // Exact root comparisons with the open interval.
    let cmp = |root: Root| root_signs(&ex, root, interval);
    let (near_after, near_before) = cmp(Root::Near);
    checks.push(Check::new(
        "t_near - t_min > 0",
        "interval-boundary",
        b.t_near - tmin,
        near_after,
    ));
    if near_after {
        checks.push(Check::new(
            "t_max - t_near > 0",
            "interval-boundary",
            tmax - b.t_near,
            near_before,
        ));
    }
    if disc_pos && near_after && near_before {
        let definite = checks.iter().all(|c| c.definite);
        let (definite, why) = normal_check::<B>(
            definite,
            center,
            radius,
            ray,
            b.t_near,
            ctx.judging,
            &mut tags,
        );
        return finish(ctx, checks, definite, tags, Some(b.t_near), why);
    }
    let near_fails_definitely = checks[1..].iter().any(|c| !c.passes && c.definite);
    let (far_after, far_before) = cmp(Root::Far);
    let n_near = checks.len();
    checks.push(Check::new(
        "t_far - t_min > 0",
        "interval-boundary",
        b.t_far - tmin,
        far_after,
    ));
    if far_after {
        checks.push(Check::new(
            "t_max - t_far > 0",
            "interval-boundary",
            tmax - b.t_far,
            far_before,
        ));
    }
    let far_fails_definitely = checks[n_near..].iter().any(|c| !c.passes && c.definite);
    let definite = match decision {
        Decision::SphereHit(Root::Far) => {
            checks[0].definite
                && near_fails_definitely
                && checks[n_near..].iter().all(|c| c.definite)
        }
        _ => (checks[0].definite || disc_pos) && near_fails_definitely && far_fails_definitely,
    };
    // A tangent ray whose roots both miss the interval is still a miss for every variant; a
    // tangent ray that hits is not definite.
    let definite = definite && (checks[0].definite || decision == Decision::Miss);
    let (definite, why) = if decision == Decision::SphereHit(Root::Far) {
        normal_check::<B>(
            definite,
            center,
            radius,
            ray,
            b.t_far,
            ctx.judging,
            &mut tags,
        )
    } else {
        (definite, None)
    };
    if ex.disc.is_zero() && decision == Decision::Miss && definite {
        // Exact tangent outside the interval: fine, but say so.
        tags.push("tangent".into());
    }
    finish(ctx, checks, definite, tags, Some(b.t_far), why)
}

/// A definite sphere hit also needs the profile's normal `(O + t d - C) / r` within the
/// judging's normal tolerance: far from the sphere, or far from the origin of coordinates, the
/// computed `t` and point are too coarse for that, and the case is ambiguous (tagged with the
/// judging's ill-conditioned tag).
fn normal_check<B: Band>(
    definite: bool,
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    t: Iv,
    judging: Judging,
    tags: &mut Vec<String>,
) -> (bool, Option<String>) {
    if !definite {
        return (false, None);
    }
    let worst = sphere_normal_radius::<B>(center, radius, ray.origin, ray.direction, t);
    let tol = judging.normal_tol();
    if worst <= tol {
        (true, None)
    } else {
        tags.push(super::tags::ill_conditioned(judging).into());
        (
            false,
            Some(format!(
                "the decision is certain, but the normal (O + t d - C) / r of {} is only known to +-{worst:e} (band widened by K = {K}), more than the {tol:e} it is compared to",
                formulas(judging)
            )),
        )
    }
}

/// Exact `(t > t_min, t < t_max)` of a root.
fn root_signs(ex: &exact::SphereExact, root: Root, interval: [f64; 2]) -> (bool, bool) {
    use exact::{Dyadic, Num};
    use std::cmp::Ordering::*;
    let disc = &ex.disc;
    let sqrt_vs = |q: &Dyadic| match q.signum() {
        Less => Greater,
        Equal => disc.signum(),
        Greater => disc.sub(&q.mul(q)).signum(),
    };
    let x = (!interval[0].is_infinite()).then(|| ex.h.sub(&ex.a.mul(&Dyadic::of(interval[0]))));
    let y = (!interval[1].is_infinite()).then(|| ex.h.sub(&ex.a.mul(&Dyadic::of(interval[1]))));
    match root {
        Root::Near => (
            x.as_ref().is_none_or(|x| sqrt_vs(x) == Less),
            y.as_ref().is_none_or(|y| sqrt_vs(y) == Greater),
        ),
        Root::Far => (
            x.as_ref().is_none_or(|x| sqrt_vs(&x.neg()) == Greater),
            y.as_ref().is_none_or(|y| sqrt_vs(&y.neg()) == Less),
        ),
    }
}

fn plane<B: Band>(
    triangle: bool,
    b: PlaneBands,
    s: PlaneSigns,
    ray: &RaySpec,
    interval: [f64; 2],
    ctx: Ctx,
) -> Analysis {
    if s.parallel {
        return parallel_plane::<B>(b, ctx);
    }
    let checks = plane_checks::<B>(triangle, &b, &s, interval);
    let geometric_hit = checks.iter().all(|c| c.passes);
    let mut tags = vec![];
    let mut why = None;
    let definite = if geometric_hit {
        match shallow_hit(&b, &s, ray) {
            Some((tag, words)) => {
                tags.push(tag.to_string());
                why = Some(words);
                false
            }
            None => checks.iter().all(|c| c.definite),
        }
    } else {
        checks.iter().any(|c| !c.passes && c.definite)
    };
    // Edge ambiguity on two edges at once is a corner.
    let edge_amb = checks[2..].iter().filter(|c| !c.definite).count();
    if !definite && edge_amb >= 2 {
        tags.push("corner".into());
    }
    finish(ctx, checks, definite, tags, Some(b.t), why)
}

/// A ray exactly parallel to the plane and off it (in the plane is degenerate, handled before).
/// It is a definite miss when the course's `f64` denominator `unit(n) . d` is surely below the
/// 1e-8 threshold; with large or skewed inputs the rounded unit normal is not exactly
/// perpendicular to d, honest code computes a t, and the case is ambiguous.
fn parallel_plane<B: Band>(b: PlaneBands, ctx: Ctx) -> Analysis {
    let check = Check::new(
        "1e-8 - |unit(n) . d| > 0 (parallel)",
        "grazing",
        end::<B>(PARALLEL_EPSILON) - b.denom.abs(),
        true,
    );
    let definite = check.definite;
    Analysis {
        decision: Some(ctx.decision),
        by_filter: ctx.by_filter,
        hit: None,
        checks: vec![check],
        class: if definite {
            Class::Miss
        } else {
            Class::Ambiguous
        },
        tags: if definite {
            vec!["parallel".into()]
        } else {
            vec!["grazing".into(), "parallel".into()]
        },
        t_tol: None,
        why: (!definite).then(|| {
            format!("the ray is exactly parallel to the plane, but the rounded unit normal of {} is not exactly perpendicular to d, so honest code may compute a t", formulas(ctx.judging))
        }),
        judging: ctx.judging,
    }
}

/// The comparisons on the course's path to a plane decision: the two interval ends first, then
/// the edges (a quad's `alpha`, `1 - alpha`, `beta`, `1 - beta`; a triangle's three
/// barycentrics).
fn plane_checks<B: Band>(
    triangle: bool,
    b: &PlaneBands,
    s: &PlaneSigns,
    interval: [f64; 2],
) -> Vec<Check> {
    let (tmin, tmax) = (end::<B>(interval[0]), end::<B>(interval[1]));
    let one = Iv::point(1.0);
    let mut checks = vec![
        Check::new(
            "t - t_min >= 0",
            "interval-boundary",
            b.t - tmin,
            s.after_min,
        ),
        Check::new(
            "t_max - t >= 0",
            "interval-boundary",
            tmax - b.t,
            s.before_max,
        ),
    ];
    if triangle {
        checks.push(Check::new(
            "beta_b >= 0 (edge ca)",
            "edge",
            b.alpha,
            s.alpha_ge_0,
        ));
        checks.push(Check::new(
            "beta_c >= 0 (edge ab)",
            "edge",
            b.beta,
            s.beta_ge_0,
        ));
        checks.push(Check::new(
            "1 - beta_b - beta_c >= 0 (edge bc)",
            "edge",
            one - b.alpha - b.beta,
            s.alpha_le_1,
        ));
    } else {
        checks.push(Check::new("alpha >= 0", "edge", b.alpha, s.alpha_ge_0));
        checks.push(Check::new(
            "1 - alpha >= 0",
            "edge",
            one - b.alpha,
            s.alpha_le_1,
        ));
        checks.push(Check::new("beta >= 0", "edge", b.beta, s.beta_ge_0));
        checks.push(Check::new(
            "1 - beta >= 0",
            "edge",
            one - b.beta,
            s.beta_le_1,
        ));
    }
    // Only the comparisons that can pass or fail matter; a passing t comparison with an
    // infinite interval end is trivially definite.
    for (c, end) in checks.iter_mut().zip(interval) {
        if end.is_infinite() {
            c.definite = true;
        }
    }
    checks
}

/// Why a ray that meets the primitive is still not a definite hit because of its angle to the
/// plane: the tag and the words, or `None` when the angle does not matter.
fn shallow_hit(b: &PlaneBands, s: &PlaneSigns, ray: &RaySpec) -> Option<(&'static str, String)> {
    let dir: B3<Iv> = b3(ray.direction);
    let len_d = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
    let denom = b.denom.abs();
    let near_threshold = denom.lo < PARALLEL_EPSILON * (1.0 + 1e-6);
    let shallow = denom.lo < 1e-6 * len_d.hi;
    if s.below_threshold || near_threshold {
        // The course's absolute threshold on |unit(n) . d| decides, or may.
        let words = if s.below_threshold {
            format!(
                "the ray meets the primitive, but exactly |unit(n) . d| < 1e-8 (its band is [{:e}, {:e}]): the course's absolute parallel threshold rejects it, so the exact answer is a miss; code that tests only denom == 0 hits, so it is not scored",
                denom.lo, denom.hi
            )
        } else {
            format!(
                "the ray meets the primitive, but |unit(n) . d| is in [{:e}, {:e}], within rounding of the course's absolute parallel threshold 1e-8, so honest code may reject it",
                denom.lo, denom.hi
            )
        };
        Some(("parallel-threshold", words))
    } else if shallow {
        Some((
            "grazing",
            format!(
                "the ray is nearly parallel to the plane: |unit(n) . d| / |d| is in [{:e}, {:e}], below 1e-6, where code that normalises d or scales the threshold differs",
                denom.lo / len_d.hi,
                denom.hi / len_d.lo
            ),
        ))
    } else {
        None
    }
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

    const CAM: [f64; 2] = [1e-6, f64::MAX];

    #[test]
    fn plain_hits_and_misses_are_definite_with_exact_t() {
        let s = ShapeSpec::Sphere {
            center: [0.0, 0.0, -5.0],
            radius: 1.0,
        };
        let e = classify(&s, &ray([0.0; 3], [0.0, 0.0, -1.0]), CAM);
        assert_eq!(
            e.class,
            Class::Hit,
            "{:#?}",
            analyse(&s, &ray([0.0; 3], [0.0, 0.0, -1.0]), CAM)
        );
        assert_eq!(e.t, Some(4.0));
        assert_eq!(e.normal, Some([0.0, 0.0, 1.0]));
        assert_eq!(e.front_face, Some(true));
        let e = classify(&s, &ray([0.0; 3], [0.0, 1.0, -1.0]), CAM);
        assert_eq!(e.class, Class::Miss);
    }

    #[test]
    fn exact_tangent_is_ambiguous_and_tagged() {
        // d = (2,3,6), n = (6,2,-3): orthogonal, both of length 7; O = C + n - s d.
        let s = ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 7.0,
        };
        let o = [6.0 - 20.0, 2.0 - 30.0, -3.0 - 60.0];
        let e = classify(&s, &ray(o, [2.0, 3.0, 6.0]), CAM);
        assert_eq!(e.class, Class::Ambiguous);
        assert!(e.tags.contains(&"tangent".to_string()), "{:?}", e.tags);
        assert_eq!(e.t, Some(10.0));
    }

    #[test]
    fn quad_corner_hit_is_ambiguous_and_parallel_off_plane_is_a_definite_miss() {
        let q = ShapeSpec::Quad {
            q: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
        };
        let e = classify(&q, &ray([1.0, 1.0, 1.0], [0.0, 0.0, -1.0]), CAM);
        assert_eq!(e.class, Class::Ambiguous);
        assert!(e.tags.contains(&"corner".to_string()), "{:?}", e.tags);
        assert_eq!(e.t, Some(1.0));
        let e = classify(&q, &ray([0.5, 0.5, 1.0], [1.0, 2.0, 0.0]), CAM);
        assert_eq!(e.class, Class::Miss);
        assert_eq!(e.tags, vec!["parallel".to_string()]);
        let e = classify(&q, &ray([0.5, 0.5, 0.0], [1.0, 2.0, 0.0]), CAM);
        assert_eq!(e.class, Class::Any);
    }

    #[test]
    fn nonfinite_and_degenerate_are_any() {
        let s = ShapeSpec::Sphere {
            center: [0.0, 0.0, f64::NAN],
            radius: 1.0,
        };
        assert_eq!(
            classify(&s, &ray([0.0; 3], [0.0, 0.0, -1.0]), CAM).class,
            Class::Any
        );
        let t = ShapeSpec::Triangle {
            a: [0.0; 3],
            b: [1.0, 1.0, 1.0],
            c: [2.0, 2.0, 2.0],
        };
        let e = classify(&t, &ray([0.0; 3], [0.0, 0.0, -1.0]), CAM);
        assert_eq!(e.class, Class::Any);
        assert_eq!(e.tags, vec!["degenerate".to_string()]);
    }
}
