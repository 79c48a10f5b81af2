//! End-to-end tests of `whirlmap sweep`: spec errors, determinism across thread counts,
//! crash-safe resume (of one thread and of several), and failed points recorded as data.

mod common;
use common::*;

use std::path::{Path, PathBuf};

fn smoke_spec() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/smoke.json")
}

fn lines(path: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).expect("complete JSON lines"))
        .collect()
}

#[test]
fn bad_specs_exit_2_name_the_field_and_run_nothing() {
    let dir = temp_dir("bad");
    let base =
        r#""name": "bad", "duration_s": 0.05, "axes": {"speed_rpm": [4000, 8000], "mu": [0.1]}"#;
    let cases: &[(&str, String, &[&str])] = &[
        ("unknown top-level key", format!("{{{base}, \"colour\": 1}}"), &["colour", "line"]),
        (
            "unknown scene key",
            format!("{{{base}, \"scene\": {{\"clearence_m\": 1e-4}}}}"),
            &["clearence_m", "column"],
        ),
        (
            "type error",
            r#"{"name": "bad", "duration_s": "long", "axes": {"mu": [0.1]}}"#.into(),
            &["line", "column"],
        ),
        (
            "empty axis",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"mu": []}}"#.into(),
            &["axes.mu", "empty"],
        ),
        (
            "a stop speed above the critical search's lowest speed",
            format!(
                "{{{base}, \"scene\": {{\"stop_speed_rpm\": 1500}}, \"critical\": {{\"mu\": [0.3], \"speed_rpm\": {{\"from\": 1000, \"to\": 2000}}}}}}"
            ),
            &["scene.stop_speed_rpm (the critical search at mu 0.3, speed_rpm.from 1000 r/min) = 1500"],
        ),
        (
            "a span beyond the largest number",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"unbalance_m": {"from": -1e308, "to": 1e308, "steps": 3}}}"#.into(),
            &["axes.unbalance_m = from -1e308 to 1e308"],
        ),
        (
            "a probability section's own field",
            format!("{{{base}, \"probability\": {{\"duration_s\": -1, \"axes\": {{\"speed_rpm\": [4000], \"mu\": [0.3]}}, \"ensemble\": {{\"members\": 2, \"seed\": 1}}}}}}"),
            &["probability.duration_s = -1"],
        ),
        (
            "a chart of a model the scene does not run",
            format!("{{{base}, \"charts\": [\"classes\", \"peak_temperature\"]}}"),
            &["charts = peak_temperature: allowed a chart of the thermal model only with `scene.thermal` set"],
        ),
        (
            "zero steps",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"mu": {"from": 0.1, "to": 0.3, "steps": 0}}}"#.into(),
            &["axes.mu.steps = 0"],
        ),
        (
            "from > to",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"speed_rpm": {"from": 9000, "to": 1000, "steps": 3}}}"#.into(),
            &["axes.speed_rpm", "9000"],
        ),
        ("unknown chart", format!("{{{base}, \"charts\": [\"pie\"]}}"), &["charts", "pie"]),
        (
            "a chart named twice",
            format!("{{{base}, \"charts\": [\"classes\", \"max_force\", \"classes\"]}}"),
            &["charts = classes: allowed each chart named once"],
        ),
        (
            "unknown axis",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"clearence_m": [1e-4]}}"#.into(),
            &["axes.clearence_m", "clearance_m"],
        ),
        (
            "mu out of range",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"mu": [0.1, 2.5]}}"#.into(),
            &["axes.mu = 2.5"],
        ),
        (
            "zero duration",
            r#"{"name": "bad", "duration_s": 0, "axes": {"mu": [0.1]}}"#.into(),
            &["duration_s = 0"],
        ),
        (
            "invalid grid point scene",
            r#"{"name": "bad", "duration_s": 0.05, "axes": {"clearance_m": [1e-4, -1e-3]}}"#.into(),
            &["grid point 1", "clearance_m = -0.001"],
        ),
        (
            "a critical re-check without a fidelity preset",
            format!("{{{base}, \"critical\": {{\"mu\": [0.3], \"speed_rpm\": {{\"from\": 1000, \"to\": 2000}}, \"recheck\": true}}}}"),
            &["critical.recheck = true without a fidelity", "draft or standard"],
        ),
        (
            "a critical re-check at the tightest preset",
            format!("{{{base}, \"fidelity\": \"reference\", \"critical\": {{\"mu\": [0.3], \"speed_rpm\": {{\"from\": 1000, \"to\": 2000}}, \"recheck\": true}}}}"),
            &["critical.recheck = true with fidelity reference"],
        ),
        (
            "a grid speed at or below the stop speed",
            r#"{"name": "bad", "duration_s": 0.05, "scene": {"stop_speed_rpm": 5000},
                "axes": {"speed_rpm": [8000, 4000]}}"#
                .into(),
            &["grid point 1", "stop_speed_rpm = 5000", "|speed_rpm| = 4000"],
        ),
    ];
    for (i, (what, text, needles)) in cases.iter().enumerate() {
        let spec = dir.join(format!("case{i}.json"));
        std::fs::write(&spec, text).unwrap();
        let out_dir = dir.join(format!("out{i}"));
        let o = whirlmap(&["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        for n in *needles {
            assert!(err.contains(n), "{what}: `{n}` not in: {err}");
        }
        assert!(
            !out_dir.join("points.jsonl").exists(),
            "{what}: points were written"
        );
    }
    // An output folder that cannot be created (below a regular file).
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out_dir = file.join("out");
    let o = whirlmap(&[
        "sweep",
        s(&smoke_spec()),
        "--out",
        s(&out_dir),
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("output folder"), "{}", stderr(&o));
    // A missing file and a bad thread count.
    let o = whirlmap(&["sweep", s(&dir.join("missing.json"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("missing.json"), "{}", stderr(&o));
    let o = whirlmap(&["sweep", s(&smoke_spec()), "--threads", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn points_are_byte_identical_for_any_thread_count() {
    let dir = temp_dir("threads");
    let (a, b) = (dir.join("t1"), dir.join("t2"));
    // With --overwrite an existing points.jsonl is replaced.
    std::fs::create_dir_all(&a).unwrap();
    std::fs::write(a.join("points.jsonl"), "stale\n").unwrap();
    for (out, threads) in [(&a, "1"), (&b, "2")] {
        let o = whirlmap(&[
            "sweep",
            s(&smoke_spec()),
            "--out",
            s(out),
            "--threads",
            threads,
            "--no-progress",
            "--overwrite",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(
            o.stderr.is_empty(),
            "--no-progress is silent: {}",
            stderr(&o)
        );
        assert!(String::from_utf8_lossy(&o.stdout).contains("4 points"));
    }
    let pa = std::fs::read(a.join("points.jsonl")).unwrap();
    let pb = std::fs::read(b.join("points.jsonl")).unwrap();
    assert!(pa == pb, "points.jsonl differs between 1 and 2 threads");
    let recs = lines(&a.join("points.jsonl"));
    assert_eq!(recs.len(), 4);
    for (i, r) in recs.iter().enumerate() {
        assert_eq!(r["index"], i);
        assert_eq!(r["status"], "ok");
        assert_eq!(r["key"].as_str().unwrap().len(), 16);
        assert!(r["record"]["class"].is_string());
        assert!(r.get("wall_time_s").is_none());
    }
    let keys: Vec<_> = recs[0]["inputs"].as_object().unwrap().keys().collect();
    assert_eq!(keys.len(), 2);
    assert_eq!(
        std::fs::read(a.join("summary.csv")).unwrap(),
        std::fs::read(b.join("summary.csv")).unwrap()
    );
    let summary = std::fs::read_to_string(a.join("summary.csv")).unwrap();
    assert!(
        summary.starts_with("index,speed_rpm,mu,class,"),
        "{summary}"
    );
    assert_eq!(summary.lines().count(), 5);
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(a.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["counts"]["points"], 4);
    assert_eq!(m["counts"]["ok"], 4);
    assert_eq!(m["spec"]["name"], "smoke");
    assert_eq!(lines(&a.join("timings.jsonl")).len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs `whirlmap sweep spec --out out` on `threads` threads and kills it as soon as two
/// records are in `points.jsonl` (and before `grid_size` are); returns that file's path.
fn kill_after_two_lines(spec: &Path, out: &Path, threads: &str, grid_size: usize) -> PathBuf {
    let args = [
        "sweep",
        s(spec),
        "--out",
        s(out),
        "--threads",
        threads,
        "--no-progress",
    ];
    let points = out.join("points.jsonl");
    let n = kill_after_lines(&args, &points, 2);
    assert!(
        n < grid_size,
        "the sweep finished before it could be killed"
    );
    points
}

const RESUME_SPEC: &str = r#"{
  "name": "resume",
  "scene": {"solver": {"rtol": 1e-9}},
  "duration_s": 0.2,
  "axes": {"speed_rpm": [2000, 4000, 6000, 8000], "mu": [0.1, 0.2, 0.3, 0.4]}
}"#;

#[test]
fn a_killed_sweep_resumes_to_the_uninterrupted_file() {
    let dir = temp_dir("resume");
    let spec = dir.join("resume.json");
    std::fs::write(&spec, RESUME_SPEC).unwrap();
    let (full, killed) = (dir.join("full"), dir.join("killed"));

    // Interrupted run: one thread; kill once some but not all lines are in.
    let points = kill_after_two_lines(&spec, &killed, "1", 16);
    let before = std::fs::read_to_string(&points).unwrap();
    let complete = before.matches('\n').count();
    assert!(
        (2..16).contains(&complete),
        "{complete} lines after the kill"
    );
    // A crash in the middle of a write leaves a torn line.
    let mut torn = before.clone();
    if !torn.ends_with('\n') {
        torn.truncate(torn.rfind('\n').unwrap() + 1);
    }
    torn.push_str(r#"{"key":"0123456789abcdef","index":9,"inputs":{"speed_"#);
    std::fs::write(&points, torn).unwrap();

    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&killed),
        "--threads",
        "2",
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&full),
        "--threads",
        "2",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let recs = lines(&points);
    assert_eq!(recs.len(), 16);
    for (i, r) in recs.iter().enumerate() {
        assert_eq!(r["index"], i, "every point exactly once, in grid order");
    }
    assert!(
        std::fs::read(&points).unwrap() == std::fs::read(full.join("points.jsonl")).unwrap(),
        "resumed points.jsonl differs from the uninterrupted run's"
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(killed.join("manifest.json")).unwrap())
            .unwrap();
    let skipped = m["counts"]["skipped"].as_u64().unwrap();
    assert!((2..16).contains(&skipped), "skipped {skipped}");
    assert_eq!(m["counts"]["ok"], 16);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_point_is_recorded_and_the_sweep_goes_on() {
    let dir = temp_dir("failed");
    let spec = dir.join("failing.json");
    std::fs::write(
        &spec,
        r#"{"name": "failing", "duration_s": 0.05,
            "axes": {"solver.max_step_attempts": [10, 20000000], "mu": [0.1, 0.3]}}"#,
    )
    .unwrap();
    let out = dir.join("out");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&out), "--no-progress"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("2 failed"));
    // Standard error says why, by kind, with the first failed point.
    assert!(
        stderr(&o).contains(
            "error: 2 of 4 points failed (step_budget 2); the first, index 0 \
             (solver.max_step_attempts 10, mu 0.1): step budget"
        ),
        "{}",
        stderr(&o)
    );
    let recs = lines(&out.join("points.jsonl"));
    assert_eq!(recs.len(), 4);
    for r in &recs[..2] {
        assert_eq!(r["status"], "failed", "{r}");
        assert_eq!(r["error"]["kind"], "step_budget", "{r}");
        assert!(r["error"]["message"]
            .as_str()
            .unwrap()
            .contains("step budget"));
        assert!(r.get("record").is_none());
    }
    for r in &recs[2..] {
        assert_eq!(r["status"], "ok", "{r}");
        assert!(r.get("error").is_none());
    }
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    assert_eq!(
        summary.lines().filter(|l| l.contains(",failed,")).count(),
        2,
        "{summary}"
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["counts"]["failed"], 2);
    assert_eq!(m["counts"]["ok"], 2);

    // Resume re-runs failed points (still failing here) and keeps one line per point.
    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&out),
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(lines(&out.join("points.jsonl")).len(), 4);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A resume keeps a record only where it holds its grid point's inputs: a record whose inputs
/// were edited is run again (with a warning), and the file comes back as an uninterrupted run
/// writes it.
#[test]
fn a_resume_runs_again_a_record_whose_inputs_were_edited() {
    let dir = temp_dir("edited");
    let out = dir.join("out");
    let spec = smoke_spec();
    let run = |extra: &[&str]| {
        let mut args = vec!["sweep", s(&spec), "--out", s(&out), "--no-progress"];
        args.extend_from_slice(extra);
        whirlmap(&args)
    };
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let path = out.join("points.jsonl");
    let original = std::fs::read_to_string(&path).unwrap();
    let first = original.lines().next().unwrap();
    let mut v: serde_json::Value = serde_json::from_str(first).unwrap();
    let speed = v["inputs"]["speed_rpm"].clone();
    v["inputs"]["speed_rpm"] = serde_json::json!(123.0);
    let edited = original.replacen(first, &v.to_string(), 1);
    assert_ne!(edited, original);
    std::fs::write(&path, edited).unwrap();
    let o = run(&["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the records at grid index 0 do not hold their points' inputs"),
        "{}",
        stderr(&o)
    );
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(3 resumed)"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(
        std::fs::read_to_string(&path).unwrap() == original,
        "{speed}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An orbit panel whose drop fails (its scene's step budget, which the grid's axis raises for
/// the grid's points) leaves its `.error.txt`, and the sweep says so and exits 1; a panel whose
/// scene is invalid (a stop speed above the panel's speed) is refused before anything runs.
#[test]
fn a_failed_orbit_panel_exits_1_and_an_invalid_one_is_refused() {
    let dir = temp_dir("orbit-failed");
    let spec = spec_file(
        &dir,
        "orbits",
        r#"{"name": "orbits", "scene": {"solver": {"max_step_attempts": 20}}, "duration_s": 0.05,
            "axes": {"speed_rpm": [4000], "mu": [0.1], "solver.max_step_attempts": [1000000]},
            "orbits": {"speed_rpm": 4000, "mu": [0.1, 0.2]}}"#,
    );
    let out = dir.join("out");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&out), "--no-progress"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("0 drops recorded, 2 failed"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let e = std::fs::read_to_string(out.join("orbits/00_4000rpm_mu0.100.error.txt")).unwrap();
    assert!(e.contains("step budget"), "{e}");

    let spec = spec_file(
        &dir,
        "invalid",
        r#"{"name": "invalid", "scene": {"stop_speed_rpm": 1500}, "duration_s": 0.05,
            "axes": {"speed_rpm": [4000], "mu": [0.1]},
            "orbits": {"speed_rpm": 1000, "mu": [0.1]}}"#,
    );
    let out = dir.join("invalid-out");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&out), "--no-progress"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("scene.stop_speed_rpm (the orbit panel at 1000 r/min, mu 0.1) = 1500"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("points.jsonl").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Points of very different cost, interleaved along the grid: in every row of four, the
/// first drop (rtol 1e-10) takes some 30 times as long as the other three. With more than one
/// thread the cheap points finish before the dear one before them.
const UNEVEN_SPEC: &str = r#"{
  "name": "uneven",
  "scene": {"classification": {"max_extension_s": 0}},
  "duration_s": 0.2,
  "axes": {"speed_rpm": [3000, 5000, 7000, 9000, 11000, 13000],
           "solver.rtol": [1e-10, 1e-4, 1e-5, 1e-6]}
}"#;

/// The `index` of every line of a records file, in file order.
fn indices(path: &Path) -> Vec<u64> {
    lines(path)
        .iter()
        .map(|r| r["index"].as_u64().expect("an index"))
        .collect()
}

#[test]
fn uneven_points_give_the_same_bytes_on_one_two_and_three_threads() {
    let dir = temp_dir("uneven");
    let spec = dir.join("uneven.json");
    std::fs::write(&spec, UNEVEN_SPEC).unwrap();
    let mut points = Vec::new();
    let mut summaries = Vec::new();
    for threads in ["1", "2", "3"] {
        let out = dir.join(format!("t{threads}"));
        let o = whirlmap(&[
            "sweep",
            s(&spec),
            "--out",
            s(&out),
            "--threads",
            threads,
            "--no-progress",
        ]);
        assert_eq!(o.status.code(), Some(0), "{threads}: {}", stderr(&o));
        let grid_order: Vec<u64> = (0..24).collect();
        assert_eq!(indices(&out.join("points.jsonl")), grid_order, "{threads}");
        // Wall times differ from run to run; their order is the grid's too.
        assert_eq!(indices(&out.join("timings.jsonl")), grid_order, "{threads}");
        points.push(std::fs::read(out.join("points.jsonl")).unwrap());
        summaries.push(std::fs::read(out.join("summary.csv")).unwrap());
    }
    assert!(points[0] == points[1], "points.jsonl: 1 vs 2 threads");
    assert!(points[0] == points[2], "points.jsonl: 1 vs 3 threads");
    assert!(summaries[0] == summaries[1] && summaries[0] == summaries[2]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_killed_run_on_three_threads_holds_a_grid_prefix_and_resumes_to_the_same_bytes() {
    let dir = temp_dir("kill3");
    let spec = dir.join("uneven.json");
    std::fs::write(&spec, UNEVEN_SPEC).unwrap();
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    let points = kill_after_two_lines(&spec, &killed, "3", 24);
    // Whatever finished out of order, the file holds the first points of the grid, in order,
    // each once.
    let got = indices(&points);
    assert!((2..24).contains(&got.len()), "{} lines", got.len());
    assert_eq!(got, (0..got.len() as u64).collect::<Vec<_>>());
    let timings = indices(&killed.join("timings.jsonl"));
    assert_eq!(timings, got, "timings.jsonl follows points.jsonl");

    for (out, extra) in [
        (&killed, &["--threads", "2", "--resume"][..]),
        (&full, &["--threads", "1"][..]),
    ] {
        let mut args = vec!["sweep", s(&spec), "--out", s(out), "--no-progress"];
        args.extend_from_slice(extra);
        let o = whirlmap(&args);
        assert_eq!(o.status.code(), Some(0), "{extra:?}: {}", stderr(&o));
    }
    assert!(
        std::fs::read(&points).unwrap() == std::fs::read(full.join("points.jsonl")).unwrap(),
        "resumed points.jsonl differs from the uninterrupted run's"
    );
    let m = read_json(&killed.join("manifest.json"));
    assert_eq!(m["counts"]["skipped"], got.len());
    assert_eq!(m["counts"]["ok"], 24);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A sweep killed while its probability ensemble ran keeps that ensemble's members on
/// `--resume`: the kill is staged (the members cut to three, the ensemble's files after
/// them removed, its manifest marked unfinished), and one kept record is marked so that a
/// rerun of that member would show.
#[test]
fn a_resumed_sweep_keeps_the_members_its_probability_ensemble_wrote() {
    let dir = temp_dir("resume-probability");
    let spec = spec_file(
        &dir,
        "p.json",
        r#"{"name": "p", "duration_s": 0.05,
            "axes": {"speed_rpm": [4000], "mu": [0.3]},
            "probability": {"axes": {"speed_rpm": [4000, 8000], "mu": [0.3]},
              "duration_s": 0.05,
              "ensemble": {"members": 3, "seed": 1,
                "unbalance_m": {"uniform": {"from": 0, "to": 5e-6}}}}}"#,
    );
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    for out in [&full, &killed] {
        let o = whirlmap(&["sweep", s(&spec), "--out", s(out), "--no-progress"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let p = killed.join("probability");
    let members = std::fs::read_to_string(p.join("members.jsonl")).unwrap();
    assert_eq!(members.lines().count(), 6);
    // Edited as text: the record's keys keep their order.
    let first = members.lines().next().unwrap();
    let at = first.find("\"peak_heat_power_w\":").unwrap() + "\"peak_heat_power_w\":".len();
    let end = at + first[at..].find([',', '}']).unwrap();
    let mut cut = format!("{}12345.0{}\n", &first[..at], &first[end..]);
    for l in members.lines().skip(1).take(2) {
        cut.push_str(l);
        cut.push('\n');
    }
    std::fs::write(p.join("members.jsonl"), &cut).unwrap();
    for f in ["cells.jsonl", "cells.csv", "contours.json"] {
        std::fs::remove_file(p.join(f)).unwrap();
    }
    let m = std::fs::read_to_string(p.join("manifest.json")).unwrap();
    std::fs::write(
        p.join("manifest.json"),
        m.replace("\"complete\": true", "\"complete\": false"),
    )
    .unwrap();

    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&killed),
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let after: Vec<serde_json::Value> = lines(&p.join("members.jsonl"));
    assert_eq!(after.len(), 6);
    assert_eq!(
        after[0]["peak_heat_power_w"], 12345.0,
        "the first member was kept"
    );
    let fresh = lines(&full.join("probability/members.jsonl"));
    assert_eq!(
        after[1..],
        fresh[1..],
        "the rest as an uninterrupted run has them"
    );
    assert_eq!(read_json(&p.join("manifest.json"))["complete"], true);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A resumed sweep keeps the critical search and the orbits a killed run finished, and runs
/// again only a critical row that failed drops left undecided. Marked records show which: a
/// kept file or row keeps its mark, a rerun one loses it.
#[test]
fn a_resumed_sweep_keeps_the_finished_critical_search_and_orbits() {
    let dir = temp_dir("resume-extras");
    let spec = spec_file(
        &dir,
        "x.json",
        r#"{"name": "x", "duration_s": 0.1,
            "axes": {"speed_rpm": [4000], "mu": [0.3]},
            "critical": {"mu": [0.3, 0.4], "speed_rpm": {"from": 2000, "to": 6000},
              "resolution_rpm": 2000, "tol_rpm": 500},
            "orbits": {"speed_rpm": 4000, "mu": [0.1, 0.3]}}"#,
    );
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    for out in [&full, &killed] {
        let o = whirlmap(&["sweep", s(&spec), "--out", s(out), "--no-progress"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let critical = killed.join("critical.json");
    let text = std::fs::read_to_string(&critical).unwrap();
    let marked = text.replace("\"note\": \"", "\"note\": \"KEPT ");
    assert_eq!(marked.matches("KEPT").count(), 2, "both rows marked");
    assert_ne!(marked, text);
    std::fs::write(&critical, &marked).unwrap();
    let orbits: Vec<PathBuf> = {
        let mut v: Vec<PathBuf> = std::fs::read_dir(killed.join("orbits"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    };
    assert_eq!(orbits.len(), 2, "{orbits:?}");
    // The first orbit is kept (marked); the second is missing, as if killed before it.
    let first = std::fs::read_to_string(&orbits[0]).unwrap();
    let first_marked = first.replacen('{', "{\"kept\": true, ", 1);
    std::fs::write(&orbits[0], &first_marked).unwrap();
    std::fs::remove_file(&orbits[1]).unwrap();

    let resume = || {
        let o = whirlmap(&[
            "sweep",
            s(&spec),
            "--out",
            s(&killed),
            "--resume",
            "--no-progress",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    };
    resume();
    assert_eq!(
        std::fs::read_to_string(&critical).unwrap(),
        marked,
        "critical.json kept"
    );
    assert!(std::fs::read_to_string(killed.join("critical.csv"))
        .unwrap()
        .contains("KEPT"));
    assert_eq!(std::fs::read_to_string(&orbits[0]).unwrap(), first_marked);
    let second = full.join("orbits").join(orbits[1].file_name().unwrap());
    assert_eq!(
        std::fs::read(&orbits[1]).unwrap(),
        std::fs::read(second).unwrap()
    );

    // A row left undecided by failed drops is run again (its mark goes); the other row is
    // kept (its mark stays).
    let undecided = marked.replacen("\"from_rpm\"", "\"undecided\": true,\n    \"from_rpm\"", 1);
    std::fs::write(&critical, &undecided).unwrap();
    resume();
    let (rows, fresh) = (read_json(&critical), read_json(&full.join("critical.json")));
    assert_eq!(rows[0], fresh[0], "the undecided row searched again");
    assert_ne!(rows[1], fresh[1]);
    let note = rows[1]["note"].as_str().unwrap();
    assert_eq!(
        note.strip_prefix("KEPT "),
        fresh[1]["note"].as_str(),
        "the decided row kept"
    );
    assert!(std::fs::read_to_string(killed.join("critical.csv"))
        .unwrap()
        .contains("KEPT"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A `draft` sweep whose critical search re-checks its onsets at `standard`: the bracket of
/// mu 0.25 is not confirmed there (tests/critical.rs); mu 0.35, which whirls from the range
/// bottom at both presets, is.
const RECHECK_SPEC: &str = r#"{"name": "rc", "duration_s": 1.0, "fidelity": "draft",
    "axes": {"speed_rpm": [4000], "mu": [0.3]},
    "critical": {"mu": [0.25, 0.35], "speed_rpm": {"from": 10000, "to": 13000},
      "resolution_rpm": 250, "tol_rpm": 25, "recheck": true},
    "charts": ["critical"]}"#;

/// With `critical.recheck`, a sweep re-checks each row at the next tighter preset
/// as `whirlmap critical --fidelity` does: its rows are the command's, a bracket the tighter
/// preset does not confirm (mu 0.25 at `draft`, see tests/critical.rs) leaves its row not
/// converged, the summary and standard error name it, and the sweep exits 1.
#[test]
fn a_sweep_rechecks_its_critical_brackets_when_asked() {
    let dir = temp_dir("recheck");
    let spec = spec_file(&dir, "rc", RECHECK_SPEC);
    let out_dir = dir.join("out");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        out(&o).contains("1 of 2 not confirmed by the re-check: mu 0.25"),
        "{}",
        out(&o)
    );
    assert!(
        stderr(&o).contains("does not confirm the onset at mu 0.25 (at standard:"),
        "{}",
        stderr(&o)
    );
    let rows = read_json(&out_dir.join("critical.json"));
    assert_eq!(rows[0]["recheck"]["confirmed"], false, "{rows}");
    assert_eq!(rows[0]["converged"], false, "{rows}");
    assert_eq!(rows[1]["recheck"]["confirmed"], true, "{rows}");
    assert_eq!(rows[1]["recheck"]["fidelity"], "standard", "{rows}");
    let csv = std::fs::read_to_string(out_dir.join("critical.csv")).unwrap();
    assert!(csv.contains("NOT CONFIRMED by the re-check at standard"));
    // The re-check's own columns: its preset, whether the onset holds, the onset at that
    // preset (the one searched again where it does not hold) and its drops.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let columns = header.len();
    let cell = |row: usize, name: &str| {
        let line = csv.lines().nth(row + 1).unwrap();
        let at = header.iter().position(|h| *h == name).unwrap();
        line.splitn(columns, ',').nth(at).unwrap().to_string()
    };
    for (i, holds) in [(0, "false"), (1, "true")] {
        let rc = &rows[i]["recheck"];
        assert_eq!(cell(i, "recheck_fidelity"), "standard");
        assert_eq!(cell(i, "recheck_holds"), holds);
        let found = match i {
            0 => rc["relocated"]["onset_rpm"].as_f64(),
            _ => rows[i]["onset_rpm"].as_f64(),
        };
        assert_eq!(
            cell(i, "recheck_onset_rpm"),
            found.map_or(String::new(), |x| x.to_string())
        );
        let cells = rc["lo"].is_array() as u64 + rc["hi"].is_array() as u64;
        let window = rc["relocated"]["drops"].as_u64().unwrap_or(0);
        assert_eq!(
            cell(i, "recheck_drops"),
            (cells + window).to_string(),
            "{rc}"
        );
    }
    assert!(!cell(0, "recheck_onset_rpm").is_empty(), "{csv}");
    let cli = whirlmap(&[
        "critical",
        "--json",
        "--mu",
        "0.25",
        "--mu",
        "0.35",
        "--from",
        "10000",
        "--to",
        "13000",
        "--resolution-rpm",
        "250",
        "--tol-rpm",
        "25",
        "--fidelity",
        "draft",
        "--no-progress",
    ]);
    let cli: serde_json::Value = serde_json::from_slice(&cli.stdout).expect("the rows");
    assert_eq!(rows, cli, "the sweep's rows are the command's");

    // Without `recheck` the same search has no re-check and exits 0.
    let plain = spec_file(
        &dir,
        "plain.json",
        &std::fs::read_to_string(&spec)
            .unwrap()
            .replace(r#", "recheck": true"#, ""),
    );
    let o = whirlmap(&[
        "sweep",
        s(&plain),
        "--out",
        s(&dir.join("plain")),
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rows = read_json(&dir.join("plain").join("critical.json"));
    assert!(
        rows[0].get("recheck").is_none() && rows[0]["converged"] == true,
        "{rows}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A sweep whose re-check does not confirm an onset keeps saying so: `--resume` of the
/// finished folder keeps its point and `critical.json` byte for byte and exits 1 with the
/// same message; sharded (shard 0 owns mu 0.25, the unconfirmed one), the shard that
/// holds the row exits 1, and the merge exits 1 and writes the single run's `critical.json`.
#[test]
fn a_rechecked_sweep_resumes_and_merges_with_its_unconfirmed_row() {
    let dir = temp_dir("recheck-resume-merge");
    let spec = spec_file(&dir, "rc", RECHECK_SPEC);
    let message = "does not confirm the onset at mu 0.25 (at standard:";
    let single = dir.join("single");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&single), "--no-progress"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let rows = std::fs::read(single.join("critical.json")).unwrap();

    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&single),
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains(message), "{}", stderr(&o));
    assert!(out(&o).contains("(1 resumed)"), "{}", out(&o));
    assert_eq!(std::fs::read(single.join("critical.json")).unwrap(), rows);

    let mut shards = Vec::new();
    for (i, code) in [(0, 1), (1, 0)] {
        let d = dir.join(format!("shard-{i}"));
        let o = sweep_shard(&spec, &d, i, 2);
        assert_eq!(o.status.code(), Some(code), "shard {i}: {}", stderr(&o));
        shards.push(d);
    }
    let merged = dir.join("merged");
    let o = whirlmap(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains(message), "{}", stderr(&o));
    assert_eq!(std::fs::read(merged.join("critical.json")).unwrap(), rows);
    std::fs::remove_dir_all(&dir).unwrap();
}

const CRITICAL_SPEC: &str = r#"{"name": "crit", "duration_s": 0.1,
    "scene": {"solver": {"rtol": 1e-7}},
    "axes": {"speed_rpm": [4000], "mu": [0.3]},
    "critical": {"mu": [0.3, 0.4], "speed_rpm": {"from": 2000, "to": 8000},
      "resolution_rpm": 1000, "tol_rpm": 250}}"#;

/// A sweep killed in the middle of its critical search keeps the search's classified drops
/// (`critical-drops.jsonl`): `--resume` runs only the others and writes the `critical.json`
/// of an uninterrupted run, then removes the log.
#[test]
fn a_sweep_killed_in_its_critical_search_resumes_without_rerunning_its_drops() {
    let dir = temp_dir("resume-critical");
    let spec = spec_file(&dir, "crit", CRITICAL_SPEC);
    let (full, killed) = (dir.join("full"), dir.join("killed"));
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&full), "--no-progress"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        !full.join("critical-drops.jsonl").exists(),
        "the log is removed once critical.json is written"
    );
    let args = [
        "sweep",
        s(&spec),
        "--out",
        s(&killed),
        "--threads",
        "2",
        "--no-progress",
    ];
    let log = killed.join("critical-drops.jsonl");
    let logged = kill_after_lines(&args, &log, 5);
    assert!(!killed.join("critical.json").exists(), "killed mid-search");
    let o = whirlmap(&[
        "sweep",
        s(&spec),
        "--out",
        s(&killed),
        "--resume",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    let reused: usize = err
        .split("critical search: ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no reuse reported: {err}"));
    assert!(reused >= logged, "{reused} reused of {logged} logged");
    assert_eq!(
        std::fs::read(killed.join("critical.json")).unwrap(),
        std::fs::read(full.join("critical.json")).unwrap()
    );
    assert!(!log.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// What a resumed critical search takes from the log, shown by a staged log: a line of the
/// same coefficient, speed and scene is used (here a false class at the top scan speed), a
/// line of another scene is not, nor a last line the kill cut before its newline (whole JSON
/// here, so only its missing newline keeps it out), nor a line that is not UTF-8.
#[test]
fn a_resumed_critical_search_uses_exactly_the_logged_drops_of_its_scenes() {
    let dir = temp_dir("critical-log");
    let spec = spec_file(&dir, "crit", CRITICAL_SPEC);
    let out = dir.join("out");
    let run = |resume: bool| {
        let mut a = vec!["sweep", s(&spec), "--out", s(&out), "--no-progress"];
        if resume {
            a.push("--resume");
        }
        let o = whirlmap(&a);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        o
    };
    run(false);
    let full = read_json(&out.join("critical.json"));
    let row = |v: &serde_json::Value, j: usize| v[j].clone();
    let hash = |j: usize| full[j]["scene_hash"].as_str().unwrap().to_string();
    // At the top of the scan mu 0.4 whirls and mu 0.3 does not; the log says the opposite.
    let top = |j: usize| full[j]["scan"].as_array().unwrap().last().unwrap()["class"].clone();
    assert_eq!(
        (top(0), top(1)),
        ("pendulum".into(), "backward_whirl".into())
    );
    let mut log = format!(
        "{}\n{}\n",
        serde_json::json!({"mu": 0.4, "speed_rpm": 8000.0, "scene_hash": hash(1), "class": "pendulum"}),
        serde_json::json!({"mu": 0.3, "speed_rpm": 8000.0, "scene_hash": "0000000000000000", "class": "backward_whirl"}),
    )
    .into_bytes();
    log.extend_from_slice(b"\xff\xfe not a line\n");
    let torn = serde_json::json!({"mu": 0.3, "speed_rpm": 8000.0, "scene_hash": hash(0), "class": "backward_whirl"});
    log.extend_from_slice(torn.to_string().as_bytes());
    std::fs::remove_file(out.join("critical.json")).unwrap();
    std::fs::write(out.join("critical-drops.jsonl"), log).unwrap();
    let o = run(true);
    assert!(
        stderr(&o).contains("critical search: 1 drop reused"),
        "{}",
        stderr(&o)
    );
    let resumed = read_json(&out.join("critical.json"));
    assert_eq!(
        row(&resumed, 0),
        row(&full, 0),
        "neither the other scene's line nor the torn one is used"
    );
    assert_ne!(row(&resumed, 1), row(&full, 1), "the logged class is used");
    assert!(!out.join("critical-drops.jsonl").exists());

    // A log a kill left beside a finished critical.json goes at the next resume.
    std::fs::write(out.join("critical-drops.jsonl"), "").unwrap();
    run(true);
    assert!(!out.join("critical-drops.jsonl").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `sweeps/critical-draft-checked.json` (docs/critical-speed.md#screening-at-draft-checked-at-standard):
/// the main job's critical search at `draft`, re-checked at `standard`. Every onset the
/// re-check confirms or finds in its window is the committed main job's (`results/paper`, a
/// `standard` search of the whole range), to the bit. The onset `standard` finds again within
/// the search's 25 r/min tolerance holds (μ 0.45), and the sweep exits 1 for the one that
/// does not (μ 0.25, 62.5 r/min low at `draft`, more than the tolerance).
#[test]
fn a_draft_search_rechecked_at_standard_finds_the_main_job_s_onsets() {
    let dir = temp_dir("draft-checked");
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/critical-draft-checked.json");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&dir), "--no-progress"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let rows = read_json(&dir.join("critical.json"));
    let main =
        read_json(&Path::new(env!("CARGO_MANIFEST_DIR")).join("results/paper/critical.json"));
    let (rows, main) = (rows.as_array().unwrap(), main.as_array().unwrap());
    assert_eq!(rows.len(), main.len());
    // Every row is re-checked: a bracket at its two ends, a row without one (no whirl in the
    // range, in both) at the range top.
    let (mut confirmed_brackets, mut confirmed_no_whirl, mut found) = (0, 0, 0);
    for (r, m) in rows.iter().zip(main) {
        assert_eq!(r["mu"], m["mu"]);
        let rc = &r["recheck"];
        assert_eq!(rc["fidelity"], "standard", "{r}");
        if rc["confirmed"] == true {
            assert_eq!(r["onset_rpm"], m["onset_rpm"], "{r}");
            if r["bracket_rpm"].is_null() {
                assert!(r["onset_rpm"].is_null(), "{r}");
                confirmed_no_whirl += 1;
            } else {
                confirmed_brackets += 1;
            }
        } else if let Some(onset) = rc["relocated"]["onset_rpm"].as_f64() {
            found += 1;
            assert_eq!(Some(onset), m["onset_rpm"].as_f64(), "{r}");
        }
    }
    // mu 0.05-0.2 and 0.3 (no whirl); mu 0.35, 0.4 and 0.5 (brackets).
    assert_eq!((confirmed_no_whirl, confirmed_brackets), (5, 3), "{rows:?}");
    let r = rows.iter().find(|r| r["mu"] == 0.5).unwrap();
    assert_eq!(r["recheck"]["confirmed"], true, "{r}");
    // mu 0.25, where `draft` is 62.5 r/min low: not confirmed, and found in the window.
    let r = rows.iter().find(|r| r["mu"] == 0.25).unwrap();
    assert_eq!(r["recheck"]["confirmed"], false, "{r}");
    assert!(r["recheck"]["relocated"]["onset_rpm"].is_f64(), "{r}");
    assert_eq!(r["converged"], false, "{r}");
    assert_eq!(found, 2, "{rows:?}");
    // mu 0.45: a bracket end has another class at `standard`, but its onset is within the
    // tolerance of `draft`'s, so the onset holds.
    let r = rows.iter().find(|r| r["mu"] == 0.45).unwrap();
    let rc = &r["recheck"];
    assert_eq!(
        (&rc["confirmed"], &rc["within_tol"]),
        (&false.into(), &true.into()),
        "{r}"
    );
    let gap = rc["relocated"]["onset_rpm"].as_f64().unwrap() - r["onset_rpm"].as_f64().unwrap();
    assert!(gap.abs() <= r["tol_rpm"].as_f64().unwrap(), "{r}");
    assert_eq!(r["converged"], true, "{r}");
    assert!(
        r["note"]
            .as_str()
            .unwrap()
            .starts_with("the onset holds to 25 r/min"),
        "{r}"
    );
    let err = stderr(&o);
    assert!(
        err.contains("mu 0.25") && !err.contains("mu 0.45") && !err.contains("mu 0.5"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
