//! Holonomic constraint curves θ_r = f(θ_c) of a closed vertex (`docs/model.md#constraint-curves`): which creases
//! drive, hold and follow ([`Setup`]), exact samples (`sweep` or an unfolding), least-squares
//! Chebyshev fits ([`ConstraintPoly`], with the Jacobian G of T4.18 and its rate), and the
//! exported report with its errors against exact loop closure.

pub(crate) mod chebyshev;
pub(crate) mod exact;
pub mod network;
pub(crate) mod sweep;
pub use chebyshev::{eval_monomial, Chebyshev};
pub use exact::{ConstraintPoint, ExactConstraint};

use crate::error::{NanofoldError, NumericalError, Result};
use crate::geometry::kinematics::{closure_residual, refine_closure, solve_closure};
use crate::pattern::{Assignment, Chain, VertexPattern};
use chebyshev::FittedCurves;
use serde::Serialize;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// Highest polynomial degree accepted.
pub const MAX_DEGREE: usize = 20;
/// Most samples one sweep takes (each a Newton solve; 100 000 take about a second).
pub const MAX_SAMPLES: usize = 100_000;

/// Which crease drives, which are held and at what angle, which follow. Indices are into
/// [`VertexPattern::creases`].
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// The driving crease.
    pub driver: usize,
    /// Held creases with their angles (rad): user locks, pattern locks, F creases.
    pub locked: Vec<(usize, f64)>,
    /// The creases whose angles are functions of the driver, in file order.
    pub dependents: Vec<usize>,
}

impl Setup {
    /// Validates a driver and user locks (crease index, rad) against the pattern: the chain
    /// must be closed, the driver free, and exactly one degree of freedom must remain.
    pub fn new(pattern: &VertexPattern, driver: usize, user_locks: &[(usize, f64)]) -> Result<Setup> {
        if pattern.chain == Chain::Open {
            return Err(NanofoldError::invalid(
                "chain",
                "open",
                "an open chain has no loop closure: its creases move independently, so there are no constraint curves",
            ));
        }
        let label = |c: usize| pattern.creases[c].label.clone();
        if driver >= pattern.creases.len() {
            return Err(NanofoldError::invalid("drive", driver, "no such crease"));
        }
        let mut locked: Vec<(usize, f64)> = Vec::new();
        for &(crease, angle) in user_locks {
            if crease == driver {
                return Err(NanofoldError::invalid(
                    "lock",
                    pattern.user_index(crease),
                    format!("cannot drive a locked crease ({} is the driver)", label(crease)),
                ));
            }
            if !angle.is_finite() || angle.abs() > PI + 1e-12 {
                return Err(NanofoldError::invalid(
                    "lock",
                    format!("{}={}", pattern.user_index(crease), angle.to_degrees()),
                    "a lock angle must lie in [−180°, 180°]",
                ));
            }
            if pattern.creases[crease].assignment == Assignment::Flat && angle != 0.0 {
                return Err(NanofoldError::invalid(
                    "lock",
                    format!("{}={}", pattern.user_index(crease), angle.to_degrees()),
                    format!("{} is a flat (F) crease and stays at 0°", label(crease)),
                ));
            }
            if locked.iter().any(|&(c, _)| c == crease) {
                return Err(NanofoldError::invalid(
                    "lock",
                    pattern.user_index(crease),
                    "the same crease is locked twice",
                ));
            }
            locked.push((crease, angle));
        }
        let driver_crease = &pattern.creases[driver];
        if driver_crease.locked {
            return Err(NanofoldError::invalid(
                "drive",
                pattern.user_index(driver),
                format!(
                    "cannot drive a locked crease ({} is locked in the pattern)",
                    label(driver)
                ),
            ));
        }
        if driver_crease.assignment == Assignment::Flat {
            return Err(NanofoldError::invalid(
                "drive",
                pattern.user_index(driver),
                format!("cannot drive a flat (F) crease ({})", label(driver)),
            ));
        }
        for (c, crease) in pattern.creases.iter().enumerate() {
            let held_by_pattern = crease.locked || crease.assignment == Assignment::Flat;
            if held_by_pattern && !locked.iter().any(|&(l, _)| l == c) {
                locked.push((c, crease.folded_angle));
            }
        }
        locked.sort_by_key(|&(c, _)| c);
        let dependents: Vec<usize> = (0..pattern.creases.len())
            .filter(|&c| c != driver && !locked.iter().any(|&(l, _)| l == c))
            .collect();
        if dependents.len() > 3 {
            let free = dependents
                .iter()
                .map(|&c| pattern.user_index(c).to_string())
                .collect::<Vec<_>>()
                .join(", ");
            return Err(NanofoldError::invalid(
                "lock",
                format!("{} lock(s)", user_locks.len()),
                format!(
                    "{} creases besides the driver are free ({free}) but loop closure fixes only 3: \
                     lock {} more to leave one degree of freedom",
                    dependents.len(),
                    dependents.len() - 3
                ),
            ));
        }
        if dependents.is_empty() {
            return Err(NanofoldError::invalid(
                "lock",
                format!("{} lock(s)", user_locks.len()),
                "no crease is left to follow the driver",
            ));
        }
        Ok(Setup {
            driver,
            locked,
            dependents,
        })
    }

