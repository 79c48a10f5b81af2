//! Chart drawing: PNG or SVG, chosen by the output file's extension.
//!
//! Every chart is a [`Figure`]: one drawing routine generic over the plotters backend, which
//! [`render`] runs on a bitmap (PNG) or SVG backend. Text uses only the embedded font
//! registered by [`crate::fonts`], so charts render on machines without system fonts.
//!
//! Bad data never panics: non-finite points are skipped, and empty data still yields a figure
//! with its axes (and, for orbits, the clearance circle).

use std::fmt::Display;
use std::path::{Path, PathBuf};

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use whirlmap_core::orbit::OrbitSample;

use crate::fonts::{self, FontError, FONT_FAMILY};
pub use crate::orbit::{draw_orbit, MAX_DRAWN_SAMPLES, ORBIT_FIGURE_SIZE};

/// Image file format, chosen from the output path's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Raster image (`.png`).
    Png,
    /// Vector image (`.svg`).
    Svg,
}

impl ImageFormat {
    /// The format for `path`'s extension (`.png` or `.svg`, any letter case).
    pub fn from_path(path: &Path) -> Result<Self, RenderError> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("png") {
            Ok(Self::Png)
        } else if ext.eq_ignore_ascii_case("svg") {
            Ok(Self::Svg)
        } else {
            Err(RenderError::UnsupportedExtension {
                path: path.to_path_buf(),
            })
        }
    }
}

/// Why a chart could not be written.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The output path's extension is neither `.png` nor `.svg`.
    #[error("cannot write chart {}: unsupported file extension, expected .png or .svg", path.display())]
    UnsupportedExtension {
        /// The requested output path.
        path: PathBuf,
    },
    /// The embedded font could not be registered.
    #[error("cannot write chart {}: {cause}", path.display())]
    Font {
        /// The requested output path.
        path: PathBuf,
        /// What went wrong with the font.
        cause: FontError,
    },
    /// Drawing or saving failed (e.g. the directory does not exist), or the size was zero.
    #[error("cannot write chart {}: {cause}", path.display())]
    Draw {
        /// The requested output path.
        path: PathBuf,
        /// The backend's description of the failure.
        cause: String,
    },
}

