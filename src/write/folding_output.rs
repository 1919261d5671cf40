//! FOLD and JSON written for crease patterns of many vertices (`docs/model.md#folding-paths`):
//! the crease pattern (with or without a state), the folding path as FOLD frames over the
//! crease pattern, and its trajectory.

use crate::dynamics::algorithms::{update_corners, update_poses as update_plates};
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::model::{Data, Model};
use crate::dynamics::network::manifold::{projection_solver, restore};
use crate::dynamics::network::modes::NetworkModes;
use crate::dynamics::network::NetworkModel;
use crate::dynamics::points::{FlatOutline, PanelPoints, GROUND};
use crate::dynamics::scene::{Scene, System};
use crate::dynamics::simulate::Response;
use crate::dynamics::strip::StripChain;
use crate::error::Result;
use crate::folding::{panel_poses, vertex_positions, FoldPath, FoldingModel, PathFrame};
use crate::names::Named;
use crate::pattern::crease_pattern::{CreasePattern, EdgeKind};
use crate::pattern::Assignment;
use crate::write::output::number;
use serde_json::{json, Value};

/// FOLD's letter for an edge, the assignment following the angle's sign (M < 0 < V) when
/// the crease is folded; a crease at 0 keeps its assignment.
fn letter(kind: EdgeKind, angle: f64) -> &'static str {
    match kind {
        EdgeKind::Boundary => "B",
        EdgeKind::Facet => "F",
        EdgeKind::Crease(_) if angle > 0.0 => "V",
        EdgeKind::Crease(_) if angle < 0.0 => "M",
        EdgeKind::Crease(assignment) => match assignment {
            Assignment::Mountain => "M",
            Assignment::Valley => "V",
            Assignment::Flat => "F",
            Assignment::Unassigned => "U",
        },
    }
}

/// Per-edge fold angles (degrees) and letters for a state given per crease column.
fn edge_arrays(pattern: &CreasePattern, fold_angles: &[f64]) -> (Vec<f64>, Vec<&'static str>) {
    let mut angles = vec![0.0; pattern.edges.len()];
    for (column, &e) in pattern.creases.iter().enumerate() {
        angles[e] = fold_angles[column].to_degrees();
    }
    let letters = pattern
        .kinds
        .iter()
        .zip(&angles)
        .map(|(&kind, &angle)| letter(kind, angle))
        .collect();
    (angles, letters)
}

/// The crease pattern as a FOLD object (2D, `creasePattern`), with `edges_foldAngle` when a
/// state is given (one angle per crease column, rad), so that `check`, `fold` and `unfold`
/// read it back.
pub fn crease_pattern_fold(pattern: &CreasePattern, fold_angles: Option<&[f64]>, creator_note: &str) -> Value {
    let zero = vec![0.0; pattern.creases.len()];
    let (angles, letters) = edge_arrays(pattern, fold_angles.unwrap_or(&zero));
    let mut root = json!({
        "file_spec": 1.1,
        "file_creator": "nanofold",
        "file_title": pattern.name,
        "file_description": creator_note,
        "file_classes": ["singleModel"],
        "frame_classes": ["creasePattern"],
        "frame_attributes": ["2D"],
        "frame_unit": pattern.unit.clone().unwrap_or_else(|| "unit".into()),
        "vertices_coords": pattern.file_vertices(),
        "edges_vertices": pattern.edges,
        "edges_assignment": letters,
        "faces_vertices": pattern.faces,
    });
    if fold_angles.is_some() {
        root["edges_foldAngle"] = json!(angles);
    }
    if pattern.locked.iter().any(|&l| l) {
        root[crate::read::fold::LOCKED_KEY] = json!(pattern.locked);
    }
    root
}

/// The folding path as FOLD: the crease pattern (flat, 2D) is the key frame; each frame
/// placed on the path ([`path_frames`](crate::folding::path_frames)) is a 3D `foldedForm`
/// frame with its fold angles and the assignments they imply.
pub fn fold_path_fold(model: &FoldingModel, frames: &[PathFrame]) -> Value {
    let frames: Vec<(String, &[f64])> = frames
        .iter()
        .map(|frame| {
            (
                format!("progress {:.4} (after step {})", frame.progress, frame.after_step),
                frame.fold_angles.as_slice(),
            )
        })
        .collect();
    states_fold(model, None, &frames, "folding path written by nanofold fold")
}

