//! Leaving a flat start (`docs/model.md#panel-networks`): at a star that lies flat the
//! closure's Jacobian loses its out-of-plane row, and several branches (mountain–valley
//! choices) cross, so the saddle-point system cannot say where the panels go. The branch is
//! the one the actuation pushes towards: the acceleration at rest under the first-order
//! closure (the push the hinges' torques give, in the kinetic metric) is followed by a kick
//! of [`KICK`] rad, and Newton's least-norm steps land on the nearest branch. Along that
//! branch, modelled to second order by two of its points, the motion from rest is the
//! one-coordinate equation of the thesis's closed chains,
//!   (gᵀMg) σ̈ = g·(τ(t) − Kρ − C(ρ, gσ̇)gσ̇ + Q_drag) − gᵀM h σ̇²,  g = ρ′(σ), h = ρ″(σ),
//! integrated (RK4, with the work of the actuation and the drag's dissipation) until σ
//! reaches the kick's size; the integrator takes over there, from the exact branch point.
//! Its error is O(KICK²) relative over a segment that lasts a few per cent of a period.

use super::algorithms::{
    update_bias, update_drag, update_kinematics, update_mass_matrix, update_stars, update_velocities, NetworkData,
};
use super::kkt::KktSystem;
use super::manifold::{mass_times, projection_solver, restore};
use super::model::NetworkModel;
use crate::error::{NanofoldError, Result};
use crate::folding::closure_jacobian;
use crate::folding::normal::NormalSolver;
use crate::pattern::crease_pattern::EdgeKind;
use crate::pattern::Assignment;

/// Size of the branch segment modelled in closed form, rad (the largest crease's angle at
/// its end).
pub const KICK: f64 = 1e-3;
/// A star counts as flat when every free crease of it lies within this of 0, rad.
const FLAT: f64 = 1e-12;
/// Alternations of Newton and the shift along the push to land on a branch point.
const BRANCH_ITERATIONS: usize = 500;
/// RK4 steps over the segment.
const SEGMENT_STEPS: usize = 2000;

/// Where the integrator starts after leaving a flat start along a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchStart {
    /// Time at the end of the segment, s.
    pub time: f64,
    /// The branch point there (every closure holds), rad.
    pub angles: Vec<f64>,
    /// Rates there, rad/s.
    pub rates: Vec<f64>,
    /// Work of the actuation over the segment, J.
    pub work: f64,
    /// Energy the air took over the segment, J.
    pub dissipation: f64,
    /// The branch's direction at flat (unit 2-norm).
    pub direction: Vec<f64>,
    /// The branch in words, for reports.
    pub note: String,
}

