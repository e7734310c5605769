//! Outward-rounded interval arithmetic ([`Iv`]).
//!
//! Without control of the rounding mode, each operation rounds to nearest and then widens the
//! result by one unit in the last place on each side, so the interval holds both the exact real
//! result for any inputs in the operand intervals and the `f64` result of the same operation.

use std::cmp::Ordering;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The next `f64` above `x` (NaN and `+inf` unchanged).
pub fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

/// The next `f64` below `x`.
pub fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// A closed interval `[lo, hi]` of reals; `[-inf, inf]` when nothing is known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Iv {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

impl Iv {
    /// Everything.
    pub const ENTIRE: Iv = Iv {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// The single value `x` (NaN gives [`Iv::ENTIRE`]).
    pub fn point(x: f64) -> Self {
        if x.is_nan() {
            Self::ENTIRE
        } else {
            Iv { lo: x, hi: x }
        }
    }

    /// The interval from rounded-to-nearest bounds, widened by one ulp each side.
    fn out(lo: f64, hi: f64) -> Self {
        Iv {
            lo: if lo.is_nan() {
                f64::NEG_INFINITY
            } else {
                next_down(lo)
            },
            hi: if hi.is_nan() {
                f64::INFINITY
            } else {
                next_up(hi)
            },
        }
    }

    /// The sign of every member, or `None` when the interval holds both signs.
    pub fn sign(&self) -> Option<Ordering> {
        if self.lo > 0.0 {
            Some(Ordering::Greater)
        } else if self.hi < 0.0 {
            Some(Ordering::Less)
        } else if self.lo == 0.0 && self.hi == 0.0 {
            Some(Ordering::Equal)
        } else {
            None
        }
    }

    /// The midpoint.
    pub fn mid(&self) -> f64 {
        self.lo * 0.5 + self.hi * 0.5
    }

    /// The radius `(hi - lo) / 2`, rounded up.
    pub fn rad(&self) -> f64 {
        next_up(self.hi * 0.5 - self.lo * 0.5)
    }

    /// Whether both ends are finite.
    pub fn is_finite(&self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The interval with the same midpoint and `k` times the radius. A half-infinite interval
    /// (an overflow at one end, such as `f64::MAX - t`) moves its finite end out by `k` units of
    /// `2^-50` of its magnitude.
    pub fn widen(&self, k: f64) -> Self {
        if !self.is_finite() {
            let slack = |x: f64| x.abs() * 2f64.powi(-50) * k;
            return match (self.lo.is_finite(), self.hi.is_finite()) {
                (true, false) => Iv::out(self.lo - slack(self.lo), f64::INFINITY),
                (false, true) => Iv::out(f64::NEG_INFINITY, self.hi + slack(self.hi)),
                _ => Self::ENTIRE,
            };
        }
        let (m, r) = (self.mid(), self.rad() * k);
        Iv::out(m - r, m + r)
    }

    /// Whether `x` lies in the interval.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// The square root of the non-negative part.
    pub fn sqrt(&self) -> Self {
        let lo = self.lo.max(0.0).sqrt();
        let hi = self.hi.max(0.0).sqrt();
        let r = Iv::out(lo, hi);
        Iv {
            lo: r.lo.max(0.0),
            hi: r.hi,
        }
    }

    /// `|self|`.
    pub fn abs(&self) -> Self {
        if self.lo >= 0.0 {
            *self
        } else if self.hi <= 0.0 {
            -*self
        } else {
            Iv {
                lo: 0.0,
                hi: self.hi.max(-self.lo),
            }
        }
    }
}

impl Add for Iv {
    type Output = Iv;
    fn add(self, o: Iv) -> Iv {
        Iv::out(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Iv {
    type Output = Iv;
    fn sub(self, o: Iv) -> Iv {
        Iv::out(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Neg for Iv {
    type Output = Iv;
    fn neg(self) -> Iv {
        Iv {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Mul for Iv {
    type Output = Iv;
    fn mul(self, o: Iv) -> Iv {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        if p.iter().any(|x| x.is_nan()) {
            return Iv::ENTIRE;
        }
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Iv::out(lo, hi)
    }
}

impl Div for Iv {
    type Output = Iv;
    fn div(self, o: Iv) -> Iv {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Iv::ENTIRE;
        }
        let p = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        if p.iter().any(|x| x.is_nan()) {
            return Iv::ENTIRE;
        }
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Iv::out(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_enclose_the_exact_result_and_the_rounded_one() {
        let third = Iv::point(1.0) / Iv::point(3.0);
        assert!(third.contains(1.0 / 3.0) && third.lo < third.hi);
        let s = Iv::point(0.1) + Iv::point(0.2);
        assert!(s.contains(0.1 + 0.2) && s.contains(0.3));
        assert_eq!((Iv::point(2.0) - Iv::point(2.0)).sign(), None);
        assert_eq!(Iv::point(0.0).sign(), Some(Ordering::Equal));
        assert_eq!((Iv::point(1.0) / Iv { lo: -1.0, hi: 1.0 }), Iv::ENTIRE);
        let inf = Iv::point(f64::INFINITY) - Iv::point(f64::INFINITY);
        assert_eq!(inf, Iv::ENTIRE);
    }

    #[test]
    fn next_up_and_down_step_one_ulp() {
        assert_eq!(next_up(1.0), 1.0 + f64::EPSILON);
        assert_eq!(next_down(1.0), 1.0 - f64::EPSILON / 2.0);
        assert_eq!(next_up(-0.0), f64::from_bits(1));
        assert_eq!(next_down(f64::from_bits(1)), 0.0);
        assert_eq!(next_up(f64::MAX), f64::INFINITY);
    }
}
