//! Fig. 4: the critical speed of backward whirl against the friction coefficient.
//!
//! Drawn from `critical.json` ([`CriticalRow`]) and, when the sweep ran a probability
//! ensemble, its `probability/contours.json`:
//!
//! - the **onset** of sustained whirl per friction coefficient as one curve (dots joined
//!   between neighbouring coefficients that both whirl in the range); an onset found already
//!   at the lowest scanned speed carries a downward arrow (at or below it); an onset that
//!   failed or unsettled drops leave undecided (`undecided` in `critical.json`) is an open
//!   circle, joined to no neighbour; an onset that does not hold at the re-check's tighter
//!   preset (`recheck` in `critical.json`, neither `confirmed` nor `within_tol`) is an open
//!   square (an open circle when it is undecided too), joined to no neighbour, with a dark
//!   diamond, joined by a dotted line, where the tighter preset's window search put the onset
//!   (`recheck.relocated`);
//! - every **whirl interval** as a translucent bar, with an upward arrow where whirl goes on
//!   to the top of the searched range;
//! - **no whirl in range** as an open triangle at the range top; as an open square there when
//!   the re-check at a tighter preset does not confirm it (whirl, or a failed or unsettled
//!   drop, at the range top), with that preset's onset, when its search below the top found
//!   it, as a diamond joined to it;
//! - the **searched range**: its top as a dashed line with its value, and its bottom (the
//!   rows' `from_rpm`) the same way when it is above the axis's 0, the speeds below it shaded
//!   as not searched, so that they do not read as speeds without whirl;
//! - the **whirl-probability band** over uncontrolled release conditions: P(whirl) from 10 %
//!   to 90 % shaded, 50 % dashed. Near the boundary the outcome is a probability; the single
//!   symmetric drops of the curve are one sample of it.
//!
//! The speed axis starts at 0. Grid classes are not drawn here (the class map is its own
//! chart).

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use whirlmap_results::contours::ContoursFile;
use whirlmap_results::critical::CriticalRow;
use whirlmap_results::grid::clamp_value;

use crate::axes::MU_DESC;
use crate::marks::{arrow, diamond, legend, open_square, triangle_up, Mark, BAND, CONTOUR};
use crate::render::{
    draw_mesh, format_quantity, text_style, with_header, DrawResult, Figure, TITLE_BAND,
    TITLE_FONT, X_LABEL_AREA, Y_LABEL_AREA,
};

/// The probability band's colour.
const PROB: RGBColor = RGBColor(31, 119, 180);
/// The "no whirl in range" marker's colour.
const NONE_MARK: RGBColor = RGBColor(90, 90, 90);

/// One friction coefficient's band ends from the ensemble (r/min): P10, P50, P90, each
/// clipped to the ensemble's speed range (`None` only without any finished member).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandPoint {
    /// Friction coefficient.
    pub mu: f64,
    /// Speeds where P(whirl) first reaches 10 %, 50 % and 90 %.
    pub p: [f64; 3],
    /// Whether each level is reached inside the ensemble's speed range (false: clipped to
    /// the range top).
    pub reached: [bool; 3],
}

/// The band ends of every group of `contours` that has a `mu` input and the three levels
/// 0.1, 0.5, 0.9; groups without them are skipped. With further axes, those of one slice, as
/// Fig. 4 as probability draws them.
pub fn band_points(contours: &ContoursFile) -> Vec<BandPoint> {
    let mut out: Vec<BandPoint> = crate::probability::slice(contours)
        .0
        .into_iter()
        .filter_map(|g| {
            let mu = *g.inputs.get("mu").or_else(|| g.inputs.get("mu_dynamic"))?;
            let lo = *g.speeds_rpm.first()?;
            let hi = *g.speeds_rpm.last()?;
            // A group without a cell that finished has no band.
            g.p_whirl.iter().flatten().next()?;
            let mut p = [0.0; 3];
            let mut reached = [false; 3];
            for (k, level) in [0.1, 0.5, 0.9].into_iter().enumerate() {
                let c = g.levels.iter().find(|c| (c.level - level).abs() < 1e-9)?;
                (p[k], reached[k]) = match c.speed_rpm {
                    Some(s) => (s, true),
                    // Reached already at the lowest speed, or never in the range.
                    None if g.reached_below_range(level) => (lo, true),
                    None => (hi, false),
                };
            }
            Some(BandPoint { mu, p, reached })
        })
        .collect();
    out.sort_by(|a, b| a.mu.total_cmp(&b.mu));
    out
}

/// Fig. 4 as a [`Figure`].
pub struct Fig4<'a> {
    /// The critical-speed rows (any order).
    pub rows: &'a [CriticalRow],
    /// The probability band, when the sweep ran an ensemble.
    pub band: Option<(&'a [BandPoint], String)>,
    /// The chart title.
    pub title: String,
}

