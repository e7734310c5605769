//! The goldens compiled into the library: `golden/<scene>.exr` of the built-in scenes that have
//! one, so an installed `rtoracle` has them without the source tree.
//!
//! The table is data, not a rule: a built-in scene missing from it (or whose golden here was
//! made from an older version of the scene, or has fewer samples than asked) still gets a golden,
//! rendered once into the cache by [`super::golden_of`].

use std::path::Path;

use super::format::golden_file_name;
use crate::image_io::{ExrImage, decode_exr};

/// The goldens compiled into the library, by scene name.
const EMBEDDED: &[(&str, &[u8])] = &[
    (
        "week04-sphere",
        include_bytes!("../../golden/week04-sphere.exr"),
    ),
    (
        "week04-quad",
        include_bytes!("../../golden/week04-quad.exr"),
    ),
    ("triangles", include_bytes!("../../golden/triangles.exr")),
    ("edge-cases", include_bytes!("../../golden/edge-cases.exr")),
    (
        "week05-quad",
        include_bytes!("../../golden/week05-quad.exr"),
    ),
    (
        "week05-quad-light",
        include_bytes!("../../golden/week05-quad-light.exr"),
    ),
    (
        "week05-point-light",
        include_bytes!("../../golden/week05-point-light.exr"),
    ),
    (
        "week05-point-light-shadow",
        include_bytes!("../../golden/week05-point-light-shadow.exr"),
    ),
    (
        "week06-mirror-point-light",
        include_bytes!("../../golden/week06-mirror-point-light.exr"),
    ),
    (
        "week06-mirrors",
        include_bytes!("../../golden/week06-mirrors.exr"),
    ),
    (
        "week06-dielectric",
        include_bytes!("../../golden/week06-dielectric.exr"),
    ),
    (
        "week07-procedural-texture",
        include_bytes!("../../golden/week07-procedural-texture.exr"),
    ),
    (
        "week07-earth",
        include_bytes!("../../golden/week07-earth.exr"),
    ),
    (
        "week08-phong",
        include_bytes!("../../golden/week08-phong.exr"),
    ),
    (
        "week08-blinn",
        include_bytes!("../../golden/week08-blinn.exr"),
    ),
    (
        "week09-blinn",
        include_bytes!("../../golden/week09-blinn.exr"),
    ),
    ("week10-dof", include_bytes!("../../golden/week10-dof.exr")),
    (
        "week10-moving",
        include_bytes!("../../golden/week10-moving.exr"),
    ),
    (
        "rtiow-materials",
        include_bytes!("../../golden/rtiow-materials.exr"),
    ),
    (
        "rtiow-defocus",
        include_bytes!("../../golden/rtiow-defocus.exr"),
    ),
];

/// The built-in scenes whose image depends on the samples per pixel (the course's jittered
/// sampling) with the counts the built-in rubrics render them at (`week_rubrics`): their
/// goldens at those counts are committed and compiled in too, as
/// `golden/<scene>.spp<N>.exr`, so grading them renders no golden.
pub const SPP_VARIANTS: &[(&str, u32)] = &[("week10-dof", 5), ("week10-moving", 5)];

/// The compiled-in goldens of [`SPP_VARIANTS`], in its order.
const EMBEDDED_VARIANTS: &[(&str, &str, &[u8])] = &[
    (
        "week10-dof",
        "week10-dof.spp5.exr",
        include_bytes!("../../golden/week10-dof.spp5.exr"),
    ),
    (
        "week10-moving",
        "week10-moving.spp5.exr",
        include_bytes!("../../golden/week10-moving.spp5.exr"),
    ),
];

/// The file name of the committed golden of `scene` at `spp` samples per pixel in
/// [`SPP_VARIANTS`]: `<scene>.spp<N>.exr`.
pub fn variant_file_name(scene: &str, spp: u32) -> String {
    format!("{scene}.spp{spp}.exr")
}

/// Every compiled-in golden of the built-in `scene`, as (file name, bytes): its own first, then
/// those of its [`SPP_VARIANTS`].
pub fn embedded_goldens(scene: &str) -> impl Iterator<Item = (String, &'static [u8])> + '_ {
    EMBEDDED
        .iter()
        .filter(move |(name, _)| *name == scene)
        .map(|(name, bytes)| (golden_file_name(name), *bytes))
        .chain(
            EMBEDDED_VARIANTS
                .iter()
                .filter(move |(name, _, _)| *name == scene)
                .map(|(_, file, bytes)| (file.to_string(), *bytes)),
        )
}

/// The names of the scenes whose golden is compiled in, in table order.
pub fn embedded_scenes() -> Vec<&'static str> {
    EMBEDDED.iter().map(|(name, _)| *name).collect()
}

/// The bytes of the committed golden of the built-in `scene`, compiled into the library
/// (`golden/<scene>.exr` when it was built), or `None` for a scene without one.
pub fn embedded_golden(scene: &str) -> Option<&'static [u8]> {
    EMBEDDED
        .iter()
        .find(|(name, _)| *name == scene)
        .map(|(_, bytes)| *bytes)
}

/// How an embedded golden is named in messages: `(embedded) golden/<scene>.exr`.
pub fn embedded_label(scene: &str) -> String {
    format!("(embedded) golden/{}", golden_file_name(scene))
}

/// The committed golden of the built-in `scene`, decoded.
pub fn embedded_golden_image(scene: &str) -> Option<ExrImage> {
    let bytes = embedded_golden(scene)?;
    let label = embedded_label(scene);
    Some(decode_exr(bytes, Path::new(&label)).expect("the embedded goldens are valid EXR files"))
}
