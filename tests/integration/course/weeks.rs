//! The course's weeks 5 to 10 as Python fixtures (`tests/fixtures/python/weeks/`, written from
//! the course's facts): each week's instructor solution and unmodified skeleton render every
//! scene of its `main.py` at a tiny size through the fixtures' own driver (`render_scene.py`),
//! the course's formulas hold on hand-worked cases (run as small Python snippets through
//! `probe.py`), and each catalogued mistake changes what `mistakes.json` says it changes.
//!
//! Nothing here uses rtoracle's renderer: these tests make the fixtures trustworthy for the
//! tests (and graders) that compare them with it. Every expected value is worked out by hand or
//! by a closed form written here, never copied from the fixtures' output. Renders that are
//! compared pixel for pixel use one numpy seed (the driver's `--seed`); the course itself seeds
//! nothing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use image::RgbImage;
use serde_json::{Value, json};

/// The seed of every render compared pixel for pixel.
const SEED: u64 = 11;

fn weeks_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks")
}

/// The Python with numpy and Pillow the fixtures need, or `None` after saying the test is
/// skipped (a failure under `RTORACLE_REQUIRE_PYTHON=1`).
fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| {
            rtoracle::bench::harness::course_python_or_skip("the course-week fixture tests")
        })
        .as_deref()
}

/// What a render of the driver gave: an image, or the exception the course's code raised.
#[derive(Debug)]
enum Rendered {
    Image(RgbImage),
    /// `TYPE: MESSAGE` of the exception.
    Raised(String),
}

impl Rendered {
    fn image(self, what: &str) -> RgbImage {
        match self {
            Rendered::Image(image) => image,
            Rendered::Raised(e) => panic!("{what}: the course's code raised {e}"),
        }
    }
}

/// One render by `render_scene.py`.
#[derive(Clone, Debug)]
struct Job {
    folder: String,
    overlays: Vec<String>,
    function: String,
    width: u32,
    spp: u32,
    no_objects: bool,
}

impl Job {
    fn new(folder: &str, function: &str, width: u32, spp: u32) -> Job {
        Job {
            folder: folder.to_string(),
            overlays: vec![],
            function: function.to_string(),
            width,
            spp,
            no_objects: false,
        }
    }

    fn overlay(mut self, dir: &str) -> Job {
        self.overlays.push(dir.to_string());
        self
    }

    fn background_only(mut self) -> Job {
        self.no_objects = true;
        self
    }
}

/// The stand-in textures (`make_textures.py`), made once per test run.
fn textures(python: &Path) -> &'static Path {
    static DIR: OnceLock<&'static Path> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = crate::common::shared_temporary_folder("rtoracle-course-textures-");
        let out = Command::new(python)
            .arg("-B")
            .arg(weeks_dir().join("make_textures.py"))
            .arg(dir)
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

fn render(python: &Path, job: &Job) -> Rendered {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("out.png");
    let weeks = weeks_dir();
    let mut cmd = Command::new(python);
    cmd.arg("-B")
        .arg(weeks.join("render_scene.py"))
        .arg(weeks.join(&job.folder))
        .arg(&job.function)
        .arg(&png)
        .args(["--width", &job.width.to_string()])
        .args(["--spp", &job.spp.to_string()])
        .args(["--seed", &SEED.to_string()]);
    if weeks.join("make_textures.py").is_file() {
        cmd.arg("--textures").arg(textures(python));
    }
    for o in &job.overlays {
        cmd.arg("--overlay").arg(weeks.join(o));
    }
    if job.no_objects {
        cmd.arg("--no-objects");
    }
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => Rendered::Image(image::open(&png).unwrap().to_rgb8()),
        Some(3) => {
            let last = stderr.trim_end().lines().last().unwrap_or("");
            let raised = last.strip_prefix("course code raised ").unwrap_or_else(|| {
                panic!("{job:?}: exit 3 without naming the exception: {stderr}")
            });
            Rendered::Raised(raised.to_string())
        }
        _ => panic!("{job:?}: render_scene.py failed: {stderr}"),
    }
}

/// Runs each of `codes` (Python setting `result`) with `probe.py --many` against `folder` and
/// `overlays`, in one process (each snippet gets freshly imported modules): its result, or the
/// exception it raised as `TYPE: MESSAGE`.
fn probes(
    python: &Path,
    folder: &str,
    overlays: &[&str],
    codes: &[&str],
) -> Vec<Result<Value, String>> {
    let weeks = weeks_dir();
    let mut cmd = Command::new(python);
    cmd.arg("-B")
        .arg(weeks.join("probe.py"))
        .arg(weeks.join(folder));
    for o in overlays {
        cmd.arg("--overlay").arg(weeks.join(o));
    }
    let out = cmd.arg("--many").args(codes).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "probe.py on {folder} failed: {stderr}"
    );
    let answers: Vec<Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(answers.len(), codes.len(), "{folder}: {stderr}");
    answers
        .into_iter()
        .map(|a| match a.get("raised") {
            Some(e) => Err(e.as_str().unwrap().to_string()),
            None => Ok(a["result"].clone()),
        })
        .collect()
}

fn probe_with(python: &Path, folder: &str, overlays: &[&str], code: &str) -> Result<Value, String> {
    probes(python, folder, overlays, &[code]).remove(0)
}

fn probe(python: &Path, folder: &str, code: &str) -> Value {
    probe_with(python, folder, &[], code)
        .unwrap_or_else(|e| panic!("{folder}: the course's code raised {e}\n{code}"))
}

/// A snippet of `probes.json` (the catalogue's `NAME_PROBE`s, by lower-case name).
fn named_probe(name: &str) -> String {
    static PROBES: OnceLock<Value> = OnceLock::new();
    let all = PROBES.get_or_init(|| {
        let text = std::fs::read_to_string(weeks_dir().join("probes.json")).unwrap();
        serde_json::from_str(&text).unwrap()
    });
    all[name]
        .as_str()
        .unwrap_or_else(|| panic!("probes.json has no {name}"))
        .to_string()
}