impl Figure for Fig4<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let mut rows: Vec<&CriticalRow> = self.rows.iter().filter(|r| r.mu.is_finite()).collect();
        rows.sort_by(|a, b| a.mu.total_cmp(&b.mu));
        let band: &[BandPoint] = self.band.as_ref().map_or(&[], |b| b.0);

        let mus: Vec<f64> = rows
            .iter()
            .map(|r| r.mu)
            .chain(band.iter().map(|b| b.mu))
            .collect();
        let (mu_lo, mu_hi) = mus
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &m| {
                (a.min(m), b.max(m))
            });
        let (mu_lo, mu_hi) = if mu_lo.is_finite() {
            (mu_lo, mu_hi)
        } else {
            (0.0, 1.0)
        };
        let pad = ((mu_hi - mu_lo) * 0.06).max(0.02);
        let (x0, x1) = ((mu_lo - pad).max(0.0), mu_hi + pad);
        let top = rows
            .iter()
            .map(|r| clamp_value(r.to_rpm))
            .chain(band.iter().map(|b| b.p[2]))
            .fold(0.0_f64, f64::max)
            .max(1.0);
        let y1 = top * 1.12;
        let bottom = searched_bottom(&rows);

        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (_, bh) = body.dim_in_pixel();
        let (plot_area, legend_band) = body.split_vertically(bh.saturating_sub(64));
        let mut chart = ChartBuilder::on(&plot_area)
            .margin_top(12)
            .margin_left(14)
            .margin_right(34)
            .margin_bottom(4)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x0..x1, AXIS_BOTTOM_RPM..y1)?;
        draw_mesh(&mut chart, MU_DESC, "release speed (r/min)", 10, 8)?;

        // The speeds below the searched range, shaded under everything else: no marker there
        // means nothing was run, not that the rotor did not whirl.
        if let Some(b) = bottom {
            chart.draw_series([Rectangle::new(
                [(x0, AXIS_BOTTOM_RPM), (x1, b)],
                UNSEARCHED.filled(),
            )])?;
        }

        // The probability band first, under everything else.
        if band.len() >= 2 {
            let poly: Vec<(f64, f64)> = band
                .iter()
                .map(|b| (b.mu, b.p[0]))
                .chain(band.iter().rev().map(|b| (b.mu, b.p[2])))
                .collect();
            chart.draw_series([Polygon::new(poly, PROB.mix(0.16).filled())])?;
            // Each edge segment solid where both its ends are crossings the ensemble reached,
            // dotted where one end is only the ensemble's top speed (the band goes on above
            // it there, unmeasured).
            for k in [0, 2] {
                for w in band.windows(2) {
                    let seg = vec![(w[0].mu, w[0].p[k]), (w[1].mu, w[1].p[k])];
                    if w[0].reached[k] && w[1].reached[k] {
                        chart
                            .draw_series([PathElement::new(seg, PROB.mix(0.5).stroke_width(1))])?;
                    } else {
                        chart.draw_series([DashedPathElement::new(
                            seg,
                            2,
                            4,
                            PROB.mix(0.8).stroke_width(1),
                        )])?;
                    }
                }
            }
            chart.draw_series([DashedPathElement::new(
                band.iter().map(|b| (b.mu, b.p[1])).collect::<Vec<_>>(),
                8,
                5,
                PROB.stroke_width(2),
            )])?;
        }

        let pa = chart.plotting_area();
        let base = pa.get_base_pixel();
        let px = |x: f64, y: f64| {
            let p = chart.backend_coord(&(x, y));
            (p.0 - base.0, p.1 - base.1)
        };
        let canvas = pa.strip_coord_spec();

        // The band's 50 % points: filled where the ensemble reached 50 %, open where it did not
        // within its speed range (the point then sits at the ensemble's top speed). The 90 %
        // edge: an open circle where the ensemble did not reach 90 % (the band is clipped at
        // its top speed there, not closed).
        let mut any_clipped = false;
        if band.len() >= 2 {
            for b in band {
                let p = px(b.mu, b.p[1]);
                if b.reached[1] {
                    canvas.draw(&Circle::new(p, 4, PROB.filled()))?;
                } else {
                    any_clipped = true;
                    canvas.draw(&Circle::new(p, 5, WHITE.filled()))?;
                    canvas.draw(&Circle::new(p, 5, PROB.stroke_width(2)))?;
                }
                if !b.reached[2] && b.reached[1] {
                    any_clipped = true;
                    let q = px(b.mu, b.p[2]);
                    canvas.draw(&Circle::new(q, 5, WHITE.filled()))?;
                    canvas.draw(&Circle::new(q, 5, PROB.stroke_width(2)))?;
                }
            }
        }

        // Whirl intervals.
        let mut any_open_top = false;
        for r in &rows {
            for (k, [a, b]) in r.whirl_intervals_rpm.iter().enumerate() {
                let last = k + 1 == r.whirl_intervals_rpm.len();
                let open = last && r.whirl_at_range_top;
                let b = if open { r.to_rpm } else { *b };
                let (pa_, pb) = (px(r.mu, clamp_value(*a)), px(r.mu, clamp_value(b)));
                let (y_top, y_bot) = (pb.1.min(pa_.1), pb.1.max(pa_.1).max(pb.1.min(pa_.1) + 3));
                canvas.draw(&Rectangle::new(
                    [(pa_.0 - 8, y_top), (pa_.0 + 8, y_bot)],
                    BAND.mix(0.28).filled(),
                ))?;
                if open {
                    any_open_top = true;
                    arrow(&canvas, (pb.0, pb.1 - 2), true, BAND)?;
                }
            }
        }

        // The onset curve: joined between neighbours that both whirl in the range and whose
        // onsets are decided.
        let onsets: Vec<Option<(f64, f64)>> = rows
            .iter()
            .map(|r| r.onset_rpm.map(|o| (r.mu, clamp_value(o))))
            .collect();
        for (w, r) in onsets.windows(2).zip(rows.windows(2)) {
            if let ([Some(a), Some(b)], true) = (w, joined(r[0], r[1])) {
                canvas.draw(&PathElement::new(
                    vec![px(a.0, a.1), px(b.0, b.1)],
                    BAND.stroke_width(3),
                ))?;
            }
        }
        let mut any_below = false;
        let mut any_undecided = false;
        // The presets whose re-check did not confirm an onset, for the legend.
        let mut unconfirmed_at: Vec<&str> = Vec::new();
        // The presets whose window search found an onset, for the legend.
        let mut relocated_at: Vec<&str> = Vec::new();
        for (r, o) in rows.iter().zip(&onsets) {
            let Some((mu, s)) = o else { continue };
            let p = px(*mu, *s);
            if let Some(rc) = r.recheck.as_ref().filter(|rc| !rc.holds() && !r.undecided) {
                // The tighter preset disagrees: an open square, and where that preset puts
                // the onset, when its window search found it: a diamond, joined by a dotted
                // line.
                if !unconfirmed_at.contains(&rc.fidelity.name()) {
                    unconfirmed_at.push(rc.fidelity.name());
                }
                let found = (rc.relocated.as_ref())
                    .and_then(|w| w.onset_rpm)
                    .map(|onset| px(*mu, clamp_value(onset)));
                not_confirmed(&canvas, p, found, BAND)?;
                if found.is_some() && !relocated_at.contains(&rc.fidelity.name()) {
                    relocated_at.push(rc.fidelity.name());
                }
            } else if r.undecided {
                // Failed drops could move this onset: an open circle.
                any_undecided = true;
                canvas.draw(&Circle::new(p, 6, WHITE.filled()))?;
                canvas.draw(&Circle::new(p, 6, BAND.stroke_width(2)))?;
            } else {
                canvas.draw(&Circle::new(p, 6, BAND.filled()))?;
                canvas.draw(&Circle::new(p, 6, WHITE.stroke_width(1)))?;
            }
            if r.bracket_rpm.is_none() {
                // Whirl already at the lowest scanned speed: the onset is at or below it.
                any_below = true;
                arrow(&canvas, (p.0 + 14, p.1 - 10), false, BAND)?;
            }
        }

        // No whirl in the range: a marker at the range top; when the re-check at a tighter
        // preset does not confirm it there, an open square instead, and that preset's onset, when its
        // search below the top found it, as a diamond joined to it.
        let mut any_none = false;
        // The presets whose re-check whirled at the top of a range with no whirl found.
        let mut none_unconfirmed_at: Vec<&str> = Vec::new();
        for r in rows.iter().filter(|r| r.whirl_intervals_rpm.is_empty()) {
            if r.scan.iter().all(|p| p.class.is_none()) {
                continue; // nothing decided (every drop failed): nothing to mark
            }
            let p = px(r.mu, clamp_value(r.to_rpm));
            let Some(rc) = r.recheck.as_ref().filter(|rc| !rc.holds() && !r.undecided) else {
                any_none = true;
                triangle_up(&canvas, p, 8, NONE_MARK)?;
                continue;
            };
            if !none_unconfirmed_at.contains(&rc.fidelity.name()) {
                none_unconfirmed_at.push(rc.fidelity.name());
            }
            let found = (rc.relocated.as_ref())
                .and_then(|w| w.onset_rpm)
                .map(|onset| px(r.mu, clamp_value(onset)));
            not_confirmed(&canvas, p, found, NONE_MARK)?;
            if found.is_some() && !relocated_at.contains(&rc.fidelity.name()) {
                relocated_at.push(rc.fidelity.name());
            }
        }
        // The top of the searched range, as a faint line with its value above it.
        if let Some(t) = rows.iter().map(|r| clamp_value(r.to_rpm)).reduce(f64::max) {
            let (a, b) = (px(x0, t), px(x1, t));
            range_line(&canvas, a, b)?;
            let label = format!("top of the searched range, {} r/min", format_quantity(t));
            let style = text_style(13.0)
                .color(&NONE_MARK)
                .pos(Pos::new(HPos::Left, VPos::Bottom));
            // Clear of the columns' arrows (whirl to the range top), which cross the line.
            let width = canvas.estimate_text_size(&label, &style)?.0 as i32;
            let arrows: Vec<i32> = (rows.iter())
                .filter(|r| r.whirl_at_range_top && !r.whirl_intervals_rpm.is_empty())
                .map(|r| px(r.mu, t).0)
                .collect();
            let x = label_x(a.0, b.0, width, &arrows);
            canvas.draw_text(&label, &style, (x, a.1 - 12))?;
        }
        // The bottom of the searched range, when the axis starts below it: marked as the top
        // is, its label in the unsearched band below the line (above it when the band is too
        // narrow for the text).
        if let Some(lo) = bottom {
            let (a, b) = (px(x0, lo), px(x1, lo));
            range_line(&canvas, a, b)?;
            let label = format!(
                "bottom of the searched range, {} r/min",
                format_quantity(lo)
            );
            let below = text_style(13.0)
                .color(&NONE_MARK)
                .pos(Pos::new(HPos::Left, VPos::Top));
            let (width, height) = canvas.estimate_text_size(&label, &below)?;
            let (width, height) = (width as i32, height as i32);
            // Below the line: the onset dots on it reach 6 px down, and the arrows of onsets
            // found at the lowest speed 12 px, beside their dot.
            let room = px(x0, AXIS_BOTTOM_RPM).1 - a.1;
            let (style, y, obstacles) = if room >= 8 + height + 2 {
                let arrows: Vec<i32> = onsets
                    .iter()
                    .zip(&rows)
                    .filter(|(o, r)| o.is_some() && r.bracket_rpm.is_none())
                    .map(|(_, r)| px(r.mu, lo).0 + 14)
                    .collect();
                (below, a.1 + 8, arrows)
            } else {
                // Above the line: clear of every column with a mark (an onset, an interval,
                // an arrow) that reaches down into the label's height.
                let reach = 12 + height + 22;
                let columns: Vec<i32> = (rows.iter())
                    .filter(|r| {
                        let lowest = (r.whirl_intervals_rpm.iter().map(|w| w[0]))
                            .chain(r.onset_rpm)
                            .map(clamp_value)
                            .reduce(f64::min);
                        lowest.is_some_and(|s| a.1 - px(r.mu, s).1 <= reach)
                    })
                    .flat_map(|r| [px(r.mu, lo).0, px(r.mu, lo).0 + 14])
                    .collect();
                let above = below.pos(Pos::new(HPos::Left, VPos::Bottom));
                (above, a.1 - 12, columns)
            };
            let x = label_x(a.0, b.0, width, &obstacles);
            canvas.draw_text(&label, &style, (x, y))?;
        }

        let mut entries = vec![
            (
                Mark::Line(BAND),
                "onset of sustained whirl (symmetric release)".to_string(),
            ),
            (
                Mark::Swatch(BAND.mix(0.28).to_rgba().into_rgb()),
                "whirl interval".to_string(),
            ),
        ];
        if any_open_top {
            entries.push((Mark::ArrowUp(BAND), "whirl to the range top".to_string()));
        }
        if any_below {
            entries.push((
                Mark::ArrowDown(BAND),
                "onset at or below the lowest speed".to_string(),
            ));
        }
        if any_undecided {
            entries.push((
                Mark::OpenDot(BAND),
                "onset undecided: failed or unsettled drops could move it".to_string(),
            ));
        }
        if !unconfirmed_at.is_empty() {
            entries.push((
                Mark::OpenSquare(BAND),
                format!(
                    "onset not confirmed by the re-check at {}",
                    unconfirmed_at.join(", ")
                ),
            ));
        }
        if !none_unconfirmed_at.is_empty() {
            entries.push((
                Mark::OpenSquare(NONE_MARK),
                format!(
                    "no whirl in range, not confirmed at its top by the re-check at {}",
                    none_unconfirmed_at.join(", ")
                ),
            ));
        }
        if !relocated_at.is_empty() {
            entries.push((
                Mark::Diamond(CONTOUR),
                format!(
                    "onset at {}, searched again nearby",
                    relocated_at.join(", ")
                ),
            ));
        }
        if any_none {
            entries.push((Mark::TriangleUp(NONE_MARK), "no whirl in range".to_string()));
        }
        if bottom.is_some() {
            entries.push((
                Mark::Swatch(UNSEARCHED.to_rgba().into_rgb()),
                "not searched".to_string(),
            ));
        }
        if let Some((b, label)) = &self.band {
            if b.len() >= 2 {
                entries.push((Mark::Fill(PROB), format!("P(whirl) 10-90 % {label}")));
                entries.push((Mark::Dashed(PROB), "P(whirl) = 50 %".to_string()));
                if any_clipped {
                    entries.push((
                        Mark::OpenDot(PROB),
                        format!(
                            "{} not reached by the ensemble's top speed (dotted: open above)",
                            clipped_levels(band)
                        ),
                    ));
                }
            }
        }
        legend(&legend_band, &entries)
    }
}

