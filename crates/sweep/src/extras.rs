//! What a sweep spec asks for beside its grid: the critical-speed search (`critical.json`)
//! and the orbits of the Fig. 3 chart (`orbits/*.json`), in the forms [`crate::charts`] reads.

use crate::classify::{classify, ClassifyParams};
use crate::critical::critical_speeds;
use crate::spec::SweepSpec;
use rayon::prelude::*;
use serde_json::json;
use std::path::{Path, PathBuf};
use thiserror::Error;
use whirlmap_core::{simulate, DropOptions};

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

fn write(path: &Path, text: &str) -> Result<(), ExtrasError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|source| ExtrasError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    std::fs::write(path, text).map_err(|source| ExtrasError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Runs both extras on `threads` worker threads (rayon's default when `None`), as the grid
/// did: the critical search, then the orbits. Returns the files written.
#[allow(clippy::type_complexity)]
pub fn run_all(
    spec: &SweepSpec,
    out_dir: &Path,
    threads: Option<usize>,
) -> Result<(Option<PathBuf>, Vec<PathBuf>), ExtrasError> {
    run_all_owned(spec, out_dir, threads, |_| true)
}

/// [`run_all`] for a shard's part: the critical searches at positions `j` of `critical.mu`
/// and the orbit panels at positions `i` for which `owns` is true.
#[allow(clippy::type_complexity)]
pub fn run_all_owned(
    spec: &SweepSpec,
    out_dir: &Path,
    threads: Option<usize>,
    owns: impl Fn(usize) -> bool + Sync,
) -> Result<(Option<PathBuf>, Vec<PathBuf>), ExtrasError> {
    let work = || -> Result<_, ExtrasError> {
        Ok((
            run_critical_owned(spec, out_dir, &owns)?,
            record_orbits_owned(spec, out_dir, &owns)?,
        ))
    };
    match threads {
        Some(n) => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(work),
            Err(_) => work(),
        },
        None => work(),
    }
}

/// Runs the spec's `critical` section, if any, and writes `critical.json`: an array of
/// `{"mu", "result"}` in the order of `critical.mu`. Returns the file written.
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
    let Some(c) = &spec.critical else {
        return Ok(None);
    };
    let mus: Vec<f64> = (c.mu.iter().enumerate())
        .filter(|(j, _)| owns(*j))
        .map(|(_, mu)| *mu)
        .collect();
    let results = critical_speeds(
        &spec.base_scene(),
        &mus,
        c.speed_rpm.from,
        c.speed_rpm.to,
        c.tol_rpm,
        spec.duration_s,
    );
    let rows: Vec<_> = results
        .iter()
        .map(|(mu, r)| json!({"mu": mu, "result": r}))
        .collect();
    let path = out_dir.join("critical.json");
    write(
        &path,
        &serde_json::to_string_pretty(&rows).expect("results serialise"),
    )?;
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
    let points = spec.points().ok()?;
    let mut mus: Vec<f64> = Vec::new();
    for p in &points {
        for (name, v) in &p.inputs {
            if name == "mu" && !mus.contains(v) {
                mus.push(*v);
            }
        }
    }
    mus.truncate(8);
    (!mus.is_empty()).then_some((8000.0, mus))
}

/// Records one orbit per panel (in parallel, order kept) and writes
/// `orbits/NN_speed_mu.json` files `{"speed_rpm", "mu", "class", "orbit"}`; a drop that fails
/// is skipped with its error in `orbits/NN_speed_mu.error.txt`. Returns the files written.
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
    let Some((speed, mus)) = orbit_panels(spec) else {
        return Ok(Vec::new());
    };
    let panels: Vec<(usize, f64)> = mus
        .iter()
        .copied()
        .enumerate()
        .filter(|(i, _)| owns(*i))
        .collect();
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
            (i, mu, simulate(&scene, &opts))
        })
        .collect();
    let mut written = Vec::new();
    for (i, mu, run) in runs {
        let stem = format!("{i:02}_{speed:.0}rpm_mu{mu:.3}");
        match run {
            Ok(r) => {
                let class = classify(&r.features, r.stop_reason, &ClassifyParams::default());
                let doc = json!({"speed_rpm": speed, "mu": mu, "class": class, "orbit": r.orbit});
                let path = out_dir.join("orbits").join(format!("{stem}.json"));
                write(
                    &path,
                    &serde_json::to_string(&doc).expect("orbits serialise"),
                )?;
                written.push(path);
            }
            Err(e) => {
                let path = out_dir.join("orbits").join(format!("{stem}.error.txt"));
                write(&path, &format!("{e}\n"))?;
            }
        }
    }
    Ok(written)
}
