//! A panel network as an integrator [`Plant`] (`docs/model.md#panel-networks`): every crease
//! angle is a coordinate, the accelerations come from the saddle-point system, and after
//! every integrator step the state goes back onto the closures (positions by Newton, rates
//! by the mass-weighted projection), so no vertex drifts. The work of the actuation and
//! the drag's dissipation are integrated with the motion, so the energy balance can be
//! checked on every sample.

use super::algorithms::{
    kinetic_energy, update_bias, update_drag, update_kinematics, update_mass_matrix, update_stars, update_velocities,
    NetworkData,
};
use super::contact::{NetworkContacts, NetworkProbe};
use super::hessian::HessianSystem;
use super::kkt::KktSystem;
use super::manifold::{equilibrium, projection_solver, restore, spring_frequencies, worst_residual, CLOSURE_TOL};
use super::model::NetworkModel;
use super::start::{leave_flat, BranchStart};
use crate::dynamics::contact::{Collision, ContactProbe};
use crate::dynamics::forcing::{Actuation, Forcing};
use crate::dynamics::plant::{InitialState, Plant, Sample, TimeScales};
use crate::error::{NumericalError, Result};
use crate::folding::normal::NormalSolver;
use nalgebra::DVector;
use std::f64::consts::TAU;
use std::sync::OnceLock;

/// What a network run reports beside its response.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, serde::Serialize)]
pub struct NetworkRunReport {
    /// Panels.
    pub panels: usize,
    /// Creases.
    pub creases: usize,
    /// FOLD face index of the anchored panel.
    pub anchored_face: usize,
    /// How a flat start was left (None: the start is not flat).
    pub branch: Option<String>,
    /// Largest vertex closure residual over the recorded states, rad.
    pub max_closure_residual: f64,
    /// Largest change of kinetic + hinge energy − work of the actuation + drag dissipation
    /// over the recorded states, relative to the largest of those energies (None on the
    /// quasi-static path, which tracks no work).
    pub energy_balance_error: Option<f64>,
    /// Every pair meeting (to 1e-6) at the first contact, the reported one included.
    pub meeting_at_contact: Vec<[String; 2]>,
    /// Panel pairs at a shared vertex that touch at the start, left out of the contacts.
    pub touching_at_start: Vec<[String; 2]>,
    /// The fitted curves a reduced run (`constraint.source` "poly") moved on (None: exact).
    pub reduced: Option<super::fitted::ReducedReport>,
}

/// Scratch of a [`NetworkPlant`].
pub struct NetworkWorkspace {
    /// The rigid-body buffers.
    pub data: NetworkData,
    kkt: KktSystem,
    statics: HessianSystem,
    solver: NormalSolver,
    forces: Vec<f64>,
    drive: Vec<f64>,
    actuation_power: f64,
    drag_power: f64,
    angles: Vec<f64>,
    rates: Vec<f64>,
}

/// A panel network as an integrator plant, with its contact candidates and its start.
pub struct NetworkPlant<'m> {
    model: &'m NetworkModel,
    contacts: NetworkContacts,
    /// Leaving a flat (singular) start along the branch the actuation picks, when it is one.
    start: Option<BranchStart>,
    /// The final balance, once found (the time scales and the quasi-static estimate both
    /// need it).
    balance: OnceLock<Vec<f64>>,
}

impl<'m> NetworkPlant<'m> {
    /// The plant of `model`, its contact candidates (none when `collisions` is false) and,
    /// for a flat start, the branch it leaves along.
    pub fn new(model: &'m NetworkModel, collisions: bool) -> Result<Self> {
        let contacts = NetworkContacts::new(model, collisions);
        let start = leave_flat(model)?;
        Ok(NetworkPlant {
            model,
            contacts,
            start,
            balance: OnceLock::new(),
        })
    }

    /// The same plant without contact candidates (its branch and balance already found).
    pub fn without_contacts(&self) -> Self {
        NetworkPlant {
            model: self.model,
            contacts: NetworkContacts::new(self.model, false),
            start: self.start.clone(),
            balance: self.balance.clone(),
        }
    }

    /// The contact candidates.
    pub fn contacts(&self) -> &NetworkContacts {
        &self.contacts
    }

