//! Hairer's DOP853: the explicit Runge-Kutta pair of order 8 with a 5th- and 3rd-order error
//! estimate and a 7th-order dense output (3 extra stages per accepted step).
//!
//! Tableau: J. R. Dormand, P. J. Prince, "High order embedded Runge-Kutta formulae",
//! J. Comp. Appl. Math. 7 (1981); error estimate, controller and dense output as in E. Hairer,
//! S. P. Nørsett, G. Wanner, "Solving Ordinary Differential Equations I", 2nd ed., Sec. II.10
//! (the `dop853` code). The coefficients below are that code's, to 30 digits.
//!
//! Why a second, hand-written stepper rather than a pinned dependency: the reference must
//! run the *same* hybrid model (mode switches at located events, the damper-never-pulls
//! switch, stick/slip, the monitor's located peaks). A crate integrator (for example
//! `differential-equations`) would need the whole event logic re-expressed in its API, and a
//! disagreement would then not tell a model-wrapping error from an integration error. Here
//! only the Runge-Kutta step differs from [`super::Dopri5`]: another tableau, another order
//! (8 against 5), another error estimator and another interpolant, while the model, the
//! event location and the observers are shared. Agreement of the two at tight tolerance
//! therefore confirms the integration, which is what a reference needs.

// The coefficients are kept to the 30 digits of the published tableau, so they can be checked
// against it digit by digit; f64 rounds them.
#![allow(clippy::excessive_precision)]

use super::control::{StepCore, StepLaw};
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

/// Stages of the step (12) and of the dense output (16).
const S: usize = 12;
const SX: usize = 16;

