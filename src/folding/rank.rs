//! Rank of the closure Jacobian and the degrees of freedom at a state
//! (`docs/model.md#rigid-folding`): after the exact reductions of
//! [`super::reduction::reduce`], faer's column-pivoted QR up to [`DENSE_RANK_LIMIT`]
//! columns, above it a count of J's null space by subspace iteration on (JᵀJ + μI)⁻¹ with
//! a sparse Cholesky factorisation.

use super::closure::ClosureJacobian;
use super::normal::NormalSolver;
use super::reduction::reduce;
use super::simd_state::clear_upper_vector_state;
use crate::error::{NumericalError, Result};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::svd::{svd, svd_scratch, ComputeSvdVectors};
use faer::linalg::{householder, qr};
use faer::{Mat, Par};

/// A diagonal entry of R (dense) or a singular value (sparse) at or below this fraction
/// of J's largest column norm counts as zero. (Pivoted QR puts the largest column first,
/// so |R_00| is that norm.)
pub const RANK_TOL: f64 = 1e-9;

/// The relative threshold of a rank count: [`RANK_TOL`], or the pattern's angle precision
/// where its coordinates hold fewer digits (far from the origin, the rounding of a
/// Miura-ori's file lifts the singular value of its one DOF above 1e-9).
pub fn rank_tolerance(jacobian: &ClosureJacobian) -> f64 {
    RANK_TOL.max(jacobian.angle_precision)
}

/// How far above the threshold (in eigenvalues of JᵀJ, squared singular values) the first
/// value counted in the rank must settle before the sparse count stops early.
const COUNT_GAP: f64 = 1e6;

/// Eigenvalues of JᵀJ within this multiple of μ form a cluster the shifted inverse cannot
/// separate (its factorisation's backward error is of order μ too): the block is doubled
/// until its largest Ritz value clears this level, so that the block holds the whole
/// cluster and Rayleigh–Ritz, on JX itself, separates the null directions inside it.
const CLUSTER_LEVEL: f64 = 1e3;

/// Patterns with more creases than this get the sparse count (the dense QR costs
/// O(rows·creases²): about 0.13 s at 1100 creases, 1 s at 2000).
pub const DENSE_RANK_LIMIT: usize = 1200;

/// μ of the sparse count, relative to J's largest squared column norm. The iteration only
/// needs the small singular values to dominate (JᵀJ + μI)⁻¹; they are then measured by
/// the SVD of JX, not from μ.
const COUNT_REGULARISATION: f64 = 1e-15;

/// How the rank was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RankMethod {
    /// Column-pivoted QR of the dense J (threshold `rank_tolerance` on |R_ii|/|R_00|).
    PivotedQr,
    /// The smallest singular values of J by subspace iteration on (JᵀJ + μI)⁻¹ (threshold
    /// `rank_tolerance` on σ / largest column norm).
    SubspaceIteration,
}

impl RankMethod {
    /// The name used in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            RankMethod::PivotedQr => "column-pivoted QR",
            RankMethod::SubspaceIteration => "subspace iteration on JᵀJ (sparse Cholesky)",
        }
    }
}

/// What the rank computation found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankReport {
    /// Numerical rank of J.
    pub rank: usize,
    /// Degrees of freedom: creases − locked creases − rank.
    pub dof: usize,
    /// The threshold applied (to |R_ii| for the QR, to σ for the sparse count).
    pub threshold: f64,
    /// Smallest value counted in the rank (|R_ii| or σ estimate; ∞ when there is none).
    pub smallest_kept: f64,
    /// Largest value counted as zero (0 when there is none).
    pub largest_dropped: f64,
    /// Which method counted what the exact reductions left.
    pub method: RankMethod,
    /// Creases the exact reductions (`reduce`) merged or eliminated before the count.
    pub reduced: usize,
}

