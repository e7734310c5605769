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
    ///
    /// When an intermediate would overflow or underflow (inputs near `f64::MAX` or far below 1),
    /// the problem is solved again with the positions and the radius scaled by one power of two
    /// and the direction by another, which is exact, and `t` is scaled back.
    #[inline(always)]
    pub fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        match Self::solve(ray.origin - self.center, ray.direction, self.radius) {
            Ok(roots) => roots,
            Err(()) => self.rescaled_roots(ray),
        }
    }

    /// The roots for `f = O - C`, or `Err` when an intermediate over- or underflowed.
    #[inline(always)]
    fn solve(f: DVec3, d: DVec3, radius: f64) -> Result<Option<(f64, f64)>, ()> {
        let r2 = radius * radius;
        roots_of(f, d, d.dot(d), f.dot(d), r2, f.dot(f) - r2)
    }

    /// [`Sphere::roots`] with the inputs scaled by powers of two so that the largest position
    /// coordinate (or radius) and the largest direction coordinate are near 1.
    #[cold]
    fn rescaled_roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let (o, c, d) = (ray.origin, self.center, ray.direction);
        let scale = |v: DVec3, e: i32| {
            DVec3::new(
                libm::scalbn(v.x, -e),
                libm::scalbn(v.y, -e),
                libm::scalbn(v.z, -e),
            )
        };
        // `O - C` overflows by at most a factor of 2: halve first then.
        let (mut f, mut r, mut pre) = (o - c, self.radius, 0);
        if !super::is_finite(f) {
            f = scale(o, 1) - scale(c, 1);
            r = libm::scalbn(r, -1);
            pre = 1;
        }
        let big = f.abs().max_element().max(r.abs());
        let dbig = d.abs().max_element();
        if !(big.is_finite() && dbig.is_finite()) || dbig == 0.0 || big == 0.0 {
            return None;
        }
        let (ef, ed) = (libm::ilogb(big), libm::ilogb(dbig));
        let (t0, t1) = Self::solve(scale(f, ef), scale(d, ed), libm::scalbn(r, -ef)).ok()??;
        let back = |t: f64| libm::scalbn(t, ef + pre - ed);
        Some((back(t0), back(t1)))
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
    #[inline(always)]
    fn pick_root(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        let (near, far) = self.roots(ray)?;
        if interval.surrounds(near) {
            Some(near)
        } else if interval.surrounds(far) {
            Some(far)
        } else {
            None
        }
    }
}

/// The robust roots from the ray's parts: `f = origin - center`, the direction `d`, `a = d . d`,
/// `half_b = f . d`, `r2 = radius^2` and `c = f . f - r2`, or `Err` when an intermediate over- or
/// underflowed (then [`Sphere::roots`] rescales). [`Sphere::roots`] and the renderer's
/// fixed-origin fast path (which computes `f`, `r2` and `c` once per render) both call it, so
/// they agree bit for bit. The fast path's ray packets repeat these operations lane by lane,
/// without branches (`PreparedSphere::hit_lanes` in `render::fast::fixed_origin`), and so do the
/// four-ray queries of the later weeks' lanes of paths (`ball_lanes` and `roots_lanes` in
/// `scene::accel::shape_lanes`): a change here must be made in both, which the renderer's and the
/// lanes' bit-for-bit tests check.
#[inline(always)]
#[allow(clippy::result_unit_err)]
pub(crate) fn roots_of(
    f: DVec3,
    d: DVec3,
    a: f64,
    half_b: f64,
    r2: f64,
    c: f64,
) -> Result<Option<(f64, f64)>, ()> {
    // a must be a normal number and squares must not overflow.
    if !(a.is_normal() && a < 1e300 && c.is_finite() && r2 < 1e300 && half_b.is_finite()) {
        return Err(());
    }
    let perpendicular = f - d * (half_b / a);
    let disc = a * (r2 - perpendicular.dot(perpendicular));
    if disc.is_nan() || disc.is_infinite() {
        return Err(());
    }
    if disc < 0.0 {
        return Ok(None);
    }
    let q = -(half_b + disc.sqrt().copysign(half_b));
    if q == 0.0 {
        // Tangent with the origin on the tangent point's plane: a double root at -b'/a.
        let t = -half_b / a;
        return Ok(Some((t, t)));
    }
    let t0 = c / q;
    let t1 = q / a;
    Ok(Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) }))
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

/// A sphere whose centre moves in a straight line with time (the course's week-10
/// `add_moving`): at time `t` it is `sphere` moved to `center + (end - center) t` (the course's
/// `move_sphere`, in that order of operations), with the same radius. Its normal and surface
/// coordinates are those of the moved sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovingSphere {
    /// The sphere at time 0.
    pub sphere: Sphere,
    /// Its centre at time 1.
    pub end: DVec3,
}

impl MovingSphere {
    /// The sphere `sphere` moving to `end` at time 1.
    pub const fn new(sphere: Sphere, end: DVec3) -> Self {
        Self { sphere, end }
    }

    /// Where the sphere is at `time`: centre `center + (end - center) * time`. The lanes of
    /// paths (`scene::accel::shape_lanes`, and `scene::accel::shape_set`'s scalar loop) compute the same
    /// centre from a precomputed `end - center`: a change here must be made there too.
    #[inline]
    pub fn at(&self, time: f64) -> Sphere {
        let c = self.sphere.center;
        Sphere::new(c + (self.end - c) * time, self.sphere.radius)
    }
}

impl Shape for MovingSphere {
    #[inline]
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        self.at(ray.time).intersect(ray, interval)
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        self.at(ray.time).hit_t(ray, interval)
    }
}

impl Shape for Sphere {
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let t = self.pick_root(ray, interval)?;
        let outward = (ray.at(t) - self.center) / self.radius;
        let uv = Sphere::surface_coordinates(outward * self.radius.signum());
        Some(HitRecord::new(ray, t, outward, uv))
    }

    #[inline(always)]
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
}
