//! `nanofold._native`: the library's front door (`nanofold::commands`) for the Python
//! package. Every call takes and returns JSON text that the package's Python layer turns into
//! objects, so a result from Python is the command line's `--json` by construction. Long calls
//! run on a worker thread with the GIL released, and Ctrl-C returns at once (the abandoned
//! run finishes within the library's own bounds and its result is dropped).

use nanofold::commands::{self, FromJson, Pattern};
use nanofold::prelude::{Named, NanofoldError, Scene};
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use serde_json::{json, Value};
use std::path::Path;
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

create_exception!(
    _native,
    NativeError,
    PyException,
    "An error of the library: args are (kind, field, value, message)."
);

/// The library's error as (kind, field, value, message), the message with its sources.
fn to_py(error: NanofoldError) -> PyErr {
    let (kind, field, value) = match &error {
        NanofoldError::InvalidField { field, value, .. } => ("invalid_field", field.clone(), value.clone()),
        NanofoldError::MissingField { field, .. } => ("missing_field", field.clone(), String::new()),
        NanofoldError::ClosureViolated { field, .. } => ("closure_violated", field.clone(), String::new()),
        NanofoldError::Io { path, .. } => ("io", "path".to_string(), path.clone()),
        NanofoldError::Output { path, .. } => ("output", "path".to_string(), path.clone()),
        NanofoldError::Json { path, .. } => ("json", "path".to_string(), path.clone()),
        NanofoldError::MultipleVertices { .. } => ("multiple_vertices", String::new(), String::new()),
        NanofoldError::OutsideFitDomain { .. } => ("outside_fit_domain", String::new(), String::new()),
        NanofoldError::Numerical(_) | NanofoldError::Unreachable { .. } => ("numerical", String::new(), String::new()),
        _ => ("other", String::new(), String::new()),
    };
    let mut message = error.to_string();
    let mut source = std::error::Error::source(&error);
    while let Some(cause) = source {
        message.push_str(": ");
        message.push_str(&cause.to_string());
        source = cause.source();
    }
    NativeError::new_err((kind, field, value, message))
}

/// Runs `work` on a worker thread with the GIL released, checking for Ctrl-C (and other
/// signals) every 20 ms.
fn run_detached<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> nanofold::prelude::Result<T> + Send + 'static,
) -> PyResult<T> {
    let (sender, receiver) = mpsc::channel();
    std::thread::Builder::new()
        .name("nanofold".into())
        .spawn(move || {
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work));
            let _ = sender.send(outcome);
        })
        .map_err(|e| NativeError::new_err(("other", "", "", format!("cannot start a worker thread: {e}"))))?;
    let mut receiver = receiver;
    loop {
        let (back, received) = py.detach(move || {
            let received = receiver.recv_timeout(Duration::from_millis(20));
            (receiver, received)
        });
        receiver = back;
        match received {
            Ok(Ok(result)) => return result.map_err(to_py),
            Ok(Err(_)) => {
                return Err(NativeError::new_err((
                    "panic",
                    "",
                    "",
                    "the library panicked (a bug: please report it with the input)",
                )))
            }
            Err(mpsc::RecvTimeoutError::Timeout) => py.check_signals()?,
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(NativeError::new_err((
                    "panic",
                    "",
                    "",
                    "the worker thread ended without a result",
                )))
            }
        }
    }
}

fn parse_json(text: &str, what: &'static str) -> PyResult<Value> {
    serde_json::from_str(text)
        .map_err(|e| NativeError::new_err(("invalid_field", what, "", format!("{what}: not JSON ({e})"))))
}

/// A pattern read by the library (a single vertex or a crease pattern of many).
#[pyclass(frozen, module = "nanofold._native")]
struct PatternHandle {
    pattern: Arc<Pattern>,
}

#[pymethods]
impl PatternHandle {
    /// The pattern's name.
    #[getter]
    fn name(&self) -> String {
        self.pattern.name().to_string()
    }
    /// "vertex" or "network": the engine that answers for it.
    #[getter]
    fn engine(&self) -> &'static str {
        self.pattern.engine().as_str()
    }
    /// The file it was read from, if any.
    #[getter]
    fn source(&self) -> Option<String> {
        self.pattern.source().map(str::to_string)
    }
    /// Every crease's label, in the order of the angle vectors.
    fn crease_labels(&self) -> Vec<String> {
        self.pattern.crease_labels()
    }
    /// The fold angles the file gives, rad.
    fn fold_angles(&self) -> Vec<f64> {
        self.pattern.fold_angles()
    }
    /// Counts of the pattern's sheet as JSON: vertices, creases, interior vertices, panels,
    /// and the reader's notes.
    fn describe(&self) -> String {
        let p = &self.pattern;
        let mut value = json!({"name": p.name(), "engine": p.engine().as_str(), "creases": p.crease_labels().len()});
        if let Some(model) = p.sheet() {
            value["vertices"] = json!(model.pattern.vertices.len());
            value["interior_vertices"] = json!(model.stars.len());
            value["panels"] = json!(model.pattern.panel_count);
            value["reading"] = json!(model.pattern.reading);
        }
        value.to_string()
    }
}

