//! The unfolding engine (SPEC §5): projected-gradient steps on the sphere. The direction
//! is the QP of [`crate::unfold::qp`] in tangent coordinates of the free nodes; a backtracking line
//! search on U refuses steps that carry a node through an arc; Newton projection restores
//! the arc-length, unit-norm and held-crease constraints; the driver decides the verdict.
//!
//! Layout after Pinocchio and argmin: [`UnfoldModel`] is the immutable description,
//! [`Workspace`] the scratch reused by every step, [`Unfolder::step`] one iteration and
//! [`unfold`] the loop with restarts that records the trajectory.

pub mod energy;
pub mod qp;

use crate::error::{NumericalError, Result};
use crate::geometry::kinematics;
use crate::geometry::sphere::{
    distance_to_arc, fold_angle, fold_angle_with_gradient, geodesic, geodesic_with_gradient, projects_onto_arc,
    side_of_arc, Vec3,
};
use crate::pattern::{Assignment, Chain, Pattern, RayRole};
use energy::{Arc, Energy, EnergyKind, EnergyWorkspace};
use nalgebra::{DVector, Matrix3, SymmetricEigen};
use qp::{ConstraintJacobian, DirectionProblem, QpMethod, RowSpace};
use serde::Serialize;
use std::f64::consts::PI;
use std::time::Instant;

/// Solver settings (plain data, Clarabel-style).
#[derive(Debug, Clone, Serialize)]
pub struct UnfoldSettings {
    pub energy: EnergyKind,
    /// Exponent p; `None` takes the energy's default (2 separable, 4 non-separable).
    pub p: Option<f64>,
    pub qp: QpMethod,
    /// Flat when every fold angle is at most this, radians.
    pub flat_tol: f64,
    /// Iterations spent past `flat_tol` polishing towards the exact flat state, until the
    /// line search is stationary (U resolves ρ only to about √ε ≈ 1e-8 there).
    pub polish_iterations: usize,
    pub max_iterations: usize,
    /// Constraints are restored to this residual after every step, radians.
    pub restore_tol: f64,
    /// Armijo sufficient-decrease constant.
    pub armijo: f64,
    /// Largest node displacement per step, radians (keeps trial steps off barriers).
    pub max_step_rad: f64,
    /// Finish with [`Unfolder::flatten`] (Newton onto ρ = 0) once within `flat_tol`, or when
    /// stalled within 1e-4 rad of flat; off, the line search polishes as far as it can.
    pub newton_flatten: bool,
    /// Weight κ of the bending metric: the direction minimises ½ yᵀ(I + SᵀS)y + ∇U·y where
    /// S takes second differences of the node displacements along the chain, scaled by
    /// √κ/ᾱ² (ᾱ the mean sector). The energy is stiff against short-wavelength bending
    /// (stiffness ~k⁴ for mode k) and soft against long-wavelength; this preconditions that
    /// spread. 0 is SPEC §5's plain QP (M = I).
    pub bending_metric: f64,
    /// Restarts from perturbed states when stuck, before a verdict.
    pub restarts: usize,
    /// Size of the restart perturbation, radians.
    pub restart_kick_rad: f64,
    pub seed: u64,
}

impl Default for UnfoldSettings {
    fn default() -> Self {
        UnfoldSettings {
            energy: EnergyKind::Separable,
            p: None,
            qp: QpMethod::Direct,
            flat_tol: 1e-6,
            polish_iterations: 500,
            max_iterations: 20_000,
            restore_tol: 1e-13,
            armijo: 1e-4,
            max_step_rad: 0.2,
            newton_flatten: true,
            bending_metric: 0.01,
            restarts: 3,
            restart_kick_rad: 0.05,
            seed: 1,
        }
    }
}

/// A crease held at a fixed fold angle: virtual and flat creases (0) and locked ones.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct HeldFold {
    pub ray: usize,
    pub target: f64,
}

/// The immutable description of a vertex for the solver.
#[derive(Debug, Clone)]
pub struct UnfoldModel {
    pub chain: Chain,
    pub node_count: usize,
    pub arcs: Vec<Arc>,
    /// Rays with a fold angle (all but boundary rays).
    pub fold_rays: Vec<usize>,
    /// Ray of each user crease, in file order.
    pub crease_rays: Vec<usize>,
    pub held: Vec<HeldFold>,
    /// Nodes 0 and 1 are fixed (gauge: sector 0 stays in the xy-plane); the rest are free.
    pub free: Vec<usize>,
    /// Exact flat layout: nodes at cumulative sector angles on the equator.
    pub flat_layout: Vec<Vec3>,
    /// Fold angles of the given folded state, per ray.
    pub folded_ray_angles: Vec<f64>,
    pub sector_angles: Vec<f64>,
}

/// Constraints restored by Newton projection, one row each.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ConstraintRow {
    Arc(usize),
    Held(usize),
    /// The fold angle at this ray is zero (only while [`Unfolder::flatten`] runs).
    Flat(usize),
    /// Component `k` (of the tangent plane at x_v) of x_v + x_w = 0: an antipodal pair held
    /// at its kink (see [`Unfolder::pin_antipodal_pairs`]).
    Antipodal {
        v: usize,
        w: usize,
        k: usize,
    },
}

impl UnfoldModel {
    pub fn new(pattern: &Pattern) -> UnfoldModel {
        let n = pattern.ray_count();
        let arcs: Vec<Arc> = pattern
            .sector_angles
            .iter()
            .enumerate()
            .map(|(k, &length)| Arc {
                a: k,
                b: (k + 1) % n,
                length,
            })
            .collect();
        let fold_rays: Vec<usize> = (0..n).filter(|&k| pattern.rays[k] != RayRole::Boundary).collect();
        let mut held = Vec::new();
        for (k, role) in pattern.rays.iter().enumerate() {
            match role {
                RayRole::Virtual => held.push(HeldFold { ray: k, target: 0.0 }),
                RayRole::Crease(i) => {
                    let c = &pattern.creases[*i];
                    if c.assignment == Assignment::Flat {
                        held.push(HeldFold { ray: k, target: 0.0 });
                    } else if c.locked {
                        held.push(HeldFold {
                            ray: k,
                            target: c.folded_angle,
                        });
                    }
                }
                RayRole::Boundary => {}
            }
        }
        let flat_layout = kinematics::forward(&pattern.sector_angles, &vec![0.0; n]);
        UnfoldModel {
            chain: pattern.chain,
            node_count: n,
            arcs,
            fold_rays,
            crease_rays: pattern.creases.iter().map(|c| c.ray).collect(),
            held,
            free: (2..n).collect(),
            flat_layout,
            folded_ray_angles: pattern.folded_ray_angles(),
            sector_angles: pattern.sector_angles.clone(),
        }
    }

