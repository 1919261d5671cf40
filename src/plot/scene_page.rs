//! The 3D pages of a scene (`response.html`, `modes.html`): a response's samples, or modes
//! as oscillations, for strips, closed chains and networks, in µm, with the substrate or
//! anchored panel grey and the first contact's bodies marked.

use super::page::{page_html, scene_of_fold, PageFrame, PageScene};
use crate::dynamics::algorithms::{update_corners, update_poses};
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::contact::Collision;
use crate::dynamics::model::{Data, Model};
use crate::dynamics::network::NetworkModel;
use crate::dynamics::scene::{Scene, System};
use crate::dynamics::simulate::Response;
use crate::dynamics::strip::StripChain;
use crate::error::Result;
use nalgebra::Point3;

/// Most frames a response page keeps (samples are thinned evenly in time, the last kept).
pub const MAX_RESPONSE_FRAMES: usize = 241;

const MICROMETRES: f64 = 1e6;

/// `response.html` of a scene's simulation: its samples as frames (at most
/// [`MAX_RESPONSE_FRAMES`]), the first contact's bodies red on the last frame.
pub fn response_page(scene: &Scene, response: &Response) -> Result<String> {
    let picks = super::response::snapshot_samples(response, MAX_RESPONSE_FRAMES);
    let label = |k: usize| format!("t = {}", super::response::time_label(response.samples[k].time));
    let collision = response.collision.as_ref();
    match &scene.system {
        System::Network(model) => {
            let motion = crate::write::folding_output::network_motion_fold(model, response);
            network_response_page(&scene.name, model, &motion, collision)
        }
        System::Strip(chain) => {
            let states: Vec<(String, Vec<f64>)> = picks
                .iter()
                .map(|&k| (label(k), response.samples[k].angles.as_slice().to_vec()))
                .collect();
            let mut page = strip_scene(&scene.name, chain, &states);
            mark_contact(&mut page, collision, |name| {
                if name == "substrate" {
                    Some(0)
                } else {
                    name.strip_prefix("plate ")?.parse::<usize>().ok().map(|p| p + 1)
                }
            });
            page_html(&page)
        }
        System::Closed(chain) => {
            let states: Vec<(String, Vec<f64>)> = picks
                .iter()
                .map(|&k| {
                    let angles = &response.samples[k].angles;
                    (label(k), chain.joint_creases.iter().map(|&c| angles[c]).collect())
                })
                .collect();
            let mut page = closed_scene(&scene.name, chain, &states);
            mark_contact(&mut page, collision, |name| {
                if name == "anchored sector" {
                    return Some(0);
                }
                let crease = name.strip_prefix("sector of ")?;
                let joint = chain
                    .joint_creases
                    .iter()
                    .position(|&c| chain.crease_labels[c] == crease)?;
                Some(joint + 1)
            });
            page_html(&page)
        }
    }
}

/// A network's `response.html` from its `motion.fold` (every sample a frame), the anchored
/// panel grey, the first contact's panels red on the last frame.
pub fn network_response_page(
    name: &str,
    model: &NetworkModel,
    motion: &serde_json::Value,
    collision: Option<&Collision>,
) -> Result<String> {
    let mut page = scene_of_fold(motion, name)?.scaled(model.unit * MICROMETRES, "µm");
    let anchored = model.folding.pattern.panel_of_face[model.anchored_face];
    page.fixed = network_panel_faces(model, |p| p == anchored);
    if let (Some(c), Some(last)) = (collision, page.frames.last_mut()) {
        last.highlight = network_panel_faces(model, |p| c.pair.contains(&model.panel_names[p]));
    }
    page_html(&page)
}

/// The faces of the panels `chosen` picks.
fn network_panel_faces(model: &NetworkModel, chosen: impl Fn(usize) -> bool) -> Vec<usize> {
    let pattern = &model.folding.pattern;
    (0..pattern.faces.len())
        .filter(|&f| chosen(pattern.panel_of_face[f]))
        .collect()
}

/// Marks the collision's bodies (faces by `face_of` their names) on the last frame.
fn mark_contact(page: &mut PageScene, collision: Option<&Collision>, face_of: impl Fn(&str) -> Option<usize>) {
    if let (Some(c), Some(last)) = (collision, page.frames.last_mut()) {
        last.highlight = c.pair.iter().filter_map(|name| face_of(name)).collect();
        last.highlight.sort_unstable();
        last.highlight.dedup();
    }
}

