//! What every stepper shares and the driver reads: the step-size control settings, the work
//! counters, the continuous extension of one accepted step, and the first-step heuristic.

/// Counters of the work done (the figures benchmarks report).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected step attempts.
    pub rejected: u64,
    /// Located events (mode switches).
    pub events: u64,
    /// Stiff Jacobians evaluated (implicit stepper only).
    #[serde(default)]
    pub jacobians: u64,
    /// LU factorisations of the Rosenbrock matrix (implicit stepper only; one per attempt).
    #[serde(default)]
    pub factorizations: u64,
}

/// Step-size control settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl<const N: usize> {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance per state component (in that component's unit).
    pub atol: [f64; N],
    /// Smallest step before [`crate::SolveError::StepSizeUnderflow`] (s).
    pub h_min: f64,
    /// Step attempts (accepted + rejected) before [`crate::SolveError::StepBudget`].
    pub max_attempts: u64,
    /// Fixed step size (s) instead of adaptive control: every step is accepted. For
    /// convergence-order studies; `None` in normal use.
    pub fixed_step: Option<f64>,
}

/// The continuous extension of one accepted step, valid on `[t0, t_end]`: DOPRI5's
/// 4th-order one (5 coefficient vectors), DOP853's 7th-order one (8), or a Rosenbrock
/// method's (5: the cubic Hermite one, or Rodas5P's own of order 4, whose attempts leave their
/// coefficients in rows 5-7 as scratch, unread with 5 terms).
///
/// Both share Hairer's nested form `r0 + th (r1 + th1 (r2 + th (r3 + th1 (r4 + ...))))`
/// with `th = (t - t0)/h`, `th1 = 1 - th`, so one type serves both steppers.
#[derive(Debug, Clone)]
pub struct Dense<const N: usize> {
    pub(super) t0: f64,
    pub(super) h: f64,
    pub(super) t_end: f64,
    /// Number of coefficient vectors in use: 5 (DOPRI5, the Rosenbrock methods) or 8 (DOP853)
    /// in the nested form; or [`BACKWARD`] `+ k` for the BDF stepper's polynomial of degree
    /// `k` through the step's end and the `k` solution values before it at spacing `h`, held
    /// as the backward differences `r[j] = nabla^j y(t0 + h)`.
    pub(super) terms: usize,
    pub(super) r: [[f64; N]; 8],
    /// The step's end state, kept exactly (not re-summed from `r`).
    pub(super) y1: [f64; N],
    /// The step's start state, kept exactly for the backward form (the nested form has it in
    /// `r[0]`).
    pub(super) y0: [f64; N],
}

/// [`Dense::terms`] at and above this value: the backward-difference form of the BDF stepper.
pub(super) const BACKWARD: usize = 16;

impl<const N: usize> Dense<N> {
    /// Start of the step (s).
    pub fn t0(&self) -> f64 {
        self.t0
    }
    /// End of the (possibly event-truncated) step (s).
    pub fn t1(&self) -> f64 {
        self.t_end
    }
    /// The order of the multistep (BDF or NDF) step whose interpolant this is; `None` for a
    /// one-step method's step.
    pub fn multistep_order(&self) -> Option<usize> {
        self.terms.checked_sub(BACKWARD)
    }
    /// State at `t` (meant for `t` in `[t0, t1]`).
    #[inline]
    pub fn eval(&self, t: f64) -> [f64; N] {
        let mut y = [0.0; N];
        let r = &self.r;
        if self.terms >= BACKWARD {
            // y = D0 + s (D1 + (s + 1)/2 (D2 + (s + 2)/3 (D3 + ...))), s = (t - t_end)/h.
            let k = self.terms - BACKWARD;
            let s = (t - (self.t0 + self.h)) / self.h;
            y = r[k];
            for j in (0..k).rev() {
                let w = (s + j as f64) / (j as f64 + 1.0);
                for i in 0..N {
                    y[i] = r[j][i] + w * y[i];
                }
            }
            return y;
        }
        let th = (t - self.t0) / self.h;
        let th1 = 1.0 - th;
        if self.terms == 5 {
            for i in 0..N {
                y[i] = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
            }
        } else {
            for i in 0..N {
                let inner = r[4][i] + th * (r[5][i] + th1 * (r[6][i] + th * r[7][i]));
                y[i] = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * inner)));
            }
        }
        y
    }
    /// State at the start of the step.
    pub fn y0(&self) -> [f64; N] {
        if self.terms >= BACKWARD {
            self.y0
        } else {
            self.r[0]
        }
    }
    /// State at the end of the (possibly truncated) step.
    pub fn y1(&self) -> [f64; N] {
        if self.t_end == self.t0 + self.h {
            self.y1
        } else {
            self.eval(self.t_end)
        }
    }
}

/// A first step from Hairer's `hinit` (the simple form): 1 % of the ratio of the state's
/// and the derivative's weighted norms, capped by `max_step` and floored at `10 h_min`.
pub(super) fn initial_step<const N: usize>(
    ctl: &StepControl<N>,
    y: &[f64; N],
    dy: &[f64; N],
    max_step: f64,
) -> f64 {
    let (mut d0, mut d1) = (0.0, 0.0);
    for i in 0..N {
        let sc = ctl.atol[i] + ctl.rtol * y[i].abs();
        d0 += (y[i] / sc).powi(2);
        d1 += (dy[i] / sc).powi(2);
    }
    let (d0, d1) = ((d0 / N as f64).sqrt(), (d1 / N as f64).sqrt());
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0.min(max_step).max(ctl.h_min * 10.0)
}
