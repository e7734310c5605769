//! The renderer's fast path for a pinhole camera, where every primary ray leaves the same point.
//!
//! Whatever depends only on the origin and an object is computed once per render instead of once
//! per ray (a sphere's `origin - center` and `|origin - center|^2 - r^2`, a quad's
//! `d - normal . origin`, a triangle's vertices relative to the origin), and whatever depends only
//! on the direction is computed once per ray for all objects (`|d|^2`, the triangles' shear).
//! The decisions themselves are the very functions the shapes' [`Shape`](crate::geometry::Shape)
//! implementations call, fed the same values, so the closest hit is the same, bit for bit, as
//! [`Scene::closest`]'s (a test checks it on millions of rays).
//!
//! The renderer asks for packets of [`WIDTH`] rays at once ([`FixedOrigin::closest_packet`]):
//! each object is decided for all the lanes in straight-line code (vector instructions, no
//! branch per ray), operation for operation as the scalar functions do it, and each lane keeps
//! its own closest hit, as the scalar loop does. A sphere the pre-filter rules out for every lane,
//! or a quad whose plane no lane meets within its interval, is skipped for the packet. A
//! triangle's lanes are first classified against its three edge planes seen from the origin
//! (`PreparedTriangle`): a lane clearly inside gets the triangle's `t` by its own formula, one
//! clearly outside misses, and only lanes too close to an edge to tell run the triangle's own
//! watertight test. Lanes whose intermediates over- or underflow take the scalar path, lane by
//! lane.
//!
//! For a whole cone of directions (a pixel's footprint, [`Cone`]), [`FixedOrigin::candidates`]
//! leaves out the spheres and triangles it proves no direction of the cone hits, so that leaving
//! them out of [`FixedOrigin::closest_packet`] changes no lane's answer, and
//! [`FixedOrigin::covering`] names the object every direction of the cone is proved to hit when
//! it is the only candidate left. Both err on the side of "cannot tell".

use glam::DVec3;

use super::packet::{Directions, Lanes, NO_HIT, WIDTH};
use crate::geometry::{Interval, PARALLEL_EPSILON, Quad, Ray};
use crate::geometry::{Shape, Sphere, Triangle, pick_root, roots_of};
use crate::scene::{Object, Scene};

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
const PREFILTER_MARGIN: f64 = 1e-12;
const SANE_MIN: f64 = 1e-100;
const SANE_MAX: f64 = 1e100;

/// A sphere's origin-dependent constants.
#[derive(Clone, Copy, Debug)]
struct PreparedSphere {
    /// The sphere itself, for the rare rays whose intermediates over- or underflow.
    sphere: Sphere,
    /// `origin - center`.
    f: DVec3,
    /// `radius^2`.
    r2: f64,
    /// `f . f - r2`.
    c: f64,
    /// `f . f + r2`, the scale of the discriminant's rounding errors, or NaN where the
    /// pre-filter is off (see [`PREFILTER_MARGIN`]).
    scale: f64,
}

