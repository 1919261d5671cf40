//! Closed chains (SPEC §7, T4.16–4.20): a single vertex cut at one unactuated crease, the
//! sectors as an open chain of plates from the sector after the cut (anchored), tied back by
//! θ_r = f(θ_c). One driving crease remains after the locks, so the generalised coordinate q
//! is its angle and, with g = ∂θ/∂q (1 for the driver, G for the dependents, 0 when held) and
//! h = ∂²θ/∂q² (f″),
//!   (gᵀ M g) q̈ = τ_q − gᵀ [M h q̇² + C(θ, g q̇) g q̇] − Σ_creases K ρ g + gᵀ Q_drag,
//! the reduced equation Gᵀ[M(G θ̈_c + Ġ θ̇_c) + C G θ̇_c + N] = τ_c written for one coordinate.
//! The elastic sum runs over every crease, the cut one included: it is a hinge too.

pub mod modes;
pub mod quasi_static;

use super::contact::{Collision, ContactProbe};
use super::simulate::{
    integrate, output_times, output_times_in, resolve_method, DynamicRun, ModelKind, Plant, Response, Sample,
    SimulationSettings, TimeScales, QUASI_STATIC_RATIO,
};
use super::{Data, Model};
use crate::constraints::exact::{ConstraintPoint, ExactConstraint};
use crate::constraints::ConstraintPoly;
use crate::error::{NanofoldError, Result};
use crate::kinematics::closure_residual;
use crate::scene::closed::ClosedScene;
use crate::scene::Actuation;
use nalgebra::{DVector, Point3, Vector3};
use quasi_static::quasi_static_path;
use std::f64::consts::PI;
use std::time::Instant;

/// Where f comes from (SPEC §6).
#[derive(Debug, Clone)]
pub enum ConstraintSource {
    /// The fitted polynomial and its derivatives.
    Poly(ConstraintPoly),
    /// Newton loop closure at every evaluation, G by the implicit function theorem.
    Exact(ExactConstraint),
}

impl ConstraintSource {
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

    /// The fitted (or swept) interval of the driving angle, rad.
    pub fn domain(&self) -> [f64; 2] {
        match self {
            ConstraintSource::Poly(poly) => poly.domain,
            ConstraintSource::Exact(exact) => exact.domain,
        }
    }
}

/// Trial states of an integrator step may overshoot the constraint's domain by this much
/// (rad) before an evaluation fails: f is extrapolated there. A recorded state outside the
/// domain is an error (see [`ClosedChain::check_samples`]).
pub const DOMAIN_MARGIN: f64 = 0.1;

/// A dynamic run of a slow forcing (≥ 10³ fastest periods) may stray from the quasi-static
/// path by its linear error bound plus this, rad.
const SLOW_FORCING_DEVIATION: f64 = 1e-3;

/// Two sector plates touch when a fold angle reaches ±π to within this, rad.
const FOLD_TOUCH: f64 = 1e-9;

/// An immutable closed-chain description: geometry, hinges, the constraint and the actuation.
#[derive(Debug, Clone)]
pub struct ClosedChain {
    /// The open chain after the cut: joint j turns about the ray of crease `joint_creases[j]`
    /// and carries sector plate j; the anchored sector is [`ClosedChain::ground`].
    pub model: Model,
    pub joint_creases: Vec<usize>,
    /// The anchored sector's outline (world frame, flat, m).
    pub ground: Vec<Point3<f64>>,
    pub cut_crease: usize,
    /// Hinge stiffness of every crease (file order), N·m/rad.
    pub crease_stiffness: Vec<f64>,
    pub crease_labels: Vec<String>,
    /// The far end of every crease in the flat state (world frame, m).
    pub crease_ends: Vec<Point3<f64>>,
    pub driver: usize,
    pub locked: Vec<(usize, f64)>,
    pub dependents: Vec<usize>,
    pub source: ConstraintSource,
    /// Sector angles and the ray of every crease, for loop-closure residuals.
    pub sector_angles: Vec<f64>,
    pub crease_rays: Vec<usize>,
    /// Driver angle at rest at t = 0 and its target (rad).
    pub start: f64,
    pub target: f64,
    pub actuation: Actuation,
    /// Radius of curvature of the driving hinge for a ramp, m.
    pub radius_of_curvature: f64,
}

