//! Rodas5P: a Rosenbrock method of order 5 with an embedded order-4 estimate, 8 stages,
//! L-stable and stiffly accurate, built to keep its order on stiff problems where RODAS4's
//! drops (G. Steinebach, "Construction of Rosenbrock-Wanner method Rodas5P and numerical
//! benchmarks within the Julia Differential Equations package", BIT Numer. Math. 63 (2023)).
//!
//! The same transformed form and the same factors as [`super::rodas`]:
//! `(I - h gamma J) u_i = h gamma f(Y_i) + gamma sum_j c_ij u_j`, `Y_i = y0 + sum_j a_ij u_j`
//! for stages 2-6 (stage 6 at `t + h`), then `Y_7 = Y_6 + u_6`, `Y_8 = Y_7 + u_7` (the
//! embedded solution) and `y1 = Y_8 + u_8`, so `u_8` is the error estimate. Autonomous
//! system: the `f_t` terms are left out. Dense output is the method's own of order 4,
//! `y(th) = (1 - th) y0 + th (y1 + (1 - th) (K1 + th (K2 + th K3)))` with `K_r = sum_j h_rj u_j`
//! (the `H` rows below): the events and the force peaks are located on it, and the cubic
//! Hermite interpolant of the step's ends (order 3) would lose to it on steps this long.

use super::control::{StepCore, StepLaw};
use super::rodas::{comb, first_stage, last_stage_end, point, stage};
use super::rosw::{rosenbrock_step, Lu, Rosenbrock};
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

const GAMMA: f64 = 0.211_937_563_194_290_14;
/// Stage times `c_i` (fractions of the step); stages 6-8 sit at `t + h`.
const C: [f64; 8] = [
    0.0,
    0.635_812_689_582_870_4,
    0.409_579_839_339_753_5,
    0.976_930_672_506_071_6,
    0.428_840_360_955_866_4,
    1.0,
    1.0,
    1.0,
];
/// `a_ij` of stages 2-6.
const A: [[f64; 5]; 6] = [
    [0.0; 5],
    [3.0, 0.0, 0.0, 0.0, 0.0],
    [
        2.849_394_379_747_939,
        0.458_422_422_044_639_23,
        0.0,
        0.0,
        0.0,
    ],
    [
        -6.954_028_509_809_101,
        2.489_845_061_869_568,
        -10.358_996_098_473_584,
        0.0,
        0.0,
    ],
    [
        2.802_998_627_562_896_4,
        0.507_246_473_622_820_6,
        -0.398_831_254_177_052_4,
        -0.047_211_872_304_046_41,
        0.0,
    ],
    [
        -7.502_846_399_306_121,
        2.561_846_144_803_919,
        -11.627_539_656_261_098,
        -0.182_687_676_599_422_56,
        0.030_198_172_008_377_946,
    ],
];
/// `c_ij` of stages 2-8.
const CC: [[f64; 7]; 8] = [
    [0.0; 7],
    [-14.155_112_264_123_755, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        -17.972_960_358_859_52,
        -2.859_693_295_451_294,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        147.121_502_757_117_16,
        -1.412_214_027_182_13,
        71.689_402_513_023_58,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        165.435_170_248_716_76,
        -0.459_282_345_649_112_6,
        42.909_383_369_586_03,
        -5.961_986_721_573_306,
        0.0,
        0.0,
        0.0,
    ],
    [
        24.854_864_614_690_072,
        -3.000_922_700_283_218_6,
        47.493_111_002_076_8,
        5.581_419_782_155_812_5,
        -0.661_069_182_524_947_1,
        0.0,
        0.0,
    ],
    [
        30.912_732_140_285_99,
        -3.120_824_334_993_797_4,
        77.799_546_460_708_92,
        34.286_460_282_947_83,
        -19.097_331_116_725_623,
        -28.087_943_162_872_662,
        0.0,
    ],
    [
        37.802_771_233_905_63,
        -3.257_196_902_907_227_6,
        112.269_188_494_963_27,
        66.934_723_124_404_7,
        -40.066_189_370_910_02,
        -54.667_802_628_779_68,
        -9.488_616_523_096_27,
    ],
];

