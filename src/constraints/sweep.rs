//! The exact reference for every fit (`docs/model.md#constraint-curves`): drive one crease, hold the locked ones, and
//! solve loop closure by Newton at every sample, continuing along one branch from the
//! pattern's folded state (secant predictor, Newton corrector, adaptive step).

use super::{CurveSamples, Setup, Source};
use crate::error::{NanofoldError, Result};
use crate::geometry::kinematics::{closure_jacobian, closure_residual, refine_closure, solve_closure};
use crate::pattern::VertexPattern;
use nalgebra::DVector;
use std::f64::consts::PI;

/// Newton tolerance on the closure residual of every accepted point, radians.
pub const CLOSURE_TOL: f64 = 1e-13;
const NEWTON_ITERATIONS: usize = 12;
/// Extra Newton steps allowed after convergence (see [`refine_closure`]).
pub const REFINE_ITERATIONS: usize = 60;
/// Largest change of any dependent angle in one accepted step (rad): keeps the path on
/// one branch near singular configurations.
const MAX_DEPENDENT_CHANGE: f64 = 0.05;
/// Below this step (in the sweep parameter) the continuation gives up.
const MIN_STEP: f64 = 1e-11;
/// Largest continuation step of the driver sweep, rad. Not capped by the sample spacing:
/// a narrow range far from the folded start (90°–90.001°) would take ~10⁷ steps to reach.
const MAX_SWEEP_STEP: f64 = 0.035;

/// Why the continuation stopped short.
#[derive(Debug, Clone)]
pub(super) enum Stop {
    /// No closed configuration beyond this parameter value (a turning point or a limit).
    NoSolution { reached: f64 },
    /// A dependent crease would pass ±180° (its faces would pass through each other).
    FoldsThrough { reached: f64, ray: usize },
}

/// Path following of the free rays while the held rays move with a scalar parameter.
pub(super) struct Continuation<'a> {
    sectors: &'a [f64],
    free: &'a [usize],
    /// Ray fold angles of the current point.
    pub rho: Vec<f64>,
    /// Current parameter value.
    pub param: f64,
    /// The previous accepted point (parameter, free angles) for the secant predictor.
    last: Option<(f64, Vec<f64>)>,
    step: f64,
    max_step: f64,
}

impl<'a> Continuation<'a> {
    pub fn new(sectors: &'a [f64], free: &'a [usize], rho: Vec<f64>, param: f64, max_step: f64) -> Self {
        Continuation {
            sectors,
            free,
            rho,
            param,
            last: None,
            step: max_step,
            max_step,
        }
    }

    fn free_values(&self, rho: &[f64]) -> Vec<f64> {
        self.free.iter().map(|&k| rho[k]).collect()
    }

    /// Predicted free angles at `next` (held rays already set in `trial`): secant through
    /// the last two points, or the implicit-function tangent at the start.
    fn predict(&self, next: f64, trial: &mut [f64], held: &[usize]) {
        let current = self.free_values(&self.rho);
        if let Some((last_param, last_free)) = &self.last {
            let ratio = (next - self.param) / (self.param - last_param);
            for (i, &k) in self.free.iter().enumerate() {
                trial[k] = current[i] + (current[i] - last_free[i]) * ratio;
            }
            return;
        }
        // J_free Δfree = −J_held Δheld (first order), minimum-norm.
        // One Jacobian for both column sets: free rays first, then held rays.
        let columns: Vec<usize> = self.free.iter().chain(held).copied().collect();
        let (_, jac) = closure_jacobian(self.sectors, &self.rho, &columns);
        let (j_free, j_held) = (
            jac.columns(0, self.free.len()),
            jac.columns(self.free.len(), held.len()),
        );
        let delta_held = DVector::from_iterator(held.len(), held.iter().map(|&k| trial[k] - self.rho[k]));
        let rhs = -(j_held * delta_held);
        if let Ok(delta) = j_free.into_owned().svd(true, true).solve(&rhs, 1e-10) {
            for (i, &k) in self.free.iter().enumerate() {
                trial[k] = self.rho[k] + delta[i];
            }
        }
    }