const C: [f64; SX] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// The Butcher matrix, rows 1-11 for the step, row 12 the 8th-order weights, rows 13-15 the
/// dense output's extra stages.
#[rustfmt::skip]
const A: [[f64; SX]; SX] = {
    let mut a = [[0.0; SX]; SX];
    a[1][0] = 5.26001519587677318785587544488e-2;
    a[2][0] = 1.97250569845378994544595329183e-2;
    a[2][1] = 5.91751709536136983633785987549e-2;
    a[3][0] = 2.95875854768068491816892993775e-2;
    a[3][2] = 8.87627564304205475450678981324e-2;
    a[4][0] = 2.41365134159266685502369798665e-1;
    a[4][2] = -8.84549479328286085344864962717e-1;
    a[4][3] = 9.24834003261792003115737966543e-1;
    a[5][0] = 3.7037037037037037037037037037e-2;
    a[5][3] = 1.70828608729473871279604482173e-1;
    a[5][4] = 1.25467687566822425016691814123e-1;
    a[6][0] = 3.7109375e-2;
    a[6][3] = 1.70252211019544039314978060272e-1;
    a[6][4] = 6.02165389804559606850219397283e-2;
    a[6][5] = -1.7578125e-2;
    a[7][0] = 3.70920001185047927108779319836e-2;
    a[7][3] = 1.70383925712239993810214054705e-1;
    a[7][4] = 1.07262030446373284651809199168e-1;
    a[7][5] = -1.53194377486244017527936158236e-2;
    a[7][6] = 8.27378916381402288758473766002e-3;
    a[8][0] = 6.24110958716075717114429577812e-1;
    a[8][3] = -3.36089262944694129406857109825;
    a[8][4] = -8.68219346841726006818189891453e-1;
    a[8][5] = 2.75920996994467083049415600797e1;
    a[8][6] = 2.01540675504778934086186788979e1;
    a[8][7] = -4.34898841810699588477366255144e1;
    a[9][0] = 4.77662536438264365890433908527e-1;
    a[9][3] = -2.48811461997166764192642586468;
    a[9][4] = -5.90290826836842996371446475743e-1;
    a[9][5] = 2.12300514481811942347288949897e1;
    a[9][6] = 1.52792336328824235832596922938e1;
    a[9][7] = -3.32882109689848629194453265587e1;
    a[9][8] = -2.03312017085086261358222928593e-2;
    a[10][0] = -9.3714243008598732571704021658e-1;
    a[10][3] = 5.18637242884406370830023853209;
    a[10][4] = 1.09143734899672957818500254654;
    a[10][5] = -8.14978701074692612513997267357;
    a[10][6] = -1.85200656599969598641566180701e1;
    a[10][7] = 2.27394870993505042818970056734e1;
    a[10][8] = 2.49360555267965238987089396762;
    a[10][9] = -3.0467644718982195003823669022;
    a[11][0] = 2.27331014751653820792359768449;
    a[11][3] = -1.05344954667372501984066689879e1;
    a[11][4] = -2.00087205822486249909675718444;
    a[11][5] = -1.79589318631187989172765950534e1;
    a[11][6] = 2.79488845294199600508499808837e1;
    a[11][7] = -2.85899827713502369474065508674;
    a[11][8] = -8.87285693353062954433549289258;
    a[11][9] = 1.23605671757943030647266201528e1;
    a[11][10] = 6.43392746015763530355970484046e-1;
    a[12][0] = 5.42937341165687622380535766363e-2;
    a[12][5] = 4.45031289275240888144113950566;
    a[12][6] = 1.89151789931450038304281599044;
    a[12][7] = -5.8012039600105847814672114227;
    a[12][8] = 3.1116436695781989440891606237e-1;
    a[12][9] = -1.52160949662516078556178806805e-1;
    a[12][10] = 2.01365400804030348374776537501e-1;
    a[12][11] = 4.47106157277725905176885569043e-2;
    a[13][0] = 5.61675022830479523392909219681e-2;
    a[13][6] = 2.53500210216624811088794765333e-1;
    a[13][7] = -2.46239037470802489917441475441e-1;
    a[13][8] = -1.24191423263816360469010140626e-1;
    a[13][9] = 1.5329179827876569731206322685e-1;
    a[13][10] = 8.20105229563468988491666602057e-3;
    a[13][11] = 7.56789766054569976138603589584e-3;
    a[13][12] = -8.298e-3;
    a[14][0] = 3.18346481635021405060768473261e-2;
    a[14][5] = 2.83009096723667755288322961402e-2;
    a[14][6] = 5.35419883074385676223797384372e-2;
    a[14][7] = -5.49237485713909884646569340306e-2;
    a[14][10] = -1.08347328697249322858509316994e-4;
    a[14][11] = 3.82571090835658412954920192323e-4;
    a[14][12] = -3.40465008687404560802977114492e-4;
    a[14][13] = 1.41312443674632500278074618366e-1;
    a[15][0] = -4.28896301583791923408573538692e-1;
    a[15][5] = -4.69762141536116384314449447206;
    a[15][6] = 7.68342119606259904184240953878;
    a[15][7] = 4.06898981839711007970213554331;
    a[15][8] = 3.56727187455281109270669543021e-1;
    a[15][12] = -1.39902416515901462129418009734e-3;
    a[15][13] = 2.9475147891527723389556272149;
    a[15][14] = -9.15095847217987001081870187138;
    a
};

/// 5th-order error estimator weights on stages 0-11.
#[rustfmt::skip]
const E5: [f64; S] = [
    0.1312004499419488073250102996e-1, 0.0, 0.0, 0.0, 0.0,
    -0.1225156446376204440720569753e1, -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1, -0.3503288487499736816886487290,
    0.3341791187130174790297318841, 0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
];

/// 3rd-order estimator: the 8th-order weights minus these (on stages 0, 8 and 11).
const BHH: [f64; 3] = [
    0.244094488188976377952755905512,
    0.733846688281611857341361741547,
    0.220588235294117647058823529412e-1,
];

