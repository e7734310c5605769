//! Scenes: materials, textures, objects, the course's camera, TOML scene files, the built-in
//! scenes, and the [`World`] a render reads.
//!
//! A scene file ([`SceneDescription`]) states a profile (how it is rendered: as the course or as
//! *Ray Tracing in One Weekend*), the image, the camera, the integrator's settings, textures,
//! materials and objects; [`SceneDescription::scene`] turns it into a [`World`].
//! [`to_mitsuba_xml`] writes one for Mitsuba 3 where the two renderers share the physics.

mod camera;
mod error;
mod profile;
mod settings;
mod texture;
mod material;
mod object;
mod accel;
mod world;
mod description;
mod builtin;

pub use accel::bvh::BVH_MIN_OBJECTS;
#[cfg(test)]
pub(crate) use accel::shape_lanes::skipped_without_lanes;
pub(crate) use accel::shape_lanes::{LANES, RayLanes, has_lanes};
#[cfg(target_arch = "x86_64")]
pub(crate) use accel::shape_lanes::{between as lanes_between, splat as lanes_splat};
pub(crate) use accel::shape_set::ShapeSet;
pub use builtin::{
    BUILTIN_SCENES, BuiltinScene, TextureSource, builtin, builtin_names, builtin_with_textures,
    rtiow_final_scene,
};
pub use camera::{Camera, CameraSettings};
pub use description::mitsuba::{MitsubaError, to_mitsuba_xml};
pub use description::validate::{MAX_DEPTH_LIMIT, MAX_SIDE};
pub use description::{
    ImageSettings, MaterialEntry, MaterialKind, ObjectEntry, SceneDescription, TextureEntry,
    TextureKind,
};
pub use error::SceneError;
pub use material::Material;
pub use object::{Object, Scene, SceneObject};
pub use profile::Profile;
pub use settings::{
    Background, COURSE_BACKGROUND, DEFAULT_MAX_DEPTH, DiffuseSampling, DirectTerm, Integrator,
    PixelSampling, RenderSettings,
};
pub use texture::{
    GENERATED_PICTURES, PictureError, RgbPicture, Texture, TextureImage, generated_picture,
    read_picture,
};
pub use world::{PointLight, World};
