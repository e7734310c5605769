//! A diagnosis of code failures: which known mistake explains a submission's failing vectors.
//!
//! When definite vectors of a shape group fail (wrong answers or raised errors; time-outs,
//! deaths, protocol errors and vectors not run are not evidence), every mistake of the
//! catalogue for that shape (the oracle's buggy transcriptions of the course's code,
//! [`mistakes::buggy`] and [`mistakes::buggy_extra`]) is replayed on the failing vectors and on
//! a deterministic sample of the passing ones (up to [`SAMPLE`], evenly spaced in suite order).
//!
//! A mistake *explains* a failing vector when the variant fails it the same way: the same
//! symptom (a hit for a miss, a miss for a hit, a wrong `t`, a wrong normal, a wrong
//! `front_face`, a raised error), and for a wrong `t` or normal the same wrong value (within
//! `1e-6` relative for `t`, `1e-4` per normal component). It is named when it explains at least
//! 95 % of the group's failures and passes all but 1 % of the sampled passing vectors; of
//! several, the one that explains most (then: disagrees least, then: comes first in the
//! catalogue). Nothing is named otherwise: the diagnosis never guesses. Other mistakes that fit
//! exactly as well (as many failures explained, as few passing vectors disagreeing) are named
//! with it ([`Diagnosis::also`]): a few failing vectors may not tell two mistakes apart (a
//! minimal case of radius -1 fails alike for a normal divided by `|r|` and one not divided at
//! all), and naming one of them alone would be a guess.
//!
//! The submission's answers are judged against its own triangle winding
//! ([`check::Winding`](crate::candidate::judging::check::Winding)); the variants wind as the reference does and are
//! judged against the reference's expectation, so a submission's winding never counts as a
//! symptom.

use serde::{Deserialize, Serialize};

use crate::candidate::judging::check::{NORMAL_TOL, Winding};
use crate::candidate::process::outcome::Outcome;
use crate::candidate::process::protocol::Answer;
use crate::oracle::mistakes::{self, VHit, Variant};
use crate::oracle::vectors::{Case, Class, Expect, ShapeKind};

/// How many passing vectors of a group are replayed at most.
pub const SAMPLE: usize = 200;

/// The mistake that explains a shape group's failures.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The shape group.
    pub shape: ShapeKind,
    /// The catalogue's id of the mistake (the variant's name, e.g. `"sphere-far-root-first"`).
    pub mistake_id: String,
    /// What the mistake is, as a phrase: `"taking the far root first"`.
    pub description: String,
    /// How many of the group's failures the mistake reproduces.
    pub explained: usize,
    /// How many failures the group has (wrong answers and raised errors).
    pub of: usize,
    /// The phrases of other mistakes that fit these failures exactly as well, in catalogue
    /// order (empty when the vectors single one out).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub also: Vec<String>,
}

impl Diagnosis {
    /// One sentence for a student: "your failures are exactly those of taking the far root
    /// first" (or "match those of ..., 11 of 12", when not all are explained).
    pub fn sentence(&self) -> String {
        let mut s = if self.explained == self.of {
            format!(
                "your {} failures are exactly those of {} ({} of {})",
                self.shape, self.description, self.explained, self.of
            )
        } else {
            format!(
                "your {} failures match those of {} ({} of {} explained)",
                self.shape, self.description, self.explained, self.of
            )
        };
        if !self.also.is_empty() {
            s.push_str(&format!(
                ", or equally of {}: these vectors cannot tell them apart",
                self.also.join(", or of ")
            ));
        }
        s
    }
}

