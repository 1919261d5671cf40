//! Forward sensitivities of a scene's trajectory to its parameters
//! (`docs/model.md#calibration`): the variational equations S̈ = ∂a/∂q S + ∂a/∂q̇ Ṡ + ∂a/∂u
//! integrated with the motion under one error control, for any plant.
//!
//! The caller hands the scene at the parameters u and at u ± ε eⱼ for each parameter j (one
//! scene per perturbation, built from the scene file, so any number the file holds can be a
//! parameter). Each column's right-hand side is two central differences (f₊ − f₋)/2h: along
//! the state, ∂a/∂q Sⱼ + ∂a/∂q̇ Ṡⱼ from the base plant at (q ± hSⱼ, q̇ ± hṠⱼ) with h sized so
//! the shift is [`STATE_SHIFT`] rad whatever |Sⱼ| is; along the parameter, ∂a/∂uⱼ from the
//! perturbed plants at (q, q̇). With the drag's sides held the right-hand side is smooth, so
//! steps of 1e-4 leave a truncation error near 1e-9 while rounding in a (a stiff strip's
//! accelerations carry ~1e-14 of it) adds 1e-10. The adaptive integrator never
//! differentiates its own step choices, so the columns are as accurate as the motion.

use super::closed::{ClosedChain, ClosedPlant};
use super::contact::{Collision, ContactProbe};
use super::forcing::Forcing;
use super::integrate::{integrate, IntegrationOptions, Method};
use super::network::{NetworkModel, NetworkPlant, ReducedPlant};
use super::plant::{InitialState, Plant, Sample, TimeScales};
use super::scene::{Scene, System};
use super::strip::{StripChain, StripPlant};
use crate::error::{NanofoldError, Result};
use nalgebra::{DMatrix, DVector};
use sides::{held_accelerations, Side, SideScratch};

mod balanced;
mod released;
mod sides;

/// The motion and its sensitivities at the requested times.
#[derive(Debug, Clone)]
pub struct TrajectorySensitivity {
    /// The output times, s (those the run reached).
    pub times: Vec<f64>,
    /// Every output angle (each hinge's, each crease's) at each time, rad.
    pub angles: Vec<DVector<f64>>,
    /// ∂angles/∂uⱼ at each time: one row per output angle, one column per parameter, rad per
    /// unit of the parameter's scaled coordinate u.
    pub sensitivities: Vec<DMatrix<f64>>,
    /// Accepted integrator steps.
    pub steps: usize,
}

/// How many perturbed scenes each parameter has.
pub const POINTS: usize = 2;
/// The offsets, in steps ε, of each parameter's perturbed scenes.
pub const STENCIL: [f64; POINTS] = [-1.0, 1.0];
/// The central difference's weights at the [`STENCIL`] offsets.
const WEIGHTS: [f64; POINTS] = [-0.5, 0.5];
/// The largest shift of an angle (rad) or a rate (rad per unit of scaled time) in the
/// differences along the state.
pub const STATE_SHIFT: f64 = 1e-4;
/// The state and the parameter are differenced together while ε(Sⱼ, Ṡⱼ) shifts no angle or
/// rate by more than this many [`STATE_SHIFT`]s.
const TOGETHER_RATIO: f64 = 2.0;

/// Whether a run's sample at `time` is one of the asked times still ahead in `requested`
/// (ascending), passing over those the run skipped.
fn asked(requested: &mut std::iter::Peekable<std::slice::Iter<'_, f64>>, time: f64) -> bool {
    while requested.next_if(|&&t| t < time).is_some() {}
    requested.next_if(|&&t| t == time).is_some()
}

/// The central difference from values at the [`STENCIL`] offsets.
fn stencil(values: [f64; POINTS], epsilon: f64) -> f64 {
    values.iter().zip(WEIGHTS).map(|(v, w)| v * w).sum::<f64>() / epsilon
}

