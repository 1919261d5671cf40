//! The fitted curves of a one-DOF network as its one coordinate
//! (`docs/model.md#fitted-curves-of-a-network`): the thesis's method for many vertices. One
//! driving crease q is the coordinate, every other crease follows its Chebyshev fit
//! ρ = f(q) of an exact sweep, so with Z = f′(q) and H = f″(q) the motion is
//!   (Zᵀ M Z) q̈ = Zᵀ (τ(t) − K ρ − C(ρ, Z q̇) Z q̇ + Q_drag) − Zᵀ M H q̇²
//! on the panels' tree; the loops close only to the fit's error, which is measured.

use super::algorithms::{
    update_bias, update_drag, update_kinematics, update_mass_matrix, update_velocities, NetworkData,
};
use super::contact::NetworkProbe;
pub use super::fitted::{FittedReduction, ReducedReport};
use super::manifold::{mass_times, tangent_basis, worst_residual};
use super::model::NetworkModel;
use super::plant::{
    fastest_drive_rate, network_report, network_sample, time_scales_of, NetworkPlant, NetworkRunReport,
};
use crate::constraints::chebyshev::FittedCurves;
use crate::constraints::network::{fit_network, network_sweep, NetworkCurve};
use crate::constraints::{MAX_DEGREE, MAX_SAMPLES};
use crate::dynamics::contact::{Collision, ContactProbe};
use crate::dynamics::forcing::{Actuation, Forcing};
use crate::dynamics::plant::{InitialState, Plant, Sample, TimeScales};
use crate::error::{NanofoldError, NumericalError, Result};
use crate::read::scene_spec::NetworkConstraintSpec;
use std::f64::consts::{PI, TAU};

/// The default domain reaches past the start and the overshoot by this fraction of its width.
const DOMAIN_WIDENING: f64 = 0.05;
/// The smallest default domain, rad (a start already at its balance still rings).
const MIN_DOMAIN: f64 = 0.05;
/// The automatic degree stops at the first that fits every crease to this, rad.
const AUTO_FIT_TOL: f64 = 1e-8;
/// How far short of ±180° the search for a step's turning point stops, rad (folded flat, the
/// closures are singular).
const FAR_END: f64 = 0.05;
/// Fitted points of that coarse search's sweep (as many − 1 between).
const PROBE_SAMPLES: usize = 17;
/// Points per fitted interval at which the curves' own closure residual is measured.
const CLOSURE_CHECKS: usize = 4;

