//! The discrete side of the model: its named guards and its jump map over the [`Mode`]s (the paper's
//! eqs. 7-10 read as a hybrid system: a contact carries force while eq. 7's force is
//! positive, and the friction switches between slip, eq. 8, and stick, eqs. 9-10).

use super::forces::Forces;
use super::friction::{self, Slip};
use super::state::{ix, Mode, N};
use super::DropSystem;
use crate::ode::{GuardSet, Hybrid, MAX_GUARDS};

/// The guards of the model, each positive while its part of the [`Mode`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Guard {
    /// Rotor-race contact: onset while free, loss while in contact (eq. 7's force reaching
    /// zero, or the penetration).
    Contact,
    /// Race-on-balls support: release or re-seat (the support's eq. 7 force).
    Support,
    /// Friction switch while in contact under the switched law: the slip velocity's reversal
    /// while slipping (eq. 8), the friction demand exceeding `mu_s F_n` while sticking
    /// (eq. 10).
    Friction,
}

impl Guard {
    /// The guard's slot in the array [`crate::ode::OdeSystem::guards`] fills.
    #[inline]
    pub const fn index(self) -> usize {
        self as usize
    }
}

impl GuardSet for Guard {
    const ALL: &'static [Self] = &[Guard::Contact, Guard::Support, Guard::Friction];
}

impl DropSystem {
    /// The guards of [`OdeSystem::guards`] from the forces at the state.
    #[inline]
    pub(super) fn guards_of(&self, f: &Forces, g: &mut [f64; MAX_GUARDS]) -> usize {
        let c = self.contact_indicator(f);
        g[Guard::Contact.index()] = if self.mode.contact { c } else { -c };
        let sup = f.support_raw_n / self.f_ref_b;
        g[Guard::Support.index()] = if self.mode.support { sup } else { -sup };
        if self.mode.contact && self.friction.switches() {
            g[Guard::Friction.index()] = match self.mode.slip {
                Slip::Slipping(sign) => sign * f.v_rel_m_s,
                Slip::Sticking => {
                    (self.friction.static_limit_n(f.normal_n) - f.friction_required_n.abs())
                        / self.f_ref
                }
            };
            3
        } else {
            2
        }
    }

    /// Contact guard: `min(delta / s, F_raw / F_ref)`, positive exactly when eq. 7's force
    /// is active (penetrating, and the damper not pulling). Continuous in the state.
    #[inline]
    fn contact_indicator(&self, f: &Forces) -> f64 {
        (f.delta_m / self.s).min(f.normal_raw_n / self.f_ref)
    }

    /// The friction mode to enter at a state in contact, per eqs. 9-10: slip along the slip
    /// velocity's sign, unless it is (numerically) zero, in which case stick if the friction
    /// that keeps rolling is at most `mu_s F_n`, else slip along that friction's sign.
    /// `at_zero` forces the stick test (the state sits at a located v_rel = 0 crossing).
    pub fn entering_slip(&self, y: &[f64; N], at_zero: bool) -> Slip {
        if !self.friction.switches() {
            return Slip::Slipping(1.0);
        }
        let mode = Mode {
            contact: true,
            support: self.mode.support,
            slip: Slip::Sticking,
        };
        let f = self.forces_in(y, mode);
        let v_scale = 1e-9 * (1.0 + y[ix::WR].abs() * self.r_r);
        if !at_zero && f.v_rel_m_s.abs() > v_scale {
            return Slip::Slipping(f.v_rel_m_s.signum());
        }
        friction::stick_or_slip(
            f.friction_required_n,
            self.friction.static_limit_n(f.normal_n.max(0.0)),
        )
    }

    /// The jump map: the mode after `guard` crossed at state `y` (eqs. 7-10). A contact
    /// onset enters slip or stick by [`DropSystem::entering_slip`]; a support crossing only
    /// toggles the support; a friction crossing re-decides stick or slip at the located
    /// `v_rel = 0` (from slip), or slips along the friction demand (from stick).
    pub fn jump(&self, guard: Guard, y: &[f64; N]) -> Mode {
        let mut m = self.mode;
        match guard {
            Guard::Contact => {
                m.contact = !m.contact;
                if m.contact {
                    m.slip = self.entering_slip(y, false);
                }
            }
            Guard::Support => m.support = !m.support,
            Guard::Friction => {
                m.slip = match m.slip {
                    Slip::Slipping(_) => self.entering_slip(y, true),
                    Slip::Sticking => {
                        let req = self.forces(y).friction_required_n;
                        Slip::Slipping(if req >= 0.0 { 1.0 } else { -1.0 })
                    }
                };
            }
        }
        // Every slip entered here (at a contact onset or a friction switch, including a slip
        // that keeps its sign through a located reversal) starts consistent.
        if guard != Guard::Support && m.contact {
            if let Slip::Slipping(sign) = m.slip {
                m.slip = Slip::Slipping(self.slip_along_drift(y, m, sign));
            }
        }
        m
    }

    /// The sign of a slip entered at a contact onset or a friction switch (eqs. 9-10), made
    /// consistent with the slip velocity actually there.
    ///
    /// Slip starts along the friction demand (or along `v_rel` at an onset). But a sticking
    /// contact holds `v_rel` only through its acceleration, so `v_rel` drifts by the
    /// integration error while it sticks, and a reversal is located only to within the root
    /// tolerance. If that small `v_rel` points against the demand, the new mode's guard
    /// (`sign * v_rel`) starts negative; the event loop watches a guard only from zero or
    /// above, so it would never see it, and the friction, pushing along the slip instead of
    /// against it, would make energy (measured before this rule: -1085 J of "friction heat"
    /// in a 1 s drop at a loose tolerance). So the slip takes the sign of `v_rel` there:
    /// friction then opposes it, `v_rel` returns through zero at once, and that reversal
    /// event re-enters the slip along the demand.
    fn slip_along_drift(&self, y: &[f64; N], mode: Mode, sign: f64) -> f64 {
        let v_rel = self.forces_in(y, mode).v_rel_m_s;
        if sign * v_rel < 0.0 {
            -sign
        } else {
            sign
        }
    }
}

impl Hybrid<N> for DropSystem {
    type Mode = Mode;
    fn mode(&self) -> Mode {
        self.mode
    }
    fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
    }
    fn jump(&self, guard: Guard, y: &[f64; N]) -> Mode {
        DropSystem::jump(self, guard, y)
    }
}
