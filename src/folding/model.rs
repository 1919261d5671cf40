//! The immutable folding model of a crease pattern: each vertex star in crease columns,
//! the spanning tree of panels that places them, and each panel's triangles.

use crate::error::{NanofoldError, Result};
use crate::pattern::crease_pattern::{CreasePattern, EdgeKind};
use std::collections::VecDeque;

/// The creases around one interior vertex, as columns of the fold-angle vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Star {
    /// The vertex.
    pub vertex: usize,
    /// Its creases counter-clockwise, as indices into the fold-angle vector.
    pub columns: Vec<usize>,
    /// Sector angle after each crease, rad (sum 2π).
    pub sector_angles: Vec<f64>,
}

/// One edge of the spanning tree of panels: `panel` is placed from `parent` by a rotation
/// about crease `edge` (fold-angle column `column`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TreeStep {
    /// The panel placed.
    pub panel: usize,
    /// The panel it hangs from (already placed).
    pub parent: usize,
    /// The crease between them.
    pub edge: usize,
    /// The crease's fold-angle column.
    pub column: usize,
    /// Whether `panel` lies left of the crease seen from `edges[edge][0]` to `[1]`.
    pub panel_on_left: bool,
}

/// A crease pattern prepared for rigid kinematics (`docs/model.md#rigid-folding`).
#[derive(Debug, Clone)]
pub struct FoldingModel {
    /// The pattern.
    pub pattern: CreasePattern,
    /// Each interior vertex's star.
    pub stars: Vec<Star>,
    /// The fold-angle column of each edge (None for boundary and facet edges).
    pub column_of_edge: Vec<Option<usize>>,
    /// The panel held fixed (the one nearest the pattern's centre).
    pub root_panel: usize,
    /// Panels in the order they are placed, each from a placed parent.
    pub tree: Vec<TreeStep>,
    /// Creases between two panels that are not tree edges (their agreement is implied by
    /// the vertex closures and checked by [`super::tree_mismatch`]).
    pub off_tree: Vec<usize>,
    /// The distinct vertices of each panel, sorted.
    pub panel_vertices: Vec<Vec<usize>>,
    /// Each panel's triangles (vertex indices, counter-clockwise in the flat pattern).
    pub panel_triangles: Vec<Vec<[usize; 3]>>,
    /// A panel that holds each vertex.
    pub panel_of_vertex: Vec<usize>,
    /// The diagonal of the pattern's bounding box: the length scale of tolerances.
    pub size: f64,
    /// Whether each fold-angle column is held at its angle (`edges_nanofold:locked`).
    pub locked_columns: Vec<bool>,
    /// (sin, cos) of each star's sector angles, computed when built (closures use them at
    /// every Newton step).
    pub(crate) sector_trig: Vec<Vec<(f64, f64)>>,
    /// The medians over panels of their flat bounding boxes' smaller and larger sides: the
    /// contact test's length scales, computed when built.
    pub(crate) median_panel_sides: [f64; 2],
}

impl FoldingModel {
    /// The angle below which a test of exact geometry (Kawasaki's condition, a crease that
    /// stays flat in a mode) counts a residual as zero, rad: 1e-9, or the pattern's own
    /// precision where its coordinates hold fewer digits.
    pub fn exact_angle_tolerance(&self) -> f64 {
        1e-9_f64.max(self.pattern.angle_precision)
    }

    /// The least depth by which two panels must pass through each other to cross (shallower
    /// is touching), in the pattern's length unit: 1e-12 of its size, or where its
    /// coordinates hold fewer digits, its angle precision over the lever of its size (layers
    /// folded flat tilt by that much from rounding alone). A contact test asks for more
    /// where the state's own placement spread is larger (`docs/model.md#panel-contact`).
    pub fn contact_tolerance(&self) -> f64 {
        (1e-12 * self.size).max(self.pattern.angle_precision * self.size)
    }