/// How to correct each mistake of the catalogue, as an imperative a student can follow (the
/// course's names: `oc = origin - center`, `half_b`, `n = u x v`, `w = n / (n . n)`, `D`,
/// alpha and beta); `None` for a mistake without one written here.
pub fn fix(mistake_id: &str) -> Option<&'static str> {
    Some(match mistake_id {
        "sphere-far-root-first" => {
            "try the near root (-half_b - sqrt_disc) / a first, and the far one only when the near one is outside the interval"
        }
        "sphere-no-interval-check" => {
            "return None when neither root is inside the interval (cInterval.surrounds(root))"
        }
        "sphere-unnormalised-normal" => "divide (P - C) by the radius for the outward normal",
        "sphere-abs-radius-in-normal" => {
            "divide (P - C) by the radius itself, not by its absolute value"
        }
        "sphere-r-instead-of-r-squared" => "use c = |oc|^2 - r * r",
        "sphere-sign-error-in-b" => "use half_b = oc . d, with oc = origin - center",
        "sphere-disc-without-a" => "use the discriminant half_b^2 - a * c",
        "sphere-front-face-reversed" | "quad-front-face-reversed" => {
            "front_face is True when the ray's direction and the outward normal point opposite ways (d . n < 0)"
        }
        "sphere-sqrt-precedence" => {
            "write the root as (-half_b - sqrt_disc) / a, with the parentheses"
        }
        "sphere-normal-not-flipped" => "call set_face_normal(ray, outward_normal) on the hit",
        "quad-sign-error-in-alpha" => "use alpha = w . (p x v)",
        "quad-w-is-unit-normal" => "use w = n / (n . n) with n = u x v, not normalised",
        "quad-no-parallel-test" => {
            "return None when |n . d| is below a small epsilon (the ray is parallel to the plane)"
        }
        "quad-wrong-d" | "quad-d-from-u" => "use D = normal . Q, with the unit normal",
        "quad-no-interval-check" => "return None when t is outside the interval",
        "quad-u-v-swapped-in-beta" | "quad-beta-uses-v" => "use beta = w . (u x p)",
        "quad-unnormalised-normal" => "normalise n = u x v for the quad's normal",
        "quad-interior-upper-bounds-only" => {
            "check 0 <= alpha <= 1 and 0 <= beta <= 1 for the interior"
        }
        "triangle-missing-third-edge" => "also check alpha + beta <= 1",
        "triangle-no-parallel-test" => {
            "return None when the determinant is zero (the ray is parallel to the triangle)"
        }
        "triangle-absolute-epsilon" => {
            "scale the epsilon by the triangle's size (or test the determinant against 0)"
        }
        _ => return None,
    })
}

/// A description for each mistake of the catalogue, as the phrase after "those of".
pub fn describe(mistake_id: &str) -> String {
    let known = match mistake_id {
        "sphere-far-root-first" => "taking the far root first",
        "sphere-no-interval-check" => "not checking the root against the interval",
        "sphere-unnormalised-normal" => "not dividing the normal (P - C) by the radius",
        "sphere-abs-radius-in-normal" => {
            "dividing the normal by |r| (a negative radius must flip it)"
        }
        "sphere-r-instead-of-r-squared" => "using r instead of r^2 in c = |oc|^2 - r^2",
        "sphere-sign-error-in-b" => "a sign error in half_b",
        "sphere-disc-without-a" => "leaving a out of the discriminant (half_b^2 - c)",
        "sphere-front-face-reversed" => "reversing front_face",
        "sphere-sqrt-precedence" => {
            "writing -half_b - sqrt_disc / a (the division binds first) for the roots"
        }
        "sphere-normal-not-flipped" => {
            "not calling set_face_normal (the normal never faces the ray)"
        }
        "quad-sign-error-in-alpha" => "a sign error in alpha (v x p instead of p x v)",
        "quad-w-is-unit-normal" => "taking w as the unit normal instead of n / (n . n)",
        "quad-no-parallel-test" => "having no test for a ray parallel to the plane",
        "quad-wrong-d" => "computing D with the unnormalised normal (u x v) . Q",
        "quad-front-face-reversed" => "reversing front_face",
        "quad-no-interval-check" => "not checking t against the interval",
        "quad-u-v-swapped-in-beta" => "a sign error in beta (p x u instead of u x p)",
        "quad-beta-uses-v" => "using v instead of u in beta (v x p)",
        "quad-unnormalised-normal" => "not normalising the quad's normal u x v",
        "quad-d-from-u" => "computing D from u instead of Q (D = n . u)",
        "quad-interior-upper-bounds-only" => {
            "checking only alpha <= 1 and beta <= 1 (not >= 0) for the interior"
        }
        "triangle-missing-third-edge" => "not checking alpha + beta <= 1",
        "triangle-no-parallel-test" => "having no test for a ray parallel to the triangle",
        "triangle-absolute-epsilon" => {
            "an absolute epsilon on the unnormalised determinant (near_zero(det) misses small triangles)"
        }
        _ => "",
    };
    if known.is_empty() {
        mistake_id.replace('-', " ")
    } else {
        known.to_string()
    }
}

