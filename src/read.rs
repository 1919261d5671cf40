//! The readers: files other tools write (FOLD) and nanofold's own inputs (native vertices,
//! scene files), parsed and validated into patterns and scene descriptions. They sit just
//! above `pattern`; loaders parse and validate and run no engine.

pub(crate) mod fold;
pub(crate) mod folded_form;
pub(crate) mod input;
pub mod measurement;
pub(crate) mod native;
pub(crate) mod scene;
pub mod scene_spec;
pub mod solid;
pub use input::MAX_PATTERN_BYTES;

pub use scene::{load_scene, parse_scene, scene_from_value, SceneDocument};

use crate::error::{NanofoldError, Result};
use crate::pattern::crease_pattern::CreasePattern;
use crate::pattern::{LoadOptions, VertexPattern};
use std::path::Path;

/// Is this a pattern file (a FOLD file or a native vertex, not a scene)?
pub fn is_pattern_file(path: &Path) -> bool {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    (name.ends_with(".fold") || name.ends_with(".json")) && !name.ends_with(".scene.json")
}

/// A pattern's name: its file name without `.fold` or `.json` (names output folders).
pub fn pattern_name(path: &Path) -> String {
    path.file_name()
        .and_then(|s| s.to_str())
        .map(|s| s.trim_end_matches(".json").trim_end_matches(".fold").to_string())
        .unwrap_or_else(|| "pattern".to_string())
}

/// Loads a `.fold` file or a native `.json` vertex (decided by content: a FOLD file has
/// keys of FOLD's `file_`, `frame_`, `vertices_`, `edges_` or `faces_` families).
///
/// ```
/// use nanofold::prelude::*;
/// let pattern = load_pattern("patterns/waterbomb.fold".as_ref(), &LoadOptions::default())?;
/// assert_eq!((pattern.chain, pattern.creases.len()), (Chain::Closed, 8));
/// // A file that is not there is an error naming it.
/// let missing = load_pattern("patterns/nothing.fold".as_ref(), &LoadOptions::default());
/// assert!(missing.unwrap_err().to_string().contains("nothing.fold"));
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn load_pattern(path: &Path, options: &LoadOptions) -> Result<VertexPattern> {
    let text = input::read_text(path, input::MAX_PATTERN_BYTES)?;
    parse_pattern(&text, &pattern_name(path), &path.display().to_string(), options)
}

/// Does this JSON object use FOLD's keys (rather than the native vertex's)?
pub(crate) fn is_fold_object(value: &serde_json::Value) -> bool {
    const FAMILIES: [&str; 5] = ["file_", "frame_", "vertices_", "edges_", "faces_"];
    value
        .as_object()
        .is_some_and(|object| object.keys().any(|key| FAMILIES.iter().any(|f| key.starts_with(f))))
}

/// Parses pattern text (FOLD or native); `origin` names it in error messages.
pub fn parse_pattern(text: &str, name: &str, origin: &str, options: &LoadOptions) -> Result<VertexPattern> {
    pattern_of_value(&input::parse_json(text, origin)?, name, origin, options)
}

/// A single vertex from a pattern file's JSON (FOLD or native), as [`parse_pattern`] reads it.
pub fn pattern_of_value(
    value: &serde_json::Value,
    name: &str,
    origin: &str,
    options: &LoadOptions,
) -> Result<VertexPattern> {
    if !value.is_object() {
        return Err(NanofoldError::invalid(
            origin,
            input::short_json(value),
            "a pattern file holds one JSON object (a FOLD file or a native vertex)",
        ));
    }
    if is_scene_object(value) {
        return Err(NanofoldError::invalid(
            origin,
            "a scene file",
            "this is a scene (it has materials, hinges or time): run it with `simulate` or `modes`",
        ));
    }
    let builder = if is_fold_object(value) {
        let unflattened = fold::unflatten_folded_form(value)?;
        let developed = match unflattened {
            Some(_) => None,
            None => developed_vertex(value, name, options.closure_tol),
        };
        fold::read_fold(developed.as_ref().or(unflattened.as_ref()).unwrap_or(value), name)?
    } else {
        native::read_native(value, name)?
    };
    let mut pattern = builder.build_with(options)?;
    pattern.adjustments.extend(frames_note(value));
    Ok(pattern)
}

