//! The fixture submissions of this repository, made into real submissions, and the grading
//! benchmark (`cargo bench --bench grade`, `rtoracle bench grade`): one submission, and a batch
//! of 30 on 2 threads, against a baseline measured in the same run (starting Python once), and
//! that batch and the rendered submission again unsandboxed (same limits and watchdog) for the
//! sandbox's share; and a
//! batch of 10 triangle submissions against the 160x160 scene file of
//! `examples/rubrics/triangles.toml` with a cold golden cache, against the same batch with the
//! built-in `triangles` scene (embedded golden) in the same run: the golden is rendered once
//! per cache, not once per submission.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::Deserialize;

use crate::grade::checkers::images::CompareImageChecker;
use crate::grade::{
    batch, checkers::ImageChecker, checkers::code::CourseCodeChecker, report::Format,
    rubric::Rubric, write::grade_to_dir,
};
use crate::image_io::{Rgb8Image, write_png};
use crate::render::{RenderOptions, render};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FixtureSpec {
    #[serde(default)]
    base: Option<String>,
    #[serde(default)]
    loses: Vec<String>,
    #[serde(default)]
    image: Vec<FixtureImage>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FixtureImage {
    file: String,
    scene: String,
    seed: u64,
    #[serde(default)]
    width: Option<usize>,
    /// `"course"` (default) or `"linear"` (the square root forgotten).
    #[serde(default)]
    encoding: Option<String>,
}

use crate::bench::fixtures::FIXTURE_FILES;

/// The embedded fixture file at `rel` (under `tests/fixtures/`).
fn embedded(rel: &str) -> Option<&'static [u8]> {
    FIXTURE_FILES
        .iter()
        .find(|(path, _)| *path == rel)
        .map(|(_, bytes)| *bytes)
}

/// `tests/fixtures/submissions` of this crate's source (for tests; the benchmark itself uses the
/// copies embedded at build time).
pub fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/submissions")
}

/// The fixture names (the folders holding a `fixture.toml`), sorted.
pub fn fixture_names() -> Vec<String> {
    let mut names: Vec<String> = FIXTURE_FILES
        .iter()
        .filter_map(|(path, _)| {
            path.strip_prefix("submissions/")?
                .strip_suffix("/fixture.toml")
                .map(String::from)
        })
        .collect();
    names.sort();
    names
}

/// Makes fixture `name` a submission in `dest` (created): the shared course modules of
/// `tests/fixtures/python/common`, the `.py` files of its `base`, then its own, and its images rendered by the reference renderer (20 spp, the fixture's seed and
/// width). Returns the rubric groups it is meant to lose points in.
pub fn materialize(name: &str, dest: &Path) -> Result<Vec<String>, String> {
    let spec = materialize_spec(name, dest)?;
    render_images(name, &spec, dest)?;
    Ok(spec.loses)
}

/// Makes fixture `name` a submission in `dest` (created) without its images: the `.py` files
/// of its `base` then its own. Returns the rubric groups it is meant to lose points in.
pub fn materialize_code(name: &str, dest: &Path) -> Result<Vec<String>, String> {
    Ok(materialize_spec(name, dest)?.loses)
}

fn materialize_spec(name: &str, dest: &Path) -> Result<FixtureSpec, String> {
    let spec_path = format!("submissions/{name}/fixture.toml");
    let text = embedded(&spec_path)
        .and_then(|b| std::str::from_utf8(b).ok())
        .ok_or_else(|| format!("{spec_path}: no such fixture"))?;
    let spec: FixtureSpec = toml::from_str(text).map_err(|e| format!("{spec_path}: {e}"))?;
    std::fs::create_dir_all(dest).map_err(|e| format!("{}: {e}", dest.display()))?;
    // The `.py` files directly in the embedded folder `from` (under `tests/fixtures/`).
    let copy_py = |from: &str| -> Result<(), String> {
        for (path, bytes) in FIXTURE_FILES {
            let Some(n) = path.strip_prefix(from).and_then(|r| r.strip_prefix('/')) else {
                continue;
            };
            if n.ends_with(".py") && !n.contains('/') {
                std::fs::write(dest.join(n), bytes).map_err(|e| format!("{n}: {e}"))?;
            }
        }
        Ok(())
    };
    // The course's shared modules (RT_utility, RT_ray, RT_material) are the ones the `check`
    // fixtures use; a fixture's `base` and its own files come on top.
    copy_py("python/common")?;
    if let Some(base) = &spec.base {
        copy_py(&format!("submissions/{base}"))?;
    }
    copy_py(&format!("submissions/{name}"))?;
    Ok(spec)
}

