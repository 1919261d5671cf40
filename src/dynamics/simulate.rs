//! Response of a scene to its actuation (SPEC §7): the model chosen from time scales, the
//! dynamics integrated by diffsol with contact location on its dense output, or the
//! quasi-static path K θ = τ(t) when inertia cannot matter.
//!
//! The integrator sees scaled time s = t ω_slow and state y = (θ, dθ/ds), so angles and rates
//! are both O(1) and one absolute tolerance fits all components (SPEC §1: masses ~1e-12 kg,
//! stiffnesses ~1e-9 N·m give rates ~1e4 rad/s in SI).

use super::contact::{gaps_at, locate, ChainProbe, Collision, ContactProbe, ContactSet};
use super::modes::modes;
use super::Data;
use crate::error::{NanofoldError, Result};
use crate::scene::{Actuation, Scene};
use diffsol::{NalgebraLU, NalgebraMat, NalgebraVec, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason};
use nalgebra::DVector;
use std::cell::{Cell, RefCell};
use std::time::Instant;

/// `auto` takes the quasi-static path when the forcing lasts at least this many fastest periods.
pub const QUASI_STATIC_RATIO: f64 = 1e3;
/// `auto` integrates with ESDIRK34 rather than Tsit45 when the forcing lasts at least this many
/// fastest periods: the response is then smooth on the fast time scale and an L-stable
/// implicit method takes long steps. A step keeps the modes ringing (quadratic drag damps
/// small oscillations slowly), every period must be resolved, and Tsit45 is cheaper per step
/// (measured on the bridge: 4× fewer steps than ESDIRK34 at the same tolerance). BDF is
/// offered too, but its Newton iterations fail at rtol ≤ 1e-8 on the ramp.
pub const IMPLICIT_RATIO: f64 = 100.0;
/// Contact scanning: sub-intervals of a solver step in which some gap comes within reach of
/// zero (catches in-and-out crossings within a step).
const CONTACT_SUBDIVISIONS: usize = 4;
/// Contact scanning of the quasi-static path: largest change of a drive angle between checks, rad.
const QUASI_STATIC_ANGLE_STEP: f64 = 2e-3;
/// The quasi-static check integrates the dynamics over this many slowest periods.
const CHECK_PERIODS: f64 = 30.0;
/// Slowest periods of that check when a fast forcing is forced onto the quasi-static model.
const STEP_CHECK_PERIODS: f64 = 2.0;
/// A run stops with an error once Newton has failed more than this many times and on more
/// than every other step (diffsol's own cap counts failures over the whole run; see `integrate`).
const NEWTON_FAILURE_FLOOR: usize = 1000;
/// Tolerance of the check run of a slow forcing.
const CHECK_RTOL: f64 = 1e-10;

/// Which equations to solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    Dynamic,
    QuasiStatic,
}

/// The user's choice: a model, or `Auto` from the time-scale ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelChoice {
    Auto,
    Dynamic,
    QuasiStatic,
}

/// diffsol's integrators; `Auto` picks Tsit45 for short runs and ESDIRK34 for long (stiff) ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    Auto,
    Bdf,
    Esdirk34,
    TrBdf2,
    Tsit45,
}

/// Settings of one run.
#[derive(Debug, Clone)]
pub struct SimulationSettings {
    pub model: ModelChoice,
    pub method: Method,
    /// Relative tolerance; the absolute tolerance is the same number in rad (and rad per scaled time).
    pub rtol: f64,
    /// Integrate through contacts (for tests and what-if runs).
    pub ignore_collisions: bool,
    /// Overrides the scene's `time.t_end_s`.
    pub t_end: Option<f64>,
    /// Called as the main run advances (a progress bar, a log); None for silence.
    pub progress: Option<ProgressObserver>,
    /// A dynamic run that needs more integrator steps stops with an error that says how many
    /// it would still need and what to try instead.
    pub max_steps: usize,
}

