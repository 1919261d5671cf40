//! Energy unfolding of crease patterns with many vertices, against independent answers:
//! finite differences, the single-vertex engine's energy and verdicts, and the Miura-ori's
//! closed form along the path.

use nanofold::folding::{vertex_residuals, FoldingModel};
use nanofold::pattern::generate::MiuraSpec;
use nanofold::pattern::LoadOptions;
use nanofold::unfold::network::{unfold_network, NetworkEnergy, NetworkUnfoldSettings};
use nanofold::unfold::{unfold, UnfoldSettings, Verdict};
use nanofold::unfold::{EnergyKind, EnergyWorkspace};
use std::path::Path;

fn miura(n: usize, zigzag_deg: f64) -> FoldingModel {
    let spec = MiuraSpec {
        rows: n,
        cols: n,
        zigzag_fold_angle: zigzag_deg.to_radians(),
        ..MiuraSpec::default()
    };
    FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap()
}

#[test]
fn the_summed_energy_gradient_matches_central_differences() {
    for kind in [EnergyKind::Separable, EnergyKind::NonSeparable] {
        let model = miura(3, 110.0);
        let energy = NetworkEnergy::new(&model, kind, None);
        let rho: Vec<f64> = model
            .given_fold_angles()
            .iter()
            .enumerate()
            .map(|(k, r)| r * (1.0 + 0.05 * ((k as f64) * 0.7).sin()))
            .collect();
        let mut ws = EnergyWorkspace::default();
        let mut gradient = vec![0.0; rho.len()];
        let u = energy.value_and_gradient(&rho, &mut ws, &mut gradient);
        assert!((u - energy.value(&rho, &mut ws)).abs() <= 1e-12 * u);
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for c in 0..rho.len() {
            let (mut plus, mut minus) = (rho.clone(), rho.clone());
            plus[c] += h;
            minus[c] -= h;
            let numeric = (energy.value(&plus, &mut ws) - energy.value(&minus, &mut ws)) / (2.0 * h);
            worst = worst.max((numeric - gradient[c]).abs() / (1.0 + gradient[c].abs()));
        }
        assert!(worst < 1e-6, "{kind:?}: {worst:e}");
    }
}

/// Every closed single vertex of the library: the many-vertex energy at its state is the
/// single-vertex engine's, and it gets that engine's verdict (flat, or locked for the vertex
/// whose locked crease leaves no motion).
#[test]
fn single_vertices_get_the_single_vertex_engines_energy_and_verdict() {
    let mut checked = 0;
    for entry in std::fs::read_dir("patterns").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("fold") {
            continue;
        }
        let Ok(vertex) = nanofold::read::load_pattern(&path, &LoadOptions::default()) else {
            continue;
        };
        let model = FoldingModel::new(nanofold::read::load_crease_pattern(&path).unwrap()).unwrap();
        if model.stars.len() != 1 {
            continue;
        }
        let single = unfold(&vertex, &UnfoldSettings::default()).unwrap();
        let energy = NetworkEnergy::new(&model, EnergyKind::Separable, None);
        let u = energy.value(&model.given_fold_angles(), &mut EnergyWorkspace::default());
        let name = path.display().to_string();
        assert!(
            (u - single.energy_initial).abs() <= 1e-9 * single.energy_initial,
            "{name}: {u} vs {}",
            single.energy_initial
        );
        let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
        assert!(
            matches!(single.verdict, Verdict::Flat | Verdict::Locked),
            "{name}: {:?}",
            single.verdict
        );
        assert_eq!(report.verdict, single.verdict, "{name}: {}", report.evidence);
        assert!(report.max_closure_residual <= 1e-10, "{name}");
        checked += 1;
    }
    assert!(checked >= 5, "{checked}");
}

