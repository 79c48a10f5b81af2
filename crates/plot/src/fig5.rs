//! Fig. 5: the maximum contact force over release speed and friction (whirl cells hatched,
//! outside the colour scale).

use whirlmap_results::grid::Grid;

use crate::heatmap::{with_slice, GridFigure, GridMode, Metric};

/// The figure of `grid` (`charts/fig5_max_force`).
pub(crate) fn figure(grid: &Grid) -> GridFigure<'_> {
    GridFigure {
        grid,
        title: with_slice("Fig. 5: maximum contact force", &grid.slice),
        mode: GridMode::Metric(Metric::linear(|r| r.max_contact_force_n)),
        bar_label: "max contact force (N)",
        whirl_label: None,
        limit: None,
    }
}
