//! The sweep engine: run every grid point of a [`SweepSpec`] in parallel and write
//! `points.jsonl`, `timings.jsonl`, `summary.csv` and `manifest.json` to the output folder.
//!
//! ## Records
//! `points.jsonl` holds one JSON object per line per grid point ([`PointRecord`]), in grid
//! order. Its bytes depend only on the spec: identical for any thread count (wall times go
//! to `timings.jsonl`).
//!
//! ## Parallel runs, records in grid order
//! The owned points of the grid (all of them, or a shard's) run by work stealing
//! ([`crate::ordered`]): each of the pool's threads takes the next point not yet taken when
//! it is free, so a slow point holds up only its own thread, never a batch. The calling thread
//! is the writer: it keeps the records that finish early in a reorder buffer and appends every
//! contiguous run of them to `points.jsonl` and `timings.jsonl` in grid order, so the file is
//! the same for any thread count. Workers run at most `16 x threads` points ahead of the first
//! point not yet written, which bounds the buffer however slow one point is.
//!
//! ## Crash safety and resume
//! Each run of records is appended with a single `write_all` per file and flushed at once; a
//! kill loses only the points in flight and those done but waiting in the reorder buffer
//! behind a slower one (at most `16 x threads`). `points.jsonl` is synced to disk (`fsync`) as
//! soon as its first records are written, then at most a second apart while records come in
//! (and a second after the last one when no more come), and at the end: a power loss loses at
//! most the last second's records. `resume` reads the existing file, drops a torn last line
//! (truncating the file back to the last complete line), skips points recorded `ok` at their
//! grid index, re-runs failed ones, and at the end rewrites the file in grid order with one
//! line per point, so it is byte-identical to an uninterrupted run.
//!
//! ## The folder
//! A run takes the folder's lock, refuses a folder holding another run's files unless told
//! to resume (the same spec and build only) or overwrite, and lists every file it writes in
//! `manifest.json` ([`crate::folder`]). An overwritten run's files are deleted once the new
//! run's first records are synced.
//!
//! ## Memory
//! Grid points are built from their index when a worker takes them ([`crate::spec::Grid`]);
//! nothing the size of the grid is held but, on a resume, the records read back and those
//! written since.

use crate::folder::{self, Mode, RunFolder, RunIdentity};
use crate::ordered::{run_ordered, OrderedSink};
use crate::record::DropRecord;
use crate::run::{catch_drop, DropFailure};
use crate::spec::{Grid, Point, SpecError, SweepSpec};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};
use std::fs::{File, OpenOptions};
use std::io::{BufRead, IsTerminal, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};
use thiserror::Error;
use whirlmap_core::scene::fnv1a64;
use whirlmap_core::{simulate, DropOptions, Scene, MODEL_VERSION};
use whirlmap_results::manifest::{Manifest, MergedShard, ShardTag, TimingRow};
use whirlmap_results::point::PointLine;
use whirlmap_results::summary::{SummaryRow, SummarySource};

pub use whirlmap_results::files::{
    BEARING_REPORT_FILE, MANIFEST_FILE, POINTS_FILE, SUMMARY_FILE, TIMINGS_FILE,
};

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
    /// The output folder may not be written as asked: another process writes it, it holds
    /// another run's results, or a resume does not match what it holds. Nothing was run.
    #[error("{0}")]
    Refused(String),
}

impl SweepError {
    /// The process exit code: 2 for a bad spec, option or output folder (nothing run), 4
    /// when an output could not be written (a full disk included).
    pub fn exit_code(&self) -> u8 {
        match self {
            SweepError::Spec(_) | SweepError::ThreadPool(_) | SweepError::Refused(_) => 2,
            SweepError::Io { .. } => 4,
        }
    }
}

impl From<whirlmap_results::WriteError> for SweepError {
    fn from(e: whirlmap_results::WriteError) -> Self {
        SweepError::Io {
            path: e.path,
            source: e.source,
        }
    }
}

pub(crate) fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> SweepError + '_ {
    move |source| SweepError::Io {
        path: path.to_path_buf(),
        source,
    }
}

