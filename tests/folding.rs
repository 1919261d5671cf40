//! Rigid kinematics of crease patterns with many vertices, against independent answers:
//! the single-vertex engine, finite differences, an SVD, the Miura-ori's closed form and
//! hand-computed panel geometry.

mod common;

use nanofold::folding::{
    closure_jacobian, jacobian_rank, panel_contacts, panel_poses, tree_mismatch, vertex_positions, vertex_residuals,
    ContactSettings, FoldingModel,
};
use nanofold::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind};
use nanofold::pattern::generate::MiuraSpec;
use nanofold::pattern::{Assignment, LoadOptions};
use std::path::Path;

/// The folding path from flat along the assignment to 90%, at the default settings.
fn path_to_90_percent(model: &FoldingModel) -> nanofold::folding::FoldPath {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    let settings = FoldSettings {
        drive: Drive::Assignment { to: 90.0 },
        ..Default::default()
    };
    fold_path(model, &model.given_fold_angles(), &settings).unwrap()
}

fn miura(rows: usize, cols: usize, gamma_deg: f64, zigzag_deg: f64) -> FoldingModel {
    let spec = MiuraSpec {
        rows,
        cols,
        sector_angle: gamma_deg.to_radians(),
        zigzag_fold_angle: zigzag_deg.to_radians(),
        ..MiuraSpec::default()
    };
    FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap()
}

/// Numerical rank by nalgebra's SVD: a second, independent factorisation.
fn svd_rank(model: &FoldingModel, fold_angles: &[f64]) -> usize {
    let jac = closure_jacobian(model, fold_angles);
    if jac.rows == 0 {
        return 0;
    }
    let mut dense = nalgebra::DMatrix::<f64>::zeros(jac.rows, jac.cols);
    for &(r, c, v) in &jac.entries {
        dense[(r, c)] += v;
    }
    let singular = dense.singular_values();
    let largest: f64 = singular.max();
    singular.iter().filter(|&&s| s > 1e-8 * largest).count()
}

#[test]
fn single_vertex_library_patterns_agree_with_the_vertex_engine() {
    let mut checked = 0;
    for entry in std::fs::read_dir("patterns").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("fold") {
            continue;
        }
        let cp = nanofold::read::load_crease_pattern(&path).unwrap();
        // The files the single-vertex engine reads (the others have many vertices or no state).
        let Ok(vertex) = nanofold::read::load_pattern(&path, &LoadOptions::default()) else {
            assert!(
                cp.stars.len() != 1 || cp.fold_angles.iter().all(|&r| r == 0.0),
                "{}",
                path.display()
            );
            continue;
        };
        let name = path.display().to_string();
        assert_eq!(cp.creases.len(), vertex.creases.len(), "{name}");
        let model = FoldingModel::new(cp).unwrap();
        let rho = model.given_fold_angles();
        let residuals = vertex_residuals(&model, &rho);
        match residuals.as_slice() {
            [] => assert!(vertex.closure_residual == 0.0, "{name}: an open vertex has no closure"),
            [r] => assert!(
                (r - vertex.closure_residual).abs() <= 1e-12,
                "{name}: {r:e} vs {:e}",
                vertex.closure_residual
            ),
            more => panic!("{name}: {} stars", more.len()),
        }
        let jac = closure_jacobian(&model, &rho);
        let report = jacobian_rank(&jac).unwrap();
        assert_eq!(report.rank, svd_rank(&model, &rho), "{name}");
        // Locked creases are held: they are neither rank nor freedom.
        assert_eq!(report.dof, model.crease_count() - jac.held - report.rank);
        if name.ends_with("degree4_locked.fold") {
            assert_eq!(
                (jac.held, report.dof),
                (1, 0),
                "the single-vertex engine calls it locked"
            );
        }
        // Every panel placed from the tree lands where the single vertex's kinematics
        // puts it: the folded nodes keep their distances from the vertex.
        let mut poses = Vec::new();
        panel_poses(&model, &rho, &mut poses);
        let positions = vertex_positions(&model, &poses);
        for &[a, b] in &model.pattern.edges {
            let (p, q) = (model.pattern.vertices[a], model.pattern.vertices[b]);
            let flat = (q[0] - p[0]).hypot(q[1] - p[1]);
            let (x, y) = (positions[a], positions[b]);
            let folded = ((y[0] - x[0]).powi(2) + (y[1] - x[1]).powi(2) + (y[2] - x[2]).powi(2)).sqrt();
            if residuals.iter().all(|&r| r < 1e-12) {
                assert!((flat - folded).abs() < 1e-12, "{name}: edge length {flat} → {folded}");
            }
        }
        checked += 1;
    }
    assert!(checked >= 9, "{checked} FOLD patterns");
}

#[test]
fn the_jacobian_matches_central_differences() {
    let model = miura(3, 4, 65.0, 70.0);
    // Off the closure manifold, so that the residual and J^-1_l are not trivial.
    let rho: Vec<f64> = model
        .given_fold_angles()
        .iter()
        .enumerate()
        .map(|(k, r)| r + 0.05 * ((k as f64) * 1.3).sin())
        .collect();
    let jac = closure_jacobian(&model, &rho);
    // The residual's size per vertex is the holonomy's angle, found independently.
    for (v, angle) in vertex_residuals(&model, &rho).into_iter().enumerate() {
        let r = &jac.residual[3 * v..3 * v + 3];
        let size = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
        assert!(
            angle > 1e-3 && (size - angle).abs() < 1e-14,
            "vertex {v}: {size} against {angle}"
        );
    }
    let mut dense = vec![vec![0.0; jac.cols]; jac.rows];
    for &(r, c, v) in &jac.entries {
        dense[r][c] += v;
    }
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for c in 0..jac.cols {
        let (mut plus, mut minus) = (rho.clone(), rho.clone());
        plus[c] += h;
        minus[c] -= h;
        let (rp, rm) = (
            closure_jacobian(&model, &plus).residual,
            closure_jacobian(&model, &minus).residual,
        );
        for r in 0..jac.rows {
            worst = worst.max(((rp[r] - rm[r]) / (2.0 * h) - dense[r][c]).abs());
        }
    }
    assert!(worst < 1e-8, "largest difference {worst:e}");
}

#[test]
fn a_folded_miura_ori_is_rigid_with_one_degree_of_freedom() {
    for (rows, cols, gamma, zigzag) in [
        (2, 2, 60.0, 40.0),
        (4, 5, 70.0, 120.0),
        (6, 6, 45.0, 10.0),
        (5, 3, 80.0, 170.0),
    ] {
        let model = miura(rows, cols, gamma, zigzag);
        let rho = model.given_fold_angles();
        let worst = vertex_residuals(&model, &rho).into_iter().fold(0.0, f64::max);
        assert!(worst < 1e-12, "{rows}x{cols}: residual {worst:e}");
        let report = jacobian_rank(&closure_jacobian(&model, &rho)).unwrap();
        assert_eq!(report.dof, 1, "{rows}x{cols} γ {gamma}: {report:?}");
        assert_eq!(svd_rank(&model, &rho), report.rank);
        let mut poses = Vec::new();
        panel_poses(&model, &rho, &mut poses);
        assert!(tree_mismatch(&model, &rho, &poses) < 1e-12 * model.size);
        // Across every crease the panels' normals make the fold angle, and a valley
        // (positive) crease puts the far panel on the near panel's upper (+normal) side.
        let pattern = &model.pattern;
        for (column, &e) in pattern.creases.iter().enumerate() {
            let [Some(l), Some(r)] = pattern.edge_faces[e] else {
                panic!()
            };
            let (pl, pr) = (pattern.panel_of_face[l], pattern.panel_of_face[r]);
            let (nl, nr) = (poses[pl].rotation.column(2), poses[pr].rotation.column(2));
            let between = nl.dot(&nr).clamp(-1.0, 1.0).acos();
            assert!(
                (between - rho[column].abs()).abs() < 1e-7,
                "crease {e}: {between} vs {}",
                rho[column]
            );
            let a = poses[pl].place(pattern.vertices[pattern.edges[e][0]]);
            let far: nalgebra::Vector3<f64> = model.panel_vertices[pr]
                .iter()
                .map(|&v| poses[pr].place(pattern.vertices[v]) - a)
                .sum();
            assert_eq!(nl.dot(&far) > 0.0, rho[column] > 0.0, "crease {e}: side");
        }
        let contacts = panel_contacts(&model, &poses, &ContactSettings::default());
        assert_eq!(contacts.crossing().count(), 0, "{rows}x{cols} γ {gamma} ρ {zigzag}");
    }
}

#[test]
fn the_flat_miura_ori_is_singular() {
    // At flat every vertex's axes lie in the plane: J loses a row per vertex, and first-order
    // analysis sees more freedom than the single folding motion.
    let model = miura(4, 4, 60.0, 0.0);
    let rho = model.given_fold_angles();
    let report = jacobian_rank(&closure_jacobian(&model, &rho)).unwrap();
    assert_eq!(report.rank, 2 * model.stars.len());
    assert!(report.dof > 1);
}