/// What a hand-worked case expects: numbers to a tolerance, or an exception of a type.
enum Want {
    Close(Value, f64),
    Raises(&'static str),
}

/// Runs every case's snippet on `folder` in one process and checks each answer.
fn check_cases(python: &Path, folder: &str, cases: &[(&str, String, Want)]) {
    let codes: Vec<&str> = cases.iter().map(|(_, code, _)| code.as_str()).collect();
    for ((what, code, want), got) in cases.iter().zip(probes(python, folder, &[], &codes)) {
        match (want, got) {
            (Want::Close(v, tol), Ok(got)) => {
                assert_close(&got, v, *tol, &format!("{folder}: {what}"))
            }
            (Want::Raises(kind), Err(e)) => {
                assert!(
                    e.starts_with(kind),
                    "{folder}: {what}: raised {e}, not {kind}"
                )
            }
            (Want::Close(..), Err(e)) => panic!("{folder}: {what}: raised {e}\n{code}"),
            (Want::Raises(kind), Ok(v)) => panic!("{folder}: {what}: gave {v}, not {kind}"),
        }
    }
}

/// Asserts two JSON values are the same numbers to `tol` (and the same everything else).
fn assert_close(got: &Value, want: &Value, tol: f64, what: &str) {
    fn walk(a: &Value, b: &Value, tol: f64) -> bool {
        match (a, b) {
            (Value::Number(x), Value::Number(y)) => {
                (x.as_f64().unwrap() - y.as_f64().unwrap()).abs() <= tol
            }
            (Value::Array(x), Value::Array(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(p, q)| walk(p, q, tol))
            }
            _ => a == b,
        }
    }
    assert!(walk(got, want, tol), "{what}: got {got}, want {want}");
}

/// The film's code of a linear value: gamma 2, clamp to [0, 0.999], times 255, truncated.
fn code(linear: f64) -> u8 {
    (255.0 * linear.sqrt().clamp(0.0, 0.999)) as u8
}

fn codes(rgb: [f64; 3]) -> [u8; 3] {
    rgb.map(code)
}

/// Share of pixels whose largest channel difference exceeds `by` codes.
fn share_differing(a: &RgbImage, b: &RgbImage, by: u8) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let n = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > by))
        .count();
    n as f64 / (a.width() * a.height()) as f64
}

/// Renders each of `scenes` from `week`'s solution at `width` pixels and 1 spp, checks the
/// size, and that at least a tenth of the pixels are not the background (the same render with
/// no objects, same camera) by more than 8 codes.
fn solution_renders(week: &str, scenes: &[&str], width: u32, height: u32) {
    let Some(py) = python() else { return };
    let folder = format!("{week}/solution");
    for scene in scenes {
        let job = Job::new(&folder, scene, width, 1);
        let image = render(py, &job).image(&format!("{week} {scene}"));
        assert_eq!(image.dimensions(), (width, height), "{week} {scene}");
        let background = render(py, &job.background_only()).image(scene);
        let share = share_differing(&image, &background, 8);
        assert!(
            share >= 0.1,
            "{week} {scene}: only {share} of the pixels differ from the background"
        );
    }
}

