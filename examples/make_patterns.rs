//! Regenerates the pattern library in `patterns/`: every folded state is reached by a
//! kinematic move from flat (driven creases stepped from 0, the others following by loop
//! closure at every step), so each is a valid rigid state on a continuous folding path.
//!
//! Run: `cargo run --release --example make_patterns`

use nanofold::geometry::kinematics::solve_closure;
use serde_json::{json, Value};
use std::f64::consts::PI;

const DEG: f64 = PI / 180.0;

/// Steps the driven creases linearly from flat to their targets; the unknown creases
/// follow by Newton from the previous step (the first step starts from `first_guess`·h).
fn fold_by_continuation(
    sectors_deg: &[f64],
    driven: &[(usize, f64)],
    unknown: &[usize],
    first_guess: &[f64],
    steps: usize,
) -> Vec<f64> {
    let sectors: Vec<f64> = sectors_deg.iter().map(|a| a * DEG).collect();
    let n = sectors.len();
    let mut rho = vec![0.0; n];
    for s in 1..=steps {
        let h = s as f64 / steps as f64;
        for &(ray, target) in driven {
            rho[ray] = target * DEG * h;
        }
        if s == 1 {
            for (k, &ray) in unknown.iter().enumerate() {
                rho[ray] = first_guess[k] * DEG * h;
            }
        }
        solve_closure(&sectors, &mut rho, unknown, 1e-15, 100).expect("closure along the path");
    }
    let degrees: Vec<f64> = rho.iter().map(|r| r / DEG).collect();
    assert!(
        degrees.iter().all(|r| r.abs() < 180.0),
        "a crease passed through ±180° (sectors through each other): {degrees:?}"
    );
    degrees
}

fn letter(rho_deg: f64) -> &'static str {
    if rho_deg > 0.0 {
        "V"
    } else if rho_deg < 0.0 {
        "M"
    } else {
        "F"
    }
}

/// A FOLD crease pattern of one interior vertex on the square [−1, 1]², or a sheet-corner
/// vertex on [0, 1]² (rays between 0° and 90°, the two sheet edges as boundary rays).
fn fold_file(title: &str, ray_angles_deg: &[f64], fold_deg: &[f64], locked: Option<&[bool]>, corner: bool) -> Value {
    let tip = |phi: f64| {
        let (s, c) = (phi * DEG).sin_cos();
        let scale = c.abs().max(s.abs());
        [c / scale, s / scale]
    };
    let mut vertices = vec![[0.0, 0.0]];
    let mut edges = Vec::new();
    let mut assignment = Vec::new();
    let mut angles = Vec::new();
    let mut locks = Vec::new();
    // Boundary points by polar angle: ray tips, and square corners between them.
    let mut boundary: Vec<(f64, usize)> = Vec::new();
    for (k, &phi) in ray_angles_deg.iter().enumerate() {
        vertices.push(tip(phi));
        boundary.push((phi, k + 1));
        edges.push([0, k + 1]);
        assignment.push(letter(fold_deg[k]).to_string());
        angles.push(fold_deg[k]);
        locks.push(locked.is_some_and(|l| l[k]));
    }
    let corners: &[f64] = if corner { &[45.0] } else { &[45.0, 135.0, 225.0, 315.0] };
    for &c in corners {
        if !ray_angles_deg.iter().any(|&phi| (phi - c).abs() < 1e-9) {
            vertices.push(tip(c));
            boundary.push((c, vertices.len() - 1));
        }
    }
    boundary.sort_by(|a, b| a.0.total_cmp(&b.0));
    let m = boundary.len();
    let links = if corner { m - 1 } else { m };
    for j in 0..links {
        edges.push([boundary[j].1, boundary[(j + 1) % m].1]);
        assignment.push("B".to_string());
        angles.push(0.0);
        locks.push(false);
    }
    if corner {
        // The two sheet edges through the corner are the boundary rays.
        assignment[0] = "B".to_string();
        let last = ray_angles_deg.len() - 1;
        assignment[last] = "B".to_string();
        angles[0] = 0.0;
        angles[last] = 0.0;
    }
    // Faces: centre, then the boundary points from one ray to the next.
    let mut faces = Vec::new();
    let ray_slots: Vec<usize> = (0..m).filter(|&j| boundary[j].1 <= ray_angles_deg.len()).collect();
    let sectors = if corner { ray_slots.len() - 1 } else { ray_slots.len() };
    for s in 0..sectors {
        let (a, b) = (ray_slots[s], ray_slots[(s + 1) % ray_slots.len()]);
        let mut face = vec![0];
        let mut j = a;
        loop {
            face.push(boundary[j].1);
            if j == b {
                break;
            }
            j = (j + 1) % m;
        }
        faces.push(face);
    }
    let mut file = json!({
        "file_spec": 1.1,
        "file_creator": "nanofold examples/make_patterns.rs",
        "file_classes": ["singleModel"],
        "frame_title": title,
        "frame_classes": ["creasePattern"],
        "frame_attributes": ["2D"],
        "vertices_coords": vertices,
        "edges_vertices": edges,
        "edges_assignment": assignment,
        "edges_foldAngle": angles,
        "faces_vertices": faces,
    });
    if locked.is_some() {
        file["edges_nanofold:locked"] = json!(locks);
    }
    file
}

fn cumulative(sectors_deg: &[f64]) -> Vec<f64> {
    let mut phi = 0.0;
    sectors_deg
        .iter()
        .map(|a| {
            let here = phi;
            phi += a;
            here
        })
        .collect()
}

