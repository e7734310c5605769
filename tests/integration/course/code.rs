//! The course's real code is the fixture (`RTORACLE_COURSE_CODE`: each week's skeleton and the
//! instructor's solution, weeks 4 to 10): `rtoracle check --week N` passes every function of
//! the solution and fails the week's own tasks on the skeleton; every function check's
//! reference answer is the course's own answer (each case's printed reproduction, run in a copy
//! of the week's solution, prints it); each catalogued mistake, built as a small patch of the
//! real solution at test time, is caught and named; departures that keep the course's
//! behaviour are named and not charged; a module nothing needs cannot sink the checks; the
//! week of each folder is found.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use rtoracle::bench::harness::course_python_or_skip;
use rtoracle::weekly::checks::{Body, week_checks};
use rtoracle::weekly::expect::{Expected, Want};
use rtoracle::weekly::{week::Week, week::detect};
use serde_json::{Value, json};

use crate::common::{CourseTree, course_code, course_week_copy};

fn python() -> Option<&'static Path> {
    static PYTHON: OnceLock<Option<PathBuf>> = OnceLock::new();
    PYTHON
        .get_or_init(|| course_python_or_skip("the course-code tests"))
        .as_deref()
}

/// `rtoracle check --week N --json` on `folder`: the report, and stderr.
fn check(folder: &Path, week: u8) -> (Value, String) {
    let python = python().expect("a Python with numpy and PIL");
    let out = crate::common::rtoracle()
        .args(["check", "--json", "--week", &week.to_string(), "--python"])
        .arg(python)
        .arg(folder)
        .output()
        .expect("rtoracle runs");
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let report: Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{}: no JSON report ({e}): {stderr}", folder.display()));
    (report, stderr)
}

/// A function's verdict in a report.
#[derive(Debug)]
struct Verdict {
    id: String,
    status: String,
    /// The names of the mistakes (or departures) it fits.
    mistakes: Vec<String>,
    /// Its smallest failing case's problem.
    problem: String,
    notes: Vec<String>,
}

/// The report's functions.
fn functions(report: &Value) -> Vec<Verdict> {
    let strings = |v: &Value, key: &str| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|m| {
                let m = if key.is_empty() { m } else { &m[key] };
                m.as_str().unwrap().to_string()
            })
            .collect()
    };
    report["functions"]["functions"]
        .as_array()
        .expect("a functions list")
        .iter()
        .map(|f| Verdict {
            id: f["id"].as_str().unwrap().to_string(),
            status: f["status"].as_str().unwrap().to_string(),
            mistakes: strings(&f["mistakes"], "name"),
            problem: f["failure"]["problem"].as_str().unwrap_or("").to_string(),
            notes: strings(&f["notes"], ""),
        })
        .collect()
}

fn status_of(report: &Value, id: &str) -> String {
    functions(report)
        .into_iter()
        .find(|f| f.id == id)
        .unwrap_or_else(|| panic!("no function {id}"))
        .status
}

/// The tasks each week's skeleton leaves to the student (its README's, as the skeleton's code
/// blanks them): the functions that must fail on the skeleton.
fn tasks(week: u8) -> &'static [&'static str] {
    match week {
        5 => &["direct-term"],
        6 => &["reflect", "mirror", "dielectric", "dielectric-choice"],
        7 => &["quad-uv", "metal", "metal-fuzz"],
        8 => &["phong", "blinn", "cook-torrance"],
        9 => &["cosine-hemisphere", "lambertian", "lambertian-lobe"],
        _ => &["lens", "ray-time"],
    }
}

