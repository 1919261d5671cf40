//! Constraint curves behind the door (`docs/model.md#constraint-curves`): every free crease
//! as a polynomial of one driving crease, swept exactly, for a single vertex or a folded
//! crease pattern of many vertices with one degree of freedom.

use super::Pattern;
use crate::constraints::network::{fit_network, fit_network_to_tolerance, network_sweep, NetworkCurves, NetworkSweep};
use crate::constraints::{
    check_curve, default_domain, fit_to_tolerance, held_pattern, sweep_samples, trajectory_samples, ConstraintPoly,
    ConstraintReport, CurveSamples, Setup,
};
use crate::error::{NanofoldError, Result};
use crate::folding::FoldingModel;
use crate::names::Named;
use serde_json::Value;

/// Most sweep samples × creases of a crease pattern of many vertices (a 174 × 174
/// Miura-ori's 60 204 creases: 83 samples; timings in `docs/guide/limits.md`).
pub const MAX_SWEEP_WORK: usize = 5_000_000;

/// How the curves' degree is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Degree {
    /// This degree (1 to 20).
    Fixed(usize),
    /// The lowest degree whose fit error is at most `tol` rad. Below 20, `at_most` caps it:
    /// none meeting `tol` gives `at_most` with the error it has (MuJoCo takes a quartic at
    /// most); at 20, none meeting `tol` is an error.
    Auto {
        /// Largest accepted fit error, rad.
        tol: f64,
        /// Highest degree tried.
        at_most: usize,
    },
}

/// What `constraints` sweeps and fits.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintSettings {
    /// The driving crease, by the file's index (a FOLD edge index; for a native vertex its
    /// position in `creases`).
    pub drive: usize,
    /// Creases held at angles (file index, rad); the others close every vertex around them.
    pub lock: Vec<(usize, f64)>,
    /// When not empty: the only creases left free besides the driver (every other held at
    /// its folded angle, unless `lock` sets its angle).
    pub free: Vec<usize>,
    /// The curves' degree.
    pub degree: Degree,
    /// The driving angle's range, rad (None: flat to the folded angle; for many vertices
    /// from 5% of it, as the flat state is a branch point).
    pub range: Option<[f64; 2]>,
    /// Sweep samples (2 to 100 000).
    pub samples: usize,
    /// Where the samples come from (a single vertex may take its unfolding's).
    pub source: CurveSource,
    /// Given polynomials to measure against exact closure: (crease by the file's index,
    /// coefficients in degrees of the driving angle in degrees, constant first).
    pub checks: Vec<(usize, Vec<f64>)>,
}

/// Where constraint samples come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveSource {
    /// Newton loop closure along a kinematic sweep: the exact reference.
    #[default]
    Sweep,
    /// The fold angles along an unfolding trajectory (single vertices).
    Unfold,
}

impl Default for ConstraintSettings {
    fn default() -> Self {
        ConstraintSettings {
            drive: 0,
            lock: Vec::new(),
            free: Vec::new(),
            degree: Degree::Fixed(4),
            range: None,
            samples: 201,
            source: CurveSource::Sweep,
            checks: Vec::new(),
        }
    }
}

/// The curves with the samples they were fitted to.
#[derive(Debug, Clone)]
pub enum Constraints {
    /// A single vertex's curves.
    Vertex {
        /// The exact sweep.
        samples: Box<CurveSamples>,
        /// The fitted polynomials.
        poly: Box<ConstraintPoly>,
        /// Their errors against loop closure.
        report: Box<ConstraintReport>,
    },
    /// A crease pattern's curves.
    Network {
        /// The exact sweep.
        sweep: Box<NetworkSweep>,
        /// The fitted curves with their errors.
        curves: Box<NetworkCurves>,
    },
}

/// The curves serialise as their report (the fitted coefficients with their errors): what
/// `nanofold constraints --json` prints and constraints.json holds.
impl serde::Serialize for Constraints {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Constraints::Vertex { report, .. } => report.serialize(serializer),
            Constraints::Network { curves, .. } => curves.serialize(serializer),
        }
    }
}

impl Constraints {
    /// As `nanofold constraints --json` prints it: its own serialisation.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }

