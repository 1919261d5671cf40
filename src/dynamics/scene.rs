//! Scenes (`docs/model.md#scenes`): a validated [`Scene`] — a strip or a closed chain, its
//! time span and outputs — assembled in SI units from a description ([`SceneSpec`], the
//! types of [`crate::read::scene_spec`]) by its `build`.

use super::closed::{assemble, ClosedChain};
use super::forcing::{Actuation, Forcing, HingeDrive};
use super::model::{Joint, Model, Plate};
use super::network::NetworkModel;
use super::strip::StripChain;
use crate::dynamics::spec::{actuation, drag_law, hinge_stiffness, time_and_outputs};
use crate::error::{NanofoldError, Result};
use crate::pattern::crease_pattern::CreasePattern;
use crate::pattern::VertexPattern;
use crate::read::scene_spec::{
    count_within, finite, limits, material, validate_materials, within, ClosedSpec, NetworkSpec, StripEquations,
    StripSpec, MICROMETRE, NETWORK_FROM_PLATES,
};
use nalgebra::{Point3, Vector3};

pub use crate::read::scene_spec::OutputSpec;
use crate::read::scene_spec::SceneSpec;

impl SceneSpec {
    /// Validates and assembles the scene. A closed chain is assembled by
    /// `assemble::closed_chain`: sweep, fit, chain.
    pub fn build(&self) -> Result<Scene> {
        match self {
            SceneSpec::Strip(spec) => spec.build(),
            SceneSpec::Closed(spec) => spec.build(),
            SceneSpec::Network(spec) => spec.build(),
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
    /// The panels of a crease pattern.
    Network(Box<NetworkModel>),
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
            _ => None,
        }
    }

    /// The closed chain, if this is one.
    pub fn closed(&self) -> Option<&ClosedChain> {
        match &self.system {
            System::Closed(chain) => Some(chain),
            _ => None,
        }
    }

    /// The panel network, if this is one.
    pub fn network(&self) -> Option<&NetworkModel> {
        match &self.system {
            System::Network(model) => Some(model),
            _ => None,
        }
    }

    /// The forcing of every hinge (every crease of a closed chain).
    pub fn forcing(&self) -> &Forcing {
        match &self.system {
            System::Strip(chain) => &chain.forcing,
            System::Closed(chain) => &chain.forcing,
            System::Network(model) => &model.forcing,
        }
    }

    /// The target of every output angle, rad: each hinge's for a strip; for a closed chain
    /// the driver's target and the locks' angles (0 for the creases that follow); for a
    /// network each crease's drive, or a locked crease's start.
    pub fn target_angles(&self) -> Vec<f64> {
        match &self.system {
            System::Strip(chain) => chain.target_angles().as_slice().to_vec(),
            System::Closed(chain) => {
                let mut targets = vec![0.0; chain.crease_stiffness.len()];
                targets[chain.driver] = chain.target();
                for &(c, value) in &chain.locked {
                    targets[c] = value;
                }
                targets
            }
            System::Network(model) => (0..model.columns())
                .map(|c| {
                    if model.locked(c) {
                        model.start[c]
                    } else {
                        model.forcing.hinges[c].target
                    }
                })
                .collect(),
        }
    }

    /// The FOLD edge of every output angle (a closed chain's creases, a network's
    /// columns); None for a strip, whose outputs are its hinges in order.
    pub fn output_edges(&self) -> Option<&[usize]> {
        match &self.system {
            System::Strip(_) => None,
            System::Closed(chain) => Some(&chain.crease_user_indices),
            System::Network(model) => Some(&model.folding.pattern.creases),
        }
    }

