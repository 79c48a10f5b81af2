//! Re-checking a critical-speed search at a tighter fidelity preset.
//!
//! A search run at a cheap preset (say `draft`) brackets the whirl boundary with two drops.
//! Those two cells decide the answer, so they are run again at the next tighter preset; the
//! result says whether the tighter model agrees (non-whirl below, whirl above) and is
//! recorded next to the bracket. A search without a bracket is decided by one end of its
//! range: "no whirl in the range" by its highest speed, "whirl already at the lowest speed" by
//! its lowest; that cell is run again the same way (a cheap preset can put an onset just
//! beyond the range the tighter one puts inside it). When the tighter preset does not agree,
//! the search runs again at it over at least two lattice steps either side of the cells
//! (within the range searched; up to sixteen), to say where that preset puts the onset
//! ([`Relocated`]).

use crate::cancel::Cancel;
use crate::critical::{
    drop_outcome, fmt_rpm, search_expecting, CriticalOptions, CriticalRow, Outcome,
};
use crate::progress::Ticker;
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::{DropOptions, Fidelity, Scene};

pub use whirlmap_results::critical::{Recheck, Relocated};

/// Re-runs the cells that decide `row` ([`deciding_cells`]; searched on `scene`, whose
/// `mu_dynamic` is set) at `tighter`, at once; `None` when nothing was decided (every scan
/// drop failed).
pub fn recheck_row(
    scene: &Scene,
    row: &CriticalRow,
    tighter: Fidelity,
    opts: &DropOptions,
) -> Option<Recheck> {
    recheck_with(
        scene,
        row,
        tighter,
        &|s, speed| drop_outcome(s, speed, opts),
        None,
    )
}

/// Re-checks every row ([`recheck_row`]) at `tighter`, the rows at once, each
/// on `base` with the row's friction coefficient, and records each in its row
/// ([`Recheck::apply_to`]: an onset that does not hold there leaves the row not converged).
/// With `cancel`, a drop not yet started when it is raised is skipped (its outcome
/// "cancelled"; the caller discards the rows) and every drop run is counted on it. Every drop
/// run ticks `ticker`, which expects each row's deciding cells, and a window search's drops
/// as it plans them.
pub fn recheck_rows(
    base: &Scene,
    rows: &mut [CriticalRow],
    tighter: Fidelity,
    opts: &DropOptions,
    cancel: Option<&Cancel>,
    ticker: Option<&Ticker>,
) {
    if let Some(t) = ticker {
        t.expect_more(
            rows.iter()
                .map(|r| deciding_cells(r).map_or(0, cells_len))
                .sum(),
        );
    }
    let run = |s: &Scene, speed: f64| {
        let outcome = match cancel {
            Some(c) if c.requested() => return Outcome::Failed("cancelled".to_owned()),
            Some(c) => {
                let outcome = drop_outcome(s, speed, opts);
                c.count_drop();
                outcome
            }
            None => drop_outcome(s, speed, opts),
        };
        if let Some(t) = ticker {
            t.tick();
        }
        outcome
    };
    rows.par_iter_mut().for_each(|row| {
        let mut s = base.clone();
        s.mu_dynamic = row.mu;
        if let Some(rc) = recheck_with(&s, row, tighter, &run, ticker) {
            rc.apply_to(row);
        }
    });
}

