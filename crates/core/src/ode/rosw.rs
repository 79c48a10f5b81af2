//! ROS34PW2: a linearly implicit Rosenbrock-W method, order 3 with an embedded order-2
//! estimate, 4 stages, L-stable and stiffly accurate, for systems whose stiffness sits in a
//! few components (here: the light race between two stiff Hertz contacts).
//!
//! Coefficients: J. Rang, L. Angermann, "New Rosenbrock W-methods of order 3 for partial
//! differential algebraic equations of index 1", BIT 45 (2005), Table 4.5 (ROS34PW2), in the
//! untransformed form of E. Hairer, G. Wanner, "Solving ODEs II", Sec. IV.7:
//!
//! `(I - h gamma J) k_i = h f(y0 + sum_j alpha_ij k_j) + h J sum_j gamma_ij k_j`,
//! `y1 = y0 + sum_i b_i k_i`.
//!
//! A W-method keeps its order for *any* matrix `J`; only stability needs `J` to hold the stiff
//! terms. So the system supplies a cheap analytic approximation restricted to a few
//! components ([`OdeSystem::stiff_jacobian`]), and the linear solves are of that size.
//! Dense output is the cubic Hermite interpolant of the step's ends (3rd order, matching the
//! method); the derivative at the end is evaluated once and reused as the next step's first
//! stage.

use super::control::{StepCore, StepLaw};
use super::step::{Dense, StepControl};
use super::stepper::Stepper;
use super::system::{OdeSystem, StiffJacobian, MAX_STIFF};
use crate::error::SolveError;
use nalgebra::{DMatrix, DVector, Dyn, Matrix6, LU};

const GAMMA: f64 = 4.358_665_215_084_590_0e-1;
const A21: f64 = 8.717_330_430_169_180_1e-1;
const A31: f64 = 8.445_706_001_536_942_3e-1;
const A32: f64 = -1.129_906_423_648_418_5e-1;
// a41 = a42 = 0, a43 = 1: the last stage is evaluated at y0 + k3.
const G21: f64 = -8.717_330_430_169_180_1e-1;
const G31: f64 = -9.033_805_701_304_408_2e-1;
const G32: f64 = 5.418_067_238_809_532_6e-2;
const G41: f64 = 2.421_238_070_609_534_6e-1;
const G42: f64 = -1.223_250_583_904_514_7;
const G43: f64 = 5.452_602_553_351_021_4e-1;
const B: [f64; 4] = [
    2.421_238_070_609_534_6e-1,
    -1.223_250_583_904_514_7,
    1.545_260_255_335_102_0,
    4.358_665_215_084_590_0e-1,
];
const BHAT: [f64; 4] = [
    3.781_090_314_581_936_9e-1,
    -9.604_229_221_242_317_8e-2,
    5.0e-1,
    2.179_332_607_542_295_0e-1,
];

/// `W = I - h gamma J` on the stiff components, LU-factored with partial pivoting. With `k`
/// kinematic components ([`StiffJacobian::kinematic`]: rows `q' = v`), `W`'s first `k` rows
/// read `q - hg v = r_q`, so `q = r_q + hg v` and only the Schur complement
/// `S = I - hg J_vv - hg^2 J_vq` over the other components is factored:
/// `S v = r_v + hg J_vq r_q` (10 components with 4 positions: a 6x6 factor, 4x fewer
/// operations than the 10x10 one). The model's 6x6 complement is factored in place in
/// nalgebra's fixed-size storage by a hand-written kernel ([`lu6`]): nalgebra's generic LU
/// costs 3 % more instructions on the 1 s drop at the ROS34PW2 setting of the time (94.4 M
/// against 91.7 M, callgrind). Unrolled column by column it took 4 % fewer of the drop's
/// instructions but more time
/// (docs/performance.md#two-remedies-and-an-unrolled-factorisation-that-did-not-work).
/// Other shapes (the stepper's tests) use nalgebra's LU in dynamic storage.
#[derive(Debug, Clone)]
pub(super) struct Lu {
    /// `J` itself, for the `J v` products of the stage right-hand sides (`len` 0: none).
    pub(super) j: StiffJacobian,
    /// The factors of `W` (no kinematic components) or of its Schur complement `S`.
    factors: Factors,
    /// `h gamma` of the factorisation.
    hg: f64,
}

