//! The constraint Jacobian in tangent coordinates and the projection onto its null space
//! (SPEC §5): a banded Cholesky of the open chain's rows plus a small Schur complement for
//! the rows that close the loop, O(n) per factorisation; a dense SVD is the reference and
//! the fallback.

use crate::error::{NumericalError, Result};
use clarabel::algebra::CscMatrix;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Relative singular-value threshold below which a constraint direction is taken as
/// dependent (the rank drop at the flat state, SPEC §9).
pub const RANK_TOL: f64 = 1e-10;

/// Nodes one row may touch: three for a fold angle, two for an arc or an antipodal pair.
const MAX_NODES_PER_ROW: usize = 4;

/// One constraint row: its gradient on at most four free nodes, two tangent components each.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct JacobianRow {
    /// (slot of the free node, the two tangent components), slots distinct.
    entries: [(usize, [f64; 2]); MAX_NODES_PER_ROW],
    len: usize,
    /// A row that closes the loop (or pins distant nodes) and may become dependent on the
    /// others, as the closing arc does at the flat state. The remaining rows form an open
    /// chain: each has its own pivot node (the highest slot it touches) and they stay
    /// independent.
    pub closing: bool,
}

impl JacobianRow {
    pub fn clear(&mut self, closing: bool) {
        self.len = 0;
        self.closing = closing;
    }

    /// Adds `gradient` on the two tangent coordinates of free node `slot`.
    pub fn add(&mut self, slot: usize, gradient: [f64; 2]) {
        if let Some(entry) = self.entries[..self.len].iter_mut().find(|e| e.0 == slot) {
            entry.1[0] += gradient[0];
            entry.1[1] += gradient[1];
            return;
        }
        assert!(
            self.len < MAX_NODES_PER_ROW,
            "a constraint row touches at most four nodes"
        );
        self.entries[self.len] = (slot, gradient);
        self.len += 1;
    }

    pub fn entries(&self) -> &[(usize, [f64; 2])] {
        &self.entries[..self.len]
    }

    fn dot(&self, y: &DVector<f64>) -> f64 {
        self.entries()
            .iter()
            .map(|(s, g)| g[0] * y[2 * s] + g[1] * y[2 * s + 1])
            .sum()
    }

    /// y += scale · rowᵀ.
    fn axpy(&self, scale: f64, y: &mut DVector<f64>) {
        for (s, g) in self.entries() {
            y[2 * s] += scale * g[0];
            y[2 * s + 1] += scale * g[1];
        }
    }

    fn dot_row(&self, other: &JacobianRow) -> f64 {
        let mut sum = 0.0;
        for (s, g) in self.entries() {
            for (t, h) in other.entries() {
                if s == t {
                    sum += g[0] * h[0] + g[1] * h[1];
                }
            }
        }
        sum
    }

    fn norm_squared(&self) -> f64 {
        self.entries().iter().map(|(_, g)| g[0] * g[0] + g[1] * g[1]).sum()
    }

    fn lowest_slot(&self) -> usize {
        self.entries().iter().map(|e| e.0).min().unwrap_or(0)
    }

    fn pivot_slot(&self) -> usize {
        self.entries().iter().map(|e| e.0).max().unwrap_or(0)
    }
}

/// The sparse constraint Jacobian A: one row per constraint, two columns per free node.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConstraintJacobian {
    pub columns: usize,
    pub rows: Vec<JacobianRow>,
}

impl ConstraintJacobian {
    pub fn new(rows: usize, columns: usize) -> ConstraintJacobian {
        ConstraintJacobian {
            columns,
            rows: vec![JacobianRow::default(); rows],
        }
    }