/// The render functions `folder`'s main.py has.
fn render_functions(py: &Path, folder: &str) -> Vec<String> {
    let out = Command::new(py)
        .arg("-B")
        .arg(weeks_dir().join("render_scene.py"))
        .arg(weeks_dir().join(folder))
        .arg("--list")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

/// The catalogue of mistakes (`mistakes.json`, written by make_weeks.py).
fn catalogue() -> Vec<Value> {
    let text = std::fs::read_to_string(weeks_dir().join("mistakes.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Every mistake of `week`: its probe's result differs from the solution's (or is the same to
/// 1e-12 when the catalogue says `same_probe`), each render it names differs from the
/// solution's render of the same seed (or raises), and each `same_render` is identical.
fn mistakes_show_where_the_catalogue_says(week: &str) {
    let Some(py) = python() else { return };
    let solution = format!("{week}/solution");
    let mistakes: Vec<Value> = catalogue()
        .into_iter()
        .filter(|m| m["week"] == week)
        .collect();
    assert!(!mistakes.is_empty(), "{week} has no catalogued mistakes");
    let codes: Vec<&str> = mistakes
        .iter()
        .filter_map(|m| m["probe"].as_str())
        .collect();
    let mut right_answers = probes(py, &solution, &[], &codes).into_iter();
    let mut solved: HashMap<(String, u32, u32), RgbImage> = HashMap::new();
    let mut solution_render = |function: &str, width: u32, spp: u32| -> RgbImage {
        solved
            .entry((function.to_string(), width, spp))
            .or_insert_with(|| {
                render(py, &Job::new(&solution, function, width, spp)).image(function)
            })
            .clone()
    };
    for m in &mistakes {
        let name = m["name"].as_str().unwrap();
        let overlay = format!("{week}/mistakes/{name}");
        assert!(weeks_dir().join(&overlay).is_dir(), "{overlay}");
        let mut shown = 0;
        if let Some(code) = m["probe"].as_str() {
            let right = right_answers.next().unwrap();
            let right = right.unwrap_or_else(|e| panic!("{name}: the solution's probe raised {e}"));
            let wrong = probe_with(py, &solution, &[&overlay], code);
            if m["same_probe"] == json!(true) {
                let wrong = wrong.unwrap_or_else(|e| panic!("{name}: probe raised {e}"));
                assert_close(&wrong, &right, 1e-12, &format!("{name}: the same probe"));
            } else {
                assert_ne!(
                    wrong.as_ref().ok(),
                    Some(&right),
                    "{name}: its probe gives the solution's answer"
                );
                shown += 1;
            }
        }
        for r in m["render"].as_array().into_iter().flatten() {
            let function = r["function"].as_str().unwrap();
            let (width, spp) = (
                r["width"].as_u64().unwrap() as u32,
                r["spp"].as_u64().unwrap() as u32,
            );
            let right = solution_render(function, width, spp);
            let job = Job::new(&solution, function, width, spp).overlay(&overlay);
            if let Rendered::Image(wrong) = render(py, &job) {
                assert_ne!(
                    wrong, right,
                    "{name}: {function} renders as the solution's (seed {SEED})"
                );
            } // a crash is a change too
            shown += 1;
        }
        for f in m["same_render"].as_array().into_iter().flatten() {
            let function = f.as_str().unwrap();
            let right = solution_render(function, 16, 1);
            let wrong =
                render(py, &Job::new(&solution, function, 16, 1).overlay(&overlay)).image(name);
            assert_eq!(
                wrong, right,
                "{name}: {function} should be identical for one seed"
            );
        }
        assert!(
            shown > 0 || m["same_probe"] == json!(true),
            "{name}: the catalogue gives no probe or render that shows it"
        );
    }
}

/// Every render of `folder` raises `kind` (an unmodified skeleton whose scenes cannot run).
fn every_render_raises(folder: &str, kind: &str, message: &str) {
    let Some(py) = python() else { return };
    let functions = render_functions(py, folder);
    assert!(!functions.is_empty(), "{folder} has no render functions");
    for f in &functions {
        match render(py, &Job::new(folder, f, 16, 1)) {
            Rendered::Raised(e) => assert!(
                e.starts_with(kind) && e.contains(message),
                "{folder} {f}: raised {e}, not {kind} ({message})"
            ),
            Rendered::Image(_) => {
                panic!("{folder} {f}: rendered, but its stubs should raise {kind}")
            }
        }
    }
}

/// Each snippet's result on `folder` is None (the student's functions are stubs).
fn stubs_return_none(folder: &str, codes: &[&str]) {
    let Some(py) = python() else { return };
    for (code, got) in codes.iter().zip(probes(py, folder, &[], codes)) {
        assert_eq!(got, Ok(Value::Null), "{folder}: {code}");
    }
}

fn v3(x: f64, y: f64, z: f64) -> Value {
    json!([x, y, z])
}

const SQRT_HALF: f64 = std::f64::consts::FRAC_1_SQRT_2;
const PI: f64 = std::f64::consts::PI;

// ---------------------------------------------------------------------------------------------
// All weeks.

const WEEKS: [&str; 6] = ["week05", "week06", "week07", "week08", "week09", "week10"];

/// The skeletons, the mistakes' overlays, the catalogue and probes.json are what make_weeks.py
/// writes from the solutions: a solution edited without regenerating them fails here.
#[test]
fn generated_week_fixtures_are_up_to_date() {
    let Some(py) = python() else { return };
    let out = Command::new(py)
        .arg("-B")
        .arg(weeks_dir().join("make_weeks.py"))
        .arg("--check")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The modules a grader imports (everything but the renderer and main.py) need neither
/// progressbar2 nor RT_pbar: importing them all (progressbar2 is not installed where the tests
/// run, and need not be) leaves RT_pbar unimported, in every week's solution and skeleton.
#[test]
fn only_the_renderer_and_main_import_the_progress_bar() {
    let Some(py) = python() else { return };
    for week in WEEKS {
        for kind in ["solution", "skeleton"] {
            let folder = format!("{week}/{kind}");
            let got = probe(py, &folder, "import sys\nresult = 'RT_pbar' in sys.modules");
            assert_eq!(got, json!(false), "{folder}");
            for name in ["RT_renderer.py", "main.py"] {
                let text = std::fs::read_to_string(weeks_dir().join(&folder).join(name)).unwrap();
                assert!(text.contains("import RT_pbar"), "{folder}/{name}");
            }
        }
    }
}

/// The driver renders the requested size and sample count and is deterministic for a seed;
/// a missing function and a missing folder are bad usage (exit 2) naming them.
#[test]
fn the_render_driver_is_deterministic_for_a_seed_and_names_bad_input() {
    let Some(py) = python() else { return };
    let job = Job::new("week05/solution", "renderPointLight", 12, 2);
    let a = render(py, &job).image("first");
    let b = render(py, &job).image("second");
    assert_eq!(a.dimensions(), (12, 12));
    assert_eq!(a, b, "two renders of one seed");
    let script = weeks_dir().join("render_scene.py");
    for (args, needle) in [
        (
            vec!["week05/solution", "renderNothing", "x.png"],
            "renderNothing",
        ),
        (vec!["week05/nowhere", "renderQuad", "x.png"], "nowhere"),
    ] {
        let mut cmd = Command::new(py);
        cmd.arg("-B").arg(&script).current_dir(weeks_dir());
        let out = cmd.args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

// ---------------------------------------------------------------------------------------------
// Week 5: point lights and shadows.

const WEEK05_SCENES: [&str; 4] = [
    "renderQuad",
    "renderQuadLight",
    "renderPointLight",
    "renderPointLightShadow",
];

/// The week-4 quads' albedos, and the area light's colour.
const WEEK05_ALBEDOS: [[f64; 3]; 6] = [
    [1.0, 0.2, 0.2],
    [0.2, 1.0, 0.2],
    [0.2, 0.2, 1.0],
    [1.0, 0.5, 0.0],
    [0.2, 0.8, 0.8],
    [1.0, 1.0, 1.0],
];

#[test]
fn week05_solution_renders_each_scene() {
    solution_renders("week05", &WEEK05_SCENES, 16, 16);
}

/// The skeleton holds the week-4 integrator (a hit is its albedo, a miss the sky) and no
/// shadow scene: at 1 spp every pixel is exactly one of the scene's albedos or a sky colour.
#[test]
fn week05_skeleton_shades_flat_albedo_and_lacks_the_shadow_scene() {
    let Some(py) = python() else { return };
    let functions = render_functions(py, "week05/skeleton");
    assert_eq!(
        functions,
        ["renderPointLight", "renderQuad", "renderQuadLight"],
        "the skeleton's scenes"
    );
    let flat: Vec<[u8; 3]> = WEEK05_ALBEDOS.iter().map(|a| codes(*a)).collect();
    for scene in &functions {
        let image = render(py, &Job::new("week05/skeleton", scene, 16, 1)).image(scene);
        let mut hits = 0;
        for p in image.pixels() {
            let p = p.0;
            if flat.contains(&p) {
                hits += 1;
            } else {
                // the sky: (1 - a) white + a (0.5, 0.7, 1), so blue is 1 and red <= green
                assert!(
                    p[2] == 254 && p[0] <= p[1] && p[0] >= code(0.5),
                    "{scene}: pixel {p:?} is neither an albedo {flat:?} nor the sky"
                );
            }
        }
        assert!(hits >= 16, "{scene}: only {hits} pixels hit a quad");
    }
    stubs_return_none(
        "week05/skeleton",
        &[
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.Lambertian(rtu.Color(1, 1, 1)).scattering(None, hit)",
            "result = rts.Scene().find_occlusion(rtr.Ray(rtu.Vec3(), rtu.Vec3(1, 0, 0)), rtu.Interval(0, 1))",
            "result = rts.Scene().find_point_lights()",
        ],
    );
}

/// Week 5's formulas on hand-worked cases.
#[test]
fn week05_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let a = [0.5, 0.25, 1.0];
    let c02 = code(0.2);
    let cases = [
        // Occlusion in t units, "more than one object": occluded behind an occluder when the
        // light is farther than 1 (its own sphere is reached); lit with the light's sphere
        // alone; lit with one occluder when the light is 0.5 away (the interval (1e-6, 0.5) in
        // t units ends before the light's sphere, which starts at t = 1 - 0.1 / 0.5 = 0.8).
        ("occlusion", named_probe("occlusion"), Want::Close(json!([true, false, false]), 0.0)),
        // The direct term at depth 1: E min(1, 1/d) times the albedo, d = 2; zero when
        // occluded; doubled after a second find_lights() (it appends the lights again).
        (
            "direct term",
            named_probe("direct"),
            Want::Close(json!([a.map(|x| x * 0.5), [0.0, 0.0, 0.0], a]), 1e-15),
        ),
        // Lambertian: n + u, not normalised, from the hit point, attenuation = albedo; the cube
        // sample (0.5, 0, 0) (three draws mapped to [-1, 1)) is accepted and normalised to x.
        (
            "Lambertian",
            named_probe("lambertian_n_plus_u"),
            Want::Close(json!([[1.0, 2.0, 3.0], [1.0, 1.0, 0.0], a, 3]), 0.0),
        ),
        // n + u = 0 (u = -n exactly) is replaced by n.
        (
            "Lambertian degenerate",
            "rtu.random_vec3_unit = lambda: rtu.Vec3(0, -1, 0)\n\
             hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             s = rtm.Lambertian(rtu.Color(1, 1, 1)).scattering(None, hit)\n\
             result = vec(s.scattered_ray.getDirection())"
                .to_string(),
            Want::Close(v3(0.0, 1.0, 0.0), 0.0),
        ),
        // A light's material: no scattering, emits its colour; only lights are lights; a sphere
        // that is a light is a point light whatever its radius, a quad light is not; the
        // background is 0.01 grey.
        (
            "lights",
            "L = rtm.Diffuse_light(rtu.Color(0.3, 0.6, 0.9))\n\
             s = rts.Scene()\n\
             s.add_object(rto.Sphere(rtu.Vec3(1, 2, 3), 5.0, L))\n\
             s.add_object(rto.Quad(rtu.Vec3(), rtu.Vec3(1, 0, 0), rtu.Vec3(0, 1, 0), L))\n\
             s.add_object(rto.Sphere(rtu.Vec3(), 1.0, rtm.Lambertian(rtu.Color(1, 1, 1))))\n\
             s.find_lights()\n\
             result = [L.scattering(None, None), vec(L.emitting()), L.is_light(),\n\
                       rtm.Lambertian(rtu.Color(1, 1, 1)).is_light(), len(s.light_list),\n\
                       [vec(p.center) for p in s.point_light_list], vec(s.getBackgroundColor())]"
                .to_string(),
            Want::Close(
                json!([null, [0.3, 0.6, 0.9], true, false, 2, [[1.0, 2.0, 3.0]], [0.01, 0.01, 0.01]]),
                0.0,
            ),
        ),
        // A None material crashes find_lights.
        (
            "None material",
            "s = rts.Scene()\ns.add_object(rto.Sphere(rtu.Vec3(), 1.0, None))\ns.find_lights()"
                .to_string(),
            Want::Raises("AttributeError"),
        ),
        // The integrator: depth 0 is black; a light hit is its emission; a miss the 0.01 grey.
        (
            "integrator",
            "s = rts.Scene()\n\
             s.add_object(rto.Sphere(rtu.Vec3(0, 0, -2), 0.5, rtm.Diffuse_light(rtu.Color(2, 3, 4))))\n\
             s.find_lights()\n\
             i = rti.Integrator()\n\
             r = rtr.Ray(rtu.Vec3(), rtu.Vec3(0, 0, -1))\n\
             result = [vec(i.compute_scattering(r, s, 0)), vec(i.compute_scattering(r, s, 3)),\n\
                       vec(i.compute_scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(0, 1, 0)), s, 3))]"
                .to_string(),
            Want::Close(json!([[0.0, 0.0, 0.0], [2.0, 3.0, 4.0], [0.01, 0.01, 0.01]]), 0.0),
        ),
        // The film: 20 samples summing to 4 -> sqrt(0.2) -> 114; above 1 clamped to 0.999 ->
        // 254; number * Color has no __rmul__ (TypeError) while Color * number scales.
        (
            "film",
            "cam = rtc.Camera()\ncam.img_width = 2\ncam.aspect_ratio = 2.0\ncam.samples_per_pixel = 20\n\
             cam.init_camera(0.0, 10.0)\ncam.write_to_film(0, 0, rtu.Color(4, 4, 4))\n\
             cam.write_to_film(1, 0, rtu.Color(40, 0.0, 20))\n\
             result = [(cam.film * 255).astype('uint8').tolist(), raised(lambda: 0.5 * rtu.Color(1, 1, 1)),\n\
                       vec(rtu.Color(1, 2, 3) * 0.5)]"
                .to_string(),
            Want::Close(
                json!([[[[c02, c02, c02], [254, 0, code(1.0)]]], "TypeError", [0.5, 1.0, 1.5]]),
                0.0,
            ),
        ),
    ];
    check_cases(py, "week05/solution", &cases);
    // random_vec3_unit lies on the unit sphere, and its mean is near 0 (2000 seeded draws:
    // each coordinate's mean has standard deviation sqrt(1/3 / 2000) = 0.013; 0.07 is 5.4 sigma).
    let unit = probe(
        py,
        "week05/solution",
        "seed(5)\nv = [rtu.random_vec3_unit() for _ in range(2000)]\n\
         result = [max(abs(x.len() - 1) for x in v), [sum(x.e[k] for x in v) / 2000 for k in range(3)]]",
    );
    assert!(unit[0].as_f64().unwrap() < 1e-15, "{unit}");
    for k in 0..3 {
        assert!(unit[1][k].as_f64().unwrap().abs() < 0.07, "{unit}");
    }
}

#[test]
fn week05_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week05");
}

// ---------------------------------------------------------------------------------------------
// Week 6: mirror and dielectric.

const WEEK06_SCENES: [&str; 3] = [
    "renderMirrorPointLight",
    "renderMirrors",
    "renderDielectric",
];

#[test]
fn week06_solution_renders_each_scene() {
    solution_renders("week06", &WEEK06_SCENES, 16, 9);
}

/// The skeleton's mirror and glass do not scatter (black, their emission), and a miss is still
/// week 5's flat grey: with no light in renderMirrors and renderDielectric nothing is brighter
/// than the background's code and the near mirror is black; renderMirrorPointLight's top
/// corners (misses) are the flat grey, not the sky.
#[test]
fn week06_skeleton_has_black_mirrors_and_no_sky() {
    let Some(py) = python() else { return };
    let grey = code(0.01);
    for scene in ["renderMirrors", "renderDielectric"] {
        let image = render(py, &Job::new("week06/skeleton", scene, 16, 9)).image(scene);
        assert!(
            image.pixels().all(|p| p.0.iter().all(|&c| c <= grey)),
            "{scene}: brighter than the background"
        );
        assert!(
            image.pixels().any(|p| p.0 == [0, 0, 0]),
            "{scene}: no black mirror pixel"
        );
    }
    let image = render(
        py,
        &Job::new("week06/skeleton", "renderMirrorPointLight", 16, 1),
    )
    .image("renderMirrorPointLight");
    for (x, y) in [(0, 0), (15, 0)] {
        assert_eq!(
            image.get_pixel(x, y).0,
            [grey; 3],
            "pixel ({x}, {y}) is not the flat grey"
        );
    }
    stubs_return_none(
        "week06/skeleton",
        &[
            "result = rtu.reflect(rtu.Vec3(1, -1, 0), rtu.Vec3(0, 1, 0))",
            "result = rtu.refract(rtu.Vec3(1, -1, 0), rtu.Vec3(0, 1, 0), 0.5)",
            "result = rtu.schlick(0.5, 1.5)",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.Mirror(rtu.Color(1, 1, 1)).scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(0, -1, 0)), hit)",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.Dielectric(rtu.Color(1, 1, 1), 1.5).scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(0, -1, 0)), hit)",
        ],
    );
}

#[test]
fn week06_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let s3 = 3f64.sqrt();
    // 30 degrees from the normal, ratio 2/3: r_perp = (2/3)(1/2) x, r_par = -sqrt(1 - 1/9) n
    let refracted = v3(1.0 / 3.0, -(8f64 / 9.0).sqrt(), 0.0);
    // leaving through the back face 30 degrees from its normal (0, -1, 0), ratio 1.5:
    // r_perp = 1.5 (1/2) x, r_par = sqrt(1 - 0.5625) y (Snell: sin = 0.75 = 1.5 sin 30)
    let leaving = v3(0.75, (1.0f64 - 0.5625).sqrt(), 0.0);
    let cases = [
        // v - 2 (v . n) n
        ("reflect", named_probe("reflect"), Want::Close(json!([[1.0, 1.0, 0.0], [2.0, 3.0, 1.0]]), 0.0)),
        // forced to refract (1), forced to reflect (0), 0.05 > Schlick(cos 30) = 0.04004
        // (refracts), total internal reflection at 60 degrees with 1.5 (reflects, draws nothing)
        (
            "refract",
            named_probe("refract"),
            Want::Close(
                json!([
                    [refracted.clone(), 1],
                    [[0.5, s3 / 2.0, 0.0], 1],
                    [refracted.clone(), 1],
                    [[s3 / 2.0, 0.5, 0.0], 0]
                ]),
                1e-12,
            ),
        ),
        // r0 = ((1 - x)/(1 + x))^2 = 0.04 at 1.5; + (1 - r0)(1 - cos)^5: 0.04 + 0.96/32 at
        // cos 0.5; 1 at grazing; (1/2)^5 with x = 1
        (
            "schlick",
            named_probe("schlick"),
            Want::Close(json!([0.04, 0.04 + 0.96 / 32.0, 1.0, 0.03125]), 1e-15),
        ),
        // Dielectric: the unit direction refracted with 1/IOR through the front face, IOR
        // through the back face; attenuation = albedo
        (
            "Dielectric",
            named_probe("dielectric"),
            Want::Close(
                json!([[refracted, [1.0, 1.0, 1.0], true], [leaving, [1.0, 1.0, 1.0], false]]),
                1e-12,
            ),
        ),
        // Mirror reflects the raw direction from the hit point; attenuation = albedo
        (
            "Mirror",
            named_probe("mirror"),
            Want::Close(json!([[1.0, 0.0, 0.0], [1.0, 2.0, 0.0], [0.8, 0.7, 0.6]]), 1e-15),
        ),
        // The sky: a = (unit(d).y + 1)/2, (1 - a) white + a (0.5, 0.7, 1), and a miss returns it
        (
            "sky",
            "s = rts.Scene()\n\
             sky = lambda d: vec(s.get_sky_background(rtr.Ray(rtu.Vec3(), d)))\n\
             result = [sky(rtu.Vec3(0, 5, 0)), sky(rtu.Vec3(0, -1, 0)), sky(rtu.Vec3(3, 0, 0)),\n\
                       vec(rti.Integrator().compute_scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(3, 0, 0)), s, 5))]"
                .to_string(),
            Want::Close(
                json!([[0.5, 0.7, 1.0], [1.0, 1.0, 1.0], [0.75, 0.85, 1.0], [0.75, 0.85, 1.0]]),
                1e-15,
            ),
        ),
    ];
    check_cases(py, "week06/solution", &cases);
}

#[test]
fn week06_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week06");
}

// ---------------------------------------------------------------------------------------------
// Week 7: textures and metal.

#[test]
fn week07_solution_renders_each_scene() {
    solution_renders("week07", &["renderProceduralTexture", "renderEarth"], 16, 9);
}

/// The skeleton's materials in main.py are None, so find_lights crashes on the first render
/// call; the student's functions are stubs.
#[test]
fn week07_skeleton_scenes_raise_on_none_materials() {
    every_render_raises("week07/skeleton", "AttributeError", "is_light");
    stubs_return_none(
        "week07/skeleton",
        &[
            "result = rto.Sphere(rtu.Vec3(), 1.0).get_uv(rtu.Vec3(1, 0, 0))",
            "result = rtt.SolidColor(rtu.Color(1, 1, 1)).tex_value(0, 0, rtu.Vec3())",
            "result = rtt.CheckerTexture(0.3, rtu.Color(1, 1, 1), rtu.Color(0, 0, 0)).tex_value(0, 0, rtu.Vec3())",
            "result = rtt.ImageTexture('not-a-picture.txt').tex_value(0, 0, rtu.Vec3())",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.Metal(rtu.Color(1, 1, 1), 0.5).scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(1, -1, 0)), hit)",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.TextureColor(None).scattering(rtr.Ray(rtu.Vec3(), rtu.Vec3(1, -1, 0)), hit)",
        ],
    );
}

