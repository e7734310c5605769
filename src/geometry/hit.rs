use glam::DVec3;

use super::Ray;

/// What a ray hit: the course's `Hitinfo`, plus surface coordinates and a material index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HitRecord {
    /// The ray parameter of the hit.
    pub t: f64,
    /// The hit point, `origin + t * direction`.
    pub point: DVec3,
    /// The unit normal, facing the ray (`normal . direction <= 0`).
    pub normal: DVec3,
    /// `direction . outward_normal < 0`: the ray arrives from the outside.
    pub front_face: bool,
    /// Surface coordinates: `(alpha, beta)` for quads, the barycentric weights of `b` and `c`
    /// for triangles, and `(u, v)` spherical coordinates in `[0, 1]` for spheres.
    pub uv: (f64, f64),
    /// Index of the material in the scene (0 when the shape is intersected on its own).
    pub material: usize,
}

impl HitRecord {
    /// A record at `t` on `ray` whose normal is set to face the ray from the unit
    /// `outward_normal`, as the course's `set_face_normal` does.
    #[inline]
    pub fn new(ray: &Ray, t: f64, outward_normal: DVec3, uv: (f64, f64)) -> Self {
        let front_face = ray.direction.dot(outward_normal) < 0.0;
        let normal = if front_face {
            outward_normal
        } else {
            -outward_normal
        };
        Self {
            t,
            point: ray.at(t),
            normal,
            front_face,
            uv,
            material: 0,
        }
    }
}
