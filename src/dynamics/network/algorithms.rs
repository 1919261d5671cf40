//! Rigid-body algorithms over a [`NetworkModel`] (`docs/model.md#panel-networks`), in world
//! Plücker coordinates at the origin: panel poses and hinge twists along the tree, the
//! composite-rigid-body mass matrix with the tree's sparsity, the recursive Newton–Euler bias
//! (Coriolis, centrifugal and drag), and each vertex star's closure rows and their velocity
//! product. Free functions filling a [`NetworkData`]; nothing is allocated per call.

use super::model::NetworkModel;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A spatial vector: a twist (ω, v at the origin) or a wrench (moment about the origin, force).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Spatial {
    /// Angular part (ω, or the moment).
    pub angular: Vector3<f64>,
    /// Linear part (the velocity of the point at the origin, or the force).
    pub linear: Vector3<f64>,
}

impl Spatial {
    /// The zero vector.
    pub fn zero() -> Spatial {
        Spatial::default()
    }

    /// Twist · wrench (power), or the pairing of a motion with a force.
    pub fn dot(&self, force: &Spatial) -> f64 {
        self.angular.dot(&force.angular) + self.linear.dot(&force.linear)
    }

    /// self + k · other.
    pub fn add_scaled(&self, other: &Spatial, k: f64) -> Spatial {
        Spatial {
            angular: self.angular + other.angular * k,
            linear: self.linear + other.linear * k,
        }
    }

    /// Motion cross product self ×ₘ other.
    pub fn cross_motion(&self, other: &Spatial) -> Spatial {
        Spatial {
            angular: self.angular.cross(&other.angular),
            linear: self.angular.cross(&other.linear) + self.linear.cross(&other.angular),
        }
    }

    /// Force cross product self ×* force.
    pub fn cross_force(&self, force: &Spatial) -> Spatial {
        Spatial {
            angular: self.angular.cross(&force.angular) + self.linear.cross(&force.linear),
            linear: self.angular.cross(&force.linear),
        }
    }

    /// Velocity of the body point at `p` for this twist.
    pub fn point_velocity(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.linear + self.angular.cross(p)
    }
}

/// A rigid body's spatial inertia at the origin: mass, first moment m c, and the rotational
/// inertia about the origin. Additive, so composites are sums.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SpatialInertia {
    /// kg.
    pub mass: f64,
    /// m c, kg·m.
    pub first_moment: Vector3<f64>,
    /// I_c − m \[c\]ₓ², kg·m².
    pub rotational: Matrix3<f64>,
}

impl SpatialInertia {
    /// The momentum (angular about the origin, linear) of a twist.
    pub fn apply(&self, twist: &Spatial) -> Spatial {
        Spatial {
            angular: self.rotational * twist.angular + self.first_moment.cross(&twist.linear),
            linear: twist.linear * self.mass - self.first_moment.cross(&twist.angular),
        }
    }

    /// Sum of two inertias.
    pub fn add(&self, other: &SpatialInertia) -> SpatialInertia {
        SpatialInertia {
            mass: self.mass + other.mass,
            first_moment: self.first_moment + other.first_moment,
            rotational: self.rotational + other.rotational,
        }
    }
}

/// Scratch of one [`NetworkModel`], filled by the algorithms.
#[derive(Debug, Clone)]
pub struct NetworkData {
    /// The drag law's switches at the last evaluation.
    pub drag_switches: crate::dynamics::model::DragSwitches,
    /// Panel rotations (flat → world).
    pub rotation: Vec<Matrix3<f64>>,
    /// Panel translations: a flat point x goes to R x + t.
    pub translation: Vec<Vector3<f64>>,
    /// World twist of every tree column's hinge (zero for the others).
    pub twist: Vec<Spatial>,
    /// Panel twists.
    pub velocity: Vec<Spatial>,
    /// Panel accelerations from the velocities alone (q̈ = 0).
    pub bias_acceleration: Vec<Spatial>,
    /// World spatial inertia of every panel.
    pub inertia: Vec<SpatialInertia>,
    /// Composite inertia of every panel's subtree.
    pub composite: Vec<SpatialInertia>,
    /// Subtree wrenches of the Newton–Euler pass.
    pub force: Vec<Spatial>,
    /// Drag wrench on every panel (at the origin).
    pub drag: Vec<Spatial>,
    /// M's entries in [`NetworkModel::mass_pattern`] order, kg·m².
    pub mass_values: Vec<f64>,
    /// C(ρ, ρ̇)ρ̇ − Q_drag per column (zero off the tree), N·m.
    pub bias: Vec<f64>,
    /// Every star's ray axes (node vectors) in its own frame, star after star.
    pub star_axes: Vec<Vector3<f64>>,
    /// Every star's velocity product Σ_{a before b} ρ̇_a ρ̇_b (x_a × x_b).
    pub star_bias: Vec<Vector3<f64>>,
    star_rates: Vec<f64>,
}

