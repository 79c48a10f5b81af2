//! The rows of `critical.json` and `critical.csv`: one [`CriticalRow`] per friction
//! coefficient of a critical-speed search, with its drops ([`Probe`]) and the optional
//! re-check of its bracket ([`Recheck`]).

use crate::files::CRITICAL_FILE;
use crate::read::{read_json_optional, ReadError};
use serde::{Deserialize, Serialize};
use std::path::Path;
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::Fidelity;

/// What one drop gave: its orbit class, or a failure (solver error) with its message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The drop finished and was classified.
    Class(OrbitClass),
    /// The drop failed (typically a typed solver error, `kind: message`).
    Failed(String),
}

impl Outcome {
    /// Whether the drop whirled; `None` when it failed.
    pub fn whirl(&self) -> Option<bool> {
        match self {
            Outcome::Class(c) => Some(c.is_whirl()),
            Outcome::Failed(_) => None,
        }
    }
}

/// One drop of a search: its speed and what it gave.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Probe {
    /// Release speed (r/min).
    pub speed_rpm: f64,
    /// The class, when the drop finished.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class: Option<OrbitClass>,
    /// The failure, when it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl Probe {
    /// The probe of a drop at `speed_rpm` that gave `o`.
    pub fn new(speed_rpm: f64, o: &Outcome) -> Self {
        match o {
            Outcome::Class(c) => Self {
                speed_rpm,
                class: Some(*c),
                error: None,
            },
            Outcome::Failed(e) => Self {
                speed_rpm,
                class: None,
                error: Some(e.clone()),
            },
        }
    }
}

/// One friction coefficient's result: the row of `critical.json`, of
/// `whirlmap critical --json` and (its scalar fields) of `critical.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CriticalRow {
    /// Friction coefficient (`mu_dynamic`).
    pub mu: f64,
    /// The lowest speed at which sustained whirl was found (r/min): the whirl side of the
    /// lowest transition into whirl, or the lowest scan speed when the range already whirls
    /// there (then `bracket_rpm` is null). Null when the range holds no whirl (`note` says
    /// so).
    pub onset_rpm: Option<f64>,
    /// `[below, above]` (r/min): no whirl at `below`, whirl at `above`, at most `tol_rpm`
    /// apart when converged. Null without a transition into whirl.
    pub bracket_rpm: Option<[f64; 2]>,
    /// Class at the bracket's lower end.
    pub class_below: Option<OrbitClass>,
    /// Class at the bracket's upper end.
    pub class_above: Option<OrbitClass>,
    /// Every speed interval `[first, last]` with whirl (r/min), in increasing speed: from
    /// the whirl side of a transition into whirl (or the lowest scan speed) to the whirl side
    /// of the transition out of it (or the range top). Gaps above the onset are where the map
    /// is not monotone.
    pub whirl_intervals_rpm: Vec<[f64; 2]>,
    /// The last interval runs to the top of the range (whirl at `to_rpm`).
    pub whirl_at_range_top: bool,
    /// More than one whirl interval.
    pub non_monotone: bool,
    /// Drops run (scan and bisections, failed ones included).
    pub drops: usize,
    /// Drops that failed (counted as neither class; see `scan` and `bisections`).
    pub failed_drops: usize,
    /// Every bisection reached `tol_rpm`, no failed drop leaves the onset undecided (false
    /// whenever `undecided` is true) and, when the bracket was re-checked at a tighter
    /// preset, the onset holds there ([`Recheck::holds`], [`Recheck::apply_to`]).
    pub converged: bool,
    /// Failed drops leave the onset undecided: every scan drop failed, or a drop failed
    /// below the reported onset (inside its bracket included), where a whirl would have
    /// given a lower onset, or anywhere in the range when no whirl was found. `note` names
    /// the speeds. Written only when true, so a decided row's JSON (and every row written
    /// before this field existed) reads back to the same bytes; absent reads as false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub undecided: bool,
    /// Lowest speed searched (r/min).
    pub from_rpm: f64,
    /// Highest speed searched (r/min).
    pub to_rpm: f64,
    /// Lattice step of the scan (r/min).
    pub resolution_rpm: f64,
    /// Bisection tolerance (r/min).
    pub tol_rpm: f64,
    /// Simulated time of each drop before extension (s).
    pub duration_s: f64,
    /// `Scene::hash_hex` of the searched scene (with this `mu`; the speed varies).
    pub scene_hash: String,
    /// `whirlmap_core::MODEL_VERSION`.
    pub model_version: u32,
    /// What was found, in words.
    pub note: String,
    /// The scan, in speed order.
    pub scan: Vec<Probe>,
    /// The bisection drops, transition by transition in speed order, each in the order run.
    pub bisections: Vec<Probe>,
    /// The cells that decide the row (its onset bracket, or the end of the range) re-run at a
    /// tighter fidelity preset, when asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recheck: Option<Recheck>,
}