/// Integrates `base` and the sensitivity of its output angles to each parameter whose
/// perturbed scenes (at u + kε, k in [`STENCIL`]) are `perturbed[j]`, from the start to the last of
/// `times` (increasing, the first ≥ 0), without contacts, by `method` (`Auto`: from the
/// time scales) at relative tolerance `rtol`. A scene released slowly (its forcing lasts
/// ≥ [`super::simulate::QUASI_STATIC_RATIO`] fastest periods) takes the quasi-static path
/// as `simulate` does, and its sensitivities come from its balance (`method` and `rtol` do
/// not apply): a tree of panels through the contact engine's contacts and seams, by the
/// balance's KKT conditions (`released`); a strip, a closed chain or fitted curves to their
/// first contact (`balanced`). A pattern with loops of its own is refused.
pub fn trajectory_sensitivities(
    base: &Scene,
    perturbed: &[[Scene; POINTS]],
    epsilon: f64,
    times: &[f64],
    method: Method,
    rtol: f64,
) -> Result<TrajectorySensitivity> {
    if !(epsilon.is_finite() && epsilon > 0.0) {
        return Err(NanofoldError::invalid("epsilon", epsilon, "must be a finite step > 0"));
    }
    let mismatch = |j: usize| {
        NanofoldError::invalid(
            format!("perturbed[{j}]"),
            "a scene of another kind or size",
            "a parameter may change numbers of a scene, not what it simulates",
        )
    };
    macro_rules! pairs {
        ($kind:ident, $make:expr) => {{
            let mut plants = Vec::with_capacity(perturbed.len());
            for (j, scenes) in perturbed.iter().enumerate() {
                let mut pair = Vec::with_capacity(POINTS);
                for scene in scenes {
                    match &scene.system {
                        System::$kind(inner) => pair.push($make(inner)?),
                        _ => return Err(mismatch(j)),
                    }
                }
                let pair: [_; POINTS] = pair.try_into().map_err(|_| mismatch(j))?;
                plants.push(pair);
            }
            plants
        }};
    }
    match &base.system {
        System::Strip(chain) => {
            let plants = pairs!(Strip, strip_plant);
            run(&strip_plant(chain)?, &plants, epsilon, times, (method, rtol, true))
        }
        System::Closed(chain) => {
            let plants = pairs!(Closed, closed_plant);
            run(&closed_plant(chain)?, &plants, epsilon, times, (method, rtol, true))
        }
        System::Network(model) if model.reduction.is_some() => {
            let plants = pairs!(Network, reduced_plant);
            run(&reduced_plant(model)?, &plants, epsilon, times, (method, rtol, true))
        }
        System::Network(model) if network_plant(model)?.time_scales()?.ratio >= super::simulate::QUASI_STATIC_RATIO => {
            // A slow release: the balance's own sensitivities along the engine's path.
            if model.friction_coefficient > 0.0 {
                return Err(NanofoldError::invalid(
                    "friction_coefficient",
                    model.friction_coefficient,
                    "a slow release's sensitivities come from its frictionless balance: with friction its state depends on the path, whose derivatives are not built",
                ));
            }
            if !model.folding.stars.is_empty() {
                return Err(NanofoldError::invalid(
                    "actuation",
                    "a slow release",
                    "the pattern closes loops of its own: the sensitivities of its balance on its closures are not built (fit a step response, or its fitted curves)",
                ));
            }
            if super::simulate::first_contact_only(model).is_some() {
                // Not for the contact engine (substrate contact, a crease driven flat): the
                // quasi-static path to its first contact, as `simulate` runs it.
                let plants = pairs!(Network, network_plant);
                return run(&network_plant(model)?, &plants, epsilon, times, (method, rtol, true));
            }
            let mut models = Vec::with_capacity(perturbed.len());
            for (j, scenes) in perturbed.iter().enumerate() {
                match (&scenes[0].system, &scenes[1].system) {
                    (System::Network(minus), System::Network(plus)) => models.push([&**minus, &**plus]),
                    _ => return Err(mismatch(j)),
                }
            }
            released::released_sensitivities(model, &models, epsilon, times)
        }
        System::Network(model) => {
            let plants = pairs!(Network, network_plant);
            run(&network_plant(model)?, &plants, epsilon, times, (method, rtol, true))
        }
    }
}

fn strip_plant(chain: &StripChain) -> Result<StripPlant<'_>> {
    Ok(StripPlant::new(chain, false))
}