/// A strip's page: the substrate (face 0, reaching back from its edge a third of the
/// strip's length) and the plates (face 1 + i), at each (title, hinge angles).
pub fn strip_scene(name: &str, chain: &StripChain, states: &[(String, Vec<f64>)]) -> PageScene {
    let model = &chain.model;
    let mut data = Data::new(model);
    update_poses(model, &vec![0.0; model.dof()], &mut data);
    update_corners(model, &mut data);
    let (mut x_lo, mut x_hi, mut y_hi) = (f64::INFINITY, f64::NEG_INFINITY, chain.substrate_edge_y);
    for c in &data.corners {
        x_lo = x_lo.min(c.x);
        x_hi = x_hi.max(c.x);
        y_hi = y_hi.max(c.y);
    }
    let edge = chain.substrate_edge_y;
    let depth = (y_hi - edge).max(x_hi - x_lo) / 3.0;
    let substrate = [
        Point3::new(x_lo, edge - depth, 0.0),
        Point3::new(x_hi, edge - depth, 0.0),
        Point3::new(x_hi, edge, 0.0),
        Point3::new(x_lo, edge, 0.0),
    ];
    let hinge_letters = letters_by_sign(model.dof(), states);
    plates_scene(name, model, &substrate, &hinge_letters, states)
}

/// A closed chain's page: the anchored sector (face 0) and the joints' plates (face 1 + j),
/// at each (title, joint angles).
pub fn closed_scene(name: &str, chain: &ClosedChain, states: &[(String, Vec<f64>)]) -> PageScene {
    let hinge_letters = letters_by_sign(chain.model.dof(), states);
    plates_scene(name, &chain.model, &chain.ground, &hinge_letters, states)
}

/// Mountain or valley by the sign of each hinge's largest excursion over the states.
fn letters_by_sign(hinges: usize, states: &[(String, Vec<f64>)]) -> Vec<char> {
    (0..hinges)
        .map(|j| {
            let largest = states
                .iter()
                .map(|(_, a)| a[j])
                .fold(0.0_f64, |m, a| if a.abs() > m.abs() { a } else { m });
            match largest.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Greater) => 'V',
                Some(std::cmp::Ordering::Less) => 'M',
                _ => 'U',
            }
        })
        .collect()
}

/// Rigid plates on hinges and one fixed polygon, as a page: each plate's outline is its own
/// face (its own vertices), the outline edge lying on its joint's axis is that hinge's crease
/// (assignment `hinge_letters`, fold angle the joint's), the rest boundary.
fn plates_scene(
    name: &str,
    model: &Model,
    fixed: &[Point3<f64>],
    hinge_letters: &[char],
    states: &[(String, Vec<f64>)],
) -> PageScene {
    let mut data = Data::new(model);
    let mut faces = vec![(0..fixed.len()).collect::<Vec<_>>()];
    let mut edges: Vec<[usize; 2]> = (0..fixed.len()).map(|k| [k, (k + 1) % fixed.len()]).collect();
    let mut assignments = vec!['B'; fixed.len()];
    let mut hinge_edges = vec![None; model.dof()];
    // At θ = 0 the plates lie at their reference poses, where each joint's axis is given.
    update_poses(model, &vec![0.0; model.dof()], &mut data);
    update_corners(model, &mut data);
    let size = data
        .corners
        .iter()
        .map(|c| c.coords.norm())
        .fold(f64::MIN_POSITIVE, f64::max);
    let mut next = fixed.len();
    for (j, plate) in model.plates().iter().enumerate() {
        let n = plate.outline.len();
        faces.push((next..next + n).collect());
        let joint = &model.joints()[j];
        let on_axis = |p: &Point3<f64>| (p - joint.point).cross(&joint.axis).norm() <= 1e-9 * size;
        for k in 0..n {
            let (a, b) = (model.corner_index(j, k), model.corner_index(j, (k + 1) % n));
            edges.push([next + k, next + (k + 1) % n]);
            if hinge_edges[j].is_none() && on_axis(&data.corners[a]) && on_axis(&data.corners[b]) {
                hinge_edges[j] = Some(edges.len() - 1);
                assignments.push(hinge_letters[j]);
            } else {
                assignments.push('B');
            }
        }
        next += n;
    }
    let frames = states
        .iter()
        .map(|(title, angles)| {
            update_poses(model, angles, &mut data);
            update_corners(model, &mut data);
            let mut fold_angles = vec![0.0; edges.len()];
            for (j, edge) in hinge_edges.iter().enumerate() {
                if let Some(e) = edge {
                    fold_angles[*e] = angles[j].to_degrees();
                }
            }
            PageFrame {
                title: title.clone(),
                coords: fixed
                    .iter()
                    .chain(&data.corners)
                    .map(|p| [p.x * MICROMETRES, p.y * MICROMETRES, p.z * MICROMETRES])
                    .collect(),
                fold_angles_deg: Some(fold_angles),
                highlight: Vec::new(),
            }
        })
        .collect();
    PageScene {
        title: name.to_string(),
        unit: "µm".into(),
        faces,
        edges,
        assignments,
        frames,
        fixed: vec![0],
    }
}

