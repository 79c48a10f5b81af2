//! The integrator: an embedded Dormand-Prince 5(4) pair with dense output, guard functions
//! located on the interpolant, and streaming observers.
//!
//! It knows nothing of bearings. A problem is an [`OdeSystem`]: a right-hand side, a maximum
//! step, and guard functions that are positive while the system's current discrete mode holds.
//! [`integrate`] steps until the end time, until an observer asks to stop, or until a guard
//! crosses to zero or below; it then returns *why* it stopped as a [`Stop`] and the caller
//! switches mode and calls it again (the step restarts cleanly, without the FSAL stage).

mod control;
mod dop853;
mod dopri5;
mod events;
mod rosw;

pub use control::StepCore;
pub use dop853::Dop853;
pub use dopri5::{Dense, Dopri5, StepControl};
pub use events::locate_crossing;
pub use rosw::Ros34pw2;

use crate::error::SolveError;
use std::ops::ControlFlow;

/// Most guard functions one mode of a system may declare.
pub const MAX_GUARDS: usize = 4;

/// Most state components an approximate (stiff) Jacobian may couple.
pub const MAX_STIFF: usize = 10;

/// The matrix of a [`StiffJacobian`] (nalgebra's fixed-size storage).
pub type JacobianMatrix = nalgebra::SMatrix<f64, MAX_STIFF, MAX_STIFF>;

/// An approximate Jacobian restricted to a few state components, for the linearly implicit
/// stepper ([`Ros34pw2`]): `jac[(a, b)]` approximates `d f_{idx[a]} / d y_{idx[b]}`; every
/// entry outside these rows and columns is taken as zero.
#[derive(Debug, Clone, Copy)]
pub struct StiffJacobian {
    /// The coupled components (the first `len` entries are used).
    pub idx: [usize; MAX_STIFF],
    /// How many components are coupled.
    pub len: usize,
    /// The restricted Jacobian (1/s units of the state's components).
    pub jac: JacobianMatrix,
    /// How many leading components are *kinematic*: positions `q_a` (a < `kinematic`) whose
    /// rows say exactly `q_a' = y_{idx[kinematic + a]}` (`jac[(a, kinematic + a)] = 1`, every
    /// other entry of the row zero). The stepper then eliminates them and factors only the
    /// remaining `len - kinematic` components (a Schur complement). 0 (the default of
    /// [`StiffJacobian::over`]): no such structure is claimed. At most `len / 2`.
    pub kinematic: usize,
}

impl StiffJacobian {
    /// An empty Jacobian over the components `idx` (at most [`MAX_STIFF`]).
    pub fn over(idx: &[usize]) -> Self {
        let mut s = Self {
            idx: [0; MAX_STIFF],
            len: idx.len(),
            jac: JacobianMatrix::zeros(),
            kinematic: 0,
        };
        s.idx[..idx.len()].copy_from_slice(idx);
        s
    }
}

/// A first-order system `y' = f(t, y)` with a fixed-size state and mode guards.
pub trait OdeSystem<const N: usize> {
    /// Writes `f(t, y)` into `dy`.
    fn rhs(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);

    /// Writes the current mode's guard values into `g` and returns how many there are.
    /// Each guard is positive while the mode holds; a crossing to `<= 0` is an event.
    /// The default has none.
    fn guards(&self, _t: f64, _y: &[f64; N], _g: &mut [f64; MAX_GUARDS]) -> usize {
        0
    }

    /// Largest step allowed in the current mode (s); `f64::INFINITY` for none.
    fn max_step(&self) -> f64 {
        f64::INFINITY
    }

    /// Largest step allowed from state `(t, y)` (s); by default [`OdeSystem::max_step`].
    fn max_step_at(&self, _t: f64, _y: &[f64; N]) -> f64 {
        self.max_step()
    }

    /// An approximation of the stiff part of the Jacobian at `(t, y)`, for the linearly
    /// implicit stepper. It need not be exact (a W-method keeps its order for any matrix); it
    /// must hold the terms that make the system stiff. The default, `None`, is the zero
    /// matrix, which turns [`Ros34pw2`] into an explicit 3rd-order Runge-Kutta method.
    fn stiff_jacobian(&self, _t: f64, _y: &[f64; N]) -> Option<StiffJacobian> {
        None
    }
}

/// One accepted step, as observers see it.
pub struct StepView<'a, const N: usize> {
    /// The step's interpolant over `[t0, t1]`.
    pub dense: &'a Dense<N>,
}

/// Receives every accepted step; may ask the integrator to stop.
pub trait Observer<S, const N: usize> {
    /// Called once per accepted (possibly event-truncated) step.
    fn on_step(&mut self, _sys: &S, _step: &StepView<'_, N>) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// An observer that does nothing.
pub struct NoObserver;
impl<S, const N: usize> Observer<S, N> for NoObserver {}

/// Why [`integrate`] returned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stop {
    /// The end time was reached.
    EndTime,
    /// Guard `index` crossed to `<= 0`; the returned state is just past the crossing.
    Event {
        /// Which guard of the mode fired.
        index: usize,
    },
    /// An observer returned `ControlFlow::Break`.
    Observer,
}

/// Counters of the work done (the figures benchmarks report).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Located events (mode switches).
    pub events: u64,
    /// Stiff Jacobians evaluated (implicit stepper only).
    #[serde(default)]
    pub jacobians: u64,
    /// LU factorisations of the Rosenbrock matrix (implicit stepper only; one per attempt).
    #[serde(default)]
    pub factorizations: u64,
}

/// An adaptive one-step method with dense output, as [`integrate`] drives it.
pub trait Stepper<const N: usize> {
    /// Evaluates the derivative at `(t, y)` (a clean restart after a mode switch) and, on
    /// the first call, picks an initial step.
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
    /// Counts one located event.
    fn count_event(&mut self) {
        self.core_mut().stats.events += 1;
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
) -> Result<Stop, SolveError>
where
    S: OdeSystem<N>,
    O: Observer<S, N>,
    M: Stepper<N>,
{
    stepper.restart(sys, *t, y);
    let mut g0 = [0.0; MAX_GUARDS];
    let mut g1 = [0.0; MAX_GUARDS];
    let ng = sys.guards(*t, y, &mut g0);
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
        sys.guards(tm, &dense.eval(tm), &mut gm);
        let guard_at = |i: usize, tt: f64| {
            let mut g = [0.0; MAX_GUARDS];
            sys.guards(tt, &dense.eval(tt), &mut g);
            g[i]
        };
        // Earliest guard to cross to <= 0 within the step.
        let mut first: Option<(usize, f64, f64)> = None;
        for i in 0..ng {
            if g0[i] <= 0.0 {
                continue;
            }
            let bracket = if gm[i] <= 0.0 {
                Some((dense.t0(), tm, g0[i], gm[i]))
            } else if g1[i] <= 0.0 {
                Some((tm, t1, gm[i], g1[i]))
            } else {
                None
            };
            if let Some((a, b, ga, gb)) = bracket {
                let (lo, hi) = locate_crossing(|tt| guard_at(i, tt), a, b, ga, gb);
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
                let view = StepView { dense: cut };
                // The observer sees the step up to the event; a break here is moot.
                let _ = observer.on_step(sys, &view);
                return Ok(Stop::Event { index });
            }
            None => {
                *t = t1;
                *y = y1;
                g0 = g1;
                let view = StepView {
                    dense: stepper.last_dense(),
                };
                if observer.on_step(sys, &view).is_break() {
                    return Ok(Stop::Observer);
                }
            }
        }
    }
    Ok(Stop::EndTime)
}
