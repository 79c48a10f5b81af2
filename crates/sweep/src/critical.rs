//! The critical backward-whirl speed: for each friction coefficient, the lowest release speed
//! at which a drop settles into sustained whirl (the designer's "safe below" speed), and every
//! speed interval where it does.
//!
//! ## The search
//! 1. **Scan on an absolute speed lattice**: every multiple of `resolution_rpm` in
//!    `[from_rpm, to_rpm]`, plus the two range ends. The lattice is aligned to multiples of
//!    the resolution, not to the range ends, so two searches over different ranges drop the
//!    same speeds where their ranges overlap. The friction coefficients, and the drops of
//!    each scan, run in parallel.
//! 2. **Every class transition** between neighbouring successful scan points (whirl on one
//!    side, no whirl on the other) is **bisected** to `tol_rpm`. A coefficient's transitions
//!    are bisected in parallel as soon as its scan is done, while the other coefficients'
//!    scans go on (a bisection is a chain of drops, each placed by the one before).
//! 3. **Report** per friction coefficient a [`CriticalRow`]: the onset (the whirl side of the
//!    lowest transition into whirl; the lowest scan speed when the range already whirls
//!    there), its bracket and the classes on each side, every whirl interval found, and
//!    `non_monotone` exactly when there is more than one interval.
//!
//! Two searches whose ranges both start below the onset and contain it find the same lowest
//! transition between the same lattice points and bisect it identically, so they give the same
//! onset (within `tol_rpm` when a range end falls inside that lattice cell). The lattice is
//! the resolution floor: a whirl interval narrower than one lattice step can be missed.
//!
//! Failed drops (solver errors, panics) count as neither class and are listed; `unresolved`
//! drops count as no whirl, and the note says so. [`search`] is a pure function of any class
//! predicate, testable without the integrator.

use crate::classify::OrbitClass;
use crate::progress::Ticker;
use crate::run::{run_drop, DropFailure};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use whirlmap_core::scene::num;
use whirlmap_core::{DropOptions, InvalidParameter, Scene, MODEL_VERSION};

/// Default lattice step of the scan (r/min).
pub const DEFAULT_RESOLUTION_RPM: f64 = 250.0;

/// Default bisection tolerance (r/min).
pub const DEFAULT_TOL_RPM: f64 = 25.0;

/// Most scan points one search may need (range / resolution).
pub const MAX_SCAN_POINTS: f64 = 10_000.0;

/// Highest speed a search may reach (r/min): the scene's speed limit.
pub const MAX_SPEED_RPM: f64 = 1e6;

/// Bisection steps at most (a guard: floats stop halving long before this).
const MAX_BISECTIONS: usize = 200;

/// Where in the bracket a bisection drop goes: the midpoint, then, if a drop fails there,
/// beside it.
const BISECTION_FRACTIONS: [f64; 3] = [0.5, 0.375, 0.625];

pub use whirlmap_results::critical::{
    csv_text, unconfirmed_summary, undecided_summary, CriticalRow, Outcome, Probe, CSV_HEADER,
};

/// Settings of a critical-speed search.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CriticalOptions {
    /// Lowest release speed searched (r/min), in [0, 1e6).
    pub from_rpm: f64,
    /// Highest release speed searched (r/min), in (`from_rpm`, 1e6].
    pub to_rpm: f64,
    /// Lattice step of the scan (r/min), in [1, 1e5]. Default 250.
    pub resolution_rpm: f64,
    /// Bracket width to stop bisecting at (r/min), in [0.01, `resolution_rpm`]. Default 25.
    pub tol_rpm: f64,
    /// Simulated time of each drop (s), before any extension the classifier asks for.
    pub duration_s: f64,
}

impl Default for CriticalOptions {
    fn default() -> Self {
        Self {
            from_rpm: 1000.0,
            to_rpm: 30_000.0,
            resolution_rpm: DEFAULT_RESOLUTION_RPM,
            tol_rpm: DEFAULT_TOL_RPM,
            duration_s: 1.0,
        }
    }
}

impl CriticalOptions {
    /// Checks the settings before any drop runs; the error names the field, its value and
    /// the allowed range.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        check_range(
            self.from_rpm,
            self.to_rpm,
            self.resolution_rpm,
            self.tol_rpm,
        )?;
        DropOptions {
            duration_s: self.duration_s,
            ..Default::default()
        }
        .validate()
    }

    /// The scan speeds: every multiple of the resolution in `[from, to]` and both ends, in
    /// increasing order.
    pub fn scan_speeds(&self) -> Vec<f64> {
        let r = self.resolution_rpm;
        let mut v = vec![self.from_rpm];
        let mut k = (self.from_rpm / r).floor() + 1.0;
        while k * r < self.to_rpm {
            v.push(k * r);
            k += 1.0;
        }
        v.push(self.to_rpm);
        v.dedup();
        v
    }
}

/// Checks a search range: `from_rpm` in [0, 1e6), `to_rpm` in (`from_rpm`, 1e6],
/// `resolution_rpm` in [1, 1e5] with at most 10 000 lattice steps in the range, and `tol_rpm`
/// in [0.01, `resolution_rpm`]. The error names the field.
pub fn check_range(
    from_rpm: f64,
    to_rpm: f64,
    resolution_rpm: f64,
    tol_rpm: f64,
) -> Result<(), InvalidParameter> {
    if !(from_rpm.is_finite() && (0.0..MAX_SPEED_RPM).contains(&from_rpm)) {
        return Err(InvalidParameter::new(
            "from_rpm",
            num(from_rpm),
            "[0, 1e6) r/min",
        ));
    }
    if !(to_rpm.is_finite() && to_rpm > from_rpm && to_rpm <= MAX_SPEED_RPM) {
        return Err(InvalidParameter::new(
            "to_rpm",
            num(to_rpm),
            &format!("({}, 1e6] r/min (above from_rpm)", num(from_rpm)),
        ));
    }
    if !(resolution_rpm.is_finite() && (1.0..=1e5).contains(&resolution_rpm)) {
        return Err(InvalidParameter::new(
            "resolution_rpm",
            num(resolution_rpm),
            "[1, 1e5] r/min",
        ));
    }
    if !((to_rpm - from_rpm) / resolution_rpm <= MAX_SCAN_POINTS) {
        return Err(InvalidParameter::new(
            "resolution_rpm",
            num(resolution_rpm),
            &format!(
                ">= {} r/min for this range (at most 10000 scan points)",
                (to_rpm - from_rpm) / MAX_SCAN_POINTS
            ),
        ));
    }
    if !(tol_rpm.is_finite() && tol_rpm >= 0.01 && tol_rpm <= resolution_rpm) {
        return Err(InvalidParameter::new(
            "tol_rpm",
            num(tol_rpm),
            &format!(
                "[0.01, {}] r/min (at most the resolution)",
                num(resolution_rpm)
            ),
        ));
    }
    Ok(())
}

