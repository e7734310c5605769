//! Checking a ray tracer written in Rust in-process, without the JSON protocol.
//!
//! Implement [`Candidate`] for a wrapper around your intersection code and call
//! [`check_candidate`] from a test:
//!
//! ```
//! use rtoracle::candidate::process::protocol::Answer;
//! use rtoracle::candidate::rust::Candidate;
//! use rtoracle::candidate::rust::check_candidate;
//! use rtoracle::oracle::vectors::{RaySpec, ShapeSpec};
//!
//! /// A tracer under test; here rtoracle's own reference stands in for it.
//! struct MyTracer;
//!
//! impl Candidate for MyTracer {
//!     fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer {
//!         use rtoracle::geometry::{Interval, Shape};
//!         let hit = shape
//!             .object()
//!             .intersect(&ray.ray(), Interval::new(interval[0], interval[1]));
//!         match hit {
//!             None => Answer::miss(),
//!             Some(h) => Answer::hit(h.t, h.point.into(), h.normal.into(), h.front_face),
//!         }
//!     }
//! }
//!
//! let suite = rtoracle::oracle::suite::default_suite(0);
//! let report = check_candidate(&mut MyTracer, &suite);
//! assert!(report.passed(), "{}", report.to_text(10));
//! assert_eq!(report.counts.failed, 0);
//! ```
//!
//! A panic inside `intersect` is caught and reported as an `error` for that case.

use std::panic::{AssertUnwindSafe, catch_unwind};

use super::judging::report::{CheckReport, RunInfo, build_report};
use super::process::outcome::Outcome;
use super::process::protocol::Answer;
use crate::geometry::{Interval, Shape};
use crate::oracle::vectors::{Case, RaySpec, ShapeKind, ShapeSpec};

/// An intersection implementation to check.
pub trait Candidate {
    /// A name for reports.
    fn name(&self) -> String {
        std::any::type_name::<Self>().to_string()
    }

    /// Whether the candidate implements `kind` (cases of other kinds are `not_run`).
    fn supports(&self, kind: ShapeKind) -> bool {
        let _ = kind;
        true
    }

    /// The answer for one ray and primitive, with `interval = [t_min, t_max]` (spheres take
    /// the open interval, quads and triangles the closed one, as the course does).
    fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer;
}

/// rtoracle's own reference tracer as a [`Candidate`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Reference;

impl Candidate for Reference {
    fn name(&self) -> String {
        "rtoracle reference".into()
    }

    fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer {
        Answer::from_record(
            shape
                .object()
                .intersect(&ray.ray(), Interval::new(interval[0], interval[1])),
        )
    }
}

/// The outcome of every case for an in-process candidate.
pub fn run_candidate<C: Candidate + ?Sized>(candidate: &mut C, cases: &[Case]) -> Vec<Outcome> {
    cases
        .iter()
        .map(|case| {
            if !candidate.supports(case.shape.kind()) {
                return Outcome::Unsupported {
                    reason: format!("the candidate does not support {}s", case.shape.kind()),
                };
            }
            let answer = catch_unwind(AssertUnwindSafe(|| {
                candidate.intersect(&case.shape, &case.ray, case.interval)
            }))
            .unwrap_or_else(|payload| {
                let message = payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "a panic".into());
                Answer::error("panic", message)
            });
            Outcome::Answered {
                answer,
                junk: Vec::new(),
            }
        })
        .collect()
}

/// Checks `candidate` against `cases` (e.g. [`crate::oracle::suite::default_suite`]) and returns the
/// report.
pub fn check_candidate<C: Candidate + ?Sized>(candidate: &mut C, cases: &[Case]) -> CheckReport {
    let outcomes = run_candidate(candidate, cases);
    build_report(
        cases,
        &outcomes,
        RunInfo {
            candidate: candidate.name(),
            ..RunInfo::default()
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    struct FarRoot;
    impl Candidate for FarRoot {
        fn supports(&self, kind: ShapeKind) -> bool {
            kind != ShapeKind::Triangle
        }
        fn intersect(&mut self, shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Answer {
            if let ShapeSpec::Quad { .. } = shape {
                panic!("quads are not done");
            }
            let mut a = Reference.intersect(shape, ray, interval);
            if let Some(t) = a.t.as_mut() {
                *t += 2.0; // the far root of the unit sphere from z = 5
            }
            a
        }
    }

    #[test]
    fn panics_wrong_answers_and_unsupported_shapes_are_reported_by_group() {
        let suite = crate::candidate::test_cases::basic_cases();
        let report = check_candidate(&mut FarRoot, &suite);
        assert_eq!(report.by_shape[&ShapeKind::Sphere].failed, 1);
        assert_eq!(report.by_shape[&ShapeKind::Sphere].passed, 1);
        assert_eq!(report.by_shape[&ShapeKind::Quad].errors, 2);
        assert_eq!(report.by_shape[&ShapeKind::Triangle].not_run, 1);
        assert!(
            report
                .failures
                .iter()
                .any(|f| f.message.contains("quads are not done"))
        );
        assert!(check_candidate(&mut Reference, &suite).passed());
    }
}
