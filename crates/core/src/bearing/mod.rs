//! The touchdown bearing pair's survival analysis: contact stress of its balls, and the
//! counting of their load cycles.
//!
//! - [`hertz`]: the contact ellipse and maximum pressure of a ball in a groove (Harris &
//!   Kotzalas, *Essential Concepts of Bearing Technology*, 5th ed., ch. 2 and 6), the
//!   ellipticity solved exactly from the complete elliptic integrals.
//! - [`rainflow`]: ASTM E1049 rainflow counting, streaming.

pub mod hertz;
pub mod rainflow;

pub use hertz::{ContactEllipse, PointContact, Race};
pub use rainflow::{Cycle, Rainflow};
