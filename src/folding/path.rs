//! Rigid folding motion (Tachi; `docs/model.md#folding-paths`): a desired velocity of the
//! fold angles projected onto the null space of the closure Jacobian, a step, and Newton
//! back onto every vertex closure; panel contact checked at every step.

use super::closure::closure_jacobian;
use super::contact::{panel_contacts, ContactSettings};
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
    let n = model.crease_count();
    if start.len() != n {
        return Err(NanofoldError::invalid(
            "start",
            format!("{} fold angles", start.len()),
            format!("one per crease ({n})"),
        ));
    }
    let signs = assigned_signs(model);
    let mut solver = NormalSolver::new(PATH_REGULARISATION);
    let mut poses: Vec<Pose> = Vec::new();
    let mut rho = start.to_vec();
    let mut newton_iterations = 0;
    let start_residual = closure_jacobian(model, &rho).worst_residual();
    if start_residual > settings.closure_tol {
        match restore_closure(model, &mut rho, settings.closure_tol, &mut solver)? {
            Some(k) if start_residual <= 1e-6 => newton_iterations += k,
            _ => {
                return Err(NanofoldError::invalid(
                    "start",
                    format!("closure residual {start_residual:.3e} rad"),
                    "the start is not a rigid state (above 1e-6 rad at some vertex)",
                ))
            }
        }
    }
    let contact_at = |rho: &[f64], poses: &mut Vec<Pose>| {
        panel_poses(model, rho, poses);
        panel_contacts(model, poses, &settings.contact)
    };
    let first = contact_at(&rho, &mut poses);
    let mut steps = vec![PathStep {
        progress: progress(&settings.drive, start, &rho, &signs),
        fold_angles: rho.clone(),
        max_residual: closure_jacobian(model, &rho).worst_residual(),
        min_clearance: first.min_clearance,
    }];
    let finish = |steps: Vec<PathStep>, stop: StopReason, evidence: String, branch: Option<String>, newton| {
        let max_closure_residual = steps.iter().map(|s| s.max_residual).fold(0.0, f64::max);
        let min_panel_clearance = steps.iter().filter_map(|s| s.min_clearance).reduce(f64::min);
        Ok(FoldPath {
            steps,
            stop,
            evidence,
            branch,
            max_closure_residual,
            min_panel_clearance,
            newton_iterations: newton,
            drive: settings.drive.clone(),
        })
    };
    if let Some(found) = first.overflow {
        return finish(
            steps,
            StopReason::ContactBudget { pairs: found - 1 },
            over_budget(found, "at the start"),
            None,
            newton_iterations,
        );
    }
    if let Some(pair) = first.crossing().next() {
        let panels = pair.panels;
        return finish(
            steps,
            StopReason::Blocked { panels },
            format!("panels {} and {} cross at the start", panels[0], panels[1]),
            None,
            newton_iterations,
        );
    }

    // Leaving the flat state: a kick along the projected direction, Newton onto the nearest
    // branch, and every crease's sign checked against its assignment.
    let mut branch = None;
    if inf_norm(&rho) <= 1e-12 {
        // The branch is the assignment's, whatever drives the motion afterwards (a driven
        // crease alone would pick any branch, e.g. a straight line folded on its own).
        let mut d = if signs.iter().any(|&s| s != 0.0) {
            signs.clone()
        } else {
            desired_velocity(&settings.drive, &rho, &signs)
        };
        model.hold_locked(&mut d);
        let factor = solver.factor(&closure_jacobian(model, &rho))?;
        let v = factor.project(&d);
        let size = inf_norm(&v);
        if size <= 1e-9 * inf_norm(&d).max(f64::MIN_POSITIVE) {
            return finish(
                steps,
                StopReason::Locked,
                "no first-order motion from flat in the driven direction".into(),
                None,
                newton_iterations,
            );
        }
        // The noise's kick first; where Newton finds nothing from it, the plain one.
        let raised = noise_kick(model, settings.kick);
        let mut landed = None;
        for kick in [raised, settings.kick] {
            let mut trial: Vec<f64> = rho.iter().zip(&v).map(|(r, x)| r + kick * x / size).collect();
            if let Some(k) = restore_closure(model, &mut trial, settings.closure_tol, &mut solver)? {
                newton_iterations += k;
                landed = Some((kick, trial));
                break;
            }
            if raised == settings.kick {
                break;
            }
        }
        let Some((kick, trial)) = landed else {
            return finish(
                steps,
                StopReason::BranchPoint { creases: vec![] },
                format!(
                    "Newton found no rigid state {:.0e} rad from flat along the projected direction",
                    settings.kick
                ),
                None,
                newton_iterations,
            );
        };
        let wrong = against_assignment(&trial, &signs, 1e-3 * kick);
        if !wrong.is_empty() {
            let evidence = format!(
                "the branch reached from flat folds creases {:?} against their assignment",
                &wrong[..wrong.len().min(8)]
            );
            return finish(
                steps,
                StopReason::BranchPoint { creases: wrong },
                evidence,
                None,
                newton_iterations,
            );
        }
        branch = Some(format!(
            "left flat by a kick of {kick:.0e} rad along the projected direction, Newton onto the closure, every crease's sign checked against its assignment{}",
            if kick > settings.kick {
                format!(" (the kick raised from {:.0e}: the sheet's vertices are flat-foldable only to its noise, and noise of size ε splits the branches within about √ε of flat)", settings.kick)
            } else {
                String::new()
            }
        ));
        rho = trial;
        let contacts = contact_at(&rho, &mut poses);
        steps.push(PathStep {
            progress: progress(&settings.drive, start, &rho, &signs),
            fold_angles: rho.clone(),
            max_residual: closure_jacobian(model, &rho).worst_residual(),
            min_clearance: contacts.min_clearance,
        });
    }

    let mut h = settings.max_step.min(INITIAL_STEP);
    let mut carried: Option<NormalFactor> = None;
    for _ in 0..settings.max_steps {
        let here = progress(&settings.drive, start, &rho, &signs);
        if here >= 1.0 - 1e-9 {
            return finish(
                steps,
                StopReason::Reached,
                format!("progress {here:.9}"),
                branch,
                newton_iterations,
            );
        }
        // Predictor: the desired velocity projected onto the tangent space, scaled to a
        // largest component of 1 (h is then the largest fold-angle change, rad).
        // The corrector's last factorisation, made within its last (tiny) correction of
        // here, serves the projection; else a fresh one.
        let factor = match carried.take() {
            Some(factor) => factor,
            None => solver.factor(&closure_jacobian(model, &rho))?,
        };
        let mut d = desired_velocity(&settings.drive, &rho, &signs);
        model.hold_locked(&mut d);
        let v = factor.project(&d);
        let size = inf_norm(&v);
        if size <= 1e-9 * inf_norm(&d) {
            return finish(
                steps,
                StopReason::Locked,
                format!("the projected velocity vanishes (|P d| = {size:.1e}): no rigid motion this way"),
                branch,
                newton_iterations,
            );
        }
        let tangent: Vec<f64> = v.iter().map(|x| x / size).collect();
        h = h.min(settings.max_step);
        if let Drive::Creases(list) = &settings.drive {
            // Do not step past a driven crease's target (to first order).
            for &(c, t) in list {
                if tangent[c] * (t - rho[c]) > 0.0 {
                    h = h.min((t - rho[c]) / tangent[c]);
                }
            }
        }
        // Corrector: Newton onto every closure. A trial that fails, overshoots the goal, or
        // meets an event (a crease against its assignment, panels crossing, the contact
        // budget) is retried shorter; an event is located to within LOCATE rad.
        let mut accepted = None;
        let mut event: Option<(StopReason, String)> = None;
        // Landing on the goal is tried until a landed state meets an event: at a singular
        // goal (a flat-folded state) holding one crease there can push another past it.
        let mut may_land = true;
        for _ in 0..80 {
            let mut trial: Vec<f64> = rho.iter().zip(&tangent).map(|(r, x)| r + h * x).collect();
            let corrected = correct(model, &mut trial, settings.closure_tol, &mut solver, None)?;
            let Some(correction) = corrected else {
                h /= 2.0;
                if h < settings.max_step.min(MIN_STEP) * 1e-3 {
                    break;
                }
                continue;
            };
            newton_iterations += correction.iterations;
            if trial.iter().any(|r| r.abs() > PI) && matches!(settings.drive, Drive::Creases(_)) {
                h /= 2.0;
                continue;
            }
            let reached = progress(&settings.drive, start, &trial, &signs);
            let mut ahead = reached;
            let mut correction = correction;
            let mut landed = false;
            if ahead > 1.0 + 1e-10 && may_land {
                // Past the goal: onto it directly, the crease that sets progress held there.
                if let Some(landing) = land_on_goal(
                    model,
                    &settings.drive,
                    &mut trial,
                    &signs,
                    settings.closure_tol,
                    &mut solver,
                )? {
                    newton_iterations += landing.iterations;
                    correction.residual = landing.residual;
                    correction.factor = None;
                    ahead = progress(&settings.drive, start, &trial, &signs);
                    landed = true;
                }
            }
            // Overshoot: aim at the goal by the secant on progress.
            let secant = ((1.0 - here) / (reached - here)).clamp(0.05, 0.999_999);
            if ahead > 1.0 + 1e-10 {
                h *= secant;
                continue;
            }
            // A crease that passes through flat against its assignment has left the branch.
            let wrong = against_assignment(&trial, &signs, 1e-9);
            let found = if !wrong.is_empty() {
                let evidence = format!(
                    "creases {:?} would fold against their assignment after progress {here:.6}",
                    &wrong[..wrong.len().min(8)]
                );
                (StopReason::BranchPoint { creases: wrong }, evidence)
            } else {
                let contacts = contact_at(&trial, &mut poses);
                if let Some(found) = contacts.overflow {
                    (
                        StopReason::ContactBudget { pairs: found - 1 },
                        over_budget(found, &format!("after progress {here:.6}")),
                    )
                } else if let Some(pair) = contacts.crossing().next() {
                    let panels = pair.panels;
                    (
                        StopReason::Blocked { panels },
                        format!(
                            "panels {} and {} would pass through each other after progress {here:.6}",
                            panels[0], panels[1]
                        ),
                    )
                } else {
                    accepted = Some((trial, contacts.min_clearance, correction));
                    break;
                }
            };
            if landed {
                // The event is the landing's: approach the goal from before it instead.
                may_land = false;
                h *= secant;
                continue;
            }
            if h <= LOCATE {
                event = Some(found);
                break;
            }
            h /= 2.0;
        }
        if let Some((stop, evidence)) = event {
            return finish(
                steps,
                stop,
                format!("{evidence} (located to {LOCATE:.0e} rad)"),
                branch,
                newton_iterations,
            );
        }
        let Some((next, min_clearance, correction)) = accepted else {
            let mut creases: Vec<usize> = (0..n).collect();
            creases.sort_by(|&a, &b| tangent[b].abs().total_cmp(&tangent[a].abs()));
            creases.truncate(6);
            return finish(
                steps,
                StopReason::BranchPoint { creases },
                "Newton found no rigid state along the projected velocity, even with a step of 1e-9 rad".into(),
                branch,
                newton_iterations,
            );
        };
        // Step control: the corrector's first move over the step is the angle between the
        // chord and the tangent, ∝ h (curvature); aim it at TARGET_ANGLE, and shrink where
        // Newton needed many iterations.
        let angle = correction.first / h;
        let mut grow = if angle > 0.0 { TARGET_ANGLE / angle } else { MAX_GROWTH };
        if correction.iterations > SLOW_CORRECTOR {
            grow = grow.min(0.7);
        }
        h *= grow.clamp(0.25, MAX_GROWTH);
        carried = correction.factor;
        rho = next;
        let now = progress(&settings.drive, start, &rho, &signs);
        if steps.len() > STALL_STEPS && now - steps[steps.len() - STALL_STEPS].progress < 1e-9 {
            return finish(
                steps,
                StopReason::Locked,
                format!("progress {now:.9} grew by less than 1e-9 over the last {STALL_STEPS} steps: the drive has no rigid motion left"),
                branch,
                newton_iterations,
            );
        }
        steps.push(PathStep {
            progress: now,
            fold_angles: rho.clone(),
            max_residual: correction.residual,
            min_clearance,
        });
    }
    finish(
        steps,
        StopReason::StepLimit,
        format!("{} steps", settings.max_steps),
        branch,
        newton_iterations,
    )
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
            // Zeroed, not removed: the sparsity pattern (and its symbolic analysis) stays.
            for entry in jac.entries.iter_mut().filter(|e| e.1 == c) {
                entry.2 = 0.0;
            }
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
