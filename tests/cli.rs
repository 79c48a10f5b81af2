//! End-to-end tests of the `whirlmap` binary: the JSON contract, bad input, scene files and
//! charts.

mod common;
use common::*;

#[test]
fn json_output_parses_and_carries_every_contract_field() {
    let out = whirlmap(&[
        "drop",
        "--speed-rpm",
        "8000",
        "--mu",
        "0.3",
        "--duration-s",
        "0.05",
        // Exactly 0.05 s: the classifier's extension off.
        "--set",
        "classification.max_extension_s=0",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    for key in [
        "class",
        "class_reason",
        "transient_whirl_turns",
        "extension_s",
        "first_contact_force_n",
        "max_contact_force_n",
        "peak_friction_power_w",
        "peak_heat_power_w",
        "whirl_frequency_hz",
        "contact_duty",
        "impacts",
        "end_time_s",
        "stop_reason",
        "energy",
        "stats",
        "scene_hash",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    for key in [
        "initial_j",
        "final_j",
        "friction_heat_j",
        "damping_loss_j",
        "drag_work_j",
        "residual_rel",
    ] {
        assert!(v["energy"][key].is_number(), "energy.{key}");
    }
    for key in ["rhs_evals", "steps", "rejected", "events"] {
        assert!(v["stats"][key].is_u64(), "stats.{key}");
    }
    let class = v["class"].as_str().unwrap();
    assert!(
        [
            "pendulum",
            "bouncing",
            "backward_whirl",
            "forward_whirl",
            "unresolved"
        ]
        .contains(&class),
        "{class}"
    );
    assert_eq!(v["stop_reason"], "duration_reached");
    assert!((v["end_time_s"].as_f64().unwrap() - 0.05).abs() < 1e-12);
    assert!(v["first_contact_force_n"].as_f64().unwrap() > 500.0);
    assert_eq!(v["scene_hash"].as_str().unwrap().len(), 16);
    // 0.05 s is too short for the final window to settle: said, not hidden.
    assert_eq!(v["class"], "unresolved");
    assert_eq!(v["extension_s"], 0.0);
}

#[test]
fn a_drop_that_has_not_settled_is_extended_until_its_class_is_decided() {
    let out = whirlmap(&[
        "drop",
        "--speed-rpm",
        "8000",
        "--mu",
        "0.1",
        "--duration-s",
        "0.05",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    assert_eq!(v["class"], "pendulum", "{v}");
    assert_eq!(v["class_reason"], "settled_rocking");
    let (end, ext) = (
        v["end_time_s"].as_f64().unwrap(),
        v["extension_s"].as_f64().unwrap(),
    );
    assert!(ext > 0.0 && (end - 0.05 - ext).abs() < 1e-12, "{end} {ext}");
    // The human summary says so.
    let out = whirlmap(&[
        "drop",
        "--speed-rpm",
        "8000",
        "--mu",
        "0.1",
        "--duration-s",
        "0.05",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("extended by"), "{text}");
    assert!(text.contains("pendulum vibration"), "{text}");
}

#[test]
fn bad_input_exits_2_naming_field_value_and_range() {
    let cases: &[(&[&str], &[&str])] = &[
        (&["--mu", "2.5"], &["--mu = 2.5", "mu_dynamic", "[0, 2]"]),
        (&["--mu", "-0.1"], &["mu_dynamic", "-0.1"]),
        (&["--mu", "NaN"], &["mu_dynamic", "NaN"]),
        (&["--duration-s", "0"], &["--duration-s = 0", "(0, 3600]"]),
        (&["--duration-s", "-1"], &["--duration-s = -1"]),
        (&["--mu", "abc"], &["--mu", "abc", "not a number", "[0, 2]"]),
        (
            &["--speed-rpm", "fast"],
            &["--speed-rpm", "fast", "[-1e6, 1e6] r/min"],
        ),
        (
            &["--duration-s", "1s"],
            &["--duration-s", "1s", "(0, 3600] s"],
        ),
        (
            &["--set", "rotor_mass_kg=0"],
            &["rotor_mass_kg", "0", "[1e-3, 1e6] kg"],
        ),
        (&["--set", "race_mass_kg=-1"], &["race_mass_kg", "-1"]),
        (&["--set", "clearance_m=0"], &["clearance_m", "(0, 0.1]"]),
        (
            &["--set", "contact_stiffness_n_per_m_e=-5"],
            &["contact_stiffness_n_per_m_e", "-5"],
        ),
        (
            &["--set", "support_stiffness_n_per_m_e=0"],
            &["support_stiffness_n_per_m_e"],
        ),
        (&["--set", "no_such_key=1"], &["no_such_key", "unknown"]),
        (&["--set", "rotor_mass_kg=heavy"], &["rotor_mass_kg"]),
        (
            &["--scene", "/nonexistent/scene.json"],
            &["/nonexistent/scene.json"],
        ),
        (&["--orbit", "chart.pdf"], &[".png or .svg"]),
    ];
    for (args, needles) in cases {
        let mut full = vec!["drop"];
        full.extend_from_slice(args);
        let out = whirlmap(&full);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        for n in *needles {
            assert!(err.contains(n), "{args:?}: message `{err}` lacks `{n}`");
        }
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    }
}

#[test]
fn scene_file_with_unknown_key_reports_line_and_column() {
    let p = temp_path("typo.json");
    std::fs::write(
        &p,
        "{\n  \"speed_rpm\": 5000,\n  \"clearence_m\": 1e-4\n}\n",
    )
    .unwrap();
    let out = whirlmap(&["drop", "--scene", p.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("clearence_m") && err.contains("line 3"),
        "{err}"
    );
    assert!(err.contains("did you mean `clearance_m`?"), "{err}");
}

/// A 0.02 s drop of the scene file `p`, as JSON.
fn short_drop_from(p: &std::path::Path) -> std::process::Output {
    whirlmap(&[
        "drop",
        "--scene",
        p.to_str().unwrap(),
        "--duration-s",
        "0.02",
        "--json",
    ])
}

#[test]
fn scene_prints_every_field_the_schema_lists_and_the_schema_says_units_and_ranges() {
    let scene: serde_json::Value = serde_json::from_slice(&whirlmap(&["scene"]).stdout).unwrap();
    let schema_out = whirlmap(&["scene", "--schema"]);
    assert!(schema_out.status.success());
    let schema: serde_json::Value = serde_json::from_slice(&schema_out.stdout).unwrap();
    let printed: Vec<&String> = scene.as_object().unwrap().keys().collect();
    let listed: Vec<&String> = schema["properties"].as_object().unwrap().keys().collect();
    let mut a = printed.clone();
    let mut b = listed.clone();
    a.sort();
    b.sort();
    assert_eq!(a, b, "`whirlmap scene` and its schema list the same fields");
    for optional in [
        "release_offset_m",
        "stop_speed_rpm",
        "thermal",
        "quasi_static_race",
    ] {
        assert!(scene.get(optional).is_some(), "{optional} not printed");
    }
    assert!(
        scene["thermal"].is_null(),
        "the thermal model is off by default"
    );
    let rpm = &schema["properties"]["speed_rpm"];
    assert_eq!(rpm["x-unit"], "r/min");
    assert_eq!(rpm["maximum"], 1e6);
    assert_eq!(rpm["default"], 8000.0);
    let all: serde_json::Value =
        serde_json::from_slice(&whirlmap(&["scene", "--all"]).stdout).unwrap();
    assert_eq!(all["thermal"]["ambient_temperature_k"], 293.15);
    // every printed field is accepted back: the full file is the default scene
    let p = temp_path("full-scene.json");
    std::fs::write(&p, serde_json::to_string(&scene).unwrap()).unwrap();
    let a = short_drop_from(&p);
    let b = whirlmap(&["drop", "--duration-s", "0.02", "--json"]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn printed_scene_round_trips_through_a_scene_file() {
    let out = whirlmap(&["scene"]);
    assert!(out.status.success());
    let mut v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["clearance_m"], 0.00015);
    v["speed_rpm"] = serde_json::json!(3000.0);
    let p = temp_path("scene.json");
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    let a = short_drop_from(&p);
    let b = whirlmap(&[
        "drop",
        "--speed-rpm",
        "3000",
        "--duration-s",
        "0.02",
        "--json",
    ]);
    assert!(a.status.success() && b.status.success());
    assert_eq!(
        a.stdout, b.stdout,
        "scene file and flags give the same drop"
    );
}

#[test]
fn orbit_option_draws_a_well_formed_svg() {
    let p = temp_path("orbit.svg");
    let out = whirlmap(&[
        "drop",
        "--mu",
        "0.2",
        "--duration-s",
        "0.03",
        "--orbit",
        p.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&p).unwrap();
    assert!(svg.contains("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("contact force"));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("class") && text.contains("first contact force"),
        "{text}"
    );
}

#[test]
fn commands_refuse_a_folder_that_holds_results_without_overwrite() {
    let dir = temp_path("held");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("accuracy.md"), "kept").unwrap();
    for args in [
        vec!["accuracy", "--out", dir.to_str().unwrap()],
        vec![
            "ensemble",
            "sweeps/ensemble-smoke.json",
            "--out",
            dir.to_str().unwrap(),
        ],
    ] {
        let out = whirlmap(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("already holds results") && err.contains("--overwrite"),
            "{err}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("accuracy.md")).unwrap(),
            "kept"
        );
    }
}

#[test]
fn an_unwritable_chart_path_is_refused_in_a_sentence_before_the_drop_runs() {
    let out = whirlmap(&["drop", "--orbit", "/nonexistent-folder/x.png", "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{err}");
    assert!(
        err.contains("cannot write chart /nonexistent-folder/x.png: the folder /nonexistent-folder does not exist"),
        "{err}"
    );
    assert!(!err.contains("Os {"), "no error dump: {err}");
    assert!(out.stdout.is_empty(), "nothing was simulated or printed");
    // A file where the folder should be is named as such.
    let file = temp_path("a-file");
    std::fs::write(&file, "").unwrap();
    let chart = file.join("x.png");
    let out = whirlmap(&["drop", "--orbit", s(&chart), "--json"]);
    assert_eq!(out.status.code(), Some(4), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(&format!("{} is a file, not a folder", file.display())),
        "{}",
        stderr(&out)
    );
    let _ = std::fs::remove_file(&file);
}

#[test]
fn a_stop_speed_at_or_above_the_release_speed_is_refused() {
    let o = whirlmap(&[
        "drop",
        "--duration-s",
        "0.05",
        "--set",
        "stop_speed_rpm=9000",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("invalid stop_speed_rpm = 9000")
            && err.contains("below the release speed |speed_rpm| = 8000"),
        "{err}"
    );
    assert!(o.stdout.is_empty(), "nothing simulated: {}", out(&o));
}

#[test]
fn bench_refuses_zero_repetitions_and_its_help_says_fastest() {
    let o = whirlmap(&["bench", "--reps", "0"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--reps") && err.contains("allowed >= 1"),
        "{err}"
    );
    assert!(o.stdout.is_empty(), "nothing timed: {}", out(&o));
    let help = out(&whirlmap(&["bench", "--help"]));
    assert!(
        help.contains("fastest") && !help.contains("median"),
        "{help}"
    );
}

#[test]
fn accuracy_messages_appear_once_and_an_empty_case_list_is_refused() {
    let dir = temp_dir("accuracy-input");
    let missing = dir.join("missing.json");
    let o = whirlmap(&[
        "accuracy",
        "--cases",
        s(&missing),
        "--out",
        s(&dir.join("o1")),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("missing.json"), "{err}");
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    let bad = spec_file(
        &dir,
        "bad",
        r#"{"rtol": [1e-4], "cases": [{"name": "a", "scene": {"clearence_m": 1e-4}}], "settings": []}"#,
    );
    let o = whirlmap(&["accuracy", "--cases", s(&bad), "--out", s(&dir.join("o2"))]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cases[0].scene") && err.contains("clearance_m"),
        "{err}"
    );
    assert_eq!(err.matches("known:").count(), 1, "{err}");
    let empty = spec_file(
        &dir,
        "empty",
        r#"{"rtol": [1e-4], "cases": [], "settings": []}"#,
    );
    let out_dir = dir.join("o3");
    let o = whirlmap(&["accuracy", "--cases", s(&empty), "--out", s(&out_dir)]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cases = []: allowed at least one case"),
        "{err}"
    );
    assert!(!out_dir.exists(), "nothing written");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A flag that asks for a model and a `--set` that switches it off: refused (exit 2) before
/// the drop, not a drop without the model that claims a chart it did not draw.
#[test]
fn a_flag_and_a_set_that_switch_a_model_both_ways_are_refused() {
    let chart = temp_path("temperatures.png");
    for (args, flag) in [
        (
            vec!["--temperatures", s(&chart), "--set", "thermal=null"],
            "--temperatures",
        ),
        (vec!["--thermal", "--set", "thermal=null"], "--thermal"),
        (vec!["--bearing", "--set", "bearing=null"], "--bearing"),
    ] {
        let mut all = vec!["drop", "--duration-s", "0.05"];
        all.extend(args);
        let o = whirlmap(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {}", out(&o));
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
        assert!(o.stdout.is_empty(), "{all:?} ran: {}", out(&o));
    }
    assert!(!chart.exists());
}

/// `RAYON_NUM_THREADS` beyond the `--threads` range is refused (exit 2) before any work by a
/// command that would start that many threads (one without `--threads`); a command that starts
/// none, or is given `--threads`, runs.
#[test]
fn a_thread_count_from_the_environment_beyond_the_range_is_refused() {
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_whirlmap"))
            .args(args)
            .env("RAYON_NUM_THREADS", "99999")
            .output()
            .unwrap()
    };
    let o = run(&["critical", "--mu", "0.4", "--from", "6000", "--to", "7000"]);
    assert_eq!(o.status.code(), Some(2), "{}", out(&o));
    assert!(stderr(&o).contains("RAYON_NUM_THREADS = 99999: allowed [1, 4096]"));
    assert!(o.stdout.is_empty());
    let o = run(&["drop", "--duration-s", "0.01"]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
    let o = run(&["scene"]);
    assert_eq!(o.status.code(), Some(0), "{}", out(&o));
}

/// A number flag given text of the wrong kind is refused (exit 2) naming the flag, the text and
/// the flag's allowed range, before any work; a bound another flag sets is named by that flag.
#[test]
fn number_flags_given_text_name_their_range() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["critical", "--mu", "0.1,x"],
            "'x' for '--mu <MU>': not a number; allowed [0, 2]",
        ),
        (
            &["critical", "--mu", "0.1", "--from", "low"],
            "'low' for '--from <FROM>': not a number; allowed [0, 1e6) r/min",
        ),
        (
            &["critical", "--mu", "0.1", "--to", "high"],
            "not a number; allowed (--from, 1e6] r/min",
        ),
        (
            &["critical", "--mu", "0.1", "--tol-rpm", "fine"],
            "not a number; allowed [0.01, --resolution-rpm] r/min",
        ),
        (
            &["sweep", "sweeps/paper.json", "--threads", "two"],
            "'two' for '--threads <THREADS>': not a whole number; allowed [1, 4096]",
        ),
        (
            &["sweep", "sweeps/paper.json", "--threads", "-1"],
            "-1 is out of range; allowed [1, 4096]",
        ),
        (
            &["sweep", "sweeps/paper.json", "--threads", "0"],
            "0 is out of range; allowed [1, 4096]",
        ),
        (
            &["compare", "a", "b", "--force-rel", "tight"],
            "'tight' for '--force-rel <FORCE_REL>': not a number; allowed [0, inf)",
        ),
    ];
    for (args, needle) in cases {
        let o = whirlmap(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", out(&o));
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{args:?} ran: {}", out(&o));
    }
}
