//! `whirlmap sweep FILE --shard I --shards N`: run one shard of a sweep (see
//! `whirlmap_sweep::shard`). Exit codes as for a whole sweep: 0 every owned point ok, 1 some
//! point failed, failed drops left an owned critical speed undecided or the re-check did not
//! confirm an owned onset (records still written), 2 bad input, 4 an output could not be
//! written.

use crate::sweep_cmd::{counts, critical_line, SweepArgs};
use crate::{CmdResult, Done, Failure};
use std::path::PathBuf;
use whirlmap_sweep::pipeline::{self, Stages};
use whirlmap_sweep::shard::Shard;
use whirlmap_sweep::spec::SweepSpec;
use whirlmap_sweep::sweep::{ProgressMode, RunOptions};

/// Runs shard `index` of `count` of `spec` with the options of `a`.
pub fn run(a: &SweepArgs, spec: &SweepSpec, index: usize, count: usize) -> CmdResult {
    let shard = Shard::new(index, count).map_err(|e| Failure::coded(2, e))?;
    let out_dir = a.out.clone().unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&spec.name)
            .join(shard.dir_name())
    });
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
    let stages = Stages {
        on_grid: &|_| {},
        draw_charts: &crate::sweep_cmd::draw_charts,
    };
    let (outcome, critical) = pipeline::run(spec, &opts, Some(shard), &stages)
        .map(|o| (o.outcome, o.extras.critical))
        .map_err(|e| Failure::coded(e.exit_code(), e))?;
    outln!(
        "sweep {} shard {}: {}",
        spec.name,
        shard.label(),
        counts(&outcome)
    );
    crate::sweep_cmd::report_failed(&opts.out_dir, outcome.failed);
    let undecided = match critical {
        Some(p) => critical_line(&opts.out_dir, &p),
        None => false,
    };
    outln!("  output           {}", opts.out_dir.display());
    Ok(Done::flagged_if(outcome.failed > 0 || undecided))
}
