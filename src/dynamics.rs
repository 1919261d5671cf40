//! Rigid-plate chain dynamics (SPEC §7): product-of-exponentials kinematics, the mass matrix
//! M(θ) = Σ Jᵢᵀ Φᵢ Jᵢ, Coriolis terms by Christoffel symbols, hinge stiffness and drag.
//!
//! [`Model`] is the immutable description of a chain (built by `scene`); [`Data`] holds the
//! scratch buffers reused across evaluations, so M, C and the right-hand side allocate nothing.
//! SI units throughout (m, kg, s, N·m/rad).

pub mod closed;
pub mod contact;
pub mod modes;
pub mod simulate;

use crate::error::{NanofoldError, Result};
use nalgebra::{
    Cholesky, DMatrix, DVector, DVectorViewMut, Isometry3, Matrix3, Point3, Translation3, Unit, UnitQuaternion, Vector3,
};

/// A revolute hinge in the flat reference configuration: the twist ξ = (−ω × q, ω) (T4.2).
#[derive(Debug, Clone)]
pub struct Joint {
    /// Unit axis ω (a positive angle folds valley: right-handed about ω).
    pub axis: Unit<Vector3<f64>>,
    /// A point q on the axis, m.
    pub point: Point3<f64>,
    /// Hinge stiffness K_ii, N·m/rad (T5.7).
    pub stiffness: f64,
}

/// A rigid thin plate: body i moves with joints 0..=i.
#[derive(Debug, Clone)]
pub struct Plate {
    /// Mass from the structural layer, kg.
    pub mass: f64,
    /// Inertia tensor at the centre of mass in the body axes, kg·m².
    pub inertia: Matrix3<f64>,
    /// Pose of the centre-of-mass frame at θ = 0 (body z the plate normal).
    pub reference_pose: Isometry3<f64>,
    /// The plate's outline in the body frame (z = 0), a convex polygon counter-clockwise.
    pub outline: Vec<Point3<f64>>,
    /// Area facing the air (drag), m².
    pub area: f64,
}

impl Plate {
    /// A uniform lamina of the given thickness (m) and density (kg/m³) whose mid-plane is the
    /// convex polygon `outline` (m, counter-clockwise in the flat xy-plane at θ = 0). Its body
    /// frame sits at the centroid with the world's axes, so body z is the normal. The inertia is
    /// the thin-box tensor: in-plane second moments of the polygon plus m t²/12 about the
    /// in-plane axes (for a rectangle exactly the box moments of SPEC §7).
    pub fn lamina(outline: &[[f64; 2]], thickness: f64, density: f64) -> Plate {
        let count = outline.len();
        let (mut area2, mut cx, mut cy) = (0.0, 0.0, 0.0);
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for k in 0..count {
            let ([x0, y0], [x1, y1]) = (outline[k], outline[(k + 1) % count]);
            let c = x0 * y1 - x1 * y0;
            area2 += c;
            cx += (x0 + x1) * c;
            cy += (y0 + y1) * c;
            sxx += (y0 * y0 + y0 * y1 + y1 * y1) * c;
            syy += (x0 * x0 + x0 * x1 + x1 * x1) * c;
            sxy += (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) * c;
        }
        let area = 0.5 * area2;
        let (cx, cy) = (cx / (3.0 * area2), cy / (3.0 * area2));
        // ∫y², ∫x², ∫xy over the polygon, moved to the centroid.
        let iyy_area = sxx / 12.0 - area * cy * cy;
        let ixx_area = syy / 12.0 - area * cx * cx;
        let ixy_area = sxy / 24.0 - area * cx * cy;
        let areal_density = density * thickness;
        let mass = areal_density * area;
        let through = mass * thickness * thickness / 12.0;
        let inertia = Matrix3::new(
            areal_density * iyy_area + through,
            -areal_density * ixy_area,
            0.0,
            -areal_density * ixy_area,
            areal_density * ixx_area + through,
            0.0,
            0.0,
            0.0,
            areal_density * (ixx_area + iyy_area),
        );
        Plate {
            mass,
            inertia,
            reference_pose: Isometry3::translation(cx, cy, 0.0),
            outline: outline.iter().map(|&[x, y]| Point3::new(x - cx, y - cy, 0.0)).collect(),
            area,
        }
    }

