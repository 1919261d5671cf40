//! The fit of a scene to a measurement (`docs/model.md#calibration`): weighted nonlinear
//! least squares on the simulated trajectory by Levenberg–Marquardt within the bounds, the
//! Jacobian from the forward sensitivities, then the covariance, intervals and what the
//! data cannot separate.

use super::parameters::{resolve, with_values, FreeParameter, ResolvedParameter};
use crate::dynamics::points::PanelPoints;
use crate::dynamics::scene::Scene;
use crate::dynamics::sensitivity::{trajectory_sensitivities, TrajectorySensitivity, STENCIL};
use crate::dynamics::Method;
use crate::error::{NanofoldError, Result};
use crate::read::measurement::{Measurement, Observed};
use crate::read::SceneDocument;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Each parameter's step ε in the differences of the sensitivity equations, in the
/// parameter's scale (|start|).
pub const SENSITIVITY_STEP: f64 = 1e-4;
/// A combination of parameters is undetermined when the data fix it no better than this
/// relative standard error (100 %), or when its singular value is below this fraction of the
/// largest (numerically degenerate).
pub const UNDETERMINED_RELATIVE_ERROR: f64 = 1.0;
/// See [`UNDETERMINED_RELATIVE_ERROR`].
pub const DEGENERATE_FRACTION: f64 = 1e-8;
/// A parameter loads on an undetermined combination when its share of the combination's
/// direction is at least this.
const LOADING: f64 = 0.1;

/// The noise of the measured columns.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Noise {
    /// Each column's standard deviation estimated from its residuals.
    Estimated,
    /// Given, in each column's unit (degrees, µm): by column name, else the default.
    Given {
        /// For columns not named.
        default: Option<f64>,
        /// By column name.
        columns: BTreeMap<String, f64>,
    },
}

/// How a fit runs, validated by [`FitSettings::validate`].
#[derive(Debug, Clone)]
pub struct FitSettings {
    /// The parameters to fit.
    pub free: Vec<FreeParameter>,
    /// The measurement's noise.
    pub noise: Noise,
    /// Relative tolerance of each simulation.
    pub rtol: f64,
    /// Levenberg–Marquardt iterations at most.
    pub max_iterations: usize,
    /// The integrator.
    pub method: Method,
}

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            free: Vec::new(),
            noise: Noise::Estimated,
            rtol: 1e-8,
            max_iterations: 50,
            method: Method::Auto,
        }
    }
}

impl FitSettings {
    /// Every setting in range; errors name the setting and its value.
    pub fn validate(&self) -> Result<()> {
        if !(self.rtol.is_finite() && self.rtol > 0.0 && self.rtol < 1e-3) {
            return Err(NanofoldError::invalid("rtol", self.rtol, "must lie in (0, 1e-3)"));
        }
        if self.max_iterations == 0 || self.max_iterations > 10_000 {
            return Err(NanofoldError::invalid(
                "max_iterations",
                self.max_iterations,
                "must lie in 1..=10000",
            ));
        }
        if let Noise::Given { default, columns } = &self.noise {
            for (name, &sigma) in columns
                .iter()
                .map(|(k, v)| (k.as_str(), v))
                .chain(default.iter().map(|d| ("default", d)))
            {
                // Its weight 1/σ² and the covariance it scales stay finite numbers.
                if !(1e-150..=1e150).contains(&sigma) {
                    return Err(NanofoldError::invalid(
                        format!("noise.{name}"),
                        sigma,
                        "a standard deviation must be finite, > 0 and within 1e-150..1e150",
                    ));
                }
            }
        }
        Ok(())
    }
}

/// How the fit ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStatus {
    /// The step and the change of the objective fell below their tolerances.
    Converged,
    /// The iteration budget ran out first.
    MaxIterations,
    /// No step within the bounds lowers the objective further (λ at its ceiling).
    Stalled,
}

/// One fitted parameter.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct FittedParameter {
    /// Its path in the scene file.
    pub path: String,
    /// The scene file's value.
    pub start: f64,
    /// The estimate.
    pub estimate: f64,
    /// Its bounds.
    pub bounds: [f64; 2],
    /// Whether the estimate sits on a bound (its interval is then not a confidence interval).
    pub at_bound: bool,
    /// Whether the data determine it (it loads on no undetermined combination).
    pub determined: bool,
    /// Standard error (None when undetermined).
    pub standard_error: Option<f64>,
    /// 95 % interval, estimate ± t₀.₉₇₅ × standard error (None when undetermined).
    pub interval_95: Option<[f64; 2]>,
}

/// A direction in parameter space the data cannot fix.
#[derive(Debug, Clone, Serialize)]
pub struct Combination {
    /// Its singular value in the scaled, weighted sensitivity matrix.
    pub singular_value: f64,
    /// The relative standard error along it (the residual scale over the singular value).
    pub relative_standard_error: f64,
    /// Each parameter's share of the direction (in relative changes), largest first.
    pub loadings: Vec<(String, f64)>,
    /// In words: what moves together without changing the fit.
    pub description: String,
}

/// Residuals of one measured column.
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct ColumnResiduals {
    /// The column.
    pub name: String,
    /// Observed values used.
    pub observations: usize,
    /// Its standard deviation, in its unit.
    pub noise: f64,
    /// `given` or `estimated`.
    pub noise_source: &'static str,
    /// Root mean square residual.
    pub rms: f64,
    /// Largest |residual|.
    pub max_abs: f64,
    /// The runs test of the residuals' signs in time order: (runs − expected)/its standard
    /// deviation; far below 0 (too few runs: a drift) or far above (too many: an
    /// oscillation) the residuals follow a pattern, not noise (absent with fewer than
    /// ten observations or one sign only).
    pub runs_z: Option<f64>,
    /// Durbin–Watson's Σ(eₜ − eₜ₋₁)²/Σeₜ²: about 2 for independent noise, towards 0 for
    /// residuals that drift.
    pub durbin_watson: Option<f64>,
    /// Fisher's test of the residuals' periodogram (its largest share against noise's),
    /// its p-value as a normal z (0 where the test sees nothing): far above 0 the residuals
    /// repeat a pattern (an oscillation the model has at another frequency or damping, or a
    /// drift), not noise.
    pub periodicity_z: Option<f64>,
    /// With a given noise: the column's Σ(e/σ)² against χ² of its observations, as a
    /// normal z; far above 0 the residuals are larger than the noise allows.
    pub chi_square_z: Option<f64>,
    /// Whether the residuals say the model does not describe this column: the runs test
    /// beyond ±4 (`LACK_OF_FIT_Z`), or the periodicity or χ² z above it.
    pub systematic: bool,
}

