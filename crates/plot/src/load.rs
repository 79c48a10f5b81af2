//! The inputs of the charts, read from a results folder through `whirlmap-results`.

use std::path::Path;

use whirlmap_results::contours::ContoursFile;
use whirlmap_results::critical::{read_critical, CriticalRow};
use whirlmap_results::files::{CONTOURS_FILE, PROBABILITY_DIR};
use whirlmap_results::orbit::read_orbits;
use whirlmap_results::read::read_json_optional;

use crate::error::ChartError;

pub use whirlmap_results::orbit::OrbitFile;
pub use whirlmap_results::point::{PointRow, PointStatus};

/// Reads `dir/points.jsonl` ([`whirlmap_results::point::load_points`]). Blank lines are
/// ignored and a torn last line (no newline, does not parse) after at least one record is
/// skipped; an unparseable line elsewhere, or a file whose only line is torn, is an error.
pub fn load_points(dir: &Path) -> Result<Vec<PointRow>, ChartError> {
    Ok(whirlmap_results::point::load_points(dir)?)
}

/// Reads `dir/critical.json` (a list of [`CriticalRow`]), or `None` if it does not exist.
pub fn load_critical(dir: &Path) -> Result<Option<Vec<CriticalRow>>, ChartError> {
    Ok(read_critical(dir)?)
}

/// Reads the probability ensemble's `contours.json` of a sweep (`dir/probability/`), or
/// `None` if the sweep ran none.
pub fn load_probability(dir: &Path) -> Result<Option<ContoursFile>, ChartError> {
    Ok(read_json_optional(
        &dir.join(PROBABILITY_DIR).join(CONTOURS_FILE),
    )?)
}

/// Reads every `dir/orbits/*.json`, sorted by speed then friction; empty if there are none.
pub fn load_orbits(dir: &Path) -> Result<Vec<OrbitFile>, ChartError> {
    Ok(read_orbits(dir)?)
}
