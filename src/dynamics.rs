//! Dynamics of rigid plates on hinges (`docs/model.md#dynamics`). One model of rigid
//! panels, the panel [`network`] (spatial composite rigid bodies, recursive Newton–Euler,
//! the loops' closures as constraint rows), runs every device; a strip and a closed vertex
//! are [`scene`]s that assemble into it. Two other sets of equations stay as model choices
//! only where `docs/performance.md#which-dynamics-model-runs-a-scene` measures them faster,
//! each held to the network by tests: the joint-space chain of [`model`] and [`algorithms`]
//! (product of exponentials, dense M; the network's oracle on a strip) for a short `strip`,
//! and the [`closed`] chain's reduced equation on fitted curves for a single vertex. Each
//! is a `plant` for one integrator, [`simulate::simulate_scene`]: diffsol `integrate`
//! with contact location, or the `quasi_static` path; [`modes`] at an equilibrium.
//!
//! Layout after Pinocchio: a [`Model`] is immutable, a [`Data`] holds the scratch the
//! algorithms (free functions) fill, so the right-hand side allocates nothing. SI units.

pub mod algorithms;
pub mod closed;
pub(crate) mod contact;
pub(crate) mod forcing;
pub(crate) mod integrate;
pub mod model;
pub mod modes;
pub mod network;
pub(crate) mod plant;
pub mod points;
pub(crate) mod quasi_static;
pub mod scene;
pub mod sensitivity;
pub mod simulate;
pub(crate) mod spec;
pub(crate) mod strip;
pub use integrate::{output_times, Method};
pub use plant::Plant;
pub use quasi_static::{quasi_static_deviation, quasi_static_path, QuasiStaticPath};
pub use strip::StripPlant;

pub use contact::Collision;
pub use forcing::{Actuation, Forcing, HingeDrive};
pub use model::{Data, Drag, Joint, Model, Plate};
