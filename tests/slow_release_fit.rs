//! Fitting slow releases: the balance's sensitivities (a tree of panels' KKT conditions
//! through contact; a strip's and a closed chain's quasi-static balance) against central
//! differences of whole runs, and a synthetic etch-ramp film of a cube fitted.

mod common;
use nanofold::calibrate::{
    fit, resolve, with_values, FitSettings, FitStatus, FreeParameter, ResolvedParameter, SENSITIVITY_STEP,
};
use nanofold::read::measurement::{MeasuredColumn, Measurement};

#[path = "../examples/common/cube.rs"]
mod cube;
#[path = "../examples/common/normal.rs"]
mod normal;
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::sensitivity::{trajectory_sensitivities, STENCIL};
use nanofold::dynamics::Method;
use nanofold::read::SceneDocument;

fn free(path: &str, lower: f64, upper: f64) -> FreeParameter {
    FreeParameter {
        path: path.into(),
        lower,
        upper,
    }
}

fn lid_first() -> SceneDocument {
    cube::lid_first().unwrap()
}

fn scene_at(document: &SceneDocument, parameters: &[ResolvedParameter], values: &[f64]) -> Scene {
    with_values(document, parameters, values)
        .spec()
        .unwrap()
        .build()
        .unwrap()
}

/// The sensitivities of `document`'s run at `times` to `free` (at the file's values), and
/// for each parameter the largest gap to Richardson-extrapolated central differences of
/// whole runs (steps 1e-4 and 2e-4 of its scale) with the differences' largest value.
fn against_whole_runs(
    document: &SceneDocument,
    free: &[FreeParameter],
    times: &[f64],
) -> (nanofold::dynamics::sensitivity::TrajectorySensitivity, Vec<(f64, f64)>) {
    let parameters = resolve(document, free).unwrap();
    let start: Vec<f64> = parameters.iter().map(|p| p.start).collect();
    let build = |values: &[f64]| scene_at(document, &parameters, values);
    let eps = SENSITIVITY_STEP;
    let perturbed: Vec<[_; STENCIL.len()]> = (0..parameters.len())
        .map(|j| {
            std::array::from_fn(|k| {
                let mut at = start.clone();
                at[j] = start[j] + STENCIL[k] * eps * parameters[j].scale;
                build(&at)
            })
        })
        .collect();
    let run = trajectory_sensitivities(&build(&start), &perturbed, eps, times, Method::Auto, 1e-8).unwrap();
    assert_eq!(run.times.len(), times.len(), "every asked time has a state");
    let plain = |values: &[f64]| {
        trajectory_sensitivities(&build(values), &[], eps, times, Method::Auto, 1e-8)
            .unwrap()
            .angles
    };
    let gaps = (0..parameters.len())
        .map(|j| {
            let columns = common::richardson_column(plain, &start, j, parameters[j].scale, 1e-4);
            let (mut worst, mut largest): (f64, f64) = (0.0, 0.0);
            for (i, column) in columns.iter().enumerate() {
                for (k, &fd) in column.iter().enumerate() {
                    worst = worst.max((fd - run.sensitivities[i][(k, j)]).abs());
                    largest = largest.max(fd.abs());
                }
            }
            eprintln!("{}: max |S| {largest:.4e}, max |S - FD| {worst:.3e}", free[j].path);
            (worst, largest)
        })
        .collect();
    (run, gaps)
}

/// The lid-first cube's walls' target and stiffness at 131 times: every 100 s, every 5 s
/// through the south wall's push, and past the closing.
#[test]
fn kkt_sensitivities_of_the_lid_first_cube_match_central_differences_of_whole_runs() {
    let free = [
        free("hinge_defaults.target_angle_deg", 80.0, 110.0),
        free("hinge_defaults.stiffness_scale", 0.2, 5.0),
    ];
    let mut t: Vec<f64> = (1..=91).map(|k| 100.0 * k as f64).collect();
    t.extend((0..12).map(|k| 9195.0 + 5.0 * k as f64));
    t.extend((0..28).map(|k| 9300.0 + 100.0 * k as f64));
    let (run, gaps) = against_whole_runs(&lid_first(), &free, &t);
    for (parameter, (worst, largest)) in free.iter().zip(gaps) {
        assert!(
            largest > 0.0 && worst <= 1e-6 * largest,
            "{}: {worst:e} against {largest:e}",
            parameter.path
        );
    }
    // The stiffness shows only while the wall presses the lid: before, every hinge is at its
    // drive; after, the closed cube is square whatever its hinges.
    let pressing: Vec<f64> = (0..run.times.len())
        .filter(|&i| run.sensitivities[i].column(1).amax() > 1e-9)
        .map(|i| run.times[i])
        .collect();
    eprintln!(
        "stiffness felt from {:?} s to {:?} s",
        pressing.first(),
        pressing.last()
    );
    assert!(
        pressing.len() >= 10 && pressing.iter().all(|&t| (9190.0..9257.0).contains(&t)),
        "{pressing:?}"
    );
}

