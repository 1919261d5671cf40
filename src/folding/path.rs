//! Rigid folding motion (Tachi; `docs/model.md#folding-paths`): a desired velocity of the
//! fold angles projected onto the null space of the closure Jacobian, a step, and Newton
//! back onto every vertex closure; panel contact checked at every step.

use super::closure::{closure_jacobian, closure_residual, worst_of, ClosureJacobian};
use super::contact::{panel_contacts, ContactReport, ContactSettings};
use super::model::FoldingModel;
use super::normal::{NormalFactor, NormalSolver};
use super::poses::{panel_poses, Pose};
use crate::error::{NanofoldError, Result};
use crate::pattern::crease_pattern::EdgeKind;
use crate::pattern::Assignment;
use std::f64::consts::PI;

/// What drives the motion.
#[derive(Debug, Clone, PartialEq)]
pub enum Drive {
    /// Every mountain crease towards −π and every valley towards +π at equal speed, until
    /// the most folded crease reaches `to` % of π.
    Assignment {
        /// Percentage of a full fold at which to stop, in [0.1, 100] (as `fold --to`).
        to: f64,
    },
    /// The listed creases (fold-angle columns) towards their target angles (rad).
    Creases(Vec<(usize, f64)>),
    /// Every crease towards its target (one per crease column, rad; a file's
    /// `edges_foldAngle` read as targets), the state kept rigid: the velocity θ* − ρ
    /// projected onto the closures' null space. It stops at the targets, at `to` % of the
    /// way there (measured by the crease furthest from its target), or at the rigid state
    /// nearest them that the path reaches.
    Targets {
        /// The target angles, rad, one per crease column.
        targets: Vec<f64>,
        /// Percentage of the way to stop at, in [0.1, 100] (as `fold --to`).
        to: f64,
    },
}

/// Settings of a folding path, validated by [`FoldSettings::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct FoldSettings {
    /// What drives the motion.
    pub drive: Drive,
    /// Largest change of any fold angle in one step, rad.
    pub max_step: f64,
    /// Largest closure residual accepted at any vertex after Newton, rad.
    pub closure_tol: f64,
    /// Most steps.
    pub max_steps: usize,
    /// First step out of the flat state along the projected direction, rad.
    pub kick: f64,
    /// Panel contact test.
    pub contact: ContactSettings,
}

impl Default for FoldSettings {
    fn default() -> Self {
        FoldSettings {
            drive: Drive::Assignment { to: 100.0 },
            // The command line's default too (`fold --max-step 15`, degrees): a cap, the step
            // control chooses below it.
            max_step: 15.0 * std::f64::consts::PI / 180.0,
            closure_tol: 1e-11,
            max_steps: 100_000,
            kick: 1e-3,
            // A narrower search than `check`'s: tested at every step, it must stay cheap.
            contact: ContactSettings {
                search: 0.1,
                ..ContactSettings::default()
            },
        }
    }
}

impl FoldSettings {
    /// Checks every setting against the model.
    pub fn validate(&self, model: &FoldingModel) -> Result<()> {
        match &self.drive {
            Drive::Assignment { to } => {
                // A goal below the kick that leaves flat would be passed by the first step.
                if !(*to >= MIN_GOAL_PERCENT && *to <= 100.0) {
                    return Err(NanofoldError::invalid(
                        "drive.to",
                        format!("{to:e}"),
                        format!("must lie in [{MIN_GOAL_PERCENT}, 100] (percent of a full fold)"),
                    ));
                }
            }
            Drive::Targets { targets, to } => {
                if !(*to >= MIN_GOAL_PERCENT && *to <= 100.0) {
                    return Err(NanofoldError::invalid(
                        "drive.to",
                        format!("{to:e}"),
                        format!("must lie in [{MIN_GOAL_PERCENT}, 100] (percent of the way to the targets)"),
                    ));
                }
                model.expect_fold_angles("drive.targets", targets)?;
                let signs = assigned_signs(model);
                for (column, &target) in targets.iter().enumerate() {
                    let edge = model.pattern.creases[column];
                    if !(target.is_finite() && target.abs() <= PI) {
                        return Err(NanofoldError::invalid(
                            format!("drive.targets[{column}] (edge {edge})"),
                            target.to_degrees(),
                            "a target lies in [−180°, 180°]",
                        ));
                    }
                    if signs[column] * target < 0.0 && !model.locked_columns[column] {
                        return Err(NanofoldError::invalid(
                            format!("drive.targets[{column}] (edge {edge})"),
                            format!("{:.3}°", target.to_degrees()),
                            "the target's sign contradicts the crease's assignment (mountain ≤ 0 ≤ valley)",
                        ));
                    }
                }
            }
            Drive::Creases(list) => {
                if list.is_empty() {
                    return Err(NanofoldError::invalid("drive", "[]", "name at least one crease"));
                }
                for &(column, target) in list {
                    if column >= model.crease_count() {
                        return Err(NanofoldError::invalid(
                            "drive",
                            column,
                            format!("the pattern has {} creases", model.crease_count()),
                        ));
                    }
                    if !(target.is_finite() && target.abs() <= PI) {
                        return Err(NanofoldError::invalid(
                            "drive",
                            target.to_degrees(),
                            "a target lies in [−180°, 180°]",
                        ));
                    }
                    if model.locked_columns[column] {
                        return Err(NanofoldError::invalid(
                            "drive",
                            format!("crease {column} (edge {})", model.pattern.creases[column]),
                            "the crease is locked (edges_nanofold:locked): it cannot be driven",
                        ));
                    }
                    let sign = assigned_signs(model)[column];
                    if sign * target < 0.0 {
                        return Err(NanofoldError::invalid(
                            "drive",
                            format!(
                                "crease {column} (edge {}) to {:.3}°",
                                model.pattern.creases[column],
                                target.to_degrees()
                            ),
                            "the target's sign contradicts the crease's assignment (mountain ≤ 0 ≤ valley)",
                        ));
                    }
                }
            }
        }
        // A step far below the closure's own tolerance cannot move the path: it would stop
        // as `locked` for want of progress, which it is not.
        if !(self.max_step >= MIN_STEP && self.max_step <= 0.5) {
            return Err(NanofoldError::invalid(
                "max_step",
                format!("{:e}", self.max_step),
                format!("must lie in [{MIN_STEP:e}, 0.5] rad"),
            ));
        }
        if !(self.closure_tol >= 1e-14 && self.closure_tol <= 1e-3) {
            return Err(NanofoldError::invalid(
                "closure_tol",
                self.closure_tol,
                "must lie in [1e-14, 1e-3] rad",
            ));
        }
        if !(1..=1_000_000).contains(&self.max_steps) {
            return Err(NanofoldError::invalid(
                "max_steps",
                self.max_steps,
                "must lie in [1, 10^6]",
            ));
        }
        if !(self.kick > 0.0 && self.kick <= 0.1) {
            return Err(NanofoldError::invalid("kick", self.kick, "must lie in (0, 0.1] rad"));
        }
        self.contact.validate()
    }
}

/// The evidence of a contact test past its budget.
fn over_budget(found: usize, when: &str) -> String {
    format!(
        "more than {} pairs of panels overlap {when} (layers stacked deep), the contact test's budget: whether panels cross there was not decided",
        found - 1
    )
}

/// Why a folding path stopped.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The drive's goal was reached.
    Reached,
    /// Two panels would pass through each other in the next step.
    Blocked {
        /// The panels.
        panels: [usize; 2],
    },
    /// The desired velocity has no component in the null space: no motion (0 DOF) that way.
    Locked,
    /// Newton found no rigid state near the next step even with small steps, or the path
    /// left the assigned signs: a branch point or the end of this branch.
    BranchPoint {
        /// The creases (columns) that moved most in the failed step, or that left their
        /// assignment.
        creases: Vec<usize>,
    },
    /// A targets drive ended short of its targets at the rigid state nearest them that its
    /// path reaches: the projected velocity towards them vanished.
    Nearest {
        /// The crease (column) furthest from its target there.
        crease: usize,
        /// The interior vertex the targets leave most open (None: they close every vertex).
        vertex: Option<usize>,
    },
    /// The step budget ran out.
    StepLimit,
    /// More pairs of panels overlap than the contact test's budget (layers stacked deep):
    /// whether the next state's panels cross was not decided, so the path stops before it.
    ContactBudget {
        /// The budget passed.
        pairs: usize,
    },
}

impl crate::names::Named for StopReason {}

/// One accepted state along the path.
#[derive(Debug, Clone, PartialEq)]
pub struct PathStep {
    /// Progress towards the drive's goal, 0 at the start, 1 at the goal.
    pub progress: f64,
    /// Fold angles, rad (one per crease).
    pub fold_angles: Vec<f64>,
    /// Largest vertex closure residual, rad.
    pub max_residual: f64,
    /// Smallest distance between panels sharing no vertex, within the search range.
    pub min_clearance: Option<f64>,
}