/// Result of drawing on a backend `DB`: plotters' own error type, so `?` works in figures.
pub type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A chart that can draw itself on any plotters backend, so the same code yields PNG and SVG.
pub trait Figure {
    /// Draws the figure on `root`, which covers the whole image and is already filled white.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Writes `figure` to `path` as a `size` (width, height) pixel PNG or SVG, by extension.
///
/// Registers the embedded font first. On a drawing error, any partly written file is removed.
pub fn render<F: Figure>(path: &Path, size: (u32, u32), figure: &F) -> Result<(), RenderError> {
    let format = ImageFormat::from_path(path)?;
    check_writable(path)?;
    fonts::register_embedded_fonts().map_err(|cause| RenderError::Font {
        path: path.to_path_buf(),
        cause,
    })?;
    let fail = |cause: &dyn Display| RenderError::Draw {
        path: path.to_path_buf(),
        cause: plain_cause(&cause.to_string()),
    };
    if size.0 == 0 || size.1 == 0 {
        return Err(fail(&format_args!(
            "image size {}x{} is empty",
            size.0, size.1
        )));
    }
    let result = match format {
        ImageFormat::Png => {
            let root = crate::text::GlyphTextBitMapBackend(BitMapBackend::new(path, size))
                .into_drawing_area();
            let r = draw_and_present(&root, figure).map_err(|e| fail(&e));
            drop(root); // a failed present is retried (and ignored) on drop
            r
        }
        ImageFormat::Svg => {
            let root = SVGBackend::new(path, size).into_drawing_area();
            let r = draw_and_present(&root, figure).map_err(|e| fail(&e));
            drop(root);
            r
        }
    };
    if result.is_err() {
        let _ = std::fs::remove_file(path);
    }
    result
}

/// Checks, before anything is drawn, that `path` can be written, so a chart that cannot be
/// saved fails with a sentence (which folder is missing, or that permission is denied)
/// instead of the backend's error dump after the drawing.
pub fn check_writable(path: &Path) -> Result<(), RenderError> {
    let fail = |cause: String| RenderError::Draw {
        path: path.to_path_buf(),
        cause,
    };
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(fail(if parent.exists() {
            format!("{} is a file, not a folder", parent.display())
        } else {
            format!("the folder {} does not exist", parent.display())
        }));
    }
    if path.is_dir() {
        return Err(fail("it is a folder".to_string()));
    }
    let existed = path.exists();
    match std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
    {
        Ok(_) => {
            if !existed {
                let _ = std::fs::remove_file(path);
            }
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::PermissionDenied => {
            Err(fail("permission denied".to_string()))
        }
        Err(e) => Err(fail(e.to_string())),
    }
}

/// The backend's error in words: plotters nests the I/O error in debug dumps
/// (`ImageError(IoError(Os { code: 28, kind: StorageFull, message: "No space left on
/// device" }))`); the OS message is what a person needs.
fn plain_cause(text: &str) -> String {
    // `Os { .. message: "..." }` and `Custom { kind: .., error: "..." }` both end in the words.
    let words = |key: &str| {
        text.split(key)
            .nth(1)
            .and_then(|m| m.split('"').next())
            .map(str::to_string)
    };
    words("message: \"")
        .or_else(|| words("error: \""))
        .unwrap_or_else(|| text.to_string())
}

pub(crate) fn draw_and_present<DB: DrawingBackend, F: Figure>(
    root: &DrawingArea<DB, Shift>,
    figure: &F,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    figure.draw(root)?;
    root.present()
}

/// Thins `samples` to at most `max_points` (at least 4) for drawing.
///
/// Keeps the first and last samples; splits the rest into equal buckets and keeps, from each,
/// its first sample (for the path's shape) and its largest finite contact force (so no force
/// peak is lost), in time order. Returns the samples unchanged if they already fit.
pub fn decimate_samples(samples: &[OrbitSample], max_points: usize) -> Vec<OrbitSample> {
    let max_points = max_points.max(4);
    let n = samples.len();
    if n <= max_points {
        return samples.to_vec();
    }
    let interior = n - 2;
    let buckets = (max_points - 2) / 2;
    let mut out = Vec::with_capacity(max_points);
    out.push(samples[0]);
    for b in 0..buckets {
        let start = 1 + b * interior / buckets;
        let end = 1 + (b + 1) * interior / buckets;
        if start >= end {
            continue;
        }
        out.push(samples[start]);
        let peak = (start..end)
            .filter(|&i| samples[i].contact_force_n.is_finite())
            .max_by(|&i, &j| {
                samples[i]
                    .contact_force_n
                    .total_cmp(&samples[j].contact_force_n)
            });
        if let Some(i) = peak.filter(|&i| i != start) {
            out.push(samples[i]);
        }
    }
    out.push(samples[n - 1]);
    out
}

// ---------------------------------------------------------------------------------------------
// Shared styling and layout helpers for all charts.

/// Draws an orbit panel into `plot`: a square, centred, equal-aspect plot of the rotor-centre
/// path (µm) about the race centre, the clearance circle dashed, release and end dotted.
/// Shared by the single-drop chart and the Fig. 3 grid; `label_areas` are the x and y label
/// areas (px), `ticks` the tick count on each axis.
pub(crate) fn orbit_panel<DB: DrawingBackend>(
    plot: &DrawingArea<DB, Shift>,
    path: &[(f64, f64)],
    clearance: Option<f64>,
    label_areas: (u32, u32),
    ticks: usize,
) -> DrawResult<DB> {
    let (x_lab, y_lab) = label_areas;
    // Symmetric range about the race centre covering the circle and every point.
    let extent = path
        .iter()
        .map(|(x, y)| x.abs().max(y.abs()))
        .chain(clearance)
        .fold(0.0_f64, f64::max);
    let extent = if extent > 0.0 && extent.is_finite() {
        extent.min(AXIS_LIMIT)
    } else {
        1.0
    };
    let half = extent * 1.08;

    // Square plotting area, centred horizontally, so the symmetric range is equal-aspect.
    let (w, h) = plot.dim_in_pixel();
    let (margin_top, margin_bottom) = (8_u32, 6_u32);
    let side = h
        .saturating_sub(margin_top + margin_bottom + x_lab)
        .min(w.saturating_sub(y_lab + 20))
        .max(1);
    let spare = w.saturating_sub(side + y_lab);
    // Centre plot and label area together, so narrow panels keep their axis titles.
    let margin_left = spare / 2;
    let margin_right = spare - margin_left;
    let mut chart = ChartBuilder::on(plot)
        .margin_top(margin_top)
        .margin_bottom(h.saturating_sub(margin_top + side + x_lab))
        .margin_left(margin_left)
        .margin_right(margin_right)
        .x_label_area_size(x_lab)
        .y_label_area_size(y_lab)
        .build_cartesian_2d(-half..half, -half..half)?;
    draw_mesh(&mut chart, "x (µm)", "y (µm)", ticks, ticks)?;

    if let Some(c) = clearance {
        let circle = (0..=360).map(|k| {
            let a = (k as f64).to_radians();
            (c * a.cos(), c * a.sin())
        });
        chart.draw_series(DashedLineSeries::new(
            circle,
            8,
            5,
            CLEARANCE_COLOUR.stroke_width(2),
        ))?;
    }
    draw_thin_line(&mut chart, path, PATH_COLOUR)?;
    if let (Some(&first), Some(&last)) = (path.first(), path.last()) {
        chart.draw_series([
            Circle::new(first, 5, START_COLOUR.filled()),
            Circle::new(last, 5, END_COLOUR.filled()),
        ])?;
    }
    Ok(())
}

/// Figure title font size (px).
pub const TITLE_FONT: f64 = 26.0;
/// Panel caption font size (px).
pub const CAPTION_FONT: f64 = 19.0;
/// Axis description font size (px).
pub const AXIS_DESC_FONT: f64 = 17.0;
/// Tick label and legend font size (px).
pub const TICK_FONT: f64 = 15.0;
/// Height of the band holding the figure title (px).
pub const TITLE_BAND: u32 = 50;
/// Space for the x tick labels and axis description below a plot (px).
pub const X_LABEL_AREA: u32 = 58;
/// Space for the y tick labels and axis description left of a plot (px).
pub const Y_LABEL_AREA: u32 = 82;

pub(crate) const TEXT_COLOUR: RGBColor = RGBColor(30, 30, 30);
pub(crate) const AXIS_COLOUR: RGBColor = RGBColor(90, 90, 90);
pub(crate) const GRID_BOLD: RGBColor = RGBColor(212, 212, 212);
pub(crate) const GRID_LIGHT: RGBColor = RGBColor(236, 236, 236);
pub(crate) const PATH_COLOUR: RGBColor = RGBColor(31, 119, 180);
pub(crate) const FORCE_COLOUR: RGBColor = RGBColor(190, 50, 40);
pub(crate) const CLEARANCE_COLOUR: RGBColor = RGBColor(120, 120, 120);
pub(crate) const START_COLOUR: RGBColor = RGBColor(44, 160, 44);
pub(crate) const END_COLOUR: RGBColor = RGBColor(214, 39, 40);

/// The embedded-font text style of `size` px in the chart text colour.
pub fn text_style(size: f64) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, size).into_font()).color(&TEXT_COLOUR)
}

