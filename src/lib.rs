//! nanofold: rigid origami of single-vertex crease patterns — unfolding by constrained
//! energy minimisation on the sphere (SPEC §3–5).

pub mod constraints;
pub mod dynamics;
pub mod energy;
pub mod error;
pub mod kinematics;
pub mod output;
pub mod pattern;
#[cfg(feature = "plot")]
pub mod plot;
pub mod qp;
pub mod scene;
pub mod sphere;
pub mod unfold;

pub use error::{NanofoldError, Result};