pub use whirlmap_results::point::{Inputs, PointError, PointRecord, Status};

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
    let result = catch_drop(|| simulate(&point.scene, &opts).map(|r| DropRecord::from_report(&r)));
    let (status, record, error) = match result {
        Ok(rec) => (Status::Ok, Some(rec), None),
        Err(e) => {
            let kind = e.kind().to_string();
            let message = match e {
                DropFailure::Solve(e) => e.to_string(),
                // The bare panic message: the kind already says it was a panic.
                DropFailure::Panic(m) => m,
            };
            (Status::Failed, None, Some(PointError { kind, message }))
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
    /// Continue the run recorded in the folder (the same spec, part and build), keeping its
    /// `ok` points.
    pub resume: bool,
    /// Replace the run recorded in the folder (its files are moved to
    /// [`folder::PREVIOUS_DIR`] until the first records are written and synced).
    pub overwrite: bool,
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

pub(crate) use whirlmap_results::manifest::Counts;

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
    clock: PlainClock,
}

pub use crate::progress::progress_line;
use crate::progress::{PlainClock, PLAIN_EVERY};

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
            clock: PlainClock::new(),
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
        if self.plain && self.clock.due() {
            progress_line(&self.line());
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

/// A recorded line of an existing `points.jsonl`: its grid index, status and text.
struct Existing {
    index: Option<u64>,
    ok: bool,
    line: String,
    /// The line's `inputs`, as written.
    inputs: std::collections::BTreeMap<String, serde_json::Value>,
}

impl Existing {
    /// Whether the line holds `p`'s inputs: axis name -> value, the same names and values.
    fn holds_inputs_of(&self, p: &Point) -> bool {
        self.inputs.len() == p.inputs.len()
            && p.inputs
                .iter()
                .all(|(k, v)| self.inputs.get(k).and_then(|x| x.as_f64()) == Some(*v))
    }
}

/// The records of an existing `points.jsonl` ([`read_existing`]): key -> latest record, and
/// the numbers (1-based) of the complete lines that are no record (edited or damaged).
struct ExistingRecords {
    map: HashMap<String, Existing>,
    unreadable_lines: Vec<usize>,
}

/// Reads `path`, drops a torn last line (truncating the file back to the last complete
/// line) and returns key -> latest record. Complete lines that are no record are left out
/// and listed (their points run again).
fn read_existing(path: &Path) -> Result<ExistingRecords, SweepError> {
    let mut map = HashMap::new();
    let mut unreadable_lines = Vec::new();
    let mut file = match OpenOptions::new().read(true).write(true).open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok(ExistingRecords {
                map,
                unreadable_lines,
            })
        }
        Err(e) => return Err(io_err(path)(e)),
    };
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes).map_err(io_err(path))?;
    let complete = whirlmap_results::read::complete_len(&bytes);
    if complete < bytes.len() {
        file.set_len(complete as u64).map_err(io_err(path))?;
        file.sync_all().map_err(io_err(path))?;
    }
    for (n, line) in bytes[..complete].split(|b| *b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let parsed = std::str::from_utf8(line)
            .ok()
            .and_then(|text| Some((text, serde_json::from_str::<PointLine>(text).ok()?)));
        let Some((text, p)) = parsed else {
            unreadable_lines.push(n + 1);
            continue;
        };
        let (Some(key), Some(_)) = (&p.key, &p.status) else {
            unreadable_lines.push(n + 1);
            continue;
        };
        map.insert(
            key.clone(),
            Existing {
                index: p.index,
                ok: p.is_ok(),
                line: text.to_string(),
                inputs: p.inputs.clone(),
            },
        );
    }
    Ok(ExistingRecords {
        map,
        unreadable_lines,
    })
}

/// Writes `out/bearing.md` from the records ([`whirlmap_results::bearing_report`]) when the
/// spec's scene turns the bearing analysis on; returns whether it did.
pub(crate) fn write_bearing_report(spec: &SweepSpec, out: &Path) -> Result<bool, SweepError> {
    use whirlmap_results::bearing_report::{report, ReportSpec};
    let Some(pair) = spec.base_scene().bearing_as_run() else {
        return Ok(false);
    };
    let rows = whirlmap_results::point::load_points(out).map_err(|e| SweepError::Io {
        path: out.join(POINTS_FILE),
        source: std::io::Error::other(e.to_string()),
    })?;
    let about = ReportSpec {
        name: spec.name.clone(),
        duration_s: spec.duration_s,
        charts: spec.charts.clone(),
        axes: spec.axes.0.iter().map(|a| a.name.clone()).collect(),
    };
    folder::write_atomic(
        &out.join(BEARING_REPORT_FILE),
        report(&about, &pair, &rows).as_bytes(),
    )?;
    Ok(true)
}

