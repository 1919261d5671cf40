//! Scene descriptions (`docs/model.md#scenes`): what a dynamics run models and no more —
//! the plates, their materials, the hinges, the actuation, the air, the time span — as a
//! scene file holds it: plain data, buildable from code, validated when built into a
//! `dynamics::scene::Scene`.
//!
//! Every dimensional field carries its unit in its name (`_um`, `_gpa`, `_g_cm3`, `_s`, …);
//! a scene file with an unknown field, such as a length without its unit, is refused.

use crate::error::{NanofoldError, Result};
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
    /// The plate's moment of inertia about its crease-parallel axis through its centre of
    /// mass, kg·m², in place of the box's m (L² + t²)/12: a stated reading of another model
    /// (`docs/thesis.md`) or a measured value. The only moment a strip's planar motion uses.
    #[serde(default)]
    pub moment_about_crease_kg_m2: Option<f64>,
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
    /// Multiplies the T5.7 stiffness (default 1): a calibration against measurement, or a
    /// stated reading of another model (`docs/thesis.md`).
    #[serde(default)]
    pub stiffness_scale: Option<f64>,
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
    /// A straight etch front crossing the wafer in direction `direction_deg` (in the
    /// pattern's plane, from its x axis, counter-clockwise) at `etch_rate_um_per_min`: each
    /// actuated hinge's ramp starts when the front has passed the whole of its crease line,
    /// the first hinge so freed at t = 0 (pattern scenes only).
    Front {
        /// a, µm/min.
        etch_rate_um_per_min: f64,
        /// The direction the front moves, degrees.
        direction_deg: f64,
    },
}

fn default_drag_coefficient() -> f64 {
    1.28
}

/// The value a scene file's number takes when its key is left out, for the numbers that
/// have one: `key` in an object listed under (or named) `parent` — C_D and ρ_air of the
/// environment, a hinge's stiffness scale. (What a fit needs to free a number the file does
/// not write.)
pub fn default_number(parent: &str, key: &str) -> Option<f64> {
    match (parent, key) {
        ("environment", "drag_coefficient") => Some(default_drag_coefficient()),
        ("environment", "air_density_kg_m3") => Some(default_air_density()),
        ("hinges" | "hinge_defaults", "stiffness_scale") => Some(1.0),
        _ => None,
    }
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
    /// Which equations of motion run the strip (default: the chain's own).
    #[serde(default)]
    pub equations: StripEquations,
}

/// From this many plates `equations` "auto" runs a strip as a panel network (where the two
/// cost the same on a bridge-like strip; README, "Devices of many panels").
pub const NETWORK_FROM_PLATES: usize = 25;

/// The equations of motion a strip runs on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StripEquations {
    /// The faster for its length: the chain's below [`NETWORK_FROM_PLATES`] plates, the
    /// network's from there.
    #[default]
    Auto,
    /// The chain's joint-space equations (a dense mass matrix; `docs/model.md#strip`).
    Chain,
    /// The panel network's (the substrate and the plates as panels; recursive, sparse;
    /// `docs/model.md#panel-networks`).
    Network,
}

impl MaterialSpec {
    /// A material from E (GPa), ν and ρ (g/cm³).
    pub fn new(youngs_modulus_gpa: f64, poisson_ratio: f64, density_g_cm3: f64) -> Self {
        MaterialSpec {
            youngs_modulus_gpa,
            poisson_ratio,
            density_g_cm3,
        }
    }
}

impl LayerSpec {
    /// A layer of `thickness_um` µm of `material`.
    pub fn new(material: &str, thickness_um: f64) -> Self {
        LayerSpec {
            material: material.to_string(),
            thickness_um,
        }
    }
}

impl HingeSpec {
    /// A passive hinge `hinge_length_um` long (its structural layer only, usually).
    pub fn passive(hinge_length_um: f64, layers: Vec<LayerSpec>) -> Self {
        HingeSpec {
            hinge_length_um,
            layers,
            actuated: false,
            target_angle_deg: None,
            radius_of_curvature_um: None,
            stiffness_scale: None,
        }
    }

