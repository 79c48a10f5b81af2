//! End-to-end tests of the fidelity presets and the `accuracy` command.

mod common;
use common::*;

fn record(args: &[&str]) -> serde_json::Value {
    let out = whirlmap(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

#[test]
fn draft_is_cheaper_and_close_on_the_first_impact_and_a_bad_preset_exits_2() {
    let base = ["drop", "--duration-s", "0.02", "--json"];
    let plain = record(&base);
    let standard = record(&[&base[..], &["--fidelity", "standard"]].concat());
    let draft = record(&[&base[..], &["--fidelity", "draft"]].concat());
    // `standard` is the scene default: the very same record.
    assert_eq!(plain, standard);
    let evals = |v: &serde_json::Value| v["stats"]["rhs_evals"].as_u64().unwrap();
    assert!(
        evals(&draft) < evals(&standard),
        "{} vs {}",
        evals(&draft),
        evals(&standard)
    );
    // The first impact agrees within the accuracy budget (0.1 %) at both presets: `draft`'s
    // worst first-impact error over the work-precision study's cases is 4.5e-5.
    let reference = record(&[&base[..], &["--fidelity", "reference"]].concat());
    let f = |v: &serde_json::Value| v["first_contact_force_n"].as_f64().unwrap();
    let rel = |a: &serde_json::Value| ((f(a) - f(&reference)) / f(&reference)).abs();
    assert!(
        rel(&draft) < 1e-3,
        "draft first impact off by {}",
        rel(&draft)
    );
    assert!(
        rel(&standard) < 1e-3,
        "standard first impact off by {}",
        rel(&standard)
    );
    assert!(evals(&standard) < evals(&reference));

    let out = whirlmap(&["drop", "--fidelity", "fast"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("fast") && err.contains("draft, standard, reference"),
        "{err}"
    );
}

/// A preset sets the numerics after `--set`: a `--set` of one of its keys has no effect, and
/// standard error says so (for `drop` and for `critical`); a `--set` of anything else is
/// kept, without a word. The text summary names the numerics a drop ran with.
#[test]
fn a_preset_says_which_set_values_it_replaces() {
    let base = ["drop", "--duration-s", "0.02", "--fidelity", "draft"];
    fn json<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        [base, extra, &["--json"]].concat()
    }
    let draft = record(&json(&base, &[]));
    let out = whirlmap(&json(&base, &["--set", "solver.rtol=1e-6"]));
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "warning: --fidelity draft sets the numerics, so --set solver.rtol=1e-6 has no effect"
        ),
        "{err}"
    );
    let overridden: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(overridden, draft);
    let out = whirlmap(&json(&base, &["--set", "unbalance_m=1e-6"]));
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    // A whole solver section: only the preset's keys in it are replaced, and named.
    let out = whirlmap(&json(&base, &["--set", r#"solver={"max_events":100000}"#]));
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    let out = whirlmap(&json(
        &base,
        &["--set", r#"solver={"max_events":100000,"rtol":1e-6}"#],
    ));
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("so rtol of --set solver="), "{err}");
    let kept: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_ne!(kept["scene_hash"], draft["scene_hash"]);
    let out = whirlmap(&base);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains(
            "numerics              rodas4_bdf, rtol 1e-4, race tolerance x1000 (the draft preset)"
        ),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = whirlmap(&[
        "critical",
        "--mu",
        "0.1",
        "--from",
        "2000",
        "--to",
        "3000",
        "--resolution-rpm",
        "1000",
        "--duration-s",
        "0.05",
        "--fidelity",
        "draft",
        "--set",
        "quasi_static_race=true",
        "--no-progress",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--set quasi_static_race=true has no effect"),
        "{err}"
    );
}

/// A sweep file's `fidelity` replaces the keys of it that its `scene` sets: standard error
/// names each, and the sweep runs at the preset's numerics. An axis is applied after the
/// preset, so a value given there is kept, without a word.
#[test]
fn a_sweep_file_says_which_scene_values_its_preset_replaces() {
    let dir = temp_dir("spec-preset");
    let spec = |name: &str, scene: &str, axes: &str| {
        let text = format!(
            r#"{{"name": "{name}", "fidelity": "draft", "duration_s": 0.02, "scene": {scene},
                "axes": {{"speed_rpm": [2000], "mu": [0.1]{axes}}}}}"#
        );
        spec_file(&dir, name, &text)
    };
    let run = |file: &std::path::Path| {
        let out_dir = dir.join(file.file_stem().unwrap());
        let out = whirlmap(&["sweep", s(file), "--out", s(&out_dir), "--no-progress"]);
        assert!(out.status.success(), "{}", stderr(&out));
        let line = std::fs::read_to_string(out_dir.join("points.jsonl")).unwrap();
        let rec: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
        // The manifest gives the numerics the preset set beside the spec's own scene.
        let manifest = read_json(&out_dir.join("manifest.json"));
        let preset = &manifest["preset_solver"];
        assert_eq!(preset["rtol"], 1e-4, "{manifest}");
        assert_eq!(preset["method"], "rodas4_bdf", "{manifest}");
        assert_eq!(preset["race_atol_scale"], 1000.0, "{manifest}");
        assert_eq!(
            preset["max_step_attempts"], 100000,
            "the file's other keys stay"
        );
        (stderr(&out), rec["scene_hash"].clone())
    };
    let replaced = spec(
        "replaced",
        r#"{"solver": {"rtol": 1e-6, "max_step_attempts": 100000}}"#,
        "",
    );
    let (err, hash_replaced) = run(&replaced);
    assert!(
        err.contains("fidelity draft sets the numerics, so scene.solver.rtol = 1e-6 has no effect"),
        "{err}"
    );
    assert!(!err.contains("max_step_attempts"), "{err}");
    let (err, hash_plain) = run(&spec(
        "plain",
        r#"{"solver": {"max_step_attempts": 100000}}"#,
        "",
    ));
    assert!(!err.contains("warning"), "{err}");
    assert_eq!(
        hash_replaced, hash_plain,
        "the file's rtol was not replaced"
    );
    let (err, hash_axis) = run(&spec(
        "axis",
        r#"{"solver": {"max_step_attempts": 100000}}"#,
        r#", "solver.rtol": [1e-6]"#,
    ));
    assert!(!err.contains("warning"), "{err}");
    assert_ne!(hash_axis, hash_plain, "an axis is applied after the preset");
}

#[test]
fn accuracy_writes_its_table_and_charts() {
    let dir = std::env::temp_dir().join(format!("whirlmap-acc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = dir.join("cases.json");
    std::fs::write(
        &cases,
        r#"{"name": "t", "duration_s": 0.01, "reference_rtol": 1e-8, "rtol": [1e-4],
            "cases": [{"name": "pendulum", "scene": {"mu_dynamic": 0.1}}],
            "settings": [{"name": "full"}]}"#,
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = whirlmap(&[
        "accuracy",
        "--cases",
        cases.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "accuracy.csv",
        "accuracy.md",
        "work_precision.png",
        "work_precision.svg",
    ] {
        assert!(out_dir.join(f).exists(), "{f} missing");
    }
    let csv = std::fs::read_to_string(out_dir.join("accuracy.csv")).unwrap();
    // One ladder row and three preset rows, each ok.
    assert_eq!(
        csv.lines().filter(|l| l.contains(",ok,")).count(),
        4,
        "{csv}"
    );
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"rtol": [0.5], "cases": [], "settings": []}"#).unwrap();
    let out = whirlmap(&["accuracy", "--cases", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));

    // `--charts-only` draws the charts again from study.json alone: with the table and the
    // charts gone, only the charts come back.
    for f in [
        "accuracy.csv",
        "work_precision.png",
        "work_precision_wall.svg",
    ] {
        std::fs::remove_file(out_dir.join(f)).unwrap();
    }
    let charts_only = |cases: &std::path::Path| {
        whirlmap(&[
            "accuracy",
            "--cases",
            cases.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--charts-only",
        ])
    };
    let out = charts_only(&cases);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out_dir.join("work_precision.png").exists());
    assert!(out_dir.join("work_precision_wall.svg").exists());
    assert!(!out_dir.join("accuracy.csv").exists(), "no drop ran");
    // Another study's cases file is refused, naming both.
    let other = dir.join("other.json");
    std::fs::write(
        &other,
        r#"{"name": "o", "rtol": [1e-4], "cases": [{"name": "whirl", "scene": {}}],
            "settings": [{"name": "full"}]}"#,
    )
    .unwrap();
    let out = charts_only(&other);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("[pendulum]") && err.contains("[whirl]"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
