//! Calibration: the sensitivities against central differences of whole runs, recovery of
//! known parameters from noisy synthetic measurements, identifiability, bad input.

use nanofold::calibrate::{resolve, with_values, FreeParameter, SENSITIVITY_STEP};
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

fn times(t_end: f64, samples: usize) -> Vec<f64> {
    (1..=samples).map(|k| t_end * k as f64 / samples as f64).collect()
}

#[test]
fn sensitivities_of_the_bridge_match_central_differences_of_whole_runs() {
    let document = SceneDocument::load("patterns/bridge_step.scene.json".as_ref()).unwrap();
    let free = [
        free("hinges[*].target_angle_deg", 30.0, 150.0),
        free("environment.drag_coefficient", 0.1, 10.0),
        free("hinges[*].layers[1].thickness_um", 0.01, 1.0),
    ];
    let parameters = resolve(&document, &free).unwrap();
    let start: Vec<f64> = parameters.iter().map(|p| p.start).collect();
    let build = |values: &[f64]| {
        with_values(&document, &parameters, values)
            .spec()
            .unwrap()
            .build()
            .unwrap()
    };
    let t = times(9e-5, 60);
    let (eps, rtol) = (SENSITIVITY_STEP, 1e-8);
    let perturbed: Vec<[_; 4]> = (0..3)
        .map(|j| {
            std::array::from_fn(|k| {
                let mut at = start.clone();
                at[j] = start[j] + STENCIL[k] * eps * parameters[j].scale;
                build(&at)
            })
        })
        .collect();
    let started = std::time::Instant::now();
    let run = trajectory_sensitivities(&build(&start), &perturbed, eps, &t, Method::Tsit45, rtol).unwrap();
    eprintln!("sensitivity run {:?} steps {}", started.elapsed(), run.steps);
    assert_eq!(run.times.len(), t.len());
    // Central differences of whole runs at a tight tolerance, Richardson-extrapolated from
    // steps 2h and h (the trajectory's phase makes the plain difference's h² error large).
    let h = 1e-4;
    let plain = |values: &[f64]| trajectory_sensitivities(&build(values), &[], eps, &t, Method::Tsit45, 1e-13).unwrap();
    for j in 0..3 {
        let difference = |step: f64| {
            let mut at = start.clone();
            at[j] = start[j] + step * parameters[j].scale;
            let plus = plain(&at);
            at[j] = start[j] - step * parameters[j].scale;
            let minus = plain(&at);
            (0..t.len())
                .map(|i| (&plus.angles[i] - &minus.angles[i]) / (2.0 * step))
                .collect::<Vec<_>>()
        };
        let (wide, narrow) = (difference(2.0 * h), difference(h));
        let mut worst: f64 = 0.0;
        let mut largest: f64 = 0.0;
        for i in 0..t.len() {
            for k in 0..4 {
                let fd = (4.0 * narrow[i][k] - wide[i][k]) / 3.0;
                let s = run.sensitivities[i][(k, j)];
                worst = worst.max((fd - s).abs());
                largest = largest.max(fd.abs());
            }
        }
        eprintln!(
            "parameter {j}: max |S| {largest:.4e}, max |S - FD| {worst:.3e} ({:.2e} relative)",
            worst / largest
        );
        assert!(worst <= 1e-6 * largest, "parameter {j}: {worst:e} against {largest:e}");
    }
}
