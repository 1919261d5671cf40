//! What an unfolding run's observers see after each step ([`UnfoldState`], argmin's `State`
//! for this solver): the nodes, the energy, the crease angles, what kind of step it was.
//! It keeps no "best" copy of the nodes (the energy only falls), so updating it allocates
//! nothing.

use crate::geometry::sphere::Vec3;
use argmin::core::{Problem, State, TerminationReason, TerminationStatus};
use serde::Serialize;
use std::collections::HashMap;

/// What a recorded step did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StepKind {
    /// The start, restored onto the constraints.
    Start,
    /// A projected-gradient step with its line search.
    Descent,
    /// A projected-gradient step after which antipodal node pairs were pinned.
    AntipodalPins,
    /// The Newton finish onto ρ = 0.
    NewtonFinish,
    /// A state on an open chain's straight path to flat.
    OpenChainPath,
    /// A state of the rigid folding path from flat onto the folded state, reversed (where
    /// the descent stopped short of flat).
    FoldingPath,
}

/// The state after a step.
#[derive(Debug, Clone)]
pub struct UnfoldState {
    /// The kind of step taken, when the step is one to record (None: a decision or a
    /// restart, which records nothing).
    pub recorded: Option<StepKind>,
    /// Recorded steps so far.
    pub steps: usize,
    /// U at the nodes.
    pub energy: f64,
    /// ‖d‖∞ of the direction that led here.
    pub direction_norm: f64,
    /// The nodes, one unit vector per ray.
    pub nodes: Vec<Vec3>,
    /// Fold angle of every user crease, file order, rad.
    pub crease_angles: Vec<f64>,
    /// max |ρ| over every folding ray, rad.
    pub max_fold_angle: f64,
    /// Largest |γ − α| at the nodes, rad.
    pub max_arc_residual: f64,
    iter: u64,
    max_iters: u64,
    status: TerminationStatus,
    counts: HashMap<String, u64>,
}

impl UnfoldState {
    /// Sizes the buffers for `nodes` nodes and `creases` creases, and caps argmin's own
    /// iteration count (which counts decisions and restarts too) at `max_calls`.
    pub fn sized(nodes: usize, creases: usize, max_calls: u64) -> Self {
        let mut state = UnfoldState::new();
        state.nodes = vec![Vec3::zeros(); nodes];
        state.crease_angles = vec![0.0; creases];
        state.max_iters = max_calls;
        state
    }
}

impl State for UnfoldState {
    type Param = Vec<Vec3>;
    type Float = f64;

    fn new() -> Self {
        UnfoldState {
            recorded: None,
            steps: 0,
            energy: f64::INFINITY,
            direction_norm: 0.0,
            nodes: Vec::new(),
            crease_angles: Vec::new(),
            max_fold_angle: 0.0,
            max_arc_residual: 0.0,
            iter: 0,
            max_iters: u64::MAX,
            status: TerminationStatus::NotTerminated,
            counts: HashMap::new(),
        }
    }

    fn update(&mut self) {}

    fn get_param(&self) -> Option<&Vec<Vec3>> {
        Some(&self.nodes)
    }

    fn get_best_param(&self) -> Option<&Vec<Vec3>> {
        Some(&self.nodes)
    }

    fn get_max_iters(&self) -> u64 {
        self.max_iters
    }

    fn increment_iter(&mut self) {
        self.iter += 1;
    }

    fn get_iter(&self) -> u64 {
        self.iter
    }

    fn get_cost(&self) -> f64 {
        self.energy
    }

    fn get_best_cost(&self) -> f64 {
        self.energy
    }

    fn get_target_cost(&self) -> f64 {
        f64::NEG_INFINITY
    }

    fn func_counts<O>(&mut self, _problem: &Problem<O>) {}

    fn get_func_counts(&self) -> &HashMap<String, u64> {
        &self.counts
    }

    fn time(&mut self, _time: Option<std::time::Duration>) -> &mut Self {
        self
    }

    fn get_time(&self) -> Option<std::time::Duration> {
        None
    }

    fn get_last_best_iter(&self) -> u64 {
        self.iter
    }

    fn is_best(&self) -> bool {
        true
    }

    fn terminate_with(mut self, reason: TerminationReason) -> Self {
        self.status = TerminationStatus::Terminated(reason);
        self
    }

    fn get_termination_status(&self) -> &TerminationStatus {
        &self.status
    }

    fn get_termination_reason(&self) -> Option<&TerminationReason> {
        match &self.status {
            TerminationStatus::Terminated(reason) => Some(reason),
            TerminationStatus::NotTerminated => None,
        }
    }
}
