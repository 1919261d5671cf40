//! What a run writes: `trajectory.json`, the FOLD animation `unfold.fold`, `response.json`
//! and the other reports, rendered as values; `write_atomic` writes one file through a
//! temporary file and a rename (a run's whole set goes through `io::folder`).

use crate::dynamics::closed::modes::ClosedModes;
use crate::dynamics::closed::ClosedChain;
use crate::dynamics::modes::Modes;
use crate::dynamics::network::modes::NetworkModes;
use crate::dynamics::network::NetworkModel;
use crate::dynamics::plant::Sample;
use crate::dynamics::scene::Scene;
use crate::dynamics::simulate::{Response, Simulation, SimulationSettings};
use crate::error::{NanofoldError, Result};
use crate::geometry::sphere::Vec3;
use crate::names::Named;
use crate::pattern::{Chain, FlatMesh, RayRole, VertexPattern};
use crate::unfold::{UnfoldModel, UnfoldReport, UnfoldSettings};
use crate::write::summary::{
    ClosedModesSummary, ClosedRunSummary, CollisionSummary, ModeSet, NetworkModesSummary, NetworkRunSummary,
    ReleasedLock, ResponseSummary, StripModesSummary, TimeScalesSummary,
};
use nalgebra::DMatrix;
use serde::Serialize;
use serde_json::{json, Value};
use std::f64::consts::TAU;
use std::path::Path;

/// Writes `contents` to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    let err = |source: std::io::Error| NanofoldError::Output {
        path: path.display().to_string(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(err)?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("output");
    let temporary = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    std::fs::write(&temporary, contents).map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        err(e)
    })?;
    std::fs::rename(&temporary, path).map_err(|e| {
        let _ = std::fs::remove_file(&temporary);
        err(e)
    })
}

/// Indices of the recorded steps to show as snapshots: the first step past each tenth of
/// the way from the folded state to flat (by the largest fold angle), and the last step.
pub fn snapshot_indices(report: &UnfoldReport, count: usize) -> Vec<usize> {
    let traj = &report.trajectory;
    if traj.is_empty() {
        return Vec::new();
    }
    let max_abs = |angles: &[f64]| angles.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
    let start = max_abs(&traj[0].fold_angles).max(1e-300);
    let mut picks = vec![0];
    for j in 1..count {
        let level = start * (1.0 - j as f64 / (count - 1) as f64);
        if let Some(i) = traj.iter().position(|r| max_abs(&r.fold_angles) <= level + 1e-15) {
            if !picks.contains(&i) {
                picks.push(i);
            }
        }
    }
    let last = traj.len() - 1;
    if !picks.contains(&last) {
        picks.push(last);
    }
    picks.sort_unstable();
    picks
}

/// The mesh written to FOLD: the input's for FOLD input, else one synthesised from the
/// vertex (centre, unit-length rays, chords between ray tips, triangular faces).
struct ExportMesh {
    coords_2d: Vec<[f64; 2]>,
    center: usize,
    ray0_direction: f64,
    edges_vertices: Vec<[usize; 2]>,
    edges_assignment: Vec<String>,
    /// Crease index (file order) of each edge, if it is a crease.
    edge_crease: Vec<Option<usize>>,
    faces_vertices: Option<Vec<Vec<usize>>>,
}

fn export_mesh(pattern: &VertexPattern) -> ExportMesh {
    if let Some(FlatMesh {
        vertices_coords,
        edges_vertices,
        edges_assignment,
        faces_vertices,
        center,
        ray0_direction,
        ..
    }) = &pattern.mesh
    {
        let mut edge_crease = vec![None; edges_vertices.len()];
        for (i, c) in pattern.creases.iter().enumerate() {
            if let Some(e) = c.fold_edge {
                edge_crease[e] = Some(i);
            }
        }
        return ExportMesh {
            coords_2d: vertices_coords.clone(),
            center: *center,
            ray0_direction: *ray0_direction,
            edges_vertices: edges_vertices.clone(),
            edges_assignment: edges_assignment.clone(),
            edge_crease,
            faces_vertices: faces_vertices.clone(),
        };
    }
    let n = pattern.ray_count();
    let directions = pattern.flat_ray_directions();
    let mut coords_2d = vec![[0.0, 0.0]];
    coords_2d.extend(directions.iter().map(|phi| [phi.cos(), phi.sin()]));
    let mut edges_vertices = Vec::new();
    let mut edges_assignment = Vec::new();
    let mut edge_crease = Vec::new();
    for (k, role) in pattern.rays.iter().enumerate() {
        edges_vertices.push([0, k + 1]);
        let (letter, crease) = match role {
            RayRole::Crease(i) => (pattern.creases[*i].assignment.letter().to_string(), Some(*i)),
            RayRole::Boundary => ("B".to_string(), None),
            RayRole::Virtual => ("F".to_string(), None),
        };
        edges_assignment.push(letter);
        edge_crease.push(crease);
    }
    let mut faces = Vec::new();
    for k in 0..pattern.sector_angles.len() {
        let next = (k + 1) % n;
        edges_vertices.push([k + 1, next + 1]);
        edges_assignment.push("B".to_string());
        edge_crease.push(None);
        faces.push(vec![0, k + 1, next + 1]);
    }
    ExportMesh {
        coords_2d,
        center: 0,
        ray0_direction: 0.0,
        edges_vertices,
        edges_assignment,
        edge_crease,
        faces_vertices: Some(faces),
    }
}

