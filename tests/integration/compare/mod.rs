//! The noise-aware comparison: honest renders pass (measured false-failure rate), every
//! mistake of IMAGES.md fails and the diagnosis names it, the course's PNGs pass, bad input
//! exits 2 without leaving files behind.

mod report;
mod two;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use rayon::prelude::*;
use rtoracle::compare::diagnose::mistakes::{MUST_FAIL, Mistake, render_with_mistake};
use rtoracle::compare::{
    CompareOptions, Comparison, candidate::CandidateImage, compare_image, noise_model::Golden,
};
use rtoracle::image_io::Rgb8Image;
use rtoracle::render::{PixelJitter, RenderOptions, render};

use crate::common::*;

const COURSE_SCENES: [&str; 2] = ["week04-sphere", "week04-quad"];

/// The golden of a course scene: the one embedded in the binary (4096 spp, seed 0; the
/// candidates below use other seeds), decoded once per test process.
fn golden(scene: &str) -> &'static Golden {
    static SPHERE: OnceLock<Golden> = OnceLock::new();
    static QUAD: OnceLock<Golden> = OnceLock::new();
    let cell = match scene {
        "week04-sphere" => &SPHERE,
        "week04-quad" => &QUAD,
        _ => panic!("no test golden for {scene}"),
    };
    cell.get_or_init(|| {
        let scene = rtoracle::golden::GoldenScene::builtin(scene).unwrap();
        let found = rtoracle::golden::golden_of(&scene, 4096, None, false).unwrap();
        assert_eq!(found.origin, rtoracle::golden::GoldenOrigin::Embedded);
        Golden::from_exr_image(found.image, &found.source).unwrap()
    })
}

fn candidate(img: Rgb8Image) -> CandidateImage {
    CandidateImage::Rgb8 {
        width: img.width,
        height: img.height,
        data: img.data,
    }
}

fn compare(scene: &str, img: Rgb8Image) -> Comparison {
    compare_image(&candidate(img), golden(scene), &CompareOptions::default()).unwrap()
}

fn smallest_p(results: &[Comparison], scale: usize) -> f64 {
    results
        .iter()
        .map(|c| c.scales[scale].smallest_adjusted_p)
        .fold(1.0, f64::min)
}

/// 200 honest renders per course scene at 20 spp with different seeds, and 20 with stratified
/// jitter, all pass. With a per-image false-failure rate of 1e-4, one failure in 440 would
/// already be a 4% event; the smallest adjusted p per scale is printed for the record.
#[test]
fn honest_renders_pass_at_every_seed() {
    for scene in COURSE_SCENES {
        let d = rtoracle::scene::builtin(scene).unwrap();
        let g = golden(scene);
        let uniform: Vec<Comparison> = (1..=200u64)
            .into_par_iter()
            .map(|seed| compare(scene, render_with_mistake(&d, Mistake::Honest, 20, seed)))
            .collect();
        let stratified: Vec<Comparison> = (1..=20u64)
            .into_par_iter()
            .map(|seed| {
                let film = render(
                    &d.scene(),
                    &d.camera(None),
                    &RenderOptions {
                        samples_per_pixel: 20,
                        seed: 1000 + seed,
                        jitter: PixelJitter::Stratified,
                        ..Default::default()
                    },
                )
                .unwrap();
                compare_image(
                    &CandidateImage::Rgb8 {
                        width: film.width,
                        height: film.height,
                        data: film.to_course_rgb8(),
                    },
                    g,
                    &CompareOptions::default(),
                )
                .unwrap()
            })
            .collect();
        for (kind, results) in [("uniform", &uniform), ("stratified", &stratified)] {
            let failed: Vec<usize> = results
                .iter()
                .enumerate()
                .filter(|(_, c)| !c.passed())
                .map(|(i, _)| i + 1)
                .collect();
            eprintln!(
                "{scene} {kind}: {} renders, {} failed; smallest adjusted p: pixel {:.3e}, tile8 {:.3e}, tile32 {:.3e}, global {:.3e}; largest |z| at the pixel scale {:.2}",
                results.len(),
                failed.len(),
                smallest_p(results, 0),
                smallest_p(results, 1),
                smallest_p(results, 2),
                smallest_p(results, 3),
                results
                    .iter()
                    .map(|c| c.scales[0].largest_abs_z)
                    .fold(0.0, f64::max),
            );
            assert!(failed.is_empty(), "{scene} {kind}: seeds {failed:?} failed");
        }
        // The noise is that of 20 samples: the estimated effective spp is near 20 (the
        // estimate pools thousands of noisy pixels; 12..32 allows for its own spread).
        let mean_neff = uniform
            .iter()
            .map(|c| c.effective_spp.unwrap())
            .sum::<f64>()
            / uniform.len() as f64;
        assert!((12.0..32.0).contains(&mean_neff), "{scene}: {mean_neff}");
    }
}

