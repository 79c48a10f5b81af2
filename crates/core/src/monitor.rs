//! The streaming observer of a drop: located peaks, impacts, contact time, the unwrapped
//! contact angle and time-binned window statistics. O(1) memory unless an orbit is recorded.

use crate::model::{DropSystem, N};
use crate::ode::{Dense, Observer, StepView};
use crate::orbit::{Orbit, OrbitSample};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::ops::ControlFlow;

/// Time bins of the classification window (a ring, so memory is O(1) however long the run
/// is extended). Even, so the window splits into two halves of whole bins.
pub const WINDOW_BINS: usize = 32;

/// A running maximum located on the step interpolants (not the largest step-end value).
#[derive(Debug, Clone, Copy, Default)]
struct Peak {
    value: f64,
    time_s: f64,
}

/// One time bin of the classification window.
#[derive(Debug, Clone, Copy)]
struct Bin {
    /// Absolute index `floor(t / bin_s)` of the bin held in this ring slot; -1 when empty.
    k: i64,
    duration_s: f64,
    contact_s: f64,
    /// Time integrals of cos and sin of the contact angle (for the circular mean).
    cos_dt: f64,
    sin_dt: f64,
    angle_time_s: f64,
    /// Unwrapped angle extremes and first and last samples in the bin (rad).
    angle_min: f64,
    angle_max: f64,
    angle_first: f64,
    angle_last: f64,
}

impl Bin {
    fn empty(k: i64) -> Self {
        Self {
            k,
            duration_s: 0.0,
            contact_s: 0.0,
            cos_dt: 0.0,
            sin_dt: 0.0,
            angle_time_s: 0.0,
            angle_min: f64::INFINITY,
            angle_max: f64::NEG_INFINITY,
            angle_first: f64::NAN,
            angle_last: f64::NAN,
        }
    }
}

/// Statistics of the contact over a stretch of time (the final window or one of its halves).
/// Angles are measured from the bottom of the race, counter-clockwise positive, while the
/// rotor is within half a clearance of the race wall.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WindowStats {
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Fraction of the time with the rotor-race contact active.
    pub contact_duty: f64,
    /// Time with the contact angle measured (s); 0 when the rotor never came near the wall.
    pub angle_time_s: f64,
    /// Circular (time-weighted) mean of the contact angle, in (-pi, pi] (rad). NaN without
    /// angle samples.
    #[serde(deserialize_with = "crate::json::f64_or_nan")]
    pub angle_mean_rad: f64,
    /// Circular standard deviation `sqrt(-2 ln R)` of the contact angle, R the mean
    /// resultant length (rad). NaN without angle samples.
    #[serde(deserialize_with = "crate::json::f64_or_nan")]
    pub angle_spread_rad: f64,
    /// Range (largest minus smallest) of the unwrapped contact angle (rad). NaN without
    /// angle samples.
    #[serde(deserialize_with = "crate::json::f64_or_nan")]
    pub angle_range_rad: f64,
    /// Net turns of the contact point, signed relative to the spin (negative: against it).
    pub net_turns: f64,
}

/// The final classification window: the last `window_s` of the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// Whether the run is at least as long as the window.
    pub full: bool,
    /// The window's statistics.
    #[serde(flatten)]
    pub stats: WindowStats,
}

/// What a drop measured, streamed; the classifier ([`crate::classify`](mod@crate::classify))
/// reads only this.
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
    /// (negative: against the spin).
    pub net_whirl_turns: f64,
    /// Net turns made before the motion that decides the class: from first touch to the
    /// start of the final window, or to the start of the whirl streak when the whirl rule
    /// stopped the run. Signed relative to the spin. A transient whirl that dies out shows
    /// here, not in the class.
    pub transient_whirl_turns: f64,
    /// Consecutive turns of the contact point in one direction at the end of the run, each
    /// made with the contact carried and faster than one turn per half window; signed
    /// relative to the spin. The whirl rule stops the run when it reaches the scene's
    /// `whirl_stop_turns`.
    pub whirl_streak_turns: f64,
    /// Whirl frequency (Hz), signed relative to the spin (negative is backward whirl): from
    /// the times of the streak's turns when it has two or more, else the net contact-angle
    /// rate over the final window.
    pub whirl_frequency_hz: f64,
    /// The final window.
    pub window: Window,
    /// The window's first and second halves (the classifier asks both to agree).
    pub window_halves: [WindowStats; 2],
    /// Rotor spin at the end (r/min).
    pub final_rotor_speed_rpm: f64,
    /// Race spin at the end (r/min).
    pub final_race_speed_rpm: f64,
}

