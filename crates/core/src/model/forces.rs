//! The forces of one state in one mode: the contact geometry, eq. 7 at the rotor-race contact
//! and at the ball support, the Palmgren drag torque (eqs. 11-13, with eq. 31's thermal
//! load), the friction (eqs. 8-10), the powers of eq. 17, and the accelerations of eqs. 1-6.

use super::friction::Slip;
use super::state::{ix, Mode, N};
use super::{drag, hertz, DropSystem};
use nalgebra::Vector2;

/// Everything the model computes at one state in one mode.
#[derive(Debug, Clone, Copy, Default)]
pub struct Forces {
    /// Contact normal n (unit, from race centre towards rotor centre).
    pub n: Vector2<f64>,
    /// Contact tangent t = (-n_y, n_x).
    pub t: Vector2<f64>,
    /// |O_r - O_b| (m).
    pub dist_m: f64,
    /// Penetration delta = |d| - s (m).
    pub delta_m: f64,
    /// Penetration rate (m/s).
    pub delta_dot_m_s: f64,
    /// Slip velocity at the contact (m/s).
    pub v_rel_m_s: f64,
    /// Normal force F_n (N), eq. 7 (0 unless the contact is active).
    pub normal_n: f64,
    /// Eq. 7's force before the never-pull switch (N); continued to delta < 0 for guards.
    pub normal_raw_n: f64,
    /// Friction force F_t on the race along +t (N); the rotor gets its opposite.
    pub friction_n: f64,
    /// While sticking: the friction that keeps v_rel = 0 (N).
    pub friction_required_n: f64,
    /// Ball support force magnitude (N), pushing the race towards the housing centre.
    pub support_n: f64,
    /// Support force before the never-pull switch (N).
    pub support_raw_n: f64,
    /// Palmgren drag torque on the race (N m, signed, opposing omega_b).
    pub drag_torque_n_m: f64,
    /// The drag torque's two powers at this state (zero without drag), kept for the
    /// Jacobian at the same state.
    pub drag_powers: drag::DragPowers,
    /// `sign(delta) |delta|^e1`, the elastic term of eq. 7 at the rotor-race contact over its
    /// stiffness (zero with the quasi-static race), kept for the Jacobian at the same state.
    pub contact_pow: f64,
    /// H_s = F_t v_rel (W), eq. 17.
    pub friction_power_w: f64,
    /// Bearing drag power M |omega_b| (W): the bearing's share of eq. 14's H.
    pub bearing_power_w: f64,
    /// Damper power (W) of both contacts.
    pub damping_power_w: f64,
    /// Accelerations: rotor (x, y, theta), race (x, y, theta).
    pub acc: [f64; 6],
}

impl DropSystem {
    /// Accelerations for given contact forces (eqs. 1-6 solved for the second derivatives).
    ///
    /// Rotor with unbalance: generalised coordinates are the geometric centre and the angle;
    /// the mass centre is at `O_r + e (cos psi, sin psi)`, `psi = theta + phase`. Lagrange's
    /// equations give eqs. 1-2 as printed and, eliminating the centre accelerations,
    /// `J theta'' = tau + e (F_x sin psi - F_y cos psi)` with `tau = -F_t r_r` and `F` the
    /// contact force on the rotor. Printed eq. 3 writes `- m g e cos theta` for the last term:
    /// the same thing when the contact carries the weight (`F_y = m g`), which is the
    /// approximation the paper made; we keep the exact form.
    #[inline]
    fn accelerations(&self, y: &[f64; N], f: &Forces, ft: f64, support: Vector2<f64>) -> [f64; 6] {
        // The contact force on the race; the rotor gets its opposite.
        let fc = f.normal_n * f.n + ft * f.t;
        let tau = -ft * self.r_r;
        let (ax_r, ay_r, al_r);
        if self.e == 0.0 {
            al_r = tau / self.j_r;
            ax_r = -fc.x / self.m_r;
            ay_r = -fc.y / self.m_r - self.g;
        } else {
            let (sp, cp) = (y[ix::TR] + self.phase).sin_cos();
            let w2 = y[ix::WR] * y[ix::WR];
            al_r = (tau + self.e * (-fc.x * sp + fc.y * cp)) / self.j_r;
            ax_r = -fc.x / self.m_r + self.e * (al_r * sp + w2 * cp);
            ay_r = -fc.y / self.m_r - self.g - self.e * (al_r * cp - w2 * sp);
        }
        let (ax_b, ay_b) = if self.series.is_some() {
            // Massless race translation: the race centre stays at the housing centre in
            // the state; its displacement lives in the series split.
            (0.0, 0.0)
        } else {
            let a = (fc + support) / self.m_b;
            (a.x, a.y - self.g)
        };
        let al_b = (ft * self.r_b + f.drag_torque_n_m) / self.j_b;
        [ax_r, ay_r, al_r, ax_b, ay_b, al_b]
    }

