//! The quasi-static engine's contact forces (`docs/model.md#contact-forces`), checked from
//! the written state alone, not from the solver's residual: at a jam no two faces overlap,
//! every force pushes, and with the latched seams' forces they balance each hinge's torque
//! (virtual work through each fold angle, by central differences of the faces' places).

use nalgebra::Vector3;
use nanofold::commands::nets::*;

/// A net's device and its run.
/// Every pattern vertex placed at the fold angles, m.
type Places = Box<dyn Fn(&[f64]) -> Vec<Vector3<f64>>>;

struct Jammed {
    places: Places,
    faces: Vec<Vec<usize>>,
    file_face: Vec<usize>,
    stiffness: Vec<f64>,
    size: f64,
    friction: f64,
    run: ClosingReport,
}

fn run(shape: &str, rank: usize, front: Option<f64>, capture_percent: f64, friction_coefficient: f64) -> Jammed {
    let (name, solid) = open_solid(shape).unwrap();
    let options = NetsOptions {
        top: rank,
        unit_um: 50.0,
        front_deg: front,
        ..NetsOptions::default()
    };
    let report = nets(&name, &solid, &options).unwrap();
    let made = best_net_patterns(&solid, &report, rank).unwrap().remove(rank - 1).1;
    let run = net_closing(
        &made,
        shape,
        &options,
        &ClosingSettings {
            capture_percent,
            friction_coefficient,
        },
    )
    .unwrap();
    let scene = net_device(&made, shape, &options).unwrap();
    let model = scene.network().unwrap().clone();
    let closing = NetClosing::new(&made, &model).unwrap();
    let unit = model.unit;
    let pattern = &model.folding.pattern;
    Jammed {
        faces: pattern.faces.clone(),
        file_face: pattern.file_face.clone(),
        stiffness: model.stiffness(),
        size: model.size(),
        friction: friction_coefficient,
        run,
        places: Box::new(move |theta| {
            closing
                .vertex_places(&model, theta)
                .iter()
                .map(|p| Vector3::new(p[0], p[1], p[2]) * unit)
                .collect()
        }),
    }
}

/// How deep two convex faces cross: the shortest shift along the separating axes that
/// parts them (the separating axis test; 0 when they are apart or only touch), m.
fn overlap(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    (-nanofold::geometry::plate_separation::plate_separation(a, b).gap).max(0.0)
}

/// A point of face `f`'s plane as an affine combination of three of its corners.
fn weights(corners: &[Vector3<f64>], x: &Vector3<f64>) -> [f64; 3] {
    let (a, b, c) = (corners[0], corners[1], corners[2]);
    let m = nalgebra::Matrix3::from_columns(&[b - a, c - a, (b - a).cross(&(c - a))]);
    let w = m.try_inverse().unwrap() * (x - a);
    [1.0 - w.x - w.y, w.x, w.y]
}

