//! Dormand-Prince 5(4) with Hairer's PI step control and 4th-order dense output.
//!
//! Coefficients: J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
//! J. Comp. Appl. Math. 6 (1980); dense output and controller as in E. Hairer, S. P. Nørsett,
//! G. Wanner, "Solving Ordinary Differential Equations I", 2nd ed., Sec. II.4-II.6 (DOPRI5).

use super::control::{StepCore, StepLaw};
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// The stepper: stage storage, the FSAL derivative, controller memory and work counters.
#[derive(Debug, Clone)]
pub struct Dopri5<const N: usize> {
    core: StepCore<N>,
    k1: [f64; N],
    /// The last trial step, written in place (returning it copied 720 bytes per attempt).
    trial: Trial<N>,
}

/// One trial step's results: the 5th-order solution and the stages k3-k7 (k7 = f(y_new)).
#[derive(Debug, Clone)]
struct Trial<const N: usize> {
    y_new: [f64; N],
    k: [[f64; N]; 5],
}

/// Hairer's PI controller for DOPRI5: safety 0.9, beta 0.04, step ratio in [1/5, 10].
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 0.2 - 0.04 * 0.75,
    beta: 0.04,
    fac_min: 0.2,
    fac_max: 10.0,
    predictive: false,
};

impl<const N: usize> Dopri5<N> {
    /// A stepper with the given control settings and no step-size history.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self {
            core: StepCore::new(ctl, 5),
            k1: [0.0; N],
            trial: Trial {
                y_new: [0.0; N],
                k: [[0.0; N]; 5],
            },
        }
    }

    /// Builds the dense output of an accepted step and keeps k7 as the next k1 (FSAL).
    fn accept(&mut self, t: f64, y: &[f64; N], h: f64) {
        let (y_new, k) = (&self.trial.y_new, &self.trial.k);
        let k7 = &k[4];
        let d = &mut self.core.dense;
        // Rows 5-7 of `r` stay unused (and zero) with `terms` 5.
        let r = &mut d.r;
        for i in 0..N {
            let ydiff = y_new[i] - y[i];
            let bspl = h * self.k1[i] - ydiff;
            r[0][i] = y[i];
            r[1][i] = ydiff;
            r[2][i] = bspl;
            r[3][i] = ydiff - h * k7[i] - bspl;
            r[4][i] = h
                * (D1 * self.k1[i]
                    + D3 * k[0][i]
                    + D4 * k[1][i]
                    + D5 * k[2][i]
                    + D6 * k[3][i]
                    + D7 * k7[i]);
        }
        (d.t0, d.h, d.t_end, d.terms, d.y1) = (t, h, t + h, 5, *y_new);
        self.k1 = *k7;
        self.core.stats.steps += 1;
    }
}

