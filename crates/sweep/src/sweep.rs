//! The sweep engine: run every grid point of a [`SweepSpec`] in parallel and write
//! `points.jsonl`, `timings.jsonl`, `summary.csv` and `manifest.json` to the output folder.
//!
//! ## Records
//! `points.jsonl` holds one JSON object per line per grid point ([`PointRecord`]), in grid
//! order. Its bytes depend only on the spec: identical for any thread count (wall times go
//! to `timings.jsonl`).
//!
//! ## Crash safety and resume
//! The grid runs in chunks of `4 x threads` points; within a chunk points run in parallel and
//! their lines are appended in grid order and flushed when the chunk ends, each line with a
//! single `write_all`. A kill loses at most the chunk in flight. `resume` reads the existing
//! file, drops a torn last line (truncating the file back to the last complete line), skips
//! points recorded `ok`, re-runs failed ones, and at the end rewrites the file in grid order
//! with one line per point, so it is byte-identical to an uninterrupted run.

use crate::record::DropRecord;
use crate::spec::{check_output_dir, Point, SpecError, SweepSpec};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use serde::ser::{SerializeMap, Serializer};
use serde::Serialize;
use serde_json::Value;
use std::collections::{BTreeMap, HashMap};
use std::fs::OpenOptions;
use std::io::{IsTerminal, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};
use thiserror::Error;
use whirlmap_core::scene::fnv1a64;
use whirlmap_core::{simulate, DropOptions, Scene, MODEL_VERSION};

/// Records file name.
pub const POINTS_FILE: &str = "points.jsonl";
/// Per-point wall times.
pub const TIMINGS_FILE: &str = "timings.jsonl";
/// One row per point.
pub const SUMMARY_FILE: &str = "summary.csv";
/// Run metadata.
pub const MANIFEST_FILE: &str = "manifest.json";

/// Why a sweep could not run or write its outputs (failed points are not errors).
#[derive(Debug, Error)]
pub enum SweepError {
    /// The spec or the output folder is unusable (nothing was run).
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// The thread pool could not be built.
    #[error("cannot build a thread pool: {0}")]
    ThreadPool(String),
    /// An output file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

pub(crate) fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> SweepError + '_ {
    move |source| SweepError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Outcome of one point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The drop ran to its end.
    Ok,
    /// The drop failed; see `error`.
    Failed,
}

/// A failed point's error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointError {
    /// Machine-readable kind (`SolveError::kind`, or `panic`).
    pub kind: String,
    /// Human-readable message.
    pub message: String,
}

/// Axis name -> value in the spec's axis order; serialises as a JSON object in that order.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs(pub Vec<(String, f64)>);

impl Serialize for Inputs {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

/// One line of `points.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointRecord {
    /// [`point_key`]: 16 hex digits.
    pub key: String,
    /// Grid index.
    pub index: usize,
    /// Axis values.
    pub inputs: Inputs,
    /// `Scene::hash_hex` of the point's scene.
    pub scene_hash: String,
    /// Simulated time asked for (s).
    pub duration_s: f64,
    /// `whirlmap_core::MODEL_VERSION`.
    pub model_version: u32,
    /// `ok` or `failed`.
    pub status: Status,
    /// The drop record when ok.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record: Option<DropRecord>,
    /// The error when failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<PointError>,
    /// Wall time of the drop (s). Not in `points.jsonl` (it would break byte-identity across
    /// runs); written to `timings.jsonl`.
    #[serde(skip)]
    pub wall_time_s: f64,
}

impl PointRecord {
    /// The line written to `points.jsonl` (without the newline).
    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("records serialise")
    }
}

/// The record key: FNV-1a 64 of the canonical JSON of `(scene, duration_s, MODEL_VERSION)`,
/// as 16 hex digits.
pub fn point_key(scene: &Scene, duration_s: f64) -> String {
    let text =
        serde_json::to_string(&(scene, duration_s, MODEL_VERSION)).expect("scenes serialise");
    format!("{:016x}", fnv1a64(text.as_bytes()))
}

