//! Solids as mesh tools write them: generated solids turned, moved, rounded to 6, 5 and 4
//! decimals as OBJ (Blender's `%.6f`), written as ASCII STL (`%e`) and binary STL (float32)
//! with every face cut into triangles, and PLY. Each must read back as the same solid: the
//! same faces, the same symmetry group (checked to be a group and named), the same nets;
//! or be refused naming the tolerance. And a near-symmetric solid whose near-symmetries do
//! not close gets a true group and a warning.

use nalgebra::{Point3, Rotation3, Unit, Vector3};
use nanofold::geometry::mesh::MergeCoplanar;
use nanofold::geometry::polyhedron::Polyhedron;
use nanofold::geometry::solids;
use nanofold::geometry::unfoldings::{distinct_nets, edge_map, spanning_trees};
use nanofold::read::solid::{parse_solid, SolidOptions};

/// A turn about an oblique axis and a move: no coordinate keeps the solid's own digits.
fn placed(solid: &Polyhedron, seed: f64) -> Vec<Point3<f64>> {
    let turn = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3 + seed, -0.7, 0.5)), 0.9 + seed);
    let shift = Vector3::new(1.25 + seed, -3.5, 0.75);
    solid.vertices.iter().map(|p| turn * p + shift).collect()
}

/// Blender's OBJ: `v` at `decimals` fixed decimals, polygons as written, normals and
/// texture lines beside them.
fn obj(vertices: &[Point3<f64>], faces: &[Vec<usize>], decimals: usize) -> String {
    let mut text = String::from("# Blender 4.2\nmtllib solid.mtl\no Solid\n");
    for p in vertices {
        text += &format!("v {:.d$} {:.d$} {:.d$}\n", p.x, p.y, p.z, d = decimals);
    }
    text += "vn 0.0000 0.0000 1.0000\nvt 0.5 0.5\ns 0\nusemtl Material\n";
    for f in faces {
        let corners: Vec<String> = f.iter().map(|&v| format!("{}/1/1", v + 1)).collect();
        text += &format!("f {}\n", corners.join(" "));
    }
    text
}

/// Every face as a fan of triangles from its first corner.
fn triangles(faces: &[Vec<usize>]) -> Vec<[usize; 3]> {
    faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
        .collect()
}

/// ASCII STL as CAD tools write it (`%e`, six decimals), each triangle its own corners.
fn ascii_stl(vertices: &[Point3<f64>], faces: &[Vec<usize>]) -> String {
    let mut text = String::from("solid part\n");
    for t in triangles(faces) {
        text += "  facet normal 0.000000e+00 0.000000e+00 1.000000e+00\n    outer loop\n";
        for v in t {
            let p = vertices[v];
            text += &format!(
                "      vertex {:e} {:e} {:e}\n",
                round_sig(p.x),
                round_sig(p.y),
                round_sig(p.z)
            );
        }
        text += "    endloop\n  endfacet\n";
    }
    text + "endsolid part\n"
}

/// `%e` with six decimals: seven significant digits.
fn round_sig(x: f64) -> f64 {
    format!("{x:.6e}").parse().unwrap()
}

/// Binary STL: float32 corners.
fn binary_stl(vertices: &[Point3<f64>], faces: &[Vec<usize>]) -> Vec<u8> {
    let list = triangles(faces);
    let mut bytes = vec![0u8; 80];
    bytes[..5].copy_from_slice(b"solid"); // as some exporters begin a binary header
    bytes.extend((list.len() as u32).to_le_bytes());
    for t in list {
        bytes.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        for v in t {
            for x in vertices[v].coords.iter() {
                bytes.extend((*x as f32).to_le_bytes());
            }
        }
        bytes.extend([0u8; 2]);
    }
    bytes
}

/// ASCII PLY with float coordinates at six decimals.
fn ply(vertices: &[Point3<f64>], faces: &[Vec<usize>]) -> String {
    let mut text = format!(
        "ply\nformat ascii 1.0\ncomment made by a test\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    );
    for p in vertices {
        text += &format!("{:.6} {:.6} {:.6}\n", p.x, p.y, p.z);
    }
    for f in faces {
        let corners: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        text += &format!("{} {}\n", f.len(), corners.join(" "));
    }
    text
}

/// Binary little-endian PLY with float coordinates and uint8-counted int indices.
fn binary_ply(vertices: &[Point3<f64>], faces: &[Vec<usize>]) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    for p in vertices {
        for x in p.coords.iter() {
            bytes.extend((*x as f32).to_le_bytes());
        }
    }
    for f in faces {
        bytes.push(f.len() as u8);
        for &v in f {
            bytes.extend((v as i32).to_le_bytes());
        }
    }
    bytes
}