/// A folding path and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct FoldPath {
    /// Every accepted state, the start first.
    pub steps: Vec<PathStep>,
    /// Why it stopped.
    pub stop: StopReason,
    /// The stop in words, with its evidence.
    pub evidence: String,
    /// How the path left the flat state (None: it did not start flat).
    pub branch: Option<String>,
    /// Whether it left flat by damped least squares (the rigid state nearest the kicked
    /// one), Newton finding no rigid state from the kick: flat's branches are then not
    /// followed to first order, and a path that goes no further is no witness.
    pub left_flat_damped: bool,
    /// Largest closure residual over every step, rad.
    pub max_closure_residual: f64,
    /// Smallest panel clearance over every step (None: no pair came within the search range).
    pub min_panel_clearance: Option<f64>,
    /// Newton iterations over the whole path (chord steps included).
    pub newton_iterations: usize,
    /// Numeric factorisations of JᵀJ + μI over the whole path: Newton's fresh steps and the
    /// tangents not served by the corrector's last one.
    pub factorisations: usize,
    /// Contact tests over the whole path (one per trial state the corrector closed, and the
    /// start's): near stacked layers each measures millions of pairs.
    pub contact_tests: usize,
    /// What drove it (frames placed on the path measure their progress by it).
    pub drive: Drive,
}

/// The smallest step a path takes, rad.
pub const MIN_STEP: f64 = 1e-6;
/// The smallest goal of an assignment drive, percent of a full fold: above the kick that
/// leaves flat (1e-3 rad), so a path can stop at its goal, not past it.
pub const MIN_GOAL_PERCENT: f64 = 0.1;

/// Kawasaki residuals below this, rad, are a flat-foldable design's noise, not its geometry.
const DESIGN_NOISE: f64 = 1e-4;

/// The kick that leaves flat: `kick`, or more on a sheet whose vertices are flat-foldable
/// only to within float noise ε (a file rounded by its writer): noise splits a flat-foldable
/// vertex's crossing branches within about √ε of flat, so the kick must reach well past
/// that (30 √ε, at most 0.1 rad) to land on the branch the clean design has.
fn noise_kick(model: &FoldingModel, kick: f64) -> f64 {
    let noise = model
        .stars
        .iter()
        .filter(|s| s.sector_angles.len() % 2 == 0)
        .map(|s| {
            let alternating: f64 = s.sector_angles.iter().step_by(2).sum();
            (alternating - std::f64::consts::PI).abs()
        })
        .fold(0.0, f64::max);
    if noise < DESIGN_NOISE {
        kick.max(30.0 * noise.sqrt()).min(0.1)
    } else {
        kick
    }
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Newton's method (least-norm steps) back onto every closure. Returns the iterations, or
/// None when it does not reach `tol` within 30 iterations or runs away (a fold angle beyond
/// π + 0.5; the caller keeps accepted states within [−π, π]).
pub fn restore_closure(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    tol: f64,
    solver: &mut NormalSolver,
) -> Result<Option<usize>> {
    // Newton from a non-finite start never meets its tolerance: refuse it by name.
    if let Some(k) = fold_angles.iter().position(|r| !r.is_finite()) {
        return Err(NanofoldError::invalid(
            format!("fold_angles[{k}]"),
            fold_angles[k],
            "a fold angle must be finite",
        ));
    }
    Ok(correct(model, fold_angles, tol, solver, None, false)?.map(|c| c.iterations))
}

/// The first step after leaving flat, rad (the step control takes it from there).
const INITIAL_STEP: f64 = 0.05;

/// The corrector's first move per unit step (the angle between chord and tangent) the step
/// control aims at.
const TARGET_ANGLE: f64 = 0.1;

/// The most a step grows over the one before.
const MAX_GROWTH: f64 = 2.0;

/// Newton iterations past which the next step does not grow.
const SLOW_CORRECTOR: usize = 6;

/// How closely an event (a crease reaching flat against its assignment, panels crossing)
/// is located: the last step before it is at most this long, rad.
pub const LOCATE: f64 = 1e-6;

/// How closely the contact budget's passing is located, rad: it is a limit of the test, not
/// an event of the folding, and each trial near it measures millions of pairs.
pub const LOCATE_BUDGET: f64 = 1e-2;

/// The step to which a trial's stop is located.
fn located_to(reason: &StopReason) -> f64 {
    match reason {
        StopReason::ContactBudget { .. } => LOCATE_BUDGET,
        _ => LOCATE,
    }
}

/// The residual cut per step for which a corrector (a path's, a frame's polish) reuses its
/// factorisation (chord steps); a step that cuts less is followed by a fresh one.
pub(crate) const CHORD_CONTRACTION: f64 = 0.1;

/// Steps over which progress must grow by 1e-9, or the path counts as stalled.
const STALL_STEPS: usize = 200;

/// μ of the projection and Newton steps, relative to the largest diagonal entry of JᵀJ.
const PATH_REGULARISATION: f64 = 1e-10;

/// The sign each crease's assignment asks for (+1 valley, −1 mountain, 0 otherwise).
pub(crate) fn assigned_signs(model: &FoldingModel) -> Vec<f64> {
    model
        .pattern
        .creases
        .iter()
        .map(|&e| match model.pattern.kinds[e] {
            EdgeKind::Crease(Assignment::Valley) => 1.0,
            EdgeKind::Crease(Assignment::Mountain) => -1.0,
            _ => 0.0,
        })
        .collect()
}

/// Progress of a state towards the drive's goal.
/// The crease whose angle sets a state's progress (the most folded assigned crease, or the
/// driven crease furthest from its target).
pub(crate) fn progress_crease(drive: &Drive, rho: &[f64], signs: &[f64]) -> Option<usize> {
    match drive {
        Drive::Assignment { .. } => (0..rho.len())
            .filter(|&c| signs[c] != 0.0)
            .max_by(|&a, &b| rho[a].abs().total_cmp(&rho[b].abs())),
        Drive::Creases(list) => list
            .iter()
            .max_by(|x, y| (x.1 - rho[x.0]).abs().total_cmp(&(y.1 - rho[y.0]).abs()))
            .map(|&(c, _)| c),
        Drive::Targets { targets, .. } => {
            (0..rho.len()).max_by(|&a, &b| (targets[a] - rho[a]).abs().total_cmp(&(targets[b] - rho[b]).abs()))
        }
    }
}

/// The largest distance of any crease from its target, rad.
fn target_distance(targets: &[f64], rho: &[f64]) -> f64 {
    targets.iter().zip(rho).fold(0.0_f64, |m, (t, r)| m.max((t - r).abs()))
}

/// The progress a state has when crease `crease`, at `value`, is the one that sets it (see
/// [`progress_crease`]): the same number [`progress`] gives, from one crease.
pub(crate) fn progress_by_crease(drive: &Drive, start: &[f64], crease: usize, value: f64) -> f64 {
    match drive {
        Drive::Assignment { to } => value.abs() / PI / (to / 100.0),
        Drive::Creases(list) => {
            let span = list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - start[c]).abs()));
            let target = list.iter().find(|&&(c, _)| c == crease).map_or(value, |&(_, t)| t);
            if span == 0.0 {
                return 1.0;
            }
            1.0 - (target - value).abs() / span
        }
        Drive::Targets { targets, to } => {
            let span = target_distance(targets, start);
            if span == 0.0 {
                return 1.0;
            }
            (1.0 - (targets[crease] - value).abs() / span) / (to / 100.0)
        }
    }
}

pub(crate) fn progress(drive: &Drive, start: &[f64], rho: &[f64], signs: &[f64]) -> f64 {
    match drive {
        Drive::Assignment { to } => {
            let amount = rho
                .iter()
                .zip(signs)
                .filter(|(_, s)| **s != 0.0)
                .fold(0.0_f64, |m, (r, _)| m.max(r.abs()))
                / PI;
            amount / (to / 100.0)
        }
        Drive::Creases(list) => {
            let span = list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - start[c]).abs()));
            if span == 0.0 {
                return 1.0;
            }
            1.0 - list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - rho[c]).abs())) / span
        }
        Drive::Targets { targets, to } => {
            let span = target_distance(targets, start);
            if span == 0.0 {
                return 1.0;
            }
            (1.0 - target_distance(targets, rho) / span) / (to / 100.0)
        }
    }
}

