//! The bearing charts of a sweep (drops to failure, contact pressure against the static
//! limit) appear when, and only because, the records carry the bearing analysis, keep whirl
//! cells in their scales, and say what a whirl cell's value covers.

use serde_json::json;
use std::path::{Path, PathBuf};
use whirlmap_plot::{load_points, render_all};

/// A results folder of 3 x 3 points; `pressure_gpa(speed, mu)` sets each peak pressure. The
/// point at the highest speed and friction is a whirl run stopped after 5 carried turns.
fn folder(name: &str, bearing: bool, pressure_gpa: fn(f64, f64) -> f64) -> PathBuf {
    folder_with_limit(name, bearing, pressure_gpa, 4.2)
}

/// [`folder`] with the records judged against a static limit of `limit_gpa`.
fn folder_with_limit(
    name: &str,
    bearing: bool,
    pressure_gpa: fn(f64, f64) -> f64,
    limit_gpa: f64,
) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("whirlmap-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut lines = Vec::new();
    let mut index = 0;
    for mu in [0.1f64, 0.2, 0.3] {
        for speed in [4000.0, 8000.0, 12000.0] {
            let whirl = speed == 12000.0 && mu == 0.3;
            let mut rec = json!({
                "class": if whirl { "backward_whirl" } else { "pendulum" },
                "stop_reason": if whirl { "whirl_decided" } else { "duration" },
                "features": {"whirl_streak_turns": if whirl { -5.0 } else { 0.0 }},
                "max_contact_force_n": 900.0, "peak_heat_power_w": 100.0});
            if bearing {
                let damage = 1e-12 * (speed / 1000.0) * (mu * 10.0).powi(2);
                let p = pressure_gpa(speed, mu);
                rec["peak_contact_pressure_pa"] = json!(p * 1e9);
                rec["static_safety_factor"] = json!(limit_gpa / p);
                rec["damage_per_drop"] = json!(damage);
                rec["drops_to_failure"] = json!(1.0 / damage);
            }
            lines.push(
                json!({"key": format!("p{index}"), "index": index, "duration_s": 1.0,
                       "inputs": {"speed_rpm": speed, "mu": mu}, "status": "ok", "record": rec})
                .to_string(),
            );
            index += 1;
        }
    }
    std::fs::write(dir.join("points.jsonl"), lines.join("\n")).unwrap();
    dir
}

/// The texts of a chart's SVG (plotters writes each on a line of its own).
fn texts(dir: &Path, stem: &str) -> Vec<String> {
    let svg = std::fs::read_to_string(dir.join("charts").join(format!("{stem}.svg"))).unwrap();
    svg.lines()
        .filter(|l| !l.trim_start().starts_with('<'))
        .map(|l| l.trim().to_string())
        .collect()
}

fn has(texts: &[String], text: &str) -> bool {
    texts.iter().any(|t| t == text)
}

/// The polylines of a chart's SVG drawn in the limit colour (rgb 214 39 40) that lie inside
/// the map (left of the colour bar at x > 845 px, above the legend at y > 620 px), as
/// their points.
fn limit_lines_in_map(dir: &Path, stem: &str) -> Vec<Vec<(f64, f64)>> {
    let svg = std::fs::read_to_string(dir.join("charts").join(format!("{stem}.svg"))).unwrap();
    svg.lines()
        .filter(|l| l.contains("<polyline") && l.contains("stroke=\"#D62728\""))
        .filter_map(|l| {
            let pts = l.split("points=\"").nth(1)?.split('"').next()?;
            let points: Vec<(f64, f64)> = pts
                .split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect();
            let inside = points.iter().all(|&(x, y)| x < 845.0 && y < 620.0);
            inside.then_some(points)
        })
        .collect()
}

