//! The one order of a run: grid → extras → charts.
//!
//! A whole sweep ([`run`] with no shard), a shard of one ([`run`] with a [`Shard`]) and a
//! merge of shards ([`crate::merge`]) all go through here, so the order in which a results
//! folder is filled, and which files its manifest lists after each stage, is decided in one
//! place:
//!
//! 1. the folder is taken and its starting manifest written ([`start_run`]); a shard also
//!    writes [`SHARD_FILE`] before it runs anything;
//! 2. the grid's points run and their records, timings and summary are written
//!    ([`run_grid`]);
//! 3. the extras run ([`crate::extras`]: critical search, orbits, probability ensemble; a
//!    shard runs only its part) and are listed in the manifest ([`record_extras`]);
//! 4. the charts are drawn ([`draw_charts`]) by the function the caller hands in (this crate
//!    draws nothing), when the spec lists charts; a shard draws none, its merge does;
//! 5. the manifest is marked complete (a shard's [`SHARD_FILE`] first).

use crate::extras::{run_all_owned, ExtrasError, ExtrasWritten, CRITICAL_CSV_FILE};
use crate::folder::write_atomic;
use crate::shard::{shard_manifest, Shard, ShardManifest, SHARD_FILE};
use crate::spec::SweepSpec;
use crate::sweep::SweepRun;
use crate::sweep::{run_grid, start_run, ProgressMode, RunOptions, SweepError, SweepOutcome};
use std::path::{Path, PathBuf};
use thiserror::Error;
use whirlmap_results::files::{CHARTS_DIR, ORBITS_DIR};

/// Why the chart drawing handed to the pipeline failed, as its caller words it.
#[derive(Debug, Error)]
#[error("{message}")]
pub struct ChartsFailed {
    /// What went wrong.
    pub message: String,
    /// Whether an output could not be written (exit code 4) rather than an input read (2).
    pub output: bool,
}

/// Draws every chart of a results folder and returns the files written (the CLI hands in
/// `whirlmap_plot::render_all`).
pub type DrawCharts<'a> = &'a dyn Fn(&Path) -> Result<Vec<PathBuf>, ChartsFailed>;

/// What the caller hands the pipeline: what to do once the grid is done, and how charts are
/// drawn.
pub struct Stages<'a> {
    /// Called with the grid's outcome once its records are written, before the extras run
    /// (the CLI prints the grid's counts there).
    pub on_grid: &'a dyn Fn(&SweepOutcome),
    /// Draws the charts.
    pub draw_charts: DrawCharts<'a>,
}

/// What a run of the pipeline wrote.
#[derive(Debug, Clone)]
pub struct PipelineOutcome {
    /// What the grid gave.
    pub outcome: SweepOutcome,
    /// The extras' files.
    pub extras: ExtrasWritten,
    /// The chart files drawn; `None` when no charts were drawn (the spec lists none, or the
    /// run is a shard's).
    pub charts: Option<Vec<PathBuf>>,
}

/// Why a run of the pipeline failed.
#[derive(Debug, Error)]
pub enum PipelineError {
    /// A bad spec, a refused folder or a failed write of the grid's files or the manifest.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// The critical search, the orbits or the ensemble could not be written.
    #[error(transparent)]
    Extras(#[from] ExtrasError),
    /// The charts could not be drawn.
    #[error("charts: {0}")]
    Charts(#[from] ChartsFailed),
}

impl PipelineError {
    /// The process exit code: 2 bad input or a refused folder (nothing run), 4 an output
    /// (records, extras or charts) could not be written.
    pub fn exit_code(&self) -> u8 {
        match self {
            PipelineError::Sweep(e) => e.exit_code(),
            PipelineError::Extras(_) | PipelineError::Charts(_) => 4,
        }
    }
}

/// Runs `spec` (or the part of it `shard` owns) into `opts.out_dir`: the folder, the grid,
/// the extras, the charts (a whole run's, when the spec lists charts), then the complete
/// manifest. See the module docs for the order.
pub fn run(
    spec: &SweepSpec,
    opts: &RunOptions,
    shard: Option<Shard>,
    stages: &Stages,
) -> Result<PipelineOutcome, PipelineError> {
    let mut run = start_run(spec, opts, shard.as_ref())?;
    let shard_manifest = match shard {
        Some(s) => Some(write_shard_file(spec, s, &mut run, false, None)?),
        None => None,
    };
    run_grid(spec, opts, shard.as_ref(), &mut run)?;
    (stages.on_grid)(&run.outcome);
    let progress = opts.progress != ProgressMode::Off;
    let extras = match shard {
        Some(s) => run_all_owned(
            spec,
            &opts.out_dir,
            opts.threads,
            progress,
            opts.resume,
            |k| s.owns(k),
        )?,
        None => run_all_owned(
            spec,
            &opts.out_dir,
            opts.threads,
            progress,
            opts.resume,
            |_| true,
        )?,
    };
    record_extras(&mut run, &opts.out_dir, &extras)?;
    let charts = match shard_manifest {
        // Shards draw no charts: their merge does.
        Some(m) => {
            write_shard_file(
                spec,
                shard.expect("a shard's manifest"),
                &mut run,
                true,
                Some(m),
            )?;
            None
        }
        None => draw_charts(spec, &opts.out_dir, stages.draw_charts)?,
    };
    if charts.is_some() {
        run.record(&opts.out_dir.join(CHARTS_DIR))?;
    }
    let outcome = run.outcome.clone();
    run.finish()?;
    Ok(PipelineOutcome {
        outcome,
        extras,
        charts,
    })
}

/// Writes a shard's [`SHARD_FILE`] (`complete` or not; `manifest` when already made) and lists
/// it in the run's manifest.
fn write_shard_file(
    spec: &SweepSpec,
    shard: Shard,
    run: &mut SweepRun,
    complete: bool,
    manifest: Option<ShardManifest>,
) -> Result<ShardManifest, SweepError> {
    let manifest = match manifest {
        Some(m) => m,
        None => shard_manifest(spec, shard)?,
    };
    let path = run.folder.dir().join(SHARD_FILE);
    let m = ShardManifest {
        complete,
        ..manifest.clone()
    };
    let text = serde_json::to_string_pretty(&m).expect("shard manifests serialise");
    write_atomic(&path, format!("{text}\n").as_bytes())?;
    run.record(&path)?;
    Ok(manifest)
}

/// Lists the extras' files in the run's manifest: `critical.json` and `critical.csv`, the
/// orbits folder and the probability ensemble's folder.
pub fn record_extras(
    run: &mut SweepRun,
    out_dir: &Path,
    x: &ExtrasWritten,
) -> Result<(), SweepError> {
    if let Some(c) = &x.critical {
        run.record(c)?;
        run.record(&out_dir.join(CRITICAL_CSV_FILE))?;
    }
    run.record(&out_dir.join(ORBITS_DIR))?;
    if let Some(p) = &x.probability {
        run.record(p)?;
    }
    Ok(())
}

/// The chart stage: when the spec lists charts, draws them with `draw` from the folder's
/// files (the records and extras written, the folder still locked, the manifest not yet
/// complete) and returns the files drawn; `None` when the spec lists none. The caller lists
/// `charts/` in the manifest.
pub fn draw_charts(
    spec: &SweepSpec,
    dir: &Path,
    draw: DrawCharts,
) -> Result<Option<Vec<PathBuf>>, ChartsFailed> {
    if spec.charts.is_empty() {
        return Ok(None);
    }
    draw(dir).map(Some)
}
