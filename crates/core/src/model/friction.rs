//! The friction law of the rotor-race contact, in one place: Coulomb slip with the paper's
//! stick/slip switch (eqs. 8-10) or its tanh regularisation, the force it gives, its
//! derivatives for the stiff Jacobian, and the static limit of eq. 10.

use crate::scene::FrictionLaw;

/// Friction state of the rotor-race contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Slip {
    /// Sliding, eq. 8: `F_t = mu_d F_n * sign` on the race along +t; `sign` (+1 or -1) is
    /// the sign of the slip velocity, fixed for the mode so the right-hand side stays smooth;
    /// its reversal is a located event.
    Slipping(f64),
    /// Rolling, eq. 9: `v_rel = 0` holds and the friction is the constraint force that keeps
    /// it, until it would exceed `mu_s F_n` (eq. 10) or the contact opens.
    Sticking,
}

/// The friction law with its coefficients (from the scene).
#[derive(Debug, Clone, Copy)]
pub struct Friction {
    law: FrictionLaw,
    /// Dynamic coefficient mu_d (eq. 8).
    mu_d: f64,
    /// Static coefficient mu_s (eq. 10).
    mu_s: f64,
}

/// How the friction force moves with the state, for the stiff Jacobian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionSlopes {
    /// `F_t = per_normal F_n` plus a slope in the slip velocity (the regularised law).
    Smooth {
        /// d F_t / d F_n at fixed slip velocity.
        per_normal: f64,
        /// d F_t / d v_rel at fixed normal force.
        per_slip_velocity: f64,
    },
    /// `F_t = per_normal F_n` (slipping under the switched law).
    Proportional {
        /// d F_t / d F_n.
        per_normal: f64,
    },
    /// The rolling constraint's force (sticking): its dependence on the state is left out.
    Constraint,
}

impl Friction {
    /// The law `law` with dynamic and static coefficients `mu_d` and `mu_s`.
    pub fn new(law: FrictionLaw, mu_d: f64, mu_s: f64) -> Self {
        Self { law, mu_d, mu_s }
    }

    /// Whether the friction mode can switch (switched law with friction present).
    pub fn switches(&self) -> bool {
        matches!(self.law, FrictionLaw::Switched) && self.mu_d > 0.0
    }

    /// Eq. 10's static limit `mu_s F_n` (N).
    #[inline]
    pub fn static_limit_n(&self, normal_n: f64) -> f64 {
        self.mu_s * normal_n
    }

    /// The friction force on the race along +t (N) in friction state `slip`, eq. 8 (or its
    /// regularisation); `None` while sticking under the switched law, where the force is the
    /// rolling constraint's (eq. 9), which only the whole model can solve for.
    #[inline]
    pub fn force(&self, slip: Slip, normal_n: f64, v_rel_m_s: f64) -> Option<f64> {
        match (self.law, slip) {
            (FrictionLaw::Regularised { v_eps_m_s }, _) => {
                Some(self.mu_d * normal_n * (v_rel_m_s / v_eps_m_s).tanh())
            }
            (FrictionLaw::Switched, Slip::Slipping(sign)) => Some(self.mu_d * normal_n * sign),
            (FrictionLaw::Switched, Slip::Sticking) => None,
        }
    }

    /// The derivatives of [`Friction::force`] in the normal force and the slip velocity.
    #[inline]
    pub fn slopes(&self, slip: Slip, normal_n: f64, v_rel_m_s: f64) -> FrictionSlopes {
        match (self.law, slip) {
            (FrictionLaw::Regularised { v_eps_m_s }, _) => {
                let th = (v_rel_m_s / v_eps_m_s).tanh();
                FrictionSlopes::Smooth {
                    per_normal: self.mu_d * th,
                    per_slip_velocity: self.mu_d * normal_n * (1.0 - th * th) / v_eps_m_s,
                }
            }
            (FrictionLaw::Switched, Slip::Slipping(sign)) => FrictionSlopes::Proportional {
                per_normal: self.mu_d * sign,
            },
            (FrictionLaw::Switched, Slip::Sticking) => FrictionSlopes::Constraint,
        }
    }
}

/// Eq. 10: stick if the friction that keeps rolling is within the static limit, otherwise
/// slip along that friction's direction (the direction slip will then develop in).
pub fn stick_or_slip(required_n: f64, static_limit_n: f64) -> Slip {
    if required_n.abs() <= static_limit_n {
        Slip::Sticking
    } else {
        Slip::Slipping(if required_n >= 0.0 { 1.0 } else { -1.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_law_gives_eq8_and_leaves_sticking_to_the_constraint() {
        let f = Friction::new(FrictionLaw::Switched, 0.4, 0.5);
        assert!(f.switches());
        assert_eq!(f.force(Slip::Slipping(-1.0), 10.0, 3.0), Some(-4.0));
        assert_eq!(f.force(Slip::Sticking, 10.0, 0.0), None);
        assert_eq!(f.static_limit_n(10.0), 5.0);
        let r = Friction::new(FrictionLaw::Regularised { v_eps_m_s: 1.0 }, 0.4, 0.4);
        assert!(!r.switches());
        assert_eq!(r.force(Slip::Sticking, 10.0, 0.0), Some(0.0));
        assert!(!Friction::new(FrictionLaw::Switched, 0.0, 0.0).switches());
    }

    #[test]
    fn eq10_decides_by_the_static_limit() {
        assert_eq!(stick_or_slip(0.5, 1.0), Slip::Sticking);
        assert_eq!(stick_or_slip(-1.0, 1.0), Slip::Sticking);
        assert_eq!(stick_or_slip(1.5, 1.0), Slip::Slipping(1.0));
        assert_eq!(stick_or_slip(-1.5, 1.0), Slip::Slipping(-1.0));
    }
}