/// Every mistake IMAGES.md lists fails on both course scenes, including the half-pixel shift
/// and jitter in [0, 1), and the diagnosis names the mistake for those it tests.
#[test]
fn every_must_fail_mistake_fails_and_is_diagnosed() {
    let expected = |m: Mistake| match m {
        Mistake::NoGamma => Some("encoding:linear"),
        Mistake::Gamma22 => Some("encoding:gamma22"),
        Mistake::GammaTwice => Some("encoding:gamma-twice"),
        Mistake::YFlipped => Some("flip-y"),
        Mistake::Bgr => Some("bgr"),
        Mistake::HalfPixelShift => Some("shift:-0.5"),
        Mistake::JitterZeroOne => Some("shift:+0.5"),
        _ => None,
    };
    for scene in COURSE_SCENES {
        let d = rtoracle::scene::builtin(scene).unwrap();
        let results: Vec<(Mistake, Comparison)> = MUST_FAIL
            .par_iter()
            .map(|&m| (m, compare(scene, render_with_mistake(&d, m, 20, 77))))
            .collect();
        for (m, c) in results {
            assert!(!c.passed(), "{scene}: '{}' passed", m.name());
            assert!(
                !c.regions.is_empty(),
                "{scene}: '{}' has no region",
                m.name()
            );
            let diagnosis = c.diagnosis.as_ref().expect("a failing image is diagnosed");
            eprintln!("{scene}: {} -> {}", m.name(), diagnosis.summary);
            if let Some(name) = expected(m) {
                assert_eq!(
                    diagnosis.best.as_deref(),
                    Some(name),
                    "{scene}: '{}' diagnosed as {:?}",
                    m.name(),
                    diagnosis.summary
                );
                // The named hypothesis makes the image pass outright.
                assert!(diagnosis.hypotheses[0].passes, "{scene}: {}", m.name());
            } else if m == Mistake::WiderFov {
                // A wider field of view is a zoom (fitted: named, passing or not).
                let best = diagnosis.best.as_deref().unwrap_or_default();
                assert!(best.starts_with("zoom:"), "{scene}: {}", diagnosis.summary);
            } else if m == Mistake::AlbedoScaled {
                // Albedos scaled but not the sky: a uniform scale at best, never another mistake.
                let best = diagnosis.best.as_deref().unwrap_or("scale:");
                assert!(best.starts_with("scale:"), "{scene}: {}", diagnosis.summary);
            } else {
                // Mistakes outside the catalogue of hypotheses are not explained away.
                assert!(
                    diagnosis.best.is_none() || !diagnosis.hypotheses[0].passes,
                    "{scene}: '{}' explained as {}",
                    m.name(),
                    diagnosis.summary
                );
            }
        }
    }
}

/// A render mirrored left to right is named "x flipped" where the scene is not symmetric, and
/// passes where it is. The course's sphere scene looks the same in a mirror (a metamorphic
/// relation, not a value from our own output): its spheres at x = -1 and x = 1 have the same
/// albedo, the others are centred on x = 0, the camera looks down -z with y up, and the only
/// asymmetry, the hollow inside the left sphere, is behind a diffuse surface no ray crosses.
/// The quad scene's left and right quads are red and blue.
#[test]
fn a_mirrored_render_is_diagnosed_x_flipped_unless_the_scene_is_symmetric() {
    for scene in COURSE_SCENES {
        let d = rtoracle::scene::builtin(scene).unwrap();
        let c = compare(scene, render_with_mistake(&d, Mistake::XFlipped, 20, 41));
        if scene == "week04-sphere" {
            assert!(
                c.passed(),
                "{scene}: a mirror image of a symmetric scene failed"
            );
            continue;
        }
        assert!(!c.passed(), "{scene}: a mirrored render passed");
        let diagnosis = c.diagnosis.as_ref().unwrap();
        assert_eq!(
            diagnosis.best.as_deref(),
            Some("flip-x"),
            "{scene}: {}",
            diagnosis.summary
        );
        assert!(diagnosis.hypotheses[0].passes, "{scene}");
        assert!(
            diagnosis.summary.contains("x flipped"),
            "{}",
            diagnosis.summary
        );
    }
    // And a y-flipped render is not taken for a mirrored one.
    let d = rtoracle::scene::builtin("week04-quad").unwrap();
    let c = compare(
        "week04-quad",
        render_with_mistake(&d, Mistake::YFlipped, 20, 41),
    );
    assert_eq!(c.diagnosis.unwrap().best.as_deref(), Some("flip-y"));
}

