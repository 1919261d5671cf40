//! Synthetic tracked marks for the calibration examples: a face's centre followed in x, y, z.

use nalgebra::DVector;
use nanofold::dynamics::network::NetworkModel;
use nanofold::dynamics::points::PanelPoints;
use nanofold::read::measurement::{MeasuredColumn, Observed};

/// The centre of pattern face `face` (µm, in the file's frame) tracked in x, y and z along
/// the fold angles `angles`, each value with `noise()` added: three columns named
/// `panel_{face}_{x}_{y}_{axis}_um`.
pub fn centre_columns(
    model: &NetworkModel,
    points: &mut PanelPoints,
    face: usize,
    angles: &[DVector<f64>],
    mut noise: impl FnMut() -> f64,
) -> Result<Vec<MeasuredColumn>, Box<dyn std::error::Error>> {
    let unit = model.unit * 1e6;
    let vertices = model.folding.pattern.file_vertices();
    let corners = &model.folding.pattern.faces[face];
    let share = 1.0 / corners.len() as f64;
    let centre = corners.iter().fold([0.0, 0.0], |c, &v| {
        [
            c[0] + vertices[v][0] * unit * share,
            c[1] + vertices[v][1] * unit * share,
        ]
    });
    let panel = points.panel(face)?;
    let mut columns = Vec::new();
    for (axis, letter) in ["x", "y", "z"].iter().enumerate() {
        let values = angles
            .iter()
            .map(|a| Some(points.position(a.as_slice(), panel, centre)[axis] + noise()))
            .collect();
        columns.push(MeasuredColumn {
            name: format!("panel_{face}_{:.3}_{:.3}_{letter}_um", centre[0], centre[1]),
            observed: Observed::Point {
                panel: face,
                at: centre,
                axis,
            },
            values,
        });
    }
    Ok(columns)
}
