//! The streaming bearing analysis of one drop: fed the race's motion sample by sample, it
//! keeps the peak ball load and contact pressures and accumulates the fatigue damage, in
//! constant memory.
//!
//! Independent of the integrator: it needs samples in non-decreasing time, at any spacing
//! (a drop's accepted steps are irregular). Between two samples the race speed and the
//! support force are taken as linear in time, which is how ball passes inside a step get
//! their time and load. Feed it at every accepted step's end; a located force peak fed as an
//! extra sample puts the peak ball load on the located peak instead of the nearest step end.

use super::geometry::BearingPair;
use super::hertz::{ContactEllipse, PointContact};
use super::life::{drops_to_failure, InnerRaceFatigue, LoadSpectrum, MILLION_REVOLUTIONS};
use super::load::BallSet;
use super::rainflow::{Cycle, Rainflow};
use crate::error::InvalidParameter;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// What a drop did to the touchdown bearing pair. Every number rests on the assumptions of
/// [`assumptions`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BearingReport {
    /// Peak load on one ball (N): the most loaded ball, a ball on the load line
    /// ([`BallSet::max_ball_load_from_force_n`]), Stribeck's `Q_max = F / (i Z J_r cos α)`.
    pub peak_ball_load_n: f64,
    /// Time of the peak (s); 0 if the bearing was never loaded.
    pub peak_time_s: f64,
    /// Radial load on the pair at the peak (N).
    pub peak_bearing_load_n: f64,
    /// Race displacement relative to the outer ring at the peak (m).
    pub peak_race_displacement_m: f64,
    /// The inner raceway's contact ellipse under the peak ball load (Harris ch. 6).
    pub inner_contact: ContactEllipse,
    /// The outer raceway's contact ellipse under the peak ball load.
    pub outer_contact: ContactEllipse,
    /// Peak maximum pressure at the inner raceway (Pa).
    pub peak_inner_pressure_pa: f64,
    /// Peak maximum pressure at the outer raceway (Pa).
    pub peak_outer_pressure_pa: f64,
    /// The larger of the two (Pa).
    pub peak_contact_pressure_pa: f64,
    /// Static safety factor as a pressure ratio, `s0 = p_limit / p_max` (ISO 76's
    /// `p_limit` = 4.2 GPa for ball bearings): below 1 the drop brinells the races. Infinite
    /// if the bearing was never loaded.
    pub static_safety_factor: f64,
    /// The same margin as a load ratio, `(p_limit / p_max)^3`: the catalogues' `s0 = C0/P0`
    /// form (pressure grows as the cube root of load), for comparison with their
    /// recommended values.
    pub static_load_safety_factor: f64,
    /// Inner-ring revolutions relative to the outer ring, `∫|ω_race| dt / 2π`.
    pub race_revolutions: f64,
    /// Over-rolling cycles of a point of the inner raceway, per row,
    /// `Z/2 (1 + γ) · race_revolutions`.
    pub over_rolling_cycles: f64,
    /// Fatigue damage of the drop, Palmgren-Miner over the rainflow-counted over-rolling
    /// cycles with ISO 281's `(C/P)^3` life ([`super::life`]).
    pub damage_per_drop: f64,
    /// Drops to failure in the L10 sense (10 % of bearings failed): `1 / damage_per_drop`;
    /// infinite (`null` in JSON) for no damage.
    pub drops_to_failure: f64,
    /// ISO 281's mean equivalent load of the drop (N): the steady radial load that would do
    /// the same damage over the same revolutions, `C (damage · 1e6 / revolutions)^(1/3)`.
    pub equivalent_load_n: f64,
    /// Counted cycles and damage by load class.
    pub load_spectrum: LoadSpectrum,
    /// Samples used.
    pub samples: u64,
    /// Samples ignored: earlier than the previous one, or not finite.
    pub ignored_samples: u64,
    /// Times the rainflow residue was cut at its memory bound (0 in practice: a pulse
    /// train keeps at most three points).
    pub rainflow_truncations: u64,
}

