//! Grading: a submission or a batch of them (`grade`) and the Gradescope package (`autograder`).

pub mod grade;
pub mod autograder;