    /// Prepares a validated crease pattern.
    pub fn new(pattern: CreasePattern) -> Result<FoldingModel> {
        let ne = pattern.edges.len();
        let mut column_of_edge = vec![None; ne];
        for (column, &e) in pattern.creases.iter().enumerate() {
            column_of_edge[e] = Some(column);
        }
        let stars: Vec<Star> = pattern
            .stars
            .iter()
            .map(|star| Star {
                vertex: star.vertex,
                columns: star
                    .creases
                    .iter()
                    .map(|&e| column_of_edge[e].expect("a star holds creases"))
                    .collect(),
                sector_angles: star.sector_angles.clone(),
            })
            .collect();

        let np = pattern.panel_count;
        let mut panel_vertices = vec![Vec::new(); np];
        let mut panel_triangles = vec![Vec::new(); np];
        for (f, face) in pattern.faces.iter().enumerate() {
            let p = pattern.panel_of_face[f];
            panel_vertices[p].extend_from_slice(face);
            panel_triangles[p].extend(
                triangulate(face, &pattern.vertices)
                    .map_err(|why| NanofoldError::invalid(format!("faces_vertices[{f}]"), format!("{face:?}"), why))?,
            );
        }
        let mut panel_of_vertex = vec![usize::MAX; pattern.vertices.len()];
        for (p, list) in panel_vertices.iter_mut().enumerate() {
            list.sort_unstable();
            list.dedup();
            for &v in list.iter() {
                if panel_of_vertex[v] == usize::MAX {
                    panel_of_vertex[v] = p;
                }
            }
        }

        let (lo, hi) = bounds(&pattern.vertices);
        let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        let root_panel = (0..np)
            .min_by(|&a, &b| {
                let distance = |p: usize| {
                    let c = centroid(&panel_vertices[p], &pattern.vertices);
                    (c[0] - centre[0]).hypot(c[1] - centre[1])
                };
                distance(a).total_cmp(&distance(b))
            })
            .unwrap_or(0);

        // Breadth-first over panels through creases.
        let mut neighbours: Vec<Vec<(usize, usize, bool)>> = vec![Vec::new(); np];
        for &e in &pattern.creases {
            if let [Some(left), Some(right)] = pattern.edge_faces[e] {
                let (pl, pr) = (pattern.panel_of_face[left], pattern.panel_of_face[right]);
                if pl != pr {
                    neighbours[pl].push((pr, e, false));
                    neighbours[pr].push((pl, e, true));
                }
            }
        }
        let mut placed = vec![false; np];
        let mut in_tree = vec![false; ne];
        let mut tree = Vec::with_capacity(np.saturating_sub(1));
        let mut queue = VecDeque::from([root_panel]);
        if np > 0 {
            placed[root_panel] = true;
        }
        while let Some(parent) = queue.pop_front() {
            for &(panel, edge, panel_on_left) in &neighbours[parent] {
                if !placed[panel] {
                    placed[panel] = true;
                    in_tree[edge] = true;
                    tree.push(TreeStep {
                        panel,
                        parent,
                        edge,
                        column: column_of_edge[edge].expect("tree edges are creases"),
                        panel_on_left,
                    });
                    queue.push_back(panel);
                }
            }
        }
        if let Some(p) = placed.iter().position(|&done| !done) {
            return Err(NanofoldError::invalid(
                "faces_vertices",
                format!("panel {p}"),
                "the panel is joined to the others by no crease (the paper must be one disc)",
            ));
        }
        let off_tree = pattern
            .creases
            .iter()
            .copied()
            .filter(|&e| {
                !in_tree[e]
                    && matches!(pattern.edge_faces[e], [Some(l), Some(r)]
                        if pattern.panel_of_face[l] != pattern.panel_of_face[r])
            })
            .collect();
        debug_assert!(
            pattern
                .kinds
                .iter()
                .filter(|k| matches!(k, EdgeKind::Crease(_)))
                .count()
                == pattern.creases.len()
        );
        let locked_columns = pattern.creases.iter().map(|&e| pattern.locked[e]).collect();
        let sector_trig = stars
            .iter()
            .map(|star: &Star| star.sector_angles.iter().map(|a| a.sin_cos()).collect())
            .collect();
        let median_panel_sides = [
            median_panel_side(&pattern.vertices, &panel_vertices, f64::min),
            median_panel_side(&pattern.vertices, &panel_vertices, f64::max),
        ];
        Ok(FoldingModel {
            locked_columns,
            sector_trig,
            median_panel_sides,
            pattern,
            stars,
            column_of_edge,
            root_panel,
            tree,
            off_tree,
            panel_vertices,
            panel_triangles,
            panel_of_vertex,
            size,
        })
    }

