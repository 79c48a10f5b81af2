//! End-to-end tests of `whirlmap ensemble` and `whirlmap adaptive`: reproducibility (same
//! seed, same bytes; 1 and 2 threads byte-identical), a changed seed changes the draws,
//! bad files exit 2 naming the field, the statistics are consistent with the members, and
//! the adaptive search on a small real grid uses fewer drops and matches the full grid.

mod common;
use common::*;

use std::path::{Path, PathBuf};

fn smoke() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/ensemble-smoke.json")
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

const OUTPUTS: [&str; 4] = ["members.jsonl", "cells.jsonl", "cells.csv", "contours.json"];

#[test]
fn same_seed_same_bytes_for_one_and_two_threads() {
    let dir = temp_dir("repro");
    let (a, b, c) = (dir.join("a"), dir.join("b"), dir.join("c"));
    for (out, threads) in [(&a, "1"), (&b, "2"), (&c, "2")] {
        let o = whirlmap(&[
            "ensemble",
            s(&smoke()),
            "--out",
            s(out),
            "--threads",
            threads,
            "--no-progress",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    for f in OUTPUTS {
        let x = read(&a.join(f));
        assert!(!x.is_empty(), "{f}");
        assert_eq!(x, read(&b.join(f)), "{f}: 1 vs 2 threads");
        assert_eq!(x, read(&c.join(f)), "{f}: a second run");
    }
    assert!(a.join("charts/fig4_probability.png").exists());
    let svg = read(&a.join("charts/fig4_probability.svg"));
    for words in [
        "cell P(whirl)",
        "open where they leave the range",
        "P(whirl) = 50 %",
    ] {
        assert!(svg.contains(words), "the legend lacks {words:?}");
    }

    // The statistics agree with the members: P = whirl / ok, p_lo <= P <= p_hi, and the
    // draws respect the declared bounds.
    let members: Vec<serde_json::Value> = read(&a.join("members.jsonl"))
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(members.len(), 16);
    for m in &members {
        let d = &m["drawn"];
        let e = d["unbalance_m"].as_f64().unwrap();
        assert!((0.0..5e-6).contains(&e), "{d}");
        let r = d["release_offset_m"][0]
            .as_f64()
            .unwrap()
            .hypot(d["release_offset_m"][1].as_f64().unwrap());
        assert!(r <= 2e-5 + 1e-18, "{d}");
        let w = d["race_speed_rad_s"].as_f64().unwrap();
        assert!((0.0..10.0).contains(&w), "{d}");
    }
    for line in read(&a.join("cells.jsonl")).lines() {
        let c: serde_json::Value = serde_json::from_str(line).unwrap();
        let idx = c["index"].as_u64().unwrap();
        let whirl = members
            .iter()
            .filter(|m| m["cell"].as_u64() == Some(idx))
            .filter(|m| {
                matches!(
                    m["class"].as_str(),
                    Some("backward_whirl") | Some("forward_whirl")
                )
            })
            .count();
        assert_eq!(c["whirl"].as_u64().unwrap() as usize, whirl);
        let p = c["p_whirl"].as_f64().unwrap();
        assert_eq!(p, whirl as f64 / c["ok"].as_f64().unwrap());
        assert!(c["p_lo"].as_f64().unwrap() <= p && p <= c["p_hi"].as_f64().unwrap());
        let f = &c["max_contact_force_n"];
        assert!(f["p10"].as_f64() <= f["p50"].as_f64() && f["p50"].as_f64() <= f["p90"].as_f64());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The axes listed in the other order give each cell the same members: the same cells, by
/// their inputs, with the same statistics (only their order in the files differs).
#[test]
fn the_order_of_the_axes_does_not_change_a_cells_members() {
    let dir = temp_dir("axis-order");
    let text = read(&smoke());
    let swapped = text.replace(
        r#""speed_rpm": [4000, 8000],
    "mu": [0.3, 0.4]"#,
        r#""mu": [0.3, 0.4],
    "speed_rpm": [4000, 8000]"#,
    );
    assert_ne!(swapped, text, "the smoke file's axes moved");
    let swapped = spec_file(&dir, "swapped", &swapped);
    let cells = |spec: &Path, out: &Path| {
        let o = whirlmap(&["ensemble", s(spec), "--out", s(out), "--no-progress"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let mut rows: Vec<serde_json::Value> = read(&out.join("cells.jsonl"))
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        for r in &mut rows {
            r.as_object_mut().unwrap().remove("index");
        }
        rows.sort_by_key(|r| r["inputs"].to_string());
        rows
    };
    let a = cells(&smoke(), &dir.join("a"));
    let b = cells(&swapped, &dir.join("b"));
    assert_eq!(a.len(), 4);
    assert_eq!(a, b);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Fig. 4 as probability is over the friction coefficient: with a further axis it is drawn for
/// one slice, named in its title; without a `mu` axis there is none, and the command says so.
#[test]
fn the_probability_chart_is_one_slice_and_needs_a_mu_axis() {
    let dir = temp_dir("ens-slice");
    let spec = |name: &str, scene: &str, axes: &str| {
        let text = format!(
            r#"{{"name": "{name}", "duration_s": 0.05, "scene": {{{scene}}},
                "axes": {{"speed_rpm": [4000, 8000], {axes}}},
                "ensemble": {{"members": 2, "seed": 1,
                  "unbalance_m": {{"uniform": {{"from": 0, "to": 5e-6}}}}}}}}"#
        );
        spec_file(&dir, name, &text)
    };
    let sliced = spec(
        "sliced",
        "",
        r#""mu": [0.3, 0.4], "clearance_m": [1e-4, 1.5e-4]"#,
    );
    let o = whirlmap(&[
        "ensemble",
        s(&sliced),
        "--out",
        s(&dir.join("a")),
        "--no-progress",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out(&o).contains("(2 charts)"), "{}", out(&o));
    let svg = read(&dir.join("a/charts/fig4_probability.svg"));
    assert!(
        svg.contains("slice at clearance_m = 0.0001"),
        "the title names the slice"
    );
    let no_mu = spec(
        "nomu",
        r#""mu_dynamic": 0.4"#,
        r#""clearance_m": [1e-4, 1.5e-4]"#,
    );
    let o = whirlmap(&[
        "ensemble",
        s(&no_mu),
        "--out",
        s(&dir.join("b")),
        "--no-progress",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        out(&o).contains("no chart: Fig. 4 as probability is drawn over the friction"),
        "{}",
        out(&o)
    );
    assert!(!dir.join("b/charts/fig4_probability.png").exists());
    // render says the same, and removes a chart drawn there before as stale.
    std::fs::create_dir_all(dir.join("b/charts")).unwrap();
    std::fs::write(dir.join("b/charts/fig4_probability.png"), "old").unwrap();
    let o = whirlmap(&["render", s(&dir.join("b"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        out(&o).contains("no chart: Fig. 4 as probability"),
        "{}",
        out(&o)
    );
    assert!(!dir.join("b/charts/fig4_probability.png").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn another_seed_draws_other_members() {
    let dir = temp_dir("seed");
    let text = read(&smoke()).replace("\"seed\": 1", "\"seed\": 2");
    assert!(text.contains("\"seed\": 2"));
    let file = dir.join("seed2.json");
    std::fs::write(&file, text).unwrap();
    for (f, out) in [(smoke(), dir.join("a")), (file, dir.join("b"))] {
        let o = whirlmap(&["ensemble", s(&f), "--out", s(&out), "--no-progress"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let a = read(&dir.join("a/members.jsonl"));
    let b = read(&dir.join("b/members.jsonl"));
    let first =
        |t: &str| -> serde_json::Value { serde_json::from_str(t.lines().next().unwrap()).unwrap() };
    assert_ne!(first(&a)["drawn"], first(&b)["drawn"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_ensemble_files_exit_2_and_name_the_field() {
    let dir = temp_dir("bad");
    let base = r#""name": "bad", "duration_s": 0.05, "axes": {"speed_rpm": [4000], "mu": [0.3]}"#;
    let cases: &[(&str, &[&str])] = &[
        (
            r#""ensemble": {"members": 0, "seed": 1}"#,
            &["ensemble.members"],
        ),
        (
            r#""ensemble": {"members": 2, "seed": 1, "unbalance_m": {"uniform": {"from": 2e-6, "to": 1e-6}}}"#,
            &["ensemble.unbalance_m"],
        ),
        (
            r#""ensemble": {"members": 2, "seed": 1, "orbit_radius_m": {"fixed": 1.4e-4}}"#,
            &["release_offset_m", "widest"],
        ),
        (
            r#""ensemble": {"members": 2, "seed": 1, "race_speed": {"fixed": 1}}"#,
            &["race_speed", "line"],
        ),
        (
            r#""ensemble": {"members": 2, "seed": 1, "levels": [1.5]}"#,
            &["ensemble.levels"],
        ),
        (
            r#""ensemble": {"members": 2, "seed": 1, "levels": [0.5, 0.5]}"#,
            &["ensemble.levels = 0.5: allowed each level once"],
        ),
        (
            r#""adaptive": {"seed_speed_points": 2, "seed_mu_points": 2}"#,
            &["axes.speed_rpm = 1 point", "at least 2 points"],
        ),
    ];
    for (i, (section, words)) in cases.iter().enumerate() {
        let f = dir.join(format!("bad{i}.json"));
        std::fs::write(&f, format!("{{{base}, {section}}}")).unwrap();
        let out = dir.join(format!("out{i}"));
        let o = whirlmap(&["ensemble", s(&f), "--out", s(&out)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{section}: {err}");
        for w in *words {
            assert!(err.contains(w), "{section}: `{w}` not in {err}");
        }
        assert!(!out.join("members.jsonl").exists(), "nothing runs");
    }
    // An adaptive search over values out of order: its cells would not be neighbours.
    let f = dir.join("unsorted.json");
    std::fs::write(
        &f,
        r#"{"name": "unsorted", "duration_s": 0.05,
            "axes": {"speed_rpm": [4000, 2000, 6000], "mu": [0.3, 0.4]},
            "adaptive": {"seed_speed_points": 2, "seed_mu_points": 2}}"#,
    )
    .unwrap();
    let out = dir.join("unsorted");
    let o = whirlmap(&["adaptive", s(&f), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("allowed values in ascending order"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("adaptive.json").exists());
    // No speed axis: nothing for the contours to cross along; refused before any drop.
    let f = dir.join("nospeed.json");
    std::fs::write(
        &f,
        r#"{"name": "nospeed", "duration_s": 0.05, "axes": {"mu": [0.3]},
            "ensemble": {"members": 2, "seed": 1}}"#,
    )
    .unwrap();
    let out = dir.join("nospeed");
    let o = whirlmap(&["ensemble", s(&f), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("axes = mu: allowed a speed_rpm axis"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "nothing runs");
    // More drops than a sweep may have grid points: refused at once, nothing built.
    let f = dir.join("huge.json");
    std::fs::write(
        &f,
        r#"{"name": "huge", "duration_s": 0.05,
            "axes": {"speed_rpm": {"from": 1000, "to": 30000, "steps": 1000}, "mu": [0.3, 0.4]},
            "ensemble": {"members": 100000, "seed": 1}}"#,
    )
    .unwrap();
    let o = whirlmap(&["ensemble", s(&f), "--out", s(&dir.join("huge"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("ensemble.members = 100000 members x 2000 cells = 200000000 drops"),
        "{}",
        stderr(&o)
    );
    // No ensemble (or adaptive) section: refused, and no folder made.
    let f = dir.join("none.json");
    std::fs::write(&f, format!("{{{base}}}")).unwrap();
    for what in ["ensemble", "adaptive"] {
        let o = whirlmap(&[what, s(&f), "--out", s(&dir.join("none"))]);
        assert_eq!(o.status.code(), Some(2));
        assert!(
            stderr(&o).contains(&format!("{what} = (missing)")),
            "{}",
            stderr(&o)
        );
        assert!(!dir.join("none").exists());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A small real adaptive search (single 0.1 s drops, 9 x 5 fine grid, 3 x 3 seed): the
/// report's counts are consistent and the boundary agrees with the full grid's to within a
/// fine cell. Too small for the 25 % target (the seed grid alone is 20 % of it; measured 33
/// of 45): that is
/// the synthetic benchmark's job (`crates/sweep/src/adaptive.rs`).
#[test]
fn adaptive_search_on_a_small_real_grid_matches_the_full_grid() {
    let dir = temp_dir("adaptive");
    let f = dir.join("a.json");
    std::fs::write(
        &f,
        r#"{"name": "a", "duration_s": 0.1,
            "axes": {"speed_rpm": {"from": 2000, "to": 18000, "steps": 9},
                     "mu": {"from": 0.3, "to": 0.5, "steps": 5}},
            "adaptive": {"seed_speed_points": 3, "seed_mu_points": 3}}"#,
    )
    .unwrap();
    let out = dir.join("out");
    let o = whirlmap(&[
        "adaptive",
        s(&f),
        "--out",
        s(&out),
        "--compare-full",
        "--no-progress",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_str(&read(&out.join("adaptive.json"))).unwrap();
    println!("{}", String::from_utf8_lossy(&o.stdout));
    assert_eq!(r["full_grid_drops"], 45);
    let used = r["drops_used"].as_u64().unwrap();
    assert_eq!(used as usize, r["evaluated"].as_array().unwrap().len());
    assert!((9..=45).contains(&used), "{used}");
    let crossings = r["boundary"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["speed_rpm"].is_number())
        .count();
    assert!(
        crossings >= 2,
        "the grid holds a whirl boundary: {}",
        r["boundary"]
    );
    let a = &r["comparison"]["agreement"];
    assert!(a["max_shift_cells"].as_f64().unwrap() <= 1.0, "{a}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn compare_full_belongs_to_adaptive_only() {
    let o = whirlmap(&["ensemble", "no-such-file.json", "--compare-full"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--compare-full applies only to `whirlmap adaptive`"),
        "{err}"
    );
    let help = out(&whirlmap(&["adaptive", "--help"]));
    assert!(help.contains("--compare-full"), "{help}");
    let help = out(&whirlmap(&["ensemble", "--help"]));
    assert!(!help.contains("--compare-full"), "{help}");
}

/// 40 one-second drops: long enough on one thread to be killed after a few records.
const KILL_SPEC: &str = r#"{"name": "kill", "duration_s": 1.0,
  "axes": {"speed_rpm": [4000, 8000], "mu": [0.3, 0.4]},
  "ensemble": {"members": 10, "seed": 7,
    "unbalance_m": {"uniform": {"from": 0, "to": 5e-6}},
    "orbit_radius_m": {"normal": {"mean": 5e-6, "sd": 3e-6, "min": 0, "max": 2e-5}}}}"#;

/// Runs `whirlmap ensemble spec --out out` on two threads and kills it once `members.jsonl`
/// holds two records (and before it holds all 40).
fn kill_after_two_members(spec: &Path, out: &Path) {
    let args = [
        "ensemble",
        s(spec),
        "--out",
        s(out),
        "--threads",
        "2",
        "--no-progress",
    ];
    let n = kill_after_lines(&args, &out.join("members.jsonl"), 2);
    assert!(n < 40, "the ensemble finished before it could be killed");
}

#[test]
fn a_killed_ensemble_keeps_its_members_and_resumes_to_the_uninterrupted_files() {
    let dir = temp_dir("ens-kill");
    let spec = spec_file(&dir, "kill.json", KILL_SPEC);
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    kill_after_two_members(&spec, &killed);
    // What the kill left: the members written so far and a manifest saying so.
    let m = read_json(&killed.join("manifest.json"));
    assert_eq!(m["complete"], false, "{m}");
    assert!(!killed.join("cells.jsonl").exists());
    let before = read(&killed.join("members.jsonl"));
    let kept = before.matches('\n').count();
    // A crash in the middle of a write leaves a torn line.
    let mut torn = before[..before.rfind('\n').unwrap() + 1].to_string();
    torn.push_str(r#"{"cell":0,"member":"#);
    std::fs::write(killed.join("members.jsonl"), &torn).unwrap();

    // Without --resume the folder is refused, and the message says how to go on.
    let o = whirlmap(&["ensemble", s(&spec), "--out", s(&killed), "--no-progress"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--resume"), "{}", stderr(&o));
    // --resume and --overwrite exclude each other.
    let o = whirlmap(&[
        "ensemble",
        s(&spec),
        "--out",
        s(&killed),
        "--resume",
        "--overwrite",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // Another spec's members are not continued: the refusal names what differs.
    let other = spec_file(
        &dir,
        "other.json",
        &KILL_SPEC.replace("\"seed\": 7", "\"seed\": 8"),
    );
    let o = whirlmap(&["ensemble", s(&other), "--out", s(&killed), "--resume"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("seed"), "{}", stderr(&o));
    assert_eq!(
        read(&killed.join("members.jsonl")),
        torn,
        "a refusal changes nothing"
    );
    // Nor are members of another model version or build, nor lines out of place.
    let manifest = read(&killed.join("manifest.json"));
    let version = read_json(&killed.join("manifest.json"))["model_version"].clone();
    let edits = [
        (
            format!("\"model_version\": {version}"),
            "\"model_version\": 1".to_string(),
            "model version 1",
        ),
        (
            "\"git_commit\": \"".to_string(),
            "\"git_commit\": \"0000".to_string(),
            "two builds",
        ),
    ];
    for (from, to, says) in edits {
        assert!(manifest.contains(&from), "{from}");
        std::fs::write(killed.join("manifest.json"), manifest.replace(&from, &to)).unwrap();
        let o = whirlmap(&["ensemble", s(&spec), "--out", s(&killed), "--resume"]);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains(says), "{says}: {}", stderr(&o));
    }
    std::fs::write(killed.join("manifest.json"), &manifest).unwrap();
    let mut swapped: Vec<&str> = torn.lines().collect();
    swapped.swap(0, 1);
    std::fs::write(killed.join("members.jsonl"), swapped.join("\n") + "\n").unwrap();
    let o = whirlmap(&["ensemble", s(&spec), "--out", s(&killed), "--resume"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("line 1 of members.jsonl"),
        "{}",
        stderr(&o)
    );
    std::fs::write(killed.join("members.jsonl"), &torn).unwrap();

    let o = whirlmap(&[
        "ensemble",
        s(&spec),
        "--out",
        s(&killed),
        "--threads",
        "2",
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        out(&o).contains(&format!("= 40 drops ({kept} resumed)")),
        "{}",
        out(&o)
    );
    let o = whirlmap(&[
        "ensemble",
        s(&spec),
        "--out",
        s(&full),
        "--threads",
        "2",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for f in OUTPUTS {
        assert_eq!(read(&full.join(f)), read(&killed.join(f)), "{f}");
    }
    let m = read_json(&killed.join("manifest.json"));
    assert_eq!(
        (m["complete"].clone(), m["drops"].clone()),
        (true.into(), 40.into())
    );
    // An --overwrite killed part way keeps the finished run in previous-run/; the --resume
    // that finishes it removes that, as the overwrite would have.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_whirlmap"))
        .args(["ensemble", s(&spec), "--out", s(&killed), "--overwrite"])
        .args(["--threads", "2", "--no-progress"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let lines = || {
        std::fs::read_to_string(killed.join("members.jsonl")).map_or(0, |t| t.matches('\n').count())
    };
    while !(killed.join("previous-run").exists() && (2..40).contains(&lines())) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "it ended before the kill"
        );
        assert!(start.elapsed().as_secs() < 120, "no progress");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(killed.join("previous-run/members.jsonl").exists());
    let o = whirlmap(&["ensemble", s(&spec), "--out", s(&killed), "--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!killed.join("previous-run").exists());
    for f in OUTPUTS {
        assert_eq!(read(&full.join(f)), read(&killed.join(f)), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

const ADAPTIVE_RESUME: &str = r#"{"name": "ar", "duration_s": 0.2,
    "scene": {"solver": {"rtol": 1e-6}},
    "axes": {"speed_rpm": {"from": 2000, "to": 18000, "steps": 17},
             "mu": {"from": 0.2, "to": 0.5, "steps": 9}},
    "adaptive": {"seed_speed_points": 5, "seed_mu_points": 3}}"#;

/// A killed adaptive search keeps the corners it evaluated (`adaptive-corners.jsonl`):
/// `--resume` evaluates only the others and writes the `adaptive.json` of an uninterrupted run,
/// then removes the log; without `--resume` the folder is refused with a hint.
#[test]
fn a_killed_adaptive_search_resumes_to_the_uninterrupted_report() {
    let dir = temp_dir("adaptive-resume");
    let f = dir.join("ar.json");
    std::fs::write(&f, ADAPTIVE_RESUME).unwrap();
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    let run = |out: &Path, extra: &[&str]| {
        let mut a = vec!["adaptive", s(&f), "--out", s(out), "--compare-full"];
        a.extend_from_slice(extra);
        a.push("--no-progress");
        whirlmap(&a)
    };
    let o = run(&full, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!full.join("adaptive-corners.jsonl").exists());
    let log = killed.join("adaptive-corners.jsonl");
    // The header and the seed (15 corners) are in, and at least one more round.
    let args = [
        "adaptive",
        s(&f),
        "--out",
        s(&killed),
        "--compare-full",
        "--threads",
        "1",
        "--no-progress",
    ];
    kill_after_lines(&args, &log, 17);
    assert!(!killed.join("adaptive.json").exists(), "killed mid-search");
    let o = run(&killed, &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--resume continues the adaptive search"),
        "{err}"
    );
    let o = run(&killed, &["--resume"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("corners kept from the killed run"), "{err}");
    assert_eq!(
        read(&killed.join("adaptive.json")),
        read(&full.join("adaptive.json"))
    );
    assert!(!log.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// What a resumed adaptive search takes from a staged log: a logged corner's value is used
/// (a marked value shows up in the report), a torn last line is not, and a log of another
/// spec or build is refused (exit 2).
#[test]
fn a_resumed_adaptive_search_uses_its_logged_corners_and_refuses_another_specs() {
    let dir = temp_dir("adaptive-log");
    let f = dir.join("ar.json");
    std::fs::write(&f, ADAPTIVE_RESUME).unwrap();
    let out = dir.join("out");
    let resume = || {
        whirlmap(&[
            "adaptive",
            s(&f),
            "--out",
            s(&out),
            "--resume",
            "--no-progress",
        ])
    };
    // A first run leaves no log; its header is rebuilt from a fresh, killed one.
    std::fs::create_dir_all(&out).unwrap();
    let args = [
        "adaptive",
        s(&f),
        "--out",
        s(&out),
        "--threads",
        "1",
        "--no-progress",
    ];
    kill_after_lines(&args, &out.join("adaptive-corners.jsonl"), 1);
    let text = read(&out.join("adaptive-corners.jsonl"));
    let header = text.lines().next().unwrap().to_string();
    // Corner (0, 0) is a seed corner; 0.25 is a value no single drop gives.
    let staged = format!(
        "{header}\n{}\n{}",
        r#"{"i":0,"j":0,"p_whirl":0.25}"#, r#"{"i":16,"j":8,"p_whirl":0.75}"#
    );
    std::fs::write(out.join("adaptive-corners.jsonl"), &staged).unwrap();
    let o = resume();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_str(&read(&out.join("adaptive.json"))).unwrap();
    let p_at = |speed: f64, mu: f64| {
        r["evaluated"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["speed_rpm"] == speed && (c["mu"].as_f64().unwrap() - mu).abs() < 1e-12)
            .map(|c| c["p_whirl"].as_f64().unwrap())
    };
    assert_eq!(p_at(2000.0, 0.2), Some(0.25), "the logged corner is used");
    let top = p_at(18000.0, 0.5).expect("a seed corner");
    assert!(top == 0.0 || top == 1.0, "the torn line is not used: {top}");

    // A log of another spec (another duration) is refused, naming why.
    std::fs::remove_file(out.join("adaptive.json")).unwrap();
    let other = header.replace("\"duration_s\":0.2", "\"duration_s\":0.3");
    assert_ne!(other, header);
    std::fs::write(out.join("adaptive-corners.jsonl"), format!("{other}\n")).unwrap();
    let o = resume();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("another spec"), "{err}");
    // So is a log of another build (another commit).
    let commit = header.find("\"git_commit\":\"").expect("a commit") + 14;
    let other = format!("{}x{}", &header[..commit], &header[commit..]);
    std::fs::write(out.join("adaptive-corners.jsonl"), format!("{other}\n")).unwrap();
    let o = resume();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("another build"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
