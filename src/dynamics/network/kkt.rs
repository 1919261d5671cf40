//! The regularised saddle-point system of a panel network's dynamics
//! (`docs/model.md#panel-networks`):
//!
//! ```text
//!   [ M/μ + JᵀJ   Jᵀ ] [ρ̈]   [ Q/μ + Jᵀb ]
//!   [ J         −εI  ] [λ ] = [ b          ]
//! ```
//!
//! with M the tree's mass matrix (zero on the creases off the tree) scaled by its largest
//! diagonal entry μ, J the stars' closure rows each scaled to unit length, and
//! b = −(their velocity product). Adding JᵀJ (the augmented Lagrangian) leaves the solution
//! unchanged and makes the upper block positive definite, so the matrix is quasi-definite
//! and faer's sparse LDLᵀ needs no pivoting; the −εI keeps redundant rows (normal here: a
//! Miura-ori has far more closure rows than loops) from making it singular, and rounds of
//! refinement against the unregularised matrix remove ε's trace. Locked creases are
//! eliminated (their row and column hold a 1). The structure, and faer's symbolic analysis
//! with its fill-reducing ordering, are made once per model.

use super::algorithms::NetworkData;
use super::model::NetworkModel;
use super::rows::{key, symmetric_multiply, ClosureRows};
use crate::error::{NumericalError, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{Conj, Par, Side};

/// When faer factorises with dense (supernodal) kernels, relative to its own default: a
/// deep tree (a long strip) has a dense mass matrix, where dense kernels win; a sheet's
/// saddle-point matrix stays sparse and simplicial (the Miura sheets up to 32 × 32 choose
/// the same at this threshold as at faer's default).
const SUPERNODAL_THRESHOLD: SupernodalThreshold = SupernodalThreshold(0.5);

/// ε on the multipliers' diagonal (the matrix is scaled to O(1)). Exactly redundant rows make
/// pivots of size ε, and the factorisation's error grows like 1/ε; the refinement's rate is
/// ε/σ² for the smallest non-zero singular value σ of the scaled rows (≥ 0.1 on the
/// Miura-ori at every fold), so a moderate ε with a few rounds beats a tiny one.
const REGULARISATION: f64 = 1e-6;
/// Most refinement rounds against the unregularised matrix (they stop once a round changes
/// the solution by less than rounding, or stops shrinking the residual).
const REFINEMENTS: usize = 8;

/// The saddle-point matrix's structure, its symbolic factorisation and the buffers of one
/// numeric factorisation.
pub struct KktSystem {
    rows: ClosureRows,
    /// Value slot of each entry in the Jᵀ block.
    entry_slots: Vec<usize>,
    /// Slot of each pair of `rows.pairs`.
    pair_slots: Vec<usize>,
    /// Slot of each mass-pattern entry (None where it touches a locked crease).
    mass_slots: Vec<Option<usize>>,
    diagonal: Vec<usize>,
    structure: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Matrix values (lower triangle, CSC order) of the last assembly.
    values: Vec<f64>,
    factor: Vec<f64>,
    signs: Vec<i8>,
    buffer: MemBuffer,
    /// μ of the last assembly, kg·m².
    mass_scale: f64,
    work: Vec<f64>,
    residual: Vec<f64>,
    original: Vec<f64>,
}

impl KktSystem {
    /// The structure for `model` (its trees, stars and locks) and its symbolic analysis.
    pub fn new(model: &NetworkModel) -> Result<KktSystem> {
        let rows = ClosureRows::new(model);
        let columns = rows.columns;
        let n = columns + rows.rows;
        let mut keys = rows.crease_keys(model);
        keys.extend((columns..n).map(|i| (i, i)));
        keys.extend(rows.entries.iter().map(|e| key(columns + e.row, e.column)));
        keys.sort_unstable();
        keys.dedup();
        let slot = ClosureRows::slots(&keys);
        let entry_slots = rows
            .entries
            .iter()
            .map(|e| slot[&key(columns + e.row, e.column)])
            .collect();
        let pair_slots = rows
            .pairs
            .iter()
            .map(|&(a, b)| slot[&key(rows.entries[a].column, rows.entries[b].column)])
            .collect();
        let mass_slots = model
            .mass_pattern
            .iter()
            .map(|&(a, c)| (!rows.locked[a] && !rows.locked[c]).then(|| slot[&key(a, c)]))
            .collect();
        let diagonal = (0..n).map(|i| slot[&(i, i)]).collect();
        let singular = |detail: String| NumericalError::Singular {
            what: "the network's KKT matrix",
            detail,
        };
        let triplets: Vec<Triplet<usize, usize, f64>> =
            keys.iter().map(|&(col, row)| Triplet::new(row, col, 0.0)).collect();
        let matrix = SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(|e| singular(format!("{e:?}")))?;
        let structure = matrix.symbolic().to_owned().map_err(|e| singular(format!("{e:?}")))?;
        let symbolic = factorize_symbolic_cholesky(
            structure.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SUPERNODAL_THRESHOLD,
                ..Default::default()
            },
        )
        .map_err(|e| singular(format!("symbolic: {e:?}")))?;
        let req = symbolic
            .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let signs = (0..n).map(|i| if i < columns { 1 } else { -1 }).collect();
        Ok(KktSystem {
            entry_slots,
            pair_slots,
            mass_slots,
            diagonal,
            values: vec![0.0; keys.len()],
            factor: vec![0.0; symbolic.len_val()],
            symbolic,
            structure,
            signs,
            buffer: MemBuffer::new(req),
            mass_scale: 1.0,
            work: vec![0.0; n],
            residual: vec![0.0; n],
            original: vec![0.0; n],
            rows,
        })
    }

    /// Assembles the matrix at the state whose mass matrix and star axes `data` holds, and
    /// factorises it.
    pub fn factor(&mut self, model: &NetworkModel, data: &NetworkData) -> Result<()> {
        let columns = self.rows.columns;
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let mut scale: f64 = 0.0;
        for (k, &(a, c)) in model.mass_pattern.iter().enumerate() {
            if a == c && !self.rows.locked[c] {
                scale = scale.max(data.mass_values[k]);
            }
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(NumericalError::NotPositiveDefinite {
                matrix: "the network's mass matrix",
                at: format!("largest diagonal entry {scale:e}"),
            }
            .into());
        }
        self.mass_scale = scale;
        for (k, slot) in self.mass_slots.iter().enumerate() {
            if let Some(slot) = slot {
                self.values[*slot] += data.mass_values[k] / scale;
            }
        }
        self.rows.update(data);
        for (e, &slot) in self.entry_slots.iter().enumerate() {
            self.values[slot] += self.rows.entry_values[e];
        }
        for (&(a, b), &slot) in self.rows.pairs.iter().zip(&self.pair_slots) {
            self.values[slot] += self.rows.entry_values[a] * self.rows.entry_values[b];
        }
        for c in 0..columns {
            if self.rows.locked[c] {
                self.values[self.diagonal[c]] = 1.0;
            }
        }
        for r in 0..self.rows.rows {
            self.values[self.diagonal[columns + r]] -= REGULARISATION;
        }
        let matrix = SparseColMatRef::new(self.structure.as_ref(), &self.values);
        let regularization = LdltRegularization {
            dynamic_regularization_signs: Some(&self.signs),
            dynamic_regularization_delta: REGULARISATION,
            dynamic_regularization_epsilon: 1e-3 * REGULARISATION,
        };
        self.symbolic
            .factorize_numeric_ldlt(
                &mut self.factor,
                matrix,
                Side::Lower,
                regularization,
                Par::Seq,
                MemStack::new(&mut self.buffer),
                Default::default(),
            )
            .map_err(|e| NumericalError::Singular {
                what: "the network's KKT matrix",
                detail: format!("{e:?}"),
            })?;
        Ok(())
    }

    /// The accelerations for generalised forces `forces` (τ − Kρ − bias, per crease, N·m) and
    /// the star velocity products in `data`, into `accel` (rad/s²). Needs [`KktSystem::factor`]
    /// at the same state.
    pub fn accelerations(&mut self, data: &NetworkData, forces: &[f64], accel: &mut [f64]) {
        let columns = self.rows.columns;
        let mut rhs = std::mem::take(&mut self.work);
        let (top, bottom) = rhs.split_at_mut(columns);
        self.rows.acceleration_rhs(data, bottom);
        // Jᵀ b joins the forces (the augmented Lagrangian's share).
        self.rows.apply_transpose(bottom, top);
        for (c, v) in top.iter_mut().enumerate() {
            *v = if self.rows.locked[c] {
                0.0
            } else {
                *v + forces[c] / self.mass_scale
            };
        }
        self.solve_refined(&mut rhs);
        accel.copy_from_slice(&rhs[..columns]);
        self.work = rhs;
    }

    /// The velocity nearest `rates` in the metric M/μ + JᵀJ that satisfies every closure row
    /// (J v = 0) and holds the locked creases, into `rates`. Needs [`KktSystem::factor`].
    pub fn project_rates(&mut self, rates: &mut [f64]) {
        let columns = self.rows.columns;
        let mut rhs = std::mem::take(&mut self.work);
        let mut x = vec![0.0; columns];
        for (c, v) in x.iter_mut().enumerate() {
            *v = if self.rows.locked[c] { 0.0 } else { rates[c] };
        }
        // rhs = W x (the crease block only), then zero rows.
        symmetric_multiply(
            self.structure.col_ptr(),
            self.structure.row_idx(),
            &self.values,
            columns,
            &x,
            &mut rhs[..columns],
        );
        rhs[columns..].iter_mut().for_each(|v| *v = 0.0);
        self.solve_refined(&mut rhs);
        rates.copy_from_slice(&rhs[..columns]);
        self.work = rhs;
    }

    /// Solves K_ε x = rhs in place, then refines against the unregularised K.
    fn solve_refined(&mut self, rhs: &mut [f64]) {
        let mut b = std::mem::take(&mut self.original);
        b.copy_from_slice(rhs);
        self.solve(rhs);
        let mut previous = f64::INFINITY;
        for _ in 0..REFINEMENTS {
            let mut residual = std::mem::take(&mut self.residual);
            self.multiply_unregularised(rhs, &mut residual);
            for (r, bi) in residual.iter_mut().zip(&b) {
                *r = bi - *r;
            }
            let size_of_residual = residual.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            // A round that does not shrink the residual would only add noise: stop.
            if size_of_residual.is_nan() || size_of_residual >= previous {
                self.residual = residual;
                break;
            }
            previous = size_of_residual;
            self.solve(&mut residual);
            let (mut change, mut size) = (0.0_f64, 0.0_f64);
            for (x, d) in rhs.iter_mut().zip(&residual) {
                *x += d;
                change = change.max(d.abs());
                size = size.max(x.abs());
            }
            self.residual = residual;
            if change <= 1e-15 * size {
                break;
            }
        }
        self.original = b;
    }

    fn solve(&mut self, rhs: &mut [f64]) {
        let factor = LdltRef::new(&self.symbolic, &self.factor);
        factor.solve_in_place_with_conj(
            Conj::No,
            faer::ColMut::from_slice_mut(rhs).as_mat_mut(),
            Par::Seq,
            MemStack::new(&mut self.buffer),
        );
    }

    /// y = K x with the unregularised matrix (the −εI dropped).
    fn multiply_unregularised(&self, x: &[f64], y: &mut [f64]) {
        let n = x.len();
        symmetric_multiply(
            self.structure.col_ptr(),
            self.structure.row_idx(),
            &self.values,
            n,
            x,
            y,
        );
        let columns = self.rows.columns;
        for r in columns..n {
            y[r] += REGULARISATION * x[r];
        }
    }
}
