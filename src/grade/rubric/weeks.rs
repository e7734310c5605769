//! The built-in rubrics of the course's weeks 4 to 10 (`grade --rubric week06`,
//! `--print-rubric week06`, `autograder --rubric week06`), as TOML text a course can print,
//! edit and give back as a file.
//!
//! Week 4's is [`WEEK04_RUBRIC`]. From week 5 on, a week's points
//! go only to that week's own tasks: what the week's skeleton leaves blank and the instructor's
//! solution fills in (the course's code, `weekNN/skeleton` against `weekNN/solution`). Out of
//! 100 points:
//! - **70 points of functions** ([`week_function_groups`]): the functions the week's students
//!   write, each group's points shared equally by its functions. The functions the week's
//!   skeleton already holds (week 6's `refract` and `schlick`, week 9's `ONB` and jitter, ...)
//!   and the earlier weeks' (week 4's intersections included) are checked and reported but carry
//!   no points: the skeleton gives them;
//! - **30 points of images**: the week's `main.py` scenes that the skeleton does not already
//!   render right ([`unscored_image`] names the others, judged and shown without points), each
//!   rendered by the grader from the submission's own `main.py` at a few samples per pixel
//!   ([`week_render_spp`]), and again from a camera the grader moves by an amount drawn from the
//!   rubric's secret ([`crate::grade::checkers::rendered`]): both must match the reference.
//!
//! So the unmodified skeleton earns nothing: every scored function is one it stubs, and every
//! scored image one its stubs (or its `main.py`'s blank materials) make wrong.
//!
//! Week 5 checks the course's current direct term (`E min(1, 1/d)`); a rubric with
//! `accept = ["older_direct_term_one_over_d"]` also passes the earlier version's functions.

use std::fmt::Write as _;

use std::path::Path;

use crate::grade::rubric::{Group, GroupKind, Rubric, RubricError, WEEK04_RUBRIC};
use crate::weekly::week::Week;

/// The names of the built-in rubrics.
pub const BUILTIN_RUBRICS: &[&str] = &[
    "week04", "week05", "week06", "week07", "week08", "week09", "week10",
];

/// The points of a week's functions (the rest are its images').
pub const FUNCTION_POINTS: f64 = 70.0;

/// The points of a week's images.
pub const IMAGE_POINTS: f64 = 30.0;

/// The wall time each of a week's renders may take, in seconds: about four times what the
/// slowest scene of the week takes in the course's Python at [`week_render_spp`] on one core.
pub const WEEK_RENDER_SECONDS: f64 = 120.0;

/// The samples per pixel of the grader's renders of week `week`'s scenes: 2 for weeks 5 to 7
/// (400-pixel-wide scenes of 24 to 44 us a sample: 4 to 10 s each), 4 for weeks 8 and 9 (320 x
/// 180, about 50 us a sample: about 12 s each), and 5 for the jittered scenes of week 10:
/// `render_jittered` takes `floor(sqrt(5))^2 = 4` samples and their sum is divided by 5, as the
/// course's film does (a count that is not a square keeps that departure visible in the
/// golden; at 4 it would vanish). The goldens of those scenes at 5 are compiled in
/// ([`crate::golden::SPP_VARIANTS`]).
pub fn week_render_spp(week: Week) -> u32 {
    match week.number() {
        ..=7 => 2,
        8 | 9 => 4,
        _ => 5,
    }
}

/// A group of a week's functions in its built-in rubric: its id, name, points and the ids of
/// its functions (`crate::weekly::checks`' ids).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FunctionGroup {
    /// Its id (`functions.materials`).
    pub id: &'static str,
    /// A name for people.
    pub name: &'static str,
    /// Its points (the week's add up to [`FUNCTION_POINTS`]).
    pub points: f64,
    /// The functions it scores, each the week's own task.
    pub functions: &'static [&'static str],
}

const fn fg(
    id: &'static str,
    name: &'static str,
    points: f64,
    functions: &'static [&'static str],
) -> FunctionGroup {
    FunctionGroup {
        id,
        name,
        points,
        functions,
    }
}