    /// Ray fold angles with the held creases at their lock values and the others folded.
    pub(crate) fn base_ray_angles(&self, pattern: &VertexPattern) -> Vec<f64> {
        let mut rho = pattern.folded_ray_angles();
        for &(c, value) in &self.locked {
            rho[pattern.creases[c].ray] = value;
        }
        rho
    }
}

/// Where the samples of a curve come from (`docs/model.md#constraint-curves`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    /// Newton loop closure along a kinematic sweep: the exact reference.
    Sweep,
    /// The fold angles along an unfolding trajectory.
    Unfold,
}

/// Exact samples of the constraint curves.
#[derive(Debug, Clone)]
pub struct CurveSamples {
    /// Which creases drive, hold and follow.
    pub setup: Setup,
    /// Where the samples come from.
    pub source: Source,
    /// [a, b] of the driving angle, rad.
    pub domain: [f64; 2],
    /// Driving angle of every sample, ascending, rad.
    pub drive_angles: Vec<f64>,
    /// Every crease's fold angle (file order) at every sample, rad.
    pub fold_angles: Vec<Vec<f64>>,
    /// Largest loop-closure residual of the samples, rad.
    pub max_closure_residual: f64,
}

impl CurveSamples {
    /// The samples of crease `c`.
    pub fn series(&self, crease: usize) -> Vec<f64> {
        self.fold_angles.iter().map(|angles| angles[crease]).collect()
    }
}

/// The default sweep domain: from flat to the driver's folded angle.
pub fn default_domain(pattern: &VertexPattern, driver: usize) -> Result<[f64; 2]> {
    let folded = pattern.creases[driver].folded_angle;
    if folded.abs() < 1e-9 {
        return Err(NanofoldError::invalid(
            "range",
            "(default)",
            format!(
                "{} is flat in the folded state, so the default domain (flat to folded) is empty: give one",
                pattern.creases[driver].label
            ),
        ));
    }
    Ok(if folded > 0.0 { [0.0, folded] } else { [folded, 0.0] })
}

/// Checks a user range [a, b] (rad).
pub fn check_domain(domain: [f64; 2]) -> Result<()> {
    let shown = format!("{}:{}", domain[0].to_degrees(), domain[1].to_degrees());
    if !domain.iter().all(|v| v.is_finite()) || domain[0] >= domain[1] {
        return Err(NanofoldError::invalid("range", shown, "needs finite A < B (degrees)"));
    }
    if domain.iter().any(|v| v.abs() > PI + 1e-12) {
        return Err(NanofoldError::invalid(
            "range",
            shown,
            "fold angles lie in [−180°, 180°]",
        ));
    }
    Ok(())
}

/// Exact samples by a kinematic sweep (see `sweep::sweep`): the driver moves over
/// `domain` (rad) and loop closure is solved at each of `samples` points.
///
/// ```
/// use nanofold::prelude::*;
/// let pattern = load_pattern("patterns/corner_cube.fold".as_ref(), &LoadOptions::default())?;
/// let setup = Setup::new(&pattern, 0, &[(1, 0.0)])?;
/// let samples = sweep_samples(&pattern, &setup, [0.0, std::f64::consts::PI], 101)?;
/// assert!(samples.max_closure_residual < 1e-12);
/// // With the flap closed (crease 0 at 180°) the cube corner stands: creases 2, 3 at 90°.
/// let end = samples.fold_angles.last().unwrap();
/// assert!((end[2].to_degrees() - 90.0).abs() < 1e-6);
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn sweep_samples(pattern: &VertexPattern, setup: &Setup, domain: [f64; 2], samples: usize) -> Result<CurveSamples> {
    check_domain(domain)?;
    if !(2..=MAX_SAMPLES).contains(&samples) {
        return Err(NanofoldError::invalid(
            "samples",
            samples,
            format!("a sweep takes 2 to {MAX_SAMPLES} samples"),
        ));
    }
    sweep::sweep(pattern, setup, domain, samples)
}

