//! One drop, run so that nothing inside the solver can take a sweep down.
//!
//! Every site that simulates drops for a sweep, a search or a study goes through [`run_drop`]:
//! a solver error is returned as it is, and a panic inside the solver is caught and returned
//! as [`DropFailure::Panic`] with its message, so it becomes a recorded failure.

use std::panic::{catch_unwind, AssertUnwindSafe};
use whirlmap_core::{simulate, DropOptions, DropReport, Scene, SolveError};

/// Why a drop produced no report.
#[derive(Debug, Clone, PartialEq)]
pub enum DropFailure {
    /// The solver returned an error.
    Solve(SolveError),
    /// The solver panicked; the panic's message.
    Panic(String),
}

impl DropFailure {
    /// Machine-readable kind: [`SolveError::kind`], or `panic`.
    pub fn kind(&self) -> &'static str {
        match self {
            DropFailure::Solve(e) => e.kind(),
            DropFailure::Panic(_) => "panic",
        }
    }
}

impl std::fmt::Display for DropFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DropFailure::Solve(e) => e.fmt(f),
            DropFailure::Panic(m) => write!(f, "the solver panicked: {m}"),
        }
    }
}

impl std::error::Error for DropFailure {}

/// Runs one drop of `scene` with `opts` ([`whirlmap_core::simulate`]). Never panics: a panic
/// inside the solver is caught and returned as [`DropFailure::Panic`].
pub fn run_drop(scene: &Scene, opts: &DropOptions) -> Result<DropReport, DropFailure> {
    catch_drop(|| simulate(scene, opts))
}

/// Runs `drop` (a simulation) and turns its solver error into [`DropFailure::Solve`] and a
/// panic into [`DropFailure::Panic`].
pub fn catch_drop<T>(drop: impl FnOnce() -> Result<T, SolveError>) -> Result<T, DropFailure> {
    match catch_unwind(AssertUnwindSafe(drop)) {
        Ok(r) => r.map_err(DropFailure::Solve),
        Err(payload) => Err(DropFailure::Panic(panic_message(payload.as_ref()))),
    }
}

/// The message of a panic payload (`panic!` gives a `&str` or a `String`).
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_is_a_failure_with_its_message() {
        let r: Result<(), _> = catch_drop(|| panic!("bad step {}", 3));
        let e = r.unwrap_err();
        assert_eq!(e, DropFailure::Panic("bad step 3".into()));
        assert_eq!(e.kind(), "panic");
        assert_eq!(e.to_string(), "the solver panicked: bad step 3");
        let r: Result<(), _> = catch_drop(|| panic!("plain"));
        assert_eq!(r.unwrap_err(), DropFailure::Panic("plain".into()));
    }

    #[test]
    fn a_solver_error_keeps_its_kind_and_message() {
        let mut s = Scene::paper();
        s.solver.max_step_attempts = 10;
        let opts = DropOptions {
            duration_s: 0.01,
            ..Default::default()
        };
        let want = simulate(&s, &opts).unwrap_err();
        let got = run_drop(&s, &opts).unwrap_err();
        assert_eq!(got.kind(), want.kind());
        assert_eq!(got.to_string(), want.to_string());
    }
}