    /// A dense matrix as open-chain rows (at most four node pairs per row); for tests.
    pub fn from_dense(a: &DMatrix<f64>, closing: &[bool]) -> ConstraintJacobian {
        assert!(a.ncols().is_multiple_of(2), "two tangent columns per node");
        let mut jacobian = ConstraintJacobian::new(a.nrows(), a.ncols());
        for (r, row) in jacobian.rows.iter_mut().enumerate() {
            row.clear(closing[r]);
            for slot in 0..a.ncols() / 2 {
                let gradient = [a[(r, 2 * slot)], a[(r, 2 * slot + 1)]];
                if gradient != [0.0, 0.0] {
                    row.add(slot, gradient);
                }
            }
        }
        jacobian
    }

    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.rows.len(), self.columns);
        for (r, row) in self.rows.iter().enumerate() {
            for (s, g) in row.entries() {
                a[(r, 2 * s)] = g[0];
                a[(r, 2 * s + 1)] = g[1];
            }
        }
        a
    }

    pub fn to_csc(&self) -> CscMatrix<f64> {
        let mut by_column: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.columns];
        for (r, row) in self.rows.iter().enumerate() {
            for (s, g) in row.entries() {
                for k in 0..2 {
                    if g[k] != 0.0 {
                        by_column[2 * s + k].push((r, g[k]));
                    }
                }
            }
        }
        let mut colptr = vec![0];
        let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
        for column in &mut by_column {
            column.sort_by_key(|e| e.0);
            rowval.extend(column.iter().map(|e| e.0));
            nzval.extend(column.iter().map(|e| e.1));
            colptr.push(rowval.len());
        }
        CscMatrix::new(self.rows.len(), self.columns, colptr, rowval, nzval)
    }

    /// A y.
    pub fn mul(&self, y: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(self.rows.len(), self.rows.iter().map(|row| row.dot(y)))
    }

    /// Aᵀ v.
    pub fn mul_transpose(&self, v: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(self.columns);
        for (row, value) in self.rows.iter().zip(v.iter()) {
            row.axpy(*value, &mut out);
        }
        out
    }

    fn largest_row_norm(&self) -> f64 {
        self.rows.iter().map(|r| r.norm_squared()).fold(0.0, f64::max).sqrt()
    }
}

/// Cholesky factor L of a symmetric positive definite band matrix (half-bandwidth w),
/// row i holding L[i, i−w..=i].
#[derive(Debug, Clone)]
struct BandedCholesky {
    size: usize,
    width: usize,
    factor: Vec<f64>,
}

impl BandedCholesky {
    /// Factorises the matrix whose (i, j) entry for |i − j| ≤ w is `entry(i, j)`. None when
    /// a pivot falls below `relative_pivot` times the largest diagonal entry.
    fn new(size: usize, width: usize, entry: impl Fn(usize, usize) -> f64, relative_pivot: f64) -> Option<Self> {
        let stride = width + 1;
        let mut factor = vec![0.0; size * stride];
        let largest_diagonal = (0..size).map(|i| entry(i, i)).fold(0.0, f64::max);
        for i in 0..size {
            let first = i.saturating_sub(width);
            for j in first..=i {
                let mut sum = entry(i, j);
                for k in first.max(j.saturating_sub(width))..j {
                    sum -= factor[i * stride + k + width - i] * factor[j * stride + k + width - j];
                }
                if i == j {
                    // Also refuses a NaN pivot.
                    if sum.is_nan() || sum <= relative_pivot * largest_diagonal {
                        return None;
                    }
                    factor[i * stride + width] = sum.sqrt();
                } else {
                    factor[i * stride + j + width - i] = sum / factor[j * stride + width];
                }
            }
        }
        Some(BandedCholesky { size, width, factor })
    }

    /// Solves L Lᵀ x = b in place.
    fn solve_in_place(&self, b: &mut [f64]) {
        let (w, stride) = (self.width, self.width + 1);
        for i in 0..self.size {
            let first = i.saturating_sub(w);
            let row = &self.factor[i * stride + first + w - i..i * stride + w];
            let sum: f64 = row.iter().zip(&b[first..i]).map(|(l, x)| l * x).sum();
            b[i] = (b[i] - sum) / self.factor[i * stride + w];
        }
        for i in (0..self.size).rev() {
            let end = (i + w + 1).min(self.size);
            let sum: f64 = (i + 1..end).map(|k| self.factor[k * stride + i + w - k] * b[k]).sum();
            b[i] = (b[i] - sum) / self.factor[i * stride + w];
        }
    }
}