/// The catalogue of known mistakes.
pub fn catalogue() -> Vec<Variant> {
    let mut list = mistakes::buggy();
    list.extend(mistakes::buggy_extra());
    list
}

/// What is wrong with an answer, compared with an expectation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Symptom {
    Pass,
    Raised,
    HitForMiss,
    MissForHit,
    WrongT(f64),
    WrongNormal([f64; 3]),
    WrongFrontFace,
}

impl Symptom {
    fn same(self, other: Symptom) -> bool {
        match (self, other) {
            (Symptom::WrongT(a), Symptom::WrongT(b)) => {
                (a - b).abs() <= 1e-6 * a.abs().max(1.0) || (a.is_nan() && b.is_nan())
            }
            (Symptom::WrongNormal(a), Symptom::WrongNormal(b)) => {
                (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-4 || (a[k].is_nan() && b[k].is_nan()))
            }
            (a, b) => a == b,
        }
    }
}

/// The symptom of a hit (or miss, `None`) against a definite `expect`, by `check`'s rules.
fn symptom(expect: &Expect, hit: Option<VHit>) -> Symptom {
    match (expect.class, hit) {
        (Class::Miss, None) => Symptom::Pass,
        (Class::Miss, Some(_)) => Symptom::HitForMiss,
        (_, None) => Symptom::MissForHit,
        (_, Some(h)) => {
            if let Some(te) = expect.t {
                let tol = expect.t_tol.unwrap_or(1e-9 * te.abs().max(1.0));
                if (h.t - te).abs().is_nan() || (h.t - te).abs() > tol {
                    return Symptom::WrongT(h.t);
                }
            }
            if let Some(ne) = expect.normal {
                let bad = (0..3).any(|k| {
                    let off = (h.normal[k] - ne[k]).abs();
                    off.is_nan() || off > NORMAL_TOL
                });
                if bad {
                    return Symptom::WrongNormal(h.normal);
                }
            }
            if expect.front_face.is_some_and(|f| f != h.front_face) {
                return Symptom::WrongFrontFace;
            }
            Symptom::Pass
        }
    }
}

/// The submission's symptom on a case, or `None` when its outcome is no evidence (no answer, a
/// malformed one, stray output).
fn submission_symptom(expect: &Expect, outcome: &Outcome) -> Option<Symptom> {
    let Outcome::Answered { answer, junk } = outcome else {
        return None;
    };
    if !junk.is_empty() {
        return None;
    }
    if answer.error.is_some() {
        return Some(Symptom::Raised);
    }
    answer.validate().ok()?;
    Some(symptom(expect, as_hit(answer)))
}

fn as_hit(answer: &Answer) -> Option<VHit> {
    if answer.hit != Some(true) {
        return None;
    }
    Some(VHit {
        t: answer.t.unwrap_or(f64::NAN),
        normal: answer.normal.unwrap_or([f64::NAN; 3]),
        front_face: answer.front_face.unwrap_or(false),
    })
}

fn variant_symptom(v: &Variant, case: &Case) -> Symptom {
    match (v.run)(&case.shape, &case.ray, case.interval) {
        Err(_) => Symptom::Raised,
        Ok(hit) => symptom(&case.expect, hit),
    }
}

