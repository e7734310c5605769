//! Grading: a rubric of points over groups of checks (intersection vectors per shape, images
//! against their reference), run on a submission in the course's layout, written as
//! `report.json`, Gradescope's `results.json`, `junit.xml` and a student's `feedback.md`; batches
//! with a gradebook; and a Gradescope autograder package.
//!
//! Grading sees the code under test only through [`CodeChecker`] and the images only through
//! [`ImageChecker`] ([`inputs`]). The code checker is [`CourseCodeChecker`] ([`checkers`]): the
//! `check` harness running the course adapter in the [sandbox](crate::sandbox); the image
//! checker is [`CompareImageChecker`] ([`image_checker`]), the noise-aware comparison against
//! the golden of a built-in scene (embedded) or of an instructor's scene file (the rubric's, or
//! rendered once and cached). Image groups are rendered by the grader from the submission's own
//! code by default ([`render`](mod@render)): the code checker renders, the image checker judges
//! the render.
//!
//! ```no_run
//! use rtoracle::grade::{CompareImageChecker, CourseCodeChecker, Format, Rubric, grade_to_dir};
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
pub mod batch_copies;
pub mod batch_entry;
pub mod bench;
pub mod checkers;
pub mod copies;
pub mod credit;
#[cfg(test)]
pub(crate) mod fakes;
mod functions_score;
pub mod image_checker;
pub mod inputs;
pub mod intake;
pub mod merge;
pub mod noise_floor;
pub mod pack;
pub mod render;
pub mod report;
mod result;
pub mod rubric;
mod run;
mod score;
pub mod week_rubrics;
mod write;

pub use checkers::CourseCodeChecker;
pub use functions_score::{UNSCORED_ID, function_checks};
pub use image_checker::CompareImageChecker;
pub use inputs::{
    CodeChecker, CodeOutcome, FailureKind, FailureSummary, FunctionsOutcome, GroupCounts,
    ImageChecker, ImageOutcome, ImageVerdict, SceneFile, SceneSource,
};
pub use report::{Format, write_reports};
pub use result::{
    CheckResult, CheckStatus, CodeRun, FAILURES_SHOWN, GradeError, GradeReport, ImageResult,
    Reproducibility, round2, smallest_failure,
};
pub use rubric::{GoldenFile, Group, GroupKind, ImageSource, Rubric, RubricError, Visibility};
pub use run::grade;
pub use write::{REPORT_FOLDER, grade_to_dir};
