//! The nearest rigid folded form to a noisy one, in vertex positions
//! (`docs/model.md#folded-forms`): every face planar, every facet edge flat and every
//! interior vertex developable (its corner angles sum to 2π), by least-norm Newton steps.

use crate::error::{NumericalError, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::Side;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::f64::consts::PI;

type V3 = Vector3<f64>;

/// A folded form moved onto the rigid ones.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidForm {
    /// The moved positions (every vertex of the input, in its order).
    pub coords: Vec<[f64; 3]>,
    /// Largest distance any vertex moved, in the input's length unit.
    pub max_move: f64,
    /// Worst constraint before: an angle defect or a flatness or planarity in rad.
    pub residual_before: f64,
    /// Worst constraint after, rad.
    pub residual_after: f64,
    /// Newton iterations.
    pub iterations: usize,
}

/// One scalar condition on a few vertices.
enum Condition {
    /// The corner angles at `vertex` over its faces' corners (previous, next) sum to 2π.
    Developable { vertex: usize, corners: Vec<[usize; 2]> },
    /// The corner angles at `vertex`, in order round it and summed between creases, sum
    /// alternately to 0 (Kawasaki): `corners` in order, `sign` +1 or −1 for each.
    FlatFoldable {
        vertex: usize,
        corners: Vec<[usize; 2]>,
        signs: Vec<f64>,
    },
    /// Four points in one plane: the triple product of b−a, c−a, d−a over `scale`.
    Coplanar { points: [usize; 4], scale: f64 },
}

/// Most Newton iterations.
const ITERATIONS: usize = 50;

/// Moves `coords` (a folded form of `faces`, counter-clockwise vertex loops, with `flat_edges`
/// its facet edges) to the nearest form whose faces are planar, whose facet edges are flat
/// and whose interior vertices develop, to `tol` rad. Least-norm steps move the vertices as
/// little as each linearisation allows. An error where Newton does not converge.
pub fn rigidify(coords: &[[f64; 3]], faces: &[Vec<usize>], flat_edges: &[[usize; 2]], tol: f64) -> Result<RigidForm> {
    let points: Vec<V3> = coords.iter().map(|p| V3::new(p[0], p[1], p[2])).collect();
    let conditions = conditions(&points, faces, flat_edges);
    let unknowns = 3 * points.len();
    let mut x: Vec<V3> = points.clone();
    let mut residual = vec![0.0; conditions.len()];
    let mut gradients: Vec<Vec<(usize, V3)>> = vec![Vec::new(); conditions.len()];
    let mut residual_before = None;
    for iteration in 0..=ITERATIONS {
        for (k, condition) in conditions.iter().enumerate() {
            gradients[k].clear();
            residual[k] = condition.value_and_gradient(&x, &mut gradients[k]);
        }
        let worst = residual.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        if !worst.is_finite() {
            break;
        }
        let before = *residual_before.get_or_insert(worst);
        if worst <= tol {
            let max_move = x.iter().zip(&points).map(|(a, b)| (a - b).norm()).fold(0.0, f64::max);
            return Ok(RigidForm {
                coords: x.iter().map(|p| [p.x, p.y, p.z]).collect(),
                max_move,
                residual_before: before,
                residual_after: worst,
                iterations: iteration,
            });
        }
        if iteration == ITERATIONS {
            break;
        }
        let step = least_norm_step(&gradients, &residual, unknowns)?;
        for (v, p) in x.iter_mut().enumerate() {
            *p -= V3::new(step[3 * v], step[3 * v + 1], step[3 * v + 2]);
        }
    }
    Err(NumericalError::ClosureNotConverged {
        residual: residual.iter().fold(0.0_f64, |m, r| m.max(r.abs())),
        iterations: ITERATIONS,
    }
    .into())
}

