//! The crease pattern with many vertices (`docs/model.md#crease-patterns`): a planar
//! straight-line graph on a disc of paper, its panels (faces merged across flat `F` edges),
//! and at every interior vertex the star of creases whose loop must close. The single
//! vertex ([`super::VertexPattern`]) is the special case of one interior (or boundary) vertex.

use super::Assignment;
use crate::error::{NanofoldError, Result};
use std::collections::HashMap;
use std::f64::consts::TAU;

/// Most edges a crease pattern may have (a 100 × 100 Miura-ori has about 20 000 creases).
pub const MAX_EDGES: usize = 200_000;

/// Most interior vertices with creases (each a loop that must close) a crease pattern may
/// have: a 174 × 174 Miura-ori has 29 929. Every folding step factorises a system of their
/// closures, whose fill grows faster than their number; past this, folding and unfolding
/// take more than 10 s on 2 cores (`docs/guide/limits.md`). A strip or accordion of
/// 100 000 vertices has none.
pub const MAX_INTERIOR_VERTICES: usize = 30_000;

/// What an edge of the paper is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// The paper's edge (FOLD's `B`).
    Boundary,
    /// A crease that folds (`M`, `V`, `U`).
    Crease(Assignment),
    /// A flat edge inside a panel (`F`: a facet line or a crease held flat); the faces on
    /// both sides are one rigid panel.
    Facet,
}

/// A crease pattern as read, before validation.
#[derive(Debug, Clone, Default)]
pub struct CreasePatternBuilder {
    /// Names the pattern (and its output folder).
    pub name: String,
    /// Flat positions of the vertices.
    pub vertices: Vec<[f64; 2]>,
    /// Each edge's two vertices.
    pub edges: Vec<[usize; 2]>,
    /// Each edge's kind.
    pub kinds: Vec<EdgeKind>,
    /// Each edge's fold angle, rad (valley positive); 0 for boundary and facet edges.
    pub fold_angles: Vec<f64>,
    /// The faces as the file lists them (vertex loops), checked against the faces the
    /// planar graph has; None to rebuild them.
    pub faces: Option<Vec<Vec<usize>>>,
    /// How the input names the fold-angle array (for errors), e.g. `edges_foldAngle`.
    pub angle_field: String,
    /// How far a folded form's faces were from a rigid, developable sheet (None for a
    /// crease pattern read flat).
    pub folded_form: Option<FoldedFormFit>,
    /// Creases held at their fold angle (one per edge, or empty for none).
    pub locked: Vec<bool>,
    /// The file's `frame_unit` (None: unstated), written back on the outputs.
    pub unit: Option<String>,
    /// The largest |coordinate| of the file the flat positions were derived from (a 3D form
    /// developed or projected into the plane), for the pattern's precision; 0 when
    /// `vertices` are the file's own numbers.
    pub source_magnitude: f64,
}

/// What developing a 3D folded form into its crease pattern measured
/// (`docs/model.md#folded-forms`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FoldedFormFit {
    /// Largest distance between two placements of one vertex by different faces (0 for a
    /// developable form), in the file's length unit.
    pub development_error: f64,
    /// Largest distance of a vertex from its face's plane.
    pub face_nonplanarity: f64,
    /// Largest |dihedral angle| across a facet (F) edge: how much the panels bend, rad.
    pub max_facet_angle: f64,
    /// Whether the faces were listed clockwise (the development was mirrored so that
    /// valleys come out positive).
    pub mirrored: bool,
    /// Creases whose dihedral angle has the sign opposite to their assignment (read as
    /// unassigned: the file's assignment is the target, the angle the state).
    pub assignment_conflicts: usize,
    /// Creases read folded flat (within 1e-4 rad of ±π, set to ±π by their assignment).
    pub folded_flat: usize,
}

/// The creases around one interior vertex, counter-clockwise.
#[derive(Debug, Clone, PartialEq)]
pub struct VertexStar {
    /// The vertex.
    pub vertex: usize,
    /// Its creases (edge indices), counter-clockwise from the first.
    pub creases: Vec<usize>,
    /// Sector angle after each crease (to the next one), rad; they sum to 2π.
    pub sector_angles: Vec<f64>,
}

