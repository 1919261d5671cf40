//! The names most programs need, in one `use nanofold::prelude::*;`: the front door
//! ([`Pattern`], [`check`], [`fold`], [`unfold`] over any pattern, each with its own verdict
//! type — [`CheckVerdict`], [`FoldVerdict`], [`UnfoldVerdict`] — named by [`Named`], and one
//! [`Report`] shape that serialises as its `--json`), scenes and their simulation, and the
//! single vertex's builder and engine (under `VertexPattern`, `unfold_vertex`,
//! `VertexReport`).

pub use crate::commands::{
    check, fold, unfold, unfold_observed, CheckVerdict, CommandKind, Detail, Engine, FoldVerdict, Pattern, Report,
    Settings, UnfoldVerdict, VertexPattern,
};
pub use crate::commands::{fit, open_measurement, open_scene_document, FitReport, FitSettings, FreeParameter};
pub use crate::commands::{modes, open_scene, simulate, ModesReport, SimulationReport};
pub use crate::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, CurveSamples, Setup};
pub use crate::dynamics::integrate::{Method, ProgressObserver};
pub use crate::dynamics::scene::{Scene, System};
pub use crate::dynamics::simulate::{
    first_contact_only, simulate_scene, ModelChoice, ModelKind, Response, Simulation, SimulationSettings,
};
pub use crate::error::{NanofoldError, NumericalError, Result};
pub use crate::folding::PatternVerdict;
pub use crate::folding::{CheckSettings, FoldSettings};
pub use crate::names::{Answer, Named};
pub use crate::pattern::{Assignment, Chain, LoadOptions, VertexBuilder};
pub use crate::read::scene_spec::{ClosedSpec, SceneSpec, StripSpec};
pub use crate::read::{load_pattern, load_scene};
pub use crate::unfold::energy::EnergyKind;
pub use crate::unfold::qp::QpMethod;
pub use crate::unfold::{unfold as unfold_vertex, UnfoldProgress, UnfoldReport as VertexReport, UnfoldSettings};