    fn neighbours(&self, ray: usize) -> (usize, usize) {
        let n = self.node_count;
        ((ray + n - 1) % n, (ray + 1) % n)
    }

    /// Fold angle at `ray` measured from the nodes.
    pub fn fold_angle_at(&self, nodes: &[Vec3], ray: usize) -> f64 {
        let (prev, next) = self.neighbours(ray);
        fold_angle(&nodes[prev], &nodes[ray], &nodes[next])
    }

    /// Fold angle of every user crease, in file order.
    pub fn crease_angles(&self, nodes: &[Vec3]) -> Vec<f64> {
        self.crease_rays.iter().map(|&r| self.fold_angle_at(nodes, r)).collect()
    }

    /// Largest |ρ| over every ray that folds (creases and virtual rays).
    pub fn max_fold_angle(&self, nodes: &[Vec3]) -> f64 {
        self.fold_rays
            .iter()
            .map(|&r| self.fold_angle_at(nodes, r).abs())
            .fold(0.0, f64::max)
    }

    /// Largest |γ(x_a, x_b) − α| over all arcs.
    pub fn max_arc_residual(&self, nodes: &[Vec3]) -> f64 {
        self.arcs
            .iter()
            .map(|arc| (geodesic(&nodes[arc.a], &nodes[arc.b]) - arc.length).abs())
            .fold(0.0, f64::max)
    }

    /// Whether a row closes the loop (see [`crate::unfold::qp::JacobianRow::closing`]). The open
    /// chain is: arc (i−1, i) and the fold angle at ray i−1 for every free node i, both of
    /// which move x_i (along and across the arc) and nothing later. The arc back to node 0,
    /// fold angles at rays n−1 and 0, and antipodal pins close it.
    fn is_closing(&self, row: ConstraintRow) -> bool {
        match row {
            ConstraintRow::Arc(e) => self.arcs[e].b < self.arcs[e].a,
            ConstraintRow::Held(h) => self.closes_at_ray(self.held[h].ray),
            ConstraintRow::Flat(ray) => self.closes_at_ray(ray),
            ConstraintRow::Antipodal { .. } => true,
        }
    }

    fn closes_at_ray(&self, ray: usize) -> bool {
        ray == 0 || ray + 1 >= self.node_count
    }

    fn constraint_rows(&self) -> Vec<ConstraintRow> {
        let mut rows: Vec<ConstraintRow> = (0..self.arcs.len())
            .filter(|&e| self.arcs[e].a >= 2 || self.arcs[e].b >= 2)
            .map(ConstraintRow::Arc)
            .collect();
        rows.extend((0..self.held.len()).map(ConstraintRow::Held));
        rows
    }

    /// Node positions of the given folded state (forward kinematics, SPEC §2).
    pub fn folded_nodes(&self) -> Vec<Vec3> {
        kinematics::forward(&self.sector_angles, &self.folded_ray_angles)
    }
}

