//! What argmin's Executor costs per unfold iteration, for both engines. The single vertex:
//! the corner cube (and a 16-crease vertex) unfolded by `nanofold::unfold::unfold` (solver
//! driven by argmin's Executor with the trajectory recorder) against the same solver driven
//! by a bare loop that records the same steps. Many vertices: a folded Huffman-style
//! waterbomb and Miura-ori unfolded by `unfold_network_observed` (the descent driven by the
//! Executor with the progress observer) against the same descent driven by a bare loop.
//! Median of many runs of each, alternated. Run:
//! `cargo run --release --example executor_overhead`

use nanofold::folding::{fold_path, Drive, FoldSettings, FoldingModel};
use nanofold::pattern::LoadOptions;
use nanofold::unfold::network::{
    start_descent, unfold_network_observed, NetworkStart, NetworkUnfoldReport, NetworkUnfoldSettings,
};
use nanofold::unfold::{unfold, ProjectedGradient, UnfoldModel, UnfoldProgress, UnfoldSettings};
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

/// The many-vertex descent driven by a bare loop, as `unfold_network` drove it before it
/// was an argmin solver.
fn bare_descent(model: &FoldingModel, start: &[f64], settings: &NetworkUnfoldSettings) -> NetworkUnfoldReport {
    let mut descent = match start_descent(model, start, settings).unwrap() {
        NetworkStart::Decided(report) => return report,
        NetworkStart::Descent(descent) => descent,
    };
    for iteration in 0..settings.max_iterations {
        if let Some(stop) = descent.iterate(iteration).unwrap() {
            return descent.finish(stop, iteration);
        }
    }
    descent.into_report()
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() {
    let settings = UnfoldSettings::default();
    for name in ["corner_cube.fold", "symmetric16.fold"] {
        let pattern = nanofold::read::load_pattern(&Path::new("patterns").join(name), &LoadOptions::default()).unwrap();
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
    let settings = NetworkUnfoldSettings::default();
    for name in ["huffman_waterbomb_6x4.fold", "miura_4x4.fold"] {
        let pattern = nanofold::read::load_crease_pattern(&Path::new("patterns/many").join(name)).unwrap();
        let model = FoldingModel::new(pattern).unwrap();
        let fold = FoldSettings {
            drive: Drive::Assignment { to: 90.0 },
            ..FoldSettings::default()
        };
        let path = fold_path(&model, &model.given_fold_angles(), &fold).unwrap();
        let folded = path.steps.last().unwrap().fold_angles.clone();
        let runs = 40;
        let (mut executor, mut bare) = (Vec::with_capacity(runs), Vec::with_capacity(runs));
        let mut iterations = 0;
        let progress = UnfoldProgress(std::sync::Arc::new(|step, largest, energy| {
            black_box((step, largest, energy));
        }));
        for _ in 0..runs {
            let start = Instant::now();
            let report =
                black_box(unfold_network_observed(&model, &folded, &settings, Some(progress.clone())).unwrap());
            executor.push(start.elapsed().as_secs_f64());
            iterations = report.iterations;
            let start = Instant::now();
            let plain = black_box(bare_descent(&model, &folded, &settings));
            bare.push(start.elapsed().as_secs_f64());
            assert_eq!(plain, report, "both drivers take the same steps");
        }
        let (e, b) = (median(executor), median(bare));
        println!(
            "{name} folded to 90%: {iterations} iterations; executor {:.1} µs/iteration, bare loop {:.1} µs/iteration: argmin adds {:+.1}% (median of {runs} alternating runs each)",
            e / iterations as f64 * 1e6,
            b / iterations as f64 * 1e6,
            100.0 * (e - b) / b
        );
    }
}