/// The half-pixel shift is found where it is: in boxes along the objects' edges, not over the
/// flat inside of the back quad, and by the tiles (edge pixels at 20 spp are too noisy for the
/// pixel scale alone).
#[test]
fn a_half_pixel_shift_is_located_on_the_edges() {
    let d = rtoracle::scene::builtin("week04-quad").unwrap();
    let c = compare(
        "week04-quad",
        render_with_mistake(&d, Mistake::HalfPixelShift, 20, 5),
    );
    assert!(!c.passed());
    assert!(c.scales[2].failing > 0);
    assert_eq!(c.scales[0].failing, 0, "{:?}", c.scales[0]);
    // Boxes follow the edges: none is larger than 32x32.
    for r in &c.regions {
        assert!(r.width <= 32 && r.height <= 32, "{r:?}");
    }
    // The back quad spans x, y in [-2, 2] at z = 0, 10 units from the eye with a 20-unit
    // viewport: pixels 160..240. Its centre is flat, right, and in no failing region.
    let centre = 200 * c.width + 200;
    assert_eq!(c.z_map[centre], [0.0; 3]);
    assert!(
        c.regions
            .iter()
            .all(|r| !(r.x <= 200 && 200 < r.x + r.width && r.y <= 200 && 200 < r.y + r.height))
    );
}

fn course_png(dir: &Path, name: &str) -> CandidateImage {
    CandidateImage::load(&dir.join(name)).unwrap()
}

