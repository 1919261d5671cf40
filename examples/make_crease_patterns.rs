//! Writes the crease patterns of many vertices in `patterns/many/`, each built from the
//! generators (and, for the broken ones, changed in one stated way).
//!
//! Run: `cargo run --release --example make_crease_patterns`

use nanofold::folding::{degree4_modes, FoldingModel};
use nanofold::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind};
use nanofold::pattern::generate::{BirdBaseSpec, MiuraSpec, SquareTwistSpec, WaterbombSpec};
use nanofold::pattern::Assignment;
use nanofold::write::crease_pattern_fold;

fn write(name: &str, builder: CreasePatternBuilder, with_state: bool, note: &str) {
    let model = FoldingModel::new(builder.build().unwrap()).unwrap();
    let state = with_state.then(|| model.given_fold_angles());
    let value = crease_pattern_fold(&model.pattern, state.as_deref(), note);
    let path = format!("patterns/many/{name}.fold");
    std::fs::write(&path, serde_json::to_string_pretty(&value).unwrap()).unwrap();
    println!("wrote {path}: {note}");
}

fn miura(zigzag_deg: f64) -> CreasePatternBuilder {
    MiuraSpec {
        zigzag_fold_angle: zigzag_deg.to_radians(),
        ..MiuraSpec::default()
    }
    .build()
    .unwrap()
}