/// The LU factors of the reduced matrix, by size. The fixed 6x6 variant is large on purpose:
/// boxing it would allocate at every factorisation, once per step.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Factors {
    /// No stiff components: `W` is the identity.
    Identity,
    /// The model's Schur complement (10 stiff components, 4 kinematic): the packed factors
    /// (unit lower below the diagonal, upper above, reciprocal pivots on it) and the row swaps.
    Six(Matrix6<f64>, [usize; 6]),
    /// Any other size.
    Dynamic(LU<f64, Dyn, Dyn>),
}

impl Lu {
    pub(super) fn identity() -> Self {
        Self {
            j: StiffJacobian::over(&[]),
            factors: Factors::Identity,
            hg: 0.0,
        }
    }

    /// Entry `(a, b)` of the reduced matrix: `I - hg J` on the non-kinematic block, minus
    /// `hg^2 J_vq` from eliminating the positions.
    #[inline(always)]
    fn reduced(&self, a: usize, b: usize) -> f64 {
        let (k, jac) = (self.j.kinematic, &self.j.jac);
        let mut w = -self.hg * jac[(k + a, k + b)];
        if b < k {
            w -= self.hg * self.hg * jac[(k + a, b)];
        }
        if a == b {
            w += 1.0;
        }
        w
    }

    /// Factors `I - hg J`; false if singular (the caller shrinks the step).
    pub(super) fn factor(&mut self, hg: f64) -> bool {
        let (n, k) = (self.j.len, self.j.kinematic);
        debug_assert!(2 * k <= n, "kinematic {k} of {n} components");
        debug_assert!(
            (0..k)
                .all(|a| (0..n).all(|b| self.j.jac[(a, b)] == if b == k + a { 1.0 } else { 0.0 })),
            "a kinematic row of the stiff Jacobian is not q' = v"
        );
        self.hg = hg;
        let m = n - k;
        let (factors, ok) = match m {
            0 => (Factors::Identity, true),
            // A non-finite factor is not caught here: it makes the attempt's error norm NaN,
            // and the step controller shrinks the step.
            6 if k == 4 => {
                // S = I - hg J_vv - hg^2 J_vq over the six non-kinematic components, built
                // block by block (the general `reduced` entry by entry costs 3x more).
                let jac = &self.j.jac;
                let hg2 = hg * hg;
                // Written in place: the factors are large enough that moving them costs.
                if !matches!(self.factors, Factors::Six(..)) {
                    self.factors = Factors::Six(Matrix6::zeros(), [0; 6]);
                }
                let Factors::Six(a, piv) = &mut self.factors else {
                    unreachable!("set just above")
                };
                // The same operations in the same order as `reduced`, so the same bits.
                for b in 0..6 {
                    for r in 0..6 {
                        a[(r, b)] = -hg * jac[(4 + r, 4 + b)];
                    }
                }
                for b in 0..4 {
                    for r in 0..6 {
                        a[(r, b)] -= hg2 * jac[(4 + r, b)];
                    }
                }
                for d in 0..6 {
                    a[(d, d)] += 1.0;
                }
                let (p, ok) = lu6(a);
                *piv = p;
                return ok;
            }
            _ => {
                let lu = DMatrix::from_fn(m, m, |a, b| self.reduced(a, b)).lu();
                let ok = lu.is_invertible();
                (Factors::Dynamic(lu), ok)
            }
        };
        self.factors = factors;
        ok
    }

    /// Solves `W x = v` in place (components outside the stiff set are untouched: W is the
    /// identity there).
    #[inline]
    pub(super) fn solve<const N: usize>(&self, v: &mut [f64; N]) {
        // The model's shape gets constant loop bounds (unrolled, no bounds checks): the
        // stepper spends most of its time in these loops.
        match (self.j.len, self.j.kinematic) {
            (0, _) => {}
            (MAX_STIFF, 4) => self.solve_n(v, MAX_STIFF, 4),
            (n, k) => self.solve_n(v, n, k),
        }
    }