/// Draws `text` centred in `area`, shrinking the font (down to 12 px) so it fits the width.
pub fn draw_centered_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    size: f64,
) -> DrawResult<DB> {
    let (w, h) = area.dim_in_pixel();
    let mut size = size;
    while size > 12.0
        && area.estimate_text_size(text, &text_style(size))?.0 as f64 > w as f64 * 0.96
    {
        size -= 1.0;
    }
    let style = text_style(size).pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(text, &style, (w as i32 / 2, h as i32 / 2))
}

/// Splits off a band of `height` px at the top of `area` with `text` centred in it; returns
/// the rest.
pub fn with_header<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    height: u32,
    text: &str,
    size: f64,
) -> Result<DrawingArea<DB, Shift>, DrawingAreaErrorKind<DB::ErrorType>> {
    let (band, rest) = area.split_vertically(height);
    draw_centered_text(&band, text, size)?;
    Ok(rest)
}

/// How a legend entry is marked.
#[derive(Clone, Copy)]
pub(crate) enum LegendMark {
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
}

const MARK_W: i32 = 26;
const MARK_GAP: i32 = 7;
const ENTRY_GAP: i32 = 30;

/// A run of legend entries.
pub(crate) type LegendEntries<'e, 'l> = &'e [(LegendMark, &'l str)];

