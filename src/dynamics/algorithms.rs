//! Rigid-body algorithms over a [`Model`] and its [`Data`] (`docs/model.md#dynamics`):
//! product-of-exponentials kinematics, the mass matrix M(θ) = Σ Jᵢᵀ Φᵢ Jᵢ and its
//! derivative, Coriolis terms (Christoffel symbols and Newton–Euler), drag and the forward
//! dynamics θ̈ = M⁻¹(τ − C θ̇ − K θ + Q_drag). Free functions, as in Pinocchio: the model
//! is read, the data written, nothing allocated.

use super::model::{Data, Model};
use crate::error::{NumericalError, Result};
use nalgebra::{Cholesky, DMatrix, DVectorViewMut, Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

/// Rotation about `axis` through `point` by `angle`: the exponential e^{ξ̂θ} of a revolute twist.
fn joint_exponential(axis: &Unit<Vector3<f64>>, point: &Point3<f64>, angle: f64) -> Isometry3<f64> {
    let rotation = UnitQuaternion::from_axis_angle(axis, angle);
    let translation = point.coords - rotation * point.coords;
    Isometry3::from_parts(Translation3::from(translation), rotation)
}

/// Forward kinematics by the product of exponentials along each plate's path from the
/// ground: gᵢ(θ) = e^{ξ̂₁θ₁} ⋯ e^{ξ̂ᵢθᵢ} gᵢ(0). Fills the joint axes and points, the joint
/// frames and the plate poses.
pub fn update_poses(model: &Model, fold_angles: &[f64], data: &mut Data) {
    for (i, (joint, plate)) in model.joints().iter().zip(model.plates()).enumerate() {
        let parent = model
            .parent(i)
            .map_or_else(Isometry3::identity, |p| data.joint_frames[p]);
        data.axes[i] = parent.rotation * joint.axis.into_inner();
        data.points[i] = (parent * joint.point).coords;
        let frame = parent * joint_exponential(&joint.axis, &joint.point, fold_angles[i]);
        data.joint_frames[i] = frame;
        data.poses[i] = frame * plate.reference_pose;
    }
}

/// The plates' corners in the world frame (contact detection); needs the poses.
pub fn update_corners(model: &Model, data: &mut Data) {
    let mut index = 0;
    for (i, plate) in model.plates().iter().enumerate() {
        for corner in &plate.outline {
            data.corners[index] = data.poses[i] * corner;
            index += 1;
        }
    }
}

/// [`update_poses`] plus the world inertias, a_ij and Iᵢ ω'_j that M and ∂M need.
pub fn update_kinematics(model: &Model, fold_angles: &[f64], data: &mut Data) {
    let n = model.dof();
    update_poses(model, fold_angles, data);
    for (i, plate) in model.plates().iter().enumerate() {
        let rotation = data.poses[i].rotation.to_rotation_matrix();
        let r = rotation.matrix();
        let inertia = r * plate.inertia * r.transpose();
        data.inertia_world[i] = inertia;
        let com = data.poses[i].translation.vector;
        for j in 0..n {
            let (a, iw) = if model.moves(i, j) {
                (data.axes[j].cross(&(com - data.points[j])), inertia * data.axes[j])
            } else {
                (Vector3::zeros(), Vector3::zeros())
            };
            data.linear_jacobian[i * n + j] = a;
            data.inertia_axes[i * n + j] = iw;
        }
    }
}

/// M(θ) = Σᵢ Jᵢᵀ Φᵢ Jᵢ, with Jᵢ the body Jacobian at plate i's centre of mass in
/// world-aligned axes (the kinetic energy is frame-invariant, so M is the same).
/// Needs [`update_kinematics`] first.
pub fn update_mass_matrix(model: &Model, data: &mut Data) {
    let n = model.dof();
    data.mass_matrix.fill(0.0);
    for (i, plate) in model.plates().iter().enumerate() {
        let path = model.support(i);
        for (position, &j) in path.iter().enumerate() {
            let a_j = data.linear_jacobian[i * n + j];
            let i_w_j = data.inertia_axes[i * n + j];
            for &k in &path[..=position] {
                let value = plate.mass * a_j.dot(&data.linear_jacobian[i * n + k]) + data.axes[k].dot(&i_w_j);
                data.mass_matrix[(j, k)] += value;
            }
        }
    }
    for j in 0..n {
        for k in 0..j {
            data.mass_matrix[(k, j)] = data.mass_matrix[(j, k)];
        }
    }
}

/// ∂M/∂θ_k in closed form: joint k rotates everything it moves rigidly, so along a plate's
/// path ∂ω'_j = ω'_k × ω'_j (j after k), ∂a_ij = ω'_k × a_ij (j after k) or
/// ω'_j × (ω'_k × (p_i − q'_k)) (j at or before k), ∂(R I Rᵀ) = [ω'_k]× I − I [ω'_k]×.
/// Entries with both j, l after k vanish (a rigid rotation leaves them unchanged), and
/// plates joint k does not move contribute nothing.
pub fn update_mass_matrix_derivative(model: &Model, data: &mut Data) {
    let n = model.dof();
    for k in 0..n {
        let omega_k = data.axes[k];
        let point_k = data.points[k];
        let mut derivative = std::mem::replace(&mut data.mass_matrix_derivative[k], DMatrix::zeros(0, 0));
        derivative.fill(0.0);
        for i in (k..n).filter(|&i| model.moves(i, k)) {
            let mass = model.plates()[i].mass;
            let lever = data.poses[i].translation.vector - point_k;
            let row = i * n;
            let path = model.support(i);
            for &j in path {
                data.scratch_linear[j] = if k < j {
                    omega_k.cross(&data.linear_jacobian[row + j])
                } else {
                    data.axes[j].cross(&omega_k.cross(&lever))
                };
                data.scratch_angular[j] = if k < j {
                    omega_k.cross(&data.axes[j])
                } else {
                    Vector3::zeros()
                };
            }
            for &j in path {
                let a_j = data.linear_jacobian[row + j];
                let da_j = data.scratch_linear[j];
                let w_j = data.axes[j];
                let dw_j = data.scratch_angular[j];
                let iw_j = data.inertia_axes[row + j];
                for &l in path.iter().take_while(|&&l| l <= j.min(k)) {
                    let a_l = data.linear_jacobian[row + l];
                    let w_l = data.axes[l];
                    let iw_l = data.inertia_axes[row + l];
                    // w_jᵀ ∂I w_l = w_j·(ω_k × I w_l) − I w_j·(ω_k × w_l).
                    let value = mass * (da_j.dot(&a_l) + a_j.dot(&data.scratch_linear[l]))
                        + dw_j.dot(&iw_l)
                        + w_j.dot(&omega_k.cross(&iw_l))
                        - iw_j.dot(&omega_k.cross(&w_l))
                        + iw_j.dot(&data.scratch_angular[l]);
                    derivative[(j, l)] += value;
                }
            }
        }
        for j in 0..n {
            for l in 0..j {
                derivative[(l, j)] = derivative[(j, l)];
            }
        }
        data.mass_matrix_derivative[k] = derivative;
    }
}

/// Centre-of-mass velocities vᵢ = Σ_j a_ij θ̇_j (m/s) and angular velocities Ωᵢ = Σ_j ω'_j θ̇_j
/// (rad/s) of every plate, into `data` (needs the kinematics).
pub fn update_velocities(model: &Model, fold_rates: &[f64], data: &mut Data) {
    let n = model.dof();
    for i in 0..n {
        let (mut velocity, mut spin) = (Vector3::zeros(), Vector3::zeros());
        for &j in model.support(i) {
            velocity += data.linear_jacobian[i * n + j] * fold_rates[j];
            spin += data.axes[j] * fold_rates[j];
        }
        data.velocities[i] = velocity;
        data.spins[i] = spin;
    }
}

/// The Coriolis and centrifugal torques C(θ, θ̇) θ̇ in O(n²), for the right-hand side:
/// Σᵢ J_vᵢᵀ mᵢ J̇_vᵢ θ̇ + J_ωᵢᵀ (Iᵢ J̇_ωᵢ θ̇ + Ωᵢ × Iᵢ Ωᵢ), the velocity-product part of each
/// plate's Newton–Euler equations projected on the joints. It equals the Christoffel form
/// of [`update_coriolis_matrix`] times θ̇ (tested); it needs the kinematics and
/// [`update_velocities`] at the same θ̇.
pub fn coriolis_torques(model: &Model, fold_rates: &[f64], data: &mut Data, out: &mut [f64]) {
    let n = model.dof();
    for i in 0..n {
        // ω̇'_i = Ω_parent × ω'_i; q̇'_i = velocity of the hinge point as a point of the parent.
        match model.parent(i) {
            None => {
                data.scratch_angular[i] = Vector3::zeros();
                data.scratch_linear[i] = Vector3::zeros();
            }
            Some(p) => {
                let parent_spin = data.spins[p];
                data.scratch_angular[i] = parent_spin.cross(&data.axes[i]);
                let com = data.poses[p].translation.vector;
                data.scratch_linear[i] = data.velocities[p] + parent_spin.cross(&(data.points[i] - com));
            }
        }
    }
    out.iter_mut().for_each(|o| *o = 0.0);
    for (i, plate) in model.plates().iter().enumerate() {
        let spin = data.spins[i];
        let com = data.poses[i].translation.vector;
        let velocity = data.velocities[i];
        let mut linear_bias = Vector3::zeros();
        let mut angular_bias = Vector3::zeros();
        for &j in model.support(i) {
            let axis_rate = data.scratch_angular[j];
            // ȧ_ij = ω̇'_j × (p_i − q'_j) + ω'_j × (v_i − q̇'_j).
            let a_dot =
                axis_rate.cross(&(com - data.points[j])) + data.axes[j].cross(&(velocity - data.scratch_linear[j]));
            linear_bias += a_dot * fold_rates[j];
            angular_bias += axis_rate * fold_rates[j];
        }
        let inertia = &data.inertia_world[i];
        let force = plate.mass * linear_bias;
        let moment = inertia * angular_bias + spin.cross(&(inertia * spin));
        for &j in model.support(i) {
            out[j] += data.linear_jacobian[i * n + j].dot(&force) + data.axes[j].dot(&moment);
        }
    }
}

/// C(θ, θ̇) with C_ij = ½ Σ_k (∂M_ij/∂θ_k + ∂M_ik/∂θ_j − ∂M_kj/∂θ_i) θ̇_k
/// (`docs/model.md#equations-of-motion`). Needs [`update_mass_matrix_derivative`] first.
pub fn update_coriolis_matrix(model: &Model, fold_rates: &[f64], data: &mut Data) {
    let n = model.dof();
    for i in 0..n {
        for j in 0..n {
            let mut sum = 0.0;
            for (k, rate) in fold_rates.iter().enumerate() {
                sum += (data.mass_matrix_derivative[k][(i, j)] + data.mass_matrix_derivative[j][(i, k)]
                    - data.mass_matrix_derivative[i][(k, j)])
                    * rate;
            }
            data.coriolis[(i, j)] = 0.5 * sum;
        }
    }
}

/// Generalised drag force Q_j = Σᵢ a_ijᵀ Fᵢ, N·m (`docs/model.md#drag`); zero without drag.
/// Its power Q·θ̇ = Σ Fᵢ·vᵢ = −½ C_D ρ A |v|²|v·n| is never positive. Needs
/// [`update_velocities`].
pub fn drag_torques(model: &Model, data: &mut Data, out: &mut [f64]) {
    out.iter_mut().for_each(|q| *q = 0.0);
    let Some(drag) = model.drag() else { return };
    let n = model.dof();
    for (i, plate) in model.plates().iter().enumerate() {
        let velocity = data.velocities[i];
        let normal = data.poses[i].rotation * Vector3::z();
        let sign = data.drag_switches.sign(i, velocity.dot(&normal));
        if sign == 0.0 {
            continue;
        }
        let magnitude = 0.5 * drag.drag_coefficient * drag.air_density * plate.area * velocity.norm_squared();
        let force = -magnitude * sign * normal;
        for &j in model.support(i) {
            out[j] += data.linear_jacobian[i * n + j].dot(&force);
        }
    }
}

/// Kinetic energy ½ θ̇ᵀ M θ̇, J (needs the mass matrix).
pub fn kinetic_energy(fold_rates: &[f64], data: &Data) -> f64 {
    quadratic_form(&data.mass_matrix, fold_rates)
}

/// ½ xᵀ A x for a square matrix.
pub(crate) fn quadratic_form(a: &DMatrix<f64>, x: &[f64]) -> f64 {
    let mut sum = 0.0;
    for (i, xi) in x.iter().enumerate() {
        for (j, xj) in x.iter().enumerate() {
            sum += a[(i, j)] * xi * xj;
        }
    }
    0.5 * sum
}

/// θ̈ = M⁻¹ (τ − C θ̇ − K θ + Q_drag), written into `accel` (`docs/model.md#equations-of-motion`).
/// Allocation-free: the factorisation reuses a buffer of `data`.
pub fn forward_dynamics(
    model: &Model,
    fold_angles: &[f64],
    fold_rates: &[f64],
    torques: &[f64],
    data: &mut Data,
    accel: &mut [f64],
) -> Result<()> {
    let n = model.dof();
    update_kinematics(model, fold_angles, data);
    update_mass_matrix(model, data);
    update_velocities(model, fold_rates, data);
    let mut coriolis = std::mem::take(&mut data.coriolis_torques);
    coriolis_torques(model, fold_rates, data, &mut coriolis);
    let drag = &mut *accel;
    drag_torques(model, data, drag);
    for i in 0..n {
        drag[i] += torques[i] - coriolis[i] - model.joints()[i].stiffness * fold_angles[i];
    }
    data.coriolis_torques = coriolis;
    let mut factor = std::mem::replace(&mut data.factor, DMatrix::zeros(0, 0));
    factor.copy_from(&data.mass_matrix);
    let Some(cholesky) = Cholesky::new(factor) else {
        data.factor = DMatrix::zeros(n, n);
        return Err(NumericalError::NotPositiveDefinite {
            matrix: "mass matrix",
            at: format!("θ = {fold_angles:?}"),
        }
        .into());
    };
    cholesky.solve_mut(&mut DVectorViewMut::from_slice(accel, n));
    data.factor = cholesky.unpack_dirty();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::model::{Joint, Plate};
    use super::*;
    use nalgebra::{DVector, Matrix3, Rotation3};

    fn plate(centre: Vector3<f64>, rotation: Rotation3<f64>) -> Plate {
        Plate {
            mass: 2.0,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.3, 0.2, 0.45)),
            reference_pose: Isometry3::from_parts(Translation3::from(centre), rotation.into()),
            outline: [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
                .iter()
                .map(|&[x, y]| Point3::new(x, y, 0.0))
                .collect(),
            area: 1.0,
            thickness: 0.01,
        }
    }

    fn skew_joints() -> Vec<Joint> {
        vec![
            Joint {
                axis: Vector3::x_axis(),
                point: Point3::origin(),
                stiffness: 1.0,
            },
            Joint {
                axis: Unit::new_normalize(Vector3::new(1.0, 0.3, 0.2)),
                point: Point3::new(0.0, 1.0, 0.0),
                stiffness: 2.0,
            },
            Joint {
                axis: Unit::new_normalize(Vector3::new(0.2, -0.1, 1.0)),
                point: Point3::new(0.1, 2.0, 0.1),
                stiffness: 0.5,
            },
            Joint {
                axis: Unit::new_normalize(Vector3::new(-0.3, 1.0, 0.4)),
                point: Point3::new(0.4, -0.5, 0.2),
                stiffness: 0.7,
            },
        ]
    }

    fn skew_plates() -> Vec<Plate> {
        vec![
            plate(Vector3::new(0.0, 0.5, 0.0), Rotation3::identity()),
            plate(Vector3::new(0.1, 1.5, 0.0), Rotation3::from_euler_angles(0.1, 0.2, 0.3)),
            plate(
                Vector3::new(0.3, 2.6, 0.2),
                Rotation3::from_euler_angles(-0.2, 0.4, 0.1),
            ),
            plate(
                Vector3::new(0.5, -1.0, 0.3),
                Rotation3::from_euler_angles(0.3, -0.1, 0.2),
            ),
        ]
    }

    /// Three plates with non-parallel hinges in a row, so every term of ∂M is exercised.
    pub(crate) fn skew_chain() -> Model {
        let mut joints = skew_joints();
        let mut plates = skew_plates();
        joints.truncate(3);
        plates.truncate(3);
        Model::chain(joints, plates, None).unwrap()
    }

    /// A tree: plates 1 and 3 hang from plate 0, plate 2 from plate 1.
    fn skew_tree() -> Model {
        Model::tree(
            skew_joints(),
            skew_plates(),
            vec![None, Some(0), Some(1), Some(0)],
            None,
        )
        .unwrap()
    }

    fn mass_matrix_at(model: &Model, data: &mut Data, angles: &[f64]) -> DMatrix<f64> {
        update_kinematics(model, angles, data);
        update_mass_matrix(model, data);
        data.mass_matrix.clone()
    }

    #[test]
    fn lamina_moments_match_closed_forms() {
        // A 2 × 3 box of thickness 0.1: m(b² + t²)/12 about x, m(a² + t²)/12 about y, m(a² + b²)/12 about z.
        let (a, b, t, rho) = (2.0, 3.0, 0.1, 5.0);
        let box_plate = Plate::lamina(&[[1.0, 1.0], [3.0, 1.0], [3.0, 4.0], [1.0, 4.0]], t, rho);
        let m = rho * a * b * t;
        assert!((box_plate.mass - m).abs() < 1e-12);
        let expected = Vector3::new(m * (b * b + t * t), m * (a * a + t * t), m * (a * a + b * b)) / 12.0;
        assert!((box_plate.inertia - Matrix3::from_diagonal(&expected)).amax() < 1e-12);
        assert!((box_plate.reference_pose.translation.vector - Vector3::new(2.0, 2.5, 0.0)).norm() < 1e-15);
        // A right triangle with legs a (x) and b (y) at the origin: centroid (a/3, b/3),
        // ∫y'² = a b³/36, ∫x'² = a³ b/36, ∫x'y' = −a² b²/72 (standard tables).
        let tri = Plate::lamina(&[[0.0, 0.0], [a, 0.0], [0.0, b]], t, rho);
        let sigma = rho * t;
        let mass = sigma * a * b / 2.0;
        let through = mass * t * t / 12.0;
        assert!((tri.reference_pose.translation.vector - Vector3::new(a / 3.0, b / 3.0, 0.0)).norm() < 1e-15);
        let want = Matrix3::new(
            sigma * a * b.powi(3) / 36.0 + through,
            sigma * a * a * b * b / 72.0,
            0.0,
            sigma * a * a * b * b / 72.0,
            sigma * a.powi(3) * b / 36.0 + through,
            0.0,
            0.0,
            0.0,
            sigma * (a * b.powi(3) + a.powi(3) * b) / 36.0,
        );
        assert!((tri.inertia - want).amax() < 1e-12, "{}", tri.inertia - want);
        assert!(tri.contains(&Point3::new(0.0, 0.0, 0.0), 1e-12));
        assert!(!tri.contains(&Point3::new(a / 3.0, b / 3.0, 0.0), 1e-12));
        assert!(tri.contains(&Point3::new(-a / 6.0, -b / 6.0, 0.0), 1e-12));
    }

    #[test]
    fn a_model_refuses_a_joint_that_hangs_from_a_later_plate() {
        let err = Model::tree(
            skew_joints(),
            skew_plates(),
            vec![None, Some(2), Some(0), Some(0)],
            None,
        )
        .unwrap_err();
        assert!(err.to_string().contains("parents[1]"), "{err}");
    }

    #[test]
    fn mass_matrix_derivative_matches_central_differences() {
        for (model, angles) in [
            (skew_chain(), vec![0.4, -0.7, 1.1]),
            (skew_tree(), vec![0.4, -0.7, 1.1, 0.5]),
        ] {
            let n = model.dof();
            let mut data = Data::new(&model);
            update_kinematics(&model, &angles, &mut data);
            update_mass_matrix(&model, &mut data);
            update_mass_matrix_derivative(&model, &mut data);
            let h = 1e-5;
            for k in 0..n {
                let mut plus = angles.clone();
                let mut minus = angles.clone();
                plus[k] += h;
                minus[k] -= h;
                let fd = (mass_matrix_at(&model, &mut data.clone(), &plus)
                    - mass_matrix_at(&model, &mut data.clone(), &minus))
                    / (2.0 * h);
                let error = (&fd - &data.mass_matrix_derivative[k]).amax();
                assert!(
                    error < 1e-8,
                    "n = {n}, ∂M/∂θ_{k}: error {error:.2e}\n{fd}\n{}",
                    data.mass_matrix_derivative[k]
                );
            }
        }
    }

    #[test]
    fn a_tree_is_the_sum_of_its_branches() {
        // Plate 3 hangs from plate 0 only: its kinetic energy must not depend on θ₁ or θ₂,
        // and zeroing θ̇₃ leaves the chain 0-1-2's kinetic energy.
        let tree = skew_tree();
        let mut data = Data::new(&tree);
        let angles = [0.2, 0.9, -0.4, 0.7];
        let rates = [0.5, -1.2, 0.8, 0.0];
        update_kinematics(&tree, &angles, &mut data);
        update_mass_matrix(&tree, &mut data);
        let tree_energy = kinetic_energy(&rates, &data);
        let chain = skew_chain();
        let mut chain_data = Data::new(&chain);
        update_kinematics(&chain, &angles[..3], &mut chain_data);
        update_mass_matrix(&chain, &mut chain_data);
        let chain_energy = kinetic_energy(&rates[..3], &chain_data);
        // Plate 3 moves with plate 0 at θ̇₀: add its energy from its own velocity.
        update_velocities(&tree, &rates, &mut data);
        let plate3 = &tree.plates()[3];
        let spin = data.spins[3];
        let own =
            0.5 * plate3.mass * data.velocities[3].norm_squared() + 0.5 * spin.dot(&(data.inertia_world[3] * spin));
        assert!(
            (tree_energy - chain_energy - own).abs() < 1e-12 * tree_energy,
            "{tree_energy} vs {chain_energy} + {own}"
        );
        assert!(!tree.moves(3, 1) && !tree.moves(3, 2) && tree.moves(3, 0));
    }

    fn kinetic_energy_at(model: &Model, angles: &[f64], rates: &[f64]) -> f64 {
        let mut data = Data::new(model);
        update_kinematics(model, angles, &mut data);
        update_mass_matrix(model, &mut data);
        kinetic_energy(rates, &data)
    }

    #[test]
    fn coriolis_christoffel_newton_euler_and_finite_differences_agree() {
        for (model, angles, rates) in [
            (skew_chain(), vec![0.3, 0.9, -0.6], vec![1.3, -0.4, 2.1]),
            (skew_tree(), vec![0.3, 0.9, -0.6, 0.4], vec![1.3, -0.4, 2.1, -0.9]),
        ] {
            let n = model.dof();
            let mut data = Data::new(&model);
            update_kinematics(&model, &angles, &mut data);
            update_mass_matrix(&model, &mut data);
            update_mass_matrix_derivative(&model, &mut data);
            update_coriolis_matrix(&model, &rates, &mut data);
            let christoffel = &data.coriolis * DVector::from_column_slice(&rates);
            let mut newton_euler = vec![0.0; n];
            let mut moving = data.clone();
            update_velocities(&model, &rates, &mut moving);
            coriolis_torques(&model, &rates, &mut moving, &mut newton_euler);
            // Independent: C θ̇ = Ṁ θ̇ − ½ ∂(θ̇ᵀ M θ̇)/∂θ, both by central differences of M.
            let h = 1e-5;
            let theta_dot = DVector::from_column_slice(&rates);
            let along: Vec<f64> = (0..n).map(|k| angles[k] + h * rates[k]).collect();
            let back: Vec<f64> = (0..n).map(|k| angles[k] - h * rates[k]).collect();
            let m_dot = (mass_matrix_at(&model, &mut data.clone(), &along)
                - mass_matrix_at(&model, &mut data.clone(), &back))
                / (2.0 * h);
            let mut expected = &m_dot * &theta_dot;
            for k in 0..n {
                let mut plus = angles.clone();
                let mut minus = angles.clone();
                plus[k] += h;
                minus[k] -= h;
                // ½ ∂(θ̇ᵀMθ̇)/∂θ_k = ∂T/∂θ_k.
                expected[k] -=
                    (kinetic_energy_at(&model, &plus, &rates) - kinetic_energy_at(&model, &minus, &rates)) / (2.0 * h);
            }
            let scale = expected.amax();
            for i in 0..n {
                assert!(
                    (christoffel[i] - expected[i]).abs() < 1e-8 * scale,
                    "n = {n}: Christoffel {christoffel} vs FD {expected}"
                );
                assert!(
                    (newton_euler[i] - christoffel[i]).abs() < 1e-12 * scale,
                    "n = {n}: Newton–Euler {newton_euler:?} vs {christoffel}"
                );
            }
            // Ṁ − 2C is skew-symmetric (passivity).
            let mut m_dot_exact = DMatrix::zeros(n, n);
            for (derivative, rate) in data.mass_matrix_derivative.iter().zip(&rates) {
                m_dot_exact += derivative * *rate;
            }
            let n_matrix = &m_dot_exact - 2.0 * &data.coriolis;
            let skew_error = (&n_matrix + n_matrix.transpose()).amax();
            assert!(
                skew_error < 1e-12 * n_matrix.amax(),
                "Ṁ − 2C not skew: {skew_error:.2e}"
            );
            assert!((m_dot_exact - m_dot).amax() < 1e-8 * scale);
        }
    }
}
