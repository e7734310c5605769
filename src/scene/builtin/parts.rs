//! The pieces the built-in scenes are made of.

use std::path::PathBuf;

use crate::scene::error::invalid;
use crate::scene::{
    CameraSettings, MaterialEntry, MaterialKind, ObjectEntry, SceneError, TextureEntry, TextureKind,
};

/// Where a built-in scene's image textures come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TextureSource {
    /// The pictures rtoracle generates (so a checked-in golden can exist).
    Generated,
    /// The course's texture files, from this folder.
    Folder(PathBuf),
}

pub(super) fn lambertian(name: &str, albedo: [f64; 3]) -> MaterialEntry {
    MaterialEntry::new(name, MaterialKind::Lambertian, albedo)
}

pub(super) fn light(name: &str, emit: [f64; 3]) -> MaterialEntry {
    MaterialEntry::new(name, MaterialKind::DiffuseLight, emit)
}

pub(super) fn mirror(name: &str, albedo: [f64; 3]) -> MaterialEntry {
    MaterialEntry::new(name, MaterialKind::Mirror, albedo)
}

pub(super) fn dielectric(name: &str, albedo: [f64; 3], ior: f64) -> MaterialEntry {
    MaterialEntry {
        ior: Some(ior),
        ..MaterialEntry::new(name, MaterialKind::Dielectric, albedo)
    }
}

pub(super) fn metal(name: &str, albedo: [f64; 3], roughness: f64) -> MaterialEntry {
    MaterialEntry {
        roughness: Some(roughness),
        ..MaterialEntry::new(name, MaterialKind::Metal, albedo)
    }
}

/// A textured material (the course's `TextureColor`) of texture `texture`.
pub(super) fn textured(name: &str, texture: &str) -> MaterialEntry {
    MaterialEntry {
        texture: Some(texture.to_string()),
        ..MaterialEntry::new(name, MaterialKind::Textured, [1.0, 1.0, 1.0])
    }
}

/// A Phong or Blinn material, `kind`, as the course's constructor `(albedo, kd, ks, alpha)`.
pub(super) fn brdf(
    name: &str,
    kind: MaterialKind,
    albedo: [f64; 3],
    kd: f64,
    ks: f64,
    alpha: f64,
) -> MaterialEntry {
    MaterialEntry {
        kd: Some(kd),
        ks: Some(ks),
        alpha: Some(alpha),
        ..MaterialEntry::new(name, kind, albedo)
    }
}

fn texture(name: &str, kind: TextureKind) -> TextureEntry {
    TextureEntry {
        name: name.to_string(),
        kind,
        color: None,
        scale: None,
        even: None,
        odd: None,
        file: None,
        generated: None,
    }
}

pub(super) fn solid(name: &str, color: [f64; 3]) -> TextureEntry {
    TextureEntry {
        color: Some(color),
        ..texture(name, TextureKind::Solid)
    }
}

pub(super) fn checker(name: &str, scale: f64, even: [f64; 3], odd: [f64; 3]) -> TextureEntry {
    TextureEntry {
        scale: Some(scale),
        even: Some(even),
        odd: Some(odd),
        ..texture(name, TextureKind::Checker)
    }
}

/// The stems the course's texture files go by, for each picture a built-in scene uses.
const COURSE_FILES: &[(&str, &[&str])] = &[
    ("earth", &["earthmap"]),
    ("basketball", &["basketball"]),
    ("soccer", &["soccer"]),
    ("pepsi", &["pepsi"]),
];

/// The extensions looked for, in order: week 7's scenes read JPEGs (`earthmap.jpg`; week 8's
/// `earthmap.png` is the fallback).
const EXTENSIONS: &[&str] = &["jpg", "jpeg", "png", "JPG", "JPEG", "PNG"];

/// The image texture `name` showing the course's picture `picture` (one of the generated
/// pictures' names): generated, or the course's file found in the folder of `source` (the first
/// of its stems with a PNG or JPEG extension that exists there, as an absolute path).
pub(super) fn picture(
    scene: &str,
    name: &str,
    picture: &str,
    source: &TextureSource,
) -> Result<TextureEntry, SceneError> {
    let base = texture(name, TextureKind::Image);
    let dir = match source {
        TextureSource::Generated => {
            return Ok(TextureEntry {
                generated: Some(picture.to_string()),
                ..base
            });
        }
        TextureSource::Folder(dir) => dir,
    };
    let stems = COURSE_FILES
        .iter()
        .find(|(p, _)| *p == picture)
        .map_or(&[][..], |(_, stems)| *stems);
    let found = stems
        .iter()
        .flat_map(|stem| EXTENSIONS.iter().map(move |ext| format!("{stem}.{ext}")))
        .map(|file| dir.join(file))
        .find(|path| path.is_file());
    match found {
        Some(path) => {
            let path = std::path::absolute(&path).unwrap_or(path);
            Ok(TextureEntry {
                file: Some(path.display().to_string()),
                ..base
            })
        }
        None => Err(invalid(
            scene,
            format!(
                "--textures {}: no {} there (the course's {picture} texture)",
                dir.display(),
                stems
                    .iter()
                    .map(|s| format!("{s}.jpg or {s}.png"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

pub(super) fn sphere(center: [f64; 3], radius: f64, material: &str) -> ObjectEntry {
    ObjectEntry::Sphere {
        center,
        radius,
        material: material.to_string(),
        moving_center: None,
    }
}

pub(super) fn moving_sphere(
    center: [f64; 3],
    moving_center: [f64; 3],
    radius: f64,
    material: &str,
) -> ObjectEntry {
    ObjectEntry::Sphere {
        center,
        radius,
        material: material.to_string(),
        moving_center: Some(moving_center),
    }
}

pub(super) fn quad(q: [f64; 3], u: [f64; 3], v: [f64; 3], material: &str) -> ObjectEntry {
    ObjectEntry::Quad {
        q,
        u,
        v,
        material: material.to_string(),
    }
}

pub(super) fn triangle(a: [f64; 3], b: [f64; 3], c: [f64; 3], material: &str) -> ObjectEntry {
    ObjectEntry::Triangle {
        a,
        b,
        c,
        material: material.to_string(),
    }
}

/// The course's camera: vfov 90, focus distance 10, no defocus.
pub(super) fn course_camera(look_from: [f64; 3], look_at: [f64; 3]) -> CameraSettings {
    camera(look_from, look_at, 90.0, 10.0)
}

/// A pinhole camera with `vfov` and `focus_distance` (`up` is `(0, 1, 0)`).
pub(super) fn camera(
    look_from: [f64; 3],
    look_at: [f64; 3],
    vfov: f64,
    focus_distance: f64,
) -> CameraSettings {
    CameraSettings {
        look_from,
        look_at,
        up: [0.0, 1.0, 0.0],
        vfov,
        focus_distance,
        defocus_angle: 0.0,
    }
}
