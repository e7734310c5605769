//! Tail bounds and multiple-testing adjustments.

/// Two-sided Bernstein bound on the probability that a sum of independent zero-mean terms, each
/// bounded by `bound` in absolute value and with total variance `variance`, deviates from zero
/// by at least `t`: `2 exp(-t^2 / (2 V + 2 b t / 3))`, capped at 1.
///
/// Unlike the normal tail it holds for any number of samples, which matters at 20 samples per
/// pixel where an edge pixel's mean is a scaled binomial.
pub fn bernstein_p(t: f64, variance: f64, bound: f64) -> f64 {
    if t.is_nan() {
        return 0.0;
    }
    if t <= 0.0 {
        return 1.0;
    }
    let denominator = 2.0 * variance + 2.0 * bound * t / 3.0;
    if denominator <= 0.0 {
        return 0.0;
    }
    (2.0 * (-t * t / denominator).exp()).min(1.0)
}

/// Šidák's adjustment of a p-value for `m` independent tests: `1 - (1 - p)^m`.
pub fn sidak(p: f64, m: f64) -> f64 {
    if p >= 1.0 {
        return 1.0;
    }
    if p <= 0.0 {
        return 0.0;
    }
    (-(m * (-p).ln_1p()).exp_m1()).min(1.0)
}

/// The constant in relMSE's denominator: it keeps the near-black pixels, where any difference is
/// a large ratio, from dominating the mean.
pub const REL_MSE_EPSILON: f64 = 0.01;

/// One term of relMSE, `(x - reference)^2 / (reference^2 + 0.01)`: how far a value is from the
/// reference's, relative to it. relMSE is the mean of these over the pixels and channels.
pub fn rel_mse_term(x: f64, reference: f64) -> f64 {
    (x - reference).powi(2) / (reference * reference + REL_MSE_EPSILON)
}

#[cfg(test)]
mod tests {
    /// A value 10% below a reference of 1: 0.01 / 1.01; equal values: 0.
    #[test]
    fn rel_mse_term_by_hand() {
        assert!((super::rel_mse_term(0.9, 1.0) - 0.01 / 1.01).abs() < 1e-15);
        assert_eq!(super::rel_mse_term(0.25, 0.25), 0.0);
        assert!((super::rel_mse_term(0.1, 0.0) - 1.0).abs() < 1e-12);
    }

    use super::*;

    #[test]
    fn bernstein_reduces_to_its_formula() {
        // t = 2, V = 1, b = 0: 2 exp(-2).
        assert!((bernstein_p(2.0, 1.0, 0.0) - 2.0 * (-2.0f64).exp()).abs() < 1e-15);
        // Capped at 1: t = 1, V = 1 gives 2 exp(-1/2) > 1.
        assert_eq!(bernstein_p(1.0, 1.0, 0.0), 1.0);
        assert_eq!(bernstein_p(0.0, 0.0, 0.0), 1.0);
        assert_eq!(bernstein_p(1e-3, 0.0, 0.0), 0.0);
        // b = 3/2, V = 0, t = 1: 2 exp(-1).
        assert!((bernstein_p(1.0, 0.0, 1.5) - 2.0 * (-1.0f64).exp()).abs() < 1e-15);
    }

    #[test]
    fn bernstein_bounds_a_binomial_tail() {
        // 20 Bernoulli(0.3) samples: the exact P(|mean - 0.3| >= 0.35) is P(X >= 13) + 0
        // (X <= -1 is impossible); the bound must lie above it.
        let n = 20u32;
        let p = 0.3f64;
        let choose = |n: u32, k: u32| -> f64 {
            (0..k).fold(1.0, |a, i| a * (n - i) as f64 / (i + 1) as f64)
        };
        let exact: f64 = (13..=n)
            .map(|k| choose(n, k) * p.powi(k as i32) * (1.0 - p).powi((n - k) as i32))
            .sum();
        let bound = bernstein_p(0.35, p * (1.0 - p) / n as f64, 1.0 / n as f64);
        assert!(bound >= exact, "{bound} < {exact}");
        assert!(bound < 0.1);
    }

    /// The bound is valid where the comparison relies on it: simulated edge pixels (20 samples,
    /// each one of two colours 0.8 apart, coverage 0.05 to 0.95) fall below a p of `a` no more
    /// often than `a`, for several `a`, with the variance known exactly.
    #[test]
    fn bernstein_p_values_are_valid_for_simulated_edge_pixels() {
        let mut rng = crate::render::PixelSampler::new(3, 5);
        let n = 20;
        let trials = 20_000;
        for coverage in [0.05, 0.3, 0.5, 0.95] {
            let variance = coverage * (1.0 - coverage) * 0.64 / n as f64;
            let mut below = [0usize; 3];
            for _ in 0..trials {
                let hits = (0..n).filter(|_| rng.next_f64() < coverage).count();
                let mean = 0.1 + 0.8 * hits as f64 / n as f64;
                let t = (mean - (0.1 + 0.8 * coverage)).abs();
                let p = bernstein_p(t, variance, 0.8 / n as f64);
                for (k, a) in [0.2, 0.05, 0.01].into_iter().enumerate() {
                    below[k] += usize::from(p < a);
                }
            }
            for (k, a) in [0.2, 0.05, 0.01].into_iter().enumerate() {
                let rate = below[k] as f64 / trials as f64;
                // Allow 4 binomial standard errors of sampling noise above a.
                let slack = 4.0 * (a * (1.0 - a) / trials as f64).sqrt();
                assert!(
                    rate <= a + slack,
                    "coverage {coverage}: P(p < {a}) = {rate}"
                );
            }
        }
    }

    #[test]
    fn sidak_matches_its_closed_form() {
        assert!((sidak(0.01, 2.0) - (1.0 - 0.99f64 * 0.99)).abs() < 1e-15);
        assert_eq!(sidak(1.0, 5.0), 1.0);
        assert_eq!(sidak(0.0, 5.0), 0.0);
        // Small p: about m p.
        assert!((sidak(1e-12, 1e6) / 1e-6 - 1.0).abs() < 1e-5);
    }
}
