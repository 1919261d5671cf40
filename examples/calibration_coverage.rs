//! Coverage of the fit's 95 % intervals (`docs/model.md#calibration`): trajectories
//! simulated at known parameters with seeded Gaussian noise, fitted again and again; the
//! intervals should contain the truth in about 95 of 100 fits (90 to 99 is the binomial
//! range). Prints each study's coverage per parameter and the time per fit.
//!
//! `cargo run --release --example calibration_coverage [RUNS]` (default 100)

use nanofold::calibrate::{fit, resolve, with_values, FitSettings, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::measurement::{MeasuredColumn, Measurement, Observed};
use nanofold::read::SceneDocument;
use std::time::Instant;

#[path = "common/normal.rs"]
mod normal;
use normal::Normal;

struct Study<'a> {
    name: &'a str,
    scene: &'a str,
    free: Vec<FreeParameter>,
    /// Output angles observed.
    outputs: Vec<usize>,
    t_end: f64,
    samples: usize,
    sigma_deg: f64,
}

fn run(study: &Study, runs: usize) -> Result<(), Box<dyn std::error::Error>> {
    let document = SceneDocument::load(study.scene.as_ref())?;
    let parameters = resolve(&document, &study.free)?;
    let truth: Vec<f64> = parameters.iter().map(|p| p.start).collect();
    let scene = with_values(&document, &parameters, &truth).spec()?.build()?;
    let edges = scene.output_edges().map(<[usize]>::to_vec);
    let times: Vec<f64> = (1..=study.samples)
        .map(|k| study.t_end * k as f64 / study.samples as f64)
        .collect();
    let exact = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-11)?;
    let mut normal = Normal(1);
    let mut covered = vec![0usize; parameters.len()];
    let mut determined = vec![0usize; parameters.len()];
    let (mut seconds, mut simulations) = (0.0, 0);
    for _ in 0..runs {
        let measured = Measurement {
            source: format!("{} synthetic", study.name),
            times: times.clone(),
            columns: study
                .outputs
                .iter()
                .map(|&k| {
                    let index = edges.as_ref().map_or(k, |e| e[k]);
                    MeasuredColumn {
                        name: format!("crease_{index}_deg"),
                        observed: Observed::Angle { index, hinge: false },
                        values: exact
                            .angles
                            .iter()
                            .map(|a| Some(a[k].to_degrees() + study.sigma_deg * normal.sample()))
                            .collect(),
                    }
                })
                .collect(),
        };
        let clock = Instant::now();
        let report = fit(
            &document,
            &measured,
            &FitSettings {
                free: study.free.clone(),
                ..FitSettings::default()
            },
        )?;
        seconds += clock.elapsed().as_secs_f64();
        simulations += report.simulations;
        for (j, p) in report.parameters.iter().enumerate() {
            if let Some([lo, hi]) = p.interval_95 {
                determined[j] += 1;
                if lo <= truth[j] && truth[j] <= hi {
                    covered[j] += 1;
                }
            }
        }
    }
    println!(
        "{}: {runs} fits of {} samples × {} angles (σ {}°), {:.2} s and {:.1} simulations per fit",
        study.name,
        study.samples,
        study.outputs.len(),
        study.sigma_deg,
        seconds / runs as f64,
        simulations as f64 / runs as f64
    );
    for (j, p) in parameters.iter().enumerate() {
        println!(
            "  {} = {}: covered in {}/{} ({} determined)",
            p.path, truth[j], covered[j], runs, determined[j]
        );
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let runs: usize = std::env::args().nth(1).map_or(Ok(100), |a| a.parse())?;
    let free = |path: &str, lower: f64, upper: f64| FreeParameter {
        path: path.into(),
        lower,
        upper,
    };
    let studies = [
        Study {
            name: "bridge step",
            scene: "patterns/bridge_step.scene.json",
            free: vec![
                free("environment.drag_coefficient", 0.2, 5.0),
                free("hinges[*].target_angle_deg", 45.0, 135.0),
            ],
            outputs: vec![0, 3],
            t_end: 45e-6,
            samples: 100,
            sigma_deg: 0.5,
        },
        Study {
            name: "corner cube step 1",
            scene: "patterns/corner_cube_step1.scene.json",
            free: vec![free("hinges[0].layers[1].thickness_um", 0.02, 0.5)],
            outputs: vec![0, 2],
            t_end: 2.5e-5,
            samples: 100,
            sigma_deg: 0.5,
        },
    ];
    for study in &studies {
        run(study, runs)?;
    }
    Ok(())
}
