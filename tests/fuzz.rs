//! Fuzzing the importers (FOLD, native vertex, scene): random byte and JSON mutations of every
//! bundled file must give a pattern/scene or a clear error — never a panic, never NaN.
//!
//! The default test run tries proptest's default number of cases (256 per property); the
//! long run is `PROPTEST_CASES=100000 cargo test --release --test fuzz`.

use nanofold::dynamics::modes::modes;
use nanofold::pattern::LoadOptions;
use proptest::prelude::*;
use serde_json::Value;

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

/// A pattern that loads must be usable: finite sector and fold angles.
fn check_pattern(text: &str) {
    if let Ok(pattern) = nanofold::io::parse_pattern(text, "fuzz", "fuzz", &LoadOptions::default()) {
        assert!(pattern.sector_angles.iter().all(|a| a.is_finite() && *a > 0.0));
        assert!(pattern.creases.iter().all(|c| c.folded_angle.is_finite()));
        assert!(pattern.closure_residual.is_finite());
    }
}

/// A scene that loads must give a finite model, and its modes must be finite.
fn check_scene(text: &str) {
    let built =
        nanofold::io::parse_scene(text, "fuzz", "fuzz", std::path::Path::new("patterns")).and_then(|s| s.build());
    if let Ok(scene) = built {
        let Some(chain) = scene.strip() else { return };
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

/// A replacement for one JSON leaf: extreme numbers, wrong types, nothing.
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
            Just(180.0),
            Just(-180.0001),
            Just(0.5)
        ]
        .prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        Just(Value::Null),
        Just(Value::Bool(true)),
        "[a-zA-Z_]{0,8}".prop_map(Value::from),
        Just(Value::Array(vec![])),
        Just(serde_json::json!({})),
    ]
}

/// Replaces the `pick`-th leaf (in document order) by `with`, or deletes the `pick`-th key.
fn mutate(value: &mut Value, pick: &mut usize, with: &Value, delete: bool) -> bool {
    match value {
        Value::Object(map) => {
            let keys: Vec<String> = map.keys().cloned().collect();
            for key in keys {
                if delete {
                    if *pick == 0 {
                        map.remove(&key);
                        return true;
                    }
                    *pick -= 1;
                }
                if mutate(map.get_mut(&key).unwrap(), pick, with, delete) {
                    return true;
                }
            }
            false
        }
        Value::Array(items) => items.iter_mut().any(|item| mutate(item, pick, with, delete)),
        leaf => {
            if delete {
                return false;
            }
            if *pick == 0 {
                *leaf = with.clone();
                return true;
            }
            *pick -= 1;
            false
        }
    }
}

fn json_mutation(text: &str, picks: &[(usize, Value, bool)]) -> String {
    let mut value: Value = serde_json::from_str(text).unwrap();
    for (pick, with, delete) in picks {
        let mut index = *pick % 400;
        mutate(&mut value, &mut index, with, *delete);
    }
    value.to_string()
}

fn picks() -> impl Strategy<Value = Vec<(usize, Value, bool)>> {
    proptest::collection::vec((any::<usize>(), leaf(), proptest::bool::weighted(0.2)), 1..4)
}

proptest! {
    #[test]
    fn mutated_pattern_bytes_never_panic(file in any::<prop::sample::Index>(), edits in proptest::collection::vec(byte_edit(), 1..5)) {
        let texts = patterns();
        check_pattern(&apply(&texts[file.index(texts.len())], &edits));
    }

    #[test]
    fn mutated_pattern_values_never_panic(file in any::<prop::sample::Index>(), picks in picks()) {
        let texts = patterns();
        check_pattern(&json_mutation(&texts[file.index(texts.len())], &picks));
    }

    #[test]
    fn mutated_scene_bytes_never_panic(file in any::<prop::sample::Index>(), edits in proptest::collection::vec(byte_edit(), 1..5)) {
        let texts = scenes();
        check_scene(&apply(&texts[file.index(texts.len())], &edits));
    }

    #[test]
    fn mutated_scene_values_never_panic(file in any::<prop::sample::Index>(), picks in picks()) {
        let texts = scenes();
        check_scene(&json_mutation(&texts[file.index(texts.len())], &picks));
    }
}