/// Three strips side by side, creases at x = 1 and x = 2.
fn three_strips(first: f64, second: f64) -> FoldingModel {
    let vertices = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [2.0, 0.0],
        [3.0, 0.0],
        [3.0, 1.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [0.0, 1.0],
    ];
    let mut edges = vec![[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 6], [6, 7], [7, 0]];
    let mut kinds = vec![EdgeKind::Boundary; 8];
    let mut fold_angles = vec![0.0; 8];
    for (edge, rho) in [([1, 6], first), ([2, 5], second)] {
        edges.push(edge);
        let assignment = if rho >= 0.0 {
            Assignment::Valley
        } else {
            Assignment::Mountain
        };
        kinds.push(EdgeKind::Crease(assignment));
        fold_angles.push(rho);
    }
    let builder = CreasePatternBuilder {
        name: "strips".into(),
        vertices,
        edges,
        kinds,
        fold_angles,
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    FoldingModel::new(builder.build().unwrap()).unwrap()
}

#[test]
fn panels_folded_through_each_other_are_found_and_walls_are_measured() {
    let wide = ContactSettings {
        clearance: 1e-9,
        search: 2.0,
        ..ContactSettings::default()
    };
    let mut poses = Vec::new();
    // Both outer strips up by 90°: two walls one unit apart.
    let model = three_strips(90f64.to_radians(), 90f64.to_radians());
    panel_poses(&model, &model.given_fold_angles(), &mut poses);
    let report = panel_contacts(&model, &poses, &wide);
    assert!(report.contacts.is_empty());
    let up = vertex_positions(&model, &poses);
    assert!(
        (up[0][2] - 1.0).abs() < 1e-15 && (up[3][2] - 1.0).abs() < 1e-15,
        "valleys lift: {up:?}"
    );
    assert!(
        (report.min_clearance.unwrap() - 1.0).abs() < 1e-14,
        "{:?}",
        report.min_clearance
    );
    // Both up by 170°: each lies over the middle strip and they pass through each other.
    let model = three_strips(170f64.to_radians(), 170f64.to_radians());
    panel_poses(&model, &model.given_fold_angles(), &mut poses);
    let report = panel_contacts(&model, &poses, &wide);
    assert_eq!(report.crossing().count(), 1, "{report:?}");
    // A zigzag (valley, mountain) at 170° stacks them without crossing.
    let model = three_strips(170f64.to_radians(), -170f64.to_radians());
    panel_poses(&model, &model.given_fold_angles(), &mut poses);
    let report = panel_contacts(&model, &poses, &wide);
    assert_eq!(report.crossing().count(), 0, "{report:?}");
    // A single crease has no closure condition: two panels, one DOF per crease.
    let rho = model.given_fold_angles();
    assert_eq!(jacobian_rank(&closure_jacobian(&model, &rho)).unwrap().dof, 2);
    assert!(Path::new("patterns").exists());
}

#[test]
fn a_miura_ori_folds_from_flat_along_its_closed_form() {
    use nanofold::folding::{fold_path, Drive, FoldSettings, StopReason};
    for (rows, cols, gamma) in [(3, 3, 60.0), (5, 4, 75.0)] {
        let model = miura(rows, cols, gamma, 0.0);
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 95.0 },
            ..FoldSettings::default()
        };
        let path = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        assert_eq!(path.stop, StopReason::Reached, "{}", path.evidence);
        assert!(path.max_closure_residual <= 1e-10);
        // Every state on the path is a Miura state: the straight creases follow
        // tan(ρ_h/2) = cos γ tan(ρ_z/2) of the zigzag ones, with the assigned signs.
        let reference = |zigzag: f64| {
            let spec = MiuraSpec {
                rows,
                cols,
                sector_angle: gamma.to_radians(),
                zigzag_fold_angle: zigzag,
                ..MiuraSpec::default()
            };
            FoldingModel::new(spec.build().unwrap().build().unwrap())
                .unwrap()
                .given_fold_angles()
        };
        let zigzag_column = model
            .pattern
            .creases
            .iter()
            .position(|&e| {
                let [a, b] = model.pattern.edges[e];
                (model.pattern.vertices[a][0] - model.pattern.vertices[b][0]).abs() < 0.99
            })
            .unwrap();
        for step in &path.steps {
            let zigzag = step.fold_angles[zigzag_column].abs();
            let expected = reference(zigzag);
            let error = step
                .fold_angles
                .iter()
                .zip(&expected)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(error < 1e-9, "{rows}x{cols} at ρ_z {zigzag}: {error:e}");
        }
        let last = path.steps.last().unwrap();
        let most = last.fold_angles.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        assert!((most - 0.95 * std::f64::consts::PI).abs() < 1e-8, "{most}");
    }
}

/// Modes of the vertex are tangent to its folding branches: from ε·mode, Newton with the
/// first crease held (the single-vertex solver) moves the others by O(ε²); from a
/// first-order direction off the modes it moves them by O(ε).
#[test]
fn degree4_modes_are_the_tangents_of_the_single_vertex_branches() {
    use nanofold::folding::{degree4_modes, Star};
    use nanofold::geometry::kinematics::solve_closure;
    let eps = 1e-3;
    for sectors_deg in [
        [60.0, 120.0, 120.0, 60.0],
        [70.0, 100.0, 120.0, 70.0],
        [80.0, 95.0, 100.0, 85.0],
    ] {
        let sector_angles: Vec<f64> = sectors_deg.iter().map(|a: &f64| a.to_radians()).collect();
        let star = Star {
            vertex: 0,
            columns: vec![0, 1, 2, 3],
            sector_angles: sector_angles.clone(),
        };
        let modes = degree4_modes(&star).unwrap();
        assert_eq!(modes.len(), 4, "{sectors_deg:?}");
        let settle = |start: [f64; 4]| {
            let mut rho = start.to_vec();
            solve_closure(&sector_angles, &mut rho, &[1, 2, 3], 1e-15, 50).unwrap();
            (0..4).map(|k| (rho[k] - start[k]).abs()).fold(0.0, f64::max)
        };
        for mode in &modes {
            let moved = settle(mode.map(|m| eps * m));
            assert!(
                moved < 20.0 * eps * eps,
                "{sectors_deg:?} mode {mode:?}: moved {moved:e}"
            );
        }
        // Half-way between the two lines, still in the first-order plane.
        let between: [f64; 4] = [0, 1, 2, 3].map(|k| eps * 0.5 * (modes[0][k] + modes[2][k]));
        let moved = settle(between);
        assert!(
            moved > 0.05 * eps,
            "{sectors_deg:?}: off the modes, moved only {moved:e}"
        );
    }
}

/// The modes do not depend on which crease a star lists first (a pattern turned in its
/// plane lists them from another): every cyclic shift of the sectors gives the same modes,
/// shifted; and a generated Miura-ori turned by 5.1266 rad, whose vertex 9 once got NaN
/// modes (its quadratic form came out as 2·q12·s·t, and the null lines were found by
/// dividing by q11 = 0), gets finite modes at every vertex and the unturned verdict.
#[test]
fn degree4_modes_do_not_depend_on_the_first_crease() {
    use nanofold::commands::{check, Generator, Pattern, Settings};
    use nanofold::folding::{degree4_modes, Star};
    let miura = Generator::Miura(MiuraSpec {
        rows: 3,
        cols: 5,
        sector_angle: 50f64.to_radians(),
        ..MiuraSpec::default()
    });
    let mut fold = miura.to_fold().unwrap();
    let turn = 5.126631449819447_f64;
    let coords: Vec<[f64; 2]> = serde_json::from_value(fold["vertices_coords"].clone()).unwrap();
    fold["vertices_coords"] = serde_json::json!(coords
        .iter()
        .map(|&[x, y]| [x * turn.cos() - y * turn.sin(), x * turn.sin() + y * turn.cos()])
        .collect::<Vec<_>>());
    let turned = Pattern::parse(&fold.to_string(), "turned", "turned", &LoadOptions::default()).unwrap();
    for star in &turned.sheet().unwrap().stars {
        let modes = degree4_modes(star).unwrap();
        assert!(
            modes.iter().flatten().all(|m| m.is_finite()),
            "vertex {}: {modes:?}",
            star.vertex
        );
    }
    let report = check(&turned, &Settings::default()).unwrap();
    assert_eq!(
        report.verdict,
        nanofold::prelude::PatternVerdict::RigidlyFoldable,
        "{}",
        report.evidence
    );
    for sectors_deg in [
        [50.0, 130.0, 130.0, 50.0],
        [60.0, 120.0, 120.0, 60.0],
        [70.0, 100.0, 120.0, 70.0],
    ] {
        let modes_from = |shift: usize| {
            let sector_angles: Vec<f64> = (0..4).map(|k| f64::to_radians(sectors_deg[(k + shift) % 4])).collect();
            let star = Star {
                vertex: 0,
                columns: vec![0, 1, 2, 3],
                sector_angles,
            };
            let mut modes: Vec<[f64; 4]> = degree4_modes(&star)
                .unwrap()
                .into_iter()
                // Back in the unshifted crease order.
                .map(|m| [0, 1, 2, 3].map(|k| m[(k + 4 - shift) % 4]))
                .collect();
            modes.sort_by(|a, b| a.partial_cmp(b).unwrap());
            modes
        };
        let reference = modes_from(0);
        assert_eq!(reference.len(), 4);
        for shift in 1..4 {
            let shifted = modes_from(shift);
            for (a, b) in reference.iter().zip(&shifted) {
                assert!(
                    (0..4).all(|k| a[k].is_finite() && (a[k] - b[k]).abs() < 1e-9),
                    "{sectors_deg:?} from crease {shift}: {b:?} against {a:?}"
                );
            }
        }
    }
}

/// At a Miura vertex the zigzag pair and the straight pair keep tan(ρ_h/2) = cos γ tan(ρ_z/2):
/// near flat the mode's ratio is cos γ.
#[test]
fn the_miura_mode_has_the_closed_form_ratio() {
    use nanofold::folding::degree4_modes;
    for gamma in [45.0_f64, 60.0, 75.0] {
        let model = miura(2, 2, gamma, 0.0);
        let star = &model.stars[0];
        let modes = degree4_modes(star).unwrap();
        // Rays of the star: which are the straight (horizontal) creases?
        let horizontal: Vec<bool> = star
            .columns
            .iter()
            .map(|&c| {
                let [a, b] = model.pattern.edges[model.pattern.creases[c]];
                (model.pattern.vertices[a][1] - model.pattern.vertices[b][1]).abs() < 1e-12
            })
            .collect();
        let ratios: Vec<f64> = modes
            .iter()
            .filter(|m| m.iter().all(|&x| x != 0.0))
            .map(|m| {
                let h = (0..4)
                    .filter(|&k| horizontal[k])
                    .map(|k| m[k].abs())
                    .fold(0.0, f64::max);
                let z = (0..4)
                    .filter(|&k| !horizontal[k])
                    .map(|k| m[k].abs())
                    .fold(0.0, f64::max);
                h / z
            })
            .collect();
        assert_eq!(ratios.len(), 2, "γ {gamma}");
        for r in ratios {
            assert!((r - gamma.to_radians().cos()).abs() < 1e-12, "γ {gamma}: {r}");
        }
    }
}

