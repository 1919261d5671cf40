//! A network scene's pipeline (`docs/model.md#panel-networks`): a validated
//! [`NetworkSpec`] → every crease's hinge (its own entry or the defaults), the drives and
//! the etch front's release times, the start (the pattern's rigid state, projected onto the
//! closures when it is within the tolerance), the locks and the anchored panel →
//! [`NetworkModel`]. Loaders never call this; building a scene does.

use super::manifold::{projection_solver, restore, worst_residual};
use super::model::{NetworkModel, NetworkParts, PanelBody};
use super::reduced::reduce;
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::forcing::{Actuation, Forcing, HingeDrive};
use crate::dynamics::spec::{drag_law, hinge_stiffness_named, network_actuation};
use crate::dynamics::strip::StripChain;
use crate::error::{NanofoldError, Result};
use crate::folding::FoldingModel;
use crate::pattern::crease_pattern::{CreasePattern, CreasePatternBuilder, EdgeKind};
use crate::pattern::{Assignment, VertexPattern};
use crate::read::scene_spec::{
    count_within, finite, limits, material, validate_materials, within, ClosedSpec, HingeSpec, NetworkSource,
    NetworkSpec, MICROMETRE,
};

/// A start whose closure residual exceeds this is not a rigid state, rad.
pub const START_TOLERANCE: f64 = 1e-6;

