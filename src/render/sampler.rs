use rand_core::Rng;
use rand_pcg::Pcg64;

/// The random stream of one pixel: PCG-XSL-RR 128/64 seeded from the render seed and the pixel's
/// index, so every pixel draws the same numbers whichever thread renders it and in whatever order.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    rng: Pcg64,
}

/// SplitMix64's finaliser: a bijective mix of 64 bits.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl PixelSampler {
    /// The stream for pixel number `pixel` (row-major) of a render with `seed`.
    #[inline]
    pub fn new(seed: u64, pixel: u64) -> Self {
        let state = ((mix(seed) as u128) << 64) | mix(pixel ^ 0x9e37_79b9_7f4a_7c15) as u128;
        let stream = ((pixel as u128) << 64) | seed as u128;
        Self {
            rng: Pcg64::new(state, stream),
        }
    }

    /// A uniform `f64` in `[0, 1)`: the top 53 bits of the next output times `2^-53`.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform point of the open unit disk, by rejection (as the book does).
    #[inline]
    pub fn in_unit_disk(&mut self) -> (f64, f64) {
        loop {
            let x = 2.0 * self.next_f64() - 1.0;
            let y = 2.0 * self.next_f64() - 1.0;
            if x * x + y * y < 1.0 {
                return (x, y);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<f64> = (0..4)
            .map({
                let mut s = PixelSampler::new(7, 3);
                move |_| s.next_f64()
            })
            .collect();
        let b: Vec<f64> = (0..4)
            .map({
                let mut s = PixelSampler::new(7, 3);
                move |_| s.next_f64()
            })
            .collect();
        let c: Vec<f64> = (0..4)
            .map({
                let mut s = PixelSampler::new(7, 4);
                move |_| s.next_f64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a.iter().all(|x| (0.0..1.0).contains(x)));
    }

    #[test]
    fn mean_of_many_draws_is_near_one_half() {
        let mut s = PixelSampler::new(1, 1);
        let n = 100_000;
        let mean = (0..n).map(|_| s.next_f64()).sum::<f64>() / n as f64;
        // Standard error is 1/sqrt(12 n) ~ 0.0009: 5 SE.
        assert!((mean - 0.5).abs() < 0.0046, "{mean}");
    }
}
