use glam::DVec3;

/// A ray `origin + t * direction` at a moment `time`. The direction is never normalised (as in
/// the course).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (`t = 0`).
    pub origin: DVec3,
    /// The direction; its length scales `t`.
    pub direction: DVec3,
    /// The moment the ray samples, in `[0, 1)` (the course's week-10 `fTime`, 0 by default): a
    /// moving sphere is intersected where it is at that moment.
    pub time: f64,
}

impl Ray {
    /// A ray from `origin` along `direction` at time 0.
    #[inline]
    pub const fn new(origin: DVec3, direction: DVec3) -> Self {
        Self {
            origin,
            direction,
            time: 0.0,
        }
    }

    /// A ray from `origin` along `direction` at `time`.
    #[inline]
    pub const fn at_time(origin: DVec3, direction: DVec3, time: f64) -> Self {
        Self {
            origin,
            direction,
            time,
        }
    }

    /// The point at parameter `t`: `origin + t * direction`, rounded component-wise as
    /// `o + (t * d)` (no fused multiply-add, as Python computes it).
    #[inline(always)]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.direction * t
    }
}