/// The state after the latest sample, for time histories.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BearingSample {
    /// Time (s).
    pub t_s: f64,
    /// Radial load on the pair (N).
    pub bearing_load_n: f64,
    /// Load on the most loaded ball (N).
    pub max_ball_load_n: f64,
    /// Maximum pressure at the inner raceway (Pa).
    pub inner_pressure_pa: f64,
    /// Maximum pressure at the outer raceway (Pa).
    pub outer_pressure_pa: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Sample {
    t_s: f64,
    x_m: f64,
    y_m: f64,
    speed_rad_s: f64,
    force_n: f64,
    q_n: f64,
}

/// The streaming analysis ([module docs](self)). Memory is constant: the rainflow residue of
/// the over-rolling pulse train holds at most three points, and is bounded by
/// [`Rainflow::DEFAULT_STACK_LIMIT`] in any case.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingAnalysis {
    pair: BearingPair,
    balls: BallSet,
    inner: PointContact,
    outer: PointContact,
    fatigue: InnerRaceFatigue,
    passes_per_revolution: f64,
    rainflow: Rainflow,
    spectrum: LoadSpectrum,
    damage: f64,
    /// Cumulative over-rolling passes (real; its fractional part is the pass in progress).
    passes: f64,
    /// `∫ Q_max³ dn` over the pass in progress (N³).
    pass_cube_integral: f64,
    revolutions: f64,
    last: Option<Sample>,
    peak: Option<Sample>,
    samples: u64,
    ignored: u64,
}

impl BearingAnalysis {
    /// An analysis of `pair` (validated).
    pub fn new(pair: &BearingPair) -> Result<Self, InvalidParameter> {
        pair.validate()?;
        let mut rainflow = Rainflow::new();
        // The history of a point of the raceway starts unloaded.
        rainflow.push(0.0, &mut |_| {});
        Ok(BearingAnalysis {
            pair: pair.clone(),
            balls: BallSet::from_lumped(pair),
            inner: pair.inner_contact(),
            outer: pair.outer_contact(),
            fatigue: InnerRaceFatigue::new(pair),
            passes_per_revolution: pair.inner_ball_passes_per_revolution(),
            rainflow,
            spectrum: LoadSpectrum::new(pair.static_limit_ball_load_n()),
            damage: 0.0,
            passes: 0.0,
            pass_cube_integral: 0.0,
            revolutions: 0.0,
            last: None,
            peak: None,
            samples: 0,
            ignored: 0,
        })
    }

    /// The bearing pair analysed.
    pub fn pair(&self) -> &BearingPair {
        &self.pair
    }

    /// The ball set (its `K_n` reproduces the pair's lumped `k2`).
    pub fn ball_set(&self) -> &BallSet {
        &self.balls
    }

    /// The inner raceway's fatigue law.
    pub fn fatigue(&self) -> &InnerRaceFatigue {
        &self.fatigue
    }

    /// One sample of the race's motion: time `t_s` (s), the race centre's displacement
    /// `(race_x_m, race_y_m)` from the housing (outer ring) centre (m), and the inner race's
    /// spin `race_speed_rad_s` (rad/s, either sign). The pair's load is the lumped law
    /// `k2 r^1.5` of that displacement (zero clearance: loaded whenever `r > 0`).
    pub fn observe(&mut self, t_s: f64, race_x_m: f64, race_y_m: f64, race_speed_rad_s: f64) {
        let r = race_x_m.hypot(race_y_m);
        let force = self.pair.lumped_stiffness_n_per_m1_5 * r * r.sqrt();
        self.observe_with_force(t_s, race_x_m, race_y_m, race_speed_rad_s, force);
    }

