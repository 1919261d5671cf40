//! FOLD (1.1/1.2) import: find the single vertex where the creases meet, its rays in CCW
//! order and its sector angles; `edges_foldAngle` (degrees, valley positive) is the folded
//! state. Locked creases use the custom key `edges_nanofold:locked` (FOLD's namespace rule).

use crate::error::{NanofoldError, Result};
use crate::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind, FoldedFormFit, ReadBuilder};
use crate::pattern::{Assignment, Chain, CreaseSpec, FlatMesh, RaySpec, VertexBuilder, MIN_SECTOR_RAD};
use crate::read::input::short_json;
use serde_json::Value;
use std::f64::consts::TAU;

/// Most vertices a FOLD file may have: a vertex of 512 rays with a corner per face needs
/// about 1 000.
pub const MAX_FOLD_VERTICES: usize = 4096;
/// Most edges (and faces) a FOLD file may have.
pub const MAX_FOLD_EDGES: usize = 8192;

/// Most vertices of a crease pattern of many vertices (a 100 × 100 Miura-ori has 10 201).
pub const MAX_PATTERN_VERTICES: usize = 100_000;
/// Most edges (and faces) of a crease pattern of many vertices.
pub const MAX_PATTERN_EDGES: usize = crate::pattern::crease_pattern::MAX_EDGES;

/// Largest |coordinate| of a crease pattern of many vertices.
pub const MAX_COORDINATE: f64 = 1e9;

/// How large a FOLD key frame may be, and why.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GraphLimits {
    vertices: usize,
    edges: usize,
    why: &'static str,
}

/// A single vertex: its outputs repeat the mesh in every frame.
pub(crate) const VERTEX_LIMITS: GraphLimits = GraphLimits {
    vertices: MAX_FOLD_VERTICES,
    edges: MAX_FOLD_EDGES,
    why: "a single-vertex pattern (its outputs repeat the mesh in every frame) has at most",
};

/// A crease pattern of many vertices.
pub(crate) const PATTERN_LIMITS: GraphLimits = GraphLimits {
    vertices: MAX_PATTERN_VERTICES,
    edges: MAX_PATTERN_EDGES,
    why: "a crease pattern has at most",
};

/// Custom FOLD key for creases held at their folded angle.
pub const LOCKED_KEY: &str = "edges_nanofold:locked";

fn array<'a>(value: &'a Value, key: &str) -> Result<&'a Vec<Value>> {
    match value.get(key) {
        None => Err(NanofoldError::missing(key)),
        Some(Value::Array(items)) => Ok(items),
        Some(other) => Err(NanofoldError::invalid(key, short_json(other), "expected an array")),
    }
}

fn number(value: &Value, field: &str) -> Result<f64> {
    let x = value
        .as_f64()
        .ok_or_else(|| NanofoldError::invalid(field, short_json(value), "expected a number"))?;
    if !x.is_finite() {
        return Err(NanofoldError::invalid(field, x, "must be finite"));
    }
    Ok(x)
}

fn index(value: &Value, field: &str, bound: usize, what: &str) -> Result<usize> {
    let i = value
        .as_u64()
        .ok_or_else(|| NanofoldError::invalid(field, short_json(value), "expected a non-negative integer"))?;
    if i as usize >= bound {
        return Err(NanofoldError::invalid(
            field,
            i,
            format!("there are only {bound} {what}"),
        ));
    }
    Ok(i as usize)
}

/// The arrays of a FOLD key frame, parsed and checked for shape and indices; `angle_key`
/// names the fold-angle array the file uses.
pub(crate) struct FoldGraph<'v> {
    pub coords: Vec<[f64; 2]>,
    /// The coordinates as given, z = 0 for 2D files.
    pub coords3: Vec<[f64; 3]>,
    /// Whether some vertex has z ≠ 0 (a folded form, not a crease pattern).
    pub is_3d: bool,
    pub edges: Vec<[usize; 2]>,
    pub letters: Vec<String>,
    pub angle_key: &'static str,
    /// The fold angles, degrees (None: the file gives none).
    pub angles_json: Option<&'v [Value]>,
    pub locked: Vec<bool>,
    pub faces_vertices: Option<Vec<Vec<usize>>>,
    /// `frame_unit`, kept for the outputs.
    pub unit: Option<String>,
}

/// The key frame's `frame_unit`: a short string, or absent.
fn frame_unit(value: &Value) -> Result<Option<String>> {
    match value.get("frame_unit") {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(unit)) if unit.len() <= 64 => Ok(Some(unit.clone())),
        Some(other) => Err(NanofoldError::invalid(
            "frame_unit",
            other.to_string().chars().take(80).collect::<String>(),
            "a unit name of at most 64 characters (FOLD: \"unit\", \"mm\", \"um\", …)",
        )),
    }
}

