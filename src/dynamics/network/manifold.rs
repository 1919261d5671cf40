//! The constraint manifold of a panel network (`docs/model.md#panel-networks`): closure
//! restored by Newton, the tangent space, the hinges' equilibrium on the manifold (statics)
//! and the linearised modes about it.
//!
//! The equilibrium minimises V(ρ) = Σ_c ½ K_c (ρ_c − r_c)² (r_c the drive angle of an
//! actuated hinge, 0 for a passive one) subject to every vertex closure: Newton on the
//! Lagrangian L = V + λᵀΦ, whose Hessian is K + Σ_r λ_r ∇²Φ_r; the stars' second
//! derivatives are ½ (x_a × x_b) for crease a before b in the holonomy's product (the
//! velocity product of the closure rows). About it, the modes solve
//! Zᵀ(K + Σ λ ∇²Φ)Z φ = ω² ZᵀMZ φ with Z a basis of the tangent space.

use super::algorithms::{update_kinematics, update_mass_matrix, update_stars, NetworkData};
use super::hessian::HessianSystem;
use super::model::NetworkModel;
use crate::dynamics::modes::{generalized_modes, Modes};
use crate::error::{NanofoldError, NumericalError, Result};
use crate::folding::normal::NormalSolver;
use crate::folding::{closure_jacobian, null_space, restore_closure, vertex_residuals};
use nalgebra::{DMatrix, DVector};

/// Closure tolerance of every projected state, rad per vertex.
pub const CLOSURE_TOL: f64 = 1e-12;
/// μ of the Newton projections, relative to JᵀJ's largest diagonal entry.
const PROJECTION_REGULARISATION: f64 = 1e-12;
/// Largest change of any fold angle in one Newton step of the statics, rad.
const STATICS_STEP_CAP: f64 = 0.1;
/// Newton steps of the statics.
const STATICS_ITERATIONS: usize = 200;
/// The statics stops once its step is below this, rad.
const STATICS_STEP_TOL: f64 = 1e-12;
/// The statics takes Newton steps (with the closures' curvature) once its step is below this, rad.
const NEWTON_SWITCH: f64 = 1e-4;

/// Moves `angles` onto every vertex closure (least-norm Newton, locked creases held), within
/// [`CLOSURE_TOL`]; an error naming the residual when Newton does not get there.
pub fn restore(model: &NetworkModel, angles: &mut [f64], solver: &mut NormalSolver) -> Result<usize> {
    match restore_closure(&model.folding, angles, CLOSURE_TOL, solver)? {
        Some(iterations) => Ok(iterations),
        None => {
            // Past a half turn and more the crease's panels have gone through each other:
            // the state is no folding any more, whatever its closure.
            if let Some(c) = angles.iter().position(|r| r.abs() > std::f64::consts::PI + 0.5) {
                return Err(NumericalError::PanelsThrough {
                    crease: model.folding.pattern.creases[c],
                    angle_deg: angles[c].to_degrees(),
                }
                .into());
            }
            // The residual where Newton gave up.
            Err(NumericalError::ClosureNotConverged {
                residual: worst_residual(model, angles),
                iterations: 30,
            }
            .into())
        }
    }
}

/// A Newton solver for [`restore`].
pub fn projection_solver() -> NormalSolver {
    NormalSolver::new(PROJECTION_REGULARISATION)
}

/// The largest vertex closure residual, rad.
pub fn worst_residual(model: &NetworkModel, angles: &[f64]) -> f64 {
    vertex_residuals(&model.folding, angles).into_iter().fold(0.0, f64::max)
}

/// An orthonormal basis of the tangent space at `angles` (one column per direction, zero on
/// locked creases): the null space of the closure Jacobian over the free creases.
pub fn tangent_basis(model: &NetworkModel, angles: &[f64]) -> Result<DMatrix<f64>> {
    let full = closure_jacobian(&model.folding, angles);
    let free: Vec<usize> = (0..model.columns()).filter(|&c| !model.locked(c)).collect();
    let keep: Vec<bool> = (0..model.columns()).map(|c| !model.locked(c)).collect();
    let basis = null_space(&full.columns(&keep))?;
    let mut z = DMatrix::zeros(model.columns(), basis.ncols());
    for (k, &c) in free.iter().enumerate() {
        for j in 0..basis.ncols() {
            z[(c, j)] = basis[(k, j)];
        }
    }
    Ok(z)
}

/// M z for a vector of fold rates (M on the tree creases, zero off it); needs the mass matrix.
pub fn mass_times(model: &NetworkModel, data: &NetworkData, z: &[f64], out: &mut [f64]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    for (&(a, c), m) in model.mass_pattern.iter().zip(&data.mass_values) {
        out[a] += m * z[c];
        if a != c {
            out[c] += m * z[a];
        }
    }
}

