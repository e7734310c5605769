//! The statistical tests of the samplers: Pearson's chi-square goodness of fit and the exact
//! two-sided binomial test, each rejecting at a stated false-alarm rate ([`DEFAULT_ALPHA`]).
//!
//! The distributions' tails come from `statrs` (regularised incomplete gamma and beta
//! functions), a maintained crate rather than a home-made series: the thresholds sit at
//! `1e-4`, far in the tails, where a rough approximation would misstate the false-alarm rate.

use serde::{Deserialize, Deserializer, Serialize};
use statrs::distribution::{Binomial, ChiSquared, ContinuousCDF, DiscreteCDF};

/// The false-alarm rate of each statistical test by default: an honest sampler fails one test
/// in ten thousand (so a class of 300 students, each with about ten such tests a week, sees one
/// false alarm in some three weeks of the whole class; one student sees one in a thousand weeks).
pub const DEFAULT_ALPHA: f64 = 1e-4;

/// Cells whose expected count is below this are pooled into a neighbour before the chi-square
/// statistic is computed (the usual rule that keeps its distribution close to chi-square).
pub const MIN_EXPECTED: f64 = 5.0;

/// What one test found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestResult {
    /// `"chi-square"` or `"binomial"`.
    pub test: &'static str,
    /// The statistic: chi-square's sum, or the binomial count.
    pub statistic: f64,
    /// Degrees of freedom (chi-square), or trials (binomial).
    pub dof: f64,
    /// The probability, under the hypothesis, of a statistic at least this extreme.
    pub p_value: f64,
    /// The false-alarm rate the test rejects at.
    pub alpha: f64,
}

/// A [`TestResult`] read back (a merge of shards reads the reports they wrote): its test's
/// name must be one this module writes.
pub(crate) fn read_test<'de, D: Deserializer<'de>>(d: D) -> Result<Option<TestResult>, D::Error> {
    #[derive(Deserialize)]
    struct Owned {
        test: String,
        statistic: f64,
        dof: f64,
        p_value: f64,
        alpha: f64,
    }
    let Some(o) = Option::<Owned>::deserialize(d)? else {
        return Ok(None);
    };
    let test = ["chi-square", "binomial"]
        .into_iter()
        .find(|n| *n == o.test)
        .ok_or_else(|| serde::de::Error::custom(format!("unknown test {:?}", o.test)))?;
    Ok(Some(TestResult {
        test,
        statistic: o.statistic,
        dof: o.dof,
        p_value: o.p_value,
        alpha: o.alpha,
    }))
}

impl TestResult {
    /// Whether the hypothesis is rejected (`p < alpha`).
    pub fn rejected(&self) -> bool {
        self.p_value < self.alpha
    }
}

