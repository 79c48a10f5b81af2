//! Every chart of a results folder, drawn into its `charts/` folder.

use std::path::{Path, PathBuf};

use whirlmap_results::files::CHARTS_DIR;
use whirlmap_results::files::{MANIFEST_FILE, POINTS_FILE};
use whirlmap_results::grid::{assemble_grid, distinct_sorted};
use whirlmap_results::read::LoadError;

use crate::axes::CHART_SIZE;
use crate::error::ChartError;
use crate::fig3_orbits::{orbit_figure_size, OrbitPanels};
use crate::fig4::{band_points, Fig4};
use crate::load::{load_critical, load_orbits, load_points, load_probability};
use crate::render::{format_quantity, render, Figure};

pub(crate) fn write_both<F: Figure>(
    out_dir: &Path,
    stem: &str,
    size: (u32, u32),
    figure: &F,
    written: &mut Vec<PathBuf>,
) -> Result<(), ChartError> {
    for ext in ["png", "svg"] {
        let name = format!("{stem}.{ext}");
        // What render, --overwrite and --resume may remove is known by these names.
        debug_assert!(whirlmap_results::files::is_chart_file(&name), "{name}");
        let path = out_dir.join(name);
        render(&path, size, figure)?;
        written.push(path);
    }
    Ok(())
}

/// The charts a sweep's spec asks for (its `charts` list, as its manifest records it), by the
/// spec's names (`orbits`, `critical`, `max_force`, `peak_power`, `classes`,
/// `peak_temperature`, `drops_to_failure`, `contact_pressure`); `None` when the folder has no manifest or the spec lists none: then
/// every chart the data allows is drawn.
fn wanted_charts(dir: &Path) -> Option<Vec<String>> {
    #[derive(serde::Deserialize)]
    struct Manifest {
        spec: Option<Spec>,
    }
    #[derive(serde::Deserialize)]
    struct Spec {
        #[serde(default)]
        charts: Vec<String>,
    }
    let text = std::fs::read_to_string(dir.join(MANIFEST_FILE)).ok()?;
    let charts = serde_json::from_str::<Manifest>(&text).ok()?.spec?.charts;
    (!charts.is_empty()).then_some(charts)
}

/// Draws every chart whose data exists in the results directory `dir` into `dir/charts/`, as
/// PNG and SVG: `fig5_max_force`, `fig6_peak_power` and `classes` from `points.jsonl`
/// (required), `peak_temperature` if the records carry temperatures, `drops_to_failure` and
/// `contact_pressure` if they carry the bearing analysis's results, `fig4_critical` if
/// `critical.json` exists, `fig3_orbits` if `orbits/` holds orbit files, `fig4_probability` if
/// `contours.json` (an ensemble's) exists (then `points.jsonl` is optional). A sweep whose
/// spec lists its `charts` gets only those. Returns the paths written.
pub fn render_all(dir: &Path) -> Result<Vec<PathBuf>, ChartError> {
    render_all_keeping(dir, &[])
}

