//! Patterns whose shape once made the broad phases or the DOF count blow up (a vertex far
//! from the rest, long strips, accordions of thin panels, layers stacked deep): each gets
//! its answer, and a stacked state says it passed the contact test's budget instead of
//! measuring every pair. Their times and memory at the limits are in README's Limits table
//! (measured in release mode, not here).

mod common;

use nanofold::prelude::*;

/// A grid of n × n unit squares (`common::grid_fold`); with `far`, its last corner moved
/// to (far, far).
fn grid(n: usize, far: Option<f64>) -> String {
    common::grid_fold(n, 0.0, far).to_string()
}

/// A strip of `panels` panels `width` × `height` side by side, creases alternating.
fn strip(panels: usize, width: f64, height: f64) -> String {
    common::strip_fold(panels, width, height).to_string()
}

fn check_text(text: &str) -> Report<CheckVerdict> {
    let pattern = Pattern::parse(text, "large", "large", &LoadOptions::default()).unwrap();
    check(&pattern, &Settings::default()).unwrap()
}

fn dof(report: &Report<CheckVerdict>) -> usize {
    let Detail::NetworkCheck(engine, _) = &report.detail else {
        panic!("a crease pattern of many vertices");
    };
    engine.rank.dof
}

fn witness(report: &Report<CheckVerdict>) -> &nanofold::folding::FoldPath {
    let Detail::NetworkCheck(engine, _) = &report.detail else {
        panic!("a crease pattern of many vertices");
    };
    engine.witness.as_ref().expect("an assignment gets a witness path")
}

/// A corner moved a million units away leaves the grid's verdict and DOF as they were.
#[test]
fn a_vertex_far_from_the_rest_changes_nothing() {
    let near = check_text(&grid(30, None));
    let far = check_text(&grid(30, Some(1e6)));
    assert_eq!(far.verdict, near.verdict, "{}", far.evidence);
    assert_eq!(dof(&far), dof(&near));
    // Its edges' broad phase finds the pairs testing every pair would (two long edges
    // cross the whole grid's box).
    let value: serde_json::Value = serde_json::from_str(&grid(12, Some(1e6))).unwrap();
    let coords: Vec<[f64; 2]> = serde_json::from_value(value["vertices_coords"].clone()).unwrap();
    let edges: Vec<[usize; 2]> = serde_json::from_value(value["edges_vertices"].clone()).unwrap();
    let boxes: Vec<([f64; 2], [f64; 2])> = edges
        .iter()
        .map(|&[a, b]| {
            let (p, q) = (coords[a], coords[b]);
            ([p[0].min(q[0]), p[1].min(q[1])], [p[0].max(q[0]), p[1].max(q[1])])
        })
        .collect();
    let mut every = Vec::new();
    for a in 0..boxes.len() {
        for b in a + 1..boxes.len() {
            if (0..2).all(|k| boxes[a].0[k] <= boxes[b].1[k] && boxes[b].0[k] <= boxes[a].1[k]) {
                every.push((a, b));
            }
        }
    }
    assert_eq!(nanofold::geometry::overlapping_pairs(&boxes), every);
}

/// Creases that meet no interior vertex are free each on their own: a strip of n panels
/// has n − 1 DOF, counted without a rank computation over them.
#[test]
fn a_strip_has_one_dof_per_crease() {
    let report = check_text(&strip(3000, 1.0, 1.0));
    assert_eq!(dof(&report), 2999);
}

/// An accordion of thin panels (0.002 × 100) leaves flat and folds: its contact test once
/// searched around each panel by half its length, so at flat every panel's box met
/// thousands of others and the test passed its budget before the first step.
#[test]
fn an_accordion_of_thin_panels_folds() {
    let report = check_text(&strip(3000, 0.002, 100.0));
    assert_eq!(report.verdict, PatternVerdict::RigidlyFoldable, "{}", report.evidence);
    let path = witness(&report);
    assert!(path.steps.last().unwrap().progress > 0.9, "{}", path.evidence);
}

/// An accordion of 2 000 panels 1 × 100 folded to ±170° (no interior vertex: every state
/// rigid) unfolds flat along the ray to flat, halving its angles each step: at most 20
/// steps, where creeping down the layers' barrier took 81 for 1 000 panels and 421 for
/// 49 999 (README's Limits table).
#[test]
fn a_folded_accordion_unfolds_along_the_ray_to_flat() {
    let mut file = common::strip_fold(2000, 1.0, 100.0);
    let angles: Vec<serde_json::Value> = file["edges_assignment"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| match a.as_str().unwrap() {
            "V" => serde_json::json!(170.0),
            "M" => serde_json::json!(-170.0),
            _ => serde_json::Value::Null,
        })
        .collect();
    file["edges_foldAngle"] = serde_json::json!(angles);
    let pattern = Pattern::parse(&file.to_string(), "accordion", "accordion", &LoadOptions::default()).unwrap();
    let report = unfold(&pattern, &Settings::default()).unwrap();
    assert_eq!(report.verdict, UnfoldVerdict::Flat, "{}", report.evidence);
    assert!(report.steps <= 20, "{} steps: {}", report.steps, report.evidence);
}

