//! The rows of an ensemble's files: `members.jsonl` ([`MemberRecord`], one per drop, with
//! what it [`Drawn`]) and `cells.jsonl` ([`CellStats`], one per cell, with [`Percentiles`]).
//! A probability or percentile with no finished member is NaN, written `null`, and read back
//! as NaN, so a file read and written again gives the same bytes.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use whirlmap_core::OrbitClass;

use crate::point::Inputs;

/// What one member drew (its release), as recorded in `members.jsonl`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Drawn {
    /// Unbalance eccentricity (m).
    pub unbalance_m: f64,
    /// Unbalance angle at release (rad).
    pub unbalance_phase_rad: f64,
    /// Rotor centre at release (m).
    pub release_offset_m: [f64; 2],
    /// Rotor centre velocity at release (m/s).
    pub release_velocity_m_s: [f64; 2],
    /// Race spin at release (rad/s).
    pub race_speed_rad_s: f64,
}

/// The `q` quantile (0..=1) of `sorted` (ascending), linear between order statistics
/// (Hyndman-Fan type 7, numpy's default). NaN when empty.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let h = q.clamp(0.0, 1.0) * (n - 1) as f64;
            let i = (h.floor() as usize).min(n - 2);
            sorted[i] + (h - i as f64) * (sorted[i + 1] - sorted[i])
        }
    }
}

/// p10, p50 and p90 of a quantity over a cell's ok members (NaN, written null, if none).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// 10th percentile.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p10: f64,
    /// Median.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p50: f64,
    /// 90th percentile.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p90: f64,
}

impl Percentiles {
    /// From unsorted values (non-finite ones dropped).
    pub fn of(values: &[f64]) -> Self {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        Self {
            p10: percentile(&v, 0.1),
            p50: percentile(&v, 0.5),
            p90: percentile(&v, 0.9),
        }
    }
}

/// One member's outcome, as written to `members.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MemberRecord {
    /// Cell index.
    pub cell: usize,
    /// Member index in the cell.
    pub member: usize,
    /// The cell's inputs.
    pub inputs: Inputs,
    /// What the member drew.
    pub drawn: Drawn,
    /// Stable hash of the member's scene.
    pub scene_hash: String,
    /// Orbit class; `None` when the drop failed.
    pub class: Option<OrbitClass>,
    /// Maximum contact force (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_contact_force_n: Option<f64>,
    /// Peak heat power (W).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_heat_power_w: Option<f64>,
    /// The failure, `kind: message`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// Statistics of one cell, as written to `cells.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellStats {
    /// Cell index.
    pub index: usize,
    /// Axis name -> value.
    pub inputs: BTreeMap<String, f64>,
    /// Members run.
    pub members: usize,
    /// Members that finished.
    pub ok: usize,
    /// Members that failed (left out of everything below).
    pub failed: usize,
    /// Members that whirled (backward or forward).
    pub whirl: usize,
    /// whirl / ok (NaN, written null, when no member finished).
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p_whirl: f64,
    /// Wilson interval lower end.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p_lo: f64,
    /// Wilson interval upper end.
    #[serde(deserialize_with = "crate::nan::null_as_nan")]
    pub p_hi: f64,
    /// Class name -> members.
    pub classes: BTreeMap<String, usize>,
    /// Maximum contact force (N) over the ok members.
    pub max_contact_force_n: Percentiles,
    /// Peak heat power (W) over the ok members.
    pub peak_heat_power_w: Percentiles,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every line of `file` read as `T` and written again is the line.
    fn round_trip<T: Serialize + for<'de> Deserialize<'de>>(file: &str) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../results")
            .join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        for (n, line) in text.lines().enumerate() {
            let row: T = serde_json::from_str(line).unwrap();
            let again = serde_json::to_string(&row).unwrap();
            assert!(again == line, "{} line {}", path.display(), n + 1);
        }
    }

    #[test]
    fn committed_ensemble_rows_read_back_to_the_same_bytes() {
        for dir in ["ensemble-paper", "paper/probability"] {
            round_trip::<MemberRecord>(&format!("{dir}/{}", crate::files::MEMBERS_FILE));
            round_trip::<CellStats>(&format!("{dir}/{}", crate::files::CELLS_FILE));
        }
    }

    #[test]
    fn a_cell_without_finished_members_reads_back_as_nan() {
        let p = Percentiles::of(&[]);
        let text = serde_json::to_string(&p).unwrap();
        assert_eq!(text, r#"{"p10":null,"p50":null,"p90":null}"#);
        let back: Percentiles = serde_json::from_str(&text).unwrap();
        assert!(back.p10.is_nan() && back.p50.is_nan() && back.p90.is_nan());
    }
}
