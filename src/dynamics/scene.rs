//! Scenes (`docs/model.md#scenes`): what a dynamics run models and no more — the plates,
//! their materials, the hinges, the actuation, the air, the time span. A [`StripSpec`] or
//! [`ClosedSpec`] is the description as a scene file holds it (plain data, units in the
//! field names, buildable from code); its `build` validates it and assembles the [`Scene`]
//! the algorithms run, in SI units.
//!
//! Every dimensional field carries its unit in its name (`_um`, `_gpa`, `_g_cm3`, `_s`, …);
//! a scene file with an unknown field, such as a length without its unit, is refused.

use super::closed::{assemble, ClosedChain};
use super::forcing::{Actuation, Forcing, HingeDrive};
use super::model::{Drag, Joint, Model, Plate};
use super::strip::StripChain;
use crate::error::{NanofoldError, Result};
use crate::pattern::Pattern;
use nalgebra::{Point3, Vector3};
use serde::Deserialize;
use std::collections::BTreeMap;

pub(crate) const MICROMETRE: f64 = 1e-6;

/// One isotropic material.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// E, GPa.
    pub youngs_modulus_gpa: f64,
    /// ν, in (−1, 0.5).
    pub poisson_ratio: f64,
    /// ρ, g/cm³.
    pub density_g_cm3: f64,
}

/// One rigid plate of a strip, in chain order from the anchored hinge.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateSpec {
    /// Along the chain (perpendicular to the creases).
    pub length_um: f64,
    /// Along the creases.
    pub width_um: f64,
    /// Structural thickness t₁: the plate's mass and inertia come from this layer only.
    pub thickness_um: f64,
    /// A key of `materials`.
    pub material: String,
}

/// One layer of a hinge: structural (first) or stressed (actuating).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    /// A key of `materials`.
    pub material: String,
    /// t, µm.
    pub thickness_um: f64,
}

/// Hinge i of a strip joins plate i to plate i − 1 (hinge 0 anchors plate 0 to the substrate).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingeSpec {
    /// l, the hinge's length across the crease, µm.
    pub hinge_length_um: f64,
    /// Layers whose bending stiffnesses add (`docs/model.md#hinge-stiffness`): a passive
    /// hinge lists only the structural layer.
    pub layers: Vec<LayerSpec>,
    /// Whether a stressed layer drives it.
    pub actuated: bool,
    /// The folded angle the stressed layer drives to (valley positive); actuated hinges only.
    #[serde(default)]
    pub target_angle_deg: Option<f64>,
    /// ρ_c of the released hinge; needed by a ramp.
    #[serde(default)]
    pub radius_of_curvature_um: Option<f64>,
}

/// How the hinges are released.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ActuationSpec {
    /// τ = K θ_target from t = 0.
    Step,
    /// An etch front frees the hinges at `etch_rate_um_per_min`: θ(t) = a t / ρ_c up to the target.
    Ramp {
        /// a, µm/min (KOH: 1.5).
        etch_rate_um_per_min: f64,
    },
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
    /// Whether to model drag at all.
    pub drag: bool,
    /// C_D (default 1.28, a flat plate).
    #[serde(default = "default_drag_coefficient")]
    pub drag_coefficient: f64,
    /// ρ_air, kg/m³ (default 1.2).
    #[serde(default = "default_air_density")]
    pub air_density_kg_m3: f64,
}

/// Where the substrate of a strip is still there: the plane z = 0 for y ≤ `edge_y_um`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SubstrateSpec {
    /// The etch front's edge, µm (default 0: the anchored hinge).
    #[serde(default)]
    pub edge_y_um: f64,
}

/// The time span.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// End of the run, s.
    pub t_end_s: f64,
}

fn default_samples() -> usize {
    401
}
fn default_snapshots() -> usize {
    6
}

/// What to record: `samples` evenly spaced output times, `snapshots` views.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Evenly spaced output times (at least 2; default 401).
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Views in `snapshots.svg` (default 6).
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

