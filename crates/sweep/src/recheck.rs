//! Re-checking a critical-speed bracket at a tighter fidelity preset.
//!
//! A search run at a cheap preset (say `draft`) brackets the whirl boundary with two drops.
//! Those two cells decide the answer, so they are run again at the next tighter preset; the
//! result says whether the tighter model agrees (non-whirl below, whirl above) and is
//! recorded next to the bracket.

use crate::cancel::Cancel;
use crate::critical::{drop_outcome, CriticalRow, Outcome};
use rayon::prelude::*;
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::{DropOptions, Fidelity, Scene};

pub use whirlmap_results::critical::Recheck;

/// Re-runs the onset bracket of `row` (searched on `scene`, whose `mu_dynamic` is set) at
/// `tighter`, its two drops at once; `None` without a bracket.
pub fn recheck_bracket(
    scene: &Scene,
    row: &CriticalRow,
    tighter: Fidelity,
    opts: &DropOptions,
) -> Option<Recheck> {
    recheck_with(scene, row, tighter, &|s, speed| {
        drop_outcome(s, speed, opts)
    })
}

/// Re-checks every row's bracket ([`recheck_bracket`]) at `tighter`, the rows at once, each
/// on `base` with the row's friction coefficient, and records each in its row
/// ([`Recheck::apply_to`]: an unconfirmed bracket leaves the row not converged). With `cancel`, a drop not yet started
/// when it is raised is skipped (its outcome "cancelled"; the caller discards the rows)
/// and every drop run is counted on it.
pub fn recheck_rows(
    base: &Scene,
    rows: &mut [CriticalRow],
    tighter: Fidelity,
    opts: &DropOptions,
    cancel: Option<&Cancel>,
) {
    let run = |s: &Scene, speed: f64| match cancel {
        Some(c) if c.requested() => Outcome::Failed("cancelled".to_owned()),
        Some(c) => {
            let outcome = drop_outcome(s, speed, opts);
            c.count_drop();
            outcome
        }
        None => drop_outcome(s, speed, opts),
    };
    rows.par_iter_mut().for_each(|row| {
        let mut s = base.clone();
        s.mu_dynamic = row.mu;
        if let Some(rc) = recheck_with(&s, row, tighter, &run) {
            rc.apply_to(row);
        }
    });
}

fn recheck_with(
    scene: &Scene,
    row: &CriticalRow,
    tighter: Fidelity,
    run: &(dyn Fn(&Scene, f64) -> Outcome + Sync),
) -> Option<Recheck> {
    let [lo, hi] = row.bracket_rpm?;
    let s = tighter.applied(scene);
    let (out_lo, out_hi) = rayon::join(|| run(&s, lo), || run(&s, hi));
    // A settled class below: an unresolved drop is no confirmation (below an onset it
    // leaves a search undecided).
    let settled_below =
        matches!(&out_lo, Outcome::Class(c) if !c.is_whirl() && *c != OrbitClass::Unresolved);
    let confirmed = settled_below && out_hi.whirl() == Some(true);
    Some(Recheck {
        fidelity: tighter,
        lo: (lo, out_lo),
        hi: (hi, out_hi),
        confirmed,
    })
}