/// Checks a list of friction coefficients: not empty, each in [0, 2], no value twice.
pub fn check_mus(mus: &[f64]) -> Result<(), InvalidParameter> {
    if mus.is_empty() {
        return Err(InvalidParameter::new("mu", "(none)", "at least one value"));
    }
    for (i, &mu) in mus.iter().enumerate() {
        if !(mu.is_finite() && (0.0..=2.0).contains(&mu)) {
            return Err(InvalidParameter::new("mu", num(mu), "[0, 2]"));
        }
        if mus[..i].contains(&mu) {
            return Err(InvalidParameter::new("mu", num(mu), "each value once"));
        }
    }
    Ok(())
}

/// The speeds-and-classes part of a result, before the settings and hash are attached.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchResult {
    /// See [`CriticalRow::onset_rpm`].
    pub onset_rpm: Option<f64>,
    /// See [`CriticalRow::bracket_rpm`].
    pub bracket_rpm: Option<[f64; 2]>,
    /// See [`CriticalRow::class_below`].
    pub class_below: Option<OrbitClass>,
    /// See [`CriticalRow::class_above`].
    pub class_above: Option<OrbitClass>,
    /// See [`CriticalRow::whirl_intervals_rpm`].
    pub whirl_intervals_rpm: Vec<[f64; 2]>,
    /// See [`CriticalRow::whirl_at_range_top`].
    pub whirl_at_range_top: bool,
    /// See [`CriticalRow::converged`].
    pub converged: bool,
    /// See [`CriticalRow::undecided`].
    pub undecided: bool,
    /// See [`CriticalRow::scan`].
    pub scan: Vec<Probe>,
    /// See [`CriticalRow::bisections`].
    pub bisections: Vec<Probe>,
    /// See [`CriticalRow::note`].
    pub note: String,
}

impl SearchResult {
    /// Drops run.
    pub fn drops(&self) -> usize {
        self.scan.len() + self.bisections.len()
    }
    /// Drops that failed.
    pub fn failed_drops(&self) -> usize {
        self.scan
            .iter()
            .chain(&self.bisections)
            .filter(|p| p.error.is_some())
            .count()
    }
    /// The full row for friction coefficient `mu` searched with `o` on a scene of hash
    /// `scene_hash`.
    pub fn into_row(self, mu: f64, o: &CriticalOptions, scene_hash: String) -> CriticalRow {
        CriticalRow {
            mu,
            onset_rpm: self.onset_rpm,
            bracket_rpm: self.bracket_rpm,
            class_below: self.class_below,
            class_above: self.class_above,
            non_monotone: self.whirl_intervals_rpm.len() > 1,
            whirl_intervals_rpm: self.whirl_intervals_rpm.clone(),
            whirl_at_range_top: self.whirl_at_range_top,
            drops: self.drops(),
            failed_drops: self.failed_drops(),
            converged: self.converged,
            undecided: self.undecided,
            from_rpm: o.from_rpm,
            to_rpm: o.to_rpm,
            resolution_rpm: o.resolution_rpm,
            tol_rpm: o.tol_rpm,
            duration_s: o.duration_s,
            scene_hash,
            model_version: MODEL_VERSION,
            note: self.note,
            scan: self.scan,
            bisections: self.bisections,
            recheck: None,
        }
    }
}

/// A transition between two neighbouring successful scan points, narrowed by bisection.
#[derive(Debug, Clone, PartialEq)]
struct Transition {
    /// Lower and upper speed and their classes; exactly one side whirls.
    lo: (f64, OrbitClass),
    hi: (f64, OrbitClass),
    probes: Vec<Probe>,
    converged: bool,
}

impl Transition {
    /// Whether this is a transition into whirl (no whirl below, whirl above).
    fn is_into_whirl(&self) -> bool {
        self.hi.1.is_whirl()
    }
    /// The speed on its whirl side.
    fn whirl_side(&self) -> f64 {
        if self.is_into_whirl() {
            self.hi.0
        } else {
            self.lo.0
        }
    }
}

/// Narrows a transition between `lo` and `hi` (whirl on exactly one side) to `tol_rpm`,
/// never re-running a speed in `failed` (a failed scan point is often exactly the midpoint).
fn bisect<F: Fn(f64) -> Outcome>(
    classify_at: &F,
    lo: (f64, OrbitClass),
    hi: (f64, OrbitClass),
    tol_rpm: f64,
    failed: &[f64],
) -> Transition {
    let mut t = Transition {
        lo,
        hi,
        probes: Vec::new(),
        converged: true,
    };
    let lo_whirl = lo.1.is_whirl();
    let mut steps = 0;
    'bisect: while t.hi.0 - t.lo.0 > tol_rpm && steps < MAX_BISECTIONS {
        steps += 1;
        let mut next = None;
        for frac in BISECTION_FRACTIONS {
            let mid = t.lo.0 + frac * (t.hi.0 - t.lo.0);
            if !(mid > t.lo.0 && mid < t.hi.0) {
                break 'bisect; // float resolution reached
            }
            if failed.contains(&mid) || t.probes.iter().any(|p| p.speed_rpm == mid) {
                continue;
            }
            let o = classify_at(mid);
            t.probes.push(Probe::new(mid, &o));
            if let Outcome::Class(c) = o {
                next = Some((mid, c));
                break;
            }
        }
        let Some((mid, c)) = next else {
            t.converged = false;
            break;
        };
        if c.is_whirl() == lo_whirl {
            t.lo = (mid, c);
        } else {
            t.hi = (mid, c);
        }
    }
    t.converged &= t.hi.0 - t.lo.0 <= tol_rpm;
    t
}