/// The pattern to unfold for constraint samples along an unfolding: every held crease of
/// `setup` locked at its folded angle. A lock at another angle is refused (the unfolding
/// starts from the folded state).
pub fn held_pattern(pattern: &VertexPattern, setup: &Setup) -> Result<VertexPattern> {
    let mut held = pattern.clone();
    for &(c, value) in &setup.locked {
        let folded = pattern.creases[c].folded_angle;
        if (value - folded).abs() > 1e-9 {
            return Err(NanofoldError::invalid(
                "lock",
                format!("{}={}", pattern.user_index(c), value.to_degrees()),
                format!(
                    "with samples from an unfolding a lock must equal the crease's folded angle {:.6}° (the unfolding starts from the folded state); use a sweep",
                    folded.to_degrees()
                ),
            ));
        }
        held.creases[c].locked = true;
    }
    Ok(held)
}

/// Samples along an unfolding trajectory of [`held_pattern`]: `fold_angles[k]` every
/// crease's angle at recorded step k (as [`crate::unfold::StepRecord`] holds them), `verdict`
/// the unfolding's verdict (for messages), `flat_tol` its flatness tolerance. `domain`, if
/// given, must lie inside the range the trajectory covers.
///
/// ```no_run
/// # use nanofold::prelude::*;
/// # use nanofold::constraints::{held_pattern, trajectory_samples};
/// # let pattern = load_pattern("patterns/corner_cube.fold".as_ref(), &LoadOptions::default())?;
/// let setup = Setup::new(&pattern, 0, &[(1, pattern.creases[1].folded_angle)])?;
/// let settings = UnfoldSettings::default();
/// let report = unfold_vertex(&held_pattern(&pattern, &setup)?, &settings)?;
/// let states: Vec<Vec<f64>> = report.trajectory.iter().map(|s| s.fold_angles.clone()).collect();
/// let samples = trajectory_samples(&pattern, &setup, None, &states, report.verdict.as_str(), settings.flat_tol)?;
/// # Ok::<(), NanofoldError>(())
/// ```
pub fn trajectory_samples(
    pattern: &VertexPattern,
    setup: &Setup,
    domain: Option<[f64; 2]>,
    fold_angles: &[Vec<f64>],
    verdict: &str,
    flat_tol: f64,
) -> Result<CurveSamples> {
    let driver = setup.driver;
    let mut points: Vec<(f64, Vec<f64>)> = fold_angles
        .iter()
        .map(|angles| (angles[driver], angles.clone()))
        .collect();
    // A step may pass through the flat state, where the branches of the constraint curve
    // meet; points past the driver's first change of sign lie on another branch. The flat
    // end itself (every angle 0) is on all of them and stays.
    let start_sign = points.first().map_or(1.0, |p| p.0.signum());
    if let Some(first_past) = points.iter().position(|p| p.0 * start_sign < -1e-12) {
        let flat_end = points
            .last()
            .filter(|p| p.1.iter().all(|a| a.abs() <= flat_tol))
            .cloned();
        points.truncate(first_past);
        points.extend(flat_end);
    }
    let covered = points.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |r, p| {
        [r[0].min(p.0), r[1].max(p.0)]
    });
    let domain = match domain {
        Some(d) => {
            check_domain(d)?;
            if d[0] < covered[0] - 1e-9 || d[1] > covered[1] + 1e-9 {
                return Err(NanofoldError::invalid(
                    "range",
                    format!("{}:{}", d[0].to_degrees(), d[1].to_degrees()),
                    format!(
                        "the unfolding trajectory covers {} ∈ [{:.4}°, {:.4}°] only ({})",
                        pattern.creases[driver].label,
                        covered[0].to_degrees(),
                        covered[1].to_degrees(),
                        verdict
                    ),
                ));
            }
            d
        }
        None => covered,
    };
    points.retain(|p| p.0 >= domain[0] - 1e-12 && p.0 <= domain[1] + 1e-12);
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    if domain[0] >= domain[1] || points.len() < 2 {
        return Err(NanofoldError::invalid(
            "source",
            "unfold",
            format!(
                "the unfolding moved {} only over [{:.6}°, {:.6}°]: nothing to fit",
                pattern.creases[driver].label,
                covered[0].to_degrees(),
                covered[1].to_degrees()
            ),
        ));
    }
    let base = setup.base_ray_angles(pattern);
    let mut max_closure_residual: f64 = 0.0;
    for (_, angles) in &points {
        let mut rho = base.clone();
        for (c, crease) in pattern.creases.iter().enumerate() {
            rho[crease.ray] = angles[c];
        }
        max_closure_residual = max_closure_residual.max(closure_residual(&pattern.sector_angles, &rho));
    }
    Ok(CurveSamples {
        setup: setup.clone(),
        source: Source::Unfold,
        domain,
        drive_angles: points.iter().map(|p| p.0).collect(),
        fold_angles: points.into_iter().map(|p| p.1).collect(),
        max_closure_residual,
    })
}

