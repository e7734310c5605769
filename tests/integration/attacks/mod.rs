//! Attacks on grading by a submission that controls its sandbox, the bundled adapter included
//! (docs/sandbox.md, "What a submission controls"), each made on the course's real code: the
//! unmodified skeleton of weeks 5 to 10 (`RTORACLE_COURSE_CODE`) plus one extra module,
//! `tests/fixtures/attacks/numpy.py`, which the course's `import numpy` picks up from the
//! submission's folder and which replaces the adapter's handlers at import time (its MODE says
//! how it then answers).
//!
//! Each attack must earn at most 5% of the points it targets, and be flagged where a person
//! looks (the report's `code.protocol_errors`, the gradebook's status), not only scored 0; a seed
//! probe must find the rubric's secret seed nowhere, in no spelling: not in any byte sent to the
//! submission (recorded with `RTORACLE_RECORD_REQUESTS`), not in any report. And honest code is
//! not charged: the course's solutions score their steered scattering cases, and a Lambertian
//! that draws its random numbers with numpy instead of the course's helpers still passes.
//!
//! Points are asserted on the groups each attack targets (the function groups; the samplers
//! among them for the short sample lists): what the skeleton earns by itself elsewhere is the
//! rubric weights' business.

mod hostile;
mod raised;
mod renders;
mod sandbox;

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::{CourseTree, course_week_copy, rtoracle};

/// The rubric's secret seed in these tests.
const SECRET: u64 = 987_654_321;

/// The hostile module in `mode` (see its docstring).
fn attack_module(mode: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/attacks/numpy.py");
    let text = std::fs::read_to_string(path).expect("the attack module");
    assert!(text.contains("@MODE@"));
    text.replace("@MODE@", mode)
}

/// The built-in rubric of `week` with its seed set to [`SECRET`], keeping only its groups for
/// which `keep` says so.
fn rubric(week: u8, keep: impl Fn(&str) -> bool) -> String {
    let out = rtoracle()
        .args(["grade", "--print-rubric", &format!("week{week:02}")])
        .output()
        .expect("rtoracle runs");
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut parts = text.split("[[group]]");
    let head = parts
        .next()
        .unwrap()
        .replace("seed = 0", &format!("seed = {SECRET}"));
    assert!(head.contains(&format!("seed = {SECRET}")), "{head}");
    let groups: String = parts
        .filter(|g| keep(g))
        .map(|g| format!("[[group]]{g}"))
        .collect();
    head + &groups
}

fn functions_only(group: &str) -> bool {
    group.contains("kind = \"functions\"")
}

/// `rubric` with one more functions group, `id`, of the week's checks `functions` (for a check
/// the week's rubric shows without points, such as week 5's Lambertian, which its skeleton
/// gives).
fn with_group(rubric: &str, id: &str, functions: &[&str]) -> String {
    let list: Vec<String> = functions.iter().map(|f| format!("\"{f}\"")).collect();
    format!(
        "{rubric}\n[[group]]\nid = \"{id}\"\nname = \"{id}\"\nkind = \"functions\"\nfunctions = [{}]\npoints = 20\nvisibility = \"visible\"\n",
        list.join(", ")
    )
}

/// What one graded submission left: its report, its folder of reports, and what was sent.
struct Graded {
    report: Value,
    out: PathBuf,
    stdout: String,
    stderr: String,
    requests: String,
    _tmp: tempfile::TempDir,
}

