//! A net laid flat (`docs/model.md#nets-of-polyhedra`): an edge unfolding's faces placed in
//! the plane across its folds, which pairs of faces overlap, and the scores a designer ranks
//! nets by (radius of gyration, leaves, seam length, footprint).

use super::polyhedron::{DualEdge, Polyhedron};
use super::unfoldings::Tree;
use nalgebra::{Point2, Rotation2, Vector2, Vector3};

/// A net in the plane: every face's corners, in the face's own winding (counter-clockwise,
/// outward normal up).
#[derive(Debug, Clone, PartialEq)]
pub struct FlatNet {
    /// Each face's corners, in the order of the solid's face.
    pub faces: Vec<Vec<Point2<f64>>>,
    /// The dual edges that are folds.
    pub folds: Vec<usize>,
    /// The dual edges that are cut: each a seam pair, its two copies on the net's boundary.
    pub seams: Vec<usize>,
}

/// Each face of the solid in its own plane: corners in a frame with the outward normal up.
fn face_shapes(solid: &Polyhedron) -> Vec<Vec<Point2<f64>>> {
    (0..solid.faces.len())
        .map(|f| {
            let face = &solid.faces[f];
            let n = solid.face_normal(f).normalize();
            let origin = solid.vertices[face[0]];
            let x = (solid.vertices[face[1]] - origin).normalize();
            let y: Vector3<f64> = n.cross(&x);
            face.iter()
                .map(|&v| {
                    let d = solid.vertices[v] - origin;
                    Point2::new(d.dot(&x), d.dot(&y))
                })
                .collect()
        })
        .collect()
}

/// A solid's dual edges and faces in their own planes, found once for laying many of its
/// nets flat and scoring them.
#[derive(Debug, Clone)]
pub struct NetLayout<'s> {
    solid: &'s Polyhedron,
    /// The solid's dual edges (`Polyhedron::dual_edges`).
    pub edges: Vec<DualEdge>,
    shapes: Vec<Vec<Point2<f64>>>,
}

impl<'s> NetLayout<'s> {
    /// The layout of `solid`'s nets.
    pub fn new(solid: &'s Polyhedron) -> Self {
        NetLayout {
            solid,
            edges: solid.dual_edges(),
            shapes: face_shapes(solid),
        }
    }

    /// Lays the unfolding `tree` flat: face 0 as it is in its own plane, then each face
    /// across its fold from the one before it, moved rigidly (turned, not mirrored) so that
    /// its copy of the fold's edge lies on its parent's; with both outward normals up it
    /// lands on the other side of the edge.
    pub fn lay_flat(&self, tree: Tree) -> FlatNet {
        let (solid, edges, shapes) = (self.solid, &self.edges, &self.shapes);
        let folds: Vec<usize> = (0..edges.len()).filter(|&k| tree >> k & 1 == 1).collect();
        let seams: Vec<usize> = (0..edges.len()).filter(|&k| tree >> k & 1 == 0).collect();
        let mut placed: Vec<Option<Vec<Point2<f64>>>> = vec![None; solid.faces.len()];
        placed[0] = Some(shapes[0].clone());
        let mut queue = vec![0];
        while let Some(parent) = queue.pop() {
            for &k in &folds {
                let e: &DualEdge = &edges[k];
                let child = match e.faces {
                    [a, b] if a == parent => b,
                    [a, b] if b == parent => a,
                    _ => continue,
                };
                if placed[child].is_some() {
                    continue;
                }
                let at = |face: usize, v: usize| solid.faces[face].iter().position(|&w| w == v).expect("edge on face");
                let here = placed[parent].as_ref().expect("placed before its children");
                let (pa, pb) = (here[at(parent, e.vertices[0])], here[at(parent, e.vertices[1])]);
                let (ca, cb) = (
                    shapes[child][at(child, e.vertices[0])],
                    shapes[child][at(child, e.vertices[1])],
                );
                let turn = Rotation2::rotation_between(&(cb - ca), &(pb - pa));
                let moved = shapes[child].iter().map(|p| pa + turn * (p - ca)).collect();
                placed[child] = Some(moved);
                queue.push(child);
            }
        }
        FlatNet {
            faces: placed
                .into_iter()
                .map(|f| f.expect("a spanning tree reaches every face"))
                .collect(),
            folds,
            seams,
        }
    }

    /// Faces with one fold (the net tree's leaves).
    pub fn leaves(&self, tree: Tree) -> usize {
        let mut degree = vec![0usize; self.solid.faces.len()];
        for (k, e) in self.edges.iter().enumerate() {
            if tree >> k & 1 == 1 {
                degree[e.faces[0]] += 1;
                degree[e.faces[1]] += 1;
            }
        }
        degree.iter().filter(|&&d| d == 1).count()
    }

    /// The total length of the cut edges: each a seam that must meet its twin again.
    pub fn seam_length(&self, tree: Tree) -> f64 {
        let vertices = &self.solid.vertices;
        self.edges
            .iter()
            .enumerate()
            .filter(|&(k, _)| tree >> k & 1 == 0)
            .map(|(_, e)| (vertices[e.vertices[0]] - vertices[e.vertices[1]]).norm())
            .sum()
    }
}

