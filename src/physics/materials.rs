//! Checking a renderer's materials through the protocol's material requests, with no golden:
//! which materials, at which outgoing directions, how many samples, the false-alarm rate, and
//! the report ([`MaterialsReport`]).
//!
//! For each material ([`MaterialCase`]): a unit normal drawn from the seed, outgoing directions
//! at `cos theta_o` of [`OUTSIDE`] (and [`INSIDE`], below the surface, for a material with an
//! index of refraction), at each the laws of [`super::laws`] from `samples` draws, the cells'
//! integrals of the pdf and of `f |cos|`, and, once per material, reciprocity over the pairs of
//! [`RECIPROCITY_COSINES`]' directions. The statistical laws share the run's false-alarm rate
//! `alpha` by Šidák's rule over every statistical test the run can make (counted before any
//! answer: four per material and direction), so an honest candidate fails a run with
//! probability at most `alpha`.
//!
//! When a reference is given (rtoracle's models of the same family), every law the candidate
//! breaks is also checked on the reference with the same inputs; where the reference breaks
//! it too, the law's status is [`Status::Finding`]: the model breaks it (the course's Phong
//! with `kd + ks > 1`), not the candidate.

use glam::DVec3;
use serde::Serialize;
use serde_json::{Value, json};

use super::laws::{
    Law, LawResult, Observed, Status, delta_laws, energy_laws, pdf_laws, sample_laws,
};
use super::source::{MaterialSample, MaterialSource, Op, Problem};
use super::sphere::{CellIntegrals, Frame, Values, integrate, integrate_cells};
use crate::render::PixelSampler;

/// `cos theta_o` of the outgoing directions above the surface.
pub const OUTSIDE: [f64; 3] = [0.95, 0.6, 0.2];
/// `cos theta_o` below it, for a material with an index of refraction (from inside the glass:
/// at `-0.6` and `ior = 1.5`, `1.5 sin theta = 1.2`: total internal reflection).
pub const INSIDE: [f64; 2] = [-0.9, -0.6];
/// `cos theta` of the directions whose pairs judge reciprocity: each with a second direction
/// at another azimuth and a third near its mirror image (so that the pairs of a glossy lobe,
/// whose BRDF vanishes away from the mirror configuration, are judged too).
pub const RECIPROCITY_COSINES: [f64; 5] = [0.95, 0.75, 0.5, 0.3, 0.12];
/// Samples per outgoing direction by default.
pub const DEFAULT_SAMPLES: usize = 10_000;
/// Statistical tests per material and outgoing direction (distribution, the pdf's integral,
/// the mean weight, the delta lobes).
pub const TESTS_PER_DIRECTION: usize = 4;

/// One material to check.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialCase {
    /// Its label.
    pub name: String,
    /// The protocol's description (`{"type": "lambertian", "albedo": [...]}`).
    pub material: Value,
    /// Whether reciprocity is judged (claimed); otherwise it is measured and reported only.
    pub reciprocal: bool,
}

impl MaterialCase {
    /// A case from its description; reciprocity is claimed.
    pub fn new(name: &str, material: Value) -> Self {
        MaterialCase {
            name: name.to_string(),
            material,
            reciprocal: true,
        }
    }

    /// Its index of refraction, when it has one.
    pub fn ior(&self) -> Option<f64> {
        self.material.get("ior").and_then(Value::as_f64)
    }

    /// The outgoing directions' `cos theta_o`.
    pub fn cosines(&self) -> Vec<f64> {
        let mut c = OUTSIDE.to_vec();
        if self.ior().is_some() && self.material["type"] == "dielectric" {
            c.extend(INSIDE);
        }
        c
    }
}

