//! The event loop of a hybrid system: integrate until a guard crosses, take the jump the
//! system's own map gives for that guard, restart, and go on until the end time or until the
//! observer halts. Every caller with discrete modes runs this one loop.

use super::integrate::{integrate, NoObserver, Observer, Stop};
use super::stepper::Stepper;
use super::system::{GuardSet, OdeSystem, MAX_GUARDS};
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
            Stop::Event {
                guard,
                crossed,
                violated_before,
            } => {
                if stepper.stats().events >= rules.max_events {
                    return Err(SolveError::EventBudget {
                        t_s: *t,
                        events: stepper.stats().events,
                    });
                }
                switch(sys, guard, *t, y, observer);
                take_follow_on_jumps(sys, *t, y, guard, &crossed, &violated_before, observer);
                stepper.cap_next_step(rules.step_after_jump_s);
            }
        }
    }
}

/// The jumps of the guards that crossed together with the located one, and of those the jump
/// itself sent below zero.
///
/// The driver watches a guard of a mode from zero or above (from exactly zero, it sees the
/// guard go below), so a guard that starts a mode below zero would never be seen, and the part
/// of the mode it ends would hold with its guard violated. Two ways lead there:
/// - **Guards that cross together.** When the friction of a sticking contact is exactly zero
///   (a drop without spin), its friction guard `mu_s F_n - |F_t|` and the contact guard `F_n`
///   vanish at once. The stick ended, the contact stayed closed and pulled the rotor with a
///   negative normal force.
/// - **A jump that moves another guard.** The isotropic support damper acts only while the
///   race is on its balls, so when the race lifts off, the race's acceleration, and with it the
///   friction that keeps a contact rolling (eq. 9), jumps. A stick that held its static limit
///   (eq. 10) before the lift-off can exceed it after; it kept sticking.
///
/// So after the located jump, in slot order and re-evaluated after every jump, a guard of the
/// new mode takes its own jump when it is at or below zero and crossed in the step
/// (`crossed`: a crossing, as the driver counts one), or when it is below zero otherwise.
/// Each guard jumps at most once this way, and once more only when its own jump left it at or
/// above zero and another guard's jump since sent it below: a located friction switch (slip to
/// stick, within the static limit) followed by the support's lift-off in the same step can
/// leave the new stick past its limit, and that stick then ends at once. The bound (two jumps
/// a guard) ends the loop whatever the jump map does. A guard that its own jump leaves below
/// zero gets no second jump: the jump map chose that mode. The drop's jumps enter a mode whose
/// own guard is at or above zero (the contact and support guards change sign; a friction
/// switch goes through `entering_slip` and `slip_along_drift`), but for one: a slip that ends
/// (`v_rel = 0`) where eq. 7's raw contact force is already below zero and no friction is
/// needed enters a stick whose guard `mu_s F_n` is below zero. The contact guard is below zero
/// there too, and its own follow-on jump opens the contact.
///
/// A guard exactly at zero that did not cross is a boundary the jump map itself decided: a
/// contact entered with no force yet (an undamped contact starts at `F_n = 0`) sticks with a
/// friction guard `mu_s F_n - |F_t|` of exactly 0 when no friction is needed; switching it to
/// a slip there would start a slip whose own guard is 0. The driver watches it from zero, and
/// it switches when it goes below. A guard the first
/// jump made irrelevant (the friction guard once the contact is open) has no slot in the new
/// mode. A guard that was already violated when the step began (`violated_before`: a
/// crossing stepped over earlier, which the model's own checks report) is left as it was.
fn take_follow_on_jumps<S, O, const N: usize>(
    sys: &mut S,
    t: f64,
    y: &[f64; N],
    located: S::Guard,
    crossed: &[bool; MAX_GUARDS],
    violated_before: &[bool; MAX_GUARDS],
    observer: &mut O,
) where
    S: Hybrid<N>,
    O: HybridObserver<S, N>,
{
    let all = S::Guard::ALL;
    // Jumps taken per slot (a violated guard counts as done), and whether the guard was at or
    // above zero right after its own jump (`None` until that is known).
    let mut jumps = [0u8; MAX_GUARDS];
    for (n, &v) in jumps.iter_mut().zip(violated_before) {
        if v {
            *n = 2;
        }
    }
    let mut settled = [None; MAX_GUARDS];
    let mut just = all.iter().position(|g| *g == located);
    if let Some(i) = just {
        jumps[i] = 1;
    }
    loop {
        let mut g = [0.0; MAX_GUARDS];
        let ng = sys.guards(t, y, &mut g);
        if let Some(i) = just.filter(|&i| i < ng) {
            settled[i] = Some(g[i] >= 0.0);
        }
        // A second jump only for a guard that its own jump left at or above zero and that
        // another jump since sent below it.
        let due = |j: usize| match jumps[j] {
            0 => g[j] < 0.0 || (crossed[j] && g[j] <= 0.0),
            1 => g[j] < 0.0 && settled[j] == Some(true),
            _ => false,
        };
        let Some(j) = (0..ng).find(|&j| due(j)) else {
            return;
        };
        jumps[j] += 1;
        just = Some(j);
        switch(sys, all[j], t, y, observer);
    }
}

