//! Open-chain dynamics (`docs/model.md#dynamics`) against independent answers: closed forms for one hinged
//! plate, kinetic energy from the plates' own motion, energy balance, the quasi-static limit,
//! contact times from plane geometry.

use nalgebra::{DVector, Vector3};
mod common;

use common::{scene_file, scene_text};
use nanofold::dynamics::algorithms::{kinetic_energy, update_kinematics, update_mass_matrix, update_poses};
use nanofold::dynamics::modes::modes;
use nanofold::dynamics::scene::Scene;
use nanofold::dynamics::simulate::{simulate_scene, ModelChoice, ModelKind, SimulationSettings};
use nanofold::dynamics::Data;
use nanofold::dynamics::Method;
use nanofold::NanofoldError;
use proptest::prelude::*;
use std::f64::consts::PI;

/// One plate per entry of `lengths_um`, 100 µm wide, SiN 0.2 µm; hinge i gets
/// `targets_deg[i]` (None: passive, SiN only; Some: SiN + Cr 0.1 µm).
fn strip(lengths_um: &[f64], targets_deg: &[Option<f64>], actuation: &str, drag: bool, t_end: f64) -> Scene {
    let plates: Vec<String> = lengths_um
        .iter()
        .map(|l| format!(r#"{{"length_um": {l}, "width_um": 100, "thickness_um": 0.2, "material": "SiN"}}"#))
        .collect();
    let hinges: Vec<String> = targets_deg
        .iter()
        .map(|t| match t {
            Some(deg) => format!(
                r#"{{"hinge_length_um": 32, "actuated": true, "target_angle_deg": {deg}, "radius_of_curvature_um": 20,
                    "layers": [{{"material": "SiN", "thickness_um": 0.2}}, {{"material": "Cr", "thickness_um": 0.1}}]}}"#
            ),
            None => r#"{"hinge_length_um": 32, "actuated": false, "layers": [{"material": "SiN", "thickness_um": 0.2}]}"#
                .to_string(),
        })
        .collect();
    let json = format!(
        r#"{{
        "materials": {{
            "SiN": {{"youngs_modulus_gpa": 300, "poisson_ratio": 0.28, "density_g_cm3": 3.27}},
            "Cr": {{"youngs_modulus_gpa": 140, "poisson_ratio": 0.21, "density_g_cm3": 7.19}}
        }},
        "plates": [{}],
        "hinges": [{}],
        "actuation": {actuation},
        "environment": {{"drag": {drag}}},
        "time": {{"t_end_s": {t_end}}},
        "outputs": {{"samples": 401}}
    }}"#,
        plates.join(","),
        hinges.join(",")
    );
    scene_text(&json).unwrap()
}

const STEP: &str = r#"{"kind": "step"}"#;

/// Bilayer stiffness (T5.7) by hand: w t³ E / (3 l (1 − ν²)) per layer.
fn bilayer_stiffness() -> f64 {
    let (w, l) = (100e-6, 32e-6);
    let sin = w * 0.2e-6_f64.powi(3) * 300e9 / (3.0 * l * (1.0 - 0.28 * 0.28));
    let cr = w * 0.1e-6_f64.powi(3) * 140e9 / (3.0 * l * (1.0 - 0.21 * 0.21));
    sin + cr
}

/// Moment of inertia of a 0.2 µm SiN plate of length L about its hinge: m(L² + t²)/12 + m(L/2)².
fn hinge_inertia(length: f64) -> f64 {
    let mass = 3270.0 * length * 100e-6 * 0.2e-6;
    mass * (length * length + 0.2e-6 * 0.2e-6) / 12.0 + mass * (length / 2.0).powi(2)
}

#[test]
fn one_hinged_plate_rings_at_the_closed_form_frequency() {
    let scene = strip(&[100.0], &[Some(90.0)], STEP, false, 1e-3);
    let k = bilayer_stiffness();
    assert!((scene.strip().unwrap().model.joints()[0].stiffness - k).abs() < 1e-12 * k);
    let omega = (k / hinge_inertia(100e-6)).sqrt();
    let m = modes(&scene.strip().unwrap().model, &[PI / 2.0]).unwrap();
    let expected_hz = omega / (2.0 * PI);
    assert!(
        (m.frequencies_hz[0] - expected_hz).abs() < 1e-10 * expected_hz,
        "{} vs {expected_hz}",
        m.frequencies_hz[0]
    );
    assert!(m.stable);
    assert!((m.eigenvalues[0] - omega * omega).abs() < 1e-10 * omega * omega);

    // The integrated step response is θ(t) = θ_t (1 − cos ωt): check it at several times.
    let period = 2.0 * PI / omega;
    let settings = SimulationSettings {
        rtol: 1e-10,
        method: Method::Tsit45,
        ignore_collisions: true,
        t_end: Some(3.0 * period),
        ..Default::default()
    };
    let response = simulate_scene(&scene, &settings).unwrap().response;
    assert_eq!(response.model, ModelKind::Dynamic);
    let worst = response
        .samples
        .iter()
        .map(|s| (s.angles[0] - PI / 2.0 * (1.0 - (omega * s.time).cos())).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-7, "max deviation from θ_t(1 − cos ωt): {worst:.2e} rad");
}

