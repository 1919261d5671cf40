//! The network part of the work-precision report: how a panel network's dynamics scales
//! with its size, with its error beside its time. The folded Miura-ori sheet of
//! `patterns/devices/miura_sheet.scene.json` at n × n panels, released at 100° zigzag folds
//! with its step torques and drag, runs for 20 µs (about 1.4 periods of its one folding
//! motion) at four tolerances against a reference at rtol 1e-12. For each run: wall time
//! (median of 3, one run from 16 × 16 up) split into set-up, integration and output samples,
//! steps, right-hand sides, the largest crease-angle error at the end, the closure residual
//! and the energy balance; power laws fit each part's cost against the number of panels.
//! With MuJoCo's venv (NANOFOLD_PYTHON) the same sheet, exported, runs in MuJoCo (RK4 at 40,
//! 20 and 10 ns) against the same reference.

use crate::common::timed;
use nanofold::dynamics::network::NetworkPlant;
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::simulate::{simulate_scene, Simulation, SimulationSettings};
use nanofold::dynamics::Plant;
use nanofold::folding::FoldingModel;
use nanofold::pattern::generate::MiuraSpec;
use nanofold::read::load_scene;
use nanofold::write::crease_pattern_fold;
use nanofold::write::write_atomic;
use nanofold::write::{scene_mjcf, LoopClosure, MujocoSettings};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The run's length, s.
const T_END: f64 = 2e-5;
/// Tolerances of the timed runs.
const TOLERANCES: [f64; 4] = [1e-4, 1e-6, 1e-8, 1e-10];
/// The reference's tolerance.
const REFERENCE_RTOL: f64 = 1e-12;
/// MuJoCo's RK4 steps, s (the finest only up to 16 × 16: at 32 × 32 it takes minutes).
const MUJOCO_STEPS: [f64; 3] = [4e-8, 2e-8, 1e-8];
/// Sheets above this many panels skip MuJoCo's finest step.
const MUJOCO_FINEST_PANELS: usize = 256;

/// Writes the folded n × n sheet and its scene (the bundled Miura sheet's materials, hinges,
/// step and drag) into `out`; returns the scene's path.
fn sheet(out: &Path, n: usize) -> PathBuf {
    let builder = MiuraSpec {
        rows: n,
        cols: n,
        zigzag_fold_angle: 100f64.to_radians(),
        ..MiuraSpec::default()
    }
    .build()
    .expect("a Miura sheet");
    let model = FoldingModel::new(builder.build().expect("a pattern")).expect("a folding model");
    let state = model.given_fold_angles();
    let note = format!("Miura-ori {n} x {n}, 60 deg, zigzag creases at 100 deg (closed form)");
    let fold = crease_pattern_fold(&model.pattern, Some(&state), &note);
    let fold_path = out.join(format!("miura_{n}x{n}_folded.fold"));
    write_atomic(&fold_path, serde_json::to_string(&fold).unwrap().as_bytes()).unwrap();
    let mut scene: Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/devices/miura_sheet.scene.json").unwrap()).unwrap();
    scene["name"] = format!("miura_{n}x{n}_folded").into();
    scene["pattern"] = fold_path.file_name().unwrap().to_str().unwrap().into();
    scene["time"]["t_end_s"] = T_END.into();
    let scene_path = out.join(format!("miura_{n}x{n}_folded.scene.json"));
    write_atomic(&scene_path, scene.to_string().as_bytes()).unwrap();
    scene_path
}

fn run(scene: &Scene, rtol: f64) -> Simulation {
    let settings = SimulationSettings {
        rtol,
        progress: None,
        ..Default::default()
    };
    simulate_scene(scene, &settings).expect("the sheet runs")
}

fn final_angles(run: &Simulation) -> Vec<f64> {
    run.response
        .samples
        .last()
        .expect("samples")
        .angles
        .iter()
        .copied()
        .collect()
}

