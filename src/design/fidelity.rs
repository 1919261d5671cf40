//! How a study's simulated yields rank against the nets' compactness
//! (`docs/model.md#fidelity`): Spearman's rank correlation with an approximate 95 %
//! interval, for comparison with the experiments' finding that compact, many-leaved nets
//! fold best.

use serde::Serialize;

/// A rank correlation and its interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RankCorrelation {
    /// Spearman's ρ: the Pearson correlation of the two lists' ranks (ties at their mean
    /// rank).
    pub rho: f64,
    /// Fisher's z interval with Bonett and Wright's variance (1 + ρ²/2)/(n − 3): about
    /// 95 % (a normal approximation; ties and small n make it rougher).
    pub interval_95: [f64; 2],
    /// Pairs ranked.
    pub pairs: usize,
}

/// The ranks of `values` (1 for the smallest), ties at their mean rank.
pub fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        // Positions start..end (0-based) share the mean of ranks start + 1 ..= end.
        let mean = 0.5 * ((start + 1) + end) as f64;
        for &k in &order[start..end] {
            ranks[k] = mean;
        }
        start = end;
    }
    ranks
}

/// Spearman's ρ of `x` against `y` (one pair per index) with its interval; None for fewer
/// than 4 pairs, lists of different lengths, a non-finite value, or a list whose values are
/// all equal (no ranking).
pub fn spearman(x: &[f64], y: &[f64]) -> Option<RankCorrelation> {
    let n = x.len();
    if n < 4 || y.len() != n || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let (rx, ry) = (ranks(x), ranks(y));
    let mean = (n as f64 + 1.0) / 2.0;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (dx, dy) = (rx[k] - mean, ry[k] - mean);
        sxy += dx * dy;
        sxx += dx * dx;
        syy += dy * dy;
    }
    if sxx == 0.0 || syy == 0.0 {
        return None;
    }
    let rho = (sxy / (sxx * syy).sqrt()).clamp(-1.0, 1.0);
    let interval_95 = if rho.abs() >= 1.0 {
        [rho, rho]
    } else {
        let spread = 1.959963984540054 * ((1.0 + 0.5 * rho * rho) / (n as f64 - 3.0)).sqrt();
        let z = rho.atanh();
        [(z - spread).tanh(), (z + spread).tanh()]
    };
    Some(RankCorrelation {
        rho,
        interval_95,
        pairs: n,
    })
}

/// A study's yields against its nets' compactness.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fidelity {
    /// Yield against the radius of gyration (compact nets have small radii: a negative ρ
    /// says compact nets fold best).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius_of_gyration: Option<RankCorrelation>,
    /// Yield against the number of leaves of the net's tree (a positive ρ says many-leaved
    /// nets fold best).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leaves: Option<RankCorrelation>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without ties ρ = 1 − 6 Σ d² / (n (n² − 1)), d each pair's rank difference: the
    /// textbook formula, against the correlation of ranks.
    #[test]
    fn without_ties_rho_is_the_rank_difference_formula() {
        let mut seed = 7_u64;
        let mut uniform = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [4, 5, 11, 50] {
            let x: Vec<f64> = (0..n).map(|_| uniform()).collect();
            let y: Vec<f64> = x.iter().map(|v| v + 0.5 * uniform()).collect();
            let (rx, ry) = (ranks(&x), ranks(&y));
            let d2: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - b) * (a - b)).sum();
            let nf = n as f64;
            let formula = 1.0 - 6.0 * d2 / (nf * (nf * nf - 1.0));
            let rho = spearman(&x, &y).unwrap().rho;
            assert!((rho - formula).abs() < 1e-12, "n {n}: {rho} against {formula}");
        }
    }

    /// Ties take their mean rank; a worked example (ranks by hand) and the degenerate cases.
    #[test]
    fn ties_share_their_mean_rank_and_degenerate_lists_have_no_rho() {
        assert_eq!(ranks(&[3.0, 1.0, 3.0, 2.0, 3.0]), [4.0, 1.0, 4.0, 2.0, 4.0]);
        // Yields 1, 1, 0.9, 0.8 against leaves 4, 3, 3, 2: ranks (3.5, 3.5, 2, 1) and
        // (4, 2.5, 2.5, 1), mean 2.5; Σ dx dy = 1.5 + 2.25 = 3.75, Σ dx² = 4.5,
        // Σ dy² = 4.5: ρ = 3.75 / 4.5.
        let rho = spearman(&[1.0, 1.0, 0.9, 0.8], &[4.0, 3.0, 3.0, 2.0]).unwrap().rho;
        assert!((rho - 3.75 / 4.5).abs() < 1e-12, "{rho}");
        let reversed = spearman(&[1.0, 2.0, 3.0, 4.0, 5.0], &[5.0, 4.0, 3.0, 2.0, 1.0]).unwrap();
        assert_eq!(reversed.rho, -1.0);
        assert!(spearman(&[1.0, 1.0, 1.0, 1.0], &[1.0, 2.0, 3.0, 4.0]).is_none());
        assert!(spearman(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]).is_none());
        assert!(spearman(&[1.0, f64::NAN, 3.0, 4.0], &[1.0, 2.0, 3.0, 4.0]).is_none());
        // The interval holds ρ and narrows as n grows.
        let x: Vec<f64> = (0..40).map(|k| k as f64).collect();
        let y: Vec<f64> = (0..40).map(|k| ((k * 7) % 40) as f64).collect();
        let wide = spearman(&x[..10], &y[..10]).unwrap();
        let narrow = spearman(&x, &y).unwrap();
        for r in [wide, narrow] {
            assert!(r.interval_95[0] <= r.rho && r.rho <= r.interval_95[1], "{r:?}");
        }
        assert!(narrow.interval_95[1] - narrow.interval_95[0] < wide.interval_95[1] - wide.interval_95[0]);
    }
}
