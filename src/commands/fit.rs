//! Calibration behind the door (`docs/model.md#calibration`): a scene file and a measured
//! trajectory in, the fitted parameters with their errors out, and the files `nanofold fit`
//! writes (fit.json, fit.csv, fitted.scene.json, fit.svg, the fitted motion's page).

pub use crate::calibrate::{
    ColumnResiduals, Combination, FitReport, FitSettings, FitStatus, FitTable, FittedParameter, FreeParameter, Noise,
};
use crate::dynamics::Method;
use crate::error::{NanofoldError, Result};
pub use crate::read::measurement::{Measurement, Observed};
pub use crate::read::SceneDocument;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Reads a scene file as JSON a fit can change (`*.scene.json`).
pub fn open_scene_document(path: &Path) -> Result<SceneDocument> {
    SceneDocument::load(path)
}

/// Reads a measurement CSV file (`docs/model.md#calibration`).
pub fn open_measurement(path: &Path) -> Result<Measurement> {
    crate::read::measurement::load_measurement(path)
}

/// Parses measurement CSV text; `source` names it in errors.
pub fn parse_measurement(text: &str, source: &str) -> Result<Measurement> {
    crate::read::measurement::parse_measurement(text, source)
}

/// Fits the free parameters of a scene file to a measurement.
pub fn fit(document: &SceneDocument, measurement: &Measurement, settings: &FitSettings) -> Result<FitReport> {
    crate::calibrate::fit(document, measurement, settings)
}

/// A free parameter as a user writes it: `"PATH=LOWER:UPPER"` or `{path, lower, upper}`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum FreeOption {
    /// `PATH=LOWER:UPPER`.
    Text(String),
    /// The three fields.
    Fields(FreeParameter),
}

/// The noise as a user gives it: one standard deviation for every column, or one per column
/// (a `default` key for the rest); absent, it is estimated.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum NoiseOption {
    /// Every column's, in its unit.
    All(f64),
    /// By column name, with an optional `default`.
    Columns(BTreeMap<String, f64>),
}

/// `fit`'s options, as the command line and Python give them.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitOptions {
    /// The parameters to fit.
    pub free: Vec<FreeOption>,
    /// The measurement's noise (None: estimated from the residuals).
    pub noise: Option<NoiseOption>,
    /// Relative tolerance of each simulation.
    pub rtol: f64,
    /// Levenberg–Marquardt iterations at most.
    pub max_iterations: usize,
    /// The integrator.
    pub method: Method,
}

impl Default for FitOptions {
    fn default() -> Self {
        let d = FitSettings::default();
        FitOptions {
            free: Vec::new(),
            noise: None,
            rtol: d.rtol,
            max_iterations: d.max_iterations,
            method: d.method,
        }
    }
}

impl FitOptions {
    /// The fit's settings, validated.
    pub fn settings(&self) -> Result<FitSettings> {
        let free = self
            .free
            .iter()
            .map(|f| match f {
                FreeOption::Text(text) => FreeParameter::parse(text),
                FreeOption::Fields(p) => Ok(p.clone()),
            })
            .collect::<Result<Vec<_>>>()?;
        let noise = match &self.noise {
            None => Noise::Estimated,
            Some(NoiseOption::All(sigma)) => Noise::Given {
                default: Some(*sigma),
                columns: BTreeMap::new(),
            },
            Some(NoiseOption::Columns(map)) => {
                let mut columns = map.clone();
                Noise::Given {
                    default: columns.remove("default"),
                    columns,
                }
            }
        };
        let settings = FitSettings {
            free,
            noise,
            rtol: self.rtol,
            max_iterations: self.max_iterations,
            method: self.method,
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// Measured against fitted at every time, as fit.csv holds them: `time_s`, then per column
/// its measured value, `_fitted` and `_residual` (empty where nothing was measured).
pub fn fit_table_csv(table: &FitTable) -> String {
    let mut text = String::from("time_s");
    for name in &table.columns {
        text += &format!(",{name},{name}_fitted,{name}_residual");
    }
    text.push('\n');
    for (i, t) in table.times.iter().enumerate() {
        text += &format!("{t:e}");
        for c in 0..table.columns.len() {
            let fitted = table.fitted[c][i];
            match table.measured[c][i] {
                Some(y) => text += &format!(",{y},{fitted},{}", y - fitted),
                None => text += &format!(",,{fitted},"),
            }
        }
        text.push('\n');
    }
    text
}

/// The files `fit` writes (rendered, not written): fit.json (the report), fit.csv,
/// fitted.scene.json (ready for `simulate`, `modes`, `export mujoco`), fit.svg, and the
/// fitted scene's simulated response page (response.html; a network's motion.fold too).
#[cfg(feature = "plot")]
pub fn fit_files(report: &FitReport) -> Result<Vec<(&'static str, String)>> {
    let fitted = serde_json::to_string_pretty(&report.fitted_scene)
        .map_err(|e| NanofoldError::invalid("fitted_scene", "JSON", e.to_string()))?;
    let scene =
        crate::read::scene_from_value(&report.fitted_scene, "fitted.scene.json", "fitted", Path::new("."))?.build()?;
    let simulation = super::scene::simulate(&scene, &crate::dynamics::simulate::SimulationSettings::default())?;
    let mut files = vec![
        (
            "fit.json",
            serde_json::to_string_pretty(report).expect("a report is plain data"),
        ),
        ("fit.csv", fit_table_csv(&report.table)),
        ("fitted.scene.json", fitted),
        ("fit.svg", crate::plot::fit::fit_svg(report)?),
    ];
    for (name, text) in super::scene::simulation_files(&scene, &simulation)? {
        if matches!(name, "response.html" | "motion.fold") {
            files.push((name, text));
        }
    }
    Ok(files)
}
