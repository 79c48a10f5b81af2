//! `whirlmap ensemble FILE` (whirl probability per cell, probability contours, Fig. 4 with
//! bands) and `whirlmap adaptive FILE` (adaptive refinement of the whirl boundary).
//!
//! Exit codes: 0 ok; 1 some drop failed (outputs still written); 2 bad file or unwritable
//! output folder (nothing run); 4 an output could not be written.

use crate::{CmdResult, Done, Failure};
use std::path::PathBuf;
use whirlmap_sweep::adaptive::run_adaptive;
use whirlmap_sweep::ensemble::{self, run_ensemble};
use whirlmap_sweep::folder::FolderLock;
use whirlmap_sweep::sweep::SweepError;

/// Arguments of `whirlmap ensemble`, shared by `whirlmap adaptive` ([`AdaptiveArgs`]).
#[derive(clap::Args)]
pub struct EnsembleArgs {
    /// Ensemble file (JSON): a sweep file (name, scene, duration_s, axes) with an `ensemble`
    /// section (and, for `adaptive`, an `adaptive` section).
    file: PathBuf,
    /// Output folder; default `results/<name>`. A folder that already holds results (a
    /// committed one among them) is refused without --overwrite (or --resume, for a run killed
    /// there).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the results already in the output folder.
    #[arg(long)]
    overwrite: bool,
    /// Worker threads; default: rayon's (RAYON_NUM_THREADS or the number of cores).
    #[arg(long, allow_negative_numbers = true, value_parser = crate::flags::threads)]
    pub(crate) threads: Option<u32>,
    /// No progress lines.
    #[arg(long)]
    no_progress: bool,
}

/// Arguments of `whirlmap ensemble`: the shared ones, and a hidden `--compare-full` that is
/// only there to be refused with a message saying it belongs to `adaptive`.
#[derive(clap::Args)]
pub struct EnsembleCmdArgs {
    /// The arguments `adaptive` takes too.
    #[command(flatten)]
    pub(crate) common: EnsembleArgs,
    /// Refused: the full-grid comparison is `adaptive`'s.
    #[arg(long, hide = true)]
    compare_full: bool,
    /// Continue an ensemble that did not finish in the output folder (killed, say): the
    /// members already in its members.jsonl are kept and only the rest run. The folder's
    /// manifest must name the same file contents, model version and whirlmap version.
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
}

/// Arguments of `whirlmap adaptive`: those of `ensemble`, `--compare-full` (which only an
/// adaptive map has, so `ensemble` refuses it) and `--resume`.
#[derive(clap::Args)]
pub struct AdaptiveArgs {
    /// The arguments `ensemble` takes too.
    #[command(flatten)]
    pub(crate) common: EnsembleArgs,
    /// Also run the full fine grid and report how the boundaries agree.
    #[arg(long)]
    compare_full: bool,
    /// Continue a search that was killed in this output folder (the same spec and build): the
    /// corners it logged are not evaluated again.
    #[arg(long, conflicts_with = "overwrite")]
    resume: bool,
}

/// The command's failure for a library error.
fn failure(e: SweepError) -> Failure {
    Failure::coded(e.exit_code(), e)
}

/// A loaded file, its output folder and the folder's lock (one writer at a time; released when
/// dropped, or when the process ends), and with `--overwrite` the earlier run's files moved
/// aside ([`whirlmap_sweep::folder::move_owned_aside`]).
type Loaded = (ensemble::EnsembleSpec, PathBuf, FolderLock, Option<PathBuf>);

/// Reads the file, takes the output folder's lock and, with `--overwrite`, moves whirlmap's
/// files already there aside.
fn load(a: &EnsembleArgs, what: &str, resume: bool) -> Result<Loaded, Failure> {
    let s = ensemble::load(&a.file).map_err(|e| Failure::coded(2, e))?;
    crate::warn_spec_preset_overrides(&a.file);
    // The section the command runs, before any folder is made.
    let (has, section) = match what {
        "adaptive" => (s.adaptive.is_some(), "an adaptive"),
        _ => (s.ensemble.is_some(), "an ensemble"),
    };
    if !has {
        return Err(Failure::coded(
            2,
            format!(
                "{}: {what} = (missing): allowed {section} section (docs/probability.md)",
                a.file.display()
            ),
        ));
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("results").join(&s.name));
    // A folder without what a killed run leaves (an ensemble's manifest, an adaptive search's
    // corner log) has nothing to resume: it is refused as any folder with results is.
    let marker = if what == "adaptive" {
        whirlmap_sweep::results::files::ADAPTIVE_CORNERS_FILE
    } else {
        ensemble::MANIFEST_FILE
    };
    if !resume || !out.join(marker).exists() {
        crate::refuse_existing_results(&out, a.overwrite).map_err(|e| {
            if what == "ensemble" && !resume {
                Failure::Input(anyhow::anyhow!(
                    "{e}; --resume continues an ensemble that did not finish there, keeping \
                     its members"
                ))
            } else if what == "adaptive" && !resume && out.join(marker).exists() {
                Failure::Input(anyhow::anyhow!(
                    "{e}; --resume continues the adaptive search that did not finish there, \
                     keeping its evaluated corners"
                ))
            } else {
                Failure::Input(e)
            }
        })?;
    }
    let lock = std::fs::create_dir_all(&out)
        .map_err(|e| whirlmap_sweep::folder::output_error(&out, e))
        .and_then(|_| FolderLock::acquire(&out, what))
        .map_err(failure)?;
    let previous = if a.overwrite {
        whirlmap_sweep::folder::move_owned_aside(&out).map_err(failure)?
    } else {
        // A resume finishing a killed `--overwrite`: what that moved aside goes once the
        // results are written, as it would have.
        let prev = out.join(whirlmap_sweep::results::files::PREVIOUS_DIR);
        (resume && prev.is_dir()).then_some(prev)
    };
    Ok((s, out, lock, previous))
}

