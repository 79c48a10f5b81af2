//! Orbit classification: a pure function of a drop's streamed features.
//!
//! The classes are the paper's (Secs. 1 and 4): pendulum vibration (the rotor rocks in the
//! bottom of the race with the contact carried), bouncing (repeated impacts with free flight
//! between), backward whirl (the contact point travels round the race against the spin),
//! plus forward whirl and `unresolved`.
//!
//! A class describes the motion the rotor *settles into*, not what it did on the way:
//!
//! - **Whirl** is sustained travel of the contact point with the contact carried: either
//!   `whirl_stop_turns` consecutive turns in one direction, each with a contact duty of at
//!   least [`ClassifyParams::min_duty`] (the drop is stopped there: in a rigid housing whirl
//!   only grows), or, on the final window, at least [`ClassifyParams::whirl_half_turns`] net
//!   turns in the same direction in each half of the window with the contact carried.
//! - **Pendulum vibration** and **bouncing** are decided on the final window
//!   ([`ClassifyParams::window_s`]): in each of its two halves the contact angle rocks about
//!   the bottom (circular mean in the lower half of the race, unwrapped range at most
//!   [`ClassifyParams::max_rocking_range_rad`], less than the whirl travel), the two halves'
//!   circular means agree within [`ClassifyParams::max_drift_rad`], and the contact duty is
//!   at least `min_duty` in both halves (pendulum) or below it in both (bouncing).
//! - Anything else has **not settled**: the drop is extended (in steps of half a window, up
//!   to [`ClassifyParams::max_extension_s`] past its duration) and classified again. A run
//!   still unsettled at the cap is `unresolved`, with the reason.
//!
//! Turns made before the rotor settles are reported as `transient_whirl_turns`, never as a
//! class. Angle statistics are taken on the circle (circular mean and spread); the unwrapped
//! angle is used only for differences (range and net travel within a window).

use crate::error::InvalidParameter;
use crate::monitor::{Features, WindowStats};
use crate::StopReason;
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// The orbit class of one drop. Serialised names are part of the JSON contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrbitClass {
    /// Pendulum vibration: the contact carried, rocking about the bottom of the race.
    Pendulum,
    /// Combined rub and bouncing: rocking about the bottom with the contact open for more
    /// than `1 - min_duty` of the time.
    Bouncing,
    /// Sustained whirl against the spin direction (the dangerous one).
    BackwardWhirl,
    /// Sustained whirl with the spin direction.
    ForwardWhirl,
    /// Not settled when the extended run ended; [`Reason`] says why.
    Unresolved,
}

impl OrbitClass {
    /// Every class, in the order charts list them.
    pub const ALL: [OrbitClass; 5] = [
        OrbitClass::Pendulum,
        OrbitClass::Bouncing,
        OrbitClass::BackwardWhirl,
        OrbitClass::ForwardWhirl,
        OrbitClass::Unresolved,
    ];

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

/// Why a drop got its class. Serialised names are part of the JSON contract
/// (`class_reason` of a record).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reason {
    /// `whirl_stop_turns` consecutive carried turns in one direction (the run was stopped).
    WhirlTurns,
    /// Both halves of the final window travel at least `whirl_half_turns` in one direction
    /// with the contact carried.
    WhirlWindow,
    /// Both halves of the final window rock about the bottom with the contact carried.
    SettledRocking,
    /// Both halves of the final window rock about the bottom with the contact open part of
    /// the time.
    SettledBouncing,
    /// Unsettled: the rotor has not touched the race in the window.
    NoContact,
    /// Unsettled: the window is not yet full (the run is shorter than the window).
    WindowNotFull,
    /// Unsettled: the mean contact angle moves between the halves of the window (or the
    /// contact point travels, too slowly for whirl).
    Drifting,
    /// Unsettled: the contact angle ranges over more than `max_rocking_range_rad` in a half
    /// window without the sustained travel of whirl.
    Wandering,
    /// Unsettled: the rotor rocks about a point in the upper half of the race.
    NotAboutBottom,
    /// Unsettled: one half of the window is carried (duty at least `min_duty`) and the other
    /// is not, or the halves travel in opposite directions.
    HalvesDisagree,
}

