//! The geometry layer: points on the unit sphere around a vertex (geodesics, fold angles
//! measured from nodes) and the kinematics of one vertex (fold angles ↔ ray directions,
//! loop closure), and which boxes overlap (the broad phase of planarity and contact tests).

pub mod broad_phase;
pub mod kinematics;
pub mod sphere;
