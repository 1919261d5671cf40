//! Coverage of the fit's 95 % intervals (`docs/model.md#calibration`): trajectories
//! simulated at known parameters with seeded Gaussian noise, fitted again and again; the
//! intervals should contain the truth in about 95 of 100 fits (90 to 99 is the binomial
//! range). Prints each study's coverage per parameter and the time per fit.
//!
//! `cargo run --release --example calibration_coverage [RUNS] [STUDY]` (default 100, every
//! study; STUDY is `bridge`, `corner`, `marks`, `miura`, `bridge_ramp` or `cube`)

use nanofold::calibrate::{fit, resolve, with_values, FitSettings, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::measurement::{MeasuredColumn, Observed};
use nanofold::read::SceneDocument;
use std::time::Instant;

#[path = "common/marks.rs"]
mod marks;
#[path = "common/normal.rs"]
mod normal;
use normal::Normal;
#[path = "common/cube.rs"]
mod cube;
#[path = "common/miura.rs"]
mod miura;

type Failure = Box<dyn std::error::Error>;

struct Study {
    name: &'static str,
    document: SceneDocument,
    free: Vec<FreeParameter>,
    truth: Vec<f64>,
    times: Vec<f64>,
    /// The observed columns at the truth, each with its σ.
    exact: Vec<(MeasuredColumn, f64)>,
}

/// A study observing output angles `outputs` of `scene` at `samples` times to `t_end`, with
/// noise of `sigma_deg`.
fn angles_study(
    name: &'static str,
    scene: &str,
    free: Vec<FreeParameter>,
    (outputs, t_end, samples, sigma_deg): (&[usize], f64, usize, f64),
) -> Result<Study, Failure> {
    let document = SceneDocument::load(scene.as_ref())?;
    let parameters = resolve(&document, &free)?;
    let truth: Vec<f64> = parameters.iter().map(|p| p.start).collect();
    let scene = with_values(&document, &parameters, &truth).spec()?.build()?;
    let edges = scene.output_edges().map(<[usize]>::to_vec);
    let times: Vec<f64> = (1..=samples).map(|k| t_end * k as f64 / samples as f64).collect();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-11)?;
    let exact = outputs
        .iter()
        .map(|&k| {
            let index = edges.as_ref().map_or(k, |e| e[k]);
            let column = MeasuredColumn {
                name: format!("crease_{index}_deg"),
                observed: Observed::Angle { index, hinge: false },
                values: run.angles.iter().map(|a| Some(a[k].to_degrees())).collect(),
            };
            (column, sigma_deg)
        })
        .collect();
    Ok(Study {
        name,
        document,
        free,
        truth,
        times: run.times,
        exact,
    })
}

fn run(study: &Study, runs: usize) -> Result<(), Failure> {
    let mut normal = Normal(1);
    let m = study.truth.len();
    let (mut covered, mut determined) = (vec![0usize; m], vec![0usize; m]);
    let (mut seconds, mut simulations, mut exact_runs) = (0.0, 0, 0);
    for _ in 0..runs {
        let measured = miura::noisy(&study.times, &study.exact, &mut normal);
        let clock = Instant::now();
        let report = fit(
            &study.document,
            &measured,
            &FitSettings {
                free: study.free.clone(),
                ..FitSettings::default()
            },
        )?;
        seconds += clock.elapsed().as_secs_f64();
        simulations += report.simulations;
        exact_runs += report.sensitivity_runs;
        for (j, p) in report.parameters.iter().enumerate() {
            if let Some([lo, hi]) = p.interval_95 {
                determined[j] += 1;
                if lo <= study.truth[j] && study.truth[j] <= hi {
                    covered[j] += 1;
                }
            }
        }
    }
    println!(
        "{}: {runs} fits of {} samples × {} columns, {:.2} s, {:.1} simulations ({:.1} with sensitivities) per fit",
        study.name,
        study.times.len(),
        study.exact.len(),
        seconds / runs as f64,
        simulations as f64 / runs as f64,
        exact_runs as f64 / runs as f64
    );
    for (j, p) in study.free.iter().enumerate() {
        println!(
            "  {} = {}: covered in {}/{} ({} determined)",
            p.path, study.truth[j], covered[j], runs, determined[j]
        );
    }
    Ok(())
}

fn main() -> Result<(), Failure> {
    let runs: usize = std::env::args().nth(1).map_or(Ok(100), |a| a.parse())?;
    let only = std::env::args().nth(2);
    let free = |path: &str, lower: f64, upper: f64| FreeParameter {
        path: path.into(),
        lower,
        upper,
    };
    let wanted = |key: &str| only.as_deref().is_none_or(|o| o == key);
    if wanted("bridge") {
        let bridge = angles_study(
            "bridge step",
            "patterns/bridge_step.scene.json",
            vec![
                free("environment.drag_coefficient", 0.2, 5.0),
                free("hinges[*].target_angle_deg", 45.0, 135.0),
            ],
            (&[0, 3], 45e-6, 100, 0.5),
        )?;
        run(&bridge, runs)?;
    }
    if wanted("corner") {
        let corner = angles_study(
            "corner cube step 1",
            "patterns/corner_cube_step1.scene.json",
            vec![free("hinges[0].layers[1].thickness_um", 0.02, 0.5)],
            (&[0, 2], 2.5e-5, 100, 0.5),
        )?;
        run(&corner, runs)?;
    }
    if wanted("marks") {
        // The calibration issue's device: drag 2.0 and target 80°, fitted from the file's
        // 1.28 and 90° by tracked marks alone, on six panels.
        let truth = [2.0, 80.0];
        let (document, free, times, exact) = miura::marks_study(truth, &[0, 3, 6, 9, 12, 15], 5e-4, 100)?;
        let marks = Study {
            name: "Miura-ori 4 x 4 from marks on 6 panels, started at 1.28 and 90 deg",
            document,
            free,
            truth: truth.to_vec(),
            times,
            exact,
        };
        run(&marks, runs)?;
    }
    if wanted("miura") {
        let document = miura::document()?;
        let (times, exact) = miura::exact_columns(&document, true)?;
        let sheet = Study {
            name: "Miura-ori 4 x 4 (2 creases, marks on 2 panels)",
            document,
            free: miura::free(),
            truth: miura::TRUTH.to_vec(),
            times,
            exact,
        };
        run(&sheet, runs)?;
    }
    if wanted("bridge_ramp") {
        // A strip released slowly: its quasi-static path, the Jacobian from its balance.
        let ramp = angles_study(
            "bridge etch ramp, hinges 0 and 3, 100 samples to 1 500 s",
            "patterns/bridge_ramp.scene.json",
            vec![
                free("hinges[*].target_angle_deg", 45.0, 135.0),
                free("hinges[*].radius_of_curvature_um", 10.0, 40.0),
            ],
            (&[0, 3], 1500.0, 100, 0.5),
        )?;
        run(&ramp, runs)?;
    }
    if wanted("cube") {
        // A slow release through contact, fitted from the file's 95° and 1.
        let document = cube::lid_first()?;
        let exact = cube::exact_columns(&document, &cube::TRUTH)?;
        let study = Study {
            name: "lid-first cube, its last wall filmed (walls' target and stiffness)",
            document,
            free: cube::free(),
            truth: cube::TRUTH.to_vec(),
            times: cube::times(),
            exact,
        };
        run(&study, runs)?;
    }
    Ok(())
}
