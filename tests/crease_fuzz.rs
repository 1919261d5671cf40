//! Mutated crease patterns of many vertices (numbers scaled, negated, zeroed, shifted;
//! letters swapped; an isolated or duplicated vertex, a far outlier, the whole file moved
//! or scaled to extremes, contradictory frames) through the whole chain — read, model,
//! check with its witness path, and the energy unfolding: every one is refused with an
//! error or runs to a verdict with finite numbers; nothing panics. A quarter of the cases
//! only move, turn or scale the file, and must keep the original's verdict and DOF.
//! Besides the bundled files, a 300-panel strip and a 2000-sided face are fuzzed.
//! `FUZZ_CASES` sets the count (default 400).

mod common;

use nanofold::folding::{check_pattern, CheckSettings, FoldingModel};
use nanofold::unfold::network::{unfold_network, NetworkUnfoldSettings};
use serde_json::Value;

fn next(seed: &mut u64) -> u64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    *seed >> 11
}

fn mutate(value: &mut Value, seed: &mut u64, depth: u64) {
    match value {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(0.0);
            let y = match next(seed) % 8 {
                0 => x * 1.0001,
                1 => -x,
                2 => 0.0,
                3 => x + 1e-7,
                4 => x * 1e6,
                5 => (next(seed) % 40) as f64,
                6 => x + 0.3,
                _ => x,
            };
            if let Some(m) = serde_json::Number::from_f64(y) {
                *value = Value::Number(m);
            }
        }
        Value::Array(items) => {
            for item in items.iter_mut() {
                if next(seed).is_multiple_of(8 + 8 * depth) || (depth < 3 && next(seed).is_multiple_of(20)) {
                    mutate(item, seed, depth + 1);
                }
            }
        }
        Value::String(s) if next(seed).is_multiple_of(3) => {
            *s = ["M", "V", "F", "B", "U", "C"][(next(seed) % 6) as usize].to_string();
        }
        _ => {}
    }
}

#[test]
fn mutated_crease_patterns_are_refused_or_run_without_panicking() {
    let cases: usize = std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400);
    let files = [
        "patterns/many/miura_4x4_folded.fold",
        "patterns/many/waterbomb_4x3.fold",
        "patterns/many/square_twist.fold",
        "patterns/many/strips_crossing.fold",
        "tests/fixtures/origami-simulator/simple_50.fold",
    ];
    let mut originals: Vec<Value> = files
        .iter()
        .map(|f| serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap())
        .collect();
    originals.push(common::strip_fold(300, 1.0, 1.0));
    originals.push(polygon(2000));
    let baselines: Vec<Option<(String, usize)>> = originals.iter().map(|v| verdict_of(v, 200)).collect();
    let mut seed = 12345_u64;
    let mut ran = 0;
    let mut placed = 0;
    for case in 0..cases {
        let index = case % originals.len();
        let mut value = originals[index].clone();
        if next(&mut seed).is_multiple_of(4) {
            // Only where the paper lies changes: the verdict must not.
            move_whole(&mut value, &mut seed);
            if let Some(expected) = &baselines[index] {
                let got = verdict_of(&value, 200);
                assert_eq!(got.as_ref(), Some(expected), "case {case}: {value}");
                placed += 1;
                ran += 1;
            }
            continue;
        }
        if next(&mut seed).is_multiple_of(3) {
            reshape(&mut value, &mut seed);
        }
        for key in [
            "vertices_coords",
            "edges_vertices",
            "edges_assignment",
            "edges_foldAngle",
            "faces_vertices",
        ] {
            if let Some(field) = value.get_mut(key) {
                if next(&mut seed).is_multiple_of(2) {
                    mutate(field, &mut seed, 0);
                }
            }
        }
        let text = value.to_string();
        let Ok(pattern) = nanofold::read::parse_crease_pattern(&text, "fuzz", "fuzz") else {
            continue;
        };
        let Ok(model) = FoldingModel::new(pattern) else {
            continue;
        };
        let mut settings = CheckSettings::default();
        settings.path.max_steps = 200;
        let Ok(report) = check_pattern(&model, &settings) else {
            continue;
        };
        assert!(report.max_vertex_residual_rad.is_finite(), "case {case}: {text}");
        let unfolded = NetworkUnfoldSettings {
            max_iterations: 200,
            ..NetworkUnfoldSettings::default()
        };
        if let Ok(run) = unfold_network(&model, &model.given_fold_angles(), &unfolded) {
            let last = run.steps.last().unwrap();
            assert!(last.fold_angles.iter().all(|r| r.is_finite()), "case {case}: {text}");
        }
        ran += 1;
    }
    // The mutations must reach the checks, not only the reader.
    assert!(ran * 5 >= cases, "only {ran} of {cases} cases ran");
    assert!(
        placed * 8 >= cases,
        "only {placed} of {cases} cases compared placements"
    );
}