/// Fewest observations of a column whose residuals are tested for a pattern.
pub const RUNS_MIN_OBSERVATIONS: usize = 10;

/// How far (standard deviations) a column's runs test or χ² lies from what noise gives
/// before the fit says the model does not describe it: 4, one column in 30 000 by chance.
pub const LACK_OF_FIT_Z: f64 = 4.0;

/// The runs test's z of residuals in time order (None without both signs or too few).
fn runs_z(values: &[f64]) -> Option<f64> {
    let signs: Vec<bool> = values.iter().filter(|r| **r != 0.0).map(|r| *r > 0.0).collect();
    let n = signs.len();
    let above = signs.iter().filter(|&&s| s).count() as f64;
    let below = n as f64 - above;
    if n < RUNS_MIN_OBSERVATIONS || above == 0.0 || below == 0.0 {
        return None;
    }
    let runs = 1 + signs.windows(2).filter(|w| w[0] != w[1]).count();
    let n = n as f64;
    let expected = 2.0 * above * below / n + 1.0;
    let variance = 2.0 * above * below * (2.0 * above * below - n) / (n * n * (n - 1.0));
    (variance > 0.0).then(|| (runs as f64 - expected) / variance.sqrt())
}

/// Fisher's test for a periodic component in residuals taken in time order: the largest
/// share g of the periodogram at the Fourier frequencies 1..m (m = ⌊(n − 1)/2⌋), whose
/// p-value for Gaussian noise is at most m (1 − g)^(m − 1) (Fisher 1929, the first term of
/// the exact series, exact where it matters, in the tail), as a one-sided normal z. A drift
/// is a periodic component of the lowest frequency. Series longer than 2048 are averaged in
/// consecutive blocks down to 2048 first (block means of noise are noise). None with too
/// few values.
fn periodicity_z(values: &[f64]) -> Option<f64> {
    use statrs::distribution::{ContinuousCDF, Normal};
    const LONGEST: usize = 2048;
    let series: Vec<f64> = if values.len() > LONGEST {
        let block = values.len().div_ceil(LONGEST);
        values
            .chunks(block)
            .map(|c| c.iter().sum::<f64>() / c.len() as f64)
            .collect()
    } else {
        values.to_vec()
    };
    let n = series.len();
    let m = n.saturating_sub(1) / 2;
    if n < RUNS_MIN_OBSERVATIONS || m < 2 {
        return None;
    }
    let mean = series.iter().sum::<f64>() / n as f64;
    let (mut largest, mut total) = (0.0_f64, 0.0);
    for k in 1..=m {
        let w = std::f64::consts::TAU * k as f64 / n as f64;
        let (re, im) = series.iter().enumerate().fold((0.0, 0.0), |(re, im), (t, x)| {
            let (s, c) = (w * t as f64).sin_cos();
            (re + (x - mean) * c, im - (x - mean) * s)
        });
        let power = re * re + im * im;
        largest = largest.max(power);
        total += power;
    }
    if total <= 0.0 {
        return None;
    }
    let g = largest / total;
    // The bound is a bound: above one half it says nothing, and the z is 0.
    let p = (m as f64 * (1.0 - g).powi(m as i32 - 1)).clamp(1e-300, 0.5);
    Normal::new(0.0, 1.0)
        .ok()
        .map(|normal| normal.inverse_cdf(1.0 - p).min(38.0))
}

/// Durbin–Watson's statistic of residuals in time order.
fn durbin_watson(values: &[f64]) -> Option<f64> {
    let total: f64 = values.iter().map(|r| r * r).sum();
    (values.len() >= RUNS_MIN_OBSERVATIONS && total > 0.0)
        .then(|| values.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / total)
}

/// Everything a fit found. It serialises as `nanofold fit --json` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// The scene file fitted.
    pub scene: String,
    /// The measurement.
    pub measurement: String,
    /// How it ended.
    pub status: FitStatus,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Simulations run (with sensitivities, and of trial steps).
    pub simulations: usize,
    /// Of those, the simulations with the sensitivities (each costs about 1 + 8m plain ones).
    pub sensitivity_runs: usize,
    /// Observations n and parameters m.
    pub observations: usize,
    /// Degrees of freedom n − m.
    pub degrees_of_freedom: usize,
    /// Σ wᵢ rᵢ² at the estimate.
    pub weighted_sum_of_squares: f64,
    /// S / (n − m): ≈ 1 when the given noise is right (1 by construction when estimated).
    pub reduced_chi_square: f64,
    /// Whether any column's residuals say the model does not describe it
    /// ([`ColumnResiduals::systematic`]); the warnings name them.
    pub lack_of_fit: bool,
    /// t₀.₉₇₅ with n − m degrees of freedom.
    pub t_quantile: f64,
    /// The parameters.
    pub parameters: Vec<FittedParameter>,
    /// The determined parameters' paths, in the order of `correlation`'s rows.
    pub correlated: Vec<String>,
    /// Correlations among the determined parameters (an undetermined one has none).
    pub correlation: Vec<Vec<f64>>,
    /// Singular values of the scaled, weighted sensitivity matrix, largest first.
    pub singular_values: Vec<f64>,
    /// Combinations the data cannot separate.
    pub undetermined: Vec<Combination>,
    /// Per column.
    pub residuals: Vec<ColumnResiduals>,
    /// What the numbers above do not say by themselves: a fit that stopped early, a given
    /// noise the residuals contradict, an estimate on a bound.
    pub warnings: Vec<String>,
    /// Wall time, s.
    pub seconds: f64,
    /// Measured against fitted, per time (not in `--json`: fit.csv holds it).
    #[serde(skip)]
    pub table: FitTable,
    /// The fitted scene file (its pattern path made absolute).
    #[serde(skip)]
    pub fitted_scene: serde_json::Value,
}

/// Measured and fitted values at every measured time.
#[derive(Debug, Clone, Default)]
pub struct FitTable {
    /// s.
    pub times: Vec<f64>,
    /// Column names.
    pub columns: Vec<String>,
    /// Per column, per time: the measured value (None where missing).
    pub measured: Vec<Vec<Option<f64>>>,
    /// Per column, per time: the fitted model's value.
    pub fitted: Vec<Vec<f64>>,
}

/// What each measured column reads from a simulation.
#[derive(Debug, Clone, Copy)]
enum Output {
    /// Output angle k, reported in degrees.
    Angle(usize),
    /// A mark at `at` (flat µm) on internal panel `panel`: its coordinate `axis`, µm.
    Point { panel: usize, at: [f64; 2], axis: usize },
}

