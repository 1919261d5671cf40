//! Folded forms (`docs/model.md#folded-forms`): a FOLD frame with 3D vertices, as Origami
//! Simulator exports, turned into its crease pattern (the faces developed into the plane,
//! lengths and face angles kept) and its state (fold angles from signed dihedral angles).
//! Only geometry: what is rigid is for `folding` to say.

use crate::error::{NanofoldError, Result};
use nalgebra::Vector3;
use std::collections::{HashMap, VecDeque};

/// The crease pattern and state developed from a folded form.
#[derive(Debug, Clone)]
pub struct Development {
    /// Flat positions of the vertices.
    pub vertices: Vec<[f64; 2]>,
    /// Signed dihedral angle at every edge, rad (valley positive; 0 on the sheet's edge).
    pub fold_angles: Vec<f64>,
    /// Largest distance between two placements of one vertex by different faces: zero for
    /// a developable form (a compliant simulator's state need not be).
    pub development_error: f64,
    /// Largest distance of a vertex from its face's plane (faces of more than 3 vertices).
    pub face_nonplanarity: f64,
}

type V3 = Vector3<f64>;

/// A face's unit normal (Newell's method) and an in-plane frame (e1, e2 = n × e1), found
/// on the corners relative to the first and divided by their spread, so that neither the
/// face's size (1e-88 across: its products would underflow) nor its place matters.
fn face_frame(corners: &[V3]) -> Option<(V3, V3, V3)> {
    let spread = corners.iter().map(|p| (p - corners[0]).amax()).fold(0.0, f64::max);
    if !(spread > 0.0 && spread.is_finite()) {
        return None;
    }
    let points: Vec<V3> = corners.iter().map(|p| (p - corners[0]) / spread).collect();
    let mut normal = V3::zeros();
    for k in 0..points.len() {
        let (p, q) = (points[k], points[(k + 1) % points.len()]);
        normal += V3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    let n = normal.try_normalize(0.0)?;
    let e1 = (points[1] - points[0]).try_normalize(0.0)?;
    let e1 = (e1 - n * n.dot(&e1)).try_normalize(0.0)?;
    Some((n, e1, n.cross(&e1)))
}

/// Develops the faces of a folded form: breadth-first over faces through shared edges,
/// each face laid in the plane by its own in-plane frame, then turned and moved so that the
/// edge it shares with its already placed neighbour lands where that one put it.
pub fn develop(coords: &[[f64; 3]], edges: &[[usize; 2]], faces: &[Vec<usize>]) -> Result<Development> {
    let points: Vec<V3> = coords.iter().map(|p| V3::new(p[0], p[1], p[2])).collect();
    let mut frames = Vec::with_capacity(faces.len());
    let mut face_nonplanarity: f64 = 0.0;
    for (f, face) in faces.iter().enumerate() {
        let corners: Vec<V3> = face.iter().map(|&v| points[v]).collect();
        let Some(frame) = face_frame(&corners) else {
            return Err(NanofoldError::invalid(
                format!("faces_vertices[{f}]"),
                format!("{face:?}"),
                "the face has no area in 3D (its vertices are collinear or coincide)",
            ));
        };
        for c in &corners {
            face_nonplanarity = face_nonplanarity.max(frame.0.dot(&(c - corners[0])).abs());
        }
        frames.push(frame);
    }
    // Directed edge (u, v) → the face that has it in its vertex order.
    let mut owner: HashMap<(usize, usize), usize> = HashMap::with_capacity(3 * faces.len());
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            owner.insert((face[k], face[(k + 1) % face.len()]), f);
        }
    }
    let local = |f: usize, v: usize| {
        let (_, e1, e2) = frames[f];
        let d = points[v] - points[faces[f][0]];
        [d.dot(&e1), d.dot(&e2)]
    };
    let mut placed: Vec<Option<[f64; 2]>> = vec![None; coords.len()];
    let mut done = vec![false; faces.len()];
    let mut development_error: f64 = 0.0;
    for root in 0..faces.len() {
        if done[root] {
            continue;
        }
        if root > 0 {
            return Err(NanofoldError::invalid(
                "faces_vertices",
                format!("face {root}"),
                "the faces do not form one connected sheet",
            ));
        }
        done[root] = true;
        for &v in &faces[root] {
            placed[v] = Some(local(root, v));
        }
        let mut queue = VecDeque::from([root]);
        while let Some(f) = queue.pop_front() {
            let face = &faces[f];
            for k in 0..face.len() {
                let (u, v) = (face[k], face[(k + 1) % face.len()]);
                let Some(&g) = owner.get(&(v, u)) else { continue };
                if done[g] {
                    continue;
                }
                done[g] = true;
                // Rigid motion of g's local frame taking (u, v) onto their placements.
                let (pu, pv) = (placed[u].expect("placed with f"), placed[v].expect("placed with f"));
                let (lu, lv) = (local(g, u), local(g, v));
                let angle = (pv[1] - pu[1]).atan2(pv[0] - pu[0]) - (lv[1] - lu[1]).atan2(lv[0] - lu[0]);
                let (c, s) = (angle.cos(), angle.sin());
                let map = |p: [f64; 2]| {
                    let (x, y) = (p[0] - lu[0], p[1] - lu[1]);
                    [pu[0] + c * x - s * y, pu[1] + s * x + c * y]
                };
                for &w in &faces[g] {
                    let q = map(local(g, w));
                    match placed[w] {
                        None => placed[w] = Some(q),
                        Some(p) => development_error = development_error.max((p[0] - q[0]).hypot(p[1] - q[1])),
                    }
                }
                queue.push_back(g);
            }
        }
    }
    let Some(vertices) = placed.into_iter().collect::<Option<Vec<[f64; 2]>>>() else {
        return Err(NanofoldError::invalid(
            "faces_vertices",
            "a vertex in no face",
            "a folded form is developed from its faces: every vertex must be in one",
        ));
    };
    // Signed dihedral angle: for the edge a → b with face L on its left (a, b in L's
    // order), ρ = atan2(−(n_L × n_R)·u, n_L·n_R), u the unit vector a → b in 3D; a valley
    // turns R towards L's normal side.
    let mut fold_angles = vec![0.0; edges.len()];
    for (e, &[a, b]) in edges.iter().enumerate() {
        let (left, right) = match (owner.get(&(a, b)), owner.get(&(b, a))) {
            (Some(&l), Some(&r)) => (l, r),
            _ => continue,
        };
        let (nl, nr) = (frames[left].0, frames[right].0);
        let Some(u) = (points[b] - points[a]).try_normalize(0.0) else {
            continue;
        };
        fold_angles[e] = (-(nl.cross(&nr)).dot(&u)).atan2(nl.dot(&nr));
    }
    Ok(Development {
        vertices,
        fold_angles,
        development_error,
        face_nonplanarity,
    })
}