fn desired_velocity(drive: &Drive, rho: &[f64], signs: &[f64]) -> Vec<f64> {
    match drive {
        Drive::Assignment { .. } => signs.to_vec(),
        Drive::Creases(list) => {
            let mut d = vec![0.0; rho.len()];
            for &(c, t) in list {
                d[c] = t - rho[c];
            }
            d
        }
        Drive::Targets { targets, .. } => targets.iter().zip(rho).map(|(t, r)| t - r).collect(),
    }
}

/// Creases whose angle contradicts their assignment by more than `slack`.
fn against_assignment(rho: &[f64], signs: &[f64], slack: f64) -> Vec<usize> {
    (0..rho.len()).filter(|&c| signs[c] * rho[c] < -slack).collect()
}

/// Folds from `start` (a rigid state, or the flat one) as `settings.drive` asks.
pub fn fold_path(model: &FoldingModel, start: &[f64], settings: &FoldSettings) -> Result<FoldPath> {
    Ok(fold_path_observed(model, start, settings, &mut |_| {})?.0)
}

/// [`fold_path`], telling `on_step` of every accepted state as it is accepted (the start
/// first): accepted states are final, so frames can be placed on them while the path goes
/// on. The path's solver comes back with it, its symbolic analysis done.
pub(crate) fn fold_path_observed(
    model: &FoldingModel,
    start: &[f64],
    settings: &FoldSettings,
    on_step: &mut dyn FnMut(&PathStep),
) -> Result<(FoldPath, NormalSolver)> {
    settings.validate(model)?;
    let mut walk = Walk::new(model, start, settings)?;
    let mut told = 0;
    let mut tell = |walk: &Walk| {
        for step in &walk.steps[told..] {
            on_step(step);
        }
        told = walk.steps.len();
    };
    tell(&walk);
    if let Some(stop) = walk.check_start() {
        return Ok(walk.finish(stop));
    }
    if inf_norm(&walk.rho) <= 1e-12 {
        let left = walk.leave_flat()?;
        tell(&walk);
        if let Some(stop) = left {
            return Ok(walk.finish(stop));
        }
    }
    for _ in 0..settings.max_steps {
        let stepped = walk.step()?;
        tell(&walk);
        if let Some(stop) = stepped {
            return Ok(walk.finish(stop));
        }
    }
    let stop = Stop::new(StopReason::StepLimit, format!("{} steps", settings.max_steps));
    Ok(walk.finish(stop))
}

/// Why a path ends, and the evidence.
struct Stop {
    reason: StopReason,
    evidence: String,
}

impl Stop {
    fn new(reason: StopReason, evidence: impl Into<String>) -> Self {
        Stop {
            reason,
            evidence: evidence.into(),
        }
    }
}

/// A path under way: the state, the steps so far and the scratch the steps reuse.
struct Walk<'a> {
    model: &'a FoldingModel,
    settings: &'a FoldSettings,
    start: &'a [f64],
    signs: Vec<f64>,
    solver: NormalSolver,
    poses: Vec<Pose>,
    rho: Vec<f64>,
    steps: Vec<PathStep>,
    newton_iterations: usize,
    branch: Option<String>,
    /// Whether the path left flat by damped least squares, Newton finding nothing.
    left_flat_damped: bool,
    /// The next step's length (the largest fold-angle change), rad.
    h: f64,
    /// The corrector's last factorisation (near `rho`: at the start of its last fresh step).
    carried: Option<Factored>,
    /// The contacts of the first state.
    first_contacts: Option<ContactReport>,
    /// Whether the next step may use the curved predictor ([`Walk::bend`]).
    curved: bool,
    /// The tangent at `rho`, projected beside its contact test ([`Walk::event_and_tangent`]).
    next_tangent: Option<(Tangent, Option<bool>)>,
    /// Whether the motion has one degree of freedom (tested once, on the path's third
    /// state): its path is then one curve whatever the drive, and the curved predictor
    /// serves. With more, the path follows the projected drive, which the tangent
    /// predictor and least-norm corrector define; they are kept as they are.
    one_dof: Option<bool>,
    /// The nearest the goal a landing on it failed from (1 − progress): the goal is then
    /// singular (a flat-folded state), and landing is tried again only from ten times
    /// nearer, each failure costing a dozen factorisations.
    landing_failed: Option<f64>,
    /// A state further along whose contact test passed the budget, and the pairs it
    /// counted: the next steps bisect towards it until it is within [`LOCATE_BUDGET`].
    budget_passed: Option<(Vec<f64>, usize)>,
    /// Contact tests run (counted where the walk is borrowed, beside the tangent).
    contact_tests: std::cell::Cell<usize>,
}

/// A tangent scaled to a largest component of 1, or the size of the projected velocity
/// where it vanishes.
type Tangent = std::result::Result<Vec<f64>, f64>;

/// A trial state's smallest clearance, or the event that stops it.
type Judged = std::result::Result<Option<f64>, Stop>;

/// Creases from which a trial's contact test runs on a second thread beside the next
/// tangent's projection (below, both take well under a millisecond).
const PARALLEL_EVENT_FROM: usize = 500;

/// How one step's trials ended.
enum Trial {
    /// The next state, its smallest clearance, its corrector's record and (where it was
    /// projected beside the contact test) the tangent there.
    Accepted(Vec<f64>, Option<f64>, Correction, Option<(Tangent, Option<bool>)>),
    /// An event located to within [`located_to`] its kind.
    Event(Stop),
    /// Newton found no rigid state, even with the shortest step.
    Lost,
}

impl<'a> Walk<'a> {
    /// The start, closed onto every vertex where it is within 1e-6 rad of rigid.
    fn new(model: &'a FoldingModel, start: &'a [f64], settings: &'a FoldSettings) -> Result<Self> {
        model.expect_fold_angles("start", start)?;
        let mut walk = Walk {
            model,
            settings,
            start,
            signs: assigned_signs(model),
            solver: NormalSolver::new(PATH_REGULARISATION),
            poses: Vec::new(),
            rho: start.to_vec(),
            steps: Vec::new(),
            newton_iterations: 0,
            branch: None,
            left_flat_damped: false,
            h: settings.max_step.min(INITIAL_STEP),
            carried: None,
            first_contacts: None,
            curved: true,
            next_tangent: None,
            one_dof: None,
            landing_failed: None,
            budget_passed: None,
            contact_tests: std::cell::Cell::new(0),
        };
        let mut residual = Vec::with_capacity(3 * model.stars.len());
        closure_residual(model, &walk.rho, &mut residual);
        let start_residual = worst_of(&residual);
        if start_residual > settings.closure_tol {
            match restore_closure(model, &mut walk.rho, settings.closure_tol, &mut walk.solver)? {
                Some(k) if start_residual <= 1e-6 => walk.newton_iterations += k,
                _ => {
                    return Err(NanofoldError::invalid(
                        "start",
                        format!("closure residual {start_residual:.3e} rad"),
                        "the start is not a rigid state (above 1e-6 rad at some vertex)",
                    ))
                }
            }
        }
        let first = walk.contacts(&walk.rho.clone());
        closure_residual(model, &walk.rho, &mut residual);
        walk.record(walk.rho.clone(), worst_of(&residual), first.min_clearance);
        walk.first_contacts = Some(first);
        Ok(walk)
    }

    fn progress_of(&self, rho: &[f64]) -> f64 {
        progress(&self.settings.drive, self.start, rho, &self.signs)
    }

    fn contacts(&mut self, rho: &[f64]) -> ContactReport {
        self.contact_tests.set(self.contact_tests.get() + 1);
        panel_poses(self.model, rho, &mut self.poses);
        panel_contacts(self.model, &self.poses, &self.settings.contact)
    }

    fn record(&mut self, fold_angles: Vec<f64>, max_residual: f64, min_clearance: Option<f64>) {
        self.steps.push(PathStep {
            progress: self.progress_of(&fold_angles),
            fold_angles,
            max_residual,
            min_clearance,
        });
    }

    /// The contact budget passed, or panels crossing, at the start.
    fn check_start(&mut self) -> Option<Stop> {
        let first = self.first_contacts.take()?;
        if let Some(found) = first.overflow {
            return Some(Stop::new(
                StopReason::ContactBudget { pairs: found - 1 },
                over_budget(found, "at the start"),
            ));
        }
        let panels = first.crossing().next()?.panels;
        Some(Stop::new(
            StopReason::Blocked { panels },
            format!("panels {} and {} cross at the start", panels[0], panels[1]),
        ))
    }