/// Step of the differences of a mark's position in the fold angles, rad.
const MARK_STEP: f64 = 1e-6;

/// Step of the forward differences that give the iterations their Jacobian, in scaled
/// units: large against the plain runs' noise (their rtol), small against the curvature.
const DIFFERENCE_STEP: f64 = 1e-4;

/// Sensitivity columns integrated in one run (the runs on the machine's cores). Fixed, not
/// the core count, so a fit gives the same numbers on every machine.
const COLUMNS_PER_RUN: usize = 2;

/// Where an evaluation's Jacobian came from.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Jacobian {
    /// Carried by Broyden's update.
    Carried,
    /// Forward differences of plain runs.
    Differences,
    /// The sensitivity equations.
    Exact,
}

/// One evaluation of the model at a parameter vector.
struct Evaluation {
    /// Fitted values per column per time.
    predicted: Vec<Vec<f64>>,
    /// Weighted residuals (ŷ − y)/σ of every observation.
    residuals: DVector<f64>,
    /// ∂residuals/∂u and where it came from, when asked.
    jacobian: Option<(DMatrix<f64>, Jacobian)>,
}

/// `job(i)` for i in 0..count on the machine's cores, in order.
fn on_cores<T: Send>(count: usize, job: &(dyn Fn(usize) -> T + Sync)) -> Vec<T> {
    let threads = std::thread::available_parallelism().map_or(1, usize::from).min(count);
    if threads <= 1 {
        return (0..count).map(job).collect();
    }
    let mut results: Vec<Option<T>> = (0..count).map(|_| None).collect();
    std::thread::scope(|scope| {
        let chunks: Vec<_> = results
            .chunks_mut(count.div_ceil(threads))
            .enumerate()
            .map(|(c, chunk)| {
                let first = c * count.div_ceil(threads);
                scope.spawn(move || {
                    for (k, slot) in chunk.iter_mut().enumerate() {
                        *slot = Some(job(first + k));
                    }
                })
            })
            .collect();
        for chunk in chunks {
            if let Err(panic) = chunk.join() {
                std::panic::resume_unwind(panic);
            }
        }
    });
    results.into_iter().map(|r| r.expect("every job ran")).collect()
}

/// The problem: the document, its parameters, the measurement and how columns map.
struct Problem<'a> {
    document: &'a SceneDocument,
    parameters: Vec<ResolvedParameter>,
    measurement: &'a Measurement,
    outputs: Vec<Output>,
    sigma: Vec<f64>,
    settings: &'a FitSettings,
    simulations: usize,
    sensitivity_runs: usize,
}

impl Problem<'_> {
    fn values(&self, u: &[f64]) -> Vec<f64> {
        self.parameters.iter().zip(u).map(|(p, x)| x * p.scale).collect()
    }

    fn scene(&self, values: &[f64]) -> Result<Scene> {
        with_values(self.document, &self.parameters, values).spec()?.build()
    }

    /// A plain run at u.
    fn evaluate(&mut self, u: &[f64]) -> Result<Evaluation> {
        self.simulations += 1;
        self.run(u, false)
    }

    /// A run at u with the sensitivities.
    fn exact(&mut self, u: &[f64]) -> Result<Evaluation> {
        self.simulations += 1;
        self.sensitivity_runs += 1;
        self.run(u, true)
    }

    /// At `at` (a plain run at u), the Jacobian from forward differences of plain runs, one
    /// per parameter, on the machine's cores; a step that would leave the bounds goes the
    /// other way.
    fn differences(&mut self, u: &[f64], at: Evaluation, (lower, upper): (&[f64], &[f64])) -> Result<Evaluation> {
        let m = u.len();
        self.simulations += m;
        let this: &Problem = self;
        let columns = on_cores(m, &|j| {
            let h = if u[j] + DIFFERENCE_STEP <= upper[j] || u[j] - DIFFERENCE_STEP < lower[j] {
                DIFFERENCE_STEP
            } else {
                -DIFFERENCE_STEP
            };
            let mut shifted = u.to_vec();
            shifted[j] += h;
            this.run(&shifted, false).map(|e| (e.residuals - &at.residuals) / h)
        });
        let mut jacobian = DMatrix::zeros(at.residuals.len(), m);
        for (j, column) in columns.into_iter().enumerate() {
            jacobian.set_column(j, &column?);
        }
        Ok(Evaluation {
            jacobian: Some((jacobian, Jacobian::Differences)),
            ..at
        })
    }

    /// The motion at `values` and its sensitivities to the parameters `columns`.
    fn sensitivities(&self, values: &[f64], columns: std::ops::Range<usize>) -> Result<TrajectorySensitivity> {
        let base = self.scene(values)?;
        let mut perturbed = Vec::with_capacity(columns.len());
        for j in columns {
            let mut at = values.to_vec();
            let mut pair = Vec::with_capacity(STENCIL.len());
            for k in STENCIL {
                at[j] = values[j] + k * SENSITIVITY_STEP * self.parameters[j].scale;
                pair.push(self.scene(&at)?);
            }
            perturbed.push(pair.try_into().expect("one scene per offset"));
        }
        trajectory_sensitivities(
            &base,
            &perturbed,
            SENSITIVITY_STEP,
            &self.measurement.times,
            self.settings.method,
            self.settings.rtol,
        )
    }

    /// The residuals at u, and their exact Jacobian if asked: the parameters' columns in
    /// groups of [`COLUMNS_PER_RUN`], the runs on the machine's cores.
    fn run(&self, u: &[f64], jacobian: bool) -> Result<Evaluation> {
        let values = self.values(u);
        let base = self.scene(&values)?;
        let run = if jacobian {
            let (m, size) = (u.len(), COLUMNS_PER_RUN);
            let runs = on_cores(m.div_ceil(size), &|g| {
                self.sensitivities(&values, g * size..((g + 1) * size).min(m))
            });
            let mut runs = runs.into_iter();
            let mut run = runs.next().expect("one group at least")?;
            for other in runs {
                let other = other?;
                for (mine, theirs) in run.sensitivities.iter_mut().zip(&other.sensitivities) {
                    let (rows, have) = mine.shape();
                    let joined = DMatrix::from_fn(rows, have + theirs.ncols(), |i, j| {
                        if j < have {
                            mine[(i, j)]
                        } else {
                            theirs[(i, j - have)]
                        }
                    });
                    *mine = joined;
                }
                run.times.truncate(other.times.len());
            }
            run
        } else {
            self.sensitivities(&values, 0..0)?
        };
        if run.times.len() != self.measurement.times.len() {
            let missing = self.measurement.times[run.times.len().min(self.measurement.times.len() - 1)];
            return Err(NanofoldError::invalid(
                format!("{}: time_s", self.measurement.source),
                missing,
                "the simulation gives no state at this time (before the motion's start, or past where a slow release stopped: a snap-through or a balance not found)",
            ));
        }
        let columns = &self.measurement.columns;
        let mut predicted = vec![vec![0.0; run.times.len()]; columns.len()];
        let rows: usize = self.measurement.observations();
        let mut residuals = DVector::zeros(rows);
        let mut matrix = jacobian.then(|| DMatrix::zeros(rows, u.len()));
        let mut points = match self.outputs.iter().any(|o| matches!(o, Output::Point { .. })) {
            true => Some(PanelPoints::new(&base)?),
            false => None,
        };
        let mut e = 0;
        for (c, column) in columns.iter().enumerate() {
            for (i, measured) in column.values.iter().enumerate() {
                let angles = run.angles[i].as_slice();
                predicted[c][i] = match self.outputs[c] {
                    Output::Angle(k) => angles[k].to_degrees(),
                    Output::Point { panel, at, axis } => points
                        .as_mut()
                        .expect("made for the points")
                        .position(angles, panel, at)[axis],
                };
                if let Some(y) = measured {
                    residuals[e] = (predicted[c][i] - y) / self.sigma[c];
                    if let Some(m) = &mut matrix {
                        // A mark moves with the angles: its columns are the angles' columns
                        // through its kinematics.
                        let slope: Vec<(usize, f64)> = match self.outputs[c] {
                            Output::Angle(k) => vec![(k, 180.0 / std::f64::consts::PI)],
                            Output::Point { panel, at, axis } => {
                                let points = points.as_mut().expect("made for the points");
                                mark_slopes(points, angles, panel, at, axis)
                            }
                        };
                        for j in 0..u.len() {
                            let total: f64 = slope.iter().map(|&(k, d)| d * run.sensitivities[i][(k, j)]).sum();
                            m[(e, j)] = total / self.sigma[c];
                        }
                    }
                    e += 1;
                }
            }
        }
        Ok(Evaluation {
            predicted,
            residuals,
            jacobian: matrix.map(|m| (m, Jacobian::Exact)),
        })
    }
}

