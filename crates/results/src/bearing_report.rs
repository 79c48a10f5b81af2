//! The touchdown-bearing survival report of a sweep whose scene turns the bearing analysis
//! on ([`BEARING_REPORT_FILE`], `bearing.md`), made from its records alone, so that a whole
//! run and a merge of shards write the same bytes. It reads as the bearing section of a
//! qualification report: the verdict against the static limit and in fatigue, the bearing's
//! data, the worst drops and the assumptions behind every number.

use crate::files::BEARING_REPORT_FILE;
use crate::point::{load_points, PointRow, PointStatus, MU_KEYS, SPEED_KEYS};
use std::fmt::Write as _;
use std::path::Path;
use whirlmap_core::bearing::{assumptions, BearingPair};
use whirlmap_core::Scene;

/// What the report needs of a sweep's spec.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportSpec {
    /// The sweep's name.
    pub name: String,
    /// Simulated time per drop (s).
    pub duration_s: f64,
    /// The charts the spec lists (the report names the bearing charts among them).
    pub charts: Vec<String>,
    /// The names of the sweep's axes (an axis over `bearing.*` is said).
    pub axes: Vec<String>,
}

/// Where a drop is (its speed and friction, then its other axes' values; an axis it does
/// not have is not named), and what a stopped whirl's numbers cover.
fn at(r: &PointRow) -> String {
    let mut s = place(r);
    if let Some(n) = r.whirl_stop_turns {
        s.push_str(&format!(" (a whirl stopped after {n} turns)"));
    }
    s
}

/// Where a drop is: its speed and friction, then its other axes' values.
fn place(r: &PointRow) -> String {
    let mut parts: Vec<String> = Vec::new();
    if let Some(v) = r.speed_rpm() {
        parts.push(format!("{v} r/min"));
    }
    if let Some(v) = r.mu() {
        parts.push(format!("mu {v}"));
    }
    let axis = |k: &str| SPEED_KEYS.contains(&k) || MU_KEYS.contains(&k);
    for (k, v) in r.inputs.iter().filter(|(k, _)| !axis(k)) {
        parts.push(match v.as_f64() {
            Some(x) => format!("{k} {x}"),
            None => format!("{k} {v}"),
        });
    }
    parts.join(", ")
}

