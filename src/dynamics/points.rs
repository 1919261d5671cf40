//! Where a point of a panel is (`docs/model.md#points-of-panels`): a point given in the
//! flat sheet's coordinates (µm) on one panel, carried with that panel to the fold angles.
//! The one place that does it: `simulate`'s `motion.fold` frames, the 3D pages drawn from
//! them and the fit's tracked marks all put their points here. A strip's panels are its
//! plates (flat coordinates: x across the strip, y along it, the world frame of the flat
//! strip); a pattern's and a closed vertex's are its FOLD faces (flat coordinates: the
//! file's vertex coordinates times the scene's length unit, and so are the points placed).

use super::algorithms::{update_corners, update_poses as place_plates};
use super::closed::ClosedChain;
use super::model::{Data, Model};
use super::network::algorithms::update_poses as place_panels;
use super::network::{NetworkData, NetworkModel};
use super::scene::{Scene, System};
use super::strip::StripChain;
use crate::error::Result;
use nalgebra::{Point3, Vector3};

/// Micrometres per metre.
const UM: f64 = 1e6;
/// The internal panel of a closed vertex's anchored sector.
pub const GROUND: usize = usize::MAX;

/// What carries the panels, with its scratch.
#[derive(Debug, Clone)]
enum Placing<'s> {
    /// A strip's plates on their serial chain.
    Plates { chain: &'s StripChain, data: Data },
    /// A pattern's panels on their tree.
    Panels { model: &'s NetworkModel, data: NetworkData },
    /// A closed vertex's sectors on the open chain its cut leaves, with each joint's angle
    /// (its crease's).
    Sectors {
        chain: &'s ClosedChain,
        data: Data,
        joint_angles: Vec<f64>,
    },
}

/// Places points of a scene's panels at a state of its angles: [`PanelPoints::pose`] once,
/// then [`PanelPoints::place`] for every point.
#[derive(Debug, Clone)]
pub struct PanelPoints<'s> {
    placing: Placing<'s>,
}

/// A panel's outline in the flat sheet, as the points are given (µm), and the internal
/// panel that carries it.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatOutline {
    /// The internal panel ([`PanelPoints::place`]'s `panel`).
    pub panel: usize,
    /// Its corners, µm.
    pub corners: Vec<[f64; 2]>,
}

impl<'s> PanelPoints<'s> {
    /// Points on `scene`'s panels: a strip's plates, a pattern's or a closed vertex's faces.
    pub fn new(scene: &'s Scene) -> Result<Self> {
        Ok(match &scene.system {
            System::Strip(chain) => Self::for_strip(chain),
            System::Network(model) => Self::for_network(model),
            System::Closed(chain) => Self::for_closed(chain),
        })
    }

    /// Points on a strip's plates.
    pub fn for_strip(chain: &'s StripChain) -> Self {
        PanelPoints {
            placing: Placing::Plates {
                chain,
                data: Data::new(&chain.model),
            },
        }
    }

    /// Points on a pattern's panels.
    pub fn for_network(model: &'s NetworkModel) -> Self {
        PanelPoints {
            placing: Placing::Panels {
                model,
                data: NetworkData::new(model),
            },
        }
    }

    /// Points on a closed vertex's sectors.
    pub fn for_closed(chain: &'s ClosedChain) -> Self {
        PanelPoints {
            placing: Placing::Sectors {
                chain,
                data: Data::new(&chain.model),
                joint_angles: vec![0.0; chain.model.dof()],
            },
        }
    }

    /// The internal panel of a panel as a user names it (a strip's plate, a pattern's or a
    /// closed vertex's FOLD face), or why it is not one.
    pub fn panel(&self, named: usize) -> std::result::Result<usize, String> {
        match &self.placing {
            Placing::Plates { chain, .. } if named < chain.model.dof() => Ok(named),
            Placing::Plates { chain, .. } => Err(format!("the strip has plates 0 to {}", chain.model.dof() - 1)),
            Placing::Panels { model, .. } => {
                let faces = &model.folding.pattern.panel_of_face;
                faces
                    .get(named)
                    .copied()
                    .ok_or_else(|| format!("the pattern has faces 0 to {}", faces.len().saturating_sub(1)))
            }
            Placing::Sectors { chain, .. } => {
                let faces: Vec<usize> = chain.sector_faces.iter().flatten().copied().collect();
                let sector = chain
                    .sector_faces
                    .iter()
                    .position(|f| *f == Some(named))
                    .ok_or_else(|| format!("the vertex's plates are faces {faces:?}"))?;
                // The anchored sector stays put; the others ride their joints.
                Ok(match chain.joint_sectors.iter().position(|&s| s == sector) {
                    Some(joint) => joint,
                    None => GROUND,
                })
            }
        }
    }

