//! The streaming observer of a drop: located peaks, impacts, contact time, the unwrapped
//! contact angle and time-binned window statistics. O(1) memory unless an orbit is recorded.

use crate::model::{DropSystem, N};
use crate::ode::{Dense, Observer, StepView};
use crate::orbit::{Orbit, OrbitSample};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};
use std::ops::ControlFlow;

/// Number of time bins the window statistics are kept in (fixed, so memory is O(1)).
pub const BINS: usize = 64;

/// A running maximum located on the step interpolants (not the largest step-end value).
#[derive(Debug, Clone, Copy, Default)]
struct Peak {
    value: f64,
    time_s: f64,
}

/// Per-bin accumulators for the classification window.
#[derive(Debug, Clone, Copy)]
struct Bin {
    duration_s: f64,
    contact_s: f64,
    angle_integral: f64,
    angle_time_s: f64,
    angle_min: f64,
    angle_max: f64,
}

impl Default for Bin {
    fn default() -> Self {
        Self {
            duration_s: 0.0,
            contact_s: 0.0,
            angle_integral: 0.0,
            angle_time_s: 0.0,
            angle_min: f64::INFINITY,
            angle_max: f64::NEG_INFINITY,
        }
    }
}

/// Statistics over the classification window: the second half of the simulated time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// Window start (s).
    pub start_s: f64,
    /// Window end = end of the run (s).
    pub end_s: f64,
    /// Fraction of the window with the rotor-race contact active.
    pub contact_duty: f64,
    /// Smallest unwrapped contact angle in the window, from the bottom of the race (rad;
    /// counter-clockwise positive). NaN when the rotor never came near the race.
    pub angle_min_rad: f64,
    /// Largest unwrapped contact angle in the window (rad).
    pub angle_max_rad: f64,
    /// Time-mean unwrapped contact angle in the window (rad).
    pub angle_mean_rad: f64,
}

/// What a drop measured, streamed; the classifier (sweep crate) reads only this.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Features {
    /// Peak normal force of the first impact after free fall (N); impact episodes closer
    /// than the merge window count as one impact. 0 if the rotor never touched.
    pub first_contact_force_n: f64,
    /// Maximum normal force over the run (N), located on the interpolant.
    pub max_contact_force_n: f64,
    /// Time of that maximum (s).
    pub max_contact_force_time_s: f64,
    /// Peak friction power H_s = F_t v_rel (W), eq. 17, located.
    pub peak_friction_power_w: f64,
    /// Peak total heat power H = H_s + bearing drag power (W), located.
    pub peak_heat_power_w: f64,
    /// Impacts: contact episodes, merging episodes separated by less than the merge window.
    pub impacts: u64,
    /// Time of the first touch (s); NaN if none.
    pub first_contact_time_s: f64,
    /// Total time with the contact active (s).
    pub contact_time_s: f64,
    /// Net turns of the contact angle since first touch, signed relative to the spin
    /// (negative: opposite to the spin, i.e. backward).
    pub net_whirl_turns: f64,
    /// Whirl frequency (Hz), signed relative to the spin (negative is backward whirl):
    /// from the times of completed net turns when there are two or more, else the net
    /// contact-angle rate over the window.
    pub whirl_frequency_hz: f64,
    /// Window statistics for the classifier.
    pub window: Window,
    /// Rotor spin at the end (r/min).
    pub final_rotor_speed_rpm: f64,
    /// Race spin at the end (r/min).
    pub final_race_speed_rpm: f64,
}

