//! The geometry layer: points on the unit sphere around a vertex (geodesics, fold angles
//! measured from nodes) and the kinematics of one vertex (fold angles ↔ ray directions,
//! loop closure).

pub mod kinematics;
pub mod sphere;