/// The branch a flat start leaves along and the state at the end of its segment; None when
/// no star lies flat, or when nothing pushes (the start stays at rest).
pub fn leave_flat(model: &NetworkModel) -> Result<Option<BranchStart>> {
    let start = &model.start;
    let flat_star = model
        .folding
        .stars
        .iter()
        .any(|star| star.columns.iter().all(|&c| model.locked(c) || start[c].abs() <= FLAT));
    if !flat_star {
        return Ok(None);
    }
    let n = model.columns();
    let mut data = NetworkData::new(model);
    let mut kkt = KktSystem::new(model)?;
    // The push: the actuation at its full strength (a ramp's torque starts from zero, but it
    // grows along the same direction).
    let torque: Vec<f64> = (0..n)
        .map(|c| {
            let drive = &model.forcing.hinges[c];
            if drive.actuated {
                model.hinges[c].stiffness * drive.target
            } else {
                0.0
            }
        })
        .collect();
    let rates = vec![0.0; n];
    let forces: Vec<f64> = (0..n)
        .map(|c| torque[c] - model.hinges[c].stiffness * start[c])
        .collect();
    let mut push = vec![0.0; n];
    accelerations(model, start, &rates, &forces, &mut data, &mut kkt, &mut push)?;
    let size = push.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if !(size > 0.0 && size.is_finite()) {
        return Ok(None);
    }
    let mut solver = projection_solver();
    // Candidate branches: kicks along the push and along the crease assignment's signs (each
    // projected onto the first-order motions), Newton onto the closures; the branch taken is
    // the one the push favours most in the kinetic metric (Gauss's least constraint from
    // rest: the largest (τ·d)² / dᵀMd with τ·d > 0).
    let mut candidates: Vec<(Vec<f64>, &str)> = vec![(push.clone(), "the push of the actuation")];
    let signs: Vec<f64> = (0..n)
        .map(
            |c| match model.folding.pattern.kinds[model.folding.pattern.creases[c]] {
                EdgeKind::Crease(Assignment::Valley) if !model.locked(c) => 1.0,
                EdgeKind::Crease(Assignment::Mountain) if !model.locked(c) => -1.0,
                _ => 0.0,
            },
        )
        .collect();
    if signs.iter().any(|&s| s != 0.0) {
        let jacobian = closure_jacobian(&model.folding, start);
        let projected = NormalSolver::new(1e-10).factor(&jacobian)?.project(&signs);
        candidates.push((projected, "the crease assignment"));
    }
    update_kinematics(model, start, &mut data);
    update_mass_matrix(model, &mut data);
    let mut best: Option<(f64, Vec<f64>, &str)> = None;
    for (direction, source) in candidates {
        let largest = direction.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !(largest > 0.0 && largest.is_finite()) {
            continue;
        }
        let mut x: Vec<f64> = start
            .iter()
            .zip(&direction)
            .map(|(s, d)| s + KICK * d / largest)
            .collect();
        if restore(model, &mut x, &mut solver).is_err() {
            continue;
        }
        let chord: Vec<f64> = x.iter().zip(start).map(|(a, b)| a - b).collect();
        if chord.iter().fold(0.0_f64, |m, v| m.max(v.abs())) < 0.5 * KICK {
            continue;
        }
        let mut mass = vec![0.0; n];
        mass_times(model, &data, &chord, &mut mass);
        let inertia: f64 = chord.iter().zip(&mass).map(|(a, b)| a * b).sum();
        let drive: f64 = chord.iter().zip(&torque).map(|(a, b)| a * b).sum();
        if drive > 0.0 && inertia > 0.0 {
            let score = drive * drive / inertia;
            if best.as_ref().is_none_or(|(s, _, _)| score > *s) {
                best = Some((score, x, source));
            }
        }
    }
    let Some((_, kicked, source)) = best else {
        return Err(NanofoldError::invalid(
            "pattern",
            "a flat start",
            format!("Newton found no rigid state {KICK:e} rad from flat along the push of the actuation or the assignment that the actuation drives forward: no branch leaves flat that way"),
        ));
    };
    let chord: Vec<f64> = kicked.iter().zip(start).map(|(k, s)| k - s).collect();
    let norm = chord.iter().map(|v| v * v).sum::<f64>().sqrt();
    let direction: Vec<f64> = chord.iter().map(|v| v / norm).collect();
    let sigma_end = direction.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let sigma_end = KICK / sigma_end;
    // Two branch points, at σ_end / 2 and σ_end, give ρ(σ) = ρ₀ + σ d₀ + ½ σ² d₁.
    let half = branch_point(model, start, &direction, 0.5 * sigma_end, &kicked, &mut solver)?;
    let end = branch_point(model, start, &direction, sigma_end, &kicked, &mut solver)?;
    let x_half: Vec<f64> = half.iter().zip(start).map(|(a, b)| a - b).collect();
    let x_end: Vec<f64> = end.iter().zip(start).map(|(a, b)| a - b).collect();
    let d0: Vec<f64> = (0..n).map(|c| (4.0 * x_half[c] - x_end[c]) / sigma_end).collect();
    let d1: Vec<f64> = (0..n)
        .map(|c| 4.0 * (x_end[c] - 2.0 * x_half[c]) / (sigma_end * sigma_end))
        .collect();
    let segment = Segment {
        model,
        start,
        d0: &d0,
        d1: &d1,
    };
    // Duration guess from the push at flat: σ ≈ ½ a t² (or ∝ t³ under a ramp, found by doubling).
    let mut state = [0.0; 4];
    let (mut t, mut h) = (0.0, 0.0);
    let first = segment.acceleration(0.0, 0.0, 0.0, &mut data)?;
    let mut horizon = if first > 0.0 {
        (2.0 * sigma_end / first).sqrt()
    } else {
        let mut probe = 1e-9;
        while segment.acceleration(probe, 0.0, 0.0, &mut data)? <= 0.0 {
            probe *= 2.0;
            if probe > 1e9 {
                return Ok(None);
            }
        }
        probe
    };
    'outer: for _ in 0..60 {
        h = horizon / SEGMENT_STEPS as f64;
        state = [0.0; 4];
        t = 0.0;
        for _ in 0..4 * SEGMENT_STEPS {
            let next = segment.rk4(t, &state, h, &mut data)?;
            if next[0] >= sigma_end {
                // The end lies within this step: bisect on the step length.
                let (mut lo, mut hi) = (0.0, h);
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    if segment.rk4(t, &state, mid, &mut data)?[0] >= sigma_end {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                state = segment.rk4(t, &state, hi, &mut data)?;
                t += hi;
                break 'outer;
            }
            if next[0] < 0.0 {
                return Err(NanofoldError::invalid(
                    "pattern",
                    "a flat start",
                    "the push turns back towards flat along its branch",
                ));
            }
            state = next;
            t += h;
        }
        horizon *= 2.0;
        if horizon > 1e9 {
            return Ok(None);
        }
    }
    if state[0] < sigma_end * (1.0 - 1e-9) {
        return Ok(None);
    }
    let _ = h;
    // Hand over at the exact branch point with the segment's rates, projected onto its
    // tangent space in the kinetic metric.
    let mut angles = end;
    restore(model, &mut angles, &mut solver)?;
    let sigma_dot = state[1];
    let mut rates: Vec<f64> = (0..n).map(|c| (d0[c] + sigma_end * d1[c]) * sigma_dot).collect();
    update_kinematics(model, &angles, &mut data);
    update_mass_matrix(model, &mut data);
    update_stars(model, &angles, None, &mut data);
    kkt.factor(model, &data)?;
    kkt.project_rates(&mut rates);
    let largest = push
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map(|(c, v)| (c, *v))
        .unwrap_or((0, 0.0));
    let note = format!(
        "left flat along the branch reached from a {KICK:e} rad kick along {source} (of the candidates the push drives hardest: first-order push strongest at {} {}), then the branch's one-coordinate equation to {KICK:e} rad in {:.3e} s",
        model.labels[largest.0],
        if largest.1 > 0.0 { "valley" } else { "mountain" },
        t
    );
    Ok(Some(BranchStart {
        time: t,
        angles,
        rates,
        work: state[2],
        dissipation: state[3],
        direction,
        note,
    }))
}