fn fmt_speed(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |s| format!("{s:.0}"))
}

/// Runs `whirlmap ensemble`.
pub fn run_ensemble_cmd(args: &EnsembleCmdArgs) -> CmdResult {
    if args.compare_full {
        return Err(Failure::coded(
            2,
            "--compare-full applies only to `whirlmap adaptive` (it compares an adaptive map \
             with the full fine grid); an ensemble runs its whole grid already",
        ));
    }
    let a = &args.common;
    let (spec, out, _lock, previous) = load(a, "ensemble", args.resume)?;
    let o = run_ensemble(
        &spec,
        &out,
        a.threads.map(|n| n as usize),
        !a.no_progress,
        args.resume,
    )
    .map_err(failure)?;
    // Its results are written: the earlier run's files go (before the charts, so a chart
    // that fails does not leave both).
    whirlmap_sweep::folder::release_previous(previous).map_err(failure)?;
    let resumed = if o.resumed > 0 {
        format!(" ({} resumed)", o.resumed)
    } else {
        String::new()
    };
    outln!(
        "ensemble {}: {} cells x {} members = {} drops{resumed}, {} failed",
        spec.name,
        o.cells,
        o.contours.members,
        o.drops,
        o.failed
    );
    for g in &o.contours.groups {
        let label = if g.inputs.is_empty() {
            "all cells".to_string()
        } else {
            g.inputs
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        // A crossing outside the range reads `<4000` (reached already at the lowest speed)
        // or `>16000` (not reached), its interval's open ends `-`.
        let ends = (
            g.speeds_rpm.first().copied().unwrap_or(f64::NAN),
            g.speeds_rpm.last().copied().unwrap_or(f64::NAN),
        );
        let levels: Vec<String> = g
            .levels
            .iter()
            .map(|l| {
                let at = match l.speed_rpm {
                    Some(s) => format!("{s:.0}"),
                    None if g.reached_below_range(l.level) => format!("<{:.0}", ends.0),
                    None => format!(">{:.0}", ends.1),
                };
                format!(
                    "P{:.0}% {at} [{}, {}]",
                    100.0 * l.level,
                    fmt_speed(l.speed_lo_rpm),
                    fmt_speed(l.speed_hi_rpm)
                )
            })
            .collect();
        let flag = if g.non_monotone {
            " (non-monotone)"
        } else {
            ""
        };
        outln!("  {label}: {} r/min{flag}", levels.join(", "));
    }
    let w = whirlmap_plot::probability::render_probability(&out)
        .map_err(|e| Failure::coded(4, format!("charts: {e}")))?;
    if w.is_empty() {
        outln!(
            "  output           {} ({})",
            out.display(),
            whirlmap_plot::probability::NO_MU_AXIS
        );
    } else {
        outln!("  output           {} ({} charts)", out.display(), w.len());
    }
    Ok(Done::flagged_if(o.failed > 0))
}

/// Runs `whirlmap adaptive`.
pub fn run_adaptive_cmd(args: &AdaptiveArgs) -> CmdResult {
    let a = &args.common;
    let (spec, out, _lock, previous) = load(a, "adaptive", args.resume)?;
    let (r, path) = run_adaptive(
        &spec,
        &out,
        a.threads.map(|n| n as usize),
        args.compare_full,
        !a.no_progress,
        args.resume,
    )
    .map_err(failure)?;
    whirlmap_sweep::folder::release_previous(previous).map_err(failure)?;
    outln!(
        "adaptive {}: {} of {} drops ({:.1} %) for a {} x {} grid from a {} x {} seed, {} rounds, {} boundary cells",
        r.name,
        r.drops_used,
        r.full_grid_drops,
        100.0 * r.drops_ratio,
        r.fine_points.0,
        r.fine_points.1,
        r.seed_points.0,
        r.seed_points.1,
        r.rounds,
        r.boundary_cells
    );
    if let Some(c) = &r.comparison {
        let g = &c.agreement;
        outln!(
            "  against the full grid: boundary within {} fine speed steps, {} columns differ, {} points differ",
            g.max_shift_cells, g.columns_differing, g.points_differing
        );
    }
    outln!("  output           {}", path.display());
    Ok(Done::flagged_if(
        r.evaluated.iter().any(|c| c.p_whirl.is_nan()),
    ))
}