    /// An actuated hinge driving to `target_angle_deg`; `radius_of_curvature_um` is needed by
    /// a ramp.
    pub fn actuated(
        hinge_length_um: f64,
        layers: Vec<LayerSpec>,
        target_angle_deg: f64,
        radius_of_curvature_um: Option<f64>,
    ) -> Self {
        HingeSpec {
            hinge_length_um,
            layers,
            actuated: true,
            target_angle_deg: Some(target_angle_deg),
            radius_of_curvature_um,
            stiffness_scale: None,
        }
    }
}

impl StripSpec {
    /// An empty strip named `name`: add materials, plates and hinges; a step by default, no
    /// drag, 1 ms.
    ///
    /// ```
    /// use nanofold::read::scene_spec::{HingeSpec, LayerSpec, MaterialSpec, StripSpec};
    /// use nanofold::prelude::*;
    /// // One 100 µm SiN plate on a SiN/Cr bilayer hinge, released by a step towards 100°.
    /// let scene = StripSpec::new("flap")
    ///     .material("SiN", MaterialSpec::new(300.0, 0.28, 3.27))
    ///     .material("Cr", MaterialSpec::new(140.0, 0.21, 7.19))
    ///     .plate(100.0, 100.0, 0.2, "SiN")
    ///     .hinge(HingeSpec::actuated(
    ///         32.0,
    ///         vec![LayerSpec::new("SiN", 0.2), LayerSpec::new("Cr", 0.1)],
    ///         100.0,
    ///         None,
    ///     ))
    ///     .build()?;
    /// let run = simulate(&scene, &SimulationSettings::default())?;
    /// // No drag: θ = θ_target (1 − cos ωt) overshoots to 200°, past the substrate at 180°.
    /// assert!(run.simulation.response.collision.is_some());
    /// # Ok::<(), NanofoldError>(())
    /// ```
    pub fn new(name: &str) -> Self {
        StripSpec {
            name: Some(name.to_string()),
            description: None,
            materials: BTreeMap::new(),
            plates: Vec::new(),
            hinges: Vec::new(),
            actuation: ActuationSpec::Step,
            environment: EnvironmentSpec {
                drag: false,
                drag_coefficient: default_drag_coefficient(),
                air_density_kg_m3: default_air_density(),
            },
            substrate: SubstrateSpec::default(),
            time: TimeSpec { t_end_s: 1e-3 },
            outputs: OutputSpec::default(),
            equations: StripEquations::Auto,
        }
    }

    /// Adds (or replaces) a material.
    pub fn material(mut self, name: &str, material: MaterialSpec) -> Self {
        self.materials.insert(name.to_string(), material);
        self
    }

    /// Adds the next plate outwards: length along the chain, width along the creases and
    /// structural thickness, µm.
    pub fn plate(mut self, length_um: f64, width_um: f64, thickness_um: f64, material: &str) -> Self {
        self.plates.push(PlateSpec {
            length_um,
            width_um,
            thickness_um,
            material: material.to_string(),
            moment_about_crease_kg_m2: None,
        });
        self
    }

    /// Adds the next hinge (hinge i carries plate i).
    pub fn hinge(mut self, hinge: HingeSpec) -> Self {
        self.hinges.push(hinge);
        self
    }

    /// Releases the hinges by an etch front at `etch_rate_um_per_min` instead of a step.
    pub fn ramp(mut self, etch_rate_um_per_min: f64) -> Self {
        self.actuation = ActuationSpec::Ramp { etch_rate_um_per_min };
        self
    }

    /// Models quadratic drag with the default coefficients.
    pub fn with_drag(mut self) -> Self {
        self.environment.drag = true;
        self
    }

    /// Sets the end of the run, s.
    pub fn t_end_s(mut self, t_end_s: f64) -> Self {
        self.time.t_end_s = t_end_s;
        self
    }
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
    /// Multiplies the T5.7 stiffness (default 1).
    #[serde(default)]
    pub stiffness_scale: Option<f64>,
}

