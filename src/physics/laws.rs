//! The laws a material is checked against at one outgoing direction, each from the answers of
//! the three material requests, and what each found ([`LawResult`]).
//!
//! Deterministic laws (no false alarm): every sample is valid (a unit direction, finite
//! non-negative weights, a positive pdf); a sample's pdf is the one `material_pdf` gives; its
//! weight is `f |cos| / pdf`; a delta direction obeys the law of reflection or Snell's law; the
//! pdf integrates to at most 1; the albedo is at most 1 (both within the integration's error
//! estimate). Statistical laws, each at the per-test rate the caller gives: the directions
//! follow the candidate's own pdf (chi-square over the sphere's cells, merged to an expected
//! count of at least 5, with a last cell for the samples no continuous pdf covers); as many
//! continuous samples as the pdf's integral says (exact binomial); the mean weight is the
//! albedo (`f |cos|` integrated: a z test); each delta lobe is chosen as often as its reported
//! probability (exact binomial).

use glam::DVec3;
use serde::Serialize;

use super::source::MaterialSample;
use super::sphere::{CellIntegrals, Frame, cell_of};
use crate::render::reflect;
use crate::weekly::stats::{binomial, chi_square_sf};

/// A law of the checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum Law {
    /// Every sample is a unit direction with finite, non-negative weights and a positive pdf.
    Samples,
    /// A sample's pdf is what `material_pdf` says at its direction.
    PdfConsistent,
    /// A sample's weight is `f |cos| / pdf`.
    Weight,
    /// The directions follow the pdf (chi-square over the sphere).
    Distribution,
    /// The pdf integrates to at most 1, and to the share of continuous samples.
    PdfIntegral,
    /// The albedo `integral f |cos|` (plus the delta lobes' mean weight) is at most 1.
    Energy,
    /// The samples' mean weight is the albedo (the estimator is unbiased).
    Unbiased,
    /// `f(wo, wi) = f(wi, wo)`.
    Reciprocity,
    /// A delta direction is the mirror direction or Snell's refraction.
    DeltaLaw,
    /// Each delta lobe is chosen as often as its reported probability.
    DeltaProbability,
}

impl Law {
    /// The law's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Law::Samples => "samples",
            Law::PdfConsistent => "pdf_consistent",
            Law::Weight => "weight",
            Law::Distribution => "distribution",
            Law::PdfIntegral => "pdf_integral",
            Law::Energy => "energy",
            Law::Unbiased => "unbiased",
            Law::Reciprocity => "reciprocity",
            Law::DeltaLaw => "delta_law",
            Law::DeltaProbability => "delta_probability",
        }
    }

    /// What it says, in words.
    pub fn says(self) -> &'static str {
        match self {
            Law::Samples => "every sample a unit direction, weights finite and >= 0, pdf > 0",
            Law::PdfConsistent => "each sample's pdf equals material_pdf at its direction",
            Law::Weight => "each sample's weight equals f |cos| / pdf",
            Law::Distribution => "the directions follow the pdf (chi-square over the sphere)",
            Law::PdfIntegral => "the pdf integrates to at most 1, and to the continuous share",
            Law::Energy => "the albedo at wo is at most 1",
            Law::Unbiased => "the mean weight equals the integral of f |cos| (the albedo)",
            Law::Reciprocity => "f(wo, wi) = f(wi, wo)",
            Law::DeltaLaw => "a delta direction is the mirror one or Snell's refraction",
            Law::DeltaProbability => "each delta lobe chosen as often as its reported pdf",
        }
    }
}

/// A law's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// It holds.
    Passed,
    /// It is broken.
    Failed,
    /// It is broken, and so it is by rtoracle's transcription of the same model: a finding
    /// about the model, not the candidate's failure.
    Finding,
    /// Not judged (the request it needs is not answered, or nothing to judge).
    NotRun,
}

/// What one law found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LawResult {
    /// The law.
    pub law: Law,
    /// Its verdict.
    pub status: Status,
    /// What was measured, in words (the first offending sample, the statistic).
    pub detail: String,
    /// The p-value of a statistical law.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_value: Option<f64>,
}

