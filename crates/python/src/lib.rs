//! # whirlmap-python: the native module `whirlmap._whirlmap`
//!
//! The Python package `whirlmap` (`python/whirlmap/__init__.py`) is a thin typed layer over
//! these functions; call those, not these. Everything a drop, a search or a sweep does is the
//! Rust crates' own: the scene overrides are [`whirlmap_sweep::overrides::apply`], the
//! checks are the scene's, the options' and the spec's own validation (their messages name
//! the field, the value and the allowed range and become a Python `ValueError`), drops run
//! through [`whirlmap_sweep::run::run_drop`], critical searches through
//! [`whirlmap_sweep::critical::critical_rows`] and sweep points through
//! [`whirlmap_sweep::sweep::run_case`].
//!
//! Records cross the boundary as JSON text (parsed by the Python layer), so every field the
//! records gain reaches Python unchanged; time series cross as NumPy arrays. Every
//! simulation runs with the GIL released, so Python threads run drops concurrently; a
//! search and a sweep stop at Ctrl-C (the drops not yet started are skipped, through
//! [`whirlmap_sweep::cancel`]).
#![warn(missing_docs)]

use numpy::IntoPyArray;
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::time::Duration;
use whirlmap_core::{DropOptions, Fidelity, Scene, MODEL_VERSION};
use whirlmap_sweep::cancel::Cancel;
use whirlmap_sweep::critical::{check_mus, critical_rows_cancellable, CriticalOptions};
use whirlmap_sweep::overrides::apply_assignment;
use whirlmap_sweep::recheck::recheck_rows;
use whirlmap_sweep::record::DropRecord;
use whirlmap_sweep::run::{run_drop, DropFailure};
use whirlmap_sweep::spec::{self, SweepSpec};
use whirlmap_sweep::sweep::run_case;

// Named `whirlmap.SimulationError`, where the package exports it, so that pickle (and with it
// multiprocessing and joblib) finds the class again.
pyo3::create_exception!(
    whirlmap,
    SimulationError,
    PyRuntimeError,
    "A drop could not be integrated to its end: a typed solver error (its kind and the \
     simulated time of the failure are in the message)."
);

/// A spec file that cannot be read: an `OSError` with the errno, the message and the path,
/// which Python turns into its subclass (`FileNotFoundError` for a missing file,
/// `PermissionError`, ...); any other spec error: a `ValueError`.
fn spec_error(e: spec::SpecError) -> PyErr {
    match &e {
        // Python's message then reads `[Errno 2] cannot read sweep spec (entity not found):
        // 'path'`. A file that is not text (no errno) is bad input: a ValueError.
        spec::SpecError::Read { path, source } if source.raw_os_error().is_some() => {
            PyOSError::new_err((
                source.raw_os_error(),
                format!("cannot read sweep spec ({})", source.kind()),
                path.display().to_string(),
            ))
        }
        _ => value_error(e),
    }
}

/// A `ValueError` with `e`'s message.
fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A `SimulationError` for a failed drop, worded as the command line words it.
fn simulation_error(e: DropFailure) -> PyErr {
    SimulationError::new_err(format!("simulation failed ({}): {e}", e.kind()))
}

use whirlmap_sweep::pool::MAX_THREADS;

