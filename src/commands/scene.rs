//! Scenes behind the door: a scene's natural modes at its folded equilibrium and its
//! simulated response, each with the summary `nanofold modes --json` and
//! `nanofold simulate --json` print (`docs/model.md#dynamics`).

use crate::dynamics::scene::{Scene, System};
use crate::dynamics::simulate::{simulate_scene, Simulation, SimulationSettings};
use crate::error::Result;
use crate::write::folding_output::{motion_fold, network_modes_fold};
use crate::write::output::{
    closed_modes_summary, network_modes_summary, response_json, response_summary, strip_modes_summary,
};
use crate::write::summary::{ModesSummary, ResponseSummary};
use serde::Serialize;
use serde_json::Value;

/// Reads and builds a scene file (`*.scene.json`); a closed chain's or a device's
/// `pattern` is read relative to the scene's folder.
pub fn open_scene(path: &std::path::Path) -> Result<Scene> {
    crate::read::load_scene(path)?.build()
}

/// Reads and builds scene text: `source` names it in errors, `name` names the scene when
/// it has none, `base` is the folder its `pattern` path is relative to.
pub fn parse_scene(text: &str, source: &str, name: &str, base: &std::path::Path) -> Result<Scene> {
    crate::read::parse_scene(text, source, name, base)?.build()
}

/// What a scene simulates, in one word: `strip`, `closed` or `network`.
pub fn scene_kind(scene: &Scene) -> &'static str {
    match scene.system {
        System::Strip(_) => "strip",
        System::Closed(_) => "closed",
        System::Network(_) => "network",
    }
}

/// Each mode's frames in modes.fold move its largest crease this far either way, rad.
pub const MODE_AMPLITUDE: f64 = 0.1;

/// A scene's modes: the summary and, for a network, each mode as a pair of FOLD frames. It
/// serialises as its summary (`nanofold modes --json`, less the command line's `out`).
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct ModesReport {
    /// As `nanofold modes --json` prints it.
    #[serde(flatten)]
    pub summary: ModesSummary,
    /// A network's modes.fold.
    #[serde(skip)]
    pub fold: Option<Value>,
    /// The modes as the engine found them.
    #[serde(skip)]
    pub detail: ModesDetail,
}

impl ModesReport {
    /// As `nanofold modes --json` prints it: its own serialisation.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).expect("a summary is plain data")
    }
}

/// The modes of each kind of scene, as its engine gives them.
#[derive(Debug, Clone)]
pub enum ModesDetail {
    /// A strip's modes about its folded equilibrium.
    Strip(crate::dynamics::modes::Modes),
    /// A closed chain's, with its torque magnification η.
    Closed(Box<crate::dynamics::closed::modes::ClosedModes>, f64),
    /// A network's.
    Network(Box<crate::dynamics::network::modes::NetworkModes>),
}

/// Natural frequencies, mode shapes and stability at the scene's folded equilibrium.
pub fn modes(scene: &Scene) -> Result<ModesReport> {
    Ok(match &scene.system {
        System::Strip(chain) => {
            let result = crate::dynamics::modes::modes(&chain.model, chain.target_angles().as_slice())?;
            ModesReport {
                summary: ModesSummary::Strip(Box::new(strip_modes_summary(scene, &result))),
                fold: None,
                detail: ModesDetail::Strip(result),
            }
        }
        System::Closed(chain) => {
            let result = chain.folded_modes()?;
            let eta = chain.torque_magnification()?;
            ModesReport {
                summary: ModesSummary::Closed(Box::new(closed_modes_summary(&scene.name, chain, &result, eta))),
                fold: None,
                detail: ModesDetail::Closed(Box::new(result), eta),
            }
        }
        System::Network(model) => {
            let result = crate::dynamics::network::modes::folded_modes(model)?;
            ModesReport {
                summary: ModesSummary::Network(Box::new(network_modes_summary(&scene.name, model, &result))),
                fold: Some(network_modes_fold(model, &result, MODE_AMPLITUDE)?),
                detail: ModesDetail::Network(Box::new(result)),
            }
        }
    })
}

