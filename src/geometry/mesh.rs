//! A solid's faces from a mesh as mesh tools write it (`docs/model.md#solids-from-mesh-files`):
//! corners that are one point welded, faces that lie in one plane merged back into the face
//! they tile, a merged face that is concave cut along its reflex corners' edges, and corners
//! where the surface runs straight on dropped. The tolerances come from the coordinates'
//! precision ([`Tolerances`]).

use super::polyhedron::{Polyhedron, MAX_VERTICES};
use super::precision::{Precision, Tolerances};
use super::surface_intersection::newell_normal;
use crate::error::{NanofoldError, Result};
use nalgebra::{Point2, Point3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashMap};

/// Whether faces in one plane are merged into one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MergeCoplanar {
    /// A mesh of triangles only (an STL file, or a triangulated export) says nothing of its
    /// faces: its coplanar triangles are merged. A mesh with polygons of more sides says what
    /// its faces are (a polycube's squares), and they are kept.
    #[default]
    Auto,
    /// Always merge faces that share an edge and lie in one plane.
    Always,
    /// Keep the faces as written.
    Never,
}

/// What reading a mesh did, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshReading {
    /// The file's format (`obj`, `stl (binary)`, …).
    pub format: String,
    /// Vertices and faces as the file gives them.
    pub vertices_read: usize,
    /// Faces as the file gives them.
    pub faces_read: usize,
    /// Vertices that were copies of another (within the coincident tolerance).
    pub vertices_welded: usize,
    /// Whether coplanar faces were merged.
    pub merged: bool,
    /// Faces after merging (before cutting concave ones).
    pub faces_merged: usize,
    /// Merged faces that were concave and cut at their reflex corners.
    pub concave_faces_cut: usize,
    /// Corners dropped where the surface runs straight on (two faces, both straight there).
    pub straight_corners_dropped: usize,
    /// The coordinates' precision and the tolerances it gives.
    pub tolerances: Tolerances,
}

/// A validated solid from a mesh's vertices and faces (each face's corners
/// counter-clockwise seen from outside), with what was done to it.
pub fn solid_from_mesh(
    vertices: Vec<Point3<f64>>,
    faces: Vec<Vec<usize>>,
    precision: Precision,
    merge: MergeCoplanar,
    format: &str,
) -> Result<(Polyhedron, MeshReading)> {
    let (vertices_read, faces_read) = (vertices.len(), faces.len());
    if vertices.len() < 4 {
        return Err(NanofoldError::invalid(
            "vertices",
            vertices.len(),
            "a solid has at least 4 vertices",
        ));
    }
    for (f, face) in faces.iter().enumerate() {
        if let Some(&v) = face.iter().find(|&&v| v >= vertices.len()) {
            return Err(NanofoldError::invalid(
                format!("faces[{f}]"),
                format!("{face:?}"),
                format!("vertex {v} does not exist (there are {})", vertices.len()),
            ));
        }
    }
    let size = size_of(&vertices);
    let tolerances = Tolerances::new(precision, size);
    let mut mesh = Mesh { vertices, faces };
    let vertices_welded = mesh.weld(tolerances.coincident)?;
    let merged = match merge {
        MergeCoplanar::Never => false,
        MergeCoplanar::Always => true,
        MergeCoplanar::Auto => mesh.faces.iter().all(|f| f.len() == 3),
    };
    let mut concave_faces_cut = 0;
    if merged {
        mesh.merge_coplanar(tolerances.planarity)?;
    }
    let faces_merged = mesh.faces.len();
    if merged {
        concave_faces_cut = mesh.cut_concave(tolerances.planarity)?;
    }
    let straight_corners_dropped = mesh.drop_straight_corners(tolerances.planarity);
    mesh.drop_unused();
    if mesh.vertices.len() > MAX_VERTICES {
        return Err(NanofoldError::invalid(
            "vertices",
            mesh.vertices.len(),
            format!("a solid has at most {MAX_VERTICES} vertices"),
        ));
    }
    let solid = Polyhedron::with_precision(mesh.vertices, mesh.faces, precision)?;
    let reading = MeshReading {
        format: format.to_string(),
        vertices_read,
        faces_read,
        vertices_welded,
        merged,
        faces_merged,
        concave_faces_cut,
        straight_corners_dropped,
        tolerances: solid.tolerances,
    };
    Ok((solid, reading))
}