/// A flat-folded form as FOLD's own `fold-convert --flat-fold` writes it — `frame_classes`
/// with `foldedForm`, 2D `vertices_coords` holding the folded positions and
/// `vertices_flatUnfoldCoords` the crease pattern — turned back into its crease pattern with
/// every mountain and valley folded by ∓180° (unless the file gives `edges_foldAngle`). A 2D
/// folded form without the crease pattern is refused by name; anything else is unchanged.
pub(crate) fn unflatten_folded_form(value: &Value) -> Result<Option<Value>> {
    let folded = value
        .get("frame_classes")
        .and_then(Value::as_array)
        .is_some_and(|classes| classes.iter().any(|c| c.as_str() == Some("foldedForm")));
    let planar = value
        .get("vertices_coords")
        .and_then(Value::as_array)
        .is_some_and(|coords| coords.iter().all(|p| p.as_array().is_some_and(|p| p.len() == 2)));
    if !(folded && planar) {
        return Ok(None);
    }
    let Some(unfolded) = value.get("vertices_flatUnfoldCoords") else {
        return Err(NanofoldError::invalid(
            "frame_classes",
            "foldedForm with 2D vertices_coords",
            "a flat-folded form needs its crease pattern (vertices_flatUnfoldCoords, as fold-convert --flat-fold writes it); or give the crease pattern itself (creasePattern)",
        ));
    };
    let count = value["vertices_coords"].as_array().map_or(0, Vec::len);
    if unfolded.as_array().map(Vec::len) != Some(count) {
        return Err(NanofoldError::invalid(
            "vertices_flatUnfoldCoords",
            input_len(unfolded),
            format!("one 2D point per vertex ({count})"),
        ));
    }
    let mut pattern = value.clone();
    pattern["vertices_coords"] = unfolded.clone();
    pattern["frame_classes"] = serde_json::json!(["creasePattern"]);
    if value.get("edges_foldAngle").is_none() {
        let letters = value.get("edges_assignment").and_then(Value::as_array);
        if let Some(letters) = letters {
            let angles: Vec<Value> = letters
                .iter()
                .map(|l| match l.as_str() {
                    Some("V") | Some("v") => serde_json::json!(180.0),
                    Some("M") | Some("m") => serde_json::json!(-180.0),
                    _ => serde_json::json!(0.0),
                })
                .collect();
            pattern["edges_foldAngle"] = Value::Array(angles);
        }
    }
    Ok(Some(pattern))
}

fn input_len(value: &Value) -> String {
    value
        .as_array()
        .map_or_else(|| "not an array".to_string(), |a| format!("{} entries", a.len()))
}

