//! What a sweep spec asks for beside its grid: the critical-speed search (`critical.json`)
//! and the orbits of the Fig. 3 chart (`orbits/*.json`), in the forms the charts (`whirlmap-plot`) read.

use crate::critical::{critical_rows_logged, csv_text, CriticalRow};
use crate::critical_log::DropLog;
use crate::progress::Ticker;
use crate::run::run_drop;
use crate::spec::SweepSpec;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use thiserror::Error;
use whirlmap_core::{DropOptions, Fidelity};
use whirlmap_results::critical::critical_json;
use whirlmap_results::files::{orbit_error_file, orbit_file, ORBITS_DIR};
use whirlmap_results::orbit::OrbitFile;

/// Why an extra output could not be made.
#[derive(Debug, Error)]
pub enum ExtrasError {
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// Writes `text` to `path` all or nothing ([`whirlmap_results::write_atomic`]), creating its
/// folder.
fn write(path: &Path, text: &str) -> Result<(), ExtrasError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|source| ExtrasError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    whirlmap_results::write_atomic(path, text.as_bytes()).map_err(|e| ExtrasError::Io {
        path: e.path,
        source: e.source,
    })
}

impl ExtrasError {
    /// The same failure from the sweep's writers.
    pub fn from_sweep(e: crate::sweep::SweepError) -> Self {
        match e {
            crate::sweep::SweepError::Io { path, source } => ExtrasError::Io { path, source },
            other => ExtrasError::Io {
                path: PathBuf::new(),
                source: std::io::Error::other(other.to_string()),
            },
        }
    }
}

/// The files the extras wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExtrasWritten {
    /// `critical.json`, when the spec has a critical section.
    pub critical: Option<PathBuf>,
    /// The orbit files.
    pub orbits: Vec<PathBuf>,
    /// The probability ensemble's folder, when the spec has a probability section.
    pub probability: Option<PathBuf>,
}

/// Runs every extra on one pool of `threads` worker threads (rayon's default when `None`), as
/// the grid did: the critical search, the orbits and the probability ensemble (with progress
/// lines when `progress`) all at once, so each fills the threads the others leave idle
/// (a bisection's last drops, the orbit drops). Each writes its own files, whose bytes do not
/// depend on the thread count.
pub fn run_all(
    spec: &SweepSpec,
    out_dir: &Path,
    threads: Option<usize>,
    progress: bool,
) -> Result<ExtrasWritten, ExtrasError> {
    run_all_owned(spec, out_dir, threads, progress, false, |_| true)
}

/// [`run_all`] for a shard's part: the critical searches at positions `j` of `critical.mu`
/// and the orbit panels at positions `i` for which `owns` is true, and the probability
/// ensemble when `owns(0)` (it is one job). When more than one fails, the error reported is
/// the critical search's, then the orbits', then the ensemble's. With `resume` (a sweep's
/// `--resume` of the same spec and build), what the killed run finished is kept: the decided
/// rows of a `critical.json` with a row for every friction coefficient the run owns (its
/// undecided rows are searched again; without that file, the critical search's logged drops
/// are reused, [`crate::critical_log`]), each orbit file, and the ensemble's members
/// ([`crate::ensemble::run_ensemble`]); the rest runs.
pub fn run_all_owned(
    spec: &SweepSpec,
    out_dir: &Path,
    threads: Option<usize>,
    progress: bool,
    resume: bool,
    owns: impl Fn(usize) -> bool + Sync,
) -> Result<ExtrasWritten, ExtrasError> {
    let panels = orbit_panels(spec).map_or(0, |(_, mus)| mus.len());
    let ticker = Ticker::new(
        &format!("sweep {}: critical search and orbits", spec.name),
        panels,
        progress && (spec.critical.is_some() || panels > 0),
    );
    let work = || -> Result<_, ExtrasError> {
        let ((critical, orbits), probability) = rayon::join(
            || {
                let both = rayon::join(
                    || run_critical_ticked(spec, out_dir, &owns, &ticker, resume),
                    || record_orbits_ticked(spec, out_dir, &owns, &ticker, resume),
                );
                ticker.finish();
                both
            },
            || {
                if owns(0) {
                    run_probability_here(spec, out_dir, progress, resume)
                } else {
                    Ok(None)
                }
            },
        );
        Ok(ExtrasWritten {
            critical: critical?,
            orbits: orbits?,
            probability: probability?,
        })
    };
    match crate::pool::pool(threads) {
        Ok(pool) => pool.install(work),
        Err(_) => work(),
    }
}