/// A validated crease pattern: a disc of paper cut into rigid panels by creases.
#[derive(Debug, Clone)]
pub struct CreasePattern {
    /// The pattern's name.
    pub name: String,
    /// Flat positions of the vertices.
    pub vertices: Vec<[f64; 2]>,
    /// Each edge's two vertices.
    pub edges: Vec<[usize; 2]>,
    /// Each edge's kind.
    pub kinds: Vec<EdgeKind>,
    /// Each edge's fold angle in the given state, rad (0 for boundary and facet edges).
    pub fold_angles: Vec<f64>,
    /// The faces of the planar graph, counter-clockwise vertex loops.
    pub faces: Vec<Vec<usize>>,
    /// The file's index (`faces_vertices` order) of each face; the faces' own order when
    /// the file lists none.
    pub file_face: Vec<usize>,
    /// The faces on each side of each edge: `[left, right]` seen from `edges[e][0]` to
    /// `edges[e][1]` (None: outside the paper).
    pub edge_faces: Vec<[Option<usize>; 2]>,
    /// The panel each face belongs to (faces joined across facet edges).
    pub panel_of_face: Vec<usize>,
    /// Number of panels.
    pub panel_count: usize,
    /// The creases (edge indices) in file order: the fold-angle coordinates.
    pub creases: Vec<usize>,
    /// Every interior vertex with at least one crease, and its star.
    pub stars: Vec<VertexStar>,
    /// The paper's outline, a counter-clockwise vertex loop.
    pub outline: Vec<usize>,
    /// For a 3D folded form: how far it was from rigid and developable.
    pub folded_form: Option<FoldedFormFit>,
    /// Whether each edge is a crease held at its fold angle.
    pub locked: Vec<bool>,
    /// The file's `frame_unit` (None: unstated), written back on the outputs.
    pub unit: Option<String>,
    /// How the file was read where it could be read more than one way (a 3D sheet flat
    /// within its noise, angles taken as targets), for the evidence.
    pub reading: Vec<String>,
    /// Per edge, the file's angles when they were read as targets, not a state, rad.
    pub target_angles: Option<Vec<f64>>,
    /// Vertices of the file that no edge uses (stray points), left out: their indices in
    /// the file. The others are numbered on without them.
    pub ignored_vertices: Vec<usize>,
    /// The centre of the vertices' bounding box in the file's coordinates. `vertices` are
    /// relative to it, so that nothing computed depends on where the paper lies (a pattern
    /// 1e8 from the origin keeps its digits); outputs add it back.
    pub origin: [f64; 2],
    /// How precisely the file's numbers fix an angle between edges, rad: 16 ε times its
    /// largest coordinate over its shortest edge. Tests of exact geometry (a flat-foldable
    /// vertex, a crease that stays straight) allow at least this much, so a pattern moved
    /// far from the origin, where its coordinates keep fewer digits, keeps its verdicts.
    pub angle_precision: f64,
    /// How precisely the file's numbers fix a position, in its length unit: 16 ε times its
    /// largest coordinate.
    pub length_precision: f64,
}

impl CreasePattern {
    /// A flat position in the file's coordinates.
    pub fn file_point(&self, p: [f64; 2]) -> [f64; 2] {
        [p[0] + self.origin[0], p[1] + self.origin[1]]
    }

    /// A posed (3D) position in the file's coordinates: the flat plane is z = 0.
    pub fn file_point_3d(&self, p: [f64; 3]) -> [f64; 3] {
        [p[0] + self.origin[0], p[1] + self.origin[1], p[2]]
    }

    /// The loop-closure residual of every interior vertex at the state the pattern carries,
    /// rad (`stars` order): what a reader needs to tell a state from targets.
    pub fn given_closure_residuals(&self) -> Vec<f64> {
        let mut by_ray = Vec::new();
        self.stars
            .iter()
            .map(|star| {
                by_ray.clear();
                by_ray.extend(star.creases.iter().map(|&e| self.fold_angles[e]));
                crate::geometry::kinematics::closure_residual(&star.sector_angles, &by_ray)
            })
            .collect()
    }

    /// The flat positions in the file's coordinates.
    pub fn file_vertices(&self) -> Vec<[f64; 2]> {
        self.vertices.iter().map(|&p| self.file_point(p)).collect()
    }

    /// The face (graph index) the file lists as `faces_vertices[index]`, if any.
    pub fn face_from_file(&self, index: usize) -> Option<usize> {
        self.file_face.iter().position(|&f| f == index)
    }
}

/// A builder with a note on how its file was read, and the file's angles as targets.
#[derive(Debug, Clone)]
pub struct ReadBuilder {
    /// The pattern.
    pub builder: CreasePatternBuilder,
    /// How the file was read.
    pub reading: Vec<String>,
    /// The file's angles, read as targets (rad, per edge).
    pub target_angles: Option<Vec<f64>>,
}

impl ReadBuilder {
    /// Validates and builds the pattern, with the reading's notes and targets.
    pub fn build(self) -> Result<CreasePattern> {
        let mut pattern = self.builder.build()?;
        pattern.reading = self.reading;
        pattern.target_angles = self.target_angles;
        Ok(pattern)
    }
}

impl From<CreasePatternBuilder> for ReadBuilder {
    fn from(builder: CreasePatternBuilder) -> ReadBuilder {
        ReadBuilder {
            builder,
            reading: Vec::new(),
            target_angles: None,
        }
    }
}

impl CreasePatternBuilder {
    /// This builder with a note on how the file was read and the targets it gave.
    pub fn with_reading(self, note: String, target_angles: Option<Vec<f64>>) -> ReadBuilder {
        ReadBuilder {
            builder: self,
            reading: vec![note],
            target_angles,
        }
    }