fn render_images(name: &str, spec: &FixtureSpec, dest: &Path) -> Result<(), String> {
    for img in &spec.image {
        let d = crate::scene::builtin(&img.scene).map_err(|e| e.to_string())?;
        let options = RenderOptions {
            samples_per_pixel: 20,
            seed: img.seed,
            ..Default::default()
        };
        let film = render(&d.scene(), &d.camera(img.width), &options).map_err(|e| e.to_string())?;
        write_png(
            &dest.join(&img.file),
            &Rgb8Image {
                width: film.width,
                height: film.height,
                data: match img.encoding.as_deref() {
                    None | Some("course") => film.to_course_rgb8(),
                    Some("linear") => film
                        .mean
                        .iter()
                        .flat_map(|c| c.to_array().map(|x| (255.0 * x.clamp(0.0, 0.999)) as u8))
                        .collect(),
                    Some(other) => return Err(format!("{name}: unknown encoding {other:?}")),
                },
            },
        )
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

/// Baseline: the median of five starts of the interpreter, as the grader must at least do.
fn python_start_baseline() -> f64 {
    let python = ["/usr/bin/python3", "/usr/local/bin/python3", "python3"]
        .into_iter()
        .find(|p| {
            std::process::Command::new(p)
                .arg("-c")
                .arg("pass")
                .status()
                .is_ok()
        })
        .unwrap_or("python3");
    let mut starts: Vec<f64> = (0..5)
        .map(|_| {
            let t = Instant::now();
            let _ = std::process::Command::new(python)
                .args(["-I", "-S", "-c", "pass"])
                .status();
            secs(t.elapsed())
        })
        .collect();
    starts.sort_by(f64::total_cmp);
    starts[2]
}

/// The grader's renders of `honest` sandboxed and not: the first sandboxed run, and the medians
/// of three runs each way.
fn rendered_each_way(
    honest: &Path,
    work: &Path,
    sandboxed: &CourseCodeChecker,
    unsandboxed: &CourseCodeChecker,
) -> (Rendered, f64, f64) {
    let rendered = rendered_one(honest, work, sandboxed, "rendered");
    // One run of a Python render varies by a tenth or more: three of each kind, taking turns
    // (the first sandboxed run is the one shown above), medians compared.
    let mut with_sandbox = vec![rendered.total];
    let mut without = Vec::new();
    for k in 0..3 {
        let out = format!("rendered-unsandboxed-{k}");
        without.push(rendered_one(honest, work, unsandboxed, &out).total);
        if k < 2 {
            let out = format!("rendered-{k}");
            with_sandbox.push(rendered_one(honest, work, sandboxed, &out).total);
        }
    }
    (rendered, median(with_sandbox), median(without))
}

/// Seconds to grade `submission` once from its uploaded images, in every format.
fn graded_once(submission: &Path, rubric: &Rubric, out: &Path) -> f64 {
    let t = Instant::now();
    grade_to_dir(
        submission,
        rubric,
        &CourseCodeChecker::default(),
        &CompareImageChecker::default(),
        out,
        &Format::ALL,
    )
    .expect("grading works");
    secs(t.elapsed())
}

/// Runs the benchmark and returns its figures as text: one submission and a batch of 30, in
/// seconds and against the baseline.
pub fn run() -> String {
    let work = tempfile::tempdir().expect("a temporary folder");
    let names = fixture_names();
    let subs = work.path().join("subs");
    for i in 0..30 {
        let name = &names[i % names.len()];
        materialize(name, &subs.join(format!("{i:02}-{name}"))).expect("fixtures materialize");
    }
    let honest = work.path().join("honest");
    materialize("honest", &honest).expect("the honest fixture");

    let baseline = python_start_baseline();

    // The grader's renders measured on their own (one submission, one core); the other figures
    // judge the uploaded images, as they did before renders, so they stay comparable.
    let sandboxed = CourseCodeChecker::default();
    let isolation = crate::sandbox::detect::isolation_for(&sandboxed.policy)
        .map_or_else(|e| format!("no sandbox: {e}"), |i| i.name().to_string());
    // The sandbox's share: the same work with the same limits and watchdog, no isolation.
    let unsandboxed = CourseCodeChecker {
        policy: crate::sandbox::policy::SandboxPolicy {
            unsandboxed: true,
            ..sandboxed.policy.clone()
        },
        ..CourseCodeChecker::default()
    };
    let (rendered, rendered_sandboxed, rendered_bare) =
        rendered_each_way(&honest, work.path(), &sandboxed, &unsandboxed);
    let rubric = Rubric::week04_uploads();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool");
    let one = pool.install(|| graded_once(&honest, &rubric, &work.path().join("one")));
    let batch_of_30 = |code: &CourseCodeChecker, out: &str| {
        pool.install(|| {
            let t = Instant::now();
            let entries = batch::grade_batch(
                &subs,
                &rubric,
                code,
                &CompareImageChecker::default(),
                &work.path().join(out),
                &Format::ALL,
            )
            .expect("batch grading works");
            assert_eq!(entries.len(), 30);
            secs(t.elapsed())
        })
    };
    let batch_time = batch_of_30(&sandboxed, "batch");
    let unsandboxed_time = batch_of_30(&unsandboxed, "batch-unsandboxed");
    let (builtin, scene_file) = pool.install(|| scene_file_batches(work.path()));
    let mut report = String::new();
    report.push_str(&format!(
        "grade benchmark (2 threads unless said; fixtures: {})",
        names.join(", ")
    ));
    report.push('\n');
    report.push_str(&format!(
        "  baseline: start python3 once            {:8.3} s",
        baseline
    ));
    report.push('\n');
    report.push_str(&format!(
        "  one submission (honest, cold)           {:8.3} s  = {:6.1} x baseline  (target < 10 s; uploaded images)",
        one,
        one / baseline
    ));
    report.push('\n');
    report.push_str(&format!(
        "  one submission, the grader's renders    {:8.3} s  = {:6.1} x baseline  (week-4 rubric, 1 thread; target <= 60 s)",
        rendered.total,
        rendered.total / baseline
    ));
    report.push('\n');
    for (id, spp, seconds) in &rendered.groups {
        report.push_str(&format!(
            "    {id:<36}{seconds:8.3} s  to render at {spp} spp"
        ));
        report.push('\n');
    }
    report.push_str(&format!(
        "    the same, unsandboxed                 {:8.3} s  : the sandbox ({isolation}) costs {:+.1}%  (medians of 3 runs each, {rendered_sandboxed:.3} s sandboxed)",
        rendered_bare,
        100.0 * (rendered_sandboxed / rendered_bare - 1.0)
    ));
    report.push('\n');
    report.push_str(&format!(
        "  batch of 30 (all fixtures, 2 threads)   {:8.3} s  = {:6.1} x baseline, {:.3} s per submission  (target < 180 s)",
        batch_time,
        batch_time / baseline,
        batch_time / 30.0
    ));
    report.push('\n');
    report.push_str(&format!(
        "    the same batch, unsandboxed           {:8.3} s  : the sandbox ({isolation}) costs {:+.1}%",
        unsandboxed_time,
        100.0 * (batch_time / unsandboxed_time - 1.0)
    ));
    report.push('\n');
    report.push_str(&week08_one(work.path()).lines(baseline));
    report.push_str(&format!(
        "  batch of 10, built-in scene 'triangles'  {:8.3} s  (embedded golden; median of 3 runs)",
        builtin
    ));
    report.push('\n');
    report.push_str(&format!(
        "  batch of 10, 160x160 scene file          {:8.3} s  = {:6.2} x built-in  (cold golden cache each run; median of 3; target < 2 x)",
        scene_file,
        scene_file / builtin
    ));
    report.push('\n');
    report
}

/// What grading one submission with the grader's renders took.
struct Rendered {
    /// Wall time of the whole grade, in seconds.
    total: f64,
    /// Per rendered group: id, spp, seconds the render took.
    groups: Vec<(String, u64, f64)>,
}

/// Grades `submission` with the built-in week-4 rubric (which renders both scenes from its
/// code) on one thread, and reads each render's spp and time from its report.
fn rendered_one(submission: &Path, work: &Path, code: &CourseCodeChecker, out: &str) -> Rendered {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let (total, report) = pool.install(|| {
        let t = Instant::now();
        let report = grade_to_dir(
            submission,
            &Rubric::week04(),
            code,
            &CompareImageChecker::default(),
            &work.join(out),
            &Format::ALL,
        )
        .expect("grading works");
        (secs(t.elapsed()), report)
    });
    Rendered {
        total,
        groups: render_times(&report),
    }
}

/// What grading the week-8 solution took.
struct WeekGrade {
    rendered: Rendered,
    score: f64,
}

impl WeekGrade {
    /// Its lines of the benchmark's output.
    fn lines(&self, baseline: f64) -> String {
        let mut out = format!(
            "  one week-8 submission, week08 rubric    {:8.3} s  = {:6.1} x baseline  (the course-shaped solution, 1 thread; target <= 180 s; {:.0} / 100)\n",
            self.rendered.total,
            self.rendered.total / baseline,
            self.score
        );
        for (id, spp, seconds) in &self.rendered.groups {
            out.push_str(&format!(
                "    {id:<36}{seconds:8.3} s  to render at {spp} spp\n"
            ));
        }
        out
    }
}

/// Grades the course-shaped week-8 solution (embedded) with the built-in week08 rubric, its
/// functions and its two scenes rendered from its code, on one thread: the week the course's
/// heaviest scenes per sample are in.
fn week08_one(work: &Path) -> WeekGrade {
    let submission = work.join("week08");
    std::fs::create_dir_all(&submission).expect("a folder");
    for (name, bytes) in crate::bench::fixtures::python_files_in("python/weeks/week08/solution") {
        std::fs::write(submission.join(name), bytes).expect("the fixture is written");
    }
    let rubric = Rubric::builtin("week08").expect("built in");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool");
    let (total, report) = pool.install(|| {
        let t = Instant::now();
        let report = grade_to_dir(
            &submission,
            &rubric,
            &CourseCodeChecker {
                week: rubric.week.and_then(crate::weekly::week::Week::new),
                time_budget: Some(Duration::from_secs_f64(rubric.code_time_budget_seconds)),
                ..CourseCodeChecker::default()
            },
            &CompareImageChecker::default(),
            &work.join("week08-report"),
            &Format::ALL,
        )
        .expect("grading works");
        (secs(t.elapsed()), report)
    });
    WeekGrade {
        rendered: Rendered {
            total,
            groups: render_times(&report),
        },
        score: report.score,
    }
}

/// Each rendered group's id, spp and seconds, from a report.
fn render_times(report: &crate::grade::result::GradeReport) -> Vec<(String, u64, f64)> {
    report
        .checks
        .iter()
        .filter_map(|c| {
            let render = &c.image.as_ref()?.metrics["render"];
            Some((
                c.id.clone(),
                render["spp"].as_u64().unwrap_or(0),
                render["seconds"].as_f64().unwrap_or(f64::NAN),
            ))
        })
        .collect()
}

/// Grades 10 honest triangle submissions twice, with the triangle rubric of `examples/rubrics`
/// (code and image groups): once with its image group on the built-in `triangles` scene, once
/// on its scene file with an empty golden cache. Returns both times in seconds, each the median
/// of three runs.
pub fn scene_file_batches(work: &Path) -> (f64, f64) {
    // The example rubric and its scene file, embedded so an installed binary can run this too.
    let rubrics = work.join("rubrics");
    std::fs::create_dir_all(&rubrics).expect("a rubric folder");
    let text = include_str!("../../examples/rubrics/triangles.toml");
    let rubric_path = rubrics.join("triangles.toml");
    std::fs::write(&rubric_path, text).expect("write the example rubric");
    std::fs::write(
        rubrics.join("triangles-scene.toml"),
        include_str!("../../examples/rubrics/triangles-scene.toml"),
    )
    .expect("write the example scene");
    let file_rubric = Rubric::from_file(&rubric_path).expect("the example rubric is valid");
    let builtin_rubric = Rubric::from_toml(
        &text.replace(
            "scene = \"triangles-scene.toml\"",
            "scene = \"triangles\"\nfile = \"triangles.png\"",
        ),
        "triangles (built-in scene)",
    )
    .expect("the built-in variant is valid");
    let scene_file = file_rubric.groups[1]
        .scene_file
        .clone()
        .expect("a scene-file group");
    let subs = work.join("triangle-subs");
    for i in 0..10u64 {
        let dest = subs.join(format!("{i:02}"));
        std::fs::create_dir_all(&dest).expect("a submission folder");
        for (path, bytes) in FIXTURE_FILES {
            let name = path
                .strip_prefix("python/common/")
                .or_else(|| path.strip_prefix("python/triangle_assignment/"));
            if let Some(name) = name.filter(|n| n.ends_with(".py") && !n.contains('/')) {
                std::fs::write(dest.join(name), bytes).expect("write a course module");
            }
        }
        let builtin = crate::scene::builtin("triangles").expect("the built-in scene");
        for (d, name) in [
            (&scene_file.description, "triangles-scene.png"),
            (&builtin, "triangles.png"),
        ] {
            let options = RenderOptions {
                samples_per_pixel: 20,
                seed: 100 + i,
                ..Default::default()
            };
            let film = render(&d.scene(), &d.camera(None), &options).expect("a render");
            write_png(
                &dest.join(name),
                &Rgb8Image {
                    width: film.width,
                    height: film.height,
                    data: film.to_course_rgb8(),
                },
            )
            .expect("write the image");
        }
    }
    let time = |rubric: &Rubric, out: &str| {
        let mut images = CompareImageChecker::default();
        // A cache of its own for each run: cold every time.
        images.cache_dir = Some(work.join(format!("{out}-cache")));
        let t = Instant::now();
        images
            .prepare(&rubric.image_scenes())
            .expect("the goldens can be made");
        let entries = batch::grade_batch(
            &subs,
            rubric,
            &CourseCodeChecker::default(),
            &images,
            &work.join(out),
            &Format::ALL,
        )
        .expect("batch grading works");
        assert_eq!(entries.len(), 10);
        secs(t.elapsed())
    };
    // Each batch three times, the two kinds taking turns, and the median of each: one run of a
    // batch of Python processes varies by a third from one run to the next on a busy machine.
    let mut builtin = Vec::new();
    let mut scene_file = Vec::new();
    for run in 0..BATCH_RUNS {
        builtin.push(time(&builtin_rubric, &format!("builtin-{run}")));
        scene_file.push(time(&file_rubric, &format!("scene-file-{run}")));
    }
    (median(builtin), median(scene_file))
}

/// How many times [`scene_file_batches`] runs each batch.
const BATCH_RUNS: usize = 3;

/// The median of `values` (not empty).
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
