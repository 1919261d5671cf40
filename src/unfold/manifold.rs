//! The constraint manifold of the unfolding (`docs/model.md#projected-gradient`): tangent
//! coordinates of the free nodes, the constraint rows' residuals and Jacobian, the bending
//! metric's rows, the retraction back onto the sphere and the Newton restoration onto
//! G = 0. Every function writes into buffers it is given.

use super::model::{ConstraintRow, UnfoldModel};
use super::qp::{ConstraintJacobian, JacobianRow, RowSpace};
use crate::error::{NumericalError, Result};
use crate::geometry::sphere::{fold_angle_with_gradient, geodesic, geodesic_with_gradient, Vec3};
use crate::pattern::Chain;
use std::f64::consts::PI;

/// Wraps an angle difference into (−π, π].
fn wrap(angle: f64) -> f64 {
    let mut a = angle.rem_euclid(2.0 * PI);
    if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// Orthonormal tangent basis at a unit vector, without pole singularities: built from the
/// coordinate axis least aligned with x.
pub(crate) fn tangent_basis(x: &Vec3) -> [Vec3; 2] {
    let axis = if x.x.abs() <= x.y.abs() && x.x.abs() <= x.z.abs() {
        Vec3::x()
    } else if x.y.abs() <= x.z.abs() {
        Vec3::y()
    } else {
        Vec3::z()
    };
    let e1 = x.cross(&axis).normalize();
    let e2 = x.cross(&e1).normalize();
    [e1, e2]
}

/// Fills the tangent bases of the free nodes.
pub fn fill_bases(model: &UnfoldModel, nodes: &[Vec3], basis: &mut [[Vec3; 2]]) {
    for &i in &model.free {
        basis[i] = tangent_basis(&nodes[i]);
    }
}

/// Residuals G(x) of the constraint rows.
pub(crate) fn fill_residuals(model: &UnfoldModel, rows: &[ConstraintRow], nodes: &[Vec3], out: &mut [f64]) {
    for (row, out) in rows.iter().zip(out.iter_mut()) {
        *out = match *row {
            ConstraintRow::Arc(e) => {
                let arc = model.arcs[e];
                geodesic(&nodes[arc.a], &nodes[arc.b]) - arc.length
            }
            ConstraintRow::Held(h) => {
                let held = model.held[h];
                wrap(model.fold_angle_at(nodes, held.ray) - held.target)
            }
            ConstraintRow::Flat(ray) => wrap(model.fold_angle_at(nodes, ray)),
            ConstraintRow::Antipodal { v, w, k } => tangent_basis(&nodes[v])[k].dot(&(nodes[v] + nodes[w])),
        };
    }
}

/// Jacobian of the constraint rows in the tangent coordinates (2 per free node), into `out`
/// (resized to the rows without giving back capacity).
pub(crate) fn fill_jacobian(
    model: &UnfoldModel,
    rows: &[ConstraintRow],
    nodes: &[Vec3],
    basis: &[[Vec3; 2]],
    out: &mut ConstraintJacobian,
) {
    out.columns = 2 * model.free.len();
    out.rows.resize(rows.len(), JacobianRow::default());
    let put = |out: &mut JacobianRow, node: usize, g: &Vec3| {
        if node >= 2 {
            out.add(node - 2, [basis[node][0].dot(g), basis[node][1].dot(g)]);
        }
    };
    let put_fold_angle = |out: &mut JacobianRow, ray: usize| {
        let (prev, next) = model.neighbours(ray);
        let (_, [gp, ga, gn]) = fold_angle_with_gradient(&nodes[prev], &nodes[ray], &nodes[next]);
        put(out, prev, &gp);
        put(out, ray, &ga);
        put(out, next, &gn);
    };
    for (row, out) in rows.iter().zip(out.rows.iter_mut()) {
        out.clear(model.is_closing(*row));
        match *row {
            ConstraintRow::Arc(e) => {
                let arc = model.arcs[e];
                let (_, ga, gb) = geodesic_with_gradient(&nodes[arc.a], &nodes[arc.b]);
                put(out, arc.a, &ga);
                put(out, arc.b, &gb);
            }
            ConstraintRow::Held(h) => put_fold_angle(out, model.held[h].ray),
            ConstraintRow::Flat(ray) => put_fold_angle(out, ray),
            ConstraintRow::Antipodal { v, w, k } => {
                let e = tangent_basis(&nodes[v])[k];
                put(out, v, &e);
                put(out, w, &e);
            }
        }
    }
}

/// Rows of S in the bending metric M = I + SᵀS (see
/// [`super::UnfoldSettings::bending_metric`]) into `out`: for every ray with two neighbours,
/// the three components of the second difference x_prev − 2 x_ray + x_next of the node
/// displacements, scaled by √(κ / ᾱ⁴).
pub fn fill_bending_rows(model: &UnfoldModel, basis: &[[Vec3; 2]], kappa: f64, out: &mut ConstraintJacobian) {
    let n = model.node_count;
    let mean_sector = model.sector_angles.iter().sum::<f64>() / model.sector_angles.len() as f64;
    let weight = (kappa / mean_sector.powi(4)).sqrt();
    out.columns = 2 * model.free.len();
    out.rows.clear();
    for centre in 0..n {
        let (prev, next) = model.neighbours(centre);
        let open_end = model.chain == Chain::Open && (centre == 0 || centre + 1 == n);
        if open_end {
            continue;
        }
        for axis in [Vec3::x(), Vec3::y(), Vec3::z()] {
            let mut row = JacobianRow::default();
            row.clear(false);
            for (node, coefficient) in [(prev, 1.0), (centre, -2.0), (next, 1.0)] {
                if node >= 2 {
                    let c = weight * coefficient;
                    row.add(node - 2, [c * basis[node][0].dot(&axis), c * basis[node][1].dot(&axis)]);
                }
            }
            if !row.entries().is_empty() {
                out.rows.push(row);
            }
        }
    }
}

/// Moves the free nodes by the tangent coordinates `y` (scaled by `t`) and renormalises.
pub fn retract(model: &UnfoldModel, nodes: &[Vec3], basis: &[[Vec3; 2]], y: &[f64], t: f64, out: &mut [Vec3]) {
    out.copy_from_slice(nodes);
    for (slot, &i) in model.free.iter().enumerate() {
        let d = basis[i][0] * y[2 * slot] + basis[i][1] * y[2 * slot + 1];
        out[i] = (nodes[i] + t * d).normalize();
    }
}

/// Residual below which [`restore`] halves a Newton step that does not reduce it.
const DAMPED_RESTORE_BELOW: f64 = 1e-8;

/// The buffers of the Newton restoration.
#[derive(Debug, Default)]
pub struct RestoreBuffers {
    basis: Vec<[Vec3; 2]>,
    jacobian: ConstraintJacobian,
    space: RowSpace,
    residual: Vec<f64>,
    trial_residual: Vec<f64>,
    moved: Vec<Vec3>,
    step: Vec<f64>,
}

fn amax(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |a, b| a.max(b.abs()))
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newton projection onto the constraints (`docs/model.md#projected-gradient`, "restore"):
/// minimum-norm steps in the tangent space, the factorisation reused while it converges
/// (chord Newton: `chord` is A factorised at the step's start with the basis it used) and
/// refreshed when it stalls. Each step is halved until the residual norm falls: near the
/// flat state A has singular values ~ρ and a full minimum-norm step can overshoot the region
/// where the linearisation holds (a 1e-6 rad fold with a 1e-12 closing error diverged
/// without it). Returns the final max residual; Err when it does not reach `tol`.
pub(crate) fn restore(
    model: &UnfoldModel,
    rows: &[ConstraintRow],
    buffers: &mut RestoreBuffers,
    nodes: &mut [Vec3],
    tol: f64,
    mut chord: Option<(&mut RowSpace, &[[Vec3; 2]])>,
) -> Result<f64> {
    let b = buffers;
    let m = rows.len();
    b.residual.resize(m, 0.0);
    b.trial_residual.resize(m, 0.0);
    b.moved.resize(nodes.len(), Vec3::zeros());
    b.basis.resize(nodes.len(), [Vec3::zeros(); 2]);
    b.step.resize(2 * model.free.len(), 0.0);
    match &chord {
        Some((_, basis)) => b.basis.copy_from_slice(basis),
        None => fill_bases(model, nodes, &mut b.basis),
    }
    let mut owned = false;
    let mut previous = f64::INFINITY;
    let mut stale = false;
    fill_residuals(model, rows, nodes, &mut b.residual);
    for iteration in 0..40 {
        let worst = amax(&b.residual);
        if !worst.is_finite() {
            return Err(NumericalError::NonFinite {
                what: "constraint restoration",
                detail: "a constraint residual".into(),
            }
            .into());
        }
        if worst <= tol {
            return Ok(worst);
        }
        let refresh = stale || (!owned && (chord.is_none() || worst > 0.5 * previous || iteration >= 10));
        if refresh {
            fill_bases(model, nodes, &mut b.basis);
            fill_jacobian(model, rows, nodes, &b.basis, &mut b.jacobian);
            b.space.factorise(&b.jacobian)?;
            owned = true;
        } else if owned && worst > 0.9 * previous && iteration > 20 {
            break;
        }
        previous = worst;
        match (&mut chord, owned) {
            (Some((space, _)), false) => space.solve_min_norm_into(&b.residual, &mut b.step),
            _ => b.space.solve_min_norm_into(&b.residual, &mut b.step),
        }
        // Trust region: a minimum-norm step near flat can be far larger than the residual;
        // allow up to 10·√residual (what the ill-conditioning legitimately needs).
        let cap = 10.0 * worst.sqrt();
        let largest = amax(&b.step);
        if largest > cap {
            let scale = cap / largest;
            b.step.iter_mut().for_each(|z| *z *= scale);
        }
        let size = norm(&b.residual);
        let mut fraction = 1.0;
        let mut accepted = false;
        // Damping is for the small residuals near flat; a large one means the trial step
        // was too long, which the line search's own halving fixes more cheaply.
        let halvings = if worst <= DAMPED_RESTORE_BELOW { 8 } else { 0 };
        for _ in 0..=halvings {
            retract(model, nodes, &b.basis, &b.step, -fraction, &mut b.moved);
            fill_residuals(model, rows, &b.moved, &mut b.trial_residual);
            if norm(&b.trial_residual) < size {
                accepted = true;
                break;
            }
            fraction *= 0.5;
        }
        if !accepted {
            if refresh {
                break;
            }
            // The chord factorisation is too old for this point: refresh and retry.
            stale = true;
            continue;
        }
        stale = false;
        nodes.copy_from_slice(&b.moved);
        std::mem::swap(&mut b.residual, &mut b.trial_residual);
    }
    let worst = amax(&b.residual);
    if worst <= tol {
        Ok(worst)
    } else {
        Err(NumericalError::RestorationFailed {
            residual: worst,
            tolerance: tol,
        }
        .into())
    }
}
