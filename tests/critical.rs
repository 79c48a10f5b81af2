//! End-to-end tests of `whirlmap critical`: a real search on the default scene, bad input
//! rejected with exit code 2 before any drop runs, and failed drops that leave an onset
//! undecided (exit 1 from `critical`, a sweep, a shard and a merge, every row written).

mod common;
use common::*;

/// Runs `whirlmap critical --json` and returns its rows.
fn rows(args: &[&str]) -> Vec<serde_json::Value> {
    let mut all = vec!["critical", "--json"];
    all.extend_from_slice(args);
    let out = whirlmap(&all);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{all:?}: {stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    v.as_array().expect("a list of rows").clone()
}

#[test]
fn default_scene_at_mu_0_4_has_an_onset_bracketed_within_the_tolerance() {
    // 11 lattice drops of 0.5 s (whirl ones stop after about 60 ms) and 3 bisections.
    let rows = rows(&[
        "--mu",
        "0.4",
        "--from",
        "2000",
        "--to",
        "12000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "125",
        "--duration-s",
        "0.5",
    ]);
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    assert_eq!(r["mu"], 0.4);
    let b = r["bracket_rpm"].as_array().expect("a bracket exists");
    let (lo, hi) = (b[0].as_f64().unwrap(), b[1].as_f64().unwrap());
    assert!(
        2000.0 <= lo && lo < hi && hi <= 12000.0 && hi - lo <= 125.0,
        "{lo} {hi}"
    );
    assert_eq!(r["onset_rpm"].as_f64(), Some(hi));
    assert_eq!(r["class_above"], "backward_whirl");
    assert_eq!(
        r["class_below"], "pendulum",
        "a settled class below, not unresolved"
    );
    assert_eq!(r["converged"], true);
    assert_eq!(r["non_monotone"], false);
    let intervals = r["whirl_intervals_rpm"].as_array().unwrap();
    assert_eq!(intervals.len(), 1);
    assert_eq!(intervals[0][0].as_f64(), Some(hi));
    assert_eq!(r["whirl_at_range_top"], true);
    assert_eq!(r["scan"].as_array().unwrap().len(), 11);
    let drops = r["drops"].as_u64().unwrap();
    assert_eq!(drops, 11 + r["bisections"].as_array().unwrap().len() as u64);
    assert!(r["note"].as_str().is_some_and(|n| !n.is_empty()));
    assert_eq!(r["tol_rpm"], 125.0);
    assert_eq!(r["model_version"], whirlmap_core::MODEL_VERSION);
}

#[test]
fn two_ranges_that_contain_the_onset_give_the_same_onset() {
    // The issue's reproducer in small: before the lattice, the bracket moved with the range.
    let search = |from: &str, to: &str| {
        rows(&[
            "--mu",
            "0.4",
            "--from",
            from,
            "--to",
            to,
            "--resolution-rpm",
            "500",
            "--tol-rpm",
            "62.5",
            "--duration-s",
            "0.5",
        ])[0]
            .clone()
    };
    let wide = search("2000", "9000");
    let narrow = search("3100", "5900");
    let onset = |r: &serde_json::Value| r["onset_rpm"].as_f64().expect("an onset");
    assert_eq!(onset(&wide), onset(&narrow), "{wide}\n{narrow}");
    assert_eq!(wide["bracket_rpm"], narrow["bracket_rpm"]);
}

#[test]
fn csv_rows_match_the_json_rows() {
    let dir = temp_dir("critical-csv");
    let csv = dir.join("critical.csv");
    let rows = rows(&[
        "--mu",
        "0.3,0.4",
        "--from",
        "4000",
        "--to",
        "5000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "1000",
        "--duration-s",
        "0.3",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(
        lines[0].starts_with("mu,onset_rpm,bracket_below_rpm"),
        "{text}"
    );
    for (line, row) in lines[1..].iter().zip(&rows) {
        assert!(line.starts_with(&format!("{},", row["mu"])), "{line}");
        let drops = row["drops"].to_string();
        assert!(
            line.contains(&format!(",{drops},")),
            "{line} lacks drops {drops}"
        );
    }
}

#[test]
fn human_output_has_a_table_per_mu() {
    let out = whirlmap(&[
        "critical",
        "--mu",
        "0.3,0.4",
        "--from",
        "2000",
        "--to",
        "2500",
        "--resolution-rpm",
        "500",
        "--tol-rpm",
        "500",
        "--duration-s",
        "0.1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "mu_d = 0.3",
        "mu_d = 0.4",
        "onset of whirl",
        "whirl intervals",
        "drops",
        "non-monotone",
        "note",
    ] {
        assert!(text.contains(needle), "missing {needle}:\n{text}");
    }
}

#[test]
fn bad_input_exits_2_naming_the_field_and_value() {
    let base = ["critical", "--duration-s", "0.1"];
    let cases: &[(&[&str], &str)] = &[
        (&["--mu", "0.4", "--from", "5000", "--to", "2000"], "--to"),
        (&["--mu", "0.4", "--from", "3000", "--to", "3000"], "--to"),
        (&["--mu", "0.4", "--from", "-1", "--to", "2000"], "--from"),
        (&["--mu", "0.4", "--from", "NaN", "--to", "2000"], "--from"),
        (&["--mu", "0.4", "--from", "0", "--to", "inf"], "--to"),
        (
            &["--mu", "0.4", "--from", "0", "--to", "10", "--tol-rpm", "0"],
            "--tol-rpm",
        ),
        (
            &[
                "--mu",
                "0.4",
                "--from",
                "0",
                "--to",
                "10",
                "--tol-rpm",
                "-5",
            ],
            "--tol-rpm",
        ),
        (
            &[
                "--mu",
                "0.1",
                "--from",
                "1000",
                "--to",
                "2000",
                "--set",
                "stop_speed_rpm=1500",
            ],
            "at the lowest speed searched, --from 1000 r/min: invalid stop_speed_rpm = 1500",
        ),
        (&["--mu", "0.3,2.5", "--from", "0", "--to", "10"], "--mu"),
        (&["--mu", "0.3,0.3", "--from", "0", "--to", "10"], "--mu"),
        (&["--mu", "0.4", "--from", "0", "--to", "1e308"], "--to"),
        (
            &[
                "--mu",
                "0.4",
                "--from",
                "0",
                "--to",
                "1000",
                "--resolution-rpm",
                "0",
            ],
            "--resolution-rpm",
        ),
        (
            &[
                "--mu",
                "0.4",
                "--from",
                "0",
                "--to",
                "1000",
                "--tol-rpm",
                "1e-300",
            ],
            "--tol-rpm",
        ),
        (&["--mu", "-0.1", "--from", "0", "--to", "10"], "--mu"),
        (
            &[
                "--mu",
                "0.4",
                "--from",
                "0",
                "--to",
                "10",
                "--set",
                "clearence_m=1",
            ],
            "clearence_m",
        ),
        (
            &[
                "--mu",
                "0.4",
                "--from",
                "0",
                "--to",
                "10",
                "--set",
                "mu_static=0.2",
            ],
            "mu_static",
        ),
    ];
    for (args, field) in cases {
        let mut all: Vec<&str> = base.to_vec();
        all.extend_from_slice(args);
        let out = whirlmap(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {stderr}");
        assert!(stderr.contains(field), "{all:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{all:?} ran something");
    }
    // Missing --mu is a usage error (clap's exit code 2).
    let out = whirlmap(&["critical", "--from", "0", "--to", "10"]);
    assert_eq!(out.status.code(), Some(2));
}

/// A step budget too small for the pendulum drops at mu 0.4 (at 4000 r/min and below they
/// fail: 0.3 s at 4000 r/min takes 6872 step attempts in the search); the whirl drops, which
/// stop early, finish (at most 3063 attempts between 4500 and 6000 r/min at mu 0.4, 2085 from
/// 4000 r/min at mu 0.45). Counts of model version 12.
const TINY_BUDGET: &str = "solver.max_step_attempts=5000";

#[test]
fn failed_drops_that_leave_the_onset_undecided_exit_1_with_every_row_written() {
    let dir = temp_dir("critical-undecided");
    let csv = dir.join("critical.csv");
    // Every scan drop fails (a budget of 2000 step attempts; the cheapest of the four takes
    // 2986 in model version 12): nothing is decided.
    let all_failed = [
        "critical",
        "--mu",
        "0.4",
        "--set",
        "solver.max_step_attempts=2000",
        "--from",
        "3000",
        "--to",
        "6000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "250",
        "--duration-s",
        "0.3",
        "--no-progress",
        "--json",
        "--csv",
        s(&csv),
    ];
    let o = whirlmap(&all_failed);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    let err = stderr(&o);
    assert!(
        err.contains("undecided at mu 0.4 (4 of 4 drops failed)"),
        "{err}"
    );
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    let r = &rows[0];
    assert_eq!(
        (&r["failed_drops"], &r["converged"], &r["undecided"]),
        (&4.into(), &false.into(), &true.into()),
        "{r}"
    );
    assert!(r["note"]
        .as_str()
        .unwrap()
        .starts_with("UNDECIDED: every scan drop failed"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let line = text.lines().nth(1).expect("the row is written");
    assert!(
        line.starts_with("0.4,") && line.contains(",4,4,false,true,"),
        "{line}"
    );

    // Drops below the onset fail, one coefficient of two: the whirl found at 5000 r/min
    // may start lower. The table names the undecided row; the decided one is kept.
    let o = whirlmap(&[
        "critical",
        "--mu",
        "0.4,0.45",
        "--set",
        TINY_BUDGET,
        "--from",
        "4000",
        "--to",
        "6000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "250",
        "--duration-s",
        "0.3",
        "--no-progress",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("mu_d = 0.45") && text.contains("mu_d = 0.4"),
        "{text}"
    );
    assert!(text.contains("UNDECIDED"), "{text}");
    let err = stderr(&o);
    assert!(err.contains("mu 0.4 (1 of 3 drops failed)"), "{err}");
    assert!(!err.contains("mu 0.45"), "{err}");
}

/// A `draft` search whose onset the re-check at `standard` does not confirm: at mu 0.25
/// `draft` brackets the onset at 11 390.625-11 406.25 r/min, where `standard` gives pendulum
/// on both sides (its onset is 62.5 r/min higher, more than the 25 r/min tolerance): every
/// row printed, and exit 1 with the coefficient and what the re-check found. The onset the
/// re-check then finds near the bracket is the one a search at `standard` over the whole
/// range finds (the lattice is the same, and a search does not depend on its range). A
/// confirmed re-check exits 0.
#[test]
fn a_re_check_that_does_not_confirm_the_onset_exits_1() {
    let args = [
        "critical",
        "--json",
        "--mu",
        "0.25",
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
    ];
    let o = whirlmap(&args);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).expect("the rows");
    assert_eq!(rows[0]["recheck"]["confirmed"], false, "{rows}");
    // The row itself says it, for the CSV (no re-check columns) and whoever reads only it.
    assert_eq!(rows[0]["converged"], false, "{rows}");
    let note = rows[0]["note"].as_str().expect("a note");
    assert!(
        note.starts_with("NOT CONFIRMED by the re-check at standard: "),
        "{note}"
    );
    let pendulum = serde_json::json!({"class": "pendulum"});
    for end in ["lo", "hi"] {
        assert_eq!(rows[0]["recheck"][end][1], pendulum, "{rows}");
    }
    let err = stderr(&o);
    assert!(
        err.contains("does not confirm the onset at mu 0.25 (at standard:")
            && err.contains("r/min pendulum, 11406.25 r/min pendulum"),
        "{err}"
    );
    // Where `standard` puts the onset: searched two lattice steps either side of the
    // bracket, and the same as a `standard` search of the whole range finds.
    let relocated = &rows[0]["recheck"]["relocated"];
    let [lo, hi] = [0, 1].map(|i| rows[0]["bracket_rpm"][i].as_f64().unwrap());
    // From two lattice steps below the lattice point under the bracket (11 250) to two
    // above the one over it (11 500).
    assert!(lo > 11250.0 && hi <= 11500.0, "{lo} {hi}");
    assert_eq!(
        relocated["window_rpm"],
        serde_json::json!([10750.0, 12000.0])
    );
    let mut standard = args.to_vec();
    standard.truncate(args.len() - 3); // no `--fidelity draft`: the scene's numerics
    standard.push("--no-progress");
    let o = whirlmap(&standard);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let full: serde_json::Value = serde_json::from_slice(&o.stdout).expect("the rows");
    let onset = full[0]["onset_rpm"].as_f64().expect("an onset at standard");
    assert_eq!(relocated["onset_rpm"].as_f64(), Some(onset), "{rows}");
    assert!(
        onset > hi,
        "standard's onset {onset} lies above the draft bracket"
    );
    assert!(
        note.contains(&format!("its onset there {onset} r/min"))
            || note.contains(&format!("its onset there {onset:.1} r/min")),
        "{note}"
    );
    // mu 0.35, whose onset near 5 000 r/min both presets find: confirmed, exit 0.
    let ok = [
        "critical",
        "--json",
        "--mu",
        "0.35",
        "--from",
        "2000",
        "--to",
        "16000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "100",
        "--fidelity",
        "draft",
        "--no-progress",
    ];
    let o = whirlmap(&ok);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).expect("the rows");
    assert_eq!(rows[0]["recheck"]["confirmed"], true, "{rows}");
    assert!(rows[0]["recheck"].get("relocated").is_none(), "{rows}");
    assert_eq!(rows[0]["converged"], true, "{rows}");
    assert!(
        !rows[0]["note"]
            .as_str()
            .expect("a note")
            .contains("CONFIRMED"),
        "{rows}"
    );
}

/// A row without an onset bracket is re-checked at the end of the range that decides it: at
/// mu 0.1 (no whirl at either preset) the range top confirms it; at mu 0.4 (whirl from
/// 6000 r/min at both) the range bottom does, and the search exits 0. Such a row that the
/// re-check does not confirm is searched again near its deciding end
/// (`a_row_without_a_bracket_is_re_checked_at_its_deciding_end` in the sweep crate's
/// `recheck.rs`) and says so in the table (`the_onset_line_says_what_the_re_check_found`):
/// on the paper's scene `draft` and `standard` part only within a band of tens of r/min
/// below each onset (62.5 r/min at most over the main job's search, each `draft` onset at or
/// below `standard`'s), where the classes also flip between neighbouring speeds, so no range
/// end gives a clean case here.
#[test]
fn a_row_without_a_bracket_is_re_checked_at_the_end_that_decides_it() {
    let args = [
        "critical",
        "--json",
        "--mu",
        "0.1,0.4",
        "--from",
        "6000",
        "--to",
        "12000",
        "--resolution-rpm",
        "1000",
        "--tol-rpm",
        "100",
        "--no-progress",
        "--fidelity",
        "draft",
    ];
    let o = whirlmap(&args);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    let rows: serde_json::Value = serde_json::from_slice(&o.stdout).expect("the rows");
    for r in 0..2 {
        assert!(rows[r]["bracket_rpm"].is_null(), "{rows}");
    }
    // mu 0.1: no whirl, confirmed at the range top.
    let rc = &rows[0]["recheck"];
    assert_eq!(
        rc["lo"],
        serde_json::json!([12000.0, {"class": "pendulum"}]),
        "{rc}"
    );
    assert!(rc.get("hi").is_none() && rc["confirmed"] == true, "{rc}");
    assert_eq!(rows[0]["converged"], true, "{rows}");
    // mu 0.4: whirl from the lowest speed, confirmed there.
    let rc = &rows[1]["recheck"];
    assert_eq!(rc["hi"][0], 6000.0, "{rc}");
    assert!(rc.get("lo").is_none() && rc["confirmed"] == true, "{rc}");
    // The table gives both rows without a warning.
    let table: Vec<&str> = args.iter().copied().filter(|a| *a != "--json").collect();
    let o = whirlmap(&table);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    assert!(out(&o).contains("none in the range\n"), "{}", out(&o));
    assert!(
        out(&o).contains("at or below 6000 r/min (whirl at the lowest speed)\n"),
        "{}",
        out(&o)
    );
    assert!(!out(&o).contains("CONFIRMED"), "{}", out(&o));
}

#[test]
fn a_sweep_shard_and_merge_exit_1_when_a_critical_speed_is_undecided() {
    let dir = temp_dir("critical-undecided-sweep");
    // TINY_BUDGET's 5000 step attempts: the pendulum drop at 4000 r/min and mu 0.4 fails.
    let spec = spec_file(
        &dir,
        "undecided",
        r#"{"name": "undecided", "scene": {"solver": {"max_step_attempts": 5000}},
 "duration_s": 0.3, "axes": {"speed_rpm": [8000], "mu": [0.4]},
 "critical": {"mu": [0.4, 0.45], "speed_rpm": {"from": 4000, "to": 6000},
              "resolution_rpm": 1000, "tol_rpm": 250}}"#,
    );
    let check_rows = |out: &std::path::Path| {
        let rows = read_json(&out.join("critical.json"));
        assert_eq!(rows.as_array().unwrap().len(), 2, "{rows}");
        assert_eq!(rows[0]["undecided"], true, "{rows}");
        assert_eq!(rows[0]["converged"], false, "{rows}");
        let csv = std::fs::read_to_string(out.join("critical.csv")).unwrap();
        assert_eq!(csv.lines().count(), 3, "{csv}");
    };
    let single = dir.join("single");
    let o = whirlmap(&["sweep", s(&spec), "--out", s(&single), "--no-progress"]);
    // The grid point is fine: exit 1 is the critical search's.
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("1 points, 1 ok, 0 failed"), "{text}");
    assert!(
        text.contains("(1 of 2 undecided by failed or unsettled drops: mu 0.4)"),
        "{text}"
    );
    assert!(
        stderr(&o).contains("undecided at mu 0.4 ("),
        "{}",
        stderr(&o)
    );
    check_rows(&single);
    assert_eq!(read_json(&single.join("manifest.json"))["complete"], true);

    // Shard 0 owns mu 0.4 (undecided), shard 1 mu 0.45; the merge says it again.
    let mut shards = Vec::new();
    for (i, code) in [(0, 1), (1, 0)] {
        let d = dir.join(format!("shard-{i}"));
        let o = sweep_shard(&spec, &d, i, 2);
        assert_eq!(o.status.code(), Some(code), "shard {i}: {}", out(&o));
        shards.push(d);
    }
    let merged = dir.join("merged");
    let o = whirlmap(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert_eq!(o.status.code(), Some(1), "{}", out(&o));
    assert!(
        stderr(&o).contains("undecided at mu 0.4 ("),
        "{}",
        stderr(&o)
    );
    check_rows(&merged);
}

/// `--log FILE` keeps the search's drops: a killed search run again with the same file runs
/// only the missing drops and prints the rows of an uninterrupted run; a second run reuses
/// every drop and appends nothing; a run at another `--duration-s` reuses none; a file that
/// is not such a log is refused (exit 2) and left as it is.
#[test]
fn a_kept_drop_log_resumes_a_killed_search_and_answers_a_rerun() {
    let dir = temp_dir("critical-log");
    let search = |log: &std::path::Path, duration: &str| -> Vec<String> {
        vec![
            "critical".into(),
            "--json".into(),
            "--no-progress".into(),
            "--mu".into(),
            "0.3,0.4".into(),
            "--from".into(),
            "2000".into(),
            "--to".into(),
            "12000".into(),
            "--resolution-rpm".into(),
            "500".into(),
            "--tol-rpm".into(),
            "62.5".into(),
            "--duration-s".into(),
            duration.into(),
            "--log".into(),
            s(log).into(),
        ]
    };
    let lines = |p: &std::path::Path| std::fs::read_to_string(p).unwrap().lines().count();

    // Uninterrupted: every classified drop is one line.
    let full_log = dir.join("full.jsonl");
    let full = whirlmap(&search(&full_log, "1"));
    assert!(full.status.success(), "{}", stderr(&full));
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&full.stdout).unwrap();
    let drops: u64 = rows.iter().map(|r| r["drops"].as_u64().unwrap()).sum();
    assert_eq!(lines(&full_log) as u64, drops);
    assert!(
        stderr(&full).contains("0 drops reused"),
        "{}",
        stderr(&full)
    );

    // Killed after ten drops, then run again: the same rows, the rest of the drops run.
    let log = dir.join("killed.jsonl");
    let held = kill_after_lines(&search(&log, "1"), &log, 10);
    assert!((held as u64) < drops, "{held} of {drops}");
    let resumed = whirlmap(&search(&log, "1"));
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert!(resumed.stdout == full.stdout, "resumed rows differ");
    assert!(
        stderr(&resumed).contains(&format!("{held} drops reused")),
        "{held}: {}",
        stderr(&resumed)
    );
    assert_eq!(lines(&log) as u64, drops);

    // Run again: every drop from the log, nothing appended.
    let before = std::fs::read(&full_log).unwrap();
    let again = whirlmap(&search(&full_log, "1"));
    assert!(again.stdout == full.stdout);
    assert!(stderr(&again).contains(&format!("{drops} drops reused")));
    assert_eq!(std::fs::read(&full_log).unwrap(), before);

    // The rows come from the log: a class changed in it changes them.
    let text = String::from_utf8(before.clone()).unwrap();
    let marked = text.replacen("\"class\":\"pendulum\"", "\"class\":\"backward_whirl\"", 1);
    assert_ne!(marked, text, "the search has a pendulum drop");
    let marked_log = dir.join("marked.jsonl");
    std::fs::write(&marked_log, marked).unwrap();
    let fooled = whirlmap(&search(&marked_log, "1"));
    assert!(fooled.status.success(), "{}", stderr(&fooled));
    assert!(fooled.stdout != full.stdout, "the marked line was not used");

    // The CSV written to the log's own path (also as another spelling of it): refused
    // before any drop, the log untouched.
    for csv in [
        full_log.clone(),
        dir.join("sub").join("..").join("full.jsonl"),
    ] {
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let mut args = search(&full_log, "1");
        args.extend(["--csv".to_string(), s(&csv).to_string()]);
        let clash = whirlmap(&args);
        assert_eq!(clash.status.code(), Some(2), "{}", stderr(&clash));
        assert!(
            stderr(&clash).contains("would replace the drop log"),
            "{}",
            stderr(&clash)
        );
        assert_eq!(std::fs::read(&full_log).unwrap(), before);
    }
    // A first run, the log not there yet, named two ways: refused, no file made.
    let fresh = dir.join("fresh.jsonl");
    let mut args = search(&fresh, "1");
    let other_spelling = dir.join("sub").join("..").join("fresh.jsonl");
    args.extend(["--csv".to_string(), s(&other_spelling).to_string()]);
    let clash = whirlmap(&args);
    assert_eq!(clash.status.code(), Some(2), "{}", stderr(&clash));
    assert!(!fresh.exists());

    // Another drop length: nothing to reuse.
    let other = whirlmap(&search(&full_log, "0.5"));
    assert!(other.status.success(), "{}", stderr(&other));
    assert!(
        stderr(&other).contains("0 drops of this --duration-s and build to reuse"),
        "{}",
        stderr(&other)
    );

    // Not a drop log: refused before any drop, the file untouched.
    let csv = dir.join("notes.csv");
    std::fs::write(&csv, "speed,class\n6000,whirl\n").unwrap();
    let refused = whirlmap(&search(&csv, "1"));
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert!(
        stderr(&refused).contains("is not a critical-search drop log (line 1"),
        "{}",
        stderr(&refused)
    );
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "speed,class\n6000,whirl\n"
    );
    // A one-line file without its newline (a scene named by mistake): refused, untouched.
    let scene = dir.join("scene.json");
    std::fs::write(&scene, r#"{"speed_rpm": 8000, "mu_dynamic": 0.3}"#).unwrap();
    let refused = whirlmap(&search(&scene, "1"));
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    assert_eq!(
        std::fs::read_to_string(&scene).unwrap(),
        r#"{"speed_rpm": 8000, "mu_dynamic": 0.3}"#
    );
    // A torn line of the log itself is cut, and the search is the full one.
    let torn = dir.join("torn.jsonl");
    let mut text = String::from_utf8(before.clone()).unwrap();
    text.push_str(r#"{"mu":0.4,"speed_rpm":60"#);
    std::fs::write(&torn, text).unwrap();
    let again = whirlmap(&search(&torn, "1"));
    assert!(again.stdout == full.stdout, "{}", stderr(&again));
    assert!(stderr(&again).contains(&format!("{drops} drops reused")));
    assert_eq!(lines(&torn) as u64, drops);
    // A directory is a bad path (exit 2), not a failed disk.
    let refused = whirlmap(&search(&dir, "1"));
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    let _ = std::fs::remove_dir_all(&dir);
}