/// The open-chain rows B (banded Gram matrix B Bᵀ) and the closing rows C, with
/// W = (I − B⁺B) Cᵀ and the eigen-decomposition of Wᵀ W kept above the rank threshold.
/// null(A) = null(B) ∩ null(C), so (I − A⁺A) g = P_B g − W (WᵀW)⁺ Wᵀ g.
#[derive(Debug, Clone)]
pub struct ChainRowSpace {
    dimension: usize,
    /// Open-chain rows sorted by pivot, and their indices in A.
    chain: Vec<JacobianRow>,
    chain_index: Vec<usize>,
    gram: BandedCholesky,
    closing: Vec<JacobianRow>,
    closing_index: Vec<usize>,
    /// P_B Cᵀ, one column per closing row.
    w: DMatrix<f64>,
    /// Generalised eigenvectors V (Vᵀ(I + ΛᵀΛ)V = I) and eigenvalues σ² of WᵀW above the
    /// threshold, so that (WᵀW)⁺ restricted to them is V diag(1/σ²) Vᵀ.
    schur_vectors: DMatrix<f64>,
    schur_values: Vec<f64>,
}

/// Smallest accepted Cholesky pivot of B Bᵀ relative to its largest diagonal entry: below
/// it (cond(B) beyond ~1e7) the dense SVD takes over.
const CHAIN_PIVOT_TOL: f64 = 1e-14;

impl ChainRowSpace {
    fn new(a: &ConstraintJacobian) -> Option<ChainRowSpace> {
        let mut chain_index: Vec<usize> = (0..a.rows.len()).filter(|&r| !a.rows[r].closing).collect();
        chain_index.sort_by_key(|&r| a.rows[r].pivot_slot());
        let chain: Vec<JacobianRow> = chain_index.iter().map(|&r| a.rows[r]).collect();
        // Half-bandwidth of B Bᵀ: with rows sorted by pivot, an earlier row meets a later one
        // only if its pivot reaches the later row's lowest slot.
        let width = chain
            .iter()
            .enumerate()
            .map(|(j, row)| j - chain.partition_point(|earlier| earlier.pivot_slot() < row.lowest_slot()))
            .max()
            .unwrap_or(0);
        let gram = BandedCholesky::new(chain.len(), width, |i, j| chain[i].dot_row(&chain[j]), CHAIN_PIVOT_TOL)?;
        let closing_index: Vec<usize> = (0..a.rows.len()).filter(|&r| a.rows[r].closing).collect();
        let closing: Vec<JacobianRow> = closing_index.iter().map(|&r| a.rows[r]).collect();
        let mut space = ChainRowSpace {
            dimension: a.columns,
            chain,
            chain_index,
            gram,
            closing,
            closing_index,
            w: DMatrix::zeros(a.columns, 0),
            schur_vectors: DMatrix::zeros(0, 0),
            schur_values: Vec::new(),
        };
        let k = space.closing.len();
        let mut w = DMatrix::zeros(a.columns, k);
        // Y Yᵀ-like weight: the vector y = (−(B Bᵀ)⁻¹ B Cᵀ μ, μ) has Aᵀ y = W μ, so the
        // singular values of A along the closing rows are those of W measured against
        // ‖y‖² = μᵀ (I + ΛᵀΛ) μ, Λ = (B Bᵀ)⁻¹ B Cᵀ.
        let mut multipliers = DMatrix::zeros(space.chain.len(), k);
        for (c, row) in space.closing.iter().enumerate() {
            let mut column = DVector::zeros(a.columns);
            row.axpy(1.0, &mut column);
            let (projected, lambda) = space.project_chain_with_multipliers(&column);
            w.set_column(c, &projected);
            multipliers.set_column(c, &DVector::from_vec(lambda));
        }
        space.w = w;
        if k == 0 {
            return Some(space);
        }
        // Generalised eigenproblem WᵀW v = σ² (I + ΛᵀΛ) v, through the Cholesky factor L of
        // I + ΛᵀΛ (≥ I, so well-conditioned): σ estimates A's smallest singular values, and
        // the rank test matches the dense one, σ > RANK_TOL·σ_max.
        let weight = DMatrix::identity(k, k) + multipliers.transpose() * &multipliers;
        let l = weight.cholesky()?.unpack();
        let l_inv = l.clone().try_inverse()?;
        let reduced = &l_inv * (space.w.transpose() * &space.w) * l_inv.transpose();
        let schur = SymmetricEigen::new((&reduced + reduced.transpose()) * 0.5);
        let threshold = (RANK_TOL * a.largest_row_norm().max(f64::MIN_POSITIVE)).powi(2);
        let keep: Vec<usize> = (0..k).filter(|&i| schur.eigenvalues[i] > threshold).collect();
        space.schur_vectors = l_inv.transpose() * schur.eigenvectors.select_columns(keep.iter());
        space.schur_values = keep.iter().map(|&i| schur.eigenvalues[i]).collect();
        Some(space)
    }