/// The exact sweep of the driver from the network's folded balance and its fits, as a
/// scene's `constraint` asks.
pub fn reduce(model: &NetworkModel, spec: &NetworkConstraintSpec) -> Result<FittedReduction> {
    if let Some(degree) = spec.degree {
        if !(1..=MAX_DEGREE).contains(&degree) {
            return Err(NanofoldError::invalid(
                "constraint.degree",
                degree,
                format!("must lie in [1, {MAX_DEGREE}]"),
            ));
        }
    }
    let lowest_samples = spec.degree.unwrap_or(MAX_DEGREE) + 1;
    if !(lowest_samples..=MAX_SAMPLES / 2).contains(&spec.samples) {
        return Err(NanofoldError::invalid(
            "constraint.samples",
            spec.samples,
            format!(
                "must lie in [degree + 1, {}] = [{lowest_samples}, {}]",
                MAX_SAMPLES / 2,
                MAX_SAMPLES / 2
            ),
        ));
    }
    let plant = NetworkPlant::new(model, false)?;
    let start = plant.branch().map_or_else(|| model.start.clone(), |b| b.angles.clone());
    let balance = plant.final_balance_angles()?;
    let basis = tangent_basis(model, &balance)?;
    if basis.ncols() != 1 {
        return Err(NanofoldError::invalid(
            "constraint.source",
            "poly",
            format!(
                "fitted curves need one degree of freedom; the network has {} at its folded balance (use source \"network\")",
                basis.ncols()
            ),
        ));
    }
    let columns = model.columns();
    let driver = match spec.driver_edge {
        Some(edge) => {
            let c = model
                .folding
                .pattern
                .creases
                .iter()
                .position(|&e| e == edge)
                .ok_or_else(|| NanofoldError::invalid("constraint.driver_edge", edge, "not a crease of the pattern"))?;
            if model.locked(c) {
                return Err(NanofoldError::invalid(
                    "constraint.driver_edge",
                    edge,
                    "the crease is locked",
                ));
            }
            c
        }
        None => (0..columns)
            .filter(|&c| !model.locked(c))
            .max_by(|&a, &b| basis[(a, 0)].abs().total_cmp(&basis[(b, 0)].abs()))
            .expect("a network with a degree of freedom has a free crease"),
    };
    let (s, e) = (start[driver], balance[driver]);
    let domain = match spec.range_deg {
        Some([a, b]) => {
            let field = "constraint.range_deg";
            let shown = format!("[{a}, {b}]");
            if !(a.is_finite() && b.is_finite() && a < b && a >= -180.0 && b <= 180.0) {
                return Err(NanofoldError::invalid(field, shown, "needs a < b within [−180, 180]"));
            }
            let (a, b) = (a.to_radians(), b.to_radians());
            for (what, x) in [("start", s), ("folded balance", e)] {
                if x < a || x > b {
                    return Err(NanofoldError::invalid(
                        field,
                        shown,
                        format!("must contain the driver's {what}, {:.4}°", x.to_degrees()),
                    ));
                }
            }
            [a, b]
        }
        None => default_domain(model, &plant, &start, &balance, driver)?,
    };
    let sweep = network_sweep(&model.folding, &balance, driver, domain, spec.samples).map_err(|err| {
        NanofoldError::invalid(
            "constraint.range_deg",
            format!("[{:.4}, {:.4}]", domain[0].to_degrees(), domain[1].to_degrees()),
            format!("the exact sweep of the driver over it failed ({err}): give a narrower range"),
        )
    })?;
    // The curves are evaluated in Chebyshev form: their error is that form's.
    let fit = |degree: usize| -> Result<(f64, Vec<NetworkCurve>)> {
        let curves = fit_network(&model.folding, &sweep, degree)?.curves;
        let error = curves.iter().map(|c| c.max_fit_error_rad).fold(0.0, f64::max);
        Ok((error, curves))
    };
    let (degree, (fit_error, fitted)) = match spec.degree {
        Some(degree) => (degree, fit(degree)?),
        None => {
            let mut best: Option<(usize, (f64, Vec<NetworkCurve>))> = None;
            for degree in 2..=MAX_DEGREE.min(spec.samples - 1) {
                let found = fit(degree)?;
                let better = best.as_ref().is_none_or(|b| found.0 < b.1 .0);
                let met = found.0 <= AUTO_FIT_TOL;
                if better {
                    best = Some((degree, found));
                }
                if met {
                    break;
                }
            }
            best.expect("at least one degree")
        }
    };
    // fit_network gives one curve per crease but the driver, in column order.
    debug_assert_eq!(fitted.len() + 1, columns);
    let mut reduction = FittedReduction {
        driver,
        fitted: FittedCurves {
            domain,
            curves: fitted.into_iter().map(|curve| curve.chebyshev).collect(),
        },
        total_slope: 0.0,
        report: ReducedReport {
            driver_edge: model.folding.pattern.creases[driver],
            degree,
            samples: spec.samples,
            domain_deg: domain.map(f64::to_degrees),
            max_fit_error_rad: fit_error,
            curves_closure_residual_rad: 0.0,
            balance_driver_rad: e,
            balance_frequency_hz: 0.0,
        },
    };
    let points = CLOSURE_CHECKS * 2 * spec.samples;
    let at = |k: usize| domain[0] + (domain[1] - domain[0]) * k as f64 / points as f64;
    reduction.total_slope = 1.0
        + reduction
            .fitted
            .curves
            .iter()
            .map(|f| {
                (0..=points)
                    .map(|k| f.eval_with_derivatives(at(k)).1.abs())
                    .fold(0.0, f64::max)
            })
            .sum::<f64>();
    let mut angles = vec![0.0; columns];
    reduction.report.curves_closure_residual_rad = (0..=points)
        .map(|k| {
            reduction.angles(at(k), &mut angles);
            worst_residual(model, &angles)
        })
        .fold(0.0, f64::max);
    // The reduced equation's own balance and frequency under the final drive.
    let (q, omega) = {
        // The exact plant already found the branch and the balance: reuse it.
        let reduced = ReducedPlant {
            model,
            reduction: &reduction,
            exact: plant,
        };
        let mut ws = reduced.workspace();
        let rest = final_rest(model);
        let mut q = [e];
        reduced.balance(&rest, &mut q, &mut ws)?;
        (q[0], reduced.frequency(q[0], &rest, &mut ws)?)
    };
    reduction.report.balance_driver_rad = q;
    reduction.report.balance_frequency_hz = omega / TAU;
    Ok(reduction)
}