    /// Leaving the flat state: a kick along the projected direction, Newton onto the nearest
    /// branch, and every crease's sign checked against its assignment.
    /// The stop of a targets drive whose projected velocity vanishes short of them: the
    /// crease furthest from its target, and the vertex the targets themselves leave most
    /// open.
    fn nearest_to_targets(&self, projected: f64) -> Stop {
        let Drive::Targets { targets, .. } = &self.settings.drive else {
            unreachable!("a targets drive")
        };
        let model = self.model;
        let crease = progress_crease(&self.settings.drive, &self.rho, &self.signs).unwrap_or(0);
        let open = crate::folding::vertex_residuals(model, targets);
        let (star, residual) = open
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map_or((None, 0.0), |(k, &r)| (Some(model.stars[k].vertex), r));
        let targets_note = match star {
            Some(vertex) if residual > self.settings.closure_tol => {
                format!("the targets are no rigid state: they leave vertex {vertex} open by {residual:.3e} rad")
            }
            _ => "the targets close every vertex, but this path does not reach them".to_string(),
        };
        Stop::new(
            StopReason::Nearest {
                crease,
                vertex: star.filter(|_| residual > self.settings.closure_tol),
            },
            format!(
                "at progress {:.6} no step along the drive's velocity, projected onto the rigid motions, brings the state nearer the targets (steps down to {projected:.1e} rad tried): the rigid state nearest them on this path; crease {crease} (edge {}) is furthest, at {:.3}° for {:.3}°; {targets_note}",
                self.progress_of(&self.rho),
                model.pattern.creases[crease],
                self.rho[crease].to_degrees(),
                targets[crease].to_degrees()
            ),
        )
    }

    fn leave_flat(&mut self) -> Result<Option<Stop>> {
        let (model, settings) = (self.model, self.settings);
        // The branch is the assignment's, whatever drives the motion afterwards (a driven
        // crease alone would pick any branch, e.g. a straight line folded on its own).
        let mut d = match &settings.drive {
            // Targets carry the assignment's signs, and say how much each crease folds.
            Drive::Targets { targets, .. } => targets.clone(),
            _ if self.signs.iter().any(|&s| s != 0.0) => self.signs.clone(),
            drive => desired_velocity(drive, &self.rho, &self.signs),
        };
        model.hold_locked(&mut d);
        let factor = self.solver.factor(&closure_jacobian(model, &self.rho))?;
        let v = factor.project(&d);
        let size = inf_norm(&v);
        if size <= 1e-9 * inf_norm(&d).max(f64::MIN_POSITIVE) {
            return Ok(Some(Stop::new(
                StopReason::Locked,
                "no first-order motion from flat in the driven direction",
            )));
        }
        // The noise's kick first; where Newton finds nothing from it, the plain one.
        let raised = noise_kick(model, settings.kick);
        let mut landed = None;
        for kick in [raised, settings.kick] {
            let mut trial: Vec<f64> = self.rho.iter().zip(&v).map(|(r, x)| r + kick * x / size).collect();
            if let Some(correction) = correct(model, &mut trial, settings.closure_tol, &mut self.solver, None, false)? {
                self.newton_iterations += correction.iterations;
                landed = Some((kick, trial, correction, false));
                break;
            }
            // Flat is a branch point: where the first-order direction leads to no branch,
            // damped least squares still find the rigid state nearest the kicked one.
            let mut damped: Vec<f64> = self.rho.iter().zip(&v).map(|(r, x)| r + kick * x / size).collect();
            if let Some(iterations) = damped_projection(model, &mut damped, settings.closure_tol, &mut self.solver)? {
                self.newton_iterations += iterations;
                let correction = Correction {
                    iterations,
                    first: 0.0,
                    residual: crate::folding::vertex_residuals(model, &damped)
                        .into_iter()
                        .fold(0.0, f64::max),
                    factor: None,
                };
                landed = Some((kick, damped, correction, true));
                break;
            }
            if raised == settings.kick {
                break;
            }
        }
        let Some((kick, trial, correction, damped)) = landed else {
            return Ok(Some(Stop::new(
                StopReason::BranchPoint { creases: vec![] },
                format!(
                    "neither Newton nor damped least squares found a rigid state {:.0e} rad from flat along the projected direction (no rigid state there)",
                    settings.kick
                ),
            )));
        };
        let wrong = against_assignment(&trial, &self.signs, 1e-3 * kick);
        if !wrong.is_empty() {
            let evidence = format!(
                "the branch reached from flat folds creases {:?} against their assignment",
                &wrong[..wrong.len().min(8)]
            );
            return Ok(Some(Stop::new(StopReason::BranchPoint { creases: wrong }, evidence)));
        }
        self.branch = Some(format!(
            "left flat by a kick of {kick:.0e} rad along the projected direction, {} onto the closure, every crease's sign checked against its assignment{}",
            if damped { "damped least squares (Newton found no rigid state there)" } else { "Newton" },
            if kick > settings.kick {
                format!(" (the kick raised from {:.0e}: the sheet's vertices are flat-foldable only to its noise, and noise of size ε splits the branches within about √ε of flat)", settings.kick)
            } else {
                String::new()
            }
        ));
        // The kicked state's clearance is recorded, not judged; on a large pattern its
        // contact test runs beside the first tangent's projection.
        let min_clearance = match &correction.factor {
            Some(factored) if model.crease_count() >= PARALLEL_EVENT_FROM => {
                let (contacts, tangent) = self.contacts_and_tangent(&trial, factored);
                self.next_tangent = Some(tangent);
                contacts.min_clearance
            }
            _ => {
                self.carried = correction.factor;
                self.contacts(&trial).min_clearance
            }
        };
        self.rho = trial;
        self.left_flat_damped = damped;
        self.record(self.rho.clone(), correction.residual, min_clearance);
        Ok(None)
    }

    /// One step: predictor, corrector, events, step control. Some(stop) where the path ends.
    fn step(&mut self) -> Result<Option<Stop>> {
        let here = self.progress_of(&self.rho);
        if here >= 1.0 - 1e-9 {
            return Ok(Some(Stop::new(StopReason::Reached, format!("progress {here:.9}"))));
        }
        let tangent = match self.tangent()? {
            Ok(tangent) => tangent,
            Err(size) if matches!(self.settings.drive, Drive::Targets { .. }) => {
                return Ok(Some(self.nearest_to_targets(size)));
            }
            Err(size) => {
                return Ok(Some(Stop::new(
                    StopReason::Locked,
                    format!("the projected velocity vanishes (|P d| = {size:.1e}): no rigid motion this way"),
                )))
            }
        };
        self.h = self.h.min(self.settings.max_step);
        if let Drive::Creases(list) = &self.settings.drive {
            // Do not step past a driven crease's target (to first order).
            for &(c, t) in list {
                if tangent[c] * (t - self.rho[c]) > 0.0 {
                    self.h = self.h.min((t - self.rho[c]) / tangent[c]);
                }
            }
        }
        if let Some(stop) = self.cap_at_targets(&tangent) {
            return Ok(Some(stop));
        }
        if let Some(stop) = self.bisect_budget(here) {
            return Ok(Some(stop));
        }
        let bend = if self.curved && self.one_dof == Some(true) {
            self.bend(&tangent)
        } else {
            None
        };
        let (next, min_clearance, correction) = match self.trials(&tangent, bend.as_ref(), here)? {
            Trial::Accepted(next, min_clearance, correction, tangent) => {
                self.next_tangent = tangent;
                (next, min_clearance, correction)
            }
            Trial::Event(stop) if matches!(stop.reason, StopReason::Nearest { .. }) => return Ok(Some(stop)),
            Trial::Event(stop) => {
                let within = located_to(&stop.reason);
                return Ok(Some(Stop::new(
                    stop.reason,
                    format!("{} (located to {within:.0e} rad)", stop.evidence),
                )));
            }
            Trial::Lost => return Ok(Some(lost(&tangent))),
        };
        // Step control: the corrector's first move from the tangent's prediction ρ + h t is
        // the angle between the chord and the tangent, ∝ h (curvature); aim it at
        // TARGET_ANGLE, and shrink where Newton needed many iterations. With the curved
        // predictor that move is not made: on a one-DOF path (the only kind it serves) the
        // accepted state is the curve's point nearest the tangent's prediction, to leading
        // order, so their distance stands in for it.
        let first = if bend.is_some() {
            next.iter()
                .zip(&self.rho)
                .zip(&tangent)
                .fold(0.0_f64, |m, ((n, r), t)| m.max((n - r - self.h * t).abs()))
        } else {
            correction.first
        };
        // The curved predictor serves while it predicts better than the tangent alone (it
        // does not near a singular end, where the path's higher derivatives grow); the
        // step is sized by the larger of the two moves, so the corrector's own move stays
        // what the step control aims at.
        self.curved = bend.is_none() || correction.first <= first;
        let angle = first.max(correction.first) / self.h;
        let mut grow = if angle > 0.0 { TARGET_ANGLE / angle } else { MAX_GROWTH };
        if correction.iterations > SLOW_CORRECTOR {
            grow = grow.min(0.7);
        }
        self.h *= grow.clamp(0.25, MAX_GROWTH);
        self.carried = if self.next_tangent.is_some() {
            None
        } else {
            correction.factor
        };
        self.rho = next;
        let now = self.progress_of(&self.rho);
        let steps = &self.steps;
        if steps.len() > STALL_STEPS && now - steps[steps.len() - STALL_STEPS].progress < 1e-9 {
            return Ok(Some(Stop::new(
                StopReason::Locked,
                format!("progress {now:.9} grew by less than 1e-9 over the last {STALL_STEPS} steps: the drive has no rigid motion left"),
            )));
        }
        self.record(self.rho.clone(), correction.residual, min_clearance);
        Ok(None)
    }

