//! Closed polyhedral surfaces, the solids a net is designed for (`docs/model.md#nets-of-polyhedra`):
//! validation (closed, manifold, consistently and outwardly wound, planar faces), the
//! generated solids, the face-adjacency (dual) graph, its number of spanning trees (the edge
//! unfoldings) and the solid's symmetry group found from its geometry.

use super::point_group::{classify, PointGroup};
use super::precision::{Precision, Tolerances};
use super::surface_intersection::{first_self_intersection, newell_normal};
use crate::error::{NanofoldError, Result};
use nalgebra::{DMatrix, Matrix3, Point3, Vector3};
use serde::Serialize;
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
    /// The tolerances its tests use, from its coordinates' precision.
    pub tolerances: Tolerances,
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
    /// The largest distance between a vertex's image and the vertex it lands on.
    pub residual: f64,
}

/// A solid's symmetry group, checked to be one: closed under composition and a point group.
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetryGroup {
    /// Its elements, the identity first.
    pub elements: Vec<Symmetry>,
    /// Which point group it is.
    pub point_group: PointGroup,
    /// How far an image may land from its vertex (the solid's symmetry tolerance).
    pub tolerance: f64,
    /// The largest residual among the elements kept.
    pub largest_residual: f64,
    /// Maps found within the tolerance but left out because with them the set was no group
    /// (the solid is near-symmetric at the tolerance's scale).
    pub left_out: usize,
}

impl SymmetryGroup {
    /// What the group is, in words, with a warning when near-symmetries were left out.
    pub fn warning(&self) -> Option<String> {
        (self.left_out > 0).then(|| {
            format!(
                "{} more maps send every vertex within {:.1e} of a vertex but do not close into a group with the others (the solid is nearly, not exactly, more symmetric at that scale): the largest group among the maps, {} of order {}, is used (its maps within {:.1e})",
                self.left_out, self.tolerance, self.point_group.name, self.point_group.order, self.largest_residual
            )
        })
    }
}

/// The symmetry group as a report shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SymmetrySummary {
    /// Schoenflies symbol.
    pub point_group: String,
    /// Order.
    pub order: usize,
    /// Rotations among them.
    pub rotations: usize,
    /// The tolerance a vertex's image was matched within.
    pub tolerance: f64,
    /// The largest residual among the kept maps.
    pub largest_residual: f64,
    /// Maps within the tolerance left out so that the rest form a group.
    pub left_out: usize,
}

impl From<&SymmetryGroup> for SymmetrySummary {
    fn from(group: &SymmetryGroup) -> Self {
        SymmetrySummary {
            point_group: group.point_group.name.clone(),
            order: group.point_group.order,
            rotations: group.point_group.rotations,
            tolerance: group.tolerance,
            largest_residual: group.largest_residual,
            left_out: group.left_out,
        }
    }
}

impl Symmetry {
    /// Whether it is a rotation (determinant +1) rather than a reflection.
    pub fn is_rotation(&self) -> bool {
        self.matrix.determinant() > 0.0
    }
}

impl Polyhedron {
    /// A validated closed surface of exactly known coordinates: every face of at least three
    /// distinct vertices, every edge in exactly two faces that run it in opposite directions
    /// (closed, manifold, consistently wound), faces planar to 1e-9 of the solid's size,
    /// wound outwards (positive volume), and all of one piece. Errors name the face or edge
    /// and the value.
    pub fn new(vertices: Vec<Point3<f64>>, faces: Vec<Vec<usize>>) -> Result<Polyhedron> {
        Polyhedron::with_precision(vertices, faces, Precision::EXACT)
    }

