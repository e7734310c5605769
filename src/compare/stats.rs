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

#[cfg(test)]
mod tests {
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

    #[test]
    fn sidak_matches_its_closed_form() {
        assert!((sidak(0.01, 2.0) - (1.0 - 0.99f64 * 0.99)).abs() < 1e-15);
        assert_eq!(sidak(1.0, 5.0), 1.0);
        assert_eq!(sidak(0.0, 5.0), 0.0);
        // Small p: about m p.
        assert!((sidak(1e-12, 1e6) / 1e-6 - 1.0).abs() < 1e-5);
    }
}
