//! A triangle's edge planes seen from the origin: a pre-classification of each lane that decides
//! most of them without the triangle's own watertight test.

use glam::DVec3;

use super::cone::Cone;
use crate::geometry::{Interval, Ray, Shape, Triangle};
use crate::render::fast::packet::{Directions, Lanes, WIDTH};

/// The triangle pre-classification's bound on an edge function's rounding error, relative to
/// `M . |d|` (see `PreparedTriangle`): `2^-45 = 256 eps`, against a worst case of about
/// `8 eps`.
const EDGE_PREFILTER_RELATIVE: f64 = 2.842170943040401e-14; // 2^-45
/// The same bound's absolute slack, above every underflow term (at most about `2^-569` for the
/// magnitudes allowed).
const EDGE_PREFILTER_ABSOLUTE: f64 = 3.054936363499605e-151; // 2^-500
/// The largest vertex coordinate (relative to the origin) the pre-classification takes, so that
/// nothing in it overflows: `2^200`.
const EDGE_PREFILTER_VERTEX_MAX: f64 = 1.6069380442589903e60;
/// The range of a direction's largest component the pre-classification takes: the range where
/// [`Triangle`]'s own test does not rescale the direction (`2^-500 .. 2^500`).
const DIRECTION_MIN: f64 = 3.054936363499605e-151;
const DIRECTION_MAX: f64 = 3.273390607896142e150;

/// A triangle's origin-dependent constants, for a pre-classification of each ray that decides
/// most of them without [`Triangle`]'s own (watertight, sheared, exact-near-edges) test.
///
/// Seen from the origin `O`, the ray's line meets the closed triangle exactly when the three
/// triple products `S_i = ((v_i - O) x (v_{i+1} - O)) . d` do not have strictly opposite signs
/// (for a triangle that is not degenerate). `edges[i]` is that cross product computed in `f64`
/// from the rounded `v_i - O`, and `magnitudes[i]` the matching sums `|A_y| |B_z| + |A_z| |B_y|`
/// (and so on), so that the computed `s_i = edges[i] . d` is within `8 eps (magnitudes[i] . |d|)`
/// plus underflow terms of the exact `S_i` while the vertices stay below `2^200` and `d` inside
/// `2^-500 .. 2^500` (`eps = 2^-53`; the shifts, products, differences and the dot product each
/// round once). The bound used is `2^-45 (magnitudes[i] . |d|) + 2^-500`, some 30 times that.
///
/// Beyond its bound each sign is the exact one. All three positive, or all three negative: the
/// line meets the triangle's inside, which [`Triangle`]'s test (exact in its decision) also finds,
/// and the hit's `t` is then computed by its very formula. One strictly positive and one strictly
/// negative: the line misses, as the triangle's test also finds. Anything else (a sign inside its
/// bound, a NaN, a direction out of range) goes to the triangle's own test, lane by lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct PreparedTriangle {
    /// The triangle itself, for the lanes the pre-classification leaves open.
    pub(super) triangle: Triangle,
    /// `(v_i - O) x (v_{i+1} - O)` for the edges ab, bc and ca, one array per coordinate.
    edges: [DVec3; 3],
    /// The rounding scale of each edge's cross product.
    magnitudes: [DVec3; 3],
    /// `normal . a - normal . O`, as the triangle's own test computes it.
    offset: f64,
    /// Whether the pre-classification applies (a finite normal, vertices below `2^200`).
    classifies: bool,
}

impl PreparedTriangle {
    pub(super) fn new(triangle: &Triangle, origin: DVec3) -> Self {
        let rel = [
            triangle.a - origin,
            triangle.b - origin,
            triangle.c - origin,
        ];
        let cross = |p: DVec3, q: DVec3| {
            DVec3::new(
                p.y * q.z - p.z * q.y,
                p.z * q.x - p.x * q.z,
                p.x * q.y - p.y * q.x,
            )
        };
        let magnitude = |p: DVec3, q: DVec3| {
            let (p, q) = (p.abs(), q.abs());
            DVec3::new(
                p.y * q.z + p.z * q.y,
                p.z * q.x + p.x * q.z,
                p.x * q.y + p.y * q.x,
            )
        };
        let pairs = [(rel[0], rel[1]), (rel[1], rel[2]), (rel[2], rel[0])];
        let n = triangle.normal;
        let classifies = n.is_finite()
            && rel
                .iter()
                .all(|v| v.is_finite() && v.abs().max_element() <= EDGE_PREFILTER_VERTEX_MAX);
        Self {
            triangle: *triangle,
            edges: pairs.map(|(p, q)| cross(p, q)),
            magnitudes: pairs.map(|(p, q)| magnitude(p, q)),
            offset: n.dot(triangle.a) - n.dot(origin),
            classifies,
        }
    }

