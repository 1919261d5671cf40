//! The drag's side on each plate during a sensitivity run (`docs/model.md#calibration`):
//! locked between located switches, or sliding on the switching surface, and a plant's
//! accelerations under those sides.
//!
//! The literal drag law's force points against the sign of a plate's normal speed g with a
//! magnitude set by its whole speed, so where g crosses zero while the plate moves edgewise
//! the force on both sides can push g back to zero: the motion slides along g = 0 (Filippov).
//! There the sign is replaced by the equivalent σ ∈ [−1, 1] that keeps dg/dt = 0; the
//! accelerations are affine in σ, so σ solves a small linear system.

use super::super::plant::Plant;
use crate::error::Result;
use nalgebra::{DMatrix, DVector};

/// The drag's side on one plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Side {
    /// Not yet moving: the speed's own sign.
    Free,
    /// Held at this sign until the crossing of g = 0 is located.
    Locked(f64),
    /// On the switching surface, with the equivalent sign.
    Sliding,
}

impl Side {
    /// The switching function the integrator locates for this side: g for a free plate,
    /// g × sign for a locked one (negative once crossed), 1 − |σ| for a sliding one
    /// (negative once the equivalent sign leaves [−1, 1]).
    pub(crate) fn switch_value(self, speed: f64, sigma: f64) -> f64 {
        match self {
            Side::Free => speed,
            Side::Locked(sign) => speed * sign,
            Side::Sliding if sigma.is_finite() => 1.0 - sigma.abs(),
            Side::Sliding => -1.0,
        }
    }
}

/// Scratch of [`held_accelerations`].
#[derive(Debug, Clone)]
pub(crate) struct SideScratch {
    signs: Vec<f64>,
    /// Each sliding plate's equivalent sign at the last evaluation.
    pub(crate) sigma: Vec<f64>,
    /// Each plate's normal speed at the last evaluation.
    pub(crate) speeds: Vec<f64>,
    affine: Vec<Vec<f64>>,
    shifted: Vec<f64>,
}

impl SideScratch {
    /// For `plates` plates and `n` coordinates.
    pub(crate) fn new(plates: usize, n: usize) -> Self {
        SideScratch {
            signs: vec![0.0; plates],
            sigma: vec![0.0; plates],
            speeds: vec![0.0; plates],
            affine: Vec::new(),
            shifted: vec![0.0; n],
        }
    }
}

/// The largest angle shift (rad) in the difference of g along the motion.
const SHIFT: f64 = 1e-4;

