//! What a deterministic function request must answer ([`Expected`]), how sure the reference is
//! of it ([`Class`]), and judging one answer against it.
//!
//! An answer is a JSON object (the protocol's `result`); each expected field names a key of it
//! and what it must hold: a vector or a number within a tolerance, a pair, a boolean, a count.
//! Tolerances are absolute on each component, and stated per function in the checks (and in
//! `docs/weekly-checks.md`).

use glam::DVec3;
use serde::Serialize;

/// How a case is judged.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "class", content = "why", rename_all = "snake_case")]
pub enum Class {
    /// Scored: every honest implementation of the course's formula gives this answer.
    Definite,
    /// Not scored: rounding decides (a branch within rounding of its threshold); the reason.
    Ambiguous(String),
    /// Not scored: the course's own code fails on this input (it raises); the reason.
    CourseFails(String),
}

impl Class {
    /// Whether the case is scored.
    pub fn is_scored(&self) -> bool {
        matches!(self, Class::Definite)
    }
}

/// What one field of an answer must hold.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Want {
    /// Three numbers, each within `tol` of the value's.
    Vector {
        /// The expected vector.
        value: [f64; 3],
        /// Absolute tolerance per component.
        tol: f64,
    },
    /// Two numbers, each within `tol`.
    Pair {
        /// The expected pair.
        value: [f64; 2],
        /// Absolute tolerance per component.
        tol: f64,
    },
    /// A number within `tol`.
    Number {
        /// The expected number.
        value: f64,
        /// Absolute tolerance.
        tol: f64,
    },
    /// A boolean.
    Bool(bool),
}

impl Want {
    /// A vector within `tol`.
    pub fn vector(v: DVec3, tol: f64) -> Self {
        Want::Vector {
            value: v.to_array(),
            tol,
        }
    }

    /// What this wants, in words.
    pub fn describe(&self) -> String {
        match self {
            Want::Vector { value, .. } => {
                format!("[{:?}, {:?}, {:?}]", value[0], value[1], value[2])
            }
            Want::Pair { value, .. } => format!("[{:?}, {:?}]", value[0], value[1]),
            Want::Number { value, .. } => format!("{value:?}"),
            Want::Bool(b) => b.to_string(),
        }
    }
}

/// Every field an answer must hold, in order.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Expected {
    /// `(key, want)` pairs.
    pub fields: Vec<(String, Want)>,
}

impl Expected {
    /// An expectation with one field.
    pub fn one(key: &str, want: Want) -> Self {
        Expected {
            fields: vec![(key.to_string(), want)],
        }
    }

    /// This expectation with one more field.
    pub fn and(mut self, key: &str, want: Want) -> Self {
        self.fields.push((key.to_string(), want));
        self
    }

    /// `Ok` when `answer` holds every field, else what differs first, in words.
    pub fn judge(&self, answer: &serde_json::Value) -> Result<(), String> {
        for (key, want) in &self.fields {
            let got = answer.get(key);
            let bad = |what: &str| {
                Err(format!(
                    "{key} = {}, expected {}{what}",
                    got.map_or("(missing)".to_string(), crate::weekly::expect::show),
                    want.describe()
                ))
            };
            match want {
                Want::Vector { value, tol } => match numbers(got, 3) {
                    Some(v) if within(&v, value, *tol) => {}
                    _ => return bad(&format!(" (within {tol:.0e})")),
                },
                Want::Pair { value, tol } => match numbers(got, 2) {
                    Some(v) if within(&v, value, *tol) => {}
                    _ => return bad(&format!(" (within {tol:.0e})")),
                },
                Want::Number { value, tol } => match got.and_then(number) {
                    Some(x) if within(&[x], &[*value], *tol) => {}
                    _ => return bad(&format!(" (within {tol:.0e})")),
                },
                Want::Bool(b) => match got.and_then(serde_json::Value::as_bool) {
                    Some(x) if x == *b => {}
                    _ => return bad(""),
                },
            }
        }
        Ok(())
    }
}

/// A JSON value as an answer shows it, capped.
pub fn show(v: &serde_json::Value) -> String {
    let text = v.to_string();
    if text.len() > 200 {
        crate::escape::truncate(&text, 200)
    } else {
        text
    }
}

/// A number of the protocol's syntax (a JSON number, or `"inf"`, `"-inf"`, `"nan"`).
pub fn number(v: &serde_json::Value) -> Option<f64> {
    match v {
        serde_json::Value::Number(n) => n.as_f64(),
        serde_json::Value::String(s) => match s.as_str() {
            "inf" => Some(f64::INFINITY),
            "-inf" => Some(f64::NEG_INFINITY),
            "nan" => Some(f64::NAN),
            _ => None,
        },
        _ => None,
    }
}

/// `k` numbers of an array.
pub fn numbers(v: Option<&serde_json::Value>, k: usize) -> Option<Vec<f64>> {
    let a = v?.as_array()?;
    if a.len() != k {
        return None;
    }
    a.iter().map(number).collect()
}

/// A vector of an answer.
pub fn vector(v: Option<&serde_json::Value>) -> Option<DVec3> {
    numbers(v, 3).map(|v| DVec3::new(v[0], v[1], v[2]))
}

/// Written so that NaN fails.
fn within(got: &[f64], want: &[f64], tol: f64) -> bool {
    got.iter()
        .zip(want)
        .all(|(g, w)| (g - w).abs() <= tol || g == w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn fields_are_judged_with_their_tolerances() {
        let e = Expected::one("vector", Want::vector(DVec3::new(1.0, 2.0, 3.0), 1e-9))
            .and("hit", Want::Bool(true));
        assert_eq!(
            e.judge(&json!({"vector": [1.0, 2.0, 3.0000000001], "hit": true})),
            Ok(())
        );
        let bad = e
            .judge(&json!({"vector": [1.0, 2.0, 3.1], "hit": true}))
            .unwrap_err();
        assert!(
            bad.starts_with("vector = [1.0,2.0,3.1], expected [1.0, 2.0, 3.0]"),
            "{bad}"
        );
        assert!(
            e.judge(&json!({"vector": [1.0, 2.0, "nan"], "hit": true}))
                .is_err()
        );
        assert!(
            e.judge(&json!({"vector": [1.0, 2.0, 3.0]}))
                .unwrap_err()
                .contains("(missing)")
        );
        let inf = Expected::one(
            "value",
            Want::Number {
                value: f64::INFINITY,
                tol: 1e-9,
            },
        );
        assert_eq!(inf.judge(&json!({"value": "inf"})), Ok(()));
    }
}
