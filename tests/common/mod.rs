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
    nanofold::read::load_scene(Path::new(path))
        .and_then(|spec| spec.build())
        .unwrap()
}

/// Scene text (a closed chain's pattern relative to `patterns/`), parsed and built.
pub fn scene_text(text: &str) -> nanofold::Result<Scene> {
    nanofold::read::parse_scene(text, "test", "test", Path::new("patterns"))?.build()
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

/// A FOLD object of a grid of n × n unit squares, horizontal creases valleys and vertical
/// ones mountains; each interior vertex moved by up to ±`jitter`/2 (a seeded sequence), and
/// with `far` the last corner moved to (far, far).
pub fn grid_fold(n: usize, jitter: f64, far: Option<f64>) -> serde_json::Value {
    let index = |i: usize, j: usize| j * (n + 1) + i;
    let mut seed: u64 = 0x2545_F491_4F6C_DD1D;
    let mut noise = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let inside = i > 0 && i < n && j > 0 && j < n;
            let (dx, dy) = if inside && jitter > 0.0 {
                (jitter * noise(), jitter * noise())
            } else {
                (0.0, 0.0)
            };
            vertices.push([i as f64 + dx, j as f64 + dy]);
        }
    }
    let (mut edges, mut letters) = (Vec::new(), Vec::new());
    for j in 0..=n {
        for i in 0..n {
            edges.push([index(i, j), index(i + 1, j)]);
            letters.push(if j == 0 || j == n { "B" } else { "V" });
        }
    }
    for i in 0..=n {
        for j in 0..n {
            edges.push([index(i, j), index(i, j + 1)]);
            letters.push(if i == 0 || i == n { "B" } else { "M" });
        }
    }
    if let Some(far) = far {
        vertices[index(n, n)] = [far, far];
    }
    serde_json::json!({"file_spec": 1.1, "vertices_coords": vertices, "edges_vertices": edges, "edges_assignment": letters})
}

/// The largest distance, after the one rigid motion that fits them best (Kabsch), between
/// `moved` and `fixed`, point for point.
pub fn fitted_distance(moved: &[nalgebra::Point3<f64>], fixed: &[nalgebra::Point3<f64>]) -> f64 {
    use nalgebra::{Matrix3, Point3, Vector3};
    let centre =
        |points: &[Point3<f64>]| points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64;
    let (cm, cf) = (centre(moved), centre(fixed));
    let h = moved.iter().zip(fixed).fold(Matrix3::zeros(), |h, (m, f)| {
        h + (m.coords - cm) * (f.coords - cf).transpose()
    });
    let svd = h.svd(true, true);
    let (u, v_t) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = Matrix3::identity();
    if (v_t.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let rotation = v_t.transpose() * d * u.transpose();
    moved
        .iter()
        .zip(fixed)
        .map(|(m, f)| (rotation * (m.coords - cm) + cf - f.coords).norm())
        .fold(0.0, f64::max)
}

/// A null anywhere in a JSON value, and where (`at` the path so far).
pub fn null_in(value: &serde_json::Value, at: String) -> Option<String> {
    match value {
        serde_json::Value::Null => Some(at),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(k, v)| null_in(v, format!("{at}[{k}]"))),
        serde_json::Value::Object(map) => map.iter().find_map(|(k, v)| null_in(v, format!("{at}.{k}"))),
        _ => None,
    }
}

/// Central differences of whole runs in value `j` (`angles_at`: the fold angles at each asked
/// time for a set of values), by steps of 2h and h times `scale` from `start`,
/// Richardson-extrapolated: one column of the sensitivities per time.
pub fn richardson_column(
    angles_at: impl Fn(&[f64]) -> Vec<nalgebra::DVector<f64>>,
    start: &[f64],
    j: usize,
    scale: f64,
    h: f64,
) -> Vec<nalgebra::DVector<f64>> {
    let difference = |step: f64| {
        let mut at = start.to_vec();
        at[j] = start[j] + step * scale;
        let plus = angles_at(&at);
        at[j] = start[j] - step * scale;
        let minus = angles_at(&at);
        plus.iter()
            .zip(&minus)
            .map(|(p, m)| (p - m) / (2.0 * step))
            .collect::<Vec<_>>()
    };
    let (wide, narrow) = (difference(2.0 * h), difference(h));
    narrow.iter().zip(&wide).map(|(n, w)| (n * 4.0 - w) / 3.0).collect()
}