/// The library of crease patterns of many vertices and what `check` must say of each, with
/// where the expectation comes from.
#[test]
fn every_crease_pattern_in_the_library_gets_its_expected_verdict() {
    use nanofold::folding::{check_pattern, CheckSettings, PatternVerdict::*};
    let expected = [
        // A closed-form folding motion exists (docs/model.md#pattern-generators).
        ("miura_4x4", RigidlyFoldable),
        // The closed-form state.
        ("miura_4x4_folded", Rigid),
        // One crease turned 5° off the closed form: its two vertices cannot close.
        ("miura_4x4_bent", NotRigid),
        // Abel et al. 2016: a degree-4 vertex folds rigidly only in its modes' patterns.
        ("miura_4x4_bad_vertex", NotRigidlyFoldable),
        ("degree4_bad_assignment", NotRigidlyFoldable),
        // The classic square twist is flat-foldable but not rigidly foldable (Evans et al. 2015).
        ("square_twist", NotRigidlyFoldable),
        // Breaks big-little-big at every corner.
        ("square_twist_flipped", NotRigidlyFoldable),
        // Two walls folded 170° over one strip must cross (hand geometry).
        ("strips_crossing", SelfIntersecting),
        // A witness path, checked below step by step.
        ("waterbomb_4x3", RigidlyFoldable),
        // The same with rectangular cells (rows 0.6 high): a witness path, checked below.
        ("huffman_waterbomb_6x4", RigidlyFoldable),
        // A witness path, checked below, and the petal points' closed form in the next test.
        ("bird_base", RigidlyFoldable),
    ];
    let mut seen = 0;
    for (name, verdict) in expected {
        let path = Path::new("patterns/many").join(format!("{name}.fold"));
        let model = FoldingModel::new(nanofold::read::load_crease_pattern(&path).unwrap()).unwrap();
        let report = check_pattern(&model, &CheckSettings::default()).unwrap();
        assert_eq!(report.verdict, verdict, "{name}: {}", report.evidence);
        if let Some(witness) = report.witness.as_ref().filter(|_| verdict == RigidlyFoldable) {
            // Every frame of the witness closes and has no panels through each other,
            // measured here again.
            let mut poses = Vec::new();
            for step in &witness.steps {
                let worst = vertex_residuals(&model, &step.fold_angles)
                    .into_iter()
                    .fold(0.0, f64::max);
                assert!(worst <= 1e-10, "{name}: frame residual {worst:e}");
                panel_poses(&model, &step.fold_angles, &mut poses);
                let contacts = panel_contacts(&model, &poses, &ContactSettings::default());
                assert_eq!(contacts.crossing().count(), 0, "{name}");
            }
            assert!(witness.steps.last().unwrap().progress > 0.3, "{name}");
        }
        seen += 1;
    }
    let files = std::fs::read_dir("patterns/many").unwrap().count();
    assert_eq!(seen, files, "every file in patterns/many has its expected verdict here");
    // The bent Miura-ori names the bent crease's two vertices as its worst.
    let path = Path::new("patterns/many/miura_4x4_bent.fold");
    let model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    let report = check_pattern(&model, &CheckSettings::default()).unwrap();
    let bent = model
        .pattern
        .creases
        .iter()
        .copied()
        .find(|&e| {
            let reference = miura(4, 4, 60.0, 100.0);
            (model.pattern.fold_angles[e] - reference.pattern.fold_angles[e]).abs() > 1e-6
        })
        .unwrap();
    let mut worst: Vec<usize> = report.worst_vertices.iter().take(2).map(|w| w.0).collect();
    worst.sort();
    let mut ends = model.pattern.edges[bent].to_vec();
    ends.sort();
    assert_eq!(worst, ends);
    assert!(report.worst_vertices[2].1 < 1e-12);
    // The crossing strips: the two outer panels.
    let path = Path::new("patterns/many/strips_crossing.fold");
    let model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    let report = check_pattern(&model, &CheckSettings::default()).unwrap();
    assert_eq!(report.intersecting_pairs.len(), 1);
    let outer: Vec<usize> = report.intersecting_pairs[0]
        .iter()
        .map(|&p| {
            model.panel_vertices[p]
                .iter()
                .filter(|&&v| [0, 3, 4, 7].contains(&v))
                .count()
        })
        .collect();
    assert_eq!(
        outer,
        vec![2, 2],
        "each crossing panel holds two of the sheet's corners"
    );
}

/// The sparse null-space count agrees with the dense pivoted QR (two methods) on folded
/// and flat states, where the dense one is still affordable.
#[test]
fn the_sparse_dof_count_agrees_with_the_pivoted_qr() {
    use nanofold::folding::{jacobian_rank_dense, jacobian_rank_sparse, RankMethod};
    let mut cases: Vec<(String, FoldingModel, Vec<f64>)> = Vec::new();
    for (n, zigzag) in [(4, 0.0), (6, 0.0), (8, 30.0), (12, 120.0), (16, 170.0)] {
        let model = miura(n, n, 60.0, zigzag);
        let rho = model.given_fold_angles();
        cases.push((format!("miura {n} at {zigzag}"), model, rho));
    }
    for name in ["square_twist", "waterbomb_4x3", "strips_crossing"] {
        let path = Path::new("patterns/many").join(format!("{name}.fold"));
        let model = FoldingModel::new(nanofold::read::load_crease_pattern(&path).unwrap()).unwrap();
        let rho = model.given_fold_angles();
        cases.push((name.into(), model, rho));
    }
    // A folded waterbomb state from a folding path.
    let path = Path::new("patterns/many/waterbomb_4x3.fold");
    let model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    let settings = nanofold::folding::FoldSettings {
        drive: nanofold::folding::Drive::Assignment { to: 30.0 },
        ..Default::default()
    };
    let folded = nanofold::folding::fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
    let rho = folded.steps.last().unwrap().fold_angles.clone();
    cases.push(("waterbomb folded".into(), model, rho));
    for (name, model, rho) in cases {
        let jac = closure_jacobian(&model, &rho);
        let dense = jacobian_rank_dense(&jac);
        let sparse = jacobian_rank_sparse(&jac).unwrap();
        assert_eq!(sparse.method, RankMethod::SubspaceIteration);
        assert_eq!(dense.dof, sparse.dof, "{name}: {dense:?} {sparse:?}");
        // The sparse count's gap is clear: two decades or more on each side of the threshold.
        assert!(sparse.largest_dropped < 0.01 * sparse.threshold, "{name}: {sparse:?}");
        assert!(sparse.smallest_kept > 100.0 * sparse.threshold, "{name}: {sparse:?}");
    }
}

/// At the flat state each star's axes lie in the plane: its closure linearises to two
/// independent equations (the in-plane rotation), so the first-order count is creases −
/// 2 · interior vertices. The sparse count gets it on flat Miura-ori past the dense limit,
/// where many small singular values sit just above the threshold.
#[test]
fn the_sparse_count_at_the_flat_miura_ori_is_creases_minus_two_per_vertex() {
    use nanofold::folding::jacobian_rank_sparse;
    for n in [36, 40] {
        let model = miura(n, n, 60.0, 0.0);
        let jac = closure_jacobian(&model, &model.given_fold_angles());
        let count = jacobian_rank_sparse(&jac).unwrap();
        let expected = model.crease_count() - 2 * model.stars.len();
        assert_eq!(count.dof, expected, "n = {n}: {count:?}");
        assert!(count.smallest_kept > 1e6 * count.threshold, "n = {n}: {count:?}");
    }
}

/// Within 1e-5° of flat the Miura-ori's first-order singular values (∝ the fold angle)
/// pass through the threshold one by one. The sparse count must give the SVD's count there:
/// it once reported 0 DOF (its null direction was mixed with the cluster of small singular
/// values the normal equations cannot separate), where the SVD has 1 to 7.
#[test]
fn the_sparse_count_near_flat_is_the_svds_count() {
    use nanofold::folding::{jacobian_rank_sparse, RANK_TOL};
    for n in [8, 12, 16] {
        for zigzag_deg in [5e-7, 1e-6, 2e-6, 5e-6] {
            let model = miura(n, n, 60.0, zigzag_deg);
            let jac = closure_jacobian(&model, &model.given_fold_angles());
            let mut dense = nalgebra::DMatrix::<f64>::zeros(jac.rows, jac.cols);
            for &(r, c, v) in &jac.entries {
                dense[(r, c)] += v;
            }
            let largest_column = (0..jac.cols).map(|c| dense.column(c).norm()).fold(0.0, f64::max);
            let threshold = RANK_TOL * largest_column;
            let singular = dense.singular_values();
            let svd_dof = jac.cols - singular.iter().filter(|&&s| s > threshold).count();
            let count = jacobian_rank_sparse(&jac).unwrap();
            assert_eq!(count.dof, svd_dof, "n = {n}, {zigzag_deg}°: {count:?}");
            // The values either side of the threshold are the SVD's, not upper bounds.
            let below = singular.iter().copied().filter(|&s| s <= threshold).fold(0.0, f64::max);
            let above = singular
                .iter()
                .copied()
                .filter(|&s| s > threshold)
                .fold(f64::INFINITY, f64::min);
            assert!(
                (count.largest_dropped - below).abs() <= 1e-3 * below + 1e-6 * threshold,
                "n = {n}, {zigzag_deg}°: {count:?}, SVD {below:e}"
            );
            assert!(
                (count.smallest_kept - above).abs() <= 1e-3 * above,
                "n = {n}, {zigzag_deg}°: {count:?}, SVD {above:e}"
            );
        }
    }
}

/// Constraint curves of a Miura-ori: the exact sweep is the closed form at every point, and
/// the fit's error, measured at points it did not see, falls with the degree.
#[test]
fn miura_constraint_curves_follow_the_closed_form() {
    use nanofold::constraints::network::{fit_network, fit_network_to_tolerance, network_mujoco, network_sweep};
    let model = miura(4, 4, 60.0, 100.0);
    let rho = model.given_fold_angles();
    // Drive a valley zigzag crease (positive, |dx| < width).
    let driver = (0..model.crease_count())
        .find(|&c| {
            let [a, b] = model.pattern.edges[model.pattern.creases[c]];
            (model.pattern.vertices[a][0] - model.pattern.vertices[b][0]).abs() < 0.99 && rho[c] > 0.0
        })
        .unwrap();
    let domain = [5f64.to_radians(), 120f64.to_radians()];
    let sweep = network_sweep(&model, &rho, driver, domain, 60).unwrap();
    assert!(sweep.max_closure_residual <= 1e-12);
    for (theta, state) in sweep.driver_values.iter().zip(&sweep.states) {
        let expected = miura(4, 4, 60.0, theta.to_degrees()).given_fold_angles();
        let error = state
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(error < 1e-10, "at {:.3}°: {error:e}", theta.to_degrees());
    }
    let errors: Vec<f64> = [2, 4, 8]
        .iter()
        .map(|&d| fit_network(&model, &sweep, d).unwrap().max_fit_error_rad)
        .collect();
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
    let auto = fit_network_to_tolerance(&model, &sweep, 1e-6).unwrap();
    assert!(auto.max_fit_error_rad <= 1e-6 && auto.degree <= 20);
    let quartic = fit_network(&model, &sweep, 4).unwrap();
    let xml = network_mujoco(&quartic).unwrap();
    assert_eq!(xml.matches("<joint ").count(), model.crease_count() - 1);
    assert!(network_mujoco(&fit_network(&model, &sweep, 5).unwrap()).is_err());
    // A flat start has many degrees of freedom: refused with the reason.
    let flat = miura(4, 4, 60.0, 0.0);
    let error = network_sweep(&flat, &flat.given_fold_angles(), driver, domain, 60).unwrap_err();
    assert!(error.to_string().contains("degrees of freedom"), "{error}");
}

