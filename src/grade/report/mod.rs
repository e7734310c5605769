//! The report formats, all written from one [`GradeReport`](super::GradeReport).

pub mod gradescope;
pub mod json;
pub mod junit;
pub mod markdown;
