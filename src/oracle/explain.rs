//! Step-by-step explanations of the oracle's answer for one case, in words a student can
//! follow: the exact quantities, the band that made a case ambiguous, and the answer.

use std::cmp::Ordering;
use std::fmt::Write;

use super::band::K;
use super::classify::{Analysis, analyse_with};
use super::exact::{self, Decision, Dyadic, Root};
use super::profile::{Judging, Profile};
use super::vectors::{Case, Class, RaySpec, ShapeSpec};

/// A dyadic as a number a reader can take in: the `f64` itself when it is exact, else `~x`.
fn show(d: &Dyadic) -> String {
    let f = d.to_f64();
    match Dyadic::from_f64(f) {
        Some(e) if e.cmp_value(d) == Ordering::Equal => format!("{f:?} (exactly)"),
        _ => format!("~{f:e} (not an f64; rounded for display)"),
    }
}

fn sign_word(s: Ordering) -> &'static str {
    match s {
        Ordering::Less => "negative",
        Ordering::Equal => "exactly zero",
        Ordering::Greater => "positive",
    }
}

fn v(x: [f64; 3]) -> String {
    format!("({:?}, {:?}, {:?})", x[0], x[1], x[2])
}

/// The explanation of `case` under the course profile in `f64` (its `expect` is recomputed, not
/// trusted).
pub fn explain(case: &Case) -> String {
    explain_with(case, Judging::COURSE)
}

/// The explanation of `case` under `judging`.
pub fn explain_with(case: &Case, judging: Judging) -> String {
    let mut s = String::new();
    let a = analyse_with(&case.shape, &case.ray, case.interval, judging);
    let (r, iv) = (&case.ray, case.interval);
    let _ = writeln!(s, "case {}", case.id);
    match case.shape {
        ShapeSpec::Sphere { center, radius } => {
            let _ = writeln!(
                s,
                "  sphere  centre C = {}, radius r = {radius:?}",
                v(center)
            );
        }
        ShapeSpec::Quad { q, u, v: e } => {
            let _ = writeln!(
                s,
                "  quad    corner Q = {}, edges u = {}, v = {}",
                v(q),
                v(u),
                v(e)
            );
        }
        ShapeSpec::Triangle { a, b, c } => {
            let _ = writeln!(s, "  triangle a = {}, b = {}, c = {}", v(a), v(b), v(c));
        }
    }
    let _ = writeln!(
        s,
        "  ray     origin O = {}, direction d = {}",
        v(r.origin),
        v(r.direction)
    );
    let open = matches!(case.shape, ShapeSpec::Sphere { .. });
    let _ = writeln!(
        s,
        "  interval {}{:?}, {:?}{} ({} for this shape)",
        if open { "(" } else { "[" },
        iv[0],
        iv[1],
        if open { ")" } else { "]" },
        if open { "open" } else { "closed" }
    );
    let _ = writeln!(s);
    if a.decision.is_none() {
        let _ = writeln!(
            s,
            "An input is NaN or infinite, so nothing can be computed exactly."
        );
        answer(&mut s, &a);
        return s;
    }
    let _ = writeln!(
        s,
        "Exact arithmetic (every f64 is a fraction m * 2^e, so these are computed without rounding;\n\
         the fast interval filter {} decide this case{}):",
        if a.by_filter { "could" } else { "could not" },
        if a.by_filter {
            ""
        } else {
            ", so big-integer arithmetic did"
        }
    );
    match case.shape {
        ShapeSpec::Sphere { center, radius } => sphere(&mut s, center, radius, r, iv, &a),
        ShapeSpec::Quad { .. } | ShapeSpec::Triangle { .. } => plane(&mut s, &case.shape, r, iv),
    }
    let _ = writeln!(s);
    answer(&mut s, &a);
    s
}

fn sphere(
    s: &mut String,
    center: [f64; 3],
    radius: f64,
    ray: &RaySpec,
    iv: [f64; 2],
    a: &Analysis,
) {
    if a.decision == Some(Decision::Degenerate) {
        let _ = writeln!(
            s,
            "  the radius or the direction is zero: the sphere is degenerate."
        );
        return;
    }
    let ex = exact::sphere_exact(center, radius, ray);
    let _ = writeln!(s, "  a = d.d                 = {}", show(&ex.a));
    let _ = writeln!(s, "  h = d.(C - O)           = {}", show(&ex.h));
    let _ = writeln!(s, "  c = |C - O|^2 - r^2     = {}", show(&ex.c));
    let _ = writeln!(
        s,
        "  disc = h^2 - a c        = {}: {}",
        show(&ex.disc),
        sign_word(ex.disc.signum())
    );
    match ex.disc.signum() {
        Ordering::Less => {
            let _ = writeln!(
                s,
                "  disc < 0: the line of the ray passes beside the sphere."
            );
        }
        _ => {
            if ex.disc.is_zero() {
                let _ = writeln!(
                    s,
                    "  disc = 0: the ray touches the sphere (a tangent); both roots are equal."
                );
            }
            let (near, far) = ex.roots.clone().expect("disc >= 0");
            let _ = writeln!(
                s,
                "  roots t = (h -+ sqrt(disc)) / a: near {:?}, far {:?}",
                near.to_f64(),
                far.to_f64()
            );
            let _ = writeln!(
                s,
                "  the course takes the near root if t_min < t < t_max, else the far root if that is inside, else a miss."
            );
            let what = match a.decision {
                Some(Decision::SphereHit(Root::Near)) => {
                    "the near root is inside the interval: it is the hit".to_string()
                }
                Some(Decision::SphereHit(Root::Far)) => {
                    "the near root is not inside the interval, the far root is: it is the hit"
                        .to_string()
                }
                _ => format!(
                    "neither root lies strictly inside ({:?}, {:?}): a miss",
                    iv[0], iv[1]
                ),
            };
            let _ = writeln!(s, "  {what}.");
        }
    }
}

