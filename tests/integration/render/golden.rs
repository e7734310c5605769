//! The golden EXRs: insta snapshots, bit-determinism, OpenEXR's own reader, `rtoracle golden`.
//!
//! Snapshots: the two course scenes are regenerated at the goldens' full 4096 spp and kept as
//! insta binary snapshots equal to `golden/<scene>.exr`; `triangles` and `edge-cases` are
//! snapshotted at 256 spp (their 4096-spp renders would double this file's cost) and their
//! committed goldens are checked against that render with an exact bound (see
//! [`prefix_mean_bound`]). Review changed snapshots with `cargo insta review`, or accept them all
//! with `INSTA_UPDATE=always cargo test --test integration render::golden::`.

use std::path::{Path, PathBuf};
use std::process::Command;

use insta::internals::SnapshotContents;
use insta::{Comparator, Snapshot};
use rtoracle::golden::{
    ATTR_SCENE, ATTR_SCENE_SHA256, ATTR_SEED, ATTR_SPP, ATTR_VERSION, GOLDEN_SEED, GOLDEN_SPP,
    GoldenScene, Tolerance, compare_goldens, embedded_golden, embedded_scenes, golden_attributes,
    golden_file_name, render_golden, render_golden_bytes, scene_sha256,
};
use rtoracle::image_io::{ExrImage, decode_exr, encode_exr, read_exr};
use rtoracle::scene::{builtin, builtin_names};
use sha2::{Digest, Sha256};

use crate::common::*;

/// Decodes both binary snapshots as EXR and compares them with [`compare_goldens`] and the
/// default [`Tolerance`]; says why on stderr when they differ.
struct ExrComparator;

impl ExrComparator {
    fn decode(snapshot: &Snapshot, which: &str) -> Option<ExrImage> {
        match snapshot.contents() {
            SnapshotContents::Binary(Some(bytes)) => {
                match decode_exr(bytes, Path::new(&format!("{which} snapshot"))) {
                    Ok(image) => Some(image),
                    Err(e) => {
                        eprintln!("EXR snapshot comparison: {e}");
                        None
                    }
                }
            }
            _ => None,
        }
    }
}

impl Comparator for ExrComparator {
    fn matches(&self, reference: &Snapshot, test: &Snapshot) -> bool {
        let (Some(old), Some(new)) = (Self::decode(reference, "stored"), Self::decode(test, "new"))
        else {
            return false;
        };
        let diff = compare_goldens(&old, &new, &Tolerance::default());
        if !diff.is_match() {
            eprintln!(
                "EXR snapshot differs: {}",
                diff.summary(old.width * old.height)
            );
        }
        diff.is_match()
    }

    fn matches_fully(&self, reference: &Snapshot, test: &Snapshot) -> bool {
        reference.contents() == test.contents()
    }

    fn dyn_clone(&self) -> Box<dyn Comparator> {
        Box::new(ExrComparator)
    }
}

/// Asserts `bytes` (an EXR) against the binary snapshot `name` with [`ExrComparator`].
fn assert_exr_snapshot(name: &str, bytes: Vec<u8>) {
    insta::with_settings!({comparator => Box::new(ExrComparator)}, {
        insta::assert_binary_snapshot!(name, bytes);
    });
}

#[test]
fn exr_comparator_tells_pixels_from_bytes() {
    // Stored snapshots as insta loads them; copies with a changed pixel and a changed version.
    let dir = tempfile::tempdir().unwrap();
    let stored = snapshot_file("week04-sphere");
    let meta = stored.with_extension("");
    let image = read_exr(&stored).unwrap();
    let film_of = |img: &ExrImage| img.to_film(4096);
    let copy = |name: &str, img: &ExrImage| {
        let bytes = encode_exr(&film_of(img), &img.attributes, Path::new(name)).unwrap();
        let snap = dir.path().join(format!("{name}.snap"));
        std::fs::copy(&meta, &snap).unwrap();
        std::fs::write(dir.path().join(format!("{name}.snap.exr")), bytes).unwrap();
        Snapshot::from_file(&snap).unwrap()
    };
    let original = Snapshot::from_file(&meta).unwrap();
    let same = copy("same", &image);

    let mut tampered = image.clone();
    tampered.variance.as_mut().unwrap()[1000][2] += 1e-3;
    let tampered = copy("tampered", &tampered);

    let mut newer = image.clone();
    for (k, v) in &mut newer.attributes {
        if k == ATTR_VERSION {
            *v = "99.0.0".into();
        }
    }
    let newer = copy("newer", &newer);

    let c = ExrComparator;
    assert!(c.matches(&original, &same));
    assert!(
        c.matches_fully(&original, &same),
        "re-encoding gives the same bytes"
    );
    assert!(!c.matches(&original, &tampered));
    assert!(
        c.matches(&original, &newer),
        "only the tool version differs"
    );
    assert!(!c.matches_fully(&original, &newer));
}

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden")
}