/// The observer a drop runs with.
pub struct Monitor {
    duration_s: f64,
    merge_s: f64,
    spin_sign: f64,
    near_wall_m: f64,
    stop_turns: f64,
    max_fn: Peak,
    max_hs: Peak,
    max_h: Peak,
    first_impact_fn: f64,
    impacts: u64,
    last_loss_s: f64,
    first_contact_s: f64,
    contact_s: f64,
    angle_raw_prev: Option<f64>,
    angle: f64,
    angle_at_first_contact: Option<f64>,
    turns_done: u64,
    first_turn_s: f64,
    last_turn_s: f64,
    bins: [Bin; BINS],
    last_t: f64,
    orbit: Option<Orbit>,
    orbit_dt: f64,
    orbit_last_t: f64,
    /// The end sample of the previous step, reused as the next step's start sample when no
    /// mode switch happened in between.
    prev_end: Option<(f64, Sample)>,
    /// Set when the whirl stopping rule fired.
    pub whirl_decided: bool,
}

/// Samples of one state: what the peak trackers and the angle need.
#[derive(Clone, Copy)]
struct Sample {
    normal: f64,
    friction_power: f64,
    heat_power: f64,
}

fn sample(sys: &DropSystem, y: &[f64; N]) -> Sample {
    sys.with_forces(y, |f| Sample {
        normal: f.normal_n,
        friction_power: f.friction_power_w,
        heat_power: f.friction_power_w + f.bearing_power_w,
    })
}