/// ∂(coordinate `axis` of the mark)/∂θₖ for every angle k that moves it, µm per rad.
fn mark_slopes(points: &mut PanelPoints, angles: &[f64], panel: usize, at: [f64; 2], axis: usize) -> Vec<(usize, f64)> {
    let mut shifted = angles.to_vec();
    (0..angles.len())
        .filter_map(|k| {
            shifted[k] = angles[k] + MARK_STEP;
            let plus = points.position(&shifted, panel, at)[axis];
            shifted[k] = angles[k] - MARK_STEP;
            let minus = points.position(&shifted, panel, at)[axis];
            shifted[k] = angles[k];
            let slope = (plus - minus) / (2.0 * MARK_STEP);
            (slope != 0.0).then_some((k, slope))
        })
        .collect()
}

/// Which output each measured column reads, or an error naming the column.
fn map_columns(scene: &Scene, measurement: &Measurement) -> Result<Vec<Output>> {
    let edges = scene.output_edges();
    let count = scene.target_angles().len();
    measurement
        .columns
        .iter()
        .map(|column| {
            let field = format!("{}: column {}", measurement.source, column.name);
            match (&column.observed, edges) {
                (Observed::Angle { index, .. }, None) if *index < count => Ok(Output::Angle(*index)),
                (Observed::Angle { index, .. }, None) => Err(NanofoldError::invalid(
                    field,
                    index,
                    format!("the strip has hinges 0 to {}", count - 1),
                )),
                (Observed::Angle { hinge: true, .. }, Some(_)) => Err(NanofoldError::invalid(
                    field,
                    &column.name,
                    "hinge_<i>_deg names a strip's hinge; this scene's creases are FOLD edges: write crease_<edge>_deg",
                )),
                (Observed::Angle { index, .. }, Some(edges)) => match edges.iter().position(|e| e == index) {
                    Some(k) => Ok(Output::Angle(k)),
                    None => Err(NanofoldError::invalid(
                        field,
                        index,
                        format!("edge {index} is not one of the scene's creases (edges {edges:?})"),
                    )),
                },
                (Observed::Point { panel, at, axis }, _) => {
                    let points = PanelPoints::new(scene)
                        .map_err(|e| NanofoldError::invalid(field.clone(), &column.name, e.to_string()))?;
                    let internal = points
                        .panel(*panel)
                        .map_err(|reason| NanofoldError::invalid(field.clone(), panel, reason))?;
                    Ok(Output::Point {
                        panel: internal,
                        at: *at,
                        axis: *axis,
                    })
                }
            }
        })
        .collect()
}

/// Fits the free parameters of `document` to `measurement` (`docs/model.md#calibration`).
pub fn fit(document: &SceneDocument, measurement: &Measurement, settings: &FitSettings) -> Result<FitReport> {
    let started = Instant::now();
    settings.validate()?;
    let parameters = resolve(document, &settings.free)?;
    let scene = document.spec()?.build()?;
    within_the_scenes_ranges(document, &parameters)?;
    let outputs = map_columns(&scene, measurement)?;
    let m = parameters.len();
    let n = measurement.observations();
    if n <= m {
        return Err(NanofoldError::invalid(
            measurement.source.clone(),
            format!("{n} observations"),
            format!("fitting {m} parameters needs more observations than parameters"),
        ));
    }
    let (given, sigma) = column_sigma(&settings.noise, measurement)?;
    let mut problem = Problem {
        document,
        parameters,
        measurement,
        outputs,
        sigma,
        settings,
        simulations: 0,
        sensitivity_runs: 0,
    };
    let start: Vec<f64> = problem.parameters.iter().map(|p| p.start / p.scale).collect();
    let (mut u, mut status, mut iterations, mut at) = levenberg_marquardt(&mut problem, start, None)?;
    if !given && measurement.columns.len() > 1 {
        // Columns of different noise: weigh each by its estimated σ and fit again from here
        // (new weights only rescale the rows of the residuals and the Jacobian).
        let sigma = column_noise(&problem, &at, n, m);
        reweigh(&mut problem, &mut at, sigma);
        let (again, again_status, more, again_at) = levenberg_marquardt(&mut problem, u, Some(at))?;
        (u, status, iterations, at) = (again, again_status, iterations + more, again_at);
    }
    if !given {
        // σ of each column from its residuals, so the residuals below are in units of it.
        let sigma = column_noise(&problem, &at, n, m);
        reweigh(&mut problem, &mut at, sigma);
    }
    let report = statistics(&problem, &u, &at, given, n, m)?;
    let values = problem.values(&u);
    let fitted = with_values(document, &problem.parameters, &values);
    let warnings = warnings(status, iterations, given, &report);
    Ok(FitReport {
        warnings,
        scene: document.source.clone(),
        measurement: measurement.source.clone(),
        status,
        iterations,
        simulations: problem.simulations,
        sensitivity_runs: problem.sensitivity_runs,
        seconds: started.elapsed().as_secs_f64(),
        fitted_scene: absolute_pattern(&fitted),
        ..report
    })
}

