//! Per-vertex loop closure of a crease pattern and its sparse Jacobian
//! (`docs/model.md#rigid-folding`): at interior vertex v the holonomy of its star,
//! R_z(α_0) R_x(ρ_1) … R_z(α_{k−1}) R_x(ρ_0), is the identity; its rotation vector r_v is
//! the residual, three rows of J per vertex, one column per crease.

use super::model::FoldingModel;
use crate::geometry::kinematics;
use crate::geometry::sphere::Vec3;
use faer::sparse::{SparseColMat, Triplet};

/// The stacked closure residual and its Jacobian at one state.
#[derive(Debug, Clone)]
pub struct ClosureJacobian {
    /// Rotation vector of each star's holonomy, 3 entries per star (in `model.stars` order).
    pub residual: Vec<f64>,
    /// Rows (3 per star).
    pub rows: usize,
    /// Columns (one per crease).
    pub cols: usize,
    /// Non-zero entries (row, column, value): ∂r/∂ρ. A locked crease's entries are 0 (kept
    /// in the structure): it does not move.
    pub entries: Vec<(usize, usize, f64)>,
    /// Number of locked columns (zeroed above).
    pub held: usize,
    /// The pattern's angle precision (`CreasePattern::angle_precision`), rad: a rank count
    /// allows singular values this small relative to the largest as null.
    pub angle_precision: f64,
}

impl ClosureJacobian {
    /// Holds crease `column` where it is: its column zeroed, not removed, so the sparsity
    /// pattern (and the factorisation's symbolic analysis) stays.
    pub fn hold(&mut self, column: usize) {
        for entry in self.entries.iter_mut().filter(|e| e.1 == column) {
            entry.2 = 0.0;
        }
    }

    /// The Jacobian over the columns where `keep` is true, in their order (none held).
    pub fn columns(&self, keep: &[bool]) -> ClosureJacobian {
        let mut position = vec![usize::MAX; self.cols];
        for (k, c) in (0..self.cols).filter(|&c| keep[c]).enumerate() {
            position[c] = k;
        }
        ClosureJacobian {
            residual: self.residual.clone(),
            rows: self.rows,
            cols: keep.iter().filter(|&&k| k).count(),
            entries: self
                .entries
                .iter()
                .filter(|e| keep[e.1])
                .map(|&(r, c, v)| (r, position[c], v))
                .collect(),
            held: 0,
            angle_precision: self.angle_precision,
        }
    }

    /// The Jacobian as a faer sparse matrix (duplicate entries summed).
    pub fn to_sparse(&self) -> SparseColMat<usize, f64> {
        let triplets: Vec<Triplet<usize, usize, f64>> =
            self.entries.iter().map(|&(r, c, v)| Triplet::new(r, c, v)).collect();
        SparseColMat::try_new_from_triplets(self.rows, self.cols, &triplets)
            .expect("entries are within the matrix and few enough for usize indices")
    }

    /// The largest vertex residual |r_v|, rad.
    pub fn worst_residual(&self) -> f64 {
        worst_of(&self.residual)
    }

    /// y = J x.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for &(r, c, v) in &self.entries {
            y[r] += v * x[c];
        }
    }

    /// x = Jᵀ y.
    pub fn apply_transpose(&self, y: &[f64], x: &mut [f64]) {
        x.iter_mut().for_each(|v| *v = 0.0);
        for &(r, c, v) in &self.entries {
            x[c] += v * y[r];
        }
    }
}

/// Fold angles of a star's creases in ray order.
fn star_angles(columns: &[usize], fold_angles: &[f64], out: &mut Vec<f64>) {
    out.clear();
    out.extend(columns.iter().map(|&c| fold_angles[c]));
}

/// The closure residual of every star, rad (`model.stars` order).
pub fn vertex_residuals(model: &FoldingModel, fold_angles: &[f64]) -> Vec<f64> {
    let mut by_ray = Vec::new();
    model
        .stars
        .iter()
        .map(|star| {
            star_angles(&star.columns, fold_angles, &mut by_ray);
            kinematics::closure_residual(&star.sector_angles, &by_ray)
        })
        .collect()
}

/// The stacked residual alone (3 entries per star, as [`ClosureJacobian::residual`], equal
/// to it bit for bit) into `residual`: what a chord step needs.
pub fn closure_residual(model: &FoldingModel, fold_angles: &[f64], residual: &mut Vec<f64>) {
    residual.clear();
    let fold_trig: Vec<(f64, f64)> = fold_angles.iter().map(|a| a.sin_cos()).collect();
    let mut by_ray = Vec::new();
    for (s, star) in model.stars.iter().enumerate() {
        by_ray.clear();
        by_ray.extend(star.columns.iter().map(|&c| fold_trig[c]));
        let r = kinematics::closure_residual_trig(&model.sector_trig[s], &by_ray);
        residual.extend(r.iter());
    }
}

/// The largest vertex residual |r_v| of a stacked residual, rad.
pub fn worst_of(residual: &[f64]) -> f64 {
    residual
        .chunks(3)
        .map(|r| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt())
        .fold(0.0, f64::max)
}

/// The stacked residual and the sparse Jacobian ∂r/∂ρ at `fold_angles` (one per crease).
pub fn closure_jacobian(model: &FoldingModel, fold_angles: &[f64]) -> ClosureJacobian {
    let mut residual = Vec::with_capacity(3 * model.stars.len());
    let mut entries = Vec::with_capacity(3 * model.stars.iter().map(|s| s.columns.len()).sum::<usize>());
    // Each crease's sine and cosine once (two stars hold it), the sectors' from the model.
    let fold_trig: Vec<(f64, f64)> = fold_angles.iter().map(|a| a.sin_cos()).collect();
    let (mut by_ray, mut nodes, mut columns) = (Vec::new(), Vec::new(), Vec::new());
    for (s, star) in model.stars.iter().enumerate() {
        by_ray.clear();
        by_ray.extend(star.columns.iter().map(|&c| fold_trig[c]));
        let degree = star.columns.len();
        nodes.resize(degree, Vec3::zeros());
        columns.resize(degree, Vec3::zeros());
        let r = kinematics::closure_jacobian_trig(&model.sector_trig[s], &by_ray, &mut nodes, &mut columns);
        residual.extend(r.iter());
        for (j, &column) in star.columns.iter().enumerate() {
            let scale = if model.locked_columns[column] { 0.0 } else { 1.0 };
            for (i, value) in columns[j].iter().enumerate() {
                entries.push((3 * s + i, column, scale * value));
            }
        }
    }
    ClosureJacobian {
        residual,
        rows: 3 * model.stars.len(),
        cols: model.crease_count(),
        entries,
        held: model.locked_columns.iter().filter(|&&l| l).count(),
        angle_precision: model.pattern.angle_precision,
    }
}