fn largest_gap(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// MuJoCo's run of the sheet exported at `step` s: (seconds, its final angles by crease
/// column, the loops' largest opening, µm); None when the client fails (said on stderr).
fn mujoco(python: &Path, out: &Path, scene: &Scene, step: f64) -> Option<(f64, Vec<f64>, f64)> {
    let settings = MujocoSettings {
        timestep: step,
        closure: LoopClosure::Connect,
    };
    let model_path = out.join(format!("{}.xml", scene.name));
    let mjcf = scene_mjcf(scene, &settings).expect("the sheet exports");
    write_atomic(&model_path, mjcf.as_bytes()).unwrap();
    let result = Command::new(python)
        .arg("tests/mujoco/nanofold_mujoco.py")
        .arg(&model_path)
        // Half a step short, so its last step ends at T_END and not one step after.
        .arg(((T_END - 0.5 * step) * 1e6).to_string())
        .output()
        .ok()?;
    if !result.status.success() {
        eprintln!("MuJoCo: {}", String::from_utf8_lossy(&result.stderr));
        return None;
    }
    let result: Value = serde_json::from_slice(&result.stdout).ok()?;
    let network = scene.network()?;
    let mut angles = vec![f64::NAN; network.columns()];
    for (name, angle) in result["joint_names"]
        .as_array()?
        .iter()
        .zip(result["final_qpos"].as_array()?)
    {
        let edge: usize = name.as_str()?.strip_prefix("crease_")?.parse().ok()?;
        let column = network.folding.pattern.creases.iter().position(|&e| e == edge)?;
        angles[column] = angle.as_f64()?;
    }
    Some((
        result["seconds"].as_f64()?,
        angles,
        result["max_equality_violation"].as_f64()?,
    ))
}

/// Seconds to set a run up: the plant (a flat start's branch), the time scales (natural
/// periods at the start and at the final balance) and the quasi-static estimate.
fn setup_seconds(scene: &Scene) -> f64 {
    let network = scene.network().expect("a network scene");
    timed(1, || {
        let plant = NetworkPlant::new(network, true).expect("the plant");
        (
            plant.time_scales().expect("time scales"),
            plant.quasi_static_error_estimate().expect("estimate"),
        )
    })
    .0
}

/// The network part of the report: the folded Miura sheet at n × n panels for each n in
/// `sizes`, nanofold at four tolerances and, with `python` (MuJoCo's venv), MuJoCo.
pub fn networks_part(sizes: &[usize], python: Option<&Path>) -> Value {
    let out = Path::new("output/work_precision/networks");
    std::fs::create_dir_all(out).unwrap();
    println!(
        "\n== panel networks: the folded Miura sheet, n x n panels, step to 90 deg with drag, {} us; error against rtol {REFERENCE_RTOL:e} ==",
        T_END * 1e6
    );
    println!(
        "ms: the whole run with the scene's {} output samples; 'integrate': with 2 samples, less the set-up; 'samples': the rest",
        nanofold::read::scene_spec::OutputSpec::default().samples
    );
    println!(
        "{:>3} {:>6} {:>7} {:>7} {:>9} {:>9} {:>9} {:>9} {:>6} {:>6} {:>9} {:>9} {:>9} {:>9}",
        "n",
        "panels",
        "creases",
        "rtol",
        "ms",
        "set-up",
        "integrate",
        "samples",
        "steps",
        "rhs",
        "ms/step",
        "max|dθ|",
        "closure",
        "energy"
    );
    let mut rows = Vec::new();
    let mut fits: [Vec<(f64, f64)>; 3] = Default::default();
    for &n in sizes {
        let scene_path = sheet(out, n);
        let scene = load_scene(&scene_path).expect("the scene").build().expect("it builds");
        let mut bare = load_scene(&scene_path).expect("the scene").build().expect("it builds");
        bare.outputs.samples = 2;
        let network = scene.network().expect("a network scene");
        let (panels, creases) = (network.panels(), network.columns());
        let runs = if n >= 16 { 1 } else { 3 };
        let (reference_seconds, reference) = timed(1, || run(&scene, REFERENCE_RTOL));
        let reference_angles = final_angles(&reference);
        let setup = timed(runs, || setup_seconds(&scene)).0;
        let mut size_rows = Vec::new();
        for rtol in TOLERANCES {
            let (seconds, simulation) = timed(runs, || run(&scene, rtol));
            let (bare_seconds, bare_run) = timed(runs, || run(&bare, rtol));
            let response = &simulation.response;
            let report = simulation.network.as_ref().expect("a network report");
            let error = largest_gap(&final_angles(&bare_run), &reference_angles);
            let integrate = (bare_seconds - setup).max(0.0);
            let sampling = (seconds - bare_seconds).max(0.0);
            let per_step = integrate / bare_run.response.steps.max(1) as f64;
            println!(
                "{n:>3} {panels:>6} {creases:>7} {rtol:>7.0e} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>6} {:>6} {:>9.2} {error:>9.2e} {:>9.1e} {:>9.1e}",
                seconds * 1e3,
                setup * 1e3,
                integrate * 1e3,
                sampling * 1e3,
                bare_run.response.steps,
                bare_run.response.rhs_evaluations,
                per_step * 1e3,
                report.max_closure_residual,
                report.energy_balance_error.unwrap_or(f64::NAN)
            );
            if rtol == 1e-8 {
                fits[0].push((panels as f64, setup));
                fits[1].push((panels as f64, per_step));
                fits[2].push((panels as f64, sampling / response.samples.len() as f64));
            }
            size_rows.push(json!({
                "rtol": rtol, "seconds": seconds, "runs": runs, "setup_seconds": setup,
                "integrate_seconds": integrate, "sampling_seconds": sampling,
                "samples": response.samples.len(),
                "steps": bare_run.response.steps, "rhs_evaluations": bare_run.response.rhs_evaluations,
                "max_angle_error_rad": error,
                "max_closure_residual": report.max_closure_residual,
                "energy_balance_error": report.energy_balance_error,
            }));
        }
        let mut mujoco_rows = Vec::new();
        if let Some(python) = python {
            for step in MUJOCO_STEPS {
                if step == MUJOCO_STEPS[2] && panels > MUJOCO_FINEST_PANELS {
                    continue;
                }
                if let Some((seconds, angles, opening)) = mujoco(python, out, &scene, step) {
                    let error = largest_gap(&angles, &reference_angles);
                    println!(
                        "{n:>3} {panels:>6} {creases:>7} MuJoCo RK4 {:>3.0} ns: {:>9.1} ms, max|dθ| {error:.2e} rad, loops open by {opening:.1e} um",
                        step * 1e9,
                        seconds * 1e3
                    );
                    mujoco_rows.push(json!({
                        "timestep_s": step, "seconds": seconds, "max_angle_error_rad": error,
                        "max_equality_violation_um": opening,
                    }));
                }
            }
        }
        rows.push(json!({
            "n": n, "panels": panels, "creases": creases,
            "reference": { "rtol": REFERENCE_RTOL, "seconds": reference_seconds,
                "steps": reference.response.steps, "rhs_evaluations": reference.response.rhs_evaluations },
            "runs": size_rows, "mujoco": mujoco_rows,
        }));
    }
    let exponents: Vec<Option<f64>> = fits
        .iter()
        .map(|points| nanofold::plot::power_law_fit(points).map(|f| f.0))
        .collect();
    for (what, exponent) in ["set-up", "one integrator step", "one output sample"]
        .iter()
        .zip(&exponents)
    {
        if let Some(k) = exponent {
            println!("{what} ~ panels^{k:.2} (rtol 1e-8)");
        }
    }
    json!({
        "t_end_s": T_END,
        "reference_rtol": REFERENCE_RTOL,
        "rows": rows,
        "exponents": { "setup": exponents[0], "step": exponents[1], "sample": exponents[2] },
        "strips": strips_part(),
    })
}

/// Plates of the strips timed both ways.
const STRIP_PLATES: [usize; 5] = [4, 10, 25, 50, 100];
/// Their run, s (through contacts: the timing is the equations', not the contact search's).
const STRIP_T_END: f64 = 1e-5;

/// A strip of `plates` bridge hinges and 20 µm plates (the bundled bridge for 4), on the
/// given equations.
fn strip(plates: usize, equations: &str) -> Scene {
    let mut value: Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap()).unwrap();
    if plates != 4 {
        let plate = json!({"length_um": 20, "width_um": 100, "thickness_um": 0.2, "material": "SiN"});
        let hinge = value["hinges"][0].clone();
        value["plates"] = Value::Array(vec![plate; plates]);
        value["hinges"] = Value::Array(vec![hinge; plates]);
    }
    value["equations"] = equations.into();
    nanofold::read::parse_scene(&value.to_string(), "strip", "strip", Path::new("patterns"))
        .and_then(|spec| spec.build())
        .expect("the strip builds")
}