/// Every parameter at each of its bounds (the others at their starts) still makes a valid
/// scene: a bound the scene refuses (a negative drag coefficient) is refused as the
/// parameter's, before the fit would step there.
fn within_the_scenes_ranges(document: &SceneDocument, parameters: &[ResolvedParameter]) -> Result<()> {
    let starts: Vec<f64> = parameters.iter().map(|p| p.start).collect();
    for (k, parameter) in parameters.iter().enumerate() {
        for bound in [parameter.lower, parameter.upper] {
            let mut values = starts.clone();
            values[k] = bound;
            if let Err(error) = with_values(document, parameters, &values)
                .spec()
                .and_then(|spec| spec.build())
            {
                return Err(NanofoldError::invalid(
                    format!("free[{k}].bounds"),
                    format!("{}:{}", parameter.lower, parameter.upper),
                    format!("at {bound} the scene is refused: {error}"),
                ));
            }
        }
    }
    Ok(())
}

/// What the report's numbers do not say by themselves.
fn warnings(status: FitStatus, iterations: usize, given: bool, report: &FitReport) -> Vec<String> {
    let mut warnings = Vec::new();
    if status != FitStatus::Converged {
        warnings.push(format!(
            "the fit stopped before converging ({status:?} after {iterations} iterations): the estimates and intervals are of the last point"
        ));
    }
    let dof = report.degrees_of_freedom as f64;
    if given && report.reduced_chi_square > 1.0 + 3.0 * (2.0 / dof).sqrt() {
        warnings.push(format!(
            "reduced χ² {:.3} with the given noise: the model does not fit the data as well as the noise allows (a local minimum from this start, or a model error), and the intervals assume it does",
            report.reduced_chi_square
        ));
    }
    let systematic: Vec<&ColumnResiduals> = report.residuals.iter().filter(|c| c.systematic).collect();
    if !systematic.is_empty() {
        let named: Vec<String> = systematic
            .iter()
            .map(|c| match c.chi_square_z {
                Some(z) if z > LACK_OF_FIT_Z => format!("{} (χ² {z:+.1} standard deviations over its noise)", c.name),
                _ => format!(
                    "{} (periodicity z {}, runs z {}, Durbin–Watson {})",
                    c.name,
                    c.periodicity_z.map_or("-".into(), |z| format!("{z:.1}")),
                    c.runs_z.map_or("-".into(), |z| format!("{z:.1}")),
                    c.durbin_watson.map_or("-".into(), |d| format!("{d:.2}"))
                ),
            })
            .collect();
        warnings.push(format!(
            "the model does not describe {}: its residuals follow a pattern in time, not noise, so its estimates are the best of a wrong model and its intervals are not confidence intervals",
            named.join(", ")
        ));
    }
    for p in report.parameters.iter().filter(|p| p.at_bound) {
        warnings.push(format!(
            "{} = {} sits on a bound: its interval is not a confidence interval",
            p.path, p.estimate
        ));
    }
    warnings
}

/// Each column's σ as given (true), or 1 until it is estimated (false); a noise named for a
/// column the measurement lacks, or a column without one, is refused by name.
fn column_sigma(noise: &Noise, measurement: &Measurement) -> Result<(bool, Vec<f64>)> {
    Ok(match noise {
        Noise::Estimated => (false, vec![1.0; measurement.columns.len()]),
        Noise::Given { default, columns } => {
            if let Some(unknown) = columns
                .keys()
                .find(|k| !measurement.columns.iter().any(|c| &c.name == *k))
            {
                return Err(NanofoldError::invalid(
                    format!("noise.{unknown}"),
                    columns[unknown],
                    format!("{} has no column {unknown}", measurement.source),
                ));
            }
            let sigma = measurement
                .columns
                .iter()
                .map(|c| {
                    columns.get(&c.name).copied().or(*default).ok_or_else(|| {
                        NanofoldError::invalid(
                            format!("noise.{}", c.name),
                            "missing",
                            "give every column's noise (or a default), or let it be estimated",
                        )
                    })
                })
                .collect::<Result<Vec<f64>>>()?;
            (true, sigma)
        }
    })
}

/// Each column's residual summary, in its unit.
fn column_residuals(problem: &Problem, at: &Evaluation, given: bool) -> Vec<ColumnResiduals> {
    let mut e = 0;
    problem
        .measurement
        .columns
        .iter()
        .enumerate()
        .map(|(c, column)| {
            let count = column.values.iter().flatten().count();
            let values: Vec<f64> = (e..e + count).map(|k| at.residuals[k] * problem.sigma[c]).collect();
            e += count;
            let sum_of_squares: f64 = values.iter().map(|r| r * r).sum();
            let runs = runs_z(&values);
            // Σ(e/σ)² of n values is χ²(n): mean n, variance 2n.
            let chi_square_z = (given && count > 0).then(|| {
                let n = count as f64;
                (sum_of_squares / (problem.sigma[c] * problem.sigma[c]) - n) / (2.0 * n).sqrt()
            });
            let periodicity = periodicity_z(&values);
            let systematic = runs.is_some_and(|z| z.abs() > LACK_OF_FIT_Z)
                || periodicity.is_some_and(|z| z > LACK_OF_FIT_Z)
                || chi_square_z.is_some_and(|z| z > LACK_OF_FIT_Z);
            ColumnResiduals {
                name: column.name.clone(),
                observations: count,
                noise: problem.sigma[c],
                noise_source: if given { "given" } else { "estimated" },
                rms: (sum_of_squares / count.max(1) as f64).sqrt(),
                max_abs: values.iter().fold(0.0, |a, r| a.max(r.abs())),
                runs_z: runs,
                periodicity_z: periodicity,
                durbin_watson: durbin_watson(&values),
                chi_square_z,
                systematic,
            }
        })
        .collect()
}

