//! Scenes: materials, objects, the course's camera, TOML scene files and the built-in scenes.

mod builtin;
mod camera;
mod file;
mod material;
mod object;

pub use builtin::{BUILTIN_SCENES, BuiltinScene, builtin, builtin_names};
pub use camera::{Camera, CameraSettings};
pub use file::{
    ImageSettings, MaterialEntry, MaterialKind, ObjectEntry, SceneDescription, SceneError,
};
pub use material::Material;
pub use object::{Object, Scene, SceneObject};
