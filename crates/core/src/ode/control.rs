//! What the three adaptive steppers share: the step-size history, the work counters, the last
//! interpolant, and the accept/reject loop with its step-size law. Each stepper supplies only
//! its trial step (stages, error norm) and builds its interpolant.

use super::step::{initial_step, Dense, Stats, StepControl};
use super::system::OdeSystem;
use crate::error::SolveError;

/// A step-size law (Hairer-Wanner I, II.4 and IV.8): after an attempt with error norm `err`,
/// the next step is `h / clamp(err^expo / err_old^beta / safe, 1/fac_max, 1/fac_min)`, where
/// `err_old` is the previous accepted step's norm (a PI controller when `beta > 0`); after a
/// rejection the step only shrinks, by at most `fac_min`.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepLaw {
    /// Safety factor.
    pub safe: f64,
    /// Exponent on the error norm (about 1 / (order of the estimate + 1), minus the PI part).
    pub expo: f64,
    /// Exponent on the previous accepted norm (0: no PI term).
    pub beta: f64,
    /// Largest shrink of one attempt (h_new >= fac_min h).
    pub fac_min: f64,
    /// Largest growth of one accepted step (h_new <= fac_max h).
    pub fac_max: f64,
    /// Gustafsson's predictive controller (Hairer-Wanner II, IV.8, as RADAU5 has it): from
    /// the second accepted step since a restart, the next step is also at most `h / gus`,
    /// with `gus = h_acc / h * (err^2 / err_acc)^expo / safe` clamped as the law's factor is,
    /// where `h_acc` and `err_acc` are the previous accepted step and its norm (floored at
    /// 1e-2). It shortens the step where the error grows from step to step, before a
    /// rejection does.
    pub predictive: bool,
}

/// The state every adaptive stepper keeps besides its stages (see
/// [`super::stepper::Stepper::core`]).
#[derive(Debug, Clone)]
pub struct StepCore<const N: usize> {
    /// Tolerances, limits and the optional fixed step.
    pub(super) ctl: StepControl<N>,
    /// Work counters, accumulated over every call.
    pub(super) stats: Stats,
    /// The next step to try (s); 0 before the first restart.
    pub(super) h: f64,
    /// The previous accepted error norm (PI memory; floored at 1e-4).
    pub(super) err_old: f64,
    /// The previous accepted step (s) since the last restart, 0 if none: the predictive
    /// controller's memory ([`StepLaw::predictive`]).
    pub(super) h_acc: f64,
    /// The previous accepted error norm, floored at 1e-2 (the predictive controller's).
    pub(super) err_acc: f64,
    /// The interpolant of the last accepted step.
    pub(super) dense: Dense<N>,
    /// The absolute tolerances of the current step ([`StepCore::begin_step`]).
    pub(super) step_atol: [f64; N],
}

impl<const N: usize> StepCore<N> {
    /// A core with no step-size history whose interpolant uses `terms` coefficient vectors.
    pub(super) fn new(ctl: StepControl<N>, terms: usize) -> Self {
        Self {
            ctl,
            stats: Stats::default(),
            h: 0.0,
            err_old: 1e-4,
            h_acc: 0.0,
            err_acc: 1e-2,
            step_atol: ctl.atol,
            dense: Dense {
                t0: 0.0,
                h: 1.0,
                t_end: 0.0,
                terms,
                r: [[0.0; N]; 8],
                y1: [0.0; N],
                y0: [0.0; N],
            },
        }
    }

    /// After a restart's derivative `dy` at `y`: the fixed step, or on the first call an
    /// initial step (Hairer's `hinit`, capped by the system's largest step).
    pub(super) fn restart<S: OdeSystem<N>>(&mut self, sys: &S, y: &[f64; N], dy: &[f64; N]) {
        self.stats.rhs_evals += 1;
        self.h_acc = 0.0;
        if let Some(hf) = self.ctl.fixed_step {
            self.h = hf;
        } else if self.h == 0.0 {
            self.h = initial_step(&self.ctl, y, dy, sys.max_step());
        }
    }

    /// Caps the next step at `h_s` (the controller grows it again from there). Used after a
    /// mode switch: a contact law like `delta^(10/9)` is not smooth where the new mode starts,
    /// so the embedded error estimate is least reliable on the first step after it.
    pub(super) fn cap_next_step(&mut self, h_s: f64) {
        if self.ctl.fixed_step.is_none() {
            self.h = self.h.min(h_s);
        }
    }

