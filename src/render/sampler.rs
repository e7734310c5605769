use glam::DVec3;
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
    #[inline(always)]
    pub fn next_f64(&mut self) -> f64 {
        (self.rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform `f64` in `[lo, hi)`: `lo + (hi - lo) u`, the book's `random_double(min, max)`.
    #[inline(always)]
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A uniform point on the unit sphere (the course's `random_vec3_unit`, the book's
    /// `random_unit_vector`): a point of the cube `[-1, 1)^3` (x, y, then z), drawn again until
    /// its squared length lies in `(1e-160, 1]`, divided by its length. About 1.9 tries.
    #[inline(always)]
    pub fn unit_vector(&mut self) -> DVec3 {
        loop {
            let p = DVec3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let length2 = p.length_squared();
            if 1e-160 < length2 && length2 <= 1.0 {
                return p / length2.sqrt();
            }
        }
    }

    /// A direction of the upper hemisphere about `z` with density `cos(theta) / pi` (week 9's
    /// `random_cosine_hemisphere_on_z`): `phi = 2 pi r1`,
    /// `(cos(phi) sqrt(r2), sin(phi) sqrt(r2), sqrt(1 - r2))`, `r1` drawn first. The sine and
    /// cosine are libm's, the same on every platform.
    #[inline]
    pub fn cosine_hemisphere(&mut self) -> DVec3 {
        let r1 = self.next_f64();
        let r2 = self.next_f64();
        let phi = 2.0 * std::f64::consts::PI * r1;
        let s = r2.sqrt();
        DVec3::new(libm::cos(phi) * s, libm::sin(phi) * s, (1.0 - r2).sqrt())
    }

    /// A uniform point of the open unit disk, by rejection (as the book does).
    #[inline(always)]
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

    /// Uniform on the sphere: `z` uniform in `[-1, 1]` and the azimuth uniform (Archimedes), so
    /// 10 x 8 cells of equal probability; chi-square at a false alarm of one in a million.
    #[test]
    fn unit_vectors_are_uniform_on_the_sphere() {
        let mut s = PixelSampler::new(2, 3);
        let mut counts = [0u64; 80];
        for _ in 0..80_000 {
            let p = s.unit_vector();
            assert!((p.length() - 1.0).abs() < 1e-15);
            let z = (((p.z + 1.0) / 2.0 * 10.0) as usize).min(9);
            let phi = (p.y.atan2(p.x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
            counts[z * 8 + ((phi * 8.0) as usize).min(7)] += 1;
        }
        crate::render::stats::assert_uniform_cells(&counts, "unit sphere");
    }

    /// The lens disk: uniform on the unit disk, so `r^2` uniform and the angle uniform, 10 x 8
    /// cells of equal probability; chi-square at a false alarm of one in a million.
    #[test]
    fn disk_points_are_uniform_on_the_disk() {
        let mut s = PixelSampler::new(8, 1);
        let mut counts = [0u64; 80];
        for _ in 0..80_000 {
            let (x, y) = s.in_unit_disk();
            let r2 = x * x + y * y;
            assert!(r2 < 1.0);
            let phi = (y.atan2(x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
            counts[((r2 * 10.0) as usize).min(9) * 8 + ((phi * 8.0) as usize).min(7)] += 1;
        }
        crate::render::stats::assert_uniform_cells(&counts, "lens disk");
    }

    /// The cosine hemisphere about `z`: `z^2` uniform in `[0, 1]` (density `cos / pi`) and the
    /// azimuth uniform; chi-square at a false alarm of one in a million.
    #[test]
    fn cosine_hemisphere_has_density_cos_over_pi() {
        let mut s = PixelSampler::new(6, 1);
        let mut counts = [0u64; 80];
        for _ in 0..80_000 {
            let d = s.cosine_hemisphere();
            assert!(d.z >= 0.0 && (d.length() - 1.0).abs() < 1e-15);
            let phi = (d.y.atan2(d.x) + std::f64::consts::PI) / (2.0 * std::f64::consts::PI);
            counts[((d.z * d.z * 10.0) as usize).min(9) * 8 + ((phi * 8.0) as usize).min(7)] += 1;
        }
        crate::render::stats::assert_uniform_cells(&counts, "cosine hemisphere");
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
