//! Points of panels land where the written motion puts them: a mark at every corner of
//! every panel of several devices, placed by the fit's kinematics
//! (`dynamics::points::PanelPoints`), against the `motion.fold` that `simulate` writes; and
//! that motion checked on its own: every edge keeps its flat length, every crease's
//! dihedral is the response's angle, and a corner that two panels share is one point.

use nanofold::dynamics::points::PanelPoints;
use nanofold::dynamics::scene::System;
use nanofold::prelude::{open_scene, simulate, SimulationSettings};
use serde_json::Value;

fn vertices(frame: &Value) -> Vec<[f64; 3]> {
    frame["vertices_coords"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let c: Vec<f64> = p.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            [c[0], c[1], *c.get(2).unwrap_or(&0.0)]
        })
        .collect()
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn minus(a: [f64; 3], b: [f64; 3]) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2])
}

/// A pattern scene's motion: every frame rigid, its creases at its angles, and every corner
/// of every face, placed as a mark on that face, where the frame has it.
fn network_marks_land_on_the_motion(path: &str, t_end: Option<f64>) {
    let scene = open_scene(path.as_ref()).unwrap();
    let report = simulate(
        &scene,
        &SimulationSettings {
            t_end,
            ..SimulationSettings::default()
        },
    )
    .unwrap();
    let motion = &report.fold;
    let System::Network(model) = &scene.system else {
        panic!("{path} is a pattern scene")
    };
    let unit_um = model.unit * 1e6;
    let flat = vertices(motion);
    let edges: Vec<[usize; 2]> = serde_json::from_value(motion["edges_vertices"].clone()).unwrap();
    let faces: Vec<Vec<usize>> = serde_json::from_value(motion["faces_vertices"].clone()).unwrap();
    let size = flat.iter().map(|&p| distance(p, flat[0])).fold(0.0, f64::max);
    let pattern = &model.folding.pattern;
    let mut points = PanelPoints::new(&scene).unwrap();
    let frames = motion["file_frames"].as_array().unwrap();
    assert!(frames.len() > 10, "{path}: {} frames", frames.len());
    let mut largest_fold = 0.0_f64;
    for frame in frames {
        let at = vertices(frame);
        // Rigid: every edge as long as flat.
        for &[a, b] in &edges {
            let (now, then) = (distance(at[a], at[b]), distance(flat[a], flat[b]));
            assert!(
                (now - then).abs() <= 1e-9 * size,
                "{path}: edge {a}-{b} {now} against {then}"
            );
        }
        // The angles the frame says, by crease, and each crease's dihedral from its faces.
        let degrees: Vec<f64> = serde_json::from_value(frame["edges_foldAngle"].clone()).unwrap();
        let angles: Vec<f64> = pattern.creases.iter().map(|&e| degrees[e].to_radians()).collect();
        for &e in &pattern.creases {
            let [a, b] = edges[e];
            let sides: Vec<&Vec<usize>> = faces.iter().filter(|f| f.contains(&a) && f.contains(&b)).collect();
            if sides.len() != 2 {
                continue;
            }
            let normal = |face: &Vec<usize>| {
                let n = face.len();
                (0..n)
                    .map(|k| minus(at[face[k]], at[face[0]]).cross(&minus(at[face[(k + 1) % n]], at[face[0]])))
                    .fold(nalgebra::Vector3::zeros(), |s, x| s + x)
                    .normalize()
            };
            let (n1, n2) = (normal(sides[0]), normal(sides[1]));
            let turn = n1.cross(&n2).norm().atan2(n1.dot(&n2));
            assert!(
                (turn - degrees[e].to_radians().abs()).abs() < 1e-9,
                "{path}: crease {e} turns {turn} against {}",
                degrees[e].to_radians()
            );
            largest_fold = largest_fold.max(turn);
        }
        // Every corner of every face, as a mark on that face.
        points.pose(&angles);
        for (f, face) in faces.iter().enumerate() {
            let panel = points.panel(f).unwrap();
            for &v in face {
                let mark = points.place(panel, [flat[v][0] * unit_um, flat[v][1] * unit_um]);
                let written = at[v].map(|c| c * unit_um);
                assert!(
                    distance(mark, written) <= 1e-9 * size * unit_um,
                    "{path}: vertex {v} as a mark on face {f}: {mark:?} against {written:?}"
                );
            }
        }
    }
    assert!(
        largest_fold > 0.3,
        "{path}: the device hardly folds ({largest_fold} rad)"
    );
}

#[test]
fn marks_on_every_panel_of_the_miura_ori_sheet_land_on_its_motion() {
    network_marks_land_on_the_motion("patterns/devices/miura_sheet.scene.json", None);
}

#[test]
fn marks_on_every_panel_of_the_waterbomb_sheet_land_on_its_motion() {
    network_marks_land_on_the_motion("patterns/devices/waterbomb_sheet.scene.json", Some(2e-4));
}

#[test]
fn marks_on_every_panel_of_the_cube_net_land_on_its_motion() {
    network_marks_land_on_the_motion("patterns/devices/cube_closes.scene.json", None);
}

