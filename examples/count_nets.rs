//! Counts every edge unfolding of the Platonic solids and the distinct nets among them
//! (orbits under the solid's symmetry group, found from its geometry), with the time each
//! took; the tabulated counts are 2, 11, 11, 43 380 and 43 380 (`docs/model.md#nets-of-polyhedra`).
//! Then lays every hundredth tree flat (every tree of the small three) and counts those
//! whose faces overlap (none, for these solids).
//!
//! `cargo run --release --example count_nets`

use nanofold::geometry::nets::lay_flat;
use nanofold::geometry::solids;
use nanofold::geometry::unfoldings::{distinct_nets, edge_map, spanning_trees};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cases = [
        ("tetrahedron", solids::tetrahedron()?, 2),
        ("cube", solids::cube()?, 11),
        ("octahedron", solids::octahedron()?, 11),
        ("dodecahedron", solids::dodecahedron()?, 43_380),
        ("icosahedron", solids::icosahedron()?, 43_380),
    ];
    for (name, solid, tabulated) in cases {
        let clock = Instant::now();
        let trees = spanning_trees(&solid, 10_000_000)?;
        let enumerated = clock.elapsed().as_secs_f64();
        let symmetries = solid.symmetries();
        let maps: Vec<Vec<usize>> = symmetries.iter().map(|s| edge_map(&solid, s)).collect();
        let nets = distinct_nets(&trees, &maps);
        println!(
            "{name}: {} trees (matrix-tree {}) in {enumerated:.2} s; |group| {}; {nets} nets (tabulated {tabulated}) in {:.2} s",
            trees.len(),
            solid.spanning_tree_count(),
            symmetries.len(),
            clock.elapsed().as_secs_f64() - enumerated
        );
        let clock = Instant::now();
        let stride = if trees.len() > 1_000 { 100 } else { 1 };
        let laid: Vec<_> = trees.iter().step_by(stride).map(|&t| lay_flat(&solid, t)).collect();
        let overlapping = laid.iter().filter(|net| !net.overlapping_pairs().is_empty()).count();
        let which = if stride == 1 {
            "every tree".to_string()
        } else {
            format!("every {stride}th tree")
        };
        println!(
            "  laid flat: {overlapping} of {} ({which}) overlap ({:.2} s)",
            laid.len(),
            clock.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
