//! The golden file: an OpenEXR image of the per-pixel mean and per-sample variance, and the
//! string attributes that say what it was made from.
//!
//! Every golden carries [`ATTR_SCENE`], [`ATTR_SCENE_SHA256`], [`ATTR_SPP`], [`ATTR_SEED`],
//! [`ATTR_VERSION`] and the four descriptions ([`ATTR_CAMERA`], [`ATTR_SAMPLING`],
//! [`ATTR_VARIANCE`], [`ATTR_DEVIATION`]). Three more are written only when they say something beyond the defaults,
//! so that the goldens of the built-in scenes keep their bytes:
//! - [`ATTR_PROFILE`], when the profile is not [`DEFAULT_PROFILE`] (absent: that profile);
//! - [`ATTR_INPUTS`], when the scene reads other files (absent: none);
//! - [`ATTR_SCENE_TOML`], the scene itself, when it is not a built-in scene (a built-in is named
//!   by [`ATTR_SCENE`] and checked by its hash), so a golden of a scene file says its scene's
//!   samples per pixel and can be checked against it with nothing else at hand.
//!
//! A reader takes an absent optional attribute as its default, so an older golden reads as what
//! it is: a golden of the default profile, of a scene that reads no other file.

use crate::image_io::ExrImage;

/// The attribute naming the scene (a built-in's name, or the scene file's name).
pub const ATTR_SCENE: &str = "rtoracle.scene";
/// The attribute holding the SHA-256 (lower-case hex) of the scene's canonical TOML
/// ([`crate::scene::SceneDescription::to_toml`]).
pub const ATTR_SCENE_SHA256: &str = "rtoracle.sceneSha256";
/// The attribute holding the samples per pixel.
pub const ATTR_SPP: &str = "rtoracle.spp";
/// The attribute holding the seed.
pub const ATTR_SEED: &str = "rtoracle.seed";
/// The attribute holding the version of rtoracle that wrote the file.
pub const ATTR_VERSION: &str = "rtoracle.version";
/// The attribute describing the camera convention.
pub const ATTR_CAMERA: &str = "rtoracle.camera";
/// The attribute describing how samples were placed in a pixel.
pub const ATTR_SAMPLING: &str = "rtoracle.sampling";
/// The attribute describing the `variance` layer.
pub const ATTR_VARIANCE: &str = "rtoracle.variance";
/// The attribute describing the `deviation` layer.
pub const ATTR_DEVIATION: &str = "rtoracle.deviation";
/// The attribute naming the profile the golden was rendered in; absent: [`DEFAULT_PROFILE`].
pub const ATTR_PROFILE: &str = "rtoracle.profile";
/// The attribute listing the other files the scene read (textures), one `SHA256  NAME` line
/// each, sorted by name; absent: none.
pub const ATTR_INPUTS: &str = "rtoracle.inputs";
/// The attribute holding the scene's canonical TOML, for goldens of scenes that are not
/// built-in.
pub const ATTR_SCENE_TOML: &str = "rtoracle.sceneToml";

/// The profile a golden is rendered in when none is named: what a correct submission of the
/// course computes.
pub const DEFAULT_PROFILE: &str = "course";

/// The camera convention written into every golden.
pub const CAMERA_CONVENTION: &str = "course (Ray Tracing in One Weekend, 4th edition): pinhole at \
look_from, vertical field of view vfov in degrees, row 0 at the top; the centre of pixel (i, j) is \
pixel00 + i * pixel_delta_u + j * pixel_delta_v";

/// The sampling written into every golden.
pub const SAMPLING: &str = "uniform jitter in [-0.5, 0.5) of a pixel around its centre, \
independently per sample (x then y), from a PCG64 stream per pixel seeded by (seed, pixel index)";

/// What the `variance` layer holds, written into every golden.
pub const VARIANCE_MEANING: &str = "per-sample variance of each channel (Welford's update in f64, \
divided by n - 1), rounded to f32; the variance of the mean is this divided by rtoracle.spp";

/// What the `deviation` layer holds, written into every golden.
pub const DEVIATION_MEANING: &str = "per channel, the largest |sample - mean| of the pixel's \
samples (the mean as the R, G, B channels hold it before rounding), rounded up to f32: a measured \
bound on how far one sample of the scene lands from the pixel's mean";

/// Name of the golden file of `scene`: `<scene>.exr`.
pub fn golden_file_name(scene: &str) -> String {
    format!("{scene}.exr")
}

/// What a golden's attributes say it was made from (each `None` when the attribute is absent or
/// unreadable).
#[derive(Clone, Debug, PartialEq)]
pub struct GoldenRecord {
    /// [`ATTR_SCENE`].
    pub scene: Option<String>,
    /// [`ATTR_SCENE_SHA256`].
    pub scene_sha256: Option<String>,
    /// [`ATTR_SPP`], when it is a count.
    pub spp: Option<u32>,
    /// [`ATTR_SEED`], when it is a number.
    pub seed: Option<u64>,
    /// [`ATTR_PROFILE`], or [`DEFAULT_PROFILE`] when absent.
    pub profile: String,
    /// [`ATTR_INPUTS`], or empty when absent.
    pub inputs: String,
    /// [`ATTR_SCENE_TOML`].
    pub scene_toml: Option<String>,
}

impl GoldenRecord {
    /// Reads the attributes of `image`.
    pub fn of(image: &ExrImage) -> Self {
        let text = |name: &str| image.attribute(name).map(str::to_string);
        GoldenRecord {
            scene: text(ATTR_SCENE),
            scene_sha256: text(ATTR_SCENE_SHA256),
            spp: image
                .attribute(ATTR_SPP)
                .and_then(|s| s.trim().parse().ok()),
            seed: image
                .attribute(ATTR_SEED)
                .and_then(|s| s.trim().parse().ok()),
            profile: text(ATTR_PROFILE).unwrap_or_else(|| DEFAULT_PROFILE.to_string()),
            inputs: text(ATTR_INPUTS).unwrap_or_default(),
            scene_toml: text(ATTR_SCENE_TOML),
        }
    }
}
