//! A sphere's origin-dependent constants, its pre-filter, and its hit for a packet of lanes.

use glam::DVec3;

use super::cone::{Cone, SANE_MAX, SANE_MIN};
use crate::geometry::{Interval, Ray, Shape, Sphere, pick_root, roots_of};
use crate::render::fast::packet::{Directions, Lanes, WIDTH};

/// The sphere pre-filter's margin, relative to `a (f . f + r2)`.
///
/// Before the robust roots (which cost a division, and a square root on a hit) the fast path
/// evaluates the naive discriminant `b'^2 - a c` and skips the sphere when it is below
/// `-PREFILTER_MARGIN a (f . f + r2)`. Both discriminants estimate the same exact value
/// `a r^2 - (a |f|^2 - b'^2)`, the naive one within about `15 eps a (|f|^2 + r^2)` and the robust one
/// within about `20 eps a (|f|^2 + r^2)` (`eps = 2^-53`; each term is bounded by
/// `a (|f|^2 + r^2)` since `b'^2 <= a |f|^2`). So a naive value below `-1e-12 a (|f|^2 + r^2)`, which
/// is some 4500 `eps` away, means the robust discriminant is negative too: the sphere is missed
/// either way and skipping it changes nothing. Any NaN or infinity makes the comparison false and
/// takes the robust path; so does `a` or `|f|^2 + r^2` outside `[1e-100, 1e100)`, where underflow
/// could make the relative bounds wrong.
pub(super) const PREFILTER_MARGIN: f64 = 1e-12;

/// A sphere's origin-dependent constants.
#[derive(Clone, Copy, Debug)]
pub(super) struct PreparedSphere {
    /// The sphere itself, for the rare rays whose intermediates over- or underflow.
    pub(super) sphere: Sphere,
    /// `origin - center`.
    pub(super) f: DVec3,
    /// `radius^2`.
    pub(super) r2: f64,
    /// `f . f - r2`.
    pub(super) c: f64,
    /// `f . f + r2`, the scale of the discriminant's rounding errors, or NaN where the
    /// pre-filter is off (see [`PREFILTER_MARGIN`]).
    pub(super) scale: f64,
}

impl PreparedSphere {
    pub(super) fn new(sphere: &Sphere, origin: DVec3) -> Self {
        let f = origin - sphere.center;
        let r2 = sphere.radius * sphere.radius;
        let scale = f.dot(f) + r2;
        Self {
            sphere: *sphere,
            f,
            r2,
            c: f.dot(f) - r2,
            scale: if (SANE_MIN..SANE_MAX).contains(&scale) {
                scale
            } else {
                f64::NAN
            },
        }
    }

    /// The sphere's hit along `d` within `within`, given `a = d . d` and
    /// `a_margin = a * PREFILTER_MARGIN` (or NaN).
    #[inline(always)]
    pub(super) fn hit_t(
        &self,
        origin: DVec3,
        d: DVec3,
        a: f64,
        a_margin: f64,
        within: Interval,
    ) -> Option<f64> {
        let half_b = self.f.dot(d);
        if half_b * half_b - a * self.c < -(a_margin * self.scale) {
            // A sure miss: see the pre-filter's note above.
            return None;
        }
        match roots_of(self.f, d, a, half_b, self.r2, self.c) {
            Ok(roots) => roots.and_then(|roots| pick_root(roots, within)),
            // Over- or underflow: the sphere's own path rescales.
            Err(()) => self.sphere.hit_t(&Ray::new(origin, d), within),
        }
    }

