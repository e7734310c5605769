//! What a case is judged by: a [`Profile`] (whose formulas draw the line between definite and
//! ambiguous) and a [`Precision`] (the arithmetic those formulas are evaluated in), together a
//! [`Judging`].
//!
//! The promise, for every combination: the *expected answer* is always the exact answer for the
//! `f64` inputs as written; only the line between definite and ambiguous, `t_tol` and the normal
//! tolerance depend on the judging.
//!
//! - [`Profile::Course`]: the bands of the course's naive formulas (`half_b^2 - a c`,
//!   `(-half_b -+ sqrt(disc)) / a`, the quad's `unit(n)`, `D`, `w`). Fair to naive code: it
//!   excuses every case where the naive formula cancels.
//! - [`Profile::Robust`]: the bands of the reference's own formulas (for spheres the discriminant
//!   `a (r^2 - |f - (f.d/a) d|^2)` and the Ray Tracing Gems roots `q = -(b' + sign(b') sqrt(disc))`,
//!   `t0 = c / q`, `t1 = q / a`; quads and triangles use the reference's quad formula, which is
//!   the course's). A case is definite whenever a carefully written `f64` intersector must get
//!   it right.
//! - [`Precision::F64`]: the formulas in `f64` on the inputs as written.
//! - [`Precision::F32`]: every input is first rounded to `f32` (the band holds both the exact
//!   input and its rounding), then every operation is rounded to `f32`; a case is ambiguous when
//!   that could flip it. The `t` tolerance comes from the same evaluation (at least
//!   [`Judging::t_floor`] `|t|`) and the normal tolerance is [`Judging::normal_tol`].

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// Whose formulas the error bands come from.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Profile {
    /// The course's naive formulas (the default for the bundled course adapter).
    #[default]
    Course,
    /// The reference's robust formulas (`--profile robust`: finds the precision bugs of naive code).
    Robust,
}

/// The arithmetic the profile's formulas are evaluated in.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// Double precision on the inputs as written.
    #[default]
    F64,
    /// Inputs rounded to single precision, every operation in single precision.
    F32,
}

/// A profile and a precision: what a report says it judged by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Judging {
    /// The profile.
    pub profile: Profile,
    /// The precision.
    pub precision: Precision,
}

impl Profile {
    /// `"course"` or `"robust"`.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Course => "course",
            Profile::Robust => "robust",
        }
    }
}

impl Precision {
    /// `"f64"` or `"f32"`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }
}

impl fmt::Display for Profile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for Precision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A `--profile` or `--precision` value that is not one of the names.
#[derive(Debug, thiserror::Error)]
#[error("{given:?} is not one of {expected}")]
pub struct UnknownName {
    /// What was given.
    pub given: String,
    /// The accepted names.
    pub expected: &'static str,
}

impl FromStr for Profile {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "course" => Ok(Profile::Course),
            "robust" => Ok(Profile::Robust),
            _ => Err(UnknownName {
                given: s.to_string(),
                expected: "course, robust",
            }),
        }
    }
}

impl FromStr for Precision {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "f64" => Ok(Precision::F64),
            "f32" => Ok(Precision::F32),
            _ => Err(UnknownName {
                given: s.to_string(),
                expected: "f64, f32",
            }),
        }
    }
}

impl Judging {
    /// Today's policy: the course's naive formulas in `f64`.
    pub const COURSE: Judging = Judging {
        profile: Profile::Course,
        precision: Precision::F64,
    };
    /// The reference's robust formulas in `f64`.
    pub const ROBUST: Judging = Judging {
        profile: Profile::Robust,
        precision: Precision::F64,
    };

    /// A profile and a precision.
    pub const fn new(profile: Profile, precision: Precision) -> Self {
        Judging { profile, precision }
    }

    /// The short name reports print, `"course/f64"`, `"robust/f32"`, ...
    pub fn name(self) -> String {
        format!("{}/{}", self.profile, self.precision)
    }

    /// How far each component of a candidate's unit normal may be from the expected one:
    /// `1e-6` in `f64`, `1e-3` in `f32`.
    pub fn normal_tol(self) -> f64 {
        match self.precision {
            Precision::F64 => 1e-6,
            Precision::F32 => 1e-3,
        }
    }

    /// The smallest `t_tol` as a fraction of `|t|`: `1e-9` in `f64`, `2^-20` (about `9.5e-7`)
    /// in `f32`.
    pub fn t_floor(self) -> f64 {
        match self.precision {
            Precision::F64 => 1e-9,
            Precision::F32 => 1.0 / (1u64 << 20) as f64,
        }
    }
}

impl fmt::Display for Judging {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.profile, self.precision)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_unknown_names_are_refused() {
        for p in [Profile::Course, Profile::Robust] {
            assert_eq!(p.name().parse::<Profile>().unwrap(), p);
        }
        for p in [Precision::F64, Precision::F32] {
            assert_eq!(p.name().parse::<Precision>().unwrap(), p);
        }
        assert!("naive".parse::<Profile>().is_err());
        assert!("f16".parse::<Precision>().is_err());
        assert_eq!(Judging::default(), Judging::COURSE);
        assert_eq!(
            Judging::new(Profile::Robust, Precision::F32).name(),
            "robust/f32"
        );
    }
}
