//! End-to-end tests of `whirlmap critical`: a real search on the default scene, and bad
//! input rejected with exit code 2 before any drop runs.

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
    // The reproducer in small: before the lattice, the bracket moved with the range.
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