/// The scored function groups of `week`'s built-in rubric: only what the week's skeleton leaves
/// blank (measured on the course's code: each of these fails on the unmodified skeleton and
/// passes on the instructor's solution):
///
/// | week | the skeleton's blanks | scored functions |
/// |---|---|---|
/// | 5 | the occlusion test and the direct term in `Integrator.compute_scattering` | `direct-term` (`find_occlusion` itself is given) |
/// | 6 | `reflect`, `Mirror`, `Dielectric` | `reflect`; `mirror`, `dielectric`, `dielectric-choice` (`refract`, `schlick`, the sky are given) |
/// | 7 | `Metal`'s reflected direction and fuzz, the quad's `set_uv` | `quad-uv`; `metal`, `metal-fuzz` (the textures and the sphere's uv are given) |
/// | 8 | Phong's and Blinn's BRDF and scattering, Cook-Torrance | `phong`, `blinn`, `cook-torrance` (`halfvector` and the integrator are given) |
/// | 9 | `random_cosine_hemisphere_on_z`, scattering through the ONB | `cosine-hemisphere`, `lambertian`, `lambertian-lobe` (the ONB and the jitter are given) |
/// | 10 | the lens and the time of `get_jittered_ray` | `lens`; `ray-time` |
pub fn week_function_groups(week: Week) -> &'static [FunctionGroup] {
    const W5: &[FunctionGroup] = &[fg(
        "functions.lights",
        "The direct term of point lights, with its shadow test",
        70.0,
        &["direct-term"],
    )];
    const W6: &[FunctionGroup] = &[
        fg("functions.optics", "reflect", 10.0, &["reflect"]),
        fg(
            "functions.materials",
            "Mirror and Dielectric",
            60.0,
            &["mirror", "dielectric", "dielectric-choice"],
        ),
    ];
    const W7: &[FunctionGroup] = &[
        fg(
            "functions.uv",
            "The texture coordinates of quads",
            20.0,
            &["quad-uv"],
        ),
        fg(
            "functions.metal",
            "Metal and its fuzz",
            50.0,
            &["metal", "metal-fuzz"],
        ),
    ];
    const W8: &[FunctionGroup] = &[fg(
        "functions.brdf",
        "The Phong, Blinn and Cook-Torrance BRDFs",
        70.0,
        &["phong", "blinn", "cook-torrance"],
    )];
    const W9: &[FunctionGroup] = &[fg(
        "functions.sampling",
        "The cosine hemisphere and Lambertian scattering through the ONB",
        70.0,
        &["cosine-hemisphere", "lambertian", "lambertian-lobe"],
    )];
    const W10: &[FunctionGroup] = &[
        fg(
            "functions.defocus",
            "The lens of the jittered rays",
            35.0,
            &["lens"],
        ),
        fg(
            "functions.motion",
            "The time of the jittered rays",
            35.0,
            &["ray-time"],
        ),
    ];
    match week.number() {
        5 => W5,
        6 => W6,
        7 => W7,
        8 => W8,
        9 => W9,
        _ => W10,
    }
}

/// A scene of a week: the built-in scene, the file the course's `main.py` writes it to, and the
/// `main.py` function that renders it, when the grader runs that function (its
/// `main_function`).
pub type WeekScene = (&'static str, &'static str, Option<&'static str>);

/// The week's scenes ([`WeekScene`]), each rendered by its `main.py` function.
///
/// Week 7's `main.py` reads the course's pictures (`./textures/earthmap.png`, ...); the grader
/// hands it its own pictures instead (the ones its goldens are made with), so the submission's
/// `ImageTexture` and the reference read the same texels.
pub fn week_scenes(week: Week) -> &'static [WeekScene] {
    match week.number() {
        5 => &[
            ("week05-quad", "week05_quad.png", Some("renderQuad")),
            (
                "week05-quad-light",
                "week05_quad_light1.png",
                Some("renderQuadLight"),
            ),
            (
                "week05-point-light",
                "week05_point_light.png",
                Some("renderPointLight"),
            ),
            (
                "week05-point-light-shadow",
                "week05_point_light_shadow.png",
                Some("renderPointLightShadow"),
            ),
        ],
        6 => &[
            (
                "week06-mirror-point-light",
                "week06_point_light.png",
                Some("renderMirrorPointLight"),
            ),
            (
                "week06-mirrors",
                "week06_glass_sky.png",
                Some("renderMirrors"),
            ),
            (
                "week06-dielectric",
                "week06_dielec_sky.png",
                Some("renderDielectric"),
            ),
        ],
        7 => &[
            (
                "week07-procedural-texture",
                "week07_texture_sky.png",
                Some("renderProceduralTexture"),
            ),
            (
                "week07-earth",
                "week07_texture_earth_sky.png",
                Some("renderEarth"),
            ),
        ],
        8 => &[
            ("week08-phong", "week08_brdf_Phong.png", Some("renderPhong")),
            ("week08-blinn", "week08_brdf_Blinn.png", Some("renderBlinn")),
        ],
        9 => &[("week09-blinn", "week09_nojittered.png", Some("renderBlinn"))],
        _ => &[
            ("week10-dof", "week10_jitter_DoF.png", Some("renderDoF")),
            (
                "week10-moving",
                "week10_moving_nojitter.png",
                Some("renderMoving"),
            ),
        ],
    }
}

