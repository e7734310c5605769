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
//!
//! [`parse_line`] tells each stdout line apart: a valid answer, a malformed one (with its id when
//! it has one: a bare `nan`, a wrong type, a number out of range, a hit without its fields), a
//! hello, or stray output; every text it keeps is capped ([`MAX_ERROR_FIELD_BYTES`],
//! [`MAX_QUOTE_CHARS`]), so a line costs bounded memory whatever the candidate writes.
//! [`Hello::check`] accepts protocol 1 and the [`KNOWN_SHAPES`] only.

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
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
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
    /// Where the candidate's own code raised it, as the candidate says (the course adapter:
    /// the last frame in the submission's folder, never the adapter's): a file's name, without
    /// a folder. Text from the candidate: capped ([`CandidateError::capped`]), and escaped
    /// wherever it is shown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The line of `file` it was raised on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<u64>,
    /// The function of `file` it was raised in, when there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub function: Option<String>,
    /// The code of that line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub code: Option<String>,
}

/// `TYPE: MESSAGE (FILE, line N)`: the exception, and where the candidate's code raised it
/// when the candidate said so (as Python writes a `SyntaxError`'s place). All of it is the
/// candidate's text.
impl std::fmt::Display for CandidateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.kind.is_empty(), self.message.is_empty()) {
            (false, false) => write!(f, "{}: {}", self.kind, self.message)?,
            (false, true) => f.write_str(&self.kind)?,
            _ => f.write_str(&self.message)?,
        }
        match self.place() {
            Some(place) => write!(f, " ({place})"),
            None => Ok(()),
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
                ..CandidateError::default()
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

/// Longest text kept of each field of a candidate's error (type, message, traceback), on the
/// harness's side: what the candidate sends beyond it is cut ([`crate::escape::truncate`]).
pub const MAX_ERROR_FIELD_BYTES: usize = 4096;

/// Longest quotation of a line that is not a valid answer (a protocol error's evidence).
pub const MAX_QUOTE_CHARS: usize = 200;

/// The shapes the protocol knows, as named in a hello.
pub const KNOWN_SHAPES: [&str; 3] = ["sphere", "quad", "triangle"];

impl CandidateError {
    /// The error with each field cut to [`MAX_ERROR_FIELD_BYTES`].
    pub fn capped(self) -> Self {
        self.capped_to(MAX_ERROR_FIELD_BYTES)
    }

    /// The error with each field cut to `max` bytes.
    pub fn capped_to(self, max: usize) -> Self {
        let cut = |s: String| {
            if s.len() <= max {
                s
            } else {
                crate::escape::truncate(&s, max)
            }
        };
        let short =
            |s: Option<String>| s.map(|s| crate::escape::truncate(&s, max.min(MAX_QUOTE_CHARS)));
        CandidateError {
            kind: cut(self.kind),
            message: cut(self.message),
            traceback: cut(self.traceback),
            // A name, not a path: what follows the last `/`.
            file: short(
                self.file
                    .map(|f| f.rsplit('/').next().unwrap_or_default().to_string()),
            ),
            line: self.line,
            function: short(self.function),
            code: short(self.code),
        }
    }

    /// Bytes of text the error holds.
    pub fn text_len(&self) -> usize {
        self.kind.len()
            + self.message.len()
            + self.traceback.len()
            + [&self.file, &self.function, &self.code]
                .iter()
                .map(|s| s.as_ref().map_or(0, String::len))
                .sum::<usize>()
    }

    /// Where the candidate's code raised it, when the candidate said (a file, and a line):
    /// `RT_object.py, line 29` (the candidate's text, unescaped).
    pub fn place(&self) -> Option<String> {
        let file = self.file.as_deref().filter(|f| !f.is_empty())?;
        Some(match self.line {
            Some(line) => format!("{file}, line {line}"),
            None => file.to_string(),
        })
    }
}

/// `s` quoted for a report around the byte `at` (where a parser found the problem): the
/// [`MAX_QUOTE_CHARS`] characters that end a quarter of that past it, with `...` where cut on
/// either side, in Rust string syntax. A line short enough is quoted whole ([`quote_line`]).
pub fn quote_around(s: &str, at: usize) -> String {
    let chars: Vec<(usize, char)> = s.char_indices().collect();
    if chars.len() <= MAX_QUOTE_CHARS {
        return quote_line(s);
    }
    let at_char = chars.partition_point(|&(i, _)| i < at.min(s.len()));
    let end = (at_char + MAX_QUOTE_CHARS / 4).clamp(MAX_QUOTE_CHARS, chars.len());
    let start = end - MAX_QUOTE_CHARS;
    let byte = |k: usize| chars.get(k).map_or(s.len(), |&(i, _)| i);
    let mut q = format!("{:?}", &s[byte(start)..byte(end)]);
    if start > 0 {
        q.insert_str(0, "...");
    }
    if end < chars.len() {
        q.push_str("...");
    }
    q
}

/// `s` quoted for a report: at most [`MAX_QUOTE_CHARS`] characters (with `...` when cut), in
/// Rust string syntax, so control characters show as escapes.
pub fn quote_line(s: &str) -> String {
    let q: String = s.chars().take(MAX_QUOTE_CHARS).collect();
    let cut = q.len() < s.len();
    let mut q = format!("{q:?}");
    if cut {
        q.push_str("...");
    }
    q
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
    /// Present in a function request's answer (its content is read from the line's text).
    #[serde(default)]
    result: Option<serde::de::IgnoredAny>,
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
                error: self.error.map(CandidateError::capped),
            },
        )
    }
}