/// Lays the unfolding `tree` of `solid` flat ([`NetLayout::lay_flat`]).
pub fn lay_flat(solid: &Polyhedron, tree: Tree) -> FlatNet {
    NetLayout::new(solid).lay_flat(tree)
}

/// Whether two convex polygons' interiors overlap by more than `tolerance` (separating
/// axes: shared edges and corners do not count).
pub fn convex_overlap(a: &[Point2<f64>], b: &[Point2<f64>], tolerance: f64) -> bool {
    for polygon in [a, b] {
        for k in 0..polygon.len() {
            let edge = polygon[(k + 1) % polygon.len()] - polygon[k];
            let axis = Vector2::new(-edge.y, edge.x).normalize();
            let span = |p: &[Point2<f64>]| {
                p.iter()
                    .map(|q| q.coords.dot(&axis))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
            };
            let ((a_lo, a_hi), (b_lo, b_hi)) = (span(a), span(b));
            if a_hi.min(b_hi) - a_lo.max(b_lo) <= tolerance {
                return false;
            }
        }
    }
    true
}

impl FlatNet {
    /// The largest distance of a corner from the net's first corner: what the tolerances
    /// are relative to.
    fn size(&self) -> f64 {
        let first = self.faces[0][0];
        self.faces
            .iter()
            .flatten()
            .map(|p| (p - first).norm())
            .fold(0.0, f64::max)
    }

    /// Every pair of faces whose interiors overlap (more than 1e-9 of the net's size deep).
    pub fn overlapping_pairs(&self) -> Vec<(usize, usize)> {
        let tolerance = 1e-9 * self.size();
        let mut pairs = Vec::new();
        for i in 0..self.faces.len() {
            for j in i + 1..self.faces.len() {
                if convex_overlap(&self.faces[i], &self.faces[j], tolerance) {
                    pairs.push((i, j));
                }
            }
        }
        pairs
    }

    /// Area, area centroid and polar second moment about the centroid of each face.
    fn moments(face: &[Point2<f64>]) -> (f64, Vector2<f64>, f64) {
        // Over the fan of triangles (p₀, pₖ, pₖ₊₁).
        let (mut area, mut first, mut second) = (0.0, Vector2::zeros(), 0.0);
        let origin = face[0].coords;
        for k in 1..face.len() - 1 {
            let (a, b) = (face[k].coords - origin, face[k + 1].coords - origin);
            let t = 0.5 * (a.x * b.y - a.y * b.x);
            area += t;
            first += t * (a + b) / 3.0;
            // ∫|x|² over the triangle (0, a, b): t (|a|² + |b|² + a·b) / 6.
            second += t * (a.norm_squared() + b.norm_squared() + a.dot(&b)) / 6.0;
        }
        let centroid = first / area;
        (area, origin + centroid, second - area * centroid.norm_squared())
    }

    /// The radius of gyration of the flat net: Rg² = (1/A) Σ_f A_f (|c_f − c|² + J_f/A_f).
    pub fn radius_of_gyration(&self) -> f64 {
        let moments: Vec<_> = self.faces.iter().map(|f| Self::moments(f)).collect();
        let area: f64 = moments.iter().map(|m| m.0).sum();
        let centre = moments.iter().fold(Vector2::zeros(), |s, m| s + m.0 * m.1) / area;
        let sum: f64 = moments
            .iter()
            .map(|(a, c, j)| a * (c - centre).norm_squared() + j)
            .sum();
        (sum / area).sqrt()
    }

    /// The smallest rectangle the net fits in, (long side, short side), over every turn of
    /// the net: one of the convex hull's edges lies along a side of the smallest (Freeman &
    /// Shapira 1975), so only those turns are tried.
    pub fn footprint(&self) -> (f64, f64) {
        let hull = convex_hull_2d(self.faces.iter().flatten().copied().collect());
        let mut best = (f64::INFINITY, 0.0, 0.0);
        for k in 0..hull.len() {
            let edge = hull[(k + 1) % hull.len()] - hull[k];
            let length = edge.norm();
            if length == 0.0 {
                continue;
            }
            let (u, v) = (edge / length, Vector2::new(-edge.y, edge.x) / length);
            let span = |axis: Vector2<f64>| {
                hull.iter()
                    .map(|p| p.coords.dot(&axis))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
            };
            let ((a0, a1), (b0, b1)) = (span(u), span(v));
            let (w, h) = (a1 - a0, b1 - b0);
            if w * h < best.0 {
                best = (w * h, w.max(h), w.min(h));
            }
        }
        (best.1, best.2)
    }
}

/// The convex hull of points in the plane, counter-clockwise (Andrew's monotone chain).
fn convex_hull_2d(mut points: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Point2<f64>, a: Point2<f64>, b: Point2<f64>| (a - o).perp(&(b - o));
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in ordered {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Faces with one fold (the net tree's leaves).
pub fn leaves(solid: &Polyhedron, tree: Tree) -> usize {
    NetLayout::new(solid).leaves(tree)
}

/// The total length of the cut edges: each a seam that must meet its twin again.
pub fn seam_length(solid: &Polyhedron, tree: Tree) -> f64 {
    NetLayout::new(solid).seam_length(tree)
}