impl NetworkData {
    /// Buffers sized for `model`.
    pub fn new(model: &NetworkModel) -> NetworkData {
        let (np, nc) = (model.panels(), model.columns());
        let rays: usize = model.folding.stars.iter().map(|s| s.columns.len()).sum();
        NetworkData {
            drag_switches: crate::dynamics::model::DragSwitches::new(np),
            rotation: vec![Matrix3::identity(); np],
            translation: vec![Vector3::zeros(); np],
            twist: vec![Spatial::zero(); nc],
            velocity: vec![Spatial::zero(); np],
            bias_acceleration: vec![Spatial::zero(); np],
            inertia: vec![SpatialInertia::default(); np],
            composite: vec![SpatialInertia::default(); np],
            force: vec![Spatial::zero(); np],
            drag: vec![Spatial::zero(); np],
            mass_values: vec![0.0; model.mass_pattern.len()],
            bias: vec![0.0; nc],
            star_axes: vec![Vector3::zeros(); rays],
            star_bias: vec![Vector3::zeros(); model.folding.stars.len()],
            star_rates: Vec::new(),
        }
    }

    /// Where flat point `x` (m) of panel `p` is.
    pub fn place(&self, p: usize, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation[p] * x + self.translation[p]
    }
}

/// Panel poses along the tree: each panel is its parent's pose composed with the turn by its
/// fold angle about its crease line (`docs/model.md#panel-networks`); the anchored panel
/// stays flat. Also every tree hinge's world twist (ω, q × ω).
pub fn update_poses(model: &NetworkModel, fold_angles: &[f64], data: &mut NetworkData) {
    let root = model.anchored_panel;
    data.rotation[root] = Matrix3::identity();
    data.translation[root] = Vector3::zeros();
    for &p in &model.order[1..] {
        let (q, c) = (
            model.parent[p].expect("placed panels have parents"),
            model.parent_column[p].expect("and tree creases"),
        );
        let axis = model.joint_axis[c];
        let point = model.hinges[c].point;
        let turn = *Rotation3::from_axis_angle(&Unit::new_unchecked(axis), fold_angles[c]).matrix();
        let (rq, tq) = (data.rotation[q], data.translation[q]);
        data.rotation[p] = rq * turn;
        // R_q (point − turn·point) + t_q.
        data.translation[p] = rq * (point - turn * point) + tq;
        let omega = rq * axis;
        let through = rq * point + tq;
        data.twist[c] = Spatial {
            angular: omega,
            linear: through.cross(&omega),
        };
    }
}