/// Grades week `week`'s skeleton (or solution) with `module` as its `numpy.py` (none when
/// `None`) and `patch` applied to its files, under the rubric text `rubric`, recording every
/// byte sent to it.
fn grade(
    week: u8,
    tree: CourseTree,
    module: Option<&str>,
    patch: &dyn Fn(&Path),
    rubric: &str,
) -> Option<Graded> {
    let (tmp, sub) = course_week_copy("attacks", week, tree)?;
    if let Some(m) = module {
        std::fs::write(sub.join("numpy.py"), m).unwrap();
    }
    patch(&sub);
    let rubric_file = tmp.path().join("rubric.toml");
    std::fs::write(&rubric_file, rubric).unwrap();
    let out = tmp.path().join("out");
    let requests = tmp.path().join("requests.txt");
    let run = rtoracle()
        .env("RTORACLE_RECORD_REQUESTS", &requests)
        .arg("grade")
        .arg(&sub)
        .arg("--rubric")
        .arg(&rubric_file)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("rtoracle runs");
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(
        matches!(run.status.code(), Some(0 | 1)),
        "week {week}: grade exited {:?}: {stderr}",
        run.status
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    Some(Graded {
        report,
        out,
        stdout: String::from_utf8_lossy(&run.stdout).into_owned(),
        stderr,
        requests: std::fs::read_to_string(&requests).unwrap_or_default(),
        _tmp: tmp,
    })
}

/// Points earned and available over the checks `pick` selects.
fn points(report: &Value, pick: impl Fn(&str) -> bool) -> (f64, f64) {
    let checks = report["checks"].as_array().unwrap();
    checks
        .iter()
        .filter(|c| pick(c["id"].as_str().unwrap()))
        .fold((0.0, 0.0), |(s, m), c| {
            (
                s + c["score"].as_f64().unwrap(),
                m + c["max_score"].as_f64().unwrap(),
            )
        })
}

fn protocol_errors(report: &Value) -> u64 {
    report["code"]["protocol_errors"].as_u64().unwrap()
}

/// The ids of week `week`'s statistical checks.
fn sampler_ids(week: u8) -> Vec<&'static str> {
    use rtoracle::weekly::checks::{Body, week_checks};
    week_checks(rtoracle::weekly::week::Week::new(week).unwrap(), 0)
        .into_iter()
        .filter(|c| matches!(c.body, Body::Samples { .. }))
        .map(|c| c.id)
        .collect()
}

fn no_patch(_: &Path) {}

/// Every function request answered `{"unsteered": true}` (samplers `{"samples": []}`), the real
/// answers with the marker written beside `result`, or empty answers: no function points, and
/// a protocol error per case, in the report and in the gradebook's status.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn a_hijacked_adapter_answering_markers_earns_nothing_and_is_flagged() {
    for week in 5..=10 {
        let rubric = rubric(week, functions_only);
        for mode in ["marker", "beside", "empty"] {
            let Some(g) = grade(
                week,
                CourseTree::Skeleton,
                Some(&attack_module(mode)),
                &no_patch,
                &rubric,
            ) else {
                return;
            };
            let (got, max) = points(&g.report, |id| id.starts_with("functions."));
            assert!(max >= 70.0 - 1e-9, "week {week}: {max}");
            assert!(
                got <= 0.05 * max,
                "week {week}, {mode}: the hijacked skeleton's functions earn {got} of {max}: {}",
                g.stdout
            );
            let flagged = protocol_errors(&g.report);
            assert!(
                flagged > 0,
                "week {week}, {mode}: no protocol error counted"
            );
            // Each failing check says so, in words.
            let said = g.report["checks"]
                .as_array()
                .unwrap()
                .iter()
                .filter_map(|c| c["function"]["failure"]["problem"].as_str())
                .any(|p| p.contains("protocol error"));
            assert!(said, "week {week}, {mode}: no failure says protocol error");
        }
    }
}

/// Samplers that answer one sample whatever was asked for (the real code's where it runs):
/// the statistical checks earn nothing (none of their points: every week's but week 5's and
/// week 8's groups hold some), each such answer is a protocol error.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn short_sample_lists_earn_nothing_for_the_samplers() {
    for week in 5..=10 {
        let samplers = sampler_ids(week);
        assert!(!samplers.is_empty(), "week {week}");
        let Some(g) = grade(
            week,
            CourseTree::Skeleton,
            Some(&attack_module("short")),
            &no_patch,
            &rubric(week, functions_only),
        ) else {
            return;
        };
        let is_sampler = |id: &str| {
            id.starts_with("functions.") && samplers.iter().any(|s| id.ends_with(&format!(".{s}")))
        };
        let (got, max) = points(&g.report, is_sampler);
        // Week 5's and week 8's groups hold no sampler (their samplers are earlier weeks' or
        // the skeleton's, without points).
        assert_eq!(max > 0.0, week != 5 && week != 8, "week {week}: {max}");
        assert!(
            got <= 0.05 * max,
            "week {week}: short sample lists earn {got} of the samplers' {max}: {}",
            g.stdout
        );
        assert!(protocol_errors(&g.report) > 0, "week {week}: not flagged");
    }
}