/// Runs the spec's probability ensemble, if any, into `out_dir/probability/` on `threads`
/// worker threads (`None`: rayon's default).
pub fn run_probability(
    spec: &SweepSpec,
    out_dir: &Path,
    threads: Option<usize>,
    progress: bool,
) -> Result<Option<PathBuf>, ExtrasError> {
    let Some(e) = spec.probability_spec() else {
        return Ok(None);
    };
    let dir = out_dir.join(PROBABILITY_DIR);
    crate::ensemble::run_ensemble(&e, &dir, threads, progress, false)
        .map_err(ExtrasError::from_sweep)?;
    Ok(Some(dir))
}

/// [`run_probability`] on the current rayon pool.
fn run_probability_here(
    spec: &SweepSpec,
    out_dir: &Path,
    progress: bool,
    resume: bool,
) -> Result<Option<PathBuf>, ExtrasError> {
    let Some(e) = spec.probability_spec() else {
        return Ok(None);
    };
    let dir = out_dir.join(PROBABILITY_DIR);
    crate::ensemble::run_ensemble_here(&e, &dir, progress, resume)
        .map_err(ExtrasError::from_sweep)?;
    Ok(Some(dir))
}

pub use whirlmap_results::files::{
    CRITICAL_CSV_FILE, CRITICAL_DROPS_FILE, CRITICAL_FILE, PROBABILITY_DIR,
};

/// Runs the spec's `critical` section, if any, and writes `critical.json` (a list of
/// [`CriticalRow`] in the order of `critical.mu`) and `critical.csv`. Returns the JSON file.
pub fn run_critical(spec: &SweepSpec, out_dir: &Path) -> Result<Option<PathBuf>, ExtrasError> {
    run_critical_owned(spec, out_dir, |_| true)
}

/// [`run_critical`] for the friction coefficients whose position `j` in `critical.mu`
/// satisfies `owns(j)` (a shard's part; see [`crate::shard`]), in that order.
pub fn run_critical_owned(
    spec: &SweepSpec,
    out_dir: &Path,
    owns: impl Fn(usize) -> bool,
) -> Result<Option<PathBuf>, ExtrasError> {
    run_critical_ticked(spec, out_dir, owns, &Ticker::off(), false)
}

