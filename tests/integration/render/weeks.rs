//! The reference against the course's weeks 5 to 10, whole images.
//!
//! For each week, the Python fixture of the instructor's solution
//! (`tests/fixtures/python/weeks/weekNN/solution`, the course's own classes and numpy's global
//! random numbers) renders each of the week's `main.py` scenes at [`WIDTH`] pixels wide and
//! [`SPP`] samples per pixel, and `rtoracle compare` passes it against the reference's golden of
//! the same scene at that size (the built-in scene dumped with `scenes --dump`, its width and
//! samples per pixel set, rendered at 4096 spp into a private cache). Renders of catalogued
//! mistakes (`mistakes.json`) that show at this size must fail.
//!
//! Every render is seeded (the Python with [`SEED`], the golden with rtoracle's golden seed), so
//! each verdict is the same on every run: there is no false alarm to budget for. The mistakes
//! listed are those that show at this size; how often honest renders of other seeds pass at full
//! size is a measured figure (`benches/false_alarms.sh`, in `docs/comparing-images.md`, "Measured
//! false alarms and power").

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use crate::common::*;

/// Width of every render here (the height follows the scene's aspect ratio).
const WIDTH: u32 = 32;
/// Samples per pixel of the candidates (and the scenes' `samples_per_pixel`, which weeks 9 and
/// 10's jittered sampling reads).
const SPP: u32 = 4;
/// The seed of the Python renders.
const SEED: u64 = 2;

fn weeks_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks")
}

fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| {
            rtoracle::bench::harness::course_python_or_skip(
                "the week renders against the reference",
            )
        })
        .as_deref()
}