/// The least-norm solution of J s = r: s = Jᵀ (JJᵀ + μI)⁻¹ r.
fn least_norm_step(gradients: &[Vec<(usize, V3)>], residual: &[f64], unknowns: usize) -> Result<Vec<f64>> {
    let rows = gradients.len();
    // JJᵀ by the vertices the rows share.
    let mut by_vertex: HashMap<usize, Vec<(usize, V3)>> = HashMap::new();
    for (k, row) in gradients.iter().enumerate() {
        for &(v, g) in row {
            by_vertex.entry(v).or_default().push((k, g));
        }
    }
    let mut products: HashMap<(usize, usize), f64> = HashMap::new();
    for entries in by_vertex.values() {
        for &(a, ga) in entries {
            for &(b, gb) in entries {
                if a >= b {
                    *products.entry((a, b)).or_default() += ga.dot(&gb);
                }
            }
        }
    }
    let largest = (0..rows)
        .filter_map(|k| products.get(&(k, k)))
        .fold(1e-300_f64, |m, &d| m.max(d));
    for k in 0..rows {
        *products.entry((k, k)).or_default() += 1e-14 * largest;
    }
    let triplets: Vec<Triplet<usize, usize, f64>> = products
        .iter()
        .map(|(&(a, b), &value)| Triplet::new(a, b, value))
        .collect();
    let singular = |detail: String| NumericalError::Singular {
        what: "the folded form's conditions JJᵀ",
        detail,
    };
    let matrix = SparseColMat::try_new_from_triplets(rows, rows, &triplets).map_err(|e| singular(format!("{e:?}")))?;
    let factor = Llt::try_new_with_symbolic(
        faer::sparse::linalg::solvers::SymbolicLlt::try_new(matrix.symbolic(), Side::Lower)
            .map_err(|e| singular(format!("{e:?}")))?,
        matrix.as_ref(),
        Side::Lower,
    )
    .map_err(|e| singular(format!("{e:?}")))?;
    let mut y = residual.to_vec();
    factor.solve_in_place(faer::ColMut::from_slice_mut(&mut y).as_mat_mut());
    let mut step = vec![0.0; unknowns];
    for (k, row) in gradients.iter().enumerate() {
        for &(v, g) in row {
            for i in 0..3 {
                step[3 * v + i] += g[i] * y[k];
            }
        }
    }
    Ok(step)
}

/// The conditions of a rigid form of these faces, scaled by the input's own lengths.
fn conditions(points: &[V3], faces: &[Vec<usize>], flat_edges: &[[usize; 2]]) -> Vec<Condition> {
    let mut conditions = Vec::new();
    // Faces through each directed edge, and each vertex's corners.
    let mut face_of: HashMap<(usize, usize), usize> = HashMap::new();
    let mut corners: HashMap<usize, Vec<[usize; 2]>> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        let k = face.len();
        for i in 0..k {
            face_of.insert((face[i], face[(i + 1) % k]), f);
            corners
                .entry(face[i])
                .or_default()
                .push([face[(i + k - 1) % k], face[(i + 1) % k]]);
        }
    }
    // Interior: every edge at the vertex has a face on both sides.
    let mut vertices: Vec<usize> = corners.keys().copied().collect();
    vertices.sort_unstable();
    for v in vertices {
        let list = &corners[&v];
        let interior = list
            .iter()
            .all(|&[_, next]| face_of.contains_key(&(next, v)) && face_of.contains_key(&(v, next)));
        if interior {
            conditions.push(Condition::Developable {
                vertex: v,
                corners: list.clone(),
            });
            if let Some(kawasaki) = flat_foldable_by_design(v, list, points, flat_edges) {
                conditions.push(kawasaki);
            }
        }
    }
    // Planar faces: every corner beyond the face's widest triangle in its plane.
    for face in faces.iter().filter(|f| f.len() >= 4) {
        let a = face[0];
        let b = *face
            .iter()
            .max_by(|&&p, &&q| {
                (points[p] - points[a])
                    .norm()
                    .total_cmp(&(points[q] - points[a]).norm())
            })
            .expect("a face has corners");
        let c = *face
            .iter()
            .max_by(|&&p, &&q| {
                let area = |r: usize| (points[b] - points[a]).cross(&(points[r] - points[a])).norm();
                area(p).total_cmp(&area(q))
            })
            .expect("a face has corners");
        for &d in face.iter().filter(|&&d| d != a && d != b && d != c) {
            conditions.push(coplanar([a, b, c, d], points));
        }
    }
    // Flat facet edges: the two faces' farthest corners in one plane with the edge.
    for &[a, b] in flat_edges {
        let (Some(&left), Some(&right)) = (face_of.get(&(a, b)), face_of.get(&(b, a))) else {
            continue;
        };
        let farthest = |f: usize| {
            faces[f].iter().copied().filter(|&p| p != a && p != b).max_by(|&p, &q| {
                let off = |r: usize| (points[b] - points[a]).cross(&(points[r] - points[a])).norm();
                off(p).total_cmp(&off(q))
            })
        };
        if let (Some(c), Some(d)) = (farthest(left), farthest(right)) {
            conditions.push(coplanar([a, b, c, d], points));
        }
    }
    conditions
}

