//! Every command's options as the front ends name them: the command line's flags are these
//! names with hyphens, Python's keywords are these names. One name has one unit everywhere:
//! a fold's target in percent, angles a person types in degrees (`_deg` where the name does
//! not say it: `drive`, `lock`, `range`, `max_step`), tolerances in rad. Each deserialises
//! from a JSON object (unknown names refused by name) and becomes the engines' validated
//! settings by one function, so the command line and Python cannot disagree.

use super::constraints::{ConstraintSettings, CurveSource, Degree};
use super::Settings;
use crate::dynamics::integrate::Method;
use crate::dynamics::simulate::{ModelChoice, SimulationSettings};
use crate::error::{NanofoldError, Result};
use crate::folding::{Drive, FoldSettings};
use crate::pattern::LoadOptions;
use crate::unfold::energy::EnergyKind;
use crate::unfold::qp::QpMethod;
use crate::unfold::UnfoldSettings;
use serde::Deserialize;
use std::collections::BTreeMap;

/// Options of a JSON object: `null` values are left at their defaults (Python passes
/// `None` for a keyword it was not given).
pub fn options_from_json<T: serde::de::DeserializeOwned>(value: &serde_json::Value) -> Result<T> {
    let mut value = value.clone();
    if let Some(object) = value.as_object_mut() {
        object.retain(|_, v| !v.is_null());
    } else if !value.is_null() {
        return Err(NanofoldError::invalid(
            "options",
            crate::read::input::short_json(&value),
            "expected named options (a JSON object)",
        ));
    } else {
        value = serde_json::json!({});
    }
    crate::read::input::from_value(&value)
}

/// Options that read themselves from a JSON object (see [`options_from_json`]): what the
/// Python package hands over.
pub trait FromJson: Sized {
    /// The options of `value`; unknown names are refused by name.
    fn from_json(value: &serde_json::Value) -> Result<Self>;
}

impl<T: serde::de::DeserializeOwned> FromJson for T {
    fn from_json(value: &serde_json::Value) -> Result<Self> {
        options_from_json(value)
    }
}

/// How a pattern file is read (`check`, `unfold`, `fold`, `constraints`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReadOptions {
    /// Largest accepted loop-closure residual of a folded state, rad.
    pub closure_tol: f64,
    /// |Σα − 2π| below which a closed vertex's sectors are taken to close the paper, rad.
    pub angle_sum_tol: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        let d = LoadOptions::default();
        ReadOptions {
            closure_tol: d.closure_tol,
            angle_sum_tol: d.angle_sum_tol,
        }
    }
}

impl ReadOptions {
    /// The readers' validated options.
    pub fn load_options(&self) -> Result<LoadOptions> {
        let options = LoadOptions {
            closure_tol: self.closure_tol,
            angle_sum_tol: self.angle_sum_tol,
        };
        options.validate()?;
        Ok(options)
    }
}

/// `unfold` (and the unfolding a `check` runs).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UnfoldOptions {
    /// The repulsive energy (`docs/model.md#energy`).
    pub energy: EnergyKind,
    /// Its exponent (None: 2 separable, 4 non-separable).
    pub p: Option<f64>,
    /// The direction solver.
    pub qp: QpMethod,
    /// Flat when every |fold angle| is at most this, rad.
    pub flat_tol: f64,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Weight κ of the direction's bending metric (0: the plain QP).
    pub bending_metric: f64,
    /// Restarts from perturbed states before a stuck verdict.
    pub restarts: usize,
    /// Seed of the restarts' perturbations.
    pub seed: u64,
}

impl Default for UnfoldOptions {
    fn default() -> Self {
        let d = UnfoldSettings::default();
        UnfoldOptions {
            energy: d.energy,
            p: d.p,
            qp: d.qp,
            flat_tol: d.flat_tol,
            max_iterations: d.max_iterations,
            bending_metric: d.bending_metric,
            restarts: d.restarts,
            seed: d.seed,
        }
    }
}

