//! Exact dyadic rationals ([`Dyadic`]): every finite `f64` is `m 2^e`, and sums and products of
//! dyadics stay dyadic, so they are evaluated exactly with a big integer and a shared binary
//! exponent (no gcd, no division). Quotients and square roots are approximated to a stated
//! number of bits, or rounded once to the nearest `f64`.

use std::cmp::Ordering;

use num_bigint::{BigInt, Sign};
use num_traits::{Signed, ToPrimitive, Zero};

/// An exact dyadic rational `m * 2^e`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Dyadic {
    /// The integer mantissa.
    pub m: BigInt,
    /// The binary exponent.
    pub e: i64,
}

impl Dyadic {
    /// Zero.
    pub fn zero() -> Self {
        Self {
            m: BigInt::zero(),
            e: 0,
        }
    }

    /// The exact value of a finite `x`, or `None` for NaN and infinities.
    pub fn from_f64(x: f64) -> Option<Self> {
        if !x.is_finite() {
            return None;
        }
        if x == 0.0 {
            return Some(Self::zero());
        }
        let bits = x.to_bits();
        let negative = bits >> 63 == 1;
        let exp = ((bits >> 52) & 0x7ff) as i64;
        let frac = bits & ((1u64 << 52) - 1);
        let (mut mant, mut e) = if exp == 0 {
            (frac, -1074)
        } else {
            (frac | (1u64 << 52), exp - 1075)
        };
        let tz = mant.trailing_zeros();
        mant >>= tz;
        e += tz as i64;
        let m = BigInt::from(mant);
        Some(Self {
            m: if negative { -m } else { m },
            e,
        })
    }

    /// The sign.
    pub fn signum(&self) -> Ordering {
        match self.m.sign() {
            Sign::Minus => Ordering::Less,
            Sign::NoSign => Ordering::Equal,
            Sign::Plus => Ordering::Greater,
        }
    }

    /// Whether the value is zero.
    pub fn is_zero(&self) -> bool {
        self.m.is_zero()
    }

    /// `self + o`.
    pub fn add(&self, o: &Self) -> Self {
        if self.m.is_zero() {
            return o.clone();
        }
        if o.m.is_zero() {
            return self.clone();
        }
        let e = self.e.min(o.e);
        let m = (&self.m << (self.e - e) as usize) + (&o.m << (o.e - e) as usize);
        Self { m, e }
    }

    /// `-self`.
    pub fn neg(&self) -> Self {
        Self {
            m: -&self.m,
            e: self.e,
        }
    }

    /// `self - o`.
    pub fn sub(&self, o: &Self) -> Self {
        self.add(&o.neg())
    }

    /// `self * o`.
    pub fn mul(&self, o: &Self) -> Self {
        if self.m.is_zero() || o.m.is_zero() {
            return Self::zero();
        }
        Self {
            m: &self.m * &o.m,
            e: self.e + o.e,
        }
    }

    /// Compares two values exactly.
    pub fn cmp_value(&self, o: &Self) -> Ordering {
        self.sub(o).signum()
    }

    /// The value rounded to the nearest `f64` (ties to even; overflow gives an infinity;
    /// subnormal results may be off by one unit).
    pub fn to_f64(&self) -> f64 {
        round_parts(&self.m, self.e, false)
    }

    /// `self / o` rounded to the nearest `f64` (`o` must be non-zero).
    pub fn div_to_f64(&self, o: &Self) -> f64 {
        if self.m.is_zero() {
            return 0.0;
        }
        let (q, e, inexact) = big_quotient(&self.m, self.e, &o.m, o.e, 70);
        round_parts(&q, e, inexact)
    }

    /// `self / o` as a dyadic truncated to about `bits` significant bits (`o` non-zero).
    pub fn div_approx(&self, o: &Self, bits: u64) -> Self {
        if self.m.is_zero() {
            return Self::zero();
        }
        let (q, e, _) = big_quotient(&self.m, self.e, &o.m, o.e, bits);
        Self { m: q, e }
    }