/// A speed for notes: integers without decimals, others with one.
pub fn fmt_rpm(s: f64) -> String {
    if s.fract() == 0.0 {
        format!("{s:.0}")
    } else {
        format!("{s:.1}")
    }
}

/// The failed drops (their speeds, in the order given) that leave the onset undecided:
/// those below the reported `onset` (inside its bracket included), where a whirl would
/// have given a lower onset, or every one of them when no onset was found (a whirl interval
/// may hide at any of them). Failed drops above the onset cannot change it; they are counted
/// in the note and can only shift the whirl intervals above it.
pub fn hiding_failures(onset: Option<f64>, failed_speeds: &[f64]) -> Vec<f64> {
    failed_speeds
        .iter()
        .copied()
        .filter(|&s| onset.is_none_or(|x| s < x))
        .collect()
}

/// Speeds for a note, in increasing order: `3000, 4000, 5000` (at most five, then
/// `and N more`).
fn rpm_list(speeds: &[f64]) -> String {
    let mut v = speeds.to_vec();
    v.sort_by(f64::total_cmp);
    let mut text = v
        .iter()
        .take(5)
        .map(|&s| fmt_rpm(s))
        .collect::<Vec<_>>()
        .join(", ");
    if v.len() > 5 {
        text.push_str(&format!(" and {} more", v.len() - 5));
    }
    text
}

/// The successful scan points and the transitions between neighbours (not yet bisected).
fn transitions_of(scan: &[Probe]) -> Vec<((f64, OrbitClass), (f64, OrbitClass))> {
    let ok: Vec<(f64, OrbitClass)> = scan
        .iter()
        .filter_map(|p| p.class.map(|c| (p.speed_rpm, c)))
        .collect();
    ok.windows(2)
        .filter(|w| w[0].1.is_whirl() != w[1].1.is_whirl())
        .map(|w| (w[0], w[1]))
        .collect()
}

/// Assembles a result from a scan (in speed order) and its bisected transitions (in speed
/// order).
fn assemble(o: &CriticalOptions, scan: Vec<Probe>, transitions: Vec<Transition>) -> SearchResult {
    let ok: Vec<(f64, OrbitClass)> = scan
        .iter()
        .filter_map(|p| p.class.map(|c| (p.speed_rpm, c)))
        .collect();
    // Transitions between neighbours alternate into and out of whirl, in speed order.
    let mut intervals: Vec<[f64; 2]> = Vec::new();
    let mut onset_transition: Option<&Transition> = None;
    let mut start = ok.first().filter(|p| p.1.is_whirl()).map(|p| p.0);
    for t in &transitions {
        if t.is_into_whirl() {
            if start.is_none() && intervals.is_empty() {
                onset_transition = Some(t);
            }
            start = Some(t.whirl_side());
        } else if let Some(s) = start.take() {
            intervals.push([s, t.whirl_side()]);
        }
    }
    let whirl_at_range_top = start.is_some();
    if let Some(s) = start {
        intervals.push([s, ok[ok.len() - 1].0]);
    }

    let mut notes: Vec<String> = Vec::new();
    let failed = scan.iter().filter(|p| p.error.is_some()).count();
    let (mut onset, mut bracket, mut below, mut above) = (None, None, None, None);
    if ok.is_empty() {
        notes.push(format!(
            "UNDECIDED: every scan drop failed ({failed} of {}): nothing decided",
            scan.len()
        ));
    } else if intervals.is_empty() {
        notes.push(format!(
            "no whirl from {} to {} r/min",
            fmt_rpm(ok[0].0),
            fmt_rpm(ok[ok.len() - 1].0)
        ));
    } else if let Some(t) = onset_transition {
        onset = Some(t.hi.0);
        bracket = Some([t.lo.0, t.hi.0]);
        below = Some(t.lo.1);
        above = Some(t.hi.1);
        notes.push(format!(
            "{} at {} r/min, {} at {} r/min",
            t.lo.1.name(),
            fmt_rpm(t.lo.0),
            t.hi.1.name(),
            fmt_rpm(t.hi.0)
        ));
        if t.lo.1 == OrbitClass::Unresolved {
            notes.push("the lower side is unresolved (counted as no whirl)".into());
        }
    } else {
        onset = Some(ok[0].0);
        above = Some(ok[0].1);
        let lowest = if scan.first().is_some_and(|p| p.error.is_some()) {
            "the lowest speed scanned that did not fail"
        } else {
            "the lowest speed scanned"
        };
        notes.push(format!(
            "whirl already at {} r/min, {lowest}: the onset is at or below it",
            fmt_rpm(ok[0].0)
        ));
    }
    if intervals.len() > 1 {
        let list = intervals
            .iter()
            .map(|[a, b]| format!("{}-{}", fmt_rpm(*a), fmt_rpm(*b)))
            .collect::<Vec<_>>()
            .join(", ");
        notes.push(format!(
            "non-monotone: whirl in {} intervals ({list} r/min)",
            intervals.len()
        ));
    }
    if whirl_at_range_top {
        notes.push(format!(
            "whirl up to the range top ({} r/min)",
            fmt_rpm(ok[ok.len() - 1].0)
        ));
    }
    // The drops that did not settle (their speeds): counted here, and below the onset they
    // leave it undecided.
    let unsettled_speeds: Vec<f64> = scan
        .iter()
        .chain(transitions.iter().flat_map(|t| &t.probes))
        .filter(|p| p.class == Some(OrbitClass::Unresolved))
        .map(|p| p.speed_rpm)
        .collect();
    let unresolved = unsettled_speeds.len();
    if unresolved > 0 {
        notes.push(format!(
            "{unresolved} unresolved drop(s) counted as no whirl in the intervals"
        ));
    }
    let bisection_failures = transitions
        .iter()
        .flat_map(|t| &t.probes)
        .filter(|p| p.error.is_some())
        .count();
    if failed + bisection_failures > 0 {
        notes.push(format!(
            "{} drop(s) failed, counted as neither class",
            failed + bisection_failures
        ));
    }
    let bisected = transitions.iter().all(|t| t.converged);
    if !bisected {
        notes.push(format!(
            "a bisection stopped short of {} r/min (drops failed inside its bracket)",
            fmt_rpm(o.tol_rpm)
        ));
    }
    let failed_speeds: Vec<f64> = scan
        .iter()
        .chain(transitions.iter().flat_map(|t| &t.probes))
        .filter(|p| p.error.is_some())
        .map(|p| p.speed_rpm)
        .collect();
    // Failed drops that could change the onset: see `hiding_failures`.
    let hiding = hiding_failures(onset, &failed_speeds);
    // So could drops below it that did not settle: an unresolved motion may be a whirl the
    // classifier could not name (a backward whirl with intermittent contact).
    let unsettled = hiding_failures(onset, &unsettled_speeds);
    if !ok.is_empty() && !unsettled.is_empty() {
        notes.insert(
            0,
            match onset {
                Some(x) => format!(
                    "UNDECIDED: {} drop(s) below the onset {} r/min did not settle (unresolved, \
                     at {} r/min), where a whirl the classifier could not name would give a \
                     lower onset",
                    unsettled.len(),
                    fmt_rpm(x),
                    rpm_list(&unsettled)
                ),
                None => format!(
                    "UNDECIDED: {} drop(s) did not settle (unresolved, at {} r/min), where a \
                     whirl the classifier could not name may hide",
                    unsettled.len(),
                    rpm_list(&unsettled)
                ),
            },
        );
    }
    if !ok.is_empty() && !hiding.is_empty() {
        notes.insert(
            0,
            match onset {
                Some(x) => format!(
                    "UNDECIDED: {} drop(s) failed below the onset {} r/min (at {} r/min), where \
                 whirl would give a lower onset",
                    hiding.len(),
                    fmt_rpm(x),
                    rpm_list(&hiding)
                ),
                None => format!(
                    "UNDECIDED: {} drop(s) failed (at {} r/min), where whirl may hide",
                    hiding.len(),
                    rpm_list(&hiding)
                ),
            },
        );
    }
    let undecided = ok.is_empty() || !hiding.is_empty() || !unsettled.is_empty();
    SearchResult {
        onset_rpm: onset,
        bracket_rpm: bracket,
        class_below: below,
        class_above: above,
        whirl_intervals_rpm: intervals,
        whirl_at_range_top,
        converged: bisected && !undecided,
        undecided,
        bisections: transitions.into_iter().flat_map(|t| t.probes).collect(),
        scan,
        note: notes.join("; "),
    }
}