#[test]
fn contact_time_of_a_swinging_plate_matches_plane_geometry() {
    // Without drag θ(t) = θ_t (1 − cos ωt); the free edge meets the substrate (y = −L, z = 0)
    // at θ = π, i.e. cos ωt = 1 − π/θ_t.
    let target = 100.0_f64.to_radians();
    let scene = strip(&[100.0], &[Some(100.0)], STEP, false, 1e-3);
    let omega = (bilayer_stiffness() / hinge_inertia(100e-6)).sqrt();
    let expected = (1.0 - PI / target).acos() / omega;
    let settings = SimulationSettings {
        rtol: 1e-11,
        method: Method::Tsit45,
        ..Default::default()
    };
    let response = simulate_scene(&scene, &settings).unwrap().response;
    let collision = response.collision.expect("the plate swings past 180°");
    assert_eq!(collision.pair, ["plate 0".to_string(), "substrate".to_string()]);
    assert!(
        (collision.time - expected).abs() < 1e-7 * expected,
        "{} vs {expected}",
        collision.time
    );
    assert!((collision.point.y + 100e-6).abs() < 1e-9, "{:?}", collision.point);
    assert!(collision.point.z.abs() < 1e-9);
    assert_eq!(response.t_end, collision.time);
}

#[test]
fn quasi_static_path_finds_a_plate_on_plate_contact_where_geometry_puts_it() {
    // Plate 0 stays flat (passive); hinges 1 and 2 fold together, a = u·120°. The tip of
    // plate 2 reaches plate 0's plane where 20 sin a + 60 sin 2a = 0: cos a = −1/6, at y = 40 µm.
    let ramp = r#"{"kind": "ramp", "etch_rate_um_per_min": 1.5}"#;
    let scene = strip(
        &[100.0, 20.0, 60.0],
        &[None, Some(120.0), Some(120.0)],
        ramp,
        false,
        1e4,
    );
    let settings = SimulationSettings {
        model: ModelChoice::QuasiStatic,
        ..Default::default()
    };
    let response = simulate_scene(&scene, &settings).unwrap().response;
    let collision = response.collision.expect("plate 2 folds onto plate 0");
    assert_eq!(collision.pair, ["plate 2".to_string(), "plate 0".to_string()]);
    let a = (-1.0_f64 / 6.0).acos();
    // θ_ramp(t) = a_etch t / ρ_c.
    let expected_time = a * 20e-6 / (1.5e-6 / 60.0);
    assert!(
        (collision.time - expected_time).abs() < 1e-9 * expected_time,
        "{} vs {expected_time}",
        collision.time
    );
    assert!((collision.point.y - 40e-6).abs() < 1e-11, "{:?}", collision.point);
}

