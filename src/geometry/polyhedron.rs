//! Closed polyhedral surfaces, the solids a net is designed for (`docs/model.md#nets-of-polyhedra`):
//! validation (closed, manifold, consistently and outwardly wound, planar faces), the
//! generated solids, the face-adjacency (dual) graph, its number of spanning trees (the edge
//! unfoldings) and the solid's symmetry group found from its geometry.

use super::surface_intersection::{first_self_intersection, newell_normal};
use crate::error::{NanofoldError, Result};
use nalgebra::{DMatrix, Matrix3, Point3, Vector3};
use std::collections::HashMap;

/// Most vertices of a solid (the convex hull of a generated solid is found by brute force,
/// O(V⁴), and the symmetry search checks every vertex for every candidate).
pub const MAX_VERTICES: usize = 4_096;
/// Faces of a generated prism, antiprism or pyramid: 3 to this many sides.
pub const MAX_SIDES: usize = 64;

/// A closed polyhedral surface: faces wound counter-clockwise seen from outside.
#[derive(Debug, Clone, PartialEq)]
pub struct Polyhedron {
    /// Vertex positions.
    pub vertices: Vec<Point3<f64>>,
    /// Each face's vertices, counter-clockwise seen from outside.
    pub faces: Vec<Vec<usize>>,
}

/// An edge of the face-adjacency graph: two faces and the surface edge they share.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DualEdge {
    /// The two faces, the first the one that runs the edge from `vertices[0]` to `vertices[1]`.
    pub faces: [usize; 2],
    /// The shared surface edge.
    pub vertices: [usize; 2],
}

/// An isometry mapping the solid onto itself, about its vertices' centroid.
#[derive(Debug, Clone, PartialEq)]
pub struct Symmetry {
    /// The orthogonal map (a rotation, or a reflection when its determinant is −1).
    pub matrix: Matrix3<f64>,
    /// Where each vertex goes.
    pub vertex_map: Vec<usize>,
    /// Where each face goes.
    pub face_map: Vec<usize>,
}

impl Symmetry {
    /// Whether it is a rotation (determinant +1) rather than a reflection.
    pub fn is_rotation(&self) -> bool {
        self.matrix.determinant() > 0.0
    }
}

impl Polyhedron {
    /// A validated closed surface: every face of at least three distinct vertices, every
    /// edge in exactly two faces that run it in opposite directions (closed, manifold,
    /// consistently wound), faces planar to 1e-9 of the solid's size, wound outwards
    /// (positive volume), and all of one piece. Errors name the face or edge and the value.
    pub fn new(vertices: Vec<Point3<f64>>, faces: Vec<Vec<usize>>) -> Result<Polyhedron> {
        if vertices.len() < 4 || vertices.len() > MAX_VERTICES {
            return Err(NanofoldError::invalid(
                "vertices",
                vertices.len(),
                format!("a solid has 4 to {MAX_VERTICES} vertices"),
            ));
        }
        if let Some(k) = vertices.iter().position(|p| !p.coords.iter().all(|x| x.is_finite())) {
            return Err(NanofoldError::invalid(
                format!("vertices[{k}]"),
                format!("{:?}", vertices[k].coords.as_slice()),
                "coordinates must be finite",
            ));
        }
        if faces.len() < 4 {
            return Err(NanofoldError::invalid(
                "faces",
                faces.len(),
                "a closed solid has at least 4 faces",
            ));
        }
        let solid = Polyhedron { vertices, faces };
        solid.check_faces()?;
        solid.check_edges()?;
        solid.check_pinched()?;
        solid.check_planar()?;
        let volume = solid.volume();
        if volume <= 0.0 {
            return Err(NanofoldError::invalid(
                "faces",
                format!("volume {volume:e}"),
                "faces must be wound counter-clockwise seen from outside (this solid is inside out)",
            ));
        }
        if !solid.connected() {
            return Err(NanofoldError::invalid(
                "faces",
                "two or more separate surfaces",
                "a solid is one closed surface",
            ));
        }
        if let Some((f, g)) = first_self_intersection(&solid.vertices, &solid.faces, 1e-9 * solid.size()) {
            return Err(NanofoldError::invalid(
                format!("faces[{f}]"),
                format!("meets faces[{g}]"),
                "the surface passes through itself (faces may meet only along their shared edges and corners)",
            ));
        }
        Ok(solid)
    }

