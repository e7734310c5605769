//! Where material answers come from: the protocol's three material requests
//! (`material_sample`, `material_eval`, `material_pdf`; `docs/PROTOCOL.md`) sent to a candidate
//! ([`ProtocolSource`], through any [`FunctionRunner`]), or rtoracle's own models
//! ([`super::models::ModelSource`]).
//!
//! What a [`ProtocolSource`] promises: requests are cut into batches whose answers stay under
//! the protocol's cap on a function's answer; every answer is read strictly (the right count of
//! rows, numbers where numbers are due, a `delta` that is a boolean); anything else is a
//! [`Problem::Broken`] naming the request and what was wrong, never a panic.

use std::time::Duration;

use glam::DVec3;
use serde_json::{Value, json};

use crate::weekly::{runner::FunctionRunner, runner::Reply};

/// One of the three material requests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `material_sample`.
    Sample,
    /// `material_eval`.
    Eval,
    /// `material_pdf`.
    Pdf,
}

impl Op {
    /// The request's `op`.
    pub fn name(self) -> &'static str {
        match self {
            Op::Sample => "material_sample",
            Op::Eval => "material_eval",
            Op::Pdf => "material_pdf",
        }
    }
}

/// One sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialSample {
    /// The incoming direction chosen (unit, away from the surface).
    pub wi: DVec3,
    /// What the throughput is multiplied by (`f |cos| / pdf` when honest).
    pub weight: DVec3,
    /// Its pdf per unit solid angle (a delta's: the probability of choosing that lobe); `None`
    /// when the candidate gives none.
    pub pdf: Option<f64>,
    /// Whether the direction is a delta lobe's (a mirror's, a refraction's).
    pub delta: bool,
}

/// Why a request got no usable answer.
#[derive(Clone, Debug, PartialEq)]
pub enum Problem {
    /// The candidate does not have the material (an answer `{"declined": why}`, or an error of
    /// type `NotFound`): the material is not run.
    Declined(String),
    /// Its code raised (`type: message`).
    Error(String),
    /// No usable answer: a timeout, a death, a malformed answer (what was wrong).
    Broken(String),
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::Declined(why) => write!(f, "declined: {why}"),
            Problem::Error(e) => write!(f, "raised {e}"),
            Problem::Broken(why) => f.write_str(why),
        }
    }
}

/// Something that answers material requests.
pub trait MaterialSource {
    /// A label for the report.
    fn label(&self) -> String;
    /// Whether it answers `op`.
    fn supports(&self, op: Op) -> bool;
    /// `material_sample`: one answer per row of four uniform numbers (`None`: absorbed).
    fn sample(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        u: &[[f64; 4]],
    ) -> Result<Vec<Option<MaterialSample>>, Problem>;
    /// `material_eval`: `f(wo, wi)` for each `wi`.
    fn eval(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<DVec3>, Problem>;
    /// `material_pdf`: the pdf of each `wi`.
    fn pdf(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<f64>, Problem>;
}

/// Samples per `material_sample` request (about 210 bytes a row: under the 128 KiB cap).
pub const SAMPLE_BATCH: usize = 400;
/// Directions per `material_eval` or `material_pdf` request.
pub const EVAL_BATCH: usize = 1000;

/// The protocol's material requests sent through a [`FunctionRunner`] (a candidate's session).
pub struct ProtocolSource<'a> {
    runner: &'a mut dyn FunctionRunner,
    label: String,
    timeout: Duration,
}

impl<'a> ProtocolSource<'a> {
    /// Requests through `runner`, each allowed `timeout`.
    pub fn new(runner: &'a mut dyn FunctionRunner, label: String, timeout: Duration) -> Self {
        ProtocolSource {
            runner,
            label,
            timeout,
        }
    }

    fn call(&mut self, request: Value) -> Result<Value, Problem> {
        match self.runner.call(&request, self.timeout) {
            Reply::Result(v) => match v.get("declined") {
                Some(why) => Err(Problem::Declined(crate::escape::truncate(
                    why.as_str().unwrap_or("(no reason given)"),
                    300,
                ))),
                None => Ok(v),
            },
            Reply::Error(e) if e.kind == "NotFound" || e.kind == "Unsupported" => {
                Err(Problem::Declined(format!("{}: {}", e.kind, e.message)))
            }
            Reply::Error(e) => Err(Problem::Error(format!("{}: {}", e.kind, e.message))),
            Reply::NotRun(why) => Err(Problem::Declined(why)),
            Reply::TimedOut => Err(Problem::Broken(format!(
                "no answer to a {} request within {} ms",
                request["op"].as_str().unwrap_or("?"),
                self.timeout.as_millis()
            ))),
            Reply::Failed(why) => Err(Problem::Broken(why)),
            Reply::Protocol(why) => Err(Problem::Broken(format!("protocol error: {why}"))),
        }
    }
}

fn arr(v: DVec3) -> Value {
    json!([num(v.x), num(v.y), num(v.z)])
}

/// A number as the protocol writes it (non-finite ones as strings).
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else if x.is_nan() {
        json!("nan")
    } else if x > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

/// A number of an answer (the protocol's strings for non-finite ones).
fn read_num(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => match s.as_str() {
            "nan" => Some(f64::NAN),
            "inf" => Some(f64::INFINITY),
            "-inf" => Some(f64::NEG_INFINITY),
            _ => None,
        },
        _ => None,
    }
}

