//! Test problems shared by the integration tests of the steppers.

use whirlmap_core::ode::{NoGuard, OdeSystem, StiffJacobian};

/// x'' = -x as a first-order system: cos t, -sin t from (1, 0). `wrong_jacobian` hands the
/// implicit stepper a matrix that is not the Jacobian.
pub struct Harmonic {
    /// Give the stepper a wrong Jacobian (for the W-method's order test).
    pub wrong_jacobian: bool,
}

/// The harmonic oscillator with its true Jacobian.
#[allow(dead_code)]
pub const HARMONIC: Harmonic = Harmonic {
    wrong_jacobian: false,
};

impl OdeSystem<2> for Harmonic {
    type Guard = NoGuard;
    fn rhs(&self, _t: f64, y: &[f64; 2], dy: &mut [f64; 2]) {
        dy[0] = y[1];
        dy[1] = -y[0];
    }
    fn stiff_jacobian(&self, _t: f64, _y: &[f64; 2]) -> Option<StiffJacobian> {
        let mut s = StiffJacobian::over(&[0, 1]);
        if self.wrong_jacobian {
            s.jac[(1, 0)] = -3.0;
            s.jac[(0, 0)] = 0.7;
        } else {
            s.jac[(0, 1)] = 1.0;
            s.jac[(1, 0)] = -1.0;
        }
        Some(s)
    }
}
