//! `whirlmap compare BASELINE NEW`: what changed between two sweep results (see
//! `whirlmap_sweep::compare`). Exit codes: 0 the same within the thresholds; 1 changed beyond
//! them; 2 error (a folder without points.jsonl, a bad option, an unwritable report).

use std::path::PathBuf;
use std::process::ExitCode;
use whirlmap_sweep::compare::{compare, write_report, Thresholds};

/// Arguments of `whirlmap compare`.
#[derive(clap::Args)]
pub struct CompareArgs {
    /// The baseline results folder (e.g. last night's, or one committed under results/).
    baseline: PathBuf,
    /// The new results folder.
    new: PathBuf,
    /// Relative change of the maximum contact force that counts as changed.
    #[arg(long, allow_negative_numbers = true, default_value_t = Thresholds::default().force_rel)]
    force_rel: f64,
    /// Relative change of the peak heat power that counts as changed.
    #[arg(long, allow_negative_numbers = true, default_value_t = Thresholds::default().power_rel)]
    power_rel: f64,
    /// The Markdown report; the class map goes beside it as `<stem>-classes.png`. Default
    /// NEW/compare.md.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs the subcommand and returns the process exit code.
pub fn run(a: &CompareArgs) -> ExitCode {
    let t = Thresholds {
        force_rel: a.force_rel,
        power_rel: a.power_rel,
    };
    if let Err(e) = t.validate() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let c = match compare(&a.baseline, &a.new, t) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let out = a.out.clone().unwrap_or_else(|| a.new.join("compare.md"));
    let png = match write_report(&c, &out) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    println!(
        "compare: {}: {} of {} points and {} of {} critical speeds changed",
        if c.changed() { "CHANGED" } else { "same" },
        c.points.len(),
        c.points_compared,
        c.critical.len(),
        c.critical_compared
    );
    for p in &c.points {
        println!("  point {}: {}", p.inputs, p.what.join("; "));
    }
    for k in &c.critical {
        println!("  critical speed at mu = {}: {}", k.mu, k.what);
    }
    println!("  report           {}", out.display());
    println!("  class map        {}", png.display());
    if c.changed() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
