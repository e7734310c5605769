//! Function checks of the course's weeks 5 to 10: the protocol's function requests, the
//! expected answers from the reference, the statistical tests of the samplers, and the
//! diagnosis of each week's catalogued mistakes (`docs/weekly-checks.md`).
//!
//! - [`week`]: the weeks, and which one a submission folder is.
//! - [`runner`]: sending function requests ([`FunctionRunner`](runner::FunctionRunner), a candidate's session).
//! - [`expect`]: what a deterministic request must answer, and judging an answer.
//! - [`stats`]: chi-square and binomial tests at a stated false-alarm rate.
//! - [`samplers`]: each random function's invariants, cells and catalogued mistakes.
//! - [`samplers::mistakes`]: the same samplers (and mistakes) in Rust, to measure false alarms and power.
//! - [`checks`]: each week's functions, their cases, expected answers and mistakes.
//! - [`run`]: running a week's checks and judging them ([`WeekReport`](run::WeekReport)).
//! - [`departures`]: departures that keep the course's behaviour, named and not charged.
//! - [`report`]: the report in words.
//! - [`score`]: each week's groups of functions and their points.
//! - [`submission`]: a week's submission checked in one session (intersections and functions).

pub mod departures;
pub mod expect;
pub mod runner;
pub mod stats;
pub mod samplers;
pub mod week;
pub mod checks;
pub mod run;
pub mod score;
pub mod report;
pub mod submission;