    /// Follows the path to parameter `target`; `held_at(param, rho)` writes the held rays.
    pub fn advance(
        &mut self,
        target: f64,
        held: &[usize],
        held_at: &dyn Fn(f64, &mut [f64]),
    ) -> std::result::Result<(), Stop> {
        while self.param != target {
            let remaining = target - self.param;
            let length = self.step.min(remaining.abs());
            let next = if length == remaining.abs() {
                target
            } else {
                self.param + length * remaining.signum()
            };
            let mut trial = self.rho.clone();
            held_at(next, &mut trial);
            self.predict(next, &mut trial, held);
            let predicted = self.free_values(&trial);
            let current = self.free_values(&self.rho);
            let solved = solve_closure(self.sectors, &mut trial, self.free, CLOSURE_TOL, NEWTON_ITERATIONS);
            let accepted = solved.is_ok() && {
                let corrected = self.free_values(&trial);
                let prediction = max_difference(&predicted, &current);
                let correction = max_difference(&corrected, &predicted);
                let change = max_difference(&corrected, &current);
                change <= MAX_DEPENDENT_CHANGE && correction <= 0.5 * prediction + 1e-7
            };
            if !accepted {
                self.step *= 0.5;
                if self.step < MIN_STEP {
                    return Err(Stop::NoSolution { reached: self.param });
                }
                continue;
            }
            if let Some(&ray) = self.free.iter().find(|&&k| trial[k].abs() > PI + 1e-9) {
                return Err(Stop::FoldsThrough {
                    reached: self.param,
                    ray,
                });
            }
            refine_closure(self.sectors, &mut trial, self.free, REFINE_ITERATIONS);
            self.last = Some((self.param, current));
            self.param = next;
            self.rho = trial;
            self.step = (self.step * 1.5).min(self.max_step);
        }
        Ok(())
    }
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Drives `setup.driver` over `domain` on a uniform grid of `samples` points.
pub fn sweep(pattern: &VertexPattern, setup: &Setup, domain: [f64; 2], samples: usize) -> Result<CurveSamples> {
    let sectors = &pattern.sector_angles;
    let driver_ray = pattern.creases[setup.driver].ray;
    let mut rho = pattern.folded_ray_angles();
    let free_rays: Vec<usize> = setup.dependents.iter().map(|&c| pattern.creases[c].ray).collect();
    let lock_rays: Vec<(usize, f64, f64)> = setup
        .locked
        .iter()
        .map(|&(c, value)| {
            let ray = pattern.creases[c].ray;
            (ray, rho[ray], value)
        })
        .collect();
    let driver_label = pattern.creases[setup.driver].label.clone();
    let folded_drive = rho[driver_ray];

    // Stage 1: move the locked creases from their folded values to the lock values, first
    // with the driver held at its folded value, and if that path is blocked with the driver
    // moving too (minimum-norm).
    if lock_rays.iter().any(|&(_, from, to)| from != to) {
        let held: Vec<usize> = lock_rays.iter().map(|&(ray, _, _)| ray).collect();
        let lerp = |s: f64, r: &mut [f64]| {
            for &(ray, from, to) in &lock_rays {
                r[ray] = from + s * (to - from);
            }
        };
        let driver_free: Vec<usize> = free_rays.iter().copied().chain([driver_ray]).collect();
        let mut first_stop = None;
        for (moving, also_held) in [(&free_rays, Some(driver_ray)), (&driver_free, None)] {
            let held_now: Vec<usize> = held.iter().copied().chain(also_held).collect();
            let mut continuation = Continuation::new(sectors, moving, rho.clone(), 0.0, 0.02);
            match continuation.advance(1.0, &held_now, &lerp) {
                Ok(()) => {
                    rho = continuation.rho;
                    first_stop = None;
                    break;
                }
                Err(stop) => {
                    first_stop.get_or_insert(stop);
                }
            }
        }
        if let Some(stop) = first_stop {
            let (reached, why) = match stop {
                Stop::NoSolution { reached } => (reached, "loop closure has no solution there".to_string()),
                Stop::FoldsThrough { reached, ray } => {
                    (reached, format!("{} would pass ±180°", ray_label(pattern, ray)))
                }
            };
            let locks = lock_rays
                .iter()
                .map(|&(ray, from, to)| {
                    format!(
                        "{} at {:.4}°",
                        ray_label(pattern, ray),
                        (from + reached * (to - from)).to_degrees()
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            return Err(NanofoldError::Unreachable {
                what: format!(
                    "the locked angles from the folded state with {driver_label} held at {:.4}°",
                    folded_drive.to_degrees()
                ),
                reached: format!("{locks} ({:.1}% of the way)", 100.0 * reached),
                reason: format!("{why}; with {driver_label} free the path is blocked too"),
            });
        }
    }
    for &(ray, _, to) in &lock_rays {
        rho[ray] = to;
    }
    let start_drive = rho[driver_ray];
    let starts_flat = rho.iter().all(|a| a.abs() < 1e-6);

    // Stage 2: the driver sweep, outwards from its folded value in both directions.
    let grid: Vec<f64> = (0..samples)
        .map(|i| domain[0] + (domain[1] - domain[0]) * i as f64 / (samples - 1) as f64)
        .collect();
    let held = [driver_ray];
    let set_driver = |value: f64, r: &mut [f64]| r[driver_ray] = value;
    let mut points: Vec<(f64, Vec<f64>)> = Vec::with_capacity(samples);
    for direction in [1.0, -1.0] {
        let mut path = Continuation::new(sectors, &free_rays, rho.clone(), start_drive, MAX_SWEEP_STEP);
        let targets: Vec<f64> = if direction > 0.0 {
            grid.iter().copied().filter(|&g| g >= start_drive).collect()
        } else {
            grid.iter().rev().copied().filter(|&g| g < start_drive).collect()
        };
        for target in targets {
            path.advance(target, &held, &set_driver).map_err(|stop| {
                let (reached, reason) = match stop {
                    Stop::NoSolution { reached } if (reached - start_drive).abs() < 1e-9 => (
                        reached,
                        "the vertex is rigid there: with these creases held, no closed configuration moves the driver"
                            .to_string(),
                    ),
                    Stop::NoSolution { reached } => (
                        reached,
                        "loop closure has no solution beyond it (the driven crease reaches a turning point or a limit)"
                            .to_string(),
                    ),
                    Stop::FoldsThrough { reached, ray } => (
                        reached,
                        format!(
                            "{} would pass ±180°, its faces through each other",
                            ray_label(pattern, ray)
                        ),
                    ),
                };
                NanofoldError::Unreachable {
                    what: format!(
                        "{driver_label} from {:.4}° (folded {:.4}°) to {:.4}°",
                        start_drive.to_degrees(),
                        folded_drive.to_degrees(),
                        target.to_degrees()
                    ),
                    reached: format!("{driver_label} = {:.6}°", reached.to_degrees()),
                    reason: if starts_flat {
                        format!(
                            "{reason}; the locked angles were reached only at the flat state, where branches of \
                             motion cross, so no branch is selected: lock other creases, or lock these at their folded angles"
                        )
                    } else {
                        reason
                    },
                }
            })?;
            points.push((target, path.rho.clone()));
        }
    }
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    take_limits_at_singular_samples(sectors, &free_rays, &mut points);

    let mut fold_angles = Vec::with_capacity(points.len());
    let mut max_closure_residual: f64 = 0.0;
    for (_, ray_angles) in &points {
        max_closure_residual = max_closure_residual.max(closure_residual(sectors, ray_angles));
        fold_angles.push(pattern.creases.iter().map(|c| ray_angles[c.ray]).collect::<Vec<_>>());
    }
    Ok(CurveSamples {
        setup: setup.clone(),
        source: Source::Sweep,
        domain,
        drive_angles: points.iter().map(|p| p.0).collect(),
        fold_angles,
        max_closure_residual,
    })
}

/// Below this σ_min/σ_max of the free rays' closure Jacobian a sample is singular.
const SINGULAR_RATIO: f64 = 1e-6;

/// At a singular sample (a bifurcation such as the flat state of a degree-4 vertex, where
/// another branch crosses) loop closure does not pin the point along the Jacobian's kernel:
/// Newton keeps whatever offset the predictor had, up to ~1e-8 rad, on the other branch.
/// The branch's own value there is its limit, taken from the nearest regular samples by a
/// local degree-5 polynomial (inter- or extrapolation, error ~h⁶), then refined by Newton.
fn take_limits_at_singular_samples(sectors: &[f64], free: &[usize], points: &mut [(f64, Vec<f64>)]) {
    let singular: Vec<bool> = points
        .iter()
        .map(|(_, rho)| {
            let (_, jac) = closure_jacobian(sectors, rho, free);
            let sv = jac.svd(false, false).singular_values;
            sv.min() < SINGULAR_RATIO * sv.max()
        })
        .collect();
    let regular: Vec<usize> = (0..points.len()).filter(|&i| !singular[i]).collect();
    if regular.len() < 6 {
        return;
    }
    for i in (0..points.len()).filter(|&i| singular[i]) {
        let mut nearest = regular.clone();
        nearest.sort_by_key(|&j| j.abs_diff(i));
        nearest.truncate(6);
        let theta = points[i].0;
        let mut rho = points[i].1.clone();
        for &k in free {
            rho[k] = nearest
                .iter()
                .map(|&j| {
                    let weight: f64 = nearest
                        .iter()
                        .filter(|&&m| m != j)
                        .map(|&m| (theta - points[m].0) / (points[j].0 - points[m].0))
                        .product();
                    weight * points[j].1[k]
                })
                .sum();
        }
        refine_closure(sectors, &mut rho, free, REFINE_ITERATIONS);
        if closure_residual(sectors, &rho) <= CLOSURE_TOL {
            points[i].1 = rho;
        }
    }
}

fn ray_label(pattern: &VertexPattern, ray: usize) -> String {
    pattern
        .creases
        .iter()
        .find(|c| c.ray == ray)
        .map_or_else(|| format!("ray {ray}"), |c| c.label.clone())
}