/// Dense output coefficients d4..d7 on stages 0-15.
#[rustfmt::skip]
const D: [[f64; SX]; 4] = [
    [-0.84289382761090128651353491142e1, 0.0, 0.0, 0.0, 0.0,
     0.56671495351937776962531783590, -0.30689499459498916912797304727e1,
     0.23846676565120698287728149680e1, 0.21170345824450282767155149946e1,
     -0.87139158377797299206789907490, 0.22404374302607882758541771650e1,
     0.63157877876946881815570249290, -0.88990336451333310820698117400e-1,
     0.18148505520854727256656404962e2, -0.91946323924783554000451984436e1,
     -0.44360363875948939664310572000e1],
    [0.10427508642579134603413151009e2, 0.0, 0.0, 0.0, 0.0,
     0.24228349177525818288430175319e3, 0.16520045171727028198505394887e3,
     -0.37454675472269020279518312152e3, -0.22113666853125306036270938578e2,
     0.77334326684722638389603898808e1, -0.30674084731089398182061213626e2,
     -0.93321305264302278729567221706e1, 0.15697238121770843886131091075e2,
     -0.31139403219565177677282850411e2, -0.93529243588444783865713862664e1,
     0.35816841486394083752465898540e2],
    [0.19985053242002433820987653617e2, 0.0, 0.0, 0.0, 0.0,
     -0.38703730874935176555105901742e3, -0.18917813819516756882830838328e3,
     0.52780815920542364900561016686e3, -0.11573902539959630126141871134e2,
     0.68812326946963000169666922661e1, -0.10006050966910838403183860980e1,
     0.77771377980534432092869265740, -0.27782057523535084065932004339e1,
     -0.60196695231264120758267380846e2, 0.84320405506677161018159903784e2,
     0.11992291136182789328035130030e2],
    [-0.25693933462703749003312586129e2, 0.0, 0.0, 0.0, 0.0,
     -0.15418974869023643374053993627e3, -0.23152937917604549567536039109e3,
     0.35763911791061412378285349910e3, 0.93405324183624310003907691704e2,
     -0.37458323136451633156875139351e2, 0.10409964950896230045147246184e3,
     0.29840293426660503123344363579e2, -0.43533456590011143754432175058e2,
     0.96324553959188282948394950600e2, -0.39177261675615439165231486172e2,
     -0.14972683625798562581422125276e3],
];

/// The DOP853 stepper: stage storage, the FSAL derivative, the step size and work counters.
#[derive(Debug, Clone)]
pub struct Dop853<const N: usize> {
    core: StepCore<N>,
    k1: [f64; N],
}

/// Hairer's dop853 defaults: safety 0.9, step ratio in [1/3, 6], no PI term.
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 1.0 / 8.0,
    beta: 0.0,
    fac_min: 0.333,
    fac_max: 6.0,
    predictive: false,
};

/// `y + h * sum_j a[j] k[j]` over the first `s` stages.
#[inline]
fn stage_state<const N: usize>(
    y: &[f64; N],
    h: f64,
    a: &[f64; SX],
    k: &[[f64; N]; SX],
    s: usize,
) -> [f64; N] {
    let mut yt = *y;
    for i in 0..N {
        let mut acc = 0.0;
        for j in 0..s {
            acc += a[j] * k[j][i];
        }
        yt[i] += h * acc;
    }
    yt
}

