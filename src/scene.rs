//! Scene files (`*.scene.json`): what a dynamics run models and no more — the chain of
//! plates, their materials, the hinges, the actuation, the air, the time span (SPEC §7, §8).
//!
//! Every dimensional field carries its unit in its name (`_um`, `_gpa`, `_g_cm3`, `_s`, …);
//! an unknown field, such as a length without its unit, is refused. The scene builds an
//! immutable [`dynamics::Model`](crate::dynamics::Model) in SI units.

use crate::dynamics::{Drag, Joint, Model, Plate};
use crate::error::{NanofoldError, Result};
use nalgebra::{DVector, Point3, Vector3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

pub mod closed;

pub(crate) const MICROMETRE: f64 = 1e-6;

/// One isotropic material.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub youngs_modulus_gpa: f64,
    pub poisson_ratio: f64,
    pub density_g_cm3: f64,
}

/// One rigid plate of the strip, in chain order from the anchored hinge.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateSpec {
    /// Along the chain (perpendicular to the creases).
    pub length_um: f64,
    /// Along the creases.
    pub width_um: f64,
    /// Structural thickness t₁: the plate's mass and inertia come from this layer only.
    pub thickness_um: f64,
    pub material: String,
}

/// One layer of a hinge: structural (first) or stressed (actuating).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    pub material: String,
    pub thickness_um: f64,
}

/// Hinge i joins plate i to plate i − 1 (hinge 0 anchors plate 0 to the substrate).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingeSpec {
    pub hinge_length_um: f64,
    /// Layers whose bending stiffnesses add (T5.7): a passive hinge lists only the structural layer.
    pub layers: Vec<LayerSpec>,
    pub actuated: bool,
    /// The folded angle the stressed layer drives to (valley positive); actuated hinges only.
    #[serde(default)]
    pub target_angle_deg: Option<f64>,
    /// ρ_c of the released hinge (T5.10); needed by a ramp.
    #[serde(default)]
    pub radius_of_curvature_um: Option<f64>,
}

/// How the hinges are released.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ActuationSpec {
    /// τ = K θ_target from t = 0 (T5.9).
    Step,
    /// An etch front frees the hinge at `etch_rate_um_per_min`: θ(t) = a t / ρ_c up to the target (T5.10–5.12).
    Ramp { etch_rate_um_per_min: f64 },
}

fn default_drag_coefficient() -> f64 {
    1.28
}
fn default_air_density() -> f64 {
    1.2
}

/// The surrounding air.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    pub drag: bool,
    #[serde(default = "default_drag_coefficient")]
    pub drag_coefficient: f64,
    #[serde(default = "default_air_density")]
    pub air_density_kg_m3: f64,
}

/// Where the substrate is still there: the plane z = 0 for y ≤ `edge_y_um` (SPEC §7).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SubstrateSpec {
    #[serde(default)]
    pub edge_y_um: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    pub t_end_s: f64,
}

fn default_samples() -> usize {
    401
}
fn default_snapshots() -> usize {
    6
}

/// What to record: `samples` evenly spaced output times, `snapshots` side views.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default = "default_samples")]
    pub samples: usize,
    #[serde(default = "default_snapshots")]
    pub snapshots: usize,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            samples: default_samples(),
            snapshots: default_snapshots(),
        }
    }
}

/// A scene file as written. The chain is a strip: plates in a row along +y from the
/// substrate edge, creases parallel to x, all in the plane z = 0 when flat.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    pub materials: BTreeMap<String, MaterialSpec>,
    pub plates: Vec<PlateSpec>,
    pub hinges: Vec<HingeSpec>,
    pub actuation: ActuationSpec,
    pub environment: EnvironmentSpec,
    #[serde(default)]
    pub substrate: SubstrateSpec,
    pub time: TimeSpec,
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// The actuation in SI: per-hinge targets (rad, 0 for passive hinges).
#[derive(Debug, Clone, PartialEq)]
pub enum Actuation {
    Step,
    /// Etch rate a in m/s and each hinge's radius of curvature ρ_c in m.
    Ramp {
        etch_rate: f64,
        radius_of_curvature: Vec<f64>,
    },
}

