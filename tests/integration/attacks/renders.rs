//! Carried renders: a submission that answers the grader's render requests with pictures made
//! before the grade earns nothing for them (issue 42, "a carried picture earns nothing").
//!
//! The course's week-10 skeleton (whose jittered rays have neither the lens nor the time, so
//! its own `renderMoving` is wrong) plus one module, `carry.py`, imported by its `RT_utility.py`:
//! at import time it replaces the adapter's `Renderer.answer` (the adapter runs in the same
//! Python process) and answers every render request, the scene's and its variant's, from
//! pictures the student made at home with `rtoracle render` (the grader's scene at the
//! grader's 5 spp and seed 777, at 2 spp, at 256 spp), resampled to whatever size is asked:
//!
//! | submission | what it answers |
//! |---|---|
//! | `carried-5spp` | the 5-spp render at seed 777 |
//! | `carried-2spp` | a 2-spp render |
//! | `carried-256spp` | a 256-spp render (too clean for 5 spp) |
//! | `carried-noised` | the 256-spp render plus fresh noise per pixel, of the spread two 5-spp renders differ by |
//! | `carried-averaged` | the 5-spp render averaged with the skeleton's own render of the same request |
//!
//! Each scores 0 of the image group's 30 points, and its message says what a person should
//! look at. The instructor's solution, in the same batch and with the same secret seed, scores
//! 30: the variants cost an honest submission nothing. Run with `--test-threads=2`.

use std::path::Path;

use serde_json::Value;

use crate::common::{CourseTree, copy_tree, course_week_copy, run_in};

/// The attacker's module: `PICTURES` (PNG bytes as hex, by name) and `MODE` are prepended.
const CARRY: &str = r#"
# Answers the grader's render requests with pictures made at home.
import io, json, math, random, sys
from PIL import Image


def _linear(name):
    im = Image.open(io.BytesIO(bytes.fromhex(PICTURES[name]))).convert("RGB")
    return im.size[0], im.size[1], [((c + 0.5) / 255.0) ** 2 for c in im.tobytes()]


def _resized(picture, width, height):
    w, h, lin = picture
    out = []
    for j in range(height):
        y = min(h - 1, int((j + 0.5) * h / height))
        for i in range(width):
            x = min(w - 1, int((i + 0.5) * w / width))
            out.extend(lin[3 * (y * w + x):3 * (y * w + x) + 3])
    return out


def _code(x):
    return int(255 * min(max(math.sqrt(max(x, 0.0)), 0.0), 0.999))


_made = {}


def _picture(width, height):
    if (width, height) not in _made:
        if MODE == "noised":
            clean = _resized(_linear("clean"), width, height)
            a = _resized(_linear("a"), width, height)
            b = _resized(_linear("b"), width, height)
            rng = random.Random(width * 7919 + height)
            lin = [c + rng.gauss(0.0, abs(x - y) / math.sqrt(2.0)) for c, x, y in zip(clean, a, b)]
        else:
            lin = _resized(_linear("carried"), width, height)
        _made[(width, height)] = lin
    return _made[(width, height)]


_adapter = sys.modules.get("__main__")
_Renderer = getattr(_adapter, "Renderer", None)
if _Renderer is not None:
    _own = _Renderer.answer

    def answer(self, req):
        image = req["scene"]["image"]
        width = int(image["width"])
        height = max(1, int(width / float(image["aspect_ratio"])))
        lin = _picture(width, height)
        x0, y0, x1, y1 = (int(v) for v in req["tile"])
        own = None
        if MODE == "averaged":
            try:
                own = json.loads(_own(self, req)).get("film")
            except Exception:
                own = None
        codes = []
        k = 0
        for j in range(y0, y1):
            for i in range(x0, x1):
                for c in range(3):
                    x = lin[3 * (j * width + i) + c]
                    if own is not None:
                        x = 0.5 * (x + ((own[k] + 0.5) / 255.0) ** 2)
                    codes.append(_code(x))
                    k += 1
        return '{"tile":[%d,%d,%d,%d],"size":[%d,%d],"film":[%s]}' % (
            x0, y0, x1, y1, width, height, ",".join(str(c) for c in codes))

    _Renderer.answer = answer
"#;

/// The rubric of the attacks: week 10's moving scene alone, rendered by `renderMoving` at the
/// built-in rubric's 5 spp, with a seed the students do not know.
const RUBRIC: &str = "name = \"attacks\"\nseed = 90210\n\n[[group]]\nid = \"image.week10-moving\"\n\
name = \"week10-moving\"\nkind = \"image\"\nfile = \"week10_moving_nojitter.png\"\n\
scene = \"week10-moving\"\nsource = \"render\"\nmain_function = \"renderMoving\"\nspp = 5\n\
render_seconds = 240\npoints = 30\n";

