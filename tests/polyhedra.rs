//! The solids a net is designed for: the generated solids against their known counts (faces,
//! Euler's formula, spanning trees of the dual graph, symmetry groups), and a surface that is
//! not a closed solid refused by name.

use nalgebra::Point3;

mod common;
use common::fitted_distance;
use nanofold::geometry::polyhedron::Polyhedron;
use nanofold::geometry::solids;

/// (faces, edges, vertices, spanning trees, symmetries).
fn counts(solid: &Polyhedron) -> (usize, usize, usize, f64, usize) {
    (
        solid.faces.len(),
        solid.dual_edges().len(),
        solid.vertices.len(),
        solid.spanning_tree_count(),
        solid.symmetries().len(),
    )
}

#[test]
fn the_platonic_solids_have_their_known_trees_and_symmetry_groups() {
    // Trees and group orders as tabulated for edge unfoldings (tetrahedron 16 / 24, cube and
    // octahedron 384 / 48, dodecahedron and icosahedron 5 184 000 / 120).
    let cases = [
        ("tetrahedron", solids::tetrahedron().unwrap(), (4, 6, 4, 16.0, 24)),
        ("cube", solids::cube().unwrap(), (6, 12, 8, 384.0, 48)),
        ("octahedron", solids::octahedron().unwrap(), (8, 12, 6, 384.0, 48)),
        (
            "dodecahedron",
            solids::dodecahedron().unwrap(),
            (12, 30, 20, 5_184_000.0, 120),
        ),
        (
            "icosahedron",
            solids::icosahedron().unwrap(),
            (20, 30, 12, 5_184_000.0, 120),
        ),
    ];
    for (name, solid, expected) in cases {
        assert_eq!(counts(&solid), expected, "{name}");
        let rotations = solid.symmetries().iter().filter(|s| s.is_rotation()).count();
        assert_eq!(2 * rotations, expected.4, "{name}: half the group are rotations");
    }
}

#[test]
fn generated_solids_obey_euler_and_their_symmetry_groups() {
    // Euler: V − E + F = 2. Groups: a box of three different sides D2h (8), a cube Oh (48);
    // over an n-gon (n ≠ 4, where a prism of the right height is a cube) a prism D_nh (4n),
    // an antiprism D_nd (4n), a pyramid C_nv (2n); the truncated tetrahedron Td (24), the
    // cuboctahedron and the truncated octahedron Oh (48).
    let mut cases = vec![
        ("box 1 × 2 × 3", solids::cuboid(1.0, 2.0, 3.0).unwrap(), 8),
        ("box 2 × 2 × 2", solids::cuboid(2.0, 2.0, 2.0).unwrap(), 48),
        ("truncated tetrahedron", solids::truncated_tetrahedron().unwrap(), 24),
        ("cuboctahedron", solids::cuboctahedron().unwrap(), 48),
        ("truncated octahedron", solids::truncated_octahedron().unwrap(), 48),
    ];
    for n in [3, 5, 6, 7, 12] {
        cases.push(("prism", solids::prism(n, 0.7).unwrap(), 4 * n));
        cases.push(("antiprism", solids::antiprism(n, 0.7).unwrap(), 4 * n));
        cases.push(("pyramid", solids::pyramid(n, 0.7).unwrap(), 2 * n));
    }
    for (name, solid, group) in cases {
        let (f, e, v, trees, symmetries) = counts(&solid);
        assert_eq!(v + f, e + 2, "{name}: Euler");
        assert_eq!(symmetries, group, "{name} ({f} faces)");
        assert!(trees >= f as f64, "{name}: {trees} trees");
    }
    // Faces of the Archimedean solids by their sides.
    let sides = |solid: &Polyhedron| {
        let mut s: Vec<usize> = solid.faces.iter().map(Vec::len).collect();
        s.sort_unstable();
        s
    };
    assert_eq!(
        sides(&solids::truncated_tetrahedron().unwrap()),
        [[3; 4].as_slice(), &[6; 4]].concat()
    );
    assert_eq!(
        sides(&solids::cuboctahedron().unwrap()),
        [[3; 8].as_slice(), &[4; 6]].concat()
    );
    assert_eq!(
        sides(&solids::truncated_octahedron().unwrap()),
        [[4; 6].as_slice(), &[6; 8]].concat()
    );
}

