//! The course's weeks 5 to 10, and which one a submission folder is, read from its files
//! without running them.
//!
//! Each week's skeleton holds the functions the week introduces (stubbed) on top of the
//! solution of the week before, so the latest week whose marks are in the folder is the week of
//! the submission, as long as the marks agree. The marks, one set per week:
//!
//! | week | marks |
//! |---|---|
//! | 10 | `def move_sphere`, `def add_moving`, `def random_in_unit_disk`, `def renderDoF`, `def renderMoving` |
//! | 9 | `class ONB`, `def random_cosine_hemisphere_on_z`, `def get_jittered_ray`, `def render_jittered` |
//! | 8 | `def halfvector`, `def BRDF`, `class Phong`, `class Blinn`, `def renderPhong` |
//! | 7 | `def get_uv`, `class Metal`, `class TextureColor`, `def renderEarth`, `def renderProceduralTexture` |
//! | 6 | `def refract`, `def schlick`, `class Dielectric`, `class Mirror`, `def renderMirrors` |
//! | 5 | `def find_occlusion`, `def find_point_lights`, `class Diffuse_light`, `def renderPointLight` |
//!
//! Marks are read as `def NAME` / `class NAME` at the start of a line (after indentation) in the
//! folder's `RT_*.py` and `main.py` files, so a name in a comment or a string does not count.
//! A folder without any is week 4's (intersections only).
//!
//! Marks that disagree: the week is the latest one with at least two of its marks in the
//! folder. A later week with a single mark, where an earlier week has two or more, is taken for
//! a piece borrowed from elsewhere (the book's `class Metal` pasted into a week-5 tree), not for
//! the week: the folder is checked as the week most of its marks say, and
//! [`Detected::set_aside`] says which mark was set aside and why. A folder whose weeks have one
//! mark each is the latest of them. Each of the course's fourteen folders (weeks 4 to 10,
//! skeleton and solution) holds at least three marks of its own week and none of a later one.
//! `RT_texture.py`, `tex_value` and `random_vec3_in_unit_disk` are not marks: later weeks' code is
//! often checked with week 4's vectors, a week-4 folder may hold a texture module already (the
//! course's `RT_object.py` imports it from week 7 on), and the course's `Vec3` has the unit disk
//! from week 4 on.

use std::path::Path;

use serde::{Deserialize, Serialize};

/// A week of the course with function checks (5 to 10).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Week(u8);

impl Week {
    /// The first week with function checks.
    pub const FIRST: u8 = 5;
    /// The last week of the course.
    pub const LAST: u8 = 10;

    /// Week `n`, when it is 5 to 10.
    pub fn new(n: u8) -> Option<Self> {
        (Self::FIRST..=Self::LAST).contains(&n).then_some(Week(n))
    }

    /// Its number.
    pub fn number(self) -> u8 {
        self.0
    }

    /// Weeks 5 to 10.
    pub fn all() -> impl Iterator<Item = Week> {
        (Self::FIRST..=Self::LAST).map(Week)
    }

    /// Weeks 5 to this one.
    pub fn up_to(self) -> impl Iterator<Item = Week> {
        (Self::FIRST..=self.0).map(Week)
    }
}

impl std::fmt::Display for Week {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "week {}", self.0)
    }
}

/// The marks of each week: `(week, kind, name)`, kind `def` or `class`.
const MARKS: &[(u8, &str, &str)] = &[
    (10, "def", "move_sphere"),
    (10, "def", "add_moving"),
    (10, "def", "random_in_unit_disk"),
    (10, "def", "renderDoF"),
    (10, "def", "renderMoving"),
    (9, "class", "ONB"),
    (9, "def", "random_cosine_hemisphere_on_z"),
    (9, "def", "get_jittered_ray"),
    (9, "def", "render_jittered"),
    (8, "def", "halfvector"),
    (8, "def", "BRDF"),
    (8, "class", "Phong"),
    (8, "class", "Blinn"),
    (8, "def", "renderPhong"),
    (7, "def", "get_uv"),
    (7, "class", "Metal"),
    (7, "class", "TextureColor"),
    (7, "def", "renderEarth"),
    (7, "def", "renderProceduralTexture"),
    (6, "def", "refract"),
    (6, "def", "schlick"),
    (6, "class", "Dielectric"),
    (6, "class", "Mirror"),
    (6, "def", "renderMirrors"),
    (5, "def", "find_occlusion"),
    (5, "def", "find_point_lights"),
    (5, "class", "Diffuse_light"),
    (5, "def", "renderPointLight"),
];

/// The week a folder was found to be, and why.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Detected {
    /// The week (`None`: week 4, no marks of a later week).
    pub week: Option<Week>,
    /// The marks of that week found, as `"def halfvector in RT_utility.py"`.
    pub because: Vec<String>,
    /// Marks of a later week that were not taken for the folder's week, and why (empty when
    /// the marks agree).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub set_aside: Vec<String>,
}

