//! Fold angles ↔ node positions of a single vertex, and loop closure (`docs/model.md#loop-closure`):
//! R_z(α_0) R_x(ρ_1) R_z(α_1) … R_x(ρ_{n−1}) R_z(α_{n−1}) R_x(ρ_0) = I.
//!
//! Frame convention (fixed here, tested below): ray 0 is +x, sector 0 lies in the xy-plane
//! on the +y side. Going CCW, the frame of ray k is T_k with T_0 = I, T_1 = R_z(α_0) and
//! T_{k+1} = T_k R_x(ρ_k) R_z(α_k); node k is T_k e_x. A positive ρ_k (valley) lifts the
//! sectors after ray k towards +z.

use crate::error::{NumericalError, Result};
use crate::geometry::sphere::Vec3;
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};

fn rot_z(angle: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Vector3::z_axis(), angle).matrix()
}

/// `frame ← frame · R_x(ρ) · R_z(α)`, column by column (a third of a full product's work).
fn turn(frame: &mut Matrix3<f64>, fold_angle: f64, sector_angle: f64) {
    turn_trig(frame, fold_angle.sin_cos(), sector_angle.sin_cos());
}

/// The frames' chain once round the vertex: returns the holonomy and, when asked, puts
/// node k (ray k's world axis, k ≥ 1) in `nodes[k]`.
fn chain(sector_angles: &[f64], fold_angles: &[f64], mut nodes: Option<&mut [Vec3]>) -> Matrix3<f64> {
    let n = fold_angles.len();
    let mut frame = rot_z(sector_angles[0]);
    if let Some(nodes) = nodes.as_deref_mut() {
        nodes[0] = Vec3::x();
        if n > 1 {
            nodes[1] = frame.column(0).into_owned();
        }
    }
    for k in 1..n {
        turn(&mut frame, fold_angles[k], sector_angles[k]);
        if let Some(nodes) = nodes.as_deref_mut() {
            if k + 1 < n {
                nodes[k + 1] = frame.column(0).into_owned();
            }
        }
    }
    // The last fold, R_x(ρ_0), on the right.
    let (s, c) = fold_angles[0].sin_cos();
    let (c1, c2) = (frame.column(1).into_owned(), frame.column(2).into_owned());
    frame.set_column(1, &(c * c1 + s * c2));
    frame.set_column(2, &(c * c2 - s * c1));
    frame
}

/// `frame ← frame · R_x(ρ) · R_z(α)` from (sin, cos) of ρ and of α.
fn turn_trig(frame: &mut Matrix3<f64>, (s, c): (f64, f64), (sa, ca): (f64, f64)) {
    let (c1, c2) = (frame.column(1).into_owned(), frame.column(2).into_owned());
    frame.set_column(1, &(c * c1 + s * c2));
    frame.set_column(2, &(c * c2 - s * c1));
    let (c0, c1) = (frame.column(0).into_owned(), frame.column(1).into_owned());
    frame.set_column(0, &(ca * c0 + sa * c1));
    frame.set_column(1, &(ca * c1 - sa * c0));
}

/// The holonomy's frame, as [`chain`] but from the (sin, cos) of the sector angles and of
/// the fold angles (ray order), with node k (k ≥ 1) in `nodes[k]` when asked.
fn chain_trig(sector_trig: &[(f64, f64)], fold_trig: &[(f64, f64)], mut nodes: Option<&mut [Vec3]>) -> Matrix3<f64> {
    let n = fold_trig.len();
    let (s0, c0) = sector_trig[0];
    let mut frame = Matrix3::new(c0, -s0, 0.0, s0, c0, 0.0, 0.0, 0.0, 1.0);
    if let Some(nodes) = nodes.as_deref_mut() {
        if n > 1 {
            nodes[1] = frame.column(0).into_owned();
        }
    }
    for k in 1..n {
        turn_trig(&mut frame, fold_trig[k], sector_trig[k]);
        if let Some(nodes) = nodes.as_deref_mut() {
            if k + 1 < n {
                nodes[k + 1] = frame.column(0).into_owned();
            }
        }
    }
    let (s, c) = fold_trig[0];
    let (c1, c2) = (frame.column(1).into_owned(), frame.column(2).into_owned());
    frame.set_column(1, &(c * c1 + s * c2));
    frame.set_column(2, &(c * c2 - s * c1));
    frame
}