/// Parses a FOLD key frame's vertices, edges, assignments, fold angles, locks and faces.
pub(crate) fn parse_graph(value: &Value, limits: GraphLimits) -> Result<FoldGraph<'_>> {
    // vertices_coords: 2D, or 3D with z = 0 (a crease pattern, not a folded form).
    let coords_json = array(value, "vertices_coords")?;
    for (key, count, limit) in [
        ("vertices_coords", coords_json.len(), limits.vertices),
        (
            "edges_vertices",
            value
                .get("edges_vertices")
                .and_then(Value::as_array)
                .map_or(0, Vec::len),
            limits.edges,
        ),
        (
            "faces_vertices",
            value
                .get("faces_vertices")
                .and_then(Value::as_array)
                .map_or(0, Vec::len),
            limits.edges,
        ),
    ] {
        if count > limit {
            return Err(NanofoldError::invalid(
                key,
                format!("{count} entries"),
                format!("{} {limit}", limits.why),
            ));
        }
    }
    let mut coords = Vec::with_capacity(coords_json.len());
    let mut coords3 = Vec::with_capacity(coords_json.len());
    for (i, c) in coords_json.iter().enumerate() {
        let field = format!("vertices_coords[{i}]");
        let items = c
            .as_array()
            .ok_or_else(|| NanofoldError::invalid(&field, short_json(c), "expected [x, y] or [x, y, z]"))?;
        if items.len() < 2 || items.len() > 3 {
            return Err(NanofoldError::invalid(
                &field,
                short_json(c),
                "expected [x, y] or [x, y, z]",
            ));
        }
        let x = number(&items[0], &field)?;
        let y = number(&items[1], &field)?;
        let z = if items.len() == 3 {
            number(&items[2], &field)?
        } else {
            0.0
        };
        coords.push([x, y]);
        coords3.push([x, y, z]);
    }
    let is_3d = coords3.iter().any(|p| p[2] != 0.0);
    let nv = coords.len();

    let edges_json = array(value, "edges_vertices")?;
    let mut edges = Vec::with_capacity(edges_json.len());
    for (i, e) in edges_json.iter().enumerate() {
        let field = format!("edges_vertices[{i}]");
        let items = e
            .as_array()
            .filter(|a| a.len() == 2)
            .ok_or_else(|| NanofoldError::invalid(&field, short_json(e), "expected [u, v]"))?;
        let u = index(&items[0], &field, nv, "vertices")?;
        let v = index(&items[1], &field, nv, "vertices")?;
        if u == v {
            return Err(NanofoldError::invalid(
                &field,
                short_json(e),
                "an edge needs two distinct vertices",
            ));
        }
        edges.push([u, v]);
    }
    let ne = edges.len();

    let assignment_json = array(value, "edges_assignment")?;
    if assignment_json.len() != ne {
        return Err(NanofoldError::invalid(
            "edges_assignment",
            format!("{} entries", assignment_json.len()),
            format!("expected one per edge ({ne})"),
        ));
    }
    let mut letters = Vec::with_capacity(ne);
    for (i, a) in assignment_json.iter().enumerate() {
        let field = format!("edges_assignment[{i}]");
        let letter = a
            .as_str()
            .ok_or_else(|| NanofoldError::invalid(&field, short_json(a), "expected a one-letter string"))?;
        letters.push(letter.to_string());
    }

    let (angle_key, angles_json) = match (value.get("edges_foldAngle"), value.get("edges_foldAngles")) {
        (Some(_), _) => ("edges_foldAngle", Some(array(value, "edges_foldAngle")?.as_slice())),
        (None, Some(_)) => ("edges_foldAngles", Some(array(value, "edges_foldAngles")?.as_slice())),
        (None, None) => ("edges_foldAngle", None),
    };
    if let Some(angles) = angles_json {
        if angles.len() != ne {
            return Err(NanofoldError::invalid(
                angle_key,
                format!("{} entries", angles.len()),
                format!("expected one per edge ({ne})"),
            ));
        }
    }

    let locked: Vec<bool> = match value.get(LOCKED_KEY) {
        None => vec![false; ne],
        Some(v) => {
            let items = v
                .as_array()
                .filter(|a| a.len() == ne)
                .ok_or_else(|| NanofoldError::invalid(LOCKED_KEY, short_json(v), format!("expected {ne} booleans")))?;
            items
                .iter()
                .enumerate()
                .map(|(i, b)| {
                    b.as_bool().ok_or_else(|| {
                        NanofoldError::invalid(format!("{LOCKED_KEY}[{i}]"), short_json(b), "expected true or false")
                    })
                })
                .collect::<Result<_>>()?
        }
    };

    let faces_vertices = match value.get("faces_vertices") {
        None => None,
        Some(v) => {
            let items = v
                .as_array()
                .ok_or_else(|| NanofoldError::invalid("faces_vertices", short_json(v), "expected an array"))?;
            let mut faces = Vec::with_capacity(items.len());
            for (i, f) in items.iter().enumerate() {
                let field = format!("faces_vertices[{i}]");
                let ids = f
                    .as_array()
                    .ok_or_else(|| NanofoldError::invalid(&field, short_json(f), "expected an array of vertex ids"))?;
                faces.push(
                    ids.iter()
                        .map(|id| index(id, &field, nv, "vertices"))
                        .collect::<Result<Vec<_>>>()?,
                );
            }
            Some(faces)
        }
    };
    Ok(FoldGraph {
        coords,
        coords3,
        is_3d,
        edges,
        letters,
        angle_key,
        angles_json,
        locked,
        faces_vertices,
        unit: frame_unit(value)?,
    })
}

