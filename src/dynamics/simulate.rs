//! Response of a scene to its actuation (`docs/model.md#model-choice`): the model chosen
//! from the time scales, the dynamics integrated by diffsol with contact location, or the
//! quasi-static path when inertia cannot matter; the same path for a strip and a closed
//! chain, which adds its own report beside the response.

use super::closed::{ClosedPlant, ClosedReport};
use super::contact::Collision;
use super::integrate::{integrate, output_times, IntegrationOptions, Method, ProgressObserver, IMPLICIT_RATIO};
use super::network::closing::{ClosingReport, ClosingSettings, NetClosing};
use super::network::plant::NetworkRunReport;
use super::network::{NetworkModel, NetworkPlant, ReducedPlant};
use super::plant::{Plant, Sample, TimeScales};
use super::quasi_static::{quasi_static_deviation, quasi_static_path};
use super::scene::{Scene, System};
use super::strip::StripPlant;
use crate::error::{NanofoldError, NumericalError, Result};
use std::time::Instant;

/// `auto` takes the quasi-static path when the forcing lasts at least this many fastest periods.
pub const QUASI_STATIC_RATIO: f64 = 1e3;
/// The quasi-static check integrates the dynamics over this many slowest periods.
const CHECK_PERIODS: f64 = 30.0;
/// Slowest periods of that check when a fast forcing is forced onto the quasi-static model.
const STEP_CHECK_PERIODS: f64 = 2.0;
/// Tolerance of the check run of a slow forcing.
const CHECK_RTOL: f64 = 1e-10;
/// A dynamic run of a slow forcing (≥ 10³ fastest periods) may stray from the quasi-static
/// path by its linear error bound (×10) plus this, rad.
const SLOW_FORCING_DEVIATION: f64 = 1e-3;

/// Which equations to solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// M q̈ + C q̇ + K q = τ(t) + Q_drag, integrated.
    Dynamic,
    /// K q = τ(t) along the constraints: inertia dropped.
    QuasiStatic,
}

/// The user's choice: a model, or `Auto` from the time-scale ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelChoice {
    /// Quasi-static from a time-scale ratio of [`QUASI_STATIC_RATIO`] up, else dynamic.
    Auto,
    /// Always integrate.
    Dynamic,
    /// Always the quasi-static path (its error is still measured).
    #[serde(alias = "quasi-static")]
    QuasiStatic,
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

/// Settings of one run, validated by [`SimulationSettings::validate`] (which
/// [`simulate_scene`] calls).
#[derive(Debug, Clone)]
pub struct SimulationSettings {
    /// Which equations.
    pub model: ModelChoice,
    /// Which integrator.
    pub method: Method,
    /// Relative tolerance in (0, 1); the absolute tolerance is the same number in rad (and rad
    /// per scaled time).
    pub rtol: f64,
    /// Integrate through contacts (for tests and what-if runs).
    pub ignore_collisions: bool,
    /// Overrides the scene's end time, s.
    pub t_end: Option<f64>,
    /// Called as the main run advances (a progress bar, a log); None for silence.
    pub progress: Option<ProgressObserver>,
    /// A dynamic run that needs more integrator steps stops with an error that says how many
    /// it would still need and what to try instead (at least 1).
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

impl SimulationSettings {
    /// Every setting in range; errors name the setting and its value.
    pub fn validate(&self) -> Result<()> {
        if !(self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1.0) {
            return Err(NanofoldError::invalid("rtol", self.rtol, "must lie in (0, 1)"));
        }
        if let Some(t_end) = self.t_end {
            if !(t_end.is_finite() && t_end > 0.0) {
                return Err(NanofoldError::invalid("t_end", t_end, "must be a finite time > 0 s"));
            }
        }
        if self.max_steps == 0 {
            return Err(NanofoldError::invalid("max_steps", 0, "must be at least 1"));
        }
        Ok(())
    }