/// The re-check of [`recheck_row`] with `run` for a drop. `ticker`, whose count `run`
/// ticks, is told of a window search's drops as they are planned.
fn recheck_with(
    scene: &Scene,
    row: &CriticalRow,
    tighter: Fidelity,
    run: &(dyn Fn(&Scene, f64) -> Outcome + Sync),
    ticker: Option<&Ticker>,
) -> Option<Recheck> {
    let (lo, hi) = deciding_cells(row)?;
    let s = tighter.applied(scene);
    let (out_lo, out_hi) = rayon::join(
        || lo.map(|v| (v, run(&s, v))),
        || hi.map(|v| (v, run(&s, v))),
    );
    // A settled class below: an unresolved drop is no confirmation (below an onset it
    // leaves a search undecided).
    let settled_below = out_lo.as_ref().is_none_or(
        |(_, o)| matches!(o, Outcome::Class(c) if !c.is_whirl() && *c != OrbitClass::Unresolved),
    );
    let whirl_above = out_hi.as_ref().is_none_or(|(_, o)| o.whirl() == Some(true));
    let confirmed = settled_below && whirl_above;
    let relocated = (!confirmed).then(|| {
        let known: Vec<(f64, &Outcome)> =
            out_lo.iter().chain(&out_hi).map(|(v, o)| (*v, o)).collect();
        // A row without a bracket has one cell: the window is searched around it.
        let one = "a row has a deciding cell";
        relocate(
            &s,
            row,
            [lo.or(hi).expect(one), hi.or(lo).expect(one)],
            &known,
            run,
            ticker,
        )
    });
    let mut rc = Recheck {
        fidelity: tighter,
        lo: out_lo,
        hi: out_hi,
        confirmed,
        within_tol: false,
        relocated,
    };
    // An undecided onset is no onset to hold: failed drops could move it.
    rc.within_tol = !confirmed && !row.undecided && rc.onset_within(row.onset_rpm, row.tol_rpm);
    Some(rc)
}

/// The speeds that decide `row`'s answer, below and above the onset: its bracket's two;
/// without a bracket, the end of its range that decides it: the highest speed scanned with a
/// class when it found no whirl (below), the lowest when whirl starts there (above, the row's
/// onset). `None` when nothing was decided (every scan drop failed).
pub fn deciding_cells(row: &CriticalRow) -> Option<(Option<f64>, Option<f64>)> {
    if let Some([lo, hi]) = row.bracket_rpm {
        return Some((Some(lo), Some(hi)));
    }
    match row.onset_rpm {
        Some(onset) => Some((None, Some(onset))),
        None if row.whirl_intervals_rpm.is_empty() => (row.scan.iter().rev())
            .find(|p| p.class.is_some())
            .map(|p| (Some(p.speed_rpm), None)),
        None => None,
    }
}

/// How many cells [`deciding_cells`] names.
fn cells_len((lo, hi): (Option<f64>, Option<f64>)) -> usize {
    usize::from(lo.is_some()) + usize::from(hi.is_some())
}

/// Lattice steps either side of the cells re-run that [`relocate`] searches first: the
/// convergence study's tolerance on an onset (docs/accuracy.md).
const WINDOW_STEPS: f64 = 2.0;

/// Lattice steps either side of the cells re-run that [`relocate`] widens its window to, at
/// most.
const MAX_WINDOW_STEPS: f64 = 16.0;