fn snapshot_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/integration/render/snapshots")
        .join(format!("integration__render__golden__{name}.snap.exr"))
}

fn committed(scene: &str) -> ExrImage {
    read_exr(&golden_dir().join(golden_file_name(scene))).unwrap()
}

/// Asserts two images have bit-identical pixels (mean and variance) and the same identifying
/// attributes.
fn assert_same_pixels(expected: &ExrImage, actual: &ExrImage, what: &str) {
    assert_eq!(
        (expected.width, expected.height),
        (actual.width, actual.height),
        "{what}"
    );
    let bits = |v: &[[f32; 3]]| -> Vec<u32> { v.iter().flatten().map(|x| x.to_bits()).collect() };
    assert!(bits(&expected.mean) == bits(&actual.mean), "{what}: means");
    assert!(
        bits(expected.variance.as_ref().unwrap()) == bits(actual.variance.as_ref().unwrap()),
        "{what}: variances"
    );
    assert!(
        bits(expected.deviation.as_ref().unwrap()) == bits(actual.deviation.as_ref().unwrap()),
        "{what}: deviations"
    );
    for name in [ATTR_SCENE, ATTR_SCENE_SHA256, ATTR_SPP, ATTR_SEED] {
        assert_eq!(
            expected.attribute(name),
            actual.attribute(name),
            "{what}: {name}"
        );
    }
}

/// Regenerates a course golden at full spp, snapshots it, and checks it is the committed golden
/// bit for bit (rendered in another process, so also across hash seeds and thread schedules).
fn full_spp_snapshot(scene: &str) {
    let bytes = golden_bytes(scene, GOLDEN_SPP);
    let fresh = decode_exr(&bytes, Path::new("fresh")).unwrap();
    let file = committed(scene);
    assert_same_pixels(
        &file,
        &fresh,
        &format!("golden/{scene}.exr vs a fresh render"),
    );
    if file.attribute(ATTR_VERSION) == fresh.attribute(ATTR_VERSION) {
        let on_disk = std::fs::read(golden_dir().join(golden_file_name(scene))).unwrap();
        assert!(
            on_disk == bytes,
            "golden/{scene}.exr: same pixels but other bytes"
        );
    }
    assert_exr_snapshot(&format!("{scene}.exr"), bytes);
}

#[test]
fn snapshot_week04_sphere_at_4096_spp() {
    full_spp_snapshot("week04-sphere");
}

#[test]
fn snapshot_week04_quad_at_4096_spp() {
    full_spp_snapshot("week04-quad");
}

/// The largest possible `|mean of the first n samples - mean of all N|` given the mean and the
/// (n - 1)-normalised variance `s2` of all N: with deviations `d` summing to 0 and squares
/// summing to `Q = (N - 1) s2`, the sum over any n of them is at most `sqrt(Q n (N - n) / N)`
/// (Cauchy-Schwarz, reached by two constant groups). A hard bound, not a statistical one.
fn prefix_mean_bound(s2: f64, n: f64, big_n: f64) -> f64 {
    ((big_n - 1.0) * s2.max(0.0) * (big_n - n) / (n * big_n)).sqrt()
}