    /// As [`Self::observe`], with the radial force the ball set carries given by the caller
    /// (N, magnitude): the dynamics' support force including its damper, so that the ball
    /// loads resolve to the force the race actually feels. The damping part is spread over
    /// the balls in the elastic distribution's shape (an approximation: each ball's damper
    /// acts along its own line with the ball's approach rate).
    pub fn observe_with_force(
        &mut self,
        t_s: f64,
        race_x_m: f64,
        race_y_m: f64,
        race_speed_rad_s: f64,
        support_force_n: f64,
    ) {
        let finite = [t_s, race_x_m, race_y_m, race_speed_rad_s, support_force_n]
            .iter()
            .all(|v| v.is_finite());
        if !finite || self.last.is_some_and(|p| t_s < p.t_s) {
            self.ignored += 1;
            return;
        }
        let force_n = support_force_n.max(0.0);
        let now = Sample {
            t_s,
            x_m: race_x_m,
            y_m: race_y_m,
            speed_rad_s: race_speed_rad_s,
            force_n,
            q_n: self.balls.max_ball_load_from_force_n(force_n),
        };
        if let Some(prev) = self.last {
            self.advance(&prev, &now);
        }
        if self.peak.is_none_or(|p| now.q_n > p.q_n) {
            self.peak = Some(now);
        }
        self.last = Some(now);
        self.samples += 1;
    }

    /// Turns of the race and the ball passes over a point of the inner raceway between two
    /// samples, the speed and the load linear in between. Each completed pass is one load
    /// pulse `0 → Q → 0` whose height `Q` is the cubic mean of the most loaded ball's load
    /// over that pass, `(∫_pass Q_max³ dn)^(1/3)` with `n` the pass count: the expected
    /// damage of the pass over the position of the point on the ring (module
    /// [`super::life`]), so that the damage is ISO 281's integral of the history whatever
    /// the sampling, and an impact shorter than a pass counts with its share of the pass.
    fn advance(&mut self, prev: &Sample, now: &Sample) {
        let dt = now.t_s - prev.t_s;
        let (w0, w1) = (prev.speed_rad_s, now.speed_rad_s);
        // Integral of |omega| for omega linear in t (exact through a sign change).
        let turned_rad = if w0 * w1 >= 0.0 {
            0.5 * (w0.abs() + w1.abs()) * dt
        } else {
            0.5 * (w0 * w0 + w1 * w1) / (w0.abs() + w1.abs()) * dt
        };
        let revs = turned_rad / (2.0 * PI);
        if !(revs > 0.0) {
            return;
        }
        self.revolutions += revs;
        let n0 = self.passes;
        let n1 = n0 + revs * self.passes_per_revolution;
        let (q0, q1) = (prev.q_n, now.q_n);
        // Load at a pass count between the samples: linear in the passes.
        let q_at = |n: f64| q0 + (q1 - q0) * (n - n0) / (n1 - n0);
        let (mut a, mut qa) = (n0, q0);
        let mut k = n0.floor() + 1.0;
        while k <= n1 {
            let qk = q_at(k);
            self.pass_cube_integral += cube_integral(a, k, qa, qk);
            let height = self.pass_cube_integral.cbrt();
            self.pass_cube_integral = 0.0;
            self.pulse(height);
            (a, qa) = (k, qk);
            k += 1.0;
        }
        self.pass_cube_integral += cube_integral(a, n1, qa, q1);
        self.passes = n1;
    }

    fn pulse(&mut self, q_n: f64) {
        let BearingAnalysis {
            rainflow,
            spectrum,
            damage,
            fatigue,
            ..
        } = self;
        let mut sink = |c: Cycle| {
            let d = fatigue.damage(c.range, c.count);
            *damage += d;
            spectrum.add(c.range, c.count, d);
        };
        rainflow.push(q_n, &mut sink);
        rainflow.push(0.0, &mut sink);
    }

    /// The state after the latest sample, or `None` before the first.
    pub fn latest(&self) -> Option<BearingSample> {
        self.last.map(|s| BearingSample {
            t_s: s.t_s,
            bearing_load_n: s.force_n,
            max_ball_load_n: s.q_n,
            inner_pressure_pa: self.inner.max_pressure_pa(s.q_n),
            outer_pressure_pa: self.outer.max_pressure_pa(s.q_n),
        })
    }

    /// The report so far (the analysis goes on).
    pub fn report(&self) -> BearingReport {
        self.clone().finish()
    }

