//! Fig. 4 with probability bands, from an ensemble's `contours.json`: for each friction
//! coefficient, the speeds where P(whirl) reaches each level (10, 50, 90 % by default) as
//! lines with their intervals as error bars (beside the cells, capped where they end in the
//! range), the band between the lowest and the highest level shaded, and every cell's
//! P(whirl) as a dot shaded from white (0) to red (1), keyed in the legend.
//! Groups are placed by their `mu` input. With further (non-speed) axes the chart is one
//! slice, every further input at its value in the first group, and its title says which (as
//! the sweep maps do); a grid without a `mu` axis has no chart.

use crate::axes::CHART_SIZE;
use crate::error::ChartError;
use crate::render::{
    draw_mesh, render, text_style, with_header, DrawResult, Figure, TITLE_BAND, TITLE_FONT,
    X_LABEL_AREA, Y_LABEL_AREA,
};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use whirlmap_results::contours::{ContourGroup, ContoursFile};
use whirlmap_results::files::CONTOURS_FILE;
use whirlmap_results::read::LoadError;

const LEVEL_COLOURS: [RGBColor; 4] = [
    RGBColor(230, 145, 30),
    RGBColor(200, 30, 30),
    RGBColor(110, 20, 60),
    RGBColor(60, 60, 160),
];
const BAND: RGBColor = RGBColor(214, 39, 40);

struct ProbabilityFigure<'a> {
    contours: &'a ContoursFile,
    /// The groups drawn: the slice of [`slice`].
    groups: Vec<&'a ContourGroup>,
    title: String,
}

/// The groups of one slice of `contours`: every input other than the friction coefficient
/// that takes more than one value fixed at its value in the first group; with the slice in
/// words (`slice at clearance_m = 0.0001`) when there are such inputs. No groups when none
/// has a friction coefficient (then there is no Fig. 4 to draw).
pub(crate) fn slice(contours: &ContoursFile) -> (Vec<&ContourGroup>, Option<String>) {
    let with_mu: Vec<&ContourGroup> = contours
        .groups
        .iter()
        .filter(|g| mu_of(&g.inputs).is_some())
        .collect();
    let Some(first) = with_mu.first() else {
        return (Vec::new(), None);
    };
    let fixed: Vec<(&String, f64)> = first
        .inputs
        .iter()
        .filter(|(k, _)| !matches!(k.as_str(), "mu" | "mu_dynamic"))
        .filter(|(k, v)| with_mu.iter().any(|g| g.inputs.get(*k) != Some(v)))
        .map(|(k, v)| (k, *v))
        .collect();
    let groups = with_mu
        .iter()
        .copied()
        .filter(|g| fixed.iter().all(|(k, v)| g.inputs.get(*k) == Some(v)))
        .collect();
    let note = (!fixed.is_empty()).then(|| {
        let parts: Vec<String> = fixed.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        format!("slice at {}", parts.join(", "))
    });
    (groups, note)
}

fn mu_of(inputs: &std::collections::BTreeMap<String, f64>) -> Option<f64> {
    inputs
        .get("mu")
        .or_else(|| inputs.get("mu_dynamic"))
        .copied()
}

