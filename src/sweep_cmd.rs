//! `whirlmap sweep FILE`: run a grid of drops from a JSON sweep spec.
//!
//! Exit codes: 0 every point ok; 1 some point or orbit drop failed, or failed drops left a
//! critical speed undecided, or the `critical.recheck` at a tighter preset did not confirm
//! an onset (records and every critical row still written); 2 bad spec, an
//! unusable output folder, or one that is in use or holds another run's results (nothing
//! run); 4 an output (records or charts) could not be written, a full disk included.

use crate::{CmdResult, Done, Failure};
use std::path::{Path, PathBuf};
use whirlmap_sweep::critical::CriticalRow;
use whirlmap_sweep::pipeline::{self, ChartsFailed, Stages};
use whirlmap_sweep::spec;
use whirlmap_sweep::sweep::{ProgressMode, RunOptions, SweepOutcome};

/// Draws every chart of the results folder `dir` (the pipeline's chart stage).
pub(crate) fn draw_charts(dir: &Path) -> Result<Vec<PathBuf>, ChartsFailed> {
    whirlmap_plot::render_all(dir).map_err(|e| ChartsFailed {
        message: e.to_string(),
        output: e.is_output(),
    })
}

/// Arguments of `whirlmap sweep`.
#[derive(clap::Args)]
pub struct SweepArgs {
    /// Sweep spec (JSON): name, scene overrides, duration_s, axes, optional critical, charts.
    pub(crate) file: PathBuf,
    /// Output folder; default `results/<name>`.
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Worker threads; default: rayon's (RAYON_NUM_THREADS or the number of cores).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::flags::threads)]
    pub(crate) threads: Option<u32>,
    /// Continue the run in the output folder: keep its ok points, its finished critical
    /// search, orbits and probability members, and run only the rest. Only a run of the same
    /// spec (and shard) by the same build is continued.
    #[arg(long, conflicts_with = "overwrite")]
    pub(crate) resume: bool,
    /// Replace the results already in the output folder (they are moved to `previous-run/`
    /// until the new run's first records are written). Without --resume or --overwrite a
    /// folder holding another run's results is refused.
    #[arg(long)]
    pub(crate) overwrite: bool,
    /// No progress bar or progress lines.
    #[arg(long)]
    pub(crate) no_progress: bool,
    /// Run only shard I of --shards N (0 <= I < N): grid points, critical searches and orbit
    /// panels whose position mod N is I; default --out `results/<name>/shard-I-of-N`. Join the
    /// shards with `whirlmap merge`.
    #[arg(long, requires = "shards", value_name = "I", allow_negative_numbers = true, value_parser = crate::flags::shard)]
    shard: Option<usize>,
    /// The number of shards (see --shard).
    #[arg(long, requires = "shard", value_name = "N", allow_negative_numbers = true, value_parser = crate::flags::shards)]
    shards: Option<usize>,
}

/// "N points, N ok, N failed (N resumed)": a run's counts, as the sweep and shard
/// commands print them.
pub(crate) fn counts(outcome: &SweepOutcome) -> String {
    let resumed = if outcome.skipped > 0 {
        format!(" ({} resumed)", outcome.skipped)
    } else {
        String::new()
    };
    format!(
        "{} points, {} ok, {} failed{resumed}",
        outcome.points, outcome.ok, outcome.failed
    )
}

/// Prints the summary line of the critical speeds in `dir` (`critical.json` at `path`),
/// with how many rows failed drops left undecided and how many onsets do not hold at the
/// re-check at a tighter preset, and says which on standard error (as `whirlmap critical`
/// does). True when some row is undecided or its onset does not hold. The sweep, shard and merge commands
/// share it.
pub(crate) fn critical_line(dir: &Path, path: &Path) -> bool {
    let rows = whirlmap_sweep::results::critical::read_critical(dir)
        .ok()
        .flatten()
        .unwrap_or_default();
    let list = |pick: &dyn Fn(&CriticalRow) -> bool| -> Vec<String> {
        (rows.iter().filter(|r| pick(r)))
            .map(|r| format!("mu {}", r.mu))
            .collect()
    };
    let undecided = list(&|r| r.undecided);
    let unconfirmed = list(&|r| r.recheck.as_ref().is_some_and(|rc| !rc.holds()));
    let mut parts = Vec::new();
    if !undecided.is_empty() {
        parts.push(format!(
            "{} of {} undecided by failed or unsettled drops: {}",
            undecided.len(),
            rows.len(),
            undecided.join(", ")
        ));
    }
    if !unconfirmed.is_empty() {
        parts.push(format!(
            "{} of {} not confirmed by the re-check: {}",
            unconfirmed.len(),
            rows.len(),
            unconfirmed.join(", ")
        ));
    }
    if parts.is_empty() {
        outln!("  critical speeds  {}", path.display());
        return false;
    }
    outln!(
        "  critical speeds  {} ({})",
        path.display(),
        parts.join("; ")
    );
    let undecided = crate::critical_cmd::report_undecided(&rows);
    let unconfirmed = crate::critical_cmd::report_unconfirmed(&rows);
    undecided || unconfirmed
}

