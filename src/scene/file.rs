//! The TOML scene format.
//!
//! ```toml
//! [image]
//! width = 400
//! aspect_ratio = 1.7777777777777777   # height = int(width / aspect_ratio)
//! samples_per_pixel = 20              # the default for `render`; --spp overrides it
//!
//! [camera]
//! look_from = [0.0, 0.0, 1.0]
//! look_at = [0.0, 0.0, -1.0]
//! up = [0.0, 1.0, 0.0]     # optional, [0, 1, 0] by default (the book's vup)
//! vfov = 90.0              # degrees
//! focus_distance = 10.0    # optional, 10 by default (the book's focus_dist)
//! defocus_angle = 0.0      # degrees; optional, 0 is a pinhole
//!
//! [[materials]]
//! name = "ground"
//! type = "lambertian"
//! albedo = [0.0, 0.0, 0.8]
//!
//! [[objects]]
//! type = "sphere"          # or "quad" (q, u, v) or "triangle" (a, b, c)
//! center = [0.0, -100.5, -1.0]
//! radius = 100.0           # negative flips the normal
//! material = "ground"
//! ```
//!
//! Every table rejects unknown fields. Every number must be finite.

use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::{Camera, CameraSettings, Material, Object, Scene, SceneObject};
use crate::geometry::{Quad, Sphere, Triangle};

/// What can be wrong with a scene (one line each, naming the scene and the problem).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    // The reason is in the message, not a `#[source]`, so a report of the whole chain (anyhow's
    // `{:#}`) does not say it twice.
    #[error("{path}: cannot read the scene file: {}", read_reason(.error))]
    Read {
        /// The file.
        path: String,
        /// Why.
        error: std::io::Error,
    },
    /// The file is not valid TOML or does not follow the schema.
    #[error("{path}: malformed scene file: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The parser's complaint, with line and column.
        message: String,
    },
    /// The scene parses but a value is unusable.
    #[error("{path}: {message}")]
    Invalid {
        /// The file or built-in scene name.
        path: String,
        /// What is wrong, naming the field.
        message: String,
    },
    /// No built-in scene has that name.
    #[error(
        "unknown scene '{name}' (not a built-in scene and not a .toml file; `rtoracle scenes` lists the built-ins)"
    )]
    Unknown {
        /// The name asked for.
        name: String,
    },
}

/// Image size and default sampling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageSettings {
    /// Width in pixels.
    pub width: usize,
    /// Width over height; the height is `int(width / aspect_ratio)`, as the course computes it.
    pub aspect_ratio: f64,
    /// Samples per pixel when the command line does not say.
    pub samples_per_pixel: u32,
}

/// A named material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialEntry {
    /// The name objects refer to it by.
    pub name: String,
    /// The kind (only `"lambertian"` in week 4).
    #[serde(rename = "type")]
    pub kind: MaterialKind,
    /// Linear RGB albedo.
    pub albedo: [f64; 3],
}

/// The kinds of material a scene file may name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    /// [`Material::Lambertian`].
    Lambertian,
}

/// One object of a scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ObjectEntry {
    /// A sphere.
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius (negative flips the normal; zero is rejected).
        radius: f64,
        /// Material name.
        material: String,
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
    fn material(&self) -> &str {
        match self {
            ObjectEntry::Sphere { material, .. }
            | ObjectEntry::Quad { material, .. }
            | ObjectEntry::Triangle { material, .. } => material,
        }
    }
}

/// A whole scene as a file states it: what `scenes --dump` prints and `render FILE` reads.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDescription {
    /// Image size and sampling.
    pub image: ImageSettings,
    /// The camera.
    pub camera: CameraSettings,
    /// The materials, referred to by name.
    pub materials: Vec<MaterialEntry>,
    /// The objects, in order (the order decides ties).
    pub objects: Vec<ObjectEntry>,
}

/// Why a scene file could not be read, in a few words ("no such file" rather than "No such file
/// or directory (os error 2)").
fn read_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::IsADirectory => "it is a folder".to_string(),
        std::io::ErrorKind::InvalidData => "it is not UTF-8 text".to_string(),
        _ => e.to_string(),
    }
}

