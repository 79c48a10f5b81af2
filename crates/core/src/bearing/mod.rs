//! Does the touchdown bearing survive the drop? Ball loads, contact stress against the static
//! limit, and fatigue damage per drop, for the pair of angular contact ball bearings that the
//! dynamics lump into one support.
//!
//! The dynamics are unchanged: this module reads the race's motion as a drop runs. It is pure
//! (no I/O, no threads) and independent of the integrator: [`BearingAnalysis`] takes samples
//! `observe(t_s, race_x_m, race_y_m, race_speed_rad_s)` at any, irregular, spacing and
//! [`BearingAnalysis::finish`] returns a [`BearingReport`].
//!
//! - [`geometry`]: the pair (two 71908 CD face to face), every parameter with its source, and
//!   the ratings from ISO 281's and ISO 76's own formulas.
//! - [`load`]: the ball loads of a displaced race (Harris & Kotzalas, *Essential Concepts of
//!   Bearing Technology*, 5th ed., ch. 7) and the relation `k2 = i Z J_r cos^2.5 α K_n` between
//!   the lumped stiffness of the paper's Table 4 and the per-ball Hertz stiffness.
//! - [`hertz`]: the contact ellipse and maximum pressure of a ball in a groove (Harris &
//!   Kotzalas ch. 2 and 6), the ellipticity solved exactly from the complete elliptic
//!   integrals.
//! - [`rainflow`]: ASTM E1049 rainflow counting, streaming.
//! - [`life`]: Lundberg-Palmgren / ISO 281 load-life and the Palmgren-Miner sum.
//! - [`analysis`]: the streaming analysis of one drop, and [`assumptions`], the text to print
//!   beside its numbers.
//!
//! ## The numbers for the paper's bearing
//! Per-ball stiffness from `k2 = 7.811e9 N/m^1.5`: `K_n = 8.46e8 N/m^1.5`. By Hertz the same
//! geometry has `K_n = 7.24e9 N/m^1.5`, a lumped `k2 = 6.69e10 N/m^1.5`: the paper's support is
//! 8.6 times softer than two rigid-ring 71908 CD (at one force the race moves 4.2 times as
//! far). The ball loads follow from the support force, not from the stiffness, so they are
//! the same either way; only the displacement that carries a given force differs.

pub mod analysis;
pub mod geometry;
pub mod hertz;
pub mod life;
pub mod load;
pub mod rainflow;

pub use analysis::{assumptions, BearingAnalysis, BearingReport, BearingSample};
pub use geometry::BearingPair;
pub use hertz::{ContactEllipse, PointContact, Race};
pub use life::{InnerRaceFatigue, LoadClass, LoadSpectrum};
pub use load::BallSet;
pub use rainflow::{Cycle, Rainflow};
