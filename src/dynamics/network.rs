//! Dynamics of panel networks (`docs/model.md#panel-networks`): any rigid crease pattern as
//! thin plates on hinges. A spanning tree of the panels, rooted at the anchored one, carries
//! them in fold-angle coordinates; every crease is a coordinate, and the vertex closures of
//! the stars tie the creases off the tree back (redundant rows are normal). The [`model`] is
//! immutable; the [`algorithms`] fill a [`NetworkData`]; the constraint forces come from the
//! regularised saddle-point system of [`kkt`]; the [`manifold`] holds the statics and the
//! modes; a flat start is left along a branch by [`start`]; [`plant`] joins them for the
//! integrator, with the [`contact`] candidates; [`reduced`] is the one-DOF model choice on
//! the [`fitted`] curves.

pub mod algorithms;
pub mod assemble;
pub mod contact;
pub mod fitted;
pub mod hessian;
pub mod kkt;
pub mod manifold;
pub mod model;
pub mod modes;
pub mod plant;
pub mod reduced;
pub mod rows;
pub mod start;

pub use algorithms::{NetworkData, Spatial, SpatialInertia};
pub use kkt::KktSystem;
pub use model::{Hinge, NetworkModel, NetworkParts, PanelBody};
pub use plant::NetworkPlant;
pub use reduced::{FittedReduction, ReducedPlant};
