//! BDF: the backward differentiation formulas of orders 1 to 5 with variable order and
//! quasi-constant step size, on the stiff Jacobian with a Newton iteration.
//!
//! The scheme is Shampine and Reichelt's (`ode15s`; L. F. Shampine, M. W. Reichelt, "The
//! MATLAB ODE Suite", SIAM J. Sci. Comput. 18, 1997), by default without its NDF
//! modification (which `ode15s` makes by default and SciPy's `BDF` always: [`Formula::Ndf`],
//! below); the formulas and their stability are in E. Hairer, G. Wanner, "Solving ODEs II",
//! Sec. III.1 and V.1. The solution is carried as the backward differences
//! `D_j = nabla^j y_n` of the last `k + 1` solution values at an equal spacing `h`; a step of
//! another size first re-interpolates them to the new spacing. A step of order `k` solves
//!
//! `y_{n+1} - c f(y_{n+1}) = y_pred - psi`, `c = h / alpha_k`,
//!
//! with `y_pred = sum_{j<=k} D_j`, `psi = sum_{j=1..k} gamma_j D_j / alpha_k`,
//! `gamma_k = sum_{j=1..k} 1/j` and `alpha_k = (1 - kappa_k) gamma_k` (`gamma_k` for the BDF,
//! whose `kappa_k` are zero), by Newton's iteration on `I - c J` from `y_pred`. Its local
//! error estimate is `C_k (y_{n+1} - y_pred)`, `C_k = kappa_k gamma_k + 1 / (k + 1)`
//! (`1 / (k + 1)` for the BDF). After `k + 1` steps at one size, the next size and order come
//! from the estimates at orders `k - 1`, `k` and `k + 1`.
//!
//! **The Jacobian at every step.** SciPy and CVODE keep a Jacobian over many steps. On the
//! drop model that fails: rolling in the race, the contact's and the support's stiffness
//! turn with the contact angle, and the light race makes them large in `I - c J`; with the
//! Jacobian of the step before, the iteration diverged on about half of the BDF's steps of
//! the 1 s pendulum drop (2 204 failures in 4 146 steps, in RODAS4 then BDF with the BDF at
//! the stepper's own tolerance; each failure then paid a new Jacobian and the iterations
//! lost). So each attempt takes the Jacobian at its prediction `y_pred` (the model
//! evaluation there serves the iteration's first right-hand side too) and factors `I - c J`.
//! Re-measured at order 4 (model version 13), a Jacobian kept until the iteration fails took
//! the pendulum drop's RHS evaluations from 18 029 to 27 878: the kept one's iteration does
//! not contract in the rolling
//! (docs/performance.md#two-remedies-and-an-unrolled-factorisation-that-did-not-work).
//!
//! **One iteration where one is enough.** With the exact Jacobian at the starting point,
//! Newton's iteration converges quadratically: the correction after the first one is about
//! `K |dy_1|^2`. The constant `K` is measured on every attempt that iterates twice; while a
//! measurement at most [`RECHECK_STEPS`] steps old, made since the last full restart (in a
//! drop: in the same mode; a restart that keeps the history keeps it too), predicts the
//! second correction below the iteration's tolerance, the first iteration ends it. On the
//! pendulum drop the second correction is some 1e-4 of the first, far below the tolerance.
//!
//! **The NDF option.** [`Formula::Ndf`] gives Klopfenstein's numerical differentiation
//! formulas with Shampine and Reichelt's `kappa_k` (`ode15s`'s default, and SciPy's `BDF`'s
//! only formulas): the formula of order `k` is
//! `sum_{j=1..k} nabla^j y_{n+1} / j - kappa_k gamma_k nabla^{k+1} y_{n+1} = h f(y_{n+1})`,
//! the BDF's with one more term, whence `alpha_k` and `C_k` above. At orders 1 to 4 the error
//! constant `C_k` is smaller than the BDF's `1 / (k + 1)` (by 37 %, 50 %, 60 % and 43 %), so
//! a step of the same estimated error is longer (Shampine and Reichelt: 26 % at orders 1 to 3,
//! 12 % at order 4). Orders 1 and 2 stay A-stable; orders 3 and 4 pay with a smaller
//! stability angle (80 degrees against 86, 66 against 73); order 5 is the BDF. The plain BDF
//! ([`Formula::Bdf`]) is the default.
//!
//! **The highest order.** [`Bdf::with_max_order`] caps the order selection (5 by default
//! here; the drop takes `solver.bdf_max_order`, 4 by default). Orders 3 to 5 are not
//! A-stable: each is unstable on a bounded region of the left half-plane beside the imaginary
//! axis, so a lightly damped mode whose `h lambda` falls there grows. Rolling in the race,
//! the drop model's Jacobian has such modes at about 0.3, 1.9 and 15 kHz (damping ratios
//! 0.03, 0.30 and 0.20): order 5 is unstable on the 1.9 kHz mode from `h |lambda| = 1.05` and
//! on the 15 kHz mode up to `h |lambda| = 7.66`, which leaves it a window of some 4 us of
//! step sizes, while order 4 is stable on the 1.9 kHz mode at any step, on the 15 kHz mode
//! above `h |lambda| = 3.2` and on the 0.3 kHz mode below 0.65: from 35 to 340 us. (Those
//! figures are at 0.51 s; the modes move with the rocking, and where the 1.9 kHz mode passes
//! order 4's stability angle of 73.35 degrees, order 4 too is unstable on it for steps of
//! about 130 to 172 us.)
//!
//! What it costs: after every restart it starts again at order 1 from a short step, so a
//! drop with many mode switches takes many low-order steps (see [`super::Rodas4Bdf`], which
//! leaves those to RODAS4), and a BDF of order 3 or more is not A-stable. Its interpolant is
//! the polynomial through the last `k + 1` solution values (the drop's events are located on
//! it).

