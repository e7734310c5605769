//! The golden cache: goldens rendered once and kept on disk, keyed by what they were made from.
//!
//! Where: the folder [`cache_dir`] (`$RTORACLE_CACHE_DIR`, else `$XDG_CACHE_HOME/rtoracle`, else
//! `~/.cache/rtoracle`), in its `goldens/` folder. The key is the file's name ([`cache_file`]):
//!
//! ```text
//! goldens/<scene sha256>-<profile>[-in<inputs>]-f<format>-<spp>spp-<version>.exr
//! ```
//!
//! that is the scene's content ([`GoldenScene::content_key`]: the hash of its canonical TOML, the
//! profile, and a hash of the other files it reads when it reads any), the cache's format
//! ([`CACHE_FORMAT`]), the samples per pixel and the tool's version; the seed is always
//! [`super::GOLDEN_SEED`]. Editing the scene or a texture, asking another profile or sample
//! count, or upgrading rtoracle looks for another file.
//!
//! A file found under a key is used only if it is a golden of that scene with that sample count
//! and seed ([`GoldenScene::fits`], then the `rtoracle.spp` and `rtoracle.seed` attributes):
//! anything else there (a corrupt file, a file planted by hand, a golden of another version's
//! layout) is rendered again and replaced, never misread. Caches of older versions used other
//! names (`goldens/<sha256>-<spp>spp-<version>.exr`, `golden-<scene>-<spp>spp-<hash>.bin`) and
//! are never read.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use super::GOLDEN_SEED;
use super::format::GoldenRecord;
use super::source::GoldenScene;
use crate::image_io::{ExrImage, write_atomically};

/// The version of the cache's layout and key, part of every cache file's name: raised whenever
/// what a cached golden holds, or what its key means, changes (3: goldens carry the `deviation`
/// layer, the largest distance of a sample from the mean).
pub const CACHE_FORMAT: u32 = 3;

/// The folder rtoracle caches in: `$RTORACLE_CACHE_DIR`, else `$XDG_CACHE_HOME/rtoracle`, else
/// `$HOME/.cache/rtoracle` (empty variables count as unset); `None` when none is set.
pub fn cache_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("RTORACLE_CACHE_DIR")
        .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("rtoracle")))
        .or_else(|| env("HOME").map(|d| d.join(".cache").join("rtoracle")))
}

/// Where the cache in folder `dir` keeps the golden of `scene` with `spp` samples per pixel (see
/// the module docs).
pub fn cache_file(dir: &Path, scene: &GoldenScene, spp: u32) -> PathBuf {
    dir.join("goldens").join(format!(
        "{}-f{CACHE_FORMAT}-{spp}spp-{}.exr",
        scene.content_key(),
        env!("CARGO_PKG_VERSION")
    ))
}

/// One lock per cache file, so the members of a batch render each golden once.
pub(crate) fn key_lock(key: &Path) -> Arc<Mutex<()>> {
    static LOCKS: OnceLock<Mutex<HashMap<PathBuf, Arc<Mutex<()>>>>> = OnceLock::new();
    let mut locks = LOCKS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    Arc::clone(locks.entry(key.to_path_buf()).or_default())
}

/// The golden at `path` when it is one of `scene` with `spp` samples per pixel and the golden
/// seed: its bytes and image; `None` for a missing file and for anything else.
pub(crate) fn read_cached(
    path: &Path,
    scene: &GoldenScene,
    spp: u32,
) -> Option<(Vec<u8>, ExrImage)> {
    let bytes = std::fs::read(path).ok()?;
    let image = scene.fits(&bytes, path).ok()?;
    let record = GoldenRecord::of(&image);
    // A render asked for `spp` samples takes whole passes over the course's strata in a
    // jittered scene (`samples_taken`): its film, and so the golden, records those.
    let taken = crate::render::samples_taken(&scene.description.scene(), spp).0;
    (record.spp == Some(taken) && record.seed == Some(GOLDEN_SEED)).then_some((bytes, image))
}

/// Writes `bytes` to the cache file `path` atomically (a temporary file renamed into place, so
/// another process never reads half a golden), creating its folder; the error says why in one
/// line.
pub(crate) fn store(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let folder = path.parent().expect("a cache file is in goldens/");
    std::fs::create_dir_all(folder)
        .map_err(|e| format!("{}: cannot create the cache folder: {e}", folder.display()))?;
    write_atomically(path, bytes).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_file_is_named_by_its_key() {
        let dir = Path::new("/cache");
        let quad = GoldenScene::builtin("week04-quad").unwrap();
        let a = cache_file(dir, &quad, 4096);
        assert_eq!(
            a,
            dir.join("goldens").join(format!(
                "{}-course-f{CACHE_FORMAT}-4096spp-{}.exr",
                quad.scene_sha256(),
                env!("CARGO_PKG_VERSION")
            ))
        );
        assert_ne!(a, cache_file(dir, &quad, 8192));
        assert_ne!(
            a,
            cache_file(dir, &quad.clone().with_profile("physical"), 4096)
        );
        assert_ne!(
            a,
            cache_file(dir, &quad.clone().with_input("t.png", b"x"), 4096)
        );
        let mut moved = quad.clone();
        moved.description.objects.pop();
        assert_ne!(a, cache_file(dir, &moved, 4096));
        // The older layouts' names are never this version's.
        let old = dir.join("goldens").join(format!(
            "{}-4096spp-{}.exr",
            quad.scene_sha256(),
            env!("CARGO_PKG_VERSION")
        ));
        assert_ne!(a, old);
    }
}
