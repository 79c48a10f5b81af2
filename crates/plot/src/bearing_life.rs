//! The touchdown bearing's survival over release speed and friction (records made with the
//! bearing analysis only): drops to fatigue failure on a log colour scale, and the peak
//! Hertz contact pressure against the static limit of ISO 76. Whirl cells stay in both
//! scales, hatched: a whirl's load is what matters most to the bearing.

use whirlmap_results::grid::{distinct_sorted, Grid};

use crate::heatmap::{with_slice, GridFigure, GridMode, Limit, Metric};
use crate::render::format_quantity;

/// ISO 76's limit of the contact pressure for ball bearings (GPa): above it the races take a
/// permanent dent (brinelling).
pub const ISO76_LIMIT_GPA: f64 = 4.2;

/// The static limit the records were judged against (GPa), from their pressure times their
/// safety factor (the limit over the pressure), rounded to the MPa; `None` when the records
/// disagree (a sweep over the limit) or carry none.
fn static_limit_gpa(grid: &Grid) -> Option<f64> {
    let limits = distinct_sorted(grid.rows.iter().filter_map(|r| {
        let gpa = r.peak_contact_pressure_pa? * r.static_safety_factor? / 1e9;
        Some((gpa * 1e3).round() / 1e3)
    }));
    match limits.as_slice() {
        [l] => Some(*l),
        _ => None,
    }
}

/// Up to three decimals, trailing zeros dropped.
fn plain_or_3(x: f64) -> String {
    let s = format!("{x:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// What a whirl cell's value covers: a rigid-housing whirl run is stopped after a set number
/// of carried turns, so its damage is that of those turns only.
fn whirl_words(grid: &Grid, what: &str) -> String {
    let turns = distinct_sorted(grid.rows.iter().filter_map(|r| r.whirl_stop_turns));
    match turns.as_slice() {
        [n] => format!(
            "whirl (hatched): {what} the run up to its {} whirl turn (it stops there)",
            ordinal(*n)
        ),
        _ => format!("whirl (hatched): {what} the run up to the whirl turn it stopped at"),
    }
}

/// A whole number without decimals, anything else as [`format_quantity`] writes it.
fn plain(x: f64) -> String {
    if x == x.round() && x.abs() < 1e15 {
        format!("{x:.0}")
    } else {
        format_quantity(x)
    }
}

/// "5th", "1st", "22nd": the turn the run stopped at.
fn ordinal(n: f64) -> String {
    let k = n.round() as i64;
    let suffix = match (k % 10, k % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{}{suffix}", plain(n))
}

/// The simulated duration of the drops, as "1 s", when all say the same.
fn duration_words(grid: &Grid) -> Option<String> {
    match distinct_sorted(grid.rows.iter().filter_map(|r| r.duration_s)).as_slice() {
        [d] => Some(format!("{} s", plain(*d))),
        _ => None,
    }
}

/// Drops to fatigue failure (L10, ISO 281 load-life, Palmgren-Miner) per cell
/// (`charts/drops_to_failure`).
pub(crate) fn drops_to_failure(grid: &Grid) -> GridFigure<'_> {
    let title = match duration_words(grid) {
        Some(d) => format!("Touchdown bearing: drops to fatigue failure (L10), drops of {d}"),
        None => "Touchdown bearing: drops to fatigue failure (L10)".to_string(),
    };
    GridFigure {
        grid,
        title: with_slice(&title, &grid.slice),
        mode: GridMode::Metric(Metric {
            // A drop that loads the bearing and does no damage has an infinite life (the
            // record's null); a drop without the analysis has no value.
            value: |r| {
                r.drops_to_failure
                    .or(r.peak_contact_pressure_pa.map(|_| f64::INFINITY))
            },
            whirl_in_scale: true,
            log: true,
            infinite_label: Some("no damage: infinite life"),
        }),
        bar_label: "drops to failure (log scale)",
        whirl_label: Some(whirl_words(grid, "the damage of")),
        limit: None,
    }
}

/// The peak contact pressure of the most loaded ball (GPa), with the static limit as a
/// dashed contour (`charts/contact_pressure`).
pub(crate) fn contact_pressure(grid: &Grid) -> GridFigure<'_> {
    GridFigure {
        grid,
        title: with_slice(
            "Touchdown bearing: peak ball-race contact pressure (Hertz)",
            &grid.slice,
        ),
        mode: GridMode::Metric(Metric {
            value: |r| r.peak_contact_pressure_pa.map(|p| p / 1e9),
            whirl_in_scale: true,
            log: false,
            infinite_label: None,
        }),
        bar_label: "peak contact pressure (GPa)",
        whirl_label: Some(whirl_words(grid, "the peak of")),
        limit: static_limit_gpa(grid).map(|gpa| Limit {
            value: gpa,
            name: if gpa == ISO76_LIMIT_GPA {
                "static limit 4.2 GPa (ISO 76)".to_string()
            } else {
                format!("static limit {} GPa (from the scene)", plain_or_3(gpa))
            },
            unit: "GPa",
        }),
    }
}