/// Week `week`'s solution passes every function (the given ones included) and every
/// intersection; its skeleton fails each of the week's tasks.
fn solution_passes_and_skeleton_fails(week: u8) {
    let Some((_guard, solution)) = course_week_copy("course code", week, CourseTree::Solution)
    else {
        return;
    };
    if python().is_none() {
        return;
    }
    let (report, stderr) = check(&solution, week);
    let failing: Vec<_> = functions(&report)
        .into_iter()
        .filter(|f| f.status != "passed")
        .collect();
    assert!(
        failing.is_empty(),
        "week {week}'s solution: {failing:#?}\n{stderr}"
    );
    assert_eq!(report["intersections"]["failed"], 0, "week {week}");
    assert_eq!(report["intersections"]["errors"], 0, "week {week}");
    let (_guard, skeleton) = course_week_copy("course code", week, CourseTree::Skeleton).unwrap();
    let (report, _) = check(&skeleton, week);
    for id in tasks(week) {
        assert_eq!(
            status_of(&report, id),
            "failed",
            "{id} on week {week}'s skeleton"
        );
    }
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week05_solution_passes_every_function_and_the_skeleton_fails_its_task() {
    solution_passes_and_skeleton_fails(5);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week06_solution_passes_every_function_and_the_skeleton_fails_its_tasks() {
    solution_passes_and_skeleton_fails(6);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week07_solution_passes_every_function_and_the_skeleton_fails_its_tasks() {
    solution_passes_and_skeleton_fails(7);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week08_solution_passes_every_function_and_the_skeleton_fails_its_tasks() {
    solution_passes_and_skeleton_fails(8);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week09_solution_passes_every_function_and_the_skeleton_fails_its_tasks() {
    solution_passes_and_skeleton_fails(9);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week10_solution_passes_every_function_and_the_skeleton_fails_its_tasks() {
    solution_passes_and_skeleton_fails(10);
}

/// Week 4's solution passes the intersections and its skeleton fails them.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week04_solution_passes_the_intersections_and_the_skeleton_fails_them() {
    let Some(python) = python() else { return };
    for (tree, code) in [(CourseTree::Solution, 0), (CourseTree::Skeleton, 1)] {
        let Some((_guard, folder)) = course_week_copy("course code", 4, tree) else {
            return;
        };
        let out = crate::common::rtoracle()
            .args(["check", "--week", "4", "--python"])
            .arg(python)
            .arg(&folder)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(code), "{tree:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Every reproduction, run in the course's folder, prints the reference's answer.

/// Runs each `(id, repro)` in the current folder (a copy of a week's solution) and prints one
/// JSON line per case: what its last `print` printed (each argument as JSON: a Vec3 or Color as
/// its three numbers) or the error it raised. The course's modules are imported once; what a
/// reproduction replaces in them (`rtu.random_double`, `rtu.Vec3.random_vec3_unit`) is put back
/// after it.
const HARNESS: &str = r#"
import builtins, glob, json, os, sys, traceback
sys.dont_write_bytecode = True
sys.path.insert(0, os.getcwd())
cases = json.load(open(sys.argv[1]))
for p in sorted(glob.glob("RT_*.py")):
    name = os.path.basename(p)[:-3]
    if name not in ("RT_renderer", "RT_pbar"):
        __import__(name)

def conv(x):
    if hasattr(x, "e"):
        return [float(c) for c in x.e]
    if isinstance(x, dict):
        return {k: conv(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [conv(v) for v in x]
    if x is None or isinstance(x, bool):
        return x
    try:
        return float(x)
    except Exception:
        return repr(x)

def snapshot():
    saved = []
    for name, m in list(sys.modules.items()):
        if name.startswith("RT_") and m is not None:
            saved.append((m, dict(vars(m))))
            for v in list(vars(m).values()):
                if isinstance(v, type) and v.__module__ == name:
                    saved.append((v, dict(vars(v))))
    return saved

def restore(saved):
    for obj, d in saved:
        now = vars(obj)
        for k in list(now.keys()):
            if k not in d:
                try:
                    delattr(obj, k)
                except Exception:
                    pass
        for k, v in d.items():
            if now.get(k) is not v:
                try:
                    setattr(obj, k, v)
                except Exception:
                    pass

for case in cases:
    printed = []
    def capture(*args, **kwargs):
        printed.append([conv(a) for a in args])
    saved = snapshot()
    out = {"id": case["id"]}
    try:
        exec(case["repro"], {"__name__": "__repro__", "print": capture})
        out["printed"] = printed[-1] if printed else None
    except BaseException as exc:
        out["error"] = "".join(traceback.format_exception_only(type(exc), exc)).strip()
    restore(saved)
    builtins.print(json.dumps(out))
"#;

/// A case's reproduction as the harness gets it, with what the reference expects and whether
/// it is scored.
struct Repro {
    id: String,
    repro: String,
    expect: Option<Expected>,
    scored: bool,
    course_raises: bool,
}

fn repros(week: u8) -> Vec<Repro> {
    let mut out = Vec::new();
    for check in week_checks(Week::new(week).unwrap(), 0) {
        match &check.body {
            Body::Cases { cases, .. } | Body::Steered { cases, .. } => {
                for c in cases {
                    out.push(Repro {
                        id: c.id.clone(),
                        repro: c.repro.clone(),
                        expect: Some(c.expect.clone()),
                        scored: c.class.is_scored(),
                        course_raises: matches!(
                            c.class,
                            rtoracle::weekly::expect::Class::CourseFails(_)
                        ),
                    });
                }
            }
            Body::Samples { repro, .. } => out.push(Repro {
                id: format!("{}-samples", check.id),
                repro: repro.clone(),
                expect: None,
                scored: false,
                course_raises: false,
            }),
        }
    }
    out
}

/// What a reproduction printed, as the answer the check judges: one dict keyed by the answer's
/// fields, or the fields' values in order (a leading `hit` or `scattered` flag may be left out);
/// and the expectation restricted to the fields printed.
fn as_answer(printed: &[Value], expect: &Expected) -> Result<(Value, Expected), String> {
    if let [Value::Object(map)] = printed {
        let fields: Vec<(String, Want)> = expect
            .fields
            .iter()
            .filter(|(k, _)| map.contains_key(k))
            .cloned()
            .collect();
        if fields.is_empty() || fields.len() != map.len() {
            return Err(format!(
                "printed keys {:?} are not the answer's",
                map.keys()
            ));
        }
        return Ok((Value::Object(map.clone()), Expected { fields }));
    }
    let mut fields = expect.fields.clone();
    if printed.len() + 1 == fields.len()
        && matches!(fields[0], (ref k, Want::Bool(_)) if k == "hit" || k == "scattered")
    {
        fields.remove(0);
    }
    if printed.len() != fields.len() {
        return Err(format!(
            "printed {} values for the {} fields {:?}",
            printed.len(),
            fields.len(),
            fields.iter().map(|f| &f.0).collect::<Vec<_>>()
        ));
    }
    let answer: serde_json::Map<String, Value> = fields
        .iter()
        .zip(printed)
        .map(|((k, _), v)| (k.clone(), v.clone()))
        .collect();
    Ok((Value::Object(answer), Expected { fields }))
}

/// Every reproduction the checks of week `week` print runs in a copy of the week's solution,
/// and on every scored case it prints the reference's answer within the check's tolerance: the
/// course's own function agrees with the reference on every input the checks send.
fn reproductions_give_the_courses_values(week: u8) {
    let Some((guard, solution)) = course_week_copy("course code", week, CourseTree::Solution)
    else {
        return;
    };
    let Some(python) = python() else { return };
    let cases = repros(week);
    let input = guard.path().join("cases.json");
    let list: Vec<Value> = cases
        .iter()
        .map(|c| json!({"id": c.id, "repro": c.repro}))
        .collect();
    std::fs::write(&input, serde_json::to_string(&list).unwrap()).unwrap();
    let harness = guard.path().join("harness.py");
    std::fs::write(&harness, HARNESS).unwrap();
    let out = std::process::Command::new(python)
        .arg("-B")
        .arg(&harness)
        .arg(&input)
        .current_dir(&solution)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<Value> = stdout
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .filter(|v: &Value| v.get("id").is_some())
        .collect();
    assert_eq!(
        lines.len(),
        cases.len(),
        "week {week}: the harness stopped: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut wrong = Vec::new();
    let mut compared = 0;
    for (case, line) in cases.iter().zip(&lines) {
        assert_eq!(line["id"], case.id.as_str());
        if let Some(e) = line.get("error") {
            if !case.course_raises {
                wrong.push(format!("{}: raised {e}\n{}", case.id, case.repro));
            }
            continue;
        }
        let (Some(expect), true) = (&case.expect, case.scored) else {
            continue;
        };
        let printed = line["printed"].as_array().cloned().unwrap_or_default();
        match as_answer(&printed, expect).and_then(|(a, e)| e.judge(&a).map(|()| a)) {
            Ok(_) => compared += 1,
            Err(why) => wrong.push(format!("{}: {why}\n{}", case.id, case.repro)),
        }
    }
    assert!(
        wrong.is_empty(),
        "week {week}: {} reproductions do not give the reference's answer:\n{}",
        wrong.len(),
        wrong.join("\n\n")
    );
    let scored = cases
        .iter()
        .filter(|c| c.scored && c.expect.is_some())
        .count();
    assert_eq!(compared, scored, "week {week}: every scored case compared");
    assert!(scored > 30, "week {week}: only {scored} scored cases");
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week05_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(5);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week06_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(6);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week07_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(7);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week08_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(8);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week09_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(9);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week10_reproductions_give_the_courses_values() {
    reproductions_give_the_courses_values(10);
}

// ---------------------------------------------------------------------------------------------
// The catalogued mistakes, as patches of the real solution.

/// A mistake (or a departure) as edits of week `week`'s solution: in `file`, each `old` text
/// (which must occur, `all` its occurrences or exactly once) becomes `new`.
struct Patch {
    week: u8,
    name: &'static str,
    file: &'static str,
    edits: &'static [(&'static str, &'static str)],
    all: bool,
}

const fn patch(
    week: u8,
    name: &'static str,
    file: &'static str,
    edits: &'static [(&'static str, &'static str)],
) -> Patch {
    Patch {
        week,
        name,
        file,
        edits,
        all: false,
    }
}

const fn patch_all(
    week: u8,
    name: &'static str,
    file: &'static str,
    edits: &'static [(&'static str, &'static str)],
) -> Patch {
    Patch {
        week,
        name,
        file,
        edits,
        all: true,
    }
}

/// Applies `p` to the copy `folder` of its week's solution.
fn apply(p: &Patch, folder: &Path) {
    let path = folder.join(p.file);
    let mut text = std::fs::read_to_string(&path).unwrap();
    for (old, new) in p.edits {
        let n = text.matches(old).count();
        assert!(
            if p.all { n >= 1 } else { n == 1 },
            "{}: {:?} occurs {n} times in week {}'s {}",
            p.name,
            old,
            p.week,
            p.file
        );
        text = text.replace(old, new);
    }
    std::fs::write(&path, text).unwrap();
}

/// The catalogued mistakes that function requests show (`tests/fixtures/python/weeks/
/// mistakes.json`'s, and the checks' other named mistakes), as patches of the real code.
const MISTAKES: &[Patch] = &[
    patch(
        5,
        "shadows_missing",
        "RT_integrator.py",
        &[("if not occlusion_hit:", "if True:")],
    ),
    patch(
        5,
        "shadows_inverted",
        "RT_scene.py",
        &[("if number_of_hit > 1:", "if number_of_hit <= 1:")],
    ),
    patch(
        5,
        "light_sphere_occludes",
        "RT_scene.py",
        &[("if number_of_hit > 1:", "if number_of_hit > 0:")],
    ),
    patch(
        5,
        "light_sphere_not_counted",
        "RT_scene.py",
        &[(
            "            if hinfo is not None:\n                number_of_hit",
            "            if hinfo is not None and not obj.material.is_light():\n                number_of_hit",
        )],
    ),
    patch(
        5,
        "n_plus_u_normalised",
        "RT_material.py",
        &[(
            "scattered_direction = hHinfo.getNormal() + rtu.Vec3.random_vec3_unit()",
            "scattered_direction = rtu.Vec3.unit_vector(hHinfo.getNormal() + rtu.Vec3.random_vec3_unit())",
        )],
    ),
    patch(
        5,
        "hemisphere_instead_of_cosine_lobe",
        "RT_material.py",
        &[(
            "scattered_direction = hHinfo.getNormal() + rtu.Vec3.random_vec3_unit()",
            "scattered_direction = rtu.Vec3.random_vec3_on_hemisphere(hHinfo.getNormal())",
        )],
    ),
    patch(
        5,
        "older_direct_term_one_over_d",
        "RT_integrator.py",
        &[
            ("* min(1.0, 1.0/max_distance))", "* (1.0/max_distance))"),
            (
                "return (Le * sinfo.attenuation_color) + self",
                "return Le + self",
            ),
        ],
    ),
    patch(
        6,
        "reflect_sign",
        "RT_material.py",
        &[(
            "return vRay - vNormal*rtu.Vec3.dot_product(vRay, vNormal)*2.0",
            "return vRay + vNormal*rtu.Vec3.dot_product(vRay, vNormal)*2.0",
        )],
    ),
    patch(
        6,
        "refraction_ratio_inverted_on_back_face",
        "RT_material.py",
        &[(
            "refract_ratio = self.IOR\n",
            "refract_ratio = 1.0/self.IOR\n",
        )],
    ),
    patch(
        6,
        "schlick_wrong_cosine",
        "RT_material.py",
        &[(
            "schlick(cos_theta, fRefractRatio) > rtu.random_double()",
            "schlick(sin_theta, fRefractRatio) > rtu.random_double()",
        )],
    ),
    patch(
        6,
        "no_total_internal_reflection",
        "RT_material.py",
        &[("if cannot_refract or schlick(", "if schlick(")],
    ),
    patch(
        6,
        "refract_raw_direction",
        "RT_material.py",
        &[(
            "uv = rtu.Vec3.unit_vector(rRayIn.getDirection())",
            "uv = rRayIn.getDirection()",
        )],
    ),
    patch(
        6,
        "schlick_fraction_inverted",
        "RT_material.py",
        &[("r0 = (1-fIOR) / (1+fIOR)", "r0 = (1+fIOR) / (1-fIOR)")],
    ),
    patch(
        6,
        "refract_without_schlick",
        "RT_material.py",
        &[(
            "if cannot_refract or schlick(cos_theta, fRefractRatio) > rtu.random_double():",
            "if cannot_refract:",
        )],
    ),
    patch(
        6,
        "mirror_reflects_unit_direction",
        "RT_material.py",
        &[(
            "reflect(rRayIn.getDirection(), hHinfo.getNormal())",
            "reflect(rtu.Vec3.unit_vector(rRayIn.getDirection()), hHinfo.getNormal())",
        )],
    ),
    patch(
        6,
        "sky_not_added",
        "RT_integrator.py",
        &[(
            "        return scene.get_sky_background_color(rGen_ray)",
            "        return scene.getBackgroundColor()",
        )],
    ),
    patch(
        7,
        "metal_roughness_ignored",
        "RT_material.py",
        &[(" + rtu.Vec3.random_vec3_unit()*self.roughness", "")],
    ),
    patch(
        7,
        "metal_reflects_raw_direction",
        "RT_material.py",
        &[(
            "reflect(rtu.Vec3.unit_vector(rRayIn.getDirection()), hHinfo.getNormal()) + rtu.Vec3",
            "reflect(rRayIn.getDirection(), hHinfo.getNormal()) + rtu.Vec3",
        )],
    ),
    patch_all(
        7,
        "checker_scale_wrong",
        "RT_texture.py",
        &[("()*self.inv_scale))", "()/self.inv_scale))")],
    ),
    patch_all(
        7,
        "checker_truncates_toward_zero",
        "RT_texture.py",
        &[("int(math.floor(vPoint.", "int((vPoint.")],
    ),
    patch(
        7,
        "checker_on_uv",
        "RT_texture.py",
        &[
            (
                "math.floor(vPoint.x()*self.inv_scale)",
                "math.floor(fu*self.inv_scale)",
            ),
            (
                "math.floor(vPoint.y()*self.inv_scale)",
                "math.floor(fv*self.inv_scale)",
            ),
            ("math.floor(vPoint.z()*self.inv_scale)", "0"),
        ],
    ),
    patch(
        7,
        "uv_swapped",
        "RT_object.py",
        &[("return (u,v)", "return (v,u)")],
    ),
    patch(
        7,
        "v_flipped",
        "RT_texture.py",
        &[(
            "j = int(v*self.img.height)",
            "j = int((1-v)*self.img.height)",
        )],
    ),
    patch(
        7,
        "quad_uv_not_set",
        "RT_object.py",
        &[("        hinfo.set_uv(alpha, beta)\n", "")],
    ),
    patch(
        7,
        "quad_uv_swapped",
        "RT_object.py",
        &[("hinfo.set_uv(alpha, beta)", "hinfo.set_uv(beta, alpha)")],
    ),
    patch(
        7,
        "sky_kept",
        "RT_integrator.py",
        &[(
            "        return scene.getBackgroundColor()",
            "        return scene.get_sky_background_color(rGen_ray)",
        )],
    ),
    patch(
        8,
        "phong_blinn_swapped",
        "RT_material.py",
        &[
            ("class Phong(Material):", "class PhongBody(Material):"),
            ("class Blinn(Material):", "class Phong(Material):"),
            ("class PhongBody(Material):", "class Blinn(Material):"),
        ],
    ),
    patch(
        8,
        "blinn_normalised_half_vector",
        "RT_material.py",
        &[(
            "half_vector = rtu.Vec3.unit_vector(halfvector(-rView.getDirection(), rLight.getDirection()))\n        H_dot_N",
            "half_vector = rtu.Vec3.unit_vector(halfvector(rtu.Vec3.unit_vector(-rView.getDirection()), rtu.Vec3.unit_vector(rLight.getDirection())))\n        H_dot_N",
        )],
    ),
    patch_all(
        8,
        "brdf_missing_kd_over_pi",
        "RT_material.py",
        &[("*self.kd*(1.0/math.pi)", "")],
    ),
    patch(
        8,
        "cook_torrance_missing_pi",
        "RT_material.py",
        &[("diff_color = self.kd/math.pi", "diff_color = self.kd")],
    ),
    patch(
        8,
        "halfvector_normalised",
        "RT_material.py",
        &[(
            "def halfvector(vView, vLight):\n",
            "def halfvector(vView, vLight):\n    return rtu.Vec3.unit_vector(vView + vLight)\n",
        )],
    ),
    patch(
        8,
        "cosine_of_unit_vectors",
        "RT_integrator.py",
        &[(
            "rtu.Vec3.dot_product(hinfo.getNormal(), tolight_dir)",
            "rtu.Vec3.dot_product(hinfo.getNormal(), rtu.Vec3.unit_vector(tolight_dir))",
        )],
    ),
    patch(
        9,
        "hemisphere_instead_of_cosine_lobe",
        "RT_utility.py",
        &[
            (
                "x = math.cos(phi)*math.sqrt(r2)",
                "x = math.cos(phi)*math.sqrt(1-r2*r2)",
            ),
            (
                "y = math.sin(phi)*math.sqrt(r2)",
                "y = math.sin(phi)*math.sqrt(1-r2*r2)",
            ),
            ("z = math.sqrt(1-r2)", "z = r2"),
        ],
    ),
    patch(
        9,
        "lobe_around_wrong_axis",
        "RT_utility.py",
        &[(
            "return self.u()*val.x() + self.v()*val.y() + self.w()*val.z()",
            "return self.u()*val.z() + self.v()*val.y() + self.w()*val.x()",
        )],
    ),
    patch(
        9,
        "onb_right_handed",
        "RT_utility.py",
        &[(
            "vec_u = Vec3.cross_product(unit_w, vec_v)",
            "vec_u = Vec3.cross_product(vec_v, unit_w)",
        )],
    ),
    patch_all(
        9,
        "jitter_outside_pixel",
        "RT_camera.py",
        &[("(self.one_over_sqrt_spp * (s_", "((s_")],
    ),
    patch(
        9,
        "jitter_step_not_frozen",
        "RT_camera.py",
        &[(
            "        self.img_height = self.compute_img_height()\n",
            "        self.img_height = self.compute_img_height()\n        self.one_over_sqrt_spp = 1.0/int(math.floor(math.sqrt(self.samples_per_pixel)))\n",
        )],
    ),
    patch(
        10,
        "defocus_radius_doubled",
        "RT_camera.py",
        &[(
            "math.radians(self.Lens.get_defocus_angle() * 0.5)",
            "math.radians(self.Lens.get_defocus_angle())",
        )],
    ),
    patch(
        10,
        "lens_square_not_disk",
        "RT_utility.py",
        &[(
            "p = Vec3(random_double(-1,1), random_double(-1,1), 0)\n            if p.len_squared() < 1:",
            "p = Vec3(random_double(-1,1), random_double(-1,1), 0)\n            if True:",
        )],
    ),
    patch(
        10,
        "moving_normal_from_start_centre",
        "RT_object.py",
        &[(
            "hit_normal = (hit_point - sphere_center) / self.radius",
            "hit_normal = (hit_point - self.center) / self.radius",
        )],
    ),
    patch(
        10,
        "motion_reversed",
        "RT_object.py",
        &[(
            "return self.center + self.moving_dir*fTime",
            "return self.moving_center - self.moving_dir*fTime",
        )],
    ),
    patch(
        10,
        "intersect_ignores_time",
        "RT_object.py",
        &[(
            "        if self.is_moving:\n            sphere_center",
            "        if False:\n            sphere_center",
        )],
    ),
    patch(
        10,
        "jittered_ray_without_time",
        "RT_camera.py",
        &[(
            "            ray_origin = self.defocus_disk_sample()\n        ray_direction = pixel_sample - ray_origin\n        ray_time = rtu.random_double()              # an additional parameter for motion blur\n\n        return rtr.Ray(ray_origin, ray_direction, ray_time)\n\n    def random_pixel_in_square",
            "            ray_origin = self.defocus_disk_sample()\n        ray_direction = pixel_sample - ray_origin\n        return rtr.Ray(ray_origin, ray_direction)\n\n    def random_pixel_in_square",
        )],
    ),
    patch(
        10,
        "jittered_ray_without_lens",
        "RT_camera.py",
        &[(
            "* 0.5\n\n        ray_origin = self.center\n        if self.Lens.get_defocus_angle() > 1e-06:\n            ray_origin = self.defocus_disk_sample()\n",
            "* 0.5\n\n        ray_origin = self.center\n",
        )],
    ),
];

/// Mistakes no function request can tell from the course: Schlick's `r0` is the same for a
/// ratio and its inverse. Each must pass as the solution does.
const UNTELLABLE: &[Patch] = &[patch(
    6,
    "schlick_ior_inverted",
    "RT_material.py",
    &[(
        "schlick(cos_theta, fRefractRatio) > rtu.random_double()",
        "schlick(cos_theta, 1.0/fRefractRatio) > rtu.random_double()",
    )],
)];

/// Each catalogued mistake of week `week`, patched into a copy of the real solution, fails a
/// function that names it.
fn mistakes_are_caught_and_named(week: u8) {
    if course_code("course code").is_none() || python().is_none() {
        return;
    }
    let mut missed = Vec::new();
    for p in MISTAKES.iter().filter(|p| p.week == week) {
        let (_guard, folder) = course_week_copy("course code", week, CourseTree::Solution).unwrap();
        apply(p, &folder);
        let (report, _) = check(&folder, week);
        let named = functions(&report)
            .into_iter()
            .any(|f| f.status == "failed" && f.mistakes.iter().any(|m| m == p.name));
        if !named {
            let failing: Vec<_> = functions(&report)
                .into_iter()
                .filter(|f| f.status != "passed")
                .map(|f| (f.id, f.mistakes, f.problem))
                .collect();
            missed.push(format!("{}: {failing:?}", p.name));
        }
    }
    for p in UNTELLABLE.iter().filter(|p| p.week == week) {
        let (_guard, folder) = course_week_copy("course code", week, CourseTree::Solution).unwrap();
        apply(p, &folder);
        let (report, _) = check(&folder, week);
        let failing: Vec<_> = functions(&report)
            .into_iter()
            .filter(|f| f.status != "passed")
            .collect();
        assert!(failing.is_empty(), "{}: {failing:?}", p.name);
    }
    assert!(
        missed.is_empty(),
        "week {week}: mistakes not caught and named on the course's code:\n{}",
        missed.join("\n")
    );
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week05_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(5);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week06_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(6);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week07_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(7);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week08_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(8);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week09_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(9);
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn week10_mistakes_are_caught_and_named_on_the_courses_code() {
    mistakes_are_caught_and_named(10);
}

// ---------------------------------------------------------------------------------------------
// Departures that keep the course's behaviour.

/// Schlick's choice moved from `refract` into `Dielectric.scattering` (the material still
/// reflects with Schlick's probability): refract passes, the departure named.
const SCHLICK_IN_DIELECTRIC: &[Patch] = &[patch(
    6,
    "schlick_in_dielectric",
    "RT_material.py",
    &[
        (
            "if cannot_refract or schlick(cos_theta, fRefractRatio) > rtu.random_double():",
            "if cannot_refract:",
        ),
        (
            "        refracted_dir = refract(uv, hHinfo.getNormal(), refract_ratio)\n",
            "        cos_theta = min(rtu.Vec3.dot_product(-uv, hHinfo.getNormal()), 1.0)\n        sin_theta = math.sqrt(1.0 - cos_theta*cos_theta)\n        if refract_ratio*sin_theta <= 1.0 and schlick(cos_theta, refract_ratio) > rtu.random_double():\n            refracted_dir = reflect(uv, hHinfo.getNormal())\n        else:\n            refracted_dir = refract(uv, hHinfo.getNormal(), refract_ratio)\n",
        ),
    ],
)];

/// `init_camera(fAperture, fFocusDist)` (week 10's task 2) with the radius aperture / 2.
const APERTURE: &[Patch] = &[patch(
    10,
    "aperture",
    "RT_camera.py",
    &[
        (
            "def init_camera(self,fDefocusAngle=0.0, fFocusDist=10.0):\n        self.set_Lens(fDefocusAngle, fFocusDist)",
            "def init_camera(self, fAperture=0.0, fFocusDist=10.0):\n        self.set_Lens(fAperture, fFocusDist)",
        ),
        (
            "defocus_radius = self.Lens.get_focus_dist() * math.tan(math.radians(self.Lens.get_defocus_angle() * 0.5))",
            "defocus_radius = self.Lens.get_defocus_angle() / 2.0",
        ),
    ],
)];

/// A Scene whose default background is black: the integrator returns the scene's own colour,
/// and the course's scenes set it (0.01 grey).
const BLACK_DEFAULT: &[Patch] = &[patch(
    7,
    "scene_colour",
    "RT_scene.py",
    &[(
        "cBgcolor=rtu.Color(0.01,0.01,0.01)",
        "cBgcolor=rtu.Color(0.0,0.0,0.0)",
    )],
)];

fn patched_report(patches: &[Patch]) -> Option<Value> {
    course_code("course code")?;
    python()?;
    let week = patches[0].week;
    let (_guard, folder) = course_week_copy("course code", week, CourseTree::Solution).unwrap();
    for p in patches {
        apply(p, &folder);
    }
    Some(check(&folder, week).0)
}

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn departures_that_keep_the_courses_behaviour_are_named_and_not_charged() {
    let Some(report) = patched_report(SCHLICK_IN_DIELECTRIC) else {
        return;
    };
    let fs = functions(&report);
    let refract = fs.iter().find(|f| f.id == "refract").unwrap();
    assert_eq!(refract.status, "passed", "{fs:#?}");
    assert_eq!(refract.mistakes, ["schlick_in_dielectric"], "{fs:#?}");
    assert!(fs.iter().all(|f| f.status == "passed"), "{fs:#?}");
    assert_eq!(report["score"]["score"], 100.0);
    // Without the material's choice it is a mistake, charged in refract and the material.
    let k = MISTAKES
        .iter()
        .position(|p| p.name == "refract_without_schlick")
        .unwrap();
    let Some(report) = patched_report(&MISTAKES[k..=k]) else {
        return;
    };
    assert_eq!(status_of(&report, "refract"), "failed");
    assert_eq!(status_of(&report, "dielectric-choice"), "failed");

    let report = patched_report(APERTURE).unwrap();
    let fs = functions(&report);
    assert!(fs.iter().all(|f| f.status == "passed"), "{fs:#?}");
    for id in ["camera", "lens"] {
        let f = fs.iter().find(|f| f.id == id).unwrap();
        assert!(
            f.notes
                .iter()
                .any(|n| n.contains("init_camera takes the lens's aperture")),
            "{id}: {f:?}"
        );
    }
    let report = patched_report(BLACK_DEFAULT).unwrap();
    let fs = functions(&report);
    assert!(fs.iter().all(|f| f.status == "passed"), "{fs:#?}");
}

// ---------------------------------------------------------------------------------------------
// A module nothing needs cannot sink the checks.

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn a_module_that_fails_to_import_fails_only_what_needs_it_and_is_named() {
    let Some((_guard, folder)) = course_week_copy("course code", 10, CourseTree::Solution) else {
        return;
    };
    if python().is_none() {
        return;
    }
    // A helper nobody imports: every function passes.
    std::fs::write(
        folder.join("RT_transformer.py"),
        "# reads STL meshes\nimport stl\n",
    )
    .unwrap();
    let (report, _) = check(&folder, 10);
    let fs = functions(&report);
    assert!(fs.iter().all(|f| f.status == "passed"), "{fs:#?}");
    // The materials import it: what needs RT_material fails and names the file, the line and
    // the package; what does not (the ONB, the samplers, the camera, the textures) passes.
    let path = folder.join("RT_material.py");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, format!("import RT_transformer\n{text}")).unwrap();
    let (report, _) = check(&folder, 10);
    let fs = functions(&report);
    let reflect = fs.iter().find(|f| f.id == "reflect").unwrap();
    assert_eq!(reflect.status, "failed");
    assert!(
        reflect.problem.contains("RT_material.py could not be imported: RT_transformer.py, line 2 imports stl, which the grader does not provide"),
        "{reflect:?}"
    );
    for id in [
        "onb",
        "unit-disk",
        "camera",
        "lens",
        "checker-texture",
        "quad-uv",
    ] {
        assert_eq!(status_of(&report, id), "passed", "{id}: {fs:#?}");
    }
    assert_eq!(report["intersections"]["failed"], 0);
    assert_eq!(report["intersections"]["errors"], 0);
}

// ---------------------------------------------------------------------------------------------
// The week of a folder.

#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn the_week_of_each_of_the_fourteen_folders_is_found() {
    let Some(root) = course_code("course code") else {
        return;
    };
    for week in 4..=10u8 {
        for tree in ["skeleton", "solution"] {
            let found = detect(&root.join(format!("week{week:02}")).join(tree));
            assert_eq!(
                found.week.map_or(4, Week::number),
                week,
                "week{week:02}/{tree}: {found:?}"
            );
            assert!(
                found.set_aside.is_empty(),
                "week{week:02}/{tree}: {found:?}"
            );
            if week > 4 {
                assert!(found.because.len() >= 3, "week{week:02}/{tree}: {found:?}");
            }
        }
    }
    // One book-style class Metal in a week-5 tree: week 5, and check says why.
    let (_guard, folder) = course_week_copy("course code", 5, CourseTree::Solution).unwrap();
    let path = folder.join("RT_material.py");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        format!("{text}\nclass Metal(Material):\n    def __init__(self, albedo, fuzz):\n        super().__init__()\n"),
    )
    .unwrap();
    let found = detect(&folder);
    assert_eq!(found.week.map(Week::number), Some(5), "{found:?}");
    let Some(python) = python() else { return };
    let out = crate::common::rtoracle()
        .args(["check", "--python"])
        .arg(python)
        .arg(&folder)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("checking as week 5 (found from the files: ")
            && stderr.contains(
                "class Metal in RT_material.py is week 7's only mark here, where 4 of week 5's are"
            ),
        "{stderr}"
    );
    assert_eq!(out.status.code(), Some(0), "{stderr}");
}

// ---------------------------------------------------------------------------------------------
// multiprocessing in a student's code.

/// Week 6's solution whose `reflect` runs `body` first (four-space indented lines).
fn reflect_running(body: &str) -> Option<(tempfile::TempDir, PathBuf)> {
    let (guard, folder) = course_week_copy("course code", 6, CourseTree::Solution)?;
    python()?;
    let path = folder.join("RT_material.py");
    let text = std::fs::read_to_string(&path).unwrap();
    let head = "def reflect(vRay, vNormal):\n";
    assert_eq!(text.matches(head).count(), 1);
    std::fs::write(&path, text.replace(head, &format!("{head}{body}"))).unwrap();
    Some((guard, folder))
}

/// A `multiprocessing.Pool` works inside the sandbox (its semaphores live in the sandbox's own
/// small `/dev/shm`); one past the sandbox's bounds, or one without `/dev/shm` (simulated: the
/// semaphore raises as it does on a read-only `/dev/shm`), fails with a message that says what
/// is missing and what to do.
#[test]
#[cfg_attr(
    not(rtoracle_course_code),
    ignore = "set RTORACLE_COURSE_CODE to the course's code to run it"
)]
fn multiprocessing_works_in_the_sandbox_or_says_what_is_missing() {
    let Some((_guard, folder)) = reflect_running(
        "    import multiprocessing\n    with multiprocessing.Pool(2) as pool:\n        assert pool.map(abs, [-1, -2]) == [1, 2]\n",
    ) else {
        return;
    };
    let (report, stderr) = check(&folder, 6);
    assert_eq!(status_of(&report, "reflect"), "passed", "{stderr}");
    let problem = |body: &str| {
        let (_guard, folder) = reflect_running(body).unwrap();
        let (report, _) = check(&folder, 6);
        let f = functions(&report)
            .into_iter()
            .find(|f| f.id == "reflect")
            .unwrap();
        assert_eq!(f.status, "failed");
        f.problem
    };
    let too_many = problem(
        "    import multiprocessing\n    with multiprocessing.Pool(200) as pool:\n        pool.map(abs, [-1, -2])\n",
    );
    assert!(
        too_many.contains("multiprocessing could not start its worker processes")
            && too_many.contains("ask for a few workers"),
        "{too_many}"
    );
    let no_shm = problem(
        "    import errno, _multiprocessing, multiprocessing\n    class NoShm:\n        SEM_VALUE_MAX = 2 ** 31 - 1\n        def __init__(self, *args, **kwargs):\n            raise OSError(errno.EROFS, 'Read-only file system')\n    _multiprocessing.SemLock = NoShm\n    multiprocessing.Lock()\n",
    );
    assert!(
        no_shm.contains("multiprocessing could not make its locks and semaphores ([Errno 30] Read-only file system): they live in /dev/shm")
            && no_shm.contains("render in one process"),
        "{no_shm}"
    );
}