/// Kinetic energy straight from the plates: centre-of-mass velocity and angular velocity by
/// central differences of the poses along θ + s θ̇, Richardson-extrapolated from steps h and 2h
/// (error O(h⁴)) so that h can be large enough (1e-4 rad) for rounding to stay near 1e-12.
fn kinetic_energy_from_plates(scene: &Scene, angles: &[f64], rates: &[f64]) -> f64 {
    let model = &scene.strip().unwrap().model;
    let h = 1e-4 / rates.iter().fold(0.0_f64, |a, r| a.max(r.abs()));
    let poses_at = |s: f64| {
        let mut data = Data::new(model);
        let a: Vec<f64> = angles.iter().zip(rates).map(|(a, r)| a + s * r).collect();
        update_poses(model, &a, &mut data);
        data.poses.clone()
    };
    let centre = poses_at(0.0);
    let (plus, minus, plus2, minus2) = (poses_at(h), poses_at(-h), poses_at(2.0 * h), poses_at(-2.0 * h));
    let mut energy = 0.0;
    for (i, plate) in model.plates().iter().enumerate() {
        let velocity = |p: &nalgebra::Isometry3<f64>, m: &nalgebra::Isometry3<f64>, step: f64| {
            (p.translation.vector - m.translation.vector) / (2.0 * step)
        };
        let spin = |p: &nalgebra::Isometry3<f64>, m: &nalgebra::Isometry3<f64>, step: f64| -> Vector3<f64> {
            (p.rotation * m.rotation.inverse()).scaled_axis() / (2.0 * step)
        };
        let v = (4.0 * velocity(&plus[i], &minus[i], h) - velocity(&plus2[i], &minus2[i], 2.0 * h)) / 3.0;
        let omega = (4.0 * spin(&plus[i], &minus[i], h) - spin(&plus2[i], &minus2[i], 2.0 * h)) / 3.0;
        let rotation = centre[i].rotation.to_rotation_matrix();
        let inertia = rotation.matrix() * plate.inertia * rotation.matrix().transpose();
        energy += 0.5 * plate.mass * v.norm_squared() + 0.5 * omega.dot(&(inertia * omega));
    }
    energy
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn mass_matrix_is_spd_and_gives_the_plates_kinetic_energy(
        angles in proptest::collection::vec(-3.0..3.0f64, 4),
        rates in proptest::collection::vec(-1.0e4..1.0e4f64, 4),
    ) {
        let scene = scene_file("patterns/bridge_step.scene.json");
        let model = &scene.strip().unwrap().model;
        let mut data = Data::new(model);
        update_kinematics(model, &angles, &mut data);
        update_mass_matrix(model, &mut data);
        let m = &data.mass_matrix;
        prop_assert!((m - m.transpose()).amax() <= 1e-15 * m.amax());
        let eigen = m.clone().symmetric_eigenvalues();
        prop_assert!(eigen.min() > 0.0, "eigenvalues {}", eigen);
        let quadratic = kinetic_energy(&rates, &data);
        let direct = kinetic_energy_from_plates(&scene, &angles, &rates);
        prop_assert!((quadratic - direct).abs() <= 1e-8 * direct.abs().max(1e-30), "½θ̇ᵀMθ̇ {} vs plates {}", quadratic, direct);
    }
}

#[test]
fn without_drag_the_step_conserves_energy_and_with_drag_it_only_loses_it() {
    let slowest_period = 2.0 * PI / (bilayer_stiffness() / hinge_inertia(300e-6)).sqrt();
    for drag in [false, true] {
        let scene = strip(
            &[300.0, 150.0, 100.0],
            &[Some(60.0), Some(-45.0), Some(90.0)],
            STEP,
            drag,
            1.0,
        );
        let settings = SimulationSettings {
            rtol: 1e-10,
            method: Method::Tsit45,
            ignore_collisions: true,
            t_end: Some(20.0 * slowest_period),
            ..Default::default()
        };
        let response = simulate_scene(&scene, &settings).unwrap().response;
        let energies: Vec<f64> = response.samples.iter().map(|s| s.total_energy()).collect();
        let scale = response.samples.iter().map(|s| s.elastic_energy).fold(0.0, f64::max);
        if drag {
            let rises = energies
                .windows(2)
                .map(|w| w[1] - w[0])
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                rises <= 1e-9 * scale,
                "energy rose by {rises:.2e} J with drag (scale {scale:.2e} J)"
            );
            assert!(
                energies.last().unwrap() < &(energies[0] - 0.05 * scale),
                "drag should dissipate: {energies:?}"
            );
        } else {
            let drift = energies.iter().map(|e| (e - energies[0]).abs()).fold(0.0, f64::max);
            assert!(
                drift < 1e-7 * scale,
                "energy drift {drift:.2e} J of {scale:.2e} J over 20 periods"
            );
        }
    }
}

#[test]
fn step_response_with_drag_settles_to_the_target_when_collisions_are_ignored() {
    // Quadratic drag damps large swings fast and small ones slowly (amplitude ~ 1/t).
    let scene = strip(&[300.0, 150.0], &[Some(60.0), Some(-45.0)], STEP, true, 0.1);
    let settings = SimulationSettings {
        rtol: 1e-8,
        ignore_collisions: true,
        ..Default::default()
    };
    let response = simulate_scene(&scene, &settings).unwrap().response;
    assert_eq!(response.method, Some(Method::Tsit45));
    let t_end = response.t_end;
    let swing = |from: f64, to: f64| {
        response
            .samples
            .iter()
            .filter(|s| s.time >= from * t_end && s.time <= to * t_end)
            .map(|s| (&s.angles - &scene.strip().unwrap().target_angles()).amax())
            .fold(0.0, f64::max)
    };
    let (early, late) = (swing(0.0, 0.1), swing(0.9, 1.0));
    assert!(late < 5e-3, "still {late:.2e} rad from the target after {t_end} s");
    assert!(late < 0.02 * early, "swing {early:.2e} rad early, {late:.2e} rad late");
}

