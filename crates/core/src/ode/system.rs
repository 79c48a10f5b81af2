//! What a problem is to the integrator: a right-hand side, step bounds, guard functions and an
//! optional stiff Jacobian. Nothing here knows the steppers.

use std::fmt::Debug;

/// Most guard functions one mode of a system may declare.
pub const MAX_GUARDS: usize = 4;

/// The named guard functions of a system: one value per guard, each with a fixed index, its
/// slot in the array [`OdeSystem::guards`] fills. The driver reports a crossing as the guard
/// that crossed, so a caller matches on names, not on slot numbers.
pub trait GuardSet: Copy + Debug + PartialEq + 'static {
    /// Every guard in index order: guard `ALL[i]` is written into `g[i]`. At most
    /// [`MAX_GUARDS`] of them.
    const ALL: &'static [Self];
}

/// The guard set of a system without discrete modes: it has no guard at all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoGuard {}

impl GuardSet for NoGuard {
    const ALL: &'static [Self] = &[];
}

/// Most state components an approximate (stiff) Jacobian may couple.
pub const MAX_STIFF: usize = 10;

/// The matrix of a [`StiffJacobian`] (nalgebra's fixed-size storage).
pub type JacobianMatrix = nalgebra::SMatrix<f64, MAX_STIFF, MAX_STIFF>;

/// Most quadrature rows a [`StiffJacobian`] may hold.
pub const MAX_QUAD: usize = 5;

/// The quadrature rows of a [`StiffJacobian`] over its coupled components.
pub type QuadratureRows = nalgebra::SMatrix<f64, MAX_QUAD, MAX_STIFF>;

/// An approximate Jacobian restricted to a few state components, for the linearly implicit
/// stepper ([`super::Ros34pw2`]): `jac[(a, b)]` approximates `d f_{idx[a]} / d y_{idx[b]}`; every
/// entry outside these rows and columns is taken as zero.
#[derive(Debug, Clone, Copy)]
pub struct StiffJacobian {
    /// The coupled components (the first `len` entries are used).
    pub idx: [usize; MAX_STIFF],
    /// How many components are coupled.
    pub len: usize,
    /// The restricted Jacobian (1/s units of the state's components).
    pub jac: JacobianMatrix,
    /// How many leading components are *kinematic*: positions `q_a` (a < `kinematic`) whose
    /// rows say exactly `q_a' = y_{idx[kinematic + a]}` (`jac[(a, kinematic + a)] = 1`, every
    /// other entry of the row zero). The stepper then eliminates them and factors only the
    /// remaining `len - kinematic` components (a Schur complement). 0 (the default of
    /// [`StiffJacobian::over`]): no such structure is claimed. At most `len / 2`.
    pub kinematic: usize,
    /// Quadrature components: accumulators `q' = g(y)` whose effect on the coupled components
    /// the matrix leaves out (energy integrals, which nothing reads; angles, read only by terms
    /// left out). The first `quad_len` entries are used; none by default.
    pub quad_idx: [usize; MAX_QUAD],
    /// How many quadrature rows are held.
    pub quad_len: usize,
    /// `quad[(a, b)]` approximates `d g_a / d y_{idx[b]}` for quadrature `quad_idx[a]`; its
    /// columns outside the coupled components are taken as zero. With these rows the matrix
    /// `I - h gamma J` is block lower triangular: the stepper solves the coupled block, then
    /// adds `h gamma (quad u)` to each quadrature. A Rosenbrock method (RODAS4) needs them to
    /// keep its order on the accumulators; a W-method keeps it without.
    pub quad: QuadratureRows,
}

impl StiffJacobian {
    /// An empty Jacobian over the components `idx` (at most [`MAX_STIFF`]).
    pub fn over(idx: &[usize]) -> Self {
        let mut s = Self {
            idx: [0; MAX_STIFF],
            len: idx.len(),
            jac: JacobianMatrix::zeros(),
            kinematic: 0,
            quad_idx: [0; MAX_QUAD],
            quad_len: 0,
            quad: QuadratureRows::zeros(),
        };
        s.idx[..idx.len()].copy_from_slice(idx);
        s
    }

    /// Makes `self` what [`StiffJacobian::over`] returns, in place. Field by field rather
    /// than `*self = Self::over(idx)`, which builds the matrix aside and moves it: 126.4 M
    /// against 124.0 M instructions on the 1 s pendulum drop (callgrind, 2026-11-28).
    pub fn reset_over(&mut self, idx: &[usize]) {
        self.idx = [0; MAX_STIFF];
        self.idx[..idx.len()].copy_from_slice(idx);
        self.len = idx.len();
        self.jac = JacobianMatrix::zeros();
        self.kinematic = 0;
        self.quad_idx = [0; MAX_QUAD];
        self.quad_len = 0;
        self.quad = QuadratureRows::zeros();
    }
}

/// A first-order system `y' = f(t, y)` with a fixed-size state and mode guards.
pub trait OdeSystem<const N: usize> {
    /// The system's guards by name ([`NoGuard`] for a system without modes).
    type Guard: GuardSet;

    /// Writes `f(t, y)` into `dy`.
    fn rhs(&self, t: f64, y: &[f64; N], dy: &mut [f64; N]);

    /// Writes the current mode's guard values into `g` and returns how many are active: the
    /// first `n` of [`GuardSet::ALL`], guard `ALL[i]` in `g[i]`. Each guard is positive while
    /// the mode holds; a crossing to `<= 0` is an event. The default has none.
    fn guards(&self, _t: f64, _y: &[f64; N], _g: &mut [f64; MAX_GUARDS]) -> usize {
        0
    }

    /// Largest step allowed in the current mode (s); `f64::INFINITY` for none.
    fn max_step(&self) -> f64 {
        f64::INFINITY
    }

    /// Largest step allowed from state `(t, y)` (s); by default [`OdeSystem::max_step`].
    fn max_step_at(&self, _t: f64, _y: &[f64; N]) -> f64 {
        self.max_step()
    }

    /// An approximation of the stiff part of the Jacobian at `(t, y)`, for the linearly
    /// implicit stepper. It need not be exact (a W-method keeps its order for any matrix); it
    /// must hold the terms that make the system stiff. The default, `None`, is the zero
    /// matrix, which turns [`super::Ros34pw2`] into an explicit 3rd-order Runge-Kutta method.
    fn stiff_jacobian(&self, _t: f64, _y: &[f64; N]) -> Option<StiffJacobian> {
        None
    }

    /// [`OdeSystem::stiff_jacobian`] written into `out` (the empty matrix for `None`): the
    /// steppers' way in, which a system overrides to build the matrix in place rather than
    /// return it (it is large enough that moving it costs).
    fn fill_stiff_jacobian(&self, t: f64, y: &[f64; N], out: &mut StiffJacobian) {
        *out = self
            .stiff_jacobian(t, y)
            .unwrap_or_else(|| StiffJacobian::over(&[]));
    }

    /// The absolute tolerances of a step from `(t, y)`, when the system widens some
    /// components there (`base` is the stepper's own); `None`, the default, keeps `base`.
    /// Every stepper asks once per step, before its attempts, and uses the answer for all of
    /// them. For a variable that matters only through terms whose own scale varies with the
    /// state.
    fn loosened_atol(&self, _t: f64, _y: &[f64; N], _base: &[f64; N]) -> Option<[f64; N]> {
        None
    }
}
