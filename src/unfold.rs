//! The unfolding engine (`docs/model.md#unfolding`): projected-gradient steps on the sphere,
//! driven to a verdict. The direction is the QP of `qp` in tangent coordinates of the free
//! nodes; a backtracking line search on U refuses steps that carry a node through an arc
//! (`checks`); Newton projection restores the arc-length, unit-norm and held-crease
//! constraints (`manifold`).
//!
//! Layout after Pinocchio and argmin: [`UnfoldModel`] is the immutable description, the
//! [`solver::ProjectedGradient`] takes one step per call (an argmin `Solver`), argmin's
//! `Executor` drives it with `observe`rs recording the trajectory and progress, and
//! [`unfold`] turns its termination into a [`Verdict`] with evidence.

pub(crate) mod barrier;
pub(crate) mod checks;
pub(crate) mod energy;
pub(crate) mod manifold;
pub(crate) mod model;
pub mod network;
pub(crate) mod observe;
pub(crate) mod qp;
pub(crate) mod settings;
pub(crate) mod solver;
pub(crate) mod state;
pub use barrier::{barrier_function, BarrierSettings, PanelBarrier};
pub use energy::{EnergyKind, EnergyWorkspace};
pub use qp::{solve_clarabel, solve_direct, DirectWorkspace, DirectionProblem, QpMethod, RowSpace};
pub use state::StepKind;

pub use checks::{find_crossing, node_arc_clearance, planarity_residual, touching_charges};
pub use model::{HeldFold, UnfoldModel};
pub use observe::{StepRecord, TrajectoryRecorder, UnfoldProgress};
pub use settings::{Recording, UnfoldSettings};
pub use solver::{ProjectedGradient, SplitMix64, StepOutcome, Termination};

use crate::error::{NanofoldError, NumericalError, Result};
use crate::geometry::kinematics;
use crate::geometry::sphere::Vec3;
use crate::pattern::{Chain, VertexPattern};
use argmin::core::observers::ObserverMode;
use argmin::core::Executor;
use serde::Serialize;
use solver::{UnfoldProblem, NEAR_FLAT, OPEN_PATH_STEPS};
use state::UnfoldState;
use std::f64::consts::PI;
use std::time::Instant;

/// Backs a flat-folded (|ρ| = π, coincident charges) start off the singularity: every fold
/// angle is scaled by (1 − 10⁻³) and the constraints restored (documented in README).
const FLAT_FOLDED_BACKOFF: f64 = 1e-3;

/// The answer to "does this pattern unfold?" (`docs/model.md#verdicts`), from either
/// engine: the single vertex's ([`unfold`]) or the crease pattern's ([`network`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Reached the flat state; the trajectory reversed is a folding path.
    Flat,
    /// Stopped away from flat, restarts disabled (no evidence either way).
    Stuck,
    /// No motion is possible: the constraint Jacobian has no null space (rigid state).
    Locked,
    /// Motion is possible, but every restart from a perturbed state came back stuck (a
    /// crease pattern: the projected gradient vanished away from flat).
    LocalMinimum,
    /// A closed chain whose sector angles do not sum to 2π has no flat state.
    NotFlatFoldable,
    /// Every step the line search tried put panels through each other (a crease pattern).
    Blocked,
    /// The iteration budget ran out (a crease pattern).
    IterationLimit,
    /// The start is not a rigid state (a vertex of a crease pattern does not close):
    /// nothing to unfold rigidly.
    NotRigid,
}

impl crate::names::Named for Verdict {}

/// Everything an unfolding run produced.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct UnfoldReport {
    /// The answer.
    pub verdict: Verdict,
    /// Why this verdict, in words (the evidence).
    pub evidence: String,
    /// Why the solver stopped (the verdict's source).
    #[serde(skip)]
    pub termination: Option<Termination>,
    /// Recorded steps.
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// U at the start.
    pub energy_initial: f64,
    /// U at the end.
    pub energy_final: f64,
    /// The given folded state's crease angles, rad.
    pub initial_fold_angles_rad: Vec<f64>,
    /// The end state's crease angles, rad.
    pub final_fold_angles_rad: Vec<f64>,
    /// Largest |γ − α| over all recorded steps.
    pub max_arc_residual: f64,
    /// Largest distance of a node from the best-fit great-circle plane at the end.
    pub planarity_residual: f64,
    /// Largest node distance from the exact flat layout at the end (meaningful when flat;
    /// NaN for a pattern with no flat state, a cone, and `null` in the CLI's JSON).
    pub flat_layout_error: f64,
    /// Restarts from perturbed states taken.
    pub restarts_used: usize,
    /// Trial steps refused because they carried a node through an arc.
    pub crossings_refused: usize,
    /// Direction QPs Clarabel solved to reduced accuracy.
    pub qp_almost_solved: usize,
    /// Rules applied to the input or the start (rescaling, splits, flat-folded back-off).
    pub adjustments: Vec<String>,
    /// The recorded steps (as [`UnfoldSettings::recording`] keeps them).
    #[serde(skip)]
    pub trajectory: Vec<StepRecord>,
    /// The nodes at the end.
    #[serde(skip)]
    pub final_nodes: Vec<Vec3>,
}

