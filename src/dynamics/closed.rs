//! Closed chains (`docs/model.md#closed-chains`): a single vertex cut at one unactuated
//! crease, its sectors as plates on a kinematic tree rooted at the anchored sector (the
//! creases on either side of it up to the cut), tied back by θ_r = f(θ_c). One driving crease remains after the locks, so the generalised coordinate q
//! is its angle and, with g = ∂θ/∂q (1 for the driver, G for the dependents, 0 when held) and
//! h = ∂²θ/∂q² (f″),
//!   (gᵀ M g) q̈ = τ_q − gᵀ [M h q̇² + C(θ, g q̇) g q̇] − Σ_creases K ρ g + gᵀ Q_drag,
//! the reduced equation Gᵀ[M(G θ̈_c + Ġ θ̇_c) + C G θ̇_c + N] = τ_c written for one coordinate.
//! The elastic sum runs over every crease, the cut one included: it is a hinge too.

pub(crate) mod assemble;
pub(crate) mod modes;
pub(crate) mod statics;
pub use modes::ClosureState;

use super::algorithms::{
    coriolis_torques, drag_torques, quadratic_form, update_corners, update_kinematics, update_mass_matrix,
    update_poses, update_velocities,
};
use super::contact::{Collision, ContactProbe};
use super::forcing::{Actuation, Forcing};
use super::model::{convex_contains, Data, Model};
use super::plant::{Plant, Sample, TimeScales};
use crate::constraints::exact::{ConstraintPoint, ExactConstraint};
use crate::constraints::ConstraintPoly;
use crate::error::{NanofoldError, NumericalError, Result};
use crate::geometry::kinematics::closure_residual;
use nalgebra::{DVector, Point3, Vector3};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// Where f comes from (`docs/model.md#constraint-curves`).
#[derive(Debug, Clone)]
pub enum ConstraintSource {
    /// The fitted polynomial and its derivatives.
    Poly(ConstraintPoly),
    /// Newton loop closure at every evaluation, G by the implicit function theorem.
    Exact(ExactConstraint),
}

impl ConstraintSource {
    /// "poly" or "exact".
    pub fn name(&self) -> &'static str {
        match self {
            ConstraintSource::Poly(_) => "poly",
            ConstraintSource::Exact(_) => "exact",
        }
    }

    pub(crate) fn evaluate(&self, theta: f64, point: &mut ConstraintPoint) -> Result<()> {
        match self {
            ConstraintSource::Poly(poly) => poly.evaluate_extended(theta, DOMAIN_MARGIN, point),
            ConstraintSource::Exact(exact) => exact.evaluate_extended(theta, DOMAIN_MARGIN, point),
        }
    }

    /// The fit's largest errors against the exact sweep samples: (|f − exact| rad,
    /// |f′ − G|), both 0 for the exact source.
    pub fn errors(&self) -> (f64, f64) {
        let largest = |errors: &[f64]| errors.iter().copied().fold(0.0, f64::max);
        match self {
            ConstraintSource::Poly(p) => (largest(&p.max_fit_error), largest(&p.max_slope_error)),
            ConstraintSource::Exact(_) => (0.0, 0.0),
        }
    }

    /// The polynomial's degree (poly only).
    pub fn degree(&self) -> Option<usize> {
        match self {
            ConstraintSource::Poly(p) => Some(p.degree()),
            ConstraintSource::Exact(_) => None,
        }
    }

    /// The fitted (or swept) interval of the driving angle, rad.
    pub fn domain(&self) -> [f64; 2] {
        match self {
            ConstraintSource::Poly(poly) => poly.fitted.domain,
            ConstraintSource::Exact(exact) => exact.domain,
        }
    }
}

/// Trial states of an integrator step may overshoot the constraint's domain by this much
/// (rad) before an evaluation fails: f is extrapolated there. A recorded state outside the
/// domain is an error (see [`ClosedChain::check_samples`]).
pub const DOMAIN_MARGIN: f64 = 0.1;

/// Two sector plates touch when a fold angle reaches ±π to within this, rad.
const FOLD_TOUCH: f64 = 1e-9;