/// Why a week's scene is rendered and judged but carries no points in the built-in rubric, when
/// it does not: an image that the week's unmodified skeleton renders right measures nothing of
/// the student's work.
///
/// - `week05-quad`, `week05-quad-light`: no point light, so the week's task (the direct term
///   of point lights) does not show; the skeleton renders them as the solution does.
/// - `week10-dof`: the week-10 skeleton's jittered rays have no lens, and at the grader's
///   samples its render matches the golden (measured at 5 and at 10 spp: the 2-degree lens
///   blurs edges by about 2 pixels, within the noise of a few samples). The lens is scored by
///   its function check instead.
pub fn unscored_image(scene: &str) -> Option<&'static str> {
    match scene {
        "week05-quad" | "week05-quad-light" => Some(
            "the scene has no point light, so the week's task (the direct term of point lights) does not show in it, and the week's skeleton renders it right",
        ),
        "week10-dof" => Some(
            "at the grader's samples the render of the week-10 skeleton, whose jittered rays have no lens, passes this image; the lens is scored by its function check",
        ),
        _ => None,
    }
}

/// The TOML text of the built-in rubric `name` (`week04` ... `week10`), or `None`.
pub fn builtin_rubric_toml(name: &str) -> Option<String> {
    if name == "week04" {
        return Some(WEEK04_RUBRIC.to_string());
    }
    let n: u8 = name.strip_prefix("week")?.parse().ok()?;
    if name.len() != 6 {
        return None;
    }
    Week::new(n).map(week_rubric_toml)
}

/// Writes a number as TOML does not mind (`24.5`, `10`).
fn points(x: f64) -> String {
    let r = (x * 100.0).round() / 100.0;
    if r.fract() == 0.0 {
        format!("{r:.0}")
    } else {
        format!("{r}")
    }
}

/// The built-in rubric of `week` ([module docs](self)).
fn week_rubric_toml(week: Week) -> String {
    let n = week.number();
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# The built-in week-{n} rubric: 100 points, {} for the week's functions and {} for its scenes' images.",
        points(FUNCTION_POINTS),
        points(IMAGE_POINTS)
    );
    t.push_str(
        "# Points go only to the week's own tasks (what its skeleton leaves blank): the functions\n\
         # the skeleton gives and the earlier weeks' (week 4's intersections included) are checked\n\
         # and reported without points, and so are the images the skeleton already renders right.\n",
    );
    let _ = writeln!(t, "name = \"week{n:02}\"");
    let _ = writeln!(t, "week = {n}");
    t.push_str("seed = 0\n");
    t.push_str("alpha = 1e-4 # false-alarm rate of each statistical check of a sampler\n");
    if n == 5 {
        t.push_str(
            "# The direct term checked is the course's current one, E min(1, 1/d) times the albedo.\n\
             # For the earlier one (E / d, not times the albedo), add:\n\
             # accept = [\"older_direct_term_one_over_d\"]\n",
        );
    }
    t.push_str(
        "code_time_budget_seconds = 120 # wall time for all of a submission's code checks\n",
    );
    for g in week_function_groups(week) {
        let list: Vec<String> = g.functions.iter().map(|f| format!("{f:?}")).collect();
        let _ = write!(
            t,
            "\n[[group]]\nid = \"{}\"\nname = \"{}\"\nkind = \"functions\"\nfunctions = [{}]\npoints = {}\nvisibility = \"visible\"\n",
            g.id,
            g.name,
            list.join(", "),
            points(g.points)
        );
    }
    let scenes = week_scenes(week);
    let scored = scenes
        .iter()
        .filter(|(scene, _, _)| unscored_image(scene).is_none())
        .count();
    let each = IMAGE_POINTS / scored.max(1) as f64;
    let spp = week_render_spp(week);
    for (scene, file, function) in scenes {
        let why = unscored_image(scene);
        if let Some(why) = why {
            let _ = write!(t, "\n# No points: {why}.");
        }
        let main = function.map_or_else(String::new, |f| {
            format!("main_function = \"{f}\" # the submission's main.py renders it, through its own film\n")
        });
        let _ = write!(
            t,
            "\n[[group]]\nid = \"image.{scene}\"\nname = \"{scene} rendered from your code ({file})\"\nkind = \"image\"\nfile = \"{file}\"\nscene = \"{scene}\"\nsource = \"render\" # rendered by the grader from the submission's code\n{main}spp = {spp}\nrender_seconds = {}\npoints = {}\nvisibility = \"visible\"\n",
            points(WEEK_RENDER_SECONDS),
            points(if why.is_some() { 0.0 } else { each })
        );
    }
    for (shape, name) in [
        ("sphere", "Sphere intersection (week 4; no points)"),
        (
            "quad",
            "Quad constructor and intersection (week 4; no points)",
        ),
    ] {
        let _ = write!(
            t,
            "\n[[group]]\nid = \"{shape}\"\nname = \"{name}\"\nkind = \"code\"\nshape = \"{shape}\"\npoints = 0\nvisibility = \"visible\"\n"
        );
    }
    t
}

