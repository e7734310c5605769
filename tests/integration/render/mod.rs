//! The reference tracer end to end: agreement with the course's published images, analytic
//! checks with closed forms, determinism, the scene files, and the command line's bad input.

mod golden;
mod mitsuba;
mod renders;
mod weeks;

use std::path::Path;

use rtoracle::geometry::DVec3;
use rtoracle::render::{Film, PixelJitter, RenderOptions, render};
use rtoracle::scene::{
    BUILTIN_SCENES, CameraSettings, ImageSettings, MaterialEntry, MaterialKind, ObjectEntry,
    SceneDescription, builtin,
};

use crate::common::*;

fn film_of(description: &SceneDescription, options: &RenderOptions) -> Film {
    render(&description.scene(), &description.camera(None), options).unwrap()
}

fn options(spp: u32, jitter: PixelJitter) -> RenderOptions {
    RenderOptions {
        samples_per_pixel: spp,
        jitter,
        ..Default::default()
    }
}

fn material(name: &str, albedo: [f64; 3]) -> MaterialEntry {
    MaterialEntry::new(name, MaterialKind::Lambertian, albedo)
}

/// A square image `width` wide seen by the course's camera (vfov 90, focus distance 10) from
/// `look_from` towards `look_at`.
fn square_view(width: usize, look_from: [f64; 3], look_at: [f64; 3]) -> SceneDescription {
    SceneDescription::new(
        ImageSettings {
            width,
            aspect_ratio: 1.0,
            samples_per_pixel: 1,
        },
        CameraSettings {
            look_from,
            look_at,
            up: [0.0, 1.0, 0.0],
            vfov: 90.0,
            focus_distance: 10.0,
            defocus_angle: 0.0,
        },
        vec![],
        vec![],
    )
}

// ---------------------------------------------------------------------------------------------
// Agreement with the course's published images.

/// Renders a course scene at 20 spp, seed 0, and compares it with the course's PNG: the share of
/// pixels that differ by more than 2 codes in some channel, and the mean absolute difference.
fn agreement(scene: &str, file: &str) -> Option<(f64, f64)> {
    let dir = course_fixtures(&format!("course agreement of {scene}"))?;
    let published = rtoracle::image_io::read_png(&dir.join(file)).unwrap();
    let film = film_of(&builtin(scene).unwrap(), &options(20, PixelJitter::Uniform));
    assert_eq!(
        (published.width, published.height),
        (film.width, film.height),
        "{file} has the size the course renders"
    );
    let ours = film.to_course_rgb8();
    let pixels = film.width * film.height;
    let mut differing = 0usize;
    let mut total = 0u64;
    for (a, b) in ours.chunks_exact(3).zip(published.data.chunks_exact(3)) {
        let d: Vec<u64> = a
            .iter()
            .zip(b)
            .map(|(x, y)| x.abs_diff(*y) as u64)
            .collect();
        total += d.iter().sum::<u64>();
        if d.iter().any(|&x| x > 2) {
            differing += 1;
        }
    }
    let share = differing as f64 / pixels as f64;
    let mae = total as f64 / (3 * pixels) as f64;
    eprintln!(
        "{scene} vs the course's {file}: {:.3}% of pixels differ by more than 2 codes, mean absolute difference {mae:.3} codes",
        100.0 * share
    );
    Some((share, mae))
}

#[test]
#[cfg_attr(
    not(rtoracle_course_fixtures),
    ignore = "set RTORACLE_COURSE_FIXTURES to the course's published images to run it"
)]
fn quad_scene_agrees_with_the_course() {
    if let Some((share, mae)) = agreement("week04-quad", "week04_quad.png") {
        // An independent honest re-render differs in about 0.5%.
        assert!(share <= 0.012, "{:.3}% of pixels differ", 100.0 * share);
        assert!(mae < 0.3, "mean absolute difference {mae}");
    }
}

#[test]
#[cfg_attr(
    not(rtoracle_course_fixtures),
    ignore = "set RTORACLE_COURSE_FIXTURES to the course's published images to run it"
)]
fn sphere_scene_agrees_with_the_course() {
    if let Some((share, mae)) = agreement("week04-sphere", "week04_sphere.png") {
        // An independent honest re-render differs in about 0.75%.
        assert!(share <= 0.015, "{:.3}% of pixels differ", 100.0 * share);
        assert!(mae < 0.3, "mean absolute difference {mae}");
    }
}

// ---------------------------------------------------------------------------------------------
// Analytic checks.

