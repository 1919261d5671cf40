//! Newton steps of a network's statics on the closures (`docs/model.md#panel-networks`):
//! min ½ δᵀHδ − fᵀδ s.t. J δ = b, with H = (K + Σ_r λ_r ∇²Φ_r)/κ the hinges' Hessian (the
//! closures' curvature weighted by the last multipliers; none for a Gauss–Newton step), by
//! the augmented Lagrangian on the matrix A = H + γ JᵀJ,
//!
//!   A δ = f + Jᵀ(γ b − λ),   λ ← λ + γ (J δ − b),
//!
//! factorised once per state by faer's sparse Cholesky. Unlike the saddle-point matrix, A
//! has no pivot from a redundant or nearly dependent row (close to a singular state the
//! rows of neighbouring stars nearly repeat each other), and a curvature term that leaves
//! the Hessian indefinite shows as a failed Cholesky, which the statics answers with a
//! Gauss–Newton step. γ costs precision (rounding grows like γ·ε), which Newton's own
//! iterations, measured on the exact residual, do not mind.

use super::algorithms::NetworkData;
use super::model::NetworkModel;
use super::rows::{key, symmetric_multiply, ClosureRows};
use crate::error::{NumericalError, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::Side;

/// γ of the augmented Lagrangian (the matrix is scaled to O(1)).
const AUGMENT: f64 = 1e6;
/// Most rounds of the augmented Lagrangian (they stop once the rows hold to rounding).
const ROUNDS: usize = 60;

/// The augmented Hessian's structure, symbolic analysis and last factorisation.
pub struct HessianSystem {
    rows: ClosureRows,
    pair_slots: Vec<usize>,
    diagonal: Vec<usize>,
    structure: SymbolicSparseColMat<usize>,
    symbolic: SymbolicLlt<usize>,
    factor: Option<Llt<usize, f64>>,
    values: Vec<f64>,
    /// κ, the largest K of the last assembly, N·m/rad.
    scale: f64,
    gamma: f64,
    /// Scaled multipliers of the last solve, per row.
    lambda: Vec<f64>,
}

impl HessianSystem {
    /// The structure for `model` and its symbolic analysis.
    pub fn new(model: &NetworkModel) -> Result<HessianSystem> {
        let rows = ClosureRows::new(model);
        let columns = rows.columns;
        let mut keys = rows.crease_keys(model);
        keys.sort_unstable();
        keys.dedup();
        let slot = ClosureRows::slots(&keys);
        let pair_slots = rows
            .pairs
            .iter()
            .map(|&(a, b)| slot[&key(rows.entries[a].column, rows.entries[b].column)])
            .collect();
        let diagonal = (0..columns).map(|i| slot[&(i, i)]).collect();
        let singular = |detail: String| NumericalError::Singular {
            what: "the hinges' augmented Hessian",
            detail,
        };
        let triplets: Vec<Triplet<usize, usize, f64>> =
            keys.iter().map(|&(col, row)| Triplet::new(row, col, 0.0)).collect();
        let matrix =
            SparseColMat::try_new_from_triplets(columns, columns, &triplets).map_err(|e| singular(format!("{e:?}")))?;
        let structure = matrix.symbolic().to_owned().map_err(|e| singular(format!("{e:?}")))?;
        let symbolic = SymbolicLlt::try_new(structure.as_ref(), Side::Lower).map_err(|e| singular(format!("{e:?}")))?;
        Ok(HessianSystem {
            lambda: vec![0.0; rows.rows],
            pair_slots,
            diagonal,
            values: vec![0.0; keys.len()],
            structure,
            symbolic,
            factor: None,
            scale: 1.0,
            gamma: AUGMENT,
            rows,
        })
    }

    /// Assembles A = (K + Σλ∇²Φ)/κ + γJᵀJ at the star axes `data` holds (`multipliers` per
    /// unscaled row, N·m; None for K alone) and factorises it; an error when it is not
    /// positive definite.
    pub fn assemble(&mut self, data: &NetworkData, stiffness: &[f64], multipliers: Option<&[f64]>) -> Result<()> {
        let columns = self.rows.columns;
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let scale = (0..columns)
            .filter(|&c| !self.rows.locked[c])
            .map(|c| stiffness[c])
            .fold(0.0, f64::max);
        if !(scale.is_finite() && scale > 0.0) {
            return Err(NumericalError::NotPositiveDefinite {
                matrix: "the network's hinge stiffness",
                at: format!("largest entry {scale:e}"),
            }
            .into());
        }
        self.scale = scale;
        for (&slot, k) in self.diagonal.iter().zip(stiffness) {
            self.values[slot] += k / scale;
        }
        self.rows.update(data);
        for (&(a, b), &slot) in self.rows.pairs.iter().zip(&self.pair_slots) {
            self.values[slot] += self.gamma * self.rows.entry_values[a] * self.rows.entry_values[b];
            if let Some(m) = multipliers {
                if let Some(curvature) = self.rows.curvature(a, b, data, m) {
                    self.values[slot] += curvature / scale;
                }
            }
        }
        for c in 0..columns {
            if self.rows.locked[c] {
                self.values[self.diagonal[c]] = 1.0;
            }
        }
        let matrix = SparseColMat::new(self.structure.clone(), self.values.clone());
        self.factor = Some(
            Llt::try_new_with_symbolic(self.symbolic.clone(), matrix.as_ref(), Side::Lower).map_err(|e| {
                NumericalError::NotPositiveDefinite {
                    matrix: "the hinges' Hessian on the closures (K + Σλ∇²Φ)/κ + γJᵀJ",
                    at: format!("{e:?}"),
                }
            })?,
        );
        Ok(())
    }

    /// Solves min ½ xᵀHx − fᵀx s.t. J x = b (scaled rows), into `x`. Needs [`HessianSystem::assemble`].
    pub fn solve(&mut self, f: &[f64], b: &[f64], x: &mut [f64]) {
        let (columns, rows) = (self.rows.columns, self.rows.rows);
        let gamma = self.gamma;
        self.lambda.iter_mut().for_each(|l| *l = 0.0);
        let mut along = vec![0.0; rows];
        let mut rhs = vec![0.0; columns];
        let mut residual = vec![0.0; columns];
        let scale_b = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let mut previous = f64::INFINITY;
        for _ in 0..ROUNDS {
            for (r, v) in along.iter_mut().enumerate() {
                *v = gamma * b[r] - self.lambda[r];
            }
            self.rows.apply_transpose(&along, &mut rhs);
            for (c, v) in rhs.iter_mut().enumerate() {
                *v = if self.rows.locked[c] { 0.0 } else { *v + f[c] };
            }
            self.solve_refined(&rhs, x, &mut residual);
            self.rows.apply(x, &mut along);
            let mut worst: f64 = 0.0;
            for (r, v) in along.iter().enumerate() {
                let error = v - b[r];
                self.lambda[r] += gamma * error;
                worst = worst.max(error.abs());
            }
            let size = x.iter().fold(scale_b, |m, v| m.max(v.abs()));
            if worst <= 1e-14 * size || worst.is_nan() || worst >= previous {
                break;
            }
            previous = worst;
        }
    }

    /// The multipliers of the last solve per unscaled row, N·m.
    pub fn multipliers(&self, out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate() {
            *o = self.scale * self.rows.row_scale[r] * self.lambda[r];
        }
    }

    /// κ of the last assembly.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Number of closure rows.
    pub fn rows(&self) -> usize {
        self.rows.rows
    }

    /// x = A⁻¹ rhs with one round of refinement.
    fn solve_refined(&self, rhs: &[f64], x: &mut [f64], residual: &mut [f64]) {
        let factor = self.factor.as_ref().expect("assembled before solving");
        x.copy_from_slice(rhs);
        factor.solve_in_place(faer::ColMut::from_slice_mut(x).as_mat_mut());
        let n = x.len();
        symmetric_multiply(
            self.structure.col_ptr(),
            self.structure.row_idx(),
            &self.values,
            n,
            x,
            residual,
        );
        for (r, b) in residual.iter_mut().zip(rhs) {
            *r = b - *r;
        }
        factor.solve_in_place(faer::ColMut::from_slice_mut(residual).as_mat_mut());
        for (xi, d) in x.iter_mut().zip(residual.iter()) {
            *xi += d;
        }
    }
}
