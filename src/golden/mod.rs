//! Golden images: the reference's high-sample renders that candidates are judged against, for
//! every scene, built-in or file, made one way.
//!
//! A golden is an OpenEXR file (`format`): the scene rendered by [`crate::render::render`] at
//! its own size with `M` samples per pixel and seed [`GOLDEN_SEED`], holding the per-pixel mean
//! (`R`, `G`, `B`), the per-sample variance of each channel (the `variance` layer), and string
//! attributes saying what it was made from. Its bytes depend only on the scene, the samples per
//! pixel, the seed and the tool version: not on the machine or its number of threads
//! ([`crate::image_io::encode_exr`]).
//!
//! What a golden is made from is a [`GoldenScene`] (`source.rs`): the scene, the profile it is
//! rendered in, and the content of every other file it reads. [`golden_of`] gives the golden of
//! any of them with at least `M` samples per pixel, used by `compare`, `grade`, `golden FILE.toml`
//! and `autograder` alike:
//! 1. a built-in scene's golden compiled into the library (`embedded.rs`), when it was made from
//!    the scene as it is now and has enough samples;
//! 2. else the one in the cache (`cache.rs`: `<cache folder>/goldens/`, keyed by the scene's
//!    content, the profile, the samples per pixel, the cache's format and the tool version; the
//!    key and the folder are documented there), when it is a golden of this scene;
//! 3. else rendered now (one line on stderr says so, with indicatif's bar when stderr is a
//!    terminal) and written into the cache atomically.
//!
//! `M` for a candidate of `N` samples per pixel is [`golden_spp`]`(N) = max(4096, 100 N)`. The
//! committed goldens of the built-in scenes (`golden/*.exr`, [`GOLDEN_SPP`]) are written and
//! checked by `rtoracle golden`, which renders them fresh ([`render_golden_bytes`]) and compares
//! pixels with [`compare_goldens`] (`diff.rs`); the test suite keeps them as insta snapshots.

mod format;
mod diff;
mod embedded;
mod source;
mod cache;
mod encode;

use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

pub use cache::{CACHE_FORMAT, cache_dir, cache_file};
pub use diff::{GoldenDiff, PixelDifference, Tolerance, compare_goldens};
pub use embedded::{
    SPP_VARIANTS, embedded_golden, embedded_golden_image, embedded_goldens, embedded_scenes,
    variant_file_name,
};
pub use encode::golden_attributes;
pub use format::{
    ATTR_CAMERA, ATTR_DEVIATION, ATTR_INPUTS, ATTR_PROFILE, ATTR_SAMPLING, ATTR_SCENE,
    ATTR_SCENE_SHA256, ATTR_SCENE_TOML, ATTR_SEED, ATTR_SPP, ATTR_VARIANCE, ATTR_VERSION,
    CAMERA_CONVENTION, DEFAULT_PROFILE, DEVIATION_MEANING, GoldenRecord, SAMPLING,
    VARIANCE_MEANING, golden_file_name,
};
pub use source::{
    GoldenInput, GoldenMisfit, GoldenScene, at_spp, files_read, golden_fits, scene_sha256,
    sha256_hex,
};

use crate::image_io::{ExrImage, ImageError, decode_exr};
use crate::render::{Film, PixelJitter, RenderError, RenderOptions, render};
use crate::scene::SceneError;

/// Samples per pixel of the committed goldens, and the least of any golden.
pub const GOLDEN_SPP: u32 = 4096;

/// The seed of every golden's per-pixel random streams (committed, cached or rendered).
pub const GOLDEN_SEED: u64 = 0;

/// Samples per pixel of the golden for candidates with `candidate_spp`: `max(4096, 100 N)`.
pub fn golden_spp(candidate_spp: u32) -> u32 {
    GOLDEN_SPP.max(candidate_spp.saturating_mul(100))
}

/// What goes wrong making, reading or checking a golden (one line).
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// The scene is not a built-in one, or its file cannot be read.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The render was refused.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The EXR could not be written or read.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A file the scene reads cannot be read.
    #[error("{}: {message}", path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

static RENDERS: AtomicUsize = AtomicUsize::new(0);

/// How many goldens this process has rendered ([`render_golden`]; a golden found embedded or in
/// the cache renders none).
pub fn golden_renders() -> usize {
    RENDERS.load(Ordering::Relaxed)
}

