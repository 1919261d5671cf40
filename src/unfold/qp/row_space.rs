//! The constraint Jacobian in tangent coordinates and the projection onto its null space
//! (`docs/model.md#projected-gradient`): a banded Cholesky of the open chain's rows plus a
//! small Schur complement (faer's dense Cholesky and symmetric eigensolver) for the rows
//! that close the loop, O(n) per factorisation and no allocation once its buffers have
//! grown; a dense SVD is the reference and the fallback.

use crate::error::{NumericalError, Result};
use clarabel::algebra::CscMatrix;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::evd::{self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors};
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use faer::{MatMut, MatRef, Par};
use nalgebra::{DMatrix, DVector};

/// Relative singular-value threshold below which a constraint direction is taken as
/// dependent (the rank drop at the flat state, `docs/model.md#hard-cases`).
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
    /// Empties the row and marks whether it closes the loop.
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

    /// The (slot, gradient) pairs.
    pub fn entries(&self) -> &[(usize, [f64; 2])] {
        &self.entries[..self.len]
    }

    fn dot(&self, y: &[f64]) -> f64 {
        self.entries()
            .iter()
            .map(|(s, g)| g[0] * y[2 * s] + g[1] * y[2 * s + 1])
            .sum()
    }

    /// y += scale · rowᵀ.
    fn axpy(&self, scale: f64, y: &mut [f64]) {
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
    /// Columns: two tangent coordinates per free node.
    pub columns: usize,
    /// The rows.
    pub rows: Vec<JacobianRow>,
}

impl ConstraintJacobian {
    /// `rows` empty rows over `columns` columns.
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

    /// The dense matrix.
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

    /// The matrix in Clarabel's compressed-column form.
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
        DVector::from_iterator(self.rows.len(), self.rows.iter().map(|row| row.dot(y.as_slice())))
    }

    /// Aᵀ v.
    pub fn mul_transpose(&self, v: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(self.columns);
        for (row, value) in self.rows.iter().zip(v.iter()) {
            row.axpy(*value, out.as_mut_slice());
        }
        out
    }

    fn largest_row_norm(&self) -> f64 {
        self.rows.iter().map(|r| r.norm_squared()).fold(0.0, f64::max).sqrt()
    }

    fn has_non_finite_entry(&self) -> bool {
        self.rows
            .iter()
            .any(|r| r.entries().iter().any(|(_, g)| !g[0].is_finite() || !g[1].is_finite()))
    }
}

/// Cholesky factor L of a symmetric positive definite band matrix (half-bandwidth w),
/// row i holding L[i, i−w..=i]; its buffer is reused from one factorisation to the next.
#[derive(Debug, Clone, Default)]
struct BandedCholesky {
    size: usize,
    width: usize,
    factor: Vec<f64>,
}

impl BandedCholesky {
    /// Factorises the matrix whose (i, j) entry for |i − j| ≤ w is `entry(i, j)`. False when
    /// a pivot falls below `relative_pivot` times the largest diagonal entry.
    fn factorise(
        &mut self,
        size: usize,
        width: usize,
        entry: impl Fn(usize, usize) -> f64,
        relative_pivot: f64,
    ) -> bool {
        let stride = width + 1;
        self.size = size;
        self.width = width;
        self.factor.clear();
        self.factor.resize(size * stride, 0.0);
        let factor = &mut self.factor;
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
                        return false;
                    }
                    factor[i * stride + width] = sum.sqrt();
                } else {
                    factor[i * stride + j + width - i] = sum / factor[j * stride + width];
                }
            }
        }
        true
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

/// Smallest accepted Cholesky pivot of B Bᵀ relative to its largest diagonal entry: below
/// it (cond(B) beyond ~1e7) the dense SVD takes over.
const CHAIN_PIVOT_TOL: f64 = 1e-14;

