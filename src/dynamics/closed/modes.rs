//! Modes of a closed chain at its folded equilibrium (`docs/model.md#modes`): every lock is
//! released, so the coordinates θ_c are the driver and the locked creases (n − 3 of them for
//! a single vertex), the others follow by loop closure θ = θ(θ_c) with Γ = ∂θ/∂θ_c.
//!
//! The hinge energy V(θ_c) = Σ_i ½ K_i (θ_i − r_i)² (r_i: the driver's target, a released
//! lock's angle, 0 for a passive hinge) has gradient Σ K_i (θ_i − r_i) Γ_i and Hessian
//!   ∂²V/∂θ_c² = Γᵀ K Γ + Σ_i K_i (θ_i − r_i) ∂²θ_i/∂θ_c²,
//! the second term being the loaded passive hinges' share (zero in the thesis's Γᵀ K Γ,
//! which holds only where every hinge is at rest). The equilibrium is found by Newton on ∇V = 0
//! from the scene's folded pose; the modes solve ∂²V φ = λ (Γᵀ M Γ) φ there.

use super::ClosedChain;
use crate::constraints::exact::ConstraintPoint;
use crate::constraints::exact::{closure_bias, implicit_jacobian_rays};
use crate::constraints::sweep::{CLOSURE_TOL, REFINE_ITERATIONS};
use crate::dynamics::algorithms::{update_kinematics, update_mass_matrix};
use crate::dynamics::model::Data;
use crate::dynamics::modes::{generalized_modes, Modes};
use crate::error::{NumericalError, Result};
use crate::geometry::kinematics::{closure_jacobian, closure_residual, refine_closure, solve_closure};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

const CLOSURE_ITERATIONS: usize = 50;
const NEWTON_ITERATIONS: usize = 100;
/// Newton stops once its step on θ_c is below this, rad.
const NEWTON_STEP_TOL: f64 = 1e-13;
/// Largest Newton step, rad: keeps the closure's warm start on its branch.
const NEWTON_STEP_CAP: f64 = 0.05;

/// The linearisation of a closed chain at its folded equilibrium.
#[derive(Debug, Clone)]
pub struct ClosedModes {
    /// Creases used as coordinates: the driver, then the released locks.
    pub coordinates: Vec<usize>,
    /// Rest angle r_i of every hinge (file order), rad.
    pub rest_angles: Vec<f64>,
    /// Every crease's angle at the scene's folded pose (driver at its target, locks at their
    /// angles), where the search starts, rad.
    pub folded_pose: Vec<f64>,
    /// Every crease's angle at the equilibrium, rad.
    pub equilibrium: Vec<f64>,
    /// Largest |∂V/∂θ_c| left at the equilibrium, N·m.
    pub residual_torque: f64,
    /// Newton steps taken to the equilibrium.
    pub newton_iterations: usize,
    /// Loop-closure residual of `equilibrium`, rad.
    pub closure_residual: f64,
    /// Γ = ∂θ/∂θ_c: a row per crease, a column per coordinate.
    pub jacobian: DMatrix<f64>,
    /// Γᵀ M Γ over the open chain after the cut, kg·m².
    pub reduced_mass: DMatrix<f64>,
    /// Γᵀ K Γ, N·m/rad.
    pub hinge_stiffness: DMatrix<f64>,
    /// Σ K_i (θ_i − r_i) ∂²θ_i/∂θ_c², N·m/rad.
    pub load_stiffness: DMatrix<f64>,
    /// Eigen-analysis of (Γᵀ K Γ + load) φ = λ Γᵀ M Γ φ; `modes.equilibrium` holds θ_c.
    pub modes: Modes,
    /// Frequencies from Γᵀ K Γ alone (the load term dropped), Hz, descending.
    pub frequencies_without_load_hz: Vec<f64>,
    /// Mode shapes in every crease (Γ φ), columns as in `modes`.
    pub crease_shapes: DMatrix<f64>,
    /// Creases folded past ±π at the equilibrium: the free equilibrium lies beyond a contact.
    pub folded_through: Vec<usize>,
}

/// A closed configuration with its first and second derivatives along the coordinates.
#[derive(Debug, Clone)]
pub struct ClosureState {
    /// Every crease's angle (file order), rad.
    pub angles: Vec<f64>,
    /// Γ: a row per crease, a column per coordinate.
    pub jacobian: DMatrix<f64>,
    /// ∂²θ_i/∂θ_c² per crease (zero for the coordinates).
    pub hessians: Vec<DMatrix<f64>>,
}

impl ClosedChain {
    /// The driver, then the locked creases: the coordinates once every lock is released.
    pub fn released_coordinates(&self) -> Vec<usize> {
        std::iter::once(self.driver)
            .chain(self.locked.iter().map(|&(c, _)| c))
            .collect()
    }

