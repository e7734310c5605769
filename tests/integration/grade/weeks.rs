//! `rtoracle grade --rubric weekNN` end to end on the course-shaped fixtures of weeks 5 to 10
//! (`tests/fixtures/python/weeks/`), in the sandbox, with the images rendered by the grader from
//! each submission's own code.
//!
//! For each week, the week's Gradescope package (`autograder --rubric weekNN`, installed by its
//! `setup.sh`, run by its `run_autograder`) grades the instructor's solution (100 of 100, every
//! test passed), and `grade --batch` the unmodified skeleton (at most 5). Every
//! render is seeded (the rubric's seed 0) and every golden is committed, so each verdict is the
//! same on every run. With the course's real code at hand (`RTORACLE_COURSE_CODE`), only
//! week 8's replay runs: `course_grades` grades every week's real solution and skeleton. The
//! catalogued function mistakes are caught and named on the course's real code in
//! `course::code::mistakes_are_caught_and_named`.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;

use crate::common::*;

fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| {
            rtoracle::bench::harness::course_python_or_skip("the weekly rubrics end to end")
        })
        .as_deref()
}

fn weeks() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/python/weeks")
}

/// Copies the `.py` files of each of `from` (in order, later ones replacing earlier ones) into
/// `to`.
fn assemble(to: &Path, from: &[PathBuf]) {
    std::fs::create_dir_all(to).unwrap();
    for dir in from {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let name = entry.file_name();
            if entry.path().is_file() && name.to_string_lossy().ends_with(".py") {
                std::fs::copy(entry.path(), to.join(name)).unwrap();
            }
        }
    }
}

fn report(out: &Path, name: &str) -> Value {
    let text = std::fs::read_to_string(out.join(name).join("report.json"))
        .unwrap_or_else(|e| panic!("{name}: no report.json: {e}"));
    serde_json::from_str(&text).unwrap()
}

/// The checks of a report as `(id, score, max, status, message)`.
fn checks(report: &Value) -> Vec<(String, f64, f64, String, String)> {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["id"].as_str().unwrap().to_string(),
                c["score"].as_f64().unwrap(),
                c["max_score"].as_f64().unwrap(),
                c["status"].as_str().unwrap().to_string(),
                c["message"].as_str().unwrap_or_default().to_string(),
            )
        })
        .collect()
}