/// θ within `domain` (rad) widened by `margin` and a few ulps, or an `OutsideFitDomain` error.
pub(crate) fn check_in_domain(driver_label: &str, domain: [f64; 2], theta: f64, margin: f64) -> Result<()> {
    let slack = margin + 1e-12 * (1.0 + domain[1].abs().max(domain[0].abs()));
    if theta.is_finite() && theta >= domain[0] - slack && theta <= domain[1] + slack {
        Ok(())
    } else {
        Err(NanofoldError::OutsideFitDomain {
            driver: driver_label.to_string(),
            value_deg: theta.to_degrees(),
            lower_deg: domain[0].to_degrees(),
            upper_deg: domain[1].to_degrees(),
        })
    }
}

/// The fitted constraint θ_r = f(θ_c) for one driving crease: what dynamics consume.
#[derive(Debug, Clone)]
pub struct ConstraintPoly {
    /// Driving crease (index into [`VertexPattern::creases`]) and its label for errors.
    pub driver: usize,
    /// The driver's label, for errors.
    pub driver_label: String,
    /// Held creases and angles (rad).
    pub locked: Vec<(usize, f64)>,
    /// The creases f returns, in this order.
    pub dependents: Vec<usize>,
    /// One series per dependent, on the driving angle's fitted interval (rad).
    pub fitted: FittedCurves,
    /// Largest |f − sample| per dependent, rad.
    pub max_fit_error: Vec<f64>,
    /// Largest |f′ − G| per dependent over the regular samples, G by the implicit function
    /// theorem on the exact closure (rad/rad).
    pub max_slope_error: Vec<f64>,
}

impl ConstraintPoly {
    /// Least-squares fit of degree `degree` (1 ≤ D ≤ 20) to every dependent.
    pub fn fit(pattern: &VertexPattern, samples: &CurveSamples, degree: usize) -> Result<ConstraintPoly> {
        if degree == 0 || degree > MAX_DEGREE {
            return Err(NanofoldError::invalid(
                "degree",
                degree,
                format!("the degree must lie in 1..={MAX_DEGREE}"),
            ));
        }
        // G by the implicit function theorem at every regular sample (the singular flat
        // state has none): the reference for the fit's slope error.
        let exact_slopes: Vec<Option<Vec<f64>>> = samples
            .fold_angles
            .iter()
            .map(|angles| implicit_jacobian(pattern, &samples.setup, angles).ok())
            .collect();
        let mut curves = Vec::new();
        let mut max_fit_error = Vec::new();
        let mut max_slope_error = Vec::new();
        for (k, &c) in samples.setup.dependents.iter().enumerate() {
            let values = samples.series(c);
            let series = Chebyshev::fit(&samples.drive_angles, &values, degree, samples.domain)?;
            let error = samples
                .drive_angles
                .iter()
                .zip(&values)
                .map(|(&x, &y)| (series.eval(x) - y).abs())
                .fold(0.0, f64::max);
            let slope_error = samples
                .drive_angles
                .iter()
                .zip(&exact_slopes)
                .filter_map(|(&x, exact)| exact.as_ref().map(|g| (series.eval_with_derivatives(x).1 - g[k]).abs()))
                .fold(0.0, f64::max);
            curves.push(series);
            max_fit_error.push(error);
            max_slope_error.push(slope_error);
        }
        Ok(ConstraintPoly {
            driver: samples.setup.driver,
            driver_label: pattern.creases[samples.setup.driver].label.clone(),
            locked: samples.setup.locked.clone(),
            dependents: samples.setup.dependents.clone(),
            fitted: FittedCurves {
                domain: samples.domain,
                curves,
            },
            max_fit_error,
            max_slope_error,
        })
    }

    /// Polynomial degree.
    pub fn degree(&self) -> usize {
        self.fitted.degree()
    }

    fn check_domain(&self, theta: f64) -> Result<()> {
        self.check_extended_domain(theta, 0.0)
    }

    fn check_extended_domain(&self, theta: f64, margin: f64) -> Result<()> {
        check_in_domain(&self.driver_label, self.fitted.domain, theta, margin)
    }

