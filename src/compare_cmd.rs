//! `whirlmap compare BASELINE NEW`: what changed between two sweep results (see
//! `whirlmap_sweep::compare`). Exit codes: 0 the same within the thresholds; 1 changed beyond
//! them; 2 error or refused (a folder without points.jsonl, nothing comparable, a folder
//! being written or holding a file its run did not write, a bad option, an unwritable
//! report). Differences between the two specs are always printed.

use crate::{CmdResult, Done, Failure};
use std::path::PathBuf;
use whirlmap_sweep::compare::{check_report_path, compare, write_report, ClassMap, Thresholds};

/// Arguments of `whirlmap compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// The baseline results folder (e.g. last night's, or one committed under results/).
    baseline: PathBuf,
    /// The new results folder.
    new: PathBuf,
    /// Relative change of the maximum contact force that counts as changed.
    #[arg(
        long,
        allow_negative_numbers = true,
        default_value_t = Thresholds::default().force_rel,
        value_parser = crate::flags::number(crate::flags::threshold_range)
    )]
    force_rel: f64,
    /// Relative change of the peak heat power that counts as changed.
    #[arg(
        long,
        allow_negative_numbers = true,
        default_value_t = Thresholds::default().power_rel,
        value_parser = crate::flags::number(crate::flags::threshold_range)
    )]
    power_rel: f64,
    /// The Markdown report; the class map goes beside it as `<stem>-classes.png`. Default
    /// NEW/compare.md. Its folder is created if missing (a nightly job's dated folder).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs the subcommand: `Flagged` (exit 1) when the runs differ.
pub fn run(a: &CompareArgs) -> CmdResult {
    let t = Thresholds {
        force_rel: a.force_rel,
        power_rel: a.power_rel,
    };
    t.validate().map_err(|e| Failure::coded(2, e))?;
    let out = a.out.clone().unwrap_or_else(|| a.new.join("compare.md"));
    check_report_path(&out).map_err(|e| Failure::coded(2, e))?;
    let c = compare(&a.baseline, &a.new, t).map_err(|e| Failure::coded(2, e))?;
    for w in &c.warnings {
        errln!("warning: {w}");
    }
    outln!(
        "compare: {}: {}{}",
        if c.changed() { "CHANGED" } else { "same" },
        c.counts(),
        if c.spec_differences.is_empty() {
            ""
        } else {
            " (the specs differ)"
        }
    );
    for d in &c.spec_differences {
        outln!("  spec differs     {d}");
    }
    for d in &c.not_comparable {
        outln!("  not comparable   {d}");
    }
    for p in &c.points {
        outln!("  point {}: {}", p.inputs, p.what.join("; "));
    }
    for k in &c.critical {
        outln!("  critical speed at mu = {}: {}", k.mu, k.what);
    }
    let draw = |m: &ClassMap| {
        whirlmap_plot::classes::draw_marked_class_map(m.path, m.grid, m.title, m.marked)
            .map_err(|e| e.to_string())
    };
    let png = write_report(&c, &out, &draw).map_err(|e| Failure::coded(2, e))?;
    outln!("  report           {}", out.display());
    outln!("  class map        {}", png.display());
    Ok(Done::flagged_if(c.changed()))
}