    /// Hinge stiffness per output angle (per hinge of a strip, per crease of a closed
    /// chain), N·m/rad.
    pub fn stiffness(&self) -> Vec<f64> {
        match &self.system {
            System::Strip(chain) => chain.model.joints().iter().map(|j| j.stiffness).collect(),
            System::Closed(chain) => chain.crease_stiffness.clone(),
            System::Network(model) => model.stiffness(),
        }
    }
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
        count_within("plates", n, (1, limits::MAX_PLATES))?;
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
            let length = within(
                &format!("plates[{i}].length_um"),
                spec.length_um,
                limits::LENGTH_UM,
                "µm",
            )? * MICROMETRE;
            let width = within(&format!("plates[{i}].width_um"), spec.width_um, limits::LENGTH_UM, "µm")? * MICROMETRE;
            let thickness = within(
                &format!("plates[{i}].thickness_um"),
                spec.thickness_um,
                limits::THICKNESS_UM,
                "µm",
            )? * MICROMETRE;
            let density =
                material(&self.materials, &format!("plates[{i}].material"), &spec.material)?.density_g_cm3 * 1e3;
            // The flat plate spans x ∈ [−w/2, w/2], y ∈ [y, y + L]: a box whose moment about the
            // crease-parallel x axis involves its length, not its width (`docs/model.md#plates`).
            let half = 0.5 * width;
            let mut plate = Plate::lamina(
                &[[-half, y], [half, y], [half, y + length], [-half, y + length]],
                thickness,
                density,
            );
            if let Some(moment) = spec.moment_about_crease_kg_m2 {
                plate.inertia[(0, 0)] = moment_about_crease(i, moment, plate.inertia[(0, 0)])?;
            }
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
                    drives[i].radius_of_curvature = within(&field, value, limits::LENGTH_UM, "µm")? * MICROMETRE;
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
        let name = self.name.clone().unwrap_or_else(|| "scene".to_string());
        let chain = StripChain {
            model: Model::chain(joints, plates, drag)?,
            forcing: Forcing {
                actuation,
                hinges: drives,
            },
            substrate_edge_y: edge_y,
        };
        let network = match self.equations {
            StripEquations::Auto => {
                n >= NETWORK_FROM_PLATES && super::network::assemble::narrower_plate(&chain).is_none()
            }
            StripEquations::Chain => false,
            StripEquations::Network => true,
        };
        let system = if network {
            System::Network(Box::new(super::network::assemble::from_strip(&name, &chain)?))
        } else {
            System::Strip(chain)
        };
        Ok(Scene {
            name,
            system,
            t_end,
            outputs: self.outputs.clone(),
        })
    }
}

/// A plate's stated moment about its crease axis, if it lies within a factor 10⁶ of the
/// box's `box_moment` either way (a wider gap is a unit slip, not a reading).
fn moment_about_crease(i: usize, moment: f64, box_moment: f64) -> Result<f64> {
    let field = format!("plates[{i}].moment_about_crease_kg_m2");
    let ratio = moment / box_moment;
    if moment.is_finite() && (1e-6..=1e6).contains(&ratio) {
        Ok(moment)
    } else {
        Err(NanofoldError::invalid(
            field,
            moment,
            format!(
                "must lie within a factor 10⁶ of the plate's box moment {box_moment:.4e} kg·m² (a wider gap is a unit slip: kg·m², not pg·µm²)"
            ),
        ))
    }
}

impl ClosedSpec<VertexPattern> {
    /// Validates the scene and assembles its chain: the sweep, the fit and the tree of
    /// sector plates (`assemble::closed_chain`).
    pub fn build(&self) -> Result<Scene> {
        // The cheap checks first: the chain's assembly runs a sweep.
        let t_end = time_and_outputs(&self.time, &self.outputs)?;
        let chain = assemble::closed_chain(self)?;
        let system = if self.constraint.source == crate::read::scene_spec::SourceKind::Network {
            System::Network(Box::new(super::network::assemble::from_closed(self, &chain)?))
        } else {
            System::Closed(Box::new(chain))
        };
        Ok(Scene {
            name: self.name.clone().unwrap_or_else(|| "scene".to_string()),
            system,
            t_end,
            outputs: self.outputs.clone(),
        })
    }
}

impl NetworkSpec<CreasePattern> {
    /// Validates the scene and assembles its network (`super::network::assemble::network`).
    pub fn build(&self) -> Result<Scene> {
        let t_end = time_and_outputs(&self.time, &self.outputs)?;
        let model = super::network::assemble::network(self)?;
        Ok(Scene {
            name: self.name.clone().unwrap_or_else(|| "scene".to_string()),
            system: System::Network(Box::new(model)),
            t_end,
            outputs: self.outputs.clone(),
        })
    }
}