/// The course's published PNGs (rendered by its Python code, unseeded) pass.
#[test]
#[cfg_attr(
    not(rtoracle_course_fixtures),
    ignore = "set RTORACLE_COURSE_FIXTURES to the course's published images to run it"
)]
fn the_course_pngs_pass() {
    let Some(dir) = course_fixtures("the_course_pngs_pass") else {
        return;
    };
    for (file, scene) in [
        ("week04_sphere.png", "week04-sphere"),
        ("week04_quad.png", "week04-quad"),
    ] {
        let c = compare_image(
            &course_png(&dir, file),
            golden(scene),
            &CompareOptions::default(),
        )
        .unwrap();
        eprintln!(
            "{file}: {:?}, smallest adjusted p {:?}",
            c.verdict,
            c.scales
                .iter()
                .map(|s| s.smallest_adjusted_p)
                .collect::<Vec<_>>()
        );
        assert!(c.passed(), "{file}: {:#?}", c.scales);
        // And read as linear (no gamma) they fail, so the pass is not vacuous.
        let linear = compare_image(
            &course_png(&dir, file),
            golden(scene),
            &CompareOptions {
                encoding: rtoracle::compare::encoding::Encoding::Linear,
                diagnose: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(!linear.passed(), "{file} passed as linear");
    }
}

// ---- The command line ----

/// A cache folder shared by the command-line tests, so the 4096-spp golden of the sphere scene
/// is rendered once per build folder.
fn cache() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("rtoracle-cache");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn compare_cli(dir: &Path, args: &[&str]) -> std::process::Output {
    rtoracle()
        .current_dir(dir)
        .env("RTORACLE_CACHE_DIR", cache())
        .arg("compare")
        .args(args)
        .output()
        .unwrap()
}

fn write(dir: &Path, name: &str, img: &Rgb8Image) -> PathBuf {
    let p = dir.join(name);
    rtoracle::image_io::write_png(&p, img).unwrap();
    p
}

/// End to end with `--scene`: an honest render passes (exit 0, JSON says so), a y-flipped one
/// fails (exit 1) with the diagnosis, a heatmap and a report folder.
#[test]
fn the_command_judges_renders_of_a_builtin_scene() {
    let dir = tempfile::tempdir().unwrap();
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    write(
        dir.path(),
        "honest.png",
        &render_with_mistake(&d, Mistake::Honest, 20, 3),
    );
    write(
        dir.path(),
        "flipped.png",
        &render_with_mistake(&d, Mistake::YFlipped, 20, 3),
    );

    let out = compare_cli(
        dir.path(),
        &["honest.png", "--scene", "week04-sphere", "--json"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["verdict"], "pass");
    assert_eq!(json["golden_spp"], 4096);
    assert_eq!(json["scales"].as_array().unwrap().len(), 4);

    let out = compare_cli(
        dir.path(),
        &[
            "flipped.png",
            "--scene",
            "week04-sphere",
            "--heatmap",
            "z.png",
            "--report",
            "report",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with("FAIL"), "{stdout}");
    assert!(stdout.contains("y flipped"), "{stdout}");
    let heat = rtoracle::image_io::read_png(&dir.path().join("z.png")).unwrap();
    // Three maps (red, green, blue channels) side by side, 4 pixels apart.
    assert_eq!((heat.width, heat.height), (3 * 400 + 8, 225));
    // The outline colour is there, and so are both signs: a flipped image is brighter than the
    // golden in some places and darker in others.
    use rtoracle::compare::heatmap::{HIGHER, LOWER, OUTLINE};
    let has = |rgb: [u8; 3]| heat.data.chunks_exact(3).any(|p| p == rgb);
    assert!(has(OUTLINE));
    assert!(has(HIGHER) && has(LOWER));
    let report = dir.path().join("report");
    for f in ["report.json", "heatmap.png", "index.html", "region-1.png"] {
        assert!(report.join(f).is_file(), "{f} missing");
    }
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(html.contains("region-1.png") && html.contains("FAIL"));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["diagnosis"]["best"], "flip-y");
}

#[test]
#[cfg_attr(
    not(rtoracle_course_fixtures),
    ignore = "set RTORACLE_COURSE_FIXTURES to the course's published images to run it"
)]
fn the_course_pngs_pass_on_the_command_line() {
    let Some(fixtures) = course_fixtures("the_course_pngs_pass_on_the_command_line") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let png = fixtures.join("week04_sphere.png");
    let out = compare_cli(
        dir.path(),
        &[png.to_str().unwrap(), "--scene", "week04-sphere"],
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Bad candidates: one line naming the file, exit 2, and no heatmap or report left behind.
#[test]
fn bad_candidates_exit_2_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    let good = write(
        p,
        "good.png",
        &render_with_mistake(&d, Mistake::Honest, 1, 1),
    );
    std::fs::write(p.join("notes.png"), "this is not an image\n").unwrap();
    let bytes = std::fs::read(&good).unwrap();
    std::fs::write(p.join("truncated.png"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(p.join("empty.png"), b"").unwrap();
    write(
        p,
        "small.png",
        &Rgb8Image {
            width: 40,
            height: 30,
            data: vec![0; 40 * 30 * 3],
        },
    );
    image::ImageBuffer::<image::Luma<u8>, _>::from_raw(400, 225, vec![0u8; 400 * 225])
        .unwrap()
        .save(p.join("grey.png"))
        .unwrap();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(400, 225, vec![0u16; 400 * 225 * 3])
        .unwrap()
        .save(p.join("deep.png"))
        .unwrap();
    // An EXR header with nothing behind it.
    std::fs::write(p.join("broken.exr"), [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0]).unwrap();

    for (file, needle) in [
        ("missing.png", "no such file"),
        ("notes.png", "not a PNG, PPM or EXR"),
        ("truncated.png", "truncated.png"),
        ("empty.png", "empty"),
        ("small.png", "is 40x30 but the golden is 400x225"),
        ("grey.png", "expected 8-bit RGB"),
        ("deep.png", "expected 8-bit RGB"),
        ("broken.exr", "broken.exr"),
    ] {
        let out = compare_cli(
            p,
            &[
                file,
                "--scene",
                "week04-sphere",
                "--heatmap",
                "z.png",
                "--report",
                "rep",
            ],
        );
        assert_bad_input(&out, needle);
        assert_bad_input(&out, file);
        assert!(
            !p.join("z.png").exists() && !p.join("rep").exists(),
            "{file}"
        );
    }
    // Bad options are usage errors, also exit 2.
    let out = compare_cli(p, &["good.png", "--scene", "week04-sphere", "--spp", "0"]);
    assert_bad_input(&out, "'0' for '--spp");
    let out = compare_cli(p, &["good.png", "--scene", "no-such-scene"]);
    assert_bad_input(&out, "no-such-scene");
    let out = compare_cli(p, &["good.png", "--golden", "missing.exr"]);
    assert_bad_input(&out, "missing.exr");
    let out = compare_cli(
        p,
        &[
            "good.png",
            "--scene",
            "week04-sphere",
            "--heatmap",
            "nodir/z.png",
        ],
    );
    assert_bad_input(&out, "nodir");
    let out = compare_cli(p, &["good.png"]);
    assert_eq!(out.status.code(), Some(2));
}

/// The comparison as grading's image checker: honest passes, a flipped image fails with the
/// diagnosis and a heatmap, missing and wrong-size files are unusable.
#[test]
fn the_grading_image_checker_uses_the_comparison() {
    use rtoracle::grade::checkers::images::CompareImageChecker;
    use rtoracle::grade::checkers::{ImageChecker, ImageVerdict};
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    let honest = write(
        p,
        "honest.png",
        &render_with_mistake(&d, Mistake::Honest, 20, 11),
    );
    let bgr = write(p, "bgr.png", &render_with_mistake(&d, Mistake::Bgr, 20, 11));
    let small = write(
        p,
        "small.png",
        &Rgb8Image {
            width: 4,
            height: 4,
            data: vec![0; 48],
        },
    );
    let checker = CompareImageChecker::default();
    let ok = checker.check(&honest, "week04-sphere", &p.join("h1.png"));
    assert_eq!(ok.verdict, ImageVerdict::Pass);
    assert_eq!(ok.metrics["verdict"], "pass");
    let bad = checker.check(&bgr, "week04-sphere", &p.join("h2.png"));
    assert_eq!(bad.verdict, ImageVerdict::Fail);
    assert!(bad.diagnosis.unwrap().contains("BGR"));
    assert!(bad.heatmap.unwrap().is_file());
    for (file, needle) in [(p.join("none.png"), "missing"), (small, "is 4x4")] {
        match checker
            .check(&file, "week04-sphere", &p.join("h3.png"))
            .verdict
        {
            ImageVerdict::Unusable(why) => assert!(why.contains(needle), "{why}"),
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(checker.golden_sha256("week04-sphere").len(), 64);
}

/// An EXR candidate (linear f32, as `rtoracle render -o X.exr` writes it) is compared as values:
/// an honest one passes, the same with every value times 0.97 fails.
#[test]
fn exr_candidates_are_compared_as_linear_values() {
    let dir = tempfile::tempdir().unwrap();
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    let film = render(
        &d.scene(),
        &d.camera(None),
        &RenderOptions {
            samples_per_pixel: 20,
            seed: 31,
            ..Default::default()
        },
    )
    .unwrap();
    let honest = dir.path().join("honest.exr");
    rtoracle::image_io::write_exr(&honest, &film, &[]).unwrap();
    let mut darker = film.clone();
    for m in &mut darker.mean {
        *m *= 0.97;
    }
    let dark = dir.path().join("dark.exr");
    rtoracle::image_io::write_exr(&dark, &darker, &[]).unwrap();
    let c = rtoracle::compare::compare_file(
        &honest,
        golden("week04-sphere"),
        &CompareOptions::default(),
    )
    .unwrap();
    assert!(c.passed(), "{:#?}", c.scales);
    assert_eq!(c.encoding, "exr");
    let c =
        rtoracle::compare::compare_file(&dark, golden("week04-sphere"), &CompareOptions::default())
            .unwrap();
    assert!(!c.passed());
    assert!(c.bias.iter().all(|b| *b < 0.0), "{:?}", c.bias);
}

/// A render of fewer samples than claimed is caught by the noise check: 1 spp claimed as 41
/// fails on both scenes, with an effective spp far below 41, while honest renders at 41 spp
/// (and at 20, in `honest_renders_pass_at_every_seed`) pass it. The check's false-failure bound
/// is NOISE_ALPHA = 1e-6 per image; honest renders sit far from it (p = 1 here: the squared
/// differences stay below their bound under the claim).
#[test]
fn fewer_samples_than_claimed_fail_the_noise_check() {
    for scene in COURSE_SCENES {
        let d = rtoracle::scene::builtin(scene).unwrap();
        let claim = |n: u32| CompareOptions {
            samples_per_pixel: n,
            ..Default::default()
        };
        let results: Vec<(u64, Comparison, Comparison)> = (1..=4u64)
            .into_par_iter()
            .map(|seed| {
                let one = render_with_mistake(&d, Mistake::Honest, 1, 500 + seed);
                let c1 = compare_image(&candidate(one), golden(scene), &claim(41)).unwrap();
                let honest = render_with_mistake(&d, Mistake::Honest, 41, 600 + seed);
                let c41 = compare_image(&candidate(honest), golden(scene), &claim(41)).unwrap();
                (seed, c1, c41)
            })
            .collect();
        for (seed, c1, c41) in results {
            let n1 = c1.noise.as_ref().expect("enough noisy pixels");
            assert!(!c1.passed() && !n1.passed, "{scene} seed {seed}: {n1:?}");
            assert!(n1.effective_spp.unwrap() < 10.0, "{scene}: {n1:?}");
            let n41 = c41.noise.as_ref().expect("enough noisy pixels");
            eprintln!(
                "{scene} seed {seed}: 1 spp as 41: effective {:.2}, p {:.1e}; 41 spp: effective {:.1}, p {:.3}",
                n1.effective_spp.unwrap(),
                n1.p,
                n41.effective_spp.unwrap_or(f64::NAN),
                n41.p
            );
            assert!(c41.passed() && n41.passed, "{scene} seed {seed}: {n41:?}");
            assert!(n41.p > 1e3 * n41.threshold, "{scene}: {n41:?}");
        }
    }
}

/// An image wrong all over (no gamma) has its failing regions outlined all over the heatmap,
/// not only in the top rows: the report lists the first 50 and says how many there are.
#[test]
fn the_heatmap_outlines_failing_regions_all_over_the_image() {
    let d = rtoracle::scene::builtin("week04-quad").unwrap();
    let c = compare(
        "week04-quad",
        render_with_mistake(&d, Mistake::NoGamma, 20, 9),
    );
    assert!(!c.passed());
    assert!(c.regions_total > 50, "{}", c.regions_total);
    assert_eq!(c.regions.len(), 50);
    assert_eq!(c.outline.len(), c.regions_total);
    let img = rtoracle::compare::heatmap::heatmap_image(&c);
    // Outline pixels (pure green) in each horizontal third of the image.
    let green = |y0: usize, y1: usize| {
        (y0..y1).any(|y| {
            (0..img.width).any(|x| img.data[3 * (y * img.width + x)..][..3] == [0, 170, 0])
        })
    };
    let h = img.height;
    assert!(green(0, h / 3) && green(h / 3, 2 * h / 3) && green(2 * h / 3, h));
}

/// A FAIL says how to see where (unless a picture was asked for); a reused `--report` folder
/// keeps no stale crop; a folder holding other files is refused before any work.
#[test]
fn a_fail_points_to_the_pictures_and_a_reused_report_folder_keeps_nothing_stale() {
    let dir = tempfile::tempdir().unwrap();
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    write(
        dir.path(),
        "bad.png",
        &render_with_mistake(&d, Mistake::NoGamma, 20, 3),
    );
    let out = compare_cli(dir.path(), &["bad.png", "--scene", "week04-sphere"]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("add --heatmap FILE.png"), "{stdout}");
    assert!(stdout.contains("--report DIR"), "{stdout}");
    // A stale file of an earlier report does not survive.
    let report = dir.path().join("rep");
    std::fs::create_dir(&report).unwrap();
    std::fs::write(report.join("region-99.png"), b"stale").unwrap();
    let out = compare_cli(
        dir.path(),
        &["bad.png", "--scene", "week04-sphere", "--report", "rep"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(!String::from_utf8_lossy(&out.stdout).contains("add --heatmap"));
    assert!(report.join("index.html").is_file() && report.join("region-1.png").is_file());
    assert!(!report.join("region-99.png").exists());
    // No temporary folder is left beside it.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A folder with a file of the user's is refused up front, and the file stays.
    std::fs::write(report.join("notes.txt"), b"mine").unwrap();
    let out = compare_cli(
        dir.path(),
        &["bad.png", "--scene", "week04-sphere", "--report", "rep"],
    );
    assert_bad_input(&out, "notes.txt");
    assert_eq!(std::fs::read(report.join("notes.txt")).unwrap(), b"mine");
}

/// `--scene FILE.toml` compares with the golden of an instructor's scene file (cached), judging
/// the candidate at the scene's own samples per pixel: here 1, where a 20-spp claim fails an
/// honest render. A missing or broken scene file is bad input naming it.
#[test]
fn the_command_judges_renders_of_a_scene_file_at_its_sample_count() {
    let dir = tempfile::tempdir().unwrap();
    let mut d = rtoracle::scene::builtin("week04-sphere").unwrap();
    d.image.width = 64;
    d.image.samples_per_pixel = 1;
    std::fs::write(dir.path().join("mine.toml"), d.to_toml()).unwrap();
    std::fs::write(dir.path().join("broken.toml"), "[image]\nwidth = \n").unwrap();
    write(
        dir.path(),
        "honest.png",
        &render_with_mistake(&d, Mistake::Honest, 1, 5),
    );
    write(
        dir.path(),
        "flipped.png",
        &render_with_mistake(&d, Mistake::YFlipped, 1, 5),
    );
    let out = compare_cli(dir.path(), &["honest.png", "--scene", "mine.toml"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.starts_with("PASS honest.png: 64x36, 1 spp against a 4096 spp golden of mine.toml"),
        "{text}"
    );
    let out = compare_cli(dir.path(), &["flipped.png", "--scene", "mine.toml"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("y flipped"));
    assert_bad_input(
        &compare_cli(dir.path(), &["honest.png", "--scene", "nope.toml"]),
        "nope.toml",
    );
    assert_bad_input(
        &compare_cli(dir.path(), &["honest.png", "--scene", "broken.toml"]),
        "broken.toml: malformed scene file",
    );
    // A golden made ahead of time, given with its scene: judged at the scene's 1 spp, as with
    // the cached golden (a 20-spp claim, which the honest 1-spp render fails, is tried below).
    let made = rtoracle()
        .current_dir(dir.path())
        .env("RTORACLE_CACHE_DIR", cache())
        .args(["golden", "mine.toml", "-o", "mine.exr"])
        .output()
        .unwrap();
    assert!(made.status.success());
    let with_scene = |image: &str, golden: &str, scene: &str| {
        compare_cli(dir.path(), &[image, "--scene", scene, "--golden", golden])
    };
    let out = with_scene("honest.png", "mine.exr", "mine.toml");
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.starts_with("PASS honest.png: 64x36, 1 spp against a 4096 spp golden of mine.toml"),
        "{text}"
    );
    assert_eq!(
        with_scene("flipped.png", "mine.exr", "mine.toml")
            .status
            .code(),
        Some(1)
    );
    // Alone, --golden judges at the spp of the scene the golden holds (1 here), and says so.
    let alone = compare_cli(dir.path(), &["honest.png", "--golden", "mine.exr"]);
    let text = String::from_utf8_lossy(&alone.stdout);
    assert_eq!(alone.status.code(), Some(0), "{text}");
    assert!(text.contains(", 1 spp against"), "{text}");
    assert!(
        text.contains("judged as a render of 1 spp, the samples_per_pixel of mine.toml"),
        "{text}"
    );
    // --spp still decides, and then nothing is said about where the count came from.
    let given = compare_cli(
        dir.path(),
        &["honest.png", "--golden", "mine.exr", "--spp", "20"],
    );
    let text = String::from_utf8_lossy(&given.stdout);
    assert_eq!(given.status.code(), Some(1), "{text}");
    assert!(
        text.contains(", 20 spp against") && !text.contains("judged as"),
        "{text}"
    );
    // A golden of another scene, or none, is refused before any work.
    let mut other = d.clone();
    other.materials[0].albedo[0] += 0.1;
    std::fs::write(dir.path().join("other.toml"), other.to_toml()).unwrap();
    assert_bad_input(
        &with_scene("honest.png", "mine.exr", "other.toml"),
        "--golden mine.exr: was made from another scene",
    );
    assert_bad_input(
        &with_scene("honest.png", "none.exr", "mine.toml"),
        "--golden none.exr: no such file",
    );
    assert_bad_input(
        &compare_cli(dir.path(), &["honest.png", "--golden", "none.exr"]),
        "none.exr: no such file",
    );
}

/// Writes `honest.png` into `dir` (week04-quad, 20 spp, seed 8) and returns the committed
/// golden of that scene.
fn honest_quad_and_its_golden(dir: &Path) -> PathBuf {
    let d = rtoracle::scene::builtin("week04-quad").unwrap();
    write(
        dir,
        "honest.png",
        &render_with_mistake(&d, Mistake::Honest, 20, 8),
    );
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden/week04-quad.exr")
}

/// `--golden` alone with a built-in scene's golden judges at that scene's spp (20), and a golden
/// that records no scene at 20 with a line saying it does not know.
#[test]
fn compare_with_a_golden_alone_uses_the_spp_it_records() {
    let dir = tempfile::tempdir().unwrap();
    let committed = honest_quad_and_its_golden(dir.path());
    let out = compare_cli(
        dir.path(),
        &["honest.png", "--golden", committed.to_str().unwrap()],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains(
            "judged as a render of 20 spp, the samples_per_pixel of the built-in scene week04-quad"
        ),
        "{text}"
    );
    // The same pixels with no scene attributes: 20, and it says it does not know.
    let mut image = rtoracle::image_io::read_exr(&committed).unwrap();
    image.attributes.retain(|(k, _)| k == "rtoracle.spp");
    let film = rtoracle::render::Film {
        deviation: None,
        ..image.to_film(4096)
    };
    rtoracle::image_io::write_exr(&dir.path().join("bare.exr"), &film, &image.attributes).unwrap();
    let out = compare_cli(dir.path(), &["honest.png", "--golden", "bare.exr"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains(
            "judged as a render of 20 spp: this golden does not say its scene's samples per pixel"
        ),
        "{text}"
    );
}

/// A `--golden` whose `deviation` layer holds a negative or NaN distance (not a bound on
/// anything) is refused before any work, one line naming the file; the same golden with its
/// deviations intact passes an honest render.
#[test]
fn compare_refuses_a_golden_whose_deviation_is_not_a_distance() {
    let dir = tempfile::tempdir().unwrap();
    let committed = honest_quad_and_its_golden(dir.path());
    let image = rtoracle::image_io::read_exr(&committed).unwrap();
    let film = |deviation: Vec<glam::DVec3>| rtoracle::render::Film {
        deviation: Some(deviation),
        ..image.to_film(4096)
    };
    let intact = image.to_film(4096).deviation.unwrap();
    for (name, bad) in [("negative.exr", -0.5), ("nan.exr", f64::NAN)] {
        let mut deviation = intact.clone();
        deviation[7].y = bad;
        let path = dir.path().join(name);
        rtoracle::image_io::write_exr(&path, &film(deviation), &image.attributes).unwrap();
        assert_bad_input(
            &compare_cli(dir.path(), &["honest.png", "--golden", name]),
            &format!("{name}: golden: the golden has a deviation that is not a finite distance"),
        );
    }
    rtoracle::image_io::write_exr(
        &dir.path().join("intact.exr"),
        &film(intact),
        &image.attributes,
    )
    .unwrap();
    let out = compare_cli(dir.path(), &["honest.png", "--golden", "intact.exr"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

/// Every 8-bit code of `img` times `f`, rounded down (as a student darkening a picture would).
fn codes_times(img: &Rgb8Image, f: f64) -> Rgb8Image {
    Rgb8Image {
        width: img.width,
        height: img.height,
        data: img.data.iter().map(|&c| (f64::from(c) * f) as u8).collect(),
    }
}

/// A scale is diagnosed in the terms of the file judged: an honest PNG with every code times
/// 0.9 is "every code times 0.90 (linear x0.81)" (the course's codes are the square root of the
/// linear values, so 0.9 on the codes is 0.81 in linear light); an honest EXR with every value
/// times 0.81 is "every value times 0.81", with no codes to speak of.
#[test]
fn a_darkened_picture_is_diagnosed_in_its_own_encoding() {
    let d = rtoracle::scene::builtin("week04-sphere").unwrap();
    let film = render(
        &d.scene(),
        &d.camera(None),
        &RenderOptions {
            samples_per_pixel: 20,
            seed: 41,
            ..Default::default()
        },
    )
    .unwrap();
    let honest = Rgb8Image {
        width: film.width,
        height: film.height,
        data: film.to_course_rgb8(),
    };
    let c = compare("week04-sphere", codes_times(&honest, 0.9));
    let summary = &c.diagnosis.as_ref().unwrap().summary;
    assert!(
        summary.contains("every code times 0.90 (linear x0.81)")
            && summary.contains("10% darker in the picture"),
        "{summary}"
    );
    let dir = tempfile::tempdir().unwrap();
    let mut darker = film.clone();
    for m in &mut darker.mean {
        *m *= 0.81;
    }
    let dark = dir.path().join("dark.exr");
    rtoracle::image_io::write_exr(&dark, &darker, &[]).unwrap();
    let c =
        rtoracle::compare::compare_file(&dark, golden("week04-sphere"), &CompareOptions::default())
            .unwrap();
    let summary = &c.diagnosis.as_ref().unwrap().summary;
    assert!(
        summary.contains("every value times 0.81 (") && summary.contains("19% darker"),
        "{summary}"
    );
    assert!(!summary.contains("code"), "{summary}");
}

/// The course's own published picture (rendered by its Python code), every code times 0.9, is
/// diagnosed the same way.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn the_course_s_picture_darkened_is_diagnosed_in_codes() {
    let Some(root) = course_code("the_course_s_picture_darkened_is_diagnosed_in_codes") else {
        return;
    };
    let png = root.join("week04/skeleton/week04_quad.png");
    let img = rtoracle::image_io::read_png(&png).unwrap();
    let c = compare("week04-quad", codes_times(&img, 0.9));
    let summary = &c.diagnosis.as_ref().unwrap().summary;
    assert!(
        summary.contains("every code times 0.90 (linear x0.81)"),
        "{summary}"
    );
}