#[test]
fn a_surface_that_is_not_a_closed_solid_is_refused_by_name() {
    let cube = solids::cube().unwrap();
    let refused = |vertices: Vec<Point3<f64>>, faces: Vec<Vec<usize>>, expected: &[&str]| {
        let message = Polyhedron::new(vertices, faces).unwrap_err().to_string();
        for part in expected {
            assert!(message.contains(part), "{message:?} lacks {part:?}");
        }
    };
    // A face missing: the surface is open along that face's edges.
    refused(cube.vertices.clone(), cube.faces[1..].to_vec(), &["edge", "not closed"]);
    // One face wound the wrong way.
    let mut faces = cube.faces.clone();
    faces[2].reverse();
    refused(cube.vertices.clone(), faces, &["faces[", "wound"]);
    // Every face wound the wrong way: inside out.
    let inside_out: Vec<Vec<usize>> = cube.faces.iter().map(|f| f.iter().rev().copied().collect()).collect();
    refused(cube.vertices.clone(), inside_out, &["volume", "inside out"]);
    // A vertex moved off its faces' planes.
    let mut vertices = cube.vertices.clone();
    vertices[0].z += 0.1;
    refused(vertices, cube.faces.clone(), &["faces[", "off its plane"]);
    // An index past the vertices, and a repeated vertex.
    let mut faces = cube.faces.clone();
    faces[0][0] = 99;
    refused(cube.vertices.clone(), faces, &["faces[0]", "vertex 99 does not exist"]);
    let mut faces = cube.faces.clone();
    faces[0][1] = faces[0][0];
    refused(cube.vertices.clone(), faces, &["faces[0]", "repeats"]);
    // Two separate cubes are two surfaces.
    let mut vertices = cube.vertices.clone();
    vertices.extend(cube.vertices.iter().map(|p| Point3::new(p.x + 10.0, p.y, p.z)));
    let mut faces = cube.faces.clone();
    faces.extend(cube.faces.iter().map(|f| f.iter().map(|v| v + 8).collect::<Vec<_>>()));
    refused(vertices, faces, &["separate surfaces"]);
    // Bad generator arguments.
    assert!(solids::prism(2, 1.0).unwrap_err().to_string().contains("sides"));
    assert!(solids::cuboid(1.0, -1.0, 1.0).unwrap_err().to_string().contains('b'));
}

#[test]
fn the_nets_of_the_tetrahedron_cube_and_octahedron_are_2_11_and_11() {
    use nanofold::geometry::unfoldings::{burnside_nets, distinct_nets, edge_map, spanning_trees};
    for (name, solid, nets) in [
        ("tetrahedron", solids::tetrahedron().unwrap(), 2),
        ("cube", solids::cube().unwrap(), 11),
        ("octahedron", solids::octahedron().unwrap(), 11),
    ] {
        let trees = spanning_trees(&solid, 10_000).unwrap();
        // As many as the matrix-tree theorem says, all different, each F − 1 folds.
        assert_eq!(trees.len() as f64, solid.spanning_tree_count(), "{name}");
        let unique: std::collections::HashSet<_> = trees.iter().collect();
        assert_eq!(unique.len(), trees.len(), "{name}");
        assert!(trees.iter().all(|t| t.count_ones() as usize == solid.faces.len() - 1));
        let maps: Vec<Vec<usize>> = solid.symmetries().iter().map(|s| edge_map(&solid, s)).collect();
        assert_eq!(distinct_nets(&trees, &maps).len(), nets, "{name}: orbits");
        assert_eq!(burnside_nets(&trees, &maps), nets as f64, "{name}: Burnside");
    }
    // More trees than the limit: refused, naming the count.
    let message = spanning_trees(&solids::dodecahedron().unwrap(), 1000)
        .unwrap_err()
        .to_string();
    assert!(message.contains("5184000"), "{message}");
}

