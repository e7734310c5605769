//! A quad's hit for a packet of lanes: portable code the compiler vectorizes
//! ([`quad_hit_lanes`]), and on x86-64 with AVX2 every quad of a packet in one vector per
//! coordinate (`avx2.rs`), to the same bits; [`quads_hit`] chooses, the one place here that
//! names the processor.

use glam::DVec3;

use super::{Candidates, is_candidate};
use crate::geometry::{PARALLEL_EPSILON, Quad};
use crate::render::fast::packet::{Directions, Lanes, WIDTH};

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2;

/// Every candidate quad of `quads` (each with its plane's offset from the origin) against the
/// packet of directions `d` from `origin`: the AVX2 kernel where the processor has it, else
/// [`quad_hit_lanes`] quad by quad; the same bits either way.
#[inline(always)]
pub(super) fn quads_hit(
    quads: &[(Quad, f64)],
    candidates: Candidates,
    origin: DVec3,
    d: &Directions,
    min: f64,
    closest: &mut Lanes,
    index: &mut [u64; WIDTH],
) {
    #[cfg(target_arch = "x86_64")]
    if crate::scene::has_lanes() {
        // SAFETY: the processor has AVX2, just checked.
        unsafe { avx2::quads_hit_avx2(quads, candidates, origin, d, min, closest, index) };
        return;
    }
    for (me, (quad, offset)) in quads.iter().enumerate() {
        if !is_candidate(candidates, me) {
            continue;
        }
        quad_hit_lanes(quad, *offset, origin, d, min, closest, index, me as u64);
    }
}

/// `Quad::solve_from` for each lane's direction from `origin`, against each lane's interval
/// `[min, closest[k]]`: where it hits, `closest[k]` becomes its `t` and `index[k]` becomes `me`.
/// The same operations in the same order as the scalar path, so the same bits.
#[inline(always)]
// Lane loops index several arrays in step.
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
pub(super) fn quad_hit_lanes(
    quad: &Quad,
    offset: f64,
    origin: DVec3,
    d: &Directions,
    min: f64,
    closest: &mut Lanes,
    index: &mut [u64; WIDTH],
    me: u64,
) {
    let (n, q, u, v, w) = (quad.normal, quad.q, quad.u, quad.v, quad.w);
    // The plane first: when no lane meets it within its interval (behind the eye, or beyond
    // what a lane has already hit), the quad is skipped for the whole packet.
    let mut denoms = [0.0; WIDTH];
    let mut ts = [0.0; WIDTH];
    let mut inside = [0u64; WIDTH];
    for k in 0..WIDTH {
        denoms[k] = n.x * d.x[k] + n.y * d.y[k] + n.z * d.z[k];
        ts[k] = offset / denoms[k];
        inside[k] = if (min <= ts[k]) & (ts[k] <= closest[k]) {
            u64::MAX
        } else {
            0
        };
    }
    if inside.iter().fold(0, |any, &i| any | i) == 0 {
        return;
    }
    for k in 0..WIDTH {
        let (denom, t) = (denoms[k], ts[k]);
        // `ray.at(t) - q`.
        let px = (origin.x + d.x[k] * t) - q.x;
        let py = (origin.y + d.y[k] * t) - q.y;
        let pz = (origin.z + d.z[k] * t) - q.z;
        // `w . (planar x v)` and `w . (u x planar)`.
        let alpha =
            w.x * (py * v.z - v.y * pz) + w.y * (pz * v.x - v.z * px) + w.z * (px * v.y - v.x * py);
        let beta =
            w.x * (u.y * pz - py * u.z) + w.y * (u.z * px - pz * u.x) + w.z * (u.x * py - px * u.y);
        let hit = (denom.abs() >= PARALLEL_EPSILON)
            & t.is_finite()
            & (min <= t)
            & (t <= closest[k])
            & (0.0..=1.0).contains(&alpha)
            & (0.0..=1.0).contains(&beta);
        closest[k] = if hit { t } else { closest[k] };
        index[k] = if hit { me } else { index[k] };
    }
}