/// Runs one point. Never panics: a solver error or a panic inside the solver is recorded as
/// a failed point.
pub fn run_case(point: &Point, duration_s: f64) -> PointRecord {
    let start = Instant::now();
    let opts = DropOptions {
        duration_s,
        ..Default::default()
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        simulate(&point.scene, &opts).map(|r| DropRecord::from_report(&r))
    }));
    let (status, record, error) = match result {
        Ok(Ok(rec)) => (Status::Ok, Some(rec), None),
        Ok(Err(e)) => (
            Status::Failed,
            None,
            Some(PointError {
                kind: e.kind().to_string(),
                message: e.to_string(),
            }),
        ),
        Err(payload) => {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".to_string());
            (
                Status::Failed,
                None,
                Some(PointError {
                    kind: "panic".into(),
                    message,
                }),
            )
        }
    };
    PointRecord {
        key: point_key(&point.scene, duration_s),
        index: point.index,
        inputs: Inputs(point.inputs.clone()),
        scene_hash: point.scene.hash_hex(),
        duration_s,
        model_version: MODEL_VERSION,
        status,
        record,
        error,
        wall_time_s: start.elapsed().as_secs_f64(),
    }
}

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// A bar on a terminal, a plain line every ~5 s otherwise.
    Auto,
    /// Nothing.
    Off,
}

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Output folder.
    pub out_dir: PathBuf,
    /// Worker threads (`None`: rayon's default).
    pub threads: Option<usize>,
    /// Keep `ok` points of an existing `points.jsonl`.
    pub resume: bool,
    /// Progress display.
    pub progress: ProgressMode,
}

/// What a sweep did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepOutcome {
    /// Grid points.
    pub points: usize,
    /// Points recorded ok (resumed included).
    pub ok: usize,
    /// Points recorded failed.
    pub failed: usize,
    /// Points skipped because a resumed file had them ok.
    pub skipped: usize,
    /// Class name -> count over the ok points.
    pub classes: BTreeMap<String, usize>,
    /// The output folder.
    pub out_dir: PathBuf,
}

#[derive(Serialize)]
struct Manifest<'a> {
    spec: &'a SweepSpec,
    whirlmap_version: &'static str,
    model_version: u32,
    /// The commit the binary was built from ([`crate::build_info::GIT_COMMIT`]), not the
    /// HEAD of the repository the command runs in.
    git_commit: Option<String>,
    started_unix_s: f64,
    ended_unix_s: f64,
    threads: usize,
    counts: Counts,
    classes: &'a BTreeMap<String, usize>,
    /// A shard run's part of the grid (`crate::shard`); absent for a whole run.
    #[serde(skip_serializing_if = "Option::is_none")]
    shard: Option<Value>,
    /// The shards a merged result was made from (`crate::merge`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    merged_from: Option<Value>,
}

#[derive(Serialize)]
struct Counts {
    points: usize,
    ok: usize,
    failed: usize,
    skipped: usize,
}

pub(crate) fn unix_now() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// Progress reporting: an indicatif bar on a terminal, else a plain line every ~5 s.
struct Progress {
    name: String,
    total: usize,
    bar: Option<ProgressBar>,
    plain: bool,
    done: AtomicUsize,
    failed: AtomicUsize,
    start_done: usize,
    start: Instant,
    last_line: Mutex<Instant>,
}

const PLAIN_EVERY: Duration = Duration::from_secs(5);