/// The header of `critical.csv`.
pub const CSV_HEADER: &str = "mu,onset_rpm,bracket_below_rpm,bracket_above_rpm,class_below,class_above,whirl_intervals_rpm,whirl_at_range_top,non_monotone,drops,failed_drops,converged,undecided,from_rpm,to_rpm,resolution_rpm,tol_rpm,recheck_fidelity,recheck_holds,recheck_onset_rpm,recheck_drops,note";

impl CriticalRow {
    /// The row's line of `critical.csv` (see [`CSV_HEADER`]): intervals as
    /// `first-last` separated by `;`, empty cells for nulls, the note quoted. The re-check's
    /// four cells are empty for a row without one; `recheck_onset_rpm` is
    /// [`Recheck::onset_rpm`].
    pub fn csv_line(&self) -> String {
        let opt = |v: Option<f64>| v.map_or(String::new(), |x| x.to_string());
        let class = |c: Option<OrbitClass>| c.map_or("", |c| c.name()).to_string();
        let intervals = self
            .whirl_intervals_rpm
            .iter()
            .map(|[a, b]| format!("{a}-{b}"))
            .collect::<Vec<_>>()
            .join(";");
        let rc = self.recheck.as_ref();
        [
            self.mu.to_string(),
            opt(self.onset_rpm),
            opt(self.bracket_rpm.map(|b| b[0])),
            opt(self.bracket_rpm.map(|b| b[1])),
            class(self.class_below),
            class(self.class_above),
            intervals,
            self.whirl_at_range_top.to_string(),
            self.non_monotone.to_string(),
            self.drops.to_string(),
            self.failed_drops.to_string(),
            self.converged.to_string(),
            self.undecided.to_string(),
            self.from_rpm.to_string(),
            self.to_rpm.to_string(),
            self.resolution_rpm.to_string(),
            self.tol_rpm.to_string(),
            rc.map_or(String::new(), |rc| rc.fidelity.name().to_string()),
            rc.map_or(String::new(), |rc| rc.holds().to_string()),
            opt(rc.and_then(|rc| rc.onset_rpm(self.onset_rpm))),
            rc.map_or(String::new(), |rc| rc.drops().to_string()),
            format!("\"{}\"", self.note.replace('"', "'")),
        ]
        .join(",")
    }
}

/// `critical.csv`'s text for `rows`: the header and one line per row.
pub fn csv_text(rows: &[CriticalRow]) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for r in rows {
        s.push_str(&r.csv_line());
        s.push('\n');
    }
    s
}

/// The rows whose onset failed drops, or drops that did not settle, left undecided, as
/// `mu 0.4 (4 of 4 drops failed), mu 0.3 (1 of 17 drops did not settle)` (the unsettled
/// ones counted below the onset); `None` when there is none. The command line's message and
/// exit code, and the Python package's warning, are built on it.
pub fn undecided_summary(rows: &[CriticalRow]) -> Option<String> {
    let list: Vec<String> = rows
        .iter()
        .filter(|r| r.undecided)
        .map(|r| {
            // The unsettled drops that could hide the onset: below it, or any without one.
            let unsettled = r
                .scan
                .iter()
                .chain(&r.bisections)
                .filter(|p| p.class == Some(OrbitClass::Unresolved))
                .filter(|p| r.onset_rpm.is_none_or(|x| p.speed_rpm < x))
                .count();
            match (r.failed_drops, unsettled) {
                (f, 0) => format!("mu {} ({f} of {} drops failed)", r.mu, r.drops),
                (0, u) => format!("mu {} ({u} of {} drops did not settle)", r.mu, r.drops),
                (f, u) => format!(
                    "mu {} ({f} of {} drops failed, {u} did not settle)",
                    r.mu, r.drops
                ),
            }
        })
        .collect();
    (!list.is_empty()).then(|| list.join(", "))
}

/// The rows whose onset does not hold at the re-check's tighter preset ([`Recheck::holds`]),
/// in words (`mu 0.25 (at standard: 13312.5 r/min backward_whirl, 13375 r/min
/// backward_whirl)`); `None` when every re-checked onset holds or none was re-checked. The command line then exits 1, as the Python package warns: the onset the
/// search's own preset found is not the tighter preset's.
pub fn unconfirmed_summary(rows: &[CriticalRow]) -> Option<String> {
    let list: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            let rc = r.recheck.as_ref().filter(|rc| !rc.holds())?;
            Some(format!("mu {} ({})", r.mu, rc.outcomes()))
        })
        .collect();
    (!list.is_empty()).then(|| list.join(", "))
}

