//! RADAU5: the 3-stage Radau IIA collocation method of order 5, L-stable, stiffly accurate,
//! of stage order 3 (E. Hairer, G. Wanner, "Solving ODEs II", Sec. IV.8, as in their code
//! RADAU5).
//!
//! The stages `Z_i = Y_i - y0` solve `Z = h (A x I) F(y0 + Z)`. A simplified Newton iteration
//! on the transformed stages `W = (T^-1 x I) Z`, where `T^-1 A^-1 T` is `gamma` and the block
//! `[[alpha, -beta], [beta, alpha]]`, needs two factorisations a step: `gamma/h - J` (real,
//! through the Rosenbrock steppers' factors, [`super::rosw`]) and `(alpha + i beta)/h - J`
//! (complex). It starts from the last step's collocation polynomial, extrapolated. The error
//! estimate is RADAU5's: the embedded difference `f0 + sum_i d_i Z_i / h` passed through
//! `(gamma/h - J)^-1`, which damps its stiff components, once more through the model on the
//! first step and after a rejection. A Newton iteration that diverges or would not converge
//! in 7 iterations cuts the step (by half, or by RADAU5's prediction) and caps the next steps
//! there, the cap growing by 5 % a step. Dense output is the cubic Hermite interpolant of the
//! step's ends, as RODAS4's.
//!
//! Why a collocation method: its stage order 3 keeps the race's stiff, damped components
//! accurate at steps that span their modes, where a Rosenbrock method's stage order 1 costs
//! it order (docs/performance.md#radau5-measured).

use super::control::{StepCore, StepLaw};
use super::rosw::Lu;
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::{OdeSystem, StiffJacobian, MAX_STIFF};
use crate::error::SolveError;
use nalgebra::{Complex, DMatrix, DVector, Dyn, Matrix6, Vector6, LU, U6};

type C64 = Complex<f64>;

const C1: f64 = 0.155_051_025_721_682_22;
const C2: f64 = 0.644_948_974_278_317_8;
const C1M1: f64 = C1 - 1.0;
const C2M1: f64 = C2 - 1.0;
const C1MC2: f64 = C1 - C2;
const DD1: f64 = -10.048_809_399_827_414;
const DD2: f64 = 1.382_142_733_160_748;
const DD3: f64 = -1.0 / 3.0;
/// The real eigenvalue of `A^-1` and the complex pair `alpha +- i beta`.
const GAMMA: f64 = 3.637_834_252_744_496_2;
const ALPHA: f64 = 2.681_082_873_627_752_3;
const BETA: f64 = 3.050_430_199_247_410_5;
const T: [[f64; 3]; 3] = [
    [
        9.123_239_487_089_294_279_2e-2,
        -0.141_255_295_020_954_208_43,
        -3.002_919_410_514_742_449_2e-2,
    ],
    [
        0.241_717_932_707_107_018_96,
        0.204_129_352_293_799_931_99,
        0.382_942_112_757_261_937_79,
    ],
    [0.966_048_182_615_092_936_19, 1.0, 0.0],
];
const TI: [[f64; 3]; 3] = [
    [
        4.325_579_890_063_155_351_0,
        0.339_199_251_815_809_869_54,
        0.541_770_539_935_874_871_19,
    ],
    [
        -4.178_718_591_551_904_727_3,
        -0.327_682_820_761_062_387_08,
        0.476_623_554_500_550_451_96,
    ],
    [
        -0.502_872_634_945_786_875_95,
        2.571_926_949_855_605_429_2,
        -0.596_039_204_828_224_924_97,
    ],
];

/// The error estimate is O(h^4): exponent 1/4, safety 0.9, step ratio in [1/5, 6], with
/// RADAU5's predictive controller (on a stiff Van der Pol problem it cut the rejections from
/// 66 to 12 at rtol 1e-6; docs/performance.md).
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 0.25,
    beta: 0.0,
    fac_min: 0.2,
    fac_max: 6.0,
    predictive: true,
};

/// Most Newton iterations per attempt (RADAU5's default).
const NIT: usize = 7;

