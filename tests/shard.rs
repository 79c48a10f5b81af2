//! End-to-end tests of `whirlmap sweep --shard I --shards N` and `whirlmap merge`: the merged
//! result equals the single-machine run byte for byte; the merge refuses missing, duplicated
//! and mismatched shards and names what is missing; a killed shard resumes.

mod common;
use common::*;

use std::path::{Path, PathBuf};
use std::process::Output;

/// 9 grid points, 3 critical searches, 2 orbit panels, a probability ensemble, every chart:
/// with 4 shards the parts are uneven (3, 2, 2, 2 points), shard 3 owns no critical search
/// and no orbit, and shard 0 runs the ensemble.
const SPEC: &str = r#"{
  "name": "shardtest",
  "duration_s": 0.1,
  "axes": {"speed_rpm": [4000, 8000, 12000], "mu": [0.1, 0.3, 0.4]},
  "critical": {"mu": [0.3, 0.35, 0.4], "speed_rpm": {"from": 2000, "to": 12000},
               "resolution_rpm": 2000, "tol_rpm": 500},
  "probability": {"axes": {"speed_rpm": [4000, 8000], "mu": [0.3, 0.4]},
                  "ensemble": {"members": 2, "seed": 7,
                               "unbalance_m": {"uniform": {"from": 0, "to": 2e-6}}}},
  "orbits": {"speed_rpm": 8000, "mu": [0.1, 0.4]},
  "charts": ["orbits", "critical", "max_force", "peak_power", "classes"]
}"#;

fn write_spec(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("spec.json");
    std::fs::write(&p, text).unwrap();
    p
}

fn full_run(spec: &Path, out: &Path) {
    let o = whirlmap(&[
        "sweep",
        s(spec),
        "--out",
        s(out),
        "--threads",
        "2",
        "--no-progress",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
}

fn run_shard(spec: &Path, out: &Path, i: usize, n: usize, extra: &[&str]) -> Output {
    sweep_shard_with(spec, out, i, n, &[&["--threads", "1"], extra].concat())
}

/// Runs every shard of `n` into `dir/shard-I` and returns the folders.
fn run_shards(spec: &Path, dir: &Path, n: usize) -> Vec<PathBuf> {
    (0..n)
        .map(|i| {
            let out = dir.join(format!("shard-{i}"));
            let o = run_shard(spec, &out, i, n, &[]);
            assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
            assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("shard {i}/{n}")));
            out
        })
        .collect()
}

fn merge(dirs: &[PathBuf], out: &Path) -> Output {
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(dirs.iter().map(|d| s(d)));
    args.extend(["--out", s(out)]);
    whirlmap(&args)
}

/// Relative paths of every file under `root`, sorted.
fn files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    out.sort();
    out
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every deterministic output byte-identical; the manifests equal up to run facts.
fn assert_same_result(single: &Path, merged: &Path) {
    let names = files(single);
    assert_eq!(
        names.iter().filter(|n| n.starts_with("charts")).count(),
        10,
        "{names:?}"
    );
    assert_eq!(names, files(merged), "the same files");
    for n in &names {
        let name = n.to_str().unwrap();
        // Run facts (wall times, threads) differ; the ensemble's manifest is one of them. The
        // lock file names the process that last held it.
        if name == "manifest.json"
            || name == "timings.jsonl"
            || name == "probability/manifest.json"
            || name == ".whirlmap.lock"
        {
            continue;
        }
        assert!(
            std::fs::read(single.join(n)).unwrap() == std::fs::read(merged.join(n)).unwrap(),
            "{name} differs between the single run and the merge"
        );
    }
    let strip = |mut v: serde_json::Value| {
        let m = v.as_object_mut().unwrap();
        for k in [
            "started_unix_s",
            "ended_unix_s",
            "threads",
            "git_commit",
            "merged_from",
        ] {
            m.remove(k);
        }
        m["counts"].as_object_mut().unwrap().remove("skipped");
        // Every file is listed; those holding run facts with their own sizes and hashes.
        let files = m["files"].as_object_mut().unwrap();
        for f in ["timings.jsonl", "probability/manifest.json"] {
            assert!(files.remove(f).is_some(), "{f} not listed");
        }
        v
    };
    let (a, b) = (
        json(&single.join("manifest.json")),
        json(&merged.join("manifest.json")),
    );
    assert_eq!(b["merged_from"].as_array().unwrap().len(), 4);
    assert_eq!(strip(a), strip(b));
}

