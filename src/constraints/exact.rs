//! The `exact` constraint source (`docs/model.md#constraint-curves`): θ_r = f(θ_c) by Newton loop closure at every
//! evaluation, G = ∂f/∂θ_c by the implicit function theorem (T4.18) and f″ from the closure's
//! second-order condition, on the branch traced by an exact sweep.
//!
//! Along a closed path the holonomy's spatial angular velocity Σ_k x_k ρ̇_k vanishes (x_k the
//! world axis of ray k). Differentiating once more, with the axes moved by the joints before
//! them in the product of `docs/model.md#loop-closure` (rays 1, 2, …, n−1, then 0):
//!   Σ_k x_k ρ̈_k + Σ_{a before b} ρ̇_a ρ̇_b (x_a × x_b) = 0,
//! so J_dep f″ = −Σ_{a before b} ρ′_a ρ′_b (x_a × x_b) with ρ′ = (1 for the driver, G, 0 held).

use super::sweep::{CLOSURE_TOL, REFINE_ITERATIONS};
use super::{check_in_domain, CurveSamples};
use crate::error::{NumericalError, Result};
use crate::geometry::kinematics::{closure_jacobian, forward, refine_closure, solve_closure};
use crate::pattern::VertexPattern;
use nalgebra::{DMatrix, Vector3};
use std::cell::Cell;

/// Below this σ_min/σ_max of the dependents' closure Jacobian (a singular configuration such
/// as the flat state), G and f″ are extrapolated from two regular points a little inside the
/// domain (see [`ExactConstraint::evaluate`]).
const SINGULAR_RATIO: f64 = 1e-6;
/// Offset of those points from the singular one, rad.
const SINGULAR_OFFSET: f64 = 1e-4;
const NEWTON_ITERATIONS: usize = 20;

/// f, G and f″ at one driving angle; one entry per dependent crease.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintPoint {
    /// f: the dependents' angles, rad.
    pub values: Vec<f64>,
    /// G = ∂f/∂θ_c.
    pub jacobian: Vec<f64>,
    /// f″ = ∂²f/∂θ_c².
    pub curvature: Vec<f64>,
}

impl ConstraintPoint {
    /// A point for `dependents` dependent creases, all zero.
    pub fn zeros(dependents: usize) -> Self {
        ConstraintPoint {
            values: vec![0.0; dependents],
            jacobian: vec![0.0; dependents],
            curvature: vec![0.0; dependents],
        }
    }
}

/// Exact loop closure along one branch, for any number of drivers (the sweep's one driver, or
/// several for a multi-DOF linearisation).
#[derive(Debug, Clone)]
pub struct ExactConstraint {
    sectors: Vec<f64>,
    /// Label of the (first) driver for errors.
    driver_label: String,
    driver_ray: usize,
    dependent_rays: Vec<usize>,
    /// Ray angles with the held rays at their lock values (the others are overwritten).
    base: Vec<f64>,
    /// The branch: driving angles (ascending) and ray angles of the sweep's samples.
    branch_drive: Vec<f64>,
    branch_rays: Vec<Vec<f64>>,
    /// The swept interval of the driving angle, rad.
    pub domain: [f64; 2],
    /// How far beyond `domain` the current evaluation may go.
    margin: Cell<f64>,
}

impl ExactConstraint {
    /// The branch traced by an exact sweep (`samples.source` should be `Sweep`).
    pub fn new(pattern: &VertexPattern, samples: &CurveSamples) -> Self {
        let setup = &samples.setup;
        let base = setup.base_ray_angles(pattern);
        let branch_rays = samples
            .fold_angles
            .iter()
            .map(|angles| {
                let mut rho = base.clone();
                for (c, crease) in pattern.creases.iter().enumerate() {
                    rho[crease.ray] = angles[c];
                }
                rho
            })
            .collect();
        ExactConstraint {
            sectors: pattern.sector_angles.clone(),
            driver_label: pattern.creases[setup.driver].label.clone(),
            driver_ray: pattern.creases[setup.driver].ray,
            dependent_rays: setup.dependents.iter().map(|&c| pattern.creases[c].ray).collect(),
            base,
            branch_drive: samples.drive_angles.clone(),
            branch_rays,
            domain: samples.domain,
            margin: Cell::new(0.0),
        }
    }