/// Sets the columns' σ and rescales an evaluation's weighted rows to it.
fn reweigh(problem: &mut Problem, at: &mut Evaluation, sigma: Vec<f64>) {
    let mut e = 0;
    for (c, column) in problem.measurement.columns.iter().enumerate() {
        let factor = problem.sigma[c] / sigma[c];
        for _ in column.values.iter().flatten() {
            at.residuals[e] *= factor;
            if let Some((j, _)) = &mut at.jacobian {
                j.row_mut(e).scale_mut(factor);
            }
            e += 1;
        }
    }
    problem.sigma = sigma;
}

/// Each column's σ from its residuals (weighted by the current σ), with the n − m correction.
fn column_noise(problem: &Problem, at: &Evaluation, n: usize, m: usize) -> Vec<f64> {
    let correction = (n as f64 / (n - m) as f64).sqrt();
    column_residuals(problem, at, false)
        .iter()
        .map(|column| {
            let sigma = correction * column.rms;
            if sigma > 0.0 {
                sigma
            } else {
                f64::MIN_POSITIVE.sqrt()
            }
        })
        .collect()
}

/// Levenberg–Marquardt (Marquardt's diagonal scaling, Nielsen's damping update) within the
/// bounds: trial points are clamped to them. The iterations' Jacobian comes from forward
/// differences of plain runs (m of them, on the machine's cores) and is carried between
/// them by Broyden's rank-one update from each accepted step's residuals; the differences
/// are taken again after a step the carried one led astray. Convergence is confirmed with
/// the exact Jacobian (a run with the sensitivities), so the estimate and the statistics
/// rest on it. Returns the estimate in scaled units, how it ended and the iterations.
fn levenberg_marquardt(
    problem: &mut Problem,
    start: Vec<f64>,
    at_start: Option<Evaluation>,
) -> Result<(Vec<f64>, FitStatus, usize, Evaluation)> {
    let lower: Vec<f64> = problem.parameters.iter().map(|p| p.lower / p.scale).collect();
    let upper: Vec<f64> = problem.parameters.iter().map(|p| p.upper / p.scale).collect();
    let bounds = (lower.as_slice(), upper.as_slice());
    let m = start.len();
    let mut u = start;
    let mut current = match at_start {
        Some(at) if at.jacobian.is_some() => at,
        _ => {
            let at = problem.evaluate(&u)?;
            problem.differences(&u, at, bounds)?
        }
    };
    let mut exact_taken = matches!(current.jacobian, Some((_, Jacobian::Exact)));
    let mut cost = current.residuals.norm_squared();
    let mut lambda: Option<f64> = None;
    let mut nu = 2.0;
    for iteration in 1..=problem.settings.max_iterations {
        let (jacobian, kind) = current.jacobian.as_ref().expect("evaluated with its Jacobian");
        let kind = *kind;
        let normal = jacobian.transpose() * jacobian;
        let gradient = jacobian.transpose() * &current.residuals;
        if converged(problem, jacobian, &current.residuals, &gradient, &u, bounds, cost) {
            if kind == Jacobian::Exact {
                return Ok((u, FitStatus::Converged, iteration - 1, current));
            }
            current = problem.exact(&u)?;
            exact_taken = true;
            continue;
        }
        let diagonal: Vec<f64> = (0..m).map(|j| normal[(j, j)].max(1e-12 * normal.max())).collect();
        let mut damping = *lambda.get_or_insert(1e-3);
        loop {
            let mut system = normal.clone();
            for j in 0..m {
                system[(j, j)] += damping * diagonal[j];
            }
            let Some(step) = system.cholesky().map(|c| c.solve(&(-&gradient))) else {
                damping *= nu;
                nu *= 2.0;
                continue;
            };
            let trial: Vec<f64> = (0..m).map(|j| (u[j] + step[j]).clamp(lower[j], upper[j])).collect();
            let taken = DVector::from_iterator(m, (0..m).map(|j| trial[j] - u[j]));
            let predicted = -(2.0 * gradient.dot(&taken) + (&normal * &taken).dot(&taken));
            let small_step = (0..m).all(|j| taken[j].abs() <= 1e-10 * (u[j].abs() + 1e-10));
            if small_step {
                if kind == Jacobian::Exact {
                    return Ok((u, FitStatus::Converged, iteration, current));
                }
                current = problem.exact(&u)?;
                exact_taken = true;
                break;
            }
            let outcome = problem.evaluate(&trial).ok();
            let trial_cost = outcome.as_ref().map_or(f64::INFINITY, |e| e.residuals.norm_squared());
            let rho = if predicted > 0.0 {
                (cost - trial_cost) / predicted
            } else {
                -1.0
            };
            if let (true, Some(outcome)) = (rho > 0.0 && trial_cost < cost, outcome) {
                let updated = broyden(jacobian, &current.residuals, &outcome.residuals, &taken);
                u = trial;
                current = Evaluation {
                    jacobian: Some((updated, Jacobian::Carried)),
                    ..outcome
                };
                cost = trial_cost;
                damping *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                lambda = Some(damping);
                break;
            }
            if kind == Jacobian::Carried {
                // A carried Jacobian that led astray: take the differences here and try again;
                // once the exact one has been needed (near the estimate, where the
                // differences' noise matters), the exact one.
                current = if exact_taken {
                    problem.exact(&u)?
                } else {
                    let at = Evaluation {
                        jacobian: None,
                        ..current
                    };
                    problem.differences(&u, at, bounds)?
                };
                break;
            }
            damping *= nu;
            nu *= 2.0;
            if damping > 1e16 {
                let at = exact_at(problem, &u, current)?;
                return Ok((u, FitStatus::Stalled, iteration, at));
            }
        }
    }
    let at = exact_at(problem, &u, current)?;
    Ok((u, FitStatus::MaxIterations, problem.settings.max_iterations, at))
}

/// The evaluation at u with its exact Jacobian (computed unless `current` has it).
fn exact_at(problem: &mut Problem, u: &[f64], current: Evaluation) -> Result<Evaluation> {
    match current.jacobian {
        Some((_, Jacobian::Exact)) => Ok(current),
        _ => problem.exact(u),
    }
}

/// Broyden's rank-one update of the Jacobian by a step δ and the residuals' change:
/// J + (Δr − J δ) δᵀ / δᵀδ.
fn broyden(jacobian: &DMatrix<f64>, before: &DVector<f64>, after: &DVector<f64>, step: &DVector<f64>) -> DMatrix<f64> {
    let change = after - before - jacobian * step;
    jacobian + change * step.transpose() / step.norm_squared()
}