/// Snapshots a scene at 256 spp and checks the committed 4096-spp golden against it: the same
/// seed makes the 256 samples of each pixel the first 256 of the golden's 4096, so every
/// channel's mean must lie within [`prefix_mean_bound`] of the golden's (exactly equal where the
/// golden's variance is 0), up to the golden's f32 rounding.
fn reduced_spp_snapshot(scene: &str) {
    const N: u32 = 256;
    let description = builtin(scene).unwrap();
    let film = render_golden(&GoldenScene::builtin(scene).unwrap(), N, false).unwrap();
    let golden = committed(scene);
    assert_eq!(golden.attribute(ATTR_SPP), Some("4096"));
    assert_eq!(
        golden.attribute(ATTR_SCENE_SHA256),
        Some(scene_sha256(&description).as_str())
    );
    assert_eq!((golden.width, golden.height), (film.width, film.height));
    let variance = golden.variance.as_ref().unwrap();
    let mut flat_checked = 0;
    for (i, (m, (g, s2))) in film
        .mean
        .iter()
        .zip(golden.mean.iter().zip(variance))
        .enumerate()
    {
        for c in 0..3 {
            let bound = prefix_mean_bound(s2[c] as f64, N as f64, GOLDEN_SPP as f64);
            let gap = (m[c] - g[c] as f64).abs();
            assert!(
                gap <= bound * (1.0 + 1e-6) + 1e-6,
                "{scene} pixel {i} channel {c}: 256-spp mean {} vs golden {} (s2 {}), bound {bound}",
                m[c],
                g[c],
                s2[c]
            );
            if s2[c] == 0.0 {
                flat_checked += 1;
            }
        }
    }
    // Most pixels are flat, where the bound is exact equality.
    assert!(flat_checked > film.mean.len(), "{flat_checked}");
    let attributes = golden_attributes(&GoldenScene::builtin(scene).unwrap(), N, GOLDEN_SEED);
    let bytes = encode_exr(&film, &attributes, Path::new(scene)).unwrap();
    assert_exr_snapshot(&format!("{scene}-{N}spp.exr"), bytes);
}

#[test]
fn snapshot_triangles_at_256_spp_and_golden_bound() {
    reduced_spp_snapshot("triangles");
}

#[test]
fn snapshot_edge_cases_at_256_spp_and_golden_bound() {
    reduced_spp_snapshot("edge-cases");
}

#[test]
fn prefix_bound_is_tight_and_holds() {
    // Two groups: n samples at +a, N - n at -b with n a = (N - n) b: the bound is reached.
    let (n, big_n) = (3.0, 8.0);
    let (a, b) = (5.0 / 8.0, 3.0 / 8.0);
    let values: Vec<f64> = (0..8).map(|k| if k < 3 { a } else { -b }).collect();
    let mean_all = values.iter().sum::<f64>() / big_n;
    let s2 = values.iter().map(|v| (v - mean_all).powi(2)).sum::<f64>() / (big_n - 1.0);
    let prefix = values[..3].iter().sum::<f64>() / n;
    assert!((prefix_mean_bound(s2, n, big_n) - (prefix - mean_all).abs()).abs() < 1e-12);
}

#[test]
fn snapshots_are_the_golden_files() {
    // The same test the snapshot comparator makes (the snapshot tests check fresh renders against
    // both; this one says which pair to update when only the files were touched).
    for scene in ["week04-sphere", "week04-quad"] {
        let snap = read_exr(&snapshot_file(scene)).unwrap();
        let diff = compare_goldens(&committed(scene), &snap, &Tolerance::default());
        assert!(
            diff.is_match(),
            "golden/{scene}.exr vs its insta snapshot: {}; update both: `rtoracle golden`, then \
             `INSTA_UPDATE=always cargo test --test integration render::golden::`",
            diff.summary(snap.width * snap.height)
        );
    }
}