/// Runs `work` on its own thread, in `pool`, with the GIL released, while the calling thread
/// checks for a signal (Ctrl-C, a notebook's "interrupt kernel") every tenth of a second.
/// On an interrupt, `cancel` is raised, so the drops not yet started are skipped; the call
/// waits for the running ones and raises `KeyboardInterrupt` with `interrupted(n)` as its
/// message, `n` the drops counted on `cancel`. Any other exception from a signal handler (a
/// subclass of `KeyboardInterrupt` too) stops the work the same way and is raised as it is.
/// A call from another thread than Python's main one is never interrupted (signals reach
/// only the main thread).
fn interruptible<T: Send>(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    cancel: &Cancel,
    interrupted: impl Fn(usize) -> String,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    std::thread::scope(|scope| {
        let (done_tx, done_rx) = std::sync::mpsc::channel();
        let worker = scope.spawn(move || {
            let out = pool.install(work);
            // The receiver lives until the worker is joined.
            let _ = done_tx.send(());
            out
        });
        let join = |w: std::thread::ScopedJoinHandle<'_, T>| {
            w.join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        };
        let mut done_rx = done_rx;
        loop {
            // Moved in and back out: a `Receiver` is `Send`, not `Sync`.
            let (wait, rx) = py.detach(move || {
                let wait = done_rx.recv_timeout(Duration::from_millis(100));
                (wait, done_rx)
            });
            done_rx = rx;
            // Disconnected: the worker ended without sending (a panic, raised by the join).
            if !matches!(wait, Err(std::sync::mpsc::RecvTimeoutError::Timeout)) {
                return Ok(py.detach(|| join(worker)));
            }
            if let Err(e) = py.check_signals() {
                cancel.request();
                py.detach(|| join(worker));
                if !e.get_type(py).is(py.get_type::<PyKeyboardInterrupt>()) {
                    return Err(e);
                }
                return Err(PyKeyboardInterrupt::new_err(interrupted(
                    cancel.drops_run(),
                )));
            }
        }
    })
}

/// The rayon pool for `threads` (`None`: rayon's default, which reads `RAYON_NUM_THREADS`).
/// More than [`MAX_THREADS`], asked or from the environment, is refused: the pool is built
/// before any drop, and a million threads never finished starting.
fn pool(threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    if let Some(n) = threads.filter(|n| !(1..=MAX_THREADS).contains(n)) {
        return Err(value_error(format!(
            "invalid threads = {n}: allowed [1, {MAX_THREADS}] (or None)"
        )));
    }
    if let Some(e) = threads
        .is_none()
        .then(whirlmap_sweep::pool::env_threads_beyond_range)
        .flatten()
    {
        return Err(value_error(format!("{e}, or pass threads")));
    }
    whirlmap_sweep::pool::pool(threads).map_err(|e| value_error(format!("threads: {e}")))
}

/// The paper's scene with `overrides` applied in order, each `(key, value as JSON text)`,
/// exactly as `--set key=value` applies it: a value that is not JSON is taken as a string,
/// and `NaN` or `Infinity` is refused with the field's range. An override error names the key
/// and the value.
fn scene_with(overrides: &[(String, String)]) -> PyResult<Scene> {
    let mut scene = Scene::paper();
    for (key, text) in overrides {
        apply_assignment(&mut scene, &format!("{key}={text}"))
            .map_err(|e| value_error(format!("{key}={text}: {e}")))?;
    }
    Ok(scene)
}

/// A fidelity preset by name, or `None`.
fn fidelity(name: Option<&str>) -> PyResult<Option<Fidelity>> {
    name.map(|n| Fidelity::parse(n).map_err(value_error))
        .transpose()
}

/// The default (paper) scene as JSON text, every key an override may name, as
/// `whirlmap scene --all` prints it (the thermal model and the bearing analysis at their
/// defaults).
#[pyfunction]
fn default_scene() -> String {
    Scene::paper_every_field(true)
}