/// Each jam's independent check; returns the worst relative imbalance.
fn check_jam(j: &Jammed) -> f64 {
    let run = &j.run;
    let jam = run.jam.as_ref().expect("a jam");
    let theta = &run.frames.last().unwrap().fold_angles;
    let places = (j.places)(theta);
    let corners = |f: usize, places: &[Vector3<f64>]| j.faces[f].iter().map(|&v| places[v]).collect::<Vec<_>>();
    let mut deepest: f64 = 0.0;
    // No two faces overlap (faces sharing an edge, a hinge or a latched seam, meet along
    // it and nowhere else unless folded onto each other).
    for f in 0..j.faces.len() {
        for g in f + 1..j.faces.len() {
            let (a, b) = (corners(f, &places), corners(g, &places));
            let shared = a
                .iter()
                .filter(|x| b.iter().any(|y| (*x - y).norm() <= 1e-9 * j.size))
                .count();
            if shared >= 2 {
                continue;
            }
            let depth = overlap(&corners(f, &places), &corners(g, &places));
            if depth > 1e-9 * j.size {
                eprintln!("faces {f} and {g} overlap by {depth:e} m");
                deepest = deepest.max(depth);
            }
        }
    }
    // Every force pushes; friction stays within its cone, across the normal.
    assert!(jam.contacts.iter().all(|c| c.force_n >= 0.0), "{jam:?}");
    for c in &jam.contacts {
        let friction = Vector3::from(c.friction_n);
        assert!(
            friction.norm() <= j.friction * c.force_n * (1.0 + 1e-6) + 1e-18,
            "{c:?}"
        );
        assert!(
            friction.dot(&Vector3::from(c.normal)).abs() <= 1e-9 * friction.norm().max(1e-30),
            "{c:?}"
        );
    }
    assert!(jam.contacts.iter().any(|c| c.force_n > 0.0), "{jam:?}");
    let face_of = |file: usize| j.file_face.iter().position(|&f| f == file).unwrap();
    // Virtual work through each fold angle: K (θ − r) = Σ F·(∂x_first − ∂x_second)/∂θ.
    let h = 1e-6;
    let n = theta.len();
    let mut worst: f64 = 0.0;
    let torques: Vec<f64> = (0..n)
        .map(|c| j.stiffness[c] * (theta[c] - run.final_drive[c]))
        .collect();
    let scale = torques.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
    for c in 0..n {
        let shifted = |d: f64| {
            let mut t = theta.clone();
            t[c] += d;
            (j.places)(&t)
        };
        let (plus, minus) = (shifted(h), shifted(-h));
        let velocity = |f: usize, x: &Vector3<f64>| {
            let w = weights(&corners(f, &places), x);
            let (p, m) = (corners(f, &plus), corners(f, &minus));
            (0..3).map(|i| (p[i] - m[i]) * (w[i] / (2.0 * h))).sum::<Vector3<f64>>()
        };
        let mut work = 0.0;
        for contact in &jam.contacts {
            let [first, second] = contact.faces.map(face_of);
            let point = Vector3::from(contact.point_um) * 1e-6;
            let normal = Vector3::from(contact.normal);
            let other = point - normal * contact.gap_um * 1e-6;
            // The push along the normal and the friction across it, on the first face.
            let force = normal * contact.force_n + Vector3::from(contact.friction_n);
            work += force.dot(&(velocity(first, &point) - velocity(second, &other)));
        }
        for seam in &jam.seams {
            let [first, second] = seam.faces.map(face_of);
            let point = Vector3::from(seam.point_um) * 1e-6;
            work += Vector3::from(seam.force_n).dot(&(velocity(first, &point) - velocity(second, &point)));
        }
        worst = worst.max((torques[c] - work).abs() / scale);
    }
    assert!(
        deepest <= 1e-9 * j.size,
        "faces overlap by {deepest:e} m; imbalance {worst:e}"
    );
    worst
}

#[test]
fn every_jam_rests_apart_pushing_and_in_balance_hinge_by_hinge() {
    assert_eq!(jams_balance(0.0, 6), vec![], "frictionless, every run is decided");
}

/// The same runs with Coulomb friction 0.3: the jams' balance counts the friction's work,
/// and no friction leaves its cone.
#[test]
fn every_jam_with_friction_balances_with_its_friction_within_the_cone() {
    // With friction most of these runs are not decided yet (docs/model.md#contact-forces:
    // a contact pressing at 1e-7 of the others' force converges by 3 % an iteration); the
    // jams that are decided are checked in full.
    let undecided = jams_balance(0.3, 3);
    eprintln!("undecided with friction: {} of 9", undecided.len());
}