    /// f(θ_c): the dependents' angles, written into `out` (one per dependent).
    pub fn eval_into(&self, theta: f64, out: &mut [f64]) -> Result<()> {
        self.check_domain(theta)?;
        for (o, curve) in out.iter_mut().zip(&self.fitted.curves) {
            *o = curve.eval(theta);
        }
        Ok(())
    }

    /// G = ∂f/∂θ_c (T4.18), one entry per dependent.
    pub fn jacobian_into(&self, theta: f64, out: &mut [f64]) -> Result<()> {
        self.check_domain(theta)?;
        for (o, curve) in out.iter_mut().zip(&self.fitted.curves) {
            *o = curve.eval_with_derivatives(theta).1;
        }
        Ok(())
    }

    /// Ġ = d/dt ∂f/∂θ_c = f″(θ_c) θ̇_c, for the Ġ θ̇_c term of the closed-chain equations.
    pub fn jacobian_dot_into(&self, theta: f64, theta_dot: f64, out: &mut [f64]) -> Result<()> {
        self.check_domain(theta)?;
        for (o, curve) in out.iter_mut().zip(&self.fitted.curves) {
            *o = curve.eval_with_derivatives(theta).2 * theta_dot;
        }
        Ok(())
    }

    /// f, G = f′ and f″ at θ_c in one pass (the closed-chain equations need all three).
    pub fn evaluate(&self, theta: f64, point: &mut exact::ConstraintPoint) -> Result<()> {
        self.evaluate_extended(theta, 0.0, point)
    }

    /// [`ConstraintPoly::evaluate`] that also extrapolates up to `margin` (rad) beyond the
    /// fitted domain (an integrator's trial stages may overshoot it; the caller checks the
    /// accepted states).
    pub fn evaluate_extended(&self, theta: f64, margin: f64, point: &mut exact::ConstraintPoint) -> Result<()> {
        self.check_extended_domain(theta, margin)?;
        self.fitted
            .evaluate(theta, &mut point.values, &mut point.jacobian, &mut point.curvature);
        Ok(())
    }

    /// f(θ_c) as a new vector.
    pub fn eval(&self, theta: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.fitted.curves.len()];
        self.eval_into(theta, &mut out)?;
        Ok(out)
    }

    /// G(θ_c) as a new vector.
    pub fn jacobian(&self, theta: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.fitted.curves.len()];
        self.jacobian_into(theta, &mut out)?;
        Ok(out)
    }

    /// Ġ(θ_c, θ̇_c) as a new vector.
    pub fn jacobian_dot(&self, theta: f64, theta_dot: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.fitted.curves.len()];
        self.jacobian_dot_into(theta, theta_dot, &mut out)?;
        Ok(out)
    }

    /// Every crease's angle (file order) at driving angle θ: driver, locks and f(θ).
    pub fn fold_angles(&self, crease_count: usize, theta: f64) -> Result<Vec<f64>> {
        let mut angles = vec![0.0; crease_count];
        angles[self.driver] = theta;
        for &(c, value) in &self.locked {
            angles[c] = value;
        }
        let values = self.eval(theta)?;
        for (&c, v) in self.dependents.iter().zip(values) {
            angles[c] = v;
        }
        Ok(angles)
    }
}

/// G = ∂f/∂θ_c from the implicit function theorem on exact loop closure (T4.18):
/// J_dep G = −J_driver, with J the closure Jacobian at the given crease angles (file order,
/// which must close the loop). An error at a singular configuration, where G is undefined.
pub fn implicit_jacobian(pattern: &VertexPattern, setup: &Setup, crease_angles: &[f64]) -> Result<Vec<f64>> {
    let mut rho = setup.base_ray_angles(pattern);
    for (c, crease) in pattern.creases.iter().enumerate() {
        rho[crease.ray] = crease_angles[c];
    }
    let dependent_rays: Vec<usize> = setup.dependents.iter().map(|&c| pattern.creases[c].ray).collect();
    let driver_ray = pattern.creases[setup.driver].ray;
    let g = exact::implicit_jacobian_rays(&pattern.sector_angles, &rho, &[driver_ray], &dependent_rays).map_err(
        |e| match e {
            NanofoldError::Numerical(NumericalError::Singular { what, detail }) => NumericalError::Singular {
                what,
                detail: format!(
                    "{detail}: the dependents are not a function of {} here",
                    pattern.creases[setup.driver].label
                ),
            }
            .into(),
            other => other,
        },
    )?;
    Ok(g.iter().copied().collect())
}