/// The holonomy's rotation vector alone, from the (sin, cos) of the sector angles and of
/// the fold angles (ray order): the same products as [`closure_jacobian_trig`], so the same
/// r to the last bit, without the Jacobian's columns.
pub fn closure_residual_trig(sector_trig: &[(f64, f64)], fold_trig: &[(f64, f64)]) -> Vector3<f64> {
    rotation_vector(&chain_trig(sector_trig, fold_trig, None))
}

/// [`closure_jacobian`] of every ray, from the (sin, cos) of the sector angles and of the
/// fold angles (ray order), without allocating: returns r and writes ∂r/∂ρ_k into
/// `columns[k]` (`nodes` is scratch; both as long as the fold angles).
pub fn closure_jacobian_trig(
    sector_trig: &[(f64, f64)],
    fold_trig: &[(f64, f64)],
    nodes: &mut [Vec3],
    columns: &mut [Vector3<f64>],
) -> Vector3<f64> {
    let frame = chain_trig(sector_trig, fold_trig, Some(nodes));
    let r = rotation_vector(&frame);
    let jl_inv = left_jacobian_inverse(&r);
    columns[0] = jl_inv * frame.column(0);
    for k in 1..fold_trig.len() {
        columns[k] = jl_inv * nodes[k];
    }
    r
}

/// Node positions of the rays for the given sector and fold angles, sector 0 fixed in the
/// xy-plane. `fold_angles[0]` is used only by [`closure_rotation`]; for an open chain
/// (`sector_angles.len() == n − 1`) the boundary rays' fold angles are ignored.
pub fn forward(sector_angles: &[f64], fold_angles: &[f64]) -> Vec<Vec3> {
    let n = fold_angles.len();
    let mut nodes = Vec::with_capacity(n);
    let mut frame = Matrix3::identity();
    nodes.push(Vec3::x());
    for k in 1..n {
        if k == 1 {
            frame = rot_z(sector_angles[0]);
        } else {
            turn(&mut frame, fold_angles[k - 1], sector_angles[k - 1]);
        }
        nodes.push(frame.column(0).into_owned());
    }
    nodes
}

/// The closed chain's holonomy: identity exactly when the loop closes.
pub fn closure_rotation(sector_angles: &[f64], fold_angles: &[f64]) -> Matrix3<f64> {
    chain(sector_angles, fold_angles, None)
}

/// Rotation vector (axis × angle) of a rotation matrix, accurate near the identity where
/// the closure residual lives: θ = atan2(|v|, (tr − 1)/2) with v the skew part (sin θ·axis).
/// nalgebra's `scaled_axis` goes through arccos of the trace, which loses half the digits
/// there; it is used only near θ = π where the skew part vanishes.
fn rotation_vector(m: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5 * Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]);
    let sin_theta = v.norm();
    let cos_theta = 0.5 * (m.trace() - 1.0);
    if cos_theta < -0.5 {
        return Rotation3::from_matrix_unchecked(*m).scaled_axis();
    }
    if sin_theta == 0.0 {
        return Vector3::zeros();
    }
    v * (sin_theta.atan2(cos_theta) / sin_theta)
}

/// Loop-closure residual: the rotation angle of the holonomy, radians.
pub fn closure_residual(sector_angles: &[f64], fold_angles: &[f64]) -> f64 {
    rotation_vector(&closure_rotation(sector_angles, fold_angles)).norm()
}

/// Singular values of the closure Jacobian below this fraction of the largest are treated
/// as zero by the Newton solvers.
const SINGULAR_CUTOFF: f64 = 1e-9;

/// Outcome of [`solve_closure`].
#[derive(Debug, Clone, Copy)]
pub struct ClosureSolve {
    /// Newton iterations taken.
    pub iterations: usize,
    /// Rotation angle of the holonomy left, rad.
    pub residual: f64,
}