/// The materials checked by default: the book's four and the course's four BRDF materials (a
/// candidate declines those it does not have).
pub fn default_materials() -> Vec<MaterialCase> {
    vec![
        MaterialCase::new(
            "lambertian",
            json!({"type": "lambertian", "albedo": [0.8, 0.6, 0.4]}),
        ),
        MaterialCase::new(
            "metal",
            json!({"type": "metal", "albedo": [0.9, 0.8, 0.7], "roughness": 0.3}),
        ),
        MaterialCase::new(
            "mirror",
            json!({"type": "metal", "albedo": [0.9, 0.9, 0.9], "roughness": 0.0}),
        ),
        MaterialCase::new(
            "dielectric",
            json!({"type": "dielectric", "albedo": [1.0, 1.0, 1.0], "ior": 1.5}),
        ),
        MaterialCase::new(
            "phong",
            json!({"type": "phong", "albedo": [0.7, 0.2, 0.4], "kd": 0.6, "ks": 0.9, "alpha": 0.8}),
        ),
        MaterialCase::new(
            "blinn",
            json!({"type": "blinn", "albedo": [0.7, 0.2, 0.4], "kd": 0.6, "ks": 0.9, "alpha": 8.0}),
        ),
        MaterialCase::new(
            "cook_torrance",
            json!({"type": "cook_torrance", "albedo": [1.0, 1.0, 1.0], "kd": 0.3, "ks": 0.7, "alpha": 0.3, "ior": 1.5}),
        ),
    ]
}

/// How the materials are checked.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MaterialOptions {
    /// Seeds the normals, the outgoing directions and the random numbers sent.
    pub seed: u64,
    /// Samples per outgoing direction.
    pub samples: usize,
    /// The run's false-alarm rate, shared by all its statistical tests.
    pub alpha: f64,
}

impl Default for MaterialOptions {
    fn default() -> Self {
        MaterialOptions {
            seed: 0,
            samples: DEFAULT_SAMPLES,
            alpha: crate::weekly::stats::DEFAULT_ALPHA,
        }
    }
}

/// The laws at one outgoing direction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DirectionResult {
    /// `cos theta_o` (negative: from below the surface).
    pub cos_theta: f64,
    /// The outgoing direction.
    pub wo: [f64; 3],
    /// Samples absorbed (no direction).
    pub absorbed: usize,
    /// Samples of a delta lobe.
    pub delta: usize,
    /// What each law found.
    pub laws: Vec<LawResult>,
}

/// The verdict on one material.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialResult {
    /// The case's label.
    pub name: String,
    /// Its description.
    pub material: Value,
    /// The normal used.
    pub normal: [f64; 3],
    /// Passed (no law failed; findings aside), failed, or not run.
    pub status: Status,
    /// Why it was not run, or what stopped it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<String>,
    /// Each outgoing direction's laws.
    pub directions: Vec<DirectionResult>,
    /// Reciprocity over pairs of directions.
    pub reciprocity: LawResult,
}

impl MaterialResult {
    /// Every law's result, the directions' and reciprocity.
    pub fn laws(&self) -> impl Iterator<Item = &LawResult> {
        self.directions
            .iter()
            .flat_map(|d| d.laws.iter())
            .chain(std::iter::once(&self.reciprocity))
    }
}

/// The checks of a candidate's materials.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialsReport {
    /// The candidate.
    pub candidate: String,
    /// How they were run.
    pub options: MaterialOptions,
    /// The false-alarm rate of each statistical test (Šidák's share of `alpha`).
    pub alpha_per_test: f64,
    /// The requests the candidate answers.
    pub ops: Vec<&'static str>,
    /// One result per material.
    pub materials: Vec<MaterialResult>,
    /// Why nothing was run, when nothing was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub not_run: Option<String>,
    /// Whose models decided the findings (`None`: none did; every breach is the candidate's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<String>,
}

impl MaterialsReport {
    /// Whether no law failed (findings about a model are not failures) and something ran.
    pub fn passed(&self) -> bool {
        self.ran() && self.materials.iter().all(|m| m.status != Status::Failed)
    }

    /// Whether any material was checked.
    pub fn ran(&self) -> bool {
        self.materials.iter().any(|m| m.status != Status::NotRun)
    }
}

/// Šidák's per-test rate for `tests` tests sharing the rate `alpha`:
/// `1 - (1 - alpha)^(1 / tests)`.
pub fn per_test(alpha: f64, tests: usize) -> f64 {
    -((-alpha).ln_1p() / tests.max(1) as f64).exp_m1()
}