fn read_v3(v: &Value) -> Option<DVec3> {
    let a = v.as_array()?;
    if a.len() != 3 {
        return None;
    }
    Some(DVec3::new(
        read_num(&a[0])?,
        read_num(&a[1])?,
        read_num(&a[2])?,
    ))
}

/// The rows of `result[key]`, exactly `count` of them.
fn rows<'v>(result: &'v Value, key: &str, count: usize, op: Op) -> Result<&'v [Value], Problem> {
    let list = result.get(key).and_then(Value::as_array).ok_or_else(|| {
        Problem::Broken(format!(
            "a malformed {} answer: its result has no \"{key}\" list",
            op.name()
        ))
    })?;
    if list.len() != count {
        return Err(Problem::Broken(format!(
            "a malformed {} answer: {} rows in \"{key}\" for {count} asked",
            op.name(),
            list.len()
        )));
    }
    Ok(list)
}

fn read_sample(row: &Value) -> Result<Option<MaterialSample>, String> {
    if row.is_null() {
        return Ok(None);
    }
    let wi = row
        .get("wi")
        .and_then(read_v3)
        .ok_or("no \"wi\" (three numbers)")?;
    let weight = row
        .get("weight")
        .and_then(read_v3)
        .ok_or("no \"weight\" (three numbers)")?;
    let pdf = match row.get("pdf") {
        None | Some(Value::Null) => None,
        Some(v) => Some(read_num(v).ok_or("a \"pdf\" that is not a number")?),
    };
    let delta = match row.get("delta") {
        None | Some(Value::Null) => false,
        Some(Value::Bool(b)) => *b,
        Some(_) => return Err("a \"delta\" that is not true or false".into()),
    };
    Ok(Some(MaterialSample {
        wi,
        weight,
        pdf,
        delta,
    }))
}

impl MaterialSource for ProtocolSource<'_> {
    fn label(&self) -> String {
        self.label.clone()
    }

    fn supports(&self, op: Op) -> bool {
        self.runner.supports(op.name())
    }

    fn sample(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        u: &[[f64; 4]],
    ) -> Result<Vec<Option<MaterialSample>>, Problem> {
        let mut out = Vec::with_capacity(u.len());
        for chunk in u.chunks(SAMPLE_BATCH) {
            let request = json!({
                "op": Op::Sample.name(), "material": material, "wo": arr(wo), "normal": arr(n),
                "u": chunk,
            });
            let result = self.call(request)?;
            for (k, row) in rows(&result, "samples", chunk.len(), Op::Sample)?
                .iter()
                .enumerate()
            {
                out.push(read_sample(row).map_err(|why| {
                    Problem::Broken(format!(
                        "a malformed material_sample answer: sample {} has {why}",
                        out.len() + k
                    ))
                })?);
            }
        }
        Ok(out)
    }

    fn eval(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<DVec3>, Problem> {
        let asked = Asked {
            material,
            wo,
            n,
            wi,
        };
        self.per_direction(
            Op::Eval,
            "f",
            "an f that is not three numbers",
            asked,
            read_v3,
        )
    }

    fn pdf(
        &mut self,
        material: &Value,
        wo: DVec3,
        n: DVec3,
        wi: &[DVec3],
    ) -> Result<Vec<f64>, Problem> {
        let asked = Asked {
            material,
            wo,
            n,
            wi,
        };
        self.per_direction(
            Op::Pdf,
            "pdf",
            "a pdf that is not a number",
            asked,
            read_num,
        )
    }
}

/// What a per-direction request asks about: the material, the outgoing direction, the normal and
/// the incoming directions.
struct Asked<'v> {
    material: &'v Value,
    wo: DVec3,
    n: DVec3,
    wi: &'v [DVec3],
}

impl ProtocolSource<'_> {
    /// One value per incoming direction (`material_eval`'s f, `material_pdf`'s pdf), asked in
    /// batches: the answer's `key` rows, each read by `read` (`None` is a broken answer, said as
    /// `malformed`).
    fn per_direction<T>(
        &mut self,
        op: Op,
        key: &str,
        malformed: &str,
        asked: Asked<'_>,
        read: impl Fn(&Value) -> Option<T>,
    ) -> Result<Vec<T>, Problem> {
        let mut out = Vec::with_capacity(asked.wi.len());
        for chunk in asked.wi.chunks(EVAL_BATCH) {
            let list: Vec<Value> = chunk.iter().map(|&w| arr(w)).collect();
            let request = json!({
                "op": op.name(), "material": asked.material, "wo": arr(asked.wo),
                "normal": arr(asked.n), "wi": list,
            });
            let result = self.call(request)?;
            for row in rows(&result, key, chunk.len(), op)? {
                out.push(read(row).ok_or_else(|| {
                    Problem::Broken(format!("a malformed {} answer: {malformed}", op.name()))
                })?);
            }
        }
        Ok(out)
    }
}
