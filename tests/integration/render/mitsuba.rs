//! The reference checked by an independent renderer: scenes written by `rtoracle scenes --export
//! mitsuba` (or `scene::to_mitsuba_xml`) are rendered by Mitsuba 3 (PyPI `mitsuba`, its
//! `scalar_rgb` variant) and compared with rtoracle's own renders by `rtoracle compare A B`.
//! Without the `mitsuba` module for `python3` the tests say they skipped (`.ci/run` installs
//! it); `RTORACLE_REQUIRE_MITSUBA=1` makes its absence a failure.

use std::path::Path;

use rtoracle::scene::{
    Background, MaterialEntry, MaterialKind, ObjectEntry, Profile, SceneDescription,
};

use crate::common::run_in;

/// Whether `python3` imports mitsuba (else says the test skipped, or fails when required).
fn mitsuba(test: &str) -> bool {
    let ok = std::process::Command::new("python3")
        .args(["-c", "import mitsuba"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os("RTORACLE_REQUIRE_MITSUBA").is_none_or(|v| v != "1"),
            "{test}: python3 cannot import mitsuba and RTORACLE_REQUIRE_MITSUBA=1"
        );
        eprintln!("skipped {test}: python3 cannot import mitsuba (python3 -m pip install mitsuba)");
    }
    ok
}