/// Searches `n` friction coefficients at once: `classify_at(j, speed)` classifies a drop of
/// coefficient `j`. The coefficients run in parallel and so do the drops of each scan; each
/// coefficient's transitions are bisected (in parallel) as soon as its own scan is done, while
/// the other scans go on, so no thread waits for a barrier between the scans and the
/// bisections. The results are in the order of `j` and do not depend on the thread count
/// (each is a function of the drops' outcomes only). Invalid settings run nothing (validate
/// first with [`CriticalOptions::validate`]).
pub fn search_all<F: Fn(usize, f64) -> Outcome + Sync>(
    classify_at: F,
    n: usize,
    o: &CriticalOptions,
) -> Result<Vec<SearchResult>, InvalidParameter> {
    search_all_expecting(classify_at, n, o, &|_| {})
}

/// The drops a bisection of `(lo, hi)` down to `tol_rpm` takes when none fails: one per
/// halving.
fn bisection_drops(lo: f64, hi: f64, tol_rpm: f64) -> usize {
    let (mut width, mut n) = (hi - lo, 0);
    while width > tol_rpm && n < MAX_BISECTIONS {
        width /= 2.0;
        n += 1;
    }
    n
}

/// [`search_all`], telling `expect` how many bisection drops each coefficient's scan has
/// made due, as soon as the scan is done (for a progress bar whose total is known before
/// the bisections run; a failed probe may add one or two more).
pub fn search_all_expecting<F: Fn(usize, f64) -> Outcome + Sync>(
    classify_at: F,
    n: usize,
    o: &CriticalOptions,
    expect: &(dyn Fn(usize) + Sync),
) -> Result<Vec<SearchResult>, InvalidParameter> {
    o.validate()?;
    let speeds = o.scan_speeds();
    Ok((0..n)
        .into_par_iter()
        .map(|j| {
            let scan: Vec<Probe> = speeds
                .par_iter()
                .map(|&s| Probe::new(s, &classify_at(j, s)))
                .collect();
            // The scan speeds that failed are not run again by a bisection.
            let failed: Vec<f64> = scan
                .iter()
                .filter(|p| p.error.is_some())
                .map(|p| p.speed_rpm)
                .collect();
            let f = |s: f64| classify_at(j, s);
            let pairs = transitions_of(&scan);
            expect(
                pairs
                    .iter()
                    .map(|(lo, hi)| bisection_drops(lo.0, hi.0, o.tol_rpm))
                    .sum(),
            );
            let transitions: Vec<Transition> = pairs
                .into_par_iter()
                .map(|(lo, hi)| bisect(&f, lo, hi, o.tol_rpm, &failed))
                .collect();
            assemble(o, scan, transitions)
        })
        .collect())
}

/// [`search_all`] for one class predicate.
pub fn search<F: Fn(f64) -> Outcome + Sync>(
    classify_at: F,
    o: &CriticalOptions,
) -> Result<SearchResult, InvalidParameter> {
    search_expecting(classify_at, o, &|_| {})
}

/// [`search`], telling `expect` how many bisection drops its scan has made due (see
/// [`search_all_expecting`]).
pub fn search_expecting<F: Fn(f64) -> Outcome + Sync>(
    classify_at: F,
    o: &CriticalOptions,
    expect: &(dyn Fn(usize) + Sync),
) -> Result<SearchResult, InvalidParameter> {
    let mut v = search_all_expecting(|_, s| classify_at(s), 1, o, expect)?;
    Ok(v.remove(0))
}

/// Classifies one drop of `scene` at `speed_rpm`: its class, or its failure (a solver error,
/// or a panic inside the solver, caught so one bad drop cannot take a search down).
pub fn drop_outcome(scene: &Scene, speed_rpm: f64, opts: &DropOptions) -> Outcome {
    let mut s = scene.clone();
    s.speed_rpm = speed_rpm;
    match run_drop(&s, opts) {
        Ok(r) => Outcome::Class(r.verdict.class),
        Err(DropFailure::Solve(e)) => Outcome::Failed(format!("{}: {e}", e.kind())),
        Err(DropFailure::Panic(m)) => Outcome::Failed(format!("panic: {m}")),
    }
}

