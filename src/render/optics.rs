//! Reflection, refraction and Schlick's approximation (week 6), and the orthonormal basis that
//! turns a direction about `z` into one about a normal (week 9), as the course and the book write
//! them.

use glam::DVec3;

use super::PixelSampler;
use crate::geometry::unit_vector;

/// `v` mirrored about the plane with unit normal `n`: `v - 2 (v . n) n` (week 6's `reflect`, the
/// book's). `v` keeps its length.
#[inline(always)]
pub fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    v - 2.0 * v.dot(n) * n
}

/// Schlick's approximation of the reflectance at an interface: `r0 + (1 - r0) (1 - cos)^5`,
/// `r0 = ((1 - x) / (1 + x))^2`. The course and the book feed it the refraction ratio rather
/// than the index of refraction, which gives the same `r0` (it is symmetric under `x -> 1/x`).
/// The fifth power is three IEEE multiplications, `(m^2)^2 m` (the same bits on every platform,
/// within 2 ulp of `pow`, and many times cheaper than a call to `pow` on the path of every
/// ray that meets glass).
#[inline(always)]
pub fn schlick(cosine: f64, x: f64) -> f64 {
    let r0 = (1.0 - x) / (1.0 + x);
    let r0 = r0 * r0;
    let m = 1.0 - cosine;
    let m2 = m * m;
    r0 + (1.0 - r0) * (m2 * m2 * m)
}

/// The refracted direction of the unit direction `v` through the interface with unit normal `n`
/// (facing `v`) at ratio `ratio` (outside index over inside, seen from `v`'s side), given
/// `cos = min(-v . n, 1)`: `r_perp = ratio (v + cos n)`, `r_par = -sqrt(|1 - |r_perp|^2|) n`,
/// `r_perp + r_par`. A unit vector up to rounding.
#[inline(always)]
pub fn refracted(v: DVec3, n: DVec3, ratio: f64, cos: f64) -> DVec3 {
    let r_perp = ratio * (v + cos * n);
    let r_par = -(1.0 - r_perp.length_squared()).abs().sqrt() * n;
    r_perp + r_par
}

/// Week 6's `refract` and the book's `dielectric::scatter`: where the unit direction `v` goes at
/// an interface with unit normal `n` (facing it) and ratio `ratio`.
///
/// `cos = min(-v . n, 1)`, `sin = sqrt(1 - cos^2)`. It reflects when refraction is impossible
/// (`ratio sin > 1`, total internal reflection) or when `schlick(cos, ratio)` is above a random
/// number, which is drawn from `sampler` only when refraction is possible (the `or` short-circuits,
/// in the course's code and in the book's); otherwise it refracts ([`refracted`]).
#[inline(always)]
pub fn refract_or_reflect(v: DVec3, n: DVec3, ratio: f64, sampler: &mut PixelSampler) -> DVec3 {
    let cos = (-v.dot(n)).min(1.0);
    let sin = (1.0 - cos * cos).sqrt();
    if ratio * sin > 1.0 || schlick(cos, ratio) > sampler.next_f64() {
        reflect(v, n)
    } else {
        refracted(v, n, ratio, cos)
    }
}

/// An orthonormal basis `(u, v, w)` (week 9's `ONB`). As the course (and the book) builds it,
/// `u x v = -w`: it is left-handed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Onb {
    /// The first axis, `w x v`.
    pub u: DVec3,
    /// The second axis, `unit(w x a)`.
    pub v: DVec3,
    /// The third axis, along the vector it was built from.
    pub w: DVec3,
}

impl Onb {
    /// `ONB.build_from_w(n)`: `w = unit(n)`; `a = (1, 0, 0)`, or `(0, 1, 0)` when `|w.x| > 0.9`;
    /// `v = unit(w x a)`, `u = w x v`.
    #[inline]
    pub fn from_w(n: DVec3) -> Self {
        let w = unit_vector(n);
        let a = if w.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
        let v = unit_vector(w.cross(a));
        let u = w.cross(v);
        Self { u, v, w }
    }