    /// A targets drive steps no further than the point of the tangent line nearest the
    /// targets; where that point is (nearly) here, the stop `nearest`.
    fn cap_at_targets(&mut self, tangent: &[f64]) -> Option<Stop> {
        let Drive::Targets { targets, .. } = &self.settings.drive else {
            return None;
        };
        let along: f64 = targets
            .iter()
            .zip(&self.rho)
            .zip(tangent)
            .map(|((t, r), x)| (t - r) * x)
            .sum();
        let nearest = along / tangent.iter().map(|x| x * x).sum::<f64>();
        if nearest <= NEAREST_STEP {
            return Some(self.nearest_to_targets(nearest));
        }
        self.h = self.h.min(nearest);
        None
    }

    /// Where a state further along passed the contact budget: the stop, if that state is
    /// within [`LOCATE_BUDGET`] of this one; else the step is capped at half the way there.
    fn bisect_budget(&mut self, here: f64) -> Option<Stop> {
        let (passed, pairs) = self.budget_passed.as_ref()?;
        let bracket = passed
            .iter()
            .zip(&self.rho)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        if bracket <= LOCATE_BUDGET {
            return Some(Stop::new(
                StopReason::ContactBudget { pairs: *pairs },
                format!(
                    "{} (located to {LOCATE_BUDGET:.0e} rad)",
                    over_budget(pairs + 1, &format!("after progress {here:.6}"))
                ),
            ));
        }
        self.h = self.h.min(bracket / 2.0);
        None
    }

    /// Whether a targets drive's trial is no nearer the targets than the state it left: past
    /// the nearest state on a curved path, the tangent's own estimate overshoots, and a
    /// step is taken nearer or not at all.
    fn not_nearer_targets(&self, trial: &[f64]) -> bool {
        let Drive::Targets { targets, .. } = &self.settings.drive else {
            return false;
        };
        let squared = |rho: &[f64]| targets.iter().zip(rho).map(|(t, r)| (t - r) * (t - r)).sum::<f64>();
        squared(trial) >= squared(&self.rho)
    }

    /// The predictor's state h along the tangent (and the curvature terms, if any).
    fn predict(&self, tangent: &[f64], bend: Option<&(Vec<f64>, Vec<f64>)>) -> Vec<f64> {
        let h = self.h;
        let mut trial: Vec<f64> = self.rho.iter().zip(tangent).map(|(r, x)| r + h * x).collect();
        if let Some((q, r)) = bend {
            trial
                .iter_mut()
                .zip(q.iter().zip(r))
                .for_each(|(x, (q, r))| *x += h * h * (q + h * r));
        }
        trial
    }

    /// [`land_on_goal`] from `state`, a failure remembered (from `here`'s distance to the
    /// goal) so that landing is not retried from as far.
    fn land(&mut self, state: &mut [f64], here: f64) -> Result<Option<Correction>> {
        let (model, settings) = (self.model, self.settings);
        let goal = land_on_goal(
            model,
            &settings.drive,
            state,
            &self.signs,
            settings.closure_tol,
            &mut self.solver,
        )?;
        if goal.is_none() {
            let distance = 1.0 - here;
            self.landing_failed = Some(self.landing_failed.map_or(distance, |d| d.min(distance)));
        }
        Ok(goal)
    }

    /// Predictor: the desired velocity projected onto the tangent space, scaled to a largest
    /// component of 1 (h is then the largest fold-angle change, rad). Err(its size) where it
    /// vanishes.
    fn tangent(&mut self) -> Result<std::result::Result<Vec<f64>, f64>> {
        if let Some((tangent, one_dof)) = self.next_tangent.take() {
            self.one_dof = self.one_dof.or(one_dof);
            return Ok(tangent);
        }
        // The corrector's last factorisation serves the projection; else a fresh one.
        let factored = match self.carried.take() {
            Some(factored) => factored,
            None => {
                let jacobian = closure_jacobian(self.model, &self.rho);
                let factor = self.solver.factor(&jacobian)?;
                Factored {
                    jacobian,
                    factor,
                    stale: false,
                }
            }
        };
        let (tangent, one_dof) = self.tangent_with(&self.rho, &factored, self.steps.len());
        self.one_dof = self.one_dof.or(one_dof);
        Ok(tangent)
    }

    /// The tangent at `rho` (a state that will be the path's `states`-th) by a factorisation
    /// near it, and, where not yet known and the state is the third or later, whether the
    /// motion has one degree of freedom.
    fn tangent_with(&self, rho: &[f64], factored: &Factored, states: usize) -> (Tangent, Option<bool>) {
        let mut d = desired_velocity(&self.settings.drive, rho, &self.signs);
        self.model.hold_locked(&mut d);
        let v = factored.project_at(self.model, rho, &d);
        let one_dof = (self.one_dof.is_none() && states >= 3).then(|| factored.one_direction(self.model, rho, &v));
        let size = inf_norm(&v);
        if size <= 1e-9 * inf_norm(&d) {
            return (Err(size), one_dof);
        }
        (Ok(v.iter().map(|x| x / size).collect()), one_dof)
    }

    /// The predictor's curvature terms: near the last accepted state ρ_k the path is the
    /// graph ρ_k + s t + s² q + s³ r over its tangent line (s = ⟨ρ − ρ_k, t⟩ / ⟨t, t⟩),
    /// with q and r fitted to the two states before it (q alone, r = 0, where there is one).
    /// A state that left flat is not used: flat is a branch point, where the path's tangent
    /// is not the projected one. None where no earlier state serves.
    fn bend(&self, tangent: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let from = usize::from(self.branch.is_some());
        let usable = self.steps.get(from..)?;
        let [.., last] = usable else {
            return None;
        };
        let tt: f64 = tangent.iter().map(|t| t * t).sum();
        // Each earlier state's parameter and its offset from the tangent line.
        let offset = |state: &PathStep| -> (f64, Vec<f64>) {
            let delta: Vec<f64> = state
                .fold_angles
                .iter()
                .zip(&last.fold_angles)
                .map(|(a, b)| a - b)
                .collect();
            let s = delta.iter().zip(tangent).map(|(d, t)| d * t).sum::<f64>() / tt;
            (s, delta.iter().zip(tangent).map(|(d, t)| d - s * t).collect())
        };
        match usable {
            [.., before2, before, _] => {
                let ((s1, g1), (s2, g2)) = (offset(before), offset(before2));
                if !(s1 < 0.0 && s2 < s1) {
                    return None;
                }
                // g = s² q + s³ r at s1 and s2.
                let det = s1 * s1 * s2 * s2 * (s2 - s1);
                let q = g1
                    .iter()
                    .zip(&g2)
                    .map(|(a, b)| (a * s2.powi(3) - b * s1.powi(3)) / det)
                    .collect();
                let r = g1
                    .iter()
                    .zip(&g2)
                    .map(|(a, b)| (b * s1 * s1 - a * s2 * s2) / det)
                    .collect();
                Some((q, r))
            }
            [.., before, _] => {
                let (s1, g1) = offset(before);
                if s1.is_nan() || s1 >= 0.0 {
                    return None;
                }
                Some((g1.iter().map(|g| g / (s1 * s1)).collect(), vec![0.0; g1.len()]))
            }
            _ => None,
        }
    }