impl CreaseHingeSpec {
    /// The same hinge as a strip's hinge spec (same fields), for the shared checks.
    pub(crate) fn hinge(&self) -> HingeSpec {
        HingeSpec {
            hinge_length_um: self.hinge_length_um,
            layers: self.layers.clone(),
            actuated: self.actuated,
            target_angle_deg: self.target_angle_deg,
            radius_of_curvature_um: self.radius_of_curvature_um,
            stiffness_scale: self.stiffness_scale,
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
    /// No reduced coordinate: the panel network's path (every crease a coordinate, the loop
    /// closed exactly by the vertex's closure rows; `docs/model.md#panel-networks`).
    Network,
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
/// `P` is the pattern: a FOLD path in a scene file, a [`crate::pattern::VertexPattern`] once loaded.
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
    /// The same scene with its pattern resolved (e.g. a path loaded into a [`crate::pattern::VertexPattern`]).
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

/// The hinge every crease of a network scene gets unless `hinges` lists it.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HingeDefaultsSpec {
    /// l, µm.
    pub hinge_length_um: f64,
    /// Structural layer first, then the stressed one if actuated.
    pub layers: Vec<LayerSpec>,
    /// Whether a stressed layer drives these hinges (default false).
    #[serde(default)]
    pub actuated: bool,
    /// The folded angle's magnitude, degrees: each crease drives to it with its assignment's
    /// sign (valley +, mountain −); an unassigned crease needs its own entry in `hinges`.
    #[serde(default)]
    pub target_angle_deg: Option<f64>,
    /// ρ_c, µm (needed by a ramp or a front).
    #[serde(default)]
    pub radius_of_curvature_um: Option<f64>,
    /// Multiplies the T5.7 stiffness (default 1).
    #[serde(default)]
    pub stiffness_scale: Option<f64>,
}

impl HingeDefaultsSpec {
    /// The same hinge as a strip's hinge spec, for the shared checks.
    pub(crate) fn hinge(&self) -> HingeSpec {
        HingeSpec {
            hinge_length_um: self.hinge_length_um,
            layers: self.layers.clone(),
            actuated: self.actuated,
            target_angle_deg: self.target_angle_deg,
            radius_of_curvature_um: self.radius_of_curvature_um,
            stiffness_scale: self.stiffness_scale,
        }
    }
}

/// Where a network scene's substrate is a contact.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct NetworkSubstrateSpec {
    /// Whether a panel reaching z = 0 outside the paper's flat outline (off the etched pit)
    /// touches the substrate (default false: the panels hang over the pit).
    #[serde(default)]
    pub contact: bool,
}

/// A scene of any crease pattern (`docs/model.md#panel-networks`): its panels are plates,
/// its creases hinges; the start is the pattern's own state, at rest. `P` is the pattern: a
/// path in a scene file, a [`crate::pattern::crease_pattern::CreasePattern`] once loaded.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkSpec<P> {
    /// Names the scene; "scene" when absent (the loader puts the file's name here).
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// The pattern: a FOLD crease pattern or folded form (relative to the scene file).
    pub pattern: P,
    /// One pattern coordinate unit in µm.
    pub length_unit_um: f64,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Every panel's structural layer.
    pub plates: SectorPlateSpec,
    /// Hinges by crease (FOLD edge index).
    #[serde(default)]
    pub hinges: Vec<CreaseHingeSpec>,
    /// The hinge of every crease `hinges` does not list.
    #[serde(default)]
    pub hinge_defaults: Option<HingeDefaultsSpec>,
    /// The face on the substrate (FOLD face index); default: the panel nearest the pattern's
    /// centre.
    #[serde(default)]
    pub anchored_face: Option<usize>,
    /// Creases held at their start angle.
    #[serde(default)]
    pub locks: Vec<LockSpec>,
    /// Step, ramp or front.
    pub actuation: ActuationSpec,
    /// The air.
    pub environment: EnvironmentSpec,
    /// Whether the substrate is a contact.
    #[serde(default)]
    pub substrate: NetworkSubstrateSpec,
    /// How the closures are kept (default: exactly, every crease a coordinate).
    #[serde(default)]
    pub constraint: Option<NetworkConstraintSpec>,
    /// Pairs of the paper's boundary edges (FOLD edge indices) that latch when they meet:
    /// a net's seams (a tree of panels only).
    #[serde(default)]
    pub seams: Vec<[usize; 2]>,
    /// Coulomb's coefficient of friction between touching faces, for a slow release through
    /// contact (default 0: frictionless; at most 10).
    #[serde(default)]
    pub friction_coefficient: Option<f64>,
    /// The time span.
    pub time: TimeSpec,
    /// What to record.
    #[serde(default)]
    pub outputs: OutputSpec,
}