/// A pixel whose whole footprint lies on one object is that object's albedo exactly, whatever
/// the sample count (a plain sum over the count would be an ulp off for 0.2 or 0.8 at 3 spp).
#[test]
fn a_fully_covered_pixel_is_its_albedo_exactly_at_any_spp() {
    // Quad scene: the back quad (x, y in [-2, 2] at z = 0, seen from z = 10 through a 20-unit
    // viewport at distance 10) covers pixels 160..240 in both directions; nothing is in front of
    // the centre. Sphere scene: the centre sphere (radius 0.5 at distance 2) covers the middle.
    let cases = [
        ("week04-quad", (200, 200), [0.2, 1.0, 0.2]),
        ("week04-quad", (170, 230), [0.2, 1.0, 0.2]),
        ("week04-sphere", (200, 112), [0.8, 0.8, 0.0]),
    ];
    for spp in [1, 3, 7, 20] {
        for jitter in [PixelJitter::Uniform, PixelJitter::Stratified] {
            for (scene, (x, y), albedo) in cases {
                let description = builtin(scene).unwrap();
                let film = film_of(&description, &options(spp, jitter));
                assert_eq!(
                    film.pixel(x, y),
                    DVec3::from(albedo),
                    "{scene} ({x}, {y}) at {spp} spp, {jitter:?}"
                );
            }
        }
    }
}

/// The course's sky, computed here from its definition.
fn sky_formula(d: [f64; 3]) -> [f64; 3] {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let a = 0.5 * (d[1] / len + 1.0);
    [
        (1.0 - a) + a * 0.5,
        (1.0 - a) + a * 0.7,
        (1.0 - a) + a * 1.0,
    ]
}

/// Sky pixels of the sphere scene match the gradient formula along the direction through the
/// pixel, worked out here from the camera's definition (eye at z = 1 looking down -z, viewport
/// 20 units high and 20 * 400 / 225 wide at distance 10).
#[test]
fn sky_pixels_match_the_gradient_formula() {
    let description = builtin("week04-sphere").unwrap();
    let (w, h) = (400.0, 225.0);
    let (vh, vw) = (20.0, 20.0 * w / h);
    // Image position (u, v) in pixels from the top-left corner -> direction from the eye.
    let direction = |u: f64, v: f64| [-vw / 2.0 + u * vw / w, vh / 2.0 - v * vh / h, -10.0];
    // Top-row pixels, away from the middle column (so the sky is monotonic across each pixel).
    let pixels = [(0, 0), (50, 3), (150, 1), (399, 0), (350, 10)];

    let centre = film_of(&description, &options(3, PixelJitter::Centre));
    for (i, j) in pixels {
        let expected = sky_formula(direction(i as f64 + 0.5, j as f64 + 0.5));
        let got = centre.pixel(i, j).to_array();
        for c in 0..3 {
            assert!(
                (got[c] - expected[c]).abs() < 1e-12,
                "pixel ({i}, {j}) channel {c}: {} against the formula's {}",
                got[c],
                expected[c]
            );
        }
    }

    // With jitter the pixel is a mean of sky values over its footprint: it lies between the
    // formula's values at the footprint's corners.
    let jittered = film_of(&description, &options(20, PixelJitter::Uniform));
    for (i, j) in pixels {
        let corners: Vec<[f64; 3]> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .map(|(du, dv)| sky_formula(direction(i as f64 + du, j as f64 + dv)))
            .collect();
        let got = jittered.pixel(i, j).to_array();
        for c in 0..3 {
            let lo = corners.iter().map(|k| k[c]).fold(f64::INFINITY, f64::min);
            let hi = corners
                .iter()
                .map(|k| k[c])
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                lo - 1e-12 <= got[c] && got[c] <= hi + 1e-12,
                "pixel ({i}, {j}) channel {c}: {} outside [{lo}, {hi}]",
                got[c]
            );
        }
    }
}

