//! The model's state: the layout of the 15-number continuous state (see [`ix`]) and the
//! discrete [`Mode`].

use super::friction::Slip;

/// State layout: rotor (x, y, theta), race (x, y, theta), their rates, then three energy
/// accumulators integrated with the state so the energy audit sees the same error control.
pub mod ix {
    /// Rotor geometric centre x (m).
    pub const XR: usize = 0;
    /// Rotor geometric centre y (m).
    pub const YR: usize = 1;
    /// Rotor rotation angle (rad).
    pub const TR: usize = 2;
    /// Race centre x (m).
    pub const XB: usize = 3;
    /// Race centre y (m).
    pub const YB: usize = 4;
    /// Race rotation angle (rad).
    pub const TB: usize = 5;
    /// Rotor centre velocity x (m/s).
    pub const VXR: usize = 6;
    /// Rotor centre velocity y (m/s).
    pub const VYR: usize = 7;
    /// Rotor spin (rad/s).
    pub const WR: usize = 8;
    /// Race velocity x (m/s).
    pub const VXB: usize = 9;
    /// Race velocity y (m/s).
    pub const VYB: usize = 10;
    /// Race spin (rad/s).
    pub const WB: usize = 11;
    /// Friction heat at the rotor-race contact, integral of H_s = F_t v_rel (J), eq. 17.
    pub const E_FRIC: usize = 12;
    /// Energy dissipated by the two contact dampers (J).
    pub const E_DAMP: usize = 13;
    /// Work of the Palmgren drag torque, integral of M |omega_b| (J): the bearing's heat.
    pub const E_DRAG: usize = 14;
}
/// State dimension.
pub const N: usize = 15;

/// The discrete mode: which contacts carry force and how the rotor-race contact rubs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Rotor-race contact active (eq. 7 force on).
    pub contact: bool,
    /// Race-on-balls support active (its damper never pulls either).
    pub support: bool,
    /// Friction state of the rotor-race contact while `contact`.
    pub slip: Slip,
}