impl Figure for ProbabilityFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let mut groups: Vec<(f64, &ContourGroup)> = self
            .groups
            .iter()
            .filter_map(|g| mu_of(&g.inputs).filter(|m| m.is_finite()).map(|m| (m, *g)))
            .collect();
        groups.sort_by(|a, b| a.0.total_cmp(&b.0));
        let speeds: Vec<f64> = groups
            .iter()
            .flat_map(|(_, g)| g.speeds_rpm.iter().copied())
            .filter(|s| s.is_finite())
            .collect();
        // A single value gets a tenth of itself either side (at least `half`), not a unit:
        // one friction coefficient of 0.25 spans 0.225-0.275, not -0.75-1.25.
        let span = |v: &[f64], half: f64| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !lo.is_finite() {
                (0.0, 1.0)
            } else if hi > lo {
                (lo, hi)
            } else {
                let h = (0.1 * lo.abs()).max(half);
                (lo - h, lo + h)
            }
        };
        let (s_lo, s_hi) = span(&speeds, 100.0);
        let mus: Vec<f64> = groups.iter().map(|g| g.0).collect();
        let (m_lo, m_hi) = span(&mus, 0.01);
        let (pad_m, pad_s) = (0.08 * (m_hi - m_lo), 0.05 * (s_hi - s_lo));

        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (_, bh) = body.dim_in_pixel();
        let (plot_area, legend_band) = body.split_vertically(bh.saturating_sub(60));
        let mut chart = ChartBuilder::on(&plot_area)
            .margin_top(12)
            .margin_left(14)
            .margin_right(34)
            .margin_bottom(4)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(
                (m_lo - pad_m)..(m_hi + pad_m),
                (s_lo - pad_s)..(s_hi + pad_s),
            )?;
        draw_mesh(
            &mut chart,
            "friction coefficient µ (-)",
            "release speed (r/min)",
            10,
            8,
        )?;

        // Cells: P(whirl) as a dot from white to red.
        let cells = chart.plotting_area().strip_coord_spec();
        let base = chart.plotting_area().get_base_pixel();
        for (mu, g) in &groups {
            for (s, p) in g.speeds_rpm.iter().zip(&g.p_whirl) {
                let Some(p) = p.filter(|p| p.is_finite() && s.is_finite()) else {
                    continue;
                };
                let at = chart.backend_coord(&(*mu, *s));
                cell_dot(&cells, (at.0 - base.0, at.1 - base.1), p)?;
            }
        }

        let n_levels = self.groups.first().map_or(0, |g| g.levels.len());
        // The band between the lowest and the highest level; a level whose crossing lies
        // beyond the range puts the band's edge at that end of the chart: the top where it
        // is not reached, the bottom where it is reached already at the lowest speed. A
        // friction coefficient whose lowest level is not reached has no band.
        if n_levels >= 2 {
            let (bottom, top) = (s_lo - pad_s, s_hi + pad_s);
            let edge = |g: &ContourGroup, l: &whirlmap_results::contours::LevelCrossing| {
                l.speed_rpm
                    .or_else(|| g.reached_below_range(l.level).then_some(bottom))
            };
            let pts: Vec<(f64, f64, f64)> = groups
                .iter()
                .filter_map(|(m, g)| {
                    let a = edge(g, g.levels.first()?)?;
                    let b = edge(g, g.levels.last()?).unwrap_or(top);
                    Some((*m, a, b))
                })
                .collect();
            if pts.len() >= 2 {
                let poly: Vec<(f64, f64)> = pts
                    .iter()
                    .map(|p| (p.0, p.1))
                    .chain(pts.iter().rev().map(|p| (p.0, p.2)))
                    .collect();
                chart.draw_series([Polygon::new(poly, BAND.mix(0.12).filled())])?;
            }
        }
        // Data units per pixel along µ, to set the interval bars beside the cells' dots.
        let (plot_w, _) = chart.plotting_area().dim_in_pixel();
        let mu_per_px = (m_hi - m_lo + 2.0 * pad_m) / f64::from(plot_w.max(1));
        // Each level: a line through the crossings and error bars for the intervals.
        for k in 0..n_levels {
            let colour = LEVEL_COLOURS[k % LEVEL_COLOURS.len()];
            let pts: Vec<(f64, f64)> = groups
                .iter()
                .filter_map(|(m, g)| Some((*m, g.levels.get(k)?.speed_rpm?)))
                .collect();
            chart.draw_series([PathElement::new(pts.clone(), colour.stroke_width(2))])?;
            for (m, g) in &groups {
                let Some(l) = g.levels.get(k) else { continue };
                if l.speed_rpm.is_none() && l.speed_lo_rpm.is_none() && l.speed_hi_rpm.is_none() {
                    continue;
                }
                let lo = l.speed_lo_rpm.unwrap_or(s_lo - pad_s);
                let hi = l.speed_hi_rpm.unwrap_or(s_hi + pad_s);
                // Side by side to the right of the cells' dots, one level after the other,
                // with a cap at each end inside the range (none where it runs out of it).
                let x = m + mu_per_px * (10.0 + 7.0 * k as f64);
                let cap = 3.0 * mu_per_px;
                let mut bar = vec![PathElement::new(
                    vec![(x, lo), (x, hi)],
                    colour.mix(0.8).stroke_width(2),
                )];
                for (end, bounded) in [(lo, l.speed_lo_rpm), (hi, l.speed_hi_rpm)] {
                    if bounded.is_some() {
                        bar.push(PathElement::new(
                            vec![(x - cap, end), (x + cap, end)],
                            colour.mix(0.8).stroke_width(2),
                        ));
                    }
                }
                chart.draw_series(bar)?;
            }
            chart.draw_series(
                pts.iter()
                    .map(|p| Circle::new(*p, 4, colour.filled()))
                    .collect::<Vec<_>>(),
            )?;
        }

        // Legend, two rows: the levels; then the cells' dots with their key and the bars.
        let style = text_style(14.0);
        let levels = self
            .groups
            .first()
            .map(|g| g.levels.as_slice())
            .unwrap_or_default();
        let mut x = 60;
        for (k, l) in levels.iter().enumerate() {
            let colour = LEVEL_COLOURS[k % LEVEL_COLOURS.len()];
            legend_band.draw(&PathElement::new(
                vec![(x, 18), (x + 30, 18)],
                colour.stroke_width(3),
            ))?;
            let text = format!("P(whirl) = {:.0} %", 100.0 * l.level);
            legend_band.draw_text(&text, &style, (x + 38, 9))?;
            x += 175;
        }
        let mut x = 60;
        let text = format!("cell P(whirl) ({} drops):", self.contours.members);
        legend_band.draw_text(&text, &style, (x, 35))?;
        x += legend_band.estimate_text_size(&text, &style)?.0 as i32 + 14;
        for p in [0.0, 0.5, 1.0] {
            cell_dot(&legend_band, (x, 43), p)?;
            legend_band.draw_text(&format!("{p}"), &style, (x + 11, 35))?;
            x += 44;
        }
        let text = format!(
            "bars: {:.0} % intervals, open where they leave the range",
            100.0 * self.contours.confidence
        );
        legend_band.draw_text(&text, &style, (x + 20, 35))?;
        Ok(())
    }
}

