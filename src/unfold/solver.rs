//! The projected-gradient solver (`docs/model.md#projected-gradient`): one step is a
//! direction (the QP of [`super::qp`] in tangent coordinates), a backtracking line search on
//! U that refuses steps carrying a node through an arc, and Newton restoration. Beside the
//! descent it owns its finish strategies as named steps: the Newton finish onto ρ = 0, the
//! antipodal pins, restarts from perturbed states and the straight open-chain path. As an
//! argmin [`Solver`], each call of `next_iter` takes one such step; [`super::unfold`] drives
//! it with argmin's `Executor`.
//!
//! A step on the direct path allocates nothing once the workspace has grown (a test counts).

use super::checks::{find_crossing, largest_move, node_arc_clearance};
use super::energy::{Energy, EnergyWorkspace};
use super::manifold::{fill_bases, fill_bending_rows, fill_jacobian, restore, retract, RestoreBuffers};
use super::model::{ConstraintRow, UnfoldModel};
use super::qp::{self, ConstraintJacobian, DirectWorkspace, DirectionProblem, QpMethod, RowSpace};
use super::settings::UnfoldSettings;
use super::state::{StepKind, UnfoldState};
use crate::error::Result;
use crate::geometry::kinematics;
use crate::geometry::sphere::{geodesic, Vec3};
use crate::pattern::Chain;
use argmin::core::{Problem, Solver, State, TerminationReason, KV};
use nalgebra::DVector;
use std::f64::consts::PI;

/// Approximate Wolfe condition φ'(t) ≤ (2δ − 1)φ'(0) with δ = 0.1, written for
/// φ'(0) = −slope; the extra φ'(t) < 0 keeps it a descent (no overshoot past the minimum).
const APPROXIMATE_WOLFE_SLOPE: f64 = -0.1;
/// Largest fold angle at which the driver first tries the Newton finish.
const FLATTEN_FROM: f64 = 1e-2;
/// Largest fold angle at which a stall counts as "near flat" rather than a local minimum.
pub(crate) const NEAR_FLAT: f64 = 1e-4;
/// Fold angles this small are flat to rounding.
const ROUNDING_FLAT: f64 = 1e-14;
/// Steps of the straight fold-angle path of an open chain.
pub(crate) const OPEN_PATH_STEPS: usize = 400;

/// What one descent step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// Accepted a step of this length (radians of the largest node displacement).
    Moved {
        /// Largest node displacement, rad.
        displacement: f64,
    },
    /// No descent step exists: the projected gradient vanished or the line search failed.
    Stationary,
}

/// Why the solver stopped: the termination reason, separate from the verdict (which the
/// driver derives from it with the evidence).
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// Every fold angle within the flat tolerance; `flattened_from` is the largest fold
    /// angle where the Newton finish was accepted, if it was.
    Flat {
        /// Where the Newton finish started, rad.
        flattened_from: Option<f64>,
    },
    /// No motion at the start: the constraint Jacobian has full column rank.
    LockedAtStart,
    /// The open chain's straight path to flat was taken after the energy stalled at
    /// `stalled` rad.
    OpenChainPath {
        /// max |ρ| where the energy was stationary, rad.
        stalled: f64,
    },
    /// Stationary (or out of iterations) away from flat after the restarts.
    Stopped {
        /// True when stationary; false when the iteration limit ended the run.
        stationary: bool,
        /// First-order degrees of freedom there.
        dof: usize,
        /// max |ρ| there, rad.
        largest: f64,
    },
}

/// Scratch reused across steps.
#[derive(Debug, Default)]
pub struct Workspace {
    energy: EnergyWorkspace,
    gradient: Vec<Vec3>,
    trial_gradient: Vec<Vec3>,
    basis: Vec<[Vec3; 2]>,
    rows: Vec<ConstraintRow>,
    jacobian: ConstraintJacobian,
    row_space: RowSpace,
    metric: ConstraintJacobian,
    direct: DirectWorkspace,
    restore: RestoreBuffers,
    q: Vec<f64>,
    y: Vec<f64>,
    trial: Vec<Vec3>,
    projected: Vec<Vec3>,
    projected_gradient: Vec<Vec3>,
    noise: Vec<f64>,
}

