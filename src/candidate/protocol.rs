//! The JSON-lines adapter protocol (see `docs/PROTOCOL.md`).
//!
//! The harness writes one request a line to the candidate's stdin; the candidate answers each
//! with one line on stdout, in order:
//!
//! ```text
//! -> {"op":"hello","protocol":1}
//! <- {"name":"my-tracer","protocol":1,"shapes":["sphere","quad"]}
//! -> {"id":"v17","op":"intersect","shape":{"type":"sphere","center":[0.0,0.0,0.0],"radius":1.0},
//!     "ray":{"origin":[0.0,0.0,5.0],"direction":[0.0,0.0,-1.0]},"interval":[1e-6,"inf"]}
//! <- {"id":"v17","hit":true,"t":4.0,"point":[0.0,0.0,1.0],"normal":[0.0,0.0,1.0],"front_face":true}
//! <- {"id":"v18","hit":false}
//! <- {"id":"v19","error":{"type":"ZeroDivisionError","message":"float division by zero","traceback":"..."}}
//! ```
//!
//! Numbers use the vector file's syntax: JSON numbers, or the strings `"inf"`, `"-inf"`, `"nan"`.

use serde::{Deserialize, Serialize};

use crate::oracle::vectors::{Case, RaySpec, ShapeKind, ShapeSpec, num2, opt_num, opt_num3};

/// The protocol version this harness speaks.
pub const PROTOCOL_VERSION: u32 = 1;

/// The first line the harness sends.
pub const HELLO_LINE: &str = "{\"op\":\"hello\",\"protocol\":1}";

/// One intersection request.
#[derive(Clone, Debug, Serialize)]
pub struct Request<'a> {
    /// The case id, echoed in the answer.
    pub id: &'a str,
    /// Always `"intersect"`.
    pub op: &'static str,
    /// The primitive.
    pub shape: &'a ShapeSpec,
    /// The ray.
    pub ray: &'a RaySpec,
    /// `[t_min, t_max]`.
    #[serde(with = "num2")]
    pub interval: [f64; 2],
}

impl<'a> Request<'a> {
    /// The request for `case`.
    pub fn for_case(case: &'a Case) -> Self {
        Request {
            id: &case.id,
            op: "intersect",
            shape: &case.shape,
            ray: &case.ray,
            interval: case.interval,
        }
    }

    /// The request as one line, without the newline.
    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("a request always serialises")
    }
}

/// An exception or error the candidate reports for one case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CandidateError {
    /// The exception's type, e.g. `ZeroDivisionError`.
    #[serde(rename = "type", default)]
    pub kind: String,
    /// The exception's message.
    #[serde(default)]
    pub message: String,
    /// The traceback, when the candidate has one.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub traceback: String,
}

impl std::fmt::Display for CandidateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.kind.is_empty(), self.message.is_empty()) {
            (false, false) => write!(f, "{}: {}", self.kind, self.message),
            (false, true) => f.write_str(&self.kind),
            _ => f.write_str(&self.message),
        }
    }
}

/// A candidate's answer to one request (the `id` aside): a hit, a miss or an error.
///
/// Build one with [`Answer::hit`], [`Answer::miss`] or [`Answer::error`]; [`Answer::validate`]
/// says whether a parsed answer is well formed.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Answer {
    /// `true` for a hit, `false` for a miss; absent on an error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hit: Option<bool>,
    /// The hit's ray parameter.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num")]
    pub t: Option<f64>,
    /// The hit point.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num3")]
    pub point: Option<[f64; 3]>,
    /// The unit normal facing the ray.
    #[serde(default, skip_serializing_if = "Option::is_none", with = "opt_num3")]
    pub normal: Option<[f64; 3]>,
    /// Whether the ray arrives from the outside.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub front_face: Option<bool>,
    /// The error the candidate raised instead of answering.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<CandidateError>,
}

