//! Rays, intervals, hit records and the primitives (spheres, moving spheres, quads, triangles),
//! in `f64`.
//!
//! Everything here follows the course's semantics (see `docs/oracle.md`, "The course's semantics"):
//! spheres take the near root when the interval *surrounds* it (open), quads and triangles take
//! `t` when the interval *contains* it (closed), directions are never normalised, and the normal
//! of a hit record is a unit vector that faces the incoming ray.

mod interval;
mod ray;
mod hit;
mod quad;
mod sphere;
mod triangle;

pub use hit::HitRecord;
pub use interval::Interval;
pub use quad::{PARALLEL_EPSILON, Quad};
pub use ray::Ray;
pub use sphere::{MovingSphere, Sphere};
pub(crate) use sphere::{pick_root, roots_of};
pub use triangle::Triangle;

/// The `f64` 3-vector used everywhere (re-exported from glam).
pub use glam::DVec3;

/// A primitive a ray can be intersected with.
///
/// One required method; everything else a scene needs is built on it. Implementations must be
/// pure functions of their inputs (no hidden state), so the renderer stays deterministic.
pub trait Shape {
    /// The hit of `ray` with this shape whose `t` lies in `interval` (open or closed ends as the
    /// shape's semantics say), or `None`. `material` of the record is left at 0.
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord>;

    /// The `t` of the hit [`Shape::intersect`] would return, without building the record.
    ///
    /// Always the same decision and the same `t`, bit for bit, as `intersect`; shapes override
    /// it when the record costs more than the decision (a sphere's surface coordinates).
    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        self.intersect(ray, interval).map(|h| h.t)
    }
}

/// The unit vector of `v`, computed as `v / |v|` (component-wise division, as the course's
/// `unit_vector` does; glam's `normalize` multiplies by the reciprocal instead, which differs
/// in the last bit for about half of all vectors).
#[inline(always)]
pub fn unit_vector(v: DVec3) -> DVec3 {
    v / v.length()
}

/// Whether every component of `v` is finite.
#[inline]
pub fn is_finite(v: DVec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}