/// A vertex's alternating angle sum is within this of 0 in the file, rad: flat-foldable by
/// design (its mechanism depends on it: a Miura-ori's quads fold only while every vertex is),
/// so the move keeps it so.
pub const FLAT_FOLDABLE_NOISE: f64 = 1e-4;

/// Kawasaki's condition at an interior vertex of even crease degree whose file angles meet
/// it within [`FLAT_FOLDABLE_NOISE`].
fn flat_foldable_by_design(
    vertex: usize,
    corners: &[[usize; 2]],
    points: &[V3],
    flat_edges: &[[usize; 2]],
) -> Option<Condition> {
    // Corners in order round the vertex: the next corner starts where this one ends.
    let mut ordered = vec![corners[0]];
    while ordered.len() < corners.len() {
        let end = ordered.last()?[1];
        ordered.push(*corners.iter().find(|c| c[0] == end)?);
    }
    if ordered.last()?[1] != ordered[0][0] {
        return None;
    }
    let is_flat = |w: usize| {
        flat_edges
            .iter()
            .any(|e| (e[0] == vertex && e[1] == w) || (e[1] == vertex && e[0] == w))
    };
    // A crease at the start of a corner flips the sign; a facet edge does not.
    let start = ordered.iter().position(|c| !is_flat(c[0]))?;
    ordered.rotate_left(start);
    let mut sign = -1.0;
    let mut signs = Vec::with_capacity(ordered.len());
    for c in &ordered {
        if !is_flat(c[0]) {
            sign = -sign;
        }
        signs.push(sign);
    }
    let creases = ordered.iter().filter(|c| !is_flat(c[0])).count();
    if creases % 2 != 0 || creases < 4 {
        return None;
    }
    let condition = Condition::FlatFoldable {
        vertex,
        corners: ordered,
        signs,
    };
    let value = condition.value_and_gradient(points, &mut Vec::new());
    (value.abs() <= FLAT_FOLDABLE_NOISE).then_some(condition)
}

fn coplanar(points_of: [usize; 4], points: &[V3]) -> Condition {
    let [a, b, c, d] = points_of.map(|i| points[i]);
    let scale = (b - a).norm() * (c - a).norm() * (d - a).norm();
    Condition::Coplanar {
        points: points_of,
        scale: if scale > 0.0 { scale } else { 1.0 },
    }
}

impl Condition {
    /// The condition's value (0 when it holds, rad) and its gradient by vertex.
    fn value_and_gradient(&self, x: &[V3], gradient: &mut Vec<(usize, V3)>) -> f64 {
        match self {
            Condition::Developable { vertex, corners } => angle_sum(x, *vertex, corners, None, gradient) - 2.0 * PI,
            Condition::FlatFoldable { vertex, corners, signs } => angle_sum(x, *vertex, corners, Some(signs), gradient),
            Condition::Coplanar { points, scale } => {
                let [a, b, c, d] = *points;
                let (u, w, z) = (x[b] - x[a], x[c] - x[a], x[d] - x[a]);
                let (gb, gc, gd) = (w.cross(&z) / *scale, z.cross(&u) / *scale, u.cross(&w) / *scale);
                gradient.push((a, -(gb + gc + gd)));
                gradient.push((b, gb));
                gradient.push((c, gc));
                gradient.push((d, gd));
                u.cross(&w).dot(&z) / scale
            }
        }
    }
}

