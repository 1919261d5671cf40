//! Speed against error for the bridge (SPEC §8): the step response to first contact with
//! each integrator and tolerance, its error against a run at a much tighter tolerance, and
//! the etch ramp quasi-static against dynamic. `cargo run --release --example dynamics_timing`

use nanofold::dynamics::simulate::{
    quasi_static_deviation, simulate, Method, ModelChoice, Response, SimulationSettings,
};
use nanofold::scene::Scene;
use std::path::Path;
use std::time::Instant;

/// Median wall time of `runs` runs, and the last response.
fn timed(scene: &Scene, settings: &SimulationSettings, runs: usize) -> (f64, Response) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let response = simulate(scene, settings).expect("run");
        times.push(start.elapsed().as_secs_f64());
        last = Some(response);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.unwrap())
}

fn main() {
    let step = Scene::load(Path::new("patterns/bridge_step.scene.json")).unwrap();
    let reference_settings = SimulationSettings {
        rtol: 1e-13,
        method: Method::Tsit45,
        ..Default::default()
    };
    let (reference_time, reference) = timed(&step, &reference_settings, 1);
    let reference_contact = reference.collision.clone().expect("the bridge step collides");
    let reference_angles = reference.samples.last().unwrap().angles.clone();
    println!(
        "bridge step, reference Tsit45 rtol 1e-13 ({reference_time:.2} s): first contact {} / {} at t = {:.9e} s",
        reference_contact.pair[0], reference_contact.pair[1], reference_contact.time
    );
    println!(
        "{:<10} {:>7} {:>10} {:>8} {:>10} {:>14} {:>14}",
        "method", "rtol", "ms (med)", "steps", "rhs", "|Δt_contact| s", "max|Δθ| rad"
    );
    for method in [Method::Tsit45, Method::Esdirk34, Method::TrBdf2, Method::Bdf] {
        for rtol in [1e-6, 1e-8, 1e-10] {
            let settings = SimulationSettings {
                rtol,
                method,
                ..Default::default()
            };
            // The implicit methods are far slower on this ringing response: fewer repeats.
            let runs = if method == Method::Tsit45 { 5 } else { 1 };
            if method != Method::Tsit45 && rtol < 1e-8 {
                continue;
            }
            let (seconds, response) = timed(&step, &settings, runs);
            let contact = response.collision.clone().expect("collides");
            let angles = &response.samples.last().unwrap().angles;
            println!(
                "{:<10} {:>7.0e} {:>10.2} {:>8} {:>10} {:>14.2e} {:>14.2e}",
                format!("{method:?}").to_lowercase(),
                rtol,
                seconds * 1e3,
                response.steps,
                response.rhs_evaluations,
                (contact.time - reference_contact.time).abs(),
                (angles - &reference_angles).amax()
            );
        }
    }

    let ramp = Scene::load(Path::new("patterns/bridge_ramp.scene.json")).unwrap();
    let (qs_seconds, quasi) = timed(&ramp, &SimulationSettings::default(), 5);
    let (window, measured) = quasi.measured_quasi_static_error.unwrap();
    let qs_contact = quasi.collision.clone().unwrap();
    println!(
        "\nbridge ramp (30 min etch), time-scale ratio {:.2e}:\n  quasi-static: {:.1} ms (incl. the {:.1e} s dynamic check); error ≤ {:.2e} rad estimated, {:.2e} rad measured; contact at {:.6} s",
        quasi.time_scales.ratio,
        qs_seconds * 1e3,
        window,
        quasi.quasi_static_error_estimate,
        measured,
        qs_contact.time
    );
    for rtol in [1e-6, 1e-8, 1e-10] {
        let settings = SimulationSettings {
            model: ModelChoice::Dynamic,
            method: Method::Esdirk34,
            rtol,
            ..Default::default()
        };
        let (seconds, dynamic) = timed(&ramp, &settings, 3);
        let contact = dynamic.collision.clone().unwrap();
        let lag = quasi_static_deviation(&ramp, &dynamic.samples);
        println!(
            "  dynamic esdirk34 rtol {rtol:.0e}: {:.1} ms, {} steps; max |θ − θ_quasi-static| {lag:.2e} rad; contact at {:.6} s (Δ {:.2e} s)",
            seconds * 1e3,
            dynamic.steps,
            contact.time,
            contact.time - qs_contact.time
        );
    }
}