    /// Largest distance of the outline from the centre of mass, m.
    pub fn radius(&self) -> f64 {
        self.outline.iter().map(|p| p.coords.norm()).fold(0.0, f64::max)
    }

    /// Whether a body-frame point (z ignored) lies inside the outline or within `tolerance` of it.
    pub fn contains(&self, local: &Point3<f64>, tolerance: f64) -> bool {
        let count = self.outline.len();
        (0..count).all(|k| {
            let (a, b) = (self.outline[k], self.outline[(k + 1) % count]);
            let edge = b - a;
            let length = edge.x.hypot(edge.y);
            // Signed distance to the left of the edge (inside for a counter-clockwise polygon).
            (edge.x * (local.y - a.y) - edge.y * (local.x - a.x)) / length >= -tolerance
        })
    }
}

/// Quadratic drag on each plate (T5.8, literal reading): F = −½ C_D ρ A |v|² sgn(v·n) n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drag {
    pub drag_coefficient: f64,
    /// kg/m³.
    pub air_density: f64,
}

/// Immutable description of an open chain of plates and hinges.
#[derive(Debug, Clone)]
pub struct Model {
    pub joints: Vec<Joint>,
    pub plates: Vec<Plate>,
    pub drag: Option<Drag>,
}

/// Scratch buffers for one [`Model`]: current joint axes and points, plate poses, M, ∂M/∂θ.
#[derive(Debug, Clone)]
pub struct Data {
    /// ω'_j: joint axes at the current configuration.
    pub axes: Vec<Vector3<f64>>,
    /// q'_j: points on the joint axes at the current configuration, m.
    pub points: Vec<Vector3<f64>>,
    /// g_i(θ): plate centre-of-mass frames.
    pub poses: Vec<Isometry3<f64>>,
    /// Rᵢ I_body Rᵢᵀ: world-frame inertia tensors at the centres of mass.
    pub inertia_world: Vec<Matrix3<f64>>,
    /// Plate outline corners in the world frame, plate after plate ([`Model::corner_index`]).
    pub corners: Vec<Point3<f64>>,
    /// Iᵢ ω'_j (row-major i·n + j).
    pub inertia_axes: Vec<Vector3<f64>>,
    /// Centre-of-mass velocities, m/s.
    pub velocities: Vec<Vector3<f64>>,
    /// a_ij = ω'_j × (p_i − q'_j): centre-of-mass velocity per unit θ̇_j (row-major i·n + j).
    pub linear_jacobian: Vec<Vector3<f64>>,
    pub mass_matrix: DMatrix<f64>,
    /// ∂M/∂θ_k, one matrix per k.
    pub mass_matrix_derivative: Vec<DMatrix<f64>>,
    /// C(θ, θ̇) by Christoffel symbols.
    pub coriolis: DMatrix<f64>,
    /// C(θ, θ̇) θ̇.
    pub coriolis_torques: Vec<f64>,
    factor: DMatrix<f64>,
    scratch_linear: Vec<Vector3<f64>>,
    scratch_angular: Vec<Vector3<f64>>,
}

impl Data {
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        Data {
            axes: vec![Vector3::zeros(); n],
            points: vec![Vector3::zeros(); n],
            poses: vec![Isometry3::identity(); n],
            inertia_world: vec![Matrix3::zeros(); n],
            corners: vec![Point3::origin(); model.plates.iter().map(|p| p.outline.len()).sum()],
            inertia_axes: vec![Vector3::zeros(); n * n],
            velocities: vec![Vector3::zeros(); n],
            linear_jacobian: vec![Vector3::zeros(); n * n],
            mass_matrix: DMatrix::zeros(n, n),
            mass_matrix_derivative: vec![DMatrix::zeros(n, n); n],
            coriolis: DMatrix::zeros(n, n),
            coriolis_torques: vec![0.0; n],
            factor: DMatrix::zeros(n, n),
            scratch_linear: vec![Vector3::zeros(); n],
            scratch_angular: vec![Vector3::zeros(); n],
        }
    }
}

