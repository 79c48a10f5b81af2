//! A results folder is a record: complete, or the tool says loudly that it is not. End-to-end
//! tests of what must never exit 0 with wrong results, one test per failure: each runs the
//! binary the way a user would and checks the exit code, the message and the files.

mod common;
use common::*;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A grid of four short drops (the classifier's extension off, so each is 0.05 s).
const TINY: &str = r#"{"name": "tiny", "scene": {"classification": {"max_extension_s": 0}},
  "duration_s": 0.05, "axes": {"speed_rpm": [4000, 8000], "mu": [0.1, 0.3]}}"#;

/// Sixteen slow drops on one thread: a sweep that is still running a second after it started.
const SLOW: &str = r#"{"name": "slow", "scene": {"solver": {"rtol": 1e-9}},
  "duration_s": 1.0, "axes": {"speed_rpm": [2000, 4000, 6000, 8000], "mu": [0.1, 0.2, 0.3, 0.4]}}"#;

/// A sweep with a small critical search and its Fig. 4, whose drops are extended until they
/// settle (an unresolved drop below an onset, or without one, would leave it undecided:
/// exit 1).
const WITH_CRITICAL: &str = r#"{"name": "withcrit",
  "duration_s": 0.05, "axes": {"speed_rpm": [4000, 8000], "mu": [0.1, 0.3]},
  "critical": {"mu": [0.4], "speed_rpm": {"from": 2000, "to": 4000},
               "resolution_rpm": 1000, "tol_rpm": 500},
  "charts": ["critical", "classes"]}"#;

/// [`TINY`] drawing `charts` (a JSON list).
fn tiny_with_charts(charts: &str) -> String {
    let body = TINY.trim_end().strip_suffix('}').unwrap();
    format!("{body}, \"charts\": {charts}}}")
}

fn sweep(spec: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["sweep", s(spec), "--out", s(out), "--no-progress"];
    args.extend_from_slice(extra);
    whirlmap(&args)
}

fn out_text(o: &std::process::Output) -> String {
    out(o)
}

fn spawn_sweep(spec: &Path, out: &Path, extra: &[&str]) -> Child {
    Command::new(BIN)
        .args([
            "sweep",
            s(spec),
            "--out",
            s(out),
            "--no-progress",
            "--threads",
            "1",
        ])
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Waits until `ready` holds (the child still running), at most 30 s.
fn wait_until(child: &mut Child, what: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before {what}"
        );
        assert!(start.elapsed() < Duration::from_secs(30), "no {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn manifest_names(out: &Path, name: &str) -> bool {
    std::fs::read_to_string(out.join("manifest.json"))
        .is_ok_and(|t| t.contains(&format!("\"name\": \"{name}\"")))
}

/// Runs `whirlmap` with standard output a pipe nobody reads (closed before it starts).
fn closed_stdout(args: &[&str]) -> std::process::Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let child = Command::new(BIN)
        .args(args)
        .stdout(writer)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.wait_with_output().unwrap()
}