/// Unfolds a pattern: the main job. Validates the settings, backs a flat-folded start off
/// its singularity, runs the solver to its termination and states the verdict.
///
/// ```
/// use nanofold::prelude::*;
/// use std::f64::consts::FRAC_PI_2;
/// // A degree-4 vertex folded along one straight crease line by 1 rad.
/// let pattern = VertexBuilder::closed("plus")
///     .sector_angles([FRAC_PI_2; 4])
///     .crease(Assignment::Valley, 1.0)
///     .crease(Assignment::Unassigned, 0.0)
///     .crease(Assignment::Valley, 1.0)
///     .crease(Assignment::Unassigned, 0.0)
///     .build()?;
/// let report = unfold_vertex(&pattern, &UnfoldSettings::default())?;
/// assert_eq!(report.verdict, UnfoldVerdict::Flat);
/// assert!(report.flat_layout_error < 1e-10);
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn unfold(pattern: &VertexPattern, settings: &UnfoldSettings) -> Result<UnfoldReport> {
    unfold_observed(pattern, settings, None)
}

/// [`unfold`], telling `progress` of every recorded step.
pub fn unfold_observed(
    pattern: &VertexPattern,
    settings: &UnfoldSettings,
    progress: Option<UnfoldProgress>,
) -> Result<UnfoldReport> {
    settings.validate()?;
    let started = Instant::now();
    let model = UnfoldModel::new(pattern);
    let paper: f64 = model.sector_angles.iter().sum();
    if model.chain == Chain::Open && paper >= 2.0 * PI - 1e-9 {
        // Its two boundary rays lie on one another when flat: a node on an arc's end, where
        // the repulsive energy is infinite (`docs/model.md#energy`).
        return Err(NanofoldError::invalid(
            "sector_angles",
            format!("sum {:.9}°", paper.to_degrees()),
            "an open chain of a full turn of paper has its two boundary rays on one another when flat, where the repulsive energy is infinite: give it less paper, or close it (the boundary rays one crease)",
        ));
    }
    let mut adjustments = pattern.adjustments.clone();
    let mut start = model.folded_nodes();
    let initial_fold_angles: Vec<f64> = pattern.creases.iter().map(|c| c.folded_angle).collect();
    if !pattern.flat_foldable {
        return Ok(not_flat_foldable(
            pattern,
            settings,
            &model,
            start,
            initial_fold_angles,
            started,
        ));
    }
    let energy = settings.energy.build(settings.p);
    // A start already flat needs no back-off (scaling zero fold angles changes nothing).
    let already_flat = model.max_fold_angle(&start) <= settings.flat_tol;
    if !already_flat && touching_charges(&model, &start)
        || !energy
            .value(&start, &model.arcs, &mut EnergyWorkspace::default())
            .is_finite()
    {
        let mut scaled: Vec<f64> = model
            .folded_ray_angles
            .iter()
            .map(|r| r * (1.0 - FLAT_FOLDED_BACKOFF))
            .collect();
        // Closed in the fold angles first (minimum-norm Newton, then to rounding): the
        // nodes placed from closed angles keep every arc, where restoring the scaled nodes
        // from near the singular flat-folded state converges only linearly.
        // An open chain has no loop to close: its scaled angles place its nodes as they are.
        let every: Vec<usize> = (0..scaled.len()).collect();
        let mut closed = scaled.clone();
        if model.chain == Chain::Closed
            && kinematics::solve_closure(&model.sector_angles, &mut closed, &every, 1e-14, 200).is_ok()
        {
            kinematics::refine_closure(&model.sector_angles, &mut closed, &every, 50);
            scaled = closed;
        }
        start = kinematics::forward(&model.sector_angles, &scaled);
        adjustments.push(format!(
            "start has touching charges (flat-folded, infinite energy): fold angles scaled by {} and constraints restored",
            1.0 - FLAT_FOLDED_BACKOFF
        ));
    }
    let solver = ProjectedGradient::new(&model, settings, start)?;
    if !solver.energy_value.is_finite() {
        return Err(NumericalError::NonFinite {
            what: "initial energy",
            detail: "charges still touch after backing off the flat-folded state".into(),
        }
        .into());
    }
    let energy_initial = solver.energy_value;
    let recorder = TrajectoryRecorder::new(settings.recording);
    // argmin counts every call (decisions and restarts too): a cap well above the steps.
    let max_calls = (4 * settings.max_iterations + OPEN_PATH_STEPS + 10 * settings.restarts + 16) as u64;
    let state = UnfoldState::sized(model.node_count, pattern.creases.len(), max_calls);
    let mut executor = Executor::new(UnfoldProblem, solver)
        .configure(|_| state)
        .add_observer(recorder.clone(), ObserverMode::Always);
    if let Some(progress) = progress {
        executor = executor.add_observer(progress, ObserverMode::Always);
    }
    let result = executor.run().map_err(from_executor)?;
    let solver = result.solver;
    let (verdict, evidence) = verdict(&solver, settings);
    let final_nodes = solver.nodes.clone();
    Ok(UnfoldReport {
        verdict,
        evidence,
        termination: solver.termination.clone(),
        iterations: solver.steps,
        seconds: started.elapsed().as_secs_f64(),
        energy_initial,
        energy_final: solver.energy_value,
        initial_fold_angles_rad: initial_fold_angles,
        final_fold_angles_rad: model.crease_angles(&final_nodes),
        max_arc_residual: solver.max_arc_residual,
        planarity_residual: planarity_residual(&final_nodes),
        flat_layout_error: model.flat_layout_error(&final_nodes),
        restarts_used: solver.restarts_used,
        crossings_refused: solver.crossings_refused,
        qp_almost_solved: solver.qp_almost_solved,
        adjustments,
        trajectory: recorder.take(),
        final_nodes,
    })
}