/// A sphere of radius 3 at distance 5 seen head-on by a 200x200 camera (vfov 90, viewport 20
/// wide at distance 10, so pixel centres at x = (2i - 199) / 20): a centre ray hits it exactly
/// when its angle to the axis has tangent below 3/4, i.e. when x^2 + y^2 < 56.25, i.e. when
/// a^2 + b^2 < 22500 for the odd integers a = 2i - 199 and b = 2j - 199. No centre lies on the
/// boundary (a^2 + b^2 is 2 mod 4, 22500 is 0 mod 4), so the count is exact.
#[test]
fn a_sphere_seen_head_on_covers_the_predicted_pixel_centres() {
    let mut expected = 0usize;
    for i in 0..200i64 {
        for j in 0..200i64 {
            let (a, b) = (2 * i - 199, 2 * j - 199);
            if a * a + b * b < 22500 {
                expected += 1;
            }
        }
    }
    // A disk of radius 75 pixels.
    assert!((expected as f64 - std::f64::consts::PI * 75.0 * 75.0).abs() < 200.0);

    let mut description = square_view(200, [0.0, 0.0, 0.0], [0.0, 0.0, -1.0]);
    description.materials = vec![material("m", [0.25, 0.5, 0.75])];
    description.objects = vec![ObjectEntry::Sphere {
        center: [0.0, 0.0, -5.0],
        radius: 3.0,
        material: "m".into(),
        moving_center: None,
    }];
    let film = film_of(&description, &options(1, PixelJitter::Centre));
    let covered = film
        .mean
        .iter()
        .filter(|&&c| c == DVec3::new(0.25, 0.5, 0.75))
        .count();
    assert_eq!(covered, expected);
}