/// Assembles the network a scene describes.
pub fn network(spec: &NetworkSpec<CreasePattern>) -> Result<NetworkModel> {
    validate_materials(&spec.materials)?;
    let unit = within("length_unit_um", spec.length_unit_um, limits::LENGTH_UNIT_UM, "µm")? * MICROMETRE;
    let mut pattern = spec.pattern.clone();
    let columns = pattern.creases.len();
    count_within("pattern (creases)", columns, (1, limits::MAX_NETWORK_CREASES)).map_err(|_| {
        NanofoldError::invalid(
            "pattern",
            format!("{columns} creases"),
            format!(
                "a network scene needs between 1 and {} creases",
                limits::MAX_NETWORK_CREASES
            ),
        )
    })?;
    // Locks: a crease held where the pattern starts.
    let mut column_of_edge = vec![None; pattern.edges.len()];
    for (c, &e) in pattern.creases.iter().enumerate() {
        column_of_edge[e] = Some(c);
    }
    let kinds = pattern.kinds.clone();
    let crease = |field: &str, e: usize| -> Result<usize> {
        column_of_edge.get(e).copied().flatten().ok_or_else(|| {
            let what = match kinds.get(e) {
                Some(EdgeKind::Boundary) => "a boundary edge, not a crease".to_string(),
                Some(EdgeKind::Facet) => "a flat facet edge (F) inside a panel, not a crease".to_string(),
                _ => format!("not an edge of the pattern ({} edges)", kinds.len()),
            };
            NanofoldError::invalid(field, e, what)
        })
    };
    for (i, lock) in spec.locks.iter().enumerate() {
        let field = format!("locks[{i}].crease");
        let c = crease(&field, lock.crease)?;
        let e = pattern.creases[c];
        let angle = finite(&format!("locks[{i}].angle_deg"), lock.angle_deg)?.to_radians();
        if (angle - pattern.fold_angles[e]).abs() > 1e-9 {
            return Err(NanofoldError::invalid(
                format!("locks[{i}].angle_deg"),
                lock.angle_deg,
                format!(
                    "the pattern starts crease {} at {:.9}°: a lock holds a crease where it starts",
                    lock.crease,
                    pattern.fold_angles[e].to_degrees()
                ),
            ));
        }
        pattern.locked[e] = true;
    }
    let folding = FoldingModel::new(pattern)?;
    let pattern = &folding.pattern;
    // Hinges: each crease's own entry, or the defaults.
    let mut entry: Vec<Option<usize>> = vec![None; columns];
    for (i, hinge) in spec.hinges.iter().enumerate() {
        let field = format!("hinges[{i}].crease");
        let c = crease(&field, hinge.crease)?;
        if entry[c].replace(i).is_some() {
            return Err(NanofoldError::invalid(
                field,
                hinge.crease,
                "this crease already has a hinge",
            ));
        }
    }
    let defaults = spec.hinge_defaults.as_ref().map(|d| d.hinge());
    let (actuation, front) = network_actuation(&spec.actuation)?;
    let mut stiffness = vec![0.0; columns];
    let mut drives = vec![HingeDrive::PASSIVE; columns];
    for c in 0..columns {
        let e = pattern.creases[c];
        let (prefix, hinge): (String, HingeSpec) = match (entry[c], &defaults) {
            (Some(i), _) => (format!("hinges[{i}]"), spec.hinges[i].hinge()),
            (None, Some(d)) => ("hinge_defaults".to_string(), d.clone()),
            (None, None) => {
                return Err(NanofoldError::missing_with(
                    format!("hinges: an entry with crease {e}"),
                    "or `hinge_defaults` for every crease not listed",
                ))
            }
        };
        let [a, b] = pattern.edges[e];
        let length = unit
            * (pattern.vertices[b][0] - pattern.vertices[a][0]).hypot(pattern.vertices[b][1] - pattern.vertices[a][1]);
        within(
            &format!("length_unit_um × the length of crease {e}"),
            length / MICROMETRE,
            limits::LENGTH_UM,
            "µm",
        )?;
        stiffness[c] = hinge_stiffness_named(&spec.materials, &prefix, &hinge, length)?;
        if !(stiffness[c].is_finite() && stiffness[c] > 0.0) {
            return Err(NanofoldError::invalid(
                prefix,
                format!("stiffness {:e} N·m/rad", stiffness[c]),
                "the bending stiffness overflows or vanishes in double precision: check the units",
            ));
        }
        drives[c] = drive(&prefix, &hinge, entry[c].is_some(), pattern.kinds[e], e, actuation)?;
    }
    if !drives.iter().any(|d| d.actuated) {
        return Err(NanofoldError::invalid(
            "hinges[*].actuated",
            "all false",
            "nothing drives the network (set `actuated` on a hinge or on `hinge_defaults`)",
        ));
    }
    if let (Some(u), Actuation::Ramp { etch_rate }) = (front, actuation) {
        // The film under a crease holds its panel flat until the front has passed the whole
        // crease line (its last point along u); the first actuated crease so freed starts at
        // t = 0.
        let reach: Vec<f64> = (0..columns)
            .map(|c| {
                let [a, b] = pattern.edges[pattern.creases[c]];
                let along = |v: usize| unit * (u[0] * pattern.vertices[v][0] + u[1] * pattern.vertices[v][1]);
                along(a).max(along(b))
            })
            .collect();
        let first = (0..columns)
            .filter(|&c| drives[c].actuated)
            .map(|c| reach[c])
            .fold(f64::INFINITY, f64::min);
        for (drive, reach) in drives.iter_mut().zip(&reach) {
            if drive.actuated {
                drive.release_time = (reach - first) / etch_rate;
            }
        }
    }
    let thickness = within(
        "plates.thickness_um",
        spec.plates.thickness_um,
        limits::THICKNESS_UM,
        "µm",
    )? * MICROMETRE;
    let density = material(&spec.materials, "plates.material", &spec.plates.material)?.density_g_cm3 * 1e3;
    let anchored_panel = match spec.anchored_face {
        None => folding.root_panel,
        Some(face) => match pattern.face_from_file(face) {
            Some(f) => pattern.panel_of_face[f],
            None => {
                return Err(NanofoldError::invalid(
                    "anchored_face",
                    face,
                    format!("the pattern has {} faces", pattern.faces.len()),
                ))
            }
        },
    };
    // The start: the pattern's own state, rigid within the tolerance.
    let mut start = folding.given_fold_angles();
    let residual = worst_residual_of(&folding, &start);
    if residual > START_TOLERANCE {
        return Err(NanofoldError::invalid(
            "pattern",
            format!("closure residual {residual:.3e} rad"),
            format!("the start is not a rigid state (above {START_TOLERANCE:e} rad at some vertex): fold it with `nanofold fold` or project it with `check --project`"),
        ));
    }
    let drag = drag_law(&spec.environment)?;
    crate::dynamics::spec::time_and_outputs(&spec.time, &spec.outputs)?;
    let mut model = NetworkModel::new(NetworkParts {
        folding,
        unit,
        anchored_panel,
        thickness,
        density,
        stiffness,
        forcing: Forcing {
            actuation,
            hinges: drives,
        },
        drag,
        start: start.clone(),
        substrate_contact: spec.substrate.contact,
    })?;
    if worst_residual(&model, &start) > super::manifold::CLOSURE_TOL {
        restore(&model, &mut start, &mut projection_solver())?;
        model.start = start;
    }
    let usable = |x: f64| x.is_finite() && x > 0.0;
    if let Some(p) = model.bodies.iter().position(|b| !usable(b.mass)) {
        return Err(NanofoldError::invalid(
            "plates",
            format!("panel {p}: mass {:e} kg", model.bodies[p].mass),
            "the panel's mass overflows or vanishes in double precision: check length_unit_um, plates.thickness_um and the density",
        ));
    }
    if !spec.seams.is_empty() {
        if !model.folding.stars.is_empty() {
            return Err(NanofoldError::invalid(
                "seams",
                format!("{} pairs", spec.seams.len()),
                "seams latch on a tree of panels (a net); this pattern closes loops of its own",
            ));
        }
        model.seams = Some(crate::pattern::net::SeamGluing::new(
            &model.folding.pattern,
            &spec.seams,
        )?);
    }
    if let Some(friction) = spec.friction_coefficient {
        if !(0.0..=10.0).contains(&friction) {
            return Err(NanofoldError::invalid(
                "friction_coefficient",
                friction,
                "Coulomb's coefficient between faces: from 0 (frictionless) to 10",
            ));
        }
        model.friction_coefficient = friction;
    }
    if let Some(constraint) = &spec.constraint {
        match constraint.source {
            NetworkSource::Poly => model.reduction = Some(reduce(&model, constraint)?),
            NetworkSource::Network => {
                if let Some(edge) = constraint.driver_edge {
                    return Err(NanofoldError::invalid(
                        "constraint.driver_edge",
                        edge,
                        "a driver is for the fitted curves (source \"poly\"); the exact network has none",
                    ));
                }
                if let Some([a, b]) = constraint.range_deg {
                    return Err(NanofoldError::invalid(
                        "constraint.range_deg",
                        format!("[{a}, {b}]"),
                        "a range is for the fitted curves (source \"poly\"); the exact network has none",
                    ));
                }
            }
        }
    }
    Ok(model)
}

