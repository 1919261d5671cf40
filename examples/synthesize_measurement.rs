//! Writes patterns/measurements/bridge_step_measured.csv: the bridge's step response
//! simulated at known parameters (drag coefficient 1.6, stress target 85°, Cr 0.1 µm), its
//! four hinges' angles every 0.45 µs up to 90 µs with seeded Gaussian noise of 0.5°, and
//! hinge 2 unobserved after 45 µs (a tracker that lost it). A stand-in for a tracked video
//! until one is measured; README's "Calibrating from a measurement" fits it.
//!
//! Writes patterns/measurements/cube_lid_first_filmed.csv too: a film of the lid-first
//! cube's last wall rising (`examples/common/cube.rs`: 200 frames from 8 000 s to 9 300 s,
//! every crease to 0.5°) released slowly with the walls' target at 97° and their stiffness
//! 1.6 times the lid's; the calibration guide fits it through the contact.
//!
//! `cargo run --release --example synthesize_measurement`

use nanofold::calibrate::{resolve, with_values, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::SceneDocument;

#[path = "common/cube.rs"]
mod cube;
#[path = "common/normal.rs"]
mod normal;
use normal::Normal;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let document = SceneDocument::load("patterns/bridge_step.scene.json".as_ref())?;
    let free = |path: &str| FreeParameter {
        path: path.into(),
        lower: f64::MIN,
        upper: f64::MAX,
    };
    let parameters = resolve(
        &document,
        &[free("environment.drag_coefficient"), free("hinges[*].target_angle_deg")],
    )?;
    let scene = with_values(&document, &parameters, &[1.6, 85.0]).spec()?.build()?;
    let times: Vec<f64> = (1..=200).map(|k| 90e-6 * k as f64 / 200.0).collect();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-10)?;
    let mut normal = Normal(2026);
    let mut text = String::from(
        "# The bridge's step response simulated at drag coefficient 1.6 and stress target 85 deg\n# with 0.5 deg Gaussian noise (examples/synthesize_measurement.rs); hinge 2 lost after 45 us.\ntime_s,hinge_0_deg,hinge_1_deg,hinge_2_deg,hinge_3_deg\n",
    );
    for (t, angles) in run.times.iter().zip(&run.angles) {
        text += &format!("{t:e}");
        for (k, a) in angles.iter().enumerate() {
            if k == 2 && *t > 45e-6 {
                text += ",";
            } else {
                text += &format!(",{:.4}", a.to_degrees() + 0.5 * normal.sample());
            }
        }
        text.push('\n');
    }
    std::fs::write("patterns/measurements/bridge_step_measured.csv", text)?;
    println!(
        "wrote patterns/measurements/bridge_step_measured.csv ({} rows)",
        run.times.len()
    );
    let film = cube::lid_first()?;
    let columns = cube::exact_columns(&film, &cube::TRUTH)?;
    let mut normal = Normal(97);
    let mut text = format!(
        "# The lid-first cube's last wall, released slowly with the walls' target at {} deg and their\n# stiffness {} times the lid's, every crease with {} deg Gaussian noise (examples/synthesize_measurement.rs).\ntime_s",
        cube::TRUTH[0],
        cube::TRUTH[1],
        cube::SIGMA_DEG
    );
    for (column, _) in &columns {
        text += &format!(",{}", column.name);
    }
    text.push('\n');
    for (i, t) in cube::times().iter().enumerate() {
        text += &format!("{t:.3}");
        for (column, sigma) in &columns {
            let angle = column.values[i].ok_or("every frame is simulated")?;
            text += &format!(",{:.4}", angle + sigma * normal.sample());
        }
        text.push('\n');
    }
    std::fs::write("patterns/measurements/cube_lid_first_filmed.csv", text)?;
    println!(
        "wrote patterns/measurements/cube_lid_first_filmed.csv ({} rows)",
        cube::times().len()
    );
    Ok(())
}