/// A square split into two triangles along a diagonal that passes through pixel centres: no
/// pixel inside the square shows the sky, at the centres or with many jittered samples.
#[test]
fn no_ray_falls_through_the_shared_diagonal() {
    // Seen from z = 4, the square [-1, 1]^2 at z = 0 spans pixels 75..125 of a 200-pixel image
    // (25 pixels a unit). The diagonal y = x goes through the centres with i + j = 199, the
    // diagonal y = -x through those with i = j.
    let corners = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    for (split, look_from) in [
        (0, [0.0, 0.0, 4.0]),
        (1, [0.0, 0.0, 4.0]),
        (0, [0.0, 0.0, 3.3]),
        (1, [0.0, 0.0, 7.1]),
    ] {
        let [p, q, r, s] = corners;
        let (first, second) = if split == 0 {
            // Along (-1, -1) - (1, 1).
            ([p, q, r], [p, r, s])
        } else {
            // Along (1, -1) - (-1, 1).
            ([q, r, s], [q, s, p])
        };
        let mut description = square_view(200, look_from, [0.0, 0.0, 0.0]);
        description.materials = vec![
            material("red", [1.0, 0.0, 0.0]),
            material("green", [0.0, 1.0, 0.0]),
        ];
        description.objects = vec![
            ObjectEntry::Triangle {
                a: first[0],
                b: first[1],
                c: first[2],
                material: "red".into(),
            },
            ObjectEntry::Triangle {
                a: second[0],
                b: second[1],
                c: second[2],
                material: "green".into(),
            },
        ];
        // A unit at z = 0 spans 100 / distance pixels (10 pixels a unit on the viewport at
        // distance 10); keep two pixels from the square's outer edges.
        let per_unit = 100.0 / look_from[2];
        let half = (per_unit - 2.0).floor() as usize;
        let inside = (100 - half)..(100 + half);
        for (spp, jitter) in [(1, PixelJitter::Centre), (16, PixelJitter::Uniform)] {
            let film = film_of(&description, &options(spp, jitter));
            for j in inside.clone() {
                for i in inside.clone() {
                    let c = film.pixel(i, j);
                    // Any sky sample would bring blue into the pixel.
                    assert!(
                        c.z == 0.0 && (c.x + c.y - 1.0).abs() < 1e-12,
                        "split {split} from {look_from:?}, {jitter:?}: pixel ({i}, {j}) is {c}"
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Determinism.

fn same_bits(a: &Film, b: &Film) -> bool {
    let bits = |v: &[DVec3]| -> Vec<u64> {
        v.iter()
            .flat_map(|c| c.to_array().map(f64::to_bits))
            .collect()
    };
    (a.width, a.height) == (b.width, b.height)
        && bits(&a.mean) == bits(&b.mean)
        && a.variance.as_deref().map(bits) == b.variance.as_deref().map(bits)
}

/// The film, variance included, is the same bit for bit on 1, 2 and 4 threads: for the pinhole
/// fast path and for the general path a defocused camera takes.
#[test]
fn the_film_is_the_same_on_1_2_and_4_threads() {
    let mut defocused = builtin("edge-cases").unwrap();
    defocused.camera.defocus_angle = 3.0;
    defocused.image.width = 120;
    let mut sphere = builtin("week04-sphere").unwrap();
    sphere.image.width = 200;
    for description in [sphere, defocused] {
        for jitter in [PixelJitter::Uniform, PixelJitter::Stratified] {
            let options = RenderOptions {
                samples_per_pixel: 6,
                seed: 42,
                variance: true,
                jitter,
                progress: false,
            };
            let films: Vec<Film> = [1, 2, 4]
                .iter()
                .map(|&threads| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap()
                        .install(|| film_of(&description, &options))
                })
                .collect();
            assert!(same_bits(&films[0], &films[1]), "1 and 2 threads differ");
            assert!(same_bits(&films[0], &films[2]), "1 and 4 threads differ");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scene files and the scenes command.

#[test]
fn scenes_lists_every_builtin_on_its_own_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["scenes"]);
    assert!(out.status.success());
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), BUILTIN_SCENES.len(), "{stdout}");
    for (line, scene) in lines.iter().zip(BUILTIN_SCENES) {
        assert_eq!(line.split_whitespace().next(), Some(scene.name));
        assert!(line.ends_with(scene.summary), "{line}");
    }
}

/// `scenes --dump NAME` is a scene file that reads back to the built-in and renders to the
/// same PNG bytes.
#[test]
fn a_dumped_scene_renders_to_the_same_bytes_as_the_builtin() {
    let dir = tempfile::tempdir().unwrap();
    for scene in BUILTIN_SCENES {
        let out = run_in(dir.path(), &["scenes", "--dump", scene.name]);
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        assert_eq!(
            SceneDescription::from_toml(&text, scene.name).unwrap(),
            scene.description()
        );
        let file = format!("{}.toml", scene.name);
        std::fs::write(dir.path().join(&file), &text).unwrap();
        let args = ["--spp", "2", "--width", "80", "--seed", "9", "-o"];
        let from_file = run_in(
            dir.path(),
            &[&["render", file.as_str()][..], &args, &["file.png"]].concat(),
        );
        let from_builtin = run_in(
            dir.path(),
            &[&["render", scene.name][..], &args, &["builtin.png"]].concat(),
        );
        assert!(from_file.status.success() && from_builtin.status.success());
        let a = std::fs::read(dir.path().join("file.png")).unwrap();
        let b = std::fs::read(dir.path().join("builtin.png")).unwrap();
        assert!(
            a == b,
            "{}: the dumped file renders differently",
            scene.name
        );
    }
}

// ---------------------------------------------------------------------------------------------
// The render command.

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The default output is `NAME.png` in the working directory, written with nothing else left
/// behind; with stderr not a terminal there is no progress bar, only the one summary line.
#[test]
fn render_writes_name_png_and_one_line_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["render", "week04-sphere", "--spp", "2"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr.lines().count(), 1, "{stderr:?}");
    assert!(stderr.starts_with("rendered week04-sphere (400x225, 2 spp"));
    assert!(
        !stderr.contains('\r') && !stderr.contains('\u{1b}'),
        "{stderr:?}"
    );
    assert_eq!(files_in(dir.path()), ["week04-sphere.png"]);
    let img = rtoracle::image_io::read_png(&dir.path().join("week04-sphere.png")).unwrap();
    assert_eq!((img.width, img.height), (400, 225));

    // A scene file's default output is named after the file.
    std::fs::write(
        dir.path().join("mine.toml"),
        builtin("triangles").unwrap().to_toml(),
    )
    .unwrap();
    let out = run_in(
        dir.path(),
        &["render", "mine.toml", "--spp", "1", "--width", "40"],
    );
    assert!(out.status.success());
    assert!(dir.path().join("mine.png").is_file());
}

#[test]
fn thread_count_does_not_change_the_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for threads in ["1", "2", "3"] {
        let name = format!("t{threads}.png");
        let out = run_in(
            dir.path(),
            &[
                "render",
                "week04-quad",
                "--spp",
                "3",
                "--width",
                "120",
                "--threads",
                threads,
                "-o",
                &name,
            ],
        );
        assert!(out.status.success());
        outputs.push(std::fs::read(dir.path().join(name)).unwrap());
    }
    assert!(outputs[0] == outputs[1] && outputs[0] == outputs[2]);
}

/// Runs a render that must fail: exit 2, one line on stderr naming the problem, no panic, and
/// no file left behind in the folder.
fn assert_render_refused(
    files: &[(&str, &str)],
    args: &[&str],
    needle: &str,
) -> std::process::Output {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let before = files_in(dir.path());
    let out = run_in(dir.path(), args);
    assert_bad_input(&out, needle);
    assert_eq!(files_in(dir.path()), before, "{args:?} left a file behind");
    out
}

fn with_line(text: &str, find: &str, replace: &str) -> String {
    assert!(text.contains(find), "{find}");
    text.replacen(find, replace, 1)
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let good = builtin("week04-sphere").unwrap().to_toml();
    let render = |extra: &[&'static str]| -> Vec<&'static str> {
        [&["render", "scene.toml"][..], extra].concat()
    };

    // An unknown scene name, and a file that does not exist.
    assert_render_refused(
        &[],
        &["render", "no-such-scene"],
        "unknown scene 'no-such-scene'",
    );
    assert_render_refused(
        &[],
        &["render", "missing.toml"],
        "missing.toml: cannot read",
    );

    // Malformed TOML: one line, with the line number.
    let broken = with_line(&good, "[camera]", "[camera");
    assert_render_refused(
        &[("scene.toml", &broken)],
        &render(&[]),
        "scene.toml: malformed scene file: line",
    );
    // An unknown field.
    let typo = with_line(&good, "samples_per_pixel", "samples_per_pixle");
    assert_render_refused(
        &[("scene.toml", &typo)],
        &render(&[]),
        "unknown field `samples_per_pixle`",
    );

    // NaN and infinite numbers (TOML spells them nan and inf).
    let nan = with_line(&good, "radius = 100.0", "radius = nan");
    assert_render_refused(
        &[("scene.toml", &nan)],
        &render(&[]),
        "objects[0].radius is NaN",
    );
    let inf = with_line(&good, "vfov = 90.0", "vfov = inf");
    assert_render_refused(&[("scene.toml", &inf)], &render(&[]), "camera.vfov is inf");
    let neg_inf = with_line(
        &good,
        "look_at = [0.0, 0.0, -1.0]",
        "look_at = [0.0, -inf, -1.0]",
    );
    assert_render_refused(
        &[("scene.toml", &neg_inf)],
        &render(&[]),
        "camera.look_at.y is -inf",
    );

    // Zero or negative sample counts and widths, on the command line and in the file.
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--spp", "0"],
        "'0' for '--spp",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--spp", "-3"],
        "'-3' for '--spp",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--width", "0"],
        "'0' for '--width",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--width", "-7"],
        "'-7' for '--width",
    );
    let zero_spp = with_line(&good, "samples_per_pixel = 20", "samples_per_pixel = 0");
    assert_render_refused(
        &[("scene.toml", &zero_spp)],
        &render(&[]),
        "samples_per_pixel must be at least 1",
    );
    let negative_width = with_line(&good, "width = 400", "width = -400");
    assert_render_refused(
        &[("scene.toml", &negative_width)],
        &render(&[]),
        "scene.toml: malformed scene file: line",
    );

    // An output folder that does not exist, and an extension it cannot write.
    assert_render_refused(
        &[],
        &["render", "week04-quad", "-o", "nowhere/out.png"],
        "-o nowhere/out.png: the folder 'nowhere' does not exist",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "-o", "out.jpg"],
        "-o out.jpg: cannot write this kind of image",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "-o", "out"],
        "-o out: cannot write this kind of image",
    );

    // An image too large to hold: past the width any image may have, or past the pixels.
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--width", "1000000"],
        "'1000000' for '--width <W>': must be an integer from 1 to 100000",
    );
    assert_render_refused(
        &[],
        &["render", "week04-quad", "--width", "100000"],
        "--width 100000: a 100000x100000 image is too large",
    );
    // A huge number is shown short, not in 309 digits.
    let wide = with_line(&good, "defocus_angle = 0.0", "defocus_angle = 1e308");
    assert_render_refused(
        &[("scene.toml", &wide)],
        &render(&[]),
        "camera.defocus_angle is 1e308, it must lie in [0, 180)",
    );
    // A scene whose aspect ratio makes it absurdly high names the aspect ratio, briefly.
    let flat = with_line(
        &good,
        "aspect_ratio = 1.7777777777777777",
        "aspect_ratio = 1e-300",
    );
    assert_render_refused(
        &[("scene.toml", &flat)],
        &render(&[]),
        "image.aspect_ratio is 1e-300: a 400-pixel-wide image would be more than 100000 pixels high",
    );

    // scenes --dump of an unknown name.
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["scenes", "--dump", "nope"]);
    assert_bad_input(&out, "unknown scene 'nope'");
    assert!(out.stdout.is_empty());
}