impl Reason {
    /// The reason in words (for summaries and notes).
    pub fn describe(self) -> &'static str {
        match self {
            Reason::WhirlTurns => "consecutive whirl turns with the contact carried",
            Reason::WhirlWindow => "whirl travel with the contact carried through the window",
            Reason::SettledRocking => "rocking about the bottom with the contact carried",
            Reason::SettledBouncing => "rocking about the bottom with intermittent contact",
            Reason::NoContact => "no contact in the final window",
            Reason::WindowNotFull => "the run is shorter than the classification window",
            Reason::Drifting => "the mean contact angle drifts through the window",
            Reason::Wandering => "the contact angle wanders beyond a rocking range",
            Reason::NotAboutBottom => "the contact angle rocks about a point above the bottom",
            Reason::HalvesDisagree => "the two halves of the final window disagree",
        }
    }
}

/// The classifier's answer: a class, whether the motion has settled, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verdict {
    /// The class. `Unresolved` exactly when `settled` is false.
    pub class: OrbitClass,
    /// Whether the class is decided (a run that is not settled is extended).
    pub settled: bool,
    /// Why.
    pub reason: Reason,
}

impl Verdict {
    fn settled(class: OrbitClass, reason: Reason) -> Self {
        Self {
            class,
            settled: true,
            reason,
        }
    }
    fn unsettled(reason: Reason) -> Self {
        Self {
            class: OrbitClass::Unresolved,
            settled: false,
            reason,
        }
    }
}

/// Thresholds of the classifier and the extension of undecided runs. Part of the scene
/// (`classification`), so they are part of every record's key.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClassifyParams {
    /// Length of the final window a class is decided on (s). Default 0.25 s: about ten
    /// periods of the pendulum rocking at the paper's scene (39 Hz), and longer than the
    /// bouncing that follows the first impact (up to about 0.1 s). A run shorter than the
    /// window has not settled and is extended (see `max_extension_s`). Allowed [0.02, 100].
    pub window_s: f64,
    /// Smallest contact duty of a carried contact: pendulum vibration in a half window, and
    /// each turn of a whirl. Below it a rocking orbit is bouncing. Default 0.9. Allowed
    /// (0, 1].
    pub min_duty: f64,
    /// Largest range of the unwrapped contact angle in a half window for a rocking
    /// (pendulum or bouncing) orbit (rad). Default pi: beyond half a turn the rotor no
    /// longer rocks about the bottom. Allowed (0, 2 pi].
    pub max_rocking_range_rad: f64,
    /// Largest difference between the circular mean contact angles of the window's two
    /// halves for a settled rocking orbit (rad). Default 0.35 rad (20 deg): a rocking orbit
    /// of up to +-60 deg whose halves hold a non-integer number of periods shifts its mean
    /// by less; a contact point creeping round the race does not. Allowed (0, pi].
    pub max_drift_rad: f64,
    /// Net turns in one direction that each half of the final window must make, with the
    /// contact carried, for whirl decided on the window. Default 1. Allowed [0.5, 1e6].
    pub whirl_half_turns: f64,
    /// Largest extension of a run that has not settled by its duration (s); the run is
    /// extended in steps of half a window. 0 switches extension off. Default 1 s. Allowed
    /// [0, 3600].
    pub max_extension_s: f64,
}

impl Default for ClassifyParams {
    fn default() -> Self {
        Self {
            window_s: 0.25,
            min_duty: 0.9,
            max_rocking_range_rad: PI,
            max_drift_rad: 0.35,
            whirl_half_turns: 1.0,
            max_extension_s: 1.0,
        }
    }
}

/// Shortest classification window allowed (s): two periods of the slowest rocking seen.
pub const MIN_WINDOW_S: f64 = 0.02;