    /// Corrector: Newton onto every closure. A trial that fails, overshoots the goal, or
    /// meets an event (a crease against its assignment, panels crossing, the contact budget)
    /// is retried shorter; an event is located to within [`located_to`] its kind.
    fn trials(&mut self, tangent: &[f64], bend: Option<&(Vec<f64>, Vec<f64>)>, here: f64) -> Result<Trial> {
        let (model, settings) = (self.model, self.settings);
        // Landing on the goal is tried until a landed state meets an event: at a singular
        // goal (a flat-folded state) holding one crease there can push another past it.
        let mut may_land = self.landing_failed.is_none_or(|failed| 1.0 - here <= failed / 10.0);
        for _ in 0..80 {
            let mut trial = self.predict(tangent, bend);
            // A prediction past the goal lands on it from there, the crease that sets progress
            // held at its goal: the state past it, which the path would not keep, is not
            // corrected first.
            let predicted = self.progress_of(&trial);
            let mut early = None;
            if may_land && predicted > 1.0 + 1e-10 {
                let mut state = trial.clone();
                let goal = self.land(&mut state, here)?;
                may_land = goal.is_some();
                early = goal.map(|landing| (state, landing));
            }
            let landed_early = early.is_some();
            let mut correction = match early {
                Some((state, mut landing)) => {
                    trial = state;
                    landing.factor = None;
                    landing
                }
                None => match correct(model, &mut trial, settings.closure_tol, &mut self.solver, None, true)? {
                    Some(correction) => correction,
                    None => {
                        self.h /= 2.0;
                        if self.h < settings.max_step.min(MIN_STEP) * 1e-3 {
                            return Ok(Trial::Lost);
                        }
                        continue;
                    }
                },
            };
            self.newton_iterations += correction.iterations;
            if trial.iter().any(|r| r.abs() > PI) && matches!(settings.drive, Drive::Creases(_) | Drive::Targets { .. })
            {
                self.h /= 2.0;
                continue;
            }
            if self.not_nearer_targets(&trial) {
                self.h /= 2.0;
                if self.h < NEAREST_STEP {
                    return Ok(Trial::Event(self.nearest_to_targets(self.h)));
                }
                continue;
            }
            let reached = if landed_early {
                predicted
            } else {
                self.progress_of(&trial)
            };
            let mut ahead = self.progress_of(&trial);
            let mut landed = landed_early;
            if !landed && ahead > 1.0 + 1e-10 && may_land {
                // Past the goal: onto it directly, the crease that sets progress held there.
                if let Some(landing) = self.land(&mut trial, here)? {
                    self.newton_iterations += landing.iterations;
                    correction.residual = landing.residual;
                    correction.factor = None;
                    ahead = self.progress_of(&trial);
                    landed = true;
                } else {
                    may_land = false;
                }
            }
            // Overshoot: aim at the goal by the secant on progress.
            let secant = ((1.0 - here) / (reached - here)).clamp(0.05, 0.999_999);
            if ahead > 1.0 + 1e-10 {
                self.h *= secant;
                continue;
            }
            let (judged, tangent) = match &correction.factor {
                Some(factored) if model.crease_count() >= PARALLEL_EVENT_FROM => {
                    self.event_and_tangent(&trial, here, factored)
                }
                _ => (self.event(&trial, here), None),
            };
            let found = match judged {
                Ok(min_clearance) => return Ok(Trial::Accepted(trial, min_clearance, correction, tangent)),
                Err(found) => found,
            };
            if let StopReason::ContactBudget { pairs } = found.reason {
                self.budget_passed = Some((trial, pairs));
            }
            if landed {
                // The event is the landing's: approach the goal from before it instead.
                may_land = false;
                self.h *= secant;
                continue;
            }
            if self.h <= located_to(&found.reason) {
                return Ok(Trial::Event(found));
            }
            self.h /= 2.0;
        }
        Ok(Trial::Lost)
    }

    /// A trial state's event (a crease folded against its assignment, the contact budget
    /// passed, panels crossing), or its smallest panel clearance where there is none.
    fn event(&mut self, trial: &[f64], here: f64) -> std::result::Result<Option<f64>, Stop> {
        against_assignment_event(trial, &self.signs, here)?;
        let contacts = self.contacts(trial);
        contact_event(&contacts, here)
    }

    /// [`Walk::event`], with the contact test on a second thread while this one projects the
    /// tangent at the trial state (the next step's first work, kept where the state is
    /// accepted): on a large pattern the contact test costs about what the projection does.
    fn event_and_tangent(
        &self,
        trial: &[f64],
        here: f64,
        factored: &Factored,
    ) -> (Judged, Option<(Tangent, Option<bool>)>) {
        if let Err(stop) = against_assignment_event(trial, &self.signs, here) {
            return (Err(stop), None);
        }
        let (contacts, tangent) = self.contacts_and_tangent(trial, factored);
        (contact_event(&contacts, here), Some(tangent))
    }

    /// The contact test of `trial` on a second thread, and the tangent there on this one.
    fn contacts_and_tangent(&self, trial: &[f64], factored: &Factored) -> (ContactReport, (Tangent, Option<bool>)) {
        let (model, contact) = (self.model, &self.settings.contact);
        self.contact_tests.set(self.contact_tests.get() + 1);
        std::thread::scope(|scope| {
            let test = scope.spawn(move || {
                let mut poses = Vec::new();
                panel_poses(model, trial, &mut poses);
                panel_contacts(model, &poses, contact)
            });
            let tangent = self.tangent_with(trial, factored, self.steps.len() + 1);
            let contacts = test.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            (contacts, tangent)
        })
    }

    /// The path as it ends, and the solver whose symbolic analysis fits its Jacobian.
    fn finish(self, stop: Stop) -> (FoldPath, NormalSolver) {
        let max_closure_residual = self.steps.iter().map(|s| s.max_residual).fold(0.0, f64::max);
        let min_panel_clearance = self.steps.iter().filter_map(|s| s.min_clearance).reduce(f64::min);
        let path = FoldPath {
            steps: self.steps,
            stop: stop.reason,
            evidence: stop.evidence,
            branch: self.branch,
            left_flat_damped: self.left_flat_damped,
            max_closure_residual,
            min_panel_clearance,
            newton_iterations: self.newton_iterations,
            factorisations: self.solver.factorisations(),
            contact_tests: self.contact_tests.get(),
            drive: self.settings.drive.clone(),
        };
        (path, self.solver)
    }
}

/// The stop where Newton finds no rigid state along the tangent: a branch point, named by
/// the six creases moving fastest along it.
fn lost(tangent: &[f64]) -> Stop {
    let mut creases: Vec<usize> = (0..tangent.len()).collect();
    creases.sort_by(|&a, &b| tangent[b].abs().total_cmp(&tangent[a].abs()));
    creases.truncate(6);
    Stop::new(
        StopReason::BranchPoint { creases },
        "Newton found no rigid state along the projected velocity, even with a step of 1e-9 rad",
    )
}

/// A crease that passes through flat against its assignment has left the branch.
fn against_assignment_event(trial: &[f64], signs: &[f64], here: f64) -> std::result::Result<(), Stop> {
    let wrong = against_assignment(trial, signs, 1e-9);
    if wrong.is_empty() {
        return Ok(());
    }
    let evidence = format!(
        "creases {:?} would fold against their assignment after progress {here:.6}",
        &wrong[..wrong.len().min(8)]
    );
    Err(Stop::new(StopReason::BranchPoint { creases: wrong }, evidence))
}

/// The contact budget passed or panels crossing in a trial state's contact test, or its
/// smallest clearance.
fn contact_event(contacts: &ContactReport, here: f64) -> std::result::Result<Option<f64>, Stop> {
    if let Some(found) = contacts.overflow {
        return Err(Stop::new(
            StopReason::ContactBudget { pairs: found - 1 },
            over_budget(found, &format!("after progress {here:.6}")),
        ));
    }
    if let Some(pair) = contacts.crossing().next() {
        let panels = pair.panels;
        return Err(Stop::new(
            StopReason::Blocked { panels },
            format!(
                "panels {} and {} would pass through each other after progress {here:.6}",
                panels[0], panels[1]
            ),
        ));
    }
    Ok(contacts.min_clearance)
}

/// Moves a state just past the drive's goal onto it: the crease that sets progress is put
/// at its goal and held there while Newton closes every vertex (an assignment's drive, or a
/// single driven crease). None where that does not apply or Newton fails (the caller then
/// shortens the step); `trial` is left unchanged then.
fn land_on_goal(
    model: &FoldingModel,
    drive: &Drive,
    trial: &mut [f64],
    signs: &[f64],
    tol: f64,
    solver: &mut NormalSolver,
) -> Result<Option<Correction>> {
    let (crease, value) = match drive {
        Drive::Assignment { to } => match progress_crease(drive, trial, signs) {
            Some(c) => (c, trial[c].signum() * PI * (to / 100.0)),
            None => return Ok(None),
        },
        Drive::Creases(list) if list.len() == 1 => list[0],
        Drive::Creases(_) | Drive::Targets { .. } => return Ok(None),
    };
    let mut state = trial.to_vec();
    state[crease] = value;
    // Fresh steps only: their last one leaves the residual far below `tol`, so the creases
    // that fold alike with the held one (a Miura-ori's zigzags) end at its angle to
    // rounding, and the goal is the state's progress to rounding too.
    let landed = correct(model, &mut state, tol, solver, Some(crease), false)?;
    if landed.is_some() {
        trial.copy_from_slice(&state);
    }
    Ok(landed)
}