impl Answer {
    /// A miss.
    pub fn miss() -> Self {
        Answer {
            hit: Some(false),
            ..Answer::default()
        }
    }

    /// A hit.
    pub fn hit(t: f64, point: [f64; 3], normal: [f64; 3], front_face: bool) -> Self {
        Answer {
            hit: Some(true),
            t: Some(t),
            point: Some(point),
            normal: Some(normal),
            front_face: Some(front_face),
            error: None,
        }
    }

    /// An error of type `kind`.
    pub fn error(kind: impl Into<String>, message: impl Into<String>) -> Self {
        Answer {
            error: Some(CandidateError {
                kind: kind.into(),
                message: message.into(),
                traceback: String::new(),
            }),
            ..Answer::default()
        }
    }

    /// The answer of a reference hit record (or miss).
    pub fn from_record(record: Option<crate::geometry::HitRecord>) -> Self {
        match record {
            None => Answer::miss(),
            Some(h) => Answer::hit(h.t, h.point.to_array(), h.normal.to_array(), h.front_face),
        }
    }

    /// `Ok` when the answer is an error, a miss, or a hit with `t`, `normal` and `front_face`;
    /// otherwise what is wrong with it.
    pub fn validate(&self) -> Result<(), String> {
        if self.error.is_some() {
            return Ok(());
        }
        match self.hit {
            None => Err("the answer has neither \"hit\" nor \"error\"".into()),
            Some(false) => Ok(()),
            Some(true) => {
                let mut missing = Vec::new();
                if self.t.is_none() {
                    missing.push("t");
                }
                if self.normal.is_none() {
                    missing.push("normal");
                }
                if self.front_face.is_none() {
                    missing.push("front_face");
                }
                if missing.is_empty() {
                    Ok(())
                } else {
                    Err(format!("a hit answer lacks {}", missing.join(", ")))
                }
            }
        }
    }
}

/// An answer line: the id and the answer (fields spelled out: `flatten` is slow).
#[derive(Debug, Deserialize)]
struct AnswerLine {
    id: String,
    #[serde(default)]
    hit: Option<bool>,
    #[serde(default, with = "opt_num")]
    t: Option<f64>,
    #[serde(default, with = "opt_num3")]
    point: Option<[f64; 3]>,
    #[serde(default, with = "opt_num3")]
    normal: Option<[f64; 3]>,
    #[serde(default)]
    front_face: Option<bool>,
    #[serde(default)]
    error: Option<CandidateError>,
}

impl AnswerLine {
    fn split(self) -> (String, Answer) {
        (
            self.id,
            Answer {
                hit: self.hit,
                t: self.t,
                point: self.point,
                normal: self.normal,
                front_face: self.front_face,
                error: self.error,
            },
        )
    }
}

/// What one stdout line turned out to be.
#[derive(Debug, PartialEq)]
pub enum ParsedLine {
    /// An answer, with any junk that preceded it on the same line (a `print` without newline).
    Answer {
        /// The id the answer carries.
        id: String,
        /// The answer.
        answer: Answer,
        /// Text before the answer on the same line (empty when the line was clean).
        junk: String,
    },
    /// Not an answer.
    Junk(String),
}

/// Parses one stdout line. A line that is not an answer but contains one after some junk (a
/// stray `print(..., end="")`) yields the answer and the junk.
pub fn parse_answer_line(line: &str) -> ParsedLine {
    let trimmed = line.trim_end_matches(['\r', '\n']);
    if let Ok(a) = serde_json::from_str::<AnswerLine>(trimmed) {
        let (id, answer) = a.split();
        return ParsedLine::Answer {
            id,
            answer,
            junk: String::new(),
        };
    }
    if let Some(pos) = trimmed.find("{\"id\"") {
        if pos > 0 {
            if let Ok(a) = serde_json::from_str::<AnswerLine>(&trimmed[pos..]) {
                let (id, answer) = a.split();
                return ParsedLine::Answer {
                    id,
                    answer,
                    junk: trimmed[..pos].to_string(),
                };
            }
        }
    }
    ParsedLine::Junk(trimmed.to_string())
}