    /// Rest angle of every hinge with the locks released: the driver's target, a lock's
    /// angle (the hinge that holds it there), 0 for a passive hinge.
    pub fn rest_angles(&self) -> Vec<f64> {
        let mut rest = vec![0.0; self.crease_stiffness.len()];
        rest[self.driver] = self.target();
        for &(c, angle) in &self.locked {
            rest[c] = angle;
        }
        rest
    }

    /// Closes the loop at coordinate values `theta_c` (creases in `coordinates`), starting
    /// Newton from `guess` (every crease's angle), and returns Γ and ∂²θ/∂θ_c².
    pub fn closure_state(&self, coordinates: &[usize], theta_c: &[f64], guess: &[f64]) -> Result<ClosureState> {
        let creases = self.crease_rays.len();
        let dependents: Vec<usize> = (0..creases).filter(|c| !coordinates.contains(c)).collect();
        let coordinate_rays: Vec<usize> = coordinates.iter().map(|&c| self.crease_rays[c]).collect();
        let dependent_rays: Vec<usize> = dependents.iter().map(|&c| self.crease_rays[c]).collect();
        let mut rho = vec![0.0; self.sector_angles.len()];
        for (c, &ray) in self.crease_rays.iter().enumerate() {
            rho[ray] = guess[c];
        }
        for (&ray, &value) in coordinate_rays.iter().zip(theta_c) {
            rho[ray] = value;
        }
        solve_closure(
            &self.sector_angles,
            &mut rho,
            &dependent_rays,
            CLOSURE_TOL,
            CLOSURE_ITERATIONS,
        )?;
        refine_closure(&self.sector_angles, &mut rho, &dependent_rays, REFINE_ITERATIONS);
        let g = implicit_jacobian_rays(&self.sector_angles, &rho, &coordinate_rays, &dependent_rays)?;
        let m = coordinates.len();
        let mut jacobian = DMatrix::zeros(creases, m);
        for (a, &c) in coordinates.iter().enumerate() {
            jacobian[(c, a)] = 1.0;
        }
        for (k, &c) in dependents.iter().enumerate() {
            jacobian.set_row(c, &g.row(k));
        }
        // Second derivatives along a direction u: J_dep θ_dep″(u) = −bias(Γ u) (see
        // constraints::exact); the mixed ones by polarisation, the bias being quadratic in u.
        let (_, j_dep) = closure_jacobian(&self.sector_angles, &rho, &dependent_rays);
        let lu = j_dep.lu();
        let along = |u: &DVector<f64>| -> Result<DVector<f64>> {
            let rates_by_crease = &jacobian * u;
            let mut rates = vec![0.0; rho.len()];
            for (c, &ray) in self.crease_rays.iter().enumerate() {
                rates[ray] = rates_by_crease[c];
            }
            let bias = closure_bias(&self.sector_angles, &rho, &rates);
            lu.solve(&DVector::from_column_slice((-bias).as_slice()))
                .ok_or_else(|| {
                    NumericalError::Singular {
                        what: "closed-chain modes",
                        detail: "the dependents' closure Jacobian".into(),
                    }
                    .into()
                })
        };
        let unit = |a: usize| DVector::from_fn(m, |i, _| if i == a { 1.0 } else { 0.0 });
        let pure: Vec<DVector<f64>> = (0..m).map(|a| along(&unit(a))).collect::<Result<_>>()?;
        let mut hessians = vec![DMatrix::zeros(m, m); creases];
        for a in 0..m {
            for b in a..m {
                let second = if a == b {
                    pure[a].clone()
                } else {
                    (along(&(unit(a) + unit(b)))? - &pure[a] - &pure[b]) * 0.5
                };
                for (k, &c) in dependents.iter().enumerate() {
                    hessians[c][(a, b)] = second[k];
                    hessians[c][(b, a)] = second[k];
                }
            }
        }
        let angles = self.crease_rays.iter().map(|&ray| rho[ray]).collect();
        Ok(ClosureState {
            angles,
            jacobian,
            hessians,
        })
    }

    /// V, ∇V and ∂²V split into Γᵀ K Γ and the load term, at a closure state.
    pub fn hinge_energy(&self, state: &ClosureState, rest: &[f64]) -> (f64, DVector<f64>, DMatrix<f64>, DMatrix<f64>) {
        let m = state.jacobian.ncols();
        let mut energy = 0.0;
        let mut gradient = DVector::zeros(m);
        let mut hinge = DMatrix::zeros(m, m);
        let mut load = DMatrix::zeros(m, m);
        for (c, &k) in self.crease_stiffness.iter().enumerate() {
            let stretch = state.angles[c] - rest[c];
            let row = state.jacobian.row(c).transpose();
            energy += 0.5 * k * stretch * stretch;
            gradient += k * stretch * &row;
            hinge += k * &row * row.transpose();
            load += k * stretch * &state.hessians[c];
        }
        (energy, gradient, hinge, load)
    }