/// What a corrector did.
struct Correction {
    /// Newton iterations.
    iterations: usize,
    /// Largest change of a fold angle in the first iteration, rad.
    first: f64,
    /// Worst vertex residual at the end, rad.
    residual: f64,
    /// The last factorisation.
    factor: Option<Factored>,
}

/// A factorised Jacobian and how far the state has moved since it was made.
struct Factored {
    jacobian: ClosureJacobian,
    factor: NormalFactor,
    /// Chord steps were taken with it: the state is as far from it as the corrections since
    /// its fresh step, not just that step's own (tiny) last correction.
    stale: bool,
}

impl Factored {
    /// Whether the tangent space at `fold_angles` is the one direction `tangent`: a fixed
    /// spread of every crease, projected, keeps less than 1e-3 of its size off `tangent`.
    fn one_direction(&self, model: &FoldingModel, fold_angles: &[f64], tangent: &[f64]) -> bool {
        // Fractional parts of multiples of the golden ratio: every crease moved, unevenly.
        let mut spread: Vec<f64> = (1..=tangent.len())
            .map(|k| (k as f64 * 0.618_033_988_749_894_9).fract() - 0.5)
            .collect();
        model.hold_locked(&mut spread);
        let w = self.project_at(model, fold_angles, &spread);
        let along = w.iter().zip(tangent).map(|(a, b)| a * b).sum::<f64>() / tangent.iter().map(|t| t * t).sum::<f64>();
        let off = w
            .iter()
            .zip(tangent)
            .map(|(a, t)| (a - along * t).powi(2))
            .sum::<f64>()
            .sqrt();
        let size = w.iter().map(|a| a * a).sum::<f64>().sqrt();
        off <= 1e-3 * size
    }

    /// The desired velocity projected onto the tangent space at `fold_angles`. A stale
    /// factorisation's projection v₀ is in the null space of the Jacobian J₀ where it was
    /// made, off by O(δ) from the current J's (δ: the distance moved since); one least-norm
    /// correction v = v₀ − J₀⁺ (J v₀) puts it in J's null space to O(δ²).
    fn project_at(&self, model: &FoldingModel, fold_angles: &[f64], desired: &[f64]) -> Vec<f64> {
        let mut v = self.factor.project(desired);
        if self.stale {
            let here = closure_jacobian(model, fold_angles);
            let mut moved = vec![0.0; here.rows];
            here.apply(&v, &mut moved);
            let mut correction = vec![0.0; v.len()];
            self.jacobian.apply_transpose(&moved, &mut correction);
            self.factor.solve(&mut correction);
            v.iter_mut().zip(&correction).for_each(|(x, c)| *x -= c);
        }
        v
    }
}

/// Newton's least-norm steps back onto every closure ([`restore_closure`]), reporting the
/// first correction's size for step control. With `chord_steps`, once a fresh step has cut
/// the residual tenfold, the factorised Jacobian is reused (chord steps on the new residual)
/// for as long as each step cuts it tenfold again; a chord step costs the residual and a
/// solve, a fresh one the Jacobian and a numeric factorisation as well. Without, every step
/// is fresh: the residual then falls quadratically far below `tol` in its last step, which
/// matters near a singular state (flat), where a residual r leaves the angles some r/σ²
/// off along J's nearly null directions.
fn correct(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    tol: f64,
    solver: &mut NormalSolver,
    held: Option<usize>,
    chord_steps: bool,
) -> Result<Option<Correction>> {
    let mut previous = f64::INFINITY;
    let mut first = 0.0;
    let mut factored: Option<Factored> = None;
    let mut residual = Vec::with_capacity(3 * model.stars.len());
    let mut step = vec![0.0; fold_angles.len()];
    for iteration in 0..30 {
        // The first iteration always factorises, so its residual comes with the Jacobian.
        let fresh_jacobian = if iteration == 0 {
            let jac = closure_jacobian(model, fold_angles);
            residual.clone_from(&jac.residual);
            Some(jac)
        } else {
            closure_residual(model, fold_angles, &mut residual);
            None
        };
        let worst = worst_of(&residual);
        if !worst.is_finite() {
            return Ok(None);
        }
        if worst <= tol {
            return Ok(Some(Correction {
                iterations: iteration,
                first,
                residual: worst,
                factor: factored,
            }));
        }
        // A landing (a crease held at its goal) that does not converge fast is at a
        // singular goal (a flat-folded state): it gives up early, the walk then
        // approaching the goal by the secant instead.
        let patience = if held.is_some() { 1 } else { 3 };
        if iteration > patience && worst > 0.5 * previous {
            return Ok(None);
        }
        let chord = chord_steps && factored.is_some() && worst <= CHORD_CONTRACTION * previous;
        if !chord {
            let mut jac = fresh_jacobian.unwrap_or_else(|| closure_jacobian(model, fold_angles));
            if let Some(c) = held {
                jac.hold(c);
            }
            let factor = solver.factor(&jac)?;
            factored = Some(Factored {
                jacobian: jac,
                factor,
                stale: false,
            });
        }
        previous = worst;
        let last = factored.as_mut().expect("set above");
        last.stale |= chord;
        last.jacobian.apply_transpose(&residual, &mut step);
        last.factor.solve(&mut step);
        if iteration == 0 {
            first = inf_norm(&step);
        }
        for (rho, d) in fold_angles.iter_mut().zip(&step) {
            *rho -= d;
        }
        if fold_angles.iter().any(|r| r.abs() > PI + 0.5) {
            return Ok(None);
        }
    }
    Ok(None)
}

/// A sheet's state off rigid by at most this is an exporter's noise, moved onto the nearest
/// rigid state when read (`docs/model.md#folded-forms`): the worst vertex closure and facet
/// bend in rad, the faces' development mismatch and warp as fractions of the sheet's size.
/// Origami Simulator's compliant solver leaves its float32 exports a few 1e-5 off; the
/// flat-sheet and folded-flat readings allow the same 1e-4.
pub const NOISY_STATE_BOUND: f64 = 1e-4;

/// A nearly rigid state moved onto every vertex closure (`docs/model.md#folded-forms`).
#[derive(Debug, Clone, PartialEq)]
pub struct Projection {
    /// The rigid state, rad (one per crease).
    pub fold_angles: Vec<f64>,
    /// Largest change of any fold angle, rad.
    pub max_change: f64,
    /// Root-mean-square change over the creases, rad.
    pub rms_change: f64,
    /// Worst vertex closure residual before, rad.
    pub residual_before: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// The rigid state near `fold_angles` (a compliant simulator's export, say): Newton's
/// least-norm steps onto every vertex closure, within `tol` rad per vertex. Least-norm steps
/// move the fold angles as little as each linearisation allows, so the result is the nearest
/// rigid state to first order. Fails by name when Newton does not converge.
pub fn project_to_rigid(model: &FoldingModel, fold_angles: &[f64], tol: f64) -> Result<Projection> {
    let residual_before = super::vertex_residuals(model, fold_angles)
        .into_iter()
        .fold(0.0, f64::max);
    let mut rho = fold_angles.to_vec();
    let mut solver = NormalSolver::new(1e-10);
    let newton = restore_closure(model, &mut rho, tol, &mut solver)?;
    let iterations = match newton {
        Some(iterations) => iterations,
        None => {
            // Near a branch point (a sheet barely folded, a vertex nearly flat) Newton's
            // fast convergence fails: damped steps still converge, linearly.
            rho.copy_from_slice(fold_angles);
            damped_projection(model, &mut rho, tol, &mut solver)?.ok_or_else(|| {
                crate::error::NanofoldError::invalid(
                    "fold_angles",
                    format!("worst vertex closure {residual_before:.3e} rad"),
                    "no rigid state near it: neither Newton nor damped least squares converges (too far from rigid to project)",
                )
            })?
        }
    };
    let changes: Vec<f64> = rho.iter().zip(fold_angles).map(|(a, b)| (a - b).abs()).collect();
    let max_change = changes.iter().copied().fold(0.0, f64::max);
    let rms_change = (changes.iter().map(|c| c * c).sum::<f64>() / changes.len().max(1) as f64).sqrt();
    Ok(Projection {
        fold_angles: rho,
        max_change,
        rms_change,
        residual_before,
        iterations,
    })
}

/// A targets drive whose best step towards them is below this, rad, has stopped at the
/// rigid state nearest them.
const NEAREST_STEP: f64 = 1e-9;

/// Most iterations of [`damped_projection`].
const DAMPED_ITERATIONS: usize = 500;

/// Levenberg–Marquardt onto every vertex closure: steps (JᵀJ + μI)⁻¹Jᵀr with μ raised
/// where a step fails to cut ‖r‖ and lowered where it does. Where the Jacobian loses rank
/// (a branch point) it converges linearly where Newton does not converge. Returns the
/// iterations, or None when μ runs away or the iterations run out.
pub fn damped_projection(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    tol: f64,
    solver: &mut NormalSolver,
) -> Result<Option<usize>> {
    let mut damping = 1e-6;
    let mut residual = Vec::with_capacity(3 * model.stars.len());
    let mut trial = fold_angles.to_vec();
    let mut step = vec![0.0; fold_angles.len()];
    let norm = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    for iteration in 0..DAMPED_ITERATIONS {
        let jacobian = closure_jacobian(model, fold_angles);
        if worst_of(&jacobian.residual) <= tol {
            solver.set_regularisation(PATH_REGULARISATION);
            return Ok(Some(iteration));
        }
        let size = norm(&jacobian.residual);
        loop {
            solver.set_regularisation(damping);
            let factor = solver.factor(&jacobian)?;
            jacobian.apply_transpose(&jacobian.residual, &mut step);
            factor.solve(&mut step);
            for ((t, r), d) in trial.iter_mut().zip(fold_angles.iter()).zip(&step) {
                *t = r - d;
            }
            closure_residual(model, &trial, &mut residual);
            if norm(&residual) < size && trial.iter().all(|r| r.abs() <= PI) {
                fold_angles.copy_from_slice(&trial);
                damping = (damping / 3.0).max(1e-12);
                break;
            }
            damping *= 10.0;
            if damping > 1e3 {
                solver.set_regularisation(PATH_REGULARISATION);
                return Ok(None);
            }
        }
    }
    solver.set_regularisation(PATH_REGULARISATION);
    Ok(None)
}

impl crate::names::Answer for FoldPath {
    fn verdict_name(&self) -> &'static str {
        crate::names::variant_name(&self.stop)
    }