/// One exported curve.
#[derive(Debug, Clone, Serialize)]
pub struct CurveReport {
    /// The crease's user index (FOLD edge index for FOLD input).
    pub crease: usize,
    /// The crease's label (`edges[3]`).
    pub label: String,
    /// c_0 … c_D: θ in rad → rad, ascending powers.
    pub coeffs_rad: Vec<f64>,
    /// The same curve with θ and result in degrees.
    pub coeffs_deg: Vec<f64>,
    /// The well-conditioned form: Chebyshev coefficients on `domain_rad`.
    pub chebyshev_coeffs: Vec<f64>,
    /// Largest |polynomial (monomial form) − exact sample|, rad.
    pub max_fit_error_rad: f64,
    /// Largest |f′ − G| over the regular samples, G by the implicit function theorem.
    pub max_slope_error: f64,
    /// Loop-closure residual with this crease on its polynomial and the others exact,
    /// largest over a grid 10× finer than the samples, rad.
    pub max_closure_residual: f64,
}

/// What `nanofold constraints` exports.
#[derive(Debug, Clone, Serialize)]
pub struct ConstraintReport {
    /// The pattern's name.
    pub pattern: String,
    /// Where the samples came from.
    pub source: Source,
    /// The driving crease's user index.
    pub driver: usize,
    /// The driver's label.
    pub driver_label: String,
    /// Held creases: user index → angle in rad.
    pub locked: BTreeMap<String, f64>,
    /// Polynomial degree.
    pub degree: usize,
    /// The fitted interval of the driving angle, rad.
    pub domain_rad: [f64; 2],
    /// The same in degrees.
    pub domain_deg: [f64; 2],
    /// Exact samples fitted.
    pub samples: usize,
    /// Largest loop-closure residual of the samples themselves, rad.
    pub samples_max_closure_residual: f64,
    /// Loop-closure residual with every dependent on its polynomial, over the fine grid, rad.
    pub max_closure_residual: f64,
    /// One curve per dependent crease.
    pub curves: Vec<CurveReport>,
    /// Curves given by the user (a published table), checked against the exact samples.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub checked_curves: Vec<CheckedCurve>,
}

/// A given polynomial for one dependent crease (`coeffs_deg`: θ and result in degrees,
/// ascending powers, as the thesis's Table 2), measured against the exact samples.
#[derive(Debug, Clone, Serialize)]
pub struct CheckedCurve {
    /// The crease's user index.
    pub crease: usize,
    /// Its label.
    pub label: String,
    /// The coefficients as given.
    pub coeffs_deg: Vec<f64>,
    /// Largest |polynomial − exact| over the samples, rad.
    pub max_error_rad: f64,
    /// The driving angle where it occurs, degrees.
    pub max_error_at_deg: f64,
    /// The domain's end farthest from flat (the folded state), degrees.
    pub folded_end_deg: f64,
    /// polynomial − exact there, rad.
    pub folded_end_error_rad: f64,
}

/// Most coefficients a checked curve may have (degree 20, as fits).
pub const MAX_CHECKED_COEFFICIENTS: usize = MAX_DEGREE + 1;

/// Measures the polynomial `coeffs_deg` (degrees → degrees, ascending powers) of crease `c`
/// (internal index) against the exact samples: a published curve's error, in the same
/// terms as a fit's.
pub fn check_curve(
    pattern: &VertexPattern,
    samples: &CurveSamples,
    c: usize,
    coeffs_deg: &[f64],
) -> Result<CheckedCurve> {
    let setup = &samples.setup;
    let label = pattern
        .creases
        .get(c)
        .map(|crease| crease.label.clone())
        .ok_or_else(|| {
            NanofoldError::invalid(
                "crease",
                c,
                format!("the pattern has {} creases", pattern.creases.len()),
            )
        })?;
    if !setup.dependents.contains(&c) {
        let role = if c == setup.driver {
            "the driver"
        } else {
            "held (locked)"
        };
        return Err(NanofoldError::invalid(
            "crease",
            &label,
            format!("is {role}: a checked curve belongs to a crease that follows the driver"),
        ));
    }
    if coeffs_deg.is_empty() || coeffs_deg.len() > MAX_CHECKED_COEFFICIENTS {
        return Err(NanofoldError::invalid(
            "coeffs_deg",
            format!("{} coefficients", coeffs_deg.len()),
            format!("give 1 to {MAX_CHECKED_COEFFICIENTS} (degree 0 to {MAX_DEGREE})"),
        ));
    }
    if let Some(k) = coeffs_deg.iter().position(|x| !x.is_finite()) {
        return Err(NanofoldError::invalid(
            format!("coeffs_deg[{k}]"),
            coeffs_deg[k],
            "must be a finite number",
        ));
    }
    let (mut max_error, mut at) = (0.0_f64, samples.domain[0]);
    let (mut end, mut end_error) = (0.0_f64, 0.0);
    for (&drive, angles) in samples.drive_angles.iter().zip(&samples.fold_angles) {
        let value_deg = coeffs_deg
            .iter()
            .rev()
            .fold(0.0, |acc, &k| acc * drive.to_degrees() + k);
        let error = value_deg.to_radians() - angles[c];
        if error.abs() > max_error {
            (max_error, at) = (error.abs(), drive);
        }
        if drive.abs() >= end.abs() {
            (end, end_error) = (drive, error);
        }
    }
    Ok(CheckedCurve {
        crease: pattern.user_index(c),
        label,
        coeffs_deg: coeffs_deg.to_vec(),
        max_error_rad: max_error,
        max_error_at_deg: at.to_degrees(),
        folded_end_deg: end.to_degrees(),
        folded_end_error_rad: end_error,
    })
}

