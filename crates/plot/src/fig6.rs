//! Fig. 6: the peak heat power over release speed and friction (whirl cells hatched,
//! outside the colour scale).

use whirlmap_results::grid::Grid;

use crate::heatmap::{with_slice, GridFigure, GridMode, Metric};

/// The figure of `grid` (`charts/fig6_peak_power`).
pub(crate) fn figure(grid: &Grid) -> GridFigure<'_> {
    GridFigure {
        grid,
        title: with_slice("Fig. 6: peak heat power", &grid.slice),
        mode: GridMode::Metric(Metric::linear(|r| r.peak_heat_power_w)),
        bar_label: "peak heat power (W)",
        whirl_label: None,
        limit: None,
    }
}