/// Says on standard error, when some of the points in `out_dir` failed, how many by error
/// kind and the first one's inputs and message (each point's is in `points.jsonl` and
/// `summary.csv`). The shard and merge commands say it the same way.
pub(crate) fn report_failed(out_dir: &Path, failed: usize) {
    if failed == 0 {
        return;
    }
    let path = out_dir.join(whirlmap_sweep::results::files::POINTS_FILE);
    match std::fs::File::open(&path) {
        Ok(f) => {
            // Line by line: the file is as long as the grid.
            let lines = std::io::BufRead::lines(std::io::BufReader::new(f)).map_while(Result::ok);
            if let Some(s) = whirlmap_sweep::results::summary::failure_summary(lines) {
                errln!(
                    "error: {s} (every failed point's error is in points.jsonl and summary.csv)"
                );
            }
        }
        Err(e) => errln!(
            "error: {failed} points failed; cannot read {}: {e}",
            path.display()
        ),
    }
}

/// Runs the subcommand: `Flagged` (exit 1) when some points failed, failed drops left a
/// critical speed undecided or an onset does not hold at the re-check.
pub fn run(a: &SweepArgs) -> CmdResult {
    let spec = spec::read(&a.file).map_err(|e| Failure::coded(2, e))?;
    crate::warn_spec_preset_overrides(&a.file);
    if let (Some(i), Some(n)) = (a.shard, a.shards) {
        return crate::shard_cmd::run(a, &spec, i, n);
    }
    let out_dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&spec.name));
    let opts = RunOptions {
        out_dir,
        threads: a.threads.map(|n| n as usize),
        resume: a.resume,
        overwrite: a.overwrite,
        progress: if a.no_progress {
            ProgressMode::Off
        } else {
            ProgressMode::Auto
        },
    };
    let on_grid = |outcome: &SweepOutcome| {
        outln!("sweep {}: {}", spec.name, counts(outcome));
        report_failed(&outcome.out_dir, outcome.failed);
        for (class, n) in &outcome.classes {
            outln!("  {class:<16} {n}");
        }
        outln!("  output           {}", outcome.out_dir.display());
        if spec.scene.bearing.is_some() {
            for line in whirlmap_sweep::results::bearing_report::worst_lines(&outcome.out_dir) {
                outln!("  {line}");
            }
        }
    };
    let stages = Stages {
        on_grid: &on_grid,
        draw_charts: &draw_charts,
    };
    let done =
        pipeline::run(&spec, &opts, None, &stages).map_err(|e| Failure::coded(e.exit_code(), e))?;
    let x = &done.extras;
    let undecided = match &x.critical {
        Some(p) => critical_line(&opts.out_dir, p),
        None => false,
    };
    // A panel whose drop failed has an `.error.txt` in orbits/ instead of its orbit.
    let panels = whirlmap_sweep::extras::orbit_panels(&spec).map_or(0, |(_, mus)| mus.len());
    let failed_orbits = panels.saturating_sub(x.orbits.len());
    if panels > 0 {
        outln!(
            "  orbits           {} drops recorded{}",
            x.orbits.len(),
            if failed_orbits > 0 {
                format!(", {failed_orbits} failed (orbits/*.error.txt say why)")
            } else {
                String::new()
            }
        );
    }
    if let Some(p) = &x.probability {
        outln!("  probability      {}", p.display());
    }
    if let Some(written) = &done.charts {
        outln!("  charts           {} files", written.len());
    }
    Ok(Done::flagged_if(
        done.outcome.failed > 0 || undecided || failed_orbits > 0,
    ))
}