/// Reads the key frame of a FOLD object into a raw vertex: the edges classified, the one
/// vertex where the creases meet, its edges ordered by direction, the paper's span, and the
/// rays and sectors in that order.
pub(crate) fn read_fold(value: &Value, name: &str) -> Result<VertexBuilder> {
    let FoldGraph {
        coords,
        coords3,
        is_3d,
        edges,
        letters,
        angle_key,
        angles_json,
        locked,
        faces_vertices,
        unit,
    } = parse_graph(value, VERTEX_LIMITS)?;
    if is_3d {
        let i = coords3.iter().position(|p| p[2] != 0.0).expect("is_3d");
        return Err(NanofoldError::invalid(
            format!("vertices_coords[{i}]"),
            format!("{:?}", coords3[i]),
            "a single vertex is read from its flat crease pattern (z = 0) with edges_foldAngle; 3D folded forms are read as crease patterns of many vertices (`check`, `fold`)",
        ));
    }
    let angles_json =
        angles_json.ok_or_else(|| NanofoldError::missing_with("edges_foldAngle", "the folded state, degrees"))?;
    let is_crease = crease_edges(&letters)?;
    let center = the_vertex(&edges, &is_crease, coords.len())?;
    let spokes = spokes_at(center, &coords, &edges)?;
    let (chain, start, ray_count) = paper_span(&spokes, &is_crease, center)?;
    let edge_table = EdgeTable {
        letters: &letters,
        is_crease: &is_crease,
        angle_key,
        angles_json,
        locked: &locked,
    };
    let (rays, sector_angles, sector_fields) = rays_and_sectors(&spokes, &edge_table, chain, start, ray_count)?;
    Ok(VertexBuilder {
        name: name.to_string(),
        chain,
        rays,
        sector_angles,
        sector_fields,
        mesh: Some(FlatMesh {
            vertices_coords: coords,
            edges_vertices: edges,
            edges_assignment: letters,
            faces_vertices,
            center,
            ray0_direction: spokes[start].direction,
            unit,
        }),
    })
}

/// Which edges are creases: every edge but the boundary (B) ones; C and J are refused.
fn crease_edges(letters: &[String]) -> Result<Vec<bool>> {
    let mut is_crease = vec![false; letters.len()];
    for (i, letter) in letters.iter().enumerate() {
        if letter != "B" && letter != "b" {
            Assignment::from_letter(letter, &format!("edges_assignment[{i}]"))?;
            is_crease[i] = true;
        }
    }
    Ok(is_crease)
}

/// The one vertex where two or more creases meet, every crease meeting it.
fn the_vertex(edges: &[[usize; 2]], is_crease: &[bool], vertex_count: usize) -> Result<usize> {
    let mut crease_degree = vec![0usize; vertex_count];
    for (i, e) in edges.iter().enumerate() {
        if is_crease[i] {
            crease_degree[e[0]] += 1;
            crease_degree[e[1]] += 1;
        }
    }
    let centers: Vec<usize> = (0..vertex_count).filter(|&v| crease_degree[v] >= 2).collect();
    let center = match centers.len() {
        0 => {
            return Err(NanofoldError::invalid(
                "edges_assignment",
                "no vertex with two or more creases",
                "a single-vertex pattern needs its creases to meet at one vertex",
            ))
        }
        1 => centers[0],
        count => return Err(NanofoldError::MultipleVertices { count }),
    };
    for (i, e) in edges.iter().enumerate() {
        if is_crease[i] && e[0] != center && e[1] != center {
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{i}]"),
                format!("[{}, {}]", e[0], e[1]),
                format!("crease does not meet the vertex {center} where the creases meet"),
            ));
        }
    }
    Ok(center)
}

/// An edge at the vertex and the direction it leaves in, rad in [0, 2π).
struct Spoke {
    edge: usize,
    direction: f64,
}

/// Every edge at `center`, by direction; refused where one has zero length or two leave in
/// the same direction.
fn spokes_at(center: usize, coords: &[[f64; 2]], edges: &[[usize; 2]]) -> Result<Vec<Spoke>> {
    let c = coords[center];
    let mut spokes = Vec::new();
    for (i, e) in edges.iter().enumerate() {
        if e[0] != center && e[1] != center {
            continue;
        }
        let other = if e[0] == center { e[1] } else { e[0] };
        let (dx, dy) = (coords[other][0] - c[0], coords[other][1] - c[1]);
        if dx == 0.0 && dy == 0.0 {
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{i}]"),
                format!("[{}, {}]", e[0], e[1]),
                "edge has zero length",
            ));
        }
        spokes.push(Spoke {
            edge: i,
            direction: dy.atan2(dx).rem_euclid(TAU),
        });
    }
    spokes.sort_by(|a, b| a.direction.total_cmp(&b.direction));
    // Every neighbouring pair, the last and the first (across 0 rad) included.
    for k in 0..spokes.len() {
        let (here, next) = (&spokes[k], &spokes[(k + 1) % spokes.len()]);
        let gap = (next.direction - here.direction).rem_euclid(TAU);
        if spokes.len() > 1 && gap < MIN_SECTOR_RAD {
            return Err(NanofoldError::invalid(
                format!("edges_vertices[{}]", next.edge),
                format!("edges {} and {}, {gap:.1e} rad apart", here.edge, next.edge),
                format!("two edges leave the vertex in the same direction (less than {MIN_SECTOR_RAD:.0e} rad apart)"),
            ));
        }
    }
    Ok(spokes)
}