fn read_bytes(bytes: &[u8], format: &str) -> nanofold::Result<Polyhedron> {
    Ok(parse_solid(bytes, format, &format!("test.{format}"), &SolidOptions::default())?.0)
}

/// Whether every face of `read` is a face of `exact` (the same corners, each within
/// `within`), whatever the numbering.
fn same_faces(read: &Polyhedron, exact: &Polyhedron, within: f64) -> bool {
    read.faces.len() == exact.faces.len()
        && read.faces.iter().all(|f| {
            exact.faces.iter().any(|g| {
                g.len() == f.len()
                    && f.iter().all(|&v| {
                        g.iter()
                            .any(|&w| (read.vertices[v] - exact.vertices[w]).norm() <= within)
                    })
            })
        })
}

fn nets_of(solid: &Polyhedron) -> usize {
    let maps: Vec<Vec<usize>> = solid.symmetries().iter().map(|s| edge_map(solid, s)).collect();
    distinct_nets(&spanning_trees(solid, 10_000_000).unwrap(), &maps).len()
}

#[test]
fn solids_written_by_mesh_tools_read_back_with_their_group_and_nets() {
    let cases: Vec<(&str, Polyhedron, &str, usize, Option<usize>)> = vec![
        ("cube", solids::cube().unwrap(), "Oh", 48, Some(11)),
        ("octahedron", solids::octahedron().unwrap(), "Oh", 48, Some(11)),
        ("tetrahedron", solids::tetrahedron().unwrap(), "Td", 24, Some(2)),
        ("box 1x2x3", solids::cuboid(1.0, 2.0, 3.0).unwrap(), "D2h", 8, Some(54)),
        ("dodecahedron", solids::dodecahedron().unwrap(), "Ih", 120, None),
        ("icosahedron", solids::icosahedron().unwrap(), "Ih", 120, None),
        ("pentagonal prism", solids::prism(5, 1.0).unwrap(), "D5h", 20, None),
        (
            "truncated octahedron",
            solids::truncated_octahedron().unwrap(),
            "Oh",
            48,
            None,
        ),
    ];
    for (name, solid, group, order, nets) in cases {
        let exact = solid.symmetry_group();
        assert_eq!(
            (exact.point_group.name.as_str(), exact.point_group.order),
            (group, order),
            "{name}"
        );
        for seed in [0.0, 0.37] {
            let vertices = placed(&solid, seed);
            let mut files: Vec<(String, Vec<u8>, &str)> = Vec::new();
            for decimals in [6, 5, 4] {
                files.push((
                    format!("OBJ {decimals} decimals"),
                    obj(&vertices, &solid.faces, decimals).into_bytes(),
                    "obj",
                ));
            }
            files.push((
                "ASCII STL".into(),
                ascii_stl(&vertices, &solid.faces).into_bytes(),
                "stl",
            ));
            files.push(("binary STL".into(), binary_stl(&vertices, &solid.faces), "stl"));
            files.push(("ASCII PLY".into(), ply(&vertices, &solid.faces).into_bytes(), "ply"));
            files.push(("binary PLY".into(), binary_ply(&vertices, &solid.faces), "ply"));
            for (what, bytes, format) in files {
                let read = read_bytes(&bytes, format).unwrap_or_else(|e| panic!("{name}, {what}: {e}"));
                let group_read = read.symmetry_group();
                assert_eq!(
                    (
                        read.faces.len(),
                        read.vertices.len(),
                        group_read.point_group.name.as_str(),
                        group_read.point_group.order
                    ),
                    (solid.faces.len(), solid.vertices.len(), group, order),
                    "{name}, {what}, turned by {seed}: {:?}",
                    group_read.warning()
                );
                assert_eq!(group_read.left_out, 0, "{name}, {what}");
                let exact_placed = Polyhedron::new(vertices.clone(), solid.faces.clone()).unwrap();
                assert!(same_faces(&read, &exact_placed, 1e-3), "{name}, {what}");
                if let Some(nets) = nets {
                    assert_eq!(nets_of(&read), nets, "{name}, {what}");
                }
            }
        }
    }
}

#[test]
fn the_icosahedron_at_six_decimals_has_its_43_380_nets() {
    // The case: a 6-decimal icosahedron counted 86 538 nets under a "group" of 108.
    let solid = solids::icosahedron().unwrap();
    let vertices = placed(&solid, 0.11);
    let read = read_bytes(obj(&vertices, &solid.faces, 6).as_bytes(), "obj").unwrap();
    assert_eq!(read.symmetry_group().point_group.name, "Ih");
    assert_eq!(nets_of(&read), 43_380);
}