    /// Refuses, naming `field`, a vector that is not one fold angle per crease.
    pub fn expect_fold_angles(&self, field: &str, fold_angles: &[f64]) -> Result<()> {
        let n = self.crease_count();
        if fold_angles.len() != n {
            return Err(NanofoldError::invalid(
                field,
                format!("{} fold angles", fold_angles.len()),
                format!("one per crease ({n})"),
            ));
        }
        Ok(())
    }

    /// Number of fold-angle coordinates (creases).
    pub fn crease_count(&self) -> usize {
        self.pattern.creases.len()
    }

    /// Zeroes the locked creases' entries of a velocity or gradient (they do not move).
    pub fn hold_locked(&self, velocity: &mut [f64]) {
        for (v, &locked) in velocity.iter_mut().zip(&self.locked_columns) {
            if locked {
                *v = 0.0;
            }
        }
    }

    /// The fold angles the pattern was read with, one per crease column, rad.
    pub fn given_fold_angles(&self) -> Vec<f64> {
        self.pattern
            .creases
            .iter()
            .map(|&e| self.pattern.fold_angles[e])
            .collect()
    }

    /// The same pattern carrying `fold_angles` (one per crease) as its state. A folded form's
    /// fit is dropped: the state no longer comes from its 3D coordinates.
    pub fn with_fold_angles(&self, fold_angles: &[f64]) -> FoldingModel {
        let mut model = self.clone();
        for (&e, &rho) in model.pattern.creases.iter().zip(fold_angles) {
            model.pattern.fold_angles[e] = rho;
        }
        model.pattern.folded_form = None;
        model
    }
}

/// The median over panels of one side of their flat bounding boxes (`pick` of the two).
fn median_panel_side(vertices: &[[f64; 2]], panel_vertices: &[Vec<usize>], pick: fn(f64, f64) -> f64) -> f64 {
    let mut sizes: Vec<f64> = panel_vertices
        .iter()
        .map(|list| {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for &v in list {
                for k in 0..2 {
                    lo[k] = lo[k].min(vertices[v][k]);
                    hi[k] = hi[k].max(vertices[v][k]);
                }
            }
            pick(hi[0] - lo[0], hi[1] - lo[1])
        })
        .collect();
    if sizes.is_empty() {
        return 0.0;
    }
    sizes.sort_by(f64::total_cmp);
    sizes[sizes.len() / 2]
}

