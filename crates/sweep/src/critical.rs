//! The critical backward-whirl speed: the lowest release speed at which a drop whirls, for
//! a given friction coefficient.
//!
//! [`search`] is a pure search over any class predicate (testable without the integrator):
//! a coarse uniform scan (in parallel, order- and thread-count-independent) finds the
//! LOWEST non-whirl-to-whirl transition between adjacent successful scan points, then a
//! bisection narrows it to `tol_rpm`. Nothing assumes the boundary is monotone: a whirl
//! point seen below a non-whirl point at a higher speed sets
//! [`CriticalResult::non_monotone`]. When no transition lies in the range (no whirl at all,
//! or whirl already at the lowest speed) the bracket is `None` and the note says which; no
//! number is invented. Failed drops (solver errors) are listed in
//! [`CriticalResult::failures`] and count as neither class.
//!
//! [`critical_speeds`] runs the search with the real model for several friction
//! coefficients (in parallel; results are deterministic whatever the thread count).

use crate::classify::{classify, ClassifyParams, OrbitClass};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use whirlmap_core::{simulate, DropOptions, InvalidParameter, Scene};

/// Scan points of the coarse scan when not told otherwise.
pub const DEFAULT_SCAN_POINTS: usize = 12;

/// Bisection steps at most (a guard: floats stop halving long before this).
const MAX_BISECTIONS: usize = 200;

/// Where in the bracket a bisection drop goes: the midpoint, then, if a drop fails there,
/// beside it.
const BISECTION_FRACTIONS: [f64; 3] = [0.5, 0.375, 0.625];

/// What one drop gave: its orbit class, or a failure (solver error) with its message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The drop finished and was classified.
    Class(OrbitClass),
    /// The drop failed (typically a typed solver error, `kind: message`).
    Failed(String),
}

/// A drop that failed during the search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedDrop {
    /// Release speed of the drop (r/min).
    pub speed_rpm: f64,
    /// Why it failed.
    pub error: String,
}

/// The result of one critical-speed search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CriticalResult {
    /// `(lo, hi)` r/min: no whirl at `lo`, whirl at `hi`, the lowest such transition found.
    /// `None` when the range holds no transition (see `note`).
    pub bracket: Option<(f64, f64)>,
    /// Class at `lo` (pendulum, bouncing or unresolved); `None` without a bracket.
    pub class_lo: Option<OrbitClass>,
    /// Class at `hi` (backward or forward whirl); `None` without a bracket.
    pub class_hi: Option<OrbitClass>,
    /// Whether the bracket is no wider than the tolerance (false if a bisection drop failed).
    pub converged: bool,
    /// Drops run (scan plus bisection, failed ones included).
    pub drops_used: usize,
    /// A whirl point was seen below a non-whirl point at a higher speed (scan or bisection).
    pub non_monotone: bool,
    /// The coarse scan, in speed order (failed drops left out: see `failures`).
    pub scanned: Vec<(f64, OrbitClass)>,
    /// The bisection drops, in the order run (failed ones left out).
    pub bisected: Vec<(f64, OrbitClass)>,
    /// Drops that failed, in the order run (scan first, in speed order).
    pub failures: Vec<FailedDrop>,
    /// What was found, in words.
    pub note: String,
}

/// Settings of a critical-speed search with the real model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CriticalOptions {
    /// Lowest release speed searched (r/min), >= 0.
    pub from_rpm: f64,
    /// Highest release speed searched (r/min), > `from_rpm`.
    pub to_rpm: f64,
    /// Bracket width to stop bisecting at (r/min), > 0.
    pub tol_rpm: f64,
    /// Points of the coarse scan, >= 2.
    pub scan_points: usize,
    /// Simulated time of each drop (s).
    pub duration_s: f64,
    /// Classifier thresholds.
    pub classify: ClassifyParams,
}

impl Default for CriticalOptions {
    fn default() -> Self {
        Self {
            from_rpm: 2000.0,
            to_rpm: 30_000.0,
            tol_rpm: 50.0,
            scan_points: DEFAULT_SCAN_POINTS,
            duration_s: 1.0,
            classify: ClassifyParams::default(),
        }
    }
}

impl CriticalOptions {
    /// Checks the search settings; the error names the field.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        check_range(self.from_rpm, self.to_rpm, self.tol_rpm)?;
        if self.scan_points < 2 || self.scan_points > 100_000 {
            return Err(InvalidParameter::new(
                "scan_points",
                self.scan_points,
                "[2, 100000]",
            ));
        }
        DropOptions {
            duration_s: self.duration_s,
            ..Default::default()
        }
        .validate()
    }
}