/// 3D position of every mesh vertex for the given node positions: each vertex moves with
/// the (split) sector that contains it.
fn place_vertices(pattern: &VertexPattern, mesh: &ExportMesh, nodes: &[Vec3]) -> Vec<[f64; 3]> {
    let directions = pattern.flat_ray_directions();
    let n = pattern.ray_count();
    let sectors = pattern.sector_angles.len();
    let c = mesh.coords_2d[mesh.center];
    let (s0, c0) = mesh.ray0_direction.sin_cos();
    mesh.coords_2d
        .iter()
        .map(|p| {
            // Into the vertex frame: centre at the origin, ray 0 along +x.
            let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
            let v = [c0 * dx + s0 * dy, -s0 * dx + c0 * dy];
            let theta = v[1].atan2(v[0]).rem_euclid(TAU);
            let mut k = (0..sectors)
                .rev()
                .find(|&k| directions[k] <= theta + 1e-12)
                .unwrap_or(0);
            if pattern.chain == Chain::Open && theta > directions[n - 1] + 1e-9 {
                k = if theta - directions[n - 1] < TAU - theta {
                    sectors - 1
                } else {
                    0
                };
            }
            let (su, cu) = directions[k].sin_cos();
            let a = v[0] * cu + v[1] * su;
            let b = -v[0] * su + v[1] * cu;
            let xk = nodes[k];
            let normal = xk.cross(&nodes[(k + 1) % n]).normalize();
            let q = a * xk + b * normal.cross(&xk);
            // Back to the pattern's orientation.
            [c[0] + c0 * q.x - s0 * q.y, c[1] + s0 * q.x + c0 * q.y, q.z]
        })
        .collect()
}

fn edge_angles_degrees(mesh: &ExportMesh, crease_angles: &[f64]) -> Vec<f64> {
    mesh.edge_crease
        .iter()
        .map(|c| c.map_or(0.0, |i| crease_angles[i].to_degrees()))
        .collect()
}

/// FOLD letters of a frame: a crease folded one way is written as that way (M < 0 < V,
/// FOLD's sign rule), whatever its assignment; a crease at 0 and every other edge keep
/// their letters.
fn frame_letters(mesh: &ExportMesh, angles_degrees: &[f64]) -> Vec<String> {
    mesh.edges_assignment
        .iter()
        .zip(&mesh.edge_crease)
        .zip(angles_degrees)
        .map(|((letter, crease), &angle)| match crease {
            Some(_) if angle > 0.0 => "V".to_string(),
            Some(_) if angle < 0.0 => "M".to_string(),
            _ => letter.clone(),
        })
        .collect()
}

