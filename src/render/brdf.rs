//! Week 8's BRDFs as the course defines them: `BRDF(ray_view, ray_light, hit)` of every
//! material, with the course's unnormalised vectors where it uses them.
//!
//! `view` is the incoming ray's direction (towards the surface), `light` the direction towards
//! the light or the scattered ray's direction (away from it), `n` the unit normal facing the
//! viewer. None of them needs to be a unit vector; where the formula normalises, it is said.

use std::f64::consts::PI;

use glam::DVec3;

use super::optics::{reflect, schlick};
use crate::geometry::unit_vector;

/// Week 8's `halfvector(V, L) = (V + L) / 2` (not normalised).
#[inline]
pub fn halfvector(v: DVec3, l: DVec3) -> DVec3 {
    (v + l) / 2.0
}

/// Phong: `kd albedo / pi + ks albedo max(0, R . V)^alpha` with `R = unit(reflect(-L, n))` and
/// `V = unit(-view)`. `pow` is libm's.
#[inline(always)]
pub fn phong(
    albedo: DVec3,
    kd: f64,
    ks: f64,
    alpha: f64,
    view: DVec3,
    light: DVec3,
    n: DVec3,
) -> DVec3 {
    let r = unit_vector(reflect(-light, n));
    let v = unit_vector(-view);
    kd * albedo / PI + ks * albedo * libm::pow(r.dot(v).max(0.0), alpha)
}

/// Blinn: `kd albedo / pi + ks albedo max(0, H . n)^alpha` with
/// `H = unit(halfvector(-view, L))` of the **unnormalised** `-view` and `L` (course departure,
/// week 8: the half vector leans towards the longer of the two, so the highlight moves with the
/// camera's focus distance and the light's distance). `pow` is libm's.
#[inline(always)]
pub fn blinn(
    albedo: DVec3,
    kd: f64,
    ks: f64,
    alpha: f64,
    view: DVec3,
    light: DVec3,
    n: DVec3,
) -> DVec3 {
    let h = unit_vector(halfvector(-view, light));
    kd * albedo / PI + ks * albedo * libm::pow(h.dot(n).max(0.0), alpha)
}

/// Week 8's `chi(x)`: 1 for `x > 1e-8`, else 0.
#[inline]
fn chi(x: f64) -> f64 {
    if x > 1e-8 { 1.0 } else { 0.0 }
}

/// The GGX distribution written through `tan^2` as the course does:
/// `cos2 = (n . h)^2`, `tan2 = (1 - cos2) / cos2`, `D = alpha^2 / (pi cos2^2 (alpha^2 + tan2)^2)`,
/// which equals `alpha^2 / (pi ((n . h)^2 (alpha^2 - 1) + 1)^2)`. `n . h <= 0` gives 0 (the
/// course divides by zero there; the distribution is zero below the surface).
#[inline]
pub fn ggx(n_dot_h: f64, alpha: f64) -> f64 {
    if n_dot_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let cos2 = n_dot_h * n_dot_h;
    let tan2 = (1.0 - cos2) / cos2;
    let s = a2 + tan2;
    a2 / (PI * cos2 * cos2 * s * s)
}

/// Smith's `G1` as the course's `Gterm(vP, vH, vN, alpha)` computes it (weeks 8 to 10):
/// `2 chi(v.h / v.n) / (1 + sqrt(1 + alpha^2 tan^2))` with `tan^2 = (1 - (v.h)^2) / (v.h)^2`,
/// taken from `v.h` (not `v.n`), both dot products already clamped to at least `1e-8`. With an
/// unnormalised `v` the dot `v.h` may exceed 1 and, for `alpha > 1`, make the root's argument
/// negative, where the course's `math.sqrt` raises; it is taken as 0 here.
#[inline]
pub fn smith_g1(v_dot_h: f64, v_dot_n: f64, alpha: f64) -> f64 {
    let c2 = v_dot_h * v_dot_h;
    let tan2 = (1.0 - c2) / c2;
    2.0 * chi(v_dot_h / v_dot_n) / (1.0 + (1.0 + alpha * alpha * tan2).max(0.0).sqrt())
}