/// The hinges' rest angles with every drive at its final angle (passive hinges at 0).
fn final_rest(model: &NetworkModel) -> Vec<f64> {
    let forcing = &model.forcing;
    let mut drive = vec![0.0; model.columns()];
    forcing.drive_angles(forcing.duration().max(1.0), &mut drive);
    drive
        .iter()
        .zip(&forcing.hinges)
        .map(|(d, h)| if h.actuated { *d } else { 0.0 })
        .collect()
}

/// Σ ½ K (ρ − r)², J.
fn hinge_potential(model: &NetworkModel, angles: &[f64], rest: &[f64]) -> f64 {
    model
        .hinges
        .iter()
        .zip(angles.iter().zip(rest))
        .map(|(h, (a, r))| 0.5 * h.stiffness * (a - r) * (a - r))
        .sum()
}

/// The driver's default range: from its start (short of flat when the start is flat: the
/// branches cross there) to where the undamped swing of a step to the final drive turns
/// back, found on a coarse exact sweep past the balance (the hinge potential there reaches
/// the start's energy), each end padded by a twentieth of the width.
fn default_domain(
    model: &NetworkModel,
    plant: &NetworkPlant<'_>,
    start: &[f64],
    balance: &[f64],
    driver: usize,
) -> Result<[f64; 2]> {
    let (s, e) = (start[driver], balance[driver]);
    let rest = final_rest(model);
    let mut data = NetworkData::new(model);
    let kinetic = plant.branch().map_or(0.0, |b| {
        update_kinematics(model, &b.angles, &mut data);
        update_velocities(model, &b.rates, &mut data);
        super::algorithms::kinetic_energy(model, &data)
    });
    let energy = hinge_potential(model, start, &rest) + kinetic;
    let side = if e >= s { 1.0 } else { -1.0 };
    let limit = side * (PI - FAR_END);
    let mut turn = 2.0 * e - s;
    for attempt in 0..5 {
        let far = e + (limit - e) * 0.5_f64.powi(attempt);
        let ends = if side > 0.0 { [e, far] } else { [far, e] };
        let Ok(sweep) = network_sweep(&model.folding, balance, driver, ends, PROBE_SAMPLES) else {
            continue;
        };
        let mut outward: Vec<usize> = (0..sweep.driver_values.len()).collect();
        if side < 0.0 {
            outward.reverse();
        }
        turn = far;
        let mut previous: Option<(f64, f64)> = None;
        for k in outward {
            let (q, v) = (sweep.driver_values[k], hinge_potential(model, &sweep.states[k], &rest));
            if v >= energy {
                turn = previous.map_or(q, |(q0, v0)| q0 + (q - q0) * (energy - v0) / (v - v0));
                break;
            }
            previous = Some((q, v));
        }
        break;
    }
    let (lo, hi) = (s.min(turn), s.max(turn));
    let pad = DOMAIN_WIDENING * (hi - lo).max(MIN_DOMAIN);
    let flat_start = plant.branch().is_some();
    let lo = if flat_start && side > 0.0 { 0.5 * lo } else { lo - pad };
    let hi = if flat_start && side < 0.0 { 0.5 * hi } else { hi + pad };
    let edge = PI - 1e-3;
    Ok([lo.max(-edge), hi.min(edge)])
}

/// Scratch of a [`ReducedPlant`].
pub struct ReducedWorkspace {
    data: NetworkData,
    angles: Vec<f64>,
    slopes: Vec<f64>,
    curvatures: Vec<f64>,
    rates: Vec<f64>,
    mass_slopes: Vec<f64>,
    drive: Vec<f64>,
    actuation_power: f64,
    drag_power: f64,
}

/// A one-DOF network on its fitted curves as an integrator plant.
pub struct ReducedPlant<'m> {
    model: &'m NetworkModel,
    reduction: &'m FittedReduction,
    exact: NetworkPlant<'m>,
}

impl<'m> ReducedPlant<'m> {
    /// The plant of `model` on `reduction`, with the exact network's contacts and branch.
    pub fn new(model: &'m NetworkModel, reduction: &'m FittedReduction, collisions: bool) -> Result<Self> {
        Ok(ReducedPlant {
            model,
            reduction,
            exact: NetworkPlant::new(model, collisions)?,
        })
    }