/// Builds the FOLD animation: the key frame is the crease pattern (2D, `creasePattern`,
/// the input's assignments) with the folded state it started from in `edges_foldAngle`, so
/// nanofold reads the file back as its input; `file_frames` are the snapshots, 3D `foldedForm` frames whose
/// assignments follow their angles.
pub fn fold_animation(pattern: &VertexPattern, model: &UnfoldModel, report: &UnfoldReport) -> Value {
    let mesh = export_mesh(pattern);
    let picks = snapshot_indices(report, 11);
    let start_nodes = model.folded_nodes();
    let start_angles = edge_angles_degrees(&mesh, &model.crease_angles(&start_nodes));
    let frames: Vec<Value> = picks
        .iter()
        .map(|&i| {
            let step = &report.trajectory[i];
            let angles = edge_angles_degrees(&mesh, &model.crease_angles(&step.nodes));
            json!({
                "frame_title": format!("iteration {}", step.iteration),
                "frame_classes": ["foldedForm"],
                "frame_attributes": ["3D"],
                "frame_parent": 0,
                "frame_inherit": true,
                "vertices_coords": place_vertices(pattern, &mesh, &step.nodes),
                "edges_assignment": frame_letters(&mesh, &angles),
                "edges_foldAngle": angles,
            })
        })
        .collect();
    let mut root = json!({
        "file_spec": 1.1,
        "file_creator": "nanofold",
        "file_classes": ["animation"],
        "frame_title": format!("{}: crease pattern and folded state (unfolding verdict {})", pattern.name, report.verdict.as_str()),
        "frame_classes": ["creasePattern"],
        "frame_attributes": ["2D"],
        "frame_unit": pattern.mesh.as_ref().and_then(|m| m.unit.clone()).unwrap_or_else(|| "unit".into()),
        "vertices_coords": mesh.coords_2d,
        "edges_vertices": mesh.edges_vertices,
        "edges_assignment": mesh.edges_assignment,
        "edges_foldAngle": start_angles,
        "file_frames": frames,
    });
    if pattern.creases.iter().any(|c| c.locked) {
        let locked: Vec<bool> = mesh
            .edge_crease
            .iter()
            .map(|c| c.is_some_and(|i| pattern.creases[i].locked))
            .collect();
        root[crate::read::fold::LOCKED_KEY] = json!(locked);
    }
    if let Some(faces) = mesh.faces_vertices {
        root["faces_vertices"] = json!(faces);
    }
    root
}

#[derive(Serialize)]
struct TrajectoryStep<'a> {
    iteration: usize,
    energy: f64,
    fold_angles_rad: &'a [f64],
    max_arc_residual_rad: f64,
    direction_norm: f64,
    /// Unit vectors of every ray (virtual rays included), in ray order.
    nodes: Vec<[f64; 3]>,
}

/// `trajectory.json`: settings, crease table and every recorded step (thinned evenly to at
/// most `max_steps`, first and last kept).
pub fn trajectory_json(
    pattern: &VertexPattern,
    settings: &UnfoldSettings,
    report: &UnfoldReport,
    max_steps: usize,
) -> Value {
    let total = report.trajectory.len();
    let stride = total.div_ceil(max_steps.max(1)).max(1);
    let mut chosen: Vec<usize> = (0..total).step_by(stride).collect();
    if total > 0 && chosen.last() != Some(&(total - 1)) {
        chosen.push(total - 1);
    }
    let steps: Vec<TrajectoryStep> = chosen
        .iter()
        .map(|&i| {
            let r = &report.trajectory[i];
            TrajectoryStep {
                iteration: r.iteration,
                energy: r.energy,
                fold_angles_rad: &r.fold_angles,
                max_arc_residual_rad: r.max_arc_residual,
                direction_norm: r.direction_norm,
                nodes: r.nodes.iter().map(|x| [x.x, x.y, x.z]).collect(),
            }
        })
        .collect();
    json!({
        "pattern": pattern.name,
        "units": {"angles": "rad", "nodes": "unit vectors, vertex at the origin, sector 0 in the xy-plane"},
        "settings": settings,
        "creases": pattern.creases,
        "rays": pattern.rays,
        "sector_angles_rad": pattern.sector_angles,
        "verdict": report.verdict,
        "evidence": report.evidence,
        "recorded_steps": total,
        "steps_written": steps.len(),
        "steps": steps,
    })
}

