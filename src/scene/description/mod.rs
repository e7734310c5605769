//! A scene as a scene file states it ([`SceneDescription`]): the types of its tables, each with
//! what its keys mean. Reading and writing the file is `file`, checking it `validate`, and
//! writing it for Mitsuba 3 `mitsuba`.

pub(super) mod file;
pub(super) mod mitsuba;
pub(super) mod validate;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::{CameraSettings, Profile, RenderSettings};

/// Image size and default sampling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageSettings {
    /// Width in pixels.
    pub width: usize,
    /// Width over height; the height is `int(width / aspect_ratio)`, as the course computes it.
    pub aspect_ratio: f64,
    /// Samples per pixel when the command line does not say (and, for the course's jittered
    /// sampling, the `spp` its strata and its division come from).
    pub samples_per_pixel: u32,
}

/// The kinds of texture a scene file may name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TextureKind {
    /// One colour (`color`).
    Solid,
    /// The 3D checker (`scale`, `even`, `odd`).
    Checker,
    /// A picture: a PNG or JPEG `file`, or a picture rtoracle `generated`.
    Image,
}

/// A named texture (`[[textures]]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureEntry {
    /// The name materials refer to it by.
    pub name: String,
    /// The kind.
    #[serde(rename = "type")]
    pub kind: TextureKind,
    /// A solid texture's colour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<[f64; 3]>,
    /// A checker's cell side (positive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// A checker's colour where the cell sum is even.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub even: Option<[f64; 3]>,
    /// A checker's colour where it is odd.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub odd: Option<[f64; 3]>,
    /// An image's file, PNG or JPEG, relative to the scene file's folder (or absolute).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// An image rtoracle generates in code instead of a file (one of
    /// [`GENERATED_PICTURES`](super::GENERATED_PICTURES)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub generated: Option<String>,
}

/// The kinds of material a scene file may name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MaterialKind {
    /// [`Material::Lambertian`](super::Material::Lambertian): `albedo`.
    Lambertian,
    /// [`Material::Textured`](super::Material::Textured): `texture` (times `albedo`).
    Textured,
    /// [`Material::DiffuseLight`](super::Material::DiffuseLight): `albedo` is the emitted colour.
    DiffuseLight,
    /// [`Material::Mirror`](super::Material::Mirror): `albedo`.
    Mirror,
    /// [`Material::Dielectric`](super::Material::Dielectric): `albedo`, `ior`.
    Dielectric,
    /// [`Material::Metal`](super::Material::Metal): `albedo`, `roughness`.
    Metal,
    /// [`Material::Phong`](super::Material::Phong): `albedo`, `kd`, `ks`, `alpha`.
    Phong,
    /// [`Material::Blinn`](super::Material::Blinn): `albedo`, `kd`, `ks`, `alpha`.
    Blinn,
    /// [`Material::CookTorrance`](super::Material::CookTorrance): `kd`, `ks`, `alpha`, `ior`
    /// (and `albedo`, the scattering's attenuation).
    CookTorrance,
}

impl MaterialKind {
    /// The kind's name as a scene file spells it.
    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Lambertian => "lambertian",
            MaterialKind::Textured => "textured",
            MaterialKind::DiffuseLight => "diffuse_light",
            MaterialKind::Mirror => "mirror",
            MaterialKind::Dielectric => "dielectric",
            MaterialKind::Metal => "metal",
            MaterialKind::Phong => "phong",
            MaterialKind::Blinn => "blinn",
            MaterialKind::CookTorrance => "cook_torrance",
        }
    }

    /// The optional keys of a material entry this kind takes (besides `name`, `type` and
    /// `albedo`), each with whether it is required.
    pub fn keys(self) -> &'static [(&'static str, bool)] {
        match self {
            MaterialKind::Lambertian | MaterialKind::DiffuseLight | MaterialKind::Mirror => &[],
            MaterialKind::Textured => &[("texture", true)],
            MaterialKind::Dielectric => &[("ior", true)],
            MaterialKind::Metal => &[("roughness", true)],
            MaterialKind::Phong | MaterialKind::Blinn => {
                &[("kd", true), ("ks", true), ("alpha", true)]
            }
            MaterialKind::CookTorrance => {
                &[("kd", true), ("ks", true), ("alpha", true), ("ior", true)]
            }
        }
    }
}