/// A 3D folded form of one interior vertex (Origami Simulator's export of a vertex in a
/// square sheet, say), developed into its flat crease pattern with its state as a 2D FOLD
/// object, so the single-vertex engine (which unfolds states folded flat) reads it. None
/// when the value is not such a form, or its state does not close within `closure_tol`
/// (then the many-vertex reader takes it, with `check`'s and `--project`'s evidence).
fn developed_vertex(value: &serde_json::Value, name: &str, closure_tol: f64) -> Option<serde_json::Value> {
    let coords = value.get("vertices_coords")?.as_array()?;
    let is_3d = coords.iter().any(|p| {
        p.as_array()
            .and_then(|p| p.get(2))
            .and_then(|z| z.as_f64())
            .is_some_and(|z| z != 0.0)
    });
    if !is_3d || !creases_share_a_vertex(value) {
        return None;
    }
    let pattern = fold::read_crease_pattern(value, name).ok()?.build().ok()?;
    if pattern.stars.len() != 1 || pattern.folded_form.is_none() {
        return None;
    }
    let residual = pattern.given_closure_residuals().into_iter().fold(0.0, f64::max);
    if residual > closure_tol {
        return None;
    }
    let letters: Vec<&str> = pattern
        .kinds
        .iter()
        .map(|k| match k {
            crate::pattern::crease_pattern::EdgeKind::Boundary => "B",
            crate::pattern::crease_pattern::EdgeKind::Facet => "F",
            crate::pattern::crease_pattern::EdgeKind::Crease(a) => a.letter(),
        })
        .collect();
    let mut developed = serde_json::json!({
        "file_spec": 1.1,
        "vertices_coords": pattern.file_vertices(),
        "edges_vertices": pattern.edges,
        "edges_assignment": letters,
        "edges_foldAngle": pattern.fold_angles.iter().map(|a| a.to_degrees()).collect::<Vec<f64>>(),
        "faces_vertices": pattern.faces,
    });
    if let Some(unit) = &pattern.unit {
        developed["frame_unit"] = serde_json::json!(unit);
    }
    Some(developed)
}

/// Whether every crease (M, V, U) of a FOLD object ends at one vertex: the cheap test that
/// it can be a single vertex, before a 3D form is developed.
fn creases_share_a_vertex(value: &serde_json::Value) -> bool {
    let (Some(edges), Some(letters)) = (
        value.get("edges_vertices").and_then(|e| e.as_array()),
        value.get("edges_assignment").and_then(|a| a.as_array()),
    ) else {
        return false;
    };
    let mut common: Option<Vec<u64>> = None;
    for (edge, letter) in edges.iter().zip(letters) {
        if !matches!(letter.as_str(), Some("M" | "m" | "V" | "v" | "U" | "u")) {
            continue;
        }
        let ends: Vec<u64> = edge
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_u64())
            .collect();
        common = Some(match common {
            None => ends,
            Some(shared) => shared.into_iter().filter(|v| ends.contains(v)).collect(),
        });
        if common.as_ref().is_some_and(|c| c.is_empty()) {
            return false;
        }
    }
    common.is_some()
}

/// A note when a FOLD file carries more frames than its key frame, which is the one read.
pub fn frames_note(value: &serde_json::Value) -> Option<String> {
    let frames = value.get("file_frames")?.as_array()?.len();
    (frames > 0).then(|| {
        format!(
            "the file has {} frames: the key frame (its top-level state) was read, its {frames} file_frames were not",
            frames + 1
        )
    })
}

/// Loads a FOLD file as a crease pattern of any number of vertices
/// (`docs/model.md#crease-patterns`).
///
/// ```
/// use nanofold::read::load_crease_pattern;
/// let cp = load_crease_pattern("patterns/waterbomb.fold".as_ref())?;
/// assert_eq!((cp.stars.len(), cp.creases.len()), (1, 8));
/// # Ok::<(), nanofold::NanofoldError>(())
/// ```
pub fn load_crease_pattern(path: &Path) -> Result<CreasePattern> {
    let text = input::read_text(path, input::MAX_PATTERN_BYTES)?;
    parse_crease_pattern(&text, &pattern_name(path), &path.display().to_string())
}

