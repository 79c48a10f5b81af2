//! The bearing-survival analysis end to end through the `whirlmap` binary: a drop's record
//! gains the five fields with `--bearing` and only then, and a sweep whose scene turns the
//! analysis on writes them to `summary.csv` and draws the drops-to-failure and
//! contact-pressure charts, whirl cells included, and its `bearing.md` report (the same from
//! merged shards).

mod common;
use common::*;

const FIELDS: [&str; 5] = [
    "peak_ball_load_n",
    "peak_contact_pressure_pa",
    "static_safety_factor",
    "damage_per_drop",
    "drops_to_failure",
];

fn record(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["drop", "--duration-s", "0.05", "--json"];
    args.extend_from_slice(extra);
    let out = whirlmap(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

#[test]
fn the_record_has_the_bearing_fields_only_with_the_analysis() {
    let off = record(&[]);
    for key in FIELDS {
        assert!(off.get(key).is_none(), "{key} present without the analysis");
    }
    let on = record(&["--bearing"]);
    for key in FIELDS {
        let v = on[key].as_f64().unwrap_or(f64::NAN);
        assert!(v.is_finite() && v > 0.0, "{key}: {}", on[key]);
    }
    // The safety factor is the static limit over the peak pressure, and drops to failure
    // the inverse of the damage.
    let p = on["peak_contact_pressure_pa"].as_f64().unwrap();
    let sf = on["static_safety_factor"].as_f64().unwrap();
    assert!((sf * p / 4.2e9 - 1.0).abs() < 1e-12, "{sf} {p}");
    let d = on["damage_per_drop"].as_f64().unwrap();
    let n = on["drops_to_failure"].as_f64().unwrap();
    assert!((n * d - 1.0).abs() < 1e-12, "{n} {d}");
}

fn sweep(name: &str, scene: &str) -> std::path::PathBuf {
    sweep_drawing(
        name,
        scene,
        r#"["drops_to_failure", "contact_pressure", "classes"]"#,
    )
}

/// [`sweep`] drawing `charts` (a JSON list).
fn sweep_drawing(name: &str, scene: &str, charts: &str) -> std::path::PathBuf {
    let dir = temp_dir(name);
    // 2000 r/min at mu 0.1 settles as a pendulum; 16 000 r/min at mu 0.4 whirls.
    let spec = spec_file(
        &dir,
        "spec",
        &format!(
            r#"{{"name": "{name}", "scene": {scene}, "duration_s": 0.3,
                "axes": {{"speed_rpm": {{"from": 2000, "to": 16000, "steps": 2}},
                          "mu": {{"from": 0.1, "to": 0.4, "steps": 2}}}},
                "charts": {charts}}}"#
        ),
    );
    let out_dir = dir.join("out");
    let out = whirlmap(&["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"]);
    assert!(out.status.success(), "{}", stderr(&out));
    out_dir
}

