//! The temperature chart of one thermal drop: every network node's temperature over time, and
//! beneath it the thermally induced load F_th (eq. 30) and the heat power H (eq. 14). Drawn from the report's decimated
//! temperature history with the shared styling of [`crate::render`].

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use whirlmap_core::thermal::network::NODES;
use whirlmap_core::thermal::ThermalSample;

use crate::render::{
    draw_mesh, draw_thin_line, render, text_style, tick_formatter, with_header, DrawResult, Figure,
    RenderError, AXIS_COLOUR, AXIS_DESC_FONT, TICK_FONT,
};

/// Size (width, height) in pixels of the temperature figure.
pub const TEMPERATURE_FIGURE_SIZE: (u32, u32) = (1000, 1100);

/// One colour per node, in network node order (tab10).
const NODE_COLOURS: [RGBColor; NODES] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(127, 127, 127),
];
const LOAD_COLOUR: RGBColor = RGBColor(190, 50, 40);

/// Readable node names for the legend, in network node order.
const NODE_LABELS: [&str; NODES] = [
    "rotor",
    "inner race",
    "inner lubricant",
    "balls",
    "outer lubricant",
    "outer race",
    "housing",
];

/// 0 deg C in kelvin.
const KELVIN_AT_0_C: f64 = 273.15;

/// Draws node temperatures (K, with deg C on the right axis), F_th (N) and the heat power (W) against time to `path` (`.png` or `.svg`).
pub fn draw_temperatures(
    path: &Path,
    title: &str,
    series: &[ThermalSample],
) -> Result<(), RenderError> {
    render(
        path,
        TEMPERATURE_FIGURE_SIZE,
        &TemperatureFigure { title, series },
    )
}

struct TemperatureFigure<'a> {
    title: &'a str,
    series: &'a [ThermalSample],
}

/// (min, max) of finite values, widened to a non-empty range with a little padding.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !(lo <= hi) {
        return (0.0, 1.0);
    }
    let span = (hi - lo).max(1e-3 * hi.abs().max(1.0));
    (lo - 0.04 * span, hi + 0.06 * span)
}

impl Figure for TemperatureFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(root, 46, self.title, 22.0)?;
        let h = body.dim_in_pixel().1 as f64;
        let (top, rest) = body.split_vertically((h * 0.56).round() as u32);
        let (middle, bottom) = rest.split_vertically((h * 0.22).round() as u32);
        self.draw_temperature_panel(&top)?;
        self.draw_series_panel(
            &middle,
            "Thermally induced bearing load F_th, eq. 30",
            "F_th (N)",
            "N",
            |s| s.load_n,
        )?;
        self.draw_series_panel(
            &bottom,
            "Heat power H = H_s + H_i + H_o, macro-step mean",
            "H (W)",
            "W",
            |s| s.heat_w,
        )
    }
}

impl TemperatureFigure<'_> {
    fn t_range(&self) -> (f64, f64) {
        let end = self.series.last().map_or(1.0, |s| s.t_s);
        (0.0, if end > 0.0 { end } else { 1.0 })
    }

    fn draw_temperature_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> DrawResult<DB> {
        let hottest = self
            .series
            .iter()
            .flat_map(|s| s.temperatures_k.iter().copied())
            .fold(f64::NEG_INFINITY, f64::max);
        let caption = if hottest.is_finite() {
            format!(
                "Node temperatures (hottest {hottest:.1} K, {:.1} \u{b0}C)",
                hottest - KELVIN_AT_0_C
            )
        } else {
            "Node temperatures".to_string()
        };
        let area = with_header(area, 34, &caption, 17.0)?;
        let (t0, t1) = self.t_range();
        let (y0, y1) = range(
            self.series
                .iter()
                .flat_map(|s| s.temperatures_k.iter().copied()),
        );
        let mut chart = ChartBuilder::on(&area)
            .margin_top(8)
            .margin_left(20)
            .margin_right(8)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .right_y_label_area_size(78)
            .build_cartesian_2d(t0..t1, y0..y1)?
            .set_secondary_coord(t0..t1, (y0 - KELVIN_AT_0_C)..(y1 - KELVIN_AT_0_C));
        draw_mesh(&mut chart, "time (s)", "temperature (K)", 10, 8)?;
        // The same scale in degrees Celsius on the right, as a designer reads it.
        let c_fmt = tick_formatter(y1 - y0);
        chart
            .configure_secondary_axes()
            .y_desc("temperature (\u{b0}C)")
            .y_labels(8)
            .y_label_formatter(&c_fmt)
            .label_style(text_style(TICK_FONT))
            .axis_desc_style(text_style(AXIS_DESC_FONT))
            .axis_style(AXIS_COLOUR.stroke_width(1))
            .draw()?;
        for k in 0..NODES {
            let pts: Vec<(f64, f64)> = self
                .series
                .iter()
                .map(|s| (s.t_s, s.temperatures_k[k]))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            draw_thin_line(&mut chart, &pts, NODE_COLOURS[k])?;
            let c = NODE_COLOURS[k];
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
                .label(NODE_LABELS[k])
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font(text_style(14.0))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .draw()?;
        Ok(())
    }

    /// A panel of one quantity of the samples against time, with its peak in the caption.
    fn draw_series_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        title: &str,
        y_desc: &str,
        unit: &str,
        value: impl Fn(&ThermalSample) -> f64,
    ) -> DrawResult<DB> {
        let peak = self
            .series
            .iter()
            .map(&value)
            .fold(f64::NEG_INFINITY, f64::max);
        let caption = if peak.is_finite() {
            format!("{title} (peak {peak:.1} {unit})")
        } else {
            title.to_string()
        };
        let area = with_header(area, 34, &caption, 17.0)?;
        let (t0, t1) = self.t_range();
        let (lo, hi) = range(self.series.iter().map(&value));
        let mut chart = ChartBuilder::on(&area)
            .margin_top(8)
            .margin_bottom(6)
            .margin_left(20)
            // Aligned with the temperature panel, whose right label area (deg C) is 78 px.
            .margin_right(8 + 78)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .build_cartesian_2d(t0..t1, lo.min(0.0)..hi.max(1.0))?;
        draw_mesh(&mut chart, "time (s)", y_desc, 10, 4)?;
        let pts: Vec<(f64, f64)> = self
            .series
            .iter()
            .map(|s| (s.t_s, value(s)))
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        draw_thin_line(&mut chart, &pts, LOAD_COLOUR)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whirlmap_core::thermal::network::node;

    #[test]
    fn node_labels_follow_the_network_order() {
        assert_eq!(NODE_LABELS.len(), node::NAMES.len());
        for (label, name) in NODE_LABELS.iter().zip(node::NAMES) {
            assert_eq!(label.replace(' ', "_"), name);
        }
    }
}