    /// Ends the drop: counts the rainflow residue as half cycles, adds the pass in progress
    /// as the fraction of a cycle it has completed (so the damage grows continuously with the
    /// drop's length), and reports.
    pub fn finish(mut self) -> BearingReport {
        {
            let BearingAnalysis {
                rainflow,
                spectrum,
                damage,
                fatigue,
                ..
            } = &mut self;
            rainflow.finish(&mut |c: Cycle| {
                let d = fatigue.damage(c.range, c.count);
                *damage += d;
                spectrum.add(c.range, c.count, d);
            });
        }
        let frac = self.passes - self.passes.floor();
        if frac > 0.0 && self.pass_cube_integral > 0.0 {
            let height = (self.pass_cube_integral / frac).cbrt();
            let d = self.fatigue.damage(height, frac);
            self.damage += d;
            self.spectrum.add(height, frac, d);
        }
        let peak = self.peak.unwrap_or(Sample {
            t_s: 0.0,
            x_m: 0.0,
            y_m: 0.0,
            speed_rad_s: 0.0,
            force_n: 0.0,
            q_n: 0.0,
        });
        let inner = self.inner.ellipse(peak.q_n);
        let outer = self.outer.ellipse(peak.q_n);
        let p_max = inner.max_pressure_pa.max(outer.max_pressure_pa);
        let s0 = if p_max > 0.0 {
            self.pair.static_limit_pressure_pa / p_max
        } else {
            f64::INFINITY
        };
        let equivalent_load_n = if self.revolutions > 0.0 {
            self.pair.dynamic_rating_n
                * (self.damage * MILLION_REVOLUTIONS / self.revolutions).cbrt()
        } else {
            0.0
        };
        BearingReport {
            peak_ball_load_n: peak.q_n,
            peak_time_s: peak.t_s,
            peak_bearing_load_n: peak.force_n,
            peak_race_displacement_m: peak.x_m.hypot(peak.y_m),
            inner_contact: inner,
            outer_contact: outer,
            peak_inner_pressure_pa: inner.max_pressure_pa,
            peak_outer_pressure_pa: outer.max_pressure_pa,
            peak_contact_pressure_pa: p_max,
            static_safety_factor: s0,
            static_load_safety_factor: s0.powi(3),
            race_revolutions: self.revolutions,
            over_rolling_cycles: self.passes,
            damage_per_drop: self.damage,
            drops_to_failure: drops_to_failure(self.damage),
            equivalent_load_n,
            load_spectrum: self.spectrum,
            samples: self.samples,
            ignored_samples: self.ignored,
            rainflow_truncations: self.rainflow.truncations(),
        }
    }
}

/// `∫_a^b Q³ dn` for `Q` linear from `qa` at `a` to `qb` at `b`.
fn cube_integral(a: f64, b: f64, qa: f64, qb: f64) -> f64 {
    0.25 * (b - a) * (qa + qb) * (qa * qa + qb * qb)
}