    /// (B Bᵀ)⁻¹ b for b in chain order.
    fn gram_solve(&self, mut b: Vec<f64>) -> Vec<f64> {
        self.gram.solve_in_place(&mut b);
        b
    }

    /// P_B y = y − Bᵀ (B Bᵀ)⁻¹ B y, with one step of refinement (the Gram matrix squares
    /// B's condition number; the refinement recovers it).
    fn project_chain(&self, y: &DVector<f64>) -> DVector<f64> {
        self.project_chain_with_multipliers(y).0
    }

    /// P_B y and the multipliers (B Bᵀ)⁻¹ B y.
    fn project_chain_with_multipliers(&self, y: &DVector<f64>) -> (DVector<f64>, Vec<f64>) {
        let mut p = y.clone();
        let mut total = vec![0.0; self.chain.len()];
        for _ in 0..2 {
            let lambda = self.gram_solve(self.chain.iter().map(|row| row.dot(&p)).collect());
            for ((row, l), t) in self.chain.iter().zip(&lambda).zip(total.iter_mut()) {
                row.axpy(-l, &mut p);
                *t += l;
            }
        }
        (p, total)
    }

    /// W (WᵀW)⁺ v for v indexed by closing row.
    fn schur_correction(&self, v: &DVector<f64>) -> DVector<f64> {
        let mut coefficients = self.schur_vectors.transpose() * v;
        for (c, value) in coefficients.iter_mut().zip(&self.schur_values) {
            *c /= value;
        }
        &self.w * (&self.schur_vectors * coefficients)
    }

    fn project_to_null(&self, g: &DVector<f64>) -> DVector<f64> {
        let p = self.project_chain(g);
        if self.closing.is_empty() {
            return p;
        }
        let v = self.w.transpose() * g;
        p - self.schur_correction(&v)
    }

    fn solve_min_norm(&self, r: &DVector<f64>) -> DVector<f64> {
        let lambda = self.gram_solve(self.chain_index.iter().map(|&i| r[i]).collect());
        let mut z = DVector::zeros(self.dimension);
        for (row, l) in self.chain.iter().zip(&lambda) {
            row.axpy(*l, &mut z);
        }
        if self.closing.is_empty() {
            return z;
        }
        let rest = DVector::from_iterator(
            self.closing.len(),
            self.closing
                .iter()
                .zip(&self.closing_index)
                .map(|(row, &i)| r[i] - row.dot(&z)),
        );
        z + self.schur_correction(&rest)
    }

    fn rank(&self) -> usize {
        self.chain.len() + self.schur_values.len()
    }
}

/// The SVD-based projector (the reference, and the fallback when the chain rows are
/// nearly dependent).
#[derive(Debug, Clone)]
pub struct DenseRowSpace {
    /// Right singular vectors with σ > RANK_TOL·σ_max, as rows.
    v_t: DMatrix<f64>,
    /// Matching left singular vectors (columns) and singular values.
    u: DMatrix<f64>,
    sigma: DVector<f64>,
}