/// An immutable closed-chain description: geometry, hinges, the constraint and the forcing.
#[derive(Debug, Clone)]
pub struct ClosedChain {
    /// The sector plates on a tree rooted at the anchored sector: joint j turns about the ray
    /// of crease `joint_creases[j]` and carries the plate of sector `joint_sectors[j]`.
    pub model: Model,
    /// The crease of every joint.
    pub joint_creases: Vec<usize>,
    /// The sector every joint's plate covers (sector k lies between rays k and k + 1).
    pub joint_sectors: Vec<usize>,
    /// The anchored sector (on the substrate).
    pub ground_sector: usize,
    /// The anchored sector's outline (world frame, flat, m).
    pub ground: Vec<Point3<f64>>,
    /// Where the loop is cut (a crease index).
    pub cut_crease: usize,
    /// Hinge stiffness of every crease (file order), N·m/rad.
    pub crease_stiffness: Vec<f64>,
    /// How errors and outputs name every crease.
    pub crease_labels: Vec<String>,
    /// The far end of every crease in the flat state (world frame, m).
    pub crease_ends: Vec<Point3<f64>>,
    /// The driving crease.
    pub driver: usize,
    /// Held creases and their angles, rad.
    pub locked: Vec<(usize, f64)>,
    /// The creases that follow the driver, in the order of the constraint's values.
    pub dependents: Vec<usize>,
    /// f and its derivatives.
    pub source: ConstraintSource,
    /// Sector angles, for loop-closure residuals.
    pub sector_angles: Vec<f64>,
    /// The ray of every crease.
    pub crease_rays: Vec<usize>,
    /// Driver angle at rest at t = 0, rad.
    pub start: f64,
    /// The file's index of every crease (FOLD edge index), for reports.
    pub crease_user_indices: Vec<usize>,
    /// FOLD face index of the anchored sector.
    pub anchored_face: usize,
    /// The FOLD face of every sector (its plate), if it has one.
    pub sector_faces: Vec<Option<usize>>,
    /// The vertex in the file's flat coordinates times the length unit, m: the chain's world
    /// frame is the flat sheet about it.
    pub vertex: [f64; 2],
    /// What drives every crease: only the driver is actuated.
    pub forcing: Forcing,
}

/// Scratch of a [`ClosedChain`]: the open chain's buffers and the constraint's values.
#[derive(Debug, Clone)]
pub struct ClosedData {
    /// The tree's rigid-body buffers.
    pub data: Data,
    point: ConstraintPoint,
    /// Every crease's angle, ∂θ/∂q and ∂²θ/∂q² (file order).
    pub crease_angles: Vec<f64>,
    /// Every crease's ∂θ/∂q.
    pub crease_g: Vec<f64>,
    /// Every crease's ∂²θ/∂q².
    pub crease_h: Vec<f64>,
    joint_angles: Vec<f64>,
    joint_rates: Vec<f64>,
    joint_g: Vec<f64>,
    joint_h: Vec<f64>,
    coriolis: Vec<f64>,
    drag: Vec<f64>,
}

impl ClosedChain {
    /// Scratch buffers sized for this chain.
    pub fn workspace(&self) -> ClosedData {
        let (n, c) = (self.model.dof(), self.crease_stiffness.len());
        ClosedData {
            data: Data::new(&self.model),
            point: ConstraintPoint::zeros(self.dependents.len()),
            crease_angles: vec![0.0; c],
            crease_g: vec![0.0; c],
            crease_h: vec![0.0; c],
            joint_angles: vec![0.0; n],
            joint_rates: vec![0.0; n],
            joint_g: vec![0.0; n],
            joint_h: vec![0.0; n],
            coriolis: vec![0.0; n],
            drag: vec![0.0; n],
        }
    }

    /// Fills every crease's angle, g and h at driving angle q, and the joints' from them.
    /// Beyond the domain's margin f is frozen at the margin's edge: only trial stages and
    /// states past a located contact go there, and a recorded state outside the domain is an
    /// error ([`ClosedChain::check_samples`]).
    pub fn update_creases(&self, q: f64, ws: &mut ClosedData) -> Result<()> {
        let [lo, hi] = self.source.domain();
        let q_in = if q.is_finite() {
            q.clamp(lo - DOMAIN_MARGIN, hi + DOMAIN_MARGIN)
        } else {
            q
        };
        self.source.evaluate(q_in, &mut ws.point)?;
        ws.crease_angles[self.driver] = q;
        ws.crease_g[self.driver] = 1.0;
        ws.crease_h[self.driver] = 0.0;
        for &(c, value) in &self.locked {
            ws.crease_angles[c] = value;
            ws.crease_g[c] = 0.0;
            ws.crease_h[c] = 0.0;
        }
        for (k, &c) in self.dependents.iter().enumerate() {
            ws.crease_angles[c] = ws.point.values[k];
            ws.crease_g[c] = ws.point.jacobian[k];
            ws.crease_h[c] = ws.point.curvature[k];
        }
        for (j, &c) in self.joint_creases.iter().enumerate() {
            ws.joint_angles[j] = ws.crease_angles[c];
            ws.joint_g[j] = ws.crease_g[c];
            ws.joint_h[j] = ws.crease_h[c];
        }
        Ok(())
    }