/// Reads a pattern file (FOLD or a native vertex).
#[pyfunction]
fn open_pattern(py: Python<'_>, path: String, options: &str) -> PyResult<PatternHandle> {
    let options = read_options(options)?;
    let pattern = run_detached(py, move || Pattern::open(Path::new(&path), &options))?;
    Ok(PatternHandle {
        pattern: Arc::new(pattern),
    })
}

/// Reads pattern text (FOLD or a native vertex); `name` names it when it has no title,
/// `origin` in errors, `source` (when given) is the file its reports name.
#[pyfunction]
#[pyo3(signature = (text, name, origin, options, source=None))]
fn parse_pattern(
    py: Python<'_>,
    text: String,
    name: String,
    origin: String,
    options: &str,
    source: Option<String>,
) -> PyResult<PatternHandle> {
    let options = read_options(options)?;
    let pattern = run_detached(py, move || {
        let pattern = Pattern::parse(&text, &name, &origin, &options)?;
        Ok(match source {
            Some(source) => pattern.with_source(source),
            None => pattern,
        })
    })?;
    Ok(PatternHandle {
        pattern: Arc::new(pattern),
    })
}

/// The keywords of a call as one command's options (the door's names and units; unknown
/// names refused by name).
fn options<T: FromJson>(text: &str, what: &'static str) -> PyResult<T> {
    T::from_json(&parse_json(text, what)?).map_err(to_py)
}

/// The reading options (`closure_tol`, `angle_sum_tol`), validated.
fn read_options(text: &str) -> PyResult<nanofold::prelude::LoadOptions> {
    options::<commands::ReadOptions>(text, "options")?
        .load_options()
        .map_err(to_py)
}

/// `check`: the report's JSON.
#[pyfunction]
fn check(py: Python<'_>, pattern: &PatternHandle, settings: &str) -> PyResult<(String, String)> {
    let check: commands::CheckOptions = options(settings, "settings")?;
    let mut settings = commands::Settings::default();
    settings.check.closure_tol = check.closure_tol;
    let pattern = pattern.pattern.clone();
    run_detached(py, move || {
        let clock = Instant::now();
        let report = commands::check(&pattern, &settings)?;
        Ok(payload(
            report.to_json(),
            json!({"trajectory": trajectory(&report), "extra": extra(&report)}),
            clock,
        ))
    })
}

/// `unfold`: the report's JSON and the fold angles of every recorded step.
#[pyfunction]
fn unfold(py: Python<'_>, pattern: &PatternHandle, settings: &str) -> PyResult<(String, String)> {
    let unfold: commands::UnfoldOptions = options(settings, "settings")?;
    let settings = commands::Settings {
        unfold: unfold.settings().map_err(to_py)?,
        ..commands::Settings::default()
    };
    let pattern = pattern.pattern.clone();
    run_detached(py, move || {
        let clock = Instant::now();
        let report = commands::unfold(&pattern, &settings)?;
        Ok(payload(
            report.to_json(),
            json!({"trajectory": trajectory(&report), "extra": extra(&report)}),
            clock,
        ))
    })
}

/// `fold`: the report's JSON, the path's fold angles and progress, its FOLD animation and
/// its end state as FOLD.
#[pyfunction]
fn fold(py: Python<'_>, pattern: &PatternHandle, settings: &str) -> PyResult<(String, String)> {
    let fold: commands::FoldOptions = options(settings, "settings")?;
    let pattern = pattern.pattern.clone();
    run_detached(py, move || {
        let clock = Instant::now();
        let run = commands::fold_run(&pattern, &fold)?;
        let commands::Detail::Fold(path) = &run.report.detail else {
            unreachable!("fold answers with a path");
        };
        let mut summary = run.report.to_json();
        summary["frames"] = json!(run.frames.len());
        Ok(payload(
            summary,
            json!({
                "trajectory": trajectory(&run.report),
                "extra": extra(&run.report),
                "progress": path.steps.iter().map(|s| s.progress).collect::<Vec<_>>(),
                "fold_file": run.animation,
                "folded_file": run.end_state,
            }),
            clock,
        ))
    })
}