/// Rank and degrees of freedom of J: creases no star ties counted at once, the rest reduced
/// exactly (`reduce`: ties merged, rows held by one crease eliminated), and what remains
/// counted by the dense pivoted QR up to [`DENSE_RANK_LIMIT`] columns, the sparse null-space
/// count above.
pub fn jacobian_rank(jacobian: &ClosureJacobian) -> Result<RankReport> {
    // A column without a non-zero entry (a crease that meets no interior vertex, as in a
    // strip of parallel creases, or a locked one) is a null direction by itself: counted
    // here, so the rank count only sees the creases the closures tie together.
    let mut tied = vec![false; jacobian.cols];
    let mut column_norm = vec![0.0_f64; jacobian.cols];
    for &(_, c, v) in &jacobian.entries {
        if v != 0.0 {
            tied[c] = true;
            column_norm[c] += v * v;
        }
    }
    let free = tied.iter().filter(|&&t| !t).count();
    let scale = column_norm.iter().fold(0.0_f64, |a, &b| a.max(b)).sqrt();
    let reduction = reduce(&jacobian.columns(&tied), rank_tolerance(jacobian), scale);
    let mut report = if reduction.remainder.cols == 0 {
        // Nothing left to count: the threshold is still the one the reductions applied.
        RankReport {
            rank: 0,
            dof: 0,
            threshold: rank_tolerance(jacobian) * scale,
            smallest_kept: f64::INFINITY,
            largest_dropped: 0.0,
            method: RankMethod::PivotedQr,
            reduced: 0,
        }
    } else {
        ranked(&reduction.remainder, scale)?
    };
    // Locked columns are among the untied ones, and are no motion.
    report.dof += reduction.free_columns + free - jacobian.held;
    report.rank = jacobian.cols - jacobian.held - report.dof;
    report.reduced = reduction.removed_columns;
    Ok(report)
}

/// The rank count of what the reductions left, its threshold relative to `scale` (the
/// largest column norm of the J they started from).
fn ranked(jacobian: &ClosureJacobian, scale: f64) -> Result<RankReport> {
    if jacobian.cols <= DENSE_RANK_LIMIT {
        Ok(dense_rank(jacobian, Some(scale)))
    } else {
        let report = settled_block(jacobian, Some(scale * scale))?.report(jacobian);
        clear_upper_vector_state();
        Ok(report)
    }
}

/// Rank by column-pivoted QR: the |R_ii| decrease, and those above RANK_TOL·|R_00| are
/// counted. The gap between `smallest_kept` and `largest_dropped` says how clear-cut the
/// count is.
pub fn jacobian_rank_dense(jacobian: &ClosureJacobian) -> RankReport {
    dense_rank(jacobian, None)
}

/// The pivoted QR's count, its threshold relative to `scale` or else to |R_00|.
fn dense_rank(jacobian: &ClosureJacobian, scale: Option<f64>) -> RankReport {
    let (rows, cols) = (jacobian.rows, jacobian.cols);
    // Nothing free (no rows, no columns, or every column held): rank 0, and no threshold is
    // needed (a QR of the zero matrix gives NaN).
    let free = jacobian.entries.iter().any(|e| e.2 != 0.0);
    if rows == 0 || cols == 0 || !free {
        return RankReport {
            rank: 0,
            dof: cols - jacobian.held,
            threshold: 0.0,
            smallest_kept: f64::INFINITY,
            largest_dropped: 0.0,
            method: RankMethod::PivotedQr,
            reduced: 0,
        };
    }
    let dense = jacobian.to_sparse().to_dense();
    let qr = dense.col_piv_qr();
    let r = qr.thin_R();
    let diagonal: Vec<f64> = (0..rows.min(cols)).map(|i| r[(i, i)].abs()).collect();
    let threshold = rank_tolerance(jacobian) * scale.unwrap_or(diagonal[0]);
    let rank = diagonal.iter().take_while(|&&d| d > threshold && d > 0.0).count();
    clear_upper_vector_state();
    RankReport {
        rank,
        dof: cols - jacobian.held - rank,
        threshold,
        smallest_kept: if rank > 0 { diagonal[rank - 1] } else { f64::INFINITY },
        largest_dropped: diagonal.get(rank).copied().unwrap_or(0.0),
        method: RankMethod::PivotedQr,
        reduced: 0,
    }
}

