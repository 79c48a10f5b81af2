//! Heat generation, eqs. 14-17: where the drop's friction and bearing losses enter the network.
//!
//! The paper writes the bearing heat per contact (eqs. 15-16) with per-ball friction torques
//! `M_ij`, `M_oj` and spin moments `M_si`, `M_so` that it never defines. We derive them from the
//! Palmgren torque `M` of eqs. 11-13 (31), which is an empirical total: it already contains
//! rolling, sliding, spin and lubricant losses, so no spin moment is added on top of it
//! (`M_si = M_so = 0`, their loss is inside `M`).
//!
//! Per-ball split: each of the `z` balls carries `M_ij = M_oj = M / z` (the torque passes
//! through every ball from the inner to the outer ring). The heat at a contact is that torque
//! times the ring's speed *relative to the cage* [Harris Ch. 15], which replaces eq. 15's rotor
//! speed `omega_r`. With the outer ring fixed and the race at `omega_b`, the cage turns at
//! `omega_c = omega_b (1 - gamma) / 2`, `gamma = D_w cos(alpha_0) / d_m`, so
//!
//! - `H_i = sum_j M_ij |omega_b - omega_c| = M |omega_b| (1 + gamma) / 2`  (eq. 15)
//! - `H_o = sum_j M_oj |omega_c|           = M |omega_b| (1 - gamma) / 2`  (eq. 16)
//!
//! and `H_i + H_o = M |omega_b|`, the bearing's total power loss (the dynamic model's drag
//! work). At the defaults (`D_w` = 5.5 mm, `alpha_0` = 15 deg, `d_m` = 51 mm) `gamma` = 0.104:
//! 55.2 % of the bearing heat is made at the inner contact, 44.8 % at the outer.
//! `H_s = F_t v_rel` (eq. 17) is the rotor-race rub heat (eqs. 19-20 call it `H_r`).

/// The inner/outer split of the bearing's power loss (eqs. 15-16).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BearingHeatSplit {
    /// `gamma = D_w cos(alpha_0) / d_m`.
    pub gamma: f64,
}

impl BearingHeatSplit {
    /// From ball diameter, contact angle and pitch diameter (m, rad, m).
    pub fn new(ball_diameter_m: f64, contact_angle_rad: f64, pitch_diameter_m: f64) -> Self {
        Self {
            gamma: ball_diameter_m * contact_angle_rad.cos() / pitch_diameter_m,
        }
    }

    /// Share of the bearing's power loss made at the inner-race contact, `(1 + gamma) / 2`.
    pub fn inner_share(&self) -> f64 {
        0.5 * (1.0 + self.gamma)
    }

    /// `(H_i, H_o)` (W) for a bearing power loss `M |omega_b|` (W), eqs. 15-16.
    pub fn split(&self, bearing_power_w: f64) -> (f64, f64) {
        let h_i = bearing_power_w * self.inner_share();
        (h_i, bearing_power_w - h_i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_sums_to_the_bearing_loss_and_favours_the_inner_contact() {
        let s = BearingHeatSplit::new(5.5e-3, 15f64.to_radians(), 0.051);
        assert!((s.gamma - 0.10417).abs() < 1e-4, "{}", s.gamma);
        let (hi, ho) = s.split(100.0);
        assert!((hi + ho - 100.0).abs() < 1e-12);
        assert!((hi - 55.208).abs() < 1e-3, "{hi}");
    }
}
