//! Thermal expansion, eqs. 26-29, and the thermally induced load, eq. 30, that eq. 31 adds
//! to the Palmgren load torque.
//!
//! How the printed equations are resolved:
//! - **Eq. 26, inner race.** A ring from its bore `r_s` (at the race node's rise `dT_i`) to
//!   its raceway `r_i` (at the inner lubricant's `dT_Li`) with a linear temperature profile
//!   grows by `xi (1 + nu) r_s` times the profile's area-weighted mean rise,
//!   `[dT_i (2 r_s + r_i) + dT_Li (2 r_i + r_s)] / (3 (r_i + r_s))`. The paper prints the
//!   denominator `3 r_i + r_s`; with it a uniform rise `dT` would give
//!   `xi (1 + nu) r_s dT * 3 (r_s + r_i) / (3 r_i + r_s)`, about 1.5 times the free expansion,
//!   which no ring does. We use `3 (r_i + r_s)`, for which a uniform rise gives exactly
//!   `xi (1 + nu) r_s dT`.
//! - **Eq. 27, outer race, and its `r_j`.** The mirror of eq. 26: the outer race spans its
//!   raceway `r_j = r_e = d_m/2 + r_b` (at the outer lubricant's `dT_Le`) to its outside
//!   `r_o` (at the race node's `dT_j = dT_o`), each rise weighted at its own radius:
//!   `eps_o = xi (1 + nu) r_o [dT_Le (2 r_e + r_o) + dT_o (2 r_o + r_e)] / (3 (r_o + r_e))`.
//!   (Printed eq. 27 pairs `dT_Le` with `2 r_o + r_j`, putting the lubricant's weight at the
//!   outside radius; that only holds if `r_j` were the outside, which would leave the raceway
//!   with no radius at all.) Eq. 29's `eps_e` is this `eps_o`.
//! - **Eq. 28, balls:** `eps_b = xi r_b dT_b`, as printed.
//! - **Eq. 29:** `eps = eps_b + (eps_i - eps_o) cos(alpha_0) / 2`, as printed, plus a mounting
//!   fit interference (a parameter, default 0).
//! - **Eq. 30 reuses `F_t`**, the friction force of eq. 8, for the thermal load. We call it
//!   `F_th`: `F_th = k max(eps, 0)^1.5` (a contact that opens carries no load), with `k` the
//!   race-on-balls Hertz stiffness. Eq. 31 then reads `M_1 = f_1 (P_1 + F_th) d_m`, and we take
//!   `f_1` at `P_0 = P_1 + F_th` too (the induced load loads the balls like any other).

use super::network::{node, NODES};

/// Eq. 26 (resolved): inner race expansion (m) for rises `dt_race` at the bore `r_s` and
/// `dt_lub` at the raceway `r_i`.
pub fn inner_race_expansion_m(
    xi_per_k: f64,
    nu: f64,
    r_s_m: f64,
    r_i_m: f64,
    dt_race_k: f64,
    dt_lub_k: f64,
) -> f64 {
    xi_per_k * (1.0 + nu) * r_s_m / (3.0 * (r_i_m + r_s_m))
        * (dt_race_k * (2.0 * r_s_m + r_i_m) + dt_lub_k * (2.0 * r_i_m + r_s_m))
}

/// Eq. 27 (resolved): outer race expansion (m) for rises `dt_lub` at the raceway `r_e` and
/// `dt_race` at the outside `r_o`.
pub fn outer_race_expansion_m(
    xi_per_k: f64,
    nu: f64,
    r_o_m: f64,
    r_e_m: f64,
    dt_lub_k: f64,
    dt_race_k: f64,
) -> f64 {
    xi_per_k * (1.0 + nu) * r_o_m / (3.0 * (r_o_m + r_e_m))
        * (dt_lub_k * (2.0 * r_e_m + r_o_m) + dt_race_k * (2.0 * r_o_m + r_e_m))
}

/// Eq. 28: ball expansion (m).
pub fn ball_expansion_m(xi_per_k: f64, r_b_m: f64, dt_ball_k: f64) -> f64 {
    xi_per_k * r_b_m * dt_ball_k
}

/// Eq. 30: the thermally induced load `F_th = k max(eps, 0)^1.5` (N).
pub fn induced_load_n(k_n_per_m15: f64, interference_m: f64) -> f64 {
    let e = interference_m.max(0.0);
    k_n_per_m15 * e * e.sqrt()
}

/// Eqs. 26-30 prepared for one bearing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Expansion {
    /// Expansion coefficient xi (1/K).
    pub xi_per_k: f64,
    /// Poisson's ratio nu.
    pub nu: f64,
    /// Inner race bore radius r_s (m).
    pub r_s_m: f64,
    /// Inner raceway radius r_i (m).
    pub r_i_m: f64,
    /// Outer raceway radius r_e = r_j (m).
    pub r_e_m: f64,
    /// Outer race outside radius r_o (m).
    pub r_o_m: f64,
    /// Ball radius r_b (m).
    pub r_b_m: f64,
    /// cos(alpha_0).
    pub cos_alpha0: f64,
    /// Hertz stiffness k of eq. 30 (N/m^1.5).
    pub k_n_per_m15: f64,
    /// Mounting fit interference added to eq. 29 (m).
    pub fit_m: f64,
}

impl Expansion {
    /// Eq. 29's interference (m) at node temperature rises `dt_k`, fit included.
    pub fn interference_m(&self, dt_k: &[f64; NODES]) -> f64 {
        let eps_i = inner_race_expansion_m(
            self.xi_per_k,
            self.nu,
            self.r_s_m,
            self.r_i_m,
            dt_k[node::INNER_RACE],
            dt_k[node::INNER_LUBRICANT],
        );
        let eps_o = outer_race_expansion_m(
            self.xi_per_k,
            self.nu,
            self.r_o_m,
            self.r_e_m,
            dt_k[node::OUTER_LUBRICANT],
            dt_k[node::OUTER_RACE],
        );
        let eps_b = ball_expansion_m(self.xi_per_k, self.r_b_m, dt_k[node::BALLS]);
        self.fit_m + eps_b + 0.5 * (eps_i - eps_o) * self.cos_alpha0
    }

    /// Eq. 30's thermally induced load F_th (N) at rises `dt_k`.
    pub fn load_n(&self, dt_k: &[f64; NODES]) -> f64 {
        induced_load_n(self.k_n_per_m15, self.interference_m(dt_k))
    }
}