/// Checks `cases` through `source`; `reference`, when given, decides which failures are
/// findings about the model.
pub fn check_materials(
    source: &mut dyn MaterialSource,
    mut reference: Option<&mut dyn MaterialSource>,
    cases: &[MaterialCase],
    options: MaterialOptions,
) -> MaterialsReport {
    let tests: usize = cases.iter().map(|c| c.cosines().len()).sum::<usize>() * TESTS_PER_DIRECTION;
    let alpha = per_test(options.alpha, tests);
    let ops: Vec<&'static str> = [Op::Sample, Op::Eval, Op::Pdf]
        .into_iter()
        .filter(|&op| source.supports(op))
        .map(Op::name)
        .collect();
    let mut report = MaterialsReport {
        candidate: source.label(),
        options,
        alpha_per_test: alpha,
        ops: ops.clone(),
        materials: Vec::new(),
        not_run: None,
        reference: reference.as_ref().map(|r| r.label()),
    };
    if !source.supports(Op::Sample) && !source.supports(Op::Eval) {
        report.not_run = Some(
            "the candidate's hello lists neither material_sample nor material_eval among its ops"
                .into(),
        );
        return report;
    }
    for (index, case) in cases.iter().enumerate() {
        let mut result = check_material(source, case, index as u64, options, alpha);
        if let Some(reference) = reference.as_deref_mut() {
            mark_findings(&mut result, reference, case, index as u64, options, alpha);
        }
        report.materials.push(result);
    }
    report
}

/// The normal and outgoing directions of case `index`.
pub(crate) fn geometry(case: &MaterialCase, index: u64, seed: u64) -> (Frame, Vec<(f64, DVec3)>) {
    let mut s = PixelSampler::new(seed ^ 0x6d61_7465_7269_616c, index);
    let n = super::models::sphere_point(s.next_f64(), s.next_f64());
    let frame = Frame::new(n);
    let dirs = case
        .cosines()
        .into_iter()
        .map(|c| {
            (
                c,
                frame.direction(c, 2.0 * std::f64::consts::PI * s.next_f64()),
            )
        })
        .collect();
    (frame, dirs)
}

fn check_material(
    source: &mut dyn MaterialSource,
    case: &MaterialCase,
    index: u64,
    options: MaterialOptions,
    alpha: f64,
) -> MaterialResult {
    let (frame, dirs) = geometry(case, index, options.seed);
    let mut result = MaterialResult {
        name: case.name.clone(),
        material: case.material.clone(),
        normal: frame.n.to_array(),
        status: Status::Passed,
        problem: None,
        directions: Vec::new(),
        reciprocity: LawResult::not_run(Law::Reciprocity, "not reached"),
    };
    let stop = |result: &mut MaterialResult, p: Problem| {
        result.status = match p {
            Problem::Declined(_) => Status::NotRun,
            _ => Status::Failed,
        };
        result.problem = Some(p.to_string());
    };
    for (k, &(cos, wo)) in dirs.iter().enumerate() {
        let stream = index * 16 + k as u64;
        match check_direction(source, case, &frame, wo, options, stream, alpha) {
            Ok(laws) => result.directions.push(laws_at(cos, wo, laws)),
            Err(p) => return with(result, stop, p),
        }
    }
    match reciprocity(source, case, &frame) {
        Ok(law) => result.reciprocity = law,
        Err(p) => return with(result, stop, p),
    }
    if result.laws().any(|l| l.status == Status::Failed) {
        result.status = Status::Failed;
    }
    result
}

fn with(
    mut result: MaterialResult,
    stop: impl Fn(&mut MaterialResult, Problem),
    p: Problem,
) -> MaterialResult {
    stop(&mut result, p);
    result
}

fn laws_at(cos: f64, wo: DVec3, laws: (Vec<LawResult>, usize, usize)) -> DirectionResult {
    DirectionResult {
        cos_theta: cos,
        wo: wo.to_array(),
        absorbed: laws.1,
        delta: laws.2,
        laws: laws.0,
    }
}