/// Help and version that cannot be written (a full disk behind `>`) exit 4, as every other
/// output that cannot be written does; a usage error keeps its exit 2.
#[test]
fn help_that_cannot_be_written_is_not_exit_0() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // not on this system
    };
    for args in [&["--help"][..], &["sweep", "--help"], &["--version"]] {
        let o = Command::new(BIN)
            .args(args)
            .stdout(full.try_clone().unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(4), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("cannot write standard output"),
            "{}",
            stderr(&o)
        );
    }
    let o = whirlmap(&["no-such-command"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// The commit `whirlmap --version` names.
fn built_commit() -> String {
    let o = whirlmap(&["--version"]);
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    text.split("commit ")
        .nth(1)
        .and_then(|t| t.split(')').next())
        .unwrap_or_else(|| panic!("no commit in --version: {text}"))
        .to_string()
}

#[test]
fn a_second_writer_is_refused_and_a_killed_writer_leaves_no_lock() {
    let dir = temp_dir("lock");
    let (slow, tiny) = (spec_file(&dir, "slow", SLOW), spec_file(&dir, "tiny", TINY));
    let out = dir.join("out");
    let mut first = spawn_sweep(&slow, &out, &[]);
    wait_until(&mut first, "the run took its folder", || {
        manifest_names(&out, "slow")
    });
    // Another spec into the same folder, with or without --overwrite: refused, naming the
    // holder, and nothing of the first run's is touched.
    for extra in [&[][..], &["--overwrite"][..], &["--resume"][..]] {
        let o = sweep(&tiny, &out, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", out_text(&o));
        let err = stderr(&o);
        assert!(
            err.contains("in use by another whirlmap")
                && err.contains(&format!("pid {}", first.id())),
            "{err}"
        );
    }
    // So does a study or an ensemble told to overwrite the folder: nothing of the run's moves.
    let cases = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/accuracy-cases.json");
    let ens = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/ensemble-smoke.json");
    for args in [
        vec![
            "accuracy",
            "--cases",
            s(&cases),
            "--out",
            s(&out),
            "--overwrite",
        ],
        vec!["ensemble", s(&ens), "--out", s(&out), "--overwrite"],
    ] {
        let o = whirlmap(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", out_text(&o));
        assert!(stderr(&o).contains("in use"), "{}", stderr(&o));
        assert!(out.join("manifest.json").is_file() && !out.join("previous-run").exists());
    }
    // `render` waits its turn too.
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("in use"), "{}", stderr(&o));
    assert!(manifest_names(&out, "slow"));
    // kill -9 once a record is in: the operating system drops the lock, so the folder is free
    // at once, and what it left is said to be partial (a folder without a record has nothing
    // to draw: `runs_of_different_kinds_never_share_a_folder`).
    wait_until(&mut first, "the first record", || {
        std::fs::read(out.join("points.jsonl")).is_ok_and(|b| b.contains(&b'\n'))
    });
    first.kill().unwrap();
    first.wait().unwrap();
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(stderr(&o).contains("did not finish"), "{}", stderr(&o));
    assert_eq!(read_json(&out.join("manifest.json"))["complete"], false);
    let o = sweep(&tiny, &out, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let m = read_json(&out.join("manifest.json"));
    assert_eq!(m["spec"]["name"], "tiny");
    assert_eq!(m["complete"], true);
    let recs = std::fs::read_to_string(out.join("points.jsonl")).unwrap();
    assert_eq!(recs.lines().count(), 4, "{recs}");
    for l in recs.lines() {
        let v: Value = serde_json::from_str(l).expect("whole lines of one run");
        assert_eq!(v["duration_s"], 0.05);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn resume_refuses_an_edited_spec_and_says_what_changed() {
    let dir = temp_dir("resume-edited");
    let spec = spec_file(&dir, "tiny", TINY);
    let out = dir.join("out");
    let o = sweep(&spec, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let before = std::fs::read(out.join("points.jsonl")).unwrap();
    let cases = [
        (
            "a new duration",
            TINY.replace("0.05,", "0.04,"),
            "duration_s: 0.05 -> 0.04",
        ),
        (
            "a narrowed axis",
            TINY.replace("[0.1, 0.3]", "[0.1]"),
            "axes.mu: [0.1,0.3] -> [0.1]",
        ),
        (
            "reordered axes",
            TINY.replace(
                r#""speed_rpm": [4000, 8000], "mu": [0.1, 0.3]"#,
                r#""mu": [0.1, 0.3], "speed_rpm": [4000, 8000]"#,
            ),
            "axes: order speed_rpm, mu -> mu, speed_rpm",
        ),
    ];
    for (what, text, needle) in cases {
        assert_ne!(text, TINY, "{what}: the edit applies");
        let edited = spec_file(&dir, "edited", &text);
        let o = sweep(&edited, &out, &["--resume"]);
        assert_eq!(o.status.code(), Some(2), "{what}: {}", out_text(&o));
        let err = stderr(&o);
        assert!(
            err.contains("cannot resume") && err.contains(needle),
            "{what}: `{needle}` not in {err}"
        );
        assert!(
            std::fs::read(out.join("points.jsonl")).unwrap() == before,
            "{what}: records changed"
        );
    }
    // The same spec resumes (nothing left to run).
    let o = sweep(&spec, &out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("(4 resumed)"));
    assert!(std::fs::read(out.join("points.jsonl")).unwrap() == before);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_rerun_is_refused_and_an_overwrite_keeps_the_old_records_until_its_first_records() {
    let dir = temp_dir("rerun");
    let (tiny, slow) = (spec_file(&dir, "tiny", TINY), spec_file(&dir, "slow", SLOW));
    let out = dir.join("out");
    let o = sweep(&tiny, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let old = std::fs::read(out.join("points.jsonl")).unwrap();
    // Without --resume or --overwrite: refused, and the records stay.
    for spec in [&tiny, &slow] {
        let o = sweep(spec, &out, &[]);
        assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
        let err = stderr(&o);
        assert!(
            err.contains("holds the results of another run")
                && err.contains("--resume")
                && err.contains("--overwrite"),
            "{err}"
        );
        assert!(std::fs::read(out.join("points.jsonl")).unwrap() == old);
    }
    // An overwrite killed before its first records: the old records are kept aside.
    let mut child = spawn_sweep(&slow, &out, &["--overwrite"]);
    wait_until(&mut child, "the overwrite took its folder", || {
        manifest_names(&out, "slow")
    });
    child.kill().unwrap();
    child.wait().unwrap();
    let kept = out.join("previous-run/points.jsonl");
    assert!(
        std::fs::read(&kept).unwrap() == old,
        "the old records are not kept in previous-run/"
    );
    // Killed again before its first record: still kept (not replaced by the empty records).
    let started = read_json(&out.join("manifest.json"))["started_unix_s"].clone();
    let mut child = spawn_sweep(&slow, &out, &["--overwrite"]);
    // Its manifest is written once the folder is prepared (milliseconds); its first record
    // is a slow drop (about half a second) away.
    wait_until(
        &mut child,
        "the second overwrite prepared its folder",
        || {
            std::fs::read_to_string(out.join("manifest.json"))
                .ok()
                .and_then(|t| serde_json::from_str::<Value>(&t).ok())
                .is_some_and(|m| m["started_unix_s"] != started)
        },
    );
    assert!(child.try_wait().unwrap().is_none());
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(std::fs::read(&kept).unwrap() == old);
    // An overwrite that writes its records removes them.
    let o = sweep(&tiny, &out, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(!out.join("previous-run").exists());
    assert!(std::fs::read(out.join("points.jsonl")).unwrap() == old);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_owns_its_folder_and_stale_files_are_never_used() {
    let dir = temp_dir("stale");
    let a = spec_file(&dir, "a", WITH_CRITICAL);
    let b = spec_file(&dir, "b", &tiny_with_charts(r#"["classes"]"#));
    let out = dir.join("out");
    let o = sweep(&a, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let m = read_json(&out.join("manifest.json"));
    assert_eq!(m["complete"], true);
    let hash_a = m["spec_hash"].as_str().unwrap().to_string();
    for f in [
        "points.jsonl",
        "summary.csv",
        "critical.json",
        "critical.csv",
        "charts/fig4_critical.png",
        "charts/classes.svg",
    ] {
        assert!(m["files"][f]["fnv1a64"].is_string(), "{f} not listed: {m}");
    }
    let stale = dir.join("critical-of-a.json");
    std::fs::copy(out.join("critical.json"), &stale).unwrap();

    // Another spec without a critical search: the old critical.json and Fig. 4 are gone.
    let o = sweep(&b, &out, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let m = read_json(&out.join("manifest.json"));
    assert_ne!(m["spec_hash"].as_str().unwrap(), hash_a);
    for f in ["critical.json", "critical.csv", "charts/fig4_critical.png"] {
        assert!(
            !out.join(f).exists(),
            "{f} of the earlier spec is still there"
        );
    }
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(!String::from_utf8_lossy(&o.stdout).contains("fig4"));
    assert!(!out.join("charts/fig4_critical.png").exists());

    // A stale file put back is refused by render and compare, named.
    std::fs::copy(&stale, out.join("critical.json")).unwrap();
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(
        stderr(&o).contains("critical.json") && stderr(&o).contains("not written by the run"),
        "{}",
        stderr(&o)
    );
    assert!(!out.join("charts/fig4_critical.png").exists());
    let base = dir.join("base");
    let o = sweep(&b, &base, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let o = whirlmap(&["compare", s(&base), s(&out), "--out", s(&dir.join("c.md"))]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("critical.json"), "{}", stderr(&o));
    // A listed file changed after the run is refused too.
    std::fs::remove_file(out.join("critical.json")).unwrap();
    let mut text = std::fs::read_to_string(out.join("points.jsonl")).unwrap();
    text = text.replacen("\"status\":\"ok\"", "\"status\":\"failed\"", 1);
    std::fs::write(out.join("points.jsonl"), text).unwrap();
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("changed afterwards"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A user's files in `charts/` and `orbits/` are left alone: by `render`, which removes only
/// the stale charts of whirlmap's names, by `--overwrite`, which moves aside only whirlmap's
/// files, and by `--resume`, which makes the charts again. None of them is listed in the
/// manifest as the run's.
#[test]
fn a_users_files_in_charts_and_orbits_are_left_alone() {
    let dir = temp_dir("users-files");
    let spec_text = tiny_with_charts(r#"["classes", "orbits"]"#);
    let body = spec_text.trim_end().strip_suffix('}').unwrap();
    let spec = spec_file(
        &dir,
        "t",
        &format!(r#"{body}, "orbits": {{"speed_rpm": 4000, "mu": [0.3]}}}}"#),
    );
    let out = dir.join("out");
    let o = sweep(&spec, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let mine = [out.join("charts/my_plot.png"), out.join("orbits/notes.txt")];
    for f in &mine {
        std::fs::write(f, "mine").unwrap();
    }
    // A chart of whirlmap's name that this spec does not draw is stale: render removes it.
    std::fs::write(out.join("charts/fig5_max_force.png"), "old").unwrap();
    let kept = |when: &str| {
        for f in &mine {
            assert_eq!(
                std::fs::read_to_string(f).ok().as_deref(),
                Some("mine"),
                "{when}"
            );
        }
        let m = read_json(&out.join("manifest.json"));
        let files = m["files"].as_object().unwrap();
        assert!(files.contains_key("charts/classes.png"), "{when}: {m}");
        assert!(
            files
                .keys()
                .all(|k| !k.contains("my_plot") && !k.contains("notes")),
            "{when}: {m}"
        );
    };
    let o = whirlmap(&["render", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(!out.join("charts/fig5_max_force.png").exists());
    kept("render");
    let o = sweep(&spec, &out, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(!out.join("previous-run").exists());
    kept("--overwrite");
    let o = sweep(&spec, &out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    kept("--resume");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn huge_grids_are_refused_at_once() {
    let dir = temp_dir("huge");
    let cases = [
        (
            r#"{"from": 0, "to": 1, "steps": 18446744073709551615}"#,
            "18446744073709551615",
        ),
        (
            r#"{"from": 0, "to": 1, "steps": 10000000000}"#,
            "10000000000",
        ),
        (r#"{"from": 0, "to": 1, "steps": 1000000000}"#, "1000000000"),
    ];
    for (i, (axis, count)) in cases.iter().enumerate() {
        let spec = spec_file(
            &dir,
            &format!("h{i}"),
            &format!(r#"{{"name": "h", "duration_s": 0.05, "axes": {{"unbalance_m": {axis}}}}}"#),
        );
        let out_dir = dir.join(format!("out{i}"));
        let start = Instant::now();
        let o = whirlmap_within(
            &["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"],
            Duration::from_secs(20),
        )
        .unwrap_or_else(|| panic!("{axis}: still validating after 20 s"));
        assert_eq!(o.status.code(), Some(2), "{axis}: {}", out_text(&o));
        let err = stderr(&o);
        assert!(
            err.contains(count) && err.contains("at most 10000000 points"),
            "{axis}: {err}"
        );
        assert!(start.elapsed() < Duration::from_secs(5), "{axis}: slow");
        assert!(!out_dir.join("points.jsonl").exists());
    }
    // Two axes whose product overflows 64 bits.
    let spec = spec_file(
        &dir,
        "h-two",
        r#"{"name": "h", "duration_s": 0.05, "axes": {
            "speed_rpm": {"from": 0, "to": 1000, "steps": 18446744073709551615},
            "mu": {"from": 0, "to": 1, "steps": 4}}}"#,
    );
    let o = whirlmap_within(
        &["sweep", s(&spec), "--no-progress"],
        Duration::from_secs(20),
    )
    .expect("answers at once");
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(
        stderr(&o).contains("18446744073709551615 x 4"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn duplicate_grid_values_are_refused() {
    let dir = temp_dir("dups");
    let base = r#""name": "d", "duration_s": 0.05"#;
    let cases = [
        (
            r#""axes": {"mu": [0.1, 0.1, 0.2]}"#,
            "axes.mu: the value 0.1",
        ),
        (
            r#""axes": {"mu": {"from": 0.2, "to": 0.2, "steps": 3}}"#,
            "axes.mu: the value 0.2",
        ),
        (
            r#""axes": {"unbalance_m": [0.0, -0.0]}"#,
            "axes.unbalance_m: the value 0",
        ),
        (
            r#""axes": {"speed_rpm": {"from": 1000, "to": 1000.0000000001, "steps": 3}}"#,
            "axes.speed_rpm: the value 1000",
        ),
        (
            r#""axes": {"mu": [0.1]}, "critical": {"mu": [0.3, 0.3], "speed_rpm": {"from": 2000, "to": 4000}}"#,
            "critical.mu",
        ),
        (
            r#""axes": {"mu": [0.1]}, "orbits": {"speed_rpm": 8000, "mu": [0.1, 0.2, 0.1]}"#,
            "orbits.mu: the value 0.1",
        ),
    ];
    for (i, (body, needle)) in cases.iter().enumerate() {
        let spec = spec_file(&dir, &format!("d{i}"), &format!("{{{base}, {body}}}"));
        let out_dir = dir.join(format!("out{i}"));
        let o = sweep(&spec, &out_dir, &[]);
        assert_eq!(o.status.code(), Some(2), "{body}: {}", out_text(&o));
        assert!(
            stderr(&o).contains(needle),
            "{body}: `{needle}` not in {}",
            stderr(&o)
        );
        assert!(
            !out_dir.join("points.jsonl").exists(),
            "{body}: points were run"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn impossible_physics_is_refused_and_a_failed_energy_audit_fails_the_drop() {
    let short = [
        "--duration-s",
        "0.02",
        "--set",
        "classification.max_extension_s=0",
    ];
    let cases: &[(&str, &[&str])] = &[
        (
            "rotor_polar_moi_kg_m2=1e-300",
            &["rotor_polar_moi_kg_m2 = 1e-300", "gyration"],
        ),
        (
            "rotor_mass_kg=1e308",
            &["rotor_mass_kg = 1e308", "[1e-3, 1e6] kg"],
        ),
        (
            "pitch_diameter_m=1e-9",
            &["pitch_diameter_m = 1e-9", "race bore diameter"],
        ),
        // Table 4's k2 in N/mm^1.5, read as N/m^1.5.
        (
            "support_stiffness_n_per_m_e=2.47e5",
            &["support_stiffness_n_per_m_e", "N/mm^e"],
        ),
        // The exponent changed, the stiffness kept in the old unit.
        (
            "contact_exponent=2",
            &["contact_stiffness_n_per_m_e", "1 um"],
        ),
    ];
    for (set, needles) in cases {
        let mut args = vec!["drop", "--set", set];
        args.extend_from_slice(&short);
        let o = whirlmap(&args);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", out_text(&o));
        for n in *needles {
            assert!(stderr(&o).contains(n), "{set}: `{n}` not in {}", stderr(&o));
        }
    }
    // A valid scene whose books do not close (the race's absolute tolerance loosened 1e4-fold
    // with the explicit stepper, no spin: the friction heat comes out negative): a typed
    // failure, exit 3.
    let bad = [
        "--set",
        "solver.method=dopri5",
        "--set",
        "solver.rtol=1e-3",
        "--set",
        "solver.race_atol_scale=1e4",
        "--set",
        "classification.max_extension_s=0",
    ];
    let mut args = vec!["drop", "--speed-rpm", "0", "--duration-s", "0.2"];
    args.extend_from_slice(&bad);
    let o = whirlmap(&args);
    assert_eq!(o.status.code(), Some(3), "{}", out_text(&o));
    assert!(
        stderr(&o).contains("energy_audit") && stderr(&o).contains("above the threshold"),
        "{}",
        stderr(&o)
    );
    // The same drop with the race's tolerance not loosened passes, so the audit tells the two apart.
    let o = whirlmap(&[
        "drop",
        "--speed-rpm",
        "0",
        "--duration-s",
        "0.2",
        "--set",
        "solver.method=dopri5",
        "--set",
        "solver.race_atol_scale=1",
        "--set",
        "solver.race_velocity_atol_from_force=false",
        "--set",
        "classification.max_extension_s=0",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["energy"]["residual_rel"].as_f64().unwrap() < 1e-4, "{v}");
    // In a sweep, a failed point recorded with its kind; the sweep goes on (exit 1).
    let dir = temp_dir("audit");
    let spec = spec_file(
        &dir,
        "audit",
        r#"{"name": "audit", "duration_s": 0.2,
            "scene": {"speed_rpm": 0, "classification": {"max_extension_s": 0},
                      "solver": {"rtol": 1e-3, "method": "dopri5"}},
            "axes": {"solver.race_atol_scale": [1, 10000]}}"#,
    );
    let out_dir = dir.join("out");
    let o = sweep(&spec, &out_dir, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", out_text(&o));
    let recs: Vec<Value> = std::fs::read_to_string(out_dir.join("points.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(recs[0]["status"], "ok", "{}", recs[0]);
    assert_eq!(recs[1]["status"], "failed");
    assert_eq!(recs[1]["error"]["kind"], "energy_audit", "{}", recs[1]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn critical_ranges_are_checked_before_any_drop_and_named_readably() {
    let dir = temp_dir("critical-ranges");
    let cases = [
        (
            r#"{"from": 2000, "to": 1e308}"#,
            "",
            "critical.speed_rpm.to = 1e308",
        ),
        (
            r#"{"from": -5, "to": 4000}"#,
            "",
            "critical.speed_rpm.from = -5",
        ),
        (
            r#"{"from": 2000, "to": 4000}"#,
            r#", "tol_rpm": 1e-300"#,
            "critical.tol_rpm = 1e-300",
        ),
        (
            r#"{"from": 2000, "to": 4000}"#,
            r#", "resolution_rpm": 1e300"#,
            "critical.resolution_rpm = 1e300",
        ),
    ];
    for (i, (range, extra, needle)) in cases.iter().enumerate() {
        let spec = spec_file(
            &dir,
            &format!("c{i}"),
            &format!(
                r#"{{"name": "c", "duration_s": 0.05, "axes": {{"mu": [0.1]}},
                    "critical": {{"mu": [0.3], "speed_rpm": {range}{extra}}}}}"#
            ),
        );
        let out_dir = dir.join(format!("out{i}"));
        let o = sweep(&spec, &out_dir, &[]);
        assert_eq!(o.status.code(), Some(2), "{needle}: {}", out_text(&o));
        let err = stderr(&o);
        assert!(err.contains(needle), "`{needle}` not in {err}");
        assert!(err.len() < 400, "a number printed in full: {err}");
        assert!(!out_dir.join("points.jsonl").exists());
    }
    // A friction range of 2^64 - 1 values: refused, not a crash.
    let spec = spec_file(
        &dir,
        "cmu",
        r#"{"name": "c", "duration_s": 0.05, "axes": {"mu": [0.1]},
            "critical": {"mu": {"from": 0, "to": 1, "steps": 18446744073709551615},
                         "speed_rpm": {"from": 2000, "to": 4000}}}"#,
    );
    let o = whirlmap_within(
        &["sweep", s(&spec), "--no-progress"],
        Duration::from_secs(20),
    )
    .expect("answers at once");
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("critical.mu"), "{}", stderr(&o));
    // The command line says the same.
    let o = whirlmap(&["critical", "--mu", "0.3", "--to", "1e308"]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("--to = 1e308"), "{}", stderr(&o));
    let o = whirlmap(&["critical", "--mu", "0.3,0.3"]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_closed_stdout_ends_quietly_and_the_work_is_finished() {
    for args in [
        &["scene"][..],
        &["--help"],
        &["drop", "--help"],
        &["--version"],
    ] {
        let o = closed_stdout(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).is_empty(), "{args:?}: {}", stderr(&o));
    }
    let o = closed_stdout(&["scene"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    let o = closed_stdout(&[
        "drop",
        "--duration-s",
        "0.02",
        "--set",
        "classification.max_extension_s=0",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let dir = temp_dir("closed-stdout");
    let spec = spec_file(
        &dir,
        "tiny",
        &tiny_with_charts(r#"["classes", "max_force"]"#),
    );
    let out_dir = dir.join("out");
    let o = closed_stdout(&["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
    assert!(
        out_dir.join("charts/classes.png").is_file(),
        "the charts were skipped"
    );
    assert_eq!(read_json(&out_dir.join("manifest.json"))["complete"], true);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_list_where_an_object_belongs_is_refused() {
    let dir = temp_dir("lists");
    let scene = dir.join("scene.json");
    std::fs::write(&scene, "[1000, 0.1]").unwrap();
    let o = whirlmap(&["drop", "--scene", s(&scene), "--duration-s", "0.02"]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(
        stderr(&o).contains("top level") && stderr(&o).contains("not a list"),
        "{}",
        stderr(&o)
    );
    for (set, needle) in [
        ("thermal=[0.5]", "`thermal` must be a JSON object"),
        ("solver=[1e-6]", "`solver` must be a JSON object"),
        // serde refuses this one itself.
        (r#"friction_law={"regularised": [0.01]}"#, "friction_law"),
    ] {
        let o = whirlmap(&["drop", "--set", set, "--duration-s", "0.02"]);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", out_text(&o));
        assert!(stderr(&o).contains(needle), "{set}: {}", stderr(&o));
    }
    let base = r#""name": "l", "duration_s": 0.05, "axes": {"mu": [0.1]}"#;
    for (body, place) in [
        (r#""scene": [1000, 0.1]"#, "`scene`"),
        (
            r#""critical": {"mu": [0.3], "speed_rpm": [2000, 4000]}"#,
            "`critical.speed_rpm`",
        ),
        (r#""orbits": [8000, [0.1]]"#, "`orbits`"),
    ] {
        let spec = spec_file(&dir, "l", &format!("{{{base}, {body}}}"));
        let out_dir = dir.join("out");
        let o = sweep(&spec, &out_dir, &[]);
        assert_eq!(o.status.code(), Some(2), "{body}: {}", out_text(&o));
        assert!(stderr(&o).contains(place), "{body}: {}", stderr(&o));
        assert!(!out_dir.join("points.jsonl").exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn results_record_the_binarys_build_and_merge_refuses_two_builds() {
    let dir = temp_dir("build");
    let commit = built_commit();
    assert!(
        commit == "unknown"
            || (commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit())),
        "{commit}"
    );
    // Run from inside another repository: its HEAD is not the binary's commit.
    let repo = dir.join("other-repo");
    std::fs::create_dir_all(&repo).unwrap();
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .current_dir(&repo)
            .env("GIT_AUTHOR_NAME", "t")
            .env("GIT_AUTHOR_EMAIL", "t@t")
            .env("GIT_COMMITTER_NAME", "t")
            .env("GIT_COMMITTER_EMAIL", "t@t")
            .output()
    };
    let have_git = git(&["init", "-q"]).is_ok_and(|o| o.status.success())
        && git(&["commit", "-q", "--allow-empty", "-m", "x"]).is_ok_and(|o| o.status.success());
    let spec = spec_file(&dir, "tiny", TINY);
    let out_dir = dir.join("out");
    let o = Command::new(BIN)
        .args(["sweep", s(&spec), "--out", s(&out_dir), "--no-progress"])
        .current_dir(if have_git { &repo } else { &dir })
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let m = read_json(&out_dir.join("manifest.json"));
    assert_eq!(m["git_commit"], commit.as_str(), "{m}");
    if have_git {
        let head = git(&["rev-parse", "HEAD"]).unwrap();
        let head = String::from_utf8_lossy(&head.stdout).trim().to_string();
        assert_ne!(
            m["git_commit"],
            head.as_str(),
            "the cwd repository's HEAD was recorded"
        );
    }
    // Two shards, one of them (as if) from another build: the merge refuses.
    let shards: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = dir.join(format!("shard-{i}"));
            let o = sweep_shard(&spec, &d, i, 2);
            assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
            assert_eq!(
                read_json(&d.join("shard.json"))["git_commit"],
                commit.as_str()
            );
            d
        })
        .collect();
    let shard_file = shards[1].join("shard.json");
    let text = std::fs::read_to_string(&shard_file).unwrap();
    std::fs::write(
        &shard_file,
        text.replace(
            &format!("\"git_commit\": \"{commit}\""),
            "\"git_commit\": \"0123456789abcdef0123456789abcdef01234567\"",
        ),
    )
    .unwrap();
    let merged = dir.join("merged");
    let o = whirlmap(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(
        stderr(&o).contains("different builds") && stderr(&o).contains("0123456789abcdef"),
        "{}",
        stderr(&o)
    );
    assert!(!merged.join("points.jsonl").exists());
    std::fs::write(&shard_file, text).unwrap();
    let o = whirlmap(&["merge", s(&shards[0]), s(&shards[1]), "--out", s(&merged)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert_eq!(
        read_json(&merged.join("manifest.json"))["git_commit"],
        commit.as_str()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn compare_refuses_incomparable_runs_and_states_spec_differences() {
    let dir = temp_dir("incomparable");
    let run = |name: &str, text: &str| {
        let spec = spec_file(&dir, name, text);
        let out_dir = dir.join(name);
        let o = sweep(&spec, &out_dir, &[]);
        assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
        out_dir
    };
    let a = run("a", TINY);
    let shorter = run("shorter", &TINY.replace("0.05,", "0.04,"));
    let o = whirlmap(&["compare", s(&a), s(&shorter), "--out", s(&dir.join("1.md"))]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    let err = stderr(&o);
    assert!(
        err.contains("nothing to compare") && err.contains("duration_s: 0.05 -> 0.04"),
        "{err}"
    );
    // Two folders of garbage.
    let (g1, g2) = (dir.join("g1"), dir.join("g2"));
    for (g, t) in [(&g1, "garbage\n"), (&g2, "{\"not\": \"a record\"}\n")] {
        std::fs::create_dir_all(g).unwrap();
        std::fs::write(g.join("points.jsonl"), t).unwrap();
    }
    let o = whirlmap(&["compare", s(&g1), s(&g2), "--out", s(&dir.join("2.md"))]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(!String::from_utf8_lossy(&o.stdout).contains("same"));
    // Comparable runs of different specs: compared, and the difference said.
    let tight = run(
        "tight",
        &TINY.replace(r#""scene": {"#, r#""scene": {"solver": {"rtol": 1e-7}, "#),
    );
    let report = dir.join("3.md");
    let o = whirlmap(&["compare", s(&a), s(&tight), "--out", s(&report)]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", out_text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("the specs differ")
            && stdout.contains("spec differs     scene.solver.rtol: ")
            && stdout.contains(" -> 1e-7"),
        "{stdout}"
    );
    let md = std::fs::read_to_string(&report).unwrap();
    assert!(
        md.contains("## The specs differ") && md.contains("scene.solver.rtol"),
        "{md}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// One folder, one kind of run: a sweep is refused in an ensemble's folder; an ensemble's
/// `--overwrite` over a sweep's folder moves the sweep's files aside and deletes them once it
/// is written (so `render` draws the ensemble's Fig. 4, not the old sweep's charts), and a
/// sweep's `--overwrite` over an ensemble's folder does the same. `render` refuses a
/// `points.jsonl` without a record, and draws an ensemble's folder without a warning.
#[test]
fn runs_of_different_kinds_never_share_a_folder() {
    let dir = temp_dir("kinds");
    let tiny = spec_file(&dir, "tiny", TINY);
    let ens = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/ensemble-smoke.json");
    let ensemble = |out: &Path, extra: &[&str]| {
        let mut args = vec!["ensemble", s(&ens), "--out", s(out), "--no-progress"];
        args.extend_from_slice(extra);
        whirlmap(&args)
    };

    let e = dir.join("ensemble");
    let o = ensemble(&e, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let o = sweep(&tiny, &e, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("members.jsonl"), "{}", stderr(&o));
    assert!(!e.join("points.jsonl").exists());
    let o = whirlmap(&["render", s(&e)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));

    let sw = dir.join("sweep");
    let o = sweep(&tiny, &sw, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    let o = ensemble(&sw, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    for gone in ["points.jsonl", "summary.csv", "previous-run"] {
        assert!(
            !sw.join(gone).exists(),
            "{gone} is left beside the ensemble"
        );
    }
    assert!(sw.join("members.jsonl").is_file());
    let o = whirlmap(&["render", s(&sw)]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    assert!(out(&o).contains("fig4_probability"), "{}", out_text(&o));
    assert!(!out(&o).contains("classes"), "{}", out_text(&o));

    let o = sweep(&tiny, &e, &["--overwrite"]);
    assert_eq!(o.status.code(), Some(0), "{}", out_text(&o));
    for gone in [
        "members.jsonl",
        "cells.jsonl",
        "contours.json",
        "previous-run",
    ] {
        assert!(!e.join(gone).exists(), "{gone} is left beside the sweep");
    }

    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    // A folder without results: refused, and no lock file left in it.
    let o = whirlmap(&["render", s(&empty)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
    std::fs::write(empty.join("points.jsonl"), "").unwrap();
    let o = whirlmap(&["render", s(&empty)]);
    assert_eq!(o.status.code(), Some(2), "{}", out_text(&o));
    assert!(stderr(&o).contains("no complete record"), "{}", stderr(&o));
    assert!(!empty.join(".whirlmap.lock").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
