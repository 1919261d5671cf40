//! The immutable description of a set of rigid plates on revolute hinges ([`Model`]: joints,
//! plates, the kinematic tree, drag) and the scratch buffers its algorithms fill ([`Data`]).
//! SI units throughout (m, kg, s, N·m/rad).

use crate::error::{NanofoldError, Result};
use nalgebra::{DMatrix, Isometry3, Matrix3, Point3, Unit, Vector3};

/// A revolute hinge in the flat reference configuration: the twist ξ = (−ω × q, ω)
/// (`docs/model.md#kinematics`).
#[derive(Debug, Clone)]
pub struct Joint {
    /// Unit axis ω (a positive angle folds valley: right-handed about ω).
    pub axis: Unit<Vector3<f64>>,
    /// A point q on the axis, m.
    pub point: Point3<f64>,
    /// Hinge stiffness K_ii, N·m/rad (`docs/model.md#hinge-stiffness`).
    pub stiffness: f64,
}

/// A rigid thin plate, carried by the joint of the same index.
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
    /// Structural thickness, m (drawn plates, exported meshes).
    pub thickness: f64,
}

impl Plate {
    /// A uniform lamina of the given thickness (m) and density (kg/m³) whose mid-plane is the
    /// convex polygon `outline` (m, counter-clockwise in the flat xy-plane at θ = 0). Its body
    /// frame sits at the centroid with the world's axes, so body z is the normal. The inertia is
    /// the thin-box tensor: in-plane second moments of the polygon plus m t²/12 about the
    /// in-plane axes (for a rectangle exactly the box moments of
    /// `docs/model.md#plates`).
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
            thickness,
        }
    }

    /// Largest distance of the outline from the centre of mass, m.
    pub fn radius(&self) -> f64 {
        self.outline.iter().map(|p| p.coords.norm()).fold(0.0, f64::max)
    }

    /// Whether a body-frame point (z ignored) lies inside the outline or within `tolerance` of it.
    pub fn contains(&self, local: &Point3<f64>, tolerance: f64) -> bool {
        convex_contains(&self.outline, local, tolerance)
    }
}

/// Whether p (z ignored) lies in the convex counter-clockwise polygon `outline`, or within
/// `tolerance` of it (a negative tolerance asks for p strictly inside by that margin).
pub fn convex_contains(outline: &[Point3<f64>], p: &Point3<f64>, tolerance: f64) -> bool {
    let count = outline.len();
    (0..count).all(|k| {
        let (a, b) = (outline[k], outline[(k + 1) % count]);
        let edge = b - a;
        // Signed distance to the left of the edge (inside for a counter-clockwise polygon).
        (edge.x * (p.y - a.y) - edge.y * (p.x - a.x)) / edge.x.hypot(edge.y) >= -tolerance
    })
}

/// Quadratic drag on each plate (`docs/model.md#drag`, the literal
/// reading): F = −½ C_D ρ A |v|² sgn(v·n) n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drag {
    /// C_D (1.28 for a flat plate).
    pub drag_coefficient: f64,
    /// Air density, kg/m³.
    pub air_density: f64,
}

/// Where the drag law switches (`docs/model.md#drag`): its force on a plate points against
/// the sign of the plate's normal speed, which is discontinuous where that speed crosses
/// zero. The speeds at the last evaluation are kept, and a sensitivity computation may hold
/// the signs fixed while it differences the right-hand side (`docs/model.md#calibration`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DragSwitches {
    /// Each plate's normal speed at the last evaluation, m/s.
    pub normal_speeds: Vec<f64>,
    /// Signs held instead of the speeds' own while `frozen`.
    signs: Vec<f64>,
    frozen: bool,
}

impl DragSwitches {
    /// Buffers for `plates` plates.
    pub fn new(plates: usize) -> Self {
        DragSwitches {
            normal_speeds: vec![0.0; plates],
            signs: vec![0.0; plates],
            frozen: false,
        }
    }