impl WindowStats {
    /// Statistics of an empty stretch from `t0` to `t1` (no contact, no angle samples).
    pub fn empty(start_s: f64, end_s: f64) -> Self {
        Self {
            start_s,
            end_s,
            contact_duty: 0.0,
            angle_time_s: 0.0,
            angle_mean_rad: f64::NAN,
            angle_spread_rad: f64::NAN,
            angle_range_rad: f64::NAN,
            net_turns: 0.0,
        }
    }
}

impl Features {
    /// The features of a run that measured nothing (the starting point of synthetic
    /// feature series in tests).
    pub fn empty() -> Self {
        let w = WindowStats::empty(0.0, 0.0);
        Self {
            first_contact_force_n: 0.0,
            max_contact_force_n: 0.0,
            max_contact_force_time_s: 0.0,
            peak_friction_power_w: 0.0,
            peak_heat_power_w: 0.0,
            impacts: 0,
            first_contact_time_s: f64::NAN,
            contact_time_s: 0.0,
            net_whirl_turns: 0.0,
            transient_whirl_turns: 0.0,
            whirl_streak_turns: 0.0,
            whirl_frequency_hz: 0.0,
            window: Window {
                full: false,
                stats: w,
            },
            window_halves: [w; 2],
            final_rotor_speed_rpm: 0.0,
            final_race_speed_rpm: 0.0,
        }
    }
}

/// Consecutive turns of the contact point in one direction (the whirl rule's counter).
///
/// A turn completes when the unwrapped angle has moved a full turn from the reference. It
/// extends the streak when it was made with the contact carried (duty of at least
/// `min_duty` over the turn), faster than `max_turn_s`, and in the streak's direction; a
/// carried turn the other way starts a new streak; any other turn ends it. Moving back by
/// more than a quarter turn against the streak also ends it (a rocking rotor).
#[derive(Debug, Clone, Copy)]
struct Streak {
    min_duty: f64,
    max_turn_s: f64,
    ref_angle: f64,
    ref_t: f64,
    ref_contact_s: f64,
    /// Signed count of consecutive turns (positive counter-clockwise).
    count: f64,
    /// Unwrapped angle where the streak began.
    start_angle: f64,
    first_turn_s: f64,
    last_turn_s: f64,
    /// The previous sample (angle, time), for turn times between samples.
    prev: Option<(f64, f64)>,
}

impl Streak {
    fn new(min_duty: f64, max_turn_s: f64) -> Self {
        Self {
            min_duty,
            max_turn_s,
            ref_angle: f64::NAN,
            ref_t: 0.0,
            ref_contact_s: 0.0,
            count: 0.0,
            start_angle: f64::NAN,
            first_turn_s: f64::NAN,
            last_turn_s: f64::NAN,
            prev: None,
        }
    }

    fn reset_at(&mut self, angle: f64, t: f64, contact_s: f64) {
        self.ref_angle = angle;
        self.ref_t = t;
        self.ref_contact_s = contact_s;
    }

