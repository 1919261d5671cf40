//! The library's front door (`nanofold::commands`): one `Pattern`, one `check`, `fold` and
//! `unfold`, against the command line's `--json` (which routes on its own) and against
//! the engines behind it.

mod common;

use common::full_message;
use nanofold::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command as Process;

fn library_patterns() -> Vec<String> {
    let mut paths: Vec<String> = ["patterns", "patterns/many", "patterns/devices"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).unwrap())
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| (p.ends_with(".fold") || p.ends_with(".json")) && !p.ends_with(".scene.json"))
        .collect();
    paths.sort();
    paths
}

/// `check` through the door gives every bundled pattern the verdict `nanofold check --json`
/// gives it, from the same engine.
#[test]
fn the_door_checks_every_bundled_pattern_as_the_command_line_does() {
    let out = Process::new(env!("CARGO_BIN_EXE_nanofold"))
        .args(["check", "--json", "--jobs", "2", "patterns"])
        .output()
        .unwrap();
    let cli: BTreeMap<String, serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .map(|v| (v["file"].as_str().unwrap().to_string(), v))
        .collect();
    let settings = Settings::default();
    let mut compared = 0;
    for path in library_patterns() {
        let line = &cli[&path];
        let opened = Pattern::open(Path::new(&path), &LoadOptions::default());
        match opened.and_then(|p| check(&p, &settings)) {
            Ok(report) => {
                assert_eq!(report.verdict.as_str(), line["verdict"], "{path}");
                // The whole report, as the command line prints it (its own timing aside).
                assert_eq!(
                    without(report.to_json(), &["seconds"]),
                    without(line.clone(), &["seconds"]),
                    "{path}"
                );
                compared += 1;
            }
            Err(e) => assert!(line.get("error").is_some(), "{path}: the door says {e}, the CLI {line}"),
        }
    }
    assert!(compared >= 20, "{compared} patterns compared");
}

/// `unfold` through the door ends where the command line's does, for a vertex and a sheet.
#[test]
fn the_door_unfolds_as_the_command_line_does() {
    let settings = Settings::default();
    for path in ["patterns/corner_cube.fold", "patterns/many/miura_4x4_folded.fold"] {
        let dir = std::env::temp_dir().join(format!("nanofold-door-{}", std::process::id()));
        let out = Process::new(env!("CARGO_BIN_EXE_nanofold"))
            .args(["unfold", "--json", path, "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let report = unfold(
            &Pattern::open(Path::new(path), &LoadOptions::default()).unwrap(),
            &settings,
        )
        .unwrap();
        assert_eq!(report.verdict.as_str(), line["verdict"], "{path}");
        assert_eq!(report.steps as u64, line["iterations"].as_u64().unwrap(), "{path}");
        let theirs: Vec<f64> = serde_json::from_value(line["final_fold_angles_rad"].clone()).unwrap();
        assert_eq!(report.final_fold_angles_rad, theirs, "{path}");
        assert_eq!(report.crease_labels.len(), theirs.len());
        assert_eq!(
            without(report.to_json(), &["seconds"]),
            without(line.clone(), &["seconds", "out"]),
            "{path}"
        );
    }
    // `fold --json` likewise (its frames and folder are the command's).
    let dir = std::env::temp_dir().join(format!("nanofold-door-fold-{}", std::process::id()));
    let out = Process::new(env!("CARGO_BIN_EXE_nanofold"))
        .args(["fold", "--json", "patterns/many/miura_4x4.fold", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pattern = Pattern::open(Path::new("patterns/many/miura_4x4.fold"), &LoadOptions::default()).unwrap();
    let report = fold(&pattern, &settings).unwrap();
    assert_eq!(
        without(report.to_json(), &["seconds"]),
        without(line, &["seconds", "out", "frames"])
    );
}

/// A JSON object without some keys.
fn without(mut value: serde_json::Value, keys: &[&str]) -> serde_json::Value {
    for key in keys {
        value.as_object_mut().unwrap().remove(*key);
    }
    value
}

/// A single vertex built from numbers has a sheet (unit rays, the outline through their
/// tips): folding it follows the same path as the FOLD file's own sheet of that vertex, and
/// the door's check of it is the vertex engine's unfolding.
#[test]
fn a_vertex_from_numbers_folds_on_its_own_sheet() {
    let settings = Settings::default();
    let file = Pattern::open(Path::new("patterns/waterbomb.fold"), &LoadOptions::default()).unwrap();
    let vertex = file.vertex().unwrap().clone();
    let mut built = VertexBuilder::closed("waterbomb").sector_angles(vertex.sector_angles.clone());
    for crease in &vertex.creases {
        built = built.crease(crease.assignment, crease.folded_angle);
    }
    let from_numbers = Pattern::from(built.build().unwrap());
    assert_eq!(from_numbers.engine(), Engine::Vertex);
    let sheet = from_numbers.sheet().expect("a flat-foldable vertex has a sheet");
    assert_eq!((sheet.stars.len(), sheet.crease_count()), (1, 8));
    let a = fold(&file, &settings).unwrap();
    let b = fold(&from_numbers, &settings).unwrap();
    assert_eq!(a.verdict, b.verdict);
    let gap = a
        .final_fold_angles_rad
        .iter()
        .zip(&b.final_fold_angles_rad)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(
        gap < 1e-9,
        "{gap:e}: {:?} vs {:?}",
        a.final_fold_angles_rad,
        b.final_fold_angles_rad
    );
    let checked = check(&from_numbers, &settings).unwrap();
    let engine = unfold_vertex(from_numbers.vertex().unwrap(), &settings.unfold).unwrap();
    assert_eq!(checked.verdict, engine.verdict);
    assert_eq!(checked.final_fold_angles_rad, engine.final_fold_angles_rad);
    // A cone has no sheet: folding it is refused by name; unfolding it still answers.
    let cone = Pattern::open(Path::new("patterns/cone.json"), &LoadOptions::default()).unwrap();
    assert!(cone.sheet().is_none());
    let refused = full_message(&fold(&cone, &settings).unwrap_err());
    assert!(refused.contains("`pattern`") && refused.contains("cone"), "{refused}");
    assert_eq!(
        unfold(&cone, &settings).unwrap().verdict,
        UnfoldVerdict::NotFlatFoldable
    );
}
