//! The robust statistics the suggestion rules stand on: medians, the median absolute
//! deviation, the sign test, a distribution-free interval for the median and shrinkage
//! toward no change. Plain functions over slices, no allocation beyond a sorted copy.

/// The median of `v` (the mean of the two middle values for an even count); `None` when empty.
pub fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let s = sorted(v);
    let n = s.len();
    Some(if n % 2 == 1 { s[n / 2] } else { (s[n / 2 - 1] + s[n / 2]) / 2.0 })
}

/// The median absolute deviation of `v` from `centre` (unscaled).
pub fn mad(v: &[f64], centre: f64) -> f64 {
    let d: Vec<f64> = v.iter().map(|x| (x - centre).abs()).collect();
    median(&d).unwrap_or(0.0)
}

/// `v` sorted ascending (NaN-free input assumed; NaNs sort last).
pub fn sorted(v: &[f64]) -> Vec<f64> {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    s
}

/// `ln(n choose k)`, exact enough for the counts of a shop's edits.
fn ln_choose(n: usize, k: usize) -> f64 {
    let k = k.min(n - k);
    (0..k).map(|i| ((n - i) as f64).ln() - ((i + 1) as f64).ln()).sum()
}

/// `P(X ≥ k)` for `X ~ Binomial(n, 1/2)`.
pub fn upper_tail(n: usize, k: usize) -> f64 {
    if k == 0 {
        return 1.0;
    }
    if k > n {
        return 0.0;
    }
    let half = (n as f64) * 0.5f64.ln();
    (k..=n).map(|i| (ln_choose(n, i) + half).exp()).sum::<f64>().min(1.0)
}

/// The two-sided exact sign test: the chance of a split at least as uneven as `agree` of
/// `agree + disagree` signs if increases and decreases were equally likely.
pub fn sign_test(agree: usize, disagree: usize) -> f64 {
    let n = agree + disagree;
    if n == 0 {
        return 1.0;
    }
    let k = agree.max(disagree);
    (2.0 * upper_tail(n, k)).min(1.0)
}

/// A distribution-free interval for the median of `v` at `confidence` (0.95): the order
/// statistics `v(l)` and `v(n+1-l)` with the largest `l` whose interval still covers the
/// median with at least that chance (binomial ranks). With too few values for that, the
/// whole range.
pub fn median_interval(v: &[f64], confidence: f64) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let s = sorted(v);
    let n = s.len();
    let tail = (1.0 - confidence) / 2.0;
    // Coverage of [v(l), v(n+1-l)] is 1 - 2·P(X ≤ l-1), X ~ Binomial(n, 1/2).
    let mut l = 1;
    // P(X ≤ l) = P(X ≥ n - l) by symmetry: widen inward while the next ranks still cover.
    while l < n.div_ceil(2) && upper_tail(n, n - l) <= tail {
        l += 1;
    }
    Some((s[l - 1], s[n - l]))
}

/// Shrinks an effect toward no change as if `prior` edits of no change stood beside the
/// `n` that were seen: `effect · n / (n + prior)`.
pub fn shrink(effect: f64, n: usize, prior: f64) -> f64 {
    let n = n as f64;
    if n + prior <= 0.0 { 0.0 } else { effect * n / (n + prior) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_deviations() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(mad(&[1.0, 2.0, 3.0, 4.0, 100.0], 3.0), 1.0);
    }

    #[test]
    fn the_sign_test_is_the_exact_binomial() {
        // 8 of 8 the same way: 2 · 0.5^8.
        assert!((sign_test(8, 0) - 2.0 / 256.0).abs() < 1e-12);
        // 4 against 4 is no evidence at all.
        assert_eq!(sign_test(4, 4), 1.0);
        // 9 of 10: 2 · (10 + 1) / 1024.
        assert!((sign_test(9, 1) - 22.0 / 1024.0).abs() < 1e-12);
        assert_eq!(sign_test(0, 0), 1.0);
    }

    #[test]
    fn the_median_interval_follows_the_binomial_ranks() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        // n = 10 at 95%: P(X ≤ 1) = 11/1024 ≤ 0.025 < P(X ≤ 2) = 56/1024, so l = 2.
        assert_eq!(median_interval(&v, 0.95), Some((2.0, 9.0)));
        // Five values: even l = 1 covers with 1 - 2/32 = 0.9375 only; the whole range.
        assert_eq!(median_interval(&[5.0, 1.0, 3.0, 2.0, 4.0], 0.95), Some((1.0, 5.0)));
        let w: Vec<f64> = (1..=20).map(f64::from).collect();
        // n = 20: P(X ≤ 5) = 0.0207 ≤ 0.025 < P(X ≤ 6) = 0.0577, so l = 6.
        assert_eq!(median_interval(&w, 0.95), Some((6.0, 15.0)));
    }

    #[test]
    fn shrinkage_pulls_toward_no_change() {
        assert!((shrink(0.3, 6, 3.0) - 0.2).abs() < 1e-12);
        assert_eq!(shrink(-0.3, 0, 0.0), 0.0);
    }
}
