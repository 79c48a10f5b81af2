//! Re-checking a critical-speed bracket at a tighter fidelity preset.
//!
//! A search run at a cheap preset (say `draft`) brackets the whirl boundary with two drops.
//! Those two cells decide the answer, so they are run again at the next tighter preset; the
//! result says whether the tighter model agrees (non-whirl below, whirl above) and is
//! recorded next to the bracket. When it does not agree, the search runs again at the
//! tighter preset over at least two lattice steps either side of the bracket (within the range
//! searched), to say where that
//! preset puts the onset ([`Relocated`]).

use crate::cancel::Cancel;
use crate::critical::{drop_outcome, fmt_rpm, search, CriticalOptions, CriticalRow, Outcome};
use rayon::prelude::*;
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::{DropOptions, Fidelity, Scene};

pub use whirlmap_results::critical::{Recheck, Relocated};

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
    let relocated = (!confirmed).then(|| relocate(&s, row, run));
    Some(Recheck {
        fidelity: tighter,
        lo: (lo, out_lo),
        hi: (hi, out_hi),
        confirmed,
        relocated,
    })
}

/// Lattice steps either side of the bracket that [`relocate`] searches: the convergence
/// study's tolerance on an onset (docs/accuracy.md).
const WINDOW_STEPS: f64 = 2.0;

/// Searches `row`'s bracket again on `tighter_scene` (the tighter preset's, with the row's
/// friction coefficient) on its lattice and tolerance, over a window from [`WINDOW_STEPS`]
/// lattice steps below the lattice point under the bracket to as many above the one over it,
/// within the range the row searched. Its ends are lattice points or the range's, so its
/// scan drops are the ones a search of the whole range drops there, and it finds the onset
/// that search would, when that onset is in the window.
fn relocate(
    tighter_scene: &Scene,
    row: &CriticalRow,
    run: &(dyn Fn(&Scene, f64) -> Outcome + Sync),
) -> Relocated {
    let [lo, hi] = row.bracket_rpm.expect("a re-checked row has a bracket");
    let res = row.resolution_rpm;
    let from = (res * ((lo / res).floor() - WINDOW_STEPS)).max(row.from_rpm);
    let to = (res * ((hi / res).ceil() + WINDOW_STEPS)).min(row.to_rpm);
    let o = CriticalOptions {
        from_rpm: from,
        to_rpm: to,
        resolution_rpm: row.resolution_rpm,
        tol_rpm: row.tol_rpm,
        duration_s: row.duration_s,
    };
    let found = search(|speed| run(tighter_scene, speed), &o)
        .expect("a window inside a searched range is a valid search");
    let w = found.into_row(row.mu, &o, String::new());
    let (range_from, range_to) = (from <= row.from_rpm, to >= row.to_rpm);
    let (onset_rpm, note) = match (w.undecided, w.onset_rpm, w.bracket_rpm) {
        (true, _, _) => (
            None,
            format!(
                "its onset there undecided in {}-{} r/min by failed or unsettled drops",
                fmt_rpm(from),
                fmt_rpm(to)
            ),
        ),
        (false, Some(onset), Some(_)) => {
            let d = onset - row.onset_rpm.unwrap_or(hi);
            let by = match d {
                0.0 => "the same".to_string(),
                _ if d < 0.0 => format!("{} r/min lower", fmt_rpm(-d)),
                _ => format!("{} r/min higher", fmt_rpm(d)),
            };
            (
                Some(onset),
                format!("its onset there {} r/min, {by}", fmt_rpm(onset)),
            )
        }
        (false, Some(_), None) if range_from => (
            None,
            format!(
                "whirl there already at the range's lowest speed, {} r/min",
                fmt_rpm(from)
            ),
        ),
        (false, Some(_), None) => (
            None,
            format!(
                "whirl there already at {} r/min: its onset is lower, by more than two lattice steps",
                fmt_rpm(from)
            ),
        ),
        (false, None, _) if range_to => (
            None,
            format!(
                "no whirl there from {} r/min to the range top",
                fmt_rpm(from)
            ),
        ),
        (false, None, _) => (
            None,
            format!(
                "no whirl there up to {} r/min: its onset is higher, by more than two lattice steps",
                fmt_rpm(to)
            ),
        ),
    };
    Relocated {
        window_rpm: [from, to],
        onset_rpm,
        drops: w.drops,
        note,
    }
}
