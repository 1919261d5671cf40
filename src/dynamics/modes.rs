//! Linearised stability and natural frequencies at an equilibrium (`docs/model.md#modes`):
//! M(θ*) δθ̈ + K δθ = 0, i.e. the eigenvalues λ of M⁻¹K and f = √λ / 2π.

use super::algorithms::{update_kinematics, update_mass_matrix};
use super::model::{Data, Model};
use crate::error::{NumericalError, Result};
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Eigen-analysis of one equilibrium, modes sorted by descending eigenvalue.
#[derive(Debug, Clone)]
pub struct Modes {
    /// θ* where M was evaluated, rad.
    pub equilibrium: DVector<f64>,
    /// λ of M⁻¹K, rad²/s², descending.
    pub eigenvalues: Vec<f64>,
    /// √λ / 2π, Hz, descending.
    pub frequencies_hz: Vec<f64>,
    /// Mode shapes as columns, each scaled to unit max-norm with its largest entry positive.
    pub mode_shapes: DMatrix<f64>,
    /// K positive definite, so every λ > 0 and the equilibrium is a strict energy minimum.
    pub stable: bool,
}

/// Solves K φ = λ M φ at the equilibrium of an open chain (K the diagonal hinge stiffness).
///
/// ```
/// use nanofold::prelude::*;
/// use nanofold::dynamics::modes::modes;
/// let scene = load_scene("patterns/bridge_step.scene.json".as_ref())?.build()?;
/// let bridge = scene.strip().unwrap();
/// let folded = modes(&bridge.model, bridge.target_angles().as_slice())?;
/// // Four modes, the 20 µm tip plate's the fastest (hundreds of kHz), all stable.
/// assert!(folded.stable && folded.frequencies_hz[0] > 1e5);
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn modes(model: &Model, equilibrium: &[f64]) -> Result<Modes> {
    let mut data = Data::new(model);
    update_kinematics(model, equilibrium, &mut data);
    update_mass_matrix(model, &mut data);
    let stiffness = DMatrix::from_diagonal(&model.stiffness());
    let mut result = generalized_modes(&data.mass_matrix, &stiffness, DVector::from_column_slice(equilibrium))?;
    result.stable &= model.joints().iter().all(|j| j.stiffness > 0.0);
    Ok(result)
}

/// K φ = λ M φ for a symmetric positive definite M and a symmetric K, through the Cholesky
/// factor M = L Lᵀ: (L⁻¹ K L⁻ᵀ) v = λ v, φ = L⁻ᵀ v. Stable when every λ > 0.
pub fn generalized_modes(mass: &DMatrix<f64>, stiffness: &DMatrix<f64>, equilibrium: DVector<f64>) -> Result<Modes> {
    let n = mass.nrows();
    let singular = || NumericalError::Singular {
        what: "modes",
        detail: "the mass matrix's Cholesky factor".into(),
    };
    let cholesky = mass
        .clone()
        .cholesky()
        .ok_or_else(|| NumericalError::NotPositiveDefinite {
            matrix: "the mass matrix",
            at: format!("the equilibrium {:?} rad", equilibrium.as_slice()),
        })?;
    let l = cholesky.l();
    let l_inv_k = l.solve_lower_triangular(stiffness).ok_or_else(singular)?;
    let a = l.solve_lower_triangular(&l_inv_k.transpose()).ok_or_else(singular)?;
    let symmetric = 0.5 * (&a + a.transpose());
    let eigen = SymmetricEigen::new(symmetric);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| eigen.eigenvalues[j].total_cmp(&eigen.eigenvalues[i]));
    let shapes_unscaled = l
        .transpose()
        .solve_upper_triangular(&eigen.eigenvectors)
        .ok_or_else(singular)?;
    let mut mode_shapes = DMatrix::zeros(n, n);
    let mut eigenvalues = Vec::with_capacity(n);
    for (column, &k) in order.iter().enumerate() {
        let shape = shapes_unscaled.column(k);
        let largest = shape
            .iter()
            .copied()
            .fold(0.0_f64, |a, b| if b.abs() > a.abs() { b } else { a });
        mode_shapes.set_column(column, &(shape / largest));
        eigenvalues.push(eigen.eigenvalues[k]);
    }
    if eigenvalues.iter().any(|l| !l.is_finite()) {
        return Err(NumericalError::NonFinite {
            what: "modes",
            detail: format!(
                "eigenvalues of M⁻¹K overflow ({eigenvalues:?}): stiffness and inertia are too far apart in double precision; check the scene's units"
            ),
        }
        .into());
    }
    let stable = eigenvalues.iter().all(|&l| l > 0.0);
    Ok(Modes {
        equilibrium,
        frequencies_hz: eigenvalues
            .iter()
            .map(|&l| l.max(0.0).sqrt() / std::f64::consts::TAU)
            .collect(),
        eigenvalues,
        mode_shapes,
        stable,
    })
}