/// Wraps an angle difference into (−π, π].
fn wrap(angle: f64) -> f64 {
    let mut a = angle.rem_euclid(2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// Orthonormal tangent basis at a unit vector, without pole singularities: built from the
/// coordinate axis least aligned with x.
fn tangent_basis(x: &Vec3) -> [Vec3; 2] {
    let axis = if x.x.abs() <= x.y.abs() && x.x.abs() <= x.z.abs() {
        Vec3::x()
    } else if x.y.abs() <= x.z.abs() {
        Vec3::y()
    } else {
        Vec3::z()
    };
    let e1 = x.cross(&axis).normalize();
    let e2 = x.cross(&e1).normalize();
    [e1, e2]
}

/// Scratch reused across steps.
#[derive(Debug, Clone)]
pub struct Workspace {
    energy: EnergyWorkspace,
    gradient: Vec<Vec3>,
    trial_gradient: Vec<Vec3>,
    basis: Vec<[Vec3; 2]>,
    rows: Vec<ConstraintRow>,
    jacobian: ConstraintJacobian,
    residual: DVector<f64>,
    trial_residual: DVector<f64>,
    trial: Vec<Vec3>,
}

impl Workspace {
    fn resize_rows(&mut self, model: &UnfoldModel) {
        self.jacobian = ConstraintJacobian::new(self.rows.len(), 2 * model.free.len());
        self.residual = DVector::zeros(self.rows.len());
        self.trial_residual = DVector::zeros(self.rows.len());
    }

    fn new(model: &UnfoldModel) -> Workspace {
        let rows = model.constraint_rows();
        let m = model.free.len();
        Workspace {
            energy: EnergyWorkspace::default(),
            gradient: vec![Vec3::zeros(); model.node_count],
            trial_gradient: vec![Vec3::zeros(); model.node_count],
            basis: vec![[Vec3::zeros(); 2]; model.node_count],
            jacobian: ConstraintJacobian::new(rows.len(), 2 * m),
            residual: DVector::zeros(rows.len()),
            trial_residual: DVector::zeros(rows.len()),
            rows,
            trial: vec![Vec3::zeros(); model.node_count],
        }
    }
}

/// Fills the tangent bases of the free nodes.
pub fn fill_bases(model: &UnfoldModel, nodes: &[Vec3], basis: &mut [[Vec3; 2]]) {
    for &i in &model.free {
        basis[i] = tangent_basis(&nodes[i]);
    }
}

/// Residuals G(x) of the constraint rows.
fn fill_residuals(model: &UnfoldModel, rows: &[ConstraintRow], nodes: &[Vec3], out: &mut DVector<f64>) {
    for (r, row) in rows.iter().enumerate() {
        out[r] = match *row {
            ConstraintRow::Arc(e) => {
                let arc = model.arcs[e];
                geodesic(&nodes[arc.a], &nodes[arc.b]) - arc.length
            }
            ConstraintRow::Held(h) => {
                let held = model.held[h];
                wrap(model.fold_angle_at(nodes, held.ray) - held.target)
            }
            ConstraintRow::Flat(ray) => wrap(model.fold_angle_at(nodes, ray)),
            ConstraintRow::Antipodal { v, w, k } => tangent_basis(&nodes[v])[k].dot(&(nodes[v] + nodes[w])),
        };
    }
}

/// Jacobian of the constraint rows in the tangent coordinates (2 per free node).
fn fill_jacobian(
    model: &UnfoldModel,
    rows: &[ConstraintRow],
    nodes: &[Vec3],
    basis: &[[Vec3; 2]],
    out: &mut ConstraintJacobian,
) {
    let put = |out: &mut qp::JacobianRow, node: usize, g: &Vec3| {
        if node >= 2 {
            out.add(node - 2, [basis[node][0].dot(g), basis[node][1].dot(g)]);
        }
    };
    let put_fold_angle = |out: &mut qp::JacobianRow, ray: usize| {
        let (prev, next) = model.neighbours(ray);
        let (_, [gp, ga, gn]) = fold_angle_with_gradient(&nodes[prev], &nodes[ray], &nodes[next]);
        put(out, prev, &gp);
        put(out, ray, &ga);
        put(out, next, &gn);
    };
    for (row, out) in rows.iter().zip(out.rows.iter_mut()) {
        out.clear(model.is_closing(*row));
        match *row {
            ConstraintRow::Arc(e) => {
                let arc = model.arcs[e];
                let (_, ga, gb) = geodesic_with_gradient(&nodes[arc.a], &nodes[arc.b]);
                put(out, arc.a, &ga);
                put(out, arc.b, &gb);
            }
            ConstraintRow::Held(h) => put_fold_angle(out, model.held[h].ray),
            ConstraintRow::Flat(ray) => put_fold_angle(out, ray),
            ConstraintRow::Antipodal { v, w, k } => {
                let e = tangent_basis(&nodes[v])[k];
                put(out, v, &e);
                put(out, w, &e);
            }
        }
    }
}

/// Rows of S in the bending metric M = I + SᵀS (see [`UnfoldSettings::bending_metric`]):
/// for every ray with two neighbours, the three components of the second difference
/// x_prev − 2 x_ray + x_next of the node displacements, scaled by √(κ / ᾱ⁴).
pub fn bending_rows(model: &UnfoldModel, basis: &[[Vec3; 2]], kappa: f64) -> ConstraintJacobian {
    let n = model.node_count;
    let mean_sector = model.sector_angles.iter().sum::<f64>() / model.sector_angles.len() as f64;
    let weight = (kappa / mean_sector.powi(4)).sqrt();
    let mut rows = ConstraintJacobian::new(0, 2 * model.free.len());
    for centre in 0..n {
        let (prev, next) = model.neighbours(centre);
        let open_end = model.chain == Chain::Open && (centre == 0 || centre + 1 == n);
        if open_end {
            continue;
        }
        for axis in [Vec3::x(), Vec3::y(), Vec3::z()] {
            let mut row = qp::JacobianRow::default();
            row.clear(false);
            for (node, coefficient) in [(prev, 1.0), (centre, -2.0), (next, 1.0)] {
                if node >= 2 {
                    let c = weight * coefficient;
                    row.add(node - 2, [c * basis[node][0].dot(&axis), c * basis[node][1].dot(&axis)]);
                }
            }
            if !row.entries().is_empty() {
                rows.rows.push(row);
            }
        }
    }
    rows
}

/// Moves the free nodes by the tangent coordinates `y` (scaled by `t`) and renormalises.
pub fn retract(model: &UnfoldModel, nodes: &[Vec3], basis: &[[Vec3; 2]], y: &DVector<f64>, t: f64, out: &mut [Vec3]) {
    out.copy_from_slice(nodes);
    for (slot, &i) in model.free.iter().enumerate() {
        let d = basis[i][0] * y[2 * slot] + basis[i][1] * y[2 * slot + 1];
        out[i] = (nodes[i] + t * d).normalize();
    }
}

/// Residual below which [`restore`] halves a Newton step that does not reduce it.
const DAMPED_RESTORE_BELOW: f64 = 1e-8;

/// Newton projection onto the constraints (SPEC §5 "restore"): minimum-norm steps in the
/// tangent space, the factorisation reused while it converges (chord Newton) and refreshed
/// when it stalls. Each step is halved until the residual norm falls: near the flat state
/// A has singular values ~ρ and a full minimum-norm step can overshoot the region where
/// the linearisation holds (a 1e-6 rad fold with a 1e-12 closing error diverged without
/// it). Returns the final max residual; Err when it does not reach `tol`.
pub fn restore(
    model: &UnfoldModel,
    ws: &mut Workspace,
    nodes: &mut [Vec3],
    tol: f64,
    row_space: Option<&RowSpace>,
) -> Result<f64> {
    let mut basis = ws.basis.clone();
    let mut owned: Option<RowSpace> = None;
    let mut previous = f64::INFINITY;
    let mut stale = false;
    let mut moved = nodes.to_vec();
    fill_residuals(model, &ws.rows, nodes, &mut ws.residual);
    for iteration in 0..40 {
        let worst = ws.residual.amax();
        if !worst.is_finite() {
            return Err(NumericalError::NonFinite {
                what: "constraint restoration",
                detail: "a constraint residual".into(),
            }
            .into());
        }
        if worst <= tol {
            return Ok(worst);
        }
        let refresh = stale || (owned.is_none() && (row_space.is_none() || worst > 0.5 * previous || iteration >= 10));
        if refresh {
            fill_bases(model, nodes, &mut basis);
            fill_jacobian(model, &ws.rows, nodes, &basis, &mut ws.jacobian);
            owned = Some(RowSpace::new(&ws.jacobian)?);
        } else if owned.is_some() && worst > 0.9 * previous && iteration > 20 {
            break;
        }
        previous = worst;
        let rs = owned.as_ref().or(row_space).expect("a factorisation");
        let mut z = rs.solve_min_norm(&ws.residual);
        // Trust region: a minimum-norm step near flat can be far larger than the residual;
        // allow up to 10·√residual (what the ill-conditioning legitimately needs).
        let cap = 10.0 * worst.sqrt();
        let largest = z.amax();
        if largest > cap {
            z *= cap / largest;
        }
        let norm = ws.residual.norm();
        let mut fraction = 1.0;
        let mut accepted = false;
        // Damping is for the small residuals near flat; a large one means the trial step
        // was too long, which the line search's own halving fixes more cheaply.
        let halvings = if worst <= DAMPED_RESTORE_BELOW { 8 } else { 0 };
        for _ in 0..=halvings {
            retract(model, nodes, &basis, &z, -fraction, &mut moved);
            fill_residuals(model, &ws.rows, &moved, &mut ws.trial_residual);
            if ws.trial_residual.norm() < norm {
                accepted = true;
                break;
            }
            fraction *= 0.5;
        }
        if !accepted {
            if refresh {
                break;
            }
            // The chord factorisation is too old for this point: refresh and retry.
            stale = true;
            continue;
        }
        stale = false;
        nodes.copy_from_slice(&moved);
        std::mem::swap(&mut ws.residual, &mut ws.trial_residual);
    }
    let worst = ws.residual.amax();
    if worst <= tol {
        Ok(worst)
    } else {
        Err(NumericalError::RestorationFailed {
            residual: worst,
            tolerance: tol,
        }
        .into())
    }
}

/// Largest distance a node moved (chord, radians to first order).
fn largest_move(before: &[Vec3], after: &[Vec3]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

/// Smallest geodesic distance from a node to an arc it is not an end of.
pub fn node_arc_clearance(model: &UnfoldModel, nodes: &[Vec3]) -> f64 {
    let mut clearance = f64::INFINITY;
    for arc in &model.arcs {
        for (v, node) in nodes.iter().enumerate() {
            if v != arc.a && v != arc.b {
                clearance = clearance.min(distance_to_arc(&nodes[arc.a], &nodes[arc.b], node));
            }
        }
    }
    clearance
}

/// Does the straight-line motion from `before` to `after` carry a node through an arc
/// (a sector through another)? Returns the first (arc, node) found.
pub fn find_crossing(model: &UnfoldModel, before: &[Vec3], after: &[Vec3]) -> Option<(usize, usize)> {
    for (e, arc) in model.arcs.iter().enumerate() {
        for v in 0..model.node_count {
            if v == arc.a || v == arc.b {
                continue;
            }
            let s0 = side_of_arc(&before[arc.a], &before[arc.b], &before[v]);
            let s1 = side_of_arc(&after[arc.a], &after[arc.b], &after[v]);
            if (s0 > 0.0 && s1 > 0.0) || (s0 < 0.0 && s1 < 0.0) || (s0 == 0.0 && s1 == 0.0) {
                continue;
            }
            let f = if s0 == s1 { 0.0 } else { s0 / (s0 - s1) };
            let lerp = |i: usize| before[i] + f * (after[i] - before[i]);
            if projects_onto_arc(&lerp(arc.a), &lerp(arc.b), &lerp(v)) {
                return Some((e, v));
            }
        }
    }
    None
}

/// Approximate Wolfe condition φ'(t) ≤ (2δ − 1)φ'(0) with δ = 0.1, written for
/// φ'(0) = −slope; the extra φ'(t) < 0 keeps it a descent (no overshoot past the minimum).
const APPROXIMATE_WOLFE_SLOPE: f64 = -0.1;

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// Accepted a step of this length (radians of the largest node displacement).
    Moved { displacement: f64 },
    /// No descent step exists: the projected gradient vanished or the line search failed.
    Stationary,
}

/// One recorded iteration.
#[derive(Debug, Clone, Serialize)]
pub struct StepRecord {
    pub iteration: usize,
    pub energy: f64,
    /// Per user crease, file order, radians.
    pub fold_angles: Vec<f64>,
    pub max_arc_residual: f64,
    /// ‖d‖∞ of the direction that led here (0 for the start).
    pub direction_norm: f64,
    #[serde(skip)]
    pub nodes: Vec<Vec3>,
}

/// The iterating solver.
pub struct Unfolder<'a> {
    model: &'a UnfoldModel,
    energy: Box<dyn Energy>,
    settings: UnfoldSettings,
    pub ws: Workspace,
    pub nodes: Vec<Vec3>,
    pub energy_value: f64,
    step_scale: Option<f64>,
    pub last_direction_norm: f64,
    /// Trial steps refused because they carried a node through an arc.
    pub crossings_refused: usize,
    /// Direction QPs solved with reduced accuracy.
    pub qp_almost_solved: usize,
    /// Times antipodal pairs were pinned.
    pub pins: usize,
}

impl<'a> Unfolder<'a> {
    /// Starts from `nodes` (restored onto the constraints first).
    pub fn new(model: &'a UnfoldModel, settings: &UnfoldSettings, mut nodes: Vec<Vec3>) -> Result<Unfolder<'a>> {
        let energy = settings.energy.build(settings.p);
        let mut ws = Workspace::new(model);
        fill_bases(model, &nodes, &mut ws.basis);
        restore(model, &mut ws, &mut nodes, settings.restore_tol, None)?;
        let energy_value = energy.value_and_gradient(&nodes, &model.arcs, &mut ws.energy, &mut ws.gradient);
        Ok(Unfolder {
            model,
            energy,
            settings: settings.clone(),
            ws,
            nodes,
            energy_value,
            step_scale: None,
            last_direction_norm: 0.0,
            crossings_refused: 0,
            qp_almost_solved: 0,
            pins: 0,
        })
    }

    /// The direction problem at the current state, and the row space of its constraints.
    pub fn direction_problem(&mut self) -> Result<(DirectionProblem, RowSpace)> {
        let model = self.model;
        fill_bases(model, &self.nodes, &mut self.ws.basis);
        fill_jacobian(model, &self.ws.rows, &self.nodes, &self.ws.basis, &mut self.ws.jacobian);
        let m = model.free.len();
        let mut q = DVector::zeros(2 * m);
        for (slot, &i) in model.free.iter().enumerate() {
            q[2 * slot] = self.ws.basis[i][0].dot(&self.ws.gradient[i]);
            q[2 * slot + 1] = self.ws.basis[i][1].dot(&self.ws.gradient[i]);
        }
        let row_space = RowSpace::new(&self.ws.jacobian)?;
        let metric = (self.settings.bending_metric > 0.0)
            .then(|| bending_rows(model, &self.ws.basis, self.settings.bending_metric));
        Ok((
            DirectionProblem {
                q,
                a: self.ws.jacobian.clone(),
                metric,
            },
            row_space,
        ))
    }

    /// First-order degrees of freedom at the current state (antipodal pins dropped).
    pub fn null_dimension(&mut self) -> Result<usize> {
        self.unpin();
        Ok(self.direction_problem()?.1.null_dimension())
    }

    /// One projected-gradient iteration.
    pub fn step(&mut self) -> Result<StepOutcome> {
        let model = self.model;
        let (problem, row_space) = self.direction_problem()?;
        let solution = match self.settings.qp {
            QpMethod::Direct => qp::solve_direct_with(&problem, &row_space)?,
            QpMethod::Clarabel => qp::solve_clarabel(&problem)?,
        };
        if solution.status == qp::QpStatus::AlmostSolved {
            self.qp_almost_solved += 1;
        }
        let y = solution.y;
        let largest = (0..model.free.len())
            .map(|s| (y[2 * s].powi(2) + y[2 * s + 1].powi(2)).sqrt())
            .fold(0.0, f64::max);
        self.last_direction_norm = largest;
        // −∇U·y = yᵀMy: the decrease rate along y in the problem's metric.
        let slope = -problem.q.dot(&y);
        if largest <= 1e-14 * (1.0 + problem.q.amax()) || !largest.is_finite() {
            if self.pin_antipodal_pairs() {
                return Ok(StepOutcome::Moved { displacement: 0.0 });
            }
            return Ok(StepOutcome::Stationary);
        }
        let cap = self.settings.max_step_rad / largest;
        let mut t = self.step_scale.map_or(cap, |s| (2.0 * s).min(cap));
        let basis = self.ws.basis.clone();
        while t * largest > 1e-16 {
            let mut trial = std::mem::take(&mut self.ws.trial);
            retract(model, &self.nodes, &basis, &y, t, &mut trial);
            let restored = restore(
                model,
                &mut self.ws,
                &mut trial,
                self.settings.restore_tol,
                Some(&row_space),
            );
            if restored.is_ok() {
                if find_crossing(model, &self.nodes, &trial).is_some() {
                    self.crossings_refused += 1;
                } else {
                    let value = self.energy.value_and_gradient(
                        &trial,
                        &model.arcs,
                        &mut self.ws.energy,
                        &mut self.ws.trial_gradient,
                    );
                    // Armijo with strict decrease; where U's change is lost in rounding (near
                    // flat U varies as ρ², so values resolve ρ only to √ε) fall back on the
                    // approximate Wolfe test of Hager–Zhang, which reads the slope instead.
                    let armijo =
                        value < self.energy_value && value <= self.energy_value - self.settings.armijo * t * slope;
                    let noise = 1e-12 * self.energy_value.abs();
                    let approximate_wolfe = !armijo && (value - self.energy_value).abs() <= noise && {
                        let slope_at_trial: f64 = model
                            .free
                            .iter()
                            .enumerate()
                            .map(|(s, &i)| {
                                let d = basis[i][0] * y[2 * s] + basis[i][1] * y[2 * s + 1];
                                self.ws.trial_gradient[i].dot(&d)
                            })
                            .sum();
                        slope_at_trial <= APPROXIMATE_WOLFE_SLOPE * slope && slope_at_trial < 0.0
                    };
                    if value.is_finite() && (armijo || approximate_wolfe) {
                        let displacement = self
                            .nodes
                            .iter()
                            .zip(&trial)
                            .map(|(a, b)| (a - b).norm())
                            .fold(0.0, f64::max);
                        std::mem::swap(&mut self.nodes, &mut trial);
                        std::mem::swap(&mut self.ws.gradient, &mut self.ws.trial_gradient);
                        self.energy_value = value;
                        self.step_scale = Some(t);
                        self.ws.trial = trial;
                        self.pin_antipodal_pairs();
                        return Ok(StepOutcome::Moved { displacement });
                    }
                }
            }
            self.ws.trial = trial;
            t *= 0.5;
        }
        self.step_scale = None;
        if self.pin_antipodal_pairs() {
            return Ok(StepOutcome::Moved { displacement: 0.0 });
        }
        Ok(StepOutcome::Stationary)
    }

    /// Near the flat state the separable energy has V-shaped kinks at antipodal node
    /// pairs (SPEC §9): γ = π − distance, minimal for the pair, with a subgradient of unit
    /// size whose direction is rounding noise. A projected gradient cannot settle on a
    /// kink, and the Newton projection keeps nudging pairs off it, which costs more energy
    /// than the ρ² left to gain. Once every |ρ| < 1e-3, pairs within 1e-5 of antipodal are
    /// held there by the equality x_v + x_w = 0, as an active-set method would, provided the
    /// projection onto the pinned set does not raise the energy; pins are dropped before
    /// restarts and before the degrees of freedom are counted. Returns whether it moved.
    fn pin_antipodal_pairs(&mut self) -> bool {
        if self.model.max_fold_angle(&self.nodes) >= 1e-3 {
            return false;
        }
        let n = self.model.node_count;
        let mut added = false;
        let rows_before = self.ws.rows.len();
        for v in 0..n {
            for w in v + 1..n {
                if w < 2 {
                    continue;
                }
                let distance_from_antipode = PI - geodesic(&self.nodes[v], &self.nodes[w]);
                let pinned = self.ws.rows.contains(&ConstraintRow::Antipodal { v: w, w: v, k: 0 });
                if distance_from_antipode < 1e-5 && !pinned {
                    // Row basis from the free node of the pair (w ≥ 2).
                    for k in 0..2 {
                        self.ws.rows.push(ConstraintRow::Antipodal { v: w, w: v, k });
                    }
                    added = true;
                }
            }
        }
        if !added {
            return false;
        }
        self.ws.resize_rows(self.model);
        // Project onto the pinned set at once; keep the pins only if that does not cost
        // energy beyond rounding.
        if self.project_if_no_worse(f64::INFINITY).is_some() {
            self.pins += 1;
            true
        } else {
            self.ws.rows.truncate(rows_before);
            self.ws.resize_rows(self.model);
            false
        }
    }

    /// Newton projection of the current state onto the workspace's constraint rows, taken
    /// only if it converges, the energy does not rise beyond rounding and no node passes
    /// through an arc on the way. Returns the largest node displacement when it moved.
    /// No node may move more than `max_displacement` (radians).
    fn project_if_no_worse(&mut self, max_displacement: f64) -> Option<f64> {
        let model = self.model;
        let mut projected = self.nodes.clone();
        if restore(model, &mut self.ws, &mut projected, self.settings.restore_tol, None).is_err()
            || largest_move(&self.nodes, &projected) > max_displacement
            || find_crossing(model, &self.nodes, &projected).is_some()
        {
            return None;
        }
        let mut gradient = vec![Vec3::zeros(); model.node_count];
        let value = self
            .energy
            .value_and_gradient(&projected, &model.arcs, &mut self.ws.energy, &mut gradient);
        if !(value.is_finite() && value <= self.energy_value + 1e-12 * self.energy_value.abs()) {
            return None;
        }
        let displacement = largest_move(&self.nodes, &projected);
        self.nodes = projected;
        self.energy_value = value;
        self.ws.gradient = gradient;
        self.step_scale = None;
        Some(displacement)
    }

    /// Newton to the flat state (SPEC §5). Near flat U varies as ρ², so its values resolve ρ
    /// only to about √ε and the line search stalls around 1e-7; the fold angles themselves
    /// are well-conditioned there, and the descent towards the singular flat state is slow.
    /// So the last stretch is a Newton projection onto {arc lengths, every fold angle = 0},
    /// accepted only if the energy does not rise (beyond rounding), no node passes through
    /// an arc on the straight way there, and no node moves more than a quarter of the
    /// smallest node–arc clearance (so no sector can reach another on the way, whatever
    /// the path within that distance). Returns whether it was accepted.
    pub fn flatten(&mut self) -> bool {
        let model = self.model;
        let clearance = node_arc_clearance(model, &self.nodes);
        self.unpin();
        let rows_before = self.ws.rows.len();
        let held: Vec<usize> = model.held.iter().map(|h| h.ray).collect();
        for &ray in &model.fold_rays {
            if !held.contains(&ray) {
                self.ws.rows.push(ConstraintRow::Flat(ray));
            }
        }
        self.ws.resize_rows(model);
        let moved = self.project_if_no_worse(0.25 * clearance);
        self.ws.rows.truncate(rows_before);
        self.ws.resize_rows(model);
        if let Some(displacement) = moved {
            self.last_direction_norm = displacement;
        }
        moved.is_some()
    }

    /// Drops every antipodal pin.
    fn unpin(&mut self) {
        self.ws.rows.retain(|r| !matches!(r, ConstraintRow::Antipodal { .. }));
        self.ws.resize_rows(self.model);
    }

    /// Random kick inside the first-order feasible directions, then restoration; a kick
    /// whose restoration fails is halved (up to five times) before giving up on it.
    fn kick(&mut self, rng: &mut SplitMix64, size: f64) -> Result<()> {
        self.unpin();
        let mut size = size;
        for _ in 0..6 {
            if self.try_kick(rng, size)? {
                return Ok(());
            }
            size *= 0.5;
        }
        Ok(())
    }

    fn try_kick(&mut self, rng: &mut SplitMix64, size: f64) -> Result<bool> {
        let (_, row_space) = self.direction_problem()?;
        let m = self.model.free.len();
        let noise = DVector::from_iterator(2 * m, (0..2 * m).map(|_| rng.next_f64() - 0.5));
        let mut direction = row_space.project_to_null(&noise);
        let largest = direction.amax();
        if largest == 0.0 {
            return Ok(true);
        }
        direction *= size / largest;
        let basis = self.ws.basis.clone();
        let mut trial = self.nodes.clone();
        retract(self.model, &self.nodes, &basis, &direction, 1.0, &mut trial);
        if restore(self.model, &mut self.ws, &mut trial, self.settings.restore_tol, None).is_err() {
            return Ok(false);
        }
        let value =
            self.energy
                .value_and_gradient(&trial, &self.model.arcs, &mut self.ws.energy, &mut self.ws.gradient);
        let accepted = value.is_finite() && find_crossing(self.model, &self.nodes, &trial).is_none();
        if accepted {
            self.nodes = trial;
            self.energy_value = value;
        } else {
            self.energy_value = self.energy.value_and_gradient(
                &self.nodes,
                &self.model.arcs,
                &mut self.ws.energy,
                &mut self.ws.gradient,
            );
        }
        self.step_scale = None;
        Ok(accepted)
    }
}

/// Deterministic generator for restart kicks (SplitMix64).
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The answer to "does this pattern unfold?" (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Reached the flat state; the trajectory reversed is a folding path.
    Flat,
    /// Stopped away from flat, restarts disabled (no evidence either way).
    Stuck,
    /// No motion is possible: the constraint Jacobian has no null space (rigid state).
    Locked,
    /// Motion is possible, but every restart from a perturbed state came back stuck.
    LocalMinimum,
    /// A closed chain whose sector angles do not sum to 2π has no flat state.
    NotFlatFoldable,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Flat => "flat",
            Verdict::Stuck => "stuck",
            Verdict::Locked => "locked",
            Verdict::LocalMinimum => "local_minimum",
            Verdict::NotFlatFoldable => "not_flat_foldable",
        }
    }
}

