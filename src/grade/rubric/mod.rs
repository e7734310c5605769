//! The rubric: groups of checks and their points, with a built-in default for week 4 and an
//! override from a TOML file.
//!
//! ```toml
//! name = "week04"
//! seed = 0                       # seed of the vector suite
//! code_time_budget_seconds = 60  # wall time for all of a submission's code checks
//! memory_limit_mib = 1024        # memory its code may hold: processes, shared memory
//! file_limit_mib = 64            # files its code may keep (its folder, its /tmp)
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
//! source = "render"              # default: the grader renders the scene with the submission's
//!                                # code and judges that; "upload": the file is judged instead
//! spp = 4                        # render: samples per pixel (default 4)
//! render_seconds = 60            # render: wall time it may take (default 60), else not run
//! main_function = "renderSphere" # render: optional, the submission's main.py function run to
//!                                # render it (its own scene, renderer and film)
//! points = 20
//!
//! [[group]]
//! id = "image.tri"
//! name = "Triangle scene image"
//! kind = "image"
//! scene = "tri.toml"             # or a scene file, relative to the rubric file
//! golden = "tri.exr"             # optional: its golden (else rendered once and cached)
//! file = "tri.png"               # optional for scene files: default the scene's stem + ".png"
//! points = 20
//! ```
//!
//! A rendered image group (`source = "render"`) is judged on the grader's render of its scene
//! from the submission's code, at `spp` samples per pixel against the golden (see
//! [`render`](super::checkers::rendered)); its uploaded `file` is still read and reported, and earns
//! nothing. A submission's worst case is `code_time_budget_seconds` for the code checks plus
//! each rendered group's `render_seconds` (the renders and the code checks run at the same time
//! when there are cores for both).
//!
//! An image group's `scene` is a built-in scene when it names one, and otherwise a scene file
//! (`.toml`) relative to the folder of the rubric file (of the current folder for a rubric
//! given as text). Loading the rubric reads and validates each scene file and each `golden`
//! (an EXR with a `variance` layer, the scene's size, and the scene's content hash in its
//! `rtoracle.sceneSha256` attribute, as `rtoracle golden FILE.toml -o FILE.exr` writes), so a
//! missing file, an unparsable scene or a golden of another scene stops the grading before it
//! starts, with one line naming the rubric. Without a `golden`, the image checker renders the
//! golden the first time it is needed and keeps it in the cache
//! ([`crate::golden::golden_of`]).

pub mod credit;
pub mod weeks;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::oracle::vectors::ShapeKind;

/// The built-in week-4 rubric, as TOML (also what `rtoracle grade --print-rubric` shows).
pub const WEEK04_RUBRIC: &str = r#"# The built-in week-4 rubric: 100 points.
name = "week04"
seed = 0
code_time_budget_seconds = 60 # wall time for all of a submission's code checks

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
source = "render" # rendered by the grader from the submission's code
spp = 4
render_seconds = 60
points = 20
visibility = "visible"

[[group]]
id = "image.week04-quad"
name = "Quad scene image (week04_quad.png)"
kind = "image"
file = "week04_quad.png"
scene = "week04-quad"
source = "render" # rendered by the grader from the submission's code
spp = 4
render_seconds = 60
points = 20
visibility = "visible"
"#;

/// The lines of the built-in rubric's image groups that make them rendered by the grader.
const WEEK04_RENDER_LINES: &str = "source = \"render\" # rendered by the grader from the submission's code\nspp = 4\nrender_seconds = 60\n";

