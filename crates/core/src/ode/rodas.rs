//! RODAS4: a Rosenbrock method of order 4 with an embedded order-3 estimate, 6 stages,
//! L-stable and stiffly accurate (both the solution and the embedded one).
//!
//! Coefficients: E. Hairer, G. Wanner, "Solving ODEs II", Sec. IV.7 and VI.4, as in their
//! code RODAS (`METH = 1`), in the transformed variables `u_i = sum_j gamma_ij k_j`:
//!
//! `(I / (h gamma) - J) u_i = f(y0 + sum_j a_ij u_j) + sum_j (c_ij / h) u_j`,
//!
//! scaled here by `h gamma` so that the factors of ROS34PW2 (`I - h gamma J`,
//! [`super::rosw`]) serve unchanged: `(I - h gamma J) u_i = h gamma f(Y_i) + gamma sum_j c_ij u_j`.
//! The transformed form needs no `J v` products, only one solve per stage. The last two
//! stages sit at `t + h`: `Y_6 = Y_5 + u_5` is the embedded solution and `y1 = Y_6 + u_6`, so
//! `u_6` is the error estimate. The system is autonomous (the model's right-hand side does
//! not depend on `t`), so the `h gamma_i f_t` terms of the non-autonomous form are left out.
//!
//! Unlike a W-method, a Rosenbrock method keeps its order only with the exact Jacobian: with
//! an approximate one the order of the terms the matrix leaves out drops (the stepper harness
//! measures it). So RODAS4 takes the Jacobian's quadrature rows ([`super::StiffJacobian::quad`]),
//! and the drop model hands it the full matrix when the scene asks for RODAS4: the energy
//! integrals' and the angles' rows (without them the energies' error estimate, not the
//! motion's, set the step at an impact), the sticking constraint's slopes and the drag's.
//! Measured on 2026-11-24 (docs/accuracy.md#rodas4-measured). Dense output and the reuse of
//! the end's derivative are ROS34PW2's: the cubic Hermite interpolant of the step's ends.

use super::control::{StepCore, StepLaw};
use super::rosw::{rosenbrock_step, Lu, Rosenbrock};
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

const GAMMA: f64 = 0.25;
/// Stage times `c_i` (fractions of the step).
const C: [f64; 6] = [0.0, 0.386, 0.21, 0.63, 1.0, 1.0];
/// `a_ij` of stages 2-5 (stage 6 is at `Y_5 + u_5`).
const A: [[f64; 4]; 5] = [
    [0.0, 0.0, 0.0, 0.0],
    [1.544, 0.0, 0.0, 0.0],
    [9.466_785_280_815_826e-1, 2.557_011_698_983_284e-1, 0.0, 0.0],
    [
        3.314_825_187_068_521,
        2.896_124_015_972_201,
        9.986_419_139_977_817e-1,
        0.0,
    ],
    [
        1.221_224_509_226_641,
        6.019_134_481_288_629,
        12.537_083_329_320_87,
        -6.878_860_361_058_950e-1,
    ],
];
/// `c_ij` of stages 2-6.
const CC: [[f64; 5]; 6] = [
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [-5.6688, 0.0, 0.0, 0.0, 0.0],
    [
        -2.430_093_356_833_875,
        -2.063_599_157_091_915e-1,
        0.0,
        0.0,
        0.0,
    ],
    [
        -1.073_529_058_151_375e-1,
        -9.594_562_251_023_355,
        -20.470_286_148_096_16,
        0.0,
        0.0,
    ],
    [
        7.496_443_313_967_647,
        -10.246_804_314_643_52,
        -33.999_903_528_199_05,
        11.708_908_932_061_60,
        0.0,
    ],
    [
        8.083_246_795_921_522,
        -7.981_132_988_064_893,
        -31.521_594_328_743_71,
        16.319_305_431_231_36,
        -6.058_818_238_834_054,
    ],
];

/// The RODAS4 stepper: the derivative at the step start, the factored iteration matrix,
/// controller memory and work counters.
#[derive(Debug, Clone)]
pub struct Rodas4<const N: usize> {
    core: StepCore<N>,
    /// The derivative at the last accepted step's end (the next step's start).
    pub(super) f0: [f64; N],
    lu: Lu,
}

/// The error estimate is O(h^4): exponent 1/4, safety 0.9, step ratio in [1/5, 6] (RODAS's
/// defaults without its predictive controller: with it, the 1 s pendulum drop took 2 % more
/// steps and 0.9 % more RHS evaluations for 40 % fewer rejections; docs/performance.md).
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 0.25,
    beta: 0.0,
    fac_min: 0.2,
    fac_max: 6.0,
    predictive: false,
};

