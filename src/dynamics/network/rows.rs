//! The vertex stars' closure rows as the solvers see them (`docs/model.md#panel-networks`):
//! one row per star and component (Σ_k x_k ρ̇_k = 0 in the star's frame), each scaled to
//! unit length, locked creases left out; and the sparsity of the crease block they share
//! with the mass matrix (JᵀJ couples the creases of one star).

use super::algorithms::NetworkData;
use super::model::NetworkModel;
use nalgebra::Vector3;
use std::collections::HashMap;

/// A closure row shorter than this is left unscaled: it is zero but for rounding (a star
/// that lies flat has no out-of-plane row), and scaling it up would invent a constraint.
const ROW_FLOOR: f64 = 1e-9;

/// One closure-row entry: its row, column and the star axis it reads.
#[derive(Debug, Clone, Copy)]
pub(super) struct RowEntry {
    pub row: usize,
    pub column: usize,
    /// Index into `NetworkData::star_axes`, and the component (row within the star).
    pub axis: usize,
    pub component: usize,
}

/// The lower-triangle key of entry (i, j): (column, row) with row ≥ column, faer's CSC order.
pub(super) fn key(i: usize, j: usize) -> (usize, usize) {
    if i >= j {
        (j, i)
    } else {
        (i, j)
    }
}

/// The scaled closure rows of one model and the crease block's pattern.
#[derive(Debug, Clone)]
pub(super) struct ClosureRows {
    pub columns: usize,
    pub rows: usize,
    pub locked: Vec<bool>,
    pub entries: Vec<RowEntry>,
    /// Each star axis's place in its star's holonomy product (rays 1, …, n−1, then 0).
    pub order: Vec<usize>,
    /// (entry a, entry b) of one row with column a ≥ column b: the products of JᵀJ.
    pub pairs: Vec<(usize, usize)>,
    /// Each row's scale of the last update (1/|row|, or 1 below the floor).
    pub row_scale: Vec<f64>,
    /// J's scaled values of the last update, per entry.
    pub entry_values: Vec<f64>,
}

impl ClosureRows {
    /// The rows of `model`'s stars over its free creases.
    pub fn new(model: &NetworkModel) -> ClosureRows {
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
        let mut by_row: Vec<Vec<usize>> = vec![Vec::new(); rows];
        for (e, entry) in entries.iter().enumerate() {
            by_row[entry.row].push(e);
        }
        let mut pairs = Vec::new();
        for row in &by_row {
            for &a in row {
                for &b in row {
                    if entries[a].column >= entries[b].column {
                        pairs.push((a, b));
                    }
                }
            }
        }
        ClosureRows {
            columns,
            rows,
            locked,
            entry_values: vec![0.0; entries.len()],
            entries,
            order,
            pairs,
            row_scale: vec![1.0; rows],
        }
    }

    /// The crease block's lower-triangle keys: the diagonal, the mass matrix's (free creases)
    /// and every pair of creases of one star.
    pub fn crease_keys(&self, model: &NetworkModel) -> Vec<(usize, usize)> {
        let mut keys: Vec<(usize, usize)> = (0..self.columns).map(|i| (i, i)).collect();
        for &(a, c) in &model.mass_pattern {
            if !self.locked[a] && !self.locked[c] {
                keys.push(key(a, c));
            }
        }
        for &(a, b) in &self.pairs {
            keys.push(key(self.entries[a].column, self.entries[b].column));
        }
        keys
    }

    /// Slot of each key in a sorted, deduplicated key list.
    pub fn slots(keys: &[(usize, usize)]) -> HashMap<(usize, usize), usize> {
        keys.iter().enumerate().map(|(k, &key)| (key, k)).collect()
    }

    /// The rows' scales and values at the star axes `data` holds.
    pub fn update(&mut self, data: &NetworkData) {
        let mut norms = vec![0.0; self.rows];
        for entry in &self.entries {
            norms[entry.row] += data.star_axes[entry.axis][entry.component].powi(2);
        }
        for (s, n) in self.row_scale.iter_mut().zip(&norms) {
            let norm = n.sqrt();
            *s = if norm > ROW_FLOOR { 1.0 / norm } else { 1.0 };
        }
        for (e, entry) in self.entries.iter().enumerate() {
            self.entry_values[e] = data.star_axes[entry.axis][entry.component] * self.row_scale[entry.row];
        }
    }

    /// −(velocity product) of every row, scaled: the right-hand side of J ρ̈ = b.
    pub fn acceleration_rhs(&self, data: &NetworkData, b: &mut [f64]) {
        for (r, v) in b.iter_mut().enumerate() {
            *v = -data.star_bias[r / 3][r % 3] * self.row_scale[r];
        }
    }

    /// ∂²Φ along the pair `(a, b)` weighted by the multipliers (one per unscaled row): ½ λ·(x_a ×
    /// x_b) for crease a before b in the product order, once per star (the component-0 row
    /// stands for the star), None for other pairs.
    pub fn curvature(&self, a: usize, b: usize, data: &NetworkData, multipliers: &[f64]) -> Option<f64> {
        let (ea, eb) = (self.entries[a], self.entries[b]);
        if ea.column == eb.column || ea.component != 0 || eb.component != 0 {
            return None;
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
        Some(0.5 * lambda.dot(&data.star_axes[first.axis].cross(&data.star_axes[second.axis])))
    }

    /// y = J x (scaled rows).
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for (e, entry) in self.entries.iter().enumerate() {
            y[entry.row] += self.entry_values[e] * x[entry.column];
        }
    }

    /// x = Jᵀ y (scaled rows).
    pub fn apply_transpose(&self, y: &[f64], x: &mut [f64]) {
        x.iter_mut().for_each(|v| *v = 0.0);
        for (e, entry) in self.entries.iter().enumerate() {
            x[entry.column] += self.entry_values[e] * y[entry.row];
        }
    }
}

/// y = A x for a symmetric matrix stored as its lower triangle (CSC), over the first
/// `count` rows and columns only when `count` is smaller than the matrix.
pub(super) fn symmetric_multiply(
    col_ptr: &[usize],
    row_idx: &[usize],
    values: &[f64],
    count: usize,
    x: &[f64],
    y: &mut [f64],
) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for j in 0..count {
        let range = col_ptr[j]..col_ptr[j + 1];
        for (&i, &v) in row_idx[range.clone()].iter().zip(&values[range]) {
            if i >= count {
                continue;
            }
            y[i] += v * x[j];
            if i != j {
                y[j] += v * x[i];
            }
        }
    }
}