/// One cell's P(whirl) as a dot shaded from white (0) to red (1).
fn cell_dot<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    p: f64,
) -> DrawResult<DB> {
    let fill = BAND.mix(0.08 + 0.85 * p.clamp(0.0, 1.0));
    area.draw(&Circle::new(at, 5, fill.filled()))?;
    area.draw(&Circle::new(at, 5, RGBColor(150, 150, 150).stroke_width(1)))
}

/// Why an ensemble has no Fig. 4 as probability ([`render_probability`] draws none): the
/// commands that run or redraw it say this.
pub const NO_MU_AXIS: &str =
    "no chart: Fig. 4 as probability is drawn over the friction coefficient, and the \
     ensemble's grid has no mu axis";

/// Draws `charts/fig4_probability.{png,svg}` in `dir` if `dir/contours.json` exists;
/// returns the files written (none without contours, or without a friction axis in them).
pub fn render_probability(dir: &Path) -> Result<Vec<PathBuf>, ChartError> {
    let path = dir.join(CONTOURS_FILE);
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(cause) => return Err(LoadError::Read { path, cause }.into()),
    };
    let contours: ContoursFile = serde_json::from_str(&text).map_err(|e| LoadError::Parse {
        path: path.clone(),
        line: e.line(),
        message: e.to_string(),
    })?;
    let (groups, note) = slice(&contours);
    if groups.is_empty() {
        return Ok(Vec::new());
    }
    let out = dir.join(whirlmap_results::files::CHARTS_DIR);
    std::fs::create_dir_all(&out).map_err(|cause| ChartError::Write {
        path: out.clone(),
        cause,
    })?;
    let what = match note {
        Some(n) => format!("{}, {n}", contours.name),
        None => contours.name.clone(),
    };
    let figure = ProbabilityFigure {
        contours: &contours,
        groups,
        title: format!("Fig. 4 as probability: critical whirl speed bands ({what})"),
    };
    let mut written = Vec::new();
    for ext in ["png", "svg"] {
        let name = format!("fig4_probability.{ext}");
        debug_assert!(whirlmap_results::files::is_chart_file(&name), "{name}");
        let p = out.join(name);
        render(&p, CHART_SIZE, &figure)?;
        written.push(p);
    }
    Ok(written)
}
