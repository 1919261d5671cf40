//! The pattern library: expected verdicts, residuals and outputs (regression).

use nanofold::pattern::{LoadOptions, VertexPattern};
use nanofold::unfold::{unfold, UnfoldSettings, Verdict};
use std::path::Path;

fn run(name: &str) -> (VertexPattern, nanofold::unfold::UnfoldReport) {
    let pattern = nanofold::read::load_pattern(&Path::new("patterns").join(name), &LoadOptions::default()).unwrap();
    let report = unfold(&pattern, &UnfoldSettings::default()).unwrap();
    (pattern, report)
}

#[test]
fn every_library_pattern_gets_its_expected_verdict() {
    let expected = [
        ("half_paper.fold", Verdict::Flat),
        ("corner_cube.fold", Verdict::Flat),
        ("waterbomb.fold", Verdict::Flat),
        ("degree4_generic.fold", Verdict::Flat),
        ("miura_vertex.fold", Verdict::Flat),
        ("degree6_asymmetric.fold", Verdict::Flat),
        ("sheet_corner.fold", Verdict::Flat),
        ("degree4_locked.fold", Verdict::Locked),
        ("degree4_native.json", Verdict::Flat),
        ("cone.json", Verdict::NotFlatFoldable),
        // The line search stalls ~2e-6 rad from flat; Newton onto ρ = 0 finishes it.
        ("symmetric16.fold", Verdict::Flat),
    ];
    for (name, verdict) in expected {
        let (pattern, report) = run(name);
        assert_eq!(report.verdict, verdict, "{name}: {}", report.evidence);
        assert_eq!(report.final_fold_angles_rad.len(), pattern.creases.len());
        assert!(
            report.max_arc_residual <= 1e-10,
            "{name}: arc residual {:e}",
            report.max_arc_residual
        );
        for step in &report.trajectory {
            assert!(
                step.energy.is_finite() && step.fold_angles.iter().all(|r| r.is_finite()),
                "{name}: non-finite step"
            );
        }
        if verdict == Verdict::Flat {
            let worst = report.final_fold_angles_rad.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            assert!(worst <= 1e-6, "{name}: flat with |ρ| = {worst:e}");
            // The end state is the exact flat layout (nodes at cumulative sector angles on
            // the equator, built independently from the sector angles) to 1e-8 (issue 2);
            // with the Newton finish it is held to the restoration tolerance, 1e-13 per arc.
            assert!(
                report.flat_layout_error <= 1e-8,
                "{name}: layout error {:e} vs |ρ| {worst:e}",
                report.flat_layout_error
            );
            assert!(report.planarity_residual <= 1e-8);
            assert!(report.energy_final < report.energy_initial);
        }
    }
}

#[test]
fn corner_cube_final_state_reaches_the_exact_flat_layout_closely() {
    // The separable energy's flat state is its minimum (`docs/model.md#energy`): at the end every node sits
    // at its cumulative sector angle on the equator.
    let (_, report) = run("corner_cube.fold");
    let layout = [0.0_f64, 45.0, 135.0, 225.0, 315.0];
    for (node, phi) in report.final_nodes.iter().zip(layout) {
        let phi = phi.to_radians();
        assert!((node.x - phi.cos()).abs() < 1e-10 && (node.y - phi.sin()).abs() < 1e-10 && node.z.abs() < 1e-10);
    }
}

#[test]
fn locked_pattern_keeps_its_folded_state() {
    let (pattern, report) = run("degree4_locked.fold");
    assert_eq!(report.iterations, 0);
    for (c, rho) in pattern.creases.iter().zip(&report.final_fold_angles_rad) {
        assert!((c.folded_angle - rho).abs() < 1e-9);
    }
}