fn write(name: &str, file: &Value) {
    let path = format!("patterns/{name}.fold");
    std::fs::write(&path, serde_json::to_string_pretty(file).unwrap() + "\n").unwrap();
    println!("wrote {path}: {}", file["frame_title"]);
}

fn main() {
    // Half-paper: one straight crease, 80% folded.
    write(
        "half_paper",
        &fold_file(
            "half-paper, one straight valley crease, 144° (80%)",
            &[0.0, 180.0],
            &[144.0, 144.0],
            None,
            false,
        ),
    );

    // Corner cube (`docs/model.md#reference-devices`): sectors 45, 90, 90, 90, 45 from the flap's centre crease (ray 0).
    // Its two-step path, taken to 90%: step 1 drives ray 0 to 162° with ray 1 held flat,
    // step 2 holds ray 0 and drives ray 1 to 81°.
    let cc = [45.0, 90.0, 90.0, 90.0, 45.0];
    let step1 = fold_by_continuation(&cc, &[(0, 162.0), (1, 0.0)], &[2, 3, 4], &[1.0, 1.0, -1.0], 180);
    let sectors: Vec<f64> = cc.iter().map(|a| a * DEG).collect();
    let mut rho: Vec<f64> = step1.iter().map(|r| r * DEG).collect();
    for s in 1..=90 {
        rho[1] = 81.0 * DEG * s as f64 / 90.0;
        solve_closure(&sectors, &mut rho, &[2, 3, 4], 1e-15, 100).unwrap();
    }
    let corner_cube: Vec<f64> = rho.iter().map(|r| r / DEG).collect();
    println!("corner cube after step 1 {step1:?}\n  at 90% {corner_cube:?}");
    write(
        "corner_cube",
        &fold_file(
            "corner cube (`docs/model.md#reference-devices`), 90% along its two-step folding path",
            &cumulative(&cc),
            &corner_cube,
            None,
            false,
        ),
    );

    // Waterbomb base: diagonals valley, midlines mountain; diagonals driven to 135° (75%).
    let wb = [45.0; 8];
    let waterbomb = fold_by_continuation(
        &wb,
        &[(1, 135.0), (3, 135.0), (5, 135.0), (7, 135.0)],
        &[0, 2, 4, 6],
        &[-1.0, -1.0, -1.0, -1.0],
        135,
    );
    println!("waterbomb {waterbomb:?}");
    write(
        "waterbomb",
        &fold_file(
            "waterbomb base, diagonals at 135° (75%)",
            &cumulative(&wb),
            &waterbomb,
            None,
            false,
        ),
    );

    // Generic degree-4 vertex (no Kawasaki condition): ray 0 driven to 120°.
    let g4 = [70.0, 100.0, 120.0, 70.0];
    let generic = fold_by_continuation(&g4, &[(0, 120.0)], &[1, 2, 3], &[-1.0, 1.0, 1.0], 120);
    println!("generic degree-4 {generic:?}");
    write(
        "degree4_generic",
        &fold_file(
            "generic degree-4 vertex, 70/100/120/70°",
            &cumulative(&g4),
            &generic,
            None,
            false,
        ),
    );

    // The same vertex with ray 0 locked: no degree of freedom left, it cannot unfold.
    write(
        "degree4_locked",
        &fold_file(
            "generic degree-4 vertex with crease 0 locked (must not unfold)",
            &cumulative(&g4),
            &generic,
            Some(&[true, false, false, false]),
            false,
        ),
    );

    // Miura-ori-like degree-4 vertex: sectors (60, 120, 120, 60), three mountains and a valley.
    // Rays 0 and 2 are collinear; driving the zigzag crease 1 selects the Miura mode, not
    // the straight-line fold.
    let mi = [60.0, 120.0, 120.0, 60.0];
    let miura = fold_by_continuation(&mi, &[(1, 150.0)], &[0, 2, 3], &[-1.0, -1.0, -1.0], 150);
    println!("miura {miura:?}");
    write(
        "miura_vertex",
        &fold_file(
            "Miura-like degree-4 vertex, 60/120/120/60°, 83% folded",
            &cumulative(&mi),
            &miura,
            None,
            false,
        ),
    );

    // Asymmetric degree-6 vertex: three creases driven, three follow.
    let d6 = [40.0, 75.0, 55.0, 65.0, 50.0, 75.0];
    let degree6 = fold_by_continuation(
        &d6,
        &[(0, 80.0), (2, -60.0), (4, 70.0)],
        &[1, 3, 5],
        &[1.0, 1.0, -1.0],
        80,
    );
    println!("degree6 {degree6:?}");
    write(
        "degree6_asymmetric",
        &fold_file("asymmetric degree-6 vertex", &cumulative(&d6), &degree6, None, false),
    );

    // 16-fold symmetric vertex: alternate creases driven to 120°, the others follow.
    let s16 = [22.5; 16];
    let driven: Vec<(usize, f64)> = (0..16).step_by(2).map(|k| (k, 120.0)).collect();
    let unknown: Vec<usize> = (1..16).step_by(2).collect();
    let sym16 = fold_by_continuation(&s16, &driven, &unknown, &[-1.0; 8], 120);
    println!("16-fold {sym16:?}");
    write(
        "symmetric16",
        &fold_file(
            "16-fold symmetric vertex, alternate creases at 120°",
            &cumulative(&s16),
            &sym16,
            None,
            false,
        ),
    );

    // Sheet-corner (boundary) vertex: two creases in a 90° corner, an open chain.
    write(
        "sheet_corner",
        &fold_file(
            "sheet-corner vertex, creases at 30° and 60°",
            &[0.0, 30.0, 60.0, 90.0],
            &[0.0, 120.0, -100.0, 0.0],
            None,
            true,
        ),
    );
}
