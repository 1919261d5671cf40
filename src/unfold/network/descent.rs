//! The many-vertex descent as argmin's `Solver`: one step at a time (L-BFGS direction on the
//! closure manifold, line search, the ray to flat, restarts), the state its observers see,
//! and the report it ends with (`docs/model.md#energy-unfolding-of-many-vertices`).

use super::{
    dot, flat_step, major_crease, norm, radial_step, restart, restart_note, try_state, Accepted, NetworkStep,
    NetworkUnfoldReport, NetworkUnfoldSettings, Objective, Trial, Verdict, FLAT_APPROACH, NEAR_FLAT, STALL_TOL,
};
use crate::error::Result;
use crate::folding::normal::{NormalFactor, NormalSolver};
use crate::folding::{closure_jacobian, vertex_residuals, FoldingModel, Pose};
use crate::unfold::energy::EnergyWorkspace;
use crate::unfold::observe::ProgressOf;
use crate::unfold::solver::SplitMix64;
use argmin::core::{IterState, Problem, Solver, State, TerminationReason, KV};

/// Adds the curvature pair (the step, the change of the projected gradient) to `history`
/// where it has positive curvature, keeping the last `memory`.
fn remember_pair(
    history: &mut Vec<(Vec<f64>, Vec<f64>, f64)>,
    rho: &[f64],
    previous_rho: &[f64],
    steepest: &[f64],
    previous_steepest: &[f64],
    memory: usize,
) {
    let s_pair: Vec<f64> = rho.iter().zip(previous_rho).map(|(a, b)| a - b).collect();
    let y_pair: Vec<f64> = previous_steepest.iter().zip(steepest).map(|(a, b)| a - b).collect();
    let sy = dot(&s_pair, &y_pair);
    if sy > 1e-12 * norm(&s_pair) * norm(&y_pair) && sy > 0.0 {
        history.push((s_pair, y_pair, 1.0 / sy));
        if history.len() > memory {
            history.remove(0);
        }
    }
}

/// L-BFGS's two-loop recursion on the projected gradient, projected onto the tangent space
/// again; the steepest direction where there is no history or the result is not downhill
/// (the history is then dropped).
fn lbfgs_direction(
    model: &FoldingModel,
    factor: &NormalFactor,
    history: &mut Vec<(Vec<f64>, Vec<f64>, f64)>,
    steepest: &[f64],
    gradient: &[f64],
) -> Vec<f64> {
    if history.is_empty() {
        return steepest.to_vec();
    }
    let mut q: Vec<f64> = steepest.iter().map(|d| -d).collect();
    let mut alphas = vec![0.0; history.len()];
    for (k, (s_pair, y_pair, rho_pair)) in history.iter().enumerate().rev() {
        alphas[k] = rho_pair * dot(s_pair, &q);
        q.iter_mut().zip(y_pair).for_each(|(q, y)| *q -= alphas[k] * y);
    }
    let (s_last, y_last, _) = history.last().expect("not empty");
    let gamma = dot(s_last, y_last) / dot(y_last, y_last);
    q.iter_mut().for_each(|q| *q *= gamma);
    for (k, (s_pair, y_pair, rho_pair)) in history.iter().enumerate() {
        let beta = rho_pair * dot(y_pair, &q);
        q.iter_mut().zip(s_pair).for_each(|(q, s)| *q += (alphas[k] - beta) * s);
    }
    let mut candidate: Vec<f64> = q.iter().map(|q| -q).collect();
    model.hold_locked(&mut candidate);
    let candidate = factor.project(&candidate);
    if dot(gradient, &candidate) < 0.0 {
        candidate
    } else {
        history.clear();
        steepest.to_vec()
    }
}

/// Why a descent ends, and the evidence.
pub type DescentStop = (Verdict, String);

/// A descent under way: the state, its energy and gradient, the steps so far, L-BFGS's
/// memory, the line search's and the restarts' state, and the scratch they reuse. Driven by
/// [`NetworkDescent::iterate`] one step at a time, or by argmin's `Executor` as a `Solver`.
pub struct NetworkDescent<'a> {
    objective: Objective<'a>,
    settings: &'a NetworkUnfoldSettings,
    solver: NormalSolver,
    ws: EnergyWorkspace,
    poses: Vec<Pose>,
    /// The fold angles now, rad.
    pub(super) rho: Vec<f64>,
    u: f64,
    gradient: Vec<f64>,
    steps: Vec<NetworkStep>,
    crossings_refused: usize,
    major: Vec<bool>,
    radial_steps: usize,
    history: Vec<(Vec<f64>, Vec<f64>, f64)>,
    pending: Option<(Vec<f64>, Vec<f64>)>,
    quasi_newton_scale: f64,
    kick: SplitMix64,
    scale: f64,
    restarts: usize,
    restart_failed: bool,
    /// Why the descent ended, at which iteration (set by the executor's driving).
    stopped: Option<(DescentStop, usize)>,
}

