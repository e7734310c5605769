//! The function checks of each week: what each request asks, what the reference answers, how
//! sure it is ([`Class`]), and the catalogued mistakes each check can name.
//!
//! A check ([`FunctionCheck`]) is one of the course's functions. A deterministic one holds
//! cases, simplest first (so the first failing one is the smallest failing case), and
//! [`Variant`]s: what a catalogued mistake answers on each case. A statistical one holds the
//! requests for its samples and the [`SamplerCheck`] that judges them.
//!
//! [`week_checks`] gives the checks a week's submission is judged by: for each function, the
//! latest version up to that week (week 9's Lambertian replaces week 5's, week 8's integrator
//! week 5's direct term, each week's background the week before's).

use std::time::Duration;

use serde::Serialize;

use super::expect::{Class, Expected};
use super::samplers::{Sample, SamplerCheck, Standing};
use super::week::Week;

pub(crate) mod py;
pub(crate) mod lights;
pub(crate) mod steer;
pub(crate) mod optics;
pub(crate) mod brdf;
pub(crate) mod lambert;
pub(crate) mod camera;
pub(crate) mod steered_camera;
pub(crate) mod surface;

/// One request of a deterministic check and what it must answer.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Case {
    /// An id unique in the run (`refract-0003`).
    pub id: String,
    /// The request (its `op` and arguments; the runner adds the id).
    pub request: serde_json::Value,
    /// The answer's fields, as the course's code computes them.
    pub expect: Expected,
    /// Scored, or why not.
    pub class: Class,
    /// The input, in words.
    pub input: String,
    /// A Python reproduction of the call, with the course's modules.
    pub repro: String,
}

/// What a catalogued mistake answers on each case of a check.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Variant {
    /// The mistake's name (the catalogue's).
    pub name: &'static str,
    /// What it does wrong, in words.
    pub says: &'static str,
    /// Mistake, or a physical alternative to the course's departure.
    pub standing: Standing,
    /// Per case: what it answers (`None`: rounding decides, or its code raises there, so any
    /// answer fits).
    pub expect: Vec<Option<Expected>>,
}

/// Turns a statistical check's answers into its samples.
pub type Extract = Box<dyn Fn(&serde_json::Value) -> Result<Vec<Sample>, String> + Send + Sync>;

/// Adjusts an answer before it is judged (Cook-Torrance's number or grey colour, say).
pub type Normalise = fn(serde_json::Value) -> serde_json::Value;

/// How a check is judged.
pub enum Body {
    /// Cases and the mistakes' answers.
    Cases {
        /// The cases, simplest first.
        cases: Vec<Case>,
        /// The catalogued mistakes.
        variants: Vec<Variant>,
        /// Applied to each answer before judging.
        normalise: Option<Normalise>,
    },
    /// Cases whose random numbers the requests steer (the values of the course's
    /// `random_double`, or of the camera's generator), judged as `steer` says: right when the
    /// answer is the course's, or when it keeps its case's behaviour and the statistical
    /// checks `partners` passed.
    Steered {
        /// The cases, simplest first.
        cases: Vec<Case>,
        /// The catalogued mistakes.
        variants: Vec<Variant>,
        /// The ids of the same function's statistical checks.
        partners: &'static [&'static str],
        /// Per case: what an answer that is not the course's must keep.
        behaviour: Vec<steer::Behaviour>,
        /// Applied to each answer (after its keys are checked) before judging.
        normalise: Option<Normalise>,
    },
    /// Samples, judged by a [`SamplerCheck`].
    Samples {
        /// The requests (each asks for part of the samples, with its own seed).
        requests: Vec<serde_json::Value>,
        /// Reads the samples of one answer.
        extract: Extract,
        /// The statistical check.
        check: SamplerCheck,
        /// A Python reproduction of one request.
        repro: String,
    },
}

