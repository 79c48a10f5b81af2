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
    /// The energy audit did not close: the energy at the end plus the heat and work booked
    /// along the way differ from the energy at release by more than the threshold
    /// ([`crate::drop::AUDIT_THRESHOLD`]), relative to the largest energy in play (or an
    /// energy was not finite). The results of such a drop are not trustworthy.
    #[error(
        "energy audit failed at t = {t_s:.9} s: residual {residual_rel:.3e} above the \
         threshold {threshold:.0e} (initial {initial_j:.6e} J = final {final_j:.6e} J + \
         losses {losses_j:.6e} J); the numerics created or lost that much energy: run the \
         drop at a tighter tolerance or fidelity"
    )]
    EnergyAudit {
        /// Simulated time at the end of the drop (s).
        t_s: f64,
        /// The audit's relative residual (infinite when an energy was not finite).
        residual_rel: f64,
        /// The threshold it exceeded.
        threshold: f64,
        /// Mechanical energy at release (J).
        initial_j: f64,
        /// Mechanical energy at the end (J).
        final_j: f64,
        /// Friction heat, damping loss and drag work (J).
        losses_j: f64,
    },
    /// The drop ended in a state the physics rules out, which the energy audit can miss: the
    /// rotor through the race with the contact not acting (a contact stepped over), or friction
    /// heat far below zero (friction made energy). The results of such a drop are not
    /// trustworthy.
    #[error(
        "unphysical result at t = {t_s:.9} s: {what}; the numerics missed the contact's \
         dynamics: run the drop at a tighter tolerance (solver.rtol) or fidelity"
    )]
    Unphysical {
        /// Simulated time at the end of the drop (s).
        t_s: f64,
        /// What the physics rules out, with its numbers.
        what: String,
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
            SolveError::EnergyAudit { .. } => "energy_audit",
            SolveError::Unphysical { .. } => "unphysical",
            SolveError::Invalid(_) => "invalid_parameter",
        }
    }
}