impl<'a> NetworkDescent<'a> {
    pub(super) fn new(
        objective: Objective<'a>,
        settings: &'a NetworkUnfoldSettings,
        solver: NormalSolver,
        mut ws: EnergyWorkspace,
        rho: Vec<f64>,
    ) -> Self {
        let n = rho.len();
        let mut gradient = vec![0.0; n];
        let mut poses = Vec::new();
        let u = objective.evaluate(&rho, &mut ws, &mut poses, &mut gradient);
        let mut descent = NetworkDescent {
            objective,
            settings,
            solver,
            ws,
            poses,
            rho,
            u,
            gradient,
            steps: Vec::new(),
            crossings_refused: 0,
            major: vec![true; n],
            radial_steps: 0,
            history: Vec::new(),
            pending: None,
            quasi_newton_scale: 1.0,
            kick: SplitMix64(0x5EED_F00D),
            scale: 1.0,
            restarts: 0,
            restart_failed: false,
            stopped: None,
        };
        descent.record();
        descent
    }

    /// Records the current state as a step.
    fn record(&mut self) {
        let max_residual = vertex_residuals(self.objective.model, &self.rho)
            .into_iter()
            .fold(0.0, f64::max);
        self.steps.push(NetworkStep {
            energy: self.u,
            fold_angles: self.rho.clone(),
            max_residual,
        });
    }

    /// Puts the flat state in as the last step.
    fn record_flat(&mut self) {
        let n = self.rho.len();
        let flat = flat_step(&self.objective, n, &mut self.ws);
        self.steps.push(flat);
    }

    /// The report, with the iteration count at the stop.
    pub fn finish(self, (verdict, evidence): DescentStop, iterations: usize) -> NetworkUnfoldReport {
        let max_closure_residual = self.steps.iter().map(|s| s.max_residual).fold(0.0, f64::max);
        NetworkUnfoldReport {
            verdict,
            evidence,
            iterations,
            steps: self.steps,
            max_closure_residual,
            crossings_refused: self.crossings_refused,
            radial_steps: self.radial_steps,
            restarts_used: self.restarts,
        }
    }

    /// A stop away from flat with no panels in the way: a restart if one is left and found
    /// (None: the descent goes on from it), else `local_minimum` saying what the restarts did.
    fn restart_or_stop(&mut self, factor: &NormalFactor, why: String) -> Result<Option<DescentStop>> {
        if self.restarts < self.settings.restarts {
            let restarted = restart(
                &self.objective,
                self.settings,
                factor,
                &mut self.kick,
                &self.rho,
                &mut self.ws,
                &mut self.poses,
                &mut self.solver,
            )?;
            if let Some(state) = restarted {
                self.restarts += 1;
                (self.rho, self.u, self.gradient) = state;
                self.history.clear();
                self.pending = None;
                self.record();
                return Ok(None);
            }
            self.restart_failed = true;
        }
        Ok(Some((
            Verdict::LocalMinimum,
            format!("{why}; {}", restart_note(self.restarts, self.restart_failed)),
        )))
    }

    /// A step along the ray to flat, counted when taken.
    fn try_radial(&mut self, refused_for_crossing: &mut Option<[usize; 2]>) -> Result<Option<Accepted>> {
        let state = radial_step(
            self.objective.model,
            &self.objective,
            self.settings,
            &mut self.solver,
            &mut self.ws,
            &mut self.poses,
            &self.rho,
            self.u,
            &mut self.crossings_refused,
            refused_for_crossing,
        )?;
        self.radial_steps += usize::from(state.is_some());
        Ok(state)
    }

