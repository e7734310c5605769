//! The intersection oracle: the language-agnostic vector format (more to come: exact decisions,
//! error bands, edge-case generators).

pub mod suite;
pub mod vectors;

pub use suite::default_suite;