/// What one stdout line turned out to be.
#[derive(Debug, PartialEq)]
pub enum ParsedLine {
    /// A valid answer, with any junk that preceded it on the same line (a `print` without
    /// newline).
    Answer {
        /// The id the answer carries.
        id: String,
        /// The answer (well formed: [`Answer::validate`] holds; error fields capped).
        answer: Answer,
        /// Text before the answer on the same line, quoted ([`quote_line`]); empty when the
        /// line was clean.
        junk: String,
    },
    /// A line meant as an answer that is not a valid one: not JSON (a bare `nan`), a field of
    /// the wrong type (`"hit":"true"`), a number out of range (`1e999`), a hit without a normal. `id` is the id it carries, when one can be read from it.
    Malformed {
        /// The id, when the line names one.
        id: Option<String>,
        /// What is wrong, in words.
        problem: String,
        /// The line, quoted and capped ([`quote_line`]).
        quoted: String,
    },
    /// A hello answer.
    Hello(Hello),
    /// A line that looks like a hello but is not a valid one.
    BadHello(String),
    /// Not an answer: stray output, quoted and capped ([`quote_line`]).
    Junk(String),
    /// A valid answer to a function request (`docs/PROTOCOL.md`, "Function requests"): the id
    /// and the answer object's text (at most [`MAX_RESULT_BYTES`]), whose `result` the session
    /// reads when it is wanted.
    Result {
        /// The id the answer carries.
        id: String,
        /// The answer object, as the candidate wrote it.
        text: String,
    },
}

/// Longest answer to a function request kept (its text): larger ones are malformed. Requests
/// for samples ask for few enough that their answers fit.
pub const MAX_RESULT_BYTES: usize = 128 * 1024;

/// Keys of an answer object.
const ANSWER_KEYS: [&str; 8] = [
    "id",
    "hit",
    "t",
    "point",
    "normal",
    "front_face",
    "error",
    "result",
];