    /// Γᵀ M Γ at a closure state, M of the open chain after the cut (symmetrised), kg·m².
    pub fn reduced_mass_matrix(&self, state: &ClosureState, data: &mut Data) -> DMatrix<f64> {
        let joint_angles: Vec<f64> = self.joint_creases.iter().map(|&c| state.angles[c]).collect();
        let joint_jacobian = state.jacobian.select_rows(&self.joint_creases);
        update_kinematics(&self.model, &joint_angles, data);
        update_mass_matrix(&self.model, data);
        let reduced = joint_jacobian.transpose() * &data.mass_matrix * &joint_jacobian;
        0.5 * (&reduced + reduced.transpose())
    }

    /// Every crease's angle at the scene's folded pose: driver at its target, locks at their
    /// angles, the dependents from the scene's constraint source.
    pub fn folded_pose(&self) -> Result<Vec<f64>> {
        let mut point = ConstraintPoint::zeros(self.dependents.len());
        self.source.evaluate(self.target(), &mut point)?;
        let mut angles = vec![0.0; self.crease_stiffness.len()];
        angles[self.driver] = self.target();
        for &(c, angle) in &self.locked {
            angles[c] = angle;
        }
        for (k, &c) in self.dependents.iter().enumerate() {
            angles[c] = point.values[k];
        }
        Ok(angles)
    }

    /// The modes of the folded chain with every lock released (see the module's comment).
    pub fn folded_modes(&self) -> Result<ClosedModes> {
        let coordinates = self.released_coordinates();
        let rest = self.rest_angles();
        let folded_pose = self.folded_pose()?;
        let mut theta_c: Vec<f64> = coordinates.iter().map(|&c| folded_pose[c]).collect();
        let mut guess = folded_pose.clone();
        let mut iterations = 0;
        let mut state = self.closure_state(&coordinates, &theta_c, &guess)?;
        let (gradient, hinge, load) = loop {
            let (_, gradient, hinge, load) = self.hinge_energy(&state, &rest);
            let step = (&hinge + &load)
                .lu()
                .solve(&(-&gradient))
                .filter(|s| s.iter().all(|v| v.is_finite()))
                .ok_or_else(|| NumericalError::Singular {
                    what: "closed-chain equilibrium",
                    detail: format!(
                        "the hinge energy's Hessian at θ_c = {:?}°",
                        theta_c.iter().map(|t| t.to_degrees()).collect::<Vec<_>>()
                    ),
                })?;
            let size = step.amax();
            if size <= NEWTON_STEP_TOL {
                break (gradient, hinge, load);
            }
            if iterations == NEWTON_ITERATIONS {
                return Err(NumericalError::NoEquilibrium {
                    what: "closed-chain equilibrium",
                    detail: format!("Newton on ∇V = 0 did not converge: last step {size:.3e} rad"),
                }
                .into());
            }
            let scale = (NEWTON_STEP_CAP / size).min(1.0);
            for (t, s) in theta_c.iter_mut().zip(step.iter()) {
                *t += scale * s;
            }
            guess.clone_from(&state.angles);
            state = self.closure_state(&coordinates, &theta_c, &guess)?;
            iterations += 1;
        };
        let jacobian = state.jacobian.clone();
        let reduced_mass = self.reduced_mass_matrix(&state, &mut Data::new(&self.model));
        let stiffness = &hinge + &load;
        let theta_c = DVector::from_column_slice(&theta_c);
        let modes = generalized_modes(&reduced_mass, &stiffness, theta_c.clone())?;
        let without_load = generalized_modes(&reduced_mass, &hinge, theta_c)?;
        let crease_shapes = &jacobian * &modes.mode_shapes;
        let mut rho = vec![0.0; self.sector_angles.len()];
        for (c, &ray) in self.crease_rays.iter().enumerate() {
            rho[ray] = state.angles[c];
        }
        let folded_through = (0..state.angles.len())
            .filter(|&c| state.angles[c].abs() > PI + 1e-9)
            .collect();
        Ok(ClosedModes {
            coordinates,
            rest_angles: rest,
            folded_pose,
            residual_torque: gradient.amax(),
            newton_iterations: iterations,
            closure_residual: closure_residual(&self.sector_angles, &rho),
            equilibrium: state.angles,
            jacobian,
            reduced_mass,
            hinge_stiffness: hinge,
            load_stiffness: load,
            modes,
            frequencies_without_load_hz: without_load.frequencies_hz,
            crease_shapes,
            folded_through,
        })
    }
}
