//! The renderer's fast paths: the same bytes as the reference, sooner.
//!
//! - `pinhole`: a pinhole camera's primary rays, traced in packets of rays that share an origin.
//! - `packet`: the packet of rays and its hit records.
//! - `fixed_origin`: rays from one origin against shapes prepared for it (spheres, quads,
//!   triangles, and the cone that bounds a packet).
//! - `lanes` (x86_64 only, chosen here): four rays at once in AVX2 intrinsics where the processor
//!   has them, the portable lanes elsewhere. The reference's renderer asks [`lanes_row`] and
//!   [`vector_instructions`], so that it names no processor itself.

#[cfg(target_arch = "x86_64")]
pub(super) mod lanes;
pub(super) mod packet;
pub(super) mod fixed_origin;
pub(super) mod pinhole;

use glam::DVec3;

use super::job::{Job, Spread};
use crate::scene::World;

/// Renders row `j` of `job` with four rays at once where this processor has AVX2 and the world
/// takes lanes (`lanes`), and says whether it did; elsewhere it does nothing and the caller
/// traces the row one ray at a time, to the same film.
#[inline(always)]
pub(super) fn lanes_row<const VARIANCE: bool, const JITTER: u8>(
    job: &Job<'_, World>,
    j: usize,
    means: &mut [DVec3],
    variances: &mut [Spread],
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if let Some(set) = lanes::takes_lanes(job.tracer) {
        // SAFETY: `takes_lanes` checked that the processor has AVX2.
        unsafe { lanes::row::<VARIANCE, JITTER>(job, set, j, means, variances) };
        return true;
    }
    // Where there are no lanes to ask (another processor), the arguments go unused.
    let _ = (job, j, means, variances);
    false
}

/// The vector instructions the renderer's fast path runs with on this processor: `"AVX2"` (four
/// `f64` lanes per instruction) where it has them, else the target's baseline (`"SSE2"` on
/// x86-64, two lanes). The film is the same either way.
pub fn vector_instructions() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return "AVX2";
    }
    if cfg!(target_arch = "x86_64") {
        "SSE2"
    } else if cfg!(target_arch = "aarch64") {
        "NEON"
    } else {
        "the target's baseline"
    }
}
