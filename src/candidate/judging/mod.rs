//! What a candidate's answer is worth, and what the failures say.
//!
//! - [`check`]: the verdict for one case (the decision, and for a hit `t`, the normal and
//!   `front_face` within the case's tolerances); [`watertight`]: the rule of the watertight
//!   groups (a ray through an edge shared by two shapes hits at least one).
//! - [`report`]: the [`CheckReport`](report::CheckReport) (serde) of a run and
//!   [`build_report`](report::build_report); [`report_text`]: its text; [`repro`]: expected
//!   answers in words and Python reproductions.
//! - [`diagnose`]: the known mistake (a buggy variant of the oracle) that explains the failures.

pub mod check;
pub mod diagnose;
pub mod repro;
pub mod watertight;
pub mod report;
pub mod report_text;