/// The null space of J counted from its smallest singular values: a block of vectors X is
/// multiplied by (JᵀJ + μI)⁻¹ until the singular values of JX (Rayleigh–Ritz values)
/// settle; those at or below RANK_TOL·(largest column norm) are the null space. Ritz values bound the
/// eigenvalues from above, so every one counted is a true small singular value; the block
/// is doubled while all of it is counted, or while all of it lies within the cluster the
/// shifted inverse cannot separate (10³ μ), so the count is complete once the
/// next Ritz value is above the threshold (`docs/model.md#rigid-folding`).
pub fn jacobian_rank_sparse(jacobian: &ClosureJacobian) -> Result<RankReport> {
    let report = settled_block(jacobian, None)?.report(jacobian);
    clear_upper_vector_state();
    Ok(report)
}

/// The block of inverse subspace iteration once the null-space count is settled, with its
/// Ritz values (ascending) and the thresholds they were judged by.
struct SettledBlock {
    x: Mat<f64>,
    ritz: Vec<f64>,
    threshold_lambda: f64,
    scale: f64,
}

impl SettledBlock {
    fn count(&self) -> usize {
        self.ritz.iter().filter(|&&l| l <= self.threshold_lambda).count()
    }

    fn report(&self, jacobian: &ClosureJacobian) -> RankReport {
        let count = self.count();
        let sigma = |l: f64| l.max(0.0).sqrt();
        RankReport {
            rank: jacobian.cols - count,
            // A locked column is zero, so it is in the null space without being a motion.
            dof: count.saturating_sub(jacobian.held),
            threshold: rank_tolerance(jacobian) * self.scale.sqrt(),
            smallest_kept: self.ritz.get(count).map_or(f64::INFINITY, |&l| sigma(l)),
            largest_dropped: if count > 0 { sigma(self.ritz[count - 1]) } else { 0.0 },
            method: RankMethod::SubspaceIteration,
            reduced: 0,
        }
    }
}

/// `reference`: the squared column norm the threshold is relative to (else JᵀJ's largest
/// diagonal).
fn settled_block(jacobian: &ClosureJacobian, reference: Option<f64>) -> Result<SettledBlock> {
    let n = jacobian.cols;
    let mut solver = NormalSolver::new(COUNT_REGULARISATION);
    let factor = solver.factor(jacobian)?;
    let scale = reference.unwrap_or(factor.max_diagonal);
    let threshold_lambda = rank_tolerance(jacobian) * rank_tolerance(jacobian) * scale;
    let cluster_lambda = CLUSTER_LEVEL * COUNT_REGULARISATION * factor.max_diagonal;
    let mut block = 8.min(n);
    // A fixed pseudo-random start (the count must not depend on the run). A doubled block
    // keeps the null directions already found and adds fresh columns.
    let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut fresh = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let mut x = Mat::<f64>::zeros(n, 0);
    loop {
        let kept = x.ncols();
        x = Mat::<f64>::from_fn(n, block, |i, j| if j < kept { x[(i, j)] } else { fresh() });
        let ritz = smallest_eigenvalues(jacobian, &factor, &mut x, threshold_lambda, cluster_lambda)?;
        let count = ritz.iter().filter(|&&l| l <= threshold_lambda).count();
        let within_cluster = ritz.last().is_some_and(|&l| l <= cluster_lambda);
        if (count < block && !within_cluster) || block == n {
            return Ok(SettledBlock {
                x,
                ritz,
                threshold_lambda,
                scale,
            });
        }
        block = (2 * block).min(n);
    }
}

