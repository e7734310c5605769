use glam::DVec3;

/// A surface material. Week 4 of the course has one: a Lambertian albedo, which the course's
/// integrator returns as the colour of a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// A diffuse surface with the given albedo (linear RGB in `[0, 1]`).
    Lambertian {
        /// Fraction of light reflected per channel.
        albedo: DVec3,
    },
}

impl Material {
    /// The albedo of the material.
    #[inline]
    pub fn albedo(&self) -> DVec3 {
        match self {
            Material::Lambertian { albedo } => *albedo,
        }
    }
}
