//! The work-precision chart of `whirlmap accuracy`: error against cost, log-log, one panel per
//! case and one line per setting (its tolerance ladder), drawn with the embedded font.

use crate::render::{
    draw_legend_row, legend_rows, render, text_style, with_header, DrawResult, Figure, LegendMark,
    RenderError, AXIS_COLOUR, AXIS_DESC_FONT, CAPTION_FONT, GRID_BOLD, GRID_LIGHT, TICK_FONT,
    TITLE_BAND, TITLE_FONT,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Which cost the x axis shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostAxis {
    /// RHS evaluations (exact and repeatable).
    RhsEvals,
    /// Wall time in ms (this machine, noisy).
    WallMs,
}

/// One run of the study, as the chart takes it: the engine's rows reduced to plain values.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyRun {
    /// Case name.
    pub case: String,
    /// Setting name (`preset:standard` for the presets, which the chart leaves out).
    pub setting: String,
    /// Tolerance.
    pub rtol: f64,
    /// What the run cost and how far it was off; `None`: the run failed.
    pub cost: Option<RunCost>,
}

/// The cost and error of one finished run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunCost {
    /// RHS evaluations.
    pub rhs_evals: u64,
    /// Wall time (ms).
    pub wall_ms: f64,
    /// The largest relative error of the measured outputs (the y value).
    pub worst_rel: f64,
    /// Whether the orbit class agrees with the reference's.
    pub class_agrees: bool,
}

/// Errors below this are drawn at it (the reference's own floor is far above).
const ERR_FLOOR: f64 = 1e-12;

/// One line: a setting's (cost, error, class agrees) points in tolerance order.
struct Line {
    setting: String,
    points: Vec<(f64, f64, bool)>,
}

struct Panel {
    case: String,
    lines: Vec<Line>,
}

struct WorkPrecision {
    title: String,
    x_desc: &'static str,
    panels: Vec<Panel>,
    settings: Vec<String>,
}

/// Settings past the palette's ten colours are drawn dashed.
fn dashed(i: usize) -> bool {
    (PALETTE_LEN..2 * PALETTE_LEN).contains(&(i % (2 * PALETTE_LEN)))
}

const PALETTE_LEN: usize = 10;

fn colour(i: usize) -> RGBColor {
    const P: [RGBColor; 10] = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(127, 127, 127),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
    ];
    P[i % P.len()]
}

fn build(cases: &[String], runs: &[StudyRun], axis: CostAxis, title: &str) -> WorkPrecision {
    let mut settings: Vec<String> = Vec::new();
    for r in runs {
        if !r.setting.starts_with("preset:") && !settings.contains(&r.setting) {
            settings.push(r.setting.clone());
        }
    }
    let panels = cases
        .iter()
        .map(|case| Panel {
            case: case.clone(),
            lines: settings
                .iter()
                .map(|s| {
                    let mut points: Vec<(f64, f64, f64, bool)> = runs
                        .iter()
                        .filter(|r| &r.case == case && &r.setting == s)
                        .filter_map(|r| r.cost.map(|c| (r.rtol, c)))
                        .map(|(rtol, c)| {
                            let cost = match axis {
                                CostAxis::RhsEvals => c.rhs_evals as f64,
                                CostAxis::WallMs => c.wall_ms,
                            };
                            (rtol, cost, c.worst_rel.max(ERR_FLOOR), c.class_agrees)
                        })
                        .filter(|p| p.1 > 0.0 && p.1.is_finite() && p.2.is_finite())
                        .collect();
                    points.sort_by(|a, b| b.0.total_cmp(&a.0));
                    Line {
                        setting: s.clone(),
                        points: points.into_iter().map(|p| (p.1, p.2, p.3)).collect(),
                    }
                })
                .collect(),
        })
        .collect();
    WorkPrecision {
        title: title.to_string(),
        x_desc: match axis {
            CostAxis::RhsEvals => "cost: RHS evaluations",
            CostAxis::WallMs => "cost: wall time (ms, one thread)",
        },
        panels,
        settings,
    }
}

/// Powers of ten spanning `(lo, hi)`, padded to whole decades.
fn decades(lo: f64, hi: f64) -> (f64, f64) {
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil());
    if hi > lo {
        (lo, hi)
    } else {
        (lo, lo * 10.0)
    }
}

