//! Barriers the unfolding must not cross (`docs/model.md#crossings`): a node passing
//! through a sector's arc, charges touching, the clearance between nodes and arcs; and the
//! flatness measures of a state.

use super::model::UnfoldModel;
use crate::geometry::sphere::{distance_to_arc, geodesic, projects_onto_arc, side_of_arc, Vec3};
use nalgebra::{Matrix3, SymmetricEigen};

/// Largest distance a node moved (chord, radians to first order).
pub(crate) fn largest_move(before: &[Vec3], after: &[Vec3]) -> f64 {
    before
        .iter()
        .zip(after)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

/// Smallest geodesic distance from a node to an arc it is not an end of.
pub fn node_arc_clearance(model: &UnfoldModel, nodes: &[Vec3]) -> f64 {
    let mut clearance = f64::INFINITY;
    for arc in &model.arcs {
        for (v, node) in nodes.iter().enumerate() {
            if v != arc.a && v != arc.b {
                clearance = clearance.min(distance_to_arc(&nodes[arc.a], &nodes[arc.b], node));
            }
        }
    }
    clearance
}

/// Does the straight-line motion from `before` to `after` carry a node through an arc
/// (a sector through another)? Returns the first (arc, node) found.
pub fn find_crossing(model: &UnfoldModel, before: &[Vec3], after: &[Vec3]) -> Option<(usize, usize)> {
    for (e, arc) in model.arcs.iter().enumerate() {
        for v in 0..model.node_count {
            if v == arc.a || v == arc.b {
                continue;
            }
            let s0 = side_of_arc(&before[arc.a], &before[arc.b], &before[v]);
            let s1 = side_of_arc(&after[arc.a], &after[arc.b], &after[v]);
            if (s0 > 0.0 && s1 > 0.0) || (s0 < 0.0 && s1 < 0.0) || (s0 == 0.0 && s1 == 0.0) {
                continue;
            }
            let f = if s0 == s1 { 0.0 } else { s0 / (s0 - s1) };
            let lerp = |i: usize| before[i] + f * (after[i] - before[i]);
            if projects_onto_arc(&lerp(arc.a), &lerp(arc.b), &lerp(v)) {
                return Some((e, v));
            }
        }
    }
    None
}

/// Distance of the nodes from their best-fit plane through the vertex.
pub fn planarity_residual(nodes: &[Vec3]) -> f64 {
    let scatter: Matrix3<f64> = nodes.iter().map(|x| x * x.transpose()).sum();
    let eigen = SymmetricEigen::new(scatter);
    let (index, _) = eigen.eigenvalues.argmin();
    let normal = eigen.eigenvectors.column(index).into_owned();
    nodes.iter().map(|x| normal.dot(x).abs()).fold(0.0, f64::max)
}

/// Does a node touch an arc it is not on (γ(v,a) + γ(v,b) − α below 1e-9 rad)? This is
/// the flat-folded case of coincident charges, where rounding may leave the energy finite
/// but astronomically large.
pub fn touching_charges(model: &UnfoldModel, nodes: &[Vec3]) -> bool {
    model.arcs.iter().any(|arc| {
        (0..model.node_count)
            .filter(|&v| v != arc.a && v != arc.b)
            .any(|v| geodesic(&nodes[v], &nodes[arc.a]) + geodesic(&nodes[v], &nodes[arc.b]) - arc.length < 1e-9)
    })
}
