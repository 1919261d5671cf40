//! Fully folded single vertices of degree 4 to 12 (every crease at ±180°): the single-vertex
//! engine's unfolding, and the many-vertex engine's path from flat onto the folded state
//! (`fold --drive-to-targets`, reversed: an unfolding witness), side by side with their
//! times. Each vertex is flat-foldable with seeded sectors (alternate sums π) and an
//! assignment made by crimping the smallest sector again and again (Hull), so it folds flat.
//! Run: `cargo run --release --example flat_folded_vertices`

use nanofold::folding::{fold_path, Drive, FoldSettings};
use nanofold::prelude::*;
use std::f64::consts::PI;

/// Sectors and the fully folded fold angles of a flat-foldable vertex of even degree `n`.
fn flat_foldable(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut state = seed;
    let mut draw = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut halves: [Vec<f64>; 2] = [
        (0..n / 2).map(|_| 0.3 + draw()).collect(),
        (0..n / 2).map(|_| 0.3 + draw()).collect(),
    ];
    for half in &mut halves {
        let total: f64 = half.iter().sum();
        half.iter_mut().for_each(|x| *x *= PI / total);
    }
    let sectors: Vec<f64> = (0..n).map(|k| halves[k % 2][k / 2]).collect();
    // Crimp the smallest sector (sector i follows crease i): its creases fold opposite ways,
    // and the three sectors about it become one.
    let (mut creases, mut after): (Vec<usize>, Vec<f64>) = ((0..n).collect(), sectors.clone());
    let mut sign = vec![0.0; n];
    let mut turn = if draw() < 0.5 { 1.0 } else { -1.0 };
    while creases.len() > 2 {
        let m = creases.len();
        let k = (0..m)
            .min_by(|&a, &b| after[a].total_cmp(&after[b]))
            .expect("creases left");
        let (previous, next) = ((k + m - 1) % m, (k + 1) % m);
        sign[creases[k]] = turn;
        sign[creases[next]] = -turn;
        turn = -turn;
        after[previous] += after[next] - after[k];
        let keep = |i: &usize| *i != k && *i != next;
        creases = (0..m).filter(keep).map(|i| creases[i]).collect();
        after = (0..m).filter(keep).map(|i| after[i]).collect();
    }
    let last = if draw() < 0.5 { 1.0 } else { -1.0 };
    sign[creases[0]] = last;
    sign[creases[1]] = last;
    (sectors, sign.iter().map(|s| s * PI).collect())
}

fn main() -> Result<()> {
    println!("degree seed | energy unfolding            | path from flat onto the folded state");
    for n in [4, 6, 8, 10, 12] {
        for seed in 1..=4u64 {
            let (sectors, folded) = flat_foldable(n, seed * 7919 + n as u64);
            let vertex = folded
                .iter()
                .fold(
                    VertexBuilder::closed("flat-folded").sector_angles(sectors.clone()),
                    |b, &r| {
                        b.crease(
                            if r > 0.0 {
                                Assignment::Valley
                            } else {
                                Assignment::Mountain
                            },
                            r,
                        )
                    },
                )
                .build()?;
            let clock = std::time::Instant::now();
            let unfolded = unfold_vertex(&vertex, &UnfoldSettings::default())?;
            let energy_time = clock.elapsed().as_secs_f64();
            let pattern = nanofold::commands::Pattern::from(vertex);
            let sheet = pattern.sheet().expect("a closed vertex has its sheet");
            let settings = FoldSettings {
                drive: Drive::Targets {
                    targets: folded.clone(),
                    to: 100.0,
                },
                ..FoldSettings::default()
            };
            let clock = std::time::Instant::now();
            let path = fold_path(sheet, &vec![0.0; folded.len()], &settings)?;
            let path_time = clock.elapsed().as_secs_f64();
            let end = &path.steps.last().expect("a path has its start").fold_angles;
            let gap = end.iter().zip(&folded).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            println!(
                "{n:>6} {seed:>4} | {:<14} {:>9.3} ms | {:<12} {:>9.3} ms, {:.1e} rad from it",
                unfolded.verdict.as_str(),
                1e3 * energy_time,
                path.stop.as_str(),
                1e3 * path_time,
                gap
            );
        }
    }
    Ok(())
}