    /// The largest fit error of any curve, rad.
    pub fn max_fit_error_rad(&self) -> f64 {
        match self {
            Constraints::Vertex { report, .. } => report.max_fit_error(),
            Constraints::Network { curves, .. } => curves.max_fit_error_rad,
        }
    }
}

/// The files `constraints` writes (rendered, not written): constraints.json (the curves
/// with their errors, as `--json` prints them), constraints.svg and, for MuJoCo,
/// constraints.xml (the curves as equality constraints).
#[cfg(feature = "plot")]
pub fn constraints_files(
    pattern: &Pattern,
    result: &Constraints,
    format: super::CurveFormat,
) -> Result<Vec<(&'static str, String)>> {
    let json = serde_json::to_string_pretty(result)
        .map_err(|e| NanofoldError::invalid("constraints.json", "JSON", e.to_string()))?;
    let mujoco = format == super::CurveFormat::Mujoco;
    let mut files = vec![("constraints.json", json)];
    match (result, pattern.vertex()) {
        (Constraints::Vertex { samples, poly, report }, Some(vertex)) => {
            files.push(("constraints.svg", crate::plot::constraints_svg(vertex, samples, poly)?));
            if mujoco {
                files.push(("constraints.xml", crate::constraints::mujoco_snippet(report)?));
            }
        }
        (Constraints::Network { sweep, curves }, _) => {
            files.push((
                "constraints.svg",
                crate::plot::folding::network_constraints_svg(sweep, curves)?,
            ));
            if mujoco {
                files.push(("constraints.xml", crate::constraints::network::network_mujoco(curves)?));
            }
        }
        (Constraints::Vertex { .. }, None) => {
            return Err(NanofoldError::invalid(
                "pattern",
                pattern.name(),
                "a single vertex's curves are not this pattern's",
            ))
        }
    }
    Ok(files)
}

impl ConstraintSettings {
    /// Checks the numbers a caller hands over: every held angle a finite fold angle in
    /// [−180°, 180°], a range of finite ends (a checked curve's coefficients are checked
    /// with the curve).
    pub fn validate(&self) -> Result<()> {
        for (crease, angle) in &self.lock {
            if !(angle.is_finite() && angle.abs() <= std::f64::consts::PI) {
                return Err(NanofoldError::invalid(
                    "lock",
                    format!("{crease}={}", angle.to_degrees()),
                    "a held angle is a finite fold angle in [-180°, 180°]",
                ));
            }
        }
        if let Some([a, b]) = self.range {
            if !(a.is_finite() && b.is_finite()) {
                return Err(NanofoldError::invalid(
                    "range",
                    format!("{}:{}", a.to_degrees(), b.to_degrees()),
                    "needs finite A < B (degrees)",
                ));
            }
        }
        Ok(())
    }
}

/// Sweeps the driver across its range by exact loop closure and fits every free crease.
pub fn constraints(pattern: &Pattern, settings: &ConstraintSettings) -> Result<Constraints> {
    settings.validate()?;
    let swept = match pattern.vertex() {
        Some(vertex) => vertex_constraints(vertex, settings),
        None => {
            let model = pattern
                .sheet()
                .ok_or_else(|| NanofoldError::invalid("pattern", pattern.name(), "has neither a vertex nor a sheet"))?;
            network_constraints(model, settings)
        }
    };
    // A sweep that cannot go on says which settings set it going.
    swept.map_err(|error| match error {
        NanofoldError::Unreachable { what, reached, reason } => NanofoldError::Unreachable {
            what: format!("{what} (sweeping `drive` over `range`, every `lock` held)"),
            reached,
            reason,
        },
        other => other,
    })
}