/// Diagnoses each shape group whose definite vectors fail: the known mistake that explains its
/// failures, if any (see the module docs). `winding` is the submission's triangle winding
/// ([`decide_winding`](crate::candidate::judging::check::decide_winding)). Deterministic: the same cases and
/// outcomes give the same diagnosis.
pub fn diagnose(cases: &[Case], outcomes: &[Outcome], winding: Option<Winding>) -> Vec<Diagnosis> {
    let catalogue = catalogue();
    let mut found = Vec::new();
    for kind in ShapeKind::ALL {
        let mut failing: Vec<(&Case, Symptom)> = Vec::new();
        let mut passing: Vec<&Case> = Vec::new();
        for (case, outcome) in cases.iter().zip(outcomes) {
            if case.shape.kind() != kind || !case.expect.class.is_definite() {
                continue;
            }
            let expect = match winding {
                Some(w) => w.expectation(case).expect.clone(),
                None => case.expect.clone(),
            };
            match submission_symptom(&expect, outcome) {
                Some(Symptom::Pass) => passing.push(case),
                Some(s) => failing.push((case, s)),
                None => {}
            }
        }
        if failing.is_empty() {
            continue;
        }
        let sample: Vec<&Case> = if passing.len() <= SAMPLE {
            passing
        } else {
            (0..SAMPLE)
                .map(|i| passing[i * passing.len() / SAMPLE])
                .collect()
        };
        let mut fits: Vec<(usize, usize, &Variant)> = Vec::new();
        for v in catalogue.iter().filter(|v| v.shape == kind) {
            let explained = failing
                .iter()
                .filter(|(case, s)| s.same(variant_symptom(v, case)))
                .count();
            if explained * 100 < failing.len() * 95 {
                continue;
            }
            let disagree = sample
                .iter()
                .filter(|case| variant_symptom(v, case) != Symptom::Pass)
                .count();
            if disagree * 100 > sample.len() {
                continue;
            }
            fits.push((explained, disagree, v));
        }
        // Most explained, then fewest disagreeing; the sort is stable, so catalogue order last.
        fits.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        if let Some(&(explained, disagree, v)) = fits.first() {
            let description = describe(v.name);
            let mut also: Vec<String> = Vec::new();
            for &(e, d, other) in &fits[1..] {
                let phrase = describe(other.name);
                if (e, d) == (explained, disagree)
                    && phrase != description
                    && !also.contains(&phrase)
                {
                    also.push(phrase);
                }
            }
            found.push(Diagnosis {
                shape: kind,
                mistake_id: v.name.to_string(),
                description,
                explained,
                of: failing.len(),
                also,
            });
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::suite::default_suite;

    fn outcome_of(v: &Variant, case: &Case) -> Outcome {
        let answer = match (v.run)(&case.shape, &case.ray, case.interval) {
            Err(e) => Answer::error(e, "division by zero"),
            Ok(None) => Answer::miss(),
            Ok(Some(h)) => Answer::hit(h.t, h.normal, h.normal, h.front_face),
        };
        Outcome::Answered {
            answer,
            junk: vec![],
        }
    }

    /// `v`'s answers on its shape, the reference's on the others.
    fn run(v: &Variant, cases: &[Case]) -> Vec<Outcome> {
        let honest = mistakes::honest();
        cases
            .iter()
            .map(|c| {
                if c.shape.kind() == v.shape {
                    outcome_of(v, c)
                } else {
                    let name = format!("{}-reference", c.shape.kind());
                    outcome_of(honest.iter().find(|h| h.name == name).unwrap(), c)
                }
            })
            .collect()
    }

    #[test]
    fn each_catalogued_mistake_is_named_for_its_own_answers_and_honest_ones_get_none() {
        let cases = default_suite(0);
        for v in catalogue() {
            let found = diagnose(&cases, &run(&v, &cases), None);
            assert_eq!(found.len(), 1, "{}: {found:?}", v.name);
            let d = &found[0];
            assert_eq!(d.shape, v.shape, "{}", v.name);
            // Two entries may answer alike on the suite (front_face reversed and a reversed
            // winding are one for triangles); the named one must then explain all of it too.
            assert_eq!(d.explained, d.of, "{}: {d:?}", v.name);
            if d.mistake_id != v.name {
                let named = catalogue()
                    .into_iter()
                    .find(|c| c.name == d.mistake_id)
                    .unwrap();
                let same = cases
                    .iter()
                    .filter(|c| c.shape.kind() == v.shape && c.expect.class.is_definite())
                    .all(|c| variant_symptom(&named, c).same(variant_symptom(&v, c)));
                assert!(same, "{} named {}", v.name, d.mistake_id);
            }
        }
        for v in mistakes::honest() {
            let found = diagnose(&cases, &run(&v, &cases), None);
            assert!(found.is_empty(), "{}: {found:?}", v.name);
        }
    }

    /// The minimal case `fuzz` shrinks a `|r|` normal to: radius -1, seen from its centre. There
    /// `(P - C) / |r|` and the undivided `P - C` are the same wrong normal, so the diagnosis names
    /// both; with the whole suite the two mistakes part, and only the real one is named.
    #[test]
    fn mistakes_the_vectors_cannot_tell_apart_are_named_together() {
        let line = r#"{"id":"shrunk","shape":{"type":"sphere","center":[0.0,0.0,0.0],"radius":-1.0},"ray":{"origin":[0.0,0.0,0.0],"direction":[0.0,-1.0,0.0]},"interval":[1e-6,1.7976931348623157e+308],"expect":{"class":"hit","tags":["negative-radius"],"t":1.0,"t_tol":1e-9,"point":[0.0,-1.0,0.0],"normal":[-0.0,1.0,-0.0],"front_face":true}}"#;
        let case: Case = serde_json::from_str(line).unwrap();
        let abs = catalogue()
            .into_iter()
            .find(|v| v.name == "sphere-abs-radius-in-normal")
            .unwrap();
        let cases = vec![case];
        let found = diagnose(&cases, &run(&abs, &cases), None);
        assert_eq!(found.len(), 1, "{found:?}");
        let d = &found[0];
        let phrases: Vec<&str> = std::iter::once(d.description.as_str())
            .chain(d.also.iter().map(String::as_str))
            .collect();
        for id in ["sphere-abs-radius-in-normal", "sphere-unnormalised-normal"] {
            assert!(phrases.contains(&describe(id).as_str()), "{id}: {d:?}");
        }
        assert!(
            d.sentence().contains("cannot tell them apart"),
            "{}",
            d.sentence()
        );
        let suite = default_suite(0);
        let found = diagnose(&suite, &run(&abs, &suite), None);
        assert_eq!(found[0].mistake_id, "sphere-abs-radius-in-normal");
        assert!(found[0].also.is_empty(), "{:?}", found[0]);
    }

    #[test]
    fn an_unexplained_failure_names_nothing_and_the_sentence_says_what_it_names() {
        let cases = default_suite(0);
        let reference = mistakes::honest()
            .into_iter()
            .find(|v| v.name == "sphere-reference")
            .unwrap();
        let mut outcomes = run(&reference, &cases);
        // One sphere hit answered with a t no mistake gives.
        let i = cases
            .iter()
            .position(|c| c.shape.kind() == ShapeKind::Sphere && c.expect.class == Class::Hit)
            .unwrap();
        if let Outcome::Answered { answer, .. } = &mut outcomes[i] {
            answer.t = Some(answer.t.unwrap() + 123.0);
        }
        assert!(diagnose(&cases, &outcomes, None).is_empty());
        let d = Diagnosis {
            shape: ShapeKind::Sphere,
            mistake_id: "sphere-far-root-first".into(),
            description: describe("sphere-far-root-first"),
            explained: 12,
            of: 12,
            also: vec![],
        };
        assert_eq!(
            d.sentence(),
            "your sphere failures are exactly those of taking the far root first (12 of 12)"
        );
    }
}