/// One jump: the mode the jump map gives for `guard` at `(t, y)`, shown to the observer, then
/// taken.
fn switch<S, O, const N: usize>(
    sys: &mut S,
    guard: S::Guard,
    t: f64,
    y: &[f64; N],
    observer: &mut O,
) where
    S: Hybrid<N>,
    O: HybridObserver<S, N>,
{
    let from = sys.mode();
    let to = sys.jump(guard, y);
    observer.on_jump(sys, t, y, from, to);
    sys.set_mode(to);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::{Dopri5, StepControl};

    /// Two latches over a falling coordinate `y' = -1` from `y = 1`. Latch A opens when its
    /// guard `y - a_at` reaches zero; latch B's guard is `y - b_at`, or `b_after_a` once A is
    /// open if that is given (a switch that moves another guard). An open A's guard is
    /// `a_open`, or `a_after_b` once B is open too if that is given; A's jump toggles it (a
    /// friction guard that ends a stick it began).
    struct Latches {
        a_at: f64,
        b_at: f64,
        b_after_a: Option<f64>,
        a_open: f64,
        a_after_b: Option<f64>,
        mode: (bool, bool),
    }

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Latch {
        A,
        B,
    }

    impl GuardSet for Latch {
        const ALL: &'static [Self] = &[Latch::A, Latch::B];
    }

    impl OdeSystem<1> for Latches {
        type Guard = Latch;
        fn rhs(&self, _t: f64, _y: &[f64; 1], dy: &mut [f64; 1]) {
            dy[0] = -1.0;
        }
        fn guards(&self, _t: f64, y: &[f64; 1], g: &mut [f64; MAX_GUARDS]) -> usize {
            let (a, b) = self.mode;
            g[0] = match (a, b, self.a_after_b) {
                (true, _, _) => y[0] - self.a_at,
                (false, false, Some(after)) => after,
                (false, _, _) => self.a_open,
            };
            g[1] = match (b, a, self.b_after_a) {
                (false, _, _) => 1.0,
                (true, false, Some(after)) => after,
                (true, _, _) => y[0] - self.b_at,
            };
            2
        }
        fn max_step(&self) -> f64 {
            0.05
        }
    }

    impl Hybrid<1> for Latches {
        type Mode = (bool, bool);
        fn mode(&self) -> (bool, bool) {
            self.mode
        }
        fn set_mode(&mut self, mode: (bool, bool)) {
            self.mode = mode;
        }
        fn jump(&self, guard: Latch, _y: &[f64; 1]) -> (bool, bool) {
            match guard {
                Latch::A => (!self.mode.0, self.mode.1),
                Latch::B => (self.mode.0, false),
            }
        }
    }

    /// The toy systems' step control: rtol 1e-9, adaptive.
    fn toy_stepper_control() -> StepControl<1> {
        StepControl {
            rtol: 1e-9,
            atol: [1e-12],
            h_min: 1e-14,
            max_attempts: 10_000,
            fixed_step: None,
        }
    }

    /// The toy systems' stepper: DOPRI5 on [`toy_stepper_control`].
    fn toy_stepper() -> Dopri5<1> {
        Dopri5::new(toy_stepper_control())
    }

    /// The toy systems' jump rules.
    const TOY_RULES: JumpRules = JumpRules {
        max_events: 10,
        step_after_jump_s: 1e-3,
    };

    /// The mode at t = 1 (y = 0) after starting with both latches closed.
    fn run(a_at: f64, b_at: f64, b_after_a: Option<f64>) -> (bool, bool) {
        run_toggling(a_at, b_at, b_after_a, 1.0, None)
    }

    /// A jump's modes, from and to.
    type Jump = ((bool, bool), (bool, bool));

    /// Records every jump's modes.
    #[derive(Default)]
    struct Jumps(Vec<Jump>);

    impl Observer<Latches, 1> for Jumps {
        type Halt = std::convert::Infallible;
    }

    impl HybridObserver<Latches, 1> for Jumps {
        fn on_jump(
            &mut self,
            _: &Latches,
            _: f64,
            _: &[f64; 1],
            from: (bool, bool),
            to: (bool, bool),
        ) {
            self.0.push((from, to));
        }
    }

    /// [`run`] with an open A's guard, alone and once B is open too.
    fn run_toggling(
        a_at: f64,
        b_at: f64,
        b_after_a: Option<f64>,
        a_open: f64,
        a_after_b: Option<f64>,
    ) -> (bool, bool) {
        run_recorded(a_at, b_at, b_after_a, a_open, a_after_b).0
    }

    /// [`run_toggling`], with the modes every jump went from and to.
    fn run_recorded(
        a_at: f64,
        b_at: f64,
        b_after_a: Option<f64>,
        a_open: f64,
        a_after_b: Option<f64>,
    ) -> ((bool, bool), Vec<Jump>) {
        let mut sys = Latches {
            a_at,
            b_at,
            b_after_a,
            a_open,
            a_after_b,
            mode: (true, true),
        };
        let mut stepper = toy_stepper();
        let (mut t, mut y) = (0.0, [1.0]);
        let mut jumps = Jumps::default();
        run_hybrid(
            &mut sys,
            &mut stepper,
            &mut t,
            &mut y,
            1.0,
            &mut jumps,
            &TOY_RULES,
        )
        .unwrap();
        (sys.mode, jumps.0)
    }

    #[test]
    fn guards_that_cross_together_both_switch() {
        // Both guards are y - 0.5: one crossing is located, the other must switch with it.
        assert_eq!(run(0.5, 0.5, None), (false, false));
        // Apart, each switches at its own crossing (and B stays closed if it never crosses).
        assert_eq!(run(0.5, 0.25, None), (false, false));
        assert_eq!(run(0.5, -1.0, None), (false, true));
    }

    #[test]
    fn a_switch_that_sends_another_guard_negative_switches_it_too() {
        // Opening A sends B's guard to -1 (B's own crossing at y = -1 is never reached).
        assert_eq!(run(0.5, -1.0, Some(-1.0)), (false, false));
        // Sent exactly to zero without crossing: a boundary the jump decided, left alone.
        assert_eq!(run(0.5, -1.0, Some(0.0)), (false, true));
    }

    #[test]
    fn a_located_guard_that_a_follow_on_jump_sends_negative_jumps_again() {
        // A's crossing is located and B crosses with it; B's jump sends the open A's guard to
        // -1, so A jumps back (closed). Its guard is then y - 0.5, at zero: it has jumped
        // twice at this event, and the driver watches it from zero, so it opens again at the
        // next step, as y falls below 0.5.
        let (open, closed) = (false, true);
        let (end, jumps) = run_recorded(0.5, 0.5, None, 1.0, Some(-1.0));
        assert_eq!(
            jumps,
            [
                ((closed, closed), (open, closed)),
                ((open, closed), (open, open)),
                ((open, open), (closed, open)),
                ((closed, open), (open, open)),
            ]
        );
        assert_eq!(end, (open, open));
        // Sent exactly to zero: left alone, as for a first jump.
        assert_eq!(run_toggling(0.5, 0.5, None, 1.0, Some(0.0)), (false, false));
    }

    #[test]
    fn a_guard_its_own_jump_left_below_zero_does_not_jump_again() {
        // A's own jump leaves its guard at -1 (the jump map chose that mode); B's jump at the
        // same event keeps it there. B's jump did not send it below zero: no second jump.
        assert_eq!(
            run_toggling(0.5, 0.5, None, -1.0, Some(-1.0)),
            (false, false)
        );
    }

    #[test]
    fn a_guard_that_starts_at_zero_is_watched_from_there() {
        // A's guard y - 1 is exactly zero at the start and falls below at once: A opens
        // there. (Before, a guard was watched only once positive, and this one never was: a
        // grazing contact whose guard reached exactly zero and closed again went unseen, and
        // the rotor passed through the race.) One that stays at zero stays put (B's guard sent
        // to 0 in `a_switch_that_sends_another_guard_negative_switches_it_too`).
        let (end, jumps) = run_recorded(1.0, -1.0, None, 1.0, None);
        assert_eq!(end, (false, true));
        assert_eq!(jumps, [((true, true), (false, true))]);
    }

    #[test]
    fn guards_that_start_at_zero_and_fall_together_both_switch() {
        // Both guards are y - 1, at zero at the start: A's fall is located, and B, at zero
        // when the step began and below zero at A's event, takes its own switch with it.
        assert_eq!(run(1.0, 1.0, None), (false, false));
    }

    /// One guard, flat at exactly zero until `y = 0.63` and below zero after it, over
    /// `y' = 1` from 0 in fixed steps of 0.05: zero at the starts of thirteen steps and at the
    /// midpoint (0.625) of the step that leaves it, [0.60, 0.65], where the crossing is in the
    /// step's second half.
    struct Flat {
        open: bool,
    }

    #[derive(Debug, Clone, Copy, PartialEq)]
    enum Edge {
        Leave,
    }

    impl GuardSet for Edge {
        const ALL: &'static [Self] = &[Edge::Leave];
    }

    impl OdeSystem<1> for Flat {
        type Guard = Edge;
        fn rhs(&self, _t: f64, _y: &[f64; 1], dy: &mut [f64; 1]) {
            dy[0] = 1.0;
        }
        fn guards(&self, _t: f64, y: &[f64; 1], g: &mut [f64; MAX_GUARDS]) -> usize {
            g[0] = match (self.open, y[0] < 0.63) {
                (true, _) => 1.0,
                (false, true) => 0.0,
                (false, false) => 0.63 - y[0],
            };
            1
        }
        fn max_step(&self) -> f64 {
            0.05
        }
    }

    impl Hybrid<1> for Flat {
        type Mode = bool;
        fn mode(&self) -> bool {
            self.open
        }
        fn set_mode(&mut self, open: bool) {
            self.open = open;
        }
        fn jump(&self, _: Edge, _: &[f64; 1]) -> bool {
            true
        }
    }

    /// Records the times of the jumps.
    #[derive(Default)]
    struct Times(Vec<f64>);

    impl Observer<Flat, 1> for Times {
        type Halt = std::convert::Infallible;
    }

    impl HybridObserver<Flat, 1> for Times {
        fn on_jump(&mut self, _: &Flat, t: f64, _: &[f64; 1], _: bool, _: bool) {
            self.0.push(t);
        }
    }

    #[test]
    fn a_guard_flat_at_zero_is_located_where_it_leaves_zero() {
        let mut sys = Flat { open: false };
        let mut stepper = Dopri5::new(StepControl {
            fixed_step: Some(0.05),
            ..toy_stepper_control()
        });
        let (mut t, mut y) = (0.0, [0.0]);
        let mut times = Times::default();
        run_hybrid(
            &mut sys,
            &mut stepper,
            &mut t,
            &mut y,
            1.0,
            &mut times,
            &TOY_RULES,
        )
        .unwrap();
        assert_eq!(times.0.len(), 1, "{:?}", times.0);
        assert!((times.0[0] - 0.63).abs() < 1e-12, "{:?}", times.0);
        assert!(sys.open);
    }

    #[test]
    fn a_guard_violated_when_the_step_began_is_left_alone() {
        // B's guard is negative from the start (y - 2): a crossing stepped over before the
        // run, which A's switch does not answer.
        assert_eq!(run(0.5, 2.0, Some(-1.0)), (false, true));
    }
}