/// The exact quantities of a quad or triangle case, from its normal to the signs that decide it.
fn plane(s: &mut String, shape: &ShapeSpec, ray: &RaySpec, iv: [f64; 2]) {
    let (q, u, v, triangle) = match *shape {
        ShapeSpec::Quad { q, u, v } => (q, u, v, false),
        ShapeSpec::Triangle { a, b, c } => (a, b, c, true),
        ShapeSpec::Sphere { .. } => return,
    };
    let ex = exact::plane_exact(q, u, v, triangle, ray);
    let edges = if triangle {
        "(b - a) x (c - a)"
    } else {
        "u x v"
    };
    let n: Vec<String> = ex.n.iter().map(|x| format!("{:?}", x.to_f64())).collect();
    let _ = writeln!(s, "  n = {edges} = ({})", n.join(", "));
    if ex.n.iter().all(|x| x.is_zero()) {
        let _ = writeln!(
            s,
            "  n = 0: the primitive is degenerate (its edges are parallel); it has no plane."
        );
        return;
    }
    let _ = writeln!(s, "  n.d = {}: {}", show(&ex.nd), sign_word(ex.nd.signum()));
    if ex.nd.is_zero() {
        let _ = if ex.tn.is_zero() {
            writeln!(
                s,
                "  n.d = 0 and O lies in the plane: the ray runs inside the plane (degenerate)."
            )
        } else {
            writeln!(
                s,
                "  n.d = 0 and O is off the plane: the ray is parallel to it and never meets it."
            )
        };
        return;
    }
    plane_angle(s, &ex, ray);
    plane_coordinates(s, &ex, triangle);
    if let Some(sg) = exact::plane_signs(shape, ray, iv) {
        plane_signs(s, &sg, triangle);
    }
}

/// The angle between the ray and a plane it is not parallel to, against the course's threshold.
fn plane_angle(s: &mut String, ex: &exact::PlaneExact, ray: &RaySpec) {
    // Exact quantities shown rounded: |unit(n).d| = |n.d| / |n|, and its ratio to |d|.
    let nn = ex.n[0]
        .mul(&ex.n[0])
        .add(&ex.n[1].mul(&ex.n[1]))
        .add(&ex.n[2].mul(&ex.n[2]));
    let eps = Dyadic::from_f64(crate::geometry::PARALLEL_EPSILON).expect("finite");
    let dd: f64 = ray.direction.iter().map(|x| x * x).sum();
    let nd = ex.nd.to_f64().abs();
    let len_n = nn.to_f64().sqrt();
    let denom = nd / len_n;
    let ratio = denom / dd.sqrt();
    let _ = writeln!(
        s,
        "  |unit(n).d| = ~{denom:e}: {} the course's absolute parallel threshold 1e-8",
        if ex.nd.mul(&ex.nd).cmp_value(&nn.mul(&eps.mul(&eps))) == Ordering::Less {
            "below"
        } else {
            "not below"
        }
    );
    let _ = writeln!(
        s,
        "  |unit(n).d| / |d| = ~{ratio:e} (the cosine between the ray and the normal; a hit with this below 1e-6 is not scored, grazing means <= 2^-10)"
    );
}

/// The hit parameter and the surface coordinates of the line's hit with the plane.
fn plane_coordinates(s: &mut String, ex: &exact::PlaneExact, triangle: bool) {
    let tq = if triangle { "a" } else { "Q" };
    let _ = writeln!(
        s,
        "  t = n.({tq} - O) / n.d   = {:?}",
        ex.tn.div_to_f64(&ex.nd)
    );
    let (an, bn) = (ex.an.div_to_f64(&ex.nd), ex.bn.div_to_f64(&ex.nd));
    if triangle {
        let _ = writeln!(
            s,
            "  P = O + t d = a + beta_b (b - a) + beta_c (c - a) with"
        );
        let _ = writeln!(
            s,
            "  beta_b = {an:?}, beta_c = {bn:?}, 1 - beta_b - beta_c = {:?}",
            1.0 - an - bn
        );
        let _ = writeln!(
            s,
            "  (a hit needs all three >= 0, and t in the closed interval)"
        );
    } else {
        let _ = writeln!(
            s,
            "  P = O + t d = Q + alpha u + beta v with alpha = {an:?}, beta = {bn:?}"
        );
        let _ = writeln!(
            s,
            "  (a hit needs alpha, beta in [0, 1], t in the closed interval, and |unit(n).d| >= 1e-8)"
        );
    }
}

