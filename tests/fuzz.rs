//! Fuzzing the importers and what runs after them (FOLD, native vertex, scene): random byte
//! and JSON mutations of every bundled file (leaves replaced by extreme, non-ASCII or
//! wrongly typed values, keys deleted, optional keys added) must give a result or a clear
//! error, never a panic or a NaN. What loads is run with small budgets: patterns are
//! unfolded (at most 150 iterations), scenes simulated (at most 3000 steps), and every
//! number they report must be finite.
//!
//! The default test run tries 256 cases per property (`FUZZ_CASES` or `PROPTEST_CASES`
//! overrides it); the long run is `FUZZ_CASES=100000 cargo test --release --test fuzz`
//! (README, "Limits", gives its last result).

use nanofold::dynamics::modes::modes;
use nanofold::dynamics::simulate::{simulate_scene, SimulationSettings};
use nanofold::pattern::LoadOptions;
use nanofold::unfold::{unfold, UnfoldSettings};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, TestRunner};
use serde_json::Value;

fn cases() -> u32 {
    ["FUZZ_CASES", "PROPTEST_CASES"]
        .iter()
        .find_map(|key| std::env::var(key).ok()?.parse().ok())
        .unwrap_or(256)
}

fn bundled(extension_filter: fn(&str) -> bool) -> Vec<String> {
    let mut paths: Vec<String> = std::fs::read_dir("patterns")
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path().display().to_string()))
        .filter(|p| extension_filter(p))
        .collect();
    paths.sort();
    paths.iter().map(|p| std::fs::read_to_string(p).unwrap()).collect()
}

fn patterns() -> Vec<String> {
    bundled(|p| (p.ends_with(".fold") || p.ends_with(".json")) && !p.ends_with(".scene.json"))
}

fn scenes() -> Vec<String> {
    bundled(|p| p.ends_with(".scene.json"))
}

/// How far a fuzzed input got.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Outcome {
    /// Refused with an error at loading or building.
    Refused,
    /// Loaded, then its run ended in an error (a budget, a numerical failure).
    RunFailed,
    /// Loaded and ran to a result.
    Ran,
}

fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// A pattern that loads must be usable (finite angles) and unfold, within a small budget,
/// to a verdict with finite numbers, or fail with a message.
fn run_pattern(text: &str) -> Outcome {
    let Ok(pattern) = nanofold::read::parse_pattern(text, "fuzz", "fuzz", &LoadOptions::default()) else {
        return Outcome::Refused;
    };
    assert!(pattern.sector_angles.iter().all(|a| a.is_finite() && *a > 0.0));
    assert!(pattern.creases.iter().all(|c| c.folded_angle.is_finite()));
    assert!(pattern.closure_residual.is_finite());
    let settings = UnfoldSettings {
        max_iterations: 150,
        restarts: 1,
        ..Default::default()
    };
    match unfold(&pattern, &settings) {
        Ok(report) => {
            assert!(all_finite(&report.final_fold_angles_rad), "{report:?}");
            assert!(report.energy_final.is_finite() && report.max_arc_residual.is_finite());
            assert!(!report.evidence.is_empty());
            Outcome::Ran
        }
        Err(e) => {
            assert!(!e.to_string().is_empty());
            Outcome::RunFailed
        }
    }
}

/// A scene that loads must give a finite model with finite modes, and simulate, within a
/// small step budget, to finite samples and a contact inside the run, or fail with a message.
fn run_scene(text: &str) -> Outcome {
    let built =
        nanofold::read::parse_scene(text, "fuzz", "fuzz", std::path::Path::new("patterns")).and_then(|s| s.build());
    let Ok(scene) = built else {
        return Outcome::Refused;
    };
    if let Some(chain) = scene.strip() {
        let model = &chain.model;
        assert!(model
            .joints()
            .iter()
            .all(|j| j.stiffness.is_finite() && j.stiffness > 0.0));
        assert!(model.plates().iter().all(|p| p.mass.is_finite() && p.mass > 0.0));
        if let Ok(m) = modes(model, chain.target_angles().as_slice()) {
            assert!(m.eigenvalues.iter().all(|l| l.is_finite()));
        }
    }
    let settings = SimulationSettings {
        max_steps: 3000,
        ..Default::default()
    };
    match simulate_scene(&scene, &settings) {
        Ok(simulation) => {
            let response = &simulation.response;
            for sample in &response.samples {
                assert!(
                    sample.time.is_finite() && all_finite(sample.angles.as_slice()),
                    "{sample:?}"
                );
                assert!(all_finite(sample.rates.as_slice()), "{sample:?}");
            }
            if let Some(c) = &response.collision {
                assert!(c.time.is_finite() && c.time >= 0.0 && c.time <= scene.t_end * (1.0 + 1e-12));
                assert!(c.point.iter().all(|x| x.is_finite()));
            }
            Outcome::Ran
        }
        Err(e) => {
            assert!(!e.to_string().is_empty());
            Outcome::RunFailed
        }
    }
}