/// Zᵀ M Z at `angles`.
pub fn reduced_mass(model: &NetworkModel, angles: &[f64], basis: &DMatrix<f64>) -> DMatrix<f64> {
    let mut data = NetworkData::new(model);
    update_kinematics(model, angles, &mut data);
    update_mass_matrix(model, &mut data);
    let (n, d) = (model.columns(), basis.ncols());
    let mut mz = DMatrix::zeros(n, d);
    let mut out = vec![0.0; n];
    for j in 0..d {
        let column: Vec<f64> = basis.column(j).iter().copied().collect();
        mass_times(model, &data, &column, &mut out);
        mz.set_column(j, &DVector::from_column_slice(&out));
    }
    let reduced = basis.transpose() * mz;
    0.5 * (&reduced + reduced.transpose())
}

/// Natural angular frequencies (rad/s, descending) of the hinges' springs about `angles`
/// on the tangent space there (Zᵀ K Z against Zᵀ M Z, no load term): the time scales.
pub fn spring_frequencies(model: &NetworkModel, angles: &[f64]) -> Result<Vec<f64>> {
    let basis = tangent_basis(model, angles)?;
    if basis.ncols() == 0 {
        return Ok(Vec::new());
    }
    let mass = reduced_mass(model, angles, &basis);
    let k = DMatrix::from_diagonal(&DVector::from_iterator(
        model.columns(),
        model.hinges.iter().map(|h| h.stiffness),
    ));
    let stiffness = basis.transpose() * k * &basis;
    let modes = generalized_modes(&mass, &stiffness, DVector::zeros(basis.ncols()))?;
    Ok(modes.eigenvalues.iter().map(|l| l.max(0.0).sqrt()).collect())
}

/// An equilibrium of the hinges on the manifold.
#[derive(Debug, Clone)]
pub struct Equilibrium {
    /// Every crease's angle, rad.
    pub angles: Vec<f64>,
    /// λ per closure row (3 per star, unscaled rows), N·m: ∇V + Jᵀλ = 0.
    pub multipliers: Vec<f64>,
    /// Newton steps taken.
    pub iterations: usize,
    /// Largest |∇V + Jᵀλ| left, N·m.
    pub residual_torque: f64,
    /// Largest vertex closure residual, rad.
    pub closure_residual: f64,
}

/// The minimum of V(ρ) = Σ ½ K (ρ − rest)² on the manifold nearest `start` (a closed state),
/// by Newton on the Lagrangian (`docs/model.md#panel-networks`). Locked creases stay.
pub fn equilibrium(model: &NetworkModel, rest: &[f64], start: &[f64], kkt: &mut HessianSystem) -> Result<Equilibrium> {
    let n = model.columns();
    let stiffness = model.stiffness();
    let mut angles = start.to_vec();
    let mut solver = projection_solver();
    restore(model, &mut angles, &mut solver)?;
    let mut data = NetworkData::new(model);
    let rows = 3 * model.folding.stars.len();
    let mut multipliers = vec![0.0; rows];
    let (mut f, b, mut step_vector) = (vec![0.0; n], vec![0.0; rows], vec![0.0; n]);
    // Gauss–Newton (the hinges' K alone) while far off, Newton (with the closures' curvature
    // weighted by the last multipliers) once the steps are small.
    let mut newton = false;
    for iteration in 0..STATICS_ITERATIONS {
        update_stars(model, &angles, None, &mut data);
        // The curvature can leave the Hessian indefinite far from a minimum: K alone then.
        if !(newton && kkt.assemble(&data, &stiffness, Some(&multipliers)).is_ok()) {
            kkt.assemble(&data, &stiffness, None)?;
        }
        let scale = kkt.scale();
        for c in 0..n {
            f[c] = if model.locked(c) {
                0.0
            } else {
                -stiffness[c] * (angles[c] - rest[c]) / scale
            };
        }
        kkt.solve(&f, &b, &mut step_vector);
        kkt.multipliers(&mut multipliers);
        if !step_vector.iter().chain(&multipliers).all(|v| v.is_finite()) {
            return Err(NumericalError::NonFinite {
                what: "the hinges' balance on the closure",
                detail: "a Newton step was not finite".into(),
            }
            .into());
        }
        let step = step_vector.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        newton = step < NEWTON_SWITCH;
        let cap = if step > STATICS_STEP_CAP {
            STATICS_STEP_CAP / step
        } else {
            1.0
        };
        for (a, d) in angles.iter_mut().zip(&step_vector) {
            *a += cap * d;
        }
        restore(model, &mut angles, &mut solver)?;
        if step <= STATICS_STEP_TOL {
            let residual_torque = stationarity(model, &angles, rest, &multipliers, &mut data);
            return Ok(Equilibrium {
                closure_residual: worst_residual(model, &angles),
                angles,
                multipliers,
                iterations: iteration + 1,
                residual_torque,
            });
        }
    }
    Err(NumericalError::NoEquilibrium {
        what: "the hinges' balance on the closure",
        detail: format!("Newton on the hinges' energy did not settle in {STATICS_ITERATIONS} steps"),
    }
    .into())
}