    /// The driver's target angle, rad.
    pub fn target(&self) -> f64 {
        self.forcing.hinges[self.driver].target
    }

    /// The angle the driving hinge's stressed layer drives to at time t, rad.
    pub fn drive_angle(&self, t: f64) -> f64 {
        self.forcing.drive_angle(self.driver, t)
    }

    /// τ_q(t) = K_driver θ_drive(t): the driving hinge's stressed-layer torque.
    pub fn drive_torque(&self, t: f64) -> f64 {
        self.crease_stiffness[self.driver] * self.drive_angle(t)
    }

    /// The plate of sector `sector`: None for the anchored sector, else its joint.
    pub fn body_of_sector(&self, sector: usize) -> Option<usize> {
        self.joint_sectors.iter().position(|&s| s == sector)
    }

    /// Reduced mass gᵀ M g (kg·m²) and stiffness Σ K g² (N·m/rad) at q.
    pub fn reduced_mass_and_stiffness(&self, q: f64, ws: &mut ClosedData) -> Result<(f64, f64)> {
        self.update_creases(q, ws)?;
        update_kinematics(&self.model, &ws.joint_angles, &mut ws.data);
        update_mass_matrix(&self.model, &mut ws.data);
        let mass = 2.0 * quadratic_form(&ws.data.mass_matrix, &ws.joint_g);
        let stiffness = self
            .crease_stiffness
            .iter()
            .zip(&ws.crease_g)
            .map(|(k, g)| k * g * g)
            .sum();
        Ok((mass, stiffness))
    }

    /// q̈ at (t, q, q̇).
    pub fn acceleration(&self, t: f64, q: f64, q_dot: f64, ws: &mut ClosedData) -> Result<f64> {
        self.update_creases(q, ws)?;
        let n = self.model.dof();
        for j in 0..n {
            ws.joint_rates[j] = ws.joint_g[j] * q_dot;
        }
        let model = &self.model;
        update_kinematics(model, &ws.joint_angles, &mut ws.data);
        update_mass_matrix(model, &mut ws.data);
        update_velocities(model, &ws.joint_rates, &mut ws.data);
        coriolis_torques(model, &ws.joint_rates, &mut ws.data, &mut ws.coriolis);
        drag_torques(model, &mut ws.data, &mut ws.drag);
        let m = &ws.data.mass_matrix;
        let mut reduced_mass = 0.0;
        let mut force = self.drive_torque(t);
        for i in 0..n {
            let (mut mg, mut mh) = (0.0, 0.0);
            for j in 0..n {
                mg += m[(i, j)] * ws.joint_g[j];
                mh += m[(i, j)] * ws.joint_h[j];
            }
            reduced_mass += ws.joint_g[i] * mg;
            force += ws.joint_g[i] * (ws.drag[i] - ws.coriolis[i] - mh * q_dot * q_dot);
        }
        for (c, k) in self.crease_stiffness.iter().enumerate() {
            force -= k * ws.crease_angles[c] * ws.crease_g[c];
        }
        if reduced_mass.is_nan() || reduced_mass <= 0.0 {
            return Err(NumericalError::NotPositiveDefinite {
                matrix: "the reduced mass gᵀMg",
                at: format!("q = {q} rad (gᵀMg = {reduced_mass:e})"),
            }
            .into());
        }
        Ok(force / reduced_mass)
    }

    /// T5.24–5.25 at the target: the torque the driving hinge must supply to hold it against
    /// every hinge of the loop, Σ K ρ g, over what its own stressed layer gives, K θ_target.
    pub fn torque_magnification(&self) -> Result<f64> {
        let mut ws = self.workspace();
        let [lo, hi] = self.source.domain();
        let target = self.target();
        self.update_creases(target.clamp(lo, hi), &mut ws)?;
        let drive = self.crease_stiffness[self.driver] * target;
        let holding: f64 = (0..self.crease_stiffness.len())
            .filter(|&c| c != self.driver)
            .map(|c| self.crease_stiffness[c] * ws.crease_angles[c] * ws.crease_g[c])
            .sum::<f64>()
            + drive;
        Ok(holding / drive)
    }