/// Everything an unfolding run produced.
#[derive(Debug, Clone, Serialize)]
pub struct UnfoldReport {
    pub verdict: Verdict,
    /// Why this verdict, in words (the evidence).
    pub evidence: String,
    pub iterations: usize,
    pub seconds: f64,
    pub energy_initial: f64,
    pub energy_final: f64,
    pub initial_fold_angles_rad: Vec<f64>,
    pub final_fold_angles_rad: Vec<f64>,
    /// Largest |γ − α| over all recorded steps.
    pub max_arc_residual: f64,
    /// Largest distance of a node from the best-fit great-circle plane at the end.
    pub planarity_residual: f64,
    /// Largest node distance from the exact flat layout at the end (meaningful when flat).
    pub flat_layout_error: f64,
    pub restarts_used: usize,
    pub crossings_refused: usize,
    pub qp_almost_solved: usize,
    /// Rules applied to the input or the start (rescaling, splits, flat-folded back-off).
    pub adjustments: Vec<String>,
    #[serde(skip)]
    pub trajectory: Vec<StepRecord>,
    #[serde(skip)]
    pub final_nodes: Vec<Vec3>,
}

/// Distance of the nodes from their best-fit plane through the vertex.
pub fn planarity_residual(nodes: &[Vec3]) -> f64 {
    let scatter: Matrix3<f64> = nodes.iter().map(|x| x * x.transpose()).sum();
    let eigen = SymmetricEigen::new(scatter);
    let (index, _) = eigen.eigenvalues.argmin();
    let normal = eigen.eigenvectors.column(index).into_owned();
    nodes.iter().map(|x| normal.dot(x).abs()).fold(0.0, f64::max)
}