/// Builds `rtoracle autograder --rubric weekNN` (seed 1), installs it as Gradescope does
/// (`setup.sh` with a `PREFIX`), and grades `submission` with its `run_autograder` (an
/// `AUTOGRADER` root): Gradescope's `results.json`.
fn graded_by_the_package(root: &Path, rubric: &str, submission: &Path) -> Value {
    let out = run_in(
        root,
        &[
            "autograder",
            "--rubric",
            rubric,
            "--seed",
            "1",
            "--out",
            "autograder.zip",
        ],
    );
    assert!(
        out.status.success(),
        "{rubric}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let gradescope = root.join("autograder");
    let source = gradescope.join("source");
    let file = std::fs::File::open(root.join("autograder.zip")).unwrap();
    zip::ZipArchive::new(file)
        .unwrap()
        .extract(&source)
        .unwrap();
    let prefix = root.join("prefix");
    let setup = std::process::Command::new("bash")
        .arg(source.join("setup.sh"))
        .env("PREFIX", &prefix)
        .output()
        .unwrap();
    assert!(
        setup.status.success(),
        "{rubric}: setup.sh: {}",
        String::from_utf8_lossy(&setup.stderr)
    );
    assemble(&gradescope.join("submission"), &[submission.to_path_buf()]);
    let run = std::process::Command::new("bash")
        .arg(source.join("run_autograder"))
        .env("PREFIX", &prefix)
        .env("AUTOGRADER", &gradescope)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{rubric}: run_autograder: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(gradescope.join("results/results.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Week `week`'s solution through the week's Gradescope package (100 of 100, every test
/// passed), then its skeleton by `grade` (at most 5).
///
/// Every scene is rendered by the solution's own `main.py` function (its `main_function`), and
/// the package's feedback says so. The catalogue's two mistakes that only
/// images show are graded in [`image_only_mistakes_cost_their_image_and_are_named`].
fn week_is_graded_fairly(week: u8) {
    let Some(python) = python() else {
        return;
    };
    let base = weeks().join(format!("week{week:02}"));
    let rubric = format!("week{week:02}");
    let root = tempfile::tempdir().unwrap();

    let results = graded_by_the_package(root.path(), &rubric, &base.join("solution"));
    let tests = results["tests"].as_array().unwrap();
    assert_eq!(
        results["score"].as_f64(),
        Some(100.0),
        "{rubric}: the solution: {tests:#?}"
    );
    for t in tests {
        let status = t["status"].as_str().unwrap_or_default();
        assert_eq!(status, "passed", "{rubric}: the solution: {t:#?}");
    }
    // The week's functions, its images and the week-4 intersections were all checked.
    let names: Vec<&str> = tests.iter().filter_map(|t| t["name"].as_str()).collect();
    for wanted in ["Sphere intersection", "rendered from your code"] {
        assert!(
            names.iter().any(|n| n.contains(wanted)),
            "{rubric}: no test of {wanted}: {names:?}"
        );
    }
    let by_main = tests
        .iter()
        .filter(|t| {
            t["output"]
                .as_str()
                .unwrap_or_default()
                .contains("main.py's render")
        })
        .count();
    assert!(
        by_main >= 1,
        "{rubric}: {by_main} images made by main.py: {tests:#?}"
    );

    let subs = root.path().join("subs");
    assemble(&subs.join("skeleton"), &[base.join("skeleton")]);
    let out = root.path().join("out");
    let run = run_in(
        root.path(),
        &[
            "grade",
            "--batch",
            subs.to_str().unwrap(),
            "--rubric",
            &rubric,
            "--python",
            python.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{rubric}: {stderr}");
    assert!(
        !stderr.contains("rendering the golden"),
        "{rubric}: every golden the rubric needs is compiled in: {stderr}"
    );
    let skeleton = report(&out, "skeleton");
    let score = skeleton["score"].as_f64().unwrap();
    assert!(
        score <= 5.0,
        "{rubric}: the skeleton scores {score}: {:#?}",
        checks(&skeleton)
    );
}

/// A rubric of one image group of week `week`'s scene `scene`, rendered by `function` of the
/// submission's `main.py` at 5 spp.
fn one_image_rubric(dir: &Path, week: u8, scene: &str, function: &str) -> PathBuf {
    let path = dir.join(format!("{scene}.toml"));
    let text = format!(
        "name = \"{scene}\"\nweek = {week}\nseed = 7\ncode_time_budget_seconds = 120\n\n\
         [[group]]\nid = \"image.{scene}\"\nname = \"{scene}\"\nkind = \"image\"\n\
         file = \"{scene}.png\"\nscene = \"{scene}\"\nmain_function = \"{function}\"\n\
         spp = 5\nrender_seconds = 120\npoints = 30\n"
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// Grades the batch `subs` with `rubric`; the image check of each submission.
fn image_checks(root: &Path, subs: &Path, rubric: &Path, python: &Path) -> Vec<(String, Value)> {
    let out = root.join(format!(
        "out-{}",
        rubric.file_stem().unwrap().to_string_lossy()
    ));
    let run = run_in(
        root,
        &[
            "grade",
            "--batch",
            subs.to_str().unwrap(),
            "--rubric",
            rubric.to_str().unwrap(),
            "--python",
            python.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut found = Vec::new();
    for entry in std::fs::read_dir(subs).unwrap().flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let r = report(&out, &name);
        let image = r["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["id"].as_str().unwrap().starts_with("image."))
            .unwrap()
            .clone();
        found.push((name, image));
    }
    found.sort_by(|a, b| a.0.cmp(&b.0));
    found
}

/// The catalogue's mistake that only an image shows costs the image group when the grader runs
/// the submission's own `main.py` function: `motion_on_wrong_sphere` (week 10's `renderMoving`
/// moves the centre sphere). A submission whose `main.py` is missing is rendered from the
/// scene's description instead, with its own classes (full marks here), and the message says
/// why; one whose function raises scores 0 with the exception (the scene is what its `main.py`
/// renders). A `main.py` that saves a picture it carries (the reference's render at another
/// seed) over classes that are wrong scores 0: the scene's variant, from a camera the grader
/// moves, does not match.
#[test]
fn image_only_mistakes_cost_their_image_and_are_named() {
    let Some(python) = python() else {
        return;
    };
    let root = tempfile::tempdir().unwrap();
    let w9 = weeks().join("week09");
    let subs = root.path().join("subs9");
    assemble(&subs.join("solution"), &[w9.join("solution")]);
    assemble(&subs.join("no-main"), &[w9.join("solution")]);
    std::fs::remove_file(subs.join("no-main/main.py")).unwrap();
    assemble(&subs.join("raising-main"), &[w9.join("solution")]);
    let main = subs.join("raising-main/main.py");
    let text = std::fs::read_to_string(&main).unwrap();
    let text = text.replace(
        "def renderBlinn():\n",
        "def renderBlinn():\n    raise RuntimeError('not today')\n",
    );
    assert!(text.contains("not today"));
    std::fs::write(&main, text).unwrap();
    // A main.py that saves a picture it carries (the reference's own render at another seed, as
    // good as an honest film) over classes that render the scene wrongly.
    let carried = subs.join("carried");
    assemble(
        &carried,
        &[
            w9.join("solution"),
            w9.join("mistakes/lobe_around_wrong_axis"),
        ],
    );
    let made = run_in(
        root.path(),
        &[
            "render",
            "week09-blinn",
            "--spp",
            "5",
            "--seed",
            "99",
            "-o",
            carried.join("carried.png").to_str().unwrap(),
        ],
    );
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    // The picture travels inside the code, as a submission's own files would carry it.
    let png = std::fs::read(carried.join("carried.png")).unwrap();
    std::fs::remove_file(carried.join("carried.png")).unwrap();
    let hex: String = png.iter().map(|b| format!("{b:02x}")).collect();
    let main = carried.join("main.py");
    let text = std::fs::read_to_string(&main).unwrap().replace(
        "def renderBlinn():\n",
        &format!(
            "CARRIED = '{hex}'\n\ndef renderBlinn():\n    import io\n    from PIL import Image\n    \
             Image.open(io.BytesIO(bytes.fromhex(CARRIED))).save('week09_nojittered.png')\n    return\n"
        ),
    );
    assert!(text.contains("CARRIED"));
    std::fs::write(&main, text).unwrap();
    let rubric = one_image_rubric(root.path(), 9, "week09-blinn", "renderBlinn");
    let checks = image_checks(root.path(), &subs, &rubric, python);
    let names: Vec<&str> = checks.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["carried", "no-main", "raising-main", "solution"]);
    let message = |c: &Value| c["message"].as_str().unwrap().to_string();
    let (_, carried) = &checks[0];
    assert_eq!(carried["score"].as_f64(), Some(0.0), "{carried:#}");
    let render = &carried["image"]["metrics"]["render"];
    assert_eq!(render["made_by"], "main_function", "{carried:#}");
    // The carried picture itself passes: only the variant tells it from an honest film.
    assert_eq!(render["variant"]["scene_matches"], true, "{carried:#}");
    assert_eq!(
        render["variant"]["verdict"]["verdict"], "fail",
        "{carried:#}"
    );
    assert!(
        message(carried).contains("matches the reference, but it scores 0")
            && message(carried).contains("from a camera the grader moved"),
        "{carried:#}"
    );
    let (_, raising) = &checks[2];
    assert_eq!(raising["score"].as_f64(), Some(0.0), "{raising:#}");
    assert!(
        message(raising).contains("RuntimeError") && message(raising).contains("not today"),
        "{raising:#}"
    );
    for (name, c) in [&checks[1], &checks[3]] {
        assert_eq!(c["score"].as_f64(), Some(30.0), "{name}: {c:#}");
        let render = &c["image"]["metrics"]["render"];
        assert_eq!(render["variant"]["verdict"]["verdict"], "pass", "{c:#}");
        if name == "solution" {
            assert_eq!(render["made_by"], "main_function", "{c:#}");
            assert!(message(c).starts_with("The image your main.py's renderBlinn() made"));
        } else {
            assert_eq!(render["made_by"], "description", "{name}: {c:#}");
            assert!(
                render["main_function_not_used"]
                    .as_str()
                    .is_some_and(|w| w.contains("has no main.py")),
                "{name}: {c:#}"
            );
            assert!(message(c).contains("was not used"), "{name}: {c:#}");
        }
    }

    let w10 = weeks().join("week10");
    let subs = root.path().join("subs10");
    assemble(&subs.join("solution"), &[w10.join("solution")]);
    assemble(
        &subs.join("moving"),
        &[
            w10.join("solution"),
            w10.join("mistakes/motion_on_wrong_sphere"),
        ],
    );
    let rubric = one_image_rubric(root.path(), 10, "week10-moving", "renderMoving");
    let checks = image_checks(root.path(), &subs, &rubric, python);
    assert_eq!(checks[0].0, "moving");
    assert_eq!(
        checks[0].1["score"].as_f64(),
        Some(0.0),
        "{:#}",
        checks[0].1
    );
    assert!(message(&checks[0].1).contains("differs"));
    assert_eq!(
        checks[1].1["score"].as_f64(),
        Some(30.0),
        "{:#}",
        checks[1].1
    );
}

// With the course's real code at hand (`RTORACLE_COURSE_CODE`), `course_grades` grades each
// week's own solution and skeleton with the same rubric, and these replays on the hand-written
// fixtures (each a few minutes of Python renders) are set aside; week 8's stays, as its
// solution is the fixture `rtoracle bench grade` embeds, and it keeps the Gradescope package's
// path of a later week tested on either kind of code.
#[test]
#[cfg_attr(
    rtoracle_course_code,
    ignore = "course_grades grades the course's real code of this week"
)]
fn week05_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(5);
}

#[test]
#[cfg_attr(
    rtoracle_course_code,
    ignore = "course_grades grades the course's real code of this week"
)]
fn week06_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(6);
}

#[test]
#[cfg_attr(
    rtoracle_course_code,
    ignore = "course_grades grades the course's real code of this week"
)]
fn week07_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(7);
}