/// Whether the fit has converged at u: no descent left through the bounds, or the
/// Gauss–Newton step would lower S by less than 1e-4 of its mean square per degree of
/// freedom (the estimates would move by under 1e-2 of their standard errors), counting only
/// the directions the data determine (along one they do not, S is flat and the step says
/// nothing).
fn converged(
    problem: &Problem,
    jacobian: &DMatrix<f64>,
    residuals: &DVector<f64>,
    gradient: &DVector<f64>,
    u: &[f64],
    (lower, upper): (&[f64], &[f64]),
    cost: f64,
) -> bool {
    let m = u.len();
    let projected = (0..m)
        .map(|j| {
            let g = gradient[j];
            if (u[j] <= lower[j] && g > 0.0) || (u[j] >= upper[j] && g < 0.0) {
                0.0
            } else {
                g.abs()
            }
        })
        .fold(0.0, f64::max);
    if projected <= 1e-12 * (1.0 + cost) {
        return true;
    }
    let scale = cost / (problem.measurement.observations() - m).max(1) as f64;
    let svd = jacobian.clone().svd(true, false);
    let Some(left) = &svd.u else { return false };
    let largest = svd.singular_values.max();
    let decrease: f64 = (0..svd.singular_values.len())
        .filter(|&k| {
            let sigma = svd.singular_values[k];
            sigma > DEGENERATE_FRACTION * largest && scale.sqrt() / sigma <= UNDETERMINED_RELATIVE_ERROR
        })
        .map(|k| left.column(k).dot(residuals).powi(2))
        .sum();
    decrease <= 1e-4 * scale
}

/// The covariance (in scaled units), which parameters the data leave undetermined and the
/// combinations they cannot fix, from the singular directions of the scaled Jacobian.
struct Directions {
    covariance: DMatrix<f64>,
    loose: Vec<bool>,
    undetermined: Vec<Combination>,
    /// Largest first.
    singular_values: Vec<f64>,
}

fn directions(problem: &Problem, jacobian: &DMatrix<f64>, u: &[f64], s2: f64) -> Directions {
    let m = u.len();
    let svd = jacobian.clone().svd(false, true);
    let v_t = svd.v_t.as_ref().expect("asked for V");
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let largest = svd.singular_values[order[0]];
    let lower: Vec<f64> = problem.parameters.iter().map(|p| p.lower / p.scale).collect();
    let upper: Vec<f64> = problem.parameters.iter().map(|p| p.upper / p.scale).collect();
    let mut covariance = DMatrix::<f64>::zeros(m, m);
    let mut undetermined = Vec::new();
    let mut loose = vec![false; m];
    // The spread along the undetermined directions: how far, within the bounds, the
    // combinations the data do not fix move the parameters.
    let mut spread = DMatrix::<f64>::zeros(m, m);
    for &k in &order {
        let sigma = svd.singular_values[k];
        let direction: Vec<f64> = (0..m).map(|j| v_t[(k, j)]).collect();
        let relative_error = s2.sqrt() / sigma;
        if sigma <= DEGENERATE_FRACTION * largest || relative_error > UNDETERMINED_RELATIVE_ERROR {
            let extent = relative_error.min(span(u, &direction, (&lower, &upper)));
            for (j, w) in direction.iter().enumerate() {
                for (i, v) in direction.iter().enumerate() {
                    spread[(i, j)] += v * w * extent * extent;
                }
                if w.abs() >= LOADING {
                    loose[j] = true;
                }
            }
            let mut loadings: Vec<(String, f64)> = problem
                .parameters
                .iter()
                .zip(&direction)
                .filter(|(_, w)| w.abs() >= LOADING)
                .map(|(p, &w)| (p.path.clone(), w))
                .collect();
            loadings.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
            undetermined.push(Combination {
                singular_value: sigma,
                relative_standard_error: relative_error,
                description: describe(&loadings, &|path: &str| {
                    problem
                        .parameters
                        .iter()
                        .position(|p| p.path == path)
                        .map_or(f64::NAN, |j| problem.values(u)[j])
                }),
                loadings,
            });
            continue;
        }
        for a in 0..m {
            for b in 0..m {
                covariance[(a, b)] += s2 * direction[a] * direction[b] / (sigma * sigma);
            }
        }
    }
    // A parameter the undetermined combinations move by more than the data's error on it
    // is undetermined too, however small its loading; otherwise its error includes that
    // spread.
    for j in 0..m {
        if spread[(j, j)] > covariance[(j, j)] {
            loose[j] = true;
        }
    }
    covariance += spread;
    Directions {
        covariance,
        loose,
        undetermined,
        singular_values: order.iter().map(|&k| svd.singular_values[k].max(0.0)).collect(),
    }
}

/// Covariance, intervals, correlations and identifiability at the estimate.
fn statistics(problem: &Problem, u: &[f64], at: &Evaluation, given: bool, n: usize, m: usize) -> Result<FitReport> {
    let (jacobian, _) = at.jacobian.as_ref().expect("evaluated with its Jacobian");
    let sum_of_squares = at.residuals.norm_squared();
    let dof = n - m;
    let reduced = sum_of_squares / dof as f64;
    let s2 = if given { 1.0 } else { reduced };
    let Directions {
        covariance,
        loose,
        undetermined,
        singular_values,
    } = directions(problem, jacobian, u, s2);
    let t = t_quantile(dof);
    let values = problem.values(u);
    let parameters: Vec<FittedParameter> = problem
        .parameters
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let se = (!loose[j]).then(|| covariance[(j, j)].sqrt() * p.scale);
            FittedParameter {
                path: p.path.clone(),
                start: p.start,
                estimate: values[j],
                bounds: [p.lower, p.upper],
                at_bound: values[j] <= p.lower || values[j] >= p.upper,
                determined: !loose[j],
                standard_error: se,
                interval_95: se.map(|se| [values[j] - t * se, values[j] + t * se]),
            }
        })
        .collect();
    let determined: Vec<usize> = (0..m).filter(|&j| !loose[j]).collect();
    let correlation = determined
        .iter()
        .map(|&a| {
            determined
                .iter()
                .map(|&b| covariance[(a, b)] / (covariance[(a, a)] * covariance[(b, b)]).sqrt())
                .collect()
        })
        .collect();
    let correlated = determined.iter().map(|&j| problem.parameters[j].path.clone()).collect();
    let measurement = problem.measurement;
    let residuals = column_residuals(problem, at, given);
    Ok(FitReport {
        scene: String::new(),
        measurement: String::new(),
        status: FitStatus::Converged,
        iterations: 0,
        simulations: 0,
        sensitivity_runs: 0,
        observations: n,
        degrees_of_freedom: dof,
        weighted_sum_of_squares: sum_of_squares,
        reduced_chi_square: reduced,
        lack_of_fit: residuals.iter().any(|c| c.systematic),
        t_quantile: t,
        parameters,
        correlated,
        correlation,
        singular_values,
        undetermined,
        residuals,
        warnings: Vec::new(),
        seconds: 0.0,
        table: FitTable {
            times: measurement.times.clone(),
            columns: measurement.columns.iter().map(|c| c.name.clone()).collect(),
            measured: measurement.columns.iter().map(|c| c.values.clone()).collect(),
            fitted: at.predicted.clone(),
        },
        fitted_scene: serde_json::Value::Null,
    })
}