fn closed_plant(chain: &ClosedChain) -> Result<ClosedPlant<'_>> {
    Ok(ClosedPlant::new(chain, false))
}

fn network_plant(model: &NetworkModel) -> Result<NetworkPlant<'_>> {
    NetworkPlant::new(model, false)
}

fn reduced_plant(model: &NetworkModel) -> Result<ReducedPlant<'_>> {
    match &model.reduction {
        Some(reduction) => ReducedPlant::new(model, reduction, false),
        None => Err(NanofoldError::invalid(
            "reduction",
            "none",
            "a parameter may change numbers of a scene, not whether its motion is reduced",
        )),
    }
}

fn run<P: Plant>(
    base: &P,
    perturbed: &[[P; POINTS]],
    epsilon: f64,
    times: &[f64],
    (method, rtol, locate): (Method, f64, bool),
) -> Result<TrajectorySensitivity> {
    let plant = Augmented {
        base,
        perturbed,
        epsilon,
        locate,
        time_unit: 1.0 / base.slowest_omega()?,
        switch_count: base.switches(&base.workspace()).len(),
        mode: std::cell::RefCell::new(vec![Side::Free; base.switches(&base.workspace()).len()]),
        initial: std::cell::OnceCell::new(),
    };
    let mut grid = Vec::with_capacity(times.len() + 1);
    if times.first().is_none_or(|&t| t > 0.0) {
        grid.push(0.0);
    }
    grid.extend_from_slice(times);
    let scales = base.time_scales()?;
    if scales.ratio >= super::simulate::QUASI_STATIC_RATIO {
        // A slow forcing: the quasi-static path, its sensitivities from its balance.
        return balanced::balanced_sensitivities(base, perturbed, epsilon, times);
    }
    let method = method.resolve(&scales);
    let options = IntegrationOptions {
        rtol,
        progress: None,
        record_steps: false,
        max_steps: 5_000_000,
    };
    let run = integrate(&plant, method, &grid, options)?;
    let (n, m) = (plant.outputs(), perturbed.len());
    let mut result = TrajectorySensitivity {
        times: Vec::with_capacity(times.len()),
        angles: Vec::with_capacity(times.len()),
        sensitivities: Vec::with_capacity(times.len()),
        steps: run.steps,
    };
    let mut requested = times.iter().peekable();
    for sample in &run.samples {
        if !asked(&mut requested, sample.time) {
            continue;
        }
        result.times.push(sample.time);
        result.angles.push(sample.angles.rows(0, n).into_owned());
        result
            .sensitivities
            .push(DMatrix::from_fn(n, m, |i, j| sample.angles[n * (1 + j) + i]));
    }
    Ok(result)
}

/// The plant of the motion and its m sensitivity columns: coordinates (q, S₁ … Sₘ).
struct Augmented<'p, P: Plant> {
    base: &'p P,
    perturbed: &'p [[P; POINTS]],
    epsilon: f64,
    /// Whether the drag's switches are located (and the columns jump there).
    locate: bool,
    /// 1/ω_slow, s: rates times it are rad per unit of scaled time.
    time_unit: f64,
    /// The base plant's drag switches.
    switch_count: usize,
    /// The drag's side on each plate (`sides`): locked between located switches, or
    /// sliding; the motion's right-hand side is then smooth within every step, and each
    /// switch is taken where it is crossed.
    mode: std::cell::RefCell<Vec<Side>>,
    /// The start, found once.
    initial: std::cell::OnceCell<InitialState>,
}

/// Scratch of the augmented plant: the base's and each perturbed plant's.
struct AugmentedWorkspace<W> {
    base: W,
    perturbed: Vec<[W; POINTS]>,
    shifted_q: Vec<f64>,
    shifted_rates: Vec<f64>,
    /// The accelerations at the stencil's offsets.
    stencil: [Vec<f64>; POINTS],
    /// The signs of the free plates' drag at the motion's state, held while differencing.
    free_signs: Vec<f64>,
    /// Scratch of the held evaluations.
    scratch: SideScratch,
    /// The base's held accelerations, and a direction.
    after: Vec<f64>,
    direction: Vec<f64>,
}

