//! Hostile and careless inputs (issue 17): every one gets a result or a clear error naming
//! the field and the value, within bounded time and memory, and nothing is written outside
//! the output folder or half-way. Each test here failed before its fix.

mod common;

use common::full_message;
use nanofold::pattern::LoadOptions;
use nanofold::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;

fn nanofold() -> Command {
    Command::new(env!("CARGO_BIN_EXE_nanofold"))
}

fn scratch(label: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nanofold-robust-{label}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn parse(text: &str) -> nanofold::Result<VertexPattern> {
    nanofold::read::parse_pattern(text, "test", "test.json", &LoadOptions::default())
}

fn error_of(text: &str) -> String {
    match parse(text) {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => full_message(&e),
    }
}

/// A flat closed vertex (every fold angle 0) with these sectors in degrees.
fn flat_vertex(sectors_deg: &[f64]) -> String {
    let creases = vec![r#"{"assignment":"U","fold_angle":0}"#; sectors_deg.len()];
    format!(
        r#"{{"chain":"closed","angle_unit":"deg","sector_angles":{sectors_deg:?},"creases":[{}]}}"#,
        creases.join(",")
    )
}

/// A single-vertex FOLD file whose creases leave the origin at these angles (rad).
fn fold_star(directions: &[f64]) -> String {
    let mut coords = vec!["[0,0]".to_string()];
    let mut edges = Vec::new();
    for (k, d) in directions.iter().enumerate() {
        coords.push(format!("[{},{}]", d.cos(), d.sin()));
        edges.push(format!("[0,{}]", k + 1));
    }
    let n = directions.len();
    format!(
        r#"{{"vertices_coords":[{}],"edges_vertices":[{}],"edges_assignment":[{}],"edges_foldAngle":[{}]}}"#,
        coords.join(","),
        edges.join(","),
        vec![r#""U""#; n].join(","),
        vec!["0"; n].join(",")
    )
}

#[test]
fn a_sector_too_small_to_resolve_is_refused_by_name() {
    // Was: accepted, then `local_minimum` with |ρ| = π (the flat-folded back-off scaled zero
    // fold angles and the solver jumped to another branch).
    for tiny in [1e-8, 1e-10, 1e-12] {
        let e = error_of(&flat_vertex(&[tiny, 90.0, 90.0, 180.0 - tiny]));
        assert!(e.contains("sector_angles[0]") && e.contains("1e-6 rad"), "{e}");
    }
}

#[test]
fn a_flat_start_with_the_smallest_accepted_sector_is_flat_at_once() {
    let a = 1.1e-6_f64.to_degrees();
    let pattern = parse(&flat_vertex(&[a, 90.0, 90.0, 180.0 - a])).unwrap();
    let report = unfold_vertex(&pattern, &UnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, UnfoldVerdict::Flat, "{}", report.evidence);
    assert_eq!(report.iterations, 0);
    let largest = report.final_fold_angles_rad.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
    assert!(largest <= 1e-12, "{largest}");
}

#[test]
fn near_coincident_rays_across_zero_are_refused() {
    // Was: the same-direction check compared sorted neighbours only, so rays at 0 and
    // 2π − 1e-9 passed and got a wrong verdict.
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let e = error_of(&fold_star(&[0.0, FRAC_PI_2, PI, TAU - 1e-9]));
    assert!(e.contains("same direction") && e.contains("edges 3 and 0"), "{e}");
    // And between sorted neighbours, as before.
    let e = error_of(&fold_star(&[0.0, 1.0, 1.0 + 1e-9, PI]));
    assert!(e.contains("same direction"), "{e}");
}

#[test]
fn a_key_given_twice_in_a_pattern_is_refused() {
    // Was: the last one silently won.
    let text = r#"{"chain":"closed","angle_unit":"deg","angle_unit":"rad","sector_angles":[90,90,90,90],"creases":[]}"#;
    let e = error_of(text);
    assert!(e.contains("angle_unit") && e.contains("twice"), "{e}");
}

#[test]
fn devices_and_oversized_files_are_not_read() {
    // Was: `check /dev/zero` read until memory ran out.
    let e = nanofold::read::load_pattern(Path::new("/dev/zero"), &LoadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
    let dir = scratch("size");
    let big = dir.join("big.fold");
    let file = std::fs::File::create(&big).unwrap();
    // Sparse: no disk is used.
    file.set_len(nanofold::read::MAX_PATTERN_BYTES + 1).unwrap();
    let e = nanofold::read::load_pattern(&big, &LoadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("byte limit"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_pattern_name_never_leads_outside_the_output_folder() {
    // Was: a native pattern's `name` became the folder under output/, so "../.." or an
    // absolute path wrote anywhere.
    let dir = scratch("names");
    for (k, name) in ["../..", "..", "", "/tmp/elsewhere", "a/b", "."].iter().enumerate() {
        let file = dir.join(format!("vertex{k}.json"));
        let text = flat_vertex(&[90.0, 90.0, 90.0, 90.0]).replacen('{', &format!(r#"{{"name":{name:?},"#), 1);
        std::fs::write(&file, text).unwrap();
        let out = nanofold().current_dir(&dir).arg("unfold").arg(&file).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(
            dir.join("output")
                .join(format!("vertex{k}"))
                .join("unfold.svg")
                .is_file(),
            "{name:?}"
        );
    }
    // Nothing but the inputs and output/ in the folder, and nothing in output/ but the runs.
    let mut top: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".json"))
        .collect();
    top.sort();
    assert_eq!(top, ["output"]);
    assert_eq!(std::fs::read_dir(dir.join("output")).unwrap().count(), 6);
    assert!(!Path::new("/tmp/elsewhere").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_replaces_its_own_files_and_keeps_the_other_commands() {
    // Was: each file renamed separately, so a failure after the first left a mix.
    let dir = scratch("folder");
    let out = dir.join("cc");
    let run = |args: &[&str]| {
        let status = nanofold().args(args).arg("--out").arg(&out).output().unwrap();
        assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    };
    run(&["unfold", "patterns/corner_cube.fold"]);
    run(&[
        "constraints",
        "patterns/corner_cube.fold",
        "--drive",
        "0",
        "--lock",
        "1=0",
        "--range",
        "0:180",
    ]);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "constraints.json",
            "constraints.svg",
            "nanofold.json",
            "trajectory.json",
            "unfold.fold",
            "unfold.html",
            "unfold.svg"
        ]
    );
    // Only the folder beside it: no temporary left.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    // A folder holding someone else's files is not replaced.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let refused = nanofold()
        .args(["unfold", "patterns/corner_cube.fold", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("notes.txt"));
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn native_type_errors_name_the_field_and_the_value() {
    // Was: "invalid `native pattern`:  (invalid type: string "x", expected f64)".
    let text = r#"{"chain":"closed","angle_unit":"deg","sector_angles":[90,90,"x",90],"creases":[]}"#;
    let e = error_of(text);
    assert!(e.contains("`sector_angles[2]`") && e.contains(r#""x""#), "{e}");
    let text = r#"{"chain":"closed","angle_unit":"deg","sector_angles":[90,90,90,90],"creases":[{"assignment":"V","fold_angle":"10"}]}"#;
    let e = error_of(text);
    assert!(e.contains("`creases[0].fold_angle`") && e.contains(r#""10""#), "{e}");
}

#[test]
fn a_fold_file_without_geometry_is_told_what_fold_lacks() {
    // Was: read as a native vertex and told "missing key `chain`".
    let e = error_of(r#"{"file_spec":1.1,"edges_vertices":[[0,1]]}"#);
    assert!(e.contains("vertices_coords") && !e.contains("chain"), "{e}");
}

#[test]
fn a_non_ascii_value_in_an_error_is_cut_between_characters() {
    // Was: a panic, the message cut by bytes inside a UTF-8 character.
    let long = "é".repeat(100);
    let text = format!(
        r#"{{"vertices_coords":[[0,0],[1,0]],"edges_vertices":[[0,"{long}"]],"edges_assignment":["V"],"edges_foldAngle":[0]}}"#
    );
    let e = error_of(&text);
    assert!(e.contains("edges_vertices[0]") && e.contains('…'), "{e}");
}

#[test]
fn a_symlink_loop_runs_each_file_once() {
    // Was: the walk followed dir/self -> dir until the OS refused, running one file 41 times.
    let dir = scratch("loop");
    std::fs::copy("patterns/half_paper.fold", dir.join("half_paper.fold")).unwrap();
    std::os::unix::fs::symlink(&dir, dir.join("self")).unwrap();
    std::os::unix::fs::symlink(dir.join("half_paper.fold"), dir.join("again.fold")).unwrap();
    let out = nanofold()
        .args(["unfold", "--json", "--out"])
        .arg(dir.join("out"))
        .arg(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let runs: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(runs.as_array().map_or(1, Vec::len), 1, "{runs}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn thousands_of_jobs_are_refused_by_name() {
    // Was: --jobs 100000 started thousands of threads (5000 took 76 s).
    let out = nanofold()
        .args(["unfold", "patterns/half_paper.fold", "--jobs", "100000"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--jobs") && stderr.contains("100000") && stderr.contains("256"),
        "{stderr}"
    );
}

/// The bridge scene with `from` replaced by `to` (every occurrence), parsed and built.
fn bridge_with(from: &str, to: &str) -> nanofold::Result<nanofold::dynamics::scene::Scene> {
    let text = std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap();
    assert!(text.contains(from), "{from}");
    common::scene_text(&text.replace(from, to))
}

fn scene_error(result: nanofold::Result<nanofold::dynamics::scene::Scene>) -> String {
    match result {
        Ok(_) => panic!("accepted"),
        Err(e) => full_message(&e),
    }
}

#[test]
fn extreme_magnitudes_are_refused_by_name_before_they_become_nan() {
    // Was: air density or drag coefficient 1e30 gave a contact at 2.7e-43 s with NaN
    // angles (exit 0); 1e20 and moduli, thicknesses or length units of 1e±300 hung.
    for (from, to, field) in [
        (
            r#""air_density_kg_m3": 1.2"#,
            r#""air_density_kg_m3": 1e30"#,
            "environment.air_density_kg_m3",
        ),
        (
            r#""air_density_kg_m3": 1.2"#,
            r#""air_density_kg_m3": 1e20"#,
            "environment.air_density_kg_m3",
        ),
        (
            r#""drag_coefficient": 1.28"#,
            r#""drag_coefficient": 1e30"#,
            "environment.drag_coefficient",
        ),
        (
            r#""youngs_modulus_gpa": 300"#,
            r#""youngs_modulus_gpa": 1e300"#,
            "materials.SiN.youngs_modulus_gpa",
        ),
        (
            r#""youngs_modulus_gpa": 300"#,
            r#""youngs_modulus_gpa": 1e-300"#,
            "materials.SiN.youngs_modulus_gpa",
        ),
        (
            r#""density_g_cm3": 3.27"#,
            r#""density_g_cm3": 1e-20"#,
            "materials.SiN.density_g_cm3",
        ),
        (
            r#""thickness_um": 0.1"#,
            r#""thickness_um": 1e-300"#,
            "hinges[0].layers[1].thickness_um",
        ),
        (r#""length_um": 400"#, r#""length_um": 1e300"#, "plates[1].length_um"),
        (r#""t_end_s": 0.002"#, r#""t_end_s": 1e300"#, "time.t_end_s"),
    ] {
        let e = scene_error(bridge_with(from, to));
        assert!(e.contains(field) && e.contains("must lie in"), "{to}: {e}");
    }
}

#[test]
fn output_sample_counts_are_bounded_by_name() {
    // Was: 2^64 − 1 overflowed a capacity (a panic) and 1e12 asked for 8 TB.
    for (value, shown) in [
        ("18446744073709551615", "18446744073709551615"),
        ("1000000000000", "1000000000000"),
    ] {
        let e = scene_error(bridge_with(r#""samples": 401"#, &format!(r#""samples": {value}"#)));
        assert!(e.contains("outputs.samples") && e.contains(shown), "{e}");
    }
    let e = scene_error(bridge_with(r#""samples": 401"#, r#""samples": 1e12"#));
    assert!(e.contains("outputs.samples"), "{e}");
    let e = scene_error(bridge_with(r#""snapshots": 6"#, r#""snapshots": 100000"#));
    assert!(e.contains("outputs.snapshots"), "{e}");
}

#[test]
fn a_strip_of_a_thousand_plates_is_refused() {
    // Was: a 300 KB scene of 1000 plates took more than 12 GB (∂M has n³ entries).
    let text = std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(&text).unwrap();
    let plate = scene["plates"][0].clone();
    let hinge = scene["hinges"][0].clone();
    scene["plates"] = serde_json::Value::Array(vec![plate; 1000]);
    scene["hinges"] = serde_json::Value::Array(vec![hinge; 1000]);
    let e = scene_error(common::scene_text(&scene.to_string()));
    assert!(
        e.contains("`plates`") && e.contains("1000") && e.contains("100]"),
        "{e}"
    );
}

/// Writes a copy of the corner cube's plates with `faces` into `dir` and a step-1 scene
/// over it; returns the scene's load-and-build result.
fn corner_cube_with_faces(
    dir: &Path,
    faces: serde_json::Value,
    extra_vertex: Option<[f64; 2]>,
) -> nanofold::Result<nanofold::dynamics::scene::Scene> {
    let mut fold: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/corner_cube_plates.fold").unwrap()).unwrap();
    fold["faces_vertices"] = faces;
    if let Some(point) = extra_vertex {
        fold["vertices_coords"]
            .as_array_mut()
            .unwrap()
            .push(serde_json::json!(point));
    }
    std::fs::write(dir.join("plates.fold"), fold.to_string()).unwrap();
    let scene = std::fs::read_to_string("patterns/corner_cube_step1.scene.json")
        .unwrap()
        .replace("corner_cube_plates.fold", "plates.fold");
    std::fs::write(dir.join("step.scene.json"), scene).unwrap();
    nanofold::read::load_scene(&dir.join("step.scene.json"))?.build()
}

#[test]
fn faces_that_are_not_a_sector_plate_are_refused() {
    // Was: a face listed twice doubled the plate's mass, a zero-area face passed as convex,
    // and a face reaching across a crease made the run hang.
    let dir = scratch("faces");
    let good = serde_json::json!([[0, 1, 2], [0, 2, 3, 4], [0, 4, 5, 6], [0, 6, 7, 8], [0, 8, 1]]);
    assert!(corner_cube_with_faces(&dir, good, None).is_ok());
    let twice = serde_json::json!([[0, 1, 2, 0, 1, 2], [0, 2, 3, 4], [0, 4, 5, 6], [0, 6, 7, 8], [0, 8, 1]]);
    let e = scene_error(corner_cube_with_faces(&dir, twice, None));
    assert!(e.contains("faces_vertices[0]") && e.contains("appears twice"), "{e}");
    // Vertex 9 halfway along crease 0 (0 → 1): the face 0, 9, 1 has no area.
    let flat = serde_json::json!([[0, 9, 1], [0, 2, 3, 4], [0, 4, 5, 6], [0, 6, 7, 8], [0, 8, 1]]);
    let e = scene_error(corner_cube_with_faces(
        &dir,
        flat,
        Some([std::f64::consts::FRAC_1_SQRT_2, 0.0]),
    ));
    assert!(e.contains("faces_vertices[0]") && e.contains("no area"), "{e}");
    let across = serde_json::json!([[0, 1, 2, 3, 4], [0, 4, 5, 6], [0, 6, 7, 8], [0, 8, 1]]);
    let e = scene_error(corner_cube_with_faces(&dir, across, None));
    assert!(e.contains("faces_vertices[0]") && e.contains("out of sector"), "{e}");
    let apart = serde_json::json!([[1, 2, 3], [0, 2, 3, 4], [0, 4, 5, 6], [0, 6, 7, 8], [0, 8, 1]]);
    let e = scene_error(corner_cube_with_faces(&dir, apart, None));
    assert!(
        e.contains("faces_vertices[0]") && e.contains("does not touch the vertex"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn closed_scene_errors_name_the_scene_fields() {
    // Was: a closed scene's constraint errors named the CLI's --degree and --samples.
    let text = std::fs::read_to_string("patterns/corner_cube_step1.scene.json").unwrap();
    let e = scene_error(common::scene_text(&text.replace(r#""degree": 8"#, r#""degree": 25"#)));
    assert!(e.contains("constraint.degree") && !e.contains("--"), "{e}");
    let e = scene_error(common::scene_text(
        &text.replace(r#""degree": 8,"#, r#""degree": 8, "samples": 18446744073709551615,"#),
    ));
    assert!(e.contains("constraint.samples") && e.contains("100000"), "{e}");
    let e = scene_error(common::scene_text(
        &text.replace(r#""target_angle_deg": 180"#, r#""target_angle_deg": 181"#),
    ));
    assert!(e.contains("hinges[0].target_angle_deg") && e.contains("181"), "{e}");
}

/// Runs the binary with `args`, killing it (and failing) if it has not finished in
/// `limit_s`: a hang must fail the test, not stall the suite.
fn run_bounded(args: &[&str], limit_s: u64) -> std::process::Output {
    let mut child = nanofold()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed().as_secs() > limit_s {
            child.kill().unwrap();
            panic!("{args:?} did not finish in {limit_s} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn a_narrow_sweep_far_from_the_fold_finishes() {
    // Was: the continuation step was capped by the sample spacing, so reaching
    // 90°–90.001° from the folded 162° took ~10⁵ Newton steps (48 s); a 1e-12° range hung.
    let dir = scratch("narrow");
    for range in ["90:90.001", "90:90.000000000001"] {
        let out = run_bounded(
            &[
                "constraints",
                "patterns/corner_cube.fold",
                "--drive",
                "0",
                "--lock",
                "1=0",
                "--range",
                range,
                "--out",
                dir.join("c").to_str().unwrap(),
            ],
            60,
        );
        assert!(
            out.status.success(),
            "{range}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_dense_sweep_through_the_flat_state_is_not_refused() {
    // Was: "no solution beyond 0.2°" at 5001 samples and more.
    use nanofold::constraints::{sweep_samples, Setup};
    let pattern =
        nanofold::read::load_pattern(Path::new("patterns/corner_cube.fold"), &LoadOptions::default()).unwrap();
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    for samples in [5001, 20001] {
        let curve = sweep_samples(&pattern, &setup, [0.0, std::f64::consts::PI], samples).unwrap();
        assert_eq!(curve.drive_angles.len(), samples);
        assert!(curve.max_closure_residual < 1e-12);
    }
    let e = sweep_samples(&pattern, &setup, [0.0, 1.0], usize::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains("samples") && e.contains("100000"), "{e}");
}

#[test]
fn four_hundred_flat_held_creases_unfold() {
    // Was: refused with "restoration residual 2.1e-13": the tolerance did not grow with n.
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/degree4_native.json").unwrap()).unwrap();
    let (mut sectors, mut creases) = (Vec::new(), Vec::new());
    for k in 0..4 {
        creases.push(base["creases"][k].clone());
        for j in 0..100 {
            sectors.push(base["sector_angles"][k].as_f64().unwrap() / 100.0);
            if j < 99 {
                creases.push(serde_json::json!({"assignment": "F", "fold_angle": 0}));
            }
        }
    }
    let text =
        serde_json::json!({"chain": "closed", "angle_unit": "deg", "sector_angles": sectors, "creases": creases});
    let pattern = parse(&text.to_string()).unwrap();
    let report = unfold_vertex(&pattern, &UnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, UnfoldVerdict::Flat, "{}", report.evidence);
    assert!(report.flat_layout_error < 1e-10, "{}", report.flat_layout_error);
}

#[test]
fn a_fold_mesh_too_large_for_its_outputs_is_refused() {
    // Was: a 42 MB FOLD file took 3.8 GB and wrote a 1.07 GB unfold.fold (every frame
    // repeats the mesh).
    let mut fold: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/corner_cube.fold").unwrap()).unwrap();
    let extra: Vec<serde_json::Value> = (0..5000).map(|i| serde_json::json!([10.0 + i as f64, 10.0])).collect();
    fold["vertices_coords"].as_array_mut().unwrap().extend(extra);
    let e = error_of(&fold.to_string());
    assert!(e.contains("vertices_coords") && e.contains("4096"), "{e}");
}

#[test]
fn extreme_solver_settings_are_refused_by_name() {
    // Was: `--p 1e-300` and `--bending-metric 1e300` gave a confident local_minimum.
    let p = UnfoldSettings {
        p: Some(1e-300),
        ..Default::default()
    };
    assert!(p.validate().unwrap_err().to_string().contains("`p`"));
    let metric = UnfoldSettings {
        bending_metric: 1e300,
        ..Default::default()
    };
    assert!(metric.validate().unwrap_err().to_string().contains("bending_metric"));
    for (flag, value) in [("--p", "1e-300"), ("--bending-metric", "1e300")] {
        let out = nanofold()
            .args(["unfold", "patterns/corner_cube.fold", flag, value])
            .output()
            .unwrap();
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(flag), "{stderr}");
    }
    // And a sample count past any allocation is refused, not a capacity overflow.
    let out = nanofold()
        .args([
            "constraints",
            "patterns/corner_cube.fold",
            "--drive",
            "0",
            "--lock",
            "1=0",
        ])
        .args(["--samples", "18446744073709551615"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--samples") && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn closed_scene_magnitudes_are_checked_like_a_strips() {
    // Was: no mass or stiffness sanity check on closed scenes; a length unit of 1e300 hung.
    let text = std::fs::read_to_string("patterns/corner_cube_step1.scene.json").unwrap();
    let e = scene_error(common::scene_text(
        &text.replace(r#""length_unit_um": 300"#, r#""length_unit_um": 1e300"#),
    ));
    assert!(e.contains("length_unit_um") && e.contains("must lie in"), "{e}");
    // In range, but the creases come out 1e-6 µm long.
    let e = scene_error(common::scene_text(
        &text.replace(r#""length_unit_um": 300"#, r#""length_unit_um": 1e-6"#),
    ));
    assert!(e.contains("length of crease") && e.contains("must lie in"), "{e}");
    let e = scene_error(common::scene_text(
        &text.replace(r#""thickness_um": 0.2,"#, r#""thickness_um": 1e-300,"#),
    ));
    assert!(e.contains("plates.thickness_um"), "{e}");
}

#[test]
fn a_file_of_the_wrong_kind_is_told_what_it_is() {
    // Was: "missing key `chain`" for a scene given to unfold or a top-level array, an
    // "unknown key edges_assignment" for a pattern given to simulate, and a missing
    // pattern file named without the scene field that points to it.
    let scene = std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap();
    let e = error_of(&scene);
    assert!(e.contains("a scene file") && e.contains("simulate"), "{e}");
    let e = error_of("[1, 2, 3]");
    assert!(e.contains("one JSON object"), "{e}");
    let e = error_of("{}");
    assert!(
        e.contains("missing key `chain`") && e.contains("vertices_coords"),
        "{e}"
    );
    let fold = std::fs::read_to_string("patterns/corner_cube.fold").unwrap();
    let e = scene_error(common::scene_text(&fold));
    assert!(e.contains("a pattern file") && e.contains("unfold"), "{e}");
    let closed = std::fs::read_to_string("patterns/corner_cube_step1.scene.json")
        .unwrap()
        .replace("corner_cube_plates.fold", "nothere.fold");
    let e = scene_error(common::scene_text(&closed));
    assert!(
        e.contains("`pattern`") && e.contains("nothere.fold") && e.contains("cannot read"),
        "{e}"
    );
}

/// Runs the binary on files in a scratch folder; returns (exit code, stdout, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out = nanofold().current_dir(dir).args(args).output().unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.code(), text(&out.stdout), text(&out.stderr))
}

#[test]
fn a_sheet_with_no_face_or_an_edge_sticking_out_is_refused_by_name() {
    // Was: an index panic in the panel tree (no face) and in the panel poses (an edge with
    // no paper on either side), in `unfold` and `fold`.
    let dir = scratch("degenerate-sheet");
    std::fs::write(
        dir.join("one_edge.fold"),
        r#"{"vertices_coords":[[0,0],[1,0]],"edges_vertices":[[0,1]],"edges_assignment":["B"]}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("sticking_out.fold"),
        r#"{"vertices_coords":[[0,0],[1,0],[1,1],[0,1],[2,0]],"edges_vertices":[[0,1],[1,2],[2,3],[3,0],[1,4]],"edges_assignment":["B","B","B","B","B"]}"#,
    )
    .unwrap();
    for (file, field, words) in [
        ("one_edge.fold", "`edges_vertices`", "no region"),
        (
            "sticking_out.fold",
            "`edges_vertices[4]`: [1, 4]",
            "sticks out of the paper",
        ),
    ] {
        for command in ["unfold", "fold"] {
            let (code, _, stderr) = run_in(&dir, &[command, file, "--out", "out"]);
            assert_eq!(code, Some(2), "{command} {file}: {stderr}");
            assert!(
                stderr.contains(file) && stderr.contains(field) && stderr.contains(words),
                "{command} {file}: {stderr}"
            );
        }
        let (code, stdout, _) = run_in(&dir, &["check", file]);
        assert_eq!(code, Some(1), "check {file}: {stdout}");
        assert!(stdout.contains(field), "check {file}: {stdout}");
    }
    assert!(!dir.join("out").exists(), "nothing is written for a refused file");
}

#[test]
fn a_flat_sheet_without_creases_is_flat_and_a_non_rigid_start_prints_no_nan() {
    // Was: `locked` for the flat square in `unfold` (its DOF test came before the flat
    // test), `not_rigidly_foldable` in `check`, and
    // "energy NaN -> NaN" for a start that does not close.
    let dir = scratch("flat-square");
    std::fs::write(
        dir.join("square.fold"),
        r#"{"vertices_coords":[[0,0],[2,0],[2,2],[0,2]],"edges_vertices":[[0,1],[1,2],[2,3],[3,0]],"edges_assignment":["B","B","B","B"]}"#,
    )
    .unwrap();
    let (code, stdout, stderr) = run_in(&dir, &["unfold", "square.fold", "--json", "--out", "out"]);
    assert_eq!(code, Some(0), "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["verdict"], "flat", "{stdout}");
    // `check` was `not_rigidly_foldable` for it: there is no assignment to fail.
    let (code, stdout, _) = run_in(&dir, &["check", "square.fold"]);
    assert_eq!(code, Some(0), "{stdout}");
    assert!(
        stdout.contains(": rigid (") && stdout.contains("no creases"),
        "{stdout}"
    );
    // A crease that ends inside the paper, folded: no rigid state has it.
    std::fs::write(
        dir.join("slit.fold"),
        r#"{"vertices_coords":[[0,0],[2,0],[2,2],[0,2],[1,1]],"edges_vertices":[[0,1],[1,2],[2,3],[3,0],[0,4]],"edges_assignment":["B","B","B","B","V"],"edges_foldAngle":[0,0,0,0,90]}"#,
    )
    .unwrap();
    let (code, stdout, stderr) = run_in(&dir, &["unfold", "slit.fold", "--out", "out-slit"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stdout.contains("not_rigid") && stdout.contains("energy not evaluated"),
        "{stdout}"
    );
    assert!(!stdout.contains("NaN"), "{stdout}");
}

#[test]
fn every_loader_error_names_its_file_once() {
    // Was: "missing key `actuation`" and "invalid `edges_vertices[7]`" with no file named,
    // and "F: error: reading F: F: malformed JSON" in `check`.
    let dir = scratch("loader-errors");
    let mut scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap()).unwrap();
    scene.as_object_mut().unwrap().remove("actuation");
    std::fs::write(dir.join("no_actuation.scene.json"), scene.to_string()).unwrap();
    for command in ["simulate", "modes"] {
        let (code, _, stderr) = run_in(&dir, &[command, "no_actuation.scene.json"]);
        assert_eq!(code, Some(2), "{stderr}");
        assert!(
            stderr.contains("no_actuation.scene.json") && stderr.contains("missing key `actuation`"),
            "{command}: {stderr}"
        );
    }
    std::fs::write(
        dir.join("bad_index.fold"),
        r#"{"vertices_coords":[[0,0],[1,0],[0,1],[-1,0],[0,-1]],"edges_vertices":[[0,1],[0,2],[0,3],[0,4],[1,2],[2,3],[3,4],[4,9]],"edges_assignment":["M","V","M","V","B","B","B","B"]}"#,
    )
    .unwrap();
    std::fs::write(dir.join("cut_short.fold"), "{").unwrap();
    for args in [
        vec!["unfold", "bad_index.fold", "--out", "out"],
        vec!["fold", "bad_index.fold", "--out", "out"],
        vec!["constraints", "bad_index.fold", "--drive", "0", "--out", "out"],
    ] {
        let (code, _, stderr) = run_in(&dir, &args);
        assert_eq!(code, Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains("bad_index.fold") && stderr.contains("`edges_vertices[7]`: 9"),
            "{args:?}: {stderr}"
        );
    }
    let (_, stdout, _) = run_in(&dir, &["check", "cut_short.fold", "bad_index.fold"]);
    for file in ["cut_short.fold", "bad_index.fold"] {
        let line = stdout.lines().find(|l| l.starts_with(file)).unwrap_or_default();
        assert_eq!(line.matches(file).count(), 1, "{stdout}");
        assert!(line.contains(": error: "), "{stdout}");
    }
}

#[test]
fn a_cone_prints_no_nan_for_its_missing_flat_layout() {
    // Was: "flat layout error NaN" for a vertex whose sectors do not sum to 360°.
    let dir = scratch("cone");
    let cone = std::fs::canonicalize("patterns/cone.json").unwrap();
    let (code, stdout, stderr) = run_in(&dir, &["unfold", cone.to_str().unwrap(), "--out", "out"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("not_flat_foldable"), "{stdout}");
    assert!(stdout.contains("flat layout error none (no flat state)"), "{stdout}");
    assert!(!stdout.contains("NaN"), "{stdout}");
}
