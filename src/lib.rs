//! nanofold: rigid origami of single-vertex crease patterns — unfolding by constrained
//! energy minimisation on the sphere (SPEC §3–5).

pub mod constraints;
pub mod dynamics;
pub mod error;
pub mod geometry;
pub mod io;
pub mod pattern;
#[cfg(feature = "plot")]
pub mod plot;
pub mod prelude;
pub mod unfold;

pub use error::{NanofoldError, Result};