/// [`run_critical_owned`], counting its drops on `ticker`. With `critical.recheck`, each
/// searched row's bracket is re-checked at the next tighter preset ([`crate::recheck`]).
/// With `resume`, the decided rows of
/// a `critical.json` already in `out_dir` ([`kept_critical`]) are kept and only its undecided
/// rows run again (nothing runs when every row is decided); without one, the drops the killed
/// run logged ([`crate::critical_log`]) are not run again. The log is removed once
/// `critical.json` is written.
fn run_critical_ticked(
    spec: &SweepSpec,
    out_dir: &Path,
    owns: impl Fn(usize) -> bool,
    ticker: &Ticker,
    resume: bool,
) -> Result<Option<PathBuf>, ExtrasError> {
    let Some(c) = &spec.critical else {
        return Ok(None);
    };
    let mus: Vec<f64> = (c.mus().into_iter().enumerate())
        .filter(|(j, _)| owns(*j))
        .map(|(_, mu)| mu)
        .collect();
    let kept = resume.then(|| kept_critical(out_dir, &mus)).flatten();
    // The coefficients to search: all of them, or the kept file's undecided rows.
    let todo: Vec<f64> = match &kept {
        Some(rows) => rows.iter().filter(|r| r.undecided).map(|r| r.mu).collect(),
        None => mus.clone(),
    };
    if let (Some(rows), true) = (&kept, todo.is_empty()) {
        let written = write_critical(out_dir, rows)?;
        // A kill after the last run's critical.json and before its log was removed.
        remove_drop_log(out_dir)?;
        return Ok(written);
    }
    let rows = if todo.is_empty() {
        Vec::new()
    } else {
        let log = DropLog::open(out_dir, resume)?;
        // The spec was validated before anything ran, so this cannot fail.
        let mut rows = critical_rows_logged(
            &spec.base_scene(),
            &todo,
            &c.options(spec.duration_s),
            ticker,
            Some(&log),
        )
        .expect("the spec's critical section was validated");
        if let Some(tighter) = spec
            .fidelity
            .and_then(Fidelity::tighter)
            .filter(|_| c.recheck)
        {
            let opts = DropOptions {
                duration_s: spec.duration_s,
                ..Default::default()
            };
            let base = spec.base_scene();
            crate::recheck::recheck_rows(&base, &mut rows, tighter, &opts, None, Some(ticker));
        }
        if let Some(kept) = kept {
            // The searched rows take the undecided rows' places, in `mus`'s order.
            let mut searched = rows.into_iter();
            rows = kept
                .into_iter()
                .map(|r| {
                    if r.undecided {
                        searched.next().expect("one searched row per undecided row")
                    } else {
                        r
                    }
                })
                .collect();
        }
        let n = log.reused();
        // Through `progress_line`: a closed standard error must not panic the run.
        if n > 0 {
            crate::progress::progress_line(&format!(
                "sweep {}: critical search: {n} drop{} reused from the killed run's {}",
                spec.name,
                if n == 1 { "" } else { "s" },
                CRITICAL_DROPS_FILE
            ));
        }
        if let Some(warning) = log.finish() {
            crate::progress::progress_line(&format!("warning: {warning}"));
        }
        rows
    };
    let written = write_critical(out_dir, &rows)?;
    // The log served its purpose: `critical.json` holds the search now.
    remove_drop_log(out_dir)?;
    Ok(written)
}

/// Removes the critical search's drop log from `out_dir`, if there.
fn remove_drop_log(out_dir: &Path) -> Result<(), ExtrasError> {
    let log = out_dir.join(CRITICAL_DROPS_FILE);
    match std::fs::remove_file(&log) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(ExtrasError::Io {
            path: log,
            source: e,
        }),
        _ => Ok(()),
    }
}

/// The rows of the `critical.json` a killed run of the same spec and build left in `out_dir`,
/// when it has one row per friction coefficient of `mus`, in that order. Its undecided rows
/// (failed or unsettled drops) are run again by the caller, as a failed grid point is.
/// `critical.json` is written whole or not at all, so a file that is there is a finished
/// search.
fn kept_critical(out_dir: &Path, mus: &[f64]) -> Option<Vec<CriticalRow>> {
    let rows = whirlmap_results::critical::read_critical(out_dir).ok()??;
    let same_mus = rows.len() == mus.len()
        && rows
            .iter()
            .zip(mus)
            .all(|(r, mu)| r.mu.to_bits() == mu.to_bits());
    same_mus.then_some(rows)
}

/// Writes `rows` as `critical.json` and `critical.csv` in `out_dir`; returns the JSON file.
pub fn write_critical(
    out_dir: &Path,
    rows: &[CriticalRow],
) -> Result<Option<PathBuf>, ExtrasError> {
    let path = out_dir.join(CRITICAL_FILE);
    write(&path, &critical_json(rows))?;
    write(&out_dir.join(CRITICAL_CSV_FILE), &csv_text(rows))?;
    Ok(Some(path))
}

/// The Fig. 3 panels the spec asks for: its `orbits` section, or, when it lists the `orbits`
/// chart without one, 8000 r/min (the paper's) and the `mu` axis values (at most eight).
pub fn orbit_panels(spec: &SweepSpec) -> Option<(f64, Vec<f64>)> {
    if let Some(o) = &spec.orbits {
        return Some((o.speed_rpm, o.mu.clone()));
    }
    if !spec.charts.iter().any(|c| c == "orbits") {
        return None;
    }
    // The `mu` axis's values in axis order: the order in which the grid first meets them.
    let axis = spec.axes.0.iter().find(|a| a.name == "mu")?;
    let mut mus: Vec<f64> = Vec::new();
    for i in 0..axis.values.count() {
        let v = axis.values.value(i);
        if !mus.contains(&v) {
            mus.push(v);
        }
        if mus.len() == 8 {
            break;
        }
    }
    (!mus.is_empty()).then_some((8000.0, mus))
}

