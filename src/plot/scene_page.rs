//! The 3D pages of a scene (`response.html`, `modes.html`): a response's samples, or modes
//! as oscillations, for strips, closed chains and networks, in µm, with the substrate or
//! anchored panel grey and the first contact's bodies marked.

use super::page::{page_html, scene_of_fold, PageScene};
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::contact::Collision;
use crate::dynamics::network::NetworkModel;
use crate::dynamics::scene::{Scene, System};
use crate::dynamics::simulate::Response;
use crate::dynamics::strip::StripChain;
use crate::error::Result;
use crate::write::folding_output::{closed_states_fold, strip_states_fold};

const MICROMETRES: f64 = 1e6;

/// `response.html` of a scene's simulation: its `motion.fold` (up to
/// [`MOTION_FRAMES`](crate::write::MOTION_FRAMES) frames at even times, every point placed as
/// the fit's marks are), the fixed body grey, the first contact's bodies red on the last
/// frame.
pub fn response_page(scene: &Scene, response: &Response) -> Result<String> {
    let motion = crate::write::folding_output::motion_fold(scene, response);
    let collision = response.collision.as_ref();
    match &scene.system {
        System::Network(model) => network_response_page(&scene.name, model, &motion, collision),
        System::Strip(_) => {
            let mut page = plates_page(&motion, &scene.name)?;
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
            let mut page = plates_page(&motion, &scene.name)?;
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

/// The page of a strip's or a closed vertex's plates as FOLD (µm), face 0 (the substrate or
/// the anchored sector) fixed.
fn plates_page(fold: &serde_json::Value, name: &str) -> Result<PageScene> {
    let mut page = scene_of_fold(fold, name)?.scaled(1.0, "µm");
    page.fixed = vec![0];
    Ok(page)
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
pub fn strip_scene(name: &str, chain: &StripChain, states: &[(String, Vec<f64>)]) -> Result<PageScene> {
    let states: Vec<(String, &[f64])> = states.iter().map(|(t, a)| (t.clone(), a.as_slice())).collect();
    plates_page(&strip_states_fold(chain, &states, name), name)
}

/// A closed chain's page: the anchored sector (face 0) and the joints' plates (face 1 + j),
/// at each (title, every crease's angle).
pub fn closed_scene(name: &str, chain: &ClosedChain, states: &[(String, Vec<f64>)]) -> Result<PageScene> {
    let states: Vec<(String, &[f64])> = states.iter().map(|(t, a)| (t.clone(), a.as_slice())).collect();
    plates_page(&closed_states_fold(chain, &states, name), name)
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
    page_html(&strip_scene(name, chain, &states)?)
}

/// `modes.html` of a closed chain: the equilibrium, then each mode as [`MODE_PHASES`] phases
/// of ±`amplitude` rad in its largest coordinate, every phase's loop closed again.
pub fn closed_modes_page(
    name: &str,
    chain: &ClosedChain,
    modes: &crate::dynamics::closed::modes::ClosedModes,
    amplitude: f64,
) -> Result<String> {
    let mut states = vec![("folded equilibrium".to_string(), modes.equilibrium.clone())];
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
            states.push((label, state.angles));
        }
    }
    page_html(&closed_scene(name, chain, &states)?)
}