/// The random numbers of stream `stream`: four a sample.
fn numbers(seed: u64, stream: u64, count: usize) -> Vec<[f64; 4]> {
    let mut s = PixelSampler::new(seed, stream);
    (0..count)
        .map(|_| [s.next_f64(), s.next_f64(), s.next_f64(), s.next_f64()])
        .collect()
}

/// The laws at `wo`, with the counts of absorbed and delta samples.
fn check_direction(
    source: &mut dyn MaterialSource,
    case: &MaterialCase,
    frame: &Frame,
    wo: DVec3,
    options: MaterialOptions,
    stream: u64,
    alpha: f64,
) -> Result<(Vec<LawResult>, usize, usize), Problem> {
    let m = &case.material;
    let n = frame.n;
    let samples: Vec<Option<MaterialSample>> = if source.supports(Op::Sample) {
        source.sample(m, wo, n, &numbers(options.seed, stream, options.samples))?
    } else {
        Vec::new()
    };
    // Each sample's own direction (the normal in place of an absorbed or invalid one, whose
    // answers are not read), as sent: a pdf with a singular edge (the book's fuzz) changes by
    // more than the consistency tolerance under a renormalisation's last-bit change.
    let dirs: Vec<DVec3> = samples
        .iter()
        .map(|s| match s {
            Some(s) if super::laws::valid(s).is_ok() => s.wi,
            _ => n,
        })
        .collect();
    let f_at = match source.supports(Op::Eval) && !dirs.is_empty() {
        true => Some(source.eval(m, wo, n, &dirs)?),
        false => None,
    };
    let pdf_at = match source.supports(Op::Pdf) && !dirs.is_empty() {
        true => Some(source.pdf(m, wo, n, &dirs)?),
        false => None,
    };
    let (has_pdf, has_f) = (source.supports(Op::Pdf), source.supports(Op::Eval));
    let integrals = if has_pdf || has_f {
        let mut ints = integrals(source, m, frame, wo, options.samples, has_pdf, has_f, None)?;
        // Where the samples found what the integral missed (a lobe's edge between the nodes),
        // or the integral has what the samples never found, integrate again, finer.
        let suspects = suspect_cells(&samples, frame, &ints, has_pdf, has_f);
        if !suspects.is_empty() {
            let fine = integrals(
                source,
                m,
                frame,
                wo,
                options.samples,
                has_pdf,
                has_f,
                Some(&suspects),
            )?;
            for &c in &suspects {
                ints.value[c] = fine.value[c];
                ints.error[c] = fine.error[c];
            }
            ints.nodes += fine.nodes;
            ints.capped |= fine.capped;
        }
        Some(ints)
    } else {
        None
    };
    let observed = Observed {
        frame,
        wo,
        samples: &samples,
        f_at: f_at.as_deref(),
        pdf_at: pdf_at.as_deref(),
        integrals: integrals.as_ref(),
        has_pdf,
        has_f,
        ior: case.ior(),
    };
    let mut laws = Vec::new();
    if samples.is_empty() {
        for law in [
            Law::Samples,
            Law::Distribution,
            Law::Unbiased,
            Law::DeltaLaw,
        ] {
            laws.push(LawResult::not_run(law, "no material_sample"));
        }
        if has_f {
            laws.extend(energy_laws(&observed, alpha).into_iter().take(1));
        }
    } else {
        laws.extend(sample_laws(&observed));
        laws.extend(pdf_laws(&observed, alpha));
        laws.extend(energy_laws(&observed, alpha));
        laws.extend(delta_laws(&observed, alpha));
    }
    let absorbed = samples.iter().filter(|s| s.is_none()).count();
    let delta = samples.iter().flatten().filter(|s| s.delta).count();
    Ok((laws, absorbed, delta))
}