/// Reads `points.jsonl` (one line per grid point in `indices`' order) and writes
/// `summary.csv` from it, line by line. Returns (ok, failed, class counts).
pub(crate) fn write_summary(
    spec: &SweepSpec,
    out: &Path,
    indices: &mut dyn Iterator<Item = usize>,
) -> Result<(usize, usize, BTreeMap<String, usize>), SweepError> {
    let points_path = out.join(POINTS_FILE);
    let summary_path = out.join(SUMMARY_FILE);
    let file = std::fs::File::open(&points_path).map_err(io_err(&points_path))?;
    let mut lines = std::io::BufReader::new(file).lines();
    let mut classes = BTreeMap::new();
    let (mut ok, mut failed) = (0, 0);
    let mut read_error: Option<std::io::Error> = None;
    folder::write_atomic_with(&summary_path, |w| {
        // The bearing analysis's columns when the scene turns it on.
        let bearing = spec.scene.bearing.is_some();
        let header = SummaryRow::header(spec.axes.0.iter().map(|a| a.name.as_str()), bearing);
        writeln!(w, "{header}")?;
        for index in indices {
            let line = match lines.next() {
                Some(Ok(l)) => l,
                Some(Err(e)) => {
                    read_error = Some(e);
                    break;
                }
                None => String::new(),
            };
            let source = SummarySource::parse(&line);
            if source.as_ref().is_some_and(SummarySource::is_ok) {
                ok += 1;
                let class = source
                    .as_ref()
                    .and_then(|s| s.record.as_ref())
                    .and_then(|r| r.class.clone());
                if let Some(c) = class {
                    *classes.entry(c).or_insert(0) += 1;
                }
            } else {
                failed += 1;
            }
            let row = SummaryRow {
                index,
                inputs: spec.inputs_at(index).iter().map(|(_, x)| *x).collect(),
                source,
                bearing,
            };
            writeln!(w, "{}", row.to_csv_line())?;
        }
        Ok(())
    })?;
    if let Some(e) = read_error {
        return Err(io_err(&points_path)(e));
    }
    Ok((ok, failed, classes))
}

/// Run facts for the manifest beside the spec and the counts.
#[derive(Debug, Clone)]
pub(crate) struct RunMeta {
    /// The whirlmap version of the binary that ran the drops.
    pub whirlmap_version: String,
    /// Its commit.
    pub git_commit: String,
    pub started_unix_s: f64,
    pub ended_unix_s: Option<f64>,
    pub threads: usize,
    pub shard: Option<ShardTag>,
    pub merged_from: Option<Vec<MergedShard>>,
}

impl RunMeta {
    /// This binary's build, started now.
    pub fn now(threads: usize, shard: Option<ShardTag>) -> Self {
        Self {
            whirlmap_version: crate::build_info::VERSION.to_string(),
            git_commit: crate::build_info::GIT_COMMIT.to_string(),
            started_unix_s: unix_now(),
            ended_unix_s: None,
            threads,
            shard,
            merged_from: None,
        }
    }
}

/// The manifest of a run being written: what `manifest.json` is made of.
#[derive(Debug)]
pub struct RunRecord {
    pub(crate) spec: SweepSpec,
    pub(crate) spec_hash: String,
    pub(crate) meta: RunMeta,
    pub(crate) counts: Option<Counts>,
    pub(crate) classes: Option<BTreeMap<String, usize>>,
}

/// Writes `manifest.json` for the run `r` in `folder`, complete or not.
pub(crate) fn write_manifest(
    folder: &RunFolder,
    r: &RunRecord,
    complete: bool,
) -> Result<(), SweepError> {
    let manifest = Manifest {
        spec: &r.spec,
        preset_solver: r.spec.fidelity.map(|_| r.spec.base_scene().solver),
        spec_hash: r.spec_hash.clone(),
        whirlmap_version: r.meta.whirlmap_version.clone(),
        model_version: MODEL_VERSION,
        git_commit: r.meta.git_commit.clone(),
        complete,
        started_unix_s: r.meta.started_unix_s,
        ended_unix_s: r.meta.ended_unix_s,
        threads: r.meta.threads,
        counts: r.counts.clone(),
        classes: r.classes.clone(),
        shard: r.meta.shard,
        merged_from: r.meta.merged_from.clone(),
        files: folder.files().clone(),
    };
    folder::write_atomic(
        &folder.dir().join(MANIFEST_FILE),
        manifest.to_text().as_bytes(),
    )
}

