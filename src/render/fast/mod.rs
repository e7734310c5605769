//! The renderer's fast paths: the same bytes as the reference, sooner.
//!
//! - `pinhole`: a pinhole camera's primary rays, traced in packets of rays that share an origin.
//! - `packet`: the packet of rays and its hit records.
//! - `fixed_origin`: rays from one origin against shapes prepared for it (spheres, quads,
//!   triangles, and the cone that bounds a packet).
//! - `lanes` (x86_64 only, chosen here): four rays at once in AVX2 intrinsics where the processor
//!   has them, the portable lanes elsewhere.

#[cfg(target_arch = "x86_64")]
pub(super) mod lanes;
pub(super) mod packet;
pub(super) mod fixed_origin;
pub(super) mod pinhole;
