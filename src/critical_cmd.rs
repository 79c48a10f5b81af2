//! `whirlmap critical`: the onset of sustained backward whirl and every whirl interval, for
//! each friction coefficient.
//!
//! `--json` prints the same rows a sweep writes to `critical.json` (a list of
//! [`CriticalRow`]); `--csv FILE` also writes them as `critical.csv` does. Exit codes as the
//! rest of the tool: 2 for bad input (validated before any drop runs), 4 when the CSV or
//! standard output cannot be written. Failed drops are reported in each row; when they leave
//! a row's onset undecided (`undecided`, see docs/critical-speed.md), or the `--fidelity`
//! re-check does not confirm an onset, the command still prints and writes every row, names
//! the friction coefficients on standard error and exits 1, as a sweep whose points failed
//! does.
//!
//! `--log FILE` keeps every classified drop in FILE and answers from it the drops it already
//! holds ([`DropLog::open_kept`]): a killed search run again does only what is missing, and
//! the rows are those of an uninterrupted run (each is a function of its drops' classes).

use crate::{build_scene, flags, CmdResult, Done, Failure};
use std::path::{Path, PathBuf};
use std::time::Instant;
use whirlmap_core::InvalidParameter;
use whirlmap_sweep::critical::undecided_summary;
use whirlmap_sweep::critical::{
    check_mus, critical_rows_logged, csv_text, fmt_rpm, CriticalOptions, CriticalRow,
    DEFAULT_RESOLUTION_RPM, DEFAULT_TOL_RPM,
};
use whirlmap_sweep::critical_log::DropLog;
use whirlmap_sweep::progress::Ticker;
use whirlmap_sweep::recheck::recheck_rows;

#[derive(clap::Args)]
pub struct CriticalArgs {
    /// Friction coefficients to search, comma-separated, each in [0, 2] (e.g. 0.3,0.35,0.4).
    #[arg(
        long,
        value_delimiter = ',',
        required = true,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::critical_mu_range)
    )]
    mu: Vec<f64>,
    /// Lowest release speed searched (r/min), in [0, 1e6).
    #[arg(
        long,
        default_value_t = 1000.0,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::from_range)
    )]
    from: f64,
    /// Highest release speed searched (r/min), in (--from, 1e6].
    #[arg(
        long,
        default_value_t = 30000.0,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::to_range)
    )]
    to: f64,
    /// Lattice step of the scan (r/min): every multiple of it in the range is dropped,
    /// whatever the range ends, so the onset does not depend on the range.
    #[arg(
        long,
        default_value_t = DEFAULT_RESOLUTION_RPM,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::resolution_range)
    )]
    resolution_rpm: f64,
    /// Bisect every transition until its bracket is this narrow (r/min), at most the
    /// resolution.
    #[arg(
        long,
        default_value_t = DEFAULT_TOL_RPM,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::tol_range)
    )]
    tol_rpm: f64,
    /// Simulated time of each drop (s); a drop whose class has not settled by then is
    /// extended (scene `classification.max_extension_s`).
    #[arg(
        long,
        default_value_t = 1.0,
        allow_negative_numbers = true,
        value_parser = flags::number(flags::duration_range)
    )]
    duration_s: f64,
    /// Scene file (JSON); any subset of the fields printed by `whirlmap scene`.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Override one scene parameter, e.g. `--set clearance_m=2e-4`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Print the rows as JSON (the schema of a sweep's critical.json) instead of a table.
    #[arg(long)]
    json: bool,
    /// Also write the rows as CSV (the columns of a sweep's critical.csv) to this file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Keep every classified drop in this file (one JSON line each) and reuse the drops it
    /// already holds of the same coefficient, speed, scene, --duration-s and build: the same
    /// command run again after a kill runs only the missing drops, and a narrower --tol-rpm
    /// or a wider range reuses the shared ones. The file is kept; delete it to start afresh.
    #[arg(long, value_name = "FILE")]
    log: Option<PathBuf>,
    /// Fidelity preset (draft, standard, reference) for the search; the cells that decide
    /// each row (its onset bracket; without one, the end of the range that decides it: the
    /// top for "no whirl", the bottom for whirl from the start) are then re-checked at the
    /// next tighter preset (recorded as `recheck`): `draft` at `standard`, `standard` at
    /// `reference`; `reference` has none, and its search is not re-checked.
    #[arg(long)]
    fidelity: Option<whirlmap_core::Fidelity>,
    /// No progress (by default a bar on a terminal, a plain line every 5 s otherwise).
    #[arg(long)]
    no_progress: bool,
}