/// One of the course's functions and how it is checked.
pub struct FunctionCheck {
    /// A short id (`refract`, `lambertian-lobe`).
    pub id: &'static str,
    /// The function as the course names it (`RT_utility.refract(v, n, ratio)`).
    pub function: &'static str,
    /// The week that introduces it (or this version of it).
    pub week: Week,
    /// Whether that week's skeleton already holds it (the course gives it).
    pub given: bool,
    /// The protocol op its requests use.
    pub op: &'static str,
    /// How answers are compared, in words (the tolerance).
    pub tolerance: &'static str,
    /// The cases or samples.
    pub body: Body,
    /// Time allowed per request.
    pub timeout: Duration,
}

/// The time a deterministic request is allowed.
pub const CASE_TIMEOUT: Duration = Duration::from_secs(2);

/// The time a request of samples is allowed.
pub const SAMPLES_TIMEOUT: Duration = Duration::from_secs(30);

fn week(n: u8) -> Week {
    Week::new(n).expect("a week of 5 to 10")
}

/// The checks of a submission of week `of`: every function of weeks 5 to `of`, each in its
/// latest version up to `of`. `seed` seeds the random cases and the samplers' requests.
pub fn week_checks(of: Week, seed: u64) -> Vec<FunctionCheck> {
    let mut all: Vec<FunctionCheck> = Vec::new();
    all.extend(lambert::checks(seed));
    all.extend(lights::checks(seed));
    all.extend(optics::checks(seed));
    all.extend(surface::checks(seed));
    all.extend(brdf::checks(seed));
    all.extend(camera::checks(seed));
    all.extend(steered_camera::checks(seed));
    // For each id, the latest version up to `of`.
    let mut chosen: Vec<FunctionCheck> = Vec::new();
    for check in all.into_iter().filter(|c| c.week <= of) {
        match chosen.iter().position(|c| c.id == check.id) {
            Some(i) if chosen[i].week <= check.week => chosen[i] = check,
            Some(_) => {}
            None => chosen.push(check),
        }
    }
    chosen.sort_by_key(|c| (c.week, c.id));
    chosen
}

/// The ids of the functions a week-`of` submission is checked on ([`week_checks`]'s), in its
/// order.
pub fn function_ids(of: Week) -> Vec<&'static str> {
    week_checks(of, 0).iter().map(|c| c.id).collect()
}

/// The names of the catalogue's alternatives among a week-`of` submission's checks: versions the
/// course itself has or documents ([`Standing::Alternative`]) and physical departures
/// ([`Standing::Physical`]), which a rubric may accept as passing.
pub fn alternatives(of: Week) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for c in week_checks(of, 0) {
        let named: Vec<(&'static str, Standing)> = match &c.body {
            Body::Cases { variants, .. } | Body::Steered { variants, .. } => {
                variants.iter().map(|v| (v.name, v.standing)).collect()
            }
            Body::Samples { check, .. } => check
                .mistakes
                .iter()
                .map(|h| (h.name, h.standing))
                .collect(),
        };
        for (name, standing) in named {
            if matches!(standing, Standing::Alternative | Standing::Physical)
                && !out.contains(&name)
            {
                out.push(name);
            }
        }
    }
    out
}

/// A small deterministic stream for the random cases of a check: the reference's sampler,
/// seeded by the run's seed and the check's id.
pub(crate) fn stream(seed: u64, id: &str) -> crate::render::PixelSampler {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in id.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    crate::render::PixelSampler::new(seed, h)
}

/// Numbers as requests carry them (the protocol's syntax for non-finite numbers).
pub(crate) fn jnum(x: f64) -> serde_json::Value {
    crate::oracle::vectors::num::to_value(x)
}

/// A vector as requests carry it.
pub(crate) fn jvec(v: glam::DVec3) -> serde_json::Value {
    serde_json::Value::Array(vec![jnum(v.x), jnum(v.y), jnum(v.z)])
}