/// Folded until its layers stack, a strip's panels overlap in nearly every pair: the path
/// stops where its contact test would pass 64 pairs per panel, and says so; the stacked
/// state's own check is `unknown` for the same reason.
#[test]
fn layers_stacked_deep_stop_at_the_contact_budget() {
    let text = strip(3000, 1.0, 1.0);
    let report = check_text(&text);
    let path = witness(&report);
    assert_eq!(path.stop.as_str(), "contact_budget", "{}", path.evidence);
    assert!(path.evidence.contains("192000"), "{}", path.evidence);
    let reached = path.steps.last().unwrap();
    assert!(reached.progress > 0.9 && reached.progress < 1.0);
    // The next state's contact test overflows; the last kept state's (with the path's own
    // contact settings) does not.
    let pattern = Pattern::parse(&text, "strip", "strip", &LoadOptions::default()).unwrap();
    let model = pattern.sheet().unwrap();
    let mut poses = Vec::new();
    nanofold::folding::panel_poses(model, &reached.fold_angles, &mut poses);
    let settings = nanofold::folding::FoldSettings::default().contact;
    assert_eq!(
        nanofold::folding::panel_contacts(model, &poses, &settings).overflow,
        None
    );
    let folded: Vec<f64> = reached
        .fold_angles
        .iter()
        .map(|r| r.signum() * (1.0 - 1e-6) * std::f64::consts::PI)
        .collect();
    nanofold::folding::panel_poses(model, &folded, &mut poses);
    assert_eq!(
        nanofold::folding::panel_contacts(model, &poses, &settings).overflow,
        Some(settings.pair_budget(model.pattern.panel_count) + 1)
    );
}

/// A fan of `n` thin panels about one vertex, folded by 60° along the straight line of
/// creases 0 and n/2 (the others unassigned creases at 0), as a crease pattern.
fn fan(n: usize) -> Pattern {
    let sheet = nanofold::read::parse_crease_pattern(&fan_fold(n).to_string(), "fan", "fan").unwrap();
    Pattern::from_crease_pattern(sheet).unwrap()
}

/// The FOLD object of [`fan`] (no `faces_vertices`, as a hand-written file may have none).
fn fan_fold(n: usize) -> serde_json::Value {
    let tau = std::f64::consts::TAU;
    let mut vertices = vec![[0.0, 0.0]];
    vertices.extend((0..n).map(|k| [(tau * k as f64 / n as f64).cos(), (tau * k as f64 / n as f64).sin()]));
    let mut edges = Vec::new();
    let (mut assignment, mut angles) = (Vec::new(), Vec::new());
    for k in 0..n {
        edges.push([0, k + 1]);
        let folded = k == 0 || k == n / 2;
        assignment.push(if folded { "V" } else { "U" });
        angles.push(if folded { 60.0 } else { 0.0 });
    }
    for k in 0..n {
        edges.push([k + 1, (k + 1) % n + 1]);
        assignment.push("B");
        angles.push(0.0);
    }
    serde_json::json!({
        "vertices_coords": vertices, "edges_vertices": edges,
        "edges_assignment": assignment, "edges_foldAngle": angles,
    })
}

/// A FOLD vertex without `faces_vertices` (a fan of 64 panels folded along a line) goes to
/// the single-vertex engine, unfolds flat, and its page is drawn from the sheet's own faces
/// (it was refused for want of faces after the unfolding had run).
#[test]
fn a_vertex_file_without_faces_unfolds_and_writes_its_page() {
    let pattern = Pattern::parse(&fan_fold(64).to_string(), "fan", "fan", &LoadOptions::default()).unwrap();
    assert_eq!(pattern.engine(), Engine::Vertex);
    let settings = Settings::default();
    let report = unfold(&pattern, &settings).unwrap();
    assert_eq!(report.verdict, UnfoldVerdict::Flat, "{}", report.evidence);
    let files = nanofold::commands::unfold_files(&pattern, &report, &settings).unwrap();
    let page = files.iter().find(|(name, _)| *name == "unfold.html").unwrap();
    assert!(page.1.contains("<canvas"), "no page drawn");
}

/// Every two of a fan's panels meet at its centre: those pairs are the vertex's to order on
/// the sphere, not the contact test's to measure, so they do not spend its pair budget. A
/// fan of 500 panels (124 750 pairs at the centre, past the 10⁵ budget) folded along one
/// line is judged rigid, not left undecided.
#[test]
fn panels_meeting_only_at_a_vertex_do_not_spend_the_contact_budget() {
    let report = check(&fan(500), &Settings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::Rigid, "{}", report.evidence);
}