/// Reads `"id":"..."` out of text that is not valid JSON (a bare `nan` further on).
fn lenient_id(text: &str) -> Option<String> {
    let rest = &text[text.find("\"id\"")? + 4..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start();
    let rest = rest.strip_prefix('"')?;
    let end = rest.find(['"', '\\'])?;
    Some(rest[..end].to_string())
}

fn malformed(id: Option<String>, problem: String, line: &str) -> ParsedLine {
    ParsedLine::Malformed {
        id,
        problem,
        quoted: quote_line(line),
    }
}

/// A malformed answer whose problem the JSON parser placed (`error`, from parsing the text
/// that starts `offset` bytes into `line`): the quote is taken around that place, so a long line
/// still shows what is wrong.
fn malformed_at(
    id: Option<String>,
    problem: String,
    line: &str,
    offset: usize,
    error: &serde_json::Error,
) -> ParsedLine {
    ParsedLine::Malformed {
        id,
        problem,
        quoted: quote_around(line, offset + error.column()),
    }
}

/// Parses one stdout line: an answer, a malformed answer, a hello, or junk. A line that is
/// not an answer but contains one after some junk (a stray `print(..., end="")`) yields the
/// answer and the junk. Every text kept from the line is capped, so what a line costs in memory
/// is bounded whatever the candidate writes.
pub fn parse_line(line: &str) -> ParsedLine {
    let trimmed = line.trim_end_matches(['\r', '\n']);
    // The fast path: a clean answer.
    if let Ok(a) = serde_json::from_str::<AnswerLine>(trimmed) {
        return answer_or_malformed(a, "", trimmed);
    }
    let (prefix, object) = if trimmed.trim_start().starts_with('{') {
        ("", trimmed.trim_start())
    } else if let Some(pos) = trimmed.find("{\"id\"") {
        (&trimmed[..pos], &trimmed[pos..])
    } else {
        return ParsedLine::Junk(quote_line(trimmed));
    };
    match serde_json::from_str::<serde_json::Value>(object) {
        Ok(serde_json::Value::Object(map)) => {
            if !map.contains_key("id") {
                if map.contains_key("name") || map.contains_key("protocol") {
                    return match Hello::from_value(serde_json::Value::Object(map)) {
                        Ok(hello) => ParsedLine::Hello(hello),
                        Err(problem) => ParsedLine::BadHello(problem),
                    };
                }
                if ANSWER_KEYS.iter().any(|k| map.contains_key(*k)) {
                    return malformed(None, "an answer without an \"id\"".into(), trimmed);
                }
                return ParsedLine::Junk(quote_line(trimmed));
            }
            let Some(id) = map.get("id").and_then(|v| v.as_str()).map(str::to_string) else {
                return malformed(None, "its \"id\" is not a string".into(), trimmed);
            };
            // Parsed again from the text, so the error says where in the line it is.
            match serde_json::from_str::<AnswerLine>(object) {
                Ok(a) => answer_or_malformed(a, prefix, trimmed),
                Err(e) => malformed_at(
                    Some(id),
                    format!("not a valid answer: {e}"),
                    trimmed,
                    trimmed.len() - object.len(),
                    &e,
                ),
            }
        }
        Ok(_) => ParsedLine::Junk(quote_line(trimmed)),
        Err(e) => {
            let offset = trimmed.len() - object.len();
            match lenient_id(object) {
                Some(id) => malformed_at(
                    Some(id),
                    format!("not valid JSON: {e}"),
                    trimmed,
                    offset,
                    &e,
                ),
                None if object.starts_with("{\"id\"") => {
                    malformed_at(None, format!("not valid JSON: {e}"), trimmed, offset, &e)
                }
                None => ParsedLine::Junk(quote_line(trimmed)),
            }
        }
    }
}

fn answer_or_malformed(a: AnswerLine, junk: &str, line: &str) -> ParsedLine {
    if a.result.is_some() && a.error.is_none() && a.hit.is_none() {
        let text = line[junk.len()..].trim_start();
        if text.len() > MAX_RESULT_BYTES {
            return malformed(
                Some(a.id),
                format!("a function's answer over {MAX_RESULT_BYTES} bytes"),
                line,
            );
        }
        return ParsedLine::Result {
            id: a.id,
            text: text.to_string(),
        };
    }
    let (id, answer) = a.split();
    match answer.validate() {
        Ok(()) => ParsedLine::Answer {
            id,
            answer,
            junk: if junk.is_empty() {
                String::new()
            } else {
                quote_line(junk)
            },
        },
        Err(problem) => malformed(Some(id), problem, line),
    }
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
    /// The requests it answers besides `intersect` (`["intersect", "reflect", ...]`); only
    /// `intersect` when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ops: Option<Vec<String>>,
    /// Set when the candidate cannot answer any case, e.g. a submission that cannot be imported:
    /// every case is then reported with this error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<CandidateError>,
    /// The keys of the hello that the protocol does not name (a misspelt `shape` for
    /// `shapes`), quoted; ignored, but warned about ([`Hello::warnings`]).
    #[serde(skip)]
    pub unknown_keys: Vec<String>,
}

/// The keys a hello answer may have.
pub const HELLO_KEYS: [&str; 5] = ["name", "protocol", "shapes", "ops", "error"];

/// The keys of `map` that are not [`HELLO_KEYS`], in order, each capped; at most 8.
fn unknown_hello_keys(map: &serde_json::Map<String, serde_json::Value>) -> Vec<String> {
    map.keys()
        .filter(|k| !HELLO_KEYS.contains(&k.as_str()))
        .take(8)
        .map(|k| crate::escape::truncate(k, 40))
        .collect()
}

/// The known key `key` is likely a misspelling of: one edit away, or the same but for case
/// or a plural `s`.
fn likely_hello_key(key: &str) -> Option<&'static str> {
    let key = key.to_ascii_lowercase();
    HELLO_KEYS.into_iter().find(|known| {
        *known == key
            || key.strip_suffix('s') == Some(known)
            || known.strip_suffix('s') == Some(key.as_str())
            || one_edit_apart(known, &key)
    })
}