/// Every golden in `golden/` is compiled in, byte for byte, and is the golden of its built-in
/// scene as the scene is now (else the library would render it again at run time: a built-in
/// without a committed golden is still served, from the cache).
#[test]
fn embedded_goldens_are_the_files() {
    let mut files: Vec<String> = std::fs::read_dir(golden_dir())
        .unwrap()
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().to_string();
            name.strip_suffix(".exr").map(String::from)
        })
        .collect();
    files.sort();
    let mut embedded: Vec<String> = embedded_scenes().into_iter().map(String::from).collect();
    // With the goldens of the jittered scenes at the built-in rubrics' samples per pixel.
    for (scene, spp) in rtoracle::golden::SPP_VARIANTS {
        embedded.push(format!("{scene}.spp{spp}"));
        let file = std::fs::read(golden_dir().join(format!("{scene}.spp{spp}.exr"))).unwrap();
        assert!(
            rtoracle::golden::embedded_goldens(scene).any(|(_, b)| b == file.as_slice()),
            "{scene} at {spp} spp: the embedded golden is stale; rebuild"
        );
        let fits = GoldenScene::builtin_at_spp(scene, *spp)
            .unwrap()
            .fits(&file, Path::new(scene));
        assert!(fits.is_ok(), "{scene}.spp{spp}: {}", fits.unwrap_err());
    }
    embedded.sort();
    assert_eq!(
        files, embedded,
        "golden/*.exr and the embedded table differ"
    );
    for scene in embedded_scenes() {
        let file = std::fs::read(golden_dir().join(golden_file_name(scene))).unwrap();
        assert!(
            embedded_golden(scene) == Some(file.as_slice()),
            "{scene}: the embedded golden is stale; rebuild"
        );
        let fits = GoldenScene::builtin(scene)
            .unwrap()
            .fits(&file, Path::new(scene));
        assert!(fits.is_ok(), "golden/{scene}.exr: {}", fits.unwrap_err());
    }
    assert!(embedded_golden("no-such-scene").is_none());
}

/// The `deviation` layer against the variance, by two inequalities that hold for any `n`
/// numbers with unbiased variance `s2` and largest distance `d` from their mean: the largest
/// squared distance is at least the mean one, `d^2 >= s2 (n - 1) / n`, and at most Samuelson's
/// `d <= sqrt(s2) (n - 1) / sqrt(n)`; both up to the layers' f32 rounding (the deviation rounded
/// up, the variance and the mean to nearest).
fn assert_deviation_fits_the_variance(scene: &str, g: &ExrImage) {
    let deviation = g
        .deviation
        .as_ref()
        .unwrap_or_else(|| panic!("{scene}: no deviation layer"));
    let n: f64 = g.attribute(ATTR_SPP).unwrap().parse().unwrap();
    let variance = g.variance.as_ref().unwrap();
    for (i, (d, (s2, mu))) in deviation
        .iter()
        .zip(variance.iter().zip(&g.mean))
        .enumerate()
    {
        for c in 0..3 {
            let (d, s2, mu) = (d[c] as f64, s2[c] as f64, mu[c] as f64);
            let slack = 1e-6 * (1.0 + mu.abs() + d);
            assert!(
                d * d >= s2 * (n - 1.0) / n * (1.0 - 1e-6) - slack,
                "{scene} pixel {i} channel {c}: deviation {d} below the spread of variance {s2}"
            );
            assert!(
                d <= s2.sqrt() * (n - 1.0) / n.sqrt() * (1.0 + 1e-6) + slack,
                "{scene} pixel {i} channel {c}: deviation {d} beyond Samuelson's bound of {s2}"
            );
        }
    }
}

#[test]
fn goldens_have_the_documented_channels_and_attributes() {
    for scene in embedded_scenes() {
        let g = committed(scene);
        let d = builtin(scene).unwrap();
        let camera = d.camera(None);
        assert_eq!(
            (g.width, g.height),
            (camera.width, camera.height),
            "{scene}"
        );
        assert!(g.variance.is_some(), "{scene}");
        assert_deviation_fits_the_variance(scene, &g);
        assert_eq!(g.attribute(ATTR_SCENE), Some(scene));
        // 4096 samples, or under the course's jittered sampling (weeks 9 and 10) the whole
        // passes over its strata that hold at least 4096: less than one more pass of week 10's
        // 196 strata.
        let spp: u32 = g.attribute(ATTR_SPP).unwrap().parse().unwrap();
        assert!((4096..4096 + 196).contains(&spp), "{scene}: {spp}");
        assert_eq!(g.attribute(ATTR_SEED), Some("0"));
        assert_eq!(
            g.attribute("rtoracle.sampling")
                .map(|s| s.contains("[-0.5, 0.5)")),
            Some(true)
        );
        assert!(g.attribute("rtoracle.camera").is_some());
        assert!(g.attribute(ATTR_VERSION).is_some());
        // Under week 4's integrator means are colours of the scene (albedos and sky are in
        // [0, 1]) and variances of samples in [0, 1] are at most 1/4 * N/(N-1); the later weeks'
        // light adds up (render_weeks.rs checks their goldens).
        let v = g.variance.as_ref().unwrap();
        if !["week04-sphere", "week04-quad", "triangles", "edge-cases"].contains(&scene) {
            assert!(
                g.mean
                    .iter()
                    .chain(v)
                    .flatten()
                    .all(|x| x.is_finite() && *x >= 0.0)
            );
            continue;
        }
        assert!(g.mean.iter().flatten().all(|x| (0.0..=1.0).contains(x)));
        assert!(
            v.iter()
                .flatten()
                .all(|x| (0.0..=0.25 * 4096.0 / 4095.0 + 1e-6).contains(x))
        );
    }
}

