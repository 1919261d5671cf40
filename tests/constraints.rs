//! Holonomic constraint curves: sweeps against closed forms, fits against exact data,
//! Jacobians against finite differences, sweep against unfolding, bad input.

use nanofold::constraints::*;
use nanofold::constraints::{eval_monomial, Chebyshev};
use nanofold::geometry::kinematics::closure_residual;
use nanofold::pattern::{LoadOptions, VertexPattern};
use nanofold::prelude::Named;
use nanofold::unfold::UnfoldSettings;
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

fn load(name: &str) -> VertexPattern {
    nanofold::read::load_pattern(&Path::new("patterns").join(name), &LoadOptions::default()).unwrap()
}

fn ray_angles(pattern: &VertexPattern, crease_angles: &[f64]) -> Vec<f64> {
    let mut rho = pattern.folded_ray_angles();
    for (c, crease) in pattern.creases.iter().enumerate() {
        rho[crease.ray] = crease_angles[c];
    }
    rho
}

/// A flat-foldable degree-4 vertex with consecutive sectors α, β, π−α, π−β built from its
/// closed form: ρ2 = −ρ0, ρ3 = ρ1, tan(ρ1/2) = k tan(ρ0/2), k = sin((α+β)/2)/sin((α−β)/2).
/// The loader rejects the file unless the closed form closes the loop.
fn flat_foldable_vertex(alpha_deg: f64, beta_deg: f64, rho0_deg: f64) -> (VertexPattern, f64) {
    let (alpha, beta) = (alpha_deg.to_radians(), beta_deg.to_radians());
    let k = ((alpha + beta) / 2.0).sin() / ((alpha - beta) / 2.0).sin();
    let rho0 = rho0_deg.to_radians();
    let rho1 = 2.0 * (k * (rho0 / 2.0).tan()).atan();
    let text = format!(
        r#"{{"chain": "closed", "angle_unit": "rad",
            "sector_angles": [{alpha}, {beta}, {}, {}],
            "creases": [{{"assignment": "U", "fold_angle": {rho0}}}, {{"assignment": "U", "fold_angle": {rho1}}},
                        {{"assignment": "U", "fold_angle": {}}}, {{"assignment": "U", "fold_angle": {rho1}}}]}}"#,
        PI - alpha,
        PI - beta,
        -rho0
    );
    let pattern = nanofold::read::parse_pattern(&text, "flat_foldable", "test", &LoadOptions::default()).unwrap();
    (pattern, k)
}

#[test]
fn sweep_through_the_flat_bifurcation_follows_the_closed_form_on_one_branch() {
    // Flat is a singular configuration: two branches of motion cross there. A sweep from
    // −170° to 170° must pass through it on the branch it started on.
    for (alpha, beta, folded) in [(60.0, 120.0, 100.0), (50.0, 110.0, -80.0), (80.0, 35.0, 150.0)] {
        let (pattern, k) = flat_foldable_vertex(alpha, beta, folded);
        let setup = Setup::new(&pattern, 0, &[]).unwrap();
        let samples = sweep_samples(&pattern, &setup, [-170f64.to_radians(), 170f64.to_radians()], 241).unwrap();
        assert!(
            samples.max_closure_residual <= 1e-12,
            "{:e}",
            samples.max_closure_residual
        );
        for (theta, angles) in samples.drive_angles.iter().zip(&samples.fold_angles) {
            let rho1 = 2.0 * (k * (theta / 2.0).tan()).atan();
            assert!(
                (angles[1] - rho1).abs() < 1e-11,
                "α={alpha} θ={theta}: {} vs {rho1}",
                angles[1]
            );
            assert!((angles[2] + theta).abs() < 1e-11);
            assert!((angles[3] - rho1).abs() < 1e-11);
            assert!(closure_residual(&pattern.sector_angles, &ray_angles(&pattern, angles)) <= 1e-12);
        }
    }
}

