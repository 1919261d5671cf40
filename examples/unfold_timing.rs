//! Speed against error for every library pattern and a 64-crease vertex: iterations, wall
//! time (median of 5), time per iteration, one energy + gradient evaluation, and the final
//! residuals. Run: `cargo run --release --example unfold_timing`

use nanofold::energy::{EnergyKind, EnergyWorkspace};
use nanofold::kinematics::solve_closure;
use nanofold::pattern::{LoadOptions, Pattern};
use nanofold::qp::QpMethod;
use nanofold::sphere::Vec3;
use nanofold::unfold::{unfold, SplitMix64, UnfoldModel, UnfoldSettings};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

/// A 64-crease vertex with random sectors, folded by driving the even creases to random
/// angles while the odd ones follow by (minimum-norm) loop closure.
fn many_creases(n: usize) -> Pattern {
    let mut rng = SplitMix64(7);
    let weights: Vec<f64> = (0..n).map(|_| 1.0 + rng.next_f64()).collect();
    let total: f64 = weights.iter().sum();
    let sectors: Vec<f64> = weights.iter().map(|w| w / total * std::f64::consts::TAU).collect();
    let drive: Vec<f64> = (0..n).map(|_| 0.6 * (rng.next_f64() - 0.5)).collect();
    let mut rho = vec![0.0; n];
    let free: Vec<usize> = (1..n).step_by(2).collect();
    for s in 1..=20 {
        for k in (0..n).step_by(2) {
            rho[k] = drive[k] * s as f64 / 20.0;
        }
        solve_closure(&sectors, &mut rho, &free, 1e-14, 100).expect("closure");
    }
    let creases: Vec<String> = rho
        .iter()
        .map(|r| format!(r#"{{"assignment":"U","fold_angle":{r}}}"#))
        .collect();
    let json = format!(
        r#"{{"chain":"closed","angle_unit":"rad","sector_angles":{sectors:?},"creases":[{}]}}"#,
        creases.join(",")
    );
    Pattern::from_str(&json, &format!("random{n}"), "generated", &LoadOptions::default()).unwrap()
}

fn main() {
    let mut patterns: Vec<Pattern> = std::fs::read_dir("patterns")
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|x| x == "fold" || x == "json") && !p.to_string_lossy().ends_with(".scene.json")
        })
        .map(|p| Pattern::load(&p, &LoadOptions::default()).unwrap())
        .collect();
    patterns.sort_by(|a, b| a.name.cmp(&b.name));
    patterns.push(many_creases(64));
    println!(
        "{:<20} {:>6} {:<18} {:>6} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9}",
        "pattern", "creases", "verdict", "iters", "ms (med)", "µs/iter", "µs U+∇U", "max|ρ|", "arc res", "layout"
    );
    for qp in [QpMethod::Direct, QpMethod::Clarabel] {
        println!("-- direction by {qp:?}");
        for pattern in &patterns {
            let settings = UnfoldSettings {
                qp,
                ..Default::default()
            };
            let mut times = Vec::new();
            let mut report = None;
            for _ in 0..5 {
                let started = Instant::now();
                let r = unfold(pattern, &settings).unwrap();
                times.push(started.elapsed().as_secs_f64());
                report = Some(r);
            }
            let report = report.unwrap();
            let seconds = median(times);
            // One energy + gradient evaluation at the folded state.
            let model = UnfoldModel::new(pattern);
            let nodes = model.folded_nodes();
            let energy = EnergyKind::Separable.build(None);
            let mut ws = EnergyWorkspace::default();
            let mut grad = vec![Vec3::zeros(); nodes.len()];
            let reps = 2000;
            let started = Instant::now();
            for _ in 0..reps {
                std::hint::black_box(energy.value_and_gradient(&nodes, &model.arcs, &mut ws, &mut grad));
            }
            let eval_us = started.elapsed().as_secs_f64() / reps as f64 * 1e6;
            let max_rho = report.final_fold_angles_rad.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            println!(
                "{:<20} {:>6} {:<18} {:>6} {:>10.3} {:>10.1} {:>10.2} {:>10.2e} {:>9.1e} {:>9.1e}",
                pattern.name,
                pattern.creases.len(),
                report.verdict.as_str(),
                report.iterations,
                seconds * 1e3,
                seconds / report.iterations.max(1) as f64 * 1e6,
                eval_us,
                max_rho,
                report.max_arc_residual,
                report.flat_layout_error
            );
        }
    }
}