/// The open-chain rows B (banded Gram matrix B Bᵀ) and the closing rows C, with
/// W = (I − B⁺B) Cᵀ and the eigen-decomposition of Wᵀ W kept above the rank threshold.
/// null(A) = null(B) ∩ null(C), so (I − A⁺A) g = P_B g − W (WᵀW)⁺ Wᵀ g.
#[derive(Debug, Default)]
struct ChainFactors {
    /// Open-chain rows sorted by pivot, and their indices in A.
    chain: Vec<JacobianRow>,
    chain_index: Vec<usize>,
    gram: BandedCholesky,
    closing: Vec<JacobianRow>,
    closing_index: Vec<usize>,
    /// P_B Cᵀ, column-major, one column per closing row.
    w: Vec<f64>,
    /// (B Bᵀ)⁻¹ B Cᵀ, column-major.
    multipliers: Vec<f64>,
    /// k × k scratch: I + ΛᵀΛ (then its Cholesky factor L), the reduced WᵀW, eigenvectors.
    weight: Vec<f64>,
    reduced: Vec<f64>,
    eigenvectors: Vec<f64>,
    eigenvalues: Vec<f64>,
    /// Generalised eigenvectors V (Vᵀ(I + ΛᵀΛ)V = I), column-major k × kept, and the
    /// eigenvalues σ² of WᵀW above the threshold: (WᵀW)⁺ restricted to them is V diag(1/σ²) Vᵀ.
    schur_vectors: Vec<f64>,
    schur_values: Vec<f64>,
    /// faer's scratch, and the k it is sized for.
    stack: Option<Scratch>,
    stack_size: usize,
    /// Vectors of the columns' and the rows' sizes.
    column_a: Vec<f64>,
    column_b: Vec<f64>,
    chain_a: Vec<f64>,
    chain_b: Vec<f64>,
    small_a: Vec<f64>,
    small_b: Vec<f64>,
}

/// faer's memory for the small dense factorisations.
struct Scratch(MemBuffer);

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Scratch({} bytes)", self.0.len())
    }
}

/// Sorts row indices by pivot, ties in their original order, without allocating (the
/// metric's augmented rows come in two sorted runs, so an insertion sort would be
/// quadratic).
fn sort_by_pivot(index: &mut [usize], rows: &[JacobianRow]) {
    index.sort_unstable_by_key(|&r| (rows[r].pivot_slot(), r));
}

