//! A solid's flat net as a crease pattern (`docs/model.md#nets-of-polyhedra`): laid with its
//! inside up, so every convex fold is a valley, its target the turn between the two faces'
//! outward normals; each cut edge a pair of boundary edges (a seam) that must meet again.

use super::crease_pattern::{CreasePattern, CreasePatternBuilder, EdgeKind};
use super::Assignment;
use crate::error::{NanofoldError, Result};
use crate::geometry::nets::FlatNet;
use crate::geometry::polyhedron::{DualEdge, Polyhedron};
use std::collections::HashMap;

/// A net's crease pattern and what ties it back to its solid.
#[derive(Debug, Clone)]
pub struct NetPattern {
    /// The flat sheet: faces in the solid's order, folds as creases (or facet edges between
    /// faces in one plane), the cut boundary; its `target_angles` fold it onto the solid.
    pub pattern: CreasePattern,
    /// Each seam: the pattern's two boundary edges that are one edge of the solid.
    pub seams: Vec<[usize; 2]>,
    /// The solid's vertex each pattern vertex is a copy of.
    pub solid_vertex: Vec<usize>,
    /// The pattern's face at the centre of the net's tree (fewest folds to the farthest
    /// face; the lowest index among equals): the face to anchor.
    pub centre_face: usize,
}

/// The face of the tree of folds `folds` (pairs of faces) from which the farthest face is
/// fewest folds away.
fn centre_of_tree(faces: usize, folds: &[[usize; 2]]) -> usize {
    let mut neighbours = vec![Vec::new(); faces];
    for &[a, b] in folds {
        neighbours[a].push(b);
        neighbours[b].push(a);
    }
    let eccentricity = |start: usize| {
        let mut depth = vec![usize::MAX; faces];
        depth[start] = 0;
        let mut queue = std::collections::VecDeque::from([start]);
        let mut farthest = 0;
        while let Some(f) = queue.pop_front() {
            farthest = farthest.max(depth[f]);
            for &g in &neighbours[f] {
                if depth[g] == usize::MAX {
                    depth[g] = depth[f] + 1;
                    queue.push_back(g);
                }
            }
        }
        farthest
    };
    (0..faces).min_by_key(|&f| (eccentricity(f), f)).unwrap_or(0)
}

/// Union–find over the faces' corners.
fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The fold angle that takes face `b` to its place beside face `a` on the solid, seen with
/// the inside up: the turn between their outward normals, positive where the edge is convex.
fn fold_angle(solid: &Polyhedron, a: usize, b: usize) -> f64 {
    let (na, nb) = (solid.face_normal(a).normalize(), solid.face_normal(b).normalize());
    let turn = na.cross(&nb).norm().atan2(na.dot(&nb));
    let towards_b = solid.face_centroid(b) - solid.face_centroid(a);
    if towards_b.dot(&na) > 0.0 {
        -turn
    } else {
        turn
    }
}

/// Two copies of solid vertices at one place: the net touches itself there (at a point, or
/// along a seam whose two sides lie on each other), which a crease pattern cannot hold.
fn touching_copies(vertices: &[[f64; 2]], solid_vertex: &[usize]) -> Result<()> {
    let size = vertices.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    let tolerance = 1e-9 * size.max(f64::MIN_POSITIVE);
    let mut order: Vec<usize> = (0..vertices.len()).collect();
    order.sort_by(|&a, &b| vertices[a][0].total_cmp(&vertices[b][0]));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if vertices[b][0] - vertices[a][0] > tolerance {
                break;
            }
            if (vertices[b][1] - vertices[a][1]).abs() <= tolerance {
                return Err(NanofoldError::invalid(
                    "net",
                    format!("copies of the solid's vertices {} and {} at one point", solid_vertex[a], solid_vertex[b]),
                    "the net touches itself there (a point, or a seam whose sides lie on each other): no crease pattern holds it",
                ));
            }
        }
    }
    Ok(())
}

/// The number of face `f`'s corner at solid vertex `v`, `offsets` each face's first.
fn corner_number(solid: &Polyhedron, offsets: &[usize], f: usize, v: usize) -> usize {
    offsets[f]
        + solid.faces[f]
            .iter()
            .position(|&w| w == v)
            .expect("the edge's vertex is on its face")
}

