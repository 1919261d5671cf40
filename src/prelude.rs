//! The names most programs need, in one `use nanofold::prelude::*;`.

pub use crate::constraints::{sweep_samples, ConstraintPoly, ConstraintReport, CurveSamples, Setup};
pub use crate::dynamics::integrate::Method;
pub use crate::dynamics::scene::{Scene, SceneSpec, System};
pub use crate::dynamics::simulate::{simulate, ModelChoice, ModelKind, Response, Simulation, SimulationSettings};
pub use crate::dynamics::spec::{ClosedSpec, StripSpec};
pub use crate::error::{NanofoldError, NumericalError, Result};
pub use crate::io::{load_pattern, load_scene};
pub use crate::pattern::{Assignment, Chain, LoadOptions, Pattern, VertexBuilder};
pub use crate::unfold::energy::EnergyKind;
pub use crate::unfold::qp::QpMethod;
pub use crate::unfold::{unfold, UnfoldReport, UnfoldSettings, Verdict};
