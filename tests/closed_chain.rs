//! Closed-chain dynamics (issue 5): the exact constraint against a closed form, its
//! derivatives against finite differences, energy conservation of the reduced equations, and
//! bad closed-chain scenes.

use nanofold::constraints::exact::{ConstraintPoint, ExactConstraint};
use nanofold::constraints::{sweep_samples, Setup};
use nanofold::dynamics::closed::simulate_closed;
use nanofold::dynamics::simulate::{Method, ModelChoice, SimulationSettings};
use nanofold::pattern::{LoadOptions, Pattern};
use nanofold::scene::closed::ClosedScene;
use std::path::Path;

fn degree4() -> Pattern {
    Pattern::load(Path::new("patterns/degree4_generic.fold"), &LoadOptions::default()).unwrap()
}

/// A 4R spherical linkage (degree-4 vertex): the diagonal between the driver's neighbours
/// seen from both sides (spherical cosine rule, interior angle π − |ρ|) gives
///   cos ρ_opp = (cos α₊₁ cos α₊₂ − cos α₋₁ cos α₀ + sin α₋₁ sin α₀ cos ρ) / (sin α₊₁ sin α₊₂).
#[test]
fn exact_matches_the_four_bar_closed_form() {
    let pattern = degree4();
    let setup = Setup::new(&pattern, 0, &[]).unwrap();
    let domain = [0.0, pattern.creases[0].folded_angle];
    let samples = sweep_samples(&pattern, &setup, domain, 41).unwrap();
    let exact = ExactConstraint::new(&pattern, &samples);
    let alpha = |k: usize| pattern.sector_angles[k % 4];
    let k = pattern.creases[0].ray;
    let (before, after, far1, far2) = (alpha(k + 3), alpha(k), alpha(k + 1), alpha(k + 2));
    let opposite = setup
        .dependents
        .iter()
        .position(|&c| pattern.creases[c].ray == (k + 2) % 4)
        .unwrap();
    let mut point = ConstraintPoint::zeros(3);
    let mut worst: f64 = 0.0;
    let mut worst_slope: f64 = 0.0;
    for i in 0..=997 {
        let rho = domain[0] + (domain[1] - domain[0]) * i as f64 / 997.0;
        exact.evaluate(rho, &mut point).unwrap();
        let formula = (far1.cos() * far2.cos() - before.cos() * after.cos() + before.sin() * after.sin() * rho.cos())
            / (far1.sin() * far2.sin());
        let value = point.values[opposite];
        worst = worst.max((value.cos() - formula).abs());
        // Where sin ρ_opp is not small, the closed form's derivative too.
        if value.sin().abs() > 0.1 {
            let slope = before.sin() * after.sin() * rho.sin() / (far1.sin() * far2.sin() * value.sin());
            worst_slope = worst_slope.max((point.jacobian[opposite] - slope).abs());
        }
    }
    assert!(worst < 1e-12, "cos ρ_opp off by {worst:e}");
    // At flat (singular: G is extrapolated there) the closed form's expansion to second order
    // gives |G_opp(0)| = √(sin α₋₁ sin α₀ / (sin α₊₁ sin α₊₂)). Measured: 5e-8; the closure
    // solves at δ = 1e-4 from the singular point carry errors amplified by 1/σ_min ≈ 1e4.
    exact.evaluate(0.0, &mut point).unwrap();
    let flat_slope = (before.sin() * after.sin() / (far1.sin() * far2.sin())).sqrt();
    assert!(
        (point.jacobian[opposite].abs() - flat_slope).abs() < 1e-7,
        "G(0) {} vs {flat_slope}",
        point.jacobian[opposite]
    );
    assert!(worst_slope < 1e-10, "G off by {worst_slope:e}");
}

/// G and f″ from the implicit function theorem against central differences of exact f and G,
/// near the flat (singular) end too.
#[test]
fn exact_derivatives_match_finite_differences() {
    let pattern = degree4();
    let setup = Setup::new(&pattern, 0, &[]).unwrap();
    let domain = [0.0, pattern.creases[0].folded_angle];
    let samples = sweep_samples(&pattern, &setup, domain, 41).unwrap();
    let exact = ExactConstraint::new(&pattern, &samples);
    let at = |x: f64| {
        let mut p = ConstraintPoint::zeros(3);
        exact.evaluate(x, &mut p).unwrap();
        p
    };
    let h = 1e-5;
    for x in [2e-3, 0.3, 1.0, 1.7, domain[1] - 2e-3] {
        let (minus, mid, plus) = (at(x - h), at(x), at(x + h));
        for k in 0..3 {
            let slope = (plus.values[k] - minus.values[k]) / (2.0 * h);
            let curvature = (plus.jacobian[k] - minus.jacobian[k]) / (2.0 * h);
            assert!(
                (mid.jacobian[k] - slope).abs() < 1e-8,
                "G at {x}: {} vs {slope}",
                mid.jacobian[k]
            );
            assert!(
                (mid.curvature[k] - curvature).abs() < 1e-6 * (1.0 + curvature.abs()),
                "f'' at {x}: {} vs {curvature}",
                mid.curvature[k]
            );
        }
    }
}