/// Without the texture pictures, renderEarth's ImageTexture raises AttributeError in its
/// constructor (the course's behaviour for a missing file).
#[test]
fn week07_a_missing_texture_file_raises_attribute_error() {
    let Some(py) = python() else { return };
    let weeks = weeks_dir();
    let out = Command::new(py)
        .arg("-B")
        .arg(weeks.join("render_scene.py"))
        .arg(weeks.join("week07/solution"))
        .args(["renderEarth", "unused.png", "--width", "8", "--spp", "1"])
        .current_dir(tempfile::tempdir().unwrap().path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr
            .trim_end()
            .ends_with("'NoneType' object has no attribute 'shape'"),
        "{stderr}"
    );
}

#[test]
fn week07_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let cases = [
        // u = (atan2(-z, x) + pi) / 2pi, v = acos(-y) / pi: +x (0.5, 0.5), +z (0.25, 0.5),
        // -z (0.75, 0.5), -y v = 0, +y v = 1, -x at the seam: u = 0 with z = +0 and u = 1 with
        // z = -0 (so ImageTexture then reads past the image); past the pole by one rounding,
        // acos raises ValueError
        (
            "get_uv",
            named_probe("uv"),
            Want::Close(
                json!([
                    [0.5, 0.5], [0.25, 0.5], [0.75, 0.5], [0.5, 0.0], [0.5, 1.0], [0.0, 0.5],
                    [1.0, 0.5], "ValueError"
                ]),
                1e-15,
            ),
        ),
        // floor(x/s) + floor(y/s) + floor(z/s) even gives the first colour (s = 0.32):
        // 0+0+0, 1+0+0, -1+0+0, 1+1+0, -1-1-1, 2+0+0 (0.64/0.32 is exactly 2), 1+0+0
        (
            "CheckerTexture",
            named_probe("checker"),
            Want::Close(json!([0.2, 0.9, 0.9, 0.2, 0.9, 0.2, 0.9]), 0.0),
        ),
        // pixel (int(u W), int(v H)) of a 4 x 2 picture, row 0 at v = 0: (0, 0); (1, 1);
        // (3, 0); u clamped to 0; u = 1 and v clamped to 1 read past the picture; not a
        // picture: cyan; a missing PNG: AttributeError in the constructor
        (
            "ImageTexture",
            named_probe("image"),
            Want::Close(
                json!([
                    [10.0, 20.0, 30.0], [160.0, 170.0, 180.0], [100.0, 110.0, 120.0],
                    [10.0, 20.0, 30.0], "IndexError", "IndexError", [0.0, 1.0, 1.0], "AttributeError"
                ]),
                1e-9,
            ),
        ),
        // reflect(unit(1, -1, 0), y) + 0.5 x; + (0, -1, 0) at roughness 1 points into the
        // surface: attenuation 0; roughness 3 is clamped to 1
        (
            "Metal",
            named_probe("metal"),
            Want::Close(
                json!([
                    [SQRT_HALF + 0.5, SQRT_HALF, 0.0], [0.8, 0.6, 0.4],
                    [SQRT_HALF, SQRT_HALF - 1.0, 0.0], [0.0, 0.0, 0.0], 1.0
                ]),
                1e-15,
            ),
        ),
        // a quad's (u, v) is (alpha, beta): (0.5, 3) on Q = 0, u = 2x, v = 4y
        (
            "quad uv",
            "q = rto.Quad(rtu.Vec3(0, 0, 0), rtu.Vec3(2, 0, 0), rtu.Vec3(0, 4, 0))\n\
             h = q.intersect(rtr.Ray(rtu.Vec3(0.5, 3, 1), rtu.Vec3(0, 0, -1)), rtu.Interval(0.000001, rtu.infinity_number))\n\
             result = list(h.getUV())"
                .to_string(),
            Want::Close(json!([0.25, 0.75]), 1e-15),
        ),
        // TextureColor: Lambertian scattering whose attenuation is tex_value(u, v, P), and a
        // sphere hit's (u, v) is get_uv of the outward normal: hit at +z -> (0.25, 0.5)
        (
            "TextureColor",
            "fixed_random([0.75, 0.5, 0.5])\n\
             m = rtm.TextureColor(rtt.CheckerTexture(0.32, rtu.Color(0.2, 0.2, 0.2), rtu.Color(0.9, 0.9, 0.9)))\n\
             s = rto.Sphere(rtu.Vec3(0, 0, 0), 1.0, m)\n\
             h = s.intersect(rtr.Ray(rtu.Vec3(0, 0, 5), rtu.Vec3(0, 0, -1)), rtu.Interval(0.000001, rtu.infinity_number))\n\
             sc = m.scattering(None, h)\n\
             result = [list(h.getUV()), vec(sc.scattered_ray.getDirection()), vec(sc.attenuation_color)]"
                .to_string(),
            // P = (0, 0, 1): floor(0) + floor(0) + floor(3.125) = 3, odd
            Want::Close(json!([[0.25, 0.5], [1.0, 0.0, 1.0], [0.9, 0.9, 0.9]]), 1e-15),
        ),
    ];
    check_cases(py, "week07/solution", &cases);
}