/// The files `modes` writes (rendered, not written): the 3D page modes.html, and a
/// network's modes.fold.
#[cfg(feature = "plot")]
pub fn modes_files(scene: &Scene, report: &ModesReport) -> Result<Vec<(&'static str, String)>> {
    use crate::plot::page::page_of_fold;
    use crate::plot::scene_page::{closed_modes_page, strip_modes_page};
    use crate::write::folding_output::network_modes_oscillation_fold;
    Ok(match (&scene.system, &report.detail) {
        (System::Strip(chain), ModesDetail::Strip(result)) => {
            vec![(
                "modes.html",
                strip_modes_page(&scene.name, chain, result, MODE_AMPLITUDE)?,
            )]
        }
        (System::Closed(chain), ModesDetail::Closed(result, _)) => {
            vec![(
                "modes.html",
                closed_modes_page(&scene.name, chain, result, MODE_AMPLITUDE)?,
            )]
        }
        (System::Network(model), ModesDetail::Network(result)) => {
            let oscillation = network_modes_oscillation_fold(model, result, MODE_AMPLITUDE, 12)?;
            let page = page_of_fold(&oscillation, &scene.name, &[], Some((model.unit * 1e6, "µm")))?;
            let fold = report.fold.as_ref().map_or_else(String::new, Value::to_string);
            vec![("modes.html", page), ("modes.fold", fold)]
        }
        _ => unreachable!("a report's modes are its scene's kind"),
    })
}

/// A scene's simulated response in the forms the command line writes. It serialises as its
/// summary (`nanofold simulate --json`).
#[serde_with::skip_serializing_none]
#[derive(Debug, Clone, Serialize)]
pub struct SimulationReport {
    /// As `nanofold simulate --json` prints it.
    #[serde(flatten)]
    pub summary: ResponseSummary,
    /// response.json: the settings, the model chosen and every sample.
    #[serde(skip)]
    pub response: Value,
    /// motion.fold: the response at even times, every point placed as the fit's marks are.
    #[serde(skip)]
    pub fold: Value,
    /// The run itself.
    #[serde(skip)]
    pub simulation: Simulation,
}

impl SimulationReport {
    /// As `nanofold simulate --json` prints it: its own serialisation.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).expect("a summary is plain data")
    }
}

/// The files `simulate` writes for a run (rendered, not written): response.json,
/// response.svg, snapshots.svg, the 3D page response.html and motion.fold.
#[cfg(feature = "plot")]
pub fn simulation_files(scene: &Scene, report: &SimulationReport) -> Result<Vec<(&'static str, String)>> {
    use crate::plot::response::{response_svg, snapshots_svg};
    use crate::plot::scene_page::response_page;
    let response = &report.simulation.response;
    let mut files = vec![
        ("response.json", report.response.to_string()),
        ("response.svg", response_svg(scene, response)?),
        ("snapshots.svg", snapshots_svg(scene, response)?),
    ];
    files.push(("response.html", response_page(scene, response)?));
    files.push(("motion.fold", report.fold.to_string()));
    Ok(files)
}

/// Simulates a scene (`settings` validated first) and renders its summaries.
pub fn simulate(scene: &Scene, settings: &SimulationSettings) -> Result<SimulationReport> {
    settings.validate()?;
    let simulation = simulate_scene(scene, settings)?;
    let fold = motion_fold(scene, &simulation.response);
    let summary = response_summary(scene, settings, &simulation);
    Ok(SimulationReport {
        response: response_json(&summary, &simulation.response),
        summary,
        fold,
        simulation,
    })
}

/// A scene as one MuJoCo MJCF model (`export mujoco`), with the fastest natural period its
/// time step was checked against, s.
#[derive(Debug, Clone)]
pub struct MujocoExport {
    /// The MJCF text.
    pub mjcf: String,
    /// The scene's fastest natural period, s (the step must be at most a twentieth of it).
    pub fastest_period_s: f64,
}

/// Writes `scene` as MJCF (`docs/model.md#mujoco-scenes`) with `settings` checked against
/// the scene's fastest natural period.
pub fn export_mujoco(scene: &Scene, settings: &crate::write::mujoco::MujocoSettings) -> Result<MujocoExport> {
    use crate::dynamics::plant::Plant;
    let scales = match &scene.system {
        System::Strip(chain) => chain.time_scales()?,
        System::Closed(chain) => chain.time_scales()?,
        System::Network(model) => crate::dynamics::network::NetworkPlant::new(model, false)?.time_scales()?,
    };
    settings.validate(scales.fastest_period_s)?;
    Ok(MujocoExport {
        mjcf: crate::write::mujoco::scene_mjcf(scene, settings)?,
        fastest_period_s: scales.fastest_period_s,
    })
}
