//! The names of the files and folders of a results folder, in one place.
//!
//! A sweep's folder holds [`POINTS_FILE`], [`TIMINGS_FILE`], [`SUMMARY_FILE`] and
//! [`MANIFEST_FILE`]; its extras add [`CRITICAL_FILE`] and [`CRITICAL_CSV_FILE`],
//! [`ORBITS_DIR`] and [`PROBABILITY_DIR`] (an ensemble's folder: [`MEMBERS_FILE`],
//! [`CELLS_FILE`], [`CONTOURS_FILE`] and its own [`MANIFEST_FILE`]); the charts go to
//! [`CHARTS_DIR`].

/// One JSON record per grid point, in grid order.
pub const POINTS_FILE: &str = "points.jsonl";
/// Per-point wall times (not in [`POINTS_FILE`], whose bytes must not depend on the run).
pub const TIMINGS_FILE: &str = "timings.jsonl";
/// One CSV row per grid point.
pub const SUMMARY_FILE: &str = "summary.csv";
/// A sweep's touchdown-bearing survival report, when its scene turns the bearing analysis on.
pub const BEARING_REPORT_FILE: &str = "bearing.md";
/// Run metadata and the list of every file the run wrote.
pub const MANIFEST_FILE: &str = "manifest.json";
/// Critical-speed results (a JSON list of [`crate::critical::CriticalRow`]).
pub const CRITICAL_FILE: &str = "critical.json";
/// The same rows as a table (one line per friction coefficient).
pub const CRITICAL_CSV_FILE: &str = "critical.csv";
/// The critical search's classified drops while it runs, one JSON line each (a resumed run
/// reuses them); removed once [`CRITICAL_FILE`] is written.
pub const CRITICAL_DROPS_FILE: &str = "critical-drops.jsonl";
/// Folder of the recorded orbits of Fig. 3 ([`orbit_file`], [`orbit_error_file`]).
pub const ORBITS_DIR: &str = "orbits";
/// Folder of the charts.
pub const CHARTS_DIR: &str = "charts";
/// Folder of a sweep's probability ensemble (its [`CONTOURS_FILE`] feeds Fig. 4's band).
pub const PROBABILITY_DIR: &str = "probability";
/// A shard's part of the grid.
pub const SHARD_FILE: &str = "shard.json";
/// The report of a comparison written into a results folder.
pub const COMPARE_REPORT_FILE: &str = "compare.md";
/// The class map of a comparison written into a results folder.
pub const COMPARE_CLASSES_FILE: &str = "compare-classes.png";
/// The lock file of a results folder.
pub const LOCK_FILE: &str = ".whirlmap.lock";
/// Where `--overwrite` keeps the previous run's files until the new run's first records are
/// written and synced.
pub const PREVIOUS_DIR: &str = "previous-run";
/// An ensemble's member records, one per line.
pub const MEMBERS_FILE: &str = "members.jsonl";
/// An ensemble's per-cell results, one per line.
pub const CELLS_FILE: &str = "cells.jsonl";
/// An ensemble's probability contours.
pub const CONTOURS_FILE: &str = "contours.json";
/// The adaptive refinement's results.
pub const ADAPTIVE_FILE: &str = "adaptive.json";
/// The adaptive refinement's evaluated corners while it runs (a header line with the spec and
/// the build, then one JSON line per corner; `--resume` reuses them); removed once
/// [`ADAPTIVE_FILE`] is written.
pub const ADAPTIVE_CORNERS_FILE: &str = "adaptive-corners.jsonl";
/// An ensemble's per-cell results as a table.
pub const CELLS_CSV_FILE: &str = "cells.csv";
/// A work-precision study's rows (`whirlmap accuracy`).
pub const ACCURACY_CSV_FILE: &str = "accuracy.csv";
/// A work-precision study's report.
pub const ACCURACY_REPORT_FILE: &str = "accuracy.md";
/// A work-precision study's whole result (every run), which its charts are drawn from.
pub const STUDY_FILE: &str = "study.json";
/// The stems of a work-precision study's charts (`.png` and `.svg` each): error against RHS
/// evaluations, and against wall time.
pub const WORK_PRECISION_CHARTS: [&str; 2] = ["work_precision", "work_precision_wall"];

/// The stems of every chart whirlmap draws into a [`CHARTS_DIR`] (each as `.png` and `.svg`):
/// a sweep's and an ensemble's.
pub const CHART_STEMS: [&str; 9] = [
    "fig3_orbits",
    "fig4_critical",
    "fig4_probability",
    "fig5_max_force",
    "fig6_peak_power",
    "classes",
    "peak_temperature",
    "drops_to_failure",
    "contact_pressure",
];

/// Whether `name`, a file in a [`CHARTS_DIR`], is a chart whirlmap draws ([`CHART_STEMS`],
/// `.png` or `.svg`): the only files there that `render`, `--overwrite` and `--resume` remove.
pub fn is_chart_file(name: &str) -> bool {
    name.rsplit_once('.')
        .is_some_and(|(stem, ext)| matches!(ext, "png" | "svg") && CHART_STEMS.contains(&stem))
}

/// Whether `name`, a file in an [`ORBITS_DIR`], is one whirlmap writes there: an orbit
/// ([`orbit_file`]) or a failed panel's error ([`orbit_error_file`]).
pub fn is_orbit_file(name: &str) -> bool {
    name.ends_with(".json") || name.ends_with(".error.txt")
}

/// The file name of a recorded orbit (in [`ORBITS_DIR`]): `stem.json`.
pub fn orbit_file(stem: &str) -> String {
    format!("{stem}.json")
}

/// The file name of an orbit whose drop failed (in [`ORBITS_DIR`]): `stem.error.txt`.
pub fn orbit_error_file(stem: &str) -> String {
    format!("{stem}.error.txt")
}