/// A validated scene: the model plus what drives it.
#[derive(Debug, Clone)]
pub struct Scene {
    pub name: String,
    pub model: Model,
    pub actuation: Actuation,
    pub actuated: Vec<bool>,
    /// θ_target per hinge, rad (0 for passive hinges).
    pub target_angles: DVector<f64>,
    /// The substrate is present for y ≤ this, m.
    pub substrate_edge_y: f64,
    pub t_end: f64,
    pub outputs: OutputSpec,
}

pub(crate) fn positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(NanofoldError::invalid(field, value, "must be a finite number > 0"))
    }
}

pub(crate) fn finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(NanofoldError::invalid(field, value, "must be finite"))
    }
}

pub(crate) fn material<'a>(
    materials: &'a BTreeMap<String, MaterialSpec>,
    field: &str,
    name: &str,
) -> Result<&'a MaterialSpec> {
    materials.get(name).ok_or_else(|| {
        let known: Vec<&str> = materials.keys().map(String::as_str).collect();
        NanofoldError::invalid(
            field,
            format!("\"{name}\""),
            format!("not in `materials` ({})", known.join(", ")),
        )
    })
}

/// Every material's moduli and density in range.
pub(crate) fn validate_materials(materials: &BTreeMap<String, MaterialSpec>) -> Result<()> {
    for (name, m) in materials {
        positive(&format!("materials.{name}.youngs_modulus_gpa"), m.youngs_modulus_gpa)?;
        positive(&format!("materials.{name}.density_g_cm3"), m.density_g_cm3)?;
        let field = format!("materials.{name}.poisson_ratio");
        finite(&field, m.poisson_ratio)?;
        if !(-1.0 < m.poisson_ratio && m.poisson_ratio < 0.5) {
            return Err(NanofoldError::invalid(field, m.poisson_ratio, "must lie in (−1, 0.5)"));
        }
    }
    Ok(())
}

/// The drag law of the environment (T5.8), or none.
pub(crate) fn drag_law(env: &EnvironmentSpec) -> Result<Option<Drag>> {
    Ok(if env.drag {
        Some(Drag {
            drag_coefficient: positive("environment.drag_coefficient", env.drag_coefficient)?,
            air_density: positive("environment.air_density_kg_m3", env.air_density_kg_m3)?,
        })
    } else {
        None
    })
}