/// Largest |K(ρ − rest) + Jᵀλ| over the free creases, N·m.
fn stationarity(
    model: &NetworkModel,
    angles: &[f64],
    rest: &[f64],
    multipliers: &[f64],
    data: &mut NetworkData,
) -> f64 {
    update_stars(model, angles, None, data);
    let mut torque: Vec<f64> = (0..model.columns())
        .map(|c| model.hinges[c].stiffness * (angles[c] - rest[c]))
        .collect();
    let mut offset = 0;
    for (s, star) in model.folding.stars.iter().enumerate() {
        for (k, &c) in star.columns.iter().enumerate() {
            let axis = data.star_axes[offset + k];
            for i in 0..3 {
                torque[c] += axis[i] * multipliers[3 * s + i];
            }
        }
        offset += star.columns.len();
    }
    (0..model.columns())
        .filter(|&c| !model.locked(c))
        .map(|c| torque[c].abs())
        .fold(0.0, f64::max)
}

/// Linearised modes about an equilibrium on the manifold.
#[derive(Debug, Clone)]
pub struct ManifoldModes {
    /// The equilibrium.
    pub equilibrium: Equilibrium,
    /// Basis of the tangent space there (a column per degree of freedom).
    pub basis: DMatrix<f64>,
    /// Eigen-analysis in the basis's coordinates; `modes.equilibrium` is empty.
    pub modes: Modes,
    /// Mode shapes in every crease (Z φ, each scaled to unit max-norm), columns as in `modes`.
    pub crease_shapes: DMatrix<f64>,
    /// Frequencies from Zᵀ K Z alone (the load term dropped), Hz, descending.
    pub frequencies_without_load_hz: Vec<f64>,
}

/// Modes about `equilibrium`: Zᵀ(K + Σ λ ∇²Φ)Z φ = ω² ZᵀMZ φ (`docs/model.md#panel-networks`).
pub fn modes(model: &NetworkModel, equilibrium: Equilibrium) -> Result<ManifoldModes> {
    let angles = &equilibrium.angles;
    let basis = tangent_basis(model, angles)?;
    let d = basis.ncols();
    if d == 0 {
        return Err(NanofoldError::invalid(
            "pattern",
            "0 degrees of freedom",
            "the network is rigid at its equilibrium: it has no modes",
        ));
    }
    let mass = reduced_mass(model, angles, &basis);
    let n = model.columns();
    let mut hessian = DMatrix::from_diagonal(&DVector::from_iterator(n, model.hinges.iter().map(|h| h.stiffness)));
    let springs = basis.transpose() * &hessian * &basis;
    let mut data = NetworkData::new(model);
    update_stars(model, angles, None, &mut data);
    let mut offset = 0;
    for (s, star) in model.folding.stars.iter().enumerate() {
        let lambda = nalgebra::Vector3::new(
            equilibrium.multipliers[3 * s],
            equilibrium.multipliers[3 * s + 1],
            equilibrium.multipliers[3 * s + 2],
        );
        let k = star.columns.len();
        let place = |j: usize| if j == 0 { k } else { j };
        for a in 0..k {
            for b in 0..k {
                if place(a) < place(b) {
                    let value = 0.5 * lambda.dot(&data.star_axes[offset + a].cross(&data.star_axes[offset + b]));
                    let (ca, cb) = (star.columns[a], star.columns[b]);
                    hessian[(ca, cb)] += value;
                    hessian[(cb, ca)] += value;
                }
            }
        }
        offset += k;
    }
    let stiffness = basis.transpose() * hessian * &basis;
    let stiffness = 0.5 * (&stiffness + stiffness.transpose());
    let modes = generalized_modes(&mass, &stiffness, DVector::zeros(0))?;
    let without = generalized_modes(&mass, &(0.5 * (&springs + springs.transpose())), DVector::zeros(0))?;
    let mut crease_shapes = &basis * &modes.mode_shapes;
    for mut column in crease_shapes.column_iter_mut() {
        let largest = column
            .iter()
            .copied()
            .fold(0.0_f64, |a, b| if b.abs() > a.abs() { b } else { a });
        if largest != 0.0 {
            column /= largest;
        }
    }
    Ok(ManifoldModes {
        equilibrium,
        basis,
        modes,
        crease_shapes,
        frequencies_without_load_hz: without.frequencies_hz,
    })
}
