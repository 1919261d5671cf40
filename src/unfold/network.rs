//! Energy unfolding of crease patterns with many vertices
//! (`docs/model.md#energy-unfolding-of-many-vertices`): the state is the fold angles on the
//! manifold where every vertex closes; the energy is the sum of every vertex's own spherical
//! energy; the direction is the negative gradient projected onto the null space of the
//! closure Jacobian; each step is restored by Newton and refused if panels cross.

use crate::error::{NanofoldError, NumericalError, Result};
use crate::folding::normal::NormalSolver;
use crate::folding::{
    closure_jacobian, jacobian_rank, panel_contacts, panel_poses, restore_closure, vertex_residuals, ContactSettings,
    FoldingModel, Pose,
};
use crate::geometry::kinematics::forward;
use crate::geometry::sphere::Vec3;
use crate::unfold::barrier::{BarrierSettings, PanelBarrier};
use crate::unfold::energy::{Arc, Energy, EnergyKind, EnergyWorkspace};
use crate::unfold::observe::UnfoldProgress;
use crate::unfold::solver::SplitMix64;
use crate::unfold::Verdict;
use argmin::core::observers::ObserverMode;
use argmin::core::Executor;
use std::f64::consts::PI;

mod descent;

pub use descent::{DescentStop, NetworkDescent, NetworkProblem, NetworkState};

/// One vertex's spherical linkage for the energy: its rays (creases and the flat rays that
/// split sectors of π or more, as the single vertex does) and their arcs.
#[derive(Debug, Clone)]
struct EnergyStar {
    /// Sector angles after splitting.
    sector_angles: Vec<f64>,
    /// The fold-angle column of each ray (None: a flat splitting ray).
    columns: Vec<Option<usize>>,
    arcs: Vec<Arc>,
}

/// Σ_v U_v(ρ) over the vertices, plus Σ (1 − cos ρ_c) over the creases that meet no
/// interior vertex, with its gradient in fold-angle coordinates.
pub struct NetworkEnergy {
    energy: Box<dyn Energy>,
    stars: Vec<EnergyStar>,
    /// Creases with no interior vertex at either end: no spherical linkage holds them, so
    /// their own opening energy, lowest at flat, drives them.
    free_columns: Vec<usize>,
}

impl NetworkEnergy {
    /// The energy `kind` (exponent `p`, or its default) at every vertex of `model`.
    pub fn new(model: &FoldingModel, kind: EnergyKind, p: Option<f64>) -> NetworkEnergy {
        let stars = model
            .stars
            .iter()
            .map(|star| {
                let mut sector_angles = Vec::new();
                let mut columns = Vec::new();
                for (k, &alpha) in star.sector_angles.iter().enumerate() {
                    let pieces = if alpha >= PI {
                        (alpha / (PI / 2.0)).ceil() as usize
                    } else {
                        1
                    };
                    for piece in 0..pieces {
                        columns.push(if piece == 0 { Some(star.columns[k]) } else { None });
                        sector_angles.push(alpha / pieces as f64);
                    }
                }
                let n = sector_angles.len();
                let arcs = (0..n)
                    .map(|k| Arc {
                        a: k,
                        b: (k + 1) % n,
                        length: sector_angles[k],
                    })
                    .collect();
                EnergyStar {
                    sector_angles,
                    columns,
                    arcs,
                }
            })
            .collect();
        let mut starred = vec![false; model.crease_count()];
        for star in &model.stars {
            for &c in &star.columns {
                starred[c] = true;
            }
        }
        NetworkEnergy {
            energy: kind.build(p),
            stars,
            free_columns: (0..starred.len()).filter(|&c| !starred[c]).collect(),
        }
    }

    fn nodes(star: &EnergyStar, fold_angles: &[f64]) -> Vec<Vec3> {
        let by_ray: Vec<f64> = star.columns.iter().map(|c| c.map_or(0.0, |c| fold_angles[c])).collect();
        forward(&star.sector_angles, &by_ray)
    }

    /// U(ρ); infinite when some vertex's sectors touch.
    pub fn value(&self, fold_angles: &[f64], ws: &mut EnergyWorkspace) -> f64 {
        let vertices: f64 = self
            .stars
            .iter()
            .map(|star| self.energy.value(&Self::nodes(star, fold_angles), &star.arcs, ws))
            .sum();
        vertices
            + self
                .free_columns
                .iter()
                .map(|&c| 1.0 - fold_angles[c].cos())
                .sum::<f64>()
    }

