//! Rigid folding motion (Tachi; `docs/model.md#folding-paths`): a desired velocity of the
//! fold angles projected onto the null space of the closure Jacobian, a step, and Newton
//! back onto every vertex closure; panel contact checked at every step.

use super::closure::closure_jacobian;
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
    /// the most folded crease reaches `to` × π.
    Assignment {
        /// Fraction of full folding at which to stop, in (0, 1].
        to: f64,
    },
    /// The listed creases (fold-angle columns) towards their target angles (rad).
    Creases(Vec<(usize, f64)>),
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
            drive: Drive::Assignment { to: 1.0 },
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
                if !(*to >= MIN_GOAL && *to <= 1.0) {
                    return Err(NanofoldError::invalid(
                        "drive.to",
                        format!("{to:e}"),
                        format!("must lie in [{MIN_GOAL:e}, 1]"),
                    ));
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
#[derive(Debug, Clone, PartialEq)]
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
    /// The step budget ran out.
    StepLimit,
    /// More pairs of panels overlap than the contact test's budget (layers stacked deep):
    /// whether the next state's panels cross was not decided, so the path stops before it.
    ContactBudget {
        /// The budget passed.
        pairs: usize,
    },
}

impl StopReason {
    /// The name used in reports.
    pub fn as_str(&self) -> &'static str {
        match self {
            StopReason::Reached => "reached",
            StopReason::Blocked { .. } => "blocked",
            StopReason::Locked => "locked",
            StopReason::BranchPoint { .. } => "branch_point",
            StopReason::StepLimit => "step_limit",
            StopReason::ContactBudget { .. } => "contact_budget",
        }
    }
}

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
    /// Largest closure residual over every step, rad.
    pub max_closure_residual: f64,
    /// Smallest panel clearance over every step (None: no pair came within the search range).
    pub min_panel_clearance: Option<f64>,
    /// Newton iterations over the whole path.
    pub newton_iterations: usize,
    /// What drove it (frames placed on the path measure their progress by it).
    pub drive: Drive,
}

/// The smallest step a path takes, rad.
pub const MIN_STEP: f64 = 1e-6;
/// The smallest goal of an assignment drive, as a fraction of a full fold: above the kick
/// that leaves flat (1e-3 rad), so a path can stop at its goal, not past it.
pub const MIN_GOAL: f64 = 1e-3;

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
    Ok(correct(model, fold_angles, tol, solver, None)?.map(|c| c.iterations))
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

/// How closely an event (a crease reaching flat against its assignment, panels crossing,
/// the contact budget) is located: the last step before it is at most this long, rad.
pub const LOCATE: f64 = 1e-6;

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
    }
}

/// The progress a state has when crease `crease`, at `value`, is the one that sets it (see
/// [`progress_crease`]): the same number [`progress`] gives, from one crease.
pub(crate) fn progress_by_crease(drive: &Drive, start: &[f64], crease: usize, value: f64) -> f64 {
    match drive {
        Drive::Assignment { to } => value.abs() / PI / to,
        Drive::Creases(list) => {
            let span = list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - start[c]).abs()));
            let target = list.iter().find(|&&(c, _)| c == crease).map_or(value, |&(_, t)| t);
            if span == 0.0 {
                return 1.0;
            }
            1.0 - (target - value).abs() / span
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
            amount / to
        }
        Drive::Creases(list) => {
            let span = list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - start[c]).abs()));
            if span == 0.0 {
                return 1.0;
            }
            1.0 - list.iter().fold(0.0_f64, |m, &(c, t)| m.max((t - rho[c]).abs())) / span
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
    }
}

/// Creases whose angle contradicts their assignment by more than `slack`.
fn against_assignment(rho: &[f64], signs: &[f64], slack: f64) -> Vec<usize> {
    (0..rho.len()).filter(|&c| signs[c] * rho[c] < -slack).collect()
}