impl DenseRowSpace {
    fn new(a: &DMatrix<f64>) -> Result<DenseRowSpace> {
        if a.nrows() == 0 {
            return Ok(DenseRowSpace {
                v_t: DMatrix::zeros(0, a.ncols()),
                u: DMatrix::zeros(0, 0),
                sigma: DVector::zeros(0),
            });
        }
        let svd = a.clone().svd(true, true);
        let (u, v_t) = match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => (u, v_t),
            _ => {
                return Err(NumericalError::Singular {
                    what: "SVD",
                    detail: "no singular vectors".into(),
                }
                .into())
            }
        };
        let sigma_max = svd.singular_values.max();
        let keep: Vec<usize> = (0..svd.singular_values.len())
            .filter(|&i| svd.singular_values[i] > RANK_TOL * sigma_max.max(f64::MIN_POSITIVE))
            .collect();
        let sigma = DVector::from_iterator(keep.len(), keep.iter().map(|&i| svd.singular_values[i]));
        if sigma.iter().any(|s| !s.is_finite()) {
            return Err(NumericalError::NonFinite {
                what: "SVD",
                detail: "a singular value".into(),
            }
            .into());
        }
        Ok(DenseRowSpace {
            v_t: v_t.select_rows(keep.iter()),
            u: u.select_columns(keep.iter()),
            sigma,
        })
    }

    fn project_to_null(&self, w: &DVector<f64>) -> DVector<f64> {
        let coefficients = &self.v_t * w;
        w - self.v_t.transpose() * coefficients
    }

    fn solve_min_norm(&self, r: &DVector<f64>) -> DVector<f64> {
        let mut coefficients = self.u.transpose() * r;
        for (c, s) in coefficients.iter_mut().zip(self.sigma.iter()) {
            *c /= s;
        }
        self.v_t.transpose() * coefficients
    }
}

#[derive(Debug, Clone)]
enum Factorisation {
    Chain(ChainRowSpace),
    Dense(DenseRowSpace),
}

/// The projector onto the row space of A, reused for the direction, the Newton
/// restoration of the constraints and the restart kicks.
#[derive(Debug, Clone)]
pub struct RowSpace {
    factorisation: Factorisation,
    /// Columns of A (tangent coordinates).
    pub dimension: usize,
}

impl RowSpace {
    /// Factorises A by its chain structure, O(rows) plus the closing rows' Schur
    /// complement; falls back on the dense SVD if the chain rows are nearly dependent.
    pub fn new(a: &ConstraintJacobian) -> Result<RowSpace> {
        if a.rows
            .iter()
            .any(|r| r.entries().iter().any(|(_, g)| !g[0].is_finite() || !g[1].is_finite()))
        {
            return Err(NumericalError::NonFinite {
                what: "constraint Jacobian",
                detail: "an entry".into(),
            }
            .into());
        }
        match ChainRowSpace::new(a) {
            Some(chain) => Ok(RowSpace {
                factorisation: Factorisation::Chain(chain),
                dimension: a.columns,
            }),
            None => RowSpace::dense(a),
        }
    }

    /// The dense SVD of A (the reference).
    pub fn dense(a: &ConstraintJacobian) -> Result<RowSpace> {
        Ok(RowSpace {
            factorisation: Factorisation::Dense(DenseRowSpace::new(&a.to_dense())?),
            dimension: a.columns,
        })
    }

    /// Whether the chain factorisation is in use (false: the dense fallback).
    pub fn is_banded(&self) -> bool {
        matches!(self.factorisation, Factorisation::Chain(_))
    }

    /// Numerical rank of A.
    pub fn rank(&self) -> usize {
        match &self.factorisation {
            Factorisation::Chain(c) => c.rank(),
            Factorisation::Dense(d) => d.sigma.len(),
        }
    }

    /// Dimension of the null space: the first-order degrees of freedom.
    pub fn null_dimension(&self) -> usize {
        self.dimension - self.rank()
    }

    /// (I − A⁺A) w: the component of `w` in the null space of A.
    pub fn project_to_null(&self, w: &DVector<f64>) -> DVector<f64> {
        match &self.factorisation {
            Factorisation::Chain(c) => c.project_to_null(w),
            Factorisation::Dense(d) => d.project_to_null(w),
        }
    }

