//! RODAS4 then BDF: a one-step method where the motion has just changed, a multistep method
//! where it runs smoothly.
//!
//! After every restart (in a drop: every mode switch, an impact, a lift-off, a stick or a
//! slip) the steps are RODAS4's ([`super::Rodas4`]), which starts at full order from the
//! switch and takes the impacts, whose peak forces are the budget's hardest outputs. Once
//! RODAS4 has taken [`HANDOVER_STEPS`] steps and [`HANDOVER_S`] of time since the restart,
//! and the system sets no step bound (in a drop: the contact carries, so no free-flight
//! bound), the BDF ([`super::Bdf`]) takes over until the next restart. It starts at order
//! [`SEED_ORDER`] (or its highest order, if lower) and RODAS4's step size from RODAS4's last
//! steps, read at equal spacing from their cubic Hermite interpolants (RODAS4's own dense
//! output).
//!
//! Why: rolling or whirling in the race, a BDF step costs one or two model evaluations, one
//! Jacobian, one factorisation and one or two solves, against RODAS4's six, one, one and six;
//! at a tenth of the tolerance ([`BDF_TOLERANCE`]) it takes about as many steps as RODAS4
//! and is as close to `reference`. Started after each switch at order 1, the BDF alone missed
//! the accuracy budget at rtol 3e-5 by up to fourteen times on the impacts of a bouncing
//! sequence (docs/accuracy.md#model-version-12-rodas4-then-bdf).

use super::bdf::{same_bits, Bdf, Formula, MAX_ORDER};
use super::control::StepCore;
use super::rodas::Rodas4;
use super::step::{Dense, Stats, StepControl};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

/// RODAS4 steps since a restart before the BDF may take over.
pub const HANDOVER_STEPS: usize = 12;
/// Time since a restart before the BDF may take over (s): longer than a touchdown impact
/// (about 1.6 ms at the paper's contact), so that RODAS4 takes every impact whole.
pub const HANDOVER_S: f64 = 2e-3;
/// The BDF's tolerances, as a fraction of the stepper's. A system's widened tolerances
/// ([`OdeSystem::loosened_atol`]) stay what the system makes them: in a drop the race's
/// velocity in contact, `rtol F_n / max(c1, c2)` from the scene's rtol. RODAS4's error
/// estimate is the distance to its embedded third-order solution, so its fourth-order
/// solution is well within the tolerance; the BDF's estimate is its own solution's error. At
/// a tenth of the tolerance the BDF's steps are as accurate as RODAS4's: on the main job's
/// grid the worst maximum contact force of a whirl (stepped by the BDF) is 4.7e-4 from
/// `reference` against RODAS4's 5.0e-4; at the same tolerance it was 2.1e-3, outside the
/// budget, and at a third 8.2e-4 (docs/performance.md#rodas4-then-bdf-model-version-12).
pub const BDF_TOLERANCE: f64 = 0.1;
/// The BDF's order when it takes over.
const SEED_ORDER: usize = 3;
/// RODAS4 step ends kept for the hand-over (more than [`SEED_ORDER`] steps' worth).
const HISTORY: usize = 8;

/// Which method takes the next step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Rodas,
    Bdf,
}

/// RODAS4 after each restart, the BDF (or the NDF) in long smooth stretches (see the module
/// doc).
#[derive(Debug, Clone)]
pub struct Rodas4Bdf<const N: usize> {
    rodas: Rodas4<N>,
    bdf: Bdf<N>,
    phase: Phase,
    /// RODAS4's accepted step ends since the last restart, `(t, y, f)`, oldest first, at most
    /// [`HISTORY`].
    history: Vec<(f64, [f64; N], [f64; N])>,
    /// RODAS4 steps since the last restart.
    since_restart: usize,
    /// Time of the last restart (s).
    t_restart: f64,
    /// Hand-overs to the BDF (or NDF) so far.
    handovers: u64,
    /// Whether the next restart keeps the history
    /// ([`Stepper::keep_history_at_next_restart`]).
    keep_history: bool,
    /// Step attempts of both methods together before a budget error.
    budget: u64,
}