    /// Poses every panel at the output `angles` (a strip's hinges, a pattern's or a closed
    /// vertex's creases), rad.
    pub fn pose(&mut self, angles: &[f64]) {
        match &mut self.placing {
            Placing::Plates { chain, data } => place_plates(&chain.model, angles, data),
            Placing::Panels { model, data } => place_panels(model, angles, data),
            Placing::Sectors {
                chain,
                data,
                joint_angles,
            } => {
                for (j, &c) in chain.joint_creases.iter().enumerate() {
                    joint_angles[j] = angles[c];
                }
                place_plates(&chain.model, joint_angles, data);
            }
        }
    }

    /// The point at `flat_um` (the flat sheet, µm) on internal panel `panel`, where the last
    /// [`PanelPoints::pose`] carried it, µm in the same frame. [`GROUND`] is what does not
    /// move: a closed vertex's anchored sector, a strip's substrate.
    pub fn place(&self, panel: usize, flat_um: [f64; 2]) -> [f64; 3] {
        if panel == GROUND {
            return [flat_um[0], flat_um[1], 0.0];
        }
        let flat = Vector3::new(flat_um[0] / UM, flat_um[1] / UM, 0.0);
        let world = match &self.placing {
            // A strip's joint frames carry the flat strip's world frame (identity when flat).
            Placing::Plates { data, .. } => data.joint_frames[panel] * Point3::from(flat),
            Placing::Panels { model, data } => {
                // The pattern's panels are placed about its own origin (the file's, moved
                // to the sheet's first corner): into it and back.
                let [ox, oy] = model.folding.pattern.origin;
                let origin = Vector3::new(ox, oy, 0.0) * model.unit;
                Point3::from(data.place(panel, &(flat - origin)) + origin)
            }
            Placing::Sectors { chain, data, .. } => {
                // The chain's world frame is the flat sheet about the vertex.
                let vertex = Vector3::new(chain.vertex[0], chain.vertex[1], 0.0);
                data.joint_frames[panel] * Point3::from(flat - vertex) + vertex
            }
        };
        [world.x * UM, world.y * UM, world.z * UM]
    }

    /// The point at `flat_um` on internal panel `panel` at the output `angles`, µm.
    pub fn position(&mut self, angles: &[f64], panel: usize, flat_um: [f64; 2]) -> [f64; 3] {
        self.pose(angles);
        self.place(panel, flat_um)
    }

    /// A strip's or a closed vertex's plates, each its outline in the flat sheet (µm) and
    /// its internal panel; a closed vertex's anchored sector first, as [`GROUND`]. (A
    /// pattern's panels are its FOLD faces, drawn from its own vertices.)
    pub fn plate_outlines(&self) -> Vec<FlatOutline> {
        let flat_plates = |model: &Model, shift: Vector3<f64>| {
            let mut data = Data::new(model);
            place_plates(model, &vec![0.0; model.dof()], &mut data);
            update_corners(model, &mut data);
            model
                .plates()
                .iter()
                .enumerate()
                .map(|(j, plate)| FlatOutline {
                    panel: j,
                    corners: (0..plate.outline.len())
                        .map(|k| {
                            let p = data.corners[model.corner_index(j, k)].coords + shift;
                            [p.x * UM, p.y * UM]
                        })
                        .collect(),
                })
                .collect::<Vec<_>>()
        };
        match &self.placing {
            Placing::Plates { chain, .. } => flat_plates(&chain.model, Vector3::zeros()),
            Placing::Sectors { chain, .. } => {
                let vertex = Vector3::new(chain.vertex[0], chain.vertex[1], 0.0);
                // The anchored sector's outline, like the plates', is about the vertex.
                let ground = FlatOutline {
                    panel: GROUND,
                    corners: chain
                        .ground
                        .iter()
                        .map(|p| [(p.x + vertex.x) * UM, (p.y + vertex.y) * UM])
                        .collect(),
                };
                std::iter::once(ground)
                    .chain(flat_plates(&chain.model, vertex))
                    .collect()
            }
            Placing::Panels { .. } => Vec::new(),
        }
    }
}