#[test]
fn week08_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(8);
}

#[test]
#[cfg_attr(
    rtoracle_course_code,
    ignore = "course_grades grades the course's real code of this week"
)]
fn week09_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(9);
}

#[test]
#[cfg_attr(
    rtoracle_course_code,
    ignore = "course_grades grades the course's real code of this week"
)]
fn week10_rubric_grades_the_course_fairly() {
    week_is_graded_fairly(10);
}

/// `--print-rubric NAME` prints each built-in rubric as TOML that `--rubric FILE` reads back
/// to the same grade settings; an unknown name is one line and exit 2.
#[test]
fn built_in_rubrics_print_and_read_back() {
    let dir = tempfile::tempdir().unwrap();
    for name in rtoracle::grade::rubric::weeks::BUILTIN_RUBRICS {
        let out = run_in(dir.path(), &["grade", "--print-rubric", name]);
        assert!(out.status.success(), "{name}");
        let text = String::from_utf8(out.stdout).unwrap();
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, &text).unwrap();
        let back = rtoracle::grade::rubric::Rubric::from_file(&file).unwrap();
        let builtin = rtoracle::grade::rubric::Rubric::builtin(name).unwrap();
        assert_eq!(back.groups, builtin.groups, "{name}");
        assert_eq!(back.week, builtin.week, "{name}");
    }
    let out = run_in(dir.path(), &["grade", "--print-rubric", "week11"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("week11") && stderr.contains("week10"),
        "{stderr}"
    );
    // A submission folder right after the flag is taken as the rubric's name: said, with the way
    // to print the rubric in use, which both other spellings do.
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let out = run_in(dir.path(), &["grade", "--print-rubric", "sub"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("--print-rubric sub: not a built-in rubric")
            && stderr.contains("it is a folder"),
        "{stderr}"
    );
    for args in [
        &["grade", "--print-rubric=", "sub"][..],
        &["grade", "sub", "--print-rubric"][..],
    ] {
        let out = run_in(dir.path(), args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            String::from_utf8_lossy(&out.stdout),
            rtoracle::grade::rubric::WEEK04_RUBRIC,
            "{args:?}"
        );
    }
    let out = run_in(dir.path(), &["grade", "--rubric", "week11", "x"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("not a built-in rubric"), "{stderr}");
}