#[test]
fn stl_triangles_merge_back_into_faces_and_a_polycube_keeps_its_geometry() {
    // The cube as 12 triangles: 6 squares, not triangles with flat hinges.
    let cube = solids::cube().unwrap();
    let vertices = placed(&cube, 0.2);
    let read = read_bytes(&binary_stl(&vertices, &cube.faces), "stl").unwrap();
    assert!(read.faces.iter().all(|f| f.len() == 4), "{:?}", read.faces);
    // Kept as triangles when asked.
    let options = SolidOptions {
        merge_coplanar: MergeCoplanar::Never,
    };
    let (kept, _) = parse_solid(&binary_stl(&vertices, &cube.faces), "stl", "cube.stl", &options).unwrap();
    assert_eq!(kept.faces.len(), 12);
    // A polycube written as OBJ quads keeps its unit squares (faces as written); as STL its
    // faces are the geometric ones: the L tromino's two L-shaped faces cut at their reflex
    // corner into three squares each, its two long sides one 2 × 1 face each.
    let tromino = solids::polycube(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]]).unwrap();
    let vertices = placed(&tromino, 0.0);
    let as_obj = read_bytes(obj(&vertices, &tromino.faces, 6).as_bytes(), "obj").unwrap();
    assert_eq!((as_obj.faces.len(), as_obj.spanning_tree_count()), (14, 2_488_976.0));
    let as_stl = read_bytes(&binary_stl(&vertices, &tromino.faces), "stl").unwrap();
    assert_eq!(as_stl.faces.len(), 12, "{:?}", as_stl.faces);
    assert!((as_stl.volume() - 3.0).abs() < 1e-5);
    // Its group is the L's: a mirror across the L's diagonal and one through its middle layer.
    assert_eq!(as_stl.symmetry_group().point_group.name, "C2v");
    assert_eq!(as_obj.symmetry_group().point_group.name, "C2v");
}

#[test]
fn a_cube_nearly_symmetric_at_the_tolerance_gets_a_true_group_and_a_warning() {
    // A cube whose top face is tilted: each top corner moved along its vertical edge by
    // ±h. At h well under the symmetry tolerance the cube's 48 maps all fit; well over it
    // only the tilt's own mirror does; in between, some maps fit and their products do not,
    // and the answer must still be a group (never 48 minus a few), with a warning.
    let cube = solids::cube().unwrap();
    let tolerance = cube.tolerances.symmetry;
    let mut orders = Vec::new();
    let mut warned = 0;
    for step in 1..=40 {
        let h = tolerance * step as f64 * 0.25;
        let vertices: Vec<Point3<f64>> = cube
            .vertices
            .iter()
            .map(|p| {
                if p.z > 0.0 {
                    Point3::new(p.x, p.y, p.z + h * p.y.signum())
                } else {
                    *p
                }
            })
            .collect();
        let tilted = Polyhedron::new(vertices, cube.faces.clone()).unwrap();
        let group = tilted.symmetry_group();
        // A group: every composition of two elements is an element.
        let maps: Vec<&Vec<usize>> = group.elements.iter().map(|s| &s.vertex_map).collect();
        for a in &maps {
            for b in &maps {
                let composed: Vec<usize> = (0..a.len()).map(|v| a[b[v]]).collect();
                assert!(maps.contains(&&composed), "h = {h:e}: not closed");
            }
        }
        assert_eq!(group.point_group.order, group.elements.len());
        assert!(
            [48, 16, 8, 4, 2].contains(&group.point_group.order),
            "h = {h:e}: {:?}",
            group.point_group
        );
        if group.left_out > 0 {
            warned += 1;
            assert!(group.warning().unwrap().contains(&format!("{:.1e}", tolerance)));
        }
        orders.push(group.point_group.order);
    }
    println!("orders {orders:?}, warned {warned}");
    assert_eq!(orders[0], 48, "{orders:?}");
    assert_eq!(*orders.last().unwrap(), 2, "{orders:?}");
    assert!(warned > 0, "no tilt left near-symmetries out: {orders:?}");
}

#[test]
fn nets_are_counted_only_under_a_group() {
    use nanofold::geometry::unfoldings::check_orbits;
    let cube = solids::cube().unwrap();
    let trees = spanning_trees(&cube, 1000).unwrap();
    let mut maps: Vec<Vec<usize>> = cube.symmetries().iter().map(|s| edge_map(&cube, s)).collect();
    let nets = distinct_nets(&trees, &maps);
    assert!(check_orbits(trees.len(), &nets, &maps).is_ok());
    // 47 of the 48 maps are no group: the orbits no longer partition the trees evenly.
    maps.pop();
    let nets = distinct_nets(&trees, &maps);
    let error = check_orbits(trees.len(), &nets, &maps).unwrap_err().to_string();
    assert!(error.contains("not a group"), "{error}");
}