    /// The same plant without contact candidates.
    pub fn without_contacts(&self) -> Self {
        ReducedPlant {
            model: self.model,
            reduction: self.reduction,
            exact: self.exact.without_contacts(),
        }
    }

    /// The run's report: the network's, with the curves'.
    pub fn report(&self, samples: &[Sample], contact: bool) -> Result<NetworkRunReport> {
        let mut report = network_report(
            self.model,
            self.exact.contacts(),
            self.exact.branch().map(|b| b.note.clone()),
            samples,
            contact,
        );
        report.reduced = Some(self.reduction.report.clone());
        Ok(report)
    }

    /// Fills ρ, Z, H at q.
    fn at(&self, q: f64, ws: &mut ReducedWorkspace) -> Result<()> {
        self.reduction
            .evaluate(q, &mut ws.angles, &mut ws.slopes, &mut ws.curvatures)
    }

    /// Zᵀ M Z at the angles in `ws` (needs the kinematics there).
    fn reduced_mass(&self, ws: &mut ReducedWorkspace) -> f64 {
        update_mass_matrix(self.model, &mut ws.data);
        mass_times(self.model, &ws.data, &ws.slopes, &mut ws.mass_slopes);
        dot(&ws.slopes, &ws.mass_slopes)
    }

    /// The reduced potential's first and second derivatives at q under rest angles r:
    /// V = Σ ½K(ρ − r)², V′ = Σ K(ρ − r)Z, V″ = Σ K(Z² + (ρ − r)H).
    fn potential_derivatives(&self, q: f64, rest: &[f64], ws: &mut ReducedWorkspace) -> Result<(f64, f64)> {
        self.at(q, ws)?;
        let (mut first, mut second) = (0.0, 0.0);
        for (c, hinge) in self.model.hinges.iter().enumerate() {
            let k = hinge.stiffness;
            let stretch = ws.angles[c] - rest[c];
            first += k * stretch * ws.slopes[c];
            second += k * (ws.slopes[c] * ws.slopes[c] + stretch * ws.curvatures[c]);
        }
        Ok((first, second))
    }

    /// The rest angle of every crease under drive angles `drive`: the drive where actuated,
    /// 0 where passive (locked creases follow no curve: their slope is 0).
    fn rest(&self, drive: &[f64]) -> Vec<f64> {
        drive
            .iter()
            .zip(&self.model.forcing.hinges)
            .map(|(d, h)| if h.actuated { *d } else { 0.0 })
            .collect()
    }

    /// Natural angular frequency of the reduced equation about q under rest angles `rest`,
    /// rad/s.
    fn frequency(&self, q: f64, rest: &[f64], ws: &mut ReducedWorkspace) -> Result<f64> {
        let (_, stiffness) = self.potential_derivatives(q, rest, ws)?;
        update_kinematics(self.model, &ws.angles, &mut ws.data);
        let mass = self.reduced_mass(ws);
        Ok((stiffness / mass).max(0.0).sqrt())
    }

    /// Spring-only angular frequency (Zᵀ K Z / Zᵀ M Z) at q, rad/s, as the exact network's
    /// time scales take it.
    fn spring_omega(&self, q: f64, ws: &mut ReducedWorkspace) -> Result<f64> {
        let zero = vec![0.0; self.model.columns()];
        let (_, _) = self.potential_derivatives(q, &zero, ws)?;
        let stiffness: f64 = self
            .model
            .hinges
            .iter()
            .zip(&ws.slopes)
            .map(|(h, z)| h.stiffness * z * z)
            .sum();
        update_kinematics(self.model, &ws.angles, &mut ws.data);
        let mass = self.reduced_mass(ws);
        Ok((stiffness / mass).sqrt())
    }

    fn start_driver(&self) -> f64 {
        self.exact
            .branch()
            .map_or(self.model.start[self.reduction.driver], |b| {
                b.angles[self.reduction.driver]
            })
    }

