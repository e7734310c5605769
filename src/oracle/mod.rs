//! The intersection oracle: exact decisions ([`exact`]), the error bands of the course's naive
//! formulas ([`band`]), the classification of a case ([`classify`](mod@classify)), edge-case generators
//! ([`generate`]), watertight groups ([`watertight`]), the default suite ([`suite`]), explanations ([`explain`]), honest and buggy
//! transcriptions of the course's code ([`mistakes`]), fuzzing entry points ([`fuzzing`]), the
//! benchmark ([`crate::bench::oracle`]) and the language-agnostic vector format ([`vectors`]).

pub mod band;
pub mod classify;
pub mod exact;
pub mod explain;
pub mod fuzzing;
pub mod generate;
pub mod mistakes;
pub mod profile;
pub mod suite;
pub mod tags;
pub mod vectors;
pub mod watertight;

pub use classify::{analyse, analyse_with, classify, classify_tagged, classify_with};
pub use profile::{Judging, Precision, Profile};
pub use suite::{default_suite, default_suite_with};
