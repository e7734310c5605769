//! The rubric: groups of checks and their points, with a built-in default for week 4 and an
//! override from a TOML file.
//!
//! ```toml
//! name = "week04"
//! seed = 0                       # seed of the vector suite
//! python_requires = ["numpy", "PIL"]  # modules the grader's Python must have (the default)
//!
//! [[group]]
//! id = "sphere"                  # check ids start with the group id
//! name = "Sphere intersection"
//! kind = "code"                  # "code" (intersection vectors) or "image"
//! shape = "sphere"               # for code groups: which vectors
//! points = 30
//! all_or_nothing = false         # default: points in proportion to the vectors passed
//! score_ambiguous = false        # default: ambiguous vectors reported, not scored
//! visibility = "visible"         # visible | hidden | after_due_date | after_published
//!
//! [[group]]
//! id = "image.week04-sphere"
//! name = "Sphere scene image"
//! kind = "image"
//! file = "week04_sphere.png"     # for image groups: the file in the submission
//! scene = "week04-sphere"        # and the built-in scene it must show
//! points = 20
//! ```

use std::collections::BTreeSet;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::oracle::vectors::ShapeKind;

/// The built-in week-4 rubric, as TOML (also what `rtoracle grade --print-rubric` shows).
pub const WEEK04_RUBRIC: &str = r#"# The built-in week-4 rubric: 100 points.
name = "week04"
seed = 0

[[group]]
id = "sphere"
name = "Sphere intersection"
kind = "code"
shape = "sphere"
points = 30
visibility = "visible"

[[group]]
id = "quad"
name = "Quad constructor and intersection"
kind = "code"
shape = "quad"
points = 30
visibility = "visible"

[[group]]
id = "image.week04-sphere"
name = "Sphere scene image (week04_sphere.png)"
kind = "image"
file = "week04_sphere.png"
scene = "week04-sphere"
points = 20
visibility = "visible"

[[group]]
id = "image.week04-quad"
name = "Quad scene image (week04_quad.png)"
kind = "image"
file = "week04_quad.png"
scene = "week04-quad"
points = 20
visibility = "visible"
"#;

/// Who sees a test on Gradescope, and when.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Visibility {
    /// Always shown.
    #[default]
    Visible,
    /// Never shown to students.
    Hidden,
    /// Shown after the due date.
    AfterDueDate,
    /// Shown once the grades are published.
    AfterPublished,
}

impl Visibility {
    /// The name Gradescope uses.
    pub fn name(self) -> &'static str {
        match self {
            Visibility::Visible => "visible",
            Visibility::Hidden => "hidden",
            Visibility::AfterDueDate => "after_due_date",
            Visibility::AfterPublished => "after_published",
        }
    }
}

/// What a group checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupKind {
    /// The intersection vectors of one shape kind.
    Code,
    /// One image against the reference of a scene.
    Image,
}

/// One group of checks and its points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Group {
    /// The id every check of the group starts with (`sphere`, `image.week04-quad`).
    pub id: String,
    /// A name for people.
    pub name: String,
    /// Code or image.
    pub kind: GroupKind,
    /// For code groups: the kind of shape whose vectors are run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape: Option<ShapeKind>,
    /// For image groups: the file name in the submission folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// For image groups: the built-in scene the image must show.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// The group's points.
    pub points: f64,
    /// Everything or nothing, instead of points in proportion to the vectors passed.
    #[serde(default)]
    pub all_or_nothing: bool,
    /// Count ambiguous vectors in the score too (passed when the answer equals the exact one).
    #[serde(default)]
    pub score_ambiguous: bool,
    /// Who sees the group's tests on Gradescope.
    #[serde(default)]
    pub visibility: Visibility,
}

/// A whole rubric.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rubric {
    /// Its name (`week04`).
    pub name: String,
    /// The seed of the vector suite.
    #[serde(default)]
    pub seed: u64,
    /// The modules the Python that runs the submissions must have (default numpy and PIL, which
    /// the course's `RT_utility.py` imports); `grade` exits 2 when no interpreter has them.
    #[serde(default = "crate::candidate::python::default_requires")]
    pub python_requires: Vec<String>,
    /// The groups, in report order.
    #[serde(rename = "group")]
    pub groups: Vec<Group>,
    /// Where it came from (`built-in` or the file), not part of the TOML.
    #[serde(skip)]
    pub source: String,
    /// SHA-256 (hex) of the TOML text it was read from.
    #[serde(skip)]
    pub sha256: String,
}

/// Why a rubric cannot be used (one line, naming the file).
#[derive(Debug, thiserror::Error)]
pub enum RubricError {
    /// The file could not be read.
    #[error("{path}: cannot read the rubric: {message}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
    /// Not valid TOML, or not a rubric.
    #[error("{path}: not a valid rubric: {message}")]
    Parse {
        /// The file.
        path: String,
        /// The parser's complaint, on one line.
        message: String,
    },
    /// A rubric that parses but makes no sense.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// SHA-256 of `bytes` as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Rubric {
    /// The built-in week-4 rubric.
    pub fn week04() -> Rubric {
        Rubric::from_toml(WEEK04_RUBRIC, "built-in").expect("the built-in rubric is valid")
    }

