//! Panel poses from fold angles (`docs/model.md#rigid-folding`): the root panel stays in
//! the plane; each other panel is its tree parent's pose composed with the rotation by its
//! crease's fold angle about the crease line.

use super::model::FoldingModel;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A rigid placement of a panel: a flat point (x, y) goes to R (x, y, 0) + t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation.
    pub rotation: Matrix3<f64>,
    /// Translation.
    pub translation: Vector3<f64>,
}

impl Pose {
    /// The identity placement (the flat sheet).
    pub fn identity() -> Pose {
        Pose {
            rotation: Matrix3::identity(),
            translation: Vector3::zeros(),
        }
    }

    /// Where a flat point goes.
    pub fn place(&self, point: [f64; 2]) -> Vector3<f64> {
        self.rotation * Vector3::new(point[0], point[1], 0.0) + self.translation
    }
}

/// The placement, relative to the panel on one side, of the panel on the other side of the
/// crease from `a` to `b` folded by `fold_angle`. A valley (positive) fold lifts the far
/// panel towards +z: the panel on the left turns by +ρ about a → b, the one on the right by −ρ.
fn hinge(a: [f64; 2], b: [f64; 2], fold_angle: f64, panel_on_left: bool) -> Pose {
    let axis = Unit::new_normalize(Vector3::new(b[0] - a[0], b[1] - a[1], 0.0));
    let angle = if panel_on_left { fold_angle } else { -fold_angle };
    let rotation = Rotation3::from_axis_angle(&axis, angle).into_inner();
    let pivot = Vector3::new(a[0], a[1], 0.0);
    Pose {
        rotation,
        translation: pivot - rotation * pivot,
    }
}

fn compose(outer: &Pose, inner: &Pose) -> Pose {
    Pose {
        rotation: outer.rotation * inner.rotation,
        translation: outer.rotation * inner.translation + outer.translation,
    }
}

/// Every panel's pose at `fold_angles` (one per crease), the root panel fixed.
pub fn panel_poses(model: &FoldingModel, fold_angles: &[f64], poses: &mut Vec<Pose>) {
    poses.clear();
    poses.resize(model.pattern.panel_count, Pose::identity());
    for step in &model.tree {
        let [a, b] = model.pattern.edges[step.edge];
        let relative = hinge(
            model.pattern.vertices[a],
            model.pattern.vertices[b],
            fold_angles[step.column],
            step.panel_on_left,
        );
        poses[step.panel] = compose(&poses[step.parent], &relative);
    }
}

/// The largest disagreement, as a length, over the creases left out of the tree: where the
/// panel on one side puts the other side's vertices against where the tree put them. Zero
/// (to rounding) when every vertex closes.
pub fn tree_mismatch(model: &FoldingModel, fold_angles: &[f64], poses: &[Pose]) -> f64 {
    let pattern = &model.pattern;
    let mut worst: f64 = 0.0;
    for &e in &model.off_tree {
        let [Some(left), Some(right)] = pattern.edge_faces[e] else {
            continue;
        };
        let (pl, pr) = (pattern.panel_of_face[left], pattern.panel_of_face[right]);
        let [a, b] = pattern.edges[e];
        let column = model.column_of_edge[e].expect("off-tree edges are creases");
        let predicted = compose(
            &poses[pl],
            &hinge(pattern.vertices[a], pattern.vertices[b], fold_angles[column], false),
        );
        for &v in &model.panel_vertices[pr] {
            let p = pattern.vertices[v];
            worst = worst.max((predicted.place(p) - poses[pr].place(p)).norm());
        }
    }
    worst
}

/// 3D position of every vertex (each from one panel that holds it).
pub fn vertex_positions(model: &FoldingModel, poses: &[Pose]) -> Vec<[f64; 3]> {
    model
        .pattern
        .vertices
        .iter()
        .zip(&model.panel_of_vertex)
        .map(|(&p, &panel)| {
            let x = poses[panel].place(p);
            [x[0], x[1], x[2]]
        })
        .collect()
}
