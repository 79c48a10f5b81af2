//! `whirlmap render DIR`: draw the design charts of a sweep's results directory.

use std::path::PathBuf;

use whirlmap_sweep::charts::{render_all, ChartError};

/// Arguments of `whirlmap render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Results directory of a sweep (holding points.jsonl, optionally critical.json and
    /// orbits/); the charts are written to DIR/charts/ as PNG and SVG.
    pub dir: PathBuf,
}

/// Why rendering failed: bad or missing input (exit 2) or an unwritable output (exit 4).
pub enum RenderFailure {
    /// DIR has no points.jsonl, or an input file is unreadable or malformed.
    Input(anyhow::Error),
    /// A chart or the charts directory could not be written.
    Output(anyhow::Error),
}

/// Draws every chart whose data exists and prints the files written.
pub fn run(a: &RenderArgs) -> Result<(), RenderFailure> {
    let written = render_all(&a.dir).map_err(|e: ChartError| {
        if e.is_output() {
            RenderFailure::Output(e.into())
        } else {
            RenderFailure::Input(e.into())
        }
    })?;
    for p in &written {
        outln!("{}", p.display());
    }
    Ok(())
}