    /// Whether every direction of `cone` (whose `d . d` is inside the pre-filter's range) hits
    /// the sphere within [`Interval::CAMERA`], with margins far above the rounding of the lanes'
    /// robust roots.
    ///
    /// The origin is outside the sphere (`|g| > r`, `g = center - origin`) and every direction is
    /// within `theta + half_angle < 90` degrees of `g` (`theta` the axis's angle to it), so every
    /// ray heads towards the centre, and its line passes within `|g| sin(theta + half_angle)` of
    /// it, below `r`: the discriminant is positive by a wide margin, and the near root's point is
    /// at least `|g| - r` from the origin, so `t >= (|g| - r) / |d|`, which is asked to be at
    /// least twice the interval's `1e-6`. A negative radius is refused (less the slack it stays
    /// negative), which is safe.
    pub(super) fn covers(&self, cone: &Cone) -> bool {
        if !self.scale.is_finite() {
            return false;
        }
        let g = -self.f;
        let (distance, r) = (g.length(), self.sphere.radius);
        // The rounding of `f = origin - center`, against the exact offset.
        let slack = 4.0
            * f64::EPSILON
            * (self.sphere.center.abs() + (self.sphere.center + self.f).abs()).max_element();
        let r = r - slack;
        if !(distance.is_finite() && r > 0.0 && distance > r * (1.0 + 1e-9) + slack) {
            return false;
        }
        let theta = cone.axis.cross(g).length().atan2(cone.axis.dot(g));
        let widest = theta + cone.half_angle + 1e-9;
        widest < std::f64::consts::FRAC_PI_2 - 1e-9
            && distance * widest.sin() < r * (1.0 - 1e-9)
            && (distance - r - slack) / cone.length2_max.sqrt() > 2e-6
    }

    /// [`Self::hit_t`] for each lane's direction, against each lane's interval
    /// `(min, closest[k])`: where it hits, `closest[k]` becomes its `t` and `index[k]` becomes
    /// `me`. The same operations in the same order as the scalar path, so the same bits; `Err`
    /// (with the lanes half updated) when a lane's intermediates over- or underflow, which only
    /// the scalar path handles.
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    pub(super) fn hit_lanes(
        &self,
        d: &Directions,
        a: &Lanes,
        a_margin: &Lanes,
        min: f64,
        closest: &mut Lanes,
        index: &mut [u64; WIDTH],
        me: u64,
    ) -> Result<(), ()> {
        // Masks are kept as all-ones or zero words (not `bool`s), which stay in vector registers.
        let mut half_b = [0.0; WIDTH];
        let mut wanted = [0u64; WIDTH];
        for k in 0..WIDTH {
            half_b[k] = self.f.x * d.x[k] + self.f.y * d.y[k] + self.f.z * d.z[k];
            let sure_miss = half_b[k] * half_b[k] - a[k] * self.c < -(a_margin[k] * self.scale);
            wanted[k] = if sure_miss { 0 } else { u64::MAX };
        }
        if wanted.iter().fold(0, |any, &w| any | w) == 0 {
            return Ok(());
        }
        let constants_sane = self.c.is_finite() && self.r2 < 1e300;
        let mut overflow = [0u64; WIDTH];
        for k in 0..WIDTH {
            let (hb, ak) = (half_b[k], a[k]);
            // `roots_of`, lane by lane.
            let sane = ak.is_normal() & (ak < 1e300) & constants_sane & hb.is_finite();
            let s = hb / ak;
            let px = self.f.x - d.x[k] * s;
            let py = self.f.y - d.y[k] * s;
            let pz = self.f.z - d.z[k] * s;
            let disc = ak * (self.r2 - (px * px + py * py + pz * pz));
            overflow[k] = wanted[k] & if sane & disc.is_finite() { 0 } else { u64::MAX };
            let q = -(hb + disc.sqrt().copysign(hb));
            let t0 = self.c / q;
            let t1 = q / ak;
            let double = -hb / ak;
            let (near, far) = if q == 0.0 {
                (double, double)
            } else if t0 <= t1 {
                (t0, t1)
            } else {
                (t1, t0)
            };
            // `pick_root` against `(min, closest[k])`.
            let within = Interval::new(min, closest[k]);
            let (near_in, far_in) = (within.surrounds(near), within.surrounds(far));
            let hit = (wanted[k] != 0) & (disc >= 0.0) & (near_in | far_in);
            let t = if near_in { near } else { far };
            closest[k] = if hit { t } else { closest[k] };
            index[k] = if hit { me } else { index[k] };
        }
        if overflow.iter().fold(0, |any, &o| any | o) != 0 {
            return Err(());
        }
        Ok(())
    }
}