/// Σ s_k θ_k over the corner angles θ_k at `vertex` (s_k = 1 without `signs`), and its
/// gradient by vertex.
fn angle_sum(
    x: &[V3],
    vertex: usize,
    corners: &[[usize; 2]],
    signs: Option<&[f64]>,
    gradient: &mut Vec<(usize, V3)>,
) -> f64 {
    let centre = x[vertex];
    let mut sum = 0.0;
    let mut at_centre = V3::zeros();
    for (k, &[previous, next]) in corners.iter().enumerate() {
        let s = signs.map_or(1.0, |signs| signs[k]);
        let (p, r) = (x[previous] - centre, x[next] - centre);
        let cross = p.cross(&r);
        let sine = cross.norm();
        sum += s * sine.atan2(p.dot(&r));
        if sine > 0.0 {
            // dθ/dp = −(r̂ − (p̂·r̂) p̂) / (|p| sin θ), and likewise for r.
            let (pn, rn) = (p.norm(), r.norm());
            let (u, w) = (p / pn, r / rn);
            let cosine = u.dot(&w);
            let sin_theta = sine / (pn * rn);
            let dp = -(w - cosine * u) / (pn * sin_theta);
            let dr = -(u - cosine * w) / (rn * sin_theta);
            gradient.push((previous, s * dp));
            gradient.push((next, s * dr));
            at_centre -= s * (dp + dr);
        }
    }
    gradient.push((vertex, at_centre));
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of two triangles folded 60° about its diagonal, plus a flat square beside it.
    fn folded_square() -> (Vec<[f64; 3]>, Vec<Vec<usize>>) {
        let half = (60.0_f64.to_radians() / 2.0).cos();
        let coords = vec![
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0 - half, half, 0.5],
            [half, 1.0 - half, 0.5],
        ];
        (coords, vec![vec![0, 1, 2], vec![1, 0, 3]])
    }

    #[test]
    fn gradients_match_central_differences() {
        let points: Vec<V3> = [
            [0.0, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [1.1, 1.0, 0.2],
            [0.0, 1.0, -0.1],
            [-1.0, 0.2, 0.1],
            [0.1, -1.0, 0.05],
        ]
        .iter()
        .map(|p| V3::new(p[0], p[1], p[2]))
        .collect();
        let conditions = [
            Condition::Developable {
                vertex: 0,
                corners: vec![[5, 1], [1, 2], [2, 3], [3, 4], [4, 5]],
            },
            coplanar([0, 1, 2, 3], &points),
            Condition::FlatFoldable {
                vertex: 0,
                corners: vec![[5, 1], [1, 2], [2, 3], [3, 4], [4, 5]],
                signs: vec![1.0, -1.0, 1.0, -1.0, -1.0],
            },
        ];
        for condition in &conditions {
            let mut gradient = Vec::new();
            condition.value_and_gradient(&points, &mut gradient);
            for v in 0..points.len() {
                let analytic: V3 = gradient.iter().filter(|g| g.0 == v).map(|g| g.1).sum();
                for i in 0..3 {
                    let h = 1e-6;
                    let mut plus = points.clone();
                    plus[v][i] += h;
                    let mut minus = points.clone();
                    minus[v][i] -= h;
                    let fd = (condition.value_and_gradient(&plus, &mut Vec::new())
                        - condition.value_and_gradient(&minus, &mut Vec::new()))
                        / (2.0 * h);
                    assert!(
                        (fd - analytic[i]).abs() < 1e-8,
                        "vertex {v} axis {i}: {fd} against {}",
                        analytic[i]
                    );
                }
            }
        }
    }

    #[test]
    fn a_rigid_form_does_not_move_and_a_bent_facet_is_flattened() {
        let (coords, faces) = folded_square();
        let form = rigidify(&coords, &faces, &[], 1e-13).unwrap();
        assert_eq!(form.iterations, 0);
        assert_eq!(form.max_move, 0.0);
        // The diagonal as a facet edge: the nearest flat form lies between the two halves.
        let flat = rigidify(&coords, &faces, &[[0, 1]], 1e-13).unwrap();
        let points: Vec<V3> = flat.coords.iter().map(|p| V3::new(p[0], p[1], p[2])).collect();
        let normal = (points[1] - points[0]).cross(&(points[2] - points[0]));
        assert!(((points[3] - points[0]).dot(&normal) / normal.norm()).abs() < 1e-12);
        assert!(flat.max_move > 0.1);
    }
}