    /// Validates the graph, finds its faces, panels and vertex stars.
    pub fn build(self) -> Result<CreasePattern> {
        let CreasePatternBuilder {
            name,
            vertices,
            edges,
            kinds,
            fold_angles,
            faces: given_faces,
            angle_field,
            folded_form,
            locked,
            unit,
            source_magnitude,
        } = self;
        let (nv, ne) = (vertices.len(), edges.len());
        let largest_coordinate = vertices
            .iter()
            .flatten()
            .fold(source_magnitude.abs(), |m, x| m.max(x.abs()));
        let (origin, vertices) = recentred(vertices);
        if edges.len() > MAX_EDGES {
            return Err(NanofoldError::invalid(
                "edges_vertices",
                format!("{ne} edges"),
                format!("a crease pattern has at most {MAX_EDGES}"),
            ));
        }
        if kinds.len() != ne || fold_angles.len() != ne {
            return Err(NanofoldError::invalid(
                "edges_assignment",
                format!("{} kinds, {} fold angles", kinds.len(), fold_angles.len()),
                format!("expected one per edge ({ne})"),
            ));
        }
        for (e, &[a, b]) in edges.iter().enumerate() {
            if a >= nv || b >= nv || a == b {
                return Err(NanofoldError::invalid(
                    format!("edges_vertices[{e}]"),
                    format!("[{a}, {b}]"),
                    format!("an edge joins two distinct vertices of the {nv}"),
                ));
            }
        }
        for (e, (&kind, &rho)) in kinds.iter().zip(&fold_angles).enumerate() {
            let field = || format!("{angle_field}[{e}]");
            if !rho.is_finite() || rho.abs() > std::f64::consts::PI {
                return Err(NanofoldError::invalid(
                    field(),
                    rho.to_degrees(),
                    "must lie in [−180°, 180°]",
                ));
            }
            let wrong_sign = match kind {
                EdgeKind::Crease(Assignment::Mountain) => rho > 0.0,
                EdgeKind::Crease(Assignment::Valley) => rho < 0.0,
                EdgeKind::Boundary | EdgeKind::Facet => rho != 0.0,
                EdgeKind::Crease(_) => false,
            };
            if wrong_sign {
                return Err(NanofoldError::invalid(
                    field(),
                    format!("{:.6}°", rho.to_degrees()),
                    format!("contradicts the edge's assignment ({kind:?})"),
                ));
            }
        }
        let locked = if locked.is_empty() { vec![false; ne] } else { locked };
        if locked.len() != ne {
            return Err(NanofoldError::invalid(
                "edges_nanofold:locked",
                format!("{} entries", locked.len()),
                format!("expected one per edge ({ne})"),
            ));
        }
        if let Some(e) = (0..ne).find(|&e| locked[e] && !matches!(kinds[e], EdgeKind::Crease(_))) {
            return Err(NanofoldError::invalid(
                format!("edges_nanofold:locked[{e}]"),
                "true",
                "only a crease (M, V, U) can be locked",
            ));
        }
        // A vertex no edge uses (a stray point an editor left) belongs to no face and no
        // panel: it is left out, the others renumbered, and the reading says so.
        let (vertices, edges, given_faces, ignored_vertices) = without_stray_vertices(vertices, edges, given_faces)?;
        let nv = vertices.len();
        let duplicates = duplicate_edge(&edges);
        if let Some((first, second)) = duplicates {
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{second}]"),
                format!("{:?}", edges[second]),
                format!("the same two vertices as edges_vertices[{first}]"),
            ));
        }
        check_planar(&vertices, &edges)?;
        let graph = PlanarGraph::new(&vertices, &edges)?;
        let (faces, outer) = graph.faces(&vertices, &edges);
        check_disc(&faces, &outer, &edges, &kinds, nv)?;
        let outline = outer.into_iter().next().expect("check_disc found one outer loop");
        let file_face = match &given_faces {
            Some(given) => check_given_faces(given, &faces)?,
            None => (0..faces.len()).collect(),
        };
        let edge_faces = graph.edge_faces(&faces, &edges);
        let (panel_of_face, panel_count) = panels(&faces, &edge_faces, &kinds);
        let creases: Vec<usize> = (0..ne).filter(|&e| matches!(kinds[e], EdgeKind::Crease(_))).collect();
        let on_outline: Vec<bool> = {
            let mut on = vec![false; nv];
            outline.iter().for_each(|&v| on[v] = true);
            on
        };
        let stars = vertex_stars(&graph, &kinds, &on_outline)?;
        let length_precision = 16.0 * f64::EPSILON * largest_coordinate;
        let angle_precision = angle_precision(length_precision, &vertices, &edges);
        Ok(CreasePattern {
            name,
            vertices,
            edges,
            kinds,
            fold_angles,
            faces,
            file_face,
            edge_faces,
            panel_of_face,
            panel_count,
            creases,
            stars,
            outline,
            folded_form,
            locked,
            unit,
            reading: Vec::new(),
            target_angles: None,
            ignored_vertices,
            origin,
            angle_precision,
            length_precision,
        })
    }
}