/// Restores loop closure by Newton's method on the fold angles listed in `free`, the
/// others held. The holonomy's spatial derivative with respect to ρ_k is the world axis of
/// ray k (the node x_k), so the Jacobian of its rotation vector r is J_l(r)⁻¹ [x_k …];
/// steps are minimum-norm (SVD) so more than three free creases are allowed.
pub fn solve_closure(
    sector_angles: &[f64],
    fold_angles: &mut [f64],
    free: &[usize],
    tol: f64,
    max_iterations: usize,
) -> Result<ClosureSolve> {
    let mut residual = f64::INFINITY;
    for iteration in 0..=max_iterations {
        let holonomy = closure_rotation(sector_angles, fold_angles);
        let r = rotation_vector(&holonomy);
        residual = r.norm();
        if residual <= tol {
            return Ok(ClosureSolve {
                iterations: iteration,
                residual,
            });
        }
        if iteration == max_iterations {
            break;
        }
        let jac = rotation_vector_jacobian(sector_angles, fold_angles, &holonomy, &r, free);
        let rhs = DVector::from_column_slice(&[-r.x, -r.y, -r.z]);
        let svd = jac.svd(true, true);
        // Relative cutoff: near a singular configuration a tiny singular value would
        // amplify the residual into a jump along the kernel, onto another branch.
        let cutoff = SINGULAR_CUTOFF * svd.singular_values.max();
        let step = svd.solve(&rhs, cutoff).map_err(|e| NumericalError::Singular {
            what: "loop closure",
            detail: e.to_string(),
        })?;
        // Damp huge steps (far from the solution the linearisation is poor).
        let largest = step.amax();
        let scale = if largest > 0.5 { 0.5 / largest } else { 1.0 };
        for (col, &k) in free.iter().enumerate() {
            fold_angles[k] += scale * step[col];
        }
    }
    Err(NumericalError::ClosureNotConverged {
        residual,
        iterations: max_iterations,
    }
    .into())
}

/// Continues Newton (undamped, minimum-norm) after [`solve_closure`] until the step stops
/// shrinking. Near a singular configuration (the flat state of a degree-4 vertex) the
/// residual is quadratic in the error along the Jacobian's kernel, so a residual of 1e-13
/// still allows angle errors near 3e-7; Newton converges linearly there and these extra
/// steps take the angles to rounding level. Returns the number of steps taken.
pub fn refine_closure(sector_angles: &[f64], fold_angles: &mut [f64], free: &[usize], max_iterations: usize) -> usize {
    let mut previous_step = f64::INFINITY;
    for iteration in 0..max_iterations {
        let (r, jac) = closure_jacobian(sector_angles, fold_angles, free);
        if r.norm() == 0.0 {
            return iteration;
        }
        let rhs = DVector::from_column_slice(&[-r.x, -r.y, -r.z]);
        let svd = jac.svd(true, true);
        let cutoff = SINGULAR_CUTOFF * svd.singular_values.max();
        let Ok(step) = svd.solve(&rhs, cutoff) else {
            return iteration;
        };
        let size = step.amax();
        if size.is_nan() || size >= 0.9 * previous_step || size > 1e-3 {
            return iteration;
        }
        for (col, &k) in free.iter().enumerate() {
            fold_angles[k] += step[col];
        }
        previous_step = size;
        if size < 1e-15 {
            return iteration + 1;
        }
    }
    max_iterations
}

/// The closure residual vector r (rotation vector of the holonomy) and its Jacobian
/// ∂r/∂ρ_k for the rays in `columns`: the implicit-function-theorem data of `docs/model.md#constraint-curves`.
pub fn closure_jacobian(sector_angles: &[f64], fold_angles: &[f64], columns: &[usize]) -> (Vector3<f64>, DMatrix<f64>) {
    let mut nodes = vec![Vec3::zeros(); fold_angles.len()];
    let holonomy = chain(sector_angles, fold_angles, Some(&mut nodes));
    let r = rotation_vector(&holonomy);
    let jac = jacobian_from_nodes(&nodes, &holonomy, &r, columns);
    (r, jac)
}

fn rotation_vector_jacobian(
    sector_angles: &[f64],
    fold_angles: &[f64],
    holonomy: &Matrix3<f64>,
    r: &Vector3<f64>,
    columns: &[usize],
) -> DMatrix<f64> {
    jacobian_from_nodes(&forward(sector_angles, fold_angles), holonomy, r, columns)
}

/// J_l(r)⁻¹ times each listed ray's world axis.
fn jacobian_from_nodes(nodes: &[Vec3], holonomy: &Matrix3<f64>, r: &Vector3<f64>, columns: &[usize]) -> DMatrix<f64> {
    let n = nodes.len();
    let jl_inv = left_jacobian_inverse(r);
    let mut jac = DMatrix::zeros(3, columns.len());
    for (col, &k) in columns.iter().enumerate() {
        // ρ_0 acts last, on the right: its spatial axis is holonomy·e_x ≈ x_0.
        let axis = if k == 0 {
            holonomy.column(0).into_owned()
        } else {
            nodes[k % n]
        };
        jac.set_column(col, &(jl_inv * axis));
    }
    jac
}

