use glam::DVec3;

/// A ray `origin + t * direction`. The direction is never normalised (as in the course).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts (`t = 0`).
    pub origin: DVec3,
    /// The direction; its length scales `t`.
    pub direction: DVec3,
}

impl Ray {
    /// A ray from `origin` along `direction`.
    #[inline]
    pub const fn new(origin: DVec3, direction: DVec3) -> Self {
        Self { origin, direction }
    }

    /// The point at parameter `t`: `origin + t * direction`, rounded component-wise as
    /// `o + (t * d)` (no fused multiply-add, as Python computes it).
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.direction * t
    }
}
