//! The reference's own outputs: a scene rendered (`render`), the built-in scenes (`scenes`), their
//! goldens (`golden`), the intersection vectors (`vectors`) and one vector's answer explained
//! (`explain`).

pub mod render;
pub mod scenes;
pub mod golden;
pub mod vectors;
pub mod explain;
