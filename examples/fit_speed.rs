//! The fit's speed against its error (`docs/guide/calibration.md#speed`): the two benchmarks
//! of the calibration issue, each fitted three times, printing the median time beside the
//! simulations it took and how far each estimate lies from the truth in standard errors.
//!
//! - The bridge's step response (`patterns/measurements/bridge_step_measured.csv`: 200 times,
//!   four hinges), three parameters: drag coefficient, stress target, Cr thickness.
//! - The 4 × 4 Miura-ori sheet of `common/miura.rs`, simulated at known values with seeded
//!   noise, from tracked points only (marks at the centres of two panels, x, y, z); four
//!   parameters: drag coefficient, the valleys' stress target and Cr thickness, the
//!   mountains' stress target.
//!
//! `cargo run --release --example fit_speed [RUNS]` (default 3)

use nanofold::calibrate::{fit, FitReport, FitSettings, FreeParameter};
use nanofold::read::measurement::Measurement;
use nanofold::read::SceneDocument;
use std::time::Instant;

#[path = "common/marks.rs"]
mod marks;
#[path = "common/normal.rs"]
mod normal;
use normal::Normal;
#[allow(dead_code)] // the marks study is the coverage example's
#[path = "common/miura.rs"]
mod miura;

type Failure = Box<dyn std::error::Error>;

fn free(path: &str, lower: f64, upper: f64) -> FreeParameter {
    FreeParameter {
        path: path.into(),
        lower,
        upper,
    }
}

/// Fits `runs` times; prints the median time, the work and each estimate's distance from
/// `truth` in standard errors.
fn time_fits(
    name: &str,
    document: &SceneDocument,
    measured: &Measurement,
    free: &[FreeParameter],
    truth: &[f64],
    runs: usize,
) -> Result<(), Failure> {
    let settings = FitSettings {
        free: free.to_vec(),
        ..FitSettings::default()
    };
    let mut seconds = Vec::with_capacity(runs);
    let mut report: Option<FitReport> = None;
    for _ in 0..runs {
        let clock = Instant::now();
        report = Some(fit(document, measured, &settings)?);
        seconds.push(clock.elapsed().as_secs_f64());
    }
    seconds.sort_by(f64::total_cmp);
    let report = report.ok_or("no run")?;
    println!(
        "{name}: {:.2} s (median of {runs}; {:.2} to {:.2}), {} iterations, {} simulations ({} with sensitivities), {:?}",
        seconds[runs / 2],
        seconds[0],
        seconds[runs - 1],
        report.iterations,
        report.simulations,
        report.sensitivity_runs,
        report.status
    );
    for (p, t) in report.parameters.iter().zip(truth) {
        let off = p.standard_error.map(|se| (p.estimate - t) / se);
        println!(
            "  {} = {:.6} ± {} (truth {t}; {} standard errors off)",
            p.path,
            p.estimate,
            p.standard_error.map_or("undetermined".into(), |se| format!("{se:.2e}")),
            off.map_or("-".into(), |z| format!("{z:+.2}"))
        );
    }
    Ok(())
}

fn bridge(runs: usize) -> Result<(), Failure> {
    let document = SceneDocument::load("patterns/bridge_step.scene.json".as_ref())?;
    let measured =
        nanofold::read::measurement::load_measurement("patterns/measurements/bridge_step_measured.csv".as_ref())?;
    let free = [
        free("environment.drag_coefficient", 0.2, 5.0),
        free("hinges[*].target_angle_deg", 45.0, 135.0),
        free("hinges[*].layers[1].thickness_um", 0.02, 0.5),
    ];
    time_fits(
        "bridge, 3 parameters",
        &document,
        &measured,
        &free,
        &[1.6, 85.0, 0.1],
        runs,
    )
}

fn miura(runs: usize) -> Result<(), Failure> {
    let document = miura::document()?;
    let (times, exact) = miura::exact_columns(&document, false)?;
    let measured = miura::noisy(&times, &exact, &mut Normal(43));
    time_fits(
        "Miura-ori 4 x 4, 4 parameters from 2 tracked marks",
        &document,
        &measured,
        &miura::free(),
        &miura::TRUTH,
        runs,
    )
}

fn main() -> Result<(), Failure> {
    let runs: usize = std::env::args().nth(1).map_or(Ok(3), |a| a.parse())?;
    bridge(runs)?;
    miura(runs)
}
