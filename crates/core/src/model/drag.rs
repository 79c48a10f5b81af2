//! Palmgren's drag torque of the touchdown ball bearing, eqs. 11-13 (with eq. 31's M_1 form
//! when a thermal load is added later). Catalogue units are converted here and only here:
//! M in N mm, d_m in mm, nu0 in mm^2/s, n in r/min, P1 and C0 in N.

use super::pow::pow;

/// Palmgren parameters in catalogue units, prepared once from a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Palmgren {
    /// f0: bearing type and lubrication factor.
    pub f0: f64,
    /// nu0: lubricant kinematic viscosity (mm^2/s).
    pub nu0_mm2_s: f64,
    /// d_m: pitch diameter (mm).
    pub dm_mm: f64,
    /// C0: basic static load rating (N).
    pub c0_n: f64,
}

/// The powers of the drag torque at one speed and load ([`Palmgren::powers`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DragPowers {
    /// Eq. 12's `(nu0 n)^(2/3)`, `nu0` in mm^2/s and `n` in r/min.
    pub nu0_n_pow_2_3: f64,
    /// Eq. 13's load part `M_1` (N m).
    pub load_torque_n_m: f64,
}

/// rad/s to r/min.
const RAD_S_TO_RPM: f64 = 30.0 / std::f64::consts::PI;

impl Palmgren {
    /// Viscous part M_0 (N m), eq. 12, at race speed `omega_rad_s`.
    ///
    /// Eq. 12 switches at `nu0 n = 2000`, where its branches differ by 0.8 % (2000^(2/3) =
    /// 158.7 against 160). We take the larger branch, `max((nu0 n)^(2/3), 160)`, which moves
    /// the switch to `nu0 n = 2024` where the branches meet: the torque is then continuous,
    /// and no integrator step straddles a jump. Differences stay below 0.8 % in that band.
    #[inline]
    pub fn viscous_torque_n_m(&self, omega_rad_s: f64) -> f64 {
        self.viscous_from_x23(self.nu0_n_pow_2_3(omega_rad_s))
    }

    /// `(nu0 n)^(2/3)` of eq. 12 at race speed `omega_rad_s`.
    #[inline]
    fn nu0_n_pow_2_3(&self, omega_rad_s: f64) -> f64 {
        let x = self.nu0_mm2_s * omega_rad_s.abs() * RAD_S_TO_RPM;
        // The model's own power (model/pow.rs), not libm's pow or cbrt.
        pow(x, 2.0 / 3.0)
    }

    /// M_0 (N m) of eq. 12 from `(nu0 n)^(2/3)`.
    #[inline]
    fn viscous_from_x23(&self, x23: f64) -> f64 {
        1e-7 * self.f0 * x23.max(160.0) * self.dm_mm.powi(3) * 1e-3
    }

    /// Load part M_1 = f_1 P_1 d_m (N m), eq. 13, with f_1 = 0.001 (P_0 / C_0)^0.33 and
    /// P_0 = P_1 = `load_n` (the instantaneous ball-support force;
    /// docs/model.md#palmgren-load-term).
    #[inline]
    pub fn load_torque_n_m(&self, load_n: f64) -> f64 {
        let p = load_n.max(0.0);
        if p == 0.0 {
            return 0.0;
        }
        let f1 = 0.001 * pow(p / self.c0_n, 0.33);
        f1 * p * self.dm_mm * 1e-3
    }

    /// The torque of [`Palmgren::torque_n_m`] and its slopes: `(M` (N m), `dM/d omega`
    /// (N m s), `dM/d load` (m)`)`. Eq. 12's M_0 grows as `|omega|^(2/3)` above its
    /// low-speed constant (flat below it); eq. 13's M_1 as `load^1.33`. Each power is taken
    /// once: the torque has the bits of [`Palmgren::torque_n_m`].
    pub fn torque_and_slopes(&self, omega_rad_s: f64, load_n: f64) -> (f64, f64, f64) {
        self.torque_and_slopes_from(self.powers(omega_rad_s, load_n), omega_rad_s, load_n)
    }

    /// The two powers of the torque at `(omega_rad_s, load_n)`: eq. 12's `(nu0 n)^(2/3)` and
    /// eq. 13's whole `M_1` (N m). [`Palmgren::torque_from`] and
    /// [`Palmgren::torque_and_slopes_from`] take them, so that the force model's evaluation
    /// and the Jacobian's at the same state take them once.
    #[inline]
    pub fn powers(&self, omega_rad_s: f64, load_n: f64) -> DragPowers {
        DragPowers {
            nu0_n_pow_2_3: self.nu0_n_pow_2_3(omega_rad_s),
            load_torque_n_m: self.load_torque_n_m(load_n),
        }
    }