/// Creases that meet at no interior vertex: one diagonal across a square sheet (as FOLD's
/// own `diagonal-cp.fold` example), and parallel pleats. Each crease is a free hinge.
#[test]
fn patterns_without_interior_vertices_fold_crease_by_crease() {
    use nanofold::folding::{check_pattern, CheckSettings, PatternVerdict};
    let diagonal = r#"{"file_spec": 1.1, "vertices_coords": [[0,0],[1,0],[1,1],[0,1]],
        "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[0,2]],
        "edges_assignment": ["B","B","B","B","V"]}"#;
    let cp = nanofold::read::parse_crease_pattern(diagonal, "diagonal", "test").unwrap();
    assert_eq!((cp.stars.len(), cp.creases.len(), cp.panel_count), (0, 1, 2));
    let model = FoldingModel::new(cp).unwrap();
    let report = check_pattern(&model, &CheckSettings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::RigidlyFoldable, "{}", report.evidence);
    assert_eq!(report.rank.dof, 1);
    // Folded all the way, the two triangles lie on each other (touching, not crossing).
    let witness = report.witness.unwrap();
    let last = witness.steps.last().unwrap();
    assert!(
        (last.fold_angles[0] - std::f64::consts::PI).abs() < 1e-9,
        "{:?}",
        last.fold_angles
    );
    // Pleats: two parallel creases, mountain and valley, folded to ±90°: rigid, 2 DOF.
    let pleats = r#"{"file_spec": 1.1, "vertices_coords": [[0,0],[1,0],[2,0],[3,0],[3,1],[2,1],[1,1],[0,1]],
        "edges_vertices": [[0,1],[1,2],[2,3],[3,4],[4,5],[5,6],[6,7],[7,0],[1,6],[2,5]],
        "edges_assignment": ["B","B","B","B","B","B","B","B","M","V"],
        "edges_foldAngle": [0,0,0,0,0,0,0,0,-90,90]}"#;
    let model = FoldingModel::new(nanofold::read::parse_crease_pattern(pleats, "pleats", "test").unwrap()).unwrap();
    let report = check_pattern(&model, &CheckSettings::default()).unwrap();
    assert_eq!(
        (report.verdict, report.rank.dof),
        (PatternVerdict::Rigid, 2),
        "{}",
        report.evidence
    );
}

/// A folded form in Origami Simulator's layout (3D vertices with y up, triangulated faces
/// with F facet edges, `edges_foldAngle` holding ±180 targets or null) built from a rigid
/// Miura-ori state: developed back, it is the same crease pattern (every edge length) with
/// the same fold angles; moved off rigidity, it is `not_rigid` with the bend reported.
fn simulator_export(model: &FoldingModel, rho: &[f64], nudge: f64, clockwise: bool) -> String {
    let mut poses = Vec::new();
    panel_poses(model, rho, &mut poses);
    let mut points = vertex_positions(model, &poses);
    points[model.stars[0].vertex][2] += nudge;
    let pattern = &model.pattern;
    let mut edges: Vec<[usize; 2]> = pattern.edges.clone();
    let mut letters: Vec<String> = pattern
        .kinds
        .iter()
        .map(|k| match k {
            EdgeKind::Boundary => "B".into(),
            EdgeKind::Facet => "F".into(),
            EdgeKind::Crease(a) => a.letter().into(),
        })
        .collect();
    let mut targets: Vec<serde_json::Value> = pattern
        .kinds
        .iter()
        .map(|k| match k {
            EdgeKind::Crease(Assignment::Valley) => serde_json::json!(180),
            EdgeKind::Crease(Assignment::Mountain) => serde_json::json!(-180),
            _ => serde_json::Value::Null,
        })
        .collect();
    // Every quadrilateral face cut by a facet edge into two triangles; triangles kept.
    let mut faces = Vec::new();
    for face in &pattern.faces {
        assert!(face.len() == 3 || face.len() == 4);
        let pieces = if face.len() == 3 {
            vec![face.clone()]
        } else {
            edges.push([face[0], face[2]]);
            letters.push("F".into());
            targets.push(serde_json::Value::Null);
            vec![vec![face[0], face[1], face[2]], vec![face[0], face[2], face[3]]]
        };
        for mut triangle in pieces {
            if clockwise {
                triangle.reverse();
            }
            faces.push(triangle);
        }
    }
    // y up: the sheet's (x, y, z) written as (x, z, −y), an orientation-keeping rotation.
    let coords: Vec<[f64; 3]> = points.iter().map(|p| [p[0], p[2], -p[1]]).collect();
    serde_json::json!({
        "file_spec": 1.1,
        "file_creator": "a test, in Origami Simulator's layout",
        "file_classes": ["singleModel"],
        "frame_classes": ["foldedForm"],
        "frame_attributes": ["3D"],
        "frame_unit": "unit",
        "vertices_coords": coords,
        "edges_vertices": edges,
        "edges_assignment": letters,
        "edges_foldAngle": targets,
        "faces_vertices": faces,
    })
    .to_string()
}

#[test]
fn a_folded_form_in_the_simulator_layout_develops_into_its_crease_pattern() {
    use nanofold::folding::{check_pattern, CheckSettings, PatternVerdict};
    let model = miura(3, 4, 65.0, 110.0);
    let rho = model.given_fold_angles();
    let text = simulator_export(&model, &rho, 0.0, false);
    let developed =
        FoldingModel::new(nanofold::read::parse_crease_pattern(&text, "exported", "test").unwrap()).unwrap();
    let fit = developed.pattern.folded_form.unwrap();
    assert!(fit.development_error < 1e-12 && fit.max_facet_angle < 1e-12, "{fit:?}");
    // The same creases (file order kept) with the same angles, and every edge its length.
    assert_eq!(developed.pattern.creases, model.pattern.creases);
    let angles = developed.given_fold_angles();
    let worst = angles.iter().zip(&rho).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-12, "fold angles differ by {worst:e}");
    for (e, &[a, b]) in model.pattern.edges.iter().enumerate() {
        let length = |p: &[[f64; 2]]| (p[a][0] - p[b][0]).hypot(p[a][1] - p[b][1]);
        assert!(
            (length(&developed.pattern.vertices) - length(&model.pattern.vertices)).abs() < 1e-12,
            "edge {e}"
        );
    }
    let report = check_pattern(&developed, &CheckSettings::default()).unwrap();
    assert_eq!(
        (report.verdict, report.rank.dof),
        (PatternVerdict::Rigid, 1),
        "{}",
        report.evidence
    );
    // Faces listed clockwise: the development is mirrored, and the assignments turn it back.
    let text = simulator_export(&model, &rho, 0.0, true);
    let mirrored = FoldingModel::new(nanofold::read::parse_crease_pattern(&text, "cw", "test").unwrap()).unwrap();
    assert!(mirrored.pattern.folded_form.unwrap().mirrored);
    let worst = mirrored
        .given_fold_angles()
        .iter()
        .zip(&rho)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "mirrored: fold angles differ by {worst:e}");
    // A compliant simulator's state: one interior vertex lifted by 1e-3.
    let text = simulator_export(&model, &rho, 1e-3, false);
    let developed = FoldingModel::new(nanofold::read::parse_crease_pattern(&text, "bent", "test").unwrap()).unwrap();
    let report = check_pattern(&developed, &CheckSettings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::NotRigid, "{}", report.evidence);
    assert!(
        report.folded_form.unwrap().max_facet_angle > 1e-4,
        "{:?}",
        report.folded_form
    );
    // Projected (`--project`)? Lifting one vertex changes the developed crease pattern, and a
    // Miura-ori's rigid folding needs its exact sector angles: no rigid state is near, and
    // the projection says so by name.
    let error = nanofold::folding::project_to_rigid(&developed, &developed.given_fold_angles(), 1e-11).unwrap_err();
    assert!(error.to_string().contains("no rigid state near"), "{error}");
}

