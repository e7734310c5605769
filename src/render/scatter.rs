//! How each material scatters a ray, in the course's weeks and in the book.
//!
//! Every scattered ray starts at the hit point and keeps the incoming ray's time (week 10:
//! "materials pass the time on").

use glam::DVec3;

use super::PixelSampler;
use super::optics::{Onb, reflect, refract_or_reflect};
use super::surface::Surface;
use crate::geometry::{Ray, unit_vector};
use crate::scene::{DiffuseSampling, Material, Profile, World};

/// A scattered ray and its attenuation (the course's `Scatterinfo`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scattered {
    /// The new ray.
    pub(crate) ray: Ray,
    /// What it is multiplied by.
    pub(crate) attenuation: DVec3,
}

/// `n + random_vec3_unit()`, or `n` itself when every component of that is below `1e-8` in
/// magnitude: week 5's Lambertian and the book's `lambertian` (its `near_zero`). Not normalised:
/// its length lies in `[0, 2]`.
#[inline(always)]
pub fn normal_plus_unit(n: DVec3, sampler: &mut PixelSampler) -> DVec3 {
    let d = n + sampler.unit_vector();
    if d.abs().max_element() < 1e-8 { n } else { d }
}

/// Week 9's Lambertian: a cosine-distributed direction about `n`,
/// `ONB.build_from_w(n).local(random_cosine_hemisphere_on_z())`, a unit vector.
#[inline(always)]
pub fn cosine_about(n: DVec3, sampler: &mut PixelSampler) -> DVec3 {
    Onb::from_w(n).local(sampler.cosine_hemisphere())
}

/// The diffuse direction of the course's week (`sampling`).
#[inline(always)]
fn diffuse(n: DVec3, sampling: DiffuseSampling, sampler: &mut PixelSampler) -> DVec3 {
    match sampling {
        DiffuseSampling::UnitSphere => normal_plus_unit(n, sampler),
        DiffuseSampling::Cosine => cosine_about(n, sampler),
    }
}

/// The course's `scattering(ray_in, hit)` of `material` (weeks 5 to 10), or `None` for a light.
///
/// - Lambertian and textured (week 5, week 9): the week's diffuse direction, attenuated by the
///   albedo or texture value. The BRDF materials scatter the same way, attenuated by their
///   albedo (the facts do not say otherwise; the BRDF integrator ignores the attenuation).
/// - Mirror (week 6): `reflect(d, n)` of the raw incoming direction, attenuated by the albedo.
/// - Dielectric (week 6): the unit direction refracted or reflected ([`refract_or_reflect`])
///   at ratio `1 / ior` on the front face and `ior` on the back, attenuated by the albedo.
/// - Metal (week 7): `reflect(unit(d), n) + roughness random_vec3_unit()`; the attenuation is
///   zero when that direction's `. n` is at most `1e-8` (the ray still goes on).
#[inline(always)]
pub(crate) fn course(
    world: &World,
    material: &Material,
    ray: &Ray,
    hit: &Surface,
    sampler: &mut PixelSampler,
) -> Option<Scattered> {
    let n = hit.normal;
    let sampling = world.settings.diffuse_sampling;
    let (direction, attenuation) = match *material {
        Material::DiffuseLight { .. } => return None,
        Material::Lambertian { albedo } => (diffuse(n, sampling, sampler), albedo),
        Material::Textured { ref texture } => {
            let colour = hit.texture(world, texture, Profile::Course);
            (diffuse(n, sampling, sampler), colour)
        }
        Material::Phong { albedo, .. }
        | Material::Blinn { albedo, .. }
        | Material::CookTorrance { albedo, .. } => (diffuse(n, sampling, sampler), albedo),
        Material::Mirror { albedo } => (reflect(ray.direction, n), albedo),
        Material::Dielectric { albedo, ior } => {
            let ratio = if hit.front_face { 1.0 / ior } else { ior };
            let v = unit_vector(ray.direction);
            (refract_or_reflect(v, n, ratio, sampler), albedo)
        }
        Material::Metal { albedo, roughness } => {
            let d = reflect(unit_vector(ray.direction), n) + roughness * sampler.unit_vector();
            let attenuation = if d.dot(n) <= 1e-8 {
                DVec3::ZERO
            } else {
                albedo
            };
            (d, attenuation)
        }
    };
    Some(Scattered {
        ray: Ray::at_time(hit.point, direction, ray.time),
        attenuation,
    })
}