/// Records one orbit per panel (in parallel, order kept) and writes
/// `orbits/NN_speed_mu.json` files `{"speed_rpm", "mu", "class", "orbit"}`; a drop that fails
/// (a solver error or a panic) is skipped with its error in `orbits/NN_speed_mu.error.txt`.
/// Returns the files written.
pub fn record_orbits(spec: &SweepSpec, out_dir: &Path) -> Result<Vec<PathBuf>, ExtrasError> {
    record_orbits_owned(spec, out_dir, |_| true)
}

/// [`record_orbits`] for the panels whose position `i` satisfies `owns(i)` (a shard's part;
/// see [`crate::shard`]); file names keep the panel's position.
pub fn record_orbits_owned(
    spec: &SweepSpec,
    out_dir: &Path,
    owns: impl Fn(usize) -> bool,
) -> Result<Vec<PathBuf>, ExtrasError> {
    record_orbits_ticked(spec, out_dir, owns, &Ticker::off(), false)
}

/// [`record_orbits_owned`], counting its drops on `ticker`. With `resume`, a panel whose
/// orbit file is already in `out_dir` (written whole or not at all) is kept; a panel whose
/// drop failed runs again.
fn record_orbits_ticked(
    spec: &SweepSpec,
    out_dir: &Path,
    owns: impl Fn(usize) -> bool,
    ticker: &Ticker,
    resume: bool,
) -> Result<Vec<PathBuf>, ExtrasError> {
    let Some((speed, mus)) = orbit_panels(spec) else {
        return Ok(Vec::new());
    };
    let stem = |i: usize, mu: f64| format!("{i:02}_{speed:.0}rpm_mu{mu:.3}");
    let mut written = Vec::new();
    let mut panels: Vec<(usize, f64)> = Vec::new();
    for (i, mu) in mus.iter().copied().enumerate().filter(|(i, _)| owns(*i)) {
        let path = out_dir.join(ORBITS_DIR).join(orbit_file(&stem(i, mu)));
        if resume && path.is_file() {
            ticker.tick();
            written.push(path);
        } else {
            panels.push((i, mu));
        }
    }
    let runs: Vec<_> = panels
        .par_iter()
        .map(|&(i, mu)| {
            let mut scene = spec.base_scene();
            scene.speed_rpm = speed;
            scene.mu_dynamic = mu;
            let opts = DropOptions {
                duration_s: spec.duration_s,
                orbit_points: Some(20_000),
                ..Default::default()
            };
            let run = run_drop(&scene, &opts);
            ticker.tick();
            (i, mu, run)
        })
        .collect();
    for (i, mu, run) in runs {
        let stem = stem(i, mu);
        let error_file = out_dir.join(ORBITS_DIR).join(orbit_error_file(&stem));
        match run {
            // Drops asked for orbit points always record an orbit.
            Ok(r) if r.orbit.is_some() => {
                let orbit = r.orbit.expect("checked above");
                let doc = OrbitFile::new(speed, mu, r.verdict.class, orbit);
                let path = out_dir.join(ORBITS_DIR).join(orbit_file(&stem));
                write(&path, &doc.to_json())?;
                // A resumed panel that failed before and now has its orbit.
                if let Err(e) = std::fs::remove_file(&error_file) {
                    if e.kind() != std::io::ErrorKind::NotFound {
                        return Err(ExtrasError::Io {
                            path: error_file,
                            source: e,
                        });
                    }
                }
                written.push(path);
            }
            Ok(_) => write(&error_file, "no orbit was recorded\n")?,
            Err(e) => write(&error_file, &format!("{e}\n"))?,
        }
    }
    // Panel order, kept ones among them.
    written.sort();
    Ok(written)
}