/// Renders `scene` as a golden: its own size, `spp` samples per pixel, [`GOLDEN_SEED`], uniform
/// jitter, with the per-sample variance, on rayon's current pool (the film does not depend on
/// its size). `progress` shows indicatif's bar on stderr when it is a terminal.
pub fn render_golden(scene: &GoldenScene, spp: u32, progress: bool) -> Result<Film, GoldenError> {
    let options = RenderOptions {
        samples_per_pixel: spp,
        seed: GOLDEN_SEED,
        variance: true,
        jitter: PixelJitter::Uniform,
        progress,
    };
    RENDERS.fetch_add(1, Ordering::Relaxed);
    let description = &scene.description;
    Ok(render(
        &description.scene(),
        &description.camera(None),
        &options,
    )?)
}

/// The bytes of a freshly rendered golden of `scene` with `spp` samples per pixel
/// ([`render_golden`], encoded with [`golden_attributes`]).
pub fn render_golden_bytes(
    scene: &GoldenScene,
    spp: u32,
    progress: bool,
) -> Result<Vec<u8>, GoldenError> {
    let film = render_golden(scene, spp, progress)?;
    encode::encode_golden(&film, scene, GOLDEN_SEED)
}

/// Where a golden [`golden_of`] gave came from.
#[derive(Clone, Debug, PartialEq)]
pub enum GoldenOrigin {
    /// Compiled into the library.
    Embedded,
    /// Read from this cache file.
    Cached(PathBuf),
    /// Rendered by this call, and written to the cache file when there is one.
    Rendered {
        /// The cache file written, or `None` when there is no cache folder or it could not be
        /// written (the golden was rendered for this process only).
        cached: Option<PathBuf>,
        /// Why it was not cached, when it was not.
        warning: Option<String>,
    },
}

/// A golden [`golden_of`] gave.
#[derive(Clone, Debug, PartialEq)]
pub struct FoundGolden {
    /// The EXR's bytes.
    pub bytes: Vec<u8>,
    /// The EXR, decoded.
    pub image: ExrImage,
    /// How it names its file in messages: the cache file, or `(embedded) golden/<scene>.exr`.
    pub source: PathBuf,
    /// Where it came from.
    pub origin: GoldenOrigin,
}

impl FoundGolden {
    /// Whether this call rendered it.
    pub fn rendered(&self) -> bool {
        matches!(self.origin, GoldenOrigin::Rendered { .. })
    }
}

/// The golden of `scene` with at least `spp` samples per pixel: embedded, cached or rendered now
/// (see the module docs), with the cache in folder `cache` (`None`: no cache, always render;
/// [`cache_dir`] is the usual one). `progress`: say in one line on stderr when a golden is
/// rendered (and when it cannot be cached), and show indicatif's bar on a terminal.
///
/// Within a process, callers asking for the same golden wait for the first one's render instead
/// of rendering again; across processes, two may render the same golden at the same time, and
/// both write the same bytes.
pub fn golden_of(
    scene: &GoldenScene,
    spp: u32,
    cache: Option<&std::path::Path>,
    progress: bool,
) -> Result<FoundGolden, GoldenError> {
    if let Some(found) = embedded_of(scene, spp) {
        return Ok(found);
    }
    let path = cache.map(|dir| cache_file(dir, scene, spp));
    let lock = path.as_deref().map(cache::key_lock);
    let _held = lock
        .as_ref()
        .map(|l| l.lock().unwrap_or_else(|e| e.into_inner()));
    if let Some(path) = &path {
        if let Some((bytes, image)) = cache::read_cached(path, scene, spp) {
            // The key is the content: a file of the same content under another name gets its
            // golden with its own name, the bytes a fresh render of it would have.
            let (bytes, image) = if image.attribute(ATTR_SCENE) == Some(scene.name.as_str()) {
                (bytes, image)
            } else {
                let bytes = encode::encode_golden(&image.to_film(spp), scene, GOLDEN_SEED)?;
                let image = decode_exr(&bytes, path)?;
                (bytes, image)
            };
            return Ok(FoundGolden {
                bytes,
                image,
                source: path.clone(),
                origin: GoldenOrigin::Cached(path.clone()),
            });
        }
    }
    if progress {
        let camera = scene.description.camera(None);
        crate::output::stderr_line(&format!(
            "rendering the golden of {} ({}x{}, {spp} spp), once per cache{}",
            crate::escape::terminal_line(&scene.name),
            camera.width,
            camera.height,
            path.as_ref().map_or(String::new(), |p| format!(
                ": {}",
                crate::escape::terminal_line(&p.display().to_string())
            ))
        ));
    }
    let bytes = render_golden_bytes(scene, spp, progress)?;
    let (source, origin) = match &path {
        None => (
            PathBuf::from(golden_file_name(&scene.name)),
            GoldenOrigin::Rendered {
                cached: None,
                warning: Some(
                    "no cache folder (set RTORACLE_CACHE_DIR, XDG_CACHE_HOME or HOME)".to_string(),
                ),
            },
        ),
        Some(p) => match cache::store(p, &bytes) {
            Ok(()) => (
                p.clone(),
                GoldenOrigin::Rendered {
                    cached: Some(p.clone()),
                    warning: None,
                },
            ),
            Err(why) => (
                PathBuf::from(golden_file_name(&scene.name)),
                GoldenOrigin::Rendered {
                    cached: None,
                    warning: Some(why),
                },
            ),
        },
    };
    if let (
        true,
        GoldenOrigin::Rendered {
            warning: Some(why), ..
        },
    ) = (progress, &origin)
    {
        crate::output::stderr_line(&format!(
            "warning: the golden of {} is not cached ({}); it is rendered again next time",
            crate::escape::terminal_line(&scene.name),
            crate::escape::terminal_line(why)
        ));
    }
    let image = decode_exr(&bytes, &source)?;
    Ok(FoundGolden {
        bytes,
        image,
        source,
        origin,
    })
}