/// A strip scene: plates in a row along +y from the substrate edge, creases parallel to x,
/// all in the plane z = 0 when flat.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StripSpec {
    /// Names the scene (and its output folder); "scene" when absent (the loader puts the
    /// file's name here).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// The plates, from the anchored hinge outwards.
    pub plates: Vec<PlateSpec>,
    /// One hinge per plate: hinge i carries plate i.
    pub hinges: Vec<HingeSpec>,
    /// Step or ramp.
    pub actuation: ActuationSpec,
    /// The air.
    pub environment: EnvironmentSpec,
    /// Where the substrate remains.
    #[serde(default)]
    pub substrate: SubstrateSpec,
    /// The time span.
    pub time: TimeSpec,
    /// What to record.
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// Every sector plate of a closed chain: one structural layer.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SectorPlateSpec {
    /// t₁, µm.
    pub thickness_um: f64,
    /// A key of `materials`.
    pub material: String,
}

/// The hinge of one crease of a closed chain (`crease`: the FOLD edge index); the other
/// fields as in a strip's hinge, the width being the crease's length.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreaseHingeSpec {
    /// FOLD edge index.
    pub crease: usize,
    /// l, µm.
    pub hinge_length_um: f64,
    /// Structural layer first, then the stressed one if actuated.
    pub layers: Vec<LayerSpec>,
    /// Whether a stressed layer drives it (exactly one crease of a closed step).
    pub actuated: bool,
    /// The driver's target, degrees.
    #[serde(default)]
    pub target_angle_deg: Option<f64>,
    /// ρ_c of the driver, µm (needed by a ramp).
    #[serde(default)]
    pub radius_of_curvature_um: Option<f64>,
}

impl CreaseHingeSpec {
    fn hinge(&self) -> HingeSpec {
        HingeSpec {
            hinge_length_um: self.hinge_length_um,
            layers: self.layers.clone(),
            actuated: self.actuated,
            target_angle_deg: self.target_angle_deg,
            radius_of_curvature_um: self.radius_of_curvature_um,
        }
    }
}

/// A crease held at an angle during this step.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LockSpec {
    /// FOLD edge index.
    pub crease: usize,
    /// The angle, degrees.
    pub angle_deg: f64,
}

/// Where f comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    /// A Chebyshev fit of an exact sweep.
    Poly,
    /// Newton loop closure at every evaluation.
    Exact,
}

fn default_constraint_samples() -> usize {
    401
}

/// How the closed chain's constraint f is made.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// Poly or exact.
    pub source: SourceKind,
    /// Polynomial degree (poly only).
    #[serde(default)]
    pub degree: Option<usize>,
    /// Exact sweep samples the fit (and the exact source's branch) use.
    #[serde(default = "default_constraint_samples")]
    pub samples: usize,
    /// Driving-angle range [a, b] in degrees; default from the start to the target.
    #[serde(default)]
    pub range_deg: Option<[f64; 2]>,
}

/// A closed-chain scene: a single-vertex pattern whose faces are the plates, the crease
/// where the loop is cut, the anchored face, the locks, the hinges and where f comes from.
/// `P` is the pattern: a FOLD path in a scene file, a [`Pattern`] once loaded.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedSpec<P> {
    /// Names the scene; "scene" when absent (the loader puts the file's name here).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// The pattern: a FOLD file (relative to the scene file) with `faces_vertices`.
    pub pattern: P,
    /// One pattern coordinate unit in µm.
    pub length_unit_um: f64,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// The sector plates.
    pub plates: SectorPlateSpec,
    /// One hinge per crease.
    pub hinges: Vec<CreaseHingeSpec>,
    /// The unactuated crease where the loop is cut for the numerics (FOLD edge index).
    pub cut_crease: usize,
    /// The face on the substrate (FOLD face index); default: the face after the cut crease
    /// (counter-clockwise), which is what scenes without this field meant.
    #[serde(default)]
    pub anchored_face: Option<usize>,
    /// Creases held during this step.
    #[serde(default)]
    pub locks: Vec<LockSpec>,
    /// The driving crease's angle at rest at t = 0, degrees.
    #[serde(default)]
    pub start_angle_deg: f64,
    /// Where f comes from.
    pub constraint: ConstraintSpec,
    /// Step or ramp.
    pub actuation: ActuationSpec,
    /// The air.
    pub environment: EnvironmentSpec,
    /// The time span.
    pub time: TimeSpec,
    /// What to record.
    #[serde(default)]
    pub outputs: OutputSpec,
}