/// A command's answer as two JSON texts: its summary (the command line's `--json`) and the
/// rest (arrays and FOLD files), which Python reads only when asked.
/// `clock` started when the worker began: the rest records the library's whole time,
/// rendering included (`library_seconds`), against which the Python layer's cost is measured.
fn payload(summary: Value, rest: Value, clock: Instant) -> (String, String) {
    let summary = summary.to_string();
    let rest = rest.to_string();
    // Spliced in after rendering, so the time includes it.
    let seconds = clock.elapsed().as_secs_f64();
    let rest = match rest.strip_suffix('}') {
        Some(open) if open.len() > 1 => format!("{open},\"library_seconds\":{seconds}}}"),
        _ => format!("{{\"library_seconds\":{seconds}}}"),
    };
    (summary, rest)
}

/// What every command's report has, whether or not its `--json` shows it.
fn extra<V>(report: &commands::Report<V>) -> Value {
    json!({
        "crease_labels": report.crease_labels,
        "start_fold_angles_rad": report.start_fold_angles_rad,
        "final_fold_angles_rad": report.final_fold_angles_rad,
        "max_closure_residual_rad": report.max_closure_residual_rad,
        "engine": report.engine.as_str(),
    })
}

/// The fold angles of every step the engine recorded.
fn trajectory<V>(report: &commands::Report<V>) -> Vec<Vec<f64>> {
    match &report.detail {
        commands::Detail::VertexUnfold(r) => r.trajectory.iter().map(|s| s.fold_angles.clone()).collect(),
        commands::Detail::NetworkUnfold(r) => r.steps.iter().map(|s| s.fold_angles.clone()).collect(),
        commands::Detail::NetworkCheck(r, _) => r
            .witness
            .as_ref()
            .map(|w| w.steps.iter().map(|s| s.fold_angles.clone()).collect())
            .unwrap_or_default(),
        commands::Detail::Fold(path) => path.steps.iter().map(|s| s.fold_angles.clone()).collect(),
    }
}

/// `constraints`: the curves' report as `constraints --json` prints it, and the samples.
#[pyfunction]
fn constraints(py: Python<'_>, pattern: &PatternHandle, settings: &str) -> PyResult<(String, String)> {
    let settings = options::<commands::ConstraintOptions>(settings, "settings")?
        .settings()
        .map_err(to_py)?;
    let pattern = pattern.pattern.clone();
    run_detached(py, move || {
        let clock = Instant::now();
        let result = commands::constraints(&pattern, &settings)?;
        Ok(payload(result.to_json(), json!({}), clock))
    })
}

/// Builds a generated pattern: its FOLD text.
#[pyfunction]
fn generate(py: Python<'_>, kind: String, parameters: &str) -> PyResult<String> {
    let generator = commands::Generator::from_options(&kind, &parse_json(parameters, "parameters")?).map_err(to_py)?;
    run_detached(py, move || Ok(generator.to_fold()?.to_string()))
}

/// A scene, built and validated by the library (behind a lock: a closed chain keeps a
/// cache of its last loop closure, so one scene runs one call at a time).
#[pyclass(frozen, module = "nanofold._native")]
struct SceneHandle {
    scene: Arc<Mutex<Scene>>,
}

impl SceneHandle {
    fn with<T>(&self, read: impl FnOnce(&Scene) -> T) -> T {
        read(&self.scene.lock().unwrap_or_else(|poisoned| poisoned.into_inner()))
    }
}

/// Runs `work` on the scene on the worker thread.
fn on_scene<T: Send + 'static>(
    py: Python<'_>,
    scene: &SceneHandle,
    work: impl FnOnce(&Scene) -> nanofold::prelude::Result<T> + Send + 'static,
) -> PyResult<T> {
    let scene = scene.scene.clone();
    run_detached(py, move || {
        work(&scene.lock().unwrap_or_else(|poisoned| poisoned.into_inner()))
    })
}

#[pymethods]
impl SceneHandle {
    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.with(|s| s.name.clone())
    }
    /// "strip", "closed" or "network".
    #[getter]
    fn kind(&self) -> &'static str {
        self.with(commands::scene_kind)
    }
}

