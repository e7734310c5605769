/// An interval of ray parameters `[min, max]` with the course's two membership tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// The lower end.
    pub min: f64,
    /// The upper end.
    pub max: f64,
}

impl Interval {
    /// The interval the course's camera uses: `(0.000001, f64::MAX)`.
    pub const CAMERA: Interval = Interval {
        min: 1e-6,
        max: f64::MAX,
    };

    /// An interval from `min` to `max`.
    #[inline]
    pub const fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// Closed membership: `min <= x <= max` (the course's `contains`, used by quads).
    #[inline]
    pub fn contains(&self, x: f64) -> bool {
        self.min <= x && x <= self.max
    }

    /// Open membership: `min < x < max` (the course's `surrounds`, used by spheres).
    #[inline]
    pub fn surrounds(&self, x: f64) -> bool {
        self.min < x && x < self.max
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contains_is_closed_and_surrounds_is_open() {
        let i = Interval::new(1.0, 2.0);
        assert!(i.contains(1.0) && i.contains(2.0));
        assert!(!i.surrounds(1.0) && !i.surrounds(2.0));
        assert!(i.surrounds(1.5) && i.contains(1.5));
        assert!(!i.contains(f64::NAN) && !i.surrounds(f64::NAN));
    }
}
