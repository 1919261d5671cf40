//! The search for the slowest single vertex within the stated crease limit (512 rays),
//! `docs/guide/limits.md`: families of vertices at 128 to 512 creases, a few seeds each,
//! checked through the front door (`check`: the energy descent, then the folding-path
//! witness where it stops short), with the wall time of each and the worst of all.
//!
//! Families:
//! - `seeded`: random sectors, every crease folded a little (|ρ| ≤ 0.3 rad), closed by Newton;
//! - `seeded_large`: the same with folds up to 0.75 rad;
//! - `fan`: equal sectors, two creases opposite folded 60° along their line, the rest flat;
//! - `few_folded`: a generic degree-4 vertex folded to 120°/−18°/124°/20°, each sector split
//!   into flat unassigned creases of 0.7 to 1.2 times the mean sector (the issue's 400-crease
//!   case);
//! - `few_folded_second`: a second degree-4 vertex (60/100/130/70°) folded by Newton to 120°
//!   at its first crease, split the same way.
//!
//! Run: `cargo run --release --example vertex_limits [N ...]` (default 128 256 400 512).

use nanofold::geometry::kinematics::solve_closure;
use nanofold::prelude::{check, LoadOptions, Named, Pattern, Settings};
use std::time::Instant;

/// splitmix64 in [0, 1).
struct Draws(u64);

