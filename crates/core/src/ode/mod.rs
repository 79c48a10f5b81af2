//! The integrator: an embedded Dormand-Prince 5(4) pair with dense output, guard functions
//! located on the interpolant, and streaming observers.
//!
//! It knows nothing of bearings. A problem is an [`OdeSystem`]: a right-hand side, a maximum
//! step, and guard functions that are positive while the system's current discrete mode holds.
//! [`integrate`] steps until the end time, until an observer asks to stop, or until a guard
//! crosses to zero or below; it then returns *why* it stopped as a [`Stop`] and the caller
//! switches mode and calls it again (the step restarts cleanly, without the FSAL stage).

mod bdf;
mod control;
mod dop853;
mod dopri5;
mod events;
mod hybrid;
mod integrate;
mod radau5;
mod rodas;
mod rodas5p;
mod rodas_bdf;
mod rosw;
mod step;
mod stepper;
mod system;

pub use bdf::{Bdf, Formula};
pub use control::StepCore;
pub use dop853::Dop853;
pub use dopri5::Dopri5;
pub use events::locate_crossing;
pub use hybrid::{run_hybrid, Finish, Hybrid, HybridObserver, JumpRules};
pub use integrate::{integrate, NoObserver, Observer, StepView, Stop};
pub use radau5::Radau5;
pub use rodas::Rodas4;
pub use rodas5p::Rodas5p;
pub use rodas_bdf::Rodas4Bdf;
pub use rosw::Ros34pw2;
pub use step::{Dense, Stats, StepControl};
pub use stepper::Stepper;
pub use system::{
    GuardSet, JacobianMatrix, NoGuard, OdeSystem, QuadratureRows, StiffJacobian, MAX_GUARDS,
    MAX_QUAD, MAX_STIFF,
};