fn worst_residual_of(folding: &FoldingModel, angles: &[f64]) -> f64 {
    crate::folding::vertex_residuals(folding, angles)
        .into_iter()
        .fold(0.0, f64::max)
}

/// One crease's drive: its target (its own, signed; or the defaults' magnitude with the
/// assignment's sign) and its ramp's radius of curvature.
fn drive(
    prefix: &str,
    hinge: &HingeSpec,
    own: bool,
    kind: EdgeKind,
    edge: usize,
    actuation: Actuation,
) -> Result<HingeDrive> {
    let target_field = format!("{prefix}.target_angle_deg");
    let sign = match kind {
        EdgeKind::Crease(Assignment::Valley) => 1.0,
        EdgeKind::Crease(Assignment::Mountain) => -1.0,
        _ => 0.0,
    };
    let target = match (hinge.actuated, hinge.target_angle_deg) {
        (false, Some(deg)) if own => {
            return Err(NanofoldError::invalid(
                target_field,
                deg,
                "a passive hinge (actuated: false) has no target",
            ))
        }
        (false, _) => return Ok(HingeDrive::PASSIVE),
        (true, None) => return Err(NanofoldError::missing(target_field)),
        (true, Some(deg)) => {
            finite(&target_field, deg)?;
            if deg.abs() > 180.0 {
                return Err(NanofoldError::invalid(target_field, deg, "must lie in [−180, 180]"));
            }
            if own {
                if sign * deg < 0.0 {
                    return Err(NanofoldError::invalid(
                        target_field,
                        deg,
                        format!(
                            "crease {edge} is a {}: its target's sign contradicts the assignment (mountain ≤ 0 ≤ valley)",
                            if sign > 0.0 { "valley" } else { "mountain" }
                        ),
                    ));
                }
                deg.to_radians()
            } else {
                if sign == 0.0 {
                    return Err(NanofoldError::invalid(
                        target_field,
                        deg,
                        format!("crease {edge} is unassigned: the defaults' target takes the assignment's sign, so it needs its own entry in `hinges`"),
                    ));
                }
                if deg < 0.0 {
                    return Err(NanofoldError::invalid(
                        target_field,
                        deg,
                        "the defaults' target is a magnitude (each crease takes its assignment's sign)",
                    ));
                }
                sign * deg.to_radians()
            }
        }
    };
    let radius = match actuation {
        Actuation::Step => f64::INFINITY,
        Actuation::Ramp { .. } => {
            let field = format!("{prefix}.radius_of_curvature_um");
            let value = hinge
                .radius_of_curvature_um
                .ok_or_else(|| NanofoldError::missing(field.clone()))?;
            within(&field, value, limits::LENGTH_UM, "µm")? * MICROMETRE
        }
    };
    Ok(HingeDrive {
        target,
        radius_of_curvature: radius,
        actuated: true,
        release_time: 0.0,
    })
}

