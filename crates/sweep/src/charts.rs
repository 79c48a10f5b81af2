//! Design charts from a sweep's results directory (the paper's Figs. 3 to 6 plus a class map).
//!
//! Reads `results/<name>/points.jsonl` (one JSON object per grid point; a torn last line is
//! skipped), the optional `critical.json` (critical whirl speed per friction coefficient) and
//! the optional `orbits/*.json`, and draws every chart whose data exists into `charts/` as
//! both PNG and SVG with [`render_all`]. Drawing reuses [`crate::render`] (embedded font,
//! shared styling), so charts render on machines without system fonts.
//!
//! Grid charts use two axes, release speed (`speed_rpm`) and friction (`mu`). If the sweep
//! has further axes, the slice at each one's first value is charted and the title says so.
//! Whirl cells are left out of the force and heat colour scales (as in the paper's Fig. 5) but
//! hatched so their place stays visible; failed points are marked with a cross.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde_json::Value;
use whirlmap_results::critical::read_critical;
use whirlmap_results::files::{CHARTS_DIR, CONTOURS_FILE, PROBABILITY_DIR};
use whirlmap_results::orbit::read_orbits;
use whirlmap_results::point::{MU_KEYS, SPEED_KEYS};
use whirlmap_results::read::{read_json_optional, ReadError};

use crate::classify::OrbitClass;
use crate::critical::CriticalRow;
use crate::ensemble::ContoursFile;
use crate::fig4::{band_points, Fig4};
use crate::render::{
    chart_header, chart_mesh, chart_quantity, chart_text_style, chart_tick_formatter,
    decimate_samples, orbit_panel, render, DrawResult, Figure, RenderError, AXIS_DESC_FONT,
    CAPTION_FONT, CLEARANCE_COLOUR, PATH_COLOUR, TICK_FONT, TITLE_BAND, TITLE_FONT, X_LABEL_AREA,
    Y_LABEL_AREA,
};

/// Size (width, height) in pixels of the grid charts and Fig. 4.
pub const CHART_SIZE: (u32, u32) = (1000, 700);

const SPEED_DESC: &str = "release speed (r/min)";
pub(crate) const MU_DESC: &str = "friction coefficient µ (-)";

/// Why charts could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// The results directory has no `points.jsonl`.
    #[error("no sweep results: {} does not exist", path.display())]
    NoPoints {
        /// The missing file.
        path: PathBuf,
    },
    /// An input file could not be read.
    #[error("cannot read {}: {cause}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// An input file is not what it should be (a torn last line of points.jsonl is not).
    #[error("{}: line {line}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (1 for whole-file JSON).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The charts directory could not be created.
    #[error("cannot create {}: {cause}", path.display())]
    Write {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// A chart could not be drawn or saved.
    #[error(transparent)]
    Render(#[from] RenderError),
}

impl ChartError {
    /// Whether this is a failure to write output (as opposed to missing or bad input).
    pub fn is_output(&self) -> bool {
        matches!(self, ChartError::Write { .. } | ChartError::Render(_))
    }
}

// ---------------------------------------------------------------------------------------------
// Loading.

pub use whirlmap_results::orbit::OrbitFile;
pub use whirlmap_results::point::{PointRow, PointStatus};

impl From<ReadError> for ChartError {
    fn from(e: ReadError) -> Self {
        match e {
            ReadError::NotFound { path } => ChartError::NoPoints { path },
            ReadError::Io { path, source } => ChartError::Read {
                path,
                cause: source,
            },
            ReadError::Parse {
                path,
                line,
                message,
            } => ChartError::Parse {
                path,
                line,
                message,
            },
        }
    }
}

/// Reads `dir/points.jsonl` ([`whirlmap_results::point::load_points`]). Blank lines are
/// ignored and a torn last line (no newline, does not parse) after at least one record is
/// skipped; an unparseable line elsewhere, or a file whose only line is torn, is an error.
pub fn load_points(dir: &Path) -> Result<Vec<PointRow>, ChartError> {
    Ok(whirlmap_results::point::load_points(dir)?)
}

// ---------------------------------------------------------------------------------------------
// Grid assembly.

/// Grid points arranged over speed (x) and friction (y).
#[derive(Debug, Clone)]
pub struct Grid {
    /// Distinct speeds (r/min), increasing.
    pub speeds_rpm: Vec<f64>,
    /// Distinct friction coefficients, increasing.
    pub mus: Vec<f64>,
    /// `cells[j * speeds_rpm.len() + i]`: the point at speed `i`, friction `j`, if any.
    pub cells: Vec<Option<PointRow>>,
    /// Every point of the charted slice (the same points as `cells`).
    pub rows: Vec<PointRow>,
    /// "slice at name = value, ..." when the sweep has further axes.
    pub slice: Option<String>,
}

impl Grid {
    /// The point at speed index `i` and friction index `j`.
    pub fn cell(&self, i: usize, j: usize) -> Option<&PointRow> {
        self.cells
            .get(j * self.speeds_rpm.len() + i)
            .and_then(Option::as_ref)
    }
}

fn distinct_sorted(values: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300));
    v
}

fn position(axis: &[f64], x: f64) -> Option<usize> {
    axis.iter()
        .position(|a| (a - x).abs() <= 1e-9 * a.abs().max(x.abs()).max(1e-300))
}

