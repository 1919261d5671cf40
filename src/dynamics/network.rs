//! Dynamics of panel networks (`docs/model.md#panel-networks`): any rigid crease pattern as
//! thin plates on hinges. A spanning tree of the panels, rooted at the anchored one, carries
//! them in fold-angle coordinates; every crease is a coordinate, and the vertex closures of
//! the stars tie the creases off the tree back (redundant rows are normal). The `model` is
//! immutable; the `algorithms` fill a [`NetworkData`]; the constraint forces come from the
//! regularised saddle-point system of `kkt`; the `manifold` holds the statics and the
//! modes; a flat start is left along a branch by `start`; `plant` joins them for the
//! integrator, with the `contact` candidates; `reduced` is the one-DOF model choice on
//! the `fitted` curves.

pub(crate) mod algorithms;
pub(crate) mod assemble;
pub mod closing;
pub(crate) mod contact;
pub(crate) mod contact_balance;
pub(crate) mod face_contact;
pub(crate) mod fitted;
pub(crate) mod hessian;
pub(crate) mod kkt;
pub(crate) mod manifold;
pub(crate) mod model;
pub(crate) mod modes;
pub(crate) mod plant;
pub(crate) mod reduced;
pub(crate) mod rows;
pub(crate) mod start;
pub use modes::folded_modes;

pub use algorithms::{NetworkData, Spatial, SpatialInertia};
pub use fitted::ReducedReport;
pub use kkt::KktSystem;
pub use model::{Hinge, NetworkModel, NetworkParts, PanelBody};
pub use plant::{NetworkPlant, NetworkRunReport};
pub use reduced::{FittedReduction, ReducedPlant};