    /// d(v_rel)/dt for given accelerations (differentiating eq. 9's slip velocity; the
    /// tangent turns with the contact angle, `t' = -(v_t/|d|) n`).
    #[inline]
    fn slip_acceleration(&self, f: &Forces, v_t: f64, a: &[f64; 6]) -> f64 {
        Vector2::new(a[0] - a[3], a[1] - a[4]).dot(&f.t) - v_t * f.delta_dot_m_s / f.dist_m
            + a[2] * self.r_r
            - a[5] * self.r_b
    }

    /// All forces, powers and accelerations at `y` in mode `mode`.
    pub fn forces_in(&self, y: &[f64; N], mode: Mode) -> Forces {
        let mut f = Forces::default();
        self.fill_forces(y, mode, &mut f);
        f
    }

    /// [`DropSystem::forces_in`], written into `out` (the memo's slot) instead of returned:
    /// a returned [`Forces`] is copied once more on the way.
    pub(super) fn fill_forces(&self, y: &[f64; N], mode: Mode, out: &mut Forces) {
        *out = Forces::default();
        let f = out;
        // d = O_r - O_b, n = d / |d|, t = (-n_y, n_x), w = v_r - v_b.
        let d = Vector2::new(y[ix::XR] - y[ix::XB], y[ix::YR] - y[ix::YB]);
        let dist = d.norm();
        f.dist_m = dist;
        f.n = if dist > 0.0 {
            d / dist
        } else {
            Vector2::new(0.0, -1.0)
        };
        f.t = Vector2::new(-f.n.y, f.n.x);
        let w = Vector2::new(y[ix::VXR] - y[ix::VXB], y[ix::VYR] - y[ix::VYB]);
        f.delta_m = dist - self.s;
        f.delta_dot_m_s = w.dot(&f.n);
        let v_t = w.dot(&f.t);
        f.v_rel_m_s = v_t + y[ix::WR] * self.r_r - y[ix::WB] * self.r_b;
        // Quasi-static race: the series springs' force and the split damper (see
        // `quasi_static`); otherwise eq. 7 between rotor and race.
        let mut c_contact = self.c1;
        if let Some(ss) = &self.series {
            let sp = ss.split(f.delta_m);
            let w = sp.w_contact;
            c_contact = self.c1 * w * w + self.c2 * (1.0 - w) * (1.0 - w);
            f.normal_raw_n = sp.force_n + c_contact * f.delta_dot_m_s;
        } else {
            // `hertz::raw_force`, with its power kept.
            f.contact_pow = hertz::signed_pow(f.delta_m, self.e1);
            f.normal_raw_n = self.k1 * f.contact_pow + self.c1 * f.delta_dot_m_s;
        }
        if mode.contact {
            f.normal_n = f.normal_raw_n;
        }

        // Ball support: isotropic, zero clearance, eq. 7 with e = 3/2 and c2.
        let b = Vector2::new(y[ix::XB], y[ix::YB]);
        let r = b.norm();
        let mut support_vec = Vector2::zeros();
        let mut r_dot = 0.0;
        let mut tangential_power_w = 0.0;
        if self.series.is_some() {
            // The support carries the contact force; its guard never fires.
            f.support_raw_n = self.f_ref_b;
            f.support_n = f.normal_n.max(0.0);
        } else if r > 0.0 {
            let nb = b / r;
            let vb = Vector2::new(y[ix::VXB], y[ix::VYB]);
            r_dot = vb.dot(&nb);
            f.support_raw_n = hertz::raw_force(self.k2, self.e2, self.c2, r, r_dot);
            if mode.support {
                f.support_n = f.support_raw_n;
                support_vec = -f.support_n * nb;
                if self.c2_t > 0.0 {
                    // Isotropic damper: c2 also on the race velocity across nb.
                    let vt = vb - r_dot * nb;
                    support_vec -= self.c2_t * vt;
                    tangential_power_w = self.c2_t * vt.norm_squared();
                }
            }
        }

        // Palmgren drag (eqs. 11-13) on the race, P1 = the support force; eq. 31 adds the
        // thermally induced load (exactly 0.0 without a thermal model, so no bit changes).
        let wb = y[ix::WB];
        if let Some(p) = &self.drag {
            f.drag_powers = p.powers(wb, f.support_n + self.thermal_load_n);
            let m = p.torque_from(f.drag_powers);
            let dir = drag::direction(wb, self.omega_eps);
            f.drag_torque_n_m = -m * dir;
            f.bearing_power_w = m * dir * wb;
        }

        // Friction: the law of [`super::friction`] (eq. 8), or the rolling constraint of eq. 9
        // while sticking.
        let ft = if !mode.contact {
            0.0
        } else {
            match self.friction.force(mode.slip, f.normal_n, f.v_rel_m_s) {
                Some(ft) => ft,
                None => {
                    // Sticking: v_rel' is affine in F_t; solve v_rel' = 0 (eq. 9).
                    let a0 = self.accelerations(y, f, 0.0, support_vec);
                    let a1 = self.accelerations(y, f, 1.0, support_vec);
                    let s0 = self.slip_acceleration(f, v_t, &a0);
                    let s1 = self.slip_acceleration(f, v_t, &a1);
                    -s0 / (s1 - s0)
                }
            }
        };
        if mode.contact && mode.slip == Slip::Sticking {
            f.friction_required_n = ft;
        }
        f.friction_n = ft;
        f.friction_power_w = ft * f.v_rel_m_s;
        f.damping_power_w = if mode.contact {
            c_contact * f.delta_dot_m_s * f.delta_dot_m_s
        } else {
            0.0
        } + if mode.support {
            self.c2 * r_dot * r_dot + tangential_power_w
        } else {
            0.0
        };
        f.acc = self.accelerations(y, f, ft, support_vec);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{hertz, DropSystem};
    use super::*;
    use crate::Scene;

    #[test]
    fn kept_powers_are_the_powers_at_that_state() {
        // The Jacobian reads `contact_pow` and `drag_powers` from the force model's evaluation
        // at its own state and mode instead of taking the powers again, so they must have the
        // bits of the powers taken afresh there: at the penetration, and at the race's spin and
        // the drag's load (the support force plus a thermal load). In contact and out of it,
        // in every slip mode, on and off the support, at speeds above and below eq. 12's
        // switch.
        let mut sys = DropSystem::new(&Scene::paper());
        sys.thermal_load_n = 37.5;
        let p = sys.drag.expect("the paper's scene has drag");
        let s = sys.clearance_m();
        let mut checked = 0;
        for (gap_m, wb) in [
            (0.2e-6, 300.0),
            (-1e-6, 300.0),
            (0.5e-6, 0.05),
            (0.0, -40.0),
        ] {
            let mut y = [0.0; N];
            y[ix::YB] = -3.7e-6;
            y[ix::XR] = 0.4e-6;
            y[ix::YR] = y[ix::YB] - (s + gap_m);
            y[ix::VXR] = 0.01;
            y[ix::VYR] = -0.02;
            y[ix::VXB] = 0.003;
            y[ix::WR] = 800.0;
            y[ix::WB] = wb;
            for contact in [true, false] {
                for support in [true, false] {
                    for slip in [Slip::Sticking, Slip::Slipping(1.0), Slip::Slipping(-1.0)] {
                        let mode = Mode {
                            contact,
                            support,
                            slip,
                        };
                        let f = sys.forces_in(&y, mode);
                        let pow = hertz::signed_pow(f.delta_m, sys.e1);
                        assert_eq!(f.contact_pow.to_bits(), pow.to_bits(), "{mode:?}");
                        let fresh = p.powers(wb, f.support_n + sys.thermal_load_n);
                        let kept = f.drag_powers;
                        assert_eq!(
                            (kept.nu0_n_pow_2_3.to_bits(), kept.load_torque_n_m.to_bits()),
                            (
                                fresh.nu0_n_pow_2_3.to_bits(),
                                fresh.load_torque_n_m.to_bits()
                            ),
                            "{mode:?}, race spin {wb}"
                        );
                        // Not a vacuous comparison: the powers are there.
                        assert!(gap_m == 0.0 || pow != 0.0);
                        assert!(!support || kept.load_torque_n_m > 0.0);
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 48);
    }
}