    fn check_faces(&self) -> Result<()> {
        for (f, face) in self.faces.iter().enumerate() {
            let field = || format!("faces[{f}]");
            if face.len() < 3 {
                return Err(NanofoldError::invalid(
                    field(),
                    format!("{face:?}"),
                    "a face has at least 3 vertices",
                ));
            }
            if let Some(&v) = face.iter().find(|&&v| v >= self.vertices.len()) {
                return Err(NanofoldError::invalid(
                    field(),
                    format!("{face:?}"),
                    format!("vertex {v} does not exist (there are {})", self.vertices.len()),
                ));
            }
            let mut sorted = face.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return Err(NanofoldError::invalid(field(), format!("{face:?}"), "a vertex repeats"));
            }
        }
        Ok(())
    }

    /// Every directed edge once, its reverse once.
    fn check_edges(&self) -> Result<()> {
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                let edge = (face[k], face[(k + 1) % face.len()]);
                if let Some(other) = directed.insert(edge, f) {
                    return Err(NanofoldError::invalid(
                        format!("faces[{f}]"),
                        format!("edge {}–{}", edge.0, edge.1),
                        format!("face {other} runs this edge the same way: the faces are not consistently wound (or the edge has more than two faces)"),
                    ));
                }
            }
        }
        for (&(a, b), &f) in &directed {
            if !directed.contains_key(&(b, a)) {
                return Err(NanofoldError::invalid(
                    format!("faces[{f}]"),
                    format!("edge {a}–{b}"),
                    "no other face has this edge: the surface is not closed",
                ));
            }
        }
        Ok(())
    }

    /// Around every vertex its faces form one fan (a surface pinched at a vertex, two
    /// cones tip to tip, is not a solid's).
    fn check_pinched(&self) -> Result<()> {
        // For each corner (face f at vertex v), the next face around v: the one across the
        // edge that enters v in f.
        let mut outgoing: HashMap<(usize, usize), usize> = HashMap::new();
        let mut corners = vec![0usize; self.vertices.len()];
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                outgoing.insert((face[k], face[(k + 1) % face.len()]), f);
                corners[face[k]] += 1;
            }
        }
        let mut walked = vec![false; self.vertices.len()];
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                let v = face[k];
                if walked[v] {
                    continue;
                }
                walked[v] = true;
                let mut previous = face[(k + face.len() - 1) % face.len()];
                let mut fan = 0;
                loop {
                    fan += 1;
                    let next = outgoing[&(v, previous)];
                    if next == f || fan > corners[v] {
                        break;
                    }
                    let around = &self.faces[next];
                    let i = around.iter().position(|&w| w == v).expect("v on the face");
                    previous = around[(i + around.len() - 1) % around.len()];
                }
                if fan != corners[v] {
                    return Err(NanofoldError::invalid(
                        format!("vertices[{v}]"),
                        format!("{} faces in a fan of {fan}", corners[v]),
                        "the surface is pinched there: its faces around a vertex must form one fan",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The size the tolerances are relative to: the largest distance from the centroid.
    fn size(&self) -> f64 {
        let c = self.centroid();
        self.vertices.iter().map(|p| (p - c).norm()).fold(0.0, f64::max)
    }

    fn check_planar(&self) -> Result<()> {
        let size = self.size();
        for f in 0..self.faces.len() {
            let (normal, centre) = (self.face_normal(f), self.face_centroid(f));
            if normal.norm() <= 1e-12 * size * size {
                return Err(NanofoldError::invalid(
                    format!("faces[{f}]"),
                    "area 0",
                    "a face has area",
                ));
            }
            let unit = normal.normalize();
            let off = self.faces[f]
                .iter()
                .map(|&v| (self.vertices[v] - centre).dot(&unit).abs())
                .fold(0.0, f64::max);
            if off > 1e-9 * size {
                return Err(NanofoldError::invalid(
                    format!("faces[{f}]"),
                    format!("a vertex {off:e} off its plane"),
                    format!("faces must be planar (to 1e-9 of the solid's size, {size:e})"),
                ));
            }
            let face = &self.faces[f];
            for k in 0..face.len() {
                let [a, b, c] = [0, 1, 2].map(|i| self.vertices[face[(k + i) % face.len()]]);
                let turn = (b - a).cross(&(c - b)).dot(&unit);
                if turn < -1e-9 * size * size {
                    return Err(NanofoldError::invalid(
                        format!("faces[{f}]"),
                        format!(
                            "corner at vertex {} turns {turn:e} the wrong way",
                            face[(k + 1) % face.len()]
                        ),
                        "faces must be convex (split a concave face into convex ones)",
                    ));
                }
            }
        }
        Ok(())
    }

    fn connected(&self) -> bool {
        let edges = self.dual_edges();
        let mut seen = vec![false; self.faces.len()];
        let mut stack = vec![0];
        seen[0] = true;
        let mut neighbours = vec![Vec::new(); self.faces.len()];
        for e in &edges {
            neighbours[e.faces[0]].push(e.faces[1]);
            neighbours[e.faces[1]].push(e.faces[0]);
        }
        while let Some(f) = stack.pop() {
            for &g in &neighbours[f] {
                if !seen[g] {
                    seen[g] = true;
                    stack.push(g);
                }
            }
        }
        seen.iter().all(|&s| s)
    }

    /// The vertices' centroid.
    pub fn centroid(&self) -> Point3<f64> {
        let sum = self.vertices.iter().fold(Vector3::zeros(), |s, p| s + p.coords);
        Point3::from(sum / self.vertices.len() as f64)
    }

    /// Newell's normal of a face: outward, its length twice the face's area.
    pub fn face_normal(&self, f: usize) -> Vector3<f64> {
        let face = &self.faces[f];
        newell_normal(face.len(), |k| self.vertices[face[k]])
    }

    /// A face's vertex centroid.
    pub fn face_centroid(&self, f: usize) -> Point3<f64> {
        let face = &self.faces[f];
        let sum = face.iter().fold(Vector3::zeros(), |s, &v| s + self.vertices[v].coords);
        Point3::from(sum / face.len() as f64)
    }

    /// The enclosed volume (positive when the faces are wound outwards).
    pub fn volume(&self) -> f64 {
        (0..self.faces.len())
            .map(|f| self.face_normal(f).dot(&self.face_centroid(f).coords) / 6.0)
            .sum()
    }

    /// The surface's edges, one per pair of faces that share it: the dual graph.
    pub fn dual_edges(&self) -> Vec<DualEdge> {
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                directed.insert((face[k], face[(k + 1) % face.len()]), f);
            }
        }
        let mut edges: Vec<DualEdge> = directed
            .iter()
            .filter(|(&(a, b), _)| a < b)
            .filter_map(|(&(a, b), &f)| {
                directed.get(&(b, a)).map(|&g| DualEdge {
                    faces: [f, g],
                    vertices: [a, b],
                })
            })
            .collect();
        edges.sort_by_key(|e| e.vertices);
        edges
    }

    /// The number of spanning trees of the dual graph (the edge unfoldings), by the
    /// matrix-tree theorem: the determinant of its Laplacian without one row and column.
    /// Exact (rounded) while below 2⁵³.
    pub fn spanning_tree_count(&self) -> f64 {
        let n = self.faces.len();
        let mut laplacian = DMatrix::<f64>::zeros(n - 1, n - 1);
        for e in self.dual_edges() {
            let [a, b] = e.faces;
            for x in [a, b] {
                if x > 0 {
                    laplacian[(x - 1, x - 1)] += 1.0;
                }
            }
            if a > 0 && b > 0 {
                laplacian[(a - 1, b - 1)] -= 1.0;
                laplacian[(b - 1, a - 1)] -= 1.0;
            }
        }
        let count = laplacian.determinant();
        if count.abs() < 2f64.powi(53) {
            count.round()
        } else {
            count
        }
    }

    /// Every isometry about the centroid that maps the solid onto itself (rotations and
    /// reflections): face 0's first edge and normal are sent to each face's edges, both ways
    /// round (the other way is a reflection), and a candidate is kept when it is orthogonal
    /// and maps every vertex onto a vertex and every face onto a face.
    pub fn symmetries(&self) -> Vec<Symmetry> {
        let c = self.centroid();
        let size = self.size();
        let tolerance = 1e-7 * size;
        let frame = |f: usize, a: usize, b: usize| {
            let n = self.face_normal(f).normalize() * size;
            Matrix3::from_columns(&[self.vertices[a] - c, self.vertices[b] - c, n])
        };
        let base_face = &self.faces[0];
        let Some(base_inverse) = frame(0, base_face[0], base_face[1]).try_inverse() else {
            return Vec::new();
        };
        let face_keys: HashMap<Vec<usize>, usize> = self
            .faces
            .iter()
            .enumerate()
            .map(|(f, face)| {
                let mut key = face.clone();
                key.sort_unstable();
                (key, f)
            })
            .collect();
        let mut found = Vec::new();
        for (g, face) in self.faces.iter().enumerate() {
            if face.len() != base_face.len() {
                continue;
            }
            for k in 0..face.len() {
                for reflected in [false, true] {
                    // A reflection reverses the winding: the base edge goes to an edge run
                    // backwards, while outward normals still go to outward normals.
                    let (a, b) = if reflected {
                        (face[(k + 1) % face.len()], face[k])
                    } else {
                        (face[k], face[(k + 1) % face.len()])
                    };
                    let matrix = frame(g, a, b) * base_inverse;
                    if (matrix.transpose() * matrix - Matrix3::identity()).norm() > 1e-7 {
                        continue;
                    }
                    if let Some(symmetry) = self.as_symmetry(matrix, c, tolerance, &face_keys) {
                        if !found.iter().any(|s: &Symmetry| s.vertex_map == symmetry.vertex_map) {
                            found.push(symmetry);
                        }
                    }
                }
            }
        }
        found
    }

    fn as_symmetry(
        &self,
        matrix: Matrix3<f64>,
        c: Point3<f64>,
        tolerance: f64,
        face_keys: &HashMap<Vec<usize>, usize>,
    ) -> Option<Symmetry> {
        let mut vertex_map = Vec::with_capacity(self.vertices.len());
        for p in &self.vertices {
            let image = c + matrix * (p - c);
            vertex_map.push(self.vertices.iter().position(|q| (q - image).norm() <= tolerance)?);
        }
        let mut face_map = Vec::with_capacity(self.faces.len());
        for face in &self.faces {
            let mut key: Vec<usize> = face.iter().map(|&v| vertex_map[v]).collect();
            key.sort_unstable();
            face_map.push(*face_keys.get(&key)?);
        }
        Some(Symmetry {
            matrix,
            vertex_map,
            face_map,
        })
    }
}
