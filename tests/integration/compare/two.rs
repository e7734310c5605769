//! `rtoracle compare A B`: two renders of the same scene compared with no golden. Renders of one
//! scene with different seeds pass; a render of the scene with one material changed, or a copy
//! scaled by 0.9, fails; bad input exits 2 in one line. Every seed is fixed, so each outcome is
//! deterministic.

use std::path::Path;

use crate::common::*;

/// The scene the tests render: the week-5 quads lit by the right quad (uniform pixel sampling,
/// so the variance layer is the spread of independent samples).
const SCENE: &str = "week05-quad-light";

/// Renders `scene` (a built-in name or a scene file in `dir`) at 100x100, 64 spp, to `out`.
fn render(dir: &Path, scene: &str, seed: u64, variance: bool, out: &str) {
    let seed = seed.to_string();
    let mut args = vec![
        "render", scene, "--width", "100", "--spp", "64", "--seed", &seed, "-o", out,
    ];
    if variance {
        args.push("--variance");
    }
    let o = run_in(dir, &args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn compare(dir: &Path, a: &str, b: &str, json: bool) -> (Option<i32>, String) {
    let mut args = vec!["compare", a, b];
    if json {
        args.push("--json");
    }
    let o = run_in(dir, &args);
    assert!(
        o.stderr.is_empty(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.code(), String::from_utf8(o.stdout).unwrap())
}

/// Two renders with variance layers, and two folders of four renders each, all with different
/// seeds, pass; so do 20 further pairs of seeds (at a per-image false-failure rate of 1e-4 one
/// failure among them would be a 0.2% event).
#[test]
fn renders_of_one_scene_with_different_seeds_pass() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, SCENE, 1, true, "a.exr");
    render(d, SCENE, 2, true, "b.exr");
    let (code, text) = compare(d, "a.exr", "b.exr", false);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.starts_with("PASS a.exr (64 spp, its variance layer) against b.exr (64 spp"),
        "{text}"
    );
    let (code, json) = compare(d, "a.exr", "b.exr", true);
    assert_eq!(code, Some(0));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["verdict"], "pass");
    assert_eq!(v["scales"].as_array().unwrap().len(), 4);

    for side in ["x", "y"] {
        std::fs::create_dir(d.join(side)).unwrap();
    }
    for k in 0..4u64 {
        render(d, SCENE, 10 + k, false, &format!("x/{k}.exr"));
        render(d, SCENE, 20 + k, false, &format!("y/{k}.exr"));
    }
    let (code, text) = compare(d, "x", "y", false);
    assert_eq!(code, Some(0), "{text}");
    assert!(
        text.contains("x (4 renders) against y (4 renders)"),
        "{text}"
    );
    let (code, text) = compare(d, "x", "b.exr", false);
    assert_eq!(code, Some(0), "{text}");

    for pair in 0..20u64 {
        render(d, SCENE, 100 + 2 * pair, true, "p.exr");
        render(d, SCENE, 101 + 2 * pair, true, "q.exr");
        let (code, text) = compare(d, "p.exr", "q.exr", false);
        assert_eq!(code, Some(0), "pair {pair}: {text}");
    }
}

/// The back wall's green albedo halved: every path that reaches the camera off that wall
/// carries half the green, so B is darker in green there; the comparison fails and says where.
#[test]
fn a_render_with_one_material_changed_fails() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dump = run_in(d, &["scenes", "--dump", SCENE]);
    let text = String::from_utf8(dump.stdout).unwrap();
    let from = "albedo = [0.2, 1.0, 0.2]";
    assert_eq!(text.matches(from).count(), 1, "{text}");
    std::fs::write(
        d.join("changed.toml"),
        text.replace(from, "albedo = [0.2, 0.5, 0.2]"),
    )
    .unwrap();
    render(d, SCENE, 1, true, "a.exr");
    render(d, "changed.toml", 2, true, "b.exr");
    let (code, text) = compare(d, "a.exr", "b.exr", false);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.starts_with("FAIL a.exr"), "{text}");
    let (_, json) = compare(d, "a.exr", "b.exr", true);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["verdict"], "fail");
    // A is the brighter in green, and the strongest region is in green.
    assert!(v["bias"][1].as_f64().unwrap() > 0.0, "{json}");
    assert_eq!(v["regions"][0]["channel"], "G", "{json}");
}