    fn check_domain(&self, theta: f64, margin: f64) -> Result<()> {
        check_in_domain(&self.driver_label, self.domain, theta, margin)
    }

    /// Ray angles of the closed configuration at driving angle θ: Newton from the branch's
    /// samples on either side, interpolated linearly.
    pub fn closed_rays(&self, theta: f64) -> Result<Vec<f64>> {
        self.check_domain(theta, self.margin.get())?;
        let upper = self
            .branch_drive
            .partition_point(|&x| x < theta)
            .clamp(1, self.branch_drive.len() - 1);
        let (x0, x1) = (self.branch_drive[upper - 1], self.branch_drive[upper]);
        let weight = ((theta - x0) / (x1 - x0)).clamp(0.0, 1.0);
        let mut rho = self.base.clone();
        for &ray in &self.dependent_rays {
            rho[ray] = (1.0 - weight) * self.branch_rays[upper - 1][ray] + weight * self.branch_rays[upper][ray];
        }
        rho[self.driver_ray] = theta;
        solve_closure(
            &self.sectors,
            &mut rho,
            &self.dependent_rays,
            CLOSURE_TOL,
            NEWTON_ITERATIONS,
        )?;
        refine_closure(&self.sectors, &mut rho, &self.dependent_rays, REFINE_ITERATIONS);
        Ok(rho)
    }

    /// G and f″ at a closed configuration, or None where the dependents' Jacobian is singular.
    fn derivatives(&self, rho: &[f64], point: &mut ConstraintPoint) -> Result<bool> {
        let (_, j_dep) = closure_jacobian(&self.sectors, rho, &self.dependent_rays);
        let (_, j_driver) = closure_jacobian(&self.sectors, rho, &[self.driver_ray]);
        let svd = j_dep.svd(true, true);
        let (largest, smallest) = (svd.singular_values.max(), svd.singular_values.min());
        if smallest < SINGULAR_RATIO * largest {
            return Ok(false);
        }
        let numerical = |e: &str| NumericalError::Singular {
            what: "exact constraint",
            detail: e.to_string(),
        };
        let g = svd.solve(&(-j_driver), 0.0).map_err(numerical)?;
        let mut rates = vec![0.0; rho.len()];
        rates[self.driver_ray] = 1.0;
        for (&ray, &gi) in self.dependent_rays.iter().zip(g.iter()) {
            rates[ray] = gi;
        }
        let bias = closure_bias(&self.sectors, rho, &rates);
        let curvature = svd
            .solve(&DMatrix::from_column_slice(3, 1, (-bias).as_slice()), 0.0)
            .map_err(numerical)?;
        point.jacobian.copy_from_slice(g.as_slice());
        point.curvature.copy_from_slice(curvature.as_slice());
        Ok(true)
    }

    /// f(θ), G(θ) and f″(θ). At a singular configuration (σ_min/σ_max < 1e-6: the flat
    /// state, where the closure Jacobian drops rank) f is still Newton's, while G and f″ are
    /// the Taylor expansion from the regular points θ + δ, θ + 2δ inside the domain
    /// (δ = 1e-4 rad; G's error O(δ³ f⁗)).
    pub fn evaluate(&self, theta: f64, point: &mut ConstraintPoint) -> Result<()> {
        self.evaluate_extended(theta, 0.0, point)
    }

