//! Yield against compactness over a sample of a solid's nets spread evenly over its
//! compactness ranking (`docs/model.md#fidelity`): each sampled net's every release and
//! fresh devices as `nets` runs them, then Spearman's ρ of the yields against the radius
//! of gyration and the leaf count, with its interval. Self-timing, on every core.
//!
//! `cargo run --release --example fidelity_study [SHAPE] [NETS] [FRONTS] [SAMPLES]`
//! (default: the dodecahedron, 200 nets, 4 fronts, 20 devices per release).

use nanofold::commands::nets::*;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape = args.get(1).map_or("dodecahedron", String::as_str);
    let count: usize = args.get(2).map_or(200, |a| a.parse().expect("NETS: a count"));
    let fronts: usize = args.get(3).map_or(4, |a| a.parse().expect("FRONTS: a count"));
    let samples: usize = args.get(4).map_or(20, |a| a.parse().expect("SAMPLES: a count"));
    let (name, solid) = open_solid(shape).expect("SHAPE: a solid nanofold generates");
    let options = NetsOptions {
        top: 1,
        simulate: 0,
        fronts,
        yield_samples: samples,
        unit_um: 50.0,
        ..NetsOptions::default()
    };
    let listed = Instant::now();
    let report = nets(&name, &solid, &options).expect("the solid's nets");
    let makeable: Vec<&NetRow> = report
        .nets
        .iter()
        .filter(|r| !r.overlapping && r.touching != Some(true))
        .collect();
    let count = count.min(makeable.len());
    // Evenly over the compactness ranking, the most and least compact included.
    let picked: Vec<usize> = (0..count)
        .map(|k| makeable[(k * (makeable.len() - 1)) / (count - 1).max(1)].rank)
        .collect();
    println!(
        "{shape}: {} nets ({} can be made) listed in {:.1} s; {count} spread over compactness, {fronts} fronts, {samples} devices each",
        report.nets.len(),
        makeable.len(),
        listed.elapsed().as_secs_f64()
    );
    let started = Instant::now();
    let yields: Vec<f64> = on_cores(count, &|k| {
        study_net(&solid, &report, picked[k], &options)
            .expect("a study of one net")
            .best_yield()
    });
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let seconds = started.elapsed().as_secs_f64();
    let row = |rank: usize| report.nets.iter().find(|r| r.rank == rank).unwrap();
    let radii: Vec<f64> = picked.iter().map(|&r| row(r).radius_of_gyration_um).collect();
    let leaves: Vec<f64> = picked.iter().map(|&r| row(r).leaves as f64).collect();
    let runs = count * (options.releases().len() * (1 + samples) + samples * options.captures().len());
    println!(
        "{runs} device runs in {seconds:.1} s on {workers} cores ({:.1} ms a run); mean yield {:.3}",
        1e3 * seconds * workers as f64 / runs as f64,
        yields.iter().sum::<f64>() / count as f64
    );
    for (label, scores) in [("radius of gyration", &radii), ("leaves", &leaves)] {
        match spearman(&yields, scores) {
            Some(r) => println!(
                "  yield against {label}: Spearman ρ = {:.3} (95% {:.3} to {:.3}) over {} nets",
                r.rho, r.interval_95[0], r.interval_95[1], r.pairs
            ),
            None => println!("  yield against {label}: no ranking (a list without spread)"),
        }
    }
}
