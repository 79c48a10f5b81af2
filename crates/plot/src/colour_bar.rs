//! The colour scale of the heat maps and its bar.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;

use crate::marks::{CONTOUR, LIMIT};
use crate::render::{
    text_style, tick_formatter, DrawResult, AXIS_DESC_FONT, TICK_FONT, X_LABEL_AREA,
};
use plotters::element::DashedPathElement;

/// The colour-scale colour of `v` in `lo..hi` (ends for anything outside, mid for NaN).
pub(crate) fn scale_colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    let t = (v - lo) / (hi - lo);
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    ViridisRGB::get_color_normalized(t, 0.0, 1.0)
}

/// What a colour bar shows.
pub(crate) struct ColourBar<'a> {
    /// The scale's low end (a decade exponent on a log scale).
    pub(crate) lo: f64,
    /// The scale's high end.
    pub(crate) hi: f64,
    /// The contour levels, drawn across the bar.
    pub(crate) levels: &'a [f64],
    /// A limit, drawn across the bar dashed in the limit colour.
    pub(crate) limit: Option<f64>,
    /// The bar's axis title.
    pub(crate) label: &'a str,
    /// A tick's text on a log scale (a linear scale uses the shared tick formatter).
    pub(crate) tick: &'a dyn Fn(&f64) -> String,
    /// Whether the scale is logarithmic (then about one tick per decade, labelled by `tick`).
    pub(crate) log: bool,
}

pub(crate) fn draw_colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    b: &ColourBar,
) -> DrawResult<DB> {
    let (lo, hi) = (b.lo, b.hi);
    let mut bar = ChartBuilder::on(area)
        .margin_top(12)
        .margin_bottom(4 + X_LABEL_AREA)
        .margin_left(8)
        .margin_right(4)
        .right_y_label_area_size(96)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    let linear = tick_formatter(hi - lo);
    let fmt: &dyn Fn(&f64) -> String = if b.log { b.tick } else { &linear };
    // On a log scale one tick per decade (plotters picks round values of the exponent);
    // on one shorter than two decades, where that would leave one tick or none, up to six
    // at round values of the exponent, each labelled with the figures that tell it apart.
    let ticks = match b.log {
        true if hi - lo < 2.0 => 6,
        true => ((hi - lo).ceil() as usize + 1).clamp(2, 10),
        false => 8,
    };
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(ticks)
        // Ticks outside the bar, so a label never touches a contour level's line.
        .set_tick_mark_size(LabelAreaPosition::Right, 6)
        .y_label_formatter(fmt)
        .y_desc(b.label)
        .label_style(text_style(TICK_FONT))
        .axis_desc_style(text_style(AXIS_DESC_FONT))
        .axis_style(RGBColor(90, 90, 90).stroke_width(1))
        .draw()?;
    const STEPS: usize = 128;
    bar.draw_series((0..STEPS).map(|k| {
        let a = lo + (hi - lo) * k as f64 / STEPS as f64;
        let b = lo + (hi - lo) * (k + 1) as f64 / STEPS as f64;
        let c = scale_colour((a + b) / 2.0, lo, hi);
        Rectangle::new([(0.0, a), (1.0, b)], c.filled())
    }))?;
    bar.draw_series(
        b.levels
            .iter()
            .map(|&l| PathElement::new(vec![(0.0, l), (1.0, l)], CONTOUR.stroke_width(2))),
    )?;
    if let Some(l) = b.limit {
        bar.draw_series([DashedPathElement::new(
            vec![(0.0, l), (1.0, l)],
            6,
            4,
            LIMIT.stroke_width(3),
        )])?;
    }
    bar.draw_series([Rectangle::new(
        [(0.0, lo), (1.0, hi)],
        RGBColor(90, 90, 90).stroke_width(1),
    )])?;
    Ok(())
}
