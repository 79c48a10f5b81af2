//! # whirlmap-plot: the charts
//!
//! Draws what a results folder holds (through [`whirlmap_results`]), one drop's orbit and
//! temperatures, and the work-precision study, with an embedded font so charts render on
//! machines without system fonts. It knows the files and the model's plain types, never the
//! engine that runs drops.
//!
//! - [`render_all()`]: every chart of a results folder into its `charts/` (Figs. 3 to 6, the
//!   class map, the peak temperature, the bearing's drops to failure and contact pressure,
//!   Fig. 4 with probability bands).
//! - One chart per file: [`fig3_orbits`], [`fig4`] (critical speeds), [`fig5`] (maximum
//!   contact force), [`fig6`] (peak heat power), [`peak_temperature`], [`bearing_life`]
//!   (drops to failure, contact pressure against the static limit), [`classes`] (the class
//!   map, also with a comparison's marked cells), [`probability`] (Fig. 4 with probability
//!   bands), [`accuracy`] (work precision), [`thermal`] (one drop's temperatures), [`orbit`]
//!   (one drop's orbit).
//! - Shared pieces: [`heatmap`] (the grid figure behind Figs. 5 and 6, the peak temperature
//!   and the class map), [`render`] (the figure trait, output formats, styling), [`axes`],
//!   [`colour_bar`], [`marks`] (legend and cell marks), [`contour`] (marching squares),
//!   [`fonts`], [`load`] (the inputs) and [`error`].
#![warn(missing_docs)]
// `!(x <= bound)` on purpose: a NaN fails the check instead of passing it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accuracy;
pub mod axes;
pub mod bearing_life;
pub mod classes;
pub mod colour_bar;
pub mod contour;
pub mod error;
pub mod fig3_orbits;
pub mod fig4;
pub mod fig5;
pub mod fig6;
pub mod fonts;
pub mod heatmap;
pub mod load;
pub mod marks;
pub mod orbit;
pub mod peak_temperature;
pub mod probability;
pub mod render;
pub mod render_all;
pub mod text;
pub mod thermal;

pub use error::ChartError;
pub use load::{load_critical, load_orbits, load_points, load_probability};
pub use render_all::{render_all, render_all_keeping, FIG3_ORBITS};
