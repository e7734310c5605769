use glam::DVec3;

use super::{HitRecord, Interval, Ray, Shape, unit_vector};

/// `|normal . d|` below this (absolute, with an unnormalised `d`) counts as parallel: the
/// course's `Interval.near_zero` tolerance.
pub const PARALLEL_EPSILON: f64 = 1e-8;

/// A parallelogram `Q + alpha u + beta v`, `alpha, beta` in the closed `[0, 1]`.
///
/// The constructor precomputes what the course's constructor does: `normal = unit(u x v)`,
/// `d = normal . Q` and `w = (u x v) / ((u x v) . (u x v))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// The corner.
    pub q: DVec3,
    /// The first edge from `q`.
    pub u: DVec3,
    /// The second edge from `q`.
    pub v: DVec3,
    /// `unit(u x v)`.
    pub normal: DVec3,
    /// `normal . q`: the plane is `normal . P = d`.
    pub d: f64,
    /// `(u x v) / |u x v|^2`, which turns a planar point into `(alpha, beta)`.
    pub w: DVec3,
}

impl Quad {
    /// A quad with corner `q` and edges `u`, `v`. A degenerate quad (`u x v = 0`) gets a NaN
    /// normal and is never hit.
    pub fn new(q: DVec3, u: DVec3, v: DVec3) -> Self {
        let n = u.cross(v);
        let normal = unit_vector(n);
        Self {
            q,
            u,
            v,
            normal,
            d: normal.dot(q),
            w: n / n.dot(n),
        }
    }

    /// The course's decision, with `(t, alpha, beta)` of a hit.
    #[inline]
    fn solve(&self, ray: &Ray, interval: Interval) -> Option<(f64, f64, f64)> {
        let denom = self.normal.dot(ray.direction);
        // `!(|denom| >= eps)` also rejects a NaN normal (degenerate quad) and NaN input.
        if denom.is_nan() || denom.abs() < PARALLEL_EPSILON {
            return None;
        }
        let t = (self.d - self.normal.dot(ray.origin)) / denom;
        // An overflowing t (huge inputs) is no hit, even when the interval is unbounded.
        if !t.is_finite() || !interval.contains(t) {
            return None;
        }
        let planar = ray.at(t) - self.q;
        let alpha = self.w.dot(planar.cross(self.v));
        let beta = self.w.dot(self.u.cross(planar));
        if (0.0..=1.0).contains(&alpha) && (0.0..=1.0).contains(&beta) {
            Some((t, alpha, beta))
        } else {
            None
        }
    }
}

impl Shape for Quad {
    #[inline]
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let (t, alpha, beta) = self.solve(ray, interval)?;
        Some(HitRecord::new(ray, t, self.normal, (alpha, beta)))
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        self.solve(ray, interval).map(|(t, _, _)| t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_square() -> Quad {
        Quad::new(
            DVec3::new(-1.0, -1.0, -2.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        )
    }

    #[test]
    fn centre_hit_has_half_coordinates() {
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        let hit = unit_square().intersect(&ray, Interval::CAMERA).unwrap();
        assert_eq!(hit.t, 2.0);
        assert_eq!(hit.uv, (0.5, 0.5));
        assert!(hit.front_face);
        assert_eq!(hit.normal, DVec3::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn edges_and_interval_ends_are_closed() {
        let q = unit_square();
        let corner = Ray::new(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(
            q.intersect(&corner, Interval::CAMERA).unwrap().uv,
            (1.0, 1.0)
        );
        let centre = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        assert!(q.hits(&centre, Interval::new(2.0, 2.0)));
        assert!(!q.hits(&centre, Interval::new(0.0, 1.5)));
    }

    #[test]
    fn parallel_and_degenerate_are_misses() {
        let parallel = Ray::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0));
        assert!(!unit_square().hits(&parallel, Interval::CAMERA));
        let flat = Quad::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        let ray = Ray::new(DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, -1.0));
        assert!(!flat.hits(&ray, Interval::CAMERA));
    }

    impl Quad {
        fn hits(&self, ray: &Ray, interval: Interval) -> bool {
            self.hit_t(ray, interval).is_some()
        }
    }
}
