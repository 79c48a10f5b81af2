//! The rows of `adaptive.json`, the adaptive refinement of a class map
//! ([`AdaptiveReport`]). A P(whirl) of a failed corner is NaN, written `null`, and read back
//! as NaN, so the file read and written again gives the same bytes.

use serde::{Deserialize, Serialize};

/// How two boundaries (the adaptive map's boundary against the full grid's) agree.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Agreement {
    /// Largest distance between the two crossings over the columns where both have one, in
    /// fine speed steps.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub max_shift_cells: f64,
    /// Columns where one has a crossing and the other not.
    pub columns_differing: usize,
    /// Fine points whose bin (safe, uncertain, whirl) differs between the two maps.
    pub points_differing: usize,
}

/// One evaluated corner in `adaptive.json`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Corner {
    /// Release speed (r/min).
    pub speed_rpm: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// P(whirl) (single drops: 1 whirl, 0 not; null failed).
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p_whirl: f64,
}

/// The boundary at one mu.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundaryPoint {
    /// Friction coefficient.
    pub mu: f64,
    /// Where P(whirl) first reaches 1/2 along speed in the adaptive map (r/min).
    pub speed_rpm: Option<f64>,
    /// The same in the full grid (with `--compare-full`).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "crate::nan::present"
    )]
    pub full_speed_rpm: Option<Option<f64>>,
}

/// The full-grid comparison of `adaptive.json`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Drops of the full fine grid.
    pub full_grid_drops: usize,
    /// How the boundaries agree.
    pub agreement: Agreement,
}

/// The contents of `adaptive.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveReport {
    /// Spec name.
    pub name: String,
    /// Fine grid points along speed and mu.
    pub fine_points: (usize, usize),
    /// Seed grid points along speed and mu.
    pub seed_points: (usize, usize),
    /// The bins' bounds.
    pub p_bounds: [f64; 2],
    /// Drops per corner (1, or the ensemble's members).
    pub drops_per_corner: usize,
    /// Refinement rounds after the seed grid.
    pub rounds: usize,
    /// Corners evaluated.
    pub corners: usize,
    /// Drops the adaptive search used.
    pub drops_used: usize,
    /// Drops of the full fine grid it replaces.
    pub full_grid_drops: usize,
    /// `drops_used / full_grid_drops`.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub drops_ratio: f64,
    /// Boundary cells (refined to the smallest size).
    pub boundary_cells: usize,
    /// Per mu, the 50 % crossing along speed.
    pub boundary: Vec<BoundaryPoint>,
    /// With `--compare-full`: the full grid's drops and the agreement.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comparison: Option<Comparison>,
    /// Every evaluated corner, in index order.
    pub evaluated: Vec<Corner>,
}

impl AdaptiveReport {
    /// The file's text: pretty JSON and a final newline.
    pub fn to_text(&self) -> String {
        let text = serde_json::to_string_pretty(self).expect("reports serialise");
        format!("{text}\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn committed_adaptive_maps_read_back_to_the_same_bytes() {
        let results = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results");
        for dir in [
            "adaptive-paper",
            "adaptive-paper-64",
            "adaptive-paper-64-seed9",
        ] {
            let path = results.join(dir).join(crate::files::ADAPTIVE_FILE);
            let text = std::fs::read_to_string(&path).unwrap();
            let report: AdaptiveReport = serde_json::from_str(&text).unwrap();
            assert!(
                report.to_text() == text,
                "{} reads back differently",
                path.display()
            );
        }
    }
}
