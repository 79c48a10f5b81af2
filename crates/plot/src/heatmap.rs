//! The grid figure: the heat maps (Figs. 5 and 6, peak temperature) and the class map, cells
//! over release speed and friction.

use plotters::coord::Shift;
use plotters::prelude::*;
use whirlmap_core::classify::OrbitClass;
use whirlmap_results::grid::{clamp_value, Grid};
use whirlmap_results::point::PointRow;

use crate::axes::{MU_DESC, SPEED_DESC};
use crate::colour_bar::{draw_colour_bar, scale_colour};
use crate::contour::{marching_squares, nice_levels};
use crate::marks::{
    boxed_text, class_colour, cross, hatch, legend, Mark, ALL_CLASSES, CONTOUR, FAILED_BG, WHIRL_BG,
};
use crate::render::{
    draw_mesh, format_quantity, with_header, DrawResult, Figure, CAPTION_FONT, TITLE_BAND,
    TITLE_FONT, X_LABEL_AREA, Y_LABEL_AREA,
};
use whirlmap_results::point::PointStatus;

/// Cell edges around increasing centres: midpoints, extended by half a step at the ends.
pub(crate) fn edges(centres: &[f64]) -> Vec<f64> {
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
    Class(OrbitClass),
    NoValue,
}

/// What the grid charts draw per cell.
#[derive(Clone, Copy)]
pub(crate) enum GridMode<'a> {
    /// A metric in a colour scale, whirl left out.
    Metric(fn(&PointRow) -> Option<f64>),
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
            GridMode::Metric(_) if class == OrbitClass::Unresolved => CellKind::Unresolved,
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

        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
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
            // A level just inside the range of the values cuts one corner of one cell: a
            // stray dot, not a line. A level whose contour is shorter than 30 pixels in all
            // is left out (here and on the colour bar).
            let seg_px = |s: &[(f64, f64); 2]| {
                let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                (((p.0 - q.0).pow(2) + (p.1 - q.1).pow(2)) as f64).sqrt()
            };
            let contours: Vec<_> = levels
                .iter()
                .map(|&level| (level, marching_squares(&g.speeds_rpm, &g.mus, &z, level)))
                .filter(|(_, segs)| segs.iter().map(seg_px).sum::<f64>() >= 30.0)
                .collect();
            levels = contours.iter().map(|(level, _)| *level).collect();
            for (level, segs) in &contours {
                for s in segs {
                    canvas.draw(&PathElement::new(
                        vec![px(s[0].0, s[0].1), px(s[1].0, s[1].1)],
                        CONTOUR.mix(0.8).stroke_width(2),
                    ))?;
                }
                // Label the level once, on its longest segment, if that is 24 px or more.
                let longest = segs.iter().max_by(|a, b| seg_px(a).total_cmp(&seg_px(b)));
                let long_enough = |s: &&[(f64, f64); 2]| seg_px(s) >= 24.0;
                if let Some(s) = longest.filter(long_enough) {
                    let (p, q) = (px(s[0].0, s[0].1), px(s[1].0, s[1].1));
                    boxed_text(
                        &canvas,
                        &format_quantity(*level),
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
                if any_unresolved {
                    entries.push((
                        Mark::Swatch(class_colour(OrbitClass::Unresolved)),
                        "unresolved (not settled; not in scale)".to_string(),
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
