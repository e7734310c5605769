//! What the integrators need of a hit: the point, the normal facing the ray, which side it came
//! from, and surface coordinates for textures (computed only when a texture reads them).

use glam::DVec3;

use crate::geometry::{Interval, Ray, Shape, Sphere};
use crate::scene::{Material, Object, Profile, Texture, World};

/// A hit, as the integrators read it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Surface {
    /// The hit point, `origin + t direction`.
    pub(crate) point: DVec3,
    /// The unit normal facing the ray.
    pub(crate) normal: DVec3,
    /// Whether the ray arrives from the outside (the outward normal faces it).
    pub(crate) front_face: bool,
    coordinates: Coordinates,
}

/// Surface coordinates, or what they are computed from.
#[derive(Clone, Copy, Debug)]
enum Coordinates {
    /// A sphere's, from its outward normal `(P - C) / r`.
    Sphere(DVec3),
    /// A quad's `(alpha, beta)` or a triangle's barycentric `(beta, gamma)`.
    Given(f64, f64),
}

/// A sphere's surface coordinates from its outward normal `n` (week 7's `get_uv`, the book's
/// `get_sphere_uv`): `theta = acos(-n.y)`, `phi = atan2(-n.z, n.x) + pi`, `u = phi / 2 pi`,
/// `v = theta / pi`.
///
/// Rounding can make `|n.y|` exceed 1 at a pole, where the course's `math.acos` raises
/// `ValueError`; what it evidently intends is the pole, so `-n.y` is clamped to `[-1, 1]`.
#[inline]
pub fn sphere_uv(n: DVec3) -> (f64, f64) {
    use std::f64::consts::PI;
    let theta = libm::acos((-n.y).clamp(-1.0, 1.0));
    let phi = libm::atan2(-n.z, n.x) + PI;
    (phi / (2.0 * PI), theta / PI)
}

impl Surface {
    /// The hit of object `object` at `t` along `ray` (found within `interval`).
    #[inline(always)]
    pub(crate) fn of(world: &World, ray: &Ray, t: f64, object: usize, interval: Interval) -> Self {
        let point = ray.at(t);
        let sphere = |s: Sphere| {
            let outward = (point - s.center) / s.radius;
            Self::facing(ray, point, outward, Coordinates::Sphere(outward))
        };
        match world.objects[object].shape {
            Object::Sphere(s) => sphere(s),
            Object::MovingSphere(m) => sphere(m.at(ray.time)),
            Object::Quad(q) => {
                // `Quad::solve_from`'s `(alpha, beta)` at the hit point.
                let planar = point - q.q;
                let alpha = q.w.dot(planar.cross(q.v));
                let beta = q.w.dot(q.u.cross(planar));
                Self::facing(ray, point, q.normal, Coordinates::Given(alpha, beta))
            }
            Object::Triangle(tri) => {
                let within = Interval::new(interval.min, f64::MAX);
                let uv = tri.intersect(ray, within).map_or((0.0, 0.0), |h| h.uv);
                Self::facing(ray, point, tri.normal, Coordinates::Given(uv.0, uv.1))
            }
        }
    }

    /// The record with the normal set to face `ray` from `outward`, as the course's
    /// `set_face_normal` does.
    #[inline(always)]
    fn facing(ray: &Ray, point: DVec3, outward: DVec3, coordinates: Coordinates) -> Self {
        let front_face = ray.direction.dot(outward) < 0.0;
        Self {
            point,
            normal: if front_face { outward } else { -outward },
            front_face,
            coordinates,
        }
    }

    /// The surface coordinates `(u, v)`.
    #[inline]
    pub(crate) fn uv(&self) -> (f64, f64) {
        match self.coordinates {
            Coordinates::Sphere(n) => sphere_uv(n),
            Coordinates::Given(u, v) => (u, v),
        }
    }

    /// `texture`'s value here.
    #[inline(always)]
    pub(crate) fn texture(&self, world: &World, texture: &Texture, profile: Profile) -> DVec3 {
        match texture {
            Texture::Solid(c) => *c,
            Texture::Checker { .. } => texture.value(&[], (0.0, 0.0), self.point, profile),
            // Only an image reads the surface coordinates.
            Texture::Image { .. } => texture.value(&world.images, self.uv(), self.point, profile),
        }
    }

    /// The colour of `material` here: its albedo, or its texture's value.
    #[inline(always)]
    pub(crate) fn colour(&self, world: &World, material: &Material) -> DVec3 {
        match material {
            Material::Textured { texture } => self.texture(world, texture, world.profile),
            other => other.albedo(),
        }
    }
}
