//! The renderer: a seeded random stream per pixel, the course's integrator, and rows rendered in
//! parallel into a film whose bytes do not depend on the number of threads.

mod film;
mod fixed_origin;
mod integrator;
mod packet;
mod pinhole;
mod renderer;
mod sampler;

pub use film::{Film, encode_course_png};
pub use integrator::{radiance, sky};
pub use renderer::{PixelJitter, RenderError, RenderOptions, render, vector_instructions};
pub use sampler::PixelSampler;