fn record(model: &UnfoldModel, solver: &Unfolder, iteration: usize) -> StepRecord {
    StepRecord {
        iteration,
        energy: solver.energy_value,
        fold_angles: model.crease_angles(&solver.nodes),
        max_arc_residual: model.max_arc_residual(&solver.nodes),
        direction_norm: solver.last_direction_norm,
        nodes: solver.nodes.clone(),
    }
}

/// Largest fold angle at which the driver first tries [`Unfolder::flatten`].
const FLATTEN_FROM: f64 = 1e-2;

/// Largest fold angle at which a stall counts as "near flat" rather than a local minimum.
const NEAR_FLAT: f64 = 1e-4;

/// Fold angles this small are flat to rounding.
const ROUNDING_FLAT: f64 = 1e-14;

/// Backs a flat-folded (|ρ| = π, coincident charges) start off the singularity: every fold
/// angle is scaled by (1 − 10⁻³) and the constraints restored (documented in README).
const FLAT_FOLDED_BACKOFF: f64 = 1e-3;

/// Does a node touch an arc it is not on (γ(v,a) + γ(v,b) − α below 1e-9 rad)? This is
/// the flat-folded case of coincident charges, where rounding may leave the energy finite
/// but astronomically large.
pub fn touching_charges(model: &UnfoldModel, nodes: &[Vec3]) -> bool {
    model.arcs.iter().any(|arc| {
        (0..model.node_count)
            .filter(|&v| v != arc.a && v != arc.b)
            .any(|v| geodesic(&nodes[v], &nodes[arc.a]) + geodesic(&nodes[v], &nodes[arc.b]) - arc.length < 1e-9)
    })
}

