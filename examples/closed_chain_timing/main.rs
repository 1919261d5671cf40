//! Speed against error for the closed chain (issue 5): the corner cube's step 1 with
//! f = poly (degrees 2…8), f = exact and the same vertex as a panel network (no cut, no
//! reduced coordinate), each against the exact run (contact time, angles at contact,
//! loop-closure drift): which of the two dynamics models a closed vertex runs on is chosen
//! from this table; and the etch ramp quasi-static against dynamic.
//! `cargo run --release --example closed_chain_timing` writes
//! `output/closed_chain_timing/{report.json, poly_vs_exact.svg, ramp.svg}`, the figures drawn
//! from the report (`figures.rs`); `-- --from REPORT.json` redraws a saved report's figures
//! without measuring.

#[path = "../common/mod.rs"]
mod common;
mod figures;

use common::machine;
use nanofold::dynamics::closed::ClosedPlant;
use nanofold::dynamics::quasi_static_deviation;
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::simulate::{simulate_scene, ModelChoice, Simulation, SimulationSettings};
use nanofold::dynamics::Method;
use nanofold::write::write_atomic;
use serde_json::{json, Value};
use std::path::Path;

const RUNS: usize = 5;

fn scene(name: &str, constraint: serde_json::Value) -> Scene {
    let path = format!("patterns/{name}.scene.json");
    let mut value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    value["constraint"] = constraint;
    nanofold::read::parse_scene(&value.to_string(), &path, name, Path::new("patterns"))
        .and_then(|spec| spec.build())
        .unwrap()
}

/// Median wall time of RUNS runs (scene set-up excluded), and the last run.
fn timed(scene: &Scene, settings: &SimulationSettings) -> (f64, Simulation) {
    common::timed(RUNS, || simulate_scene(scene, settings).expect("run"))
}