/// The text of [`Rubric::week04_uploads`]: the built-in rubric with `source = "upload"` image
/// groups.
pub fn week04_uploads_toml() -> String {
    WEEK04_RUBRIC.replace(WEEK04_RENDER_LINES, "source = \"upload\"\n")
}

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
    /// Functions of the rubric's `week` (weeks 5 to 10), through the protocol's function
    /// requests ([`crate::weekly`]).
    Functions,
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
    /// For functions groups: the ids of the functions it scores (`reflect`, `refract`), as the
    /// week's checks name them; its points are shared equally by them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub functions: Option<Vec<String>>,
    /// For image groups: the file name in the submission folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// For image groups: the built-in scene the image must show, or a scene file (`.toml`)
    /// relative to the rubric's folder.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
    /// For image groups on a scene file: its golden (EXR) relative to the rubric's folder;
    /// without it the golden is rendered once and cached.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub golden: Option<String>,
    /// For image groups on a scene file: the scene file and golden as read at load time.
    #[serde(skip)]
    pub scene_file: Option<Arc<SceneFile>>,
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
    /// For image groups: where the judged image comes from: rendered by the grader from the
    /// submission's code (`render`, the default) or the uploaded file (`upload`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<ImageSource>,
    /// For rendered image groups: the samples per pixel of the grader's render (default
    /// [`DEFAULT_RENDER_SPP`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spp: Option<u32>,
    /// For rendered image groups: the wall time the render may take, in seconds (default
    /// [`DEFAULT_RENDER_SECONDS`]); past it the group is not run, with the reason.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub render_seconds: Option<f64>,
    /// For rendered image groups: the submission's own `main.py` function that renders the
    /// scene (`renderMoving`). The grader runs it, through the submission's renderer and film,
    /// and judges the film it saves; when it cannot (no such function, it raises, no picture),
    /// the scene's description is rendered with the submission's classes and the report says
    /// why.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub main_function: Option<String>,
}

/// Where an image group's judged image comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImageSource {
    /// The grader renders the scene with the submission's own code, in the sandbox; an uploaded
    /// image is judged and reported too, but earns nothing.
    #[default]
    Render,
    /// The image the submission uploaded (for assignments whose code cannot be run).
    Upload,
}

/// The samples per pixel of a rendered image group when the rubric does not say: at the
/// course's Python cost (about 12 to 16 us of one core per sample on the week-4 scenes), the
/// 400x225 sphere scene takes about 4.5 s and the 400x400 quad scene about 10 s.
pub const DEFAULT_RENDER_SPP: u32 = 4;

/// The wall time a rendered image group may take when the rubric does not say, in seconds.
pub const DEFAULT_RENDER_SECONDS: f64 = 60.0;

/// The most samples per pixel a rubric may ask a render for.
pub const MAX_RENDER_SPP: u32 = 4096;

/// A scene file an image group names, read and validated when the rubric was loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    /// The `scene` value as the rubric wrote it (the label in reports).
    pub label: String,
    /// The file, resolved against the rubric's folder.
    pub path: PathBuf,
    /// The scene it describes.
    pub description: crate::scene::SceneDescription,
    /// SHA-256 (hex) of the file's bytes.
    pub sha256: String,
    /// The golden the rubric names, if it names one.
    pub golden: Option<GoldenFile>,
}

/// A golden EXR an image group names, read and validated when the rubric was loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct GoldenFile {
    /// The `golden` value as the rubric wrote it.
    pub label: String,
    /// The file, resolved against the rubric's folder.
    pub path: PathBuf,
    /// The file's bytes (an EXR golden of the scene).
    pub bytes: Vec<u8>,
    /// SHA-256 (hex) of the bytes.
    pub sha256: String,
}

/// The scene an image group's image must show.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    /// A built-in scene, by name (`week04-sphere`).
    Builtin(String),
    /// An instructor's scene file.
    File(Arc<SceneFile>),
}

impl SceneSource {
    /// The name reports use: the built-in's name, or the `scene` value of the rubric.
    pub fn label(&self) -> &str {
        match self {
            SceneSource::Builtin(name) => name,
            SceneSource::File(f) => &f.label,
        }
    }
}