    #[inline(always)]
    fn solve_n<const N: usize>(&self, v: &mut [f64; N], n: usize, k: usize) {
        let m = n - k;
        let idx = &self.j.idx;
        let mut rq = [0.0; MAX_STIFF];
        for c in 0..k {
            rq[c] = v[idx[c]];
        }
        // Right-hand side of the (reduced) system: r_v + hg J_vq r_q.
        let mut x = [0.0; MAX_STIFF];
        for a in 0..m {
            let mut s = 0.0;
            for c in 0..k {
                s += self.j.jac[(k + a, c)] * rq[c];
            }
            x[a] = v[idx[k + a]] + self.hg * s;
        }
        match &self.factors {
            Factors::Identity => {}
            Factors::Six(lu, piv) => solve6(lu, piv, &mut x),
            Factors::Dynamic(lu) => {
                let mut b = DVector::from_column_slice(&x[..m]);
                lu.solve_mut(&mut b);
                x[..m].copy_from_slice(b.as_slice());
            }
        }
        for a in 0..m {
            v[idx[k + a]] = x[a];
        }
        // The positions: q = r_q + hg v.
        for c in 0..k {
            v[idx[c]] = rq[c] + self.hg * x[c];
        }
        // The quadratures, below the coupled block: r_q + hg (quad x).
        for a in 0..self.j.quad_len {
            let mut s = 0.0;
            for b in 0..n {
                s += self.j.quad[(a, b)] * v[idx[b]];
            }
            v[self.j.quad_idx[a]] += self.hg * s;
        }
    }

    /// Adds `scale * J u` into `out`.
    #[inline]
    fn add_jv<const N: usize>(&self, scale: f64, u: &[f64; N], out: &mut [f64; N]) {
        match (self.j.len, self.j.kinematic) {
            (MAX_STIFF, 4) => self.add_jv_n(scale, u, out, MAX_STIFF, 4),
            (n, k) => self.add_jv_n(scale, u, out, n, k),
        }
    }

    #[inline(always)]
    fn add_jv_n<const N: usize>(
        &self,
        scale: f64,
        u: &[f64; N],
        out: &mut [f64; N],
        n: usize,
        k: usize,
    ) {
        let idx = &self.j.idx;
        let mut ug = [0.0; MAX_STIFF];
        for b in 0..n {
            ug[b] = u[idx[b]];
        }
        // Kinematic rows: (J u)_q = u_v.
        for a in 0..k {
            out[idx[a]] += scale * ug[k + a];
        }
        for a in k..n {
            let mut s = 0.0;
            for b in 0..n {
                s += self.j.jac[(a, b)] * ug[b];
            }
            out[idx[a]] += scale * s;
        }
        for a in 0..self.j.quad_len {
            let mut s = 0.0;
            for b in 0..n {
                s += self.j.quad[(a, b)] * ug[b];
            }
            out[self.j.quad_idx[a]] += scale * s;
        }
    }
}

/// LU factorisation with partial pivoting of a 6x6 matrix in place: the unit lower factor
/// below the diagonal, the upper above it, the reciprocals of the pivots on it; returns the
/// row swaps and whether no pivot was zero.
fn lu6(a: &mut Matrix6<f64>) -> ([usize; 6], bool) {
    let mut piv = [0; 6];
    for c in 0..6 {
        let mut p = c;
        for r in c + 1..6 {
            if a[(r, c)].abs() > a[(p, c)].abs() {
                p = r;
            }
        }
        piv[c] = p;
        if a[(p, c)] == 0.0 {
            return (piv, false);
        }
        a.swap_rows(c, p);
        let d = 1.0 / a[(c, c)];
        a[(c, c)] = d;
        for r in c + 1..6 {
            let mul = a[(r, c)] * d;
            a[(r, c)] = mul;
            if mul != 0.0 {
                for col in c + 1..6 {
                    a[(r, col)] -= mul * a[(c, col)];
                }
            }
        }
    }
    (piv, true)
}

/// Solves with [`lu6`]'s factors in place (the first six entries of `x`).
fn solve6(lu: &Matrix6<f64>, piv: &[usize; 6], x: &mut [f64; MAX_STIFF]) {
    for c in 0..6 {
        x.swap(c, piv[c]);
    }
    for c in 0..6 {
        let xc = x[c];
        for r in c + 1..6 {
            x[r] -= lu[(r, c)] * xc;
        }
    }
    for c in (0..6).rev() {
        let mut s = x[c];
        for col in c + 1..6 {
            s -= lu[(c, col)] * x[col];
        }
        x[c] = s * lu[(c, c)];
    }
}

