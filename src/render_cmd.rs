//! `whirlmap render DIR`: draw the design charts of a sweep's results directory.
//!
//! The folder is locked while the charts are drawn (a sweep writing it is not raced), its
//! inputs are checked against its manifest first (a `critical.json` or orbit the run did not
//! write is refused rather than drawn: `whirlmap_sweep::folder`), charts the data no longer
//! has are removed, and the manifest's file list is brought up to date.

use std::path::PathBuf;

use whirlmap_plot::{render_all, ChartError};
use whirlmap_sweep::folder::{self, FolderLock};

/// Arguments of `whirlmap render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Results directory of a sweep (holding points.jsonl, optionally critical.json and
    /// orbits/); the charts are written to DIR/charts/ as PNG and SVG.
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

/// Draws every chart whose data exists and prints the files written.
pub fn run(a: &RenderArgs) -> Result<(), RenderFailure> {
    if !a.dir.is_dir() {
        return Err(RenderFailure::Input(anyhow::anyhow!(
            "no sweep results: {} is not a folder",
            a.dir.display()
        )));
    }
    let _lock = FolderLock::acquire(&a.dir, "render").map_err(|e| match e.exit_code() {
        4 => RenderFailure::Output(e.into()),
        _ => RenderFailure::Input(e.into()),
    })?;
    let inputs = folder::reader_inputs(&a.dir);
    let checked = folder::check_inputs(&a.dir, &inputs).map_err(|problems| {
        RenderFailure::Input(anyhow::anyhow!(
            "render refused:\n  - {}",
            problems.join("\n  - ")
        ))
    })?;
    for w in &checked.warnings {
        errln!("warning: {w}");
    }
    let written = render_all(&a.dir).map_err(|e: ChartError| {
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
    Ok(())
}
