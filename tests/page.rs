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