/// The ROS34PW2 stepper: the derivative at the step start, the factored iteration matrix,
/// controller memory and work counters.
#[derive(Debug, Clone)]
pub struct Ros34pw2<const N: usize> {
    core: StepCore<N>,
    f0: [f64; N],
    lu: Lu,
}

/// The error estimate is O(h^3): exponent 1/3, safety 0.9, step ratio in [1/5, 6].
const LAW: StepLaw = StepLaw {
    safe: 0.9,
    expo: 1.0 / 3.0,
    beta: 0.0,
    fac_min: 0.2,
    fac_max: 6.0,
    predictive: false,
};

impl<const N: usize> Ros34pw2<N> {
    /// A stepper with the given control settings and no step-size history.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self {
            core: StepCore::new(ctl, 5),
            f0: [0.0; N],
            lu: Lu::identity(),
        }
    }

    /// One trial step of size `h` from `(t, y)` with derivative `f0` there and `lu` factored
    /// for it: the new state, the error norm.
    fn attempt<S: OdeSystem<N>>(
        core: &mut StepCore<N>,
        lu: &Lu,
        f0: &[f64; N],
        sys: &S,
        t: f64,
        y: &[f64; N],
        h: f64,
    ) -> ([f64; N], f64) {
        let mut k = [[0.0; N]; 4];
        // Stage 1.
        let mut r = [0.0; N];
        for i in 0..N {
            r[i] = h * f0[i];
        }
        lu.solve(&mut r);
        k[0] = r;
        // Stage 2.
        let mut yt = [0.0; N];
        for i in 0..N {
            yt[i] = y[i] + A21 * k[0][i];
        }
        let mut f = [0.0; N];
        sys.rhs(t + A21 * h, &yt, &mut f);
        let mut u = [0.0; N];
        for i in 0..N {
            r[i] = h * f[i];
            u[i] = G21 * k[0][i];
        }
        lu.add_jv(h, &u, &mut r);
        lu.solve(&mut r);
        k[1] = r;
        // Stage 3.
        for i in 0..N {
            yt[i] = y[i] + A31 * k[0][i] + A32 * k[1][i];
        }
        sys.rhs(t + (A31 + A32) * h, &yt, &mut f);
        for i in 0..N {
            r[i] = h * f[i];
            u[i] = G31 * k[0][i] + G32 * k[1][i];
        }
        lu.add_jv(h, &u, &mut r);
        lu.solve(&mut r);
        k[2] = r;
        // Stage 4 at y0 + k3.
        for i in 0..N {
            yt[i] = y[i] + k[2][i];
        }
        sys.rhs(t + h, &yt, &mut f);
        for i in 0..N {
            r[i] = h * f[i];
            u[i] = G41 * k[0][i] + G42 * k[1][i] + G43 * k[2][i];
        }
        lu.add_jv(h, &u, &mut r);
        lu.solve(&mut r);
        k[3] = r;
        core.stats.rhs_evals += 3;
        let mut y1 = [0.0; N];
        let mut e = [0.0; N];
        for i in 0..N {
            let mut s = y[i];
            for j in 0..4 {
                s += B[j] * k[j][i];
                e[i] += (B[j] - BHAT[j]) * k[j][i];
            }
            y1[i] = s;
        }
        // Shampine's filter (Hairer-Wanner IV.8, as in RADAU5): the raw difference of the two
        // solutions overstates the error of components that sit on a stiff slow manifold;
        // `W^-1` damps exactly those and leaves the non-stiff ones as they are.
        lu.solve(&mut e);
        let mut err = 0.0;
        let atol = core.step_atol;
        for i in 0..N {
            let sc = atol[i] + core.ctl.rtol * y[i].abs().max(y1[i].abs());
            err += (e[i] / sc) * (e[i] / sc);
        }
        (y1, (err / N as f64).sqrt())
    }
}

