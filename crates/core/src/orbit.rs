//! Decimated orbit recording: the only trajectory whirlmap keeps, and only when asked for.

use serde::{Deserialize, Serialize};

/// One recorded point of a drop's orbit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrbitSample {
    /// Time since release (s).
    pub t_s: f64,
    /// Rotor geometric centre minus race centre, x (m).
    pub x_rel_m: f64,
    /// Rotor geometric centre minus race centre, y (m; up is positive).
    pub y_rel_m: f64,
    /// Rotor-race normal contact force at that time (N, >= 0).
    pub contact_force_n: f64,
}

/// A recorded orbit: samples in time order plus what is needed to draw it.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Orbit {
    /// Radial clearance between rotor and race bore (m): the radius of the clearance circle.
    pub clearance_m: f64,
    /// The samples, in increasing time.
    pub samples: Vec<OrbitSample>,
}