/// The chi-square statistic and its degrees of freedom for `counts` against cell
/// probabilities `probs` (summing to 1), cells with expected counts under [`MIN_EXPECTED`]
/// pooled in order with the next ones; `None` when fewer than two cells remain.
pub fn chi_square_statistic(counts: &[u64], probs: &[f64]) -> Option<(f64, f64)> {
    assert_eq!(counts.len(), probs.len(), "one probability per cell");
    let n: u64 = counts.iter().sum();
    if n == 0 {
        return None;
    }
    // An observation where the hypothesis allows none refutes it, whatever the pooling.
    if counts.iter().zip(probs).any(|(&c, &p)| c > 0 && p <= 0.0) {
        return Some((f64::INFINITY, (counts.len().max(2) - 1) as f64));
    }
    let n = n as f64;
    let mut pooled: Vec<(f64, f64)> = Vec::with_capacity(counts.len());
    let (mut observed, mut expected) = (0.0, 0.0);
    for (&c, &p) in counts.iter().zip(probs) {
        observed += c as f64;
        expected += p * n;
        if expected >= MIN_EXPECTED {
            pooled.push((observed, expected));
            observed = 0.0;
            expected = 0.0;
        }
    }
    if expected > 0.0 || observed > 0.0 {
        match pooled.last_mut() {
            Some(last) => {
                last.0 += observed;
                last.1 += expected;
            }
            None => pooled.push((observed, expected)),
        }
    }
    if pooled.len() < 2 {
        return None;
    }
    let statistic = pooled
        .iter()
        .map(|&(o, e)| {
            if e > 0.0 {
                (o - e) * (o - e) / e
            } else if o > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .sum();
    Some((statistic, (pooled.len() - 1) as f64))
}

/// Pearson's chi-square test of `counts` against `probs` at false-alarm rate `alpha`.
/// Observations in a cell of probability 0 give an infinite statistic (p = 0).
pub fn chi_square(counts: &[u64], probs: &[f64], alpha: f64) -> TestResult {
    match chi_square_statistic(counts, probs) {
        None => TestResult {
            test: "chi-square",
            statistic: 0.0,
            dof: 0.0,
            p_value: 1.0,
            alpha,
        },
        Some((statistic, dof)) => TestResult {
            test: "chi-square",
            statistic,
            dof,
            p_value: chi_square_sf(statistic, dof),
            alpha,
        },
    }
}

/// [`chi_square`] against cells of equal probability.
pub fn chi_square_uniform(counts: &[u64], alpha: f64) -> TestResult {
    let probs = vec![1.0 / counts.len() as f64; counts.len()];
    chi_square(counts, &probs, alpha)
}

/// `P(X >= x)` for `X` chi-square with `dof` degrees of freedom.
pub fn chi_square_sf(x: f64, dof: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return 0.0;
    }
    ChiSquared::new(dof).map_or(1.0, |d| d.sf(x))
}

/// The smallest statistic [`chi_square`] rejects at `alpha` with `dof` degrees of freedom (the
/// `1 - alpha` quantile), by bisection on [`chi_square_sf`].
pub fn chi_square_threshold(dof: f64, alpha: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, dof + 10.0);
    while chi_square_sf(hi, dof) >= alpha {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi_square_sf(mid, dof) >= alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The exact two-sided binomial test: `k` successes in `n` trials against probability `p`.
/// The p-value is twice the smaller tail (`P(X <= k)`, `P(X >= k)`), capped at 1.
pub fn binomial(k: u64, n: u64, p: f64, alpha: f64) -> TestResult {
    let p_value = match Binomial::new(p.clamp(0.0, 1.0), n) {
        Err(_) => 1.0,
        Ok(d) => {
            let below = d.cdf(k);
            let above = if k == 0 { 1.0 } else { d.sf(k - 1) };
            (2.0 * below.min(above)).min(1.0)
        }
    };
    TestResult {
        test: "binomial",
        statistic: k as f64,
        dof: n as f64,
        p_value,
        alpha,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table values: the 0.95 quantile of chi-square(10) is 18.307, its 0.9999 quantile 35.56;
    /// chi-square(1) at 3.841 has p 0.05.
    #[test]
    fn chi_square_tails_match_the_tables() {
        assert!((chi_square_sf(18.307, 10.0) - 0.05).abs() < 1e-4);
        assert!((chi_square_threshold(10.0, 1e-4) - 35.56).abs() < 0.01);
        assert!((chi_square_sf(3.841, 1.0) - 0.05).abs() < 1e-4);
        assert_eq!(chi_square_sf(f64::INFINITY, 3.0), 0.0);
    }

    /// Equal counts give 0; counts in a cell of probability 0 reject; small cells are pooled
    /// (1 + 1 expected in the last two cells become one cell of 2, then joined to its
    /// neighbour).
    #[test]
    fn chi_square_pools_small_cells_and_rejects_the_impossible() {
        let r = chi_square_uniform(&[10, 10, 10, 10], 1e-4);
        assert_eq!((r.statistic, r.dof, r.p_value), (0.0, 3.0, 1.0));
        let r = chi_square(&[50, 50, 1], &[0.5, 0.5, 0.0], 1e-4);
        assert!(r.statistic.is_infinite() && r.rejected(), "{r:?}");
        let (stat, dof) = chi_square_statistic(&[48, 48, 2, 2], &[0.48, 0.48, 0.02, 0.02])
            .expect("two cells at least");
        assert_eq!(dof, 1.0);
        assert!((stat - 0.0).abs() < 1e-12, "{stat}");
    }

    /// 10 heads in 10 tosses of a fair coin: p = 2 / 1024; 5 of 10: p = 1.
    #[test]
    fn binomial_is_exact() {
        let r = binomial(10, 10, 0.5, 1e-4);
        assert!((r.p_value - 2.0 / 1024.0).abs() < 1e-12, "{r:?}");
        assert_eq!(binomial(5, 10, 0.5, 1e-4).p_value, 1.0);
        assert!(binomial(0, 1000, 0.5, 1e-4).rejected());
        // Probability 1: every trial a success is no evidence against it.
        assert!(!binomial(1000, 1000, 1.0, 1e-4).rejected());
        assert!(binomial(999, 1000, 1.0, 1e-4).rejected());
    }
}
