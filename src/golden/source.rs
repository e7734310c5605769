//! What a golden is made from: a scene ([`GoldenScene`]), the profile it is rendered in, and the
//! content of every other file the scene reads (a texture's bytes, by their SHA-256).
//!
//! Two goldens are the same golden exactly when these agree (with the samples per pixel, the
//! seed and the tool version): the cache's key ([`GoldenScene::content_key`]) and the check of
//! a golden against its scene ([`GoldenScene::fits`]) both read them here, in one place.
//!
//! The files a scene reads are listed by [`files_read`]: the one function to extend when scene
//! descriptions gain fields that name files (image textures), so that editing a texture makes a
//! new golden without any change to the cache.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::GoldenError;
use super::format::{
    ATTR_INPUTS, ATTR_PROFILE, ATTR_SCENE_SHA256, ATTR_SCENE_TOML, DEFAULT_PROFILE, GoldenRecord,
};
use crate::image_io::{ExrImage, decode_exr};
use crate::scene::{SceneDescription, builtin};

/// Lower-case hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Lower-case hex SHA-256 of the scene's canonical TOML ([`SceneDescription::to_toml`]).
pub fn scene_sha256(description: &SceneDescription) -> String {
    sha256_hex(description.to_toml().as_bytes())
}

/// The files `description` reads besides itself (its image textures' files), as it names them:
/// relative to the scene file's folder unless absolute, in the order of its `[[textures]]`. A
/// field that names a file must be listed here, so that its content enters every golden's key
/// ([`GoldenScene::inputs`]); the destructuring below fails to compile when a field is added.
pub fn files_read(description: &SceneDescription) -> Vec<PathBuf> {
    let SceneDescription {
        profile: _,
        image: _,
        camera: _,
        render: _,
        textures,
        materials: _,
        objects: _,
        base_dir: _,
    } = description;
    textures
        .iter()
        .filter_map(|t| t.file.as_deref())
        .map(PathBuf::from)
        .collect()
}

/// `description` with `spp` samples per pixel when its image depends on them (the course's
/// jittered sampling) and they differ from its own; `None` when it does not change.
pub fn at_spp(description: &SceneDescription, spp: u32) -> Option<SceneDescription> {
    let jittered = description.render.sampling == crate::scene::PixelSampling::CourseJittered;
    (jittered && description.image.samples_per_pixel != spp).then(|| {
        let mut d = description.clone();
        d.image.samples_per_pixel = spp;
        d
    })
}

/// One file a scene reads, by content.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct GoldenInput {
    /// The file as the scene names it (`textures/earthmap.jpg`).
    pub name: String,
    /// Lower-case hex SHA-256 of its bytes.
    pub sha256: String,
}

/// A scene to make (or find) the golden of, with everything its render depends on.
#[derive(Clone, Debug, PartialEq)]
pub struct GoldenScene {
    /// The name written into the golden ([`super::ATTR_SCENE`]): a built-in's name, or the
    /// scene file's name.
    pub name: String,
    /// The scene.
    pub description: SceneDescription,
    /// Whether this is the built-in scene `name` as it is built in (its embedded golden may
    /// serve, and the golden names the scene rather than holding its TOML).
    pub builtin: bool,
    /// The profile the golden is rendered in ([`DEFAULT_PROFILE`] unless another is asked for).
    pub profile: String,
    /// The other files the scene reads, by content, sorted by name.
    pub inputs: Vec<GoldenInput>,
}

impl GoldenScene {
    /// The built-in scene `name`.
    pub fn builtin(name: &str) -> Result<Self, GoldenError> {
        let description = builtin(name)?;
        let mut scene = Self::from_description(name, description, None)?;
        scene.builtin = true;
        Ok(scene)
    }

    /// The built-in scene `name` as a candidate of `spp` samples per pixel renders it: the
    /// scene itself, except that a scene of the course's jittered sampling (weeks 9 and 10,
    /// whose strata, and whose division of their sum, come from the scene's
    /// `samples_per_pixel`) has `spp` as its `samples_per_pixel`, since its image depends on it.
    pub fn builtin_at_spp(name: &str, spp: u32) -> Result<Self, GoldenError> {
        let mut scene = Self::builtin(name)?;
        if let Some(d) = at_spp(&scene.description, spp) {
            scene.description = d;
        }
        Ok(scene)
    }

    /// The scene file at `path`, named by its file name, with the files it reads (resolved
    /// against its folder) hashed.
    pub fn from_file(path: &Path) -> Result<Self, GoldenError> {
        let description = SceneDescription::from_file(path)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_else(|| path.display().to_string());
        Self::from_description(&name, description, path.parent())
    }