/// `c I - J` for the complex shift `c = (alpha + i beta) / h`, LU-factored on the coupled
/// components with the kinematic ones eliminated (as [`Lu`] does for a real shift): the
/// model's 6x6 complement in nalgebra's fixed-size storage, any other shape in dynamic
/// storage. The fixed variant is large on purpose: boxing it would allocate at every
/// factorisation, once per attempt.
#[allow(clippy::large_enum_variant)]
enum ComplexLu {
    /// No coupled components: `c I`.
    Scalar,
    /// The model's shape (10 coupled components, 4 kinematic).
    Six(LU<C64, U6, U6>),
    /// Any other shape.
    Dynamic(LU<C64, Dyn, Dyn>),
}

/// The entry `(a, b)` of the complement `c I - J_vv - J_vq / c` (positions eliminated).
#[inline(always)]
fn complement(j: &StiffJacobian, c: C64, a: usize, b: usize) -> C64 {
    let k = j.kinematic;
    let mut w = C64::new(-j.jac[(k + a, k + b)], 0.0);
    if b < k {
        w -= c.inv() * j.jac[(k + a, b)];
    }
    if a == b {
        w += c;
    }
    w
}

impl ComplexLu {
    fn factor(j: &StiffJacobian, c: C64) -> Self {
        let m = j.len - j.kinematic;
        match (m, j.kinematic) {
            (0, _) => ComplexLu::Scalar,
            (6, 4) => ComplexLu::Six(Matrix6::from_fn(|a, b| complement(j, c, a, b)).lu()),
            _ => ComplexLu::Dynamic(DMatrix::from_fn(m, m, |a, b| complement(j, c, a, b)).lu()),
        }
    }

    /// Solves `(c I - J) x = r` in place: the complement for the coupled velocities, then the
    /// positions `q = (r_q + v) / c`, the quadratures `(r + quad x) / c` and the uncoupled
    /// components `r / c`.
    fn solve<const N: usize>(&self, j: &StiffJacobian, c: C64, r: &mut [C64; N]) {
        let (n, k) = (j.len, j.kinematic);
        let m = n - k;
        let idx = &j.idx;
        let ci = c.inv();
        let mut x = [C64::new(0.0, 0.0); MAX_STIFF];
        let mut rq = [C64::new(0.0, 0.0); MAX_STIFF];
        for b in 0..k {
            rq[b] = r[idx[b]];
        }
        for a in 0..m {
            let mut s = r[idx[k + a]];
            for b in 0..k {
                s += rq[b] * (ci * j.jac[(k + a, b)]);
            }
            x[k + a] = s;
        }
        match self {
            ComplexLu::Scalar => {}
            ComplexLu::Six(lu) => {
                let mut v = Vector6::from_fn(|a, _| x[k + a]);
                lu.solve_mut(&mut v);
                for a in 0..6 {
                    x[k + a] = v[a];
                }
            }
            ComplexLu::Dynamic(lu) => {
                let mut v = DVector::from_fn(m, |a, _| x[k + a]);
                lu.solve_mut(&mut v);
                for a in 0..m {
                    x[k + a] = v[a];
                }
            }
        }
        for b in 0..k {
            x[b] = (rq[b] + x[k + b]) * ci;
        }
        // Every component `r / c` (the uncoupled ones' answer), then the quadratures and the
        // coupled components over it.
        let r0 = *r;
        for v in r.iter_mut() {
            *v *= ci;
        }
        for a in 0..j.quad_len {
            let mut s = r0[j.quad_idx[a]];
            for b in 0..n {
                s += x[b] * j.quad[(a, b)];
            }
            r[j.quad_idx[a]] = s * ci;
        }
        for a in 0..n {
            r[idx[a]] = x[a];
        }
    }
}