/// Where a network's constraint comes from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NetworkSource {
    /// Every crease a coordinate, every closure kept exactly (`docs/model.md#panel-networks`).
    #[default]
    Network,
    /// One driving crease the coordinate, every other crease its fitted curve of the driver
    /// (the thesis's method; one degree of freedom only; `docs/model.md#fitted-curves-of-a-network`).
    Poly,
}

fn default_network_fit_samples() -> usize {
    64
}

/// How a network's closures are kept: exactly, or by the fitted curves of one driver.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkConstraintSpec {
    /// "network" or "poly".
    pub source: NetworkSource,
    /// The driving crease (FOLD edge index); default: the crease that moves most along the
    /// motion at the final balance.
    #[serde(default)]
    pub driver_edge: Option<usize>,
    /// Chebyshev degree of the curves; default: the lowest (up to 20) that fits every crease
    /// to 1e-8 rad, else the best.
    #[serde(default)]
    pub degree: Option<usize>,
    /// Sweep points fitted (as many − 1 more check the fit; default 64).
    #[serde(default = "default_network_fit_samples")]
    pub samples: usize,
    /// The driver's range [a, b] in degrees; default: from its start to where a step's
    /// undamped swing past the final balance turns back (energy), a tenth wider.
    #[serde(default)]
    pub range_deg: Option<[f64; 2]>,
}

impl<P> NetworkSpec<P> {
    /// The same scene with its pattern resolved.
    pub fn with_pattern<Q>(self, resolve: impl FnOnce(P) -> Result<Q>) -> Result<NetworkSpec<Q>> {
        Ok(NetworkSpec {
            name: self.name,
            description: self.description,
            pattern: resolve(self.pattern)?,
            length_unit_um: self.length_unit_um,
            materials: self.materials,
            plates: self.plates,
            hinges: self.hinges,
            hinge_defaults: self.hinge_defaults,
            anchored_face: self.anchored_face,
            locks: self.locks,
            actuation: self.actuation,
            environment: self.environment,
            substrate: self.substrate,
            constraint: self.constraint,
            seams: self.seams,
            friction_coefficient: self.friction_coefficient,
            time: self.time,
            outputs: self.outputs,
        })
    }
}