/// Steps of the straight fold-angle path checked by [`open_chain_path`].
const OPEN_PATH_STEPS: usize = 400;

/// An open chain (a boundary vertex) has no loop closure, so every fold angle moves on its
/// own, and for open chains the energy's minimum need not be flat (e.g. 310° of paper with
/// a 200° sector stalls at |ρ| = 0.45 from any start). Straight in fold angles from `nodes`
/// to flat, ρ(s) = (1 − s) ρ: the states along it, if no step carries a node through an arc
/// and the energy stays finite; None otherwise (or for closed chains and held creases).
fn open_chain_path(model: &UnfoldModel, energy: &dyn Energy, nodes: &[Vec3]) -> Option<Vec<(Vec<Vec3>, f64)>> {
    if model.chain != Chain::Open || model.held.iter().any(|h| h.target != 0.0) {
        return None;
    }
    let start: Vec<f64> = (0..model.node_count)
        .map(|ray| {
            if model.fold_rays.contains(&ray) {
                model.fold_angle_at(nodes, ray)
            } else {
                0.0
            }
        })
        .collect();
    let mut workspace = EnergyWorkspace::default();
    let mut previous = nodes.to_vec();
    let mut path = Vec::with_capacity(OPEN_PATH_STEPS);
    for step in 0..=OPEN_PATH_STEPS {
        let keep = 1.0 - step as f64 / OPEN_PATH_STEPS as f64;
        let angles: Vec<f64> = start.iter().map(|r| r * keep).collect();
        let state = kinematics::forward(&model.sector_angles, &angles);
        let value = energy.value(&state, &model.arcs, &mut workspace);
        if !value.is_finite() || find_crossing(model, &previous, &state).is_some() {
            return None;
        }
        previous.clone_from(&state);
        path.push((state, value));
    }
    Some(path)
}