/// One trial step from `(t, y)` with first stage `k1`, written into `trial` (the 5th-order
/// solution and stages 3-7, k7 the end derivative); returns the error norm (RMS of the
/// embedded error over `atol + rtol * max(|y0|, |y1|)`).
fn attempt<S: OdeSystem<N>, const N: usize>(
    core: &mut StepCore<N>,
    k1: &[f64; N],
    trial: &mut Trial<N>,
    sys: &S,
    t: f64,
    y: &[f64; N],
    h: f64,
) -> f64 {
    let mut yt = [0.0; N];
    let mut k2 = [0.0; N];
    let [k3, k4, k5, k6, k7] = &mut trial.k;
    let y_new = &mut trial.y_new;
    for i in 0..N {
        yt[i] = y[i] + h * A21 * k1[i];
    }
    sys.rhs(t + C2 * h, &yt, &mut k2);
    for i in 0..N {
        yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
    }
    sys.rhs(t + C3 * h, &yt, k3);
    for i in 0..N {
        yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
    }
    sys.rhs(t + C4 * h, &yt, k4);
    for i in 0..N {
        yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
    }
    sys.rhs(t + C5 * h, &yt, k5);
    for i in 0..N {
        yt[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
    }
    sys.rhs(t + h, &yt, k6);
    for i in 0..N {
        y_new[i] = y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
    }
    sys.rhs(t + h, y_new, k7);
    core.stats.rhs_evals += 6;
    let mut acc = 0.0;
    let atol = core.step_atol;
    for i in 0..N {
        let e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        let sc = atol[i] + core.ctl.rtol * y[i].abs().max(y_new[i].abs());
        acc += (e / sc) * (e / sc);
    }
    (acc / N as f64).sqrt()
}

impl<const N: usize> Stepper<N> for Dopri5<N> {
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        sys.rhs(t, y, &mut self.k1);
        self.core.restart(sys, y, &self.k1);
    }
    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        self.core.begin_step(sys, t, y);
        let (k1, trial) = (&self.k1, &mut self.trial);
        let ((), h) = self.core.control(&LAW, t, h_cap, |core, h| {
            ((), attempt(core, k1, trial, sys, t, y, h))
        })?;
        self.accept(t, y, h);
        Ok(&self.core.dense)
    }
    fn core(&self) -> &StepCore<N> {
        &self.core
    }
    fn core_mut(&mut self) -> &mut StepCore<N> {
        &mut self.core
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::{integrate, NoObserver, Stop};

    /// x'' = -x as a first-order system; exact solution cos t.
    struct Harmonic;
    impl OdeSystem<2> for Harmonic {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    fn fixed(h: f64) -> StepControl<2> {
        StepControl {
            rtol: 1.0,
            atol: [1.0; 2],
            h_min: 0.0,
            max_attempts: u64::MAX,
            fixed_step: Some(h),
        }
    }

    #[test]
    fn dense_output_is_fourth_order_inside_a_step() {
        let err_at = |h: f64| {
            let mut st = Dopri5::new(fixed(h));
            st.restart(&Harmonic, 0.0, &[1.0, 0.0]);
            let d = st.step(&Harmonic, 0.0, &[1.0, 0.0], h).unwrap().clone();
            (d.eval(0.37 * h)[0] - (0.37 * h).cos()).abs()
        };
        let order = (err_at(0.2) / err_at(0.1)).log2();
        // Local error of an order-4 interpolant scales like h^5.
        assert!(order > 4.6, "interpolant local order {order}");
    }

    #[test]
    fn non_finite_rhs_is_a_typed_error_with_time() {
        struct Blow;
        impl OdeSystem<1> for Blow {
            type Guard = crate::ode::NoGuard;
            fn rhs(&self, t: f64, _y: &[f64; 1], dy: &mut [f64; 1]) {
                dy[0] = if t > 0.5 { f64::NAN } else { 1.0 };
            }
        }
        let ctl = StepControl {
            rtol: 1e-8,
            atol: [1e-8],
            h_min: 1e-12,
            max_attempts: 10_000,
            fixed_step: None,
        };
        let mut st = Dopri5::new(ctl);
        let (mut t, mut y) = (0.0, [0.0]);
        match integrate(&Blow, &mut st, &mut t, &mut y, 1.0, &mut NoObserver) {
            Err(SolveError::NonFiniteState { t_s })
            | Err(SolveError::StepSizeUnderflow { t_s, .. }) => {
                assert!((0.4..=0.5).contains(&t_s), "{t_s}")
            }
            other => panic!("expected a typed failure, got {other:?}"),
        }
    }

    #[test]
    fn event_on_a_falling_ball_is_located_at_the_closed_form_time() {
        // y'' = -g from height 1 m: the guard y crosses zero at sqrt(2/g).
        struct Ball;
        #[derive(Debug, Clone, Copy, PartialEq)]
        struct Floor;
        impl crate::ode::GuardSet for Floor {
            const ALL: &'static [Self] = &[Floor];
        }
        impl OdeSystem<2> for Ball {
            type Guard = Floor;
            fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
                dy[0] = y[1];
                dy[1] = -9.81;
            }
            fn guards(
                &self,
                _t: f64,
                y: &[f64; 2],
                g: &mut [f64; crate::ode::MAX_GUARDS],
            ) -> usize {
                g[0] = y[0];
                1
            }
            fn max_step(&self) -> f64 {
                0.1
            }
        }
        let ctl = StepControl {
            rtol: 1e-6,
            atol: [1e-9; 2],
            h_min: 1e-14,
            max_attempts: 10_000,
            fixed_step: None,
        };
        let mut st = Dopri5::new(ctl);
        let (mut t, mut y) = (0.0, [1.0, 0.0]);
        let stop = integrate(&Ball, &mut st, &mut t, &mut y, 10.0, &mut NoObserver).unwrap();
        assert!(matches!(stop, Stop::Event { guard: Floor, .. }));
        let exact = (2.0 / 9.81f64).sqrt();
        assert!((t - exact).abs() < 1e-12, "event at {t}, exact {exact}");
        // The run continues just past the crossing, on the new mode's side.
        assert!(y[0] <= 0.0 && y[0] > -1e-12, "{}", y[0]);
    }
}