    /// Holds the signs at `signs` (one per plate; 0 leaves that plate's own) until called
    /// with None.
    pub fn freeze(&mut self, signs: Option<&[f64]>) {
        self.frozen = signs.is_some();
        if let Some(signs) = signs {
            self.signs.copy_from_slice(signs);
        }
    }

    /// Records plate p's normal speed and returns the sign its drag acts against (0: none).
    pub fn sign(&mut self, plate: usize, normal_speed: f64) -> f64 {
        self.normal_speeds[plate] = normal_speed;
        if self.frozen && self.signs[plate] != 0.0 {
            self.signs[plate]
        } else if normal_speed == 0.0 {
            0.0
        } else {
            normal_speed.signum()
        }
    }
}

/// Immutable description of plates on hinges forming a kinematic tree: joint i carries plate
/// i and hangs from plate `parent(i)` (or from the fixed ground). Parents come before their
/// children, so a serial chain is the tree whose joint i hangs from plate i − 1.
#[derive(Debug, Clone)]
pub struct Model {
    joints: Vec<Joint>,
    plates: Vec<Plate>,
    parents: Vec<Option<usize>>,
    /// The joints that move plate i, root first (its path to the ground).
    support: Vec<Vec<usize>>,
    /// Whether joint j moves plate i, row-major i·n + j.
    moves: Vec<bool>,
    drag: Option<Drag>,
}

impl Model {
    /// A serial chain: joint 0 hangs from the ground, joint i from plate i − 1.
    pub fn chain(joints: Vec<Joint>, plates: Vec<Plate>, drag: Option<Drag>) -> Result<Model> {
        let parents = (0..joints.len()).map(|i| i.checked_sub(1)).collect();
        Model::tree(joints, plates, parents, drag)
    }

    /// A kinematic tree; `parents[i]` is the plate joint i hangs from (None: the ground),
    /// and must come before i.
    pub fn tree(
        joints: Vec<Joint>,
        plates: Vec<Plate>,
        parents: Vec<Option<usize>>,
        drag: Option<Drag>,
    ) -> Result<Model> {
        let n = joints.len();
        if plates.len() != n || parents.len() != n {
            return Err(NanofoldError::invalid(
                "plates",
                format!("{} plates, {} parents", plates.len(), parents.len()),
                format!("a model needs one plate and one parent per joint ({n})"),
            ));
        }
        if let Some(i) = (0..n).find(|&i| parents[i].is_some_and(|p| p >= i)) {
            return Err(NanofoldError::invalid(
                format!("parents[{i}]"),
                format!("{:?}", parents[i]),
                "a joint must hang from an earlier plate (or the ground)",
            ));
        }
        let mut support: Vec<Vec<usize>> = Vec::with_capacity(n);
        for (i, parent) in parents.iter().enumerate() {
            let mut path = parent.map_or_else(Vec::new, |p| support[p].clone());
            path.push(i);
            support.push(path);
        }
        let mut moves = vec![false; n * n];
        for (i, path) in support.iter().enumerate() {
            for &j in path {
                moves[i * n + j] = true;
            }
        }
        Ok(Model {
            joints,
            plates,
            parents,
            support,
            moves,
            drag,
        })
    }

    /// Degrees of freedom: one per hinge.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The hinges, in order.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The plates; plate i is carried by joint i.
    pub fn plates(&self) -> &[Plate] {
        &self.plates
    }

    /// The plate joint i hangs from (None: the ground).
    pub fn parent(&self, joint: usize) -> Option<usize> {
        self.parents[joint]
    }

    /// The joints that move plate i, root first.
    pub fn support(&self, plate: usize) -> &[usize] {
        &self.support[plate]
    }

    /// Whether joint j moves plate i.
    pub fn moves(&self, plate: usize, joint: usize) -> bool {
        self.moves[plate * self.dof() + joint]
    }

    /// The drag law, if the air is modelled.
    pub fn drag(&self) -> Option<Drag> {
        self.drag
    }