/// The book's `scatter` of `material`: `None` when the ray is absorbed or the material emits.
///
/// - lambertian (and textured, as book 2's): `n + random_unit_vector()`, `n` when that is near
///   zero; attenuation the albedo (texture value).
/// - metal: `unit(reflect(d, n)) + fuzz random_unit_vector()`, absorbed unless its `. n` is
///   positive; a mirror is a metal of fuzz 0 (no random vector drawn).
/// - dielectric: as the course ([`refract_or_reflect`]), attenuated by the albedo (the book's
///   is white; a scene's albedo tints it).
/// - diffuse light (book 2): emits, does not scatter. The course's BRDF materials are refused
///   by validation under this profile; they scatter as lambertians if a world is built by hand.
#[inline(always)]
pub(crate) fn physical(
    world: &World,
    material: &Material,
    ray: &Ray,
    hit: &Surface,
    sampler: &mut PixelSampler,
) -> Option<Scattered> {
    let n = hit.normal;
    let (direction, attenuation) = match *material {
        Material::DiffuseLight { .. } => return None,
        Material::Lambertian { albedo }
        | Material::Phong { albedo, .. }
        | Material::Blinn { albedo, .. }
        | Material::CookTorrance { albedo, .. } => (normal_plus_unit(n, sampler), albedo),
        Material::Textured { ref texture } => {
            let colour = hit.texture(world, texture, Profile::Physical);
            (normal_plus_unit(n, sampler), colour)
        }
        Material::Metal { albedo, roughness } => {
            let d = unit_vector(reflect(ray.direction, n)) + roughness * sampler.unit_vector();
            if d.dot(n) <= 0.0 {
                return None;
            }
            (d, albedo)
        }
        Material::Mirror { albedo } => {
            let d = unit_vector(reflect(ray.direction, n));
            if d.dot(n) <= 0.0 {
                return None;
            }
            (d, albedo)
        }
        Material::Dielectric { albedo, ior } => {
            let ratio = if hit.front_face { 1.0 / ior } else { ior };
            let v = unit_vector(ray.direction);
            (refract_or_reflect(v, n, ratio, sampler), albedo)
        }
    };
    Some(Scattered {
        ray: Ray::at_time(hit.point, direction, ray.time),
        attenuation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::stats::assert_uniform_cells;

    /// Week 5's `n + random unit` gives, once normalised, the cosine lobe about `n` (the sum of
    /// a unit normal and a uniform unit vector is cosine-distributed): 10 x 8 cells of equal
    /// probability in `cos^2` and azimuth, chi-square at a false alarm of one in a million. Its
    /// length is `2 cos`, so it lies in `[0, 2]`.
    #[test]
    fn normal_plus_unit_is_the_cosine_lobe() {
        let n = DVec3::new(-0.2, 0.9, 0.1).normalize();
        let basis = crate::render::Onb::from_w(n);
        let mut sampler = PixelSampler::new(3, 3);
        let mut counts = [0u64; 80];
        for _ in 0..80_000 {
            let raw = normal_plus_unit(n, &mut sampler);
            let d = raw / raw.length();
            let z = d.dot(n);
            assert!((raw.length() - 2.0 * z).abs() < 1e-9, "{raw}");
            let phi = (d.dot(basis.v).atan2(d.dot(basis.u)) + std::f64::consts::PI)
                / (2.0 * std::f64::consts::PI);
            counts[((z * z * 10.0) as usize).min(9) * 8 + ((phi * 8.0) as usize).min(7)] += 1;
        }
        assert_uniform_cells(&counts, "n + random unit");
    }
}