/// The spellings of the secret seed a probe could print.
fn spellings(seed: u64) -> Vec<String> {
    vec![
        seed.to_string(),
        format!("{seed:x}"),
        format!("{seed:X}"),
        format!("{:x}", seed.swap_bytes()),
        format!("{:x}", (seed as u32).swap_bytes()),
    ]
}

/// Every file under `dir`, with its text (lossy).
fn files_under(dir: &Path) -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            let bytes = std::fs::read(&path).unwrap();
            out.push((path, String::from_utf8_lossy(&bytes).into_owned()));
        }
    }
    out
}

/// A probe raises on every request, intersections, functions, samplers and renders, with the
/// request in the exception's message: the reports show the requests, and the secret seed is in
/// none of them, nor in any byte sent.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn seed_probes_through_every_request_kind_find_no_secret() {
    for week in [5, 10] {
        let Some(g) = grade(
            week,
            CourseTree::Skeleton,
            Some(&attack_module("probe")),
            &no_patch,
            &rubric(week, |_| true),
        ) else {
            return;
        };
        // Every kind of request went out, and the probe's text reached the reports.
        for kind in [
            "\"op\":\"intersect\"",
            "\"op\":\"render\"",
            "\"op\":\"scatter\"",
            "\"op\":\"sample_",
            "\"seed\":",
        ] {
            assert!(g.requests.contains(kind), "week {week}: no {kind} sent");
        }
        let reports = files_under(&g.out);
        let shown = |needle: &str| reports.iter().any(|(_, text)| text.contains(needle));
        assert!(
            shown("PROBE REQ=") && shown("\\\"op\\\": \\\"render\\\""),
            "week {week}: the probe's output is not in the reports"
        );
        for spelling in spellings(SECRET) {
            assert!(
                !g.requests.contains(&spelling),
                "week {week}: the secret ({spelling}) was sent to the submission"
            );
            for (path, text) in &reports {
                assert!(
                    !text.contains(&spelling),
                    "week {week}: the secret ({spelling}) is in {}",
                    path.display()
                );
            }
            assert!(!g.stdout.contains(&spelling) && !g.stderr.contains(&spelling));
        }
        // report.json names the secret by its digest only.
        let digest = rtoracle::secret::digest(SECRET);
        assert!(
            g.report["reproducibility"]["code_checker"]
                .as_str()
                .unwrap()
                .contains(&digest),
            "{}",
            g.report["reproducibility"]
        );
        let (got, max) = points(&g.report, |_| true);
        assert!(got <= 0.05 * max, "week {week}: the probe earns {got}");
    }
}

/// The result of function `id` in a graded report (its check holds it when it did not pass).
fn check<'a>(report: &'a Value, id: &str) -> &'a Value {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"].as_str().unwrap().ends_with(&format!(".{id}")))
        .unwrap_or_else(|| panic!("no check {id}"))
}

/// The course's solutions: their steered scattering cases are scored (none left "not scored")
/// and right, and their function groups keep full marks.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn honest_solutions_score_their_steered_cases() {
    let steered: &[(u8, &[&str])] = &[
        (5, &["lambertian"]),
        (6, &["dielectric"]),
        (7, &["metal"]),
        (8, &[]),
        (9, &["lambertian"]),
        (10, &[]),
    ];
    for &(week, ids) in steered {
        let mut text = rubric(week, functions_only);
        if week == 5 {
            text = with_group(
                &text,
                "functions.scattering",
                &["lambertian", "lambertian-lobe"],
            );
        }
        let Some(g) = grade(week, CourseTree::Solution, None, &no_patch, &text) else {
            return;
        };
        for id in ids {
            let c = check(&g.report, id);
            let msg = c["message"].as_str().unwrap();
            assert_eq!(c["score"], c["max_score"], "week {week} {id}: {msg}");
            // "N of N scored cases right." with N > 0 and nothing left unscored.
            let n: usize = msg
                .split(" passed: ")
                .nth(1)
                .and_then(|r| r.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("week {week} {id}: {msg}"));
            assert!(
                n > 0 && msg.contains(&format!("{n} of {n} scored cases right.")),
                "week {week} {id}: {msg}"
            );
        }
        for c in g.report["checks"].as_array().unwrap() {
            let id = c["id"].as_str().unwrap();
            assert_eq!(
                c["score"], c["max_score"],
                "week {week}: {id}: {}",
                c["message"]
            );
        }
        assert_eq!(protocol_errors(&g.report), 0, "week {week}");
    }
}