/// Where the speed axis starts (r/min): at rest, so a chart's speeds read from zero.
const AXIS_BOTTOM_RPM: f64 = 0.0;

/// The shading of the speeds below the searched range.
const UNSEARCHED: RGBAColor = RGBAColor(90, 90, 90, 0.14);

/// The bottom of the searched range (r/min), the lowest `from_rpm` of `rows` (below it no
/// search ran: `critical.json` records each row's range as the sweep's `critical.speed_rpm`
/// or `whirlmap critical --from` set it), when it is above the speed axis's bottom; `None`
/// when a search starts at the bottom, or there are no rows.
fn searched_bottom(rows: &[&CriticalRow]) -> Option<f64> {
    rows.iter()
        .map(|r| clamp_value(r.from_rpm))
        .filter(|f| f.is_finite())
        .reduce(f64::min)
        .filter(|&f| f > AXIS_BOTTOM_RPM)
}

/// Draws what the re-check at a tighter preset did not confirm, at pixel `p`: an open square
/// in `colour`, and where that preset puts the onset, when its search found it (`found`): a
/// diamond, joined to the square by a dotted line.
fn not_confirmed<DB: DrawingBackend>(
    canvas: &DrawingArea<DB, Shift>,
    p: (i32, i32),
    found: Option<(i32, i32)>,
    colour: RGBColor,
) -> DrawResult<DB> {
    if let Some(q) = found {
        canvas.draw(&DashedPathElement::new(
            vec![p, q],
            3,
            3,
            CONTOUR.mix(0.7).stroke_width(1),
        ))?;
    }
    open_square(canvas, p, 6, colour)?;
    if let Some(q) = found {
        diamond(canvas, q, 6, CONTOUR)?;
    }
    Ok(())
}