fn format_input(v: &Value) -> String {
    match v {
        Value::Number(n) => n
            .as_f64()
            .map(|x| {
                let s = format!("{x}");
                if s.len() > 10 {
                    format!("{x:.4e}")
                } else {
                    s
                }
            })
            .unwrap_or_else(|| n.to_string()),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Arranges `rows` on the speed x friction grid. Further axes (inputs that take more than one
/// value) are fixed at the value of the first point (lowest index), and [`Grid::slice`] says
/// so. A missing speed or friction input counts as a single value (0). A point appearing
/// twice (a rerun) is taken from its later line.
pub fn assemble_grid(rows: &[PointRow]) -> Grid {
    let mut first = rows.iter().collect::<Vec<_>>();
    first.sort_by_key(|r| r.index.unwrap_or(u64::MAX));
    let axis_keys: Vec<&str> = SPEED_KEYS.iter().chain(MU_KEYS.iter()).copied().collect();
    let mut fixed: Vec<(String, Value)> = Vec::new();
    let keys: std::collections::BTreeSet<&String> =
        rows.iter().flat_map(|r| r.inputs.keys()).collect();
    for key in keys {
        if axis_keys.contains(&key.as_str()) {
            continue;
        }
        let mut seen: Vec<&Value> = Vec::new();
        for r in rows {
            if let Some(v) = r.inputs.get(key) {
                if !seen.contains(&v) {
                    seen.push(v);
                }
            }
        }
        if seen.len() > 1 {
            if let Some(v) = first.iter().find_map(|r| r.inputs.get(key)) {
                fixed.push((key.clone(), v.clone()));
            }
        }
    }
    let slice: Vec<PointRow> = rows
        .iter()
        .filter(|r| fixed.iter().all(|(k, v)| r.inputs.get(k) == Some(v)))
        .cloned()
        .collect();
    let speed = |r: &PointRow| clamp_value(r.speed_rpm().unwrap_or(0.0));
    let mu = |r: &PointRow| clamp_value(r.mu().unwrap_or(0.0));
    let speeds_rpm = distinct_sorted(slice.iter().map(speed));
    let mus = distinct_sorted(slice.iter().map(mu));
    let mut cells = vec![None; speeds_rpm.len() * mus.len()];
    for r in &slice {
        if let (Some(i), Some(j)) = (position(&speeds_rpm, speed(r)), position(&mus, mu(r))) {
            cells[j * speeds_rpm.len() + i] = Some(r.clone());
        }
    }
    let slice_note = (!fixed.is_empty()).then(|| {
        let parts: Vec<String> = fixed
            .iter()
            .map(|(k, v)| format!("{k} = {}", format_input(v)))
            .collect();
        format!("slice at {}", parts.join(", "))
    });
    Grid {
        speeds_rpm,
        mus,
        cells,
        rows: slice,
        slice: slice_note,
    }
}

// ---------------------------------------------------------------------------------------------
// Contours.

/// Contour segments of `z` at `level` by marching squares.
///
/// `z[j * xs.len() + i]` is the value at `(xs[i], ys[j])`. Cells with a non-finite corner are
/// skipped; saddles are resolved by the cell's mean. Crossings are interpolated linearly, and
/// a crossing shared by two cells is computed identically in both, so closed contours join
/// exactly.
pub fn marching_squares(xs: &[f64], ys: &[f64], z: &[f64], level: f64) -> Vec<[(f64, f64); 2]> {
    let (nx, ny) = (xs.len(), ys.len());
    let mut out = Vec::new();
    if nx < 2 || ny < 2 || z.len() < nx * ny || !level.is_finite() {
        return out;
    }
    let at = |i: usize, j: usize| z[j * nx + i];
    let cross = |p: (f64, f64, f64), q: (f64, f64, f64)| {
        let t = (level - p.2) / (q.2 - p.2);
        (p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1))
    };
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            // a bottom-left, b bottom-right, c top-right, d top-left.
            let a = (xs[i], ys[j], at(i, j));
            let b = (xs[i + 1], ys[j], at(i + 1, j));
            let c = (xs[i + 1], ys[j + 1], at(i + 1, j + 1));
            let d = (xs[i], ys[j + 1], at(i, j + 1));
            if ![a.2, b.2, c.2, d.2].iter().all(|v| v.is_finite()) {
                continue;
            }
            let inside = |p: (f64, f64, f64)| p.2 >= level;
            let (ia, ib, ic, id) = (inside(a), inside(b), inside(c), inside(d));
            let bottom = (ia != ib).then(|| cross(a, b));
            let right = (ib != ic).then(|| cross(b, c));
            let top = (id != ic).then(|| cross(d, c));
            let left = (ia != id).then(|| cross(a, d));
            let hits: Vec<(f64, f64)> = [bottom, right, top, left].into_iter().flatten().collect();
            match hits.len() {
                2 => out.push([hits[0], hits[1]]),
                4 => {
                    let centre = (a.2 + b.2 + c.2 + d.2) / 4.0 >= level;
                    let (bo, r, t, l) = (hits[0], hits[1], hits[2], hits[3]);
                    if centre == ia {
                        // a and c connected through the centre: cut off b and d.
                        out.push([bo, r]);
                        out.push([t, l]);
                    } else {
                        out.push([l, bo]);
                        out.push([r, t]);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// About `target` round contour levels strictly inside (lo, hi).
pub fn nice_levels(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) || target == 0 {
        return Vec::new();
    }
    let raw = span / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).floor() * step;
    // Bounded, so a step too small to move a huge start cannot loop forever.
    (0..=target * 3 + 2)
        .map(|k| start + k as f64 * step)
        .filter(|v| *v > lo + span * 1e-6 && *v < hi - span * 1e-6)
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Shared drawing pieces.

const WHITE_TEXT_BG: RGBColor = RGBColor(255, 255, 255);
const WHIRL_BG: RGBColor = RGBColor(236, 236, 236);
const HATCH: RGBColor = RGBColor(120, 120, 120);
const FAILED_BG: RGBColor = RGBColor(252, 226, 226);
const FAILED_MARK: RGBColor = RGBColor(170, 20, 20);
const CONTOUR: RGBColor = RGBColor(25, 25, 25);
pub(crate) const BAND: RGBColor = RGBColor(214, 39, 40);

/// The colour of each class on the class map and Fig. 4.
pub fn class_colour(c: OrbitClass) -> RGBColor {
    match c {
        OrbitClass::Pendulum => RGBColor(31, 119, 180),
        OrbitClass::Bouncing => RGBColor(255, 157, 40),
        OrbitClass::BackwardWhirl => RGBColor(214, 39, 40),
        OrbitClass::ForwardWhirl => RGBColor(148, 103, 189),
        OrbitClass::Unresolved => RGBColor(175, 175, 175),
    }
}

const ALL_CLASSES: [OrbitClass; 5] = [
    OrbitClass::Pendulum,
    OrbitClass::Bouncing,
    OrbitClass::BackwardWhirl,
    OrbitClass::ForwardWhirl,
    OrbitClass::Unresolved,
];

/// A legend entry's mark (see [`legend`]).
#[derive(Clone, Copy)]
pub enum Mark {
    /// A filled box.
    Swatch(RGBColor),
    /// A hatched box (the other diagonal when true).
    Hatch(bool),
    /// A failed-point cross.
    Failed,
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled dot.
    Dot(RGBColor),
    /// An open triangle pointing up: "no whirl up to the range top".
    TriangleUp(RGBColor),
    /// A translucent filled box: a probability band.
    Fill(RGBColor),
    /// An upward arrow in a colour.
    ArrowUp(RGBColor),
    /// A downward arrow in a colour.
    ArrowDown(RGBColor),
    /// An open circle.
    OpenDot(RGBColor),
}

/// Draws hatch lines (45 degrees; the other diagonal if `forward`) in a pixel rectangle.
fn hatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x0, y0): (i32, i32),
    (x1, y1): (i32, i32),
    forward: bool,
) -> DrawResult<DB> {
    const STEP: i32 = 9;
    let style = HATCH.stroke_width(1);
    let (w, h) = (x1 - x0, y1 - y0);
    let mut c = -h;
    while c <= w {
        // Line through (x0 + c + t, y1 - t) (or mirrored), clipped to the rectangle.
        let t0 = (-c).max(0);
        let t1 = (w - c).min(h);
        if t0 < t1 {
            let p = |t: i32| {
                if forward {
                    (x0 + c + t, y0 + t)
                } else {
                    (x0 + c + t, y1 - t)
                }
            };
            area.draw(&PathElement::new(vec![p(t0), p(t1)], style))?;
        }
        c += STEP;
    }
    Ok(())
}

/// Draws the failed-point cross centred at `(cx, cy)` with half-size `r` px.
fn cross<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (cx, cy): (i32, i32),
    r: i32,
) -> DrawResult<DB> {
    let style = FAILED_MARK.stroke_width(2);
    area.draw(&PathElement::new(
        vec![(cx - r, cy - r), (cx + r, cy + r)],
        style,
    ))?;
    area.draw(&PathElement::new(
        vec![(cx - r, cy + r), (cx + r, cy - r)],
        style,
    ))
}

pub(crate) fn arrow<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    up: bool,
    colour: RGBColor,
) -> DrawResult<DB> {
    let s = if up { -1 } else { 1 };
    area.draw(&PathElement::new(
        vec![(x, y - s * 4), (x, y + s * 14)],
        colour.stroke_width(2),
    ))?;
    area.draw(&Polygon::new(
        vec![(x - 6, y + s * 12), (x + 6, y + s * 12), (x, y + s * 22)],
        colour.filled(),
    ))
}

/// Draws an open triangle pointing up, centred at `(x, y)`, of half-size `r` px.
pub(crate) fn triangle_up<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    r: i32,
    colour: RGBColor,
) -> DrawResult<DB> {
    let pts = vec![(x - r, y + r), (x + r, y + r), (x, y - r), (x - r, y + r)];
    area.draw(&Polygon::new(pts.clone(), WHITE.filled()))?;
    area.draw(&PathElement::new(pts, colour.stroke_width(2)))
}