/// A strip of triangles: `m` + 1 vertices on each of two lines, every rung and diagonal a
/// crease folded by ±`degrees` (a state every vertex closes: all lie on the boundary).
fn triangle_strip(m: usize, degrees: f64) -> serde_json::Value {
    let mut points: Vec<[f64; 2]> = (0..=m).map(|i| [i as f64, 0.0]).collect();
    points.extend((0..=m).map(|i| [i as f64 + 0.5, 1.0]));
    let (mut edges, mut letters, mut angles) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..m {
        edges.extend([[i, i + 1], [m + 1 + i, m + 2 + i]]);
        letters.extend(["B", "B"]);
        angles.extend([0.0, 0.0]);
    }
    for i in 0..=m {
        let end = i == 0 || i == m;
        edges.push([i, m + 1 + i]);
        letters.push(if end { "B" } else { "V" });
        angles.push(if end { 0.0 } else { degrees });
        if i < m {
            edges.push([m + 1 + i, i + 1]);
            letters.push("M");
            angles.push(-degrees);
        }
    }
    serde_json::json!({"file_spec": 1.1, "vertices_coords": points, "edges_vertices": edges,
                       "edges_assignment": letters, "edges_foldAngle": angles})
}

/// The energy unfolding's panel barrier once stored every panel's path to the root: memory
/// quadratic in a strip's length (a strip of 100 000 vertices ran out of a 4 GiB address
/// space; 20 000 vertices needed 6 GB). `check` of 20 000 vertices, which also unfolds the
/// rigid state by energy, now runs within a 1 GiB address space.
#[test]
fn a_long_folded_strip_is_checked_within_a_bounded_address_space() {
    let dir = std::env::temp_dir().join(format!("nanofold-strip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("strip.fold");
    std::fs::write(&file, triangle_strip(9_999, 1e-3).to_string()).unwrap();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && exec "$0" check --json "$1""#)
        .arg(env!("CARGO_BIN_EXE_nanofold"))
        .arg(&file)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let line: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(line["verdict"], "rigid", "{line}");
    assert_eq!(line["unfold"]["verdict"], "flat", "{line}");
}

/// Passing the contact budget is located by bisection towards the state that passed it, to
/// 1e-2 rad: every trial near it measures millions of pairs on a long sheet. Crept up on
/// to 1e-6 rad by halving and regrowing the step, a strip of 100 000 vertices took 30
/// steps and 61 contact tests (13 s); a strip of 2 000 took 28 steps.
#[test]
fn the_contact_budget_is_located_in_few_contact_tests() {
    let report = check_text(&triangle_strip(999, 0.0).to_string());
    assert_eq!(report.verdict, PatternVerdict::RigidlyFoldable, "{}", report.evidence);
    let path = witness(&report);
    assert!(
        matches!(path.stop, nanofold::folding::StopReason::ContactBudget { .. }),
        "{}",
        path.evidence
    );
    assert!(path.steps.last().unwrap().progress > 0.99, "{}", path.evidence);
    assert!(path.evidence.contains("located to 1e-2 rad"), "{}", path.evidence);
    assert!(
        path.contact_tests <= 24 && path.steps.len() <= 22,
        "{} contact tests, {} steps",
        path.contact_tests,
        path.steps.len()
    );
}

/// A fold's animation holds every frame in memory until written: frames × vertices is
/// bounded (1.2 × 10⁶) before anything is folded, and the error names the most this pattern
/// gets. 2 000 frames of a strip of 100 000 vertices ran out of a 4 GiB address space, and
/// so did 40.
#[test]
fn more_frames_than_a_large_pattern_allows_are_refused_by_name() {
    use nanofold::commands::{fold_run, FoldOptions};
    let text = triangle_strip(2_499, 0.0).to_string();
    let pattern = Pattern::parse(&text, "strip", "strip", &LoadOptions::default()).unwrap();
    let options = |frames| FoldOptions {
        frames,
        to: 1.0,
        ..FoldOptions::default()
    };
    let error = fold_run(&pattern, &options(241)).unwrap_err().to_string();
    assert!(
        error.contains("frames") && error.contains("241") && error.contains("at most 240 frames"),
        "{error}"
    );
    let run = fold_run(&pattern, &options(240)).unwrap();
    assert_eq!(run.frames.len(), 240);
}

/// Every folding step factorises the closure system of the interior vertices, whose fill
/// grows faster than their number: past 30 000 of them a pattern is refused by name, before
/// anything is folded (README's Limits table). A strip of 100 000 vertices has none.
#[test]
fn more_interior_vertices_than_the_limit_are_refused_by_name() {
    let text = grid(174, None);
    let pattern = Pattern::parse(&text, "grid", "grid", &LoadOptions::default()).unwrap();
    assert_eq!(pattern.sheet().unwrap().stars.len(), 173 * 173);
    let error = Pattern::parse(&grid(175, None), "grid", "grid", &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("vertices_coords") && error.contains("30276 interior vertices"),
        "{error}"
    );
}