#[test]
fn week07_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week07");
}

// ---------------------------------------------------------------------------------------------
// Week 8: the BRDF integrator.

#[test]
fn week08_solution_renders_each_scene() {
    solution_renders("week08", &["renderPhong", "renderBlinn"], 16, 9);
}

#[test]
fn week08_skeleton_scenes_raise_on_blanked_materials() {
    every_render_raises("week08/skeleton", "AttributeError", "is_light");
    stubs_return_none(
        "week08/skeleton",
        &[
            "result = rtu.halfvector(rtu.Vec3(1, 0, 0), rtu.Vec3(0, 1, 0))",
            "result = rtm.Phong(rtu.Color(1, 1, 1), 0.5, 0.5, 8).BRDF(None, None, None)",
            "result = rtm.Blinn(rtu.Color(1, 1, 1), 0.5, 0.5, 8).BRDF(None, None, None)",
            "result = rtm.CookTorrance(rtu.Color(1, 1, 1), 0.5, 0.5, 0.5, 1.5).BRDF(None, None, None)",
        ],
    );
}

/// Phong, Blinn and Cook-Torrance at chosen angles (see the probes in catalogue.py).
fn brdf_cases(week: &str) -> Vec<(&'static str, String, Want)> {
    let a = [0.7, 0.2, 0.4];
    let diffuse = 0.6 / PI;
    let scaled = |k: f64| json!(a.map(|x| x * k));
    // Seen straight down, the light straight up: H = N, D = 1 / (pi alpha^2), G1 = 1, F = 0.04.
    let ct = 0.636 / PI;
    // The light along (1, 1, 0): H = unit(0.5, 1, 0) = (1, 2, 0) / sqrt 5, so N.H = V.H = 2 / sqrt 5
    // and L.H = 3 / sqrt 5; D = 0.25 / (pi (0.8 (0.25 + 0.25))^2) = 1.5625 / pi; the course's
    // G1 takes tan^2 from X.H: 1/4 for V, -4/9 for the unnormalised L; F = schlick(1) = 0.04.
    let g_v = 2.0 / (1.0 + (1.0f64 + 0.25 * 0.25).sqrt());
    let g_l = 2.0 / (1.0 + (1.0f64 - 0.25 * 4.0 / 9.0).sqrt());
    let ct_oblique = (0.6 + 0.9 * 1.5625 * g_v * g_l * 0.04 / 4.0) / PI;
    let with_albedo = if week == "week08" { "True" } else { "False" };
    vec![
        (
            "Phong and Blinn",
            named_probe("brdf"),
            Want::Close(
                json!([
                    [2.0, 2.0, 2.0],
                    scaled(diffuse + 0.9 / 16.0),
                    scaled(diffuse + 0.9 * 0.9f64.powi(4)),
                    scaled(diffuse + 0.9)
                ]),
                1e-12,
            ),
        ),
        (
            "Cook-Torrance",
            format!("ALBEDO = {with_albedo}\n{}", named_probe("cook_torrance")),
            Want::Close(json!([ct, ct_oblique, "TypeError"]), 1e-12),
        ),
    ]
}

