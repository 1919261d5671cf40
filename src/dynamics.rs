//! Dynamics of rigid plates on hinges (`docs/model.md#dynamics`): the [`model`] and its
//! [`algorithms`] (product-of-exponentials kinematics, M, C, drag), the `forcing` law,
//! [`scene`]s (a strip or a closed vertex), the two [`plant`]s ([`strip`], [`closed`]) and one
//! [`simulate`] for both: diffsol [`integrate`] with `contact` location, or the
//! [`quasi_static`] path; [`modes`] at an equilibrium.
//!
//! Layout after Pinocchio: a [`Model`] is immutable, a [`Data`] holds the scratch the
//! algorithms (free functions) fill, so the right-hand side allocates nothing. SI units.

pub mod algorithms;
pub mod closed;
pub(crate) mod contact;
pub(crate) mod forcing;
pub mod integrate;
pub mod model;
pub mod modes;
pub mod network;
pub mod plant;
pub mod quasi_static;
pub mod scene;
pub mod simulate;
pub(crate) mod spec;
pub mod strip;

pub use contact::Collision;
pub use forcing::{Actuation, Forcing, HingeDrive};
pub use model::{Data, Drag, Joint, Model, Plate};