/// The cells that decide a search's answer, run again at a tighter fidelity preset: the
/// onset bracket's two; for a row without a bracket, the end of the range that decides it
/// (the highest speed scanned when it found no whirl, `lo`; the lowest when whirl starts
/// there, `hi`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recheck {
    /// The preset the cells were re-run at.
    pub fidelity: Fidelity,
    /// Lower bracket speed (r/min) and its outcome at that preset; for a row that found no
    /// whirl, its highest speed scanned with a class (the range top unless that drop failed).
    /// Absent for a row whose whirl starts at the lowest speed scanned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lo: Option<(f64, Outcome)>,
    /// Upper bracket speed (r/min) and its outcome at that preset; for a row whose whirl
    /// starts at the lowest speed scanned with a class, that speed. Absent for a row that
    /// found no whirl. (A row with either one absent cannot be read by a build from before
    /// rows without a bracket were re-checked.)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hi: Option<(f64, Outcome)>,
    /// True when the tighter preset agrees at the cells re-run: a settled class other than
    /// whirl at `lo` and whirl at `hi`, each where present.
    pub confirmed: bool,
    /// True when the bracket is not confirmed but the tighter preset's onset, searched again
    /// (`relocated`), lies within the row's `tol_rpm` of the row's onset, and the row is not
    /// undecided: the onset holds to
    /// the tolerance the search was asked for, though a bracket end's class differs at the
    /// tighter preset (near an onset the class can flip within tens of r/min). Written only
    /// when true; absent reads as false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub within_tol: bool,
    /// Where the tighter preset puts the onset, when it does not confirm the cells.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relocated: Option<Relocated>,
}

/// The search run again at the re-check's tighter preset when that preset does not confirm
/// the cells re-run, on the search's lattice and tolerance, from two lattice steps below the
/// lattice point under the lower cell to two above the one over the upper (the bracket's
/// ends, or twice the end of the range that decides a row without a bracket; within the
/// range searched), each side widened, doubling its steps up to sixteen, while the onset lies
/// beyond it: where that preset puts the onset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Relocated {
    /// The window searched last, the widest (r/min), on the search's lattice and bisection
    /// tolerance.
    pub window_rpm: [f64; 2],
    /// The tighter preset's onset in the window: the whirl side of its lowest transition
    /// into whirl, bisected to `tol_rpm`. Null when the window holds none: whirl already at
    /// its lower end, no whirl in it, or failed or unsettled drops; or when the window was not
    /// searched (a row read from a file whose bracket lies outside its range). `note` says
    /// which.
    pub onset_rpm: Option<f64>,
    /// Drops run in the window (failed ones included; the bracket's two, when the window
    /// meets them, are not run again).
    pub drops: usize,
    /// What the window shows, in words (`its onset there 11437.5 r/min, 31.2 r/min lower`).
    pub note: String,
}

impl Recheck {
    /// Whether the onset holds at the tighter preset: the bracket confirmed, or the tighter
    /// preset's onset within the search's tolerance of it (`within_tol`).
    pub fn holds(&self) -> bool {
        self.confirmed || self.within_tol
    }

    /// Whether the tighter preset's onset, searched again in `relocated`, lies within
    /// `tol_rpm` of `onset_rpm` (the row's). False without either onset.
    pub fn onset_within(&self, onset_rpm: Option<f64>, tol_rpm: f64) -> bool {
        let found = self.relocated.as_ref().and_then(|r| r.onset_rpm);
        matches!((found, onset_rpm), (Some(a), Some(b)) if (a - b).abs() <= tol_rpm)
    }

    /// The onset at the re-check's preset, for a row whose search put it at `row_onset_rpm`:
    /// that onset when the preset confirms the cells (its bracket then lies within the same
    /// cells), else the onset searched again there (`relocated`), null when that search found
    /// none. Null for a row without an onset whose range end is confirmed.
    pub fn onset_rpm(&self, row_onset_rpm: Option<f64>) -> Option<f64> {
        if self.confirmed {
            row_onset_rpm
        } else {
            self.relocated.as_ref().and_then(|r| r.onset_rpm)
        }
    }

    /// The cells re-run, lower first.
    pub fn cells(&self) -> impl Iterator<Item = &(f64, Outcome)> {
        self.lo.iter().chain(&self.hi)
    }