impl LawResult {
    fn new(law: Law, status: Status, detail: impl Into<String>) -> Self {
        LawResult {
            law,
            status,
            detail: detail.into(),
            p_value: None,
        }
    }

    /// A law not judged, and why.
    pub fn not_run(law: Law, why: impl Into<String>) -> Self {
        Self::new(law, Status::NotRun, why)
    }

    fn judged(law: Law, ok: bool, detail: impl Into<String>) -> Self {
        Self::new(
            law,
            if ok { Status::Passed } else { Status::Failed },
            detail,
        )
    }

    fn tested(law: Law, p: f64, alpha: f64, detail: impl Into<String>) -> Self {
        LawResult {
            p_value: Some(p),
            ..Self::judged(law, p >= alpha, detail)
        }
    }
}

/// Everything known at one outgoing direction.
pub struct Observed<'a> {
    /// The surface's frame.
    pub frame: &'a Frame,
    /// The outgoing direction.
    pub wo: DVec3,
    /// The samples (`None`: absorbed).
    pub samples: &'a [Option<MaterialSample>],
    /// `material_eval` at each sample's direction (when answered).
    pub f_at: Option<&'a [DVec3]>,
    /// `material_pdf` at each sample's direction (when answered).
    pub pdf_at: Option<&'a [f64]>,
    /// The integrals over the cells: `[pdf, f_r |cos|, f_g |cos|, f_b |cos|]`, with `pdf` and `f`
    /// saying which were answered.
    pub integrals: Option<&'a CellIntegrals>,
    /// Whether the pdf was integrated.
    pub has_pdf: bool,
    /// Whether `f |cos|` was integrated.
    pub has_f: bool,
    /// The material's index of refraction, when it has one.
    pub ior: Option<f64>,
}

fn fmt(v: DVec3) -> String {
    format!("({:.6}, {:.6}, {:.6})", v.x, v.y, v.z)
}

fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

/// The validity of each sample: `Err` says what is wrong with the first bad one.
pub fn valid(s: &MaterialSample) -> Result<(), String> {
    if !s.wi.is_finite() || (s.wi.length() - 1.0).abs() > 1e-6 {
        return Err(format!("direction {} is not a unit vector", fmt(s.wi)));
    }
    if !s.weight.is_finite() || s.weight.min_element() < -1e-12 {
        return Err(format!(
            "weight {} is not finite and non-negative",
            fmt(s.weight)
        ));
    }
    match s.pdf {
        Some(p) if !p.is_finite() || p <= 0.0 => Err(format!("pdf {p:?} is not a positive number")),
        Some(p) if s.delta && p > 1.0 + 1e-9 => {
            Err(format!("a delta lobe's probability {p:?} is above 1"))
        }
        _ => Ok(()),
    }
}

/// The deterministic laws of the samples: validity, pdf consistency, weight.
pub fn sample_laws(o: &Observed) -> Vec<LawResult> {
    let mut out = Vec::new();
    let bad: Vec<(usize, String)> = o
        .samples
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.as_ref().and_then(|s| valid(s).err().map(|e| (k, e))))
        .collect();
    out.push(match bad.first() {
        None => LawResult::judged(Law::Samples, true, format!("{} samples", o.samples.len())),
        Some((k, why)) => LawResult::judged(
            Law::Samples,
            false,
            format!(
                "{} of {} samples invalid; sample {k}: {why}",
                bad.len(),
                o.samples.len()
            ),
        ),
    });
    let continuous = |k: usize| {
        o.samples[k]
            .as_ref()
            .filter(|s| !s.delta && valid(s).is_ok())
    };
    // pdf consistency.
    out.push(match o.pdf_at {
        None => LawResult::not_run(Law::PdfConsistent, "no material_pdf"),
        Some(pdfs) => {
            let mut judged = 0;
            let mut first = None;
            let mut wrong = 0;
            for (k, &p) in pdfs.iter().enumerate() {
                let Some(s) = continuous(k) else { continue };
                let Some(own) = s.pdf else { continue };
                judged += 1;
                if !close(own, p, 1e-6, 1e-12) {
                    wrong += 1;
                    first.get_or_insert(format!(
                        "sample {k} at {}: its pdf {own:?}, material_pdf {p:?}",
                        fmt(s.wi)
                    ));
                }
            }
            match first {
                _ if judged == 0 => LawResult::not_run(Law::PdfConsistent, "no sample gave a pdf"),
                None => LawResult::judged(Law::PdfConsistent, true, format!("{judged} samples")),
                Some(f) => LawResult::judged(
                    Law::PdfConsistent,
                    false,
                    format!("{wrong} of {judged} samples differ; {f}"),
                ),
            }
        }
    });
    out.push(weight_law(o, &continuous));
    out
}