/// The paper around the vertex: all the way round (no boundary edge: a closed chain), or the
/// angular gap between its two boundary edges that holds the creases (an open chain). Returns
/// the chain, the spoke it starts at, and how many rays it has.
fn paper_span(spokes: &[Spoke], is_crease: &[bool], center: usize) -> Result<(Chain, usize, usize)> {
    let m = spokes.len();
    let boundary_spokes: Vec<usize> = (0..m).filter(|&k| !is_crease[spokes[k].edge]).collect();
    match boundary_spokes.len() {
        0 => Ok((Chain::Closed, 0, m)),
        2 => {
            let (b0, b1) = (boundary_spokes[0], boundary_spokes[1]);
            let creases_between = (b0 + 1..b1).count();
            let creases_outside = m - 2 - creases_between;
            if creases_between > 0 && creases_outside > 0 {
                return Err(NanofoldError::invalid(
                    "vertices_coords",
                    format!(
                        "boundary edges {} and {} at vertex {center}",
                        spokes[b0].edge, spokes[b1].edge
                    ),
                    "creases leave the vertex on both sides of its two boundary edges: the paper must lie between them",
                ));
            }
            if creases_between > 0 {
                Ok((Chain::Open, b0, b1 - b0 + 1))
            } else {
                Ok((Chain::Open, b1, m - b1 + b0 + 1))
            }
        }
        k => Err(NanofoldError::invalid(
            "edges_assignment",
            format!("{k} boundary (B) edges at vertex {center}"),
            "a vertex has 0 (interior) or 2 (on the sheet's edge) boundary edges",
        )),
    }
}

/// What a ray reads of its edge: the assignment, whether it is a crease, its fold angle
/// (under `angle_key`), whether it is locked.
struct EdgeTable<'a> {
    letters: &'a [String],
    is_crease: &'a [bool],
    angle_key: &'a str,
    angles_json: &'a [Value],
    locked: &'a [bool],
}

/// The rays from the span's first spoke on (creases with their assignment and fold angle,
/// boundary edges as boundary rays), and the sector after each but an open chain's last,
/// with the field each sector is read from.
fn rays_and_sectors(
    spokes: &[Spoke],
    table: &EdgeTable,
    chain: Chain,
    start: usize,
    ray_count: usize,
) -> Result<(Vec<RaySpec>, Vec<f64>, Vec<String>)> {
    let m = spokes.len();
    let gap = |k: usize| -> f64 {
        let next = spokes[(k + 1) % m].direction;
        let here = spokes[k].direction;
        if k + 1 == m {
            next + TAU - here
        } else {
            next - here
        }
    };
    // Creases are numbered by their edge index.
    let mut order_of_edge = vec![usize::MAX; table.letters.len()];
    let mut crease_edges: Vec<usize> = spokes.iter().map(|s| s.edge).filter(|&e| table.is_crease[e]).collect();
    crease_edges.sort_unstable();
    for (order, &e) in crease_edges.iter().enumerate() {
        order_of_edge[e] = order;
    }
    let mut rays = Vec::with_capacity(ray_count);
    let mut sector_angles = Vec::new();
    let mut sector_fields = Vec::new();
    for j in 0..ray_count {
        let k = (start + j) % m;
        let edge = spokes[k].edge;
        if table.is_crease[edge] {
            let field = format!("{}[{edge}]", table.angle_key);
            let degrees = number(&table.angles_json[edge], &field)?;
            rays.push(RaySpec::Crease(CreaseSpec {
                label: format!("edges[{edge}]"),
                assignment: Assignment::from_letter(&table.letters[edge], &format!("edges_assignment[{edge}]"))?,
                fold_angle: degrees.to_radians(),
                locked: table.locked[edge],
                fold_edge: Some(edge),
                order: order_of_edge[edge],
                angle_field: field,
            }));
        } else {
            rays.push(RaySpec::Boundary);
        }
        let last = match chain {
            Chain::Closed => false,
            Chain::Open => j + 1 == ray_count,
        };
        if !last {
            sector_angles.push(gap(k));
            sector_fields.push(format!(
                "vertices_coords (sector between edges {} and {})",
                edge,
                spokes[(k + 1) % m].edge
            ));
        }
    }
    Ok((rays, sector_angles, sector_fields))
}