/// Draws a legend centred in `area`: one row, or more if the entries do not fit its width.
pub fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(Mark, String)],
) -> DrawResult<DB> {
    const MARK_W: i32 = 26;
    const GAP: i32 = 7;
    const ENTRY_GAP: i32 = 26;
    let style = chart_text_style(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Center));
    let mut widths = Vec::new();
    for (_, label) in entries {
        widths.push(MARK_W + GAP + area.estimate_text_size(label, &style)?.0 as i32);
    }
    let (w, h) = area.dim_in_pixel();
    let max_w = (w as f64 * 0.96) as i32;
    // Greedy rows of entry indices.
    let mut rows: Vec<Vec<usize>> = vec![Vec::new()];
    let mut row_w = 0;
    for (k, ew) in widths.iter().enumerate() {
        let last = rows.last_mut().expect("one row");
        let add = if last.is_empty() { *ew } else { ENTRY_GAP + ew };
        if !last.is_empty() && row_w + add > max_w {
            rows.push(vec![k]);
            row_w = *ew;
        } else {
            last.push(k);
            row_w += add;
        }
    }
    let n_rows = rows.len() as i32;
    for (r, row) in rows.iter().enumerate() {
        let total: i32 =
            row.iter().map(|&k| widths[k]).sum::<i32>() + ENTRY_GAP * (row.len() as i32 - 1);
        let y = (h as i32 * (2 * r as i32 + 1)) / (2 * n_rows);
        let mut x = (w as i32 - total).max(0) / 2;
        for &k in row {
            let (mark, label) = &entries[k];
            draw_mark(area, *mark, x, y, MARK_W)?;
            area.draw_text(label, &style, (x + MARK_W + GAP, y))?;
            x += widths[k] + ENTRY_GAP;
        }
    }
    Ok(())
}