#[test]
fn a_folded_miura_ori_unfolds_flat_along_its_closed_form() {
    let model = miura(6, 150.0);
    let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    assert!(report.max_closure_residual <= 1e-10);
    // Every state on the path is a Miura state (the path never leaves the branch), and the
    // energy falls at every step.
    let zigzag = (0..model.crease_count())
        .find(|&c| {
            let [a, b] = model.pattern.edges[model.pattern.creases[c]];
            (model.pattern.vertices[a][0] - model.pattern.vertices[b][0]).abs() < 0.99
        })
        .unwrap();
    for pair in report.steps.windows(2) {
        assert!(pair[1].energy <= pair[0].energy);
    }
    // Within 0.01 rad of flat the comparison loses its meaning: the flat state is singular,
    // so a closure residual r allows angle errors of order √r along the branch.
    for step in report.steps.iter().filter(|s| s.fold_angles[zigzag].abs() > 0.01) {
        let expected = miura(6, step.fold_angles[zigzag].abs().to_degrees()).given_fold_angles();
        let error = step
            .fold_angles
            .iter()
            .zip(&expected)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(error < 1e-9, "{error:e}");
    }
    for step in &report.steps {
        assert!(
            vertex_residuals(&model, &step.fold_angles)
                .into_iter()
                .fold(0.0, f64::max)
                <= 1e-10
        );
    }
    assert!(Path::new("patterns").exists());
}

/// A small fixed pseudo-random generator (the suite must not depend on the run).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

/// Random Miura-ori variants (size, angle, panel sides) folded by `fold` to random depths
/// from flat, then unfolded by energy: every one flat, every state closed along the way, no
/// step refused for crossing panels.
#[test]
fn random_miura_states_folded_by_fold_unfold_flat() {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    let mut seed = 0x5EED_u64;
    for case in 0..12 {
        let rows = 2 + (uniform(&mut seed) * 6.0) as usize;
        let cols = 2 + (uniform(&mut seed) * 6.0) as usize;
        let spec = MiuraSpec {
            rows,
            cols,
            sector_angle: (35.0 + 50.0 * uniform(&mut seed)).to_radians(),
            width: 0.5 + uniform(&mut seed),
            slant: 0.5 + uniform(&mut seed),
            ..MiuraSpec::default()
        };
        let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let depth = 0.1 + 0.85 * uniform(&mut seed);
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 100.0 * depth },
            ..FoldSettings::default()
        };
        let folded = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        let start = folded.steps.last().unwrap().fold_angles.clone();
        let report = unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap();
        let name = format!(
            "case {case}: {rows}x{cols}, γ {:.1}°, depth {depth:.2}",
            spec.sector_angle.to_degrees()
        );
        assert_eq!(report.verdict, Verdict::Flat, "{name}: {}", report.evidence);
        assert!(report.max_closure_residual <= 1e-10, "{name}");
        assert_eq!(report.crossings_refused, 0, "{name}");
        for step in &report.steps {
            assert!(
                vertex_residuals(&model, &step.fold_angles)
                    .into_iter()
                    .fold(0.0, f64::max)
                    <= 1e-10,
                "{name}"
            );
        }
    }
}

/// Hard cases: a start at the flat state, a start next to it (a branch point), a pattern
/// with a tiny panel, and a pattern with no degree of freedom.
#[test]
fn hard_starts_get_their_verdicts() {
    // At flat: nothing to do.
    let model = miura(4, 0.0);
    let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!((report.verdict, report.iterations), (Verdict::Flat, 0));
    // One degree from flat, beside the branch point: flat without leaving the branch.
    let model = miura(4, 1.0);
    let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    for step in &report.steps {
        let signs_kept = step
            .fold_angles
            .iter()
            .zip(&model.given_fold_angles())
            .all(|(now, then)| now * then >= 0.0);
        assert!(signs_kept, "a crease passed through flat");
    }
    // A tiny panel: slanted sides 1e-3 of the horizontal ones.
    let spec = MiuraSpec {
        rows: 3,
        cols: 3,
        slant: 1e-3,
        zigzag_fold_angle: 120f64.to_radians(),
        ..MiuraSpec::default()
    };
    let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
    let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    assert!(report.max_closure_residual <= 1e-10);
    // No degree of freedom: the library's locked single vertex.
    let path = Path::new("patterns/degree4_locked.fold");
    let model = FoldingModel::new(nanofold::read::load_crease_pattern(path).unwrap()).unwrap();
    let report = unfold_network(&model, &model.given_fold_angles(), &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Locked, "{}", report.evidence);
}