/// Writes a progress line to standard error; a closed standard error is ignored (progress is
/// not the result, and `eprintln!` would panic).
pub fn progress_line(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

impl Progress {
    fn new(name: &str, total: usize, already: usize, mode: ProgressMode) -> Self {
        let on = mode == ProgressMode::Auto;
        let tty = std::io::stderr().is_terminal();
        // The bar counts this run's points only, so its rate and ETA are not skewed by
        // points taken over from a resumed file.
        let bar = (on && tty).then(|| {
            let b = ProgressBar::with_draw_target(
                Some((total - already) as u64),
                ProgressDrawTarget::stderr(),
            );
            b.set_style(
                ProgressStyle::with_template(
                    "sweep {msg} [{bar:40}] {pos}/{len} points, {per_sec}, ETA {eta}",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            if already > 0 {
                b.set_message(format!("{name} ({already} resumed)"));
            } else {
                b.set_message(name.to_string());
            }
            b
        });
        Self {
            name: name.to_string(),
            total,
            bar,
            plain: on && !tty,
            done: AtomicUsize::new(already),
            failed: AtomicUsize::new(0),
            start_done: already,
            start: Instant::now(),
            last_line: Mutex::new(Instant::now()),
        }
    }

    fn point_done(&self, failed: bool) {
        self.done.fetch_add(1, Ordering::Relaxed);
        if failed {
            self.failed.fetch_add(1, Ordering::Relaxed);
        }
        if let Some(b) = &self.bar {
            b.inc(1);
        }
        if self.plain {
            let mut last = self.last_line.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= PLAIN_EVERY {
                *last = Instant::now();
                progress_line(&self.line());
            }
        }
    }

    fn line(&self) -> String {
        let done = self.done.load(Ordering::Relaxed);
        let failed = self.failed.load(Ordering::Relaxed);
        let elapsed = self.start.elapsed().as_secs_f64();
        let rate = (done - self.start_done) as f64 / elapsed.max(1e-9);
        let eta = if rate > 0.0 {
            format!("{:.0} s", (self.total - done) as f64 / rate)
        } else {
            "unknown".to_string()
        };
        format!(
            "sweep {}: {done}/{} points, {failed} failed, {rate:.1} points/s, ETA {eta}",
            self.name, self.total
        )
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        if self.plain && self.start.elapsed() >= PLAIN_EVERY {
            progress_line(&self.line());
        }
    }
}

/// A recorded line of an existing `points.jsonl`: its status and its text.
struct Existing {
    ok: bool,
    line: String,
}

/// Reads `path`, drops a torn last line (truncating the file back to the last complete
/// line) and returns key -> latest record. Lines that do not parse are ignored.
fn read_existing(path: &Path) -> Result<HashMap<String, Existing>, SweepError> {
    let mut map = HashMap::new();
    let mut file = match OpenOptions::new().read(true).write(true).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(map),
        Err(e) => return Err(io_err(path)(e)),
    };
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes).map_err(io_err(path))?;
    let complete = bytes.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
    if complete < bytes.len() {
        file.set_len(complete as u64).map_err(io_err(path))?;
        file.sync_all().map_err(io_err(path))?;
    }
    for line in bytes[..complete].split(|b| *b == b'\n') {
        let Ok(text) = std::str::from_utf8(line) else {
            continue;
        };
        let Ok(v) = serde_json::from_str::<Value>(text) else {
            continue;
        };
        let (Some(key), Some(status)) = (
            v.get("key").and_then(Value::as_str),
            v.get("status").and_then(Value::as_str),
        ) else {
            continue;
        };
        map.insert(
            key.to_string(),
            Existing {
                ok: status == "ok",
                line: text.to_string(),
            },
        );
    }
    Ok(map)
}

/// Reads the records of a `points.jsonl` as JSON values, skipping a torn or corrupt line
/// (for charts and tools).
pub fn read_points(path: &Path) -> std::io::Result<Vec<Value>> {
    let text = std::fs::read_to_string(path)?;
    Ok(text
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect())
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn json_cell(v: Option<&Value>) -> String {
    match v {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => csv_field(s),
        Some(other) => csv_field(&other.to_string()),
    }
}

const SUMMARY_FIELDS: &[&str] = &[
    "class",
    "first_contact_force_n",
    "max_contact_force_n",
    "peak_friction_power_w",
    "peak_heat_power_w",
    "whirl_frequency_hz",
    "contact_duty",
    "impacts",
    "end_time_s",
];

fn write_summary(path: &Path, points: &[Point], lines: &[Value]) -> Result<(), SweepError> {
    let mut out = String::new();
    let mut header = vec!["index".to_string()];
    if let Some(p) = points.first() {
        header.extend(p.inputs.iter().map(|(k, _)| csv_field(k)));
    }
    header.extend(SUMMARY_FIELDS.iter().map(|s| s.to_string()));
    header.extend(["status".to_string(), "error".to_string()]);
    out.push_str(&header.join(","));
    out.push('\n');
    for (p, v) in points.iter().zip(lines) {
        let mut row = vec![p.index.to_string()];
        row.extend(
            p.inputs
                .iter()
                .map(|(_, x)| json_cell(Some(&Value::from(*x)))),
        );
        let rec = v.get("record");
        for f in SUMMARY_FIELDS {
            row.push(json_cell(rec.and_then(|r| r.get(*f))));
        }
        row.push(json_cell(v.get("status")));
        row.push(json_cell(v.get("error").and_then(|e| e.get("message"))));
        out.push_str(&row.join(","));
        out.push('\n');
    }
    std::fs::write(path, out).map_err(io_err(path))
}

pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), SweepError> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, bytes).map_err(io_err(&tmp))?;
    std::fs::rename(&tmp, path).map_err(io_err(path))
}