    /// U(ρ) and ∂U/∂ρ (overwrites `gradient`). Node k of a vertex turns about the axis of
    /// every ray j < k by that ray's fold angle, ∂x_k/∂ρ_j = x_j × x_k, so
    /// ∂U_v/∂ρ_j = x_j · Σ_{k>j} x_k × ∂U_v/∂x_k (ray 0's angle closes the loop and moves no
    /// node: on the manifold it follows the others).
    pub fn value_and_gradient(&self, fold_angles: &[f64], ws: &mut EnergyWorkspace, gradient: &mut [f64]) -> f64 {
        gradient.iter_mut().for_each(|g| *g = 0.0);
        let mut total = 0.0;
        let mut node_gradient: Vec<Vec3> = Vec::new();
        for star in &self.stars {
            let nodes = Self::nodes(star, fold_angles);
            node_gradient.clear();
            node_gradient.resize(nodes.len(), Vec3::zeros());
            total += self
                .energy
                .value_and_gradient(&nodes, &star.arcs, ws, &mut node_gradient);
            let mut suffix = Vec3::zeros();
            for j in (1..nodes.len()).rev() {
                if let Some(c) = star.columns[j] {
                    gradient[c] += nodes[j].dot(&suffix);
                }
                suffix += nodes[j].cross(&node_gradient[j]);
            }
        }
        for &c in &self.free_columns {
            total += 1.0 - fold_angles[c].cos();
            gradient[c] += fold_angles[c].sin();
        }
        total
    }
}

/// A step towards flat goes at most this fraction of the way to the first crease's zero.
const FLAT_APPROACH: f64 = 0.9;

/// A line search that stalls within this of flat (max |ρ|, rad) ends the descent there.
const STALL_TOL: f64 = 1e-4;

/// Settings of a many-vertex unfolding.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkUnfoldSettings {
    /// Which energy.
    pub energy: EnergyKind,
    /// Its exponent (None: the energy's default).
    pub p: Option<f64>,
    /// Flat when every |fold angle| is at most this, rad.
    pub flat_tol: f64,
    /// Most descent steps.
    pub max_iterations: usize,
    /// Largest change of any fold angle in one step, rad.
    pub max_step: f64,
    /// Closure tolerance after every step, rad per vertex.
    pub closure_tol: f64,
    /// Panel contact test at every step.
    pub contact: ContactSettings,
    /// Curvature pairs the L-BFGS direction remembers (0: the projected gradient alone).
    pub memory: usize,
    /// The barrier between panels that share no vertex (None: crossings are only refused).
    pub barrier: Option<BarrierSettings>,
    /// Random kicks tried from a local minimum before it is the verdict.
    pub restarts: usize,
}

impl Default for NetworkUnfoldSettings {
    fn default() -> Self {
        NetworkUnfoldSettings {
            energy: EnergyKind::Separable,
            p: None,
            flat_tol: 1e-6,
            max_iterations: 20_000,
            max_step: 0.1,
            closure_tol: 1e-11,
            contact: ContactSettings {
                search: 0.1,
                ..ContactSettings::default()
            },
            memory: 8,
            barrier: Some(BarrierSettings::default()),
            restarts: 3,
        }
    }
}

/// One accepted state.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkStep {
    /// Energy.
    pub energy: f64,
    /// Fold angles, rad.
    pub fold_angles: Vec<f64>,
    /// Largest vertex closure residual, rad.
    pub max_residual: f64,
}

/// What a many-vertex unfolding found.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkUnfoldReport {
    /// The verdict.
    pub verdict: Verdict,
    /// Its evidence in words.
    pub evidence: String,
    /// Descent steps taken.
    pub iterations: usize,
    /// Every accepted state, the start first (the last is the flat state for `Flat`; for
    /// `NotRigid` only the start, with its energy not evaluated: NaN).
    pub steps: Vec<NetworkStep>,
    /// Largest vertex closure residual over the path, rad.
    pub max_closure_residual: f64,
    /// Trial steps refused because panels would cross.
    pub crossings_refused: usize,
    /// Steps taken along the ray to flat, ρ → (1 − f)ρ, where the projected gradient's
    /// line search found none.
    pub radial_steps: usize,
    /// Random kicks taken from local minima.
    pub restarts_used: usize,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// What the restarts did, for a local minimum's evidence.