    /// One iteration: the flat finishes, the direction, the line search, the step. Some(stop)
    /// where the descent ends.
    pub fn iterate(&mut self, iteration: usize) -> Result<Option<DescentStop>> {
        let (model, settings) = (self.objective.model, self.settings);
        let u = self.u;
        let largest = self.rho.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        if largest <= STALL_TOL && largest > settings.flat_tol {
            // The flat finish: this close, the energy's changes are at its rounding and
            // descent crawls. The flat state is rigid; it is taken if its energy is no higher.
            let n = self.rho.len();
            let flat = flat_step(&self.objective, n, &mut self.ws);
            let u_flat = flat.energy;
            if u_flat <= u * (1.0 + 1e-12) {
                self.steps.push(flat);
                return Ok(Some((
                    Verdict::Flat,
                    format!("descended to max |ρ| = {largest:.1e} rad after {iteration} steps, then finished onto the flat state (within {STALL_TOL:.0e}; energy {u:.9e} → {u_flat:.9e})"),
                )));
            }
        }
        if largest <= settings.flat_tol {
            self.record_flat();
            return Ok(Some((
                Verdict::Flat,
                format!("every fold angle within {:.0e} rad after {iteration} steps (max |ρ| = {largest:.1e}), then set to 0", settings.flat_tol),
            )));
        }
        let factor = self.solver.factor(&closure_jacobian(model, &self.rho))?;
        let mut downhill: Vec<f64> = self.gradient.iter().map(|g| -g).collect();
        model.hold_locked(&mut downhill);
        let steepest: Vec<f64> = factor.project(&downhill);
        let steepest_size = steepest.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        if steepest_size <= 1e-14 {
            return self.restart_or_stop(
                &factor,
                format!("the projected gradient vanishes (|d| = {steepest_size:.1e}) with max |ρ| = {largest:.3e} rad"),
            );
        }
        // The L-BFGS direction on the manifold: curvature pairs of steps and changes of the
        // projected gradient, the result projected onto the tangent space again.
        if let Some((previous_rho, previous_steepest)) = self.pending.take() {
            remember_pair(
                &mut self.history,
                &self.rho,
                &previous_rho,
                &steepest,
                &previous_steepest,
                settings.memory,
            );
        }
        let descent = lbfgs_direction(model, &factor, &mut self.history, &steepest, &self.gradient);
        self.pending = Some((self.rho.clone(), steepest));
        let size = descent.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        let slope: f64 = self.gradient.iter().zip(&descent).map(|(g, d)| g * d).sum();
        if size <= 1e-14 || slope >= 0.0 {
            return Ok(Some((
                Verdict::LocalMinimum,
                format!("the projected gradient vanishes (|d| = {size:.1e}) with max |ρ| = {largest:.3e} rad"),
            )));
        }
        // A quasi-Newton step is tried whole first (within max_step); the gradient's length
        // says nothing of the step, so there the line search remembers its last share.
        let quasi_newton = settings.memory > 0 && !self.history.is_empty();
        let mut t = if quasi_newton {
            (settings.max_step / size).min(self.quasi_newton_scale)
        } else {
            (settings.max_step / size) * self.scale
        };
        let t_planned = t;
        // No vertex may pass through its flat state in one step: there the branches of its
        // folding motion cross, and beyond lies the mirrored state, not progress. A vertex
        // heads there when one of its major creases (|ρ| within MAJOR_SHARE of its largest)
        // heads to 0; a minor crease of a vertex that stays folded may change sign.
        major_crease(model, &self.rho, &mut self.major);
        for ((r, d), &is_major) in self.rho.iter().zip(&descent).zip(&self.major) {
            if is_major && r * d < 0.0 && r.abs() > settings.flat_tol {
                t = t.min(FLAT_APPROACH * (r / d).abs());
            }
        }
        let t_before_search = t;
        let mut refused_for_crossing = None;
        let mut halvings = 0;
        // Near flat the ray to flat is tried first: the cheapest step that keeps the branch.
        // Without interior vertices every state is rigid, the ray among them: first at any
        // fold (an accordion halves its angles each step instead of creeping down its
        // barrier's gradient).
        let radial_first = largest <= NEAR_FLAT || model.stars.is_empty();
        let mut accepted = None;
        if radial_first {
            accepted = self.try_radial(&mut refused_for_crossing)?;
        }
        // Steps shorter than this are lost in the closure tolerance.
        while accepted.is_none() && t * size > 1e-13 {
            let trial: Vec<f64> = self.rho.iter().zip(&descent).map(|(r, d)| r + t * d).collect();
            let armijo = u + 1e-4 * t * slope;
            match try_state(
                model,
                &self.objective,
                settings,
                &mut self.solver,
                &mut self.ws,
                &mut self.poses,
                trial,
                |v| v <= armijo,
            )? {
                Trial::Accepted(state) => {
                    accepted = Some(state);
                    break;
                }
                Trial::Crossing(pair) => {
                    self.crossings_refused += 1;
                    refused_for_crossing = Some(pair);
                }
                Trial::Refused => {}
            }
            t /= 2.0;
            halvings += 1;
        }
        // Within STALL_TOL of flat a step that does not lower the energy at all is lost in
        // its rounding: count it as the line search stalling.
        let mut accepted = accepted.filter(|(_, u_next, _)| largest > STALL_TOL || *u_next < u);
        if accepted.is_none() && !radial_first {
            accepted = self.try_radial(&mut refused_for_crossing)?;
        }
        let Some((next, u_next, g_next)) = accepted else {
            if largest <= STALL_TOL && refused_for_crossing.is_none() {
                // The energy's changes are below its rounding this close to flat; the flat
                // state is rigid and the descent was heading there.
                self.record_flat();
                return Ok(Some((
                    Verdict::Flat,
                    format!("the line search stalled {largest:.1e} rad from flat (within {STALL_TOL:.0e}, where the energy's changes are at its rounding), then set to 0"),
                )));
            }
            if let Some([a, b]) = refused_for_crossing {
                return Ok(Some((
                    Verdict::Blocked,
                    format!("every shorter step still puts panels through each other: panels {a} and {b} would meet (max |ρ| = {largest:.3e} rad)"),
                )));
            }
            return self.restart_or_stop(
                &factor,
                format!("the line search found no decrease (max |ρ| = {largest:.3e} rad, energy {u:.6e})"),
            );
        };
        // The line search's memory: twice the largest step if this one needed no halving,
        // fewer halvings than this one next time otherwise. A step cut short by the flat
        // approach says nothing about the energy's curvature, so it leaves the memory alone.
        if quasi_newton {
            // The step multiple to try next: doubled after a step taken whole, the one taken
            // otherwise; a step cut by the flat approach leaves it alone.
            if t_before_search >= t_planned {
                self.quasi_newton_scale = if halvings == 0 { 2.0 * t } else { t }.max(1e-6);
            }
        } else {
            self.scale = (self.scale * 2f64.powi(1 - halvings)).clamp(1e-6, 1.0);
        }
        self.rho = next;
        self.u = u_next;
        self.gradient = g_next;
        self.record();
        Ok(None)
    }