fn vertex_constraints(pattern: &crate::pattern::VertexPattern, settings: &ConstraintSettings) -> Result<Constraints> {
    let index = |i: usize, field: &str| {
        pattern.crease_from_user_index(i).ok_or_else(|| {
            NanofoldError::invalid(
                field,
                i,
                format!(
                    "no crease with this index in {} (its creases are {:?})",
                    pattern.name,
                    pattern.user_indices()
                ),
            )
        })
    };
    let driver = index(settings.drive, "drive")?;
    let mut locks = settings
        .lock
        .iter()
        .map(|&(i, angle)| Ok((index(i, "lock")?, angle)))
        .collect::<Result<Vec<_>>>()?;
    if !settings.free.is_empty() {
        let free = settings
            .free
            .iter()
            .map(|&i| index(i, "free"))
            .collect::<Result<Vec<_>>>()?;
        for (c, crease) in pattern.creases.iter().enumerate() {
            if c != driver && !free.contains(&c) && !locks.iter().any(|(l, _)| *l == c) {
                locks.push((c, crease.folded_angle));
            }
        }
    }
    let checks = settings
        .checks
        .iter()
        .map(|(i, coefficients)| Ok((index(*i, "check")?, coefficients)))
        .collect::<Result<Vec<_>>>()?;
    // With `free`, the locks are the creases it leaves out: a refusal of them is of `free`.
    let setup = Setup::new(pattern, driver, &locks).map_err(|error| match error {
        NanofoldError::InvalidField { field, value, reason } if field == "lock" && !settings.free.is_empty() => {
            NanofoldError::InvalidField {
                field: "free".into(),
                value: format!("{:?} ({value})", settings.free),
                reason,
            }
        }
        other => other,
    })?;
    for &(crease, _) in &checks {
        if !setup.dependents.contains(&crease) {
            return Err(NanofoldError::invalid(
                "check",
                pattern.user_index(crease),
                format!(
                    "{} is {}; a checked curve belongs to a crease that follows the driver",
                    pattern.creases[crease].label,
                    if crease == driver {
                        "the driver"
                    } else {
                        "held by lock or free"
                    }
                ),
            ));
        }
    }
    let samples = match settings.source {
        CurveSource::Sweep => {
            let domain = match settings.range {
                Some(d) => d,
                None => default_domain(pattern, driver)?,
            };
            sweep_samples(pattern, &setup, domain, settings.samples)?
        }
        CurveSource::Unfold => {
            let unfolding = crate::unfold::UnfoldSettings::default();
            let report = crate::unfold::unfold(&held_pattern(pattern, &setup)?, &unfolding)?;
            let states: Vec<Vec<f64>> = report.trajectory.iter().map(|s| s.fold_angles.clone()).collect();
            trajectory_samples(
                pattern,
                &setup,
                settings.range,
                &states,
                report.verdict.as_str(),
                unfolding.flat_tol,
            )?
        }
    };
    let (poly, report) = match settings.degree {
        Degree::Fixed(d) => {
            let poly = ConstraintPoly::fit(pattern, &samples, d)?;
            let report = ConstraintReport::new(pattern, &samples, &poly)?;
            (poly, report)
        }
        Degree::Auto { tol, at_most } if at_most < crate::constraints::MAX_DEGREE => {
            let mut chosen = None;
            for d in 1..=at_most.max(1) {
                let poly = ConstraintPoly::fit(pattern, &samples, d)?;
                let report = ConstraintReport::new(pattern, &samples, &poly)?;
                let met = report.max_fit_error() <= tol;
                chosen = Some((poly, report));
                if met {
                    break;
                }
            }
            chosen.expect("degree 1 at least was fitted")
        }
        Degree::Auto { tol, .. } => fit_to_tolerance(pattern, &samples, tol)?,
    };
    let mut report = report;
    for (crease, coefficients) in checks {
        report.checked_curves.push(
            check_curve(pattern, &samples, crease, coefficients)
                .map_err(|e| NanofoldError::invalid("check", pattern.user_index(crease), e.to_string()))?,
        );
    }
    Ok(Constraints::Vertex {
        samples: Box::new(samples),
        poly: Box::new(poly),
        report: Box::new(report),
    })
}

/// A sweep of `samples` points over a crease pattern of many vertices, refused by name
/// where samples × creases passes [`MAX_SWEEP_WORK`].
fn within_sweep_work(model: &FoldingModel, samples: usize) -> Result<()> {
    // Each of the sweep's points closes every vertex anew (a factorisation of the closure
    // system at least): their cost grows with the creases.
    let creases = model.crease_count();
    let most = (MAX_SWEEP_WORK / creases.max(1)).max(2);
    if samples > most {
        return Err(NanofoldError::invalid(
            "samples",
            samples,
            format!(
                "a pattern of {creases} creases is swept at {most} samples at most (samples × creases ≤ {MAX_SWEEP_WORK}, so that the sweep answers within 10 s)"
            ),
        ));
    }
    Ok(())
}

