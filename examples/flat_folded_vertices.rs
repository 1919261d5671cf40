//! Fully folded single vertices of degree 4 to 12 (every crease at ±180°,
//! `pattern::generate::flat_folded_vertex`): the energy descent alone, then what `unfold`
//! answers (the descent, or where it stops short, the reversed rigid folding path from flat
//! onto the folded state), each with its time.
//! Run: `cargo run --release --example flat_folded_vertices`

use nanofold::pattern::generate::flat_folded_vertex;
use nanofold::prelude::*;
use std::time::Instant;

fn main() -> Result<()> {
    println!("degree seed | energy descent alone      | unfold");
    let (mut descended, mut unfolded, mut cases) = (0, 0, 0);
    for degree in [4, 6, 8, 10, 12] {
        for seed in 1..=4u64 {
            let (sectors, folded) = flat_folded_vertex(degree, seed * 7919 + degree as u64)?;
            let vertex = folded
                .iter()
                .fold(VertexBuilder::closed("flat-folded").sector_angles(sectors), |b, &r| {
                    b.crease(
                        if r > 0.0 {
                            Assignment::Valley
                        } else {
                            Assignment::Mountain
                        },
                        r,
                    )
                })
                .build()?;
            let clock = Instant::now();
            let energy = unfold_vertex(&vertex, &UnfoldSettings::default())?;
            let energy_ms = 1e3 * clock.elapsed().as_secs_f64();
            let clock = Instant::now();
            let answer = nanofold::commands::unfold(&Pattern::from(vertex), &Settings::default())?;
            let answer_ms = 1e3 * clock.elapsed().as_secs_f64();
            cases += 1;
            descended += usize::from(energy.verdict == UnfoldVerdict::Flat);
            unfolded += usize::from(answer.verdict == UnfoldVerdict::Flat);
            println!(
                "{degree:>6} {seed:>4} | {:<14} {:>8.2} ms | {:<14} {:>8.2} ms",
                energy.verdict.as_str(),
                energy_ms,
                answer.verdict.as_str(),
                answer_ms
            );
        }
    }
    println!("flat: {descended} of {cases} by the descent alone, {unfolded} of {cases} by unfold");
    Ok(())
}