/// The sheet's vertices: the faces' corners joined across the folds (union–find), each
/// class one vertex, placed mirrored (x → −x) so the inside is up. Returns each face's
/// first corner's number, each corner's vertex, the vertices and their solid vertices.
#[allow(clippy::type_complexity)]
fn sheet_vertices(
    solid: &Polyhedron,
    net: &FlatNet,
    edges: &[DualEdge],
) -> (Vec<usize>, Vec<usize>, Vec<[f64; 2]>, Vec<usize>) {
    // Corners as (face, position in the face), numbered by their face's offset.
    let offsets: Vec<usize> = solid
        .faces
        .iter()
        .scan(0, |total, face| {
            let start = *total;
            *total += face.len();
            Some(start)
        })
        .collect();
    let corner_count: usize = solid.faces.iter().map(Vec::len).sum();
    let corner = |f: usize, v: usize| corner_number(solid, &offsets, f, v);
    let mut parent: Vec<usize> = (0..corner_count).collect();
    for &k in &net.folds {
        let e = &edges[k];
        for v in e.vertices {
            let (a, b) = (
                root(&mut parent, corner(e.faces[0], v)),
                root(&mut parent, corner(e.faces[1], v)),
            );
            parent[a] = b;
        }
    }
    // Each class of corners is one vertex of the sheet, mirrored (x → −x) so the inside is up.
    let mut vertex_of_root: HashMap<usize, usize> = HashMap::new();
    let mut vertices: Vec<[f64; 2]> = Vec::new();
    let mut solid_vertex = Vec::new();
    let mut vertex_of_corner = vec![0; corner_count];
    for (f, face) in solid.faces.iter().enumerate() {
        for (i, &v) in face.iter().enumerate() {
            let r = root(&mut parent, offsets[f] + i);
            let index = *vertex_of_root.entry(r).or_insert_with(|| {
                let p = net.faces[f][i];
                vertices.push([-p.x, p.y]);
                solid_vertex.push(v);
                vertices.len() - 1
            });
            vertex_of_corner[offsets[f] + i] = index;
        }
    }
    (offsets, vertex_of_corner, vertices, solid_vertex)
}

/// `net` of `solid` as a crease pattern named `name`; a net that touches itself is refused.
pub fn net_pattern(solid: &Polyhedron, net: &FlatNet, name: &str) -> Result<NetPattern> {
    let edges = solid.dual_edges();
    let (offsets, vertex_of_corner, vertices, solid_vertex) = sheet_vertices(solid, net, &edges);
    let corner = |f: usize, v: usize| corner_number(solid, &offsets, f, v);
    touching_copies(&vertices, &solid_vertex)?;
    // Faces reversed by the mirror, so counter-clockwise again.
    let faces: Vec<Vec<usize>> = solid
        .faces
        .iter()
        .enumerate()
        .map(|(f, face)| {
            (0..face.len())
                .rev()
                .map(|i| vertex_of_corner[offsets[f] + i])
                .collect()
        })
        .collect();
    let mut edge_vertices: Vec<[usize; 2]> = Vec::new();
    let mut kinds = Vec::new();
    let mut targets = Vec::new();
    let mut index_of: HashMap<[usize; 2], usize> = HashMap::new();
    let mut add = |pair: [usize; 2], kind: EdgeKind, target: f64| -> usize {
        let key = [pair[0].min(pair[1]), pair[0].max(pair[1])];
        *index_of.entry(key).or_insert_with(|| {
            edge_vertices.push(pair);
            kinds.push(kind);
            targets.push(target);
            edge_vertices.len() - 1
        })
    };
    let mut seams = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let side = |f: usize| {
            [
                vertex_of_corner[corner(f, e.vertices[0])],
                vertex_of_corner[corner(f, e.vertices[1])],
            ]
        };
        if net.folds.contains(&k) {
            let rho = fold_angle(solid, e.faces[0], e.faces[1]);
            let kind = if rho.abs() < 1e-12 {
                EdgeKind::Facet
            } else if rho > 0.0 {
                EdgeKind::Crease(Assignment::Valley)
            } else {
                EdgeKind::Crease(Assignment::Mountain)
            };
            add(side(e.faces[0]), kind, if rho.abs() < 1e-12 { 0.0 } else { rho });
        } else {
            let pair = [
                add(side(e.faces[0]), EdgeKind::Boundary, 0.0),
                add(side(e.faces[1]), EdgeKind::Boundary, 0.0),
            ];
            if pair[0] == pair[1] {
                return Err(NanofoldError::invalid(
                    format!("seam {k}"),
                    format!("edge {}–{}", e.vertices[0], e.vertices[1]),
                    "both sides of a cut landed on one edge of the net",
                ));
            }
            seams.push(pair);
        }
    }
    let edge_count = edge_vertices.len();
    let pattern = CreasePatternBuilder {
        name: name.to_string(),
        vertices,
        edges: edge_vertices,
        kinds,
        fold_angles: vec![0.0; edge_count],
        faces: Some(faces),
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    }
    .with_reading(
        "a net of a solid: its fold angles are the targets that close it".into(),
        Some(targets),
    )
    .build()?;
    let fold_faces: Vec<[usize; 2]> = net.folds.iter().map(|&k| edges[k].faces).collect();
    let centre = centre_of_tree(solid.faces.len(), &fold_faces);
    let centre_face = pattern.file_face.iter().position(|&f| f == centre).unwrap_or(0);
    Ok(NetPattern {
        pattern,
        seams,
        solid_vertex,
        centre_face,
    })
}