    /// Loop-closure residual of the crease angles in `ws`, rad.
    pub fn closure_residual(&self, ws: &ClosedData) -> f64 {
        let mut rho = vec![0.0; self.sector_angles.len()];
        for (c, &ray) in self.crease_rays.iter().enumerate() {
            rho[ray] = ws.crease_angles[c];
        }
        closure_residual(&self.sector_angles, &rho)
    }

    /// An output sample: every crease's angle and rate, the energies.
    pub fn sample(&self, t: f64, q: f64, q_dot: f64, ws: &mut ClosedData) -> Result<Sample> {
        let (reduced_mass, _) = self.reduced_mass_and_stiffness(q, ws)?;
        let elastic = 0.5
            * self
                .crease_stiffness
                .iter()
                .zip(&ws.crease_angles)
                .map(|(k, a)| k * a * a)
                .sum::<f64>();
        Ok(Sample {
            time: t,
            angles: DVector::from_column_slice(&ws.crease_angles),
            rates: DVector::from_iterator(ws.crease_g.len(), ws.crease_g.iter().map(|g| g * q_dot)),
            kinetic_energy: 0.5 * reduced_mass * q_dot * q_dot,
            elastic_energy: elastic,
            actuator_potential: -self.drive_torque(t) * q,
            actuation_work: None,
            drag_dissipation: None,
        })
    }

    /// An error when a recorded state left the constraint's domain (extrapolated f).
    pub fn check_samples(&self, samples: &[Sample]) -> Result<()> {
        let [lo, hi] = self.source.domain();
        let slack = 1e-9;
        match samples.iter().find(|s| {
            let q = s.angles[self.driver];
            q < lo - slack || q > hi + slack
        }) {
            Some(s) => Err(NanofoldError::OutsideFitDomain {
                driver: format!("{} (at t = {:.6e} s)", self.crease_labels[self.driver], s.time),
                value_deg: s.angles[self.driver].to_degrees(),
                lower_deg: lo.to_degrees(),
                upper_deg: hi.to_degrees(),
            }),
            None => Ok(()),
        }
    }

    /// Largest distance of a plate corner from the vertex, m: corners move at most this × |θ̇|
    /// summed over the joints.
    fn lever(&self) -> f64 {
        self.model
            .plates()
            .iter()
            .map(|p| {
                p.outline
                    .iter()
                    .map(|c| (p.reference_pose * c).coords.norm())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    }
}

/// A contact candidate of a closed chain.
#[derive(Debug, Clone, Copy)]
enum Candidate {
    /// Two neighbouring sectors fold flat onto each other: |ρ| reaches π.
    Fold { crease: usize },
    /// A corner (not the vertex) of sector plate `plate` crosses the face of a sector that is
    /// not its neighbour (`face`; `None` for the anchored sector). Plates are indexed by joint.
    Face {
        face: Option<usize>,
        plate: usize,
        corner: usize,
    },
}

/// The closed chain as an integrator [`Plant`], with its contact candidates.
pub struct ClosedPlant<'c> {
    chain: &'c ClosedChain,
    candidates: Vec<Candidate>,
    touch_tolerance: f64,
    /// max over the domain of Σ_j |∂θ_j/∂q|, sampled.
    rate_gain: f64,
}

impl<'c> ClosedPlant<'c> {
    /// Candidates: every moving crease folding flat; every corner of a sector plate except the
    /// vertex against every sector two or more creases away around the vertex (the anchored
    /// one included). Corners that only graze a face's boundary (edges meeting along a line,
    /// as the cube's edges do) are not contacts: the gate needs the corner strictly inside.
    pub fn new(chain: &'c ClosedChain, collisions: bool) -> Self {
        let mut candidates = Vec::new();
        let touch_tolerance = 1e-9 * chain.lever();
        if collisions {
            for c in (0..chain.crease_stiffness.len()).filter(|c| !chain.locked.iter().any(|(l, _)| l == c)) {
                candidates.push(Candidate::Fold { crease: c });
            }
            // Sectors two or more creases apart around the vertex can touch; neighbours meet
            // along their shared crease.
            let sectors = chain.model.dof() + 1;
            let apart = |a: usize, b: usize| {
                let d = a.abs_diff(b);
                d.min(sectors - d) >= 2
            };
            let bodies: Vec<(Option<usize>, usize)> = std::iter::once((None, chain.ground_sector))
                .chain(chain.joint_sectors.iter().enumerate().map(|(j, &s)| (Some(j), s)))
                .collect();
            for plate in 0..chain.model.dof() {
                let outline = &chain.model.plates()[plate].outline;
                for (corner, local) in outline.iter().enumerate() {
                    let world = chain.model.plates()[plate].reference_pose * local;
                    if world.coords.norm() <= touch_tolerance {
                        continue;
                    }
                    for &(face, sector) in &bodies {
                        if apart(sector, chain.joint_sectors[plate]) {
                            candidates.push(Candidate::Face { face, plate, corner });
                        }
                    }
                }
            }
        }
        // Σ|g| over the domain, sampled densely, with a margin for what falls between samples.
        let [lo, hi] = chain.source.domain();
        let mut ws = chain.workspace();
        let rate_gain = (0..=200)
            .filter_map(|k| {
                let q = lo + (hi - lo) * k as f64 / 200.0;
                chain.update_creases(q, &mut ws).ok()?;
                Some(ws.joint_g.iter().map(|g| g.abs()).sum::<f64>())
            })
            .fold(1.0, f64::max);
        ClosedPlant {
            chain,
            candidates,
            touch_tolerance,
            rate_gain: 1.5 * rate_gain,
        }
    }

