//! Dynamics of panel networks (`docs/model.md#panel-networks`): any rigid crease pattern as
//! thin plates on hinges. A spanning tree of the panels, rooted at the anchored one, carries
//! them in fold-angle coordinates; every crease is a coordinate, and the vertex closures of
//! the stars tie the creases off the tree back (redundant rows are normal). The [`model`] is
//! immutable; the [`algorithms`] fill a [`NetworkData`]; the constraint forces come from the
//! regularised saddle-point system of [`kkt`].

pub mod algorithms;
pub mod kkt;
pub mod model;

pub use algorithms::{NetworkData, Spatial, SpatialInertia};
pub use kkt::KktSystem;
pub use model::{Hinge, NetworkModel, NetworkParts, PanelBody};
