//! The names most programs need, in one `use nanofold::prelude::*;`: the front door
//! ([`Pattern`], [`check`], [`fold`], [`unfold`] over any pattern, one [`Verdict`] and one
//! [`Report`]), scenes and their simulation, and the single vertex's builder and engine
//! (under `VertexPattern`, `unfold_vertex`, `VertexReport`, `VertexVerdict`).

pub use crate::commands::{
    check, fold, unfold, unfold_observed, CommandKind, Detail, Engine, Pattern, Report, Settings, Verdict,
    VertexPattern,
};
pub use crate::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, CurveSamples, Setup};
pub use crate::dynamics::integrate::{Method, ProgressObserver};
pub use crate::dynamics::scene::{Scene, System};
pub use crate::dynamics::simulate::{simulate, ModelChoice, ModelKind, Response, Simulation, SimulationSettings};
pub use crate::error::{NanofoldError, NumericalError, Result};
pub use crate::folding::{CheckSettings, FoldSettings};
pub use crate::pattern::{Assignment, Chain, LoadOptions, VertexBuilder};
pub use crate::read::scene_spec::{ClosedSpec, SceneSpec, StripSpec};
pub use crate::read::{load_pattern, load_scene};
pub use crate::unfold::energy::EnergyKind;
pub use crate::unfold::qp::QpMethod;
pub use crate::unfold::{
    unfold as unfold_vertex, UnfoldProgress, UnfoldReport as VertexReport, UnfoldSettings, Verdict as VertexVerdict,
};
