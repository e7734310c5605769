//! The renderer: a seeded random stream per pixel, the integrators of the course's weeks 4 to 10
//! and of *Ray Tracing in One Weekend*, and rows rendered in parallel into a film whose bytes do
//! not depend on the number of threads.

mod brdf;
mod film;
mod fixed_origin;
mod integrator;
mod job;
#[cfg(target_arch = "x86_64")]
mod lanes;
mod optics;
mod packet;
mod pinhole;
mod renderer;
mod sampler;
mod scatter;
#[cfg(test)]
mod stats;
mod surface;

pub use brdf::{blinn, cook_torrance, ggx, halfvector, phong, smith_g1};
pub use film::{Film, encode_book_png, encode_course_png};
pub use integrator::{occluded, radiance, sky, trace};
pub use job::PixelJitter;
pub use optics::{Onb, reflect, refract_or_reflect, refracted, schlick};
pub use renderer::{
    CourseJitter, RenderError, RenderOptions, render, samples_taken, vector_instructions,
};
pub use sampler::PixelSampler;
pub use scatter::{cosine_about, normal_plus_unit};
pub use surface::sphere_uv;
