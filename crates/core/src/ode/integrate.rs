//! The driver: steps a system towards an end time, locates guard crossings on each step's
//! interpolant, and shows every accepted step to an observer, which may stop the run.

use super::events::locate_crossing;
use super::step::Dense;
use super::stepper::Stepper;
use super::system::{GuardSet, OdeSystem, MAX_GUARDS};
use crate::error::SolveError;
use std::ops::ControlFlow;

/// One accepted step, as observers see it.
pub struct StepView<'a, const N: usize> {
    /// The step's interpolant over `[t0, t1]`.
    pub dense: &'a Dense<N>,
    /// The interpolant's value at the step's midpoint `0.5 * (t0 + t1)`, where the driver
    /// has evaluated it for the guards (bit for bit what `dense.eval` gives there); `None` on
    /// a step cut at an event, whose midpoint the driver did not evaluate.
    pub midpoint: Option<&'a [f64; N]>,
}

/// Receives every accepted step; may ask the integrator to stop, and says why.
pub trait Observer<S, const N: usize> {
    /// Why this observer stops a run ([`std::convert::Infallible`] if it never does); the
    /// driver hands it back in [`Stop::Halted`].
    type Halt;
    /// Called once per accepted (possibly event-truncated) step.
    fn on_step(&mut self, _sys: &S, _step: &StepView<'_, N>) -> ControlFlow<Self::Halt> {
        ControlFlow::Continue(())
    }
}

/// An observer that does nothing.
pub struct NoObserver;
impl<S, const N: usize> Observer<S, N> for NoObserver {
    type Halt = std::convert::Infallible;
}

/// Why [`integrate`] returned: `G` is the system's guard set, `H` the observer's halt reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop<G, H> {
    /// The end time was reached.
    EndTime,
    /// A guard crossed to `<= 0` (or, from exactly zero at the step's start, to `< 0`); the
    /// returned state is just past the crossing.
    Event {
        /// Which guard of the mode fired.
        guard: G,
        /// The other guards (by slot, as in [`OdeSystem::guards`]) that crossed in the same
        /// step: positive at its start and `<= 0` at the returned state (or zero and `< 0`),
        /// so at the same instant to the locator's resolution ([`super::run_hybrid`] takes
        /// their jumps too).
        crossed: [bool; MAX_GUARDS],
        /// The guards that were already below zero at the start of the step and `<= 0` at the
        /// returned state: a violation the step began with (a crossing stepped over before),
        /// not one it made.
        violated_before: [bool; MAX_GUARDS],
    },
    /// The observer returned `ControlFlow::Break(halt)`.
    Halted(H),
}

/// Whether a guard that starts a step at `g0` has crossed at a later value `v`: from above
/// zero to `<= 0`, or from exactly zero to `< 0` (never from below zero).
fn crosses_from(g0: f64, v: f64) -> bool {
    if g0 == 0.0 {
        v < 0.0
    } else {
        g0 > 0.0 && v <= 0.0
    }
}

/// Integrates `sys` from `(t, y)` towards `t_end`, advancing `t` and `y` in place.
///
/// The step stops exactly at `t_end`, at a located guard crossing, or where an observer
/// breaks. `stepper` keeps its step-size history across calls; after an event the caller
/// changes the system's mode, and the next call restarts the step from a fresh RHS value.
pub fn integrate<S, O, M, const N: usize>(
    sys: &S,
    stepper: &mut M,
    t: &mut f64,
    y: &mut [f64; N],
    t_end: f64,
    observer: &mut O,
) -> Result<Stop<S::Guard, O::Halt>, SolveError>
where
    S: OdeSystem<N>,
    O: Observer<S, N>,
    M: Stepper<N>,
{
    stepper.restart(sys, *t, y);
    let mut g0 = [0.0; MAX_GUARDS];
    let mut g1 = [0.0; MAX_GUARDS];
    let ng = sys.guards(*t, y, &mut g0);
    debug_assert!(ng <= S::Guard::ALL.len() && S::Guard::ALL.len() <= MAX_GUARDS);
    while *t < t_end {
        let h_cap = sys.max_step_at(*t, y).min(t_end - *t);
        let dense = stepper.step(sys, *t, y, h_cap)?;
        let t1 = dense.t1();
        let y1 = dense.y1();
        sys.guards(t1, &y1, &mut g1);
        // Guards are also checked at the step's midpoint on the interpolant, so a mode that
        // ends and resumes inside one step (a grazing contact that opens and closes again)
        // is not missed; a crossing in the first half wins over one in the second.
        let tm = 0.5 * (dense.t0() + t1);
        let mut gm = [0.0; MAX_GUARDS];
        let ym = dense.eval(tm);
        sys.guards(tm, &ym, &mut gm);
        let guard_at = |i: usize, tt: f64| {
            let mut g = [0.0; MAX_GUARDS];
            sys.guards(tt, &dense.eval(tt), &mut g);
            g[i]
        };
        // Earliest guard to cross within the step: from > 0 to <= 0, or, for a guard that
        // starts the step at exactly zero, from zero to < 0. A guard below zero at the step's
        // start is not watched (a violation the model's own checks report).
        let mut first: Option<(usize, f64, f64)> = None;
        for i in 0..ng {
            if g0[i] < 0.0 {
                continue;
            }
            // A guard at zero is located as if zero were above it: `crosses` is the side
            // the crossing reaches, `lifted` the guard with zero counted on the near side.
            let from_zero = g0[i] == 0.0;
            let crosses = |v: f64| crosses_from(g0[i], v);
            let lifted = |v: f64| {
                if from_zero && v >= 0.0 {
                    f64::MIN_POSITIVE
                } else {
                    v
                }
            };
            let bracket = if crosses(gm[i]) {
                Some((dense.t0(), tm, lifted(g0[i]), gm[i]))
            } else if crosses(g1[i]) {
                Some((tm, t1, lifted(gm[i]), g1[i]))
            } else {
                None
            };
            if let Some((a, b, ga, gb)) = bracket {
                let (lo, hi) = locate_crossing(|tt| lifted(guard_at(i, tt)), a, b, ga, gb);
                if first.is_none_or(|(_, _, h)| hi < h) {
                    first = Some((i, lo, hi));
                }
            }
        }
        match first {
            Some((index, _lo, hi)) => {
                stepper.count_event();
                let cut = stepper.cut_last_step(hi);
                *t = hi;
                *y = cut.y1();
                let mut at_event = [0.0; MAX_GUARDS];
                sys.guards(hi, y, &mut at_event);
                let mut crossed = [false; MAX_GUARDS];
                let mut violated_before = [false; MAX_GUARDS];
                for j in 0..ng {
                    crossed[j] = j != index && crosses_from(g0[j], at_event[j]);
                    violated_before[j] = g0[j] < 0.0 && at_event[j] <= 0.0;
                }
                let view = StepView {
                    dense: cut,
                    midpoint: None,
                };
                // The observer sees the step up to the event; a break here is moot.
                let _ = observer.on_step(sys, &view);
                return Ok(Stop::Event {
                    guard: S::Guard::ALL[index],
                    crossed,
                    violated_before,
                });
            }
            None => {
                *t = t1;
                *y = y1;
                g0 = g1;
                let view = StepView {
                    dense: stepper.last_dense(),
                    midpoint: Some(&ym),
                };
                if let ControlFlow::Break(halt) = observer.on_step(sys, &view) {
                    return Ok(Stop::Halted(halt));
                }
            }
        }
    }
    Ok(Stop::EndTime)
}