/// Folds from `start` (a rigid state, or the flat one) as `settings.drive` asks.
pub fn fold_path(model: &FoldingModel, start: &[f64], settings: &FoldSettings) -> Result<FoldPath> {
    settings.validate(model)?;
    let mut walk = Walk::new(model, start, settings)?;
    if let Some(stop) = walk.check_start() {
        return Ok(walk.finish(stop));
    }
    if inf_norm(&walk.rho) <= 1e-12 {
        if let Some(stop) = walk.leave_flat()? {
            return Ok(walk.finish(stop));
        }
    }
    for _ in 0..settings.max_steps {
        if let Some(stop) = walk.step()? {
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
    /// The next step's length (the largest fold-angle change), rad.
    h: f64,
    /// The corrector's last factorisation, made within its last (tiny) correction of `rho`.
    carried: Option<NormalFactor>,
    /// The contacts of the first state.
    first_contacts: Option<ContactReport>,
}

/// How one step's trials ended.
enum Trial {
    /// The next state, its smallest clearance and its corrector's record.
    Accepted(Vec<f64>, Option<f64>, Correction),
    /// An event located to within [`LOCATE`].
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
            h: settings.max_step.min(INITIAL_STEP),
            carried: None,
            first_contacts: None,
        };
        let start_residual = closure_jacobian(model, &walk.rho).worst_residual();
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
        walk.record(
            walk.rho.clone(),
            closure_jacobian(model, &walk.rho).worst_residual(),
            first.min_clearance,
        );
        walk.first_contacts = Some(first);
        Ok(walk)
    }

    fn progress_of(&self, rho: &[f64]) -> f64 {
        progress(&self.settings.drive, self.start, rho, &self.signs)
    }

    fn contacts(&mut self, rho: &[f64]) -> ContactReport {
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
    fn leave_flat(&mut self) -> Result<Option<Stop>> {
        let (model, settings) = (self.model, self.settings);
        // The branch is the assignment's, whatever drives the motion afterwards (a driven
        // crease alone would pick any branch, e.g. a straight line folded on its own).
        let mut d = if self.signs.iter().any(|&s| s != 0.0) {
            self.signs.clone()
        } else {
            desired_velocity(&settings.drive, &self.rho, &self.signs)
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
            if let Some(k) = restore_closure(model, &mut trial, settings.closure_tol, &mut self.solver)? {
                self.newton_iterations += k;
                landed = Some((kick, trial));
                break;
            }
            if raised == settings.kick {
                break;
            }
        }
        let Some((kick, trial)) = landed else {
            return Ok(Some(Stop::new(
                StopReason::BranchPoint { creases: vec![] },
                format!(
                    "Newton found no rigid state {:.0e} rad from flat along the projected direction",
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
            "left flat by a kick of {kick:.0e} rad along the projected direction, Newton onto the closure, every crease's sign checked against its assignment{}",
            if kick > settings.kick {
                format!(" (the kick raised from {:.0e}: the sheet's vertices are flat-foldable only to its noise, and noise of size ε splits the branches within about √ε of flat)", settings.kick)
            } else {
                String::new()
            }
        ));
        self.rho = trial;
        let contacts = self.contacts(&self.rho.clone());
        self.record(
            self.rho.clone(),
            closure_jacobian(model, &self.rho).worst_residual(),
            contacts.min_clearance,
        );
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
        let (next, min_clearance, correction) = match self.trials(&tangent, here)? {
            Trial::Accepted(next, min_clearance, correction) => (next, min_clearance, correction),
            Trial::Event(stop) => {
                return Ok(Some(Stop::new(
                    stop.reason,
                    format!("{} (located to {LOCATE:.0e} rad)", stop.evidence),
                )))
            }
            Trial::Lost => {
                let mut creases: Vec<usize> = (0..tangent.len()).collect();
                creases.sort_by(|&a, &b| tangent[b].abs().total_cmp(&tangent[a].abs()));
                creases.truncate(6);
                return Ok(Some(Stop::new(
                    StopReason::BranchPoint { creases },
                    "Newton found no rigid state along the projected velocity, even with a step of 1e-9 rad",
                )));
            }
        };
        // Step control: the corrector's first move over the step is the angle between the
        // chord and the tangent, ∝ h (curvature); aim it at TARGET_ANGLE, and shrink where
        // Newton needed many iterations.
        let angle = correction.first / self.h;
        let mut grow = if angle > 0.0 { TARGET_ANGLE / angle } else { MAX_GROWTH };
        if correction.iterations > SLOW_CORRECTOR {
            grow = grow.min(0.7);
        }
        self.h *= grow.clamp(0.25, MAX_GROWTH);
        self.carried = correction.factor;
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

    /// Predictor: the desired velocity projected onto the tangent space, scaled to a largest
    /// component of 1 (h is then the largest fold-angle change, rad). Err(its size) where it
    /// vanishes.
    fn tangent(&mut self) -> Result<std::result::Result<Vec<f64>, f64>> {
        // The corrector's last factorisation serves the projection; else a fresh one.
        let factor = match self.carried.take() {
            Some(factor) => factor,
            None => self.solver.factor(&closure_jacobian(self.model, &self.rho))?,
        };
        let mut d = desired_velocity(&self.settings.drive, &self.rho, &self.signs);
        self.model.hold_locked(&mut d);
        let v = factor.project(&d);
        let size = inf_norm(&v);
        if size <= 1e-9 * inf_norm(&d) {
            return Ok(Err(size));
        }
        Ok(Ok(v.iter().map(|x| x / size).collect()))
    }

    /// Corrector: Newton onto every closure. A trial that fails, overshoots the goal, or
    /// meets an event (a crease against its assignment, panels crossing, the contact budget)
    /// is retried shorter; an event is located to within LOCATE rad.
    fn trials(&mut self, tangent: &[f64], here: f64) -> Result<Trial> {
        let (model, settings) = (self.model, self.settings);
        // Landing on the goal is tried until a landed state meets an event: at a singular
        // goal (a flat-folded state) holding one crease there can push another past it.
        let mut may_land = true;
        for _ in 0..80 {
            let h = self.h;
            let mut trial: Vec<f64> = self.rho.iter().zip(tangent).map(|(r, x)| r + h * x).collect();
            let Some(mut correction) = correct(model, &mut trial, settings.closure_tol, &mut self.solver, None)? else {
                self.h /= 2.0;
                if self.h < settings.max_step.min(MIN_STEP) * 1e-3 {
                    return Ok(Trial::Lost);
                }
                continue;
            };
            self.newton_iterations += correction.iterations;
            if trial.iter().any(|r| r.abs() > PI) && matches!(settings.drive, Drive::Creases(_)) {
                self.h /= 2.0;
                continue;
            }
            let reached = self.progress_of(&trial);
            let mut ahead = reached;
            let mut landed = false;
            if ahead > 1.0 + 1e-10 && may_land {
                // Past the goal: onto it directly, the crease that sets progress held there.
                let goal = land_on_goal(
                    model,
                    &settings.drive,
                    &mut trial,
                    &self.signs,
                    settings.closure_tol,
                    &mut self.solver,
                )?;
                if let Some(landing) = goal {
                    self.newton_iterations += landing.iterations;
                    correction.residual = landing.residual;
                    correction.factor = None;
                    ahead = self.progress_of(&trial);
                    landed = true;
                }
            }
            // Overshoot: aim at the goal by the secant on progress.
            let secant = ((1.0 - here) / (reached - here)).clamp(0.05, 0.999_999);
            if ahead > 1.0 + 1e-10 {
                self.h *= secant;
                continue;
            }
            let found = match self.event(&trial, here) {
                Ok(min_clearance) => return Ok(Trial::Accepted(trial, min_clearance, correction)),
                Err(found) => found,
            };
            if landed {
                // The event is the landing's: approach the goal from before it instead.
                may_land = false;
                self.h *= secant;
                continue;
            }
            if self.h <= LOCATE {
                return Ok(Trial::Event(found));
            }
            self.h /= 2.0;
        }
        Ok(Trial::Lost)
    }

    /// A trial state's event (a crease folded against its assignment, the contact budget
    /// passed, panels crossing), or its smallest panel clearance where there is none.
    fn event(&mut self, trial: &[f64], here: f64) -> std::result::Result<Option<f64>, Stop> {
        // A crease that passes through flat against its assignment has left the branch.
        let wrong = against_assignment(trial, &self.signs, 1e-9);
        if !wrong.is_empty() {
            let evidence = format!(
                "creases {:?} would fold against their assignment after progress {here:.6}",
                &wrong[..wrong.len().min(8)]
            );
            return Err(Stop::new(StopReason::BranchPoint { creases: wrong }, evidence));
        }
        let contacts = self.contacts(trial);
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

    /// The path as it ends.
    fn finish(self, stop: Stop) -> FoldPath {
        let max_closure_residual = self.steps.iter().map(|s| s.max_residual).fold(0.0, f64::max);
        let min_panel_clearance = self.steps.iter().filter_map(|s| s.min_clearance).reduce(f64::min);
        FoldPath {
            steps: self.steps,
            stop: stop.reason,
            evidence: stop.evidence,
            branch: self.branch,
            max_closure_residual,
            min_panel_clearance,
            newton_iterations: self.newton_iterations,
            drive: self.settings.drive.clone(),
        }
    }
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
            Some(c) => (c, trial[c].signum() * PI * to),
            None => return Ok(None),
        },
        Drive::Creases(list) if list.len() == 1 => list[0],
        Drive::Creases(_) => return Ok(None),
    };
    let mut state = trial.to_vec();
    state[crease] = value;
    let landed = correct(model, &mut state, tol, solver, Some(crease))?;
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
    /// The last factorisation (at the state before the last correction).
    factor: Option<NormalFactor>,
}

/// Newton's least-norm steps back onto every closure ([`restore_closure`]), reporting the
/// first correction's size for step control.
fn correct(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    tol: f64,
    solver: &mut NormalSolver,
    held: Option<usize>,
) -> Result<Option<Correction>> {
    let mut previous = f64::INFINITY;
    let mut first = 0.0;
    let mut last = None;
    for iteration in 0..30 {
        let mut jac = closure_jacobian(model, fold_angles);
        if let Some(c) = held {
            jac.hold(c);
        }
        let worst = jac.worst_residual();
        if !worst.is_finite() {
            return Ok(None);
        }
        if worst <= tol {
            return Ok(Some(Correction {
                iterations: iteration,
                first,
                residual: worst,
                factor: last,
            }));
        }
        if iteration > 3 && worst > 0.5 * previous {
            return Ok(None);
        }
        previous = worst;
        let factor = solver.factor(&jac)?;
        let mut step = vec![0.0; jac.cols];
        jac.apply_transpose(&jac.residual, &mut step);
        factor.solve(&mut step);
        if iteration == 0 {
            first = inf_norm(&step);
        }
        for (rho, d) in fold_angles.iter_mut().zip(&step) {
            *rho -= d;
        }
        last = Some(factor);
        if fold_angles.iter().any(|r| r.abs() > PI + 0.5) {
            return Ok(None);
        }
    }
    Ok(None)
}

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
    let iterations = restore_closure(model, &mut rho, tol, &mut solver)?.ok_or_else(|| {
        crate::error::NanofoldError::invalid(
            "fold_angles",
            format!("worst vertex closure {residual_before:.3e} rad"),
            "Newton found no rigid state near it (too far from rigid to project)",
        )
    })?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pattern::generate::MiuraSpec;

    /// A state just past the goal lands on it: progress 1 to rounding, every vertex closed,
    /// and the move is small (the state was within a step of the goal).
    #[test]
    fn a_state_past_the_goal_lands_on_it() {
        let spec = MiuraSpec {
            rows: 4,
            cols: 4,
            ..MiuraSpec::default()
        };
        let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 0.5 },
            ..FoldSettings::default()
        };
        let start = model.given_fold_angles();
        let path = fold_path(&model, &start, &settings).unwrap();
        let past = path.steps.last().unwrap().fold_angles.clone();
        let signs = assigned_signs(&model);
        let goal = Drive::Assignment { to: 0.48 };
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