/// Waterbomb tessellations (square cells and the Huffman-style rectangular cells) and the bird
/// base, folded from flat by `fold` to part of the way, unfold to flat: many degrees of
/// freedom and degree-6 vertices, where minor creases change sign on the way and the last
/// stretch runs along the ray to flat. Every recorded state closes and no panels cross.
#[test]
fn waterbombs_and_the_bird_base_folded_by_fold_unfold_flat() {
    use nanofold::folding::{fold_path, panel_contacts, panel_poses, ContactSettings, Drive, FoldSettings};
    use nanofold::pattern::generate::{BirdBaseSpec, WaterbombSpec};
    let cases = [
        (
            "waterbomb 4x3",
            WaterbombSpec {
                rows: 4,
                cols: 3,
                row_height: 1.0,
            }
            .build()
            .unwrap(),
            0.4,
        ),
        (
            "waterbomb 6x4, rows 0.6",
            WaterbombSpec {
                rows: 6,
                cols: 4,
                row_height: 0.6,
            }
            .build()
            .unwrap(),
            0.3,
        ),
        ("bird base", BirdBaseSpec::default().build().unwrap(), 0.5),
    ];
    for (name, builder, depth) in cases {
        let model = FoldingModel::new(builder.build().unwrap()).unwrap();
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 100.0 * depth },
            ..FoldSettings::default()
        };
        let folded = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        let start = folded.steps.last().unwrap().fold_angles.clone();
        let largest = start.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
        assert!(largest > 0.3, "{name}: folded only to {largest}");
        let report = unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap();
        assert_eq!(report.verdict, Verdict::Flat, "{name}: {}", report.evidence);
        assert!(report.max_closure_residual <= 1e-10, "{name}");
        let mut poses = Vec::new();
        let contact = ContactSettings::default();
        for step in &report.steps {
            let worst = vertex_residuals(&model, &step.fold_angles)
                .into_iter()
                .fold(0.0, f64::max);
            assert!(worst <= 1e-10, "{name}: {worst:e}");
            panel_poses(&model, &step.fold_angles, &mut poses);
            assert_eq!(panel_contacts(&model, &poses, &contact).crossing().count(), 0, "{name}");
        }
        assert!(report.steps.last().unwrap().fold_angles.iter().all(|&r| r == 0.0));
    }
}

/// Three unit strips side by side; the outer two folded (valley) about x = 1 and x = 2. Folded
/// by α and β their far edges sit at x = 1 − cos α and x = 2 + cos β, both at height sin.
fn three_strips(alpha: f64, beta: f64) -> FoldingModel {
    use nanofold::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind};
    use nanofold::pattern::Assignment;
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
    for (edge, angle) in [([1, 6], alpha), ([2, 5], beta)] {
        edges.push(edge);
        kinds.push(EdgeKind::Crease(Assignment::Valley));
        fold_angles.push(angle);
    }
    let builder = CreasePatternBuilder {
        name: "three_strips".into(),
        vertices,
        edges,
        kinds,
        fold_angles,
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    FoldingModel::new(builder.build().unwrap()).unwrap()
}

/// The barrier b(x) = −(x − 1)² ln x: zero with zero slope and curvature at x = 1 (C²),
/// unbounded as x → 0; and its gradient in fold angles, through the panels' poses, equals
/// central differences of its value.
#[test]
fn the_panel_barrier_is_c2_and_its_gradient_matches_central_differences() {
    use nanofold::folding::panel_poses;
    use nanofold::unfold::{barrier_function, BarrierSettings, PanelBarrier};
    assert_eq!(barrier_function(1.0), (0.0, 0.0));
    for h in [1e-2, 1e-3, 1e-4] {
        let (value, slope) = barrier_function(1.0 - h);
        // b ≈ h³ and b′ ≈ −3h² near 1: curvature b″ ≈ 6h → 0.
        assert!(value > 0.0 && value < 2.0 * h * h * h, "{h}: {value}");
        assert!(slope < 0.0 && slope.abs() < 4.0 * h * h, "{h}: {slope}");
    }
    assert!(barrier_function(1e-12).0 > 20.0);
    // Far edges about 0.0075 apart, within d̂ = 0.01 (1% of the unit panels).
    let model = three_strips(119.8f64.to_radians(), 119.7f64.to_radians());
    let barrier = PanelBarrier::new(&model, &BarrierSettings::default()).unwrap();
    assert!((barrier.activation() - 0.01).abs() < 1e-12);
    let rho = model.given_fold_angles();
    let mut poses = Vec::new();
    let value_at = |rho: &[f64], poses: &mut Vec<_>| {
        panel_poses(&model, rho, poses);
        let mut scratch = vec![0.0; rho.len()];
        barrier.value_and_gradient(&model, poses, &mut scratch)
    };
    panel_poses(&model, &rho, &mut poses);
    let mut gradient = vec![0.0; rho.len()];
    let value = barrier.value_and_gradient(&model, &poses, &mut gradient);
    assert!(value > 0.0, "{value}");
    for c in 0..rho.len() {
        let h = 1e-7;
        let (mut up, mut down) = (rho.clone(), rho.clone());
        up[c] += h;
        down[c] -= h;
        let numeric = (value_at(&up, &mut poses) - value_at(&down, &mut poses)) / (2.0 * h);
        assert!(
            (numeric - gradient[c]).abs() <= 1e-5 * gradient[c].abs().max(1e-3),
            "column {c}: analytic {} numeric {numeric}",
            gradient[c]
        );
    }
}