    /// A scene already read, named `name`; the files it reads are resolved against `folder` (the
    /// scene file's) and hashed, and one it cannot read is an error naming it.
    pub fn from_description(
        name: &str,
        description: SceneDescription,
        folder: Option<&Path>,
    ) -> Result<Self, GoldenError> {
        let mut scene = GoldenScene {
            name: name.to_string(),
            profile: description.profile.name().to_string(),
            description,
            builtin: false,
            inputs: Vec::new(),
        };
        for file in files_read(&scene.description) {
            let path = match folder {
                Some(dir) if file.is_relative() => dir.join(&file),
                _ => file.clone(),
            };
            let bytes = std::fs::read(&path).map_err(|e| GoldenError::Input {
                path: path.clone(),
                message: format!("cannot read this file the scene {name} reads: {e}"),
            })?;
            scene = scene.with_input(&file.to_string_lossy(), &bytes);
        }
        Ok(scene)
    }

    /// The same scene rendered in `profile` (the scene's own profile too, when `profile` names
    /// one the renderer knows).
    pub fn with_profile(mut self, profile: &str) -> Self {
        self.profile = profile.to_string();
        if let Some(known) = crate::scene::Profile::from_name(profile) {
            self.description.profile = known;
        }
        self
    }

    /// The same scene reading one more file, `name`, whose content is `bytes` (a texture given
    /// from elsewhere, say a submission's `textures/` folder). A name given twice keeps the
    /// last content.
    pub fn with_input(mut self, name: &str, bytes: &[u8]) -> Self {
        self.inputs.retain(|i| i.name != name);
        self.inputs.push(GoldenInput {
            name: name.to_string(),
            sha256: sha256_hex(bytes),
        });
        self.inputs.sort();
        self
    }

    /// SHA-256 of the scene's canonical TOML ([`super::ATTR_SCENE_SHA256`]).
    pub fn scene_sha256(&self) -> String {
        scene_sha256(&self.description)
    }

    /// The [`super::ATTR_INPUTS`] text: one `SHA256  NAME` line per input (as `sha256sum`
    /// prints), sorted by name; empty when the scene reads no other file.
    pub fn inputs_text(&self) -> String {
        self.inputs
            .iter()
            .map(|i| format!("{}  {}\n", i.sha256, i.name.replace('\n', " ")))
            .collect()
    }

    /// The part of the cache key that is the golden's content: the scene's hash, then the
    /// profile, then (when the scene reads other files) the first 16 hex digits of the SHA-256
    /// of [`GoldenScene::inputs_text`], joined by `-`. Names never contain `/`.
    pub fn content_key(&self) -> String {
        let profile: String = self
            .profile
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut key = format!("{}-{profile}", self.scene_sha256());
        if !self.inputs.is_empty() {
            key.push_str("-in");
            key.push_str(&sha256_hex(self.inputs_text().as_bytes())[..16]);
        }
        key
    }

    /// Checks that EXR `bytes` (read from `source`) are a golden of this scene: an EXR with a
    /// `variance` layer, the scene's size, its hash in `rtoracle.sceneSha256`, the same profile
    /// and the same other files (their hashes). The error says which, in one line without the
    /// file name.
    pub fn fits(&self, bytes: &[u8], source: &Path) -> Result<ExrImage, GoldenMisfit> {
        let image = decode_exr(bytes, source).map_err(|e| {
            let text = e.to_string();
            let prefix = format!("{}: ", source.display());
            GoldenMisfit::Unreadable(text.strip_prefix(&prefix).map(String::from).unwrap_or(text))
        })?;
        self.fits_image(&image)?;
        Ok(image)
    }

    /// [`GoldenScene::fits`] of an image already decoded.
    pub fn fits_image(&self, image: &ExrImage) -> Result<(), GoldenMisfit> {
        let camera = self.description.camera(None);
        if (image.width, image.height) != (camera.width, camera.height) {
            return Err(GoldenMisfit::Size {
                found: (image.width, image.height),
                expected: (camera.width, camera.height),
            });
        }
        let record = GoldenRecord::of(image);
        // The profile is part of the scene's text too: say it first, as the more telling reason.
        if record.profile != self.profile {
            return Err(GoldenMisfit::Profile {
                found: record.profile,
                expected: self.profile.clone(),
            });
        }
        let want = self.scene_sha256();
        match &record.scene_sha256 {
            Some(h) if *h == want => {}
            Some(h) => {
                return Err(GoldenMisfit::OtherScene {
                    found: h.clone(),
                    expected: want,
                });
            }
            None => return Err(GoldenMisfit::NoSceneHash),
        }
        if let Some(toml) = &record.scene_toml {
            if sha256_hex(toml.as_bytes()) != want {
                return Err(GoldenMisfit::SceneTextMismatch);
            }
        }
        if record.inputs != self.inputs_text() {
            return Err(GoldenMisfit::OtherInputs {
                found: record.inputs.trim_end().replace('\n', "; "),
                expected: self.inputs_text().trim_end().replace('\n', "; "),
            });
        }
        if image.variance.is_none() {
            return Err(GoldenMisfit::NoVariance);
        }
        Ok(())
    }
}