impl WorkPrecision {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        p: &Panel,
    ) -> DrawResult<DB> {
        let body = with_header(area, 30, &p.case, CAPTION_FONT)?;
        let all = p.lines.iter().flat_map(|l| l.points.iter());
        let (mut xl, mut xh, mut yl, mut yh) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(x, y, _) in all {
            xl = xl.min(x);
            xh = xh.max(x);
            yl = yl.min(y);
            yh = yh.max(y);
        }
        if xl > xh {
            (xl, xh, yl, yh) = (1.0, 10.0, 1e-6, 1.0);
        }
        let (xl, xh) = decades(xl, xh);
        let (yl, yh) = decades(yl, yh);
        let mut chart = ChartBuilder::on(&body)
            .margin(8)
            // Room for the last decade's tick label, centred on the right edge.
            .margin_right(24)
            .x_label_area_size(48)
            .y_label_area_size(70)
            .build_cartesian_2d((xl..xh).log_scale(), (yl..yh).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(self.x_desc)
            .y_desc("worst relative error")
            .x_labels(5)
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style(text_style(TICK_FONT))
            .axis_desc_style(text_style(AXIS_DESC_FONT))
            .axis_style(AXIS_COLOUR.stroke_width(1))
            .bold_line_style(GRID_BOLD.stroke_width(1))
            .light_line_style(GRID_LIGHT.stroke_width(1))
            .draw()?;
        for (i, line) in p.lines.iter().enumerate() {
            let k = self
                .settings
                .iter()
                .position(|s| *s == line.setting)
                .unwrap_or(i);
            let c = colour(k);
            let points = line.points.iter().map(|&(x, y, _)| (x, y));
            // The palette's second round is dashed, so no two settings look alike.
            if dashed(k) {
                chart.draw_series(DashedLineSeries::new(points, 7, 4, c.stroke_width(2)))?;
            } else {
                chart.draw_series(LineSeries::new(points, c.stroke_width(2)))?;
            }
            for &(x, y, agrees) in &line.points {
                if agrees {
                    chart.draw_series(std::iter::once(Circle::new((x, y), 4, c.filled())))?;
                } else {
                    chart.draw_series(std::iter::once(Cross::new((x, y), 6, c.stroke_width(2))))?;
                }
            }
        }
        Ok(())
    }
}

impl Figure for WorkPrecision {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let entries: Vec<(LegendMark, &str)> = self
            .settings
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let mark = if dashed(i) {
                    LegendMark::Dashed(colour(i))
                } else {
                    LegendMark::Line(colour(i))
                };
                (mark, s.as_str())
            })
            .collect();
        // As many legend rows as the settings' names need, 35 px each, under the panels.
        let legend_rows = legend_rows(&body, &entries)?;
        let h_total = body.dim_in_pixel().1;
        let (plots, legend) =
            body.split_vertically(h_total.saturating_sub(35 * legend_rows.len() as u32));
        let cols = 3usize;
        let rows = self.panels.len().div_ceil(cols).max(1);
        let areas = plots.split_evenly((rows, cols));
        for (a, p) in areas.iter().zip(&self.panels) {
            self.panel(a, p)?;
        }
        let mut rest = legend;
        for row in legend_rows {
            let (band, below) = rest.split_vertically(35);
            draw_legend_row(&band, row)?;
            rest = below;
        }
        // A note on the markers, in the last free panel if any.
        if let Some(a) = areas.get(self.panels.len()) {
            let style = text_style(TICK_FONT);
            let lines = [
                "One line per setting, one point per tolerance",
                "(loosest at the left). Dot: class agrees with",
                "the reference; cross: class differs.",
                "Error: the worst of the relative errors in first",
                "and maximum contact force and peak heat power.",
            ];
            for (k, t) in lines.iter().enumerate() {
                a.draw_text(t, &style, (20, 60 + 24 * k as i32))?;
            }
        }
        Ok(())
    }
}

/// Writes the work-precision chart of the study's `runs` against `axis` to `path` (`.png` or
/// `.svg`): one panel per entry of `cases`, in that order.
pub fn draw_work_precision(
    path: &Path,
    cases: &[String],
    runs: &[StudyRun],
    axis: CostAxis,
    title: &str,
) -> Result<(), RenderError> {
    let fig = build(cases, runs, axis, title);
    let rows = fig.panels.len().div_ceil(3).max(1) as u32;
    render(path, (1500, 80 + 70 + 420 * rows), &fig)
}