/// Phases of one cycle a mode's page shows.
pub const MODE_PHASES: usize = 12;

/// (factor, label) of each phase of one cycle: sin of the phase.
fn cycle(frequency_hz: f64, mode: usize, amplitude: f64) -> Vec<(f64, String)> {
    (0..MODE_PHASES)
        .map(|j| {
            let phase = 2.0 * std::f64::consts::PI * j as f64 / MODE_PHASES as f64;
            (
                phase.sin(),
                format!("mode {mode} ({frequency_hz:.4e} Hz), phase {j}/{MODE_PHASES} of a ±{amplitude} rad cycle"),
            )
        })
        .collect()
}

/// `modes.html` of a strip: the equilibrium, then each mode as [`MODE_PHASES`] phases of an
/// oscillation of ±`amplitude` rad in its largest hinge.
pub fn strip_modes_page(
    name: &str,
    chain: &StripChain,
    modes: &crate::dynamics::modes::Modes,
    amplitude: f64,
) -> Result<String> {
    let equilibrium = modes.equilibrium.as_slice();
    let mut states = vec![("folded equilibrium".to_string(), equilibrium.to_vec())];
    for (k, shape) in modes.mode_shapes.column_iter().enumerate() {
        let largest = shape.amax().max(f64::MIN_POSITIVE);
        for (factor, label) in cycle(modes.frequencies_hz[k], k, amplitude) {
            let angles = equilibrium
                .iter()
                .zip(shape.iter())
                .map(|(e, s)| e + factor * amplitude * s / largest)
                .collect();
            states.push((label, angles));
        }
    }
    page_html(&strip_scene(name, chain, &states))
}

/// `modes.html` of a closed chain: the equilibrium, then each mode as [`MODE_PHASES`] phases
/// of ±`amplitude` rad in its largest coordinate, every phase's loop closed again.
pub fn closed_modes_page(
    name: &str,
    chain: &ClosedChain,
    modes: &crate::dynamics::closed::modes::ClosedModes,
    amplitude: f64,
) -> Result<String> {
    let joints = |angles: &[f64]| -> Vec<f64> { chain.joint_creases.iter().map(|&c| angles[c]).collect() };
    let mut states = vec![("folded equilibrium".to_string(), joints(&modes.equilibrium))];
    let centre: Vec<f64> = modes.coordinates.iter().map(|&c| modes.equilibrium[c]).collect();
    for (k, shape) in modes.modes.mode_shapes.column_iter().enumerate() {
        let largest = shape.amax().max(f64::MIN_POSITIVE);
        for (factor, label) in cycle(modes.modes.frequencies_hz[k], k, amplitude) {
            let theta_c: Vec<f64> = centre
                .iter()
                .zip(shape.iter())
                .map(|(e, s)| e + factor * amplitude * s / largest)
                .collect();
            let state = chain.closure_state(&modes.coordinates, &theta_c, &modes.equilibrium)?;
            states.push((label, joints(&state.angles)));
        }
    }
    page_html(&closed_scene(name, chain, &states))
}