// ---------------------------------------------------------------------------------------------
// Weeks 5 to 10 and the two profiles.

/// Every built-in scene, in each profile it is meant for, renders the same film (variance
/// included) on 1, 2 and 3 threads: small images at a few samples, so all twenty scenes in two
/// profiles stay within a few seconds.
#[test]
fn every_builtin_renders_the_same_on_1_2_and_3_threads_in_its_profiles() {
    for scene in BUILTIN_SCENES {
        for &profile in scene.profiles {
            let mut description = scene.description();
            description.profile = profile;
            let options = RenderOptions {
                samples_per_pixel: 3,
                seed: 11,
                variance: true,
                jitter: PixelJitter::Uniform,
                progress: false,
            };
            let world = description.scene();
            let camera = description.camera(Some(24));
            let films: Vec<Film> = [1, 2, 3]
                .iter()
                .map(|&threads| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap()
                        .install(|| render(&world, &camera, &options).unwrap())
                })
                .collect();
            let what = format!("{} ({profile})", scene.name);
            assert!(
                films[0].mean.iter().all(|c| c.is_finite()),
                "{what}: not finite"
            );
            assert!(
                same_bits(&films[0], &films[1]),
                "{what}: 1 and 2 threads differ"
            );
            assert!(
                same_bits(&films[0], &films[2]),
                "{what}: 1 and 3 threads differ"
            );
        }
    }
}

