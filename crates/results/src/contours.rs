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

impl ContourGroup {
    /// For a level without a crossing in the range (`speed_rpm` null): whether P(whirl) is at
    /// or above it already at the lowest speed with a value, so that the crossing lies below
    /// the range; false when P stays below the level (the crossing lies above the range, or
    /// no cell has a value).
    pub fn reached_below_range(&self, level: f64) -> bool {
        self.p_whirl
            .iter()
            .flatten()
            .find(|p| p.is_finite())
            .is_some_and(|p| *p >= level)
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_out_of_range_is_placed_below_or_above_it() {
        let g = |p: Vec<Option<f64>>| ContourGroup {
            inputs: BTreeMap::new(),
            speeds_rpm: (0..p.len()).map(|k| 4000.0 + 2000.0 * k as f64).collect(),
            p_whirl: p,
            levels: Vec::new(),
            non_monotone: false,
        };
        // P 0.25 already at the lowest speed with a value (the first cell had none).
        let rising = g(vec![None, Some(0.25), Some(0.5), Some(0.75)]);
        assert!(rising.reached_below_range(0.1) && rising.reached_below_range(0.25));
        assert!(
            !rising.reached_below_range(0.9),
            "never reached: above the range"
        );
        assert!(!g(vec![None, None]).reached_below_range(0.1));
    }
}