impl Draws {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn native(sectors: &[f64], creases: &[(char, f64)]) -> String {
    let creases: Vec<String> = creases
        .iter()
        .map(|(a, r)| format!(r#"{{"assignment":"{a}","fold_angle":{r}}}"#))
        .collect();
    format!(
        r#"{{"chain":"closed","angle_unit":"rad","sector_angles":{sectors:?},"creases":[{}]}}"#,
        creases.join(",")
    )
}

/// Random sectors, every crease folded by up to `amplitude`, closed by Newton on every other
/// crease (continued from flat in 20 steps).
fn seeded(n: usize, amplitude: f64, seed: u64) -> Option<String> {
    let mut draws = Draws(seed);
    let weights: Vec<f64> = (0..n).map(|_| 1.0 + draws.next()).collect();
    let total: f64 = weights.iter().sum();
    let sectors: Vec<f64> = weights.iter().map(|w| w / total * std::f64::consts::TAU).collect();
    let drive: Vec<f64> = (0..n).map(|_| amplitude * (2.0 * draws.next() - 1.0)).collect();
    let free: Vec<usize> = (1..n).step_by(2).collect();
    let mut rho = vec![0.0; n];
    for s in 1..=20 {
        for k in (0..n).filter(|k| !free.contains(k)) {
            rho[k] = drive[k] * s as f64 / 20.0;
        }
        solve_closure(&sectors, &mut rho, &free, 1e-14, 100).ok()?;
    }
    Some(native(&sectors, &rho.iter().map(|&r| ('U', r)).collect::<Vec<_>>()))
}

fn fan(n: usize) -> String {
    let sectors = vec![std::f64::consts::TAU / n as f64; n];
    let creases: Vec<(char, f64)> = (0..n)
        .map(|k| {
            if k == 0 || k == n / 2 {
                ('V', 60f64.to_radians())
            } else {
                ('U', 0.0)
            }
        })
        .collect();
    native(&sectors, &creases)
}

/// A degree-4 vertex's folded state with each sector split into flat unassigned creases.
fn few_folded(n: usize, base_deg: [f64; 4], folds_deg: [f64; 4], assignments: [char; 4], seed: u64) -> String {
    let mut draws = Draws(seed);
    let mean = 360.0 / n as f64;
    let mut sectors = Vec::new();
    let mut creases = Vec::new();
    for k in 0..4 {
        let pieces = ((base_deg[k] / mean).floor() as usize).max(1);
        let weights: Vec<f64> = (0..pieces).map(|_| 0.7 + 0.5 * draws.next()).collect();
        let total: f64 = weights.iter().sum();
        creases.push((assignments[k], folds_deg[k].to_radians()));
        for (j, w) in weights.iter().enumerate() {
            if j > 0 {
                creases.push(('U', 0.0));
            }
            sectors.push((w / total * base_deg[k]).to_radians());
        }
    }
    native(&sectors, &creases)
}

/// A degree-4 vertex of these sectors (degrees) folded with its first crease at
/// `first_deg`, the others closing the loop: Newton continued from a small fold.
fn degree4_folded(sectors_deg: [f64; 4], first_deg: f64) -> Option<[f64; 4]> {
    let sectors: Vec<f64> = sectors_deg.iter().map(|s| s.to_radians()).collect();
    let mut rho = vec![0.02, -0.01, 0.02, 0.01];
    solve_closure(&sectors, &mut rho, &[1, 2, 3], 1e-14, 100).ok()?;
    for s in 1..=60 {
        rho[0] = 0.02 + (first_deg.to_radians() - 0.02) * s as f64 / 60.0;
        solve_closure(&sectors, &mut rho, &[1, 2, 3], 1e-14, 100).ok()?;
    }
    Some([rho[0], rho[1], rho[2], rho[3]].map(f64::to_degrees))
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() {
        vec![128, 256, 400, 512]
    } else {
        sizes
    };
    // The generic vertex of patterns/degree4_native.json, and a second one folded by Newton
    // from near flat (its first crease driven to 120°, the other three following).
    let generic = (
        [70.0, 100.0, 120.0, 70.0],
        [120.0, -18.3905306410385, 123.57536812922761, 19.622908594655108],
        ['V', 'M', 'V', 'V'],
    );
    let second_sectors = [60.0, 100.0, 130.0, 70.0];
    let second = degree4_folded(second_sectors, 120.0).map(|folds| {
        let assignments = folds.map(|f: f64| if f >= 0.0 { 'V' } else { 'M' });
        (second_sectors, folds, assignments)
    });
    println!(
        "{:<18} {:>6} {:>5} {:>18} {:>9} {:>10}",
        "family", "rays", "seed", "verdict", "steps", "seconds"
    );
    let mut worst: (f64, String) = (0.0, String::new());
    for &n in &sizes {
        let mut cases: Vec<(String, u64, Option<String>)> = Vec::new();
        for seed in 1..=3 {
            cases.push(("seeded".into(), seed, seeded(n, 0.3, seed)));
            cases.push(("seeded_large".into(), seed, seeded(n, 0.75, seed)));
            cases.push((
                "few_folded".into(),
                seed,
                Some(few_folded(n, generic.0, generic.1, generic.2, seed)),
            ));
            cases.push((
                "few_folded_second".into(),
                seed,
                second.map(|(base, folds, assignments)| few_folded(n, base, folds, assignments, seed)),
            ));
        }
        cases.push(("fan".into(), 0, Some(fan(n))));
        for (family, seed, text) in cases {
            let Some(text) = text else {
                println!("{family:<18} {n:>6} {seed:>5} {:>18}", "no closed state");
                continue;
            };
            let pattern = match Pattern::parse(&text, &format!("{family}_{n}"), "generated", &LoadOptions::default()) {
                Ok(p) => p,
                Err(e) => {
                    println!("{family:<18} {n:>6} {seed:>5} refused: {e}");
                    continue;
                }
            };
            let started = Instant::now();
            let outcome = check(&pattern, &Settings::default());
            let seconds = started.elapsed().as_secs_f64();
            let (verdict, steps) = match &outcome {
                Ok(report) => (report.verdict.as_str().to_string(), report.steps),
                Err(e) => (format!("error: {e}"), 0),
            };
            println!("{family:<18} {n:>6} {seed:>5} {verdict:>18} {steps:>9} {seconds:>10.2}");
            if seconds > worst.0 {
                worst = (seconds, format!("{family}, {n} rays, seed {seed}: {verdict}"));
            }
        }
    }
    println!("worst: {:.2} s ({})", worst.0, worst.1);
}
