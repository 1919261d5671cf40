//! The crate's one error type: every bad input names the field and the value.

use thiserror::Error;

/// Everything that can go wrong in nanofold's library code.
#[derive(Debug, Error)]
pub enum NanofoldError {
    /// The input file could not be read.
    #[error("cannot read {path}: {error}")]
    Io { path: String, error: std::io::Error },
    /// The input is not valid JSON.
    #[error("{path}: malformed JSON: {message}")]
    Json { path: String, message: String },
    /// A required key is absent.
    #[error("missing key `{field}`")]
    MissingField { field: String },
    /// A field holds a value that is out of range or of the wrong kind.
    #[error("invalid `{field}`: {value} ({reason})")]
    InvalidField {
        field: String,
        value: String,
        reason: String,
    },
    /// The folded state does not close up (SPEC §2).
    #[error("folded state violates loop closure: residual {residual:.3e} rad > tolerance {tolerance:.1e} rad (check `{field}`)")]
    ClosureViolated {
        field: String,
        residual: f64,
        tolerance: f64,
    },
    /// The pattern has more than one vertex where creases meet.
    #[error("{count} vertices with creases; only single-vertex patterns are supported")]
    MultipleVertices { count: usize },
    /// A numerical routine failed in a way the caller should hear about.
    #[error("numerical failure in {stage}: {message}")]
    Numerical { stage: String, message: String },
    /// A sweep cannot reach the requested configuration; says where it stopped and why.
    #[error("cannot reach {what}: stopped at {reached}: {reason}")]
    Unreachable {
        what: String,
        reached: String,
        reason: String,
    },
    /// A fitted constraint was evaluated outside the interval it was fitted on.
    #[error("{driver} = {value_deg:.6}° is outside the fitted domain [{lower_deg:.6}°, {upper_deg:.6}°] of the constraint polynomial")]
    OutsideFitDomain {
        driver: String,
        value_deg: f64,
        lower_deg: f64,
        upper_deg: f64,
    },
    /// Writing an output file failed.
    #[error("cannot write {path}: {message}")]
    Output { path: String, message: String },
}

impl NanofoldError {
    /// Shorthand for [`NanofoldError::InvalidField`].
    pub fn invalid(field: impl Into<String>, value: impl ToString, reason: impl Into<String>) -> Self {
        NanofoldError::InvalidField {
            field: field.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}

/// Result alias used across the crate.
pub type Result<T> = std::result::Result<T, NanofoldError>;