/// Poses, twists and the world inertia of every panel.
pub fn update_kinematics(model: &NetworkModel, fold_angles: &[f64], data: &mut NetworkData) {
    update_poses(model, fold_angles, data);
    for (p, body) in model.bodies.iter().enumerate() {
        let r = data.rotation[p];
        let c = r * body.centre + data.translation[p];
        let about_centre = r * body.inertia * r.transpose();
        // Parallel axes: I_O = I_c + m (|c|² 1 − c cᵀ).
        let shift = (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * body.mass;
        data.inertia[p] = SpatialInertia {
            mass: body.mass,
            first_moment: c * body.mass,
            rotational: about_centre + shift,
        };
    }
}

/// Panel twists V_p = V_parent + s_c ρ̇_c and their velocity-product accelerations
/// A_p = A_parent + V_p ×ₘ s_c ρ̇_c (needs the kinematics).
pub fn update_velocities(model: &NetworkModel, fold_rates: &[f64], data: &mut NetworkData) {
    let root = model.anchored_panel;
    data.velocity[root] = Spatial::zero();
    data.bias_acceleration[root] = Spatial::zero();
    for &p in &model.order[1..] {
        let (q, c) = (
            model.parent[p].expect("parent"),
            model.parent_column[p].expect("column"),
        );
        let joint = Spatial {
            angular: data.twist[c].angular * fold_rates[c],
            linear: data.twist[c].linear * fold_rates[c],
        };
        let velocity = data.velocity[q].add_scaled(&joint, 1.0);
        let product = velocity.cross_motion(&joint);
        data.velocity[p] = velocity;
        data.bias_acceleration[p] = data.bias_acceleration[q].add_scaled(&product, 1.0);
    }
}

/// The drag wrench of every panel (the literal T5.8 law at its centre of mass,
/// `docs/model.md#drag`), zero without air; returns the drag power Σ F·v (never positive).
/// Needs the velocities.
pub fn update_drag(model: &NetworkModel, data: &mut NetworkData) -> f64 {
    let Some(drag) = model.drag else {
        data.drag.iter_mut().for_each(|f| *f = Spatial::zero());
        return 0.0;
    };
    let mut power = 0.0;
    for (p, body) in model.bodies.iter().enumerate() {
        let centre = data.rotation[p] * body.centre + data.translation[p];
        let v = data.velocity[p].point_velocity(&centre);
        let normal = data.rotation[p].column(2).into_owned();
        let sign = data.drag_switches.sign(p, v.dot(&normal));
        if sign == 0.0 {
            data.drag[p] = Spatial::zero();
            continue;
        }
        let magnitude = 0.5 * drag.drag_coefficient * drag.air_density * body.area * v.norm_squared();
        let force = -magnitude * sign * normal;
        power += force.dot(&v);
        data.drag[p] = Spatial {
            angular: centre.cross(&force),
            linear: force,
        };
    }
    power
}

/// The Newton–Euler bias per column: C(ρ, ρ̇)ρ̇ − Q_drag (tree columns; zero for the others).
/// Needs the kinematics, velocities and drag.
pub fn update_bias(model: &NetworkModel, data: &mut NetworkData) {
    for p in 0..model.panels() {
        let momentum = data.inertia[p].apply(&data.velocity[p]);
        let f = data.inertia[p]
            .apply(&data.bias_acceleration[p])
            .add_scaled(&data.velocity[p].cross_force(&momentum), 1.0)
            .add_scaled(&data.drag[p], -1.0);
        data.force[p] = f;
    }
    data.bias.iter_mut().for_each(|b| *b = 0.0);
    for &p in model.order[1..].iter().rev() {
        let (q, c) = (
            model.parent[p].expect("parent"),
            model.parent_column[p].expect("column"),
        );
        data.bias[c] = data.twist[c].dot(&data.force[p]);
        let subtree = data.force[p];
        data.force[q] = data.force[q].add_scaled(&subtree, 1.0);
    }
}

/// The mass matrix by composite rigid bodies: M[a, c] = s_a · (I^C_p s_c) for the tree
/// column c carrying panel p and every tree column a on p's path to the root, in
/// [`NetworkModel::mass_pattern`] order. Needs the kinematics.
pub fn update_mass_matrix(model: &NetworkModel, data: &mut NetworkData) {
    for p in 0..model.panels() {
        data.composite[p] = data.inertia[p];
    }
    for &p in model.order[1..].iter().rev() {
        let q = model.parent[p].expect("parent");
        let child = data.composite[p];
        data.composite[q] = data.composite[q].add(&child);
    }
    let mut k = 0;
    for &p in &model.order[1..] {
        let c = model.parent_column[p].expect("column");
        let force = data.composite[p].apply(&data.twist[c]);
        data.mass_values[k] = data.twist[c].dot(&force);
        k += 1;
        for a in model.path_columns(model.parent[p].expect("parent")) {
            data.mass_values[k] = data.twist[a].dot(&force);
            k += 1;
        }
    }
}

/// ½ ρ̇ᵀ M ρ̇ = ½ Σ_p V_p · I_p V_p, J (needs the velocities).
pub fn kinetic_energy(model: &NetworkModel, data: &NetworkData) -> f64 {
    (0..model.panels())
        .map(|p| 0.5 * data.velocity[p].dot(&data.inertia[p].apply(&data.velocity[p])))
        .sum()
}

/// Every star's ray axes x_k (its closure rows: Σ_k x_k ρ̇_k = 0, the holonomy's angular
/// velocity) and, for the rates given, its velocity product Σ_{a before b} ρ̇_a ρ̇_b (x_a × x_b)
/// with the rays in product order 1, 2, …, n−1, 0 (`docs/model.md#rigid-folding`).
pub fn update_stars(model: &NetworkModel, fold_angles: &[f64], fold_rates: Option<&[f64]>, data: &mut NetworkData) {
    let mut offset = 0;
    for (s, star) in model.folding.stars.iter().enumerate() {
        let n = star.columns.len();
        // The frame of ray k: T_1 = R_z(α_0), T_{k+1} = T_k R_x(ρ_k) R_z(α_k); x_k = T_k e_x,
        // x_0 = e_x (as `geometry::kinematics::forward`).
        data.star_axes[offset] = Vector3::x();
        let mut frame = Matrix3::identity();
        for k in 1..n {
            frame = if k == 1 {
                rot_z(star.sector_angles[0])
            } else {
                frame * rot_x(fold_angles[star.columns[k - 1]]) * rot_z(star.sector_angles[k - 1])
            };
            data.star_axes[offset + k] = frame.column(0).into_owned();
        }
        let mut product = Vector3::zeros();
        if let Some(rates) = fold_rates {
            data.star_rates.clear();
            data.star_rates.extend(star.columns.iter().map(|&c| rates[c]));
            let mut upstream = Vector3::zeros();
            for k in (1..n).chain([0]) {
                let axis_rate = data.star_axes[offset + k] * data.star_rates[k];
                product += upstream.cross(&axis_rate);
                upstream += axis_rate;
            }
        }
        data.star_bias[s] = product;
        offset += n;
    }
}

fn rot_x(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn rot_z(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::super::model::{NetworkModel, NetworkParts};
    use super::*;
    use crate::dynamics::forcing::{Actuation, Forcing, HingeDrive};
    use crate::folding::FoldingModel;
    use crate::pattern::generate::MiuraSpec;

    /// A folded 2 × 3 Miura-ori of 100 µm panels, anchored at panel `anchor`, with drag.
    pub(crate) fn miura(anchor: usize) -> (NetworkModel, Vec<f64>) {
        let spec = MiuraSpec {
            rows: 2,
            cols: 3,
            zigzag_fold_angle: 1.1,
            ..MiuraSpec::default()
        };
        let folding = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let state = folding.given_fold_angles();
        let n = folding.crease_count();
        let model = NetworkModel::new(NetworkParts {
            folding,
            unit: 1e-4,
            anchored_panel: anchor,
            thickness: 2e-7,
            density: 3270.0,
            stiffness: vec![1e-9; n],
            forcing: Forcing {
                actuation: Actuation::Step,
                hinges: vec![HingeDrive::PASSIVE; n],
            },
            drag: Some(crate::dynamics::model::Drag {
                drag_coefficient: 1.28,
                air_density: 1.2,
            }),
            start: state.clone(),
            substrate_contact: false,
        })
        .unwrap();
        (model, state)
    }

    /// Panel p's centre and rotation at `angles`.
    fn pose(model: &NetworkModel, angles: &[f64], p: usize) -> (Vector3<f64>, Matrix3<f64>) {
        let mut data = NetworkData::new(model);
        update_poses(model, angles, &mut data);
        (data.place(p, &model.bodies[p].centre), data.rotation[p])
    }

    /// Kinetic energy from panel velocities by central differences of the poses along ρ̇:
    /// ½ m |v_c|² + ½ ωᵀ I ω, with ω from (R(+h) − R(−h)) Rᵀ / 2h. Independent of the spatial
    /// algebra (no twists, no Plücker coordinates).
    fn kinetic_energy_by_differences(model: &NetworkModel, angles: &[f64], rates: &[f64]) -> f64 {
        let h = 1e-6;
        let along = |sign: f64| -> Vec<f64> { angles.iter().zip(rates).map(|(a, r)| a + sign * h * r).collect() };
        let (plus, minus) = (along(1.0), along(-1.0));
        (0..model.panels())
            .map(|p| {
                let (c1, r1) = pose(model, &plus, p);
                let (c0, r0) = pose(model, &minus, p);
                let (_, r) = pose(model, angles, p);
                let v = (c1 - c0) / (2.0 * h);
                let w = (r1 - r0) / (2.0 * h) * r.transpose();
                let omega = Vector3::new(w[(2, 1)] - w[(1, 2)], w[(0, 2)] - w[(2, 0)], w[(1, 0)] - w[(0, 1)]) * 0.5;
                let inertia = r * model.bodies[p].inertia * r.transpose();
                0.5 * model.bodies[p].mass * v.norm_squared() + 0.5 * omega.dot(&(inertia * omega))
            })
            .sum()
    }

    fn quadratic(model: &NetworkModel, data: &NetworkData, x: &[f64], y: &[f64]) -> f64 {
        model
            .mass_pattern
            .iter()
            .zip(&data.mass_values)
            .map(|(&(a, c), m)| {
                if a == c {
                    m * x[a] * y[c]
                } else {
                    m * (x[a] * y[c] + x[c] * y[a])
                }
            })
            .sum()
    }

    fn rates(n: usize) -> Vec<f64> {
        (0..n).map(|k| ((k * 7 + 3) % 11) as f64 / 5.0 - 1.0).collect()
    }

    #[test]
    fn mass_matrix_and_twists_give_the_kinetic_energy_of_the_moving_panels() {
        for anchor in [0, 3] {
            let (model, angles) = miura(anchor);
            let rates = rates(model.columns());
            let mut data = NetworkData::new(&model);
            update_kinematics(&model, &angles, &mut data);
            update_velocities(&model, &rates, &mut data);
            update_mass_matrix(&model, &mut data);
            let expected = kinetic_energy_by_differences(&model, &angles, &rates);
            let from_mass = 0.5 * quadratic(&model, &data, &rates, &rates);
            let from_twists = kinetic_energy(&model, &data);
            assert!(
                (from_mass - expected).abs() < 1e-8 * expected,
                "{from_mass} vs {expected}"
            );
            assert!((from_twists - from_mass).abs() < 1e-12 * expected);
        }
    }

    #[test]
    fn newton_euler_bias_matches_the_lagrangian_by_differences() {
        // C ρ̇ = Ṁ ρ̇ − ∂T/∂ρ, both by central differences of M; drag off here (no air in T).
        let (mut model, angles) = miura(2);
        model.drag = None;
        let n = model.columns();
        let rates = rates(n);
        let mut data = NetworkData::new(&model);
        update_kinematics(&model, &angles, &mut data);
        update_velocities(&model, &rates, &mut data);
        update_drag(&model, &mut data);
        update_bias(&model, &mut data);
        let h = 1e-6;
        let mass_times = |angles: &[f64], x: &[f64]| -> Vec<f64> {
            let mut d = NetworkData::new(&model);
            update_kinematics(&model, angles, &mut d);
            update_mass_matrix(&model, &mut d);
            (0..n)
                .map(|i| {
                    let mut e = vec![0.0; n];
                    e[i] = 1.0;
                    quadratic(&model, &d, &e, x)
                })
                .collect()
        };
        let shifted = |sign: f64| -> Vec<f64> { angles.iter().zip(&rates).map(|(a, r)| a + sign * h * r).collect() };
        let (mp, mm) = (mass_times(&shifted(1.0), &rates), mass_times(&shifted(-1.0), &rates));
        let scale = mp.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for k in 0..n {
            let mut plus = angles.clone();
            let mut minus = angles.clone();
            plus[k] += h;
            minus[k] -= h;
            let energy = |a: &[f64]| {
                let mut d = NetworkData::new(&model);
                update_kinematics(&model, a, &mut d);
                update_velocities(&model, &rates, &mut d);
                kinetic_energy(&model, &d)
            };
            let expected = (mp[k] - mm[k]) / (2.0 * h) - (energy(&plus) - energy(&minus)) / (2.0 * h);
            assert!(
                (data.bias[k] - expected).abs() < 1e-6 * scale,
                "column {k}: {} vs {expected} (scale {scale:e})",
                data.bias[k]
            );
        }
    }

    #[test]
    fn drag_power_is_the_force_on_each_centre_times_its_velocity() {
        let (model, angles) = miura(1);
        let rates = rates(model.columns());
        let mut data = NetworkData::new(&model);
        update_kinematics(&model, &angles, &mut data);
        update_velocities(&model, &rates, &mut data);
        let power = update_drag(&model, &mut data);
        let generalised: f64 = {
            let mut d = data.clone();
            update_bias(&model, &mut d);
            let mut without = data.clone();
            without.drag.iter_mut().for_each(|f| *f = Spatial::zero());
            update_bias(&model, &mut without);
            // bias = Cρ̇ − Q_drag: the difference is −Q_drag, and Q_drag·ρ̇ is the power.
            (0..model.columns())
                .map(|c| (without.bias[c] - d.bias[c]) * rates[c])
                .sum()
        };
        assert!(power < 0.0);
        assert!(
            (generalised - power).abs() < 1e-10 * power.abs(),
            "{generalised} vs {power}"
        );
    }
}