fn main() {
    std::fs::create_dir_all("patterns/many").unwrap();
    write(
        "miura_4x4",
        miura(0.0),
        false,
        "Miura-ori 4 x 4, 60 deg, assignment only",
    );
    write(
        "miura_4x4_folded",
        miura(100.0),
        true,
        "Miura-ori 4 x 4, zigzag creases at 100 deg (closed form)",
    );

    // One interior zigzag crease bent by 5 degrees: its two vertices no longer close.
    let mut bent = miura(100.0);
    let model = FoldingModel::new(bent.clone().build().unwrap()).unwrap();
    let star = &model.stars[model.stars.len() / 2];
    let edge = model.pattern.creases[star.columns[1]];
    bent.fold_angles[edge] += 5f64.to_radians().copysign(bent.fold_angles[edge]);
    write(
        "miura_4x4_bent",
        bent,
        true,
        &format!("Miura-ori 4 x 4 at 100 deg with edge {edge} turned 5 deg further: needs bending"),
    );

    // At a corner vertex, the creases it shares with no other vertex changed so that it
    // still has three creases of one kind (Maekawa) but an assignment no folding mode has.
    let mut bad = miura(0.0);
    let model = FoldingModel::new(bad.clone().build().unwrap()).unwrap();
    let sign_of = |kind: EdgeKind| {
        if kind == EdgeKind::Crease(Assignment::Valley) {
            1.0
        } else {
            -1.0
        }
    };
    let (vertex, changes) = model
        .stars
        .iter()
        .find_map(|star| {
            let own: Vec<usize> = (0..4)
                .filter(|&k| {
                    model
                        .stars
                        .iter()
                        .filter(|s| s.columns.contains(&star.columns[k]))
                        .count()
                        == 1
                })
                .collect();
            let modes = degree4_modes(star)?;
            let original: Vec<f64> = star
                .columns
                .iter()
                .map(|&c| sign_of(model.pattern.kinds[model.pattern.creases[c]]))
                .collect();
            (1..(1usize << own.len())).find_map(|mask| {
                let mut signs = original.clone();
                for (bit, &k) in own.iter().enumerate() {
                    if mask & (1 << bit) != 0 {
                        signs[k] = -signs[k];
                    }
                }
                let valleys = signs.iter().filter(|&&x| x > 0.0).count();
                let maekawa = valleys == 1 || valleys == 3;
                let is_mode = modes.iter().any(|m| m.iter().zip(&signs).all(|(a, b)| a * b > 0.0));
                (maekawa && !is_mode).then(|| {
                    let edges: Vec<(usize, f64)> = (0..4)
                        .filter(|&k| signs[k] != original[k])
                        .map(|k| (model.pattern.creases[star.columns[k]], signs[k]))
                        .collect();
                    (star.vertex, edges)
                })
            })
        })
        .expect("a corner vertex of the Miura-ori can be reassigned alone");
    for &(edge, sign) in &changes {
        bad.kinds[edge] = EdgeKind::Crease(if sign > 0.0 {
            Assignment::Valley
        } else {
            Assignment::Mountain
        });
    }
    let edges: Vec<usize> = changes.iter().map(|c| c.0).collect();
    write(
        "miura_4x4_bad_vertex",
        bad,
        false,
        &format!("Miura-ori 4 x 4 with edges {edges:?} (at vertex {vertex}, shared with no other vertex) reassigned: still three of one kind, but in no folding mode"),
    );

    // The Miura-ori's single vertex with the odd crease moved to a place no mode allows.
    let single = MiuraSpec {
        rows: 2,
        cols: 2,
        ..MiuraSpec::default()
    }
    .build()
    .unwrap();
    let model = FoldingModel::new(single.clone().build().unwrap()).unwrap();
    let star = &model.stars[0];
    let modes = degree4_modes(star).unwrap();
    let mut alone = single;
    'search: for odd in 0..4 {
        for sign in [1.0, -1.0] {
            let pattern: Vec<f64> = (0..4).map(|k| if k == odd { -sign } else { sign }).collect();
            let is_mode = modes.iter().any(|m| m.iter().zip(&pattern).all(|(a, b)| a * b > 0.0));
            if !is_mode {
                for (k, &c) in star.columns.iter().enumerate() {
                    let assignment = if pattern[k] > 0.0 {
                        Assignment::Valley
                    } else {
                        Assignment::Mountain
                    };
                    alone.kinds[model.pattern.creases[c]] = EdgeKind::Crease(assignment);
                }
                break 'search;
            }
        }
    }
    write(
        "degree4_bad_assignment",
        alone,
        false,
        "one Miura vertex (2 x 2 Miura-ori) with three creases of one kind but the odd one where no folding mode has it",
    );

    write(
        "square_twist",
        SquareTwistSpec::default().build().unwrap(),
        false,
        "square twist, 30 deg, classic assignment",
    );
    write(
        "square_twist_flipped",
        SquareTwistSpec {
            flip_pleats: true,
            ..SquareTwistSpec::default()
        }
        .build()
        .unwrap(),
        false,
        "square twist, 30 deg, each corner's crease after its smallest sector flipped",
    );
    write(
        "waterbomb_4x3",
        WaterbombSpec {
            rows: 4,
            cols: 3,
            row_height: 1.0,
        }
        .build()
        .unwrap(),
        false,
        "waterbomb tessellation 4 x 3",
    );
    write(
        "huffman_waterbomb_6x4",
        WaterbombSpec {
            rows: 6,
            cols: 4,
            row_height: 0.6,
        }
        .build()
        .unwrap(),
        false,
        "Huffman-style rectangular waterbomb 6 x 4, rows 0.6 high (diagonals at 31 deg)",
    );
    write(
        "bird_base",
        BirdBaseSpec::default().build().unwrap(),
        false,
        "bird base, flat-foldable assignment, square of side 2",
    );

    // Three strips, both outer ones folded up by 170 degrees: they pass through each other
    // above the middle strip.
    let vertices = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [2.0, 0.0],
        [3.0, 0.0],
        [3.0, 1.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [0.0, 1.0],
    ];
    let mut edges = vec![[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [6, 7], [7, 0]];
    let mut kinds = vec![EdgeKind::Boundary; 8];
    let mut fold_angles = vec![0.0; 8];
    for edge in [[1, 6], [2, 5]] {
        edges.push(edge);
        kinds.push(EdgeKind::Crease(Assignment::Valley));
        fold_angles.push(170f64.to_radians());
    }
    let strips = CreasePatternBuilder {
        name: "strips_crossing".into(),
        vertices,
        edges,
        kinds,
        fold_angles,
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    write(
        "strips_crossing",
        strips,
        true,
        "three strips, both outer ones valley-folded by 170 deg over the middle one",
    );
}