#[test]
fn quasi_static_and_dynamic_agree_on_a_slow_ramp_within_the_stated_estimate() {
    // A fast etch (so the dynamic run is short), no drag (the linear bound is then tight).
    let ramp = r#"{"kind": "ramp", "etch_rate_um_per_min": 600000}"#;
    let mut scene = strip(&[200.0, 100.0], &[Some(90.0), Some(60.0)], ramp, false, 1.0);
    scene.t_end = 1.2 * scene.forcing().duration();
    let run = |model| {
        let settings = SimulationSettings {
            model,
            rtol: 1e-10,
            method: Method::Esdirk34,
            ignore_collisions: true,
            ..Default::default()
        };
        simulate_scene(&scene, &settings).unwrap().response
    };
    let quasi = run(ModelChoice::QuasiStatic);
    let dynamic = run(ModelChoice::Dynamic);
    assert!(
        quasi.time_scales.ratio > 100.0,
        "the ramp must be slow: ratio {}",
        quasi.time_scales.ratio
    );
    let mut drive = vec![0.0; 2];
    let difference = dynamic
        .samples
        .iter()
        .map(|s| {
            scene.forcing().drive_angles(s.time, &mut drive);
            (&s.angles - DVector::from_column_slice(&drive)).amax()
        })
        .fold(0.0, f64::max);
    let estimate = quasi.quasi_static_error_estimate;
    // The estimate is the linear bound with no slack: measured 0.66 of it here (no drag),
    // and the quasi-static check's own run 0.58.
    assert!(
        difference <= estimate,
        "dynamic − quasi-static {difference:.3e} rad > estimate {estimate:.3e}"
    );
    assert!(
        difference >= 0.3 * estimate,
        "estimate {estimate:.3e} far above the difference {difference:.3e}"
    );
    let (_, measured) = quasi.measured_quasi_static_error.unwrap();
    assert!(measured <= estimate);
}

#[test]
fn auto_model_choice_follows_the_time_scales() {
    let step = scene_file("patterns/bridge_step.scene.json");
    let ramp = scene_file("patterns/bridge_ramp.scene.json");
    let settings = SimulationSettings::default();
    let step_response = simulate_scene(&step, &settings).unwrap().response;
    assert_eq!(step_response.model, ModelKind::Dynamic);
    assert_eq!(step_response.time_scales.ratio, 0.0);
    let ramp_response = simulate_scene(&ramp, &settings).unwrap().response;
    assert_eq!(ramp_response.model, ModelKind::QuasiStatic);
    // `docs/model.md#dynamics`: the etch ramp is ~10⁹ fastest periods long.
    assert!(
        (1e8..1e10).contains(&ramp_response.time_scales.ratio),
        "{}",
        ramp_response.time_scales.ratio
    );
    // The ramp lands the folded bridge on the substrate when it reaches its target: t_p = ρ_c (π/2) / a.
    let t_p = 20e-6 * PI / 2.0 / (1.5e-6 / 60.0);
    let collision = ramp_response.collision.unwrap();
    assert!((collision.time - t_p).abs() < 1e-6 * t_p, "{} vs {t_p}", collision.time);
}

fn scene_error(json: &str) -> String {
    match scene_text(json) {
        Ok(_) => panic!("accepted a bad scene"),
        Err(e) => common::full_message(&e),
    }
}

fn bridge_text() -> String {
    std::fs::read_to_string("patterns/bridge_step.scene.json").unwrap()
}

