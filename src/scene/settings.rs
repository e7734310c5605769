//! How a scene is to be rendered: the `[render]` table of a scene file (integrator, depth,
//! background, how diffuse surfaces scatter, how pixels are sampled).
//!
//! A scene file without the table is a week-4 scene: the closest hit's albedo, the sky on a miss.

use serde::{Deserialize, Serialize};

/// The course's integrator of a week (the `course` profile; the `physical` profile always path
/// traces).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Week 4: the albedo (texture value) of the closest hit in `(1e-6, f64::MAX)`, the
    /// background on a miss. No bounces, no lights.
    #[default]
    Albedo,
    /// Weeks 5 to 7 (`compute_scattering`): at each hit, the material's scattered ray and the
    /// direct term of the unoccluded point lights ([`DirectTerm`]); a light returns its emission.
    Direct,
    /// Weeks 8 to 10: the direct term weighted by the BRDF and `n . (c - P)`, plus the BRDF times
    /// the scattered radiance times `n . w`, neither divided by a pdf.
    Brdf,
}

/// The weeks-5-to-7 direct term: the two versions of the instructor's code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DirectTerm {
    /// Week 6's skeleton (the current one): `Le = sum of E min(1, 1/|c - P|)` over the
    /// unoccluded point lights, returned as `Le a + Li a`.
    #[default]
    Clamped,
    /// Week 5's earlier solution: `Le = sum of E / |c - P|`, returned as `Le + a Li` (the
    /// direct term not multiplied by the albedo).
    Unclamped,
}

/// What a ray that hits nothing sees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Background {
    /// The sky gradient: `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1)`, `a = 0.5 (unit(d).y + 1)`.
    #[default]
    Sky,
    /// One colour, `background_color` (the course's `Scene(cBgcolor=Color(0.01, 0.01, 0.01))`).
    Flat,
}

/// How a diffuse surface (Lambertian, textured, and the BRDF materials) picks its scattered
/// direction in the `course` profile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DiffuseSampling {
    /// Weeks 5 to 8: `n + random_vec3_unit()`, not normalised, `n` itself when every component
    /// is below `1e-8` in magnitude.
    #[default]
    UnitSphere,
    /// Weeks 9 and 10: `random_cosine_hemisphere_on_z()` through the ONB built from `n`, a unit
    /// vector.
    Cosine,
}

/// Where a pixel's samples go in the `course` profile.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PixelSampling {
    /// Weeks 4 to 8 (`render`): each sample uniform in `[-0.5, 0.5)` around the pixel's centre,
    /// the sum divided by the number of samples.
    #[default]
    Uniform,
    /// Weeks 9 and 10 (`render_jittered`): `m = floor(sqrt(spp))` strata a side, sample
    /// `(s_i, s_j)` offset by `0.5 (-0.5 + step (s + U))` on each axis with the frozen `step`
    /// ([`RenderSettings::jitter_step`]), `m^2` samples summed and divided by `spp` (the
    /// scene's `samples_per_pixel`).
    CourseJittered,
}

/// The `[render]` table of a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSettings {
    /// The course's integrator (ignored by the `physical` profile).
    #[serde(default)]
    pub integrator: Integrator,
    /// Which version of the weeks-5-to-7 direct term.
    #[serde(default)]
    pub direct_term: DirectTerm,
    /// Week 8's `bDlight`: whether the BRDF integrator adds the point lights' direct term.
    #[serde(default = "yes")]
    pub direct_light: bool,
    /// The recursion depth: a path has at most this many hits (at least 1). The course's
    /// `depth`, the book's `max_depth`.
    #[serde(default = "default_depth")]
    pub max_depth: u32,
    /// What a ray that hits nothing sees.
    #[serde(default)]
    pub background: Background,
    /// The colour of the flat background.
    #[serde(default = "default_background_color")]
    pub background_color: [f64; 3],
    /// How diffuse surfaces scatter in the `course` profile.
    #[serde(default)]
    pub diffuse_sampling: DiffuseSampling,
    /// Where a pixel's samples go in the `course` profile.
    #[serde(default)]
    pub sampling: PixelSampling,
    /// The frozen stratum width of [`PixelSampling::CourseJittered`], required by it: the
    /// course's `one_over_sqrt_spp`, computed once from the default spp of 10 (`1/3` in week 9,
    /// where it is `1 / int(sqrt(10))`, and `1/sqrt(10)` in week 10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jitter_step: Option<f64>,
}

fn yes() -> bool {
    true
}

/// The depth when a scene file does not say: *Ray Tracing in One Weekend*'s `max_depth`.
pub const DEFAULT_MAX_DEPTH: u32 = 50;

fn default_depth() -> u32 {
    DEFAULT_MAX_DEPTH
}

/// The flat background's colour when a scene file does not say: the course's `0.01` grey.
pub const COURSE_BACKGROUND: [f64; 3] = [0.01, 0.01, 0.01];

fn default_background_color() -> [f64; 3] {
    COURSE_BACKGROUND
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            integrator: Integrator::Albedo,
            direct_term: DirectTerm::Clamped,
            direct_light: true,
            max_depth: DEFAULT_MAX_DEPTH,
            background: Background::Sky,
            background_color: COURSE_BACKGROUND,
            diffuse_sampling: DiffuseSampling::UnitSphere,
            sampling: PixelSampling::Uniform,
            jitter_step: None,
        }
    }
}

impl RenderSettings {
    /// Whether these are the defaults (a week-4 scene), so a scene file may leave the table out.
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}
