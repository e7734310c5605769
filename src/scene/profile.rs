//! The two ways a scene can be rendered: as the course computes it, or as *Ray Tracing in One
//! Weekend* does.

use serde::{Deserialize, Serialize};

/// Which renderer's rules a scene is rendered by. Every output names it (`render` prints it,
/// a golden records it, `rtoracle scenes` lists it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// What a correct submission of the course's week computes, including every departure from
    /// physics its instructor's code makes (each named, with its week, where it is implemented).
    /// The integrator, background, depth and sampling are the scene's `[render]` settings.
    #[default]
    Course,
    /// What *Ray Tracing in One Weekend* (book 1, with book 2's emission, background colour,
    /// moving spheres and textures) computes for the same scene: a path tracer whose estimator
    /// is unbiased for the scene's materials, bounces from `t = 0.001`, the scene's depth limit,
    /// and the book's film encoding. The course-only settings (integrator, direct term, diffuse
    /// sampling, the course's jitter) are ignored; the course's BRDF materials are refused.
    Physical,
}

impl Profile {
    /// The profile's name as scene files and outputs spell it.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Course => "course",
            Profile::Physical => "physical",
        }
    }

    /// The profile called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "course" => Some(Profile::Course),
            "physical" => Some(Profile::Physical),
            _ => None,
        }
    }

    /// Whether this is the default profile (so a scene file may leave it out).
    pub fn is_course(&self) -> bool {
        *self == Profile::Course
    }
}

impl std::fmt::Display for Profile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