#[test]
fn a_life_sweep_writes_the_bearing_columns_and_charts() {
    let out_dir = sweep("life-sweep", r#"{"bearing": {}}"#);
    let summary = std::fs::read_to_string(out_dir.join("summary.csv")).unwrap();
    let mut lines = summary.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let records: Vec<serde_json::Value> = std::fs::read_to_string(out_dir.join("points.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let mut classes = Vec::new();
    for (line, point) in lines.zip(&records) {
        let cells: Vec<&str> = line.split(',').collect();
        for key in FIELDS {
            let csv: f64 = cells[col(key)].parse().expect(key);
            assert_eq!(csv, point["record"][key].as_f64().unwrap(), "{key}");
        }
        classes.push(cells[col("class")].to_string());
    }
    assert_eq!(records.len(), 4);
    assert!(classes.iter().any(|c| c == "backward_whirl"), "{classes:?}");
    assert!(classes.iter().any(|c| c == "pendulum"), "{classes:?}");
    for stem in ["drops_to_failure", "contact_pressure", "classes"] {
        let png = out_dir.join("charts").join(format!("{stem}.png"));
        assert!(png.exists(), "{png:?}");
    }
    // The report: the verdict against the static limit and in fatigue, the whirl caveat.
    let report = std::fs::read_to_string(out_dir.join("bearing.md")).unwrap();
    assert!(
        report.contains(
            "- **Static (brinelling, ISO 76):** no drop reaches the static limit of 4.2 GPa"
        ),
        "{report}"
    );
    assert!(report.contains("- **Fatigue (ISO 281, L10):**"), "{report}");
    assert!(
        report.contains("- **Whirl:** 1 of 4 drops end in whirl"),
        "{report}"
    );
    assert!(report.contains("## Assumptions"), "{report}");
    // The manifest lists it.
    let manifest = std::fs::read_to_string(out_dir.join("manifest.json")).unwrap();
    assert!(manifest.contains("\"bearing.md\""), "{manifest}");
    // Whirl cells are in the charts' scales, described, not left out.
    let svg = std::fs::read_to_string(out_dir.join("charts/drops_to_failure.svg")).unwrap();
    assert!(svg.contains("whirl (hatched): the damage of the run up to its 5th whirl turn"));
    assert!(!svg.contains("not in colour scale"));
}

#[test]
fn merged_shards_write_the_same_bearing_report() {
    let whole = sweep("life-whole", r#"{"bearing": {}}"#);
    let dir = temp_dir("life-shards");
    let spec = whole.parent().unwrap().join("spec.json");
    let mut shards = Vec::new();
    for i in 0..2 {
        let out = dir.join(format!("shard-{i}"));
        let i = i.to_string();
        let run = whirlmap(&[
            "sweep",
            s(&spec),
            "--shard",
            &i,
            "--shards",
            "2",
            "--out",
            s(&out),
            "--no-progress",
        ]);
        assert!(run.status.success(), "{}", stderr(&run));
        assert!(
            !out.join("bearing.md").exists(),
            "a shard holds part of the grid only"
        );
        shards.push(out);
    }
    let merged = dir.join("merged");
    let run = whirlmap(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(
        std::fs::read(merged.join("bearing.md")).unwrap(),
        std::fs::read(whole.join("bearing.md")).unwrap()
    );
}

#[test]
fn a_sweep_without_the_analysis_keeps_its_columns() {
    let out_dir = sweep_drawing("no-life-sweep", "{}", r#"["classes"]"#);
    let summary = std::fs::read_to_string(out_dir.join("summary.csv")).unwrap();
    let header = summary.lines().next().unwrap();
    for key in FIELDS {
        assert!(!header.contains(key), "{header}");
    }
    assert!(out_dir.join("charts/classes.png").exists());
    assert!(!out_dir.join("bearing.md").exists());
    // The bearing charts need the analysis's results: asking for them without it is refused
    // before any drop (it drew the class map alone, in silence).
    let dir = temp_dir("no-life-charts");
    let spec = spec_file(
        &dir,
        "spec",
        r#"{"name": "x", "duration_s": 0.05, "axes": {"speed_rpm": [2000], "mu": [0.1]},
            "charts": ["drops_to_failure", "classes"]}"#,
    );
    let out = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&dir.join("out")),
        "--no-progress",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("charts = drops_to_failure: allowed a chart of the bearing model"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("out/points.jsonl").exists());
}

/// A drop that must be refused as bad input: exit 2, and the message on stderr.
fn refused(extra: &[&str]) -> String {
    let mut args = vec!["drop", "--duration-s", "0.05"];
    args.extend_from_slice(extra);
    let out = whirlmap(&args);
    assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
    stderr(&out)
}

#[test]
fn bad_bearing_fields_are_named_by_their_dotted_key_with_value_and_range() {
    let e = refused(&["--set", "bearing={}", "--set", "bearing.rows=0"]);
    assert!(
        e.contains("invalid bearing.rows = 0: allowed [1, 8]"),
        "{e}"
    );
    let e = refused(&[
        "--set",
        "bearing={}",
        "--set",
        "bearing.pitch_diameter_m=0.001",
    ]);
    assert!(
        e.contains("bearing.pitch_diameter_m = 0.001")
            && e.contains("bearing.ball_diameter_m = 0.0055"),
        "{e}"
    );
    // Balls that cannot fit on the pitch circle.
    let e = refused(&[
        "--set",
        "bearing={}",
        "--set",
        "bearing.ball_diameter_m=0.05",
    ]);
    assert!(e.contains("must fit on the pitch circle"), "{e}");
    let e = refused(&[
        "--bearing",
        "--set",
        "bearing.balls_per_row=200",
        "--set",
        "bearing.ball_diameter_m=0.01",
    ]);
    assert!(e.contains("must fit on the pitch circle"), "{e}");
    // A rating that would make the damage infinite.
    let e = refused(&[
        "--set",
        "bearing={}",
        "--set",
        "bearing.dynamic_rating_n=1e-300",
    ]);
    assert!(
        e.contains("invalid bearing.dynamic_rating_n = 1e-300: allowed [1, 1e8] N"),
        "{e}"
    );
}

#[test]
fn the_bearing_flag_is_applied_before_set() {
    let three = record(&["--bearing", "--set", "bearing.rows=3"]);
    let two = record(&["--bearing"]);
    assert!(
        three["peak_ball_load_n"].as_f64().unwrap() < two["peak_ball_load_n"].as_f64().unwrap(),
        "three rows share the load: {} vs {}",
        three["peak_ball_load_n"],
        two["peak_ball_load_n"]
    );
    // A scene bearing (the drag's pitch circle) other than the one analysed: refused.
    let e = refused(&[
        "--bearing",
        "--set",
        "rotor_diameter_m=0.08",
        "--set",
        "pitch_diameter_m=0.1",
        "--set",
        "rotor_polar_moi_kg_m2=0.02",
    ]);
    assert!(
        e.contains("bearing.pitch_diameter_m = 0.051") && e.contains("pitch_diameter_m = 0.1 m"),
        "{e}"
    );
    // Three rows take ISO 281's rating for three rows (25 854 N, above the two rows' 19 470):
    // the damage is below that with a catalogue rating of 19 000 N, by (25854/19000)^3.
    let catalogue = record(&[
        "--bearing",
        "--set",
        "bearing.rows=3",
        "--set",
        "bearing.dynamic_rating_n=19000",
    ]);
    let ratio =
        catalogue["damage_per_drop"].as_f64().unwrap() / three["damage_per_drop"].as_f64().unwrap();
    assert!(
        (ratio / (25854.0f64 / 19000.0).powi(3) - 1.0).abs() < 1e-3,
        "damage ratio {ratio}"
    );
    // Without the flag or the section, the hint names the bearing's own flag.
    let e = refused(&["--set", "bearing.rows=3"]);
    assert!(
        e.contains("--set bearing={}") && e.contains("--bearing") && !e.contains("--thermal"),
        "{e}"
    );
}
