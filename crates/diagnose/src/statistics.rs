//! The few statistics the diagnosis needs.

/// Arithmetic mean (0 for an empty slice).
pub(crate) fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// Wilcoxon's signed-rank statistic of the paired differences `a − b`, standardised: positive
/// when `a` tends to be larger. Zero differences are dropped, tied absolute differences share
/// their mean rank, and the variance is corrected for ties (Hollander & Wolfe, *Nonparametric
/// Statistical Methods*, 2nd ed., 1999, §3.1, the large-sample form). It looks at ranks, not
/// sizes, so a few huge differences of either sign cannot hide a gain that most pairs show.
pub(crate) fn signed_rank_z(a: &[f64], b: &[f64]) -> f64 {
    let mut d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).filter(|v| *v != 0.0 && v.is_finite()).collect();
    let n = d.len();
    if n == 0 {
        return 0.0;
    }
    d.sort_by(|x, y| x.abs().total_cmp(&y.abs()));
    let (mut positive_ranks, mut ties) = (0.0, 0.0);
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        while end < n && d[end].abs() == d[start].abs() {
            end += 1;
        }
        // Ranks start + 1 ..= end share their mean.
        let rank = (start + 1 + end) as f64 / 2.0;
        positive_ranks += rank * d[start..end].iter().filter(|v| **v > 0.0).count() as f64;
        let t = (end - start) as f64;
        ties += t * t * t - t;
        start = end;
    }
    let n = n as f64;
    let mean = n * (n + 1.0) / 4.0;
    let variance = n * (n + 1.0) * (2.0 * n + 1.0) / 24.0 - ties / 48.0;
    if variance <= 0.0 {
        return 0.0;
    }
    (positive_ranks - mean) / variance.sqrt()
}

/// The median (0 for an empty slice).
pub(crate) fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n % 2 == 1 { sorted[n / 2] } else { 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]) }
}

/// The standard normal quantile `Φ⁻¹(p)`, by Acklam's rational approximation (relative error
/// below 1.2e-9), for `0 < p < 1`.
pub(crate) fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.38357751867269e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] =
        [-5.447609879822406e1, 1.615858368580409e2, -1.556989798598866e2, 6.680131188771972e1, -1.328068155288572e1];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [7.784695709041462e-3, 3.224671290700398e-1, 2.445134137142996, 3.754408661907416];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantiles_match_tables() {
        for (p, z) in
            [(0.5, 0.0), (0.975, 1.959963985), (0.99, 2.326347874), (0.999, 3.090232306), (0.01, -2.326347874)]
        {
            assert!((normal_quantile(p) - z).abs() < 1e-8, "{p}: {}", normal_quantile(p));
        }
    }

    #[test]
    fn signed_rank_matches_a_hand_count_and_ignores_the_size_of_outliers() {
        // Differences 1, 2, −3, 4, 5: W+ = 1 + 2 + 4 + 5 = 12, mean 7.5, variance 13.75.
        let a = [1.0, 2.0, -3.0, 4.0, 5.0];
        let b = [0.0; 5];
        let expected = (12.0 - 7.5) / 13.75f64.sqrt();
        assert!((signed_rank_z(&a, &b) - expected).abs() < 1e-12);
        assert!((signed_rank_z(&b, &a) + expected).abs() < 1e-12);
        // 40 pairs improve by 0.1, two get 100 worse: the mean says "worse", the ranks "better".
        let mut before = vec![1.0; 42];
        let mut after = vec![0.9; 42];
        after[0] = 101.0;
        after[1] = 101.0;
        assert!(mean(&after) > mean(&before));
        assert!(signed_rank_z(&before, &after) > 4.0, "{}", signed_rank_z(&before, &after));
        before.iter_mut().for_each(|v| *v = 0.9);
        after.iter_mut().for_each(|v| *v = 0.9);
        assert_eq!(signed_rank_z(&before, &after), 0.0);
    }

    #[test]
    fn tied_ranks_share_the_mean_rank_and_shrink_the_variance() {
        // |d| = 1, 1, 1, 1 with signs + + + −: ranks 2.5 each, W+ = 7.5, mean 5,
        // variance 4·5·9/24 − (64 − 4)/48 = 7.5 − 1.25.
        let z = signed_rank_z(&[1.0, 1.0, 1.0, 0.0], &[0.0, 0.0, 0.0, 1.0]);
        assert!((z - 2.5 / 6.25f64.sqrt()).abs() < 1e-12, "{z}");
    }
}
