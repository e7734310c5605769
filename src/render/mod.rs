//! The renderer: a seeded random stream per pixel, the integrators of the course's weeks 4 to 10
//! and of *Ray Tracing in One Weekend*, and rows rendered in parallel into a film whose bytes do
//! not depend on the number of threads.
//!
//! The reference is the files here, readable on their own: [`trace`] and [`radiance`] follow a
//! ray through the scene's objects one by one (`integrator.rs`), the materials scatter
//! (`scatter.rs`, `optics.rs`, `brdf.rs`), a pixel's samples come from its own seeded stream
//! (`sampler.rs`, `job.rs`) and [`render`] fills a film row by row (`renderer.rs`, `film.rs`).
//! The fast paths are in `fast/`, each giving the same bytes as the reference (the tests compare
//! them bit for bit): primary rays of a pinhole camera in packets, rays from one origin against
//! prepared shapes (`fast/fixed_origin/`), and, on x86_64, four rays at once in AVX2
//! (`fast/lanes.rs`; the processor is chosen in `fast/mod.rs`, the one place).

mod film;
mod sampler;
mod job;
mod optics;
mod brdf;
mod surface;
mod scatter;
mod integrator;
mod fast;
mod renderer;
#[cfg(test)]
mod stats;

pub use brdf::{blinn, cook_torrance, ggx, halfvector, phong, smith_g1};
pub use fast::vector_instructions;
pub use film::{Film, encode_book_png, encode_course_png};
pub use integrator::{occluded, radiance, sky, trace};
pub use job::PixelJitter;
pub use optics::{Onb, reflect, refract_or_reflect, refracted, schlick};
pub use renderer::{CourseJitter, RenderError, RenderOptions, render, samples_taken};
pub use sampler::PixelSampler;
pub use scatter::{cosine_about, normal_plus_unit};
pub use surface::sphere_uv;
