//! The peak-temperature chart of a sweep appears when, and only because, the records carry
//! the thermal model's temperatures.

use serde_json::json;
use whirlmap_plot::{load_points, render_all};

#[test]
fn peak_temperature_chart_is_drawn_from_records_with_temperatures() {
    let dir = std::env::temp_dir().join(format!("whirlmap-thermal-charts-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut lines = Vec::new();
    let mut index = 0;
    for mu in [0.05, 0.1, 0.2] {
        for speed in [4000.0, 8000.0, 12000.0] {
            let hot = 293.15 + speed * mu * 1e-3;
            let node = |t: f64| json!({"final": t - 0.5, "peak": t});
            let rec = json!({"class": "pendulum", "max_contact_force_n": 880.0,
                "peak_heat_power_w": 100.0, "whirl_frequency_hz": 0.0,
                "temperatures_k": {"rotor": node(293.2), "inner_race": node(hot - 1.0),
                    "inner_lubricant": node(hot - 0.5), "balls": node(hot),
                    "outer_lubricant": node(294.0), "outer_race": node(293.9),
                    "housing": node(293.3)},
                "thermal_load_n": 1.0});
            lines.push(
                json!({"key": format!("p{index}"), "index": index,
                       "inputs": {"speed_rpm": speed, "mu": mu}, "status": "ok", "record": rec})
                .to_string(),
            );
            index += 1;
        }
    }
    std::fs::write(dir.join("points.jsonl"), lines.join("\n")).unwrap();
    let rows = load_points(&dir).unwrap();
    let last = rows.last().unwrap();
    assert_eq!(last.peak_temperature_k, Some(293.15 + 12000.0 * 0.2 * 1e-3));
    let written = render_all(&dir).unwrap();
    for ext in ["png", "svg"] {
        let p = dir.join("charts").join(format!("peak_temperature.{ext}"));
        assert!(written.contains(&p), "{written:?}");
        assert!(std::fs::metadata(&p).unwrap().len() > 1000);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