impl UnfoldOptions {
    /// The unfolding settings, validated.
    pub fn settings(&self) -> Result<UnfoldSettings> {
        let settings = UnfoldSettings {
            energy: self.energy,
            p: self.p,
            qp: self.qp,
            flat_tol: self.flat_tol,
            max_iterations: self.max_iterations,
            bending_metric: self.bending_metric,
            restarts: self.restarts,
            seed: self.seed,
            ..UnfoldSettings::default()
        };
        settings.validate()?;
        Ok(settings)
    }
}

/// `fold`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FoldOptions {
    /// Stop when the most folded crease reaches this percentage of a full fold (an
    /// assignment drive; 0.1 to 100).
    pub to: f64,
    /// Drive these creases (FOLD edge index) to these angles, degrees, instead of the
    /// assignment.
    pub drive: BTreeMap<usize, f64>,
    /// Largest change of any fold angle in one step, degrees: a cap, the step control
    /// chooses below it.
    pub max_step: f64,
    /// Most steps.
    pub max_steps: usize,
    /// Frames of the FOLD animation (2 to 10 000).
    pub frames: usize,
    /// Drive every crease towards the pattern's target angles (a file's `edges_foldAngle`
    /// read as targets): None folds towards them when the file gives them and no `drive` is
    /// named, `Some(true)` requires them, `Some(false)` folds by the assignment instead.
    pub drive_to_targets: Option<bool>,
}

/// Most frames of a fold's animation.
pub const MAX_FRAMES: usize = 10_000;

/// Largest cap on a fold's step, degrees (0.5 rad).
pub const MAX_STEP_DEG: f64 = 28.64788975654116;

impl Default for FoldOptions {
    fn default() -> Self {
        let d = FoldSettings::default();
        FoldOptions {
            to: 100.0,
            drive: BTreeMap::new(),
            max_step: d.max_step.to_degrees(),
            max_steps: d.max_steps,
            frames: 11,
            drive_to_targets: None,
        }
    }
}

impl FoldOptions {
    /// Whether the run folds from flat to the pattern's given state (`drive_to_targets`
    /// asked of a file whose angles are a folded state, not targets).
    fn folds_to_given_state(&self, model: &crate::folding::FoldingModel) -> bool {
        self.drive_to_targets == Some(true)
            && self.drive.is_empty()
            && model.pattern.target_angles.is_none()
            && model.given_fold_angles().iter().any(|&a| a != 0.0)
    }

    /// Where the run starts: the pattern's state, or flat where it folds to that state.
    pub fn start(&self, model: &crate::folding::FoldingModel) -> Vec<f64> {
        let given = model.given_fold_angles();
        if self.folds_to_given_state(model) {
            vec![0.0; given.len()]
        } else {
            given
        }
    }