use super::control::StepCore;
use super::rosw::Lu;
use super::step::{Dense, StepControl, BACKWARD};
use super::stepper::Stepper;
use super::system::OdeSystem;
use crate::error::SolveError;

/// Highest order.
pub(super) const MAX_ORDER: usize = 5;
/// Most Newton iterations per attempt.
const NEWTON_MAXITER: usize = 4;
/// Smallest and largest step ratios.
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;
/// A Newton correction at or below `ROUNDING / rtol` in the error norm is at the rounding
/// level of the state (whose weights are about `rtol |y|`).
const ROUNDING: f64 = 10.0 * f64::EPSILON;
/// How many accepted steps a measured Newton constant `K` may serve before an attempt
/// iterates twice again to measure it anew.
const RECHECK_STEPS: u64 = 10;

/// `gamma_k = sum_{j=1..k} 1/j`, `k = 0..=MAX_ORDER + 1`.
const fn gammas() -> [f64; MAX_ORDER + 2] {
    let mut g = [0.0; MAX_ORDER + 2];
    let mut k = 1;
    while k < MAX_ORDER + 2 {
        g[k] = g[k - 1] + 1.0 / k as f64;
        k += 1;
    }
    g
}
const GAMMA: [f64; MAX_ORDER + 2] = gammas();

