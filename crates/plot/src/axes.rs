//! The axes shared by the grid charts and Fig. 4: figure size and axis descriptions.

/// Size (width, height) in pixels of the grid charts and Fig. 4.
pub const CHART_SIZE: (u32, u32) = (1000, 700);

pub(crate) const SPEED_DESC: &str = "release speed (r/min)";
pub(crate) const MU_DESC: &str = "friction coefficient µ (-)";