/// An orthonormal basis of J's null space, one column per direction: the right singular
/// vectors whose singular values lie at or below [`RANK_TOL`] of the largest (dense SVD up
/// to [`DENSE_RANK_LIMIT`] columns), or the Ritz vectors of the settled block of the sparse
/// count counted as null (its singular values at or below RANK_TOL times the largest column
/// norm). Zero columns of J (locked creases) are in it like any other direction.
pub fn null_space(jacobian: &ClosureJacobian) -> Result<Mat<f64>> {
    let (rows, cols) = (jacobian.rows, jacobian.cols);
    if cols == 0 {
        return Ok(Mat::zeros(0, 0));
    }
    let (x, b) = if cols <= DENSE_RANK_LIMIT {
        let dense = jacobian.to_sparse().to_dense();
        let dense = if rows == 0 { Mat::<f64>::zeros(1, cols) } else { dense };
        let svd = dense.svd().map_err(|_| NumericalError::NonFinite {
            what: "singular values of J (null space)",
            detail: "the SVD did not converge".into(),
        })?;
        let s = svd.S().column_vector();
        let largest = (0..s.nrows()).map(|i| s[i]).fold(0.0_f64, f64::max);
        let threshold = rank_tolerance(jacobian) * largest;
        let v = svd.V();
        let null: Vec<usize> = (0..cols).filter(|&j| j >= s.nrows() || s[j] <= threshold).collect();
        let basis = Mat::<f64>::from_fn(cols, null.len(), |i, k| v[(i, null[k])]);
        (basis, null.len())
    } else {
        let settled = settled_block(jacobian, None)?;
        let count = settled.count();
        // Rotate the block onto the right singular vectors of JX, smallest first.
        let jx = apply_to_columns(jacobian, &settled.x);
        let svd = jx.svd().map_err(|_| NumericalError::NonFinite {
            what: "singular values of J X (null space)",
            detail: "the SVD did not converge".into(),
        })?;
        let v = svd.V();
        let b = settled.x.ncols();
        let s = svd.S().column_vector();
        let mut order: Vec<usize> = (0..b).collect();
        order.sort_by(|&i, &j| {
            let si = if i < s.nrows() { s[i] } else { 0.0 };
            let sj = if j < s.nrows() { s[j] } else { 0.0 };
            si.total_cmp(&sj)
        });
        let rotated = &settled.x * v;
        let basis = Mat::<f64>::from_fn(cols, count, |i, k| rotated[(i, order[k])]);
        (basis, count)
    };
    debug_assert_eq!(x.ncols(), b);
    clear_upper_vector_state();
    Ok(x)
}

/// J X, column by column.
fn apply_to_columns(jacobian: &ClosureJacobian, x: &Mat<f64>) -> Mat<f64> {
    let (n, b) = (x.nrows(), x.ncols());
    let mut jx = Mat::<f64>::zeros(jacobian.rows.max(1), b);
    let mut column = vec![0.0; n];
    let mut image = vec![0.0; jacobian.rows];
    for j in 0..b {
        for (k, c) in column.iter_mut().enumerate() {
            *c = x[(k, j)];
        }
        jacobian.apply(&column, &mut image);
        for (r, v) in image.iter().enumerate() {
            jx[(r, j)] = *v;
        }
    }
    jx
}