/// The RADAU5 stepper: the derivative at the step start, the last step's stages for the
/// Newton iteration's starting values, the Newton iteration's memory, controller memory and
/// work counters.
#[derive(Debug, Clone)]
pub struct Radau5<const N: usize> {
    core: StepCore<N>,
    f0: [f64; N],
    /// The last accepted step's stages (relative to its start) and size, for the next
    /// Newton iteration's starting values; `None` after a restart.
    last: Option<([[f64; N]; 3], f64)>,
    /// The Newton iteration's contraction estimate `theta / (1 - theta)`, carried over.
    faccon: f64,
    /// A cap on the step from the last Newton failure, grown by [`NEWTON_CAP_GROWTH`] at
    /// every step without one; none after a restart or on fixed steps.
    h_newton: f64,
    /// Newton iterations, over every attempt.
    newton_iterations: u64,
}

/// How much the Newton cap on the step grows at each step whose iteration converged.
const NEWTON_CAP_GROWTH: f64 = 1.05;

impl<const N: usize> Radau5<N> {
    /// A stepper with the given control settings and no step-size history.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self {
            core: StepCore::new(ctl, 5),
            f0: [0.0; N],
            last: None,
            faccon: 1.0,
            h_newton: f64::INFINITY,
            newton_iterations: 0,
        }
    }

    /// Newton iterations so far, over every attempt (each evaluates the model three times).
    pub fn newton_iterations(&self) -> u64 {
        self.newton_iterations
    }
}

/// The Newton iteration's starting stages for a step of size `h`: the last step's collocation
/// polynomial (through its start, its three stages), extrapolated (RADAU5's), or zero.
fn starting_stages<const N: usize>(last: Option<&([[f64; N]; 3], f64)>, h: f64) -> [[f64; N]; 3] {
    let mut z = [[0.0; N]; 3];
    let Some((zl, hl)) = last else { return z };
    let c3q = h / hl;
    let cq = [C1 * c3q, C2 * c3q, c3q];
    for i in 0..N {
        let (z1, z2, z3) = (zl[0][i], zl[1][i], zl[2][i]);
        let ak1 = (z2 - z3) / C2M1;
        let ak = (z1 - z2) / C1MC2;
        let acont3 = (ak - z1 / C1) / C2;
        let ak2 = (ak - ak1) / C1M1;
        let ak3 = ak2 - acont3;
        for s in 0..3 {
            let q = cq[s];
            z[s][i] = q * (ak1 + (q - C2M1) * (ak2 + (q - C1M1) * ak3));
        }
    }
    z
}

/// `m v` for each component, a 3x3 matrix over the three stages.
#[inline(always)]
fn stage_mix<const N: usize>(m: &[[f64; 3]; 3], v: &[[f64; N]; 3]) -> [[f64; N]; 3] {
    let mut out = [[0.0; N]; 3];
    for a in 0..3 {
        for i in 0..N {
            out[a][i] = m[a][0] * v[0][i] + m[a][1] * v[1][i] + m[a][2] * v[2][i];
        }
    }
    out
}

/// One attempt's outcome.
enum Attempt<const N: usize> {
    /// The Newton iteration converged: the stages and the scaled error estimate.
    Converged([[f64; N]; 3], f64),
    /// It diverged or would not converge in [`NIT`] iterations: the factor to cut the step by.
    Failed(f64),
}

