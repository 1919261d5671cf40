//! Speed against error, in one report (issue 6): unfolding every library pattern over a
//! sweep of solver settings, the constraint fits by degree, the bridge's step response per
//! integrator and tolerance against a much tighter reference, the bridge's etch ramp
//! quasi-static against dynamic, the cost of one unfold iteration against the number of
//! creases, and panel networks (the folded Miura sheet from 4 × 4 to 32 × 32, time against
//! error and against panels, beside MuJoCo when NANOFOLD_PYTHON names its venv's python),
//! and folding paths by continuation (time against closure and size, frames' accuracy).
//! Each time is the median of several runs.
//!
//! `cargo run --release --example work_precision` prints the tables and writes
//! `output/work_precision/{report.json, unfold_*.svg, fits.svg, bridge_step.svg,
//! bridge_ramp.svg, scaling.svg, networks_*.svg}`; the figures are drawn from the report
//! (`figures.rs`). `-- --from REPORT.json` redraws a saved report's figures without
//! measuring; `-- --networks-into REPORT.json` measures the network part alone into a saved
//! report; `-- --network-sizes 4,8` chooses the sheets; `-- --folding-into REPORT.json`
//! measures the folding paths alone (continuation, frames) into a saved report.

#[path = "../common/mod.rs"]
mod common;
mod figures;
mod folding;
mod networks;

use common::{library_patterns, machine, many_creases, median, timed};
use nanofold::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, Setup};
use nanofold::dynamics::quasi_static_deviation;
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::simulate::{simulate_scene, ModelChoice, SimulationSettings};
use nanofold::dynamics::Method;
use nanofold::dynamics::StripPlant;
use nanofold::geometry::sphere::Vec3;
use nanofold::pattern::LoadOptions;
use nanofold::plot::{largest_sizes, power_law_fit};
use nanofold::prelude::Named;
use nanofold::unfold::{unfold, ProjectedGradient, UnfoldModel, UnfoldSettings, Verdict};
use nanofold::unfold::{DirectWorkspace, QpMethod, RowSpace};
use nanofold::unfold::{EnergyKind, EnergyWorkspace};
use nanofold::write::write_atomic;
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

/// Runs per point (the median is reported).
const RUNS: usize = 5;
/// Runs per dynamics point (the implicit methods take up to half a second a run).
const DYNAMIC_RUNS: usize = 3;

fn write(out: &Path, name: &str, contents: &str) {
    write_atomic(&out.join(name), contents.as_bytes()).expect("writing the report");
}

/// One unfolding configuration of the sweep.
#[derive(Clone, Copy)]
struct UnfoldConfig {
    qp: QpMethod,
    newton_flatten: bool,
    flat_tol: f64,
    max_step_rad: f64,
    bending_metric: f64,
}

impl UnfoldConfig {
    fn settings(self) -> UnfoldSettings {
        UnfoldSettings {
            qp: self.qp,
            newton_flatten: self.newton_flatten,
            flat_tol: self.flat_tol,
            max_step_rad: self.max_step_rad,
            bending_metric: self.bending_metric,
            ..UnfoldSettings::default()
        }
    }
    fn series(self) -> String {
        let qp = match self.qp {
            QpMethod::Direct => "direct",
            QpMethod::Clarabel => "clarabel",
        };
        let finish = if self.newton_flatten {
            "newton finish"
        } else {
            "line search only"
        };
        if self.bending_metric == 0.0 {
            format!("{qp}, plain QP, {finish}")
        } else {
            format!("{qp}, {finish}")
        }
    }
}