/// Checks a search range: `from_rpm` and `to_rpm` finite, >= 0, `from_rpm < to_rpm`;
/// `tol_rpm` finite and > 0. The error names the field.
pub fn check_range(from_rpm: f64, to_rpm: f64, tol_rpm: f64) -> Result<(), InvalidParameter> {
    if !(from_rpm.is_finite() && from_rpm >= 0.0) {
        return Err(InvalidParameter::new("from_rpm", from_rpm, ">= 0, finite"));
    }
    if !(to_rpm.is_finite() && to_rpm >= 0.0) {
        return Err(InvalidParameter::new("to_rpm", to_rpm, ">= 0, finite"));
    }
    if from_rpm >= to_rpm {
        return Err(InvalidParameter::new(
            "to_rpm",
            to_rpm,
            &format!("> {from_rpm} (the lower end)"),
        ));
    }
    if !(tol_rpm.is_finite() && tol_rpm > 0.0) {
        return Err(InvalidParameter::new("tol_rpm", tol_rpm, "> 0, finite"));
    }
    Ok(())
}

/// Checks a list of friction coefficients: not empty, each in [0, 2].
pub fn check_mus(mus: &[f64]) -> Result<(), InvalidParameter> {
    if mus.is_empty() {
        return Err(InvalidParameter::new("mu", "(none)", "at least one value"));
    }
    for &mu in mus {
        if !(mu.is_finite() && (0.0..=2.0).contains(&mu)) {
            return Err(InvalidParameter::new("mu", mu, "[0, 2]"));
        }
    }
    Ok(())
}

/// Speeds of the coarse scan: `n` uniform points from `from` to `to`, both included.
fn scan_speeds(from: f64, to: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|i| {
            if i + 1 == n {
                to
            } else {
                from + (to - from) * i as f64 / (n - 1) as f64
            }
        })
        .collect()
}

/// Whether a whirl point lies below a non-whirl point at a higher speed; returns the first
/// such pair `(whirl speed, non-whirl speed)` in speed order.
fn find_non_monotone(points: &[(f64, OrbitClass)]) -> Option<(f64, f64)> {
    let mut sorted: Vec<(f64, OrbitClass)> = points.to_vec();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut lowest_whirl: Option<f64> = None;
    for &(s, c) in &sorted {
        if c.is_whirl() {
            lowest_whirl.get_or_insert(s);
        } else if let Some(w) = lowest_whirl {
            return Some((w, s));
        }
    }
    None
}