impl Default for SimulationSettings {
    fn default() -> Self {
        SimulationSettings {
            model: ModelChoice::Auto,
            method: Method::Auto,
            rtol: 1e-8,
            ignore_collisions: false,
            t_end: None,
            progress: None,
            max_steps: 5_000_000,
        }
    }
}

/// Natural periods (over the flat and the target configurations) against the forcing.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TimeScales {
    pub fastest_period_s: f64,
    pub slowest_period_s: f64,
    /// 0 for a step, the longest ramp time t_p for a ramp.
    pub forcing_time_s: f64,
    /// forcing_time / fastest_period.
    pub ratio: f64,
}

/// One output time.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    pub time: f64,
    pub angles: DVector<f64>,
    pub rates: DVector<f64>,
    /// ½ θ̇ᵀ M θ̇, J.
    pub kinetic_energy: f64,
    /// ½ Σ K θ², J.
    pub elastic_energy: f64,
    /// −τ(t)·θ, J: with the elastic energy, the potential of a constant (step) torque.
    pub actuator_potential: f64,
}

impl Sample {
    /// Kinetic + elastic + actuator potential: conserved for a step without drag.
    pub fn total_energy(&self) -> f64 {
        self.kinetic_energy + self.elastic_energy + self.actuator_potential
    }
}

/// Everything a run found.
#[derive(Debug, Clone)]
pub struct Response {
    pub model: ModelKind,
    /// The integrator used (dynamic runs).
    pub method: Option<Method>,
    pub rtol: f64,
    pub time_scales: TimeScales,
    /// Linear bound on |θ_dynamic − θ_quasi-static|: each mode's response to the jumps in
    /// the drive rate (ramp) or drive angle (step), summed over modes, rad.
    pub quasi_static_error_estimate: f64,
    /// max |θ_dynamic − θ_quasi-static| over a short dynamic run at the start, when the
    /// quasi-static model was chosen: (window s, error rad).
    pub measured_quasi_static_error: Option<(f64, f64)>,
    /// Time the run stopped (collision or the end of the span), s.
    pub t_end: f64,
    pub collision: Option<Collision>,
    pub samples: Vec<Sample>,
    pub steps: usize,
    pub rhs_evaluations: usize,
    pub seconds: f64,
    /// What a closed chain adds (None for an open chain).
    pub closed: Option<super::closed::ClosedReport>,
}

/// Fastest and slowest natural periods over the flat and the target configurations.
pub fn time_scales(scene: &Scene) -> Result<TimeScales> {
    let n = scene.model.dof();
    let mut fastest = f64::INFINITY;
    let mut slowest: f64 = 0.0;
    for angles in [DVector::zeros(n), scene.target_angles.clone()] {
        let m = modes(&scene.model, angles.as_slice())?;
        for f in m.frequencies_hz {
            fastest = fastest.min(1.0 / f);
            slowest = slowest.max(1.0 / f);
        }
    }
    let forcing = scene.forcing_time();
    Ok(TimeScales {
        fastest_period_s: fastest,
        slowest_period_s: slowest,
        forcing_time_s: forcing,
        ratio: forcing / fastest,
    })
}