/// Accepted ranges of a scene's inputs, (lowest, highest): wide enough for nanometre films
/// and centimetre models, narrow enough that every derived quantity (masses ~ρ L² t,
/// stiffnesses ~E t³, their ratio) stays far inside double precision.
pub mod limits {
    /// Young's modulus, GPa (1 kPa gels to 10 TPa).
    pub const YOUNGS_MODULUS_GPA: (f64, f64) = (1e-6, 1e4);
    /// Density, g/cm³.
    pub const DENSITY_G_CM3: (f64, f64) = (1e-3, 1e2);
    /// A plate's or a layer's thickness, µm (1 Å to 1 cm).
    pub const THICKNESS_UM: (f64, f64) = (1e-4, 1e4);
    /// Plate lengths and widths, hinge lengths, radii of curvature, µm (1 nm to 1 m).
    pub const LENGTH_UM: (f64, f64) = (1e-3, 1e6);
    /// A closed chain's length unit, µm per pattern unit.
    pub const LENGTH_UNIT_UM: (f64, f64) = (1e-6, 1e6);
    /// The drag coefficient.
    pub const DRAG_COEFFICIENT: (f64, f64) = (1e-6, 1e2);
    /// The surrounding fluid's density, kg/m³ (a rarefied gas to mercury).
    pub const FLUID_DENSITY_KG_M3: (f64, f64) = (1e-6, 2e4);
    /// The etch front's speed, µm/min.
    pub const ETCH_RATE_UM_PER_MIN: (f64, f64) = (1e-6, 1e6);
    /// The simulated time, s.
    pub const T_END_S: (f64, f64) = (1e-12, 1e7);
    /// Output samples of a run.
    pub const OUTPUT_SAMPLES: (usize, usize) = (2, 100_000);
    /// Views in `snapshots.svg`.
    pub const SNAPSHOTS: (usize, usize) = (1, 64);
    /// Plates of a strip (∂M has n³ entries: 8 MB at 100).
    pub const MAX_PLATES: usize = 100;
    /// A hinge's `stiffness_scale`.
    pub const STIFFNESS_SCALE: (f64, f64) = (1e-6, 1e6);
    /// Exact sweep samples of a closed chain's constraint.
    pub const CONSTRAINT_SAMPLES: (usize, usize) = (3, 100_000);
    /// Creases of a network scene.
    pub const MAX_NETWORK_CREASES: usize = 20_000;
}

/// `value` if it lies in `range` (closed); else an error naming `field` and the range.
pub(crate) fn within(field: &str, value: f64, range: (f64, f64), unit: &str) -> Result<f64> {
    if value.is_finite() && value >= range.0 && value <= range.1 {
        Ok(value)
    } else {
        // 1.2e-308, not three hundred zeros.
        let shown = if value == 0.0 || (1e-4..1e7).contains(&value.abs()) || !value.is_finite() {
            value.to_string()
        } else {
            format!("{value:e}")
        };
        Err(NanofoldError::invalid(
            field,
            shown,
            format!("must lie in [{:e}, {:e}] {unit}", range.0, range.1),
        ))
    }
}

/// A count in `range` (closed); else an error naming `field` and the range.
pub(crate) fn count_within(field: &str, value: usize, range: (usize, usize)) -> Result<usize> {
    if (range.0..=range.1).contains(&value) {
        Ok(value)
    } else {
        Err(NanofoldError::invalid(
            field,
            value,
            format!("must lie in [{}, {}]", range.0, range.1),
        ))
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
        within(
            &format!("materials.{name}.youngs_modulus_gpa"),
            m.youngs_modulus_gpa,
            limits::YOUNGS_MODULUS_GPA,
            "GPa",
        )?;
        within(
            &format!("materials.{name}.density_g_cm3"),
            m.density_g_cm3,
            limits::DENSITY_G_CM3,
            "g/cm³",
        )?;
        let field = format!("materials.{name}.poisson_ratio");
        finite(&field, m.poisson_ratio)?;
        if !(-1.0 < m.poisson_ratio && m.poisson_ratio < 0.5) {
            return Err(NanofoldError::invalid(field, m.poisson_ratio, "must lie in (−1, 0.5)"));
        }
    }
    Ok(())
}

/// A scene description: a strip or a closed chain.
#[derive(Debug, Clone)]
pub enum SceneSpec {
    /// Plates in a row on parallel hinges.
    Strip(StripSpec),
    /// The sectors of a closed single vertex.
    Closed(Box<ClosedSpec<crate::pattern::VertexPattern>>),
    /// The panels of any crease pattern.
    Network(Box<NetworkSpec<crate::pattern::crease_pattern::CreasePattern>>),
}

impl SceneSpec {
    /// The scene's name, if it has one.
    pub fn name(&self) -> Option<&str> {
        match self {
            SceneSpec::Strip(spec) => spec.name.as_deref(),
            SceneSpec::Closed(spec) => spec.name.as_deref(),
            SceneSpec::Network(spec) => spec.name.as_deref(),
        }
    }
}