impl Rubric {
    /// The built-in rubric `name` (`week04` ... `week10`,
    /// [`BUILTIN_RUBRICS`]), or `None`.
    pub fn builtin(name: &str) -> Option<Rubric> {
        let text = builtin_rubric_toml(name)?;
        Some(Rubric::from_toml(&text, "built-in").expect("the built-in rubrics are valid"))
    }

    /// The rubric `--rubric` names: a built-in one by its name (`week06`), else a file (a file
    /// called like a built-in rubric is given as `./week06`). With the TOML text it was read from.
    pub fn named(arg: &Path) -> Result<(Rubric, String), RubricError> {
        if let Some(name) = arg.to_str() {
            if let Some(text) = builtin_rubric_toml(name) {
                let rubric = Rubric::from_toml(&text, "built-in")?;
                return Ok((rubric, text));
            }
        }
        let text = std::fs::read_to_string(arg).map_err(|e| RubricError::Read {
            path: arg.display().to_string(),
            message: if e.kind() == std::io::ErrorKind::NotFound {
                format!(
                    "no such file (and not a built-in rubric: {})",
                    BUILTIN_RUBRICS.join(", ")
                )
            } else {
                e.to_string()
            },
        })?;
        let base = arg.parent().unwrap_or(Path::new(""));
        let rubric = Rubric::from_toml_in(&text, &arg.display().to_string(), base)?;
        Ok((rubric, text))
    }
}

/// The rubric's week-5-to-10 keys and its functions groups, checked when it is read.
impl Rubric {
    /// The week, `alpha` and `accept`, and that no function is scored by two groups.
    pub(in crate::grade) fn validate_week(&self) -> Result<(), RubricError> {
        let week = match self.week {
            None => {
                if self.alpha.is_some() || !self.accept.is_empty() {
                    return Err(self.invalid(
                        "alpha and accept are for a rubric with a week (week = 5 to 10)".into(),
                    ));
                }
                return Ok(());
            }
            Some(n) => crate::weekly::week::Week::new(n).ok_or_else(|| {
                self.invalid(format!(
                    "week = {n}: function checks exist for weeks 5 to 10 (leave week out for week 4)"
                ))
            })?,
        };
        if let Some(a) = self.alpha {
            if !(a.is_finite() && a > 0.0 && a < 0.5) {
                return Err(self.invalid(format!(
                    "alpha = {a}: it must be more than 0 and less than 0.5"
                )));
            }
        }
        let known = crate::weekly::checks::alternatives(week);
        for name in &self.accept {
            if !known.contains(&name.as_str()) {
                return Err(self.invalid(format!(
                    "accept: {name:?} is not one of {week}'s alternatives (known: {})",
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                )));
            }
        }
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for g in self
            .groups
            .iter()
            .filter(|g| g.kind == GroupKind::Functions)
        {
            for f in g.functions.iter().flatten() {
                if let Some((_, first)) = seen.iter().find(|(s, _)| s == f) {
                    return Err(self.invalid(format!(
                        "function {f:?} is in groups {first:?} and {:?}; a function is scored by one group",
                        g.id
                    )));
                }
                seen.push((f.as_str(), g.id.as_str()));
            }
        }
        Ok(())
    }

