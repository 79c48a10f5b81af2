//! The hottest node's peak temperature over release speed and friction (records made with
//! the thermal model only), in degrees Celsius as a designer reads it (records keep kelvin).

use whirlmap_results::grid::Grid;

use crate::heatmap::{with_slice, GridFigure, GridMode, Metric};

/// The figure of `grid` (`charts/peak_temperature`).
pub(crate) fn figure(grid: &Grid) -> GridFigure<'_> {
    GridFigure {
        grid,
        title: with_slice("Peak touchdown-bearing temperature", &grid.slice),
        mode: GridMode::Metric(Metric::linear(|r| r.peak_temperature_k.map(|k| k - 273.15))),
        bar_label: "hottest node peak temperature (\u{b0}C = K - 273.15)",
        whirl_label: None,
        limit: None,
    }
}
