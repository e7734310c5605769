//! Checking another implementation: its intersections against the vectors (`check`), fuzzed
//! (`fuzz`), its materials' physics (`physics`) and its images against a golden or each other
//! (`compare`).

pub mod check;
pub mod fuzz;
pub mod physics;
pub mod compare;