    /// Minimum-norm z with A z = r (least squares on the dependent closing directions).
    pub fn solve_min_norm(&self, r: &DVector<f64>) -> DVector<f64> {
        match &self.factorisation {
            Factorisation::Chain(c) => c.solve_min_norm(r),
            Factorisation::Dense(d) => d.solve_min_norm(r),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn banded_cholesky_matches_a_dense_solve() {
        // A pentadiagonal SPD matrix.
        let n = 9;
        let entry = |i: usize, j: usize| match i.abs_diff(j) {
            0 => 6.0 + i as f64 * 0.1,
            1 => -1.5,
            2 => 0.4,
            _ => 0.0,
        };
        let dense = DMatrix::from_fn(n, n, entry);
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 0.5).collect();
        let cholesky = BandedCholesky::new(n, 2, entry, 1e-14).unwrap();
        let mut x = b.clone();
        cholesky.solve_in_place(&mut x);
        let expected = dense.cholesky().unwrap().solve(&DVector::from_vec(b));
        assert!((DVector::from_vec(x) - expected).amax() < 1e-14);
        // Indefinite: refused, not a NaN.
        assert!(BandedCholesky::new(2, 1, |i, j| if i == j { 1.0 } else { 2.0 }, 1e-14).is_none());
    }

    #[test]
    fn chain_and_dense_agree_with_dependent_closing_rows() {
        // Three nodes; rows 0–2 an open chain, row 3 closing and independent, row 4 closing
        // and the sum of rows 0 and 3 (dependent).
        #[rustfmt::skip]
        let a = DMatrix::from_row_slice(5, 6, &[
            1.0, 0.2, 0.0, 0.0, 0.0, 0.0,
            0.5, -1.0, 1.0, 0.3, 0.0, 0.0,
            0.0, 0.0, -0.7, 0.1, 0.9, 1.1,
            0.3, 0.0, 0.0, 0.0, 1.0, -0.4,
            1.3, 0.2, 0.0, 0.0, 1.0, -0.4,
        ]);
        let jacobian = ConstraintJacobian::from_dense(&a, &[false, false, false, true, true]);
        let chain = RowSpace::new(&jacobian).unwrap();
        let dense = RowSpace::dense(&jacobian).unwrap();
        assert!(chain.is_banded() && !dense.is_banded());
        assert_eq!((chain.rank(), dense.rank()), (4, 4));
        let g = DVector::from_vec(vec![0.3, -1.0, 2.0, 0.5, -0.2, 0.7]);
        assert!((chain.project_to_null(&g) - dense.project_to_null(&g)).amax() < 1e-14);
        // A consistent right-hand side: both give the same minimum-norm solution.
        let r = &a * DVector::from_vec(vec![0.1, 0.2, -0.3, 0.4, 0.0, 0.6]);
        let (zc, zd) = (chain.solve_min_norm(&r), dense.solve_min_norm(&r));
        assert!((&zc - &zd).amax() < 1e-13, "{zc} vs {zd}");
        assert!((&a * zc - r).amax() < 1e-13);
    }

    #[test]
    fn nearly_dependent_chain_rows_fall_back_on_the_svd() {
        #[rustfmt::skip]
        let a = DMatrix::from_row_slice(2, 4, &[
            1.0, 0.0, 0.0, 0.0,
            1.0, 1e-9, 0.0, 0.0,
        ]);
        let jacobian = ConstraintJacobian::from_dense(&a, &[false, false]);
        let space = RowSpace::new(&jacobian).unwrap();
        assert!(!space.is_banded());
        assert_eq!(space.rank(), 2);
    }

    #[test]
    fn sparse_products_match_the_dense_matrix() {
        #[rustfmt::skip]
        let a = DMatrix::from_row_slice(2, 4, &[
            1.0, 2.0, 0.0, -1.0,
            0.0, 0.0, 1.5, 3.0,
        ]);
        let jacobian = ConstraintJacobian::from_dense(&a, &[false, true]);
        assert_eq!(jacobian.to_dense(), a);
        let y = DVector::from_vec(vec![0.5, -1.0, 2.0, 0.25]);
        assert!((jacobian.mul(&y) - &a * &y).amax() < 1e-15);
        let csc = jacobian.to_csc();
        assert_eq!((csc.m, csc.n, csc.nzval.len()), (2, 4, 5));
    }
}
