//! Grading: a rubric of points over groups of checks (intersection vectors per shape, images
//! against their reference), run on a submission in the course's layout, written as
//! `report.json`, Gradescope's `results.json`, `junit.xml` and a student's `feedback.md`; batches
//! with a gradebook; and a Gradescope autograder package.
//!
//! Grading sees the code under test only through [`CodeChecker`] and the images only through
//! [`ImageChecker`] ([`inputs`]). The code checker is [`CourseCodeChecker`] ([`checkers`]): the
//! `check` harness running the course adapter in the [sandbox](crate::sandbox); the image
//! checker is [`CompareImageChecker`](crate::compare::CompareImageChecker), the noise-aware
//! comparison against the embedded goldens.
//!
//! ```no_run
//! use rtoracle::compare::CompareImageChecker;
//! use rtoracle::grade::{CourseCodeChecker, Format, Rubric, grade_to_dir};
//! let report = grade_to_dir(
//!     "submission".as_ref(),
//!     &Rubric::week04(),
//!     &CourseCodeChecker::default(),
//!     &CompareImageChecker::default(),
//!     "grade-report".as_ref(),
//!     &Format::ALL,
//! )?;
//! println!("{} / {}", report.score, report.max_score);
//! # Ok::<(), rtoracle::grade::GradeError>(())
//! ```

pub mod autograder;
pub mod batch;
pub mod bench;
pub mod checkers;
pub mod inputs;
pub mod intake;
pub mod report;
pub mod rubric;
mod run;

pub use checkers::CourseCodeChecker;
pub use inputs::{
    CodeChecker, CodeOutcome, FailureKind, FailureSummary, GroupCounts, ImageChecker, ImageOutcome,
    ImageVerdict,
};
pub use rubric::{Group, GroupKind, Rubric, RubricError, Visibility};
pub use run::{
    CheckResult, CheckStatus, CodeRun, FAILURES_SHOWN, Format, GradeError, GradeReport,
    ImageResult, Reproducibility, grade, grade_to_dir, round2, smallest_failure, write_public,
    write_reports,
};
