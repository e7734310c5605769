use glam::DVec3;

use super::{HitRecord, Interval, Ray, Shape};

/// A sphere. A negative radius keeps the same surface but flips the outward normal
/// (`(P - C) / r`), which the course uses for hollow glass-like shells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// The centre.
    pub center: DVec3,
    /// The radius; negative flips the normal.
    pub radius: f64,
}

impl Sphere {
    /// A sphere at `center` with `radius` (negative allowed).
    pub const fn new(center: DVec3, radius: f64) -> Self {
        Self { center, radius }
    }

    /// The two roots `(t_near, t_far)` of `|O + t d - C|^2 = r^2`, or `None` when the ray misses
    /// the sphere's surface.
    ///
    /// Computed the robust way of *Ray Tracing Gems* ch. 7 rather than the course's naive
    /// `half_b^2 - a c`: the discriminant as `a (r^2 - |f - (f.d / a) d|^2)` (the squared distance
    /// of the centre from the line, which does not cancel catastrophically far from the sphere),
    /// and the roots as `c / q` and `q / a` with `q = -(b' + sign(b') sqrt(disc))`, which avoids
    /// the cancellation of `-b' + sqrt(disc)`.
    #[inline]
    pub fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let d = ray.direction;
        let f = ray.origin - self.center;
        let r2 = self.radius * self.radius;
        roots_of(f, d, d.dot(d), r2, || f.dot(f) - r2)
    }

    /// The spherical surface coordinates `(u, v)` in `[0, 1]` of a point whose outward unit
    /// normal is `n` (`u` around the y axis from -x, `v` from -y to +y), as the book defines them.
    pub fn surface_coordinates(n: DVec3) -> (f64, f64) {
        let theta = libm::acos(-n.y);
        let phi = libm::atan2(-n.z, n.x) + std::f64::consts::PI;
        (
            phi / (2.0 * std::f64::consts::PI),
            theta / std::f64::consts::PI,
        )
    }

    /// The root the course takes: the near one if the interval surrounds it, else the far one.
    #[inline]
    fn pick_root(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        pick_root(self.roots(ray)?, interval)
    }
}

