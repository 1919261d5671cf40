//! The regularised saddle-point system of a panel network (`docs/model.md#panel-networks`):
//!
//!   [ M/μ + JᵀJ   Jᵀ ] [ρ̈]   [ Q/μ + Jᵀb ]
//!   [ J         −εI  ] [λ ] = [ b          ]
//!
//! with M the tree's mass matrix (zero on the creases off the tree) scaled by its largest
//! diagonal entry μ, J the vertex stars' closure rows each scaled to unit length, and
//! b = −(their velocity product). Adding JᵀJ (the augmented Lagrangian) leaves the solution
//! unchanged and makes the upper block positive definite, so the matrix is quasi-definite
//! and faer's sparse LDLᵀ needs no pivoting; the −εI keeps redundant rows (normal here: a
//! Miura-ori has far more closure rows than loops) from making it singular, and two rounds
//! of refinement against the unregularised matrix remove ε's trace. Locked creases are
//! eliminated (their row and column hold a 1). The structure, and faer's symbolic analysis
//! with its fill-reducing ordering, are made once per model.

use super::algorithms::NetworkData;
use super::model::NetworkModel;
use crate::error::{NumericalError, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{Conj, Par, Side};
use nalgebra::Vector3;
use std::collections::HashMap;

/// ε on the multipliers' diagonal (the matrix is scaled to O(1)). Exactly redundant rows make
/// pivots of size ε, and the factorisation's error grows like 1/ε; the refinement's rate is
/// ε/σ² for the smallest non-zero singular value σ of the scaled rows (≥ 0.1 on the
/// Miura-ori at every fold), so a moderate ε with a few rounds beats a tiny one.
const REGULARISATION: f64 = 1e-6;
/// A closure row shorter than this is left unscaled: it is zero but for rounding (a star
/// that lies flat has no out-of-plane row), and scaling it up would invent a constraint.
const ROW_FLOOR: f64 = 1e-9;
/// Most refinement rounds against the unregularised matrix (they stop once a round changes
/// the solution by less than rounding).
const REFINEMENTS: usize = 8;

/// The upper-left block of the saddle-point matrix.
#[derive(Debug, Clone, Copy)]
pub enum PrimalBlock<'a> {
    /// The mass matrix (dynamics, velocity projection).
    Inertia,
    /// The Hessian of the hinges' energy on the manifold: diag(K) plus the stars' curvature
    /// weighted by the multipliers of the last solve (statics).
    Hessian {
        /// K per crease, N·m/rad.
        stiffness: &'a [f64],
        /// λ per closure row (unscaled rows), N·m.
        multipliers: &'a [f64],
    },
}

/// One closure-row entry: its row, column and the star axis it reads.
#[derive(Debug, Clone, Copy)]
struct RowEntry {
    row: usize,
    column: usize,
    /// Index into `NetworkData::star_axes`, and the component (row within the star).
    axis: usize,
    component: usize,
}

/// The saddle-point system's structure, its symbolic factorisation and the buffers of one
/// numeric factorisation.
pub struct KktSystem {
    columns: usize,
    rows: usize,
    locked: Vec<bool>,
    entries: Vec<RowEntry>,
    /// Value slot of each `entries` item in the Jᵀ block.
    entry_slots: Vec<usize>,
    /// (entry a, entry b, slot) for the products of two entries of one row, column a ≥ column b.
    products: Vec<(usize, usize, usize)>,
    /// Slot of each mass-pattern entry (None where it touches a locked crease).
    mass_slots: Vec<Option<usize>>,
    diagonal: Vec<usize>,
    /// Each star axis's place in its star's holonomy product (rays 1, …, n−1, then 0).
    order: Vec<usize>,
    structure: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Matrix values (lower triangle, CSC order) of the last assembly.
    values: Vec<f64>,
    factor: Vec<f64>,
    signs: Vec<i8>,
    buffer: MemBuffer,
    /// μ of the last assembly, kg·m².
    pub mass_scale: f64,
    /// Each row's scale of the last assembly (1/|row|, or 1 below the floor).
    row_scale: Vec<f64>,
    /// J's values of the last assembly, per entry.
    entry_values: Vec<f64>,
    work: Vec<f64>,
    residual: Vec<f64>,
    original: Vec<f64>,
}

