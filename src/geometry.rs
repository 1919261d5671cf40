//! The geometry layer: points on the unit sphere around a vertex (geodesics, fold angles
//! measured from nodes) and the kinematics of one vertex (fold angles ↔ ray directions,
//! loop closure), which boxes overlap (the broad phase of planarity and contact tests), and
//! the closed solids a net is designed for (their dual graphs, spanning trees, symmetries),
//! and the nearest rigid folded form to a noisy one.

pub(crate) mod broad_phase;
pub mod kinematics;
pub mod mesh;
pub mod nets;
pub mod plate_separation;
pub mod point_group;
pub mod polyhedron;
pub mod precision;
pub mod rigid_form;
pub mod solids;
pub mod sphere;
pub mod surface_intersection;
pub mod unfoldings;
pub use broad_phase::overlapping_pairs;

/// Uniform draws in [0, 1) from a fixed seed (xorshift): the deterministic random inputs of
/// the geometry tests and of the tests built on them.
#[cfg(test)]
pub(crate) fn test_draws(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}