/// Names a bad flag: `--from = -5: allowed ...`.
fn flag_error(e: InvalidParameter) -> Failure {
    let flag = match e.field.as_str() {
        "from_rpm" => "--from",
        "to_rpm" => "--to",
        "tol_rpm" => "--tol-rpm",
        "resolution_rpm" => "--resolution-rpm",
        "duration_s" => "--duration-s",
        "mu" => "--mu",
        other => other,
    };
    Failure::Input(anyhow::anyhow!(
        "invalid {flag} = {}: allowed {}",
        e.value,
        e.allowed
    ))
}

/// Runs the subcommand: `Flagged` (exit 1) when failed drops left some row's onset
/// undecided or one does not hold at the re-check, after every row is printed and written.
pub fn run(a: &CriticalArgs) -> CmdResult {
    let opts = CriticalOptions {
        from_rpm: a.from,
        to_rpm: a.to,
        resolution_rpm: a.resolution_rpm,
        tol_rpm: a.tol_rpm,
        duration_s: a.duration_s,
    };
    opts.validate().map_err(flag_error)?;
    check_mus(&a.mu).map_err(flag_error)?;
    let mut base = build_scene(a.scene.as_deref(), &a.set, None, None).map_err(Failure::Input)?;
    if let Some(f) = a.fidelity {
        crate::warn_preset_overrides(f, &a.set);
        f.apply(&mut base);
    }
    // Each mu must make a valid scene (e.g. mu_static >= mu_dynamic) before anything runs,
    // at the lowest speed searched too (a stop speed must lie below every release speed).
    for &mu in &a.mu {
        let mut s = base.clone();
        s.mu_dynamic = mu;
        s.validate()
            .map_err(|e| Failure::Input(anyhow::anyhow!("with --mu {mu}: {e}")))?;
        s.speed_rpm = a.from;
        s.validate().map_err(|e| {
            Failure::Input(anyhow::anyhow!(
                "with --mu {mu} at the lowest speed searched, --from {} r/min: {e}",
                fmt_rpm(a.from)
            ))
        })?;
    }
    if let Some(p) = &a.csv {
        if let Some(log) = a.log.as_deref().filter(|l| same_file(p, l)) {
            return Err(Failure::Input(anyhow::anyhow!(
                "--csv {} is the --log file {}: the CSV would replace the drop log (the record \
                 of every drop classified); give the CSV another path",
                p.display(),
                log.display()
            )));
        }
        crate::check_writable(p).map_err(Failure::Output)?;
    }

    let log = match &a.log {
        None => None,
        Some(p) => Some(DropLog::open_kept(p, a.duration_s).map_err(|e| {
            if e.is_storage_error() {
                Failure::Output(e.into())
            } else {
                Failure::Input(e.into())
            }
        })?),
    };
    if let (Some(l), Some(p)) = (&log, &a.log) {
        errln!(
            "drop log {}: {} drops of this --duration-s and build to reuse",
            p.display(),
            l.usable()
        );
    }

    let start = Instant::now();
    let label = format!("critical search, {} friction coefficient(s)", a.mu.len());
    let ticker = Ticker::new(&label, 0, !a.no_progress);
    let rows = critical_rows_logged(&base, &a.mu, &opts, &ticker, log.as_ref());
    ticker.finish();
    let mut rows = rows.map_err(|e| Failure::Input(e.into()))?;
    if let (Some(l), Some(p)) = (log, &a.log) {
        let reused = l.reused();
        if let Some(warning) = l.finish() {
            errln!("warning: {warning}");
        }
        errln!("drop log {}: {reused} drops reused", p.display());
    }
    if let Some(tighter) = a.fidelity.and_then(|f| f.tighter()) {
        let drop_opts = whirlmap_core::DropOptions {
            duration_s: a.duration_s,
            ..Default::default()
        };
        let ticker = Ticker::new(&format!("re-check at {tighter}"), 0, !a.no_progress);
        recheck_rows(&base, &mut rows, tighter, &drop_opts, None, Some(&ticker));
        ticker.finish();
    }
    let wall_s = start.elapsed().as_secs_f64();
    // The rows are printed first: a CSV that cannot be written (a full disk) loses nothing.
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("results serialise")
        );
    } else {
        print_table(a, &rows, wall_s);
    }
    if let Some(p) = &a.csv {
        std::fs::write(p, csv_text(&rows))
            .map_err(|e| Failure::Output(anyhow::anyhow!("cannot write {}: {e}", p.display())))?;
    }
    let undecided = report_undecided(&rows);
    let unconfirmed = report_unconfirmed(&rows);
    Ok(Done::flagged_if(undecided || unconfirmed))
}

