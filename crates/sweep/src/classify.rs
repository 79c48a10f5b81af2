//! Orbit classification: a pure function of a drop's streamed features.
//!
//! The classes are the paper's (Sec. 1 and 4): pendulum vibration (the rotor rocks in the
//! bottom of the race in permanent contact), bouncing (repeated impacts with free flight
//! between), backward whirl (the contact point travels round the race against the spin),
//! plus forward whirl and `unresolved` for runs that decide nothing.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use whirlmap_core::{Features, StopReason};

/// The orbit class of one drop. Serialised names are part of the JSON contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrbitClass {
    /// Pendulum vibration: contact (nearly) all the time, rocking about the bottom.
    Pendulum,
    /// Combined rub and bouncing: contact less than the pendulum duty threshold.
    Bouncing,
    /// Whirl against the spin direction (the dangerous one).
    BackwardWhirl,
    /// Whirl with the spin direction.
    ForwardWhirl,
    /// Nothing decided: no touch, too short a window, or a contact angle that wanders
    /// beyond a pendulum's range without completing the whirl turns.
    Unresolved,
}

impl OrbitClass {
    /// The contract name (`pendulum`, `bouncing`, `backward_whirl`, ...).
    pub fn name(self) -> &'static str {
        match self {
            OrbitClass::Pendulum => "pendulum",
            OrbitClass::Bouncing => "bouncing",
            OrbitClass::BackwardWhirl => "backward_whirl",
            OrbitClass::ForwardWhirl => "forward_whirl",
            OrbitClass::Unresolved => "unresolved",
        }
    }
    /// Words for charts and summaries.
    pub fn label(self) -> &'static str {
        match self {
            OrbitClass::Pendulum => "pendulum vibration",
            OrbitClass::Bouncing => "bouncing",
            OrbitClass::BackwardWhirl => "backward whirl",
            OrbitClass::ForwardWhirl => "forward whirl",
            OrbitClass::Unresolved => "unresolved",
        }
    }
    /// Whether this is a whirl class.
    pub fn is_whirl(self) -> bool {
        matches!(self, OrbitClass::BackwardWhirl | OrbitClass::ForwardWhirl)
    }
}

/// Thresholds of the classifier. The window is the second half of the simulated time
/// (see `whirlmap_core::monitor`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClassifyParams {
    /// Net turns of the contact point (since first touch) that make a whirl, when the run
    /// was not already stopped by the scene's whirl rule. Default 3.
    pub whirl_turns: f64,
    /// Smallest window contact duty of a pendulum; below it the orbit is bouncing.
    /// Default 0.9.
    pub pendulum_min_duty: f64,
    /// Largest range of the contact angle within the window for a pendulum or bouncing
    /// orbit (rad). Default pi: beyond half a turn the rotor is no longer rocking about the
    /// bottom.
    pub max_rocking_range_rad: f64,
    /// Shortest window that may decide a non-whirl class (s). Default 0.02 s, several
    /// pendulum periods (the rocking period is about 10-20 ms at the default scene).
    pub min_window_s: f64,
}

impl Default for ClassifyParams {
    fn default() -> Self {
        Self {
            whirl_turns: 3.0,
            pendulum_min_duty: 0.9,
            max_rocking_range_rad: PI,
            min_window_s: 0.02,
        }
    }
}

/// Classifies one drop from its features and why it stopped.
pub fn classify(f: &Features, stop: StopReason, p: &ClassifyParams) -> OrbitClass {
    let whirl_sign = f.net_whirl_turns;
    if stop == StopReason::WhirlTurnsReached || whirl_sign.abs() >= p.whirl_turns {
        return if whirl_sign < 0.0 {
            OrbitClass::BackwardWhirl
        } else {
            OrbitClass::ForwardWhirl
        };
    }
    let w = &f.window;
    if f.first_contact_time_s.is_nan() || w.end_s - w.start_s < p.min_window_s {
        return OrbitClass::Unresolved;
    }
    let range = w.angle_max_rad - w.angle_min_rad;
    // NaN range (never near the wall in the window) with no contact: a rotor still falling.
    if !(range <= p.max_rocking_range_rad) || w.angle_mean_rad.abs() > 0.5 * PI {
        return OrbitClass::Unresolved;
    }
    if w.contact_duty >= p.pendulum_min_duty {
        OrbitClass::Pendulum
    } else {
        OrbitClass::Bouncing
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whirlmap_core::Window;

    fn features(duty: f64, amin: f64, amax: f64, turns: f64) -> Features {
        Features {
            first_contact_force_n: 880.0,
            max_contact_force_n: 900.0,
            max_contact_force_time_s: 0.006,
            peak_friction_power_w: 1000.0,
            peak_heat_power_w: 1001.0,
            impacts: 5,
            first_contact_time_s: 0.0055,
            contact_time_s: 0.4,
            net_whirl_turns: turns,
            whirl_frequency_hz: 0.0,
            window: Window {
                start_s: 0.5,
                end_s: 1.0,
                contact_duty: duty,
                angle_min_rad: amin,
                angle_max_rad: amax,
                angle_mean_rad: 0.5 * (amin + amax),
            },
            final_rotor_speed_rpm: 7700.0,
            final_race_speed_rpm: 7600.0,
        }
    }
    const P: ClassifyParams = ClassifyParams {
        whirl_turns: 3.0,
        pendulum_min_duty: 0.9,
        max_rocking_range_rad: PI,
        min_window_s: 0.02,
    };
    const END: StopReason = StopReason::DurationReached;

    #[test]
    fn permanent_contact_rocking_at_the_bottom_is_pendulum() {
        assert_eq!(
            classify(&features(1.0, -0.7, 0.5, 0.05), END, &P),
            OrbitClass::Pendulum
        );
    }

    #[test]
    fn intermittent_contact_at_the_bottom_is_bouncing() {
        assert_eq!(
            classify(&features(0.3, -0.2, 0.2, 0.0), END, &P),
            OrbitClass::Bouncing
        );
    }

    #[test]
    fn net_turns_against_the_spin_are_backward_whirl() {
        assert_eq!(
            classify(&features(0.9, -31.0, -3.0, -5.0), END, &P),
            OrbitClass::BackwardWhirl
        );
        // Stopped by the scene's rule with fewer turns than the classifier's own threshold.
        let stop = StopReason::WhirlTurnsReached;
        assert_eq!(
            classify(&features(0.9, -13.0, -3.0, -2.0), stop, &P),
            OrbitClass::BackwardWhirl
        );
    }

    #[test]
    fn net_turns_with_the_spin_are_forward_whirl() {
        assert_eq!(
            classify(&features(1.0, 3.0, 25.0, 4.0), END, &P),
            OrbitClass::ForwardWhirl
        );
    }

    #[test]
    fn undecided_runs_are_unresolved() {
        // Wandering over more than half a turn without completing the whirl turns.
        assert_eq!(
            classify(&features(1.0, -4.0, 0.0, -1.0), END, &P),
            OrbitClass::Unresolved
        );
        // Never touched.
        let mut f = features(0.0, f64::NAN, f64::NAN, 0.0);
        f.first_contact_time_s = f64::NAN;
        assert_eq!(classify(&f, END, &P), OrbitClass::Unresolved);
        // Too short a window.
        let mut f = features(1.0, -0.1, 0.1, 0.0);
        f.window.start_s = 0.99;
        assert_eq!(classify(&f, END, &P), OrbitClass::Unresolved);
    }
}