/// A compliant export of a pattern with freedom to spare (the bird base, folded to 30% by
/// `fold`, one interior vertex lifted by 1e-3): `check` calls it not_rigid; projected, it is a
/// rigid state near the source, and `check --project` and `unfold --project` take it, say how
/// far they moved it, and unfold it flat.
#[test]
fn a_nearly_rigid_export_is_projected_onto_a_rigid_state() {
    use nanofold::folding::{check_pattern, fold_path, CheckSettings, Drive, FoldSettings, PatternVerdict};
    let model =
        FoldingModel::new(nanofold::read::load_crease_pattern(Path::new("patterns/many/bird_base.fold")).unwrap())
            .unwrap();
    let settings = FoldSettings {
        drive: Drive::Assignment { to: 30.0 },
        ..FoldSettings::default()
    };
    let rho = fold_path(&model, &model.given_fold_angles(), &settings)
        .unwrap()
        .steps
        .last()
        .unwrap()
        .fold_angles
        .clone();
    let text = simulator_export(&model, &rho, 1e-3, false);
    let developed = FoldingModel::new(nanofold::read::parse_crease_pattern(&text, "bent", "test").unwrap()).unwrap();
    let report = check_pattern(&developed, &CheckSettings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::NotRigid, "{}", report.evidence);
    let projection = nanofold::folding::project_to_rigid(&developed, &developed.given_fold_angles(), 1e-11).unwrap();
    assert!(projection.residual_before > 1e-5, "{projection:?}");
    let closed = vertex_residuals(&developed, &projection.fold_angles)
        .into_iter()
        .fold(0.0, f64::max);
    assert!(closed <= 1e-11, "{closed:e}");
    // Near the state the export came from (the lift is 1e-3 of the sheet's half side).
    let from_source = projection
        .fold_angles
        .iter()
        .zip(&rho)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        from_source < 1e-2 && projection.max_change < 1e-2,
        "{from_source} {projection:?}"
    );
    let projected = developed.with_fold_angles(&projection.fold_angles);
    let report = check_pattern(&projected, &CheckSettings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::Rigid, "{}", report.evidence);
    // The same from the command line.
    let dir = std::env::temp_dir().join(format!("nanofold-project-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bent.fold");
    std::fs::write(&file, &text).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_nanofold"))
            .args(args)
            .arg(&file)
            .output()
            .unwrap();
        serde_json::from_slice::<serde_json::Value>(&out.stdout)
            .unwrap_or_else(|_| panic!("{}", String::from_utf8_lossy(&out.stderr)))
    };
    assert_eq!(run(&["check", "--json"])["verdict"], "not_rigid");
    // Without --project, `unfold` refuses to unfold a state that needs bending.
    let refused = run(&["unfold", "--json", "--out", dir.join("raw").to_str().unwrap()]);
    assert_eq!(refused["verdict"], "not_rigid", "{refused}");
    let checked = run(&["check", "--json", "--project"]);
    assert_eq!(checked["verdict"], "rigid", "{checked}");
    assert!(checked["projection"]["max_change_rad"].as_f64().unwrap() > 0.0);
    let out_dir = dir.join("out");
    let unfolded = run(&["unfold", "--project", "--json", "--out", out_dir.to_str().unwrap()]);
    assert_eq!(unfolded["verdict"], "flat", "{unfolded}");
    assert!(unfolded["adjustments"][0].as_str().unwrap().contains("projected"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Origami Simulator export folded "to 50%": every crease near ±90°, with its sign.
#[test]
fn the_simulator_fixture_is_half_folded() {
    let cp = nanofold::read::load_crease_pattern(Path::new("tests/fixtures/origami-simulator/simple_50.fold")).unwrap();
    for &e in &cp.creases {
        let degrees = cp.fold_angles[e].to_degrees();
        let sign = match cp.kinds[e] {
            EdgeKind::Crease(Assignment::Valley) => 1.0,
            _ => -1.0,
        };
        assert!(sign * degrees > 60.0 && sign * degrees < 120.0, "edge {e}: {degrees}°");
    }
}

/// Kawasaki and Maekawa, counted by hand: every Miura vertex satisfies both; flipping a
/// crease that only one vertex holds breaks Maekawa there and nowhere else.
#[test]
fn flat_foldability_conditions_are_reported_per_vertex() {
    use nanofold::folding::FlatFoldability;
    let spec = MiuraSpec {
        rows: 3,
        cols: 3,
        sector_angle: 70f64.to_radians(),
        ..MiuraSpec::default()
    };
    let mut builder = spec.build().unwrap();
    let model = FoldingModel::new(builder.clone().build().unwrap()).unwrap();
    let conditions = FlatFoldability::of(&model);
    assert!(conditions.worst_kawasaki.unwrap().1 < 1e-12);
    assert!(conditions.maekawa_failures.is_empty());
    let (vertex, edge) = model
        .stars
        .iter()
        .find_map(|star| {
            star.columns
                .iter()
                .find(|&&c| model.stars.iter().filter(|s| s.columns.contains(&c)).count() == 1)
                .map(|&c| (star.vertex, model.pattern.creases[c]))
        })
        .unwrap();
    builder.kinds[edge] = match builder.kinds[edge] {
        EdgeKind::Crease(Assignment::Valley) => EdgeKind::Crease(Assignment::Mountain),
        _ => EdgeKind::Crease(Assignment::Valley),
    };
    let flipped = FoldingModel::new(builder.build().unwrap()).unwrap();
    assert_eq!(FlatFoldability::of(&flipped).maekawa_failures, vec![vertex]);
}

/// The many-vertex sweep with a locked crease against the single-vertex sweep (a second,
/// independent implementation) on the corner cube: flap crease 1 held flat, crease 0 driving.
#[test]
fn a_locked_sweep_agrees_with_the_single_vertex_sweep() {
    use nanofold::constraints::network::network_sweep;
    use nanofold::constraints::{sweep_samples, Setup};
    let path = Path::new("patterns/corner_cube.fold");
    let vertex = nanofold::read::load_pattern(path, &LoadOptions::default()).unwrap();
    let setup = Setup::new(&vertex, 0, &[(1, 0.0)]).unwrap();
    let mut model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    assert_eq!(model.crease_count(), vertex.creases.len());
    // Hold crease 1; start from one state of the single-vertex sweep (crease 1 at 0) and
    // sweep the whole range independently from there.
    model.locked_columns[1] = true;
    let (a, b) = (0.3, 3.0);
    let single = sweep_samples(&vertex, &setup, [a, b], 79).unwrap();
    let start = single.fold_angles[50].clone();
    assert_eq!(start[1], 0.0);
    let network = network_sweep(&model, &start, 0, [a, b], 40).unwrap();
    assert_eq!(network.driver_values.len(), 79);
    let mut worst: f64 = 0.0;
    for (k, (x, y)) in network.driver_values.iter().zip(&single.drive_angles).enumerate() {
        assert!((x - y).abs() < 1e-12);
        for c in 0..model.crease_count() {
            worst = worst.max((network.states[k][c] - single.fold_angles[k][c]).abs());
        }
    }
    assert!(worst < 1e-9, "largest difference {worst:e} rad");
}

/// The bird base's four petal points are symmetric flat-foldable degree-4 vertices (sectors
/// 67.5°, 112.5°, 112.5°, 67.5°), the same kind as a Miura-ori vertex with γ = 67.5°: along
/// any rigid folding the kites fold equally, the two midline creases equally and oppositely,
/// and tan(ρ_midline/2) = cos γ · tan(ρ_kite/2) (docs/model.md#pattern-generators). Checked on
/// every frame of the witness path that `check` finds.
#[test]
fn the_bird_base_folds_with_the_flat_foldable_vertex_closed_form() {
    use nanofold::folding::{check_pattern, CheckSettings, PatternVerdict};
    let path = Path::new("patterns/many/bird_base.fold");
    let model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    let report = check_pattern(&model, &CheckSettings::default()).unwrap();
    assert_eq!(report.verdict, PatternVerdict::RigidlyFoldable, "{}", report.evidence);
    let witness = report.witness.unwrap();
    let pattern = &model.pattern;
    let half = pattern.vertices.iter().map(|p| p[0].abs()).fold(0.0, f64::max);
    let petal_distance = (2.0 - 2f64.sqrt()) * half;
    let gamma = 67.5f64.to_radians();
    let mut petals = 0;
    for (v, p) in pattern.vertices.iter().enumerate() {
        let r = p[0].hypot(p[1]);
        if (r - petal_distance).abs() > 1e-9 || p[0].abs().min(p[1].abs()) > 1e-9 {
            continue;
        }
        petals += 1;
        // Its creases: the two on the midline (radial) and the two kites.
        let mut midline = Vec::new();
        let mut kites = Vec::new();
        // Fold angles are indexed by crease (column), not by edge.
        for (column, &e) in pattern.creases.iter().enumerate() {
            let [a, b] = pattern.edges[e];
            if a != v && b != v {
                continue;
            }
            let other = pattern.vertices[if a == v { b } else { a }];
            let cross = p[0] * other[1] - p[1] * other[0];
            if cross.abs() < 1e-9 {
                midline.push(column);
            } else {
                kites.push(column);
            }
        }
        assert_eq!((midline.len(), kites.len()), (2, 2), "petal point {v}");
        for step in witness.steps.iter().filter(|s| s.progress < 0.999) {
            let rho = &step.fold_angles;
            let (k0, k1) = (rho[kites[0]], rho[kites[1]]);
            let (m0, m1) = (rho[midline[0]], rho[midline[1]]);
            // Near flat a closure residual r pins the fold angles only to about r / |ρ|.
            let tol = 1e-9 + 10.0 * step.max_residual / m0.abs().min(k0.abs());
            assert!((k0 - k1).abs() < tol, "kites {k0} {k1}");
            assert!((m0 + m1).abs() < tol, "midline {m0} {m1}");
            // |tan(m/2)| = cos γ |tan(k/2)|, compared as angles: near flat-folded the tangents
            // grow without bound and amplify a fold angle's error by (1 + tan²)/2.
            let t = (k0 / 2.0).tan().abs();
            let expected = 2.0 * (gamma.cos() * t).atan();
            let slope = gamma.cos() * (1.0 + t * t) / (1.0 + (gamma.cos() * t).powi(2));
            assert!(
                (m0.abs() - expected).abs() < tol * (1.0 + slope),
                "petal point {v} at progress {}: {} against {expected}",
                step.progress,
                m0.abs()
            );
        }
    }
    assert_eq!(petals, 4);
    // And it reaches the flat-folded base: every crease at ±π in the last frame. The path
    // stops when the most folded crease is within 1e-9·π of π; at a flat-folded state the
    // others follow on square-root branches, so they lag by at most about √(1e-9·π).
    let last = witness.steps.last().unwrap();
    assert!(last.progress > 0.999, "{}", last.progress);
    let lag = (1e-9 * std::f64::consts::PI).sqrt();
    for (column, angle) in last.fold_angles.iter().enumerate() {
        assert!(
            (angle.abs() - std::f64::consts::PI).abs() < lag,
            "crease {column}: {angle}"
        );
    }
}

/// Flat-folded forms written by FOLD's own `fold-convert --flat-fold`
/// (tests/fixtures/fold-convert): read as their crease pattern (`vertices_flatUnfoldCoords`)
/// with every mountain and valley at ∓180°, each is a rigid state (its vertices flat-foldable).
/// The bird base, the Miura-ori and the package's diagonal unfold flat from it; the square
/// twist, not rigidly foldable (Evans et al. 2015), has no rigid motion out of it. A 2D folded
/// form without its crease pattern is refused by name.
#[test]
fn flat_folded_forms_from_fold_convert_are_read_as_their_crease_patterns() {
    use nanofold::folding::{check_pattern, CheckSettings, PatternVerdict};
    use nanofold::unfold::network::{unfold_network, NetworkUnfoldSettings};
    use nanofold::unfold::Verdict;
    let dir = Path::new("tests/fixtures/fold-convert");
    for (name, unfolds) in [
        ("bird_base", true),
        ("miura_4x4", true),
        ("square_twist", false),
        ("diagonal-cp", true),
    ] {
        let path = dir.join(format!("{name}-flat.fold"));
        let value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let model = FoldingModel::new(nanofold::read::load_crease_pattern(&path).unwrap()).unwrap();
        // The crease pattern is the unfolded coordinates, not the folded ones.
        let unfolded = value["vertices_flatUnfoldCoords"].as_array().unwrap();
        for (v, p) in model.pattern.file_vertices().iter().enumerate() {
            assert!(
                (p[0] - unfolded[v][0].as_f64().unwrap()).abs() < 1e-12,
                "{name}: vertex {v}"
            );
            assert!(
                (p[1] - unfolded[v][1].as_f64().unwrap()).abs() < 1e-12,
                "{name}: vertex {v}"
            );
        }
        let rho = model.given_fold_angles();
        assert!(
            rho.iter().all(|r| (r.abs() - std::f64::consts::PI).abs() < 1e-12),
            "{name}"
        );
        let report = check_pattern(&model, &CheckSettings::default()).unwrap();
        assert_eq!(report.verdict, PatternVerdict::Rigid, "{name}: {}", report.evidence);
        let unfolding = unfold_network(&model, &rho, &NetworkUnfoldSettings::default()).unwrap();
        if unfolds {
            assert_eq!(unfolding.verdict, Verdict::Flat, "{name}: {}", unfolding.evidence);
            assert_eq!(unfolding.crossings_refused, 0, "{name}");
        } else {
            assert_eq!(
                unfolding.verdict,
                Verdict::LocalMinimum,
                "{name}: {}",
                unfolding.evidence
            );
            assert_eq!(unfolding.iterations, 0, "{name}");
        }
    }
    // Without its crease pattern a 2D folded form cannot be read.
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("bird_base-flat.fold")).unwrap()).unwrap();
    value.as_object_mut().unwrap().remove("vertices_flatUnfoldCoords");
    let error = nanofold::read::parse_crease_pattern(&value.to_string(), "x", "test").unwrap_err();
    assert!(error.to_string().contains("vertices_flatUnfoldCoords"), "{error}");
}