impl<const N: usize> Radau5<N> {
    /// One attempt of size `h` from `(t, y)`: the simplified Newton iteration on the
    /// transformed stages `W = T^-1 Z`, with `(gamma/h - J)` and `((alpha + i beta)/h - J)`
    /// factored once, then the error estimate (RADAU5's ESTRAD: the embedded difference
    /// passed through `(gamma/h - J)^-1`, and once more after the model when `refine`).
    #[allow(clippy::too_many_arguments)]
    fn attempt<S: OdeSystem<N>>(
        core: &mut StepCore<N>,
        lu: &mut Lu,
        faccon: &mut f64,
        newton: &mut u64,
        start: [[f64; N]; 3],
        f0: &[f64; N],
        sys: &S,
        t: f64,
        y: &[f64; N],
        h: f64,
        refine: bool,
    ) -> Attempt<N> {
        let fac1 = GAMMA / h;
        let c2 = C64::new(ALPHA / h, BETA / h);
        // The real shift through the Rosenbrock factors: (fac1 - J) x = r is
        // (I - J / fac1) x = r / fac1.
        let hg = 1.0 / fac1;
        core.stats.factorizations += 2;
        if !lu.factor(hg) {
            return Attempt::Failed(0.5);
        }
        let e2 = ComplexLu::factor(&lu.j, c2);
        let scal: [f64; N] =
            std::array::from_fn(|i| core.step_atol[i] + core.ctl.rtol * y[i].abs());
        let mut z = start;
        let mut w = stage_mix(&TI, &z);
        let rtol = core.ctl.rtol;
        // RADAU5's stopping tolerance of the iteration, against the error scale; on fixed
        // steps (no error control) the iteration runs down to rounding instead (at most
        // `eps / rtol` in that scale), so that the solution is the collocation method's.
        let (fnewt, nit) = if core.ctl.fixed_step.is_some() {
            (
                (10.0 * f64::EPSILON / rtol).max(1e3 * f64::EPSILON),
                4 * NIT,
            )
        } else {
            (
                (10.0 * f64::EPSILON / rtol).max(0.03_f64.min(rtol.sqrt())),
                NIT,
            )
        };
        *faccon = faccon.max(f64::EPSILON).powf(0.8);
        let mut dynold = 0.0;
        let mut converged = false;
        for it in 0..nit {
            *newton += 1;
            let mut f = [[0.0; N]; 3];
            for (s, cs) in [C1, C2, 1.0].into_iter().enumerate() {
                let ys: [f64; N] = std::array::from_fn(|i| y[i] + z[s][i]);
                sys.rhs(t + cs * h, &ys, &mut f[s]);
            }
            core.stats.rhs_evals += 3;
            let tf = stage_mix(&TI, &f);
            let mut r1 = [0.0; N];
            let mut r23 = [C64::new(0.0, 0.0); N];
            for i in 0..N {
                r1[i] = hg * (tf[0][i] - fac1 * w[0][i]);
                r23[i] = C64::new(
                    tf[1][i] - c2.re * w[1][i] + c2.im * w[2][i],
                    tf[2][i] - c2.im * w[1][i] - c2.re * w[2][i],
                );
            }
            lu.solve(&mut r1);
            e2.solve(&lu.j, c2, &mut r23);
            let mut sum = 0.0;
            for i in 0..N {
                for v in [r1[i], r23[i].re, r23[i].im] {
                    sum += (v / scal[i]) * (v / scal[i]);
                }
            }
            let dyno = (sum / (3 * N) as f64).sqrt();
            if !dyno.is_finite() {
                return Attempt::Failed(0.5);
            }
            if it >= 1 {
                let theta = dyno / dynold;
                if theta >= 0.99 {
                    return Attempt::Failed(0.5);
                }
                *faccon = theta / (1.0 - theta);
                let left = nit as i32 - 2 - it as i32;
                let dyth = *faccon * dyno * theta.powi(left) / fnewt;
                if dyth >= 1.0 {
                    // Would not converge in the iterations left: the step RADAU5 predicts.
                    let qnewt = dyth.clamp(1e-4, 20.0);
                    return Attempt::Failed(0.8 * qnewt.powf(-1.0 / (4.0 + left as f64)));
                }
            }
            dynold = dyno.max(f64::EPSILON);
            for i in 0..N {
                w[0][i] += r1[i];
                w[1][i] += r23[i].re;
                w[2][i] += r23[i].im;
            }
            z = stage_mix(&T, &w);
            if *faccon * dyno <= fnewt {
                converged = true;
                break;
            }
        }
        if !converged {
            return Attempt::Failed(0.5);
        }
        // The error estimate: (fac1 - J)^-1 (f0 + sum_i dd_i Z_i / h).
        let f2: [f64; N] =
            std::array::from_fn(|i| (DD1 * z[0][i] + DD2 * z[1][i] + DD3 * z[2][i]) / h);
        let mut cont: [f64; N] = std::array::from_fn(|i| hg * (f2[i] + f0[i]));
        lu.solve(&mut cont);
        let norm = |cont: &[f64; N]| {
            let mut e = 0.0;
            for i in 0..N {
                let y1 = y[i] + z[2][i];
                let sc = core.step_atol[i] + rtol * y[i].abs().max(y1.abs());
                e += (cont[i] / sc) * (cont[i] / sc);
            }
            (e / N as f64).sqrt()
        };
        let mut err = norm(&cont);
        if err >= 1.0 && refine {
            // Once more through the model, on the first step and after a rejection.
            let yc: [f64; N] = std::array::from_fn(|i| y[i] + cont[i]);
            let mut fc = [0.0; N];
            sys.rhs(t, &yc, &mut fc);
            core.stats.rhs_evals += 1;
            cont = std::array::from_fn(|i| hg * (fc[i] + f2[i]));
            lu.solve(&mut cont);
            err = norm(&cont);
        }
        Attempt::Converged(z, err)
    }
}