/// Replaces `from` by `to` in the submission's `file` (once, exactly).
fn patch_file(sub: &Path, file: &str, from: &str, to: &str) {
    let path = sub.join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches(from).count(), 1, "{file}: {from}");
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

/// A week-5 Lambertian that draws its unit vector with numpy's normal distribution (a correct
/// sampler the steering cannot reach) passes, its cases judged by what they do; the same code
/// normalising `n + u` (a catalogued mistake) fails and is named.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn a_lambertian_drawing_otherwise_is_judged_by_what_it_does() {
    const DRAW: &str = "rtu.Vec3.unit_vector(rtu.Vec3(*__import__('numpy').random.normal(size=3)))";
    let course = "hHinfo.getNormal() + rtu.Vec3.random_vec3_unit()";
    let rubric = with_group(
        &rubric(5, functions_only),
        "functions.scattering",
        &["lambertian", "lambertian-lobe"],
    );
    let other = move |sub: &Path| {
        patch_file(
            sub,
            "RT_material.py",
            course,
            &format!("hHinfo.getNormal() + {DRAW}"),
        )
    };
    let Some(g) = grade(5, CourseTree::Solution, None, &other, &rubric) else {
        return;
    };
    let c = check(&g.report, "lambertian");
    assert_eq!(c["score"], c["max_score"], "{}", c["message"]);
    let lobe = check(&g.report, "lambertian-lobe");
    assert_eq!(lobe["score"], lobe["max_score"], "{}", lobe["message"]);
    let normalised = move |sub: &Path| {
        patch_file(
            sub,
            "RT_material.py",
            course,
            &format!("rtu.Vec3.unit_vector(hHinfo.getNormal() + {DRAW})"),
        )
    };
    let g = grade(5, CourseTree::Solution, None, &normalised, &rubric).unwrap();
    let c = check(&g.report, "lambertian");
    assert_eq!(c["score"], 0.0, "{}", c["message"]);
    // Its samples name the mistake (its exact cases cannot: its u is not the steered one).
    let lobe = check(&g.report, "lambertian-lobe");
    assert_eq!(lobe["score"], 0.0, "{}", lobe["message"]);
    assert!(
        lobe["message"]
            .as_str()
            .unwrap()
            .contains("n_plus_u_normalised"),
        "{}",
        lobe["message"]
    );
}

/// A batch's gradebook asks for a review of a submission whose answers broke the protocol.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn the_gradebook_asks_for_a_review_of_protocol_errors() {
    let Some((tmp, sub)) = course_week_copy("attacks", 5, CourseTree::Skeleton) else {
        return;
    };
    let batch = tmp.path().join("batch");
    std::fs::create_dir(&batch).unwrap();
    std::fs::write(sub.join("numpy.py"), attack_module("marker")).unwrap();
    std::fs::rename(&sub, batch.join("hijacker")).unwrap();
    let rubric_file = tmp.path().join("rubric.toml");
    std::fs::write(&rubric_file, rubric(5, functions_only)).unwrap();
    let out = tmp.path().join("out");
    let run = rtoracle()
        .arg("grade")
        .arg("--batch")
        .arg(&batch)
        .arg("--rubric")
        .arg(&rubric_file)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("rtoracle runs");
    assert!(
        matches!(run.status.code(), Some(0 | 1)),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let csv = std::fs::read_to_string(out.join("gradebook.csv")).unwrap();
    let row = csv.lines().find(|l| l.starts_with("hijacker,")).unwrap();
    assert!(
        row.contains(",review: ")
            && row.ends_with("protocol errors (a broken or hijacked adapter)"),
        "{csv}"
    );
}