    /// Whether every direction of `cone` (whose `d . d` is inside the pre-filter's range) hits
    /// the triangle within [`Interval::CAMERA`].
    ///
    /// A line meets the triangle's inside when its three edge functions `S_i = E_i . d` have one
    /// strict sign (see above): here, when every direction is more than 90 degrees less the
    /// margin away from each edge plane's normal `+-E_i`, the margin holding the rounding of the
    /// computed `E_i` (`2 eps M_i`, turned into an angle by `|E_i|`). The hit's lanes decide it
    /// exactly, whichever way they go. Its `t = (n . a - n . O) / n . d` has one sign over the cone
    /// (no direction of it is within `1e-6` radians of the plane `n . d = 0`), the axis's, and
    /// is at least `|n . a - n . O| / |d|`, asked to be at least twice the interval's `1e-6`; and
    /// at most that over `|d| sin(1e-6)`, finite.
    pub(super) fn covers(&self, cone: &Cone) -> bool {
        let n = self.triangle.normal;
        if !(n.is_finite() && self.offset.is_finite() && self.offset != 0.0) {
            return false;
        }
        let angle = |v: DVec3| cone.axis.cross(v).length().atan2(cone.axis.dot(v));
        let inside = |sign: f64| {
            self.edges.iter().zip(&self.magnitudes).all(|(&e, &m)| {
                let length = e.length();
                let margin = 1e-9 + 4.0 * f64::EPSILON * m.length() / length;
                length > 0.0
                    && margin < 1e-3
                    && angle(sign * e) + cone.half_angle + margin < std::f64::consts::FRAC_PI_2
            })
        };
        if !(inside(1.0) || inside(-1.0)) {
            return false;
        }
        let towards = n.dot(cone.axis);
        let off_plane = (towards.abs().min(1.0).asin() - cone.half_angle - 1e-9).sin();
        let (shortest, longest) = (cone.length2_min.sqrt(), cone.length2_max.sqrt());
        off_plane > 1e-6
            && (towards > 0.0) == (self.offset > 0.0)
            && self.offset.abs() / longest * (1.0 - 1e-9) > 2e-6
            && self.offset.abs() / (shortest * off_plane) < 1e300
    }

    /// [`Triangle::hit_t`] for each lane's direction from `origin`, against each lane's interval
    /// `[min, closest[k]]`: where it hits, `closest[k]` becomes its `t` and `index[k]` becomes
    /// `me`. Lanes the pre-classification decides are done in straight-line code; the others
    /// call the triangle's test.
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    pub(super) fn hit_lanes(
        &self,
        origin: DVec3,
        d: &Directions,
        min: f64,
        closest: &mut Lanes,
        index: &mut [u64; WIDTH],
        me: u64,
    ) {
        let (inside, open) = if self.classifies {
            self.classify(d)
        } else {
            ([0; WIDTH], [u64::MAX; WIDTH])
        };
        if inside.iter().fold(0, |any, &i| any | i) != 0 {
            let n = self.triangle.normal;
            for k in 0..WIDTH {
                // The triangle's `t`: `(n . a - n . O) / n . d`, finite, in the closed interval.
                let t = self.offset / (n.x * d.x[k] + n.y * d.y[k] + n.z * d.z[k]);
                let hit = (inside[k] != 0) & t.is_finite() & (min <= t) & (t <= closest[k]);
                closest[k] = if hit { t } else { closest[k] };
                index[k] = if hit { me } else { index[k] };
            }
        }
        if open.iter().fold(0, |any, &o| any | o) != 0 {
            for k in 0..WIDTH {
                if open[k] == 0 {
                    continue;
                }
                let within = Interval::new(min, closest[k]);
                if let Some(t) = self.triangle.hit_t(&Ray::new(origin, d.lane(k)), within) {
                    closest[k] = t;
                    index[k] = me;
                }
            }
        }
    }

    /// The pre-classification of each lane, as masks (all-ones or zero words, which stay in
    /// vector registers): `(inside, open)`, the lanes whose line surely meets the triangle's
    /// inside, and those it cannot decide. The others surely miss.
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::needless_range_loop)]
    fn classify(&self, d: &Directions) -> ([u64; WIDTH], [u64; WIDTH]) {
        let mut inside = [0u64; WIDTH];
        let mut open = [0u64; WIDTH];
        for k in 0..WIDTH {
            let (x, y, z) = (d.x[k], d.y[k], d.z[k]);
            let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
            let big = ax.max(ay).max(az);
            let mut positive = 0u64;
            let mut negative = 0u64;
            for i in 0..3 {
                let (e, m) = (self.edges[i], self.magnitudes[i]);
                let s = e.x * x + e.y * y + e.z * z;
                let bound = (m.x * ax + m.y * ay + m.z * az) * EDGE_PREFILTER_RELATIVE
                    + EDGE_PREFILTER_ABSOLUTE;
                positive |= if s > bound { 1 << i } else { 0 };
                negative |= if s < -bound { 1 << i } else { 0 };
            }
            let in_range = (DIRECTION_MIN..=DIRECTION_MAX).contains(&big);
            let all_one_sign = (positive == 0b111) | (negative == 0b111);
            let opposite = (positive != 0) & (negative != 0);
            inside[k] = if in_range & all_one_sign { u64::MAX } else { 0 };
            open[k] = if in_range & (all_one_sign | opposite) {
                0
            } else {
                u64::MAX
            };
        }
        (inside, open)
    }
}