/// The report's text.
pub fn report(spec: &ReportSpec, pair: &BearingPair, rows: &[PointRow]) -> String {
    let ran: Vec<&PointRow> = rows
        .iter()
        .filter(|r| r.status == PointStatus::Ok)
        .collect();
    let failed = rows.len() - ran.len();
    // A drop that never loads the bearing has an infinite safety factor and no damage (the
    // record's nulls): it is judged, and passes.
    let ok: Vec<&PointRow> = ran
        .iter()
        .copied()
        .filter(|r| r.static_safety_factor.is_some())
        .collect();
    let unloaded = ran.len() - ok.len();
    let limit_gpa = pair.static_limit_pressure_pa / 1e9;
    let mut t = String::new();
    let w = &mut t;
    let _ = writeln!(w, "# Touchdown-bearing survival: sweep `{}`\n", spec.name);
    let mut counts = format!("{} ran", ran.len());
    if failed > 0 {
        counts.push_str(&format!(", {failed} failed (no bearing results)"));
    }
    if unloaded > 0 {
        counts.push_str(&format!(
            ", {unloaded} never loaded the bearing (no damage, an infinite margin)"
        ));
    }
    let charts: Vec<String> = ["drops_to_failure", "contact_pressure"]
        .iter()
        .filter(|c| spec.charts.iter().any(|s| s == *c))
        .map(|c| format!("`charts/{c}`"))
        .collect();
    // The version that ran the records (a report drawn again from older records names
    // theirs, not the binary's).
    let mut versions: Vec<u64> = rows.iter().filter_map(|r| r.model_version).collect();
    versions.sort_unstable();
    versions.dedup();
    let version = match versions.as_slice() {
        [] => "model version not recorded".to_string(),
        [v] => format!("model version {v}"),
        vs => format!(
            "model versions {}",
            vs.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")
        ),
    };
    let _ = writeln!(
        w,
        "{} drops of {} s each ({version}): {counts}. Every drop is in \
         `summary.csv`{}.\n",
        rows.len(),
        spec.duration_s,
        match charts.as_slice() {
            [] => String::new(),
            cs => format!("; the charts are {}", cs.join(" and ")),
        }
    );
    let varied: Vec<&str> = spec
        .axes
        .iter()
        .map(String::as_str)
        .filter(|n| n.starts_with("bearing."))
        .collect();
    if !varied.is_empty() {
        let _ = writeln!(
            w,
            "The sweep varies {}: the bearing's data below are the base scene's.\n",
            varied.join(", ")
        );
    }

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
            "- **Fatigue (ISO 281, L10):** of the drops not stopped as whirl, the fewest drops \
             to failure are {n:.3e}, at {}.",
            at(r)
        );
    }
    let whirls = ok.iter().filter(|r| r.whirl_stop_turns.is_some()).count();
    if let Some((n, r)) = fewest(true) {
        let _ = writeln!(
            w,
            "- **Whirl:** {whirls} of {} drops end in whirl. A whirl run is stopped once the \
             whirl is decided, so its damage is that of the run up to there: the fewest drops \
             to failure among them, {n:.3e} at {}, count that run only. In a rigid housing a \
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
    // A value the scene changed is the scene's, whatever the default's source.
    // The paper's pair as a drop runs it (k2 from the paper scene's support law).
    let paper = Scene {
        bearing: Some(BearingPair::default()),
        ..Scene::default()
    }
    .bearing_as_run()
    .expect("a bearing");
    let changed = [
        pair.rows != paper.rows,
        pair.contact_angle_rad != paper.contact_angle_rad,
        pair.ball_diameter_m != paper.ball_diameter_m,
        pair.pitch_diameter_m != paper.pitch_diameter_m,
        pair.balls_per_row != paper.balls_per_row,
        pair.inner_conformity != paper.inner_conformity
            || pair.outer_conformity != paper.outer_conformity,
        pair.young_modulus_pa != paper.young_modulus_pa
            || pair.poisson_ratio != paper.poisson_ratio,
        pair.dynamic_rating_n != paper.dynamic_rating_n,
        pair.static_rating_n != paper.static_rating_n,
        pair.static_limit_pressure_pa != paper.static_limit_pressure_pa,
        pair.lumped_stiffness_n_per_m1_5 != paper.lumped_stiffness_n_per_m1_5,
    ];
    // A rating that followed the geometry is its formula's, not a value the scene gave.
    let from_formula = [
        pair.iso281_dynamic_rating_n() == Some(pair.dynamic_rating_n),
        pair.iso76_static_rating_n() == pair.static_rating_n,
    ];
    for (k, ((q, v, src), changed)) in rows_table.into_iter().zip(changed).enumerate() {
        let src = match k {
            7 if changed && from_formula[0] => "ISO 281's formula for this geometry",
            8 if changed && from_formula[1] => "ISO 76 for this geometry",
            _ if changed => "the scene",
            _ => src,
        };
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
    // A speed and a friction column on a speed x friction grid; otherwise one column naming
    // each drop's axes.
    let speed_mu = rows.iter().all(|r| {
        r.speed_rpm().is_some()
            && r.mu().is_some()
            && r.inputs
                .keys()
                .all(|k| SPEED_KEYS.contains(&k.as_str()) || MU_KEYS.contains(&k.as_str()))
    });
    let _ = writeln!(
        w,
        "| {} | class | peak contact pressure (GPa) | static safety factor | drops to failure (L10) |\n|---|---|---|---|---|{}",
        if speed_mu { "speed (r/min) | mu" } else { "drop" },
        if speed_mu { "---|" } else { "" }
    );
    for r in by_drops.iter().take(10) {
        let _ = writeln!(
            w,
            "| {} | {}{} | {:.3} | {:.2} | {:.3e} |",
            if speed_mu {
                format!(
                    "{} | {}",
                    r.speed_rpm().map_or(String::new(), |v| format!("{v}")),
                    r.mu().map_or(String::new(), |v| format!("{v}"))
                )
            } else {
                place(r)
            },
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Failed drops, drops that never load the bearing and a changed bearing are each said.
    #[test]
    fn failures_unloaded_drops_and_scene_values_are_named() {
        let spec = ReportSpec {
            name: "t".to_string(),
            duration_s: 0.1,
            charts: vec!["contact_pressure".to_string()],
            axes: vec!["speed_rpm".to_string()],
        };
        let pair = Scene {
            bearing: Some(BearingPair {
                balls_per_row: 20,
                ..BearingPair::default()
            }),
            ..Scene::default()
        }
        .bearing_as_run()
        .unwrap();
        let line = |i: u64, status: &str, rec: &str| {
            let text = format!(
                r#"{{"key": "k{i}", "index": {i}, "inputs": {{"speed_rpm": {}}}, "status": "{status}"{rec}}}"#,
                1000 + 500 * i
            );
            PointRow::from(serde_json::from_str::<crate::point::PointLine>(&text).unwrap())
        };
        let rows = vec![
            line(
                0,
                "ok",
                r#", "record": {"class": "pendulum", "peak_contact_pressure_pa": 1.4e9, "static_safety_factor": 3.0, "damage_per_drop": 1e-12, "drops_to_failure": 1e12}"#,
            ),
            line(
                1,
                "ok",
                r#", "record": {"class": "pendulum", "peak_contact_pressure_pa": 0.0, "static_safety_factor": null, "damage_per_drop": 0.0, "drops_to_failure": null}"#,
            ),
            line(2, "failed", r#", "error": {"kind": "x", "message": "y"}"#),
        ];
        let text = report(&spec, &pair, &rows);
        assert!(
            text.contains("3 drops of 0.1 s each (model version not recorded)"),
            "{text}"
        );
        assert!(
            text.contains("2 ran, 1 failed (no bearing results), 1 never loaded the bearing"),
            "{text}"
        );
        assert!(
            text.contains("the charts are `charts/contact_pressure`."),
            "{text}"
        );
        assert!(
            text.contains("| balls per row | 20 | the scene |"),
            "{text}"
        );
        assert!(
            text.contains("| ball diameter | 5.5 mm | paper, Table 3 |"),
            "{text}"
        );
        assert!(
            text.contains("The lowest static safety factor is 3.00"),
            "{text}"
        );
        // A speed axis without a friction axis: the drops are named by the axes they have
        // (the friction was printed as "?"), in one column.
        assert!(
            text.contains("(peak contact pressure 1.40 GPa), at 1000 r/min."),
            "{text}"
        );
        assert!(
            text.contains("| drop | class |") && text.contains("| 1000 r/min | pendulum |"),
            "{text}"
        );
        assert!(!text.contains('?'), "{text}");
        // The axes: one over the bearing is said.
        let varied = ReportSpec {
            axes: vec!["bearing.balls_per_row".to_string()],
            ..spec.clone()
        };
        assert!(report(&varied, &pair, &rows).contains("The sweep varies bearing.balls_per_row"));
        // The model version is the records' (a report drawn again from older records names
        // theirs), and two are both named.
        let versioned = |v: u64| {
            let mut r = rows[0].clone();
            r.model_version = Some(v);
            r
        };
        let text = report(&spec, &pair, &[versioned(7), versioned(7)]);
        assert!(text.contains("(model version 7)"), "{text}");
        let text = report(&spec, &pair, &[versioned(8), versioned(7)]);
        assert!(text.contains("(model versions 7, 8)"), "{text}");
    }
}