/// What differs between the Rosenbrock methods sharing [`rosenbrock_step`]: the step law, the
/// diagonal `gamma` of the matrix `I - h gamma J`, the attempt, whether the matrix holds the
/// quadrature rows, and the interpolant.
pub(super) struct Rosenbrock<'a, A> {
    /// The step-size law (orders, safety, growth limits).
    pub(super) law: &'a StepLaw,
    /// The method's diagonal coefficient.
    pub(super) gamma: f64,
    /// One attempt at a step of size `h`: `(core, lu, f0, sys, t, y, h)` to the new state and
    /// its scaled error (a method's `attempt`, a function item, so it inlines).
    pub(super) attempt: A,
    /// Whether the matrix holds the Jacobian's quadrature rows
    /// ([`StiffJacobian::quad`]). A Rosenbrock method needs them for its order on the
    /// accumulators; a W-method does not, and leaves them out.
    pub(super) quadratures: bool,
    /// Whether the attempt leaves its own dense-output coefficients `K1, K2, K3` in rows 5-7
    /// of `core.dense.r`, for `y(th) = (1 - th) y0 + th (y1 + (1 - th) (K1 + th (K2 + th K3)))`
    /// (Rodas5P's 4th-order interpolant); otherwise the step's ends give the cubic Hermite one.
    pub(super) own_dense: bool,
}

/// One accepted step of a Rosenbrock method on the stiff Jacobian (ROS34PW2, RODAS4, Rodas5P): the
/// Jacobian once per step, a factorisation per attempt, the step control, then the cubic
/// Hermite dense output in DOPRI5's nested form with the 4th coefficient zero, written in
/// place (row 4 stays zero from `StepCore::new`, rows 5-7 unused with `terms` 5), or the
/// method's own interpolant ([`Rosenbrock::own_dense`]). `f0` is
/// the derivative at the step's start, and becomes the one at its end.
#[allow(clippy::too_many_arguments)]
pub(super) fn rosenbrock_step<'c, const N: usize, S, A>(
    core: &'c mut StepCore<N>,
    lu: &mut Lu,
    f0: &mut [f64; N],
    method: &Rosenbrock<'_, A>,
    sys: &S,
    t: f64,
    y: &[f64; N],
    h_cap: f64,
) -> Result<&'c Dense<N>, SolveError>
where
    S: OdeSystem<N>,
    A: Fn(&mut StepCore<N>, &Lu, &[f64; N], &S, f64, &[f64; N], f64) -> ([f64; N], f64),
{
    sys.fill_stiff_jacobian(t, y, &mut lu.j);
    if !method.quadratures {
        lu.j.quad_len = 0;
    }
    core.stats.jacobians += 1;
    core.begin_step(sys, t, y);
    let start = *f0;
    let (y1, h) = core.control(method.law, t, h_cap, |core, h| {
        core.stats.factorizations += 1;
        if lu.factor(h * method.gamma) {
            (method.attempt)(core, lu, &start, sys, t, y, h)
        } else {
            ([f64::NAN; N], f64::NAN)
        }
    })?;
    let mut f1 = [0.0; N];
    sys.rhs(t + h, &y1, &mut f1);
    core.stats.rhs_evals += 1;
    *f0 = f1;
    if !method.own_dense {
        return Ok(core.hermite_end(t, h, y, y1, &start, &f1));
    }
    let d = &mut core.dense;
    let r = &mut d.r;
    // In the nested form: r2 = K1, r3 = K2 + K3, r4 = -K3 (rows 5-7 hold K1..K3, from the
    // accepted attempt, the last one).
    for i in 0..N {
        let (k1, k2, k3) = (r[5][i], r[6][i], r[7][i]);
        r[0][i] = y[i];
        r[1][i] = y1[i] - y[i];
        r[2][i] = k1;
        r[3][i] = k2 + k3;
        r[4][i] = -k3;
    }
    (d.t0, d.h, d.t_end, d.terms, d.y1) = (t, h, t + h, 5, y1);
    core.stats.steps += 1;
    Ok(&core.dense)
}

impl<const N: usize> Stepper<N> for Ros34pw2<N> {
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
            // Measured with them on 2026-11-24: the drops at `draft`, then ROS34PW2, took
            // 0.1-0.5 % more RHS evaluations, so the W-method keeps its matrix without them.
            quadratures: false,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::{integrate, NoObserver, StiffJacobian};

    /// A stiff linear system: a slow oscillator (omega 1) coupled to a fast, damped one
    /// (eigenvalues about -1e4 +- 4e4 i), exact Jacobian supplied or not.
    struct Stiff {
        with_jac: bool,
    }
    const M: [[f64; 4]; 4] = [
        [0.0, 1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.5, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [1.0e8, 0.0, -1.7e9, -2.0e4],
    ];
    impl OdeSystem<4> for Stiff {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, _t: f64, y: &[f64; 4], dy: &mut [f64; 4]) {
            for i in 0..4 {
                dy[i] = (0..4).map(|j| M[i][j] * y[j]).sum();
            }
        }
        fn stiff_jacobian(&self, _t: f64, _y: &[f64; 4]) -> Option<StiffJacobian> {
            self.with_jac.then(|| {
                let mut s = StiffJacobian::over(&[0, 1, 2, 3]);
                for i in 0..4 {
                    for j in 0..4 {
                        s.jac[(i, j)] = M[i][j];
                    }
                }
                s
            })
        }
    }

