//! Speed against error for every library pattern and a 64-crease vertex: iterations, wall
//! time (median of 5), time per iteration, one energy + gradient evaluation, and the final
//! residuals. Run: `cargo run --release --example unfold_timing`

mod common;

use common::{library_patterns, many_creases, timed};
use nanofold::geometry::sphere::Vec3;
use nanofold::prelude::Named;
use nanofold::unfold::QpMethod;
use nanofold::unfold::{unfold, UnfoldModel, UnfoldSettings};
use nanofold::unfold::{EnergyKind, EnergyWorkspace};
use std::time::Instant;

fn main() {
    let mut patterns = library_patterns();
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
            let (seconds, report) = timed(5, || unfold(pattern, &settings).unwrap());
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
