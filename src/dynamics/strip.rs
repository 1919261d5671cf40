//! A strip of plates on parallel hinges (`docs/model.md#strip`): the open chain of the
//! bridge, anchored at the substrate's edge. Its forcing, contacts (plate corners against the
//! substrate where it remains and against non-adjacent plates), time scales and the
//! [`Plant`] the simulation drives.

use super::algorithms::{
    forward_dynamics, kinetic_energy, update_corners, update_kinematics, update_mass_matrix, update_poses,
};
use super::contact::{Collision, ContactProbe};
use super::forcing::{Actuation, Forcing};
use super::model::{Data, Model};
use super::modes::modes;
use super::plant::{Plant, Sample, TimeScales};
use crate::error::{NumericalError, Result};
use nalgebra::{DVector, Point3, Vector3};

/// A validated strip: plates in a row along +y from the substrate edge, creases parallel to
/// x, flat in the plane z = 0 at rest.
#[derive(Debug, Clone)]
pub struct StripChain {
    /// The serial chain, hinge 0 anchored to the substrate.
    pub model: Model,
    /// What drives each hinge.
    pub forcing: Forcing,
    /// The substrate is present for y ≤ this, m.
    pub substrate_edge_y: f64,
}

impl StripChain {
    /// θ_target per hinge, rad (0 for passive hinges).
    pub fn target_angles(&self) -> DVector<f64> {
        DVector::from_iterator(self.model.dof(), self.forcing.hinges.iter().map(|h| h.target))
    }

    /// Input torques τ = K θ_drive(t), N·m.
    pub fn torques(&self, t: f64, out: &mut [f64]) {
        self.forcing.drive_angles(t, out);
        for (tau, joint) in out.iter_mut().zip(self.model.joints()) {
            *tau *= joint.stiffness;
        }
    }

    /// Fastest and slowest natural periods over the flat and the target configurations.
    pub fn time_scales(&self) -> Result<TimeScales> {
        let n = self.model.dof();
        let mut fastest = f64::INFINITY;
        let mut slowest: f64 = 0.0;
        for angles in [DVector::zeros(n), self.target_angles()] {
            let m = modes(&self.model, angles.as_slice())?;
            for f in m.frequencies_hz {
                fastest = fastest.min(1.0 / f);
                slowest = slowest.max(1.0 / f);
            }
        }
        let forcing = self.forcing.duration();
        Ok(TimeScales {
            fastest_period_s: fastest,
            slowest_period_s: slowest,
            forcing_time_s: forcing,
            ratio: forcing / fastest,
        })
    }

    /// Linear bound on how far the dynamics can stray from the quasi-static path
    /// (`docs/model.md#model-choice`). Each jump the dynamics cannot follow starts free
    /// oscillations in the modes of the configuration where it happens: a step's drive angle
    /// Δθ, or a change Δṙ of the ramp's drive rate (at t = 0 and where each hinge reaches its
    /// target). With M ë + K e = 0,
    ///   step: |e_i| ≤ Σ_k |φ̂_ki| |φ̂_kᵀ M Δθ|,   ramp: |e_i| ≤ Σ_k |φ̂_ki| |φ̂_kᵀ M Δṙ| / ω_k
    /// (φ̂ mass-normalised); the bound sums over jumps since drag-free oscillations add up.
    pub fn quasi_static_error_estimate(&self) -> Result<f64> {
        let n = self.model.dof();
        let mut data = Data::new(&self.model);
        let mut bound = DVector::<f64>::zeros(n);
        let mut add_jump = |at: &[f64], jump: &DVector<f64>, per_frequency: bool| -> Result<()> {
            let modes = modes(&self.model, at)?;
            update_kinematics(&self.model, at, &mut data);
            update_mass_matrix(&self.model, &mut data);
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
        match self.forcing.actuation {
            Actuation::Step => add_jump(&vec![0.0; n], &self.target_angles(), false)?,
            Actuation::Ramp { .. } => {
                let rate = DVector::from_fn(n, |i, _| self.forcing.drive_rate(i, 0.0));
                add_jump(&vec![0.0; n], &rate, true)?;
                let mut at = vec![0.0; n];
                for i in (0..n).filter(|&i| rate[i] != 0.0) {
                    self.forcing.drive_angles(self.forcing.ramp_time(i), &mut at);
                    let jump = DVector::from_fn(n, |j, _| if j == i { rate[i] } else { 0.0 });
                    add_jump(&at, &jump, true)?;
                }
            }
        }
        Ok(bound.amax())
    }
}

/// A strip as an integrator [`Plant`]: q = θ, the hinge angles.
pub struct StripPlant<'s> {
    chain: &'s StripChain,
    contacts: Option<ContactSet>,
}

impl<'s> StripPlant<'s> {
    /// The plant, with its contact candidates unless `collisions` is false.
    pub fn new(chain: &'s StripChain, collisions: bool) -> Self {
        StripPlant {
            chain,
            contacts: collisions.then(|| ContactSet::new(&chain.model, chain.substrate_edge_y)),
        }
    }
}