/// Draws one legend mark, `mark_w` px wide, starting at `x`, centred on `y`.
fn draw_mark<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mark: Mark,
    x: i32,
    y: i32,
    mark_w: i32,
) -> DrawResult<DB> {
    let (bx0, by0, bx1, by1) = (x + 2, y - 8, x + mark_w - 2, y + 8);
    let border = RGBColor(110, 110, 110).stroke_width(1);
    match mark {
        Mark::Swatch(c) => {
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], c.filled()))?;
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], border))?;
        }
        Mark::Hatch(forward) => {
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], WHIRL_BG.filled()))?;
            hatch(area, (bx0, by0), (bx1, by1), forward)?;
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], border))?;
        }
        Mark::Failed => {
            area.draw(&Rectangle::new(
                [(bx0, by0), (bx1, by1)],
                FAILED_BG.filled(),
            ))?;
            cross(area, (x + mark_w / 2, y), 5)?;
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], border))?;
        }
        Mark::Line(c) => area.draw(&PathElement::new(
            vec![(x, y), (x + mark_w, y)],
            c.stroke_width(2),
        ))?,
        Mark::Dashed(c) => area.draw(&DashedPathElement::new(
            vec![(x, y), (x + mark_w, y)],
            7,
            4,
            c.stroke_width(2),
        ))?,
        Mark::Dot(c) => {
            area.draw(&Circle::new((x + mark_w / 2, y), 6, c.filled()))?;
            area.draw(&Circle::new((x + mark_w / 2, y), 6, WHITE.stroke_width(1)))?;
        }
        Mark::TriangleUp(c) => triangle_up(area, (x + mark_w / 2, y), 7, c)?,
        Mark::ArrowUp(c) => arrow(area, (x + mark_w / 2, y + 9), true, c)?,
        Mark::ArrowDown(c) => arrow(area, (x + mark_w / 2, y - 9), false, c)?,
        Mark::OpenDot(c) => {
            area.draw(&Circle::new((x + mark_w / 2, y), 5, WHITE.filled()))?;
            area.draw(&Circle::new((x + mark_w / 2, y), 5, c.stroke_width(2)))?;
        }
        Mark::Fill(c) => {
            area.draw(&Rectangle::new(
                [(bx0, by0), (bx1, by1)],
                c.mix(0.25).filled(),
            ))?;
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], c.stroke_width(1)))?;
        }
    }
    Ok(())
}

/// Largest magnitude drawn: beyond it values are clamped, so spans stay finite.
const VALUE_LIMIT: f64 = 1e300;

pub(crate) fn clamp_value(v: f64) -> f64 {
    v.clamp(-VALUE_LIMIT, VALUE_LIMIT)
}

/// The colour-scale colour of `v` in `lo..hi` (ends for anything outside, mid for NaN).
fn scale_colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    let t = (v - lo) / (hi - lo);
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    ViridisRGB::get_color_normalized(t, 0.0, 1.0)
}

/// Cell edges around increasing centres: midpoints, extended by half a step at the ends.
fn edges(centres: &[f64]) -> Vec<f64> {
    match centres.len() {
        0 => vec![0.0, 1.0],
        1 => {
            let c = centres[0];
            let h = if c == 0.0 { 0.5 } else { c.abs() * 0.05 };
            vec![c - h, c + h]
        }
        n => {
            let mut e = Vec::with_capacity(n + 1);
            e.push(centres[0] - (centres[1] - centres[0]) / 2.0);
            for k in 0..n - 1 {
                e.push((centres[k] + centres[k + 1]) / 2.0);
            }
            e.push(centres[n - 1] + (centres[n - 1] - centres[n - 2]) / 2.0);
            e
        }
    }
}

fn with_slice(title: &str, slice: &Option<String>) -> String {
    match slice {
        Some(s) => format!("{title} ({s})"),
        None => title.to_string(),
    }
}

/// Draws `text` with a white box behind it, centred at pixel `(x, y)` of `area`.
pub(crate) fn boxed_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    (x, y): (i32, i32),
    size: f64,
    colour: RGBColor,
) -> DrawResult<DB> {
    let style = chart_text_style(size)
        .color(&colour)
        .pos(Pos::new(HPos::Center, VPos::Center));
    let (w, h) = area.estimate_text_size(text, &style)?;
    let (w, h) = (w as i32 / 2 + 3, h as i32 / 2 + 1);
    area.draw(&Rectangle::new(
        [(x - w, y - h), (x + w, y + h)],
        WHITE_TEXT_BG.mix(0.85).filled(),
    ))?;
    area.draw_text(text, &style, (x, y))
}

// ---------------------------------------------------------------------------------------------
// Grid charts: heatmaps (Figs. 5 and 6) and the class map.

#[derive(Clone, Copy, PartialEq)]
enum CellKind {
    Empty,
    Failed,
    Whirl(OrbitClass),
    Value(f64),
    Class(OrbitClass),
    NoValue,
}

/// What the grid charts draw per cell.
#[derive(Clone, Copy)]
enum GridMode<'a> {
    /// A metric in a colour scale, whirl left out.
    Metric(fn(&PointRow) -> Option<f64>),
    /// The class colour.
    Classes,
    /// The class colour, the cells `(speed index, friction index)` outlined (`compare`).
    MarkedClasses(&'a [(usize, usize)]),
}