fn network_constraints(model: &FoldingModel, settings: &ConstraintSettings) -> Result<Constraints> {
    if !settings.checks.is_empty() {
        return Err(NanofoldError::invalid(
            "check",
            format!("{} curves", settings.checks.len()),
            "is for single vertices; for a crease pattern of many vertices compare with the sweep in constraints.json",
        ));
    }
    if settings.source != CurveSource::Sweep {
        return Err(NanofoldError::invalid(
            "source",
            "unfold",
            "is for single vertices; a crease pattern of many vertices is swept exactly",
        ));
    }
    let mut model = model.clone();
    let column = |edge: usize, field: &str| {
        model.column_of_edge.get(edge).copied().flatten().ok_or_else(|| {
            NanofoldError::invalid(
                field,
                edge,
                format!(
                    "edge {edge} is not a crease of {} (a FOLD edge index)",
                    model.pattern.name
                ),
            )
        })
    };
    let mut rho = model.given_fold_angles();
    let mut locked = Vec::new();
    for &(edge, angle) in &settings.lock {
        locked.push((column(edge, "lock")?, angle));
    }
    let driver = column(settings.drive, "drive")?;
    let mut free = vec![settings.free.is_empty(); model.crease_count()];
    for &edge in &settings.free {
        free[column(edge, "free")?] = true;
    }
    for &(c, angle) in &locked {
        model.locked_columns[c] = true;
        rho[c] = angle;
    }
    for (c, is_free) in free.iter().enumerate() {
        if c != driver && !is_free {
            model.locked_columns[c] = true;
        }
    }
    if !locked.is_empty() {
        let mut solver = crate::folding::normal::NormalSolver::new(1e-10);
        if crate::folding::restore_closure(&model, &mut rho, 1e-12, &mut solver)?.is_none() {
            return Err(NanofoldError::invalid(
                "lock",
                format!("{:?}", settings.lock),
                "no rigid state near the file's with these creases held",
            ));
        }
    }
    if rho.iter().all(|&r| r == 0.0) {
        return Err(NanofoldError::invalid(
            "pattern",
            &model.pattern.name,
            "constraint curves of many vertices start from a folded state (e.g. folded.fold written by `nanofold fold`); this pattern is flat",
        ));
    }
    let domain = settings.range.unwrap_or_else(|| {
        let (a, b) = (0.05 * rho[driver], rho[driver]);
        [a.min(b), a.max(b)]
    });
    within_sweep_work(&model, settings.samples)?;
    // The sweep's points are fitted and the midpoints between them checked.
    // Held creases that leave the state no motion (or more than one) are the holder's doing.
    let held_by = if !settings.lock.is_empty() {
        Some("lock")
    } else if !settings.free.is_empty() {
        Some("free")
    } else {
        None
    };
    let sweep =
        network_sweep(&model, &rho, driver, domain, settings.samples.div_ceil(2).max(2)).map_err(|error| {
            match (error, held_by) {
                (NanofoldError::InvalidField { field, value, reason }, Some(held)) if field == "fold angles" => {
                    NanofoldError::InvalidField {
                        field: held.into(),
                        value: format!("{value} with the creases held"),
                        reason,
                    }
                }
                (other, _) => other,
            }
        })?;
    let curves = match settings.degree {
        Degree::Fixed(d) => fit_network(&model, &sweep, d)?,
        Degree::Auto { tol, at_most } if at_most < crate::constraints::MAX_DEGREE => {
            let mut chosen = fit_network(&model, &sweep, 1)?;
            for d in 2..=at_most {
                if chosen.max_fit_error_rad <= tol {
                    break;
                }
                chosen = fit_network(&model, &sweep, d)?;
            }
            chosen
        }
        Degree::Auto { tol, .. } => fit_network_to_tolerance(&model, &sweep, tol)?,
    };
    Ok(Constraints::Network {
        sweep: Box::new(sweep),
        curves: Box::new(curves),
    })
}