#[test]
fn library_sweeps_close_the_loop_and_are_continuous() {
    for (name, locks) in [
        ("degree4_generic.fold", vec![]),
        ("miura_vertex.fold", vec![]),
        ("half_paper.fold", vec![]),
        ("degree4_native.json", vec![]),
        ("corner_cube.fold", vec![(1, 0.0)]),
    ] {
        let pattern = load(name);
        let setup = Setup::new(&pattern, 0, &locks).unwrap();
        let domain = default_domain(&pattern, 0).unwrap();
        let samples = sweep_samples(&pattern, &setup, domain, 101).unwrap();
        assert!(
            samples.max_closure_residual <= 1e-12,
            "{name}: {:e}",
            samples.max_closure_residual
        );
        // No branch jumps: every step changes each angle by at most a few driver steps.
        let h = (domain[1] - domain[0]) / 100.0;
        for pair in samples.fold_angles.windows(2) {
            for (a, b) in pair[0].iter().zip(&pair[1]) {
                assert!((a - b).abs() < 6.0 * h, "{name}: jump {a} → {b}");
            }
        }
    }
}

#[test]
fn corner_cube_step_one_closes_the_cube_corner() {
    // Flap centre crease driven 0 → 180° with crease 1 locked flat: at 180° the flap halves
    // lie on each other and creases 2, 3, 4 form a cube corner (fold angles ±90°, `docs/model.md#reference-devices`).
    let pattern = load("corner_cube.fold");
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    assert_eq!(setup.dependents, vec![2, 3, 4]);
    let samples = sweep_samples(&pattern, &setup, [0.0, PI], 181).unwrap();
    let end = samples.fold_angles.last().unwrap();
    assert!((end[2] - FRAC_PI_2).abs() < 1e-10, "{}", end[2]);
    assert!((end[3] - FRAC_PI_2).abs() < 1e-10, "{}", end[3]);
    assert!((end[4] + FRAC_PI_2).abs() < 1e-10, "{}", end[4]);
    let start = &samples.fold_angles[0];
    assert!(start.iter().all(|a| a.abs() < 1e-8), "{start:?}");

    let poly = ConstraintPoly::fit(&pattern, &samples, 4).unwrap();
    let report = ConstraintReport::new(&pattern, &samples, &poly).unwrap();
    assert_eq!(report.curves.len(), 3);
    // Degree 4 is good to a few mrad here; degree auto reaches 1e-9 rad.
    assert!(report.max_fit_error() < 5e-3 && report.max_fit_error() > 1e-4);
    let (fine, fine_report) = fit_to_tolerance(&pattern, &samples, 1e-9).unwrap();
    assert!(fine_report.max_fit_error() <= 1e-9);
    assert!(fine.degree() > 4 && fine.degree() <= 20);
    let (coarser, _) = fit_to_tolerance(&pattern, &samples, 1e-6).unwrap();
    assert!(coarser.degree() < fine.degree());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn fit_is_exact_on_polynomial_data(
        coeffs in prop::collection::vec(-2.0f64..2.0, 1..=9),
        start in -PI..1.0,
        width in 0.3f64..2.0,
        extra in 0usize..3,
    ) {
        let degree = coeffs.len() - 1 + extra;
        let domain = [start, start + width];
        let x: Vec<f64> = (0..60).map(|i| domain[0] + width * i as f64 / 59.0).collect();
        let y: Vec<f64> = x.iter().map(|&v| eval_monomial(&coeffs, v)).collect();
        let series = Chebyshev::fit(&x, &y, degree.max(1), domain).unwrap();
        let monomial = series.monomial_coefficients();
        // Relative to the data's scale: least squares cannot beat rounding of the largest value.
        let scale = 1.0 + y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (&xi, &yi) in x.iter().zip(&y) {
            prop_assert!((series.eval(xi) - yi).abs() <= 1e-12 * scale);
            prop_assert!((eval_monomial(&monomial, xi) - yi).abs() <= 1e-10 * scale);
        }
    }
}

