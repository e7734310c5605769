//! An instructor's own assignment end to end: the triangle rubric of `examples/rubrics`
//! (a triangle code group and an image group on the scene file beside it), the golden cache,
//! `rtoracle golden FILE.toml`, the autograder package with the scene and its golden, rubric
//! validation, and `rtoracle check` with no argument in a submission folder.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;
use std::time::SystemTime;

use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::common::*;
use rtoracle::image_io::{Rgb8Image, write_png};
use rtoracle::render::{RenderOptions, render};
use rtoracle::scene::SceneDescription;

const RENDER_NOTE: &str = "rendering the golden of";

fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn rubric_path() -> PathBuf {
    crate_dir().join("examples/rubrics/triangles.toml")
}

fn scene_path() -> PathBuf {
    crate_dir().join("examples/rubrics/triangles-scene.toml")
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// A course submission in `dest`: the shared course modules, the `RT_object.py` of
/// `tests/fixtures/python/triangle_assignment/<variant>` and, when given, the image.
fn submission(dest: &Path, variant: &str, image: Option<&Rgb8Image>) {
    std::fs::create_dir_all(dest).unwrap();
    let python = crate_dir().join("tests/fixtures/python");
    for e in std::fs::read_dir(python.join("common")).unwrap().flatten() {
        std::fs::copy(e.path(), dest.join(e.file_name())).unwrap();
    }
    std::fs::copy(
        python
            .join("triangle_assignment")
            .join(variant)
            .join("RT_object.py"),
        dest.join("RT_object.py"),
    )
    .unwrap();
    if let Some(image) = image {
        write_png(&dest.join("triangles-scene.png"), image).unwrap();
    }
}

/// An honest student's image: the reference's render of the scene file at the assignment's
/// 20 spp with a seed of the student's (not the golden's).
fn honest_image(seed: u64) -> Rgb8Image {
    let d = SceneDescription::from_file(&scene_path()).unwrap();
    let film = render(
        &d.scene(),
        &d.camera(None),
        &RenderOptions {
            samples_per_pixel: 20,
            seed,
            ..Default::default()
        },
    )
    .unwrap();
    Rgb8Image {
        width: film.width,
        height: film.height,
        data: film.to_course_rgb8(),
    }
}

/// The same image upside down (rows in reverse order).
fn flipped(image: &Rgb8Image) -> Rgb8Image {
    let row = 3 * image.width;
    let data = image.data.chunks(row).rev().flatten().copied().collect();
    Rgb8Image {
        data,
        ..image.clone()
    }
}

fn cache_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("goldens"))
        .map(|rd| rd.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files
}

struct Graded {
    root: PathBuf,
    cache: PathBuf,
    subs: PathBuf,
    out: PathBuf,
    output: Output,
}

/// Three submissions graded as one batch with the triangle rubric and a cold cache.
fn graded() -> &'static Graded {
    static GRADED: OnceLock<Graded> = OnceLock::new();
    GRADED.get_or_init(|| {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("triangle-assignment");
        let _ = std::fs::remove_dir_all(&root);
        let subs = root.join("subs");
        let honest = honest_image(11);
        submission(&subs.join("honest"), "", Some(&honest));
        submission(&subs.join("flipped"), "", Some(&flipped(&honest)));
        submission(
            &subs.join("parallelogram"),
            "bug_parallelogram",
            Some(&honest_image(12)),
        );
        let cache = root.join("cache");
        let out = root.join("out");
        let output = rtoracle()
            .current_dir(&root)
            .env("RTORACLE_CACHE_DIR", &cache)
            .args(["grade", "--batch", "subs", "--out", "out", "--rubric"])
            .arg(rubric_path())
            .output()
            .unwrap();
        assert!(output.status.success(), "{}", stderr(&output));
        Graded {
            root,
            cache,
            subs,
            out,
            output,
        }
    })
}