/// Why an EXR is not the golden of a scene ([`GoldenScene::fits`]): each says what differs, in
/// one line that goes after the file's name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GoldenMisfit {
    /// It is not a readable EXR (the decoder's reason).
    #[error("{0}")]
    Unreadable(String),
    /// Its size is not the scene's.
    #[error("is {}x{} but the scene is {}x{}", .found.0, .found.1, .expected.0, .expected.1)]
    Size {
        /// The image's width and height.
        found: (usize, usize),
        /// The scene's.
        expected: (usize, usize),
    },
    /// It was rendered in another profile.
    #[error(
        "was rendered in the {found} profile ({}), not {expected}",
        ATTR_PROFILE
    )]
    Profile {
        /// The image's profile.
        found: String,
        /// The scene's.
        expected: String,
    },
    /// Its scene hash is another scene's.
    #[error(
        "was made from another scene ({} {found}, but the scene's is {expected})",
        ATTR_SCENE_SHA256
    )]
    OtherScene {
        /// The image's scene hash.
        found: String,
        /// The scene's.
        expected: String,
    },
    /// It records no scene hash.
    #[error("has no {} attribute", ATTR_SCENE_SHA256)]
    NoSceneHash,
    /// The scene text it holds does not hash to the scene hash it records.
    #[error(
        "holds a scene ({}) whose hash is not its {}",
        ATTR_SCENE_TOML,
        ATTR_SCENE_SHA256
    )]
    SceneTextMismatch,
    /// It was made from other files than the scene reads.
    #[error(
        "was made from other files than the scene reads ({} '{found}', but the scene's are '{expected}')",
        ATTR_INPUTS
    )]
    OtherInputs {
        /// The image's files and hashes, one `; ` apart.
        found: String,
        /// The scene's.
        expected: String,
    },
    /// It has no variance layer.
    #[error("has no 'variance' layer")]
    NoVariance,
}

/// Checks that EXR `bytes` (read from `source`) are a golden of `description`, a scene that reads
/// no other file, in the default profile ([`GoldenScene::fits`]).
pub fn golden_fits(
    bytes: &[u8],
    source: &Path,
    description: &SceneDescription,
) -> Result<ExrImage, GoldenMisfit> {
    let scene = GoldenScene {
        name: String::new(),
        description: description.clone(),
        builtin: false,
        profile: DEFAULT_PROFILE.to_string(),
        inputs: Vec::new(),
    };
    scene.fits(bytes, source)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_hash_is_sha256_of_the_toml() {
        // Published test vectors (FIPS 180-2): "" and "abc".
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let d = builtin("week04-quad").unwrap();
        let h = scene_sha256(&d);
        assert_eq!(h, sha256_hex(d.to_toml().as_bytes()));
        assert_ne!(h, scene_sha256(&builtin("week04-sphere").unwrap()));
    }

    /// The key follows the scene, the profile and every other file's content, and nothing else.
    #[test]
    fn the_content_key_follows_scene_profile_and_inputs() {
        let quad = GoldenScene::builtin("week04-quad").unwrap();
        let key = quad.content_key();
        assert_eq!(key, format!("{}-course", quad.scene_sha256()));
        assert_eq!(
            key,
            GoldenScene::from_description("q.toml", quad.description.clone(), None)
                .unwrap()
                .content_key(),
            "the name is not part of the content"
        );
        let physical = quad.clone().with_profile("physical");
        assert_eq!(
            physical.content_key(),
            format!("{}-physical", physical.scene_sha256())
        );
        assert_ne!(
            physical.content_key(),
            key,
            "another profile is another golden"
        );
        let textured = quad.clone().with_input("textures/earth.png", b"one");
        let retextured = quad.clone().with_input("textures/earth.png", b"two");
        assert!(textured.content_key().starts_with(&key));
        assert_ne!(textured.content_key(), key);
        assert_ne!(textured.content_key(), retextured.content_key());
        // The same files given in another order are the same inputs.
        let ab = quad
            .clone()
            .with_input("a.png", b"a")
            .with_input("b.png", b"b");
        let ba = quad
            .clone()
            .with_input("b.png", b"b")
            .with_input("a.png", b"a");
        assert_eq!(ab.content_key(), ba.content_key());
        assert_eq!(
            ab.inputs_text(),
            format!("{}  a.png\n{}  b.png\n", sha256_hex(b"a"), sha256_hex(b"b"))
        );
        // A profile name cannot leave the cache folder.
        assert!(!quad.with_profile("../x").content_key().contains('/'));
    }

    #[test]
    fn the_scenes_of_this_version_read_no_other_file() {
        for name in crate::scene::builtin_names() {
            assert!(files_read(&builtin(name).unwrap()).is_empty());
            assert!(GoldenScene::builtin(name).unwrap().inputs.is_empty());
        }
    }
}