/// A work folder per test process: the stand-in pictures (`make_textures.py`) and the goldens'
/// cache, shared by the tests of this module.
fn work(python: &Path) -> &'static Path {
    static DIR: OnceLock<&'static Path> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = crate::common::shared_temporary_folder("rtoracle-render-weeks-");
        let out = Command::new(python)
            .arg("-B")
            .arg(weeks_dir().join("make_textures.py"))
            .arg(dir.join("textures"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "make_textures.py: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    })
}

/// The built-in `scene` as a scene file at [`WIDTH`] and `spp`, reading the stand-in pictures.
fn scene_file(work: &Path, scene: &str, spp: u32) -> PathBuf {
    let textures = work.join("textures");
    let out = run_in(
        work,
        &[
            "scenes",
            "--dump",
            scene,
            "--textures",
            textures.to_str().unwrap(),
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text: String = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|line| {
            if line.starts_with("width = ") {
                format!("width = {WIDTH}\n")
            } else if line.starts_with("samples_per_pixel = ") {
                format!("samples_per_pixel = {spp}\n")
            } else {
                format!("{line}\n")
            }
        })
        .collect();
    let path = work.join(format!("{scene}-{WIDTH}w-{spp}spp.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Renders `function` of week `week`'s solution (with the mistake `overlay`'s modules when
/// given) into `out`; `Err` with the last line of stderr when the course's code raised.
fn python_render(
    python: &Path,
    work: &Path,
    week: &str,
    function: &str,
    overlay: Option<&str>,
    seed: u64,
    out: &Path,
) -> Result<(), String> {
    let mut cmd = Command::new(python);
    cmd.arg("-B")
        .arg(weeks_dir().join("render_scene.py"))
        .arg(weeks_dir().join(week).join("solution"))
        .arg(function)
        .arg(out)
        .args(["--width", &WIDTH.to_string(), "--spp", &SPP.to_string()])
        .args(["--seed", &seed.to_string()])
        .arg("--textures")
        .arg(work.join("textures"));
    if let Some(name) = overlay {
        cmd.arg("--overlay")
            .arg(weeks_dir().join(week).join("mistakes").join(name));
    }
    let o = cmd.output().unwrap();
    if o.status.success() {
        Ok(())
    } else {
        let err = String::from_utf8_lossy(&o.stderr);
        Err(err.lines().last().unwrap_or("").to_string())
    }
}

/// `rtoracle compare --scene FILE --spp SPP IMAGE`: its exit code and first line.
fn compare(work: &Path, scene: &Path, image: &Path) -> (Option<i32>, String) {
    let o = rtoracle()
        .current_dir(work)
        .env("RTORACLE_CACHE_DIR", work.join("cache"))
        .args(["compare", "--scene"])
        .arg(scene)
        .args(["--spp", &SPP.to_string()])
        .arg(image)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let first = text.lines().next().unwrap_or("").to_string();
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "compare of {}: {first}\n{}",
        image.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.code(), first)
}

/// The week's scenes: its `main.py` function and the built-in scene that follows it.
fn scenes_of(week: &str) -> &'static [(&'static str, &'static str)] {
    match week {
        "week05" => &[
            ("renderQuad", "week05-quad"),
            ("renderQuadLight", "week05-quad-light"),
            ("renderPointLight", "week05-point-light"),
            ("renderPointLightShadow", "week05-point-light-shadow"),
        ],
        "week06" => &[
            ("renderMirrorPointLight", "week06-mirror-point-light"),
            ("renderMirrors", "week06-mirrors"),
            ("renderDielectric", "week06-dielectric"),
        ],
        "week07" => &[
            ("renderProceduralTexture", "week07-procedural-texture"),
            ("renderEarth", "week07-earth"),
        ],
        "week08" => &[
            ("renderPhong", "week08-phong"),
            ("renderBlinn", "week08-blinn"),
        ],
        "week09" => &[("renderBlinn", "week09-blinn")],
        "week10" => &[
            ("renderDoF", "week10-dof"),
            ("renderMoving", "week10-moving"),
        ],
        _ => unreachable!("{week}"),
    }
}

/// Week `week`'s solution passes on each of its scenes, and each `(mistake, function)` fails.
fn week_passes_and_mistakes_fail(week: &str, mistakes: &[(&str, &str)]) {
    let Some(py) = python() else { return };
    let work = work(py);
    let scene_of = |function: &str| {
        scenes_of(week)
            .iter()
            .find(|(f, _)| *f == function)
            .map(|(_, s)| *s)
            .unwrap()
    };
    for (function, scene) in scenes_of(week) {
        let toml = scene_file(work, scene, SPP);
        let png = work.join(format!("{scene}-solution.png"));
        python_render(py, work, week, function, None, SEED, &png).unwrap();
        let (code, line) = compare(work, &toml, &png);
        assert_eq!(
            code,
            Some(0),
            "{week} {function} (the solution) vs {scene}: {line}"
        );
    }
    for (mistake, function) in mistakes {
        let scene = scene_of(function);
        let toml = scene_file(work, scene, SPP);
        let png = work.join(format!("{scene}-{mistake}.png"));
        python_render(py, work, week, function, Some(mistake), SEED, &png)
            .unwrap_or_else(|e| panic!("{week} {mistake} {function} raised: {e}"));
        let (code, line) = compare(work, &toml, &png);
        assert_eq!(
            code,
            Some(1),
            "{week} {mistake} in {function} vs {scene}: {line}"
        );
        assert!(line.starts_with("FAIL"), "{line}");
    }
}

#[test]
fn week05_solution_passes_and_its_mistakes_fail() {
    week_passes_and_mistakes_fail(
        "week05",
        &[
            ("shadows_missing", "renderPointLightShadow"),
            ("shadows_inverted", "renderPointLightShadow"),
            ("light_sphere_not_counted", "renderPointLightShadow"),
            ("light_sphere_occludes", "renderPointLight"),
        ],
    );
}

#[test]
fn week06_solution_passes_and_its_mistakes_fail() {
    week_passes_and_mistakes_fail(
        "week06",
        &[
            ("reflect_sign", "renderMirrors"),
            ("schlick_fraction_inverted", "renderDielectric"),
            ("sky_not_added", "renderMirrors"),
        ],
    );
}

#[test]
fn week07_solution_passes_and_its_mistakes_fail() {
    week_passes_and_mistakes_fail(
        "week07",
        &[
            ("checker_scale_wrong", "renderProceduralTexture"),
            ("checker_on_uv", "renderProceduralTexture"),
            ("uv_swapped", "renderEarth"),
            ("quad_uv_not_set", "renderEarth"),
        ],
    );
}

#[test]
fn week08_solution_passes_and_its_mistakes_fail() {
    week_passes_and_mistakes_fail("week08", &[("cosine_of_unit_vectors", "renderPhong")]);
}

#[test]
fn week09_solution_passes_and_its_mistakes_fail() {
    week_passes_and_mistakes_fail(
        "week09",
        &[
            ("hemisphere_instead_of_cosine_lobe", "renderBlinn"),
            ("lobe_around_wrong_axis", "renderBlinn"),
        ],
    );
}

#[test]
fn week10_solution_passes() {
    week_passes_and_mistakes_fail("week10", &[]);
}

// ---------------------------------------------------------------------------------------------
// The committed goldens of the scenes of weeks 5 to 10 and of the book.

/// The built-in scenes whose goldens `golden.rs` checks on its own (week 4's and rtoracle's).
const WEEK_4_GOLDENS: &[&str] = &["week04-sphere", "week04-quad", "triangles", "edge-cases"];

/// Samples per pixel of the fresh renders the committed goldens are checked against.
const PREFIX_SPP: u32 = 32;

/// The largest possible `|mean of the first n samples - mean of all N|` given the mean and the
/// (n - 1)-normalised variance `s2` of all N (Cauchy-Schwarz on deviations that sum to 0): a
/// hard bound, not a statistical one.
fn prefix_mean_bound(s2: f64, n: f64, big_n: f64) -> f64 {
    ((big_n - 1.0) * s2.max(0.0) * (big_n - n) / (n * big_n)).sqrt()
}

/// Each committed golden of a later week's scene (or the book's) is the reference's render of
/// the scene as it is now: a fresh render of [`PREFIX_SPP`] samples with the golden's seed takes
/// the first samples of each pixel's stream (under the course's jittered sampling, the first
/// whole passes over the strata), so its mean must lie within [`prefix_mean_bound`] of the
/// golden's, up to the golden's f32 rounding. An insta snapshot holds each golden's record
/// (samples, scene hash, the SHA-256 of the file, the image's mean colour) for review.
#[test]
fn committed_goldens_of_the_later_weeks_are_the_reference_s_renders() {
    use rtoracle::golden::{
        ATTR_SCENE_SHA256, ATTR_SPP, GoldenScene, embedded_golden, embedded_golden_image,
        embedded_scenes, render_golden, sha256_hex,
    };
    let mut record = String::new();
    for scene in embedded_scenes() {
        if WEEK_4_GOLDENS.contains(&scene) {
            continue;
        }
        let golden = embedded_golden_image(scene).unwrap();
        let big_n: f64 = golden.attribute(ATTR_SPP).unwrap().parse().unwrap();
        assert!(big_n >= 4096.0, "{scene}: {big_n} samples");
        let film = render_golden(&GoldenScene::builtin(scene).unwrap(), PREFIX_SPP, false).unwrap();
        let n = film.samples_per_pixel as f64;
        assert_eq!(
            (golden.width, golden.height),
            (film.width, film.height),
            "{scene}"
        );
        let variance = golden.variance.as_ref().unwrap();
        let mut sum = [0.0f64; 3];
        for (i, (m, (g, s2))) in film
            .mean
            .iter()
            .zip(golden.mean.iter().zip(variance))
            .enumerate()
        {
            for c in 0..3 {
                let g = g[c] as f64;
                let bound = prefix_mean_bound(s2[c] as f64, n, big_n);
                let gap = (m[c] - g).abs();
                assert!(
                    gap <= bound * (1.0 + 1e-5) + 1e-6 * g.abs().max(1.0),
                    "{scene} pixel {i} channel {c}: {n}-sample mean {} vs golden {g} (s2 {}), \
                     bound {bound}",
                    m[c],
                    s2[c]
                );
                sum[c] += g;
            }
        }
        let pixels = golden.mean.len() as f64;
        record.push_str(&format!(
            "{scene}: {} samples, scene {}, file {}, mean colour [{:.4}, {:.4}, {:.4}]\n",
            golden.attribute(ATTR_SPP).unwrap(),
            &golden.attribute(ATTR_SCENE_SHA256).unwrap()[..16],
            &sha256_hex(embedded_golden(scene).unwrap())[..16],
            sum[0] / pixels,
            sum[1] / pixels,
            sum[2] / pixels
        ));
    }
    insta::assert_snapshot!("later-weeks-goldens", record);
}
