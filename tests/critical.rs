//! End-to-end tests of `whirlmap critical`: a real search on the default scene, and bad
//! input rejected with exit code 2 before any drop runs.

mod common;
use common::*;

#[test]
fn default_scene_at_mu_0_4_has_a_narrow_backward_whirl_bracket() {
    // About 13 drops, under a second in the optimised test profile.
    let out = whirlmap(&[
        "critical",
        "--mu",
        "0.4",
        "--from",
        "2000",
        "--to",
        "12000",
        "--tol-rpm",
        "500",
        "--duration-s",
        "0.5",
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    let results = v["results"].as_array().expect("results array");
    assert_eq!(results.len(), 1);
    let r = &results[0];
    assert_eq!(r["mu"], 0.4);
    let bracket = r["bracket"].as_array().expect("a bracket exists");
    let (lo, hi) = (bracket[0].as_f64().unwrap(), bracket[1].as_f64().unwrap());
    assert!(2000.0 <= lo && lo < hi && hi <= 12000.0, "{lo} {hi}");
    assert!(hi - lo <= 500.0, "{lo} {hi}");
    assert_eq!(r["class_hi"], "backward_whirl");
    assert_eq!(r["converged"], true);
    let drops = r["drops_used"].as_u64().unwrap();
    assert!((12..=20).contains(&drops), "drops_used {drops}");
    assert_eq!(r["scanned"].as_array().unwrap().len(), 12);
    assert!(r["note"].as_str().is_some_and(|n| !n.is_empty()));
    assert_eq!(v["tol_rpm"], 500.0);
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
        "--scan-points",
        "2",
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
        "bracket",
        "drops used",
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