/// A sweep run in progress: the folder it owns and the manifest it keeps up to date. The
/// grid is done when [`run_sweep`] returns it; the extras ([`crate::extras`]) and the charts
/// are recorded with [`SweepRun::record`], and [`SweepRun::finish`] marks it complete.
#[derive(Debug)]
pub struct SweepRun {
    /// What the grid gave.
    pub outcome: SweepOutcome,
    /// The folder, locked while this value lives.
    pub folder: RunFolder,
    pub(crate) record: RunRecord,
}

impl SweepRun {
    /// Lists the file or folder `path` (written by the run) in the manifest, and rewrites
    /// the manifest (still incomplete).
    pub fn record(&mut self, path: &Path) -> Result<(), SweepError> {
        self.folder.record_path(path)?;
        write_manifest(&self.folder, &self.record, false)
    }

    /// Marks the run complete: the manifest, with its end time, says every file is written.
    /// The lock is released when this returns.
    pub fn finish(mut self) -> Result<(), SweepError> {
        self.record.meta.ended_unix_s = Some(unix_now());
        write_manifest(&self.folder, &self.record, true)
    }
}

/// Runs the sweep's grid and writes its records, summary and manifest (not yet complete:
/// the caller adds the extras and charts, then [`SweepRun::finish`]). Failed points are
/// recorded, not errors; errors are an unusable spec or output folder (before anything runs)
/// or an I/O failure.
pub fn run_sweep(spec: &SweepSpec, opts: &RunOptions) -> Result<SweepRun, SweepError> {
    let mut run = start_run(spec, opts, None)?;
    run_grid(spec, opts, None, &mut run)?;
    Ok(run)
}

/// The mode of a run from its options.
fn mode(opts: &RunOptions) -> Mode {
    if opts.resume {
        Mode::Resume
    } else if opts.overwrite {
        Mode::Overwrite
    } else {
        Mode::Fresh
    }
}

/// Validates the spec and every grid point, takes the output folder (lock, earlier files as
/// `opts` says) and writes the starting manifest. Nothing has run when this returns.
pub fn start_run(
    spec: &SweepSpec,
    opts: &RunOptions,
    shard: Option<&crate::shard::Shard>,
) -> Result<SweepRun, SweepError> {
    // A big grid takes a while to check (about 4 us a point): say so, not nothing.
    if spec.len() >= 100_000 && matches!(opts.progress, ProgressMode::Auto) {
        progress_line(&format!(
            "sweep {}: checking the scenes of {} grid points before any drop runs",
            spec.name,
            spec.len()
        ));
    }
    spec.check_points()?;
    let threads = match opts.threads {
        Some(n) => n,
        None => rayon::current_num_threads(),
    };
    let spec_hash = crate::shard::spec_hash(spec);
    let tag = shard.map(|s| s.manifest_tag());
    let id = RunIdentity {
        spec,
        spec_hash: spec_hash.clone(),
        shard: tag,
    };
    let what = match shard {
        Some(s) => format!("sweep --shard {} --shards {}", s.index, s.count),
        None => "sweep".to_string(),
    };
    let (folder, _found) = RunFolder::prepare(&opts.out_dir, &what, &id, mode(opts))?;
    let record = RunRecord {
        spec: spec.clone(),
        spec_hash,
        meta: RunMeta::now(threads, tag),
        counts: None,
        classes: None,
    };
    write_manifest(&folder, &record, false)?;
    Ok(SweepRun {
        outcome: SweepOutcome {
            points: 0,
            ok: 0,
            failed: 0,
            skipped: 0,
            classes: BTreeMap::new(),
            out_dir: opts.out_dir.clone(),
        },
        folder,
        record,
    })
}

/// [`run_sweep`] over the grid points a shard owns (all of them for `None`); the manifest
/// then names the shard. See [`crate::shard`].
pub fn run_sweep_part(
    spec: &SweepSpec,
    opts: &RunOptions,
    shard: Option<&crate::shard::Shard>,
) -> Result<SweepRun, SweepError> {
    let mut run = start_run(spec, opts, shard)?;
    run_grid(spec, opts, shard, &mut run)?;
    Ok(run)
}