/// Leaves out the vertices no edge uses and renumbers the rest (edges and given faces with
/// them); returns the original indices of those left out. A given face that lists such a
/// vertex is refused, naming it.
#[allow(clippy::type_complexity)]
fn without_stray_vertices(
    vertices: Vec<[f64; 2]>,
    edges: Vec<[usize; 2]>,
    faces: Option<Vec<Vec<usize>>>,
) -> Result<(Vec<[f64; 2]>, Vec<[usize; 2]>, Option<Vec<Vec<usize>>>, Vec<usize>)> {
    let mut used = vec![false; vertices.len()];
    for &[a, b] in &edges {
        used[a] = true;
        used[b] = true;
    }
    let stray: Vec<usize> = (0..vertices.len()).filter(|&v| !used[v]).collect();
    if stray.is_empty() {
        return Ok((vertices, edges, faces, stray));
    }
    if stray.len() == vertices.len() {
        return Err(NanofoldError::invalid(
            "edges_vertices",
            "[]",
            "a crease pattern needs edges (its paper's outline at least)",
        ));
    }
    let mut renumbered = vec![usize::MAX; vertices.len()];
    let mut kept = Vec::with_capacity(vertices.len() - stray.len());
    for (v, point) in vertices.into_iter().enumerate() {
        if used[v] {
            renumbered[v] = kept.len();
            kept.push(point);
        }
    }
    let edges = edges.into_iter().map(|[a, b]| [renumbered[a], renumbered[b]]).collect();
    let faces = match faces {
        None => None,
        Some(faces) => Some(
            faces
                .into_iter()
                .enumerate()
                .map(|(f, face)| {
                    face.iter()
                        .map(|&v| match renumbered.get(v) {
                            Some(&n) if n != usize::MAX => Ok(n),
                            _ => Err(NanofoldError::invalid(
                                format!("faces_vertices[{f}]"),
                                format!("{face:?}"),
                                format!("vertex {v} is on no edge"),
                            )),
                        })
                        .collect::<Result<Vec<usize>>>()
                })
                .collect::<Result<Vec<_>>>()?,
        ),
    };
    Ok((kept, edges, faces, stray))
}

/// The length precision over the shortest edge: the angle the file's rounding can move
/// (see [`CreasePattern::angle_precision`]).
fn angle_precision(length_precision: f64, vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> f64 {
    let shortest = edges
        .iter()
        .map(|&[a, b]| (vertices[b][0] - vertices[a][0]).hypot(vertices[b][1] - vertices[a][1]))
        .fold(f64::INFINITY, f64::min);
    if shortest > 0.0 && shortest.is_finite() {
        length_precision / shortest
    } else {
        0.0
    }
}

/// The centre of the points' bounding box, and the points relative to it (exact where a
/// point lies within a factor 2 of the centre, as on a pattern far from the origin).
fn recentred(mut vertices: Vec<[f64; 2]>) -> ([f64; 2], Vec<[f64; 2]>) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if vertices.is_empty() || !(0..2).all(|k| lo[k].is_finite() && hi[k].is_finite()) {
        return ([0.0; 2], vertices);
    }
    let origin = [0, 1].map(|k| lo[k] / 2.0 + hi[k] / 2.0);
    for p in &mut vertices {
        for k in 0..2 {
            p[k] -= origin[k];
        }
    }
    (origin, vertices)
}

/// The first pair of edges joining the same two vertices.
fn duplicate_edge(edges: &[[usize; 2]]) -> Option<(usize, usize)> {
    let mut seen: HashMap<[usize; 2], usize> = HashMap::with_capacity(edges.len());
    for (e, &[a, b]) in edges.iter().enumerate() {
        if let Some(&first) = seen.get(&[a.min(b), a.max(b)]) {
            return Some((first, e));
        }
        seen.insert([a.min(b), a.max(b)], e);
    }
    None
}