/// A number for JSON, which has no infinity or NaN: those are written as the strings
/// "inf", "-inf" and "nan" (serde_json would write `null`, the mark of an absent value).
pub fn number(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else if x.is_nan() {
        json!("nan")
    } else if x > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

/// The summary of a dynamics run: the `--json` object, and the head of `response.json`.
/// A closed chain adds `cut_crease`, `anchored_face`, `constraint_source`,
/// `torque_magnification`, `max_closure_residual` and the fit's errors (angles are every
/// crease's, in FOLD edge order).
pub fn response_summary(scene: &Scene, settings: &SimulationSettings, simulation: &Simulation) -> ResponseSummary {
    let response = &simulation.response;
    let scales = &response.time_scales;
    let closed = match (&simulation.closed, scene.closed()) {
        (Some(closed), Some(chain)) => Some(ClosedRunSummary {
            cut_crease: closed.cut_crease,
            anchored_face: closed.anchored_face,
            driving_crease: closed.driver,
            constraint_source: closed.constraint_source,
            constraint_degree: closed.degree,
            constraint_fit_error_rad: closed.fit_error,
            constraint_slope_error: closed.slope_error,
            torque_magnification: closed.torque_magnification,
            driving_hinge_width_um: closed.driving_hinge_width_um,
            required_hinge_width_um: closed.required_hinge_width_um,
            max_closure_residual: closed.max_closure_residual,
            crease_edges: chain.crease_user_indices.clone(),
        }),
        _ => None,
    };
    let network = match (&simulation.network, scene.network()) {
        (Some(report), Some(model)) => Some(NetworkRunSummary {
            run: report.clone(),
            crease_edges: model.folding.pattern.creases.clone(),
            release_times_s: model.forcing.hinges.iter().map(|h| h.release_time).collect(),
        }),
        _ => None,
    };
    ResponseSummary {
        scene: scene.name.clone(),
        model: response.model,
        method: response.method,
        rtol: response.rtol,
        time_scale_ratio: scales.ratio,
        time_scales: TimeScalesSummary {
            fastest_period_s: scales.fastest_period_s,
            slowest_period_s: scales.slowest_period_s,
            forcing_time_s: scales.forcing_time_s,
            ratio: scales.ratio,
        },
        quasi_static_error_estimate_rad: response.quasi_static_error_estimate,
        measured_quasi_static_error_rad: response.measured_quasi_static_error.map(|(_, e)| e),
        quasi_static_check_window_s: response.measured_quasi_static_error.map(|(w, _)| w),
        ignore_collisions: settings.ignore_collisions,
        t_end_s: response.t_end,
        collision: response.collision.as_ref().map(|c| CollisionSummary {
            time_s: c.time,
            pair: c.pair.clone(),
            point: [c.point.x, c.point.y, c.point.z],
            point_um: [c.point.x * 1e6, c.point.y * 1e6, c.point.z * 1e6],
        }),
        final_angles_rad: response
            .samples
            .last()
            .map(|s| s.angles.as_slice().to_vec())
            .unwrap_or_default(),
        target_angles_rad: scene.target_angles(),
        steps: response.steps,
        rhs_evaluations: response.rhs_evaluations,
        seconds: response.seconds,
        closed,
        network,
        released: simulation.released.clone(),
    }
}

/// `response.json`: the summary plus every output sample.
pub fn response_json(summary: &ResponseSummary, response: &Response) -> Value {
    let summary = serde_json::to_value(summary).expect("a summary is plain data");
    with_samples(summary, response)
}

fn with_samples(mut value: Value, response: &Response) -> Value {
    let samples = &response.samples;
    let column = |f: &dyn Fn(&Sample) -> f64| samples.iter().map(f).collect::<Vec<f64>>();
    value["units"] = json!({
        "time": "s", "angles": "rad (valley positive)", "velocities": "rad/s", "energy": "J",
        "point": "m (point_um: µm), world frame: creases along x, the chain along +y, z up",
    });
    value["time_s"] = json!(column(&|s| s.time));
    value["angles_rad"] = json!(samples.iter().map(|s| s.angles.as_slice().to_vec()).collect::<Vec<_>>());
    value["velocities_rad_s"] = json!(samples.iter().map(|s| s.rates.as_slice().to_vec()).collect::<Vec<_>>());
    value["energy_j"] = json!({
        "kinetic": column(&|s| s.kinetic_energy),
        "elastic": column(&|s| s.elastic_energy),
        "actuator_potential": column(&|s| s.actuator_potential),
        "total": column(&|s| s.total_energy()),
    });
    if samples.iter().all(|s| s.energy_balance().is_some()) && !samples.is_empty() {
        value["energy_j"]["actuation_work"] = json!(column(&|s| s.actuation_work.unwrap_or(f64::NAN)));
        value["energy_j"]["drag_dissipation"] = json!(column(&|s| s.drag_dissipation.unwrap_or(f64::NAN)));
        value["energy_j"]["balance"] = json!(column(&|s| s.energy_balance().unwrap_or(f64::NAN)));
    }
    value
}

/// `nanofold modes --json` of a network: the equilibrium, the released locks, the
/// frequencies (with and without the constraints' load term) and the shapes over every crease.
pub fn network_modes_summary(name: &str, model: &NetworkModel, result: &NetworkModes) -> NetworkModesSummary {
    let modes = &result.modes;
    NetworkModesSummary {
        scene: name.to_string(),
        panels: model.panels(),
        creases: model.columns(),
        crease_edges: model.folding.pattern.creases.clone(),
        anchored_face: model.anchored_face,
        degrees_of_freedom: modes.basis.ncols(),
        released_locks: result
            .released
            .iter()
            .map(|&(c, angle_rad)| ReleasedLock {
                edge: model.folding.pattern.creases[c],
                angle_rad,
            })
            .collect(),
        rest_angles_rad: result.rest_angles.clone(),
        equilibrium_rad: modes.equilibrium.angles.clone(),
        equilibrium_newton_steps: modes.equilibrium.iterations,
        residual_torque_n_m: modes.equilibrium.residual_torque,
        closure_residual_rad: modes.equilibrium.closure_residual,
        modes: mode_set(&modes.modes, &modes.crease_shapes),
        frequencies_without_load_hz: modes.frequencies_without_load_hz.to_vec(),
        reduced: model.reduction.as_ref().map(|r| r.report.clone()),
    }
}

/// Eigenvalues, frequencies and stability of `modes`, with `shapes` (one column a mode).
fn mode_set(modes: &Modes, shapes: &DMatrix<f64>) -> ModeSet {
    ModeSet {
        eigenvalues: modes.eigenvalues.to_vec(),
        frequencies_hz: modes.frequencies_hz.to_vec(),
        mode_shapes: columns(shapes),
        stable: modes.stable,
    }
}

/// A matrix's columns, each a vector.
fn columns(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.ncols()).map(|k| m.column(k).iter().copied().collect()).collect()
}