#[test]
fn nets_lay_flat_true_to_their_faces_and_the_platonic_ones_never_overlap() {
    use nanofold::geometry::nets::{lay_flat, leaves, seam_length};
    use nanofold::geometry::unfoldings::spanning_trees;
    // (The dodecahedron's and icosahedron's millions: examples/count_nets.)
    for (name, solid) in [
        ("tetrahedron", solids::tetrahedron().unwrap()),
        ("cube", solids::cube().unwrap()),
        ("octahedron", solids::octahedron().unwrap()),
    ] {
        let trees = spanning_trees(&solid, 1_000).unwrap();
        let edges = solid.dual_edges();
        let length = |e: &nanofold::geometry::polyhedron::DualEdge| {
            (solid.vertices[e.vertices[0]] - solid.vertices[e.vertices[1]]).norm()
        };
        let surface: f64 = (0..solid.faces.len()).map(|f| solid.face_normal(f).norm() / 2.0).sum();
        for &tree in &trees {
            let net = lay_flat(&solid, tree);
            let at = |f: usize, v: usize| net.faces[f][solid.faces[f].iter().position(|&w| w == v).unwrap()];
            // Every face keeps its edges' lengths, its winding (not mirrored) and its area.
            let mut area = 0.0;
            for (f, corners) in net.faces.iter().enumerate() {
                let face = &solid.faces[f];
                let mut twice = 0.0;
                for k in 0..face.len() {
                    let (a, b) = (corners[k], corners[(k + 1) % face.len()]);
                    let real = (solid.vertices[face[k]] - solid.vertices[face[(k + 1) % face.len()]]).norm();
                    assert!(((b - a).norm() - real).abs() < 1e-12 * real, "{name}: face {f}");
                    twice += a.x * b.y - a.y * b.x;
                }
                assert!(twice > 0.0, "{name}: face {f} mirrored");
                area += twice / 2.0;
            }
            assert!((area - surface).abs() < 1e-12 * surface, "{name}: area");
            // Faces across a fold share its edge in the plane.
            for &k in &net.folds {
                let e = &edges[k];
                for v in e.vertices {
                    assert!(
                        (at(e.faces[0], v) - at(e.faces[1], v)).norm() < 1e-9,
                        "{name}: fold {k}"
                    );
                }
            }
            // Horiyama & Shoji: no edge unfolding of a Platonic solid overlaps.
            assert!(net.overlapping_pairs().is_empty(), "{name}: tree {tree:b} overlaps");
            // The seams are the cut edges: E − (F − 1) of them, the rest of the edges' length.
            assert_eq!(net.seams.len(), edges.len() + 1 - solid.faces.len());
            let total: f64 = edges.iter().map(length).sum();
            let folded: f64 = net.folds.iter().map(|&k| length(&edges[k])).sum();
            assert!((seam_length(&solid, tree) - (total - folded)).abs() < 1e-12 * total);
        }
        if name == "tetrahedron" {
            // K4's 16 spanning trees: 4 stars (3 leaves) and 12 paths (2).
            let mut by_leaves = [0usize; 4];
            for &tree in &trees {
                by_leaves[leaves(&solid, tree)] += 1;
            }
            assert_eq!(by_leaves, [0, 0, 12, 4]);
        }
    }
}

#[test]
fn a_cube_nets_radius_of_gyration_is_its_squares_own() {
    use nanofold::geometry::nets::lay_flat;
    use nanofold::geometry::unfoldings::spanning_trees;
    // Six squares of side s: Rg² = (1/6) Σ |c_f − c|² + s²/6 (a square's polar moment about
    // its centre is A s²/6), with c_f the squares' centres.
    let cube = solids::cube().unwrap();
    let side = 2.0;
    let mut seen = Vec::new();
    for tree in spanning_trees(&cube, 1000).unwrap() {
        let net = lay_flat(&cube, tree);
        let centres: Vec<_> = net
            .faces
            .iter()
            .map(|f| f.iter().fold(nalgebra::Vector2::zeros(), |s, p| s + p.coords) / 4.0)
            .collect();
        let c = centres.iter().fold(nalgebra::Vector2::zeros(), |s, x| s + x) / 6.0;
        let expected = (centres.iter().map(|x| (x - c).norm_squared()).sum::<f64>() / 6.0 + side * side / 6.0).sqrt();
        let rg = net.radius_of_gyration();
        assert!((rg - expected).abs() < 1e-12 * expected, "{rg} against {expected}");
        if !seen.iter().any(|&x: &f64| (x - rg).abs() < 1e-9) {
            seen.push(rg);
        }
    }
    // The 11 nets are not all equally compact.
    assert!(seen.len() > 3, "{seen:?}");
}