/// Ritz values (ascending) of JᵀJ on the block that inverse subspace iteration settles on,
/// starting from X and leaving its last iterate there.
///
/// Ritz values bound the eigenvalues from above (the k-th Ritz value is at least the k-th
/// eigenvalue), so a block whose every Ritz value is at or below `threshold` holds that many
/// null directions for certain, and the iteration stops at once; so it does when every Ritz
/// value is within the `cluster` level (the block is to be widened). Otherwise it stops when all
/// Ritz values settle, or earlier when the count at or below `threshold` has held and the
/// first value above it has settled [`COUNT_GAP`] times above it: an uncaught null direction
/// grows by that ratio each iteration, so it could not stay hidden.
fn smallest_eigenvalues(
    jacobian: &ClosureJacobian,
    factor: &super::normal::NormalFactor,
    x: &mut Mat<f64>,
    threshold: f64,
    cluster: f64,
) -> Result<Vec<f64>> {
    let count_of = |ritz: &[f64]| ritz.iter().filter(|&&l| l <= threshold).count();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(1e-3 * factor.max_diagonal * RANK_TOL * RANK_TOL);
    let mut previous: Vec<f64> = Vec::new();
    for iteration in 0..60 {
        factor.solve_many(x.as_mut());
        orthonormalise(x);
        let ritz = rayleigh_ritz(jacobian, x)?;
        let count = count_of(&ritz);
        // Every Ritz value counted, or all within the unresolved cluster: a wider block
        // is needed either way (Ritz values only fall with more iterations).
        let needs_wider_block = count == ritz.len() || ritz.last().is_some_and(|&l| l <= cluster);
        let all_settled = previous.len() == ritz.len() && ritz.iter().zip(&previous).all(|(a, b)| close(*a, *b));
        let count_settled = iteration >= 2
            && previous.len() == ritz.len()
            && count < ritz.len()
            && count_of(&previous) == count
            && ritz[count] >= COUNT_GAP * threshold
            && close(ritz[count], previous[count]);
        previous = ritz;
        if needs_wider_block || all_settled || count_settled {
            break;
        }
    }
    Ok(previous)
}

/// Orthonormal columns spanning X's (Householder QR, faer's blocked kernels).
fn orthonormalise(x: &mut Mat<f64>) {
    let (rows, cols) = (x.nrows(), x.ncols());
    let block = qr::no_pivoting::factor::recommended_block_size::<f64>(rows, cols);
    let mut householder = Mat::<f64>::zeros(block, cols.min(rows));
    let req = StackReq::any_of(&[
        qr::no_pivoting::factor::qr_in_place_scratch::<f64>(rows, cols, block, Par::Seq, Default::default()),
        householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(rows, block, cols),
    ]);
    let mut buffer = MemBuffer::new(req);
    qr::no_pivoting::factor::qr_in_place(
        x.as_mut(),
        householder.as_mut(),
        Par::Seq,
        MemStack::new(&mut buffer),
        Default::default(),
    );
    // Q's first columns: Q applied to the identity's.
    let mut q = Mat::<f64>::from_fn(rows, cols, |i, j| if i == j { 1.0 } else { 0.0 });
    householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
        x.as_ref(),
        householder.as_ref(),
        faer::Conj::No,
        q.as_mut(),
        Par::Seq,
        MemStack::new(&mut buffer),
    );
    *x = q;
}

/// Eigenvalues (ascending) of XᵀJᵀJX for orthonormal X, as the squared singular values of
/// JX: the singular values keep their absolute accuracy (ε‖J‖) where the eigenvalues of the
/// Gram matrix would lose the small ones below √ε.
fn rayleigh_ritz(jacobian: &ClosureJacobian, x: &Mat<f64>) -> Result<Vec<f64>> {
    let b = x.ncols();
    let jx = apply_to_columns(jacobian, x);
    // Sequential: at these sizes faer's threads cost more than they save on 2 cores.
    let (rows, cols) = (jx.nrows(), jx.ncols());
    let req = svd_scratch::<f64>(
        rows,
        cols,
        ComputeSvdVectors::No,
        ComputeSvdVectors::No,
        Par::Seq,
        Default::default(),
    );
    let mut buffer = MemBuffer::new(req);
    let mut singular = Diag::<f64>::zeros(rows.min(cols));
    svd(
        jx.as_ref(),
        singular.as_mut(),
        None,
        None,
        Par::Seq,
        MemStack::new(&mut buffer),
        Default::default(),
    )
    .map_err(|_| NumericalError::NonFinite {
        what: "singular values of J X (sparse DOF count)",
        detail: "the SVD did not converge".into(),
    })?;
    let mut values: Vec<f64> = singular.column_vector().iter().map(|s| s * s).collect();
    // JX has min(rows, b) singular values; a block wider than J is tall has zeros besides.
    values.resize(b, 0.0);
    values.sort_by(f64::total_cmp);
    Ok(values)
}
