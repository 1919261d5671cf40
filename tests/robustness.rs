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

fn parse(text: &str) -> nanofold::Result<Pattern> {
    nanofold::io::parse_pattern(text, "test", "test.json", &LoadOptions::default())
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
    let report = unfold(&pattern, &UnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
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
    let e = nanofold::io::load_pattern(Path::new("/dev/zero"), &LoadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("not a regular file"), "{e}");
    let dir = scratch("size");
    let big = dir.join("big.fold");
    let file = std::fs::File::create(&big).unwrap();
    // Sparse: no disk is used.
    file.set_len(nanofold::io::input::MAX_PATTERN_BYTES + 1).unwrap();
    let e = nanofold::io::load_pattern(&big, &LoadOptions::default()).unwrap_err();
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
            "trajectory.json",
            "unfold.fold",
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