    fn gap(&self, k: usize, ws: &ClosedData) -> f64 {
        match self.candidates[k] {
            Candidate::Fold { crease } => PI - ws.crease_angles[crease].abs() - FOLD_TOUCH,
            Candidate::Face { face, plate, corner } => {
                let p = ws.data.corners[self.chain.model.corner_index(plate, corner)];
                match face {
                    None => p.z,
                    Some(f) => {
                        let pose = &ws.data.poses[f];
                        (pose.rotation * Vector3::z()).dot(&(p - pose.translation.vector).coords)
                    }
                }
            }
        }
    }

    fn gate(&self, k: usize, ws: &ClosedData) -> bool {
        match self.candidates[k] {
            Candidate::Fold { .. } => true,
            Candidate::Face { face, plate, corner } => {
                let p = ws.data.corners[self.chain.model.corner_index(plate, corner)];
                match face {
                    None => convex_contains(&self.chain.ground, &p, -self.touch_tolerance),
                    Some(f) => {
                        let local = ws.data.poses[f].inverse_transform_point(&p);
                        self.chain.model.plates()[f].contains(&local, -self.touch_tolerance)
                    }
                }
            }
        }
    }

    fn collision(&self, k: usize, t: f64, ws: &ClosedData) -> Collision {
        let name = |joint: usize| {
            format!(
                "sector of {}",
                self.chain.crease_labels[self.chain.joint_creases[joint]]
            )
        };
        let ground = || "anchored sector".to_string();
        match self.candidates[k] {
            Candidate::Fold { crease } => {
                // The crease's far end moves with the sector after its ray (as with the one
                // before: the end lies on their shared hinge axis).
                let flat_end = self.chain.crease_ends[crease];
                let ray_end = match self.chain.body_of_sector(self.chain.crease_rays[crease]) {
                    Some(j) => {
                        let plate = &self.chain.model.plates()[j];
                        (ws.data.poses[j] * plate.reference_pose.inverse_transform_point(&flat_end)).coords
                    }
                    None => flat_end.coords,
                };
                Collision {
                    time: t,
                    pair: [
                        format!("{} folded flat", self.chain.crease_labels[crease]),
                        format!("{:.6}°", ws.crease_angles[crease].to_degrees()),
                    ],
                    point: ray_end,
                }
            }
            Candidate::Face { face, plate, corner } => Collision {
                time: t,
                pair: [name(plate), face.map_or_else(ground, name)],
                point: ws.data.corners[self.chain.model.corner_index(plate, corner)].coords,
            },
        }
    }