/// The accelerations at (ρ, ρ̇) for generalised forces `forces` (bias not included).
fn accelerations(
    model: &NetworkModel,
    angles: &[f64],
    rates: &[f64],
    forces: &[f64],
    data: &mut NetworkData,
    kkt: &mut KktSystem,
    out: &mut [f64],
) -> Result<()> {
    update_kinematics(model, angles, data);
    update_velocities(model, rates, data);
    update_mass_matrix(model, data);
    update_stars(model, angles, Some(rates), data);
    kkt.factor(model, data)?;
    kkt.accelerations(data, forces, out);
    Ok(())
}

/// The branch point at σ = d̂·(ρ − ρ₀): Newton onto the closures, then a shift along d̂ to
/// the wanted σ, until σ holds to rounding.
fn branch_point(
    model: &NetworkModel,
    start: &[f64],
    direction: &[f64],
    sigma: f64,
    guess: &[f64],
    solver: &mut NormalSolver,
) -> Result<Vec<f64>> {
    let along = |rho: &[f64]| -> f64 {
        rho.iter()
            .zip(start)
            .zip(direction)
            .map(|((r, s), d)| (r - s) * d)
            .sum()
    };
    let scale = sigma / along(guess).max(f64::MIN_POSITIVE);
    let mut rho: Vec<f64> = guess.iter().zip(start).map(|(g, s)| s + (g - s) * scale).collect();
    for _ in 0..BRANCH_ITERATIONS {
        restore(model, &mut rho, solver)?;
        let error = sigma - along(&rho);
        if error.abs() <= 1e-14 * sigma {
            return Ok(rho);
        }
        for (r, d) in rho.iter_mut().zip(direction) {
            *r += error * d;
        }
    }
    Err(NanofoldError::invalid(
        "pattern",
        "a flat start",
        "no branch point found along the push (the closures and the push's plane do not meet near flat)",
    ))
}