/// Reads scene text; `base` is the folder its `pattern` path is relative to.
#[pyfunction]
fn parse_scene(py: Python<'_>, text: String, source: String, name: String, base: String) -> PyResult<SceneHandle> {
    let scene = run_detached(py, move || {
        commands::parse_scene(&text, &source, &name, Path::new(&base))
    })?;
    Ok(SceneHandle {
        scene: Arc::new(Mutex::new(scene)),
    })
}

/// `simulate`: the summary, response.json and motion.fold.
#[pyfunction]
fn simulate(py: Python<'_>, scene: &SceneHandle, settings: &str) -> PyResult<(String, String)> {
    let settings = options::<commands::SimulateOptions>(settings, "settings")?
        .settings()
        .map_err(to_py)?;
    on_scene(py, scene, move |scene| {
        let clock = Instant::now();
        let report = commands::simulate(scene, &settings)?;
        Ok(payload(
            report.to_json(),
            json!({"response": report.response, "fold_file": report.fold}),
            clock,
        ))
    })
}

/// `nets`: a solid (a file path or a generated solid's name) and its ranked nets, the best
/// simulated closing on this machine's cores (the command line's study); the report, and
/// the ranked table (CSV), the best nets as FOLD with their scenes and the gallery.
#[pyfunction]
fn nets(py: Python<'_>, shape: String, settings: &str) -> PyResult<(String, String)> {
    let options = options::<commands::nets::NetsOptions>(settings, "settings")?;
    options.validate().map_err(to_py)?;
    run_detached(py, move || {
        let clock = Instant::now();
        let (opened, mut report) = commands::nets::nets_of_shape(&shape, &options)?;
        let solid = opened.solid;
        commands::nets::study_nets(&solid, &mut report, &options, &|_, _| {})?;
        nets_payload(&solid, &report, &options, clock)
    })
}

/// `nets_table`: the ranked nets alone (no study), as JSON, for a study spread over a cluster.
#[pyfunction]
fn nets_table(py: Python<'_>, shape: String, settings: &str) -> PyResult<String> {
    let options = options::<commands::nets::NetsOptions>(settings, "settings")?;
    options.validate().map_err(to_py)?;
    run_detached(py, move || {
        let (_, report) = commands::nets::nets_of_shape(&shape, &options)?;
        Ok(serde_json::json!({
            "report": report,
            "releases": options.releases(),
            "simulate": options.simulate,
        })
        .to_string())
    })
}

/// `nets_release`: one job of a study: release `release` of the net folded along `folds`,
/// its nominal and sampled devices; the result as JSON.
#[pyfunction]
fn nets_release(py: Python<'_>, shape: String, settings: &str, folds: Vec<usize>, release: usize) -> PyResult<String> {
    let options = options::<commands::nets::NetsOptions>(settings, "settings")?;
    run_detached(py, move || {
        let opened = commands::nets::open_solid_with(&shape, &options.solid_options())?;
        let result = commands::nets::study_release_of(&opened.solid, &opened.name, &folds, release, &options)?;
        Ok(serde_json::to_string(&result).expect("a result is plain data"))
    })
}

/// `nets_with_study`: the ranked nets with a study's releases (JSON: `by_rank`, a list of
/// [rank, [release results]], and `seconds`) put in; the same payload as `nets`.
#[pyfunction]
fn nets_with_study(py: Python<'_>, shape: String, settings: &str, study: &str) -> PyResult<(String, String)> {
    let options = options::<commands::nets::NetsOptions>(settings, "settings")?;
    options.validate().map_err(to_py)?;
    let study = parse_json(study, "study")?;
    run_detached(py, move || {
        let clock = Instant::now();
        let by_rank = commands::nets::releases_from_json(&study["by_rank"])?;
        let seconds = study["seconds"].as_f64().unwrap_or(0.0);
        let (opened, mut report) = commands::nets::nets_of_shape(&shape, &options)?;
        let solid = opened.solid;
        commands::nets::apply_releases(&solid, &mut report, by_rank, &options, seconds)?;
        nets_payload(&solid, &report, &options, clock)
    })
}

