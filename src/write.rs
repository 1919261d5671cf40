//! The writers: every output file (JSON reports, FOLD animations, MuJoCo models) and the
//! output folders they go into, written atomically. They sit above the engines whose results
//! they write.

pub(crate) mod folder;
pub(crate) mod folding_output;
pub(crate) mod mujoco;
pub mod net_output;
pub(crate) mod output;
pub(crate) mod summary;
pub use folding_output::{
    crease_pattern_fold, network_modes_fold, network_modes_oscillation_fold, network_motion_fold, MOTION_FRAMES,
};
pub use mujoco::{scene_mjcf, LoopClosure, MujocoSettings};
pub use output::write_atomic;
