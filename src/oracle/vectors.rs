//! The vector file: JSON lines, one case a line, as `docs/oracle.md` ("The vector format")
//! specifies.
//!
//! ```json
//! {"id": "quad-corner-0007",
//!  "shape": {"type": "quad", "q": [..], "u": [..], "v": [..]},
//!  "ray": {"origin": [..], "direction": [..]},
//!  "interval": [t_min, t_max],
//!  "expect": {"class": "hit", "tags": ["corner"], "t": 2.0, "t_tol": 2e-9,
//!             "point": [..], "normal": [..], "front_face": true}}
//! ```
//!
//! Numbers are written as shortest round-trip decimals, so parsing gives back the exact bits;
//! `"inf"`, `"-inf"` and `"nan"` are strings. The same number syntax is used by the adapter
//! protocol.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::arithmetic::Line;
use crate::geometry::{Interval, Quad, Ray, Sphere, Triangle};
use crate::scene::Object;

/// Version of the vector format, written to the `.meta.json` sidecar.
pub const SCHEMA_VERSION: u32 = 1;

/// A primitive as the vector file and the adapter protocol describe it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum ShapeSpec {
    /// A sphere (negative radius allowed).
    Sphere {
        /// Centre.
        #[serde(with = "num3")]
        center: [f64; 3],
        /// Radius.
        #[serde(with = "num")]
        radius: f64,
    },
    /// A parallelogram `q + alpha u + beta v`.
    Quad {
        /// Corner.
        #[serde(with = "num3")]
        q: [f64; 3],
        /// First edge.
        #[serde(with = "num3")]
        u: [f64; 3],
        /// Second edge.
        #[serde(with = "num3")]
        v: [f64; 3],
    },
    /// A triangle.
    Triangle {
        /// First vertex.
        #[serde(with = "num3")]
        a: [f64; 3],
        /// Second vertex.
        #[serde(with = "num3")]
        b: [f64; 3],
        /// Third vertex.
        #[serde(with = "num3")]
        c: [f64; 3],
    },
}

/// The kinds of shape, in the order reports list them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// Spheres.
    Sphere,
    /// Quads.
    Quad,
    /// Triangles.
    Triangle,
}

impl ShapeKind {
    /// Every kind.
    pub const ALL: [ShapeKind; 3] = [ShapeKind::Sphere, ShapeKind::Quad, ShapeKind::Triangle];

    /// The lowercase name (`"sphere"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Sphere => "sphere",
            ShapeKind::Quad => "quad",
            ShapeKind::Triangle => "triangle",
        }
    }

    /// The kind called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        ShapeKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

impl std::fmt::Display for ShapeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl ShapeSpec {
    /// The kind of shape.
    pub fn kind(&self) -> ShapeKind {
        match self {
            ShapeSpec::Sphere { .. } => ShapeKind::Sphere,
            ShapeSpec::Quad { .. } => ShapeKind::Quad,
            ShapeSpec::Triangle { .. } => ShapeKind::Triangle,
        }
    }

    /// The reference tracer's object for this shape.
    pub fn object(&self) -> Object {
        let v = DVec3::from;
        match *self {
            ShapeSpec::Sphere { center, radius } => Object::Sphere(Sphere::new(v(center), radius)),
            ShapeSpec::Quad { q, u, v: e } => Object::Quad(Quad::new(v(q), v(u), v(e))),
            ShapeSpec::Triangle { a, b, c } => Object::Triangle(Triangle::new(v(a), v(b), v(c))),
        }
    }

    /// Every number of the shape, in field order.
    pub fn numbers(&self) -> Vec<f64> {
        match self {
            ShapeSpec::Sphere { center, radius } => {
                center.iter().copied().chain([*radius]).collect()
            }
            ShapeSpec::Quad { q, u, v } => q.iter().chain(u).chain(v).copied().collect(),
            ShapeSpec::Triangle { a, b, c } => a.iter().chain(b).chain(c).copied().collect(),
        }
    }
}

/// A ray as the vector file describes it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RaySpec {
    /// Origin.
    #[serde(with = "num3")]
    pub origin: [f64; 3],
    /// Direction (not normalised).
    #[serde(with = "num3")]
    pub direction: [f64; 3],
}

impl RaySpec {
    /// The reference tracer's ray.
    pub fn ray(&self) -> Ray {
        Ray::new(DVec3::from(self.origin), DVec3::from(self.direction))
    }

    /// The ray as the exact decisions take it.
    pub fn line(&self) -> Line {
        Line {
            origin: self.origin,
            direction: self.direction,
        }
    }
}

