//! The rule that turns a code group's answers into its share of the points, so that no answer
//! given without computing the intersection earns anything.
//!
//! Most vectors of a suite are misses, so points in proportion to the vectors passed paid a
//! submission that always answers "miss" a third (spheres) to two thirds (quads) of a group.
//! The rule scores the two kinds of vector apart and multiplies the two credits:
//!
//! - **hit credit** `H`: over the vectors where the ray hits, 1 for the right answer (the right
//!   `t`, normal and `front_face`); for a hit at the right `t` otherwise, [`T_CREDIT`] plus
//!   [`ORIENTATION_CREDIT`] for each of the normal and `front_face` that is right (the
//!   intersection was found; its orientation is the rest of the work); 0 for anything else;
//! - **miss credit** `M`: the share of the vectors where the ray misses answered with a miss;
//! - the group earns `H x M` of its points (an all-or-nothing group earns them when every
//!   vector is right).
//!
//! Every answer that ignores the ray earns nothing: "always a miss" has `H = 0`, a constant hit
//! or the ray's origin has `M = 0` (and no `t` right), a coin toss has `H` near 0. A mistake
//! costs in proportion to the vectors of its kind it gets wrong, and a second mistake costs
//! more. A kind with no vector counts as 1 (a vector file of misses alone cannot tell a constant
//! answer from a right one). Vectors that raised, crashed, timed out or were not run earn
//! nothing. The rule was chosen among others by measuring them (`docs/grading.md`).

use serde::{Deserialize, Serialize};

use crate::candidate::judging::check::{NORMAL_TOL, Verdict, Winding};
use crate::candidate::process::outcome::Outcome;
use crate::oracle::vectors::{Case, Class};

/// The credit of a hit at the right `t`, before its normal and `front_face`.
pub const T_CREDIT: f64 = 0.5;

/// The credit of each of the normal and the `front_face` of a hit at the right `t`.
pub const ORIENTATION_CREDIT: f64 = 0.25;

/// How one scored vector was answered, as the rule sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// The right answer.
    Right,
    /// A hit at the right `t` with a wrong normal, a wrong `front_face`, or both (only for
    /// vectors that hit): which of the two are right.
    RightT {
        /// The normal is right.
        normal: bool,
        /// `front_face` is right.
        front_face: bool,
    },
    /// Anything else: a wrong answer, an error, a crash, a time-out, not run.
    Wrong,
}

/// A group's scored vectors by what they expect and how they were answered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClassTally {
    /// Vectors where the ray hits.
    pub hits: usize,
    /// Of those, answered right.
    pub hits_right: usize,
    /// Answered with the right `t` and `front_face` but a wrong normal.
    pub hits_wrong_normal: usize,
    /// Answered with the right `t` and normal but a wrong `front_face`.
    pub hits_wrong_front_face: usize,
    /// Answered with the right `t` but a wrong normal and a wrong `front_face`.
    pub hits_t_only: usize,
    /// Vectors where the ray misses.
    pub misses: usize,
    /// Of those, answered with a miss.
    pub misses_right: usize,
}

impl ClassTally {
    /// Counts one vector that expects a hit (`hit`) or a miss, answered as `mark`.
    pub fn record(&mut self, hit: bool, mark: Mark) {
        if hit {
            self.hits += 1;
            match mark {
                Mark::Right => self.hits_right += 1,
                Mark::RightT {
                    normal: false,
                    front_face: true,
                } => self.hits_wrong_normal += 1,
                Mark::RightT {
                    normal: true,
                    front_face: false,
                } => self.hits_wrong_front_face += 1,
                Mark::RightT { .. } => self.hits_t_only += 1,
                Mark::Wrong => {}
            }
        } else {
            self.misses += 1;
            if mark == Mark::Right {
                self.misses_right += 1;
            }
        }
    }

    /// The hit credit earned, summed over the vectors that hit.
    fn hit_points(&self) -> f64 {
        self.hits_right as f64
            + (T_CREDIT + ORIENTATION_CREDIT)
                * (self.hits_wrong_normal + self.hits_wrong_front_face) as f64
            + T_CREDIT * self.hits_t_only as f64
    }

    /// The sum of two tallies (a group that scores its ambiguous vectors too).
    pub fn plus(self, o: ClassTally) -> ClassTally {
        ClassTally {
            hits: self.hits + o.hits,
            hits_right: self.hits_right + o.hits_right,
            hits_wrong_normal: self.hits_wrong_normal + o.hits_wrong_normal,
            hits_wrong_front_face: self.hits_wrong_front_face + o.hits_wrong_front_face,
            hits_t_only: self.hits_t_only + o.hits_t_only,
            misses: self.misses + o.misses,
            misses_right: self.misses_right + o.misses_right,
        }
    }

    /// Whether nothing was counted.
    pub fn is_empty(&self) -> bool {
        self.hits + self.misses == 0
    }
}

