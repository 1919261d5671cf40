//! The 3D page (`plot::page`): its data decode to the frames' geometry to within the stated
//! quantum, it makes no network request, and bad scenes get errors naming the field. (The
//! page's drawing is tested in a real browser by `scripts/browser_test.sh`.)

use nanofold::plot::page::{page_html, PageFrame, PageScene, MAX_PAGE_POINTS};

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
    let frames = MAX_PAGE_POINTS / 4 + 1;
    assert!(message(square(frames)).contains("at most"));
}

/// A FOLD animation as another tool writes it: the 2D key frame is dropped where 3D frames
/// follow, a frame's missing faces come from the file, the last frame carries the contact
/// faces, and a physical scale multiplies every coordinate (the scale bar's unit with it).
#[test]
fn a_fold_animation_becomes_a_page_in_physical_units() {
    use nanofold::plot::page::page_of_fold;
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