/// A closed-chain scene (a single vertex, `constraint.source` "network") as a panel network:
/// its faces the panels, its hinges, drives, locks and anchored face as the chain has them,
/// and its start (the driver's start angle with the others closed on the chain's branch)
/// the network's rigid start (`docs/model.md#panel-networks`).
pub fn from_closed(spec: &ClosedSpec<VertexPattern>, chain: &ClosedChain) -> Result<NetworkModel> {
    let pattern = &spec.pattern;
    let mesh = pattern.mesh.as_ref().ok_or_else(|| {
        NanofoldError::invalid(
            "pattern",
            &pattern.name,
            "must be a FOLD file (its faces are the plates)",
        )
    })?;
    let mut ws = chain.workspace();
    chain.update_creases(chain.start, &mut ws)?;
    let edges = mesh.edges_vertices.len();
    let mut fold_angles = vec![0.0; edges];
    let mut locked = vec![false; edges];
    for c in 0..pattern.creases.len() {
        let e = pattern.user_index(c);
        // A flat start carries the sweep's rounding (±1e-13): it must not contradict the assignment.
        let angle = ws.crease_angles[c];
        fold_angles[e] = if angle.abs() < 1e-10 { 0.0 } else { angle };
        locked[e] = chain.locked.iter().any(|&(l, _)| l == c);
    }
    let kinds = mesh
        .edges_assignment
        .iter()
        .map(|letter| match letter.as_str() {
            "B" => EdgeKind::Boundary,
            "F" => EdgeKind::Facet,
            "M" => EdgeKind::Crease(Assignment::Mountain),
            "V" => EdgeKind::Crease(Assignment::Valley),
            _ => EdgeKind::Crease(Assignment::Unassigned),
        })
        .collect();
    let crease_pattern = CreasePatternBuilder {
        name: pattern.name.clone(),
        vertices: mesh.vertices_coords.clone(),
        edges: mesh.edges_vertices.clone(),
        kinds,
        fold_angles,
        faces: mesh.faces_vertices.clone(),
        angle_field: "edges_foldAngle".to_string(),
        folded_form: None,
        locked,
        unit: mesh.unit.clone(),
        source_magnitude: 0.0,
    }
    .build()?;
    let folding = FoldingModel::new(crease_pattern)?;
    let of_column: Vec<usize> = folding
        .pattern
        .creases
        .iter()
        .map(|&e| {
            pattern.crease_from_user_index(e).ok_or_else(|| {
                NanofoldError::invalid(
                    "pattern",
                    e,
                    "an edge the crease pattern reads as a crease is no crease of the vertex",
                )
            })
        })
        .collect::<Result<_>>()?;
    let stiffness = of_column.iter().map(|&c| chain.crease_stiffness[c]).collect();
    let forcing = Forcing {
        actuation: chain.forcing.actuation,
        hinges: of_column.iter().map(|&c| chain.forcing.hinges[c]).collect(),
    };
    let start = of_column
        .iter()
        .map(|&c| {
            let angle = ws.crease_angles[c];
            if angle.abs() < 1e-10 {
                0.0
            } else {
                angle
            }
        })
        .collect();
    let anchored_panel = folding
        .pattern
        .face_from_file(chain.anchored_face)
        .map(|f| folding.pattern.panel_of_face[f])
        .ok_or_else(|| NanofoldError::invalid("anchored_face", chain.anchored_face, "not a face of the pattern"))?;
    let thickness = within(
        "plates.thickness_um",
        spec.plates.thickness_um,
        limits::THICKNESS_UM,
        "µm",
    )? * MICROMETRE;
    let density = material(&spec.materials, "plates.material", &spec.plates.material)?.density_g_cm3 * 1e3;
    let unit = within("length_unit_um", spec.length_unit_um, limits::LENGTH_UNIT_UM, "µm")? * MICROMETRE;
    NetworkModel::new(NetworkParts {
        folding,
        unit,
        anchored_panel,
        thickness,
        density,
        stiffness,
        forcing,
        drag: chain.model.drag(),
        start,
        substrate_contact: false,
    })
}