/// Finds the lowest non-whirl-to-whirl transition of `classify_at` in `[from_rpm, to_rpm]`.
///
/// A coarse scan of `scan_points` uniform speeds (at least 2; evaluated in parallel and
/// collected in speed order) picks the first pair of adjacent successful points with no
/// whirl at the lower and whirl (backward or forward; the class is recorded) at the upper;
/// bisection then narrows it until `hi - lo <= tol_rpm`. Known failed speeds are not run
/// again; where a bisection drop fails, the search tries 3/8 and 5/8 of the bracket, and
/// if those fail too it stops (`converged = false`, the bracket stays valid). Invalid ranges (see
/// [`check_range`]) give no bracket and say so in the note; nothing is run.
pub fn search<F: Fn(f64) -> Outcome + Sync>(
    classify_at: F,
    from_rpm: f64,
    to_rpm: f64,
    scan_points: usize,
    tol_rpm: f64,
) -> CriticalResult {
    let mut result = CriticalResult {
        bracket: None,
        class_lo: None,
        class_hi: None,
        converged: false,
        drops_used: 0,
        non_monotone: false,
        scanned: Vec::new(),
        bisected: Vec::new(),
        failures: Vec::new(),
        note: String::new(),
    };
    if let Err(e) = check_range(from_rpm, to_rpm, tol_rpm) {
        result.note = format!("not searched: {e}");
        return result;
    }

    // Coarse scan: parallel map, collected in speed order.
    let speeds = scan_speeds(from_rpm, to_rpm, scan_points);
    let outcomes: Vec<Outcome> = speeds.par_iter().map(|&s| classify_at(s)).collect();
    result.drops_used += speeds.len();
    for (&s, o) in speeds.iter().zip(outcomes) {
        match o {
            Outcome::Class(c) => result.scanned.push((s, c)),
            Outcome::Failed(error) => result.failures.push(FailedDrop {
                speed_rpm: s,
                error,
            }),
        }
    }

    let mut notes: Vec<String> = Vec::new();
    let scanned = result.scanned.clone();
    match scanned.first() {
        None => notes.push(format!(
            "every drop failed ({} of {}): nothing decided",
            result.failures.len(),
            speeds.len()
        )),
        Some(&(s0, c0)) if c0.is_whirl() => {
            let below = result.failures.iter().filter(|f| f.speed_rpm < s0).count();
            if below == 0 {
                notes.push(format!("already whirling at {} r/min", fmt_rpm(s0)));
            } else {
                notes.push(format!(
                    "already whirling at {} r/min (lowest successful drop; {below} failed below)",
                    fmt_rpm(s0)
                ));
            }
        }
        Some(_) => {
            let pair = scanned
                .windows(2)
                .find(|w| !w[0].1.is_whirl() && w[1].1.is_whirl());
            match pair {
                None => {
                    let top = scanned.last().expect("not empty").0;
                    notes.push(format!("no whirl up to {} r/min", fmt_rpm(top)));
                }
                Some(w) => {
                    let (mut lo, mut c_lo) = w[0];
                    let (mut hi, mut c_hi) = w[1];
                    let mut converged = true;
                    let mut steps = 0;
                    'bisect: while hi - lo > tol_rpm && steps < MAX_BISECTIONS {
                        steps += 1;
                        // The midpoint, or beside it when a drop fails there (a failed scan
                        // point is often exactly the midpoint of its neighbours).
                        let mut next = None;
                        for frac in BISECTION_FRACTIONS {
                            let mid = lo + frac * (hi - lo);
                            if !(mid > lo && mid < hi) {
                                break 'bisect; // float resolution reached
                            }
                            if result.failures.iter().any(|f| f.speed_rpm == mid) {
                                continue;
                            }
                            result.drops_used += 1;
                            match classify_at(mid) {
                                Outcome::Class(c) => {
                                    next = Some((mid, c));
                                    break;
                                }
                                Outcome::Failed(error) => result.failures.push(FailedDrop {
                                    speed_rpm: mid,
                                    error,
                                }),
                            }
                        }
                        let Some((mid, c)) = next else {
                            notes.push(format!(
                                "bisection stopped: drops failed inside [{}, {}] r/min",
                                fmt_rpm(lo),
                                fmt_rpm(hi)
                            ));
                            converged = false;
                            break;
                        };
                        result.bisected.push((mid, c));
                        if c.is_whirl() {
                            (hi, c_hi) = (mid, c);
                        } else {
                            (lo, c_lo) = (mid, c);
                        }
                    }
                    converged &= hi - lo <= tol_rpm;
                    result.bracket = Some((lo, hi));
                    result.class_lo = Some(c_lo);
                    result.class_hi = Some(c_hi);
                    result.converged = converged;
                    notes.insert(
                        0,
                        format!(
                            "{} at {} r/min, {} at {} r/min",
                            c_lo.name(),
                            fmt_rpm(lo),
                            c_hi.name(),
                            fmt_rpm(hi)
                        ),
                    );
                    if c_lo == OrbitClass::Unresolved {
                        notes.push("the lower side is unresolved, not a decided orbit".into());
                    }
                }
            }
        }
    }

    let mut all = result.scanned.clone();
    all.extend_from_slice(&result.bisected);
    if let Some((w, n)) = find_non_monotone(&all) {
        result.non_monotone = true;
        notes.push(format!(
            "non-monotone: whirl at {} r/min below no whirl at {} r/min",
            fmt_rpm(w),
            fmt_rpm(n)
        ));
    }
    if !result.failures.is_empty() {
        notes.push(format!(
            "{} drop(s) failed, counted as neither class",
            result.failures.len()
        ));
    }
    result.note = notes.join("; ");
    result
}

/// A speed for notes: integers without decimals, others with one.
fn fmt_rpm(s: f64) -> String {
    if s.fract() == 0.0 {
        format!("{s:.0}")
    } else {
        format!("{s:.1}")
    }
}

/// Classifies one drop of `scene` at `speed_rpm`.
pub fn drop_outcome(
    scene: &Scene,
    speed_rpm: f64,
    opts: &DropOptions,
    params: &ClassifyParams,
) -> Outcome {
    let mut s = scene.clone();
    s.speed_rpm = speed_rpm;
    match simulate(&s, opts) {
        Ok(r) => Outcome::Class(classify(&r.features, r.stop_reason, params)),
        Err(e) => Outcome::Failed(format!("{}: {e}", e.kind())),
    }
}