/// Linear bound on how far the dynamics can stray from the quasi-static path. Each jump the
/// dynamics cannot follow starts free oscillations in the modes of the configuration where it
/// happens: a step's drive angle Δθ, or a change Δṙ of the ramp's drive rate (at t = 0 and
/// where each hinge reaches its target). With M ë + K e = 0,
///   step: |e_i| ≤ Σ_k |φ̂_ki| |φ̂_kᵀ M Δθ|,   ramp: |e_i| ≤ Σ_k |φ̂_ki| |φ̂_kᵀ M Δṙ| / ω_k
/// (φ̂ mass-normalised); the bound sums over jumps since drag-free oscillations add up.
fn quasi_static_error_estimate(scene: &Scene) -> Result<f64> {
    let n = scene.model.dof();
    let mut data = Data::new(&scene.model);
    let mut bound = DVector::<f64>::zeros(n);
    let mut add_jump = |at: &[f64], jump: &DVector<f64>, per_frequency: bool| -> Result<()> {
        let modes = modes(&scene.model, at)?;
        scene.model.update_kinematics(at, &mut data);
        scene.model.update_mass_matrix(&mut data);
        let mass = &data.mass_matrix;
        for k in 0..n {
            let shape = modes.mode_shapes.column(k);
            let normalised = shape / shape.dot(&(mass * shape)).sqrt();
            let scale = if per_frequency {
                1.0 / modes.eigenvalues[k].sqrt()
            } else {
                1.0
            };
            bound += normalised.abs() * (normalised.dot(&(mass * jump)).abs() * scale);
        }
        Ok(())
    };
    match &scene.actuation {
        Actuation::Step => add_jump(&vec![0.0; n], &scene.target_angles, false)?,
        Actuation::Ramp {
            etch_rate,
            radius_of_curvature,
        } => {
            let rate = DVector::from_fn(n, |i, _| {
                if scene.actuated[i] && scene.target_angles[i] != 0.0 {
                    scene.target_angles[i].signum() * etch_rate / radius_of_curvature[i]
                } else {
                    0.0
                }
            });
            add_jump(&vec![0.0; n], &rate, true)?;
            let mut at = vec![0.0; n];
            for i in (0..n).filter(|&i| rate[i] != 0.0) {
                let stop = radius_of_curvature[i] * scene.target_angles[i].abs() / etch_rate;
                scene.drive_angles(stop, &mut at);
                let jump = DVector::from_fn(n, |j, _| if j == i { rate[i] } else { 0.0 });
                add_jump(&at, &jump, true)?;
            }
        }
    }
    Ok(bound.amax())
}

impl ModelChoice {
    /// The model to run: `Auto` is quasi-static from a time-scale ratio of 10³ up.
    pub fn resolve(self, scales: &TimeScales) -> ModelKind {
        match self {
            ModelChoice::Dynamic => ModelKind::Dynamic,
            ModelChoice::QuasiStatic => ModelKind::QuasiStatic,
            ModelChoice::Auto if scales.ratio >= QUASI_STATIC_RATIO => ModelKind::QuasiStatic,
            ModelChoice::Auto => ModelKind::Dynamic,
        }
    }
}

impl SimulationSettings {
    /// Integration options of the main dynamic run.
    pub(crate) fn run_options(&self) -> IntegrationOptions {
        IntegrationOptions {
            rtol: self.rtol,
            progress: self.progress.clone(),
            record_steps: true,
            max_steps: self.max_steps,
        }
    }

    /// The dynamic run that measures a quasi-static model's error: its window (s), method and
    /// options. Slow forcing: a smooth response, ESDIRK34 at a tolerance well below the model's
    /// error. A step forced onto the quasi-static model rings at O(1) rad: a few periods with
    /// Tsit45 at the run's tolerance show it (an implicit method would crawl).
    pub(crate) fn check_run(&self, scales: &TimeScales, t_end: f64) -> (f64, Method, IntegrationOptions) {
        let (periods, method, rtol) = if scales.ratio >= IMPLICIT_RATIO {
            (CHECK_PERIODS, Method::Esdirk34, CHECK_RTOL.min(self.rtol))
        } else {
            (STEP_CHECK_PERIODS, Method::Tsit45, self.rtol)
        };
        let options = IntegrationOptions {
            rtol,
            progress: None,
            record_steps: false,
            max_steps: self.max_steps,
        };
        ((periods * scales.slowest_period_s).min(t_end), method, options)
    }
}