impl ConstraintReport {
    /// Evaluates the fit: monomial coefficients, errors against the samples, and loop
    /// closure on a grid 10× finer than the samples.
    pub fn new(pattern: &VertexPattern, samples: &CurveSamples, poly: &ConstraintPoly) -> Result<ConstraintReport> {
        let setup = &samples.setup;
        let base = setup.base_ray_angles(pattern);
        let driver_ray = pattern.creases[setup.driver].ray;
        let free_rays: Vec<usize> = setup.dependents.iter().map(|&c| pattern.creases[c].ray).collect();
        let fine_count = 10 * (samples.drive_angles.len() - 1) + 1;
        let mut all_poly_residual: f64 = 0.0;
        let mut per_curve = vec![0.0_f64; setup.dependents.len()];
        let mut fitted = vec![0.0; setup.dependents.len()];
        for i in 0..fine_count {
            let theta = poly.fitted.domain[0]
                + (poly.fitted.domain[1] - poly.fitted.domain[0]) * i as f64 / (fine_count - 1) as f64;
            poly.eval_into(theta, &mut fitted)?;
            let mut rho = base.clone();
            rho[driver_ray] = theta;
            for (&ray, &value) in free_rays.iter().zip(&fitted) {
                rho[ray] = value;
            }
            all_poly_residual = all_poly_residual.max(closure_residual(&pattern.sector_angles, &rho));
            // The exact configuration nearest the polynomial's (same branch: the fit is close).
            let mut exact = rho.clone();
            solve_closure(&pattern.sector_angles, &mut exact, &free_rays, sweep::CLOSURE_TOL, 30)?;
            refine_closure(&pattern.sector_angles, &mut exact, &free_rays, sweep::REFINE_ITERATIONS);
            for (j, &ray) in free_rays.iter().enumerate() {
                let mut mixed = exact.clone();
                mixed[ray] = fitted[j];
                per_curve[j] = per_curve[j].max(closure_residual(&pattern.sector_angles, &mixed));
            }
        }
        let mut curves = Vec::new();
        for (j, &c) in setup.dependents.iter().enumerate() {
            let coeffs_rad = poly.fitted.curves[j].monomial_coefficients();
            let coeffs_deg: Vec<f64> = coeffs_rad
                .iter()
                .enumerate()
                .map(|(k, &m)| m * (PI / 180.0).powi(k as i32 - 1))
                .collect();
            let values = samples.series(c);
            let monomial_error = samples
                .drive_angles
                .iter()
                .zip(&values)
                .map(|(&x, &y)| (eval_monomial(&coeffs_rad, x) - y).abs())
                .fold(0.0, f64::max);
            curves.push(CurveReport {
                crease: pattern.user_index(c),
                label: pattern.creases[c].label.clone(),
                coeffs_rad,
                coeffs_deg,
                chebyshev_coeffs: poly.fitted.curves[j].coeffs.clone(),
                max_fit_error_rad: monomial_error.max(poly.max_fit_error[j]),
                max_slope_error: poly.max_slope_error[j],
                max_closure_residual: per_curve[j],
            });
        }
        Ok(ConstraintReport {
            pattern: pattern.name.clone(),
            source: samples.source,
            driver: pattern.user_index(setup.driver),
            driver_label: pattern.creases[setup.driver].label.clone(),
            locked: setup
                .locked
                .iter()
                .map(|&(c, v)| (pattern.user_index(c).to_string(), v))
                .collect(),
            degree: poly.degree(),
            domain_rad: poly.fitted.domain,
            domain_deg: [poly.fitted.domain[0].to_degrees(), poly.fitted.domain[1].to_degrees()],
            samples: samples.drive_angles.len(),
            samples_max_closure_residual: samples.max_closure_residual,
            max_closure_residual: all_poly_residual,
            curves,
            checked_curves: Vec::new(),
        })
    }