/// Whether `a` becomes `b` by one insertion, deletion or substitution of a character.
fn one_edit_apart(a: &str, b: &str) -> bool {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let (short, long) = if a.len() <= b.len() {
        (&a, &b)
    } else {
        (&b, &a)
    };
    if long.len() - short.len() > 1 || a == b {
        return false;
    }
    let k = short
        .iter()
        .zip(long.iter())
        .take_while(|(x, y)| x == y)
        .count();
    if short.len() == long.len() {
        short[k + 1..] == long[k + 1..]
    } else {
        short[k..] == long[k + 1..]
    }
}

impl Hello {
    /// What the harness warns about in this hello: each key the protocol does not name, with
    /// the key it is likely a misspelling of.
    pub fn warnings(&self) -> Vec<String> {
        self.unknown_keys
            .iter()
            .map(|key| {
                let hint = match likely_hello_key(key) {
                    Some(known) => format!(" (did you mean \"{known}\"?)"),
                    None => String::new(),
                };
                format!(
                    "its hello has the key {}, which the protocol does not name, so it was \
                     ignored{hint}; a hello's keys are {}",
                    quote_line(key),
                    HELLO_KEYS.join(", ")
                )
            })
            .collect()
    }

    /// Parses a hello answer line; `None` when the line is not one (or not a valid one).
    pub fn parse(line: &str) -> Option<Hello> {
        match parse_line(line) {
            ParsedLine::Hello(h) => Some(h),
            _ => None,
        }
    }

    /// A hello from a JSON object (no `id`, a `name` or a `protocol`); `Err` says what is wrong
    /// with its fields. Text fields are capped.
    fn from_value(value: serde_json::Value) -> Result<Hello, String> {
        let unknown_keys = match &value {
            serde_json::Value::Object(map) => unknown_hello_keys(map),
            _ => Vec::new(),
        };
        let mut hello: Hello =
            serde_json::from_value(value).map_err(|e| format!("its hello is malformed: {e}"))?;
        hello.unknown_keys = unknown_keys;
        if hello.name.len() > MAX_QUOTE_CHARS {
            hello.name = crate::escape::truncate(&hello.name, MAX_QUOTE_CHARS);
        }
        hello.error = hello.error.map(CandidateError::capped);
        if let Some(ops) = &mut hello.ops {
            ops.truncate(64);
            for s in ops.iter_mut() {
                if s.len() > 40 {
                    *s = crate::escape::truncate(s, 40);
                }
            }
        }
        if let Some(shapes) = &mut hello.shapes {
            shapes.truncate(16);
            for s in shapes.iter_mut() {
                if s.len() > 40 {
                    *s = crate::escape::truncate(s, 40);
                }
            }
        }
        Ok(hello)
    }

    /// `Ok` when the hello can be accepted: protocol version [`PROTOCOL_VERSION`] and only known
    /// shape names; otherwise one line saying what is wrong.
    pub fn check(&self) -> Result<(), String> {
        match self.protocol {
            Some(PROTOCOL_VERSION) => {}
            Some(v) => {
                return Err(format!(
                    "its hello says \"protocol\": {v}, but rtoracle speaks protocol {PROTOCOL_VERSION}"
                ));
            }
            None => {
                return Err(format!(
                    "its hello has no \"protocol\" (rtoracle speaks protocol {PROTOCOL_VERSION}: answer {{\"protocol\":{PROTOCOL_VERSION},...}})"
                ));
            }
        }
        if let Some(shapes) = &self.shapes {
            if let Some(bad) = shapes.iter().find(|s| !KNOWN_SHAPES.contains(&s.as_str())) {
                return Err(format!(
                    "its hello names an unknown shape {}; the known shapes are {}",
                    quote_line(bad),
                    KNOWN_SHAPES.join(", ")
                ));
            }
        }
        Ok(())
    }