/// A FOLD animation over the crease pattern: the key frame is the pattern (2D,
/// `creasePattern`; with `key_state`, that state's fold angles, so the file reads back as
/// that state), then one 3D `foldedForm` frame per (title, fold angles) with the
/// assignments its angles imply.
pub fn states_fold(
    model: &FoldingModel,
    key_state: Option<&[f64]>,
    frames: &[(String, &[f64])],
    description: &str,
) -> Value {
    let pattern = &model.pattern;
    let mut root = crease_pattern_fold(pattern, key_state, description);
    if key_state.is_some() {
        // The key frame keeps the input's own assignments.
        root["edges_assignment"] = json!(pattern.kinds.iter().map(|&kind| letter(kind, 0.0)).collect::<Vec<_>>());
    }
    root["file_classes"] = json!(["animation"]);
    root["frame_title"] = json!(format!("{}: crease pattern", pattern.name));
    let mut poses = Vec::new();
    let frames: Vec<Value> = frames
        .iter()
        .map(|(title, fold_angles)| {
            panel_poses(model, fold_angles, &mut poses);
            let (angles, letters) = edge_arrays(pattern, fold_angles);
            let coords: Vec<_> = vertex_positions(model, &poses)
                .into_iter()
                .map(|p| pattern.file_point_3d(p))
                .collect();
            let mut frame = inheriting_frame(title, json!(coords), json!(angles));
            frame["edges_assignment"] = json!(letters);
            frame
        })
        .collect();
    root["file_frames"] = json!(frames);
    root
}

/// `trajectory.json` of a folding path: every step (thinned evenly to at most `max_steps`).
pub fn fold_trajectory_json(model: &FoldingModel, path: &FoldPath, max_steps: usize) -> Value {
    let chosen = evenly(path.steps.len(), steps_to_write(max_steps, model.crease_count()));
    let steps: Vec<Value> = chosen
        .iter()
        .map(|&i| {
            let s = &path.steps[i];
            json!({
                "step": i,
                "progress": s.progress,
                "fold_angles_rad": s.fold_angles,
                "max_closure_residual_rad": s.max_residual,
                "min_panel_clearance": s.min_clearance.map_or(Value::Null, number),
            })
        })
        .collect();
    json!({
        "pattern": model.pattern.name,
        "units": {"angles": "rad", "lengths": "the pattern's own"},
        "creases_edge_index": model.pattern.creases,
        "stop_reason": path.stop.as_str(),
        "evidence": path.evidence,
        "branch": path.branch,
        "recorded_steps": path.steps.len(),
        "steps_written": steps.len(),
        "steps": steps,
    })
}

/// Most fold angles a written trajectory holds (steps × creases): a pattern of many creases
/// gets fewer steps written, so the file and the memory that renders it stay bounded.
pub const MAX_TRAJECTORY_ANGLES: usize = 2_000_000;

/// How many of a run's steps a trajectory file writes for `creases` angles a step: up to
/// `max_steps`, fewer when that would pass [`MAX_TRAJECTORY_ANGLES`] (at least the first
/// and the last).
pub fn steps_to_write(max_steps: usize, creases: usize) -> usize {
    max_steps.min(MAX_TRAJECTORY_ANGLES / creases.max(1)).max(2)
}

/// `count` indices spread evenly over 0..total, first and last kept.
pub fn evenly(total: usize, count: usize) -> Vec<usize> {
    if total == 0 {
        return Vec::new();
    }
    if total <= count {
        return (0..total).collect();
    }
    let mut out: Vec<usize> = (0..count.max(2))
        .map(|k| k * (total - 1) / (count.max(2) - 1))
        .collect();
    out.dedup();
    out
}

/// A network's states as a FOLD animation: the crease pattern is the key frame (2D, with
/// the first state's fold angles, so the file reads back as the start), then one 3D
/// `foldedForm` frame per (title, fold angles), posed as the dynamics poses them (the
/// anchored panel fixed; lengths in the pattern's units).
pub fn network_states_fold(model: &NetworkModel, frames: &[(String, &[f64])], description: &str) -> Value {
    let pattern = &model.folding.pattern;
    let key = frames.first().map(|(_, angles)| *angles);
    let mut root = crease_pattern_fold(pattern, key, description);
    root["edges_assignment"] = json!(pattern.kinds.iter().map(|&kind| letter(kind, 0.0)).collect::<Vec<_>>());
    root["file_classes"] = json!(["animation"]);
    root["frame_title"] = json!(format!("{}: crease pattern", pattern.name));
    // Every vertex placed by the panel it belongs to, as the fit's marks are.
    let mut points = PanelPoints::for_network(model);
    let unit_um = model.unit * 1e6;
    let frames: Vec<Value> = frames
        .iter()
        .map(|(title, fold_angles)| {
            points.pose(fold_angles);
            let coords: Vec<[f64; 3]> = pattern
                .vertices
                .iter()
                .zip(&model.folding.panel_of_vertex)
                .map(|(&vertex, &panel)| {
                    let [x, y] = pattern.file_point(vertex);
                    points.place(panel, [x * unit_um, y * unit_um]).map(|c| c / unit_um)
                })
                .collect();
            let (angles, letters) = edge_arrays(pattern, fold_angles);
            let mut frame = inheriting_frame(title, json!(coords), json!(angles));
            frame["edges_assignment"] = json!(letters);
            frame
        })
        .collect();
    root["file_frames"] = json!(frames);
    root
}