/// Run facts for the manifest beside the spec and the counts.
pub(crate) struct RunMeta {
    pub git_commit: Option<String>,
    pub started_unix_s: f64,
    pub ended_unix_s: f64,
    pub threads: usize,
    pub skipped: usize,
    pub shard: Option<Value>,
    pub merged_from: Option<Value>,
}

/// Writes `summary.csv` and `manifest.json` for `points` whose `points.jsonl` lines are
/// `lines` (same order; an empty line for a point without a record). Returns (ok, failed,
/// class counts).
pub(crate) fn write_summary_and_manifest(
    spec: &SweepSpec,
    out: &Path,
    points: &[Point],
    lines: &[&str],
    meta: RunMeta,
) -> Result<(usize, usize, BTreeMap<String, usize>), SweepError> {
    let values: Vec<Value> = lines
        .iter()
        .map(|l| serde_json::from_str(l).unwrap_or(Value::Null))
        .collect();
    let mut classes = BTreeMap::new();
    let mut ok = 0;
    for v in &values {
        if v.get("status").and_then(Value::as_str) == Some("ok") {
            ok += 1;
            if let Some(c) = v
                .get("record")
                .and_then(|r| r.get("class"))
                .and_then(Value::as_str)
            {
                *classes.entry(c.to_string()).or_insert(0) += 1;
            }
        }
    }
    let failed = points.len() - ok;
    write_summary(&out.join(SUMMARY_FILE), points, &values)?;
    let manifest = Manifest {
        spec,
        whirlmap_version: crate::build_info::VERSION,
        model_version: MODEL_VERSION,
        git_commit: meta.git_commit,
        started_unix_s: meta.started_unix_s,
        ended_unix_s: meta.ended_unix_s,
        threads: meta.threads,
        counts: Counts {
            points: points.len(),
            ok,
            failed,
            skipped: meta.skipped,
        },
        classes: &classes,
        shard: meta.shard,
        merged_from: meta.merged_from,
    };
    let text = serde_json::to_string_pretty(&manifest).expect("manifest serialises");
    write_atomic(&out.join(MANIFEST_FILE), format!("{text}\n").as_bytes())?;
    Ok((ok, failed, classes))
}

/// Runs the sweep and writes its outputs. Failed points are recorded, not errors; errors
/// are an unusable spec or output folder (before anything runs) or an I/O failure.
pub fn run_sweep(spec: &SweepSpec, opts: &RunOptions) -> Result<SweepOutcome, SweepError> {
    run_sweep_part(spec, opts, None)
}