impl<const N: usize> Dop853<N> {
    /// A stepper with the given control settings and no step-size history.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self {
            core: StepCore::new(ctl, 8),
            k1: [0.0; N],
        }
    }

    /// One trial step: the stages 0-12 (12 = the derivative at the new state) and the error
    /// norm (Hairer's: the 5th-order estimate damped by the 3rd-order one).
    #[allow(clippy::type_complexity)]
    fn attempt<S2: OdeSystem<N>>(
        core: &mut StepCore<N>,
        k1: &[f64; N],
        sys: &S2,
        t: f64,
        y: &[f64; N],
        h: f64,
    ) -> (([f64; N], Box<[[f64; N]; SX]>), f64) {
        let mut k: Box<[[f64; N]; SX]> = Box::new([[0.0; N]; SX]);
        k[0] = *k1;
        for s in 1..S {
            let yt = stage_state(y, h, &A[s], &k, s);
            let mut ks = [0.0; N];
            sys.rhs(t + C[s] * h, &yt, &mut ks);
            k[s] = ks;
        }
        let y_new = stage_state(y, h, &A[S], &k, S);
        let mut kn = [0.0; N];
        sys.rhs(t + h, &y_new, &mut kn);
        k[S] = kn;
        core.stats.rhs_evals += S as u64;
        let (mut err5, mut err3) = (0.0, 0.0);
        let atol = core.step_atol;
        for i in 0..N {
            let sc = atol[i] + core.ctl.rtol * y[i].abs().max(y_new[i].abs());
            let mut e5 = 0.0;
            let mut b8 = 0.0;
            for j in 0..S {
                e5 += E5[j] * k[j][i];
                b8 += A[S][j] * k[j][i];
            }
            let e3 = b8 - BHH[0] * k[0][i] - BHH[1] * k[8][i] - BHH[2] * k[11][i];
            err5 += (e5 / sc) * (e5 / sc);
            err3 += (e3 / sc) * (e3 / sc);
        }
        let deno = err5 + 0.01 * err3;
        let err = if deno > 0.0 {
            h.abs() * err5 / (deno * N as f64).sqrt()
        } else {
            0.0
        };
        ((y_new, k), err)
    }

    /// Builds the 7th-order dense output of an accepted step (3 more RHS evaluations).
    fn accept<S2: OdeSystem<N>>(
        &mut self,
        sys: &S2,
        t: f64,
        y: &[f64; N],
        h: f64,
        y_new: &[f64; N],
        k: &mut [[f64; N]; SX],
    ) {
        for s in S + 1..SX {
            let yt = stage_state(y, h, &A[s], k, s);
            let mut ks = [0.0; N];
            sys.rhs(t + C[s] * h, &yt, &mut ks);
            k[s] = ks;
        }
        self.core.stats.rhs_evals += (SX - S - 1) as u64;
        let mut r = [[0.0; N]; 8];
        for i in 0..N {
            let dy = y_new[i] - y[i];
            r[0][i] = y[i];
            r[1][i] = dy;
            r[2][i] = h * k[0][i] - dy;
            r[3][i] = 2.0 * dy - h * (k[S][i] + k[0][i]);
            for (m, d) in D.iter().enumerate() {
                let mut acc = 0.0;
                for j in 0..SX {
                    acc += d[j] * k[j][i];
                }
                r[4 + m][i] = h * acc;
            }
        }
        self.core.dense = Dense {
            t0: t,
            h,
            t_end: t + h,
            terms: 8,
            r,
            y1: *y_new,
            y0: *y,
        };
        self.k1 = k[S];
        self.core.stats.steps += 1;
    }
}

impl<const N: usize> Stepper<N> for Dop853<N> {
    fn restart<S2: OdeSystem<N>>(&mut self, sys: &S2, t: f64, y: &[f64; N]) {
        sys.rhs(t, y, &mut self.k1);
        self.core.restart(sys, y, &self.k1);
    }

    fn step<S2: OdeSystem<N>>(
        &mut self,
        sys: &S2,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        self.core.begin_step(sys, t, y);
        let k1 = &self.k1;
        let ((y_new, mut k), h) = self.core.control(&LAW, t, h_cap, |core, h| {
            Self::attempt(core, k1, sys, t, y, h)
        })?;
        self.accept(sys, t, y, h, &y_new, &mut k);
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

    /// x'' = -x; exact solution cos t.
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
    fn the_tableau_is_consistent() {
        // Row sums equal the nodes; the 8th-order weights sum to 1; the estimators to 0.
        for s in 1..SX {
            let sum: f64 = A[s].iter().sum();
            assert!((sum - C[s]).abs() < 1e-13, "row {s}: {sum} vs {}", C[s]);
        }
        assert!((A[S].iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!(E5.iter().sum::<f64>().abs() < 1e-14);
        assert!((BHH.iter().sum::<f64>() - 1.0).abs() < 1e-14);
    }

    #[test]
    fn dense_output_is_seventh_order_inside_a_step() {
        let err_at = |h: f64| {
            let mut st = Dop853::new(fixed(h));
            st.restart(&Harmonic, 0.0, &[1.0, 0.0]);
            let d = st.step(&Harmonic, 0.0, &[1.0, 0.0], h).unwrap().clone();
            (d.eval(0.37 * h)[0] - (0.37 * h).cos()).abs()
        };
        // Local error of an order-7 interpolant scales like h^8.
        let order = (err_at(0.8) / err_at(0.4)).log2();
        assert!(order > 7.3, "interpolant local order {order}");
    }
}
