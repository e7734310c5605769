use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::geometry::{Ray, unit_vector};

/// The camera as a scene file states it (the course's `Camera` fields).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSettings {
    /// The eye position.
    pub look_from: [f64; 3],
    /// The point looked at.
    pub look_at: [f64; 3],
    /// The "up" direction (need not be orthogonal to the view direction). Optional in a scene
    /// file: `[0, 1, 0]` by default, the book's and the course's `vup`.
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Vertical field of view in degrees, in `(0, 180)`.
    pub vfov: f64,
    /// Distance from `look_from` to the plane in focus (the viewport lies there). Optional in a
    /// scene file: 10 by default, the book's and the course's `focus_dist` (with a pinhole it
    /// only scales the viewport, so the image does not depend on it).
    #[serde(default = "default_focus_distance")]
    pub focus_distance: f64,
    /// Angle of the cone of rays through each pixel, in degrees; 0 is a pinhole.
    #[serde(default)]
    pub defocus_angle: f64,
}

/// `up` when a scene file leaves it out: the book's `vup`.
fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// `focus_distance` when a scene file leaves it out: the book's `focus_dist`.
fn default_focus_distance() -> f64 {
    10.0
}

/// The course's camera (after *Ray Tracing in One Weekend*, 4th edition), with every derived
/// quantity computed as the course computes it, in the same order of operations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels: `int(width / aspect_ratio)`, at least 1.
    pub height: usize,
    /// The eye position (`look_from`).
    pub center: DVec3,
    /// Centre of the upper-left pixel on the focus plane.
    pub pixel00: DVec3,
    /// Step from one pixel to the next one to the right.
    pub pixel_delta_u: DVec3,
    /// Step from one pixel to the next one down.
    pub pixel_delta_v: DVec3,
    /// Horizontal radius vector of the defocus disk.
    pub defocus_disk_u: DVec3,
    /// Vertical radius vector of the defocus disk.
    pub defocus_disk_v: DVec3,
    /// Whether rays start on the defocus disk (`defocus_angle > 0`).
    pub defocus: bool,
}

/// `degrees * pi / 180`, the course's `degrees_to_radians` (not `f64::to_radians`, which rounds
/// differently).
#[inline]
fn degrees_to_radians(degrees: f64) -> f64 {
    degrees * std::f64::consts::PI / 180.0
}

impl Camera {
    /// The camera for an image `width` pixels wide with the given aspect ratio.
    ///
    /// `tan` is libm's so the result does not depend on the platform's maths library.
    pub fn new(settings: &CameraSettings, width: usize, aspect_ratio: f64) -> Self {
        let height = ((width as f64 / aspect_ratio) as usize).max(1);
        let center = DVec3::from(settings.look_from);
        let theta = degrees_to_radians(settings.vfov);
        let h = libm::tan(theta / 2.0);
        let viewport_height = 2.0 * h * settings.focus_distance;
        let viewport_width = viewport_height * (width as f64 / height as f64);

        let w = unit_vector(center - DVec3::from(settings.look_at));
        let u = unit_vector(DVec3::from(settings.up).cross(w));
        let v = w.cross(u);

        let viewport_u = viewport_width * u;
        let viewport_v = viewport_height * -v;
        let pixel_delta_u = viewport_u / width as f64;
        let pixel_delta_v = viewport_v / height as f64;
        let upper_left = center - settings.focus_distance * w - viewport_u / 2.0 - viewport_v / 2.0;
        let pixel00 = upper_left + 0.5 * (pixel_delta_u + pixel_delta_v);

        let defocus_radius =
            settings.focus_distance * libm::tan(degrees_to_radians(settings.defocus_angle / 2.0));
        Self {
            width,
            height,
            center,
            pixel00,
            pixel_delta_u,
            pixel_delta_v,
            defocus_disk_u: u * defocus_radius,
            defocus_disk_v: v * defocus_radius,
            defocus: settings.defocus_angle > 0.0,
        }
    }

    /// The ray through the continuous pixel position `(x, y)`, where `(i, j)` is the centre of
    /// pixel column `i`, row `j` (the course adds a jitter in `[-0.5, 0.5)` to each).
    ///
    /// `disk` is a point of the unit disk (used only with defocus blur).
    #[inline]
    pub fn ray_through(&self, x: f64, y: f64, disk: (f64, f64)) -> Ray {
        let pixel_sample = self.pixel00 + (x * self.pixel_delta_u) + (y * self.pixel_delta_v);
        let origin = if self.defocus {
            self.center + (disk.0 * self.defocus_disk_u) + (disk.1 * self.defocus_disk_v)
        } else {
            self.center
        };
        Ray::new(origin, pixel_sample - origin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn course_sphere_camera_has_the_course_geometry() {
        let settings = CameraSettings {
            look_from: [0.0, 0.0, 1.0],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            vfov: 90.0,
            focus_distance: 10.0,
            defocus_angle: 0.0,
        };
        let cam = Camera::new(&settings, 400, 16.0 / 9.0);
        assert_eq!((cam.width, cam.height), (400, 225));
        // vfov 90 at focus distance 10: the viewport is 20 high and 20 * 400/225 wide, at z = -9.
        assert!((cam.pixel_delta_v.y + 20.0 / 225.0).abs() < 1e-12);
        assert!((cam.pixel_delta_u.x - 20.0 * (400.0 / 225.0) / 400.0).abs() < 1e-12);
        assert!((cam.pixel00.z + 9.0).abs() < 1e-12);
    }
}
