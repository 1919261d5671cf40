//! Calibration (`docs/model.md#calibration`): a scene's parameters fitted to a measured
//! trajectory, with standard errors, intervals and the combinations the data cannot
//! separate. It sits above the dynamics, which it runs with their sensitivities.

pub(crate) mod fit;
pub(crate) mod parameters;

pub use fit::{
    fit, t_quantile, ColumnResiduals, Combination, FitReport, FitSettings, FitStatus, FitTable, FittedParameter, Noise,
    DEGENERATE_FRACTION, SENSITIVITY_STEP, UNDETERMINED_RELATIVE_ERROR,
};
pub use parameters::{resolve, with_values, FreeParameter, ResolvedParameter};