impl ClassifyParams {
    /// Checks every field; the error names `classification.<field>`.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        let check = |field: &str, v: f64, ok: bool, allowed: &str| {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(InvalidParameter::new(
                    &format!("classification.{field}"),
                    v,
                    allowed,
                ))
            }
        };
        check(
            "window_s",
            self.window_s,
            (MIN_WINDOW_S..=100.0).contains(&self.window_s),
            "[0.02, 100] s",
        )?;
        check(
            "min_duty",
            self.min_duty,
            self.min_duty > 0.0 && self.min_duty <= 1.0,
            "(0, 1]",
        )?;
        check(
            "max_rocking_range_rad",
            self.max_rocking_range_rad,
            self.max_rocking_range_rad > 0.0 && self.max_rocking_range_rad <= 2.0 * PI,
            "(0, 2 pi] rad",
        )?;
        check(
            "max_drift_rad",
            self.max_drift_rad,
            self.max_drift_rad > 0.0 && self.max_drift_rad <= PI,
            "(0, pi] rad",
        )?;
        check(
            "whirl_half_turns",
            self.whirl_half_turns,
            (0.5..=1e6).contains(&self.whirl_half_turns),
            "[0.5, 1e6]",
        )?;
        check(
            "max_extension_s",
            self.max_extension_s,
            (0.0..=3600.0).contains(&self.max_extension_s),
            "[0, 3600] s",
        )
    }
}

/// Difference of two angles on the circle, in (-pi, pi].
fn circular_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    if d > PI {
        d - 2.0 * PI
    } else {
        d
    }
}

/// How one half window moves: travelling (whirl-like), rocking, or neither.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Half {
    /// Net travel of at least `whirl_half_turns` with the contact carried; sign +1 with the
    /// spin, -1 against.
    Travelling(f64),
    /// Rocking about a point, with the contact carried (`true`) or not.
    Rocking { carried: bool, mean_rad: f64 },
    /// Not settled in this half.
    Unsettled(Reason),
}

fn half(w: &WindowStats, p: &ClassifyParams) -> Half {
    if w.contact_duty <= 0.0 || w.angle_time_s <= 0.0 {
        return Half::Unsettled(Reason::NoContact);
    }
    let carried = w.contact_duty >= p.min_duty;
    if w.net_turns.abs() >= p.whirl_half_turns {
        return if carried {
            Half::Travelling(w.net_turns.signum())
        } else {
            // Travel with the contact open much of the time: not a carried whirl yet.
            Half::Unsettled(Reason::Wandering)
        };
    }
    if !(w.angle_range_rad <= p.max_rocking_range_rad) {
        return Half::Unsettled(Reason::Wandering);
    }
    if !(w.angle_mean_rad.abs() <= FRAC_PI_2) {
        return Half::Unsettled(Reason::NotAboutBottom);
    }
    Half::Rocking {
        carried,
        mean_rad: w.angle_mean_rad,
    }
}

/// Classifies one drop from its features and why it stopped. Pure: the same features give
/// the same verdict.
pub fn classify(f: &Features, stop: StopReason, p: &ClassifyParams) -> Verdict {
    if stop == StopReason::WhirlDecided {
        return Verdict::settled(whirl_class(f.whirl_streak_turns), Reason::WhirlTurns);
    }
    if f.first_contact_time_s.is_nan() {
        return Verdict::unsettled(Reason::NoContact);
    }
    if !f.window.full {
        return Verdict::unsettled(Reason::WindowNotFull);
    }
    let [a, b] = f.window_halves;
    match (half(&a, p), half(&b, p)) {
        (Half::Unsettled(r), _) | (_, Half::Unsettled(r)) => Verdict::unsettled(r),
        (Half::Travelling(s1), Half::Travelling(s2)) if s1 == s2 => {
            Verdict::settled(whirl_class(s1), Reason::WhirlWindow)
        }
        (Half::Travelling(_), _) | (_, Half::Travelling(_)) => {
            Verdict::unsettled(Reason::HalvesDisagree)
        }
        (
            Half::Rocking {
                carried: c1,
                mean_rad: m1,
            },
            Half::Rocking {
                carried: c2,
                mean_rad: m2,
            },
        ) => {
            if !(circular_diff(m2, m1).abs() <= p.max_drift_rad) {
                Verdict::unsettled(Reason::Drifting)
            } else if c1 != c2 {
                Verdict::unsettled(Reason::HalvesDisagree)
            } else if c1 {
                Verdict::settled(OrbitClass::Pendulum, Reason::SettledRocking)
            } else {
                Verdict::settled(OrbitClass::Bouncing, Reason::SettledBouncing)
            }
        }
    }
}