impl<const N: usize> Rodas4Bdf<N> {
    /// A stepper with the given control settings and no step-size history, whose multistep
    /// method is the BDF.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self::with_formula(ctl, Formula::Bdf)
    }

    /// As [`Rodas4Bdf::new`], with the multistep method's formulas given: the BDF or the NDF
    /// ([`Formula`]; `solver.method = "rodas4_ndf"` in a scene).
    pub fn with_formula(ctl: StepControl<N>, formula: Formula) -> Self {
        const { assert!(SEED_ORDER <= MAX_ORDER && SEED_ORDER < HISTORY) };
        Self {
            rodas: Rodas4::new(ctl),
            bdf: Bdf::with_formula(
                StepControl {
                    rtol: ctl.rtol * BDF_TOLERANCE,
                    atol: ctl.atol.map(|a| a * BDF_TOLERANCE),
                    ..ctl
                },
                formula,
            ),
            phase: Phase::Rodas,
            history: Vec::with_capacity(HISTORY),
            since_restart: 0,
            t_restart: 0.0,
            handovers: 0,
            keep_history: false,
            budget: ctl.max_attempts,
        }
    }

    /// The same stepper with the BDF's (or NDF's) order capped at `max_order`
    /// ([`Bdf::with_max_order`]); it then takes over at order 3 or `max_order`, the lower.
    pub fn with_max_order(mut self, max_order: usize) -> Self {
        self.bdf = self.bdf.with_max_order(max_order);
        self
    }

    /// Hand-overs to the BDF (or NDF) so far.
    pub fn handovers(&self) -> u64 {
        self.handovers
    }

    /// Accepted steps the BDF (or NDF) took so far (the rest of [`Stepper::stats`]' steps are
    /// RODAS4's).
    pub fn bdf_steps(&self) -> u64 {
        self.bdf.stats().steps
    }

    /// The solution at `t` from the kept step ends: the cubic Hermite interpolant of the step
    /// holding `t` (the first step for a `t` rounded below the first end).
    fn hermite_at(&self, t: f64) -> [f64; N] {
        let k = self
            .history
            .windows(2)
            .position(|w| t <= w[1].0)
            .unwrap_or(self.history.len() - 2);
        let (t0, y0, f0) = &self.history[k];
        let (t1, y1, f1) = &self.history[k + 1];
        let h = t1 - t0;
        let s = (t - t0) / h;
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s),
            s * (1.0 - s) * (1.0 - s),
            s * s * (3.0 - 2.0 * s),
            s * s * (s - 1.0),
        );
        std::array::from_fn(|i| h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i])
    }

    /// `e`, with a step budget's attempts counted over both methods.
    fn counting_both(&self, e: SolveError) -> SolveError {
        match e {
            SolveError::StepBudget { t_s, .. } => {
                let s = self.stats();
                SolveError::StepBudget {
                    t_s,
                    attempts: s.steps + s.rejected,
                }
            }
            e => e,
        }
    }

    /// Hands over to the BDF if RODAS4 has run long enough since the restart, before a step
    /// (so that the step the driver saw last stays RODAS4's, with its interpolant).
    fn maybe_hand_over<S: OdeSystem<N>>(&mut self, sys: &S) {
        let Some(&(t, y, _)) = self.history.last() else {
            return;
        };
        if self.since_restart < HANDOVER_STEPS
            || t - self.t_restart < HANDOVER_S
            || sys.max_step().is_finite()
        {
            return;
        }
        // `order + 1` values (order SEED_ORDER, or the BDF's highest if lower) at RODAS4's
        // next step size, or closer where the kept steps span less.
        let order = SEED_ORDER.min(self.bdf.max_order());
        let span = t - self.history[0].0;
        let h = self.rodas.core().h.min(span / order as f64);
        let mut values = [[0.0; N]; SEED_ORDER + 1];
        values[0] = y;
        for (j, v) in values.iter_mut().enumerate().take(order + 1).skip(1) {
            *v = self.hermite_at(t - j as f64 * h);
        }
        self.bdf.seed(&values[..=order], h);
        self.phase = Phase::Bdf;
        self.handovers += 1;
    }
}

