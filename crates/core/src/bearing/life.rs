//! Load-life and damage: Lundberg-Palmgren's rating life as ISO 281 states it, and the
//! Palmgren-Miner sum over counted over-rolling cycles.
//!
//! - ISO 281:2007 § 6 (Lundberg & Palmgren 1947): the basic rating life of a ball bearing,
//!   reached or exceeded by 90 % of a large group of identical bearings, is
//!   `L10 = (C / P)^3` million revolutions, `P` the dynamic equivalent radial load. For a
//!   face-to-face pair rated as one double-row bearing, with no axial load, `P = F_r`.
//! - Palmgren-Miner (Palmgren 1924, Miner 1945; ISO 281 § 6 for variable loads): the damage of
//!   `n_k` cycles at a load whose life is `N_k` cycles is `Σ n_k / N_k`; failure (in the
//!   L10 sense) at a damage of 1.
//!
//! ## Cycles at the inner race
//! A point of the rotating inner raceway is over-rolled by the balls `Z/2 (1 + γ)` times per
//! revolution of the ring (per row, Harris & Kotzalas ch. 10). Each over-rolling is one
//! stress cycle from zero to the contact load and back. The damage per cycle is normalised so
//! that a steady radial load reproduces ISO 281's life exactly:
//!
//! ```text
//! Q_C  = C / (i Z J_r cos α)             the most loaded ball's load when the pair carries C
//! N_C  = 1e6 · Z/2 (1 + γ)               over-rolling cycles in 10^6 revolutions
//! d(Q) = (Q / Q_C)^3 / N_C               damage of one cycle whose height is the most
//!                                        loaded ball's load Q
//! ```
//!
//! In a drop the load changes within a pass; the analysis gives each pass the cubic mean of
//! the most loaded ball's load over it (`analysis`), which keeps this normalisation exact.
//!
//! A steady `F_r` gives `Q = Q_C F_r / C` at every pass and `Z/2 (1 + γ)` passes a
//! revolution, so the damage per revolution is `(F_r / C)^3 / 1e6 = 1 / L10`.
//! Why the most loaded ball's load stands for the cycle: with zero clearance and pure radial
//! load the distribution keeps its shape (`cos^1.5` over 180°), so every ball's load, and the
//! cubic mean over the circumference that a point of the rotating ring integrates over its
//! revolutions (ISO/TS 16281's equivalent load of a rotating ring), are fixed multiples of
//! `Q_max`; the normalisation at the rating condition carries that constant.

use super::geometry::BearingPair;
use super::load::RADIAL_INTEGRAL_ZERO_CLEARANCE;
use serde::{Deserialize, Serialize};

/// Lundberg-Palmgren's load-life exponent of ball bearings (ISO 281): `L ∝ P^-3`.
pub const BALL_LIFE_EXPONENT: f64 = 3.0;

/// Revolutions in ISO 281's unit of life.
pub const MILLION_REVOLUTIONS: f64 = 1e6;

/// ISO 281's basic rating life `L10 = (C/P)^3` million revolutions, returned in revolutions.
/// Infinite for `P = 0`.
pub fn l10_revolutions(dynamic_rating_n: f64, equivalent_load_n: f64) -> f64 {
    if equivalent_load_n <= 0.0 {
        return f64::INFINITY;
    }
    MILLION_REVOLUTIONS * (dynamic_rating_n / equivalent_load_n).powf(BALL_LIFE_EXPONENT)
}

/// Drops to failure in the L10 sense from the damage of one drop (Palmgren-Miner: failure at
/// a damage sum of 1): `1 / damage`, infinite for no damage.
pub fn drops_to_failure(damage_per_drop: f64) -> f64 {
    if damage_per_drop > 0.0 {
        1.0 / damage_per_drop
    } else {
        f64::INFINITY
    }
}

/// The inner raceway's fatigue law in over-rolling cycles, normalised to ISO 281 (module
/// docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InnerRaceFatigue {
    /// `Q_C` (N): the most loaded ball's load when the pair carries its dynamic rating `C`.
    pub rating_ball_load_n: f64,
    /// `N_C`: over-rolling cycles of one point in 10^6 revolutions, `1e6 Z/2 (1 + γ)`.
    pub cycles_at_rating: f64,
}