/// Unfolds a pattern: the main job.
pub fn unfold(pattern: &Pattern, settings: &UnfoldSettings) -> Result<UnfoldReport> {
    let started = Instant::now();
    let model = UnfoldModel::new(pattern);
    let mut adjustments = pattern.adjustments.clone();
    let mut start = model.folded_nodes();
    let initial_fold_angles = pattern.creases.iter().map(|c| c.folded_angle).collect::<Vec<_>>();

    if !pattern.flat_foldable {
        let energy = settings
            .energy
            .build(settings.p)
            .value(&start, &model.arcs, &mut EnergyWorkspace::default());
        let excess = pattern.angle_sum - 2.0 * PI;
        return Ok(UnfoldReport {
            verdict: Verdict::NotFlatFoldable,
            evidence: format!(
                "closed chain with sector angles summing to {:.9}° ({:+.3e} rad from 360°): a cone has no flat state",
                pattern.angle_sum.to_degrees(),
                excess
            ),
            iterations: 0,
            seconds: started.elapsed().as_secs_f64(),
            energy_initial: energy,
            energy_final: energy,
            final_fold_angles_rad: initial_fold_angles.clone(),
            initial_fold_angles_rad: initial_fold_angles,
            max_arc_residual: model.max_arc_residual(&start),
            planarity_residual: planarity_residual(&start),
            flat_layout_error: f64::NAN,
            restarts_used: 0,
            crossings_refused: 0,
            qp_almost_solved: 0,
            adjustments,
            trajectory: Vec::new(),
            final_nodes: start,
        });
    }

    let energy = settings.energy.build(settings.p);
    if touching_charges(&model, &start)
        || !energy
            .value(&start, &model.arcs, &mut EnergyWorkspace::default())
            .is_finite()
    {
        let scaled: Vec<f64> = model
            .folded_ray_angles
            .iter()
            .map(|r| r * (1.0 - FLAT_FOLDED_BACKOFF))
            .collect();
        start = kinematics::forward(&model.sector_angles, &scaled);
        adjustments.push(format!(
            "start has touching charges (flat-folded, infinite energy): fold angles scaled by {} and constraints restored",
            1.0 - FLAT_FOLDED_BACKOFF
        ));
    }
    let mut solver = Unfolder::new(&model, settings, start)?;
    if !solver.energy_value.is_finite() {
        return Err(NumericalError::NonFinite {
            what: "initial energy",
            detail: "charges still touch after backing off the flat-folded state".into(),
        }
        .into());
    }
    let energy_initial = solver.energy_value;
    let mut trajectory = vec![record(&model, &solver, 0)];
    let mut iteration = 0;
    let mut rng = SplitMix64(settings.seed);
    let mut restarts_used = 0;
    let mut flattened_from: Option<f64> = None;
    let is_flat = |s: &Unfolder| model.max_fold_angle(&s.nodes) <= settings.flat_tol;

    let verdict;
    let evidence;
    if !is_flat(&solver) && solver.null_dimension()? == 0 {
        verdict = Verdict::Locked;
        evidence = "the constraint Jacobian has full column rank at the given state: no motion is possible".to_string();
    } else {
        loop {
            // Descend until flat, stationary or out of iterations; once flat, polish until
            // the line search is stationary or the polish budget is spent.
            let mut stationary = false;
            let mut polish_left = settings.polish_iterations;
            let mut flatten_tried = false;
            let mut next_flatten = FLATTEN_FROM;
            while iteration < settings.max_iterations {
                let largest = model.max_fold_angle(&solver.nodes);
                // Near flat the descent is linear at best; try Newton onto ρ = 0 once per
                // decade of max |ρ| below FLATTEN_FROM (it checks energy, crossings, clearance).
                let decade = largest <= next_flatten && largest > settings.flat_tol;
                if settings.newton_flatten && flattened_from.is_none() && decade {
                    next_flatten = largest / 10.0;
                    if solver.flatten() {
                        iteration += 1;
                        trajectory.push(record(&model, &solver, iteration));
                        flattened_from = Some(largest);
                        break;
                    }
                }
                if largest <= settings.flat_tol {
                    // Nothing for Newton to gain once the fold angles are at rounding level.
                    if settings.newton_flatten && !flatten_tried && largest > ROUNDING_FLAT {
                        flatten_tried = true;
                        if solver.flatten() {
                            iteration += 1;
                            trajectory.push(record(&model, &solver, iteration));
                            flattened_from = Some(largest);
                            break;
                        }
                    }
                    if polish_left == 0 {
                        break;
                    }
                    polish_left -= 1;
                }
                match solver.step()? {
                    StepOutcome::Moved { .. } => {
                        iteration += 1;
                        trajectory.push(record(&model, &solver, iteration));
                    }
                    StepOutcome::Stationary => {
                        stationary = true;
                        break;
                    }
                }
            }
            // A stall this close to flat is the √ε limit of U, not a minimum: Newton decides.
            let left = model.max_fold_angle(&solver.nodes);
            let stalled_near_flat = stationary && left < NEAR_FLAT && left > ROUNDING_FLAT;
            if settings.newton_flatten && flattened_from.is_none() && stalled_near_flat && solver.flatten() {
                iteration += 1;
                trajectory.push(record(&model, &solver, iteration));
                flattened_from = Some(left);
            }
            if is_flat(&solver) {
                verdict = Verdict::Flat;
                let mut words = format!("every fold angle ≤ {:.0e} rad", settings.flat_tol);
                if let Some(from) = flattened_from {
                    words += &format!(
                        " (max |ρ| = {:.1e} rad after Newton onto ρ = 0 from {from:.1e} rad)",
                        model.max_fold_angle(&solver.nodes)
                    );
                }
                if restarts_used > 0 {
                    words += &format!(" after {restarts_used} restart(s) from perturbed states");
                }
                evidence = words;
                break;
            }
            let why = if stationary { "stationary" } else { "iteration limit" };
            if restarts_used >= settings.restarts || iteration >= settings.max_iterations {
                let dof = solver.null_dimension()?;
                if settings.restarts == 0 || !stationary {
                    verdict = Verdict::Stuck;
                    evidence = format!(
                        "{why} at max |ρ| = {:.3e} rad after {iteration} iterations ({restarts_used} restarts)",
                        model.max_fold_angle(&solver.nodes)
                    );
                } else if model.max_fold_angle(&solver.nodes) < NEAR_FLAT {
                    // SPEC §4/§5: a stall this close to flat is the solver meeting the singular
                    // constraint Jacobian of the flat state, not a minimum of the energy.
                    verdict = Verdict::Stuck;
                    evidence = format!(
                        "stalled {:.3e} rad from flat after {iteration} iterations and {restarts_used} restarts: the constraint Jacobian is singular at the flat state, so this is a solver limit near flat, not a local minimum",
                        model.max_fold_angle(&solver.nodes)
                    );
                } else if dof == 0 {
                    verdict = Verdict::Locked;
                    evidence = "stationary at a state with no first-order motion (rigid)".to_string();
                } else if let Some(path) = open_chain_path(&model, solver.energy.as_ref(), &solver.nodes) {
                    let stalled = model.max_fold_angle(&solver.nodes);
                    for (nodes, value) in path {
                        solver.nodes = nodes;
                        solver.energy_value = value;
                        iteration += 1;
                        trajectory.push(record(&model, &solver, iteration));
                    }
                    verdict = Verdict::Flat;
                    evidence = format!(
                        "open chain: the energy is stationary at max |ρ| = {stalled:.3e} rad ({restarts_used} restarts all came back), and from there every fold angle scaled straight to 0 in {OPEN_PATH_STEPS} steps carries no node through an arc"
                    );
                } else {
                    verdict = Verdict::LocalMinimum;
                    evidence = format!(
                        "stationary at max |ρ| = {:.3e} rad with {dof} first-order degrees of freedom; {restarts_used} restarts from perturbed states all stuck",
                        model.max_fold_angle(&solver.nodes)
                    );
                }
                break;
            }
            restarts_used += 1;
            solver.kick(&mut rng, settings.restart_kick_rad)?;
        }
    }

    let final_nodes = solver.nodes.clone();
    let flat_layout_error = final_nodes
        .iter()
        .zip(&model.flat_layout)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    Ok(UnfoldReport {
        verdict,
        evidence,
        iterations: iteration,
        seconds: started.elapsed().as_secs_f64(),
        energy_initial,
        energy_final: solver.energy_value,
        initial_fold_angles_rad: initial_fold_angles,
        final_fold_angles_rad: model.crease_angles(&final_nodes),
        max_arc_residual: trajectory.iter().map(|r| r.max_arc_residual).fold(0.0, f64::max),
        planarity_residual: planarity_residual(&final_nodes),
        flat_layout_error,
        restarts_used,
        crossings_refused: solver.crossings_refused,
        qp_almost_solved: solver.qp_almost_solved,
        adjustments,
        trajectory,
        final_nodes,
    })
}
