//! Constraint curves of a crease pattern of many vertices with one degree of freedom
//! (`docs/model.md#constraint-curves-of-many-vertices`): an exact sweep of the driving
//! crease (predictor along the null space, Newton with the driver held), Chebyshev fits of
//! every other crease, their errors at sweep points the fit did not see, and the MuJoCo
//! couplings.

use super::chebyshev::{eval_monomial, Chebyshev};
use super::{MAX_DEGREE, MAX_SAMPLES};
use crate::error::{NanofoldError, NumericalError, Result};
use crate::folding::normal::NormalSolver;
use crate::folding::{closure_jacobian, jacobian_rank, vertex_residuals, FoldingModel};
use crate::pattern::crease_pattern::EdgeKind;
use serde::Serialize;
use std::fmt::Write as _;

/// Largest change of the driver between two Newton solves of the sweep, rad.
const SWEEP_STEP: f64 = 0.02;
/// Closure tolerance of every sweep point, rad per vertex.
const SWEEP_TOL: f64 = 1e-12;
/// μ of the sweep's Newton steps, relative to JᵀJ's largest diagonal entry.
const SWEEP_REGULARISATION: f64 = 1e-12;

/// Exact states along the driver, on a uniform grid of 2·samples − 1 driver values: the
/// even points are fitted, the odd ones check the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkSweep {
    /// The driving crease's fold-angle column.
    pub driver: usize,
    /// [a, b], rad.
    pub domain: [f64; 2],
    /// Driver values, ascending.
    pub driver_values: Vec<f64>,
    /// Every crease's fold angle at each driver value, rad.
    pub states: Vec<Vec<f64>>,
    /// Largest vertex closure residual over the sweep, rad.
    pub max_closure_residual: f64,
}

/// One crease's fitted curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetworkCurve {
    /// The crease's FOLD edge index.
    pub edge: usize,
    /// Its assignment letter.
    pub assignment: String,
    /// The fit on the domain.
    pub chebyshev: Chebyshev,
    /// Monomial coefficients in the driver (rad), ascending powers.
    pub coeffs_rad: Vec<f64>,
    /// Largest |fit − exact| over every sweep point (the fitted and the held-out), rad.
    pub max_fit_error_rad: f64,
    /// The same for the monomial form.
    pub max_monomial_error_rad: f64,
}

/// The curves of every crease against the driver, with their errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetworkCurves {
    /// The pattern's name.
    pub pattern: String,
    /// The driver's FOLD edge index.
    pub driver_edge: usize,
    /// [a, b] of the driver, rad.
    pub domain_rad: [f64; 2],
    /// The same in degrees.
    pub domain_deg: [f64; 2],
    /// Points fitted (the sweep also solved as many − 1 in between, for the errors).
    pub samples: usize,
    /// Polynomial degree.
    pub degree: usize,
    /// Largest vertex closure residual over the sweep, rad.
    pub max_closure_residual_rad: f64,
    /// Largest fit error over the curves (fitted and held-out points), rad.
    pub max_fit_error_rad: f64,
    /// One curve per crease other than the driver.
    pub curves: Vec<NetworkCurve>,
}

fn letter(kind: EdgeKind) -> String {
    match kind {
        EdgeKind::Crease(a) => a.letter().to_string(),
        EdgeKind::Boundary => "B".into(),
        EdgeKind::Facet => "F".into(),
    }
}

/// Newton onto every closure with the driver held: its Jacobian column is zeroed (the
/// structure kept), so the least-norm step leaves it alone.
fn restore_held(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    driver: usize,
    solver: &mut NormalSolver,
) -> Result<f64> {
    let mut worst = f64::INFINITY;
    for _ in 0..40 {
        let mut jac = closure_jacobian(model, fold_angles);
        worst = jac.worst_residual();
        if !worst.is_finite() {
            break;
        }
        if worst <= SWEEP_TOL {
            return Ok(worst);
        }
        jac.hold(driver);
        let factor = solver.factor(&jac)?;
        let mut step = vec![0.0; jac.cols];
        jac.apply_transpose(&jac.residual, &mut step);
        factor.solve(&mut step);
        for (rho, d) in fold_angles.iter_mut().zip(&step) {
            *rho -= d;
        }
    }
    Err(NumericalError::ClosureNotConverged {
        residual: worst,
        iterations: 40,
    }
    .into())
}

/// A factorisation of the held Jacobian (the driver's column zeroed) that chord steps reuse.
struct HeldFactor {
    jacobian: crate::folding::ClosureJacobian,
    factor: crate::folding::normal::NormalFactor,
}

