//! Sensitivities of a slow release carried through contact
//! (`docs/model.md#sensitivities-of-a-slow-release`): each sample is a balance, the minimum of
//! V = Σ ½ Kᵢ (θᵢ − rᵢ(t))² on its held rows h(θ) = 0 (latched seams, pressing contacts), so
//! its KKT conditions ∇V + Jᵀλ = 0, h = 0, differentiated with the same rows held, give
//!
//!   [H Jᵀ; J 0] [∂θ/∂u; ∂λ/∂u] = −[∂(∇V + Jᵀλ)/∂u; ∂h/∂u],   H = K + Σ λₖ ∇²hₖ.
//!
//! The right-hand side is the central difference of those functions across the perturbed
//! scenes at the sample's own θ and λ (any number of the scene file can be a parameter); H's
//! curvature part is the central difference of Jᵀλ along each fold angle. Rows that close a
//! solid are redundant (a box's 20 rows fix 5 angles), so the system is solved on J's row
//! space and its null space: the particular part from the rows, the rest from H there.

use super::{asked, stencil, TrajectorySensitivity, POINTS};
use crate::dynamics::network::closing::{ClosingSettings, HeldRows, NetClosing};
use crate::dynamics::network::NetworkModel;
use crate::error::{NanofoldError, NumericalError, Result};
use nalgebra::{DMatrix, DVector};

/// The turn of a fold angle by which the rows' curvature is differenced, rad.
const CURVATURE_STEP: f64 = 1e-6;
/// Singular values of the held rows below this share of the largest are zero (as the
/// balance reads their rank).
const RANK_CUT: f64 = 1e-6;
/// A sample is a balance when its hinge torques less what the held rows carry are below
/// this share of the largest hinge torque (the engine holds its balances to about 1e-9).
const STATIONARY: f64 = 1e-6;

/// The slow release of `base` through its contacts and seams at `times`, with the
/// sensitivities of its fold angles to each parameter whose scenes at u ± ε are
/// `perturbed[j]`.
pub(super) fn released_sensitivities(
    base: &NetworkModel,
    perturbed: &[[&NetworkModel; POINTS]],
    epsilon: f64,
    times: &[f64],
) -> Result<TrajectorySensitivity> {
    let t_end = times.last().copied().unwrap_or(0.0);
    if t_end.is_nan() || t_end <= 0.0 {
        return Err(NanofoldError::invalid(
            "times",
            t_end,
            "a slow release is sampled at times up to one > 0 s",
        ));
    }
    let net = NetClosing::of_scene(base)?;
    let stiffness = base.stiffness();
    let path = net.states_at(base, &base.forcing, &stiffness, &ClosingSettings::default(), times)?;
    let nets: Vec<[NetClosing; POINTS]> = perturbed
        .iter()
        .map(|pair| -> Result<[NetClosing; POINTS]> {
            Ok([NetClosing::of_scene(pair[0])?, NetClosing::of_scene(pair[1])?])
        })
        .collect::<Result<_>>()?;
    let mut result = TrajectorySensitivity {
        times: Vec::with_capacity(times.len()),
        angles: Vec::with_capacity(times.len()),
        sensitivities: Vec::with_capacity(times.len()),
        steps: path.qp_solves,
    };
    let mut requested = times.iter().peekable();
    for sample in &path.samples {
        if !asked(&mut requested, sample.time_s) {
            continue;
        }
        let columns = if perturbed.is_empty() {
            DMatrix::zeros(sample.fold_angles.len(), 0)
        } else {
            let at = Balance {
                model: base,
                net: &net,
                time: sample.time_s,
                theta: &sample.fold_angles,
                held: &sample.held,
            };
            at.sensitivities(perturbed, &nets, epsilon)?
        };
        result.times.push(sample.time_s);
        result.angles.push(DVector::from_column_slice(&sample.fold_angles));
        result.sensitivities.push(columns);
    }
    Ok(result)
}

/// One sample's balance.
struct Balance<'a> {
    model: &'a NetworkModel,
    net: &'a NetClosing,
    time: f64,
    theta: &'a [f64],
    held: &'a HeldRows,
}

