//! Load distribution over the balls of the pair, and the relation between the per-ball Hertz
//! stiffness `K_n` and the lumped support stiffness `k2` the dynamics use.
//!
//! ## Ball loads (Harris & Kotzalas, *Essential Concepts of Bearing Technology*, 5th ed.,
//! ch. 7, rigid rings, small displacements)
//! The race centre is displaced by `r` in the direction `θ` relative to the outer ring (the
//! housing). A ball of a row at the angle `ψ_j = ψ_c + 2π j / Z` (`ψ_c` the cage angle) sees
//! the radial approach `r cos(ψ_j - θ)`; along its contact line, inclined at the contact
//! angle `α`, the approach is `δ_j = r cos α cos(ψ_j - θ)` (no axial displacement, zero
//! internal clearance), and its load is Hertz's `Q_j = K_n δ_j^1.5` for `δ_j > 0`, zero
//! otherwise: a 180° load zone. Each row carries the radial components `Q_j cos α`; their
//! axial components `Q_j sin α` are equal and opposite in the two rows of a face-to-face pair
//! under pure radial load, so the pair carries no axial load. This planar model has no axial
//! load of its own (the rotor's axial dynamics are not modelled).
//!
//! ## `K_n` and `k2`
//! The resultant of a row, with the ball sum replaced by its integral over the load zone
//! (`Σ_j → Z/(2π) ∫ dψ`), is
//!
//! ```text
//! F_row = Z K_n cos^2.5 α r^1.5 · (1/2π) ∫_{-π/2}^{π/2} cos^2.5 ψ dψ = Z K_n cos^2.5 α J_r r^1.5
//! J_r = J_r(ε = 0.5) = Γ(7/4) / (2 √π Γ(9/4)) = 0.228 828        (Harris's 0.2288)
//! ```
//!
//! along `θ`: the lumped law `F = k2 r^1.5` exactly, with
//!
//! ```text
//! k2 = i Z J_r cos^2.5 α K_n    ⇔    K_n = k2 / (i Z J_r cos^2.5 α)       (i = 2 rows)
//! ```
//!
//! The integral is the cage-angle average of the discrete sum, so the ball set reproduces
//! `k2 r^1.5` exactly on average over the cage position. At one cage position the discrete
//! sum ripples about it (the varying-compliance effect): for 22 balls a row, by at most
//! 1.5e-4 in magnitude and 1.2 mrad in direction (tests/bearing.rs).
//!
//! Stribeck's relation follows: the most loaded ball (on the load line) carries
//! `Q_max = K_n (r cos α)^1.5 = F_row / (Z J_r cos α) = 4.370 F_row / (Z cos α)`.

use super::geometry::BearingPair;
pub use super::geometry::RADIAL_INTEGRAL_ZERO_CLEARANCE;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Stribeck's factor for point contact and zero clearance, `1 / J_r(0.5) = 4.370`:
/// `Q_max = 4.37 F_r / (Z cos α)` (Harris & Kotzalas ch. 7; Stribeck 1901). The design rule
/// `5 F_r / (Z cos α)` (ISO 76) allows for clearance.
pub const STRIBECK_FACTOR: f64 = 1.0 / RADIAL_INTEGRAL_ZERO_CLEARANCE;

/// The ball set of the pair: `rows` identical rows of `balls_per_row` balls at the contact
/// angle `contact_angle_rad`, each ball a Hertz spring `Q = K_n δ^1.5` along its contact line.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BallSet {
    /// Per-ball stiffness `K_n` (N/m^1.5), inner and outer contacts in series.
    pub ball_stiffness_n_per_m1_5: f64,
    /// Balls per row `Z`.
    pub balls_per_row: u32,
    /// Rows `i`.
    pub rows: u32,
    /// Contact angle `α` (rad).
    pub contact_angle_rad: f64,
}

impl BallSet {
    /// The ball set whose resultant reproduces the pair's lumped stiffness `k2`
    /// ([`BearingPair::ball_stiffness_from_lumped_n_per_m1_5`]): the loads the dynamics'
    /// support force implies.
    pub fn from_lumped(pair: &BearingPair) -> Self {
        BallSet {
            ball_stiffness_n_per_m1_5: pair.ball_stiffness_from_lumped_n_per_m1_5(),
            balls_per_row: pair.balls_per_row,
            rows: pair.rows,
            contact_angle_rad: pair.contact_angle_rad,
        }
    }

    /// The ball set of Hertz's stiffness for this geometry
    /// ([`BearingPair::hertz_ball_stiffness_n_per_m1_5`]).
    pub fn from_hertz(pair: &BearingPair) -> Self {
        BallSet {
            ball_stiffness_n_per_m1_5: pair.hertz_ball_stiffness_n_per_m1_5(),
            ..BallSet::from_lumped(pair)
        }
    }

    /// The lumped stiffness `k2 = i Z J_r cos^2.5 α K_n` this ball set is equivalent to
    /// (N/m^1.5).
    pub fn lumped_stiffness_n_per_m1_5(&self) -> f64 {
        self.rows as f64
            * self.balls_per_row as f64
            * RADIAL_INTEGRAL_ZERO_CLEARANCE
            * self.contact_angle_rad.cos().powf(2.5)
            * self.ball_stiffness_n_per_m1_5
    }

