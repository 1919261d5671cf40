//! The crate's error types: [`NanofoldError`] for everything a caller can get back, with
//! [`NumericalError`] for the failures of the numerics. Bad input names the field and the
//! value; sources (io, JSON, Clarabel, diffsol) are kept, not flattened into strings.

use thiserror::Error;

/// Everything that can go wrong in nanofold's library code.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NanofoldError {
    /// The input file could not be read.
    #[error("cannot read {path}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The input is not valid JSON, or not of the expected shape.
    #[error("{path}: malformed JSON")]
    Json {
        /// The file (or another name of the input).
        path: String,
        /// serde_json's account, with line and column.
        #[source]
        source: serde_json::Error,
    },
    /// A required key is absent.
    #[error("missing key `{field}`{}", hint.as_deref().map(|h| format!(" ({h})")).unwrap_or_default())]
    MissingField {
        /// The key, as the input names it.
        field: String,
        /// What the key holds, when the name alone does not say.
        hint: Option<String>,
    },
    /// A field holds a value that is out of range or of the wrong kind.
    #[error("invalid `{field}`: {value} ({reason})")]
    InvalidField {
        /// The field, as the input or the settings name it.
        field: String,
        /// The value found.
        value: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The folded state does not close up (`docs/model.md#loop-closure`).
    #[error("folded state violates loop closure: residual {residual:.3e} rad > tolerance {tolerance:.1e} rad (check `{field}`)")]
    ClosureViolated {
        /// The field holding the fold angles.
        field: String,
        /// Rotation angle of the holonomy, rad.
        residual: f64,
        /// Largest accepted residual, rad.
        tolerance: f64,
    },
    /// The pattern has more than one vertex where creases meet.
    #[error("{count} vertices with creases; only single-vertex patterns are supported")]
    MultipleVertices {
        /// How many.
        count: usize,
    },
    /// A numerical routine failed in a way the caller should hear about.
    #[error(transparent)]
    Numerical(#[from] NumericalError),
    /// A sweep cannot reach the requested configuration; says where it stopped and why.
    #[error("cannot reach {what}: stopped at {reached}: {reason}")]
    Unreachable {
        /// The configuration asked for.
        what: String,
        /// Where the sweep stopped.
        reached: String,
        /// Why it could go no further.
        reason: String,
    },
    /// A fitted constraint was evaluated outside the interval it was fitted on.
    #[error("{driver} = {value_deg:.6}° is outside the fitted domain [{lower_deg:.6}°, {upper_deg:.6}°] of the constraint polynomial")]
    OutsideFitDomain {
        /// The driving crease (and when, for a run).
        driver: String,
        /// The driving angle asked for, degrees.
        value_deg: f64,
        /// The fitted interval, degrees.
        lower_deg: f64,
        /// The fitted interval, degrees.
        upper_deg: f64,
    },
    /// Drawing a figure failed.
    #[error("cannot draw {figure}: {message}")]
    Plot {
        /// Which figure.
        figure: String,
        /// The plotting library's account.
        message: String,
    },
    /// Writing an output file failed.
    #[error("cannot write {path}")]
    Output {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
}

/// How a numerical method failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NumericalError {
    /// Newton projection back onto the constraints did not reach its tolerance.
    #[error(
        "constraint restoration failed: residual {residual:.3e} after Newton projection (tolerance {tolerance:.1e})"
    )]
    RestorationFailed {
        /// Largest constraint residual left (rad).
        residual: f64,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// Newton on the loop closure did not converge.
    #[error("loop closure: Newton did not converge: residual {residual:.3e} rad after {iterations} iterations")]
    ClosureNotConverged {
        /// Rotation angle of the holonomy left, rad.
        residual: f64,
        /// Iterations spent.
        iterations: usize,
    },
    /// Clarabel stopped with a status other than solved.
    #[error("direction QP (Clarabel): status {status}")]
    QpStatus {
        /// Clarabel's status, as it names it.
        status: String,
    },
    /// Clarabel refused the problem or its settings.
    #[error("direction QP (Clarabel): the solver refused the problem: {message}")]
    QpSetup {
        /// Clarabel's account.
        message: String,
    },
    /// A matrix that must be symmetric positive definite is not.
    #[error("{matrix} is not positive definite at {at}")]
    NotPositiveDefinite {
        /// Which matrix.
        matrix: &'static str,
        /// Where it was evaluated.
        at: String,
    },
    /// A linear system that must be regular is singular (or too ill-conditioned).
    #[error("{what}: singular ({detail})")]
    Singular {
        /// Which system.
        what: &'static str,
        /// How singular, where.
        detail: String,
    },
    /// A crease of a moving network turned past a half turn: its panels went through each
    /// other, which nothing in the model stops.
    #[error("crease {crease} turned to {angle_deg:.1}°, its panels through each other (past ±180°): nothing in this model stops them (a stiffer drag, or contact, would)")]
    PanelsThrough {
        /// The crease, by the file's edge index.
        crease: usize,
        /// Its angle there, degrees.
        angle_deg: f64,
    },
    /// A computation produced NaN or infinity.
    #[error("{what}: non-finite value ({detail})")]
    NonFinite {
        /// Which computation.
        what: &'static str,
        /// Which value.
        detail: String,
    },
    /// diffsol failed.
    #[error("ODE integration (diffsol) failed")]
    Ode {
        /// diffsol's own error.
        #[source]
        source: diffsol::error::DiffsolError,
    },
    /// diffsol failed during a step; its own message gives its scaled time.
    #[error(
        "ODE integration ({method}, diffsol) failed at t = {reached_s:.6e} s of {end_s:.6e} s \
         (diffsol's message below counts time in units of 1/ω_slow = {time_unit:.6e} s)"
    )]
    OdeStep {
        /// The integrator.
        method: String,
        /// Where the run had got to, s.
        reached_s: f64,
        /// Its end, s.
        end_s: f64,
        /// Seconds per unit of diffsol's scaled time.
        time_unit: f64,
        /// diffsol's own error.
        #[source]
        source: diffsol::error::DiffsolError,
    },
    /// A dynamic run used its step budget before the end of its time span.
    #[error(
        "{method} used its budget of {steps} steps by t = {reached_s:.6e} s of {end_s:.6e} s; at this pace it needs \
         about {projected:.1e} more. Use the esdirk34 method for a slow forcing, tsit45 for a step, the quasi-static \
         model when the time-scale ratio is large, or a looser rtol"
    )]
    StepBudget {
        /// The integrator.
        method: String,
        /// Steps taken.
        steps: usize,
        /// Time reached, s.
        reached_s: f64,
        /// End of the span, s.
        end_s: f64,
        /// Steps it would still need at this pace.
        projected: f64,
    },
    /// More pairs of panels overlap than a contact test measures (layers stacked deep).
    #[error(
        "more than {pairs} pairs of panels overlap {when} (layers stacked deep), the contact test's budget \
         (ContactSettings::pairs_per_panel): whether panels cross cannot be decided there"
    )]
    ContactBudget {
        /// The budget passed.
        pairs: usize,
        /// Where (e.g. "at the start").
        when: String,
    },
    /// An implicit integrator's Newton iterations keep failing.
    #[error(
        "{method}'s Newton iterations failed {failures} times in {steps} steps by t = {reached_s:.6e} s (the fast modes \
         make its iteration matrix ill-conditioned at this tolerance); use the esdirk34 method for a slow forcing, \
         tsit45 for a step, or a looser rtol"
    )]
    NewtonFailures {
        /// The integrator.
        method: String,
        /// Failed Newton iterations so far.
        failures: usize,
        /// Steps taken.
        steps: usize,
        /// Time reached, s.
        reached_s: f64,
    },
    /// A dynamic run of a slow forcing strayed from the quasi-static path it should follow.
    #[error(
        "the {method} run strays {deviation_deg:.3}° from the quasi-static path, whose linear error bound is \
         {bound:.1e} rad: its error control failed on this stiff forcing; use a tighter rtol (1e-10) or the \
         quasi-static model"
    )]
    Strayed {
        /// The integrator.
        method: String,
        /// Largest distance from the quasi-static path, degrees.
        deviation_deg: f64,
        /// The linear bound on that distance, rad.
        bound: f64,
    },
    /// No equilibrium (or balance) was found where one was sought.
    #[error("{what}: {detail}")]
    NoEquilibrium {
        /// Which equilibrium.
        what: &'static str,
        /// Where the search looked and what to change.
        detail: String,
    },
    /// The optimisation executor (argmin) failed for a reason of its own.
    #[error("the unfolding executor failed: {detail}")]
    Executor {
        /// argmin's account.
        detail: String,
    },
    /// A least-squares fit failed.
    #[error("polynomial fit: {detail}")]
    Fit {
        /// Why.
        detail: String,
    },
}

impl From<diffsol::error::DiffsolError> for NumericalError {
    fn from(source: diffsol::error::DiffsolError) -> Self {
        NumericalError::Ode { source }
    }
}

impl From<diffsol::error::DiffsolError> for NanofoldError {
    fn from(source: diffsol::error::DiffsolError) -> Self {
        NumericalError::Ode { source }.into()
    }
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

    /// Shorthand for [`NanofoldError::MissingField`] without a hint.
    pub fn missing(field: impl Into<String>) -> Self {
        NanofoldError::MissingField {
            field: field.into(),
            hint: None,
        }
    }

    /// Shorthand for [`NanofoldError::MissingField`] with what the key holds.
    pub fn missing_with(field: impl Into<String>, hint: impl Into<String>) -> Self {
        NanofoldError::MissingField {
            field: field.into(),
            hint: Some(hint.into()),
        }
    }
}

/// Result alias used across the crate.
pub type Result<T> = std::result::Result<T, NanofoldError>;
