//! End-to-end tests of `whirlmap compare`: exit 0 for the same result, 1 for changes beyond
//! the thresholds (classes, forces and power, critical speeds), 2 for errors; the Markdown
//! report and its class map.

mod common;
use common::*;

use std::path::{Path, PathBuf};
use std::process::Command;

fn sweep(spec: &str, dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, spec).unwrap();
    let res = dir.join(name);
    let o = whirlmap(&["sweep", s(&path), "--out", s(&res), "--no-progress"]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    res
}

const SPEC: &str = r#"{"name": "cmp", "duration_s": 0.05,
  "axes": {"speed_rpm": [4000, 8000], "mu": [0.1, 0.3]}}"#;

#[test]
fn compare_exit_codes_thresholds_and_report() {
    let dir = temp_dir("all");
    let base = sweep(SPEC, &dir, "base");
    let again = sweep(SPEC, &dir, "again");

    // Two runs of the same spec: the same (exit 0).
    let report = dir.join("same.md");
    let o = whirlmap(&["compare", s(&base), s(&again), "--out", s(&report)]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(md.contains("**SAME**: 0 of 4 points"), "{md}");
    assert!(md.contains("No point changed."));
    let png = std::fs::read(dir.join("same-classes.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");

    // A report that would replace a run's own file, or a folder: refused (exit 2) before
    // anything is written, the run's file untouched.
    let points = std::fs::read(base.join("points.jsonl")).unwrap();
    for bad in [
        base.join("points.jsonl"),
        base.join("summary.csv"),
        dir.clone(),
    ] {
        let o = whirlmap(&["compare", s(&base), s(&again), "--out", s(&bad)]);
        assert_eq!(o.status.code(), Some(2), "{}", out(&o));
        assert!(
            stderr(&o).contains("the report would replace"),
            "{}",
            out(&o)
        );
    }
    assert!(std::fs::read(base.join("points.jsonl")).unwrap() == points);
    assert!(!base.join("points-classes.png").exists());
    assert!(!dir
        .parent()
        .unwrap()
        .join(format!(
            "{}-classes.png",
            dir.file_name().unwrap().to_string_lossy()
        ))
        .exists());

    // A tighter solver tolerance moves forces and power by tiny amounts: the same at the
    // default 5 % thresholds, changed at zero thresholds.
    let tight = sweep(
        &SPEC.replace(
            "\"duration_s\"",
            "\"scene\": {\"solver\": {\"rtol\": 1e-8}}, \"duration_s\"",
        ),
        &dir,
        "tight",
    );
    let o = whirlmap(&[
        "compare",
        s(&base),
        s(&tight),
        "--out",
        s(&dir.join("t.md")),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    let o = whirlmap(&[
        "compare",
        s(&base),
        s(&tight),
        "--force-rel",
        "0",
        "--power-rel",
        "0",
        "--out",
        s(&dir.join("t0.md")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    assert!(out(&o).contains("max force"), "{}", out(&o));

    // A class change and a critical speed whose brackets no longer overlap (files edited as
    // a regression would change them): changed (exit 1), both named in the report. Edited
    // files are no run's record, so they go into folders without a manifest (compare warns
    // that it cannot check them); a run's own folder refuses them.
    let new = dir.join("edited");
    std::fs::create_dir_all(&new).unwrap();
    let run_base = base;
    let base = dir.join("edited-base");
    std::fs::create_dir_all(&base).unwrap();
    std::fs::copy(run_base.join("points.jsonl"), base.join("points.jsonl")).unwrap();
    let text = std::fs::read_to_string(again.join("points.jsonl")).unwrap();
    let first = text.lines().next().unwrap();
    let v: serde_json::Value = serde_json::from_str(first).unwrap();
    let class = v["record"]["class"].as_str().unwrap().to_string();
    let other = if class == "bouncing" {
        "pendulum"
    } else {
        "bouncing"
    };
    let edited = first.replace(
        &format!("\"class\":\"{class}\""),
        &format!("\"class\":\"{other}\""),
    );
    assert_ne!(edited, first);
    std::fs::write(new.join("points.jsonl"), text.replacen(first, &edited, 1)).unwrap();
    // Critical-speed rows in the schema of critical.json: the onset bracket [lo, hi] at
    // mu 0.3, and a fixed one at mu 0.4.
    let row = |mu: f64, lo: f64, hi: f64| {
        whirlmap_sweep::critical::SearchResult {
            onset_rpm: Some(hi),
            bracket_rpm: Some([lo, hi]),
            class_below: None,
            class_above: None,
            whirl_intervals_rpm: vec![[hi, 12000.0]],
            whirl_at_range_top: true,
            converged: true,
            undecided: false,
            scan: Vec::new(),
            bisections: Vec::new(),
            note: String::new(),
        }
        .into_row(mu, &Default::default(), String::new())
    };
    let critical = |lo: f64, hi: f64| {
        serde_json::to_string(&[row(0.3, lo, hi), row(0.4, 4000.0, 4100.0)]).unwrap()
    };
    std::fs::write(base.join("critical.json"), critical(4000.0, 4500.0)).unwrap();
    std::fs::write(new.join("critical.json"), critical(4400.0, 4900.0)).unwrap();
    let o = whirlmap(&[
        "compare",
        s(&run_base),
        s(&new),
        "--out",
        s(&dir.join("x.md")),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    std::fs::write(run_base.join("critical.json"), critical(4000.0, 4500.0)).unwrap();
    let o = whirlmap(&[
        "compare",
        s(&run_base),
        s(&new),
        "--out",
        s(&dir.join("x.md")),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "a file the run did not write: {}",
        out(&o)
    );
    assert!(stderr(&o).contains("critical.json"), "{}", stderr(&o));
    let report = dir.join("overlap.md");
    let o = whirlmap(&["compare", s(&base), s(&new), "--out", s(&report)]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    assert!(
        stderr(&o).contains("warning") && stderr(&o).contains("no manifest.json"),
        "{}",
        stderr(&o)
    );
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(
        md.contains("1 of 4 points and 0 of 2 critical speeds"),
        "overlapping brackets are the same: {md}"
    );
    assert!(md.contains(&format!("class {class} -> {other}")), "{md}");
    std::fs::write(new.join("critical.json"), critical(4600.0, 4900.0)).unwrap();
    let report = dir.join("moved.md");
    let o = whirlmap(&["compare", s(&base), s(&new), "--out", s(&report)]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(
        md.contains("**CHANGED**: 1 of 4 points and 1 of 2 critical speeds"),
        "{md}"
    );
    assert!(
        md.contains(
            "| 0.3 | 4000-4500 r/min | 4600-4900 r/min | onset moved up (brackets do not overlap) |"
        ),
        "{md}"
    );
    assert!(md.contains("![class map, changed cells outlined](moved-classes.png)"));
    assert!(dir.join("moved-classes.png").is_file());

    // Errors (exit 2): a folder without results, a negative threshold.
    let o = whirlmap(&["compare", s(&dir.join("nothing")), s(&new)]);
    assert_eq!(o.status.code(), Some(2), "{}", out(&o));
    assert!(
        out(&o).contains("nothing") && out(&o).contains("points.jsonl"),
        "{}",
        out(&o)
    );
    let o = whirlmap(&["compare", s(&base), s(&new), "--force-rel", "-0.1"]);
    assert_eq!(o.status.code(), Some(2), "{}", out(&o));
    assert!(out(&o).contains("--force-rel"), "{}", out(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The nightly example end to end: `scripts/nightly.sh` runs `sweeps/nightly.json` and finds
/// it the same as the committed `results/nightly-baseline/` (exit 0), with its report.
#[test]
fn nightly_script_reproduces_the_committed_baseline() {
    let dir = temp_dir("nightly");
    let run = dir.join("run");
    let o = Command::new("bash")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/nightly.sh"))
        .arg(&run)
        .env("WHIRLMAP", BIN)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    assert!(out(&o).contains("nightly: the same as results/nightly-baseline"));
    let md = std::fs::read_to_string(run.join("compare.md")).unwrap();
    assert!(
        md.contains("**SAME**: 0 of 20 points and 0 of 3 critical speeds"),
        "{md}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Grids that overlap in part: the points in one run only are counted apart from the points
/// compared (the summary said "4 of 2 points changed" before).
#[test]
fn points_in_one_run_only_are_counted_apart_from_those_compared() {
    let dir = temp_dir("overlap-grids");
    let base = sweep(SPEC, &dir, "base");
    let other = SPEC.replace("[4000, 8000]", "[4000, 6000]");
    let new = sweep(&other, &dir, "new");
    let report = dir.join("partial.md");
    let o = whirlmap(&["compare", s(&base), s(&new), "--out", s(&report)]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    assert!(
        out(&o).contains(
            "compare: CHANGED: 0 of 2 points and 0 of 0 critical speeds changed; \
             in one run only: 4 points, 0 critical speeds"
        ),
        "{}",
        out(&o)
    );
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(
        md.contains(
            "**CHANGED**: 0 of 2 points and 0 of 0 critical speeds changed beyond the \
             thresholds; in one run only: 4 points, 0 critical speeds"
        ),
        "{md}"
    );
    // A point simulated for another duration is in neither count: it is said apart.
    let edited = dir.join("edited");
    std::fs::create_dir_all(&edited).unwrap();
    let text = std::fs::read_to_string(base.join("points.jsonl")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let mut v: serde_json::Value = serde_json::from_str(&lines[0]).unwrap();
    v["duration_s"] = serde_json::json!(0.1);
    lines[0] = v.to_string();
    std::fs::write(edited.join("points.jsonl"), lines.join("\n") + "\n").unwrap();
    let o = whirlmap(&[
        "compare",
        s(&base),
        s(&edited),
        "--out",
        s(&dir.join("d.md")),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    assert!(
        out(&o).contains(
            "compare: same: 0 of 3 points and 0 of 0 critical speeds changed; \
             not comparable: 1 point"
        ),
        "{}",
        out(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