/// Reads the key frame of a FOLD object into a crease pattern of any number of vertices
/// (`docs/model.md#crease-patterns`). Fold angles may be absent (the flat state) or `null`
/// on boundary and facet edges, as Origami Simulator writes them.
pub(crate) fn read_crease_pattern(value: &Value, name: &str) -> Result<ReadBuilder> {
    let graph = parse_graph(value, PATTERN_LIMITS)?;
    // Lengths far from 1 leave no digits for the planarity tolerances (1e-12 of the size).
    if let Some(i) = graph
        .coords3
        .iter()
        .position(|p| p.iter().any(|x| x.abs() > MAX_COORDINATE))
    {
        return Err(NanofoldError::invalid(
            format!("vertices_coords[{i}]"),
            format!("{:?}", graph.coords3[i]),
            format!("coordinates of a crease pattern lie within ±{MAX_COORDINATE:e} (rescale the file)"),
        ));
    }
    let mut kinds = Vec::with_capacity(graph.edges.len());
    for (e, letter) in graph.letters.iter().enumerate() {
        let field = format!("edges_assignment[{e}]");
        kinds.push(match letter.as_str() {
            "B" | "b" => EdgeKind::Boundary,
            "F" | "f" => EdgeKind::Facet,
            "C" | "c" => {
                return Err(NanofoldError::invalid(
                    field,
                    "\"C\"",
                    "cut edges are not supported yet: the paper must be one disc",
                ))
            }
            other => EdgeKind::Crease(Assignment::from_letter(other, &field)?),
        });
    }
    let mut graph = graph;
    let mut reading = None;
    let source_magnitude = largest_coordinate(&graph.coords3);
    if graph.is_3d {
        match flat_within_noise(&graph.coords3, graph.faces_vertices.as_deref()) {
            Some((coords, planarity)) => {
                graph.coords = coords;
                reading = Some(planarity);
            }
            None => return read_folded_form(graph, kinds, name),
        }
    }
    let fold_angles = crease_angles(&graph, &kinds)?;
    if let Some(planarity) = reading {
        // The sheet is the state (flat); its angles can only be targets.
        return Ok(flat_sheet(
            graph,
            None,
            kinds,
            fold_angles,
            name,
            source_magnitude,
            |targets| {
                format!(
                "a 3D sheet flat within its noise (every vertex within {planarity:.1e} of the sheet's size of one plane; tolerance {FLAT_NOISE:.0e}): read as the flat crease pattern with its assignment{}",
                targets.map_or(String::new(), |t| format!(", {t}"))
            )
            },
        ));
    }
    Ok(CreasePatternBuilder {
        name: name.to_string(),
        vertices: graph.coords,
        edges: graph.edges,
        kinds,
        fold_angles,
        faces: graph.faces_vertices,
        angle_field: graph.angle_key.to_string(),
        folded_form: None,
        locked: graph.locked,
        unit: graph.unit,
        source_magnitude,
    }
    .into())
}

/// A 3D sheet read as its flat crease pattern (at `vertices`, or the graph's own flat
/// coordinates): every fold angle 0, the file's angles kept as targets where any is not 0,
/// and `reading` saying so (given "its … read as targets" when there are targets).
fn flat_sheet(
    graph: FoldGraph<'_>,
    vertices: Option<Vec<[f64; 2]>>,
    kinds: Vec<EdgeKind>,
    targets: Vec<f64>,
    name: &str,
    source_magnitude: f64,
    reading: impl FnOnce(Option<&str>) -> String,
) -> ReadBuilder {
    let any_target = targets.iter().any(|a| *a != 0.0);
    let targets_note = format!("its {} read as targets", graph.angle_key);
    let note = reading(any_target.then_some(targets_note.as_str()));
    let edge_count = graph.edges.len();
    CreasePatternBuilder {
        name: name.to_string(),
        vertices: vertices.unwrap_or(graph.coords),
        edges: graph.edges,
        kinds,
        fold_angles: vec![0.0; edge_count],
        faces: None,
        angle_field: graph.angle_key.to_string(),
        folded_form: None,
        locked: graph.locked,
        unit: graph.unit,
        source_magnitude,
    }
    .with_reading(note, any_target.then_some(targets))
}