impl<const N: usize> Stepper<N> for Radau5<N> {
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        sys.rhs(t, y, &mut self.f0);
        self.core.restart(sys, y, &self.f0);
        // A new mode: no collocation polynomial to start from, and no Newton cap from the
        // old one (the driver caps the first step of a mode itself).
        self.last = None;
        self.h_newton = f64::INFINITY;
    }

    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        let mut lu = Lu::identity();
        lu.j = sys
            .stiff_jacobian(t, y)
            .unwrap_or_else(|| StiffJacobian::over(&[]));
        self.core.stats.jacobians += 1;
        self.core.begin_step(sys, t, y);
        let f0 = self.f0;
        let last = self.last;
        let (mut faccon, mut newton) = (self.faccon, 0);
        let mut h_newton = self.h_newton;
        let mut failed = false;
        let mut tried = false;
        let fixed = self.core.ctl.fixed_step.is_some();
        let h_cap = if fixed { h_cap } else { h_cap.min(h_newton) };
        let (z, h) = self.core.control(&LAW, t, h_cap, |core, h| {
            let start = starting_stages(last.as_ref(), h);
            // RADAU5 refines the error estimate on the first step and after a rejection.
            let refine = last.is_none() || tried;
            tried = true;
            match Self::attempt(
                core,
                &mut lu,
                &mut faccon,
                &mut newton,
                start,
                &f0,
                sys,
                t,
                y,
                h,
                refine,
            ) {
                Attempt::Converged(z, err) => (z, err),
                Attempt::Failed(cut) => {
                    failed = true;
                    faccon = 1.0;
                    h_newton = h * cut;
                    // The step times `cut` (LAW: h / (err^(1/4) / 0.9)); on a fixed step, which
                    // control() accepts whatever a finite error, a non-finite one, which it
                    // refuses (NonFiniteState).
                    let err = if fixed { f64::NAN } else { (0.9 / cut).powi(4) };
                    ([[f64::NAN; N]; 3], err)
                }
            }
        })?;
        self.faccon = faccon;
        self.newton_iterations += newton;
        self.h_newton = if failed {
            h_newton
        } else {
            h_newton * NEWTON_CAP_GROWTH
        };
        self.last = Some((z, h));
        let y1: [f64; N] = std::array::from_fn(|i| y[i] + z[2][i]);
        let mut f1 = [0.0; N];
        sys.rhs(t + h, &y1, &mut f1);
        self.core.stats.rhs_evals += 1;
        self.f0 = f1;
        Ok(self.core.hermite_end(t, h, y, y1, &f0, &f1))
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
    use crate::ode::{integrate, NoObserver};

    /// `y' = -1e6 (y - cos t)` with no Jacobian given: the simplified Newton iteration is then
    /// a fixed-point one, which diverges once `h 1e6` passes about 1.
    struct Relax;
    impl OdeSystem<1> for Relax {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
            dy[0] = -1e6 * (y[0] - t.cos());
        }
    }

    /// A Newton iteration that fails on a fixed step is an error, never a state of NaN taken
    /// as the step's end; with error control the step shrinks until it converges, and the
    /// solution follows `cos t`.
    #[test]
    fn a_newton_failure_on_a_fixed_step_is_an_error() {
        let ctl = |fixed_step| StepControl {
            rtol: 1e-6,
            atol: [1e-9],
            h_min: 1e-14,
            max_attempts: 1_000_000,
            fixed_step,
        };
        let (mut t, mut y) = (0.0, [1.0]);
        let e = integrate(
            &Relax,
            &mut Radau5::new(ctl(Some(1e-3))),
            &mut t,
            &mut y,
            0.01,
            &mut NoObserver,
        )
        .unwrap_err();
        assert!(matches!(e, SolveError::NonFiniteState { .. }), "{e:?}");
        let (mut t, mut y) = (0.0, [1.0]);
        let mut st = Radau5::new(ctl(None));
        integrate(&Relax, &mut st, &mut t, &mut y, 0.01, &mut NoObserver).unwrap();
        assert!((y[0] - 0.01_f64.cos()).abs() < 1e-6, "{}", y[0]);
        assert!(st.stats().rejected > 0 && st.newton_iterations() > 0);
    }

    /// The two shifted solves against the full 15 x 15 system `c I - J` (coupled block with
    /// four kinematic rows, quadrature rows, uncoupled components), for a real shift through
    /// the Rosenbrock factors and for a complex one.
    #[test]
    fn the_shifted_solves_solve_the_full_system() {
        const N: usize = 15;
        let idx = [0, 1, 3, 4, 6, 7, 8, 9, 10, 11];
        let mut j = StiffJacobian::over(&idx);
        j.kinematic = 4;
        let mut seed = 12345_u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for a in 0..10 {
            for b in 0..10 {
                j.jac[(a, b)] = if a < 4 {
                    if b == 4 + a {
                        1.0
                    } else {
                        0.0
                    }
                } else {
                    1e3 * rnd()
                };
            }
        }
        // Two of the fifteen components are in neither set: `c I` there.
        j.quad_len = 3;
        j.quad_idx[..3].copy_from_slice(&[2, 12, 13]);
        for a in 0..3 {
            for b in 0..10 {
                j.quad[(a, b)] = rnd();
            }
        }
        let mut full = DMatrix::<C64>::zeros(N, N);
        for a in 0..10 {
            for b in 0..10 {
                full[(idx[a], idx[b])] = C64::new(j.jac[(a, b)], 0.0);
            }
        }
        for a in 0..3 {
            for b in 0..10 {
                full[(j.quad_idx[a], idx[b])] = C64::new(j.quad[(a, b)], 0.0);
            }
        }
        let residual = |c: C64, x: &[C64; N], r: &[C64; N]| {
            let xv = DVector::from_column_slice(x);
            let back = DMatrix::<C64>::identity(N, N) * c * &xv - &full * &xv;
            (0..N).map(|i| (back[i] - r[i]).norm()).fold(0.0, f64::max)
        };
        for c in [
            C64::new(3.7e3, 0.0),
            C64::new(2.6e3, 3.05e3),
            C64::new(40.0, -7.0),
        ] {
            let r: [C64; N] = std::array::from_fn(|_| C64::new(rnd(), rnd()));
            let mut x = r;
            ComplexLu::factor(&j, c).solve(&j, c, &mut x);
            assert!(residual(c, &x, &r) < 1e-9, "complex shift {c}");
        }
        // The real shift: (c - J) x = r as (I - J / c) x = r / c.
        let c = 3.7e3;
        let mut lu = Lu::identity();
        lu.j = j;
        assert!(lu.factor(1.0 / c));
        let r: [f64; N] = std::array::from_fn(|_| rnd());
        let mut x: [f64; N] = std::array::from_fn(|i| r[i] / c);
        lu.solve(&mut x);
        let (xc, rc) = (x.map(|v| C64::new(v, 0.0)), r.map(|v| C64::new(v, 0.0)));
        assert!(residual(C64::new(c, 0.0), &xc, &rc) < 1e-9, "real shift");
    }
}