/// A plate's extent along its crease, m.
fn plate_width(plate: &crate::dynamics::model::Plate) -> f64 {
    let xs = plate.outline.iter().map(|q| q.x);
    xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min)
}

/// The first plate of another width than plate 0's (a strip the network cannot carry).
pub fn narrower_plate(chain: &StripChain) -> Option<usize> {
    let plates = chain.model.plates();
    let w = plate_width(&plates[0]);
    (1..plates.len()).find(|&i| (plate_width(&plates[i]) / w - 1.0).abs() > 1e-12)
}

/// A strip scene (`equations` "network") as a panel network: the substrate is the anchored
/// panel (as wide as the plates, reaching back from the edge as far as the strip reaches
/// forward), plate i the panel beyond crease i, each with the strip's own plate body (its
/// mass, centre and inertia, a stated moment included), hinge, drive and drag.
pub fn from_strip(name: &str, chain: &StripChain) -> Result<NetworkModel> {
    let model = &chain.model;
    let plates = model.plates();
    let n = plates.len();
    // The strip's plates span x ∈ [−w/2, w/2]; a network's panels must share whole creases.
    let w = plate_width(&plates[0]);
    if let Some(i) = narrower_plate(chain) {
        return Err(NanofoldError::invalid(
            format!("plates[{i}].width_um"),
            plate_width(&plates[i]) / MICROMETRE,
            format!(
                "equations \"network\" needs every plate as wide as plate 0 ({} µm): a crease joins whole plate edges",
                w / MICROMETRE
            ),
        ));
    }
    // Crease lines in µm (the pattern's unit), from the joints' points.
    let unit = MICROMETRE;
    let lines: Vec<f64> = model.joints().iter().map(|j| j.point.y / unit).collect();
    let end = plates
        .last()
        .map(|p| {
            (p.reference_pose.translation.y + p.outline.iter().map(|q| q.y).fold(f64::NEG_INFINITY, f64::max)) / unit
        })
        .unwrap_or(lines[0]);
    let (left, right) = (-0.5 * w / unit, 0.5 * w / unit);
    let mut rows = vec![lines[0] - (end - lines[0])];
    rows.extend(&lines);
    rows.push(end);
    // Vertices row by row (left, right); faces between consecutive rows.
    let vertices: Vec<[f64; 2]> = rows.iter().flat_map(|&y| [[left, y], [right, y]]).collect();
    let (mut edges, mut kinds, mut fold_angles) = (Vec::new(), Vec::new(), Vec::new());
    for (r, _) in rows.iter().enumerate() {
        let (l, rr) = (2 * r, 2 * r + 1);
        let kind = if r == 0 || r == rows.len() - 1 {
            EdgeKind::Boundary
        } else {
            let target = chain.forcing.hinges[r - 1].target;
            EdgeKind::Crease(if target > 0.0 {
                Assignment::Valley
            } else if target < 0.0 {
                Assignment::Mountain
            } else {
                Assignment::Unassigned
            })
        };
        edges.push([l, rr]);
        kinds.push(kind);
        fold_angles.push(0.0);
        if r + 1 < rows.len() {
            for side in [l, rr] {
                edges.push([side, side + 2]);
                kinds.push(EdgeKind::Boundary);
                fold_angles.push(0.0);
            }
        }
    }
    let faces: Vec<Vec<usize>> = (0..rows.len() - 1)
        .map(|r| vec![2 * r, 2 * r + 1, 2 * r + 3, 2 * r + 2])
        .collect();
    let locked = vec![false; edges.len()];
    let pattern = CreasePatternBuilder {
        name: name.to_string(),
        vertices,
        edges,
        kinds,
        fold_angles,
        faces: Some(faces),
        angle_field: "edges_foldAngle".to_string(),
        folded_form: None,
        locked,
        unit: Some("um".to_string()),
        source_magnitude: 0.0,
    }
    .build()?;
    let folding = FoldingModel::new(pattern)?;
    // Column c is crease i when its edge lies on row i + 1.
    let hinge_of_column: Vec<usize> = folding
        .pattern
        .creases
        .iter()
        .map(|&e| {
            // The hinge lines are in the strip's own coordinates, as the file's are.
            let y = folding
                .pattern
                .file_point(folding.pattern.vertices[folding.pattern.edges[e][0]])[1];
            (0..lines.len())
                .min_by(|&a, &b| (lines[a] - y).abs().total_cmp(&(lines[b] - y).abs()))
                .expect("a strip has hinges")
        })
        .collect();
    let anchored_panel = folding
        .pattern
        .face_from_file(0)
        .map(|f| folding.pattern.panel_of_face[f])
        .expect("face 0 is the substrate");
    let thickness = plates.iter().map(|p| p.thickness).fold(0.0, f64::max);
    let density = plates[0].mass / (plates[0].area * plates[0].thickness);
    let mut network = NetworkModel::new(NetworkParts {
        folding,
        unit,
        anchored_panel,
        thickness,
        density,
        stiffness: hinge_of_column.iter().map(|&i| model.joints()[i].stiffness).collect(),
        forcing: Forcing {
            actuation: chain.forcing.actuation,
            hinges: hinge_of_column.iter().map(|&i| chain.forcing.hinges[i]).collect(),
        },
        drag: model.drag(),
        start: vec![0.0; hinge_of_column.len()],
        substrate_contact: false,
    })?;
    // Each plate's own body (the strip's box, or its stated moment), on the panel of face i + 1.
    for (i, plate) in plates.iter().enumerate() {
        let face = network
            .folding
            .pattern
            .face_from_file(i + 1)
            .expect("one face per plate");
        let panel = network.folding.pattern.panel_of_face[face];
        network.bodies[panel] = PanelBody {
            mass: plate.mass,
            centre: plate.reference_pose.translation.vector,
            inertia: plate.inertia,
            area: plate.area,
        };
    }
    for (c, &i) in hinge_of_column.iter().enumerate() {
        network.labels[c] = format!("hinge {i}");
    }
    // The strip's own names: the substrate, plate i.
    network.panel_names[anchored_panel] = "substrate".to_string();
    for i in 0..n {
        let face = network
            .folding
            .pattern
            .face_from_file(i + 1)
            .expect("one face per plate");
        network.panel_names[network.folding.pattern.panel_of_face[face]] = format!("plate {i}");
    }
    Ok(network)
}