fn step1_scene(edit: impl Fn(&mut serde_json::Value)) -> nanofold::error::Result<ClosedScene> {
    let text = std::fs::read_to_string("patterns/corner_cube_step1.scene.json").unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    edit(&mut value);
    ClosedScene::from_json(&value.to_string(), "test", "test", Path::new("patterns"))
}

/// Without drag a step's total energy (kinetic + elastic + −τθ) is conserved by the reduced
/// equations, whichever source gives f (each conserves its own constrained energy).
#[test]
fn reduced_dynamics_conserve_energy_without_drag() {
    for source in [
        serde_json::json!({"source": "exact", "range_deg": [-5, 180]}),
        serde_json::json!({"source": "poly", "degree": 8, "range_deg": [-5, 180]}),
    ] {
        let scene = step1_scene(|v| {
            v["environment"]["drag"] = serde_json::json!(false);
            v["constraint"] = source.clone();
        })
        .unwrap();
        let settings = SimulationSettings {
            model: ModelChoice::Dynamic,
            method: Method::Tsit45,
            rtol: 1e-10,
            t_end: Some(2.5e-5),
            ..SimulationSettings::default()
        };
        let response = simulate_closed(&scene, &settings).unwrap();
        assert!(response.collision.is_none(), "{:?}", response.collision);
        let scale = response.samples.iter().map(|s| s.kinetic_energy).fold(0.0, f64::max);
        assert!(scale > 0.0);
        let drift = response
            .samples
            .iter()
            .map(|s| s.total_energy().abs())
            .fold(0.0, f64::max);
        assert!(
            drift < 1e-6 * scale,
            "{source}: energy drift {drift:e} J vs kinetic {scale:e} J"
        );
        // And the fold has moved a good part of the way.
        assert!(response.samples.last().unwrap().angles[0] > 1.0);
    }
}

#[test]
fn the_corner_cube_folds_in_two_steps() {
    let settings = SimulationSettings::default();
    let one = ClosedScene::load(Path::new("patterns/corner_cube_step1.scene.json")).unwrap();
    let first = simulate_closed(&one, &settings).unwrap();
    let c = first.collision.as_ref().expect("the flap halves close");
    assert!(c.pair[0].starts_with("edges[0]"), "{:?}", c.pair);
    let end = first.samples.last().unwrap();
    // The cube corner: creases 2 and 3 at 90°, crease 4 at −90°.
    for (k, want) in [(2, 90.0), (3, 90.0), (4, -90.0)] {
        assert!(
            (end.angles[k].to_degrees() - want).abs() < 0.01,
            "crease {k}: {}",
            end.angles[k].to_degrees()
        );
    }
    let two = ClosedScene::load(Path::new("patterns/corner_cube_step2.scene.json")).unwrap();
    let second = simulate_closed(&two, &settings).unwrap();
    let c = second.collision.as_ref().expect("the flap lands on the third square");
    assert!(c.pair[0].starts_with("edges[4]"), "{:?}", c.pair);
    let end = second.samples.last().unwrap();
    assert!((end.angles[1].to_degrees() - 90.0).abs() < 1e-5);
}

#[test]
fn bad_closed_scenes_name_the_problem() {
    let cut_actuated = step1_scene(|v| v["cut_crease"] = serde_json::json!(0))
        .unwrap_err()
        .to_string();
    assert!(
        cut_actuated.contains("cut_crease") && cut_actuated.contains("actuated"),
        "{cut_actuated}"
    );
    let rigid =
        step1_scene(|v| v["locks"] = serde_json::json!([{"crease": 1, "angle_deg": 0}, {"crease": 3, "angle_deg": 0}]))
            .unwrap_err()
            .to_string();
    assert!(
        rigid.contains("locks") && rigid.contains("0 degree(s) of freedom"),
        "{rigid}"
    );
    let no_degree = step1_scene(|v| v["constraint"] = serde_json::json!({"source": "poly"}))
        .unwrap_err()
        .to_string();
    assert!(no_degree.contains("constraint.degree"), "{no_degree}");
    // A start outside the fitted range is refused, not extrapolated silently.
    let outside = step1_scene(|v| v["start_angle_deg"] = serde_json::json!(-30))
        .unwrap_err()
        .to_string();
    assert!(outside.contains("start_angle_deg"), "{outside}");
}