    /// The folding settings for `pattern`, validated (a driven edge must be one of its
    /// creases).
    pub fn settings(&self, model: &crate::folding::FoldingModel) -> Result<FoldSettings> {
        let targets = match &model.pattern.target_angles {
            Some(by_edge) => Some(model.pattern.creases.iter().map(|&e| by_edge[e]).collect::<Vec<f64>>()),
            // Asked for targets, a file whose angles are a state gives that state.
            None if self.folds_to_given_state(model) => Some(model.given_fold_angles()),
            None => None,
        };
        let drive = if self.drive.is_empty() {
            match (self.drive_to_targets, targets) {
                (Some(true), None) => {
                    return Err(NanofoldError::invalid(
                        "drive_to_targets",
                        "true",
                        "the pattern gives no target angles and no folded state (a file's edges_foldAngle are its targets, or the state to fold to from flat)",
                    ))
                }
                (None | Some(true), Some(targets)) => Drive::Targets { targets, to: self.to },
                _ => Drive::Assignment { to: self.to },
            }
        } else if self.drive_to_targets == Some(true) {
            return Err(NanofoldError::invalid(
                "drive_to_targets",
                "true",
                "drive either named creases (drive) or every crease to its target, not both",
            ));
        } else {
            Drive::Creases(
                self.drive
                    .iter()
                    .map(|(&edge, &degrees)| {
                        let column = model.column_of_edge.get(edge).copied().flatten().ok_or_else(|| {
                            NanofoldError::invalid(
                                "drive",
                                edge,
                                format!(
                                    "edge {edge} is not a crease of the pattern (it has {} edges; creases are the M, V and U ones)",
                                    model.pattern.edges.len()
                                ),
                            )
                        })?;
                        Ok((column, degrees.to_radians()))
                    })
                    .collect::<Result<_>>()?,
            )
        };
        // In the option's own degrees, before the engine's radians.
        let (lowest, highest) = (crate::folding::MIN_STEP.to_degrees(), MAX_STEP_DEG);
        if !(self.max_step >= lowest && self.max_step <= highest) {
            return Err(NanofoldError::invalid(
                "max_step",
                format!("{:e}", self.max_step),
                format!("must lie in [{lowest:.1e}, {highest:.1}] degrees"),
            ));
        }
        if !(2..=MAX_FRAMES).contains(&self.frames) {
            return Err(NanofoldError::invalid(
                "frames",
                self.frames,
                format!("must lie in [2, {MAX_FRAMES}]"),
            ));
        }
        let vertices = model.pattern.vertices.len().max(1);
        let most = crate::folding::MAX_FRAME_POINTS / vertices;
        if self.frames > most {
            return Err(NanofoldError::invalid(
                "frames",
                self.frames,
                format!(
                    "a pattern of {vertices} vertices gets at most {most} frames (frames × vertices ≤ {}: every frame is held in memory until written)",
                    crate::folding::MAX_FRAME_POINTS
                ),
            ));
        }
        let settings = FoldSettings {
            drive,
            max_step: self.max_step.to_radians(),
            max_steps: self.max_steps,
            ..FoldSettings::default()
        };
        settings.validate(model)?;
        Ok(settings)
    }
}

/// `check`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CheckOptions {
    /// Largest closure residual of a state called rigid, rad.
    pub closure_tol: f64,
}

impl Default for CheckOptions {
    fn default() -> Self {
        CheckOptions {
            closure_tol: Settings::default().check.closure_tol,
        }
    }
}

/// A constraint curve's degree as the front ends give it: a number, or `"auto"` with a
/// tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum DegreeOption {
    /// This degree (1 to 20).
    Fixed(usize),
    /// `"auto"`: the lowest degree whose fit meets `tol`.
    Named(AutoDegree),
}

/// The one word a degree may be instead of a number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AutoDegree {
    /// The lowest degree whose fit meets `tol`.
    Auto,
}

/// `constraints`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ConstraintOptions {
    /// The driving crease (the file's index: a FOLD edge index).
    pub drive: usize,
    /// Creases held at angles, degrees.
    pub lock: BTreeMap<usize, f64>,
    /// When not empty: the only creases left free besides the driver.
    pub free: Vec<usize>,
    /// The curves' degree.
    pub degree: DegreeOption,
    /// With degree `"auto"`: the largest accepted fit error, rad.
    pub tol: Option<f64>,
    /// The driving angle's range [from, to], degrees (None: flat to the folded angle; for
    /// many vertices from 5% of it).
    pub range: Option<[f64; 2]>,
    /// Sweep samples.
    pub samples: usize,
    /// Where the samples come from: `sweep` (exact) or, for a single vertex, `unfold`.
    pub source: CurveSource,
    /// Given polynomials to measure against exact closure: (crease by the file's index,
    /// coefficients in degrees of the driving angle in degrees, constant first), as many as
    /// given, a crease more than once if wished.
    pub check: Vec<(usize, Vec<f64>)>,
    /// The export the curves are for: `json`, or `mujoco` (a quartic at most: `degree`
    /// `"auto"` stops at 4).
    pub format: CurveFormat,
}

/// What constraint curves are written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveFormat {
    /// constraints.json.
    #[default]
    Json,
    /// Also a MuJoCo `<equality>` snippet: polycoef holds a quartic at most.
    Mujoco,
}