    /// Reads a rubric file.
    pub fn from_file(path: &Path) -> Result<Rubric, RubricError> {
        let text = std::fs::read_to_string(path).map_err(|e| RubricError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Rubric::from_toml(&text, &path.display().to_string())
    }

    /// Parses and validates a rubric; `source` labels errors and the report.
    pub fn from_toml(text: &str, source: &str) -> Result<Rubric, RubricError> {
        let mut rubric: Rubric = toml::from_str(text).map_err(|e| RubricError::Parse {
            path: source.to_string(),
            message: e
                .message()
                .lines()
                .collect::<Vec<_>>()
                .join(" ")
                .to_string(),
        })?;
        rubric.source = source.to_string();
        rubric.sha256 = sha256_hex(text.as_bytes());
        rubric.validate()?;
        Ok(rubric)
    }

    fn validate(&self) -> Result<(), RubricError> {
        let invalid = |message: String| RubricError::Invalid {
            path: self.source.clone(),
            message,
        };
        if self.groups.is_empty() {
            return Err(invalid("the rubric has no [[group]]".into()));
        }
        let mut ids = BTreeSet::new();
        for g in &self.groups {
            if g.id.is_empty() || g.id.contains(char::is_whitespace) {
                return Err(invalid(format!(
                    "group id {:?} must be non-empty without spaces",
                    g.id
                )));
            }
            if !ids.insert(g.id.as_str()) {
                return Err(invalid(format!("group id {:?} appears twice", g.id)));
            }
            if !(g.points.is_finite() && g.points >= 0.0) {
                return Err(invalid(format!(
                    "group {:?}: points must be a number >= 0, found {}",
                    g.id, g.points
                )));
            }
            match g.kind {
                GroupKind::Code => {
                    if g.shape.is_none() {
                        return Err(invalid(format!(
                            "code group {:?} needs a shape (sphere, quad or triangle)",
                            g.id
                        )));
                    }
                    if g.file.is_some() || g.scene.is_some() {
                        return Err(invalid(format!(
                            "code group {:?} takes no file or scene",
                            g.id
                        )));
                    }
                }
                GroupKind::Image => {
                    if !g.id.starts_with("image.") {
                        return Err(invalid(format!(
                            "image group id {:?} must start with \"image.\"",
                            g.id
                        )));
                    }
                    let (Some(file), Some(scene)) = (&g.file, &g.scene) else {
                        return Err(invalid(format!(
                            "image group {:?} needs a file and a scene",
                            g.id
                        )));
                    };
                    if file.contains('/') || file.contains('\\') || file.starts_with('.') {
                        return Err(invalid(format!(
                            "image group {:?}: file {file:?} must be a plain file name",
                            g.id
                        )));
                    }
                    if crate::scene::builtin(scene).is_err() {
                        return Err(invalid(format!(
                            "image group {:?}: unknown scene {scene:?} (known: {})",
                            g.id,
                            crate::scene::builtin_names().join(", ")
                        )));
                    }
                    if g.score_ambiguous || g.shape.is_some() {
                        return Err(invalid(format!(
                            "image group {:?} takes no shape or score_ambiguous",
                            g.id
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// The sum of the groups' points.
    pub fn max_score(&self) -> f64 {
        self.groups.iter().map(|g| g.points).sum()
    }

    /// The shape kinds the code groups need, without repeats, in order.
    pub fn code_shapes(&self) -> Vec<ShapeKind> {
        let set: BTreeSet<ShapeKind> = self.groups.iter().filter_map(|g| g.shape).collect();
        set.into_iter().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtin_rubric_is_the_issue_s_week_4_rubric() {
        let r = Rubric::week04();
        let points: Vec<(&str, f64)> = r.groups.iter().map(|g| (g.id.as_str(), g.points)).collect();
        assert_eq!(
            points,
            [
                ("sphere", 30.0),
                ("quad", 30.0),
                ("image.week04-sphere", 20.0),
                ("image.week04-quad", 20.0)
            ]
        );
        assert_eq!(r.max_score(), 100.0);
        assert_eq!(r.code_shapes(), [ShapeKind::Sphere, ShapeKind::Quad]);
        assert!(
            r.groups
                .iter()
                .all(|g| !g.all_or_nothing && !g.score_ambiguous)
        );
        assert_eq!(r.sha256, sha256_hex(WEEK04_RUBRIC.as_bytes()));
    }

    #[test]
    fn overrides_parse_and_nonsense_is_refused_with_the_file_named() {
        let custom = WEEK04_RUBRIC
            .replace("points = 30\nvisibility = \"visible\"\n\n[[group]]\nid = \"quad\"", "points = 40\nall_or_nothing = true\nvisibility = \"hidden\"\n\n[[group]]\nid = \"quad\"");
        let r = Rubric::from_toml(&custom, "custom.toml").unwrap();
        assert_eq!(r.groups[0].points, 40.0);
        assert!(r.groups[0].all_or_nothing);
        assert_eq!(r.groups[0].visibility, Visibility::Hidden);
        assert_ne!(r.sha256, Rubric::week04().sha256);

        let bad = [
            ("name = \"x\"\ngroup = []\n", "no [[group]]"),
            (
                &WEEK04_RUBRIC.replace("id = \"quad\"", "id = \"sphere\""),
                "appears twice",
            ),
            (&WEEK04_RUBRIC.replace("points = 20", "points = -1"), ">= 0"),
            (
                &WEEK04_RUBRIC.replace("scene = \"week04-quad\"", "scene = \"nope\""),
                "unknown scene",
            ),
            (
                &WEEK04_RUBRIC.replace("visibility = \"visible\"", "visibility = \"sometimes\""),
                "not a valid rubric",
            ),
            (
                &WEEK04_RUBRIC.replace("file = \"week04_quad.png\"", "file = \"../x.png\""),
                "plain file name",
            ),
            ("this is not toml", "not a valid rubric"),
        ];
        for (text, needle) in bad {
            let e = Rubric::from_toml(text, "r.toml").unwrap_err().to_string();
            assert!(e.starts_with("r.toml: ") && e.contains(needle), "{e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
