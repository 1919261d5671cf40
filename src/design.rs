//! The design layer: from a shape to the nets that make it, ranked, and whether each net's
//! device closes (with its yield under fabrication variation). It sits above the geometry,
//! crease patterns and dynamics it uses, below the door.

pub mod closing;
pub mod fabrication;
pub mod fidelity;
pub mod nets;