impl Group {
    /// For an image group: where its judged image comes from (`render` unless the rubric says
    /// `upload`).
    pub fn image_source(&self) -> ImageSource {
        self.source.unwrap_or_default()
    }

    /// For an image group: whether the grader renders its scene from the submission's code.
    pub fn renders(&self) -> bool {
        self.kind == GroupKind::Image && self.image_source() == ImageSource::Render
    }

    /// The samples per pixel of the grader's render.
    pub fn render_spp(&self) -> u32 {
        self.spp.unwrap_or(DEFAULT_RENDER_SPP)
    }

    /// The wall time the grader's render may take, in seconds.
    pub fn render_seconds(&self) -> f64 {
        self.render_seconds.unwrap_or(DEFAULT_RENDER_SECONDS)
    }

    /// For an image group of a validated rubric: the scene its image must show.
    pub fn scene_source(&self) -> Option<SceneSource> {
        match (&self.scene_file, &self.scene) {
            (Some(f), _) => Some(SceneSource::File(Arc::clone(f))),
            (None, Some(name)) => Some(SceneSource::Builtin(name.clone())),
            (None, None) => None,
        }
    }
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
    /// Wall time allowed for all of a submission's code checks (start-up and every vector):
    /// past it the vectors not yet answered are `not_run`, and the grade of the rest stands.
    #[serde(default = "default_code_time_budget")]
    pub code_time_budget_seconds: f64,
    /// The modules the Python that runs the submissions must have (default numpy and PIL, which
    /// the course's `RT_utility.py` imports); `grade` exits 2 when no interpreter has them.
    #[serde(default = "crate::candidate::process::python::default_requires")]
    pub python_requires: Vec<String>,
    /// MiB of memory a submission's code may hold, all its processes and its shared memory
    /// together: past it the sandbox stops the code, the report says why, and the grade of what
    /// ran before stands.
    #[serde(default = "default_memory_limit_mib")]
    pub memory_limit_mib: u64,
    /// MiB of files its code may keep (its folder and its `/tmp`, which is in the host's
    /// memory where the sandbox has a view of its own), stopped as for memory.
    #[serde(default = "default_file_limit_mib")]
    pub file_limit_mib: u64,
    /// The course week whose function checks run (5 to 10; `None`: none, as for week 4). Every
    /// function of weeks 5 to `week` is checked and reported; the functions groups say which
    /// carry points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub week: Option<u8>,
    /// The false-alarm rate of each statistical check of the week's samplers (default 1e-4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha: Option<f64>,
    /// Versions of a function the course itself has, accepted as passing where the answers fit
    /// them (`older_direct_term_one_over_d`: week 5's earlier direct term). The names are the
    /// week's catalogue's alternatives ([`crate::weekly::checks::alternatives`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub accept: Vec<String>,
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

fn default_code_time_budget() -> f64 {
    60.0
}

fn default_memory_limit_mib() -> u64 {
    crate::sandbox::policy::SandboxPolicy::grading().memory_bytes >> 20
}

fn default_file_limit_mib() -> u64 {
    crate::sandbox::policy::SandboxPolicy::grading().disk_bytes >> 20
}

impl Rubric {
    /// The sandbox's limits for this rubric's submissions: `grade`'s, with its memory and file
    /// limits.
    pub fn sandbox_policy(&self) -> crate::sandbox::policy::SandboxPolicy {
        crate::sandbox::policy::SandboxPolicy {
            memory_bytes: self.memory_limit_mib << 20,
            disk_bytes: self.file_limit_mib << 20,
            ..crate::sandbox::policy::SandboxPolicy::grading()
        }
    }
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

/// An I/O error in a few words ("no such file" rather than "No such file or directory (os
/// error 2)").
fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::IsADirectory => "is a folder".to_string(),
        _ => e.to_string(),
    }
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

    /// The built-in week-4 rubric with its image groups judging the uploaded images
    /// (`source = "upload"`) instead of the grader's renders of the submission's code.
    pub fn week04_uploads() -> Rubric {
        Rubric::from_toml(&week04_uploads_toml(), "built-in, uploads")
            .expect("the upload variant is valid")
    }

