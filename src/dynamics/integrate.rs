//! Integration of a [`Plant`] from rest by diffsol (`docs/model.md#integration`), with
//! contact location on the dense output and a stop at every kink of the forcing.
//!
//! The integrator sees scaled time s = t ω_slow and state y = (q, dq/ds), so angles and rates
//! are both O(1) and one absolute tolerance fits all components (masses ~1e-12 kg and
//! stiffnesses ~1e-9 N·m give rates ~1e4 rad/s in SI).

use super::contact::{gaps_at, locate, Collision};
use super::plant::{Plant, Sample, TimeScales};
use crate::error::{NanofoldError, NumericalError, Result};
use diffsol::{
    NalgebraLU, NalgebraMat, NalgebraVec, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Vector,
};
use serde::{Deserialize, Serialize};
use std::cell::{Cell, RefCell};

/// Contact scanning: sub-intervals of a solver step in which some gap comes within reach of
/// zero (catches in-and-out crossings within a step).
const CONTACT_SUBDIVISIONS: usize = 4;
/// A run stops with an error once Newton has failed more than this many times and on more
/// than every other step (diffsol's own cap counts failures over the whole run; see `integrate`).
const NEWTON_FAILURE_FLOOR: usize = 1000;
/// The step after a jump is searched at this many equal parts for where the just-switched
/// function has risen from zero (a crossing in and out within it would leave no sign change).
const AFTER_JUMP_PARTS: usize = 8;
/// `auto` integrates with ESDIRK34 rather than Tsit45 when the forcing lasts at least this many
/// fastest periods: the response is then smooth on the fast time scale and an L-stable
/// implicit method takes long steps. A step keeps the modes ringing (quadratic drag damps
/// small oscillations slowly), every period must be resolved, and Tsit45 is cheaper per step
/// (measured on the bridge: 4× fewer steps than ESDIRK34 at the same tolerance). BDF is
/// offered too, but its Newton iterations fail at rtol ≤ 1e-8 on the ramp.
pub const IMPLICIT_RATIO: f64 = 100.0;

/// diffsol's integrators; `Auto` picks Tsit45 for short runs and ESDIRK34 for long (stiff) ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Chosen from the time scales.
    Auto,
    /// Variable-order BDF.
    Bdf,
    /// The L-stable ESDIRK34 Runge–Kutta method.
    Esdirk34,
    /// TR-BDF2.
    #[serde(alias = "tr_bdf2")]
    TrBdf2,
    /// Tsitouras 5(4), explicit.
    Tsit45,
}

impl Method {
    /// `Auto` resolved by the time-scale ratio (see `IMPLICIT_RATIO`).
    pub fn resolve(self, scales: &TimeScales) -> Method {
        match self {
            Method::Auto if scales.ratio >= IMPLICIT_RATIO => Method::Esdirk34,
            Method::Auto => Method::Tsit45,
            other => other,
        }
    }
}

/// `samples` evenly spaced times from 0 to `t_end` (at least two).
pub fn output_times(t_end: f64, samples: usize) -> Vec<f64> {
    let samples = samples.max(2);
    (0..samples).map(|k| t_end * k as f64 / (samples - 1) as f64).collect()
}

/// Receives the progress of a run: the fraction of its time span done (0..=1) and the time
/// reached, s. Called once per accepted integrator step.
#[derive(Clone)]
pub struct ProgressObserver(pub std::sync::Arc<dyn Fn(f64, f64) + Send + Sync>);

impl std::fmt::Debug for ProgressObserver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressObserver")
    }
}

/// Step samples recorded at each stride before the stride doubles.
const STEP_SAMPLE_CHUNK: usize = 10_000;

/// How one diffsol run is driven.
#[derive(Debug, Clone)]
pub struct IntegrationOptions {
    /// Relative tolerance; the absolute tolerance is the same number in rad (and rad per
    /// scaled time).
    pub rtol: f64,
    /// Told of every accepted step.
    pub progress: Option<ProgressObserver>,
    /// Record a sample at every accepted step besides the output times.
    pub record_steps: bool,
    /// A run needing more steps stops with [`NumericalError::StepBudget`].
    pub max_steps: usize,
}