/// What the oracle says of a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Class {
    /// A definite hit: every honest variant computed in f64 hits.
    Hit,
    /// A definite miss.
    Miss,
    /// Floating point cannot settle it (tangent, edge, grazing, interval boundary, ...): the exact
    /// answer is recorded, but no candidate is marked wrong on it by default.
    Ambiguous,
    /// Degenerate or non-finite input: any answer, or an error, is accepted; a crash is not.
    Any,
}

impl Class {
    /// Whether the class is `hit` or `miss`.
    pub fn is_definite(self) -> bool {
        matches!(self, Class::Hit | Class::Miss)
    }
}

/// The expected answer of a case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// The class.
    pub class: Class,
    /// Edge-case tags (`tangent`, `corner`, `parallel`, ...).
    #[serde(default)]
    pub tags: Vec<String>,
    /// The exact `t` (rounded to nearest), for a hit or an ambiguous case that hits exactly.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num")]
    pub t: Option<f64>,
    /// How far an honest candidate's `t` may be from `t`.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num")]
    pub t_tol: Option<f64>,
    /// The hit point `origin + t direction`.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num3")]
    pub point: Option<[f64; 3]>,
    /// The unit normal facing the ray.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num3")]
    pub normal: Option<[f64; 3]>,
    /// Whether the ray arrives from the outside.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub front_face: Option<bool>,
    /// How far each component of a candidate's normal may be from `normal`, when not the
    /// default `1e-6` (written for `f32` judging: `1e-3`).
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num")]
    pub normal_tol: Option<f64>,
    /// The watertight group the case belongs to, and the group's rule
    /// ([`super::watertight`]): a ray through an edge or vertex this shape shares with the
    /// group's other shapes must hit at least one of them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub watertight: Option<Watertight>,
}

/// The rule of a watertight group, carried by each of its members.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Watertight {
    /// The group's id (`watertight-quads-0003`): the members are the cases that carry it.
    pub group: String,
    /// `hit`: the ray must hit at least one member (at the right `t`); `ambiguous`: a ray in
    /// the plane of the group, not scored.
    pub class: Class,
}

/// One test vector.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// A unique, stable id such as `quad-corner-0007`.
    pub id: String,
    /// The primitive.
    pub shape: ShapeSpec,
    /// The ray.
    pub ray: RaySpec,
    /// `[t_min, t_max]`; open or closed as the shape's semantics say.
    #[serde(with = "num2")]
    pub interval: [f64; 2],
    /// The oracle's answer.
    pub expect: Expect,
}

impl Case {
    /// The reference tracer's interval.
    pub fn interval(&self) -> Interval {
        Interval::new(self.interval[0], self.interval[1])
    }

    /// One JSON line (no trailing newline).
    pub fn to_json_line(&self) -> String {
        serde_json::to_string(self).expect("a case always serialises")
    }

    /// Parses one JSON line.
    pub fn from_json_line(line: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(line)
    }
}

/// What can be wrong with a vector file.
#[derive(Debug, thiserror::Error)]
pub enum VectorFileError {
    /// The file could not be read.
    // The reason is in the message, not a `#[source]`, so a report of the whole chain prints it
    // once.
    #[error("{path}: cannot read: {reason}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        reason: std::io::Error,
    },
    /// A line is not a valid case.
    #[error("{path}:{line}: not a valid vector: {message}")]
    Line {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// The parser's complaint.
        message: String,
    },
    /// The file has no cases.
    #[error("{path}: the vector file has no cases")]
    Empty {
        /// The file.
        path: String,
    },
}

/// Parses a whole vector file's text (blank lines are skipped; ids must be unique); `path`
/// labels errors.
pub fn parse_vectors(text: &str, path: &str) -> Result<Vec<Case>, VectorFileError> {
    let mut cases = Vec::new();
    // Ids name the failures in every report: each must be unique.
    let mut seen = std::collections::HashMap::<String, usize>::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let case = Case::from_json_line(line).map_err(|e| VectorFileError::Line {
            path: path.to_string(),
            line: i + 1,
            message: e.to_string(),
        })?;
        if let Some(first) = seen.insert(case.id.clone(), i + 1) {
            return Err(VectorFileError::Line {
                path: path.to_string(),
                line: i + 1,
                message: format!("the id {:?} is already used on line {first}", case.id),
            });
        }
        cases.push(case);
    }
    if cases.is_empty() {
        return Err(VectorFileError::Empty {
            path: path.to_string(),
        });
    }
    Ok(cases)
}

/// Reads a vector file.
pub fn read_vectors(path: &std::path::Path) -> Result<Vec<Case>, VectorFileError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|reason| VectorFileError::Read {
        path: name.clone(),
        reason,
    })?;
    parse_vectors(&text, &name)
}

