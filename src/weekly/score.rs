//! Points for a week's function checks: each week's groups of the functions its students write
//! ([`week_groups`]), and a [`WeekReport`] scored against them ([`score`]).
//!
//! A group's points are shared equally by its functions, and a function earns its share when it
//! passes (every scored case, or its statistical test); a function that fails, raises or is not
//! answered earns nothing. The functions a week's skeleton already holds (`given`) and the
//! earlier weeks' functions carry no points: the skeleton gives them. A failure there is a
//! regression, listed with the score but not taken off it. The groups of a week add up to 100.

use serde::Serialize;

use super::run::{FunctionResult, Status, WeekReport};
use super::week::Week;

/// A group of a week's functions and its points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GroupSpec {
    /// Its id (`functions.optics`).
    pub id: &'static str,
    /// A name for people.
    pub name: &'static str,
    /// Its points.
    pub points: f64,
    /// The ids of its functions (as the week's checks name them).
    pub functions: &'static [&'static str],
}

const fn group(
    id: &'static str,
    name: &'static str,
    points: f64,
    functions: &'static [&'static str],
) -> GroupSpec {
    GroupSpec {
        id,
        name,
        points,
        functions,
    }
}

/// The groups of week `week`'s own functions (their points add up to 100).
pub fn week_groups(week: Week) -> &'static [GroupSpec] {
    const W5: &[GroupSpec] = &[
        group(
            "functions.lights",
            "Point lights: the shadow test and the direct term",
            50.0,
            &["occlusion", "direct-term"],
        ),
        group(
            "functions.lambertian",
            "Lambertian scattering (n + u)",
            40.0,
            &["lambertian", "lambertian-lobe"],
        ),
        group(
            "functions.background",
            "What a miss returns",
            10.0,
            &["background"],
        ),
    ];
    const W6: &[GroupSpec] = &[
        group(
            "functions.optics",
            "reflect, refract, schlick",
            50.0,
            &["reflect", "refract", "schlick"],
        ),
        group(
            "functions.materials",
            "Mirror and Dielectric",
            40.0,
            &["mirror", "dielectric", "dielectric-choice"],
        ),
        group(
            "functions.background",
            "The sky on a miss",
            10.0,
            &["background"],
        ),
    ];
    const W7: &[GroupSpec] = &[
        group(
            "functions.uv",
            "Texture coordinates of spheres and quads",
            30.0,
            &["sphere-uv", "quad-uv"],
        ),
        group(
            "functions.textures",
            "SolidColor, CheckerTexture, ImageTexture, TextureColor",
            45.0,
            &[
                "solid-texture",
                "checker-texture",
                "image-texture",
                "textured",
            ],
        ),
        group(
            "functions.metal",
            "Metal and its fuzz",
            25.0,
            &["metal", "metal-fuzz"],
        ),
    ];
    const W8: &[GroupSpec] = &[
        group(
            "functions.brdf",
            "halfvector and the Phong, Blinn and Cook-Torrance BRDFs",
            60.0,
            &["halfvector", "phong", "blinn", "cook-torrance"],
        ),
        group(
            "functions.integrator",
            "The BRDF integrator's direct term and background",
            40.0,
            &["direct-term", "background"],
        ),
    ];
    const W9: &[GroupSpec] = &[
        group(
            "functions.sampling",
            "The cosine hemisphere, the ONB and Lambertian scattering through it",
            70.0,
            &["cosine-hemisphere", "onb", "lambertian", "lambertian-lobe"],
        ),
        group(
            "functions.jitter",
            "Jittered camera rays",
            30.0,
            &["jitter", "camera-ray"],
        ),
    ];
    const W10: &[GroupSpec] = &[
        group(
            "functions.defocus",
            "The lens of the jittered rays",
            50.0,
            &["lens", "camera-ray"],
        ),
        group(
            "functions.motion",
            "The time of the jittered rays",
            50.0,
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

/// One group, scored.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GroupScore {
    /// The group's id.
    pub id: String,
    /// Its name.
    pub name: String,
    /// Points earned.
    pub score: f64,
    /// Points it carries.
    pub max: f64,
    /// Its functions' ids and verdicts.
    pub functions: Vec<(String, Status)>,
    /// The catalogued mistakes its failing functions' answers fit.
    pub mistakes: Vec<String>,
}

/// A week's function checks, scored.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeekScore {
    /// The week.
    pub week: Week,
    /// Points earned.
    pub score: f64,
    /// Points in all (100).
    pub max: f64,
    /// The groups.
    pub groups: Vec<GroupScore>,
    /// Functions that carry no points (given, or an earlier week's) and failed.
    pub regressions: Vec<String>,
}

/// `report` scored against its week's groups ([module docs](self)).
pub fn score(report: &WeekReport) -> WeekScore {
    let specs = week_groups(report.week);
    let own = |id: &str| -> Option<&FunctionResult> {
        report.of_the_week().find(|f| f.id == id && !f.given)
    };
    let mut groups = Vec::new();
    for g in specs {
        let share = g.points / g.functions.len() as f64;
        let mut got = 0.0;
        let mut functions = Vec::new();
        let mut mistakes: Vec<String> = Vec::new();
        for id in g.functions {
            let status = own(id).map_or(Status::NotRun, |f| f.status);
            if status == Status::Passed {
                got += share;
            }
            if let Some(f) = own(id) {
                for m in &f.mistakes {
                    if !mistakes.contains(&m.name) {
                        mistakes.push(m.name.clone());
                    }
                }
            }
            functions.push((id.to_string(), status));
        }
        groups.push(GroupScore {
            id: g.id.to_string(),
            name: g.name.to_string(),
            score: got,
            max: g.points,
            functions,
            mistakes,
        });
    }
    let scored: Vec<&str> = specs
        .iter()
        .flat_map(|g| g.functions.iter().copied())
        .collect();
    let regressions = report
        .functions
        .iter()
        .filter(|f| f.status == Status::Failed)
        .filter(|f| f.week != report.week || f.given || !scored.contains(&f.id.as_str()))
        .map(|f| format!("{} {}", f.week, f.id))
        .collect();
    WeekScore {
        week: report.week,
        score: groups.iter().map(|g| g.score).sum(),
        max: specs.iter().map(|g| g.points).sum(),
        groups,
        regressions,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weekly::checks::week_checks;

    /// Every group names functions the week introduces and its skeleton does not hold, each in
    /// one group only, and the points add up to 100; every such function is in a group.
    #[test]
    fn the_groups_cover_each_weeks_own_functions() {
        for week in Week::all() {
            let checks = week_checks(week, 0);
            let own: Vec<&str> = checks
                .iter()
                .filter(|c| c.week == week && !c.given)
                .map(|c| c.id)
                .collect();
            let groups = week_groups(week);
            let mut named: Vec<&str> = groups
                .iter()
                .flat_map(|g| g.functions.iter().copied())
                .collect();
            let total: f64 = groups.iter().map(|g| g.points).sum();
            assert_eq!(total, 100.0, "{week}");
            named.sort();
            let mut expected = own.clone();
            expected.sort();
            assert_eq!(named, expected, "{week}");
        }
    }
}