    fn omegas(&self) -> Result<Vec<f64>> {
        let mut ws = self.workspace();
        let mut all = vec![self.spring_omega(self.start_driver(), &mut ws)?];
        all.push(self.spring_omega(self.reduction.report.balance_driver_rad, &mut ws)?);
        Ok(all.into_iter().filter(|w| *w > 0.0 && w.is_finite()).collect())
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Plant for ReducedPlant<'_> {
    type Workspace = ReducedWorkspace;

    fn switches<'w>(&self, ws: &'w Self::Workspace) -> &'w [f64] {
        &ws.data.drag_switches.normal_speeds
    }

    fn freeze_switches(&self, ws: &mut Self::Workspace, signs: Option<&[f64]>) {
        ws.data.drag_switches.freeze(signs);
    }

    fn workspace(&self) -> ReducedWorkspace {
        let n = self.model.columns();
        ReducedWorkspace {
            data: NetworkData::new(self.model),
            angles: vec![0.0; n],
            slopes: vec![0.0; n],
            curvatures: vec![0.0; n],
            rates: vec![0.0; n],
            mass_slopes: vec![0.0; n],
            drive: vec![0.0; n],
            actuation_power: 0.0,
            drag_power: 0.0,
        }
    }

    fn dof(&self) -> usize {
        1
    }

    fn forcing(&self) -> &Forcing {
        &self.model.forcing
    }

    fn time_scales(&self) -> Result<TimeScales> {
        time_scales_of(
            &self.omegas()?,
            &self.model.forcing,
            "the fitted curves give no stiffness or no inertia",
        )
    }

    fn quasi_static_error_estimate(&self) -> Result<f64> {
        let mut ws = self.workspace();
        let start = self.start_driver();
        let mut from = vec![0.0; self.model.columns()];
        self.reduction.angles(start, &mut from);
        let jump = |q: f64, ws: &mut ReducedWorkspace| -> Result<f64> {
            self.at(q, ws)?;
            Ok(ws
                .angles
                .iter()
                .zip(&from)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max))
        };
        Ok(match self.model.forcing.actuation {
            Actuation::Step => jump(self.reduction.report.balance_driver_rad, &mut ws)?,
            Actuation::Ramp { .. } => {
                let mut q = [start];
                self.balance(&vec![0.0; self.model.columns()], &mut q, &mut ws)?;
                2.0 * fastest_drive_rate(&self.model.forcing) / self.slowest_omega()? + jump(q[0], &mut ws)?
            }
        })
    }

    fn slowest_omega(&self) -> Result<f64> {
        let mut ws = self.workspace();
        let omega = self.spring_omega(self.start_driver(), &mut ws)?;
        if omega > 0.0 && omega.is_finite() {
            Ok(omega)
        } else {
            Err(NumericalError::NonFinite {
                what: "natural periods",
                detail: "the fitted curves give no stiffness or no inertia at the start".into(),
            }
            .into())
        }
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        vec![self.model.start[self.reduction.driver]]
    }

    fn initial_state(&self) -> Result<InitialState> {
        let d = self.reduction.driver;
        Ok(match self.exact.branch() {
            Some(branch) => InitialState {
                time: branch.time,
                coordinates: vec![branch.angles[d]],
                rates: vec![branch.rates[d]],
                accumulated: vec![branch.work, branch.dissipation],
                note: Some(branch.note.clone()),
            },
            None => InitialState {
                time: 0.0,
                coordinates: self.initial_coordinates(),
                rates: vec![0.0],
                accumulated: vec![0.0; 2],
                note: None,
            },
        })
    }

    fn accumulators(&self) -> usize {
        2
    }

    fn energy_scale(&self) -> f64 {
        super::plant::energy_scale(self.model)
    }

    fn accumulator_rates(&self, ws: &ReducedWorkspace, out: &mut [f64]) {
        out[0] = ws.actuation_power;
        out[1] = -ws.drag_power;
    }

    fn accelerations(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        ws: &mut ReducedWorkspace,
        out: &mut [f64],
    ) -> Result<()> {
        let model = self.model;
        let rate = q_dot[0];
        self.at(q[0], ws)?;
        for (r, z) in ws.rates.iter_mut().zip(&ws.slopes) {
            *r = z * rate;
        }
        update_kinematics(model, &ws.angles, &mut ws.data);
        update_velocities(model, &ws.rates, &mut ws.data);
        ws.drag_power = update_drag(model, &mut ws.data);
        update_bias(model, &mut ws.data);
        let mass = self.reduced_mass(ws);
        // Zᵀ M H = (M Z)ᵀ H.
        let curvature_inertia = dot(&ws.mass_slopes, &ws.curvatures);
        model.forcing.drive_angles(t, &mut ws.drive);
        let (mut force, mut power) = (0.0, 0.0);
        for c in 0..model.columns() {
            let k = model.hinges[c].stiffness;
            let torque = if model.forcing.hinges[c].actuated {
                k * ws.drive[c]
            } else {
                0.0
            };
            power += torque * ws.rates[c];
            force += (torque - k * ws.angles[c] - ws.data.bias[c]) * ws.slopes[c];
        }
        ws.actuation_power = power;
        out[0] = (force - curvature_inertia * rate * rate) / mass;
        if !out[0].is_finite() {
            return Err(NumericalError::NonFinite {
                what: "reduced network acceleration",
                detail: format!("at t = {t:.6e} s: check the scene's magnitudes"),
            }
            .into());
        }
        Ok(())
    }

    fn sample(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        accumulated: &[f64],
        ws: &mut ReducedWorkspace,
    ) -> Result<Sample> {
        // Before a flat start is left, the sheet rests flat (the branch's own start).
        if self.exact.branch().is_some_and(|b| t < b.time) {
            ws.rates.iter_mut().for_each(|r| *r = 0.0);
            return Ok(network_sample(
                self.model,
                t,
                &self.model.start,
                &ws.rates,
                accumulated,
                &mut ws.data,
                &mut ws.drive,
            ));
        }
        self.at(q[0], ws)?;
        for (r, z) in ws.rates.iter_mut().zip(&ws.slopes) {
            *r = z * q_dot[0];
        }
        Ok(network_sample(
            self.model,
            t,
            &ws.angles,
            &ws.rates,
            accumulated,
            &mut ws.data,
            &mut ws.drive,
        ))
    }

    fn balance(&self, drive: &[f64], q: &mut [f64], ws: &mut ReducedWorkspace) -> Result<()> {
        let rest = self.rest(drive);
        let mut x = q[0];
        for _ in 0..50 {
            let (first, second) = self.potential_derivatives(x, &rest, ws)?;
            if second.is_nan() || second <= 0.0 {
                return Err(NumericalError::NonFinite {
                    what: "reduced balance",
                    detail: format!(
                        "the fitted curves' potential is not convex at the driver's {:.4}°",
                        x.to_degrees()
                    ),
                }
                .into());
            }
            let step = first / second;
            x -= step;
            if step.abs() <= 1e-14 * (1.0 + x.abs()) {
                q[0] = x;
                return Ok(());
            }
        }
        q[0] = x;
        Ok(())
    }

    fn balance_rates(
        &self,
        q: &[f64],
        drive: &[f64],
        drive_rates: &[f64],
        out: &mut [f64],
        ws: &mut ReducedWorkspace,
    ) -> Result<()> {
        // V′(q, r) = 0 along the drive: V″ q̇ = Σ K Z ṙ.
        let rest = self.rest(drive);
        let (_, second) = self.potential_derivatives(q[0], &rest, ws)?;
        let pushed: f64 = (0..self.model.columns())
            .filter(|&c| self.model.forcing.hinges[c].actuated)
            .map(|c| self.model.hinges[c].stiffness * ws.slopes[c] * drive_rates[c])
            .sum();
        out[0] = pushed / second;
        Ok(())
    }

    fn check_samples(&self, samples: &[Sample]) -> Result<()> {
        let [a, b] = self.reduction.fitted.domain;
        let slack = 1e-9 * (b - a);
        let resting = self.exact.branch().map_or(f64::NEG_INFINITY, |b| b.time);
        match samples
            .iter()
            .filter(|s| s.time >= resting)
            .map(|s| s.angles[self.reduction.driver])
            .find(|q| !(*q >= a - slack && *q <= b + slack))
        {
            Some(q) => Err(self.reduction.outside(q)),
            None => Ok(()),
        }
    }

    fn contact_count(&self) -> usize {
        self.exact.contact_count()
    }

    fn touching(&self, t: f64, q: &[f64], ws: &mut ReducedWorkspace) -> Option<Collision> {
        self.reduction.angles(q[0], &mut ws.angles);
        self.exact.contacts().touching(self.model, t, &ws.angles, &mut ws.data)
    }

    fn contact_lever(&self) -> f64 {
        // The exact network's lever is per unit of Σ|ρ̇|; here Σ|ρ̇| ≤ Σ|f′| |q̇| (sampled
        // densely over the domain, with a quarter more for between the samples).
        1.25 * self.exact.contact_lever() * self.reduction.total_slope
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut ReducedWorkspace,
        _q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        let reduction = self.reduction;
        Box::new(NetworkProbe::new(
            self.model,
            self.exact.contacts(),
            &mut ws.data,
            &mut ws.angles,
            Box::new(move |u: f64, angles: &mut [f64]| {
                let mut q = [0.0];
                path(u, &mut q);
                reduction.angles(q[0], angles);
            }),
        ))
    }
}