/// Draws an end of the searched range across the chart, from `a` to `b`: a faint dashed line.
fn range_line<DB: DrawingBackend>(
    canvas: &DrawingArea<DB, Shift>,
    a: (i32, i32),
    b: (i32, i32),
) -> DrawResult<DB> {
    canvas.draw(&DashedPathElement::new(
        vec![a, b],
        4,
        4,
        NONE_MARK.mix(0.6).stroke_width(1),
    ))
}

/// Where a label `width` px wide starts on a line from `left` to `right` (pixels) that the
/// columns centred at `obstacles` cross, 16 px wide each: at the left end if clear, else in
/// the widest gap between obstacles if it fits with 20 px to spare on each side, else at the
/// right end; at the left end when every place is crossed.
fn label_x(left: i32, right: i32, width: i32, obstacles: &[i32]) -> i32 {
    let clear = |x: i32| obstacles.iter().all(|&c| c + 8 < x || c - 8 > x + width);
    let mut edges = obstacles.to_vec();
    edges.push(right);
    let gap = edges
        .iter()
        .scan(left, |l, &r| {
            let g = (*l, r);
            *l = r;
            Some(g)
        })
        .max_by_key(|(l, r)| r - l)
        .filter(|(l, r)| r - l >= width + 40)
        .map(|(l, r)| (l + r - width) / 2);
    [Some(left + 6), gap, Some(right - 6 - width)]
        .into_iter()
        .flatten()
        .find(|&x| clear(x))
        .unwrap_or(left + 6)
}

