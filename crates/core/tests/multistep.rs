//! The BDF and RODAS4 then BDF with the driver: the hand-over happens and carries most of a
//! smooth run, the two methods share one budget of step attempts, a step cut short only by
//! the end time is not an underflow, a state that is not finite fails at once, and a restart
//! announced as no mode switch keeps the history only where the last step ended.

use std::ops::ControlFlow;
use whirlmap_core::ode::{
    integrate, Bdf, Formula, NoObserver, Observer, Rodas4Bdf, StepControl, StepView, Stepper,
};
use whirlmap_core::SolveError;

mod common;
use common::{Harmonic, HARMONIC};

fn ctl(rtol: f64, max_attempts: u64) -> StepControl<2> {
    StepControl {
        rtol,
        atol: [rtol * 1e-3; 2],
        h_min: 1e-14,
        max_attempts,
        fixed_step: None,
    }
}

fn run<M: Stepper<2>>(st: &mut M, t_end: f64) -> Result<(f64, [f64; 2]), SolveError> {
    let (mut t, mut y) = (0.0, [1.0, 0.0]);
    integrate(&HARMONIC, st, &mut t, &mut y, t_end, &mut NoObserver)?;
    Ok((t, y))
}

#[test]
fn rodas4_then_bdf_hands_over_and_the_bdf_takes_most_of_a_smooth_run() {
    let mut st = Rodas4Bdf::new(ctl(1e-8, 1_000_000));
    let (t, y) = run(&mut st, 20.0).unwrap();
    let err = (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
    assert_eq!(st.handovers(), 1, "one run, one hand-over");
    let steps = st.stats().steps;
    assert!(2 * st.bdf_steps() > steps, "{} of {steps}", st.bdf_steps());
    assert!(err < 100.0 * 1e-8, "error {err:e}");
}

/// The highest multistep order of the accepted steps.
struct HighestOrder(usize);
impl<S: whirlmap_core::ode::OdeSystem<2>> Observer<S, 2> for HighestOrder {
    type Halt = std::convert::Infallible;
    fn on_step(&mut self, _sys: &S, s: &StepView<'_, 2>) -> ControlFlow<Self::Halt> {
        self.0 = self.0.max(s.dense.multistep_order().unwrap_or(0));
        ControlFlow::Continue(())
    }
}

#[test]
fn rodas4_then_bdf_hands_over_at_any_highest_order() {
    // Capped below the hand-over's order 3 the BDF is seeded at the cap. At every cap the
    // BDF takes over and reaches the cap but no higher, and on this undamped oscillator
    // (about three periods) a higher cap takes fewer steps at the same tolerance; the lower
    // orders' local errors add up over many more steps (implicit Euler's also damp it).
    let mut runs = Vec::new();
    for cap in 1..=5 {
        let mut st = Rodas4Bdf::new(ctl(1e-8, 1_000_000)).with_max_order(cap);
        let (mut t, mut y) = (0.0, [1.0, 0.0]);
        let mut highest = HighestOrder(0);
        integrate(&HARMONIC, &mut st, &mut t, &mut y, 20.0, &mut highest).unwrap();
        let err = (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs());
        assert_eq!(st.handovers(), 1, "cap {cap}");
        assert_eq!(highest.0, cap, "cap {cap}");
        runs.push((st.stats().steps, err));
    }
    for w in runs.windows(2) {
        assert!(w[1].0 < w[0].0, "{runs:?}");
    }
    for w in runs[..4].windows(2) {
        assert!(w[1].1 < w[0].1, "{runs:?}");
    }
    for (steps, err) in &runs[3..] {
        assert!(*err < 100.0 * 1e-8, "{steps} steps, error {err:e}");
    }
}

#[test]
fn both_methods_share_one_budget_of_step_attempts() {
    let mut whole = Rodas4Bdf::new(ctl(1e-8, 1_000_000));
    run(&mut whole, 20.0).unwrap();
    let needed = whole.stats().steps + whole.stats().rejected;
    // A budget below what the run needs, but above what either method alone takes.
    let budget = needed - 10;
    assert!(whole.bdf_steps() < budget && needed - whole.bdf_steps() < budget);
    let mut st = Rodas4Bdf::new(ctl(1e-8, budget));
    match run(&mut st, 20.0) {
        Err(SolveError::StepBudget { attempts, .. }) => assert_eq!(attempts, budget),
        other => panic!("{other:?}"),
    }
    let s = st.stats();
    assert_eq!(s.steps + s.rejected, budget);
}

#[test]
fn a_step_cut_short_only_by_the_end_time_is_not_an_underflow() {
    fn check<M: Stepper<2>>(name: &str, mut st: M) {
        let (mut t, mut y) = (0.0, [1.0, 0.0]);
        integrate(&HARMONIC, &mut st, &mut t, &mut y, 10.0, &mut NoObserver).unwrap();
        let end = t + 4e-15;
        integrate(&HARMONIC, &mut st, &mut t, &mut y, end, &mut NoObserver)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(t, end, "{name}");
        // And a run from there goes on normally.
        integrate(&HARMONIC, &mut st, &mut t, &mut y, 20.0, &mut NoObserver)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!((y[0] - 20f64.cos()).abs() < 1e-5, "{name}: {y:?}");
    }
    check("BDF", Bdf::new(ctl(1e-7, 1_000_000)));
    check("RODAS4 then BDF", Rodas4Bdf::new(ctl(1e-7, 1_000_000)));
    check(
        "RODAS4 then NDF",
        Rodas4Bdf::with_formula(ctl(1e-7, 1_000_000), Formula::Ndf),
    );
}

#[test]
fn a_state_that_is_not_finite_fails_at_once() {
    let mut st = Bdf::new(ctl(1e-6, 1_000_000));
    let (mut t, mut y) = (0.0, [f64::NAN, 0.0]);
    let e = integrate(&HARMONIC, &mut st, &mut t, &mut y, 1.0, &mut NoObserver).unwrap_err();
    assert!(matches!(e, SolveError::NonFiniteState { .. }), "{e:?}");
    let s = st.stats();
    assert!(s.steps + s.rejected < 100, "{s:?}");
}

/// Halts after the first step that reaches `at`, as the drop's thermal coupling halts at a
/// macro step's end: the run stops where a step ended, not at a cut step.
struct HaltAt(f64);
impl whirlmap_core::ode::Observer<Harmonic, 2> for HaltAt {
    type Halt = ();
    fn on_step(
        &mut self,
        _sys: &Harmonic,
        step: &whirlmap_core::ode::StepView<'_, 2>,
    ) -> std::ops::ControlFlow<()> {
        if step.dense.t1() >= self.0 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    }
}

#[test]
fn an_announced_restart_keeps_the_bdf_only_where_its_last_step_ended() {
    let go = |st: &mut Rodas4Bdf<2>, t: &mut f64, y: &mut [f64; 2], at: f64| {
        integrate(&HARMONIC, st, t, y, 100.0, &mut HaltAt(at)).unwrap();
    };
    // After a run long enough for the hand-over the BDF steps; an announced restart where a
    // step ended goes on with the BDF (no new hand-over), an unannounced one goes back to
    // RODAS4 (one more hand-over later).
    let (mut t, mut y) = (0.0, [1.0, 0.0]);
    let mut st = Rodas4Bdf::new(ctl(1e-8, 1_000_000));
    go(&mut st, &mut t, &mut y, 10.0);
    assert_eq!(st.handovers(), 1);
    let bdf_before = st.bdf_steps();
    st.keep_history_at_next_restart();
    go(&mut st, &mut t, &mut y, 12.0);
    assert_eq!(st.handovers(), 1, "the BDF went on");
    assert!(st.bdf_steps() > bdf_before);
    go(&mut st, &mut t, &mut y, 14.0);
    assert_eq!(
        st.handovers(),
        2,
        "RODAS4 again after an unannounced restart"
    );
    // Announced, but from another state (a jump moved it): RODAS4 again.
    st.keep_history_at_next_restart();
    y[0] += 1e-12;
    go(&mut st, &mut t, &mut y, 16.0);
    assert_eq!(st.handovers(), 3);
    // Announced during RODAS4's steps: the hand-over still comes once RODAS4 has taken its
    // steps, counted across the restarts.
    let (mut t, mut y) = (0.0, [1.0, 0.0]);
    let mut st = Rodas4Bdf::new(ctl(1e-8, 1_000_000));
    for k in 1..=40 {
        st.keep_history_at_next_restart();
        go(&mut st, &mut t, &mut y, k as f64 * 0.01);
    }
    assert_eq!(st.handovers(), 1, "{:?}", st.stats());
    // A run that ends at an end time with a step cut far short: the next restart starts
    // afresh from the step size proposed before the cut, announced or not.
    let (mut t, mut y) = (0.0, [1.0, 0.0]);
    let mut bdf = Bdf::new(ctl(1e-8, 1_000_000));
    integrate(&HARMONIC, &mut bdf, &mut t, &mut y, 10.0, &mut NoObserver).unwrap();
    let end = t + 1e-12;
    integrate(&HARMONIC, &mut bdf, &mut t, &mut y, end, &mut NoObserver).unwrap();
    bdf.keep_history_at_next_restart();
    bdf.restart(&HARMONIC, t, &y);
    assert_eq!(bdf.order(), 1, "not kept after a step cut to 1e-12 s");
}

#[test]
fn a_cap_after_a_jump_holds_though_the_last_step_was_cut_by_the_end_time() {
    // As the drop does after a mode switch: cap the next step, then restart. The last step
    // before it was shortened to the end time, so the step proposed before that cut is
    // larger than the cap; the cap wins.
    fn check<M: Stepper<2>>(name: &str, mut st: M) {
        let (mut t, mut y) = (0.0, [1.0, 0.0]);
        integrate(&HARMONIC, &mut st, &mut t, &mut y, 20.0, &mut NoObserver).unwrap();
        let cap = 1e-6;
        st.cap_next_step(cap);
        st.restart(&HARMONIC, t, &y);
        let dense = st.step(&HARMONIC, t, &y, f64::INFINITY).unwrap();
        // (t1 - t0 at t = 20 carries rounding of some 1e-15 s.)
        let h = dense.t1() - dense.t0();
        assert!(
            h <= cap * (1.0 + 1e-6),
            "{name}: first step {h:e} after a cap of {cap:e}"
        );
    }
    check("BDF", Bdf::new(ctl(1e-8, 1_000_000)));
    check("RODAS4 then BDF", Rodas4Bdf::new(ctl(1e-8, 1_000_000)));
}

#[test]
fn a_kept_history_needs_the_state_bit_for_bit() {
    // At rest at the origin the state stays (0, 0) exactly. (-0.0, 0.0) compares equal to
    // it but is another state's bits: an announced restart there starts afresh (with the
    // history kept, the next step, which checks its state bit for bit under debug
    // assertions, would refuse it).
    let (mut t, mut y) = (0.0, [0.0, 0.0]);
    let mut bdf = Bdf::new(ctl(1e-8, 1_000_000));
    integrate(&HARMONIC, &mut bdf, &mut t, &mut y, 1.0, &mut NoObserver).unwrap();
    assert_eq!(y, [0.0, 0.0]);
    let flipped = [-0.0, 0.0];
    bdf.keep_history_at_next_restart();
    bdf.restart(&HARMONIC, t, &flipped);
    bdf.step(&HARMONIC, t, &flipped, f64::INFINITY).unwrap();
    let mut st = Rodas4Bdf::new(ctl(1e-8, 1_000_000));
    let (mut t, mut y) = (0.0, [0.0, 0.0]);
    integrate(&HARMONIC, &mut st, &mut t, &mut y, 1.0, &mut NoObserver).unwrap();
    st.keep_history_at_next_restart();
    st.restart(&HARMONIC, t, &flipped);
    st.step(&HARMONIC, t, &flipped, f64::INFINITY).unwrap();
}