/// Scratch of a [`StripPlant`]: the model's buffers and the hinge torques.
pub struct StripWorkspace {
    data: Data,
    torques: Vec<f64>,
}

impl Plant for StripPlant<'_> {
    type Workspace = StripWorkspace;

    fn switches<'w>(&self, ws: &'w Self::Workspace) -> &'w [f64] {
        &ws.data.drag_switches.normal_speeds
    }

    fn freeze_switches(&self, ws: &mut Self::Workspace, signs: Option<&[f64]>) {
        ws.data.drag_switches.freeze(signs);
    }

    fn workspace(&self) -> StripWorkspace {
        StripWorkspace {
            data: Data::new(&self.chain.model),
            torques: vec![0.0; self.dof()],
        }
    }

    fn dof(&self) -> usize {
        self.chain.model.dof()
    }

    fn forcing(&self) -> &Forcing {
        &self.chain.forcing
    }

    fn time_scales(&self) -> Result<TimeScales> {
        self.chain.time_scales()
    }

    fn quasi_static_error_estimate(&self) -> Result<f64> {
        self.chain.quasi_static_error_estimate()
    }

    fn slowest_omega(&self) -> Result<f64> {
        let flat = modes(&self.chain.model, &vec![0.0; self.dof()])?;
        Ok(flat.eigenvalues.last().copied().unwrap_or(1.0).sqrt())
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        vec![0.0; self.dof()]
    }

    fn accelerations(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut StripWorkspace, out: &mut [f64]) -> Result<()> {
        self.chain.torques(t, &mut ws.torques);
        forward_dynamics(&self.chain.model, q, q_dot, &ws.torques, &mut ws.data, out)
    }

    fn sample(
        &self,
        t: f64,
        q: &[f64],
        q_dot: &[f64],
        _accumulated: &[f64],
        ws: &mut StripWorkspace,
    ) -> Result<Sample> {
        let model = &self.chain.model;
        update_kinematics(model, q, &mut ws.data);
        update_mass_matrix(model, &mut ws.data);
        self.chain.torques(t, &mut ws.torques);
        Ok(Sample {
            time: t,
            angles: DVector::from_column_slice(q),
            rates: DVector::from_column_slice(q_dot),
            kinetic_energy: kinetic_energy(q_dot, &ws.data),
            elastic_energy: 0.5
                * model
                    .joints()
                    .iter()
                    .zip(q)
                    .map(|(j, a)| j.stiffness * a * a)
                    .sum::<f64>(),
            actuator_potential: -ws.torques.iter().zip(q).map(|(t, a)| t * a).sum::<f64>(),
            actuation_work: None,
            drag_dissipation: None,
        })
    }

    fn balance(&self, drive: &[f64], q: &mut [f64], _ws: &mut StripWorkspace) -> Result<()> {
        // K θ = K θ_drive with K diagonal and positive.
        q.copy_from_slice(drive);
        Ok(())
    }

    fn balance_rates(
        &self,
        _q: &[f64],
        _drive: &[f64],
        drive_rates: &[f64],
        out: &mut [f64],
        _ws: &mut StripWorkspace,
    ) -> Result<()> {
        out.copy_from_slice(drive_rates);
        Ok(())
    }

    fn check_samples(&self, samples: &[Sample]) -> Result<()> {
        match samples
            .iter()
            .find(|s| s.angles.iter().chain(s.rates.iter()).any(|v| !v.is_finite()))
        {
            Some(s) => Err(NumericalError::NonFinite {
                what: "strip dynamics",
                detail: format!("a hinge angle or rate is NaN or infinite at t = {:.6e} s", s.time),
            }
            .into()),
            None => Ok(()),
        }
    }

    fn contact_count(&self) -> usize {
        self.contacts.as_ref().map_or(0, ContactSet::len)
    }

    fn touching(&self, t: f64, q: &[f64], ws: &mut StripWorkspace) -> Option<Collision> {
        let contacts = self.contacts.as_ref()?;
        update_kinematics(&self.chain.model, q, &mut ws.data);
        update_corners(&self.chain.model, &mut ws.data);
        contacts.touching(t, &ws.data)
    }

    fn contact_lever(&self) -> f64 {
        ContactSet::lever(&self.chain.model)
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut StripWorkspace,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        Box::new(ChainProbe {
            contacts: self.contacts.as_ref().expect("probe needs contacts"),
            model: &self.chain.model,
            data: &mut ws.data,
            angles: q,
            path,
        })
    }
}

/// What touched what.
#[derive(Debug, Clone, Copy, PartialEq)]
enum StripCandidate {
    /// Corner `corner` of plate `plate` against the substrate.
    Substrate { plate: usize, corner: usize },
    /// Corner `corner` of plate `plate` against the face of plate `face`.
    Face { face: usize, plate: usize, corner: usize },
}

/// All contact candidates of a chain.
#[derive(Debug, Clone)]
pub struct ContactSet {
    candidates: Vec<StripCandidate>,
    /// Where each plate's corners start in [`Data::corners`].
    corner_start: Vec<usize>,
    substrate_edge_y: f64,
    /// Gaps within this distance count as touching, m (1e-9 of the chain's length).
    touch_tolerance: f64,
}

