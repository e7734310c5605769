//! The intersection oracle: exact decisions ([`exact`]), the error bands of the course's naive
//! formulas ([`band`]), the classification of a case ([`classify`](mod@classify)), edge-case generators
//! ([`generate`]), watertight groups ([`watertight`]), the default suite ([`suite`]), explanations ([`explain`]), honest and buggy
//! transcriptions of the course's code ([`mistakes`]), fuzzing entry points ([`fuzzing`]), the
//! benchmark ([`crate::bench::oracle`]) and the language-agnostic vector format ([`vectors`]).

pub mod band;
pub mod profile;
pub mod vectors;
pub mod exact;
pub mod tags;
pub mod classify;
pub mod explain;
pub mod generate;
pub mod fuzzing;
pub mod mistakes;
pub mod watertight;
pub mod suite;