/// A matrix's rows, each a vector.
fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|k| m.row(k).iter().copied().collect()).collect()
}

/// `nanofold modes` output of a strip.
pub fn strip_modes_summary(scene: &Scene, modes: &Modes) -> StripModesSummary {
    StripModesSummary {
        scene: scene.name.clone(),
        equilibrium_rad: modes.equilibrium.as_slice().to_vec(),
        equilibrium: "folded: K θ = K θ_target, so θ* = θ_target (passive hinges at 0)",
        modes: mode_set(modes, &modes.mode_shapes),
        stiffness_n_m_per_rad: scene.stiffness(),
    }
}

/// `nanofold modes` output of a closed chain: the strip's keys (`equilibrium_rad` and
/// `mode_shapes` are over the released coordinates) plus every crease's angles and shapes,
/// the reduced matrices and the closed-chain keys. Crease numbers are FOLD edge indices.
pub fn closed_modes_summary(
    name: &str,
    chain: &ClosedChain,
    modes: &ClosedModes,
    torque_magnification: f64,
) -> ClosedModesSummary {
    let stiffness = &modes.hinge_stiffness + &modes.load_stiffness;
    let user = |creases: &[usize]| {
        creases
            .iter()
            .map(|&c| chain.crease_user_indices[c])
            .collect::<Vec<_>>()
    };
    ClosedModesSummary {
        scene: name.to_string(),
        cut_crease: chain.crease_user_indices[chain.cut_crease],
        anchored_face: chain.anchored_face,
        constraint_source: chain.source.name(),
        torque_magnification,
        max_closure_residual: modes.closure_residual,
        coordinates: user(&modes.coordinates),
        crease_edges: chain.crease_user_indices.clone(),
        equilibrium_rad: modes.modes.equilibrium.as_slice().to_vec(),
        equilibrium: "∇V = 0 with every lock released; V = Σ ½ K (θ − rest)² along the loop closure",
        equilibrium_crease_angles_rad: modes.equilibrium.clone(),
        folded_pose_rad: modes.folded_pose.clone(),
        rest_angles_rad: modes.rest_angles.clone(),
        residual_torque_n_m: modes.residual_torque,
        newton_iterations: modes.newton_iterations,
        folded_through: user(&modes.folded_through),
        modes: mode_set(&modes.modes, &modes.modes.mode_shapes),
        frequencies_without_load_hz: modes.frequencies_without_load_hz.to_vec(),
        crease_mode_shapes: columns(&modes.crease_shapes),
        stiffness_n_m_per_rad: chain.crease_stiffness.clone(),
        reduced_mass_kg_m2: rows(&modes.reduced_mass),
        reduced_stiffness_n_m_per_rad: rows(&stiffness),
        load_stiffness_n_m_per_rad: rows(&modes.load_stiffness),
    }
}

#[cfg(test)]
mod tests {
    use super::number;

    #[test]
    fn non_finite_numbers_are_written_as_text_not_null() {
        assert_eq!(number(f64::INFINITY), "inf");
        assert_eq!(number(f64::NEG_INFINITY), "-inf");
        assert_eq!(number(f64::NAN), "nan");
        assert_eq!(number(2.5), 2.5);
    }
}