impl Balance<'_> {
    /// K (θ − r(t)) of `model` at this sample's angles.
    fn hinge_torques(&self, model: &NetworkModel) -> DVector<f64> {
        let mut drive = vec![0.0; self.theta.len()];
        model.forcing.drive_angles(self.time, &mut drive);
        let stiffness = model.stiffness();
        DVector::from_iterator(
            self.theta.len(),
            (0..self.theta.len()).map(|c| stiffness[c] * (self.theta[c] - drive[c])),
        )
    }

    /// The largest torque a hinge carries at this angle or drive, max Kᵢ (|θᵢ| + |rᵢ|), N·m.
    fn torque_scale(&self) -> f64 {
        let mut drive = vec![0.0; self.theta.len()];
        self.model.forcing.drive_angles(self.time, &mut drive);
        let stiffness = self.model.stiffness();
        (0..self.theta.len())
            .map(|c| stiffness[c] * (self.theta[c].abs() + drive[c].abs()))
            .fold(f64::MIN_POSITIVE, f64::max)
    }

    /// The held rows (and their residuals) of `net` on `model` at angles `theta`.
    fn rows(&self, net: &NetClosing, model: &NetworkModel, theta: &[f64]) -> Result<(DVector<f64>, DMatrix<f64>)> {
        let (residual, rows, _) = net.held_rows(model, theta, self.held)?;
        Ok((residual, rows))
    }

    /// ∂θ/∂uⱼ for every parameter, one column each.
    fn sensitivities(
        &self,
        perturbed: &[[&NetworkModel; POINTS]],
        nets: &[[NetClosing; POINTS]],
        epsilon: f64,
    ) -> Result<DMatrix<f64>> {
        let n = self.theta.len();
        let torques = self.hinge_torques(self.model);
        let (_, rows) = self.rows(self.net, self.model, self.theta)?;
        // λ from the balance itself: Jᵀλ = −K (θ − r), least squares on J's row space.
        let multipliers = if rows.nrows() == 0 {
            DVector::zeros(0)
        } else {
            let svd = rows.transpose().svd(true, true);
            let cut = RANK_CUT * svd.singular_values.max();
            svd.solve(&(-&torques), cut)
                .map_err(|reason| NumericalError::Singular {
                    what: "the held rows' multipliers",
                    detail: reason.to_string(),
                })?
        };
        let unbalanced = &torques + rows.transpose() * &multipliers;
        // Against the torques the hinges carry at these angles and drives.
        let largest = self.torque_scale();
        if unbalanced.amax() > STATIONARY * largest {
            return Err(NumericalError::Singular {
                what: "a slow release's sensitivities",
                detail: format!(
                    "the state at {:.6e} s is no balance of its held rows: torques {:.3e} of {:.3e} N·m left over",
                    self.time,
                    unbalanced.amax(),
                    largest
                ),
            }
            .into());
        }
        // H = K + Σ λₖ ∇²hₖ, the curvature from Jᵀλ differenced along each angle.
        let mut hessian = DMatrix::from_diagonal(&DVector::from_vec(self.model.stiffness()));
        if rows.nrows() > 0 {
            let mut shifted = self.theta.to_vec();
            for c in 0..n {
                shifted[c] = self.theta[c] + CURVATURE_STEP;
                let (_, plus) = self.rows(self.net, self.model, &shifted)?;
                shifted[c] = self.theta[c] - CURVATURE_STEP;
                let (_, minus) = self.rows(self.net, self.model, &shifted)?;
                shifted[c] = self.theta[c];
                let column = (plus - minus).transpose() * &multipliers / (2.0 * CURVATURE_STEP);
                for i in 0..n {
                    hessian[(i, c)] += column[i];
                }
            }
            hessian = (&hessian + hessian.transpose()) * 0.5;
        }
        let (range, null, row_solve) = split(&rows);
        let reduced = null.transpose() * &hessian * &null;
        let factor = if null.ncols() > 0 {
            Some(reduced.clone().cholesky().ok_or_else(|| NumericalError::NotPositiveDefinite {
                matrix: "the reduced Hessian of a slow release's balance (it is not stable along its held rows, so its sensitivities are not defined)",
                at: format!("{:.6e} s", self.time),
            })?)
        } else {
            None
        };
        let mut columns = DMatrix::zeros(n, perturbed.len());
        for (j, (models, nets)) in perturbed.iter().zip(nets).enumerate() {
            let mut gradients = [DVector::zeros(n), DVector::zeros(n)];
            let mut residuals = [DVector::zeros(rows.nrows()), DVector::zeros(rows.nrows())];
            for p in 0..POINTS {
                let (residual, rows_p) = self.rows(&nets[p], models[p], self.theta)?;
                if residual.len() != rows.nrows() {
                    return Err(NanofoldError::invalid(
                        format!("perturbed[{j}]"),
                        "a scene whose held rows differ",
                        "a parameter may change numbers of a scene, not what holds its faces",
                    ));
                }
                gradients[p] = self.hinge_torques(models[p]) + rows_p.transpose() * &multipliers;
                residuals[p] = residual;
            }
            let gradient = DVector::from_fn(n, |i, _| -stencil([gradients[0][i], gradients[1][i]], epsilon));
            let residual = DVector::from_fn(rows.nrows(), |i, _| {
                -stencil([residuals[0][i], residuals[1][i]], epsilon)
            });
            // The rows fix the part on their row space; the energy the rest.
            let particular = &range * row_solve(&residual);
            let mut change = particular.clone();
            if let Some(factor) = &factor {
                let free = factor.solve(&(null.transpose() * (gradient - &hessian * &particular)));
                change += &null * free;
            }
            columns.set_column(j, &change);
        }
        Ok(columns)
    }
}

/// The held rows J split: (Y, Z, y(c)): Y an orthonormal basis of J's row space, Z of its
/// null space, and y(c) solving J Y y = c in least squares.
#[allow(clippy::type_complexity)]
fn split(rows: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>, Box<dyn Fn(&DVector<f64>) -> DVector<f64>>) {
    let n = rows.ncols();
    if rows.nrows() == 0 {
        return (
            DMatrix::zeros(n, 0),
            DMatrix::identity(n, n),
            Box::new(|_| DVector::zeros(0)),
        );
    }
    // JᵀJ's eigenvectors: its null space whole, even where J has fewer rows than columns.
    let eigen = (rows.transpose() * rows).symmetric_eigen();
    let largest = eigen.eigenvalues.max().max(f64::MIN_POSITIVE);
    let kept: Vec<usize> = (0..n)
        .filter(|&i| eigen.eigenvalues[i] > RANK_CUT * RANK_CUT * largest)
        .collect();
    let dropped: Vec<usize> = (0..n).filter(|i| !kept.contains(i)).collect();
    let range = DMatrix::from_fn(n, kept.len(), |i, k| eigen.eigenvectors[(i, kept[k])]);
    let null = DMatrix::from_fn(n, dropped.len(), |i, k| eigen.eigenvectors[(i, dropped[k])]);
    let projected = rows * &range;
    let solver = projected.svd(true, true);
    let cut = RANK_CUT * solver.singular_values.max();
    let count = kept.len();
    (
        range,
        null,
        Box::new(move |c: &DVector<f64>| solver.solve(c, cut).unwrap_or_else(|_| DVector::zeros(count))),
    )
}