fn check_vec(path: &str, field: &str, v: [f64; 3]) -> Result<(), SceneError> {
    for (axis, x) in ["x", "y", "z"].iter().zip(v) {
        check_num(path, &format!("{field}.{axis}"), x)?;
    }
    Ok(())
}

/// The largest width or height a scene may have, in pixels.
pub const MAX_SIDE: usize = 100_000;

fn check_num(path: &str, field: &str, x: f64) -> Result<(), SceneError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            path,
            format!("{field} is {x}, but every number in a scene must be finite"),
        ))
    }
}

fn invalid(path: &str, message: String) -> SceneError {
    SceneError::Invalid {
        path: path.to_string(),
        message,
    }
}

impl SceneDescription {
    /// Reads and validates a TOML scene file.
    pub fn from_file(path: &Path) -> Result<Self, SceneError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|error| SceneError::Read {
            path: name.clone(),
            error,
        })?;
        Self::from_toml(&text, &name)
    }

    /// Parses and validates TOML text; `name` labels errors.
    pub fn from_toml(text: &str, name: &str) -> Result<Self, SceneError> {
        let description: SceneDescription = toml::from_str(text).map_err(|e| {
            let location = e
                .span()
                .map(|span| {
                    let line = text[..span.start].matches('\n').count() + 1;
                    format!("line {line}: ")
                })
                .unwrap_or_default();
            let message = e.message().replace('\n', " ");
            SceneError::Parse {
                path: name.to_string(),
                message: format!("{location}{message}"),
            }
        })?;
        description.validate(name)?;
        Ok(description)
    }

    /// The scene as TOML, which [`SceneDescription::from_toml`] reads back to an equal value
    /// (numbers are written as shortest round-trip decimals).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a scene description always serialises")
    }

    /// Checks every number is finite and every value usable; `name` labels errors.
    pub fn validate(&self, name: &str) -> Result<(), SceneError> {
        let image = &self.image;
        if image.width == 0 {
            return Err(invalid(name, "image.width must be at least 1".into()));
        }
        check_num(name, "image.aspect_ratio", image.aspect_ratio)?;
        if image.aspect_ratio <= 0.0 {
            return Err(invalid(
                name,
                format!(
                    "image.aspect_ratio is {:?}, it must be positive",
                    image.aspect_ratio
                ),
            ));
        }
        if image.width > MAX_SIDE {
            return Err(invalid(
                name,
                format!("image.width is {}, at most {MAX_SIDE} pixels", image.width),
            ));
        }
        if image.width as f64 / image.aspect_ratio >= (MAX_SIDE + 1) as f64 {
            return Err(invalid(
                name,
                format!(
                    "image.aspect_ratio is {:?}: a {}-pixel-wide image would be more than \
                     {MAX_SIDE} pixels high",
                    image.aspect_ratio, image.width
                ),
            ));
        }
        if image.samples_per_pixel == 0 {
            return Err(invalid(
                name,
                "image.samples_per_pixel must be at least 1".into(),
            ));
        }
        let cam = &self.camera;
        check_vec(name, "camera.look_from", cam.look_from)?;
        check_vec(name, "camera.look_at", cam.look_at)?;
        check_vec(name, "camera.up", cam.up)?;
        check_num(name, "camera.vfov", cam.vfov)?;
        check_num(name, "camera.focus_distance", cam.focus_distance)?;
        check_num(name, "camera.defocus_angle", cam.defocus_angle)?;
        if !(cam.vfov > 0.0 && cam.vfov < 180.0) {
            return Err(invalid(
                name,
                format!(
                    "camera.vfov is {:?}, it must lie strictly between 0 and 180 degrees",
                    cam.vfov
                ),
            ));
        }
        if cam.focus_distance <= 0.0 {
            return Err(invalid(
                name,
                format!(
                    "camera.focus_distance is {:?}, it must be positive",
                    cam.focus_distance
                ),
            ));
        }
        if !(0.0..180.0).contains(&cam.defocus_angle) {
            return Err(invalid(
                name,
                format!(
                    "camera.defocus_angle is {:?}, it must lie in [0, 180)",
                    cam.defocus_angle
                ),
            ));
        }
        let view = DVec3::from(cam.look_from) - DVec3::from(cam.look_at);
        if view == DVec3::ZERO {
            return Err(invalid(
                name,
                "camera.look_from equals camera.look_at".into(),
            ));
        }
        if DVec3::from(cam.up).cross(view) == DVec3::ZERO {
            return Err(invalid(
                name,
                "camera.up is zero or parallel to the viewing direction".into(),
            ));
        }
        for (i, m) in self.materials.iter().enumerate() {
            check_vec(name, &format!("materials[{i}].albedo"), m.albedo)?;
            if self.materials[..i].iter().any(|other| other.name == m.name) {
                return Err(invalid(
                    name,
                    format!("materials[{i}]: the name '{}' is used twice", m.name),
                ));
            }
        }
        for (i, o) in self.objects.iter().enumerate() {
            let field = |f: &str| format!("objects[{i}].{f}");
            match o {
                ObjectEntry::Sphere { center, radius, .. } => {
                    check_vec(name, &field("center"), *center)?;
                    check_num(name, &field("radius"), *radius)?;
                    if *radius == 0.0 {
                        return Err(invalid(
                            name,
                            format!("{} is 0: a sphere needs a non-zero radius", field("radius")),
                        ));
                    }
                }
                ObjectEntry::Quad { q, u, v, .. } => {
                    check_vec(name, &field("q"), *q)?;
                    check_vec(name, &field("u"), *u)?;
                    check_vec(name, &field("v"), *v)?;
                    if DVec3::from(*u).cross(DVec3::from(*v)) == DVec3::ZERO {
                        return Err(invalid(
                            name,
                            format!("objects[{i}]: u and v are parallel, the quad is degenerate"),
                        ));
                    }
                }
                ObjectEntry::Triangle { a, b, c, .. } => {
                    check_vec(name, &field("a"), *a)?;
                    check_vec(name, &field("b"), *b)?;
                    check_vec(name, &field("c"), *c)?;
                    let (a, b, c) = (DVec3::from(*a), DVec3::from(*b), DVec3::from(*c));
                    if (b - a).cross(c - a) == DVec3::ZERO {
                        return Err(invalid(
                            name,
                            format!(
                                "objects[{i}]: the vertices are collinear, the triangle is degenerate"
                            ),
                        ));
                    }
                }
            }
            if !self.materials.iter().any(|m| m.name == o.material()) {
                return Err(invalid(
                    name,
                    format!(
                        "{} names the material '{}', which is not defined",
                        field("material"),
                        o.material()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The scene's objects and materials, ready to intersect.
    pub fn scene(&self) -> Scene {
        let materials = self
            .materials
            .iter()
            .map(|m| Material::Lambertian {
                albedo: DVec3::from(m.albedo),
            })
            .collect();
        let index = |name: &str| {
            self.materials
                .iter()
                .position(|m| m.name == name)
                .unwrap_or(0)
        };
        let objects = self
            .objects
            .iter()
            .map(|o| {
                let shape = match o {
                    ObjectEntry::Sphere { center, radius, .. } => {
                        Object::Sphere(Sphere::new(DVec3::from(*center), *radius))
                    }
                    ObjectEntry::Quad { q, u, v, .. } => {
                        Object::Quad(Quad::new(DVec3::from(*q), DVec3::from(*u), DVec3::from(*v)))
                    }
                    ObjectEntry::Triangle { a, b, c, .. } => Object::Triangle(Triangle::new(
                        DVec3::from(*a),
                        DVec3::from(*b),
                        DVec3::from(*c),
                    )),
                };
                SceneObject {
                    shape,
                    material: index(o.material()),
                }
            })
            .collect();
        Scene { objects, materials }
    }

    /// The camera for an image `width` pixels wide (the file's width when `None`).
    pub fn camera(&self, width: Option<usize>) -> Camera {
        Camera::new(
            &self.camera,
            width.unwrap_or(self.image.width),
            self.image.aspect_ratio,
        )
    }
}