/// Checks every jam of the octahedron's nets 1, 2 and 5 along three fronts (at least
/// `least_jams` of them); returns the runs left undecided.
fn jams_balance(friction: f64, least_jams: usize) -> Vec<(usize, Option<f64>)> {
    // The octahedron's nets 1, 2 and 5 released along three fronts with a 1 % capture:
    // faces meet out of line and their hinges are held off their drives by contact. Every
    // run is decided; every jam is checked.
    let (mut jams, mut undecided) = (0, Vec::new());
    for rank in [1, 2, 5] {
        for front in [Some(0.0), Some(45.0), Some(90.0)] {
            let jammed = run("octahedron", rank, front, 1.0, friction);
            if jammed.run.outcome == Outcome::Undecided {
                eprintln!("net {rank} along {front:?} undecided: {:?}", jammed.run.undecided);
                undecided.push((rank, front));
                continue;
            }
            if jammed.run.outcome != Outcome::Jams {
                continue;
            }
            jams += 1;
            eprintln!(
                "net {rank} along {front:?}: {} contacts, {} seam forces",
                jammed.run.jam.as_ref().unwrap().contacts.len(),
                jammed.run.jam.as_ref().unwrap().seams.len()
            );
            let imbalance = check_jam(&jammed);
            eprintln!("  imbalance {imbalance:.2e}");
            assert!(imbalance <= 1e-6, "net {rank} along {front:?}: imbalance {imbalance:e}");
        }
    }
    eprintln!("μ {friction}: {jams} jams checked, undecided {undecided:?}");
    assert!(jams >= least_jams, "{jams} jams to check");
    undecided
}

/// A flap driven into a wall that stands across its path (`docs/model.md#slow-release-through-contact`):
/// a base of 2 × 1 sides, a wall of 1 × 1 on its north edge driven to r_w = 90°, a flap of
/// 2 × 2 on its south edge driven to r_f. The flap's face meets the wall's top edge where
/// its plane passes through it: θ_f = π − θ_w / 2, at 2 ℓ cos(θ_w / 2) from the flap's hinge,
/// the force's arm about the wall's hinge ℓ cos(θ_w / 2). The hinges then balance with
/// K_f (r_f − θ_f) = 2 K_w (r_w − θ_w): linear in θ_w, so the rest and the force
/// f = K_f (r_f − θ_f) / (2 ℓ cos(θ_w / 2)) (the flap's torque over its lever arm) are
/// closed forms.
fn flap_and_wall(flap_target_deg: f64) -> (nanofold::dynamics::simulate::Simulation, Vec<f64>) {
    flap_and_wall_with(flap_target_deg, 0.0)
}

/// [`flap_and_wall`] with Coulomb friction `friction` between the faces.
fn flap_and_wall_with(flap_target_deg: f64, friction: f64) -> (nanofold::dynamics::simulate::Simulation, Vec<f64>) {
    use nanofold::dynamics::simulate::{simulate_scene, ModelChoice, SimulationSettings};
    let built = flap_scene(flap_target_deg, friction).unwrap();
    let settings = SimulationSettings {
        model: ModelChoice::QuasiStatic,
        ..SimulationSettings::default()
    };
    let stiffness = built.network().unwrap().stiffness();
    (simulate_scene(&built, &settings).unwrap(), stiffness)
}

/// The flap and wall's scene, built.
fn flap_scene(flap_target_deg: f64, friction: f64) -> nanofold::Result<nanofold::dynamics::scene::Scene> {
    let dir = std::env::temp_dir().join(format!(
        "nanofold-flap-{}-{flap_target_deg}-{friction}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let fold = serde_json::json!({
        "file_spec": 1.1,
        "frame_classes": ["creasePattern"],
        "vertices_coords": [[-0.5, 0], [1.5, 0], [1.5, 1], [1, 1], [0, 1], [-0.5, 1], [1, 2], [0, 2], [-0.5, -2], [1.5, -2]],
        "edges_vertices": [[0, 1], [4, 3], [1, 2], [2, 3], [4, 5], [5, 0], [3, 6], [6, 7], [7, 4], [8, 9], [9, 1], [0, 8]],
        "edges_assignment": ["V", "V", "B", "B", "B", "B", "B", "B", "B", "B", "B", "B"],
        "faces_vertices": [[0, 1, 2, 3, 4, 5], [4, 3, 6, 7], [8, 9, 1, 0]]
    });
    std::fs::write(dir.join("flap.fold"), fold.to_string()).unwrap();
    let hinge = |crease: usize, target: f64| {
        serde_json::json!({
            "crease": crease, "hinge_length_um": 20, "actuated": true, "target_angle_deg": target,
            "radius_of_curvature_um": 20,
            "layers": [{"material": "SiN", "thickness_um": 0.2}, {"material": "Cr", "thickness_um": 0.1}]
        })
    };
    let scene = serde_json::json!({
        "name": "flap",
        "pattern": "flap.fold",
        "length_unit_um": 100,
        "materials": {
            "SiN": {"youngs_modulus_gpa": 300, "poisson_ratio": 0.28, "density_g_cm3": 3.27},
            "Cr": {"youngs_modulus_gpa": 140, "poisson_ratio": 0.21, "density_g_cm3": 7.19}
        },
        "plates": {"thickness_um": 0.2, "material": "SiN"},
        "hinges": [hinge(0, flap_target_deg), hinge(1, 90.0)],
        "anchored_face": 0,
        "actuation": {"kind": "step"},
        "environment": {"drag": true},
        "friction_coefficient": friction,
        "time": {"t_end_s": 0.01}
    });
    let built = nanofold::read::parse_scene(&scene.to_string(), "flap", "flap", &dir).and_then(|s| s.build());
    std::fs::remove_dir_all(&dir).ok();
    built
}