/// The unfolding sweep: every pattern that unfolds × direction solver × finish × flat
/// tolerance, plus the step cap of the line search at the default setting.
fn unfold_part() -> Value {
    let defaults = UnfoldSettings::default();
    let mut configs = Vec::new();
    for qp in [QpMethod::Direct, QpMethod::Clarabel] {
        for newton_flatten in [true, false] {
            for flat_tol in [1e-2, 1e-4, 1e-6] {
                configs.push(UnfoldConfig {
                    qp,
                    newton_flatten,
                    flat_tol,
                    max_step_rad: defaults.max_step_rad,
                    bending_metric: defaults.bending_metric,
                });
            }
        }
    }
    // The plain QP (M = I) beside the default bending metric.
    for flat_tol in [1e-2, 1e-4, 1e-6] {
        configs.push(UnfoldConfig {
            qp: QpMethod::Direct,
            newton_flatten: true,
            flat_tol,
            max_step_rad: defaults.max_step_rad,
            bending_metric: 0.0,
        });
    }
    let step_caps = [0.05, 0.8];
    for max_step_rad in step_caps {
        configs.push(UnfoldConfig {
            qp: QpMethod::Direct,
            newton_flatten: true,
            flat_tol: defaults.flat_tol,
            max_step_rad,
            bending_metric: defaults.bending_metric,
        });
    }

    println!("== unfolding: wall time against error (median of {RUNS}) ==");
    println!(
        "{:<20} {:<40} {:>8} {:>9} {:<14} {:>6} {:>10} {:>10} {:>10}",
        "pattern", "direction, finish", "flat tol", "step cap", "verdict", "iters", "ms", "layout err", "arc resid"
    );
    let mut rows = Vec::new();
    for pattern in library_patterns() {
        let probe = unfold(&pattern, &defaults).expect("library pattern unfolds without error");
        if probe.verdict != Verdict::Flat {
            println!(
                "{:<20} verdict {} at the default settings: no flat layout to measure against",
                pattern.name,
                probe.verdict.as_str()
            );
            rows.push(json!({"pattern": pattern.name, "verdict": probe.verdict.as_str()}));
            continue;
        }
        for config in &configs {
            let settings = config.settings();
            let (seconds, report) = timed(RUNS, || unfold(&pattern, &settings).expect("unfold"));
            println!(
                "{:<20} {:<40} {:>8.0e} {:>9} {:<14} {:>6} {:>10.3} {:>10.1e} {:>10.1e}",
                pattern.name,
                config.series(),
                config.flat_tol,
                config.max_step_rad,
                report.verdict.as_str(),
                report.iterations,
                seconds * 1e3,
                report.flat_layout_error,
                report.max_arc_residual
            );
            rows.push(json!({
                "pattern": pattern.name, "creases": pattern.creases.len(),
                "qp": config.qp, "bending_metric": config.bending_metric, "newton_flatten": config.newton_flatten, "flat_tol": config.flat_tol,
                "max_step_rad": config.max_step_rad, "verdict": report.verdict.as_str(),
                "iterations": report.iterations, "seconds": seconds,
                "flat_layout_error": report.flat_layout_error, "max_arc_residual": report.max_arc_residual,
            }));
        }
    }

    json!({"runs_per_point": RUNS, "rows": rows})
}

/// Degree against error and evaluation time of f and G for the corner cube's step-1 curves.
fn fits_part() -> Value {
    let pattern =
        nanofold::read::load_pattern(Path::new("patterns/corner_cube.fold"), &LoadOptions::default()).expect("pattern");
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).expect("setup");
    let (sweep_seconds, samples) = timed(RUNS, || sweep_samples(&pattern, &setup, [0.0, PI], 201).expect("sweep"));
    println!(
        "\n== constraint fits: corner cube step 1, driver crease 0 on [0, π], crease 1 held flat ==\nexact sweep of 201 samples: {:.3} ms, closure residual {:.1e} rad",
        sweep_seconds * 1e3,
        samples.max_closure_residual
    );
    println!(
        "{:>6} {:>13} {:>14} {:>14} {:>10} {:>10}",
        "degree", "fit err rad", "slope err", "closure rad", "f ns", "G ns"
    );
    let thetas: Vec<f64> = (0..1000).map(|i| PI * i as f64 / 999.0).collect();
    let mut buffer = vec![0.0; setup.dependents.len()];
    let mut rows = Vec::new();
    for degree in [1, 2, 3, 4, 6, 8, 10, 12, 14, 16, 20] {
        let poly = ConstraintPoly::fit(&pattern, &samples, degree).expect("fit");
        let report = ConstraintReport::new(&pattern, &samples, &poly).expect("report");
        let slope_error = report.curves.iter().map(|c| c.max_slope_error).fold(0.0, f64::max);
        let mut per_eval = |jacobian: bool| {
            let times: Vec<f64> = (0..RUNS)
                .map(|_| {
                    let start = Instant::now();
                    for &theta in &thetas {
                        if jacobian {
                            poly.jacobian_into(black_box(theta), &mut buffer).expect("G");
                        } else {
                            poly.eval_into(black_box(theta), &mut buffer).expect("f");
                        }
                        black_box(&buffer);
                    }
                    start.elapsed().as_secs_f64() / thetas.len() as f64
                })
                .collect();
            median(times)
        };
        let (f_seconds, g_seconds) = (per_eval(false), per_eval(true));
        println!(
            "{degree:>6} {:>13.2e} {:>14.2e} {:>14.2e} {:>10.1} {:>10.1}",
            report.max_fit_error(),
            slope_error,
            report.max_closure_residual,
            f_seconds * 1e9,
            g_seconds * 1e9
        );
        rows.push(json!({
            "degree": degree, "max_fit_error_rad": report.max_fit_error(), "max_slope_error": slope_error,
            "max_closure_residual_rad": report.max_closure_residual,
            "f_seconds_per_eval": f_seconds, "g_seconds_per_eval": g_seconds,
        }));
    }
    json!({
        "pattern": "corner_cube", "driver": 0, "held": {"1": 0.0}, "domain_rad": [0.0, PI], "samples": 201,
        "sweep_seconds": sweep_seconds, "rows": rows,
    })
}