/// The assumptions behind every number of a [`BearingReport`], to print beside them.
pub fn assumptions() -> &'static str {
    "Bearing: the pair of the scene's `bearing` section, with the values listed under \
\"The bearing\" above; \
its defaults are two 71908 CD (15 deg contact angle) face to face, 5.5 mm balls on a 51 mm pitch \
circle (paper Table 3), 22 balls a row and groove conformities 0.52/0.53 assumed (ISO 281 \
rating basis; not in the catalogue tables), bearing steel E = 208 GPa, nu = 0.3.
Loads: rigid rings, zero internal clearance, no axial load (planar model; the two rows share \
the radial load equally and their axial components cancel), contact angle constant, no \
centrifugal or gyroscopic ball loads (quasi-static distribution). The per-ball stiffness is \
the one whose ball set reproduces the paper's lumped k2 (K_n = k2 / (i Z J_r cos^2.5 alpha), \
J_r = 0.2288), so the ball loads resolve to the dynamics' support force; the most loaded ball \
is taken on the load line (Stribeck: Q_max = F / (i Z J_r cos alpha) = 4.37 F_row / (Z cos alpha)), \
an upper bound within 1.5 % at any cage position. A real 71908 CD pair is stiffer by Hertz \
than the paper's k2; that changes the race's displacement, not the ball loads for a given force.
Stress: Hertz point contact, exact elliptic integrals, smooth dry contact (no EHL film, no \
surface traction, no edge loading). Static limit: ISO 76's 4.2 GPa for ball bearings; the \
static safety factor is the pressure ratio 4.2 GPa / p_max (its cube is the load ratio C0/P0 \
of the catalogues).
Fatigue: rolling-contact fatigue of the inner raceway from over-rolling only; a point of the \
rotating inner ring is over-rolled Z/2 (1 + D cos alpha / d_m) times per revolution relative to \
the fixed outer ring (pure rolling kinematics: ball skid during the spin-up is not modelled and \
would change the count); each pass is one cycle 0 -> Q -> 0, Q the cubic mean of the most \
loaded ball's load over the pass (the expected damage of the pass over the position of the \
point on the ring, so an impact shorter than a pass counts with its share of it), \
rainflow-counted by ASTM E1049, with Lundberg-Palmgren / ISO 281 life L10 = (C/P)^3 million revolutions normalised so that \
a steady load gives ISO 281's life exactly, C the pair's basic dynamic rating (ISO 281 formula, \
i = 2), and Palmgren-Miner damage summation. Basic rating life: 90 % reliability, no life \
modification (a_ISO = 1: no lubrication, contamination or fatigue-limit factor), no load \
sequence effect, impact and static overload not counted as fatigue (see the static safety \
factor). Drops to failure = 1 / damage per drop, in the L10 sense (10 % of bearings failed), \
for drops identical to this one; a run stopped early (e.g. a whirl stopped after N turns) gives \
the damage of that run only."
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unloaded_drop_reports_no_damage_and_infinite_margins() {
        let mut a = BearingAnalysis::new(&BearingPair::default()).unwrap();
        for k in 0..100 {
            a.observe(k as f64 * 1e-4, 0.0, 0.0, 500.0);
        }
        let r = a.finish();
        assert_eq!(r.damage_per_drop, 0.0);
        assert!(r.drops_to_failure.is_infinite());
        assert!(r.static_safety_factor.is_infinite());
        assert!(r.race_revolutions > 0.0);
    }

    #[test]
    fn samples_going_back_in_time_or_not_finite_are_ignored() {
        let mut a = BearingAnalysis::new(&BearingPair::default()).unwrap();
        a.observe(1.0, 1e-6, 0.0, 10.0);
        a.observe(0.5, 1e-6, 0.0, 10.0);
        a.observe(2.0, f64::NAN, 0.0, 10.0);
        a.observe(2.0, 1e-6, 0.0, 10.0);
        let r = a.report();
        assert_eq!((r.samples, r.ignored_samples), (2, 2));
    }

    #[test]
    fn a_given_support_force_sets_the_ball_loads() {
        // The damper adds to the elastic force: the balls carry the sum.
        let pair = BearingPair::default();
        let mut a = BearingAnalysis::new(&pair).unwrap();
        let r: f64 = 2e-5;
        let elastic = pair.lumped_stiffness_n_per_m1_5 * r.powf(1.5);
        a.observe_with_force(0.0, r, 0.0, 0.0, 1.5 * elastic);
        let s = a.latest().unwrap();
        let q = 1.5 * elastic
            / (2.0
                * 22.0
                * super::super::load::RADIAL_INTEGRAL_ZERO_CLEARANCE
                * 15f64.to_radians().cos());
        assert!((s.max_ball_load_n / q - 1.0).abs() < 1e-14);
        assert!(
            (s.inner_pressure_pa / pair.inner_contact().max_pressure_pa(q) - 1.0).abs() < 1e-14
        );
    }

    #[test]
    fn a_speed_reversal_turns_by_the_exact_area() {
        // omega goes linearly from +10 to -30 rad/s over 1 s: |omega| integrates to
        // (100 + 900) / (2 * 40) = 12.5 rad.
        let mut a = BearingAnalysis::new(&BearingPair::default()).unwrap();
        a.observe(0.0, 0.0, 0.0, 10.0);
        a.observe(1.0, 0.0, 0.0, -30.0);
        let r = a.finish();
        assert!((r.race_revolutions - 12.5 / (2.0 * PI)).abs() < 1e-14);
    }
}
