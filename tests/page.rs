//! The 3D page (`plot::page`): its data decode to the frames' geometry to within the stated
//! quantum, it makes no network request, and bad scenes get errors naming the field. (The
//! page's drawing is tested in a real browser by `scripts/browser_test.sh`.)

use nanofold::plot::{page_html, PageFrame, PageScene, MAX_PAGE_POINTS};

fn square(frames: usize) -> PageScene {
    PageScene {
        title: "square </script> & co".into(),
        unit: "µm".into(),
        faces: vec![vec![0, 1, 2, 3]],
        edges: vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
        assignments: vec!['B', 'B', 'B', 'B', 'V'],
        frames: (0..frames)
            .map(|k| {
                let lift = k as f64 * 0.37;
                PageFrame {
                    title: format!("frame {k}"),
                    coords: vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, lift], [0.0, 2.0, 0.0]],
                    fold_angles_deg: Some(vec![0.0, 0.0, 0.0, 0.0, 10.0 * k as f64]),
                    highlight: Vec::new(),
                }
            })
            .collect(),
        fixed: Vec::new(),
    }
}

fn data(html: &str) -> serde_json::Value {
    let start = html.find(r#"<script type="application/json" id="data">"#).unwrap();
    let body = &html[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</script>").unwrap();
    serde_json::from_str(&body[open..close].replace("<\\/", "</")).unwrap()
}

#[test]
fn the_pages_data_decode_to_the_frames_to_within_the_quantum() {
    let scene = square(3);
    let html = page_html(&scene).unwrap();
    // One document, nothing fetched: no URL of any scheme but the page's own.
    assert!(!html.contains("http://") && !html.contains("https://") && !html.contains(" src="));
    // The title is escaped in the head and cannot end the data's script element.
    assert!(html.contains("<title>square &lt;/script&gt; &amp; co</title>"));
    let value = data(&html);
    let step = value["step"].as_f64().unwrap();
    for (k, frame) in scene.frames.iter().enumerate() {
        let q: Vec<f64> = value["frames"][k]["q"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        // The page recentres: differences between vertices are what it keeps.
        for a in 0..4 {
            for b in 0..4 {
                for c in 0..3 {
                    let kept = (q[3 * a + c] - q[3 * b + c]) * step;
                    let given = frame.coords[a][c] - frame.coords[b][c];
                    assert!((kept - given).abs() <= step, "frame {k}: {kept} against {given}");
                }
            }
        }
        assert_eq!(value["frames"][k]["a"][4].as_f64().unwrap(), 10.0 * k as f64);
    }
    assert_eq!(value["letters"], "BBBBV");
}

#[test]
fn bad_scenes_are_refused_by_name() {
    let message = |scene: PageScene| page_html(&scene).unwrap_err().to_string();
    assert!(message(square(0)).contains("frames"));
    let mut scene = square(2);
    scene.frames[1].coords.pop();
    assert!(message(scene).contains("frames[1].coords"));
    let mut scene = square(2);
    scene.frames[0].coords[2][1] = f64::NAN;
    assert!(message(scene).contains("frames[0].coords"));
    let mut scene = square(1);
    scene.edges.push([0, 9]);
    assert!(message(scene).contains('9'));
    let mut scene = square(1);
    scene.frames[0].highlight = vec![4];
    assert!(message(scene).contains("highlight"));
    let mut scene = square(1);
    scene.fixed = vec![7];
    let refused = message(scene);
    assert!(refused.contains("fixed") && refused.contains('7'), "{refused}");
    let frames = MAX_PAGE_POINTS / 4 + 1;
    assert!(message(square(frames)).contains("at most"));
}

/// A FOLD animation as another tool writes it: the 2D key frame is dropped where 3D frames
/// follow, a frame's missing faces come from the file, the last frame carries the contact
/// faces, and a physical scale multiplies every coordinate (the scale bar's unit with it).
#[test]
fn a_fold_animation_becomes_a_page_in_physical_units() {
    use nanofold::plot::page_of_fold;
    let fold = serde_json::json!({
        "file_spec": 1.1,
        "frame_unit": "unit",
        "vertices_coords": [[0, 0], [1, 0], [1, 1], [0, 1]],
        "edges_vertices": [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
        "edges_assignment": ["B", "B", "B", "B", "V"],
        "faces_vertices": [[0, 1, 2], [0, 2, 3]],
        "file_frames": [
            {"frame_title": "half", "vertices_coords": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0.5, 0.5, 0.7]]},
            {"frame_title": "shut", "vertices_coords": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 0, 0.0]], "edges_foldAngle": [0, 0, 0, 0, 180]}
        ]
    });
    let html = page_of_fold(&fold, "square", &[0, 1], Some((100.0, "µm"))).unwrap();
    let value = data(&html);
    assert_eq!(value["unit"], "µm");
    let frames = value["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2, "the flat key frame is left out");
    assert_eq!(frames[0]["t"], "half");
    assert_eq!(frames[1]["h"], serde_json::json!([0, 1]));
    assert!(frames[0]["h"].as_array().unwrap().is_empty());
    assert_eq!(frames[1]["a"][4].as_f64().unwrap(), 180.0);
    // Vertex 1 − vertex 0 is one file unit along x: 100 µm on the page.
    let step = value["step"].as_f64().unwrap();
    let x = |i: usize| frames[0]["q"][i].as_f64().unwrap() * step;
    assert!((x(3) - x(0) - 100.0).abs() <= step, "{}", x(3) - x(0));
    // No faces at all is refused by name.
    let mut bare = fold.clone();
    bare.as_object_mut().unwrap().remove("faces_vertices");
    let message = page_of_fold(&bare, "square", &[], None).unwrap_err().to_string();
    assert!(message.contains("faces_vertices"), "{message}");
}

/// Positions of a page frame's vertices, decoded (recentred, in the page's unit).
fn positions(value: &serde_json::Value, frame: usize) -> Vec<[f64; 3]> {
    let step = value["step"].as_f64().unwrap();
    let q: Vec<f64> = value["frames"][frame]["q"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() * step)
        .collect();
    q.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn face_normal(points: &[[f64; 3]], face: &[usize]) -> nalgebra::Vector3<f64> {
    let p = |k: usize| nalgebra::Vector3::from(points[face[k]]);
    (p(1) - p(0)).cross(&(p(2) - p(0))).normalize()
}

/// A strip's response page: the substrate stays put, the angle between consecutive plates'
/// normals, measured on the page's own coordinates, is the simulated hinge angle, and the
/// first contact (plate 3 with the substrate) is marked on the last frame alone.
#[test]
fn a_strips_response_page_shows_its_hinge_angles_and_its_contact() {
    use nanofold::dynamics::simulate::{simulate_scene, SimulationSettings};
    let scene = nanofold::prelude::load_scene("patterns/bridge_step.scene.json".as_ref())
        .unwrap()
        .build()
        .unwrap();
    let simulation = simulate_scene(&scene, &SimulationSettings::default()).unwrap();
    let collision = simulation
        .response
        .collision
        .as_ref()
        .expect("the bridge's plate 3 meets the substrate");
    assert_eq!(collision.pair, ["plate 3".to_string(), "substrate".to_string()]);
    let html = nanofold::plot::response_page(&scene, &simulation.response).unwrap();
    let value = data(&html);
    assert_eq!(value["unit"], "µm");
    assert_eq!(value["fixed"], serde_json::json!([0]));
    let faces: Vec<Vec<usize>> = serde_json::from_value(value["faces"].clone()).unwrap();
    let letters: Vec<char> = value["letters"].as_str().unwrap().chars().collect();
    let frames = value["frames"].as_array().unwrap();
    assert!(frames.len() > 90 && frames.len() <= nanofold::write::MOTION_FRAMES);
    let step = value["step"].as_f64().unwrap();
    let start = positions(&value, 0);
    let mut worst: f64 = 0.0;
    for (k, frame) in frames.iter().enumerate() {
        let points = positions(&value, k);
        for &v in &faces[0] {
            for c in 0..3 {
                assert!((points[v][c] - start[v][c]).abs() <= step, "the substrate moved");
            }
        }
        // Each plate's hinge edge carries its angle; the dihedral is the one between normals.
        let angles = frame["a"].as_array().unwrap();
        for plate in 1..faces.len() {
            // The substrate's 4 edges come first, then each plate's 4.
            let hinge = (4 * plate..4 * plate + 4)
                .find(|&e| letters[e] != 'B')
                .expect("every plate's hinge edge is a crease");
            let angle = angles[hinge].as_f64().unwrap().to_radians();
            let between = face_normal(&points, &faces[plate - 1])
                .dot(&face_normal(&points, &faces[plate]))
                .clamp(-1.0, 1.0)
                .acos();
            worst = worst.max((between - angle.abs()).abs());
        }
        let highlight = frame["h"].as_array().unwrap();
        if k + 1 == frames.len() {
            assert_eq!(frame["h"], serde_json::json!([0, 4]), "substrate and plate 3");
        } else {
            assert!(highlight.is_empty(), "frame {k} marks a contact");
        }
    }
    // Coordinates are kept to 1e-5 of the half-size on plates ~100 µm long in a ~500 µm scene.
    assert!(
        worst < 1e-3,
        "dihedral from the page's coordinates against the hinge angle: {worst:.2e} rad"
    );
}

/// A closed chain's modes page: its loop stays closed in every frame (as many distinct
/// corner positions as the flat sheet has, the cut crease's two copies meeting), phases 0 and 6
/// are the equilibrium, and a quarter cycle moves the largest coordinate by the amplitude.
#[test]
fn a_closed_chains_modes_page_oscillates_with_its_loop_closed() {
    use nanofold::dynamics::scene::System;
    use nanofold::plot::{closed_modes_page, closed_scene, MODE_PHASES};
    let scene = nanofold::prelude::load_scene("patterns/corner_cube_step2.scene.json".as_ref())
        .unwrap()
        .build()
        .unwrap();
    let System::Closed(chain) = &scene.system else {
        panic!("a closed chain")
    };
    let modes = chain.folded_modes().unwrap();
    let amplitude = 0.1;
    let value = data(&closed_modes_page(&scene.name, chain, &modes, amplitude).unwrap());
    let frames = value["frames"].as_array().unwrap();
    let count = modes.modes.eigenvalues.len();
    assert_eq!(frames.len(), 1 + count * MODE_PHASES);
    let half = value["half"].as_f64().unwrap();
    let distinct = |points: &[[f64; 3]], tol: f64| {
        let mut kept: Vec<[f64; 3]> = Vec::new();
        for p in points {
            if !kept.iter().any(|q| (0..3).all(|c| (p[c] - q[c]).abs() <= tol)) {
                kept.push(*p);
            }
        }
        kept.len()
    };
    let flat = closed_scene(
        &scene.name,
        chain,
        &[("flat".into(), vec![0.0; chain.crease_labels.len()])],
    )
    .unwrap();
    let flat_count = distinct(&flat.frames[0].coords, 1e-9 * half);
    for k in 0..frames.len() {
        assert_eq!(
            distinct(&positions(&value, k), 1e-4 * half),
            flat_count,
            "frame {k}: the loop is open"
        );
    }
    let angles = |k: usize| -> Vec<f64> {
        frames[k]["a"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a.as_f64().unwrap())
            .collect()
    };
    for mode in 0..count {
        let first = 1 + mode * MODE_PHASES;
        for phase in [0, MODE_PHASES / 2] {
            let moved = angles(first + phase)
                .iter()
                .zip(angles(0))
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                moved < 2e-3,
                "mode {mode} phase {phase} is not the equilibrium: {moved}°"
            );
        }
        let quarter = angles(first + MODE_PHASES / 4);
        let moved = quarter
            .iter()
            .zip(angles(0))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            moved >= amplitude.to_degrees() - 2e-3,
            "mode {mode}: a quarter cycle moves {moved}°"
        );
    }
}