#[test]
fn week08_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let mut cases = brdf_cases("week08");
    // Le = BRDF * E * n . (c - P), unnormalised: albedo * 2; no direct light: 0; a miss: the
    // flat grey, or the sky with bSkyBG
    cases.push((
        "BRDF integrator",
        named_probe("brdf_integrator"),
        Want::Close(
            json!([
                [1.0, 0.5, 2.0],
                [0.0, 0.0, 0.0],
                [0.01, 0.01, 0.01],
                [0.5, 0.7, 1.0]
            ]),
            1e-15,
        ),
    ));
    // every material's BRDF: the albedo (Lambertian, Mirror, Dielectric, Metal), the texture
    // value (TextureColor); a glass's transmitted direction has n . w < 0, so its weight is 0
    cases.push((
        "material BRDFs",
        "hit = rtu.Hitinfo(rtu.Vec3(0, 0, 0), rtu.Vec3(0, 1, 0), 1.0, None)\n\
         c = rtu.Color(0.1, 0.2, 0.3)\n\
         ms = [rtm.Lambertian(c), rtm.Mirror(c), rtm.Dielectric(c, 1.5), rtm.Metal(c, 0.2),\n\
               rtm.TextureColor(rtt.SolidColor(rtu.Color(0.4, 0.5, 0.6)))]\n\
         fixed_random([1.0])\n\
         d = rtm.Dielectric(c, 1.5).scattering(rtr.Ray(rtu.Vec3(0, 1, 0), rtu.Vec3(1, -1, 0)), hit)\n\
         result = [vec(m.BRDF(None, None, hit)) for m in ms] + [rti.Integrator().positive_cosine(\n\
                   rtu.Vec3.dot_product(hit.getNormal(), d.scattered_ray.getDirection()))]"
            .to_string(),
        Want::Close(
            json!([
                [0.1, 0.2, 0.3], [0.1, 0.2, 0.3], [0.1, 0.2, 0.3], [0.1, 0.2, 0.3], [0.4, 0.5, 0.6],
                0.0
            ]),
            1e-15,
        ),
    ));
    check_cases(py, "week08/solution", &cases);
}

