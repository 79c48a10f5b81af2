//! The grid figure: the heat maps (Figs. 5 and 6, peak temperature) and the class map, cells
//! over release speed and friction.

use plotters::coord::Shift;
use plotters::prelude::*;
use whirlmap_core::classify::OrbitClass;
use whirlmap_results::grid::{clamp_value, Grid};
use whirlmap_results::point::PointRow;

use crate::axes::{MU_DESC, SPEED_DESC};
use crate::colour_bar::{draw_colour_bar, scale_colour, ColourBar};
use crate::contour::{marching_squares, nice_levels};
use crate::marks::{
    boxed_text, class_colour, cross, drop_dot, hatch, hatch_in, legend, Mark, ALL_CLASSES, CONTOUR,
    FAILED_BG, LIMIT, WHIRL_BG, WHIRL_OVER,
};
use crate::render::{
    draw_mesh, format_quantity, with_header, DrawResult, Figure, CAPTION_FONT, TITLE_BAND,
    TITLE_FONT, X_LABEL_AREA, Y_LABEL_AREA,
};
use plotters::element::DashedPathElement;
use whirlmap_results::point::PointStatus;

/// Cell edges around increasing centres: midpoints, extended by half a step at the ends; the
/// first edge no lower than 0 when every centre is above 0 (no cell of a friction or speed
/// axis reaches below zero: mu 0.05 and 0.3 give `[0, 0.175, 0.425]`, not from -0.075). A
/// cell centred on 0 keeps its lower half.
pub(crate) fn edges(centres: &[f64]) -> Vec<f64> {
    let mut e = open_edges(centres);
    if centres.len() >= 2 && centres[0] > 0.0 {
        e[0] = e[0].max(0.0);
    }
    e
}

/// Whether [`edges`] clips the first cell at 0, so that its drop is not at its middle.
pub(crate) fn clipped_at_zero(centres: &[f64]) -> bool {
    centres.len() >= 2 && centres[0] > 0.0 && open_edges(centres)[0] < 0.0
}

/// [`edges`] without the floor at 0.
fn open_edges(centres: &[f64]) -> Vec<f64> {
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

/// Whether increasing centres are unevenly spaced (three or more, steps differing by more
/// than one part in a million): then a cell reaches halfway to each neighbour and its drop
/// is not at its middle, so the chart marks where the drops were.
pub(crate) fn uneven(centres: &[f64]) -> bool {
    let steps: Vec<f64> = centres.windows(2).map(|w| w[1] - w[0]).collect();
    let (lo, hi) = steps.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &d| {
        (lo.min(d), hi.max(d))
    });
    steps.len() >= 2 && hi - lo > 1e-6 * hi
}

pub(crate) fn with_slice(title: &str, slice: &Option<String>) -> String {
    match slice {
        Some(s) => format!("{title} ({s})"),
        None => title.to_string(),
    }
}

#[derive(Clone, Copy, PartialEq)]
pub(crate) enum CellKind {
    Empty,
    Failed,
    Whirl(OrbitClass),
    /// A drop that had not settled at its extension cap: its peaks are not those of a
    /// settled motion, so they stay out of the scale.
    Unresolved,
    Value(f64),
    /// A whirl cell whose value stays in the scale ([`Metric::whirl_in_scale`]).
    WhirlValue(f64, OrbitClass),
    /// An infinite value (a drop that did no damage lasts forever): drawn in the colour of
    /// the scale's top, named in the legend.
    Infinite,
    Class(OrbitClass),
    NoValue,
}

/// The narrowest span a colour scale is stretched over, relative to its values: 1 %. Forces
/// and heat powers are computed to 0.1 % (the accuracy budget of docs/accuracy.md), so cells
/// closer than that are the same result, and stretching the whole scale over a map whose
/// values all lie within a few times the budget paints solver noise as yellow against purple.
/// Ten times the budget keeps every difference that is a result on the full scale: the floor
/// only acts on a map whose values all lie within 1 % (the committed maps span 13 % and
/// more). The other maps take the same floor: at the force's budget a contact pressure moves
/// less (as the force's cube root) and drops to failure three times more (as its inverse
/// cube), both still well inside 1 %; a temperature in degrees Celsius gets 1 % of its value
/// (0.3 K at 30 degrees, 1.5 K at 150), differences no design of the bearing turns on.
pub(crate) const MIN_RELATIVE_SPAN: f64 = 0.01;