impl InnerRaceFatigue {
    /// The law for `pair`, from its dynamic rating and geometry.
    pub fn new(pair: &BearingPair) -> Self {
        InnerRaceFatigue {
            rating_ball_load_n: pair.dynamic_rating_n
                / (pair.rows as f64
                    * pair.balls_per_row as f64
                    * RADIAL_INTEGRAL_ZERO_CLEARANCE
                    * pair.contact_angle_rad.cos()),
            cycles_at_rating: MILLION_REVOLUTIONS * pair.inner_ball_passes_per_revolution(),
        }
    }

    /// Life (cycles) of a point over-rolled at the most-loaded-ball load `q_n`:
    /// `N_C (Q_C / Q)^3`.
    pub fn cycles_to_failure(&self, q_n: f64) -> f64 {
        if q_n <= 0.0 {
            return f64::INFINITY;
        }
        self.cycles_at_rating * (self.rating_ball_load_n / q_n).powf(BALL_LIFE_EXPONENT)
    }

    /// Palmgren-Miner damage of `count` cycles (1 or 0.5 from the rainflow count, or a
    /// fraction) of range `range_n` from zero: `count / N(Q)`.
    pub fn damage(&self, range_n: f64, count: f64) -> f64 {
        if range_n <= 0.0 {
            return 0.0;
        }
        count * (range_n / self.rating_ball_load_n).powf(BALL_LIFE_EXPONENT) / self.cycles_at_rating
    }
}

/// One class of the load spectrum: the counted cycles whose range falls in
/// `[lower_n, upper_n)` and their Palmgren-Miner damage.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LoadClass {
    /// Lower bound of the class (N), most-loaded-ball load.
    pub lower_n: f64,
    /// Upper bound (N); the last class is open (`f64::INFINITY`, `null` in JSON).
    pub upper_n: f64,
    /// Cycles counted in the class (half cycles count 0.5).
    pub cycles: f64,
    /// Their damage.
    pub damage: f64,
}

/// The load spectrum of a drop: [`LoadSpectrum::CLASSES`] classes of width a tenth of the
/// static-limit ball load (the load at which the contact reaches the static limit pressure),
/// the last one holding everything at or above the limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoadSpectrum {
    /// The classes, lowest first.
    pub classes: Vec<LoadClass>,
}

impl LoadSpectrum {
    /// Number of classes: ten below the static limit, one at or above it.
    pub const CLASSES: usize = 11;

    /// An empty spectrum for the static-limit ball load `limit_n` (N).
    pub fn new(limit_n: f64) -> Self {
        let w = limit_n / 10.0;
        let classes = (0..LoadSpectrum::CLASSES)
            .map(|i| LoadClass {
                lower_n: w * i as f64,
                upper_n: if i + 1 == LoadSpectrum::CLASSES {
                    f64::INFINITY
                } else {
                    w * (i + 1) as f64
                },
                cycles: 0.0,
                damage: 0.0,
            })
            .collect();
        LoadSpectrum { classes }
    }

    /// Adds `count` cycles of range `range_n` with damage `damage`.
    pub fn add(&mut self, range_n: f64, count: f64, damage: f64) {
        let w = self.classes[1].lower_n;
        let i = if w > 0.0 {
            ((range_n / w).floor().max(0.0) as usize).min(LoadSpectrum::CLASSES - 1)
        } else {
            0
        };
        self.classes[i].cycles += count;
        self.classes[i].damage += damage;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steady_load_damage_per_revolution_is_one_over_l10() {
        let pair = BearingPair::default();
        let f = InnerRaceFatigue::new(&pair);
        let fr = 3000.0;
        let q = f.rating_ball_load_n * fr / pair.dynamic_rating_n;
        let per_rev = pair.inner_ball_passes_per_revolution() * f.damage(q, 1.0);
        let l10 = l10_revolutions(pair.dynamic_rating_n, fr);
        assert!((per_rev * l10 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn spectrum_classes_cover_the_line() {
        let mut s = LoadSpectrum::new(2000.0);
        s.add(0.0, 1.0, 0.0);
        s.add(199.9, 0.5, 0.0);
        s.add(200.0, 1.0, 0.0);
        s.add(1999.0, 1.0, 0.0);
        s.add(5000.0, 1.0, 0.0);
        assert_eq!(s.classes[0].cycles, 1.5);
        assert_eq!(s.classes[1].cycles, 1.0);
        assert_eq!(s.classes[9].cycles, 1.0);
        assert_eq!(s.classes[10].cycles, 1.0);
        assert!(s.classes[10].upper_n.is_infinite());
    }
}