#[test]
fn bearing_charts_are_drawn_from_records_with_the_analysis() {
    let dir = folder("bearing-charts", true, |speed, _| 1.0 + speed / 10000.0);
    let rows = load_points(&dir).unwrap();
    let whirl: Vec<Option<f64>> = rows.iter().map(|r| r.whirl_stop_turns).collect();
    assert_eq!(whirl.iter().filter(|t| t.is_some()).count(), 1);
    assert_eq!(whirl[8], Some(5.0));
    let drops = rows[0].drops_to_failure.unwrap();
    assert!((drops / 2.5e11 - 1.0).abs() < 1e-12, "{drops}");
    assert_eq!(rows[0].peak_contact_pressure_pa, Some(1.4e9));

    let written = render_all(&dir).unwrap();
    for stem in ["drops_to_failure", "contact_pressure"] {
        for ext in ["png", "svg"] {
            let p = dir.join("charts").join(format!("{stem}.{ext}"));
            assert!(written.contains(&p), "{written:?}");
            assert!(std::fs::metadata(&p).unwrap().len() > 1000);
        }
    }
    // Drops to failure: a log scale with decades as levels, the whirl cell in it.
    let drops = texts(&dir, "drops_to_failure");
    assert!(has(&drops, "contour lines (decades)"), "{drops:?}");
    assert!(
        has(&drops, "1e10") && has(&drops, "1e11"),
        "decade labels: {drops:?}"
    );
    assert!(
        has(
            &drops,
            "whirl (hatched): the damage of the run up to its 5th whirl turn (it stops there)"
        ),
        "the whirl cell's value is said to cover 5 turns: {drops:?}"
    );
    assert!(
        !drops.iter().any(|t| t.contains("not in colour scale")),
        "whirl cells are in the scale"
    );
    // Pressures of 1.4 to 2.2 GPa: the static limit is not reached, and the legend says so.
    let pressure = texts(&dir, "contact_pressure");
    assert!(
        has(
            &pressure,
            "static limit 4.2 GPa (ISO 76): not reached (highest 2.20 GPa)"
        ),
        "the legend gives the margin: {pressure:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_static_limit_is_a_contour_where_the_pressure_crosses_it() {
    // 3.3, 4.5 and 5.7 GPa at 4000, 8000 and 12000 r/min: the 4.2 GPa line crosses every
    // friction row between the first two speeds, three quarters of the way to 8000 r/min.
    let dir = folder("bearing-limit", true, |speed, _| {
        3.0 + 0.3 * speed / 1000.0 - 0.9
    });
    render_all(&dir).unwrap();
    let pressure = texts(&dir, "contact_pressure");
    assert!(
        has(&pressure, "static limit 4.2 GPa (ISO 76)"),
        "{pressure:?}"
    );
    assert!(!pressure.iter().any(|t| t.contains("not reached")));
    // Dashed in the limit colour inside the map, running from the lowest friction row to
    // the highest at one speed (a vertical line, x constant).
    let lines = limit_lines_in_map(&dir, "contact_pressure");
    assert!(lines.len() >= 4, "{} dashes in the map", lines.len());
    let xs: Vec<f64> = lines.iter().flatten().map(|p| p.0).collect();
    let (x_lo, x_hi) = xs
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &x| (a.0.min(x), a.1.max(x)));
    assert!(
        x_hi - x_lo <= 1.0,
        "the line is vertical: x from {x_lo} to {x_hi}"
    );
    let ys: Vec<f64> = lines.iter().flatten().map(|p| p.1).collect();
    let (y_lo, y_hi) = ys
        .iter()
        .fold((f64::MAX, f64::MIN), |a, &y| (a.0.min(y), a.1.max(y)));
    assert!(
        y_hi - y_lo > 200.0,
        "it spans the friction rows: y from {y_lo} to {y_hi}"
    );
    // Without a crossing no dash is in the map.
    let low = folder("bearing-limit-low", true, |speed, _| 1.0 + speed / 10000.0);
    render_all(&low).unwrap();
    assert!(limit_lines_in_map(&low, "contact_pressure").is_empty());
    let _ = std::fs::remove_dir_all(&low);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_scene_limit_other_than_iso_76_is_the_one_drawn() {
    // Records judged against 2 GPa: the line runs where the pressure crosses 2 GPa, and the
    // legend gives the scene's limit, not ISO 76's.
    let dir = folder_with_limit(
        "bearing-own-limit",
        true,
        |speed, _| 1.0 + speed / 10000.0,
        2.0,
    );
    render_all(&dir).unwrap();
    let pressure = texts(&dir, "contact_pressure");
    assert!(
        has(&pressure, "static limit 2 GPa (from the scene)"),
        "{pressure:?}"
    );
    assert!(!pressure.iter().any(|t| t.contains("4.2")), "{pressure:?}");
    // 1 + speed / 10 000 crosses 2 GPa at 10 000 r/min: a line in the map.
    assert!(!limit_lines_in_map(&dir, "contact_pressure").is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_drop_without_damage_has_an_infinite_life() {
    // The records' null drops to failure beside a pressure: a loaded drop that did no
    // damage (the core's infinite life, which JSON cannot hold).
    let dir = folder("bearing-no-damage", true, |speed, _| 1.0 + speed / 10000.0);
    let path = dir.join("points.jsonl");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    lines[0]["record"]["damage_per_drop"] = json!(0.0);
    lines[0]["record"]["drops_to_failure"] = serde_json::Value::Null;
    let out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    std::fs::write(&path, out.join("\n")).unwrap();
    let rows = load_points(&dir).unwrap();
    assert_eq!(rows[0].drops_to_failure, None);
    render_all(&dir).unwrap();
    let drops = texts(&dir, "drops_to_failure");
    assert!(
        has(
            &drops,
            "no damage: infinite life (drawn at the top of the scale)"
        ),
        "{drops:?}"
    );
    assert!(!has(&drops, "no data"), "{drops:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn records_without_the_analysis_get_no_bearing_charts() {
    let dir = folder("bearing-none", false, |_, _| 0.0);
    let written = render_all(&dir).unwrap();
    assert!(!written.is_empty());
    for p in &written {
        let name = p.file_name().unwrap().to_string_lossy();
        assert!(!name.starts_with("drops_to_failure") && !name.starts_with("contact_pressure"));
    }
    let rows = load_points(&dir).unwrap();
    assert!(rows.iter().all(|r| r.drops_to_failure.is_none()));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Drops to failure spanning less than two decades: the contour levels are round values, not
/// decades, and the legend does not call them decades.
#[test]
fn contours_on_a_log_scale_short_of_two_decades_are_not_called_decades() {
    let dir = folder("bearing-short-span", true, |speed, _| 1.0 + speed / 10000.0);
    let points = dir.join("points.jsonl");
    let text = std::fs::read_to_string(&points).unwrap();
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
            let drops = 1e10 * (1.0 + 0.1 * i as f64);
            v["record"]["drops_to_failure"] = json!(drops);
            v["record"]["damage_per_drop"] = json!(1.0 / drops);
            v.to_string()
        })
        .collect();
    std::fs::write(&points, lines.join("\n")).unwrap();
    render_all(&dir).unwrap();
    let drops = texts(&dir, "drops_to_failure");
    assert!(!has(&drops, "contour lines (decades)"), "{drops:?}");
    assert!(has(&drops, "contour lines"), "{drops:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