    /// The model.
    pub fn model(&self) -> &NetworkModel {
        self.model
    }

    /// How the run left a flat start (None: the start is not singular).
    pub fn branch(&self) -> Option<&BranchStart> {
        self.start.as_ref()
    }

    /// The report of a run (its samples, and whether it stopped at a contact): the branch,
    /// closure residuals, energy balance and the pairs meeting at the contact.
    pub fn report(&self, samples: &[Sample], contact: bool) -> Result<NetworkRunReport> {
        Ok(network_report(
            self.model,
            &self.contacts,
            self.start.as_ref().map(|b| b.note.clone()),
            samples,
            contact,
        ))
    }

    /// The hinges' balance with every drive at its final angle, reached from the start (along
    /// the branch a flat start leaves by).
    pub fn final_balance_angles(&self) -> Result<Vec<f64>> {
        self.final_balance()
    }

    /// A configuration to take the time scales at: the start, or the branch's first state
    /// when the start is flat (its tangent space there is the branch's, not the flat
    /// state's larger first-order one).
    fn regular_start(&self) -> &[f64] {
        self.start.as_ref().map_or(&self.model.start, |b| &b.angles)
    }

    /// The hinges' balance with every drive at its final angle, from the start.
    fn final_balance(&self) -> Result<Vec<f64>> {
        if let Some(balance) = self.balance.get() {
            return Ok(balance.clone());
        }
        let forcing = &self.model.forcing;
        let mut rest = vec![0.0; self.model.columns()];
        forcing.drive_angles(forcing.duration().max(1.0), &mut rest);
        self.rest_angles(&mut rest);
        let balance = super::modes::follow_drive(self.model, &rest, self.regular_start())?.angles;
        Ok(self.balance.get_or_init(|| balance).clone())
    }

    /// Locked creases rest at their lock.
    fn rest_angles(&self, rest: &mut [f64]) {
        for (c, r) in rest.iter_mut().enumerate() {
            if self.model.locked(c) {
                *r = self.model.start[c];
            }
        }
    }

    /// The accelerations at (t, ρ, ρ̇), with the powers of the actuation and the drag.
    fn evaluate(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut NetworkWorkspace, out: &mut [f64]) -> Result<()> {
        let model = self.model;
        update_kinematics(model, q, &mut ws.data);
        update_velocities(model, q_dot, &mut ws.data);
        ws.drag_power = update_drag(model, &mut ws.data);
        update_bias(model, &mut ws.data);
        update_mass_matrix(model, &mut ws.data);
        update_stars(model, q, Some(q_dot), &mut ws.data);
        ws.kkt.factor(model, &ws.data)?;
        model.forcing.drive_angles(t, &mut ws.drive);
        let mut power = 0.0;
        for c in 0..model.columns() {
            let k = model.hinges[c].stiffness;
            let torque = if model.forcing.hinges[c].actuated {
                k * ws.drive[c]
            } else {
                0.0
            };
            power += torque * q_dot[c];
            ws.forces[c] = torque - k * q[c] - ws.data.bias[c];
        }
        ws.actuation_power = power;
        ws.kkt.accelerations(&ws.data, &ws.forces, out);
        if out.iter().any(|a| !a.is_finite()) {
            return Err(NumericalError::NonFinite {
                what: "network accelerations",
                detail: format!("at t = {t:.6e} s: check the scene's magnitudes"),
            }
            .into());
        }
        Ok(())
    }

    /// Moves (ρ, ρ̇) onto the closures: Newton on the positions, the mass-weighted
    /// projection of the rates.
    fn project_state(&self, q: &mut [f64], q_dot: &mut [f64], ws: &mut NetworkWorkspace) -> Result<()> {
        let model = self.model;
        restore(model, q, &mut ws.solver)?;
        update_kinematics(model, q, &mut ws.data);
        update_mass_matrix(model, &mut ws.data);
        update_stars(model, q, None, &mut ws.data);
        ws.kkt.factor(model, &ws.data)?;
        ws.kkt.project_rates(q_dot);
        Ok(())
    }