impl<P: Plant> Augmented<'_, P> {
    fn columns(&self) -> usize {
        self.perturbed.len()
    }

    /// Output angles per sample of the base plant.
    fn outputs(&self) -> usize {
        let mut ws = self.base.workspace();
        let q = self.base.initial_coordinates();
        let rates = vec![0.0; q.len()];
        self.base
            .sample(0.0, &q, &rates, &[], &mut ws)
            .map_or(0, |s| s.angles.len())
    }

    /// Each column moved onto the tangent of the plant's constraints at the projected
    /// state, as the motion is moved onto them: the difference of the plant's own projection
    /// along the column (a network's closures hold for every parameter, so ∂q/∂u is tangent
    /// to them, and the rates' columns satisfy the differentiated closures; unprojected,
    /// the columns drift off as the motion would).
    fn project_columns(
        &self,
        t: f64,
        q: &mut [f64],
        q_dot: &mut [f64],
        ws: &mut AugmentedWorkspace<P::Workspace>,
    ) -> Result<()> {
        let n = self.base.dof();
        let mut angles: [Vec<f64>; POINTS] = std::array::from_fn(|_| vec![0.0; n]);
        let mut rates: [Vec<f64>; POINTS] = std::array::from_fn(|_| vec![0.0; n]);
        for j in 0..self.columns() {
            let Some(h) = self.state_step(j, q_dot, q) else {
                continue;
            };
            for (k, offset) in STENCIL.iter().enumerate() {
                self.shift(j, offset * h, q, q_dot, &mut angles[k], &mut rates[k]);
                self.base.project(t, &mut angles[k], &mut rates[k], &mut ws.base)?;
            }
            for i in 0..n {
                q[n * (1 + j) + i] = stencil(std::array::from_fn(|k| angles[k][i]), h);
                q_dot[n * (1 + j) + i] = stencil(std::array::from_fn(|k| rates[k][i]), h);
            }
        }
        Ok(())
    }

    /// The base's accelerations (into `after`), speeds and equivalent signs (into the
    /// scratch) at (q, q̇) under the current sides.
    fn held_base(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut AugmentedWorkspace<P::Workspace>) -> Result<()> {
        let sides = self.mode.borrow();
        held_accelerations(
            self.base,
            &sides,
            None,
            t,
            q,
            q_dot,
            &mut ws.base,
            &mut ws.scratch,
            &mut ws.after,
        )
    }

    /// Each column's acceleration with the signs held: along the parameter, then the state.
    fn column_accelerations(
        &self,
        sides: &[Side],
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        ws: &mut AugmentedWorkspace<P::Workspace>,
        out: &mut [f64],
    ) -> Result<()> {
        let n = self.base.dof();
        for (j, pair) in self.perturbed.iter().enumerate() {
            // One difference along (Sⱼ, Ṡⱼ, eⱼ) together, on the perturbed plants at the state
            // shifted by ±ε(Sⱼ, Ṡⱼ), where that shift is small enough; else the parameter's
            // and the state's differences apart.
            let h = self.state_step(j, q_dot, q);
            let together = h.is_none_or(|h| self.epsilon <= TOGETHER_RATIO * h);
            for (k, plant) in pair.iter().enumerate() {
                let shift = if together { STENCIL[k] * self.epsilon } else { 0.0 };
                self.shift(j, shift, q, q_dot, &mut ws.shifted_q, &mut ws.shifted_rates);
                held_accelerations(
                    plant,
                    sides,
                    Some(&ws.free_signs),
                    t,
                    &ws.shifted_q,
                    &ws.shifted_rates,
                    &mut ws.perturbed[j][k],
                    &mut ws.scratch,
                    &mut ws.stencil[k],
                )?;
            }
            let column = &mut out[n * (1 + j)..n * (2 + j)];
            for (i, c) in column.iter_mut().enumerate() {
                *c = stencil(std::array::from_fn(|k| ws.stencil[k][i]), self.epsilon);
            }
            if together {
                continue;
            }
            if let Some(h) = h {
                for (k, offset) in STENCIL.iter().enumerate() {
                    self.shift(j, offset * h, q, q_dot, &mut ws.shifted_q, &mut ws.shifted_rates);
                    held_accelerations(
                        self.base,
                        sides,
                        Some(&ws.free_signs),
                        t,
                        &ws.shifted_q,
                        &ws.shifted_rates,
                        &mut ws.base,
                        &mut ws.scratch,
                        &mut ws.stencil[k],
                    )?;
                }
                for (i, c) in column.iter_mut().enumerate() {
                    *c += stencil(std::array::from_fn(|k| ws.stencil[k][i]), h);
                }
            }
        }
        Ok(())
    }

    /// ∇gᵢ·(dq, dq̇) at (q, q̇): the central difference of drag switch i of the base.
    fn switch_derivative(
        &self,
        t: f64,
        i: usize,
        (q, q_dot): (&[f64], &[f64]),
        (dq, dq_dot): (&[f64], &[f64]),
        ws: &mut AugmentedWorkspace<P::Workspace>,
    ) -> Result<f64> {
        let size = dq
            .iter()
            .map(|x| x.abs())
            .chain(dq_dot.iter().map(|x| x.abs() * self.time_unit))
            .fold(0.0, f64::max);
        if !(size > 0.0 && size.is_finite()) {
            return Ok(0.0);
        }
        let h = STATE_SHIFT / size;
        let mut values = [0.0; POINTS];
        for (k, offset) in STENCIL.iter().enumerate() {
            for r in 0..q.len() {
                ws.shifted_q[r] = q[r] + offset * h * dq[r];
                ws.shifted_rates[r] = q_dot[r] + offset * h * dq_dot[r];
            }
            self.base
                .accelerations(t, &ws.shifted_q, &ws.shifted_rates, &mut ws.base, &mut ws.stencil[k])?;
            values[k] = self.base.switches(&ws.base)[i];
        }
        Ok(stencil(values, h))
    }

    /// Each plate in `switched` to its side past the switch, and each column's jump there
    /// (`docs/model.md#calibration`). `at_crossing`: on g = 0, where the plate may slide on;
    /// otherwise (a crossing found only at a step's end) a locked plate takes the other side.
    fn switch_sides(
        &self,
        t: f64,
        q: &mut [f64],
        q_dot: &mut [f64],
        switched: &[usize],
        at_crossing: bool,
        ws: &mut AugmentedWorkspace<P::Workspace>,
    ) -> Result<()> {
        let n = self.base.dof();
        for &i in switched {
            self.held_base(t, &q[..n], &q_dot[..n], ws)?;
            let (speed, sigma) = (ws.scratch.speeds[i], ws.scratch.sigma[i]);
            let side = self.mode.borrow()[i];
            let old_side = match side {
                Side::Sliding => {
                    self.mode.borrow_mut()[i] = Side::Locked(if sigma < 0.0 { -1.0 } else { 1.0 });
                    continue;
                }
                Side::Locked(sign) => sign,
                Side::Free if speed != 0.0 => -speed.signum(),
                Side::Free => continue,
            };
            self.mode.borrow_mut()[i] = Side::Locked(old_side);
            self.held_base(t, &q[..n], &q_dot[..n], ws)?;
            let before = ws.after.clone();
            let mut sigma = f64::NAN;
            if at_crossing {
                self.mode.borrow_mut()[i] = Side::Sliding;
                self.held_base(t, &q[..n], &q_dot[..n], ws)?;
                sigma = ws.scratch.sigma[i];
            }
            if !(sigma.is_finite() && sigma.abs() <= 1.0) {
                self.mode.borrow_mut()[i] = Side::Locked(-old_side);
                self.held_base(t, &q[..n], &q_dot[..n], ws)?;
            }
            let after = ws.after.clone();
            ws.direction.copy_from_slice(&q_dot[..n]);
            let direction = std::mem::take(&mut ws.direction);
            let along_motion = self.switch_derivative(t, i, (&q[..n], &q_dot[..n]), (&direction, &before), ws);
            ws.direction = direction;
            let along_motion = along_motion?;
            if along_motion == 0.0 || !along_motion.is_finite() {
                continue;
            }
            for j in 0..self.columns() {
                let (s, s_dot) = (
                    q[n * (1 + j)..n * (2 + j)].to_vec(),
                    q_dot[n * (1 + j)..n * (2 + j)].to_vec(),
                );
                let along_column = self.switch_derivative(t, i, (&q[..n], &q_dot[..n]), (&s, &s_dot), ws)?;
                let mut values = [0.0; POINTS];
                for (k, plant) in self.perturbed[j].iter().enumerate() {
                    plant.accelerations(t, &q[..n], &q_dot[..n], &mut ws.perturbed[j][k], &mut ws.stencil[k])?;
                    values[k] = plant.switches(&ws.perturbed[j][k])[i];
                }
                let tau = -(along_column + stencil(values, self.epsilon)) / along_motion;
                for r in 0..n {
                    q_dot[n * (1 + j) + r] += (before[r] - after[r]) * tau;
                }
            }
        }
        Ok(())
    }

    /// The step h along column j's (Sⱼ, Ṡⱼ) that shifts no angle or scaled rate by more than
    /// [`STATE_SHIFT`]; None when the column is zero.
    fn state_step(&self, j: usize, q_dot: &[f64], q: &[f64]) -> Option<f64> {
        let n = self.base.dof();
        let (s, s_dot) = (&q[n * (1 + j)..n * (2 + j)], &q_dot[n * (1 + j)..n * (2 + j)]);
        let size = s
            .iter()
            .map(|x| x.abs())
            .chain(s_dot.iter().map(|x| x.abs() * self.time_unit))
            .fold(0.0, f64::max);
        (size > 0.0 && size.is_finite()).then(|| STATE_SHIFT / size)
    }

    /// (q + khSⱼ, q̇ + khṠⱼ) into the shifted buffers.
    fn shift(&self, j: usize, kh: f64, q: &[f64], q_dot: &[f64], shifted_q: &mut [f64], shifted_rates: &mut [f64]) {
        let n = self.base.dof();
        let (s, s_dot) = (&q[n * (1 + j)..n * (2 + j)], &q_dot[n * (1 + j)..n * (2 + j)]);
        for i in 0..n {
            shifted_q[i] = q[i] + kh * s[i];
            shifted_rates[i] = q_dot[i] + kh * s_dot[i];
        }
    }
}