/// The largest distance of a vertex from the vertices' centroid.
fn size_of(vertices: &[Point3<f64>]) -> f64 {
    let c = Point3::from(vertices.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / vertices.len() as f64);
    vertices.iter().map(|p| (p - c).norm()).fold(0.0, f64::max)
}

/// A surface being made into a solid's.
struct Mesh {
    vertices: Vec<Point3<f64>>,
    faces: Vec<Vec<usize>>,
}

/// Union–find over indices.
struct Sets(Vec<usize>);

impl Sets {
    fn new(n: usize) -> Self {
        Sets((0..n).collect())
    }
    fn root(&mut self, mut k: usize) -> usize {
        while self.0[k] != k {
            self.0[k] = self.0[self.0[k]];
            k = self.0[k];
        }
        k
    }
    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        // The smaller index stays the root, so a class is named by its first member.
        if a < b {
            self.0[b] = a;
        } else {
            self.0[a] = b;
        }
    }
}

impl Mesh {
    /// Vertices within `tolerance` of each other become one (the first of them); a face
    /// whose corners repeat after that is refused. Returns how many were welded.
    fn weld(&mut self, tolerance: f64) -> Result<usize> {
        let n = self.vertices.len();
        let cell = |p: &Point3<f64>| [0, 1, 2].map(|i| (p[i] / tolerance).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        let mut sets = Sets::new(n);
        for (k, p) in self.vertices.iter().enumerate() {
            let [x, y, z] = cell(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        for &other in grid.get(&[x + dx, y + dy, z + dz]).into_iter().flatten() {
                            if (self.vertices[other] - p).norm() <= tolerance {
                                sets.join(other, k);
                            }
                        }
                    }
                }
            }
            grid.entry([x, y, z]).or_default().push(k);
        }
        let roots: Vec<usize> = (0..n).map(|k| sets.root(k)).collect();
        let welded = (0..n).filter(|&k| roots[k] != k).count();
        for (f, face) in self.faces.iter_mut().enumerate() {
            for v in face.iter_mut() {
                *v = roots[*v];
            }
            let mut sorted = face.clone();
            sorted.sort_unstable();
            if sorted.windows(2).any(|w| w[0] == w[1]) {
                return Err(NanofoldError::invalid(
                    format!("faces[{f}]"),
                    format!("{face:?}"),
                    format!("two of its corners are one point (within {tolerance:.1e}, the coincident tolerance)"),
                ));
            }
        }
        Ok(welded)
    }

    /// A face's plane: unit Newell normal and centroid.
    fn plane(&self, face: &[usize]) -> Option<(Vector3<f64>, Point3<f64>)> {
        let normal = newell_normal(face.len(), |k| self.vertices[face[k]]);
        let centroid =
            Point3::from(face.iter().fold(Vector3::zeros(), |s, &v| s + self.vertices[v].coords) / face.len() as f64);
        (normal.norm() > 0.0).then(|| (normal.normalize(), centroid))
    }

    /// The largest distance of `points` from a plane.
    fn off_plane(&self, points: impl Iterator<Item = usize>, (normal, centre): (Vector3<f64>, Point3<f64>)) -> f64 {
        points
            .map(|v| (self.vertices[v] - centre).dot(&normal).abs())
            .fold(0.0, f64::max)
    }

    /// Faces that share an edge and lie in one plane (every corner of each within `tolerance`
    /// of the other's plane, and of the plane of all of them) become one face, its outline
    /// the edges of theirs that no other of them shares.
    fn merge_coplanar(&mut self, tolerance: f64) -> Result<()> {
        let planes: Vec<Option<(Vector3<f64>, Point3<f64>)>> = self.faces.iter().map(|f| self.plane(f)).collect();
        let mut owner: HashMap<(usize, usize), usize> = HashMap::new();
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                owner.insert((face[k], face[(k + 1) % face.len()]), f);
            }
        }
        let mut sets = Sets::new(self.faces.len());
        for (f, face) in self.faces.iter().enumerate() {
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                let Some(&g) = owner.get(&(b, a)) else { continue };
                if g <= f {
                    continue;
                }
                let (Some(pf), Some(pg)) = (planes[f], planes[g]) else {
                    continue;
                };
                // Facing the same way, and each within the tolerance of the other's plane.
                if pf.0.dot(&pg.0) > 0.0
                    && self.off_plane(self.faces[g].iter().copied(), pf) <= tolerance
                    && self.off_plane(face.iter().copied(), pg) <= tolerance
                {
                    sets.join(f, g);
                }
            }
        }
        let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for f in 0..self.faces.len() {
            groups.entry(sets.root(f)).or_default().push(f);
        }
        let mut merged = Vec::with_capacity(groups.len());
        for members in groups.values() {
            if members.len() == 1 {
                merged.push(self.faces[members[0]].clone());
                continue;
            }
            merged.push(self.outline(members, tolerance)?);
        }
        self.faces = merged;
        Ok(())
    }

    /// The outline of a group of faces: their edges that no other member runs backwards,
    /// chained into one cycle (a group that is not one disc is refused by name).
    fn outline(&self, members: &[usize], tolerance: f64) -> Result<Vec<usize>> {
        let field = || {
            format!(
                "faces[{}]",
                members.iter().map(|f| f.to_string()).collect::<Vec<_>>().join(", ")
            )
        };
        // The whole group in one plane, not a slowly turning strip of nearly flat pairs.
        let normal = members
            .iter()
            .map(|&f| newell_normal(self.faces[f].len(), |k| self.vertices[self.faces[f][k]]))
            .fold(Vector3::zeros(), |s, n| s + n);
        let corners: Vec<usize> = members.iter().flat_map(|&f| self.faces[f].iter().copied()).collect();
        let centre = Point3::from(
            corners
                .iter()
                .fold(Vector3::zeros(), |s, &v| s + self.vertices[v].coords)
                / corners.len() as f64,
        );
        let off = self.off_plane(corners.iter().copied(), (normal.normalize(), centre));
        if off > tolerance {
            return Err(NanofoldError::invalid(
                field(),
                format!("{off:.3e} off their common plane"),
                format!("each neighbour lies within {tolerance:.1e} of the next one's plane, but not all within one plane (a curved surface is no solid's face)"),
            ));
        }
        let mut directed: HashMap<(usize, usize), ()> = HashMap::new();
        for &f in members {
            let face = &self.faces[f];
            for k in 0..face.len() {
                directed.insert((face[k], face[(k + 1) % face.len()]), ());
            }
        }
        let mut next: HashMap<usize, usize> = HashMap::new();
        for &(a, b) in directed.keys() {
            if directed.contains_key(&(b, a)) {
                continue;
            }
            if next.insert(a, b).is_some() {
                return Err(NanofoldError::invalid(
                    field(),
                    format!("their outline passes vertex {a} twice"),
                    "faces in one plane merge into one face only when they make a disc (this group touches itself at a corner)",
                ));
            }
        }
        let start = *next.keys().min().expect("a group of faces has an outline");
        let mut cycle = vec![start];
        let mut at = next[&start];
        while at != start {
            cycle.push(at);
            at = *next.get(&at).ok_or_else(|| {
                NanofoldError::invalid(field(), "an open outline", "the faces in one plane do not close around")
            })?;
            if cycle.len() > next.len() {
                break;
            }
        }
        if cycle.len() != next.len() {
            return Err(NanofoldError::invalid(
                field(),
                format!("an outline of {} edges in more than one loop", next.len()),
                "faces in one plane merge into one face only when they make a disc (this group has a hole)",
            ));
        }
        Ok(cycle)
    }

    /// A frame in a face's plane: origin, x and y axes (normal up).
    fn frame(&self, face: &[usize]) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        let normal = newell_normal(face.len(), |k| self.vertices[face[k]]).normalize();
        let origin = self.vertices[face[0]];
        let longest = (0..face.len())
            .map(|k| self.vertices[face[(k + 1) % face.len()]] - self.vertices[face[k]])
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .expect("a face has edges");
        let x = (longest - normal * longest.dot(&normal)).normalize();
        (origin, x, normal.cross(&x))
    }

    /// Cuts every concave face along the extensions of the two edges at each of its reflex
    /// corners, each run to where it first meets the face's outline: the convex pieces
    /// left are faces, meeting flat. A point where an extension meets an edge is a new
    /// corner of both faces along that edge. Returns how many faces were cut.
    fn cut_concave(&mut self, tolerance: f64) -> Result<usize> {
        // Extensions of each concave face: (face, from vertex, to point) with the point
        // either a vertex or on an edge.
        let mut plans: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
        // New points on edges: (a, b) with a < b → (parameter along a→b, vertex).
        let mut on_edges: BTreeMap<(usize, usize), Vec<(f64, usize)>> = BTreeMap::new();
        for f in 0..self.faces.len() {
            let face = self.faces[f].clone();
            let (origin, x, y) = self.frame(&face);
            let flat: Vec<Point2<f64>> = face
                .iter()
                .map(|&v| {
                    let d = self.vertices[v] - origin;
                    Point2::new(d.dot(&x), d.dot(&y))
                })
                .collect();
            let n = face.len();
            let reflex: Vec<usize> = (0..n)
                .filter(|&k| {
                    let (a, b, c) = (flat[(k + n - 1) % n], flat[k], flat[(k + 1) % n]);
                    (b - a).perp(&(c - b)) / (b - a).norm() < -tolerance
                })
                .collect();
            if reflex.is_empty() {
                continue;
            }
            let mut segments = Vec::new();
            for &k in &reflex {
                for direction in [flat[k] - flat[(k + n - 1) % n], flat[k] - flat[(k + 1) % n]] {
                    let (edge, t) = first_hit(&flat, k, direction.normalize()).ok_or_else(|| {
                        NanofoldError::invalid(
                            format!("faces[{f}]"),
                            format!("reflex corner at vertex {}", face[k]),
                            "a concave face's reflex corner could not be cut (its edges' extensions meet nothing)",
                        )
                    })?;
                    let (a, b) = (face[edge], face[(edge + 1) % n]);
                    let length = (flat[(edge + 1) % n] - flat[edge]).norm();
                    let target = if t * length <= tolerance {
                        a
                    } else if (1.0 - t) * length <= tolerance {
                        b
                    } else {
                        let (lo, hi, s) = if a < b { (a, b, t) } else { (b, a, 1.0 - t) };
                        let list = on_edges.entry((lo, hi)).or_default();
                        let edge_length = (self.vertices[hi] - self.vertices[lo]).norm();
                        match list.iter().find(|(u, _)| (u - s).abs() * edge_length <= tolerance) {
                            Some(&(_, v)) => v,
                            None => {
                                let p = self.vertices[lo] + (self.vertices[hi] - self.vertices[lo]) * s;
                                self.vertices.push(p);
                                let v = self.vertices.len() - 1;
                                list.push((s, v));
                                v
                            }
                        }
                    };
                    if target != face[k]
                        && !segments
                            .iter()
                            .any(|&(p, q)| (p, q) == (target, face[k]) || (p, q) == (face[k], target))
                    {
                        segments.push((face[k], target));
                    }
                }
            }
            plans.push((f, segments));
        }
        if plans.is_empty() {
            return Ok(0);
        }
        // Every face along a cut edge takes its new corners, in order along its own edge.
        for face in self.faces.iter_mut() {
            let mut with = Vec::with_capacity(face.len());
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                with.push(a);
                let key = if a < b { (a, b) } else { (b, a) };
                if let Some(points) = on_edges.get(&key) {
                    let mut along: Vec<(f64, usize)> = points
                        .iter()
                        .map(|&(s, v)| (if a < b { s } else { 1.0 - s }, v))
                        .collect();
                    along.sort_by(|p, q| p.0.total_cmp(&q.0));
                    with.extend(along.into_iter().map(|(_, v)| v));
                }
            }
            *face = with;
        }
        let mut pieces: Vec<(usize, Vec<Vec<usize>>)> = Vec::new();
        for (f, segments) in &plans {
            pieces.push((*f, self.split(*f, segments, tolerance)?));
        }
        let cut = pieces.len();
        let mut faces = Vec::with_capacity(self.faces.len() + cut);
        for (f, face) in self.faces.iter().enumerate() {
            match pieces.iter().find(|(g, _)| *g == f) {
                Some((_, parts)) => faces.extend(parts.iter().cloned()),
                None => faces.push(face.clone()),
            }
        }
        self.faces = faces;
        Ok(cut)
    }

    /// Face `f` (its outline already holding the cuts' end points) split along `segments`
    /// (vertex pairs): the cells of the plane graph of its outline and the segments, split
    /// where they cross, each traced with the face on its left.
    fn split(&mut self, f: usize, segments: &[(usize, usize)], tolerance: f64) -> Result<Vec<Vec<usize>>> {
        let face = self.faces[f].clone();
        let (origin, x, y) = self.frame(&face);
        let to_plane = |p: &Point3<f64>| {
            let d = p - origin;
            Point2::new(d.dot(&x), d.dot(&y))
        };
        // Segments split where they cross one another.
        let mut pieces: Vec<Vec<(f64, usize)>> = segments.iter().map(|&(a, b)| vec![(0.0, a), (1.0, b)]).collect();
        for i in 0..segments.len() {
            for j in i + 1..segments.len() {
                let (a, b) = segments[i];
                let (c, d) = segments[j];
                if [a, b].iter().any(|v| [c, d].contains(v)) {
                    continue;
                }
                let (pa, pb, pc, pd) = (
                    to_plane(&self.vertices[a]),
                    to_plane(&self.vertices[b]),
                    to_plane(&self.vertices[c]),
                    to_plane(&self.vertices[d]),
                );
                let (r, s) = (pb - pa, pd - pc);
                let denominator = r.perp(&s);
                if denominator.abs() <= 1e-15 * r.norm() * s.norm() {
                    continue; // parallel
                }
                let t = (pc - pa).perp(&s) / denominator;
                let u = (pc - pa).perp(&r) / denominator;
                let inside = |t: f64, length: f64| t * length > tolerance && (1.0 - t) * length > tolerance;
                if inside(t, r.norm()) && inside(u, s.norm()) {
                    let p = self.vertices[a] + (self.vertices[b] - self.vertices[a]) * t;
                    self.vertices.push(p);
                    let v = self.vertices.len() - 1;
                    pieces[i].push((t, v));
                    pieces[j].push((u, v));
                }
            }
        }
        let mut edges: Vec<(usize, usize)> = Vec::new();
        let n = face.len();
        for k in 0..n {
            edges.push((face[k], face[(k + 1) % n]));
        }
        for points in &mut pieces {
            points.sort_by(|p, q| p.0.total_cmp(&q.0));
            for w in points.windows(2) {
                edges.push((w[0].1, w[1].1));
            }
        }
        // Each undirected edge once, both ways as half-edges; neighbours in angle order.
        let mut neighbours: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for &(a, b) in &edges {
            for (p, q) in [(a, b), (b, a)] {
                let list = neighbours.entry(p).or_default();
                if !list.contains(&q) {
                    list.push(q);
                }
            }
        }
        let position: HashMap<usize, Point2<f64>> =
            neighbours.keys().map(|&v| (v, to_plane(&self.vertices[v]))).collect();
        let angle = |from: usize, to: usize| {
            let d: Vector2<f64> = position[&to] - position[&from];
            d.y.atan2(d.x)
        };
        for (&v, list) in neighbours.iter_mut() {
            list.sort_by(|&a, &b| angle(v, a).total_cmp(&angle(v, b)));
        }
        let mut used: std::collections::HashSet<(usize, usize)> = std::collections::HashSet::new();
        let mut cells = Vec::new();
        for (&start, list) in &neighbours {
            for &first in list {
                if used.contains(&(start, first)) {
                    continue;
                }
                let mut cell = vec![start];
                let (mut from, mut at) = (start, first);
                used.insert((start, first));
                while at != start {
                    cell.push(at);
                    // The next half-edge: the neighbour just clockwise of where we came from.
                    let around = &neighbours[&at];
                    let back = around.iter().position(|&w| w == from).expect("both ways");
                    let next = around[(back + around.len() - 1) % around.len()];
                    from = at;
                    at = next;
                    if !used.insert((from, at)) || cell.len() > edges.len() + 1 {
                        break;
                    }
                }
                let area: f64 = (0..cell.len())
                    .map(|k| {
                        position[&cell[k]]
                            .coords
                            .perp(&position[&cell[(k + 1) % cell.len()]].coords)
                    })
                    .sum();
                if area > 0.0 && at == start {
                    cells.push(cell);
                }
            }
        }
        if cells.len() < 2 {
            return Err(NanofoldError::invalid(
                format!("faces[{f}]"),
                "concave",
                "cutting the concave face at its reflex corners left no convex pieces",
            ));
        }
        Ok(cells)
    }

    /// Drops each vertex that only two faces hold and where both run straight on (within
    /// `tolerance` of the line through its neighbours): the two faces' edges through it are
    /// one edge. Returns how many.
    fn drop_straight_corners(&mut self, tolerance: f64) -> usize {
        let mut holders = vec![0usize; self.vertices.len()];
        for face in &self.faces {
            for &v in face {
                holders[v] += 1;
            }
        }
        let straight = |mesh: &Mesh, face: &[usize], k: usize| {
            let n = face.len();
            let (a, b, c) = (
                mesh.vertices[face[(k + n - 1) % n]],
                mesh.vertices[face[k]],
                mesh.vertices[face[(k + 1) % n]],
            );
            let along = c - a;
            along.norm() > 0.0 && (b - a).cross(&along).norm() / along.norm() <= tolerance && (b - a).dot(&along) > 0.0
        };
        let mut dropped = vec![false; self.vertices.len()];
        for v in 0..self.vertices.len() {
            if holders[v] != 2 {
                continue;
            }
            let every = self.faces.iter().all(|face| match face.iter().position(|&w| w == v) {
                Some(k) => straight(self, face, k),
                None => true,
            });
            dropped[v] = every;
        }
        for face in &mut self.faces {
            face.retain(|&v| !dropped[v]);
        }
        dropped.iter().filter(|&&d| d).count()
    }

    /// Removes vertices no face holds, renumbering the faces.
    fn drop_unused(&mut self) {
        let mut used = vec![false; self.vertices.len()];
        self.faces.iter().flatten().for_each(|&v| used[v] = true);
        let mut index = vec![usize::MAX; self.vertices.len()];
        let mut kept = Vec::new();
        for (v, p) in self.vertices.iter().enumerate() {
            if used[v] {
                index[v] = kept.len();
                kept.push(*p);
            }
        }
        self.vertices = kept;
        for face in &mut self.faces {
            face.iter_mut().for_each(|v| *v = index[*v]);
        }
    }
}

