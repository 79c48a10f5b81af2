//! `whirlmap render DIR`: redraw the charts of a results directory: a sweep's (or a merge's)
//! design charts, an ensemble's Fig. 4 with probability bands. An adaptive map
//! (`adaptive.json`) has no charts: render says so and exits 0.
//!
//! The folder is locked while the charts are drawn (a sweep writing it is not raced), its
//! inputs are checked against its manifest first (a `critical.json` or orbit the run did not
//! write is refused rather than drawn: `whirlmap_sweep::folder`), charts the data no longer
//! has are removed, and the manifest's file list is brought up to date.

use std::path::{Path, PathBuf};

use whirlmap_plot::{render_all_keeping, ChartError, FIG3_ORBITS};
use whirlmap_sweep::folder::{self, FolderLock};
use whirlmap_sweep::results::files::{ADAPTIVE_FILE, CONTOURS_FILE, ORBITS_DIR, POINTS_FILE};

/// Arguments of `whirlmap render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Results directory of a sweep or merge (holding points.jsonl, optionally critical.json
    /// and orbits/) or of an ensemble (contours.json); the charts are written to DIR/charts/
    /// as PNG and SVG.
    pub dir: PathBuf,
}

/// Why rendering failed: bad or missing input (exit 2) or an unwritable output (exit 4).
pub enum RenderFailure {
    /// DIR has no points.jsonl, an input file is unreadable, malformed or not the run's, or
    /// another process writes DIR.
    Input(anyhow::Error),
    /// A chart or the charts directory could not be written.
    Output(anyhow::Error),
}

/// Whether `dir` holds only an adaptive map: `adaptive.json` and no sweep records or ensemble
/// contours (the files charts are drawn from).
fn is_adaptive_map(dir: &Path) -> bool {
    dir.join(ADAPTIVE_FILE).is_file()
        && !dir.join(POINTS_FILE).is_file()
        && !dir.join(CONTOURS_FILE).is_file()
}

/// Draws every chart whose data exists and prints the files written; says so and draws
/// nothing for an adaptive map, which has no charts.
pub fn run(a: &RenderArgs) -> Result<(), RenderFailure> {
    if !a.dir.is_dir() {
        return Err(RenderFailure::Input(anyhow::anyhow!(
            "no sweep results: {} is not a folder",
            a.dir.display()
        )));
    }
    if is_adaptive_map(&a.dir) {
        outln!(
            "{}: an adaptive map ({ADAPTIVE_FILE}); `whirlmap adaptive` draws no charts, so there \
             are none to draw",
            a.dir.display()
        );
        return Ok(());
    }
    // Nothing to draw from: refused before the folder is locked (no lock file left in it): no
    // records (a points.jsonl whose first megabyte holds no whole line) and no contours.
    let records = std::fs::File::open(a.dir.join(POINTS_FILE)).is_ok_and(|f| {
        let mut head = Vec::new();
        std::io::Read::read_to_end(&mut std::io::Read::take(f, 1 << 20), &mut head).is_ok()
            && (head.contains(&b'\n') || head.len() == 1 << 20)
    });
    // (A folder a run is writing is refused as in use, below, whatever it holds yet.)
    let writing = folder::running_writer(&a.dir).is_some();
    if !writing && !records && !a.dir.join(CONTOURS_FILE).is_file() {
        if a.dir.join(POINTS_FILE).is_file() {
            return Err(RenderFailure::Input(anyhow::anyhow!(
                "{}: line 1: no sweep results: the file holds no complete record",
                a.dir.join(POINTS_FILE).display()
            )));
        }
        return Err(RenderFailure::Input(anyhow::anyhow!(
            "no sweep results: {} holds neither {POINTS_FILE} (a sweep's) nor {CONTOURS_FILE} \
             (an ensemble's)",
            a.dir.display()
        )));
    }
    let _lock = FolderLock::acquire(&a.dir, "render").map_err(|e| match e.exit_code() {
        4 => RenderFailure::Output(e.into()),
        _ => RenderFailure::Input(e.into()),
    })?;
    // An ensemble's folder (its contours, no sweep records) has the ensemble's own manifest,
    // which lists no files: there is nothing of a sweep's to check.
    let ensemble = a.dir.join(CONTOURS_FILE).is_file() && !a.dir.join(POINTS_FILE).is_file();
    let inputs = folder::reader_inputs(&a.dir);
    let checked = if ensemble {
        Ok(folder::Checked::default())
    } else {
        folder::check_inputs(&a.dir, &inputs)
    };
    let checked = checked.map_err(|problems| {
        RenderFailure::Input(anyhow::anyhow!(
            "render refused:\n  - {}",
            problems.join("\n  - ")
        ))
    })?;
    for w in &checked.warnings {
        errln!("warning: {w}");
    }
    // Orbit files the run wrote but the folder no longer holds (a clone of the repository
    // leaves them out): Fig. 3 cannot be redrawn, and is kept as the run drew it.
    let missing_orbits = checked
        .manifest
        .as_ref()
        .and_then(|m| m.files.as_ref())
        .map(|files| {
            files
                .keys()
                .filter(|rel| rel.starts_with(&format!("{ORBITS_DIR}/")))
                .filter(|rel| !a.dir.join(rel).is_file())
                .count()
        })
        .unwrap_or(0);
    let keep: &[&str] = if missing_orbits > 0 {
        errln!(
            "warning: {missing_orbits} orbit file(s) the run wrote are not in {} (a clone of \
             the repository leaves {ORBITS_DIR}/ out): {FIG3_ORBITS} is kept as the run drew it; \
             rerun the sweep to redraw it",
            a.dir.join(ORBITS_DIR).display()
        );
        &[FIG3_ORBITS]
    } else {
        &[]
    };
    let written = render_all_keeping(&a.dir, keep).map_err(|e: ChartError| {
        if e.is_output() {
            RenderFailure::Output(e.into())
        } else {
            RenderFailure::Input(e.into())
        }
    })?;
    if checked.listed {
        folder::relist_tree(&a.dir, whirlmap_sweep::results::files::CHARTS_DIR)
            .map_err(|e| RenderFailure::Output(e.into()))?;
    }
    for p in &written {
        outln!("{}", p.display());
    }
    if written.is_empty() && ensemble {
        outln!(
            "{}: {}",
            a.dir.display(),
            whirlmap_plot::probability::NO_MU_AXIS
        );
    }
    Ok(())
}