impl<const N: usize> Stepper<N> for Rodas4Bdf<N> {
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        if std::mem::take(&mut self.keep_history) {
            match self.phase {
                // The BDF goes on with its differences.
                Phase::Bdf if self.bdf.continues_at(t, y) => return,
                // RODAS4 takes the derivative anew and keeps its count towards the hand-over.
                Phase::Rodas
                    if self
                        .history
                        .last()
                        .is_some_and(|h| h.0 == t && same_bits(&h.1, y)) =>
                {
                    self.rodas.restart(sys, t, y);
                    self.history.last_mut().expect("checked").2 = self.rodas.f0;
                    return;
                }
                _ => {}
            }
        }
        if self.phase == Phase::Bdf {
            // RODAS4 goes on from the BDF's step size.
            self.rodas.core_mut().h = self.bdf.next_step_size();
        }
        self.phase = Phase::Rodas;
        self.rodas.restart(sys, t, y);
        self.history.clear();
        self.history.push((t, *y, self.rodas.f0));
        self.since_restart = 0;
        self.t_restart = t;
    }

    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        if self.phase == Phase::Rodas {
            self.maybe_hand_over(sys);
        }
        // One budget of step attempts for both methods together: each may use what the other
        // left, and a budget error counts them all.
        let (a, b) = (self.rodas.stats(), self.bdf.stats());
        let used = [a.steps + a.rejected, b.steps + b.rejected];
        if self.phase == Phase::Bdf {
            self.bdf.core.ctl.max_attempts = self.budget.saturating_sub(used[0]);
            if let Err(e) = self.bdf.step(sys, t, y, h_cap) {
                return Err(self.counting_both(e));
            }
            return Ok(&self.bdf.core.dense);
        }
        self.rodas.core_mut().ctl.max_attempts = self.budget.saturating_sub(used[1]);
        if let Err(e) = self.rodas.step(sys, t, y, h_cap) {
            return Err(self.counting_both(e));
        }
        let d = self.rodas.last_dense();
        let end = (d.t1(), d.y1());
        if self.history.len() == HISTORY {
            self.history.remove(0);
        }
        self.history.push((end.0, end.1, self.rodas.f0));
        self.since_restart += 1;
        Ok(self.rodas.last_dense())
    }

    fn core(&self) -> &StepCore<N> {
        match self.phase {
            Phase::Rodas => self.rodas.core(),
            Phase::Bdf => &self.bdf.core,
        }
    }
    fn core_mut(&mut self) -> &mut StepCore<N> {
        match self.phase {
            Phase::Rodas => self.rodas.core_mut(),
            Phase::Bdf => &mut self.bdf.core,
        }
    }
    /// Caps the next step of the method in use: the BDF re-spaces its differences and caps
    /// the step size a restart hands to RODAS4 as well.
    fn cap_next_step(&mut self, h_s: f64) {
        match self.phase {
            Phase::Rodas => self.rodas.cap_next_step(h_s),
            Phase::Bdf => self.bdf.cap_next_step(h_s),
        }
    }

    fn keep_history_at_next_restart(&mut self) {
        self.keep_history = true;
    }
    /// Both methods' counters together.
    fn stats(&self) -> Stats {
        let (a, b) = (self.rodas.stats(), self.bdf.stats());
        Stats {
            rhs_evals: a.rhs_evals + b.rhs_evals,
            steps: a.steps + b.steps,
            rejected: a.rejected + b.rejected,
            events: a.events + b.events,
            jacobians: a.jacobians + b.jacobians,
            factorizations: a.factorizations + b.factorizations,
        }
    }
}