/// `check`'s verdict and DOF of a FOLD object (None when refused).
fn verdict_of(value: &Value, max_steps: usize) -> Option<(String, usize)> {
    let pattern = nanofold::read::parse_crease_pattern(&value.to_string(), "fuzz", "fuzz").ok()?;
    let model = FoldingModel::new(pattern).ok()?;
    let mut settings = CheckSettings::default();
    settings.path.max_steps = max_steps;
    let report = check_pattern(&model, &settings).ok()?;
    Some((format!("{:?}", report.verdict), report.rank.dof))
}

fn coords(value: &Value) -> Vec<Vec<f64>> {
    serde_json::from_value(value["vertices_coords"].clone()).unwrap_or_default()
}

/// Moves, turns (about z) or scales the whole file, to extremes the reader admits.
fn move_whole(value: &mut Value, seed: &mut u64) {
    let points = coords(value);
    let unit = |seed: &mut u64| (next(seed) % 2001) as f64 / 1000.0 - 1.0;
    let (a, b) = (unit(seed), unit(seed));
    let moved: Vec<Vec<f64>> = match next(seed) % 3 {
        0 => {
            let shift = 10f64.powi((next(seed) % 9) as i32);
            points
                .iter()
                .map(|p| {
                    p.iter()
                        .enumerate()
                        .map(|(k, x)| x + shift * [a, b, a * b][k])
                        .collect()
                })
                .collect()
        }
        1 => {
            let (c, s) = (a * std::f64::consts::PI).sin_cos();
            points
                .iter()
                .map(|p| {
                    let mut q = p.clone();
                    q[0] = c * p[0] - s * p[1];
                    q[1] = s * p[0] + c * p[1];
                    q
                })
                .collect()
        }
        _ => {
            let factor = 10f64.powi(-((next(seed) % 100) as i32));
            points.iter().map(|p| p.iter().map(|x| x * factor).collect()).collect()
        }
    };
    value["vertices_coords"] = serde_json::json!(moved);
}

/// One structural change: an isolated vertex, a vertex duplicated under an edge, a far
/// outlier, or a second frame that contradicts the first.
fn reshape(value: &mut Value, seed: &mut u64) {
    let mut points = coords(value);
    if points.is_empty() {
        return;
    }
    let pick = (next(seed) as usize) % points.len();
    match next(seed) % 4 {
        0 => points.push(points[pick].iter().map(|x| x + 0.25).collect()),
        1 => {
            points.push(points[pick].clone());
            let copy = points.len() - 1;
            if let Some(edges) = value["edges_vertices"].as_array_mut() {
                if let Some(edge) = edges.iter_mut().find(|e| e[0] == pick || e[1] == pick) {
                    let slot = if edge[0] == pick { 0 } else { 1 };
                    edge[slot] = copy.into();
                }
            }
        }
        2 => points[pick] = points[pick].iter().map(|x| x + 1e6).collect(),
        _ => {
            let fewer: Vec<Vec<f64>> = points.iter().skip(1).cloned().collect();
            value["file_frames"] = serde_json::json!([{"frame_classes": ["foldedForm"], "vertices_coords": fewer}]);
        }
    }
    value["vertices_coords"] = serde_json::json!(points);
}

/// A regular polygon of `sides` sides with one valley across it.
fn polygon(sides: usize) -> Value {
    let points: Vec<[f64; 2]> = (0..sides)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / sides as f64;
            [a.cos(), a.sin()]
        })
        .collect();
    let mut edges: Vec<[usize; 2]> = (0..sides).map(|k| [k, (k + 1) % sides]).collect();
    let mut letters = vec!["B"; sides];
    edges.push([0, sides / 2]);
    letters.push("V");
    serde_json::json!({"file_spec": 1.1, "vertices_coords": points, "edges_vertices": edges, "edges_assignment": letters})
}