fn weight_law<'s>(
    o: &'s Observed,
    continuous: &dyn Fn(usize) -> Option<&'s MaterialSample>,
) -> LawResult {
    let Some(fs) = o.f_at else {
        return LawResult::not_run(Law::Weight, "no material_eval");
    };
    let (mut judged, mut wrong, mut first) = (0, 0, None);
    for (k, &f) in fs.iter().enumerate() {
        let Some(s) = continuous(k) else { continue };
        let Some(pdf) = s.pdf.or(o.pdf_at.map(|p| p[k])).filter(|p| *p > 0.0) else {
            continue;
        };
        judged += 1;
        let expected = f * s.wi.dot(o.frame.n).abs() / pdf;
        let ok = (0..3).all(|c| close(s.weight[c], expected[c], 1e-6, 1e-9));
        if !ok {
            wrong += 1;
            first.get_or_insert(format!(
                "sample {k} at {}: weight {}, f |cos| / pdf {}",
                fmt(s.wi),
                fmt(s.weight),
                fmt(expected)
            ));
        }
    }
    match first {
        _ if judged == 0 => LawResult::not_run(Law::Weight, "no continuous sample with a pdf"),
        None => LawResult::judged(Law::Weight, true, format!("{judged} samples")),
        Some(f) => LawResult::judged(
            Law::Weight,
            false,
            format!("{wrong} of {judged} samples differ; {f}"),
        ),
    }
}

/// The counts of the samples in the sphere's cells (continuous, valid ones) and how many are
/// not there (absorbed, delta, invalid).
fn counts(o: &Observed) -> (Vec<u64>, u64) {
    let mut cells = vec![0u64; super::sphere::CELLS];
    let mut rest = 0;
    for s in o.samples {
        match s {
            Some(s) if !s.delta && valid(s).is_ok() => cells[cell_of(o.frame, s.wi)] += 1,
            _ => rest += 1,
        }
    }
    (cells, rest)
}

/// The distribution and the pdf's integral.
pub fn pdf_laws(o: &Observed, alpha: f64) -> Vec<LawResult> {
    let Some(ints) = o.integrals.filter(|_| o.has_pdf) else {
        return vec![
            LawResult::not_run(Law::Distribution, "no material_pdf"),
            LawResult::not_run(Law::PdfIntegral, "no material_pdf"),
        ];
    };
    let n = o.samples.len() as f64;
    let (cells, rest) = counts(o);
    let (integral, err) = ints.total(0);
    let continuous = n - rest as f64;
    // The integral: at most 1 within the integration's error.
    let allowance = (ERR_WIDTH * err).max(2e-3);
    let mut integral_law = if integral > 1.0 + allowance {
        LawResult::judged(
            Law::PdfIntegral,
            false,
            format!("the pdf integrates to {integral:.4} over the sphere (+- {err:.1e}), above 1"),
        )
    } else {
        // As many continuous samples as it says: the least-rejecting integral within its error.
        let share = (continuous / n).clamp(
            (integral - ERR_WIDTH * err).max(0.0),
            (integral + ERR_WIDTH * err).min(1.0),
        );
        let t = binomial(continuous as u64, n as u64, share.clamp(0.0, 1.0), alpha);
        LawResult::tested(
            Law::PdfIntegral,
            t.p_value,
            alpha,
            format!(
                "integral {integral:.4} (+- {err:.1e}); {} of {} samples continuous",
                continuous, n
            ),
        )
    };
    if integral_law.status == Status::Failed && integral_law.p_value.is_none() {
        integral_law.p_value = Some(0.0);
    }
    vec![chi_square_law(o, ints, &cells, rest, alpha), integral_law]
}