/// Seams named on a sheet of panels (a scene's `seams`): each a pair of the paper's
/// boundary edges that meet once folded, and which pattern vertices they make one point.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamGluing {
    /// Each seam's two edges (pattern edge indices).
    pub edges: Vec<[usize; 2]>,
    /// Each pattern vertex's point once every seam is shut (numbered from 0; a vertex on
    /// no seam is a point of its own).
    pub point: Vec<usize>,
}

/// Two edges of one seam may differ in length by this share of their length (plus the
/// file's own precision): a file written at six significant digits.
const SEAM_LENGTH_MATCH: f64 = 1e-6;

impl SeamGluing {
    /// The seams `edges` (FOLD edge indices) of `pattern`, validated: each pair two
    /// different boundary edges of different faces, of one length, every edge in one seam
    /// at most. The ends meet as the surface closes without turning over: walked with its
    /// face (counter-clockwise), one edge's start meets the other's end.
    pub fn new(pattern: &CreasePattern, edges: &[[usize; 2]]) -> Result<SeamGluing> {
        let field = |k: usize| format!("seams[{k}]");
        let mut used = vec![None; pattern.edges.len()];
        let mut parent: Vec<usize> = (0..pattern.vertices.len()).collect();
        fn root(parent: &mut [usize], mut v: usize) -> usize {
            while parent[v] != v {
                parent[v] = parent[parent[v]];
                v = parent[v];
            }
            v
        }
        for (k, &[e, f]) in edges.iter().enumerate() {
            if e == f {
                return Err(NanofoldError::invalid(
                    field(k),
                    format!("[{e}, {f}]"),
                    "a seam joins two different edges",
                ));
            }
            for edge in [e, f] {
                if edge >= pattern.edges.len() {
                    return Err(NanofoldError::invalid(
                        field(k),
                        format!("[{e}, {f}]"),
                        format!("the pattern has edges 0 to {}", pattern.edges.len() - 1),
                    ));
                }
                if pattern.kinds[edge] != EdgeKind::Boundary {
                    return Err(NanofoldError::invalid(
                        field(k),
                        format!("[{e}, {f}]"),
                        format!("edge {edge} is not on the paper's boundary (a seam joins two cut edges)"),
                    ));
                }
                if let Some(other) = used[edge] {
                    return Err(NanofoldError::invalid(
                        field(k),
                        format!("[{e}, {f}]"),
                        format!("edge {edge} is already in seams[{other}]"),
                    ));
                }
                used[edge] = Some(k);
            }
            // Each edge as its face walks it: (start, end, face).
            let walked = |edge: usize| {
                let [a, b] = pattern.edges[edge];
                match pattern.edge_faces[edge] {
                    [Some(face), _] => (a, b, face),
                    [None, Some(face)] => (b, a, face),
                    [None, None] => (a, b, usize::MAX),
                }
            };
            let ((a0, a1, face_e), (b0, b1, face_f)) = (walked(e), walked(f));
            if face_e == usize::MAX || face_f == usize::MAX {
                return Err(NanofoldError::invalid(
                    field(k),
                    format!("[{e}, {f}]"),
                    "a seam's edges bound a face",
                ));
            }
            if pattern.panel_of_face[face_e] == pattern.panel_of_face[face_f] {
                return Err(NanofoldError::invalid(
                    field(k),
                    format!("[{e}, {f}]"),
                    "both edges bound one panel: a seam joins two panels",
                ));
            }
            let length = |[p, q]: [usize; 2]| {
                let (x, y) = (pattern.vertices[p], pattern.vertices[q]);
                (x[0] - y[0]).hypot(x[1] - y[1])
            };
            let (le, lf) = (length(pattern.edges[e]), length(pattern.edges[f]));
            if (le - lf).abs() > SEAM_LENGTH_MATCH * le.max(lf) + pattern.length_precision {
                return Err(NanofoldError::invalid(
                    field(k),
                    format!("[{e}, {f}]: lengths {le} and {lf}"),
                    format!(
                        "a seam's edges meet end to end, so their lengths agree to {SEAM_LENGTH_MATCH:e} of the length"
                    ),
                ));
            }
            for (v, w) in [(a0, b1), (a1, b0)] {
                let (rv, rw) = (root(&mut parent, v), root(&mut parent, w));
                parent[rv] = rw;
            }
        }
        let mut number = vec![usize::MAX; parent.len()];
        let mut point = vec![0; parent.len()];
        let mut next = 0;
        for (v, place) in point.iter_mut().enumerate() {
            let r = root(&mut parent, v);
            if number[r] == usize::MAX {
                number[r] = next;
                next += 1;
            }
            *place = number[r];
        }
        Ok(SeamGluing {
            edges: edges.to_vec(),
            point,
        })
    }
}