    /// Integration options of the main dynamic run.
    fn run_options(&self) -> IntegrationOptions {
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
    fn check_run(&self, scales: &TimeScales, t_end: f64) -> (f64, Method, IntegrationOptions) {
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

/// Everything a run found.
#[derive(Debug, Clone)]
pub struct Response {
    /// The equations solved.
    pub model: ModelKind,
    /// The integrator used (dynamic runs).
    pub method: Option<Method>,
    /// The run's relative tolerance.
    pub rtol: f64,
    /// Natural periods against the forcing.
    pub time_scales: TimeScales,
    /// Linear bound on |θ_dynamic − θ_quasi-static|, rad (see the plants' estimates).
    pub quasi_static_error_estimate: f64,
    /// max |θ_dynamic − θ_quasi-static| measured by a dynamic run: (window s, error rad). A
    /// quasi-static run measures it over a short dynamic run at its start, a dynamic run of a
    /// slow forcing over itself.
    pub measured_quasi_static_error: Option<(f64, f64)>,
    /// Time the run stopped (collision or the end of the span), s.
    pub t_end: f64,
    /// The first contact.
    pub collision: Option<Collision>,
    /// Output samples.
    pub samples: Vec<Sample>,
    /// Integrator steps (dynamic) or contact checks along the drive (quasi-static).
    pub steps: usize,
    /// Right-hand-side evaluations (dynamic).
    pub rhs_evaluations: usize,
    /// Wall time, s.
    pub seconds: f64,
}

/// A run's response, and what a closed chain reports beside it.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// The response (every hinge's angle for a strip, every crease's for a closed chain).
    pub response: Response,
    /// The closed chain's constraint errors, torque magnification and closure residual.
    pub closed: Option<ClosedReport>,
    /// A network's branch, closure residuals and energy balance.
    pub network: Option<NetworkRunReport>,
    /// A tree of panels released slowly, carried through its contacts: how it ended, its
    /// latches, contacts and forces (`docs/model.md#slow-release-through-contact`).
    pub released: Option<ClosingReport>,
}

/// Why a network's slow release stops at its first contact instead of going on through it
/// with the contact engine (None: it goes on).
pub fn first_contact_only(model: &NetworkModel) -> Option<&'static str> {
    if !model.folding.stars.is_empty() {
        Some("the pattern closes loops of its own (the contact engine follows trees of panels)")
    } else if model.reduction.is_some() {
        Some("the scene moves on fitted curves")
    } else if model.substrate_contact {
        Some("the substrate is a contact (the contact engine has faces only)")
    } else if model
        .forcing
        .hinges
        .iter()
        .any(|h| h.target.abs() >= std::f64::consts::PI)
    {
        Some("a drive folds its crease flat (a crease's own limit, which the contact engine does not watch)")
    } else {
        None
    }
}

/// Runs a scene: the dynamics, or the quasi-static path when the model is chosen so (`auto`:
/// the forcing lasts ≥ 10³ fastest periods).
///
/// ```
/// use nanofold::prelude::*;
/// let scene = load_scene("patterns/bridge_ramp.scene.json".as_ref())?.build()?;
/// let run = simulate_scene(&scene, &SimulationSettings::default())?;
/// // A 21-minute etch ramp against kHz modes: quasi-static, with its error measured.
/// assert_eq!(run.response.model, ModelKind::QuasiStatic);
/// assert!(run.response.measured_quasi_static_error.unwrap().1 < 1e-6);
/// # Ok::<(), nanofold::NanofoldError>(())
/// ```
pub fn simulate_scene(scene: &Scene, settings: &SimulationSettings) -> Result<Simulation> {
    settings.validate()?;
    let t_end = settings.t_end.unwrap_or(scene.t_end);
    let times = output_times(t_end, scene.outputs.samples);
    let collisions = !settings.ignore_collisions;
    match &scene.system {
        System::Strip(chain) => {
            let (response, _) = run(
                &StripPlant::new(chain, collisions),
                &StripPlant::new(chain, false),
                settings,
                &times,
                None,
            )?;
            Ok(Simulation {
                response,
                closed: None,
                network: None,
                released: None,
            })
        }
        System::Closed(chain) => {
            let (response, _) = run(
                &ClosedPlant::new(chain, collisions),
                &ClosedPlant::new(chain, false),
                settings,
                &times,
                None,
            )?;
            let closed = Some(chain.report(&response.samples)?);
            Ok(Simulation {
                response,
                closed,
                network: None,
                released: None,
            })
        }
        System::Network(model) => {
            let (response, network, released) = match &model.reduction {
                Some(reduction) => {
                    let plant = ReducedPlant::new(model, reduction, collisions)?;
                    let (response, _) = run(&plant, &plant.without_contacts(), settings, &times, None)?;
                    let report = plant.report(&response.samples, response.collision.is_some())?;
                    (response, report, None)
                }
                None => {
                    let plant = NetworkPlant::new(model, collisions)?;
                    let engine = (collisions && first_contact_only(model).is_none() && plant.dof() == model.columns())
                        .then_some(&**model);
                    let (response, released) = run(&plant, &plant.without_contacts(), settings, &times, engine)?;
                    let report = plant.report(&response.samples, response.collision.is_some())?;
                    (response, report, released)
                }
            };
            Ok(Simulation {
                response,
                closed: None,
                network: Some(network),
                released,
            })
        }
    }
}

/// One run of a plant (`check` is the same plant without contacts, for the model's check);
/// a tree of panels given as `engine` goes on through its contacts when quasi-static.
fn run<P: Plant>(
    plant: &P,
    check: &P,
    settings: &SimulationSettings,
    times: &[f64],
    engine: Option<&NetworkModel>,
) -> Result<(Response, Option<ClosingReport>)> {
    let started = Instant::now();
    let t_end = times.last().copied().unwrap_or(0.0);
    let scales = plant.time_scales()?;
    let estimate = plant.quasi_static_error_estimate()?;
    let kind = settings.model.resolve(&scales);
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
    };
    let mut released = None;
    match kind {
        ModelKind::Dynamic => {
            let method = settings.method.resolve(&scales);
            let run = integrate(plant, method, times, settings.run_options())?;
            plant.check_samples(&run.samples)?;
            // A slow forcing has an accurate second answer, the quasi-static path: a dynamic
            // run far from it has been misled by its error control (ESDIRK34 at rtol 1e-6
            // drifts past the equilibrium after a closed chain's ramp), so it is refused.
            if scales.ratio >= QUASI_STATIC_RATIO {
                let deviation = quasi_static_deviation(plant, &run.samples)?;
                if deviation > SLOW_FORCING_DEVIATION + 10.0 * estimate {
                    return Err(NumericalError::Strayed {
                        method: format!("{method:?}"),
                        deviation_deg: deviation.to_degrees(),
                        bound: estimate,
                    }
                    .into());
                }
                response.measured_quasi_static_error = Some((run.samples.last().map_or(0.0, |s| s.time), deviation));
            }
            response.method = Some(method);
            response.steps = run.steps;
            response.rhs_evaluations = run.rhs_evaluations;
            response.collision = run.collision;
            response.samples = run.samples;
        }
        ModelKind::QuasiStatic => {
            match engine {
                Some(model) => {
                    let (samples, report, solves) = released_path(plant, model, t_end, times)?;
                    response.samples = samples;
                    response.steps = solves;
                    response.collision = NetClosing::of_scene(model)?
                        .first_meeting(model, &report)
                        .map(|(time, pair, point)| Collision { time, pair, point });
                    released = Some(report);
                }
                None => {
                    let path = quasi_static_path(plant, times)?;
                    response.samples = path.samples;
                    response.collision = path.collision;
                    response.steps = path.scans;
                }
            }
            // The check of the model: a short dynamic run from rest.
            let (window, method, options) = settings.check_run(&scales, t_end);
            let checked = integrate(check, method, &output_times(window, 201), options)?;
            response.measured_quasi_static_error = Some((window, quasi_static_deviation(check, &checked.samples)?));
        }
    }
    match &released {
        // Through contact: the run ends where the engine's path does.
        Some(report) => response.t_end = report.time_s.min(t_end),
        None => {
            if let Some(c) = &response.collision {
                response.t_end = c.time;
            }
        }
    }
    response.seconds = started.elapsed().as_secs_f64();
    Ok((response, released))
}

/// A tree of panels' slow release through its contacts and seams, sampled at `times` (up
/// to where it ends): (samples, the engine's report, its QP solves).
fn released_path<P: Plant>(
    plant: &P,
    model: &NetworkModel,
    t_end: f64,
    times: &[f64],
) -> Result<(Vec<Sample>, ClosingReport, usize)> {
    let closing = NetClosing::of_scene(model)?;
    let path = closing.run_until(
        model,
        &model.forcing,
        &model.stiffness(),
        &ClosingSettings {
            friction_coefficient: model.friction_coefficient,
            ..ClosingSettings::default()
        },
        t_end,
        Some(times),
    )?;
    let mut ws = plant.workspace();
    let samples = path
        .samples
        .iter()
        .map(|s| plant.sample(s.time_s, &s.fold_angles, &s.rates, &[], &mut ws))
        .collect::<Result<Vec<_>>>()?;
    plant.check_samples(&samples)?;
    Ok((samples, path.report, path.qp_solves))
}
