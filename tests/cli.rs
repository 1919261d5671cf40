//! The binary, end to end: outputs, JSON keys, exit codes, and nothing written on error.

use std::process::Command;

fn nanofold() -> Command {
    Command::new(env!("CARGO_BIN_EXE_nanofold"))
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("nanofold-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs a command that must succeed and print one JSON value; returns its output and the value.
fn json_run(command: &mut Command) -> (std::process::Output, serde_json::Value) {
    let out = command.output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let value = serde_json::from_slice(&out.stdout).unwrap();
    (out, value)
}

#[test]
fn unfold_writes_outputs_and_json_summary() {
    let dir = temp_dir("unfold");
    let (_, summary) = json_run(
        nanofold()
            .args(["unfold", "patterns/corner_cube.fold", "--json", "--out"])
            .arg(&dir),
    );
    for key in [
        "verdict",
        "iterations",
        "seconds",
        "energy_initial",
        "energy_final",
        "final_fold_angles_rad",
        "max_arc_residual",
        "planarity_residual",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}");
    }
    assert_eq!(summary["verdict"], "flat");
    assert_eq!(summary["final_fold_angles_rad"].as_array().unwrap().len(), 5);

    let fold: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("unfold.fold")).unwrap()).unwrap();
    let frames = fold["file_frames"].as_array().unwrap();
    assert!(frames.len() >= 3);
    let vertices = fold["vertices_coords"].as_array().unwrap().len();
    for frame in frames {
        assert_eq!(frame["vertices_coords"].as_array().unwrap().len(), vertices);
        assert_eq!(frame["vertices_coords"][0].as_array().unwrap().len(), 3);
    }
    // The last frame is flat: every z ≈ 0 and every fold angle ≈ 0.
    let last = frames.last().unwrap();
    for v in last["vertices_coords"].as_array().unwrap() {
        assert!(v[2].as_f64().unwrap().abs() < 1e-5);
    }
    let trajectory: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("trajectory.json")).unwrap()).unwrap();
    assert_eq!(trajectory["steps"][0]["fold_angles_rad"].as_array().unwrap().len(), 5);
    assert!(std::fs::read_to_string(dir.join("unfold.svg"))
        .unwrap()
        .starts_with("<svg"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn errors_exit_nonzero_and_write_nothing() {
    let dir = temp_dir("error");
    let out = nanofold()
        .args(["unfold", "patterns/does_not_exist.fold", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(
        message.contains("does_not_exist.fold") && message.lines().count() == 1,
        "{message}"
    );
    assert!(!dir.exists());
    let out = nanofold()
        .args(["unfold", "patterns/corner_cube.fold", "--p", "-1", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--p"));
    assert!(!dir.exists());
    for flag in ["--flat-tol", "--closure-tol"] {
        let out = nanofold()
            .args(["unfold", "patterns/corner_cube.fold", flag, "-1", "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert!(String::from_utf8_lossy(&out.stderr).contains(flag), "{flag}");
        assert!(!dir.exists());
    }
}

#[test]
fn check_prints_one_line_per_pattern_and_fails_only_on_unreadable_input() {
    let out = nanofold()
        .args(["check", "--json", "patterns/degree4_locked.fold", "patterns/cone.json"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let lines: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // Lines come out as patterns finish: match them by file.
    let verdict_of = |file: &str| {
        lines
            .iter()
            .find(|l| l["file"] == file)
            .map(|l| l["verdict"].clone())
            .unwrap()
    };
    assert_eq!(lines.len(), 2);
    assert_eq!(verdict_of("patterns/degree4_locked.fold"), "locked");
    assert_eq!(verdict_of("patterns/cone.json"), "not_flat_foldable");
    let out = nanofold()
        .args(["check", "patterns/half_paper.fold", "Cargo.toml"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 2);
}

/// JSON lines of a command, keyed by their "file".
fn json_lines(out: &std::process::Output) -> std::collections::BTreeMap<String, serde_json::Value> {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let value: serde_json::Value = serde_json::from_str(l).unwrap();
            (value["file"].as_str().unwrap().to_string(), value)
        })
        .collect()
}

#[test]
fn check_of_a_directory_runs_every_pattern_in_parallel_one_line_each() {
    let out = nanofold()
        .args(["check", "--json", "--jobs", "2", "patterns"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines = json_lines(&out);
    // Every pattern file of the library, scene files skipped, each once.
    let mut expected: Vec<String> = ["patterns", "patterns/devices", "patterns/many"]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).unwrap())
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| (p.ends_with(".fold") || p.ends_with(".json")) && !p.ends_with(".scene.json"))
        .collect();
    expected.sort();
    assert_eq!(lines.keys().cloned().collect::<Vec<_>>(), expected);
    assert_eq!(lines["patterns/degree4_locked.fold"]["verdict"], "locked");
    assert_eq!(lines["patterns/cone.json"]["verdict"], "not_flat_foldable");
    assert_eq!(lines["patterns/symmetric16.fold"]["verdict"], "flat");
    // Crease patterns of many vertices get their own verdicts in the same run.
    assert_eq!(lines["patterns/many/miura_4x4_folded.fold"]["verdict"], "rigid");
    // A rigid folded state is unfolded too.
    assert_eq!(
        lines["patterns/many/miura_4x4_folded.fold"]["unfold"]["verdict"],
        "flat"
    );
    assert_eq!(
        lines["patterns/many/square_twist.fold"]["verdict"],
        "not_rigidly_foldable"
    );
    // The same answers one at a time: parallel runs do not disturb each other.
    let serial = nanofold()
        .args(["check", "--json", "--jobs", "1", "patterns"])
        .output()
        .unwrap();
    for (file, line) in json_lines(&serial) {
        assert_eq!(line["verdict"], lines[&file]["verdict"], "{file}");
        assert_eq!(
            line["final_fold_angles_rad"], lines[&file]["final_fold_angles_rad"],
            "{file}"
        );
    }
}

#[test]
fn unfold_of_several_patterns_writes_a_folder_each_and_refuses_name_clashes() {
    let dir = temp_dir("unfold-many");
    let out = nanofold()
        .args([
            "unfold",
            "--json",
            "patterns/half_paper.fold",
            "patterns/degree4_generic.fold",
            "patterns/cone.json",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let lines = json_lines(&out);
    assert_eq!(lines.len(), 3);
    for name in ["half_paper", "degree4_generic", "cone"] {
        for file in ["trajectory.json", "unfold.svg", "unfold.fold"] {
            assert!(dir.join(name).join(file).is_file(), "{name}/{file}");
        }
    }
    assert_eq!(lines["patterns/degree4_generic.fold"]["verdict"], "flat");
    assert_eq!(
        lines["patterns/degree4_generic.fold"]["out"],
        dir.join("degree4_generic").display().to_string()
    );

    // Two files with one name would share a folder: refused before anything runs.
    let other = temp_dir("unfold-clash");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::copy("patterns/half_paper.fold", other.join("half_paper.fold")).unwrap();
    let clash_out = temp_dir("unfold-clash-out");
    let out = nanofold()
        .args(["unfold", "patterns/half_paper.fold"])
        .arg(other.join("half_paper.fold"))
        .arg("--out")
        .arg(&clash_out)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("would both write"));
    assert!(!clash_out.exists());

    // A bad --jobs is refused by name.
    let out = nanofold()
        .args(["check", "patterns", "--jobs", "two"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--jobs"));

    // So is a negative bending metric, with its value.
    let out = nanofold()
        .args(["check", "patterns/corner_cube.fold", "--bending-metric", "-1"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--bending-metric -1"));

    // A directory without patterns is an error naming it.
    let empty = temp_dir("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = nanofold().arg("check").arg(&empty).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no pattern files"));

    // One unreadable file among several: the others still run, the exit status says so.
    let out = nanofold()
        .args(["unfold", "--json", "patterns/half_paper.fold", "Cargo.toml", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let lines = json_lines(&out);
    assert_eq!(lines["patterns/half_paper.fold"]["verdict"], "flat");
    assert!(lines["Cargo.toml"]["error"].as_str().unwrap().contains("Cargo.toml"));
}

#[test]
fn constraints_command_writes_json_svg_and_mujoco() {
    let dir = temp_dir("constraints");
    let out = nanofold()
        .args([
            "constraints",
            "patterns/corner_cube.fold",
            "--drive",
            "0",
            "--lock",
            "1=0",
            "--range",
            "0:180",
            "--format",
            "mujoco",
            "--json",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["driver", "locked", "degree", "domain_rad", "samples", "curves"] {
        assert!(report.get(key).is_some(), "missing {key}");
    }
    assert_eq!(report["locked"]["1"], 0.0);
    assert_eq!(report["degree"], 4);
    let curves = report["curves"].as_array().unwrap();
    assert_eq!(curves.len(), 3);
    for curve in curves {
        for key in [
            "crease",
            "coeffs_rad",
            "coeffs_deg",
            "max_fit_error_rad",
            "max_closure_residual",
        ] {
            assert!(curve.get(key).is_some(), "missing curves[].{key}");
        }
        assert_eq!(curve["coeffs_rad"].as_array().unwrap().len(), 5);
    }
    // The file on disk is the same report.
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("constraints.json")).unwrap()).unwrap();
    assert_eq!(on_disk, report);
    let xml = std::fs::read_to_string(dir.join("constraints.xml")).unwrap();
    assert_eq!(xml.matches("joint2=\"crease_0\"").count(), 3);
    assert!(std::fs::read_to_string(dir.join("constraints.svg"))
        .unwrap()
        .starts_with("<svg"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn constraints_bad_arguments_fail_clearly_and_write_nothing() {
    let dir = temp_dir("constraints-bad");
    let cases: [(&[&str], &str); 9] = [
        (&["--drive", "9"], "no crease with this index"),
        (&["--drive", "0", "--lock", "0=0"], "cannot drive a locked crease"),
        (&["--drive", "0", "--degree", "0"], "--degree"),
        (&["--drive", "0", "--degree", "21"], "--degree"),
        (&["--drive", "0", "--degree", "5", "--format", "mujoco"], "quartic"),
        (
            &["--drive", "0", "--range", "0:180"],
            "loop closure has no solution beyond it",
        ),
        (&["--drive", "0", "--degree", "auto"], "--tol"),
        (&["--drive", "0", "--degree", "-1"], "--degree"),
        (&["--drive", "0", "--samples", "2"], "--samples"),
    ];
    for (args, expected) in cases {
        let out = nanofold()
            .args(["constraints", "patterns/degree4_generic.fold"])
            .args(args)
            .arg("--out")
            .arg(&dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!dir.exists(), "{args:?} wrote {}", dir.display());
    }
}

#[test]
fn simulate_writes_response_files_and_the_documented_json_keys() {
    let dir = temp_dir("simulate");
    let out = nanofold()
        .args(["simulate", "patterns/bridge_step.scene.json", "--json", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        out.stderr.is_empty(),
        "--json must keep stderr quiet: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "model",
        "time_scale_ratio",
        "t_end_s",
        "collision",
        "final_angles_rad",
        "steps",
        "rhs_evaluations",
        "seconds",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}");
    }
    assert_eq!(summary["model"], "dynamic");
    let collision = &summary["collision"];
    assert_eq!(collision["pair"][1], "substrate");
    assert_eq!(collision["time_s"], summary["t_end_s"]);
    assert_eq!(collision["point"].as_array().unwrap().len(), 3);
    let response: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("response.json")).unwrap()).unwrap();
    let times = response["time_s"].as_array().unwrap();
    assert_eq!(times.len(), response["angles_rad"].as_array().unwrap().len());
    assert_eq!(times.len(), response["velocities_rad_s"].as_array().unwrap().len());
    assert_eq!(times.len(), response["energy_j"]["total"].as_array().unwrap().len());
    for (name, label) in [("response.svg", "hinge 0"), ("snapshots.svg", "substrate")] {
        let svg = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains(label), "{name}");
    }

    let (_, summary) = json_run(
        nanofold()
            .args(["simulate", "patterns/bridge_ramp.scene.json", "--json", "--out"])
            .arg(temp_dir("simulate-ramp")),
    );
    assert_eq!(summary["model"], "quasi_static");
    assert!(summary["time_scale_ratio"].as_f64().unwrap() > 1e8);
    let estimate = summary["quasi_static_error_estimate_rad"].as_f64().unwrap();
    let measured = summary["measured_quasi_static_error_rad"].as_f64().unwrap();
    assert!(measured <= estimate, "measured {measured} > estimate {estimate}");
}

#[test]
fn modes_prints_descending_frequencies_and_stability() {
    let (_, modes) = json_run(
        nanofold()
            .args(["modes", "patterns/bridge_step.scene.json", "--json", "--out"])
            .arg(temp_dir("modes-bridge")),
    );
    let eigenvalues: Vec<f64> = modes["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let frequencies: Vec<f64> = modes["frequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(eigenvalues.len(), 4);
    assert!(eigenvalues.windows(2).all(|w| w[0] >= w[1]));
    for (l, f) in eigenvalues.iter().zip(&frequencies) {
        assert!((l.sqrt() / std::f64::consts::TAU - f).abs() < 1e-9 * f);
    }
    assert_eq!(modes["stable"], true);
    for shape in modes["mode_shapes"].as_array().unwrap() {
        let max = shape
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap().abs())
            .fold(0.0, f64::max);
        assert!((max - 1.0).abs() < 1e-12);
    }
    assert_eq!(modes["equilibrium_rad"].as_array().unwrap().len(), 4);
}

#[test]
fn simulate_of_a_closed_scene_writes_its_figures_and_the_closed_keys() {
    let dir = temp_dir("simulate-closed");
    let (_, summary) = json_run(
        nanofold()
            .args(["simulate", "patterns/corner_cube_step1.scene.json", "--json", "--out"])
            .arg(&dir),
    );
    for key in [
        "model",
        "collision",
        "final_angles_rad",
        "cut_crease",
        "constraint_source",
        "torque_magnification",
        "max_closure_residual",
        "constraint_slope_error",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}");
    }
    assert_eq!(summary["final_angles_rad"].as_array().unwrap().len(), 5);
    for (name, label) in [("response.svg", "edges[0]"), ("snapshots.svg", "anchored sector")] {
        let svg = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains(label), "{name}");
    }
    assert!(dir.join("response.json").exists());
}

#[test]
fn modes_of_a_closed_scene_release_its_locks_and_report_the_closed_keys() {
    let (_, modes) = json_run(
        nanofold()
            .args(["modes", "patterns/corner_cube_step2.scene.json", "--json", "--out"])
            .arg(temp_dir("modes-cube-json")),
    );
    for key in [
        "eigenvalues",
        "frequencies_hz",
        "mode_shapes",
        "stable",
        "equilibrium_rad",
        "cut_crease",
        "constraint_source",
        "torque_magnification",
        "max_closure_residual",
        "crease_mode_shapes",
        "frequencies_without_load_hz",
    ] {
        assert!(modes.get(key).is_some(), "missing {key}");
    }
    assert_eq!(modes["coordinates"], serde_json::json!([1, 0]));
    assert_eq!(modes["cut_crease"], 2);
    assert_eq!(modes["stable"], true);
    assert_eq!(modes["eigenvalues"].as_array().unwrap().len(), 2);
    assert_eq!(modes["crease_mode_shapes"][0].as_array().unwrap().len(), 5);
    let table = nanofold()
        .args(["modes", "patterns/corner_cube_step2.scene.json", "--out"])
        .arg(temp_dir("modes-cube"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        table.status.success() && text.contains("locks released") && text.contains("stable"),
        "{text}"
    );
}

#[test]
fn a_bad_scene_fails_clearly_and_writes_nothing() {
    let dir = temp_dir("bad-scene");
    let scene = dir.with_extension("scene.json");
    let text = std::fs::read_to_string("patterns/bridge_step.scene.json")
        .unwrap()
        .replace(r#""poisson_ratio": 0.28"#, r#""poisson_ratio": 0.7"#);
    std::fs::write(&scene, text).unwrap();
    let out = nanofold()
        .arg("simulate")
        .arg(&scene)
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("materials.SiN.poisson_ratio") && stderr.contains("0.7"),
        "{stderr}"
    );
    assert!(!dir.exists(), "nothing may be written for a bad scene");
    let _ = std::fs::remove_file(&scene);
}

#[test]
fn fold_writes_frames_that_check_and_read_back() {
    let dir = temp_dir("fold");
    let (_, summary) = json_run(
        nanofold()
            .args([
                "fold",
                "patterns/many/miura_4x4.fold",
                "--to",
                "80",
                "--frames",
                "6",
                "--json",
                "--out",
            ])
            .arg(&dir),
    );
    for key in [
        "stop_reason",
        "frames",
        "dof",
        "max_closure_residual_rad",
        "min_panel_clearance",
        "seconds",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}: {summary}");
    }
    assert_eq!(summary["stop_reason"], "reached");
    assert_eq!(summary["frames"], 6);
    assert_eq!(summary["dof"], 1);
    assert!(summary["max_closure_residual_rad"].as_f64().unwrap() <= 1e-10);
    // The animation: the crease pattern (2D) as key frame, 3D folded frames whose
    // assignments follow their angles' signs.
    let animation: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fold.fold")).unwrap()).unwrap();
    assert_eq!(animation["frame_classes"][0], "creasePattern");
    assert!(animation["vertices_coords"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p.as_array().unwrap().len() == 2));
    let frames = animation["file_frames"].as_array().unwrap();
    assert_eq!(frames.len(), 6);
    for frame in frames {
        assert_eq!(frame["frame_classes"][0], "foldedForm");
        let angles = frame["edges_foldAngle"].as_array().unwrap();
        let letters = frame["edges_assignment"].as_array().unwrap();
        for (angle, letter) in angles.iter().zip(letters) {
            let (angle, letter) = (angle.as_f64().unwrap(), letter.as_str().unwrap());
            assert!(
                (angle <= 0.0 || letter == "V") && (angle >= 0.0 || letter == "M"),
                "{angle} {letter}"
            );
        }
    }
    // The end state reads back as a rigid state, and the last frame's 3D edge lengths are
    // the crease pattern's.
    let (_, check) = json_run(nanofold().args(["check", "--json"]).arg(dir.join("folded.fold")));
    assert_eq!(check["verdict"], "rigid", "{check}");
    assert!(check["max_vertex_residual_rad"].as_f64().unwrap() <= 1e-10);
    assert_eq!(check["intersecting_pairs"].as_array().unwrap().len(), 0);
    let flat = animation["vertices_coords"].as_array().unwrap();
    let last = frames.last().unwrap()["vertices_coords"].as_array().unwrap();
    for edge in animation["edges_vertices"].as_array().unwrap() {
        let (a, b) = (edge[0].as_u64().unwrap() as usize, edge[1].as_u64().unwrap() as usize);
        let length = |points: &Vec<serde_json::Value>| {
            let p: Vec<f64> = points[a]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let q: Vec<f64> = points[b]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            p.iter().zip(&q).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
        };
        assert!((length(flat) - length(last)).abs() < 1e-12);
    }
    for file in ["fold.svg", "trajectory.json"] {
        assert!(dir.join(file).exists(), "{file}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn generate_and_fold_refuse_bad_values_by_flag() {
    let dir = temp_dir("generate");
    std::fs::create_dir_all(&dir).unwrap();
    let out = nanofold()
        .args(["generate", "miura", "--angle", "95", "--out"])
        .arg(dir.join("m.fold"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("--angle") && text.contains("95"), "{text}");
    assert!(!dir.join("m.fold").exists());
    let out = nanofold()
        .args(["fold", "patterns/many/miura_4x4.fold", "--drive", "0=30"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && text.contains("edge 0 is not a crease"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn constraints_of_a_folded_crease_pattern_fit_every_crease_against_the_driver() {
    let dir = temp_dir("network-constraints");
    let (_, report) = json_run(
        nanofold()
            .args([
                "constraints",
                "patterns/many/miura_4x4_folded.fold",
                "--drive",
                "28",
                "--degree",
                "4",
                "--format",
                "mujoco",
                "--json",
                "--out",
            ])
            .arg(&dir),
    );
    assert_eq!(report["driver_edge"], 28);
    assert_eq!(report["curves"].as_array().unwrap().len(), 23);
    assert!(report["max_closure_residual_rad"].as_f64().unwrap() <= 1e-12);
    assert!(report["max_fit_error_rad"].as_f64().unwrap() < 1e-3);
    let xml = std::fs::read_to_string(dir.join("constraints.xml")).unwrap();
    assert_eq!(xml.matches("joint2=\"crease_28\"").count(), 23);
    // A flat pattern has no state to sweep from: refused, nothing written.
    let out = nanofold()
        .args(["constraints", "patterns/many/miura_4x4.fold", "--drive", "28", "--out"])
        .arg(dir.join("flat"))
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("folded state"));
    assert!(!dir.join("flat").exists());
    // Each sweep point closes every vertex anew: a large sheet is swept at fewer samples,
    // the most it allows named (samples × creases ≤ 5 × 10⁶), before any work.
    let large = dir.join("miura_120.fold");
    let made = nanofold()
        .args([
            "generate",
            "miura",
            "--rows",
            "120",
            "--cols",
            "120",
            "--fold-deg",
            "90",
            "--out",
        ])
        .arg(&large)
        .output()
        .unwrap();
    assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
    let out = nanofold()
        .args(["constraints", "--drive", "120", "--out"])
        .arg(dir.join("large"))
        .arg(&large)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && err.contains("--samples 201")
            && err.contains("28560 creases is swept at 175 samples at most"),
        "{err}"
    );
    assert!(!dir.join("large").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_reads_a_folded_form_exported_by_origami_simulator() {
    let (_, value) = json_run(nanofold().args(["check", "--json", "tests/fixtures/origami-simulator/simple_50.fold"]));
    // Three creases that end on the sheet's edge: no vertex closure, each a free hinge.
    assert_eq!(value["verdict"], "rigid", "{value}");
    assert_eq!(value["creases"], 3);
    assert_eq!(value["dof"], 3);
    let form = &value["folded_form"];
    assert!(form["development_error"].as_f64().unwrap() < 1e-9, "{form}");
    assert!(form["max_facet_angle_rad"].as_f64().unwrap() < 1e-9, "{form}");
    // Valleys came out positive without mirroring: the faces are counter-clockwise.
    assert_eq!(form["mirrored"], false);
}

#[test]
fn unfold_fold_reads_back_as_its_input_and_its_frames_follow_the_sign_rule() {
    use nanofold::pattern::LoadOptions;
    for name in [
        "corner_cube.fold",
        "degree4_locked.fold",
        "degree4_native.json",
        "symmetric16.fold",
    ] {
        let dir = temp_dir(&format!("roundtrip-{name}"));
        let out = nanofold()
            .args(["unfold", &format!("patterns/{name}"), "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let original =
            nanofold::read::load_pattern(&std::path::Path::new("patterns").join(name), &LoadOptions::default())
                .unwrap();
        let again = nanofold::read::load_pattern(&dir.join("unfold.fold"), &LoadOptions::default()).unwrap();
        assert_eq!(original.sector_angles.len(), again.sector_angles.len(), "{name}");
        for (a, b) in original.sector_angles.iter().zip(&again.sector_angles) {
            assert!((a - b).abs() < 1e-12, "{name}: sector {a} vs {b}");
        }
        for (a, b) in original.creases.iter().zip(&again.creases) {
            assert!(
                (a.folded_angle - b.folded_angle).abs() < 1e-9,
                "{name}: {} vs {}",
                a.folded_angle,
                b.folded_angle
            );
            assert_eq!((a.assignment, a.locked), (b.assignment, b.locked), "{name}");
        }
        let fold: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("unfold.fold")).unwrap()).unwrap();
        assert_eq!(fold["frame_classes"][0], "creasePattern");
        for frame in fold["file_frames"].as_array().unwrap() {
            let angles = frame["edges_foldAngle"].as_array().unwrap();
            let letters = frame["edges_assignment"].as_array().unwrap();
            for (angle, letter) in angles.iter().zip(letters) {
                let (angle, letter) = (angle.as_f64().unwrap(), letter.as_str().unwrap());
                assert!(
                    (angle <= 0.0 || letter == "V") && (angle >= 0.0 || letter == "M"),
                    "{name}: {angle} {letter}"
                );
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn unfold_takes_a_folded_crease_pattern_of_many_vertices() {
    let dir = temp_dir("unfold-network");
    let (_, summary) = json_run(
        nanofold()
            .args(["unfold", "patterns/many/miura_4x4_folded.fold", "--json", "--out"])
            .arg(&dir),
    );
    assert_eq!(summary["verdict"], "flat", "{summary}");
    for key in [
        "iterations",
        "seconds",
        "energy_initial",
        "energy_final",
        "final_fold_angles_rad",
        "max_closure_residual_rad",
        "flat_layout_error",
    ] {
        assert!(summary.get(key).is_some(), "missing {key}");
    }
    assert!(summary["max_closure_residual_rad"].as_f64().unwrap() <= 1e-10);
    assert!(summary["flat_layout_error"].as_f64().unwrap() <= 1e-12);
    // The animation's key frame is the folded input: read back, it is the same state.
    let (_, check) = json_run(nanofold().args(["check", "--json"]).arg(dir.join("unfold.fold")));
    assert_eq!(check["verdict"], "rigid", "{check}");
    let original: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/many/miura_4x4_folded.fold").unwrap()).unwrap();
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("unfold.fold")).unwrap()).unwrap();
    for (a, b) in original["edges_foldAngle"]
        .as_array()
        .unwrap()
        .iter()
        .zip(written["edges_foldAngle"].as_array().unwrap())
    {
        assert!((a.as_f64().unwrap() - b.as_f64().unwrap()).abs() < 1e-9);
    }
    assert_eq!(original["edges_assignment"], written["edges_assignment"]);
    // A state that needs bending gets its verdict, not an error.
    let (_, bent) = json_run(
        nanofold()
            .args(["unfold", "patterns/many/miura_4x4_bent.fold", "--json", "--out"])
            .arg(dir.join("bent")),
    );
    assert_eq!(bent["verdict"], "not_rigid", "{bent}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_crease_pattern_of_many_vertices_gets_the_crease_pattern_error() {
    let dir = temp_dir("bad-network");
    std::fs::create_dir_all(&dir).unwrap();
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/many/miura_4x4_folded.fold").unwrap()).unwrap();
    value["faces_vertices"][0] = serde_json::json!([0, 1, 2]);
    let bad_face = dir.join("bad_face.fold");
    std::fs::write(&bad_face, value.to_string()).unwrap();
    value.as_object_mut().unwrap().remove("faces_vertices");
    value["vertices_coords"][7] = serde_json::json!([1e300, 0.0]);
    let far = dir.join("far.fold");
    std::fs::write(&far, value.to_string()).unwrap();
    for (file, expected) in [(&bad_face, "faces_vertices[0]"), (&far, "vertices_coords[7]")] {
        let out = nanofold().arg("check").arg(file).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(!out.status.success(), "{text}");
        assert!(
            text.contains(expected) && !text.contains("only single-vertex"),
            "{text}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn degree_auto_for_mujoco_is_capped_at_four_with_its_error_stated() {
    let dir = temp_dir("auto-mujoco");
    let out = nanofold()
        .args([
            "constraints",
            "patterns/corner_cube.fold",
            "--drive",
            "0",
            "--lock",
            "1=0",
            "--degree",
            "auto",
            "--tol",
            "1e-9",
            "--format",
            "mujoco",
            "--json",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["degree"], 4);
    assert!(String::from_utf8_lossy(&out.stderr).contains("capped at 4"));
    assert!(dir.join("constraints.xml").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn new_crease_pattern_inputs_are_refused_by_name() {
    let dir = temp_dir("crease-inputs");
    std::fs::create_dir_all(&dir).unwrap();
    // A lock on a boundary edge.
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/many/miura_4x4.fold").unwrap()).unwrap();
    let edges = value["edges_vertices"].as_array().unwrap().len();
    let mut locked = vec![false; edges];
    locked[0] = true;
    value["edges_nanofold:locked"] = serde_json::json!(locked);
    let file = dir.join("locked_boundary.fold");
    std::fs::write(&file, value.to_string()).unwrap();
    let out = nanofold().arg("check").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        !out.status.success() && text.contains("edges_nanofold:locked[0]"),
        "{text}"
    );
    // Generator and fold flags out of range: each named, nothing written.
    for (args, flag) in [
        (vec!["generate", "square-twist", "--twist", "60"], "--twist"),
        (vec!["generate", "waterbomb", "--rows", "0"], "--rows"),
        (vec!["generate", "waterbomb", "--row-height", "0"], "--row-height"),
        (vec!["generate", "bird-base", "--half-side", "-2"], "--half-side"),
        (vec!["generate", "miura", "--slant", "-1"], "--slant"),
    ] {
        let target = dir.join("out.fold");
        let out = nanofold().args(&args).arg("--out").arg(&target).output().unwrap();
        let text = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && text.contains(flag), "{args:?}: {text}");
        assert!(!target.exists());
    }
    let out = nanofold()
        .args(["fold", "patterns/many/miura_4x4.fold", "--to", "150", "--out"])
        .arg(dir.join("fold"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && text.contains("--to"), "{text}");
    assert!(!dir.join("fold").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The terminal prints every coefficient at full precision: the degree-16 corner-cube curves
/// read back from stdout give the JSON's curves to rounding at θ = 180° (with seven digits
/// they were 1.1e-3° off).
#[test]
fn printed_constraint_coefficients_reproduce_the_curves() {
    let dir = temp_dir("coefficients");
    let out = nanofold()
        .args([
            "constraints",
            "patterns/corner_cube.fold",
            "--drive",
            "0",
            "--lock",
            "1=0",
            "--range",
            "0:180",
            "--degree",
            "16",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let printed: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.contains("·θ^"))
        .map(|l| {
            l.split_whitespace()
                .map(|term| term.split('·').next().unwrap().parse::<f64>().unwrap())
                .collect()
        })
        .collect();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("constraints.json")).unwrap()).unwrap();
    let curves = json["curves"].as_array().unwrap();
    assert_eq!(printed.len(), curves.len());
    let eval = |c: &[f64], x: f64| c.iter().rev().fold(0.0, |acc, a| acc * x + a);
    for (terms, curve) in printed.iter().zip(curves) {
        let exact: Vec<f64> = curve["coeffs_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(terms.len(), 17);
        for x in [45.0, 90.0, 180.0] {
            let (a, b) = (eval(terms, x), eval(&exact, x));
            assert!((a - b).abs() < 1e-9, "at {x}°: printed {a}, JSON {b}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--free I,J,...` holds every other crease (but the driver) at its folded angle: on
/// symmetric16 it gives exactly the curves of the twelve hand-typed `--lock`s it replaces.
#[test]
fn free_creases_replace_a_lock_for_every_other_crease() {
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/symmetric16.fold").unwrap()).unwrap();
    let angles = file["edges_foldAngle"].as_array().unwrap();
    let dir = temp_dir("free");
    let run = |extra: Vec<String>, name: &str| {
        let out = nanofold()
            .args([
                "constraints",
                "patterns/symmetric16.fold",
                "--drive",
                "0",
                "--range",
                "60:120",
                "--json",
                "--out",
            ])
            .arg(dir.join(name))
            .args(&extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        value
    };
    let free = run(vec!["--free".into(), "1,2,3".into()], "free");
    let locks: Vec<String> = (4..16)
        .flat_map(|e| ["--lock".to_string(), format!("{e}={}", angles[e].as_f64().unwrap())])
        .collect();
    let locked = run(locks, "locked");
    assert_eq!(free["curves"].as_array().unwrap().len(), 3);
    assert_eq!(free["curves"], locked["curves"]);
    // A crease that is not one is named.
    let out = nanofold()
        .args([
            "constraints",
            "patterns/symmetric16.fold",
            "--drive",
            "0",
            "--free",
            "1,99",
            "--out",
        ])
        .arg(dir.join("bad"))
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--free 99"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--check` measures a given polynomial against exact closure. The Miura vertex's collinear
/// creases fold equal and opposite (a flat-foldable degree-4 vertex, closed form), so
/// ρ₂ = −ρ₀ exactly: −θ has no error, +0.5° has 0.5° everywhere, and a 1e-3·θ² term has
/// 1e-3·θ_end² at the folded end.
#[test]
fn a_checked_curve_is_measured_against_exact_closure() {
    let dir = temp_dir("check");
    let run = |checks: &[&str]| {
        let mut command = nanofold();
        command.args([
            "constraints",
            "patterns/miura_vertex.fold",
            "--drive",
            "0",
            "--json",
            "--out",
        ]);
        command.arg(dir.join("out"));
        for check in checks {
            command.args(["--check", check]);
        }
        command.output().unwrap()
    };
    let out = run(&["2=0,-1", "2=0.5,-1", "2=0,-1,1e-3"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let checked = report["checked_curves"].as_array().unwrap();
    assert_eq!(checked.len(), 3);
    let end = report["domain_deg"][0].as_f64().unwrap();
    assert!((checked[0]["max_error_rad"].as_f64().unwrap()) < 1e-9, "{}", checked[0]);
    let offset = checked[1]["max_error_rad"].as_f64().unwrap();
    assert!((offset - 0.5_f64.to_radians()).abs() < 1e-9, "{offset}");
    let quadratic = checked[2]["folded_end_error_rad"].as_f64().unwrap();
    assert!((checked[2]["folded_end_deg"].as_f64().unwrap() - end).abs() < 1e-9);
    assert!(
        (quadratic - (1e-3 * end * end).to_radians()).abs() < 1e-9,
        "{quadratic} at {end}°"
    );
    // The driver, a held crease and a bad coefficient are refused by name.
    for (check, says) in [
        ("0=1", "edges[0] is the driver"),
        ("1=1,x", "coefficient \"x\" is not a number"),
        ("1=nan", "coeffs_deg[0]"),
        ("9=1", "--check 9"),
    ] {
        let out = run(&[check]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(says), "{check}: {stderr}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A failed integration says when it failed in seconds of the run, not in diffsol's scaled
/// time alone.
#[test]
fn a_failed_integration_reports_the_runs_own_time() {
    let dir = temp_dir("ode-failure");
    let out = nanofold()
        .args([
            "simulate",
            "patterns/bridge_step.scene.json",
            "--model",
            "dynamic",
            "--method",
            "esdirk34",
            "--rtol",
            "1e-15",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        text.contains("failed at t = ") && text.contains(" s of 2.000000e-3 s"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `frame_unit` is kept: a single vertex's `unfold.fold`, and `fold`'s `fold.fold` and
/// `folded.fold` (and `unfold` of that) carry the input's unit; a unit that is not a short
/// string is refused by name.
#[test]
fn the_frame_unit_is_kept_on_every_output() {
    let dir = temp_dir("unit");
    std::fs::create_dir_all(&dir).unwrap();
    let with_unit = |source: &str, unit: serde_json::Value, name: &str| {
        let mut value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(source).unwrap()).unwrap();
        value["frame_unit"] = unit;
        let path = dir.join(name);
        std::fs::write(&path, value.to_string()).unwrap();
        path
    };
    let unit_of = |path: std::path::PathBuf| {
        let value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        value["frame_unit"].clone()
    };
    let vertex = with_unit("patterns/corner_cube.fold", "um".into(), "cube.fold");
    let out = nanofold()
        .arg("unfold")
        .arg(&vertex)
        .arg("--out")
        .arg(dir.join("cube"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(unit_of(dir.join("cube/unfold.fold")), "um");
    let miura = with_unit("patterns/many/miura_4x4.fold", "mm".into(), "miura.fold");
    let out = nanofold()
        .arg("fold")
        .arg(&miura)
        .args(["--to", "50", "--out"])
        .arg(dir.join("miura"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(unit_of(dir.join("miura/fold.fold")), "mm");
    assert_eq!(unit_of(dir.join("miura/folded.fold")), "mm");
    let out = nanofold()
        .arg("unfold")
        .arg(dir.join("miura/folded.fold"))
        .arg("--out")
        .arg(dir.join("miura_unfolded"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(unit_of(dir.join("miura_unfolded/unfold.fold")), "mm");
    let bad = with_unit("patterns/many/miura_4x4.fold", 3.into(), "bad.fold");
    let out = nanofold().arg("check").arg(&bad).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && text.contains("frame_unit"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two degree-3 vertices (a crease between them, two more from each to the sheet's
/// corners): Kawasaki's condition has no meaning there, and the check says so in words
/// (it wrote `"inf"` before) and lists the vertices.
#[test]
fn odd_degree_vertices_are_named_not_infinite() {
    let dir = temp_dir("odd-degree");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two_degree3.fold");
    let fold = serde_json::json!({
        "file_spec": 1.1,
        "vertices_coords": [[-1, -1], [1, -1], [1, 1], [-1, 1], [-0.5, 0], [0.5, 0]],
        "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [4, 3], [4, 0], [5, 2], [5, 1]],
        "edges_assignment": ["B", "B", "B", "B", "V", "M", "M", "M", "M"],
    });
    std::fs::write(&file, fold.to_string()).unwrap();
    let out = nanofold().args(["check", "--json"]).arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(!text.contains("inf"), "{text}");
    let value: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    assert_eq!(
        value["flat_foldability"]["odd_degree_vertices"],
        serde_json::json!([4, 5]),
        "{value}"
    );
    assert!(value["flat_foldability"]["worst_kawasaki"].is_null(), "{value}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `fold` given a scene says it is a scene, as `unfold` does.
#[test]
fn fold_of_a_scene_says_it_is_a_scene() {
    let out = nanofold()
        .args([
            "fold",
            "patterns/devices/miura_sheet.scene.json",
            "--out",
            "/nonexistent/never",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("this is a scene") && err.contains("simulate"), "{err}");
}

/// Unfolding a FOLD animation (nanofold's own `unfold.fold`) reads its key frame and says
/// that its other frames were not read, for a vertex and for a sheet.
#[test]
fn unfold_of_an_animation_says_its_frames_were_not_read() {
    for pattern in ["patterns/corner_cube.fold", "patterns/many/miura_4x4_folded.fold"] {
        let dir = temp_dir("animation");
        let first = nanofold()
            .args(["unfold", pattern, "--out"])
            .arg(&dir)
            .output()
            .unwrap();
        assert!(first.status.success());
        let animation = dir.join("unfold.fold");
        let frames = serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&animation).unwrap()).unwrap()
            ["file_frames"]
            .as_array()
            .unwrap()
            .len();
        let again = nanofold()
            .args(["unfold", "--json"])
            .arg(&animation)
            .arg("--out")
            .arg(dir.join("again"))
            .output()
            .unwrap();
        let value: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
        let notes = value["adjustments"].to_string();
        assert!(
            notes.contains(&format!("its {frames} file_frames were not")),
            "{pattern}: {notes}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Two inputs with one file name (`a/folded.fold`, `b/folded.fold`) share a default output
/// folder: the second run is refused, naming the folder, the input it holds and what to do,
/// and the first run's results stay; `--force` replaces them; the same input again may.
#[test]
fn an_output_folder_of_another_input_is_not_replaced() {
    let dir = temp_dir("owner");
    for (sub, source) in [("a", "patterns/corner_cube.fold"), ("b", "patterns/waterbomb.fold")] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::copy(source, dir.join(sub).join("folded.fold")).unwrap();
    }
    let run = |file: &str, force: bool| {
        let mut command = nanofold();
        command.current_dir(&dir).args(["unfold", file]);
        if force {
            command.arg("--force");
        }
        command.output().unwrap()
    };
    let results = dir.join("output/folded/trajectory.json");
    assert!(run("a/folded.fold", false).status.success());
    let first = std::fs::read_to_string(&results).unwrap();
    let refused = run("b/folded.fold", false);
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        message.contains("output/folded") && message.contains("a/folded.fold") && message.contains("--force"),
        "{message}"
    );
    assert_eq!(
        std::fs::read_to_string(&results).unwrap(),
        first,
        "the first results stay"
    );
    assert!(
        run("a/folded.fold", false).status.success(),
        "the same input may replace its own"
    );
    assert!(run("b/folded.fold", true).status.success());
    assert_ne!(std::fs::read_to_string(&results).unwrap(), first);
    let owner: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("output/folded/nanofold.json")).unwrap()).unwrap();
    assert!(owner["input"].as_str().unwrap().ends_with("b/folded.fold"), "{owner}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 30's settings at their edges and inputs that broke the many-vertex commands: each
/// refused by name, or answered as what it is (each failed before: a step of 1e-300 stopped
/// `locked`, a goal of 1e-300 reported progress 3e298, an all-locked check wrote a null
/// threshold, a non-rigid start's energies were "nan", a 258 × 258 Miura-ori was refused as
/// over 200 000 edges, a 1e-300 bird base failed with "enclose no region", and a vertex no
/// edge uses made `fold` and `unfold` panic).
#[test]
fn many_vertex_settings_and_inputs_at_their_edges() {
    let dir = temp_dir("edges30");
    std::fs::create_dir_all(&dir).unwrap();
    let run = |args: &[&str]| {
        let out = nanofold().args(args).output().unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).to_string(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let out = dir.join("out").display().to_string();
    let (ok, _, err) = run(&[
        "fold",
        "patterns/many/miura_4x4.fold",
        "--max-step",
        "1e-300",
        "--out",
        &out,
    ]);
    assert!(
        !ok && err.contains("--max-step 1e-300") && err.contains("degrees"),
        "{err}"
    );
    let (ok, _, err) = run(&["fold", "patterns/many/miura_4x4.fold", "--to", "1e-300", "--out", &out]);
    assert!(
        !ok && err.contains("--to 1e-300") && err.contains("[0.1, 100]"),
        "{err}"
    );
    // Every crease locked: rank 0 with a threshold of 0, not null.
    let mut locked: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/many/miura_4x4_folded.fold").unwrap()).unwrap();
    let all: Vec<bool> = locked["edges_assignment"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a == "M" || a == "V")
        .collect();
    locked["edges_nanofold:locked"] = serde_json::json!(all);
    let file = dir.join("locked.fold");
    std::fs::write(&file, locked.to_string()).unwrap();
    let (ok, stdout, _) = run(&["check", "--json", &file.display().to_string()]);
    let value: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert!(ok && value["rank_threshold"] == 0.0 && value["dof"] == 0, "{value}");
    // A start that is not rigid: not_rigid, its energies absent.
    let (ok, stdout, _) = run(&["unfold", "--json", "patterns/many/miura_4x4_bent.fold", "--out", &out]);
    let value: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert!(ok && value["verdict"] == "not_rigid", "{value}");
    assert!(
        value["energy_initial"].is_null() && value["energy_final"].is_null(),
        "{value}"
    );
    // Generators: the edge count is the pattern's own; a length far below the tolerances is
    // refused by its range.
    let miura = dir.join("miura.fold").display().to_string();
    let (ok, stdout, err) = run(&["generate", "miura", "--rows", "174", "--cols", "174", "--out", &miura]);
    assert!(ok && stdout.contains("60204 creases"), "{stdout}{err}");
    // One more row and column passes the interior vertices' limit, refused by name.
    let (ok, _, err) = run(&["generate", "miura", "--rows", "175", "--cols", "175", "--out", &miura]);
    assert!(
        !ok && err.contains("--rows, --cols") && err.contains("30276 interior vertices"),
        "{err}"
    );
    let (ok, _, err) = run(&["generate", "bird-base", "--half-side", "1e-300", "--out", &miura]);
    assert!(!ok && err.contains("half_side") && err.contains("[1e-6, 1e6]"), "{err}");
    // A vertex that no edge uses (a stray point, valid FOLD): left out and said so; the
    // answers are those of the same paper without it.
    let clean = "patterns/many/miura_4x4_folded.fold";
    let mut stray: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(clean).unwrap()).unwrap();
    stray["vertices_coords"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!([0.3, 0.3]));
    let file = dir.join("stray.fold");
    std::fs::write(&file, stray.to_string()).unwrap();
    let path = file.display().to_string();
    for command in ["check", "unfold"] {
        let json_of = |pattern: &str, out: &str| {
            let mut args = vec![command, pattern, "--json"];
            if command == "unfold" {
                args.extend(["--out", out]);
            }
            let (ok, stdout, err) = run(&args);
            assert!(ok, "{command} {pattern}: {err}");
            serde_json::from_str::<serde_json::Value>(stdout.trim()).unwrap()
        };
        let (with, without) = (
            json_of(&path, &format!("{out}/stray")),
            json_of(clean, &format!("{out}/clean")),
        );
        assert_eq!(with["verdict"], without["verdict"], "{command}: {with}");
        let notes = with.to_string();
        assert!(notes.contains("vertices_coords[25] on no edge"), "{command}: {notes}");
        for key in ["dof", "final_fold_angles_rad", "iterations"] {
            assert_eq!(with[key], without[key], "{command}: {key}");
        }
    }
    let (ok, stdout, err) = run(&["fold", &path, "--to", "50", "--out", &format!("{out}/stray_fold")]);
    assert!(ok && stdout.contains("vertices_coords[25] on no edge"), "{stdout}{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fit_writes_its_files_and_refuses_bad_input_by_name_writing_nothing() {
    let dir = temp_dir("fit");
    let measured = "patterns/measurements/bridge_step_measured.csv";
    // A short window of one hinge keeps the run quick; the file's own values are the truth.
    let short = dir.with_extension("short.csv");
    let text = std::fs::read_to_string(measured).unwrap();
    let kept: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).take(61).collect();
    std::fs::write(&short, kept.join("\n") + "\n").unwrap();
    let (_, json) = json_run(
        nanofold()
            .args(["fit", "patterns/bridge_step.scene.json"])
            .arg(&short)
            .args(["--free", "environment.drag_coefficient=0.2:5", "--json", "--out"])
            .arg(&dir),
    );
    assert_eq!(json["status"], "converged");
    assert_eq!(json["parameters"][0]["path"], "environment.drag_coefficient");
    for file in ["fit.json", "fit.csv", "fitted.scene.json", "fit.svg", "response.html"] {
        assert!(dir.join(file).is_file(), "{file} missing");
    }
    // The fitted scene is a scene file `simulate` reads, with the estimate in it.
    let fitted: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fitted.scene.json")).unwrap()).unwrap();
    assert_eq!(
        fitted["environment"]["drag_coefficient"],
        json["parameters"][0]["estimate"]
    );
    let out = nanofold()
        .arg("simulate")
        .arg(dir.join("fitted.scene.json"))
        .arg("--out")
        .arg(dir.with_extension("sim"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));

    let bad = |name: &str, csv: Option<&str>, free: &str, expected: &[&str]| {
        let out_dir = temp_dir(&format!("fit-bad-{name}"));
        let file = out_dir.with_extension("csv");
        std::fs::write(&file, csv.unwrap_or(&(kept.join("\n") + "\n"))).unwrap();
        let out = nanofold()
            .args(["fit", "patterns/bridge_step.scene.json"])
            .arg(&file)
            .args(["--free", free, "--out"])
            .arg(&out_dir)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}: succeeded");
        for part in expected {
            assert!(stderr.contains(part), "{name}: {stderr}");
        }
        assert!(!out_dir.exists(), "{name}: wrote its folder");
        let _ = std::fs::remove_file(&file);
    };
    let drag = "environment.drag_coefficient=0.2:5";
    bad(
        "path",
        None,
        "environment.drag_coeficient=0.2:5",
        &["drag_coeficient", "no key"],
    );
    bad(
        "bounds",
        None,
        "environment.drag_coefficient=2:5",
        &["exclude the scene's value 1.28"],
    );
    bad(
        "time",
        Some("time_s,hinge_0_deg\n0,0\n1e-6,1\n1e-6,2\n"),
        drag,
        &["time_s", "must increase"],
    );
    bad(
        "nan",
        Some("time_s,hinge_0_deg\n0,0\n1e-6,NaN\n"),
        drag,
        &["hinge_0_deg", "NaN"],
    );
    bad("text", Some("time_s,hinge_0_deg\n0,0\n1e-6,abc\n"), drag, &["abc"]);
    bad(
        "column",
        Some("time_s,hinge_7_deg\n0,0\n1e-6,1\n"),
        drag,
        &["hinge_7_deg", "hinges 0 to 3"],
    );
    bad(
        "few",
        Some("time_s,hinge_0_deg\n1e-6,1\n"),
        drag,
        &["1 observations", "more observations than parameters"],
    );
    for d in [&dir, &dir.with_extension("sim")] {
        let _ = std::fs::remove_dir_all(d);
    }
    let _ = std::fs::remove_file(&short);
}

#[test]
fn nets_ranks_the_cubes_eleven_and_writes_each_best_net_as_fold() {
    let dir = temp_dir("nets-cube");
    let (out, report) = json_run(
        nanofold()
            .args([
                "nets",
                "cube",
                "--top",
                "3",
                "--simulate",
                "3",
                "--fronts",
                "0",
                "--yield-samples",
                "4",
                "--json",
                "--out",
            ])
            .arg(&dir),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(report["distinct_nets"], 11);
    // The three simulated, released at once: every hinge passes 90° together on the step's
    // path (driven to 95°), and every seam shuts there.
    for net in &report["nets"].as_array().unwrap()[..3] {
        let release = &net["closing"]["releases"][0];
        assert_eq!(release["front_deg"], serde_json::Value::Null);
        assert_eq!(release["outcome"], "closes", "{net}");
        assert_eq!(release["latched"], 7);
        assert_eq!(release["yield"]["samples"], 4);
    }
    assert_eq!(report["nets"][3]["closing"], serde_json::Value::Null);
    // Three nets, one release of a nominal and 4 varied devices each, then 4 fresh ones at
    // each of the captures 10, 5 and 20 %.
    assert_eq!(report["study"]["devices"], 3 * (5 + 3 * 4));
    for net in &report["nets"].as_array().unwrap()[..3] {
        let captures: Vec<f64> = net["closing"]["capture_yields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["capture_percent"].as_f64().unwrap())
            .collect();
        assert_eq!(captures, [5.0, 20.0], "{net}");
    }
    assert_eq!(report["symmetry_order"], 48);
    assert_eq!(report["search"], "enumerated");
    let rg: Vec<f64> = report["nets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["radius_of_gyration_um"].as_f64().unwrap())
        .collect();
    assert!(rg.windows(2).all(|w| w[0] <= w[1]), "ranked by Rg: {rg:?}");
    for k in 1..=3 {
        let fold = std::fs::read_to_string(dir.join(format!("net_{k:03}.fold"))).unwrap();
        let pattern = nanofold::read::parse_crease_pattern(&fold, "net", "net.fold").unwrap();
        assert_eq!((pattern.faces.len(), pattern.creases.len()), (6, 5));
    }
    assert!(!dir.join("net_004.fold").exists());
    // The best net's ready scene, released at once: its walls rise and first meet where its
    // seams are, each pair of faces that touches meeting along a seam's two edges.
    let (_, run) = json_run(
        nanofold()
            .args(["simulate", "--json", "--out"])
            .arg(temp_dir("nets-cube-simulated"))
            .arg(dir.join("net_001.scene.json")),
    );
    let fold: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("net_001.fold")).unwrap()).unwrap();
    let seams: Vec<[u64; 2]> = serde_json::from_value(fold["nanofold:seams"].clone()).unwrap();
    let edge_of = |text: &str| -> u64 {
        let start = text.find("edges[").expect("an edge named") + 6;
        text[start..].split(']').next().unwrap().parse().unwrap()
    };
    let meeting = run["meeting_at_contact"].as_array().unwrap();
    assert!(!meeting.is_empty(), "{run}");
    for pair in meeting {
        let (a, b) = (edge_of(pair[0].as_str().unwrap()), edge_of(pair[1].as_str().unwrap()));
        assert!(
            seams.iter().any(|s| s == &[a.min(b), a.max(b)]),
            "edges {a} and {b} meet but are no seam: {seams:?}"
        );
    }
    for name in [
        "nets.json",
        "nets.csv",
        "gallery.svg",
        "net_001.scene.json",
        "closing.html",
    ] {
        assert!(dir.join(name).exists(), "{name}");
    }
    // Every release simulated closes: there is no jam to show.
    assert!(!dir.join("jam.html").exists());
    let csv = std::fs::read_to_string(dir.join("nets.csv")).unwrap();
    assert_eq!(csv.lines().count(), 12);
    assert!(csv.lines().nth(1).unwrap().contains(",step,closes,"), "{csv}");
    // Run again with fewer nets into the same folder: the old third net does not stay.
    let again = nanofold()
        .args(["nets", "cube", "--top", "2", "--simulate", "0", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(again.status.success(), "{}", String::from_utf8_lossy(&again.stderr));
    assert!(dir.join("net_002.scene.json").exists() && !dir.join("net_003.fold").exists());
    assert!(
        !dir.join("closing.html").exists(),
        "nothing simulated, so no closing page stays"
    );
    // A bad shape or setting is refused by name, with nothing written.
    let bad_dir = temp_dir("nets-bad");
    for (args, part) in [
        (vec!["nets", "box:1x2"], "box:AxBxC"),
        (vec!["nets", "prism:2"], "sides"),
        (vec!["nets", "cube", "--top", "500"], "--top"),
        (vec!["nets", "cube", "--unit-um", "-1"], "--unit-um"),
        (vec!["nets", "sphere"], "shape"),
        (vec!["nets", "cube", "--overdrive-deg", "50"], "--overdrive-deg"),
        (
            vec!["nets", "cube", "--etch-rate-um-per-min", "0"],
            "--etch-rate-um-per-min",
        ),
        (vec!["nets", "cube", "--anchored-face", "9"], "--anchored-face"),
        (vec!["nets", "cube", "--capture-percent", "0"], "--capture-percent"),
        (
            vec!["nets", "cube", "--stress-spread-percent", "40"],
            "--stress-spread-percent",
        ),
        (
            vec!["nets", "cube", "--stiffness-spread-percent", "-1"],
            "--stiffness-spread-percent",
        ),
        (vec!["nets", "cube", "--yield-samples", "20000"], "--yield-samples"),
        (vec!["nets", "cube", "--fronts", "1000"], "--fronts"),
        (vec!["nets", "cube", "--simulate", "500"], "--simulate"),
        (
            vec!["nets", "cube", "--rank-by", "yield", "--simulate", "0"],
            "--rank-by",
        ),
    ] {
        let out = nanofold().args(&args).arg("--out").arg(&bad_dir).output().unwrap();
        assert!(!out.status.success());
        let message = String::from_utf8_lossy(&out.stderr);
        assert!(message.contains(part), "{args:?}: {message}");
        assert!(!bad_dir.exists(), "{args:?} wrote its folder");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_bundled_cubes_closing_and_jam_come_back_through_the_nets_path() {
    // The cube's most compact net is the Latin cross; laid by `nets` its hub-to-lid arm runs
    // along −x where the bundled cube_net.fold's runs along +y, so the bundled front along
    // +y (closes) is 180° here and −y (jams) is 0°. Squares of 100 µm, hinges to 95°.
    for (bundled, front) in [("cube_closes", "180"), ("cube_lid_first", "0")] {
        let dir = temp_dir(&format!("nets-{bundled}"));
        let made = nanofold()
            .args([
                "nets",
                "cube",
                "--top",
                "1",
                "--unit-um",
                "50",
                "--overdrive-deg",
                "5",
                "--front-deg",
                front,
            ])
            .arg("--out")
            .arg(&dir)
            .output()
            .unwrap();
        assert!(made.status.success(), "{}", String::from_utf8_lossy(&made.stderr));
        let (_, ours) = json_run(
            nanofold()
                .args(["simulate", "--json", "--out"])
                .arg(dir.join("run"))
                .arg(dir.join("net_001.scene.json")),
        );
        let (_, theirs) = json_run(
            nanofold()
                .args(["simulate", "--json", "--out"])
                .arg(dir.join("bundled"))
                .arg(format!("patterns/devices/{bundled}.scene.json")),
        );
        let time = |run: &serde_json::Value| run["collision"]["time_s"].as_f64().unwrap();
        assert!(
            (time(&ours) - time(&theirs)).abs() <= 1e-9 * time(&theirs),
            "{bundled}: first contact at {} s through nets, {} s bundled",
            time(&ours),
            time(&theirs)
        );
        // The same number of pairs meeting where the runs end (both closed).
        assert_eq!(
            ours["meeting_at_contact"].as_array().map(Vec::len),
            theirs["meeting_at_contact"].as_array().map(Vec::len),
            "{bundled}"
        );
        // The design study carries the run on past that contact. The closing cube latches
        // its walls there and its lid 4000 s later. The other (which the first-touch rule
        // called a jam) has its lid pressed on a wall's edge: held by the contact force, it
        // slides along the edge and latches within the capture later.
        let table: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("nets.json")).unwrap()).unwrap();
        let release = &table["nets"][0]["closing"]["releases"][0];
        let ended = release["time_s"].as_f64().unwrap();
        assert_eq!(release["outcome"], "closes", "{bundled}: {release}");
        assert_eq!(release["latched"], 7, "{bundled}: {release}");
        assert!(ended > time(&theirs) * (1.0 + 1e-6), "{bundled}: {release}");
        if bundled == "cube_closes" {
            assert!(ended > time(&theirs) + 3999.0, "{release}");
        }
        // `simulate` of the scene the study wrote (its seams in the file) carries the
        // device through contact to the study's own end, and so does the bundled scene.
        for run in [&ours, &theirs] {
            assert_eq!(run["released"]["outcome"], "closes", "{bundled}: {}", run["released"]);
            let simulated = run["released"]["time_s"].as_f64().unwrap();
            assert!(
                (simulated - ended).abs() <= 1e-9 * ended,
                "{bundled}: {simulated} against {ended}"
            );
        }
        assert!(!dir.join("jam.html").exists(), "{bundled}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