    /// `sqrt(self)` truncated to about `bits` significant bits (`self >= 0`).
    pub fn sqrt_approx(&self, bits: u64) -> Self {
        if self.m.sign() != Sign::Plus {
            return Self::zero();
        }
        let mut m = self.m.clone();
        let mut e = self.e;
        let want = 2 * bits + 2;
        let have = m.bits();
        let mut shift = want.saturating_sub(have) as i64;
        if (e - shift) % 2 != 0 {
            shift += 1;
        }
        m <<= shift as usize;
        e -= shift;
        Self {
            m: m.sqrt(),
            e: e / 2,
        }
    }
}

/// `(n 2^ne) / (d 2^de)` as an integer quotient `q 2^e` with at least `bits` significant bits,
/// and whether the division left a remainder.
fn big_quotient(n: &BigInt, ne: i64, d: &BigInt, de: i64, bits: u64) -> (BigInt, i64, bool) {
    let shift = (bits + d.bits()).saturating_sub(n.bits()) as i64 + 2;
    let num = n << shift as usize;
    let q = &num / d;
    let inexact = !(&q * d - &num).is_zero();
    (q, ne - de - shift, inexact)
}

/// Rounds `m 2^e` (plus a sticky bit for a discarded remainder) to the nearest `f64`.
fn round_parts(m: &BigInt, e: i64, sticky: bool) -> f64 {
    if m.is_zero() {
        return 0.0;
    }
    let negative = m.is_negative();
    let mag = m.abs();
    let bits = mag.bits();
    let (top, e) = if bits > 62 {
        let s = bits - 62;
        let top = &mag >> s as usize;
        let lost = sticky || (&top << s as usize) != mag;
        let top = top.to_u64().expect("62 bits fit") | u64::from(lost);
        (top, e + s as i64)
    } else {
        let top = mag.to_u64().expect("62 bits fit");
        // A remainder below the last bit: shift in one guard bit set.
        if sticky {
            ((top << 2) | 1, e - 2)
        } else {
            (top, e)
        }
    };
    // `top < 2^63` converts with one correct rounding; the sticky bit breaks ties.
    let x = top as f64;
    let e = e.clamp(-4000, 4000) as i32;
    let y = libm::scalbn(x, e);
    if negative { -y } else { y }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dy(x: f64) -> Dyadic {
        Dyadic::from_f64(x).unwrap()
    }

    #[test]
    fn dyadic_round_trips_every_kind_of_f64() {
        for x in [
            0.0,
            1.0,
            -1.5,
            0.1,
            1e300,
            -5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            3.0e-310,
        ] {
            assert_eq!(dy(x).to_f64().to_bits(), x.to_bits(), "{x}");
        }
    }

    #[test]
    fn dyadic_arithmetic_is_exact_where_f64_is_not() {
        // 0.1 + 0.2 != 0.3 in f64, and the exact sum is neither.
        let s = dy(0.1).add(&dy(0.2));
        assert_ne!(s.cmp_value(&dy(0.3)), Ordering::Equal);
        assert_eq!(s.sub(&dy(0.1)).cmp_value(&dy(0.2)), Ordering::Equal);
        // (1 + 2^-60)^2 - 1 - 2^-59 = 2^-120 exactly.
        let x = dy(1.0).add(&dy(2f64.powi(-60)));
        let r = x.mul(&x).sub(&dy(1.0)).sub(&dy(2f64.powi(-59)));
        assert_eq!(r.to_f64(), 2f64.powi(-120));
    }

    #[test]
    fn quotients_and_roots_round_correctly() {
        assert_eq!(dy(1.0).div_to_f64(&dy(3.0)), 1.0 / 3.0);
        assert_eq!(dy(-2.0).div_to_f64(&dy(7.0)), -2.0 / 7.0);
        assert_eq!(dy(2.0).sqrt_approx(120).to_f64(), 2f64.sqrt());
        assert_eq!(dy(1e-300).sqrt_approx(120).to_f64(), 1e-300f64.sqrt());
        // Ties go to even: 1 + 2^-53 rounds to 1.
        assert_eq!(dy(1.0).add(&dy(2f64.powi(-53))).to_f64(), 1.0);
        assert_eq!(
            dy(1.0)
                .add(&dy(2f64.powi(-53)))
                .add(&dy(2f64.powi(-100)))
                .to_f64(),
            1.0 + f64::EPSILON
        );
    }
}