/// A hard case: two panels that share no vertex start 1e-6 apart. The descent (the strips'
/// creases meet no interior vertex, so their own opening energy drives them) unfolds them
/// flat along a rigid path on which the gap never closes and no step crosses; the barrier's
/// first push is what moves them apart at the start.
#[test]
fn panels_a_micrometre_apart_unfold_without_touching() {
    use nanofold::folding::{panel_contacts, panel_poses, ContactSettings};
    // Far edges at x = 1 − cos α and 2 + cos α: 1 + 2 cos α = 1e-6 apart.
    let alpha = (-0.5 + 0.5e-6f64).acos();
    let model = three_strips(alpha, alpha);
    let contact = ContactSettings {
        search: 1.0,
        ..ContactSettings::default()
    };
    let clearance = |rho: &[f64]| {
        let mut poses = Vec::new();
        panel_poses(&model, rho, &mut poses);
        panel_contacts(&model, &poses, &contact).min_clearance
    };
    let start = model.given_fold_angles();
    let first = clearance(&start).unwrap();
    assert!((first - 1e-6).abs() < 1e-9, "{first}");
    let report = unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    assert_eq!(report.crossings_refused, 0);
    let mut previous = 0.0;
    for step in &report.steps {
        // Beyond the search range the pair is not measured: the gap is then larger.
        let now = clearance(&step.fold_angles).unwrap_or(f64::INFINITY);
        assert!(now >= previous - 1e-12, "clearance fell from {previous} to {now}");
        previous = now;
    }
    // The first step already widened the gap past the barrier's reach (d̂ = 0.01).
    let second = clearance(&report.steps[1].fold_angles).unwrap_or(f64::INFINITY);
    assert!(second > 1e-4, "{second}");
}

/// Random Huffman-style waterbombs (rows, columns and row height drawn), folded by `fold`
/// along their assignment to a random depth (or until panels block), unfold flat: every
/// recorded state closes within 1e-10 rad and no step crosses panels.
#[test]
fn random_waterbomb_states_folded_by_fold_unfold_flat() {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    use nanofold::pattern::generate::WaterbombSpec;
    let mut seed = 0x3A7E_u64;
    for case in 0..10 {
        let spec = WaterbombSpec {
            rows: 2 + (uniform(&mut seed) * 5.0) as usize,
            cols: 1 + (uniform(&mut seed) * 4.0) as usize,
            row_height: 0.5 + uniform(&mut seed),
        };
        let model = FoldingModel::new(spec.build().unwrap().build().unwrap()).unwrap();
        let depth = 0.1 + 0.4 * uniform(&mut seed);
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 100.0 * depth },
            ..FoldSettings::default()
        };
        let folded = fold_path(&model, &model.given_fold_angles(), &settings).unwrap();
        let start = folded.steps.last().unwrap().fold_angles.clone();
        let name = format!(
            "case {case}: {} x {}, rows {:.2} high, depth {depth:.2}, reached {:.2}",
            spec.rows,
            spec.cols,
            spec.row_height,
            folded.steps.last().unwrap().progress
        );
        let report = unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap();
        assert_eq!(report.verdict, Verdict::Flat, "{name}: {}", report.evidence);
        assert_eq!(report.crossings_refused, 0, "{name}");
        for step in &report.steps {
            let worst = vertex_residuals(&model, &step.fold_angles)
                .into_iter()
                .fold(0.0, f64::max);
            assert!(worst <= 1e-10, "{name}: {worst:e}");
        }
    }
}