    fn evidence(&self) -> &str {
        &self.evidence
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::generate::{BirdBaseSpec, MiuraSpec};

    fn miura_4x4() -> FoldingModel {
        let spec = MiuraSpec {
            rows: 4,
            cols: 4,
            ..MiuraSpec::default()
        };
        FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap()
    }

    /// A state a few steps along the default path to `to`.
    fn along(model: &FoldingModel, to: f64) -> Vec<f64> {
        let settings = FoldSettings {
            drive: Drive::Assignment { to },
            ..FoldSettings::default()
        };
        let path = fold_path(model, &model.given_fold_angles(), &settings).unwrap();
        assert_eq!(path.stop, StopReason::Reached, "{}", path.evidence);
        path.steps.last().unwrap().fold_angles.clone()
    }

    fn factored_at(model: &FoldingModel, rho: &[f64], stale: bool) -> Factored {
        let jacobian = closure_jacobian(model, rho);
        let factor = NormalSolver::new(PATH_REGULARISATION).factor(&jacobian).unwrap();
        Factored {
            jacobian,
            factor,
            stale,
        }
    }

    /// |J v| / |v| at `rho`: how far v is from the tangent space there.
    fn off_tangent(model: &FoldingModel, rho: &[f64], v: &[f64]) -> f64 {
        let jac = closure_jacobian(model, rho);
        let mut jv = vec![0.0; jac.rows];
        jac.apply(v, &mut jv);
        let norm = |x: &[f64]| x.iter().map(|a| a * a).sum::<f64>().sqrt();
        norm(&jv) / norm(v)
    }

    /// A factorisation made δ away projects the drive off the tangent space by O(δ); the
    /// stale correction leaves O(δ²): tenfold nearer, the error falls about tenfold without
    /// it and about a hundredfold with it.
    #[test]
    fn a_stale_projection_is_corrected_to_second_order() {
        let model = miura_4x4();
        let rho = along(&model, 50.0);
        let signs = assigned_signs(&model);
        let offset: Vec<f64> = (0..rho.len()).map(|k| ((k * 7 % 11) as f64 - 5.0) / 5.0).collect();
        let errors = |delta: f64, stale: bool| {
            let made_at: Vec<f64> = rho.iter().zip(&offset).map(|(r, o)| r + delta * o).collect();
            let v = factored_at(&model, &made_at, stale).project_at(&model, &rho, &signs);
            off_tangent(&model, &rho, &v)
        };
        let (plain, plain_nearer) = (errors(1e-3, false), errors(1e-4, false));
        let (corrected, corrected_nearer) = (errors(1e-3, true), errors(1e-4, true));
        assert!(
            plain / plain_nearer > 7.0 && plain / plain_nearer < 14.0,
            "{plain:e} {plain_nearer:e}"
        );
        assert!(
            corrected / corrected_nearer > 70.0,
            "{corrected:e} {corrected_nearer:e}"
        );
        assert!(corrected < 1e-2 * plain, "{corrected:e} {plain:e}");
    }

    /// The one-direction test: a Miura-ori moves one way; the bird base, off flat, three.
    #[test]
    fn one_degree_of_freedom_is_told_from_several() {
        let miura = miura_4x4();
        let bird = FoldingModel::new(BirdBaseSpec::default().build().unwrap().build().unwrap()).unwrap();
        for (model, one) in [(&miura, true), (&bird, false)] {
            let rho = along(model, 30.0);
            let factored = factored_at(model, &rho, false);
            let signs = assigned_signs(model);
            let tangent = factored.project_at(model, &rho, &signs);
            assert_eq!(factored.one_direction(model, &rho, &tangent), one);
        }
    }

    /// Chord steps end within the tolerance asked for, in fewer factorisations than fresh
    /// steps, at nearly the same rigid state.
    #[test]
    fn chord_steps_reach_the_tolerance_with_fewer_factorisations() {
        let model = miura_4x4();
        let rho = along(&model, 50.0);
        let signs = assigned_signs(&model);
        let start: Vec<f64> = rho.iter().zip(&signs).map(|(r, s)| r + 0.02 * s).collect();
        let mut ends = Vec::new();
        for chord_steps in [false, true] {
            let mut state = start.clone();
            let mut solver = NormalSolver::new(PATH_REGULARISATION);
            let correction = correct(&model, &mut state, 1e-12, &mut solver, None, chord_steps)
                .unwrap()
                .expect("Newton converges from 0.02 rad off");
            assert!(correction.residual <= 1e-12);
            assert_eq!(
                super::super::closure::vertex_residuals(&model, &state)
                    .into_iter()
                    .fold(0.0, f64::max),
                correction.residual
            );
            ends.push((state, solver.factorisations(), correction.iterations));
        }
        let (fresh, chord) = (&ends[0], &ends[1]);
        assert!(chord.1 < fresh.1, "{} against {} factorisations", chord.1, fresh.1);
        assert!(chord.2 > chord.1, "chord steps were taken");
        let apart = fresh
            .0
            .iter()
            .zip(&chord.0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // Both are least-norm corrections from one start: their feet differ by second-order
        // terms of the 0.02 rad correction, far below the correction itself.
        assert!(apart < 1e-6, "{apart:e}");
    }

    /// A state just past the goal lands on it: progress 1 to rounding, every vertex closed,
    /// and the move is small (the state was within a step of the goal).
    #[test]
    fn a_state_past_the_goal_lands_on_it() {
        let model = miura_4x4();
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 50.0 },
            ..FoldSettings::default()
        };
        let start = model.given_fold_angles();
        let path = fold_path(&model, &start, &settings).unwrap();
        let past = path.steps.last().unwrap().fold_angles.clone();
        let signs = assigned_signs(&model);
        let goal = Drive::Assignment { to: 48.0 };
        assert!(progress(&goal, &start, &past, &signs) > 1.03);
        let mut state = past.clone();
        let mut solver = NormalSolver::new(PATH_REGULARISATION);
        let landed = land_on_goal(&model, &goal, &mut state, &signs, 1e-12, &mut solver)
            .unwrap()
            .expect("Newton lands within a step");
        assert!(landed.residual <= 1e-12);
        assert!((progress(&goal, &start, &state, &signs) - 1.0).abs() < 1e-14);
        let moved = state.iter().zip(&past).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(moved < 0.1, "{moved}");
        // Several driven creases: no single crease sets the goal, so nothing is done.
        let several = Drive::Creases(vec![(0, 0.1), (1, 0.1)]);
        let mut untouched = past.clone();
        assert!(
            land_on_goal(&model, &several, &mut untouched, &signs, 1e-12, &mut solver)
                .unwrap()
                .is_none()
        );
        assert_eq!(untouched, past);
    }
}
