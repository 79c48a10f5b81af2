//! Embedded font registration for the charts.
//!
//! plotters is built without its `ttf` feature, so it never asks the operating system for
//! fonts: every family a chart names must be registered from bytes first. This module embeds
//! DejaVu Sans (licence in `assets/DejaVu-LICENSE.txt`) and registers it once per process as
//! the `"sans-serif"` family, which is what plotters' defaults and [`crate::render`] use.
//! Charts therefore render identically on machines with no system fonts at all.

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

/// The font family name every chart uses (and plotters' default for axis labels).
pub const FONT_FAMILY: &str = "sans-serif";

/// DejaVu Sans, regular. The only face embedded: other styles fall back to it.
pub(crate) static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The embedded font bytes could not be parsed as a font.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("embedded font {font} for family \"{family}\" could not be parsed")]
pub struct FontError {
    /// The embedded font file's name.
    pub font: &'static str,
    /// The family it was being registered as.
    pub family: &'static str,
}

/// Registers the embedded fonts with plotters; cheap and idempotent, safe from any thread.
///
/// Call before drawing any text. [`crate::render`] does so itself.
pub fn register_embedded_fonts() -> Result<(), FontError> {
    static REGISTERED: OnceLock<Result<(), FontError>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            // plotters falls back to the Normal face for any style not registered, but the
            // styles we may ask for are registered explicitly so that stays true even if
            // that fallback changes.
            for style in [FontStyle::Normal, FontStyle::Bold] {
                register_font(FONT_FAMILY, style, DEJAVU_SANS).map_err(|_| FontError {
                    font: "DejaVuSans.ttf",
                    family: FONT_FAMILY,
                })?;
            }
            Ok(())
        })
        .clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_font_registers_twice_without_error() {
        assert_eq!(register_embedded_fonts(), Ok(()));
        assert_eq!(register_embedded_fonts(), Ok(()));
    }
}
