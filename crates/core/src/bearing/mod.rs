//! The touchdown bearing pair's survival analysis: its geometry and ratings, the loads of its
//! balls, their contact stress, the counting of their load cycles, and the fatigue damage.
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

pub mod geometry;
pub mod hertz;
pub mod life;
pub mod load;
pub mod rainflow;

pub use geometry::BearingPair;
pub use hertz::{ContactEllipse, PointContact, Race};
pub use life::{InnerRaceFatigue, LoadClass, LoadSpectrum};
pub use load::BallSet;
pub use rainflow::{Cycle, Rainflow};
