//! The yield study: all 11 cube nets × 16 etch-front directions × 50 varied devices
//! (and each release's nominal one: 8 976 devices; then each net's best release on 50 fresh
//! devices at each of three captures: 10 626 in all), on the machine's cores, as `nanofold nets
//! cube --simulate 11 --top 11` runs it; the issue asks < 60 s on 2 cores. Then where the
//! time goes, one core: building each release's scene and network model, and the closing
//! runs; and beside the time the error of a run against a closed form (the Latin cross
//! released along its closing front shuts when its last hinge reaches 90°).
//!
//! `cargo run --release --example nets_yield_study [RUNS]` (default 3; the median is printed)

use nanofold::commands::nets::*;
use std::time::Instant;

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() {
    let runs: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(3);
    let (name, solid) = open_solid("cube").expect("a generated solid");
    let options = NetsOptions {
        top: 11,
        simulate: 11,
        fronts: 16,
        yield_samples: 50,
        unit_um: 50.0,
        ..NetsOptions::default()
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut walls = Vec::new();
    let mut devices = 0;
    for _ in 0..runs {
        let mut report = nets(&name, &solid, &options).expect("the cube's nets");
        let clock = Instant::now();
        study_nets(&solid, &mut report, &options, &|_, _| {}).expect("the study");
        walls.push(clock.elapsed().as_secs_f64());
        devices = report.study.as_ref().map_or(0, |s| s.devices);
    }
    println!(
        "cube: 11 nets × 16 fronts × (1 + 50) devices, and each best release on 50 fresh ones at 3 captures = {devices} devices in {:.2} s on {cores} cores (median of {runs}); {:.3} ms a device",
        median(walls.clone()),
        1e3 * median(walls) * cores as f64 / devices as f64
    );

    // Where the time goes, one core, the first net's 16 releases.
    let report = nets(&name, &solid, &options).expect("the cube's nets");
    let (_, made) = best_net_patterns(&solid, &report, 1).expect("a net").remove(0);
    let (mut build, mut run, mut count) = (0.0, 0.0, 0);
    for release in options.releases() {
        let released = NetsOptions {
            front_deg: release,
            ..options.clone()
        };
        let clock = Instant::now();
        let scene = net_device(&made, "cube", &released).expect("a scene");
        let model = scene.network().expect("a network");
        let closing = NetClosing::new(&made, model).expect("the net's tests");
        build += clock.elapsed().as_secs_f64();
        let clock = Instant::now();
        let variation = options.variation();
        for sample in 0..variation.samples {
            let (forcing, stiffness) = variation.device(&model.forcing, &model.stiffness(), sample);
            closing
                .run(model, &forcing, &stiffness, &options.closing())
                .expect("a run");
            count += 1;
        }
        run += clock.elapsed().as_secs_f64();
    }
    println!(
        "one core, the best net's 16 releases: scenes and models built in {:.2} ms each ({:.1} % of the time), {count} closing runs in {:.3} ms each",
        1e3 * build / 16.0,
        100.0 * build / (build + run),
        1e3 * run / count as f64
    );

    // The error beside it: the Latin cross along +y (180° as nets lays it) closes when its
    // last hinge squares: released when the front has passed its crease, then a/ρ_c.
    let closing_front = NetsOptions {
        front_deg: Some(180.0),
        ..options.clone()
    };
    let run = net_closing(&made, "cube", &closing_front, &options.closing()).expect("a run");
    let pattern = &made.pattern;
    let passed: Vec<f64> = pattern
        .creases
        .iter()
        .map(|&e| {
            pattern.edges[e]
                .iter()
                .map(|&v| -pattern.vertices[v][0] * 50.0)
                .fold(f64::MIN, f64::max)
        })
        .collect();
    let first = passed.iter().copied().fold(f64::INFINITY, f64::min);
    let rate = 1.5 / 60.0;
    let exact = passed
        .iter()
        .map(|p| (p - first) / rate + std::f64::consts::FRAC_PI_2 * 20.0 / rate)
        .fold(0.0, f64::max);
    println!(
        "error: the Latin cross closes at {:.9e} s, the ramps' closed form {exact:.9e} s (relative {:.1e})",
        run.time_s,
        ((run.time_s - exact) / exact).abs()
    );
}