    pub(in crate::grade) fn validate_functions_group(&self, g: &Group) -> Result<(), RubricError> {
        if !g.id.starts_with("functions.") {
            return Err(self.invalid(format!(
                "functions group id {:?} must start with \"functions.\"",
                g.id
            )));
        }
        let Some(week) = self.week.and_then(crate::weekly::week::Week::new) else {
            return Err(self.invalid(format!(
                "functions group {:?} needs the rubric's week (week = 5 to 10)",
                g.id
            )));
        };
        let names = g.functions.as_deref().unwrap_or_default();
        if names.is_empty() {
            return Err(self.invalid(format!(
                "functions group {:?} needs functions = [...] (the ids of the functions it scores)",
                g.id
            )));
        }
        let known = crate::weekly::checks::function_ids(week);
        for f in names {
            if !known.contains(&f.as_str()) {
                return Err(self.invalid(format!(
                    "functions group {:?}: {f:?} is not a function {week} checks (known: {})",
                    g.id,
                    known.join(", ")
                )));
            }
        }
        if g.shape.is_some()
            || g.file.is_some()
            || g.scene.is_some()
            || g.golden.is_some()
            || g.source.is_some()
            || g.spp.is_some()
            || g.render_seconds.is_some()
            || g.score_ambiguous
            || g.all_or_nothing
        {
            return Err(self.invalid(format!(
                "functions group {:?} takes no shape, file, scene, golden, source, spp, render_seconds, score_ambiguous or all_or_nothing",
                g.id
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every built-in rubric parses, adds up to 100, and from week 5 on scores every one of the
    /// week's own functions once, renders every scene of the week, and keeps the week-4
    /// intersections at no points.
    #[test]
    fn every_built_in_rubric_is_valid_and_adds_up_to_100() {
        for name in BUILTIN_RUBRICS {
            let text = builtin_rubric_toml(name).unwrap();
            let r = Rubric::from_toml(&text, "built-in").unwrap();
            assert_eq!(r.name, *name);
            assert!(
                (r.max_score() - 100.0).abs() < 1e-9,
                "{name}: {}",
                r.max_score()
            );
            let Some(week) = r.week.and_then(Week::new) else {
                assert_eq!(*name, "week04");
                continue;
            };
            let scored: Vec<&str> = r
                .groups
                .iter()
                .filter(|g| g.kind == GroupKind::Functions)
                .flat_map(|g| g.functions.iter().flatten().map(String::as_str))
                .collect();
            let own: Vec<&str> = week_function_groups(week)
                .iter()
                .flat_map(|g| g.functions.iter().copied())
                .collect();
            assert_eq!(scored, own, "{name}");
            let points: f64 = week_function_groups(week).iter().map(|g| g.points).sum();
            assert!((points - FUNCTION_POINTS).abs() < 1e-9, "{name}: {points}");
            // Every scored function is one the week checks in its own version, and not one the
            // checks hold as given by the skeleton.
            let checks = crate::weekly::checks::week_checks(week, 0);
            for f in &own {
                let c = checks.iter().find(|c| c.id == *f);
                let c =
                    c.unwrap_or_else(|| panic!("{name}: {f} is not a function the week checks"));
                assert_eq!(c.week, week, "{name}: {f} is an earlier week's");
                assert!(!c.given, "{name}: {f} is given by the skeleton");
            }
            let image_points: f64 = r
                .groups
                .iter()
                .filter(|g| g.kind == GroupKind::Image)
                .map(|g| g.points)
                .sum();
            assert!((image_points - IMAGE_POINTS).abs() < 1e-9, "{name}");
            let images: Vec<&str> = r
                .groups
                .iter()
                .filter(|g| g.kind == GroupKind::Image)
                .map(|g| g.scene.as_deref().unwrap())
                .collect();
            let expected: Vec<&str> = crate::scene::BUILTIN_SCENES
                .iter()
                .filter(|s| s.week == Some(u32::from(week.number())))
                .map(|s| s.name)
                .collect();
            assert_eq!(
                images, expected,
                "{name}: every scene of the week, in order"
            );
            for g in r.groups.iter().filter(|g| g.kind == GroupKind::Code) {
                assert_eq!(g.points, 0.0, "{name} {}", g.id);
            }
            // A render whose golden depends on its samples per pixel has that golden compiled in.
            for g in r.groups.iter().filter(|g| g.renders()) {
                let scene = crate::scene::builtin(g.scene.as_deref().unwrap()).unwrap();
                if crate::golden::at_spp(&scene, g.render_spp()).is_some() {
                    let wanted = (g.scene.as_deref().unwrap(), g.render_spp());
                    assert!(
                        crate::golden::SPP_VARIANTS.contains(&wanted),
                        "{name}: {wanted:?} has no committed golden"
                    );
                }
            }
        }
        assert!(builtin_rubric_toml("week11").is_none());
        assert!(builtin_rubric_toml("week5").is_none());
        assert!(builtin_rubric_toml("week004").is_none());
    }
}
