//! Re-checking a critical-speed bracket at a tighter fidelity preset.
//!
//! A search run at a cheap preset (say `draft`) brackets the whirl boundary with two drops.
//! Those two cells decide the answer, so they are run again at the next tighter preset; the
//! result says whether the tighter model agrees (non-whirl below, whirl above) and is
//! recorded next to the bracket.

use crate::critical::{drop_outcome, CriticalRow, Outcome};
use serde::{Deserialize, Serialize};
use whirlmap_core::{DropOptions, Fidelity, Scene};

/// The bracket cells run again at a tighter preset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recheck {
    /// The preset the cells were re-run at.
    pub fidelity: Fidelity,
    /// Lower bracket speed (r/min) and its outcome at that preset.
    pub lo: (f64, Outcome),
    /// Upper bracket speed (r/min) and its outcome at that preset.
    pub hi: (f64, Outcome),
    /// True when the tighter preset also gives no whirl at `lo` and whirl at `hi`.
    pub confirmed: bool,
}

/// Re-runs the onset bracket of `row` (searched on `scene`, whose `mu_dynamic` is set) at
/// `tighter`; `None` without a bracket.
pub fn recheck_bracket(
    scene: &Scene,
    row: &CriticalRow,
    tighter: Fidelity,
    opts: &DropOptions,
) -> Option<Recheck> {
    let [lo, hi] = row.bracket_rpm?;
    let s = tighter.applied(scene);
    let out_lo = drop_outcome(&s, lo, opts);
    let out_hi = drop_outcome(&s, hi, opts);
    let confirmed = out_lo.whirl() == Some(false) && out_hi.whirl() == Some(true);
    Some(Recheck {
        fidelity: tighter,
        lo: (lo, out_lo),
        hi: (hi, out_hi),
        confirmed,
    })
}