#[cfg(test)]
mod tests {
    use super::super::algorithms::{
        update_bias, update_drag, update_kinematics, update_mass_matrix, update_velocities, NetworkData,
    };
    use crate::dynamics::algorithms as chain_algorithms;
    use crate::dynamics::model::Data;
    use crate::dynamics::scene::System;
    use crate::read::scene_spec::StripEquations;

    /// The serial chain is the network's oracle on a strip: the network's M by composite
    /// rigid bodies and its Newton–Euler bias C ρ̇ − Q_drag equal the chain's dense M (product
    /// of exponentials), its Coriolis torques and its drag torques, entry by entry, at states
    /// far from the start (both drag laws on, rates of 10⁴ rad/s).
    #[test]
    fn a_strips_mass_matrix_and_coriolis_torques_are_the_serial_chains() {
        for path in [
            "patterns/bridge_step.scene.json",
            "patterns/thesis/bridge_thesis_reading.scene.json",
        ] {
            let mut spec = crate::read::load_scene(path.as_ref()).unwrap();
            let crate::read::scene_spec::SceneSpec::Strip(strip) = &mut spec else {
                panic!("{path} is a strip")
            };
            strip.equations = StripEquations::Chain;
            let scene = spec.build().unwrap();
            let System::Strip(chain) = &scene.system else {
                panic!("{path}: the chain's equations")
            };
            let network = super::from_strip("strip", chain).unwrap();
            let n = chain.model.dof();
            assert_eq!(network.columns(), n);
            // Column c is hinge i (the labels say which).
            let hinge: Vec<usize> = network
                .labels
                .iter()
                .map(|label| label.strip_prefix("hinge ").unwrap().parse().unwrap())
                .collect();
            let mut chain_data = Data::new(&chain.model);
            let mut network_data = NetworkData::new(&network);
            for (angles, rates) in [
                (vec![0.3, -0.5, 1.1, 0.7], vec![1e4, -3e4, 2e4, 5e3]),
                (vec![1.5, 1.4, 1.6, 2.9], vec![-2e3, 4e4, 1e3, -3e4]),
            ] {
                // Hinge i's angle and rate, in network columns.
                let rho: Vec<f64> = hinge.iter().map(|&i| angles[i]).collect();
                let rho_dot: Vec<f64> = hinge.iter().map(|&i| rates[i]).collect();
                chain_algorithms::update_kinematics(&chain.model, &angles, &mut chain_data);
                chain_algorithms::update_mass_matrix(&chain.model, &mut chain_data);
                chain_algorithms::update_velocities(&chain.model, &rates, &mut chain_data);
                let mut coriolis = vec![0.0; n];
                chain_algorithms::coriolis_torques(&chain.model, &rates, &mut chain_data, &mut coriolis);
                let mut drag = vec![0.0; n];
                chain_algorithms::drag_torques(&chain.model, &mut chain_data, &mut drag);
                update_kinematics(&network, &rho, &mut network_data);
                update_mass_matrix(&network, &mut network_data);
                update_velocities(&network, &rho_dot, &mut network_data);
                update_drag(&network, &mut network_data);
                update_bias(&network, &mut network_data);
                let mass = &chain_data.mass_matrix;
                let scale = mass.amax();
                // Every stored entry of the network's M (a strip is one path: all of them).
                assert_eq!(network.mass_pattern.len(), n * (n + 1) / 2, "{path}");
                for (&(a, c), value) in network.mass_pattern.iter().zip(&network_data.mass_values) {
                    let expected = mass[(hinge[a], hinge[c])];
                    assert!(
                        (value - expected).abs() <= 1e-12 * scale,
                        "{path}: M[{a}, {c}] {value:e} vs the chain's {expected:e}"
                    );
                }
                let torques: Vec<f64> = (0..n).map(|i| coriolis[i] - drag[i]).collect();
                let scale = torques.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
                assert!(drag.iter().any(|d| d.abs() > 1e-3 * scale), "{path}: drag takes part");
                for (c, bias) in network_data.bias.iter().enumerate() {
                    let expected = torques[hinge[c]];
                    assert!(
                        (bias - expected).abs() <= 1e-10 * scale,
                        "{path}: column {c}: C ρ̇ − Q {bias:e} vs the chain's {expected:e}"
                    );
                }
            }
        }
    }
}