    /// Index of plate `plate`'s corner `corner` in [`Data::corners`].
    pub fn corner_index(&self, plate: usize, corner: usize) -> usize {
        self.plates[..plate].iter().map(|p| p.outline.len()).sum::<usize>() + corner
    }

    /// Diagonal hinge stiffness K, N·m/rad.
    pub fn stiffness(&self) -> nalgebra::DVector<f64> {
        nalgebra::DVector::from_iterator(self.dof(), self.joints.iter().map(|j| j.stiffness))
    }
}

/// Scratch buffers for one [`Model`]: current joint axes and points, plate poses, M, ∂M/∂θ.
/// Made once; the algorithms of [`crate::dynamics::algorithms`] fill it without allocating.
#[derive(Debug, Clone)]
pub struct Data {
    /// ω'_j: joint axes at the current configuration.
    pub axes: Vec<Vector3<f64>>,
    /// q'_j: points on the joint axes at the current configuration, m.
    pub points: Vec<Vector3<f64>>,
    /// The product of exponentials up to and including joint i.
    pub joint_frames: Vec<Isometry3<f64>>,
    /// g_i(θ): plate centre-of-mass frames.
    pub poses: Vec<Isometry3<f64>>,
    /// Rᵢ I_body Rᵢᵀ: world-frame inertia tensors at the centres of mass.
    pub inertia_world: Vec<Matrix3<f64>>,
    /// Plate outline corners in the world frame, plate after plate ([`Model::corner_index`]).
    pub corners: Vec<Point3<f64>>,
    /// Iᵢ ω'_j (row-major i·n + j; zero where joint j does not move plate i).
    pub inertia_axes: Vec<Vector3<f64>>,
    /// Centre-of-mass velocities, m/s.
    pub velocities: Vec<Vector3<f64>>,
    /// Angular velocities of the plates, rad/s.
    pub spins: Vec<Vector3<f64>>,
    /// a_ij = ω'_j × (p_i − q'_j): centre-of-mass velocity per unit θ̇_j (row-major i·n + j).
    pub linear_jacobian: Vec<Vector3<f64>>,
    /// M(θ).
    pub mass_matrix: DMatrix<f64>,
    /// ∂M/∂θ_k, one matrix per k.
    pub mass_matrix_derivative: Vec<DMatrix<f64>>,
    /// C(θ, θ̇) by Christoffel symbols.
    pub coriolis: DMatrix<f64>,
    /// C(θ, θ̇) θ̇.
    pub coriolis_torques: Vec<f64>,
    pub(crate) factor: DMatrix<f64>,
    pub(crate) scratch_linear: Vec<Vector3<f64>>,
    pub(crate) scratch_angular: Vec<Vector3<f64>>,
    /// The drag law's switches at the last evaluation.
    pub drag_switches: DragSwitches,
}

impl Data {
    /// Buffers sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.dof();
        Data {
            axes: vec![Vector3::zeros(); n],
            points: vec![Vector3::zeros(); n],
            joint_frames: vec![Isometry3::identity(); n],
            poses: vec![Isometry3::identity(); n],
            inertia_world: vec![Matrix3::zeros(); n],
            corners: vec![Point3::origin(); model.plates.iter().map(|p| p.outline.len()).sum()],
            inertia_axes: vec![Vector3::zeros(); n * n],
            velocities: vec![Vector3::zeros(); n],
            spins: vec![Vector3::zeros(); n],
            linear_jacobian: vec![Vector3::zeros(); n * n],
            mass_matrix: DMatrix::zeros(n, n),
            mass_matrix_derivative: vec![DMatrix::zeros(n, n); n],
            coriolis: DMatrix::zeros(n, n),
            coriolis_torques: vec![0.0; n],
            factor: DMatrix::zeros(n, n),
            scratch_linear: vec![Vector3::zeros(); n],
            scratch_angular: vec![Vector3::zeros(); n],
            drag_switches: DragSwitches::new(model.plates.len()),
        }
    }
}