/// `albedo` when a material entry leaves it out: white.
fn white() -> [f64; 3] {
    [1.0, 1.0, 1.0]
}

/// A named material (`[[materials]]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialEntry {
    /// The name objects refer to it by.
    pub name: String,
    /// The kind.
    #[serde(rename = "type")]
    pub kind: MaterialKind,
    /// Linear RGB: the albedo or attenuation; a light's emitted colour; the tint a texture is
    /// multiplied by. White when left out.
    #[serde(default = "white")]
    pub albedo: [f64; 3],
    /// A `textured` material's texture, by name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<String>,
    /// Index of refraction (`dielectric`, `cook_torrance`), positive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<f64>,
    /// A `metal`'s roughness (the book's fuzz), at least 0; above 1 counts as 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<f64>,
    /// The diffuse weight of a BRDF material, at least 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kd: Option<f64>,
    /// The specular weight of a BRDF material, at least 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ks: Option<f64>,
    /// The specular exponent (Phong, Blinn; at least 0) or roughness (Cook-Torrance; positive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
}

impl MaterialEntry {
    /// A material of `kind` called `name` with colour `albedo` and no other key.
    pub fn new(name: &str, kind: MaterialKind, albedo: [f64; 3]) -> Self {
        Self {
            name: name.to_string(),
            kind,
            albedo,
            texture: None,
            ior: None,
            roughness: None,
            kd: None,
            ks: None,
            alpha: None,
        }
    }

    /// The optional keys that are set, by name.
    pub fn keys_set(&self) -> Vec<&'static str> {
        [
            ("texture", self.texture.is_some()),
            ("ior", self.ior.is_some()),
            ("roughness", self.roughness.is_some()),
            ("kd", self.kd.is_some()),
            ("ks", self.ks.is_some()),
            ("alpha", self.alpha.is_some()),
        ]
        .into_iter()
        .filter_map(|(key, set)| set.then_some(key))
        .collect()
    }
}

/// One object of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ObjectEntry {
    /// A sphere.
    Sphere {
        /// Centre (at time 0, when it moves).
        center: [f64; 3],
        /// Radius (negative flips the normal; zero is rejected).
        radius: f64,
        /// Material name.
        material: String,
        /// Where the centre is at time 1, for a sphere that moves (week 10's `add_moving`); it
        /// moves in a straight line, `center + (moving_center - center) t`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        moving_center: Option<[f64; 3]>,
    },
    /// A parallelogram `q + alpha u + beta v`.
    Quad {
        /// Corner.
        q: [f64; 3],
        /// First edge.
        u: [f64; 3],
        /// Second edge.
        v: [f64; 3],
        /// Material name.
        material: String,
    },
    /// A triangle.
    Triangle {
        /// First vertex.
        a: [f64; 3],
        /// Second vertex.
        b: [f64; 3],
        /// Third vertex.
        c: [f64; 3],
        /// Material name.
        material: String,
    },
}

impl ObjectEntry {
    /// The name of the object's material.
    pub fn material(&self) -> &str {
        match self {
            ObjectEntry::Sphere { material, .. }
            | ObjectEntry::Quad { material, .. }
            | ObjectEntry::Triangle { material, .. } => material,
        }
    }
}

/// A whole scene as a file states it: what `scenes --dump` prints and `render FILE` reads.
///
/// Its canonical form ([`SceneDescription::to_toml`]) holds everything that decides the image
/// except the content of the texture files it names ([`SceneDescription::external_files`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// The rules the scene is rendered by (`course` when a file leaves it out).
    #[serde(default, skip_serializing_if = "Profile::is_course")]
    pub profile: Profile,
    /// Image size and sampling.
    pub image: ImageSettings,
    /// The camera.
    pub camera: CameraSettings,
    /// The integrator and its settings (a week-4 scene when a file leaves the table out).
    #[serde(default, skip_serializing_if = "RenderSettings::is_default")]
    pub render: RenderSettings,
    /// The textures, referred to by name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<TextureEntry>,
    /// The materials, referred to by name.
    pub materials: Vec<MaterialEntry>,
    /// The objects, in order (the order decides ties).
    pub objects: Vec<ObjectEntry>,
    /// The folder relative texture files are found in (the scene file's; the working folder
    /// when `None`).
    #[serde(skip)]
    pub base_dir: Option<PathBuf>,
}