impl Default for ConstraintOptions {
    fn default() -> Self {
        let d = ConstraintSettings::default();
        ConstraintOptions {
            drive: d.drive,
            lock: BTreeMap::new(),
            free: Vec::new(),
            degree: DegreeOption::Fixed(4),
            tol: None,
            range: None,
            samples: d.samples,
            source: CurveSource::Sweep,
            check: Vec::new(),
            format: CurveFormat::Json,
        }
    }
}

impl ConstraintOptions {
    /// The sweep's settings (checked against the pattern when it runs).
    pub fn settings(&self) -> Result<ConstraintSettings> {
        let mujoco = self.format == CurveFormat::Mujoco;
        let degree = match (self.degree, self.tol) {
            (DegreeOption::Fixed(n), None) if mujoco && n > 4 => return Err(NanofoldError::invalid(
                "degree",
                n,
                "MuJoCo's polycoef holds a quartic at most: 1 to 4 (or \"auto\", capped at 4) with the mujoco format",
            )),
            (DegreeOption::Fixed(n), None) => Degree::Fixed(n),
            (DegreeOption::Named(AutoDegree::Auto), Some(tol)) => Degree::Auto {
                tol,
                at_most: if mujoco { 4 } else { crate::constraints::MAX_DEGREE },
            },
            (DegreeOption::Named(AutoDegree::Auto), None) => {
                return Err(NanofoldError::invalid(
                    "degree",
                    "\"auto\"",
                    "needs tol (the largest accepted fit error, rad)",
                ))
            }
            (DegreeOption::Fixed(_), Some(_)) => {
                return Err(NanofoldError::invalid(
                    "tol",
                    "given",
                    "applies only to degree \"auto\"",
                ))
            }
        };
        Ok(ConstraintSettings {
            drive: self.drive,
            lock: self.lock.iter().map(|(&c, &deg)| (c, deg.to_radians())).collect(),
            free: self.free.clone(),
            degree,
            range: self.range.map(|[a, b]| [a.to_radians(), b.to_radians()]),
            samples: self.samples,
            source: self.source,
            checks: self.check.clone(),
        })
    }
}

/// `simulate`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimulateOptions {
    /// Equations to solve; `auto` compares the forcing time with the fastest period.
    pub model: ModelChoice,
    /// Integrator.
    pub method: Method,
    /// Relative tolerance (the absolute one is the same in rad).
    pub rtol: f64,
    /// End time, s (None: the scene's `time.t_end_s`).
    pub t_end: Option<f64>,
    /// Integrate through contacts instead of stopping at the first.
    pub ignore_collisions: bool,
    /// Integrator steps before the run stops with an error.
    pub max_steps: usize,
}

impl Default for SimulateOptions {
    fn default() -> Self {
        let d = SimulationSettings::default();
        SimulateOptions {
            model: d.model,
            method: d.method,
            rtol: d.rtol,
            t_end: d.t_end,
            ignore_collisions: d.ignore_collisions,
            max_steps: d.max_steps,
        }
    }
}

