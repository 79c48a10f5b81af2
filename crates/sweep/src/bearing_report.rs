//! `bearing.md`: the touchdown-bearing survival report of a sweep whose scene turns the
//! bearing analysis on, written from `points.jsonl` beside `summary.csv` (so a merge of
//! shards writes the same bytes). It reads as the bearing section of a qualification report:
//! the verdict against the static limit and in fatigue, the bearing's data, the worst drops
//! and the assumptions behind every number.

use crate::folder::write_atomic;
use crate::spec::SweepSpec;
use crate::sweep::SweepError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use whirlmap_core::bearing::{assumptions, BearingPair};
use whirlmap_core::MODEL_VERSION;
use whirlmap_results::files::BEARING_REPORT_FILE;
use whirlmap_results::point::{load_points, PointRow, PointStatus};

/// Writes `dir/bearing.md` when the spec's scene has a bearing; returns its path.
pub fn write(spec: &SweepSpec, dir: &Path) -> Result<Option<PathBuf>, SweepError> {
    let Some(pair) = spec.scene.bearing.as_ref() else {
        return Ok(None);
    };
    let rows = load_points(dir).map_err(|e| SweepError::Io {
        path: dir.join(whirlmap_results::files::POINTS_FILE),
        source: std::io::Error::other(e.to_string()),
    })?;
    let path = dir.join(BEARING_REPORT_FILE);
    write_atomic(&path, report(spec, pair, &rows).as_bytes())?;
    Ok(Some(path))
}

/// Where a drop is, and what a stopped whirl's numbers cover.
fn at(r: &PointRow) -> String {
    let mut s = format!(
        "{} r/min, mu {}",
        r.speed_rpm().map_or("?".to_string(), |v| format!("{v}")),
        r.mu().map_or("?".to_string(), |v| format!("{v}"))
    );
    if let Some(n) = r.whirl_stop_turns {
        s.push_str(&format!(" (a whirl stopped after {n} turns)"));
    }
    s
}