fn restart_note(taken: usize, failed: bool) -> String {
    let kicks = format!("kicks of {RESTART_KICK} rad along random directions of the null space");
    if failed {
        format!("{taken} restarts taken, then none found: no kicked state closes within ±π without crossing panels ({kicks})")
    } else {
        format!("{taken} restarts tried ({kicks})")
    }
}

/// The largest fold-angle change of a restart's kick, rad.
const RESTART_KICK: f64 = 0.05;

/// A restart from a local minimum: a random direction of the null space of J (the rigid
/// motions), scaled so no crease moves more than [`RESTART_KICK`], tried both ways and up to
/// four draws; the first kicked state that closes with finite energy and no crossing panels.
#[allow(clippy::too_many_arguments)]
fn restart(
    objective: &Objective,
    settings: &NetworkUnfoldSettings,
    factor: &crate::folding::normal::NormalFactor,
    random: &mut SplitMix64,
    rho: &[f64],
    ws: &mut EnergyWorkspace,
    poses: &mut Vec<Pose>,
    solver: &mut NormalSolver,
) -> Result<Option<Accepted>> {
    let model = objective.model;
    for draw in 0..4 {
        // The first two draws head towards flat (every crease's |ρ| shrinking by a random
        // share: a start folded to ±π sits at a stationary point on its bound); the others
        // are any direction.
        let mut direction: Vec<f64> = rho
            .iter()
            .map(|&r| {
                let u = random.next_f64();
                if draw < 2 && r != 0.0 {
                    -r.signum() * u
                } else {
                    2.0 * u - 1.0
                }
            })
            .collect();
        model.hold_locked(&mut direction);
        let direction = factor.project(&direction);
        let size = direction.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        if size <= 1e-14 {
            continue;
        }
        for sign in [1.0, -1.0] {
            let trial: Vec<f64> = rho
                .iter()
                .zip(&direction)
                .map(|(r, d)| r + sign * RESTART_KICK * d / size)
                .collect();
            if let Trial::Accepted(state) = try_state(model, objective, settings, solver, ws, poses, trial, |_| true)? {
                return Ok(Some(state));
            }
        }
    }
    Ok(None)
}

/// Below this largest |ρ|, rad, a step along the ray to flat is tried before the line search.
const NEAR_FLAT: f64 = 0.05;

/// A step along the ray to flat, ρ → (1 − f)ρ for f = 1/2, 1/4, …, 1e-4: near the flat state
/// the closure manifold is close to a cone with its apex there, where Newton from a tangent
/// step converges slowly or not at all, while the cone's ray stays nearly on it. Taken when it
/// lowers the energy and puts no panels through each other.
#[allow(clippy::too_many_arguments)]
fn radial_step(
    model: &FoldingModel,
    objective: &Objective,
    settings: &NetworkUnfoldSettings,
    solver: &mut NormalSolver,
    ws: &mut EnergyWorkspace,
    poses: &mut Vec<Pose>,
    rho: &[f64],
    u: f64,
    crossings_refused: &mut usize,
    refused_for_crossing: &mut Option<[usize; 2]>,
) -> Result<Option<Accepted>> {
    let mut f = 0.5;
    while f > 1e-4 {
        let trial: Vec<f64> = rho.iter().map(|r| (1.0 - f) * r).collect();
        match try_state(model, objective, settings, solver, ws, poses, trial, |v| v < u)? {
            Trial::Accepted(state) => return Ok(Some(state)),
            Trial::Crossing(pair) => {
                *crossings_refused += 1;
                *refused_for_crossing = Some(pair);
            }
            Trial::Refused => {}
        }
        f /= 2.0;
    }
    Ok(None)
}

/// A crease is a major crease of a vertex when its |ρ| is at least this share of the
/// largest |ρ| there.
const MAJOR_SHARE: f64 = 0.25;

/// Marks the creases that are major at one of their vertices, or have no interior vertex.
fn major_crease(model: &FoldingModel, rho: &[f64], major: &mut [bool]) {
    major.fill(false);
    let mut starred = vec![false; rho.len()];
    for star in &model.stars {
        let largest = star.columns.iter().map(|&c| rho[c].abs()).fold(0.0, f64::max);
        for &c in &star.columns {
            starred[c] = true;
            if rho[c].abs() >= MAJOR_SHARE * largest {
                major[c] = true;
            }
        }
    }
    for (m, s) in major.iter_mut().zip(&starred) {
        *m |= !s;
    }
}

