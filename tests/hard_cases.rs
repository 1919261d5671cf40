//! Hard cases of SPEC §9, each with its stated expectation (issue 6; more to come). Others
//! live beside the feature they stress: the exactly flat-folded input and sectors ≥ 360° in
//! bad_input.rs, the locked pattern in library.rs, the 10⁹ stiffness ratio in dynamics.rs.

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