/// A restart: one crease across a sheet folded to exactly 180° sits where its own energy's
/// gradient (sin ρ) vanishes, a stationary point that is no minimum. A kick along the rigid
/// motions (one way puts the panels through each other, the other opens them) starts the
/// descent again, and it ends flat with the restart counted.
#[test]
fn a_stationary_start_is_left_by_a_restart() {
    use nanofold::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind};
    use nanofold::pattern::Assignment;
    let builder = CreasePatternBuilder {
        name: "one_crease".into(),
        vertices: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [0.0, 1.0]],
        edges: vec![[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0], [1, 4]],
        kinds: vec![
            EdgeKind::Boundary,
            EdgeKind::Boundary,
            EdgeKind::Boundary,
            EdgeKind::Boundary,
            EdgeKind::Boundary,
            EdgeKind::Boundary,
            EdgeKind::Crease(Assignment::Valley),
        ],
        fold_angles: vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, std::f64::consts::PI],
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    let model = FoldingModel::new(builder.build().unwrap()).unwrap();
    let start = model.given_fold_angles();
    let report = unfold_network(&model, &start, &NetworkUnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    assert_eq!(report.restarts_used, 1);
    let without = unfold_network(
        &model,
        &start,
        &NetworkUnfoldSettings {
            restarts: 0,
            ..NetworkUnfoldSettings::default()
        },
    )
    .unwrap();
    assert_eq!(without.verdict, Verdict::LocalMinimum);
    assert!(without.evidence.contains("0 restarts tried"), "{}", without.evidence);
}

/// Random trapezoidal Miura-ori (a sector angle per zigzag line, so the panels are
/// trapezoids, not parallelograms): rigidly foldable quad meshes beyond the Miura-ori. The
/// generator's closed-form state closes every vertex; `fold` from flat follows the closed
/// form (one straight fold angle for every horizontal crease, tan(ρ_z,j/2) = tan(ρ_h/2)/cos γ_j
/// on line j) at every frame; and the folded state unfolds flat.
#[test]
fn random_trapezoidal_miura_quad_meshes_fold_by_the_closed_form_and_unfold_flat() {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    let mut seed = 0x7A9E_u64;
    for case in 0..8 {
        let rows = 2 + (uniform(&mut seed) * 4.0) as usize;
        let cols = 2 + (uniform(&mut seed) * 4.0) as usize;
        let spec = MiuraSpec {
            rows,
            cols,
            sector_angle: 60f64.to_radians(),
            width: 1.5,
            slant: 1.0,
            zigzag_fold_angle: (40.0 + 100.0 * uniform(&mut seed)).to_radians(),
        };
        let angles: Vec<f64> = (0..=cols)
            .map(|_| (45.0 + 30.0 * uniform(&mut seed)).to_radians())
            .collect();
        let name = format!(
            "case {case}: {rows}x{cols}, γ_j {:?}°",
            angles.iter().map(|g| g.to_degrees().round()).collect::<Vec<_>>()
        );
        let model = FoldingModel::new(spec.build_with_column_angles(&angles).unwrap().build().unwrap()).unwrap();
        // The closed-form state closes every vertex.
        let state = model.given_fold_angles();
        let worst = vertex_residuals(&model, &state).into_iter().fold(0.0, f64::max);
        assert!(worst < 1e-12, "{name}: closed form residual {worst:e}");
        // Which creases are horizontal, and each zigzag crease's line.
        let line_of = |c: usize| {
            let [a, b] = model.pattern.edges[model.pattern.creases[c]];
            let (pa, pb) = (model.pattern.vertices[a], model.pattern.vertices[b]);
            ((pa[1] - pb[1]).abs() > 1e-9).then(|| a % (cols + 1))
        };
        // Fold from flat (the crease pattern alone) along the assignment.
        let flat = model.with_fold_angles(&vec![0.0; state.len()]);
        let settings = FoldSettings {
            drive: Drive::Assignment { to: 60.0 },
            ..FoldSettings::default()
        };
        let path = fold_path(&flat, &flat.given_fold_angles(), &settings).unwrap();
        for step in path.steps.iter().filter(|s| s.progress > 0.05) {
            let rho = &step.fold_angles;
            let straight: Vec<f64> = (0..rho.len())
                .filter(|&c| line_of(c).is_none())
                .map(|c| rho[c].abs())
                .collect();
            let rho_h = straight[0];
            assert!(
                straight.iter().all(|r| (r - rho_h).abs() < 1e-9),
                "{name}: straight creases differ"
            );
            for c in (0..rho.len()).filter(|&c| line_of(c).is_some()) {
                let gamma = angles[line_of(c).unwrap()];
                let expected = 2.0 * ((rho_h / 2.0).tan() / gamma.cos()).atan();
                assert!(
                    (rho[c].abs() - expected).abs() < 1e-9,
                    "{name}: zigzag {c} {} vs {expected}",
                    rho[c]
                );
            }
        }
        let start = path.steps.last().unwrap().fold_angles.clone();
        let report = unfold_network(&flat, &start, &NetworkUnfoldSettings::default()).unwrap();
        assert_eq!(report.verdict, Verdict::Flat, "{name}: {}", report.evidence);
        assert!(report.max_closure_residual <= 1e-10, "{name}");
        assert_eq!(report.crossings_refused, 0, "{name}");
    }
}