impl ChainFactors {
    /// Factorises A; false when the chain rows are nearly dependent (the SVD takes over).
    fn factorise(&mut self, a: &ConstraintJacobian) -> bool {
        let dimension = a.columns;
        self.chain_index.clear();
        self.chain_index
            .extend((0..a.rows.len()).filter(|&r| !a.rows[r].closing));
        sort_by_pivot(&mut self.chain_index, &a.rows);
        self.chain.clear();
        self.chain.extend(self.chain_index.iter().map(|&r| a.rows[r]));
        let chain = &self.chain;
        // Half-bandwidth of B Bᵀ: with rows sorted by pivot, an earlier row meets a later one
        // only if its pivot reaches the later row's lowest slot.
        let width = chain
            .iter()
            .enumerate()
            .map(|(j, row)| j - chain.partition_point(|earlier| earlier.pivot_slot() < row.lowest_slot()))
            .max()
            .unwrap_or(0);
        if !self
            .gram
            .factorise(chain.len(), width, |i, j| chain[i].dot_row(&chain[j]), CHAIN_PIVOT_TOL)
        {
            return false;
        }
        self.closing_index.clear();
        self.closing_index
            .extend((0..a.rows.len()).filter(|&r| a.rows[r].closing));
        self.closing.clear();
        self.closing.extend(self.closing_index.iter().map(|&r| a.rows[r]));
        let (m, k) = (self.chain.len(), self.closing.len());
        for buffer in [&mut self.column_a, &mut self.column_b] {
            buffer.resize(dimension, 0.0);
        }
        for buffer in [&mut self.chain_a, &mut self.chain_b] {
            buffer.resize(m, 0.0);
        }
        self.w.resize(dimension * k, 0.0);
        self.multipliers.resize(m * k, 0.0);
        self.schur_vectors.clear();
        self.schur_values.clear();
        if k == 0 {
            return true;
        }
        // Y Yᵀ-like weight: the vector y = (−(B Bᵀ)⁻¹ B Cᵀ μ, μ) has Aᵀ y = W μ, so the
        // singular values of A along the closing rows are those of W measured against
        // ‖y‖² = μᵀ (I + ΛᵀΛ) μ, Λ = (B Bᵀ)⁻¹ B Cᵀ.
        for c in 0..k {
            self.column_a.iter_mut().for_each(|x| *x = 0.0);
            self.closing[c].axpy(1.0, &mut self.column_a);
            self.project_chain(c);
        }
        for buffer in [&mut self.weight, &mut self.reduced, &mut self.eigenvectors] {
            buffer.clear();
            buffer.resize(k * k, 0.0);
        }
        self.eigenvalues.resize(k, 0.0);
        self.small_a.resize(k, 0.0);
        self.small_b.resize(k, 0.0);
        for i in 0..k {
            for j in 0..k {
                let lambda_i = &self.multipliers[i * m..(i + 1) * m];
                let lambda_j = &self.multipliers[j * m..(j + 1) * m];
                let w_i = &self.w[i * dimension..(i + 1) * dimension];
                let w_j = &self.w[j * dimension..(j + 1) * dimension];
                let identity = if i == j { 1.0 } else { 0.0 };
                self.weight[i + j * k] = identity + dot(lambda_i, lambda_j);
                self.reduced[i + j * k] = dot(w_i, w_j);
            }
        }
        // Generalised eigenproblem WᵀW v = σ² (I + ΛᵀΛ) v, through the Cholesky factor L of
        // I + ΛᵀΛ (≥ I, so well-conditioned): σ estimates A's smallest singular values, and
        // the rank test matches the dense one, σ > RANK_TOL·σ_max.
        self.ensure_stack(k);
        let stack = MemStack::new(&mut self.stack.as_mut().expect("sized by ensure_stack").0);
        let mut l = MatMut::from_column_major_slice_mut(&mut self.weight, k, k);
        if cholesky_in_place(l.as_mut(), Default::default(), Par::Seq, stack, Default::default()).is_err() {
            return false;
        }
        let l = MatRef::from_column_major_slice(&self.weight, k, k);
        // reduced ← L⁻¹ WᵀW L⁻ᵀ by two triangular solves (the second on the transpose).
        {
            let mut x = MatMut::from_column_major_slice_mut(&mut self.reduced, k, k);
            solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
            for i in 0..k {
                for j in 0..i {
                    let (a, b) = (x[(i, j)], x[(j, i)]);
                    x[(i, j)] = b;
                    x[(j, i)] = a;
                }
            }
            solve_lower_triangular_in_place(l, x.as_mut(), Par::Seq);
            for i in 0..k {
                for j in 0..i {
                    let mean = 0.5 * (x[(i, j)] + x[(j, i)]);
                    x[(i, j)] = mean;
                    x[(j, i)] = mean;
                }
            }
        }
        let stack = MemStack::new(&mut self.stack.as_mut().expect("sized by ensure_stack").0);
        let reduced = MatRef::from_column_major_slice(&self.reduced, k, k);
        let values = faer::diag::DiagMut::from_slice_mut(&mut self.eigenvalues);
        let vectors = MatMut::from_column_major_slice_mut(&mut self.eigenvectors, k, k);
        if self_adjoint_evd(reduced, values, Some(vectors), Par::Seq, stack, Default::default()).is_err() {
            return false;
        }
        let threshold = (RANK_TOL * a.largest_row_norm().max(f64::MIN_POSITIVE)).powi(2);
        for i in 0..k {
            if self.eigenvalues[i] > threshold {
                self.schur_values.push(self.eigenvalues[i]);
                self.schur_vectors
                    .extend_from_slice(&self.eigenvectors[i * k..(i + 1) * k]);
            }
        }
        // V = L⁻ᵀ U: solve Lᵀ V = U.
        let kept = self.schur_values.len();
        let v = MatMut::from_column_major_slice_mut(&mut self.schur_vectors, k, kept);
        solve_upper_triangular_in_place(l.transpose(), v, Par::Seq);
        crate::folding::simd_state::clear_upper_vector_state();
        true
    }

    /// faer's scratch for k × k Cholesky and eigen-decomposition (grown, never shrunk).
    fn ensure_stack(&mut self, k: usize) {
        if self.stack.is_some() && self.stack_size >= k {
            return;
        }
        let req = StackReq::any_of(&[
            cholesky_in_place_scratch::<f64>(k, Par::Seq, Default::default()),
            self_adjoint_evd_scratch::<f64>(k, ComputeEigenvectors::Yes, Par::Seq, Default::default()),
        ]);
        self.stack = Some(Scratch(MemBuffer::new(req)));
        self.stack_size = k;
    }