#[test]
fn week08_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week08");
}

// ---------------------------------------------------------------------------------------------
// Week 9: cosine sampling and jittered pixels.

#[test]
fn week09_solution_renders_each_scene() {
    solution_renders("week09", &["renderBlinn"], 16, 9);
}

#[test]
fn week09_skeleton_scene_renders_without_the_stubs_which_return_none() {
    // The course's renderBlinn renders with `render()` (one ray through each pixel's centre)
    // and Blinn materials: none of week 9's stubs is on its path, so the skeleton renders it.
    let Some(py) = python() else { return };
    assert_eq!(render_functions(py, "week09/skeleton"), ["renderBlinn"]);
    match render(py, &Job::new("week09/skeleton", "renderBlinn", 16, 1)) {
        Rendered::Image(_) => {}
        Rendered::Raised(e) => panic!("week09/skeleton renderBlinn raised {e}"),
    }
    stubs_return_none(
        "week09/skeleton",
        &[
            "result = rtu.random_cosine_hemisphere_on_z()",
            "result = rtu.ONB().build_from_w(rtu.Vec3(0, 0, 1))",
            "result = rtu.ONB().local(1, 2, 3)",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             result = rtm.Lambertian(rtu.Color(1, 1, 1)).scattering(None, hit)",
            "cam = rtc.Camera()\ncam.init_camera(0.0, 5.0)\nresult = cam.get_jittered_ray(0, 0, 0, 0)",
        ],
    );
}

/// The ONB's u, v, w are orthonormal for 200 seeded random normals (and for normals near the
/// x axis, where a switches), and left-handed as the course builds it: u x v = -w.
const ONB_ORTHONORMAL: &str = "seed(9)\n\
    worst = 0.0\n\
    ns = [rtu.random_vec3_unit() * (0.1 + 3 * k / 200) for k in range(200)]\n\
    ns += [rtu.Vec3(1, 1e-9, 0), rtu.Vec3(-1, 0, 1e-9), rtu.Vec3(0.9, 0.43, 0.0)]\n\
    for n in ns:\n\
    \x20   o = rtu.ONB()\n\
    \x20   o.build_from_w(n)\n\
    \x20   d = rtu.Vec3.dot_product\n\
    \x20   c = rtu.Vec3.cross_product(o.u, o.v) + o.w\n\
    \x20   worst = max(worst, abs(d(o.u, o.v)), abs(d(o.u, o.w)), abs(d(o.v, o.w)),\n\
    \x20               abs(o.u.len() - 1), abs(o.v.len() - 1), abs(o.w.len() - 1), c.len(),\n\
    \x20               (rtu.Vec3.unit_vector(n) - o.w).len())\n\
    result = worst";

#[test]
fn week09_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let mut cases = brdf_cases("week09");
    let w = (25f64 / 30.0).sqrt();
    cases.extend([
        // (cos(2 pi r1) sqrt r2, sin(2 pi r1) sqrt r2, sqrt(1 - r2))
        (
            "cosine hemisphere",
            named_probe("cosine"),
            Want::Close(
                json!([[0.0, SQRT_HALF, SQRT_HALF], [0.0, 0.0, 1.0], 4]),
                1e-15,
            ),
        ),
        (
            "ONB",
            named_probe("onb"),
            Want::Close(
                json!([
                    [-1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, 1.0],
                    [-1.0, 2.0, 3.0],
                    [0.0, -1.0, 0.0],
                    [0.0, 0.0, 1.0],
                    [1.0, 0.0, 0.0],
                    [3.0, -1.0, 2.0]
                ]),
                0.0,
            ),
        ),
        (
            "ONB orthonormal",
            ONB_ORTHONORMAL.to_string(),
            Want::Close(json!(0.0), 1e-14),
        ),
        // Lambertian through the ONB of y: (0, sqrt 0.5, -sqrt 0.5), two draws
        (
            "Lambertian",
            named_probe("lambertian_onb"),
            Want::Close(
                json!([
                    [1.0, 2.0, 3.0],
                    [0.0, SQRT_HALF, -SQRT_HALF],
                    [0.5, 0.25, 1.0],
                    2
                ]),
                1e-15,
            ),
        ),
        // one_over_sqrt_spp stays 1/3 after spp 30; 0.5 (-0.5 + (s + U)/3)
        (
            "jitter",
            format!(
                "ARGS = lambda si, sj, x, y: (si, sj, x, y)\n{}",
                named_probe("jitter")
            ),
            Want::Close(
                json!([
                    1.0 / 3.0,
                    [0.5, -1.0 / 6.0, 0.0],
                    [-0.25, -0.25, 0.0],
                    [7.0 / 12.0, 7.0 / 12.0, 0.0]
                ]),
                1e-15,
            ),
        ),
        // floor(sqrt 30)^2 = 25 samples of white per pixel, divided by 30
        (
            "render_jittered",
            named_probe("render_jittered"),
            Want::Close(json!([50, [[[w, w, w], [w, w, w]]]]), 1e-15),
        ),
    ]);
    check_cases(py, "week09/solution", &cases);
    // The cosine lobe: E[z] = 2/3 (a uniform hemisphere would give 1/2); 4000 seeded draws,
    // standard deviation sqrt(1/18 / 4000) = 0.0037 of the mean: 0.02 is 5.4 sigma.
    let mean = probe(
        py,
        "week09/solution",
        "seed(4)\nresult = sum(rtu.random_cosine_hemisphere_on_z().z() for _ in range(4000)) / 4000",
    );
    assert!(
        (mean.as_f64().unwrap() - 2.0 / 3.0).abs() < 0.02,
        "mean z {mean}"
    );
}

#[test]
fn week09_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week09");
}

// ---------------------------------------------------------------------------------------------
// Week 10: depth of field and motion blur.

#[test]
fn week10_solution_renders_each_scene() {
    solution_renders("week10", &["renderDoF", "renderMoving"], 16, 9);
}

