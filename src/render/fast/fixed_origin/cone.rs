//! Cones of directions from the origin (a pixel's footprint) and the bounds that rule an object
//! out for a whole cone.

use glam::DVec3;

/// The smallest magnitude the sphere pre-filter trusts (see `sphere::PREFILTER_MARGIN`).
pub(super) const SANE_MIN: f64 = 1e-100;
/// The largest magnitude the sphere pre-filter trusts.
pub(super) const SANE_MAX: f64 = 1e100;

/// A round cone of directions from the origin: every direction within `half_angle` (radians)
/// of the unit vector `axis`, with `|d|^2` between `length2_min` and `length2_max`. The renderer
/// builds one per pixel that holds every direction its samples can take, rounding included.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cone {
    /// The unit axis.
    pub(crate) axis: DVec3,
    /// At most 1 radian.
    pub(crate) half_angle: f64,
    /// A lower bound of `d . d` over the cone's directions.
    pub(crate) length2_min: f64,
    /// An upper bound of `d . d`.
    pub(crate) length2_max: f64,
}

/// What rules an object out for a cone of directions: a ball around it, seen from the origin.
#[derive(Clone, Copy, Debug)]
pub(super) enum Bound {
    /// The object's hit is decided exactly for each ray (a triangle): ruled out when no line
    /// of the cone meets the ball (`to_center = center - origin`).
    Line { to_center: DVec3, radius: f64 },
    /// A sphere with its pre-filter on: ruled out when the pre-filter would find a sure miss
    /// for every direction of the cone, which needs the lines to clear the sphere by a margin
    /// far above the pre-filter's and `d . d` inside the pre-filter's range.
    Prefiltered { to_center: DVec3, radius: f64 },
    /// Never ruled out (a quad, whose floating-point test can find a hit just off its edges, or
    /// a sphere without its pre-filter).
    Always,
}

impl Bound {
    /// Whether no direction of `cone` can hit the object (`false` when in doubt).
    ///
    /// Every direction `d` of the cone is within `half_angle` of the axis, so its line makes an
    /// angle of at least `psi = min(theta - half_angle, pi - theta - half_angle)` with the
    /// ball's centre, `theta` being the axis's angle to it; the line clears the ball when
    /// `|g| sin(psi) > r`. For a sphere the pre-filter's exact value is at most
    /// `|d|^2 (r^2 - |g|^2 sin^2 psi)` (it squares the sphere's radius, whose magnitude is at
    /// most the ball's `r`: the radius's sign does not matter), so asking for
    /// `|g|^2 sin^2 psi > r^2 + 1e-9 (|g|^2 + r^2)` leaves it below `-1e-9 a (|f|^2 + r^2)`, a thousand times the pre-filter's margin and far
    /// beyond its rounding. The angles here are computed to about `1e-15` radians; `1e-9` is
    /// taken off `psi` for them.
    pub(super) fn rules_out(&self, cone: &Cone) -> bool {
        let (to_center, radius) = match *self {
            Bound::Line { to_center, radius } => (to_center, radius),
            Bound::Prefiltered { to_center, radius } => {
                let sane = |a: f64| (SANE_MIN * 4.0..SANE_MAX / 4.0).contains(&a);
                if !(sane(cone.length2_min) && sane(cone.length2_max)) {
                    return false;
                }
                (to_center, radius)
            }
            Bound::Always => return false,
        };
        let distance = to_center.length();
        if !(distance.is_finite() && distance > radius * (1.0 + 1e-9)) {
            return false;
        }
        let theta = cone
            .axis
            .cross(to_center)
            .length()
            .atan2(cone.axis.dot(to_center));
        let psi =
            (theta - cone.half_angle).min(std::f64::consts::PI - theta - cone.half_angle) - 1e-9;
        if psi.is_nan() || psi <= 0.0 {
            return false;
        }
        let (g2, r2) = (distance * distance, radius * radius);
        g2 * psi.sin().powi(2) > r2 + 1e-9 * (g2 + r2)
    }
}