/// The report and the files of a ranked (and maybe studied) table, as `nets` returns them.
fn nets_payload(
    solid: &commands::nets::Polyhedron,
    report: &commands::nets::NetsReport,
    options: &commands::nets::NetsOptions,
    clock: Instant,
) -> nanofold::prelude::Result<(String, String)> {
    let summary = serde_json::to_value(report).expect("a report is plain data");
    let files = commands::nets::nets_files(solid, report, options)?;
    let (mut folds, mut scenes) = (Vec::new(), Vec::new());
    let mut rest = serde_json::Map::new();
    for (file, text) in files {
        if file.ends_with(".scene.json") {
            scenes.push(
                serde_json::from_str::<Value>(&text)
                    .map_err(|e| NanofoldError::invalid("scene", file.clone(), e.to_string()))?,
            );
        } else if file.ends_with(".fold") {
            folds.push(
                serde_json::from_str::<Value>(&text)
                    .map_err(|e| NanofoldError::invalid("fold", file.clone(), e.to_string()))?,
            );
        } else if file == "nets.csv" {
            rest.insert("table_csv".into(), Value::String(text));
        } else if file == "gallery.svg" {
            rest.insert("gallery_svg".into(), Value::String(text));
        }
    }
    rest.insert("folds".into(), Value::Array(folds));
    rest.insert("scenes".into(), Value::Array(scenes));
    Ok(payload(summary, Value::Object(rest), clock))
}

/// `fit`: a scene file's JSON (with the name, source and base folder its pattern path is
/// relative to) fitted to measurement CSV text; the report, and the fitted scene with the
/// table of measured against fitted values.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fit(
    py: Python<'_>,
    scene: &str,
    source: String,
    name: String,
    base: String,
    measured: String,
    measured_source: String,
    settings: &str,
) -> PyResult<(String, String)> {
    let settings = options::<commands::FitOptions>(settings, "settings")?
        .settings()
        .map_err(to_py)?;
    let document = commands::SceneDocument {
        value: parse_json(scene, "scene")?,
        source,
        fallback_name: name,
        base: base.into(),
    };
    run_detached(py, move || {
        let clock = Instant::now();
        let measurement = commands::parse_measurement(&measured, &measured_source)?;
        let report = commands::fit(&document, &measurement, &settings)?;
        let summary = serde_json::to_value(&report).expect("a report is plain data");
        Ok(payload(
            summary,
            json!({"fitted_scene": report.fitted_scene, "table_csv": commands::fit_table_csv(&report.table)}),
            clock,
        ))
    })
}

/// `modes`: the summary and a network's modes.fold.
#[pyfunction]
fn modes(py: Python<'_>, scene: &SceneHandle) -> PyResult<(String, String)> {
    on_scene(py, scene, |scene| {
        let clock = Instant::now();
        let report = commands::modes(scene)?;
        Ok(payload(report.to_json(), json!({"fold_file": report.fold}), clock))
    })
}

/// A call that does nothing but cross the boundary: the per-call overhead's floor.
#[pyfunction]
fn noop(py: Python<'_>) -> PyResult<String> {
    run_detached(py, || Ok(String::new()))
}

/// Waits `seconds` on the worker thread, as a long call does, and returns: a call whose
/// length is known, so the interruption and GIL tests do not depend on how fast the library
/// is. At most 60 s.
#[pyfunction]
fn wait(py: Python<'_>, seconds: f64) -> PyResult<f64> {
    if !(0.0..=60.0).contains(&seconds) {
        return Err(to_py(NanofoldError::invalid("seconds", seconds, "must lie in [0, 60]")));
    }
    run_detached(py, move || {
        let clock = Instant::now();
        std::thread::sleep(Duration::from_secs_f64(seconds));
        Ok(clock.elapsed().as_secs_f64())
    })
}

/// The library's version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("NativeError", m.py().get_type::<NativeError>())?;
    m.add_class::<PatternHandle>()?;
    m.add_class::<SceneHandle>()?;
    for function in [
        wrap_pyfunction!(open_pattern, m)?,
        wrap_pyfunction!(parse_pattern, m)?,
        wrap_pyfunction!(check, m)?,
        wrap_pyfunction!(unfold, m)?,
        wrap_pyfunction!(fold, m)?,
        wrap_pyfunction!(constraints, m)?,
        wrap_pyfunction!(generate, m)?,
        wrap_pyfunction!(parse_scene, m)?,
        wrap_pyfunction!(simulate, m)?,
        wrap_pyfunction!(modes, m)?,
        wrap_pyfunction!(fit, m)?,
        wrap_pyfunction!(nets, m)?,
        wrap_pyfunction!(nets_table, m)?,
        wrap_pyfunction!(nets_release, m)?,
        wrap_pyfunction!(nets_with_study, m)?,
        wrap_pyfunction!(noop, m)?,
        wrap_pyfunction!(wait, m)?,
        wrap_pyfunction!(version, m)?,
    ] {
        m.add_function(function)?;
    }
    Ok(())
}