/// What the descent minimises: the summed vertex energies and, if asked, the barrier between
/// panels that share no vertex.
struct Objective<'m> {
    model: &'m FoldingModel,
    energy: NetworkEnergy,
    barrier: Option<PanelBarrier>,
}

impl Objective<'_> {
    /// U(ρ) + B(ρ), its gradient into `gradient`, the panel poses into `poses`.
    fn evaluate(&self, rho: &[f64], ws: &mut EnergyWorkspace, poses: &mut Vec<Pose>, gradient: &mut [f64]) -> f64 {
        let value = self.energy.value_and_gradient(rho, ws, gradient);
        panel_poses(self.model, rho, poses);
        match &self.barrier {
            Some(barrier) if value.is_finite() => value + barrier.value_and_gradient(self.model, poses, gradient),
            _ => value,
        }
    }
}

/// The flat state (rigid, every vertex closed exactly) as the path's last step.
fn flat_step(objective: &Objective, creases: usize, ws: &mut EnergyWorkspace) -> NetworkStep {
    let fold_angles = vec![0.0; creases];
    let mut poses = Vec::new();
    let mut gradient = vec![0.0; creases];
    NetworkStep {
        energy: objective.evaluate(&fold_angles, ws, &mut poses, &mut gradient),
        fold_angles,
        max_residual: 0.0,
    }
}

/// An accepted state: fold angles, energy, gradient.
type Accepted = (Vec<f64>, f64, Vec<f64>);

/// What a trial state came to.
enum Trial {
    /// Closed, energy accepted, no panels crossing.
    Accepted(Accepted),
    /// Closed and energy accepted, but these panels cross.
    Crossing([usize; 2]),
    /// Newton could not close it, or its energy was not accepted.
    Refused,
}

/// Restores `trial` onto the closure and judges it: every fold angle within ±π, its energy
/// finite and passing `accept`, and no two panels crossing.
#[allow(clippy::too_many_arguments)]
fn try_state(
    model: &FoldingModel,
    objective: &Objective,
    settings: &NetworkUnfoldSettings,
    solver: &mut NormalSolver,
    ws: &mut EnergyWorkspace,
    poses: &mut Vec<Pose>,
    mut trial: Vec<f64>,
    accept: impl Fn(f64) -> bool,
) -> Result<Trial> {
    if restore_closure(model, &mut trial, settings.closure_tol, solver)?.is_none() {
        return Ok(Trial::Refused);
    }
    // Beyond ±π a crease has passed its two panels through each other.
    if trial.iter().any(|r| r.abs() > PI + 1e-12) {
        return Ok(Trial::Refused);
    }
    let mut gradient = vec![0.0; trial.len()];
    let value = objective.evaluate(&trial, ws, poses, &mut gradient);
    if !(value.is_finite() && accept(value)) {
        return Ok(Trial::Refused);
    }
    let contacts = panel_contacts(model, poses, &settings.contact);
    if let Some(found) = contacts.overflow {
        return Err(NumericalError::ContactBudget {
            pairs: found - 1,
            when: "at a trial step".into(),
        }
        .into());
    }
    if let Some(contact) = contacts.crossing().next() {
        return Ok(Trial::Crossing(contact.panels));
    }
    Ok(Trial::Accepted((trial, value, gradient)))
}

/// Unfolds a rigid state of `model` by projected gradient descent on the summed vertex
/// energies.
pub fn unfold_network(
    model: &FoldingModel,
    start: &[f64],
    settings: &NetworkUnfoldSettings,
) -> Result<NetworkUnfoldReport> {
    unfold_network_observed(model, start, settings, None)
}

/// [`unfold_network`], its descent driven by argmin's `Executor` with `progress` (the
/// observer the single vertex's unfolding takes too) told of every step.
pub fn unfold_network_observed(
    model: &FoldingModel,
    start: &[f64],
    settings: &NetworkUnfoldSettings,
    progress: Option<UnfoldProgress>,
) -> Result<NetworkUnfoldReport> {
    let descent = match start_descent(model, start, settings)? {
        NetworkStart::Decided(report) => return Ok(report),
        NetworkStart::Descent(descent) => descent,
    };
    let state = descent.state();
    let mut executor = Executor::new(NetworkProblem, *descent).configure(|_| state);
    if let Some(progress) = progress {
        executor = executor.add_observer(progress, ObserverMode::Always);
    }
    let result = executor.run().map_err(crate::unfold::from_executor)?;
    Ok(result.solver.into_report())
}