    fn move_to(&self, q: f64, ws: &mut ClosedData) -> Result<()> {
        self.chain.update_creases(q, ws)?;
        update_poses(&self.chain.model, &ws.joint_angles, &mut ws.data);
        update_corners(&self.chain.model, &mut ws.data);
        Ok(())
    }
}

struct ClosedProbe<'a> {
    plant: &'a ClosedPlant<'a>,
    ws: &'a mut ClosedData,
    q: &'a mut [f64],
    path: &'a mut dyn FnMut(f64, &mut [f64]),
    /// An evaluation outside the constraint's extended domain: the gaps read +∞ there.
    failed: bool,
}

impl ContactProbe for ClosedProbe<'_> {
    fn count(&self) -> usize {
        self.plant.candidates.len()
    }

    fn move_to(&mut self, t: f64) {
        (self.path)(t, self.q);
        self.failed = self.plant.move_to(self.q[0], self.ws).is_err();
    }

    fn gap(&self, k: usize) -> f64 {
        if self.failed {
            f64::INFINITY
        } else {
            self.plant.gap(k, self.ws)
        }
    }

    fn gate(&self, k: usize) -> bool {
        !self.failed && self.plant.gate(k, self.ws)
    }

    fn collision(&self, k: usize, t: f64) -> Collision {
        self.plant.collision(k, t, self.ws)
    }
}

impl ClosedChain {
    /// Natural periods of the one-degree-of-freedom chain at its start and its target
    /// (ω² = Σ K g² / gᵀ M g) against the forcing.
    pub fn time_scales(&self) -> Result<TimeScales> {
        let omegas = self.omegas()?;
        let fastest = omegas.iter().copied().fold(0.0, f64::max);
        let slowest = omegas.iter().copied().fold(f64::INFINITY, f64::min);
        let forcing = self.forcing.duration();
        Ok(TimeScales {
            fastest_period_s: TAU / fastest,
            slowest_period_s: TAU / slowest,
            forcing_time_s: forcing,
            ratio: forcing * fastest / TAU,
        })
    }

    /// ω at the start and at the target (clamped to the constraint's domain), rad/s.
    fn omegas(&self) -> Result<[f64; 2]> {
        let mut ws = self.workspace();
        let [lo, hi] = self.source.domain();
        let mut omegas = [0.0; 2];
        for (omega, q) in omegas.iter_mut().zip([self.start, self.target().clamp(lo, hi)]) {
            let (mass, stiffness) = self.reduced_mass_and_stiffness(q, &mut ws)?;
            *omega = (stiffness / mass).sqrt();
        }
        Ok(omegas)
    }

    /// Linear bound on the distance from the quasi-static path, rad: one mode, so a step's
    /// jump, or the ramp's rate jumps over ω at its start and end plus the jump from the start
    /// to the balance at t = 0 (a start that the passive hinges do not hold, as in step 2 of
    /// the corner cube, rings by that much).
    pub fn quasi_static_error_estimate(&self) -> Result<f64> {
        Ok(match self.forcing.actuation {
            Actuation::Step => (self.target() - self.start).abs(),
            Actuation::Ramp { .. } => {
                let omegas = self.omegas()?;
                let rate = self.forcing.drive_rate(self.driver, 0.0).abs();
                let balance = self.quasi_static_angle(0.0, self.start, &mut self.workspace())?;
                rate / omegas[0] + rate / omegas[1] + (balance - self.start).abs()
            }
        })
    }

    /// What a run reports of the chain besides its response: the constraint's errors, the
    /// torque magnification and the largest loop-closure residual of the samples.
    pub fn report(&self, samples: &[Sample]) -> Result<ClosedReport> {
        let mut ws = self.workspace();
        let mut max_closure_residual: f64 = 0.0;
        for sample in samples {
            ws.crease_angles.copy_from_slice(sample.angles.as_slice());
            max_closure_residual = max_closure_residual.max(self.closure_residual(&ws));
        }
        let eta = self.torque_magnification()?;
        let width = self.crease_ends[self.driver].coords.norm() * 1e6;
        let (fit_error, slope_error) = self.source.errors();
        Ok(ClosedReport {
            cut_crease: self.crease_user_indices[self.cut_crease],
            driver: self.crease_user_indices[self.driver],
            anchored_face: self.anchored_face,
            constraint_source: self.source.name(),
            degree: self.source.degree(),
            fit_error,
            slope_error,
            torque_magnification: eta,
            driving_hinge_width_um: width,
            required_hinge_width_um: width * eta,
            max_closure_residual,
        })
    }
}

