//! Writes the bundled solids as mesh tools write them (patterns/solids/): the icosahedron as
//! Blender's OBJ (6 decimals, turned and moved), the cube as binary STL (float32, twelve
//! triangles), the L tromino as ASCII STL (its squares triangulated) and the dodecahedron as
//! ASCII PLY. `nanofold nets` reads each back as its solid.
//!
//! Run: `cargo run --release --example mesh_files`

use nalgebra::{Point3, Rotation3, Unit, Vector3};
use nanofold::geometry::polyhedron::Polyhedron;
use nanofold::geometry::solids;
use std::fmt::Write as _;

fn placed(solid: &Polyhedron) -> Vec<Point3<f64>> {
    let turn = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::new(0.3, -0.7, 0.5)), 0.9);
    solid
        .vertices
        .iter()
        .map(|p| turn * p + Vector3::new(1.25, -3.5, 0.75))
        .collect()
}

fn triangles(faces: &[Vec<usize>]) -> Vec<[usize; 3]> {
    faces
        .iter()
        .flat_map(|f| (1..f.len() - 1).map(move |k| [f[0], f[k], f[k + 1]]))
        .collect()
}

fn main() -> std::io::Result<()> {
    let folder = std::path::Path::new("patterns/solids");
    std::fs::create_dir_all(folder)?;

    let icosahedron = solids::icosahedron().expect("generated");
    let vertices = placed(&icosahedron);
    let mut obj = String::from("# Blender 4.2.0\n# www.blender.org\nmtllib icosahedron.mtl\no Icosphere\n");
    for p in &vertices {
        writeln!(obj, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z).unwrap();
    }
    obj += "vn -0.1876 0.7947 0.5774\nvt 0.818181 0.000000\ns 0\nusemtl Material\n";
    for f in &icosahedron.faces {
        let corners: Vec<String> = f.iter().map(|&v| format!("{}/1/1", v + 1)).collect();
        writeln!(obj, "f {}", corners.join(" ")).unwrap();
    }
    std::fs::write(folder.join("icosahedron_blender.obj"), obj)?;

    let cube = solids::cuboid(2.0, 2.0, 2.0).expect("generated");
    let vertices = placed(&cube);
    let list = triangles(&cube.faces);
    let mut stl = vec![0u8; 80];
    stl[..30].copy_from_slice(b"binary STL written by nanofold");
    stl.extend((list.len() as u32).to_le_bytes());
    for t in list {
        stl.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        for v in t {
            for x in vertices[v].coords.iter() {
                stl.extend((*x as f32).to_le_bytes());
            }
        }
        stl.extend([0u8; 2]);
    }
    std::fs::write(folder.join("cube_binary.stl"), stl)?;

    let tromino = solids::polycube(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]]).expect("generated");
    let mut ascii = String::from("solid l_tromino\n");
    for t in triangles(&tromino.faces) {
        ascii += "  facet normal 0.000000e+00 0.000000e+00 0.000000e+00\n    outer loop\n";
        for v in t {
            let p = tromino.vertices[v];
            writeln!(ascii, "      vertex {:.6e} {:.6e} {:.6e}", p.x, p.y, p.z).unwrap();
        }
        ascii += "    endloop\n  endfacet\n";
    }
    ascii += "endsolid l_tromino\n";
    std::fs::write(folder.join("l_tromino.stl"), ascii)?;

    let dodecahedron = solids::dodecahedron().expect("generated");
    let vertices = placed(&dodecahedron);
    let mut ply = format!(
        "ply\nformat ascii 1.0\ncomment written by nanofold's mesh_files example\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        dodecahedron.faces.len()
    );
    for p in &vertices {
        writeln!(ply, "{:.6} {:.6} {:.6}", p.x, p.y, p.z).unwrap();
    }
    for f in &dodecahedron.faces {
        let corners: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        writeln!(ply, "{} {}", f.len(), corners.join(" ")).unwrap();
    }
    std::fs::write(folder.join("dodecahedron.ply"), ply)?;
    println!("wrote patterns/solids/: icosahedron_blender.obj, cube_binary.stl, l_tromino.stl, dodecahedron.ply");
    Ok(())
}
