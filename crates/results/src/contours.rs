//! The rows of an ensemble's `contours.json`: per group of cells (one friction coefficient,
//! for a speed x friction grid) the speeds where the whirl probability reaches each level,
//! with their confidence intervals. Written by the ensemble runs, read by the probability
//! charts.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// One crossing level of a contour group.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevelCrossing {
    /// The probability level.
    pub level: f64,
    /// Speed where P(whirl) first reaches the level (r/min); `None`: not in the range.
    pub speed_rpm: Option<f64>,
    /// Lower end of the interval (where the Wilson upper bound reaches the level); `None`:
    /// below the lowest speed of the grid.
    pub speed_lo_rpm: Option<f64>,
    /// Upper end (where the Wilson lower bound reaches the level); `None`: above the
    /// highest speed of the grid.
    pub speed_hi_rpm: Option<f64>,
    /// What was found, in words.
    pub note: String,
}

/// The contours of one group of cells (one mu, for a speed x mu grid).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContourGroup {
    /// Every input but `speed_rpm`.
    pub inputs: BTreeMap<String, f64>,
    /// The cells' speeds, ascending (r/min).
    pub speeds_rpm: Vec<f64>,
    /// P(whirl) at those speeds (`None`: no member finished).
    pub p_whirl: Vec<Option<f64>>,
    /// One entry per level.
    pub levels: Vec<LevelCrossing>,
    /// P falls with speed by more than the intervals allow somewhere.
    pub non_monotone: bool,
}

/// The contents of `contours.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContoursFile {
    /// Spec name.
    pub name: String,
    /// Members per cell.
    pub members: usize,
    /// Confidence of the intervals.
    pub confidence: f64,
    /// One group per combination of the non-speed inputs.
    pub groups: Vec<ContourGroup>,
}
