//! The calibration issue's tracked-marks fit (`docs/guide/calibration.md`): the bundled
//! 4 × 4 Miura-ori device simulated at a drag coefficient of 2.0 and a hinge target of 80°,
//! marks at the centres of three panels tracked in x, y, z with 0.5 µm of noise, 100 times
//! over 0.5 ms; fitted from the scene file's 1.28 and 90°. Prints the time, each estimate
//! against the truth in standard errors, the residuals and the warnings; then the same data
//! fitted by a wrong model (the drag held at the file's value), which must be told apart by
//! its lack of fit.
//!
//! `cargo run --release --example fit_marks`

use nanofold::calibrate::{fit, resolve, with_values, FitReport, FitSettings, FreeParameter, SENSITIVITY_STEP};
use nanofold::dynamics::points::PanelPoints;
use nanofold::dynamics::sensitivity::trajectory_sensitivities;
use nanofold::dynamics::Method;
use nanofold::read::measurement::Measurement;
use nanofold::read::SceneDocument;
use std::time::Instant;

#[path = "common/marks.rs"]
mod marks;
#[path = "common/normal.rs"]
mod normal;
use marks::centre_columns;
use normal::Normal;

type Failure = Box<dyn std::error::Error>;

fn free(path: &str, lower: f64, upper: f64) -> FreeParameter {
    FreeParameter {
        path: path.into(),
        lower,
        upper,
    }
}

/// The tracked marks of the device at `truth`: each of `faces`' centres in x, y, z, with
/// 0.5 µm of noise.
fn tracked(
    document: &SceneDocument,
    parameters: &[FreeParameter],
    truth: &[f64],
    faces: &[usize],
) -> Result<Measurement, Failure> {
    let resolved = resolve(document, parameters)?;
    let scene = with_values(document, &resolved, truth).spec()?.build()?;
    let times: Vec<f64> = (1..=100).map(|k| 5e-4 * k as f64 / 100.0).collect();
    let run = trajectory_sensitivities(&scene, &[], SENSITIVITY_STEP, &times, Method::Auto, 1e-10)?;
    let model = scene.network().ok_or("a network")?;
    let mut points = PanelPoints::new(&scene)?;
    let mut normal = Normal(7);
    let mut columns = Vec::new();
    for &face in faces {
        columns.extend(centre_columns(model, &mut points, face, &run.angles, || {
            0.5 * normal.sample()
        })?);
    }
    Ok(Measurement {
        source: "tracked (synthetic)".into(),
        times: run.times.clone(),
        columns,
    })
}

fn show(name: &str, report: &FitReport, seconds: f64, truth: &[f64]) {
    println!(
        "{name}: {seconds:.1} s, {:?}, {} iterations, {} simulations ({} with sensitivities), reduced χ² {:.3}",
        report.status, report.iterations, report.simulations, report.sensitivity_runs, report.reduced_chi_square
    );
    for (p, t) in report.parameters.iter().zip(truth) {
        let z = p.standard_error.map(|se| (p.estimate - t) / se);
        println!(
            "  {} = {:.5} ± {} (truth {t}: {} standard errors{})",
            p.path,
            p.estimate,
            p.standard_error.map_or("undetermined".into(), |se| format!("{se:.2e}")),
            z.map_or("-".into(), |z| format!("{z:+.2}")),
            if p.at_bound { ", on its bound" } else { "" }
        );
    }
    for column in &report.residuals {
        println!(
            "  {}: σ {:.3} µm, RMS {:.3}, largest {:.3}, periodicity z {}, runs z {}, Durbin–Watson {}",
            column.name,
            column.noise,
            column.rms,
            column.max_abs,
            column.periodicity_z.map_or("-".into(), |z| format!("{z:+.2}")),
            column.runs_z.map_or("-".into(), |z| format!("{z:+.2}")),
            column.durbin_watson.map_or("-".into(), |d| format!("{d:.2}"))
        );
    }
    for warning in &report.warnings {
        println!("  warning: {warning}");
    }
}

/// Where a fit's time goes: one plain run of the motion at the measurement's times, and one
/// with the sensitivities to both parameters integrated beside it (the fit's two kinds of
/// simulation), each the median of three.
fn time_runs(document: &SceneDocument, parameters: &[FreeParameter], times: &[f64]) -> Result<(), Failure> {
    use nanofold::dynamics::sensitivity::STENCIL;
    let resolved = resolve(document, parameters)?;
    let start: Vec<f64> = resolved.iter().map(|p| p.start).collect();
    let scene = |values: &[f64]| -> Result<nanofold::dynamics::scene::Scene, Failure> {
        Ok(with_values(document, &resolved, values).spec()?.build()?)
    };
    let base = scene(&start)?;
    let mut perturbed = Vec::new();
    for (j, p) in resolved.iter().enumerate() {
        let pair: Vec<_> = STENCIL
            .iter()
            .map(|k| {
                let mut at = start.clone();
                at[j] += k * SENSITIVITY_STEP * p.scale;
                scene(&at)
            })
            .collect::<Result<_, _>>()?;
        perturbed.push(pair.try_into().map_err(|_| "one scene per offset")?);
    }
    let median = |run: &dyn Fn() -> Result<(), Failure>| -> Result<f64, Failure> {
        let mut seconds = Vec::new();
        for _ in 0..3 {
            let clock = Instant::now();
            run()?;
            seconds.push(clock.elapsed().as_secs_f64());
        }
        seconds.sort_by(f64::total_cmp);
        Ok(seconds[1])
    };
    let plain = median(&|| {
        trajectory_sensitivities(&base, &[], SENSITIVITY_STEP, times, Method::Auto, 1e-8)?;
        Ok(())
    })?;
    let with = median(&|| {
        trajectory_sensitivities(&base, &perturbed, SENSITIVITY_STEP, times, Method::Auto, 1e-8)?;
        Ok(())
    })?;
    println!("one plain run {plain:.2} s; one run with both sensitivities {with:.2} s (median of 3)");
    Ok(())
}

fn main() -> Result<(), Failure> {
    let document = SceneDocument::load("patterns/devices/miura_sheet.scene.json".as_ref())?;
    let parameters = [
        free("environment.drag_coefficient", 0.2, 4.0),
        free("hinge_defaults.target_angle_deg", 45.0, 135.0),
    ];
    let truth = [2.0, 80.0];
    let measured = tracked(&document, &parameters, &truth, &[0, 6, 13])?;
    time_runs(&document, &parameters, &measured.times)?;
    let settings = FitSettings {
        free: parameters.to_vec(),
        ..FitSettings::default()
    };
    let clock = Instant::now();
    let report = fit(&document, &measured, &settings)?;
    show(
        "drag and target from 3 tracked panels",
        &report,
        clock.elapsed().as_secs_f64(),
        &truth,
    );
    // The same data, the drag held at the file's 1.28: a model that cannot describe them.
    let settings = FitSettings {
        free: vec![free("hinge_defaults.target_angle_deg", 45.0, 135.0)],
        ..FitSettings::default()
    };
    let clock = Instant::now();
    let report = fit(&document, &measured, &settings)?;
    show(
        "the same data, the drag held at the file's 1.28",
        &report,
        clock.elapsed().as_secs_f64(),
        &truth[1..],
    );
    Ok(())
}
