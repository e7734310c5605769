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
];

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