/// Result of one diffsol run.
#[derive(Debug, Clone)]
pub struct DynamicRun {
    /// Output samples (and every accepted step when asked).
    pub samples: Vec<Sample>,
    /// The first contact, where the run stopped.
    pub collision: Option<Collision>,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: usize,
}

/// Integrates a plant from rest at its initial coordinates: for an open chain
/// M θ̈ + C θ̇ + K θ = τ(t) + Q_drag.
pub fn integrate<P: Plant>(
    plant: &P,
    method: Method,
    output_times: &[f64],
    options: IntegrationOptions,
) -> Result<DynamicRun> {
    let IntegrationOptions {
        rtol,
        progress,
        record_steps,
        max_steps,
    } = options;
    let n = plant.dof();
    let accumulators = plant.accumulators();
    let size = 2 * n + accumulators;
    let energy_scale = plant.energy_scale();
    let time_unit = 1.0 / plant.slowest_omega()?;
    let initial = plant.initial_state()?;
    let evaluations = Cell::new(0usize);
    let failure: RefCell<Option<NanofoldError>> = RefCell::new(None);
    let workspace = RefCell::new((plant.workspace(), vec![0.0; n], vec![0.0; n], vec![0.0; accumulators]));
    let rhs = |y: &[f64], s: f64, dy: &mut [f64]| {
        evaluations.set(evaluations.get() + 1);
        let mut guard = workspace.borrow_mut();
        let (ws, rates, accel, powers) = &mut *guard;
        let (angles, scaled_rates) = (&y[..n], &y[n..2 * n]);
        for (r, v) in rates.iter_mut().zip(scaled_rates) {
            *r = v / time_unit;
        }
        if let Err(e) = plant.accelerations(s * time_unit, angles, rates, ws, accel) {
            failure.borrow_mut().get_or_insert(e);
            dy.iter_mut().for_each(|d| *d = f64::NAN);
            return;
        }
        dy[..n].copy_from_slice(scaled_rates);
        for (d, a) in dy[n..2 * n].iter_mut().zip(accel.iter()) {
            *d = a * time_unit * time_unit;
        }
        if accumulators > 0 {
            plant.accumulator_rates(ws, powers);
            for (d, p) in dy[2 * n..].iter_mut().zip(powers.iter()) {
                *d = p * time_unit / energy_scale;
            }
        }
    };
    // Jacobian-vector products by central differences (diffsol assembles J from them).
    let shifted = RefCell::new((vec![0.0; size], vec![0.0; size], vec![0.0; size]));
    let jacobian_times = |y: &[f64], s: f64, v: &[f64], jv: &mut [f64]| {
        let mut guard = shifted.borrow_mut();
        let (y_shift, f_plus, f_minus) = &mut *guard;
        let v_norm = v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        if v_norm == 0.0 {
            jv.iter_mut().for_each(|x| *x = 0.0);
            return;
        }
        let y_norm = y.iter().fold(1.0_f64, |a, b| a.max(b.abs()));
        let h = f64::EPSILON.cbrt() * y_norm / v_norm;
        for sign in [1.0, -1.0] {
            for ((ys, yi), vi) in y_shift.iter_mut().zip(y).zip(v) {
                *ys = yi + sign * h * vi;
            }
            rhs(y_shift, s, if sign > 0.0 { f_plus } else { f_minus });
        }
        for ((j, p), m) in jv.iter_mut().zip(f_plus.iter()).zip(f_minus.iter()) {
            *j = (p - m) / (2.0 * h);
        }
    };
    let t0 = initial.time / time_unit;
    let mut problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .t0(t0)
        .rtol(rtol)
        .atol(vec![rtol; size])
        .rhs_implicit(
            |y: &[f64], _p: &[f64], s: f64, dy: &mut [f64]| rhs(y, s, dy),
            |y: &[f64], _p: &[f64], s: f64, v: &[f64], jv: &mut [f64]| jacobian_times(y, s, v, jv),
        )
        .init(
            |_p: &[f64], _t: f64, y: &mut [f64]| {
                y[..n].copy_from_slice(&initial.coordinates);
                for (v, r) in y[n..2 * n].iter_mut().zip(&initial.rates) {
                    *v = r * time_unit;
                }
                for (v, e) in y[2 * n..].iter_mut().zip(&initial.accumulated) {
                    *v = e / energy_scale;
                }
            },
            size,
        )
        .build()?;
    // diffsol counts Newton failures over the whole run, not per step: a long run with rare,
    // harmless failures (each retried with a new Jacobian or a smaller step) would abort.
    // The minimum step size still stops a run that genuinely cannot proceed.
    problem.ode_options.max_nonlinear_solver_failures = usize::MAX / 2;
    let s_end = output_times.last().copied().unwrap_or(0.0) / time_unit;
    let driver = Driver {
        plant,
        output_times,
        time_unit,
        energy_scale,
        rhs: &rhs,
        start: &initial,
        s_end,
        progress: progress.as_ref(),
        record_steps,
        method,
        max_steps,
    };
    let result = match method {
        Method::Bdf | Method::Auto => driver.run(problem.bdf::<NalgebraLU<f64>>()?),
        Method::Esdirk34 => driver.run(problem.esdirk34::<NalgebraLU<f64>>()?),
        Method::TrBdf2 => driver.run(problem.tr_bdf2::<NalgebraLU<f64>>()?),
        Method::Tsit45 => driver.run(problem.tsit45()?),
    };
    if let Some(e) = failure.borrow_mut().take() {
        return Err(e);
    }
    let (samples, collision, steps, _) = result?;
    Ok(DynamicRun {
        samples,
        collision,
        steps,
        rhs_evaluations: evaluations.get(),
    })
}