/// Rotation about `axis` through `point` by `angle`: the exponential e^{ξ̂θ} of a revolute twist.
fn joint_exponential(axis: &Unit<Vector3<f64>>, point: &Point3<f64>, angle: f64) -> Isometry3<f64> {
    let rotation = UnitQuaternion::from_axis_angle(axis, angle);
    let translation = point.coords - rotation * point.coords;
    Isometry3::from_parts(Translation3::from(translation), rotation)
}

impl Model {
    /// Degrees of freedom: one per hinge.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Index of plate `plate`'s corner `corner` in [`Data::corners`].
    pub fn corner_index(&self, plate: usize, corner: usize) -> usize {
        self.plates[..plate].iter().map(|p| p.outline.len()).sum::<usize>() + corner
    }

    /// Diagonal hinge stiffness K, N·m/rad.
    pub fn stiffness(&self) -> DVector<f64> {
        DVector::from_iterator(self.dof(), self.joints.iter().map(|j| j.stiffness))
    }

    /// Forward kinematics by the product of exponentials (T4.1):
    /// gᵢ(θ) = e^{ξ̂₁θ₁} ⋯ e^{ξ̂ᵢθᵢ} gᵢ(0); fills the joint axes and points and the plate poses.
    pub fn update_poses(&self, fold_angles: &[f64], data: &mut Data) {
        let mut chain = Isometry3::identity();
        for (i, (joint, plate)) in self.joints.iter().zip(&self.plates).enumerate() {
            data.axes[i] = chain.rotation * joint.axis.into_inner();
            data.points[i] = (chain * joint.point).coords;
            chain *= joint_exponential(&joint.axis, &joint.point, fold_angles[i]);
            data.poses[i] = chain * plate.reference_pose;
        }
    }

    /// The plates' corners in the world frame (contact detection); needs the poses.
    pub fn update_corners(&self, data: &mut Data) {
        let mut index = 0;
        for (i, plate) in self.plates.iter().enumerate() {
            for corner in &plate.outline {
                data.corners[index] = data.poses[i] * corner;
                index += 1;
            }
        }
    }

    /// [`Model::update_poses`] plus the world inertias, a_ij and Iᵢ ω'_j that M and ∂M need.
    pub fn update_kinematics(&self, fold_angles: &[f64], data: &mut Data) {
        let n = self.dof();
        self.update_poses(fold_angles, data);
        for (i, plate) in self.plates.iter().enumerate() {
            let rotation = data.poses[i].rotation.to_rotation_matrix();
            let r = rotation.matrix();
            let inertia = r * plate.inertia * r.transpose();
            data.inertia_world[i] = inertia;
            let com = data.poses[i].translation.vector;
            for j in 0..n {
                let (a, iw) = if j <= i {
                    (data.axes[j].cross(&(com - data.points[j])), inertia * data.axes[j])
                } else {
                    (Vector3::zeros(), Vector3::zeros())
                };
                data.linear_jacobian[i * n + j] = a;
                data.inertia_axes[i * n + j] = iw;
            }
        }
    }