#[test]
fn fit_recovers_monomial_coefficients_and_degree_units() {
    let coeffs = [0.1, -0.7, 0.25, 0.05, -0.01];
    let x: Vec<f64> = (0..41).map(|i| PI * i as f64 / 40.0).collect();
    let y: Vec<f64> = x.iter().map(|&v| eval_monomial(&coeffs, v)).collect();
    let series = Chebyshev::fit(&x, &y, 4, [0.0, PI]).unwrap();
    for (got, want) in series.monomial_coefficients().iter().zip(coeffs) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn constraint_jacobian_and_its_rate_match_finite_differences() {
    let pattern = load("corner_cube.fold");
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    let samples = sweep_samples(&pattern, &setup, [0.0, PI], 201).unwrap();
    let poly = ConstraintPoly::fit(&pattern, &samples, 6).unwrap();
    let h = 1e-6;
    for theta in [0.3, 1.2, 2.0, 2.9] {
        let g = poly.jacobian(theta).unwrap();
        let (plus, minus) = (poly.eval(theta + h).unwrap(), poly.eval(theta - h).unwrap());
        for j in 0..g.len() {
            let fd = (plus[j] - minus[j]) / (2.0 * h);
            assert!((g[j] - fd).abs() < 1e-8, "G[{j}] {} vs {fd}", g[j]);
        }
        // Ġ along θ(t) = θ + v t.
        let v = -1.7;
        let gdot = poly.jacobian_dot(theta, v).unwrap();
        let (gp, gm) = (
            poly.jacobian(theta + v * h).unwrap(),
            poly.jacobian(theta - v * h).unwrap(),
        );
        for j in 0..g.len() {
            let fd = (gp[j] - gm[j]) / (2.0 * h);
            assert!((gdot[j] - fd).abs() < 1e-6, "Ġ[{j}] {} vs {fd}", gdot[j]);
        }
        // The fitted G agrees with the exact slope of the samples (central differences).
        let i = samples.drive_angles.iter().position(|&x| x >= theta).unwrap();
        let dx = samples.drive_angles[i + 1] - samples.drive_angles[i - 1];
        for (j, &c) in poly.dependents.iter().enumerate() {
            let exact_slope = (samples.fold_angles[i + 1][c] - samples.fold_angles[i - 1][c]) / dx;
            let g_here = poly.jacobian(samples.drive_angles[i]).unwrap()[j];
            assert!((g_here - exact_slope).abs() < 1e-3, "slope {g_here} vs {exact_slope}");
        }
    }
    // Outside the fitted domain: a clear error, not an extrapolation.
    let err = poly.eval(PI + 0.1).unwrap_err().to_string();
    assert!(err.contains("outside the fitted domain"), "{err}");
}

/// Constraint samples along an unfolding of the pattern with the setup's locks held.
fn unfold_samples(pattern: &VertexPattern, setup: &Setup) -> nanofold::Result<CurveSamples> {
    let settings = UnfoldSettings::default();
    let report = nanofold::unfold::unfold(&held_pattern(pattern, setup)?, &settings)?;
    let states: Vec<Vec<f64>> = report.trajectory.iter().map(|s| s.fold_angles.clone()).collect();
    trajectory_samples(
        pattern,
        setup,
        None,
        &states,
        report.verdict.as_str(),
        settings.flat_tol,
    )
}

#[test]
fn sweep_and_unfolding_trajectory_give_the_same_curve() {
    let pattern = load("degree4_generic.fold");
    let setup = Setup::new(&pattern, 0, &[]).unwrap();
    let unfolded = unfold_samples(&pattern, &setup).unwrap();
    assert!(unfolded.drive_angles.len() > 5);
    let domain = [unfolded.domain[0], unfolded.domain[1]];
    let swept = sweep_samples(&pattern, &setup, domain, 201).unwrap();
    let (exact, _) = fit_to_tolerance(&pattern, &swept, 1e-10).unwrap();
    let mut worst: f64 = 0.0;
    for (theta, angles) in unfolded.drive_angles.iter().zip(&unfolded.fold_angles) {
        // Within ~1e-5 rad of flat the unfolding wanders between the two branches that
        // meet there; elsewhere it must lie on the swept branch.
        if theta.abs() < 1e-3 {
            continue;
        }
        let f = exact.eval(*theta).unwrap();
        for (j, &c) in exact.dependents.iter().enumerate() {
            worst = worst.max((f[j] - angles[c]).abs());
        }
    }
    assert!(worst < 1e-8, "unfold vs sweep: {worst:e}");
}

#[test]
fn mujoco_snippet_holds_the_fitted_quartic() {
    let pattern = load("degree4_generic.fold");
    let setup = Setup::new(&pattern, 0, &[]).unwrap();
    let samples = sweep_samples(&pattern, &setup, default_domain(&pattern, 0).unwrap(), 101).unwrap();
    let poly = ConstraintPoly::fit(&pattern, &samples, 3).unwrap();
    let report = ConstraintReport::new(&pattern, &samples, &poly).unwrap();
    let xml = mujoco_snippet(&report).unwrap();
    let lines: Vec<&str> = xml.lines().filter(|l| l.contains("joint2=")).collect();
    assert_eq!(lines.len(), 3);
    for (line, curve) in lines.iter().zip(&report.curves) {
        let coeffs: Vec<f64> = line
            .split("polycoef=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .split_whitespace()
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(coeffs.len(), 5);
        assert_eq!(coeffs[4], 0.0);
        for theta in [0.2, 1.0, 2.0] {
            let from_xml = eval_monomial(&coeffs, theta);
            let c = pattern.crease_from_user_index(curve.crease).unwrap();
            let j = poly.dependents.iter().position(|&d| d == c).unwrap();
            assert!((from_xml - poly.fitted.curves[j].eval(theta)).abs() < 1e-12);
        }
    }
    let quintic = ConstraintPoly::fit(&pattern, &samples, 5).unwrap();
    let err = mujoco_snippet(&ConstraintReport::new(&pattern, &samples, &quintic).unwrap()).unwrap_err();
    assert!(err.to_string().contains("quartic"), "{err}");
}

#[test]
fn bad_constraint_requests_get_clear_errors() {
    let generic = load("degree4_generic.fold");
    // Driving a locked crease.
    let err = Setup::new(&generic, 0, &[(0, 0.0)]).unwrap_err().to_string();
    assert!(err.contains("cannot drive a locked crease"), "{err}");
    let locked = load("degree4_locked.fold");
    let held = locked.creases.iter().position(|c| c.locked).unwrap();
    let err = Setup::new(&locked, held, &[]).unwrap_err().to_string();
    assert!(err.contains("cannot drive a locked crease"), "{err}");
    // A range the pattern cannot reach. Closed form: crease 0 sits between sectors a, b
    // (70°, 70°); the diagonal between its neighbours' nodes has cos d = cos a cos b +
    // sin a sin b cos φ with φ = π − |ρ₀|, and the other two sectors c, e (100°, 120°) close
    // only while d ≥ |c − e|: the driver turns back at cos φ* = (cos|c−e| − cos a cos b) /
    // (sin a sin b).
    let setup = Setup::new(&generic, 0, &[]).unwrap();
    let err = sweep_samples(&generic, &setup, [0.0, PI], 181).unwrap_err().to_string();
    let ray = generic.creases[0].ray;
    let alpha = |k: usize| generic.sector_angles[k % 4];
    let (a, b, c, e) = (alpha(ray + 3), alpha(ray), alpha(ray + 1), alpha(ray + 2));
    let cos_phi = ((c - e).abs().cos() - a.cos() * b.cos()) / (a.sin() * b.sin());
    let turning = (PI - cos_phi.acos()).to_degrees();
    let reported: f64 = err
        .split(" = ")
        .nth(1)
        .and_then(|rest| rest.split('°').next())
        .and_then(|number| number.parse().ok())
        .unwrap_or_else(|| panic!("no angle in {err}"));
    // The message rounds to 1e-6°; the sweep's last solvable point matched the closed form
    // to that (measured).
    assert!(
        (reported - turning).abs() < 2e-6,
        "stopped at {reported}°, turning point {turning}°: {err}"
    );
    // Degrees 0 and 21.
    let samples = sweep_samples(&generic, &setup, [0.0, 1.0], 41).unwrap();
    for degree in [0, 21] {
        let err = ConstraintPoly::fit(&generic, &samples, degree).unwrap_err().to_string();
        assert!(err.contains("`degree`") && err.contains(&degree.to_string()), "{err}");
    }
    // Too many free creases, an open chain, an out-of-range lock.
    let err = Setup::new(&load("waterbomb.fold"), 0, &[]).unwrap_err().to_string();
    assert!(err.contains("lock 4 more"), "{err}");
    let err = Setup::new(&load("sheet_corner.fold"), 0, &[]).unwrap_err().to_string();
    assert!(err.contains("open chain"), "{err}");
    let err = Setup::new(&generic, 0, &[(1, 4.0)]).unwrap_err().to_string();
    assert!(err.contains("[−180°, 180°]"), "{err}");
    let err = sweep_samples(&generic, &setup, [1.0, 0.5], 41).unwrap_err().to_string();
    assert!(err.contains("`range`"), "{err}");
    // --source unfold cannot move a lock away from the folded state.
    let corner = load("corner_cube.fold");
    let setup = Setup::new(&corner, 0, &[(1, 0.0)]).unwrap();
    let err = unfold_samples(&corner, &setup).unwrap_err().to_string();
    assert!(err.contains("folded angle"), "{err}");
}

#[test]
fn every_closed_library_pattern_yields_curves_once_locked_to_one_degree_of_freedom() {
    // Lock every crease after the first four at its folded angle and sweep the driver ±10°
    // about its folded value: the curves exist, close the loop and fit.
    for name in [
        "half_paper.fold",
        "corner_cube.fold",
        "waterbomb.fold",
        "degree4_generic.fold",
        "miura_vertex.fold",
        "degree6_asymmetric.fold",
        "symmetric16.fold",
        "degree4_native.json",
    ] {
        let pattern = load(name);
        let locks: Vec<(usize, f64)> = (4..pattern.creases.len())
            .map(|c| (c, pattern.creases[c].folded_angle))
            .collect();
        let setup = Setup::new(&pattern, 0, &locks).unwrap();
        let folded = pattern.creases[0].folded_angle;
        let domain = [(folded - 0.17).max(-PI), (folded + 0.17).min(PI)];
        let samples = sweep_samples(&pattern, &setup, domain, 41).unwrap();
        assert!(samples.max_closure_residual <= 1e-12, "{name}");
        let poly = ConstraintPoly::fit(&pattern, &samples, 4).unwrap();
        let report = ConstraintReport::new(&pattern, &samples, &poly).unwrap();
        assert!(report.max_fit_error() < 1e-3, "{name}: {:e}", report.max_fit_error());
        assert!(mujoco_snippet(&report).is_ok());
        #[cfg(feature = "plot")]
        assert!(nanofold::plot::constraints_svg(&pattern, &samples, &poly).is_ok());
    }
}

#[test]
fn polynomial_jacobian_matches_the_implicit_function_theorem() {
    // Two independent routes to G = ∂f/∂θ_c (T4.18): the fitted polynomial's derivative and
    // the implicit function theorem on the exact closure Jacobian.
    let pattern = load("corner_cube.fold");
    let setup = Setup::new(&pattern, 0, &[(1, 0.0)]).unwrap();
    let samples = sweep_samples(&pattern, &setup, [0.0, PI], 201).unwrap();
    let (poly, _) = fit_to_tolerance(&pattern, &samples, 1e-9).unwrap();
    let mut worst: f64 = 0.0;
    for (theta, angles) in samples.drive_angles.iter().zip(&samples.fold_angles).skip(1) {
        let exact = implicit_jacobian(&pattern, &setup, angles).unwrap();
        let fitted = poly.jacobian(*theta).unwrap();
        for (e, f) in exact.iter().zip(&fitted) {
            worst = worst.max((e - f).abs());
        }
    }
    assert!(worst < 1e-6, "G: polynomial vs implicit function theorem {worst:e}");
    // At the flat state the dependents are no function of the driver: a clear error.
    let err = implicit_jacobian(&pattern, &setup, &samples.fold_angles[0]).unwrap_err();
    assert!(err.to_string().contains("singular configuration"), "{err}");
}