#[test]
fn a_nets_footprint_is_the_smallest_rectangle_over_every_turn() {
    use nanofold::geometry::nets::NetLayout;
    use nanofold::geometry::unfoldings::spanning_trees;
    // Against a brute search over turns of 0.005 degrees: the rotating-calipers answer must
    // be no larger than any, and within the search's resolution of the best.
    for solid in [
        solids::cube().unwrap(),
        solids::octahedron().unwrap(),
        solids::tetrahedron().unwrap(),
    ] {
        let layout = NetLayout::new(&solid);
        for tree in spanning_trees(&solid, 1000).unwrap().into_iter().step_by(7) {
            let net = layout.lay_flat(tree);
            let (long, short) = net.footprint();
            assert!(long >= short && short > 0.0);
            let points: Vec<_> = net.faces.iter().flatten().collect();
            let mut best = f64::INFINITY;
            for step in 0..36_000 {
                let angle = (step as f64 * 0.005).to_radians();
                let (u, v) = (
                    nalgebra::Vector2::new(angle.cos(), angle.sin()),
                    nalgebra::Vector2::new(-angle.sin(), angle.cos()),
                );
                let span = |axis: nalgebra::Vector2<f64>| {
                    let values = points.iter().map(|p| p.coords.dot(&axis));
                    values.clone().fold(f64::NEG_INFINITY, f64::max) - values.fold(f64::INFINITY, f64::min)
                };
                best = best.min(span(u) * span(v));
            }
            let area = long * short;
            assert!(area <= best * (1.0 + 1e-12), "{area} above a turn's {best}");
            // The area has a corner at its minimum, so a turn δ off it costs ~δ (w/h + h/w):
            // 8.7e-5 rad × a few.
            assert!(area >= best * (1.0 - 5e-4), "{area} below every turn's {best}");
        }
    }
    // The tetrahedron's triangular net: a triangle of side 2a in a 2a × √3 a rectangle.
    let tetrahedron = solids::tetrahedron().unwrap();
    let layout = NetLayout::new(&tetrahedron);
    let a = (tetrahedron.vertices[0] - tetrahedron.vertices[1]).norm();
    let triangles: Vec<_> = spanning_trees(&tetrahedron, 100)
        .unwrap()
        .into_iter()
        .map(|t| layout.lay_flat(t).footprint())
        .filter(|&(long, short)| (long - 2.0 * a).abs() < 1e-12 * a && (short - 3f64.sqrt() * a).abs() < 1e-12 * a)
        .collect();
    assert_eq!(triangles.len(), 4, "the star trees fold to the big triangle");
}

#[test]
fn convex_faces_overlap_only_through_their_interiors() {
    use nalgebra::Point2;
    use nanofold::geometry::nets::convex_overlap;
    let square = |x: f64, y: f64| {
        vec![
            Point2::new(x, y),
            Point2::new(x + 1.0, y),
            Point2::new(x + 1.0, y + 1.0),
            Point2::new(x, y + 1.0),
        ]
    };
    assert!(
        !convex_overlap(&square(0.0, 0.0), &square(1.0, 0.0), 1e-12),
        "a shared edge"
    );
    assert!(
        !convex_overlap(&square(0.0, 0.0), &square(1.0, 1.0), 1e-12),
        "a shared corner"
    );
    assert!(convex_overlap(&square(0.0, 0.0), &square(0.5, 0.0), 1e-12), "half over");
    assert!(
        convex_overlap(&square(0.0, 0.0), &square(0.999, 0.999), 1e-12),
        "a corner over"
    );
    let triangle = vec![Point2::new(1.5, -1.0), Point2::new(3.0, 0.5), Point2::new(1.5, 0.5)];
    assert!(
        !convex_overlap(&square(0.0, 0.0), &triangle, 1e-12),
        "apart along a diagonal"
    );
}

#[test]
fn sampled_trees_are_uniform_over_the_cubes_384() {
    use nanofold::geometry::unfoldings::{sample_trees, spanning_trees};
    let cube = solids::cube().unwrap();
    let all = spanning_trees(&cube, 1_000).unwrap();
    let draws = 38_400;
    let sampled = sample_trees(&cube, draws, 42).unwrap();
    let mut seen = std::collections::HashMap::new();
    for t in &sampled {
        *seen.entry(*t).or_insert(0usize) += 1;
    }
    // Every draw a spanning tree; all 384 drawn; Pearson's χ² against uniform (383 degrees of
    // freedom: mean 383, sd 27.7) below 520, which a uniform sampler exceeds with p < 1e-6.
    assert!(seen.keys().all(|t| all.contains(t)));
    assert_eq!(seen.len(), all.len());
    let expected = draws as f64 / all.len() as f64;
    let chi2: f64 = seen.values().map(|&n| (n as f64 - expected).powi(2) / expected).sum();
    assert!(chi2 < 520.0, "χ² {chi2}");
}