/// The candidate's answer to the hello.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// The candidate's name, for the report.
    #[serde(default)]
    pub name: String,
    /// The protocol version it speaks.
    #[serde(default)]
    pub protocol: Option<u32>,
    /// The shapes it supports (all three when absent).
    #[serde(default)]
    pub shapes: Option<Vec<String>>,
    /// Set when the candidate cannot answer any case, e.g. a submission that cannot be imported:
    /// every case is then reported with this error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<CandidateError>,
}

impl Hello {
    /// Parses a hello answer line; `None` when the line is not one.
    pub fn parse(line: &str) -> Option<Hello> {
        let value: serde_json::Value = serde_json::from_str(line.trim()).ok()?;
        let obj = value.as_object()?;
        if obj.contains_key("id") || !(obj.contains_key("name") || obj.contains_key("protocol")) {
            return None;
        }
        serde_json::from_value(value).ok()
    }

    /// Whether the candidate supports `kind`.
    pub fn supports(&self, kind: ShapeKind) -> bool {
        match &self.shapes {
            None => true,
            Some(list) => list.iter().any(|s| s == kind.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_parse_with_and_without_junk() {
        let line =
            r#"{"id":"v1","hit":true,"t":4.0,"point":[0,0,1],"normal":[0,0,1],"front_face":true}"#;
        match parse_answer_line(line) {
            ParsedLine::Answer { id, answer, junk } => {
                assert_eq!(id, "v1");
                assert_eq!(answer.t, Some(4.0));
                assert!(junk.is_empty());
                assert!(answer.validate().is_ok());
            }
            other => panic!("{other:?}"),
        }
        match parse_answer_line(&format!("debug 1 2{line}")) {
            ParsedLine::Answer { junk, .. } => assert_eq!(junk, "debug 1 2"),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse_answer_line("hello world"),
            ParsedLine::Junk("hello world".into())
        );
        // Non-finite numbers as strings.
        match parse_answer_line(
            r#"{"id":"x","hit":true,"t":"nan","normal":[0,0,1],"front_face":false}"#,
        ) {
            ParsedLine::Answer { answer, .. } => assert!(answer.t.unwrap().is_nan()),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn malformed_answers_are_named() {
        let a: Answer = serde_json::from_str(r#"{"hit":true,"t":1.0}"#).unwrap();
        assert_eq!(
            a.validate().unwrap_err(),
            "a hit answer lacks normal, front_face"
        );
        let a: Answer = serde_json::from_str(r#"{}"#).unwrap();
        assert!(a.validate().is_err());
        let a: Answer =
            serde_json::from_str(r#"{"error":{"type":"ValueError","message":"m"}}"#).unwrap();
        assert_eq!(a.error.as_ref().unwrap().to_string(), "ValueError: m");
    }

    #[test]
    fn hello_is_told_apart_from_answers() {
        let h = Hello::parse(r#"{"name":"c","protocol":1,"shapes":["sphere"]}"#).unwrap();
        assert!(h.supports(ShapeKind::Sphere) && !h.supports(ShapeKind::Quad));
        assert!(Hello::parse(r#"{"id":"x","hit":false}"#).is_none());
        assert!(Hello::parse("junk").is_none());
        assert!(
            Hello::parse(r#"{"name":"c"}"#)
                .unwrap()
                .supports(ShapeKind::Triangle)
        );
    }

    #[test]
    fn requests_use_the_vector_number_syntax() {
        let case = crate::candidate::test_cases::basic_cases().remove(0);
        let line = Request::for_case(&case).to_line();
        assert!(line.starts_with("{\"id\":\"sphere-basic-0000\",\"op\":\"intersect\""));
        assert!(
            line.contains("\"interval\":[1e-6,1.7976931348623157e+308]"),
            "{line}"
        );
    }
}