/// Runs a scene.
pub fn simulate(scene: &Scene, settings: &SimulationSettings) -> Result<Response> {
    let started = Instant::now();
    if !(settings.rtol.is_finite() && settings.rtol > 0.0 && settings.rtol < 1.0) {
        return Err(NanofoldError::invalid("--rtol", settings.rtol, "must lie in (0, 1)"));
    }
    let t_end = settings.t_end.unwrap_or(scene.t_end);
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(NanofoldError::invalid("t_end", t_end, "must be a finite time > 0 s"));
    }
    let scales = time_scales(scene)?;
    let estimate = quasi_static_error_estimate(scene)?;
    let kind = settings.model.resolve(&scales);
    let contacts = (!settings.ignore_collisions).then(|| ContactSet::new(&scene.model, scene.substrate_edge_y));
    let output_times = output_times(t_end, scene.outputs.samples);
    let mut response = Response {
        model: kind,
        method: None,
        rtol: settings.rtol,
        time_scales: scales,
        quasi_static_error_estimate: estimate,
        measured_quasi_static_error: None,
        t_end,
        collision: None,
        samples: Vec::new(),
        steps: 0,
        rhs_evaluations: 0,
        seconds: 0.0,
        closed: None,
    };
    match kind {
        ModelKind::Dynamic => {
            let method = resolve_method(settings.method, &scales);
            let run = integrate(
                &OpenChain { scene, contacts },
                method,
                &output_times,
                settings.run_options(),
            )?;
            response.method = Some(method);
            response.steps = run.steps;
            response.rhs_evaluations = run.rhs_evaluations;
            response.collision = run.collision;
            response.samples = run.samples;
        }
        ModelKind::QuasiStatic => {
            let (samples, collision, steps) = quasi_static(scene, &output_times, contacts.as_ref());
            response.samples = samples;
            response.collision = collision;
            response.steps = steps;
            let (window, method, options) = settings.check_run(&scales, t_end);
            let check_times = output_times_in(window, 201);
            let run = integrate(&OpenChain { scene, contacts: None }, method, &check_times, options)?;
            response.measured_quasi_static_error = Some((window, quasi_static_deviation(scene, &run.samples)));
        }
    }
    if let Some(c) = &response.collision {
        response.t_end = c.time;
    }
    response.seconds = started.elapsed().as_secs_f64();
    Ok(response)
}

