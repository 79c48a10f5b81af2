//! Cell marks and the legend shared by the grid charts, Fig. 4 and the studies: class
//! colours, hatching, crosses, arrows, triangles, boxed labels.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use whirlmap_core::classify::OrbitClass;

use crate::render::{text_style, DrawResult, TICK_FONT};

pub(crate) const WHITE_TEXT_BG: RGBColor = RGBColor(255, 255, 255);
pub(crate) const WHIRL_BG: RGBColor = RGBColor(236, 236, 236);
pub(crate) const HATCH: RGBColor = RGBColor(120, 120, 120);
pub(crate) const FAILED_BG: RGBColor = RGBColor(252, 226, 226);
pub(crate) const FAILED_MARK: RGBColor = RGBColor(170, 20, 20);
pub(crate) const CONTOUR: RGBColor = RGBColor(25, 25, 25);
pub(crate) const BAND: RGBColor = RGBColor(214, 39, 40);
/// A limit drawn on a heat map (the static limit of the contact pressure).
pub(crate) const LIMIT: RGBColor = RGBColor(214, 39, 40);
/// The hatching over a whirl cell kept in a colour scale.
pub(crate) const WHIRL_OVER: ShapeStyle = ShapeStyle {
    color: RGBAColor(255, 255, 255, 0.6),
    filled: false,
    stroke_width: 1,
};

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

pub(crate) const ALL_CLASSES: [OrbitClass; 5] = [
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
    /// A box of a colour with white hatching over it (the other diagonal when true): a whirl
    /// cell kept in the colour scale.
    HatchOver(RGBColor, bool),
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
    /// An open square (drawn by `open_square`).
    OpenSquare(RGBColor),
    /// A filled diamond (drawn by `diamond`).
    Diamond(RGBColor),
    /// Where a drop was, on a grid of uneven cells (drawn by `drop_dot`).
    Drop,
}

/// A drop's place on a grid chart: a small dark dot ringed in white, seen on every cell
/// colour.
pub(crate) fn drop_dot<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
) -> DrawResult<DB> {
    area.draw(&Circle::new(at, 4, WHITE.filled()))?;
    area.draw(&Circle::new(at, 3, RGBColor(30, 30, 30).filled()))
}

/// Draws hatch lines (45 degrees; the other diagonal if `forward`) in a pixel rectangle.
pub(crate) fn hatch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x0, y0): (i32, i32),
    (x1, y1): (i32, i32),
    forward: bool,
) -> DrawResult<DB> {
    hatch_in(area, (x0, y0), (x1, y1), forward, HATCH.stroke_width(1))
}

/// Draws hatch lines as [`hatch`] does, in `style`.
pub(crate) fn hatch_in<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x0, y0): (i32, i32),
    (x1, y1): (i32, i32),
    forward: bool,
    style: ShapeStyle,
) -> DrawResult<DB> {
    const STEP: i32 = 9;
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
pub(crate) fn cross<DB: DrawingBackend>(
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
    let style = text_style(TICK_FONT).pos(Pos::new(HPos::Left, VPos::Center));
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
pub(crate) fn draw_mark<DB: DrawingBackend>(
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
        Mark::HatchOver(c, forward) => {
            area.draw(&Rectangle::new([(bx0, by0), (bx1, by1)], c.filled()))?;
            hatch_in(area, (bx0, by0), (bx1, by1), forward, WHIRL_OVER)?;
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
        Mark::Drop => drop_dot(area, (x + mark_w / 2, y))?,
        Mark::OpenDot(c) => {
            area.draw(&Circle::new((x + mark_w / 2, y), 5, WHITE.filled()))?;
            area.draw(&Circle::new((x + mark_w / 2, y), 5, c.stroke_width(2)))?;
        }
        Mark::OpenSquare(c) => open_square(area, (x + mark_w / 2, y), 5, c)?,
        Mark::Diamond(c) => diamond(area, (x + mark_w / 2, y), 6, c)?,
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

/// An open square of half-width `r` centred at pixel `p`: white inside, a 2 px outline.
pub(crate) fn open_square<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    r: i32,
    colour: RGBColor,
) -> DrawResult<DB> {
    let corners = [(x - r, y - r), (x + r, y + r)];
    area.draw(&Rectangle::new(corners, WHITE.filled()))?;
    area.draw(&Rectangle::new(corners, colour.stroke_width(2)))
}

/// A filled diamond of half-diagonal `r` centred at pixel `p`, ringed in white.
pub(crate) fn diamond<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    r: i32,
    colour: RGBColor,
) -> DrawResult<DB> {
    let pts = vec![(x, y - r), (x + r, y), (x, y + r), (x - r, y), (x, y - r)];
    area.draw(&Polygon::new(pts.clone(), colour.filled()))?;
    area.draw(&PathElement::new(pts, WHITE.stroke_width(1)))
}

/// Draws `text` with a white box behind it, centred at pixel `(x, y)` of `area`.
pub(crate) fn boxed_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    (x, y): (i32, i32),
    size: f64,
    colour: RGBColor,
) -> DrawResult<DB> {
    let style = text_style(size)
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