#[test]
fn a_face_off_its_plane_by_more_than_the_files_rounding_is_refused_naming_the_tolerance() {
    let cube = solids::cube().unwrap();
    let mut vertices = placed(&cube, 0.0);
    // One corner 1e-4 along a face's normal: twenty times what 6 decimals can do.
    let normal = cube.face_normal(0).normalize();
    let corner = cube.faces[0][0];
    let turn = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3, -0.7, 0.5)), 0.9);
    vertices[corner] += turn * normal * 1e-4;
    let error = read_bytes(obj(&vertices, &cube.faces, 6).as_bytes(), "obj")
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("off its plane") && error.contains("3.5e-6") && error.contains("7 significant digits"),
        "{error}"
    );
    // At 3 decimals the same corner is within the file's own rounding, and the cube reads.
    assert!(read_bytes(obj(&vertices, &cube.faces, 3).as_bytes(), "obj").is_ok());
}

#[test]
fn bad_stl_and_ply_files_are_refused_where_the_fault_is() {
    let cube = solids::cube().unwrap();
    let refused = |bytes: &[u8], format: &str, expected: &[&str]| {
        let message = read_bytes(bytes, format).unwrap_err().to_string();
        for part in expected {
            assert!(message.contains(part), "{message:?} lacks {part:?}");
        }
    };
    // A binary STL cut short is neither binary (its size) nor text.
    let binary = binary_stl(&cube.vertices, &cube.faces);
    refused(&binary[..binary.len() - 7], "stl", &["neither binary STL", "nor ASCII"]);
    // ASCII STL: a bad number, a loop of four corners, a stray keyword.
    let ascii = ascii_stl(&cube.vertices, &cube.faces);
    let first_vertex = ascii.find("vertex ").unwrap();
    let mut bad = ascii.clone();
    bad.replace_range(first_vertex + 7..first_vertex + 8, "x");
    refused(bad.as_bytes(), "stl", &["line 4", "three coordinates"]);
    refused(
        ascii
            .replacen("    endloop", "      vertex 0 0 0\n    endloop", 1)
            .as_bytes(),
        "stl",
        &["a loop of 4 vertices"],
    );
    refused(
        ascii.replacen("outer loop", "outer lop\n lop", 1).as_bytes(),
        "stl",
        &["lop"],
    );
    refused(
        ascii.replacen("      vertex", "      vertex nan 0 0 #", 1).as_bytes(),
        "stl",
        &["finite"],
    );
    // PLY without faces, and with a face naming a vertex that is not there.
    let text = ply(&cube.vertices, &cube.faces);
    let no_faces = text.replace("element face 6\nproperty list uchar int vertex_indices\n", "");
    let no_faces: String = no_faces
        .lines()
        .filter(|l| !l.starts_with("4 "))
        .map(|l| format!("{l}\n"))
        .collect();
    refused(no_faces.as_bytes(), "ply", &["element face", "missing"]);
    refused(
        text.replace("4 0 ", "4 99 ").as_bytes(),
        "ply",
        &["vertex 99 does not exist"],
    );
    refused(b"ply\nformat ascii 1.0\nelement vertex x\n", "ply", &["not PLY"]);
    // Triangles that stop short of closing: a face missing.
    let open: Vec<Vec<usize>> = cube.faces[1..].to_vec();
    refused(&binary_stl(&cube.vertices, &open), "stl", &["not closed"]);
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    /// The bundled mesh files, each with its format.
    fn files() -> Vec<(Vec<u8>, &'static str)> {
        let cube = solids::cube().unwrap();
        let vertices = placed(&cube, 0.1);
        vec![
            (obj(&vertices, &cube.faces, 6).into_bytes(), "obj"),
            (ascii_stl(&vertices, &cube.faces).into_bytes(), "stl"),
            (binary_stl(&vertices, &cube.faces), "stl"),
            (ply(&vertices, &cube.faces).into_bytes(), "ply"),
            (binary_ply(&vertices, &cube.faces), "ply"),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

        /// Bytes changed anywhere in a mesh file: a solid or an error, never a panic.
        #[test]
        fn mutated_mesh_files_never_panic(
            file in any::<prop::sample::Index>(),
            edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        ) {
            let all = files();
            let (mut bytes, format) = all[file.index(all.len())].clone();
            for (at, byte) in edits {
                let k = at.index(bytes.len());
                bytes[k] = byte;
            }
            let _ = parse_solid(&bytes, format, "fuzzed", &SolidOptions::default());
        }

        /// Arbitrary bytes as every format.
        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            for format in ["obj", "stl", "ply", "off", "fold"] {
                let _ = parse_solid(&bytes, format, "arbitrary", &SolidOptions::default());
            }
        }
    }
}
