//! One drop's orbit, the paper's Fig. 3 view: the rotor centre's path relative to the race
//! inside the clearance circle, above the contact force against time.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use whirlmap_core::orbit::{Orbit, OrbitSample};

use crate::render::{
    decimate_samples, draw_legend_row, draw_mesh, draw_thin_line, finite_bounds, format_quantity,
    orbit_panel, padded_range, render, text_style, with_header, DrawResult, Figure, LegendMark,
    RenderError, CAPTION_FONT, CLEARANCE_COLOUR, END_COLOUR, FORCE_COLOUR, PATH_COLOUR,
    START_COLOUR, TITLE_BAND, TITLE_FONT, X_LABEL_AREA, Y_LABEL_AREA,
};

/// Size (width, height) in pixels of the orbit figure drawn by [`draw_orbit`].
pub const ORBIT_FIGURE_SIZE: (u32, u32) = (900, 1100);

/// Most samples [`draw_orbit`] draws; longer orbits are thinned by [`decimate_samples`].
pub const MAX_DRAWN_SAMPLES: usize = 20_000;

/// Draws a recorded orbit, the paper's Fig. 3 view, to `path` (`.png` or `.svg`).
///
/// Top: the rotor centre's path relative to the race in µm, equal aspect, inside the dashed
/// clearance circle, with the release and final positions marked. Bottom: the contact force
/// against time. Orbits longer than [`MAX_DRAWN_SAMPLES`] are thinned for drawing by
/// [`decimate_samples`], which keeps every bucket's force peak.
pub fn draw_orbit(path: &Path, title: &str, orbit: &Orbit) -> Result<(), RenderError> {
    let figure = OrbitFigure {
        title,
        clearance_m: orbit.clearance_m,
        samples: decimate_samples(&orbit.samples, MAX_DRAWN_SAMPLES),
    };
    render(path, ORBIT_FIGURE_SIZE, &figure)
}

// ---------------------------------------------------------------------------------------------
// The orbit figure.

pub(crate) struct OrbitFigure<'a> {
    title: &'a str,
    clearance_m: f64,
    samples: Vec<OrbitSample>,
}

/// Fraction of the area below the title given to the orbit (top) panel.
pub(crate) const ORBIT_PANEL_SHARE: f64 = 0.655;

impl Figure for OrbitFigure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(root, TITLE_BAND, self.title, TITLE_FONT)?;
        let top_h = (body.dim_in_pixel().1 as f64 * ORBIT_PANEL_SHARE).round() as u32;
        let (top, bottom) = body.split_vertically(top_h);
        self.draw_path_panel(&top)?;
        self.draw_force_panel(&bottom)
    }
}

impl OrbitFigure<'_> {
    fn clearance_um(&self) -> Option<f64> {
        let c = self.clearance_m * 1e6;
        (c.is_finite() && c > 0.0).then_some(c)
    }

    /// Top panel: rotor-centre path relative to the race, equal aspect, clearance circle.
    fn draw_path_panel<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let path: Vec<(f64, f64)> = self
            .samples
            .iter()
            .map(|s| (s.x_rel_m * 1e6, s.y_rel_m * 1e6))
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        let clearance = self.clearance_um();

        let caption = "Rotor-centre path relative to the race";
        let rest = with_header(area, 34, caption, CAPTION_FONT)?;
        let (legend_band, plot_area) = rest.split_vertically(26);
        let mut legend = vec![(LegendMark::Line(PATH_COLOUR), "path".to_string())];
        if !path.is_empty() {
            legend.push((LegendMark::Dot(START_COLOUR), "release".to_string()));
            legend.push((LegendMark::Dot(END_COLOUR), "end".to_string()));
        }
        if let Some(c) = clearance {
            let text = format!("clearance circle, r = {} µm", format_quantity(c));
            legend.push((LegendMark::Dashed(CLEARANCE_COLOUR), text));
        }
        let legend: Vec<(LegendMark, &str)> =
            legend.iter().map(|(m, t)| (*m, t.as_str())).collect();
        draw_legend_row(&legend_band, &legend)?;

        orbit_panel(
            &plot_area,
            &path,
            clearance,
            (X_LABEL_AREA, Y_LABEL_AREA),
            9,
        )
    }

    /// Bottom panel: contact force against time.
    fn draw_force_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> DrawResult<DB> {
        let points: Vec<(f64, f64)> = self
            .samples
            .iter()
            .map(|s| (s.t_s * 1e3, s.contact_force_n))
            .filter(|(t, f)| t.is_finite() && f.is_finite())
            .collect();
        let peak = points
            .iter()
            .copied()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .filter(|p| p.1 > 0.0);
        let caption = match peak {
            Some((t, f)) => format!(
                "Rotor-race contact force (peak {} N at {} ms)",
                format_quantity(f),
                format_quantity(t)
            ),
            None => "Rotor-race contact force".to_string(),
        };
        let plot_area = with_header(area, 34, &caption, CAPTION_FONT)?;

        let t_range = padded_range(finite_bounds(points.iter().map(|p| p.0)), 0.0);
        let f_bounds = finite_bounds(points.iter().map(|p| p.1));
        let f_range = match f_bounds {
            Some((lo, hi)) if hi > 0.0 => (lo.min(0.0), hi + (hi - lo.min(0.0)) * 0.06),
            other => padded_range(other.map(|(lo, hi)| (lo.min(0.0), hi.max(0.0))), 0.06),
        };
        let mut chart = ChartBuilder::on(&plot_area)
            .margin_top(8)
            .margin_bottom(6)
            .margin_left(20)
            .margin_right(34)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(t_range.0..t_range.1, f_range.0..f_range.1)?;
        draw_mesh(&mut chart, "time (ms)", "contact force (N)", 10, 6)?;
        if points.is_empty() {
            let style = text_style(CAPTION_FONT).pos(Pos::new(HPos::Center, VPos::Center));
            let (w, h) = chart.plotting_area().dim_in_pixel();
            chart.plotting_area().strip_coord_spec().draw_text(
                "no samples recorded",
                &style,
                (w as i32 / 2, h as i32 / 2),
            )?;
        } else {
            draw_thin_line(&mut chart, &points, FORCE_COLOUR)?;
        }
        Ok(())
    }
}