impl Scene {
    pub fn load(path: &Path) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|error| NanofoldError::Io {
            path: path.display().to_string(),
            error,
        })?;
        let fallback = path
            .file_name()
            .and_then(|n| n.to_str())
            .map(|n| n.trim_end_matches(".json").trim_end_matches(".scene").to_string())
            .unwrap_or_else(|| "scene".into());
        Scene::from_json(&text, &path.display().to_string(), &fallback)
    }

    /// Parses and validates a scene; `source` names the input in errors.
    pub fn from_json(text: &str, source: &str, fallback_name: &str) -> Result<Scene> {
        let file: SceneFile = serde_json::from_str(text).map_err(|e| NanofoldError::Json {
            path: source.to_string(),
            message: e.to_string(),
        })?;
        Scene::from_file(file, fallback_name)
    }

    pub fn from_file(file: SceneFile, fallback_name: &str) -> Result<Scene> {
        validate_materials(&file.materials)?;
        let n = file.plates.len();
        if n == 0 {
            return Err(NanofoldError::invalid(
                "plates",
                "[]",
                "a chain needs at least one plate",
            ));
        }
        if file.hinges.len() != n {
            return Err(NanofoldError::invalid(
                "hinges",
                format!("{} entries", file.hinges.len()),
                format!("need one hinge per plate ({n}): hinge i carries plate i"),
            ));
        }
        let edge_y = finite("substrate.edge_y_um", file.substrate.edge_y_um)? * MICROMETRE;
        let mut joints = Vec::with_capacity(n);
        let mut plates = Vec::with_capacity(n);
        let mut y = edge_y;
        for (i, spec) in file.plates.iter().enumerate() {
            let length = positive(&format!("plates[{i}].length_um"), spec.length_um)? * MICROMETRE;
            let width = positive(&format!("plates[{i}].width_um"), spec.width_um)? * MICROMETRE;
            let thickness = positive(&format!("plates[{i}].thickness_um"), spec.thickness_um)? * MICROMETRE;
            let density =
                material(&file.materials, &format!("plates[{i}].material"), &spec.material)?.density_g_cm3 * 1e3;
            // The flat plate spans x ∈ [−w/2, w/2], y ∈ [y, y + L]: a box whose moment about the
            // crease-parallel x axis involves its length, not its width (SPEC §7).
            let half = 0.5 * width;
            let plate = Plate::lamina(
                &[[-half, y], [half, y], [half, y + length], [-half, y + length]],
                thickness,
                density,
            );
            let mass = plate.mass;
            let usable = |x: f64| x.is_finite() && x > 0.0;
            if !(usable(mass) && (0..3).all(|k| usable(plate.inertia[(k, k)]))) {
                return Err(NanofoldError::invalid(
                    format!("plates[{i}]"),
                    format!("mass {mass:e} kg"),
                    "the plate's mass or inertia overflows or vanishes in double precision: check the units of its length_um, width_um, thickness_um and its material's density_g_cm3",
                ));
            }
            let hinge = &file.hinges[i];
            let stiffness = hinge_stiffness(&file.materials, i, hinge, width)?;
            if !usable(stiffness) {
                return Err(NanofoldError::invalid(
                    format!("hinges[{i}]"),
                    format!("stiffness {stiffness:e} N·m/rad"),
                    "the bending stiffness overflows or vanishes in double precision: check the units of hinge_length_um, the layers' thickness_um and youngs_modulus_gpa",
                ));
            }
            joints.push(Joint {
                axis: Vector3::x_axis(),
                point: Point3::new(0.0, y, 0.0),
                stiffness,
            });
            plates.push(plate);
            y += length;
        }
        let mut target_angles = DVector::zeros(n);
        let mut actuated = vec![false; n];
        for (i, hinge) in file.hinges.iter().enumerate() {
            actuated[i] = hinge.actuated;
            match (hinge.actuated, hinge.target_angle_deg) {
                (true, Some(deg)) => {
                    let field = format!("hinges[{i}].target_angle_deg");
                    finite(&field, deg)?;
                    if deg.abs() > 180.0 {
                        return Err(NanofoldError::invalid(field, deg, "must lie in [−180, 180]"));
                    }
                    target_angles[i] = deg.to_radians();
                }
                (true, None) => {
                    return Err(NanofoldError::MissingField {
                        field: format!("hinges[{i}].target_angle_deg"),
                    })
                }
                (false, Some(deg)) => {
                    return Err(NanofoldError::invalid(
                        format!("hinges[{i}].target_angle_deg"),
                        deg,
                        "a passive hinge (actuated: false) has no target",
                    ))
                }
                (false, None) => {}
            }
        }
        if !actuated.iter().any(|&a| a) {
            return Err(NanofoldError::invalid(
                "hinges[*].actuated",
                "all false",
                "nothing drives the chain",
            ));
        }
        let actuation = match file.actuation {
            ActuationSpec::Step => Actuation::Step,
            ActuationSpec::Ramp { etch_rate_um_per_min } => {
                let rate = positive("actuation.etch_rate_um_per_min", etch_rate_um_per_min)? * MICROMETRE / 60.0;
                let mut radius_of_curvature = vec![f64::INFINITY; n];
                for (i, hinge) in file.hinges.iter().enumerate().filter(|(_, h)| h.actuated) {
                    let field = format!("hinges[{i}].radius_of_curvature_um");
                    let value = hinge
                        .radius_of_curvature_um
                        .ok_or_else(|| NanofoldError::MissingField { field: field.clone() })?;
                    radius_of_curvature[i] = positive(&field, value)? * MICROMETRE;
                }
                Actuation::Ramp {
                    etch_rate: rate,
                    radius_of_curvature,
                }
            }
        };
        let drag = drag_law(&file.environment)?;
        let t_end = positive("time.t_end_s", file.time.t_end_s)?;
        if file.outputs.samples < 2 {
            return Err(NanofoldError::invalid(
                "outputs.samples",
                file.outputs.samples,
                "need at least 2",
            ));
        }
        Ok(Scene {
            name: file.name.clone().unwrap_or_else(|| fallback_name.to_string()),
            model: Model { joints, plates, drag },
            actuation,
            actuated,
            target_angles,
            substrate_edge_y: edge_y,
            t_end,
            outputs: file.outputs.clone(),
        })
    }

    /// The angle each hinge's stressed layer is driving to at time t, rad (T5.9–5.12).
    pub fn drive_angles(&self, t: f64, out: &mut [f64]) {
        for (i, angle) in out.iter_mut().enumerate() {
            let target = self.target_angles[i];
            *angle = match &self.actuation {
                Actuation::Step => target,
                Actuation::Ramp {
                    etch_rate,
                    radius_of_curvature,
                } => {
                    let released = etch_rate * t.max(0.0) / radius_of_curvature[i];
                    target.signum() * released.min(target.abs())
                }
            };
        }
    }

    /// dθ_drive/dt, rad/s: a/ρ_c (with the target's sign) while a ramp releases a hinge, else 0.
    pub fn drive_rates(&self, t: f64, out: &mut [f64]) {
        for (i, rate) in out.iter_mut().enumerate() {
            let target = self.target_angles[i];
            *rate = match &self.actuation {
                Actuation::Ramp {
                    etch_rate,
                    radius_of_curvature,
                } if target != 0.0 && etch_rate * t.max(0.0) / radius_of_curvature[i] < target.abs() => {
                    target.signum() * etch_rate / radius_of_curvature[i]
                }
                _ => 0.0,
            };
        }
    }

    /// Input torques τ = K θ_drive(t), N·m.
    pub fn torques(&self, t: f64, out: &mut [f64]) {
        self.drive_angles(t, out);
        for (tau, joint) in out.iter_mut().zip(&self.model.joints) {
            *tau *= joint.stiffness;
        }
    }

    /// "step" or "ramp".
    pub fn actuation_kind(&self) -> &'static str {
        match self.actuation {
            Actuation::Step => "step",
            Actuation::Ramp { .. } => "ramp",
        }
    }

    /// Times where τ(t) has a kink (a ramp reaching its target), sorted, s.
    pub fn forcing_breakpoints(&self) -> Vec<f64> {
        let mut times: Vec<f64> = match &self.actuation {
            Actuation::Step => Vec::new(),
            Actuation::Ramp {
                etch_rate,
                radius_of_curvature,
            } => (0..self.model.dof())
                .filter(|&i| self.actuated[i] && self.target_angles[i] != 0.0)
                .map(|i| radius_of_curvature[i] * self.target_angles[i].abs() / etch_rate)
                .collect(),
        };
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// The slowest forcing time scale, s: 0 for a step, the longest ramp time t_p = ρ_c θ / a.
    pub fn forcing_time(&self) -> f64 {
        match &self.actuation {
            Actuation::Step => 0.0,
            Actuation::Ramp {
                etch_rate,
                radius_of_curvature,
            } => (0..self.model.dof())
                .filter(|&i| self.actuated[i])
                .map(|i| radius_of_curvature[i] * self.target_angles[i].abs() / etch_rate)
                .fold(0.0, f64::max),
        }
    }
}

/// K = Σ_layers w t³ E / (3 l (1 − ν²)) (T5.7), with w the width of the plate the hinge carries.
pub(crate) fn hinge_stiffness(
    materials: &BTreeMap<String, MaterialSpec>,
    i: usize,
    hinge: &HingeSpec,
    width: f64,
) -> Result<f64> {
    let length = positive(&format!("hinges[{i}].hinge_length_um"), hinge.hinge_length_um)? * MICROMETRE;
    if hinge.layers.is_empty() {
        return Err(NanofoldError::invalid(
            format!("hinges[{i}].layers"),
            "[]",
            "a hinge needs its structural layer",
        ));
    }
    let mut stiffness = 0.0;
    for (k, layer) in hinge.layers.iter().enumerate() {
        let t = positive(&format!("hinges[{i}].layers[{k}].thickness_um"), layer.thickness_um)? * MICROMETRE;
        let m = material(materials, &format!("hinges[{i}].layers[{k}].material"), &layer.material)?;
        let modulus = m.youngs_modulus_gpa * 1e9;
        stiffness += width * t.powi(3) * modulus / (3.0 * length * (1.0 - m.poisson_ratio * m.poisson_ratio));
    }
    Ok(stiffness)
}
