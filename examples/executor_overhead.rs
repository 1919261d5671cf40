//! What argmin's Executor costs per unfold iteration: the corner cube (and a 16-crease vertex)
//! unfolded by `nanofold::unfold::unfold` (solver driven by argmin's Executor with the
//! trajectory recorder) against the same solver driven by a bare loop that records the same
//! steps. Median of many runs of each, alternated. Run:
//! `cargo run --release --example executor_overhead`

use nanofold::pattern::LoadOptions;
use nanofold::unfold::{unfold, ProjectedGradient, UnfoldModel, UnfoldSettings};
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

/// The bare loop: the solver's own steps, the nodes and fold angles of each recorded step
/// kept as the recorder keeps them.
fn bare_loop(model: &UnfoldModel, settings: &UnfoldSettings) -> usize {
    let mut solver = ProjectedGradient::new(model, settings, model.folded_nodes()).unwrap();
    let mut kept = vec![(solver.nodes.clone(), model.crease_angles(&solver.nodes))];
    while solver.termination.is_none() {
        if solver.advance().unwrap().is_some() {
            kept.push((solver.nodes.clone(), model.crease_angles(&solver.nodes)));
        }
    }
    black_box(kept).len()
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() {
    let settings = UnfoldSettings::default();
    for name in ["corner_cube.fold", "symmetric16.fold"] {
        let pattern = nanofold::io::load_pattern(&Path::new("patterns").join(name), &LoadOptions::default()).unwrap();
        let model = UnfoldModel::new(&pattern);
        let runs = 2000;
        let (mut executor, mut bare) = (Vec::with_capacity(runs), Vec::with_capacity(runs));
        let mut iterations = 0;
        for _ in 0..runs {
            let start = Instant::now();
            let report = black_box(unfold(&pattern, &settings).unwrap());
            executor.push(start.elapsed().as_secs_f64());
            iterations = report.iterations;
            let start = Instant::now();
            black_box(bare_loop(&model, &settings));
            bare.push(start.elapsed().as_secs_f64());
        }
        let (e, b) = (median(executor), median(bare));
        println!(
            "{name}: {iterations} iterations; executor {:.1} µs/iteration, bare loop {:.1} µs/iteration: argmin adds {:+.1}% (median of {runs} alternating runs each)",
            e / iterations as f64 * 1e6,
            b / iterations as f64 * 1e6,
            100.0 * (e - b) / b
        );
    }
}