/// The exact signs of the comparisons that decide a plane case.
fn plane_signs(s: &mut String, sg: &exact::PlaneSigns, triangle: bool) {
    let yes = |b: bool| if b { "yes" } else { "NO" };
    let (e1, e2, e3) = if triangle {
        ("beta_b >= 0", "beta_c >= 0", "beta_b + beta_c <= 1")
    } else {
        ("alpha >= 0", "beta >= 0", "alpha <= 1")
    };
    let _ = writeln!(
        s,
        "  exactly: t >= t_min {}, t <= t_max {}, {e1} {}, {e2} {}, {e3} {}{}",
        yes(sg.after_min),
        yes(sg.before_max),
        yes(sg.alpha_ge_0),
        yes(sg.beta_ge_0),
        yes(sg.alpha_le_1),
        if triangle {
            String::new()
        } else {
            format!(", beta <= 1 {}", yes(sg.beta_le_1))
        }
    );
    if sg.below_threshold {
        let _ = writeln!(
            s,
            "  exactly |unit(n).d| < 1e-8: the course calls the ray parallel (a miss), whatever |d| is."
        );
    }
}

fn answer(s: &mut String, a: &Analysis) {
    let exact_answer = match (&a.hit, a.decision) {
        (_, None) => "none (non-finite input)".to_string(),
        (_, Some(Decision::Degenerate)) => "none (degenerate)".to_string(),
        (Some(h), _) => format!(
            "hit at t = {:?}, point {}, normal {}, front_face {}",
            h.t,
            v(h.point),
            v(h.normal),
            h.front_face
        ),
        (None, _) => "miss".to_string(),
    };
    let _ = writeln!(s, "Exact answer: {exact_answer}.");
    let who = match a.judging.profile {
        Profile::Course => "the course's naive formula",
        Profile::Robust => "the reference's robust formula",
    };
    let _ = writeln!(
        s,
        "Tolerance policy ({}): each deciding comparison is checked against the band of\n\
         {who} in {} (outward-rounded interval arithmetic, widened by K = {K}).",
        a.judging, a.judging.precision
    );
    for c in &a.checks {
        let w = c.band.widen(K);
        let _ = writeln!(
            s,
            "  {:<36} exactly {:<6} band [{:e}, {:e}] -> {}",
            c.quantity,
            if c.passes { "passes" } else { "fails" },
            w.lo,
            w.hi,
            if c.definite { "clear of 0" } else { "HOLDS 0" }
        );
    }
    let class = match a.class {
        Class::Hit => {
            "hit (definite: every honest implementation this judging covers must hit, with t within t_tol)"
        }
        Class::Miss => "miss (definite: every honest implementation this judging covers must miss)",
        Class::Ambiguous => {
            "ambiguous (floating point cannot settle it; no answer is marked wrong by default)"
        }
        Class::Any => {
            "any (degenerate or non-finite input: any answer or an error is accepted, a crash is not)"
        }
    };
    let _ = writeln!(s, "Class: {class}.");
    if !a.tags.is_empty() {
        let _ = writeln!(s, "Tags: {}.", a.tags.join(", "));
    }
    if let Some(tol) = a.t_tol.filter(|_| a.class == Class::Hit) {
        let _ = writeln!(
            s,
            "t_tol: {tol:e}; normal tolerance {:e} per component.",
            a.judging.normal_tol()
        );
    }
    if let Some(why) = &a.why {
        let _ = writeln!(s, "Why: {why}.");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::classify::classify;

    #[test]
    fn a_tangent_is_explained_with_a_zero_discriminant_and_its_band() {
        let shape = ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 7.0,
        };
        let ray = RaySpec {
            origin: [6.0 - 20.0, 2.0 - 30.0, -3.0 - 60.0],
            direction: [2.0, 3.0, 6.0],
        };
        let interval = [1e-6, f64::MAX];
        let case = Case {
            id: "t".into(),
            shape,
            ray,
            interval,
            expect: classify(&shape, &ray, interval),
        };
        let text = explain(&case);
        assert!(
            text.contains("disc = h^2 - a c        = 0.0 (exactly): exactly zero"),
            "{text}"
        );
        assert!(text.contains("HOLDS 0"), "{text}");
        assert!(text.contains("Class: ambiguous"), "{text}");
        assert!(text.contains("hit at t = 10.0"), "{text}");
    }
}