impl<P> ClosedSpec<P> {
    /// The same scene with its pattern resolved (e.g. a path loaded into a [`Pattern`]).
    pub fn with_pattern<Q>(self, resolve: impl FnOnce(P) -> Result<Q>) -> Result<ClosedSpec<Q>> {
        Ok(ClosedSpec {
            name: self.name,
            description: self.description,
            pattern: resolve(self.pattern)?,
            length_unit_um: self.length_unit_um,
            materials: self.materials,
            plates: self.plates,
            hinges: self.hinges,
            cut_crease: self.cut_crease,
            anchored_face: self.anchored_face,
            locks: self.locks,
            start_angle_deg: self.start_angle_deg,
            constraint: self.constraint,
            actuation: self.actuation,
            environment: self.environment,
            time: self.time,
            outputs: self.outputs,
        })
    }
}

/// A scene description: a strip or a closed chain.
#[derive(Debug, Clone)]
pub enum SceneSpec {
    /// Plates in a row on parallel hinges.
    Strip(StripSpec),
    /// The sectors of a closed single vertex.
    Closed(Box<ClosedSpec<Pattern>>),
}

impl SceneSpec {
    /// Validates and assembles the scene. A closed chain is assembled by
    /// [`assemble::closed_chain`]: sweep, fit, chain.
    pub fn build(&self) -> Result<Scene> {
        match self {
            SceneSpec::Strip(spec) => spec.build(),
            SceneSpec::Closed(spec) => spec.build(),
        }
    }

    /// The scene's name, if it has one.
    pub fn name(&self) -> Option<&str> {
        match self {
            SceneSpec::Strip(spec) => spec.name.as_deref(),
            SceneSpec::Closed(spec) => spec.name.as_deref(),
        }
    }
}

/// What a scene simulates.
#[derive(Debug, Clone)]
pub enum System {
    /// An open chain on parallel hinges.
    Strip(StripChain),
    /// A closed single vertex.
    Closed(Box<ClosedChain>),
}

/// A validated scene: the system, its time span and what to record.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Names outputs.
    pub name: String,
    /// The mechanical system.
    pub system: System,
    /// End of the run, s.
    pub t_end: f64,
    /// Output samples and snapshots.
    pub outputs: OutputSpec,
}

impl Scene {
    /// The strip, if this is one.
    pub fn strip(&self) -> Option<&StripChain> {
        match &self.system {
            System::Strip(chain) => Some(chain),
            System::Closed(_) => None,
        }
    }

    /// The closed chain, if this is one.
    pub fn closed(&self) -> Option<&ClosedChain> {
        match &self.system {
            System::Strip(_) => None,
            System::Closed(chain) => Some(chain),
        }
    }

    /// The forcing of every hinge (every crease of a closed chain).
    pub fn forcing(&self) -> &Forcing {
        match &self.system {
            System::Strip(chain) => &chain.forcing,
            System::Closed(chain) => &chain.forcing,
        }
    }

