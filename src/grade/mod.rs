//! Grading: a rubric of points over groups of checks (intersection vectors per shape, images
//! against their reference), run on a submission in the course's layout, written as
//! `report.json`, Gradescope's `results.json`, `junit.xml` and a student's `feedback.md`; batches
//! with a gradebook; and a Gradescope autograder package.
//!
//! Grading sees the code under test only through [`CodeChecker`](checkers::CodeChecker) and the images only through
//! [`ImageChecker`](checkers::ImageChecker) ([`checkers`]). The code checker is [`CourseCodeChecker`](checkers::code::CourseCodeChecker) ([`checkers::code`]): the
//! `check` harness running the course adapter in the [sandbox](crate::sandbox); the image
//! checker is [`CompareImageChecker`](checkers::images::CompareImageChecker) ([`checkers::images`]), the noise-aware comparison against
//! the golden of a built-in scene (embedded) or of an instructor's scene file (the rubric's, or
//! rendered once and cached). Image groups are rendered by the grader from the submission's own
//! code by default ([`checkers::rendered`]): the code checker renders, the image checker judges
//! the render.
//!
//! Rooms, bottom floor first, and the single-submission path on top:
//!
//! - [`rubric`]: the [`Rubric`](rubric::Rubric) (built-in weeks in [`rubric::weeks`], TOML
//!   files) and partial credit ([`rubric::credit`]).
//! - [`checkers`]: the two interfaces and their real implementations: the course's code through
//!   the `check` harness ([`checkers::code`]), images against their reference
//!   ([`checkers::images`]), renders asked of the submission's own code ([`checkers::rendered`],
//!   [`checkers::noise_floor`]) and copied images ([`checkers::copies`]).
//! - [`score`]: what the checkers found made checks, points and messages, the weekly function
//!   checks' in [`score::weekly`].
//! - [`batch`]: a folder of submissions in parallel, the gradebook, one shard's entry
//!   ([`batch::entry`]), the merge of shards ([`batch::merge`]) and the pairs whose noise is
//!   shared ([`batch::shared_noise`]).
//! - [`autograder`]: the Gradescope package ([`autograder::pack`]).
//! - [`report`]: every format written from one [`GradeReport`](result::GradeReport).
//! - Here: [`intake`] of a submission's files, the run ([`grade`](run::grade)), the result model and
//!   [`grade_to_dir`](write::grade_to_dir).
//!
//! ```no_run
//! use rtoracle::grade::{checkers::images::CompareImageChecker, checkers::code::CourseCodeChecker, report::Format, rubric::Rubric, write::grade_to_dir};
//! let report = grade_to_dir(
//!     "submission".as_ref(),
//!     &Rubric::week04(),
//!     &CourseCodeChecker::default(),
//!     &CompareImageChecker::default(),
//!     "grade-report".as_ref(),
//!     &Format::ALL,
//! )?;
//! println!("{} / {}", report.score, report.max_score);
//! # Ok::<(), rtoracle::grade::result::GradeError>(())
//! ```

pub mod rubric;
pub mod checkers;
pub mod autograder;
pub mod intake;
pub mod result;
pub mod score;
pub mod report;
pub mod run;
pub mod write;
pub mod batch;