    /// [`Palmgren::torque_n_m`] from [`Palmgren::powers`] at the same speed and load (the
    /// same bits).
    #[inline]
    pub fn torque_from(&self, pw: DragPowers) -> f64 {
        self.viscous_from_x23(pw.nu0_n_pow_2_3) + pw.load_torque_n_m
    }

    /// [`Palmgren::torque_and_slopes`] from [`Palmgren::powers`] at the same speed and load
    /// (the same bits).
    pub fn torque_and_slopes_from(
        &self,
        pw: DragPowers,
        omega_rad_s: f64,
        load_n: f64,
    ) -> (f64, f64, f64) {
        let x23 = pw.nu0_n_pow_2_3;
        let m0 = self.viscous_from_x23(x23);
        let m1 = pw.load_torque_n_m;
        let d_omega = if omega_rad_s != 0.0 && x23 > 160.0 {
            (2.0 / 3.0) * m0 / omega_rad_s
        } else {
            0.0
        };
        let d_load = if load_n > 0.0 {
            1.33 * m1 / load_n
        } else {
            0.0
        };
        (m0 + m1, d_omega, d_load)
    }

    /// Total drag torque magnitude M = M_0 + M_1 (N m), eq. 11.
    #[inline]
    pub fn torque_n_m(&self, omega_rad_s: f64, load_n: f64) -> f64 {
        self.viscous_torque_n_m(omega_rad_s) + self.load_torque_n_m(load_n)
    }
}

/// Direction factor of the drag torque: `tanh(omega / omega_eps)`. The drag opposes the race
/// speed; at zero speed a Coulomb-like sign would chatter, so it fades to zero linearly within
/// `omega_eps` (a documented scene parameter, default 0.1 rad/s, about 1 r/min).
#[inline]
pub fn direction(omega_rad_s: f64, omega_eps_rad_s: f64) -> f64 {
    let x = omega_rad_s / omega_eps_rad_s;
    // From |x| = 22 on, tanh is +-1 to the last bit (glibc returns exactly that there): the
    // common case of a spinning race skips the call.
    if x >= 22.0 {
        1.0
    } else if x <= -22.0 {
        -1.0
    } else {
        x.tanh()
    }
}