    /// As [`Polyhedron::new`], its coordinates rounded by `precision` (a file's digits or
    /// float width): planarity, convexity and self-intersection allow what that rounding can
    /// do ([`Tolerances`]), and the solid carries them for its symmetry search.
    pub fn with_precision(
        vertices: Vec<Point3<f64>>,
        faces: Vec<Vec<usize>>,
        precision: Precision,
    ) -> Result<Polyhedron> {
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
        let size = size_of(&vertices);
        let solid = Polyhedron {
            vertices,
            faces,
            tolerances: Tolerances::new(precision, size),
        };
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
        if let Some((f, g)) = first_self_intersection(&solid.vertices, &solid.faces, solid.tolerances.planarity) {
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
    pub fn size(&self) -> f64 {
        self.tolerances.size
    }

    fn check_planar(&self) -> Result<()> {
        let size = self.size();
        let tolerance = self.tolerances.planarity;
        let within = || {
            if self.tolerances.rounded() {
                format!(
                    "{tolerance:.1e}, what coordinates rounded to {} can be off",
                    self.tolerances.precision.describe()
                )
            } else {
                format!("{tolerance:.1e}, 1e-9 of the solid's size")
            }
        };
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
            if off > tolerance {
                return Err(NanofoldError::invalid(
                    format!("faces[{f}]"),
                    format!("a vertex {off:.3e} off its plane"),
                    format!("faces must be planar (to {})", within()),
                ));
            }
            let face = &self.faces[f];
            for k in 0..face.len() {
                let [a, b, c] = [0, 1, 2].map(|i| self.vertices[face[(k + i) % face.len()]]);
                // c's distance from the line through a and b, on the inner side when positive.
                let turn = (b - a).cross(&(c - b)).dot(&unit) / (b - a).norm();
                if turn < -tolerance {
                    return Err(NanofoldError::invalid(
                        format!("faces[{f}]"),
                        format!(
                            "corner at vertex {} turns {:.3e} the wrong way",
                            face[(k + 1) % face.len()],
                            -turn
                        ),
                        format!(
                            "faces must be convex, to {} (split a concave face into convex ones)",
                            within()
                        ),
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

    /// The elements of the solid's symmetry group ([`Polyhedron::symmetry_group`]).
    pub fn symmetries(&self) -> Vec<Symmetry> {
        self.symmetry_group().elements
    }

    /// Every isometry about the centroid that maps the solid onto itself (rotations and
    /// reflections), checked to be a group.
    ///
    /// A candidate sends face 0's first edge and normal to each face's edges, both ways
    /// round (the other way is a reflection); each vertex's image is matched to the nearest
    /// vertex within half the closest two vertices' distance, the map refitted to those
    /// pairs (Kabsch), and kept when every vertex lands within the symmetry tolerance and
    /// every face on a face. The maps kept must close under composition: while they do not,
    /// the map of largest residual is left out (a near-symmetry of rounded data), and the
    /// set that closes is named as a point group ([`classify`]) or cut further.
    pub fn symmetry_group(&self) -> SymmetryGroup {
        let tolerance = self.tolerances.symmetry;
        let identity: Vec<usize> = (0..self.vertices.len()).collect();
        let mut found = self.isometries(tolerance);
        found.retain(|s| s.vertex_map != identity);
        found.sort_by(|a, b| a.residual.total_cmp(&b.residual));
        found.insert(
            0,
            Symmetry {
                matrix: Matrix3::identity(),
                vertex_map: identity,
                face_map: (0..self.faces.len()).collect(),
                residual: 0.0,
            },
        );
        // A fitted map's turn is off by about its residual over the size.
        let angle_tolerance = 1e-6_f64.max(2.0 * tolerance / self.size());
        let named = |maps: &[Symmetry]| {
            let matrices: Vec<Matrix3<f64>> = maps.iter().map(|s| s.matrix).collect();
            classify(&matrices, angle_tolerance)
        };
        let kept = if closed(&found) && named(&found).is_some() {
            (0..found.len()).collect()
        } else {
            largest_group(&found, &named)
        };
        let left_out = found.len() - kept.len();
        let elements: Vec<Symmetry> = kept.into_iter().map(|k| found[k].clone()).collect();
        let point_group = named(&elements).unwrap_or(PointGroup {
            name: "C1".into(),
            order: 1,
            rotations: 1,
        });
        let largest_residual = elements.iter().map(|s| s.residual).fold(0.0, f64::max);
        SymmetryGroup {
            elements,
            point_group,
            tolerance,
            largest_residual,
            left_out,
        }
    }

    /// Every map about the centroid found by the candidates, its residual within `tolerance`.
    fn isometries(&self, tolerance: f64) -> Vec<Symmetry> {
        let c = self.centroid();
        let size = self.size();
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
        let lookup = NearestVertex::new(&self.vertices);
        let mut found: Vec<Symmetry> = Vec::new();
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
                    let guess = frame(g, a, b) * base_inverse;
                    let Some(symmetry) = self.as_symmetry(guess, !reflected, c, &lookup, tolerance, &face_keys) else {
                        continue;
                    };
                    if !found.iter().any(|s| s.vertex_map == symmetry.vertex_map) {
                        found.push(symmetry);
                    }
                }
            }
        }
        found
    }

    /// The map near `guess` that sends the solid onto itself: vertices matched to their
    /// images' nearest, the orthogonal map of determinant ±1 (`proper`) fitted to the
    /// pairs, kept when every vertex lands within `tolerance` and faces on faces.
    fn as_symmetry(
        &self,
        guess: Matrix3<f64>,
        proper: bool,
        c: Point3<f64>,
        lookup: &NearestVertex,
        tolerance: f64,
        face_keys: &HashMap<Vec<usize>, usize>,
    ) -> Option<Symmetry> {
        let mut vertex_map = Vec::with_capacity(self.vertices.len());
        let mut taken = vec![false; self.vertices.len()];
        for p in &self.vertices {
            let w = lookup.nearest(&(c + guess * (p - c)))?;
            if std::mem::replace(&mut taken[w], true) {
                return None;
            }
            vertex_map.push(w);
        }
        let matrix = kabsch(
            self.vertices
                .iter()
                .zip(&vertex_map)
                .map(|(p, &w)| (p - c, self.vertices[w] - c)),
            proper,
        )?;
        let residual = self
            .vertices
            .iter()
            .zip(&vertex_map)
            .map(|(p, &w)| (c + matrix * (p - c) - self.vertices[w]).norm())
            .fold(0.0, f64::max);
        if residual > tolerance {
            return None;
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
            residual,
        })
    }
}

/// The largest distance of a vertex from the vertices' centroid.
fn size_of(vertices: &[Point3<f64>]) -> f64 {
    let c = Point3::from(vertices.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / vertices.len() as f64);
    vertices.iter().map(|p| (p - c).norm()).fold(0.0, f64::max)
}

/// The largest group among maps that are not one (near-symmetries of rounded data), as
/// indices into `maps` (the identity first): of the group left when the worst-fitting maps
/// are dropped one by one until the rest close, and every group two of the maps generate
/// within the set (tried while |maps|³ · vertices stays below 2·10⁸), the largest that is a
/// point group.
fn largest_group(maps: &[Symmetry], named: &dyn Fn(&[Symmetry]) -> Option<PointGroup>) -> Vec<usize> {
    let pick = |indices: &[usize]| indices.iter().map(|&k| maps[k].clone()).collect::<Vec<_>>();
    // Worst fit first out (the identity, first, stays).
    let mut best: Vec<usize> = (0..maps.len()).collect();
    while best.len() > 1 && !(closed(&pick(&best)) && named(&pick(&best)).is_some()) {
        let worst = (1..best.len())
            .max_by(|&a, &b| maps[best[a]].residual.total_cmp(&maps[best[b]].residual))
            .expect("more than the identity");
        best.remove(worst);
    }
    let n = maps.len();
    let vertices = maps.first().map_or(0, |s| s.vertex_map.len());
    if (n * n * n).saturating_mul(vertices) > 200_000_000 {
        return best;
    }
    let index: HashMap<&[usize], usize> = maps
        .iter()
        .enumerate()
        .map(|(k, s)| (s.vertex_map.as_slice(), k))
        .collect();
    for a in 1..n {
        for b in a..n {
            if let Some(group) = generated(maps, &index, &[a, b]) {
                if group.len() > best.len() && named(&pick(&group)).is_some() {
                    best = group;
                }
            }
        }
    }
    best
}

/// The group `generators` generate, as indices into `maps`, or None when a product falls
/// outside the maps.
fn generated(maps: &[Symmetry], index: &HashMap<&[usize], usize>, generators: &[usize]) -> Option<Vec<usize>> {
    let identity = *index.get((0..maps[0].vertex_map.len()).collect::<Vec<_>>().as_slice())?;
    let mut group = vec![identity];
    let mut k = 0;
    while k < group.len() {
        for &g in generators {
            let product: Vec<usize> = maps[g]
                .vertex_map
                .iter()
                .map(|&v| maps[group[k]].vertex_map[v])
                .collect();
            let at = *index.get(product.as_slice())?;
            if !group.contains(&at) {
                group.push(at);
            }
        }
        k += 1;
    }
    group.sort_unstable();
    Some(group)
}

/// Whether the maps (by their vertex permutations) hold the identity and every composition
/// of two of them.
fn closed(maps: &[Symmetry]) -> bool {
    let index: HashMap<&[usize], usize> = maps
        .iter()
        .enumerate()
        .map(|(k, s)| (s.vertex_map.as_slice(), k))
        .collect();
    let n = maps.first().map_or(0, |s| s.vertex_map.len());
    let identity: Vec<usize> = (0..n).collect();
    if !index.contains_key(identity.as_slice()) {
        return false;
    }
    let mut composed = vec![0; n];
    maps.iter().all(|a| {
        maps.iter().all(|b| {
            for (v, slot) in composed.iter_mut().enumerate() {
                *slot = a.vertex_map[b.vertex_map[v]];
            }
            index.contains_key(composed.as_slice())
        })
    })
}

/// The orthogonal map R of determinant +1 (`proper`) or −1 minimising Σ |R a − b|² over the
/// pairs (Kabsch): R = V diag(1, 1, ±1) Uᵀ from the SVD of Σ a bᵀ = U Σ Vᵀ.
fn kabsch(pairs: impl Iterator<Item = (Vector3<f64>, Vector3<f64>)>, proper: bool) -> Option<Matrix3<f64>> {
    let covariance = pairs.fold(Matrix3::zeros(), |h, (a, b)| h + a * b.transpose());
    let svd = covariance.svd(true, true);
    let (u, v_t) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    let sign = (v_t.transpose() * u.transpose()).determinant().signum();
    d[(2, 2)] = if proper { sign } else { -sign };
    Some(v_t.transpose() * d * u.transpose())
}

/// The nearest vertex to a point, among those closer than half the smallest distance
/// between two vertices (so at most one is), by a grid of that cell size.
struct NearestVertex<'a> {
    vertices: &'a [Point3<f64>],
    radius: f64,
    cells: HashMap<[i64; 3], Vec<usize>>,
}

impl<'a> NearestVertex<'a> {
    fn new(vertices: &'a [Point3<f64>]) -> Self {
        let mut closest = f64::INFINITY;
        for (i, p) in vertices.iter().enumerate() {
            for q in &vertices[i + 1..] {
                closest = closest.min((p - q).norm());
            }
        }
        let radius = 0.5 * closest;
        let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (k, p) in vertices.iter().enumerate() {
            cells.entry(Self::cell(p, radius)).or_default().push(k);
        }
        NearestVertex {
            vertices,
            radius,
            cells,
        }
    }

    fn cell(p: &Point3<f64>, radius: f64) -> [i64; 3] {
        [0, 1, 2].map(|i| (p[i] / radius).floor() as i64)
    }

    fn nearest(&self, p: &Point3<f64>) -> Option<usize> {
        if self.radius.is_nan() || self.radius <= 0.0 {
            return None;
        }
        let [x, y, z] = Self::cell(p, self.radius);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &k in self.cells.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                        let d = (self.vertices[k] - p).norm();
                        if d < self.radius && best.is_none_or(|(b, _)| d < b) {
                            best = Some((d, k));
                        }
                    }
                }
            }
        }
        best.map(|(_, k)| k)
    }
}