impl<const N: usize> Rodas4<N> {
    /// A stepper with the given control settings and no step-size history.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self {
            core: StepCore::new(ctl, 5),
            f0: [0.0; N],
            lu: Lu::identity(),
        }
    }

    /// One trial step of size `h` from `(t, y)` with derivative `f0` there and `lu` factored
    /// for `h gamma`: the new state, the error norm.
    fn attempt<S: OdeSystem<N>>(
        core: &mut StepCore<N>,
        lu: &Lu,
        f0: &[f64; N],
        sys: &S,
        t: f64,
        y: &[f64; N],
        h: f64,
    ) -> ([f64; N], f64) {
        let hg = h * GAMMA;
        let mut u = [[0.0; N]; 6];
        first_stage(hg, f0, lu, &mut u);
        let (mut yt, mut f) = ([0.0; N], [0.0; N]);
        let st = |s: usize| (t + C[s] * h, hg, GAMMA);
        point::<N, 1, 6>(y, &A[1], &u, &mut yt);
        stage::<N, 1, 6, S>(sys, st(1), &CC[1], lu, &yt, &mut f, &mut u, 1);
        point::<N, 2, 6>(y, &A[2], &u, &mut yt);
        stage::<N, 2, 6, S>(sys, st(2), &CC[2], lu, &yt, &mut f, &mut u, 2);
        point::<N, 3, 6>(y, &A[3], &u, &mut yt);
        stage::<N, 3, 6, S>(sys, st(3), &CC[3], lu, &yt, &mut f, &mut u, 3);
        point::<N, 4, 6>(y, &A[4], &u, &mut yt);
        stage::<N, 4, 6, S>(sys, st(4), &CC[4], lu, &yt, &mut f, &mut u, 4);
        // Y_6 = Y_5 + u_5: the embedded solution.
        for i in 0..N {
            yt[i] += u[4][i];
        }
        stage::<N, 5, 6, S>(sys, st(5), &CC[5], lu, &yt, &mut f, &mut u, 5);
        core.stats.rhs_evals += 5;
        last_stage_end(core, y, &yt, &u[5])
    }
}

/// `sum_j c_j u_j` over the first `M` stages, unrolled (a constant number of terms, in
/// order of `j`).
#[inline(always)]
pub(super) fn comb<const N: usize, const M: usize, const S: usize>(
    c: &[f64],
    u: &[[f64; N]; S],
) -> [f64; N] {
    let mut v = [0.0; N];
    for j in 0..M {
        for i in 0..N {
            v[i] += c[j] * u[j][i];
        }
    }
    v
}

/// The first stage of a RODAS-type step: `u_1 = W^-1 (h gamma f(y0))`.
#[inline(always)]
pub(super) fn first_stage<const N: usize, const S: usize>(
    hg: f64,
    f0: &[f64; N],
    lu: &Lu,
    u: &mut [[f64; N]; S],
) {
    for i in 0..N {
        u[0][i] = hg * f0[i];
    }
    lu.solve(&mut u[0]);
}

/// A stage point from the `a_sj` row `a` of the stages before it: `yt = y0 + sum_j a_sj u_j`.
#[inline(always)]
pub(super) fn point<const N: usize, const M: usize, const S: usize>(
    y: &[f64; N],
    a: &[f64],
    u: &[[f64; N]; S],
    yt: &mut [f64; N],
) {
    let v = comb::<N, M, S>(a, u);
    for i in 0..N {
        yt[i] = y[i] + v[i];
    }
}

/// Stage `s` (0-based) at `yt` from the `M = s` stages before it, `(t_s, h gamma, gamma)` its
/// time and the method's diagonal: `u_s = W^-1 (h gamma f(t_s, yt) + gamma sum_j c_sj u_j)`,
/// with `f` as scratch for the derivative.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn stage<const N: usize, const M: usize, const S: usize, Sys: OdeSystem<N>>(
    sys: &Sys,
    (t_s, hg, gamma): (f64, f64, f64),
    cc: &[f64],
    lu: &Lu,
    yt: &[f64; N],
    f: &mut [f64; N],
    u: &mut [[f64; N]; S],
    s: usize,
) {
    sys.rhs(t_s, yt, f);
    let v = comb::<N, M, S>(cc, u);
    let r = &mut u[s];
    for i in 0..N {
        r[i] = hg * f[i] + gamma * v[i];
    }
    lu.solve(r);
}

/// The step's end `y1 = yt + u_last` (the stiffly accurate solution after the embedded one at
/// `yt`) and the error norm of `u_last`, scaled by the step's tolerances.
#[inline(always)]
pub(super) fn last_stage_end<const N: usize>(
    core: &StepCore<N>,
    y: &[f64; N],
    yt: &[f64; N],
    last: &[f64; N],
) -> ([f64; N], f64) {
    let mut y1 = [0.0; N];
    let mut err = 0.0;
    let atol = core.step_atol;
    for i in 0..N {
        y1[i] = yt[i] + last[i];
        let sc = atol[i] + core.ctl.rtol * y[i].abs().max(y1[i].abs());
        err += (last[i] / sc) * (last[i] / sc);
    }
    (y1, (err / N as f64).sqrt())
}

impl<const N: usize> Stepper<N> for Rodas4<N> {
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        sys.rhs(t, y, &mut self.f0);
        self.core.restart(sys, y, &self.f0);
    }

    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        let method = Rosenbrock {
            law: &LAW,
            gamma: GAMMA,
            attempt: Self::attempt::<S>,
            quadratures: true,
            own_dense: false,
        };
        rosenbrock_step(
            &mut self.core,
            &mut self.lu,
            &mut self.f0,
            &method,
            sys,
            t,
            y,
            h_cap,
        )
    }

    fn core(&self) -> &StepCore<N> {
        &self.core
    }
    fn core_mut(&mut self) -> &mut StepCore<N> {
        &mut self.core
    }
}