/// No two edges may cross, and no vertex may lie inside an edge: the graph must be a
/// planar straight-line graph. Only edges whose boxes overlap are compared
/// ([`crate::geometry::broad_phase`]), so the test costs about O(E log E) however the edges
/// are spread (a vertex far from the rest, a long strip).
fn check_planar(vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> Result<()> {
    if edges.is_empty() {
        return Ok(());
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &[a, b] in edges {
        for p in [vertices[a], vertices[b]] {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let tolerance = 1e-12 * size;
    let boxes: Vec<([f64; 2], [f64; 2])> = edges
        .iter()
        .map(|&[a, b]| {
            let (p, q) = (vertices[a], vertices[b]);
            // Widened by the tolerance: a vertex that far off an axis-aligned edge touches it.
            (
                [p[0].min(q[0]) - tolerance, p[1].min(q[1]) - tolerance],
                [p[0].max(q[0]) + tolerance, p[1].max(q[1]) + tolerance],
            )
        })
        .collect();
    let cross = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    for (e, f) in crate::geometry::broad_phase::overlapping_pairs(&boxes) {
        let ([a, b], [c, d]) = (edges[e], edges[f]);
        let shared = [a, b].iter().filter(|v| [c, d].contains(v)).count();
        let (p, q, r, t) = (vertices[a], vertices[b], vertices[c], vertices[d]);
        let length = |u: [f64; 2], v: [f64; 2]| (v[0] - u[0]).hypot(v[1] - u[1]);
        let (d1, d2) = (cross(p, q, r) / length(p, q), cross(p, q, t) / length(p, q));
        let (d3, d4) = (cross(r, t, p) / length(r, t), cross(r, t, q) / length(r, t));
        let crosses = shared == 0
            && ((d1 > tolerance && d2 < -tolerance) || (d1 < -tolerance && d2 > tolerance))
            && ((d3 > tolerance && d4 < -tolerance) || (d3 < -tolerance && d4 > tolerance));
        // A vertex of one edge strictly inside the other (a T-junction).
        let inside = |u: [f64; 2], from: [f64; 2], to: [f64; 2], distance: f64| {
            let along = ((u[0] - from[0]) * (to[0] - from[0]) + (u[1] - from[1]) * (to[1] - from[1]))
                / length(from, to).powi(2);
            distance.abs() <= tolerance && along > 1e-9 && along < 1.0 - 1e-9
        };
        let touches = (!([a, b].contains(&c)) && inside(r, p, q, d1))
            || (!([a, b].contains(&d)) && inside(t, p, q, d2))
            || (!([c, d].contains(&a)) && inside(p, r, t, d3))
            || (!([c, d].contains(&b)) && inside(q, r, t, d4));
        if crosses || touches {
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{}]", e.max(f)),
                format!("edges {} and {}", e.min(f), e.max(f)),
                if crosses {
                    "two edges cross away from a vertex: split them at a shared vertex"
                } else {
                    "a vertex lies inside another edge: split that edge at the vertex"
                },
            ));
        }
    }
    Ok(())
}

/// Edges around each vertex sorted by direction, and the half-edge structure.
struct PlanarGraph {
    /// (edge, direction angle in [0, 2π)) around each vertex, counter-clockwise.
    around: Vec<Vec<(usize, f64)>>,
}

impl PlanarGraph {
    fn new(vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> Result<PlanarGraph> {
        let mut around: Vec<Vec<(usize, f64)>> = vec![Vec::new(); vertices.len()];
        for (e, &[a, b]) in edges.iter().enumerate() {
            for (from, to) in [(a, b), (b, a)] {
                let (dx, dy) = (vertices[to][0] - vertices[from][0], vertices[to][1] - vertices[from][1]);
                if dx == 0.0 && dy == 0.0 {
                    return Err(NanofoldError::invalid(
                        format!("edges_vertices[{e}]"),
                        format!("[{a}, {b}]"),
                        "the edge has zero length (its vertices coincide)",
                    ));
                }
                around[from].push((e, dy.atan2(dx).rem_euclid(TAU)));
            }
        }
        for (v, list) in around.iter_mut().enumerate() {
            list.sort_by(|x, y| x.1.total_cmp(&y.1));
            let k = list.len();
            for j in 0..k {
                let gap = (list[(j + 1) % k].1 - list[j].1).rem_euclid(TAU);
                if k > 1 && gap < super::MIN_SECTOR_RAD {
                    return Err(NanofoldError::invalid(
                        format!("edges_vertices[{}]", list[(j + 1) % k].0),
                        format!("edges {} and {} at vertex {v}", list[j].0, list[(j + 1) % k].0),
                        "two edges leave the vertex in the same direction (overlapping edges)",
                    ));
                }
            }
        }
        Ok(PlanarGraph { around })
    }

    /// The other end of edge `e` seen from `v`.
    fn other(edges: &[[usize; 2]], e: usize, v: usize) -> usize {
        if edges[e][0] == v {
            edges[e][1]
        } else {
            edges[e][0]
        }
    }

    /// Every face cycle of the graph: (inner faces counter-clockwise, outer loops). A face
    /// is traced with its inside on the left: from the half-edge u → v the next leaves v
    /// along the edge just clockwise of v → u.
    fn faces(&self, vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> (Vec<Vec<usize>>, Vec<Vec<usize>>) {
        // Position of each edge in the sorted list around each of its ends.
        let mut slot: HashMap<(usize, usize), usize> = HashMap::with_capacity(2 * edges.len());
        for (v, list) in self.around.iter().enumerate() {
            for (j, &(e, _)) in list.iter().enumerate() {
                slot.insert((v, e), j);
            }
        }
        let mut used: std::collections::HashSet<(usize, usize)> =
            std::collections::HashSet::with_capacity(2 * edges.len());
        let (mut inner, mut outer) = (Vec::new(), Vec::new());
        for (e, &[a, b]) in edges.iter().enumerate() {
            for start in [a, b] {
                if used.contains(&(start, e)) {
                    continue;
                }
                let mut cycle = Vec::new();
                let (mut from, mut edge) = (start, e);
                // Each half-edge is used once, so a walk ends within 2E steps.
                while used.insert((from, edge)) {
                    cycle.push(from);
                    let to = PlanarGraph::other(edges, edge, from);
                    let list = &self.around[to];
                    let j = slot[&(to, edge)];
                    edge = list[(j + list.len() - 1) % list.len()].0;
                    from = to;
                }
                let area: f64 = (0..cycle.len())
                    .map(|k| {
                        let (p, q) = (vertices[cycle[k]], vertices[cycle[(k + 1) % cycle.len()]]);
                        p[0] * q[1] - q[0] * p[1]
                    })
                    .sum();
                if area > 0.0 {
                    inner.push(cycle);
                } else {
                    outer.push(cycle);
                }
            }
        }
        (inner, outer)
    }

    /// [left, right] face of each edge, seen from edges[e][0] to edges[e][1].
    fn edge_faces(&self, faces: &[Vec<usize>], edges: &[[usize; 2]]) -> Vec<[Option<usize>; 2]> {
        let mut index: HashMap<[usize; 2], usize> = HashMap::with_capacity(edges.len());
        for (e, &[a, b]) in edges.iter().enumerate() {
            index.insert([a, b], e);
        }
        let mut sides = vec![[None, None]; edges.len()];
        for (f, face) in faces.iter().enumerate() {
            for k in 0..face.len() {
                let (u, v) = (face[k], face[(k + 1) % face.len()]);
                // The face lies left of u → v.
                if let Some(&e) = index.get(&[u, v]) {
                    sides[e][0] = Some(f);
                } else if let Some(&e) = index.get(&[v, u]) {
                    sides[e][1] = Some(f);
                }
            }
        }
        sides
    }
}

/// The paper must be one disc: a connected graph with one outer loop, V − E + F = 1, the
/// outer loop made of boundary edges only and no boundary edge inside.
fn check_disc(
    faces: &[Vec<usize>],
    outer: &[Vec<usize>],
    edges: &[[usize; 2]],
    kinds: &[EdgeKind],
    vertex_count: usize,
) -> Result<()> {
    if faces.is_empty() {
        return Err(NanofoldError::invalid(
            "edges_vertices",
            format!("{} edges", edges.len()),
            "the edges enclose no region: the paper needs at least one face (an outline of boundary (B) edges)",
        ));
    }
    if outer.len() != 1 {
        return Err(NanofoldError::invalid(
            "edges_vertices",
            format!("{} separate outlines", outer.len()),
            "the paper must be one connected sheet (a disc): a vertex or edge lies apart from the rest",
        ));
    }
    let used: usize = {
        let mut seen = vec![false; vertex_count];
        edges.iter().for_each(|&[a, b]| {
            seen[a] = true;
            seen[b] = true;
        });
        seen.iter().filter(|&&s| s).count()
    };
    let euler = used as i64 - edges.len() as i64 + faces.len() as i64;
    if euler != 1 {
        return Err(NanofoldError::invalid(
            "edges_vertices",
            format!("V − E + F = {euler}"),
            "the paper must be a disc (V − E + F = 1): holes and cuts are not supported yet",
        ));
    }
    let loop_ = &outer[0];
    let mut on_outline: std::collections::HashSet<[usize; 2]> = std::collections::HashSet::new();
    for k in 0..loop_.len() {
        let (u, v) = (loop_[k], loop_[(k + 1) % loop_.len()]);
        if !on_outline.insert([u.min(v), u.max(v)]) {
            // The outline walks this edge both ways: no paper on either side.
            let e = edges
                .iter()
                .position(|&[a, b]| [a.min(b), a.max(b)] == [u.min(v), u.max(v)])
                .unwrap_or(0);
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{e}]"),
                format!("{:?}", edges[e]),
                "the edge sticks out of the paper (no face on either side): remove it or close the outline",
            ));
        }
    }
    for (e, &[a, b]) in edges.iter().enumerate() {
        let outside = on_outline.contains(&[a.min(b), a.max(b)]);
        match (outside, kinds[e]) {
            (true, EdgeKind::Boundary) | (false, EdgeKind::Crease(_) | EdgeKind::Facet) => {}
            (true, _) => {
                return Err(NanofoldError::invalid(
                    format!("edges_assignment[{e}]"),
                    format!("{:?}", kinds[e]),
                    "this edge lies on the paper's outline: it must be a boundary (B) edge (a crease there is a cut)",
                ))
            }
            (false, _) => {
                return Err(NanofoldError::invalid(
                    format!("edges_assignment[{e}]"),
                    "B",
                    "a boundary edge inside the paper is a cut: cuts and holes are not supported yet",
                ))
            }
        }
    }
    Ok(())
}

