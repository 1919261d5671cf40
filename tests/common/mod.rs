//! Helpers shared by the integration tests.
#![allow(dead_code)]

use nanofold::dynamics::scene::Scene;
use std::path::Path;

/// A closed native vertex with `sectors` and fold angles `rho`, both in rad, creases unassigned.
pub fn native_json(sectors: &[f64], rho: &[f64]) -> String {
    let creases: Vec<String> = rho
        .iter()
        .map(|r| format!(r#"{{"assignment":"U","fold_angle":{r}}}"#))
        .collect();
    format!(
        r#"{{"chain":"closed","angle_unit":"rad","sector_angles":{sectors:?},"creases":[{}]}}"#,
        creases.join(",")
    )
}

/// A bundled scene file, loaded and built.
pub fn scene_file(path: &str) -> Scene {
    nanofold::io::load_scene(Path::new(path))
        .and_then(|spec| spec.build())
        .unwrap()
}

/// Scene text (a closed chain's pattern relative to `patterns/`), parsed and built.
pub fn scene_text(text: &str) -> nanofold::Result<Scene> {
    nanofold::io::parse_scene(text, "test", "test", Path::new("patterns"))?.build()
}

/// An error and its sources, joined as the CLI prints them.
pub fn full_message(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(s) = source {
        text += &format!(": {s}");
        source = s.source();
    }
    text
}

/// A FOLD object of a strip of `panels` panels `width` × `height` side by side, its creases
/// alternating valley and mountain.
pub fn strip_fold(panels: usize, width: f64, height: f64) -> serde_json::Value {
    let m = panels;
    let mut points: Vec<[f64; 2]> = (0..=m).map(|i| [i as f64 * width, 0.0]).collect();
    points.extend((0..=m).map(|i| [i as f64 * width, height]));
    let (mut edges, mut letters) = (Vec::new(), Vec::new());
    for i in 0..m {
        edges.extend([[i, i + 1], [m + 1 + i, m + 2 + i]]);
        letters.extend(["B", "B"]);
    }
    for i in 0..=m {
        edges.push([i, m + 1 + i]);
        letters.push(if i == 0 || i == m {
            "B"
        } else if i % 2 == 1 {
            "V"
        } else {
            "M"
        });
    }
    serde_json::json!({"file_spec": 1.1, "vertices_coords": points, "edges_vertices": edges, "edges_assignment": letters})
}