/// A strip's or a closed vertex's motion (µm, face 0 fixed, face 1 + j joint j's plate):
/// every plate rigid, every corner of every plate where a mark on it lands, the fixed face
/// unmoved, and corners that two plates share (as flat points) one point in every frame:
/// to 1e-9 of the size, or, across a closed vertex's cut crease, to the loop closure the
/// run reports (its constraint's own accuracy).
fn plate_marks_land_on_the_motion(path: &str) {
    let scene = open_scene(path.as_ref()).unwrap();
    let report = simulate(&scene, &SimulationSettings::default()).unwrap();
    let shared = report.to_json()["max_closure_residual"]
        .as_f64()
        .unwrap_or(0.0)
        .max(1e-9);
    let motion = &report.fold;
    let mut points = PanelPoints::new(&scene).unwrap();
    let mut outlines = points.plate_outlines();
    // The user's name of each plate: a strip's plate index, a closed vertex's FOLD face.
    let named: Vec<Option<usize>> = match &scene.system {
        System::Strip(chain) => {
            // The substrate is face 0, not a panel.
            outlines.insert(
                0,
                nanofold::dynamics::points::FlatOutline {
                    panel: usize::MAX,
                    corners: Vec::new(),
                },
            );
            std::iter::once(None).chain((0..chain.model.dof()).map(Some)).collect()
        }
        System::Closed(chain) => std::iter::once(Some(chain.anchored_face))
            .chain(chain.joint_sectors.iter().map(|&s| chain.sector_faces[s]))
            .collect(),
        System::Network(_) => panic!("{path}: a strip or a closed vertex"),
    };
    let faces: Vec<Vec<usize>> = serde_json::from_value(motion["faces_vertices"].clone()).unwrap();
    assert_eq!(faces.len(), outlines.len(), "{path}");
    let mut frames = vec![motion.clone()];
    frames.extend(motion["file_frames"].as_array().cloned().unwrap_or_default());
    assert!(frames.len() > 10, "{path}: {} frames", frames.len());
    let key = vertices(motion);
    let size = key.iter().map(|&p| distance(p, key[0])).fold(0.0, f64::max);
    let mut largest_move = 0.0_f64;
    for frame in &frames {
        let at = if frame.get("vertices_coords").is_some() {
            vertices(frame)
        } else {
            key.clone()
        };
        let degrees: Vec<f64> = serde_json::from_value(frame["edges_foldAngle"].clone()).unwrap();
        // The output angles this frame is of: a strip's hinges, or every crease of the vertex.
        let angles: Vec<f64> = match &scene.system {
            System::Closed(chain) => {
                let mut all = vec![0.0; chain.crease_labels.len()];
                // Joint j's hinge edge is the one crease edge of face 1 + j.
                let edges: Vec<[usize; 2]> = serde_json::from_value(motion["edges_vertices"].clone()).unwrap();
                let letters: Vec<String> = serde_json::from_value(motion["edges_assignment"].clone()).unwrap();
                for (j, &c) in chain.joint_creases.iter().enumerate() {
                    let face = &faces[1 + j];
                    let e = (0..edges.len())
                        .find(|&e| letters[e] != "B" && face.contains(&edges[e][0]) && face.contains(&edges[e][1]))
                        .expect("each plate's hinge");
                    all[c] = degrees[e].to_radians();
                }
                all
            }
            _ => {
                let edges: Vec<[usize; 2]> = serde_json::from_value(motion["edges_vertices"].clone()).unwrap();
                let letters: Vec<String> = serde_json::from_value(motion["edges_assignment"].clone()).unwrap();
                (1..faces.len())
                    .map(|f| {
                        let e = (0..edges.len())
                            .find(|&e| {
                                letters[e] != "B" && faces[f].contains(&edges[e][0]) && faces[f].contains(&edges[e][1])
                            })
                            .expect("each plate's hinge");
                        degrees[e].to_radians()
                    })
                    .collect()
            }
        };
        points.pose(&angles);
        for (f, face) in faces.iter().enumerate() {
            let Some(user) = named[f] else {
                // The substrate: where it was.
                for &v in face {
                    assert!(distance(at[v], key[v]) <= 1e-9 * size, "{path}: the substrate moved");
                }
                continue;
            };
            let panel = points.panel(user).unwrap();
            for (k, &v) in face.iter().enumerate() {
                let flat = outlines[f].corners[k];
                let mark = points.place(panel, flat);
                assert!(
                    distance(mark, at[v]) <= 1e-9 * size,
                    "{path}: corner {k} of face {f} as a mark: {mark:?} against {:?}",
                    at[v]
                );
                largest_move = largest_move.max(distance(at[v], [flat[0], flat[1], 0.0]));
                // Rigid: each edge of the plate as long as flat.
                let (w, next) = (face[(k + 1) % face.len()], outlines[f].corners[(k + 1) % face.len()]);
                let flat_length = ((next[0] - flat[0]).powi(2) + (next[1] - flat[1]).powi(2)).sqrt();
                assert!(
                    (distance(at[v], at[w]) - flat_length).abs() <= 1e-9 * size,
                    "{path}: an edge of face {f} stretched"
                );
            }
        }
        // Corners two plates share when flat are one point folded.
        for f in 0..faces.len() {
            for g in f + 1..faces.len() {
                for (k, &v) in faces[f].iter().enumerate() {
                    for (l, &w) in faces[g].iter().enumerate() {
                        let (a, b) = (outlines[f].corners.get(k), outlines[g].corners.get(l));
                        let same_flat = match (a, b) {
                            (Some(a), Some(b)) => (a[0] - b[0]).abs() + (a[1] - b[1]).abs() <= 1e-9 * size,
                            _ => false,
                        };
                        if same_flat {
                            assert!(
                                distance(at[v], at[w]) <= shared * size,
                                "{path}: a corner of faces {f} and {g} is two points: {}",
                                distance(at[v], at[w]) / size
                            );
                        }
                    }
                }
            }
        }
    }
    assert!(largest_move > 0.1 * size, "{path}: the device hardly moves");
}

#[test]
fn marks_on_every_plate_of_the_bridge_strip_land_on_its_motion() {
    plate_marks_land_on_the_motion("patterns/bridge_step.scene.json");
}

#[test]
fn marks_on_every_sector_of_a_closed_vertex_land_on_its_motion() {
    plate_marks_land_on_the_motion("patterns/corner_cube_step1.scene.json");
}