impl PreparedSphere {
    fn new(sphere: &Sphere, origin: DVec3) -> Self {
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
    fn hit_t(
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
    fn covers(&self, cone: &Cone) -> bool {
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
    fn hit_lanes(
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

/// `Quad::solve_from` for each lane's direction from `origin`, against each lane's interval
/// `[min, closest[k]]`: where it hits, `closest[k]` becomes its `t` and `index[k]` becomes `me`.
/// The same operations in the same order as the scalar path, so the same bits.
#[inline(always)]
// Lane loops index several arrays in step.
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
fn quad_hit_lanes(
    quad: &Quad,
    offset: f64,
    origin: DVec3,
    d: &Directions,
    min: f64,
    closest: &mut Lanes,
    index: &mut [u64; WIDTH],
    me: u64,
) {
    let (n, q, u, v, w) = (quad.normal, quad.q, quad.u, quad.v, quad.w);
    // The plane first: when no lane meets it within its interval (behind the eye, or beyond
    // what a lane has already hit), the quad is skipped for the whole packet.
    let mut denoms = [0.0; WIDTH];
    let mut ts = [0.0; WIDTH];
    let mut inside = [0u64; WIDTH];
    for k in 0..WIDTH {
        denoms[k] = n.x * d.x[k] + n.y * d.y[k] + n.z * d.z[k];
        ts[k] = offset / denoms[k];
        inside[k] = if (min <= ts[k]) & (ts[k] <= closest[k]) {
            u64::MAX
        } else {
            0
        };
    }
    if inside.iter().fold(0, |any, &i| any | i) == 0 {
        return;
    }
    for k in 0..WIDTH {
        let (denom, t) = (denoms[k], ts[k]);
        // `ray.at(t) - q`.
        let px = (origin.x + d.x[k] * t) - q.x;
        let py = (origin.y + d.y[k] * t) - q.y;
        let pz = (origin.z + d.z[k] * t) - q.z;
        // `w . (planar x v)` and `w . (u x planar)`.
        let alpha =
            w.x * (py * v.z - v.y * pz) + w.y * (pz * v.x - v.z * px) + w.z * (px * v.y - v.x * py);
        let beta =
            w.x * (u.y * pz - py * u.z) + w.y * (u.z * px - pz * u.x) + w.z * (u.x * py - px * u.y);
        let hit = (denom.abs() >= PARALLEL_EPSILON)
            & t.is_finite()
            & (min <= t)
            & (t <= closest[k])
            & (0.0..=1.0).contains(&alpha)
            & (0.0..=1.0).contains(&beta);
        closest[k] = if hit { t } else { closest[k] };
        index[k] = if hit { me } else { index[k] };
    }
}

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
struct PreparedTriangle {
    /// The triangle itself, for the lanes the pre-classification leaves open.
    triangle: Triangle,
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
    fn new(triangle: &Triangle, origin: DVec3) -> Self {
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
    fn covers(&self, cone: &Cone) -> bool {
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
    fn hit_lanes(
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

/// One object with its origin-dependent constants.
#[derive(Clone, Copy, Debug)]
enum Prepared {
    Sphere(PreparedSphere),
    Quad {
        quad: Quad,
        /// `quad.d - quad.normal . origin`.
        offset: f64,
    },
    /// A triangle with its edge planes seen from the origin.
    Triangle(PreparedTriangle),
}

/// The objects, with the common cases of a scene of one kind stored without the enum, so the
/// closest-hit loop over them has no branch on the kind (the course's scenes are all spheres or
/// all quads). The order is kept either way.
#[derive(Clone, Debug)]
enum Layout {
    Spheres(Vec<PreparedSphere>),
    Quads(Vec<(Quad, f64)>),
    Mixed(Vec<Prepared>),
}

/// A scene prepared for rays from one origin.
#[derive(Clone, Debug)]
pub(crate) struct FixedOrigin {
    origin: DVec3,
    layout: Layout,
    /// Per object, what [`Self::candidates`] may rule out for a whole cone of directions.
    bounds: Vec<Bound>,
    /// The objects in order, for [`Self::covering`].
    objects: Vec<Prepared>,
}

/// The objects a packet must test: bit `k` for object `k` (objects from 64 on are always
/// tested).
pub(crate) type Candidates = u64;

/// Every object a candidate.
pub(crate) const ALL_CANDIDATES: Candidates = u64::MAX;

/// Whether object `me` is among `candidates`.
#[inline(always)]
fn is_candidate(candidates: Candidates, me: usize) -> bool {
    me >= 64 || (candidates >> me) & 1 == 1
}

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
enum Bound {
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
    /// The bound of `object` for rays from `origin`. The ball's radius is the magnitude of the
    /// object's (a sphere's negative radius is the same surface with its normal flipped: the
    /// slack added to the signed radius shrank the ball, far from the world's origin below the
    /// distance of an eye inside the sphere, which every ray hits, and the sphere was ruled out),
    /// widened by four times the rounding of `center - origin`, so the computed offset can stand
    /// for the exact one.
    fn of(object: &Prepared, origin: DVec3) -> Self {
        let widened = |center: DVec3, radius: f64| {
            radius.abs() + 4.0 * f64::EPSILON * (center.abs() + origin.abs()).max_element()
        };
        match object {
            Prepared::Sphere(sphere) if sphere.scale.is_finite() => Bound::Prefiltered {
                to_center: sphere.sphere.center - origin,
                radius: widened(sphere.sphere.center, sphere.sphere.radius),
            },
            Prepared::Triangle(prepared) => {
                let t = prepared.triangle;
                let center = (t.a + t.b + t.c) / 3.0;
                let radius = [t.a, t.b, t.c]
                    .map(|v| (v - center).length())
                    .into_iter()
                    .fold(0.0, f64::max);
                if center.is_finite() && radius.is_finite() {
                    // Rounding in the centre and the distances is far below this slack.
                    Bound::Line {
                        to_center: center - origin,
                        radius: widened(center, radius * (1.0 + 1e-9) + 1e-300),
                    }
                } else {
                    Bound::Always
                }
            }
            _ => Bound::Always,
        }
    }

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
    fn rules_out(&self, cone: &Cone) -> bool {
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

impl FixedOrigin {
    /// `scene` prepared for rays leaving `origin`.
    pub(crate) fn new(scene: &Scene, origin: DVec3) -> Self {
        let objects: Vec<Prepared> = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Object::Sphere(s) => Prepared::Sphere(PreparedSphere::new(&s, origin)),
                Object::Quad(quad) => Prepared::Quad {
                    quad,
                    offset: quad.plane_offset(origin),
                },
                Object::Triangle(t) => Prepared::Triangle(PreparedTriangle::new(&t, origin)),
            })
            .collect();
        let layout = if objects.iter().all(|o| matches!(o, Prepared::Sphere(_))) {
            Layout::Spheres(
                objects
                    .iter()
                    .filter_map(|o| match o {
                        Prepared::Sphere(s) => Some(*s),
                        _ => None,
                    })
                    .collect(),
            )
        } else if objects.iter().all(|o| matches!(o, Prepared::Quad { .. })) {
            Layout::Quads(
                objects
                    .iter()
                    .filter_map(|o| match o {
                        Prepared::Quad { quad, offset } => Some((*quad, *offset)),
                        _ => None,
                    })
                    .collect(),
            )
        } else {
            Layout::Mixed(objects.clone())
        };
        Self {
            origin,
            layout,
            bounds: objects.iter().map(|o| Bound::of(o, origin)).collect(),
            objects,
        }
    }

    /// The object every direction of `cone` hits, when `candidates` (from
    /// [`Self::candidates`]) holds that object alone and it is proved hit (within
    /// [`Interval::CAMERA`]) by every direction of the cone: then each such ray's closest hit is
    /// that object.
    pub(crate) fn covering(&self, cone: &Cone, candidates: Candidates) -> Option<usize> {
        if self.objects.len() > 64 || candidates.count_ones() != 1 {
            return None;
        }
        let me = candidates.trailing_zeros() as usize;
        let sane = |a: f64| (SANE_MIN * 4.0..SANE_MAX / 4.0).contains(&a);
        if !(sane(cone.length2_min) && sane(cone.length2_max)) {
            return None;
        }
        let covered = match &self.objects[me] {
            Prepared::Sphere(sphere) => sphere.covers(cone),
            Prepared::Triangle(triangle) => triangle.covers(cone),
            Prepared::Quad { .. } => false,
        };
        covered.then_some(me)
    }

    /// The objects some direction of `cone` may hit: the others are proved missed by every
    /// one of them, so leaving them out of [`Self::closest_packet`] changes no answer.
    pub(crate) fn candidates(&self, cone: &Cone) -> Candidates {
        let mut candidates = match self.bounds.len() {
            n @ 0..64 => (1 << n) - 1,
            _ => ALL_CANDIDATES,
        };
        for (me, bound) in self.bounds.iter().enumerate().take(64) {
            if bound.rules_out(cone) {
                candidates &= !(1 << me);
            }
        }
        candidates
    }

    /// The closest hit's `t` and object index along direction `d`: the same answer as
    /// `scene.closest(&Ray::new(origin, d), interval)`.
    #[inline(always)]
    pub(crate) fn closest(&self, d: DVec3, interval: Interval) -> Option<(f64, usize)> {
        // Each layout has its own loop; the two homogeneous ones are inlined into the sample
        // loop, the mixed one is not (measured on the course's scenes).
        match &self.layout {
            Layout::Spheres(spheres) => Self::closest_sphere(self.origin, spheres, d, interval),
            Layout::Quads(quads) => self.closest_quad(quads, d, interval),
            Layout::Mixed(objects) => self.closest_mixed(objects, d, interval),
        }
    }

    /// The index of the closest hit along each lane's direction ([`NO_HIT`] for none): for every
    /// lane, the same answer as [`Self::closest`].
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::needless_range_loop)]
    pub(crate) fn closest_packet(
        &self,
        d: &Directions,
        interval: Interval,
        candidates: Candidates,
    ) -> [u64; WIDTH] {
        let mut closest = [interval.max; WIDTH];
        let mut index = [NO_HIT; WIDTH];
        if candidates == 0 {
            return index;
        }
        match &self.layout {
            Layout::Spheres(spheres) => {
                let (a, a_margin) = Self::squared_lengths(d);
                for (me, sphere) in spheres.iter().enumerate() {
                    if !is_candidate(candidates, me) {
                        continue;
                    }
                    let lanes = sphere.hit_lanes(
                        d,
                        &a,
                        &a_margin,
                        interval.min,
                        &mut closest,
                        &mut index,
                        me as u64,
                    );
                    if lanes.is_err() {
                        return self.closest_each(d, interval);
                    }
                }
            }
            Layout::Quads(quads) => {
                for (me, (quad, offset)) in quads.iter().enumerate() {
                    if !is_candidate(candidates, me) {
                        continue;
                    }
                    quad_hit_lanes(
                        quad,
                        *offset,
                        self.origin,
                        d,
                        interval.min,
                        &mut closest,
                        &mut index,
                        me as u64,
                    );
                }
            }
            Layout::Mixed(objects) => {
                let (a, a_margin) = Self::squared_lengths(d);
                for (me, object) in objects.iter().enumerate() {
                    if !is_candidate(candidates, me) {
                        continue;
                    }
                    let me = me as u64;
                    match object {
                        Prepared::Sphere(sphere) => {
                            let lanes = sphere.hit_lanes(
                                d,
                                &a,
                                &a_margin,
                                interval.min,
                                &mut closest,
                                &mut index,
                                me,
                            );
                            if lanes.is_err() {
                                return self.closest_each(d, interval);
                            }
                        }
                        Prepared::Quad { quad, offset } => quad_hit_lanes(
                            quad,
                            *offset,
                            self.origin,
                            d,
                            interval.min,
                            &mut closest,
                            &mut index,
                            me,
                        ),
                        Prepared::Triangle(triangle) => triangle.hit_lanes(
                            self.origin,
                            d,
                            interval.min,
                            &mut closest,
                            &mut index,
                            me,
                        ),
                    }
                }
            }
        }
        index
    }

    /// Each lane's `a = d . d` and `a * PREFILTER_MARGIN` (see [`Self::margin`]).
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::needless_range_loop)]
    fn squared_lengths(d: &Directions) -> (Lanes, Lanes) {
        let mut a = [0.0; WIDTH];
        let mut a_margin = [0.0; WIDTH];
        for k in 0..WIDTH {
            a[k] = d.x[k] * d.x[k] + d.y[k] * d.y[k] + d.z[k] * d.z[k];
            a_margin[k] = Self::margin(a[k]);
        }
        (a, a_margin)
    }

    /// [`Self::closest_packet`] one lane at a time.
    #[inline(never)]
    fn closest_each(&self, d: &Directions, interval: Interval) -> [u64; WIDTH] {
        std::array::from_fn(|k| {
            self.closest(d.lane(k), interval)
                .map_or(NO_HIT, |(_, index)| index as u64)
        })
    }

    /// `a * PREFILTER_MARGIN` for `a = d . d`, or NaN (pre-filter off) unless `a` is far from
    /// overflow and underflow.
    #[inline(always)]
    fn margin(a: f64) -> f64 {
        if (SANE_MIN..SANE_MAX).contains(&a) {
            a * PREFILTER_MARGIN
        } else {
            f64::NAN
        }
    }

    #[inline(always)]
    fn closest_sphere(
        origin: DVec3,
        spheres: &[PreparedSphere],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let a = d.dot(d);
        let a_margin = Self::margin(a);
        let mut best = None;
        let mut closest = interval.max;
        for (index, sphere) in spheres.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            if let Some(t) = sphere.hit_t(origin, d, a, a_margin, within) {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }

    #[inline(always)]
    fn closest_quad(
        &self,
        quads: &[(Quad, f64)],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let ray = Ray::new(self.origin, d);
        let mut best = None;
        let mut closest = interval.max;
        for (index, (quad, offset)) in quads.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            if let Some((t, _, _)) = quad.solve_from(&ray, *offset, within) {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }

    #[inline(never)]
    fn closest_mixed(
        &self,
        objects: &[Prepared],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let ray = Ray::new(self.origin, d);
        let a = d.dot(d);
        let a_margin = Self::margin(a);
        let mut best = None;
        let mut closest = interval.max;
        for (index, object) in objects.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            let t = match *object {
                Prepared::Sphere(ref sphere) => sphere.hit_t(self.origin, d, a, a_margin, within),
                Prepared::Quad { ref quad, offset } => {
                    quad.solve_from(&ray, offset, within).map(|(t, _, _)| t)
                }
                Prepared::Triangle(ref prepared) => prepared.triangle.hit_t(&ray, within),
            };
            if let Some(t) = t {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PixelSampler;
    use crate::scene::BUILTIN_SCENES;

    /// Every built-in scene, from its camera's eye, over rays through (and far beyond) the image,
    /// plus rays aimed at object features (centres, corners, edges, vertices) where ties and
    /// boundaries live: the fast path answers exactly as `Scene::closest`.
    #[test]
    fn agrees_with_the_scene_bit_for_bit() {
        let mut checked = 0usize;
        for builtin in BUILTIN_SCENES {
            let description = builtin.description();
            let scene = description.scene();
            let camera = description.camera(Some(64));
            let fast = FixedOrigin::new(&scene, camera.center);
            let mut rng = PixelSampler::new(11, checked as u64);
            let mut targets: Vec<DVec3> = Vec::new();
            for _ in 0..250_000 {
                // Positions over three times the image in each direction.
                let x = (rng.next_f64() * 3.0 - 1.0) * camera.width as f64;
                let y = (rng.next_f64() * 3.0 - 1.0) * camera.height as f64;
                targets.push(camera.pixel00 + x * camera.pixel_delta_u + y * camera.pixel_delta_v);
            }
            for o in &scene.objects {
                match o.shape {
                    Object::Sphere(s) => {
                        targets.push(s.center);
                        // The silhouette seen from the eye (tangent rays) and just inside and outside
                        // it, where the pre-filter and the robust discriminant are closest to 0.
                        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                            for k in [0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6] {
                                targets.push(s.center + axis * s.radius * (1.0 + k));
                                targets.push(s.center - axis * s.radius * (1.0 + k));
                            }
                        }
                    }
                    Object::Quad(q) => {
                        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.0)] {
                            targets.push(q.q + a * q.u + b * q.v);
                        }
                    }
                    Object::Triangle(t) => {
                        targets.extend([t.a, t.b, t.c, (t.a + t.b) * 0.5, (t.b + t.c) * 0.5]);
                    }
                }
            }
            let mut packet = Directions::default();
            let mut expected_indices = [NO_HIT; WIDTH];
            for (n, target) in targets.into_iter().enumerate() {
                let d = target - camera.center;
                let ray = Ray::new(camera.center, d);
                let expected = scene.closest(&ray, Interval::CAMERA);
                let got = fast.closest(d, Interval::CAMERA);
                assert_eq!(
                    got.map(|(t, i)| (t.to_bits(), i)),
                    expected.map(|(t, i)| (t.to_bits(), i)),
                    "{} along {d}",
                    builtin.name
                );
                // Packets of consecutive targets: neighbours in the image, or unrelated features.
                packet.set(n % WIDTH, d);
                expected_indices[n % WIDTH] = expected.map_or(NO_HIT, |(_, i)| i as u64);
                if n % WIDTH == WIDTH - 1 {
                    assert_eq!(
                        fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                        expected_indices,
                        "{} along {packet:?}",
                        builtin.name
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 1_000_000);
    }

    /// Triangles from random eyes, alone and mixed with spheres and quads, over rays aimed at
    /// their vertices, at points of their edges (and just off them, by a few ulps and by
    /// `1e-9`), and anywhere: the edge pre-classification answers exactly as `Scene::closest`,
    /// in packets and one ray at a time. Far, huge and tiny triangles take the same paths.
    #[test]
    fn triangles_agree_with_the_scene_bit_for_bit_near_their_edges() {
        let mut rng = PixelSampler::new(23, 0);
        let mut r = move |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
        let mut checked = 0usize;
        for scene_index in 0..300 {
            let scale = [1.0, 1e-3, 1e4, 1e-150, 1e150][scene_index % 5];
            let mut point = |spread: f64| {
                DVec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-3.0, -1.0)) * spread * scale
            };
            let triangles: Vec<Triangle> = (0..3)
                .map(|_| Triangle::new(point(1.0), point(1.0), point(1.0)))
                .collect();
            let mut shapes: Vec<Object> = triangles.iter().map(|&t| Object::Triangle(t)).collect();
            if scene_index % 3 == 1 {
                shapes.insert(1, Object::Sphere(Sphere::new(point(1.0), 0.3 * scale)));
                shapes.push(Object::Quad(Quad::new(
                    point(1.0),
                    DVec3::new(0.5, 0.1, 0.0) * scale,
                    DVec3::new(0.0, 0.4, 0.2) * scale,
                )));
            }
            let scene = scene_of(&shapes);
            let origin = DVec3::new(r(-0.2, 0.2), r(-0.2, 0.2), r(0.0, 0.5)) * scale;
            let fast = FixedOrigin::new(&scene, origin);
            let mut targets = Vec::new();
            for t in &triangles {
                for (p, q) in [(t.a, t.b), (t.b, t.c), (t.c, t.a)] {
                    targets.push(p);
                    for _ in 0..40 {
                        let on_edge = p + (q - p) * r(0.0, 1.0);
                        targets.push(on_edge);
                        let off = (q - p).cross(t.normal);
                        for k in [1e-9, -1e-9, 4e-16, -4e-16, 1e-15, -1e-15] {
                            targets.push(on_edge + off * k);
                        }
                    }
                }
                for _ in 0..100 {
                    targets.push(t.a + (t.b - t.a) * r(-0.5, 1.5) + (t.c - t.a) * r(-0.5, 1.5));
                }
            }
            let mut packet = Directions::default();
            let mut expected_indices = [NO_HIT; WIDTH];
            for (n, target) in targets.into_iter().enumerate() {
                let d = target - origin;
                let expected = scene.closest(&Ray::new(origin, d), Interval::CAMERA);
                assert_eq!(
                    fast.closest(d, Interval::CAMERA)
                        .map(|(t, i)| (t.to_bits(), i)),
                    expected.map(|(t, i)| (t.to_bits(), i)),
                    "scene {scene_index} along {d}"
                );
                packet.set(n % WIDTH, d);
                expected_indices[n % WIDTH] = expected.map_or(NO_HIT, |(_, i)| i as u64);
                if n % WIDTH == WIDTH - 1 {
                    assert_eq!(
                        fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                        expected_indices,
                        "scene {scene_index} along {packet:?}"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked > 500_000, "{checked}");
    }

    /// Degenerate and non-finite directions take the same (missing) path in both.
    #[test]
    fn agrees_on_degenerate_directions() {
        let description = crate::scene::builtin("triangles").unwrap();
        let scene = description.scene();
        let origin = DVec3::new(0.0, 0.0, 6.0);
        let fast = FixedOrigin::new(&scene, origin);
        for d in [
            DVec3::ZERO,
            DVec3::new(f64::NAN, 0.0, -1.0),
            DVec3::new(0.0, f64::INFINITY, -1.0),
            DVec3::new(1e-300, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -1e300),
        ] {
            let expected = scene.closest(&Ray::new(origin, d), Interval::CAMERA);
            assert_eq!(
                fast.closest(d, Interval::CAMERA)
                    .map(|(t, i)| (t.to_bits(), i)),
                expected.map(|(t, i)| (t.to_bits(), i)),
                "{d}"
            );
        }
    }

    /// A scene of `shapes`, all with one material.
    fn scene_of(shapes: &[Object]) -> Scene {
        Scene {
            objects: shapes
                .iter()
                .map(|&shape| crate::scene::SceneObject { shape, material: 0 })
                .collect(),
            materials: vec![crate::scene::Material::Lambertian {
                albedo: DVec3::splat(0.5),
            }],
        }
    }

    /// Exact cases the random rays above almost never meet, each with a known answer: equal
    /// spheres keep the first (the open `surrounds`), equal quads the last (the closed
    /// `contains`), a ray tangent to a sphere with a discriminant of exactly 0 hits it at `t = 5`,
    /// a ray through a quad's corner hits it, a quad exactly at `t = 1e-6` is hit (closed) and one
    /// at `t = 2^-20 < 1e-6` is not. Every lane of a packet gets the scene's answer, in any lane.
    #[test]
    fn packets_keep_ties_tangents_and_boundaries() {
        let eye = DVec3::new(-5.0, 0.0, 0.0);
        let sphere = Sphere::new(DVec3::new(0.0, 0.0, -1.0), 1.0);
        // A square in the plane x = x0 facing -x (normal (1, 0, 0) from u x v = (4, 0, 0)), from
        // (x0, 0, 0) to (x0, 2, -2).
        let square_at = |x0: f64| {
            Quad::new(
                DVec3::new(x0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, -2.0),
                DVec3::new(0.0, 2.0, 0.0),
            )
        };
        let square = square_at(0.0);
        let cases: [(&str, DVec3, Vec<Object>, DVec3, u64); 7] = [
            (
                "equal spheres",
                eye,
                vec![Object::Sphere(sphere), Object::Sphere(sphere)],
                DVec3::new(5.0, 0.0, -1.0),
                0,
            ),
            (
                "equal quads",
                eye,
                vec![Object::Quad(square), Object::Quad(square)],
                DVec3::new(5.0, 1.0, -1.0),
                1,
            ),
            // f = (-5, 0, 1), a = 1, b' = -5: the perpendicular is (0, 0, 1) and the
            // discriminant 1 * (1 - 1) = 0 exactly; q = 5, both roots 25 / 5 = 5 / 1 = 5.
            (
                "tangent sphere",
                eye,
                vec![Object::Sphere(sphere)],
                DVec3::new(1.0, 0.0, 0.0),
                0,
            ),
            (
                "quad corner",
                eye,
                vec![Object::Quad(square)],
                DVec3::new(5.0, 0.0, 0.0),
                0,
            ),
            // offset = 1e-6 - 0 and t = 1e-6 / 1, both exact.
            (
                "quad at t = 1e-6",
                DVec3::new(0.0, 1.0, -1.0),
                vec![Object::Quad(square_at(1e-6))],
                DVec3::new(1.0, 0.0, 0.0),
                0,
            ),
            // -5 + 2^-20 is exact, so t = 2^-20 ~ 9.5e-7.
            (
                "quad at t = 2^-20",
                DVec3::new(-5.0, 1.0, -1.0),
                vec![Object::Quad(square_at(-5.0 + 2f64.powi(-20)))],
                DVec3::new(1.0, 0.0, 0.0),
                NO_HIT,
            ),
            (
                "no hit behind",
                eye,
                vec![Object::Sphere(sphere), Object::Quad(square)],
                DVec3::new(-1.0, 0.0, 0.0),
                NO_HIT,
            ),
        ];
        let filler = DVec3::new(0.0, 1.0, 0.0);
        for (what, origin, shapes, d, answer) in cases {
            let scene = scene_of(&shapes);
            let expected = scene
                .closest(&Ray::new(origin, d), Interval::CAMERA)
                .map_or(NO_HIT, |(_, i)| i as u64);
            assert_eq!(expected, answer, "{what}: the scene's own answer");
            let fast = FixedOrigin::new(&scene, origin);
            for slot in 0..WIDTH {
                let mut packet = Directions::default();
                for k in 0..WIDTH {
                    packet.set(k, if k == slot { d } else { filler });
                }
                let got = fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES);
                assert_eq!(got[slot], answer, "{what} in lane {slot}");
            }
        }
    }

    /// A packet where one lane's intermediates overflow (a direction near `f64::MAX`, or one so
    /// short its square underflows) takes the scalar path for all its lanes, and every lane still
    /// gets the scene's answer; so does a lane with a NaN direction.
    #[test]
    fn packets_with_an_overflowing_lane_agree_with_the_scene() {
        for name in ["week04-sphere", "week04-quad", "edge-cases", "triangles"] {
            let description = crate::scene::builtin(name).unwrap();
            let scene = description.scene();
            let camera = description.camera(Some(32));
            let fast = FixedOrigin::new(&scene, camera.center);
            let ordinary = [
                camera.pixel00 + 16.0 * camera.pixel_delta_u + 9.0 * camera.pixel_delta_v,
                camera.pixel00 + 3.0 * camera.pixel_delta_u + 20.0 * camera.pixel_delta_v,
                camera.pixel00 + 28.0 * camera.pixel_delta_u + 2.0 * camera.pixel_delta_v,
            ]
            .map(|target| target - camera.center);
            for odd in [
                DVec3::new(0.0, -1e300, -1e300),
                DVec3::new(1e-200, -1e-200, -1e-200),
                DVec3::new(f64::NAN, 0.0, -1.0),
                DVec3::new(0.0, 0.0, f64::NEG_INFINITY),
            ] {
                for slot in 0..WIDTH {
                    let mut packet = Directions::default();
                    for k in 0..WIDTH {
                        let d = if k == slot {
                            odd
                        } else {
                            ordinary[k % ordinary.len()]
                        };
                        packet.set(k, d);
                    }
                    let expected: [u64; WIDTH] = std::array::from_fn(|k| {
                        scene
                            .closest(&Ray::new(camera.center, packet.lane(k)), Interval::CAMERA)
                            .map_or(NO_HIT, |(_, i)| i as u64)
                    });
                    assert_eq!(
                        fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                        expected,
                        "{name}: {odd} in lane {slot}"
                    );
                }
            }
        }
    }
}