    fn update(&mut self, angle: f64, t: f64, contact_s: f64) {
        let prev = self.prev.replace((angle, t));
        if self.ref_angle.is_nan() {
            self.reset_at(angle, t, contact_s);
            return;
        }
        let d = angle - self.ref_angle;
        if d.abs() >= TAU {
            let dir = d.signum();
            // The time the angle passed the full turn, linear between this sample and the
            // previous one (samples are a step's midpoint and end): the turn times, and so
            // the whirl frequency, do not depend on where the steps fall.
            let target = self.ref_angle + dir * TAU;
            let t_turn = match prev {
                Some((a0, t0)) if (angle - a0) * dir > 0.0 && (target - a0) * dir >= 0.0 => {
                    t0 + (t - t0) * ((target - a0) / (angle - a0)).clamp(0.0, 1.0)
                }
                _ => t,
            };
            let dt = t_turn - self.ref_t;
            let duty = if t > self.ref_t {
                (contact_s - self.ref_contact_s) / (t - self.ref_t)
            } else {
                0.0
            };
            let whirl_turn = duty >= self.min_duty && dt <= self.max_turn_s;
            if whirl_turn && self.count * dir >= 0.0 {
                if self.count == 0.0 {
                    self.start_angle = self.ref_angle;
                    self.first_turn_s = t_turn;
                }
                self.count += dir;
                self.last_turn_s = t_turn;
            } else if whirl_turn {
                self.count = dir;
                self.start_angle = self.ref_angle;
                self.first_turn_s = t_turn;
                self.last_turn_s = t_turn;
            } else {
                self.count = 0.0;
            }
            self.reset_at(target, t_turn, contact_s);
        } else if self.count != 0.0 && d * self.count.signum() < -FRAC_PI_2 {
            self.count = 0.0;
            self.reset_at(angle, t, contact_s);
        }
    }
}

/// The observer a drop runs with.
pub struct Monitor {
    merge_s: f64,
    spin_sign: f64,
    near_wall_m: f64,
    stop_turns: f64,
    /// Classification window length (s) and bin width (s).
    window_s: f64,
    bin_s: f64,
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
    streak: Streak,
    /// The window ring: slot `k mod WINDOW_BINS` holds bin `k`.
    bins: [Bin; WINDOW_BINS],
    /// Absolute index of the newest bin (-1 before the first step).
    cur_k: i64,
    last_t: f64,
    orbit: Option<Orbit>,
    orbit_dt: f64,
    orbit_last_t: f64,
    /// The end sample of the previous step, reused as the next step's start sample when no
    /// mode switch happened in between.
    prev_end: Option<(f64, Sample)>,
    /// The interpolant's samples that one step's peak searches took, keyed on the bits of
    /// their time (see [`Probes`]).
    probes: Probes,
    /// Set when the whirl stopping rule fired.
    pub whirl_decided: bool,
}

/// Samples of one state: what the peak trackers and the angle need.
#[derive(Debug, Clone, Copy)]
struct Sample {
    normal: f64,
    friction_power: f64,
    heat_power: f64,
}

/// `x.rem_euclid(TAU)`, bit for bit, without its `fmod` call where `x` is in
/// `(-TAU, 2 TAU)`, as the contact angle's increments always are: there `fmod` returns `x`
/// itself (then `x + TAU` below zero, as `rem_euclid` adds) or `x - TAU`, which is exact
/// (Sterbenz's lemma). A NaN passes through either way.
#[inline]
fn wrap_tau(x: f64) -> f64 {
    if x > -TAU && x < 2.0 * TAU {
        if x < 0.0 {
            x + TAU
        } else if x >= TAU {
            x - TAU
        } else {
            x
        }
    } else {
        x.rem_euclid(TAU)
    }
}

fn sample(sys: &DropSystem, y: &[f64; N]) -> Sample {
    sys.with_forces(y, |f| Sample {
        normal: f.normal_n,
        friction_power: f.friction_power_w,
        heat_power: f.friction_power_w + f.bearing_power_w,
    })
}

/// The samples one step's peak searches took on the interpolant, keyed on the exact bits of
/// their time.
///
/// The three peaks (contact force, friction power, heat power) are refined one after the
/// other on the same step, and where they start from the same bracket (all three rising
/// through the step, as in a compression or a growing whirl) their golden-section searches
/// probe the same times for as long as they turn the same way. A sample is a pure function
/// of the interpolant and the time, so a repeated probe is answered from here with the bits
/// a fresh evaluation would give: the peaks are bit-identical with and without it. On the
/// 1 s pendulum drop at `standard` it answers 1 889 of the 2 965 probes; on the whirl drop
/// at 8000 r/min, μ 0.4, 1 908 of 3 188, a sixth of that drop's force evaluations
/// (docs/performance.md#shared-probes-for-the-peak-searches-the-same-bits).
#[derive(Debug, Clone, Default)]
struct Probes {
    /// `(time bits, sample)` in the order taken.
    taken: Vec<(u64, Sample)>,
}