    /// Hinge stiffness per output angle (per hinge of a strip, per crease of a closed
    /// chain), N·m/rad.
    pub fn stiffness(&self) -> Vec<f64> {
        match &self.system {
            System::Strip(chain) => chain.model.joints().iter().map(|j| j.stiffness).collect(),
            System::Closed(chain) => chain.crease_stiffness.clone(),
        }
    }
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

/// The drag law of the environment (`docs/model.md#drag`), or none.
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

/// The etch rate of a ramp, m/s; a step has none.
pub(crate) fn actuation(spec: &ActuationSpec) -> Result<Actuation> {
    Ok(match spec {
        ActuationSpec::Step => Actuation::Step,
        ActuationSpec::Ramp { etch_rate_um_per_min } => Actuation::Ramp {
            etch_rate: positive("actuation.etch_rate_um_per_min", *etch_rate_um_per_min)? * MICROMETRE / 60.0,
        },
    })
}

/// The time span and outputs every scene shares.
pub(crate) fn time_and_outputs(time: &TimeSpec, outputs: &OutputSpec) -> Result<f64> {
    let t_end = positive("time.t_end_s", time.t_end_s)?;
    if outputs.samples < 2 {
        return Err(NanofoldError::invalid(
            "outputs.samples",
            outputs.samples,
            "need at least 2",
        ));
    }
    Ok(t_end)
}

impl StripSpec {
    /// Validates the strip and builds its chain in SI units.
    pub fn build(&self) -> Result<Scene> {
        validate_materials(&self.materials)?;
        let n = self.plates.len();
        if n == 0 {
            return Err(NanofoldError::invalid(
                "plates",
                "[]",
                "a chain needs at least one plate",
            ));
        }
        if self.hinges.len() != n {
            return Err(NanofoldError::invalid(
                "hinges",
                format!("{} entries", self.hinges.len()),
                format!("need one hinge per plate ({n}): hinge i carries plate i"),
            ));
        }
        let edge_y = finite("substrate.edge_y_um", self.substrate.edge_y_um)? * MICROMETRE;
        let mut joints = Vec::with_capacity(n);
        let mut plates = Vec::with_capacity(n);
        let mut y = edge_y;
        for (i, spec) in self.plates.iter().enumerate() {
            let length = positive(&format!("plates[{i}].length_um"), spec.length_um)? * MICROMETRE;
            let width = positive(&format!("plates[{i}].width_um"), spec.width_um)? * MICROMETRE;
            let thickness = positive(&format!("plates[{i}].thickness_um"), spec.thickness_um)? * MICROMETRE;
            let density =
                material(&self.materials, &format!("plates[{i}].material"), &spec.material)?.density_g_cm3 * 1e3;
            // The flat plate spans x ∈ [−w/2, w/2], y ∈ [y, y + L]: a box whose moment about the
            // crease-parallel x axis involves its length, not its width (`docs/model.md#plates`).
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
            let hinge = &self.hinges[i];
            let stiffness = hinge_stiffness(&self.materials, i, hinge, width)?;
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
        let actuation = actuation(&self.actuation)?;
        let mut drives = vec![HingeDrive::PASSIVE; n];
        for (i, hinge) in self.hinges.iter().enumerate() {
            match (hinge.actuated, hinge.target_angle_deg) {
                (true, Some(deg)) => {
                    let field = format!("hinges[{i}].target_angle_deg");
                    finite(&field, deg)?;
                    if deg.abs() > 180.0 {
                        return Err(NanofoldError::invalid(field, deg, "must lie in [−180, 180]"));
                    }
                    drives[i].target = deg.to_radians();
                    drives[i].actuated = true;
                }
                (true, None) => return Err(NanofoldError::missing(format!("hinges[{i}].target_angle_deg"))),
                (false, Some(deg)) => {
                    return Err(NanofoldError::invalid(
                        format!("hinges[{i}].target_angle_deg"),
                        deg,
                        "a passive hinge (actuated: false) has no target",
                    ))
                }
                (false, None) => {}
            }
            if hinge.actuated {
                if let Actuation::Ramp { .. } = actuation {
                    let field = format!("hinges[{i}].radius_of_curvature_um");
                    let value = hinge
                        .radius_of_curvature_um
                        .ok_or_else(|| NanofoldError::missing(field.clone()))?;
                    drives[i].radius_of_curvature = positive(&field, value)? * MICROMETRE;
                }
            }
        }
        if !drives.iter().any(|d| d.actuated) {
            return Err(NanofoldError::invalid(
                "hinges[*].actuated",
                "all false",
                "nothing drives the chain",
            ));
        }
        let drag = drag_law(&self.environment)?;
        let t_end = time_and_outputs(&self.time, &self.outputs)?;
        Ok(Scene {
            name: self.name.clone().unwrap_or_else(|| "scene".to_string()),
            system: System::Strip(StripChain {
                model: Model::chain(joints, plates, drag)?,
                forcing: Forcing {
                    actuation,
                    hinges: drives,
                },
                substrate_edge_y: edge_y,
            }),
            t_end,
            outputs: self.outputs.clone(),
        })
    }
}

impl ClosedSpec<Pattern> {
    /// Validates the scene and assembles its chain: the sweep, the fit and the tree of
    /// sector plates ([`assemble::closed_chain`]).
    pub fn build(&self) -> Result<Scene> {
        let chain = assemble::closed_chain(self)?;
        let t_end = time_and_outputs(&self.time, &self.outputs)?;
        Ok(Scene {
            name: self.name.clone().unwrap_or_else(|| "scene".to_string()),
            system: System::Closed(Box::new(chain)),
            t_end,
            outputs: self.outputs.clone(),
        })
    }
}

/// K = Σ_layers w t³ E / (3 l (1 − ν²)) (`docs/model.md#hinge-stiffness`), with w the width
/// of the plate the hinge carries (a crease's length for a sector plate).
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

/// A closed chain's hinge spec as a strip hinge (same fields), for the shared checks.
pub(crate) fn crease_hinge(spec: &CreaseHingeSpec) -> HingeSpec {
    spec.hinge()
}