/// [`restore_held`] by chord steps: `held`'s factorisation (from a state nearby on the
/// sweep) serves while each step cuts the residual tenfold; where one does not, a fresh one
/// is made and kept for the next states. Neighbouring sweep points are a fraction of a
/// degree apart, so most states need no factorisation of their own.
fn restore_held_chord(
    model: &FoldingModel,
    fold_angles: &mut [f64],
    driver: usize,
    solver: &mut NormalSolver,
    held: &mut Option<HeldFactor>,
) -> Result<f64> {
    let mut residual = Vec::with_capacity(3 * model.stars.len());
    let mut step = vec![0.0; fold_angles.len()];
    let mut previous = f64::INFINITY;
    let mut fresh = false;
    for _ in 0..40 {
        crate::folding::closure_residual(model, fold_angles, &mut residual);
        let worst = crate::folding::worst_of(&residual);
        if !worst.is_finite() {
            break;
        }
        // Chord steps converge linearly: a tenth of Newton's tolerance leaves the sweep's
        // states as closed as Newton's quadratic last step did.
        if worst <= 0.1 * SWEEP_TOL {
            return Ok(worst);
        }
        if held.is_none() || (worst > 0.1 * previous && !fresh) {
            let mut jacobian = closure_jacobian(model, fold_angles);
            jacobian.hold(driver);
            let factor = solver.factor(&jacobian)?;
            *held = Some(HeldFactor { jacobian, factor });
            fresh = true;
        } else if worst > 0.5 * previous {
            // Even a fresh factorisation does not converge here.
            break;
        }
        previous = worst;
        let chord = held.as_ref().expect("set above");
        chord.jacobian.apply_transpose(&residual, &mut step);
        chord.factor.solve(&mut step);
        for (rho, d) in fold_angles.iter_mut().zip(&step) {
            *rho -= d;
        }
    }
    // Newton's own steps, from where the chord steps stopped.
    restore_held(model, fold_angles, driver, solver)
}

/// d(fold angles)/d(driver) at a state: the null vector of J scaled to move the driver at
/// unit rate.
fn tangent(model: &FoldingModel, fold_angles: &[f64], driver: usize, solver: &mut NormalSolver) -> Result<Vec<f64>> {
    let jac = closure_jacobian(model, fold_angles);
    let factor = solver.factor(&jac)?;
    let mut unit = vec![0.0; jac.cols];
    unit[driver] = 1.0;
    let v = factor.project(&unit);
    let size = v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    if v[driver].is_nan() || v[driver].abs() <= 1e-6 * size {
        return Err(NanofoldError::invalid(
            "drive",
            format!("edge {}", model.pattern.creases[driver]),
            format!(
                "the driver does not move along the pattern's motion here (driver rate {:.1e} of the fastest crease's): choose another crease",
                v[driver].abs() / size.max(f64::MIN_POSITIVE)
            ),
        ));
    }
    Ok(v.iter().map(|x| x / v[driver]).collect())
}

/// The exact sweep from a rigid state with one degree of freedom over `domain` (which
/// must contain the state's driver value), `samples` fitted points.
pub fn network_sweep(
    model: &FoldingModel,
    start: &[f64],
    driver: usize,
    domain: [f64; 2],
    samples: usize,
) -> Result<NetworkSweep> {
    if driver >= model.crease_count() {
        return Err(NanofoldError::invalid(
            "drive",
            driver,
            format!("the pattern has {} creases", model.crease_count()),
        ));
    }
    if !(2..=MAX_SAMPLES / 2).contains(&samples) {
        return Err(NanofoldError::invalid(
            "samples",
            samples,
            format!("must lie in [2, {}]", MAX_SAMPLES / 2),
        ));
    }
    let [a, b] = domain;
    if !(a.is_finite() && b.is_finite() && a < b && a.abs() <= std::f64::consts::PI && b.abs() <= std::f64::consts::PI)
    {
        return Err(NanofoldError::invalid(
            "range",
            format!("[{:.4}°, {:.4}°]", a.to_degrees(), b.to_degrees()),
            "needs a < b within [−180°, 180°]",
        ));
    }
    if model.locked_columns[driver] {
        return Err(NanofoldError::invalid(
            "drive",
            format!("edge {}", model.pattern.creases[driver]),
            "the crease is locked (edges_nanofold:locked): it cannot drive",
        ));
    }
    let mut solver = NormalSolver::new(SWEEP_REGULARISATION);
    let mut rho = start.to_vec();
    let start_residual = vertex_residuals(model, &rho).into_iter().fold(0.0, f64::max);
    if start_residual > 1e-6 {
        return Err(NanofoldError::invalid(
            "fold angles",
            format!("closure residual {start_residual:.3e} rad"),
            "the sweep starts from a rigid state (every vertex within 1e-6 rad)",
        ));
    }
    restore_held(model, &mut rho, driver, &mut solver)?;
    let rank = jacobian_rank(&closure_jacobian(model, &rho))?;
    if rank.dof != 1 {
        return Err(NanofoldError::invalid(
            "fold angles",
            format!("{} degrees of freedom", rank.dof),
            "constraint curves need a state with exactly one degree of freedom (a flat state has more: start from a folded one)",
        ));
    }
    let theta0 = rho[driver];
    if theta0 < a - 1e-9 || theta0 > b + 1e-9 {
        return Err(NanofoldError::invalid(
            "range",
            format!("[{:.4}°, {:.4}°]", a.to_degrees(), b.to_degrees()),
            format!(
                "must contain the driver's angle in the state, {:.4}°",
                theta0.to_degrees()
            ),
        ));
    }
    let points = 2 * samples - 1;
    let grid: Vec<f64> = (0..points)
        .map(|k| a + (b - a) * k as f64 / (points - 1) as f64)
        .collect();
    let nearest = grid
        .iter()
        .enumerate()
        .min_by(|x, y| (x.1 - theta0).abs().total_cmp(&(y.1 - theta0).abs()))
        .map(|(k, _)| k)
        .expect("at least three points");
    let (states, max_residual) = continue_over_grid(model, &rho, driver, &grid, nearest, &mut solver)?;
    let max_closure_residual = states
        .iter()
        .map(|s| vertex_residuals(model, s).into_iter().fold(0.0, f64::max))
        .fold(max_residual, f64::max);
    Ok(NetworkSweep {
        driver,
        domain,
        driver_values: grid,
        states,
        max_closure_residual,
    })
}