/// The length, in scaled units, of the line through u along `direction` within the bounds.
fn span(u: &[f64], direction: &[f64], (lower, upper): (&[f64], &[f64])) -> f64 {
    let (mut below, mut above) = (f64::NEG_INFINITY, f64::INFINITY);
    for j in 0..u.len() {
        let w = direction[j];
        if w.abs() < f64::EPSILON {
            continue;
        }
        let (a, b) = ((lower[j] - u[j]) / w, (upper[j] - u[j]) / w);
        below = below.max(a.min(b));
        above = above.min(a.max(b));
    }
    (above - below).max(0.0)
}

/// The 0.975 quantile of Student's t with `dof` degrees of freedom.
pub fn t_quantile(dof: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    StudentsT::new(0.0, 1.0, dof as f64)
        .map(|t| t.inverse_cdf(0.975))
        .unwrap_or(f64::NAN)
}

/// An undetermined direction in words, with the value of what the data do fix.
fn describe(loadings: &[(String, f64)], value: &dyn Fn(&str) -> f64) -> String {
    match loadings {
        [(a, wa), (b, wb)] => {
            // Moving along (wa Δln a + wb Δln b) leaves the fit unchanged: a · b^(−wa/wb) is
            // what the data fix.
            let exponent = -wa / wb;
            let fixed = value(a) * value(b).powf(exponent);
            if (exponent - 1.0).abs() < 0.2 {
                format!("only the product {a} × {b} is determined ({:.6e})", value(a) * value(b))
            } else if (exponent + 1.0).abs() < 0.2 {
                format!("only the ratio {a} / {b} is determined ({:.6e})", value(a) / value(b))
            } else {
                format!("only {a} × {b}^({exponent:.3}) is determined ({fixed:.6e})")
            }
        }
        [(a, _)] => format!("{a} does not change the fitted trajectory"),
        _ => {
            let names: Vec<&str> = loadings.iter().map(|(n, _)| n.as_str()).collect();
            format!("one combination of {} is not determined", names.join(", "))
        }
    }
}

/// The document's JSON with its `pattern` made absolute (the fitted scene is written
/// elsewhere than the original).
fn absolute_pattern(document: &SceneDocument) -> serde_json::Value {
    let mut value = document.value.clone();
    if let Some(serde_json::Value::String(pattern)) = value.get("pattern") {
        let joined = document.base.join(pattern);
        let absolute = joined.canonicalize().unwrap_or(joined);
        value["pattern"] = serde_json::Value::String(absolute.display().to_string());
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_refused_by_name() {
        let error = |settings: FitSettings| settings.validate().unwrap_err().to_string();
        let given = |default: Option<f64>, column: f64| Noise::Given {
            default,
            columns: BTreeMap::from([("hinge_0_deg".to_string(), column)]),
        };
        let base = FitSettings::default;
        assert!(error(FitSettings { rtol: 0.0, ..base() }).contains("rtol"));
        assert!(error(FitSettings {
            max_iterations: 0,
            ..base()
        })
        .contains("max_iterations"));
        let noise = FitSettings {
            noise: given(None, -0.5),
            ..base()
        };
        assert!(error(noise).contains("noise.hinge_0_deg"));
        let noise = FitSettings {
            noise: given(Some(f64::NAN), 0.5),
            ..base()
        };
        assert!(error(noise).contains("noise.default"));
        assert!(FitSettings {
            noise: given(Some(0.5), 0.5),
            ..base()
        }
        .validate()
        .is_ok());
    }

    /// Seeded standard normals (splitmix64 and Box–Muller).
    fn noise(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed;
        let mut uniform = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            (((z ^ (z >> 31)) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos())
            .collect()
    }

    #[test]
    fn noise_passes_the_pattern_tests_and_patterns_do_not() {
        // Noise: every test near its null, in 200 series of 100.
        let mut flagged = 0;
        for seed in 0..200 {
            let e = noise(seed, 100);
            let (runs, periodic) = (runs_z(&e).unwrap(), periodicity_z(&e).unwrap());
            flagged += usize::from(runs.abs() > LACK_OF_FIT_Z || periodic > LACK_OF_FIT_Z);
            let dw = durbin_watson(&e).unwrap();
            assert!((1.2..2.8).contains(&dw), "Durbin–Watson {dw}");
        }
        assert_eq!(flagged, 0, "noise flagged as a pattern");
        // A sine of 1.5 σ in the noise (an oscillation the model misses): periodic.
        let e: Vec<f64> = noise(7, 100)
            .iter()
            .enumerate()
            .map(|(t, x)| x + 1.5 * (0.7 * t as f64).sin())
            .collect();
        assert!(periodicity_z(&e).unwrap() > LACK_OF_FIT_Z);
        // A slow drift of 2 σ: too few runs, and periodic at the lowest frequencies.
        let e: Vec<f64> = noise(8, 100)
            .iter()
            .enumerate()
            .map(|(t, x)| 0.3 * x + (t as f64 / 25.0 - 2.0))
            .collect();
        assert!(runs_z(&e).unwrap() < -LACK_OF_FIT_Z);
        assert!(periodicity_z(&e).unwrap() > LACK_OF_FIT_Z);
        // Signs that alternate every sample: too many runs.
        let e: Vec<f64> = (0..100).map(|t| if t % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert!(runs_z(&e).unwrap() > LACK_OF_FIT_Z);
        // Too few to test.
        assert!(runs_z(&[1.0, -1.0, 1.0]).is_none() && periodicity_z(&[1.0, 2.0]).is_none());
    }
}
