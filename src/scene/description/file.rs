//! The TOML scene format: reading a scene file, writing a scene's canonical form, and turning a
//! description into the [`World`] a render reads.
//!
//! ```toml
//! profile = "course"       # optional: "course" (the default) or "physical"
//!
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
//! [render]                 # optional: without it, week 4 (albedo of the closest hit, sky)
//! integrator = "direct"    # "albedo" (week 4), "direct" (weeks 5-7), "brdf" (weeks 8-10)
//! direct_term = "clamped"  # weeks 5-7: "clamped" (E min(1, 1/d)) or "unclamped" (E / d)
//! direct_light = true      # weeks 8-10: add the point lights' direct term
//! max_depth = 5            # at least 1; 50 by default
//! background = "flat"      # "sky" (the default) or "flat"
//! background_color = [0.01, 0.01, 0.01]
//! diffuse_sampling = "unit-sphere"   # or "cosine" (weeks 9-10)
//! sampling = "uniform"     # or "course-jittered" (weeks 9-10), with jitter_step
//!
//! [[textures]]
//! name = "ground"
//! type = "checker"         # "solid" (color), "checker" (scale, even, odd),
//! scale = 0.32             # "image" (file = "earthmap.png" relative to this file,
//! even = [0.2, 0.2, 0.2]   #   or generated = "earth")
//! odd = [0.9, 0.9, 0.9]
//!
//! [[materials]]
//! name = "ground"
//! type = "textured"        # lambertian, textured (texture), diffuse_light, mirror,
//! texture = "ground"       # dielectric (ior), metal (roughness), phong and blinn
//!                          # (kd, ks, alpha), cook_torrance (kd, ks, alpha, ior)
//! albedo = [1.0, 1.0, 1.0] # the colour (a light's emission, a texture's tint)
//!
//! [[objects]]
//! type = "sphere"          # or "quad" (q, u, v) or "triangle" (a, b, c)
//! center = [0.0, -100.5, -1.0]
//! radius = 100.0           # negative flips the normal
//! material = "ground"
//! # moving_center = [0.0, -100.0, -1.0]   # where the centre is at time 1
//! ```
//!
//! Every table rejects unknown keys, and a key that does not apply to its kind. Every number must
//! be finite.

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::geometry::{MovingSphere, Quad, Sphere, Triangle};
use crate::scene::error::SceneError;
use crate::scene::texture::{RgbPicture, generated_picture, read_picture};
use crate::scene::{
    Camera, CameraSettings, ImageSettings, Material, MaterialEntry, MaterialKind, Object,
    ObjectEntry, Profile, RenderSettings, Scene, SceneDescription, SceneObject, Texture,
    TextureEntry, TextureImage, TextureKind, World,
};

impl SceneDescription {
    /// A course-profile, week-4 scene (no `[render]` table, no textures) of these parts.
    pub fn new(
        image: ImageSettings,
        camera: CameraSettings,
        materials: Vec<MaterialEntry>,
        objects: Vec<ObjectEntry>,
    ) -> Self {
        Self {
            profile: Profile::Course,
            image,
            camera,
            render: RenderSettings::default(),
            textures: Vec::new(),
            materials,
            objects,
            base_dir: None,
        }
    }