#[test]
fn golden_bytes_do_not_depend_on_the_thread_count() {
    // 4 samples: rows split among threads as at any count (a jittered scene takes its strata's
    // one pass whatever is asked).
    for scene in builtin_names() {
        let with = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| golden_bytes(scene, 4))
        };
        let one = with(1);
        assert!(one == with(2), "{scene}: 1 vs 2 threads");
        assert!(one == with(3), "{scene}: 1 vs 3 threads");
        assert!(one == golden_bytes(scene, 4));
    }
}

#[test]
fn render_to_exr_reads_back_the_film_means() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &["render", "week04-quad", "-o", "x.exr", "--spp", "4"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let read = read_exr(&dir.path().join("x.exr")).unwrap();
    let d = builtin("week04-quad").unwrap();
    let film = rtoracle::render::render(
        &d.scene(),
        &d.camera(None),
        &rtoracle::render::RenderOptions {
            samples_per_pixel: 4,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((read.width, read.height), (400, 400));
    // f64 -> f32 is IEEE round-to-nearest, and EXR float channels store f32 exactly.
    for (a, b) in film.mean.iter().zip(&read.mean) {
        assert_eq!([a.x as f32, a.y as f32, a.z as f32], *b);
    }
    assert_eq!(read.attribute("rtoracle.scene"), Some("week04-quad"));
    assert_eq!(read.attribute("rtoracle.spp"), Some("4"));
}

// ---------------------------------------------------------------------------------------------
// OpenEXR's own library (Python bindings), when installed.

/// Whether `python3` can `import OpenEXR` (and numpy); says the test is skipped when not.
fn openexr_python(test: &str) -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import OpenEXR, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("skipped {test}: python3 cannot import OpenEXR (pip install OpenEXR)");
    }
    ok
}