/// The grid indices a run owns, in order.
fn owned_indices(
    len: usize,
    shard: Option<&crate::shard::Shard>,
) -> Box<dyn Iterator<Item = usize> + '_> {
    match shard {
        Some(s) => Box::new((s.index..len).step_by(s.count)),
        None => Box::new(0..len),
    }
}

/// At most this long between syncs of `points.jsonl` while records are being written: a
/// power loss loses at most the records of the last second (a kill loses none that were
/// written). The first records are synced at once, and everything at the end.
const SYNC_EVERY: Duration = Duration::from_secs(1);

/// The reorder window per worker thread: workers run at most `16 x threads` points ahead of
/// the first point not yet written, so one slow point holds back only the records after it
/// (kept in memory, at most that many, about 2 kB each) and the other workers go on
/// meanwhile. The paper grid needs it: its third point costs as much as 17 others, and with
/// `8 x threads` the second of two threads ran out of window before that point was done
/// (0.418 s against 0.388 s for the grid on 2 threads, replaying its measured point times).
const WINDOW_PER_THREAD: usize = 16;

/// What a grid job gives: the point's record, `None` for a point a resumed file already has
/// ok, or an error building the point.
type GridJob = Result<Option<PointRecord>, SpecError>;

/// Appends the grid's records to `points.jsonl` and `timings.jsonl` in grid order, as
/// [`run_ordered`] hands them over: each contiguous run of records with one `write_all` per
/// file, flushed at once (so a kill loses none), and `points.jsonl` synced at most
/// [`SYNC_EVERY`] apart.
struct GridWriter<'a> {
    points_file: File,
    points_path: &'a Path,
    timings_file: File,
    timings_path: &'a Path,
    folder: &'a mut RunFolder,
    /// Records written since the last sync.
    unsynced: bool,
    last_sync: Instant,
    /// The first records are synced and the previous run's files (`--overwrite`) removed.
    released: bool,
    /// On a resume: key -> this run's record of the point (it replaces the file's).
    fresh: Option<HashMap<String, Existing>>,
}

impl GridWriter<'_> {
    /// Syncs `points.jsonl` if records were written since the last sync; after the first,
    /// removes the previous run's files.
    fn sync(&mut self) -> Result<(), SweepError> {
        if self.unsynced {
            self.points_file
                .sync_data()
                .map_err(io_err(self.points_path))?;
            self.unsynced = false;
            self.last_sync = Instant::now();
            if !self.released {
                self.folder.release_previous()?;
                self.released = true;
            }
        }
        Ok(())
    }
}

impl OrderedSink<GridJob> for GridWriter<'_> {
    type Error = SweepError;

    fn take(&mut self, _first: usize, items: Vec<GridJob>) -> Result<(), SweepError> {
        let mut text = String::new();
        let mut times = String::new();
        let mut failure = None;
        for job in items {
            let r = match job {
                Ok(Some(r)) => r,
                Ok(None) => continue,
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            };
            let line = r.to_line();
            text.push_str(&line);
            text.push('\n');
            let t = TimingRow {
                index: r.index,
                key: r.key.clone(),
                wall_time_s: r.wall_time_s,
            };
            times.push_str(&t.to_line());
            times.push('\n');
            if let Some(fresh) = &mut self.fresh {
                fresh.insert(
                    r.key.clone(),
                    Existing {
                        index: Some(r.index as u64),
                        ok: r.status == Status::Ok,
                        line,
                        // This run's own record: its inputs are the point's.
                        inputs: Default::default(),
                    },
                );
            }
        }
        if !text.is_empty() {
            self.points_file
                .write_all(text.as_bytes())
                .and_then(|_| self.points_file.flush())
                .map_err(io_err(self.points_path))?;
            self.timings_file
                .write_all(times.as_bytes())
                .and_then(|_| self.timings_file.flush())
                .map_err(io_err(self.timings_path))?;
            self.unsynced = true;
            if !self.released || self.last_sync.elapsed() >= SYNC_EVERY {
                self.sync()?;
            }
        }
        match failure {
            Some(e) => Err(e.into()),
            None => Ok(()),
        }
    }

    fn wait_limit(&self) -> Option<Duration> {
        self.unsynced
            .then(|| SYNC_EVERY.saturating_sub(self.last_sync.elapsed()))
    }

    fn idle(&mut self) -> Result<(), SweepError> {
        self.sync()
    }
}