/// Cook-Torrance as the course's `CookTorrance.BRDF(rView, rLight, hHinfo)` computes it (weeks 8
/// to 10): `kd / pi + ks D G1(V) G1(L) F / (4 (V.N)(L.N))` with `V = -view` and `L = light`
/// unnormalised (course departure), `H = unit(halfvector(V, L))`, `V.N`, `L.N`, `H.N`, `V.H`
/// and `L.H` each clamped to at least `1e-8`, `D` [`ggx`] of `H.N` (0 where the clamped `H.N`
/// fails `chi`), [`smith_g1`] of `V` and `L`, `F = schlick(min(L.N, 1), ior)` (unclamped below).
///
/// The course's function returns a number, and its integrator then computes `float * Color`,
/// which raises `TypeError` (`Color` has no `__rmul__`): what it evidently intends is a grey
/// BRDF, this number on every channel, which is what this returns.
#[inline]
pub fn cook_torrance(
    kd: f64,
    ks: f64,
    alpha: f64,
    ior: f64,
    view: DVec3,
    light: DVec3,
    n: DVec3,
) -> DVec3 {
    let v = -view;
    let h = unit_vector(halfvector(v, light));
    let nv = n.dot(v).max(1e-8);
    let nl = n.dot(light).max(1e-8);
    let nh = h.dot(n).max(1e-8);
    let d = chi(nh) * ggx(nh, alpha);
    let g = smith_g1(v.dot(h).max(1e-8), nv, alpha) * smith_g1(light.dot(h).max(1e-8), nl, alpha);
    let f = schlick(n.dot(light).min(1.0), ior);
    DVec3::splat(kd / PI + ks * d * g * f * (1.0 / (4.0 * nv * nl)))
}

#[cfg(test)]
mod tests {
    use super::*;

    const N: DVec3 = DVec3::Z;
    /// Looking straight down at the surface.
    const DOWN: DVec3 = DVec3::new(0.0, 0.0, -1.0);

    /// `integral over the hemisphere of f(L) cos(theta_L) dL` by the midpoint rule in
    /// `(cos theta, phi)`, which integrates `cos` exactly.
    fn hemisphere(f: impl Fn(DVec3) -> f64) -> f64 {
        let (k, m) = (2000, 64);
        let mut sum = 0.0;
        for i in 0..k {
            let c = (i as f64 + 0.5) / k as f64;
            let s = (1.0 - c * c).sqrt();
            for j in 0..m {
                let phi = 2.0 * PI * (j as f64 + 0.5) / m as f64;
                sum += f(DVec3::new(s * phi.cos(), s * phi.sin(), c)) * c;
            }
        }
        sum * 2.0 * PI / (k * m) as f64
    }

    /// Phong seen from the normal: at `L = n` the value is `kd a / pi + ks a`; over the
    /// hemisphere the diffuse part reflects `kd a` and the lobe `ks a 2 pi / (alpha + 2)` (here
    /// `R . V = cos theta_L`).
    #[test]
    fn phong_value_and_energy() {
        let a = DVec3::new(0.7, 0.2, 0.4);
        let value = phong(a, 0.6, 0.9, 8.0, DOWN, N, N);
        assert!((value - (0.6 * a / PI + 0.9 * a)).abs().max_element() < 1e-15);
        for alpha in [0.8, 8.0, 30.0] {
            let energy = hemisphere(|l| phong(DVec3::ONE, 0.6, 0.9, alpha, DOWN, l, N).x);
            let expected = 0.6 + 0.9 * 2.0 * PI / (alpha + 2.0);
            assert!(
                (energy - expected).abs() < 1e-4 * expected,
                "alpha {alpha}: {energy}"
            );
        }
    }