/// How many times its error estimate an integral may be off: the estimate is `|rule - refined
/// rule|`, which a smooth integrand's refined rule beats by far, but which a pdf with an
/// integrable singularity (the book's fuzz at the edge of its cone, converging as the square
/// root of the rectangle's size) only about halves at each level, leaving the refined rule up
/// to `1 / (sqrt 2 - 1) = 2.4` times the estimate away.
pub const ERR_WIDTH: f64 = 3.0;

/// Pearson's chi-square of the cell counts against `N` times each cell's pdf integral, with a
/// last cell for the rest (`N (1 - integral)`), cells merged in order to an expected count of
/// at least 5. Each term's variance is widened by the integration's error (`(N err)^2`), which
/// keeps the test conservative where the pdf is too sharp for the grid.
fn chi_square_law(
    o: &Observed,
    ints: &CellIntegrals,
    cells: &[u64],
    rest: u64,
    alpha: f64,
) -> LawResult {
    let n = o.samples.len() as f64;
    let (integral, err) = ints.total(0);
    let mut terms: Vec<(f64, f64, f64)> = cells
        .iter()
        .zip(ints.value.iter().zip(&ints.error))
        .map(|(&c, (v, e))| (c as f64, n * v[0].max(0.0), ERR_WIDTH * n * e[0]))
        .collect();
    terms.push((
        rest as f64,
        n * (1.0 - integral).max(0.0),
        ERR_WIDTH * n * err,
    ));
    let mut pooled: Vec<(f64, f64, f64)> = Vec::new();
    let mut acc = (0.0, 0.0, 0.0);
    for (obs, exp, e) in terms {
        acc = (acc.0 + obs, acc.1 + exp, acc.2 + e);
        if acc.1 >= crate::weekly::stats::MIN_EXPECTED {
            pooled.push(acc);
            acc = (0.0, 0.0, 0.0);
        }
    }
    if acc.0 > 0.0 || acc.1 > 0.0 {
        match pooled.last_mut() {
            Some(last) => *last = (last.0 + acc.0, last.1 + acc.1, last.2 + acc.2),
            None => pooled.push(acc),
        }
    }
    if pooled.len() < 2 {
        return LawResult::not_run(Law::Distribution, "fewer than two cells to compare");
    }
    let statistic: f64 = pooled
        .iter()
        .map(|&(obs, exp, e)| {
            let var = exp + e * e;
            if var > 0.0 {
                (obs - exp).powi(2) / var
            } else if obs > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .sum();
    let dof = (pooled.len() - 1) as f64;
    let p = chi_square_sf(statistic, dof);
    LawResult::tested(
        Law::Distribution,
        p,
        alpha,
        format!(
            "chi-square {statistic:.1} on {dof} degrees of freedom ({} cells after merging; \
             {} evaluations{})",
            pooled.len(),
            ints.nodes,
            if ints.capped {
                ", refinement capped"
            } else {
                ""
            }
        ),
    )
}

/// The two-sided normal tail of `z`.
fn normal_two_sided(z: f64) -> f64 {
    libm::erfc(z.abs() / std::f64::consts::SQRT_2).min(1.0)
}

/// The weights' per-sample contributions: of the continuous samples (else 0) and of the delta
/// ones (else 0), each channel's mean and standard error over all samples.
fn weight_means(o: &Observed, delta: bool) -> ([f64; 3], [f64; 3]) {
    let n = o.samples.len() as f64;
    let mut sum = [0.0; 3];
    let mut sq = [0.0; 3];
    for s in o.samples.iter().flatten() {
        if s.delta == delta && valid(s).is_ok() {
            for c in 0..3 {
                sum[c] += s.weight[c];
                sq[c] += s.weight[c] * s.weight[c];
            }
        }
    }
    let mean = sum.map(|s| s / n);
    let mut se = [0.0; 3];
    for c in 0..3 {
        let var = (sq[c] / n - mean[c] * mean[c]).max(0.0) * n / (n - 1.0).max(1.0);
        se[c] = (var / n).sqrt();
    }
    (mean, se)
}

/// Energy (the albedo at most 1) and the unbiased mean weight.
pub fn energy_laws(o: &Observed, alpha: f64) -> Vec<LawResult> {
    let (dmean, dse) = weight_means(o, true);
    let (cmean, cse) = weight_means(o, false);
    // One-sided normal quantile at alpha (for the delta lobes' part).
    let z = normal_quantile(alpha);
    let ints = o.integrals.filter(|_| o.has_f);
    let (albedo, allowance, how) = match ints {
        Some(ints) => {
            let mut a = [0.0; 3];
            let mut allow = [0.0; 3];
            for c in 0..3 {
                let (v, e) = ints.total(c + 1);
                a[c] = v + dmean[c];
                allow[c] = (ERR_WIDTH * e).max(2e-3) + z * dse[c];
            }
            (
                a,
                allow,
                "integral of f |cos| over the sphere plus the delta lobes' mean weight",
            )
        }
        None => {
            let mut a = [0.0; 3];
            let mut allow = [0.0; 3];
            for c in 0..3 {
                a[c] = cmean[c] + dmean[c];
                allow[c] = 1e-9 + z * (cse[c] + dse[c]);
            }
            (a, allow, "the samples' mean weight (no material_eval)")
        }
    };
    let worst = (0..3)
        .max_by(|&a, &b| (albedo[a] - allowance[a]).total_cmp(&(albedo[b] - allowance[b])))
        .unwrap_or(0);
    let ok = (0..3).all(|c| albedo[c] <= 1.0 + allowance[c]);
    let energy = LawResult::judged(
        Law::Energy,
        ok,
        format!(
            "albedo ({:.4}, {:.4}, {:.4}) by the {how}; channel {} allows up to {:.4}",
            albedo[0],
            albedo[1],
            albedo[2],
            ["R", "G", "B"][worst],
            1.0 + allowance[worst]
        ),
    );
    let unbiased = match ints {
        None => LawResult::not_run(Law::Unbiased, "no material_eval"),
        Some(ints) => {
            let mut p = 1.0f64;
            let mut text = Vec::new();
            for c in 0..3 {
                let (v, e) = ints.total(c + 1);
                let gap = ((cmean[c] - v).abs() - ERR_WIDTH * e - 1e-9).max(0.0);
                let pc = if gap == 0.0 {
                    1.0
                } else if cse[c] == 0.0 {
                    0.0
                } else {
                    normal_two_sided(gap / cse[c])
                };
                p = p.min((3.0 * pc).min(1.0));
                text.push(format!("{:.4} vs {:.4}", cmean[c], v));
            }
            LawResult::tested(
                Law::Unbiased,
                p,
                alpha,
                format!(
                    "mean weight against the integral of f |cos| (R G B): {}",
                    text.join(", ")
                ),
            )
        }
    };
    vec![energy, unbiased]
}

/// The upper `alpha` quantile of the standard normal (bisection on its tail).
pub fn normal_quantile(alpha: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 40.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 0.5 * libm::erfc(mid / std::f64::consts::SQRT_2) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The refracted direction of `wo` through the surface (Snell, facing the side `wo` is on),
/// `None` under total internal reflection.
pub fn snell(wo: DVec3, n: DVec3, ior: f64) -> Option<DVec3> {
    let outside = wo.dot(n) > 0.0;
    let (facing, ratio) = if outside { (n, 1.0 / ior) } else { (-n, ior) };
    let cos_i = wo.dot(facing);
    let sin2_t = ratio * ratio * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(ratio * (-wo) + (ratio * cos_i - cos_t) * facing)
}

/// The delta lobes: the law of their directions and how often each is chosen.
pub fn delta_laws(o: &Observed, alpha: f64) -> Vec<LawResult> {
    let deltas: Vec<(usize, &MaterialSample)> = o
        .samples
        .iter()
        .enumerate()
        .filter_map(|(k, s)| {
            s.as_ref()
                .filter(|s| s.delta && valid(s).is_ok())
                .map(|s| (k, s))
        })
        .collect();
    if deltas.is_empty() {
        return vec![
            LawResult::not_run(Law::DeltaLaw, "no delta sample"),
            LawResult::not_run(Law::DeltaProbability, "no delta sample"),
        ];
    }
    let mirror = reflect(-o.wo, o.frame.n);
    let refracted = o.ior.and_then(|ior| snell(o.wo, o.frame.n, ior));
    // 0: reflected, 1: refracted.
    let mut kinds: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    let mut broken = None;
    let mut wrong = 0;
    for &(k, s) in &deltas {
        let kind = if (s.wi - mirror).length() <= 1e-6 {
            0
        } else if refracted.is_some_and(|t| (s.wi - t).length() <= 1e-6) {
            1
        } else {
            wrong += 1;
            broken.get_or_insert_with(|| {
                let other = match (o.ior, refracted) {
                    (None, _) => " (the material has no ior: only reflection)".to_string(),
                    (Some(_), None) => {
                        " (total internal reflection: no refracted direction at this angle)"
                            .to_string()
                    }
                    (Some(_), Some(t)) => format!(" nor the refracted one {}", fmt(t)),
                };
                format!(
                    "sample {k}: direction {} is neither the mirror direction {}{other}",
                    fmt(s.wi),
                    fmt(mirror)
                )
            });
            continue;
        };
        if let Some(p) = s.pdf {
            kinds[kind].push(p);
        }
    }
    let law = match broken {
        None => LawResult::judged(
            Law::DeltaLaw,
            true,
            format!("{} delta samples", deltas.len()),
        ),
        Some(b) => LawResult::judged(
            Law::DeltaLaw,
            false,
            format!("{wrong} of {} delta samples off; {b}", deltas.len()),
        ),
    };
    vec![law, delta_probability(o.samples.len(), &kinds, alpha)]
}

fn delta_probability(n: usize, kinds: &[Vec<f64>; 2], alpha: f64) -> LawResult {
    let mut p_value = 1.0f64;
    let mut parts = Vec::new();
    for (name, ps) in ["reflected", "refracted"].iter().zip(kinds) {
        let Some(&p) = ps.first() else { continue };
        if ps.iter().any(|&q| !close(p, q, 1e-9, 1e-12)) {
            return LawResult::judged(
                Law::DeltaProbability,
                false,
                format!(
                    "the {name} lobe's reported probability changes from sample to sample at the same wo ({p:?} and others)"
                ),
            );
        }
        let t = binomial(ps.len() as u64, n as u64, p.clamp(0.0, 1.0), alpha);
        p_value = p_value.min((2.0 * t.p_value).min(1.0));
        parts.push(format!("{name} {} of {n} (reported {p:.4})", ps.len()));
    }
    if parts.is_empty() {
        return LawResult::not_run(Law::DeltaProbability, "no delta sample gave a pdf");
    }
    LawResult::tested(Law::DeltaProbability, p_value, alpha, parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Snell at 45 degrees into glass: `sin t = sin 45 / 1.5`; from inside at 60 degrees
    /// (`1.5 sin 60 > 1`) there is none.
    #[test]
    fn snell_matches_the_law() {
        let n = DVec3::Z;
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let t = snell(DVec3::new(s, 0.0, s), n, 1.5).unwrap();
        assert!((t.x + s / 1.5).abs() < 1e-15, "{t}");
        assert!((t.length() - 1.0).abs() < 1e-15);
        assert!(t.z < 0.0);
        let inside = DVec3::new(60f64.to_radians().sin(), 0.0, -0.5);
        assert!(snell(inside, n, 1.5).is_none());
    }

    /// Table value: the upper 1e-6 quantile of the normal is 4.7534.
    #[test]
    fn normal_quantile_matches_the_table() {
        assert!((normal_quantile(1e-6) - 4.7534).abs() < 1e-3);
        assert!((normal_quantile(0.025) - 1.95996).abs() < 1e-4);
    }
}