/// Distance from p to segment [a, b].
fn point_segment(p: &nalgebra::Vector3<f64>, a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

/// Distance between two non-crossing triangles, the slow way: the least of every vertex
/// against the other triangle (its plane when the foot falls inside, else its edges) and
/// every edge pair, the latter by a fine scan of one edge against the other's distance.
fn triangle_gap(s: &[nalgebra::Vector3<f64>; 3], t: &[nalgebra::Vector3<f64>; 3]) -> f64 {
    let point_triangle = |p: &nalgebra::Vector3<f64>, tri: &[nalgebra::Vector3<f64>; 3]| {
        let normal = (tri[1] - tri[0]).cross(&(tri[2] - tri[0])).normalize();
        let foot = p - normal * (p - tri[0]).dot(&normal);
        let inside = (0..3).all(|k| {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            (b - a).cross(&(foot - a)).dot(&normal) >= 0.0
        });
        let edges = (0..3)
            .map(|k| point_segment(p, &tri[k], &tri[(k + 1) % 3]))
            .fold(f64::INFINITY, f64::min);
        if inside {
            (p - foot).norm().min(edges)
        } else {
            edges
        }
    };
    let mut best = f64::INFINITY;
    for p in s {
        best = best.min(point_triangle(p, t));
    }
    for p in t {
        best = best.min(point_triangle(p, s));
    }
    // Edge–edge: the distance from a point of one edge to the other is convex along the
    // edge; golden-section search finds its minimum.
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) = (s[i], s[(i + 1) % 3]);
            let (c, d) = (t[j], t[(j + 1) % 3]);
            let f = |u: f64| point_segment(&(a + (b - a) * u), &c, &d);
            let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
            for _ in 0..200 {
                let m1 = lo + (hi - lo) * 0.381_966;
                let m2 = hi - (hi - lo) * 0.381_966;
                if f(m1) <= f(m2) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            best = best.min(f(0.5 * (lo + hi)));
        }
    }
    best
}