/// Scratch of a [`ClosedChain`]: the open chain's buffers and the constraint's values.
#[derive(Debug, Clone)]
pub struct ClosedData {
    pub data: Data,
    point: ConstraintPoint,
    /// Every crease's angle, ∂θ/∂q and ∂²θ/∂q² (file order).
    pub crease_angles: Vec<f64>,
    pub crease_g: Vec<f64>,
    pub crease_h: Vec<f64>,
    joint_angles: Vec<f64>,
    joint_rates: Vec<f64>,
    joint_g: Vec<f64>,
    joint_h: Vec<f64>,
    coriolis: Vec<f64>,
    drag: Vec<f64>,
}

impl ClosedChain {
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

    /// The angle the driving hinge's stressed layer drives to at time t (T5.9–5.12), rad.
    pub fn drive_angle(&self, t: f64) -> f64 {
        match &self.actuation {
            Actuation::Step => self.target,
            Actuation::Ramp { etch_rate, .. } => {
                let reached = etch_rate * t / self.radius_of_curvature;
                self.target.signum() * reached.min(self.target.abs())
            }
        }
    }

    /// τ_q(t) = K_driver θ_drive(t): the driving hinge's stressed-layer torque.
    pub fn drive_torque(&self, t: f64) -> f64 {
        self.crease_stiffness[self.driver] * self.drive_angle(t)
    }

    /// The ramp's duration t_p (0 for a step), s.
    pub fn forcing_time(&self) -> f64 {
        match &self.actuation {
            Actuation::Step => 0.0,
            Actuation::Ramp { etch_rate, .. } => self.radius_of_curvature * self.target.abs() / etch_rate,
        }
    }