/// The file's angle of each edge, rad: a crease's as given (required when the file gives
/// angles at all), 0 for boundary and facet edges whatever the file says of them (Origami
/// Simulator writes its facets' target angles).
fn crease_angles(graph: &FoldGraph<'_>, kinds: &[EdgeKind]) -> Result<Vec<f64>> {
    let mut fold_angles = Vec::with_capacity(graph.edges.len());
    for (e, &kind) in kinds.iter().enumerate() {
        let angle_field = format!("{}[{e}]", graph.angle_key);
        let degrees = match graph.angles_json.map(|a| &a[e]) {
            None | Some(Value::Null) if !matches!(kind, EdgeKind::Crease(_)) || graph.angles_json.is_none() => 0.0,
            None | Some(Value::Null) => {
                return Err(NanofoldError::invalid(
                    angle_field,
                    "null",
                    "a crease needs its fold angle (degrees), or the file none at all (the flat state)",
                ))
            }
            Some(v) => number(v, &angle_field)?,
        };
        // A facet or boundary edge is flat whatever the file says of it (Origami Simulator
        // writes its facets' target angles); a crease keeps its angle.
        fold_angles.push(if matches!(kind, EdgeKind::Crease(_)) {
            degrees.to_radians()
        } else {
            0.0
        });
    }
    Ok(fold_angles)
}

/// A crease of a 3D folded form within this of ±π is folded flat (its faces' normals
/// opposite, the dihedral's sign noise), rad: it is read at ±π with its assignment's sign.
pub const FOLDED_FLAT: f64 = 1e-4;

/// A 3D folded form whose every dihedral angle (creases and facets) lies within this of 0,
/// rad, is a flat sheet with an exporter's noise: Origami Simulator's compliant solver
/// leaves its float32 exports off rigid by a few 1e-5 rad, and so bent. The same bound as
/// [`FOLDED_FLAT`] at the other end of the range.
pub const FLAT_DIHEDRAL_NOISE: f64 = 1e-4;

/// A 3D sheet whose vertices all lie within this fraction of its size of one plane is flat
/// (float noise of an exporter), not a folded state.
pub const FLAT_NOISE: f64 = 1e-4;

/// The largest |coordinate| of a file's points (what its rounding is relative to).
fn largest_coordinate(coords: &[[f64; 3]]) -> f64 {
    coords.iter().flatten().fold(0.0, |m: f64, x| m.max(x.abs()))
}

/// The 2D coordinates of a 3D sheet that is flat within [`FLAT_NOISE`] (in its best-fit
/// plane, turned so the listed faces run counter-clockwise), and its planarity relative to
/// its size; None when it is folded.
fn flat_within_noise(coords: &[[f64; 3]], faces: Option<&[Vec<usize>]>) -> Option<(Vec<[f64; 2]>, f64)> {
    use nalgebra::{Matrix3, Vector3};
    let n = coords.len();
    if n < 3 {
        return None;
    }
    let points: Vec<Vector3<f64>> = coords.iter().map(|p| Vector3::new(p[0], p[1], p[2])).collect();
    let centre = points.iter().sum::<Vector3<f64>>() / n as f64;
    let size = points.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    if !(size > 0.0 && size.is_finite()) {
        return None;
    }
    let mut scatter = Matrix3::zeros();
    for p in &points {
        let d = (p - centre) / size;
        scatter += d * d.transpose();
    }
    let eigen = scatter.symmetric_eigen();
    let order = {
        let mut k = [0, 1, 2];
        k.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
        k
    };
    let mut normal: Vector3<f64> = eigen.eigenvectors.column(order[0]).into_owned();
    let planarity = points
        .iter()
        .map(|p| (p - centre).dot(&normal).abs())
        .fold(0.0, f64::max)
        / size;
    if planarity > FLAT_NOISE {
        return None;
    }
    // Faces listed counter-clockwise about the normal (FOLD's convention): pick its sign so
    // they are. A sheet folded flat has faces turned over (every 180° fold flips a layer):
    // it is a folded form, not a flat sheet.
    if let Some(faces) = faces {
        let turns: Vec<f64> = faces
            .iter()
            .filter(|f| f.len() >= 3 && f.iter().all(|&v| v < n))
            .map(|f| {
                // Newell's normal: robust for any simple polygon.
                let mut area = Vector3::zeros();
                for (k, &v) in f.iter().enumerate() {
                    area += (points[v] - centre).cross(&(points[f[(k + 1) % f.len()]] - centre));
                }
                area.dot(&normal)
            })
            .collect();
        let scale = turns.iter().map(|t| t.abs()).fold(0.0, f64::max);
        let up = turns.iter().filter(|t| **t > 1e-9 * scale).count();
        let down = turns.iter().filter(|t| **t < -1e-9 * scale).count();
        if up > 0 && down > 0 {
            return None;
        }
        if down > up {
            normal = -normal;
        }
    }
    let u: Vector3<f64> = eigen.eigenvectors.column(order[2]).into_owned();
    let v = normal.cross(&u);
    Some((
        points
            .iter()
            .map(|p| [(p - centre).dot(&u), (p - centre).dot(&v)])
            .collect(),
        planarity,
    ))
}

