//! Decimated orbit recording: the only trajectory whirlmap keeps, and only when asked for.
//! Each sample holds the rotor's path relative to the race (the Fig. 3 view) and the time
//! series a designer reads beside it: the race centre, the contact force, the slip velocity,
//! the heat power and both spins.

use serde::{Deserialize, Serialize};

/// One recorded point of a drop's orbit.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct OrbitSample {
    /// Time since release (s).
    pub t_s: f64,
    /// Rotor geometric centre minus race centre, x (m).
    pub x_rel_m: f64,
    /// Rotor geometric centre minus race centre, y (m; up is positive).
    pub y_rel_m: f64,
    /// Rotor-race normal contact force at that time (N, >= 0).
    pub contact_force_n: f64,
    /// Race centre x relative to the housing centre (m); the rotor centre is this plus
    /// `x_rel_m`.
    #[serde(default)]
    pub x_race_m: f64,
    /// Race centre y relative to the housing centre (m; up is positive).
    #[serde(default)]
    pub y_race_m: f64,
    /// Slip velocity at the contact, `v_rel` of eq. 9 (m/s): zero while the contact rolls.
    #[serde(default)]
    pub slip_m_s: f64,
    /// Total heat power H = H_s + bearing drag power (W), eqs. 14 and 17.
    #[serde(default)]
    pub heat_power_w: f64,
    /// Rotor spin (rad/s).
    #[serde(default)]
    pub rotor_speed_rad_s: f64,
    /// Race spin (rad/s).
    #[serde(default)]
    pub race_speed_rad_s: f64,
}

/// A recorded orbit: samples in time order plus what is needed to draw it.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Orbit {
    /// Radial clearance between rotor and race bore (m): the radius of the clearance circle.
    pub clearance_m: f64,
    /// The samples, in increasing time.
    pub samples: Vec<OrbitSample>,
}
