//! End-to-end test of the design charts on a synthetic results directory.

use std::path::{Path, PathBuf};

use serde_json::json;
use whirlmap_core::classify::OrbitClass;
use whirlmap_core::MODEL_VERSION;
use whirlmap_plot::{load_points, render_all, ChartError};
use whirlmap_results::critical::{CriticalRow, Probe};
use whirlmap_results::point::PointStatus;
use whirlmap_results::read::LoadError;

const SPEEDS: [f64; 6] = [2000.0, 4000.0, 6000.0, 8000.0, 10000.0, 12000.0];
const MUS: [f64; 5] = [0.05, 0.1, 0.15, 0.2, 0.3];

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("whirlmap-charts-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The class of a synthetic point: whirl above a critical speed falling with mu.
fn class_of(speed: f64, mu: f64) -> &'static str {
    if speed > 11000.0 - 30000.0 * mu {
        if mu >= 0.3 && speed >= 12000.0 {
            "forward_whirl"
        } else {
            "backward_whirl"
        }
    } else if mu <= 0.05 {
        "bouncing"
    } else if speed == 2000.0 && mu >= 0.2 {
        "unresolved"
    } else {
        "pendulum"
    }
}

/// Writes a 6 x 5 grid (whirl, one failed point, a torn last line), critical.json and one
/// orbit file into `dir`.
pub fn write_synthetic(dir: &Path, orbits: usize) {
    let mut lines = Vec::new();
    let mut index = 0;
    for &mu in &MUS {
        for &speed in &SPEEDS {
            let inputs = json!({"speed_rpm": speed, "mu": mu});
            let line = if speed == 6000.0 && mu == 0.1 {
                json!({"key": format!("p{index}"), "index": index, "inputs": inputs,
                       "scene_hash": "abc", "duration_s": 1.0, "model_version": 1,
                       "status": "failed",
                       "error": {"kind": "step_size_underflow", "message": "step size underflow"}})
            } else {
                let force = 400.0 + 0.06 * speed + 3000.0 * mu + 1e-6 * speed * speed * mu * 10.0;
                let heat = 50.0 + 0.02 * speed * mu * 10.0 + 200.0 * mu;
                json!({"key": format!("p{index}"), "index": index, "inputs": inputs,
                       "scene_hash": "abc", "duration_s": 1.0, "model_version": 1,
                       "status": "ok",
                       "record": {"class": class_of(speed, mu),
                                  "first_contact_force_n": force * 0.8,
                                  "max_contact_force_n": force,
                                  "peak_friction_power_w": heat * 0.9,
                                  "peak_heat_power_w": heat,
                                  "whirl_frequency_hz": 0.0}})
            };
            lines.push(line.to_string());
            index += 1;
        }
    }
    let mut text = lines.join("\n");
    text.push_str("\n{\"key\": \"p99\", \"index\": 99, \"inputs\": {\"speed_r");
    std::fs::write(dir.join("points.jsonl"), text).unwrap();

    let critical: Vec<CriticalRow> = MUS.iter().map(|&mu| critical_row(mu)).collect();
    std::fs::write(
        dir.join("critical.json"),
        serde_json::to_string_pretty(&critical).unwrap(),
    )
    .unwrap();

    let odir = dir.join("orbits");
    std::fs::create_dir_all(&odir).unwrap();
    let c = 2e-4;
    for k in 0..orbits {
        let mu = MUS[k % MUS.len()];
        let whirl = k % 2 == 1;
        let samples: Vec<_> = (0..2000)
            .map(|i| {
                let t = i as f64 * 1e-4;
                let (x, y) = if whirl {
                    let r = c * (1.0 - (-t * 20.0).exp()) * 0.98;
                    let a = -std::f64::consts::FRAC_PI_2 - t * 60.0;
                    (r * a.cos(), r * a.sin())
                } else {
                    let a =
                        -std::f64::consts::FRAC_PI_2 + 0.4 * (t * 40.0).sin() * (-t * 3.0).exp();
                    let r = c * (1.0 - (-t * 40.0).exp());
                    (r * a.cos(), r * a.sin())
                };
                json!({"t_s": t, "x_rel_m": x, "y_rel_m": y, "contact_force_n": 100.0})
            })
            .collect();
        let class = if whirl { "backward_whirl" } else { "pendulum" };
        let file = json!({"speed_rpm": 8000.0, "mu": mu, "class": class,
                          "orbit": {"clearance_m": c, "samples": samples}});
        std::fs::write(odir.join(format!("orbit_{k}.json")), file.to_string()).unwrap();
    }
}

