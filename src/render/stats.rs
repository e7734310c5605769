//! What the renderer's statistical tests share: a chi-square goodness-of-fit test over cells of
//! equal probability, at a stated false-alarm rate.

/// The `1 - alpha` quantile of the chi-square distribution with `dof` degrees of freedom, by the
/// Wilson-Hilferty approximation, with `z` the standard normal's `1 - alpha` quantile (4.753 for
/// `alpha = 1e-6`). Accurate to a fraction of a percent for `dof >= 30`, ample for a threshold.
pub(crate) fn chi_square_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}

/// The standard normal's quantile at `1 - 1e-6`.
pub(crate) const Z_ONE_IN_A_MILLION: f64 = 4.753;

/// The chi-square statistic of `counts` against equal expected counts.
pub(crate) fn chi_square(counts: &[u64]) -> f64 {
    let n: u64 = counts.iter().sum();
    let expected = n as f64 / counts.len() as f64;
    counts
        .iter()
        .map(|&c| (c as f64 - expected).powi(2) / expected)
        .sum()
}

/// Asserts that `counts` (cells of equal probability under the hypothesis) fit it: the
/// chi-square statistic is below its `1 - 1e-6` quantile, so a correct sampler fails with
/// probability under one in a million (the seed is fixed, so the test is deterministic), and
/// above its `1e-6` quantile too (a sampler that repeats the expected counts too exactly is as
/// wrong).
pub(crate) fn assert_uniform_cells(counts: &[u64], what: &str) {
    let dof = (counts.len() - 1) as f64;
    let statistic = chi_square(counts);
    let upper = chi_square_quantile(dof, Z_ONE_IN_A_MILLION);
    let lower = chi_square_quantile(dof, -Z_ONE_IN_A_MILLION);
    assert!(
        statistic < upper && statistic > lower,
        "{what}: chi-square {statistic:.1} over {dof} degrees of freedom, outside [{lower:.1}, {upper:.1}]"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Known quantiles: chi-square(79) at 1 - 1e-6 is about 154; chi-square(100) at 0.95 is
    /// 124.34.
    #[test]
    fn quantiles_match_the_tables() {
        assert!((chi_square_quantile(100.0, 1.6449) - 124.34).abs() < 0.3);
        let q = chi_square_quantile(79.0, Z_ONE_IN_A_MILLION);
        assert!((150.0..158.0).contains(&q), "{q}");
        assert_eq!(chi_square(&[10, 10, 10]), 0.0);
    }
}