/// Which of the band's 50 % and 90 % levels some friction coefficient did not reach, for
/// the legend ("50 %", "90 %" or "50 % or 90 %").
fn clipped_levels(band: &[BandPoint]) -> &'static str {
    match (
        band.iter().any(|b| !b.reached[1]),
        band.iter().any(|b| !b.reached[2] && b.reached[1]),
    ) {
        (true, true) => "50 % or 90 %",
        (false, true) => "90 %",
        _ => "50 %",
    }
}

/// Whether the onset curve joins two neighbouring rows: both whirl in the range and neither
/// onset is undecided or left unconfirmed by a re-check.
fn joined(a: &CriticalRow, b: &CriticalRow) -> bool {
    let sure = |r: &CriticalRow| {
        r.onset_rpm.is_some() && !r.undecided && r.recheck.as_ref().is_none_or(|rc| rc.holds())
    };
    sure(a) && sure(b)
}

/// Converts an RGBA colour back to RGB (for swatches of mixed colours).
trait IntoRgb {
    fn into_rgb(self) -> RGBColor;
}

impl IntoRgb for RGBAColor {
    fn into_rgb(self) -> RGBColor {
        // Blend over white, as the chart does.
        let a = self.3;
        let mix = |c: u8| (c as f64 * a + 255.0 * (1.0 - a)).round() as u8;
        RGBColor(mix(self.0), mix(self.1), mix(self.2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;
    use whirlmap_results::contours::{ContourGroup, LevelCrossing};

    fn group(mu: f64, p: &[f64], crossings: [Option<f64>; 3]) -> ContourGroup {
        ContourGroup {
            inputs: BTreeMap::from([("mu".to_string(), mu)]),
            speeds_rpm: (0..p.len()).map(|i| 2000.0 + 2000.0 * i as f64).collect(),
            p_whirl: p.iter().map(|v| Some(*v)).collect(),
            levels: [0.1, 0.5, 0.9]
                .iter()
                .zip(crossings)
                .map(|(&level, s)| LevelCrossing {
                    level,
                    speed_rpm: s,
                    speed_lo_rpm: None,
                    speed_hi_rpm: None,
                    note: String::new(),
                })
                .collect(),
            non_monotone: false,
        }
    }

    /// The PNG bytes of Fig. 4 drawn from `rows` with `title`, through a temp file named by
    /// `tag`, kept (and named on standard error) when `WHIRLMAP_KEEP_CHART` is set, to be
    /// looked at.
    fn drawn(rows: &[CriticalRow], tag: &str, title: &str) -> Vec<u8> {
        drawn_with_band(rows, None, tag, title)
    }

    /// [`drawn`] with a probability band.
    fn drawn_with_band(
        rows: &[CriticalRow],
        band: Option<&[BandPoint]>,
        tag: &str,
        title: &str,
    ) -> Vec<u8> {
        let path =
            std::env::temp_dir().join(format!("whirlmap-fig4-{tag}-{}.png", std::process::id()));
        let fig = Fig4 {
            rows,
            band: band.map(|b| (b, "(test)".to_string())),
            title: title.into(),
        };
        crate::render::render(&path, (1000, 700), &fig).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        if std::env::var_os("WHIRLMAP_KEEP_CHART").is_some() {
            eprintln!("chart: {}", path.display());
        } else {
            std::fs::remove_file(&path).ok();
        }
        bytes
    }

    /// The main job's committed critical rows in order of mu, and the index of mu 0.4 (an
    /// onset joined to both neighbours).
    fn paper_rows_at_mu_0_4() -> (Vec<CriticalRow>, usize) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../results/paper");
        let mut rows = whirlmap_results::critical::read_critical(&dir)
            .expect("committed critical.json")
            .expect("a critical search");
        rows.sort_by(|a, b| a.mu.total_cmp(&b.mu));
        let i = rows
            .iter()
            .position(|r| (r.mu - 0.4).abs() < 1e-9)
            .expect("mu 0.4");
        (rows, i)
    }

    /// An undecided onset is joined to no neighbour, and the chart draws it (as an open
    /// circle, with its legend entry) where a decided onset would be a filled dot. The picture
    /// is kept under the temp folder when `WHIRLMAP_KEEP_CHART` is set, to be looked at.
    #[test]
    fn an_undecided_onset_is_not_joined_and_is_drawn_apart() {
        let (mut rows, i) = paper_rows_at_mu_0_4();
        assert!(joined(&rows[i - 1], &rows[i]) && joined(&rows[i], &rows[i + 1]));
        rows[i].undecided = true;
        rows[i].converged = false;
        assert!(!joined(&rows[i - 1], &rows[i]) && !joined(&rows[i], &rows[i + 1]));
        assert!(joined(&rows[i + 1], &rows[i + 2]), "the others stay joined");

        let pixels = |rows: &[CriticalRow]| {
            let tag = format!("undecided-{}", rows.iter().filter(|r| r.undecided).count());
            drawn(rows, &tag, "Fig. 4 with an undecided onset")
        };
        let mut decided = rows.clone();
        decided[i].undecided = false;
        assert_ne!(pixels(&rows), pixels(&decided));
    }

    /// An onset the re-check at a tighter preset did not confirm is joined to no neighbour and
    /// drawn apart from both a decided and an undecided one (an open square); a confirmed
    /// re-check changes nothing.
    #[test]
    fn an_unconfirmed_onset_is_not_joined_and_is_drawn_apart() {
        use whirlmap_core::classify::OrbitClass;
        use whirlmap_core::Fidelity;
        use whirlmap_results::critical::{Outcome, Recheck, Relocated};
        let (rows, i) = paper_rows_at_mu_0_4();
        let [lo, hi] = rows[i].bracket_rpm.expect("a bracket");
        let recheck = |confirmed: bool| Recheck {
            fidelity: Fidelity::Reference,
            lo: Some((lo, Outcome::Class(OrbitClass::BackwardWhirl))),
            hi: Some((hi, Outcome::Class(OrbitClass::BackwardWhirl))),
            confirmed,
            within_tol: false,
            relocated: None,
        };
        let draw = |rows: &[CriticalRow], tag: &str| {
            drawn(
                rows,
                &format!("recheck-{tag}"),
                "Fig. 4 with an unconfirmed onset",
            )
        };
        let plain = draw(&rows, "plain");
        let mut confirmed = rows.clone();
        recheck(true).apply_to(&mut confirmed[i]);
        assert!(
            joined(&confirmed[i - 1], &confirmed[i]) && joined(&confirmed[i], &confirmed[i + 1])
        );
        assert_eq!(
            draw(&confirmed, "confirmed"),
            plain,
            "a confirmed onset is drawn as before"
        );

        let mut unconfirmed = rows.clone();
        recheck(false).apply_to(&mut unconfirmed[i]);
        let u = &unconfirmed;
        assert!(!joined(&u[i - 1], &u[i]) && !joined(&u[i], &u[i + 1]));
        assert!(joined(&u[i + 1], &u[i + 2]), "the others stay joined");
        let mut undecided = rows.clone();
        undecided[i].undecided = true;
        let drawn = draw(&unconfirmed, "unconfirmed");
        assert_ne!(drawn, plain);
        assert_ne!(drawn, draw(&undecided, "undecided"));
        // Where the tighter preset's window search put the onset, 500 r/min lower: a diamond
        // joined to the square (and its legend entry).
        let mut relocated = unconfirmed.clone();
        let rc = relocated[i].recheck.as_mut().unwrap();
        rc.relocated = Some(Relocated {
            window_rpm: [lo - 1000.0, hi + 500.0],
            onset_rpm: Some(lo - 500.0),
            drops: 10,
            note: String::new(),
        });
        assert_ne!(draw(&relocated, "relocated"), drawn);
        // The same window search putting the onset within the row's tolerance of it: the
        // onset holds, and is drawn and joined as a confirmed one.
        let mut within = rows.clone();
        let mut rc = recheck(false);
        rc.relocated = Some(Relocated {
            window_rpm: [lo - 1000.0, hi + 500.0],
            onset_rpm: Some(hi - within[i].tol_rpm),
            drops: 10,
            note: String::new(),
        });
        rc.within_tol = rc.onset_within(within[i].onset_rpm, within[i].tol_rpm);
        assert!(rc.within_tol);
        rc.apply_to(&mut within[i]);
        assert!(within[i].converged);
        let w = &within;
        assert!(joined(&w[i - 1], &w[i]) && joined(&w[i], &w[i + 1]));
        assert_eq!(draw(&within, "within-tol"), plain);
    }

    /// A row with no whirl in its range whose re-check whirls at the range top: an open
    /// square there instead of the triangle, with its legend entry; with the tighter preset's
    /// onset found below the top, a diamond too. A confirmed one is drawn as before.
    #[test]
    fn no_whirl_not_confirmed_at_the_range_top_is_drawn_apart() {
        use whirlmap_core::classify::OrbitClass;
        use whirlmap_core::Fidelity;
        use whirlmap_results::critical::{Outcome, Recheck, Relocated};
        let (mut rows, _) = paper_rows_at_mu_0_4();
        // mu 0.3 the only row without whirl: the triangle's legend entry says whether one is
        // drawn.
        rows.retain(|r| !r.whirl_intervals_rpm.is_empty() || (r.mu - 0.3).abs() < 1e-9);
        let i = rows
            .iter()
            .position(|r| (r.mu - 0.3).abs() < 1e-9)
            .expect("mu 0.3");
        assert!(rows[i].whirl_intervals_rpm.is_empty(), "no whirl at mu 0.3");
        let top = rows[i].to_rpm;
        let recheck = |class| Recheck {
            fidelity: Fidelity::Standard,
            lo: Some((top, Outcome::Class(class))),
            hi: None,
            confirmed: class != OrbitClass::BackwardWhirl,
            within_tol: false,
            relocated: None,
        };
        let legend = "no whirl in range, not confirmed at its top by the re-check at standard";
        let plain = svg_of(&rows, "none-plain");
        let mut confirmed = rows.clone();
        recheck(OrbitClass::Pendulum).apply_to(&mut confirmed[i]);
        assert_eq!(svg_of(&confirmed, "none-plain"), plain);
        let mut unconfirmed = rows.clone();
        recheck(OrbitClass::BackwardWhirl).apply_to(&mut unconfirmed[i]);
        let u = svg_of(&unconfirmed, "none-unconfirmed");
        assert!(u.contains(legend) && !plain.contains(legend), "{u}");
        // The square replaces the triangle.
        let triangle = |svg: &str| svg.lines().any(|l| l.trim() == "no whirl in range");
        assert!(triangle(&plain) && !triangle(&u), "{u}");
        assert!(!u.contains("searched again"), "{u}");
        let mut relocated = unconfirmed.clone();
        relocated[i].recheck.as_mut().unwrap().relocated = Some(Relocated {
            window_rpm: [top - 2000.0, top],
            onset_rpm: Some(top - 1500.0),
            drops: 8,
            note: String::new(),
        });
        let r = svg_of(&relocated, "none-relocated");
        assert!(r.contains("onset at standard, searched again"), "{r}");
        assert!(r.contains(legend), "{r}");
    }

    /// The SVG text of Fig. 4 drawn from `rows`, through a temp file named by `tag`.
    fn svg_of(rows: &[CriticalRow], tag: &str) -> String {
        let path =
            std::env::temp_dir().join(format!("whirlmap-fig4-{tag}-{}.svg", std::process::id()));
        let fig = Fig4 {
            rows,
            band: None,
            title: tag.into(),
        };
        crate::render::render(&path, (1000, 700), &fig).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).ok();
        text
    }

    /// Rows of a search from `from` to `to` r/min, as a sweep's `critical.speed_rpm` sets it:
    /// no whirl at mu 0.3, an onset bracketed at 4375 r/min at 0.4, whirl already at the
    /// lowest speed at 0.5 (the main job's row at mu 0.05 as the template).
    fn searched(from: f64, to: f64) -> Vec<CriticalRow> {
        let (rows, _) = paper_rows_at_mu_0_4();
        let row = |mu: f64, onset: Option<f64>, bracketed: bool| {
            let mut r = rows[0].clone();
            r.mu = mu;
            r.from_rpm = from;
            r.to_rpm = to;
            r.onset_rpm = onset;
            r.bracket_rpm = onset.filter(|_| bracketed).map(|o| [o - 62.5, o]);
            r.whirl_intervals_rpm = onset.map(|o| vec![[o, to]]).unwrap_or_default();
            r.whirl_at_range_top = onset.is_some();
            r
        };
        vec![
            row(0.3, None, false),
            row(0.4, Some(4375.0), true),
            row(0.5, Some(from.max(4000.0)), false),
        ]
    }

    /// A search that starts above the speed axis's 0 has its bottom marked as its top is,
    /// and the speeds below it shaded and named as not searched (they read as speeds without
    /// whirl); a search from 0 draws neither. The main job's search starts at 1000 r/min.
    /// The picture of the 4000 to 7000 r/min search is kept under the temp folder when
    /// `WHIRLMAP_KEEP_CHART` is set, to be looked at.
    #[test]
    fn the_bottom_of_a_search_above_zero_is_marked() {
        let refs = |rows: &[CriticalRow]| -> Option<f64> {
            searched_bottom(&rows.iter().collect::<Vec<_>>())
        };
        let (paper, _) = paper_rows_at_mu_0_4();
        assert_eq!(refs(&paper), Some(1000.0));
        let above = searched(4000.0, 7000.0);
        assert_eq!(refs(&above), Some(4000.0));
        let svg = svg_of(&above, "bottom-4000");
        for text in [
            "bottom of the searched range, 4000 r/min",
            "top of the searched range, 7000 r/min",
            "not searched",
        ] {
            assert!(svg.contains(text), "{text:?} missing");
        }
        drawn(&above, "bottom-4000", "Fig. 4 searched from 4000 r/min");

        let from_zero = searched(0.0, 7000.0);
        assert_eq!(refs(&from_zero), None);
        let svg = svg_of(&from_zero, "bottom-0");
        assert!(svg.contains("top of the searched range, 7000 r/min"));
        assert!(!svg.contains("bottom of the searched range") && !svg.contains("not searched"));
        // One row from 0 among rows from 4000: some search ran down to 0.
        let mut mixed = above.clone();
        mixed[1].from_rpm = 0.0;
        assert_eq!(refs(&mixed), None);
        assert_eq!(refs(&[]), None);
    }

    /// A band whose 90 % level one friction coefficient never reaches is drawn open there
    /// (a dotted edge and an open circle at the ensemble's top speed), not closed at it: the
    /// same numbers marked reached draw a different picture, and the legend names the level.
    /// Both pictures are kept under the temp folder when `WHIRLMAP_KEEP_CHART` is set.
    #[test]
    fn a_band_that_never_reaches_90_percent_is_drawn_open_at_the_top() {
        let (rows, _) = paper_rows_at_mu_0_4();
        let clipped = [
            BandPoint {
                mu: 0.25,
                p: [7200.0, 12800.0, 16000.0],
                reached: [true, true, false],
            },
            BandPoint {
                mu: 0.4,
                p: [2600.0, 4600.0, 5900.0],
                reached: [true, true, true],
            },
        ];
        let mut closed = clipped;
        closed[0].reached[2] = true;
        let draw = |band: &[BandPoint], tag: &str| drawn_with_band(&rows, Some(band), tag, tag);
        assert_ne!(draw(&clipped, "band-open"), draw(&closed, "band-closed"));
        assert_eq!(clipped_levels(&clipped), "90 %");
        let mut none_at_50 = clipped;
        none_at_50[1].reached[1] = false;
        none_at_50[1].reached[2] = false;
        assert_eq!(clipped_levels(&none_at_50), "50 % or 90 %");
        none_at_50[0].reached[2] = true;
        assert_eq!(clipped_levels(&none_at_50), "50 %");
    }

    #[test]
    fn band_ends_are_clipped_to_the_ensemble_range() {
        let file = ContoursFile {
            name: "t".into(),
            members: 8,
            confidence: 0.95,
            groups: vec![
                group(0.4, &[0.2, 0.6, 1.0], [None, Some(3500.0), Some(5000.0)]),
                group(0.3, &[0.0, 0.0, 0.3], [Some(5300.0), None, None]),
            ],
        };
        let b = band_points(&file);
        assert_eq!(b.len(), 2);
        assert_eq!(b[0].mu, 0.3);
        // Never reaching 50 % or 90 %: clipped to the top, marked not reached.
        assert_eq!(b[0].p, [5300.0, 6000.0, 6000.0]);
        assert_eq!(b[0].reached, [true, false, false]);
        // Already above 10 % at the lowest speed: the band starts there.
        assert_eq!(b[1].p, [2000.0, 3500.0, 5000.0]);
        assert_eq!(b[1].reached, [true, true, true]);
    }
}
