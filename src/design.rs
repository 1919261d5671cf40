//! The design layer: from a shape to the nets that make it, ranked. It sits above the
//! geometry and crease patterns it uses, below the door.

pub mod closing;
pub mod nets;