/// Parses FOLD text as a crease pattern; `origin` names it in errors.
pub fn parse_crease_pattern(text: &str, name: &str, origin: &str) -> Result<CreasePattern> {
    crease_pattern_of_value(&input::parse_json(text, origin)?, name, origin)
}

/// A crease pattern from a FOLD file's JSON, as [`parse_crease_pattern`] reads it.
pub fn crease_pattern_of_value(value: &serde_json::Value, name: &str, origin: &str) -> Result<CreasePattern> {
    if is_scene_object(value) {
        return Err(NanofoldError::invalid(
            origin,
            "a scene file",
            "this is a scene (it has materials, hinges or time): run it with `simulate` or `modes`",
        ));
    }
    if !is_fold_object(value) {
        return Err(NanofoldError::invalid(
            origin,
            "not a FOLD object",
            "a crease pattern of many vertices is read from a FOLD file (vertices_coords, edges_vertices, edges_assignment)",
        ));
    }
    let unflattened = fold::unflatten_folded_form(value)?;
    let mut pattern = fold::read_crease_pattern(unflattened.as_ref().unwrap_or(value), name)?.build()?;
    // A flat-folded form (fold-convert's) states its fold: its ±180° are the state.
    if unflattened.is_none() {
        angles_as_targets(&mut pattern, value.get(NET_SEAMS_KEY).is_some())?;
    }
    if !pattern.ignored_vertices.is_empty() {
        let shown: Vec<String> = pattern.ignored_vertices.iter().map(|v| v.to_string()).collect();
        pattern.reading.push(format!(
            "vertices_coords[{}] on no edge (stray points): left out, the vertices after them numbered on without them",
            shown.join(", ")
        ));
    }
    Ok(pattern)
}

/// A vertex closes when its residual is at most this, rad (`check`'s default tolerance).
const STATE_CLOSURE: f64 = 1e-6;

/// Flat coordinates with fold angles that are targets, not a state, read as the flat crease
/// pattern with those targets: every crease at exactly ±180° (the convention of Origami
/// Simulator's and other solvers' exports), or angles that close no vertex of three or more
/// creases (a state closes at least where it is not bent). A state that closes somewhere
/// stays a state.
fn angles_as_targets(pattern: &mut CreasePattern, net: bool) -> Result<()> {
    if pattern.folded_form.is_some() || !pattern.reading.is_empty() {
        return Ok(());
    }
    let angles: Vec<f64> = pattern.creases.iter().map(|&e| pattern.fold_angles[e]).collect();
    if angles.iter().all(|a| *a == 0.0) || pattern.locked.iter().any(|&l| l) {
        return Ok(());
    }
    let full = angles.iter().all(|a| (a.abs().to_degrees() - 180.0).abs() <= 1e-9);
    let why = if net {
        format!("a net of a solid ({NET_SEAMS_KEY} given): its angles close the solid")
    } else if full {
        "every crease at ±180° (the targets' convention of Origami Simulator and other solvers)".to_string()
    } else {
        let residuals = pattern.given_closure_residuals();
        // A vertex of two creases (one crease line through it) closes whenever they are equal:
        // it says nothing of a state.
        let closing = residuals
            .iter()
            .zip(&pattern.stars)
            .filter(|(_, star)| star.creases.len() >= 3)
            .map(|(r, _)| *r)
            .fold(f64::INFINITY, f64::min);
        if !closing.is_finite() || closing <= STATE_CLOSURE {
            return Ok(());
        }
        format!("they close no vertex (the best closes to {closing:.2e} rad, above {STATE_CLOSURE:e})")
    };
    pattern.reading.push(format!(
        "flat coordinates with edges_foldAngle that are targets, not a state: {why}; read as the flat crease pattern with its assignment"
    ));
    pattern.target_angles = Some(std::mem::replace(
        &mut pattern.fold_angles,
        vec![0.0; pattern.edges.len()],
    ));
    Ok(())
}

/// The FOLD key a net's seams go under (`docs/model.md#nets-of-polyhedra`): a file with it
/// is read flat, its `edges_foldAngle` the targets that close the solid.
pub const NET_SEAMS_KEY: &str = "nanofold:seams";

/// Does this JSON object look like a scene file (keys only scenes have)?
pub(crate) fn is_scene_object(value: &serde_json::Value) -> bool {
    ["materials", "hinges", "time", "plates"]
        .iter()
        .any(|key| value.get(key).is_some())
}