/// The report's text.
pub fn report(spec: &SweepSpec, pair: &BearingPair, rows: &[PointRow]) -> String {
    let ok: Vec<&PointRow> = rows
        .iter()
        .filter(|r| r.status == PointStatus::Ok && r.static_safety_factor.is_some())
        .collect();
    let failed = rows.len() - ok.len();
    let limit_gpa = pair.static_limit_pressure_pa / 1e9;
    let mut t = String::new();
    let w = &mut t;
    let _ = writeln!(w, "# Touchdown-bearing survival: sweep `{}`\n", spec.name);
    let _ = writeln!(
        w,
        "{} drops of {} s each (model version {MODEL_VERSION}), {} with the bearing analysis's \
         results{}. Every cell is in `summary.csv`; the charts are `charts/drops_to_failure` \
         and `charts/contact_pressure`.\n",
        rows.len(),
        spec.duration_s,
        ok.len(),
        if failed > 0 {
            format!(", {failed} without (failed drops)")
        } else {
            String::new()
        }
    );

    let _ = writeln!(w, "## Verdict\n");
    let over: Vec<&&PointRow> = ok
        .iter()
        .filter(|r| r.static_safety_factor.is_some_and(|f| f < 1.0))
        .collect();
    let lowest = ok.iter().min_by(|a, b| {
        a.static_safety_factor
            .unwrap_or(f64::INFINITY)
            .total_cmp(&b.static_safety_factor.unwrap_or(f64::INFINITY))
    });
    if let Some(r) = lowest {
        let sf = r.static_safety_factor.unwrap_or(f64::NAN);
        let p = r.peak_contact_pressure_pa.unwrap_or(f64::NAN) / 1e9;
        let head = if over.is_empty() {
            format!("no drop reaches the static limit of {limit_gpa} GPa")
        } else {
            format!(
                "**{} of {} drops exceed the static limit of {limit_gpa} GPa** and brinell the races",
                over.len(),
                ok.len()
            )
        };
        let _ = writeln!(
            w,
            "- **Static (brinelling, ISO 76):** {head}. The lowest static safety factor is \
             {sf:.2} (peak contact pressure {p:.2} GPa), at {}.",
            at(r)
        );
    }
    let fewest = |whirl: bool| {
        ok.iter()
            .filter(|r| r.whirl_stop_turns.is_some() == whirl)
            .filter_map(|r| r.drops_to_failure.map(|n| (n, *r)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    if let Some((n, r)) = fewest(false) {
        let _ = writeln!(
            w,
            "- **Fatigue (ISO 281, L10):** of the drops that run their full {} s, the fewest \
             drops to failure are {n:.3e}, at {}.",
            spec.duration_s,
            at(r)
        );
    }
    let whirls = ok.iter().filter(|r| r.whirl_stop_turns.is_some()).count();
    if let Some((n, r)) = fewest(true) {
        let _ = writeln!(
            w,
            "- **Whirl:** {whirls} of {} drops end in whirl. A whirl run is stopped once the \
             whirl is decided, so its damage is that of the turns it ran: the fewest drops to \
             failure among them, {n:.3e} at {}, count those turns only. In a rigid housing a \
             whirl goes on until the rotor is stopped, and every further turn adds damage.",
            ok.len(),
            at(r)
        );
    }
    let _ = writeln!(w);

    let _ = writeln!(w, "## The bearing\n");
    let _ = writeln!(w, "| quantity | value | source |\n|---|---|---|");
    let rows_table = [
        (
            "rows, arrangement",
            format!("{}, face to face", pair.rows),
            "two 71908 CD (the paper's touchdown bearing)",
        ),
        (
            "contact angle",
            format!("{:.1} deg", pair.contact_angle_rad.to_degrees()),
            "CD suffix: 15 deg",
        ),
        (
            "ball diameter",
            format!("{} mm", pair.ball_diameter_m * 1e3),
            "paper, Table 3",
        ),
        (
            "pitch diameter",
            format!("{} mm", pair.pitch_diameter_m * 1e3),
            "paper, Table 3",
        ),
        (
            "balls per row",
            format!("{}", pair.balls_per_row),
            "assumed (not in the paper or the catalogue tables)",
        ),
        (
            "groove conformities (inner, outer)",
            format!("{}, {}", pair.inner_conformity, pair.outer_conformity),
            "ISO 281 / ISO 76 rating basis",
        ),
        (
            "Young's modulus, Poisson's ratio",
            format!(
                "{} GPa, {}",
                pair.young_modulus_pa / 1e9,
                pair.poisson_ratio
            ),
            "bearing steel (AISI 52100)",
        ),
        (
            "dynamic load rating C of the pair",
            format!("{:.0} N", pair.dynamic_rating_n),
            "ISO 281 formula, i = 2",
        ),
        (
            "static load rating C0 of the pair",
            format!("{:.0} N", pair.static_rating_n),
            "ISO 76, i = 2",
        ),
        (
            "static limit of the contact pressure",
            format!("{limit_gpa} GPa"),
            "ISO 76 (ball bearings)",
        ),
        (
            "lumped support stiffness k2",
            format!("{:.4e} N/m^1.5", pair.lumped_stiffness_n_per_m1_5),
            "paper, Table 4 (the dynamics' support law)",
        ),
    ];
    for (q, v, src) in rows_table {
        let _ = writeln!(w, "| {q} | {v} | {src} |");
    }
    let _ = writeln!(w);

    let mut by_drops: Vec<&&PointRow> =
        ok.iter().filter(|r| r.drops_to_failure.is_some()).collect();
    by_drops.sort_by(|a, b| {
        a.drops_to_failure
            .unwrap_or(f64::INFINITY)
            .total_cmp(&b.drops_to_failure.unwrap_or(f64::INFINITY))
    });
    let _ = writeln!(w, "## The ten drops with the fewest drops to failure\n");
    let _ = writeln!(
        w,
        "| speed (r/min) | mu | class | peak contact pressure (GPa) | static safety factor | drops to failure (L10) |\n|---|---|---|---|---|---|"
    );
    for r in by_drops.iter().take(10) {
        let _ = writeln!(
            w,
            "| {} | {} | {}{} | {:.3} | {:.2} | {:.3e} |",
            r.speed_rpm().map_or("?".to_string(), |v| format!("{v}")),
            r.mu().map_or("?".to_string(), |v| format!("{v}")),
            r.class.map_or("?", |c| c.name()),
            r.whirl_stop_turns
                .map_or(String::new(), |n| format!(" (stopped after {n} turns)")),
            r.peak_contact_pressure_pa.unwrap_or(f64::NAN) / 1e9,
            r.static_safety_factor.unwrap_or(f64::NAN),
            r.drops_to_failure.unwrap_or(f64::NAN),
        );
    }
    let _ = writeln!(w);
    let _ = writeln!(w, "## Assumptions\n");
    for para in assumptions().split('\n') {
        let _ = writeln!(w, "{para}\n");
    }
    t
}

/// The worst cells of a sweep's records, as two lines for a terminal: the lowest static
/// safety factor and the fewest drops to failure, each with where it is. Empty when the
/// records carry no bearing results (or cannot be read).
pub fn worst_lines(dir: &Path) -> Vec<String> {
    let Ok(rows) = load_points(dir) else {
        return Vec::new();
    };
    let mut lines = Vec::new();
    let worst = rows
        .iter()
        .filter_map(|r| Some((r.static_safety_factor?, r.peak_contact_pressure_pa?, r)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((sf, p, r)) = worst {
        lines.push(format!(
            "bearing          lowest static safety factor {sf:.2}: peak contact pressure {:.2} GPa against {:.2} GPa, at {}",
            p / 1e9,
            sf * p / 1e9,
            at(r)
        ));
    }
    let fewest = rows
        .iter()
        .filter_map(|r| r.drops_to_failure.map(|n| (n, r)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((n, r)) = fewest {
        lines.push(format!(
            "fatigue          fewest drops to failure {n:.3e} (L10), at {}",
            at(r)
        ));
    }
    if dir.join(BEARING_REPORT_FILE).exists() {
        lines.push(format!(
            "bearing report   {}",
            dir.join(BEARING_REPORT_FILE).display()
        ));
    }
    lines
}
