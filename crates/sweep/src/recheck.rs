//! Re-checking a critical-speed bracket at a tighter fidelity preset.
//!
//! A search run at a cheap preset (say `draft`) brackets the whirl boundary with two drops.
//! Those two cells decide the answer, so they are run again at the next tighter preset; the
//! result says whether the tighter model agrees (non-whirl below, whirl above) and is
//! recorded next to the bracket.

use crate::critical::{drop_outcome, CriticalRow};
use whirlmap_core::{DropOptions, Fidelity, Scene};

pub use whirlmap_results::critical::Recheck;

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