#[test]
fn the_l_tromino_has_its_trees_and_overlaps_in_about_two_unfoldings_of_five() {
    use nanofold::geometry::nets::lay_flat;
    use nanofold::geometry::unfoldings::sample_trees;
    let tromino = solids::polycube(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]]).unwrap();
    assert_eq!(tromino.faces.len(), 14);
    assert!((tromino.volume() - 3.0).abs() < 1e-12);
    assert_eq!(tromino.spanning_tree_count(), 2_488_976.0);
    // A uniform sample of 5 000 gave 0.394 (the issue); 4 000 draws here have a standard
    // error of 0.008.
    let trees = sample_trees(&tromino, 4_000, 7).unwrap();
    let overlapping = trees
        .iter()
        .filter(|&&t| !lay_flat(&tromino, t).overlapping_pairs().is_empty())
        .count() as f64
        / trees.len() as f64;
    eprintln!("L-tromino: {overlapping} of its sampled unfoldings overlap");
    assert!((overlapping - 0.394).abs() < 0.04, "{overlapping}");
    // Cubes that touch only along an edge, or only at a corner, or that repeat, are refused.
    let refused = |cubes: &[[i64; 3]], part: &str| {
        let message = solids::polycube(cubes).unwrap_err().to_string();
        assert!(message.contains(part), "{cubes:?}: {message}");
    };
    refused(&[[0, 0, 0], [1, 1, 0]], "more than two faces");
    refused(&[[0, 0, 0], [1, 1, 1]], "pinched");
    // Joined by faces the long way round, the first and last cube still meet at the corner
    // (1, 1, 1) only, and no other cube has that corner.
    refused(
        &[
            [0, 0, 0],
            [0, 0, -1],
            [1, 0, -1],
            [2, 0, -1],
            [2, 0, 0],
            [2, 0, 1],
            [2, 1, 1],
            [1, 1, 1],
        ],
        "pinched",
    );
    refused(&[[0, 0, 0], [0, 0, 0]], "repeats");
}