/// An error out of argmin's executor: the solver's own error where it raised one.
pub(crate) fn from_executor(error: argmin::core::Error) -> NanofoldError {
    match error.downcast::<NanofoldError>() {
        Ok(error) => error,
        Err(other) => NumericalError::Executor {
            detail: other.to_string(),
        }
        .into(),
    }
}

/// The verdict and its evidence from the solver's termination.
fn verdict(solver: &ProjectedGradient, settings: &UnfoldSettings) -> (Verdict, String) {
    let model = solver.model();
    let restarts_used = solver.restarts_used;
    let iterations = solver.steps;
    match solver.termination.clone() {
        Some(Termination::LockedAtStart) => (
            Verdict::Locked,
            "the constraint Jacobian has full column rank at the given state: no motion is possible".to_string(),
        ),
        Some(Termination::Flat { flattened_from }) => {
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
            (Verdict::Flat, words)
        }
        Some(Termination::OpenChainPath { stalled }) => (
            Verdict::Flat,
            format!(
                "open chain: the energy is stationary at max |ρ| = {stalled:.3e} rad ({restarts_used} restarts all came back), and from there every fold angle scaled straight to 0 in {OPEN_PATH_STEPS} steps carries no node through an arc"
            ),
        ),
        Some(Termination::Stopped {
            stationary,
            dof,
            largest,
        }) => {
            let budget = solver::step_budget(settings.max_iterations, model.node_count);
            let why = if stationary {
                "stationary".to_string()
            } else if budget < settings.max_iterations {
                format!(
                    "work bound ({budget} steps for {} nodes, {} node pairs in all)",
                    model.node_count,
                    solver::DESCENT_WORK
                )
            } else {
                "iteration limit".to_string()
            };
            if settings.restarts == 0 || !stationary {
                (
                    Verdict::Stuck,
                    format!("{why} at max |ρ| = {largest:.3e} rad after {iterations} iterations ({restarts_used} restarts)"),
                )
            } else if largest < NEAR_FLAT {
                // A stall this close to flat is the solver meeting the singular constraint
                // Jacobian of the flat state, not a minimum of the energy.
                (
                    Verdict::Stuck,
                    format!(
                        "stalled {largest:.3e} rad from flat after {iterations} iterations and {restarts_used} restarts: the constraint Jacobian is singular at the flat state, so this is a solver limit near flat, not a local minimum"
                    ),
                )
            } else if dof == 0 {
                (
                    Verdict::Locked,
                    "stationary at a state with no first-order motion (rigid)".to_string(),
                )
            } else {
                (
                    Verdict::LocalMinimum,
                    format!(
                        "stationary at max |ρ| = {largest:.3e} rad with {dof} first-order degrees of freedom; {restarts_used} restarts from perturbed states all stuck"
                    ),
                )
            }
        }
        None => (
            Verdict::Stuck,
            format!("the executor stopped after {iterations} recorded steps without a termination"),
        ),
    }
}

/// The report of a closed chain whose sectors do not sum to 2π (a cone): no flat state.
fn not_flat_foldable(
    pattern: &VertexPattern,
    settings: &UnfoldSettings,
    model: &UnfoldModel,
    start: Vec<Vec3>,
    initial_fold_angles: Vec<f64>,
    started: Instant,
) -> UnfoldReport {
    let energy = settings
        .energy
        .build(settings.p)
        .value(&start, &model.arcs, &mut EnergyWorkspace::default());
    let excess = pattern.angle_sum - 2.0 * PI;
    UnfoldReport {
        verdict: Verdict::NotFlatFoldable,
        evidence: format!(
            "closed chain with sector angles summing to {:.9}° ({:+.3e} rad from 360°): a cone has no flat state",
            pattern.angle_sum.to_degrees(),
            excess
        ),
        termination: None,
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
        adjustments: pattern.adjustments.clone(),
        trajectory: Vec::new(),
        final_nodes: start,
    }
}

impl crate::names::Answer for UnfoldReport {
    fn verdict_name(&self) -> &'static str {
        crate::names::variant_name(&self.verdict)
    }

    fn evidence(&self) -> &str {
        &self.evidence
    }
}
