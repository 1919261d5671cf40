//! Helpers shared by the timing examples: medians, the machine and commit a report was made
//! on, and random many-crease vertices.

#![allow(dead_code)]

use nanofold::geometry::kinematics::solve_closure;
use nanofold::pattern::{LoadOptions, VertexPattern};
use nanofold::read::is_pattern_file;
use nanofold::unfold::SplitMix64;
use serde_json::json;

/// Median of a non-empty list.
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// Median wall time of `runs` calls of `work`, and the last result.
pub fn timed<T>(runs: usize, mut work: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = std::time::Instant::now();
        let result = work();
        times.push(start.elapsed().as_secs_f64());
        last = Some(result);
    }
    (median(times), last.expect("at least one run"))
}

/// Cores, CPU model and commit, for a report.
pub fn machine() -> serde_json::Value {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let commit = std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    json!({
        "cores": std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        "cpu": cpu,
        "commit": commit,
    })
}

/// A closed vertex with n random sectors (weights in [1, 2)), folded by driving the even
/// creases (for n < 6, all but the last three) to random angles in ±0.3 rad while the others
/// follow by (minimum-norm) loop closure, in 20 continuation steps.
pub fn many_creases(n: usize) -> VertexPattern {
    let mut rng = SplitMix64(7);
    let weights: Vec<f64> = (0..n).map(|_| 1.0 + rng.next_f64()).collect();
    let total: f64 = weights.iter().sum();
    let sectors: Vec<f64> = weights.iter().map(|w| w / total * std::f64::consts::TAU).collect();
    let drive: Vec<f64> = (0..n).map(|_| 0.6 * (rng.next_f64() - 0.5)).collect();
    let mut rho = vec![0.0; n];
    // Loop closure is three equations: at least three creases follow.
    let free: Vec<usize> = if n >= 6 {
        (1..n).step_by(2).collect()
    } else {
        (n - 3..n).collect()
    };
    for s in 1..=20 {
        for k in (0..n).filter(|k| !free.contains(k)) {
            rho[k] = drive[k] * s as f64 / 20.0;
        }
        solve_closure(&sectors, &mut rho, &free, 1e-14, 100).expect("closure");
    }
    let creases: Vec<String> = rho
        .iter()
        .map(|r| format!(r#"{{"assignment":"U","fold_angle":{r}}}"#))
        .collect();
    let json = format!(
        r#"{{"chain":"closed","angle_unit":"rad","sector_angles":{sectors:?},"creases":[{}]}}"#,
        creases.join(",")
    );
    nanofold::read::parse_pattern(&json, &format!("random{n}"), "generated", &LoadOptions::default())
        .expect("a valid vertex")
}

/// The library's pattern files (scene files aside), in name order.
pub fn library_patterns() -> Vec<VertexPattern> {
    let mut paths: Vec<std::path::PathBuf> = std::fs::read_dir("patterns")
        .expect("run from the repository root")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_pattern_file(p))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| nanofold::read::load_pattern(p, &LoadOptions::default()).expect("library pattern"))
        .collect()
}