/// The cells where the samples and the integrals disagree by more than 3 standard deviations
/// of a count (the pdf), or by more than 5% (the weights' sum against `f |cos|`).
fn suspect_cells(
    samples: &[Option<MaterialSample>],
    frame: &Frame,
    ints: &CellIntegrals,
    has_pdf: bool,
    has_f: bool,
) -> Vec<usize> {
    let n = samples.len().max(1) as f64;
    let mut counts = vec![0.0; super::sphere::CELLS];
    let mut weights = vec![DVec3::ZERO; super::sphere::CELLS];
    for s in samples.iter().flatten() {
        if !s.delta && super::laws::valid(s).is_ok() {
            let c = super::sphere::cell_of(frame, s.wi);
            counts[c] += 1.0;
            weights[c] += s.weight / n;
        }
    }
    (0..super::sphere::CELLS)
        .filter(|&c| {
            let e = n * ints.value[c][0];
            let count_off = has_pdf && (counts[c] - e).abs() > 3.0 * (e.max(0.0) + 1.0).sqrt();
            let weight_off = has_f
                && counts[c] > 0.0
                && (0..3).any(|k| {
                    let (w, f) = (weights[c][k], ints.value[c][k + 1]);
                    (w - f).abs() > 0.05 * w.abs().max(f.abs()) + 1e-4
                });
            count_off || weight_off
        })
        .collect()
}

/// The cells' integrals of `[pdf, f |cos|]`, refined until each rectangle's estimate is within
/// a tenth of a sample's count (for the pdf, given `samples`) and 1e-3 relative (for `f`); with
/// `only`, those cells alone, refined deeper and to a fiftieth of a count.
#[allow(clippy::too_many_arguments)]
fn integrals(
    source: &mut dyn MaterialSource,
    m: &Value,
    frame: &Frame,
    wo: DVec3,
    samples: usize,
    has_pdf: bool,
    has_f: bool,
    only: Option<&[usize]>,
) -> Result<CellIntegrals, Problem> {
    let n = frame.n;
    let count = samples.max(1) as f64;
    let mut f = |dirs: &[DVec3]| -> Result<Vec<Values>, Problem> {
        let pdf = if has_pdf {
            source.pdf(m, wo, n, dirs)?
        } else {
            vec![0.0; dirs.len()]
        };
        let fs = if has_f {
            source.eval(m, wo, n, dirs)?
        } else {
            vec![DVec3::ZERO; dirs.len()]
        };
        Ok(dirs
            .iter()
            .zip(pdf.iter().zip(&fs))
            .map(|(d, (&p, f))| {
                let c = d.dot(n).abs();
                let clean = |x: f64| if x.is_finite() { x } else { 0.0 };
                [clean(p), clean(f.x * c), clean(f.y * c), clean(f.z * c)]
            })
            .collect())
    };
    let fine = if only.is_some() { 0.2 } else { 1.0 };
    let accept = move |a: &Values, b: &Values, area: f64| {
        let pdf_ok =
            (a[0] - b[0]).abs() <= fine * 0.1 * (count * b[0].abs()).max(1.0).sqrt() / count;
        let share = area / (4.0 * std::f64::consts::PI);
        let f_ok = (1..4).all(|c| (a[c] - b[c]).abs() <= fine * (1e-3 * b[c].abs() + 1e-5 * share));
        pdf_ok && f_ok
    };
    match only {
        None => integrate(frame, &mut f, &accept),
        Some(cells) => {
            integrate_cells(frame, cells, super::sphere::DEPTHS_SUSPECT, &mut f, &accept)
        }
    }
}