/// Backward whirl for travel against the spin (negative), forward whirl otherwise.
fn whirl_class(sign: f64) -> OrbitClass {
    if sign < 0.0 {
        OrbitClass::BackwardWhirl
    } else {
        OrbitClass::ForwardWhirl
    }
}

#[cfg(test)]
mod tests {
    //! The classifier on synthetic feature series: one per class and one per edge the
    //! classifier must get right (transient whirl then pendulum, pendulum about the bottom
    //! after transient turns, slow drift, a half window of each kind).
    use super::*;
    use crate::monitor::Window;

    /// A half window: duty, circular mean and unwrapped range of the angle (deg), net
    /// turns (signed relative to the spin).
    fn hw(duty: f64, mean_deg: f64, range_deg: f64, turns: f64) -> WindowStats {
        WindowStats {
            start_s: 0.0,
            end_s: 0.125,
            contact_duty: duty,
            angle_time_s: 0.125,
            angle_mean_rad: mean_deg.to_radians(),
            angle_spread_rad: (range_deg / 4.0).to_radians(),
            angle_range_rad: range_deg.to_radians(),
            net_turns: turns,
        }
    }

    fn features(halves: [WindowStats; 2], net_turns: f64, streak: f64) -> Features {
        let mut f = Features::empty();
        f.first_contact_time_s = 0.0055;
        f.net_whirl_turns = net_turns;
        f.whirl_streak_turns = streak;
        f.window = Window {
            full: true,
            stats: hw(1.0, 0.0, 10.0, 0.0),
        };
        f.window_halves = halves;
        f
    }

    const P: ClassifyParams = ClassifyParams {
        window_s: 0.25,
        min_duty: 0.9,
        max_rocking_range_rad: PI,
        max_drift_rad: 0.35,
        whirl_half_turns: 1.0,
        max_extension_s: 1.0,
    };
    const END: StopReason = StopReason::DurationReached;

    fn verdict(halves: [WindowStats; 2]) -> Verdict {
        classify(&features(halves, 0.0, 0.0), END, &P)
    }

    #[test]
    fn carried_rocking_about_the_bottom_is_pendulum() {
        let v = verdict([hw(1.0, -5.0, 100.0, 0.1), hw(1.0, 3.0, 110.0, -0.05)]);
        assert_eq!(
            v,
            Verdict::settled(OrbitClass::Pendulum, Reason::SettledRocking)
        );
    }

    #[test]
    fn intermittent_contact_at_the_bottom_is_bouncing() {
        let v = verdict([hw(0.4, 2.0, 30.0, 0.0), hw(0.5, -1.0, 25.0, 0.0)]);
        assert_eq!(
            v,
            Verdict::settled(OrbitClass::Bouncing, Reason::SettledBouncing)
        );
    }

    #[test]
    fn turns_stopped_by_the_whirl_rule_are_whirl_in_their_direction() {
        let f = features([hw(1.0, 0.0, 10.0, 0.0); 2], -5.0, -5.0);
        let v = classify(&f, StopReason::WhirlDecided, &P);
        assert_eq!(
            v,
            Verdict::settled(OrbitClass::BackwardWhirl, Reason::WhirlTurns)
        );
        let f = features([hw(1.0, 0.0, 10.0, 0.0); 2], 5.0, 5.0);
        let v = classify(&f, StopReason::WhirlDecided, &P);
        assert_eq!(v.class, OrbitClass::ForwardWhirl);
    }

    #[test]
    fn carried_travel_through_both_halves_is_whirl() {
        let v = verdict([hw(0.97, 40.0, 1500.0, -4.2), hw(0.99, -70.0, 1600.0, -4.5)]);
        assert_eq!(
            v,
            Verdict::settled(OrbitClass::BackwardWhirl, Reason::WhirlWindow)
        );
    }

    #[test]
    fn transient_whirl_then_pendulum_is_pendulum() {
        // 2.1 net turns since first touch, all before the window: the transient is a
        // feature, the settled rocking is the class.
        let mut f = features(
            [hw(1.0, -2.0, 96.0, 0.02), hw(1.0, 1.5, 101.0, -0.01)],
            -2.1,
            -1.0,
        );
        f.transient_whirl_turns = -2.1;
        let v = classify(&f, END, &P);
        assert_eq!(v.class, OrbitClass::Pendulum);
        assert!(v.settled);
    }