/// `nanofold view` of a file another tool wrote (Origami Simulator's export of a folded
/// state at 50 %): one frame, every vertex where the file puts it (to the quantum), the
/// file's assignments.
#[test]
fn view_draws_an_origami_simulator_export_where_the_file_puts_it() {
    let input = "tests/fixtures/origami-simulator/simple_50.fold";
    let out = std::env::temp_dir().join(format!("nanofold-view-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_nanofold"))
        .args(["view", input, "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let value = data(&std::fs::read_to_string(out.join("view.html")).unwrap());
    let file: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(input).unwrap()).unwrap();
    let given: Vec<Vec<f64>> = serde_json::from_value(file["vertices_coords"].clone()).unwrap();
    assert_eq!(value["frames"].as_array().unwrap().len(), 1);
    let shown = positions(&value, 0);
    assert_eq!(shown.len(), given.len());
    let step = value["step"].as_f64().unwrap();
    for (a, b) in [(0, shown.len() - 1), (1, shown.len() / 2)] {
        for (c, (x, y)) in shown[a].iter().zip(&shown[b]).enumerate() {
            let kept = x - y;
            let wanted = given[a].get(c).copied().unwrap_or(0.0) - given[b].get(c).copied().unwrap_or(0.0);
            assert!(
                (kept - wanted).abs() <= step,
                "vertex {a} − {b}, axis {c}: {kept} against {wanted}"
            );
        }
    }
    let letters: String = file["edges_assignment"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap().chars().next().unwrap().to_ascii_uppercase())
        .collect();
    assert_eq!(value["letters"].as_str().unwrap(), letters);
    assert!(
        shown.iter().any(|p| p[2].abs() > 100.0 * step),
        "the folded state is drawn in 3D"
    );
    let _ = std::fs::remove_dir_all(&out);
}
