//! Guarantees a refactor once dropped, each restored with a test of its own: a panic, NaN
//! taken and replaced by a default, a hang, a null number in exit-0 JSON, and a slow vertex.
//! `tests/flags.rs` walks every option so that none can be dropped again unseen.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nanofold-guarantees-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary, killing it past `limit` (None: it was still running).
fn run(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nanofold"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    Some(child.wait_with_output().unwrap())
}

fn refused(args: &[&str], names: &[&str]) {
    let out = run(args, Duration::from_secs(60)).unwrap_or_else(|| panic!("nanofold {args:?} did not return"));
    // `check` prints each file's error on its line of stdout and exits 1; the others exit 2.
    let stderr = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(matches!(out.status.code(), Some(1 | 2)), "nanofold {args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for name in names {
        assert!(
            stderr.contains(name),
            "nanofold {args:?} does not name {name}: {stderr}"
        );
    }
}

#[test]
fn an_open_chain_of_a_full_turn_folded_along_its_line_is_refused_by_name_not_a_panic() {
    // Two 180° sectors, the crease between them folded 180°: the chain's boundary rays lie
    // on one another when flat, where the energy is infinite.
    let dir = temp_dir("chain");
    let file = dir.join("chain.json");
    std::fs::write(
        &file,
        r#"{"chain": "open", "angle_unit": "deg", "sector_angles": [180, 180],
            "creases": [{"assignment": "V", "fold_angle": 180}]}"#,
    )
    .unwrap();
    let path = file.to_str().unwrap();
    refused(&["check", path], &["sector_angles", "360"]);
    refused(
        &["unfold", path, "--out", dir.join("out").to_str().unwrap()],
        &["sector_angles"],
    );
    assert!(!dir.join("out").exists(), "nothing is written for a refused input");
    // Less paper folds and unfolds as before.
    std::fs::write(
        &file,
        r#"{"chain": "open", "angle_unit": "deg", "sector_angles": [170, 170],
            "creases": [{"assignment": "V", "fold_angle": 150}]}"#,
    )
    .unwrap();
    let out = run(&["check", path], Duration::from_secs(60)).unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).contains("flat"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn generators_refuse_nan_by_flag_instead_of_writing_a_default() {
    let dir = temp_dir("generate");
    for (args, flag) in [
        (&["miura", "--angle-deg", "NaN"][..], "--angle-deg"),
        (&["miura", "--width", "NaN"][..], "--width"),
        (&["miura", "--fold-deg", "NaN"][..], "--fold-deg"),
        (&["square-twist", "--twist", "NaN"][..], "--twist"),
        (&["waterbomb", "--row-height", "NaN"][..], "--row-height"),
        (&["bird-base", "--half-side", "NaN"][..], "--half-side"),
    ] {
        let file = dir.join("made.fold");
        let mut full = vec!["generate"];
        full.extend_from_slice(args);
        full.extend_from_slice(&["--out", file.to_str().unwrap()]);
        refused(&full, &[flag, "NaN"]);
        assert!(!file.exists(), "{args:?} wrote {}", file.display());
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn constraints_with_a_nan_lock_are_refused_instead_of_hanging() {
    let dir = temp_dir("lock");
    let folded = dir.join("folded.fold");
    let out = run(
        &[
            "generate",
            "miura",
            "--fold-deg",
            "60",
            "--out",
            folded.to_str().unwrap(),
        ],
        Duration::from_secs(60),
    )
    .unwrap();
    assert!(out.status.success());
    refused(
        &[
            "constraints",
            folded.to_str().unwrap(),
            "--drive",
            "4",
            "--lock",
            "5=NaN",
            "--out",
            dir.join("c").to_str().unwrap(),
        ],
        &["--lock", "5=NaN"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn projected_checks_and_unfoldings_print_numbers_never_null() {
    // A Miura crease pattern, a bent Miura sheet, a self-crossing sheet and a nearly rigid
    // 3D form (Origami Simulator's export).
    let dir = temp_dir("project");
    for file in [
        "patterns/many/miura_4x4.fold",
        "patterns/many/miura_4x4_bent.fold",
        "patterns/many/strips_crossing.fold",
        "tests/fixtures/origami-simulator/simple_50.fold",
    ] {
        for command in ["check", "unfold"] {
            let out_dir = dir.join(Path::new(file).file_stem().unwrap());
            let mut args = vec![command, file, "--project", "--json"];
            if command == "unfold" {
                args.extend_from_slice(&["--out", out_dir.to_str().unwrap()]);
            }
            let out = run(&args, Duration::from_secs(60)).unwrap();
            if !out.status.success() {
                // A refusal (the crossing sheet does not unfold) names why; it prints no JSON.
                assert_eq!(out.status.code(), Some(2), "{command} {file}");
                continue;
            }
            let line = String::from_utf8_lossy(&out.stdout);
            let value: serde_json::Value = serde_json::from_str(line.lines().next().unwrap()).unwrap();
            assert_eq!(common::null_in(&value, String::new()), None, "{command} {file}");
            let projection = &value["projection"];
            assert!(projection.is_object(), "{command} {file}: {value}");
            for key in ["max_change_rad", "rms_change_rad", "residual_before_rad"] {
                assert!(
                    projection[key].is_f64(),
                    "{command} {file}: projection.{key} = {}",
                    projection[key]
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_vertex_of_400_creases_mostly_flat_unfolds_flat_by_the_witness_once_the_descent_spends_its_work() {
    // The issue's vertex: 400 creases of 0.7 to 1.2°, four folded (a degree-4 vertex's
    // 120°/−18°/124°/20°), the others flat and unassigned. The energy descent crept to flat
    // in thousands of steps; it now stops at its work bound and the folding path answers.
    let mut state = 3u64;
    let mut draw = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let (base, folds, assignments) = (
        [70.0, 100.0, 120.0, 70.0],
        [120.0, -18.3905306410385, 123.57536812922761, 19.622908594655108],
        ["V", "M", "V", "V"],
    );
    let (mut sectors, mut creases) = (Vec::new(), Vec::new());
    for k in 0..4 {
        let pieces = (base[k] / 0.9_f64).round() as usize;
        let weights: Vec<f64> = (0..pieces).map(|_| 0.7 + 0.5 * draw()).collect();
        let total: f64 = weights.iter().sum();
        creases.push(format!(
            r#"{{"assignment": "{}", "fold_angle": {}}}"#,
            assignments[k], folds[k]
        ));
        for (j, w) in weights.iter().enumerate() {
            if j > 0 {
                creases.push(r#"{"assignment": "U", "fold_angle": 0}"#.to_string());
            }
            sectors.push(w / total * base[k]);
        }
    }
    assert_eq!(creases.len(), 400);
    let dir = temp_dir("vertex400");
    let file = dir.join("v400.json");
    std::fs::write(
        &file,
        format!(
            r#"{{"chain": "closed", "angle_unit": "deg", "sector_angles": {sectors:?}, "creases": [{}]}}"#,
            creases.join(", ")
        ),
    )
    .unwrap();
    let out = run(&["check", "--json", file.to_str().unwrap()], Duration::from_secs(120)).unwrap();
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(value["verdict"], "flat", "{value}");
    let evidence = value["evidence"].as_str().unwrap();
    assert!(
        evidence.contains("work bound") && evidence.contains("folding path"),
        "{evidence}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