/// [`render_all`], leaving the charts named in `keep` (file stems such as
/// [`FIG3_ORBITS`]) as they are when this rendering does not draw them: a chart whose
/// data the run wrote but the folder no longer holds (orbit files left out of a repository)
/// is kept rather than removed as stale.
pub fn render_all_keeping(dir: &Path, keep: &[&str]) -> Result<Vec<PathBuf>, ChartError> {
    // An ensemble's results: Fig. 4 with probability bands (docs/probability.md); none for
    // an ensemble without a friction axis, whose old chart, if any, is stale.
    let prob = crate::probability::render_probability(dir)?;
    let ensemble = dir.join(whirlmap_results::files::CONTOURS_FILE).is_file();
    if ensemble && !dir.join(POINTS_FILE).exists() {
        remove_stale_charts(&dir.join(CHARTS_DIR), &prob)?;
        return Ok(prob);
    }
    let rows = load_points(dir)?;
    if rows.is_empty() {
        // Nothing to draw: an empty file, or a run killed before its first record.
        return Err(LoadError::Parse {
            path: dir.join(POINTS_FILE),
            line: 1,
            message: "no sweep results: the file holds no complete record".into(),
        }
        .into());
    }
    let critical = load_critical(dir)?;
    let orbits = load_orbits(dir)?;
    let grid = assemble_grid(&rows);

    let out_dir = dir.join(CHARTS_DIR);
    std::fs::create_dir_all(&out_dir).map_err(|cause| ChartError::Write {
        path: out_dir.clone(),
        cause,
    })?;
    let wanted = wanted_charts(dir);
    // The maps are over release speed and friction: a run without both axes (a sweep over
    // clearance and friction) has none, rather than one drawn at speed 0.
    let mapped = rows
        .iter()
        .all(|r| r.speed_rpm().is_some() && r.mu().is_some());
    let wants = |name: &str| {
        let map = !matches!(name, "critical" | "orbits");
        (mapped || !map) && wanted.as_ref().is_none_or(|w| w.iter().any(|c| c == name))
    };
    let mut written = Vec::new();
    if wants("max_force") {
        let fig5 = crate::fig5::figure(&grid);
        write_both(&out_dir, "fig5_max_force", CHART_SIZE, &fig5, &mut written)?;
    }
    if wants("peak_power") {
        let fig6 = crate::fig6::figure(&grid);
        write_both(&out_dir, "fig6_peak_power", CHART_SIZE, &fig6, &mut written)?;
    }
    if wants("classes") {
        let classes = crate::classes::figure(&grid);
        write_both(&out_dir, "classes", CHART_SIZE, &classes, &mut written)?;
    }
    if wants("peak_temperature") && rows.iter().any(|r| r.peak_temperature_k.is_some()) {
        // Only records made with the thermal model carry temperatures.
        let temps = crate::peak_temperature::figure(&grid);
        write_both(
            &out_dir,
            "peak_temperature",
            CHART_SIZE,
            &temps,
            &mut written,
        )?;
    }
    // Only records made with the bearing analysis carry its results.
    // (A drop without damage has no drops to failure, but a pressure.)
    if wants("drops_to_failure") && rows.iter().any(|r| r.peak_contact_pressure_pa.is_some()) {
        let fig = crate::bearing_life::drops_to_failure(&grid);
        write_both(&out_dir, "drops_to_failure", CHART_SIZE, &fig, &mut written)?;
    }
    if wants("contact_pressure") && rows.iter().any(|r| r.peak_contact_pressure_pa.is_some()) {
        let fig = crate::bearing_life::contact_pressure(&grid);
        write_both(&out_dir, "contact_pressure", CHART_SIZE, &fig, &mut written)?;
    }
    if let Some(rows) = critical.as_ref().filter(|_| wants("critical")) {
        let probability = load_probability(dir)?;
        let band = probability.as_ref().map(band_points);
        let label = probability.as_ref().map(|c| {
            let top = c
                .groups
                .iter()
                .filter_map(|g| g.speeds_rpm.last().copied())
                .fold(0.0, f64::max);
            let slice = match crate::probability::slice(c).1 {
                Some(n) => format!(", {n}"),
                None => String::new(),
            };
            format!(
                "over release conditions ({} drops per cell, up to {} r/min{slice})",
                c.members,
                format_quantity(top)
            )
        });
        let fig4 = Fig4 {
            rows,
            band: band.as_deref().zip(label),
            title: "Fig. 4: critical speed of backward whirl".to_string(),
        };
        write_both(&out_dir, "fig4_critical", CHART_SIZE, &fig4, &mut written)?;
    }
    if !orbits.is_empty() && wants("orbits") {
        let speeds = distinct_sorted(orbits.iter().map(|o| o.speed_rpm));
        let title = match speeds.as_slice() {
            [s] => format!(
                "Fig. 3: orbits relative to the race at {} r/min",
                format_quantity(*s)
            ),
            _ => "Fig. 3: orbits relative to the race".to_string(),
        };
        let fig3 = OrbitPanels {
            orbits: &orbits,
            title,
        };
        write_both(
            &out_dir,
            FIG3_ORBITS,
            orbit_figure_size(orbits.len()),
            &fig3,
            &mut written,
        )?;
    }
    written.extend(prob);
    let mut spared = written.clone();
    for stem in keep {
        for ext in ["png", "svg"] {
            spared.push(out_dir.join(format!("{stem}.{ext}")));
        }
    }
    remove_stale_charts(&out_dir, &spared)?;
    Ok(written)
}

/// The file stem of Fig. 3 (orbits) in a results folder's `charts/`.
pub const FIG3_ORBITS: &str = "fig3_orbits";

/// Removes the charts in `dir` that this rendering did not draw (a Fig. 4 left from an
/// earlier spec with a critical search, say), so `charts/` shows only what the data holds.
/// Only whirlmap's charts ([`whirlmap_results::files::is_chart_file`]) are removed: a file of
/// the user's in `charts/` stays.
pub(crate) fn remove_stale_charts(dir: &Path, written: &[PathBuf]) -> Result<(), ChartError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let p = e.path();
        let chart = whirlmap_results::files::is_chart_file(&e.file_name().to_string_lossy());
        if chart && p.is_file() && !written.iter().any(|w| w == &p) {
            std::fs::remove_file(&p).map_err(|cause| ChartError::Write {
                path: p.clone(),
                cause,
            })?;
        }
    }
    Ok(())
}
