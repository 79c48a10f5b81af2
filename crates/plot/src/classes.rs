//! The class map: the orbit class over release speed and friction, and the same map with
//! marked cells (a comparison's changed cells).

use std::path::Path;

use whirlmap_results::grid::Grid;

use crate::axes::CHART_SIZE;
use crate::error::ChartError;
use crate::heatmap::{with_slice, GridFigure, GridMode};
use crate::render::render;
/// Draws the class map of `grid` to `path` (PNG or SVG by extension) with the cells
/// `marked` (speed index, friction index into the grid's axes) outlined in black: the changed
/// cells of a comparison.
pub fn draw_marked_class_map(
    path: &Path,
    grid: &Grid,
    title: &str,
    marked: &[(usize, usize)],
) -> Result<(), ChartError> {
    let figure = GridFigure {
        grid,
        title: with_slice(title, &grid.slice),
        mode: GridMode::MarkedClasses(marked),
        bar_label: "",
        whirl_label: None,
        limit: None,
    };
    render(path, CHART_SIZE, &figure)?;
    Ok(())
}

/// The class map of `grid` (`charts/classes`).
pub(crate) fn figure(grid: &Grid) -> GridFigure<'_> {
    GridFigure {
        grid,
        title: with_slice("Orbit class over release speed and friction", &grid.slice),
        mode: GridMode::Classes,
        bar_label: "",
        whirl_label: None,
        limit: None,
    }
}