/// The branch modelled as ρ(σ) = ρ₀ + σ d₀ + ½ σ² d₁.
struct Segment<'a> {
    model: &'a NetworkModel,
    start: &'a [f64],
    d0: &'a [f64],
    d1: &'a [f64],
}

impl Segment<'_> {
    /// σ̈ at (t, σ, σ̇), from the one-coordinate equation.
    fn acceleration(&self, t: f64, sigma: f64, sigma_dot: f64, data: &mut NetworkData) -> Result<f64> {
        Ok(self.evaluate(t, sigma, sigma_dot, data)?.0)
    }

    /// (σ̈, actuation power, drag power) at (t, σ, σ̇).
    fn evaluate(&self, t: f64, sigma: f64, sigma_dot: f64, data: &mut NetworkData) -> Result<(f64, f64, f64)> {
        let model = self.model;
        let n = model.columns();
        let angles: Vec<f64> = (0..n)
            .map(|c| self.start[c] + sigma * self.d0[c] + 0.5 * sigma * sigma * self.d1[c])
            .collect();
        let g: Vec<f64> = (0..n).map(|c| self.d0[c] + sigma * self.d1[c]).collect();
        let rates: Vec<f64> = g.iter().map(|v| v * sigma_dot).collect();
        update_kinematics(model, &angles, data);
        update_velocities(model, &rates, data);
        let drag_power = update_drag(model, data);
        update_bias(model, data);
        update_mass_matrix(model, data);
        let mut mg = vec![0.0; n];
        mass_times(model, data, &g, &mut mg);
        let mut mh = vec![0.0; n];
        mass_times(model, data, self.d1, &mut mh);
        let mass: f64 = g.iter().zip(&mg).map(|(a, b)| a * b).sum();
        let mut drive = vec![0.0; n];
        model.forcing.drive_angles(t, &mut drive);
        let (mut force, mut power) = (0.0, 0.0);
        for c in 0..n {
            let k = model.hinges[c].stiffness;
            let torque = if model.forcing.hinges[c].actuated {
                k * drive[c]
            } else {
                0.0
            };
            power += torque * rates[c];
            force += g[c] * (torque - k * angles[c] - data.bias[c]) - sigma_dot * sigma_dot * g[c] * mh[c];
        }
        Ok((force / mass, power, drag_power))
    }

    /// One RK4 step of (σ, σ̇, work, dissipation).
    fn rk4(&self, t: f64, y: &[f64; 4], h: f64, data: &mut NetworkData) -> Result<[f64; 4]> {
        let mut f = |t: f64, y: &[f64; 4]| -> Result<[f64; 4]> {
            let (a, power, drag) = self.evaluate(t, y[0], y[1], data)?;
            Ok([y[1], a, power, -drag])
        };
        let k1 = f(t, y)?;
        let shift = |y: &[f64; 4], k: &[f64; 4], s: f64| -> [f64; 4] { std::array::from_fn(|i| y[i] + s * k[i]) };
        let k2 = f(t + 0.5 * h, &shift(y, &k1, 0.5 * h))?;
        let k3 = f(t + 0.5 * h, &shift(y, &k2, 0.5 * h))?;
        let k4 = f(t + h, &shift(y, &k3, h))?;
        Ok(std::array::from_fn(|i| {
            y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        }))
    }
}