/// Searches `row`'s deciding cells `[lo, hi]` (its bracket, or twice the end of the range
/// that decides it) again on `tighter_scene` (the tighter preset's, with the row's friction
/// coefficient) on its lattice and tolerance, over a window from [`WINDOW_STEPS`] lattice
/// steps below the lattice point under `lo` to as many above the one over `hi`, within the
/// range the row searched. When the tighter preset whirls at the window's lowest
/// speed (or does not at its highest), that side is widened, doubling its steps up to
/// [`MAX_WINDOW_STEPS`], and searched again. Its ends are lattice points or the range's, so its
/// scan drops are the ones a search of the whole range drops there, and it finds the onset
/// that search would, when that onset is in the window above its lower end. No drop runs
/// twice: the cells already run at the tighter preset (`known`) and every drop of a narrower
/// window are answered from memory. `ticker` expects each window's scan and bisections as
/// they are planned, less those answered from memory.
fn relocate(
    tighter_scene: &Scene,
    row: &CriticalRow,
    [lo, hi]: [f64; 2],
    known: &[(f64, &Outcome)],
    run: &(dyn Fn(&Scene, f64) -> Outcome + Sync),
    ticker: Option<&Ticker>,
) -> Relocated {
    let res = row.resolution_rpm;
    // Every outcome so far by the speed's bits, and the drops run (a cancelled one counts
    // too; a cancelled run's rows are discarded).
    let memo: Mutex<HashMap<u64, Outcome>> = Mutex::new(
        (known.iter())
            .map(|(s, o)| (s.to_bits(), (*o).clone()))
            .collect(),
    );
    let ran = AtomicUsize::new(0);
    let classify = |speed: f64| {
        if let Some(o) = memo
            .lock()
            .expect("no panic holds it")
            .get(&speed.to_bits())
        {
            if let Some(t) = ticker {
                t.expect_fewer(1);
            }
            return o.clone();
        }
        ran.fetch_add(1, Ordering::Relaxed);
        let o = run(tighter_scene, speed);
        memo.lock()
            .expect("no panic holds it")
            .insert(speed.to_bits(), o.clone());
        o
    };
    let (mut below, mut above) = (WINDOW_STEPS, WINDOW_STEPS);
    let (from, to, w) = loop {
        let from = (res * ((lo / res).floor() - below)).max(row.from_rpm);
        let to = (res * ((hi / res).ceil() + above)).min(row.to_rpm);
        let o = CriticalOptions {
            from_rpm: from,
            to_rpm: to,
            resolution_rpm: res,
            tol_rpm: row.tol_rpm,
            duration_s: row.duration_s,
        };
        if let (Some(t), Ok(())) = (ticker, o.validate()) {
            t.expect_more(o.scan_speeds().len());
        }
        let expect = |n| {
            if let Some(t) = ticker {
                t.expect_more(n)
            }
        };
        // A row read back from a hand-edited file may hold a bracket outside its range.
        let w = match search_expecting(classify, &o, &expect) {
            Ok(found) => found.into_row(row.mu, &o, String::new()),
            Err(e) => {
                return Relocated {
                    window_rpm: [from, to],
                    onset_rpm: None,
                    drops: ran.load(Ordering::Relaxed),
                    note: format!("not searched again there: {e}"),
                }
            }
        };
        match (w.undecided, w.onset_rpm, w.bracket_rpm) {
            (false, Some(_), None) if from > row.from_rpm && below < MAX_WINDOW_STEPS => {
                below *= 2.0
            }
            (false, None, _) if to < row.to_rpm && above < MAX_WINDOW_STEPS => above *= 2.0,
            _ => break (from, to, w),
        }
    };
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
        (false, Some(onset), Some(_)) if row.onset_rpm.is_none() => (
            Some(onset),
            format!(
                "its onset there {} r/min, where the search found no whirl",
                fmt_rpm(onset)
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
                "whirl there already at {} r/min, the window's lowest speed: its onset is there \
                 or lower, sixteen lattice steps or more below the bracket",
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
                "no whirl there up to {} r/min: its onset is higher, by more than sixteen lattice \
                 steps",
                fmt_rpm(to)
            ),
        ),
    };
    Relocated {
        window_rpm: [from, to],
        onset_rpm,
        drops: ran.into_inner(),
        note,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::critical::search;
    use std::sync::Mutex;
    use OrbitClass::*;

    /// A search of 1000-9000 r/min on a 250 r/min lattice to 10 r/min.
    fn opts() -> CriticalOptions {
        CriticalOptions {
            from_rpm: 1000.0,
            to_rpm: 9000.0,
            resolution_rpm: 250.0,
            tol_rpm: 10.0,
            duration_s: 1.0,
        }
    }

    /// Whirl from `threshold` up.
    fn class_at(threshold: f64, speed: f64) -> Outcome {
        Outcome::Class(if speed >= threshold {
            BackwardWhirl
        } else {
            Pendulum
        })
    }

    /// The row a search with whirl from `threshold` gives.
    fn row(threshold: f64) -> CriticalRow {
        let o = opts();
        search(|s| class_at(threshold, s), &o)
            .unwrap()
            .into_row(0.3, &o, String::new())
    }

    /// The re-check of the row searched with whirl from `search_at`, at a "tighter preset"
    /// with whirl from `tighter_at` (`fails` lists speeds whose drop fails there), and the
    /// speeds it ran. Its progress ticker, expecting the row's deciding cells as
    /// [`recheck_rows`] does, expects every drop before it runs, and ends with every drop it
    /// expected run (a failed one may add bisection drops, so not with `fails`).
    fn recheck(search_at: f64, tighter_at: f64, fails: &[f64]) -> (Recheck, Vec<f64>) {
        let ran = Mutex::new(Vec::new());
        let unexpected = Mutex::new(Vec::<f64>::new());
        let ticker = Ticker::off();
        ticker.expect_more(deciding_cells(&row(search_at)).map_or(0, cells_len));
        let run = |_: &Scene, speed: f64| {
            ran.lock().unwrap().push(speed);
            if ticker.expected() <= ticker.done() {
                unexpected.lock().unwrap().push(speed);
            }
            ticker.tick();
            if fails.contains(&speed) {
                Outcome::Failed("step_budget: x".into())
            } else {
                class_at(tighter_at, speed)
            }
        };
        let rc = recheck_with(
            &Scene::paper(),
            &row(search_at),
            Fidelity::Standard,
            &run,
            Some(&ticker),
        )
        .expect("a deciding cell");
        let ran = ran.into_inner().unwrap();
        assert_eq!(ticker.done(), ran.len());
        if fails.is_empty() {
            assert_eq!(
                unexpected.into_inner().unwrap(),
                [0.0; 0],
                "drops not expected"
            );
            assert_eq!(ticker.expected(), ran.len(), "the progress total");
        }
        (rc, ran)
    }

    /// A row without a bracket is re-checked at the end of the range that decides it, one
    /// drop: the top when it found no whirl, the bottom when whirl starts there. Not
    /// confirmed, the tighter preset's onset is searched for below the top (above the
    /// bottom) and found where a search of the whole range with it puts it.
    #[test]
    fn a_row_without_a_bracket_is_re_checked_at_its_deciding_end() {
        // No whirl up to 9000 at the search's preset.
        let (rc, ran) = recheck(9500.0, 9500.0, &[]);
        assert_eq!(ran, [9000.0]);
        assert!(rc.confirmed && rc.hi.is_none());
        assert_eq!(rc.lo, Some((9000.0, Outcome::Class(Pendulum))));
        let (rc, _) = recheck(9500.0, 8621.0, &[]);
        let w = rc.relocated.as_ref().expect("searched again");
        assert!(!rc.confirmed && !rc.within_tol);
        assert_eq!(w.window_rpm, [8500.0, 9000.0], "two steps below the top");
        assert_eq!(w.onset_rpm, row(8621.0).onset_rpm);
        assert!(
            w.note.ends_with("where the search found no whirl"),
            "{}",
            w.note
        );
        // Whirl from 1000 (the range bottom) at the search's preset.
        let (rc, ran) = recheck(500.0, 500.0, &[]);
        assert_eq!(ran, [1000.0]);
        assert!(rc.confirmed && rc.lo.is_none());
        let (rc, _) = recheck(500.0, 1321.0, &[]);
        let w = rc.relocated.as_ref().expect("searched again");
        assert!(!rc.confirmed);
        assert_eq!(w.window_rpm, [1000.0, 1500.0], "two steps above the bottom");
        assert_eq!(w.onset_rpm, row(1321.0).onset_rpm);
        // Beyond the first window: widened above until the onset lies in it.
        let (rc, _) = recheck(500.0, 2600.0, &[]);
        let w = rc.relocated.as_ref().expect("searched again");
        assert_eq!(w.onset_rpm, row(2600.0).onset_rpm);
        // An unresolved drop at the top is no confirmation of "no whirl".
        let mut r = row(9500.0);
        let rc = recheck_with(
            &Scene::paper(),
            &r,
            Fidelity::Standard,
            &|_, _| Outcome::Class(Unresolved),
            None,
        )
        .unwrap();
        assert!(!rc.confirmed);
        // A row every scan drop of which failed decides nothing and is not re-checked.
        r.scan.iter_mut().for_each(|p| {
            p.class = None;
            p.error = Some("x".into());
        });
        assert_eq!(deciding_cells(&r), None);
    }

    #[test]
    fn a_confirmed_bracket_searches_nothing_more() {
        let (rc, ran) = recheck(4321.0, 4321.0, &[]);
        assert!(rc.confirmed && rc.relocated.is_none());
        assert_eq!(ran.len(), 2);
    }

    /// Where the tighter preset puts the onset inside the window is where a search of the
    /// whole range with it does, lower or higher; the bracket's two drops are not run again.
    #[test]
    fn an_onset_in_the_window_is_the_whole_range_search_s() {
        for tighter_at in [4100.0, 4600.0] {
            let (rc, ran) = recheck(4321.0, tighter_at, &[]);
            let w = rc.relocated.expect("searched again");
            assert!(!rc.confirmed && !rc.within_tol);
            assert_eq!(
                w.window_rpm,
                [3750.0, 5000.0],
                "two steps below 4250, above 4500"
            );
            assert_eq!(w.onset_rpm, row(tighter_at).onset_rpm);
            let side = if tighter_at < 4321.0 {
                "lower"
            } else {
                "higher"
            };
            assert!(w.note.ends_with(side), "{}", w.note);
            assert_eq!(w.drops, ran.len() - 2);
            let [lo, hi] = row(4321.0).bracket_rpm.unwrap();
            assert_eq!(ran.iter().filter(|&&s| s == lo || s == hi).count(), 2);
        }
    }

    /// An onset the tighter preset puts within the row's tolerance (10 r/min) of the row's
    /// holds though a bracket end's class differs there; one just beyond it does not.
    #[test]
    fn an_onset_found_again_within_the_tolerance_holds() {
        assert_eq!(row(4321.0).onset_rpm, Some(4328.125));
        // Whirl from 4318: the search's lower end, 4320.3125, whirls there, and its onset is
        // 4320.3125, 7.8 r/min lower.
        let (rc, _) = recheck(4321.0, 4318.0, &[]);
        assert_eq!(row(4318.0).onset_rpm, Some(4320.3125));
        assert!(!rc.confirmed && rc.within_tol && rc.holds(), "{rc:?}");
        // Whirl from 4310: its onset 4312.5, 15.6 r/min lower.
        let (rc, _) = recheck(4321.0, 4310.0, &[]);
        assert_eq!(row(4310.0).onset_rpm, Some(4312.5));
        assert!(!rc.confirmed && !rc.within_tol && !rc.holds(), "{rc:?}");
        // A confirmed bracket is not marked within the tolerance: it needs no window.
        let (rc, _) = recheck(4321.0, 4321.0, &[]);
        assert!(rc.confirmed && !rc.within_tol);
        // An undecided row's onset does not hold, however close the tighter preset's is.
        let mut r = row(4321.0);
        r.undecided = true;
        let run = |_: &Scene, speed: f64| class_at(4318.0, speed);
        let rc = recheck_with(&Scene::paper(), &r, Fidelity::Standard, &run, None).unwrap();
        let found = rc.relocated.as_ref().and_then(|w| w.onset_rpm);
        assert_eq!(found, Some(4320.3125));
        assert!(!rc.within_tol && !rc.holds(), "{rc:?}");
    }

    /// A bracket end the window meets again, as a scan point (an end on the lattice) or as a
    /// bisection midpoint, is not run again.
    #[test]
    fn the_window_reuses_the_bracket_s_drops() {
        let [lo, _] = row(4255.0).bracket_rpm.unwrap();
        assert_eq!(lo, 4250.0, "every bisection midpoint whirled");
        let (rc, ran) = recheck(4255.0, 4600.0, &[]);
        assert_eq!(ran.iter().filter(|&&s| s == lo).count(), 1, "{ran:?}");
        assert_eq!(rc.relocated.unwrap().drops, ran.len() - 2);
        // Whirl from 4370 at the tighter preset: its bisection of [4250, 4500] passes 4375,
        // the search's lower bracket end.
        let [lo, _] = row(4380.0).bracket_rpm.unwrap();
        assert_eq!(lo, 4375.0);
        let (rc, ran) = recheck(4380.0, 4370.0, &[]);
        assert_eq!(ran.iter().filter(|&&s| s == lo).count(), 1, "{ran:?}");
        let w = rc.relocated.unwrap();
        assert_eq!(w.onset_rpm, row(4370.0).onset_rpm);
        assert_eq!(w.drops, ran.len() - 2);
    }

    /// A row whose bracket lies outside its own range (a hand-edited file) is not searched
    /// again, and the note says why; nothing panics.
    #[test]
    fn a_bracket_outside_its_range_gives_a_note() {
        let mut r = row(4321.0);
        r.from_rpm = 5000.0;
        let ticker = Ticker::off();
        ticker.expect_more(2);
        let run = |_: &Scene, speed: f64| {
            ticker.tick();
            class_at(4100.0, speed)
        };
        let rc = recheck_with(&Scene::paper(), &r, Fidelity::Standard, &run, Some(&ticker));
        let w = rc.unwrap().relocated.unwrap();
        assert_eq!((w.onset_rpm, w.drops), (None, 0));
        assert_eq!(
            (ticker.done(), ticker.expected()),
            (2, 2),
            "no window planned"
        );
        assert!(
            w.note.starts_with("not searched again there: "),
            "{}",
            w.note
        );
    }

    /// An onset beyond the first window is found by widening it, doubling its steps on that
    /// side (here to sixteen, clipped at the range's lowest speed; and to sixteen above): the
    /// whole-range search's, and no drop runs twice.
    #[test]
    fn a_wider_shift_is_found_by_widening_the_window() {
        for (tighter_at, window) in [(2000.0, [1000.0, 5000.0]), (7000.0, [3750.0, 8500.0])] {
            let (rc, ran) = recheck(4321.0, tighter_at, &[]);
            let w = rc.relocated.unwrap();
            assert_eq!(w.window_rpm, window);
            assert_eq!(w.onset_rpm, row(tighter_at).onset_rpm);
            let mut unique = ran.clone();
            unique.sort_by(f64::total_cmp);
            unique.dedup();
            assert_eq!(unique.len(), ran.len(), "a drop ran twice: {ran:?}");
            assert_eq!(w.drops, ran.len() - 2);
        }
    }

    /// Whirl at the widest window's lowest speed, or none in it: no onset there, and the
    /// note says which side and whether the window reached the range's end.
    #[test]
    fn an_onset_outside_the_window_is_named_by_its_side() {
        let note = |search_at: f64, tighter_at: f64| {
            let w = recheck(search_at, tighter_at, &[]).0.relocated.unwrap();
            assert_eq!(w.onset_rpm, None);
            w.note
        };
        let n = note(8600.0, 2000.0);
        assert!(
            n.contains("at 4500 r/min, the window's lowest speed: its onset is there or lower"),
            "{n}"
        );
        assert!(note(1300.0, 500.0).contains("at the range's lowest speed, 1000 r/min"));
        let n = note(1300.0, 9500.0);
        assert!(
            n.contains("up to 5500 r/min: its onset is higher, by more than sixteen"),
            "{n}"
        );
        assert!(note(8600.0, 9500.0).contains("no whirl there from 8000 r/min to the range top"));
    }

    #[test]
    fn failed_drops_in_the_window_leave_its_onset_undecided() {
        let (rc, _) = recheck(4321.0, 4100.0, &[4000.0]);
        let w = rc.relocated.unwrap();
        assert_eq!(w.onset_rpm, None);
        assert!(
            w.note.contains("undecided in 3750-5000 r/min"),
            "{}",
            w.note
        );
    }
}