/// Names defined at the start of a line of `text`: `(kind, name)` for `def NAME` and
/// `class NAME`.
fn definitions(text: &str) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.trim_start();
        for kind in ["def", "class"] {
            let Some(rest) = line.strip_prefix(kind) else {
                continue;
            };
            if !rest.starts_with([' ', '\t']) {
                continue;
            }
            let name: String = rest
                .trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((kind, name));
            }
        }
    }
    out
}

/// Reads the week of the submission in `dir` from its files ([module docs](self)). Files that
/// cannot be read are skipped; only `RT_*.py` and `main.py` of the folder itself are read, at
/// most 1 MiB of each.
pub fn detect(dir: &Path) -> Detected {
    let mut found: Vec<(u8, String)> = Vec::new();
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n == "main.py" || (n.starts_with("RT_") && n.ends_with(".py")))
        .collect();
    files.sort();
    for file in &files {
        let Ok(text) = read_capped(&dir.join(file)) else {
            continue;
        };
        for (kind, name) in definitions(&text) {
            for &(week, k, n) in MARKS {
                if k == kind && n == name {
                    found.push((week, format!("{kind} {name} in {file}")));
                }
            }
        }
    }
    // Each mark once (a class's `def BRDF` is one mark however many classes define it).
    let mut seen = std::collections::HashSet::new();
    found.retain(|m| seen.insert(m.clone()));
    let count = |week: u8| found.iter().filter(|(w, _)| *w == week).count();
    let latest_agreed = found
        .iter()
        .map(|(w, _)| *w)
        .filter(|&w| count(w) >= 2)
        .max();
    let latest = found.iter().map(|(w, _)| *w).max();
    // The latest week two of its marks agree on; without one, the latest week with a mark.
    let week = latest_agreed.or(latest);
    let set_aside = match (week, latest) {
        (Some(w), Some(l)) if l > w => found
            .iter()
            .filter(|(m, _)| *m > w)
            .map(|(m, why)| {
                format!(
                    "{why} is week {m}'s only mark here, where {} of week {w}'s are: taken for a piece from elsewhere, not the week (--week {m} checks it as week {m})",
                    count(w)
                )
            })
            .collect(),
        _ => Vec::new(),
    };
    let because: Vec<String> = found
        .into_iter()
        .filter(|(w, _)| Some(*w) == week)
        .map(|(_, why)| why)
        .collect();
    Detected {
        week: week.and_then(Week::new),
        because,
        set_aside,
    }
}

fn read_capped(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(1 << 20)
        .read_to_end(&mut bytes)?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn definitions_are_read_at_the_start_of_lines_only() {
        let text = "def a():\n    def b(x):\nclass C(Base):\n# def d()\nx = 'def e'\ndefine = 1\n";
        let names: Vec<String> = definitions(text).into_iter().map(|(_, n)| n).collect();
        assert_eq!(names, ["a", "b", "C"]);
    }

    #[test]
    fn the_latest_week_with_a_mark_wins_and_says_why() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("RT_utility.py"),
            "def reflect(v, n):\n    pass\ndef halfvector(v, l):\n    pass\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("RT_texture.py"),
            "class SolidColor:\n    def tex_value(self, u, v, p):\n        pass\n",
        )
        .unwrap();
        std::fs::write(dir.path().join("notes.txt"), "def move_sphere").unwrap();
        let d = detect(dir.path());
        assert_eq!(d.week, Week::new(8));
        assert_eq!(d.because, ["def halfvector in RT_utility.py"]);
        let empty = tempfile::tempdir().unwrap();
        assert_eq!(detect(empty.path()).week, None);
        assert!(Week::new(4).is_none() && Week::new(11).is_none());
    }

    /// One book-style `class Metal` (week 7's mark) in a week-5 tree is set aside: three marks
    /// of week 5 against one of week 7. Two marks of week 7 are the week.
    #[test]
    fn a_single_mark_of_a_later_week_is_set_aside_with_the_reason() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("RT_scene.py"),
            "class Scene:\n    def find_occlusion(self, r, i):\n        pass\n    def find_point_lights(self):\n        pass\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("RT_light.py"),
            "class Diffuse_light:\n    pass\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("RT_material.py"),
            "class Metal:\n    pass\n",
        )
        .unwrap();
        let d = detect(dir.path());
        assert_eq!(d.week, Week::new(5));
        assert_eq!(d.because.len(), 3, "{d:?}");
        assert_eq!(d.set_aside.len(), 1, "{d:?}");
        assert!(
            d.set_aside[0].starts_with(
                "class Metal in RT_material.py is week 7's only mark here, where 3 of week 5's are"
            ),
            "{d:?}"
        );
        std::fs::write(
            dir.path().join("RT_object.py"),
            "class Sphere:\n    def get_uv(self, n):\n        pass\n",
        )
        .unwrap();
        let d = detect(dir.path());
        assert_eq!(d.week, Week::new(7));
        assert!(d.set_aside.is_empty());
        // One mark only, of one week: that week.
        let one = tempfile::tempdir().unwrap();
        std::fs::write(
            one.path().join("RT_utility.py"),
            "def schlick(c, x):\n    pass\n",
        )
        .unwrap();
        assert_eq!(detect(one.path()).week, Week::new(6));
    }
}