fn scores(report: &Value) -> Vec<(String, f64, f64)> {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["max_score"].as_f64().unwrap() > 0.0)
        .map(|c| {
            (
                c["id"].as_str().unwrap().to_string(),
                c["score"].as_f64().unwrap(),
                c["max_score"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn honest_gets_full_marks_a_flipped_image_zero_and_a_triangle_bug_loses_triangle_points() {
    let g = graded();
    let honest = read_json(&g.out.join("honest/report.json"));
    assert_eq!(honest["score"], 100.0, "{:?}", scores(&honest));
    assert_eq!(honest["max_score"], 100.0);

    let flipped = read_json(&g.out.join("flipped/report.json"));
    let s = scores(&flipped);
    assert_eq!(
        s,
        [
            ("triangle.intersect".to_string(), 60.0, 60.0),
            ("image.triangles-scene".to_string(), 0.0, 40.0)
        ],
        "{s:?}"
    );
    let image = flipped["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "image.triangles-scene")
        .unwrap();
    assert_eq!(image["status"], "failed");
    assert_eq!(image["image"]["file"], "triangles-scene.png");
    assert_eq!(image["image"]["scene"], "triangles-scene.toml");

    let bug = read_json(&g.out.join("parallelogram/report.json"));
    let s = scores(&bug);
    assert_eq!(s[1], ("image.triangles-scene".to_string(), 40.0, 40.0));
    assert_eq!(s[0].0, "triangle.intersect");
    assert!(s[0].1 < 60.0, "{s:?}");
}

#[test]
fn a_batch_renders_the_golden_once_and_a_warm_cache_renders_nothing() {
    let g = graded();
    // Three submissions, one golden rendered and cached.
    assert_eq!(
        stderr(&g.output).matches(RENDER_NOTE).count(),
        1,
        "{}",
        stderr(&g.output)
    );
    let files = cache_files(&g.cache);
    assert_eq!(files.len(), 1, "{files:?}");
    let name = files[0].file_name().unwrap().to_string_lossy().to_string();
    let d = SceneDescription::from_file(&scene_path()).unwrap();
    assert!(
        name.starts_with(&rtoracle::golden::scene_sha256(&d))
            && name.ends_with(&format!("-{}.exr", env!("CARGO_PKG_VERSION"))),
        "{name}"
    );
    let mtime = |p: &Path| -> SystemTime { std::fs::metadata(p).unwrap().modified().unwrap() };
    let before = (mtime(&files[0]), std::fs::read(&files[0]).unwrap());
    let again = rtoracle()
        .current_dir(&g.root)
        .env("RTORACLE_CACHE_DIR", &g.cache)
        .args(["grade", "subs/honest", "--out", "again", "--rubric"])
        .arg(rubric_path())
        .output()
        .unwrap();
    assert!(again.status.success(), "{}", stderr(&again));
    assert!(!stderr(&again).contains(RENDER_NOTE), "{}", stderr(&again));
    assert_eq!(
        (mtime(&files[0]), std::fs::read(&files[0]).unwrap()),
        before
    );
    assert_eq!(read_json(&g.root.join("again/report.json"))["score"], 100.0);
}

#[test]
fn report_json_records_the_sha256_of_the_scene_file_and_of_the_golden() {
    let g = graded();
    let report = read_json(&g.out.join("honest/report.json"));
    let r = &report["reproducibility"];
    let scene = std::fs::read(scene_path()).unwrap();
    assert_eq!(
        r["scenes_sha256"]["triangles-scene.toml"],
        sha256_hex(&scene)
    );
    let golden = std::fs::read(&cache_files(&g.cache)[0]).unwrap();
    assert_eq!(
        r["goldens_sha256"]["triangles-scene.toml"],
        sha256_hex(&golden)
    );
    assert_eq!(
        r["submission_sha256"]["triangles-scene.png"],
        sha256_hex(&std::fs::read(g.subs.join("honest/triangles-scene.png")).unwrap())
    );
}

#[test]
fn the_golden_command_writes_the_bytes_the_cache_holds_and_a_rubric_accepts_them() {
    let g = graded();
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(scene_path(), dir.path().join("triangles-scene.toml")).unwrap();
    let out = run_in(
        dir.path(),
        &["golden", "triangles-scene.toml", "-o", "tri.exr"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // Same scene, samples, seed and version: the same bytes as the golden the grader rendered.
    let made = std::fs::read(dir.path().join("tri.exr")).unwrap();
    assert_eq!(made, std::fs::read(&cache_files(&g.cache)[0]).unwrap());
    // A rubric naming it grades without any cache and without rendering.
    let rubric = std::fs::read_to_string(rubric_path()).unwrap().replace(
        "scene = \"triangles-scene.toml\"",
        "scene = \"triangles-scene.toml\"\ngolden = \"tri.exr\"",
    );
    std::fs::write(dir.path().join("r.toml"), rubric).unwrap();
    let empty = dir.path().join("empty-cache");
    std::fs::create_dir(&empty).unwrap();
    let graded = rtoracle()
        .current_dir(dir.path())
        .env("RTORACLE_CACHE_DIR", &empty)
        .args(["grade", "--rubric", "r.toml", "--out", "out"])
        .arg(g.subs.join("honest"))
        .output()
        .unwrap();
    assert!(graded.status.success(), "{}", stderr(&graded));
    assert!(!stderr(&graded).contains(RENDER_NOTE));
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
    let report = read_json(&dir.path().join("out/report.json"));
    assert_eq!(report["score"], 100.0);
    assert_eq!(
        report["reproducibility"]["goldens_sha256"]["triangles-scene.toml"],
        sha256_hex(&made)
    );
}

#[test]
fn the_autograder_package_carries_the_scene_and_its_golden_so_gradescope_never_renders() {
    let g = graded();
    let dir = tempfile::tempdir().unwrap();
    // Packing with the warm cache renders nothing either.
    let out = rtoracle()
        .current_dir(dir.path())
        .env("RTORACLE_CACHE_DIR", &g.cache)
        .args(["autograder", "--out", "autograder.zip", "--rubric"])
        .arg(rubric_path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let root = dir.path().join("autograder");
    let source = root.join("source");
    let file = std::fs::File::open(dir.path().join("autograder.zip")).unwrap();
    let mut archive = zip::ZipArchive::new(file).unwrap();
    let mut names: Vec<String> = archive.file_names().map(String::from).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "rtoracle",
            "rtoracle-scenes/triangles-scene.exr",
            "rtoracle-scenes/triangles-scene.toml",
            "rubric.toml",
            "run_autograder",
            "setup.sh"
        ]
    );
    archive.extract(&source).unwrap();
    assert_eq!(
        std::fs::read(source.join("rtoracle-scenes/triangles-scene.toml")).unwrap(),
        std::fs::read(scene_path()).unwrap()
    );
    assert_eq!(
        std::fs::read(source.join("rtoracle-scenes/triangles-scene.exr")).unwrap(),
        std::fs::read(&cache_files(&g.cache)[0]).unwrap()
    );
    // Install and run it as Gradescope would, with an empty cache.
    let prefix = dir.path().join("prefix");
    let empty = dir.path().join("empty-cache");
    std::fs::create_dir(&empty).unwrap();
    let setup = std::process::Command::new("bash")
        .arg(source.join("setup.sh"))
        .env("PREFIX", &prefix)
        .output()
        .unwrap();
    assert!(setup.status.success(), "{}", stderr(&setup));
    copy_dir(&g.subs.join("honest"), &root.join("submission"));
    let run = std::process::Command::new("bash")
        .arg(source.join("run_autograder"))
        .env("PREFIX", &prefix)
        .env("AUTOGRADER", &root)
        .env("RTORACLE_CACHE_DIR", &empty)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(!stderr(&run).contains(RENDER_NOTE), "{}", stderr(&run));
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
    let results = read_json(&root.join("results/results.json"));
    assert_eq!(results["score"], 100.0, "{results}");
    // Students read of their scene by its name, not of the package's folder for it.
    let text = results.to_string();
    assert!(
        text.contains("the reference of triangles-scene.toml"),
        "{text}"
    );
    assert!(!text.contains("rtoracle-scenes/"), "{text}");
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

#[test]
fn rubric_scene_file_errors_exit_2_with_one_line_naming_the_rubric() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let scene = std::fs::read_to_string(scene_path()).unwrap();
    std::fs::write(p.join("tri.toml"), &scene).unwrap();
    std::fs::write(p.join("broken.toml"), "[image]\nwidth = \"wide\"\n").unwrap();
    // Goldens of other scenes, cheaply (4 spp): a narrower one and one with the sphere moved.
    std::fs::write(
        p.join("narrow.toml"),
        scene.replace("width = 160", "width = 80"),
    )
    .unwrap();
    std::fs::write(
        p.join("moved.toml"),
        scene.replace("center = [0.55, -0.2, -1.2]", "center = [0.5, -0.2, -1.2]"),
    )
    .unwrap();
    for name in ["narrow", "moved"] {
        let out = run_in(
            p,
            &[
                "golden",
                &format!("{name}.toml"),
                "-o",
                &format!("{name}.exr"),
                "--spp",
                "4",
            ],
        );
        assert!(out.status.success(), "{}", stderr(&out));
    }
    std::fs::write(p.join("notexr.exr"), b"not an exr").unwrap();
    std::fs::write(p.join("image.png"), b"not an exr").unwrap();
    let rubric = |scene_line: &str| {
        format!(
            "name = \"t\"\n[[group]]\nid = \"image.t\"\nname = \"T\"\nkind = \"image\"\n{scene_line}\npoints = 10\n"
        )
    };
    let cases = [
        ("scene = \"missing.toml\"", "missing.toml: no such file"),
        ("scene = \"broken.toml\"", "malformed scene file"),
        ("scene = \"tri\"", "unknown scene \"tri\""),
        (
            "scene = \"tri.toml\"\ngolden = \"narrow.exr\"",
            "is 80x80 but the scene is 160x160",
        ),
        (
            "scene = \"tri.toml\"\ngolden = \"moved.exr\"",
            "was made from another scene",
        ),
        (
            "scene = \"tri.toml\"\ngolden = \"nope.exr\"",
            "nope.exr: no such file",
        ),
        (
            "scene = \"tri.toml\"\ngolden = \"notexr.exr\"",
            "notexr.exr",
        ),
        // The command the message suggests must work: `golden -o` wants a .exr name.
        (
            "scene = \"tri.toml\"\ngolden = \"image.png\"",
            "make it with `rtoracle golden tri.toml -o image.exr` and name it in `golden`",
        ),
        // Two groups wanting one image could never both pass.
        (
            "scene = \"tri.toml\"\npoints = 5\n[[group]]\nid = \"image.u\"\nname = \"U\"\n\
             kind = \"image\"\nscene = \"week04-quad\"\nfile = \"tri.png\"",
            "image groups \"image.t\" and \"image.u\" both want the image \"tri.png\"",
        ),
        (
            "scene = \"week04-quad\"\nfile = \"q.png\"\ngolden = \"moved.exr\"",
            "golden is for scene files",
        ),
    ];
    std::fs::create_dir(p.join("sub")).unwrap();
    for (line, needle) in cases {
        std::fs::write(p.join("r.toml"), rubric(line)).unwrap();
        let out = run_in(p, &["grade", "sub", "--rubric", "r.toml", "--out", "o"]);
        assert_bad_input(&out, needle);
        assert!(stderr(&out).contains("r.toml: "), "{}", stderr(&out));
        assert!(!p.join("o").exists(), "{line}");
        // The package is refused the same way, before anything is written.
        let out = run_in(p, &["autograder", "--rubric", "r.toml", "--out", "a.zip"]);
        assert_bad_input(&out, needle);
        assert!(!p.join("a.zip").exists());
    }
    // Paths are relative to the rubric, not to the current folder.
    std::fs::write(p.join("r.toml"), rubric("scene = \"tri.toml\"")).unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let r = p.join("r.toml");
    let out = run_in(
        elsewhere.path(),
        &["grade", "--print-rubric", "--rubric", r.to_str().unwrap()],
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn check_with_no_argument_checks_the_submission_in_the_current_folder() {
    let dir = tempfile::tempdir().unwrap();
    submission(dir.path(), "", None);
    let out = run_in(dir.path(), &["check"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let here = dir.path().canonicalize().unwrap();
    assert!(
        err.lines().next().unwrap().starts_with(&format!(
            "checking the course submission in {}",
            here.display()
        )),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("verdict: PASS"));

    // The triangle bug fails the same way `--python-course .` does.
    submission(dir.path(), "bug_parallelogram", None);
    let bare = run_in(dir.path(), &["check", "--json"]);
    let explicit = run_in(dir.path(), &["check", "--json", "--python-course", "."]);
    assert_eq!(bare.status.code(), Some(1));
    assert_eq!(explicit.status.code(), Some(1));
    let failed = |o: &Output| -> (Value, Value) {
        let v: Value = serde_json::from_slice(&o.stdout).unwrap();
        (
            v["intersections"]["by_shape"].clone(),
            v["intersections"]["failed"].clone(),
        )
    };
    assert_eq!(failed(&bare), failed(&explicit));

    // The folder as an argument is `--python-course FOLDER`; from one folder too high, the
    // message names the submission folder below.
    let parent = dir.path().parent().unwrap();
    let name = dir.path().file_name().unwrap().to_str().unwrap();
    let positional = run_in(parent, &["check", "--json", name]);
    assert_eq!(positional.status.code(), Some(1));
    assert_eq!(failed(&positional), failed(&explicit));
    let above = tempfile::tempdir().unwrap();
    submission(&above.path().join("my-sub"), "", None);
    assert_bad_input(
        &run_in(above.path(), &["check"]),
        "; my-sub has one: `rtoracle check my-sub`",
    );
    assert_bad_input(
        &run_in(above.path(), &["check", "nope"]),
        "nope: no such folder",
    );

    // Outside a submission folder: what it looked for, exit 2.
    let empty = tempfile::tempdir().unwrap();
    let out = run_in(empty.path(), &["check"]);
    assert_bad_input(&out, "no RT_object.py in");
    assert!(stderr(&out).contains("--python-course DIR"));
    assert!(!stderr(&out).contains("has one"));
}

/// For the triangle assignment a student checks with `--require triangle`: an RT_object.py
/// without a usable Triangle then fails (without the flag its triangles are "not run" and the
/// check passes, as week 4 wants), an honest one passes, and a submission that cannot be
/// imported reports the import error on its triangles too, not "does not support triangles".
#[test]
fn check_require_triangle_fails_a_submission_without_triangles() {
    let dir = tempfile::tempdir().unwrap();
    submission(dir.path(), "", None);
    let out = run_in(dir.path(), &["check", "--require", "triangle"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // The same Sphere and Quad, and the Triangle class cut out.
    let object = dir.path().join("RT_object.py");
    let text = std::fs::read_to_string(&object).unwrap();
    let at = text
        .find("class Triangle")
        .expect("the fixture has a Triangle");
    assert!(text[at..].lines().skip(1).all(|l| !l.starts_with("class ")));
    std::fs::write(&object, &text[..at]).unwrap();
    let without = run_in(dir.path(), &["check"]);
    assert_eq!(without.status.code(), Some(0), "{}", stderr(&without));
    let report = String::from_utf8_lossy(&without.stdout).to_string();
    assert!(
        report.contains("not run: 559 triangle vectors: the candidate does not support triangles"),
        "{report}"
    );
    let required = run_in(dir.path(), &["check", "--require", "sphere,triangle"]);
    assert_eq!(required.status.code(), Some(1), "{}", stderr(&required));
    let report = String::from_utf8_lossy(&required.stdout).to_string();
    assert!(report.contains("verdict: FAIL"), "{report}");
    assert!(
        report.contains(
            "required: triangles (--require triangle), but 559 triangle vectors were not run"
        ),
        "{report}"
    );
    assert!(!report.contains("required: spheres"), "{report}");
    assert_bad_input(
        &run_in(dir.path(), &["check", "--require", "cube"]),
        "\"cube\" is not a shape",
    );
    // A syntax error: every triangle vector gets the import error.
    std::fs::write(&object, "class Sphere(:\n").unwrap();
    let broken = run_in(dir.path(), &["check", "--json"]);
    assert_eq!(broken.status.code(), Some(1));
    let v: Value = serde_json::from_slice(&broken.stdout).unwrap();
    assert_eq!(
        v["intersections"]["by_shape"]["triangle"]["errors"],
        v["intersections"]["by_shape"]["triangle"]["total"]
    );
    assert_eq!(v["intersections"]["by_shape"]["triangle"]["not_run"], 0);
    assert!(!String::from_utf8_lossy(&broken.stdout).contains("does not support"));
}

/// A scene file as an instructor writes one: a triangle and a sphere, `spp` samples per pixel.
fn own_scene(width: usize, aspect_ratio: f64, spp: u32, albedo: [f64; 3]) -> String {
    format!(
        "[image]\nwidth = {width}\naspect_ratio = {aspect_ratio:?}\nsamples_per_pixel = {spp}\n\n\
         [camera]\nlook_from = [0.3, 0.4, 1.0]\nlook_at = [0.0, 0.0, -1.5]\nup = [0.0, 1.0, 0.0]\n\
         vfov = 60.0\nfocus_distance = 2.5\n\n\
         [[materials]]\nname = \"tri\"\ntype = \"lambertian\"\nalbedo = {albedo:?}\n\n\
         [[materials]]\nname = \"ball\"\ntype = \"lambertian\"\nalbedo = [0.2, 0.5, 0.9]\n\n\
         [[objects]]\ntype = \"triangle\"\na = [-1.0, -0.6, -1.8]\nb = [0.3, -0.7, -1.6]\n\
         c = [-0.5, 0.8, -1.7]\nmaterial = \"tri\"\n\n\
         [[objects]]\ntype = \"sphere\"\ncenter = [0.6, 0.1, -1.4]\nradius = 0.45\n\
         material = \"ball\"\n"
    )
}

/// The image group of `scene` (a file beside the rubric), judging the uploaded image (these
/// tests are of the judging of uploads; `renders.rs` tests the grader's renders).
fn image_group(id: &str, scene: &str, points: u32) -> String {
    format!(
        "[[group]]\nid = \"image.{id}\"\nname = \"{id}\"\nkind = \"image\"\nscene = \"{scene}\"\n\
         source = \"upload\"\npoints = {points}\n\n"
    )
}

/// Renders `scene` (a TOML file) into `out` with `tests/fixtures/python/independent_render.py`:
/// numpy's random numbers and the course's formulas, none of rtoracle's renderer.
fn independent_render(python: &Path, scene: &Path, out: &Path, seed: u64, flip: bool) {
    let d = SceneDescription::from_file(scene).unwrap();
    let json = out.with_extension("json");
    std::fs::write(&json, serde_json::to_string(&d).unwrap()).unwrap();
    let mut cmd = std::process::Command::new(python);
    cmd.arg(crate_dir().join("tests/fixtures/python/independent_render.py"))
        .arg(&json)
        .arg(out)
        .arg(seed.to_string());
    if flip {
        cmd.arg("flip-y");
    }
    let done = cmd.output().unwrap();
    assert!(done.status.success(), "{}", stderr(&done));
    std::fs::remove_file(json).unwrap();
}

/// Image groups on scene files whose `samples_per_pixel` is not 20 (1 and 50): each image is
/// compared as a render of its scene's sample count with a golden of `max(4096, 100 N)`
/// samples, so an honest render made by another program gets full marks (at 1 spp too: judged
/// as 20 spp, its noise failed every one), a flipped one zero, and `rtoracle golden FILE.toml`
/// writes by default the golden the cache holds.
#[test]
fn honest_independent_renders_of_scene_files_at_1_and_50_spp_get_full_marks_flipped_zero() {
    let Some(python) =
        rtoracle::bench::harness::course_python_or_skip("the independent-render grading test")
    else {
        return;
    };
    let root = tempfile::tempdir().unwrap();
    let p = root.path();
    std::fs::write(p.join("one.toml"), own_scene(120, 1.5, 1, [0.9, 0.3, 0.1])).unwrap();
    std::fs::write(
        p.join("fifty.toml"),
        own_scene(72, 0.75, 50, [0.1, 0.8, 0.3]),
    )
    .unwrap();
    std::fs::write(
        p.join("r.toml"),
        format!(
            "name = \"own\"\nseed = 3\n\n{}{}",
            image_group("one", "one.toml", 50),
            image_group("fifty", "fifty.toml", 50)
        ),
    )
    .unwrap();
    let subs = p.join("subs");
    for (name, seed, flip) in [
        ("honest-1", 1, false),
        ("honest-2", 2, false),
        ("honest-3", 3, false),
        ("flipped", 4, true),
    ] {
        let dir = subs.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        for scene in ["one", "fifty"] {
            let toml = p.join(format!("{scene}.toml"));
            independent_render(
                &python,
                &toml,
                &dir.join(format!("{scene}.png")),
                seed,
                flip,
            );
        }
    }
    let cache = p.join("cache");
    let out = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", &cache)
        .args([
            "grade", "--batch", "subs", "--rubric", "r.toml", "--out", "out",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("(120x80, 4096 spp)") && stderr(&out).contains("(72x96, 5000 spp)"),
        "{}",
        stderr(&out)
    );
    for name in ["honest-1", "honest-2", "honest-3", "flipped"] {
        let report = read_json(&p.join("out").join(name).join("report.json"));
        let want = if name == "flipped" { 0.0 } else { 50.0 };
        let s = scores(&report);
        assert_eq!(
            s,
            [
                ("image.one".to_string(), want, 50.0),
                ("image.fifty".to_string(), want, 50.0)
            ],
            "{name}: {s:?}"
        );
        let checks = report["checks"].as_array().unwrap();
        for (check, spp, golden_spp) in [(&checks[0], 1, 4096), (&checks[1], 50, 5000)] {
            let m = &check["image"]["metrics"];
            assert_eq!(
                (m["candidate_spp"].as_u64(), m["golden_spp"].as_u64()),
                (Some(spp), Some(golden_spp)),
                "{name}"
            );
        }
    }
    // A built-in's name where a scene file is wanted: the command that makes its golden.
    assert_bad_input(
        &run_in(p, &["golden", "week04-quad", "-o", "q.exr"]),
        "names a built-in scene, whose golden `rtoracle golden --scenes week04-quad --dir DIR`",
    );
    assert!(!p.join("q.exr").exists());
    // `golden FILE.toml` with no --spp makes the golden a grading of that scene uses.
    // From the cache the grading filled: the same bytes, rendering nothing.
    let made = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", &cache)
        .args(["golden", "fifty.toml", "-o", "fifty.exr"])
        .output()
        .unwrap();
    assert!(made.status.success(), "{}", stderr(&made));
    assert!(
        String::from_utf8_lossy(&made.stdout).contains("(5000 spp, seed 0,"),
        "{}",
        String::from_utf8_lossy(&made.stdout)
    );
    let d = SceneDescription::from_file(&p.join("fifty.toml")).unwrap();
    assert_eq!(
        std::fs::read(p.join("fifty.exr")).unwrap(),
        std::fs::read(rtoracle::golden::cache_file(
            &cache,
            &rtoracle::golden::GoldenScene::from_description("fifty.toml", d, None).unwrap(),
            5000
        ))
        .unwrap()
    );
}

/// A rubric of images only runs no code: it grades with no Python fit for the course (here
/// `--python /bin/true`) and no warning about a public seed of vectors it never runs, where a
/// rubric with a code group refuses that Python up front. Its scene file leaves out the camera's
/// `up` and `focus_distance`, which take the book's values.
#[test]
fn a_rubric_of_images_only_needs_no_python_and_no_seed() {
    let root = tempfile::tempdir().unwrap();
    let p = root.path();
    let scene = own_scene(64, 1.0, 4, [0.9, 0.3, 0.1])
        .replace("up = [0.0, 1.0, 0.0]\n", "")
        .replace("focus_distance = 2.5\n", "");
    assert!(!scene.contains("up =") && !scene.contains("focus_distance"));
    std::fs::write(p.join("mine.toml"), &scene).unwrap();
    std::fs::write(
        p.join("images.toml"),
        format!(
            "name = \"images\"\n\n{}",
            image_group("mine", "mine.toml", 10)
        ),
    )
    .unwrap();
    std::fs::create_dir(p.join("sub")).unwrap();
    let rendered = run_in(
        p,
        &["render", "mine.toml", "--seed", "5", "-o", "sub/mine.png"],
    );
    assert!(rendered.status.success(), "{}", stderr(&rendered));
    let cache = p.join("cache");
    let grade = |rubric: &str, out: &str| {
        rtoracle()
            .current_dir(p)
            .env("RTORACLE_CACHE_DIR", &cache)
            .args(["grade", "sub", "--rubric", rubric, "--out", out])
            .args(["--python", "/bin/true"])
            .output()
            .unwrap()
    };
    let out = grade("images.toml", "out");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("seed"), "{}", stderr(&out));
    assert!(!stderr(&out).contains("sandbox"), "{}", stderr(&out));
    let report = read_json(&p.join("out/report.json"));
    assert_eq!(scores(&report), [("image.mine".to_string(), 10.0, 10.0)]);
    // Its package has a seed, and says it is not used.
    let packed = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", &cache)
        .args(["autograder", "--rubric", "images.toml", "--out", "a.zip"])
        .output()
        .unwrap();
    assert!(packed.status.success(), "{}", stderr(&packed));
    assert!(
        stderr(&packed).contains("(unused: the rubric has no code group)"),
        "{}",
        stderr(&packed)
    );
    // With a code group the same Python is refused before any grading.
    std::fs::write(
        p.join("code.toml"),
        format!(
            "name = \"code\"\nseed = 4\n\n{}[[group]]\nid = \"sphere\"\nname = \"Spheres\"\n\
             kind = \"code\"\nshape = \"sphere\"\npoints = 10\n",
            image_group("mine", "mine.toml", 10)
        ),
    )
    .unwrap();
    let out = grade("code.toml", "out2");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("/bin/true"), "{}", stderr(&out));
    assert!(!p.join("out2").exists());
}

/// A palette PNG holding exactly an honest render's colours (what a PNG optimiser makes of an
/// image of few colours) is that render: `grade` gives it full marks, as `compare` passes it.
#[test]
fn a_lossless_palette_png_of_an_honest_render_gets_full_marks() {
    let Some(python) = rtoracle::bench::harness::course_python_or_skip("the palette PNG test")
    else {
        return;
    };
    let root = tempfile::tempdir().unwrap();
    let p = root.path();
    std::fs::write(p.join("mine.toml"), own_scene(40, 1.0, 4, [0.9, 0.3, 0.1])).unwrap();
    std::fs::write(
        p.join("r.toml"),
        format!("name = \"pal\"\n\n{}", image_group("mine", "mine.toml", 10)),
    )
    .unwrap();
    std::fs::create_dir(p.join("sub")).unwrap();
    let made = run_in(p, &["render", "mine.toml", "--seed", "9", "-o", "rgb.png"]);
    assert!(made.status.success(), "{}", stderr(&made));
    // Quantised to a palette, and checked to be lossless (the test's premise), by Pillow.
    let script = "import sys\nfrom PIL import Image\nrgb = Image.open(sys.argv[1]).convert('RGB')\n\
                  pal = rgb.convert('P', palette=Image.ADAPTIVE, colors=256)\n\
                  assert list(pal.convert('RGB').getdata()) == list(rgb.getdata()), 'lossy'\n\
                  pal.save(sys.argv[2])\n";
    let done = std::process::Command::new(&python)
        .args(["-c", script])
        .arg(p.join("rgb.png"))
        .arg(p.join("sub/mine.png"))
        .output()
        .unwrap();
    assert!(done.status.success(), "{}", stderr(&done));
    let bytes = std::fs::read(p.join("sub/mine.png")).unwrap();
    assert_eq!(bytes[25], 3, "colour type 3 (palette) in IHDR");
    let cache = p.join("cache");
    let out = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", &cache)
        .args(["grade", "sub", "--rubric", "r.toml", "--out", "out"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let report = read_json(&p.join("out/report.json"));
    assert_eq!(scores(&report), [("image.mine".to_string(), 10.0, 10.0)]);
    let compared = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", &cache)
        .args(["compare", "sub/mine.png", "--scene", "mine.toml"])
        .output()
        .unwrap();
    assert_eq!(compared.status.code(), Some(0), "{}", stderr(&compared));
}

/// An image rendered with far fewer samples than its scene asks for is told so, with the count
/// to render with: the feedback names the noise, not only "no common mistake explains it".
#[test]
fn a_render_with_too_few_samples_is_told_the_count_to_render_with() {
    let root = tempfile::tempdir().unwrap();
    let p = root.path();
    std::fs::write(p.join("mine.toml"), own_scene(64, 1.0, 50, [0.9, 0.3, 0.1])).unwrap();
    std::fs::write(
        p.join("r.toml"),
        format!("name = \"few\"\n\n{}", image_group("mine", "mine.toml", 10)),
    )
    .unwrap();
    std::fs::create_dir(p.join("sub")).unwrap();
    let made = run_in(
        p,
        &[
            "render",
            "mine.toml",
            "--spp",
            "1",
            "--seed",
            "2",
            "-o",
            "sub/mine.png",
        ],
    );
    assert!(made.status.success(), "{}", stderr(&made));
    let out = rtoracle()
        .current_dir(p)
        .env("RTORACLE_CACHE_DIR", p.join("cache"))
        .args(["grade", "sub", "--rubric", "r.toml", "--out", "out"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let report = read_json(&p.join("out/report.json"));
    assert_eq!(scores(&report), [("image.mine".to_string(), 0.0, 10.0)]);
    assert_eq!(
        report["checks"][0]["image"]["metrics"]["noise"]["passed"],
        false
    );
    let message = report["checks"][0]["message"].as_str().unwrap();
    assert!(
        message.contains("noisier than a render of 50 samples per pixel")
            && message.contains("render it with 50 samples per pixel"),
        "{message}"
    );
    let feedback = std::fs::read_to_string(p.join("out/feedback.md")).unwrap();
    assert!(
        feedback.contains("render it with 50 samples per pixel"),
        "{feedback}"
    );
}