    /// The drops at the tighter preset, in words: `at standard: 13312.5 r/min
    /// backward_whirl, 13375 r/min backward_whirl` (a failed drop reads `failed`), then,
    /// when the onset was searched again there, the window's note ([`Relocated::note`]).
    pub fn outcomes(&self) -> String {
        let show = |o: &Outcome| match o {
            Outcome::Class(c) => c.name().to_string(),
            Outcome::Failed(_) => "failed".to_string(),
        };
        let relocated = match &self.relocated {
            Some(r) => format!("; {}", r.note),
            None => String::new(),
        };
        let cells: Vec<String> = self
            .cells()
            .map(|(speed, o)| format!("{speed} r/min {}", show(o)))
            .collect();
        format!("at {}: {}{relocated}", self.fidelity, cells.join(", "))
    }

    /// Drops the re-check ran: its cells and the window's.
    pub fn drops(&self) -> usize {
        self.cells().count() + self.relocated.as_ref().map_or(0, |r| r.drops)
    }

    /// Records this re-check in `row`. One whose onset does not hold at the tighter preset
    /// ([`Recheck::holds`]) makes the row not converged (its onset is the search preset's
    /// only) and puts `NOT CONFIRMED` and the drops ([`Recheck::outcomes`]) in its note,
    /// so that `critical.csv`'s note says it too (beside its re-check columns): at the head
    /// of the note, or after the note of an undecided row, which starts with `UNDECIDED`.
    /// One that holds only within the tolerance (`within_tol`) says so in the note, in the
    /// same place, and leaves `converged` as it was.
    pub fn apply_to(self, row: &mut CriticalRow) {
        let clause = if !self.holds() {
            row.converged = false;
            Some(format!("NOT CONFIRMED by the re-check {}", self.outcomes()))
        } else if self.within_tol {
            Some(format!(
                "the onset holds to {} r/min at the re-check {}",
                row.tol_rpm,
                self.outcomes()
            ))
        } else {
            None
        };
        if let Some(clause) = clause {
            row.note = if row.undecided {
                format!("{}; {clause}", row.note)
            } else {
                format!("{clause}; {}", row.note)
            };
        }
        row.recheck = Some(self);
    }
}

/// The text of `critical.json` for `rows` (pretty JSON, no final newline).
pub fn critical_json(rows: &[CriticalRow]) -> String {
    serde_json::to_string_pretty(rows).expect("results serialise")
}