    /// Natural angular frequencies at the start and at the final balance, rad/s.
    fn omegas(&self) -> Result<Vec<f64>> {
        let mut all = spring_frequencies(self.model, self.regular_start())?;
        if let Ok(balance) = self.final_balance() {
            all.extend(spring_frequencies(self.model, &balance)?);
        }
        Ok(all.into_iter().filter(|w| *w > 0.0).collect())
    }
}

impl Plant for NetworkPlant<'_> {
    type Workspace = NetworkWorkspace;

    fn switches<'w>(&self, ws: &'w Self::Workspace) -> &'w [f64] {
        &ws.data.drag_switches.normal_speeds
    }

    fn freeze_switches(&self, ws: &mut Self::Workspace, signs: Option<&[f64]>) {
        ws.data.drag_switches.freeze(signs);
    }

    fn workspace(&self) -> NetworkWorkspace {
        let n = self.model.columns();
        NetworkWorkspace {
            data: NetworkData::new(self.model),
            kkt: KktSystem::new(self.model).expect("the structure was analysed when the plant was made"),
            statics: HessianSystem::new(self.model).expect("the structure was analysed when the plant was made"),
            solver: projection_solver(),
            forces: vec![0.0; n],
            drive: vec![0.0; n],
            actuation_power: 0.0,
            drag_power: 0.0,
            angles: vec![0.0; n],
            rates: vec![0.0; n],
        }
    }

    fn dof(&self) -> usize {
        self.model.columns()
    }

    fn forcing(&self) -> &Forcing {
        &self.model.forcing
    }

    fn time_scales(&self) -> Result<TimeScales> {
        time_scales_of(
            &self.omegas()?,
            &self.model.forcing,
            "the network has no degree of freedom at its start",
        )
    }

    fn quasi_static_error_estimate(&self) -> Result<f64> {
        let mut ws = self.workspace();
        let start = self.regular_start().to_vec();
        let jump = |to: &[f64]| to.iter().zip(&start).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        Ok(match self.model.forcing.actuation {
            // A step's jump: from the start to the final balance.
            Actuation::Step => jump(&self.final_balance()?),
            Actuation::Ramp { .. } => {
                let omegas = self.omegas()?;
                let slowest = omegas.iter().copied().fold(f64::INFINITY, f64::min);
                let mut rest = vec![0.0; self.model.columns()];
                self.rest_angles(&mut rest);
                let settled = equilibrium(self.model, &rest, &start, &mut ws.statics)?;
                2.0 * fastest_drive_rate(&self.model.forcing) / slowest + jump(&settled.angles)
            }
        })
    }

    fn slowest_omega(&self) -> Result<f64> {
        let omegas = spring_frequencies(self.model, self.regular_start())?;
        omegas.into_iter().filter(|w| *w > 0.0).reduce(f64::min).ok_or_else(|| {
            NumericalError::NonFinite {
                what: "natural periods",
                detail: "the network has no degree of freedom at its start".into(),
            }
            .into()
        })
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        self.model.start.clone()
    }

    fn initial_state(&self) -> Result<InitialState> {
        Ok(match &self.start {
            Some(branch) => InitialState {
                time: branch.time,
                coordinates: branch.angles.clone(),
                rates: branch.rates.clone(),
                accumulated: vec![branch.work, branch.dissipation],
                note: Some(branch.note.clone()),
            },
            None => InitialState {
                time: 0.0,
                coordinates: self.model.start.clone(),
                rates: vec![0.0; self.model.columns()],
                accumulated: vec![0.0; 2],
                note: None,
            },
        })
    }

    fn accumulators(&self) -> usize {
        2
    }

    fn energy_scale(&self) -> f64 {
        energy_scale(self.model)
    }

    fn accumulator_rates(&self, ws: &NetworkWorkspace, out: &mut [f64]) {
        out[0] = ws.actuation_power;
        out[1] = -ws.drag_power;
    }

    fn project(&self, _t: f64, q: &mut [f64], q_dot: &mut [f64], ws: &mut NetworkWorkspace) -> Result<bool> {
        self.project_state(q, q_dot, ws)?;
        Ok(true)
    }

    fn accelerations(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        ws: &mut NetworkWorkspace,
        out: &mut [f64],
    ) -> Result<()> {
        self.evaluate(t, q, q_dot, ws, out)
    }

    fn sample(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        accumulated: &[f64],
        ws: &mut NetworkWorkspace,
    ) -> Result<Sample> {
        let mut angles = std::mem::take(&mut ws.angles);
        let mut rates = std::mem::take(&mut ws.rates);
        angles.copy_from_slice(q);
        rates.copy_from_slice(q_dot);
        // Every recorded state lies on the closures (an interpolated one drifts by up to the
        // integrator's tolerance).
        if worst_residual(self.model, &angles) > CLOSURE_TOL || rates.iter().any(|r| *r != 0.0) {
            self.project_state(&mut angles, &mut rates, ws)?;
        }
        let sample = network_sample(self.model, t, &angles, &rates, accumulated, &mut ws.data, &mut ws.drive);
        ws.angles = angles;
        ws.rates = rates;
        Ok(sample)
    }

    fn balance(&self, drive: &[f64], q: &mut [f64], ws: &mut NetworkWorkspace) -> Result<()> {
        let mut rest = drive.to_vec();
        for (c, r) in rest.iter_mut().enumerate() {
            if !self.model.forcing.hinges[c].actuated {
                *r = 0.0;
            }
        }
        self.rest_angles(&mut rest);
        let found = equilibrium(self.model, &rest, q, &mut ws.statics)?;
        q.copy_from_slice(&found.angles);
        Ok(())
    }

    fn balance_rates(
        &self,
        q: &[f64],
        drive: &[f64],
        drive_rates: &[f64],
        out: &mut [f64],
        ws: &mut NetworkWorkspace,
    ) -> Result<()> {
        // Differentiating K(ρ − r) + Jᵀλ = 0, Φ = 0 along the drive:
        // (K + Σ λ ∇²Φ) ρ̇ + Jᵀ λ̇ = K ṙ, J ρ̇ = 0.
        let model = self.model;
        let mut rest = drive.to_vec();
        for (c, r) in rest.iter_mut().enumerate() {
            if !model.forcing.hinges[c].actuated {
                *r = 0.0;
            }
        }
        self.rest_angles(&mut rest);
        let found = equilibrium(model, &rest, q, &mut ws.statics)?;
        let stiffness = model.stiffness();
        update_stars(model, &found.angles, None, &mut ws.data);
        ws.statics.assemble(&ws.data, &stiffness, Some(&found.multipliers))?;
        let scale = ws.statics.scale();
        let f: Vec<f64> = (0..model.columns())
            .map(|c| {
                if model.forcing.hinges[c].actuated && !model.locked(c) {
                    stiffness[c] * drive_rates[c] / scale
                } else {
                    0.0
                }
            })
            .collect();
        let b = vec![0.0; ws.statics.rows()];
        ws.statics.solve(&f, &b, out);
        Ok(())
    }

    fn check_samples(&self, _samples: &[Sample]) -> Result<()> {
        Ok(())
    }

    fn contact_count(&self) -> usize {
        self.contacts.count()
    }

    fn touching(&self, t: f64, q: &[f64], ws: &mut NetworkWorkspace) -> Option<Collision> {
        self.contacts.touching(self.model, t, q, &mut ws.data)
    }

    fn contact_lever(&self) -> f64 {
        self.model.size()
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut NetworkWorkspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        Box::new(NetworkProbe::new(
            self.model,
            &self.contacts,
            &mut ws.data,
            q,
            Box::new(move |u: f64, x: &mut [f64]| path(u, x)),
        ))
    }
}