    /// Largest fit error over the curves, rad.
    pub fn max_fit_error(&self) -> f64 {
        self.curves.iter().map(|c| c.max_fit_error_rad).fold(0.0, f64::max)
    }
}

/// The smallest degree (1…20) whose fit error (Chebyshev and monomial forms) is ≤ `tol`.
pub fn fit_to_tolerance(
    pattern: &VertexPattern,
    samples: &CurveSamples,
    tol: f64,
) -> Result<(ConstraintPoly, ConstraintReport)> {
    if !tol.is_finite() || tol <= 0.0 {
        return Err(NanofoldError::invalid(
            "tolerance",
            tol,
            "must be a positive number of radians",
        ));
    }
    let highest = MAX_DEGREE.min(samples.drive_angles.len() - 1);
    let mut best = (f64::INFINITY, 0);
    for degree in 1..=highest {
        let poly = ConstraintPoly::fit(pattern, samples, degree)?;
        // Cheap screen on the Chebyshev form before the full report.
        let screen = poly.max_fit_error.iter().copied().fold(0.0, f64::max);
        if screen > tol {
            if screen < best.0 {
                best = (screen, degree);
            }
            continue;
        }
        let report = ConstraintReport::new(pattern, samples, &poly)?;
        if report.max_fit_error() <= tol {
            return Ok((poly, report));
        }
        if report.max_fit_error() < best.0 {
            best = (report.max_fit_error(), degree);
        }
    }
    Err(NanofoldError::invalid(
        "tolerance",
        format!("{tol:e}"),
        format!(
            "no degree ≤ {highest} meets it: the best is {:.3e} rad at degree {}; narrow the domain or raise the tolerance",
            best.0, best.1
        ),
    ))
}

/// The MuJoCo `<equality>` snippet: one `<joint>` coupling per curve (joint1 = dependent,
/// joint2 = driver) and one per locked crease. MuJoCo's polycoef is a quartic in
/// (x − x0) giving y − y0 about the reference configuration; here that is the flat state
/// (joint ref = 0), so polycoef are the monomial coefficients in rad.
pub fn mujoco_snippet(report: &ConstraintReport) -> Result<String> {
    if report.degree > 4 {
        return Err(NanofoldError::invalid(
            "degree",
            report.degree,
            "MuJoCo's polycoef holds a quartic at most: fit degree 4 or lower for MuJoCo",
        ));
    }
    let joint = |i: usize| format!("crease_{i}");
    let mut xml = String::new();
    let _ = writeln!(
        xml,
        "<!-- nanofold constraints: pattern \"{}\", driver {} ({}), fitted on [{:.6}, {:.6}] rad ({} samples, source {:?}).\n     \
         Joints are the creases' fold angles in rad, valley positive. Reference configuration: the flat\n     \
         state (joint ref = 0), so y = a0 + a1 x + ... + a4 x^4 with x the driver. Outside the fitted\n     \
         range the polynomial is an extrapolation. -->",
        report.pattern,
        joint(report.driver),
        report.driver_label,
        report.domain_rad[0],
        report.domain_rad[1],
        report.samples,
        report.source
    );
    let _ = writeln!(xml, "<equality>");
    for curve in &report.curves {
        let mut coeffs = curve.coeffs_rad.clone();
        coeffs.resize(5, 0.0);
        let _ = writeln!(
            xml,
            "  <!-- {} ({}): max fit error {:.3e} rad, max loop-closure residual {:.3e} rad -->",
            joint(curve.crease),
            curve.label,
            curve.max_fit_error_rad,
            curve.max_closure_residual
        );
        let _ = writeln!(
            xml,
            "  <joint joint1=\"{}\" joint2=\"{}\" polycoef=\"{}\"/>",
            joint(curve.crease),
            joint(report.driver),
            coeffs.iter().map(|c| format!("{c:.17e}")).collect::<Vec<_>>().join(" ")
        );
    }
    for (crease, value) in &report.locked {
        let _ = writeln!(xml, "  <!-- crease_{crease}: locked -->");
        let _ = writeln!(
            xml,
            "  <joint joint1=\"crease_{crease}\" polycoef=\"{value:.17e} 0 0 0 0\"/>"
        );
    }
    let _ = writeln!(xml, "</equality>");
    Ok(xml)
}