    /// P_B of `column_a` into column `c` of W, its multipliers into column `c` of Λ.
    fn project_chain(&mut self, c: usize) {
        let (dimension, m) = (self.column_a.len(), self.chain.len());
        self.chain_b.iter_mut().for_each(|t| *t = 0.0);
        for _ in 0..2 {
            for (lambda, row) in self.chain_a.iter_mut().zip(&self.chain) {
                *lambda = row.dot(&self.column_a);
            }
            self.gram.solve_in_place(&mut self.chain_a);
            for ((row, l), t) in self.chain.iter().zip(&self.chain_a).zip(self.chain_b.iter_mut()) {
                row.axpy(-l, &mut self.column_a);
                *t += l;
            }
        }
        self.w[c * dimension..(c + 1) * dimension].copy_from_slice(&self.column_a);
        self.multipliers[c * m..(c + 1) * m].copy_from_slice(&self.chain_b);
    }

    /// P_B y = y − Bᵀ (B Bᵀ)⁻¹ B y into `out`, with one step of refinement (the Gram matrix
    /// squares B's condition number; the refinement recovers it).
    fn project_chain_into(&mut self, y: &[f64], out: &mut [f64]) {
        out.copy_from_slice(y);
        for _ in 0..2 {
            for (lambda, row) in self.chain_a.iter_mut().zip(&self.chain) {
                *lambda = row.dot(out);
            }
            self.gram_solve_chain_a();
            for (row, l) in self.chain.iter().zip(&self.chain_a) {
                row.axpy(-l, out);
            }
        }
    }

    fn gram_solve_chain_a(&mut self) {
        let (gram, b) = (&self.gram, &mut self.chain_a);
        gram.solve_in_place(b);
    }

    /// out −= W (WᵀW)⁺ v with v = `small_a` (one entry per closing row).
    fn subtract_schur_correction(&mut self, out: &mut [f64], sign: f64) {
        let (dimension, k, kept) = (out.len(), self.closing.len(), self.schur_values.len());
        // coefficients = V diag(1/σ²) Vᵀ v, then out −= W · coefficients.
        self.small_b.iter_mut().for_each(|x| *x = 0.0);
        for j in 0..kept {
            let column = &self.schur_vectors[j * k..(j + 1) * k];
            let scale = dot(column, &self.small_a) / self.schur_values[j];
            for (b, v) in self.small_b.iter_mut().zip(column) {
                *b += scale * v;
            }
        }
        for c in 0..k {
            let coefficient = self.small_b[c];
            if coefficient != 0.0 {
                for (o, w) in out.iter_mut().zip(&self.w[c * dimension..(c + 1) * dimension]) {
                    *o -= sign * coefficient * w;
                }
            }
        }
    }

    fn project_to_null(&mut self, g: &[f64], out: &mut [f64]) {
        self.project_chain_into(g, out);
        let (dimension, k) = (g.len(), self.closing.len());
        if k == 0 {
            return;
        }
        for c in 0..k {
            self.small_a[c] = dot(&self.w[c * dimension..(c + 1) * dimension], g);
        }
        self.subtract_schur_correction(out, 1.0);
    }

    fn solve_min_norm(&mut self, r: &[f64], out: &mut [f64]) {
        for (lambda, &i) in self.chain_a.iter_mut().zip(&self.chain_index) {
            *lambda = r[i];
        }
        self.gram_solve_chain_a();
        out.iter_mut().for_each(|x| *x = 0.0);
        for (row, l) in self.chain.iter().zip(&self.chain_a) {
            row.axpy(*l, out);
        }
        let k = self.closing.len();
        if k == 0 {
            return;
        }
        for c in 0..k {
            self.small_a[c] = r[self.closing_index[c]] - self.closing[c].dot(out);
        }
        // z + W (WᵀW)⁺ rest.
        self.subtract_schur_correction(out, -1.0);
    }