/// Runs the owned grid points of `run`'s folder (see [`run_sweep`]).
pub fn run_grid(
    spec: &SweepSpec,
    opts: &RunOptions,
    shard: Option<&crate::shard::Shard>,
    run: &mut SweepRun,
) -> Result<(), SweepError> {
    let grid: Grid = spec.grid()?;
    let pool =
        crate::pool::pool(opts.threads).map_err(|e| SweepError::ThreadPool(e.to_string()))?;
    let threads = pool.current_num_threads();
    run.record.meta.threads = threads;
    let out = opts.out_dir.clone();
    let points_path = out.join(POINTS_FILE);
    let timings_path = out.join(TIMINGS_FILE);
    let resume = opts.resume;
    let existing = if resume {
        let read = read_existing(&points_path)?;
        if !read.unreadable_lines.is_empty() {
            let lines: Vec<String> = read
                .unreadable_lines
                .iter()
                .map(|n| n.to_string())
                .collect();
            let (noun, verb) = if lines.len() == 1 {
                ("line", "is no point record")
            } else {
                ("lines", "are no point records")
            };
            progress_line(&format!(
                "warning: {}: {noun} {} {verb} (edited or damaged?): left out (a point with \
                 no other record runs again)",
                points_path.display(),
                lines.join(", ")
            ));
        }
        read.map
    } else {
        HashMap::new()
    };
    let total = owned_indices(grid.len(), shard).count();
    // A record counts for a point only at the point's own grid index, with its inputs.
    let done = |p: &Point, key: &str, existing: &HashMap<String, Existing>| {
        existing
            .get(key)
            .is_some_and(|e| e.ok && e.index == Some(p.index as u64) && e.holds_inputs_of(p))
    };
    let mut skipped = 0;
    if resume {
        let mut altered = Vec::new();
        for index in owned_indices(grid.len(), shard) {
            let p = grid.point(index)?;
            let key = point_key(&p.scene, spec.duration_s);
            if done(&p, &key, &existing) {
                skipped += 1;
            } else if existing
                .get(&key)
                .is_some_and(|e| e.ok && !e.holds_inputs_of(&p))
            {
                altered.push(index.to_string());
            }
        }
        if !altered.is_empty() {
            progress_line(&format!(
                "warning: {}: the records at grid index {} do not hold their points' inputs \
                 (edited?): those points run again",
                points_path.display(),
                altered.join(", ")
            ));
        }
    }

    let points_file = OpenOptions::new()
        .create(true)
        .append(resume)
        .write(true)
        .truncate(!resume)
        .open(&points_path)
        .map_err(io_err(&points_path))?;
    let timings_file = OpenOptions::new()
        .create(true)
        .append(resume)
        .write(true)
        .truncate(!resume)
        .open(&timings_path)
        .map_err(io_err(&timings_path))?;

    let progress = Progress::new(&spec.name, total, skipped, opts.progress);
    let duration = spec.duration_s;
    // The grid index of the run's `pos`-th owned point (see `owned_indices`).
    let owned = |pos: usize| match shard {
        Some(s) => s.index + pos * s.count,
        None => pos,
    };
    // One owned point, built from its index when a worker takes it.
    let work = |pos: usize| -> GridJob {
        let p = grid.point(owned(pos))?;
        if resume && done(&p, &point_key(&p.scene, duration), &existing) {
            return Ok(None);
        }
        let r = run_case(&p, duration);
        progress.point_done(r.status == Status::Failed);
        Ok(Some(r))
    };
    let mut writer = GridWriter {
        points_file,
        points_path: &points_path,
        timings_file,
        timings_path: &timings_path,
        folder: &mut run.folder,
        unsynced: false,
        last_sync: Instant::now(),
        released: false,
        fresh: resume.then(HashMap::new),
    };
    run_ordered(&pool, total, WINDOW_PER_THREAD * threads, work, &mut writer)?;
    writer.sync()?;
    let fresh = writer.fresh.take().unwrap_or_default();
    drop(writer);
    progress.finish();
    run.folder.release_previous()?;

    // One line per point in grid order.
    if resume {
        let mut missing = None;
        folder::write_atomic_with(&points_path, |w| {
            for index in owned_indices(grid.len(), shard) {
                let line = match grid.point(index) {
                    Ok(p) => {
                        let key = point_key(&p.scene, duration);
                        // This run's record of a point replaces the file's.
                        fresh
                            .get(&key)
                            .or_else(|| existing.get(&key))
                            .filter(|e| e.index == Some(index as u64))
                    }
                    .map(|e| e.line.as_str()),
                    Err(e) => {
                        missing = Some(e);
                        None
                    }
                };
                writeln!(w, "{}", line.unwrap_or(""))?;
            }
            Ok(())
        })?;
        if let Some(e) = missing {
            return Err(e.into());
        }
    }
    let (ok, failed, classes) = write_summary(spec, &out, &mut owned_indices(grid.len(), shard))?;
    run.folder.record(POINTS_FILE)?;
    run.folder.record(TIMINGS_FILE)?;
    run.folder.record(SUMMARY_FILE)?;
    // A shard holds part of the grid: its merge writes the report.
    if shard.is_none() && write_bearing_report(spec, &out)? {
        run.folder.record(BEARING_REPORT_FILE)?;
    }
    run.record.counts = Some(Counts {
        points: total,
        ok,
        failed,
        skipped,
    });
    run.record.classes = Some(classes.clone());
    write_manifest(&run.folder, &run.record, false)?;
    run.outcome = SweepOutcome {
        points: total,
        ok,
        failed,
        skipped,
        classes,
        out_dir: out,
    };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_summary_of_committed_records_is_the_committed_summary() {
        for name in ["paper", "paper-radial", "life"] {
            let src = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../results")
                .join(name);
            let spec = folder::manifest_spec(&src).expect("a committed manifest");
            let dir = std::env::temp_dir()
                .join(format!("whirlmap-summary-{name}-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::copy(src.join(POINTS_FILE), dir.join(POINTS_FILE)).unwrap();
            let n = spec.grid().unwrap().len();
            write_summary(&spec, &dir, &mut (0..n)).unwrap();
            let made = std::fs::read(dir.join(SUMMARY_FILE)).unwrap();
            let committed = std::fs::read(src.join(SUMMARY_FILE)).unwrap();
            assert!(made == committed, "{name}: summary.csv differs");
            std::fs::remove_dir_all(&dir).ok();
        }
    }

    /// The committed life study's report is what its committed records give.
    #[test]
    fn the_report_of_committed_records_is_the_committed_report() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results/life");
        let spec = folder::manifest_spec(&src).expect("a committed manifest");
        let dir = std::env::temp_dir().join(format!("whirlmap-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(src.join(POINTS_FILE), dir.join(POINTS_FILE)).unwrap();
        assert!(write_bearing_report(&spec, &dir).unwrap());
        let made = std::fs::read(dir.join(BEARING_REPORT_FILE)).unwrap();
        let committed = std::fs::read(src.join(BEARING_REPORT_FILE)).unwrap();
        assert!(made == committed, "results/life/bearing.md differs");
        std::fs::remove_dir_all(&dir).ok();
    }

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
        let p = dir.join(POINTS_FILE);
        std::fs::write(
            &p,
            "{\"key\":\"a\",\"status\":\"ok\"}\n{\"key\":\"b\",\"status\":\"failed\"}\n{\"key\":\"b\",\"status\":\"ok\"}\n{\"key\":\"c\",\"sta",
        )
        .unwrap();
        let read = read_existing(&p).unwrap();
        assert_eq!(
            read.unreadable_lines,
            Vec::<usize>::new(),
            "a torn last line is no damage"
        );
        let m = read.map;
        assert_eq!(m.len(), 2);
        assert!(m["a"].ok && m["b"].ok, "the newer record wins");
        assert!(std::fs::read_to_string(&p).unwrap().ends_with("\"ok\"}\n"));
        // A complete line that is no record, and one without a key: listed, the rest kept.
        std::fs::write(
            &p,
            "{\"key\":\"a\",\"status\":\"ok\"}\ngarbage{{{\n\n{\"status\":\"ok\"}\n{\"key\":\"b\",\"status\":\"ok\"}\n",
        )
        .unwrap();
        let read = read_existing(&p).unwrap();
        assert_eq!(read.unreadable_lines, vec![2, 4]);
        assert_eq!(read.map.len(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
