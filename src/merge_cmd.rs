//! `whirlmap merge DIR... [--out DIR]`: join the shards of a sweep into one result (see
//! `whirlmap_sweep::merge`; the charts are drawn by `whirlmap_plot`).
//!
//! Exit codes: 0 merged, every point ok; 1 merged, some point failed (recorded as data),
//! failed drops left a critical speed undecided or the re-check did not confirm an onset (its
//! row says so); 2
//! refused (a point missing or present twice, shards of different specs, shard counts,
//! model versions or builds, a shard still running or with a file its manifest does not
//! list, a folder that is not a shard's, an output folder holding another run's results
//! without --overwrite) with every problem listed; 4 an output could not be written.

use crate::{CmdResult, Done, Failure};
use std::path::PathBuf;
use whirlmap_sweep::merge::merge;

/// Arguments of `whirlmap merge`.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// The shard output folders (each written by `whirlmap sweep --shard I --shards N`).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output folder; default: `results/<name>` of the shards' spec.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the results already in the output folder (they are moved to
    /// `previous-run/` until the merged records are written). Without it a folder holding
    /// another run's results is refused.
    #[arg(long)]
    overwrite: bool,
}

/// Runs the subcommand: `Flagged` (exit 1) when some points failed, failed drops left a
/// critical speed undecided or an onset does not hold at the re-check.
pub fn run(a: &MergeArgs) -> CmdResult {
    let out = match &a.out {
        Some(o) => o.clone(),
        None => match whirlmap_sweep::shard::read_shard_manifest(&a.dirs[0]) {
            Ok(m) => PathBuf::from("results").join(&m.spec.name),
            Err(e) => return Err(Failure::coded(2, format!("merge refused:\n  - {e}"))),
        },
    };
    match merge(&a.dirs, &out, a.overwrite, &crate::sweep_cmd::draw_charts) {
        Ok(o) => {
            for w in &o.warnings {
                errln!("warning: {w}");
            }
            outln!(
                "merge {}: {} shards, {} points, {} ok, {} failed",
                o.name,
                o.shards,
                o.points,
                o.ok,
                o.failed
            );
            crate::sweep_cmd::report_failed(&out, o.failed);
            for (class, n) in &o.classes {
                outln!("  {class:<16} {n}");
            }
            let critical = out.join(whirlmap_sweep::extras::CRITICAL_FILE);
            let undecided = critical.is_file() && crate::sweep_cmd::critical_line(&out, &critical);
            outln!("  output           {}", out.display());
            // The bearing's worst cells, as the sweep prints them (empty without its results).
            for line in whirlmap_sweep::results::bearing_report::worst_lines(&out) {
                outln!("  {line}");
            }
            if !o.charts.is_empty() {
                outln!("  charts           {} files", o.charts.len());
            }
            Ok(Done::flagged_if(o.failed > 0 || undecided))
        }
        Err(e) => Err(Failure::coded(e.exit_code(), e)),
    }
}