/// Serde for one `f64` with `"inf"`, `"-inf"` and `"nan"` as strings.
pub mod num {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    /// Writes a finite number as a JSON number, the others as strings.
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else if x.is_nan() {
            s.serialize_str("nan")
        } else if *x > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Raw<'a> {
        Number(f64),
        Text(&'a str),
    }

    /// Reads a JSON number or one of the strings `"inf"`, `"-inf"`, `"nan"`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Raw::deserialize(d)? {
            Raw::Number(x) => Ok(x),
            Raw::Text("inf") | Raw::Text("+inf") => Ok(f64::INFINITY),
            Raw::Text("-inf") => Ok(f64::NEG_INFINITY),
            Raw::Text("nan") => Ok(f64::NAN),
            Raw::Text(other) => Err(D::Error::custom(format!(
                "expected a number, \"inf\", \"-inf\" or \"nan\", found \"{other}\""
            ))),
        }
    }

    /// A number as the format writes it, for building JSON by hand.
    pub fn to_value(x: f64) -> serde_json::Value {
        serialize(&x, serde_json::value::Serializer).expect("numbers always serialise")
    }
}

macro_rules! num_array {
    ($name:ident, $n:literal) => {
        /// Serde for a fixed array of numbers in the format's number syntax.
        pub mod $name {
            use serde::{Deserialize, Deserializer, Serialize, Serializer};

            #[derive(Serialize, Deserialize)]
            struct N(#[serde(with = "super::num")] f64);

            /// Writes the array.
            pub fn serialize<S: Serializer>(v: &[f64; $n], s: S) -> Result<S::Ok, S::Error> {
                v.map(N).serialize(s)
            }

            /// Reads the array.
            pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; $n], D::Error> {
                Ok(<[N; $n]>::deserialize(d)?.map(|n| n.0))
            }
        }
    };
}
num_array!(num2, 2);
num_array!(num3, 3);

/// Serde for an optional number.
pub mod opt_num {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct N(#[serde(with = "super::num")] f64);

    /// Writes the number (the field is skipped when `None`).
    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        v.map(N).serialize(s)
    }

    /// Reads the number or `null`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        Ok(Option::<N>::deserialize(d)?.map(|n| n.0))
    }
}

/// Serde for an optional 3-vector.
pub mod opt_num3 {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct V(#[serde(with = "super::num3")] [f64; 3]);

    /// Writes the vector (the field is skipped when `None`).
    pub fn serialize<S: Serializer>(v: &Option<[f64; 3]>, s: S) -> Result<S::Ok, S::Error> {
        v.map(V).serialize(s)
    }

    /// Reads the vector or `null`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 3]>, D::Error> {
        Ok(Option::<V>::deserialize(d)?.map(|v| v.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_round_trips_bit_for_bit_with_non_finite_numbers() {
        let case = Case {
            id: "sphere-nonfinite-0001".into(),
            shape: ShapeSpec::Sphere {
                center: [0.1, -0.0, f64::NAN],
                radius: f64::INFINITY,
            },
            ray: RaySpec {
                origin: [1e-300, 5e-324, f64::NEG_INFINITY],
                direction: [0.0, 0.0, -1.0],
            },
            interval: [1e-6, f64::MAX],
            expect: Expect {
                class: Class::Any,
                tags: vec!["nonfinite".into()],
                t: None,
                t_tol: None,
                point: None,
                normal: None,
                front_face: None,
                normal_tol: None,
                watertight: None,
            },
        };
        let line = case.to_json_line();
        assert!(line.contains("\"nan\"") && line.contains("\"-inf\"") && line.contains("\"inf\""));
        let back = Case::from_json_line(&line).unwrap();
        assert_eq!(
            back.shape.numbers()[..2]
                .iter()
                .map(|x| x.to_bits())
                .collect::<Vec<_>>(),
            [0.1f64.to_bits(), (-0.0f64).to_bits()]
        );
        assert!(back.shape.numbers()[2].is_nan());
        assert_eq!(back.ray.origin[1].to_bits(), 5e-324f64.to_bits());
        assert_eq!(back.interval[1], f64::MAX);
    }

    #[test]
    fn unknown_fields_and_bad_strings_are_rejected() {
        let good = r#"{"id":"x","shape":{"type":"sphere","center":[0,0,0],"radius":1},"ray":{"origin":[0,0,5],"direction":[0,0,-1]},"interval":[0.000001,"inf"],"expect":{"class":"hit","tags":[]}}"#;
        assert!(Case::from_json_line(good).is_ok());
        assert!(
            Case::from_json_line(&good.replace("\"radius\":1", "\"radius\":1,\"colour\":2"))
                .is_err()
        );
        assert!(Case::from_json_line(&good.replace("\"inf\"", "\"infinity\"")).is_err());
        assert!(parse_vectors("\n\n", "empty.jsonl").is_err());
    }
}