    /// Reads a rubric file.
    pub fn from_file(path: &Path) -> Result<Rubric, RubricError> {
        let text = std::fs::read_to_string(path).map_err(|e| RubricError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let base = path.parent().unwrap_or(Path::new(""));
        Rubric::from_toml_in(&text, &path.display().to_string(), base)
    }

    /// Parses and validates a rubric; `source` labels errors and the report; scene files are
    /// relative to the current folder.
    pub fn from_toml(text: &str, source: &str) -> Result<Rubric, RubricError> {
        Rubric::from_toml_in(text, source, Path::new(""))
    }

    /// Parses and validates a rubric whose scene and golden files are relative to `base`.
    pub fn from_toml_in(text: &str, source: &str, base: &Path) -> Result<Rubric, RubricError> {
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
        rubric.read_scene_files(base)?;
        Ok(rubric)
    }

    /// Reads and checks the scene files and goldens of the image groups, and gives scene-file
    /// groups without a `file` their default (the scene's stem + `.png`).
    fn read_scene_files(&mut self, base: &Path) -> Result<(), RubricError> {
        let source = self.source.clone();
        let invalid = |message: String| RubricError::Invalid {
            path: source.clone(),
            message,
        };
        for g in &mut self.groups {
            let Some(scene) = g.scene.clone() else {
                continue;
            };
            if crate::scene::builtin(&scene).is_ok() {
                if g.golden.is_some() {
                    return Err(invalid(format!(
                        "image group {:?}: the built-in scene {scene:?} has its golden already; golden is for scene files",
                        g.id
                    )));
                }
                continue;
            }
            let path = base.join(&scene);
            let bytes = std::fs::read(&path).map_err(|e| {
                invalid(format!(
                    "image group {:?}: cannot read the scene file {}: {}",
                    g.id,
                    path.display(),
                    io_reason(&e)
                ))
            })?;
            let text = String::from_utf8(bytes.clone()).map_err(|_| {
                invalid(format!(
                    "image group {:?}: the scene file {} is not UTF-8 text",
                    g.id,
                    path.display()
                ))
            })?;
            let description =
                crate::scene::SceneDescription::from_toml(&text, &path.display().to_string())
                    .map_err(|e| invalid(format!("image group {:?}: {e}", g.id)))?;
            let golden = match &g.golden {
                None => None,
                Some(label) => {
                    let gpath = base.join(label);
                    let gbytes = std::fs::read(&gpath).map_err(|e| {
                        invalid(format!(
                            "image group {:?}: cannot read the golden {}: {}",
                            g.id,
                            gpath.display(),
                            io_reason(&e)
                        ))
                    })?;
                    crate::golden::golden_fits(&gbytes, &gpath, &description).map_err(|why| {
                        // The command suggested must itself work: `golden -o` wants a .exr name.
                        let is_exr = gpath
                            .extension()
                            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
                        let target = if is_exr {
                            gpath.clone()
                        } else {
                            gpath.with_extension("exr")
                        };
                        let rename = if is_exr {
                            String::new()
                        } else {
                            " and name it in `golden`".to_string()
                        };
                        invalid(format!(
                            "image group {:?}: the golden {} {why}; make it with `rtoracle golden {} -o {}`{rename}",
                            g.id,
                            gpath.display(),
                            path.display(),
                            target.display()
                        ))
                    })?;
                    Some(GoldenFile {
                        label: label.clone(),
                        path: gpath,
                        sha256: sha256_hex(&gbytes),
                        bytes: gbytes,
                    })
                }
            };
            if g.file.is_none() {
                let stem = Path::new(&scene)
                    .file_stem()
                    .map(|s| s.to_string_lossy().to_string())
                    .unwrap_or_default();
                g.file = Some(format!("{stem}.png"));
            }
            g.scene_file = Some(Arc::new(SceneFile {
                label: scene,
                path,
                description,
                sha256: sha256_hex(&bytes),
                golden,
            }));
        }
        Ok(())
    }

    pub(super) fn invalid(&self, message: String) -> RubricError {
        RubricError::Invalid {
            path: self.source.clone(),
            message,
        }
    }

    fn validate(&self) -> Result<(), RubricError> {
        if self.groups.is_empty() {
            return Err(self.invalid("the rubric has no [[group]]".into()));
        }
        let budget = self.code_time_budget_seconds;
        if !(budget.is_finite() && budget > 0.0 && budget <= 86_400.0) {
            return Err(self.invalid(format!(
                "code_time_budget_seconds = {budget}: it must be more than 0 and at most 86400"
            )));
        }
        for (key, mib, most) in [
            ("memory_limit_mib", self.memory_limit_mib, 65_536),
            ("file_limit_mib", self.file_limit_mib, 16_384),
        ] {
            if !(16..=most).contains(&mib) {
                return Err(self.invalid(format!(
                    "{key} = {mib}: it must be at least 16 and at most {most}"
                )));
            }
        }
        let mut ids = BTreeSet::new();
        for g in &self.groups {
            if g.id.is_empty() || g.id.contains(char::is_whitespace) {
                return Err(self.invalid(format!(
                    "group id {:?} must be non-empty without spaces",
                    g.id
                )));
            }
            if !ids.insert(g.id.as_str()) {
                return Err(self.invalid(format!("group id {:?} appears twice", g.id)));
            }
            if !(g.points.is_finite() && g.points >= 0.0) {
                return Err(self.invalid(format!(
                    "group {:?}: points must be a number >= 0, found {}",
                    g.id, g.points
                )));
            }
            match g.kind {
                GroupKind::Code => self.validate_code_group(g)?,
                GroupKind::Image => self.validate_image_group(g)?,
                GroupKind::Functions => self.validate_functions_group(g)?,
            }
            if g.kind != GroupKind::Functions && g.functions.is_some() {
                return Err(self.invalid(format!(
                    "group {:?}: functions is for kind = \"functions\" groups",
                    g.id
                )));
            }
        }
        self.validate_week()?;
        self.validate_image_files()
    }

    fn validate_code_group(&self, g: &Group) -> Result<(), RubricError> {
        if g.shape.is_none() {
            return Err(self.invalid(format!(
                "code group {:?} needs a shape (sphere, quad or triangle)",
                g.id
            )));
        }
        if g.file.is_some()
            || g.scene.is_some()
            || g.golden.is_some()
            || g.source.is_some()
            || g.spp.is_some()
            || g.render_seconds.is_some()
            || g.main_function.is_some()
        {
            return Err(self.invalid(format!(
                "code group {:?} takes no file, scene, golden, source, spp, render_seconds or main_function",
                g.id
            )));
        }
        Ok(())
    }

    fn validate_image_group(&self, g: &Group) -> Result<(), RubricError> {
        if !g.id.starts_with("image.") {
            return Err(self.invalid(format!(
                "image group id {:?} must start with \"image.\"",
                g.id
            )));
        }
        let Some(scene) = &g.scene else {
            return Err(self.invalid(format!("image group {:?} needs a scene", g.id)));
        };
        let builtin = crate::scene::builtin(scene).is_ok();
        if !builtin && !scene.ends_with(".toml") {
            return Err(self.invalid(format!(
                "image group {:?}: unknown scene {scene:?} (known: {}; or a scene file FILE.toml relative to the rubric)",
                g.id,
                crate::scene::builtin_names().join(", ")
            )));
        }
        match &g.file {
            None if builtin => {
                return Err(self.invalid(format!(
                    "image group {:?} needs a file (the image in the submission)",
                    g.id
                )));
            }
            Some(file)
                if file.is_empty()
                    || file.contains('/')
                    || file.contains('\\')
                    || file.starts_with('.') =>
            {
                return Err(self.invalid(format!(
                    "image group {:?}: file {file:?} must be a plain file name",
                    g.id
                )));
            }
            _ => {}
        }
        if !builtin {
            let stem = Path::new(scene)
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default();
            if g.file.is_none() && (stem.is_empty() || stem.starts_with('.')) {
                return Err(self.invalid(format!(
                    "image group {:?}: give a file, the scene file's name {scene:?} makes no image name",
                    g.id
                )));
            }
        }
        if g.score_ambiguous || g.shape.is_some() {
            return Err(self.invalid(format!(
                "image group {:?} takes no shape or score_ambiguous",
                g.id
            )));
        }
        self.validate_render_settings(g)
    }

    fn validate_render_settings(&self, g: &Group) -> Result<(), RubricError> {
        if g.image_source() == ImageSource::Upload
            && (g.spp.is_some() || g.render_seconds.is_some() || g.main_function.is_some())
        {
            return Err(self.invalid(format!(
                "image group {:?}: spp, render_seconds and main_function are for source = \"render\", not \"upload\"",
                g.id
            )));
        }
        if let Some(f) = &g.main_function {
            let identifier = f.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                && f.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !identifier || f.len() > 100 {
                return Err(self.invalid(format!(
                    "image group {:?}: main_function = {:?}: it must be a Python function name",
                    g.id,
                    crate::escape::truncate(f, 100)
                )));
            }
        }
        if let Some(spp) = g.spp {
            if !(1..=MAX_RENDER_SPP).contains(&spp) {
                return Err(self.invalid(format!(
                    "image group {:?}: spp = {spp}: it must be from 1 to {MAX_RENDER_SPP}",
                    g.id
                )));
            }
        }
        if let Some(s) = g.render_seconds {
            if !(s.is_finite() && s > 0.0 && s <= 3600.0) {
                return Err(self.invalid(format!(
                    "image group {:?}: render_seconds = {s}: it must be more than 0 and at most 3600",
                    g.id
                )));
            }
        }
        Ok(())
    }

    /// One image file can answer one group only: two groups wanting the same file (two scene
    /// files of the same name, say) could never both pass.
    fn validate_image_files(&self) -> Result<(), RubricError> {
        let mut files: Vec<(String, &str)> = Vec::new();
        for g in self.groups.iter().filter(|g| g.kind == GroupKind::Image) {
            let file = match (&g.file, &g.scene) {
                (Some(file), _) => file.clone(),
                (None, Some(scene)) => format!(
                    "{}.png",
                    Path::new(scene)
                        .file_stem()
                        .map(|s| s.to_string_lossy().to_string())
                        .unwrap_or_default()
                ),
                (None, None) => continue,
            };
            if let Some((_, first)) = files.iter().find(|(f, _)| *f == file) {
                return Err(self.invalid(format!(
                    "image groups {first:?} and {:?} both want the image {file:?}; give one of them another `file`",
                    g.id
                )));
            }
            files.push((file, g.id.as_str()));
        }
        Ok(())
    }

    /// The sum of the groups' points.
    pub fn max_score(&self) -> f64 {
        self.groups.iter().map(|g| g.points).sum()
    }

    /// The scenes of the image groups, in order.
    pub fn image_scenes(&self) -> Vec<SceneSource> {
        self.groups.iter().filter_map(Group::scene_source).collect()
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
    fn the_builtin_rubric_renders_its_images_and_its_upload_variant_does_not() {
        let r = Rubric::week04();
        for g in r.groups.iter().filter(|g| g.kind == GroupKind::Image) {
            assert!(g.renders(), "{}", g.id);
            assert_eq!((g.render_spp(), g.render_seconds()), (4, 60.0));
        }
        let u = Rubric::week04_uploads();
        assert_eq!(
            week04_uploads_toml().matches("source = \"upload\"").count(),
            2
        );
        for g in u.groups.iter().filter(|g| g.kind == GroupKind::Image) {
            assert_eq!(g.image_source(), ImageSource::Upload, "{}", g.id);
            assert!(!g.renders());
        }
        // Defaults: an image group without `source` renders at the default spp and time.
        let text = "name = \"t\"\n[[group]]\nid = \"image.s\"\nname = \"S\"\nkind = \"image\"\nfile = \"s.png\"\nscene = \"week04-sphere\"\npoints = 5\n";
        let g = &Rubric::from_toml(text, "t.toml").unwrap().groups[0];
        assert!(g.renders());
        assert_eq!(
            (g.render_spp(), g.render_seconds()),
            (DEFAULT_RENDER_SPP, DEFAULT_RENDER_SECONDS)
        );
        let bad = [
            (
                "points = 5",
                "spp = 0\npoints = 5",
                "spp = 0: it must be from 1 to 4096",
            ),
            (
                "points = 5",
                "render_seconds = -1\npoints = 5",
                "render_seconds = -1",
            ),
            (
                "points = 5",
                "source = \"upload\"\nspp = 8\npoints = 5",
                "main_function are for source = \"render\"",
            ),
            (
                "points = 5",
                "source = \"paint\"\npoints = 5",
                "not a valid rubric",
            ),
        ];
        for (from, to, needle) in bad {
            let e = Rubric::from_toml(&text.replace(from, to), "t.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{e}");
        }
        let code =
            WEEK04_RUBRIC.replacen("shape = \"sphere\"\n", "shape = \"sphere\"\nspp = 2\n", 1);
        let e = Rubric::from_toml(&code, "t.toml").unwrap_err().to_string();
        assert!(
            e.contains("takes no file, scene, golden, source, spp"),
            "{e}"
        );
    }

    #[test]
    fn a_scene_file_group_reads_its_scene_relative_to_the_rubric_and_names_the_image_after_it() {
        let dir = tempfile::tempdir().unwrap();
        let scene = crate::scene::builtin("week04-quad").unwrap().to_toml();
        std::fs::create_dir(dir.path().join("scenes")).unwrap();
        std::fs::write(dir.path().join("scenes/tri.toml"), &scene).unwrap();
        let text = "name = \"t\"\n[[group]]\nid = \"image.tri\"\nname = \"T\"\nkind = \"image\"\nscene = \"scenes/tri.toml\"\npoints = 5\n";
        std::fs::write(dir.path().join("r.toml"), text).unwrap();
        let r = Rubric::from_file(&dir.path().join("r.toml")).unwrap();
        let g = &r.groups[0];
        assert_eq!(g.file.as_deref(), Some("tri.png"));
        let Some(SceneSource::File(f)) = g.scene_source() else {
            panic!("a scene file: {:?}", g.scene_source());
        };
        assert_eq!(f.label, "scenes/tri.toml");
        assert_eq!(f.path, dir.path().join("scenes/tri.toml"));
        assert_eq!(f.sha256, sha256_hex(scene.as_bytes()));
        assert_eq!(f.description, crate::scene::builtin("week04-quad").unwrap());
        assert!(f.golden.is_none());
        // An explicit file wins; a built-in scene stays a built-in.
        let named = text.replace("points = 5", "file = \"mine.png\"\npoints = 5");
        let r = Rubric::from_toml_in(&named, "r.toml", dir.path()).unwrap();
        assert_eq!(r.groups[0].file.as_deref(), Some("mine.png"));
        assert_eq!(
            Rubric::week04().groups[2].scene_source(),
            Some(SceneSource::Builtin("week04-sphere".into()))
        );
        // Relative to the rubric, not to the current folder.
        let e = Rubric::from_toml(text, "r.toml").unwrap_err().to_string();
        assert!(e.contains("scenes/tri.toml: no such file"), "{e}");
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
