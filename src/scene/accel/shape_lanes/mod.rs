//! Four rays at once through a [`ShapeSet`](crate::scene::accel::shape_set::ShapeSet): the rays
//! side by side ([`RayLanes`]), whether this processor runs the lanes queries ([`has_lanes`]:
//! an x86-64 with AVX2, asked once at run time), and the queries themselves in `avx2.rs`, the
//! one place this room names the processor (compiled on x86-64 only; elsewhere the renderer
//! traces one ray at a time, to the same film).

use glam::DVec3;

#[cfg(target_arch = "x86_64")]
mod avx2;

#[cfg(target_arch = "x86_64")]
pub(crate) use avx2::{between, splat};

/// How many rays [`ShapeSet::closest_lanes`] and [`ShapeSet::shadowed_lanes`] take at once:
/// four `f64` lanes, one AVX2 vector.
pub(crate) const LANES: usize = 4;

/// Up to [`LANES`] rays side by side (origins, directions and times), for the lanes queries. A
/// lane that is not `active` is ignored.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RayLanes {
    ox: [f64; LANES],
    oy: [f64; LANES],
    oz: [f64; LANES],
    dx: [f64; LANES],
    dy: [f64; LANES],
    dz: [f64; LANES],
    time: [f64; LANES],
    active: [u64; LANES],
}

impl RayLanes {
    /// Puts the ray from `origin` along `direction` at `time` in lane `k`.
    #[inline(always)]
    pub(crate) fn set(&mut self, k: usize, origin: DVec3, direction: DVec3, time: f64) {
        (self.ox[k], self.oy[k], self.oz[k]) = (origin.x, origin.y, origin.z);
        (self.dx[k], self.dy[k], self.dz[k]) = (direction.x, direction.y, direction.z);
        self.time[k] = time;
        self.active[k] = u64::MAX;
    }
}

/// Whether this processor runs the lanes queries ([`ShapeSet::closest_lanes`],
/// [`ShapeSet::shadowed_lanes`]): an x86-64 with AVX2. Elsewhere the renderer traces one ray at
/// a time, to the same film.
#[inline]
pub(crate) fn has_lanes() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// For the tests of the lanes: whether this processor has none (no AVX2), in which case it says
/// so on stderr, with `what` the test would have checked, so that `cargo test` shows the skip.
#[cfg(test)]
pub(crate) fn skipped_without_lanes(what: &str) -> bool {
    let skipped = !has_lanes();
    if skipped {
        eprintln!("skipped: this processor has no AVX2, so {what}");
    }
    skipped
}
