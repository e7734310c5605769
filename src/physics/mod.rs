//! Physics checks that need no golden, for authors of other renderers (`rtoracle physics`,
//! `docs/physics-checks.md`): a material's sampling, pdf, weights, energy and reciprocity
//! through the protocol's material requests, and whole renders of scenes whose answer is known
//! in closed form (furnaces) through its render requests.
//!
//! - `source`: the three material requests, sent to a candidate or answered by a model.
//! - `models`: rtoracle's materials (the book's, the course's) and the catalogued mistakes.
//! - `sphere`: the cells of the sphere of directions and adaptive integrals over them.
//! - `laws`: the laws at one outgoing direction, deterministic and statistical.
//! - `materials`: which materials and directions, the false-alarm rate, the findings about a
//!   model, the report.
//! - `report`: the report in words.
//! - `furnace`: scenes with a closed-form answer, rendered by a candidate (or the reference)
//!   and judged against their exact image with no golden.

mod furnace;
mod source;
mod models;
mod sphere;
mod laws;
mod materials;
mod report;

pub use furnace::{
    CandidateRenderer, DEFAULT_RENDERS, DEFAULT_SPP, Furnace, FurnaceOptions, FurnaceRenderer,
    FurnaceReport, FurnaceResult, ReferenceRenderer, check_furnaces, furnaces,
};
pub use laws::{Law, LawResult, Status};
pub use materials::{
    DEFAULT_SAMPLES, MaterialCase, MaterialOptions, MaterialsReport, check_candidate_materials,
    check_materials, default_materials,
};
pub use models::{Family, Mistake, Model, ModelSource};
pub use source::{MaterialSample, MaterialSource, Op, Problem, ProtocolSource};

#[cfg(test)]
mod tests;