struct GridFigure<'a> {
    grid: &'a Grid,
    title: String,
    mode: GridMode<'a>,
    bar_label: &'static str,
}

impl GridFigure<'_> {
    fn kind(&self, i: usize, j: usize) -> CellKind {
        let Some(row) = self.grid.cell(i, j) else {
            return CellKind::Empty;
        };
        if row.status == PointStatus::Failed {
            return CellKind::Failed;
        }
        let Some(class) = row.class else {
            return CellKind::NoValue;
        };
        match self.mode {
            GridMode::Classes | GridMode::MarkedClasses(_) => CellKind::Class(class),
            GridMode::Metric(_) if class.is_whirl() => CellKind::Whirl(class),
            GridMode::Metric(f) => {
                f(row).map_or(CellKind::NoValue, |v| CellKind::Value(clamp_value(v)))
            }
        }
    }
}

impl Figure for GridFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let g = self.grid;
        let (nx, ny) = (g.speeds_rpm.len(), g.mus.len());
        let kinds: Vec<CellKind> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .map(|(i, j)| self.kind(i, j))
            .collect();
        let values: Vec<f64> = kinds
            .iter()
            .filter_map(|k| match k {
                CellKind::Value(v) => Some(*v),
                _ => None,
            })
            .collect();
        let scale = values
            .iter()
            .fold(None, |acc: Option<(f64, f64)>, &v| match acc {
                None => Some((v, v)),
                Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
            });
        let scale = scale.map(|(lo, hi)| {
            if hi > lo {
                (lo, hi)
            } else {
                let h = if lo == 0.0 { 1.0 } else { lo.abs() * 0.05 };
                (lo - h, hi + h)
            }
        });
        let is_metric = matches!(self.mode, GridMode::Metric(_));

        let body = chart_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (bw, bh) = body.dim_in_pixel();
        let (main, legend_band) = body.split_vertically(bh.saturating_sub(44));
        let (plot_area, bar_area) = if is_metric {
            main.split_horizontally(bw.saturating_sub(150))
        } else {
            main.split_horizontally(bw.saturating_sub(30))
        };
        let (xe, ye) = (edges(&g.speeds_rpm), edges(&g.mus));
        let mut chart = ChartBuilder::on(&plot_area)
            .margin_top(12)
            .margin_left(14)
            .margin_right(12)
            .margin_bottom(4)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])?;
        chart_mesh(&mut chart, SPEED_DESC, MU_DESC, 10, 8)?;

        let pa = chart.plotting_area();
        let base = pa.get_base_pixel();
        let px = |x: f64, y: f64| {
            let p = chart.backend_coord(&(x, y));
            (p.0 - base.0, p.1 - base.1)
        };
        let canvas = pa.strip_coord_spec();
        let (mut any_failed, mut any_empty) = (false, false);
        let mut whirl_seen = [false, false];
        for j in 0..ny {
            for i in 0..nx {
                let tl = px(xe[i], ye[j + 1]);
                let br = px(xe[i + 1], ye[j]);
                let centre = ((tl.0 + br.0) / 2, (tl.1 + br.1) / 2);
                let r = ((br.0 - tl.0).min(br.1 - tl.1) / 5).clamp(4, 12);
                match kinds[j * nx + i] {
                    CellKind::Value(v) => {
                        let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                        let c = scale_colour(v, lo, hi);
                        canvas.draw(&Rectangle::new([tl, br], c.filled()))?;
                    }
                    CellKind::Class(c) => {
                        canvas.draw(&Rectangle::new([tl, br], class_colour(c).filled()))?;
                    }
                    CellKind::Whirl(c) => {
                        let forward = c == OrbitClass::ForwardWhirl;
                        whirl_seen[forward as usize] = true;
                        canvas.draw(&Rectangle::new([tl, br], WHIRL_BG.filled()))?;
                        hatch(&canvas, tl, br, forward)?;
                    }
                    CellKind::Failed => {
                        any_failed = true;
                        canvas.draw(&Rectangle::new([tl, br], FAILED_BG.filled()))?;
                        cross(&canvas, centre, r)?;
                    }
                    CellKind::NoValue | CellKind::Empty => {
                        any_empty = true;
                    }
                }
                if kinds[j * nx + i] != CellKind::Empty {
                    canvas.draw(&Rectangle::new([tl, br], WHITE.stroke_width(1)))?;
                }
            }
        }

        if let GridMode::MarkedClasses(marked) = self.mode {
            for &(i, j) in marked.iter().filter(|(i, j)| *i < nx && *j < ny) {
                let (tl, br) = (px(xe[i], ye[j + 1]), px(xe[i + 1], ye[j]));
                for k in 2..6 {
                    canvas.draw(&Rectangle::new(
                        [(tl.0 + k, tl.1 + k), (br.0 - k, br.1 - k)],
                        BLACK.stroke_width(1),
                    ))?;
                }
            }
        }

        let mut levels = Vec::new();
        if let (GridMode::Metric(_), Some((lo, hi))) = (self.mode, scale) {
            if values.len() >= 2 {
                levels = nice_levels(lo, hi, 6);
            }
            let z: Vec<f64> = kinds
                .iter()
                .map(|k| match k {
                    CellKind::Value(v) => *v,
                    _ => f64::NAN,
                })
                .collect();
            for &level in &levels {
                let segs = marching_squares(&g.speeds_rpm, &g.mus, &z, level);
                for s in &segs {
                    canvas.draw(&PathElement::new(
                        vec![px(s[0].0, s[0].1), px(s[1].0, s[1].1)],
                        CONTOUR.mix(0.8).stroke_width(2),
                    ))?;
                }
                // Label the level once, on its longest segment.
                let longest = segs.iter().max_by(|a, b| {
                    let len = |s: &[(f64, f64); 2]| {
                        let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                        (((p.0 - q.0).pow(2) + (p.1 - q.1).pow(2)) as f64).sqrt()
                    };
                    len(a).total_cmp(&len(b))
                });
                let long_enough = |s: &&[(f64, f64); 2]| {
                    let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                    (p.0 - q.0).pow(2) + (p.1 - q.1).pow(2) >= 24 * 24
                };
                if let Some(s) = longest.filter(long_enough) {
                    let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                    boxed_text(
                        &canvas,
                        &chart_quantity(level),
                        ((p.0 + q.0) / 2, (p.1 + q.1) / 2),
                        13.0,
                        CONTOUR,
                    )?;
                }
            }
            if values.is_empty() {
                let (w, h) = canvas.dim_in_pixel();
                boxed_text(
                    &canvas,
                    "no values in scale",
                    (w as i32 / 2, h as i32 / 2),
                    CAPTION_FONT,
                    CONTOUR,
                )?;
            }
        }

        // Legend.
        let mut entries: Vec<(Mark, String)> = Vec::new();
        match self.mode {
            GridMode::Classes | GridMode::MarkedClasses(_) => {
                if matches!(self.mode, GridMode::MarkedClasses(_)) {
                    entries.push((Mark::Line(BLACK), "changed".to_string()));
                }
                let present: Vec<OrbitClass> = ALL_CLASSES.to_vec();
                for c in present {
                    entries.push((Mark::Swatch(class_colour(c)), c.label().to_string()));
                }
                entries.push((Mark::Failed, "failed".to_string()));
            }
            GridMode::Metric(_) => {
                if !levels.is_empty() {
                    entries.push((Mark::Line(CONTOUR), "contour lines".to_string()));
                }
                // The backward-whirl entry is always shown: it is where the scale stops.
                entries.push((
                    Mark::Hatch(false),
                    "backward whirl (not in scale)".to_string(),
                ));
                if whirl_seen[1] {
                    entries.push((
                        Mark::Hatch(true),
                        "forward whirl (not in scale)".to_string(),
                    ));
                }
                if any_failed {
                    entries.push((Mark::Failed, "failed".to_string()));
                }
            }
        }
        if any_empty {
            entries.push((Mark::Swatch(WHITE), "no data".to_string()));
        }
        legend(&legend_band, &entries)?;

        if let (GridMode::Metric(_), Some((lo, hi))) = (self.mode, scale) {
            draw_colour_bar(&bar_area, lo, hi, &levels, self.bar_label)?;
        }
        Ok(())
    }
}