/// Inverse of SO(3)'s left Jacobian: maps a spatial angular velocity to d(rotation vector).
fn left_jacobian_inverse(r: &Vector3<f64>) -> Matrix3<f64> {
    let theta = r.norm();
    let k = r.cross_matrix();
    if theta < 1e-8 {
        return Matrix3::identity() - 0.5 * k + k * k / 12.0;
    }
    let coeff = 1.0 / (theta * theta) - (1.0 + theta.cos()) / (2.0 * theta * theta.sin());
    Matrix3::identity() - 0.5 * k + coeff * k * k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::sphere::{fold_angle, geodesic};
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

    #[test]
    fn the_trigonometric_closure_jacobian_is_the_angle_one() {
        let sectors = [1.1, 0.9, 1.4, 1.2, TAU - 4.6];
        let folds = [0.3, -1.2, 2.9, 0.7, -0.4];
        let (r, jac) = closure_jacobian(&sectors, &folds, &[0, 1, 2, 3, 4]);
        let sector_trig: Vec<(f64, f64)> = sectors.iter().map(|a| a.sin_cos()).collect();
        let fold_trig: Vec<(f64, f64)> = folds.iter().map(|a| a.sin_cos()).collect();
        let (mut nodes, mut columns) = (vec![Vec3::zeros(); 5], vec![Vec3::zeros(); 5]);
        let r_trig = closure_jacobian_trig(&sector_trig, &fold_trig, &mut nodes, &mut columns);
        assert!(r.norm() > 0.1 && (r - r_trig).norm() < 1e-14);
        for (k, column) in columns.iter().enumerate() {
            assert!((jac.column(k) - column).norm() < 1e-14, "ray {k}");
        }
    }

    #[test]
    fn flat_state_puts_nodes_at_cumulative_angles() {
        let sectors = [0.5, 1.0, 2.0, TAU - 3.5];
        let nodes = forward(&sectors, &[0.0; 4]);
        let mut phi = 0.0_f64;
        for (k, x) in nodes.iter().enumerate() {
            assert!((x - Vec3::new(phi.cos(), phi.sin(), 0.0)).norm() < 1e-15);
            phi += sectors[k];
        }
        assert!(closure_residual(&sectors, &[0.0; 4]) < 1e-14);
    }

    #[test]
    fn fold_angles_round_trip_through_positions() {
        // A degree-4 vertex folded by a kinematic move from flat.
        let sectors = [1.2, 1.7, 1.4, TAU - 4.3];
        let mut rho = vec![0.0, 0.9, 0.0, 0.0];
        rho[0] = 0.3;
        solve_closure(&sectors, &mut rho, &[0, 2, 3], 1e-14, 50).unwrap();
        let nodes = forward(&sectors, &rho);
        let n = 4;
        for k in 0..n {
            let measured = fold_angle(&nodes[(k + n - 1) % n], &nodes[k], &nodes[(k + 1) % n]);
            assert!((measured - rho[k]).abs() < 1e-12, "ray {k}: {measured} vs {}", rho[k]);
            assert!((geodesic(&nodes[k], &nodes[(k + 1) % n]) - sectors[k]).abs() < 1e-12);
        }
    }

    #[test]
    fn straight_crease_line_closes_for_equal_fold_angles() {
        // A plus-shaped vertex: one straight crease line folds alone, ρ = (ρ, 0, ρ, 0).
        let sectors = [FRAC_PI_2; 4];
        for rho in [0.1, 1.0, 2.5, PI] {
            assert!(closure_residual(&sectors, &[rho, 0.0, rho, 0.0]) < 1e-14);
        }
        // Opposite signs on one straight line do not close: the residual is |2ρ|.
        for rho in [0.1_f64, 1.0] {
            assert!((closure_residual(&sectors, &[rho, 0.0, -rho, 0.0]) - 2.0 * rho).abs() < 1e-12);
        }
        // Rays 0 and 2 at 0° and 135° are no straight line: no closure at ρ ≠ 0.
        let skew = [FRAC_PI_4, FRAC_PI_2, 3.0 * FRAC_PI_4, FRAC_PI_2];
        assert!(closure_residual(&skew, &[1.0, 0.0, 1.0, 0.0]) > 1e-3);
    }
}