impl Probes {
    /// The sample at time `t`: a repeat of an earlier probe of this step, or `take(t)` (kept).
    /// `k` is the probe's index in its search: a search that repeats an earlier one finds its
    /// `k`-th probe at index `k`, so that slot is looked at first.
    fn get_or_take(&mut self, t: f64, k: usize, take: impl FnOnce(f64) -> Sample) -> Sample {
        let key = t.to_bits();
        if let Some((_, s)) = self.taken.get(k).filter(|(b, _)| *b == key) {
            return *s;
        }
        if let Some((_, s)) = self.taken.iter().find(|(b, _)| *b == key) {
            return *s;
        }
        let s = take(t);
        self.taken.push((key, s));
        s
    }
}

/// Locates the maximum of `q` on `[a, b]` by golden-section search on the interpolant.
/// `q` gets the probe's time and its index in the search.
fn golden_max(mut q: impl FnMut(f64, usize) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_9;
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (q(c, 0), q(d, 1));
    for k in 2..62 {
        if (b - a) <= 1e-9 * (b.abs() + 1e-12) {
            break;
        }
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = q(c, k);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = q(d, k);
        }
    }
    if fc > fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

impl Monitor {
    /// A monitor for a run of `duration_s` (s) classified on a final window of `window_s`
    /// (see [`crate::classify::ClassifyParams::window_s`]), merging impacts closer than
    /// `merge_s`, stopping after `stop_turns` consecutive whirl turns made with a contact duty
    /// of at least `min_duty`, recording an orbit of about `orbit_points` samples when that
    /// is `Some`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        duration_s: f64,
        window_s: f64,
        merge_s: f64,
        spin_rad_s: f64,
        clearance_m: f64,
        stop_turns: f64,
        min_duty: f64,
        orbit_points: Option<usize>,
    ) -> Self {
        let bin_s = window_s / WINDOW_BINS as f64;
        Self {
            merge_s,
            spin_sign: if spin_rad_s < 0.0 { -1.0 } else { 1.0 },
            near_wall_m: 0.5 * clearance_m,
            stop_turns,
            window_s,
            bin_s,
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
            // A whirl turn must be at least as fast as the window rule's whirl travel.
            streak: Streak::new(min_duty, 0.5 * window_s),
            bins: [Bin::empty(-1); WINDOW_BINS],
            cur_k: -1,
            last_t: 0.0,
            orbit: orbit_points.map(|_| Orbit {
                clearance_m,
                samples: Vec::new(),
            }),
            orbit_dt: orbit_points.map_or(f64::INFINITY, |n| duration_s / n.max(1) as f64),
            orbit_last_t: f64::NEG_INFINITY,
            prev_end: None,
            probes: Probes::default(),
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
        // This step's interpolant only. (Probes lie strictly inside their step, so no time
        // of an earlier step could match; the clear keeps the list to one step's probes.)
        self.probes.taken.clear();
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
            // No sample beats the peak: nothing to refine, unless the peak is this step's
            // start (a step end where the quantity was still rising), whose maximum can lie
            // inside this step although both later samples are lower.
            if vmax <= peak.value && !(imax == 0 && peak.time_s == ts[0]) {
                continue;
            }
            // Bracket around the best sample and refine on the interpolant.
            let (a, b) = match imax {
                0 => (ts[0], ts[1]),
                1 => (ts[0], ts[2]),
                _ => (ts[1], ts[2]),
            };
            let probes = &mut self.probes;
            let (tm, vm) = golden_max(
                |tt, k| get(&probes.get_or_take(tt, k, |tt| sample(sys, &dense.eval(tt)))),
                a,
                b,
            );
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

    /// Updates the unwrapped contact angle from state `y` at time `t` (only while the rotor
    /// is within half a clearance of the wall) and the whirl streak; returns whether the
    /// angle was measured.
    fn track_angle(&mut self, y: &[f64; N], t: f64) -> bool {
        use crate::model::ix::*;
        let (dx, dy) = (y[XR] - y[XB], y[YR] - y[YB]);
        if (dx * dx + dy * dy).sqrt() < self.near_wall_m {
            return false;
        }
        // Angle from the bottom of the race, counter-clockwise positive.
        let raw = dy.atan2(dx) + 0.5 * PI;
        match self.angle_raw_prev {
            None => self.angle = wrap_tau(raw + PI) - PI,
            Some(prev) => self.angle += wrap_tau(raw - prev + PI) - PI,
        }
        self.angle_raw_prev = Some(raw);
        if self.angle_at_first_contact.is_some() {
            self.streak.update(self.angle, t, self.contact_s);
            if self.streak.count.abs() >= self.stop_turns {
                self.whirl_decided = true;
            }
        }
        true
    }

    /// The ring slot of bin `k`, emptied first when it still holds an older bin.
    fn bin_mut(&mut self, k: i64) -> &mut Bin {
        if k > self.cur_k {
            let first = (self.cur_k + 1).max(k - WINDOW_BINS as i64 + 1);
            for kk in first..=k {
                self.bins[kk.rem_euclid(WINDOW_BINS as i64) as usize] = Bin::empty(kk);
            }
            self.cur_k = k;
        }
        &mut self.bins[k.rem_euclid(WINDOW_BINS as i64) as usize]
    }

    /// Books a step `[t0, t1]` (to the bin of its midpoint) with its contact state and the
    /// contact angles measured at its midpoint and end.
    fn bin_step(&mut self, t0: f64, t1: f64, contact: bool, mid: Option<f64>, end: Option<f64>) {
        let k = (0.5 * (t0 + t1) / self.bin_s).floor() as i64;
        let h = t1 - t0;
        let b = self.bin_mut(k);
        b.duration_s += h;
        if contact {
            b.contact_s += h;
        }
        if let Some(a) = mid {
            b.cos_dt += a.cos() * h;
            b.sin_dt += a.sin() * h;
            b.angle_time_s += h;
        }
        for a in [mid, end].into_iter().flatten() {
            b.angle_min = b.angle_min.min(a);
            b.angle_max = b.angle_max.max(a);
            if b.angle_first.is_nan() {
                b.angle_first = a;
            }
            b.angle_last = a;
        }
    }

    /// Statistics over the bins `k0..=k1` of the ring, ending at `t_end`.
    fn stats(&self, k0: i64, k1: i64, t_end: f64) -> WindowStats {
        let mut w = WindowStats::empty(k0.max(0) as f64 * self.bin_s, t_end);
        let (mut dur, mut con, mut c, mut sn, mut at) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut amin, mut amax) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut first, mut last) = (f64::NAN, f64::NAN);
        for k in k0.max(0)..=k1 {
            let b = &self.bins[k.rem_euclid(WINDOW_BINS as i64) as usize];
            if b.k != k {
                continue;
            }
            dur += b.duration_s;
            con += b.contact_s;
            c += b.cos_dt;
            sn += b.sin_dt;
            at += b.angle_time_s;
            amin = amin.min(b.angle_min);
            amax = amax.max(b.angle_max);
            if first.is_nan() {
                first = b.angle_first;
            }
            if !b.angle_last.is_nan() {
                last = b.angle_last;
            }
        }
        if dur > 0.0 {
            w.contact_duty = con / dur;
        }
        if at > 0.0 {
            let (mc, ms) = (c / at, sn / at);
            w.angle_time_s = at;
            w.angle_mean_rad = ms.atan2(mc);
            let r = mc.hypot(ms).min(1.0);
            w.angle_spread_rad = (-2.0 * r.max(1e-300).ln()).sqrt();
        }
        if amax >= amin {
            w.angle_range_rad = amax - amin;
        }
        if !first.is_nan() && !last.is_nan() {
            w.net_turns = (last - first) / TAU * self.spin_sign;
        }
        w
    }

    /// The unwrapped angle at the start of bins `k0..`: the first sample there, else the
    /// current angle.
    fn angle_from(&self, k0: i64) -> f64 {
        for k in k0.max(0)..=self.cur_k {
            let b = &self.bins[k.rem_euclid(WINDOW_BINS as i64) as usize];
            if b.k == k && !b.angle_first.is_nan() {
                return b.angle_first;
            }
        }
        self.angle
    }

    fn record_orbit(&mut self, sys: &DropSystem, t: f64, y: &[f64; N], force: bool) {
        use crate::model::ix::*;
        if let Some(orbit) = &mut self.orbit {
            // A forced sample (release, end) is skipped where a sample at that very time
            // exists already (a run that ends on a step's end): times strictly increase.
            if (force && t > self.orbit_last_t) || t - self.orbit_last_t >= self.orbit_dt {
                let f = sys.forces(y);
                orbit.samples.push(OrbitSample {
                    t_s: t,
                    x_rel_m: y[XR] - y[XB],
                    y_rel_m: y[YR] - y[YB],
                    contact_force_n: f.normal_n.max(0.0),
                    x_race_m: y[XB],
                    y_race_m: y[YB],
                    slip_m_s: f.v_rel_m_s,
                    heat_power_w: f.friction_power_w + f.bearing_power_w,
                    rotor_speed_rad_s: y[WR],
                    race_speed_rad_s: y[WB],
                });
                self.orbit_last_t = t;
            }
        }
    }

    /// Records the release state in the orbit.
    pub fn start(&mut self, sys: &DropSystem, y: &[f64; N]) {
        self.record_orbit(sys, 0.0, y, true);
    }

    /// The features so far, at time `t_end` in state `y` (the driver asks whether the class
    /// has settled before it ends a run).
    pub fn features(&self, t_end: f64, y: &[f64; N]) -> Features {
        let half = (WINDOW_BINS / 2) as i64;
        let k1 = self.cur_k;
        let k0 = k1 - WINDOW_BINS as i64 + 1;
        let stats = self.stats(k0, k1, t_end);
        let halves = [
            {
                let mut h = self.stats(k0, k0 + half - 1, t_end);
                h.end_s = (k0 + half).max(0) as f64 * self.bin_s;
                h
            },
            self.stats(k0 + half, k1, t_end),
        ];
        let window = Window {
            // The window is full once the run has passed its length (to bin rounding).
            full: k0 >= 0 && t_end >= self.window_s * (1.0 - 1e-9),
            stats,
        };
        let turns_from = |a: f64| {
            self.angle_at_first_contact
                .map_or(0.0, |a0| (a - a0) / TAU * self.spin_sign)
        };
        let net = turns_from(self.angle);
        let streak = self.streak.count * self.spin_sign;
        let transient_whirl_turns = if self.whirl_decided {
            turns_from(self.streak.start_angle)
        } else {
            turns_from(self.angle_from(k0))
        };
        let st = &self.streak;
        let whirl_frequency_hz = if st.count.abs() >= 2.0 && st.last_turn_s > st.first_turn_s {
            st.count.signum() * (st.count.abs() - 1.0) / (st.last_turn_s - st.first_turn_s)
                * self.spin_sign
        } else if stats.end_s > stats.start_s {
            stats.net_turns / (stats.end_s - stats.start_s)
        } else {
            0.0
        };
        use crate::model::ix::*;
        let to_rpm = 30.0 / PI;
        Features {
            first_contact_force_n: self.first_impact_fn,
            max_contact_force_n: self.max_fn.value,
            max_contact_force_time_s: self.max_fn.time_s,
            peak_friction_power_w: self.max_hs.value,
            peak_heat_power_w: self.max_h.value,
            impacts: self.impacts,
            first_contact_time_s: self.first_contact_s,
            contact_time_s: self.contact_s,
            net_whirl_turns: net,
            transient_whirl_turns,
            whirl_streak_turns: streak,
            whirl_frequency_hz,
            window,
            window_halves: halves,
            final_rotor_speed_rpm: y[WR] * to_rpm,
            final_race_speed_rpm: y[WB] * to_rpm,
        }
    }

    /// Final features after the run ended at `t_end` in state `y`, and the orbit.
    pub fn finish(
        mut self,
        sys: &DropSystem,
        t_end: f64,
        y: &[f64; N],
    ) -> (Features, Option<Orbit>) {
        self.record_orbit(sys, t_end, y, true);
        (self.features(t_end, y), self.orbit)
    }
}

