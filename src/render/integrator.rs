use glam::DVec3;

use crate::geometry::{Interval, Ray};
use crate::scene::Scene;

/// The course's sky: `a = 0.5 (unit(d).y + 1)`, `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1.0)`.
#[inline]
pub fn sky(direction: DVec3) -> DVec3 {
    sky_at(sky_height(direction))
}

/// The sky's height coordinate along `direction`: `a = 0.5 (unit(d).y + 1)`, computing
/// `unit_vector(direction).y` without the two divisions whose results are not used.
#[inline(always)]
pub(crate) fn sky_height(direction: DVec3) -> f64 {
    0.5 * (direction.y / direction.length() + 1.0)
}

/// The sky's colour at height `a = 0.5 (unit(d).y + 1)`: `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1.0)`.
#[inline(always)]
pub(crate) fn sky_at(a: f64) -> DVec3 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit_vector;

    /// The shortcut computes the same `a` as the course's `unit_vector(d).y`, bit for bit.
    #[test]
    fn sky_uses_the_y_of_the_unit_vector() {
        let mut s = crate::render::PixelSampler::new(3, 5);
        for _ in 0..100_000 {
            let d = DVec3::new(
                s.next_f64() * 40.0 - 20.0,
                s.next_f64() * 40.0 - 20.0,
                s.next_f64() * 40.0 - 20.0,
            );
            let a = 0.5 * (unit_vector(d).y + 1.0);
            let expected = (1.0 - a) * DVec3::ONE + a * DVec3::new(0.5, 0.7, 1.0);
            assert_eq!(sky(d), expected, "{d}");
        }
    }

    /// Closed forms: straight up is the top colour, straight down white, horizontal the average.
    #[test]
    fn sky_gradient_ends() {
        assert_eq!(sky(DVec3::Y), DVec3::new(0.5, 0.7, 1.0));
        assert_eq!(sky(-DVec3::Y * 3.0), DVec3::ONE);
        assert_eq!(sky(DVec3::X), DVec3::new(0.75, 0.85, 1.0));
    }
}