/// New inputs refused by name: the barrier's settings, a trapezoidal Miura-ori's column
/// angles, and a flat-folded form whose crease pattern has the wrong number of vertices.
#[test]
fn new_inputs_are_refused_by_name() {
    use nanofold::unfold::{BarrierSettings, PanelBarrier};
    let model = miura(3, 100.0);
    for (settings, field) in [
        (
            BarrierSettings {
                activation: 0.0,
                stiffness: 1.0,
            },
            "barrier.activation",
        ),
        (
            BarrierSettings {
                activation: f64::NAN,
                stiffness: 1.0,
            },
            "barrier.activation",
        ),
        (
            BarrierSettings {
                activation: 0.01,
                stiffness: -1.0,
            },
            "barrier.stiffness",
        ),
    ] {
        let error = PanelBarrier::new(&model, &settings).err().expect("refused");
        assert!(error.to_string().contains(field), "{error}");
    }
    let spec = MiuraSpec::default();
    let error = spec.build_with_column_angles(&[1.0; 3]).unwrap_err();
    assert!(error.to_string().contains("column_angles"), "{error}");
    let mut angles = vec![60f64.to_radians(); spec.cols + 1];
    angles[2] = 95f64.to_radians();
    let error = spec.build_with_column_angles(&angles).unwrap_err();
    assert!(error.to_string().contains("column_angles[2]"), "{error}");
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("tests/fixtures/fold-convert/bird_base-flat.fold").unwrap())
            .unwrap();
    value["vertices_flatUnfoldCoords"].as_array_mut().unwrap().pop();
    let error = nanofold::read::parse_crease_pattern(&value.to_string(), "x", "test").unwrap_err();
    assert!(error.to_string().contains("vertices_flatUnfoldCoords"), "{error}");
}

/// The descent is an argmin solver: the progress observer the single vertex takes is told of
/// every iteration, with the state each step left; driven by a bare loop over
/// `NetworkDescent::iterate` it takes the same steps as under argmin's executor.
#[test]
fn the_descent_under_argmin_reports_every_step_to_the_shared_observer() {
    use nanofold::folding::{fold_path, Drive, FoldSettings};
    use nanofold::unfold::network::{start_descent, unfold_network_observed, NetworkStart};
    use nanofold::unfold::UnfoldProgress;
    use std::sync::{Arc, Mutex};
    let model = miura(4, 60.0);
    let fold = FoldSettings {
        drive: Drive::Assignment { to: 80.0 },
        ..FoldSettings::default()
    };
    let start = fold_path(&model, &model.given_fold_angles(), &fold)
        .unwrap()
        .steps
        .last()
        .unwrap()
        .fold_angles
        .clone();
    let settings = NetworkUnfoldSettings::default();
    let told = Arc::new(Mutex::new(Vec::new()));
    let seen = told.clone();
    let progress = UnfoldProgress(Arc::new(move |step, largest, energy| {
        seen.lock().unwrap().push((step, largest, energy));
    }));
    let report = unfold_network_observed(&model, &start, &settings, Some(progress)).unwrap();
    assert_eq!(report.verdict, Verdict::Flat, "{}", report.evidence);
    assert_eq!(report.restarts_used, 0);
    let told = told.lock().unwrap().clone();
    // One call per iteration, the stopping one included.
    assert_eq!(told.len(), report.iterations + 1);
    for (k, &(step, largest, energy)) in told.iter().enumerate() {
        assert_eq!(step, k + 1);
        if k < report.iterations {
            let after = &report.steps[k + 1];
            let expected = after.fold_angles.iter().fold(0.0_f64, |m, r| m.max(r.abs()));
            assert_eq!((largest, energy), (expected, after.energy), "iteration {k}");
        }
    }
    // The same descent, driven by hand.
    let NetworkStart::Descent(mut descent) = start_descent(&model, &start, &settings).unwrap() else {
        panic!("a folded Miura-ori is not decided at its start");
    };
    let mut iteration = 0;
    let by_hand = loop {
        if let Some(stop) = descent.iterate(iteration).unwrap() {
            break descent.finish(stop, iteration);
        }
        iteration += 1;
    };
    assert_eq!(by_hand, report);
    // A start that is not one fold angle per crease is refused by name, by either way in.
    let short = &start[1..];
    for refused in [
        unfold_network_observed(&model, short, &settings, None).err(),
        start_descent(&model, short, &settings).err(),
    ] {
        let message = refused.expect("a short start is refused").to_string();
        assert!(
            message.contains("start") && message.contains("one per crease"),
            "{message}"
        );
    }
}

