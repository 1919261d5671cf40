//! Where a mark on a panel is (`docs/model.md#calibration`): a point given in the flat
//! sheet's coordinates (µm) on one panel, carried with that panel to the fold angles: what a
//! camera tracking a mark on the device sees. A strip's panels are its plates (flat
//! coordinates: x across the strip, y along it); a pattern's and a closed vertex's are its
//! FOLD faces (flat coordinates: the file's vertex coordinates times the scene's length
//! unit, and so are the marks' positions).

use super::algorithms::update_poses as place_plates;
use super::model::Data;
use super::network::algorithms::update_poses as place_panels;
use super::network::NetworkData;
use super::scene::{Scene, System};
use crate::error::Result;
use nalgebra::{Point3, Vector3};

/// Micrometres per metre.
const UM: f64 = 1e6;
/// The internal panel of a closed vertex's anchored sector.
const GROUND: usize = usize::MAX;

/// Scratch for placing marks on a scene's panels.
#[derive(Debug, Clone)]
pub struct PanelPoints<'s> {
    scene: &'s Scene,
    /// A strip's or a closed vertex's tree.
    strip: Option<Data>,
    network: Option<NetworkData>,
    /// A closed vertex's joint angles (its creases' through the tree).
    joint_angles: Vec<f64>,
}

impl<'s> PanelPoints<'s> {
    /// Marks on `scene`'s panels: a strip's plates, a pattern's or a closed vertex's faces.
    pub fn new(scene: &'s Scene) -> Result<Self> {
        Ok(match &scene.system {
            System::Strip(chain) => PanelPoints {
                scene,
                strip: Some(Data::new(&chain.model)),
                network: None,
                joint_angles: Vec::new(),
            },
            System::Network(model) => PanelPoints {
                scene,
                strip: None,
                network: Some(NetworkData::new(model)),
                joint_angles: Vec::new(),
            },
            System::Closed(chain) => PanelPoints {
                scene,
                strip: Some(Data::new(&chain.model)),
                network: None,
                joint_angles: vec![0.0; chain.model.dof()],
            },
        })
    }

    /// The internal panel of a panel as a user names it (a strip's plate, a pattern's or a
    /// closed vertex's FOLD face), or why it is not one.
    pub fn panel(&self, named: usize) -> std::result::Result<usize, String> {
        match &self.scene.system {
            System::Strip(chain) if named < chain.model.dof() => Ok(named),
            System::Strip(chain) => Err(format!("the strip has plates 0 to {}", chain.model.dof() - 1)),
            System::Network(model) => {
                let faces = &model.folding.pattern.panel_of_face;
                faces
                    .get(named)
                    .copied()
                    .ok_or_else(|| format!("the pattern has faces 0 to {}", faces.len().saturating_sub(1)))
            }
            System::Closed(chain) => {
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

    /// The mark at `flat_um` on internal panel `panel` at the output `angles` (a strip's
    /// hinges, a pattern's or a closed vertex's creases), µm.
    pub fn position(&mut self, angles: &[f64], panel: usize, flat_um: [f64; 2]) -> [f64; 3] {
        let flat = Point3::new(flat_um[0] / UM, flat_um[1] / UM, 0.0);
        let world = match (&self.scene.system, &mut self.strip, &mut self.network) {
            (System::Strip(chain), Some(data), _) => {
                place_plates(&chain.model, angles, data);
                data.joint_frames[panel] * flat
            }
            (System::Network(model), _, Some(data)) => {
                place_panels(model, angles, data);
                Point3::from(data.rotation[panel] * flat.coords + data.translation[panel])
            }
            (System::Closed(chain), Some(data), _) => {
                let vertex = Vector3::new(chain.vertex[0], chain.vertex[1], 0.0);
                if panel == GROUND {
                    flat
                } else {
                    for (j, &c) in chain.joint_creases.iter().enumerate() {
                        self.joint_angles[j] = angles[c];
                    }
                    place_plates(&chain.model, &self.joint_angles, data);
                    data.joint_frames[panel] * (flat - vertex) + vertex
                }
            }
            _ => Point3::from(Vector3::repeat(f64::NAN)),
        };
        [world.x * UM, world.y * UM, world.z * UM]
    }
}