#[derive(Debug, Clone)]
enum ByteEdit {
    Flip(usize, u8),
    Delete(usize, usize),
    Insert(usize, Vec<u8>),
    Truncate(usize),
}

fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| ByteEdit::Flip(i, b)),
        (any::<usize>(), 1usize..16).prop_map(|(i, n)| ByteEdit::Delete(i, n)),
        (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..8)).prop_map(|(i, b)| ByteEdit::Insert(i, b)),
        any::<usize>().prop_map(ByteEdit::Truncate),
    ]
}

fn apply(text: &str, edits: &[ByteEdit]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for edit in edits {
        let len = bytes.len().max(1);
        match edit {
            ByteEdit::Flip(i, b) => {
                if !bytes.is_empty() {
                    bytes[i % len] = *b;
                }
            }
            ByteEdit::Delete(i, n) => {
                let start = i % len;
                let end = (start + n).min(bytes.len());
                bytes.drain(start.min(bytes.len())..end);
            }
            ByteEdit::Insert(i, b) => {
                let at = i % (bytes.len() + 1);
                bytes.splice(at..at, b.iter().copied());
            }
            ByteEdit::Truncate(i) => bytes.truncate(i % len),
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// A replacement for one JSON leaf: extreme, nearby and wrongly typed numbers, non-ASCII
/// and long strings, nothing.
fn leaf() -> impl Strategy<Value = Value> {
    prop_oneof![
        any::<f64>()
            .prop_filter("JSON has no NaN/inf", |x| x.is_finite())
            .prop_map(Value::from),
        prop_oneof![
            Just(0.0),
            Just(-1.0),
            Just(1e-300),
            Just(1e300),
            Just(1.7e308),
            Just(-1.7e308),
            Just(180.0),
            Just(-180.0001),
            Just(0.5),
            Just(1e-9),
            Just(1e9),
        ]
        .prop_map(Value::from),
        // Small changes of a typical value keep many scenes loadable, so they run.
        (0.5f64..2.0).prop_map(|x| Value::from((x * 100.0).round() / 10.0)),
        any::<i64>().prop_map(Value::from),
        prop_oneof![Just(u64::MAX), Just(1u64 << 40), Just(100_001), Just(3)].prop_map(Value::from),
        Just(Value::Null),
        Just(Value::Bool(true)),
        "[a-zA-Z_]{0,8}".prop_map(Value::from),
        "[é∂∑😀\u{0}/.]{0,12}".prop_map(Value::from),
        Just(Value::from("x".repeat(5000))),
        Just(Value::Array(vec![])),
        Just(serde_json::json!({})),
    ]
}

/// Keys the bundled files may lack (optional ones) or misspell, to add at any object.
const KEYS: &[&str] = &[
    "name",
    "description",
    "locked",
    "edges_nanofold:locked",
    "faces_vertices",
    "frame_classes",
    "anchored_face",
    "start_angle_deg",
    "cut_crease",
    "locks",
    "samples",
    "snapshots",
    "range_deg",
    "degree",
    "source",
    "drag",
    "drag_coefficient",
    "air_density_kg_m3",
    "radius_of_curvature_um",
    "target_angle_deg",
    "substrate",
    "edge_y_um",
    "outputs",
    "length_unit_um",
    "etch_rate_um_per_min",
    "t_end_s",
    "kind",
    "unknown_key",
];

#[derive(Debug, Clone)]
enum Mutation {
    /// Replace the n-th leaf.
    Replace(usize, Value),
    /// Delete the n-th key.
    Delete(usize),
    /// Add (or overwrite) a key at the n-th object.
    Add(usize, &'static str, Value),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        5 => (any::<usize>(), leaf()).prop_map(|(i, v)| Mutation::Replace(i, v)),
        1 => any::<usize>().prop_map(Mutation::Delete),
        2 => (any::<usize>(), prop::sample::select(KEYS), leaf()).prop_map(|(i, k, v)| Mutation::Add(i, k, v)),
    ]
}

/// Visits the leaves (Replace), the keys (Delete) or the objects (Add) in document order
/// and applies the mutation at the `pick`-th one.
fn mutate(value: &mut Value, pick: &mut usize, mutation: &Mutation) -> bool {
    match value {
        Value::Object(map) => {
            if let Mutation::Add(_, key, with) = mutation {
                if *pick == 0 {
                    map.insert(key.to_string(), with.clone());
                    return true;
                }
                *pick -= 1;
            }
            let keys: Vec<String> = map.keys().cloned().collect();
            for key in keys {
                if let Mutation::Delete(_) = mutation {
                    if *pick == 0 {
                        map.remove(&key);
                        return true;
                    }
                    *pick -= 1;
                }
                if mutate(map.get_mut(&key).unwrap(), pick, mutation) {
                    return true;
                }
            }
            false
        }
        Value::Array(items) => items.iter_mut().any(|item| mutate(item, pick, mutation)),
        leaf => {
            if let Mutation::Replace(_, with) = mutation {
                if *pick == 0 {
                    *leaf = with.clone();
                    return true;
                }
                *pick -= 1;
            }
            false
        }
    }
}

fn json_mutation(text: &str, mutations: &[Mutation]) -> String {
    let mut value: Value = serde_json::from_str(text).unwrap();
    for m in mutations {
        let (Mutation::Replace(pick, _) | Mutation::Delete(pick) | Mutation::Add(pick, _, _)) = m;
        let mut index = *pick % 400;
        mutate(&mut value, &mut index, m);
    }
    value.to_string()
}

fn mutations() -> impl Strategy<Value = Vec<Mutation>> {
    proptest::collection::vec(mutation(), 1..4)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn mutated_pattern_bytes_never_panic(file in any::<prop::sample::Index>(), edits in proptest::collection::vec(byte_edit(), 1..5)) {
        let texts = patterns();
        run_pattern(&apply(&texts[file.index(texts.len())], &edits));
    }

    #[test]
    fn mutated_pattern_values_never_panic(file in any::<prop::sample::Index>(), mutations in mutations()) {
        let texts = patterns();
        run_pattern(&json_mutation(&texts[file.index(texts.len())], &mutations));
    }

    #[test]
    fn mutated_scene_bytes_never_panic(file in any::<prop::sample::Index>(), edits in proptest::collection::vec(byte_edit(), 1..5)) {
        let texts = scenes();
        run_scene(&apply(&texts[file.index(texts.len())], &edits));
    }

    #[test]
    fn mutated_scene_values_never_panic(file in any::<prop::sample::Index>(), mutations in mutations()) {
        let texts = scenes();
        run_scene(&json_mutation(&texts[file.index(texts.len())], &mutations));
    }
}

/// The fuzzer must reach runs, not only loading: over a fixed sample of value mutations,
/// count how far inputs get.
#[test]
fn value_mutations_reach_runs() {
    let mut runner = TestRunner::new(Config {
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        ..Config::default()
    });
    let (pattern_texts, scene_texts) = (patterns(), scenes());
    let strategy = (any::<prop::sample::Index>(), mutations());
    let mut counts = std::collections::BTreeMap::new();
    for _ in 0..40 {
        let (file, mutations) = strategy.new_tree(&mut runner).unwrap().current();
        let scene = run_scene(&json_mutation(&scene_texts[file.index(scene_texts.len())], &mutations));
        let pattern = run_pattern(&json_mutation(
            &pattern_texts[file.index(pattern_texts.len())],
            &mutations,
        ));
        *counts.entry(("scene", scene)).or_insert(0) += 1;
        *counts.entry(("pattern", pattern)).or_insert(0) += 1;
    }
    let ran = |kind| counts.get(&(kind, Outcome::Ran)).copied().unwrap_or(0);
    eprintln!("{counts:?}");
    assert!(ran("scene") >= 5, "too few mutated scenes ran: {counts:?}");
    assert!(ran("pattern") >= 10, "too few mutated patterns ran: {counts:?}");
}