    /// Blinn seen from the normal, with unit vectors: `H . n = cos(theta/2)`, and
    /// `integral of cos^alpha(theta/2) cos theta = 4 pi [2 u^(b+2)/(b+2) - u^(b+1)/(b+1)]` over
    /// `u` from 1/2 to 1, `b = alpha / 2`.
    #[test]
    fn blinn_value_and_energy() {
        let a = DVec3::new(0.8, 0.5, 0.4);
        let value = blinn(a, 0.5, 0.2, 300.0, DOWN, N, N);
        assert!((value - (0.5 * a / PI + 0.2 * a)).abs().max_element() < 1e-15);
        for alpha in [0.08, 8.0, 300.0] {
            let energy = hemisphere(|l| blinn(DVec3::ONE, 0.0, 1.0, alpha, DOWN, l, N).x);
            let b = alpha / 2.0;
            let antiderivative =
                |u: f64| 2.0 * u.powf(b + 2.0) / (b + 2.0) - u.powf(b + 1.0) / (b + 1.0);
            let expected = 4.0 * PI * (antiderivative(1.0) - antiderivative(0.5));
            assert!(
                (energy - expected).abs() < 1e-3 * expected,
                "alpha {alpha}: {energy} vs {expected}"
            );
        }
    }

    /// The course's Blinn half vector is built from the unnormalised view: seen along a ray of
    /// length 10 with a light at 45 degrees, `H . n = 10.7071 / |(0.7071, 0, 10.7071)|`, not
    /// `cos 22.5`.
    #[test]
    fn blinn_half_vector_leans_towards_the_longer_vector() {
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let light = DVec3::new(s, 0.0, s);
        let far = blinn(DVec3::ONE, 0.0, 1.0, 1.0, DOWN * 10.0, light, N).x;
        let h = DVec3::new(s, 0.0, 10.0 + s);
        assert!((far - h.z / h.length()).abs() < 1e-15);
        let near = blinn(DVec3::ONE, 0.0, 1.0, 1.0, DOWN, light, N).x;
        assert!((near - (PI / 8.0).cos()).abs() < 1e-15);
    }

    /// GGX is normalised: `integral of D(h) (n . h) dh = 1` over the hemisphere.
    #[test]
    fn ggx_is_normalised() {
        for alpha in [0.1, 0.3, 0.8] {
            let total = hemisphere(|h| ggx(h.z, alpha));
            assert!((total - 1.0).abs() < 2e-3, "alpha {alpha}: {total}");
        }
        assert_eq!(ggx(0.0, 0.5), 0.0);
        assert_eq!(ggx(-0.3, 0.5), 0.0);
    }

    /// Cook-Torrance at normal incidence with unit vectors: `H = n`, `D = 1 / (pi alpha^2)`,
    /// `G1 = 1` (`tan = 0`), `F = r0 = 0.04`, so `kd / pi + ks 0.04 / (4 pi alpha^2)`; grey.
    #[test]
    fn cook_torrance_at_normal_incidence() {
        let got = cook_torrance(0.3, 0.7, 0.5, 1.5, DOWN, N, N);
        let expected = 0.3 / PI + 0.7 * 0.04 / (4.0 * PI * 0.25);
        assert!((got.x - expected).abs() < 1e-15 && got.x == got.y && got.y == got.z);
        // Smith's G1 falls to 0 where v.h / v.n is not positive, and is 1 where v.h = 1 (the
        // course takes its tangent from v.h).
        assert_eq!(smith_g1(-0.1, 0.5, 0.5), 0.0);
        assert_eq!(smith_g1(1.0, 0.5, 0.5), 1.0);
        // v.h = 0.5: tan^2 = 3, G1 = 2 / (1 + sqrt(1 + 0.25 * 3)).
        assert!((smith_g1(0.5, 1.0, 0.5) - 2.0 / (1.0 + 1.75f64.sqrt())).abs() < 1e-15);
    }

    #[test]
    fn halfvector_is_the_unnormalised_mean() {
        assert_eq!(
            halfvector(DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0)),
            DVec3::new(1.0, 2.0, 0.0)
        );
    }
}