/// Where the ray from corner `k` of a polygon along `direction` first meets the outline:
/// the edge (its first corner's index) and the parameter along it, skipping the two
/// edges at `k`.
fn first_hit(polygon: &[Point2<f64>], k: usize, direction: Vector2<f64>) -> Option<(usize, f64)> {
    let n = polygon.len();
    let origin = polygon[k];
    let mut best: Option<(f64, usize, f64)> = None;
    for edge in 0..n {
        if edge == k || (edge + 1) % n == k {
            continue;
        }
        let (a, b) = (polygon[edge], polygon[(edge + 1) % n]);
        let s = b - a;
        let denominator = direction.perp(&s);
        if denominator.abs() <= 1e-15 * s.norm() {
            continue;
        }
        let distance = (a - origin).perp(&s) / denominator;
        let t = (a - origin).perp(&direction) / denominator;
        if distance > 0.0 && (-1e-12..=1.0 + 1e-12).contains(&t) && best.is_none_or(|(d, _, _)| distance < d) {
            best = Some((distance, edge, t.clamp(0.0, 1.0)));
        }
    }
    best.map(|(_, edge, t)| (edge, t))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_faces() -> (Vec<Point3<f64>>, Vec<Vec<usize>>) {
        // The unit cube's corners and its six faces, each cut into two triangles.
        let vertices: Vec<Point3<f64>> = (0..8)
            .map(|k| Point3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let faces = quads
            .iter()
            .flat_map(|q| [vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]])
            .collect();
        (vertices, faces)
    }

    #[test]
    fn a_cube_of_twelve_triangles_is_six_squares_again() {
        let (vertices, faces) = square_faces();
        let (solid, reading) = solid_from_mesh(vertices, faces, Precision::EXACT, MergeCoplanar::Auto, "test").unwrap();
        assert_eq!((solid.faces.len(), solid.vertices.len()), (6, 8));
        assert!(solid.faces.iter().all(|f| f.len() == 4));
        assert!(reading.merged);
        // Kept as written when asked: twelve triangles, flat hinges between pairs.
        let (vertices, faces) = square_faces();
        let (solid, _) = solid_from_mesh(vertices, faces, Precision::EXACT, MergeCoplanar::Never, "test").unwrap();
        assert_eq!(solid.faces.len(), 12);
    }

    #[test]
    fn split_copies_of_a_vertex_weld_within_the_coincident_tolerance() {
        // Each triangle with its own copies of its corners, as STL writes them, each copy
        // moved by a rounding of 1e-7.
        let (vertices, faces) = square_faces();
        let mut copies = Vec::new();
        let mut separate = Vec::new();
        for (f, face) in faces.iter().enumerate() {
            let mut corners = Vec::new();
            for (k, &v) in face.iter().enumerate() {
                let wobble = if (f + k) % 2 == 0 { 0.9e-7 } else { -0.9e-7 };
                copies.push(vertices[v] + Vector3::new(wobble, -wobble, wobble));
                corners.push(copies.len() - 1);
            }
            separate.push(corners);
        }
        let precision = Precision {
            rounding: 1e-7,
            source: crate::geometry::precision::PrecisionSource::Digits,
            significant_digits: 7,
        };
        let (solid, reading) = solid_from_mesh(copies, separate, precision, MergeCoplanar::Auto, "test").unwrap();
        assert_eq!((solid.vertices.len(), solid.faces.len()), (8, 6));
        assert_eq!(reading.vertices_welded, 36 - 8);
    }

    #[test]
    fn an_l_shaped_face_is_cut_at_its_reflex_corner_into_three_squares() {
        // An L prism (three unit cubes in an L, one layer): its top and bottom are L-shaped
        // when merged, and each is cut at its reflex corner along both edges' extensions.
        let outline = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
        let mut vertices = Vec::new();
        for z in [0.0, 1.0] {
            for &(x, y) in &outline {
                vertices.push(Point3::new(x, y, z));
            }
        }
        let n = outline.len();
        let mut faces = Vec::new();
        // Bottom and top as fans of triangles from corner 0 (bottom wound downwards).
        for k in 1..n - 1 {
            faces.push(vec![0, k + 1, k]);
            faces.push(vec![n, n + k, n + k + 1]);
        }
        for k in 0..n {
            let (a, b) = (k, (k + 1) % n);
            faces.push(vec![a, b, n + b]);
            faces.push(vec![a, n + b, n + a]);
        }
        let (solid, reading) = solid_from_mesh(vertices, faces, Precision::EXACT, MergeCoplanar::Auto, "test").unwrap();
        assert_eq!(reading.concave_faces_cut, 2);
        // 3 + 3 squares, 6 sides: the long sides carry the cut's new corner.
        assert_eq!(solid.faces.len(), 12);
        assert!((solid.volume() - 3.0).abs() < 1e-12);
        let squares = solid.faces.iter().filter(|f| f.len() == 4).count();
        assert!(squares >= 6, "{:?}", solid.faces);
    }
}
