//! Folding paths by continuation (issue 31): time against closure tolerance and against
//! pattern size, with the step and Newton counts, and the frames placed on each path —
//! their time, their closure and their edge lengths measured from the spanning tree's
//! coordinates against the crease pattern's.

use super::common::timed;
use nanofold::folding::{
    fold_path, fold_path_and_frames, panel_poses, path_frames, vertex_positions, vertex_residuals, Drive, FoldSettings,
    FoldingModel, PathFrame,
};
use nanofold::pattern::generate::MiuraSpec;
use nanofold::prelude::Named;
use serde_json::{json, Value};
use std::path::Path;

fn miura(n: usize) -> FoldingModel {
    let spec = MiuraSpec {
        rows: n,
        cols: n,
        ..MiuraSpec::default()
    };
    FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap()
}

fn library(name: &str) -> FoldingModel {
    let path = Path::new("patterns/many").join(format!("{name}.fold"));
    FoldingModel::new(nanofold::read::load_crease_pattern(&path).unwrap()).unwrap()
}

/// Worst closure (rad) and worst relative edge-length error over the frames.
fn frame_errors(model: &FoldingModel, frames: &[PathFrame]) -> (f64, f64) {
    let pattern = &model.pattern;
    let mut poses = Vec::new();
    let (mut closure, mut edges) = (0.0_f64, 0.0_f64);
    for frame in frames {
        closure = closure.max(
            vertex_residuals(model, &frame.fold_angles)
                .into_iter()
                .fold(0.0, f64::max),
        );
        panel_poses(model, &frame.fold_angles, &mut poses);
        let placed = vertex_positions(model, &poses);
        for &[a, b] in &pattern.edges {
            let (p, q) = (pattern.vertices[a], pattern.vertices[b]);
            let flat = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
            let d: f64 = (0..3)
                .map(|k| (placed[a][k] - placed[b][k]).powi(2))
                .sum::<f64>()
                .sqrt();
            edges = edges.max((d - flat).abs() / flat);
        }
    }
    (closure, edges)
}

fn measure(name: &str, model: &FoldingModel, to_percent: f64, closure_tol: f64) -> Value {
    let settings = FoldSettings {
        drive: Drive::Assignment { to: to_percent },
        closure_tol,
        ..FoldSettings::default()
    };
    let runs = if model.crease_count() > 10_000 { 1 } else { 5 };
    let start = model.given_fold_angles();
    let (seconds, path) = timed(runs, || fold_path(model, &start, &settings).unwrap());
    let (frames_11, frames) = timed(runs, || path_frames(model, &path, 11).unwrap());
    // The path with 11 frames placed while it goes on, as `fold --frames 11` does it.
    let (together_11, (_, together)) = timed(runs, || fold_path_and_frames(model, &start, &settings, 11).unwrap());
    assert_eq!(
        together, frames,
        "frames placed during the path are those placed after it"
    );
    let (frame_closure, frame_edges) = frame_errors(model, &frames);
    let (frames_101, frames) = timed(1, || path_frames(model, &path, 101).unwrap());
    let (closure_101, edges_101) = frame_errors(model, &frames);
    let row = json!({
        "pattern": name,
        "creases": model.crease_count(),
        "to_percent": to_percent,
        "closure_tol": closure_tol,
        "seconds": seconds,
        "steps": path.steps.len() - 1,
        "newton_iterations": path.newton_iterations,
        "factorisations": path.factorisations,
        "max_closure_residual": path.max_closure_residual,
        "stop": path.stop.as_str(),
        "progress": path.steps.last().map(|s| s.progress),
        "frames_11_seconds": frames_11,
        "path_and_11_frames_seconds": together_11,
        "frames_101_seconds": frames_101,
        "frame_closure": frame_closure.max(closure_101),
        "frame_edge_error": frame_edges.max(edges_101),
    });
    println!(
        "{:<22} {:>6} {:>7.0e} {:>8.3} {:>5} {:>6} {:>6} {:>9.1e} {:>9.3} {:>9.3} {:>9.3} {:>9.1e} {:>9.1e}  {}",
        name,
        model.crease_count(),
        closure_tol,
        seconds,
        path.steps.len() - 1,
        path.newton_iterations,
        path.factorisations,
        path.max_closure_residual,
        frames_11,
        together_11,
        frames_101,
        frame_closure.max(closure_101),
        frame_edges.max(edges_101),
        path.stop.as_str()
    );
    row
}

/// The folding part of the report.
pub fn folding_part() -> Value {
    println!("\nFolding paths by continuation to 90% (median of 5 runs; 1 above 10 000 creases)");
    println!(
        "{:<22} {:>6} {:>7} {:>8} {:>5} {:>6} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}  stop",
        "pattern",
        "creases",
        "tol",
        "path s",
        "steps",
        "newton",
        "factor",
        "closure",
        "11 fr. s",
        "both s",
        "101 fr. s",
        "fr. closure",
        "fr. edges"
    );
    let mut rows = Vec::new();
    for n in [4, 8, 16, 32, 64, 100] {
        rows.push(measure(&format!("miura {n}x{n}"), &miura(n), 90.0, 1e-11));
    }
    for tol in [1e-6, 1e-8, 1e-10, 1e-12] {
        rows.push(measure("miura 32x32", &miura(32), 90.0, tol));
    }
    for name in ["square_twist", "waterbomb_4x3", "huffman_waterbomb_6x4"] {
        rows.push(measure(name, &library(name), 90.0, 1e-11));
    }
    json!({ "rows": rows })
}