/// A code check's credit as `report.json` shows it: the components and the share of the points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Credit {
    /// The rule's name: [`RULE`].
    pub rule: &'static str,
    /// The vectors counted.
    #[serde(flatten)]
    pub tally: ClassTally,
    /// `H`: `(hits_right + 0.75 (hits_wrong_normal + hits_wrong_front_face) + 0.5 hits_t_only)
    /// / hits` (1 when there is no hit vector).
    pub hit_credit: f64,
    /// `M`: `misses_right / misses` (1 when there is no miss vector).
    pub miss_credit: f64,
    /// The share of the group's points earned: `H x M`, or for an all-or-nothing group 1 or 0.
    pub fraction: f64,
}

/// The rule's name in `report.json`.
pub const RULE: &str = "hit_credit_times_miss_credit";

/// A check's [`Credit`] read back (a merge of shards reads the reports they wrote): its rule
/// must be [`RULE`].
pub(crate) fn read_credit<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<Credit>, D::Error> {
    #[derive(Deserialize)]
    struct Owned {
        rule: String,
        #[serde(flatten)]
        tally: ClassTally,
        hit_credit: f64,
        miss_credit: f64,
        fraction: f64,
    }
    let Some(o) = Option::<Owned>::deserialize(d)? else {
        return Ok(None);
    };
    if o.rule != RULE {
        return Err(serde::de::Error::custom(format!(
            "unknown scoring rule {:?}",
            o.rule
        )));
    }
    Ok(Some(Credit {
        rule: RULE,
        tally: o.tally,
        hit_credit: o.hit_credit,
        miss_credit: o.miss_credit,
        fraction: o.fraction,
    }))
}

/// The credit of `tally`; `all_or_nothing` groups earn 1 only when every vector is right.
pub fn credit(tally: ClassTally, all_or_nothing: bool) -> Credit {
    let ratio = |part: f64, whole: usize| {
        if whole == 0 { 1.0 } else { part / whole as f64 }
    };
    let hit_credit = ratio(tally.hit_points(), tally.hits);
    let miss_credit = ratio(tally.misses_right as f64, tally.misses);
    let perfect = tally.hits_right == tally.hits && tally.misses_right == tally.misses;
    let fraction = if perfect {
        1.0
    } else if all_or_nothing {
        0.0
    } else {
        hit_credit * miss_credit
    };
    Credit {
        rule: RULE,
        tally,
        hit_credit,
        miss_credit,
        fraction,
    }
}

/// Whether `case` counts as a vector that hits: a definite hit, or an ambiguous one whose
/// exact answer is a hit (the vector records a `t`).
pub fn expects_hit(case: &Case) -> bool {
    match case.expect.class {
        Class::Hit => true,
        Class::Ambiguous => case.expect.t.is_some(),
        Class::Miss | Class::Any => false,
    }
}

/// The answer of `outcome` when it is a hit delivered cleanly (no stray output, no error).
fn clean_hit(outcome: &Outcome) -> Option<&crate::candidate::process::protocol::Answer> {
    let Outcome::Answered { answer, junk } = outcome else {
        return None;
    };
    (junk.is_empty() && answer.error.is_none() && answer.hit == Some(true)).then_some(answer)
}

/// Whether `outcome` is a clean hit at the `t` that `case` expects (within its tolerance): the
/// part of a wrong answer that still earns [`T_CREDIT`].
pub fn right_t(case: &Case, outcome: &Outcome) -> bool {
    let Some(answer) = clean_hit(outcome) else {
        return false;
    };
    match (answer.t, case.expect.t) {
        (Some(t), Some(te)) => {
            let tol = case.expect.t_tol.unwrap_or(1e-9 * te.abs().max(1.0));
            // Written so that a NaN t is not right.
            (t - te).abs() <= tol
        }
        _ => false,
    }
}

/// How the rule counts a vector judged `verdict`: a pass, or a failure that may still be a hit
/// at the right `t` (triangles' `front_face` judged by the submission's `winding`, as the
/// verdict was).
pub fn mark(case: &Case, outcome: &Outcome, verdict: &Verdict, winding: Option<Winding>) -> Mark {
    match verdict {
        Verdict::Pass => Mark::Right,
        Verdict::Fail { .. } if expects_hit(case) && right_t(case, outcome) => {
            let case = match winding {
                Some(w) => w.expectation(case),
                None => std::borrow::Cow::Borrowed(case),
            };
            let Some(answer) = clean_hit(outcome) else {
                return Mark::Wrong;
            };
            let expect = &case.expect;
            let normal = match (expect.normal, answer.normal) {
                (Some(ne), Some(n)) => {
                    let off = (0..3)
                        .map(|k| (n[k] - ne[k]).abs())
                        .fold(0.0f64, |a, b| if b.is_nan() { f64::NAN } else { a.max(b) });
                    // Written so that a NaN component is not right.
                    off <= expect.normal_tol.unwrap_or(NORMAL_TOL)
                }
                (None, _) => true,
                (Some(_), None) => false,
            };
            let front_face = match (expect.front_face, answer.front_face) {
                (Some(f), Some(g)) => f == g,
                (None, _) => true,
                (Some(_), None) => false,
            };
            Mark::RightT { normal, front_face }
        }
        _ => Mark::Wrong,
    }
}

#[cfg(test)]
#[path = "credit_tests.rs"]
mod tests;
