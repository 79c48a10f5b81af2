//! Coulomb friction with the paper's stick/slip switch, eqs. 8-10.

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
    fn eq10_decides_by_the_static_limit() {
        assert_eq!(stick_or_slip(0.5, 1.0), Slip::Sticking);
        assert_eq!(stick_or_slip(-1.0, 1.0), Slip::Sticking);
        assert_eq!(stick_or_slip(1.5, 1.0), Slip::Slipping(1.0));
        assert_eq!(stick_or_slip(-1.5, 1.0), Slip::Slipping(-1.0));
    }
}