/// The bridge's step response per integrator and tolerance against a reference, and its
/// etch ramp quasi-static against dynamic.
fn dynamics_part() -> Value {
    let step = load_scene(Path::new("patterns/bridge_step.scene.json"));
    let reference_settings = SimulationSettings {
        rtol: 1e-13,
        method: Method::Tsit45,
        progress: None,
        ..Default::default()
    };
    let (reference_seconds, reference) = timed(1, || {
        simulate_scene(&step, &reference_settings).expect("reference").response
    });
    let reference_contact = reference.collision.clone().expect("the bridge step collides");
    let reference_angles = reference.samples.last().expect("samples").angles.clone();
    println!(
        "\n== bridge step response: error against Tsit45 at rtol 1e-13 ({:.2} s), median of {DYNAMIC_RUNS} ==\nreference first contact {} / {} at t = {:.9e} s",
        reference_seconds, reference_contact.pair[0], reference_contact.pair[1], reference_contact.time
    );
    println!(
        "{:<10} {:>7} {:>10} {:>8} {:>10} {:>14} {:>14}",
        "method", "rtol", "ms", "steps", "rhs", "|Δt contact| s", "max|Δθ| rad"
    );
    let mut rows = Vec::new();
    for method in [Method::Tsit45, Method::Bdf, Method::Esdirk34, Method::TrBdf2] {
        let name = format!("{method:?}").to_lowercase();
        for rtol in [1e-6, 1e-8, 1e-10] {
            // The implicit methods take seconds at 1e-10 on this ringing response.
            if method != Method::Tsit45 && rtol < 1e-8 {
                continue;
            }
            let settings = SimulationSettings {
                rtol,
                method,
                progress: None,
                ..Default::default()
            };
            let (seconds, response) = timed(DYNAMIC_RUNS, || simulate_scene(&step, &settings).expect("run").response);
            let contact = response.collision.clone().expect("collides");
            let angle_error = (&response.samples.last().expect("samples").angles - &reference_angles).amax();
            let time_error = (contact.time - reference_contact.time).abs();
            println!(
                "{name:<10} {rtol:>7.0e} {:>10.2} {:>8} {:>10} {time_error:>14.2e} {angle_error:>14.2e}",
                seconds * 1e3,
                response.steps,
                response.rhs_evaluations
            );
            rows.push(json!({
                "method": name, "rtol": rtol, "seconds": seconds, "steps": response.steps,
                "rhs_evaluations": response.rhs_evaluations, "contact_time_error_s": time_error,
                "angle_error_at_contact_rad": angle_error,
            }));
        }
    }

    let ramp = load_scene(Path::new("patterns/bridge_ramp.scene.json"));
    let quasi_settings = SimulationSettings {
        progress: None,
        ..Default::default()
    };
    let (quasi_seconds, quasi) = timed(RUNS, || {
        simulate_scene(&ramp, &quasi_settings).expect("quasi-static").response
    });
    let (window, measured) = quasi.measured_quasi_static_error.expect("auto measures its error");
    let quasi_contact = quasi.collision.clone().expect("the ramp lands");
    println!(
        "\n== bridge etch ramp (time-scale ratio {:.2e}) ==\nquasi-static: {:.2} ms (with its {:.0e} s dynamic check); error bound {:.2e} rad, measured {:.2e} rad; contact at {:.6} s",
        quasi.time_scales.ratio,
        quasi_seconds * 1e3,
        window,
        quasi.quasi_static_error_estimate,
        measured,
        quasi_contact.time
    );
    let mut ramp_rows = vec![json!({
        "model": "quasi_static", "seconds": quasi_seconds, "error_bound_rad": quasi.quasi_static_error_estimate,
        "measured_error_rad": measured, "contact_time_s": quasi_contact.time,
    })];
    for rtol in [1e-6, 1e-8, 1e-10] {
        let settings = SimulationSettings {
            model: ModelChoice::Dynamic,
            method: Method::Esdirk34,
            rtol,
            progress: None,
            ..Default::default()
        };
        let (seconds, dynamic) = timed(DYNAMIC_RUNS, || {
            simulate_scene(&ramp, &settings).expect("dynamic ramp").response
        });
        let contact = dynamic.collision.clone().expect("the ramp lands");
        let deviation = quasi_static_deviation(
            &StripPlant::new(ramp.strip().expect("a strip"), false),
            &dynamic.samples,
        )
        .expect("deviation");
        println!(
            "dynamic ESDIRK34 rtol {rtol:.0e}: {:.2} ms, {} steps; max |θ − θ_quasi-static| {deviation:.2e} rad; contact Δ {:.2e} s",
            seconds * 1e3,
            dynamic.steps,
            contact.time - quasi_contact.time
        );
        ramp_rows.push(json!({
            "model": "dynamic", "method": "esdirk34", "rtol": rtol, "seconds": seconds, "steps": dynamic.steps,
            "deviation_from_quasi_static_rad": deviation, "contact_time_s": contact.time,
        }));
    }
    json!({
        "step": {"scene": "bridge_step", "reference": {"method": "tsit45", "rtol": 1e-13, "seconds": reference_seconds,
                 "contact_time_s": reference_contact.time}, "runs_per_point": DYNAMIC_RUNS, "rows": rows},
        "ramp": {"scene": "bridge_ramp", "time_scale_ratio": quasi.time_scales.ratio, "rows": ramp_rows},
    })
}

