//! FOLD and JSON written for crease patterns of many vertices (`docs/model.md#folding-paths`):
//! the crease pattern (with or without a state), the folding path as FOLD frames over the
//! crease pattern, and its trajectory.

use crate::dynamics::network::algorithms::update_poses;
use crate::dynamics::network::manifold::{projection_solver, restore};
use crate::dynamics::network::modes::NetworkModes;
use crate::dynamics::network::{NetworkData, NetworkModel};
use crate::dynamics::simulate::Response;
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
            json!({
                "frame_title": title,
                "frame_classes": ["foldedForm"],
                "frame_attributes": ["3D"],
                "frame_parent": 0,
                "frame_inherit": true,
                "vertices_coords": vertex_positions(model, &poses).into_iter().map(|p| pattern.file_point_3d(p)).collect::<Vec<_>>(),
                "edges_assignment": letters,
                "edges_foldAngle": angles,
            })
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
    let mut data = NetworkData::new(model);
    let frames: Vec<Value> = frames
        .iter()
        .map(|(title, fold_angles)| {
            update_poses(model, fold_angles, &mut data);
            let coords: Vec<[f64; 3]> = pattern
                .vertices
                .iter()
                .zip(&model.folding.panel_of_vertex)
                .map(|(&[x, y], &panel)| {
                    let p =
                        data.place(panel, &nalgebra::Vector3::new(x * model.unit, y * model.unit, 0.0)) / model.unit;
                    pattern.file_point_3d([p.x, p.y, p.z])
                })
                .collect();
            let (angles, letters) = edge_arrays(pattern, fold_angles);
            json!({
                "frame_title": title,
                "frame_classes": ["foldedForm"],
                "frame_attributes": ["3D"],
                "frame_parent": 0,
                "frame_inherit": true,
                "vertices_coords": coords,
                "edges_assignment": letters,
                "edges_foldAngle": angles,
            })
        })
        .collect();
    root["file_frames"] = json!(frames);
    root
}

/// Most frames of a network's motion animation.
pub const MOTION_FRAMES: usize = 101;

/// `motion.fold`: the response at up to [`MOTION_FRAMES`] evenly spaced times (the sample
/// nearest each), so FOLD viewers play it at an even pace.
pub fn network_motion_fold(model: &NetworkModel, response: &Response) -> Value {
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
    let frames: Vec<(String, &[f64])> = chosen
        .iter()
        .map(|&i| (format!("t = {:.6e} s", samples[i].time), samples[i].angles.as_slice()))
        .collect();
    network_states_fold(
        model,
        &frames,
        "a network's motion written by nanofold simulate (frames at even times)",
    )
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