    /// Approach along the contact line of a ball at the angle `psi_rad` (m) for the race
    /// displacement `(dx_m, dy_m)` relative to the outer ring: `cos α (dx cos ψ + dy sin ψ)`;
    /// negative means the ball is unloaded.
    pub fn approach_m(&self, dx_m: f64, dy_m: f64, psi_rad: f64) -> f64 {
        self.contact_angle_rad.cos() * (dx_m * psi_rad.cos() + dy_m * psi_rad.sin())
    }

    /// Normal load of a ball at the angle `psi_rad` (N): `K_n δ^1.5` for `δ > 0`.
    pub fn ball_load_n(&self, dx_m: f64, dy_m: f64, psi_rad: f64) -> f64 {
        let d = self.approach_m(dx_m, dy_m, psi_rad);
        if d > 0.0 {
            self.ball_stiffness_n_per_m1_5 * d * d.sqrt()
        } else {
            0.0
        }
    }

    /// Angle of ball `j` of a row with the cage at `cage_angle_rad`: `ψ_c + 2π j / Z`.
    pub fn ball_angle_rad(&self, cage_angle_rad: f64, j: u32) -> f64 {
        cage_angle_rad + 2.0 * PI * j as f64 / self.balls_per_row as f64
    }

    /// The normal loads of the balls of one row (N), ball `j` at
    /// [`Self::ball_angle_rad`]; every row of the pair carries the same loads. `out` must
    /// hold `balls_per_row` values.
    pub fn row_loads(&self, dx_m: f64, dy_m: f64, cage_angle_rad: f64, out: &mut [f64]) {
        assert_eq!(out.len(), self.balls_per_row as usize);
        for (j, q) in out.iter_mut().enumerate() {
            *q = self.ball_load_n(dx_m, dy_m, self.ball_angle_rad(cage_angle_rad, j as u32));
        }
    }

    /// The radial resultant of the whole ball set on the race (N), `[x, y]`, pointing along
    /// the displacement (it pushes the race back with the opposite sign): the sum over the
    /// balls of both rows of `Q_j cos α (cos ψ_j, sin ψ_j)`, the rows' cages at the same
    /// angle.
    pub fn resultant_n(&self, dx_m: f64, dy_m: f64, cage_angle_rad: f64) -> [f64; 2] {
        let c = self.contact_angle_rad.cos();
        let (mut fx, mut fy) = (0.0, 0.0);
        for j in 0..self.balls_per_row {
            let psi = self.ball_angle_rad(cage_angle_rad, j);
            let q = self.ball_load_n(dx_m, dy_m, psi);
            fx += q * c * psi.cos();
            fy += q * c * psi.sin();
        }
        let rows = self.rows as f64;
        [rows * fx, rows * fy]
    }

    /// The load of a ball on the load line (N), `K_n (r cos α)^1.5`: the most loaded ball
    /// when the cage puts one there, an upper bound at any cage position (the discrete
    /// maximum is at least `cos^1.5(π/Z)` of it: 0.985 for 22 balls).
    pub fn max_ball_load_n(&self, dx_m: f64, dy_m: f64) -> f64 {
        let r = dx_m.hypot(dy_m);
        let d = r * self.contact_angle_rad.cos();
        self.ball_stiffness_n_per_m1_5 * d * d.sqrt()
    }

    /// The same maximum ball load from the radial force the pair carries (N):
    /// `Q_max = F / (i Z J_r cos α)`, Stribeck's `4.37 F_row / (Z cos α)` per row.
    pub fn max_ball_load_from_force_n(&self, force_n: f64) -> f64 {
        force_n
            / (self.rows as f64
                * self.balls_per_row as f64
                * RADIAL_INTEGRAL_ZERO_CLEARANCE
                * self.contact_angle_rad.cos())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(1/2π) ∫_{-π/2}^{π/2} cos^p ψ dψ` by composite Simpson on `[0, π/2]` after the
    /// substitution `ψ = π/2 (1 - u²)`, which removes the endpoint kink.
    fn cos_power_mean(p: f64) -> f64 {
        let n = 20_000;
        let h = 1.0 / n as f64;
        let f = |u: f64| (0.5 * PI * (1.0 - u * u)).cos().max(0.0).powf(p) * PI * u;
        let mut s = f(0.0) + f(1.0);
        for k in 1..n {
            s += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        2.0 * (s * h / 3.0) / (2.0 * PI)
    }

    #[test]
    fn radial_integral_is_harris_value() {
        let j = cos_power_mean(2.5);
        assert!(
            (j - RADIAL_INTEGRAL_ZERO_CLEARANCE).abs() < 1e-12,
            "J_r {j}"
        );
        assert!((RADIAL_INTEGRAL_ZERO_CLEARANCE - 0.2288).abs() < 5e-5);
        assert!((STRIBECK_FACTOR - 4.37).abs() < 5e-3);
    }

    #[test]
    fn load_zone_is_half_the_circle_and_symmetric() {
        let b = BallSet::from_lumped(&BearingPair::default());
        let mut q = vec![0.0; 22];
        b.row_loads(1e-5, 0.0, 0.0, &mut q);
        let loaded = q.iter().filter(|&&x| x > 0.0).count();
        assert_eq!(loaded, 11, "ball 0 on the load line and 5 on each side");
        for j in 1..11 {
            assert!((q[j] - q[22 - j]).abs() <= 1e-12 * q[0]);
        }
        assert!((q[0] - b.max_ball_load_n(1e-5, 0.0)).abs() < 1e-12 * q[0]);
    }
}