fn python(script: &str, args: &[&str]) -> String {
    let out = Command::new("python3")
        .arg("-c")
        .arg(script)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// For each file: size, channels (type, shape, SHA-256 of the f32 little-endian samples,
/// row-major), string attributes, compression, line order, and the SHA-256 of `rtoracle scenes
/// --dump NAME` for the file's scene (hashlib, not rtoracle's hash).
const OPENEXR_INSPECT: &str = r#"
import hashlib, json, subprocess, sys
import numpy as np
import OpenEXR
exe = sys.argv[1]
out = {}
for path in sys.argv[2:]:
    with OpenEXR.File(path, separate_channels=True) as f:
        h = f.header()
        (x0, y0), (x1, y1) = h["dataWindow"]
        chans = {}
        for name, c in f.channels().items():
            px = np.ascontiguousarray(c.pixels).astype("<f4")
            chans[name] = {"dtype": str(c.pixels.dtype), "shape": list(c.pixels.shape),
                           "sha256": hashlib.sha256(px.tobytes()).hexdigest()}
        attrs = {k: v for k, v in h.items() if isinstance(v, str)}
        dump = subprocess.run([exe, "scenes", "--dump", attrs["rtoracle.scene"]],
                              capture_output=True, check=True).stdout
        out[path] = {"width": int(x1 - x0 + 1), "height": int(y1 - y0 + 1), "channels": chans,
                     "attributes": attrs, "compression": str(h["compression"]),
                     "lineOrder": str(h["lineOrder"]),
                     "dump_sha256": hashlib.sha256(dump).hexdigest()}
print(json.dumps(out))
"#;

fn sha256_of_channel(values: &[[f32; 3]], c: usize) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|p| p[c].to_le_bytes()).collect();
    Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn openexr_reads_the_goldens() {
    if !openexr_python("openexr_reads_the_goldens") {
        return;
    }
    let paths: Vec<String> = embedded_scenes()
        .iter()
        .map(|s| golden_dir().join(golden_file_name(s)).display().to_string())
        .collect();
    let mut args = vec![env!("CARGO_BIN_EXE_rtoracle")];
    args.extend(paths.iter().map(String::as_str));
    let report: serde_json::Value = serde_json::from_str(&python(OPENEXR_INSPECT, &args)).unwrap();
    for (scene, path) in embedded_scenes().into_iter().zip(&paths) {
        let r = &report[path.as_str()];
        let ours = read_exr(Path::new(path)).unwrap();
        assert_eq!(r["width"], ours.width, "{scene}");
        assert_eq!(r["height"], ours.height, "{scene}");
        let channels = r["channels"].as_object().unwrap();
        let mut names: Vec<&str> = channels.keys().map(String::as_str).collect();
        names.sort();
        assert_eq!(
            names,
            [
                "B",
                "G",
                "R",
                "deviation.B",
                "deviation.G",
                "deviation.R",
                "variance.B",
                "variance.G",
                "variance.R"
            ],
            "{scene}"
        );
        for (layer, values) in [
            ("", &ours.mean),
            ("variance.", ours.variance.as_ref().unwrap()),
            ("deviation.", ours.deviation.as_ref().unwrap()),
        ] {
            for (c, ch) in ["R", "G", "B"].into_iter().enumerate() {
                let info = &channels[&format!("{layer}{ch}")];
                assert_eq!(info["dtype"], "float32", "{scene} {layer}{ch}");
                assert_eq!(
                    info["shape"],
                    serde_json::json!([ours.height, ours.width]),
                    "{scene}"
                );
                assert_eq!(
                    info["sha256"].as_str().unwrap(),
                    sha256_of_channel(values, c),
                    "{scene} {layer}{ch}: OpenEXR decodes other pixels than rtoracle"
                );
            }
        }
        let attrs = r["attributes"].as_object().unwrap();
        for (k, v) in &ours.attributes {
            assert_eq!(attrs[k.as_str()], v.as_str(), "{scene} {k}");
        }
        assert_eq!(attrs["rtoracle.scene"], scene);
        assert_eq!(
            attrs["rtoracle.spp"].as_str(),
            ours.attribute("rtoracle.spp"),
            "{scene}"
        );
        assert_eq!(attrs["rtoracle.seed"], "0");
        assert_eq!(
            attrs["rtoracle.sceneSha256"], r["dump_sha256"],
            "{scene}: the hash is not SHA-256 of `rtoracle scenes --dump`"
        );
        assert!(r["lineOrder"].as_str().unwrap().contains("INCREASING"));
    }
}