#[test]
fn merged_shards_equal_the_single_run_byte_for_byte() {
    let dir = temp_dir("equal");
    let spec = write_spec(&dir, SPEC);
    let single = dir.join("single");
    full_run(&spec, &single);
    let mut shards = run_shards(&spec, &dir, 4);
    let sm = json(&shards[1].join("shard.json"));
    assert_eq!(
        (sm["shard"].as_u64(), sm["shards"].as_u64()),
        (Some(1), Some(4))
    );
    let owned: Vec<u64> = sm["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["index"].as_u64().unwrap())
        .collect();
    assert_eq!(owned, [1, 5]);
    assert_eq!(sm["critical_mu"], serde_json::json!([1]));
    assert_eq!(sm["spec_hash"].as_str().unwrap().len(), 16);
    assert_eq!(
        json(&shards[3].join("critical.json")),
        serde_json::json!([]),
        "shard 3 owns no critical search"
    );
    // The order of the folders does not matter.
    shards.reverse();
    let merged = dir.join("merged");
    let o = merge(&shards, &merged);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 shards, 9 points"));
    assert_same_result(&single, &merged);
    // Merging again into the same folder is refused with the options merge has.
    let o = merge(&shards, &merged);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--overwrite") && err.contains("--out") && !err.contains("--resume"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn merge_refuses_missing_duplicated_and_mismatched_shards() {
    let dir = temp_dir("refuse");
    let spec = write_spec(&dir, SPEC);
    let shards = run_shards(&spec, &dir, 4);
    let out = dir.join("merged");
    let refused = |dirs: &[PathBuf], expect: &[&str]| {
        let o = merge(dirs, &out);
        assert_eq!(o.status.code(), Some(2), "{expect:?}: {}", stderr(&o));
        for e in expect {
            assert!(stderr(&o).contains(e), "{e:?} not in: {}", stderr(&o));
        }
        assert!(!out.join("points.jsonl").exists(), "nothing written");
    };

    // A shard not given: its points are listed with their inputs.
    refused(
        &[shards[0].clone(), shards[1].clone(), shards[3].clone()],
        &[
            "shard 2/4 (no folder given) lacks 2 of its 2 points",
            "#2 (speed_rpm=4000, mu=0.4)",
            "#6 (speed_rpm=12000, mu=0.1)",
            "lacks its critical-speed searches (mu = 0.4)",
        ],
    );
    // A shard given twice.
    let mut twice = shards.clone();
    twice.push(shards[1].clone());
    refused(
        &twice,
        &[
            "shard 1/4 given twice",
            "point #1 (speed_rpm=4000, mu=0.3) is present 2 times",
        ],
    );
    // A shard of another spec.
    let other_dir = dir.join("other");
    std::fs::create_dir_all(&other_dir).unwrap();
    let other = write_spec(&other_dir, &SPEC.replace("0.1,\n", "0.11,\n"));
    let o = run_shard(&other, &other_dir.join("s2"), 2, 4, &[]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let mut mixed = shards.clone();
    mixed[2] = other_dir.join("s2");
    refused(&mixed, &["different specs"]);
    // A shard of another model version.
    let old = dir.join("old-model");
    std::fs::create_dir_all(&old).unwrap();
    for f in [
        "shard.json",
        "points.jsonl",
        "manifest.json",
        "critical.json",
    ] {
        std::fs::copy(shards[3].join(f), old.join(f)).unwrap();
    }
    let text = std::fs::read_to_string(old.join("shard.json")).unwrap();
    let v = json(&old.join("shard.json"));
    let mv = v["model_version"].as_u64().unwrap();
    std::fs::write(
        old.join("shard.json"),
        text.replace(
            &format!("\"model_version\": {mv}"),
            &format!("\"model_version\": {}", mv + 1),
        ),
    )
    .unwrap();
    let mut mixed = shards.clone();
    mixed[3] = old;
    refused(&mixed, &["different model versions"]);
    // Not a shard folder.
    refused(
        std::slice::from_ref(&dir),
        &["shard.json", "not a shard's output folder"],
    );
    // A record that is not of this spec's grid.
    let stray = dir.join("stray");
    std::fs::create_dir_all(&stray).unwrap();
    for f in ["shard.json", "manifest.json", "critical.json"] {
        std::fs::copy(shards[3].join(f), stray.join(f)).unwrap();
    }
    let mut lines = std::fs::read_to_string(shards[3].join("points.jsonl")).unwrap();
    lines.push_str(
        std::fs::read_to_string(other_dir.join("s2/points.jsonl"))
            .unwrap()
            .lines()
            .next()
            .unwrap(),
    );
    lines.push('\n');
    std::fs::write(stray.join("points.jsonl"), lines).unwrap();
    let mut mixed = shards.clone();
    mixed[3] = stray;
    refused(&mixed, &["not a record of a grid point"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn shard_options_are_checked() {
    let dir = temp_dir("options");
    let spec = write_spec(&dir, SPEC);
    let o = run_shard(&spec, &dir.join("x"), 4, 4, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--shard = 4") && stderr(&o).contains("[0, 3]"),
        "{}",
        stderr(&o)
    );
    let o = whirlmap(&["sweep", s(&spec), "--shard", "1", "--no-progress"]);
    assert_eq!(o.status.code(), Some(2), "--shard needs --shards");
    assert!(stderr(&o).contains("--shards"), "{}", stderr(&o));
    let o = whirlmap(&["merge"]);
    assert_eq!(o.status.code(), Some(2));
    // Resuming into another shard's folder is refused before anything runs.
    let out = dir.join("s0");
    let o = run_shard(&spec, &out, 3, 4, &[]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let o = run_shard(&spec, &out, 2, 4, &["--resume"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("holds shard 3/4"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_killed_shard_is_reported_then_resumes_without_duplicates_or_losses() {
    let dir = temp_dir("killed");
    let spec = write_spec(&dir, SPEC);
    let single = dir.join("single");
    full_run(&spec, &single);
    let mut shards = run_shards(&spec, &dir, 4);

    // Shard 0 again, killed once some of its records are in (its 3 points run on one thread;
    // its critical search, about 17 drops, and its orbit panel are still to go).
    let killed = dir.join("killed-0");
    let args = [
        "sweep",
        s(&spec),
        "--shard",
        "0",
        "--shards",
        "4",
        "--out",
        s(&killed),
        "--threads",
        "1",
        "--no-progress",
    ];
    let points = killed.join("points.jsonl");
    kill_after_lines(&args, &points, 1);
    assert!(
        !killed.join("critical.json").exists(),
        "the shard finished before it could be killed"
    );
    // A crash in the middle of a write also leaves a torn line.
    let mut text = std::fs::read_to_string(&points).unwrap();
    text.truncate(text.rfind('\n').map_or(0, |i| i + 1));
    let kept = text.lines().count();
    // Keep one complete record so the torn line follows real data.
    let first = text.lines().next().unwrap().to_string();
    let torn = format!("{first}\n{}", &first[..first.len() / 2]);
    std::fs::write(&points, torn).unwrap();
    assert!(kept >= 1);

    // The merge names the incomplete shard and the points it lacks.
    shards[0] = killed.clone();
    let merged = dir.join("merged");
    let o = merge(&shards, &merged);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("did not finish") && err.contains("lacks 2 of its 3 points"),
        "{err}"
    );
    assert!(
        err.contains("#4 (speed_rpm=8000, mu=0.3)") && err.contains("#8 (speed_rpm=12000, mu=0.4)"),
        "{err}"
    );
    assert!(
        err.contains("lacks its critical-speed searches (mu = 0.3)"),
        "{err}"
    );

    // Resubmitted with --resume, the shard completes and the merge equals the single run.
    let o = run_shard(&spec, &killed, 0, 4, &["--resume"]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("(1 resumed)"));
    let o = merge(&shards, &merged);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    assert_same_result(&single, &merged);
    std::fs::remove_dir_all(&dir).unwrap();
}
