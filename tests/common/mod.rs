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
