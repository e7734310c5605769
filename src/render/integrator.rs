use glam::DVec3;

use crate::geometry::{Interval, Ray, unit_vector};
use crate::scene::Scene;

/// The course's sky: `a = 0.5 (unit(d).y + 1)`, `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1.0)`.
#[inline]
pub fn sky(direction: DVec3) -> DVec3 {
    let a = 0.5 * (unit_vector(direction).y + 1.0);
    (1.0 - a) * DVec3::ONE + a * DVec3::new(0.5, 0.7, 1.0)
}

/// The course's week-4 integrator: the albedo of the closest hit in `(1e-6, f64::MAX)`, or the
/// sky on a miss.
#[inline]
pub fn radiance(scene: &Scene, ray: &Ray) -> DVec3 {
    match scene.closest(ray, Interval::CAMERA) {
        Some((_, index)) => scene.material_of(index).albedo(),
        None => sky(ray.direction),
    }
}
