//! Fuzzing a candidate: random cases, classified by the oracle, and the failures shrunk.
//!
//! - [`generate`]: random cases and their classification through
//!   [`generate::oracle_expect`] (only definite cases are asked).
//! - [`fuzz`](mod@fuzz): the driver, a budget of cases run through a session.
//! - [`shrink`]: a failing case made smaller while it still fails.

pub mod generate;
pub mod shrink;
pub mod fuzz;