impl SimulateOptions {
    /// The simulation settings, validated.
    pub fn settings(&self) -> Result<SimulationSettings> {
        let settings = SimulationSettings {
            model: self.model,
            method: self.method,
            rtol: self.rtol,
            t_end: self.t_end,
            ignore_collisions: self.ignore_collisions,
            max_steps: self.max_steps,
            ..SimulationSettings::default()
        };
        settings.validate()?;
        Ok(settings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_engines_defaults_and_unknown_names_are_refused() {
        let fold: FoldOptions = options_from_json(&serde_json::json!({"to": null})).unwrap();
        assert_eq!(fold, FoldOptions::default());
        let (unfold, engine) = (UnfoldOptions::default().settings().unwrap(), UnfoldSettings::default());
        assert_eq!(format!("{unfold:?}"), format!("{engine:?}"));
        let simulate = SimulateOptions::default().settings().unwrap();
        assert_eq!((simulate.rtol, simulate.max_steps), (1e-8, 5_000_000));
        let error = options_from_json::<FoldOptions>(&serde_json::json!({"too": 90})).unwrap_err();
        assert!(error.to_string().contains("too"), "{error}");
        let error = options_from_json::<UnfoldOptions>(&serde_json::json!({"energy": "elastic"})).unwrap_err();
        assert!(error.to_string().contains("energy"), "{error}");
        // Python's spelling and the command line's both name the same choice.
        for name in ["non_separable", "non-separable"] {
            let options: UnfoldOptions = options_from_json(&serde_json::json!({ "energy": name })).unwrap();
            assert_eq!(options.energy, EnergyKind::NonSeparable);
        }
    }

    #[test]
    fn bad_values_of_the_new_options_are_refused_by_name() {
        let sheet = crate::folding::FoldingModel::new(
            crate::pattern::generate::MiuraSpec::default()
                .build()
                .unwrap()
                .build()
                .unwrap(),
        )
        .unwrap();
        let refused = |value: serde_json::Value, field: &str| {
            let error = options_from_json::<FoldOptions>(&value)
                .and_then(|o| o.settings(&sheet))
                .unwrap_err()
                .to_string();
            assert!(error.contains(&format!("`{field}`")), "{value}: {error}");
        };
        refused(serde_json::json!({"frames": 1}), "frames");
        refused(serde_json::json!({"frames": 20_000}), "frames");
        refused(serde_json::json!({"max_step": 40.0}), "max_step");
        refused(serde_json::json!({"to": 150.0}), "drive.to");
        refused(serde_json::json!({"drive": {"0": 30.0}}), "drive");
        refused(serde_json::json!({"frames": "many"}), "frames");
        let curves = |value: serde_json::Value| {
            options_from_json::<ConstraintOptions>(&value)
                .and_then(|o| o.settings())
                .unwrap_err()
                .to_string()
        };
        assert!(curves(serde_json::json!({"format": "xml"})).contains("format"));
        assert!(curves(serde_json::json!({"source": "guess"})).contains("source"));
        assert!(curves(serde_json::json!({"degree": 5, "format": "mujoco"})).contains("quartic"));
        assert!(curves(serde_json::json!({"degree": 4, "tol": 1e-6})).contains("tol"));
        assert!(curves(serde_json::json!({"check": [[2, "x"]]})).contains("check"));
        // What only a single vertex has is refused for a sheet of many, by name.
        let pattern = super::super::Pattern::from_crease_pattern(sheet.pattern.clone()).unwrap();
        for (value, field) in [
            (serde_json::json!({"check": [[0, [0.0, 1.0]]]}), "check"),
            (serde_json::json!({"source": "unfold"}), "source"),
        ] {
            let settings = options_from_json::<ConstraintOptions>(&value)
                .unwrap()
                .settings()
                .unwrap();
            let error = super::super::constraints(&pattern, &settings).unwrap_err().to_string();
            assert!(
                error.contains(&format!("`{field}`")) && error.contains("single vertices"),
                "{error}"
            );
        }
        let error = options_from_json::<SimulateOptions>(&serde_json::json!({"model": "fast"})).unwrap_err();
        assert!(error.to_string().contains("model"), "{error}");
        let error = options_from_json::<FoldOptions>(&serde_json::json!([90])).unwrap_err();
        assert!(error.to_string().contains("options"), "{error}");
    }

    #[test]
    fn degrees_and_percent_become_the_engines_radians_and_fractions() {
        let options: ConstraintOptions = options_from_json(
            &serde_json::json!({"drive": 2, "lock": {"1": 90.0}, "degree": "auto", "tol": 1e-6, "range": [0.0, 180.0]}),
        )
        .unwrap();
        let settings = options.settings().unwrap();
        assert_eq!(settings.lock, vec![(1, std::f64::consts::FRAC_PI_2)]);
        assert_eq!(settings.range, Some([0.0, std::f64::consts::PI]));
        assert!(matches!(settings.degree, Degree::Auto { tol, .. } if tol == 1e-6));
        let error = options_from_json::<ConstraintOptions>(&serde_json::json!({"degree": "auto"}))
            .unwrap()
            .settings()
            .unwrap_err();
        assert!(error.to_string().contains("tol"), "{error}");
    }
}