/// Accelerations of `plant` at (t, q, q̇) into `out`, the drag on each plate as `sides`
/// says: a locked side's sign, a free plate's own (or `free_signs`' where given and
/// non-zero), a sliding plate's equivalent sign.
#[allow(clippy::too_many_arguments)]
pub(crate) fn held_accelerations<P: Plant>(
    plant: &P,
    sides: &[Side],
    free_signs: Option<&[f64]>,
    t: f64,
    q: &[f64],
    q_dot: &[f64],
    ws: &mut P::Workspace,
    scratch: &mut SideScratch,
    out: &mut [f64],
) -> Result<()> {
    for (p, side) in sides.iter().enumerate() {
        scratch.signs[p] = match side {
            Side::Locked(sign) => *sign,
            Side::Free => free_signs.map_or(0.0, |f| f[p]),
            Side::Sliding => 0.0,
        };
    }
    let sliding: Vec<usize> = (0..sides.len()).filter(|&p| sides[p] == Side::Sliding).collect();
    if sliding.is_empty() {
        plant.freeze_switches(ws, Some(&scratch.signs));
        plant.accelerations(t, q, q_dot, ws, out)?;
        scratch.speeds.copy_from_slice(plant.switches(ws));
        plant.freeze_switches(ws, None);
        return Ok(());
    }
    // Sliding plates at σ = 0, then each at σ = 1 alone: a = a₀ + Σ σₖ bₖ.
    let n = q.len();
    // A held sign of 0 means "the speed's own": a sliding plate at σ = 0 needs a sign whose
    // force vanishes, which the freeze cannot express, so its σ = 0 point is the midpoint of
    // its σ = ±1 evaluations.
    scratch.affine.resize_with(2 * sliding.len() + 1, || vec![0.0; n]);
    for (k, &p) in sliding.iter().enumerate() {
        for (slot, sign) in [(2 * k, 1.0), (2 * k + 1, -1.0)] {
            for &r in &sliding {
                scratch.signs[r] = if r == p { sign } else { 1.0 };
            }
            plant.freeze_switches(ws, Some(&scratch.signs));
            plant.accelerations(t, q, q_dot, ws, &mut scratch.affine[slot])?;
            if slot == 0 {
                // The speeds at (q, q̇), whatever the signs, for the switching functions.
                scratch.speeds.copy_from_slice(plant.switches(ws));
            }
        }
    }
    // With every sliding plate at +1, plate p's column: bₚ = (a(+1) − a(−1)) / 2 and
    // a₀ = a(all +1) − Σ bₖ.
    let k_count = sliding.len();
    let b: Vec<Vec<f64>> = (0..k_count)
        .map(|k| {
            let (plus, minus) = (&scratch.affine[2 * k], &scratch.affine[2 * k + 1]);
            plus.iter().zip(minus).map(|(p, m)| 0.5 * (p - m)).collect()
        })
        .collect();
    let mut a0 = scratch.affine[0].clone();
    for column in &b {
        for i in 0..n {
            a0[i] -= column[i];
        }
    }
    plant.freeze_switches(ws, None);
    // dg/dt = ∂g/∂q q̇ + g(q, q̈), g linear in the rates: g(q, a₀) + Σ σₖ g(q, bₖ).
    let speed_at =
        |plant: &P, ws: &mut P::Workspace, at_q: &[f64], rates: &[f64], buffer: &mut [f64]| -> Result<Vec<f64>> {
            plant.accelerations(t, at_q, rates, ws, buffer)?;
            Ok(sliding.iter().map(|&p| plant.switches(ws)[p]).collect())
        };
    let mut buffer = vec![0.0; n];
    let along_motion = speeds_along_motion(plant, &sliding, t, q, q_dot, ws, &mut scratch.shifted)?;
    let at_a0 = speed_at(plant, ws, q, &a0, &mut buffer)?;
    let mut matrix = DMatrix::zeros(k_count, k_count);
    for (k, column) in b.iter().enumerate() {
        let g_b = speed_at(plant, ws, q, column, &mut buffer)?;
        for i in 0..k_count {
            matrix[(i, k)] = g_b[i];
        }
    }
    let rhs = DVector::from_iterator(k_count, (0..k_count).map(|i| -(along_motion[i] + at_a0[i])));
    // No equivalent sign (the drag cannot move g): σ is NaN, the switching function negative,
    // and the motion evaluated with the drag off these plates.
    let sigma = matrix
        .lu()
        .solve(&rhs)
        .filter(|s| s.iter().all(|x| x.is_finite()))
        .unwrap_or_else(|| DVector::from_element(k_count, f64::NAN));
    for (k, &p) in sliding.iter().enumerate() {
        scratch.sigma[p] = sigma[k];
    }
    for (i, o) in out.iter_mut().enumerate() {
        *o = a0[i]
            + (0..k_count)
                .filter(|&k| sigma[k].is_finite())
                .map(|k| sigma[k] * b[k][i])
                .sum::<f64>();
    }
    Ok(())
}

/// ∂g/∂q q̇ of each sliding plate's normal speed g at (q, q̇): the fourth-order difference of
/// g along the motion, the angles shifted by at most [`SHIFT`].
fn speeds_along_motion<P: Plant>(
    plant: &P,
    sliding: &[usize],
    t: f64,
    q: &[f64],
    q_dot: &[f64],
    ws: &mut P::Workspace,
    shifted: &mut [f64],
) -> Result<Vec<f64>> {
    let size = q_dot.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
    if size == 0.0 {
        return Ok(vec![0.0; sliding.len()]);
    }
    let h = SHIFT / size;
    let mut buffer = vec![0.0; q.len()];
    let mut values = [vec![], vec![], vec![], vec![]];
    for (slot, offset) in [-2.0, -1.0, 1.0, 2.0].iter().enumerate() {
        for i in 0..q.len() {
            shifted[i] = q[i] + offset * h * q_dot[i];
        }
        plant.accelerations(t, shifted, q_dot, ws, &mut buffer)?;
        values[slot] = sliding.iter().map(|&p| plant.switches(ws)[p]).collect::<Vec<f64>>();
    }
    Ok((0..sliding.len())
        .map(|k| (8.0 * (values[2][k] - values[1][k]) - (values[3][k] - values[0][k])) / (12.0 * h))
        .collect())
}