/// Given faces must be the graph's faces (each a rotation of one, either orientation); the
/// file's index of each graph face.
fn check_given_faces(given: &[Vec<usize>], faces: &[Vec<usize>]) -> Result<Vec<usize>> {
    let key = |face: &[usize]| {
        let mut sorted = face.to_vec();
        sorted.sort_unstable();
        sorted
    };
    let known: HashMap<Vec<usize>, usize> = faces.iter().enumerate().map(|(g, f)| (key(f), g)).collect();
    let mut file_face = vec![usize::MAX; faces.len()];
    for (i, face) in given.iter().enumerate() {
        match known.get(&key(face)) {
            Some(&g) => file_face[g] = i,
            None => {
                return Err(NanofoldError::invalid(
                    format!("faces_vertices[{i}]"),
                    format!("{face:?}"),
                    "not a face of the crease pattern's edges (faces must be the regions the edges enclose)",
                ))
            }
        }
    }
    if given.len() != faces.len() {
        return Err(NanofoldError::invalid(
            "faces_vertices",
            format!("{} faces", given.len()),
            format!("the edges enclose {} faces", faces.len()),
        ));
    }
    let mut listed = vec![false; given.len()];
    for &i in file_face.iter().filter(|&&i| i != usize::MAX) {
        listed[i] = true;
    }
    if let Some(i) = listed.iter().position(|&seen| !seen) {
        return Err(NanofoldError::invalid(
            format!("faces_vertices[{i}]"),
            format!("{:?}", given[i]),
            "lists a face twice",
        ));
    }
    Ok(file_face)
}

