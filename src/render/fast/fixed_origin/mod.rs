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
//! lane. In a scene of quads only, on a processor with AVX2, the packet's quads are tested in
//! AVX2 intrinsics (`quad::quads_hit_avx2`), the same operations again: the compiler had turned
//! the portable code's four lanes into two-lane vectors there (week 4's quads ran 1.3 times
//! faster so).
//!
//! For a whole cone of directions (a pixel's footprint, [`Cone`]), [`FixedOrigin::candidates`]
//! leaves out the spheres and triangles it proves no direction of the cone hits, so that leaving
//! them out of [`FixedOrigin::closest_packet`] changes no lane's answer, and
//! [`FixedOrigin::covering`] names the object every direction of the cone is proved to hit when
//! it is the only candidate left. Both err on the side of "cannot tell".

mod cone;
mod quad;
mod sphere;
#[cfg(test)]
mod tests;
mod triangle;

use glam::DVec3;

use self::cone::Bound;
pub(crate) use self::cone::Cone;
use self::cone::{SANE_MAX, SANE_MIN};
use self::quad::{quad_hit_lanes, quads_hit};
use self::sphere::{PREFILTER_MARGIN, PreparedSphere};
use self::triangle::PreparedTriangle;
use super::packet::{Directions, Lanes, NO_HIT, WIDTH};
use crate::geometry::{Interval, Quad, Ray, Shape};
use crate::scene::{Object, Scene};

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

/// The bound of `object` for rays from `origin`. The ball's radius is the magnitude of the
/// object's (a sphere's negative radius is the same surface with its normal flipped: the
/// slack added to the signed radius shrank the ball, far from the world's origin below the
/// distance of an eye inside the sphere, which every ray hits, and the sphere was ruled out),
/// widened by four times the rounding of `center - origin`, so the computed offset can stand
/// for the exact one.
fn bound_of(object: &Prepared, origin: DVec3) -> Bound {
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

impl FixedOrigin {
    /// `scene` prepared for rays leaving `origin`.
    pub(crate) fn new(scene: &Scene, origin: DVec3) -> Self {
        let objects: Vec<Prepared> = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Object::Sphere(s) => Prepared::Sphere(PreparedSphere::new(&s, origin)),
                // The fast path's rays are at time 0 (it is not taken when something moves).
                Object::MovingSphere(m) => {
                    Prepared::Sphere(PreparedSphere::new(&m.at(0.0), origin))
                }
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
            bounds: objects.iter().map(|o| bound_of(o, origin)).collect(),
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
            Layout::Quads(quads) => quads_hit(
                quads,
                candidates,
                self.origin,
                d,
                interval.min,
                &mut closest,
                &mut index,
            ),
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