impl Workspace {
    fn new(model: &UnfoldModel) -> Workspace {
        let mut rows = model.constraint_rows();
        let n = model.node_count;
        // Room for the Newton finish's flat rows and the antipodal pins, so that adding
        // them later does not grow the buffers.
        rows.reserve(model.fold_rays.len() + 2 * n);
        Workspace {
            gradient: vec![Vec3::zeros(); n],
            trial_gradient: vec![Vec3::zeros(); n],
            basis: vec![[Vec3::zeros(); 2]; n],
            rows,
            trial: vec![Vec3::zeros(); n],
            projected: vec![Vec3::zeros(); n],
            projected_gradient: vec![Vec3::zeros(); n],
            ..Default::default()
        }
    }
}

/// Deterministic generator for restart kicks (SplitMix64).
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
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

/// Where the driver is between steps.
#[derive(Debug, Clone)]
enum Phase {
    /// Descending (and past the flat tolerance, polishing `polish_left` more steps).
    Descend,
    /// Out of descent: decide flat, restart, the open-chain path or a stop.
    Decide,
    /// Walking the open chain's straight path: the states left, in order.
    OpenPath(std::vec::IntoIter<(Vec<Vec3>, f64)>, f64),
    /// Finished.
    Done,
}

/// The most node pairs the descent evaluates, summed over its steps (each step's energy is
/// O(n²) in the nodes): a vertex of many rays hands over to the folding-path witness after
/// about this much work instead of creeping to flat (`docs/model.md#unfolding`).
pub const DESCENT_WORK: usize = 60_000_000;

/// The steps the descent takes at most: `max_iterations`, and no more than [`DESCENT_WORK`]
/// allows for `nodes` nodes (at least 100).
pub fn step_budget(max_iterations: usize, nodes: usize) -> usize {
    max_iterations.min((DESCENT_WORK / (nodes * nodes).max(1)).max(100))
}

/// The iterating solver: the model, the energy, the state (nodes) and the driver's phase.
pub struct ProjectedGradient<'a> {
    model: &'a UnfoldModel,
    energy: Box<dyn Energy>,
    settings: UnfoldSettings,
    ws: Workspace,
    /// The current nodes (unit vectors, one per ray).
    pub nodes: Vec<Vec3>,
    /// U at the current nodes.
    pub energy_value: f64,
    step_scale: Option<f64>,
    /// ‖d‖∞ of the last direction (or the last Newton finish's largest move).
    pub last_direction_norm: f64,
    /// Trial steps refused because they carried a node through an arc.
    pub crossings_refused: usize,
    /// Direction QPs solved with reduced accuracy.
    pub qp_almost_solved: usize,
    /// Times antipodal pairs were pinned.
    pub pins: usize,
    /// Restarts from perturbed states taken.
    pub restarts_used: usize,
    /// Recorded steps taken (descent, Newton finish, pins, path states).
    pub steps: usize,
    /// Largest |γ − α| over every recorded step.
    pub max_arc_residual: f64,
    /// |γ − α| at the last recorded step.
    arc_residual: f64,
    /// Why the driver stopped (None while running).
    pub termination: Option<Termination>,
    phase: Phase,
    polish_left: usize,
    flatten_tried: bool,
    next_flatten: f64,
    flattened_from: Option<f64>,
    stationary: bool,
    rng: SplitMix64,
}