/// max over samples and hinges of |θ − θ_quasi-static(t)|, rad: how far a response strays
/// from the quasi-static path θ_drive(t).
pub fn quasi_static_deviation(scene: &Scene, samples: &[Sample]) -> f64 {
    let mut drive = vec![0.0; scene.model.dof()];
    samples
        .iter()
        .map(|s| {
            scene.drive_angles(s.time, &mut drive);
            s.angles
                .iter()
                .zip(&drive)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// What the integrator needs of a mechanical system: its generalised coordinates q (the
/// hinge angles of an open chain, the driving angle of a closed one), their accelerations,
/// output samples and contact candidates.
pub trait Plant {
    /// Scratch buffers reused across evaluations.
    type Workspace;
    fn workspace(&self) -> Self::Workspace;
    /// Number of generalised coordinates.
    fn dof(&self) -> usize;
    /// The slowest natural angular frequency at the start, rad/s: the integrator's time unit.
    fn slowest_omega(&self) -> Result<f64>;
    /// q at t = 0 (at rest).
    fn initial_coordinates(&self) -> Vec<f64>;
    /// q̈ at (t, q, q̇), written into `out`.
    fn accelerations(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut Self::Workspace, out: &mut [f64]) -> Result<()>;
    /// An output sample at (t, q, q̇).
    fn sample(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut Self::Workspace) -> Result<Sample>;
    /// Times where the forcing has a kink (no step may straddle them), s.
    fn forcing_breakpoints(&self) -> Vec<f64>;
    /// Number of contact candidates (0 when collisions are ignored).
    fn contact_count(&self) -> usize;
    /// A contact present at the configuration q (e.g. at t = 0).
    fn touching(&self, t: f64, q: &[f64], ws: &mut Self::Workspace) -> Option<Collision>;
    /// Two contact points approach each other at most this × Σ|q̇_j| (m per rad).
    fn contact_lever(&self) -> f64;
    /// The contact candidates along a path q(u) of a parameter u.
    fn probe<'a>(
        &'a self,
        ws: &'a mut Self::Workspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a>;
}

/// An open chain of a strip scene: q = θ, the hinge angles.
pub struct OpenChain<'s> {
    pub scene: &'s Scene,
    pub contacts: Option<ContactSet>,
}

/// Scratch of an [`OpenChain`]: the model's buffers and the hinge torques.
pub struct OpenChainWorkspace {
    data: Data,
    torques: Vec<f64>,
}

impl Plant for OpenChain<'_> {
    type Workspace = OpenChainWorkspace;

    fn workspace(&self) -> OpenChainWorkspace {
        OpenChainWorkspace {
            data: Data::new(&self.scene.model),
            torques: vec![0.0; self.dof()],
        }
    }

    fn dof(&self) -> usize {
        self.scene.model.dof()
    }

    fn slowest_omega(&self) -> Result<f64> {
        let flat = modes(&self.scene.model, &vec![0.0; self.dof()])?;
        Ok(flat.eigenvalues.last().copied().unwrap_or(1.0).sqrt())
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        vec![0.0; self.dof()]
    }

    fn accelerations(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        ws: &mut OpenChainWorkspace,
        out: &mut [f64],
    ) -> Result<()> {
        self.scene.torques(t, &mut ws.torques);
        self.scene.model.accelerations(q, q_dot, &ws.torques, &mut ws.data, out)
    }

    fn sample(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut OpenChainWorkspace) -> Result<Sample> {
        Ok(sample(self.scene, &mut ws.data, t, q, q_dot))
    }

    fn forcing_breakpoints(&self) -> Vec<f64> {
        self.scene.forcing_breakpoints()
    }

    fn contact_count(&self) -> usize {
        self.contacts.as_ref().map_or(0, ContactSet::len)
    }

    fn touching(&self, t: f64, q: &[f64], ws: &mut OpenChainWorkspace) -> Option<Collision> {
        let contacts = self.contacts.as_ref()?;
        self.scene.model.update_kinematics(q, &mut ws.data);
        self.scene.model.update_corners(&mut ws.data);
        contacts.touching(t, &ws.data)
    }

    fn contact_lever(&self) -> f64 {
        ContactSet::lever(&self.scene.model)
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut OpenChainWorkspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        Box::new(ChainProbe {
            contacts: self.contacts.as_ref().expect("probe needs contacts"),
            model: &self.scene.model,
            data: &mut ws.data,
            angles: q,
            path,
        })
    }
}

pub(crate) fn resolve_method(method: Method, scales: &TimeScales) -> Method {
    match method {
        Method::Auto if scales.ratio >= IMPLICIT_RATIO => Method::Esdirk34,
        Method::Auto => Method::Tsit45,
        other => other,
    }
}

pub(crate) fn output_times_in(t_end: f64, samples: usize) -> Vec<f64> {
    (0..samples).map(|k| t_end * k as f64 / (samples - 1) as f64).collect()
}

pub(crate) fn output_times(t_end: f64, samples: usize) -> Vec<f64> {
    output_times_in(t_end, samples.max(2))
}

/// Fills a sample's energies.
fn sample(scene: &Scene, data: &mut Data, time: f64, angles: &[f64], rates: &[f64]) -> Sample {
    let model = &scene.model;
    model.update_kinematics(angles, data);
    model.update_mass_matrix(data);
    let mut torques = vec![0.0; model.dof()];
    scene.torques(time, &mut torques);
    Sample {
        time,
        angles: DVector::from_column_slice(angles),
        rates: DVector::from_column_slice(rates),
        kinetic_energy: model.kinetic_energy(rates, data),
        elastic_energy: 0.5
            * model
                .joints
                .iter()
                .zip(angles)
                .map(|(j, a)| j.stiffness * a * a)
                .sum::<f64>(),
        actuator_potential: -torques.iter().zip(angles).map(|(t, a)| t * a).sum::<f64>(),
    }
}

/// The quasi-static path θ(t) = K⁻¹ τ(t) = θ_drive(t), scanned for contacts.
fn quasi_static(
    scene: &Scene,
    output_times: &[f64],
    contacts: Option<&ContactSet>,
) -> (Vec<Sample>, Option<Collision>, usize) {
    let model = &scene.model;
    let n = model.dof();
    let mut data = Data::new(model);
    let t_last = *output_times.last().unwrap_or(&0.0);
    let moving_until = match scene.actuation {
        // A step jumps at t = 0: scan the straight path to the target as if at t = 0⁺.
        Actuation::Step => 0.0,
        Actuation::Ramp { .. } => scene.forcing_time().min(t_last),
    };
    let largest = scene.target_angles.amax();
    let subdivisions = ((largest / QUASI_STATIC_ANGLE_STEP).ceil() as usize).max(1);
    let mut collision = None;
    if let Some(contacts) = contacts {
        let mut angles = vec![0.0; n];
        model.update_kinematics(&angles, &mut data);
        model.update_corners(&mut data);
        collision = contacts.touching(0.0, &data);
        if collision.is_none() {
            let mut gaps = vec![0.0; contacts.len()];
            let mut scratch = vec![0.0; contacts.len()];
            contacts.gaps(&data, &mut gaps);
            let mut path = |t: f64, out: &mut [f64]| match scene.actuation {
                Actuation::Step => {
                    for (o, target) in out.iter_mut().zip(scene.target_angles.iter()) {
                        *o = t * target;
                    }
                }
                Actuation::Ramp { .. } => scene.drive_angles(t * moving_until, out),
            };
            // Scan the path over its parameter u ∈ [0, 1].
            let mut probe = ChainProbe {
                contacts,
                model,
                data: &mut data,
                angles: &mut angles,
                path: &mut path,
            };
            collision = locate(
                &mut probe,
                0.0,
                1.0,
                f64::INFINITY,
                subdivisions,
                &mut gaps,
                &mut scratch,
            )
            .map(|mut c| {
                c.time *= moving_until;
                c
            });
        }
    }
    let stop = collision.as_ref().map_or(f64::INFINITY, |c| c.time);
    let mut samples = Vec::new();
    let mut angles = vec![0.0; n];
    let mut rates = vec![0.0; n];
    let mut record = |t: f64, samples: &mut Vec<Sample>| {
        scene.drive_angles(t, &mut angles);
        scene.drive_rates(t, &mut rates);
        samples.push(sample(scene, &mut data, t, &angles, &rates));
    };
    for &t in output_times.iter().filter(|&&t| t < stop) {
        record(t, &mut samples);
    }
    if stop.is_finite() {
        record(stop, &mut samples);
    }
    (samples, collision, subdivisions)
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

/// How one diffsol run is driven.
#[derive(Debug, Clone)]
pub struct IntegrationOptions {
    pub rtol: f64,
    pub progress: Option<ProgressObserver>,
    /// Record a sample at every accepted step besides the output times.
    pub record_steps: bool,
    pub max_steps: usize,
}

/// Result of one diffsol run.
pub struct DynamicRun {
    pub samples: Vec<Sample>,
    pub collision: Option<Collision>,
    pub steps: usize,
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
    let time_unit = 1.0 / plant.slowest_omega()?;
    let initial = plant.initial_coordinates();
    let evaluations = Cell::new(0usize);
    let failure: RefCell<Option<NanofoldError>> = RefCell::new(None);
    let workspace = RefCell::new((plant.workspace(), vec![0.0; n], vec![0.0; n]));
    let rhs = |y: &[f64], s: f64, dy: &mut [f64]| {
        evaluations.set(evaluations.get() + 1);
        let mut guard = workspace.borrow_mut();
        let (ws, rates, accel) = &mut *guard;
        let (angles, scaled_rates) = y.split_at(n);
        for (r, v) in rates.iter_mut().zip(scaled_rates) {
            *r = v / time_unit;
        }
        if let Err(e) = plant.accelerations(s * time_unit, angles, rates, ws, accel) {
            failure.borrow_mut().get_or_insert(e);
            dy.iter_mut().for_each(|d| *d = f64::NAN);
            return;
        }
        dy[..n].copy_from_slice(scaled_rates);
        for (d, a) in dy[n..].iter_mut().zip(accel.iter()) {
            *d = a * time_unit * time_unit;
        }
    };
    // Jacobian-vector products by central differences (diffsol assembles J from them).
    let shifted = RefCell::new((vec![0.0; 2 * n], vec![0.0; 2 * n], vec![0.0; 2 * n]));
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
    let mut problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(rtol)
        .atol(vec![rtol; 2 * n])
        .rhs_implicit(
            |y: &[f64], _p: &[f64], s: f64, dy: &mut [f64]| rhs(y, s, dy),
            |y: &[f64], _p: &[f64], s: f64, v: &[f64], jv: &mut [f64]| jacobian_times(y, s, v, jv),
        )
        .init(
            |_p: &[f64], _t: f64, y: &mut [f64]| {
                y.iter_mut().for_each(|x| *x = 0.0);
                y[..n].copy_from_slice(&initial);
            },
            2 * n,
        )
        .build()
        .map_err(|e| ode_error(&e))?;
    // diffsol counts Newton failures over the whole run, not per step: a long run with rare,
    // harmless failures (each retried with a new Jacobian or a smaller step) would abort.
    // The minimum step size still stops a run that genuinely cannot proceed.
    problem.ode_options.max_nonlinear_solver_failures = usize::MAX / 2;
    let s_end = output_times.last().copied().unwrap_or(0.0) / time_unit;
    let driver = Driver {
        plant,
        output_times,
        time_unit,
        s_end,
        progress: progress.as_ref(),
        record_steps,
        method,
        max_steps,
    };
    let result = match method {
        Method::Bdf | Method::Auto => driver.run(problem.bdf::<NalgebraLU<f64>>().map_err(|e| ode_error(&e))?),
        Method::Esdirk34 => driver.run(problem.esdirk34::<NalgebraLU<f64>>().map_err(|e| ode_error(&e))?),
        Method::TrBdf2 => driver.run(problem.tr_bdf2::<NalgebraLU<f64>>().map_err(|e| ode_error(&e))?),
        Method::Tsit45 => driver.run(problem.tsit45().map_err(|e| ode_error(&e))?),
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

fn ode_error(e: &diffsol::error::DiffsolError) -> NanofoldError {
    NanofoldError::Numerical {
        stage: "ODE integration (diffsol)".into(),
        message: e.to_string(),
    }
}

/// Steps a diffsol solver to the end or the first contact, sampling the dense output.
struct Driver<'r, P: Plant> {
    plant: &'r P,
    output_times: &'r [f64],
    time_unit: f64,
    s_end: f64,
    progress: Option<&'r ProgressObserver>,
    /// Record a sample at every accepted step besides the output times.
    record_steps: bool,
    /// For error messages.
    method: Method,
    max_steps: usize,
}

impl<P: Plant> Driver<'_, P> {
    fn run<'a, Eqn, S>(&self, mut solver: S) -> Result<(Vec<Sample>, Option<Collision>, usize, usize)>
    where
        Eqn: OdeEquations<T = f64, V = NalgebraVec<f64>> + 'a,
        S: OdeSolverMethod<'a, Eqn>,
    {
        let plant = self.plant;
        let n = plant.dof();
        let mut ws = plant.workspace();
        let mut samples = Vec::with_capacity(self.output_times.len());
        let mut state = solver.state().y.clone();
        let mut angles = vec![0.0; n];
        let mut rates = vec![0.0; n];
        let split = |y: &NalgebraVec<f64>, angles: &mut [f64], rates: &mut [f64]| {
            for i in 0..n {
                angles[i] = y[i];
                rates[i] = y[n + i] / self.time_unit;
            }
        };
        split(&state, &mut angles, &mut rates);
        samples.push(plant.sample(0.0, &angles, &rates, &mut ws)?);
        let mut next_output = 1;
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
        // Stop exactly at each kink of the forcing (a ramp reaching its target), so no step
        // straddles it, then at the end.
        let mut stops: Vec<f64> = self
            .plant
            .forcing_breakpoints()
            .into_iter()
            .map(|t| t / self.time_unit)
            .filter(|&s| s > 0.0 && s < self.s_end)
            .collect();
        stops.push(self.s_end);
        let mut next_stop = 0;
        solver.set_stop_time(stops[0]).map_err(|e| ode_error(&e))?;
        let mut steps = 0;
        let mut s_previous = 0.0;
        // Σ|dθ/ds| at the previous step's end, for the contact reach bound.
        let speed_sum = |y: &NalgebraVec<f64>| (n..2 * n).map(|i| y[i].abs()).sum::<f64>();
        let mut previous_speed: f64 = 0.0;
        let lever = plant.contact_lever();
        loop {
            let reason = solver.step().map_err(|e| ode_error(&e))?;
            steps += 1;
            let s_now = solver.state().t;
            let newton_failures = solver.get_statistics().number_of_nonlinear_solver_fails;
            if steps >= self.max_steps && s_now < self.s_end {
                return Err(NanofoldError::Numerical {
                    stage: "ODE integration (diffsol)".into(),
                    message: format!(
                        "{:?} used its budget of {steps} steps by t = {:.6e} s of {:.6e} s; at this pace it needs about \
                         {:.1e} more. Use --method esdirk34 for a slow forcing, tsit45 for a step, --model quasi-static \
                         when the time-scale ratio is large, or a looser --rtol",
                        self.method,
                        s_now * self.time_unit,
                        self.s_end * self.time_unit,
                        steps as f64 * (self.s_end - s_now) / s_now.max(f64::MIN_POSITIVE)
                    ),
                });
            }
            if newton_failures > NEWTON_FAILURE_FLOOR && 2 * newton_failures > steps {
                return Err(NanofoldError::Numerical {
                    stage: "ODE integration (diffsol)".into(),
                    message: format!(
                        "{:?}'s Newton iterations failed {newton_failures} times in {steps} steps by t = {:.6e} s (the fast \
                         modes make its iteration matrix ill-conditioned at this tolerance); use --method esdirk34 for a \
                         slow forcing, tsit45 for a step, or a looser --rtol",
                        self.method,
                        s_now * self.time_unit
                    ),
                });
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
            let s_stop = collision.as_ref().map_or(s_now, |c| c.time / self.time_unit);
            while next_output < self.output_times.len() && self.output_times[next_output] / self.time_unit <= s_stop {
                let s = (self.output_times[next_output] / self.time_unit).min(s_now);
                solver.interpolate_inplace(s, &mut state).map_err(|e| ode_error(&e))?;
                split(&state, &mut angles, &mut rates);
                samples.push(plant.sample(self.output_times[next_output], &angles, &rates, &mut ws)?);
                next_output += 1;
            }
            if let Some(c) = collision {
                solver
                    .interpolate_inplace(c.time / self.time_unit, &mut state)
                    .map_err(|e| ode_error(&e))?;
                split(&state, &mut angles, &mut rates);
                samples.push(plant.sample(c.time, &angles, &rates, &mut ws)?);
                return Ok((
                    samples,
                    Some(c),
                    steps,
                    solver.get_statistics().number_of_nonlinear_solver_fails,
                ));
            }
            // Every accepted step too: the steps resolve the fastest mode, a fixed grid may alias it.
            let s_now_time = s_now * self.time_unit;
            if self.record_steps && samples.last().is_none_or(|last| last.time < s_now_time) {
                solver
                    .interpolate_inplace(s_now, &mut state)
                    .map_err(|e| ode_error(&e))?;
                split(&state, &mut angles, &mut rates);
                samples.push(plant.sample(s_now_time, &angles, &rates, &mut ws)?);
            }
            if let Some(progress) = self.progress {
                (progress.0)(s_now / self.s_end, s_now * self.time_unit);
            }
            if s_now >= self.s_end {
                break;
            }
            if matches!(reason, OdeSolverStopReason::TstopReached) {
                next_stop += 1;
                match stops.get(next_stop) {
                    Some(&stop) => solver.set_stop_time(stop).map_err(|e| ode_error(&e))?,
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