    #[test]
    fn a_transient_still_in_the_window_is_not_settled() {
        // The end of the transient whirl lies in the first half: travel there, rocking in
        // the second half.
        let v = verdict([hw(1.0, 150.0, 500.0, -1.1), hw(1.0, 2.0, 95.0, 0.0)]);
        assert_eq!(v, Verdict::unsettled(Reason::HalvesDisagree));
        // Less than a turn of travel but a wide range: wandering.
        let v = verdict([hw(1.0, 120.0, 300.0, -0.6), hw(1.0, 2.0, 95.0, 0.0)]);
        assert_eq!(v, Verdict::unsettled(Reason::Wandering));
    }

    #[test]
    fn pendulum_about_the_bottom_uses_the_circular_mean() {
        // After turns the unwrapped angle sits near -4 pi; the circular mean is near 0.
        let mean = circular_diff(-4.0 * PI + 0.05, 0.0).to_degrees();
        assert!(mean.abs() < 5.0, "{mean}");
        let v = verdict([hw(1.0, mean, 79.0, 0.0), hw(1.0, mean - 1.0, 80.0, 0.0)]);
        assert_eq!(v.class, OrbitClass::Pendulum);
        // Rocking about a point high on the wall is not a pendulum about the bottom.
        let v = verdict([hw(1.0, 120.0, 40.0, 0.0), hw(1.0, 118.0, 40.0, 0.0)]);
        assert_eq!(v, Verdict::unsettled(Reason::NotAboutBottom));
    }

    #[test]
    fn slow_drift_is_not_settled() {
        // The contact point creeps against the spin: a third of a turn per half window.
        let v = verdict([hw(1.0, -20.0, 130.0, -0.33), hw(1.0, -60.0, 125.0, -0.34)]);
        assert_eq!(v, Verdict::unsettled(Reason::Drifting));
    }

    #[test]
    fn halves_of_different_duty_are_not_settled() {
        let v = verdict([hw(0.6, 0.0, 40.0, 0.0), hw(1.0, 0.0, 60.0, 0.0)]);
        assert_eq!(v, Verdict::unsettled(Reason::HalvesDisagree));
        // Travel in opposite directions.
        let v = verdict([hw(1.0, 0.0, 600.0, -1.5), hw(1.0, 0.0, 600.0, 1.5)]);
        assert_eq!(v, Verdict::unsettled(Reason::HalvesDisagree));
        // Travel with the contact open most of the time.
        let v = verdict([hw(0.5, 0.0, 600.0, -1.5), hw(0.5, 0.0, 600.0, -1.5)]);
        assert_eq!(v, Verdict::unsettled(Reason::Wandering));
    }

    #[test]
    fn no_contact_and_short_runs_are_not_settled() {
        let mut f = features([hw(0.0, f64::NAN, f64::NAN, 0.0); 2], 0.0, 0.0);
        f.first_contact_time_s = f64::NAN;
        assert_eq!(classify(&f, END, &P), Verdict::unsettled(Reason::NoContact));
        let mut f = features([hw(1.0, 0.0, 10.0, 0.0); 2], 0.0, 0.0);
        f.window.full = false;
        assert_eq!(
            classify(&f, END, &P),
            Verdict::unsettled(Reason::WindowNotFull)
        );
        // In contact but never near the wall in a half (no angle samples).
        let mut h = hw(1.0, 0.0, 10.0, 0.0);
        h.angle_time_s = 0.0;
        assert_eq!(verdict([h, h]), Verdict::unsettled(Reason::NoContact));
    }

    #[test]
    fn parameters_are_validated_by_name() {
        let mut p = P;
        p.min_duty = 1.5;
        assert_eq!(p.validate().unwrap_err().field, "classification.min_duty");
        let mut p = P;
        p.window_s = 0.001;
        assert_eq!(p.validate().unwrap_err().field, "classification.window_s");
        P.validate().unwrap();
    }
}