    /// `local(x, y, z) = x u + y v + z w`.
    #[inline]
    pub fn local(&self, d: DVec3) -> DVec3 {
        d.x * self.u + d.y * self.v + d.z * self.w
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::stats::assert_uniform_cells;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).abs().max_element() < 1e-12
    }

    #[test]
    fn reflect_mirrors_about_the_normal() {
        assert_eq!(
            reflect(DVec3::new(1.0, -1.0, 0.0), DVec3::Y),
            DVec3::new(1.0, 1.0, 0.0)
        );
        // The length is kept: a raw direction of length 10 comes back as long.
        let r = reflect(DVec3::new(0.0, -6.0, 8.0), DVec3::Y);
        assert_eq!(r, DVec3::new(0.0, 6.0, 8.0));
    }

    /// `r0 = ((1 - 1.5) / 2.5)^2 = 0.04`; at `cos = 0.5`, `0.04 + 0.96 / 32 = 0.07`; at grazing
    /// incidence everything is reflected; the ratio and its inverse give the same value.
    #[test]
    fn schlick_matches_hand_worked_values() {
        assert!((schlick(1.0, 1.5) - 0.04).abs() < 1e-15);
        assert!((schlick(0.5, 1.5) - 0.07).abs() < 1e-15);
        assert_eq!(schlick(0.0, 1.5), 1.0);
        assert!((schlick(0.3, 1.0 / 1.5) - schlick(0.3, 1.5)).abs() < 1e-15);
    }

    /// Straight through at normal incidence; Snell's law at 45 degrees into glass
    /// (`sin t = sin 45 / 1.5 = 0.4714`); a unit result.
    #[test]
    fn refraction_follows_snell() {
        let n = DVec3::Z;
        let down = DVec3::new(0.0, 0.0, -1.0);
        assert!(close(refracted(down, n, 1.0 / 1.5, 1.0), down));
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let v = DVec3::new(s, 0.0, -s);
        let r = refracted(v, n, 1.0 / 1.5, s);
        assert!((r.x - s / 1.5).abs() < 1e-15, "{r}");
        assert!((r.length() - 1.0).abs() < 1e-15);
        assert!((r.z + (1.0 - (s / 1.5).powi(2)).sqrt()).abs() < 1e-15);
    }

    /// From glass into air at 60 degrees (`1.5 sin 60 = 1.3 > 1`): total internal reflection,
    /// and no random number drawn for it; from air into glass at the same angle the random
    /// number decides, and 1 - U refracts while U below Schlick's value reflects.
    #[test]
    fn total_internal_reflection_draws_nothing() {
        let n = DVec3::Z;
        let v = DVec3::new(0.75f64.sqrt(), 0.0, -0.5);
        let mut sampler = PixelSampler::new(1, 2);
        let before = sampler.clone();
        let out = refract_or_reflect(v, n, 1.5, &mut sampler);
        assert!(close(out, reflect(v, n)));
        assert_eq!(
            sampler.next_f64(),
            before.clone().next_f64(),
            "no number was drawn"
        );
        let mut s = before.clone();
        let u = s.next_f64();
        let mut s = before;
        let out = refract_or_reflect(v, n, 1.0 / 1.5, &mut s);
        let reflects = schlick(0.5, 1.0 / 1.5) > u;
        assert_eq!(close(out, reflect(v, n)), reflects);
    }

    /// The reflection probability of the dielectric's choice is Schlick's value: at
    /// `cos = 0.5` into glass, `0.07`. A binomial count over 200 000 draws is within 5 standard
    /// errors (a false alarm below one in a million).
    #[test]
    fn dielectric_reflects_with_schlick_probability() {
        let n = DVec3::Z;
        let v = DVec3::new(0.75f64.sqrt(), 0.0, -0.5);
        let mut sampler = PixelSampler::new(9, 9);
        let trials = 200_000;
        let reflected = (0..trials)
            .filter(|_| refract_or_reflect(v, n, 1.0 / 1.5, &mut sampler).z > 0.0)
            .count() as f64;
        let p = schlick(0.5, 1.0 / 1.5);
        let se = (p * (1.0 - p) / trials as f64).sqrt();
        assert!(
            (reflected / trials as f64 - p).abs() < 5.0 * se,
            "{reflected}"
        );
    }

    /// The ONB of any direction is orthonormal, with `w` along it and `u x v = -w`, including
    /// near the x axis where it switches its helper vector.
    #[test]
    fn onb_is_orthonormal() {
        let mut sampler = PixelSampler::new(4, 4);
        let mut cases: Vec<DVec3> = (0..10_000).map(|_| sampler.unit_vector() * 3.0).collect();
        cases.extend([
            DVec3::X,
            -DVec3::X,
            DVec3::new(0.9, 0.435889894354, 0.0),
            DVec3::Y,
            DVec3::Z,
        ]);
        for n in cases {
            let b = Onb::from_w(n);
            for axis in [b.u, b.v, b.w] {
                assert!((axis.length() - 1.0).abs() < 1e-14, "{n}");
            }
            assert!(
                b.u.dot(b.v).abs() < 1e-14
                    && b.v.dot(b.w).abs() < 1e-14
                    && b.u.dot(b.w).abs() < 1e-14
            );
            // `u = w x v` makes `u x v = -w`: the course's (and the book's) basis is
            // left-handed, which a cosine-symmetric sampler does not notice.
            assert!(close(b.u.cross(b.v), -b.w), "handedness for {n}");
            assert!(close(b.w, n / n.length()));
            assert!(close(b.local(DVec3::Z), b.w) && close(b.local(DVec3::X), b.u));
        }
    }

    /// Directions about a tilted normal through the ONB: their cosine with it has density
    /// `2 cos` (`cos^2` uniform) and their azimuth about it is uniform, so 10 x 8 cells of
    /// equal probability, chi-square at a false alarm of one in a million.
    #[test]
    fn cosine_directions_through_the_onb_fit_the_cosine_lobe() {
        let n = DVec3::new(0.3, -0.5, 0.81).normalize();
        let basis = Onb::from_w(n);
        let mut sampler = PixelSampler::new(5, 6);
        let mut counts = [0u64; 80];
        for _ in 0..80_000 {
            let d = crate::render::cosine_about(n, &mut sampler);
            let (x, y, z) = (d.dot(basis.u), d.dot(basis.v), d.dot(n));
            let cos2 = ((z * z) * 10.0).min(9.999) as usize;
            let phi = (y.atan2(x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
            counts[cos2 * 8 + ((phi * 8.0) as usize).min(7)] += 1;
        }
        assert_uniform_cells(&counts, "cosine hemisphere");
    }
}
