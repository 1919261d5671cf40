//! Rigid kinematics of crease patterns with many vertices (`docs/model.md#rigid-folding`):
//! the per-vertex closure conditions and their sparse Jacobian, the degrees of freedom at
//! a state, the panels' poses, and the test that no two panels pass through each other.

pub(crate) mod closure;
pub(crate) mod contact;
pub(crate) mod frames;
pub(crate) mod model;
pub(crate) mod normal;
pub(crate) mod path;
pub(crate) mod poses;
pub(crate) mod rank;
pub(crate) mod reduction;
pub(crate) mod second_order;
pub(crate) mod simd_state;
pub(crate) mod verdict;
pub use normal::NormalSolver;
pub use second_order::{cone_range, quadratic_form, second_order, SecondOrder};

pub use closure::{closure_jacobian, closure_residual, vertex_residuals, worst_of, ClosureJacobian};
pub use contact::{panel_contacts, ContactReport, ContactSettings, PanelContact};
pub use frames::{
    fold_path_and_frames, path_frames, path_frames_on, PathFrame, FRAME_CLOSURE, MAX_FRAME_POINTS, MAX_FRAME_THREADS,
};
pub use model::{FoldingModel, Star, TreeStep};
pub use path::{
    damped_projection, fold_path, project_to_rigid, restore_closure, Drive, FoldPath, FoldSettings, PathStep,
    Projection, StopReason, MIN_GOAL_PERCENT, MIN_STEP, NOISY_STATE_BOUND,
};
pub use poses::{panel_poses, tree_mismatch, vertex_positions, Pose};
pub use rank::{
    jacobian_rank, jacobian_rank_dense, jacobian_rank_sparse, null_space, RankMethod, RankReport, DENSE_RANK_LIMIT,
    RANK_TOL,
};
pub use verdict::{
    check_pattern, degree4_modes, degree4_modes_within, CheckReport, CheckSettings, FlatFoldability, PatternVerdict,
};