impl<P: Plant> Plant for Augmented<'_, P> {
    type Workspace = AugmentedWorkspace<P::Workspace>;

    fn workspace(&self) -> Self::Workspace {
        let n = self.base.dof();
        AugmentedWorkspace {
            base: self.base.workspace(),
            perturbed: self
                .perturbed
                .iter()
                .map(|pair| pair.each_ref().map(P::workspace))
                .collect(),
            shifted_q: vec![0.0; n],
            shifted_rates: vec![0.0; n],
            stencil: std::array::from_fn(|_| vec![0.0; n]),
            free_signs: vec![0.0; self.switch_count],
            scratch: SideScratch::new(self.switch_count, n),
            after: vec![0.0; n],
            direction: vec![0.0; n],
        }
    }

    fn dof(&self) -> usize {
        self.base.dof() * (1 + self.columns())
    }

    fn forcing(&self) -> &Forcing {
        self.base.forcing()
    }

    fn time_scales(&self) -> Result<TimeScales> {
        self.base.time_scales()
    }

    fn quasi_static_error_estimate(&self) -> Result<f64> {
        self.base.quasi_static_error_estimate()
    }

    fn slowest_omega(&self) -> Result<f64> {
        self.base.slowest_omega()
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        let mut q = self.base.initial_coordinates();
        q.resize(self.dof(), 0.0);
        q
    }

    /// The base's start; each column's start is the difference of the perturbed plants'
    /// starts, less the motion over the difference of their start times (a plant that leaves
    /// a flat start along a branch starts later when it is stiffer).
    fn initial_state(&self) -> Result<InitialState> {
        if let Some(state) = self.initial.get() {
            return Ok(state.clone());
        }
        let start = self.base.initial_state()?;
        let n = self.base.dof();
        let mut ws = self.base.workspace();
        let mut acceleration = vec![0.0; n];
        self.base
            .accelerations(start.time, &start.coordinates, &start.rates, &mut ws, &mut acceleration)?;
        let mut coordinates = start.coordinates.clone();
        let mut rates = start.rates.clone();
        let eps = self.epsilon;
        for pair in self.perturbed {
            let mut states = Vec::with_capacity(POINTS);
            for plant in pair {
                states.push(plant.initial_state()?);
            }
            let states: [InitialState; POINTS] = states
                .try_into()
                .map_err(|_| NanofoldError::invalid("perturbed", "a pair of scenes", "one scene per stencil offset"))?;
            let dt = stencil(states.each_ref().map(|s| s.time), eps);
            for (i, (rate, accel)) in start.rates.iter().zip(&acceleration).enumerate() {
                coordinates.push(stencil(states.each_ref().map(|s| s.coordinates[i]), eps) - rate * dt);
                rates.push(stencil(states.each_ref().map(|s| s.rates[i]), eps) - accel * dt);
            }
        }
        let state = InitialState {
            time: start.time,
            coordinates,
            rates,
            accumulated: Vec::new(),
            note: start.note,
        };
        Ok(self.initial.get_or_init(|| state).clone())
    }

    /// The base's projection; then each plate that has started moving has its drag's side
    /// locked until its switch is located.
    fn project(&self, t: f64, q: &mut [f64], q_dot: &mut [f64], ws: &mut Self::Workspace) -> Result<bool> {
        let n = self.base.dof();
        let projected = self.base.project(t, &mut q[..n], &mut q_dot[..n], &mut ws.base)?;
        if projected {
            self.project_columns(t, q, q_dot, ws)?;
        }
        // Unlocated, the drag keeps its natural sign, as in `simulate`.
        if self.switch_count == 0 || !self.locate {
            return Ok(projected);
        }
        self.held_base(t, &q[..n], &q_dot[..n], ws)?;
        let mut missed = Vec::new();
        {
            let mut mode = self.mode.borrow_mut();
            for (p, side) in mode.iter_mut().enumerate() {
                let speed = ws.scratch.speeds[p];
                if *side == Side::Free && speed != 0.0 {
                    *side = Side::Locked(speed.signum());
                } else if side.switch_value(speed, ws.scratch.sigma[p]) < 0.0 {
                    missed.push(p);
                }
            }
        }
        // A crossing the integrator did not locate: taken here, at the end of the step, where
        // the plate is plainly on the other side (it cannot slide there).
        if !missed.is_empty() {
            self.switch_sides(t, q, q_dot, &missed, false, ws)?;
            return Ok(true);
        }
        Ok(projected)
    }

    /// The motion's accelerations with the drag's sides held, then each column's with the
    /// free plates' signs held at the motion's too (a difference straddling a switch would
    /// see its jump; the integrator applies the jump where the switch is crossed instead).
    fn accelerations(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut Self::Workspace, out: &mut [f64]) -> Result<()> {
        let n = self.base.dof();
        let sides = self.mode.borrow();
        held_accelerations(
            self.base,
            &sides,
            None,
            t,
            &q[..n],
            &q_dot[..n],
            &mut ws.base,
            &mut ws.scratch,
            &mut out[..n],
        )?;
        for (sign, speed) in ws.free_signs.iter_mut().zip(&ws.scratch.speeds) {
            *sign = if *speed == 0.0 { 0.0 } else { speed.signum() };
        }
        self.column_accelerations(&sides, t, q, q_dot, ws, out)
    }

    fn located_switches(&self) -> usize {
        if self.locate {
            self.switch_count
        } else {
            0
        }
    }

    fn switch_values(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut Self::Workspace, out: &mut [f64]) -> Result<()> {
        let n = self.base.dof();
        self.held_base(t, &q[..n], &q_dot[..n], ws)?;
        let sides = self.mode.borrow();
        for (p, value) in out.iter_mut().enumerate() {
            *value = sides[p].switch_value(ws.scratch.speeds[p], ws.scratch.sigma[p]);
        }
        Ok(())
    }

    /// Where plate i's switching function crosses zero. Leaving a sliding stretch (σ
    /// reaching ±1) the field is continuous: the side is locked and nothing jumps. Crossing
    /// g = 0 the plate slides on if its equivalent sign lies in [−1, 1], else it locks to the
    /// other side; each column then jumps (Hiskens & Pai 2000): the crossing time moves by
    /// τⱼ = −(∇g·Xⱼ + ∂g/∂uⱼ) / (∇g·f⁻), and Ṡⱼ by (a⁻ − a⁺) τⱼ, a⁻ and a⁺ the accelerations
    /// before and after (the angles are continuous, so Sⱼ does not jump).
    fn jump(
        &self,
        t: f64,
        q: &mut [f64],
        q_dot: &mut [f64],
        switched: &[usize],
        ws: &mut Self::Workspace,
    ) -> Result<()> {
        self.switch_sides(t, q, q_dot, switched, true, ws)
    }

    /// The base's sample, its angles followed by each column's output sensitivities (the
    /// difference of the perturbed plants' outputs at the shifted states).
    fn sample(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        _accumulated: &[f64],
        ws: &mut Self::Workspace,
    ) -> Result<Sample> {
        let n = self.base.dof();
        let mut sample = self.base.sample(t, &q[..n], &q_dot[..n], &[], &mut ws.base)?;
        let outputs = sample.angles.len();
        let mut angles = sample.angles.as_slice().to_vec();
        let mut rates = sample.rates.as_slice().to_vec();
        for (j, pair) in self.perturbed.iter().enumerate() {
            let mut along_parameter = Vec::with_capacity(POINTS);
            for (k, plant) in pair.iter().enumerate() {
                along_parameter.push(plant.sample(t, &q[..n], &q_dot[..n], &[], &mut ws.perturbed[j][k])?);
            }
            let mut along_state = Vec::with_capacity(POINTS);
            let h = self.state_step(j, q_dot, q);
            for offset in STENCIL {
                self.shift(
                    j,
                    offset * h.unwrap_or(0.0),
                    q,
                    q_dot,
                    &mut ws.shifted_q,
                    &mut ws.shifted_rates,
                );
                along_state.push(
                    self.base
                        .sample(t, &ws.shifted_q, &ws.shifted_rates, &[], &mut ws.base)?,
                );
            }
            let derivative = |of: &dyn Fn(&Sample) -> f64| {
                stencil(std::array::from_fn(|k| of(&along_parameter[k])), self.epsilon)
                    + h.map_or(0.0, |h| stencil(std::array::from_fn(|k| of(&along_state[k])), h))
            };
            for i in 0..outputs {
                angles.push(derivative(&|s| s.angles[i]));
                rates.push(derivative(&|s| s.rates[i]));
            }
        }
        sample.angles = DVector::from_vec(angles);
        sample.rates = DVector::from_vec(rates);
        Ok(sample)
    }

    fn balance(&self, _drive: &[f64], _q: &mut [f64], _ws: &mut Self::Workspace) -> Result<()> {
        Err(NanofoldError::invalid(
            "model",
            "quasi_static",
            "sensitivities are integrated with the dynamics only",
        ))
    }

    fn balance_rates(
        &self,
        q: &[f64],
        drive: &[f64],
        _drive_rates: &[f64],
        _out: &mut [f64],
        ws: &mut Self::Workspace,
    ) -> Result<()> {
        let mut q = q.to_vec();
        self.balance(drive, &mut q, ws)
    }

    fn check_samples(&self, samples: &[Sample]) -> Result<()> {
        match samples.iter().find(|s| s.angles.iter().any(|a| !a.is_finite())) {
            Some(s) => Err(NanofoldError::invalid(
                "sensitivities",
                format!("NaN at t = {:e} s", s.time),
                "the motion or its sensitivities left the finite numbers",
            )),
            None => Ok(()),
        }
    }

    fn contact_count(&self) -> usize {
        0
    }

    fn touching(&self, _t: f64, _q: &[f64], _ws: &mut Self::Workspace) -> Option<Collision> {
        None
    }

    fn contact_lever(&self) -> f64 {
        self.base.contact_lever()
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut Self::Workspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        let n = self.base.dof();
        self.base.probe(&mut ws.base, &mut q[..n], path)
    }
}