/// `render` names the profile on its line and in the EXR, renders a course scene by the
/// book's rules with `--profile physical` (the book's encoding: a white sky pixel is 255, the
/// course's 254), and says how many samples the course's jitter took.
#[test]
fn render_names_the_profile_and_the_samples_taken() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &["render", "week06-mirrors", "--spp", "1", "--width", "40"],
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("profile course"), "{stderr}");
    let out = run_in(
        dir.path(),
        &[
            "render",
            "week06-mirrors",
            "--spp",
            "1",
            "--width",
            "40",
            "--profile",
            "physical",
            "-o",
            "p.exr",
        ],
    );
    assert!(out.status.success());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("profile physical"), "{stderr}");
    let exr = std::fs::read(dir.path().join("p.exr")).unwrap();
    let at = exr
        .windows(16)
        .position(|w| w == b"rtoracle.profile")
        .unwrap();
    assert!(exr[at..at + 60].windows(8).any(|w| w == b"physical"));
    let out = run_in(
        dir.path(),
        &["render", "week10-dof", "--spp", "30", "--width", "16"],
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        // One pass over the course's 10 x 10 strata (renderDoF's 100 spp) however few are asked.
        stderr.contains("30 spp: 100 jittered samples a pixel, seed"),
        "{stderr}"
    );
    // The course's renderBlinn renders with `render()`: no jitter, no count to explain.
    let out = run_in(
        dir.path(),
        &["render", "week09-blinn", "--spp", "30", "--width", "16"],
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("jittered"), "{stderr}");
    let out = run_in(
        dir.path(),
        &["render", "week10-moving", "--spp", "200", "--width", "16"],
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("200 spp: 196 jittered samples a pixel"),
        "{stderr}"
    );
    // The book's encoding reaches 255 where the course's stops at 254: a ray straight up.
    let mut sky = builtin("rtiow-materials").unwrap();
    sky.camera.look_at = [0.0, 1.0, 0.0];
    sky.camera.up = [0.0, 0.0, 1.0];
    sky.objects.clear();
    std::fs::write(dir.path().join("sky.toml"), sky.to_toml()).unwrap();
    let out = run_in(
        dir.path(),
        &[
            "render", "sky.toml", "--spp", "1", "--width", "8", "-o", "sky.png",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = rtoracle::image_io::read_png(&dir.path().join("sky.png")).unwrap();
    assert!(png.data.contains(&255), "the book's encoding");
}

/// The scene file's new keys are refused when they are wrong, with one line naming the file
/// and the key, and exit 2: an unknown key in `[render]`, a key of another kind of material,
/// a missing or unreadable texture file, negative roughness and IOR, a depth of 0, the
/// course's jitter without its step, a BRDF material in the physical profile, an unknown
/// texture name; and `--profile`, `--textures` used wrongly.
#[test]
fn bad_new_keys_are_one_line_and_exit_2() {
    let good = builtin("week07-earth").unwrap().to_toml();
    let command = ["render", "scene.toml"];
    let refused = |text: &str, needle: &str| {
        assert_render_refused(&[("scene.toml", text)], &command, needle);
    };
    refused(
        &with_line(&good, "max_depth = 5", "max_depht = 5"),
        "unknown field `max_depht`",
    );
    refused(
        &with_line(&good, "max_depth = 5", "max_depth = 0"),
        "scene.toml: render.max_depth is 0",
    );
    refused(
        &with_line(
            &good,
            "generated = \"earth\"",
            "file = \"textures/earthmap.png\"",
        ),
        "textures[1].file = '",
    );
    refused(
        &with_line(
            &good,
            "generated = \"earth\"",
            "file = \"textures/earthmap.png\"",
        ),
        "earthmap.png': no such file",
    );
    refused(
        &with_line(&good, "generated = \"earth\"", "generated = \"mars\""),
        "textures[1].generated is 'mars'",
    );
    refused(
        &with_line(&good, "texture = \"checker_bw\"", "texture = \"chequer\""),
        "materials[1].texture names the texture 'chequer', which is not defined",
    );
    refused(
        &with_line(
            &good,
            "sampling = \"uniform\"",
            "sampling = \"course-jittered\"",
        ),
        "render.sampling is \"course-jittered\", which needs render.jitter_step",
    );
    refused(
        &with_line(
            &good,
            "texture = \"earth\"",
            "texture = \"earth\"\nior = 1.5",
        ),
        "materials[0].ior does not apply to a textured material",
    );
    let glass = builtin("week06-dielectric").unwrap().to_toml();
    refused(
        &with_line(&glass, "ior = 1.5", "ior = -1.5"),
        "materials[3].ior is -1.5, it must be positive",
    );
    refused(
        &with_line(&glass, "ior = 1.5", "ior = 0.0"),
        "materials[3].ior is 0.0, it must be positive",
    );
    refused(
        &with_line(&glass, "ior = 1.5\n", ""),
        "materials[3].ior is missing",
    );
    let metal = builtin("rtiow-materials").unwrap().to_toml();
    refused(
        &with_line(&metal, "roughness = 1.0", "roughness = -0.2"),
        "materials[4].roughness is -0.2, it must be at least 0",
    );
    let phong = builtin("week08-phong").unwrap().to_toml();
    refused(
        &format!("profile = \"physical\"\n{phong}"),
        "materials[1].type is phong, one of the course's BRDF models",
    );
    refused(
        &format!("profile = \"bookish\"\n{phong}"),
        "unknown variant `bookish`",
    );
    // A texture file that is not an image, relative to the scene file's folder.
    assert_render_refused(
        &[
            (
                "scene.toml",
                &with_line(&good, "generated = \"earth\"", "file = \"earth.png\""),
            ),
            ("earth.png", "not a picture"),
        ],
        &command,
        "earth.png': not a PNG or JPEG image",
    );
    // The command line.
    assert_render_refused(
        &[],
        &["render", "week08-phong", "--profile", "physical"],
        "--profile physical",
    );
    assert_render_refused(
        &[],
        &["render", "week08-phong", "--profile", "book"],
        "'book' is not a profile",
    );
    assert_render_refused(
        &[],
        &["render", "week07-earth", "--textures", "nowhere"],
        "--textures nowhere: no such folder",
    );
    assert_render_refused(
        &[],
        &["render", "week07-earth", "--textures", "."],
        "no earthmap.jpg or earthmap.png there (the course's earth texture)",
    );
    assert_render_refused(
        &[("scene.toml", &good)],
        &["render", "scene.toml", "--textures", "."],
        "--textures: scene.toml is a scene file",
    );
}

/// A texture file is named relative to the scene file's folder, wherever `render` runs, and
/// it is what the image shows: a scene file naming a copy of a generated picture renders the
/// same bytes as the built-in with the generated picture.
#[test]
fn a_texture_file_is_read_relative_to_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("scenes")).unwrap();
    // Each generated picture under the course's file name (the earth is `earthmap`).
    for name in rtoracle::scene::GENERATED_PICTURES {
        let picture = rtoracle::scene::generated_picture(name).unwrap();
        let stem = if *name == "earth" { "earthmap" } else { name };
        rtoracle::image_io::write_png(
            &dir.path().join(format!("scenes/{stem}.png")),
            &rtoracle::image_io::Rgb8Image {
                width: picture.width,
                height: picture.height,
                data: picture.data,
            },
        )
        .unwrap();
    }
    let text = builtin("week07-earth")
        .unwrap()
        .to_toml()
        .replace("generated = \"earth\"", "file = \"earthmap.png\"");
    assert!(text.contains("file = \"earthmap.png\""), "{text}");
    std::fs::write(dir.path().join("scenes/earth.toml"), text).unwrap();
    let args = ["--spp", "2", "--width", "60", "-o"];
    let from_file = run_in(
        dir.path(),
        &[&["render", "scenes/earth.toml"][..], &args, &["a.png"]].concat(),
    );
    assert!(
        from_file.status.success(),
        "{}",
        String::from_utf8_lossy(&from_file.stderr)
    );
    let builtin = run_in(
        dir.path(),
        &[&["render", "week07-earth"][..], &args, &["b.png"]].concat(),
    );
    assert!(builtin.status.success());
    assert_eq!(
        std::fs::read(dir.path().join("a.png")).unwrap(),
        std::fs::read(dir.path().join("b.png")).unwrap()
    );
    // --textures DIR with the course's names gives the same scene, with the files' absolute
    // paths.
    let dumped = run_in(
        dir.path(),
        &["scenes", "--dump", "week07-earth", "--textures", "scenes"],
    );
    let text = String::from_utf8(dumped.stdout).unwrap();
    let path = dir.path().join("scenes/earthmap.png");
    assert!(
        text.contains(&format!("file = \"{}\"", path.display())),
        "{text}"
    );
}