    /// Sets the absolute tolerances of the step from `(t, y)`, which every attempt of it
    /// uses: the system's widened ones ([`OdeSystem::loosened_atol`]) or the stepper's own.
    /// Asked once per step, before its attempts, while the state's model evaluation is
    /// still at hand.
    #[inline]
    pub(super) fn begin_step<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        self.step_atol = sys
            .loosened_atol(t, y, &self.ctl.atol)
            .unwrap_or(self.ctl.atol);
    }

    /// Records the accepted step from `(t, y)` to `(t + h, y1)` with derivatives `f_start` and
    /// `f1` at its ends: its interpolant, the cubic Hermite one of the ends (as the implicit
    /// steppers without their own give it), and one more step counted.
    pub(super) fn hermite_end(
        &mut self,
        t: f64,
        h: f64,
        y: &[f64; N],
        y1: [f64; N],
        f_start: &[f64; N],
        f1: &[f64; N],
    ) -> &Dense<N> {
        let d = &mut self.dense;
        let r = &mut d.r;
        for i in 0..N {
            let ydiff = y1[i] - y[i];
            let bspl = h * f_start[i] - ydiff;
            r[0][i] = y[i];
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - h * f1[i] - bspl;
        }
        (d.t0, d.h, d.t_end, d.terms, d.y1) = (t, h, t + h, 5, y1);
        self.stats.steps += 1;
        &self.dense
    }

    /// Cuts the last accepted step at `t_cut` and returns its interpolant.
    pub(super) fn cut_last_step(&mut self, t_cut: f64) -> &Dense<N> {
        self.dense.t_end = t_cut;
        &self.dense
    }

    /// Tries steps of at most `h_cap` from time `t` until one is accepted, and returns its
    /// trial and size; the next step size is then already set. `attempt(core, h)` returns a
    /// trial and its error norm (NaN when the step could not be formed). Errors: the attempt
    /// budget, a step below `h_min`, and a non-finite norm at the smallest or a fixed step.
    pub(super) fn control<T>(
        &mut self,
        law: &StepLaw,
        t: f64,
        h_cap: f64,
        mut attempt: impl FnMut(&mut Self, f64) -> (T, f64),
    ) -> Result<(T, f64), SolveError> {
        let mut rejected_last = false;
        // The step the history proposes, before any cap.
        let proposal = self.h;
        loop {
            if self.stats.steps + self.stats.rejected >= self.ctl.max_attempts {
                return Err(SolveError::StepBudget {
                    t_s: t,
                    attempts: self.stats.steps + self.stats.rejected,
                });
            }
            let h = self.h.min(h_cap);
            if h < self.ctl.h_min && h < h_cap {
                return Err(SolveError::StepSizeUnderflow { t_s: t, h_s: h });
            }
            let (trial, err) = attempt(self, h);
            let fixed = self.ctl.fixed_step.is_some();
            if !err.is_finite() && (fixed || h <= self.ctl.h_min) {
                return Err(SolveError::NonFiniteState { t_s: t });
            }
            if fixed || (err.is_finite() && err <= 1.0) {
                if !fixed {
                    // err_old^0 is 1 exactly: the call is skipped without the PI term.
                    let pi = if law.beta == 0.0 {
                        1.0
                    } else {
                        self.err_old.powf(law.beta)
                    };
                    let mut fac = (err.max(1e-10).powf(law.expo) / pi / law.safe)
                        .clamp(1.0 / law.fac_max, 1.0 / law.fac_min);
                    if law.predictive {
                        if self.h_acc > 0.0 {
                            let e2 = err.max(1e-10).powi(2) / self.err_acc;
                            let gus = (self.h_acc / h * e2.powf(law.expo) / law.safe)
                                .clamp(1.0 / law.fac_max, 1.0 / law.fac_min);
                            fac = fac.max(gus);
                        }
                        self.h_acc = h;
                        self.err_acc = err.max(1e-2);
                    }
                    let mut h_new = h / fac;
                    if rejected_last {
                        h_new = h_new.min(h);
                    } else if h < proposal {
                        // A step shortened by the cap (to meet an end time or the system's
                        // largest step) says nothing against the proposal; without this, a
                        // last step cut to a few femtoseconds by rounding would leave the
                        // next call starting below `h_min` (a step-size underflow).
                        h_new = h_new.max(proposal);
                    }
                    self.err_old = err.max(1e-4);
                    self.h = h_new;
                }
                return Ok((trial, h));
            }
            self.stats.rejected += 1;
            rejected_last = true;
            self.h = if err.is_finite() {
                h / (err.powf(law.expo) / law.safe).min(1.0 / law.fac_min)
            } else {
                h * law.fac_min
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAW: StepLaw = StepLaw {
        safe: 0.9,
        expo: 0.25,
        beta: 0.0,
        fac_min: 0.2,
        fac_max: 6.0,
        predictive: false,
    };

    fn core(max_attempts: u64, fixed_step: Option<f64>) -> StepCore<1> {
        let mut c = StepCore::new(
            StepControl {
                rtol: 1e-6,
                atol: [1e-9],
                h_min: 1e-12,
                max_attempts,
                fixed_step,
            },
            5,
        );
        c.h = 1e-3;
        c
    }

    #[test]
    fn accepted_steps_follow_the_law_and_rejections_only_shrink() {
        let mut c = core(100, None);
        // err = 1/16: growth 16^(1/4) * 0.9 = 1.8.
        let (_, h) = c.control(&LAW, 0.0, 1.0, |_, _| ((), 1.0 / 16.0)).unwrap();
        assert_eq!(h, 1e-3);
        assert!((c.h / 1e-3 - 1.8).abs() < 1e-12);
        // Tiny errors are capped at fac_max.
        let h0 = c.h;
        c.control(&LAW, 0.0, 1.0, |_, _| ((), 0.0)).unwrap();
        assert!((c.h / h0 - 6.0).abs() < 1e-12);
        // Two rejections (err 16: shrink to 0.45 h each), then an acceptance with a small
        // error may not grow beyond the step just taken.
        let mut errs = [16.0, 16.0, 1e-6].into_iter();
        let h0 = c.h;
        let (_, h) = c
            .control(&LAW, 0.0, 1.0, |_, _| ((), errs.next().unwrap()))
            .unwrap();
        assert!((h / h0 - 0.45 * 0.45).abs() < 1e-12);
        assert_eq!(c.h, h);
        assert_eq!(c.stats.rejected, 2);
        // A huge error shrinks by at most fac_min; a non-finite one by exactly fac_min.
        let mut errs = [1e30, f64::NAN, 0.5].into_iter();
        let h0 = c.h;
        let (_, h) = c
            .control(&LAW, 0.0, 1.0, |_, _| ((), errs.next().unwrap()))
            .unwrap();
        assert!((h / h0 - 0.04).abs() < 1e-12);
        // The cap bounds the attempt without shrinking the proposal: a step cut short to meet
        // an end time does not leave the next one tiny.
        let h0 = c.h;
        let (_, h) = c.control(&LAW, 0.0, 1e-9, |_, _| ((), 0.5)).unwrap();
        assert_eq!(h, 1e-9);
        assert_eq!(c.h, h0);
    }

    #[test]
    fn the_predictive_law_shortens_the_step_where_the_error_grows() {
        let pred = StepLaw {
            predictive: true,
            ..LAW
        };
        let (mut plain, mut c) = (core(100, None), core(100, None));
        // The first accepted step has no history: both laws agree.
        for k in [&mut plain, &mut c] {
            k.control(&pred, 0.0, 1.0, |_, _| ((), 0.1)).unwrap();
        }
        assert_eq!(c.h, plain.h);
        // An error growing from 0.1 to 0.9 over a step grown 1.6-fold: the plain law shrinks
        // the step by 0.9 / 0.9^(1/4), the predictive one further, to
        // h 0.9 (h / h_acc) / (0.9^2 / 0.1)^(1/4).
        let h1 = c.h;
        let (_, h) = c.control(&pred, 0.0, 1.0, |_, _| ((), 0.9)).unwrap();
        plain.control(&LAW, 0.0, 1.0, |_, _| ((), 0.9)).unwrap();
        assert_eq!(h, h1);
        let expected = h1 * 0.9 * (h1 / 1e-3) / 8.1f64.powf(0.25);
        assert!((c.h / expected - 1.0).abs() < 1e-12, "{} {expected}", c.h);
        assert!(c.h < plain.h, "{} {}", c.h, plain.h);
        // With no history (a restart clears it) the next step follows the plain law.
        c.h_acc = 0.0;
        let h2 = c.h;
        c.control(&pred, 0.0, 1.0, |_, _| ((), 0.5)).unwrap();
        assert!((c.h / (h2 * 0.9 / 0.5f64.powf(0.25)) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn budget_underflow_and_non_finite_errors() {
        let mut c = core(3, None);
        let e = c.control(&LAW, 0.5, 1.0, |_, _| ((), 2.0)).unwrap_err();
        assert!(
            matches!(e, SolveError::StepBudget { attempts: 3, .. }),
            "{e:?}"
        );

        let mut c = core(1000, None);
        let e = c.control(&LAW, 0.5, 1.0, |_, _| ((), 1e300)).unwrap_err();
        assert!(matches!(e, SolveError::StepSizeUnderflow { .. }), "{e:?}");

        // A fixed step is accepted whatever the error, unless it is not finite.
        let mut c = core(1000, Some(1e-4));
        c.h = 1e-4;
        let (_, h) = c.control(&LAW, 0.0, 1.0, |_, _| ((), 1e9)).unwrap();
        assert_eq!((h, c.h), (1e-4, 1e-4));
        let e = c
            .control(&LAW, 0.0, 1.0, |_, _| ((), f64::NAN))
            .unwrap_err();
        assert!(matches!(e, SolveError::NonFiniteState { .. }), "{e:?}");
    }
}