/// The strip's two equations of motion (the chain's dense joint-space ones, and the panel
/// network's), timed on strips of 4 to 100 plates at rtol 1e-8 through contacts, with the
/// largest difference of their final angles.
fn strips_part() -> Value {
    println!(
        "\n== strips on the chain's equations and on the network's: {} us of a step response through contacts, rtol 1e-8 ==",
        STRIP_T_END * 1e6
    );
    println!(
        "{:>6} {:>10} {:>7} {:>10} {:>7} {:>10}",
        "plates", "chain ms", "steps", "network ms", "steps", "max|dθ|"
    );
    let settings = SimulationSettings {
        t_end: Some(STRIP_T_END),
        ignore_collisions: true,
        progress: None,
        ..Default::default()
    };
    let mut rows = Vec::new();
    for plates in STRIP_PLATES {
        let runs = if plates >= 50 { 1 } else { 3 };
        let (chain, network) = (strip(plates, "chain"), strip(plates, "network"));
        let (chain_seconds, chain_run) = timed(runs, || simulate_scene(&chain, &settings).expect("chain"));
        let (network_seconds, network_run) = timed(runs, || simulate_scene(&network, &settings).expect("network"));
        let gap = largest_gap(&final_angles(&chain_run), &final_angles(&network_run));
        println!(
            "{plates:>6} {:>10.1} {:>7} {:>10.1} {:>7} {gap:>10.2e}",
            chain_seconds * 1e3,
            chain_run.response.steps,
            network_seconds * 1e3,
            network_run.response.steps
        );
        rows.push(json!({
            "plates": plates, "runs": runs,
            "chain_seconds": chain_seconds, "chain_steps": chain_run.response.steps,
            "network_seconds": network_seconds, "network_steps": network_run.response.steps,
            "max_angle_difference_rad": gap,
        }));
    }
    json!({ "t_end_s": STRIP_T_END, "rtol": 1e-8, "rows": rows })
}