/// A 3D folded form: the crease pattern developed from its faces, the state from its
/// dihedral angles (`edges_foldAngle` is ignored: Origami Simulator writes the targets there).
fn read_folded_form(graph: FoldGraph<'_>, kinds: Vec<EdgeKind>, name: &str) -> Result<ReadBuilder> {
    let source_magnitude = largest_coordinate(&graph.coords3);
    let Some(faces) = graph.faces_vertices.clone() else {
        return Err(NanofoldError::missing_with(
            "faces_vertices",
            "a 3D folded form is developed into its crease pattern face by face",
        ));
    };
    let development = crate::read::folded_form::develop(&graph.coords3, &graph.edges, &faces)?;
    // Bent nowhere beyond a compliant exporter's noise, the sheet is flat: the nearest
    // rigid state is the flat one, and the file's angles can only be targets.
    let bend = development.fold_angles.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
    if bend <= FLAT_DIHEDRAL_NOISE {
        let targets = crease_angles(&graph, &kinds)?;
        return Ok(flat_sheet(
            graph,
            Some(development.vertices),
            kinds,
            targets,
            name,
            source_magnitude,
            |targets| {
                format!(
                "a 3D sheet whose every dihedral angle lies within {FLAT_DIHEDRAL_NOISE:.0e} rad of flat (largest {bend:.2e} rad, creases and facets): read as the flat crease pattern developed from its faces, with its assignment, moved to flat by at most {bend:.2e} rad{}",
                targets.map_or(String::new(), |t| format!("; {t}"))
            )
            },
        ));
    }
    // Faces listed clockwise give a mirrored development with every angle's sign flipped:
    // the assignments say which way round the file is.
    let (mut agree, mut disagree) = (0usize, 0usize);
    for (kind, &rho) in kinds.iter().zip(&development.fold_angles) {
        let sign = match kind {
            EdgeKind::Crease(Assignment::Valley) => 1.0,
            EdgeKind::Crease(Assignment::Mountain) => -1.0,
            _ => 0.0,
        };
        if sign * rho > 0.0 {
            agree += 1;
        } else if sign * rho < 0.0 {
            disagree += 1;
        }
    }
    let mirrored = disagree > agree;
    let flip = if mirrored { -1.0 } else { 1.0 };
    let vertices = development.vertices.iter().map(|p| [flip * p[0], p[1]]).collect();
    let mut max_facet_angle: f64 = 0.0;
    let mut snapped = 0usize;
    let fold_angles: Vec<f64> = kinds
        .iter()
        .zip(&development.fold_angles)
        .map(|(kind, &rho)| match kind {
            // Folded flat, two faces' normals are opposite and the dihedral's sign is noise:
            // the assignment says which way it folded.
            EdgeKind::Crease(a) if std::f64::consts::PI - rho.abs() <= FOLDED_FLAT => {
                snapped += 1;
                match a {
                    Assignment::Valley => std::f64::consts::PI,
                    Assignment::Mountain => -std::f64::consts::PI,
                    _ => flip * rho.signum() * std::f64::consts::PI,
                }
            }
            EdgeKind::Crease(_) => flip * rho,
            EdgeKind::Facet => {
                max_facet_angle = max_facet_angle.max(rho.abs());
                0.0
            }
            EdgeKind::Boundary => 0.0,
        })
        .collect();
    // A folded form's assignment is the target; a crease the state folds the other way (a
    // compliant simulator's start, say) keeps its angle and becomes unassigned.
    let mut kinds = kinds;
    let mut assignment_conflicts = 0;
    for (kind, &rho) in kinds.iter_mut().zip(&fold_angles) {
        let contradicts = matches!(
            (*kind, rho),
            (EdgeKind::Crease(Assignment::Mountain), r) if r > 0.0
        ) || matches!((*kind, rho), (EdgeKind::Crease(Assignment::Valley), r) if r < 0.0);
        if contradicts {
            *kind = EdgeKind::Crease(Assignment::Unassigned);
            assignment_conflicts += 1;
        }
    }
    Ok(CreasePatternBuilder {
        name: name.to_string(),
        vertices,
        edges: graph.edges,
        kinds,
        fold_angles,
        faces: None,
        angle_field: "dihedral angle of the 3D faces".into(),
        locked: graph.locked,
        unit: graph.unit,
        source_magnitude,
        folded_form: Some(FoldedFormFit {
            development_error: development.development_error,
            face_nonplanarity: development.face_nonplanarity,
            max_facet_angle,
            mirrored,
            assignment_conflicts,
            folded_flat: snapped,
        }),
    }
    .into())
}