fn main() {
    let out = Path::new("output/closed_chain_timing");
    std::fs::create_dir_all(out).unwrap();
    // --from REPORT: redraw the figures of a saved report, measuring nothing.
    let args: Vec<String> = std::env::args().collect();
    if let Some(at) = args.iter().position(|a| a == "--from") {
        let path = args.get(at + 1).expect("--from REPORT.json");
        let report: Value = serde_json::from_str(&std::fs::read_to_string(path).expect("the report")).expect("JSON");
        for (name, svg) in figures::figures(&report) {
            write_atomic(&out.join(name), svg.as_bytes()).unwrap();
        }
        println!("redrew the figures of {path} into {}", out.display());
        return;
    }
    let settings = SimulationSettings {
        model: ModelChoice::Dynamic,
        method: Method::Tsit45,
        rtol: 1e-10,
        progress: None,
        ..SimulationSettings::default()
    };
    let range = json!([-5, 180]);
    let exact_scene = scene("corner_cube_step1", json!({"source": "exact", "range_deg": range}));
    let (exact_seconds, exact) = timed(&exact_scene, &settings);
    let exact_contact = exact.response.collision.clone().expect("exact run reaches contact");
    let exact_end = exact.response.samples.last().unwrap().angles.clone();
    println!("corner cube step 1, Tsit45 rtol 1e-10, median of {RUNS} runs");
    println!(
        "{:>7} {:>10} {:>10} {:>10} {:>12} {:>12} {:>12}",
        "f", "ms", "fit err", "slope err", "closure", "Δt contact", "Δθ contact"
    );
    let closure = |r: &Simulation| r.closed.as_ref().unwrap().max_closure_residual;
    println!(
        "{:>7} {:>10.3} {:>10} {:>10} {:>12.1e} {:>12} {:>12}",
        "exact",
        exact_seconds * 1e3,
        "0",
        "0",
        closure(&exact),
        "0",
        "0"
    );
    let mut rows = vec![json!({
        "source": "exact", "seconds": exact_seconds, "fit_error_rad": 0.0, "slope_error": 0.0,
        "max_closure_residual": closure(&exact), "contact_time_s": exact_contact.time,
        "contact_time_error_s": 0.0, "contact_angle_error_rad": 0.0, "steps": exact.response.steps,
    })];
    for degree in 2..=8 {
        let poly_scene = scene(
            "corner_cube_step1",
            json!({"source": "poly", "degree": degree, "range_deg": range}),
        );
        let (seconds, run) = timed(&poly_scene, &settings);
        let contact = run.response.collision.clone().expect("poly run reaches contact");
        let dt = contact.time - exact_contact.time;
        let dtheta = (&run.response.samples.last().unwrap().angles - &exact_end).amax();
        let report = run.closed.as_ref().unwrap();
        println!(
            "{:>7} {:>10.3} {:>10.1e} {:>10.1e} {:>12.1e} {:>12.1e} {:>12.1e}",
            format!("poly {degree}"),
            seconds * 1e3,
            report.fit_error,
            report.slope_error,
            report.max_closure_residual,
            dt,
            dtheta
        );
        rows.push(json!({
            "source": "poly", "degree": degree, "seconds": seconds, "fit_error_rad": report.fit_error,
            "slope_error": report.slope_error, "max_closure_residual": report.max_closure_residual,
            "contact_time_s": contact.time, "contact_time_error_s": dt, "contact_angle_error_rad": dtheta,
            "steps": run.response.steps,
        }));
    }
    // The same vertex on the panel network's equations.
    let network_scene = scene("corner_cube_step1", json!({"source": "network"}));
    let (seconds, run) = timed(&network_scene, &settings);
    let contact = run.response.collision.clone().expect("network run reaches contact");
    let dt = contact.time - exact_contact.time;
    let end = &run.response.samples.last().unwrap().angles;
    assert_eq!(end.len(), exact_end.len(), "one angle per crease, in FOLD edge order");
    let dtheta = (end - &exact_end).amax();
    let residual = run.network.as_ref().unwrap().max_closure_residual;
    println!(
        "{:>7} {:>10.3} {:>10} {:>10} {:>12.1e} {:>12.1e} {:>12.1e}",
        "network",
        seconds * 1e3,
        "0",
        "0",
        residual,
        dt,
        dtheta
    );
    rows.push(json!({
        "source": "network", "seconds": seconds, "fit_error_rad": 0.0, "slope_error": 0.0,
        "max_closure_residual": residual, "contact_time_s": contact.time, "contact_time_error_s": dt,
        "contact_angle_error_rad": dtheta, "steps": run.response.steps,
    }));
    // The etch ramp: quasi-static (auto) against dynamic ESDIRK34 at two tolerances.
    let ramp = nanofold::read::load_scene(Path::new("patterns/corner_cube_step1_ramp.scene.json"))
        .and_then(|spec| spec.build())
        .unwrap();
    let auto = SimulationSettings {
        progress: None,
        ..SimulationSettings::default()
    };
    let (qs_seconds, qs) = timed(&ramp, &auto);
    let qs = qs.response;
    let (_, qs_measured) = qs.measured_quasi_static_error.unwrap();
    println!(
        "\ncorner cube step 1 ramp ({:.0} s of etch): quasi-static {:.2} ms, error ≤ {:.1e} rad (bound), {:.1e} rad measured",
        qs.time_scales.forcing_time_s,
        qs_seconds * 1e3,
        qs.quasi_static_error_estimate,
        qs_measured
    );
    let mut ramp_rows = vec![json!({
        "model": "quasi_static", "seconds": qs_seconds, "error_bound_rad": qs.quasi_static_error_estimate,
        "measured_error_rad": qs_measured,
    })];
    for rtol in [1e-10, 1e-11] {
        let dynamic = SimulationSettings {
            model: ModelChoice::Dynamic,
            method: Method::Esdirk34,
            rtol,
            progress: None,
            ..SimulationSettings::default()
        };
        let (seconds, run) = timed(&ramp, &dynamic);
        let run = run.response;
        let plant = ClosedPlant::new(ramp.closed().unwrap(), false);
        let deviation = quasi_static_deviation(&plant, &run.samples).unwrap();
        println!(
            "  dynamic ESDIRK34 rtol {rtol:.0e}: {:.2} ms, {} steps, max |θ − θ_quasi-static| {:.1e} rad",
            seconds * 1e3,
            run.steps,
            deviation
        );
        ramp_rows.push(json!({
            "model": "dynamic", "method": "esdirk34", "rtol": rtol, "seconds": seconds, "steps": run.steps,
            "deviation_from_quasi_static_rad": deviation,
        }));
    }
    let report = json!({
        "machine": machine(),
        "runs_per_point": RUNS,
        "step": {"scene": "corner_cube_step1", "method": "tsit45", "rtol": 1e-10, "rows": rows},
        "ramp": {"scene": "corner_cube_step1_ramp", "rows": ramp_rows},
    });
    write_atomic(
        &out.join("report.json"),
        serde_json::to_string_pretty(&report).unwrap().as_bytes(),
    )
    .unwrap();
    for (name, svg) in figures::figures(&report) {
        write_atomic(&out.join(name), svg.as_bytes()).unwrap();
    }
    println!("wrote {}/{{report.json, poly_vs_exact.svg, ramp.svg}}", out.display());
}
