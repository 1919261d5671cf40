//! Hard cases of SPEC §9, each with its stated expectation (issue 6; more to come): Σα near
//! 2π, tiny sectors, n = 64 and 256, a degree-12 fit exported in degrees, plates touching at
//! the first step. Others live beside the feature they stress: the exactly flat-folded input
//! and sectors ≥ 360° in bad_input.rs, the locked pattern in library.rs, the 10⁹ stiffness
//! ratio in dynamics.rs and closed_chain.rs (the etch ramps).

mod common;
use common::native_json;
use nanofold::pattern::{LoadOptions, Pattern};
use nanofold::unfold::{unfold, UnfoldSettings, Verdict};
use std::f64::consts::TAU;

/// A closed vertex with the given sectors (rad), every crease at `fold` rad.
fn vertex(sectors: &[f64], fold: f64) -> String {
    native_json(sectors, &vec![fold; sectors.len()])
}

fn load(text: &str) -> nanofold::Result<Pattern> {
    Pattern::from_str(text, "hard", "hard", &LoadOptions::default())
}

#[test]
fn angle_sum_within_1e9_of_a_full_turn_is_rescaled_and_just_above_it_is_a_cone() {
    // Expectation: |Σα − 2π| ≤ tolerance → rescaled to 2π exactly and reported; 1e-6 above →
    // loads, verdict not_flat_foldable, nothing NaN.
    let near = [1.0, 2.0, 1.5, TAU - 4.5 + 1e-9];
    let pattern = load(&vertex(&near, 0.0)).unwrap();
    assert!(pattern.flat_foldable);
    assert!((pattern.sector_angles.iter().sum::<f64>() - TAU).abs() < 1e-14);
    assert!(
        pattern.adjustments.iter().any(|a| a.contains("rescaled")),
        "{:?}",
        pattern.adjustments
    );
    assert_eq!(
        unfold(&pattern, &UnfoldSettings::default()).unwrap().verdict,
        Verdict::Flat
    );

    let above = [1.0, 2.0, 1.5, TAU - 4.5 + 1e-6];
    let cone = load(&vertex(&above, 0.0)).unwrap();
    assert!(!cone.flat_foldable);
    let report = unfold(&cone, &UnfoldSettings::default()).unwrap();
    assert_eq!(report.verdict, Verdict::NotFlatFoldable);
    assert!(report.final_fold_angles_rad.iter().all(|r| r.is_finite()));
}

#[test]
fn tiny_sectors_and_many_creases_load_and_stay_finite() {
    // Expectation: a 1e-4 rad sector and n = 64, 256 creases load; a flat input is flat at once.
    let tiny = [1e-4, 2.0, 2.0, TAU - 4.0 - 1e-4];
    let pattern = load(&vertex(&tiny, 0.0)).unwrap();
    assert_eq!(
        unfold(&pattern, &UnfoldSettings::default()).unwrap().verdict,
        Verdict::Flat
    );
    for n in [64, 256] {
        let sectors = vec![TAU / n as f64; n];
        let pattern = load(&vertex(&sectors, 0.0)).unwrap();
        assert_eq!(pattern.creases.len(), n);
        let report = unfold(&pattern, &UnfoldSettings::default()).unwrap();
        assert_eq!(report.verdict, Verdict::Flat, "n = {n}: {}", report.evidence);
        assert!(report
            .final_fold_angles_rad
            .iter()
            .all(|r| r.is_finite() && r.abs() <= 1e-12));
    }
}

#[test]
fn a_degree_twelve_fit_exported_in_degrees_on_0_to_180_stays_accurate() {
    // Expectation: the fit itself is Chebyshev (well conditioned), and the exported monomial
    // coefficients in degrees, where t¹² reaches 180¹² ≈ 1.2e27, are finite and reproduce
    // the exact samples in degrees to within the stated fit error plus 1e-12 rad of rounding
    // (measured: the same as the radian form to 3e-16 rad; fit error 6e-8 rad).
    use nanofold::constraints::chebyshev::eval_monomial;
    use nanofold::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, Setup};
    let pattern = Pattern::load(
        std::path::Path::new("patterns/corner_cube.fold"),
        &LoadOptions::default(),
    )
    .unwrap();
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    let samples = sweep_samples(&pattern, &setup, [0.0, std::f64::consts::PI], 181).unwrap();
    let poly = ConstraintPoly::fit(&pattern, &samples, 12).unwrap();
    let report = ConstraintReport::new(&pattern, &samples, &poly).unwrap();
    for (curve, &c) in report.curves.iter().zip(&setup.dependents) {
        assert!(curve.coeffs_deg.iter().all(|k| k.is_finite()));
        let mut worst: f64 = 0.0;
        for (theta, angles) in samples.drive_angles.iter().zip(&samples.fold_angles) {
            let in_degrees = eval_monomial(&curve.coeffs_deg, theta.to_degrees());
            worst = worst.max((in_degrees - angles[c].to_degrees()).abs().to_radians());
        }
        assert!(
            worst <= curve.max_fit_error_rad + 1e-12,
            "{}: {worst:e} rad in degrees vs stated {:e}",
            curve.label,
            curve.max_fit_error_rad
        );
    }
}

#[test]
fn plates_touching_at_the_first_step_stop_the_run_at_once() {
    // Expectation: corner cube step 2 started at its end (crease 1 at 90°, so the doubled flap
    // already lies folded flat on the third square, crease 4 at −180°) reports that contact at
    // t = 0 with zero steps and finite angles, for the dynamic and the quasi-static model.
    use nanofold::dynamics::closed::simulate_closed;
    use nanofold::dynamics::simulate::{ModelChoice, SimulationSettings};
    use nanofold::scene::closed::ClosedScene;
    let text = std::fs::read_to_string("patterns/corner_cube_step2.scene.json").unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["start_angle_deg"] = serde_json::json!(90);
    value["hinges"][1]["target_angle_deg"] = serde_json::json!(60);
    value["constraint"]["range_deg"] = serde_json::json!([0, 90]);
    let scene = ClosedScene::from_json(&value.to_string(), "test", "test", std::path::Path::new("patterns")).unwrap();
    for model in [ModelChoice::Dynamic, ModelChoice::QuasiStatic] {
        let settings = SimulationSettings {
            model,
            ..SimulationSettings::default()
        };
        let response = simulate_closed(&scene, &settings).unwrap();
        let contact = response.collision.as_ref().expect("touching at t = 0");
        assert_eq!(contact.time, 0.0, "{model:?}");
        assert!(contact.pair[0].starts_with("edges[4]"), "{model:?}: {:?}", contact.pair);
        assert!(response.samples.iter().all(|s| s.angles.iter().all(|a| a.is_finite())));
        if model == ModelChoice::Dynamic {
            assert_eq!(response.steps, 0);
        }
    }
}