fn draw_colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
    levels: &[f64],
    label: &str,
) -> DrawResult<DB> {
    let mut bar = ChartBuilder::on(area)
        .margin_top(12)
        .margin_bottom(4 + X_LABEL_AREA)
        .margin_left(8)
        .margin_right(4)
        .right_y_label_area_size(96)
        .build_cartesian_2d(0.0..1.0, lo..hi)?;
    let fmt = chart_tick_formatter(hi - lo);
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(8)
        .y_label_formatter(&fmt)
        .y_desc(label)
        .label_style(chart_text_style(TICK_FONT))
        .axis_desc_style(chart_text_style(AXIS_DESC_FONT))
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
        levels
            .iter()
            .map(|&l| PathElement::new(vec![(0.0, l), (1.0, l)], CONTOUR.stroke_width(2))),
    )?;
    bar.draw_series([Rectangle::new(
        [(0.0, lo), (1.0, hi)],
        RGBColor(90, 90, 90).stroke_width(1),
    )])?;
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Fig. 4's inputs (the figure is in `crate::fig4`).

/// Reads `dir/critical.json` (a list of [`CriticalRow`]), or `None` if it does not exist.
pub fn load_critical(dir: &Path) -> Result<Option<Vec<CriticalRow>>, ChartError> {
    Ok(read_critical(dir)?)
}

/// Reads the probability ensemble's `contours.json` of a sweep (`dir/probability/`), or
/// `None` if the sweep ran none.
pub fn load_probability(dir: &Path) -> Result<Option<ContoursFile>, ChartError> {
    Ok(read_json_optional(
        &dir.join(PROBABILITY_DIR).join(CONTOURS_FILE),
    )?)
}

// ---------------------------------------------------------------------------------------------
// Fig. 3: orbit panels.

/// Reads every `dir/orbits/*.json`, sorted by speed then friction; empty if there are none.
pub fn load_orbits(dir: &Path) -> Result<Vec<OrbitFile>, ChartError> {
    Ok(read_orbits(dir)?)
}

struct OrbitPanels<'a> {
    orbits: &'a [OrbitFile],
    title: String,
}

const START_COLOUR: RGBColor = RGBColor(44, 160, 44);
const END_COLOUR: RGBColor = RGBColor(214, 39, 40);

fn panel_layout(n: usize) -> (usize, usize) {
    let cols = match n {
        0 | 1 => 1,
        2 | 4 => 2,
        3 | 5 | 6 | 9 => 3,
        _ => 4,
    };
    (cols, n.max(1).div_ceil(cols))
}

fn orbit_figure_size(n: usize) -> (u32, u32) {
    let (cols, rows) = panel_layout(n);
    let w = (cols as u32 * 420).max(1000);
    let h = TITLE_BAND + 44 + rows as u32 * if cols == 1 { 600 } else { 430 };
    (w, h.max(700))
}