/// The smallest clearance the contact test reports along a folding path is the least
/// distance over every pair of panels that share no vertex, found by brute force with a
/// separate triangle distance (the test prunes pairs that cannot lower it).
#[test]
fn the_smallest_panel_clearance_matches_a_brute_force_search() {
    let mut checked = 0;
    for (name, model) in [
        ("miura 6x6", miura(6, 6, 60.0, 0.0)),
        (
            "waterbomb 4x3",
            FoldingModel::new(
                nanofold::read::load_crease_pattern(Path::new("patterns/many/waterbomb_4x3.fold")).unwrap(),
            )
            .unwrap(),
        ),
    ] {
        let settings = nanofold::folding::FoldSettings {
            drive: nanofold::folding::Drive::Assignment { to: 90.0 },
            ..Default::default()
        };
        let path = nanofold::folding::fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        let last = path.steps.len() - 1;
        for step in [last / 3, 2 * last / 3, last] {
            let rho = &path.steps[step].fold_angles;
            let mut poses = Vec::new();
            panel_poses(&model, rho, &mut poses);
            let wide = ContactSettings {
                search: 2.0,
                ..ContactSettings::default()
            };
            let report = panel_contacts(&model, &poses, &wide);
            let placed: Vec<Vec<[nalgebra::Vector3<f64>; 3]>> = model
                .panel_triangles
                .iter()
                .enumerate()
                .map(|(p, list)| {
                    list.iter()
                        .map(|t| t.map(|v| poses[p].place(model.pattern.vertices[v])))
                        .collect()
                })
                .collect();
            let mut brute = f64::INFINITY;
            for a in 0..placed.len() {
                for b in a + 1..placed.len() {
                    if model.panel_vertices[a]
                        .iter()
                        .any(|v| model.panel_vertices[b].contains(v))
                    {
                        continue;
                    }
                    for s in &placed[a] {
                        for t in &placed[b] {
                            brute = brute.min(triangle_gap(s, t));
                        }
                    }
                }
            }
            assert!(report.crossing().next().is_none(), "{name} step {step}");
            // Inside the search range (half the search, 2, times the median panel width: the
            // smaller side of a panel's flat box), the smallest clearance is measured exactly.
            let mut widths: Vec<f64> = model
                .panel_vertices
                .iter()
                .map(|list| {
                    let side = |k: usize| {
                        let values = list.iter().map(|&v| model.pattern.vertices[v][k]);
                        values.clone().fold(f64::NEG_INFINITY, f64::max) - values.fold(f64::INFINITY, f64::min)
                    };
                    side(0).min(side(1))
                })
                .collect();
            widths.sort_by(f64::total_cmp);
            if brute < 0.5 * wide.search * widths[widths.len() / 2] {
                let found = report.min_clearance.expect("a pair within the search range");
                assert!(
                    (found - brute).abs() <= 1e-9 * model.size,
                    "{name} step {step}: contact test {found:e}, brute force {brute:e}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 3, "{checked} states compared");
}

/// The grid of `common::grid_fold` as a folding model.
fn grid_model(n: usize, jitter: f64) -> FoldingModel {
    let text = common::grid_fold(n, jitter, None).to_string();
    FoldingModel::new(nanofold::read::parse_crease_pattern(&text, "grid", "grid").unwrap()).unwrap()
}

/// The exact reductions before the rank count (ties merged, rows held by one crease
/// eliminated) leave the count the SVD of the whole J gives, flat and folded, on straight
/// lines (where they remove nearly everything) and on jittered ones (where a tie must not
/// be taken for one).
#[test]
fn the_reduced_rank_count_is_the_svds_count() {
    use nanofold::folding::RANK_TOL;
    let mut cases: Vec<(String, FoldingModel, Vec<f64>)> = Vec::new();
    for (n, zigzag) in [(6, 0.0), (8, 30.0), (10, 1e-6), (10, 5e-6), (12, 120.0), (7, 179.0)] {
        let model = miura(n, n, 60.0, zigzag);
        let rho = model.given_fold_angles();
        cases.push((format!("miura {n} at {zigzag}°"), model, rho));
    }
    for (n, jitter) in [(6, 0.0), (9, 0.0), (6, 1e-3), (6, 1e-12), (8, 0.2)] {
        let model = grid_model(n, jitter);
        let rho = model.given_fold_angles();
        cases.push((format!("grid {n} jitter {jitter}"), model, rho));
    }
    for name in ["square_twist", "waterbomb_4x3", "strips_crossing", "bird_base"] {
        let path = Path::new("patterns/many").join(format!("{name}.fold"));
        let Ok(pattern) = nanofold::read::load_crease_pattern(&path) else {
            continue;
        };
        let model = FoldingModel::new(pattern).unwrap();
        let rho = model.given_fold_angles();
        // Flat, and part-way along its assignment's path where there is one.
        let settings = nanofold::folding::FoldSettings {
            drive: nanofold::folding::Drive::Assignment { to: 30.0 },
            ..Default::default()
        };
        if let Ok(path) = nanofold::folding::fold_path(&model, &rho, &settings) {
            let folded = path.steps.last().unwrap().fold_angles.clone();
            cases.push((format!("{name} folded"), model.clone(), folded));
        }
        cases.push((name.into(), model, rho));
    }
    let mut reduced_somewhere = 0;
    for (name, model, rho) in cases {
        let jac = closure_jacobian(&model, &rho);
        let mut dense = nalgebra::DMatrix::<f64>::zeros(jac.rows, jac.cols);
        for &(r, c, v) in &jac.entries {
            dense[(r, c)] += v;
        }
        let largest_column = (0..jac.cols).map(|c| dense.column(c).norm()).fold(0.0, f64::max);
        let singular = if jac.rows == 0 {
            nalgebra::DVector::zeros(0)
        } else {
            dense.singular_values()
        };
        let threshold = RANK_TOL * largest_column;
        let svd_rank = singular.iter().filter(|&&s| s > threshold).count();
        let report = jacobian_rank(&jac).unwrap();
        assert_eq!(report.dof, jac.cols - jac.held - report.rank, "{name}: {report:?}");
        // Within a decade of the threshold the count depends on the method (the pivoted
        // QR's |R_ii| overestimate small singular values): there it must be the SVD's or
        // the unreduced QR's.
        let clear = singular.iter().all(|&s| s < 0.1 * threshold || s > 10.0 * threshold);
        if clear {
            assert_eq!(report.rank, svd_rank, "{name}: {report:?}");
        } else {
            let qr_rank = nanofold::folding::jacobian_rank_dense(&jac).rank;
            assert!(
                report.rank == svd_rank || report.rank == qr_rank,
                "{name}: {report:?}, SVD {svd_rank}, QR {qr_rank}"
            );
        }
        reduced_somewhere += usize::from(report.reduced > 0);
    }
    assert!(
        reduced_somewhere >= 10,
        "the reductions removed creases in {reduced_somewhere} cases"
    );
}

/// At the flat state every straight crease line of a grid, and every straight and zigzag
/// line of a Miura-ori, is a first-order motion of its own: 2 (n − 1) DOF, as many as
/// creases − 2 · interior vertices for any flat sheet of degree-4 vertices. The reductions
/// find them without a subspace iteration whose block would grow with the count.
#[test]
fn flat_sheets_with_hundreds_of_dof_are_counted_by_the_reductions() {
    // Jittered, no line is straight and nothing is tied: the creases at the boundary are
    // eliminated star by star, inwards.
    for (n, jitter) in [(60, 0.0), (150, 0.0), (150, 1e-3)] {
        let model = grid_model(n, jitter);
        let report = jacobian_rank(&closure_jacobian(&model, &model.given_fold_angles())).unwrap();
        assert_eq!(report.dof, 2 * (n - 1), "grid {n} jitter {jitter}: {report:?}");
        assert!(report.reduced > model.crease_count() / 2, "{report:?}");
    }
    let model = miura(100, 100, 60.0, 0.0);
    let report = jacobian_rank(&closure_jacobian(&model, &model.given_fold_angles())).unwrap();
    assert_eq!(report.dof, 2 * 99, "miura 100: {report:?}");
    assert!(report.reduced > model.crease_count() / 2, "{report:?}");
}

/// Frames placed on a continuation path (between its steps, by a cubic and a Newton
/// polish) are states of the Miura-ori's closed-form motion (`MiuraSpec` at the frame's
/// zigzag angle), at evenly spaced progress, rigid to 1e-10 rad, with every edge length of
/// the spanning tree's coordinates within 1e-12 of the crease pattern's.
#[test]
fn frames_between_steps_lie_on_the_miura_oris_closed_form_motion() {
    use nanofold::folding::path_frames;
    let (n, gamma) = (8, 60.0);
    let model = miura(n, n, gamma, 0.0);
    let path = path_to_90_percent(&model);
    // The last step lands on the goal (the crease that sets progress held there), and a
    // smooth one-DOF path takes few steps.
    let end = path.steps.last().unwrap().progress;
    assert!((end - 1.0).abs() < 1e-12, "the path ends at progress {end}");
    assert!(path.steps.len() <= 21, "{} steps", path.steps.len() - 1);
    let count = 41;
    assert!(
        path.steps.len() < count,
        "{} steps: frames must fall between them",
        path.steps.len()
    );
    let frames = path_frames(&model, &path, count).unwrap();
    assert_eq!(frames.len(), count);
    let refused = path_frames(&model, &path, 1).unwrap_err().to_string();
    assert!(refused.contains("frames") && refused.contains('1'), "{refused}");
    // Zigzag creases: those the closed form folds to its zigzag angle.
    let reference = miura(n, n, gamma, 30.0).given_fold_angles();
    let zigzag = (0..reference.len())
        .find(|&c| (reference[c].abs() - 30f64.to_radians()).abs() < 1e-12)
        .unwrap();
    let pattern = &model.pattern;
    let length =
        |p: [f64; 3], q: [f64; 3]| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
    let mut poses = Vec::new();
    for (k, frame) in frames.iter().enumerate() {
        let target = frames[0].progress + (1.0 - frames[0].progress) * k as f64 / (count - 1) as f64;
        assert!(
            (frame.progress - target).abs() < 1e-9,
            "frame {k}: {} for {target}",
            frame.progress
        );
        let worst = vertex_residuals(&model, &frame.fold_angles)
            .into_iter()
            .fold(0.0, f64::max);
        assert!(worst <= 1e-10, "frame {k}: closure {worst:e}");
        let z = frame.fold_angles[zigzag].abs().to_degrees();
        if z > 1e-3 {
            let exact = miura(n, n, gamma, z).given_fold_angles();
            let gap = exact
                .iter()
                .zip(&frame.fold_angles)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(gap < 1e-8, "frame {k} (zigzag {z}°): {gap:e} from the closed form");
        }
        panel_poses(&model, &frame.fold_angles, &mut poses);
        let placed = vertex_positions(&model, &poses);
        for &[a, b] in &pattern.edges {
            let flat = {
                let (p, q) = (pattern.vertices[a], pattern.vertices[b]);
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
            };
            let error = (length(placed[a], placed[b]) - flat).abs() / flat;
            assert!(error <= 1e-12, "frame {k}: edge {a}-{b} off by {error:e}");
        }
    }
}

/// At 100 × 100 the spanning tree is about 100 panels deep, so a closure residual r at each
/// vertex moves the far panels by about 100·r of the sheet's size: 101 frames polished only
/// to 1e-14 rad put edge lengths 3.6e-12 off. Polished as far as rounding allows, every edge
/// of every frame holds to 1e-12 relative.
#[test]
fn frames_of_a_100_by_100_miura_ori_hold_every_edge_to_1e_12() {
    use nanofold::folding::path_frames;
    let model = miura(100, 100, 60.0, 0.0);
    let path = path_to_90_percent(&model);
    let frames = path_frames(&model, &path, 101).unwrap();
    let pattern = &model.pattern;
    let mut poses = Vec::new();
    let mut worst_edge: f64 = 0.0;
    for frame in &frames {
        panel_poses(&model, &frame.fold_angles, &mut poses);
        let placed = vertex_positions(&model, &poses);
        for &[a, b] in &pattern.edges {
            let (p, q) = (pattern.vertices[a], pattern.vertices[b]);
            let flat = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
            let folded = (0..3)
                .map(|k| (placed[a][k] - placed[b][k]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst_edge = worst_edge.max((folded - flat).abs() / flat);
        }
    }
    assert!(worst_edge <= 1e-12, "worst relative edge error {worst_edge:e}");
}

/// The residual a chord step recomputes is the Jacobian's residual to the last bit (the same
/// products), at flat, folded and off-manifold states.
#[test]
fn the_residual_alone_equals_the_jacobians_residual() {
    use nanofold::folding::{closure_residual, worst_of};
    let model = miura(6, 5, 60.0, 40.0);
    let folded = model.given_fold_angles();
    let mut residual = Vec::new();
    for shift in [0.0, 1e-3, 0.2] {
        let rho: Vec<f64> = folded
            .iter()
            .enumerate()
            .map(|(k, r)| r + shift * ((k as f64) * 0.7).sin())
            .collect();
        let jac = closure_jacobian(&model, &rho);
        closure_residual(&model, &rho, &mut residual);
        assert_eq!(residual, jac.residual, "shift {shift}");
        assert_eq!(worst_of(&residual), jac.worst_residual());
        if shift > 0.0 {
            assert!(worst_of(&residual) > 0.0);
        }
    }
}

/// The normal equations' solve, checked by its own residual: x from (JᵀJ + μI) x = b gives
/// back b through J and Jᵀ to a backward error of 1e-14, for a small pattern (faer's simplicial Cholesky) and one past
/// the size where the supernodal one takes over, at a folded state.
#[test]
fn the_normal_equations_are_solved_at_either_factorisation() {
    use nanofold::folding::NormalSolver;
    for n in [8, 40] {
        let model = miura(n, n, 60.0, 50.0);
        let jac = closure_jacobian(&model, &model.given_fold_angles());
        let mut solver = NormalSolver::new(1e-10);
        let factor = solver.factor(&jac).unwrap();
        let b: Vec<f64> = (0..jac.cols).map(|k| ((k as f64) * 0.37).sin()).collect();
        let mut x = b.clone();
        factor.solve(&mut x);
        let mut jx = vec![0.0; jac.rows];
        jac.apply(&x, &mut jx);
        let mut back = vec![0.0; jac.cols];
        jac.apply_transpose(&jx, &mut back);
        let worst = back
            .iter()
            .zip(&x)
            .zip(&b)
            .map(|((a, x), b)| (a + factor.mu * x - b).abs())
            .fold(0.0, f64::max);
        // Backward error: JᵀJ + μI is as ill-conditioned as μ is small, so x is large along
        // J's null space and the residual is measured against ‖A‖‖x‖ + ‖b‖.
        let largest = |v: &[f64]| v.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
        let scale = factor.max_diagonal * largest(&x) + largest(&b);
        assert!(
            worst <= 1e-14 * scale,
            "n = {n} ({} creases): residual {worst:e} against {scale:e}",
            jac.cols
        );
    }
}

/// Frames are independent: placed on several threads (runs of consecutive frames, each with
/// its own factorisation workspace) they are the frames placed one at a time, bit for bit.
#[test]
fn frames_on_several_threads_are_the_frames_placed_one_at_a_time() {
    use nanofold::folding::path_frames_on;
    let model = miura(12, 12, 60.0, 0.0);
    let path = path_to_90_percent(&model);
    let alone = path_frames_on(&model, &path, 23, 1).unwrap();
    for threads in [2, 3, 23, 40] {
        assert_eq!(
            path_frames_on(&model, &path, 23, threads).unwrap(),
            alone,
            "{threads} threads"
        );
    }
    let refused = path_frames_on(&model, &path, 23, 0).unwrap_err().to_string();
    assert!(refused.contains("threads") && refused.contains('0'), "{refused}");
}

/// Frames placed while the path goes on are the frames placed on the finished path, bit
/// for bit: on a path that reaches its goal (frames placed early, then shared), on one cut
/// short by its step budget (the early ones dropped, all placed on its own end), and on a
/// small pattern (one thread, path first).
#[test]
fn frames_placed_during_the_path_are_the_frames_placed_after_it() {
    use nanofold::folding::{fold_path, fold_path_and_frames, path_frames, Drive, FoldSettings, StopReason};
    let large = miura(18, 18, 60.0, 0.0);
    assert!(
        large.crease_count() >= 500,
        "{} creases: not the threaded case",
        large.crease_count()
    );
    let small = miura(4, 4, 60.0, 0.0);
    let reach = FoldSettings {
        drive: Drive::Assignment { to: 90.0 },
        ..Default::default()
    };
    let cut = FoldSettings {
        max_steps: 6,
        ..reach.clone()
    };
    for (model, settings, stop) in [
        (&large, &reach, StopReason::Reached),
        (&large, &cut, StopReason::StepLimit),
        (&small, &reach, StopReason::Reached),
    ] {
        let start = model.given_fold_angles();
        for count in [2, 11, 40] {
            let (path, frames) = fold_path_and_frames(model, &start, settings, count).unwrap();
            assert_eq!(path.stop, stop);
            let alone = fold_path(model, &start, settings).unwrap();
            assert_eq!(path, alone);
            assert_eq!(frames, path_frames(model, &alone, count).unwrap(), "{count} frames");
        }
    }
    let refused = fold_path_and_frames(&small, &small.given_fold_angles(), &reach, 1)
        .unwrap_err()
        .to_string();
    assert!(refused.contains("frames") && refused.contains('1'), "{refused}");
}

/// The export above with Gaussian noise of `sigma` on every coordinate (seeded), turned
/// about a tilted axis and moved when `turned`.
fn noisy_export(text: &str, sigma: f64, turned: bool, seed: u64) -> String {
    let mut file: serde_json::Value = serde_json::from_str(text).unwrap();
    let mut state = seed;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gauss = move || (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
    let turn = nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(nalgebra::Vector3::new(0.3, -0.5, 0.8)),
        0.9,
    );
    let coords: Vec<[f64; 3]> = serde_json::from_value(file["vertices_coords"].clone()).unwrap();
    let moved: Vec<[f64; 3]> = coords
        .iter()
        .map(|p| {
            let mut q = nalgebra::Vector3::new(p[0], p[1], p[2]);
            if turned {
                q = turn * q + nalgebra::Vector3::new(12.0, -7.0, 3.0);
            }
            [q.x + sigma * gauss(), q.y + sigma * gauss(), q.z + sigma * gauss()]
        })
        .collect();
    file["vertices_coords"] = serde_json::json!(moved);
    file.to_string()
}

/// A compliant simulator's export off rigid within its noise (1e-4) is moved, when read, onto
/// the nearest rigid folded form: every vertex closes and every facet is flat again, the
/// Miura-ori keeps its one degree of freedom (its vertices kept flat-foldable) and unfolds
/// flat, and the move is reported; turned and moved in space, the same. Beyond the bound
/// the form stays as read and `check` says `not_rigid`, naming the bound.
#[test]
fn a_noisy_folded_form_is_moved_onto_the_nearest_rigid_form_when_read() {
    use nanofold::commands::{check, unfold, CheckVerdict, Pattern, Settings};
    use nanofold::folding::PatternVerdict;
    let model = miura(3, 4, 65.0, 110.0);
    let rho = model.given_fold_angles();
    let clean = simulator_export(&model, &rho, 0.0, false);
    for (sigma, turned, seed) in [(3e-6, false, 7), (3e-6, true, 11), (1e-5, false, 13)] {
        let text = noisy_export(&clean, sigma, turned, seed);
        let pattern = Pattern::parse(&text, "noisy", "test", &LoadOptions::default()).unwrap();
        let projection = pattern.projection().unwrap_or_else(|| panic!("σ {sigma:e}: not moved"));
        let figures = &projection.figures;
        assert_eq!(figures.moved, "vertex_positions");
        // Noise σ per coordinate: a vertex moves by a few σ, the angles by a few σ / edge.
        assert!(figures.max_vertex_move.unwrap() < 20.0 * sigma, "{}", projection.note);
        assert!(figures.residual_before_rad > 1e-6, "{}", projection.note);
        let sheet = pattern.sheet().unwrap();
        let worst = nanofold::folding::vertex_residuals(sheet, &sheet.given_fold_angles())
            .into_iter()
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "closure {worst:e} after the move");
        let near = sheet
            .given_fold_angles()
            .iter()
            .zip(&rho)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(near < 1e-3, "σ {sigma:e}: {near:e} rad from the clean state");
        let report = check(&pattern, &Settings::default()).unwrap();
        assert_eq!(
            report.verdict,
            CheckVerdict::Pattern(PatternVerdict::Rigid),
            "{}",
            report.evidence
        );
        assert!(
            report.evidence.contains("1 DOF at the given state") || report.evidence.contains("(1 DOF"),
            "{}",
            report.evidence
        );
        let unfolded = unfold(&pattern, &Settings::default()).unwrap();
        assert_eq!(
            unfolded.verdict,
            nanofold::commands::UnfoldVerdict::Flat,
            "{}",
            unfolded.evidence
        );
    }
    let far = noisy_export(&clean, 1e-3, true, 5);
    let pattern = Pattern::parse(&far, "far", "test", &LoadOptions::default()).unwrap();
    assert!(pattern.projection().is_none());
    let report = check(&pattern, &Settings::default()).unwrap();
    assert_eq!(
        report.verdict,
        CheckVerdict::Pattern(PatternVerdict::NotRigid),
        "{}",
        report.evidence
    );
    assert!(report.evidence.contains("beyond the 1e-4"), "{}", report.evidence);
}

/// The worst relative edge-length error of a state's 3D placement (panels posed along the
/// spanning tree, every vertex placed once): a check of rigidity apart from the closures.
fn worst_edge_error(model: &FoldingModel, fold_angles: &[f64]) -> f64 {
    let mut poses = Vec::new();
    panel_poses(model, fold_angles, &mut poses);
    let placed = vertex_positions(model, &poses);
    let pattern = &model.pattern;
    pattern.edges.iter().fold(0.0_f64, |worst, &[a, b]| {
        let (p, q) = (pattern.vertices[a], pattern.vertices[b]);
        let flat = (p[0] - q[0]).hypot(p[1] - q[1]);
        let folded = (0..3)
            .map(|k| (placed[a][k] - placed[b][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst.max((folded - flat).abs() / flat)
    })
}

/// `fold --drive-to-targets` on a Miura-ori whose targets are a rigid state (its own folded
/// state, 110° zigzags) folds from flat onto it to 1e-9 rad; every frame holds its edges
/// and closures to 1e-9 and keeps the assigned signs; `to: 50` stops with the furthest
/// crease halfway. Targets no rigid state meets (every crease at half its angle but one)
/// stop at the rigid state nearest them on the path, naming the furthest crease and the
/// vertex the targets leave open.
#[test]
fn a_targets_drive_folds_a_miura_ori_onto_its_rigid_state_or_stops_nearest() {
    use nanofold::commands::{fold_run, FoldOptions, Pattern};
    use nanofold::folding::{fold_path, Drive, FoldSettings, StopReason};
    let folded = miura(3, 4, 65.0, 110.0);
    let targets = folded.given_fold_angles();
    let pattern = Pattern::from_crease_pattern(folded.pattern.clone()).unwrap();
    let options = FoldOptions {
        drive_to_targets: Some(true),
        frames: 21,
        ..FoldOptions::default()
    };
    let run = fold_run(&pattern, &options).unwrap();
    assert_eq!(run.report.start_fold_angles_rad, vec![0.0; targets.len()]);
    let end = &run.report.final_fold_angles_rad;
    let off = end.iter().zip(&targets).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(off < 1e-9, "{off:e} rad from the targets: {}", run.report.evidence);
    for frame in &run.frames {
        let closure = nanofold::folding::vertex_residuals(&folded, &frame.fold_angles)
            .into_iter()
            .fold(0.0, f64::max);
        assert!(closure < 1e-9 && worst_edge_error(&folded, &frame.fold_angles) < 1e-9);
        assert!(frame.fold_angles.iter().zip(&targets).all(|(a, t)| a * t >= 0.0));
    }
    let halfway = fold_run(
        &pattern,
        &FoldOptions {
            to: 50.0,
            ..options.clone()
        },
    )
    .unwrap();
    let span = targets.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
    let left = halfway
        .report
        .final_fold_angles_rad
        .iter()
        .zip(&targets)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!((left / span - 0.5).abs() < 1e-9, "{left} of {span} left");

    let mut off_targets: Vec<f64> = targets.iter().map(|t| 0.5 * t).collect();
    off_targets[0] = targets[0];
    let settings = FoldSettings {
        drive: Drive::Targets {
            targets: off_targets.clone(),
            to: 100.0,
        },
        ..FoldSettings::default()
    };
    let flat = vec![0.0; targets.len()];
    let path = fold_path(&folded, &flat, &settings).unwrap();
    let StopReason::Nearest { crease, vertex } = path.stop.clone() else {
        panic!("{:?}: {}", path.stop, path.evidence);
    };
    let open = nanofold::folding::vertex_residuals(&folded, &off_targets);
    let worst = (0..open.len()).max_by(|&a, &b| open[a].total_cmp(&open[b])).unwrap();
    assert_eq!(vertex, Some(folded.stars[worst].vertex));
    let last = &path.steps.last().unwrap().fold_angles;
    let furthest = (0..last.len())
        .max_by(|&a, &b| {
            (off_targets[a] - last[a])
                .abs()
                .total_cmp(&(off_targets[b] - last[b]).abs())
        })
        .unwrap();
    assert_eq!(crease, furthest);
    assert!(
        path.evidence
            .contains(&format!("leave vertex {} open", folded.stars[worst].vertex)),
        "{}",
        path.evidence
    );
    // Stationary: the distance to the targets grows both ways along the one motion.
    let distance = |rho: &[f64]| off_targets.iter().zip(rho).map(|(t, r)| (t - r).powi(2)).sum::<f64>();
    let steps = &path.steps;
    assert!(distance(last) <= distance(&steps[steps.len() - 2].fold_angles));
    // Bad targets are refused by name: one per crease, signs as assigned.
    let mut wrong_sign = targets.clone();
    wrong_sign[3] = -wrong_sign[3];
    for (bad, field) in [(vec![0.1; 3], "drive.targets"), (wrong_sign, "drive.targets[3]")] {
        let settings = FoldSettings {
            drive: Drive::Targets {
                targets: bad,
                to: 100.0,
            },
            ..FoldSettings::default()
        };
        let error = fold_path(&folded, &flat, &settings).unwrap_err().to_string();
        assert!(error.contains(field), "{error}");
    }
}

/// `drive_to_targets` with named creases, or asked of a flat sheet that gives no targets, is
/// refused by name, before any folding.
#[test]
fn drive_to_targets_is_refused_by_name_where_it_cannot_apply() {
    use nanofold::commands::{fold_run, FoldOptions, Pattern};
    let folded = miura(3, 4, 65.0, 110.0);
    let pattern = Pattern::from_crease_pattern(folded.pattern.clone()).unwrap();
    let edge = folded.pattern.creases[0];
    let both = FoldOptions {
        drive: [(edge, 10.0_f64.copysign(folded.given_fold_angles()[0]))]
            .into_iter()
            .collect(),
        drive_to_targets: Some(true),
        ..FoldOptions::default()
    };
    let Err(error) = fold_run(&pattern, &both) else {
        panic!("named creases and targets together were accepted")
    };
    let error = error.to_string();
    assert!(
        error.contains("drive_to_targets") && error.contains("not both"),
        "{error}"
    );
    let flat = Pattern::from_crease_pattern(miura(3, 4, 65.0, 0.0).pattern.clone()).unwrap();
    let none = FoldOptions {
        drive_to_targets: Some(true),
        ..FoldOptions::default()
    };
    let Err(error) = fold_run(&flat, &none) else {
        panic!("targets asked of a flat sheet without any were accepted")
    };
    let error = error.to_string();
    assert!(
        error.contains("drive_to_targets") && error.contains("no target angles"),
        "{error}"
    );
}

/// A Miura-ori's full fold ends at a flat-folded state, a singular goal where landing on it
/// (the furthest crease held at ±π, Newton on the rest) fails: it gives up early and is not
/// retried from every step, the secant on progress approaching instead. A 30 × 30 sheet
/// reaches its goal with at most 110 factorisations, where a landing retried at each step
/// took 153.
#[test]
fn a_flat_folded_goal_is_reached_without_repeated_landings() {
    use nanofold::folding::{fold_path, Drive, FoldSettings, StopReason};
    let model = miura(30, 30, 60.0, 0.0);
    let settings = FoldSettings {
        drive: Drive::Assignment { to: 100.0 },
        ..Default::default()
    };
    let path = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
    assert_eq!(path.stop, StopReason::Reached, "{}", path.evidence);
    let last = path.steps.last().unwrap();
    assert!(last.progress > 1.0 - 1e-9, "{}", last.progress);
    assert!(path.max_closure_residual < 1e-9, "{}", path.max_closure_residual);
    assert!(path.factorisations <= 110, "{} factorisations", path.factorisations);
}