#[test]
fn bad_scenes_get_errors_that_name_the_field() {
    let cases = [
        (
            bridge_text().replacen(
                r#""thickness_um": 0.2, "material""#,
                r#""thickness_um": -0.2, "material""#,
                1,
            ),
            "plates[0].thickness_um",
        ),
        (
            bridge_text().replace(r#""poisson_ratio": 0.28"#, r#""poisson_ratio": 0.5"#),
            "materials.SiN.poisson_ratio",
        ),
        (
            bridge_text().replacen(r#""width_um": 100"#, r#""width_um": 0"#, 1),
            "plates[0].width_um",
        ),
        (
            bridge_text().replace(r#""kind": "step""#, r#""kind": "pulse""#),
            "unknown variant `pulse`",
        ),
        (
            bridge_text().replacen(r#""length_um": 100"#, r#""length": 100"#, 1),
            "invalid `plates[0].length`: an unknown key",
        ),
        (
            bridge_text().replace(r#""t_end_s": 0.002"#, r#""t_end": 0.002"#),
            "invalid `time.t_end`: an unknown key",
        ),
        (
            bridge_text().replacen(r#""material": "SiN" }"#, r#""material": "Si" }"#, 1),
            "plates[0].material",
        ),
        (
            bridge_text().replacen(r#""target_angle_deg": 90"#, r#""target_angle_deg": 270"#, 1),
            "hinges[0].target_angle_deg",
        ),
        (
            bridge_text().replace(r#""t_end_s": 0.002"#, r#""t_end_s": 0"#),
            "time.t_end_s",
        ),
        ("{".to_string(), "malformed JSON"),
        (
            bridge_text().replacen(
                r#""material": "SiN" }"#,
                r#""material": "SiN", "moment_about_crease_kg_m2": 5.4e6 }"#,
                1,
            ),
            "invalid `plates[0].moment_about_crease_kg_m2`: 5400000 (must lie within a factor 10⁶",
        ),
        (
            bridge_text().replacen(
                r#""material": "SiN" }"#,
                r#""material": "SiN", "moment_about_crease_kg_m2": -1e-20 }"#,
                1,
            ),
            "plates[0].moment_about_crease_kg_m2",
        ),
        (
            bridge_text().replacen(r#""actuated": true,"#, r#""actuated": true, "stiffness_scale": 0,"#, 1),
            "hinges[0].stiffness_scale",
        ),
        (
            bridge_text().replacen(
                r#""actuated": true,"#,
                r#""actuated": true, "stiffness_scale": 1e9,"#,
                1,
            ),
            "hinges[0].stiffness_scale",
        ),
    ];
    for (text, expected) in cases {
        let message = scene_error(&text);
        assert!(message.contains(expected), "expected {expected:?} in: {message}");
    }
    let no_targets = bridge_text().replace(r#""target_angle_deg": 90, "#, "");
    assert!(scene_error(&no_targets).contains("hinges[0].target_angle_deg"));
    let ramp = std::fs::read_to_string("patterns/bridge_ramp.scene.json").unwrap();
    let no_radius = ramp.replace(r#", "radius_of_curvature_um": 20"#, "");
    assert!(scene_error(&no_radius).contains("hinges[0].radius_of_curvature_um"));
    let scene = scene_file("patterns/bridge_step.scene.json");
    let bad_rtol = SimulationSettings {
        rtol: -1.0,
        ..Default::default()
    };
    assert!(matches!(
        simulate_scene(&scene, &bad_rtol),
        Err(NanofoldError::InvalidField { .. })
    ));
}

#[test]
fn quasi_static_forced_on_a_step_reports_its_large_error() {
    let scene = strip(&[300.0, 150.0], &[Some(60.0), Some(-45.0)], STEP, true, 0.01);
    let settings = SimulationSettings {
        model: ModelChoice::QuasiStatic,
        ignore_collisions: true,
        ..Default::default()
    };
    let response = simulate_scene(&scene, &settings).unwrap().response;
    assert_eq!(response.model, ModelKind::QuasiStatic);
    let (_, measured) = response.measured_quasi_static_error.unwrap();
    // The undamped step would overshoot by its own size; drag takes a little off.
    assert!(measured > 0.5 * 60f64.to_radians(), "measured {measured}");
    // Drag only takes energy out, so the linear (drag-free) bound holds: measured 0.989 of it.
    assert!(measured <= response.quasi_static_error_estimate);
    let last = response.samples.last().unwrap();
    assert!((&last.angles - &scene.strip().unwrap().target_angles()).amax() < 1e-15);
}

#[test]
fn a_run_that_outgrows_its_step_budget_stops_with_advice() {
    let scene = strip(&[300.0, 150.0], &[Some(60.0), Some(-45.0)], STEP, true, 0.01);
    let settings = SimulationSettings {
        max_steps: 200,
        ignore_collisions: true,
        ..Default::default()
    };
    let message = simulate_scene(&scene, &settings).unwrap_err().to_string();
    assert!(
        message.contains("budget of 200 steps") && message.contains("esdirk34"),
        "{message}"
    );
}

#[test]
fn stiffness_and_inertia_too_far_apart_for_doubles_is_an_error_not_nan() {
    // Found by tests/fuzz.rs: a hinge 1e-308 µm long gives K ~ 1e300 and λ = K/I overflows.
    // A scene file now refuses such a length by name ...
    let text = std::fs::read_to_string("patterns/bridge_step.scene.json")
        .unwrap()
        .replacen(r#""hinge_length_um": 32"#, r#""hinge_length_um": 1.2e-308"#, 1);
    let Err(error) = scene_text(&text) else {
        panic!("a 1.2e-308 µm hinge was accepted")
    };
    let message = error.to_string();
    assert!(
        message.contains("hinges[0].hinge_length_um") && message.contains("1.2e-308"),
        "{message}"
    );
    // ... and a model built in code with such a stiffness still gets an error, not NaN.
    use nalgebra::Point3;
    use nanofold::dynamics::model::{Joint, Model, Plate};
    let plate = Plate::lamina(&[[-5e-5, 0.0], [5e-5, 0.0], [5e-5, 1e-4], [-5e-5, 1e-4]], 2e-7, 3270.0);
    let joint = Joint {
        axis: Vector3::x_axis(),
        point: Point3::origin(),
        stiffness: 1e300,
    };
    let model = Model::chain(vec![joint], vec![plate], None).unwrap();
    let message = modes(&model, &[0.5]).unwrap_err().to_string();
    assert!(message.contains("overflow"), "{message}");
}

#[test]
fn ramp_drive_rates_are_the_derivative_of_the_drive_angles() {
    let scene = scene_file("patterns/bridge_ramp.scene.json");
    let ramp = scene.forcing();
    let t_p = ramp.duration();
    let (mut rates, mut plus, mut minus) = (vec![0.0; 4], vec![0.0; 4], vec![0.0; 4]);
    for (t, expected_moving) in [(0.3 * t_p, true), (0.99 * t_p, true), (1.01 * t_p, false)] {
        ramp.drive_rates(t, &mut rates);
        let h = 1e-4 * t_p;
        ramp.drive_angles(t + h, &mut plus);
        ramp.drive_angles(t - h, &mut minus);
        for i in 0..4 {
            let central = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (rates[i] - central).abs() < 1e-9 * central.abs().max(1e-9),
                "t = {t}: {rates:?} vs {central}"
            );
            assert_eq!(rates[i] != 0.0, expected_moving);
        }
    }
    // a / ρ_c = (1.5 µm/min) / 20 µm.
    ramp.drive_rates(0.0, &mut rates);
    assert!((rates[0] - 1.5e-6 / 60.0 / 20e-6).abs() < 1e-15);
}

/// The two stated-reading fields of a strip: a `stiffness_scale` s scales every frequency by
/// √s (K → sK, M unchanged, the same folded target), and a `moment_about_crease_kg_m2`
/// equal to the box's m (L² + t²)/12 changes nothing.
#[test]
fn stated_stiffness_and_moment_act_as_their_closed_forms() {
    let frequencies = |text: &str| {
        let scene = scene_text(text).unwrap();
        let chain = scene.strip().unwrap();
        modes(&chain.model, chain.target_angles().as_slice())
            .unwrap()
            .frequencies_hz
    };
    let base = frequencies(&bridge_text());
    let scaled =
        frequencies(&bridge_text().replace(r#""actuated": true,"#, r#""actuated": true, "stiffness_scale": 4,"#));
    for (f, g) in base.iter().zip(&scaled) {
        assert!((g / f - 2.0).abs() < 1e-9, "{g} against 2 × {f}");
    }
    // Plate 0: 100 × 100 × 0.2 µm of SiN at 3.27 g/cm³.
    let (l, t) = (100e-6_f64, 0.2e-6_f64);
    let mass = 3270.0 * l * 100e-6 * t;
    let moment = mass * (l * l + t * t) / 12.0;
    let stated = bridge_text().replacen(
        r#""material": "SiN" }"#,
        &format!(r#""material": "SiN", "moment_about_crease_kg_m2": {moment:e} }}"#),
        1,
    );
    for (f, g) in base.iter().zip(&frequencies(&stated)) {
        assert!((g / f - 1.0).abs() < 1e-12, "{g} against {f}");
    }
}