/// Locates the maximum of `q` on `[a, b]` by golden-section search on the interpolant.
fn golden_max(mut q: impl FnMut(f64) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_9;
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (q(c), q(d));
    for _ in 0..60 {
        if (b - a) <= 1e-9 * (b.abs() + 1e-12) {
            break;
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = q(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = q(d);
        }
    }
    if fc > fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

impl Monitor {
    /// A monitor for a run of `duration_s` (s), merging impacts closer than `merge_s`,
    /// stopping after `stop_turns` net whirl turns, recording an orbit of about
    /// `orbit_points` samples when that is `Some`.
    pub fn new(
        duration_s: f64,
        merge_s: f64,
        spin_rad_s: f64,
        clearance_m: f64,
        stop_turns: f64,
        orbit_points: Option<usize>,
    ) -> Self {
        Self {
            duration_s,
            merge_s,
            spin_sign: if spin_rad_s < 0.0 { -1.0 } else { 1.0 },
            near_wall_m: 0.5 * clearance_m,
            stop_turns,
            max_fn: Peak::default(),
            max_hs: Peak::default(),
            max_h: Peak::default(),
            first_impact_fn: 0.0,
            impacts: 0,
            last_loss_s: f64::NEG_INFINITY,
            first_contact_s: f64::NAN,
            contact_s: 0.0,
            angle_raw_prev: None,
            angle: 0.0,
            angle_at_first_contact: None,
            turns_done: 0,
            first_turn_s: f64::NAN,
            last_turn_s: f64::NAN,
            bins: [Bin::default(); BINS],
            last_t: 0.0,
            orbit: orbit_points.map(|_| Orbit {
                clearance_m,
                samples: Vec::new(),
            }),
            orbit_dt: orbit_points.map_or(f64::INFINITY, |n| duration_s / n.max(1) as f64),
            orbit_last_t: f64::NEG_INFINITY,
            prev_end: None,
            whirl_decided: false,
        }
    }

    /// Called by the driver at a contact onset (`on = true`) or loss at time `t`.
    pub fn contact_switch(&mut self, t: f64, on: bool) {
        if on {
            if self.impacts == 0 {
                self.first_contact_s = t;
            }
            if self.impacts == 0 || t - self.last_loss_s > self.merge_s {
                self.impacts += 1;
            }
        } else {
            self.last_loss_s = t;
        }
        self.prev_end = None;
    }

    /// Called by the driver after any mode switch: the cached step-end sample is stale.
    pub fn mode_switched(&mut self) {
        self.prev_end = None;
    }

    fn track_peaks(&mut self, sys: &DropSystem, dense: &Dense<N>, ts: [f64; 3], s: [&Sample; 3]) {
        type Get = fn(&Sample) -> f64;
        let trackers: [(Get, usize); 3] = [
            (|x| x.normal, 0),
            (|x| x.friction_power, 1),
            (|x| x.heat_power, 2),
        ];
        for (get, which) in trackers {
            let vals = [get(s[0]), get(s[1]), get(s[2])];
            let (imax, vmax) =
                vals.iter()
                    .enumerate()
                    .fold((0, f64::NEG_INFINITY), |acc, (i, v)| {
                        if *v > acc.1 {
                            (i, *v)
                        } else {
                            acc
                        }
                    });
            let peak = match which {
                0 => &mut self.max_fn,
                1 => &mut self.max_hs,
                _ => &mut self.max_h,
            };
            if vmax <= peak.value {
                continue;
            }
            // Bracket around the best sample and refine on the interpolant.
            let (a, b) = match imax {
                0 => (ts[0], ts[1]),
                1 => (ts[0], ts[2]),
                _ => (ts[1], ts[2]),
            };
            let (tm, vm) = golden_max(|tt| get(&sample(sys, &dense.eval(tt))), a, b);
            let (tp, vp) = if vm > vmax {
                (tm, vm)
            } else {
                (ts[imax], vmax)
            };
            let peak = match which {
                0 => &mut self.max_fn,
                1 => &mut self.max_hs,
                _ => &mut self.max_h,
            };
            *peak = Peak {
                value: vp,
                time_s: tp,
            };
        }
        if self.impacts == 1 {
            self.first_impact_fn = self.max_fn.value;
        }
    }

    fn track_angle(&mut self, y: &[f64; N], t: f64) {
        use crate::model::ix::*;
        let (dx, dy) = (y[XR] - y[XB], y[YR] - y[YB]);
        if (dx * dx + dy * dy).sqrt() < self.near_wall_m {
            return;
        }
        // Angle from the bottom of the race, counter-clockwise positive.
        let raw = dy.atan2(dx) + 0.5 * PI;
        match self.angle_raw_prev {
            None => self.angle = (raw + PI).rem_euclid(TAU) - PI,
            Some(prev) => self.angle += (raw - prev + PI).rem_euclid(TAU) - PI,
        }
        self.angle_raw_prev = Some(raw);
        if let Some(a0) = self.angle_at_first_contact {
            let turns = ((self.angle - a0) / TAU).abs();
            let k = turns.floor() as u64;
            if k > self.turns_done {
                if self.turns_done == 0 {
                    self.first_turn_s = t;
                }
                self.turns_done = k;
                self.last_turn_s = t;
            }
            if turns >= self.stop_turns {
                self.whirl_decided = true;
            }
        }
    }

    fn bin_step(&mut self, t0: f64, t1: f64, contact: bool, angle_mid: Option<f64>) {
        let w = self.duration_s / BINS as f64;
        let i = ((0.5 * (t0 + t1) / w) as usize).min(BINS - 1);
        let h = t1 - t0;
        let b = &mut self.bins[i];
        b.duration_s += h;
        if contact {
            b.contact_s += h;
        }
        if let Some(a) = angle_mid {
            b.angle_integral += a * h;
            b.angle_time_s += h;
            b.angle_min = b.angle_min.min(a);
            b.angle_max = b.angle_max.max(a);
        }
    }

    fn record_orbit(&mut self, sys: &DropSystem, t: f64, y: &[f64; N], force: bool) {
        use crate::model::ix::*;
        if let Some(orbit) = &mut self.orbit {
            if force || t - self.orbit_last_t >= self.orbit_dt {
                let f = sys.forces(y);
                orbit.samples.push(OrbitSample {
                    t_s: t,
                    x_rel_m: y[XR] - y[XB],
                    y_rel_m: y[YR] - y[YB],
                    contact_force_n: f.normal_n.max(0.0),
                });
                self.orbit_last_t = t;
            }
        }
    }

    /// Records the release state in the orbit.
    pub fn start(&mut self, sys: &DropSystem, y: &[f64; N]) {
        self.record_orbit(sys, 0.0, y, true);
    }

    /// Final features after the run ended at `t_end` in state `y`.
    pub fn finish(
        mut self,
        sys: &DropSystem,
        t_end: f64,
        y: &[f64; N],
    ) -> (Features, Option<Orbit>) {
        self.record_orbit(sys, t_end, y, true);
        let w = self.duration_s / BINS as f64;
        let start_s = 0.5 * t_end;
        let first = ((start_s / w) as usize).min(BINS - 1);
        let (mut dur, mut con, mut ai, mut at, mut amin, mut amax) =
            (0.0, 0.0, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        for b in &self.bins[first..] {
            dur += b.duration_s;
            con += b.contact_s;
            ai += b.angle_integral;
            at += b.angle_time_s;
            amin = amin.min(b.angle_min);
            amax = amax.max(b.angle_max);
        }
        let window = Window {
            start_s: first as f64 * w,
            end_s: t_end,
            contact_duty: if dur > 0.0 { con / dur } else { 0.0 },
            angle_min_rad: if at > 0.0 { amin } else { f64::NAN },
            angle_max_rad: if at > 0.0 { amax } else { f64::NAN },
            angle_mean_rad: if at > 0.0 { ai / at } else { f64::NAN },
        };
        let net = self
            .angle_at_first_contact
            .map_or(0.0, |a0| (self.angle - a0) / TAU);
        let whirl_frequency_hz = if self.turns_done >= 2 && self.last_turn_s > self.first_turn_s {
            net.signum() * (self.turns_done - 1) as f64 / (self.last_turn_s - self.first_turn_s)
        } else if let Some(a0) = self.angle_at_first_contact {
            let t0 = self.first_contact_s;
            if t_end > t0 {
                (self.angle - a0) / TAU / (t_end - t0)
            } else {
                0.0
            }
        } else {
            0.0
        };
        use crate::model::ix::*;
        let to_rpm = 30.0 / PI;
        let features = Features {
            first_contact_force_n: self.first_impact_fn,
            max_contact_force_n: self.max_fn.value,
            max_contact_force_time_s: self.max_fn.time_s,
            peak_friction_power_w: self.max_hs.value,
            peak_heat_power_w: self.max_h.value,
            impacts: self.impacts,
            first_contact_time_s: self.first_contact_s,
            contact_time_s: self.contact_s,
            net_whirl_turns: net * self.spin_sign,
            whirl_frequency_hz: whirl_frequency_hz * self.spin_sign,
            window,
            final_rotor_speed_rpm: y[WR] * to_rpm,
            final_race_speed_rpm: y[WB] * to_rpm,
        };
        (features, self.orbit)
    }
}

impl Observer<DropSystem, N> for Monitor {
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<()> {
        let d = step.dense;
        let (t0, t1) = (d.t0(), d.t1());
        let tm = 0.5 * (t0 + t1);
        let (y0, ym, y1) = (d.y0(), d.eval(tm), d.y1());
        let contact = sys.mode.contact;
        if contact {
            self.contact_s += t1 - t0;
            if self.angle_at_first_contact.is_none() {
                self.track_angle(&y0, t0);
                self.angle_at_first_contact = Some(self.angle);
            }
        }
        let s0 = match self.prev_end {
            Some((t, s)) if t == t0 => s,
            _ => sample(sys, &y0),
        };
        let s1 = sample(sys, &y1);
        // In free flight only the (smooth, slowly varying) bearing power is non-zero: its
        // step-end values suffice. In contact a midpoint sample brackets interior peaks.
        let sm = if contact {
            sample(sys, &ym)
        } else if s0.heat_power >= s1.heat_power {
            s0
        } else {
            s1
        };
        self.track_peaks(sys, d, [t0, tm, t1], [&s0, &sm, &s1]);
        self.prev_end = Some((t1, s1));
        self.track_angle(&ym, tm);
        let angle_mid = self.angle_raw_prev.map(|_| self.angle);
        self.track_angle(&y1, t1);
        self.bin_step(t0, t1, contact, angle_mid);
        self.last_t = t1;
        self.record_orbit(sys, t1, &y1, false);
        if self.whirl_decided {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}