fn bounds(vertices: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

fn centroid(list: &[usize], vertices: &[[f64; 2]]) -> [f64; 2] {
    let n = list.len().max(1) as f64;
    let sum = list
        .iter()
        .fold([0.0, 0.0], |acc, &v| [acc[0] + vertices[v][0], acc[1] + vertices[v][1]]);
    [sum[0] / n, sum[1] / n]
}

/// Triangles of a counter-clockwise simple polygon by ear clipping; vertices where the
/// outline runs straight on are dropped first (they add no area).
fn triangulate(face: &[usize], vertices: &[[f64; 2]]) -> std::result::Result<Vec<[usize; 3]>, &'static str> {
    let cross = |a: usize, b: usize, c: usize| {
        let (p, q, r) = (vertices[a], vertices[b], vertices[c]);
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let scale = face
        .iter()
        .flat_map(|&v| vertices[v])
        .fold(0.0_f64, |m, x| m.max(x.abs()))
        .max(f64::MIN_POSITIVE);
    let flat = 1e-14 * scale * scale;
    let mut ring: Vec<usize> = face.to_vec();
    let mut k = 0;
    while ring.len() > 3 && k < ring.len() {
        let n = ring.len();
        if cross(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]).abs() <= flat {
            ring.remove(k);
        } else {
            k += 1;
        }
    }
    let mut triangles = Vec::with_capacity(ring.len().saturating_sub(2));
    let n = ring.len();
    if n > 3 && (0..n).all(|k| cross(ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]) > flat) {
        // Convex (a face of a planar graph is simple): ear clipping would take the first
        // vertex every time, a fan around the last one. Built at once, it costs O(n) where
        // ear clipping costs O(n²) (a 50 000-sided face).
        triangles.extend((0..n - 3).map(|i| [ring[n - 1], ring[i], ring[i + 1]]));
        triangles.push([ring[n - 3], ring[n - 2], ring[n - 1]]);
        return Ok(triangles);
    }
    ear_clipping(ring, triangles, cross, flat)
}

/// Cuts a simple polygon (counter-clockwise, no straight-through vertices) into triangles
/// by clipping ears, O(n²).
fn ear_clipping(
    mut ring: Vec<usize>,
    mut triangles: Vec<[usize; 3]>,
    cross: impl Fn(usize, usize, usize) -> f64,
    flat: f64,
) -> std::result::Result<Vec<[usize; 3]>, &'static str> {
    while ring.len() > 3 {
        let n = ring.len();
        let ear = (0..n).find(|&k| {
            let (a, b, c) = (ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]);
            cross(a, b, c) > flat
                && ring.iter().all(|&v| {
                    v == a || v == b || v == c || cross(a, b, v) < 0.0 || cross(b, c, v) < 0.0 || cross(c, a, v) < 0.0
                })
        });
        let Some(k) = ear else {
            return Err("the face cannot be cut into triangles (it is not a simple polygon)");
        };
        triangles.push([ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]]);
        ring.remove(k);
    }
    if ring.len() == 3 && cross(ring[0], ring[1], ring[2]) > flat {
        triangles.push([ring[0], ring[1], ring[2]]);
    }
    Ok(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ear_clipping_covers_a_non_convex_face() {
        // An L-shaped hexagon of area 3, with a straight-through vertex on its bottom side.
        let vertices = [
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let face: Vec<usize> = (0..7).collect();
        let triangles = triangulate(&face, &vertices).unwrap();
        assert_eq!(triangles.len(), 4);
        let area: f64 = triangles
            .iter()
            .map(|&[a, b, c]| {
                let (p, q, r) = (vertices[a], vertices[b], vertices[c]);
                0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))
            })
            .inspect(|&a| assert!(a > 0.0))
            .sum();
        assert!((area - 3.0).abs() < 1e-15);
    }

    #[test]
    fn a_convex_face_is_cut_as_ear_clipping_cuts_it() {
        // A regular 40-gon and a convex pentagon: the fan equals the ears, triangle for
        // triangle (so panels keep their triangles whichever path cut them).
        for vertices in [
            (0..40)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / 40.0;
                    [a.cos(), a.sin()]
                })
                .collect::<Vec<_>>(),
            vec![[0.0, 0.0], [2.0, 0.0], [3.0, 1.0], [1.5, 2.5], [-0.5, 1.0]],
        ] {
            let face: Vec<usize> = (0..vertices.len()).collect();
            let cross = |a: usize, b: usize, c: usize| {
                let (p, q, r) = (vertices[a], vertices[b], vertices[c]);
                (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
            };
            let by_ears = ear_clipping(face.clone(), Vec::new(), cross, 1e-14).unwrap();
            assert_eq!(triangulate(&face, &vertices).unwrap(), by_ears);
        }
    }
}