    /// Reduced mass gᵀ M g (kg·m²) and stiffness Σ K g² (N·m/rad) at q.
    pub fn reduced_mass_and_stiffness(&self, q: f64, ws: &mut ClosedData) -> Result<(f64, f64)> {
        self.update_creases(q, ws)?;
        self.model.update_kinematics(&ws.joint_angles, &mut ws.data);
        self.model.update_mass_matrix(&mut ws.data);
        let mass = quadratic_form(&ws.data, &ws.joint_g);
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
        model.update_kinematics(&ws.joint_angles, &mut ws.data);
        model.update_mass_matrix(&mut ws.data);
        model.update_velocities(&ws.joint_rates, &mut ws.data);
        model.coriolis_torques(&ws.joint_rates, &mut ws.data, &mut ws.coriolis);
        model.drag_torques(&ws.data, &mut ws.drag);
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
            return Err(NanofoldError::Numerical {
                stage: "closed-chain dynamics".into(),
                message: format!("reduced mass gᵀMg = {reduced_mass:e} is not positive at q = {q}"),
            });
        }
        Ok(force / reduced_mass)
    }

    /// T5.24–5.25 at the target: the torque the driving hinge must supply to hold it against
    /// every hinge of the loop, Σ K ρ g, over what its own stressed layer gives, K θ_target.
    pub fn torque_magnification(&self) -> Result<f64> {
        let mut ws = self.workspace();
        let [lo, hi] = self.source.domain();
        self.update_creases(self.target.clamp(lo, hi), &mut ws)?;
        let drive = self.crease_stiffness[self.driver] * self.target;
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
            .plates
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

fn quadratic_form(data: &Data, g: &[f64]) -> f64 {
    let m = &data.mass_matrix;
    let mut sum = 0.0;
    for (i, gi) in g.iter().enumerate() {
        for (j, gj) in g.iter().enumerate() {
            sum += m[(i, j)] * gi * gj;
        }
    }
    sum
}

/// A contact candidate of a closed chain.
#[derive(Debug, Clone, Copy)]
enum Candidate {
    /// Two neighbouring sectors fold flat onto each other: |ρ| reaches π.
    Fold { crease: usize },
    /// A corner (not the vertex) of sector plate `plate` crosses the face of a non-adjacent
    /// sector (`face`; `None` for the anchored sector). Bodies are indexed by joint.
    Face {
        face: Option<usize>,
        plate: usize,
        corner: usize,
    },
}

/// The closed chain as an integrator [`Plant`], with its contact candidates.
pub struct ClosedPlant<'c> {
    pub chain: &'c ClosedChain,
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
            // Bodies around the vertex: ground = position 0, plate j = position j + 1.
            let bodies = chain.model.dof() + 1;
            let apart = |a: usize, b: usize| {
                let d = a.abs_diff(b);
                d.min(bodies - d) >= 2
            };
            for plate in 0..chain.model.dof() {
                let outline = &chain.model.plates[plate].outline;
                for (corner, local) in outline.iter().enumerate() {
                    let world = chain.model.plates[plate].reference_pose * local;
                    if world.coords.norm() <= touch_tolerance {
                        continue;
                    }
                    for face in 0..bodies {
                        if apart(face, plate + 1) {
                            candidates.push(Candidate::Face {
                                face: face.checked_sub(1),
                                plate,
                                corner,
                            });
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
                        self.chain.model.plates[f].contains(&local, -self.touch_tolerance)
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
                // The crease's far end moves with the plate after it (fixed for the cut crease).
                let flat_end = self.chain.crease_ends[crease];
                let ray_end = match self.chain.joint_creases.iter().position(|&c| c == crease) {
                    Some(j) => {
                        let plate = &self.chain.model.plates[j];
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
        self.chain.model.update_poses(&ws.joint_angles, &mut ws.data);
        self.chain.model.update_corners(&mut ws.data);
        Ok(())
    }
}

/// Whether p (z ignored) lies in the convex counter-clockwise polygon, within `tolerance`.
fn convex_contains(outline: &[Point3<f64>], p: &Point3<f64>, tolerance: f64) -> bool {
    let count = outline.len();
    (0..count).all(|k| {
        let (a, b) = (outline[k], outline[(k + 1) % count]);
        let edge = b - a;
        (edge.x * (p.y - a.y) - edge.y * (p.x - a.x)) / edge.x.hypot(edge.y) >= -tolerance
    })
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

impl Plant for ClosedPlant<'_> {
    type Workspace = ClosedData;

    fn workspace(&self) -> ClosedData {
        self.chain.workspace()
    }

    fn dof(&self) -> usize {
        1
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

    fn sample(&self, t: f64, q: &[f64], q_dot: &[f64], ws: &mut ClosedData) -> Result<Sample> {
        self.chain.sample(t, q[0], q_dot[0], ws)
    }

    fn forcing_breakpoints(&self) -> Vec<f64> {
        match self.chain.actuation {
            Actuation::Step => Vec::new(),
            Actuation::Ramp { .. } => vec![self.chain.forcing_time()],
        }
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

/// What a closed-chain run reports besides the open chain's keys.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ClosedReport {
    /// FOLD edge index of the cut crease.
    pub cut_crease: usize,
    pub driver: usize,
    /// "poly" or "exact".
    pub constraint_source: &'static str,
    pub degree: Option<usize>,
    /// Largest |f − exact| over the sweep samples, rad (0 for exact).
    pub fit_error: f64,
    /// Largest |f′ − G| over the regular sweep samples (0 for exact).
    pub slope_error: f64,
    /// T5.24–5.25: the torque the driving hinge must supply to hold the target against every
    /// hinge of the loop, Σ K ρ g, over the torque its own stressed layer gives, K θ_target;
    /// and the driving hinge width that would supply it (stiffness ∝ width).
    pub torque_magnification: f64,
    pub driving_hinge_width_um: f64,
    pub required_hinge_width_um: f64,
    /// Largest loop-closure residual of the recorded states, rad.
    pub max_closure_residual: f64,
}

/// Runs a closed-chain scene: the reduced dynamics, or the quasi-static path when the model
/// is chosen so (`auto`: the forcing lasts ≥ 10³ fastest periods, as for open chains).
pub fn simulate_closed(scene: &ClosedScene, settings: &SimulationSettings) -> Result<Response> {
    let started = Instant::now();
    if !(settings.rtol.is_finite() && settings.rtol > 0.0 && settings.rtol < 1.0) {
        return Err(NanofoldError::invalid("--rtol", settings.rtol, "must lie in (0, 1)"));
    }
    let t_end = settings.t_end.unwrap_or(scene.t_end);
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(NanofoldError::invalid("t_end", t_end, "must be a finite time > 0 s"));
    }
    let chain = &scene.chain;
    let plant = ClosedPlant::new(chain, !settings.ignore_collisions);
    let mut ws = chain.workspace();
    let [lo, hi] = chain.source.domain();
    let mut omegas = Vec::new();
    for q in [chain.start, chain.target.clamp(lo, hi)] {
        let (mass, stiffness) = chain.reduced_mass_and_stiffness(q, &mut ws)?;
        omegas.push((stiffness / mass).sqrt());
    }
    let fastest = omegas.iter().copied().fold(0.0, f64::max);
    let slowest = omegas.iter().copied().fold(f64::INFINITY, f64::min);
    let forcing = chain.forcing_time();
    let scales = TimeScales {
        fastest_period_s: std::f64::consts::TAU / fastest,
        slowest_period_s: std::f64::consts::TAU / slowest,
        forcing_time_s: forcing,
        ratio: forcing * fastest / std::f64::consts::TAU,
    };
    // One mode: a step's jump, or the ramp's rate jumps over ω at its start and end.
    let estimate = match chain.actuation {
        Actuation::Step => (chain.target - chain.start).abs(),
        Actuation::Ramp { etch_rate, .. } => {
            // Plus the jump from the start to the balance at t = 0 (a start that the passive
            // hinges do not hold, as in step 2 of the corner cube, rings by that much).
            let rate = etch_rate / chain.radius_of_curvature;
            let balance = chain.quasi_static_angle(0.0, chain.start, &mut ws)?;
            rate / omegas[0] + rate / omegas[1] + (balance - chain.start).abs()
        }
    };
    let kind = settings.model.resolve(&scales);
    let times = output_times(t_end, scene.outputs.samples);
    let (run, method, measured) = match kind {
        ModelKind::Dynamic => {
            let method = resolve_method(settings.method, &scales);
            let run = integrate(&plant, method, &times, settings.run_options())?;
            chain.check_samples(&run.samples)?;
            // A slow forcing has an accurate second answer, the quasi-static path: a dynamic
            // run far from it has been misled by its error control (ESDIRK34 at rtol 1e-6
            // drifts past the equilibrium after a ramp's end), so it is refused, not returned.
            let mut measured = None;
            if scales.ratio >= QUASI_STATIC_RATIO {
                let deviation = chain.quasi_static_deviation(&run.samples)?;
                if deviation > SLOW_FORCING_DEVIATION + 10.0 * estimate {
                    return Err(NanofoldError::Numerical {
                        stage: "closed-chain dynamics".into(),
                        message: format!(
                            "the {method:?} run strays {:.3}° from the quasi-static path, whose linear error bound is {:.1e} rad: its error control failed on this stiff forcing; use a tighter --rtol (1e-10) or --model quasi-static",
                            deviation.to_degrees(),
                            estimate
                        ),
                    });
                }
                measured = Some((run.samples.last().map_or(0.0, |s| s.time), deviation));
            }
            (run, Some(method), measured)
        }
        ModelKind::QuasiStatic => {
            let (samples, collision, steps) = quasi_static_path(&plant, &times)?;
            // The check of the model, as for open chains: a short dynamic run from rest.
            let (window, method, options) = settings.check_run(&scales, t_end);
            let check = integrate(
                &ClosedPlant::new(chain, false),
                method,
                &output_times_in(window, 201),
                options,
            )?;
            let deviation = chain.quasi_static_deviation(&check.samples)?;
            let run = DynamicRun {
                samples,
                collision,
                steps,
                rhs_evaluations: 0,
            };
            (run, None, Some((window, deviation)))
        }
    };
    let mut max_closure_residual: f64 = 0.0;
    for sample in &run.samples {
        ws.crease_angles.copy_from_slice(sample.angles.as_slice());
        max_closure_residual = max_closure_residual.max(chain.closure_residual(&ws));
    }
    let eta = chain.torque_magnification()?;
    let width = chain.crease_ends[chain.driver].coords.norm() * 1e6;
    let collision = run.collision;
    Ok(Response {
        model: kind,
        method,
        rtol: settings.rtol,
        time_scales: scales,
        quasi_static_error_estimate: estimate,
        measured_quasi_static_error: measured,
        t_end: collision.as_ref().map_or(t_end, |c| c.time),
        collision,
        samples: run.samples,
        steps: run.steps,
        rhs_evaluations: run.rhs_evaluations,
        seconds: started.elapsed().as_secs_f64(),
        closed: Some(ClosedReport {
            cut_crease: scene.pattern.user_index(chain.cut_crease),
            driver: scene.pattern.user_index(chain.driver),
            constraint_source: chain.source.name(),
            degree: match &chain.source {
                ConstraintSource::Poly(p) => Some(p.degree()),
                ConstraintSource::Exact(_) => None,
            },
            fit_error: scene.fit_error,
            slope_error: scene.slope_error,
            torque_magnification: eta,
            driving_hinge_width_um: width,
            required_hinge_width_um: width * eta,
            max_closure_residual,
        }),
    })
}
