//! A scene description's physics in the engine's SI quantities: the drag law, the
//! actuation, the time span and the hinges' stiffness, each validated by the field it comes
//! from (`docs/model.md#scenes`).

use super::forcing::Actuation;
use super::model::Drag;
use crate::error::{NanofoldError, Result};
use crate::read::scene_spec::{
    count_within, finite, limits, material, within, ActuationSpec, EnvironmentSpec, HingeSpec, MaterialSpec,
    OutputSpec, TimeSpec, MICROMETRE,
};
use std::collections::BTreeMap;

/// The drag law of the environment (`docs/model.md#drag`), or none.
pub(crate) fn drag_law(env: &EnvironmentSpec) -> Result<Option<Drag>> {
    Ok(if env.drag {
        Some(Drag {
            drag_coefficient: within(
                "environment.drag_coefficient",
                env.drag_coefficient,
                limits::DRAG_COEFFICIENT,
                "",
            )?,
            air_density: within(
                "environment.air_density_kg_m3",
                env.air_density_kg_m3,
                limits::FLUID_DENSITY_KG_M3,
                "kg/m³",
            )?,
        })
    } else {
        None
    })
}

/// The etch rate of a ramp, m/s; a step has none.
pub(crate) fn actuation(spec: &ActuationSpec) -> Result<Actuation> {
    Ok(match spec {
        ActuationSpec::Step => Actuation::Step,
        ActuationSpec::Front { .. } => {
            return Err(NanofoldError::invalid(
                "actuation.kind",
                "\"front\"",
                "an etch front crossing the wafer is for pattern scenes of many panels; a strip or a closed chain takes \"ramp\"",
            ))
        }
        ActuationSpec::Ramp { etch_rate_um_per_min } => Actuation::Ramp {
            etch_rate: within(
                "actuation.etch_rate_um_per_min",
                *etch_rate_um_per_min,
                limits::ETCH_RATE_UM_PER_MIN,
                "µm/min",
            )? * MICROMETRE
                / 60.0,
        },
    })
}

/// A network scene's actuation and, for an etch front, the unit vector it moves along in
/// the pattern's plane.
pub(crate) fn network_actuation(spec: &ActuationSpec) -> Result<(Actuation, Option<[f64; 2]>)> {
    Ok(match spec {
        ActuationSpec::Front {
            etch_rate_um_per_min,
            direction_deg,
        } => {
            let rate = actuation(&ActuationSpec::Ramp {
                etch_rate_um_per_min: *etch_rate_um_per_min,
            })?;
            let angle = finite("actuation.direction_deg", *direction_deg)?.to_radians();
            (rate, Some([angle.cos(), angle.sin()]))
        }
        other => (actuation(other)?, None),
    })
}

/// The time span and outputs every scene shares.
pub(crate) fn time_and_outputs(time: &TimeSpec, outputs: &OutputSpec) -> Result<f64> {
    let t_end = within("time.t_end_s", time.t_end_s, limits::T_END_S, "s")?;
    count_within("outputs.samples", outputs.samples, limits::OUTPUT_SAMPLES)?;
    count_within("outputs.snapshots", outputs.snapshots, limits::SNAPSHOTS)?;
    Ok(t_end)
}

/// K = s Σ_layers w t³ E / (3 l (1 − ν²)) (`docs/model.md#hinge-stiffness`), with w the width
/// of the plate the hinge carries (a crease's length for a sector plate) and s the hinge's
/// `stiffness_scale` (1 unless given).
pub(crate) fn hinge_stiffness(
    materials: &BTreeMap<String, MaterialSpec>,
    i: usize,
    hinge: &HingeSpec,
    width: f64,
) -> Result<f64> {
    hinge_stiffness_named(materials, &format!("hinges[{i}]"), hinge, width)
}

/// [`hinge_stiffness`] for a hinge the scene names `prefix` (`hinges[3]`, `hinge_defaults`).
pub(crate) fn hinge_stiffness_named(
    materials: &BTreeMap<String, MaterialSpec>,
    prefix: &str,
    hinge: &HingeSpec,
    width: f64,
) -> Result<f64> {
    let i = prefix;
    let length = within(
        &format!("{i}.hinge_length_um"),
        hinge.hinge_length_um,
        limits::LENGTH_UM,
        "µm",
    )? * MICROMETRE;
    if hinge.layers.is_empty() {
        return Err(NanofoldError::invalid(
            format!("{i}.layers"),
            "[]",
            "a hinge needs its structural layer",
        ));
    }
    let mut stiffness = 0.0;
    for (k, layer) in hinge.layers.iter().enumerate() {
        let t = within(
            &format!("{i}.layers[{k}].thickness_um"),
            layer.thickness_um,
            limits::THICKNESS_UM,
            "µm",
        )? * MICROMETRE;
        let m = material(materials, &format!("{i}.layers[{k}].material"), &layer.material)?;
        let modulus = m.youngs_modulus_gpa * 1e9;
        stiffness += width * t.powi(3) * modulus / (3.0 * length * (1.0 - m.poisson_ratio * m.poisson_ratio));
    }
    let scale = match hinge.stiffness_scale {
        Some(scale) => within(&format!("{i}.stiffness_scale"), scale, limits::STIFFNESS_SCALE, "")?,
        None => 1.0,
    };
    Ok(scale * stiffness)
}