/// Reciprocity over every pair of the directions of [`RECIPROCITY_COSINES`] (two azimuths
/// each): `|f(a, b) - f(b, a)| <= 1e-6 max + 1e-9` per channel.
fn reciprocity(
    source: &mut dyn MaterialSource,
    case: &MaterialCase,
    frame: &Frame,
) -> Result<LawResult, Problem> {
    if !source.supports(Op::Eval) {
        return Ok(LawResult::not_run(Law::Reciprocity, "no material_eval"));
    }
    let dirs: Vec<DVec3> = RECIPROCITY_COSINES
        .iter()
        .enumerate()
        .flat_map(|(k, &c)| {
            let phi = 0.7 + 2.3 * k as f64;
            [
                frame.direction(c, phi),
                frame.direction(c, phi + 2.0),
                frame.direction(0.97 * c, phi + std::f64::consts::PI + 0.05),
            ]
        })
        .collect();
    let mut rows = Vec::with_capacity(dirs.len());
    for &a in &dirs {
        rows.push(source.eval(&case.material, a, frame.n, &dirs)?);
    }
    let (mut worst, mut pair) = (0.0f64, None);
    let mut broken = 0;
    let total = dirs.len() * (dirs.len() - 1) / 2;
    for (i, row_i) in rows.iter().enumerate() {
        for (j, row_j) in rows.iter().enumerate().skip(i + 1) {
            let (a, b) = (row_i[j], row_j[i]);
            let gap = (a - b).abs().max_element();
            let allowed = 1e-6 * a.abs().max(b.abs()).max_element() + 1e-9;
            if gap > allowed {
                broken += 1;
                let rel = gap / a.abs().max(b.abs()).max_element().max(1e-300);
                if rel > worst {
                    worst = rel;
                    pair = Some((i, j, a, b));
                }
            }
        }
    }
    let detail = match pair {
        None => format!("{total} pairs of directions"),
        Some((i, j, a, b)) => format!(
            "{broken} of {total} pairs differ; worst: f(d{i}, d{j}) = ({:.5}, {:.5}, {:.5}) but \
             f(d{j}, d{i}) = ({:.5}, {:.5}, {:.5}), cos theta {:.2} and {:.2}",
            a.x,
            a.y,
            a.z,
            b.x,
            b.y,
            b.z,
            frame.local(dirs[i]).z,
            frame.local(dirs[j]).z
        ),
    };
    Ok(match (broken, case.reciprocal) {
        (0, _) => LawResult {
            law: Law::Reciprocity,
            status: Status::Passed,
            detail,
            p_value: None,
        },
        (_, true) => LawResult {
            law: Law::Reciprocity,
            status: Status::Failed,
            detail,
            p_value: None,
        },
        (_, false) => LawResult::not_run(
            Law::Reciprocity,
            format!("not claimed by the material; measured: {detail}"),
        ),
    })
}

/// Re-checks `case` on `reference`; each law the candidate failed that the reference fails at
/// the same place becomes a finding about the model.
fn mark_findings(
    result: &mut MaterialResult,
    reference: &mut dyn MaterialSource,
    case: &MaterialCase,
    index: u64,
    options: MaterialOptions,
    alpha: f64,
) {
    if result.status != Status::Failed || result.problem.is_some() {
        return;
    }
    let model = check_material(reference, case, index, options, alpha);
    if model.status == Status::NotRun {
        return;
    }
    let model_fails = |k: Option<usize>, law: Law| match k {
        Some(k) => model.directions.get(k).is_some_and(|d| {
            d.laws
                .iter()
                .any(|l| l.law == law && l.status == Status::Failed)
        }),
        None => model.reciprocity.status == Status::Failed,
    };
    for (k, d) in result.directions.iter_mut().enumerate() {
        for l in &mut d.laws {
            if l.status == Status::Failed && model_fails(Some(k), l.law) {
                l.status = Status::Finding;
            }
        }
    }
    if result.reciprocity.status == Status::Failed && model_fails(None, Law::Reciprocity) {
        result.reciprocity.status = Status::Finding;
    }
    if !result.laws().any(|l| l.status == Status::Failed) {
        result.status = Status::Passed;
    }
}

/// Starts `command` and checks `cases` through the protocol's material requests; `reference`
/// is the family of rtoracle's models whose breaches are findings about the model (`None`: every
/// breach is the candidate's).
pub fn check_candidate_materials(
    command: crate::candidate::process::command::CandidateCommand,
    run: crate::candidate::process::options::RunOptions,
    cases: &[MaterialCase],
    options: MaterialOptions,
    reference: Option<super::models::Family>,
) -> Result<MaterialsReport, crate::candidate::process::error::HarnessError> {
    let label = command.label.clone();
    let timeout = run.timeout;
    let mut session = crate::candidate::process::session::Session::start(command, run)?;
    let mut runner = crate::weekly::runner::SessionRunner::new(&mut session);
    let mut source = super::source::ProtocolSource::new(&mut runner, label, timeout);
    let mut model = reference.map(super::models::ModelSource::new);
    Ok(check_materials(
        &mut source,
        model.as_mut().map(|m| m as &mut dyn MaterialSource),
        cases,
        options,
    ))
}