/// A synthetic critical-speed row: no whirl at mu 0.05, two whirl intervals at mu 0.2, one
/// to the range top otherwise.
fn critical_row(mu: f64) -> CriticalRow {
    let crit = 11000.0 - 30000.0 * mu;
    let (onset, intervals, top) = if mu == 0.05 {
        (None, vec![], false)
    } else if mu == 0.2 {
        (Some(crit), vec![[crit, 7000.0], [9000.0, 12000.0]], true)
    } else {
        (Some(crit), vec![[crit, 12000.0]], true)
    };
    CriticalRow {
        mu,
        onset_rpm: onset,
        bracket_rpm: onset.map(|c| [c - 20.0, c]),
        class_below: onset.map(|_| OrbitClass::Pendulum),
        class_above: onset.map(|_| OrbitClass::BackwardWhirl),
        non_monotone: intervals.len() > 1,
        whirl_intervals_rpm: intervals,
        whirl_at_range_top: top,
        drops: 1,
        failed_drops: 0,
        converged: true,
        undecided: false,
        from_rpm: 1000.0,
        to_rpm: 12000.0,
        resolution_rpm: 250.0,
        tol_rpm: 25.0,
        duration_s: 1.0,
        scene_hash: "abc".into(),
        model_version: MODEL_VERSION,
        note: String::new(),
        scan: vec![Probe {
            speed_rpm: 1000.0,
            class: Some(OrbitClass::Pendulum),
            error: None,
        }],
        bisections: vec![],
        recheck: None,
    }
}