impl KktSystem {
    /// The structure for `model` (its trees, stars and locks) and its symbolic analysis.
    pub fn new(model: &NetworkModel) -> Result<KktSystem> {
        let columns = model.columns();
        let rows = 3 * model.folding.stars.len();
        let locked: Vec<bool> = (0..columns).map(|c| model.locked(c)).collect();
        let mut entries = Vec::new();
        let mut order = Vec::new();
        let mut offset = 0;
        for (s, star) in model.folding.stars.iter().enumerate() {
            order.extend((0..star.columns.len()).map(|k| if k == 0 { star.columns.len() } else { k }));
            for (k, &column) in star.columns.iter().enumerate() {
                if !locked[column] {
                    for component in 0..3 {
                        entries.push(RowEntry {
                            row: 3 * s + component,
                            column,
                            axis: offset + k,
                            component,
                        });
                    }
                }
            }
            offset += star.columns.len();
        }
        let n = columns + rows;
        let key = |i: usize, j: usize| if i >= j { (j, i) } else { (i, j) };
        let mut keys: Vec<(usize, usize)> = (0..n).map(|i| (i, i)).collect();
        for &(a, c) in &model.mass_pattern {
            if !locked[a] && !locked[c] {
                keys.push(key(a, c));
            }
        }
        let mut by_row: Vec<Vec<usize>> = vec![Vec::new(); rows];
        for (e, entry) in entries.iter().enumerate() {
            by_row[entry.row].push(e);
            keys.push(key(columns + entry.row, entry.column));
        }
        for row in &by_row {
            for &a in row {
                for &b in row {
                    if entries[a].column >= entries[b].column {
                        keys.push(key(entries[a].column, entries[b].column));
                    }
                }
            }
        }
        // (column, row) with row ≥ column: faer's CSC order for the lower triangle.
        keys.sort_unstable();
        keys.dedup();
        let slot: HashMap<(usize, usize), usize> = keys.iter().enumerate().map(|(k, &key)| (key, k)).collect();
        let entry_slots = entries.iter().map(|e| slot[&key(columns + e.row, e.column)]).collect();
        let mut products = Vec::new();
        for row in &by_row {
            for &a in row {
                for &b in row {
                    if entries[a].column >= entries[b].column {
                        products.push((a, b, slot[&key(entries[a].column, entries[b].column)]));
                    }
                }
            }
        }
        let mass_slots = model
            .mass_pattern
            .iter()
            .map(|&(a, c)| (!locked[a] && !locked[c]).then(|| slot[&key(a, c)]))
            .collect();
        let diagonal = (0..n).map(|i| slot[&(i, i)]).collect();
        let singular = |what: &'static str| {
            move |e: faer::sparse::CreationError| NumericalError::Singular {
                what,
                detail: format!("{e:?}"),
            }
        };
        let triplets: Vec<Triplet<usize, usize, f64>> =
            keys.iter().map(|&(col, row)| Triplet::new(row, col, 0.0)).collect();
        let matrix =
            SparseColMat::try_new_from_triplets(n, n, &triplets).map_err(singular("the network's KKT matrix"))?;
        let structure = matrix.symbolic().to_owned().map_err(|e| NumericalError::Singular {
            what: "the network's KKT matrix",
            detail: format!("{e:?}"),
        })?;
        let symbolic = factorize_symbolic_cholesky(
            structure.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| NumericalError::Singular {
            what: "the network's KKT matrix (symbolic)",
            detail: format!("{e:?}"),
        })?;
        let req = symbolic
            .factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let signs = (0..n).map(|i| if i < columns { 1 } else { -1 }).collect();
        Ok(KktSystem {
            columns,
            rows,
            entry_values: vec![0.0; entries.len()],
            entries,
            entry_slots,
            products,
            mass_slots,
            diagonal,
            order,
            values: vec![0.0; keys.len()],
            factor: vec![0.0; symbolic.len_val()],
            symbolic,
            structure,
            signs,
            buffer: MemBuffer::new(req),
            mass_scale: 1.0,
            row_scale: vec![1.0; rows],
            locked,
            work: vec![0.0; n],
            residual: vec![0.0; n],
            original: vec![0.0; n],
        })
    }

    /// Size of the unknown vector: creases, then closure rows.
    pub fn size(&self) -> usize {
        self.columns + self.rows
    }

    /// Assembles the matrix with the mass block M/μ at the state whose mass matrix and star
    /// axes `data` holds, and factorises it.
    pub fn factor(&mut self, model: &NetworkModel, data: &NetworkData) -> Result<()> {
        self.assemble(model, data, PrimalBlock::Inertia, 1.0)
    }

    /// Assembles the matrix with `block` (and γ times JᵀJ added to it) and factorises it.
    pub fn assemble(
        &mut self,
        model: &NetworkModel,
        data: &NetworkData,
        block: PrimalBlock<'_>,
        augment: f64,
    ) -> Result<()> {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        let scale = match block {
            PrimalBlock::Inertia => {
                let mut scale: f64 = 0.0;
                for (k, &(a, c)) in model.mass_pattern.iter().enumerate() {
                    if a == c && !self.locked[c] {
                        scale = scale.max(data.mass_values[k]);
                    }
                }
                scale
            }
            PrimalBlock::Hessian { stiffness, .. } => (0..self.columns)
                .filter(|&c| !self.locked[c])
                .map(|c| stiffness[c])
                .fold(0.0, f64::max),
        };
        if !(scale.is_finite() && scale > 0.0) {
            return Err(NumericalError::NotPositiveDefinite {
                matrix: match block {
                    PrimalBlock::Inertia => "the network's mass matrix",
                    PrimalBlock::Hessian { .. } => "the network's hinge stiffness",
                },
                at: format!("largest diagonal entry {scale:e}"),
            }
            .into());
        }
        self.mass_scale = scale;
        match block {
            PrimalBlock::Inertia => {
                for (k, slot) in self.mass_slots.iter().enumerate() {
                    if let Some(slot) = slot {
                        self.values[*slot] += data.mass_values[k] / scale;
                    }
                }
            }
            PrimalBlock::Hessian { stiffness, multipliers } => {
                for (&slot, k) in self.diagonal.iter().zip(stiffness) {
                    self.values[slot] += k / scale;
                }
                // Σ_r λ_r ∇²r_r: ½ λ·(x_a × x_b) for crease a before b in the product order.
                for &(a, b, slot) in &self.products {
                    let (ea, eb) = (self.entries[a], self.entries[b]);
                    if ea.column == eb.column || ea.component != 0 || eb.component != 0 {
                        continue;
                    }
                    let star = ea.row / 3;
                    let lambda = Vector3::new(
                        multipliers[3 * star],
                        multipliers[3 * star + 1],
                        multipliers[3 * star + 2],
                    );
                    let (first, second) = if self.order[ea.axis] < self.order[eb.axis] {
                        (ea, eb)
                    } else {
                        (eb, ea)
                    };
                    let cross = data.star_axes[first.axis].cross(&data.star_axes[second.axis]);
                    self.values[slot] += 0.5 * lambda.dot(&cross) / scale;
                }
            }
        }
        let mut norms = vec![0.0; self.rows];
        for entry in &self.entries {
            norms[entry.row] += data.star_axes[entry.axis][entry.component].powi(2);
        }
        for (s, n) in self.row_scale.iter_mut().zip(&norms) {
            let norm = n.sqrt();
            *s = if norm > ROW_FLOOR { 1.0 / norm } else { 1.0 };
        }
        for (e, entry) in self.entries.iter().enumerate() {
            let value = data.star_axes[entry.axis][entry.component] * self.row_scale[entry.row];
            self.entry_values[e] = value;
            self.values[self.entry_slots[e]] += value;
        }
        for &(a, b, slot) in &self.products {
            self.values[slot] += augment * self.entry_values[a] * self.entry_values[b];
        }
        for c in 0..self.columns {
            if self.locked[c] {
                self.values[self.diagonal[c]] = 1.0;
            }
        }
        for r in 0..self.rows {
            self.values[self.diagonal[self.columns + r]] -= REGULARISATION;
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
        let mut rhs = std::mem::take(&mut self.work);
        rhs.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..self.columns {
            if !self.locked[c] {
                rhs[c] = forces[c] / self.mass_scale;
            }
        }
        for (e, entry) in self.entries.iter().enumerate() {
            let b = -data.star_bias[entry.row / 3][entry.row % 3] * self.row_scale[entry.row];
            rhs[entry.column] += self.entry_values[e] * b;
        }
        for r in 0..self.rows {
            rhs[self.columns + r] = -data.star_bias[r / 3][r % 3] * self.row_scale[r];
        }
        self.solve_refined(&mut rhs);
        accel.copy_from_slice(&rhs[..self.columns]);
        self.work = rhs;
    }

    /// The velocity nearest `rates` in the metric M/μ + JᵀJ that satisfies every closure row
    /// (J v = 0) and holds the locked creases, into `rates`. Needs [`KktSystem::factor`].
    pub fn project_rates(&mut self, rates: &mut [f64]) {
        let mut rhs = std::mem::take(&mut self.work);
        rhs.iter_mut().for_each(|v| *v = 0.0);
        let mut x = vec![0.0; self.size()];
        for c in 0..self.columns {
            if !self.locked[c] {
                x[c] = rates[c];
            }
        }
        // rhs = W x (the upper block only).
        self.multiply(&x, &mut rhs, true);
        for r in 0..self.rows {
            rhs[self.columns + r] = 0.0;
        }
        self.solve_refined(&mut rhs);
        rates.copy_from_slice(&rhs[..self.columns]);
        self.work = rhs;
    }

    /// Solves the assembled system for `rhs` (creases, then rows as assembled: rows scaled
    /// to unit length) in place, refined against the unregularised matrix.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.solve_refined(rhs);
    }

    /// Each closure row's scale (1/|row|, or 1 below the floor) in the last assembly.
    pub fn row_scales(&self) -> &[f64] {
        &self.row_scale
    }

    /// The scale of the upper block in the last assembly (μ or the largest K).
    pub fn scale(&self) -> f64 {
        self.mass_scale
    }

    /// Solves K_ε x = rhs in place, then refines against the unregularised K.
    fn solve_refined(&mut self, rhs: &mut [f64]) {
        let mut b = std::mem::take(&mut self.original);
        b.copy_from_slice(rhs);
        self.solve(rhs);
        for _ in 0..REFINEMENTS {
            let mut residual = std::mem::take(&mut self.residual);
            self.multiply(rhs, &mut residual, false);
            for (r, bi) in residual.iter_mut().zip(&b) {
                *r = bi - *r;
            }
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

    /// y = K x with the unregularised matrix (the −εI dropped); with `upper_only`, only the
    /// crease block W (x's multiplier part ignored, y's left as is).
    fn multiply(&self, x: &[f64], y: &mut [f64], upper_only: bool) {
        if !upper_only {
            y.iter_mut().for_each(|v| *v = 0.0);
        }
        let col_ptr = self.structure.col_ptr();
        let row_idx = self.structure.row_idx();
        for j in 0..self.columns + self.rows {
            let range = col_ptr[j]..col_ptr[j + 1];
            for (&i, &value) in row_idx[range.clone()].iter().zip(&self.values[range]) {
                if upper_only && i >= self.columns {
                    continue;
                }
                let mut v = value;
                if i == j && i >= self.columns {
                    v += REGULARISATION;
                }
                y[i] += v * x[j];
                if i != j {
                    y[j] += v * x[i];
                }
            }
            if upper_only && j + 1 >= self.columns {
                break;
            }
        }
    }
}