/// The legend `entries` split into rows that each fit the width of `area` less 20 px on either
/// side (an entry wider than that gets a row of its own), in order; at least one row.
pub(crate) fn legend_rows<'e, 'l, DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &'e [(LegendMark, &'l str)],
) -> Result<Vec<LegendEntries<'e, 'l>>, DrawingAreaErrorKind<DB::ErrorType>> {
    let style = text_style(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Center));
    // A margin of 20 px on either side.
    let width = area.dim_in_pixel().0 as i32 - 40;
    let mut rows = Vec::new();
    let (mut start, mut used) = (0, 0);
    for (i, (_, label)) in entries.iter().enumerate() {
        let w = MARK_W + MARK_GAP + area.estimate_text_size(label, &style)?.0 as i32;
        if i > start && used + ENTRY_GAP + w > width {
            rows.push(&entries[start..i]);
            (start, used) = (i, w);
        } else {
            used += if i > start { ENTRY_GAP + w } else { w };
        }
    }
    rows.push(&entries[start..]);
    Ok(rows)
}

/// Draws a one-row legend centred in `area` (outside the plot, so it never hides data).
pub(crate) fn draw_legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(LegendMark, &str)],
) -> DrawResult<DB> {
    let style = text_style(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Center));
    let mut widths = Vec::with_capacity(entries.len());
    for (_, label) in entries {
        widths.push(area.estimate_text_size(label, &style)?.0 as i32);
    }
    let total: i32 = widths.iter().map(|w| MARK_W + MARK_GAP + w).sum::<i32>()
        + ENTRY_GAP * (entries.len() as i32 - 1).max(0);
    let (w, h) = area.dim_in_pixel();
    let y = h as i32 / 2;
    let mut x = (w as i32 - total).max(0) / 2;
    for ((mark, label), text_w) in entries.iter().zip(widths) {
        match *mark {
            LegendMark::Line(c) => area.draw(&PathElement::new(
                vec![(x, y), (x + MARK_W, y)],
                c.stroke_width(2),
            ))?,
            LegendMark::Dashed(c) => area.draw(&DashedPathElement::new(
                vec![(x, y), (x + MARK_W, y)],
                7,
                4,
                c.stroke_width(2),
            ))?,
            LegendMark::Dot(c) => area.draw(&Circle::new((x + MARK_W / 2, y), 5, c.filled()))?,
        }
        area.draw_text(label, &style, (x + MARK_W + MARK_GAP, y))?;
        x += MARK_W + MARK_GAP + text_w + ENTRY_GAP;
    }
    Ok(())
}

/// A tick-label formatter for an axis spanning `span`: enough decimals for the tick step,
/// trailing zeros trimmed, scientific notation for very large or small values.
pub fn tick_formatter(span: f64) -> impl Fn(&f64) -> String {
    let span = if span.is_finite() && span > 0.0 {
        span
    } else {
        1.0
    };
    let decimals = (2.0 - span.log10().floor()).clamp(0.0, 8.0) as usize;
    move |&v: &f64| {
        if v.abs() < span * 1e-9 {
            return "0".to_string();
        }
        if v.abs() >= 1e6 || span < 1e-4 {
            let s = format!("{v:.2e}");
            let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
            return format!("{}e{exponent}", trim_decimal_zeros(mantissa));
        }
        trim_decimal_zeros(&format!("{v:.decimals$}")).to_string()
    }
}

/// `"2.50"` to `"2.5"`, `"3.00"` to `"3"`; integers unchanged.
pub fn trim_decimal_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// `value` with about three significant digits, for captions.
pub fn format_quantity(value: f64) -> String {
    let a = value.abs();
    if !value.is_finite() {
        "n/a".to_string()
    } else if a >= 1e6 || (a < 1e-2 && a > 0.0) {
        format!("{value:.2e}")
    } else if a >= 100.0 {
        format!("{value:.0}")
    } else if a >= 10.0 {
        format!("{value:.1}")
    } else {
        format!("{value:.2}")
    }
}

/// Largest magnitude an axis range reaches: keeps spans and padding finite (plotters hangs
/// on infinite ranges) when a blown-up solution records values near `f64::MAX`.
pub(crate) const AXIS_LIMIT: f64 = 1e300;