/// Where an unfolding of many vertices begins.
pub enum NetworkStart<'a> {
    /// Decided at the start (not a rigid state; no motion): the report.
    Decided(NetworkUnfoldReport),
    /// A descent to drive, from the start restored onto the closure.
    Descent(Box<NetworkDescent<'a>>),
}

/// Validates the settings and the start, and sets up the descent from it: the checks and
/// set-up of [`unfold_network`] before its first step.
pub fn start_descent<'a>(
    model: &'a FoldingModel,
    start: &[f64],
    settings: &'a NetworkUnfoldSettings,
) -> Result<NetworkStart<'a>> {
    settings.contact.validate()?;
    if !(settings.flat_tol > 0.0 && settings.flat_tol <= 0.1) {
        return Err(NanofoldError::invalid(
            "flat_tol",
            settings.flat_tol,
            "must lie in (0, 0.1] rad",
        ));
    }
    if !(settings.max_step > 0.0 && settings.max_step <= 1.0) {
        return Err(NanofoldError::invalid(
            "max_step",
            settings.max_step,
            "must lie in (0, 1] rad",
        ));
    }
    model.expect_fold_angles("start", start)?;
    let residuals = vertex_residuals(model, start);
    let residual = residuals.iter().copied().fold(0.0, f64::max);
    if residual > 1e-6 {
        let worst = residuals
            .iter()
            .position(|&r| r == residual)
            .expect("the largest is one of them");
        return Ok(NetworkStart::Decided(NetworkUnfoldReport {
            verdict: Verdict::NotRigid,
            evidence: format!(
                "the start is not a rigid state: vertex {} is {residual:.3e} rad from closing (above 1e-6)",
                model.stars[worst].vertex
            ),
            iterations: 0,
            steps: vec![NetworkStep {
                energy: f64::NAN,
                fold_angles: start.to_vec(),
                max_residual: residual,
            }],
            max_closure_residual: residual,
            crossings_refused: 0,
            radial_steps: 0,
            restarts_used: 0,
        }));
    }
    let mut poses = Vec::new();
    panel_poses(model, start, &mut poses);
    // A start stacked deeper than the contact test measures is refused before the barrier's
    // own broad phase would list every pair.
    if let Some(found) = panel_contacts(model, &poses, &settings.contact).overflow {
        return Err(NumericalError::ContactBudget {
            pairs: found - 1,
            when: "at the start".into(),
        }
        .into());
    }
    let mut barrier = settings.barrier.map(|b| PanelBarrier::new(model, &b)).transpose()?;
    if let Some(barrier) = barrier.as_mut() {
        barrier.exclude_touching(model, &poses);
    }
    let objective = Objective {
        model,
        energy: NetworkEnergy::new(model, settings.energy, settings.p),
        barrier,
    };
    let mut solver = NormalSolver::new(1e-10);
    let ws = EnergyWorkspace::default();
    let mut rho = start.to_vec();
    if restore_closure(model, &mut rho, settings.closure_tol, &mut solver)?.is_none() {
        // At a singular state (folded flat, say) Newton's steps need not converge, but the
        // start closes within the tolerance (above): descend from it as it is; every step
        // after it is closed to `closure_tol`.
        rho = start.to_vec();
    }
    let descent = NetworkDescent::new(objective, settings, solver, ws, rho);
    // An already flat start is `flat` (the descent says so at step 0), even with no motion.
    let already_flat = descent.rho.iter().all(|r| r.abs() <= settings.flat_tol);
    if !already_flat && jacobian_rank(&closure_jacobian(model, &descent.rho))?.dof == 0 {
        let stop = (
            Verdict::Locked,
            "0 degrees of freedom at the start: no rigid motion".to_string(),
        );
        return Ok(NetworkStart::Decided(descent.finish(stop, 0)));
    }
    Ok(NetworkStart::Descent(Box::new(descent)))
}

impl crate::names::Answer for NetworkUnfoldReport {
    fn verdict_name(&self) -> &'static str {
        crate::names::variant_name(&self.verdict)
    }

    fn evidence(&self) -> &str {
        &self.evidence
    }
}