    /// Whether the candidate answers requests of kind `op`; every candidate answers
    /// `"intersect"`.
    pub fn answers(&self, op: &str) -> bool {
        op == "intersect"
            || self
                .ops
                .as_ref()
                .is_some_and(|ops| ops.iter().any(|o| o == op))
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
        match parse_line(line) {
            ParsedLine::Answer { id, answer, junk } => {
                assert_eq!(id, "v1");
                assert_eq!(answer.t, Some(4.0));
                assert!(junk.is_empty());
                assert!(answer.validate().is_ok());
            }
            other => panic!("{other:?}"),
        }
        match parse_line(&format!("debug 1 2{line}")) {
            ParsedLine::Answer { junk, .. } => assert_eq!(junk, "\"debug 1 2\""),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            parse_line("hello world"),
            ParsedLine::Junk("\"hello world\"".into())
        );
        // A dict printed by the submission is stray output, not an answer.
        assert!(matches!(parse_line("{'a': 1}"), ParsedLine::Junk(_)));
        assert!(matches!(parse_line(r#"{"a": 1}"#), ParsedLine::Junk(_)));
        // Non-finite numbers as strings.
        match parse_line(r#"{"id":"x","hit":true,"t":"nan","normal":[0,0,1],"front_face":false}"#) {
            ParsedLine::Answer { answer, .. } => assert!(answer.t.unwrap().is_nan()),
            other => panic!("{other:?}"),
        }
    }

    /// Each way an answer line can be wrong is a malformed answer, with the id when it has one.
    #[test]
    fn malformed_lines_are_told_apart_from_junk_and_keep_their_id() {
        let cases = [
            // printf("%.17g") of a NaN: not JSON.
            (
                r#"{"id":"v1","hit":true,"t":nan,"normal":[0,0,1],"front_face":true}"#,
                Some("v1"),
                "not valid JSON",
            ),
            (
                r#"{"id":"v2","hit":"true"}"#,
                Some("v2"),
                "not a valid answer",
            ),
            (
                r#"{"id":"v3","hit":true,"t":1e999,"normal":[0,0,1],"front_face":true}"#,
                Some("v3"),
                "number out of range",
            ),
            (
                r#"{"id":"v4","hit":true,"t":1.0}"#,
                Some("v4"),
                "lacks normal, front_face",
            ),
            (r#"{"id":"v5"}"#, Some("v5"), "neither"),
            (r#"{"hit":false}"#, None, "without an \"id\""),
            (r#"{"id":7,"hit":false}"#, None, "not a string"),
            (r#"{"id":"v8","hit":fals"#, Some("v8"), "not valid JSON"),
        ];
        for (line, want_id, want_problem) in cases {
            match parse_line(line) {
                ParsedLine::Malformed {
                    id,
                    problem,
                    quoted,
                } => {
                    assert_eq!(id.as_deref(), want_id, "{line}");
                    assert!(problem.contains(want_problem), "{line}: {problem}");
                    assert!(quoted.starts_with('"') && quoted.len() <= 2 * line.len() + 2);
                }
                other => panic!("{line}: {other:?}"),
            }
        }
    }

    #[test]
    fn what_is_kept_of_a_line_is_capped() {
        let big = "m".repeat(300_000);
        let line =
            format!(r#"{{"id":"v","error":{{"type":"E","message":"{big}","traceback":"{big}"}}}}"#);
        match parse_line(&line) {
            ParsedLine::Answer { answer, .. } => {
                let e = answer.error.unwrap();
                assert!(
                    e.message.len() < MAX_ERROR_FIELD_BYTES + 40,
                    "{}",
                    e.message.len()
                );
                assert!(e.traceback.len() < MAX_ERROR_FIELD_BYTES + 40);
                assert!(e.message.ends_with("more bytes]"));
            }
            other => panic!("{other:?}"),
        }
        match parse_line(&big) {
            ParsedLine::Junk(q) => assert!(q.len() <= MAX_QUOTE_CHARS + 5),
            other => panic!("{other:?}"),
        }
        let bad = format!(r#"{{"id":"v","hit":tru {big}"#);
        match parse_line(&bad) {
            ParsedLine::Malformed { quoted, .. } => {
                assert!(quoted.len() <= 2 * MAX_QUOTE_CHARS + 5)
            }
            other => panic!("{other:?}"),
        }
    }

    /// The quote of a long bad answer (400 characters of an unknown field before the bad key) showed
    /// its first 200 characters, which stopped before the problem.
    #[test]
    fn a_long_bad_answer_is_quoted_around_its_problem() {
        let pad = "p".repeat(400);
        let line = format!(
            r#"{{"id":"v1","hit":true,"t":1.0,"pad":"{pad}","normal":[0,0,1],"front_face":"yes"}}"#
        );
        assert!(line.len() > 2 * MAX_QUOTE_CHARS);
        match parse_line(&line) {
            ParsedLine::Malformed {
                problem, quoted, ..
            } => {
                assert!(problem.contains("expected a boolean"), "{problem}");
                assert!(quoted.contains(r#"front_face\":\"yes"#), "{quoted}");
                assert!(quoted.starts_with("...\""), "{quoted}");
                assert!(quoted.len() <= MAX_QUOTE_CHARS + 60, "{quoted}");
            }
            other => panic!("{other:?}"),
        }
        // Not JSON at all, far into the line: the same.
        let line = format!(r#"{{"id":"v2","hit":true,"pad":"{pad}","t":nan}}"#);
        match parse_line(&line) {
            ParsedLine::Malformed { quoted, .. } => {
                assert!(quoted.contains(r#"\"t\":nan"#), "{quoted}")
            }
            other => panic!("{other:?}"),
        }
        // A short line is quoted whole.
        assert_eq!(quote_around("abc", 2), "\"abc\"");
        let s = "é".repeat(500);
        let q = quote_around(&s, 700);
        assert!(q.starts_with("...\"") && q.ends_with("\"..."), "{q}");
    }

    /// A misspelt key (`shape` for `shapes`) was silently ignored: it is warned about, with the
    /// key meant.
    #[test]
    fn unknown_hello_keys_are_warned_about() {
        let h =
            Hello::parse(r#"{"name":"c","protocol":1,"shape":["sphere"],"x-build":"7"}"#).unwrap();
        assert_eq!(h.check(), Ok(()));
        let w = h.warnings();
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].contains("\"shape\"") && w[0].contains("did you mean \"shapes\"?"),
            "{w:?}"
        );
        assert!(w[1].contains("\"x-build\"") && !w[1].contains("did you mean"));
        assert!(w[1].contains("name, protocol, shapes, ops, error"));
        let ok = Hello::parse(r#"{"name":"c","protocol":1,"shapes":["sphere"]}"#).unwrap();
        assert!(ok.warnings().is_empty());
        // The function and render requests' list is a key of its own, not a typo.
        let ops =
            Hello::parse(r#"{"name":"c","protocol":1,"ops":["intersect","render"]}"#).unwrap();
        assert!(ops.warnings().is_empty(), "{:?}", ops.warnings());
        for (typo, meant) in [("nme", "name"), ("protocl", "protocol"), ("Error", "error")] {
            assert_eq!(likely_hello_key(typo), Some(meant), "{typo}");
        }
        assert_eq!(likely_hello_key("colour"), None);
    }

    #[test]
    fn hellos_are_validated() {
        let ok = Hello::parse(r#"{"name":"c","protocol":1,"shapes":["sphere","quad"]}"#).unwrap();
        assert_eq!(ok.check(), Ok(()));
        let v2 = Hello::parse(r#"{"name":"c","protocol":2}"#).unwrap();
        assert!(v2.check().unwrap_err().contains("\"protocol\": 2"));
        let none = Hello::parse(r#"{"name":"c"}"#).unwrap();
        assert!(none.check().unwrap_err().contains("no \"protocol\""));
        let typo =
            Hello::parse(r#"{"name":"c","protocol":1,"shapes":["sphere","quads"]}"#).unwrap();
        let problem = typo.check().unwrap_err();
        assert!(
            problem.contains("\"quads\"") && problem.contains("sphere, quad, triangle"),
            "{problem}"
        );
        assert!(matches!(
            parse_line(r#"{"name":"c","protocol":"one"}"#),
            ParsedLine::BadHello(_)
        ));
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