/// The critical whirl speed of `base` for each friction coefficient in `mus` (set as
/// `mu_dynamic`), with the real model. Scans and bisections of all coefficients run in
/// parallel; rows are in the order of `mus` and do not depend on the thread count.
pub fn critical_rows(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
) -> Result<Vec<CriticalRow>, InvalidParameter> {
    critical_rows_ticked(base, mus, o, &Ticker::off())
}

/// [`critical_rows`], counting every finished drop on `ticker` (progress for a search that
/// takes seconds); the ticker expects the scan's drops at once and each coefficient's
/// bisection drops as soon as its scan is done. The caller finishes the ticker (it may count
/// other drops too).
pub fn critical_rows_ticked(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
    ticker: &Ticker,
) -> Result<Vec<CriticalRow>, InvalidParameter> {
    critical_rows_logged(base, mus, o, ticker, None)
}

/// [`critical_rows_ticked`], answering the drops `log` knows from an earlier run and logging
/// every other classified drop to it ([`crate::critical_log`]). The rows are those of a
/// search without a log: each is a function of its drops' classes.
pub fn critical_rows_logged(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
    ticker: &Ticker,
    log: Option<&crate::critical_log::DropLog>,
) -> Result<Vec<CriticalRow>, InvalidParameter> {
    rows_inner(base, mus, o, ticker, log, None)
}

/// [`critical_rows`] that stops early when `cancel` is raised: the drops not yet started are
/// skipped (their probes fail as "cancelled"), so the search ends once the running drops
/// have. `None` then, since such rows are not the search's; otherwise the rows of
/// [`critical_rows`]. Every drop that ran is counted on `cancel`.
pub fn critical_rows_cancellable(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
    cancel: &crate::cancel::Cancel,
) -> Result<Option<Vec<CriticalRow>>, InvalidParameter> {
    let rows = rows_inner(base, mus, o, &Ticker::off(), None, Some(cancel))?;
    Ok((!cancel.requested()).then_some(rows))
}

