//! The slow-release study of the calibration examples: the lid-first cube with its lid's
//! hinge listed apart from the walls' (`patterns/devices/cube_lid_first_lid_apart.scene.json`), filmed as its last (south) wall rises, meets the lid's edge and pushes it back
//! until the cube closes: 200 frames from 8 000 s to 9 300 s, every crease's angle to 0.5°.
//! The walls' stress target and stiffness are free; the contact's balance rests on the
//! walls' stiffness against the lid's.

use nanofold::calibrate::{resolve, with_values, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::measurement::{MeasuredColumn, Observed};
use nanofold::read::SceneDocument;

type Failure = Box<dyn std::error::Error>;

/// The walls' target and stiffness scale the film was made at.
pub const TRUTH: [f64; 2] = [97.0, 1.6];
/// The tracking's σ, degrees.
pub const SIGMA_DEG: f64 = 0.5;

/// The lid-first cube with its lid's hinge (crease 4) listed on its own, at the walls'
/// values, and the walls' stiffness scale written out (1):
/// `patterns/devices/cube_lid_first_lid_apart.scene.json`.
pub fn lid_first() -> Result<SceneDocument, Failure> {
    Ok(SceneDocument::load(
        "patterns/devices/cube_lid_first_lid_apart.scene.json".as_ref(),
    )?)
}

/// The walls' stress target and stiffness scale, free within their bounds.
pub fn free() -> Vec<FreeParameter> {
    let free = |path: &str, lower: f64, upper: f64| FreeParameter {
        path: path.into(),
        lower,
        upper,
    };
    vec![
        free("hinge_defaults.target_angle_deg", 85.0, 105.0),
        free("hinge_defaults.stiffness_scale", 0.2, 5.0),
    ]
}

/// The film's times, s.
pub fn times() -> Vec<f64> {
    (0..200).map(|k| 8000.0 + 1300.0 * k as f64 / 199.0).collect()
}

/// Every crease's angle at the film's times at `truth`, without noise, each with its σ.
pub fn exact_columns(document: &SceneDocument, truth: &[f64]) -> Result<Vec<(MeasuredColumn, f64)>, Failure> {
    let parameters = resolve(document, &free())?;
    let scene = with_values(document, &parameters, truth).spec()?.build()?;
    let times = times();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-8)?;
    if run.times.len() != times.len() {
        return Err(format!("the run gave {} of the film's {} frames", run.times.len(), times.len()).into());
    }
    let edges = scene
        .output_edges()
        .ok_or("a network scene names its creases")?
        .to_vec();
    Ok(edges
        .iter()
        .enumerate()
        .map(|(k, &edge)| {
            let column = MeasuredColumn {
                name: format!("crease_{edge}_deg"),
                observed: Observed::Angle {
                    index: edge,
                    hinge: false,
                },
                values: run.angles.iter().map(|a| Some(a[k].to_degrees())).collect(),
            };
            (column, SIGMA_DEG)
        })
        .collect())
}