/// Median seconds per call of `work`, repeated until about 20 ms have passed (at least 5).
fn per_call(mut work: impl FnMut()) -> f64 {
    let mut times = Vec::new();
    let started = Instant::now();
    while times.len() < 5 || (started.elapsed().as_secs_f64() < 0.02 && times.len() < 10_000) {
        let start = Instant::now();
        work();
        times.push(start.elapsed().as_secs_f64());
    }
    median(times)
}

/// The cost of one unfold iteration against n, split into its parts.
fn scaling_part() -> Value {
    println!("\n== one unfold iteration against the number of creases (random vertices, median) ==");
    println!(
        "{:>5} {:>14} {:>14} {:>20} {:>10} {:>13} {:>6} {:>10} {:>10}",
        "n", "iteration µs", "U+∇U µs", "direction µs", "share", "unfold", "iters", "ms", "layout err"
    );
    let sizes = [4usize, 8, 16, 32, 64, 128, 256];
    let (mut iteration, mut energy, mut direction) = (Vec::new(), Vec::new(), Vec::new());
    let mut rows = Vec::new();
    for &n in &sizes {
        let pattern = many_creases(n);
        let model = UnfoldModel::new(&pattern);
        let settings = UnfoldSettings::default();
        let mut solver = ProjectedGradient::new(&model, &settings, model.folded_nodes()).expect("start");
        let kind = EnergyKind::Separable.build(None);
        let mut ws = EnergyWorkspace::default();
        let mut gradient = vec![Vec3::zeros(); model.node_count];
        let nodes = solver.nodes.clone();
        let energy_seconds = per_call(|| {
            black_box(kind.value_and_gradient(&nodes, &model.arcs, &mut ws, &mut gradient));
        });
        // The direction as a step computes it: A factorised in place, then the projection
        // (with the metric, the augmented rows' factorisation too), all buffers reused.
        let problem = solver.direction_problem().expect("direction");
        let mut row_space = RowSpace::new(&problem.a).expect("factorisation");
        let mut direct = DirectWorkspace::default();
        let mut y = vec![0.0; problem.q.len()];
        let direction_seconds = per_call(|| {
            row_space.factorise(&problem.a).expect("factorisation");
            direct
                .solve(
                    &problem.a,
                    problem.q.as_slice(),
                    problem.metric.as_ref(),
                    &mut row_space,
                    &mut y,
                )
                .expect("direction solve");
            black_box(&y);
        });
        // Steps change the state: time a fixed number from the folded start.
        let step_times: Vec<f64> = (0..15)
            .map(|_| {
                let start = Instant::now();
                solver.step().expect("step");
                start.elapsed().as_secs_f64()
            })
            .collect();
        let step_seconds = median(step_times);
        // The whole unfold from the folded state, once.
        let start = Instant::now();
        let report = unfold(&pattern, &settings).expect("unfold");
        let unfold_seconds = start.elapsed().as_secs_f64();
        println!(
            "{n:>5} {:>14.1} {:>14.2} {:>20.1} {:>9.0}% {:>13} {:>6} {:>10.1} {:>10.1e}",
            step_seconds * 1e6,
            energy_seconds * 1e6,
            direction_seconds * 1e6,
            100.0 * direction_seconds / step_seconds,
            report.verdict.as_str(),
            report.iterations,
            unfold_seconds * 1e3,
            report.flat_layout_error
        );
        rows.push(json!({
            "creases": n, "iteration_seconds": step_seconds, "energy_and_gradient_seconds": energy_seconds,
            "direction_seconds": direction_seconds, "unfold_verdict": report.verdict.as_str(),
            "unfold_iterations": report.iterations, "unfold_seconds": unfold_seconds,
            "flat_layout_error": report.flat_layout_error,
        }));
        iteration.push((n as f64, step_seconds));
        energy.push((n as f64, energy_seconds));
        direction.push((n as f64, direction_seconds));
    }
    // Exponents from the large sizes, where the leading term dominates.
    let tail = |points: &[(f64, f64)]| power_law_fit(largest_sizes(points)).map(|(k, _)| k);
    let exponents = json!({
        "iteration": tail(&iteration), "energy_and_gradient": tail(&energy), "direction": tail(&direction),
    });
    println!(
        "exponents over n = 64…256: iteration n^{:.2}, U+∇U n^{:.2}, direction (factorisations, solve) n^{:.2}",
        tail(&iteration).unwrap_or(f64::NAN),
        tail(&energy).unwrap_or(f64::NAN),
        tail(&direction).unwrap_or(f64::NAN)
    );
    json!({"rows": rows, "exponents_over_64_to_256": exponents})
}