/// The embedded golden of a built-in `scene` when it was made from the scene as it is now (hash,
/// profile, inputs) and has at least `spp` samples per pixel.
fn embedded_of(scene: &GoldenScene, spp: u32) -> Option<FoundGolden> {
    if !scene.builtin {
        return None;
    }
    embedded::embedded_goldens(&scene.name).find_map(|(file, bytes)| {
        let source = PathBuf::from(format!("(embedded) golden/{file}"));
        let image = scene.fits(bytes, &source).ok()?;
        let record = GoldenRecord::of(&image);
        if record.spp? < spp || record.seed != Some(GOLDEN_SEED) {
            return None;
        }
        Some(FoundGolden {
            bytes: bytes.to_vec(),
            image,
            source,
            origin: GoldenOrigin::Embedded,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    fn tiny_scene(radius: f64) -> GoldenScene {
        let mut d = builtin("week04-sphere").unwrap();
        d.image.width = 8;
        if let crate::scene::ObjectEntry::Sphere { radius: r, .. } = &mut d.objects[1] {
            *r = radius;
        }
        GoldenScene::from_description("tiny.toml", d, None).unwrap()
    }

    #[test]
    fn golden_spp_follows_the_rule() {
        assert_eq!(golden_spp(1), 4096);
        assert_eq!(golden_spp(20), 4096);
        assert_eq!(golden_spp(41), 4100);
        assert_eq!(golden_spp(100), 10_000);
        assert_eq!(golden_spp(u32::MAX), u32::MAX);
    }

    /// The course's goldens serve candidates of up to 40 spp from the library; above that, a
    /// golden of more samples is rendered (and with no cache, not kept).
    #[test]
    fn built_in_goldens_come_embedded_while_they_have_enough_samples() {
        for name in ["week04-sphere", "week04-quad"] {
            let scene = GoldenScene::builtin(name).unwrap();
            let found = golden_of(&scene, golden_spp(40), None, false).unwrap();
            assert_eq!(found.origin, GoldenOrigin::Embedded);
            assert_eq!(found.bytes, embedded_golden(name).unwrap());
            assert_eq!(found.image.attribute(ATTR_SCENE), Some(name));
            // The same scene as a file is not the built-in: its golden is its own.
            let as_file = GoldenScene {
                builtin: false,
                ..scene.clone()
            };
            assert!(embedded_of(&as_file, 4096).is_none());
            // Another profile, or a texture, is another golden.
            assert!(embedded_of(&scene.clone().with_profile("physical"), 4096).is_none());
            assert!(embedded_of(&scene.clone().with_input("t.png", b"x"), 4096).is_none());
            assert!(embedded_of(&scene, golden_spp(41)).is_none());
        }
    }

    /// A built-in scene changed since its golden was embedded (here: made smaller, as a new
    /// scene without an embedded golden would be) gets one rendered into the cache, once.
    #[test]
    fn a_built_in_without_a_fitting_embedded_golden_is_rendered_into_the_cache() {
        let dir = tempfile::tempdir().unwrap();
        let mut scene = GoldenScene::builtin("week04-quad").unwrap();
        scene.description.image.width = 6;
        let first = golden_of(&scene, 3, Some(dir.path()), false).unwrap();
        assert!(first.rendered());
        let path = cache_file(dir.path(), &scene, 3);
        assert_eq!(
            first.origin,
            GoldenOrigin::Rendered {
                cached: Some(path.clone()),
                warning: None
            }
        );
        let again = golden_of(&scene, 3, Some(dir.path()), false).unwrap();
        assert_eq!(again.origin, GoldenOrigin::Cached(path));
        assert_eq!(again.bytes, first.bytes);
        // A built-in's golden names the scene and holds no TOML; a scene file's holds it.
        assert_eq!(first.image.attribute(ATTR_SCENE), Some("week04-quad"));
        assert!(first.image.attribute(ATTR_SCENE_TOML).is_none());
    }

    /// A jittered scene asked for a count that is not a whole number of passes over its strata
    /// (week 10's 200 spp take 14 x 14 = 196 a pass, so 20 000 take 20 188) records the samples
    /// it took, and is found in the cache the next time, not rendered again.
    #[test]
    fn a_jittered_golden_of_more_samples_than_asked_is_found_in_the_cache() {
        let dir = tempfile::tempdir().unwrap();
        let mut scene = GoldenScene::builtin("week10-moving").unwrap();
        scene.description.image.width = 4;
        let first = golden_of(&scene, 201, Some(dir.path()), false).unwrap();
        assert!(first.rendered());
        assert_eq!(GoldenRecord::of(&first.image).spp, Some(2 * 196));
        let again = golden_of(&scene, 201, Some(dir.path()), false).unwrap();
        assert_eq!(
            again.origin,
            GoldenOrigin::Cached(cache_file(dir.path(), &scene, 201))
        );
        assert_eq!(again.bytes, first.bytes);
    }

    #[test]
    fn the_cache_renders_each_golden_once_even_when_asked_concurrently() {
        let dir = tempfile::tempdir().unwrap();
        let d = tiny_scene(0.5);
        let results: Vec<FoundGolden> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| s.spawn(|| golden_of(&d, 4, Some(dir.path()), false)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap().unwrap())
                .collect()
        });
        assert_eq!(results.iter().filter(|r| r.rendered()).count(), 1);
        let path = cache_file(dir.path(), &d, 4);
        assert!(results.iter().all(|r| r.source == path));
        let on_disk = std::fs::read(&path).unwrap();
        assert!(results.iter().all(|r| r.bytes == on_disk));
        // The file is the golden of this scene and of no other.
        assert!(d.fits(&on_disk, &path).is_ok());
        let other = tiny_scene(0.3);
        let e = other.fits(&on_disk, &path).unwrap_err();
        assert!(matches!(e, GoldenMisfit::OtherScene { .. }), "{e}");
        assert!(e.to_string().contains("another scene"), "{e}");
        let mut wider = d.clone();
        wider.description.image.width = 9;
        let e = wider.fits(&on_disk, &path).unwrap_err();
        assert!(
            matches!(
                e,
                GoldenMisfit::Size {
                    found: (8, _),
                    expected: (9, _)
                }
            ),
            "{e}"
        );
        assert!(e.to_string().starts_with("is 8x"), "{e}");
        let e = d
            .clone()
            .with_profile("physical")
            .fits(&on_disk, &path)
            .unwrap_err();
        assert!(e.to_string().contains("course profile"), "{e}");
        let e = d
            .clone()
            .with_input("t.png", b"x")
            .fits(&on_disk, &path)
            .unwrap_err();
        assert!(matches!(e, GoldenMisfit::OtherInputs { .. }), "{e}");
        assert!(e.to_string().contains("other files"), "{e}");
        // A scene file's golden holds the scene.
        let image = decode_exr(&on_disk, &path).unwrap();
        assert_eq!(
            image.attribute(ATTR_SCENE_TOML),
            Some(d.description.to_toml().as_str())
        );
        assert_ne!(cache_file(dir.path(), &other, 4), path);
        // The same content under another name: the cached golden, named as asked, and the
        // bytes a fresh render of it would have.
        let renamed = GoldenScene {
            name: "renamed.toml".into(),
            ..d.clone()
        };
        let found = golden_of(&renamed, 4, Some(dir.path()), false).unwrap();
        assert_eq!(found.origin, GoldenOrigin::Cached(path.clone()));
        assert_eq!(found.image.attribute(ATTR_SCENE), Some("renamed.toml"));
        assert!(found.bytes == render_golden_bytes(&renamed, 4, false).unwrap());
    }

    /// Whatever lies under a key that is not this scene's golden with this many samples is
    /// rendered again and replaced, never used: junk, the older `.bin` cache's format, a golden
    /// of another scene, of another sample count, of another profile, or one whose scene reads
    /// other files; and a golden left under an older version's name is never read.
    #[test]
    fn a_wrong_or_old_cache_file_is_rendered_again_never_misread() {
        let dir = tempfile::tempdir().unwrap();
        let scene = tiny_scene(0.5);
        let path = cache_file(dir.path(), &scene, 4);
        let right = render_golden_bytes(&scene, 4, false).unwrap();
        let other = tiny_scene(0.3);
        let mut old_bin = b"rtoracle golden cache v1\n".to_vec();
        old_bin.extend_from_slice(&[8, 0, 0, 0, 5, 0, 0, 0, 4, 0, 0, 0]);
        old_bin.extend(std::iter::repeat_n(0u8, 8 * 5 * 24));
        let planted: Vec<(&str, Vec<u8>)> = vec![
            ("junk", b"junk".to_vec()),
            ("the older .bin format", old_bin),
            (
                "another scene",
                render_golden_bytes(&other, 4, false).unwrap(),
            ),
            (
                "another spp",
                render_golden_bytes(&scene, 5, false).unwrap(),
            ),
            (
                "another profile",
                render_golden_bytes(&scene.clone().with_profile("physical"), 4, false).unwrap(),
            ),
            (
                "other inputs",
                render_golden_bytes(&scene.clone().with_input("t.png", b"x"), 4, false).unwrap(),
            ),
        ];
        for (what, bytes) in planted {
            store_at(&path, &bytes);
            let found = golden_of(&scene, 4, Some(dir.path()), false).unwrap();
            assert!(found.rendered(), "{what} was used");
            assert_eq!(found.bytes, right, "{what}");
            assert_eq!(
                std::fs::read(&path).unwrap(),
                right,
                "{what} was not replaced"
            );
        }
        // The previous version's cache named its goldens `<scene sha256>-<spp>spp-<version>.exr`
        // (and the one before wrote `.bin` files): a file under such a name is never looked at.
        std::fs::remove_file(&path).unwrap();
        let old_name = dir.path().join("goldens").join(format!(
            "{}-4spp-{}.exr",
            scene.scene_sha256(),
            env!("CARGO_PKG_VERSION")
        ));
        store_at(&old_name, &right);
        let before = golden_renders();
        assert!(
            golden_of(&scene, 4, Some(dir.path()), false)
                .unwrap()
                .rendered()
        );
        assert!(golden_renders() > before);
    }

    fn store_at(path: &std::path::Path, bytes: &[u8]) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }

    #[test]
    fn without_a_cache_the_golden_is_rendered_and_says_why_it_is_not_kept() {
        let scene = tiny_scene(0.5);
        let found = golden_of(&scene, 2, None, false).unwrap();
        match found.origin {
            GoldenOrigin::Rendered {
                cached: None,
                warning: Some(w),
            } => assert!(w.contains("RTORACLE_CACHE_DIR"), "{w}"),
            other => panic!("{other:?}"),
        }
        // A cache folder that cannot be made: rendered, with the reason.
        let file = tempfile::NamedTempFile::new().unwrap();
        let found = golden_of(&scene, 2, Some(file.path()), false).unwrap();
        match found.origin {
            GoldenOrigin::Rendered {
                cached: None,
                warning: Some(w),
            } => assert!(w.contains("cannot create the cache folder"), "{w}"),
            other => panic!("{other:?}"),
        }
    }
}