    /// [`ExactConstraint::evaluate`] that also continues the closure up to `margin` (rad)
    /// beyond the swept domain, for an integrator's trial stages.
    pub fn evaluate_extended(&self, theta: f64, margin: f64, point: &mut ConstraintPoint) -> Result<()> {
        self.margin.set(margin);
        let result = self.evaluate_in_margin(theta, point);
        self.margin.set(0.0);
        result
    }

    fn evaluate_in_margin(&self, theta: f64, point: &mut ConstraintPoint) -> Result<()> {
        let rho = self.closed_rays(theta)?;
        for (v, &ray) in point.values.iter_mut().zip(&self.dependent_rays) {
            *v = rho[ray];
        }
        if self.derivatives(&rho, point)? {
            return Ok(());
        }
        let inward = if theta - self.domain[0] <= self.domain[1] - theta {
            1.0
        } else {
            -1.0
        };
        let mut near = ConstraintPoint::zeros(self.dependent_rays.len());
        let mut far = near.clone();
        let (theta1, theta2) = (theta + inward * SINGULAR_OFFSET, theta + 2.0 * inward * SINGULAR_OFFSET);
        let regular = self.derivatives(&self.closed_rays(theta1)?, &mut near)?
            && self.derivatives(&self.closed_rays(theta2)?, &mut far)?;
        if !regular {
            return Err(NumericalError::Singular {
                what: "exact constraint",
                detail: format!(
                    "the closure Jacobian at and near {} = {:.6}°: the dependents are not a function of it here",
                    self.driver_label,
                    theta.to_degrees()
                ),
            }
            .into());
        }
        let step = theta - theta1;
        for k in 0..self.dependent_rays.len() {
            let third = (far.curvature[k] - near.curvature[k]) / (theta2 - theta1);
            point.jacobian[k] = near.jacobian[k] + near.curvature[k] * step + 0.5 * third * step * step;
            point.curvature[k] = near.curvature[k] + third * step;
        }
        Ok(())
    }

    /// Number of dependents.
    pub fn dependent_count(&self) -> usize {
        self.dependent_rays.len()
    }
}

/// Σ_{a before b} ρ̇_a ρ̇_b (x_a × x_b) over the product order of `docs/model.md#loop-closure` (rays 1 … n−1, then
/// ray 0): the velocity-product part of the holonomy's spatial angular acceleration at a
/// closed configuration.
pub fn closure_bias(sector_angles: &[f64], fold_angles: &[f64], rates: &[f64]) -> Vector3<f64> {
    let n = fold_angles.len();
    let nodes = forward(sector_angles, fold_angles);
    let mut upstream = Vector3::zeros();
    let mut bias = Vector3::zeros();
    for k in (1..n).chain([0]) {
        let axis_rate = nodes[k] * rates[k];
        bias += upstream.cross(&axis_rate);
        upstream += axis_rate;
    }
    bias
}

/// G for several drivers at once by the implicit function theorem: J_dep G = −J_drivers,
/// rows per dependent ray, columns per driver ray. An error at a singular configuration.
pub fn implicit_jacobian_rays(
    sector_angles: &[f64],
    rho: &[f64],
    driver_rays: &[usize],
    dependent_rays: &[usize],
) -> Result<DMatrix<f64>> {
    let (_, j_dep) = closure_jacobian(sector_angles, rho, dependent_rays);
    let (_, j_drivers) = closure_jacobian(sector_angles, rho, driver_rays);
    let svd = j_dep.svd(true, true);
    let (largest, smallest) = (svd.singular_values.max(), svd.singular_values.min());
    if smallest < SINGULAR_RATIO * largest {
        return Err(NumericalError::Singular {
            what: "implicit-function Jacobian",
            detail: format!("singular configuration (σ_min/σ_max = {:.1e})", smallest / largest),
        }
        .into());
    }
    svd.solve(&(-j_drivers), 0.0).map_err(|e| {
        NumericalError::Singular {
            what: "implicit-function Jacobian",
            detail: e.to_string(),
        }
        .into()
    })
}