/// [`run_sweep`] over the grid points a shard owns (all of them for `None`); the manifest
/// then names the shard. See [`crate::shard`].
pub fn run_sweep_part(
    spec: &SweepSpec,
    opts: &RunOptions,
    shard: Option<&crate::shard::Shard>,
) -> Result<SweepOutcome, SweepError> {
    let started = unix_now();
    let mut points = spec.points()?;
    if let Some(sh) = shard {
        points.retain(|p| sh.owns(p.index));
    }
    let out = &opts.out_dir;
    check_output_dir(out)?;
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = opts.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| SweepError::ThreadPool(e.to_string()))?;
    let threads = pool.current_num_threads();

    let points_path = out.join(POINTS_FILE);
    let timings_path = out.join(TIMINGS_FILE);
    let mut existing = if opts.resume {
        read_existing(&points_path)?
    } else {
        HashMap::new()
    };
    let keys: Vec<String> = points
        .iter()
        .map(|p| point_key(&p.scene, spec.duration_s))
        .collect();
    let todo: Vec<&Point> = points
        .iter()
        .zip(&keys)
        .filter(|(_, k)| !existing.get(*k).is_some_and(|e| e.ok))
        .map(|(p, _)| p)
        .collect();
    let skipped = points.len() - todo.len();

    let mut points_file = OpenOptions::new()
        .create(true)
        .append(opts.resume)
        .write(true)
        .truncate(!opts.resume)
        .open(&points_path)
        .map_err(io_err(&points_path))?;
    if opts.resume {
        points_file
            .seek(SeekFrom::End(0))
            .map_err(io_err(&points_path))?;
    }
    let mut timings_file = OpenOptions::new()
        .create(true)
        .append(opts.resume)
        .write(true)
        .truncate(!opts.resume)
        .open(&timings_path)
        .map_err(io_err(&timings_path))?;

    let progress = Progress::new(&spec.name, points.len(), skipped, opts.progress);
    let chunk = (4 * threads).max(1);
    let duration = spec.duration_s;
    for batch in todo.chunks(chunk) {
        let records: Vec<PointRecord> = pool.install(|| {
            batch
                .par_iter()
                .map(|p| {
                    let r = run_case(p, duration);
                    progress.point_done(r.status == Status::Failed);
                    r
                })
                .collect()
        });
        for r in &records {
            let line = r.to_line();
            points_file
                .write_all(format!("{line}\n").as_bytes())
                .map_err(io_err(&points_path))?;
            let t =
                serde_json::json!({"key": r.key, "index": r.index, "wall_time_s": r.wall_time_s});
            timings_file
                .write_all(format!("{t}\n").as_bytes())
                .map_err(io_err(&timings_path))?;
            existing.insert(
                r.key.clone(),
                Existing {
                    ok: r.status == Status::Ok,
                    line,
                },
            );
        }
        points_file.flush().map_err(io_err(&points_path))?;
        timings_file.flush().map_err(io_err(&timings_path))?;
    }
    progress.finish();
    drop(points_file);
    drop(timings_file);

    // One line per point in grid order.
    let lines: Vec<&str> = keys
        .iter()
        .map(|k| existing.get(k).map(|e| e.line.as_str()).unwrap_or(""))
        .collect();
    if opts.resume {
        let mut text = String::new();
        for l in &lines {
            text.push_str(l);
            text.push('\n');
        }
        write_atomic(&points_path, text.as_bytes())?;
    }

    let meta = RunMeta {
        git_commit: Some(crate::build_info::GIT_COMMIT.to_string()),
        started_unix_s: started,
        ended_unix_s: unix_now(),
        threads,
        skipped,
        shard: shard.map(|s| s.manifest_tag()),
        merged_from: None,
    };
    let (ok, failed, classes) = write_summary_and_manifest(spec, out, &points, &lines, meta)?;
    Ok(SweepOutcome {
        points: points.len(),
        ok,
        failed,
        skipped,
        classes,
        out_dir: out.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(scene: Scene) -> Point {
        Point {
            index: 3,
            inputs: vec![("mu".into(), scene.mu_dynamic)],
            scene,
        }
    }

    #[test]
    fn keys_are_stable_hex_and_depend_on_scene_and_duration() {
        let s = Scene::paper();
        let k = point_key(&s, 0.05);
        assert_eq!(k.len(), 16);
        assert_eq!(k, point_key(&s.clone(), 0.05));
        assert_ne!(k, point_key(&s, 0.06));
        let mut t = s.clone();
        t.mu_dynamic = 0.2;
        assert_ne!(k, point_key(&t, 0.05));
    }

    #[test]
    fn run_case_records_failures_as_data() {
        let mut s = Scene::paper();
        s.solver.max_step_attempts = 10;
        let r = run_case(&point(s), 0.01);
        assert_eq!(r.status, Status::Failed);
        assert_eq!(r.error.as_ref().unwrap().kind, "step_budget");
        assert!(r.record.is_none());
        let line = r.to_line();
        assert!(line.contains("\"status\":\"failed\"") && !line.contains("wall_time_s"));
        let r = run_case(&point(Scene::paper()), 0.01);
        assert_eq!(r.status, Status::Ok, "{:?}", r.error);
        assert!(r.to_line().starts_with(&format!(
            "{{\"key\":\"{}\",\"index\":3,\"inputs\":{{\"mu\":0.1}}",
            r.key
        )));
    }

    #[test]
    fn torn_last_line_is_dropped_and_truncated() {
        let dir = std::env::temp_dir().join(format!("whirlmap-sweep-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("points.jsonl");
        std::fs::write(
            &p,
            "{\"key\":\"a\",\"status\":\"ok\"}\n{\"key\":\"b\",\"status\":\"failed\"}\n{\"key\":\"b\",\"status\":\"ok\"}\n{\"key\":\"c\",\"sta",
        )
        .unwrap();
        let m = read_existing(&p).unwrap();
        assert_eq!(m.len(), 2);
        assert!(m["a"].ok && m["b"].ok, "the newer record wins");
        assert!(std::fs::read_to_string(&p).unwrap().ends_with("\"ok\"}\n"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
