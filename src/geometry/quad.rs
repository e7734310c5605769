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
        self.solve_from(ray, self.plane_offset(ray.origin), interval)
    }

    /// `d - normal . origin`: the numerator of the plane's `t` for rays from `origin`, which the
    /// renderer's fixed-origin fast path computes once per render.
    #[inline(always)]
    pub(crate) fn plane_offset(&self, origin: DVec3) -> f64 {
        self.d - self.normal.dot(origin)
    }

    /// The course's decision given `offset = self.plane_offset(ray.origin)`. [`Shape::hit_t`] and
    /// the fast path both call it, so they agree bit for bit. The fast path's ray packets repeat
    /// these operations lane by lane, without branches (`quad_hit_lanes` in
    /// `render::fast::fixed_origin`), and so do the four-ray queries of the later weeks' lanes of paths
    /// (`quad_lanes` in `scene::accel::shape_lanes`): a change here must be made in both, which the
    /// renderer's and the lanes' bit-for-bit tests check.
    #[inline(always)]
    // `!(x >= y)` is meant: it is true for NaN too.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub(crate) fn solve_from(
        &self,
        ray: &Ray,
        offset: f64,
        interval: Interval,
    ) -> Option<(f64, f64, f64)> {
        let denom = self.normal.dot(ray.direction);
        // `!(|denom| >= eps)` also rejects a NaN normal (degenerate quad) and NaN input.
        if denom.is_nan() || denom.abs() < PARALLEL_EPSILON {
            return None;
        }
        let t = offset / denom;
        // An overflowing t (huge inputs) is no hit, even when the interval is unbounded.
        if !t.is_finite() || !interval.contains(t) {
            return None;
        }
        let planar = ray.at(t) - self.q;
        let alpha = self.w.dot(planar.cross(self.v));
        if !(0.0..=1.0).contains(&alpha) {
            return None;
        }
        let beta = self.w.dot(self.u.cross(planar));
        if !(0.0..=1.0).contains(&beta) {
            return None;
        }
        Some((t, alpha, beta))
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

    /// A small deterministic generator for the tests (SplitMix64), uniform in `[lo, hi)`.
    struct Gen(u64);
    impl Gen {
        fn next(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
        }
        fn vec(&mut self, lo: f64, hi: f64) -> DVec3 {
            DVec3::new(self.next(lo, hi), self.next(lo, hi), self.next(lo, hi))
        }
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    /// A ray aimed at `Q + a u + b v` from the quad's front hits there at t = 1 with
    /// coordinates `(a, b)`.
    #[test]
    fn aimed_rays_hit_where_they_are_aimed() {
        let mut g = Gen(2);
        for _ in 0..10_000 {
            let quad = Quad::new(g.vec(-10.0, 10.0), g.vec(-5.0, 5.0), g.vec(-5.0, 5.0));
            let (a, b) = (g.next(0.01, 0.99), g.next(0.01, 0.99));
            let p = quad.q + a * quad.u + b * quad.v;
            let side = if g.next(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
            let origin = p + (quad.normal * side + g.vec(-0.5, 0.5)) * g.next(0.5, 20.0);
            let ray = Ray::new(origin, p - origin);
            if quad.normal.dot(ray.direction).abs() < 1e-3 {
                continue; // grazing: the closed form is ill-conditioned
            }
            let hit = quad.intersect(&ray, Interval::CAMERA).unwrap();
            assert!(close(hit.t, 1.0, 1e-9), "{}", hit.t);
            assert!(
                close(hit.uv.0, a, 1e-7) && close(hit.uv.1, b, 1e-7),
                "{:?}",
                hit.uv
            );
            assert!(
                hit.normal.dot(ray.direction) < 0.0,
                "the normal faces the ray"
            );
        }
    }

    /// Aimed just outside an edge (alpha or beta slightly beyond [0, 1]): a miss.
    #[test]
    fn just_outside_is_a_miss() {
        let q = unit_square();
        for (x, y) in [(1.001, 0.0), (-1.001, 0.5), (0.3, 1.001), (0.0, -1.001)] {
            let ray = Ray::new(DVec3::new(x, y, 0.0), DVec3::new(0.0, 0.0, -1.0));
            assert!(q.intersect(&ray, Interval::CAMERA).is_none(), "({x}, {y})");
        }
    }
}