/// Whether two states are equal bit for bit (`-0.0` is not `0.0`, a NaN equals itself): the
/// test a history kept across a restart must pass.
pub(super) fn same_bits<const N: usize>(a: &[f64; N], b: &[f64; N]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The formulas a [`Bdf`] stepper steps with (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Formula {
    /// The backward differentiation formulas.
    Bdf,
    /// The numerical differentiation formulas of Klopfenstein, with Shampine and Reichelt's
    /// `kappa_k`: -0.1850, -1/9, -0.0823, -0.0415 and 0 at orders 1 to 5.
    Ndf,
}

/// Shampine and Reichelt's `kappa_k` of the NDF of order `k` (`k = 0..=MAX_ORDER`; order 5
/// is the BDF's, and order 0 is not a formula).
const NDF_KAPPA: [f64; MAX_ORDER + 1] = [0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0];

impl Formula {
    /// `kappa_k` for `k = 0..=MAX_ORDER`: zero for the BDF.
    fn kappa(self) -> [f64; MAX_ORDER + 1] {
        match self {
            Formula::Bdf => [0.0; MAX_ORDER + 1],
            Formula::Ndf => NDF_KAPPA,
        }
    }
}

/// Backward differences: rows `0..=MAX_ORDER + 2` (the last two hold the estimates of the
/// next higher differences that the order selection reads).
type Diffs<const N: usize> = [[f64; N]; MAX_ORDER + 3];

/// The matrix `R(k, factor)` of the re-interpolation of the differences to a new spacing
/// (Shampine and Reichelt, eq. 2.5): row 0 ones, then the cumulative products of
/// `(i - 1 - factor j) / i`; zero outside rows and columns `0..=order`. A `const fn`, so that
/// [`U_TABLE`] is computed by the compiler, with the same IEEE operations as at run time.
const fn interp_matrix(order: usize, factor: f64) -> [[f64; MAX_ORDER + 1]; MAX_ORDER + 1] {
    const INV: [f64; MAX_ORDER + 1] = [0.0, 1.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 4.0, 1.0 / 5.0];
    let mut m = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    let mut j = 0;
    while j <= order {
        m[0][j] = 1.0;
        j += 1;
    }
    let mut i = 1;
    while i <= order {
        let mut j = 1;
        while j <= order {
            m[i][j] = m[i - 1][j] * ((i as f64 - 1.0 - factor * j as f64) * INV[i]);
            j += 1;
        }
        i += 1;
    }
    m
}

/// `U(k) = R(k, 1)` for every order `k`, computed once. Upper triangular: below the diagonal,
/// row `j + 1` of column `j` takes the factor `(j - j) / (j + 1) = 0`, and the rows under it
/// are its multiples.
const U_TABLE: [[[f64; MAX_ORDER + 1]; MAX_ORDER + 1]; MAX_ORDER + 1] = {
    let mut t = [[[0.0; MAX_ORDER + 1]; MAX_ORDER + 1]; MAX_ORDER + 1];
    let mut k = 0;
    while k <= MAX_ORDER {
        t[k] = interp_matrix(k, 1.0);
        k += 1;
    }
    t
};

/// Re-interpolates the differences of order `order` from spacing `h` to `factor h`:
/// `D <- (R U)^T D` over rows `0..=order`, with `U = R(order, 1)`. Exact for a solution that
/// is a polynomial of degree `order`. The rows above `order` are left as they are.
///
/// `U` comes from [`U_TABLE`], and `R U` leaves out `U`'s zeros below its diagonal. For a
/// finite `factor` (every caller's, in `(0, MAX_FACTOR]`), so that `R` is finite, that
/// changes no bit: each sum starts at `+0.0` and never holds `-0.0` (round to nearest gives a
/// cancellation `+0.0`), so adding a product of `±0.0` to it would leave it as it is. Both
/// together took this function's instructions on the 1 s pendulum drop from 7.73 M to 3.05 M
/// (callgrind).
fn change_spacing<const N: usize>(d: &mut Diffs<N>, order: usize, factor: f64) {
    let n = order + 1;
    let r = interp_matrix(order, factor);
    let u = &U_TABLE[order];
    let mut ru = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
    for i in 0..n {
        for k in 0..n {
            let rik = r[i][k];
            for j in k..n {
                ru[i][j] += rik * u[k][j];
            }
        }
    }
    let old = [d[0], d[1], d[2], d[3], d[4], d[5]];
    for j in 0..n {
        let mut row = [0.0; N];
        for (k, old_k) in old.iter().enumerate().take(n) {
            let w = ru[k][j];
            for i in 0..N {
                row[i] += w * old_k[i];
            }
        }
        d[j] = row;
    }
}

/// The root-mean-square norm of `c v` weighted by `1 / (atol + rtol |y|)`.
#[inline]
fn scaled_norm<const N: usize>(
    c: f64,
    v: &[f64; N],
    atol: &[f64; N],
    rtol: f64,
    y: &[f64; N],
) -> f64 {
    let mut s = 0.0;
    for i in 0..N {
        let x = c * v[i] / (atol[i] + rtol * y[i].abs());
        s += x * x;
    }
    (s / N as f64).sqrt()
}

/// The BDF (or NDF, [`Formula`]) stepper: the backward differences, the order, the factored
/// Newton matrix with its Jacobian, the Newton iteration's measured constant, and the work
/// counters.
#[derive(Debug, Clone)]
pub struct Bdf<const N: usize> {
    pub(super) core: StepCore<N>,
    d: Diffs<N>,
    order: usize,
    /// Steps taken at the current size and order.
    n_equal: usize,
    lu: Lu,
    /// Newton iterations, over every attempt.
    newton_iterations: u64,
    /// The measured constant `K` of the quadratic convergence (second correction over the
    /// first's square, in the error norm), infinite before a measurement.
    newton_k: f64,
    /// Accepted steps since `newton_k` was measured.
    newton_k_age: u64,
    /// Whether the next restart keeps the differences
    /// ([`Stepper::keep_history_at_next_restart`]).
    keep_history: bool,
    /// Whether the last accepted step was shortened to the driver's cap.
    last_capped: bool,
    /// The step size before the last shortening to the cap (s).
    proposal: f64,
    /// `kappa_k` of the formulas ([`Formula`]); zero for the BDF.
    kappa: [f64; MAX_ORDER + 1],
    /// The highest order the order selection may raise to ([`Bdf::with_max_order`]).
    max_order: usize,
}

/// One attempt's outcome.
enum Attempt<const N: usize> {
    /// The iteration converged: the new state, its difference from the prediction, and the
    /// iterations it took.
    Converged([f64; N], [f64; N], usize),
    /// It diverged or would not converge in [`NEWTON_MAXITER`] iterations.
    Failed,
}

impl<const N: usize> Bdf<N> {
    /// A BDF stepper with the given control settings and no step-size history. On fixed steps
    /// (`ctl.fixed_step`) it keeps the order it starts at: 1 after a restart.
    pub fn new(ctl: StepControl<N>) -> Self {
        Self::with_formula(ctl, Formula::Bdf)
    }

    /// A stepper of the given formulas (the BDF or the NDF), as [`Bdf::new`] otherwise.
    pub fn with_formula(ctl: StepControl<N>, formula: Formula) -> Self {
        Self {
            core: StepCore::new(ctl, 5),
            d: [[0.0; N]; MAX_ORDER + 3],
            order: 1,
            n_equal: 0,
            lu: Lu::identity(),
            newton_iterations: 0,
            newton_k: f64::INFINITY,
            newton_k_age: 0,
            keep_history: false,
            last_capped: false,
            proposal: 0.0,
            kappa: formula.kappa(),
            max_order: MAX_ORDER,
        }
    }

    /// The same stepper with its order capped at `max_order` (clamped to `1..=5`; 5 by
    /// default), for use when the stepper is built, at order 1.
    /// Orders 3 to 5 are not A-stable: each is unstable on a bounded region of the left
    /// half-plane beside the imaginary axis (the BDF's stability angles are 86, 73 and 52
    /// degrees, the NDF's 80, 66 and 52), so a lightly damped mode that a step spans can
    /// grow under them. On the drop model such modes leave order 5 almost no stable step
    /// (`solver.bdf_max_order`, docs/performance.md#the-bdfs-highest-order).
    pub fn with_max_order(mut self, max_order: usize) -> Self {
        self.max_order = max_order.clamp(1, MAX_ORDER);
        self
    }

    /// The highest order the stepper may take.
    pub fn max_order(&self) -> usize {
        self.max_order
    }

    /// The error constant of order `k` in units of `nabla^{k+1} y`:
    /// `kappa_k gamma_k + 1 / (k + 1)` (`1 / (k + 1)` for the BDF).
    #[inline]
    fn error_constant(&self, k: usize) -> f64 {
        self.kappa[k] * GAMMA[k] + 1.0 / (k as f64 + 1.0)
    }

    /// `alpha_k = (1 - kappa_k) gamma_k`, so that `c = h / alpha_k` (`gamma_k` for the BDF).
    #[inline]
    fn alpha(&self, k: usize) -> f64 {
        (1.0 - self.kappa[k]) * GAMMA[k]
    }

    /// Newton iterations so far, over every attempt (each evaluates the model once).
    pub fn newton_iterations(&self) -> u64 {
        self.newton_iterations
    }

    /// The current order.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Whether `(t, y)` is where the last step ended, so that the differences still hold
    /// there (a restart announced by [`Stepper::keep_history_at_next_restart`] keeps them).
    pub(super) fn continues_at(&self, t: f64, y: &[f64; N]) -> bool {
        // Differences spaced by a step cut far below the one proposed (to femtoseconds, at
        // worst, by an end time) are not a history to go on from.
        let cut_short = self.last_capped && self.core.h < 0.1 * self.proposal;
        !cut_short && self.core.h > 0.0 && self.core.dense.t_end == t && same_bits(&self.d[0], y)
    }

    /// The step size a restart should start from: the current one, or the one proposed before
    /// the last step was shortened to the cap.
    pub(super) fn next_step_size(&self) -> f64 {
        if self.last_capped {
            self.proposal
        } else {
            self.core.h
        }
    }

    /// Starts the method at order `values.len() - 1` and spacing `h` from the solution values
    /// `values[j] = y(t - j h)`, `values[0]` the state the next step starts from (the step
    /// after a one-step method's, [`super::Rodas4Bdf`]).
    pub(super) fn seed(&mut self, values: &[[f64; N]], h: f64) {
        let order = values.len() - 1;
        assert!(
            (1..=self.max_order).contains(&order),
            "seeded at order {order}, the highest is {}",
            self.max_order
        );
        // The difference table: after pass m, v[j] = nabla^m y(t - (j - m) h) for j >= m.
        let mut v = [[0.0; N]; MAX_ORDER + 1];
        v[..=order].copy_from_slice(values);
        self.d = [[0.0; N]; MAX_ORDER + 3];
        self.d[0] = values[0];
        for m in 1..=order {
            for j in (m..=order).rev() {
                for i in 0..N {
                    v[j][i] = v[j - 1][i] - v[j][i];
                }
            }
            self.d[m] = v[m];
        }
        self.order = order;
        self.n_equal = 0;
        self.core.h = h;
        self.newton_k = f64::INFINITY;
        self.newton_k_age = 0;
    }

    /// Rescales the differences to a step `factor` times the current one.
    fn rescale(&mut self, factor: f64) {
        change_spacing(&mut self.d, self.order, factor);
        self.core.h *= factor;
        self.n_equal = 0;
    }

    /// One attempt at `t_new` from `y_pred` with `c = h / alpha_k`: the Jacobian at
    /// `y_pred`, `I - c J` factored, then Newton's iteration on
    /// `y - c f(t_new, y) = y_pred - psi`. It stops with SciPy's test (the contraction rate
    /// `rho` of successive corrections: converged when `rho / (1 - rho) |dy| < tol`, failed
    /// when `rho >= 1` or when the corrections left would not meet `tol` within
    /// [`NEWTON_MAXITER`] iterations), or after one iteration when the measured constant
    /// predicts the next correction below `tol` (see the module doc).
    #[allow(clippy::too_many_arguments)]
    fn attempt<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t_new: f64,
        y_pred: &[f64; N],
        psi: &[f64; N],
        c: f64,
        scale: &[f64; N],
        tol: f64,
    ) -> Attempt<N> {
        sys.fill_stiff_jacobian(t_new, y_pred, &mut self.lu.j);
        self.core.stats.jacobians += 1;
        self.core.stats.factorizations += 1;
        if !self.lu.factor(c) {
            return Attempt::Failed;
        }
        let mut y = *y_pred;
        let mut d = [0.0; N];
        let mut dy_norm_old = f64::NAN;
        for k in 0..NEWTON_MAXITER {
            self.newton_iterations += 1;
            let mut f = [0.0; N];
            sys.rhs(t_new, &y, &mut f);
            self.core.stats.rhs_evals += 1;
            let mut dy = [0.0; N];
            for i in 0..N {
                dy[i] = c * f[i] - psi[i] - d[i];
            }
            self.lu.solve(&mut dy);
            let mut sq = 0.0;
            for i in 0..N {
                let x = dy[i] / scale[i];
                sq += x * x;
            }
            let dy_norm = (sq / N as f64).sqrt();
            if !dy_norm.is_finite() {
                return Attempt::Failed;
            }
            // A correction at the rounding level of the state: converged (two such in a row
            // would give a contraction rate of noise; a step cut to femtoseconds by an end
            // time makes them).
            if dy_norm <= ROUNDING / self.core.ctl.rtol {
                for i in 0..N {
                    y[i] += dy[i];
                    d[i] += dy[i];
                }
                return Attempt::Converged(y, d, k + 1);
            }
            let rate = (k > 0).then(|| dy_norm / dy_norm_old);
            if let Some(r) = rate {
                if r >= 1.0 || r.powi((NEWTON_MAXITER - k) as i32) / (1.0 - r) * dy_norm > tol {
                    return Attempt::Failed;
                }
                if k == 1 {
                    self.newton_k = dy_norm / (dy_norm_old * dy_norm_old);
                    self.newton_k_age = 0;
                }
            }
            for i in 0..N {
                y[i] += dy[i];
                d[i] += dy[i];
            }
            let one_is_enough = k == 0
                && self.newton_k_age < RECHECK_STEPS
                && self.newton_k * dy_norm * dy_norm <= tol;
            if one_is_enough
                || dy_norm == 0.0
                || rate.is_some_and(|r| r / (1.0 - r) * dy_norm < tol)
            {
                return Attempt::Converged(y, d, k + 1);
            }
            dy_norm_old = dy_norm;
        }
        Attempt::Failed
    }
}

impl<const N: usize> Stepper<N> for Bdf<N> {
    fn restart<S: OdeSystem<N>>(&mut self, sys: &S, t: f64, y: &[f64; N]) {
        if std::mem::take(&mut self.keep_history) && self.continues_at(t, y) {
            return;
        }
        // A new mode: the Newton constant is measured anew.
        self.newton_k = f64::INFINITY;
        self.newton_k_age = 0;
        self.core.h = self.next_step_size();
        self.last_capped = false;
        let mut f = [0.0; N];
        sys.rhs(t, y, &mut f);
        self.core.restart(sys, y, &f);
        self.order = 1;
        self.n_equal = 0;
        self.d = [[0.0; N]; MAX_ORDER + 3];
        self.d[0] = *y;
        let h = self.core.h;
        for i in 0..N {
            self.d[1][i] = h * f[i];
        }
    }

    fn keep_history_at_next_restart(&mut self) {
        self.keep_history = true;
    }

    fn cap_next_step(&mut self, h_s: f64) {
        if self.core.ctl.fixed_step.is_none() {
            if self.core.h > h_s {
                let factor = h_s / self.core.h;
                self.rescale(factor);
            }
            // The step size a restart takes ([`Bdf::next_step_size`]) obeys the cap too.
            self.proposal = self.proposal.min(h_s);
        }
    }

    fn step<S: OdeSystem<N>>(
        &mut self,
        sys: &S,
        t: f64,
        y: &[f64; N],
        h_cap: f64,
    ) -> Result<&Dense<N>, SolveError> {
        // Bitwise, so that a state that is not finite (which fails below) passes.
        debug_assert!(
            same_bits(&self.d[0], y),
            "the BDF stepper continues only from its own last step"
        );
        self.core.begin_step(sys, t, y);
        let rtol = self.core.ctl.rtol;
        let atol = self.core.step_atol;
        let fixed = self.core.ctl.fixed_step.is_some();
        // SciPy's (and RADAU5's) stopping tolerance of the Newton iteration.
        let newton_tol = (ROUNDING / rtol).max(0.03_f64.min(rtol.sqrt()));
        // A state that is not finite, or a step size that is not (the first step's heuristic
        // on such a state), fails at once rather than halving the step to no end.
        if !self.core.h.is_finite() || !y.iter().all(|v| v.is_finite()) {
            return Err(SolveError::NonFiniteState { t_s: t });
        }
        // A step shortened to the cap (an end time) re-spaces the differences to it; the step
        // size before it is kept for a restart ([`Bdf::next_step_size`]).
        let capped = self.core.h > h_cap;
        if capped {
            self.proposal = self.core.h;
            self.rescale(h_cap / self.core.h);
            self.core.h = h_cap;
        }
        let mut rejected = false;
        let (y_new, d_new, error_norm, safety) = loop {
            let attempts = self.core.stats.steps + self.core.stats.rejected;
            if attempts >= self.core.ctl.max_attempts {
                return Err(SolveError::StepBudget { t_s: t, attempts });
            }
            let h = self.core.h;
            // A step shortened to the cap (to meet an end time) is not an underflow, as in
            // the one-step methods' control.
            let short_only_by_cap = h == h_cap && h > 0.0;
            if !(h >= self.core.ctl.h_min) && !short_only_by_cap {
                return Err(SolveError::StepSizeUnderflow { t_s: t, h_s: h });
            }
            let order = self.order;
            let mut y_pred = [0.0; N];
            let mut psi = [0.0; N];
            for j in 0..=order {
                for i in 0..N {
                    y_pred[i] += self.d[j][i];
                }
            }
            let alpha = self.alpha(order);
            for j in 1..=order {
                let w = GAMMA[j] / alpha;
                for i in 0..N {
                    psi[i] += w * self.d[j][i];
                }
            }
            let scale: [f64; N] = std::array::from_fn(|i| atol[i] + rtol * y_pred[i].abs());
            let c = h / alpha;
            let Attempt::Converged(y_new, d, iterations) =
                self.attempt(sys, t + h, &y_pred, &psi, c, &scale, newton_tol)
            else {
                if fixed {
                    return Err(SolveError::NonFiniteState { t_s: t });
                }
                self.core.stats.rejected += 1;
                rejected = true;
                self.rescale(0.5);
                continue;
            };
            // SciPy's safety factor, counting an iteration that ended after one as two (with
            // it counted as one, the 1 s pendulum drop took 6 507 steps with 606 rejections
            // against 5 481 and 314).
            let safety = 0.9 * (2 * NEWTON_MAXITER + 1) as f64
                / (2 * NEWTON_MAXITER + iterations.max(2)) as f64;
            let error_norm = scaled_norm(self.error_constant(order), &d, &atol, rtol, &y_new);
            if !fixed && !(error_norm <= 1.0) {
                self.core.stats.rejected += 1;
                rejected = true;
                let factor = if error_norm.is_finite() {
                    (safety * error_norm.powf(-1.0 / (order as f64 + 1.0))).max(MIN_FACTOR)
                } else {
                    MIN_FACTOR
                };
                self.rescale(factor);
                continue;
            }
            break (y_new, d, error_norm, safety);
        };
        let h = self.core.h;
        let order = self.order;
        // A capped step that was rejected and shrunk says nothing for the proposal before
        // the cap (as in the one-step methods' control).
        self.last_capped = capped && !rejected;
        self.n_equal += 1;
        self.newton_k_age += 1;
        // The differences of the new step: nabla^{k+1} y_{n+1} = d, then downwards.
        for i in 0..N {
            self.d[order + 2][i] = d_new[i] - self.d[order + 1][i];
            self.d[order + 1][i] = d_new[i];
        }
        for j in (0..=order).rev() {
            for i in 0..N {
                self.d[j][i] += self.d[j + 1][i];
            }
        }
        // The summed differences differ from y_new in the last bits: the stepper goes on from
        // the state it reports.
        self.d[0] = y_new;
        // The interpolant: the polynomial through y_{n+1}, ..., y_{n+1-k}.
        let dense = &mut self.core.dense;
        dense.r[..=order].copy_from_slice(&self.d[..=order]);
        (dense.t0, dense.h, dense.t_end) = (t, h, t + h);
        dense.terms = BACKWARD + order;
        (dense.y0, dense.y1) = (*y, y_new);
        self.core.stats.steps += 1;
        if self.n_equal > order && !fixed {
            // The next order and size from the error estimates at orders k - 1, k, k + 1.
            let e_minus = if order > 1 {
                scaled_norm(
                    self.error_constant(order - 1),
                    &self.d[order],
                    &atol,
                    rtol,
                    &y_new,
                )
            } else {
                f64::INFINITY
            };
            let e_plus = if order < self.max_order {
                scaled_norm(
                    self.error_constant(order + 1),
                    &self.d[order + 2],
                    &atol,
                    rtol,
                    &y_new,
                )
            } else {
                f64::INFINITY
            };
            let mut best = (order, error_norm.powf(-1.0 / (order as f64 + 1.0)));
            for (k, e) in [(order - 1, e_minus), (order + 1, e_plus)] {
                let f = e.powf(-1.0 / (k as f64 + 1.0));
                if f > best.1 {
                    best = (k, f);
                }
            }
            self.order = best.0;
            self.rescale((safety * best.1).min(MAX_FACTOR));
        }
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

    /// `y' = p'(t)` for a polynomial `p` of degree 4, both components.
    struct Poly;
    fn p(t: f64) -> f64 {
        1.0 + t - 0.5 * t * t + 0.25 * t.powi(3) - 0.125 * t.powi(4)
    }
    fn dp(t: f64) -> f64 {
        1.0 - t + 0.75 * t * t - 0.5 * t.powi(3)
    }
    impl OdeSystem<2> for Poly {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, t: f64, _y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = dp(t);
            dy[1] = 2.0 * dp(t);
        }
    }
    fn ctl(fixed: Option<f64>) -> StepControl<2> {
        StepControl {
            rtol: 1e-6,
            atol: [1e-9; 2],
            h_min: 1e-14,
            max_attempts: 1_000_000,
            fixed_step: fixed,
        }
    }

    #[test]
    fn re_interpolation_is_exact_for_a_polynomial_of_the_order() {
        // Differences of p at spacing 0.1 behind t = 1, re-spaced to 0.037: those of p at
        // spacing 0.037, for p of degree 4 and order 4.
        let diffs = |h: f64| {
            let mut st = Bdf::<2>::new(ctl(None));
            let v: Vec<[f64; 2]> = (0..=4)
                .map(|j| {
                    let x = p(1.0 - j as f64 * h);
                    [x, 2.0 * x]
                })
                .collect();
            st.seed(&v, h);
            st.d
        };
        let mut d = diffs(0.1);
        change_spacing(&mut d, 4, 0.37);
        let want = diffs(0.037);
        for j in 0..=4 {
            for i in 0..2 {
                assert!(
                    (d[j][i] - want[j][i]).abs() < 1e-13,
                    "row {j}: {} against {}",
                    d[j][i],
                    want[j][i]
                );
            }
        }
    }

    #[test]
    fn re_interpolation_is_the_full_product_bit_for_bit() {
        // `change_spacing` takes `U` from the table and leaves out its zeros; the product in
        // full, with `U` computed here, must give the same bits, at every order and for
        // factors that shrink and grow the step (and for differences of both signs, so that
        // negative zeros would show).
        for order in 1..=MAX_ORDER {
            for factor in [0.2, 0.37, 0.5, 0.93, 1.0, 1.7, 10.0] {
                let mut d: Diffs<3> = [[0.0; 3]; MAX_ORDER + 3];
                for (j, row) in d.iter_mut().enumerate() {
                    for (i, x) in row.iter_mut().enumerate() {
                        *x = ((j * 7 + i * 3) as f64 * 0.731).sin() * 10f64.powi(-(j as i32));
                    }
                }
                let mut full = d;
                let r = interp_matrix(order, factor);
                let u = interp_matrix(order, 1.0);
                let mut ru = [[0.0; MAX_ORDER + 1]; MAX_ORDER + 1];
                for i in 0..=order {
                    for k in 0..=order {
                        for j in 0..=order {
                            ru[i][j] += r[i][k] * u[k][j];
                        }
                    }
                }
                let old = full;
                for j in 0..=order {
                    let mut row = [0.0; 3];
                    for k in 0..=order {
                        for i in 0..3 {
                            row[i] += ru[k][j] * old[k][i];
                        }
                    }
                    full[j] = row;
                }
                change_spacing(&mut d, order, factor);
                for j in 0..MAX_ORDER + 3 {
                    for i in 0..3 {
                        assert!(
                            d[j][i].to_bits() == full[j][i].to_bits(),
                            "order {order}, factor {factor}, row {j}: {:e} against {:e}",
                            d[j][i],
                            full[j][i]
                        );
                    }
                }
            }
        }
    }

    /// A stepper on fixed steps `h` seeded at order 4 with [`Poly`]'s exact values behind
    /// `t = 0`, and the state there.
    fn seeded(h: f64) -> (Bdf<2>, [f64; 2]) {
        seeded_with(h, Formula::Bdf)
    }

    /// As [`seeded`], with the given formulas.
    fn seeded_with(h: f64, formula: Formula) -> (Bdf<2>, [f64; 2]) {
        let mut st = Bdf::<2>::with_formula(ctl(Some(h)), formula);
        let v: Vec<[f64; 2]> = (0..=4)
            .map(|j| {
                let x = p(-(j as f64) * h);
                [x, 2.0 * x]
            })
            .collect();
        st.seed(&v, h);
        (st, v[0])
    }

    #[test]
    fn order_k_integrates_a_polynomial_of_degree_k_exactly_and_its_interpolant_too() {
        // Seeded at order 4 from exact values, fixed steps: the BDF of order 4 is exact for
        // polynomials of degree 4, and so is the interpolant through its last five values;
        // so is the NDF (its term in nabla^5 y vanishes on them).
        let h = 0.05;
        for formula in [Formula::Bdf, Formula::Ndf] {
            let (mut st, y0) = seeded_with(h, formula);
            let (mut t, mut y) = (0.0, y0);
            for _ in 0..20 {
                let dense = st.step(&Poly, t, &y, f64::INFINITY).unwrap().clone();
                for th in [0.1, 0.5, 0.9] {
                    let tm = t + th * h;
                    let ym = dense.eval(tm);
                    assert!(
                        (ym[0] - p(tm)).abs() < 1e-12,
                        "interpolant at {tm}: {}",
                        ym[0]
                    );
                }
                assert_eq!(dense.y0(), y);
                t = dense.t1();
                y = dense.y1();
                assert!((y[0] - p(t)).abs() < 1e-12 && (y[1] - 2.0 * p(t)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn a_restart_announced_as_no_switch_keeps_the_differences_from_the_same_state_only() {
        let h = 0.05;
        // Announced, from the state the last step ended at: the order and the differences
        // stay, and the next step is exact as before.
        let (mut st, y) = seeded(h);
        let d = st.step(&Poly, 0.0, &y, f64::INFINITY).unwrap();
        let (t, y) = (d.t1(), d.y1());
        st.keep_history_at_next_restart();
        st.restart(&Poly, t, &y);
        assert_eq!(st.order(), 4);
        let y2 = st.step(&Poly, t, &y, f64::INFINITY).unwrap().y1();
        assert!((y2[0] - p(t + h)).abs() < 1e-12);
        // Not announced, or from another state: a restart at order 1.
        let (mut st, y) = seeded(h);
        st.restart(&Poly, 0.0, &y);
        assert_eq!(st.order(), 1);
        let (mut st, y) = seeded(h);
        st.keep_history_at_next_restart();
        st.restart(&Poly, 0.0, &[y[0] + 1e-9, y[1]]);
        assert_eq!(st.order(), 1);
    }

    /// `y' = -y`, with its Jacobian.
    struct Decay;
    impl OdeSystem<1> for Decay {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, _t: f64, y: &[f64; 1], dy: &mut [f64; 1]) {
            dy[0] = -y[0];
        }
        fn stiff_jacobian(&self, _t: f64, _y: &[f64; 1]) -> Option<crate::ode::StiffJacobian> {
            let mut s = crate::ode::StiffJacobian::over(&[0]);
            s.jac[(0, 0)] = -1.0;
            Some(s)
        }
    }

    /// A stepper of the given formulas on fixed steps `h`, seeded at the given order with
    /// [`Decay`]'s exact values behind `t = 0` (where `y = 1`).
    fn seeded_decay(formula: Formula, order: usize, h: f64) -> Bdf<1> {
        let ctl = StepControl {
            rtol: 1e-12,
            atol: [1e-12],
            h_min: 0.0,
            max_attempts: u64::MAX,
            fixed_step: Some(h),
        };
        let mut st = Bdf::<1>::with_formula(ctl, formula);
        let v: Vec<[f64; 1]> = (0..=order).map(|j| [(j as f64 * h).exp()]).collect();
        st.seed(&v, h);
        st
    }

    /// The error estimate `C_k (y_1 - y_pred)` of one fixed step of [`Decay`] of length
    /// `1 / 200` by the given formulas of the given order, from the exact values behind it.
    fn decay_step_estimate(formula: Formula, order: usize) -> f64 {
        let mut st = seeded_decay(formula, order, 1.0 / 200.0);
        st.step(&Decay, 0.0, &[1.0], f64::INFINITY).unwrap();
        // On fixed steps the row above the order keeps the step's `y_1 - y_pred`.
        st.error_constant(order) * st.d[order + 1][0]
    }

    /// The global error at `t = 1` of `n` fixed steps of [`Decay`] from `y(0) = 1` by the
    /// given formulas of the given order, seeded with the exact values behind `t = 0`.
    fn decay_error(formula: Formula, order: usize, n: usize) -> f64 {
        let mut st = seeded_decay(formula, order, 1.0 / n as f64);
        let (mut t, mut y) = (0.0, [1.0]);
        for _ in 0..n {
            let d = st.step(&Decay, t, &y, f64::INFINITY).unwrap();
            (t, y) = (d.t1(), d.y1());
        }
        y[0] - (-t).exp()
    }

    /// A damped oscillator `x'' + 2 zeta x' + x = 0` as `(x, v)`, with its Jacobian, whose
    /// eigenvalues `-zeta +- i sqrt(1 - zeta^2)` lie at `acos(zeta)` from the negative real
    /// axis.
    struct Oscillator {
        zeta: f64,
    }
    impl Oscillator {
        /// The solution from `(1, -zeta)` at `t = 0`: `x = e^(-zeta t) cos(w t)`.
        fn exact(&self, t: f64) -> [f64; 2] {
            let w = (1.0 - self.zeta * self.zeta).sqrt();
            let e = (-self.zeta * t).exp();
            let (s, c) = (w * t).sin_cos();
            [e * c, -e * (self.zeta * c + w * s)]
        }
    }
    impl OdeSystem<2> for Oscillator {
        type Guard = crate::ode::NoGuard;
        fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
            dy[0] = y[1];
            dy[1] = -y[0] - 2.0 * self.zeta * y[1];
        }
        fn stiff_jacobian(&self, _t: f64, _y: &[f64; 2]) -> Option<crate::ode::StiffJacobian> {
            let mut s = crate::ode::StiffJacobian::over(&[0, 1]);
            s.jac[(0, 1)] = 1.0;
            s.jac[(1, 0)] = -1.0;
            s.jac[(1, 1)] = -2.0 * self.zeta;
            Some(s)
        }
    }

    #[test]
    fn order_5_lets_a_damped_mode_spanned_by_its_steps_grow_and_order_4_damps_it() {
        // A mode of damping ratio 0.2957 (72.8 degrees from the negative real axis, like the
        // drop model's 1.9 kHz mode while rolling) at h |lambda| = 3: inside order 5's
        // unstable region (stability angle 51.8 degrees; its largest root there is 1.16 in
        // modulus), outside order 4's (73.4 degrees; root 0.96). The exact solution falls
        // by e^-177 over the 200 steps.
        let osc = Oscillator { zeta: 0.2957 };
        let h = 3.0;
        let run = |order: usize| {
            let mut st = Bdf::<2>::new(ctl(Some(h)));
            let v: Vec<[f64; 2]> = (0..=order).map(|j| osc.exact(-(j as f64) * h)).collect();
            st.seed(&v, h);
            let (mut t, mut y) = (0.0, osc.exact(0.0));
            for _ in 0..200 {
                let d = st.step(&osc, t, &y, f64::INFINITY).unwrap();
                (t, y) = (d.t1(), d.y1());
            }
            assert_eq!(st.order(), order);
            y[0].hypot(y[1])
        };
        let (at4, at5) = (run(4), run(5));
        assert!(at5 > 1e6, "order 5: {at5:e}");
        assert!(at4 < 1e-2, "order 4: {at4:e}");
    }

    #[test]
    fn the_order_selection_stays_at_or_below_the_cap() {
        // A smooth problem at a tight tolerance, on which the order selection reaches 5
        // uncapped: capped at 4 (and 2) it never goes above the cap, and it still converges.
        let osc = Oscillator { zeta: 0.05 };
        let run = |cap: Option<usize>| {
            let ctl = StepControl {
                rtol: 1e-10,
                atol: [1e-12; 2],
                h_min: 1e-12,
                ..ctl(None)
            };
            let mut st = Bdf::<2>::new(ctl);
            if let Some(k) = cap {
                st = st.with_max_order(k);
            }
            let (mut t, mut y) = (0.0, osc.exact(0.0));
            st.restart(&osc, t, &y);
            let mut highest = 0;
            while t < 20.0 {
                let d = st.step(&osc, t, &y, 20.0 - t).unwrap();
                (t, y) = (d.t1(), d.y1());
                highest = highest.max(st.order());
            }
            let e = osc.exact(t);
            (highest, (y[0] - e[0]).hypot(y[1] - e[1]))
        };
        let (free, free_err) = run(None);
        assert_eq!(free, 5);
        for cap in [4, 2] {
            let (highest, err) = run(Some(cap));
            assert_eq!(highest, cap);
            assert!(
                err < 1e-6 && free_err < 1e-6,
                "cap {cap}: {err:e}, uncapped {free_err:e}"
            );
        }
    }

    #[test]
    fn fixed_steps_converge_at_the_seeded_order() {
        // The global error of order k falls as h^k, for both formulas.
        for formula in [Formula::Bdf, Formula::Ndf] {
            for order in 1..=MAX_ORDER {
                let err = |n| decay_error(formula, order, n).abs();
                let observed = (err(20) / err(40)).log2();
                assert!(
                    (observed - order as f64).abs() < 0.25,
                    "{formula:?} order {order}: observed {observed:.2}"
                );
            }
        }
    }

    #[test]
    fn the_ndfs_error_is_the_bdfs_times_the_ratio_of_their_error_constants() {
        // The formula of order k, written as
        // sum_{j<=k} nabla^j y / j - kappa gamma_k nabla^{k+1} y = h f, leaves on the exact
        // solution the residual -C_k h^{k+1} y^{(k+1)}, C_k = kappa gamma_k + 1 / (k + 1).
        // With the coefficient of h f one in both, the global error is C_k times the same
        // factor, so the NDF's is the BDF's times 1 + (k + 1) kappa_k gamma_k: 0.63, 0.50,
        // 0.40, 0.57 and 1 at orders 1 to 5. One step's own error is the residual over the
        // formula's derivative in y_{n+1}, alpha_k, and the step's estimate
        // C_k (y_{n+1} - y_pred) = C_k (1 + C_k / alpha_k) nabla^{k+1} y is that error times
        // (alpha_k + C_k) = gamma_{k+1} for both formulas; so the estimates go as C_k / alpha_k,
        // the NDF's the BDF's times (1 + (k + 1) kappa_k gamma_k) / (1 - kappa_k): 0.53,
        // 0.45, 0.37, 0.55 and 1. An estimate that left out kappa would be too large, and the
        // NDF's steps too short.
        for order in 1..=MAX_ORDER {
            let (kappa, gamma) = (NDF_KAPPA[order], GAMMA[order]);
            let global = 1.0 + (order as f64 + 1.0) * kappa * gamma;
            let local = global / (1.0 - kappa);
            let errors =
                decay_error(Formula::Ndf, order, 200) / decay_error(Formula::Bdf, order, 200);
            let estimates =
                decay_step_estimate(Formula::Ndf, order) / decay_step_estimate(Formula::Bdf, order);
            println!(
                "order {order}: NDF over BDF: global errors {errors:.4} (expected {global:.4}), \
                 step estimates {estimates:.4} (expected {local:.4})"
            );
            for (what, r, want) in [
                ("global error", errors, global),
                ("step estimate", estimates, local),
            ] {
                assert!(
                    (r / want - 1.0).abs() < 0.02,
                    "order {order}: NDF over BDF {what} {r:.4}, expected {want:.4}"
                );
            }
        }
    }
}