/// `solid` as OFF text.
fn off_text(solid: &Polyhedron) -> String {
    let mut text = format!(
        "OFF\n# written by the test\n{} {} 0\n",
        solid.vertices.len(),
        solid.faces.len()
    );
    for p in &solid.vertices {
        text += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    for f in &solid.faces {
        text += &format!(
            "{} {} 0.5 0.5 0.5\n",
            f.len(),
            f.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ")
        );
    }
    text
}

#[test]
fn solids_read_from_off_obj_and_fold_files_are_the_generated_ones() {
    use nanofold::read::solid::{load_solid, parse_fold_solid, parse_obj, parse_off};
    for solid in [
        solids::cube().unwrap(),
        solids::icosahedron().unwrap(),
        solids::pyramid(5, 1.0).unwrap(),
    ] {
        let off = parse_off(&off_text(&solid), "test.off").unwrap();
        // OBJ: 1-based, the faces in v/t/n form, the last face by negative indices.
        let mut obj = String::from("# test\no solid\n");
        for p in &solid.vertices {
            obj += &format!("v {} {} {}\nvn 0 0 1\n", p.x, p.y, p.z);
        }
        let n = solid.vertices.len();
        for (k, f) in solid.faces.iter().enumerate() {
            let corners: Vec<String> = if k + 1 == solid.faces.len() {
                f.iter().map(|&v| format!("{}", v as i64 - n as i64)).collect()
            } else {
                f.iter().map(|&v| format!("{}/1/1", v + 1)).collect()
            };
            obj += &format!("f {}\n", corners.join(" "));
        }
        let obj = parse_obj(&obj, "test.obj").unwrap();
        let fold = serde_json::json!({
            "file_spec": 1.1,
            "vertices_coords": solid.vertices.iter().map(|p| vec![p.x, p.y, p.z]).collect::<Vec<_>>(),
            "faces_vertices": solid.faces,
        });
        let fold = parse_fold_solid(&fold.to_string(), "test.fold").unwrap();
        for read in [&off, &obj, &fold] {
            // The same solid; the files' digits are a double's, so their tolerances are
            // the exact solid's floors.
            assert_eq!((&read.vertices, &read.faces), (&solid.vertices, &solid.faces));
            assert_eq!(read.tolerances.planarity, solid.tolerances.planarity);
        }
    }
    // Through a file, the format from its extension.
    let folder = std::env::temp_dir().join(format!("nanofold-solids-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    let path = folder.join("cube.off");
    std::fs::write(&path, off_text(&solids::cube().unwrap())).unwrap();
    assert_eq!(load_solid(&path).unwrap().faces.len(), 6);
    let wrong = folder.join("cube.xyz");
    std::fs::write(&wrong, "solid").unwrap();
    assert!(load_solid(&wrong)
        .unwrap_err()
        .to_string()
        .contains(".off, .obj, .stl, .ply or .fold"));
    std::fs::remove_dir_all(&folder).unwrap();
    // Bad files, each refused where the fault is.
    let refused = |text: &str, parse: fn(&str, &str) -> nanofold::Result<Polyhedron>, expected: &[&str]| {
        let message = parse(text, "bad").unwrap_err().to_string();
        for part in expected {
            assert!(message.contains(part), "{message:?} lacks {part:?}");
        }
    };
    let cube_off = off_text(&solids::cube().unwrap());
    refused(
        &cube_off.replace("OFF", "PLY"),
        parse_off,
        &["line 1", "starts with OFF"],
    );
    refused(
        &cube_off.replacen("-1 ", "x ", 1),
        parse_off,
        &["line", ": x (", "three coordinates"],
    );
    refused(&cube_off.replace("8 6 0", "8 7 0"), parse_off, &["faces[6]", "missing"]);
    refused(
        &cube_off.replace("8 6 0", "900000 6 0"),
        parse_off,
        &["vertices", "4096 after welding"],
    );
    refused(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 5\n",
        parse_obj,
        &["line 5", ": 5 (", "vertex index"],
    );
    refused("v 0 0 nan\n", parse_obj, &["line 1", "finite"]);
    refused(
        r#"{"vertices_coords": [[0, 0]], "faces_vertices": []}"#,
        parse_fold_solid,
        &["vertices_coords[0]", "three coordinates"],
    );
    refused(
        r#"{"vertices_coords": []}"#,
        parse_fold_solid,
        &["faces_vertices", "missing"],
    );
}

/// A bar of square section (side 2w, height 1) along a path in the plane z = 0..1, mitred at
/// its corners: planar convex faces, wound outwards.
fn bar(path: &[[f64; 2]], w: f64) -> (Vec<Point3<f64>>, Vec<Vec<usize>>) {
    use nalgebra::Vector2;
    let n = path.len();
    let p = |i: usize| Vector2::new(path[i][0], path[i][1]);
    let left = |d: Vector2<f64>| Vector2::new(-d.y, d.x).normalize();
    let mut vertices = Vec::new();
    for i in 0..n {
        let offset = if i == 0 {
            left(p(1) - p(0))
        } else if i == n - 1 {
            left(p(n - 1) - p(n - 2))
        } else {
            let (a, b) = (left(p(i) - p(i - 1)), left(p(i + 1) - p(i)));
            (a + b) / (1.0 + a.dot(&b))
        };
        // Per section: right bottom, left bottom, left top, right top.
        for (side, z) in [(-1.0, 0.0), (1.0, 0.0), (1.0, 1.0), (-1.0, 1.0)] {
            let q = p(i) + offset * (side * w);
            vertices.push(Point3::new(q.x, q.y, z));
        }
    }
    let mut faces = Vec::new();
    for i in 0..n - 1 {
        let (a, b) = (4 * i, 4 * (i + 1));
        faces.push(vec![a, b, b + 3, a + 3]); // right
        faces.push(vec![a + 1, a + 2, b + 2, b + 1]); // left
        faces.push(vec![a + 3, b + 3, b + 2, a + 2]); // top
        faces.push(vec![a, a + 1, b + 1, b]); // bottom
    }
    let last = 4 * (n - 1);
    faces.push(vec![0, 3, 2, 1]);
    faces.push(vec![last, last + 1, last + 2, last + 3]);
    (vertices, faces)
}

#[test]
fn pinched_concave_and_self_crossing_surfaces_are_refused_by_name() {
    // A bar bent round a square is a solid; bent on until it crosses itself it is refused,
    // naming the two faces that meet.
    let (vertices, faces) = bar(&[[0.0, 0.0], [6.0, 0.0], [6.0, 3.0], [3.0, 3.0], [3.0, 1.5]], 0.5);
    let solid = Polyhedron::new(vertices, faces).unwrap();
    assert_eq!(solid.faces.len(), 18);
    let (vertices, faces) = bar(&[[0.0, 0.0], [6.0, 0.0], [6.0, 3.0], [3.0, 3.0], [3.0, -3.0]], 0.5);
    let message = Polyhedron::new(vertices, faces).unwrap_err().to_string();
    assert!(
        message.contains("passes through itself") && message.contains("meets faces["),
        "{message}"
    );
    // Two tetrahedra tip to tip share one vertex: pinched there.
    let tetra = solids::tetrahedron().unwrap();
    let mut vertices = tetra.vertices.clone();
    let tip = tetra.vertices[0];
    vertices.extend(
        tetra.vertices[1..]
            .iter()
            .map(|p| Point3::from(2.0 * tip.coords - p.coords)),
    );
    let map = |v: usize| if v == 0 { 0 } else { v + 3 };
    let mut faces = tetra.faces.clone();
    // The mirror image through the tip turns the winding inside out; reverse it back.
    faces.extend(
        tetra
            .faces
            .iter()
            .map(|f| f.iter().rev().map(|&v| map(v)).collect::<Vec<_>>()),
    );
    let message = Polyhedron::new(vertices, faces).unwrap_err().to_string();
    assert!(
        message.contains("vertices[0]") && message.contains("pinched"),
        "{message}"
    );
    // A concave face: an L-shaped prism whose L faces are single faces.
    let l = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]];
    let mut vertices: Vec<Point3<f64>> = l.iter().map(|q| Point3::new(q[0], q[1], 0.0)).collect();
    vertices.extend(l.iter().map(|q| Point3::new(q[0], q[1], 1.0)));
    let mut faces = vec![(0..6).rev().collect::<Vec<_>>(), (6..12).collect()];
    for k in 0..6 {
        let j = (k + 1) % 6;
        faces.push(vec![k, j, j + 6, k + 6]);
    }
    let message = Polyhedron::new(vertices, faces).unwrap_err().to_string();
    assert!(message.contains("faces[") && message.contains("convex"), "{message}");
}

#[test]
fn every_net_folded_by_the_crease_pattern_kinematics_lands_on_its_solid() {
    use nanofold::folding::{panel_poses, vertex_positions, FoldingModel};
    use nanofold::geometry::nets::NetLayout;
    use nanofold::geometry::unfoldings::{distinct_nets, edge_map, sample_trees, spanning_trees};
    use nanofold::pattern::net::net_pattern;
    let mut cases: Vec<(&str, Polyhedron, Vec<u64>)> = Vec::new();
    for (name, solid) in [
        ("tetrahedron", solids::tetrahedron().unwrap()),
        ("cube", solids::cube().unwrap()),
        ("octahedron", solids::octahedron().unwrap()),
        ("box 1 x 2 x 3", solids::cuboid(1.0, 2.0, 3.0).unwrap()),
    ] {
        let maps: Vec<Vec<usize>> = solid.symmetries().iter().map(|s| edge_map(&solid, s)).collect();
        let nets = distinct_nets(&spanning_trees(&solid, 100_000).unwrap(), &maps);
        cases.push((name, solid, nets));
    }
    for (name, solid) in [
        ("dodecahedron", solids::dodecahedron().unwrap()),
        ("icosahedron", solids::icosahedron().unwrap()),
        ("truncated octahedron", solids::truncated_octahedron().unwrap()),
        ("pentagonal antiprism", solids::antiprism(5, 1.0).unwrap()),
        (
            "L tromino",
            solids::polycube(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]]).unwrap(),
        ),
    ] {
        let trees = sample_trees(&solid, 60, 11).unwrap();
        cases.push((name, solid, trees));
    }
    for (name, solid, trees) in &cases {
        let layout = NetLayout::new(solid);
        let size = solid.vertices.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        let (mut folded_nets, mut touching) = (0, 0);
        let mut worst: f64 = 0.0;
        for &tree in trees {
            let net = layout.lay_flat(tree);
            if !net.overlapping_pairs().is_empty() {
                continue;
            }
            let made = match net_pattern(solid, &net, name) {
                Ok(made) => made,
                Err(e) if e.to_string().contains("touches itself") => {
                    touching += 1;
                    continue;
                }
                Err(e) => panic!("{name}: {e}"),
            };
            assert_eq!(made.seams.len(), solid.dual_edges().len() - solid.faces.len() + 1);
            let targets = made.pattern.target_angles.clone().unwrap();
            let model = FoldingModel::new(made.pattern.clone()).unwrap();
            let fold_angles: Vec<f64> = model.pattern.creases.iter().map(|&e| targets[e]).collect();
            let mut poses = Vec::new();
            panel_poses(&model, &fold_angles, &mut poses);
            let folded: Vec<Point3<f64>> = vertex_positions(&model, &poses).into_iter().map(Point3::from).collect();
            let on_solid: Vec<Point3<f64>> = made.solid_vertex.iter().map(|&v| solid.vertices[v]).collect();
            let distance = fitted_distance(&folded, &on_solid);
            assert!(
                distance <= 1e-12 * size,
                "{name}: a net lands {distance:e} off its solid"
            );
            // Each seam's two edges meet: their ends are copies of the same solid vertices,
            // now at the same places.
            for [a, b] in &made.seams {
                let ends = |e: usize| model.pattern.edges[e].map(|v| made.solid_vertex[v]);
                let (mut x, mut y) = (ends(*a), ends(*b));
                x.sort_unstable();
                y.sort_unstable();
                assert_eq!(x, y, "{name}: a seam's edges are one edge of the solid");
            }
            worst = worst.max(distance / size);
            folded_nets += 1;
        }
        eprintln!("{name}: {folded_nets} nets folded onto the solid, worst {worst:.1e} of its size; {touching} touch themselves");
        // A convex solid's nets never touch themselves; the L tromino's flat sides may.
        assert!(folded_nets > 0 && (touching == 0 || *name == "L tromino"));
    }
}

