//! The native single-vertex schema (documented in patterns/README.md): sector angles,
//! closed or open chain, one entry per crease with assignment, folded angle and lock.

use crate::error::{NanofoldError, Result};
use crate::pattern::{Assignment, Chain, CreaseSpec, RaySpec, VertexBuilder};
use serde::Deserialize;
use serde_json::Value;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NativeVertex {
    #[serde(default)]
    name: Option<String>,
    chain: String,
    angle_unit: String,
    sector_angles: Vec<f64>,
    creases: Vec<NativeCrease>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NativeCrease {
    assignment: String,
    fold_angle: f64,
    #[serde(default)]
    locked: bool,
}

/// Reads a native vertex. `chain` is "closed" (interior vertex: one sector after each
/// crease) or "open" (boundary vertex: the sheet's edge, then the creases, then the other
/// edge; one more sector than creases).
pub(crate) fn read_native(value: &Value, name: &str) -> Result<VertexBuilder> {
    for key in ["chain", "angle_unit", "sector_angles", "creases"] {
        if value.get(key).is_none() {
            return Err(NanofoldError::missing_with(
                key,
                "read as a native vertex, which needs chain, angle_unit, sector_angles and creases; a FOLD file has vertices_coords",
            ));
        }
    }
    let vertex: NativeVertex = crate::read::input::from_value(value)?;
    let to_rad = match vertex.angle_unit.as_str() {
        "deg" | "degrees" => std::f64::consts::PI / 180.0,
        "rad" | "radians" => 1.0,
        other => {
            return Err(NanofoldError::invalid(
                "angle_unit",
                format!("\"{other}\""),
                "expected \"deg\" or \"rad\"",
            ))
        }
    };
    let chain = match vertex.chain.as_str() {
        "closed" => Chain::Closed,
        "open" => Chain::Open,
        other => {
            return Err(NanofoldError::invalid(
                "chain",
                format!("\"{other}\""),
                "expected \"closed\" or \"open\"",
            ))
        }
    };
    let nc = vertex.creases.len();
    let expected = match chain {
        Chain::Closed => nc,
        Chain::Open => nc + 1,
    };
    if vertex.sector_angles.len() != expected {
        return Err(NanofoldError::invalid(
            "sector_angles",
            format!("{} values", vertex.sector_angles.len()),
            format!("a {} chain with {nc} creases needs {expected}", vertex.chain),
        ));
    }
    let mut rays = Vec::new();
    if chain == Chain::Open {
        rays.push(RaySpec::Boundary);
    }
    for (i, c) in vertex.creases.iter().enumerate() {
        rays.push(RaySpec::Crease(CreaseSpec {
            label: format!("creases[{i}]"),
            assignment: Assignment::from_letter(&c.assignment, &format!("creases[{i}].assignment"))?,
            fold_angle: c.fold_angle * to_rad,
            locked: c.locked,
            fold_edge: None,
            order: i,
            angle_field: format!("creases[{i}].fold_angle"),
        }));
    }
    if chain == Chain::Open {
        rays.push(RaySpec::Boundary);
    }
    Ok(VertexBuilder {
        name: vertex.name.unwrap_or_else(|| name.to_string()),
        chain,
        rays,
        sector_angles: vertex.sector_angles.iter().map(|a| a * to_rad).collect(),
        sector_fields: (0..expected).map(|k| format!("sector_angles[{k}]")).collect(),
        mesh: None,
    })
}
