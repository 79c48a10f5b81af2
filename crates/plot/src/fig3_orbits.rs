//! Fig. 3: the recorded orbits, one panel each.

use plotters::coord::Shift;
use plotters::prelude::*;
use whirlmap_results::grid::clamp_value;
use whirlmap_results::orbit::OrbitFile;

use crate::marks::{legend, Mark};
use crate::render::{
    decimate_samples, format_quantity, orbit_panel, with_header, DrawResult, Figure, CAPTION_FONT,
    CLEARANCE_COLOUR, PATH_COLOUR, TITLE_BAND, TITLE_FONT,
};

pub(crate) struct OrbitPanels<'a> {
    pub(crate) orbits: &'a [OrbitFile],
    pub(crate) title: String,
}

pub(crate) const START_COLOUR: RGBColor = RGBColor(44, 160, 44);
pub(crate) const END_COLOUR: RGBColor = RGBColor(214, 39, 40);

pub(crate) fn panel_layout(n: usize) -> (usize, usize) {
    let cols = match n {
        0 | 1 => 1,
        2 | 4 => 2,
        3 | 5 | 6 | 9 => 3,
        _ => 4,
    };
    (cols, n.max(1).div_ceil(cols))
}

pub(crate) fn orbit_figure_size(n: usize) -> (u32, u32) {
    let (cols, rows) = panel_layout(n);
    let w = (cols as u32 * 420).max(1000);
    let h = TITLE_BAND + 44 + rows as u32 * if cols == 1 { 600 } else { 430 };
    // A single row of square panels needs no more height than its panels (a floor of 700
    // left the lower half of three panels empty).
    (w, if rows == 1 && cols > 1 { h } else { h.max(700) })
}

impl Figure for OrbitPanels<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let body = with_header(root, TITLE_BAND, &self.title, TITLE_FONT)?;
        let (_, bh) = body.dim_in_pixel();
        let (panels_area, legend_band) = body.split_vertically(bh.saturating_sub(44));
        let (cols, rows) = panel_layout(self.orbits.len());
        let panels = panels_area.split_evenly((rows, cols));
        for (o, area) in self.orbits.iter().zip(panels.iter()) {
            let caption = format!(
                "µ = {}, {} r/min: {}",
                format_quantity(o.mu),
                format_quantity(o.speed_rpm),
                o.class_label()
            );
            let plot = with_header(area, 34, &caption, CAPTION_FONT)?;
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