#[test]
fn a_nets_fold_file_reads_back_with_its_targets_and_seams() {
    use nanofold::geometry::nets::lay_flat;
    use nanofold::geometry::unfoldings::spanning_trees;
    use nanofold::pattern::net::net_pattern;
    use nanofold::read::parse_crease_pattern;
    use nanofold::write::net_output::{net_fold, SEAMS_KEY, SOLID_VERTEX_KEY};
    let octahedron = solids::octahedron().unwrap();
    let tree = spanning_trees(&octahedron, 1000).unwrap()[17];
    let made = net_pattern(&octahedron, &lay_flat(&octahedron, tree), "octahedron").unwrap();
    let fold = net_fold(&made, "a net of the octahedron");
    let read = parse_crease_pattern(&fold.to_string(), "octahedron", "octahedron.fold").unwrap();
    // The octahedron's dihedral is acos(-1/3): each fold turns by its supplement, a valley.
    let turn = std::f64::consts::PI - (-1.0_f64 / 3.0).acos();
    // Read flat, its angles the targets that close the solid.
    assert!(read.fold_angles.iter().all(|&a| a == 0.0));
    assert!(
        read.reading.iter().any(|r| r.contains("a net of a solid")),
        "{:?}",
        read.reading
    );
    let angles = read.target_angles.clone().expect("read as targets");
    assert_eq!(read.creases.len(), 7);
    for &e in &read.creases {
        assert!((angles[e] - turn).abs() < 1e-12, "{} against {turn}", angles[e]);
    }
    assert_eq!(fold[SEAMS_KEY].as_array().unwrap().len(), 12 - 8 + 1);
    assert_eq!(fold[SOLID_VERTEX_KEY].as_array().unwrap().len(), read.vertices.len());
    for pair in fold[SEAMS_KEY].as_array().unwrap() {
        for e in pair.as_array().unwrap() {
            assert_eq!(fold["edges_assignment"][e.as_u64().unwrap() as usize], "B");
        }
    }
}