    /// M(θ) = Σᵢ Jᵢᵀ Φᵢ Jᵢ (T4.13), with Jᵢ the body Jacobian at plate i's centre of mass in
    /// world-aligned axes (the kinetic energy is frame-invariant, so M is the same).
    /// Needs [`Model::update_kinematics`] first.
    pub fn update_mass_matrix(&self, data: &mut Data) {
        let n = self.dof();
        data.mass_matrix.fill(0.0);
        for (i, plate) in self.plates.iter().enumerate() {
            for j in 0..=i {
                let a_j = data.linear_jacobian[i * n + j];
                let i_w_j = data.inertia_axes[i * n + j];
                for k in 0..=j {
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

    /// ∂M/∂θ_k in closed form: joint k rotates everything after it rigidly, so
    /// ∂ω'_j = ω'_k × ω'_j (k < j), ∂a_ij = ω'_k × a_ij (k < j) or ω'_j × (ω'_k × (p_i − q'_k))
    /// (j ≤ k ≤ i), ∂(R I Rᵀ) = [ω'_k]× I − I [ω'_k]× (k ≤ i). Entries with both j, l > k
    /// vanish (a rigid rotation leaves them unchanged).
    pub fn update_mass_matrix_derivative(&self, data: &mut Data) {
        let n = self.dof();
        for k in 0..n {
            let omega_k = data.axes[k];
            let point_k = data.points[k];
            let mut derivative = std::mem::replace(&mut data.mass_matrix_derivative[k], DMatrix::zeros(0, 0));
            derivative.fill(0.0);
            for i in k..n {
                let mass = self.plates[i].mass;
                let lever = data.poses[i].translation.vector - point_k;
                let row = i * n;
                for j in 0..=i {
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
                for j in 0..=i {
                    let a_j = data.linear_jacobian[row + j];
                    let da_j = data.scratch_linear[j];
                    let w_j = data.axes[j];
                    let dw_j = data.scratch_angular[j];
                    let iw_j = data.inertia_axes[row + j];
                    for l in 0..=j.min(k) {
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

    /// The Coriolis and centrifugal torques C(θ, θ̇) θ̇ in O(n²), for the right-hand side:
    /// Σᵢ J_vᵢᵀ mᵢ J̇_vᵢ θ̇ + J_ωᵢᵀ (Iᵢ J̇_ωᵢ θ̇ + ωᵢ × Iᵢ ωᵢ), the velocity-product part of each
    /// plate's Newton–Euler equations projected on the joints. It equals the Christoffel form
    /// of [`Model::update_coriolis`] times θ̇ (tested); it needs the kinematics and
    /// [`Model::update_velocities`] at the same θ̇.
    pub fn coriolis_torques(&self, fold_rates: &[f64], data: &mut Data, out: &mut [f64]) {
        let n = self.dof();
        // Ω_i: angular velocity of plate i; v_i: its centre-of-mass velocity.
        let mut spin = Vector3::zeros();
        for (i, rate) in fold_rates.iter().enumerate() {
            let previous_spin = spin;
            spin += data.axes[i] * *rate;
            // ω̇'_i = Ω_{i−1} × ω'_i; q̇'_i = velocity of the hinge point as a point of plate i − 1.
            data.scratch_angular[i] = previous_spin.cross(&data.axes[i]);
            data.scratch_linear[i] = if i == 0 {
                Vector3::zeros()
            } else {
                let com = data.poses[i - 1].translation.vector;
                data.velocities[i - 1] + previous_spin.cross(&(data.points[i] - com))
            };
        }
        out.iter_mut().for_each(|o| *o = 0.0);
        let mut spin = Vector3::zeros();
        for (i, plate) in self.plates.iter().enumerate() {
            spin += data.axes[i] * fold_rates[i];
            let com = data.poses[i].translation.vector;
            let velocity = data.velocities[i];
            let mut linear_bias = Vector3::zeros();
            let mut angular_bias = Vector3::zeros();
            for (j, rate) in fold_rates.iter().enumerate().take(i + 1) {
                let axis_rate = data.scratch_angular[j];
                // ȧ_ij = ω̇'_j × (p_i − q'_j) + ω'_j × (v_i − q̇'_j).
                let a_dot =
                    axis_rate.cross(&(com - data.points[j])) + data.axes[j].cross(&(velocity - data.scratch_linear[j]));
                linear_bias += a_dot * *rate;
                angular_bias += axis_rate * *rate;
            }
            let inertia = &data.inertia_world[i];
            let force = plate.mass * linear_bias;
            let moment = inertia * angular_bias + spin.cross(&(inertia * spin));
            for (j, o) in out.iter_mut().enumerate().take(i + 1) {
                *o += data.linear_jacobian[i * n + j].dot(&force) + data.axes[j].dot(&moment);
            }
        }
    }

    /// C(θ, θ̇) with C_ij = ½ Σ_k (∂M_ij/∂θ_k + ∂M_ik/∂θ_j − ∂M_kj/∂θ_i) θ̇_k (SPEC §7).
    /// Needs [`Model::update_mass_matrix_derivative`] first.
    pub fn update_coriolis(&self, fold_rates: &[f64], data: &mut Data) {
        let n = self.dof();
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

    /// Centre-of-mass velocities vᵢ = Σ_j a_ij θ̇_j, m/s, into `data.velocities` (needs kinematics).
    pub fn update_velocities(&self, fold_rates: &[f64], data: &mut Data) {
        let n = self.dof();
        for i in 0..n {
            data.velocities[i] = (0..=i).map(|j| data.linear_jacobian[i * n + j] * fold_rates[j]).sum();
        }
    }

    /// Generalised drag force Q_j = Σᵢ a_ijᵀ Fᵢ, N·m (T5.8); zero without drag. Its power
    /// Q·θ̇ = Σ Fᵢ·vᵢ = −½ C_D ρ A |v|²|v·n| is never positive. Needs [`Model::update_velocities`].
    pub fn drag_torques(&self, data: &Data, out: &mut [f64]) {
        out.iter_mut().for_each(|q| *q = 0.0);
        let Some(drag) = self.drag else { return };
        let n = self.dof();
        for (i, plate) in self.plates.iter().enumerate() {
            let velocity = data.velocities[i];
            let normal = data.poses[i].rotation * Vector3::z();
            let normal_speed = velocity.dot(&normal);
            if normal_speed == 0.0 {
                continue;
            }
            let magnitude = 0.5 * drag.drag_coefficient * drag.air_density * plate.area * velocity.norm_squared();
            let force = -magnitude * normal_speed.signum() * normal;
            for (j, q) in out.iter_mut().enumerate().take(i + 1) {
                *q += data.linear_jacobian[i * n + j].dot(&force);
            }
        }
    }

    /// Kinetic energy ½ θ̇ᵀ M θ̇, J (needs the mass matrix).
    pub fn kinetic_energy(&self, fold_rates: &[f64], data: &Data) -> f64 {
        let mut sum = 0.0;
        for (i, ri) in fold_rates.iter().enumerate() {
            for (j, rj) in fold_rates.iter().enumerate() {
                sum += data.mass_matrix[(i, j)] * ri * rj;
            }
        }
        0.5 * sum
    }

    /// θ̈ = M⁻¹ (τ − C θ̇ − K θ + Q_drag) (T4.12, T4.15), written into `accel`.
    /// Allocation-free: the factorisation reuses a buffer of `data`.
    pub fn accelerations(
        &self,
        fold_angles: &[f64],
        fold_rates: &[f64],
        torques: &[f64],
        data: &mut Data,
        accel: &mut [f64],
    ) -> Result<()> {
        let n = self.dof();
        self.update_kinematics(fold_angles, data);
        self.update_mass_matrix(data);
        self.update_velocities(fold_rates, data);
        let mut coriolis = std::mem::take(&mut data.coriolis_torques);
        self.coriolis_torques(fold_rates, data, &mut coriolis);
        let drag = &mut *accel;
        self.drag_torques(data, drag);
        for i in 0..n {
            drag[i] += torques[i] - coriolis[i] - self.joints[i].stiffness * fold_angles[i];
        }
        data.coriolis_torques = coriolis;
        let mut factor = std::mem::replace(&mut data.factor, DMatrix::zeros(0, 0));
        factor.copy_from(&data.mass_matrix);
        let cholesky = Cholesky::new(factor).ok_or_else(|| NanofoldError::Numerical {
            stage: "dynamics".into(),
            message: format!("mass matrix not positive definite at θ = {fold_angles:?}"),
        })?;
        cholesky.solve_mut(&mut DVectorViewMut::from_slice(accel, n));
        data.factor = cholesky.unpack_dirty();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    /// Two plates with non-parallel hinges, so every term of ∂M is exercised.
    pub(crate) fn skew_chain() -> Model {
        let plate = |centre: Vector3<f64>, rotation: Rotation3<f64>| Plate {
            mass: 2.0,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.3, 0.2, 0.45)),
            reference_pose: Isometry3::from_parts(Translation3::from(centre), rotation.into()),
            outline: [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
                .iter()
                .map(|&[x, y]| Point3::new(x, y, 0.0))
                .collect(),
            area: 1.0,
        };
        Model {
            joints: vec![
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
            ],
            plates: vec![
                plate(Vector3::new(0.0, 0.5, 0.0), Rotation3::identity()),
                plate(Vector3::new(0.1, 1.5, 0.0), Rotation3::from_euler_angles(0.1, 0.2, 0.3)),
                plate(
                    Vector3::new(0.3, 2.6, 0.2),
                    Rotation3::from_euler_angles(-0.2, 0.4, 0.1),
                ),
            ],
            drag: None,
        }
    }

    fn mass_matrix_at(model: &Model, data: &mut Data, angles: &[f64]) -> DMatrix<f64> {
        model.update_kinematics(angles, data);
        model.update_mass_matrix(data);
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
    fn mass_matrix_derivative_matches_central_differences() {
        let model = skew_chain();
        let mut data = Data::new(&model);
        let angles = [0.4, -0.7, 1.1];
        model.update_kinematics(&angles, &mut data);
        model.update_mass_matrix(&mut data);
        model.update_mass_matrix_derivative(&mut data);
        let h = 1e-5;
        for k in 0..3 {
            let mut plus = angles;
            let mut minus = angles;
            plus[k] += h;
            minus[k] -= h;
            let fd = (mass_matrix_at(&model, &mut data.clone(), &plus)
                - mass_matrix_at(&model, &mut data.clone(), &minus))
                / (2.0 * h);
            let error = (&fd - &data.mass_matrix_derivative[k]).amax();
            assert!(
                error < 1e-8,
                "∂M/∂θ_{k}: error {error:.2e}\n{fd}\n{}",
                data.mass_matrix_derivative[k]
            );
        }
    }

    fn kinetic_energy_at(model: &Model, angles: &[f64], rates: &[f64]) -> f64 {
        let mut data = Data::new(model);
        model.update_kinematics(angles, &mut data);
        model.update_mass_matrix(&mut data);
        model.kinetic_energy(rates, &data)
    }

    #[test]
    fn coriolis_christoffel_newton_euler_and_finite_differences_agree() {
        let model = skew_chain();
        let mut data = Data::new(&model);
        let angles = [0.3, 0.9, -0.6];
        let rates = [1.3, -0.4, 2.1];
        model.update_kinematics(&angles, &mut data);
        model.update_mass_matrix(&mut data);
        model.update_mass_matrix_derivative(&mut data);
        model.update_coriolis(&rates, &mut data);
        let christoffel = &data.coriolis * DVector::from_column_slice(&rates);
        let mut newton_euler = vec![0.0; 3];
        let mut moving = data.clone();
        model.update_velocities(&rates, &mut moving);
        model.coriolis_torques(&rates, &mut moving, &mut newton_euler);
        // Independent: C θ̇ = Ṁ θ̇ − ½ ∂(θ̇ᵀ M θ̇)/∂θ, both by central differences of M.
        let h = 1e-5;
        let theta_dot = DVector::from_column_slice(&rates);
        let mut along = [0.0; 3];
        let mut back = [0.0; 3];
        for k in 0..3 {
            along[k] = angles[k] + h * rates[k];
            back[k] = angles[k] - h * rates[k];
        }
        let m_dot = (mass_matrix_at(&model, &mut data.clone(), &along)
            - mass_matrix_at(&model, &mut data.clone(), &back))
            / (2.0 * h);
        let mut expected = &m_dot * &theta_dot;
        for k in 0..3 {
            let mut plus = angles;
            let mut minus = angles;
            plus[k] += h;
            minus[k] -= h;
            // ½ ∂(θ̇ᵀMθ̇)/∂θ_k = ∂T/∂θ_k.
            expected[k] -=
                (kinetic_energy_at(&model, &plus, &rates) - kinetic_energy_at(&model, &minus, &rates)) / (2.0 * h);
        }
        let scale = expected.amax();
        for i in 0..3 {
            assert!(
                (christoffel[i] - expected[i]).abs() < 1e-8 * scale,
                "Christoffel {christoffel} vs FD {expected}"
            );
            assert!(
                (newton_euler[i] - christoffel[i]).abs() < 1e-12 * scale,
                "Newton–Euler {newton_euler:?} vs {christoffel}"
            );
        }
        // Ṁ − 2C is skew-symmetric (passivity).
        let mut m_dot_exact = DMatrix::zeros(3, 3);
        for (derivative, rate) in data.mass_matrix_derivative.iter().zip(rates) {
            m_dot_exact += derivative * rate;
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