#[test]
fn torn_last_line_is_skipped() {
    let dir = temp_dir("load");
    write_synthetic(&dir, 0);
    let rows = load_points(&dir).unwrap();
    assert_eq!(rows.len(), 30);
    assert_eq!(
        rows.iter()
            .filter(|r| r.status == PointStatus::Failed)
            .count(),
        1
    );
    // A torn line in the middle is an error.
    let text = std::fs::read_to_string(dir.join("points.jsonl")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.swap(3, 30);
    std::fs::write(dir.join("points.jsonl"), lines.join("\n")).unwrap();
    assert!(matches!(
        load_points(&dir),
        Err(ChartError::Load(LoadError::Parse { line: 4, .. }))
    ));
    let missing = temp_dir("missing");
    assert!(matches!(
        load_points(&missing),
        Err(ChartError::Load(LoadError::NoPoints { .. }))
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&missing);
}

#[test]
fn render_all_writes_every_chart_as_png_and_svg() {
    let dir = temp_dir("render");
    write_synthetic(&dir, 1);
    let written = render_all(&dir).unwrap();
    let stems = [
        (
            "fig5_max_force",
            vec![
                "release speed (r/min)",
                "friction coefficient",
                "max contact force (N)",
                "backward whirl (not in colour scale)",
                // MUS step 0.05, then 0.1: the drops are marked.
                "drop (uneven grid)",
            ],
        ),
        (
            "fig6_peak_power",
            vec![
                "release speed (r/min)",
                "friction coefficient",
                "peak heat power (W)",
            ],
        ),
        (
            "classes",
            vec![
                "release speed (r/min)",
                "friction coefficient",
                "pendulum vibration",
                "failed",
            ],
        ),
        (
            "fig4_critical",
            vec![
                "friction coefficient",
                "release speed (r/min)",
                "onset of sustained whirl",
                "whirl interval",
                "whirl to the range top",
                "no whirl in range",
            ],
        ),
        (
            "fig3_orbits",
            vec!["x (µm)", "y (µm)", "pendulum vibration", "clearance circle"],
        ),
    ];
    assert_eq!(written.len(), stems.len() * 2, "{written:?}");
    for (stem, labels) in &stems {
        let png = dir.join("charts").join(format!("{stem}.png"));
        let svg = dir.join("charts").join(format!("{stem}.svg"));
        assert!(written.contains(&png) && written.contains(&svg), "{stem}");
        let bytes = std::fs::read(&png).unwrap();
        assert!(bytes.len() > 1000, "{stem}.png is {} bytes", bytes.len());
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{stem}.png signature");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<svg"), "{stem}.svg");
        assert!(text.trim_end().ends_with("</svg>"), "{stem}.svg");
        for label in labels {
            assert!(text.contains(label), "{stem}.svg lacks {label:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn optional_charts_are_skipped_without_their_data() {
    let dir = temp_dir("optional");
    write_synthetic(&dir, 0);
    std::fs::remove_file(dir.join("critical.json")).unwrap();
    let written = render_all(&dir).unwrap();
    let names: Vec<String> = written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 6, "{names:?}");
    assert!(!names
        .iter()
        .any(|n| n.starts_with("fig4") || n.starts_with("fig3")));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes a fuller demo (four orbit panels) to `$WHIRLMAP_CHART_DEMO` for viewing by eye.
#[test]
fn demo_charts_for_viewing() {
    let Some(dir) = std::env::var_os("WHIRLMAP_CHART_DEMO") else {
        return;
    };
    let dir = PathBuf::from(dir);
    std::fs::create_dir_all(&dir).unwrap();
    write_synthetic(&dir, 4);
    for p in render_all(&dir).unwrap() {
        println!("{}", p.display());
    }
}

#[test]
fn extreme_values_neither_panic_nor_hang() {
    let dir = temp_dir("extreme");
    let lines = [
        r#"{"key":"a","index":0,"inputs":{"speed_rpm":1000,"mu":0.1},"status":"ok","record":{"class":"pendulum","max_contact_force_n":1.7e308,"peak_heat_power_w":null}}"#,
        r#"{"key":"b","index":1,"inputs":{"speed_rpm":2000,"mu":0.1},"status":"ok","record":{"class":"pendulum","max_contact_force_n":500.0,"peak_heat_power_w":1.0}}"#,
        r#"{"key":"c","index":2,"inputs":{"speed_rpm":1000,"mu":0.2},"status":"ok","record":{"class":"pendulum","max_contact_force_n":500.0000000000001,"peak_heat_power_w":1.0}}"#,
        r#"{"key":"d","index":3,"inputs":{"speed_rpm":2000,"mu":0.2},"status":"ok","record":{"class":"bouncing","max_contact_force_n":-1.7e308,"peak_heat_power_w":1.0}}"#,
    ];
    std::fs::write(dir.join("points.jsonl"), lines.join("\n")).unwrap();
    // Extreme speeds in every field the chart reads.
    let mut a = critical_row(0.1);
    a.onset_rpm = Some(1.7e308);
    a.bracket_rpm = Some([1.7e308, -1.7e308]);
    a.whirl_intervals_rpm = vec![[-1.7e308, 1.7e308]];
    a.to_rpm = 1.7e308;
    let mut b = critical_row(0.05);
    b.to_rpm = f64::MAX;
    std::fs::write(
        dir.join("critical.json"),
        serde_json::to_string(&[a, b]).unwrap(),
    )
    .unwrap();
    let odir = dir.join("orbits");
    std::fs::create_dir_all(&odir).unwrap();
    let orbit = r#"{"speed_rpm":1.7e308,"mu":0.1,"class":"pendulum","orbit":{"clearance_m":2e-4,"samples":[
        {"t_s":0.0,"x_rel_m":0.0,"y_rel_m":0.0,"contact_force_n":0.0},
        {"t_s":0.1,"x_rel_m":1.7e308,"y_rel_m":-1.7e308,"contact_force_n":1.7e308},
        {"t_s":0.2,"x_rel_m":1e-5,"y_rel_m":1e-5,"contact_force_n":1.0}]}}"#;
    std::fs::write(odir.join("huge.json"), orbit).unwrap();
    assert_eq!(render_all(&dir).unwrap().len(), 10);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A field with two separate humps: every contour level crosses the map as two closed lines,
/// and each line carries the level's label (the second one had none when a level was labelled
/// once); the labels placed do not cover each other.
#[test]
fn each_separate_piece_of_a_contour_level_is_labelled() {
    let dir = temp_dir("two-humps");
    let (speeds, mus): (Vec<f64>, Vec<f64>) = (
        (0..12).map(|i| 2000.0 + 2000.0 * i as f64).collect(),
        (0..10).map(|j| 0.05 + 0.05 * j as f64).collect(),
    );
    let hump = |i: f64, j: f64, ci: f64, cj: f64| {
        1000.0 * (-((i - ci).powi(2) + (j - cj).powi(2)) / 3.0).exp()
    };
    let mut lines = Vec::new();
    for (j, &mu) in mus.iter().enumerate() {
        for (i, &speed) in speeds.iter().enumerate() {
            let (fi, fj) = (i as f64, j as f64);
            let force = 900.0 + hump(fi, fj, 2.5, 2.5) + hump(fi, fj, 8.5, 6.5);
            lines.push(
                json!({"key": format!("p{}", lines.len()), "index": lines.len(),
                       "inputs": {"speed_rpm": speed, "mu": mu}, "scene_hash": "abc",
                       "duration_s": 1.0, "model_version": 1, "status": "ok",
                       "record": {"class": "pendulum", "first_contact_force_n": force,
                                  "max_contact_force_n": force,
                                  "peak_friction_power_w": 100.0, "peak_heat_power_w": 100.0,
                                  "whirl_frequency_hz": 0.0}})
                .to_string(),
            );
        }
    }
    std::fs::write(dir.join("points.jsonl"), lines.join("\n") + "\n").unwrap();
    render_all(&dir).unwrap();
    let svg = std::fs::read_to_string(dir.join("charts/fig5_max_force.svg")).unwrap();
    let texts: Vec<&str> = svg
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with('<'))
        .collect();
    // The contour labels are the texts that are levels and appear more than once (the colour
    // bar's ticks appear once).
    let count = |t: &str| texts.iter().filter(|x| **x == t).count();
    let labelled: Vec<&str> = ["1200", "1400", "1600"]
        .into_iter()
        .filter(|t| count(t) >= 1)
        .collect();
    assert!(!labelled.is_empty(), "{texts:?}");
    for t in labelled {
        // The colour bar's tick, and one label on each hump's line.
        assert_eq!(count(t), 3, "{t}: {texts:?}");
    }
    // An even grid: each drop is at its cell's middle, and nothing marks it.
    assert!(!svg.contains("drop (uneven grid)"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Records of a sweep over clearance and friction (no speed axis): no map is drawn (one was
/// drawn at speed 0, on an invented speed range, with clearance as a slice).
#[test]
fn no_speed_and_friction_map_without_both_axes() {
    let dir = temp_dir("no-speed-axis");
    let mut lines = Vec::new();
    for (index, (c, mu)) in [(1e-4, 0.1), (2e-4, 0.1), (1e-4, 0.3), (2e-4, 0.3)]
        .into_iter()
        .enumerate()
    {
        lines.push(
            json!({"key": format!("p{index}"), "index": index,
                   "inputs": {"clearance_m": c, "mu": mu},
                   "scene_hash": "abc", "duration_s": 1.0, "model_version": 1,
                   "status": "ok",
                   "record": {"class": "pendulum", "first_contact_force_n": 800.0,
                              "max_contact_force_n": 900.0, "peak_friction_power_w": 100.0,
                              "peak_heat_power_w": 110.0, "whirl_frequency_hz": 0.0}})
            .to_string(),
        );
    }
    std::fs::write(dir.join("points.jsonl"), lines.join("\n") + "\n").unwrap();
    let written = render_all(&dir).unwrap();
    assert!(written.is_empty(), "{written:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes `points.jsonl` of one drop per `(speed, mu, class, max force, peak heat power)`, a
/// class of "failed" writing a failed point.
fn write_points(dir: &Path, points: &[(f64, f64, &str, f64, f64)]) {
    let lines: Vec<String> = points
        .iter()
        .enumerate()
        .map(|(index, &(speed, mu, class, force, heat))| {
            let inputs = json!({"speed_rpm": speed, "mu": mu});
            let line = if class == "failed" {
                json!({"key": format!("p{index}"), "index": index, "inputs": inputs,
                       "scene_hash": "abc", "duration_s": 0.3, "model_version": 1,
                       "status": "failed",
                       "error": {"kind": "step_size_underflow", "message": "step size underflow"}})
            } else {
                json!({"key": format!("p{index}"), "index": index, "inputs": inputs,
                       "scene_hash": "abc", "duration_s": 0.3, "model_version": 1,
                       "status": "ok",
                       "record": {"class": class, "first_contact_force_n": 879.0,
                                  "max_contact_force_n": force,
                                  "peak_friction_power_w": heat * 0.9,
                                  "peak_heat_power_w": heat, "whirl_frequency_hz": 0.0}})
            };
            line.to_string()
        })
        .collect();
    std::fs::write(dir.join("points.jsonl"), lines.join("\n") + "\n").unwrap();
}

/// The fill colours of a map's cells in an SVG chart, in the order drawn (friction slowest):
/// the filled rectangles 100 px or more on each side (the colour bar is narrower, the
/// background is the first).
fn cell_fills(svg: &str) -> Vec<[u8; 3]> {
    let attr = |tag: &str, name: &str| -> Option<String> {
        let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
        Some(tag[start..].split('"').next()?.to_string())
    };
    svg.split("<rect")
        .skip(2)
        .filter_map(|tag| {
            let tag = tag.split('>').next()?;
            let size = |name| attr(tag, name)?.parse::<u32>().ok();
            let fill = attr(tag, "fill")?;
            let hex = fill.strip_prefix('#')?;
            let channel = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).ok();
            (size("width")? >= 100 && size("height")? >= 100)
                .then(|| Some([channel(0)?, channel(1)?, channel(2)?]))?
        })
        .collect()
}

/// Two pendulum cells 0.00002 % apart (solver noise, far below the 0.1 % accuracy budget)
/// take alike colours from the middle of the scale: they were drawn one at each end of it, as
/// if they were the map's lowest and highest results, with a colour bar from 880.1318 to
/// 880.1319 N. The whirl cells are outside the scale either way. Nor does a contour line
/// part such cells.
#[test]
fn near_equal_cells_are_drawn_alike() {
    let dir = temp_dir("near-equal");
    write_points(
        &dir,
        &[
            (4000.0, 0.3, "pendulum", 880.13194, 500.0),
            (8000.0, 0.3, "pendulum", 880.13176, 500.0001),
            (4000.0, 0.4, "backward_whirl", 1500.0, 3000.0),
            (8000.0, 0.4, "backward_whirl", 2000.0, 4000.0),
        ],
    );
    render_all(&dir).unwrap();
    for stem in ["fig5_max_force", "fig6_peak_power"] {
        let svg = std::fs::read_to_string(dir.join(format!("charts/{stem}.svg"))).unwrap();
        let fills = cell_fills(&svg);
        assert_eq!(fills.len(), 4, "{stem}: {fills:?}");
        let (a, b) = (fills[0], fills[1]);
        let apart = (0..3).map(|k| a[k].abs_diff(b[k])).max().unwrap();
        assert!(apart <= 2, "{stem}: the pendulum cells are {a:?} and {b:?}");
        // Viridis's middle is teal: green and blue well above red (its ends are dark purple,
        // blue above green, and yellow, blue low).
        assert!(
            a[1] > a[0] + 60 && a[2] > a[0] + 60,
            "{stem}: {a:?} is not the middle"
        );
        assert!(!svg.contains("880.1318"), "{stem}: a bar over the noise");
    }
    let _ = std::fs::remove_dir_all(&dir);

    // Four such cells either side of a round value: no contour line parts them.
    let dir = temp_dir("near-equal-contour");
    let (a, b) = (499.9999, 500.0001);
    write_points(
        &dir,
        &[
            (4000.0, 0.3, "pendulum", 880.0 - 1e-4, a),
            (8000.0, 0.3, "pendulum", 880.0 + 1e-4, b),
            (4000.0, 0.4, "pendulum", 880.0 - 1e-4, a),
            (8000.0, 0.4, "pendulum", 880.0 + 1e-4, b),
        ],
    );
    render_all(&dir).unwrap();
    for stem in ["fig5_max_force", "fig6_peak_power"] {
        let svg = std::fs::read_to_string(dir.join(format!("charts/{stem}.svg"))).unwrap();
        assert!(
            !svg.contains("contour lines"),
            "{stem}: a contour over the noise"
        );
        let fills = cell_fills(&svg);
        assert_eq!(fills.len(), 4, "{stem}: {fills:?}");
        assert!(fills
            .iter()
            .all(|f| f.iter().zip(fills[0]).all(|(x, y)| x.abs_diff(y) <= 2)));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A map without backward-whirl cells does not name them in its legend (it did always, so a
/// sweep whose every drop failed, or whose drops all settled into pendulum vibration, read as
/// if some had whirled); one with them still does.
#[test]
fn the_whirl_legend_entry_names_only_cells_drawn() {
    let entry = "backward whirl (not in colour scale)";
    let grid = |class: [&'static str; 4]| -> Vec<(f64, f64, &'static str, f64, f64)> {
        vec![
            (4000.0, 0.3, class[0], 900.0, 500.0),
            (8000.0, 0.3, class[1], 950.0, 600.0),
            (4000.0, 0.4, class[2], 1000.0, 700.0),
            (8000.0, 0.4, class[3], 1100.0, 800.0),
        ]
    };
    let cases = [
        ("all-failed", grid(["failed"; 4]), false),
        ("all-pendulum", grid(["pendulum"; 4]), false),
        (
            "forward-only",
            grid(["pendulum", "pendulum", "pendulum", "forward_whirl"]),
            false,
        ),
        (
            "one-whirl",
            grid(["pendulum", "pendulum", "pendulum", "backward_whirl"]),
            true,
        ),
    ];
    for (name, points, named) in cases {
        let dir = temp_dir(&format!("whirl-legend-{name}"));
        write_points(&dir, &points);
        render_all(&dir).unwrap();
        for stem in ["fig5_max_force", "fig6_peak_power"] {
            let svg = std::fs::read_to_string(dir.join(format!("charts/{stem}.svg"))).unwrap();
            assert_eq!(svg.contains(entry), named, "{name}: {stem}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
