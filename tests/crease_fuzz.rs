//! Mutated crease patterns of many vertices (numbers scaled, negated, zeroed, shifted;
//! letters swapped) through the whole chain — read, model, check with its witness path, and
//! the energy unfolding: every one is refused with an error or runs to a verdict with finite
//! numbers; nothing panics. `FUZZ_CASES` sets the count (default 400).

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
    let originals: Vec<Value> = files
        .iter()
        .map(|f| serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap())
        .collect();
    let mut seed = 12345_u64;
    let mut ran = 0;
    for case in 0..cases {
        let mut value = originals[case % files.len()].clone();
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
        let Ok(pattern) = nanofold::io::parse_crease_pattern(&text, "fuzz", "fuzz") else {
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
}