    /// The executor's state at the start: the fold angles and energy, and the iteration
    /// budget.
    pub fn state(&self) -> NetworkState {
        NetworkState::new()
            .param(self.rho.clone())
            .cost(self.u)
            .max_iters(self.settings.max_iterations as u64)
    }

    /// The report once the executor has stopped: the descent's own stop, or the iteration
    /// budget spent.
    pub fn into_report(mut self) -> NetworkUnfoldReport {
        match self.stopped.take() {
            Some((stop, iteration)) => self.finish(stop, iteration),
            None => {
                let limit = self.settings.max_iterations;
                self.finish((Verdict::IterationLimit, format!("{limit} steps")), limit)
            }
        }
    }
}

/// The problem argmin's executor carries: the energy and the closure live in the descent.
#[derive(Debug, Clone, Copy, Default)]
pub struct NetworkProblem;

/// What the descent's observers see after each step: the fold angles (argmin's parameter)
/// and the energy (its cost).
pub type NetworkState = IterState<Vec<f64>, (), (), (), (), f64>;

impl ProgressOf for NetworkState {
    fn progress(&self) -> Option<(usize, f64, f64)> {
        let largest = self
            .get_param()
            .map_or(0.0, |rho| rho.iter().fold(0.0_f64, |m, r| m.max(r.abs())));
        Some((self.get_iter() as usize + 1, largest, self.get_cost()))
    }
}

impl Solver<NetworkProblem, NetworkState> for NetworkDescent<'_> {
    fn name(&self) -> &str {
        "nanofold network descent"
    }

    fn next_iter(
        &mut self,
        _problem: &mut Problem<NetworkProblem>,
        state: NetworkState,
    ) -> std::result::Result<(NetworkState, Option<KV>), argmin::core::Error> {
        let iteration = state.get_iter() as usize;
        let stop = self.iterate(iteration)?;
        let mut state = state.param(self.rho.clone()).cost(self.u);
        if let Some(stop) = stop {
            self.stopped = Some((stop, iteration));
            state = state.terminate_with(TerminationReason::SolverConverged);
        }
        Ok((state, None))
    }
}