/// In the skeleton only get_ray has the lens and the ray time: get_jittered_ray starts every
/// ray at the camera's centre at time 0 and draws nothing, while get_ray uses the lens.
#[test]
fn week10_skeleton_jittered_rays_have_no_lens_and_no_time() {
    let Some(py) = python() else { return };
    let got = probe(py, "week10/skeleton", &named_probe("lens"));
    let radius = 5.0 * 1f64.to_radians().tan();
    assert_close(
        &got[0],
        &json!(radius),
        1e-15,
        "the skeleton's defocus radius",
    );
    assert_close(
        &got[4],
        &v3(-2.0, 2.0, 1.0),
        0.0,
        "the skeleton's jittered origin",
    );
    assert_eq!(
        (&got[5], &got[6]),
        (&json!(0.0), &json!(0)),
        "time and draws"
    );
    let get_ray = probe(
        py,
        "week10/skeleton",
        &named_probe("lens")
            .replace("cam.get_jittered_ray(3, 4, 1, 2)", "cam.get_ray(3, 4)")
            .replace("[0.75, 0.5, 0.3]", "[0.5, 0.5, 0.75, 0.5, 0.3]"),
    );
    let u = SQRT_HALF * radius * 0.5;
    assert_close(
        &get_ray[4],
        &v3(-2.0 + u, 2.0, 1.0 + u),
        1e-15,
        "get_ray's origin",
    );
    assert_eq!(
        (&get_ray[5], &get_ray[6]),
        (&json!(0.3), &json!(5)),
        "get_ray's time and draws"
    );
    for scene in ["renderDoF", "renderMoving"] {
        let image = render(py, &Job::new("week10/skeleton", scene, 16, 1)).image(scene);
        assert_eq!(image.dimensions(), (16, 9));
    }
}

#[test]
fn week10_formulas_hold_on_hand_worked_cases() {
    let Some(py) = python() else { return };
    let radius = 5.0 * 1f64.to_radians().tan();
    let (s2, s3, s6) = (2f64.sqrt(), 3f64.sqrt(), 6f64.sqrt());
    let lens_u = SQRT_HALF * radius * 0.5;
    let step = 1.0 / 10f64.sqrt();
    let cases = [
        // frame u = (1,0,1)/sqrt 2, v = (1,2,-1)/sqrt 6, w = (-1,1,1)/sqrt 3; radius
        // 5 tan(1 degree); the lens sample (0.5, 0) moves the origin by 0.5 radius u; time 0.3
        (
            "lens",
            named_probe("lens"),
            Want::Close(
                json!([
                    radius,
                    [1.0 / s2, 0.0, 1.0 / s2],
                    [1.0 / s6, 2.0 / s6, -1.0 / s6],
                    [-1.0 / s3, 1.0 / s3, 1.0 / s3],
                    [-2.0 + lens_u, 2.0, 1.0 + lens_u],
                    0.3,
                    3
                ]),
                1e-15,
            ),
        ),
        // rejection from the square: (0.9, 0.9) is outside, the centre is kept
        ("unit disk", named_probe("disk"), Want::Close(json!([[0.0, 0.0, 0.0], 4]), 0.0)),
        (
            "moving sphere",
            named_probe("motion"),
            Want::Close(
                json!([true, [0.0, 0.5, 0.0], 4.0, [1.0, 2.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.5], true]),
                0.0,
            ),
        ),
        // week 10's order (du, dv, s_i, s_j) and step 1/sqrt(10), frozen; the extremes of
        // spp 100's strata: -0.25 and 0.5 (-0.5 + 10/sqrt 10) = 1.33
        (
            "jitter",
            format!("ARGS = lambda si, sj, x, y: (x, y, si, sj)\n{}", named_probe("jitter"))
                .replace("offset(4, 4, 1.0)", "offset(9, 9, 1.0)")
                .replace("cam.samples_per_pixel = 30", "cam.samples_per_pixel = 100"),
            Want::Close(
                json!([
                    step,
                    [0.5 * (-0.5 + 4.5 * step), 0.5 * (-0.5 + 0.5 * step), 0.0],
                    [-0.25, -0.25, 0.0],
                    [0.5 * (-0.5 + 10.0 * step), 0.5 * (-0.5 + 10.0 * step), 0.0]
                ]),
                1e-15,
            ),
        ),
        // materials pass the ray's time on
        (
            "time passed on",
            "hit = rtu.Hitinfo(rtu.Vec3(), rtu.Vec3(0, 1, 0), 1.0, None)\n\
             ray = rtr.Ray(rtu.Vec3(0, 1, 0), rtu.Vec3(1, -1, 0), 0.7)\n\
             seed(1)\n\
             ms = [rtm.Lambertian(rtu.Color(1, 1, 1)), rtm.Mirror(rtu.Color(1, 1, 1)),\n\
                   rtm.Dielectric(rtu.Color(1, 1, 1), 1.5), rtm.Metal(rtu.Color(1, 1, 1), 0.3),\n\
                   rtm.TextureColor(rtt.SolidColor(rtu.Color(1, 1, 1))), rtm.Blinn(rtu.Color(1, 1, 1), 0.5, 0.5, 8)]\n\
             result = [m.scattering(ray, hit).scattered_ray.getTime() for m in ms] + [rtr.Ray().getTime()]"
                .to_string(),
            Want::Close(json!([0.7, 0.7, 0.7, 0.7, 0.7, 0.7, 0.0]), 0.0),
        ),
    ];
    check_cases(py, "week10/solution", &cases);
}

#[test]
fn week10_mistakes_show_where_the_catalogue_says() {
    mistakes_show_where_the_catalogue_says("week10");
}

/// `render_scene.py --describe` reports the scene main.py built, as the facts give it: week 6's
/// glass on the right (IOR 1.5) under the sky, week 10's left sphere moving up by 0.5 and
/// rendered with render_jittered at spp 200.
#[test]
fn the_render_driver_describes_the_scene_main_builds() {
    let Some(py) = python() else { return };
    let describe = |folder: &str, function: &str| -> Value {
        let weeks = weeks_dir();
        let out = Command::new(py)
            .arg("-B")
            .arg(weeks.join("render_scene.py"))
            .arg(weeks.join(folder))
            .args([function, "--describe"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let glass = describe("week06/solution", "renderDielectric");
    assert_eq!(glass["output"], "week06_dielec_sky.png");
    assert_eq!(glass["miss"], "sky");
    assert_eq!(glass["camera"]["vertical_fov"], json!(50));
    assert_eq!(glass["camera"]["look_from"], v3(-2.0, 2.0, 1.0));
    let right = &glass["objects"][4];
    assert_eq!(right["center"], v3(1.0, 0.0, -1.0));
    assert_eq!(right["material"]["class"], "Dielectric");
    assert_eq!(right["material"]["IOR"], json!(1.5));
    let moving = describe("week10/solution", "renderMoving");
    assert_eq!(moving["method"], "render_jittered");
    assert_eq!(moving["camera"]["samples_per_pixel"], json!(200));
    let left = &moving["objects"][1];
    assert_eq!(left["is_moving"], json!(true));
    assert_eq!(left["moving_center"], v3(-1.0, 0.5, -1.0));
    assert_eq!(moving["objects"][2]["is_moving"], json!(false));
}