    fn ctl<const N: usize>(rtol: f64, fixed: Option<f64>) -> StepControl<N> {
        StepControl {
            rtol,
            atol: [rtol; N],
            h_min: 1e-14,
            max_attempts: 10_000_000,
            fixed_step: fixed,
        }
    }

    /// The Schur path (kinematic rows eliminated) solves the same `W x = v` as the full
    /// factorisation, and its `J u` product is the full one.
    #[test]
    fn kinematic_elimination_solves_the_full_system() {
        // A deterministic pseudo-random Jacobian with the model's layout: 4 positions whose
        // rows are q' = v, then 4 velocities and 2 spins with dense rows.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        const N: usize = 12;
        let idx = [0, 1, 2, 3, 4, 5, 6, 7, 9, 11];
        let mut full = StiffJacobian::over(&idx);
        for a in 0..4 {
            full.jac[(a, 4 + a)] = 1.0;
        }
        for a in 4..MAX_STIFF {
            for b in 0..MAX_STIFF {
                // Stiffness-like entries (1e8) on the positions, damping-like (1e4) on the rest.
                full.jac[(a, b)] = rnd() * if b < 4 { 1e8 } else { 1e4 };
            }
        }
        let mut schur = full;
        schur.kinematic = 4;
        // The full factor is 10x10 (dynamic storage), the Schur one 6x6 (fixed).
        let v: [f64; N] = std::array::from_fn(|_| rnd());
        for hg in [1e-6, 1e-4, 1e-2] {
            let (mut a, mut b) = (Lu::identity(), Lu::identity());
            a.j = full;
            b.j = schur;
            assert!(a.factor(hg) && b.factor(hg));
            let (mut xa, mut xb) = (v, v);
            a.solve(&mut xa);
            b.solve(&mut xb);
            // Residual of W x = v for the Schur solution, in the full matrix.
            let mut wx = xb;
            let mut jx = [0.0; N];
            a.add_jv(1.0, &xb, &mut jx);
            for i in 0..N {
                wx[i] -= hg * jx[i];
            }
            for i in 0..N {
                let scale = xa[i].abs().max(1e-300);
                assert!(
                    (xa[i] - xb[i]).abs() <= 1e-9 * scale + 1e-12,
                    "hg {hg}: component {i}: full {} schur {}",
                    xa[i],
                    xb[i]
                );
                assert!(
                    (wx[i] - v[i]).abs() <= 1e-8,
                    "hg {hg}: residual {i}: {}",
                    wx[i] - v[i]
                );
            }
            let (mut ja, mut jb) = ([0.0; N], [0.0; N]);
            a.add_jv(0.5, &v, &mut ja);
            b.add_jv(0.5, &v, &mut jb);
            assert_eq!(ja, jb);
        }
    }

    #[test]
    fn stiff_mode_does_not_bound_the_step_and_the_slow_motion_is_right() {
        let run = |with_jac: bool| {
            let mut st = Ros34pw2::new(ctl::<4>(1e-6, None));
            let (mut t, mut y) = (0.0, [1.0, 0.0, 0.0, 0.0]);
            integrate(
                &Stiff { with_jac },
                &mut st,
                &mut t,
                &mut y,
                10.0,
                &mut NoObserver,
            )
            .unwrap();
            (y, st.stats())
        };
        let (y_imp, s_imp) = run(true);
        let (y_exp, s_exp) = run(false);
        // Without the matrix the method is explicit: the fast mode (|lambda| ~ 4e4) bounds
        // the step to ~1e-4, so 10 s take ~1e5 steps; with it, the slow mode sets the step.
        assert!(s_exp.steps > 20 * s_imp.steps, "{s_exp:?} vs {s_imp:?}");
        for i in 0..2 {
            assert!((y_imp[i] - y_exp[i]).abs() < 1e-4, "{y_imp:?} vs {y_exp:?}");
        }
    }
}