/// Films the lid-first cube's last wall rising at the truth, with noise from `seed`.
fn filmed(document: &SceneDocument, seed: u64) -> Measurement {
    let mut noise = normal::Normal(seed);
    Measurement {
        source: "synthetic.csv".into(),
        times: cube::times(),
        columns: cube::exact_columns(document, &cube::TRUTH)
            .unwrap()
            .into_iter()
            .map(|(column, sigma)| MeasuredColumn {
                values: column
                    .values
                    .iter()
                    .map(|v| v.map(|v| v + sigma * noise.sample()))
                    .collect(),
                ..column
            })
            .collect(),
    }
}

/// A synthetic film (200 frames, 0.5°) of the lid-first cube's last wall, made with the walls'
/// target at 97° and their stiffness 1.6 times the lid's, fitted from the file's 95° and 1:
/// the fit passes through the contact's balance with its KKT sensitivities and lands within
/// 3 standard errors of the truth. (The coverage of its intervals over 100 such fits is
/// `examples/calibration_coverage.rs cube`.)
#[test]
fn a_filmed_slow_release_of_the_cube_is_fitted_through_its_contact() {
    let document = lid_first();
    let measured = filmed(&document, 11);
    let settings = FitSettings {
        free: cube::free(),
        ..FitSettings::default()
    };
    let report = fit(&document, &measured, &settings).unwrap();
    eprintln!(
        "{} iterations, {} simulations, {:.3} s",
        report.iterations, report.simulations, report.seconds
    );
    assert_eq!(report.status, FitStatus::Converged);
    assert!(report.sensitivity_runs > 0, "the Jacobian is the balance's own");
    for (p, truth) in report.parameters.iter().zip(cube::TRUTH) {
        let se = p.standard_error.unwrap();
        eprintln!("{}: {} ± {se} (truth {truth})", p.path, p.estimate);
        assert!(
            (p.estimate - truth).abs() <= 3.0 * se,
            "{}: {} ± {se} against {truth}",
            p.path,
            p.estimate
        );
        assert!(p.start != truth, "started away from the truth");
    }
    for column in &report.residuals {
        assert!(
            (column.noise - cube::SIGMA_DEG).abs() < 0.1,
            "{}: σ {}°",
            column.name,
            column.noise
        );
    }
}

/// A strip's and a closed chain's etch ramps: the quasi-static path's sensitivities from its
/// balance (`balanced`) against Richardson-extrapolated central differences of whole runs.
#[test]
fn balance_sensitivities_of_a_strip_and_a_closed_chain_match_whole_run_differences() {
    for (file, free, t_end) in [
        (
            "patterns/bridge_ramp.scene.json",
            vec![
                free("hinges[*].target_angle_deg", 45.0, 135.0),
                free("hinges[*].radius_of_curvature_um", 10.0, 40.0),
            ],
            1800.0,
        ),
        (
            "patterns/corner_cube_step2_ramp.scene.json",
            vec![
                free("hinges[1].target_angle_deg", 60.0, 120.0),
                free("hinges[1].radius_of_curvature_um", 10.0, 40.0),
            ],
            3000.0,
        ),
    ] {
        let document = SceneDocument::load(file.as_ref()).unwrap();
        let t: Vec<f64> = (1..=40).map(|k| t_end * k as f64 / 40.0 - 1.0).collect();
        let (_, gaps) = against_whole_runs(&document, &free, &t);
        for (parameter, (worst, largest)) in free.iter().zip(gaps) {
            assert!(
                largest > 0.0 && worst <= 1e-6 * largest,
                "{file} {}: {worst:e} against {largest:e}",
                parameter.path
            );
        }
    }
}