/// The roots of a sphere from the ray's parts: `f = origin - center`, the direction `d`,
/// `a = d . d`, `r2 = radius^2` and `c()` computing `f . f - r2` (called only when the ray meets
/// the sphere). [`Sphere::roots`] and the renderer's fixed-origin fast path (which precomputes `f`
/// and `c` once per render and `a` once per ray) both call this, so they agree bit for bit.
#[inline(always)]
// `!(x >= y)` is meant: it is true for NaN too.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(crate) fn roots_of(
    f: DVec3,
    d: DVec3,
    a: f64,
    r2: f64,
    c: impl FnOnce() -> f64,
) -> Option<(f64, f64)> {
    let half_b = f.dot(d);
    let perpendicular = f - d * (half_b / a);
    let disc = a * (r2 - perpendicular.dot(perpendicular));
    // `!(disc >= 0)` also rejects NaN.
    if !(disc >= 0.0) {
        return None;
    }
    let c = c();
    let q = -(half_b + disc.sqrt().copysign(half_b));
    if q == 0.0 {
        // Tangent with the origin on the tangent point's plane: a double root at -b'/a.
        let t = -half_b / a;
        return Some((t, t));
    }
    let t0 = c / q;
    let t1 = q / a;
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The root the course takes of `(near, far)`: the near one if the interval surrounds it, else
/// the far one.
#[inline(always)]
pub(crate) fn pick_root((near, far): (f64, f64), interval: Interval) -> Option<f64> {
    if interval.surrounds(near) {
        Some(near)
    } else if interval.surrounds(far) {
        Some(far)
    } else {
        None
    }
}

impl Shape for Sphere {
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let t = self.pick_root(ray, interval)?;
        let outward = (ray.at(t) - self.center) / self.radius;
        let uv = Sphere::surface_coordinates(outward * self.radius.signum());
        Some(HitRecord::new(ray, t, outward, uv))
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        self.pick_root(ray, interval)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_hit_takes_the_near_root_and_faces_the_ray() {
        let s = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0);
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        let hit = s.intersect(&ray, Interval::CAMERA).unwrap();
        assert_eq!(hit.t, 4.0);
        assert_eq!(hit.normal, DVec3::new(0.0, 0.0, 1.0));
        assert!(hit.front_face);
    }

    #[test]
    fn from_inside_takes_the_far_root_with_back_face() {
        let s = Sphere::new(DVec3::ZERO, 2.0);
        let ray = Ray::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0));
        let hit = s.intersect(&ray, Interval::CAMERA).unwrap();
        assert_eq!(hit.t, 2.0);
        assert!(!hit.front_face);
        assert_eq!(hit.normal, DVec3::new(-1.0, 0.0, 0.0));
    }

    #[test]
    fn negative_radius_flips_the_outward_normal_only() {
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        let pos = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0).intersect(&ray, Interval::CAMERA);
        let neg = Sphere::new(DVec3::new(0.0, 0.0, -5.0), -1.0).intersect(&ray, Interval::CAMERA);
        let (pos, neg) = (pos.unwrap(), neg.unwrap());
        assert_eq!(pos.t, neg.t);
        assert!(pos.front_face && !neg.front_face);
        // The normal always faces the ray.
        assert_eq!(pos.normal, neg.normal);
    }

    #[test]
    fn open_interval_rejects_a_root_on_its_end() {
        let s = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0);
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        // Near root 4 is on the end: the far root 6 is outside too.
        assert!(s.intersect(&ray, Interval::new(0.0, 4.0)).is_none());
        assert_eq!(s.hit_t(&ray, Interval::new(4.0, 10.0)), Some(6.0));
    }

    #[test]
    fn miss_and_nan_are_misses() {
        let s = Sphere::new(DVec3::new(0.0, 3.0, -5.0), 1.0);
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        assert!(s.intersect(&ray, Interval::CAMERA).is_none());
        let nan = Ray::new(DVec3::ZERO, DVec3::new(f64::NAN, 0.0, -1.0));
        assert!(s.intersect(&nan, Interval::CAMERA).is_none());
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

    /// A ray from outside aimed along the inward normal at a point P of the sphere hits P at
    /// t = 1, with the outward normal there; doubling the direction halves t.
    #[test]
    fn aimed_rays_hit_where_they_are_aimed() {
        let mut g = Gen(1);
        for _ in 0..10_000 {
            let center = g.vec(-50.0, 50.0);
            let radius = g.next(0.01, 20.0);
            let n = g.vec(-1.0, 1.0).normalize();
            let p = center + n * radius;
            // Start outside, off the normal a little so the direction is not special.
            let origin = p + (n + g.vec(-0.3, 0.3) * n.length()).normalize() * g.next(0.5, 30.0);
            if (origin - center).length() <= radius * 1.01 {
                continue;
            }
            let sphere = Sphere::new(center, radius);
            let ray = Ray::new(origin, p - origin);
            let Some(hit) = sphere.intersect(&ray, Interval::CAMERA) else {
                continue; // P is behind the sphere's near side from this origin
            };
            if hit.t > 1.0 + 1e-9 {
                panic!(
                    "the near hit cannot lie beyond the aimed point: t = {}",
                    hit.t
                );
            }
            if !close(hit.t, 1.0, 1e-9) {
                continue; // the ray entered the sphere before reaching P
            }
            assert!((hit.point - p).length() <= 1e-9 * (1.0 + p.length()));
            assert!((hit.normal - n).length() < 1e-6, "{} vs {n}", hit.normal);
            let doubled = Ray::new(origin, (p - origin) * 2.0);
            let t2 = sphere.hit_t(&doubled, Interval::CAMERA).unwrap();
            assert!(close(t2, 0.5, 1e-12), "{t2}");
        }
    }

    /// A ray from the axis straight down: roots at distance - r and distance + r exactly.
    #[test]
    fn roots_are_the_closed_form_on_axis() {
        for (dist, r) in [(5.0, 1.0), (100.0, 0.5), (3.0, 2.5), (1e6, 1.0)] {
            let s = Sphere::new(DVec3::new(0.0, 0.0, -dist), r);
            let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
            assert_eq!(s.roots(&ray), Some((dist - r, dist + r)));
        }
        // A tangent ray (distance from the centre exactly r): a double root.
        let s = Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0);
        let tangent = Ray::new(DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(s.roots(&tangent), Some((5.0, 5.0)));
        let outside = Ray::new(DVec3::new(1.0 + 1e-9, 0.0, 0.0), DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(s.roots(&outside), None);
    }

    /// Far from the sphere the robust discriminant still finds a small sphere the naive one
    /// loses to cancellation (the reason for the Ray Tracing Gems formula).
    #[test]
    fn a_small_far_sphere_is_still_hit() {
        let s = Sphere::new(DVec3::new(0.0, 0.0, -1e7), 1.0);
        let ray = Ray::new(DVec3::new(0.9, 0.0, 0.0), DVec3::new(0.0, 0.0, -1.0));
        let (near, far) = s.roots(&ray).unwrap();
        let half_chord = (1.0f64 - 0.81).sqrt();
        assert!(close(near, 1e7 - half_chord, 1e-15), "{near}");
        assert!(close(far, 1e7 + half_chord, 1e-15), "{far}");
    }
}
