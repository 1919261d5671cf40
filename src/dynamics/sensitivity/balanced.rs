//! Sensitivities of a plant's quasi-static path (`docs/model.md#sensitivities-of-a-slow-release`):
//! each sample is a balance, q̈(t, q, 0) = 0 (the hinges balance their drives, inertia
//! dropped), so along the path ∂q̈/∂q · ∂q/∂u + ∂q̈/∂u = 0. At a balance the forces vanish,
//! so M⁻¹ (which q̈ carries) changes nothing of the solution: ∂q/∂u = −(∂f/∂q)⁻¹ ∂f/∂u, the
//! balance differentiated. ∂q̈/∂q is the central difference over the coordinates, ∂q̈/∂u over
//! the scenes at u ± ε at the same q; the output angles follow through the plant's own
//! sample, differenced the same two ways. For plants whose coordinates are free (strips,
//! closed chains on their curve, fitted curves, trees of panels); a plant that projects
//! onto closures is the contact engine's or refused.

use super::{asked, stencil, TrajectorySensitivity, POINTS};
use crate::dynamics::plant::Plant;
use crate::dynamics::quasi_static::quasi_static_path;
use crate::error::{NumericalError, Result};
use nalgebra::{DMatrix, DVector};

/// The turn of a coordinate by which the balance's Jacobian is differenced, rad.
const COORDINATE_STEP: f64 = 1e-6;
/// A sample whose coordinates' accelerations exceed this share of their scale (ω² times a
/// radian) is no balance.
const STATIONARY: f64 = 1e-6;

/// The quasi-static path of `base` at `times` up to its first contact, with the
/// sensitivities of its output angles to each parameter whose plants at u ± ε are
/// `perturbed[j]`.
pub(super) fn balanced_sensitivities<P: Plant>(
    base: &P,
    perturbed: &[[P; POINTS]],
    epsilon: f64,
    times: &[f64],
) -> Result<TrajectorySensitivity> {
    let path = quasi_static_path(base, times)?;
    let forcing = base.forcing();
    let n = base.dof();
    let mut ws = base.workspace();
    let mut perturbed_ws: Vec<[P::Workspace; POINTS]> = perturbed
        .iter()
        .map(|pair| [pair[0].workspace(), pair[1].workspace()])
        .collect();
    let zeros = vec![0.0; n];
    let scale = base.slowest_omega()?.powi(2);
    // The same balances the path found, from the same start: its coordinates are needed.
    let mut q = base.initial_coordinates();
    let mut drive = vec![0.0; forcing.hinges.len()];
    base.balance(&drive, &mut q, &mut ws)?;
    let mut result = TrajectorySensitivity {
        times: Vec::with_capacity(times.len()),
        angles: Vec::with_capacity(times.len()),
        sensitivities: Vec::with_capacity(times.len()),
        steps: path.scans,
    };
    let mut requested = times.iter().peekable();
    for sample in &path.samples {
        if !asked(&mut requested, sample.time) {
            continue;
        }
        let t = sample.time;
        forcing.drive_angles(t, &mut drive);
        base.balance(&drive, &mut q, &mut ws)?;
        let angles = base.sample(t, &q, &zeros, &[], &mut ws)?.angles;
        let outputs = angles.len();
        let off = (&angles - &sample.angles).amax();
        if off > 1e-9 {
            return Err(NumericalError::Singular {
                what: "a quasi-static path's sensitivities",
                detail: format!("the balance at {t:.6e} s was found {off:.3e} rad from the path's own"),
            }
            .into());
        }
        let mut accelerations = vec![0.0; n];
        base.accelerations(t, &q, &zeros, &mut ws, &mut accelerations)?;
        let residual = accelerations.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
        if residual > STATIONARY * scale {
            return Err(NumericalError::Singular {
                what: "a quasi-static path's sensitivities",
                detail: format!(
                    "the state at {t:.6e} s is no balance: accelerations {residual:.3e} against {scale:.3e} rad/s² a radian"
                ),
            }
            .into());
        }
        // ∂q̈/∂q and ∂angles/∂q by central differences over each coordinate.
        let mut jacobian = DMatrix::zeros(n, n);
        let mut angle_slopes = DMatrix::zeros(outputs, n);
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        let mut shifted = q.clone();
        for c in 0..n {
            shifted[c] = q[c] + COORDINATE_STEP;
            base.accelerations(t, &shifted, &zeros, &mut ws, &mut plus)?;
            let angles_plus = base.sample(t, &shifted, &zeros, &[], &mut ws)?.angles;
            shifted[c] = q[c] - COORDINATE_STEP;
            base.accelerations(t, &shifted, &zeros, &mut ws, &mut minus)?;
            let angles_minus = base.sample(t, &shifted, &zeros, &[], &mut ws)?.angles;
            shifted[c] = q[c];
            for i in 0..n {
                jacobian[(i, c)] = (plus[i] - minus[i]) / (2.0 * COORDINATE_STEP);
            }
            angle_slopes.set_column(c, &((angles_plus - angles_minus) / (2.0 * COORDINATE_STEP)));
        }
        let factor = jacobian.clone().lu();
        let mut columns = DMatrix::zeros(outputs, perturbed.len());
        for (j, pair) in perturbed.iter().enumerate() {
            let mut pushed = [vec![0.0; n], vec![0.0; n]];
            let mut moved = [DVector::zeros(outputs), DVector::zeros(outputs)];
            for p in 0..POINTS {
                pair[p].accelerations(t, &q, &zeros, &mut perturbed_ws[j][p], &mut pushed[p])?;
                moved[p] = pair[p].sample(t, &q, &zeros, &[], &mut perturbed_ws[j][p])?.angles;
            }
            let push = DVector::from_fn(n, |i, _| -stencil([pushed[0][i], pushed[1][i]], epsilon));
            let coordinates = factor.solve(&push).ok_or_else(|| NumericalError::Singular {
                what: "a quasi-static balance's stiffness",
                detail: format!("at {t:.6e} s (a limit point of the path)"),
            })?;
            let direct = DVector::from_fn(outputs, |i, _| stencil([moved[0][i], moved[1][i]], epsilon));
            columns.set_column(j, &(&angle_slopes * coordinates + direct));
        }
        result.times.push(t);
        result.angles.push(angles);
        result.sensitivities.push(columns);
    }
    Ok(result)
}