/// (min, max) of the finite values, clamped to [`AXIS_LIMIT`], or `None` if there are none.
pub(crate) fn finite_bounds(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .map(|v| v.clamp(-AXIS_LIMIT, AXIS_LIMIT))
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A non-degenerate axis range from optional data bounds, widened by `pad` of its span.
pub(crate) fn padded_range(bounds: Option<(f64, f64)>, pad: f64) -> (f64, f64) {
    match bounds {
        None => (0.0, 1.0),
        Some((lo, hi)) if hi - lo > 0.0 && (hi - lo).is_finite() => {
            let p = (hi - lo) * pad;
            (lo - p, hi + p)
        }
        Some((lo, _)) => {
            let half = if lo == 0.0 { 0.5 } else { lo.abs() * 0.05 };
            (lo - half, lo + half)
        }
    }
}

/// Applies the common axis styling (fonts, grid, units, tick formats) to `chart`'s mesh.
pub fn draw_mesh<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    x_desc: &str,
    y_desc: &str,
    x_ticks: usize,
    y_ticks: usize,
) -> DrawResult<DB> {
    let x_range = chart.x_range();
    let y_range = chart.y_range();
    let x_fmt = tick_formatter(x_range.end - x_range.start);
    let y_fmt = tick_formatter(y_range.end - y_range.start);
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_labels(x_ticks)
        .y_labels(y_ticks)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(text_style(TICK_FONT))
        .axis_desc_style(text_style(AXIS_DESC_FONT))
        .axis_style(AXIS_COLOUR.stroke_width(1))
        .bold_line_style(GRID_BOLD.stroke_width(1))
        .light_line_style(GRID_LIGHT.stroke_width(1))
        .max_light_lines(4)
        .draw()
}

/// Draws `points` as a 1 px polyline, without gaps on bitmaps.
///
/// plotters' anti-aliased 1 px bitmap lines leave out some segment end pixels, which shows as
/// gaps along dense paths, so on a bitmap backend every vertex is also set as a pixel. SVG
/// lines are exact already (and a pixel there would be a `<rect>` each), so nothing is added.
pub(crate) fn draw_thin_line<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    points: &[(f64, f64)],
    colour: RGBColor,
) -> DrawResult<DB> {
    chart.draw_series(LineSeries::new(
        points.iter().copied(),
        colour.stroke_width(1),
    ))?;
    // `Figure::draw` is generic over the backend; its type name is the one place the
    // raster/vector distinction is visible without widening that trait.
    if std::any::type_name::<DB>().contains("BitMapBackend") {
        chart.draw_series(points.iter().map(|&p| Pixel::new(p, colour)))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, f: f64) -> OrbitSample {
        OrbitSample {
            t_s: t,
            x_rel_m: 0.0,
            y_rel_m: 0.0,
            contact_force_n: f,
            ..Default::default()
        }
    }

    #[test]
    fn extension_picks_format_case_insensitively() {
        assert_eq!(
            ImageFormat::from_path(Path::new("a/b.PNG")).unwrap(),
            ImageFormat::Png
        );
        assert_eq!(
            ImageFormat::from_path(Path::new("b.Svg")).unwrap(),
            ImageFormat::Svg
        );
        for bad in ["c.jpg", "noext", "d.png.txt", ""] {
            let err = ImageFormat::from_path(Path::new(bad)).unwrap_err();
            assert!(
                matches!(err, RenderError::UnsupportedExtension { .. }),
                "{bad}"
            );
            assert!(err.to_string().contains(".png or .svg"));
        }
    }

    #[test]
    fn decimation_keeps_ends_and_peaks_within_budget() {
        let n = 200_000;
        let mut s: Vec<_> = (0..n).map(|i| sample(i as f64, 0.0)).collect();
        s[12_345].contact_force_n = 5.0e3;
        s[150_001].contact_force_n = f64::NAN;
        s[150_002].contact_force_n = 7.0;
        let d = decimate_samples(&s, 20_000);
        assert!(d.len() <= 20_000, "{}", d.len());
        assert_eq!(d.first().unwrap().t_s, 0.0);
        assert_eq!(d.last().unwrap().t_s, (n - 1) as f64);
        assert!(d.iter().any(|x| x.t_s == 12_345.0));
        assert!(d.iter().any(|x| x.t_s == 150_002.0));
        assert!(d.windows(2).all(|w| w[0].t_s < w[1].t_s));
        assert_eq!(decimate_samples(&s[..10], 20_000).len(), 10);
        assert!(decimate_samples(&s[..100], 0).len() <= 4);
    }

    #[test]
    fn tick_labels_are_short() {
        let f = tick_formatter(300.0);
        assert_eq!(f(&-150.0), "-150");
        assert_eq!(f(&1e-13), "0");
        let f = tick_formatter(5.0);
        assert_eq!(f(&2.5), "2.5");
        assert_eq!(f(&2.0), "2");
        let f = tick_formatter(1e300);
        assert_eq!(f(&8e299), "8e299");
        assert_eq!(f(&-1.25e300), "-1.25e300");
    }
}
