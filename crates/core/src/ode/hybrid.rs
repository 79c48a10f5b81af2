//! The event loop of a hybrid system: integrate until a guard crosses, take the jump the
//! system's own map gives for that guard, restart, and go on until the end time or until the
//! observer halts. Every caller with discrete modes runs this one loop.

use super::integrate::{integrate, NoObserver, Observer, Stop};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

/// A system with discrete modes: the mode it is in, and its jump map.
pub trait Hybrid<const N: usize>: OdeSystem<N> {
    /// The discrete mode (which right-hand side and which guards hold).
    type Mode: Copy;
    /// The current mode.
    fn mode(&self) -> Self::Mode;
    /// Switches to `mode`.
    fn set_mode(&mut self, mode: Self::Mode);
    /// The jump map: the mode entered when `guard` of the current mode crosses at state `y`.
    fn jump(&self, guard: Self::Guard, y: &[f64; N]) -> Self::Mode;
}

/// An observer of a hybrid run, which also sees every jump.
pub trait HybridObserver<S: Hybrid<N>, const N: usize>: Observer<S, N> {
    /// Called at each jump at `(t, y)`, before the system switches from mode `from` to `to`.
    fn on_jump(&mut self, _sys: &S, _t: f64, _y: &[f64; N], _from: S::Mode, _to: S::Mode) {}
}

impl<S: Hybrid<N>, const N: usize> HybridObserver<S, N> for NoObserver {}

/// How [`run_hybrid`] treats jumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JumpRules {
    /// Located events allowed over the stepper's life before [`SolveError::EventBudget`].
    pub max_events: u64,
    /// Largest first step after a jump (s): the error estimate is least reliable on the
    /// first step of a new mode whose right-hand side is not smooth where it starts.
    pub step_after_jump_s: f64,
}

/// Why [`run_hybrid`] returned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Finish<H> {
    /// The end time was reached.
    EndTime,
    /// The observer halted the run, for this reason.
    Halted(H),
}

/// Integrates the hybrid system `sys` from `(t, y)` towards `t_end` through every located
/// guard crossing: at each, the event budget is checked, the jump map gives the new mode, the
/// observer sees the jump, the system switches, and the next step is capped. Returns at the
/// end time or when the observer halts; `t`, `y`, the mode and the stepper's history are left
/// where the run stopped, so a caller can change the system and call again.
pub fn run_hybrid<S, O, M, const N: usize>(
    sys: &mut S,
    stepper: &mut M,
    t: &mut f64,
    y: &mut [f64; N],
    t_end: f64,
    observer: &mut O,
    rules: &JumpRules,
) -> Result<Finish<O::Halt>, SolveError>
where
    S: Hybrid<N>,
    O: HybridObserver<S, N>,
    M: Stepper<N>,
{
    loop {
        match integrate(&*sys, stepper, t, y, t_end, observer)? {
            Stop::EndTime => return Ok(Finish::EndTime),
            Stop::Halted(halt) => return Ok(Finish::Halted(halt)),
            Stop::Event { guard } => {
                if stepper.stats().events >= rules.max_events {
                    return Err(SolveError::EventBudget {
                        t_s: *t,
                        events: stepper.stats().events,
                    });
                }
                let from = sys.mode();
                let to = sys.jump(guard, y);
                observer.on_jump(sys, *t, y, from, to);
                sys.set_mode(to);
                stepper.cap_next_step(rules.step_after_jump_s);
            }
        }
    }
}