fn rows_inner(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
    ticker: &Ticker,
    log: Option<&crate::critical_log::DropLog>,
    cancel: Option<&crate::cancel::Cancel>,
) -> Result<Vec<CriticalRow>, InvalidParameter> {
    check_mus(mus)?;
    o.validate()?;
    ticker.expect_more(mus.len() * o.scan_speeds().len());
    let drop_opts = DropOptions {
        duration_s: o.duration_s,
        ..Default::default()
    };
    let scenes: Vec<Scene> = mus
        .iter()
        .map(|&mu| {
            let mut s = base.clone();
            s.mu_dynamic = mu;
            s
        })
        .collect();
    for s in &scenes {
        s.validate()?;
    }
    let hashes: Vec<String> = scenes.iter().map(Scene::hash_hex).collect();
    let results = search_all_expecting(
        |j, speed| {
            let (mu, hash) = (mus[j], &hashes[j]);
            if cancel.is_some_and(|c| c.requested()) {
                return Outcome::Failed("cancelled".to_owned());
            }
            let outcome = match log.and_then(|l| l.known(mu, speed, hash)) {
                Some(class) => Outcome::Class(class),
                None => {
                    let outcome = drop_outcome(&scenes[j], speed, &drop_opts);
                    if let Some(c) = cancel {
                        c.count_drop();
                    }
                    if let (Some(l), Outcome::Class(class)) = (log, &outcome) {
                        l.record(mu, speed, hash, *class);
                    }
                    outcome
                }
            };
            ticker.tick();
            outcome
        },
        scenes.len(),
        o,
        &|n| ticker.expect_more(n),
    )?;
    Ok(results
        .into_iter()
        .zip(mus.iter().zip(hashes))
        .map(|(r, (&mu, hash))| r.into_row(mu, o, hash))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use OrbitClass::*;

    fn opts(from: f64, to: f64) -> CriticalOptions {
        CriticalOptions {
            from_rpm: from,
            to_rpm: to,
            resolution_rpm: 250.0,
            tol_rpm: 10.0,
            duration_s: 1.0,
        }
    }

    fn step_at(threshold: f64) -> impl Fn(f64) -> Outcome + Sync {
        move |s| {
            Outcome::Class(if s >= threshold {
                BackwardWhirl
            } else {
                Pendulum
            })
        }
    }

    #[test]
    fn the_scan_lies_on_multiples_of_the_resolution_plus_the_range_ends() {
        let o = opts(1900.0, 3100.0);
        assert_eq!(
            o.scan_speeds(),
            vec![1900.0, 2000.0, 2250.0, 2500.0, 2750.0, 3000.0, 3100.0]
        );
        assert_eq!(opts(2000.0, 3000.0).scan_speeds().len(), 5);
    }

    #[test]
    fn bisection_brackets_a_known_threshold_within_tolerance() {
        let calls = AtomicUsize::new(0);
        let f = |s: f64| {
            calls.fetch_add(1, Ordering::Relaxed);
            step_at(12345.6)(s)
        };
        let o = opts(2000.0, 30000.0);
        let r = search(f, &o).unwrap();
        let [lo, hi] = r.bracket_rpm.expect("a bracket");
        assert!(
            lo < 12345.6 && 12345.6 <= hi && hi - lo <= 10.0,
            "{lo} {hi}"
        );
        assert_eq!(r.onset_rpm, Some(hi));
        assert_eq!(
            (r.class_below, r.class_above),
            (Some(Pendulum), Some(BackwardWhirl))
        );
        // 113 lattice points; halving 250 to <= 10 takes 5 steps.
        assert_eq!(r.scan.len(), 113);
        assert_eq!(r.bisections.len(), 5);
        assert_eq!(calls.load(Ordering::Relaxed), r.drops());
        assert_eq!(r.whirl_intervals_rpm, vec![[hi, 30000.0]]);
        assert!(r.whirl_at_range_top && r.converged);
    }

    #[test]
    fn the_onset_does_not_depend_on_the_search_range() {
        let f = step_at(4321.0);
        let ranges = [
            (2000.0, 30000.0),
            (2000.0, 8000.0),
            (3000.0, 5000.0),
            (4100.0, 4400.0),
        ];
        let onsets: Vec<f64> = ranges
            .iter()
            .map(|&(a, b)| search(&f, &opts(a, b)).unwrap().onset_rpm.unwrap())
            .collect();
        // Ranges containing the lattice cell [4250, 4500] bisect it identically.
        assert_eq!(onsets[0], onsets[1]);
        assert_eq!(onsets[0], onsets[2]);
        // A range end inside the cell changes the bisection, not the answer (within tol).
        assert!((onsets[3] - onsets[0]).abs() <= 10.0, "{onsets:?}");
        assert!(
            onsets.iter().all(|&x| (4321.0..=4331.0).contains(&x)),
            "{onsets:?}"
        );
    }

    #[test]
    fn every_whirl_interval_is_found_and_non_monotone_means_more_than_one() {
        // Whirl pocket [6000, 9000), a pendulum band, whirl from 20000 to 25000, then
        // bouncing.
        let f = |s: f64| {
            Outcome::Class(
                if (6000.0..9000.0).contains(&s) || (20000.0..25000.0).contains(&s) {
                    BackwardWhirl
                } else if s >= 25000.0 {
                    Bouncing
                } else {
                    Pendulum
                },
            )
        };
        let r = search(f, &opts(2000.0, 30000.0)).unwrap();
        assert_eq!(r.whirl_intervals_rpm.len(), 2);
        let [[a, b], [c, d]] = [r.whirl_intervals_rpm[0], r.whirl_intervals_rpm[1]];
        for (got, want) in [(a, 6000.0), (b, 9000.0), (c, 20000.0), (d, 25000.0)] {
            assert!((got - want).abs() <= 10.0, "{got} vs {want}");
        }
        assert!(!r.whirl_at_range_top);
        assert_eq!(r.onset_rpm, Some(a));
        let row = r.into_row(0.3, &opts(2000.0, 30000.0), "x".into());
        assert!(row.non_monotone);
        assert!(row.note.contains("non-monotone"), "{}", row.note);
    }

    #[test]
    fn a_single_interval_is_monotone_and_no_whirl_gives_no_onset() {
        let r = search(step_at(5000.0), &opts(2000.0, 9000.0)).unwrap();
        let row = r.into_row(0.4, &opts(2000.0, 9000.0), "x".into());
        assert!(!row.non_monotone);
        let r = search(|_| Outcome::Class(Pendulum), &opts(2000.0, 9000.0)).unwrap();
        assert_eq!((r.onset_rpm, r.bracket_rpm), (None, None));
        assert!(r.whirl_intervals_rpm.is_empty());
        assert_eq!(r.note, "no whirl from 2000 to 9000 r/min");
        assert!(r.bisections.is_empty());
    }

    #[test]
    fn whirl_at_the_lowest_speed_gives_that_speed_without_a_bracket() {
        let r = search(|_| Outcome::Class(BackwardWhirl), &opts(2000.0, 3000.0)).unwrap();
        assert_eq!(r.onset_rpm, Some(2000.0));
        assert_eq!(r.bracket_rpm, None);
        assert!(r.note.contains("the onset is at or below it"), "{}", r.note);
    }

    #[test]
    fn failed_drops_count_as_neither_class_and_are_not_run_again() {
        // The lattice point 4500 fails, just above the threshold at 4400.
        let f = |s: f64| {
            if s == 4500.0 {
                Outcome::Failed("step_size_underflow: test".into())
            } else {
                step_at(4400.0)(s)
            }
        };
        let r = search(f, &opts(2000.0, 9000.0)).unwrap();
        assert_eq!(r.failed_drops(), 1);
        let [lo, hi] = r.bracket_rpm.unwrap();
        assert!(lo < 4400.0 && 4400.0 <= hi && hi - lo <= 10.0);
        assert!(r.bisections.iter().all(|p| p.speed_rpm != 4500.0));
        assert!(r.note.contains("1 drop(s) failed"), "{}", r.note);
        // Every drop failing decides nothing.
        let r = search(|_| Outcome::Failed("x".into()), &opts(0.0, 500.0)).unwrap();
        assert_eq!(r.onset_rpm, None);
        assert!(r.note.contains("every scan drop failed"), "{}", r.note);
        // Failures inside a bisection stop it with a valid, unconverged bracket.
        let g = |s: f64| {
            if s.fract() != 0.0 || s % 250.0 != 0.0 {
                Outcome::Failed("event_budget: test".into())
            } else {
                step_at(4400.0)(s)
            }
        };
        let r = search(g, &opts(2000.0, 9000.0)).unwrap();
        assert!(!r.converged);
        assert_eq!(r.bracket_rpm, Some([4250.0, 4500.0]));
    }

    /// `step_at(threshold)` with the drops at `failing` speeds failed.
    fn step_failing_at(threshold: f64, failing: &[f64]) -> impl Fn(f64) -> Outcome + Sync + '_ {
        move |s| {
            if failing.contains(&s) {
                Outcome::Failed("step_budget: test".into())
            } else {
                step_at(threshold)(s)
            }
        }
    }

    #[test]
    fn a_failed_drop_below_the_onset_leaves_it_undecided() {
        // The lattice point 3000 fails, well below the onset at 4400: had it whirled, the
        // onset would be 3000 or lower.
        let r = search(step_failing_at(4400.0, &[3000.0]), &opts(2000.0, 9000.0)).unwrap();
        let [lo, hi] = r.bracket_rpm.unwrap();
        assert!(lo < 4400.0 && 4400.0 <= hi && hi - lo <= 10.0);
        assert!(r.undecided && !r.converged);
        assert!(
            r.note
                .starts_with("UNDECIDED: 1 drop(s) failed below the onset")
                && r.note.contains("(at 3000 r/min)"),
            "{}",
            r.note
        );
        let row = r.into_row(0.4, &opts(2000.0, 9000.0), "x".into());
        assert!(row.undecided && !row.converged);
        assert!(
            row.csv_line().contains(",1,false,true,"),
            "{}",
            row.csv_line()
        );
        // In the JSON only when true, so decided rows keep the bytes they always had.
        let json = serde_json::to_string(&row).unwrap();
        assert!(
            json.contains(r#""converged":false,"undecided":true,"#),
            "{json}"
        );
        let back: CriticalRow = serde_json::from_str(&json).unwrap();
        assert_eq!(back, row);
        let o = opts(2000.0, 9000.0);
        let decided = search(step_at(4400.0), &o)
            .unwrap()
            .into_row(0.4, &o, "x".into());
        let json = serde_json::to_string(&decided).unwrap();
        assert!(!json.contains("undecided"), "{json}");
        assert!(
            !serde_json::from_str::<CriticalRow>(&json)
                .unwrap()
                .undecided
        );
    }

    #[test]
    fn a_failed_drop_inside_the_final_bracket_leaves_the_onset_undecided() {
        // The first bisection midpoint of [4250, 4500] fails, just below the threshold; the
        // bisection goes on beside it and its bracket closes around the failed speed.
        let r = search(step_failing_at(4376.0, &[4375.0]), &opts(2000.0, 9000.0)).unwrap();
        let [lo, hi] = r.bracket_rpm.unwrap();
        assert!(lo < 4375.0 && 4375.0 < hi && hi - lo <= 10.0, "{lo} {hi}");
        assert!(r.undecided && !r.converged, "{}", r.note);
    }

    #[test]
    fn failed_drops_above_the_onset_leave_it_decided() {
        // Failures in the whirl above the onset (a lattice point and the range top) cannot
        // lower it: the row converges and the note counts them.
        let r = search(
            step_failing_at(4400.0, &[6000.0, 9000.0]),
            &opts(2000.0, 9000.0),
        )
        .unwrap();
        assert!(!r.undecided && r.converged, "{}", r.note);
        assert_eq!(r.failed_drops(), 2);
        assert!(r.note.contains("2 drop(s) failed"), "{}", r.note);
        assert!(!r.note.contains("UNDECIDED"), "{}", r.note);
    }

    /// Unresolved drops (the motion did not settle into a class; a backward whirl with
    /// intermittent contact is one) below the onset leave it undecided, as failed drops do:
    /// they were counted as no whirl, so the onset above them was reported as decided.
    #[test]
    fn unresolved_drops_below_the_onset_or_without_whirl_leave_it_undecided() {
        let with_unresolved = |threshold: f64, at: &'static [f64]| {
            move |s: f64| {
                Outcome::Class(if at.contains(&s) {
                    Unresolved
                } else if s >= threshold {
                    BackwardWhirl
                } else {
                    Pendulum
                })
            }
        };
        let o = opts(2000.0, 9000.0);
        let r = search(with_unresolved(4400.0, &[3000.0]), &o).unwrap();
        assert!(r.undecided && !r.converged, "{}", r.note);
        assert!(
            r.note
                .starts_with("UNDECIDED: 1 drop(s) below the onset 4406.2 r/min")
                && r.note
                    .contains("did not settle (unresolved, at 3000 r/min)"),
            "{}",
            r.note
        );
        let row = r.into_row(0.3, &o, "x".into());
        assert_eq!(
            undecided_summary(std::slice::from_ref(&row)).as_deref(),
            Some(format!("mu 0.3 (1 of {} drops did not settle)", row.drops).as_str())
        );
        // Above the onset they cannot lower it: decided.
        let r = search(with_unresolved(4400.0, &[6000.0]), &o).unwrap();
        assert!(!r.undecided && r.converged, "{}", r.note);
        // No whirl found: any of them may hide a whirl.
        let r = search(with_unresolved(1e9, &[5000.0]), &o).unwrap();
        assert_eq!(r.onset_rpm, None);
        assert!(r.undecided, "{}", r.note);
        assert!(
            r.note
                .contains("UNDECIDED: 1 drop(s) did not settle (unresolved, at 5000 r/min)"),
            "{}",
            r.note
        );
    }

    #[test]
    fn without_whirl_any_failed_drop_leaves_the_row_undecided() {
        // No whirl found: the failed drop at 5000 could hide a whirl interval.
        let f = |s: f64| {
            if s == 5000.0 {
                Outcome::Failed("step_budget: test".into())
            } else {
                Outcome::Class(Pendulum)
            }
        };
        let r = search(f, &opts(2000.0, 9000.0)).unwrap();
        assert_eq!(r.onset_rpm, None);
        assert!(r.undecided && !r.converged);
        assert!(
            r.note
                .contains("UNDECIDED: 1 drop(s) failed (at 5000 r/min)"),
            "{}",
            r.note
        );
        // Every scan drop failing decides nothing.
        let r = search(|_| Outcome::Failed("x".into()), &opts(0.0, 500.0)).unwrap();
        assert!(r.undecided && !r.converged);
        assert!(r.note.starts_with("UNDECIDED: every scan drop failed"));
        // Whirl at the lowest speed that did not fail: the failed speeds below it decide.
        let r = search(step_failing_at(0.0, &[2000.0]), &opts(2000.0, 3000.0)).unwrap();
        assert_eq!((r.onset_rpm, r.bracket_rpm), (Some(2250.0), None));
        assert!(r.undecided && !r.converged, "{}", r.note);
        assert!(r
            .note
            .contains("the lowest speed scanned that did not fail"));
        // Without failures nothing is undecided.
        let r = search(step_at(4400.0), &opts(2000.0, 9000.0)).unwrap();
        assert!(!r.undecided && r.converged);
    }

    #[test]
    fn the_failures_that_hide_an_onset_are_those_below_it() {
        assert_eq!(
            hiding_failures(Some(4400.0), &[3000.0, 4400.0, 5000.0]),
            vec![3000.0]
        );
        assert_eq!(
            hiding_failures(None, &[3000.0, 5000.0]),
            vec![3000.0, 5000.0]
        );
        assert!(hiding_failures(Some(4400.0), &[]).is_empty());
        let speeds: Vec<f64> = (1..=7).rev().map(|k| 1000.0 * k as f64).collect();
        assert_eq!(rpm_list(&speeds), "1000, 2000, 3000, 4000, 5000 and 2 more");
    }

    #[test]
    fn the_summary_names_the_undecided_rows() {
        let o = opts(2000.0, 9000.0);
        let decided = search(step_at(4400.0), &o)
            .unwrap()
            .into_row(0.3, &o, "x".into());
        let undecided = search(step_failing_at(4400.0, &[3000.0]), &o)
            .unwrap()
            .into_row(0.4, &o, "x".into());
        assert_eq!(undecided_summary(std::slice::from_ref(&decided)), None);
        let drops = undecided.drops;
        assert_eq!(
            undecided_summary(&[decided, undecided]),
            Some(format!("mu 0.4 (1 of {drops} drops failed)"))
        );
    }

    #[test]
    fn invalid_settings_are_refused_by_name() {
        let bad = |from, to, res, tol| check_range(from, to, res, tol).unwrap_err().field;
        assert_eq!(bad(-1.0, 5.0, 1.0, 1.0), "from_rpm");
        assert_eq!(bad(5.0, 5.0, 1.0, 1.0), "to_rpm");
        assert_eq!(bad(0.0, 1e308, 250.0, 10.0), "to_rpm");
        assert_eq!(bad(0.0, 5000.0, 0.0, 1.0), "resolution_rpm");
        assert_eq!(bad(0.0, 1e6, 1.0, 1.0), "resolution_rpm");
        assert_eq!(bad(0.0, 5000.0, 250.0, 1e-300), "tol_rpm");
        assert_eq!(bad(0.0, 5000.0, 250.0, 300.0), "tol_rpm");
        assert_eq!(check_mus(&[]).unwrap_err().field, "mu");
        assert_eq!(check_mus(&[0.3, 2.5]).unwrap_err().field, "mu");
        assert_eq!(check_mus(&[0.3, 0.3]).unwrap_err().field, "mu");
        assert!(search(step_at(1.0), &opts(5.0, 5.0)).is_err());
    }

    #[test]
    fn csv_rows_carry_the_scalar_fields() {
        let r = search(step_at(5000.0), &opts(2000.0, 9000.0)).unwrap();
        let row = r.into_row(0.4, &opts(2000.0, 9000.0), "abc".into());
        let text = csv_text(std::slice::from_ref(&row));
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some(CSV_HEADER));
        let line = lines.next().unwrap();
        // Fields, with commas inside the quoted note kept in it.
        let mut fields = vec![String::new()];
        let mut quoted = false;
        for ch in line.chars() {
            match ch {
                '"' => quoted = !quoted,
                ',' if !quoted => fields.push(String::new()),
                c => fields.last_mut().unwrap().push(c),
            }
        }
        assert_eq!(fields.len(), CSV_HEADER.split(',').count(), "{line}");
        assert_eq!(fields.last().unwrap(), &row.note);
        assert!(line.starts_with("0.4,"), "{line}");
        assert!(line.contains(",pendulum,backward_whirl,"), "{line}");
    }

    #[test]
    fn real_drops_are_deterministic_whatever_the_thread_count() {
        let run = |threads: usize| {
            crate::pool::pool(Some(threads)).unwrap().install(|| {
                critical_rows(
                    &Scene::paper(),
                    &[0.4, 0.3],
                    &CriticalOptions {
                        from_rpm: 4000.0,
                        to_rpm: 5000.0,
                        resolution_rpm: 500.0,
                        tol_rpm: 250.0,
                        duration_s: 0.2,
                    },
                )
                .unwrap()
            })
        };
        let one = run(1);
        let three = run(3);
        assert_eq!(one, three);
        assert_eq!((one[0].mu, one[1].mu), (0.4, 0.3));
        let json = serde_json::to_string(&one).unwrap();
        let back: Vec<CriticalRow> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, one);
    }

    #[test]
    fn the_bisection_drops_are_expected_as_each_scan_ends() {
        let expected = AtomicUsize::new(0);
        let calls = AtomicUsize::new(0);
        let o = opts(2000.0, 9000.0);
        let step = step_at(5000.0);
        let r = search_all_expecting(
            |_, s| {
                calls.fetch_add(1, Ordering::Relaxed);
                step(s)
            },
            3,
            &o,
            &|n| {
                expected.fetch_add(n, Ordering::Relaxed);
            },
        )
        .unwrap();
        let scan = 3 * o.scan_speeds().len();
        // 250 r/min down to 10: five halvings, for one transition per coefficient.
        assert_eq!(expected.load(Ordering::Relaxed), 3 * 5);
        assert_eq!(calls.load(Ordering::Relaxed), scan + 3 * 5);
        assert!(r.iter().all(|r| r.onset_rpm.is_some()));
    }

    #[test]
    fn a_cancelled_search_runs_no_further_drop_and_an_uncancelled_one_gives_the_rows() {
        let o = CriticalOptions {
            from_rpm: 4000.0,
            to_rpm: 5000.0,
            resolution_rpm: 500.0,
            tol_rpm: 250.0,
            duration_s: 0.05,
        };
        let scene = Scene::paper();
        let cancel = crate::cancel::Cancel::new();
        let rows = critical_rows_cancellable(&scene, &[0.4], &o, &cancel).unwrap();
        let plain = critical_rows(&scene, &[0.4], &o).unwrap();
        assert_eq!(rows.as_ref(), Some(&plain));
        assert_eq!(cancel.drops_run(), plain[0].drops);

        // Raised while the search runs (after its second drop, on one thread): the drops
        // not yet started are skipped.
        let o_long = CriticalOptions {
            from_rpm: 2000.0,
            to_rpm: 30000.0,
            resolution_rpm: 250.0,
            ..o
        };
        let cancel = crate::cancel::Cancel::new();
        let rows = std::thread::scope(|sc| {
            sc.spawn(|| {
                while cancel.drops_run() < 2 {
                    std::thread::yield_now();
                }
                cancel.request();
            });
            crate::pool::pool(Some(1)).unwrap().install(|| {
                critical_rows_cancellable(&scene, &[0.1, 0.4], &o_long, &cancel).unwrap()
            })
        });
        assert_eq!(rows, None);
        let total = 2 * o_long.scan_speeds().len();
        assert!(
            (2..total / 2).contains(&cancel.drops_run()),
            "{} of {total}",
            cancel.drops_run()
        );

        let cancel = crate::cancel::Cancel::new();
        cancel.request();
        assert_eq!(
            critical_rows_cancellable(&scene, &[0.4], &o, &cancel).unwrap(),
            None
        );
        assert_eq!(cancel.drops_run(), 0);
    }
}