impl<'a> ProjectedGradient<'a> {
    /// Starts from `nodes` (restored onto the constraints first). Validates the settings.
    pub fn new(
        model: &'a UnfoldModel,
        settings: &UnfoldSettings,
        mut nodes: Vec<Vec3>,
    ) -> Result<ProjectedGradient<'a>> {
        settings.validate()?;
        let mut settings = settings.clone();
        settings.restore_tol = model.restore_tolerance(settings.restore_tol);
        settings.max_iterations = step_budget(settings.max_iterations, model.node_count);
        let settings = &settings;
        let energy = settings.energy.build(settings.p);
        let mut ws = Workspace::new(model);
        restore(model, &ws.rows, &mut ws.restore, &mut nodes, settings.restore_tol, None)?;
        let energy_value = energy.value_and_gradient(&nodes, &model.arcs, &mut ws.energy, &mut ws.gradient);
        let max_arc_residual = model.max_arc_residual(&nodes);
        Ok(ProjectedGradient {
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
            restarts_used: 0,
            steps: 0,
            max_arc_residual,
            arc_residual: max_arc_residual,
            termination: None,
            phase: Phase::Descend,
            polish_left: settings.polish_iterations,
            flatten_tried: false,
            next_flatten: FLATTEN_FROM,
            flattened_from: None,
            stationary: false,
            rng: SplitMix64(settings.seed),
        })
    }

    /// The model this solver works on.
    pub fn model(&self) -> &UnfoldModel {
        self.model
    }

    /// Bases, constraint Jacobian, energy gradient in tangent coordinates, A's
    /// factorisation and the metric rows at the current nodes, into the workspace.
    fn prepare_direction(&mut self) -> Result<()> {
        let (model, ws) = (self.model, &mut self.ws);
        fill_bases(model, &self.nodes, &mut ws.basis);
        fill_jacobian(model, &ws.rows, &self.nodes, &ws.basis, &mut ws.jacobian);
        let m = model.free.len();
        ws.q.resize(2 * m, 0.0);
        for (slot, &i) in model.free.iter().enumerate() {
            ws.q[2 * slot] = ws.basis[i][0].dot(&ws.gradient[i]);
            ws.q[2 * slot + 1] = ws.basis[i][1].dot(&ws.gradient[i]);
        }
        ws.row_space.factorise(&ws.jacobian)?;
        if self.settings.bending_metric > 0.0 {
            fill_bending_rows(model, &ws.basis, self.settings.bending_metric, &mut ws.metric);
        }
        Ok(())
    }

    /// The direction problem at the current state (allocating; for tests and tools).
    pub fn direction_problem(&mut self) -> Result<DirectionProblem> {
        self.prepare_direction()?;
        Ok(DirectionProblem {
            q: DVector::from_column_slice(&self.ws.q),
            a: self.ws.jacobian.clone(),
            metric: (self.settings.bending_metric > 0.0).then(|| self.ws.metric.clone()),
        })
    }

    /// First-order degrees of freedom at the current state (antipodal pins dropped).
    pub fn null_dimension(&mut self) -> Result<usize> {
        self.unpin();
        self.prepare_direction()?;
        Ok(self.ws.row_space.null_dimension())
    }

    /// The direction y into the workspace (after [`Self::prepare_direction`]).
    fn solve_direction(&mut self) -> Result<()> {
        let ws = &mut self.ws;
        ws.y.resize(ws.q.len(), 0.0);
        let metric = (self.settings.bending_metric > 0.0).then_some(&ws.metric);
        match self.settings.qp {
            QpMethod::Direct => ws
                .direct
                .solve(&ws.jacobian, &ws.q, metric, &mut ws.row_space, &mut ws.y),
            QpMethod::Clarabel => {
                let problem = DirectionProblem {
                    q: DVector::from_column_slice(&ws.q),
                    a: ws.jacobian.clone(),
                    metric: metric.cloned(),
                };
                let solution = qp::solve_clarabel(&problem)?;
                if solution.status == qp::QpStatus::AlmostSolved {
                    self.qp_almost_solved += 1;
                }
                ws.y.copy_from_slice(solution.y.as_slice());
                Ok(())
            }
        }
    }

    /// One projected-gradient iteration.
    pub fn step(&mut self) -> Result<StepOutcome> {
        let model = self.model;
        self.prepare_direction()?;
        self.solve_direction()?;
        let largest = (0..model.free.len())
            .map(|s| (self.ws.y[2 * s].powi(2) + self.ws.y[2 * s + 1].powi(2)).sqrt())
            .fold(0.0, f64::max);
        self.last_direction_norm = largest;
        // −∇U·y = yᵀMy: the decrease rate along y in the problem's metric.
        let slope = -self.ws.q.iter().zip(&self.ws.y).map(|(q, y)| q * y).sum::<f64>();
        let q_scale = self.ws.q.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        if largest <= 1e-14 * (1.0 + q_scale) || !largest.is_finite() {
            if self.pin_antipodal_pairs() {
                return Ok(StepOutcome::Moved { displacement: 0.0 });
            }
            return Ok(StepOutcome::Stationary);
        }
        let cap = self.settings.max_step_rad / largest;
        let mut t = self.step_scale.map_or(cap, |s| (2.0 * s).min(cap));
        while t * largest > 1e-16 {
            let ws = &mut self.ws;
            retract(model, &self.nodes, &ws.basis, &ws.y, t, &mut ws.trial);
            let restored = restore(
                model,
                &ws.rows,
                &mut ws.restore,
                &mut ws.trial,
                self.settings.restore_tol,
                Some((&mut ws.row_space, &ws.basis)),
            );
            if restored.is_ok() {
                if find_crossing(model, &self.nodes, &ws.trial).is_some() {
                    self.crossings_refused += 1;
                } else {
                    let value =
                        self.energy
                            .value_and_gradient(&ws.trial, &model.arcs, &mut ws.energy, &mut ws.trial_gradient);
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
                                let d = ws.basis[i][0] * ws.y[2 * s] + ws.basis[i][1] * ws.y[2 * s + 1];
                                ws.trial_gradient[i].dot(&d)
                            })
                            .sum();
                        slope_at_trial <= APPROXIMATE_WOLFE_SLOPE * slope && slope_at_trial < 0.0
                    };
                    if value.is_finite() && (armijo || approximate_wolfe) {
                        let displacement = largest_move(&self.nodes, &ws.trial);
                        std::mem::swap(&mut self.nodes, &mut ws.trial);
                        std::mem::swap(&mut ws.gradient, &mut ws.trial_gradient);
                        self.energy_value = value;
                        self.step_scale = Some(t);
                        self.pin_antipodal_pairs();
                        return Ok(StepOutcome::Moved { displacement });
                    }
                }
            }
            t *= 0.5;
        }
        self.step_scale = None;
        if self.pin_antipodal_pairs() {
            return Ok(StepOutcome::Moved { displacement: 0.0 });
        }
        Ok(StepOutcome::Stationary)
    }

    /// Near the flat state the separable energy has V-shaped kinks at antipodal node
    /// pairs (`docs/model.md#hard-cases`): γ = π − distance, minimal for the pair, with a
    /// subgradient of unit size whose direction is rounding noise. A projected gradient
    /// cannot settle on a kink, and the Newton projection keeps nudging pairs off it, which
    /// costs more energy than the ρ² left to gain. Once every |ρ| < 1e-3, pairs within 1e-5
    /// of antipodal are held there by the equality x_v + x_w = 0, as an active-set method
    /// would, provided the projection onto the pinned set does not raise the energy; pins
    /// are dropped before restarts and before the degrees of freedom are counted. Returns
    /// whether it moved.
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
        // Project onto the pinned set at once; keep the pins only if that does not cost
        // energy beyond rounding.
        if self.project_if_no_worse(f64::INFINITY).is_some() {
            self.pins += 1;
            true
        } else {
            self.ws.rows.truncate(rows_before);
            false
        }
    }

    /// Newton projection of the current state onto the workspace's constraint rows, taken
    /// only if it converges, the energy does not rise beyond rounding and no node passes
    /// through an arc on the way. Returns the largest node displacement when it moved.
    /// No node may move more than `max_displacement` (radians).
    fn project_if_no_worse(&mut self, max_displacement: f64) -> Option<f64> {
        let (model, ws) = (self.model, &mut self.ws);
        ws.projected.copy_from_slice(&self.nodes);
        if restore(
            model,
            &ws.rows,
            &mut ws.restore,
            &mut ws.projected,
            self.settings.restore_tol,
            None,
        )
        .is_err()
            || largest_move(&self.nodes, &ws.projected) > max_displacement
            || find_crossing(model, &self.nodes, &ws.projected).is_some()
        {
            return None;
        }
        let value =
            self.energy
                .value_and_gradient(&ws.projected, &model.arcs, &mut ws.energy, &mut ws.projected_gradient);
        if !(value.is_finite() && value <= self.energy_value + 1e-12 * self.energy_value.abs()) {
            return None;
        }
        let displacement = largest_move(&self.nodes, &ws.projected);
        std::mem::swap(&mut self.nodes, &mut ws.projected);
        std::mem::swap(&mut ws.gradient, &mut ws.projected_gradient);
        self.energy_value = value;
        self.step_scale = None;
        Some(displacement)
    }

    /// The Newton finish (`docs/model.md#newton-finish`). Near flat U varies as ρ², so its
    /// values resolve ρ only to about √ε and the line search stalls around 1e-7; the fold
    /// angles themselves are well-conditioned there, and the descent towards the singular
    /// flat state is slow. So the last stretch is a Newton projection onto {arc lengths,
    /// every fold angle = 0}, accepted only if the energy does not rise (beyond rounding), no
    /// node passes through an arc on the straight way there, and no node moves more than a
    /// quarter of the smallest node–arc clearance (so no sector can reach another on the
    /// way, whatever the path within that distance). Returns whether it was accepted.
    pub fn flatten(&mut self) -> bool {
        let model = self.model;
        let clearance = node_arc_clearance(model, &self.nodes);
        self.unpin();
        let rows_before = self.ws.rows.len();
        for &ray in &model.fold_rays {
            if !model.held.iter().any(|h| h.ray == ray) {
                self.ws.rows.push(ConstraintRow::Flat(ray));
            }
        }
        let moved = self.project_if_no_worse(0.25 * clearance);
        self.ws.rows.truncate(rows_before);
        if let Some(displacement) = moved {
            self.last_direction_norm = displacement;
        }
        moved.is_some()
    }

    /// Drops every antipodal pin.
    fn unpin(&mut self) {
        self.ws.rows.retain(|r| !matches!(r, ConstraintRow::Antipodal { .. }));
    }

    /// Random kick inside the first-order feasible directions, then restoration; a kick
    /// whose restoration fails is halved (up to five times) before giving up on it.
    fn kick(&mut self, size: f64) -> Result<()> {
        self.unpin();
        let mut size = size;
        for _ in 0..6 {
            if self.try_kick(size)? {
                return Ok(());
            }
            size *= 0.5;
        }
        Ok(())
    }

    fn try_kick(&mut self, size: f64) -> Result<bool> {
        self.prepare_direction()?;
        let (model, ws) = (self.model, &mut self.ws);
        let m = model.free.len();
        ws.noise.clear();
        for _ in 0..2 * m {
            ws.noise.push(self.rng.next_f64() - 0.5);
        }
        ws.y.resize(2 * m, 0.0);
        ws.row_space.project_to_null_into(&ws.noise, &mut ws.y);
        let largest = ws.y.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        if largest == 0.0 {
            return Ok(true);
        }
        ws.y.iter_mut().for_each(|v| *v *= size / largest);
        retract(model, &self.nodes, &ws.basis, &ws.y, 1.0, &mut ws.trial);
        if restore(
            model,
            &ws.rows,
            &mut ws.restore,
            &mut ws.trial,
            self.settings.restore_tol,
            None,
        )
        .is_err()
        {
            return Ok(false);
        }
        let value = self
            .energy
            .value_and_gradient(&ws.trial, &model.arcs, &mut ws.energy, &mut ws.trial_gradient);
        let accepted = value.is_finite() && find_crossing(model, &self.nodes, &ws.trial).is_none();
        if accepted {
            std::mem::swap(&mut self.nodes, &mut ws.trial);
            std::mem::swap(&mut ws.gradient, &mut ws.trial_gradient);
            self.energy_value = value;
        }
        self.step_scale = None;
        Ok(accepted)
    }

    /// Whether every fold angle is within the flat tolerance.
    fn is_flat(&self) -> bool {
        self.model.max_fold_angle(&self.nodes) <= self.settings.flat_tol
    }

    /// Checks the start: a rigid (locked) state ends the run before any step.
    fn check_start(&mut self) -> Result<()> {
        if !self.is_flat() && self.null_dimension()? == 0 {
            self.termination = Some(Termination::LockedAtStart);
            self.phase = Phase::Done;
        }
        Ok(())
    }

    /// A recorded step: counts it and tracks the largest arc residual.
    fn recorded(&mut self, kind: StepKind) -> Option<StepKind> {
        self.steps += 1;
        self.arc_residual = self.model.max_arc_residual(&self.nodes);
        self.max_arc_residual = self.max_arc_residual.max(self.arc_residual);
        Some(kind)
    }

    /// One action of the driver: a descent step, a Newton finish, a restart, a path state or
    /// a decision. Returns the kind of step when the nodes moved and the step is recorded.
    pub fn advance(&mut self) -> Result<Option<StepKind>> {
        match std::mem::replace(&mut self.phase, Phase::Done) {
            Phase::Done => Ok(None),
            Phase::Descend => {
                self.phase = Phase::Descend;
                self.descend()
            }
            Phase::Decide => self.decide(),
            Phase::OpenPath(mut states, stalled) => match states.next() {
                Some((nodes, value)) => {
                    self.nodes = nodes;
                    self.energy_value = value;
                    self.phase = Phase::OpenPath(states, stalled);
                    Ok(self.recorded(StepKind::OpenChainPath))
                }
                None => {
                    self.termination = Some(Termination::OpenChainPath { stalled });
                    Ok(None)
                }
            },
        }
    }

    /// Descend until flat, stationary or out of iterations; once flat, polish until the line
    /// search is stationary or the polish budget is spent.
    fn descend(&mut self) -> Result<Option<StepKind>> {
        if self.steps >= self.settings.max_iterations {
            self.phase = Phase::Decide;
            return Ok(None);
        }
        let largest = self.model.max_fold_angle(&self.nodes);
        // Near flat the descent is linear at best; try Newton onto ρ = 0 once per decade of
        // max |ρ| below FLATTEN_FROM (it checks energy, crossings, clearance).
        let decade = largest <= self.next_flatten && largest > self.settings.flat_tol;
        if self.settings.newton_flatten && self.flattened_from.is_none() && decade {
            self.next_flatten = largest / 10.0;
            if self.flatten() {
                self.flattened_from = Some(largest);
                self.phase = Phase::Decide;
                return Ok(self.recorded(StepKind::NewtonFinish));
            }
        }
        if largest <= self.settings.flat_tol {
            // Nothing for Newton to gain once the fold angles are at rounding level.
            if self.settings.newton_flatten && !self.flatten_tried && largest > ROUNDING_FLAT {
                self.flatten_tried = true;
                if self.flatten() {
                    self.flattened_from = Some(largest);
                    self.phase = Phase::Decide;
                    return Ok(self.recorded(StepKind::NewtonFinish));
                }
            }
            if self.polish_left == 0 {
                self.phase = Phase::Decide;
                return Ok(None);
            }
            self.polish_left -= 1;
        }
        let pins_before = self.pins;
        match self.step()? {
            StepOutcome::Moved { .. } => {
                let kind = if self.pins > pins_before {
                    StepKind::AntipodalPins
                } else {
                    StepKind::Descent
                };
                Ok(self.recorded(kind))
            }
            StepOutcome::Stationary => {
                self.stationary = true;
                self.phase = Phase::Decide;
                Ok(None)
            }
        }
    }

    /// After the descent: a stall near flat goes to Newton; flat ends; otherwise restart,
    /// or after the restarts decide between the open chain's path and a stop.
    fn decide(&mut self) -> Result<Option<StepKind>> {
        // A stall this close to flat is the √ε limit of U, not a minimum: Newton decides.
        let left = self.model.max_fold_angle(&self.nodes);
        let stalled_near_flat = self.stationary && left < NEAR_FLAT && left > ROUNDING_FLAT;
        if self.settings.newton_flatten && self.flattened_from.is_none() && stalled_near_flat && self.flatten() {
            self.flattened_from = Some(left);
            self.phase = Phase::Decide;
            return Ok(self.recorded(StepKind::NewtonFinish));
        }
        if self.is_flat() {
            self.termination = Some(Termination::Flat {
                flattened_from: self.flattened_from,
            });
            return Ok(None);
        }
        let out_of_iterations = self.steps >= self.settings.max_iterations;
        if self.restarts_used >= self.settings.restarts || out_of_iterations {
            let dof = self.null_dimension()?;
            let largest = self.model.max_fold_angle(&self.nodes);
            if self.settings.restarts > 0 && self.stationary && largest >= NEAR_FLAT && dof > 0 {
                if let Some(path) = open_chain_path(self.model, self.energy.as_ref(), &self.nodes) {
                    self.phase = Phase::OpenPath(path.into_iter(), largest);
                    return Ok(None);
                }
            }
            self.termination = Some(Termination::Stopped {
                stationary: self.stationary,
                dof,
                largest,
            });
            return Ok(None);
        }
        self.restarts_used += 1;
        self.kick(self.settings.restart_kick_rad)?;
        self.stationary = false;
        self.polish_left = self.settings.polish_iterations;
        self.flatten_tried = false;
        self.next_flatten = FLATTEN_FROM;
        self.phase = Phase::Descend;
        Ok(None)
    }

    /// Copies what observers read into the state (the geometry only after a recorded step:
    /// decisions and restarts leave nothing to observe).
    fn fill_state(&self, state: &mut UnfoldState, kind: Option<StepKind>) {
        state.recorded = kind;
        state.steps = self.steps;
        state.energy = self.energy_value;
        if kind.is_none() {
            return;
        }
        state.direction_norm = self.last_direction_norm;
        state.nodes.clone_from(&self.nodes);
        self.model.crease_angles_into(&self.nodes, &mut state.crease_angles);
        state.max_fold_angle = self.model.max_fold_angle(&self.nodes);
        state.max_arc_residual = self.arc_residual;
    }
}

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

/// The problem argmin's executor carries: the energy and the constraints live in the
/// solver's model, so there is nothing else to hold.
#[derive(Debug, Clone, Copy, Default)]
pub struct UnfoldProblem;

impl Solver<UnfoldProblem, UnfoldState> for ProjectedGradient<'_> {
    fn name(&self) -> &str {
        "nanofold projected gradient"
    }

    fn init(
        &mut self,
        _problem: &mut Problem<UnfoldProblem>,
        mut state: UnfoldState,
    ) -> std::result::Result<(UnfoldState, Option<KV>), argmin::core::Error> {
        self.check_start()?;
        self.fill_state(&mut state, Some(StepKind::Start));
        if matches!(self.phase, Phase::Done) {
            state = state.terminate_with(TerminationReason::SolverConverged);
        }
        Ok((state, None))
    }

    fn next_iter(
        &mut self,
        _problem: &mut Problem<UnfoldProblem>,
        mut state: UnfoldState,
    ) -> std::result::Result<(UnfoldState, Option<KV>), argmin::core::Error> {
        let kind = self.advance()?;
        self.fill_state(&mut state, kind);
        if self.termination.is_some() {
            state = state.terminate_with(TerminationReason::SolverConverged);
        }
        Ok((state, None))
    }
}