/// Renders the grader's scene (week10-moving as the grader sends it: its jittered sampling at
/// `spp`) with the reference, as a student can at home; the PNG's bytes.
fn render_at_home(dir: &Path, spp: u32, seed: u64) -> Vec<u8> {
    let dumped = run_in(dir, &["scenes", "--dump", "week10-moving"]);
    assert!(dumped.status.success());
    let toml = String::from_utf8(dumped.stdout).unwrap().replace(
        "samples_per_pixel = 200\n",
        &format!("samples_per_pixel = {}\n", spp.min(5)),
    );
    let scene = dir.join(format!("moving-{spp}-{seed}.toml"));
    std::fs::write(&scene, toml).unwrap();
    let png = dir.join(format!("moving-{spp}-{seed}.png"));
    let (spp, seed) = (spp.to_string(), seed.to_string());
    let made = run_in(
        dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--spp",
            &spp,
            "--seed",
            &seed,
            "-o",
            png.to_str().unwrap(),
        ],
    );
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    std::fs::read(png).unwrap()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A copy of the skeleton whose `RT_utility.py` imports `carry.py`, answering as `mode` with
/// `pictures`.
fn attacker(skeleton: &Path, to: &Path, mode: &str, pictures: &[(&str, &[u8])]) {
    copy_tree(skeleton, to);
    let mut module = format!("MODE = {mode:?}\nPICTURES = {{\n");
    for (name, png) in pictures {
        module.push_str(&format!("    {name:?}: \"{}\",\n", hex(png)));
    }
    module.push_str("}\n");
    module.push_str(CARRY);
    std::fs::write(to.join("carry.py"), module).unwrap();
    let utility = to.join("RT_utility.py");
    let mut text = std::fs::read_to_string(&utility).unwrap();
    text.push_str("\nimport carry\n");
    std::fs::write(utility, text).unwrap();
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn carried_renders_earn_nothing() {
    let test = "attacks_renders::carried_renders_earn_nothing";
    let Some((tmp, skeleton)) = course_week_copy(test, 10, CourseTree::Skeleton) else {
        return;
    };
    let Some((_solution_tmp, solution)) = course_week_copy(test, 10, CourseTree::Solution) else {
        return;
    };
    let root = tmp.path();
    let (at5, at2, at256) = (
        render_at_home(root, 5, 777),
        render_at_home(root, 2, 778),
        render_at_home(root, 256, 779),
    );
    let (a, b) = (render_at_home(root, 5, 780), render_at_home(root, 5, 781));
    let subs = root.join("subs");
    attacker(
        &skeleton,
        &subs.join("carried-5spp"),
        "carried",
        &[("carried", &at5)],
    );
    attacker(
        &skeleton,
        &subs.join("carried-2spp"),
        "carried",
        &[("carried", &at2)],
    );
    attacker(
        &skeleton,
        &subs.join("carried-256spp"),
        "carried",
        &[("carried", &at256)],
    );
    attacker(
        &skeleton,
        &subs.join("carried-noised"),
        "noised",
        &[("clean", &at256), ("a", &a), ("b", &b)],
    );
    attacker(
        &skeleton,
        &subs.join("carried-averaged"),
        "averaged",
        &[("carried", &at5)],
    );
    copy_tree(&solution, &subs.join("solution"));
    let rubric = root.join("attacks.toml");
    std::fs::write(&rubric, RUBRIC).unwrap();
    let out = root.join("out");
    let run = run_in(
        root,
        &[
            "grade",
            "--batch",
            subs.to_str().unwrap(),
            "--rubric",
            rubric.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let check = |name: &str| -> Value {
        let text = std::fs::read_to_string(out.join(name).join("report.json")).unwrap();
        let report: Value = serde_json::from_str(&text).unwrap();
        report["checks"][0].clone()
    };
    let honest = check("solution");
    assert_eq!(honest["score"].as_f64(), Some(30.0), "{honest:#}");
    let render = &honest["image"]["metrics"]["render"];
    assert_eq!(
        render["variant"]["verdict"]["verdict"], "pass",
        "{honest:#}"
    );
    for name in [
        "carried-5spp",
        "carried-2spp",
        "carried-256spp",
        "carried-noised",
        "carried-averaged",
    ] {
        let c = check(name);
        eprintln!(
            "{name}: {} / 30: {}",
            c["score"],
            c["message"].as_str().unwrap_or("")
        );
        assert_eq!(c["score"].as_f64(), Some(0.0), "{name}: {c:#}");
        assert_ne!(c["status"], "passed", "{name}: {c:#}");
        let render = &c["image"]["metrics"]["render"];
        // The carried picture answered the scene's request; the variant's could not be.
        assert_eq!(render["made_by"], "main_function", "{name}: {c:#}");
        assert_ne!(
            render["variant"]["verdict"]["verdict"], "pass",
            "{name}: {c:#}"
        );
    }
    // The picture at the grader's spp passes as the scene: only the variant tells it, and the
    // message says so. The one at 256 spp is too clean for 5 spp.
    let c = check("carried-5spp");
    assert_eq!(
        c["image"]["metrics"]["render"]["variant"]["scene_matches"], true,
        "{c:#}"
    );
    let message = c["message"].as_str().unwrap();
    assert!(
        message.contains("matches the reference, but it scores 0")
            && message.contains("from a camera the grader moved"),
        "{message}"
    );
    let c = check("carried-256spp");
    let noise = &c["image"]["metrics"]["noise_floor"];
    assert_eq!(noise["too_clean"], true, "{c:#}");
    assert!(
        c["message"]
            .as_str()
            .unwrap()
            .contains("cleaner than a render of 5 samples per pixel")
    );
}
