//! rtoracle: geometry core (work in progress)
#![warn(missing_docs)]
pub mod geometry;
pub mod image_io;
pub mod render;
pub mod scene;
