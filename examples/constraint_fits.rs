//! Speed against error of the constraint fits: the corner cube's step-1 curves (SPEC §8)
//! at every degree, with the fit error against the exact sweep, the loop-closure residual
//! of the fitted curves, and the time of one evaluation of f and of G.
//!
//! `cargo run --release --example constraint_fits`

use nanofold::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, Setup};
use nanofold::pattern::{LoadOptions, Pattern};
use std::f64::consts::PI;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn main() -> nanofold::Result<()> {
    let pattern = Pattern::load(Path::new("patterns/corner_cube.fold"), &LoadOptions::default())?;
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)])?;

    let sweep_times: Vec<f64> = (0..9)
        .map(|_| {
            let start = Instant::now();
            let samples = sweep_samples(&pattern, &setup, [0.0, PI], 201);
            black_box(samples.is_ok());
            start.elapsed().as_secs_f64()
        })
        .collect();
    let samples = sweep_samples(&pattern, &setup, [0.0, PI], 201)?;
    println!(
        "corner cube step 1: exact sweep of 201 samples in {:.3} ms, closure residual of samples {:.1e} rad",
        median(sweep_times) * 1e3,
        samples.max_closure_residual
    );
    println!(
        "{:>6} {:>14} {:>18} {:>12} {:>12}",
        "degree", "fit error rad", "closure resid rad", "f ns/eval", "G ns/eval"
    );
    let thetas: Vec<f64> = (0..1000).map(|i| PI * i as f64 / 999.0).collect();
    let mut out = vec![0.0; setup.dependents.len()];
    for degree in [1, 2, 3, 4, 6, 8, 10, 12, 14, 16, 18, 20] {
        let poly = ConstraintPoly::fit(&pattern, &samples, degree)?;
        let report = ConstraintReport::new(&pattern, &samples, &poly)?;
        let mut f_times = Vec::new();
        let mut g_times = Vec::new();
        for _ in 0..7 {
            let start = Instant::now();
            for &theta in &thetas {
                poly.eval_into(black_box(theta), &mut out)?;
                black_box(&out);
            }
            f_times.push(start.elapsed().as_secs_f64() / thetas.len() as f64);
            let start = Instant::now();
            for &theta in &thetas {
                poly.jacobian_into(black_box(theta), &mut out)?;
                black_box(&out);
            }
            g_times.push(start.elapsed().as_secs_f64() / thetas.len() as f64);
        }
        println!(
            "{degree:>6} {:>14.2e} {:>18.2e} {:>12.1} {:>12.1}",
            report.max_fit_error(),
            report.max_closure_residual,
            median(f_times) * 1e9,
            median(g_times) * 1e9
        );
    }
    Ok(())
}
