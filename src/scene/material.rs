//! Surface materials: what the course's `RT_material` classes hold, weeks 4 to 10, and the
//! book's `lambertian`, `metal` and `dielectric`. How each scatters and what its BRDF is live in
//! the renderer (`render::scatter`, `render::brdf`), next to the integrators that use them.

use glam::DVec3;

use super::Texture;

/// A surface material. Colours are linear RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// A diffuse surface (the course's `Lambertian(cAlbedo)`, the book's `lambertian`): week 4
    /// shows its albedo, later weeks scatter diffusely and attenuate by it.
    Lambertian {
        /// Fraction of light reflected per channel.
        albedo: DVec3,
    },
    /// A diffuse surface coloured by a texture (week 7's `TextureColor(tex)`): a Lambertian
    /// whose albedo is the texture's value at the hit.
    Textured {
        /// The texture.
        texture: Texture,
    },
    /// An emitter (week 5's `Diffuse_light(cAlbedo)`): it does not scatter and returns its
    /// colour. A sphere of this material is also a point light at its centre in the `course`
    /// profile.
    DiffuseLight {
        /// The emitted radiance per channel.
        emit: DVec3,
    },
    /// A perfect mirror (week 6's `Mirror(cAlbedo)`): reflects the incoming direction as it is.
    Mirror {
        /// Attenuation per channel.
        albedo: DVec3,
    },
    /// Glass (week 6's `Dielectric(cAlbedo, fIor)`, the book's `dielectric`): refracts or
    /// reflects by Schlick's approximation.
    Dielectric {
        /// Attenuation per channel (the book's is white).
        albedo: DVec3,
        /// Index of refraction, inside over outside (positive).
        ior: f64,
    },
    /// A rough mirror (week 7's `Metal(cAlbedo, fRoughness)`, the book's `metal` with `fuzz`).
    Metal {
        /// Attenuation per channel.
        albedo: DVec3,
        /// Radius of the sphere of random offsets added to the unit reflection, at most 1
        /// (larger values are clamped to 1, as both the course and the book do).
        roughness: f64,
    },
    /// Week 8's Phong BRDF: `kd albedo / pi + ks albedo max(0, R . V)^alpha`.
    Phong {
        /// Colour per channel.
        albedo: DVec3,
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Specular exponent.
        alpha: f64,
    },
    /// Week 8's Blinn BRDF: `kd albedo / pi + ks albedo max(0, H . n)^alpha`.
    Blinn {
        /// Colour per channel.
        albedo: DVec3,
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Specular exponent.
        alpha: f64,
    },
    /// Week 8's Cook-Torrance BRDF (GGX distribution, Smith shadowing, Schlick's Fresnel).
    CookTorrance {
        /// The scattering attenuation (week 8's signature has a colour; the BRDF itself is grey).
        albedo: DVec3,
        /// Diffuse weight.
        kd: f64,
        /// Specular weight.
        ks: f64,
        /// Roughness of the GGX distribution.
        alpha: f64,
        /// Index of refraction for the Fresnel term.
        ior: f64,
    },
}

impl Material {
    /// The material's colour: the albedo (attenuation) of the colour-bearing kinds, the emitted
    /// colour of a light, and for a texture its solid colour (a checker's even colour, an image's
    /// tint): what the week-4 integrator shows for an untextured material.
    #[inline]
    pub fn albedo(&self) -> DVec3 {
        match *self {
            Material::Lambertian { albedo }
            | Material::Mirror { albedo }
            | Material::Dielectric { albedo, .. }
            | Material::Metal { albedo, .. }
            | Material::Phong { albedo, .. }
            | Material::Blinn { albedo, .. }
            | Material::CookTorrance { albedo, .. } => albedo,
            Material::Textured { texture } => texture.base_colour(),
            Material::DiffuseLight { emit } => emit,
        }
    }

    /// Whether the material emits (the course's `is_light()`).
    #[inline]
    pub fn is_light(&self) -> bool {
        matches!(self, Material::DiffuseLight { .. })
    }

    /// Whether the material is one of the course's BRDF models, which the `physical` profile
    /// does not have.
    pub fn is_course_brdf(&self) -> bool {
        matches!(
            self,
            Material::Phong { .. } | Material::Blinn { .. } | Material::CookTorrance { .. }
        )
    }
}