/// One drop, as `whirlmap drop` runs it: the paper's scene, the overrides, then `speed_rpm`
/// and `mu` (set as `mu_dynamic`), validated, then the fidelity preset. Returns the drop
/// record and the scene as JSON text, and, when `series_points` is given, the recorded time
/// series as a dict of NumPy arrays and the clearance (m).
#[pyfunction]
#[pyo3(signature = (speed_rpm, mu, duration_s, fidelity_name, series_points, overrides))]
#[pyo3(name = "drop")]
#[allow(clippy::type_complexity)]
fn drop_one<'py>(
    py: Python<'py>,
    speed_rpm: Option<f64>,
    mu: Option<f64>,
    duration_s: f64,
    fidelity_name: Option<String>,
    series_points: Option<usize>,
    overrides: Vec<(String, String)>,
) -> PyResult<(String, String, Option<Bound<'py, PyDict>>, f64)> {
    let mut scene = scene_with(&overrides)?;
    if let Some(v) = speed_rpm {
        scene.speed_rpm = v;
    }
    if let Some(v) = mu {
        scene.mu_dynamic = v;
    }
    scene.validate().map_err(value_error)?;
    if let Some(f) = fidelity(fidelity_name.as_deref())? {
        f.apply(&mut scene);
    }
    let opts = DropOptions {
        duration_s,
        orbit_points: series_points,
        ..Default::default()
    };
    opts.validate().map_err(value_error)?;
    let report = py
        .detach(|| run_drop(&scene, &opts))
        .map_err(simulation_error)?;
    let record =
        serde_json::to_string(&DropRecord::from_report(&report)).expect("records serialise");
    let scene_json = serde_json::to_string(&scene).expect("a scene serialises");
    let Some(orbit) = report.orbit.filter(|_| series_points.is_some()) else {
        return Ok((record, scene_json, None, scene.clearance_m));
    };
    let s = &orbit.samples;
    let column = |f: fn(&whirlmap_core::orbit::OrbitSample) -> f64| -> Vec<f64> {
        s.iter().map(f).collect()
    };
    let series = PyDict::new(py);
    let columns: [(&str, Vec<f64>); 12] = [
        ("t_s", column(|p| p.t_s)),
        ("x_rotor_m", column(|p| p.x_race_m + p.x_rel_m)),
        ("y_rotor_m", column(|p| p.y_race_m + p.y_rel_m)),
        ("x_race_m", column(|p| p.x_race_m)),
        ("y_race_m", column(|p| p.y_race_m)),
        ("x_rel_m", column(|p| p.x_rel_m)),
        ("y_rel_m", column(|p| p.y_rel_m)),
        ("contact_force_n", column(|p| p.contact_force_n)),
        ("slip_m_s", column(|p| p.slip_m_s)),
        ("heat_power_w", column(|p| p.heat_power_w)),
        ("rotor_speed_rad_s", column(|p| p.rotor_speed_rad_s)),
        ("race_speed_rad_s", column(|p| p.race_speed_rad_s)),
    ];
    for (name, values) in columns {
        series.set_item(name, values.into_pyarray(py))?;
    }
    Ok((record, scene_json, Some(series), orbit.clearance_m))
}

/// The critical speed of backward whirl for each friction coefficient in `mus`, as
/// `whirlmap critical` searches it (the same rows, as JSON text). Everything is checked
/// before any drop runs.
#[pyfunction]
#[pyo3(signature = (mus, from_rpm, to_rpm, resolution_rpm, tol_rpm, duration_s, fidelity_name, overrides, threads))]
#[allow(clippy::too_many_arguments)]
fn critical(
    py: Python<'_>,
    mus: Vec<f64>,
    from_rpm: f64,
    to_rpm: f64,
    resolution_rpm: f64,
    tol_rpm: f64,
    duration_s: f64,
    fidelity_name: Option<String>,
    overrides: Vec<(String, String)>,
    threads: Option<usize>,
) -> PyResult<String> {
    let opts = CriticalOptions {
        from_rpm,
        to_rpm,
        resolution_rpm,
        tol_rpm,
        duration_s,
    };
    opts.validate().map_err(value_error)?;
    check_mus(&mus).map_err(value_error)?;
    let mut base = scene_with(&overrides)?;
    base.validate().map_err(value_error)?;
    let preset = fidelity(fidelity_name.as_deref())?;
    if let Some(f) = preset {
        f.apply(&mut base);
    }
    // Each friction coefficient's scene, at the scene's speed and at the lowest speed
    // searched (a stop speed, say, must lie below every release speed), as the command line
    // checks them.
    for &mu in &mus {
        let mut s = base.clone();
        s.mu_dynamic = mu;
        s.validate()
            .map_err(|e| value_error(format!("with mu {mu}: {e}")))?;
        s.speed_rpm = from_rpm;
        s.validate().map_err(|e| {
            value_error(format!(
                "with mu {mu} at the lowest speed searched, from_rpm = {from_rpm}: {e}"
            ))
        })?;
    }
    let pool = pool(threads)?;
    let cancel = Cancel::new();
    let scan = mus.len() * opts.scan_speeds().len();
    let interrupted = |n| {
        format!(
            "critical search interrupted after {n} drops (its scan has {scan}, then \
             bisections and, with a fidelity preset, two re-check drops per onset and a window \
             search at the tighter preset for each onset they do not confirm); nothing is \
             returned"
        )
    };
    let rows = interruptible(py, &pool, &cancel, interrupted, || {
        let Some(mut rows) = critical_rows_cancellable(&base, &mus, &opts, &cancel)? else {
            return Ok(None);
        };
        if let Some(tighter) = preset.and_then(|f| f.tighter()) {
            let drop_opts = DropOptions {
                duration_s,
                ..Default::default()
            };
            recheck_rows(&base, &mut rows, tighter, &drop_opts, Some(&cancel), None);
            if cancel.requested() {
                return Ok(None);
            }
        }
        Ok::<_, whirlmap_core::InvalidParameter>(Some(rows))
    })?;
    // `None` only after a cancel, which `interruptible` has raised already.
    let rows = rows.map_err(value_error)?.unwrap_or_default();
    Ok(serde_json::to_string(&rows).expect("rows serialise"))
}