/// Reads `dir/critical.json`, or `None` if it does not exist.
pub fn read_critical(dir: &Path) -> Result<Option<Vec<CriticalRow>>, ReadError> {
    read_json_optional(&dir.join(CRITICAL_FILE))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(undecided: bool, note: &str) -> CriticalRow {
        CriticalRow {
            mu: 0.25,
            onset_rpm: Some(13375.0),
            bracket_rpm: Some([13312.5, 13375.0]),
            class_below: Some(OrbitClass::Pendulum),
            class_above: Some(OrbitClass::BackwardWhirl),
            whirl_intervals_rpm: vec![[13375.0, 16000.0]],
            whirl_at_range_top: true,
            non_monotone: false,
            drops: 19,
            failed_drops: 0,
            converged: !undecided,
            undecided,
            from_rpm: 2000.0,
            to_rpm: 16000.0,
            resolution_rpm: 1000.0,
            tol_rpm: 100.0,
            duration_s: 1.0,
            scene_hash: "abc".into(),
            model_version: 9,
            note: note.into(),
            scan: vec![],
            bisections: vec![],
            recheck: None,
        }
    }

    fn recheck(confirmed: bool) -> Recheck {
        Recheck {
            fidelity: Fidelity::Standard,
            lo: Some((13312.5, Outcome::Class(OrbitClass::BackwardWhirl))),
            hi: Some((13375.0, Outcome::Failed("step_budget: x".into()))),
            confirmed,
            within_tol: false,
            relocated: None,
        }
    }

    #[test]
    fn an_unconfirmed_re_check_is_in_the_row_and_undecided_stays_first() {
        let mut r = row(false, "pendulum at 13312.5 r/min");
        recheck(false).apply_to(&mut r);
        assert!(!r.converged);
        assert_eq!(
            r.note,
            "NOT CONFIRMED by the re-check at standard: 13312.5 r/min backward_whirl, \
             13375 r/min failed; pendulum at 13312.5 r/min"
        );
        assert!(
            r.csv_line().contains(",false,false,2000,"),
            "{}",
            r.csv_line()
        );

        let mut u = row(true, "UNDECIDED: 1 drop(s) failed");
        recheck(false).apply_to(&mut u);
        assert!(u
            .note
            .starts_with("UNDECIDED: 1 drop(s) failed; NOT CONFIRMED"));

        let mut c = row(false, "pendulum at 13312.5 r/min");
        recheck(true).apply_to(&mut c);
        assert!(c.converged && c.recheck.is_some());
        assert_eq!(c.note, "pendulum at 13312.5 r/min");
    }

    /// A re-check whose tighter preset puts the onset within the row's tolerance of it holds:
    /// the row stays converged and its note says to what tolerance; one tolerance further
    /// and it does not.
    #[test]
    fn an_onset_found_again_within_the_tolerance_holds() {
        let with_onset = |onset: f64| {
            let mut rc = recheck(false);
            rc.relocated = Some(Relocated {
                window_rpm: [11000.0, 16000.0],
                onset_rpm: Some(onset),
                drops: 7,
                note: format!("its onset there {onset} r/min"),
            });
            rc
        };
        let r = row(false, "pendulum at 13312.5 r/min");
        // The row's onset is 13 375 r/min and its tolerance 100 r/min.
        assert!(with_onset(13275.0).onset_within(r.onset_rpm, r.tol_rpm));
        assert!(with_onset(13475.0).onset_within(r.onset_rpm, r.tol_rpm));
        assert!(!with_onset(13274.0).onset_within(r.onset_rpm, r.tol_rpm));
        assert!(!with_onset(13275.0).onset_within(None, r.tol_rpm));
        assert!(!recheck(false).onset_within(r.onset_rpm, r.tol_rpm));

        let mut held = r.clone();
        let mut rc = with_onset(13300.0);
        rc.within_tol = true;
        assert!(rc.holds());
        rc.apply_to(&mut held);
        assert!(held.converged);
        assert!(
            held.note.starts_with(
                "the onset holds to 100 r/min at the re-check at standard: 13312.5 r/min \
                 backward_whirl, 13375 r/min failed; its onset there 13300 r/min; pendulum"
            ),
            "{}",
            held.note
        );
        assert_eq!(unconfirmed_summary(std::slice::from_ref(&held)), None);
        // The field is written only when true, so older rows read back to the same bytes.
        let json = serde_json::to_string(held.recheck.as_ref().unwrap()).unwrap();
        assert!(json.contains("\"within_tol\":true"), "{json}");
        let mut not_held = r.clone();
        with_onset(13000.0).apply_to(&mut not_held);
        assert!(!not_held.converged && not_held.note.starts_with("NOT CONFIRMED"));
        let json = serde_json::to_string(not_held.recheck.as_ref().unwrap()).unwrap();
        assert!(!json.contains("within_tol"), "{json}");
        assert!(unconfirmed_summary(&[not_held]).is_some());
    }

    /// `critical.csv`'s re-check cells: the preset, whether the onset holds, the onset at
    /// that preset and the drops the re-check ran; empty without a re-check.
    #[test]
    fn the_csv_says_what_the_re_check_found() {
        let cells = |r: &CriticalRow| {
            let line = r.csv_line();
            // The note, last, may hold commas; it is quoted.
            let columns = CSV_HEADER.split(',').count();
            let fields: Vec<&str> = line.splitn(columns, ',').collect();
            assert_eq!(fields.len(), columns, "{line}");
            assert!(fields[columns - 1].starts_with('"'), "{line}");
            fields[17..21].join(",")
        };
        let plain = row(false, "pendulum at 13312.5 r/min");
        assert_eq!(cells(&plain), ",,,");
        let mut confirmed = plain.clone();
        recheck(true).apply_to(&mut confirmed);
        assert_eq!(cells(&confirmed), "standard,true,13375,2");
        let mut lost = plain.clone();
        recheck(false).apply_to(&mut lost);
        assert_eq!(cells(&lost), "standard,false,,2");
        let mut moved = plain.clone();
        let mut rc = recheck(false);
        rc.relocated = Some(Relocated {
            window_rpm: [11000.0, 16000.0],
            onset_rpm: Some(12500.0),
            drops: 7,
            note: "its onset there 12500 r/min".into(),
        });
        rc.apply_to(&mut moved);
        assert_eq!(cells(&moved), "standard,false,12500,9");
        // No whirl in the range, confirmed at the range top: no onset at either preset.
        let mut none = plain.clone();
        none.onset_rpm = None;
        recheck(true).apply_to(&mut none);
        assert_eq!(cells(&none), "standard,true,,2");
    }
}