/// [`direction`] and its slope in `omega_rad_s` (s/rad).
pub fn direction_and_slope(omega_rad_s: f64, omega_eps_rad_s: f64) -> (f64, f64) {
    let d = direction(omega_rad_s, omega_eps_rad_s);
    let slope = if d.abs() < 1.0 {
        (1.0 - d * d) / omega_eps_rad_s
    } else {
        0.0
    };
    (d, slope)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bearing() -> Palmgren {
        Palmgren {
            f0: 2.0,
            nu0_mm2_s: 22.0,
            dm_mm: 51.0,
            c0_n: 10_000.0,
        }
    }

    #[test]
    fn slopes_match_central_differences() {
        let b = bearing();
        // Above eq. 12's low-speed constant, either sign of the speed; below it (flat).
        for omega in [-900.0, -50.0, 30.0, 400.0, 3000.0, 0.5] {
            for load in [0.0, 3.0, 500.0, 20_000.0] {
                let (m, dw, dl) = b.torque_and_slopes(omega, load);
                // The bits of the formulas as written before the powers were shared.
                let x = b.nu0_mm2_s * f64::abs(omega) * RAD_S_TO_RPM;
                let m0 = 1e-7 * b.f0 * pow(x, 2.0 / 3.0).max(160.0) * b.dm_mm.powi(3) * 1e-3;
                let p = f64::max(load, 0.0);
                let m1 = if p == 0.0 {
                    0.0
                } else {
                    0.001 * pow(p / b.c0_n, 0.33) * p * b.dm_mm * 1e-3
                };
                assert_eq!(m.to_bits(), (m0 + m1).to_bits());
                // The force model's torque from the kept powers: torque_n_m's bits.
                let pw = b.powers(omega, load);
                assert_eq!(
                    b.torque_from(pw).to_bits(),
                    b.torque_n_m(omega, load).to_bits()
                );
                let old_dw = if omega != 0.0 && pow(x, 2.0 / 3.0) > 160.0 {
                    (2.0 / 3.0) * m0 / omega
                } else {
                    0.0
                };
                let old_dl = if load > 0.0 { 1.33 * m1 / load } else { 0.0 };
                assert_eq!(
                    (dw.to_bits(), dl.to_bits()),
                    (old_dw.to_bits(), old_dl.to_bits())
                );
                let h = 1e-6 * f64::abs(omega);
                let fd_w =
                    (b.torque_n_m(omega + h, load) - b.torque_n_m(omega - h, load)) / (2.0 * h);
                assert!(
                    (dw - fd_w).abs() <= 1e-6 * fd_w.abs() + 1e-15,
                    "omega {omega}: {dw} {fd_w}"
                );
                if load > 0.0 {
                    let h = 1e-6 * load;
                    let fd_l =
                        (b.torque_n_m(omega, load + h) - b.torque_n_m(omega, load - h)) / (2.0 * h);
                    assert!(
                        (dl - fd_l).abs() <= 1e-6 * fd_l.abs(),
                        "load {load}: {dl} {fd_l}"
                    );
                } else {
                    assert_eq!(dl, 0.0);
                }
            }
        }
        for (omega, eps) in [
            (0.0, 0.1),
            (0.03, 0.1),
            (-0.25, 0.1),
            (1.5, 0.1),
            (5.0, 0.1),
        ] {
            let (d, slope) = direction_and_slope(omega, eps);
            assert_eq!(d, direction(omega, eps));
            let h = 1e-7;
            let fd = (direction(omega + h, eps) - direction(omega - h, eps)) / (2.0 * h);
            assert!(
                (slope - fd).abs() <= 1e-6 * fd.abs() + 1e-9,
                "omega {omega}: {slope} {fd}"
            );
        }
    }

    #[test]
    fn torque_matches_a_hand_computed_catalogue_example() {
        // n = 5000 r/min, nu0 = 22 cSt: nu0 n = 110 000, (110 000)^(2/3) = 2295.77;
        // M0 = 1e-7 * 2 * 2295.77 * 51^3 = 60.907 N mm.
        // P1 = 500 N: f1 = 0.001 * 0.05^0.33 = 3.72100e-4; M1 = f1 * 500 * 51 = 9.4886 N mm.
        let omega = 5000.0 / RAD_S_TO_RPM;
        let m0 = bearing().viscous_torque_n_m(omega) * 1e3;
        let m1 = bearing().load_torque_n_m(500.0) * 1e3;
        assert!((m0 - 60.907).abs() < 0.005, "M0 = {m0} N mm");
        assert!((m1 - 9.4886).abs() < 0.001, "M1 = {m1} N mm");
        assert!((bearing().torque_n_m(-omega, 500.0) * 1e3 - 70.396).abs() < 0.006);
    }

    #[test]
    fn low_speed_branch_is_the_constant_of_eq12_and_continuous() {
        // nu0 n <= 2000: M0 = 160e-7 f0 d_m^3 = 4.2448 N mm, whatever the speed.
        let b = bearing();
        assert!((b.viscous_torque_n_m(0.0) * 1e3 - 4.24483).abs() < 1e-4);
        assert!((b.viscous_torque_n_m(5.0) * 1e3 - 4.24483).abs() < 1e-4);
        // Continuity where the branches meet (nu0 n = 160^1.5 = 2023.9).
        let w = 160f64.powf(1.5) / 22.0 / RAD_S_TO_RPM;
        let (a, c) = (
            b.viscous_torque_n_m(w * (1.0 - 1e-9)),
            b.viscous_torque_n_m(w * (1.0 + 1e-9)),
        );
        assert!((a - c).abs() / a < 1e-8);
    }

    #[test]
    fn direction_is_odd_bounded_and_smooth_at_zero() {
        assert_eq!(direction(0.0, 0.1), 0.0);
        assert!((direction(10.0, 0.1) - 1.0).abs() < 1e-12);
        assert!((direction(-10.0, 0.1) + 1.0).abs() < 1e-12);
        assert!((direction(1e-4, 0.1) - 1e-3).abs() < 1e-8);
        // The shortcut beyond |x| = 22 gives tanh's own bits.
        for x in [21.99, 22.0, 22.5, 30.0, 1e3, 1e300, f64::INFINITY] {
            assert_eq!(direction(x, 1.0), x.tanh(), "{x}");
            assert_eq!(direction(-x, 1.0), (-x).tanh(), "{x}");
        }
    }
}