/// The monitor's halt: the whirl stopping rule decided (the contact point made the scene's
/// `whirl_stop_turns` consecutive carried turns in one direction).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WhirlDecided;

impl Observer<DropSystem, N> for Monitor {
    type Halt = WhirlDecided;
    fn on_step(&mut self, sys: &DropSystem, step: &StepView<'_, N>) -> ControlFlow<WhirlDecided> {
        let d = step.dense;
        let (t0, t1) = (d.t0(), d.t1());
        let tm = 0.5 * (t0 + t1);
        let (y0, y1) = (d.y0(), d.y1());
        // The driver's midpoint value where it has one (the same bits as evaluating here).
        let ym_here;
        let ym = match step.midpoint {
            Some(ym) => ym,
            None => {
                ym_here = d.eval(tm);
                &ym_here
            }
        };
        let contact = sys.mode.contact;
        if contact {
            self.contact_s += t1 - t0;
            if self.angle_at_first_contact.is_none() {
                let _ = self.track_angle(&y0, t0);
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
            sample(sys, ym)
        } else if s0.heat_power >= s1.heat_power {
            s0
        } else {
            s1
        };
        self.track_peaks(sys, d, [t0, tm, t1], [&s0, &sm, &s1]);
        self.prev_end = Some((t1, s1));
        let angle_mid = self.track_angle(ym, tm).then_some(self.angle);
        let angle_end = self.track_angle(&y1, t1).then_some(self.angle);
        self.bin_step(t0, t1, contact, angle_mid, angle_end);
        self.last_t = t1;
        self.record_orbit(sys, t1, &y1, false);
        if self.whirl_decided {
            ControlFlow::Break(WhirlDecided)
        } else {
            ControlFlow::Continue(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_probes_give_the_searches_the_same_bits() {
        // Three quantities refined one after the other on the same bracket, as `track_peaks`
        // does: with the probes shared, each search must end where it ends alone, to the bit,
        // and a probe must be taken afresh only once per time. Two brackets: all three rising
        // through it (the searches coincide), and peaks at three different places inside (they
        // part after a few probes).
        type Get = fn(&Sample) -> f64;
        let gets: [Get; 3] = [|x| x.normal, |x| x.friction_power, |x| x.heat_power];
        for (a, b, peaks) in [(0.4, 0.5, [0.9, 0.8, 0.7]), (0.0, 1.0, [0.3, 0.5, 0.71])] {
            let at = |t: f64| Sample {
                normal: -(t - peaks[0]) * (t - peaks[0]) + 0.1 * t,
                friction_power: (3.0 * (t - peaks[1])).cos(),
                heat_power: 1.0 / (1.0 + (t - peaks[2]).powi(2)),
            };
            let mut probes = Probes::default();
            let (mut fresh_shared, mut fresh_alone) = (0, 0);
            for get in gets {
                let shared = golden_max(
                    |t, k| {
                        get(&probes.get_or_take(t, k, |t| {
                            fresh_shared += 1;
                            at(t)
                        }))
                    },
                    a,
                    b,
                );
                let alone = golden_max(
                    |t, _| {
                        fresh_alone += 1;
                        get(&at(t))
                    },
                    a,
                    b,
                );
                assert_eq!(
                    (shared.0.to_bits(), shared.1.to_bits()),
                    (alone.0.to_bits(), alone.1.to_bits())
                );
            }
            let distinct = {
                let mut t: Vec<u64> = probes.taken.iter().map(|(k, _)| *k).collect();
                t.sort_unstable();
                t.dedup();
                t.len()
            };
            assert_eq!(fresh_shared, distinct);
            assert_eq!(fresh_shared, probes.taken.len());
            assert!(fresh_shared < fresh_alone, "{fresh_shared} {fresh_alone}");
        }
    }

    #[test]
    fn wrap_tau_is_rem_euclid_bit_for_bit() {
        // The edges of the fast path and of each branch, their neighbours, and a sweep.
        let mut xs = vec![-0.0, 0.0, TAU, -TAU, 2.0 * TAU, PI, -PI, 3.0 * PI, f64::NAN];
        for e in [-TAU, 0.0, TAU, 2.0 * TAU] {
            xs.extend([e.next_down(), e.next_up()]);
        }
        xs.extend((-4000..=4000).map(|i| i as f64 * 0.003_141_5));
        for x in xs {
            let (a, b) = (wrap_tau(x), x.rem_euclid(TAU));
            assert!(a.to_bits() == b.to_bits(), "x {x:e}: {a:e} against {b:e}");
        }
    }
}