    /// Reads and validates a TOML scene file; its texture files are named relative to its
    /// folder.
    pub fn from_file(path: &Path) -> Result<Self, SceneError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|error| SceneError::Read {
            path: name.clone(),
            error,
        })?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml_in(&text, &name, &base)
    }

    /// Parses and validates TOML text; `name` labels errors, and texture files are named
    /// relative to the working folder.
    pub fn from_toml(text: &str, name: &str) -> Result<Self, SceneError> {
        Self::from_toml_in(text, name, Path::new(""))
    }

    /// Parses and validates TOML text whose texture files are named relative to `base`; `name`
    /// labels errors.
    pub fn from_toml_in(text: &str, name: &str, base: &Path) -> Result<Self, SceneError> {
        let mut description: SceneDescription = toml::from_str(text).map_err(|e| {
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
        description.base_dir = (!base.as_os_str().is_empty()).then(|| base.to_path_buf());
        description.validate(name)?;
        Ok(description)
    }

    /// The scene's canonical form: TOML that [`SceneDescription::from_toml`] reads back to an
    /// equal value (numbers as shortest round-trip decimals). Everything that decides the
    /// image is in it except the content of the files [`SceneDescription::external_files`]
    /// names; a table or key at its default is left out, so a week-4 scene's form is what it
    /// always was.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a scene description always serialises")
    }

    /// `file` as the scene reads it: relative to [`SceneDescription::base_dir`] unless absolute.
    pub fn resolve(&self, file: &str) -> PathBuf {
        match &self.base_dir {
            Some(base) if Path::new(file).is_relative() => base.join(file),
            _ => PathBuf::from(file),
        }
    }

    /// The files the image depends on besides the scene itself (its image textures), resolved,
    /// in the order of the `[[textures]]` table: a cache of its renders must be keyed by their
    /// content too.
    pub fn external_files(&self) -> Vec<PathBuf> {
        self.textures
            .iter()
            .filter_map(|t| t.file.as_deref())
            .map(|f| self.resolve(f))
            .collect()
    }

    /// The picture of image texture `t`, read from its file or generated.
    fn picture(&self, t: &TextureEntry) -> Result<RgbPicture, String> {
        match (&t.file, &t.generated) {
            (Some(file), _) => read_picture(&self.resolve(file)).map_err(|e| e.to_string()),
            (None, Some(name)) => {
                generated_picture(name).ok_or_else(|| format!("no generated picture '{name}'"))
            }
            (None, None) => Err("no file".into()),
        }
    }

    /// The scene ready to render: objects, materials, the textures' images prepared for the
    /// profile, the point lights and settings.
    ///
    /// The texture files are read again here (validation read them once, before any work);
    /// one that has become unreadable since gives the course's colour for an unusable file,
    /// `(0, 1, 1)`, everywhere.
    pub fn scene(&self) -> World {
        let profile = self.profile;
        let mut images = Vec::new();
        let textures: Vec<(String, Texture)> = self
            .textures
            .iter()
            .map(|t| {
                let v = |c: Option<[f64; 3]>| DVec3::from(c.unwrap_or([0.0; 3]));
                let texture = match t.kind {
                    TextureKind::Solid => Texture::Solid(v(t.color)),
                    TextureKind::Checker => Texture::Checker {
                        scale: t.scale.unwrap_or(1.0),
                        even: v(t.even),
                        odd: v(t.odd),
                    },
                    TextureKind::Image => {
                        let image = match self.picture(t) {
                            Ok(p) => TextureImage::new(p.width, p.height, &p.data, profile),
                            Err(_) => TextureImage::new(0, 0, &[], profile),
                        };
                        images.push(image);
                        Texture::Image {
                            image: images.len() - 1,
                            tint: DVec3::ONE,
                        }
                    }
                };
                (t.name.clone(), texture)
            })
            .collect();
        let texture_of = |name: &Option<String>| {
            name.as_ref()
                .and_then(|n| textures.iter().find(|(t, _)| t == n))
                .map_or(Texture::Solid(DVec3::ONE), |(_, t)| *t)
        };
        let materials = self
            .materials
            .iter()
            .map(|m| material_of(m, texture_of(&m.texture)))
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
            .map(|o| SceneObject {
                shape: shape_of(o),
                material: index(o.material()),
            })
            .collect();
        let cam = &self.camera;
        let lens = cam.focus_distance * libm::tan(cam.defocus_angle.to_radians() / 2.0);
        let reach = DVec3::from(cam.look_from).abs().max_element() + lens.abs();
        let mut world = World::new(
            Scene { objects, materials },
            profile,
            self.render,
            images,
            reach,
        );
        world.samples_per_pixel = self.image.samples_per_pixel;
        world
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

/// The material of entry `m`, whose texture (for a textured one) is `texture`.
fn material_of(m: &MaterialEntry, texture: Texture) -> Material {
    let albedo = DVec3::from(m.albedo);
    let (kd, ks, alpha) = (
        m.kd.unwrap_or(0.0),
        m.ks.unwrap_or(0.0),
        m.alpha.unwrap_or(0.0),
    );
    let ior = m.ior.unwrap_or(1.0);
    match m.kind {
        MaterialKind::Lambertian => Material::Lambertian { albedo },
        MaterialKind::Textured => Material::Textured {
            texture: tinted(texture, albedo),
        },
        MaterialKind::DiffuseLight => Material::DiffuseLight { emit: albedo },
        MaterialKind::Mirror => Material::Mirror { albedo },
        MaterialKind::Dielectric => Material::Dielectric { albedo, ior },
        MaterialKind::Metal => Material::Metal {
            albedo,
            // Both the course and the book clamp the roughness (fuzz) to at most 1.
            roughness: m.roughness.unwrap_or(0.0).min(1.0),
        },
        MaterialKind::Phong => Material::Phong {
            albedo,
            kd,
            ks,
            alpha,
        },
        MaterialKind::Blinn => Material::Blinn {
            albedo,
            kd,
            ks,
            alpha,
        },
        MaterialKind::CookTorrance => Material::CookTorrance {
            albedo,
            kd,
            ks,
            alpha,
            ior,
        },
    }
}

/// `texture` with every colour multiplied by `tint` (white changes nothing, bit for bit).
fn tinted(texture: Texture, tint: DVec3) -> Texture {
    match texture {
        Texture::Solid(c) => Texture::Solid(tint * c),
        Texture::Checker { scale, even, odd } => Texture::Checker {
            scale,
            even: tint * even,
            odd: tint * odd,
        },
        Texture::Image { image, tint: t } => Texture::Image {
            image,
            tint: tint * t,
        },
    }
}

/// The shape of object entry `o`.
fn shape_of(o: &ObjectEntry) -> Object {
    match o {
        ObjectEntry::Sphere {
            center,
            radius,
            moving_center,
            ..
        } => {
            let sphere = Sphere::new(DVec3::from(*center), *radius);
            match moving_center {
                Some(end) => Object::MovingSphere(MovingSphere::new(sphere, DVec3::from(*end))),
                None => Object::Sphere(sphere),
            }
        }
        ObjectEntry::Quad { q, u, v, .. } => {
            Object::Quad(Quad::new(DVec3::from(*q), DVec3::from(*u), DVec3::from(*v)))
        }
        ObjectEntry::Triangle { a, b, c, .. } => Object::Triangle(Triangle::new(
            DVec3::from(*a),
            DVec3::from(*b),
            DVec3::from(*c),
        )),
    }
}
