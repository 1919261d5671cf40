//! A net as FOLD (`docs/model.md#nets-of-polyhedra`): the flat crease pattern with its fold
//! targets in `edges_foldAngle`, and what ties it to its solid in `nanofold:` fields, so
//! other tools and a closing simulation can find the seams.

use crate::pattern::net::NetPattern;
use crate::write::folding_output::crease_pattern_fold;
use serde_json::{json, Value};

/// The FOLD key of the seams: pairs of boundary edges that are one edge of the solid.
pub const SEAMS_KEY: &str = crate::read::NET_SEAMS_KEY;
/// The FOLD key of each vertex's solid vertex.
pub const SOLID_VERTEX_KEY: &str = "nanofold:solid_vertex";

/// `net` as a FOLD object; `description` is its `file_description`.
pub fn net_fold(net: &NetPattern, description: &str) -> Value {
    let pattern = &net.pattern;
    let targets: Vec<f64> = match &pattern.target_angles {
        Some(per_edge) => pattern.creases.iter().map(|&e| per_edge[e]).collect(),
        None => vec![0.0; pattern.creases.len()],
    };
    let mut root = crease_pattern_fold(pattern, Some(&targets), description);
    root[SEAMS_KEY] = json!(net.seams);
    root[SOLID_VERTEX_KEY] = json!(net.solid_vertex);
    root
}