fn main() {
    let out = Path::new("output/work_precision");
    std::fs::create_dir_all(out).expect("output folder");
    // --from REPORT: redraw the figures of a saved report, measuring nothing.
    let args: Vec<String> = std::env::args().collect();
    if let Some(at) = args.iter().position(|a| a == "--from") {
        let path = report_flag(&args, at, "--from");
        if !Path::new(path).exists() {
            eprintln!("error: the report {path} does not exist");
            std::process::exit(2)
        }
        let report = saved_report(path);
        for (name, svg) in figures::figures(&report) {
            write(out, name, &svg);
        }
        println!("redrew the figures of {path} into {}", out.display());
        return;
    }
    // --network-sizes 4,8: the Miura sheets measured (default 4, 8, 16, 32).
    let sizes: Vec<usize> = args
        .iter()
        .position(|a| a == "--network-sizes")
        .map(|at| {
            args.get(at + 1)
                .expect("--network-sizes N,N,...")
                .split(',')
                .map(|n| n.parse().expect("sizes like 4,8,16"))
                .collect()
        })
        .unwrap_or_else(|| vec![4, 8, 16, 32]);
    let python = std::env::var_os("NANOFOLD_PYTHON").map(std::path::PathBuf::from);
    if python.is_none() {
        println!("(MuJoCo not measured: set NANOFOLD_PYTHON to scripts/test.sh's target/clients-venv/bin/python)");
    }
    // --networks-into REPORT: measure the network part only, put it (with its own machine
    // and commit) into that saved report, and redraw the report's figures.
    if let Some(at) = args.iter().position(|a| a == "--networks-into") {
        let path = report_flag(&args, at, "--networks-into");
        let saved = saved_report(path);
        let report = measure_into(
            path,
            saved,
            "networks",
            networks::networks_part(&sizes, python.as_deref()),
        );
        if report.get("unfolding").is_none() {
            println!("measured the network part into {path} (a report without the other parts: no figures drawn)");
            return;
        }
        for (name, svg) in figures::figures(&report) {
            write(out, name, &svg);
        }
        println!(
            "measured the network part into {path}; its figures are in {}",
            out.display()
        );
        return;
    }
    // --folding-into REPORT: measure the folding paths alone into that saved report.
    if let Some(at) = args.iter().position(|a| a == "--folding-into") {
        let path = report_flag(&args, at, "--folding-into");
        let saved = saved_report(path);
        measure_into(path, saved, "folding", folding::folding_part());
        println!("measured the folding paths into {path}");
        return;
    }
    let started = Instant::now();
    let unfolding = unfold_part();
    let fits = fits_part();
    let dynamics = dynamics_part();
    let scaling = scaling_part();
    let networks = networks::networks_part(&sizes, python.as_deref());
    let folding = folding::folding_part();
    let report = json!({
        "machine": machine(),
        "seconds_total": started.elapsed().as_secs_f64(),
        "unfolding": unfolding,
        "constraint_fits": fits,
        "dynamics": dynamics,
        "scaling": scaling,
        "networks": networks,
        "folding": folding,
    });
    write(
        out,
        "report.json",
        &serde_json::to_string_pretty(&report).expect("json"),
    );
    for (name, svg) in figures::figures(&report) {
        write(out, name, &svg);
    }
    println!(
        "\nwrote {}/{{report.json, unfold_*.svg, fits.svg, bridge_step.svg, bridge_ramp.svg, scaling.svg, networks_*.svg}} in {:.0} s",
        out.display(),
        started.elapsed().as_secs_f64()
    );
}