/// Every interior vertex with at least one crease, and its star (creases counter-clockwise,
/// the sector angles between them); at most [`MAX_INTERIOR_VERTICES`].
fn vertex_stars(graph: &PlanarGraph, kinds: &[EdgeKind], on_outline: &[bool]) -> Result<Vec<VertexStar>> {
    let mut stars = Vec::new();
    for v in (0..on_outline.len()).filter(|&v| !on_outline[v]) {
        let around: Vec<(usize, f64)> = graph.around[v]
            .iter()
            .filter(|&&(e, _)| matches!(kinds[e], EdgeKind::Crease(_)))
            .map(|&(e, angle)| (e, angle))
            .collect();
        if around.is_empty() {
            continue;
        }
        let k = around.len();
        let sector_angles = (0..k)
            .map(|j| {
                let gap = (around[(j + 1) % k].1 - around[j].1).rem_euclid(TAU);
                if k == 1 {
                    TAU
                } else {
                    gap
                }
            })
            .collect();
        stars.push(VertexStar {
            vertex: v,
            creases: around.iter().map(|&(e, _)| e).collect(),
            sector_angles,
        });
    }
    if stars.len() > MAX_INTERIOR_VERTICES {
        return Err(NanofoldError::invalid(
            "vertices_coords",
            format!("{} interior vertices where creases meet", stars.len()),
            format!(
                "a crease pattern has at most {MAX_INTERIOR_VERTICES} (a 174 × 174 Miura-ori); more would take longer than 10 s to fold or unfold"
            ),
        ));
    }
    Ok(stars)
}