/// Time scales from natural angular frequencies (rad/s, every one > 0) against the forcing;
/// `none` says why there are none.
pub(crate) fn time_scales_of(omegas: &[f64], forcing: &Forcing, none: &str) -> Result<TimeScales> {
    let fastest = omegas.iter().copied().fold(0.0, f64::max);
    let slowest = omegas.iter().copied().fold(f64::INFINITY, f64::min);
    if !(fastest > 0.0 && slowest.is_finite()) {
        return Err(NumericalError::NonFinite {
            what: "natural periods",
            detail: none.into(),
        }
        .into());
    }
    let duration = forcing.duration();
    Ok(TimeScales {
        fastest_period_s: TAU / fastest,
        slowest_period_s: TAU / slowest,
        forcing_time_s: duration,
        ratio: duration * fastest / TAU,
    })
}

/// The fastest drive rate of any actuated hinge with a target, rad/s (a ramp's, at release).
pub(crate) fn fastest_drive_rate(forcing: &Forcing) -> f64 {
    forcing
        .hinges
        .iter()
        .enumerate()
        .map(|(c, hinge)| {
            if hinge.actuated && hinge.target != 0.0 {
                forcing.drive_rate(c, hinge.release_time).abs()
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// A network run's report from its samples: closure residuals, the energy balance, the
/// pairs meeting at the first contact (`contact`: the run ended at one).
pub(crate) fn network_report(
    model: &NetworkModel,
    contacts: &NetworkContacts,
    branch: Option<String>,
    samples: &[Sample],
    contact: bool,
) -> NetworkRunReport {
    let max_closure_residual = samples
        .iter()
        .map(|s| worst_residual(model, s.angles.as_slice()))
        .fold(0.0, f64::max);
    let balances: Option<Vec<f64>> = samples.iter().map(|s| s.energy_balance()).collect();
    let energy_balance_error = balances.and_then(|b| {
        let first = *b.first()?;
        let scale = samples
            .iter()
            .map(|s| {
                s.kinetic_energy
                    .max(s.elastic_energy)
                    .max(s.actuation_work.unwrap_or(0.0).abs())
            })
            .fold(0.0, f64::max);
        let drift = b.iter().map(|x| (x - first).abs()).fold(0.0, f64::max);
        Some(if scale > 0.0 { drift / scale } else { 0.0 })
    });
    let meeting_at_contact = match (contact, samples.last()) {
        (true, Some(last)) => {
            let mut data = NetworkData::new(model);
            contacts.meeting(model, last.angles.as_slice(), &mut data, 1e-6)
        }
        _ => Vec::new(),
    };
    NetworkRunReport {
        meeting_at_contact,
        touching_at_start: contacts.touching_at_start().to_vec(),
        panels: model.panels(),
        creases: model.columns(),
        anchored_face: model.anchored_face,
        branch,
        max_closure_residual,
        energy_balance_error,
        reduced: None,
    }
}

/// ½ Σ K θ_target² over the creases (or ½ Σ K when nothing has a target), J: the scale of a
/// network's energies.
pub(crate) fn energy_scale(model: &NetworkModel) -> f64 {
    let scale: f64 = model
        .hinges
        .iter()
        .zip(&model.forcing.hinges)
        .map(|(h, d)| 0.5 * h.stiffness * d.target * d.target)
        .sum();
    if scale > 0.0 {
        scale
    } else {
        0.5 * model.hinges.iter().map(|h| h.stiffness).sum::<f64>()
    }
}

/// The sample at (t, ρ, ρ̇) (on the closures) with the accumulated work and dissipation.
pub(crate) fn network_sample(
    model: &NetworkModel,
    t: f64,
    angles: &[f64],
    rates: &[f64],
    accumulated: &[f64],
    data: &mut NetworkData,
    drive: &mut [f64],
) -> Sample {
    update_kinematics(model, angles, data);
    update_velocities(model, rates, data);
    model.forcing.drive_angles(t, drive);
    let (mut elastic, mut potential) = (0.0, 0.0);
    for (c, &angle) in angles.iter().enumerate() {
        let k = model.hinges[c].stiffness;
        elastic += 0.5 * k * angle * angle;
        if model.forcing.hinges[c].actuated {
            potential -= k * drive[c] * angle;
        }
    }
    Sample {
        time: t,
        angles: DVector::from_column_slice(angles),
        rates: DVector::from_column_slice(rates),
        kinetic_energy: kinetic_energy(model, data),
        elastic_energy: elastic,
        actuator_potential: potential,
        actuation_work: accumulated.first().copied(),
        drag_dissipation: accumulated.get(1).copied(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::forcing::HingeDrive;
    use crate::dynamics::integrate::{integrate, output_times, IntegrationOptions, Method};
    use crate::dynamics::network::model::NetworkParts;
    use crate::folding::FoldingModel;
    use crate::pattern::generate::MiuraSpec;

    fn folded_miura(drag: bool, zigzag: f64) -> NetworkModel {
        let spec = MiuraSpec {
            rows: 2,
            cols: 3,
            zigzag_fold_angle: zigzag,
            ..MiuraSpec::default()
        };
        let folding = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let state = folding.given_fold_angles();
        let n = folding.crease_count();
        let sign = |a: f64| if a >= 0.0 { 1.0 } else { -1.0 };
        let hinges = folding
            .pattern
            .creases
            .iter()
            .map(|&e| {
                let assignment = match folding.pattern.kinds[e] {
                    crate::pattern::crease_pattern::EdgeKind::Crease(crate::pattern::Assignment::Mountain) => -1.0,
                    _ => 1.0,
                };
                HingeDrive {
                    target: assignment * 1.2,
                    radius_of_curvature: 2e-5,
                    actuated: true,
                    release_time: 0.0,
                }
            })
            .collect();
        let _ = sign;
        NetworkModel::new(NetworkParts {
            folding,
            unit: 1e-4,
            anchored_panel: 0,
            thickness: 2e-7,
            density: 3270.0,
            stiffness: vec![3e-9; n],
            forcing: Forcing {
                actuation: Actuation::Step,
                hinges,
            },
            drag: drag.then_some(crate::dynamics::model::Drag {
                drag_coefficient: 1.28,
                air_density: 1.2,
            }),
            start: state,
            substrate_contact: false,
        })
        .unwrap()
    }

    #[test]
    fn a_flat_miura_leaves_along_its_branch() {
        let model = folded_miura(false, 0.0);
        let plant = NetworkPlant::new(&model, false).unwrap();
        let branch = plant.branch().unwrap();
        eprintln!(
            "{} t {:e} angles {:?} rates {:?}",
            branch.note, branch.time, branch.angles, branch.rates
        );
        let period = plant.time_scales().unwrap().slowest_period_s;
        let run = integrate(
            &plant,
            Method::Tsit45,
            &output_times(2.0 * period, 51),
            IntegrationOptions {
                rtol: 1e-10,
                progress: None,
                record_steps: true,
                max_steps: 1_000_000,
            },
        )
        .unwrap();
        let first = run.samples[0].energy_balance().unwrap();
        let scale = run.samples.iter().map(|s| s.kinetic_energy).fold(0.0, f64::max);
        let drift = run
            .samples
            .iter()
            .map(|s| (s.energy_balance().unwrap() - first).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "steps {} drift {:.3e} last {:?}",
            run.steps,
            drift / scale,
            run.samples.last().unwrap().angles.as_slice()
        );
    }

    #[test]
    fn a_folded_miura_conserves_energy_and_closure() {
        let model = folded_miura(false, 1.1);
        let plant = NetworkPlant::new(&model, false).unwrap();
        let period = plant.time_scales().unwrap().slowest_period_s;
        let run = integrate(
            &plant,
            Method::Tsit45,
            &output_times(5.0 * period, 51),
            IntegrationOptions {
                rtol: 1e-10,
                progress: None,
                record_steps: true,
                max_steps: 1_000_000,
            },
        )
        .unwrap();
        let first = run.samples[0].energy_balance().unwrap();
        let scale = run.samples.iter().map(|s| s.kinetic_energy).fold(0.0, f64::max);
        let drift = run
            .samples
            .iter()
            .map(|s| (s.energy_balance().unwrap() - first).abs())
            .fold(0.0, f64::max);
        let closure = run
            .samples
            .iter()
            .map(|s| super::super::manifold::worst_residual(&model, s.angles.as_slice()))
            .fold(0.0, f64::max);
        eprintln!(
            "steps {} evals {} period {period:e} ke {scale:e} drift {:.3e} closure {closure:.3e} last {:?}",
            run.steps,
            run.rhs_evaluations,
            drift / scale,
            run.samples.last().unwrap().angles.as_slice()
        );
        assert!(drift < 1e-8 * scale, "energy drift {drift:e} of {scale:e}");
        assert!(closure < 1e-10, "closure {closure:e}");
    }
}
