//! Rank of the closure Jacobian and the degrees of freedom at a state
//! (`docs/model.md#rigid-folding`), by faer's column-pivoted QR.

use super::closure::ClosureJacobian;

/// A diagonal entry of R at or below this fraction of the largest counts as zero.
pub const RANK_TOL: f64 = 1e-9;

/// What the rank-revealing factorisation found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankReport {
    /// Numerical rank of J.
    pub rank: usize,
    /// Degrees of freedom: creases − rank.
    pub dof: usize,
    /// The threshold applied to |R_ii| (RANK_TOL × |R_00|).
    pub threshold: f64,
    /// Smallest |R_ii| counted in the rank (∞ when the rank is 0).
    pub smallest_kept: f64,
    /// Largest |R_ii| counted as zero (0 when J has full column rank).
    pub largest_dropped: f64,
}

/// Rank and degrees of freedom of J by column-pivoted QR: the |R_ii| decrease, and those
/// above RANK_TOL·|R_00| are counted. The gap between `smallest_kept` and
/// `largest_dropped` says how clear-cut the count is.
pub fn jacobian_rank(jacobian: &ClosureJacobian) -> RankReport {
    let (rows, cols) = (jacobian.rows, jacobian.cols);
    if rows == 0 || cols == 0 {
        return RankReport {
            rank: 0,
            dof: cols,
            threshold: 0.0,
            smallest_kept: f64::INFINITY,
            largest_dropped: 0.0,
        };
    }
    let dense = jacobian.to_sparse().to_dense();
    let qr = dense.col_piv_qr();
    let r = qr.thin_R();
    let diagonal: Vec<f64> = (0..rows.min(cols)).map(|i| r[(i, i)].abs()).collect();
    let threshold = RANK_TOL * diagonal[0];
    let rank = diagonal.iter().take_while(|&&d| d > threshold && d > 0.0).count();
    RankReport {
        rank,
        dof: cols - rank,
        threshold,
        smallest_kept: if rank > 0 { diagonal[rank - 1] } else { f64::INFINITY },
        largest_dropped: diagonal.get(rank).copied().unwrap_or(0.0),
    }
}