/// Renders `xml` (written to `dir/NAME.xml`) with Mitsuba `renders` times at `spp` into the
/// folder `dir/NAME-mitsuba/`.
fn render_in_mitsuba(dir: &Path, name: &str, xml: &str, spp: u32, renders: u32) {
    let file = dir.join(format!("{name}.xml"));
    std::fs::write(&file, xml).unwrap();
    let out_dir = dir.join(format!("{name}-mitsuba"));
    std::fs::create_dir_all(&out_dir).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mitsuba/render.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(&file)
        .arg(out_dir.join("render"))
        .args([spp.to_string(), renders.to_string()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "mitsuba on {name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `rtoracle compare NAME-mitsuba/ NAME-ref.exr`: the exit code and the summary.
fn compare(dir: &Path, name: &str) -> (Option<i32>, String) {
    let out = run_in(
        dir,
        &[
            "compare",
            &format!("{name}-mitsuba"),
            &format!("{name}-ref.exr"),
        ],
    );
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.code(), text)
}

/// The size the tests render at: `width` wide, the scene's aspect.
fn resize(xml: &str, from: (usize, usize), to: (usize, usize)) -> String {
    xml.replace(
        &format!("<integer name=\"width\" value=\"{}\"/>", from.0),
        &format!("<integer name=\"width\" value=\"{}\"/>", to.0),
    )
    .replace(
        &format!("<integer name=\"height\" value=\"{}\"/>", from.1),
        &format!("<integer name=\"height\" value=\"{}\"/>", to.1),
    )
}

/// Week 5's lit quads in the physical profile (Lambertian quads, a two-sided quad light, the
/// flat 0.01 background, depth 8): Mitsuba's path tracer (light sampling, MIS, Russian roulette)
/// and the reference's (the book's, no light sampling) agree within their noise, 100x100, 4
/// Mitsuba renders of 256 spp against a reference render of 1024 spp with its variance layer.
/// And the comparison can fail: the same scene with the light 10% brighter in Mitsuba fails.
#[test]
fn mitsuba_agrees_with_the_reference_on_week5_s_lit_quads() {
    if !mitsuba("mitsuba_agrees_with_the_reference_on_week5_s_lit_quads") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let name = "week05-quad-light";
    let export = run_in(
        dir,
        &[
            "scenes",
            "--export",
            "mitsuba",
            name,
            "--profile",
            "physical",
        ],
    );
    assert_eq!(export.status.code(), Some(0), "{export:?}");
    let xml = resize(
        &String::from_utf8(export.stdout).unwrap(),
        (400, 400),
        (100, 100),
    );
    let reference = run_in(
        dir,
        &[
            "render",
            name,
            "--profile",
            "physical",
            "--width",
            "100",
            "--spp",
            "1024",
            "--variance",
            "-o",
            &format!("{name}-ref.exr"),
        ],
    );
    assert_eq!(reference.status.code(), Some(0), "{reference:?}");
    render_in_mitsuba(dir, name, &xml, 256, 4);
    let (code, text) = compare(dir, name);
    assert_eq!(code, Some(0), "{text}");
    // The light 10% brighter: a difference the comparison must see.
    let light = rtoracle::scene::builtin(name)
        .unwrap()
        .materials
        .into_iter()
        .find(|m| m.kind == MaterialKind::DiffuseLight)
        .unwrap();
    let value = |v: [f64; 3]| format!("{:?}, {:?}, {:?}", v[0], v[1], v[2]);
    let brighter = xml.replace(
        &format!(
            "<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/>",
            value(light.albedo)
        ),
        &format!(
            "<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/>",
            value(light.albedo.map(|x| x * 1.1))
        ),
    );
    assert_ne!(brighter, xml);
    std::fs::copy(
        dir.join(format!("{name}-ref.exr")),
        dir.join("brighter-ref.exr"),
    )
    .unwrap();
    render_in_mitsuba(dir, "brighter", &brighter, 256, 4);
    let (code, text) = compare(dir, "brighter");
    assert_eq!(code, Some(1), "{text}");
}

/// A scene of spheres and quads with a perfect mirror (a two-sided conductor in Mitsuba), a
/// Lambertian sphere and floor, under a quad light and a flat grey environment: the two agree,
/// 96x72, 4 Mitsuba renders of 256 spp against 1024 reference spp.
#[test]
fn mitsuba_agrees_with_the_reference_on_a_mirror_and_diffuse_scene() {
    if !mitsuba("mitsuba_agrees_with_the_reference_on_a_mirror_and_diffuse_scene") {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mut d = SceneDescription::new(
        rtoracle::scene::ImageSettings {
            width: 96,
            aspect_ratio: 4.0 / 3.0,
            samples_per_pixel: 256,
        },
        rtoracle::scene::CameraSettings {
            look_from: [0.0, 1.0, 3.0],
            look_at: [0.0, 0.5, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov: 50.0,
            focus_distance: 1.0,
            defocus_angle: 0.0,
        },
        vec![
            MaterialEntry::new("floor", MaterialKind::Lambertian, [0.7, 0.7, 0.6]),
            MaterialEntry::new("red", MaterialKind::Lambertian, [0.8, 0.2, 0.1]),
            MaterialEntry::new("mirror", MaterialKind::Mirror, [0.9, 0.9, 0.9]),
            MaterialEntry::new("lamp", MaterialKind::DiffuseLight, [4.0, 4.0, 3.5]),
        ],
        vec![
            ObjectEntry::Quad {
                q: [-3.0, 0.0, 3.0],
                u: [6.0, 0.0, 0.0],
                v: [0.0, 0.0, -6.0],
                material: "floor".into(),
            },
            ObjectEntry::Sphere {
                center: [-0.6, 0.5, 0.0],
                radius: 0.5,
                material: "mirror".into(),
                moving_center: None,
            },
            ObjectEntry::Sphere {
                center: [0.6, 0.5, -0.3],
                radius: 0.5,
                material: "red".into(),
                moving_center: None,
            },
            ObjectEntry::Quad {
                q: [-0.5, 2.5, -0.5],
                u: [1.0, 0.0, 0.0],
                v: [0.0, 0.0, 1.0],
                material: "lamp".into(),
            },
        ],
    );
    d.profile = Profile::Physical;
    d.render.max_depth = 10;
    d.render.background = Background::Flat;
    d.render.background_color = [0.2, 0.2, 0.25];
    let xml = rtoracle::scene::to_mitsuba_xml(&d).unwrap();
    std::fs::write(dir.join("mirror.toml"), d.to_toml()).unwrap();
    let reference = run_in(
        dir,
        &[
            "render",
            "mirror.toml",
            "--spp",
            "1024",
            "--variance",
            "-o",
            "mirror-ref.exr",
        ],
    );
    assert_eq!(reference.status.code(), Some(0), "{reference:?}");
    render_in_mitsuba(dir, "mirror", &xml, 256, 4);
    let (code, text) = compare(dir, "mirror");
    assert_eq!(code, Some(0), "{text}");
}

/// What the two do not share is refused from the command line in one line, exit 2: a course
/// scene (unless in the physical profile), a sky, a dielectric.
#[test]
fn scenes_mitsuba_does_not_share_are_refused_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (
            vec!["scenes", "--export", "mitsuba", "week05-quad"],
            "course-profile",
        ),
        (
            vec!["scenes", "--export", "mitsuba", "rtiow-materials"],
            "sky",
        ),
        (
            vec!["scenes", "--export", "mitsuba", "no-such-scene"],
            "no-such-scene",
        ),
        (
            vec!["scenes", "--export", "blender", "week05-quad"],
            "blender",
        ),
        (vec!["scenes", "--export", "mitsuba"], "NAME"),
        (vec!["scenes", "--profile", "physical"], "--profile"),
    ] {
        crate::common::assert_bad_input(&run_in(tmp.path(), &args), needle);
    }
}