/// The critical whirl speed of `base` for each friction coefficient in `mus` (set as
/// `mu_dynamic`), searched over `[from, to]` r/min with [`DEFAULT_SCAN_POINTS`] scan points
/// down to `tol` r/min, each drop simulated for `duration_s` and classified with
/// `ClassifyParams::default()`. The mus run in parallel; results are in the order of `mus`
/// and do not depend on the thread count.
pub fn critical_speeds(
    base: &Scene,
    mus: &[f64],
    from: f64,
    to: f64,
    tol: f64,
    duration_s: f64,
) -> Vec<(f64, CriticalResult)> {
    critical_speeds_with(
        base,
        mus,
        &CriticalOptions {
            from_rpm: from,
            to_rpm: to,
            tol_rpm: tol,
            scan_points: DEFAULT_SCAN_POINTS,
            duration_s,
            classify: ClassifyParams::default(),
        },
    )
}

/// [`critical_speeds`] with every setting explicit.
pub fn critical_speeds_with(
    base: &Scene,
    mus: &[f64],
    o: &CriticalOptions,
) -> Vec<(f64, CriticalResult)> {
    let drop_opts = DropOptions {
        duration_s: o.duration_s,
        ..Default::default()
    };
    mus.par_iter()
        .map(|&mu| {
            let mut scene = base.clone();
            scene.mu_dynamic = mu;
            let r = search(
                |s| drop_outcome(&scene, s, &drop_opts, &o.classify),
                o.from_rpm,
                o.to_rpm,
                o.scan_points,
                o.tol_rpm,
            );
            (mu, r)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use OrbitClass::*;

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
    fn bisection_brackets_a_known_threshold_within_tolerance() {
        let calls = AtomicUsize::new(0);
        let f = |s: f64| {
            calls.fetch_add(1, Ordering::Relaxed);
            step_at(12345.6)(s)
        };
        let r = search(f, 2000.0, 30000.0, 12, 50.0);
        let (lo, hi) = r.bracket.expect("a bracket");
        assert!(lo < 12345.6 && 12345.6 <= hi, "{lo} {hi}");
        assert!(hi - lo <= 50.0);
        assert!(r.converged);
        assert_eq!(r.class_lo, Some(Pendulum));
        assert_eq!(r.class_hi, Some(BackwardWhirl));
        // Scan step 28000/11 = 2545.5 r/min; halving to <= 50 takes ceil(log2(50.9)) = 6.
        assert_eq!(r.drops_used, 12 + 6);
        assert_eq!(calls.load(Ordering::Relaxed), r.drops_used);
        assert_eq!(r.bisected.len(), 6);
        assert!(!r.non_monotone);
        assert!(r.failures.is_empty());
        assert_eq!(r.scanned.len(), 12);
        assert_eq!(r.scanned[0].0, 2000.0);
        assert_eq!(r.scanned[11].0, 30000.0);
    }

    #[test]
    fn forward_whirl_counts_as_whirl_and_is_recorded() {
        let f = |s: f64| Outcome::Class(if s >= 9000.0 { ForwardWhirl } else { Bouncing });
        let r = search(f, 2000.0, 30000.0, 12, 100.0);
        let (lo, hi) = r.bracket.unwrap();
        assert!(lo < 9000.0 && 9000.0 <= hi && hi - lo <= 100.0);
        assert_eq!(r.class_lo, Some(Bouncing));
        assert_eq!(r.class_hi, Some(ForwardWhirl));
    }

    #[test]
    fn non_monotone_boundary_is_flagged_and_the_lowest_transition_found() {
        // Pendulum, a whirl pocket in [6000, 9000), a pendulum band, whirl from 20000.
        let f = |s: f64| {
            Outcome::Class(if (6000.0..9000.0).contains(&s) || s >= 20000.0 {
                BackwardWhirl
            } else {
                Pendulum
            })
        };
        let r = search(f, 2000.0, 30000.0, 12, 50.0);
        let (lo, hi) = r.bracket.unwrap();
        assert!(lo < 6000.0 && 6000.0 <= hi && hi - lo <= 50.0, "{lo} {hi}");
        assert!(r.non_monotone);
        assert!(r.note.contains("non-monotone"), "{}", r.note);
    }

    #[test]
    fn no_transition_gives_no_bracket_and_says_why() {
        let all_pendulum = |_s: f64| Outcome::Class(Pendulum);
        let r = search(all_pendulum, 2000.0, 30000.0, 12, 50.0);
        assert_eq!(r.bracket, None);
        assert_eq!(r.class_lo, None);
        assert_eq!(r.drops_used, 12);
        assert_eq!(r.note, "no whirl up to 30000 r/min");
        assert!(!r.non_monotone);

        let all_whirl = |_s: f64| Outcome::Class(BackwardWhirl);
        let r = search(all_whirl, 2000.0, 30000.0, 12, 50.0);
        assert_eq!(r.bracket, None);
        assert_eq!(r.drops_used, 12);
        assert_eq!(r.note, "already whirling at 2000 r/min");

        // Whirl at the bottom, pendulum above: still no number, but flagged.
        let r = search(
            |s: f64| Outcome::Class(if s < 5000.0 { BackwardWhirl } else { Pendulum }),
            2000.0,
            30000.0,
            12,
            50.0,
        );
        assert_eq!(r.bracket, None);
        assert!(r.non_monotone);
        assert!(
            r.note.starts_with("already whirling at 2000 r/min"),
            "{}",
            r.note
        );
    }

    #[test]
    fn failed_drops_are_reported_and_count_as_neither_class() {
        // Scan points: 2000, 4545.45, 7090.9, ...; the one at 7090.9 fails, just below the
        // threshold. The transition is bracketed by its successful neighbours.
        let f = |s: f64| {
            if (s - 7090.9).abs() < 1.0 {
                Outcome::Failed("step_size_underflow: test".into())
            } else {
                step_at(8000.0)(s)
            }
        };
        let r = search(f, 2000.0, 30000.0, 12, 50.0);
        assert_eq!(r.failures.len(), 1);
        assert!((r.failures[0].speed_rpm - 7090.9).abs() < 1.0);
        assert_eq!(r.scanned.len(), 11);
        assert!(r.scanned.iter().all(|p| (p.0 - 7090.9).abs() > 1.0));
        let (lo, hi) = r.bracket.unwrap();
        assert!(lo < 8000.0 && 8000.0 <= hi && hi - lo <= 50.0);
        assert!(r.note.contains("1 drop(s) failed"), "{}", r.note);
        assert!(!r.non_monotone);

        // A failure in the bisection stops it with a valid but wide bracket.
        let calls = AtomicUsize::new(0);
        let g = |s: f64| {
            if calls.fetch_add(1, Ordering::SeqCst) >= 12 {
                Outcome::Failed("event_budget: test".into())
            } else {
                step_at(8000.0)(s)
            }
        };
        let r = search(g, 2000.0, 30000.0, 12, 50.0);
        let (lo, hi) = r.bracket.unwrap();
        assert!(lo < 8000.0 && 8000.0 <= hi);
        assert!(!r.converged);
        assert_eq!(
            r.drops_used,
            12 + 3,
            "midpoint and its two neighbours tried"
        );
        assert_eq!(r.failures.len(), 3);
        assert!(r.note.contains("bisection stopped"), "{}", r.note);

        // Every drop failed.
        let r = search(|_| Outcome::Failed("x".into()), 0.0, 100.0, 3, 1.0);
        assert_eq!(r.bracket, None);
        assert_eq!(r.failures.len(), 3);
        assert!(r.note.contains("every drop failed"), "{}", r.note);
    }

    #[test]
    fn invalid_ranges_run_nothing() {
        let r = search(step_at(1.0), 5.0, 5.0, 12, 1.0);
        assert_eq!((r.bracket, r.drops_used), (None, 0));
        assert!(r.note.contains("to_rpm"), "{}", r.note);
        assert_eq!(check_range(-1.0, 5.0, 1.0).unwrap_err().field, "from_rpm");
        assert_eq!(check_range(0.0, 5.0, 0.0).unwrap_err().field, "tol_rpm");
        assert_eq!(check_mus(&[]).unwrap_err().field, "mu");
        assert_eq!(check_mus(&[0.3, 2.5]).unwrap_err().field, "mu");
    }

    #[test]
    fn real_drops_are_deterministic_whatever_the_thread_count() {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    critical_speeds_with(
                        &Scene::paper(),
                        &[0.4, 0.3],
                        &CriticalOptions {
                            from_rpm: 2000.0,
                            to_rpm: 8000.0,
                            tol_rpm: 1000.0,
                            scan_points: 4,
                            duration_s: 0.2,
                            ..Default::default()
                        },
                    )
                })
        };
        let one = run(1);
        let three = run(3);
        assert_eq!(one, three);
        assert_eq!(one[0].0, 0.4);
        assert_eq!(one[1].0, 0.3);
        let json = serde_json::to_string(&one).unwrap();
        assert!(json.contains("\"bracket\""), "{json}");
    }
}