/// Runs the grid of a sweep spec in memory (nothing is written): the spec is JSON text, or
/// read from `path` when `text` is `None`. Every grid point's scene is checked before any
/// drop runs. Returns the points' records (the lines of a sweep's `points.jsonl`, in grid
/// order) as a JSON list. Only the grid runs: a spec's `critical`, `orbits`, `probability`
/// and `charts` sections are read and checked but not run.
#[pyfunction]
#[pyo3(signature = (text, path, threads))]
fn sweep(
    py: Python<'_>,
    text: Option<String>,
    path: Option<String>,
    threads: Option<usize>,
) -> PyResult<String> {
    let spec: SweepSpec = match (text, path) {
        (Some(t), _) => {
            let s = spec::parse(&t).map_err(|e| value_error(format!("sweep spec: {e}")))?;
            s.validate().map_err(value_error)?;
            s
        }
        (None, Some(p)) => spec::read(&p).map_err(spec_error)?,
        (None, None) => return Err(value_error("a sweep spec (text or path) is required")),
    };
    // Checking every point of a large grid takes seconds: without the GIL, so that the
    // caller's other threads run meanwhile.
    py.detach(|| spec.check_points()).map_err(value_error)?;
    let grid = spec.grid().map_err(value_error)?;
    let pool = pool(threads)?;
    let cancel = Cancel::new();
    let total = grid.len();
    let interrupted =
        |n| format!("sweep interrupted: {n} of {total} points had run; nothing is returned");
    let records = interruptible(py, &pool, &cancel, interrupted, || {
        (0..grid.len())
            .into_par_iter()
            .map(|i| {
                if cancel.requested() {
                    return None;
                }
                let point = grid.point(i).expect("every point was checked");
                let record = run_case(&point, spec.duration_s);
                cancel.count_drop();
                Some(record)
            })
            .collect::<Option<Vec<_>>>()
    })?;
    // `None` only after a cancel, which `interruptible` has raised already.
    let records = records.unwrap_or_default();
    Ok(serde_json::to_string(&records).expect("records serialise"))
}

/// The scene values of a sweep spec (JSON text) that its `fidelity` preset replaces, as
/// `(scene.solver.rtol, 1e-6)` pairs ([`spec::replaced_by_fidelity`]); empty when the text is
/// not JSON (the sweep itself then says why).
#[pyfunction]
fn replaced_by_fidelity(text: &str) -> Vec<(String, String)> {
    serde_json::from_str(whirlmap_core::json::without_bom(text))
        .map(|v| spec::replaced_by_fidelity(&v))
        .unwrap_or_default()
}

/// The native module: `drop`, `critical`, `sweep`, `replaced_by_fidelity`, `default_scene`,
/// `SimulationError`, `MODEL_VERSION` and `PRESET_KEYS` (the scene keys a fidelity preset
/// sets).
#[pymodule]
fn _whirlmap(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(drop_one, m)?)?;
    m.add_function(wrap_pyfunction!(critical, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(replaced_by_fidelity, m)?)?;
    m.add_function(wrap_pyfunction!(default_scene, m)?)?;
    m.add("SimulationError", m.py().get_type::<SimulationError>())?;
    m.add("MODEL_VERSION", MODEL_VERSION)?;
    m.add("PRESET_KEYS", Fidelity::KEYS.to_vec())?;
    Ok(())
}