#[test]
fn a_friction_coefficient_out_of_range_is_refused_by_name() {
    for bad in [-0.1, 10.5] {
        let error = flap_scene(170.0, bad).unwrap_err().to_string();
        assert!(
            error.contains("friction_coefficient") && error.contains(&bad.to_string()),
            "{error}"
        );
    }
}

#[test]
fn a_flap_driven_into_a_standing_wall_stops_with_its_torque_over_its_lever_arm() {
    use std::f64::consts::PI;
    let (run, stiffness) = flap_and_wall(170.0);
    let released = run.released.as_ref().expect("a tree of panels goes on through contact");
    assert_eq!(released.outcome.label(), "jams", "{released:?}");
    let (k_f, k_w) = (stiffness[0], stiffness[1]);
    let (r_f, r_w) = (170f64.to_radians(), 90f64.to_radians());
    let wall = (2.0 * k_w * r_w + k_f * (PI - r_f)) / (0.5 * k_f + 2.0 * k_w);
    let flap = PI - 0.5 * wall;
    let side = 100e-6;
    let force = k_f * (r_f - flap) / (2.0 * side * (0.5 * wall).cos());
    let angles = run.response.samples.last().unwrap().angles.as_slice().to_vec();
    assert!(
        (angles[0] - flap).abs() <= 1e-9,
        "flap at {} against {}",
        angles[0],
        flap
    );
    assert!(
        (angles[1] - wall).abs() <= 1e-9,
        "wall at {} against {}",
        angles[1],
        wall
    );
    // Both top corners of the wall press on the flap: one contact (parallel rows), the whole
    // force on it.
    let total: f64 = released.final_contacts.iter().map(|c| c.force_n).sum();
    eprintln!(
        "flap {:.9}° (closed form {:.9}°), wall {:.9}° ({:.9}°), force {total:.9e} N ({force:.9e} N)",
        angles[0].to_degrees(),
        flap.to_degrees(),
        angles[1].to_degrees(),
        wall.to_degrees()
    );
    assert!(
        (total - force).abs() <= 1e-9 * force,
        "contact force {total} N against the closed form {force} N"
    );
    // The wall's balance gives the same force through its own arm.
    let through_wall = k_w * (r_w - wall) / (side * (0.5 * wall).cos());
    assert!((through_wall - force).abs() <= 1e-12 * force);
    // The flap's drive turned down short of the wall (120° < 135°): nothing holds it, and it
    // rests at its drive with the wall at 90°.
    let (run, _) = flap_and_wall(120.0);
    let released = run.released.as_ref().unwrap();
    assert_eq!(released.outcome.label(), "rests", "{released:?}");
    assert!(released.final_contacts.iter().all(|c| c.force_n <= 0.0));
    let angles = run.response.samples.last().unwrap().angles.as_slice().to_vec();
    assert!((angles[0] - 120f64.to_radians()).abs() <= 1e-12);
    assert!((angles[1] - r_w).abs() <= 1e-12);
}