#[test]
fn nets_met_in_a_sample_are_the_enumerated_ones_by_their_smallest_tree() {
    use nanofold::commands::nets::{nets, NetsOptions, Search};
    use nanofold::geometry::unfoldings::{distinct_among, distinct_nets, edge_map, sample_trees, spanning_trees};
    // Each of the cube's 11 nets is at least 8 of its 384 trees: 2 000 uniform draws miss
    // one with probability below 11 (1 − 8/384)^2000 ≈ 1e-17.
    let cube = solids::cube().unwrap();
    let maps: Vec<Vec<usize>> = cube.symmetries().iter().map(|s| edge_map(&cube, s)).collect();
    let mut all = distinct_nets(&spanning_trees(&cube, 1000).unwrap(), &maps);
    let mut met = distinct_among(&sample_trees(&cube, 2000, 5).unwrap(), &maps);
    all.sort_unstable();
    met.sort_unstable();
    assert_eq!(met, all);
    // The door samples when the trees are more than it may enumerate, and says so.
    let options = NetsOptions {
        max_trees: 100,
        samples: 2000,
        ..NetsOptions::default()
    };
    let report = nets("cube", &cube, &options).unwrap();
    assert_eq!(
        (report.search, report.trees_considered, report.distinct_nets),
        (Search::Sampled, 2000, 11)
    );
}