/// `bench render` times four scenes, week 4's, week 6's dielectric (seven bounces of mirror,
/// glass and Lambertian) and week 8's Phong (shadow rays and BRDFs), against `benches/baseline.c`,
/// and reports that the C loop rendered each one's film bit for bit; and the films on all
/// threads are the one-thread films. Without a C compiler the C columns say why, and the rest
/// still runs. Against Mitsuba 3 it times both shared scenes on the scalar variant where Python
/// imports mitsuba (required with `RTORACLE_REQUIRE_MITSUBA=1`), and says it skipped with a
/// Python that cannot run it.
#[test]
fn bench_render_finds_the_c_loops_films_the_same_bit_for_bit() {
    let has_cc = std::process::Command::new("cc")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    let run = |cc: &str, python: &str| {
        let out = rtoracle()
            .args(["bench", "render", "--runs", "1", "--memory-width", "16"])
            .args(["--cc", cc, "--mitsuba-spp", "2", "--python", python])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        stdout
    };
    let scenes = [
        "week04-sphere",
        "week04-quad",
        "week06-dielectric",
        "week08-phong",
    ];
    let has_mitsuba = std::process::Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .is_ok_and(|o| o.status.success());
    if has_cc {
        let stdout = run("cc", "python3");
        for scene in scenes {
            let row = stdout
                .lines()
                .find(|l| l.trim_start().starts_with(scene))
                .unwrap_or_else(|| panic!("no row for {scene}: {stdout}"));
            assert!(row.ends_with("x  yes"), "{row}");
        }
        assert!(
            stdout.contains("same film as on one thread: yes")
                || stdout.contains("this machine has one core"),
            "{stdout}"
        );
        if has_mitsuba {
            for scene in ["week05-quad", "week05-quad-light"] {
                let row = stdout
                    .lines()
                    .find(|l| l.trim_start().starts_with(&format!("{scene} ")))
                    .unwrap_or_else(|| panic!("no Mitsuba row for {scene}: {stdout}"));
                assert!(
                    row.contains("scalar_rgb") && row.contains("Mitsuba"),
                    "{row}"
                );
                let ratios = row
                    .split_whitespace()
                    .filter_map(|w| w.strip_suffix('x')?.parse::<f64>().ok())
                    .filter(|r| r.is_finite() && *r > 0.0)
                    .count();
                assert_eq!(ratios, 2, "one ratio on one thread, one on all: {row}");
            }
            assert!(
                stdout.contains(
                    "goal: ahead of Mitsuba's scalar_rgb on every scene, on one core and on all: "
                ),
                "{stdout}"
            );
        } else {
            assert!(
                std::env::var_os("RTORACLE_REQUIRE_MITSUBA").is_none(),
                "RTORACLE_REQUIRE_MITSUBA is set and python3 cannot import mitsuba"
            );
            eprintln!(
                "SKIPPED: python3 cannot import mitsuba, bench render's Mitsuba rows not run"
            );
        }
    } else {
        eprintln!("SKIPPED: no `cc` here, the C loop's films were not compared");
    }
    let stdout = run("/nonexistent/cc", "/nonexistent/python");
    assert!(
        stdout
            .contains("against Mitsuba 3 (scalar_rgb): skipped, /nonexistent/python cannot run it")
            && stdout.contains("goal: ahead of Mitsuba's scalar_rgb: not measured"),
        "{stdout}"
    );
    // The reason names the program, not the embedded timer's whole source.
    let skipped = stdout
        .lines()
        .find(|l| l.starts_with("against Mitsuba 3"))
        .unwrap();
    assert!(
        skipped.contains("cannot start /nonexistent/python: ") && skipped.len() < 300,
        "{skipped}"
    );
    for scene in scenes {
        let row = stdout
            .lines()
            .find(|l| l.trim_start().starts_with(scene))
            .unwrap();
        assert!(
            row.contains("skipped: no C compiler '/nonexistent/cc'"),
            "{row}"
        );
    }
    assert!(
        stdout.contains("not measured (the C loop was skipped)"),
        "{stdout}"
    );
}