/// The flap and the wall with Coulomb friction μ between them (`docs/model.md#contact-forces`).
/// Past the first touch the wall's top edge slides out along the flap's face (the wall
/// pushed back), so the friction on the edge points back towards the flap's hinge with its
/// whole μ N. Along the flap's face it passes through the flap's hinge line (no torque
/// there); about the wall's hinge its arm is ℓ sin(θ_w / 2), against the push. So
/// K_f (r_f − θ_f) = 2 N ℓ cos(θ_w / 2) as before and K_w (r_w − θ_w) = N ℓ (cos(θ_w / 2) −
/// μ sin(θ_w / 2)), θ_f = π − θ_w / 2: one equation in θ_w, solved here by bisection.
#[test]
fn friction_holds_the_wall_up_by_its_coefficient_times_the_force() {
    use std::f64::consts::PI;
    let side = 100e-6;
    let (r_f, r_w) = (170f64.to_radians(), 90f64.to_radians());
    let mut previous_wall = 0.0;
    for mu in [0.1, 0.3, 0.6] {
        let (run, stiffness) = flap_and_wall_with(170.0, mu);
        let (k_f, k_w) = (stiffness[0], stiffness[1]);
        let released = run.released.as_ref().unwrap();
        assert_eq!(released.outcome.label(), "jams", "μ {mu}: {released:?}");
        let imbalance = |wall: f64| {
            let half = 0.5 * wall;
            k_w * (r_w - wall) - 0.5 * k_f * (r_f - PI + half) * (1.0 - mu * half.tan())
        };
        let (mut low, mut high) = (0.0, r_w);
        for _ in 0..200 {
            let middle = 0.5 * (low + high);
            if imbalance(middle) > 0.0 {
                low = middle;
            } else {
                high = middle;
            }
        }
        let wall = 0.5 * (low + high);
        let flap = PI - 0.5 * wall;
        let force = k_f * (r_f - flap) / (2.0 * side * (0.5 * wall).cos());
        let angles = run.response.samples.last().unwrap().angles.as_slice().to_vec();
        let pressing: Vec<_> = released.final_contacts.iter().filter(|c| c.force_n > 0.0).collect();
        assert_eq!(pressing.len(), 1, "μ {mu}: one meeting");
        let contact = pressing[0];
        let friction = contact.friction_n.iter().map(|f| f * f).sum::<f64>().sqrt();
        let across: f64 = (0..3).map(|i| contact.friction_n[i] * contact.normal[i]).sum();
        eprintln!(
            "μ {mu}: wall {:.9}° (closed form {:.9}°), flap {:.9}° ({:.9}°), force {:.9e} N ({force:.9e}), friction {friction:.9e} N",
            angles[1].to_degrees(),
            wall.to_degrees(),
            angles[0].to_degrees(),
            flap.to_degrees(),
            contact.force_n
        );
        assert!(
            (angles[1] - wall).abs() <= 1e-9,
            "μ {mu}: wall {} against {wall}",
            angles[1]
        );
        assert!(
            (angles[0] - flap).abs() <= 1e-9,
            "μ {mu}: flap {} against {flap}",
            angles[0]
        );
        assert!(
            (contact.force_n - force).abs() <= 1e-9 * force,
            "μ {mu}: force {} against {force}",
            contact.force_n
        );
        // Sliding: the friction is μ N, across the normal. Its bound is μ times the force
        // of the balance's last iterate but one (the normal force is lagged), which the
        // last step (under 1e-10 rad) moves by a few 1e-9 of itself.
        assert!(
            (friction - mu * contact.force_n).abs() <= 1e-8 * friction,
            "μ {mu}: friction {friction}"
        );
        assert!(across.abs() <= 1e-9 * friction);
        // More friction holds the wall up further.
        assert!(wall > previous_wall);
        previous_wall = wall;
    }
}