impl Figure for OrbitPanels<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = chart_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (_, bh) = body.dim_in_pixel();
        let (panels_area, legend_band) = body.split_vertically(bh.saturating_sub(44));
        let (cols, rows) = panel_layout(self.orbits.len());
        let panels = panels_area.split_evenly((rows, cols));
        for (o, area) in self.orbits.iter().zip(panels.iter()) {
            let caption = format!(
                "µ = {}, {} r/min: {}",
                chart_quantity(o.mu),
                chart_quantity(o.speed_rpm),
                o.class_label()
            );
            let plot = chart_header(area, 34, &caption, CAPTION_FONT)?;
            let samples = decimate_samples(&o.orbit.samples, 8_000);
            let path: Vec<(f64, f64)> = samples
                .iter()
                .map(|s| (s.x_rel_m * 1e6, s.y_rel_m * 1e6))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| (clamp_value(x), clamp_value(y)))
                .collect();
            let clearance =
                Some(clamp_value(o.orbit.clearance_m * 1e6)).filter(|c| c.is_finite() && *c > 0.0);
            orbit_panel(&plot, &path, clearance, (50, 70), 7)?;
        }
        legend(
            &legend_band,
            &[
                (
                    Mark::Line(PATH_COLOUR),
                    "rotor-centre path relative to the race".to_string(),
                ),
                (
                    Mark::Dashed(CLEARANCE_COLOUR),
                    "clearance circle".to_string(),
                ),
                (Mark::Dot(START_COLOUR), "release".to_string()),
                (Mark::Dot(END_COLOUR), "end".to_string()),
            ],
        )
    }
}

// ---------------------------------------------------------------------------------------------
// Entry point.

pub(crate) fn write_both<F: Figure>(
    out_dir: &Path,
    stem: &str,
    size: (u32, u32),
    figure: &F,
    written: &mut Vec<PathBuf>,
) -> Result<(), ChartError> {
    for ext in ["png", "svg"] {
        let path = out_dir.join(format!("{stem}.{ext}"));
        render(&path, size, figure)?;
        written.push(path);
    }
    Ok(())
}

/// Draws the class map of `grid` to `path` (PNG or SVG by extension) with the cells
/// `marked` (speed index, friction index into the grid's axes) outlined in black: the changed
/// cells of a comparison ([`crate::compare`]).
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
    };
    render(path, CHART_SIZE, &figure)?;
    Ok(())
}

/// Draws every chart whose data exists in the results directory `dir` into `dir/charts/`, as
/// PNG and SVG: `fig5_max_force`, `fig6_peak_power` and `classes` from `points.jsonl`
/// (required), `peak_temperature` if the records carry temperatures, `fig4_critical` if
/// `critical.json` exists, `fig3_orbits` if `orbits/` holds orbit files, `fig4_probability` if
/// `contours.json` (an ensemble's) exists (then `points.jsonl` is optional). Returns the paths
/// written.
pub fn render_all(dir: &Path) -> Result<Vec<PathBuf>, ChartError> {
    // An ensemble's results: Fig. 4 with probability bands (docs/probability.md).
    let prob = crate::prob_chart::render_probability(dir)?;
    if !prob.is_empty() && !dir.join(crate::sweep::POINTS_FILE).exists() {
        return Ok(prob);
    }
    let rows = load_points(dir)?;
    let critical = load_critical(dir)?;
    let orbits = load_orbits(dir)?;
    let grid = assemble_grid(&rows);

    let out_dir = dir.join(CHARTS_DIR);
    std::fs::create_dir_all(&out_dir).map_err(|cause| ChartError::Write {
        path: out_dir.clone(),
        cause,
    })?;
    let mut written = Vec::new();
    let fig5 = GridFigure {
        grid: &grid,
        title: with_slice("Fig. 5: maximum contact force", &grid.slice),
        mode: GridMode::Metric(|r| r.max_contact_force_n),
        bar_label: "max contact force (N)",
    };
    write_both(&out_dir, "fig5_max_force", CHART_SIZE, &fig5, &mut written)?;
    let fig6 = GridFigure {
        grid: &grid,
        title: with_slice("Fig. 6: peak heat power", &grid.slice),
        mode: GridMode::Metric(|r| r.peak_heat_power_w),
        bar_label: "peak heat power (W)",
    };
    write_both(&out_dir, "fig6_peak_power", CHART_SIZE, &fig6, &mut written)?;
    let classes = GridFigure {
        grid: &grid,
        title: with_slice("Orbit class over release speed and friction", &grid.slice),
        mode: GridMode::Classes,
        bar_label: "",
    };
    write_both(&out_dir, "classes", CHART_SIZE, &classes, &mut written)?;
    if rows.iter().any(|r| r.peak_temperature_k.is_some()) {
        // Only records made with the thermal model carry temperatures.
        let temps = GridFigure {
            grid: &grid,
            title: with_slice("Peak touchdown-bearing temperature", &grid.slice),
            mode: GridMode::Metric(|r| r.peak_temperature_k),
            bar_label: "hottest node peak temperature (K)",
        };
        write_both(
            &out_dir,
            "peak_temperature",
            CHART_SIZE,
            &temps,
            &mut written,
        )?;
    }
    if let Some(rows) = &critical {
        let probability = load_probability(dir)?;
        let band = probability.as_ref().map(band_points);
        let label = probability.as_ref().map(|c| {
            let top = c
                .groups
                .iter()
                .filter_map(|g| g.speeds_rpm.last().copied())
                .fold(0.0, f64::max);
            format!(
                "over release conditions ({} drops per cell, up to {} r/min)",
                c.members,
                chart_quantity(top)
            )
        });
        let fig4 = Fig4 {
            rows,
            band: band.as_deref().zip(label),
            title: "Fig. 4: critical speed of backward whirl".to_string(),
        };
        write_both(&out_dir, "fig4_critical", CHART_SIZE, &fig4, &mut written)?;
    }
    if !orbits.is_empty() {
        let speeds = distinct_sorted(orbits.iter().map(|o| o.speed_rpm));
        let title = match speeds.as_slice() {
            [s] => format!(
                "Fig. 3: orbits relative to the race at {} r/min",
                chart_quantity(*s)
            ),
            _ => "Fig. 3: orbits relative to the race".to_string(),
        };
        let fig3 = OrbitPanels {
            orbits: &orbits,
            title,
        };
        write_both(
            &out_dir,
            "fig3_orbits",
            orbit_figure_size(orbits.len()),
            &fig3,
            &mut written,
        )?;
    }
    written.extend(prob);
    remove_stale_charts(&out_dir, &written)?;
    Ok(written)
}

