//! Primary rays in packets: [`WIDTH`] samples of one pixel side by side, one array per
//! coordinate, so the fixed-origin fast path decides each object for all of them in
//! straight-line code that the compiler turns into vector instructions (two `f64` per SSE2
//! register, four per AVX register), without a branch per ray.
//!
//! Each lane does the scalar path's operations in the scalar path's order (vector lanes round
//! as scalars do and nothing is fused), so each lane's answer is the scalar answer, bit for bit.

use glam::DVec3;

/// Rays per packet.
pub(crate) const WIDTH: usize = 4;

/// One `f64` per lane.
pub(crate) type Lanes = [f64; WIDTH];

/// The object index of a lane whose ray hits nothing.
pub(crate) const NO_HIT: u64 = u64::MAX;

/// The directions of a packet's rays, one array per coordinate.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Directions {
    /// The x coordinates.
    pub(crate) x: Lanes,
    /// The y coordinates.
    pub(crate) y: Lanes,
    /// The z coordinates.
    pub(crate) z: Lanes,
}

impl Directions {
    /// Lane `k`'s direction.
    #[inline(always)]
    pub(crate) fn lane(&self, k: usize) -> DVec3 {
        DVec3::new(self.x[k], self.y[k], self.z[k])
    }

    /// Sets lane `k`'s direction.
    #[cfg(test)]
    pub(crate) fn set(&mut self, k: usize, d: DVec3) {
        (self.x[k], self.y[k], self.z[k]) = (d.x, d.y, d.z);
    }
}