#[test]
fn reader_accepts_files_written_by_openexr() {
    if !openexr_python("reader_accepts_files_written_by_openexr") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let script = r#"
import sys
import numpy as np
import OpenEXR
d = sys.argv[1]
h, w = 3, 4
y, x = np.mgrid[0:h, 0:w]
header = {"compression": OpenEXR.PIZ_COMPRESSION, "type": OpenEXR.scanlineimage}
rgba = np.stack([x / 4, y / 4, (x + y) / 8, np.ones((h, w))], axis=-1).astype("float16")
OpenEXR.File(header, {"RGBA": rgba}).write(d + "/rgba_half.exr")
rgb = np.stack([x / 4, y / 4, (x + y) / 8], axis=-1).astype("float32")
OpenEXR.File(header, {"RGB": rgb}).write(d + "/rgb_float.exr")
OpenEXR.File(header, {"R": rgb[:, :, 0].copy(), "G": rgb[:, :, 1].copy()}).write(d + "/rg.exr")
"#;
    python(script, &[dir.path().to_str().unwrap()]);
    for name in ["rgba_half.exr", "rgb_float.exr"] {
        let img = read_exr(&dir.path().join(name)).unwrap();
        assert_eq!((img.width, img.height), (4, 3), "{name}");
        assert!(img.variance.is_none());
        for y in 0..3 {
            for x in 0..4 {
                // All of these are multiples of 1/8 below 1: exact in half and float.
                let want = [x as f32 / 4.0, y as f32 / 4.0, (x + y) as f32 / 8.0];
                assert_eq!(img.mean[y * 4 + x], want, "{name} ({x}, {y})");
            }
        }
    }
    let err = read_exr(&dir.path().join("rg.exr"))
        .unwrap_err()
        .to_string();
    assert!(
        err.ends_with("rg.exr: has no R, G, B channels (it has G, R)"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// `rtoracle golden`.

fn stdout(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn golden_cli_writes_then_checks_equal() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "golden",
        "--dir",
        "g",
        "--spp",
        "2",
        "--scenes",
        "week04-quad,triangles",
    ];
    let out = run_in(dir.path(), &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout(&out).contains("wrote g/week04-quad.exr (2 spp, seed 0"));
    let written = std::fs::read(dir.path().join("g/triangles.exr")).unwrap();
    assert!(written == golden_bytes("triangles", 2));

    let mut check = args.to_vec();
    check.push("--check");
    let out = run_in(dir.path(), &check);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    assert!(stdout(&out).contains("g/week04-quad.exr: identical bytes"));
}

#[test]
fn golden_check_names_the_differing_pixel() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("g")).unwrap();
    // A golden of 2 spp with one value changed: pixel (17, 5), channel G.
    let bytes = golden_bytes("week04-quad", 2);
    let mut img = decode_exr(&bytes, Path::new("x")).unwrap();
    img.mean[5 * 400 + 17][1] += 0.25;
    let film = img.to_film(2);
    let tampered = encode_exr(&film, &img.attributes, Path::new("x")).unwrap();
    std::fs::write(dir.path().join("g/week04-quad.exr"), tampered).unwrap();
    let out = run_in(
        dir.path(),
        &[
            "golden",
            "--check",
            "--dir",
            "g",
            "--spp",
            "2",
            "--scenes",
            "week04-quad",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stdout(&out));
    let text = stdout(&out);
    assert!(text.contains("1 of 160000 pixels differ"), "{text}");
    assert!(text.contains("worst at x=17 y=5 G"), "{text}");

    // A golden made with other settings differs too.
    let out = run_in(
        dir.path(),
        &[
            "golden",
            "--check",
            "--dir",
            "g",
            "--spp",
            "3",
            "--scenes",
            "week04-quad",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    // The file (2 spp) is what is checked; the fresh render (3 spp) is what is expected.
    assert!(stdout(&out).contains("rtoracle.spp is '2' but '3' was expected"));
}

#[test]
fn golden_check_rejects_unreadable_files() {
    let dir = tempfile::tempdir().unwrap();
    let g = dir.path().join("g");
    std::fs::create_dir(&g).unwrap();
    let check = [
        "golden",
        "--check",
        "--dir",
        "g",
        "--spp",
        "1",
        "--scenes",
        "week04-quad",
    ];

    let out = run_in(dir.path(), &check);
    assert_bad_input(&out, "g/week04-quad.exr: cannot read");

    std::fs::write(g.join("week04-quad.exr"), "P3\n1 1\n255\n0 0 0\n").unwrap();
    let out = run_in(dir.path(), &check);
    assert_bad_input(&out, "g/week04-quad.exr: is not an OpenEXR file");

    let good = golden_bytes("week04-quad", 1);
    std::fs::write(g.join("week04-quad.exr"), &good[..good.len() / 3]).unwrap();
    let out = run_in(dir.path(), &check);
    assert_bad_input(
        &out,
        "g/week04-quad.exr: is a truncated or damaged OpenEXR file",
    );
}

#[test]
fn golden_cli_rejects_bad_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["golden", "--spp", "0"]);
    assert_bad_input(&out, "'0' for '--spp");
    let out = run_in(dir.path(), &["golden", "--scenes", "week04-quad,nope"]);
    assert_bad_input(&out, "--scenes nope: no such built-in scene");
    std::fs::write(dir.path().join("file"), "").unwrap();
    let out = run_in(
        dir.path(),
        &[
            "golden",
            "--dir",
            "file",
            "--spp",
            "1",
            "--scenes",
            "week04-quad",
        ],
    );
    assert_bad_input(&out, "file");
    assert!(!dir.path().join("file/week04-quad.exr").exists());
}

/// The bytes of a fresh golden of the built-in `scene` at `spp`.
fn golden_bytes(scene: &str, spp: u32) -> Vec<u8> {
    render_golden_bytes(&GoldenScene::builtin(scene).unwrap(), spp, false).unwrap()
}