/// Removes the charts in `dir` that this rendering did not draw (a Fig. 4 left from an
/// earlier spec with a critical search, say), so `charts/` shows only what the data holds.
fn remove_stale_charts(dir: &Path, written: &[PathBuf]) -> Result<(), ChartError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let p = e.path();
        let chart = p
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("png") || x.eq_ignore_ascii_case("svg"));
        if chart && p.is_file() && !written.iter().any(|w| w == &p) {
            std::fs::remove_file(&p).map_err(|cause| ChartError::Write {
                path: p.clone(),
                cause,
            })?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marching_squares_rings_a_cone() {
        let n = 41;
        let xs: Vec<f64> = (0..n)
            .map(|i| -2.0 + 4.0 * i as f64 / (n - 1) as f64)
            .collect();
        let ys = xs.clone();
        let z: Vec<f64> = (0..n * n)
            .map(|k| {
                let (x, y) = (xs[k % n], ys[k / n]);
                (x * x + y * y).sqrt()
            })
            .collect();
        // Levels off the grid nodes' radii (a node exactly on a level is a degenerate touch).
        for r in [0.55, 1.05, 1.45] {
            let segs = marching_squares(&xs, &ys, &z, r);
            assert!(segs.len() > 8, "{r}: {}", segs.len());
            // Every point lies near the circle of radius r.
            for s in &segs {
                for p in s {
                    let d = (p.0 * p.0 + p.1 * p.1).sqrt();
                    assert!((d - r).abs() < 0.01, "level {r}: point at {d}");
                }
            }
            // Closed: every endpoint is shared by exactly two segments.
            let ends: Vec<(f64, f64)> = segs.iter().flat_map(|s| [s[0], s[1]]).collect();
            for p in &ends {
                let k = ends
                    .iter()
                    .filter(|q| (q.0 - p.0).abs() < 1e-12 && (q.1 - p.1).abs() < 1e-12)
                    .count();
                assert_eq!(k, 2, "level {r}: open end at {p:?}");
            }
            // And it goes all the way round.
            let mut quadrants = [false; 4];
            for p in &ends {
                quadrants[(p.0 >= 0.0) as usize * 2 + (p.1 >= 0.0) as usize] = true;
            }
            assert!(quadrants.iter().all(|q| *q));
        }
        // NaN cells are skipped; a level outside the data gives nothing.
        let mut z2 = z.clone();
        z2.iter_mut().for_each(|v| *v = f64::NAN);
        assert!(marching_squares(&xs, &ys, &z2, 1.0).is_empty());
        assert!(marching_squares(&xs, &ys, &z, 10.0).is_empty());
    }

    #[test]
    fn marching_squares_saddle_gives_two_segments() {
        let xs = [0.0, 1.0];
        let ys = [0.0, 1.0];
        let z = [1.0, 0.0, 0.0, 1.0]; // a, b / d, c: diagonal highs
        assert_eq!(marching_squares(&xs, &ys, &z, 0.5).len(), 2);
    }

    #[test]
    fn levels_are_round_and_inside() {
        assert_eq!(nice_levels(0.0, 10.0, 5), vec![2.0, 4.0, 6.0, 8.0]);
        let l = nice_levels(123.0, 987.0, 6);
        assert!(
            l.iter().all(|v| *v > 123.0 && *v < 987.0) && l.len() >= 4,
            "{l:?}"
        );
        assert!(nice_levels(1.0, 1.0, 5).is_empty());
    }

    #[test]
    fn grid_takes_first_slice_of_a_third_axis() {
        let row = |i: u64, s: f64, m: f64, c: f64| PointRow {
            key: format!("k{i}"),
            index: Some(i),
            inputs: [
                ("speed_rpm".to_string(), Value::from(s)),
                ("mu".to_string(), Value::from(m)),
                ("clearance_m".to_string(), Value::from(c)),
            ]
            .into_iter()
            .collect(),
            status: PointStatus::Failed,
            class: None,
            max_contact_force_n: None,
            peak_heat_power_w: None,
            peak_temperature_k: None,
            error: None,
            duration_s: None,
        };
        let rows = vec![
            row(3, 1000.0, 0.1, 2e-4),
            row(0, 1000.0, 0.1, 1e-4),
            row(1, 2000.0, 0.1, 1e-4),
            row(2, 2000.0, 0.2, 1e-4),
        ];
        let g = assemble_grid(&rows);
        assert_eq!(g.speeds_rpm, vec![1000.0, 2000.0]);
        assert_eq!(g.mus, vec![0.1, 0.2]);
        assert_eq!(g.rows.len(), 3);
        assert!(g.cell(0, 1).is_none());
        assert_eq!(g.cell(1, 1).unwrap().key, "k2");
        assert_eq!(g.slice.as_deref(), Some("slice at clearance_m = 0.0001"));
    }
}