/// The dense-output rows `h_rj` (`K_r = sum_j h_rj u_j`).
const H: [[f64; 8]; 3] = [
    [
        25.948_786_856_663_858,
        -2.557_972_484_584_623_5,
        10.433_815_404_888_879,
        -2.367_925_102_268_520_4,
        0.524_948_541_321_073,
        1.124_108_831_045_040_4,
        0.427_287_619_443_187_4,
        -0.172_022_210_701_554_93,
    ],
    [
        -9.915_688_506_951_71,
        -0.968_994_459_411_515_4,
        3.043_803_724_297_845_3,
        -24.495_224_566_215_796,
        20.176_138_334_709_044,
        15.980_663_614_246_51,
        -6.789_040_303_419_874,
        -6.710_236_069_923_372,
    ],
    [
        11.419_903_575_922_262,
        2.887_964_514_613_699_4,
        72.921_379_959_960_29,
        80.125_118_346_226_43,
        -52.072_871_366_152_654,
        -59.789_936_252_667_29,
        -0.155_826_842_827_519_13,
        4.883_087_185_713_722,
    ],
];

/// The Rodas5P stepper: the derivative at the step start, the factored iteration matrix,
/// controller memory and work counters.
#[derive(Debug, Clone)]
pub struct Rodas5p<const N: usize> {
    core: StepCore<N>,
    f0: [f64; N],
    lu: Lu,
}

/// The error estimate is O(h^5): exponent 1/5, safety 0.9, step ratio in [1/5, 6].
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 0.2,
    beta: 0.0,
    fac_min: 0.2,
    fac_max: 6.0,
    predictive: false,
};

impl<const N: usize> Rodas5p<N> {
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
        let mut u = [[0.0; N]; 8];
        first_stage(hg, f0, lu, &mut u);
        let (mut yt, mut f) = ([0.0; N], [0.0; N]);
        let st = |s: usize| (t + C[s] * h, hg, GAMMA);
        point::<N, 1, 8>(y, &A[1], &u, &mut yt);
        stage::<N, 1, 8, S>(sys, st(1), &CC[1], lu, &yt, &mut f, &mut u, 1);
        point::<N, 2, 8>(y, &A[2], &u, &mut yt);
        stage::<N, 2, 8, S>(sys, st(2), &CC[2], lu, &yt, &mut f, &mut u, 2);
        point::<N, 3, 8>(y, &A[3], &u, &mut yt);
        stage::<N, 3, 8, S>(sys, st(3), &CC[3], lu, &yt, &mut f, &mut u, 3);
        point::<N, 4, 8>(y, &A[4], &u, &mut yt);
        stage::<N, 4, 8, S>(sys, st(4), &CC[4], lu, &yt, &mut f, &mut u, 4);
        point::<N, 5, 8>(y, &A[5], &u, &mut yt);
        stage::<N, 5, 8, S>(sys, st(5), &CC[5], lu, &yt, &mut f, &mut u, 5);
        // Y_7 = Y_6 + u_6, then Y_8 = Y_7 + u_7: the embedded solution.
        for i in 0..N {
            yt[i] += u[5][i];
        }
        stage::<N, 6, 8, S>(sys, st(6), &CC[6], lu, &yt, &mut f, &mut u, 6);
        for i in 0..N {
            yt[i] += u[6][i];
        }
        stage::<N, 7, 8, S>(sys, st(7), &CC[7], lu, &yt, &mut f, &mut u, 7);
        core.stats.rhs_evals += 7;
        // The interpolant's K1..K3 into the dense rows 5-7 ([`Rosenbrock::own_dense`]).
        for (row, h_r) in core.dense.r[5..8].iter_mut().zip(&H) {
            *row = comb::<N, 8, 8>(h_r, &u);
        }
        last_stage_end(core, y, &yt, &u[7])
    }
}

impl<const N: usize> Stepper<N> for Rodas5p<N> {
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
            own_dense: true,
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
