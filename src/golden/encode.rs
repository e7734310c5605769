//! A golden's bytes: the attributes the golden of a scene carries ([`super::format`] names
//! them) and the OpenEXR file that holds them with the film.

use std::path::Path;

use super::GoldenError;
use super::format::{
    ATTR_CAMERA, ATTR_DEVIATION, ATTR_INPUTS, ATTR_PROFILE, ATTR_SAMPLING, ATTR_SCENE,
    ATTR_SCENE_SHA256, ATTR_SCENE_TOML, ATTR_SEED, ATTR_SPP, ATTR_VARIANCE, ATTR_VERSION,
    CAMERA_CONVENTION, DEFAULT_PROFILE, DEVIATION_MEANING, SAMPLING, VARIANCE_MEANING,
    golden_file_name,
};
use super::source::GoldenScene;
use crate::image_io::encode_exr;
use crate::render::Film;

/// The string attributes of a golden of `scene` with `spp` samples per pixel and `seed`.
pub fn golden_attributes(scene: &GoldenScene, spp: u32, seed: u64) -> Vec<(String, String)> {
    let mut attributes = vec![
        (ATTR_SCENE, scene.name.clone()),
        (ATTR_SCENE_SHA256, scene.scene_sha256()),
        (ATTR_SPP, spp.to_string()),
        (ATTR_SEED, seed.to_string()),
        (ATTR_VERSION, env!("CARGO_PKG_VERSION").to_string()),
        (ATTR_CAMERA, CAMERA_CONVENTION.to_string()),
        (ATTR_SAMPLING, SAMPLING.to_string()),
        (ATTR_VARIANCE, VARIANCE_MEANING.to_string()),
        (ATTR_DEVIATION, DEVIATION_MEANING.to_string()),
    ];
    if scene.profile != DEFAULT_PROFILE {
        attributes.push((ATTR_PROFILE, scene.profile.clone()));
    }
    if !scene.inputs.is_empty() {
        attributes.push((ATTR_INPUTS, scene.inputs_text()));
    }
    if !scene.builtin {
        attributes.push((ATTR_SCENE_TOML, scene.description.to_toml()));
    }
    attributes
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
}

/// Encodes a film rendered for `scene` with `seed` as a golden file's bytes; `name` labels
/// errors.
pub(crate) fn encode_golden(
    film: &Film,
    scene: &GoldenScene,
    seed: u64,
) -> Result<Vec<u8>, GoldenError> {
    let attributes = golden_attributes(scene, film.samples_per_pixel, seed);
    Ok(encode_exr(
        film,
        &attributes,
        Path::new(&golden_file_name(&scene.name)),
    )?)
}