/// A folded frame of a FOLD animation that inherits the key frame's edges and faces: its
/// title, placed vertices and fold angles (degrees).
fn inheriting_frame(title: &str, coords: Value, fold_angles_deg: Value) -> Value {
    json!({
        "frame_title": title,
        "frame_classes": ["foldedForm"],
        "frame_attributes": ["3D"],
        "frame_parent": 0,
        "frame_inherit": true,
        "vertices_coords": coords,
        "edges_foldAngle": fold_angles_deg,
    })
}

/// Most frames of a motion animation.
pub const MOTION_FRAMES: usize = 101;

/// The samples a motion animation shows: the nearest to each of up to [`MOTION_FRAMES`]
/// evenly spaced times, so FOLD viewers play it at an even pace.
fn motion_samples(response: &Response) -> Vec<(String, &[f64])> {
    let samples = &response.samples;
    let end = samples.last().map_or(0.0, |s| s.time);
    let count = MOTION_FRAMES.min(samples.len()).max(1);
    let mut chosen: Vec<usize> = (0..count)
        .map(|k| {
            let t = if count > 1 {
                end * k as f64 / (count - 1) as f64
            } else {
                end
            };
            (0..samples.len())
                .min_by(|&a, &b| (samples[a].time - t).abs().total_cmp(&(samples[b].time - t).abs()))
                .unwrap_or(0)
        })
        .collect();
    chosen.dedup();
    chosen
        .iter()
        .map(|&i| (format!("t = {:.6e} s", samples[i].time), samples[i].angles.as_slice()))
        .collect()
}

/// A network's `motion.fold` (see `motion_fold`).
pub fn network_motion_fold(model: &NetworkModel, response: &Response) -> Value {
    network_states_fold(
        model,
        &motion_samples(response),
        "a network's motion written by nanofold simulate (frames at even times)",
    )
}

/// `motion.fold` of any scene: the response at up to [`MOTION_FRAMES`] evenly spaced times,
/// every point placed by [`PanelPoints`] (as the fit's marks are). A pattern's in its file's
/// coordinates ([`network_states_fold`]); a strip's or a closed vertex's in µm
/// ([`plates_states_fold`]).
pub fn motion_fold(scene: &Scene, response: &Response) -> Value {
    let states = motion_samples(response);
    let description = "a device's motion written by nanofold simulate (frames at even times)";
    match &scene.system {
        System::Network(model) => network_motion_fold(model, response),
        System::Strip(chain) => strip_states_fold(chain, &states, description),
        System::Closed(chain) => closed_states_fold(chain, &states, description),
    }
}

