//! The Miura-ori study of the calibration examples: the 4 × 4 sheet with its mountain
//! hinges deposited apart from its valley ones (each mountain crease its own hinge), four
//! free parameters, and what a camera sees of it: marks at the centres of two panels tracked
//! in x, y, z (0.5 µm), and two creases' angles (0.5°), 100 times over 0.5 ms.

use nanofold::calibrate::{resolve, with_values, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::points::PanelPoints;
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::measurement::{MeasuredColumn, Measurement, Observed};
use nanofold::read::SceneDocument;

use super::marks::centre_columns;
use super::normal::Normal;

type Failure = Box<dyn std::error::Error>;
/// Measured columns at the truth, each with its σ.
pub type ExactColumns = Vec<(MeasuredColumn, f64)>;

/// The free parameters: the drag coefficient, the valleys' stress target and Cr thickness,
/// the mountains' stress target. (The plates' thickness would not do as a fourth: scaling
/// inertia, drag and stiffness together leaves the motion unchanged.)
pub fn free() -> Vec<FreeParameter> {
    let free = |path: &str, lower: f64, upper: f64| FreeParameter {
        path: path.into(),
        lower,
        upper,
    };
    vec![
        free("environment.drag_coefficient", 0.2, 5.0),
        free("hinge_defaults.target_angle_deg", 45.0, 135.0),
        free("hinge_defaults.layers[1].thickness_um", 0.02, 0.5),
        free("hinges[*].target_angle_deg", -135.0, -45.0),
    ]
}

/// The values the measurements are simulated at (the scene file says 1.28, 90°, 0.1 µm, −90°).
pub const TRUTH: [f64; 4] = [1.6, 85.0, 0.11, -88.0];

/// The bundled sheet (its drag coefficient left to the default, 1.28) with a hinge of its
/// own for every mountain crease.
pub fn document() -> Result<SceneDocument, Failure> {
    let file = SceneDocument::load("patterns/devices/miura_sheet.scene.json".as_ref())?;
    let mut value = file.value.clone();
    let pattern: serde_json::Value = serde_json::from_str(&std::fs::read_to_string("patterns/many/miura_4x4.fold")?)?;
    let mountains: Vec<serde_json::Value> = pattern["edges_assignment"]
        .as_array()
        .ok_or("edges_assignment")?
        .iter()
        .enumerate()
        .filter(|(_, a)| a.as_str() == Some("M"))
        .map(|(crease, _)| {
            serde_json::json!({
                "crease": crease, "hinge_length_um": 20, "actuated": true,
                "target_angle_deg": -90, "radius_of_curvature_um": 20,
                "layers": [{ "material": "SiN", "thickness_um": 0.2 }, { "material": "Cr", "thickness_um": 0.1 }]
            })
        })
        .collect();
    value["hinges"] = mountains.into();
    Ok(file.with_value(value))
}

/// The observed columns without noise, each with its σ: the sheet simulated at [`TRUTH`],
/// the marks and, if `angles`, the two creases.
pub fn exact_columns(document: &SceneDocument, angles: bool) -> Result<(Vec<f64>, ExactColumns), Failure> {
    let parameters = resolve(document, &free())?;
    let scene = with_values(document, &parameters, &TRUTH).spec()?.build()?;
    let times: Vec<f64> = (1..=100).map(|k| 5e-4 * k as f64 / 100.0).collect();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-10)?;
    let model = scene.network().ok_or("the sheet is a network")?;
    // Marks are drawn in the file's coordinates times the unit, as the calibration guide says.
    let faces = &model.folding.pattern.faces;
    let mut points = PanelPoints::new(&scene)?;
    let mut columns = Vec::new();
    let edges = scene.output_edges().ok_or("a pattern's creases")?.to_vec();
    for k in [0, edges.len() / 2].into_iter().filter(|_| angles) {
        let values = run.angles.iter().map(|a| Some(a[k].to_degrees())).collect();
        let observed = Observed::Angle {
            index: edges[k],
            hinge: false,
        };
        let name = format!("crease_{}_deg", edges[k]);
        columns.push((MeasuredColumn { name, observed, values }, 0.5));
    }
    for face in [faces.len() / 2 + 1, faces.len() - 1] {
        for column in centre_columns(model, &mut points, face, &run.angles, || 0.0)? {
            columns.push((column, 0.5));
        }
    }
    Ok((run.times.clone(), columns))
}

/// The bundled sheet's marks (the file as it is, its drag coefficient 1.28 and hinge target
/// 90°), simulated at `truth` = (drag coefficient, hinge target in degrees): the centres of
/// `faces` tracked in x, y, z (σ 0.5 µm) at `samples` times to `t_end` s. Returns the
/// document, its two free parameters, the times and the exact columns.
pub fn marks_study(
    truth: [f64; 2],
    faces: &[usize],
    t_end: f64,
    samples: usize,
) -> Result<(SceneDocument, Vec<FreeParameter>, Vec<f64>, ExactColumns), Failure> {
    let document = SceneDocument::load("patterns/devices/miura_sheet.scene.json".as_ref())?;
    let free = vec![
        FreeParameter {
            path: "environment.drag_coefficient".into(),
            lower: 0.2,
            upper: 5.0,
        },
        FreeParameter {
            path: "hinge_defaults.target_angle_deg".into(),
            lower: 45.0,
            upper: 135.0,
        },
    ];
    let parameters = resolve(&document, &free)?;
    let scene = with_values(&document, &parameters, &truth).spec()?.build()?;
    let times: Vec<f64> = (1..=samples).map(|k| t_end * k as f64 / samples as f64).collect();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-10)?;
    let model = scene.network().ok_or("the sheet is a network")?;
    let mut points = PanelPoints::new(&scene)?;
    let mut columns = Vec::new();
    for &face in faces {
        for column in centre_columns(model, &mut points, face, &run.angles, || 0.0)? {
            columns.push((column, 0.5));
        }
    }
    Ok((document, free, run.times.clone(), columns))
}

/// One noisy measurement of exact columns (each with its σ).
pub fn noisy(times: &[f64], exact: &[(MeasuredColumn, f64)], normal: &mut Normal) -> Measurement {
    Measurement {
        source: "synthetic".into(),
        times: times.to_vec(),
        columns: exact
            .iter()
            .map(|(column, sigma)| MeasuredColumn {
                values: column
                    .values
                    .iter()
                    .map(|v| v.map(|v| v + sigma * normal.sample()))
                    .collect(),
                ..column.clone()
            })
            .collect(),
    }
}