    fn rank(&self) -> usize {
        self.chain.len() + self.schur_values.len()
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The SVD-based projector (the reference, and the fallback when the chain rows are
/// nearly dependent). It allocates.
#[derive(Debug, Clone)]
struct DenseRowSpace {
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

    fn project_to_null(&self, w: &[f64], out: &mut [f64]) {
        let w = DVector::from_column_slice(w);
        let coefficients = &self.v_t * &w;
        out.copy_from_slice((w - self.v_t.transpose() * coefficients).as_slice());
    }

    fn solve_min_norm(&self, r: &[f64], out: &mut [f64]) {
        let mut coefficients = self.u.transpose() * DVector::from_column_slice(r);
        for (c, s) in coefficients.iter_mut().zip(self.sigma.iter()) {
            *c /= s;
        }
        out.copy_from_slice((self.v_t.transpose() * coefficients).as_slice());
    }
}

/// The projector onto the row space of A, reused for the direction, the Newton
/// restoration of the constraints and the restart kicks. [`RowSpace::factorise`] refills it
/// in place: after the first call at a size, the chain path allocates nothing.
#[derive(Debug, Default)]
pub struct RowSpace {
    chain: ChainFactors,
    dense: Option<DenseRowSpace>,
    /// Columns of A (tangent coordinates).
    pub dimension: usize,
}

impl RowSpace {
    /// Factorises A (see [`RowSpace::factorise`]).
    pub fn new(a: &ConstraintJacobian) -> Result<RowSpace> {
        let mut space = RowSpace::default();
        space.factorise(a)?;
        Ok(space)
    }

    /// Factorises A by its chain structure, O(rows) plus the closing rows' Schur
    /// complement; falls back on the dense SVD if the chain rows are nearly dependent.
    pub fn factorise(&mut self, a: &ConstraintJacobian) -> Result<()> {
        if a.has_non_finite_entry() {
            return Err(NumericalError::NonFinite {
                what: "constraint Jacobian",
                detail: "an entry".into(),
            }
            .into());
        }
        self.dimension = a.columns;
        self.dense = None;
        if !self.chain.factorise(a) {
            self.dense = Some(DenseRowSpace::new(&a.to_dense())?);
        }
        Ok(())
    }

    /// The dense SVD of A (the reference).
    pub fn dense(a: &ConstraintJacobian) -> Result<RowSpace> {
        Ok(RowSpace {
            chain: ChainFactors::default(),
            dense: Some(DenseRowSpace::new(&a.to_dense())?),
            dimension: a.columns,
        })
    }

    /// Whether the chain factorisation is in use (false: the dense fallback).
    pub fn is_banded(&self) -> bool {
        self.dense.is_none()
    }

    /// Numerical rank of A.
    pub fn rank(&self) -> usize {
        match &self.dense {
            None => self.chain.rank(),
            Some(d) => d.sigma.len(),
        }
    }

    /// Dimension of the null space: the first-order degrees of freedom.
    pub fn null_dimension(&self) -> usize {
        self.dimension - self.rank()
    }

    /// (I − A⁺A) w into `out`: the component of `w` in the null space of A.
    pub fn project_to_null_into(&mut self, w: &[f64], out: &mut [f64]) {
        match &self.dense {
            None => self.chain.project_to_null(w, out),
            Some(d) => d.project_to_null(w, out),
        }
    }

    /// Minimum-norm z with A z = r (least squares on the dependent closing directions),
    /// into `out`.
    pub fn solve_min_norm_into(&mut self, r: &[f64], out: &mut [f64]) {
        match &self.dense {
            None => self.chain.solve_min_norm(r, out),
            Some(d) => d.solve_min_norm(r, out),
        }
    }

    /// (I − A⁺A) w, allocating the result.
    pub fn project_to_null(&mut self, w: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(w.len());
        self.project_to_null_into(w.as_slice(), out.as_mut_slice());
        out
    }

    /// Minimum-norm z with A z = r, allocating the result.
    pub fn solve_min_norm(&mut self, r: &DVector<f64>) -> DVector<f64> {
        let mut out = DVector::zeros(self.dimension);
        self.solve_min_norm_into(r.as_slice(), out.as_mut_slice());
        out
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
        let mut cholesky = BandedCholesky::default();
        assert!(cholesky.factorise(n, 2, entry, 1e-14));
        let mut x = b.clone();
        cholesky.solve_in_place(&mut x);
        let expected = dense.cholesky().unwrap().solve(&DVector::from_vec(b));
        assert!((DVector::from_vec(x) - expected).amax() < 1e-14);
        // Indefinite: refused, not a NaN.
        assert!(!BandedCholesky::default().factorise(2, 1, |i, j| if i == j { 1.0 } else { 2.0 }, 1e-14));
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
        let mut chain = RowSpace::new(&jacobian).unwrap();
        let mut dense = RowSpace::dense(&jacobian).unwrap();
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