impl ContactSet {
    /// Every plate corner against the substrate, except corners on the anchoring hinge's
    /// line (they sit on the substrate edge by construction); every corner against the face
    /// of every plate at least two links away.
    pub fn new(model: &Model, substrate_edge_y: f64) -> Self {
        let n = model.dof();
        let chain_length: f64 = model.plates().iter().map(|p| 2.0 * p.radius()).sum();
        let touch_tolerance = 1e-9 * chain_length;
        let mut candidates = Vec::new();
        let anchor = &model.joints()[0];
        for (i, plate) in model.plates().iter().enumerate() {
            for (c, corner) in plate.outline.iter().enumerate() {
                let world = plate.reference_pose * corner;
                let offset = world - anchor.point;
                let off_axis = offset - anchor.axis.into_inner() * offset.dot(&anchor.axis);
                if off_axis.norm() > touch_tolerance {
                    candidates.push(StripCandidate::Substrate { plate: i, corner: c });
                }
            }
        }
        for face in 0..n {
            for plate in 0..n {
                if face.abs_diff(plate) >= 2 {
                    for corner in 0..model.plates()[plate].outline.len() {
                        candidates.push(StripCandidate::Face { face, plate, corner });
                    }
                }
            }
        }
        ContactSet {
            candidates,
            corner_start: (0..n).map(|i| model.corner_index(i, 0)).collect(),
            substrate_edge_y,
            touch_tolerance,
        }
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.candidates.len()
    }

    fn corner_world(&self, data: &Data, plate: usize, corner: usize) -> Point3<f64> {
        data.corners[self.corner_start[plate] + corner]
    }

    /// Signed gap of candidate k (needs kinematics): negative means penetration.
    fn gap(&self, k: usize, data: &Data) -> f64 {
        match self.candidates[k] {
            StripCandidate::Substrate { plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let (dy, dz) = (p.y - self.substrate_edge_y, p.z);
                // Signed distance to the quarter-space {y ≤ edge, z ≤ 0}, minus the touch tolerance.
                let distance = if dy > 0.0 && dz > 0.0 { dy.hypot(dz) } else { dy.max(dz) };
                distance - self.touch_tolerance
            }
            StripCandidate::Face { face, plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let pose = &data.poses[face];
                let normal = pose.rotation * Vector3::z();
                normal.dot(&(p - pose.translation.vector).coords)
            }
        }
    }

    /// Whether a zero of candidate k's gap is a real contact (the corner lies on the face).
    fn gate(&self, k: usize, model: &Model, data: &Data) -> bool {
        match self.candidates[k] {
            StripCandidate::Substrate { .. } => true,
            StripCandidate::Face { face, plate, corner } => {
                let p = self.corner_world(data, plate, corner);
                let local = data.poses[face].inverse_transform_point(&p);
                model.plates()[face].contains(&local, self.touch_tolerance)
            }
        }
    }

    /// A contact already present in `data`'s configuration (e.g. at t = 0).
    pub fn touching(&self, time: f64, data: &Data) -> Option<Collision> {
        (0..self.len())
            .find(|&k| matches!(self.candidates[k], StripCandidate::Substrate { .. }) && self.gap(k, data) <= 0.0)
            .map(|k| self.collision(k, time, data))
    }

    fn collision(&self, k: usize, time: f64, data: &Data) -> Collision {
        let (pair, plate, corner) = match self.candidates[k] {
            StripCandidate::Substrate { plate, corner } => {
                ([format!("plate {plate}"), "substrate".into()], plate, corner)
            }
            StripCandidate::Face { face, plate, corner } => {
                ([format!("plate {plate}"), format!("plate {face}")], plate, corner)
            }
        };
        Collision {
            time,
            pair,
            point: self.corner_world(data, plate, corner).coords,
        }
    }

    /// An upper bound on how far any corner can be from any hinge axis upstream of it, m:
    /// the sum of the plates' diagonals. A corner moves at most this × Σ|θ̇_j|.
    pub fn lever(model: &Model) -> f64 {
        model.plates().iter().map(|p| 2.0 * p.radius()).sum()
    }
}

/// A strip's [`ContactSet`] along a path of joint angles.
struct ChainProbe<'a> {
    contacts: &'a ContactSet,
    model: &'a Model,
    data: &'a mut Data,
    angles: &'a mut [f64],
    /// Joint angles at a path parameter.
    path: &'a mut dyn FnMut(f64, &mut [f64]),
}

impl ContactProbe for ChainProbe<'_> {
    fn count(&self) -> usize {
        self.contacts.len()
    }

    fn move_to(&mut self, t: f64) {
        (self.path)(t, self.angles);
        update_poses(self.model, self.angles, self.data);
        update_corners(self.model, self.data);
    }

    fn gap(&self, k: usize) -> f64 {
        self.contacts.gap(k, self.data)
    }

    fn gate(&self, k: usize) -> bool {
        self.contacts.gate(k, self.model, self.data)
    }

    fn collision(&self, k: usize, t: f64) -> Collision {
        self.contacts.collision(k, t, self.data)
    }
}