/// The right-hand side in scaled time: (y, s, dy/ds).
type Rhs<'r> = dyn Fn(&[f64], f64, &mut [f64]) + 'r;

/// Steps a diffsol solver to the end or the first contact, sampling the dense output.
struct Driver<'r, P: Plant> {
    plant: &'r P,
    output_times: &'r [f64],
    time_unit: f64,
    /// J per unit of an accumulator in the state.
    energy_scale: f64,
    /// The right-hand side in scaled time, to refresh dy/ds after a projection.
    rhs: &'r Rhs<'r>,
    /// Where the run starts.
    start: &'r super::plant::InitialState,
    s_end: f64,
    progress: Option<&'r ProgressObserver>,
    /// Record a sample at every accepted step besides the output times.
    record_steps: bool,
    /// For error messages.
    method: Method,
    max_steps: usize,
}

impl<P: Plant> Driver<'_, P> {
    /// The earliest crossing of a located switching function within (s_before, s_now) on the
    /// step's dense output, by bisection to rounding: (the first scaled time past it, the
    /// functions crossing there).
    #[allow(clippy::type_complexity)]
    fn first_switch<'a, Eqn, S>(
        &self,
        solver: &S,
        (s_before, s_now): (f64, f64),
        (before, now): (&[f64], &[f64]),
        (state, angles, rates, accumulated): (&mut NalgebraVec<f64>, &mut [f64], &mut [f64], &mut [f64]),
        scratch: &mut [f64],
        ws: &mut P::Workspace,
    ) -> Result<Option<(f64, Vec<usize>)>>
    where
        Eqn: OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let n = self.plant.dof();
        // Every function that changes sign in the step, bracketed together: each evaluation
        // gives all of them, and the bracket closes on the earliest crossing.
        let mut crossing: Vec<(usize, f64, f64, f64)> = (0..before.len())
            .filter(|&k| before[k] > 0.0 && now[k] < 0.0)
            .map(|k| {
                let side = before[k].signum();
                (k, side, before[k] * side, now[k] * side)
            })
            .collect();
        if crossing.is_empty() {
            return Ok(None);
        }
        // Regula falsi with the Illinois modification (an end kept twice has its values
        // halved), to rounding: far fewer evaluations than bisection's fifty. (Stopping at
        // 1e-13 of the step instead moved the Miura-ori sheet's sensitivities by 1e-6.)
        let (mut lo, mut hi) = (s_before, s_now);
        let mut kept = 0_i8;
        loop {
            let secant = crossing
                .iter()
                .map(|&(_, _, f_lo, f_hi)| (lo * f_hi - hi * f_lo) / (f_hi - f_lo))
                .fold(f64::INFINITY, f64::min);
            let mid = if secant > lo && secant < hi && secant.is_finite() {
                secant
            } else {
                0.5 * (lo + hi)
            };
            if mid <= lo || mid >= hi {
                break;
            }
            solver.interpolate_inplace(mid, state)?;
            for i in 0..n {
                angles[i] = state[i];
                rates[i] = state[n + i] / self.time_unit;
            }
            accumulated.iter_mut().for_each(|a| *a = 0.0);
            self.plant
                .switch_values(mid * self.time_unit, angles, rates, ws, scratch)?;
            if crossing.iter().any(|&(k, side, _, _)| scratch[k] * side <= 0.0) {
                // Something crosses by mid: the earliest is before it; those that have not
                // crossed yet cross later, found again after the jump.
                hi = mid;
                crossing.retain(|&(k, side, _, _)| scratch[k] * side <= 0.0);
                for entry in &mut crossing {
                    entry.3 = scratch[entry.0] * entry.1;
                    if kept == 1 {
                        entry.2 *= 0.5;
                    }
                }
                kept = 1;
            } else {
                lo = mid;
                for entry in &mut crossing {
                    entry.2 = scratch[entry.0] * entry.1;
                    if kept == -1 {
                        entry.3 *= 0.5;
                    }
                }
                kept = -1;
            }
        }
        Ok(Some((hi, crossing.into_iter().map(|(k, ..)| k).collect())))
    }

    fn run<'a, Eqn, S>(&self, mut solver: S) -> Result<(Vec<Sample>, Option<Collision>, usize, usize)>
    where
        Eqn: OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let plant = self.plant;
        let n = plant.dof();
        let accumulators = plant.accumulators();
        let size = 2 * n + accumulators;
        let mut ws = plant.workspace();
        let mut samples = Vec::with_capacity(self.output_times.len());
        let mut state = solver.state().y.clone();
        let mut angles = vec![0.0; n];
        let mut rates = vec![0.0; n];
        let mut accumulated = vec![0.0; accumulators];
        let split = |y: &NalgebraVec<f64>, angles: &mut [f64], rates: &mut [f64], accumulated: &mut [f64]| {
            for i in 0..n {
                angles[i] = y[i];
                rates[i] = y[n + i] / self.time_unit;
            }
            for (k, a) in accumulated.iter_mut().enumerate() {
                *a = y[2 * n + k] * self.energy_scale;
            }
        };
        // At rest at t = 0; a plant that starts later (leaving a singular start) is sampled
        // there too, from its own record of the way.
        let t_start = self.start.time;
        split(&state, &mut angles, &mut rates, &mut accumulated);
        if t_start > 0.0 {
            let at_rest = vec![0.0; n];
            let zero = vec![0.0; accumulators];
            samples.push(plant.sample(0.0, &plant.initial_coordinates(), &at_rest, &zero, &mut ws)?);
        }
        samples.push(plant.sample(t_start, &angles, &rates, &accumulated, &mut ws)?);
        let mut next_output = self.output_times.partition_point(|&t| t <= t_start).max(1);
        let mut gaps = Vec::new();
        let mut gaps_scratch = Vec::new();
        let contact_count = plant.contact_count();
        if contact_count > 0 {
            if let Some(c) = plant.touching(0.0, &angles, &mut ws) {
                return Ok((samples, Some(c), 0, 0));
            }
            gaps = vec![0.0; contact_count];
            gaps_scratch = vec![0.0; contact_count];
            let start = angles.clone();
            let mut at_start = |_: f64, out: &mut [f64]| out.copy_from_slice(&start);
            let mut probe = plant.probe(&mut ws, &mut angles, &mut at_start);
            gaps_at(probe.as_mut(), 0.0, &mut gaps);
        }
        // Located switching functions (a sensitivity plant's): their values at the last
        // accepted state, to catch each sign change and jump there.
        let switch_count = plant.located_switches();
        let mut switches_before = vec![0.0; switch_count];
        let mut switches_now = vec![0.0; switch_count];
        let mut switches_scratch = vec![0.0; switch_count];
        let mut just_switched: Vec<usize> = Vec::new();
        if switch_count > 0 {
            plant.switch_values(t_start, &angles, &rates, &mut ws, &mut switches_before)?;
        }
        // Stop exactly at each kink of the forcing (a ramp reaching its target), so no step
        // straddles it, then at the end.
        let mut stops: Vec<f64> = self
            .plant
            .forcing()
            .breakpoints()
            .into_iter()
            .map(|t| t / self.time_unit)
            .filter(|&s| s > t_start / self.time_unit && s < self.s_end)
            .collect();
        stops.push(self.s_end);
        let mut next_stop = 0;
        solver.set_stop_time(stops[0])?;
        let mut steps = 0;
        let mut s_previous = t_start / self.time_unit;
        // Σ|dθ/ds| at the previous step's end, for the contact reach bound.
        let speed_sum = |y: &NalgebraVec<f64>| (n..2 * n).map(|i| y[i].abs()).sum::<f64>();
        let mut previous_speed: f64 = 0.0;
        let lever = plant.contact_lever();
        let (mut step_stride, mut step_samples) = (1usize, 0usize);
        loop {
            let reason = match solver.step() {
                Ok(reason) => reason,
                Err(source) => {
                    return Err(NumericalError::OdeStep {
                        method: format!("{:?}", self.method),
                        reached_s: solver.state().t * self.time_unit,
                        end_s: self.s_end * self.time_unit,
                        time_unit: self.time_unit,
                        source,
                    }
                    .into())
                }
            };
            steps += 1;
            let s_now = solver.state().t;
            if !s_now.is_finite() || (0..size).any(|i| !solver.state().y[i].is_finite()) {
                return Err(NumericalError::NonFinite {
                    what: "ODE integration",
                    detail: format!(
                        "the state became NaN or infinite after {steps} steps, near t = {:.6e} s: check the scene's magnitudes",
                        s_previous * self.time_unit
                    ),
                }
                .into());
            }
            let newton_failures = solver.get_statistics().number_of_nonlinear_solver_fails;
            if steps >= self.max_steps && s_now < self.s_end {
                return Err(NumericalError::StepBudget {
                    method: format!("{:?}", self.method),
                    steps,
                    reached_s: s_now * self.time_unit,
                    end_s: self.s_end * self.time_unit,
                    projected: steps as f64 * (self.s_end - s_now) / s_now.max(f64::MIN_POSITIVE),
                }
                .into());
            }
            if newton_failures > NEWTON_FAILURE_FLOOR && 2 * newton_failures > steps {
                return Err(NumericalError::NewtonFailures {
                    method: format!("{:?}", self.method),
                    failures: newton_failures,
                    steps,
                    reached_s: s_now * self.time_unit,
                }
                .into());
            }
            let current_speed = speed_sum(solver.state().y);
            let mut collision = None;
            if contact_count > 0 {
                // Two corners approach each other at most 2 × lever × Σ|θ̇| (with θ̇ between its
                // values at the step's ends, ×2 for safety as it varies within the step).
                let reach = 4.0 * lever * (s_now - s_previous) * previous_speed.max(current_speed);
                let mut path = |t: f64, out: &mut [f64]| {
                    if solver.interpolate_inplace(t, &mut state).is_ok() {
                        for (i, o) in out.iter_mut().enumerate() {
                            *o = state[i];
                        }
                    }
                };
                let mut probe = plant.probe(&mut ws, &mut angles, &mut path);
                collision = locate(
                    probe.as_mut(),
                    s_previous,
                    s_now,
                    reach,
                    CONTACT_SUBDIVISIONS,
                    &mut gaps,
                    &mut gaps_scratch,
                )
                .map(|mut c| {
                    c.time *= self.time_unit;
                    c
                });
            }
            let mut switch = None;
            if switch_count > 0 {
                solver.interpolate_inplace(s_now, &mut state)?;
                split(&state, &mut angles, &mut rates, &mut accumulated);
                plant.switch_values(s_now * self.time_unit, &angles, &rates, &mut ws, &mut switches_now)?;
                // A function just switched starts this step at zero, so its sign there cannot
                // show a crossing within the step: the step is split where it is positive.
                let (mut s_from, mut s_to) = (s_previous, s_now);
                let mut interior = None;
                if just_switched
                    .iter()
                    .any(|&k| switches_before[k] <= 0.0 && switches_now[k] < 0.0)
                {
                    for part in 1..AFTER_JUMP_PARTS {
                        let s = s_previous + (s_now - s_previous) * part as f64 / AFTER_JUMP_PARTS as f64;
                        solver.interpolate_inplace(s, &mut state)?;
                        split(&state, &mut angles, &mut rates, &mut accumulated);
                        plant.switch_values(s * self.time_unit, &angles, &rates, &mut ws, &mut switches_scratch)?;
                        if just_switched.iter().any(|&k| switches_scratch[k] > 0.0) {
                            interior = Some(s);
                            break;
                        }
                    }
                }
                let mut at_interior = Vec::new();
                if let Some(s) = interior {
                    at_interior.clone_from(&switches_scratch);
                    if (0..switch_count).any(|k| switches_before[k] > 0.0 && at_interior[k] < 0.0) {
                        s_to = s;
                    } else {
                        s_from = s;
                    }
                }
                let (values_from, values_to) = match interior {
                    Some(s) if s == s_to => (&switches_before, &at_interior),
                    Some(_) => (&at_interior, &switches_now),
                    None => (&switches_before, &switches_now),
                };
                switch = self.first_switch(
                    &solver,
                    (s_from, s_to),
                    (values_from, values_to),
                    (&mut state, &mut angles, &mut rates, &mut accumulated),
                    &mut switches_scratch,
                    &mut ws,
                )?;
                just_switched.clear();
                // A contact after the switch is found again after the jump.
                if let (Some((s_switch, _)), Some(c)) = (&switch, &collision) {
                    if *s_switch < c.time / self.time_unit {
                        collision = None;
                    }
                }
            }
            let s_stop = match (&collision, &switch) {
                (Some(c), _) => c.time / self.time_unit,
                (None, Some((s_switch, _))) => *s_switch,
                (None, None) => s_now,
            };
            while next_output < self.output_times.len() && self.output_times[next_output] / self.time_unit <= s_stop {
                let s = (self.output_times[next_output] / self.time_unit).min(s_now);
                solver.interpolate_inplace(s, &mut state)?;
                split(&state, &mut angles, &mut rates, &mut accumulated);
                samples.push(plant.sample(self.output_times[next_output], &angles, &rates, &accumulated, &mut ws)?);
                next_output += 1;
            }
            if let Some(c) = collision {
                solver.interpolate_inplace(c.time / self.time_unit, &mut state)?;
                split(&state, &mut angles, &mut rates, &mut accumulated);
                samples.push(plant.sample(c.time, &angles, &rates, &accumulated, &mut ws)?);
                return Ok((
                    samples,
                    Some(c),
                    steps,
                    solver.get_statistics().number_of_nonlinear_solver_fails,
                ));
            }
            if let Some((s_switch, switched)) = switch {
                just_switched.clone_from(&switched);
                // Back to the crossing, the jump applied, and on from there.
                solver.state_mut_back(s_switch)?;
                let y = solver.state().y.clone();
                split(&y, &mut angles, &mut rates, &mut accumulated);
                plant.jump(s_switch * self.time_unit, &mut angles, &mut rates, &switched, &mut ws)?;
                let mut fresh = y.clone();
                for i in 0..n {
                    fresh[i] = angles[i];
                    fresh[n + i] = rates[i] * self.time_unit;
                }
                let mut derivative = solver.state().dy.clone();
                (self.rhs)(fresh.batch_as_slice(0), s_switch, derivative.batch_as_mut_slice(0));
                let state_mut = solver.state_mut();
                state_mut.y.copy_from(&fresh);
                state_mut.dy.copy_from(&derivative);
                plant.switch_values(
                    s_switch * self.time_unit,
                    &angles,
                    &rates,
                    &mut ws,
                    &mut switches_before,
                )?;
                // Zero at the crossing, up to rounding whose sign means nothing.
                for &k in &just_switched {
                    switches_before[k] = 0.0;
                }
                s_previous = s_switch;
                previous_speed = speed_sum(solver.state().y);
                continue;
            }
            // Every accepted step too: the steps resolve the fastest mode, a fixed grid may alias
            // it. A long run thins them (the stride doubles every STEP_SAMPLE_CHUNK samples), so
            // memory grows with the logarithm of the steps, not the steps.
            let s_now_time = s_now * self.time_unit;
            if self.record_steps && steps % step_stride == 0 && samples.last().is_none_or(|last| last.time < s_now_time)
            {
                solver.interpolate_inplace(s_now, &mut state)?;
                split(&state, &mut angles, &mut rates, &mut accumulated);
                samples.push(plant.sample(s_now_time, &angles, &rates, &accumulated, &mut ws)?);
                step_samples += 1;
                if step_samples % STEP_SAMPLE_CHUNK == 0 {
                    step_stride *= 2;
                }
            }
            if let Some(progress) = self.progress {
                (progress.0)(s_now / self.s_end, s_now * self.time_unit);
            }
            if s_now >= self.s_end {
                break;
            }
            // Back onto the plant's constraints (a network's closures); the solver continues
            // from the projected state with its derivative evaluated there.
            {
                let y = solver.state().y.clone();
                split(&y, &mut angles, &mut rates, &mut accumulated);
                if plant.project(s_now_time, &mut angles, &mut rates, &mut ws)? {
                    let mut fresh = y.clone();
                    for i in 0..n {
                        fresh[i] = angles[i];
                        fresh[n + i] = rates[i] * self.time_unit;
                    }
                    let mut derivative = solver.state().dy.clone();
                    (self.rhs)(fresh.batch_as_slice(0), s_now, derivative.batch_as_mut_slice(0));
                    let state_mut = solver.state_mut();
                    state_mut.y.copy_from(&fresh);
                    state_mut.dy.copy_from(&derivative);
                }
            }
            if switch_count > 0 {
                // At the step's end as the plant now holds it (projected, its sides updated).
                let y = solver.state().y.clone();
                split(&y, &mut angles, &mut rates, &mut accumulated);
                plant.switch_values(s_now_time, &angles, &rates, &mut ws, &mut switches_before)?;
            }
            if matches!(reason, OdeSolverStopReason::TstopReached) {
                next_stop += 1;
                match stops.get(next_stop) {
                    Some(&stop) => solver.set_stop_time(stop)?,
                    None => break,
                }
            }
            s_previous = s_now;
            previous_speed = current_speed;
        }
        Ok((
            samples,
            None,
            steps,
            solver.get_statistics().number_of_nonlinear_solver_fails,
        ))
    }
}