/// The colour scale's ends for values from `lo` to `hi` on the scale's axis (decade exponents
/// on a log scale): their own range when it spans at least [`MIN_RELATIVE_SPAN`] of their
/// largest magnitude (on a log scale: of the values, a fixed number of decades), else that
/// span centred on them, so that near-equal cells take near-equal colours from the middle of
/// the scale instead of its two ends. Values all zero get the scale -1 to 1.
pub(crate) fn colour_scale((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    let min_span = if log {
        (1.0 + MIN_RELATIVE_SPAN).log10()
    } else {
        match lo.abs().max(hi.abs()) {
            0.0 => 2.0,
            m => MIN_RELATIVE_SPAN * m,
        }
    };
    if hi - lo >= min_span {
        return (lo, hi);
    }
    // Halfway from one end, not the ends' sum halved: that overflows near f64::MAX; and
    // within half the span of f64::MAX the scale is moved inward to stay finite.
    let mid = lo + (hi - lo) / 2.0;
    let (a, b) = (mid - min_span / 2.0, mid + min_span / 2.0);
    if b.is_infinite() {
        (f64::MAX - min_span, f64::MAX)
    } else if a.is_infinite() {
        (-f64::MAX, -f64::MAX + min_span)
    } else {
        (a, b)
    }
}

/// A quantity drawn in a colour scale.
#[derive(Clone, Copy)]
pub(crate) struct Metric {
    /// The cell's value, in the colour bar's unit.
    pub(crate) value: fn(&PointRow) -> Option<f64>,
    /// Whirl cells keep their value in the scale, hatched over their colour, instead of
    /// being left out.
    pub(crate) whirl_in_scale: bool,
    /// A logarithmic colour scale, with the decades as contour levels (values must be
    /// positive; others are left out).
    pub(crate) log: bool,
    /// The legend's words for an infinite value, when the metric has them ("no damage:
    /// infinite life"); without, infinite values are "infinite".
    pub(crate) infinite_label: Option<&'static str>,
}

/// A limit drawn on a heat map as its own dashed contour where the values cross it; the
/// legend names it and says when no cell reaches it.
pub(crate) struct Limit {
    /// The limit in the colour bar's unit.
    pub(crate) value: f64,
    /// Its legend name ("static limit 4.2 GPa (ISO 76)").
    pub(crate) name: String,
    /// The bar's unit, for the legend's "highest" value.
    pub(crate) unit: &'static str,
}

impl Metric {
    /// A linear scale, whirl cells left out (Figs. 5 and 6).
    pub(crate) const fn linear(value: fn(&PointRow) -> Option<f64>) -> Self {
        Self {
            value,
            whirl_in_scale: false,
            log: false,
            infinite_label: None,
        }
    }

    /// The value of `row` on the scale's axis (its decade exponent on a log scale).
    fn scaled(&self, row: &PointRow) -> Option<f64> {
        let v = (self.value)(row)?;
        match self.log {
            true if v > 0.0 => Some(v.log10()),
            true => None,
            false => Some(v),
        }
    }

    /// A value on the scale's axis as text in the bar's unit.
    fn label(&self, x: f64) -> String {
        if !self.log {
            return format_quantity(x);
        }
        if (x - x.round()).abs() < 1e-9 {
            return format!("1e{}", x.round() as i64);
        }
        let s = format!("{:.1e}", 10f64.powf(x));
        s.replace(".0e", "e")
    }

    /// A colour bar tick's text, `x` on the scale's axis and `span` the bar's extent on it. On
    /// a log scale shorter than a few decades, two significant figures can give two ticks the
    /// same text (the bar of a 1 % wide scale holds ticks 0.05 % apart): each tick then gets
    /// the figures that tell ticks a tenth of the span apart. Whole decades read `1eN`.
    fn tick_label(&self, x: f64, span: f64) -> String {
        if !self.log || (x - x.round()).abs() < 1e-9 {
            return self.label(x);
        }
        // Ticks a tenth of the span apart differ by a factor 10^(span / 10), a relative
        // difference of about ln(10) span / 10.
        let rel = std::f64::consts::LN_10 * span.abs() / 10.0;
        let decimals = if rel > 0.0 && rel.is_finite() {
            (-rel.log10()).ceil().clamp(1.0, 6.0) as usize
        } else {
            1
        };
        let s = format!("{:.*e}", decimals, 10f64.powf(x));
        // 2.50e3 reads 2.5e3 and 3.00e3 reads 3e3.
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

/// What the grid charts draw per cell.
#[derive(Clone, Copy)]
pub(crate) enum GridMode<'a> {
    /// A quantity in a colour scale.
    Metric(Metric),
    /// The class colour.
    Classes,
    /// The class colour, the cells `(speed index, friction index)` outlined (`compare`).
    MarkedClasses(&'a [(usize, usize)]),
}

pub(crate) struct GridFigure<'a> {
    pub(crate) grid: &'a Grid,
    pub(crate) title: String,
    pub(crate) mode: GridMode<'a>,
    pub(crate) bar_label: &'static str,
    /// The legend's words for whirl cells kept in the scale (what their value means), when
    /// the default ("whirl (in scale)") says too little.
    pub(crate) whirl_label: Option<String>,
    /// A limit to draw (metric modes only).
    pub(crate) limit: Option<Limit>,
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
            GridMode::Metric(m) if class.is_whirl() && !m.whirl_in_scale => CellKind::Whirl(class),
            GridMode::Metric(_) if class == OrbitClass::Unresolved => CellKind::Unresolved,
            GridMode::Metric(m) => match m.scaled(row) {
                Some(v) if v == f64::INFINITY => CellKind::Infinite,
                Some(v) if class.is_whirl() => CellKind::WhirlValue(clamp_value(v), class),
                Some(v) => CellKind::Value(clamp_value(v)),
                None => CellKind::NoValue,
            },
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
                CellKind::Value(v) | CellKind::WhirlValue(v, _) => Some(*v),
                _ => None,
            })
            .collect();
        let metric = match self.mode {
            GridMode::Metric(m) => Some(m),
            _ => None,
        };
        // The limit on the scale's axis.
        let limit = metric.zip(self.limit.as_ref()).and_then(|(m, lim)| {
            let l = if m.log { lim.value.log10() } else { lim.value };
            l.is_finite().then_some((l, lim.name.as_str(), lim.unit))
        });
        let scale = values
            .iter()
            .fold(None, |acc: Option<(f64, f64)>, &v| match acc {
                None => Some((v, v)),
                Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
            });
        let data_range = scale;
        let scale = scale.map(|range| colour_scale(range, metric.is_some_and(|m| m.log)));
        let is_metric = matches!(self.mode, GridMode::Metric(_));

        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (bw, bh) = body.dim_in_pixel();
        // On an uneven grid, a dot marks where each drop was, and the legend says so.
        let uneven_grid = uneven(&g.speeds_rpm) || uneven(&g.mus);
        let drops_marked = uneven_grid || clipped_at_zero(&g.speeds_rpm) || clipped_at_zero(&g.mus);
        let legend_h = if self.whirl_label.is_some() || limit.is_some() {
            66
        } else {
            44
        } + if drops_marked { 22 } else { 0 };
        let (main, legend_band) = body.split_vertically(bh.saturating_sub(legend_h));
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
        draw_mesh(&mut chart, SPEED_DESC, MU_DESC, 10, 8)?;

        let pa = chart.plotting_area();
        let base = pa.get_base_pixel();
        let px = |x: f64, y: f64| {
            let p = chart.backend_coord(&(x, y));
            (p.0 - base.0, p.1 - base.1)
        };
        let canvas = pa.strip_coord_spec();
        let (mut any_failed, mut any_empty, mut any_unresolved) = (false, false, false);
        let mut whirl_seen = [false, false];
        // Whirl cells in the scale seen: [backward, forward].
        let mut whirl_in_scale_seen = [false, false];
        let mut any_infinite = false;
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
                    CellKind::WhirlValue(v, c) => {
                        whirl_in_scale_seen[(c == OrbitClass::ForwardWhirl) as usize] = true;
                        let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                        canvas.draw(&Rectangle::new([tl, br], scale_colour(v, lo, hi).filled()))?;
                        hatch_in(&canvas, tl, br, c == OrbitClass::ForwardWhirl, WHIRL_OVER)?;
                    }
                    CellKind::Infinite => {
                        any_infinite = true;
                        let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                        canvas
                            .draw(&Rectangle::new([tl, br], scale_colour(hi, lo, hi).filled()))?;
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
                    CellKind::Unresolved => {
                        any_unresolved = true;
                        let c = class_colour(OrbitClass::Unresolved);
                        canvas.draw(&Rectangle::new([tl, br], c.filled()))?;
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

        // The drops' dots go under the contours and their labels.
        if drops_marked {
            for j in 0..ny {
                for i in 0..nx {
                    if kinds[j * nx + i] != CellKind::Empty {
                        drop_dot(&canvas, px(g.speeds_rpm[i], g.mus[j]))?;
                    }
                }
            }
        }

        let mut levels = Vec::new();
        // Whether the levels are whole decades (a log scale spanning two or more).
        let mut decade_levels = false;
        let mut limit_entry = None;
        if let (GridMode::Metric(_), Some((lo, hi))) = (self.mode, scale) {
            let m = metric.expect("a metric mode");
            // No contour levels on a scale widened to its floor: a line between cells that
            // close would part what the colours show as alike.
            if values.len() >= 2 && scale == data_range {
                decade_levels = m.log && hi.floor() - lo.ceil() >= 1.0;
                levels = if decade_levels {
                    (lo.ceil() as i64..=hi.floor() as i64)
                        .map(|d| d as f64)
                        .collect()
                } else {
                    nice_levels(lo, hi, 6)
                };
            }
            // With whirl cells in the scale, the whirl runs (stopped after a few turns) and
            // the others are contoured apart: no line joins a cell of one to the other.
            let population = |whirl: bool| -> Vec<f64> {
                kinds
                    .iter()
                    .map(|k| match k {
                        CellKind::Value(v) if !whirl => *v,
                        CellKind::WhirlValue(v, _) if whirl => *v,
                        _ => f64::NAN,
                    })
                    .collect()
            };
            let zs: Vec<Vec<f64>> = if m.whirl_in_scale {
                vec![population(false), population(true)]
            } else {
                vec![population(false)]
            };
            let trace = |level: f64| -> Vec<[(f64, f64); 2]> {
                zs.iter()
                    .flat_map(|z| marching_squares(&g.speeds_rpm, &g.mus, z, level))
                    .collect()
            };
            // A level just inside the range of the values cuts one corner of one cell: a
            // stray dot, not a line. A level whose contour is shorter than 30 pixels in all
            // is left out (here and on the colour bar).
            let seg_px = |s: &[(f64, f64); 2]| {
                let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                (((p.0 - q.0).pow(2) + (p.1 - q.1).pow(2)) as f64).sqrt()
            };
            let contours: Vec<_> = levels
                .iter()
                .map(|&level| (level, trace(level)))
                .filter(|(_, segs)| segs.iter().map(seg_px).sum::<f64>() >= 30.0)
                .collect();
            levels = contours.iter().map(|(level, _)| *level).collect();
            // The labels placed so far: (centre, half size) in pixels.
            let mut placed: Vec<((i32, i32), (i32, i32))> = Vec::new();
            for (level, segs) in &contours {
                for s in segs {
                    canvas.draw(&PathElement::new(
                        vec![px(s[0].0, s[0].1), px(s[1].0, s[1].1)],
                        CONTOUR.mix(0.8).stroke_width(2),
                    ))?;
                }
                // Label each piece of the level (a level may cross the map in several
                // separate lines) of 40 px or more, at the middle of its longest segment,
                // unless the label would cover one already placed; a level keeps at least one
                // label, on its longest piece, if that is 24 px or more.
                let ends: Vec<[(i32, i32); 2]> = segs
                    .iter()
                    .map(|s| [px(s[0].0, s[0].1), px(s[1].0, s[1].1)])
                    .collect();
                // Each piece: its length and its segments, longest first (the places its
                // label may go).
                let mut pieces: Vec<(f64, Vec<usize>)> = connected_pieces(&ends)
                    .into_iter()
                    .map(|mut piece| {
                        let length: f64 = piece.iter().map(|&i| seg_px(&segs[i])).sum();
                        piece.sort_by(|&a, &b| seg_px(&segs[b]).total_cmp(&seg_px(&segs[a])));
                        (length, piece)
                    })
                    .collect();
                pieces.sort_by(|a, b| b.0.total_cmp(&a.0));
                let text = m.label(*level);
                // The label's half size, about (13 px type: 7 px a character).
                let half = (text.len() as i32 * 7 / 2 + 4, 10);
                let mut labelled = false;
                for (k, (length, piece)) in pieces.iter().enumerate() {
                    if !(*length >= 40.0 || (k == 0 && *length >= 24.0)) {
                        continue;
                    }
                    let mid = |i: usize| {
                        let [p, q] = ends[i];
                        ((p.0 + q.0) / 2, (p.1 + q.1) / 2)
                    };
                    let free = |at: (i32, i32)| {
                        !placed.iter().any(|&(c, h): &((i32, i32), (i32, i32))| {
                            (at.0 - c.0).abs() < half.0 + h.0 && (at.1 - c.1).abs() < half.1 + h.1
                        })
                    };
                    // The middle of the longest segment that leaves the labels placed so far
                    // clear; a level's first label goes on its longest segment regardless.
                    let at = piece.iter().map(|&i| mid(i)).find(|&at| free(at));
                    let at = match at {
                        Some(at) => at,
                        None if !labelled => mid(piece[0]),
                        None => continue,
                    };
                    boxed_text(&canvas, &text, at, 13.0, CONTOUR)?;
                    placed.push((at, half));
                    labelled = true;
                }
            }
            if let Some((l, name, unit)) = limit {
                let segs = trace(l);
                for s in &segs {
                    canvas.draw(&DashedPathElement::new(
                        vec![px(s[0].0, s[0].1), px(s[1].0, s[1].1)],
                        8,
                        5,
                        LIMIT.stroke_width(3),
                    ))?;
                }
                limit_entry = Some(match data_range {
                    _ if !segs.is_empty() => name.to_string(),
                    Some((_, top)) if top < l => {
                        format!("{name}: not reached (highest {} {unit})", m.label(top))
                    }
                    Some((bottom, _)) if bottom > l => format!("{name}: exceeded in every cell"),
                    _ => name.to_string(),
                });
            }
        }
        if metric.is_some() && values.is_empty() {
            let (w, h) = canvas.dim_in_pixel();
            boxed_text(
                &canvas,
                "no values in scale",
                (w as i32 / 2, h as i32 / 2),
                CAPTION_FONT,
                CONTOUR,
            )?;
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
            GridMode::Metric(m) => {
                if !levels.is_empty() {
                    let words = if decade_levels {
                        "contour lines (decades)"
                    } else {
                        "contour lines"
                    };
                    entries.push((Mark::Line(CONTOUR), words.to_string()));
                }
                if let Some(text) = limit_entry.take() {
                    entries.push((Mark::Dashed(LIMIT), text));
                }
                if m.whirl_in_scale {
                    if whirl_in_scale_seen[0] {
                        let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                        let mid = scale_colour((lo + hi) / 2.0, lo, hi);
                        let label = self
                            .whirl_label
                            .clone()
                            .unwrap_or_else(|| "whirl (in scale)".to_string());
                        entries.push((Mark::HatchOver(mid, false), label));
                    }
                    if whirl_in_scale_seen[1] {
                        let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                        let mid = scale_colour((lo + hi) / 2.0, lo, hi);
                        entries.push((
                            Mark::HatchOver(mid, true),
                            "forward whirl (hatched the other way)".to_string(),
                        ));
                    }
                }
                // Named only when drawn: an entry for cells the map does not have would read
                // as if some drops had whirled.
                if whirl_seen[0] {
                    entries.push((
                        Mark::Hatch(false),
                        "backward whirl (not in colour scale)".to_string(),
                    ));
                }
                if whirl_seen[1] {
                    entries.push((
                        Mark::Hatch(true),
                        "forward whirl (not in colour scale)".to_string(),
                    ));
                }
                if any_infinite {
                    let (lo, hi) = scale.unwrap_or((0.0, 1.0));
                    let words = m.infinite_label.unwrap_or("infinite");
                    entries.push((
                        Mark::Swatch(scale_colour(hi, lo, hi)),
                        format!("{words} (drawn at the top of the scale)"),
                    ));
                }
                if any_unresolved {
                    entries.push((
                        Mark::Swatch(class_colour(OrbitClass::Unresolved)),
                        "unresolved (not settled; not in colour scale)".to_string(),
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
        if drops_marked {
            let why = if uneven_grid {
                "uneven grid"
            } else {
                "first cell clipped at 0"
            };
            entries.push((Mark::Drop, format!("drop ({why})")));
        }
        legend(&legend_band, &entries)?;

        if let (Some(m), Some((lo, hi))) = (metric, scale) {
            let bar = ColourBar {
                lo,
                hi,
                levels: &levels,
                limit: limit.map(|(l, _, _)| l).filter(|l| (lo..=hi).contains(l)),
                label: self.bar_label,
                tick: &|x: &f64| m.tick_label(*x, hi - lo),
                log: m.log,
            };
            draw_colour_bar(&bar_area, &bar)?;
        }
        Ok(())
    }
}

/// The connected pieces of a contour drawn as segments (end points in pixels): segments that
/// share an end point belong to one piece. Each piece is the list of its segments' indices,
/// in order of their first segment.
fn connected_pieces(ends: &[[(i32, i32); 2]]) -> Vec<Vec<usize>> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..ends.len()).collect();
    let mut first_at: std::collections::HashMap<(i32, i32), usize> =
        std::collections::HashMap::new();
    for (i, e) in ends.iter().enumerate() {
        for point in e {
            match first_at.get(point) {
                Some(&j) => {
                    let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    first_at.insert(*point, i);
                }
            }
        }
    }
    let mut pieces: Vec<Vec<usize>> = Vec::new();
    let mut index_of: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for i in 0..ends.len() {
        let r = root(&mut parent, i);
        let k = *index_of.entry(r).or_insert_with(|| {
            pieces.push(Vec::new());
            pieces.len() - 1
        });
        pieces[k].push(i);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::{
        clipped_at_zero, colour_scale, connected_pieces, edges, uneven, Metric, MIN_RELATIVE_SPAN,
    };

    /// On a log colour bar, ticks a tenth of the span apart read differently at every span
    /// down to the floor (1 % of the values), where two significant figures once repeated;
    /// whole decades read `1eN`, and a long scale keeps two figures.
    #[test]
    fn log_bar_ticks_a_tenth_of_the_span_apart_read_differently() {
        let m = Metric {
            log: true,
            ..Metric::linear(|_| None)
        };
        for span in [
            (1.0f64 + MIN_RELATIVE_SPAN).log10(),
            0.01,
            0.05,
            0.3,
            1.0,
            4.0,
        ] {
            let lo = 2.944_482_5; // 880 (the first impact's newtons)
            let labels: Vec<String> = (0..=10)
                .map(|k| m.tick_label(lo + span * k as f64 / 10.0, span))
                .collect();
            for w in labels.windows(2) {
                assert_ne!(w[0], w[1], "span {span}: {labels:?}");
            }
        }
        // The old two figures repeat on the floor's span: the test above could fail.
        let floor = (1.0f64 + MIN_RELATIVE_SPAN).log10();
        assert_eq!(m.label(2.9444825), m.label(2.9444825 + floor / 10.0));
        assert_eq!(m.tick_label(3.0, floor), "1e3");
        assert_eq!(m.tick_label(3.0 + 2.5f64.log10(), 4.0), "2.5e3");
        assert_eq!(m.tick_label(2.9444825, floor), "8.8e2");
    }

    /// Values closer than the floor get a scale of the floor's span centred on them; values
    /// further apart keep their own range; all zero, -1 to 1; on a log scale the floor is a
    /// fixed number of decades.
    #[test]
    fn the_colour_scale_spans_at_least_one_percent_of_its_values() {
        let (lo, hi) = colour_scale((880.13176, 880.13194), false);
        assert!((hi - lo - 0.01 * 880.13194).abs() < 1e-9, "{lo} {hi}");
        assert!(((lo + hi) / 2.0 - 880.13185).abs() < 1e-9, "{lo} {hi}");
        // The main job's Fig. 5 range, and one just at the floor: their own.
        assert_eq!(colour_scale((880.0, 1064.0), false), (880.0, 1064.0));
        assert_eq!(colour_scale((99.0, 100.0), false), (99.0, 100.0));
        let (lo, hi) = colour_scale((-200.0, -199.5), false);
        assert!((hi - lo - 2.0).abs() < 1e-9 && ((lo + hi) / 2.0 + 199.75).abs() < 1e-9);
        assert_eq!(colour_scale((0.0, 0.0), false), (-1.0, 1.0));
        let (lo, hi) = colour_scale((6.0, 6.0001), true);
        assert!((hi - lo - (1.0 + MIN_RELATIVE_SPAN).log10()).abs() < 1e-12);
        assert_eq!(colour_scale((3.0, 6.0), true), (3.0, 6.0));
        // The largest values a chart keeps stay finite.
        for v in [1e300, f64::MAX, -f64::MAX] {
            let (lo, hi) = colour_scale((v, v), false);
            assert!(
                lo.is_finite() && hi.is_finite() && hi > lo,
                "{v}: {lo} {hi}"
            );
        }
    }

    #[test]
    fn no_cell_reaches_below_zero_on_a_non_negative_axis() {
        let e = edges(&[0.05, 0.3]);
        assert_eq!(e[0], 0.0);
        assert!((e[1] - 0.175).abs() < 1e-15 && (e[2] - 0.425).abs() < 1e-15);
        assert!(clipped_at_zero(&[0.05, 0.3]));
        // Half a step fits below the first centre: nothing is clipped.
        assert_eq!(edges(&[2000.0, 4000.0])[0], 1000.0);
        assert!(!clipped_at_zero(&[2000.0, 4000.0]) && !clipped_at_zero(&[0.0, 0.1]));
        assert_eq!(
            edges(&[0.0, 0.1])[0],
            -0.05,
            "a centre at 0 keeps its whole cell"
        );
        // An axis that goes below zero (speeds of the other spin direction) is left alone.
        assert_eq!(edges(&[-1000.0, 1000.0])[0], -2000.0);
        assert!(!clipped_at_zero(&[-1000.0, 1000.0]) && !clipped_at_zero(&[0.01]));
    }

    #[test]
    fn uneven_spacing_is_told_from_rounding() {
        assert!(uneven(&[2000.0, 3000.0, 5000.0]));
        assert!(uneven(&[0.05, 0.1, 0.15, 0.2, 0.3]));
        assert!(
            !uneven(&[0.1, 0.15, 0.2, 0.25, 0.3]),
            "steps differing in rounding"
        );
        let built: Vec<f64> = (0..11)
            .map(|k| 0.1 + k as f64 * (0.4 - 0.1) / 10.0)
            .collect();
        assert!(!uneven(&built));
        assert!(!uneven(&[1.0, 2.0]) && !uneven(&[1.0]) && !uneven(&[]));
    }

    #[test]
    fn segments_sharing_an_end_are_one_piece() {
        // Two chains and a lone segment; the second chain's segments are given out of order.
        let ends = [
            [(0, 0), (1, 0)],
            [(10, 10), (11, 10)],
            [(1, 0), (2, 1)],
            [(12, 11), (13, 11)],
            [(11, 10), (12, 11)],
            [(50, 50), (51, 51)],
        ];
        assert_eq!(
            connected_pieces(&ends),
            vec![vec![0, 2], vec![1, 3, 4], vec![5]]
        );
    }
}