/// The sweep's states at every grid value of the driver, continued from `start` (at the grid
/// point `nearest`) to each end: a secant predictor (the tangent's first), then Newton with
/// the driver held, in steps of at most `SWEEP_STEP`; and the largest residual left.
fn continue_over_grid(
    model: &FoldingModel,
    start: &[f64],
    driver: usize,
    grid: &[f64],
    nearest: usize,
    solver: &mut NormalSolver,
) -> Result<(Vec<Vec<f64>>, f64)> {
    let points = grid.len();
    let mut states = vec![Vec::new(); points];
    let mut max_residual: f64 = 0.0;
    let mut held = None;
    for direction in [1_i64, -1] {
        let mut state = start.to_vec();
        // The state before, for the secant predictor (the tangent's first, where none).
        let mut before: Option<Vec<f64>> = None;
        let mut k = nearest as i64;
        while (0..points as i64).contains(&k) {
            let target = grid[k as usize];
            let gap = target - state[driver];
            let substeps = (gap.abs() / SWEEP_STEP).ceil().max(1.0) as usize;
            for j in 1..=substeps {
                let aim = if j == substeps {
                    target
                } else {
                    state[driver] + gap / substeps as f64
                };
                let step = aim - state[driver];
                if step == 0.0 {
                    continue;
                }
                let secant = before
                    .as_ref()
                    .filter(|b| (state[driver] - b[driver]).abs() > 1e-12)
                    .map(|b| (b, step / (state[driver] - b[driver])));
                let direction: Vec<f64> = match secant {
                    Some((b, scale)) => state.iter().zip(b.iter()).map(|(s, b)| (s - b) * scale).collect(),
                    None => tangent(model, &state, driver, solver)?
                        .iter()
                        .map(|t| t * step)
                        .collect(),
                };
                before = Some(state.clone());
                for (x, dx) in state.iter_mut().zip(&direction) {
                    *x += dx;
                }
                // The driver is held exactly at its grid value (Newton leaves it alone).
                state[driver] = aim;
                max_residual = max_residual.max(restore_held_chord(model, &mut state, driver, solver, &mut held)?);
            }
            states[k as usize] = state.clone();
            k += direction;
        }
    }
    Ok((states, max_residual))
}