/// The report file a `--…-into` flag names; exits with a message when it names none.
fn report_flag<'a>(args: &'a [String], at: usize, flag: &str) -> &'a str {
    match args.get(at + 1) {
        Some(path) if !path.starts_with("--") => path,
        _ => {
            eprintln!("error: {flag} needs a report file, e.g. {flag} docs/work_precision_report.json");
            std::process::exit(2)
        }
    }
}

/// The saved report a part goes into, read before anything is measured: a report that does
/// not exist yet starts empty; one that cannot be read or is not a JSON object ends the run.
fn saved_report(path: &str) -> Value {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            println!("{path} does not exist yet: a new report is started there");
            return json!({});
        }
        Err(e) => {
            eprintln!("error: reading the report {path}: {e}");
            std::process::exit(2)
        }
    };
    match serde_json::from_str::<Value>(&text) {
        Ok(report) if report.is_object() => report,
        Ok(_) => {
            eprintln!("error: the report {path} is not a JSON object");
            std::process::exit(2)
        }
        Err(e) => {
            eprintln!("error: the report {path} is not JSON: {e}");
            std::process::exit(2)
        }
    }
}

/// Puts one part (with this machine) into a saved report, rewrites it, and returns it.
fn measure_into(path: &str, mut report: Value, key: &str, mut part: Value) -> Value {
    part["machine"] = machine();
    report[key] = part;
    write_atomic(
        Path::new(path),
        serde_json::to_string_pretty(&report).expect("json").as_bytes(),
    )
    .expect("writing the report");
    report
}

/// A bundled scene, loaded and built.
fn load_scene(path: &Path) -> Scene {
    nanofold::read::load_scene(path)
        .and_then(|spec| spec.build())
        .expect("scene")
}