/// A strip's states ([`plates_states_fold`]): the substrate's edge strip first (a third of
/// the strip's length deep, as wide as the plates), then plate i as face 1 + i; `states`
/// hold the hinge angles.
pub fn strip_states_fold(chain: &StripChain, states: &[(String, &[f64])], description: &str) -> Value {
    let mut points = PanelPoints::for_strip(chain);
    let outlines = points.plate_outlines();
    let (mut x_lo, mut x_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let edge = chain.substrate_edge_y * 1e6;
    let mut y_hi = edge;
    for [x, y] in outlines.iter().flat_map(|o| o.corners.iter().copied()) {
        x_lo = x_lo.min(x);
        x_hi = x_hi.max(x);
        y_hi = y_hi.max(y);
    }
    let depth = (y_hi - edge).max(x_hi - x_lo) / 3.0;
    let substrate = vec![[x_lo, edge - depth], [x_hi, edge - depth], [x_hi, edge], [x_lo, edge]];
    plates_states_fold(
        &mut points,
        &chain.model,
        Some(substrate),
        outlines,
        &|angles, j| angles[j],
        states,
        description,
    )
}

/// A closed vertex's states ([`plates_states_fold`]): the anchored sector first, then joint
/// j's plate as face 1 + j; `states` hold every crease's angle.
pub fn closed_states_fold(chain: &ClosedChain, states: &[(String, &[f64])], description: &str) -> Value {
    let mut points = PanelPoints::for_closed(chain);
    let outlines = points.plate_outlines();
    plates_states_fold(
        &mut points,
        &chain.model,
        None,
        outlines,
        &|angles, j| angles[chain.joint_creases[j]],
        states,
        description,
    )
}

/// Plates on hinges as a FOLD animation in µm: `fixed` (if any) and each outline a face of
/// its own corners, placed by `points` at every state (the first the key frame, the others
/// its frames); the outline edge of joint j's plate on its axis is that hinge's crease, its
/// fold angle `joint_angle(state, j)` and its assignment the sign of its largest excursion.
fn plates_states_fold(
    points: &mut PanelPoints,
    model: &Model,
    fixed: Option<Vec<[f64; 2]>>,
    outlines: Vec<FlatOutline>,
    joint_angle: &dyn Fn(&[f64], usize) -> f64,
    states: &[(String, &[f64])],
    description: &str,
) -> Value {
    // Joint j's hinge edge: the outline edge whose ends lie on its axis when flat.
    let mut data = Data::new(model);
    update_plates(model, &vec![0.0; model.dof()], &mut data);
    update_corners(model, &mut data);
    let size = data
        .corners
        .iter()
        .map(|c| c.coords.norm())
        .fold(f64::MIN_POSITIVE, f64::max);
    let hinge_of = |j: usize| -> Option<usize> {
        let joint = &model.joints()[j];
        let on_axis = |k: usize| {
            let p = data.corners[model.corner_index(j, k)];
            (p - joint.point).cross(&joint.axis).norm() <= 1e-9 * size
        };
        let n = model.plates()[j].outline.len();
        (0..n).find(|&k| on_axis(k) && on_axis((k + 1) % n))
    };
    let largest = |j: usize| {
        states
            .iter()
            .map(|(_, a)| joint_angle(a, j))
            .fold(0.0_f64, |m, a| if a.abs() > m.abs() { a } else { m })
    };
    let mut corners: Vec<(usize, [f64; 2])> = Vec::new();
    let mut faces: Vec<Vec<usize>> = Vec::new();
    let mut edges: Vec<[usize; 2]> = Vec::new();
    let mut letters: Vec<&str> = Vec::new();
    let mut creases: Vec<(usize, usize)> = Vec::new();
    let mut add = |panel: usize, outline: &[[f64; 2]], hinge: Option<(usize, usize)>| {
        let first = corners.len();
        let n = outline.len();
        corners.extend(outline.iter().map(|&c| (panel, c)));
        faces.push((first..first + n).collect());
        for k in 0..n {
            edges.push([first + k, first + (k + 1) % n]);
            match hinge {
                Some((j, at)) if at == k => {
                    creases.push((edges.len() - 1, j));
                    let sign = largest(j);
                    letters.push(if sign > 0.0 {
                        "V"
                    } else if sign < 0.0 {
                        "M"
                    } else {
                        "U"
                    });
                }
                _ => letters.push("B"),
            }
        }
    };
    if let Some(fixed) = &fixed {
        add(GROUND, fixed, None);
    }
    for outline in &outlines {
        let hinge = (outline.panel != GROUND)
            .then(|| hinge_of(outline.panel).map(|k| (outline.panel, k)))
            .flatten();
        add(outline.panel, &outline.corners, hinge);
    }
    let frame = |angles: &[f64], points: &mut PanelPoints| {
        points.pose(angles);
        let coords: Vec<[f64; 3]> = corners.iter().map(|&(panel, flat)| points.place(panel, flat)).collect();
        let mut degrees = vec![0.0; edges.len()];
        for &(e, j) in &creases {
            degrees[e] = joint_angle(angles, j).to_degrees();
        }
        (coords, degrees)
    };
    let first: &[f64] = states.first().map_or(&[], |(_, a)| a);
    let (coords, degrees) = frame(first, points);
    let mut root = json!({
        "file_spec": 1.1,
        "file_creator": "nanofold",
        "file_description": description,
        "file_classes": ["animation"],
        "frame_title": states.first().map_or(String::new(), |(t, _)| t.clone()),
        "frame_classes": ["foldedForm"],
        "frame_attributes": ["3D"],
        "frame_unit": "um",
        "vertices_coords": coords,
        "edges_vertices": edges,
        "edges_assignment": letters,
        "edges_foldAngle": degrees,
        "faces_vertices": faces,
    });
    let frames: Vec<Value> = states
        .iter()
        .skip(1)
        .map(|(title, angles)| {
            let (coords, degrees) = frame(angles, points);
            inheriting_frame(title, json!(coords), json!(degrees))
        })
        .collect();
    if !frames.is_empty() {
        root["file_frames"] = json!(frames);
    }
    root
}

/// `modes.fold`: the folded equilibrium as the key frame's state, then each mode as a pair
/// of frames, the equilibrium moved by ± its shape scaled to `amplitude` rad at its largest
/// crease and put back onto the closures.
pub fn network_modes_fold(model: &NetworkModel, modes: &NetworkModes, amplitude: f64) -> Result<Value> {
    let (plus, minus) = (format!("+ {amplitude} rad"), format!("− {amplitude} rad"));
    let phases = [(1.0, plus.as_str()), (-1.0, minus.as_str())];
    modes_states_fold(
        model,
        modes,
        amplitude,
        &phases,
        "a network's modes written by nanofold modes: the folded equilibrium, then each mode's shape either way",
    )
}

/// The modes as oscillations, for the 3D page: each mode at `phases` evenly spaced phases
/// of one cycle, the equilibrium moved by amplitude · sin(phase) along its shape.
pub fn network_modes_oscillation_fold(
    model: &NetworkModel,
    modes: &NetworkModes,
    amplitude: f64,
    phases: usize,
) -> Result<Value> {
    let labels: Vec<(f64, String)> = (0..phases)
        .map(|j| {
            let phase = 2.0 * std::f64::consts::PI * j as f64 / phases as f64;
            (phase.sin(), format!("phase {j}/{phases} of a ±{amplitude} rad cycle"))
        })
        .collect();
    let phases: Vec<(f64, &str)> = labels.iter().map(|(s, l)| (*s, l.as_str())).collect();
    modes_states_fold(
        model,
        modes,
        amplitude,
        &phases,
        "a network's modes as oscillations about the folded equilibrium, written by nanofold modes",
    )
}

/// The equilibrium, then each mode at each (factor, label): the equilibrium moved by factor ·
/// `amplitude` along the mode's shape (its largest crease at `amplitude` rad), put back onto
/// the closures.
fn modes_states_fold(
    model: &NetworkModel,
    modes: &NetworkModes,
    amplitude: f64,
    phases: &[(f64, &str)],
    description: &str,
) -> Result<Value> {
    let equilibrium = &modes.modes.equilibrium.angles;
    let shapes = &modes.modes.crease_shapes;
    let mut states: Vec<(String, Vec<f64>)> = vec![("folded equilibrium".to_string(), equilibrium.clone())];
    let mut released = model.clone();
    released.folding.locked_columns.iter_mut().for_each(|l| *l = false);
    let mut solver = projection_solver();
    for k in 0..shapes.ncols() {
        let largest = shapes
            .column(k)
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for &(factor, label) in phases {
            let mut state: Vec<f64> = equilibrium
                .iter()
                .zip(shapes.column(k).iter())
                .map(|(e, s)| e + factor * amplitude * s / largest)
                .collect();
            restore(&released, &mut state, &mut solver)?;
            states.push((
                format!("mode {k} ({:.3} Hz), {label}", modes.modes.modes.frequencies_hz[k]),
                state,
            ));
        }
    }
    let frames: Vec<(String, &[f64])> = states.iter().map(|(t, s)| (t.clone(), s.as_slice())).collect();
    Ok(network_states_fold(model, &frames, description))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trajectory keeps its 1000 steps up to 2000 creases, then as many as 2e6 angles
    /// allow, and never fewer than its two ends.
    #[test]
    fn written_trajectories_hold_at_most_two_million_angles() {
        assert_eq!(steps_to_write(1000, 24), 1000);
        assert_eq!(steps_to_write(1000, 2000), 1000);
        assert_eq!(steps_to_write(1000, 49_998), 40);
        assert_eq!(steps_to_write(1000, 10_000_000), 2);
        for creases in [1, 7, 2001, 49_998, 199_997] {
            assert!(steps_to_write(1000, creases) * creases <= MAX_TRAJECTORY_ANGLES.max(2 * creases));
        }
    }
}