impl Plant for ClosedPlant<'_> {
    type Workspace = ClosedData;

    fn switches<'w>(&self, ws: &'w Self::Workspace) -> &'w [f64] {
        &ws.data.drag_switches.normal_speeds
    }

    fn freeze_switches(&self, ws: &mut Self::Workspace, signs: Option<&[f64]>) {
        ws.data.drag_switches.freeze(signs);
    }

    fn workspace(&self) -> ClosedData {
        self.chain.workspace()
    }

    fn dof(&self) -> usize {
        1
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
        let mut ws = self.workspace();
        let (mass, stiffness) = self.chain.reduced_mass_and_stiffness(self.chain.start, &mut ws)?;
        Ok((stiffness / mass).sqrt())
    }

    fn initial_coordinates(&self) -> Vec<f64> {
        vec![self.chain.start]
    }

    fn accelerations(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut ClosedData, out: &mut [f64]) -> Result<()> {
        out[0] = self.chain.acceleration(t, q[0], q_dot[0], ws)?;
        Ok(())
    }

    fn sample(&self, t: f64, q: &[f64], q_dot: &[f64], _accumulated: &[f64], ws: &mut ClosedData) -> Result<Sample> {
        self.chain.sample(t, q[0], q_dot[0], ws)
    }

    fn balance(&self, drive: &[f64], q: &mut [f64], ws: &mut ClosedData) -> Result<()> {
        q[0] = self.chain.quasi_static_angle(drive[self.chain.driver], q[0], ws)?;
        Ok(())
    }

    fn balance_rates(
        &self,
        q: &[f64],
        drive: &[f64],
        drive_rates: &[f64],
        out: &mut [f64],
        ws: &mut ClosedData,
    ) -> Result<()> {
        let driver = self.chain.driver;
        let (_, stiffness) = self.chain.static_torque(q[0], drive[driver], ws)?;
        out[0] = self.chain.crease_stiffness[driver] * drive_rates[driver] / stiffness;
        Ok(())
    }

    fn check_samples(&self, samples: &[Sample]) -> Result<()> {
        self.chain.check_samples(samples)
    }

    fn contact_count(&self) -> usize {
        self.candidates.len()
    }

    fn touching(&self, t: f64, q: &[f64], ws: &mut ClosedData) -> Option<Collision> {
        self.move_to(q[0], ws).ok()?;
        (0..self.candidates.len())
            .find(|&k| matches!(self.candidates[k], Candidate::Fold { .. }) && self.gap(k, ws) <= 0.0)
            .map(|k| self.collision(k, t, ws))
    }

    fn contact_lever(&self) -> f64 {
        // A corner moves at most lever × Σ_j |θ̇_j| = lever × Σ_j |g_j| × |q̇|.
        self.chain.lever() * self.rate_gain
    }

    fn probe<'a>(
        &'a self,
        ws: &'a mut ClosedData,
        q: &'a mut [f64],
        path: &'a mut dyn FnMut(f64, &mut [f64]),
    ) -> Box<dyn ContactProbe + 'a> {
        Box::new(ClosedProbe {
            plant: self,
            ws,
            q,
            path,
            failed: false,
        })
    }
}

/// What a closed-chain run reports beside its response.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct ClosedReport {
    /// FOLD edge index of the cut crease.
    pub cut_crease: usize,
    /// FOLD edge index of the driving crease.
    pub driver: usize,
    /// FOLD face index of the anchored sector.
    pub anchored_face: usize,
    /// "poly" or "exact".
    pub constraint_source: &'static str,
    /// The polynomial's degree (poly only).
    pub degree: Option<usize>,
    /// Largest |f − exact| over the sweep samples, rad (0 for exact).
    pub fit_error: f64,
    /// Largest |f′ − G| over the regular sweep samples (0 for exact).
    pub slope_error: f64,
    /// The torque the driving hinge must supply to hold the target against every hinge of
    /// the loop, Σ K ρ g, over the torque its own stressed layer gives, K θ_target
    /// (`docs/model.md#torque-magnification`).
    pub torque_magnification: f64,
    /// The driving hinge's width (its crease's length), µm.
    pub driving_hinge_width_um: f64,
    /// The width that would supply that torque (stiffness ∝ width), µm.
    pub required_hinge_width_um: f64,
    /// Largest loop-closure residual of the recorded states, rad.
    pub max_closure_residual: f64,
}