/// Panels: faces joined across facet edges (union–find).
fn panels(faces: &[Vec<usize>], edge_faces: &[[Option<usize>; 2]], kinds: &[EdgeKind]) -> (Vec<usize>, usize) {
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn root(parent: &mut [usize], mut f: usize) -> usize {
        while parent[f] != f {
            parent[f] = parent[parent[f]];
            f = parent[f];
        }
        f
    }
    for (e, sides) in edge_faces.iter().enumerate() {
        if let (EdgeKind::Facet, [Some(a), Some(b)]) = (kinds[e], sides) {
            let (ra, rb) = (root(&mut parent, *a), root(&mut parent, *b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let mut number = HashMap::new();
    let panel_of_face = (0..faces.len())
        .map(|f| {
            let r = root(&mut parent, f);
            let next = number.len();
            *number.entry(r).or_insert(next)
        })
        .collect();
    (panel_of_face, number.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of m × n unit squares; inner edges are creases of `assignment` at 0.
    fn grid(m: usize, n: usize, inner: EdgeKind) -> CreasePatternBuilder {
        let id = |i: usize, j: usize| i * (n + 1) + j;
        let mut b = CreasePatternBuilder {
            name: "grid".into(),
            angle_field: "edges_foldAngle".into(),
            ..Default::default()
        };
        for i in 0..=m {
            for j in 0..=n {
                b.vertices.push([j as f64, i as f64]);
            }
        }
        let mut push = |a: usize, c: usize, outline: bool| {
            b.edges.push([a, c]);
            b.kinds.push(if outline { EdgeKind::Boundary } else { inner });
            b.fold_angles.push(0.0);
        };
        for i in 0..=m {
            for j in 0..n {
                push(id(i, j), id(i, j + 1), i == 0 || i == m);
            }
        }
        for i in 0..m {
            for j in 0..=n {
                push(id(i, j), id(i + 1, j), j == 0 || j == n);
            }
        }
        b
    }

    #[test]
    fn a_grid_has_its_faces_stars_and_outline() {
        let cp = grid(3, 3, EdgeKind::Crease(Assignment::Unassigned)).build().unwrap();
        assert_eq!(cp.faces.len(), 9);
        assert_eq!(cp.panel_count, 9);
        assert_eq!(cp.creases.len(), 12);
        assert_eq!(cp.stars.len(), 4);
        assert_eq!(cp.outline.len(), 12);
        for star in &cp.stars {
            assert_eq!(star.creases.len(), 4);
            let sum: f64 = star.sector_angles.iter().sum();
            assert!((sum - TAU).abs() < 1e-12);
            assert!(star
                .sector_angles
                .iter()
                .all(|a| (a - std::f64::consts::FRAC_PI_2).abs() < 1e-12));
        }
        // Every inner edge has a face on each side, every outline edge one.
        for (e, sides) in cp.edge_faces.iter().enumerate() {
            let count = sides.iter().flatten().count();
            assert_eq!(count, if cp.kinds[e] == EdgeKind::Boundary { 1 } else { 2 });
        }
    }

    #[test]
    fn facet_edges_join_faces_into_panels() {
        let cp = grid(2, 2, EdgeKind::Facet).build().unwrap();
        assert_eq!((cp.faces.len(), cp.panel_count), (4, 1));
        assert!(cp.stars.is_empty() && cp.creases.is_empty());
    }

    #[test]
    fn one_crease_across_the_sheet_has_no_star() {
        // A square with its diagonal (FOLD's diagonal-cp example).
        let b = CreasePatternBuilder {
            name: "diagonal".into(),
            vertices: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            edges: vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
            kinds: vec![
                EdgeKind::Boundary,
                EdgeKind::Boundary,
                EdgeKind::Boundary,
                EdgeKind::Boundary,
                EdgeKind::Crease(Assignment::Valley),
            ],
            fold_angles: vec![0.0, 0.0, 0.0, 0.0, 1.0],
            faces: Some(vec![vec![0, 1, 2], vec![0, 2, 3]]),
            angle_field: "edges_foldAngle".into(),
            folded_form: None,
            locked: Vec::new(),
            unit: None,
            source_magnitude: 0.0,
        };
        let cp = b.build().unwrap();
        assert_eq!(
            (cp.faces.len(), cp.panel_count, cp.creases.len(), cp.stars.len()),
            (2, 2, 1, 0)
        );
    }

    #[test]
    fn papers_that_are_not_a_disc_are_refused() {
        // A crease on the outline (a cut).
        let mut b = grid(2, 2, EdgeKind::Crease(Assignment::Unassigned));
        b.kinds[0] = EdgeKind::Crease(Assignment::Unassigned);
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("edges_assignment[0]") && e.contains("outline"), "{e}");
        // A boundary edge inside.
        let mut b = grid(2, 2, EdgeKind::Crease(Assignment::Unassigned));
        let inner = b.kinds.iter().position(|k| *k != EdgeKind::Boundary).unwrap();
        b.kinds[inner] = EdgeKind::Boundary;
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("cut"), "{e}");
        // Two sheets.
        let mut b = grid(1, 1, EdgeKind::Crease(Assignment::Unassigned));
        let offset = b.vertices.len();
        for v in b.vertices.clone() {
            b.vertices.push([v[0] + 5.0, v[1]]);
        }
        for e in b.edges.clone() {
            b.edges.push([e[0] + offset, e[1] + offset]);
            b.kinds.push(EdgeKind::Boundary);
            b.fold_angles.push(0.0);
        }
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("one connected sheet"), "{e}");
        // A hole: a 3 × 3 grid without its middle square's inside (its four edges become
        // an inner outline).
        let b = grid(3, 3, EdgeKind::Crease(Assignment::Unassigned));
        let mut holed = b.clone();
        let middle = [[5usize, 6usize], [9, 10], [5, 9], [6, 10]];
        for (e, edge) in holed.edges.iter().enumerate() {
            if middle
                .iter()
                .any(|m| (m[0] == edge[0] && m[1] == edge[1]) || (m[0] == edge[1] && m[1] == edge[0]))
            {
                holed.kinds[e] = EdgeKind::Boundary;
            }
        }
        assert!(holed.build().is_err());
    }

    #[test]
    fn given_faces_must_be_the_graphs() {
        let mut b = grid(1, 2, EdgeKind::Crease(Assignment::Unassigned));
        b.faces = Some(vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]]);
        assert!(b.clone().build().is_ok());
        b.faces = Some(vec![vec![0, 1, 2, 5, 4, 3]]);
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("faces_vertices[0]"), "{e}");
    }

    #[test]
    fn crossing_edges_and_t_junctions_are_refused() {
        // Both diagonals of a square, with no vertex where they meet.
        let b = CreasePatternBuilder {
            name: "x".into(),
            vertices: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            edges: vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [1, 3]],
            kinds: vec![EdgeKind::Boundary; 4]
                .into_iter()
                .chain([EdgeKind::Crease(Assignment::Unassigned); 2])
                .collect(),
            fold_angles: vec![0.0; 6],
            faces: None,
            angle_field: "edges_foldAngle".into(),
            folded_form: None,
            locked: Vec::new(),
            unit: None,
            source_magnitude: 0.0,
        };
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("cross"), "{e}");
        // A crease ending in the middle of the bottom edge, which is not split there.
        let b = CreasePatternBuilder {
            name: "t".into(),
            vertices: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.0]],
            edges: vec![[0, 1], [1, 2], [2, 3], [3, 0], [4, 2]],
            kinds: vec![EdgeKind::Boundary; 4]
                .into_iter()
                .chain([EdgeKind::Crease(Assignment::Unassigned)])
                .collect(),
            fold_angles: vec![0.0; 5],
            faces: None,
            angle_field: "edges_foldAngle".into(),
            folded_form: None,
            locked: Vec::new(),
            unit: None,
            source_magnitude: 0.0,
        };
        let e = b.build().unwrap_err().to_string();
        assert!(e.contains("inside another edge"), "{e}");
    }

    #[test]
    fn overlapping_and_repeated_edges_are_refused() {
        let mut b = grid(1, 1, EdgeKind::Crease(Assignment::Unassigned));
        b.edges.push([0, 1]);
        b.kinds.push(EdgeKind::Boundary);
        b.fold_angles.push(0.0);
        assert!(b.build().unwrap_err().to_string().contains("same two vertices"));
    }
}
