//! The writers: every output file (JSON reports, FOLD animations, MuJoCo models) and the
//! output folders they go into, written atomically. They sit above the engines whose results
//! they write.

pub(crate) mod folder;
pub mod folding_output;
pub mod mujoco;
pub mod output;
pub(crate) mod summary;
