//! The touchdown bearing pair's survival analysis: contact stress of its balls.
//!
//! - [`hertz`]: the contact ellipse and maximum pressure of a ball in a groove (Harris &
//!   Kotzalas, *Essential Concepts of Bearing Technology*, 5th ed., ch. 2 and 6), the
//!   ellipticity solved exactly from the complete elliptic integrals.

pub mod hertz;

pub use hertz::{ContactEllipse, PointContact, Race};
