//! Typed errors: invalid parameters, and solver failures that carry the time they happened.

use thiserror::Error;

/// A parameter outside its allowed range, named by its field.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("invalid {field} = {value}: allowed {allowed}")]
pub struct InvalidParameter {
    /// The field's name as it appears in the scene file (for example `clearance_m`).
    pub field: String,
    /// The offending value, as text.
    pub value: String,
    /// The allowed range, in words (for example `> 0 and finite`).
    pub allowed: String,
}

impl InvalidParameter {
    /// Builds the error for `field` with `value` and the allowed range.
    pub fn new(field: &str, value: impl ToString, allowed: &str) -> Self {
        Self {
            field: field.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }
}

/// Why a drop could not be integrated to its end.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SolveError {
    /// The step size fell below the floor without meeting the tolerance.
    #[error("step size underflow at t = {t_s:.9} s (h = {h_s:e} s)")]
    StepSizeUnderflow {
        /// Simulated time of the failure (s).
        t_s: f64,
        /// The step that was too small (s).
        h_s: f64,
    },
    /// The step budget ran out.
    #[error("step budget of {attempts} step attempts exhausted at t = {t_s:.9} s")]
    StepBudget {
        /// Simulated time when the budget ran out (s).
        t_s: f64,
        /// Attempts made (accepted plus rejected).
        attempts: u64,
    },
    /// The state or its derivative became NaN or infinite.
    #[error("non-finite state at t = {t_s:.9} s")]
    NonFiniteState {
        /// Simulated time of the failure (s).
        t_s: f64,
    },
    /// Too many mode switches (contact, stick/slip) for the event budget: a Zeno-like chatter.
    #[error("event budget of {events} mode switches exhausted at t = {t_s:.9} s")]
    EventBudget {
        /// Simulated time when the budget ran out (s).
        t_s: f64,
        /// Events located so far.
        events: u64,
    },
    /// The scene failed validation.
    #[error(transparent)]
    Invalid(#[from] InvalidParameter),
}

impl SolveError {
    /// A short machine-readable name of the failure (for records and CLI output).
    pub fn kind(&self) -> &'static str {
        match self {
            SolveError::StepSizeUnderflow { .. } => "step_size_underflow",
            SolveError::StepBudget { .. } => "step_budget",
            SolveError::NonFiniteState { .. } => "non_finite_state",
            SolveError::EventBudget { .. } => "event_budget",
            SolveError::Invalid(_) => "invalid_parameter",
        }
    }
}