/// B's film scaled by 0.9 (its variance by 0.81) fails against A; the same film written back
/// unscaled passes, so the failure is the scale's, not the rewriting's.
#[test]
fn a_copy_scaled_by_nine_tenths_fails() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, SCENE, 1, true, "a.exr");
    render(d, SCENE, 2, true, "b.exr");
    let image = rtoracle::image_io::read_exr(&d.join("b.exr")).unwrap();
    let film = image.to_film(64);
    rtoracle::image_io::write_exr(&d.join("same.exr"), &film, &image.attributes).unwrap();
    let mut scaled = image.to_film(64);
    for m in &mut scaled.mean {
        *m *= 0.9;
    }
    for v in scaled.variance.iter_mut().flatten() {
        *v *= 0.81;
    }
    rtoracle::image_io::write_exr(&d.join("scaled.exr"), &scaled, &image.attributes).unwrap();
    let (code, text) = compare(d, "a.exr", "same.exr", false);
    assert_eq!(code, Some(0), "{text}");
    let (code, json) = compare(d, "a.exr", "scaled.exr", true);
    assert_eq!(code, Some(1), "{json}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    // The whole image is 10% darker: the global scale sees it in every channel.
    assert_eq!(v["scales"][3]["failing"], 3, "{json}");
}

/// A missing file, a folder without EXRs, renders of different sizes, one EXR without a
/// variance layer, a folder holding the same render twice, and a golden given with B: exit 2,
/// one line naming the input.
#[test]
fn bad_input_exits_2_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    render(d, SCENE, 1, true, "a.exr");
    render(d, SCENE, 2, false, "plain.exr");
    let o = run_in(
        d,
        &[
            "render",
            SCENE,
            "--width",
            "50",
            "--spp",
            "4",
            "--variance",
            "-o",
            "small.exr",
        ],
    );
    assert!(o.status.success());
    std::fs::create_dir(d.join("empty")).unwrap();
    std::fs::write(d.join("empty/notes.txt"), "no renders here").unwrap();
    std::fs::create_dir(d.join("twice")).unwrap();
    std::fs::copy(d.join("plain.exr"), d.join("twice/1.exr")).unwrap();
    std::fs::copy(d.join("plain.exr"), d.join("twice/2.exr")).unwrap();
    let cases: [(&[&str], &str); 7] = [
        (&["a.exr", "missing.exr"], "missing.exr: no such file"),
        (&["empty", "a.exr"], "empty: the folder holds no .exr"),
        (
            &["a.exr", "small.exr"],
            "small.exr: is 50x50 but a.exr is 100x100",
        ),
        (
            &["plain.exr", "a.exr"],
            "plain.exr: one render without a variance layer",
        ),
        (&["a.exr", "twice"], "is the same render as"),
        (&["a.exr", "a.exr", "--scene", SCENE], "cannot be used with"),
        (&["a.exr", "notes.png"], "notes.png"),
    ];
    std::fs::write(d.join("notes.png"), "not an image").unwrap();
    for (args, needle) in cases {
        let out = run_in(d, &[&["compare"][..], args].concat());
        assert_bad_input(&out, needle);
        assert!(out.stdout.is_empty());
    }
    // A PNG cannot hold the variance layers `--variance` asks for: refused, nothing written.
    let out = run_in(d, &["render", SCENE, "--variance", "-o", "v.png"]);
    assert_bad_input(&out, "--variance: v.png is not an .exr output");
    assert!(!d.join("v.png").exists());
}
