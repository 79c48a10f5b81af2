//! The interface the driver steps through: an adaptive method with dense output (a one-step
//! method, or the multistep BDF, which keeps its history from step to step).

use super::control::StepCore;
use super::step::{Dense, Stats};
use super::system::OdeSystem;
use crate::error::SolveError;

/// An adaptive method with dense output, as [`super::integrate`] drives it.
pub trait Stepper<const N: usize> {
    /// Evaluates the derivative at `(t, y)` (a clean restart after a mode switch) and, on
    /// the first call, picks an initial step. After [`Stepper::keep_history_at_next_restart`]
    /// a stepper with a history may keep it instead, when `(t, y)` is where its last step
    /// ended.
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]);
    /// Takes one accepted step from `(t, y)` of at most `h_cap`, retrying rejected attempts.
    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError>;
    /// The step-size history, counters and last interpolant every stepper keeps.
    fn core(&self) -> &StepCore<N>;
    /// [`Stepper::core`], mutably.
    fn core_mut(&mut self) -> &mut StepCore<N>;
    /// Cuts the last accepted step at `t_cut` (an event time inside it) and returns it. The
    /// state there comes from the interpolant; the next restart re-evaluates the derivative.
    fn cut_last_step(&mut self, t_cut: f64) -> &Dense<N> {
        self.core_mut().cut_last_step(t_cut)
    }
    /// The interpolant of the last accepted step.
    fn last_dense(&self) -> &Dense<N> {
        &self.core().dense
    }
    /// Caps the next step at `h_s` (after a mode switch: the error estimate is least reliable
    /// on the first step of a new mode; the controller grows the step again from there).
    fn cap_next_step(&mut self, h_s: f64) {
        self.core_mut().cap_next_step(h_s)
    }
    /// Work counters, accumulated over every call.
    fn stats(&self) -> Stats {
        self.core().stats
    }
    /// Says that the next [`Stepper::restart`] follows no mode switch: the run stopped at an
    /// end time or an observer's halt and goes on from the same state, with the system's
    /// right-hand side the same or changed by a small parameter step (the thermal coupling's
    /// macro step). A stepper with a history (the BDF) may then keep it; the default does
    /// nothing, and a one-step method restarts as always.
    fn keep_history_at_next_restart(&mut self) {}
    /// Counts one located event.
    fn count_event(&mut self) {
        self.core_mut().stats.events += 1;
    }
}
