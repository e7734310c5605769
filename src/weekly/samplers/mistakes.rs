//! Samplers in Rust, honest and mistaken, drawing from the reference's seeded stream
//! ([`PixelSampler`]): what a student's sampler does, so that the statistical checks' false-alarm
//! rate (on the honest ones) and power (on each catalogued mistake) can be measured fast, and so
//! that a mistake's cell probabilities can be estimated when its distribution has no closed
//! form.
//!
//! These are models of the *submissions'* samplers (the course's `random_vec3_unit`,
//! `random_cosine_hemisphere_on_z`, `random_in_unit_disk` and the mistakes the docs list), not
//! of the reference's rendering; where the reference has the same sampler it is used.

use glam::DVec3;

use crate::render::PixelSampler;

/// A uniform point of the cube `[-1, 1)^3`.
#[inline]
pub fn in_cube(s: &mut PixelSampler) -> DVec3 {
    DVec3::new(
        2.0 * s.next_f64() - 1.0,
        2.0 * s.next_f64() - 1.0,
        2.0 * s.next_f64() - 1.0,
    )
}

/// A uniform point of the unit ball, by rejection from the cube (the course's
/// `random_vec3_in_unit_sphere`).
#[inline]
pub fn in_ball(s: &mut PixelSampler) -> DVec3 {
    loop {
        let p = in_cube(s);
        let l2 = p.length_squared();
        if l2 < 1.0 && l2 > 1e-160 {
            return p;
        }
    }
}

/// A uniform point of the unit sphere (the course's `random_vec3_unit`: a point of the ball,
/// normalised).
#[inline]
pub fn unit_vector(s: &mut PixelSampler) -> DVec3 {
    let p = in_ball(s);
    p / p.length()
}

/// Mistake: a point of the cube normalised without rejection (corners over-represented).
#[inline]
pub fn unit_vector_from_cube(s: &mut PixelSampler) -> DVec3 {
    loop {
        let p = in_cube(s);
        let l = p.length();
        if l > 1e-80 {
            return p / l;
        }
    }
}

/// Mistake: polar angle and azimuth drawn uniformly (the poles over-represented).
#[inline]
pub fn unit_vector_uniform_angles(s: &mut PixelSampler) -> DVec3 {
    let theta = std::f64::consts::PI * s.next_f64();
    let phi = 2.0 * std::f64::consts::PI * s.next_f64();
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// A cosine-distributed direction about `z` (the course's `random_cosine_hemisphere_on_z`):
/// `phi = 2 pi r1`, `(cos phi sqrt r2, sin phi sqrt r2, sqrt(1 - r2))`.
#[inline]
pub fn cosine_hemisphere(s: &mut PixelSampler) -> DVec3 {
    let r1 = s.next_f64();
    let r2 = s.next_f64();
    let phi = 2.0 * std::f64::consts::PI * r1;
    DVec3::new(
        phi.cos() * r2.sqrt(),
        phi.sin() * r2.sqrt(),
        (1.0 - r2).sqrt(),
    )
}

/// Mistake: the hemisphere about `z` uniformly (`z = r2`).
#[inline]
pub fn uniform_hemisphere(s: &mut PixelSampler) -> DVec3 {
    let r1 = s.next_f64();
    let z = s.next_f64();
    let phi = 2.0 * std::f64::consts::PI * r1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(phi.cos() * r, phi.sin() * r, z)
}

/// A uniform point of the open unit disk, by rejection (the course's `random_in_unit_disk`).
#[inline]
pub fn in_disk(s: &mut PixelSampler) -> DVec3 {
    let (x, y) = s.in_unit_disk();
    DVec3::new(x, y, 0.0)
}

/// Mistake: the first point of the square `[-1, 1)^2`, no rejection.
#[inline]
pub fn in_square(s: &mut PixelSampler) -> DVec3 {
    DVec3::new(2.0 * s.next_f64() - 1.0, 2.0 * s.next_f64() - 1.0, 0.0)
}

/// Mistake: polar coordinates with the radius uniform (the centre over-represented).
#[inline]
pub fn disk_radius_uniform(s: &mut PixelSampler) -> DVec3 {
    let r = s.next_f64();
    let phi = 2.0 * std::f64::consts::PI * s.next_f64();
    DVec3::new(r * phi.cos(), r * phi.sin(), 0.0)
}

/// `d` about the unit axis `n`: the local `(x, y, z)` taken along a frame `(t, b, n)`.
#[inline]
pub fn about(n: DVec3, d: DVec3) -> DVec3 {
    let (t, b) = n.any_orthonormal_pair();
    d.x * t + d.y * b + d.z * n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_samplers_land_where_they_should() {
        let mut s = PixelSampler::new(1, 2);
        for _ in 0..1000 {
            assert!((unit_vector(&mut s).length() - 1.0).abs() < 1e-12);
            assert!((unit_vector_from_cube(&mut s).length() - 1.0).abs() < 1e-12);
            assert!((unit_vector_uniform_angles(&mut s).length() - 1.0).abs() < 1e-12);
            let c = cosine_hemisphere(&mut s);
            assert!((c.length() - 1.0).abs() < 1e-12 && c.z >= 0.0);
            let h = uniform_hemisphere(&mut s);
            assert!((h.length() - 1.0).abs() < 1e-12 && h.z >= 0.0);
            assert!(in_disk(&mut s).length() < 1.0);
            assert!(disk_radius_uniform(&mut s).length() < 1.0);
            let q = in_square(&mut s);
            assert!(q.x.abs() <= 1.0 && q.y.abs() <= 1.0);
        }
        let n = DVec3::new(0.0, 0.6, 0.8);
        assert!((about(n, DVec3::Z) - n).length() < 1e-15);
    }
}