/// Whether two paths name the same file, through links, `.` and `..`, whether the files
/// exist yet or not (a first run's log does not).
fn same_file(a: &Path, b: &Path) -> bool {
    /// The path with its folder resolved on disk, when the folder exists.
    fn resolved(p: &Path) -> Option<PathBuf> {
        if let Ok(full) = p.canonicalize() {
            return Some(full);
        }
        let name = p.file_name()?;
        let folder = match p.parent() {
            Some(f) if !f.as_os_str().is_empty() => f,
            _ => Path::new("."),
        };
        Some(folder.canonicalize().ok()?.join(name))
    }
    match (resolved(a), resolved(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

/// Says on standard error which rows' onsets do not hold at the re-check at the next tighter
/// preset ([`whirlmap_results::critical::Recheck::holds`]; the `sweep` command shares it);
/// true when there are some.
pub(crate) fn report_unconfirmed(rows: &[CriticalRow]) -> bool {
    let Some(list) = whirlmap_sweep::critical::unconfirmed_summary(rows) else {
        return false;
    };
    let without_bracket = rows
        .iter()
        .any(|r| r.bracket_rpm.is_none() && r.recheck.as_ref().is_some_and(|rc| !rc.holds()));
    let cells = if without_bracket {
        "the cells re-run (the bracket's, or for a row without one the end of the range that \
         decides it)"
    } else {
        "the bracket"
    };
    errln!(
        "error: the re-check at the next tighter preset does not confirm the onset at {list}; \
         do not use this preset's onset there. The row gives the tighter preset's onset, \
         searched again from two lattice steps below {cells} to two above it (within the \
         range)"
    );
    true
}

/// Says on standard error which rows failed drops left undecided (see
/// [`undecided_summary`]); true when there is any. The sweep, shard and merge commands say
/// it the same way about their `critical.json`.
pub(crate) fn report_undecided(rows: &[CriticalRow]) -> bool {
    let Some(list) = undecided_summary(rows) else {
        return false;
    };
    errln!(
        "error: failed or unsettled drops leave the critical speed undecided at {list}; every row is \
         written and its note says why"
    );
    true
}

fn print_table(a: &CriticalArgs, rows: &[CriticalRow], wall_s: f64) {
    outln!(
        "whirlmap critical: {}-{} r/min on a {} r/min lattice, bisected to {} r/min, {} s per drop",
        fmt_rpm(a.from),
        fmt_rpm(a.to),
        fmt_rpm(a.resolution_rpm),
        a.tol_rpm,
        a.duration_s
    );
    let class = |c: Option<whirlmap_sweep::classify::OrbitClass>| c.map_or("-", |c| c.name());
    for r in rows {
        outln!();
        outln!("  mu_d = {}", r.mu);
        outln!("    onset of whirl      {}", onset_line(r));
        outln!(
            "    classes             {} below, {} above",
            class(r.class_below),
            class(r.class_above)
        );
        let intervals: Vec<String> = r
            .whirl_intervals_rpm
            .iter()
            .map(|[x, y]| format!("{}-{}", fmt_rpm(*x), fmt_rpm(*y)))
            .collect();
        outln!(
            "    whirl intervals     {}{}",
            if intervals.is_empty() {
                "none".to_string()
            } else {
                intervals.join(", ")
            },
            if r.whirl_at_range_top {
                " (to the range top)"
            } else {
                ""
            }
        );
        outln!(
            "    non-monotone        {}",
            if r.non_monotone { "YES" } else { "no" }
        );
        outln!(
            "    drops               {} ({} failed)",
            r.drops,
            r.failed_drops
        );
        outln!("    note                {}", r.note);
        if let Some(rc) = &r.recheck {
            let show = |o: &whirlmap_sweep::critical::Outcome| match o {
                whirlmap_sweep::critical::Outcome::Class(c) => c.name().to_string(),
                whirlmap_sweep::critical::Outcome::Failed(e) => format!("failed ({e})"),
            };
            let cells: Vec<String> = rc
                .cells()
                .map(|(speed, o)| format!("{}: {}", fmt_rpm(*speed), show(o)))
                .collect();
            outln!(
                "    {:<20}{} -> {}",
                format!("recheck ({})", rc.fidelity),
                cells.join(", "),
                if rc.confirmed && r.bracket_rpm.is_none() {
                    "confirmed".to_string()
                } else if rc.confirmed {
                    "bracket confirmed".to_string()
                } else if rc.within_tol {
                    format!("the onset holds to {} r/min", fmt_rpm(r.tol_rpm))
                } else {
                    "NOT confirmed".to_string()
                }
            );
            if let Some(w) = &rc.relocated {
                outln!(
                    "    searched again      {}-{} r/min at {}: {} ({} drops)",
                    fmt_rpm(w.window_rpm[0]),
                    fmt_rpm(w.window_rpm[1]),
                    rc.fidelity,
                    w.note,
                    w.drops
                );
            }
        }
    }
    let drops: usize = rows.iter().map(|r| r.drops).sum::<usize>()
        + rows
            .iter()
            .filter_map(|r| r.recheck.as_ref())
            .map(|rc| rc.drops())
            .sum::<usize>();
    outln!();
    outln!("  {drops} drops, {wall_s:.2} s wall");
}

/// The table's onset line for a row (after "onset of whirl"): the onset and its bracket, or
/// where the range already whirls, or "none in the range", each with what holds it back
/// (failed drops, a re-check that does not confirm it, no convergence).
fn onset_line(r: &CriticalRow) -> String {
    // What holds the row back, failed drops first.
    let why = if r.undecided {
        Some("UNDECIDED: failed drops below it")
    } else if r.recheck.as_ref().is_some_and(|rc| !rc.holds()) {
        Some("NOT CONFIRMED by the re-check")
    } else {
        None
    };
    match (r.onset_rpm, r.bracket_rpm) {
        (Some(o), Some([lo, hi])) => format!(
            "{} r/min (bracket {}-{}{})",
            fmt_rpm(o),
            fmt_rpm(lo),
            fmt_rpm(hi),
            why.or((!r.converged).then_some("NOT converged"))
                .map_or(String::new(), |w| format!(", {w}"))
        ),
        (Some(o), None) => format!(
            "at or below {} r/min (whirl at the lowest speed{})",
            fmt_rpm(o),
            why.map_or(String::new(), |w| format!("; {w}"))
        ),
        _ if r.undecided => "UNDECIDED (failed drops)".into(),
        _ if why.is_some() => "none in the range, NOT CONFIRMED by the re-check".into(),
        _ => "none in the range".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row as `critical.json` holds it (no whirl from 1000 to 30 000 r/min, re-checked at
    /// the range top), with `edit` applied to its JSON.
    fn row(edit: impl FnOnce(&mut serde_json::Value)) -> CriticalRow {
        let mut v: serde_json::Value = serde_json::from_str(
            r#"{"mu": 0.1, "onset_rpm": null, "bracket_rpm": null, "class_below": null,
            "class_above": null, "whirl_intervals_rpm": [], "whirl_at_range_top": false,
            "non_monotone": false, "drops": 117, "failed_drops": 0, "converged": true,
            "from_rpm": 1000.0, "to_rpm": 30000.0, "resolution_rpm": 250.0, "tol_rpm": 25.0,
            "duration_s": 1.0, "scene_hash": "f6db08a9e1dcc632", "model_version": 11,
            "note": "no whirl from 1000 to 30000 r/min",
            "scan": [{"speed_rpm": 29750.0, "class": "pendulum"},
                     {"speed_rpm": 30000.0, "class": "pendulum"}],
            "bisections": [],
            "recheck": {"fidelity": "standard", "lo": [30000.0, {"class": "pendulum"}],
                        "confirmed": true}}"#,
        )
        .unwrap();
        edit(&mut v);
        serde_json::from_value(v).expect("a row")
    }

    /// Each kind of row says in its headline whether the re-check holds it: the end-to-end
    /// tests meet only the kinds the presets' real disagreements give (a bracket the re-check
    /// does not confirm), so the table's other branches are checked here.
    #[test]
    fn the_onset_line_says_what_the_re_check_found() {
        assert_eq!(onset_line(&row(|_| {})), "none in the range");
        let unconfirmed = |v: &mut serde_json::Value| v["recheck"]["confirmed"] = false.into();
        assert_eq!(
            onset_line(&row(unconfirmed)),
            "none in the range, NOT CONFIRMED by the re-check"
        );
        let whirl_from_bottom = |v: &mut serde_json::Value| {
            v["onset_rpm"] = 1000.0.into();
            v["recheck"] = serde_json::json!({"fidelity": "standard",
                "hi": [1000.0, {"class": "pendulum"}], "confirmed": false});
        };
        assert_eq!(
            onset_line(&row(whirl_from_bottom)),
            "at or below 1000 r/min (whirl at the lowest speed; NOT CONFIRMED by the re-check)"
        );
        let bracket = |v: &mut serde_json::Value| {
            v["onset_rpm"] = 11406.25.into();
            v["bracket_rpm"] = serde_json::json!([11390.625, 11406.25]);
            v["converged"] = false.into();
            v["recheck"] = serde_json::json!({"fidelity": "standard",
                "lo": [11390.625, {"class": "pendulum"}],
                "hi": [11406.25, {"class": "pendulum"}], "confirmed": false});
        };
        assert_eq!(
            onset_line(&row(bracket)),
            "11406.2 r/min (bracket 11390.6-11406.2, NOT CONFIRMED by the re-check)"
        );
        let within_tol = |v: &mut serde_json::Value| {
            bracket(v);
            v["converged"] = true.into();
            v["recheck"]["within_tol"] = true.into();
        };
        assert_eq!(
            onset_line(&row(within_tol)),
            "11406.2 r/min (bracket 11390.6-11406.2)"
        );
        let not_converged = |v: &mut serde_json::Value| {
            bracket(v);
            v["recheck"]["confirmed"] = true.into();
        };
        assert_eq!(
            onset_line(&row(not_converged)),
            "11406.2 r/min (bracket 11390.6-11406.2, NOT converged)"
        );
        let undecided = |v: &mut serde_json::Value| {
            v["undecided"] = true.into();
            v["converged"] = false.into();
        };
        assert_eq!(onset_line(&row(undecided)), "UNDECIDED (failed drops)");
        // Failed drops below an onset come before what the re-check says.
        let undecided_bracket = |v: &mut serde_json::Value| {
            bracket(v);
            undecided(v);
        };
        assert_eq!(
            onset_line(&row(undecided_bracket)),
            "11406.2 r/min (bracket 11390.6-11406.2, UNDECIDED: failed drops below it)"
        );
        let undecided_bottom = |v: &mut serde_json::Value| {
            whirl_from_bottom(v);
            undecided(v);
        };
        assert_eq!(
            onset_line(&row(undecided_bottom)),
            "at or below 1000 r/min (whirl at the lowest speed; UNDECIDED: failed drops below it)"
        );
    }
}