/// An accordion of `n` unit strips side by side, crease i folded by `angles[i]` (valley
/// positive).
fn accordion(angles: &[f64]) -> FoldingModel {
    use nanofold::pattern::crease_pattern::{CreasePatternBuilder, EdgeKind};
    use nanofold::pattern::Assignment;
    let n = angles.len() + 1;
    let mut vertices: Vec<[f64; 2]> = (0..=n).map(|i| [i as f64, 0.0]).collect();
    vertices.extend((0..=n).map(|i| [i as f64, 1.0]));
    let (mut edges, mut kinds, mut fold_angles) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        edges.extend([[i, i + 1], [n + 1 + i, n + 2 + i]]);
        kinds.extend([EdgeKind::Boundary; 2]);
        fold_angles.extend([0.0; 2]);
    }
    for i in 0..=n {
        edges.push([i, n + 1 + i]);
        let crease = i > 0 && i < n;
        let angle = if crease { angles[i - 1] } else { 0.0 };
        kinds.push(match (crease, angle > 0.0) {
            (false, _) => EdgeKind::Boundary,
            (true, true) => EdgeKind::Crease(Assignment::Valley),
            (true, false) => EdgeKind::Crease(Assignment::Mountain),
        });
        fold_angles.push(angle);
    }
    let builder = CreasePatternBuilder {
        name: "accordion".into(),
        vertices,
        edges,
        kinds,
        fold_angles,
        angle_field: "edges_foldAngle".into(),
        ..Default::default()
    };
    FoldingModel::new(builder.build().unwrap()).unwrap()
}

/// The barrier's gradient is summed up the tree of panels (each panel's force and moment
/// over its subtree): on an accordion of eight strips folded to ±179.8°, where every layer
/// presses on the layer two away, through paths up to seven creases deep, it equals
/// central differences of the barrier's value in every fold angle.
#[test]
fn the_barrier_gradient_through_deep_paths_matches_central_differences() {
    use nanofold::folding::panel_poses;
    use nanofold::unfold::{BarrierSettings, PanelBarrier};
    let angles: Vec<f64> = (0..7)
        .map(|i| if i % 2 == 0 { 179.8f64 } else { -179.8 }.to_radians())
        .collect();
    let model = accordion(&angles);
    let barrier = PanelBarrier::new(&model, &BarrierSettings::default()).unwrap();
    let rho = model.given_fold_angles();
    let mut poses = Vec::new();
    let mut value_at = |rho: &[f64]| {
        panel_poses(&model, rho, &mut poses);
        let mut gradient = vec![0.0; rho.len()];
        let value = barrier.value_and_gradient(&model, &poses, &mut gradient);
        (value, gradient)
    };
    let (value, gradient) = value_at(&rho);
    assert!(value > 0.0 && value.is_finite(), "{value}");
    assert!(gradient.iter().filter(|g| g.abs() > 1e-6).count() >= 5, "{gradient:?}");
    for c in 0..rho.len() {
        let h = 1e-7;
        let (mut up, mut down) = (rho.clone(), rho.clone());
        up[c] += h;
        down[c] -= h;
        let numeric = (value_at(&up).0 - value_at(&down).0) / (2.0 * h);
        assert!(
            (numeric - gradient[c]).abs() <= 1e-5 * gradient[c].abs().max(1e-3),
            "column {c}: analytic {} numeric {numeric}",
            gradient[c]
        );
    }
}