/// Fits every crease but the driver with a degree-`degree` polynomial on the even sweep
/// points; errors are measured at all of them.
pub fn fit_network(model: &FoldingModel, sweep: &NetworkSweep, degree: usize) -> Result<NetworkCurves> {
    if !(1..=MAX_DEGREE).contains(&degree) {
        return Err(NanofoldError::invalid(
            "degree",
            degree,
            format!("must lie in [1, {MAX_DEGREE}]"),
        ));
    }
    let fitted: Vec<usize> = (0..sweep.driver_values.len()).step_by(2).collect();
    let x: Vec<f64> = fitted.iter().map(|&k| sweep.driver_values[k]).collect();
    let mut curves = Vec::with_capacity(model.crease_count().saturating_sub(1));
    for column in (0..model.crease_count()).filter(|&c| c != sweep.driver) {
        let y: Vec<f64> = fitted.iter().map(|&k| sweep.states[k][column]).collect();
        let chebyshev = Chebyshev::fit(&x, &y, degree, sweep.domain)?;
        let coeffs_rad = chebyshev.monomial_coefficients();
        let (mut fit_error, mut monomial_error) = (0.0_f64, 0.0_f64);
        for (k, &theta) in sweep.driver_values.iter().enumerate() {
            let exact = sweep.states[k][column];
            fit_error = fit_error.max((chebyshev.eval(theta) - exact).abs());
            monomial_error = monomial_error.max((eval_monomial(&coeffs_rad, theta) - exact).abs());
        }
        let edge = model.pattern.creases[column];
        curves.push(NetworkCurve {
            edge,
            assignment: letter(model.pattern.kinds[edge]),
            chebyshev,
            coeffs_rad,
            max_fit_error_rad: fit_error,
            max_monomial_error_rad: monomial_error,
        });
    }
    let max_fit_error_rad = curves
        .iter()
        .map(|c| c.max_fit_error_rad.max(c.max_monomial_error_rad))
        .fold(0.0, f64::max);
    Ok(NetworkCurves {
        pattern: model.pattern.name.clone(),
        driver_edge: model.pattern.creases[sweep.driver],
        domain_rad: sweep.domain,
        domain_deg: sweep.domain.map(f64::to_degrees),
        samples: fitted.len(),
        degree,
        max_closure_residual_rad: sweep.max_closure_residual,
        max_fit_error_rad,
        curves,
    })
}

/// The smallest degree whose error (both forms) is at most `tol`.
pub fn fit_network_to_tolerance(model: &FoldingModel, sweep: &NetworkSweep, tol: f64) -> Result<NetworkCurves> {
    if !(tol.is_finite() && tol > 0.0) {
        return Err(NanofoldError::invalid(
            "tolerance",
            tol,
            "must be a positive number of radians",
        ));
    }
    let highest = MAX_DEGREE.min(sweep.driver_values.len().div_ceil(2) - 1);
    let mut best = (f64::INFINITY, 0);
    for degree in 1..=highest {
        let curves = fit_network(model, sweep, degree)?;
        if curves.max_fit_error_rad <= tol {
            return Ok(curves);
        }
        if curves.max_fit_error_rad < best.0 {
            best = (curves.max_fit_error_rad, degree);
        }
    }
    Err(NanofoldError::invalid(
        "tolerance",
        format!("{tol:e}"),
        format!(
            "no degree ≤ {highest} meets it: the best is {:.3e} rad at degree {}",
            best.0, best.1
        ),
    ))
}

/// MuJoCo `<equality>` couplings, one per crease (joint `crease_<edge>`, the driver
/// `crease_<driver edge>`), polycoef the monomial coefficients about the flat state.
pub fn network_mujoco(curves: &NetworkCurves) -> Result<String> {
    if curves.degree > 4 {
        return Err(NanofoldError::invalid(
            "degree",
            curves.degree,
            "MuJoCo's polycoef holds a quartic at most: fit degree 4 or lower for MuJoCo",
        ));
    }
    let mut xml = String::new();
    let _ = writeln!(
        xml,
        "<!-- nanofold constraints: pattern \"{}\", driver crease_{}, fitted on [{:.6}, {:.6}] rad, degree {}.\n     \
         Joints are the creases' fold angles in rad (valley positive), named by FOLD edge index;\n     \
         reference configuration the flat state (ref = 0). Largest fit error {:.3e} rad. -->",
        curves.pattern,
        curves.driver_edge,
        curves.domain_rad[0],
        curves.domain_rad[1],
        curves.degree,
        curves.max_fit_error_rad
    );
    let _ = writeln!(xml, "<equality>");
    for curve in &curves.curves {
        let mut coeffs = curve.coeffs_rad.clone();
        coeffs.resize(5, 0.0);
        let _ = writeln!(
            xml,
            "  <joint name=\"couple_{e}\" joint1=\"crease_{e}\" joint2=\"crease_{d}\" polycoef=\"{p}\"/> <!-- {a}, max error {err:.3e} rad -->",
            e = curve.edge,
            d = curves.driver_edge,
            p = coeffs.iter().map(|c| format!("{c:.17e}")).collect::<Vec<_>>().join(" "),
            a = curve.assignment,
            err = curve.max_fit_error_rad.max(curve.max_monomial_error_rad)
        );
    }
    let _ = writeln!(xml, "</equality>");
    Ok(xml)
}
